// test_overload.c: the `overload` scenario does what its description says.
// The description used to say the port reliefs "open and hold the
// pressure"; the run shows the lift's port relief capping the trapped
// chamber's pressure while the boom sinks through it onto the lift
// cylinder's end stop. The times the description states (the relief's first
// opening, the end stop) are read from it and checked against the run (Krus
// 0.1 ms, and RODAS3 at rtol 1e-4 as an independent integration) within
// 0.1 s; p1A capped a little above the 25 MPa cracking pressure (measured
// 26.7 MPa as the relief passes the sinking boom's flow; at most 27.5 MPa
// allowed), q1 from 110 to about 70 degrees. The seal friction moved both
// times (docs/model.md): the frictionless crane's lift rang on its oil
// column as the jib accelerated the load, and a ringing peak reached the
// relief at 2.1 s, before the mean pressure did (2.7 s); and the seal's
// Coulomb force holds part of the load while the boom sinks, so the relief
// passes less and the stop is reached later. Checked here as the physics
// says: with the seals switched off (the paper's friction) the relief opens
// earlier and the stop comes sooner.
#include "check.h"
#include "crane_fixture.h"
#include "sim.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// The run's first relief opening and first lift end-stop time [s], the
// largest p1A before 5.6 s [Pa] and q1 at the end [deg].
static void overload_times(const model* m, const scenario* sc, hyd_method method, double* t_relief, double* t_stop,
                           double* p1a_max, double* q1_end) {
    sim_opts o = sim_default_opts();
    o.solver = method;
    o.rtol = 1e-4;
    sim_trace tr = {0};
    sim_result r;
    CHECK(sim_run(m, sc, &o, NULL, NULL, &tr, NULL, NULL, &r) == 0, "%s: %s", hyd_method_name(method), r.message);
    *t_relief = -1, *t_stop = -1, *p1a_max = 0;
    for (int i = 0; i < tr.nrow; ++i) {
        const double* row = tr.v + (size_t)i * SIM_NCOL;
        if (*t_relief < 0 && row[COL_RELIEF_OPEN] > 0) *t_relief = row[COL_T];
        if (*t_stop < 0 && ((int)row[COL_END_STOP] & 1)) *t_stop = row[COL_T];
        if (row[COL_T] < 5.6) *p1a_max = fmax(*p1a_max, row[COL_P1A]);
    }
    *q1_end = tr.nrow ? tr.v[(size_t)(tr.nrow - 1) * SIM_NCOL + COL_Q1] * 180.0 / M_PI : NAN;
    sim_trace_free(&tr);
}

static void test_overload_as_described(void) {
    scenario sc;
    model* m = load_crane("overload", &sc);
    if (!m) return;
    double said_relief = NAN, said_stop = NAN;
    const char* a = strstr(sc.description, "From ");
    const char* b = strstr(sc.description, "end stop at ");
    if (a) sscanf(a, "From %lf s", &said_relief);
    if (b) sscanf(b, "end stop at %lf s", &said_stop);
    CHECK(isfinite(said_relief) && isfinite(said_stop) && strstr(sc.description, "25 MPa port relief") &&
              !strstr(sc.description, "hold the pressure"),
          "description: %s", sc.description);
    const hyd_method ms[2] = {HYD_KRUS, HYD_RODAS3};
    double t_relief = NAN, t_stop = NAN;
    for (int j = 0; j < 2; ++j) {
        double p1a_max, q1_end;
        overload_times(m, &sc, ms[j], &t_relief, &t_stop, &p1a_max, &q1_end);
        CHECK(fabs(t_relief - said_relief) < 0.1, "%s: first relief open at %g s, the description says %g s",
              hyd_method_name(ms[j]), t_relief, said_relief);
        CHECK(p1a_max > 25e6 && p1a_max < 27.5e6, "%s: p1A up to %.3f MPa before the stop", hyd_method_name(ms[j]),
              p1a_max * 1e-6);
        CHECK(fabs(t_stop - said_stop) < 0.1, "%s: lift end stop at %g s, the description says %g s",
              hyd_method_name(ms[j]), t_stop, said_stop);
        CHECK(fabs(q1_end - 70.0) < 1.5, "%s: q1 ends at %.2f deg", hyd_method_name(ms[j]), q1_end);
        printf("  %s: relief at %g s, p1A up to %.2f MPa, end stop at %g s, q1 %.1f deg at the end\n",
               hyd_method_name(ms[j]), t_relief, p1a_max * 1e-6, t_stop, q1_end);
    }
    model_free(m);
    // The same crane with the seal friction the paper modelled (none beyond
    // the viscous term): the relief must open earlier (a ringing peak) and
    // the boom must sink faster onto its stop.
    m = load_crane_paper_friction("overload", &sc);
    if (!m) return;
    double p_relief, p_stop, p_p1a, p_q1;
    overload_times(m, &sc, HYD_KRUS, &p_relief, &p_stop, &p_p1a, &p_q1);
    printf("  without the seals' Coulomb and Stribeck terms: relief at %g s, end stop at %g s\n", p_relief, p_stop);
    CHECK(p_relief < t_relief && p_stop < t_stop, "seal friction: relief %g s and stop %g s, without %g and %g s",
          t_relief, t_stop, p_relief, p_stop);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_overload_as_described);
    TEST_MAIN_END();
}
