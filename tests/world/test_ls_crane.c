// test_ls_crane.c: every solver integrates the load-sensing crane
// (assets/models/hiab031_ls.json). The reference is Krus at 0.01 ms (it
// agrees with RODAS3 at rtol 1e-6 to 0.06 % RMS of peak p1A on ramp,
// docs/model.md); ROS34PW2 and RODAS3 at the paper's 1 % tolerance and
// Krus at the paper's 0.1 ms must stay within 1 % RMS (each chamber's
// pressure, of the highest chamber peak of the reference, as cranesim
// compare) over the whole ramp, and their strokes within 0.5 mm RMS. The
// draft LS crane failed this: its lowering rang (12 % RMS) and Krus 0.1 ms
// rang in the P nodes behind the 50 kPa compensators.
#include "check.h"
#include "crane_fixture.h"
#include "sim.h"

#include <math.h>
#include <string.h>

static int run(model* m, const scenario* sc, hyd_method solver, double h, double rtol, sim_trace* tr) {
    sim_opts o = sim_default_opts();
    o.solver = solver;
    if (h > 0) o.h = h;
    if (rtol > 0) o.rtol = rtol;
    sim_result r;
    const int rc = sim_run(m, sc, &o, NULL, NULL, tr, NULL, NULL, &r);
    CHECK(rc == 0, "%s", r.message);
    return rc;
}

static void test_solvers_agree(void) {
    scenario sc;
    if (load_scenario("ramp", &sc)) return;
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    sim_trace ref = {0};
    if (run(m, &sc, HYD_KRUS, 1e-5, 0, &ref)) {
        model_free(m);
        return;
    }
    static const int pc[4] = {COL_P1A, COL_P1B, COL_P2A, COL_P2B};
    double peak[4] = {0, 0, 0, 0};
    for (int i = 0; i < ref.nrow; ++i)
        for (int k = 0; k < 4; ++k) peak[k] = fmax(peak[k], ref.v[(size_t)i * SIM_NCOL + pc[k]]);
    const struct { const char* name; hyd_method s; double h, rtol; } runs[] = {
        {"krus 0.1 ms", HYD_KRUS, 1e-4, 0},
        {"ros34pw2 rtol 1e-2", HYD_ROS34PW2, 0, 1e-2},
        {"rodas3 rtol 1e-2", HYD_RODAS3, 0, 1e-2},
    };
    for (size_t j = 0; j < sizeof runs / sizeof runs[0]; ++j) {
        sim_trace tr = {0};
        if (run(m, &sc, runs[j].s, runs[j].h, runs[j].rtol, &tr)) continue;
        CHECK(tr.nrow == ref.nrow, "%s: %d rows, the reference %d", runs[j].name, tr.nrow, ref.nrow);
        const int n = tr.nrow < ref.nrow ? tr.nrow : ref.nrow;
        double sp[4] = {0, 0, 0, 0}, sx = 0.0;
        for (int i = 0; i < n; ++i) {
            const double* a = tr.v + (size_t)i * SIM_NCOL;
            const double* b = ref.v + (size_t)i * SIM_NCOL;
            for (int k = 0; k < 4; ++k) sp[k] += (a[pc[k]] - b[pc[k]]) * (a[pc[k]] - b[pc[k]]);
            sx += (a[COL_X1] - b[COL_X1]) * (a[COL_X1] - b[COL_X1]) + (a[COL_X2] - b[COL_X2]) * (a[COL_X2] - b[COL_X2]);
        }
        // As cranesim compare: RMS of each chamber against the highest
        // chamber peak of the reference.
        const double pk = fmax(fmax(peak[0], peak[1]), fmax(peak[2], peak[3]));
        double worst = 0.0;
        for (int k = 0; k < 4; ++k) {
            worst = fmax(worst, 100.0 * sqrt(sp[k] / n) / pk);
        }
        const double xr = 1e3 * sqrt(sx / (2.0 * n));
        printf("  %s: worst chamber-pressure RMS %.3f %% of peak, strokes %.4f mm RMS\n", runs[j].name, worst, xr);
        CHECK(worst < 1.0, "%s: chamber pressure RMS %.3f %% of peak against Krus 0.01 ms", runs[j].name, worst);
        CHECK(xr < 0.5, "%s: strokes %.4f mm RMS against Krus 0.01 ms", runs[j].name, xr);
        sim_trace_free(&tr);
    }
    sim_trace_free(&ref);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_solvers_agree);
    TEST_MAIN_END();
}
