// test_rcl.c: the rated capacity limiter at the cylinders' end stops, where
// a chamber pressure carries the stop's force as well as the load, and on a
// seeded random drive.
//
// The reference is the hooked load itself: the sandbox's 200 kg box over
// the load chart's capacity where it hangs (the chart is a static analysis
// of the geometry and the relief settings, loadchart.c; the limiter's
// utilisation is a pressure measurement). On a stop the limiter must read
// that, not the stop's force, and lowering out of the stop must pass whole.
#include "check.h"
#include "engine.h"
#include "lagrange.h"
#include "loadchart.h"
#include "rcl.h"
#include "scenario.h"
#include "sim.h"

#include <cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include "random_drive.h"

#define SANDBOX CRANESIM_ASSETS "/worlds/sandbox.json"

static model* load_model(void) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "model: %s", err);
    return m;
}

// The scenario: hook the 200 kg box, lift until the lift cylinder
// is on its end stop with the valve still open (1.5..8 s), let go (8.5 s),
// then lower at half command (12.5..16 s).
static const char* k_lift_stop =
    "{\"name\": \"rcl_endstop\", \"duration\": 17, \"initial\": {\"q1_deg\": 117.3, \"q2_deg\": -65.8, "
    "\"slew_deg\": -60}, \"commands\": {\"lift\": [[0, 0], [1.0, 0], [1.5, 1.0], [8.0, 1.0], [8.5, 0], [12.0, 0], "
    "[12.5, -0.5], [16.0, -0.5], [16.5, 0]]}, \"hook\": [[0.5, \"attach\"]]}";
// The same box lifted clear, then the jib out onto its end stop with the
// valve open (4.5..14 s), let go, then in at half command (17.5..21 s).
static const char* k_jib_stop =
    "{\"name\": \"rcl_jibstop\", \"duration\": 21, \"initial\": {\"q1_deg\": 117.3, \"q2_deg\": -65.8, "
    "\"slew_deg\": -60}, \"commands\": {\"lift\": [[0, 0], [1.0, 0], [1.5, 1.0], [3.0, 1.0], [3.5, 0]], "
    "\"jib\": [[0, 0], [4.0, 0], [4.5, 1.0], [14.0, 1.0], [14.5, 0], [17, 0], [17.5, -0.5], [21, -0.5]]}, "
    "\"hook\": [[0.5, \"attach\"]]}";

static int scenario_text(const char* text, scenario* sc) {
    char err[400];
    cJSON* j = cJSON_Parse(text);
    CHECK(j != NULL, "scenario JSON");
    const int rc = j ? scenario_from_json(j, "test scenario", sc, err, sizeof err) : -1;
    CHECK(rc == 0, "%s", err);
    cJSON_Delete(j);
    return rc;
}

typedef struct rows {
    double* v;
    int n, cap;
} rows;

static int keep_row(void* user, const double* row) {
    rows* r = user;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 4096;
        r->v = realloc(r->v, sizeof(double) * SIM_NCOL * (size_t)r->cap);
    }
    memcpy(r->v + (size_t)r->n++ * SIM_NCOL, row, sizeof(double) * SIM_NCOL);
    return 0;
}

static sim_opts sandbox_opts(void) {
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = SANDBOX;
    o.rcl = true;
    o.dt_out = 0.01;
    return o;
}

// The scenario's rows on the sandbox with the limiter on: the ode backend's
// scripted run (`run --scenario`), or the stepped engine as drive steps it
// (10 ms frames, commands at each frame's middle through engine_play and
// engine_set_commands).
static int scenario_rows(const model* m, const scenario* sc, bool stepped, rows* out) {
    const sim_opts o = sandbox_opts();
    if (!stepped) {
        sim_result res;
        const engine_sink k = {.row = keep_row, .user = out, .rows = true, .t_end = sc->duration};
        const int rc = engine_run(m, sc, &o, &k, &res);
        CHECK(rc == 0, "run: %s", res.message);
        return rc;
    }
    char err[400];
    engine* e = engine_create(m, &o, sc->q0, sc->slew0, -1, err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (!e) return -1;
    const double frame = 0.01;
    int ev = 0, rc = 0;
    for (long i = 0; i < (long)(sc->duration / frame + 0.5) && !rc; ++i) {
        double u[3];
        engine_play(e, sc, (i + 0.5) * frame, &ev, u, NULL, NULL);
        engine_set_commands(e, u);
        rc = engine_advance_to(e, (double)(i + 1) * frame, keep_row, out);
    }
    CHECK(rc == 0, "stepped: %s", engine_error(e));
    engine_destroy(e);
    return rc;
}

// The hooked box's utilisation: its mass over the chart's capacity at the
// row's outreach and slew (the limiter's own chart, on the sandbox truck).
static double true_util(const model* m, const rcl* r, const double* row, double mass) {
    double R, z;
    crane_tip(&m->mech, row[COL_Q1], row[COL_Q2], &R, &z);
    return mass / loadchart_capacity(&r->chart, R, row[COL_SLEW], NULL);
}

static const double* row_at(const rows* r, double t) {
    for (int i = 0; i < r->n; ++i)
        if (r->v[(size_t)i * SIM_NCOL + COL_T] >= t - 1e-9) return r->v + (size_t)i * SIM_NCOL;
    return r->n ? r->v + (size_t)(r->n - 1) * SIM_NCOL : NULL;
}

// Checks over the rows of [t0, t1]: the cylinder (0 lift, 1 jib) on its end
// stop with a stop pressure above 15 MPa (the premise; the stop's flag in 90 % of the
// rows, as ODE's hinge limit bounces), and the
// utilisation within 25 % of the box's; returns the largest |util - true|
// relative to the true one.
static double stop_phase(const model* m, const rcl* r, const rows* rw, double t0, double t1, int cyl, double mass,
                         const char* what) {
    double worst = 0, umax = 0, pmax = 0;
    int on_stop = 0, n = 0;
    for (int i = 0; i < rw->n; ++i) {
        const double* row = rw->v + (size_t)i * SIM_NCOL;
        if (row[COL_T] < t0 || row[COL_T] > t1) continue;
        ++n;
        on_stop += ((int)row[COL_END_STOP] >> cyl) & 1;
        pmax = fmax(pmax, row[cyl ? COL_P2A : COL_P1A]);
        const double tu = true_util(m, r, row, mass);
        worst = fmax(worst, fabs(row[COL_RCL_UTIL] - tu) / tu);
        umax = fmax(umax, row[COL_RCL_UTIL]);
    }
    printf("  %s: %d rows on the stop of %d, stop pressure up to %.2f MPa, rcl_util up to %.3f, "
           "within %.1f %% of the box's\n", what, on_stop, n, pmax * 1e-6, umax, 100 * worst);
    // The end_stop bit flickers as the hinge limit bounces: most rows.
    CHECK(n > 0 && on_stop >= 0.9 * n, "%s: the cylinder was on its end stop in %d of %d rows", what, on_stop, n);
    CHECK(pmax > 15e6, "%s: the stop pressure reached only %.2f MPa (the scenario no longer reaches the stop?)", what,
          pmax * 1e-6);
    CHECK(worst < 0.25, "%s: rcl_util off the box's by %.1f %% (up to %.3f)", what, 100 * worst, umax);
    return worst;
}

// Leaving the stop: over [t0, t1] the command col passes whole (the
// operator's cmd), and the stroke comes off the stop by more than 0.1 m.
static void leaves_stop(const rows* rw, double t0, double t1, int col, double cmd, int xcol, double x_stop,
                        const char* what) {
    int cut = 0, n = 0;
    for (int i = 0; i < rw->n; ++i) {
        const double* row = rw->v + (size_t)i * SIM_NCOL;
        if (row[COL_T] < t0 || row[COL_T] > t1) continue;
        ++n;
        cut += row[col] != cmd;
    }
    const double* end = row_at(rw, t1);
    printf("  %s: command %+g passed whole in %d of %d rows; stroke %.3f m at %.1f s (stop at %.3f m)\n", what, cmd,
           n - cut, n, end[xcol], t1, x_stop);
    CHECK(n > 0 && cut == 0, "%s: the limiter cut the command in %d of %d rows", what, cut, n);
    CHECK(fabs(end[xcol] - x_stop) > 0.1, "%s: the stroke stayed at %.3f m (stop %.3f m)", what, end[xcol], x_stop);
}

static void lift_stop_case(bool stepped) {
    model* m = load_model();
    scenario sc;
    if (!m || scenario_text(k_lift_stop, &sc)) return;
    rcl r;
    char err[300];
    CHECK(rcl_init_world(&r, m, SANDBOX, err, sizeof err) == 0, "%s", err);
    rows rw = {0};
    if (!scenario_rows(m, &sc, stepped, &rw)) {
        const double* hooked = row_at(&rw, 2.0);
        CHECK(hooked[COL_ATTACHED] >= 0, "the box was not hooked");
        const char* what = stepped ? "stepped engine, lift on its stop" : "scripted run, lift on its stop";
        // From 1 s after the stop is reached (the filter's lag) to the
        // lowering command.
        stop_phase(m, &r, &rw, 6.5, 12.4, 0, 200, what);
        double AA, AB, s;
        hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &AA, &AB, &s);
        // The operator's -0.5 from 12.5 s (the scenario ramps to it until then).
        leaves_stop(&rw, 12.55, 16.0, COL_U1_CMD, -0.5, COL_X1, s, stepped ? "stepped, lowering" : "scripted, lowering");
    }
    free(rw.v);
    rcl_free(&r);
    model_free(m);
}

static void test_lift_end_stop_scripted(void) { lift_stop_case(false); }
static void test_lift_end_stop_stepped(void) { lift_stop_case(true); }

// The jib's end stop: its force acts between the two booms and cancels in
// the moment about joint 1, so the lift pressure the limiter reads is the
// load's there as anywhere; jib in out of the stop passes whole.
static void test_jib_end_stop(void) {
    model* m = load_model();
    scenario sc;
    if (!m || scenario_text(k_jib_stop, &sc)) return;
    rcl r;
    char err[300];
    CHECK(rcl_init_world(&r, m, SANDBOX, err, sizeof err) == 0, "%s", err);
    rows rw = {0};
    if (!scenario_rows(m, &sc, false, &rw)) {
        stop_phase(m, &r, &rw, 6.0, 17.4, 1, 200, "scripted run, jib on its stop");
        double AA, AB, s;
        hyd_model_cylinder_geometry(m->hyd, m->cyl[1], &AA, &AB, &s);
        leaves_stop(&rw, 17.55, 20.5, COL_U2_CMD, -0.5, COL_X2, s, "jib in");
    }
    free(rw.v);
    rcl_free(&r);
    model_free(m);
}

// The limiter alone on rows made by hand: a load held statically clear of
// the stops, then the same pose on the lift cylinder's extended stop with
// the pump's pressure in chamber A (the stop takes the rest), and on the
// retracted stop with it in chamber B. The estimate holds the load measured
// before the stop in both, instead of reading 20.6 MPa as load (extended)
// or a negative force as no load (retracted); clear of the stop again, it
// measures again.
static void static_row(const model* m, double q1, double q2, double ml, double t, double* row) {
    memset(row, 0, sizeof(double) * SIM_NCOL);
    row[COL_T] = t;
    const double q[2] = {q1, q2};
    double G[2], r, AA, AB, st;
    lagrange_gravity(&m->mech, LAGRANGE_FULL, ml, q, G);
    crane_pin_length(&m->mech.act[0], q1, &r);
    hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &AA, &AB, &st);
    row[COL_Q1] = q1, row[COL_Q2] = q2;
    row[COL_X1] = crane_stroke(&m->mech.act[0], q1);
    row[COL_P1B] = 0.5e6;
    row[COL_P1A] = (G[0] / r + row[COL_P1B] * AB) / AA;
}

static void test_held_on_both_stops(void) {
    model* m = load_model();
    if (!m) return;
    rcl r;
    char err[300];
    CHECK(rcl_init(&r, m, NULL, err, sizeof err) == 0, "%s", err);
    double AA, AB, s;
    hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &AA, &AB, &s);
    const crane_actuator* a = &m->mech.act[0];
    const double q2 = -60 * M_PI / 180, p_pump = 20.6e6;
    // Poses 5 mm inside each stop (within the band) and 50 mm clear of it.
    const double q_ext = crane_joint_for_stroke(a, s - 0.005), q_ext_clear = crane_joint_for_stroke(a, s - 0.05);
    const double q_ret = crane_joint_for_stroke(a, 0.005), q_ret_clear = crane_joint_for_stroke(a, 0.05);
    const double ml = 300; // [kg] at the tip
    for (int end = 0; end < 2; ++end) {
        const double qs = end ? q_ret : q_ext, qc = end ? q_ret_clear : q_ext_clear;
        double row[SIM_NCOL], t = 1000.0 * (end + 1);
        // 10 s clear of the stop: the filter settles on the load.
        for (int i = 0; i < 1000; ++i, t += 0.01) {
            static_row(m, qc, q2, ml, t, row);
            rcl_utilisation(&r, row);
        }
        const double m_clear = r.m_filt;
        // 10 s on the stop with the pump's pressure on the stop's side.
        double m_lo = INFINITY, m_hi = -INFINITY;
        for (int i = 0; i < 1000; ++i, t += 0.01) {
            static_row(m, qs, q2, ml, t, row);
            if (end) row[COL_P1A] = 0.2e6, row[COL_P1B] = p_pump;
            else row[COL_P1A] = p_pump, row[COL_P1B] = 0.1e6;
            rcl_utilisation(&r, row);
            m_lo = fmin(m_lo, r.m_filt), m_hi = fmax(m_hi, r.m_filt);
        }
        printf("  %s stop: load %.1f kg clear of it, %.1f..%.1f kg on it at %.1f MPa (tip load %.0f kg with the "
               "hook's share)\n",
               end ? "retracted" : "extended", m_clear, m_lo, m_hi, p_pump * 1e-6, ml);
        CHECK(r.held, "%s stop: the pressure was trusted 5 mm from the stop", end ? "retracted" : "extended");
        CHECK(fabs(m_lo - m_clear) < 0.01 * ml && fabs(m_hi - m_clear) < 0.01 * ml,
              "%s stop: the estimate moved from %.1f kg to %.1f..%.1f kg", end ? "retracted" : "extended", m_clear,
              m_lo, m_hi);
        // Clear again with another load: measured again (the filter's 1 s lag: 5 s suffice).
        for (int i = 0; i < 500; ++i, t += 0.01) {
            static_row(m, qc, q2, 2 * ml, t, row);
            rcl_utilisation(&r, row);
        }
        CHECK(!r.held && fabs(r.m_filt - (m_clear + ml)) < 0.02 * ml, "%s stop: clear again, %.1f kg (expected %.1f)",
              end ? "retracted" : "extended", r.m_filt, m_clear + ml);
    }
    rcl_free(&r);
    model_free(m);
}

// A short seeded random drive (random_drive.h: random sticks and hook
// events through the stepped engine, the limiter on). Seed 1 over 60 s
// drives the lift cylinder into its end stops with the valve open: before,
// the stop's pressure read as load (117 %, 3.2 s at or above 90 % with
// nothing on the hook). Now no time at or above 90 % near a stop, and every
// moment at or above 90 % is explained: a boom touching the world or the
// truck (a force the lift pressure carries, as a real limiter reads it), or
// a hooked load over the chart. rcl_soak runs the long drives.
static void test_random_drive(void) {
    model* m = load_model();
    if (!m) return;
    rd_result r;
    CHECK(random_drive(m, 1, 60, false, &r) == 0, "%s", r.err);
    printf("  seed 1, 60 s: rcl_util max %.3f at %.2f s; at or above 90 %%: %.2f s, near a stop %.2f s, "
           "touching %.2f s, load over the chart %.2f s, other %.2f s; lift near a stop %.2f s in all\n",
           r.util_max, r.t_util_max, r.t90, r.t90_stop, r.t90_contact, r.t90_over, r.t90_other, r.t_stop);
    CHECK(!r.failed, "the drive failed: %s", r.err);
    CHECK(r.t_stop > 1.0, "the drive no longer reaches an end stop (%.2f s): the test shows nothing", r.t_stop);
    CHECK(r.t90_stop == 0, "%.2f s at or above 90 %% with the lift near an end stop", r.t90_stop);
    CHECK(r.t90_other == 0, "%.2f s at or above 90 %% with no contact and no load over the chart", r.t90_other);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_held_on_both_stops);
    RUN_TEST(test_lift_end_stop_scripted);
    RUN_TEST(test_lift_end_stop_stepped);
    RUN_TEST(test_jib_end_stop);
    RUN_TEST(test_random_drive);
    TEST_MAIN_END();
}
