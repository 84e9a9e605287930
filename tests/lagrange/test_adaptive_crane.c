// test_adaptive_crane.c: the adaptive Rosenbrock methods on the whole crane
// (ramp scenario) against an independent reference, SUNDIALS CVODE (BDF) at a
// tight tolerance: chamber pressures within 1 % of the peak pressure at
// rtol = 1e-3, with far fewer steps than the fixed 0.1 ms step.
#include "check.h"
#include "crane_fixture.h"
#include "sim.h"

#include <math.h>
#include <string.h>

static void test_adaptive_within_one_percent(void) {
    CHECK(sim_have_cvode(), "this build has no CVODE reference");
    if (!sim_have_cvode()) return;
    scenario sc;
    model* m = load_crane("ramp", &sc);
    if (!m) return;
    sim_opts ro = sim_default_opts();
    ro.cvode = true;
    ro.rtol = 1e-10;
    ro.atol = 1e-8;
    sim_trace ref = {0};
    sim_result rr;
    CHECK(sim_run(m, &sc, &ro, NULL, NULL, &ref, NULL, NULL, &rr) == 0, "reference: %s", rr.message);
    double peak = 0;
    for (int i = 0; i < ref.nrow; ++i)
        for (int k = COL_P1A; k <= COL_P2B; ++k) peak = fmax(peak, ref.v[(size_t)i * SIM_NCOL + k]);
    const hyd_method methods[2] = {HYD_ROS34PW2, HYD_RODAS3};
    for (int j = 0; j < 2; ++j) {
        sim_opts o = sim_default_opts();
        o.solver = methods[j];
        o.rtol = 1e-3;
        sim_trace tr = {0};
        sim_result r;
        CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r) == 0, "%s: %s", hyd_method_name(methods[j]),
              r.message);
        CHECK(tr.nrow == ref.nrow, "rows %d vs %d", tr.nrow, ref.nrow);
        double emax = 0;
        for (int i = 0; i < tr.nrow && i < ref.nrow; ++i)
            for (int k = COL_P1A; k <= COL_P2B; ++k)
                emax = fmax(emax, fabs(tr.v[(size_t)i * SIM_NCOL + k] - ref.v[(size_t)i * SIM_NCOL + k]));
        CHECK(emax < 0.01 * peak, "%s: max pressure error %.3f MPa = %.2f %% of peak", hyd_method_name(methods[j]),
              emax * 1e-6, 100 * emax / peak);
        // The point of adaptivity: steps far longer than 0.1 ms on average.
        double mean_h = sc.duration / (double)r.stats.steps;
        CHECK(mean_h > 100 * 1e-4, "%s: mean step %.3g ms", hyd_method_name(methods[j]), mean_h * 1e3);
        sim_trace_free(&tr);
    }
    sim_trace_free(&ref);
    model_free(m);
}

// The overload scenario drives a chamber towards cavitation. At the paper's
// loose tolerance (rtol 1e-2) RODAS3 used to accept steps that took a
// pressure to -262 kPa absolute (the error estimate does not see the
// barrier): the problem's domain hook (hyd_problem.outside) now rejects
// those trial steps, and the rejections are counted. ROS34PW2 at the same
// tolerance takes steps so long (0.26 s) that the cubic output interpolant
// dipped to -2.5 kPa between two admissible end points; the output then
// falls back to the chord. Both runs end normally, every output pressure
// above absolute zero.
static void test_domain_keeps_pressures_physical(void) {
    scenario sc;
    model* m = load_crane("overload", &sc);
    if (!m) return;
    const hyd_method methods[2] = {HYD_RODAS3, HYD_ROS34PW2};
    for (int j = 0; j < 2; ++j) {
        sim_opts o = sim_default_opts();
        o.solver = methods[j];
        o.rtol = 1e-2;
        sim_trace tr = {0};
        sim_result r;
        CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r) == 0, "%s: %s", hyd_method_name(methods[j]),
              r.message);
        double pmin = HUGE_VAL;
        for (int i = 0; i < tr.nrow; ++i)
            for (int k = COL_P1A; k <= COL_P2B; ++k) pmin = fmin(pmin, tr.v[(size_t)i * SIM_NCOL + k]);
        printf("  overload, %s rtol 1e-2: lowest chamber pressure %.1f kPa abs, %ld trial steps rejected for "
               "leaving the domain\n", hyd_method_name(methods[j]), pmin * 1e-3, r.stats.outside);
        CHECK(pmin > 0.0, "%s: pressure %.4g Pa", hyd_method_name(methods[j]), pmin);
        if (methods[j] == HYD_RODAS3) CHECK(r.stats.outside > 0, "the hook never acted: the test no longer covers it");
        sim_trace_free(&tr);
    }
    model_free(m);
}

// Below absolute zero (decision 6): a fixed-step W-method that dips there for
// a step at a stiff event (ROS2 at 1 ms on `overload`, the crane with the
// seal friction the paper modelled: -3.7 kPa as the lift hits its end stop
// at 5.70 s) finishes with a note naming the state, the depth and the time;
// CVODE at rtol 1e-2 on `ramp`, which leaves the physical range by far more
// (-192 kPa, then a crane falling while commanded up), fails. The shipped
// crane (realistic seal friction) at ROS2 1 ms on `overload` either
// finishes, with or without such a note, or stops with a message naming
// the state, the time and the cure: never a silent wrong answer (it stops
// at the end-stop impact at 6.19 s: docs/model.md, seal friction).
static void test_dips_and_failures(void) {
    if (!sim_have_cvode()) {
        CHECK(0, "this build has no CVODE");
        return;
    }
    scenario sc;
    model* p = load_crane_paper_friction("overload", &sc);
    if (!p) return;
    sim_opts o = sim_default_opts();
    o.solver = HYD_ROS2;
    o.h = 1e-3;
    sim_result r;
    CHECK(sim_run(p, &sc, &o, NULL, NULL, NULL, NULL, NULL, &r) == 0, "ros2 1 ms: %s", r.message);
    CHECK(strstr(r.note, "dipped below absolute zero") && strstr(r.note, "kPa"), "note: '%s'", r.note);
    printf("  ros2 1 ms on overload, the paper's friction: %s\n", r.note);
    model_free(p);
    model* m = load_crane("overload", &sc);
    if (!m) return;
    const int rc = sim_run(m, &sc, &o, NULL, NULL, NULL, NULL, NULL, &r);
    CHECK((rc == 0 && (!r.note[0] || (strstr(r.note, "dipped below absolute zero") && strstr(r.note, " s")))) ||
              (rc == 1 && strstr(r.message, "numerical blow-up: state ") && strstr(r.message, " at t = ") &&
               strstr(r.message, "smaller")),
          "ros2 1 ms, shipped crane: status %d: '%s' '%s'", rc, r.message, r.note);
    printf("  ros2 1 ms on overload, the shipped crane: status %d: %s%s\n", rc, r.message, r.note);
    load_scenario("ramp", &sc);
    o = sim_default_opts();
    o.cvode = true;
    o.rtol = 1e-2;
    CHECK(sim_run(m, &sc, &o, NULL, NULL, NULL, NULL, NULL, &r) == 1 && strstr(r.message, "below absolute zero"),
          "cvode rtol 1e-2: status %d: %s", r.status, r.message);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_adaptive_within_one_percent);
    RUN_TEST(test_domain_keeps_pressures_physical);
    RUN_TEST(test_dips_and_failures);
    TEST_MAIN_END();
}
