// test_jac_events.c: the Jacobian renewed at events (hyd_problem.events,
// lsim_events) on the whole crane. Krus at h = 1 ms on `step` used to stop
// at 3.629 s with lift_hose_B.p at -0.35 MPa: the lift rod side recompresses
// from 0.06 MPa, where the entrained air makes the bulk modulus 100 times
// smaller than at 1 MPa, and a J reused for 10 steps from 0.23 MPa
// underestimated the stiffness 3x. Renewed as the pressure rises through
// each octave below the bulk modulus' knee (and at the other events), the
// run goes through and follows CVODE (an independent BDF code) at a tight
// tolerance: measured 0.32 % of the peak pressure RMS, 1.9 % max.
#include "check.h"
#include "crane_fixture.h"
#include "sim.h"

#include <math.h>
#include <string.h>

// Pressure differences of tr from ref over the rows both have, as fractions
// of ref's peak chamber pressure.
static void pressure_error(const sim_trace* tr, const sim_trace* ref, double* rms, double* max) {
    double peak = 0, s2 = 0, mx = 0;
    long n = 0;
    for (int i = 0; i < ref->nrow; ++i)
        for (int k = COL_P1A; k <= COL_P2B; ++k) peak = fmax(peak, ref->v[(size_t)i * SIM_NCOL + k]);
    for (int i = 0; i < tr->nrow && i < ref->nrow; ++i)
        for (int k = COL_P1A; k <= COL_P2B; ++k) {
            const double d = tr->v[(size_t)i * SIM_NCOL + k] - ref->v[(size_t)i * SIM_NCOL + k];
            s2 += d * d;
            mx = fmax(mx, fabs(d));
            ++n;
        }
    *rms = n ? sqrt(s2 / (double)n) / peak : NAN;
    *max = mx / peak;
}

static void test_krus_1ms_step(void) {
    CHECK(sim_have_cvode(), "this build has no CVODE reference");
    if (!sim_have_cvode()) return;
    scenario sc;
    model* m = load_crane("step", &sc);
    if (!m) return;
    sim_opts ro = sim_default_opts();
    ro.cvode = true;
    ro.rtol = 1e-9;
    ro.atol = 1e-7;
    sim_trace ref = {0};
    sim_result rr;
    CHECK(sim_run(m, &sc, &ro, NULL, NULL, &ref, NULL, NULL, &rr) == 0, "reference: %s", rr.message);
    // Krus only: ROS2 (L-stable, a larger error constant) ran through before
    // too, at 4.7 % RMS from the reference.
    const hyd_method ms[1] = {HYD_KRUS};
    for (int j = 0; j < 1; ++j) {
        sim_opts o = sim_default_opts();
        o.solver = ms[j];
        o.h = 1e-3; // jac_every 10, the default
        sim_trace tr = {0};
        sim_result r;
        CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r) == 0, "%s 1 ms: %s", hyd_method_name(ms[j]),
              r.message);
        CHECK(tr.nrow == ref.nrow, "%s: %d rows, reference %d", hyd_method_name(ms[j]), tr.nrow, ref.nrow);
        double rms, max;
        pressure_error(&tr, &ref, &rms, &max);
        // The tolerance: 1 % RMS (the study's accuracy target), 4 % max
        // (twice the measured 1.9 %: the valve steps' transients at 1 ms).
        CHECK(rms < 0.01 && max < 0.04, "%s 1 ms on step: pressure error RMS %.3f %%, max %.3f %% of peak",
              hyd_method_name(ms[j]), 100 * rms, 100 * max);
        CHECK(r.stats.jevents > 0, "%s: no J renewed at an event", hyd_method_name(ms[j]));
        printf("  %s 1 ms on step: pressure error RMS %.3f %%, max %.3f %% of peak; %ld J, %ld at events\n",
               hyd_method_name(ms[j]), 100 * rms, 100 * max, r.stats.jevals, r.stats.jevents);
        sim_trace_free(&tr);
    }
    sim_trace_free(&ref);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_krus_1ms_step);
    TEST_MAIN_END();
}
