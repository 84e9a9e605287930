// ode_bench.c: real-time factor of the ODE sandbox with the full circuit
// (hydraulics at 0.1 ms), ODE at 1 ms and at 0.1 ms; median of 3 runs each.
// A benchmark, not a test: prints JSON lines, never registered with ctest.
//   ode_bench [duration_s] [world.json]
#include "model.h"
#include "ode_world.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int cmp(const void* a, const void* b) {
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

int main(int argc, char** argv) {
    double dur = argc > 1 ? atof(argv[1]) : 10.0;
    const char* wpath = argc > 2 ? argv[2] : CRANESIM_ASSETS "/worlds/sandbox.json";
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    if (!m) { fprintf(stderr, "%s\n", err); return 2; }
    world_desc d;
    if (world_desc_load(wpath, &d, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 2; }
    const double dts[2] = {1e-3, 1e-4};
    for (int c = 0; c < 2; ++c) {
        double rtf[3];
        long steps = 0;
        int contacts = 0;
        for (int r = 0; r < 3; ++r) {
            ode_world_opts o = ode_world_default_opts();
            o.dt_ode = dts[c];
            o.dt_hyd = 1e-4;
            o.q0[0] = 110 * 3.14159265358979 / 180;
            o.q0[1] = -60 * 3.14159265358979 / 180;
            o.slew0 = -0.6;
            o.model_file = "hiab031.json";
            ode_world* w = ode_world_create(&m->mech, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"), &d, &o,
                                            err, sizeof err);
            if (!w) { fprintf(stderr, "%s\n", err); return 1; }
            // A moving crane: all three valves driven with slow sinusoids-ish
            // (piecewise constant per 0.1 s), so the hook swings and contacts change.
            double t0 = now();
            for (double t = 0; t < dur - 1e-9; t += 0.1) {
                double u[3] = {0.4 * ((int)(t / 2.0) % 2 ? 1 : -1), 0.3 * ((int)(t / 3.0) % 2 ? 1 : -1),
                               0.5 * ((int)(t / 4.0) % 2 ? 1 : -1)};
                ode_world_set_commands(w, u);
                if (ode_world_step(w, 0.1)) { fprintf(stderr, "%s\n", ode_world_error(w)); break; }
            }
            double wall = now() - t0;
            rtf[r] = ode_world_time(w) / wall;
            steps = ode_world_hyd_steps(w);
            ode_world_state s;
            ode_world_get_state(w, &s);
            contacts = s.ncontact;
            ode_world_destroy(w);
        }
        qsort(rtf, 3, sizeof *rtf, cmp);
        printf("{\"bench\":\"ode_sandbox\",\"dt_ode\":%g,\"dt_hyd\":%g,\"solver\":\"krus\",\"duration\":%g,"
               "\"hyd_steps\":%ld,\"contacts_end\":%d,\"rt_factor_median\":%.2f,\"rt_factor_min\":%.2f,\"rt_factor_max\":%.2f}\n",
               dts[c], 1e-4, dur, steps, contacts, rtf[1], rtf[0], rtf[2]);
        fflush(stdout);
    }
    world_desc_free(&d);
    model_free(m);
    return 0;
}
