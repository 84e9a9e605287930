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
#include "engine.h"
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

// The LS crane on the default engine at scenario name's start; NULL (with
// the check failed and nothing left allocated) if either does not load.
static engine* ls_engine(const char* name, scenario* sc, model** m) {
    if (load_scenario(name, sc)) return NULL;
    char err[512];
    *m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", NULL, 0, err, sizeof err);
    CHECK(*m != NULL, "%s", err);
    if (!*m) return NULL;
    sim_opts o = sim_default_opts();
    engine* e = engine_create(*m, &o, sc->q0, sc->slew0, sim_load_mass(*m, sc, &o), err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (!e) model_free(*m);
    return e;
}

// Lowering through the counterbalance valve, in the full crane. 1000 kg
// held (hose_burst_line's pose), valves closed; then the lift command ramps
// slowly to -0.3 over 4 s, so the rod side (the valve's pilot) charges
// slowly. The valve's opening balance (docs/hydraulics.md) says it cracks
// when (p_l - p_v) + R (p_p - p_v) = p_setting: with the load pressure p_l,
// the valve-port pressure p_v and the pilot volume's pressure p_p (behind
// the damping orifice) read at that moment, the pilot pressure must be
// p_v + (p_setting - (p_l - p_v)) / R (25 MPa, R = 4: about 3.2 MPa),
// within 5 %. And by hand from the holding state alone: raising the rod
// side by p_p pushes the piston down, and the load side rises by
// (A_B p_p - F_b) / A_A (area ratio 0.64; F_b = 4.5 kN, the seal's
// breakaway, resists the creeping piston), so p_p = (p_setting - p_hold +
// F_b / A_A) / (R + A_B / A_A) in gauge pressures, within 5 % (the pilot
// volume lags the rod side by about 0.1 s, a few kPa at this slow ramp,
// so it reads the rod side's pressure here). Before the
// crack the lift only creeps by the load column's compression (about
// 3.2 L x 1.7 MPa / Be over A_A: under 1 mm).
static void test_lowering_pilot(void) {
    scenario sc;
    model* m;
    engine* e = ls_engine("hose_burst_line", &sc, &m);
    if (!e) return;
    const hyd_model* h = engine_circuit(e);
    const int sl = hyd_model_node_state(h, hyd_model_find_node(h, "lift_cyl.A"));
    const int sv = hyd_model_node_state(h, hyd_model_find_node(h, "lift_cbv_A"));
    const int sp = hyd_model_node_state(h, hyd_model_find_node(h, "lift_cbv_pilot"));
    const int sx = hyd_model_find_state(h, "lift_cbv.spool");
    CHECK(sl >= 0 && sv >= 0 && sp >= 0 && sx >= 0, "states %d %d %d %d", sl, sv, sp, sx);
    const double pset = 25e6, R = 4.0, pt = 1e5; // lift_cbv: p_setting, pilot_ratio
    const double AA = 0.25 * 3.14159265358979 * 0.1 * 0.1, AB = 0.25 * 3.14159265358979 * (0.1 * 0.1 - 0.06 * 0.06);
    double y[256], row[SIM_NCOL];
    CHECK(hyd_model_nstate(h) <= 256, "%d states", hyd_model_nstate(h));
    // Settle for 1 s with the valves closed.
    double u[3] = {0, 0, 0};
    engine_set_commands(e, u);
    CHECK(engine_advance_to(e, 1.0, NULL, NULL) == 0, "%s", engine_error(e));
    engine_circuit_state(e, y, NULL);
    const double p_hold = y[sl];
    engine_row(e, row);
    const double x0 = row[COL_X1];
    int cracked = 0;
    for (int k = 1; k <= 4000 && !cracked && sl >= 0 && sv >= 0 && sp >= 0 && sx >= 0; ++k) {
        u[0] = -0.3 * k / 4000.0;
        engine_set_commands(e, u);
        if (engine_advance_to(e, 1.0 + 1e-3 * k, NULL, NULL)) break;
        engine_circuit_state(e, y, NULL);
        if (y[sx] < 0.01) continue;
        cracked = 1;
        const double pl = y[sl], pv = y[sv], pp = y[sp];
        const double pred = pv + (pset - (pl - pv)) / R;
        const double Fb = 4500.0; // lift_cyl coulomb + stribeck [N]
        const double hand = pt + (pset - (p_hold - pt) + Fb / AA) / (R + AB / AA);
        engine_row(e, row);
        printf("  cracks at u = %.4f: pilot %.3f MPa; balance %.3f MPa (p_l %.3f, p_v %.3f); by hand from the "
               "holding %.3f MPa: %.3f MPa; lift moved %.3f mm\n",
               u[0], pp / 1e6, pred / 1e6, pl / 1e6, pv / 1e6, p_hold / 1e6, hand / 1e6, 1e3 * (row[COL_X1] - x0));
        CHECK_REL(pp - pt, pred - pt, 0.05);
        CHECK_REL(pp - pt, hand - pt, 0.05);
        CHECK(fabs(row[COL_X1] - x0) < 1e-3, "the lift moved %g m before the valve cracked", row[COL_X1] - x0);
    }
    CHECK(cracked, "the counterbalance valve did not open while lowering");
    engine_destroy(e);
    model_free(m);
}


// Standard deviation [Pa] of column col over the rows with t in [t0, t1],
// and the change of stroke column xc over the window [m].
static double window_sd(const sim_trace* tr, int col, int xc, double t0, double t1, double* dx) {
    double s = 0.0, s2 = 0.0, xa = 0.0, xb = 0.0;
    int n = 0;
    for (int i = 0; i < tr->nrow; ++i) {
        const double* r = tr->v + (size_t)i * SIM_NCOL;
        if (r[COL_T] < t0 - 1e-9 || r[COL_T] > t1 + 1e-9) continue;
        if (n == 0) xa = r[xc];
        xb = r[xc];
        s += r[col], s2 += r[col] * r[col];
        ++n;
    }
    *dx = xb - xa;
    CHECK(n > 100, "%d rows in [%g, %g] s", n, t0, t1);
    if (n == 0) return 0.0;
    const double mean = s / n;
    return sqrt(fmax(s2 / n - mean * mean, 0.0));
}

// Lowering through the counterbalance valves is steady. The window of each
// motion starts 0.5 s after its command has reached its lowering value (the
// valve cracking and the load accelerating are a start transient) and ends
// where the command starts to return: ls_lowering (1500 kg) lift 1.5-4.0 s
// (p1A), jib 5.5-7.0 s (p2A); ramp (500 kg, both lowering) 14.0-15.9 s (p1A).
// The holding chamber's pressure must not swing more than 1 MPa (standard
// deviation) while the cylinder keeps lowering (more than 100 mm moved, so a
// valve that stayed shut cannot pass). A 20 mm^2 valve without the pilot
// damping orifice rings there at 4 Hz (p1A 6-26 MPa lowering 1500 kg).
static void test_lowering_steady(void) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    const struct { const char* scen; const char* name; int col, xc; double t0, t1; } w[] = {
        {"ls_lowering", "ls_lowering, lift p1A", COL_P1A, COL_X1, 1.5, 4.0},
        {"ls_lowering", "ls_lowering, jib p2A", COL_P2A, COL_X2, 5.5, 7.0},
        {"ramp", "ramp, lift p1A", COL_P1A, COL_X1, 14.0, 15.9},
    };
    sim_trace tr = {0};
    const char* have = NULL;
    for (size_t j = 0; j < sizeof w / sizeof w[0]; ++j) {
        if (!have || strcmp(have, w[j].scen) != 0) {
            sim_trace_free(&tr);
            memset(&tr, 0, sizeof tr);
            have = NULL;
            scenario sc;
            if (load_scenario(w[j].scen, &sc) || run(m, &sc, HYD_KRUS, 1e-4, 0, &tr)) continue;
            have = w[j].scen;
        }
        double dx;
        const double sd = window_sd(&tr, w[j].col, w[j].xc, w[j].t0, w[j].t1, &dx);
        printf("  %s, %.1f-%.1f s: SD %.3f MPa, stroke moved %.1f mm\n", w[j].name, w[j].t0, w[j].t1, sd / 1e6,
               1e3 * dx);
        CHECK(dx < -0.1, "%s: the cylinder only moved %g m while lowering", w[j].name, dx);
        CHECK(sd < 1e6, "%s: chamber pressure SD %.3f MPa while lowering", w[j].name, sd / 1e6);
    }
    sim_trace_free(&tr);
    model_free(m);
}

// Flow sharing on the full crane: ls_flow_sharing drives lift and jib at
// full command together (1-3 s), more than the pump's 35 L/min. The
// post-compensated sections must share the pump's flow in the ratio of the
// commands (1:1) within 3 %. The flows come from the rows' cylinder
// velocities times the piston areas (both extend), not from the circuit's
// own flow outputs. The window starts at 1.5 s: until about 1.45 s the
// overrunning jib still refills its piston side through the anti-cavitation
// check (a flow no section meters). Before the LS ports followed the spool,
// the jib's shuttle sensed its rod side and the flows were 13.9 : 19.8 L/min.
static void test_flow_sharing_crane(void) {
    scenario sc;
    if (load_scenario("ls_flow_sharing", &sc)) return;
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    sim_trace tr = {0};
    if (run(m, &sc, HYD_KRUS, 1e-4, 0, &tr)) {
        model_free(m);
        return;
    }
    const double pi = 3.14159265358979;
    const double A1 = 0.25 * pi * 0.1 * 0.1, A2 = 0.25 * pi * 0.08 * 0.08; // piston areas [m^2]
    double q1 = 0, q2 = 0, c1 = 0, c2 = 0;
    int n = 0;
    for (int i = 0; i < tr.nrow; ++i) {
        const double* r = tr.v + (size_t)i * SIM_NCOL;
        if (r[COL_T] < 1.5 - 1e-9 || r[COL_T] > 3.0 + 1e-9) continue;
        q1 += r[COL_V1] * A1, q2 += r[COL_V2] * A2;
        c1 += r[COL_U1_CMD], c2 += r[COL_U2_CMD];
        ++n;
    }
    CHECK(n > 1000, "%d rows in the window", n);
    if (n > 0) {
        q1 /= n, q2 /= n, c1 /= n, c2 /= n;
        printf("  saturated, commands %.3f : %.3f: lift %.2f L/min, jib %.2f L/min (sum %.2f of the pump's 35), "
               "ratio %.4f\n", c1, c2, 6e4 * q1, 6e4 * q2, 6e4 * (q1 + q2), (q1 / q2) / (c1 / c2));
        CHECK(fabs((q1 / q2) / (c1 / c2) - 1.0) <= 0.03, "flow ratio %.4f, commands %.4f", q1 / q2, c1 / c2);
        // Saturated indeed: the two take (nearly) all of the pump's flow
        // (the rest compresses the lines and leaks).
        CHECK(6e4 * (q1 + q2) > 0.95 * 35.0 && 6e4 * (q1 + q2) < 35.0, "sum %.2f L/min", 6e4 * (q1 + q2));
    }
    sim_trace_free(&tr);
    model_free(m);
}

// In neutral each section's LS port is drained to tank through its spool,
// so with the valves closed the whole LS network settles at tank pressure
// (0.1 MPa abs; the LS line w/4 above, the main shuttle's corner) and the pump at its standby, whatever the loads hold. A
// max-select shuttle of A and B would hand the holding pressure of a work
// line to the pump instead (the jib's rod side, 2.5 MPa: the pump then stood
// at 19.5 MPa on ramp before any command).
static void test_ls_neutral(void) {
    scenario sc;
    model* m;
    engine* e = ls_engine("ls_flow_sharing", &sc, &m);
    if (!e) return;
    const hyd_model* h = engine_circuit(e);
    const char* ls[3] = {"lift_ls", "jib_ls", "ls_line"};
    const char* port[2] = {"jib_hose_B", "lift_hose_B"};
    double u[3] = {0, 0, 0}, y[256];
    CHECK(hyd_model_nstate(h) <= 256, "%d states", hyd_model_nstate(h));
    engine_set_commands(e, u);
    CHECK(engine_advance_to(e, 0.8, NULL, NULL) == 0, "%s", engine_error(e));
    engine_circuit_state(e, y, NULL);
    for (int k = 0; k < 2; ++k) {
        const int s = hyd_model_node_state(h, hyd_model_find_node(h, port[k]));
        CHECK(s >= 0 && y[s] > 0.4e6, "%s holds %g Pa", port[k], s >= 0 ? y[s] : 0.0);
    }
    for (int k = 0; k < 3; ++k) {
        const int s = hyd_model_node_state(h, hyd_model_find_node(h, ls[k]));
        CHECK(s >= 0, "no node %s", ls[k]);
        if (s < 0) continue;
        printf("  neutral: %s at %.4f MPa abs\n", ls[k], y[s] / 1e6);
        // The main shuttle's smooth max of two equal inputs is w/4 above
        // them (corner half-width w = 0.1 MPa, docs/hydraulics.md).
        CHECK_NEAR(y[s], 1e5 + (k == 2 ? 0.25 * 1e5 : 0.0), 1e3);
    }
    engine_destroy(e);
    model_free(m);
}

// Long fixed steps on the LS crane. The draft blew up in the first
// millisecond at Krus 1 ms and ROS2 0.2 and 1 ms (section LS nodes below
// absolute zero): its max-select shuttles charged the 5 mL LS nodes from
// 0.1 MPa to the work lines' holding pressures through 2e-11 m^3/(s Pa) at
// t = 0. With the LS ports following the spool the initial state is
// consistent (in neutral the LS network sits at tank pressure).
// Krus above 0.1 ms integrates `ramp` but not abrupt valve steps: on the
// `step` commands its spools ring (R(-inf) = -1) and the jib's stroke is
// 25-35 % RMS of its peak off the 0.1 ms run at 0.2-1 ms, without a
// blow-up once a failed step is retried in shorter ones. A run is therefore
// refused before it starts (the step probe, sim_check_step_probe, issue 25
// item 7), naming 0.1 ms; with the probe off Krus 0.2 ms still runs the
// whole ramp, as it always did. ROS2 (L-stable) passes the probe at 0.2,
// 0.5 and 1 ms (1.2 % and 5 % off at 1 ms) and runs the whole ramp.
static void test_long_steps(void) {
    scenario sc;
    if (load_scenario("ramp", &sc)) return;
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    enum { RUNS, REFUSED };
    const struct { hyd_method s; double h; bool no_probe; int want; } runs[] = {
        {HYD_KRUS, 2e-4, false, REFUSED}, {HYD_KRUS, 5e-4, false, REFUSED}, {HYD_KRUS, 1e-3, false, REFUSED},
        {HYD_KRUS, 2e-4, true, RUNS},     {HYD_ROS2, 2e-4, false, RUNS},    {HYD_ROS2, 5e-4, false, RUNS},
        {HYD_ROS2, 1e-3, false, RUNS}};
    for (size_t j = 0; j < sizeof runs / sizeof runs[0]; ++j) {
        sim_opts o = sim_default_opts();
        o.solver = runs[j].s, o.h = runs[j].h, o.dt_out = runs[j].h > 1e-3 ? runs[j].h : 1e-3;
        o.no_step_probe = runs[j].no_probe;
        sim_trace tr = {0};
        sim_result r;
        const int rc = sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r);
        const char* name = runs[j].s == HYD_KRUS ? "krus" : "ros2";
        const double t_end = tr.nrow > 0 ? tr.v[(size_t)(tr.nrow - 1) * SIM_NCOL + COL_T] : -1;
        if (runs[j].want == RUNS) {
            CHECK(rc == 0, "%s h = %g%s: %s", name, runs[j].h, runs[j].no_probe ? " (no probe)" : "", r.message);
            CHECK(t_end > 19.99, "%s h = %g: stopped early", name, runs[j].h);
        } else {
            printf("  %s h = %g ms: %s\n", name, 1e3 * runs[j].h, r.message);
            CHECK(rc == SIM_REFUSED && tr.nrow == 0 && strstr(r.message, "is inaccurate") &&
                      strstr(r.message, "is 0.0001 s"),
                  "%s h = %g: want refused before the run naming 0.1 ms: rc %d, %d rows: %s", name, runs[j].h, rc,
                  tr.nrow, r.message);
        }
        sim_trace_free(&tr);
    }
    model_free(m);
}

// The slew in the sandbox on the LS crane is a load-sensing section of its
// own (the world's circuit_ls: compensator, spool-mode shuttle, a
// max-select shuttle into the pump's LS line). While the slew alone moves
// (sandbox_swing, 1-2 s at 0.8) the pump must sit one margin (2 MPa) above
// the slew's loaded chamber, within the compensator's setting plus the LS
// line's drop (0.5 MPa), and the slew must turn as far as the standard
// crane's, whose pump stands at 20 MPa (within 15 %). With the slew fed from
// the pump line outside the LS network the pump stayed at standby (2.1-2.8
// MPa) and the slew turned 6.6 deg against 33.5.
static void test_sandbox_slew_ls(void) {
    scenario sc;
    if (load_scenario("sandbox_swing", &sc)) return;
    const char* models[2] = {"hiab031_ls.json", "hiab031.json"};
    double turned[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
        model* m = load_model(models[k]);
        if (!m) continue;
        sim_opts o = sim_default_opts();
        o.mechanics = SIM_ODE;
        o.world = CRANESIM_ASSETS "/worlds/sandbox.json";
        sim_trace tr = {0};
        sim_result r;
        const int rc = sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r);
        CHECK(rc == 0, "%s: %s", models[k], r.message);
        if (rc == 0) {
            double s0 = NAN, s1 = NAN, dmin = 1e30, dmax = -1e30;
            for (int i = 0; i < tr.nrow; ++i) {
                const double* row = tr.v + (size_t)i * SIM_NCOL;
                const double t = row[COL_T];
                if (fabs(t - 1.0) < 5e-4) s0 = row[COL_SLEW];
                if (fabs(t - 2.0) < 5e-4) s1 = row[COL_SLEW];
                if (t >= 1.5 && t <= 1.95) {
                    const double d = row[COL_P_PUMP] - fmax(row[COL_P3A], row[COL_P3B]);
                    dmin = fmin(dmin, d), dmax = fmax(dmax, d);
                }
            }
            turned[k] = fabs(s1 - s0) * 57.29577951308232; // deg/rad
            printf("  %s: slew turns %.1f deg in 1-2 s; p_pump - max(p3A, p3B) %.2f..%.2f MPa over 1.5-1.95 s\n",
                   models[k], turned[k], dmin / 1e6, dmax / 1e6);
            if (k == 0)
                CHECK(dmin > 2e6 - 0.5e6 && dmax < 2e6 + 0.5e6,
                      "LS crane: the pump does not follow the slew's load: margin %.2f..%.2f MPa (2 MPa expected)",
                      dmin / 1e6, dmax / 1e6);
            sim_trace_free(&tr);
        }
        model_free(m);
    }
    CHECK(turned[1] > 10 && fabs(turned[0] - turned[1]) < 0.15 * turned[1],
          "the LS crane slews %.1f deg, the standard crane %.1f deg", turned[0], turned[1]);
}

// The block pattern of the fixed-step W: on `step` (lift and jib steps, the
// pump to its cut-off) Krus at the default 0.1 ms must stay within 1.5 % of
// peak, at every output row and in each chamber, of Krus at 0.01 ms (within
// 0.7 % of RODAS3 at rtol 1e-7 itself). With the hose, the valve-side node
// and the chamber behind each counterbalance valve in 1x1 blocks it was
// 15.9 % off (0.95 % with them in one 3x3 block, as the standard crane's
// [hose, chamber]).
static void test_block_pattern_step(void) {
    scenario sc;
    if (load_scenario("step", &sc)) return;
    model* m = load_model("hiab031_ls.json");
    if (!m) return;
    sim_trace ref = {0}, tr = {0};
    if (!run(m, &sc, HYD_KRUS, 1e-5, 0, &ref) && !run(m, &sc, HYD_KRUS, 1e-4, 0, &tr)) {
        static const int pc[4] = {COL_P1A, COL_P1B, COL_P2A, COL_P2B};
        double peak = 0, worst = 0;
        const int n = tr.nrow < ref.nrow ? tr.nrow : ref.nrow;
        for (int i = 0; i < ref.nrow; ++i)
            for (int k = 0; k < 4; ++k) peak = fmax(peak, ref.v[(size_t)i * SIM_NCOL + pc[k]]);
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < 4; ++k)
                worst = fmax(worst, fabs(tr.v[(size_t)i * SIM_NCOL + pc[k]] - ref.v[(size_t)i * SIM_NCOL + pc[k]]));
        printf("  step: Krus 0.1 ms against 0.01 ms: max chamber-pressure difference %.3f %% of peak %.2f MPa\n",
               100 * worst / peak, peak / 1e6);
        CHECK(n == ref.nrow && worst < 0.015 * peak, "Krus 0.1 ms off by %.2f %% of peak", 100 * worst / peak);
    }
    sim_trace_free(&ref);
    sim_trace_free(&tr);
    model_free(m);
}

// The ode backend's block pattern on the LS crane: `step` with the default
// pattern must stay within 1 % of peak of the same run with the dense J. It
// was 3.75 % off while the pattern, sampled where the counterbalance valves
// are shut, kept their two nodes in separate blocks.
static void test_ode_block_pattern_step(void) {
    scenario sc;
    if (load_scenario("step", &sc)) return;
    model* m = load_model("hiab031_ls.json");
    if (!m) return;
    sim_trace tr[2] = {{0}, {0}};
    int ok = 1;
    for (int k = 0; k < 2; ++k) {
        sim_opts o = sim_default_opts();
        o.mechanics = SIM_ODE;
        o.dense_jac = k == 1;
        sim_result r;
        const int rc = sim_run(m, &sc, &o, NULL, NULL, &tr[k], NULL, NULL, &r);
        CHECK(rc == 0, "ode %s: %s", k ? "dense" : "blocks", r.message);
        ok &= rc == 0;
    }
    if (ok) {
        static const int pc[4] = {COL_P1A, COL_P1B, COL_P2A, COL_P2B};
        double peak = 0, worst = 0;
        const int n = tr[0].nrow < tr[1].nrow ? tr[0].nrow : tr[1].nrow;
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < 4; ++k) {
                const double a = tr[0].v[(size_t)i * SIM_NCOL + pc[k]], b = tr[1].v[(size_t)i * SIM_NCOL + pc[k]];
                peak = fmax(peak, b), worst = fmax(worst, fabs(a - b));
            }
        printf("  ode step: block pattern against dense J: max chamber-pressure difference %.3f %% of peak\n",
               100 * worst / peak);
        CHECK(n > 0 && worst < 0.01 * peak, "ode: the block pattern is %.2f %% of peak off the dense J", 100 * worst / peak);
    }
    sim_trace_free(&tr[0]);
    sim_trace_free(&tr[1]);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_ls_neutral);
    RUN_TEST(test_block_pattern_step);
    RUN_TEST(test_ode_block_pattern_step);
    RUN_TEST(test_sandbox_slew_ls);
    RUN_TEST(test_long_steps);
    RUN_TEST(test_flow_sharing_crane);
    RUN_TEST(test_lowering_pilot);
    RUN_TEST(test_lowering_steady);
    RUN_TEST(test_solvers_agree);
    TEST_MAIN_END();
}
