// crane_headless.c: run the default crane on the ramp scenario headless and
// print a summary, through the world API (what `cranesim run` does).
#include <stdio.h>

#include "sim.h"

int main(void) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    if (!m) {
        fprintf(stderr, "%s\n", err);
        return 2;
    }
    scenario sc;
    if (scenario_load(CRANESIM_ASSETS "/scenarios/ramp.json", &sc, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        model_free(m);
        return 2;
    }
    sim_opts o = sim_default_opts(); // lagrange full, Krus, h = 0.1 ms
    sim_trace tr = {0};
    sim_result r;
    if (sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r)) {
        fprintf(stderr, "run failed: %s\n", r.message);
        model_free(m);
        return 1;
    }
    double pmax = 0, reach = 0;
    for (int i = 0; i < tr.nrow; ++i) {
        const double* v = tr.v + (size_t)i * SIM_NCOL;
        for (int k = COL_P1A; k <= COL_P2B; ++k) pmax = v[k] > pmax ? v[k] : pmax;
        reach = v[COL_TIP_X] > reach ? v[COL_TIP_X] : reach;
    }
    const double* e = tr.v + (size_t)(tr.nrow - 1) * SIM_NCOL;
    printf("%s on %s: %.1f s simulated in %.3f s (%.0fx real time), %ld steps\n", sc.name, m->name, r.t_end, r.wall,
           r.t_end / r.wall, r.stats.steps);
    printf("peak chamber pressure %.2f MPa, max reach %.2f m, final strokes %.0f / %.0f mm\n", pmax * 1e-6, reach,
           e[COL_X1] * 1e3, e[COL_X2] * 1e3);
    sim_trace_free(&tr);
    model_free(m);
    return 0;
}
