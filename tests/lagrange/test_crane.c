// test_crane.c: the analytic crane with its full circuit, against physics:
// Jacobian vs finite differences, static equilibrium, flow continuity,
// pump-limited speed, the docs/model.md sanity targets, variants, scenarios.
#include "check.h"
#include "sim.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double urand01(void) { return rand() / (double)RAND_MAX; }

static model* load_default(void) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "default model: %s", err);
    return m;
}

static void test_jacobian_matches_finite_differences(void) {
    model* m = load_default();
    if (!m) return;
    lsim s;
    char err[256];
    CHECK(lsim_init(&s, m, LAGRANGE_FULL, 500, err, sizeof err) == 0, "%s", err);
    const int n = s.n;
    double y[LSIM_MAX_STATES];
    static double J[LSIM_MAX_STATES * LSIM_MAX_STATES], Jfd[LSIM_MAX_STATES * LSIM_MAX_STATES];
    const double q0[2] = {110 * M_PI / 180, -80 * M_PI / 180};
    lsim_initial_state(&s, q0, 0.5e6, y);
    // Moving, valves partly open, pressures away from any corner.
    y[s.iq + 2] = 0.05;
    y[s.iq + 3] = -0.08;
    y[s.iu[0]] = 0.4;
    y[s.iu[1]] = -0.3;
    s.u_cmd[0] = 0.5;
    s.u_cmd[1] = -0.2;
    lsim_jac(&s, 0.0, y, J);
    double f1[LSIM_MAX_STATES], f2[LSIM_MAX_STATES];
    for (int j = 0; j < n; ++j) {
        double h = 1e-6 * fmax(fabs(y[j]), j >= s.iq ? 1.0 : 1e5);
        double yj = y[j];
        y[j] = yj + h;
        lsim_rhs(&s, 0.0, y, f1);
        y[j] = yj - h;
        lsim_rhs(&s, 0.0, y, f2);
        y[j] = yj;
        for (int i = 0; i < n; ++i) Jfd[i * n + j] = (f1[i] - f2[i]) / (2 * h);
    }
    int bad = 0;
    for (int i = 0; i < n; ++i) {
        double rowmax = 0;
        for (int j = 0; j < n; ++j) rowmax = fmax(rowmax, fabs(Jfd[i * n + j]));
        for (int j = 0; j < n; ++j) {
            double a = J[i * n + j], b = Jfd[i * n + j];
            if (fabs(a - b) > 1e-4 * fabs(b) + 1e-7 * rowmax + 1e-12) {
                if (bad++ < 8)
                    fprintf(stderr, "  J[%d][%d] analytic %.8g vs fd %.8g\n", i, j, a, b);
            }
        }
    }
    CHECK(bad == 0, "%d Jacobian entries differ from central differences", bad);
    lsim_free(&s);
    model_free(m);
}

static scenario make_scenario(double duration, double q1_deg, double q2_deg, double m3) {
    scenario sc;
    memset(&sc, 0, sizeof sc);
    snprintf(sc.name, sizeof sc.name, "test");
    sc.duration = duration;
    sc.load_mass = m3;
    sc.q0[0] = q1_deg * M_PI / 180;
    sc.q0[1] = q2_deg * M_PI / 180;
    return sc;
}

static const double* last_row(const sim_trace* tr) { return tr->v + (size_t)(tr->nrow - 1) * SIM_NCOL; }

// Valves closed with a load: the crane holds, and the trapped chamber
// pressures balance gravity through the lever arms (torque balance computed
// from the model's own parameters, independent of the simulation).
static void test_static_hold_matches_torque_balance(void) {
    model* m = load_default();
    if (!m) return;
    scenario sc = make_scenario(5.0, 120, -70, 1000);
    sim_opts o = sim_default_opts();
    sim_trace tr = {0};
    sim_result r;
    CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r) == 0, "%s", r.message);
    const double* e = last_row(&tr);
    CHECK_NEAR(e[COL_Q1], sc.q0[0], 0.05 * M_PI / 180);
    CHECK_NEAR(e[COL_Q2], sc.q0[1], 0.05 * M_PI / 180);
    double G[2];
    const double q[2] = {e[COL_Q1], e[COL_Q2]};
    lagrange_gravity(&m->mech, LAGRANGE_FULL, 1000, q, G);
    for (int k = 0; k < 2; ++k) {
        double AA, AB, st, r_k;
        hyd_model_cylinder_geometry(m->hyd, m->cyl[k], &AA, &AB, &st);
        crane_pin_length(&m->mech.act[k], q[k], &r_k);
        double pA = e[COL_P1A + 2 * k], pB = e[COL_P1B + 2 * k];
        // At rest friction is zero, so pA AA - pB AB = G / r.
        CHECK_REL(pA * AA - pB * AB, G[k] / r_k, 2e-3);
    }
    sim_trace_free(&tr);
    model_free(m);
}

// Lift valve fully open: the pump's flow limit, not the valve, sets the
// speed. At steady state the piston speed is the pump flow over the piston
// area (less what the main relief and leakage take, both ~0 here).
static void test_steady_lift_speed_matches_flow(void) {
    model* m = load_default();
    if (!m) return;
    scenario sc = make_scenario(3.0, 80, -120, 500);
    sc.cmd[0].n = 2;
    sc.cmd[0].t[0] = 0.0;
    sc.cmd[0].u[0] = 0.0;
    sc.cmd[0].t[1] = 0.1;
    sc.cmd[0].u[1] = 1.0;
    sim_opts o = sim_default_opts();
    sim_trace tr = {0};
    sim_result r;
    CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r) == 0, "%s", r.message);
    double AA, AB, st, qmax;
    hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &AA, &AB, &st);
    CHECK(hyd_model_get(m->hyd, "pump.q_max", &qmax) == 0, "pump.q_max");
    // Mean speed over 1.5..2.5 s from the stroke difference.
    const double* a = tr.v + (size_t)1500 * SIM_NCOL;
    const double* b = tr.v + (size_t)2500 * SIM_NCOL;
    double v = (b[COL_X1] - a[COL_X1]) / (b[COL_T] - a[COL_T]);
    CHECK_REL(v, qmax / AA, 0.01);
    // Still inside the stroke, so the end stop did not limit it.
    CHECK(b[COL_X1] < st - 0.01, "reached the end stop: x1 = %g", b[COL_X1]);
    sim_trace_free(&tr);
    model_free(m);
}

// Partly open, the valve meters the flow: at steady state the piston speed is
// the metering edge's orifice flow for the steady pressure drop, over the
// piston area (flow continuity; compressibility terms vanish at steady state).
static void test_steady_speed_is_valve_flow_over_area(void) {
    model* m = load_default();
    if (!m) return;
    lsim s;
    char err[256];
    CHECK(lsim_init(&s, m, LAGRANGE_FULL, 500, err, sizeof err) == 0, "%s", err);
    double y[LSIM_MAX_STATES];
    const double q0[2] = {85 * M_PI / 180, -120 * M_PI / 180};
    lsim_initial_state(&s, q0, 0.5e6, y);
    s.u_cmd[0] = 0.1;
    hyd_problem p = lsim_problem(&s, true);
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = 1e-4;
    hyd_solver* sol = hyd_solver_create(&p, HYD_KRUS, &so);
    double t = 0;
    CHECK(hyd_solver_advance(sol, &t, y, 1.5) == HYD_OK, "advance");
    // The oil column is lightly damped (2-12 Hz modes), so compare means over
    // 2 s rather than instantaneous values.
    double qn, dpn, cd;
    hyd_model_get(m->hyd, "lift_valve.q_nominal", &qn);
    hyd_model_get(m->hyd, "lift_valve.dp_nominal", &dpn);
    hyd_model_get(m->hyd, "lift_valve.cd", &cd);
    hyd_fluid_def fl = hyd_model_fluid(m->hyd);
    double Amax = qn / (cd * sqrt(2 * dpn / fl.density));
    lsim_out o;
    lsim_outputs(&s, t, y, &o);
    const double x_start = o.x[0];
    double qsum = 0;
    const int nsamp = 2000;
    for (int i = 1; i <= nsamp; ++i) {
        CHECK(hyd_solver_advance(sol, &t, y, 1.5 + 1e-3 * i) == HYD_OK, "advance");
        lsim_outputs(&s, t, y, &o);
        // Orifice law of the P->A edge at the spool opening and the pressure
        // drop from the pump line to the hose, with A_max from the rating.
        double p_hose = y[s.ihose[0][0]];
        qsum += hyd_orifice_flow(&fl, cd, o.u[0] * Amax, o.p_pump - p_hose, NULL, NULL);
    }
    double qA = qsum / nsamp;
    double vmean = (o.x[0] - x_start) / (1e-3 * nsamp);
    double AA, AB, st;
    hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &AA, &AB, &st);
    CHECK(vmean > 0.005, "lifting: v = %g", vmean);
    CHECK_REL(vmean * AA, qA, 0.01);
    // The metering edge limits it: below the pump's maximum.
    double qmax;
    hyd_model_get(m->hyd, "pump.q_max", &qmax);
    CHECK(qA < 0.9 * qmax, "valve-limited flow %g vs pump %g", qA, qmax);
    hyd_solver_destroy(sol);
    lsim_free(&s);
    model_free(m);
}

// docs/model.md: with the default load, static holding pressures stay well
// below the reliefs over the whole workspace, and 2000 kg can be held close in.
static double holding_pressure(const model* m, double m3, double q1, double q2, int k) {
    const double q[2] = {q1, q2};
    double G[2], r, AA, AB, st;
    lagrange_gravity(&m->mech, LAGRANGE_FULL, m3, q, G);
    crane_pin_length(&m->mech.act[k], q[k], &r);
    hyd_model_cylinder_geometry(m->hyd, m->cyl[k], &AA, &AB, &st);
    double F = G[k] / r;
    const double p_low = 0.5e6;
    return F >= 0 ? (F + p_low * AB) / AA : (p_low * AA - F) / AB;
}

static void test_sanity_targets(void) {
    model* m = load_default();
    if (!m) return;
    double relief;
    CHECK(hyd_model_get(m->hyd, "lift_relief_A.p_crack", &relief) == 0, "port relief setting");
    double worst = 0;
    for (int i = 0; i <= 30; ++i) {
        for (int k = 0; k < 2; ++k) {
            // Sweep each joint over its stroke, the other over its range.
            for (int j = 0; j <= 30; ++j) {
                double q1 = crane_joint_for_stroke(&m->mech.act[0], m->stroke[0] * i / 30.0);
                double q2 = crane_joint_for_stroke(&m->mech.act[1], m->stroke[1] * j / 30.0);
                worst = fmax(worst, holding_pressure(m, m->mech.load_mass, q1, q2, k));
            }
        }
    }
    CHECK(worst < 0.8 * relief, "worst holding pressure %.2f MPa vs relief %.2f MPa", worst * 1e-6, relief * 1e-6);
    // 2000 kg close in: lifting arm at 45 deg, end arm folded back to bring
    // the tip within ~1.5 m of the column.
    double q1 = 135 * M_PI / 180, q2 = -130 * M_PI / 180, x, z;
    crane_tip(&m->mech, q1, q2, &x, &z);
    CHECK(x < 2.0, "close in: reach %.2f m", x);
    for (int k = 0; k < 2; ++k) {
        double p = holding_pressure(m, 2000, q1, q2, k);
        CHECK(p < relief, "2000 kg close in: cylinder %d needs %.2f MPa, relief %.2f MPa", k, p * 1e-6,
              relief * 1e-6);
    }
    model_free(m);
}

// paper-typo differs measurably from paper; paper differs from full only by
// the terms it drops, which are small at the crane's speeds.
static void test_variants_on_ramp(void) {
    model* m = load_default();
    if (!m) return;
    scenario sc;
    char err[512];
    CHECK(scenario_load(CRANESIM_ASSETS "/scenarios/ramp.json", &sc, err, sizeof err) == 0, "%s", err);
    sim_trace tr[3] = {{0}, {0}, {0}};
    for (int v = 0; v < 3; ++v) {
        sim_opts o = sim_default_opts();
        o.variant = (lagrange_variant)v;
        sim_result r;
        CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr[v], NULL, NULL, &r) == 0, "%s", r.message);
    }
    double dtypo = 0, dfull = 0, pmax = 0;
    for (int i = 0; i < tr[0].nrow; ++i) {
        const double* f = tr[0].v + (size_t)i * SIM_NCOL;
        const double* p = tr[1].v + (size_t)i * SIM_NCOL;
        const double* t = tr[2].v + (size_t)i * SIM_NCOL;
        pmax = fmax(pmax, f[COL_P1A]);
        dtypo = fmax(dtypo, fabs(t[COL_P1A] - p[COL_P1A]));
        dfull = fmax(dfull, fabs(f[COL_P1A] - p[COL_P1A]));
    }
    CHECK(dtypo > 0.02 * pmax, "typo changes lift pressure by only %.3g MPa", dtypo * 1e-6);
    CHECK(dfull > 0, "full and paper identical");
    CHECK(dfull < dtypo, "full vs paper (%.3g MPa) should be smaller than the typo effect (%.3g MPa)",
          dfull * 1e-6, dtypo * 1e-6);
    for (int v = 0; v < 3; ++v) sim_trace_free(&tr[v]);
    model_free(m);
}

// The overload scenario opens port reliefs, and they hold the pressure
// within their override band (crack + override), never far above.
static void test_overload_opens_relief(void) {
    model* m = load_default();
    if (!m) return;
    scenario sc;
    char err[512];
    CHECK(scenario_load(CRANESIM_ASSETS "/scenarios/overload.json", &sc, err, sizeof err) == 0, "%s", err);
    sim_opts o = sim_default_opts();
    sim_trace tr = {0};
    sim_result r;
    CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r) == 0, "%s", r.message);
    double crack, over, tank = 1e5;
    hyd_model_get(m->hyd, "lift_relief_A.p_crack", &crack);
    hyd_model_get(m->hyd, "lift_relief_A.dp_override", &over);
    int open_rows = 0;
    double pmax = 0;
    for (int i = 0; i < tr.nrow; ++i) {
        const double* v = tr.v + (size_t)i * SIM_NCOL;
        open_rows += v[COL_RELIEF_OPEN] > 0;
        for (int k = COL_P1A; k <= COL_P2B; ++k) pmax = fmax(pmax, v[k]);
    }
    CHECK(open_rows > 100, "relief open in only %d rows", open_rows);
    CHECK(pmax > tank + crack, "peak %.2f MPa never reached the %.2f MPa relief", pmax * 1e-6, (tank + crack) * 1e-6);
    CHECK(pmax < tank + crack + 2 * over, "peak %.2f MPa beyond the relief band", pmax * 1e-6);
    sim_trace_free(&tr);
    model_free(m);
}

// Every shipped scenario runs to its end with finite values.
static void test_all_scenarios_run(void) {
    model* m = load_default();
    if (!m) return;
    DIR* d = opendir(CRANESIM_ASSETS "/scenarios");
    CHECK(d != NULL, "no scenarios folder");
    if (!d) return;
    struct dirent* e;
    int count = 0;
    while ((e = readdir(d))) {
        size_t L = strlen(e->d_name);
        if (L < 6 || strcmp(e->d_name + L - 5, ".json")) continue;
        char path[512], err[512];
        snprintf(path, sizeof path, "%s/scenarios/%s", CRANESIM_ASSETS, e->d_name);
        scenario sc;
        CHECK(scenario_load(path, &sc, err, sizeof err) == 0, "%s", err);
        // A scenario written for another shipped crane (its "model", a file
        // in assets/models: loader10_cycle) runs on that crane.
        model* own = NULL;
        if (sc.model[0]) {
            char mp[512];
            snprintf(mp, sizeof mp, "%s/models/%s", CRANESIM_ASSETS, sc.model);
            own = model_load(mp, NULL, 0, err, sizeof err);
            CHECK(own != NULL, "%s: model %s: %s", e->d_name, sc.model, err);
            if (!own) continue;
        }
        sim_opts o = sim_default_opts();
        sim_trace tr = {0};
        sim_result r;
        int rc = sim_run(own ? own : m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r);
        model_free(own);
        CHECK(rc == 0, "%s: %s", e->d_name, r.message);
        CHECK(tr.nrow > 0 && fabs(last_row(&tr)[COL_T] - sc.duration) < 1e-9, "%s ended at %g of %g s",
              e->d_name, tr.nrow ? last_row(&tr)[COL_T] : -1.0, sc.duration);
        bool finite = true;
        for (int i = 0; i < tr.nrow * SIM_NCOL; ++i) finite &= isfinite(tr.v[i]);
        CHECK(finite, "%s: non-finite values", e->d_name);
        sim_trace_free(&tr);
        ++count;
    }
    closedir(d);
    CHECK(count >= 4, "only %d scenarios shipped", count);
    model_free(m);
}

// The fused right-hand side and Jacobian (hyd_fused + lagrange_accel_fast)
// against the general ones, over random states: pressures across the whole
// range and near vacuum and the reliefs, spools either side of closed, moving
// booms over the joint ranges, for every variant. The two paths share the
// component laws but not their summation order, so they agree to rounding:
// derivatives within 1e-12 of their row's largest term, Jacobian entries
// within 1e-9 of themselves plus 1e-13 of their row's largest entry.
// A random crane state at the circuit's regime switches: angles over the
// workspace, pressures near vacuum, near the reliefs or anywhere between,
// random spools, joint rates and commands.
static void random_crane_state(lsim* s, double* y) {
    const double q0[2] = {(70 + 90 * urand01()) * M_PI / 180, (-130 + 100 * urand01()) * M_PI / 180};
    lsim_initial_state(s, q0, 0.5e6, y);
    for (int i = 0; i < s->nh; ++i) {
        if (!s->is_pressure[i]) { y[i] = 2 * urand01() - 1; continue; }
        const int r = rand() % 4;
        y[i] = r == 0 ? 1e3 + 5e4 * urand01() : r == 1 ? 24.5e6 + 2e6 * urand01() : 0.2e6 + 22e6 * urand01();
    }
    y[s->iq + 2] = 0.3 * (2 * urand01() - 1);
    y[s->iq + 3] = 0.3 * (2 * urand01() - 1);
    s->u_cmd[0] = 1.2 * (2 * urand01() - 1);
    s->u_cmd[1] = 1.2 * (2 * urand01() - 1);
}

static void test_fused_matches_general(void) {
    model* m = load_default();
    if (!m) return;
    srand(2024);
    int bad_f = 0, bad_j = 0, trials = 0;
    for (int v = 0; v < 3; ++v) {
        lsim s;
        char err[256];
        CHECK(lsim_init(&s, m, (lagrange_variant)v, 700, err, sizeof err) == 0, "%s", err);
        CHECK(s.have_fused && s.use_fused, "fused kernel refused: %s", s.fused_why);
        if (!s.have_fused) { lsim_free(&s); continue; }
        const int n = s.n;
        static double J[LSIM_MAX_STATES * LSIM_MAX_STATES], Jf[LSIM_MAX_STATES * LSIM_MAX_STATES];
        double y[LSIM_MAX_STATES], f[LSIM_MAX_STATES], ff[LSIM_MAX_STATES];
        for (int trial = 0; trial < 1000; ++trial, ++trials) {
            random_crane_state(&s, y);
            if (rand() % 3 == 0) y[s.iu[0]] = 1e-4 * (2 * urand01() - 1);
            lsim_rhs(&s, 0.0, y, f);
            lsim_rhs_fused(&s, 0.0, y, ff);
            lsim_jac(&s, 0.0, y, J);
            lsim_jac_fused(&s, 0.0, y, Jf);
            // Scale of each row's terms: |f| plus Be/V times the largest flow,
            // which the general Jacobian's own row carries (|J_ij| |y_j|).
            for (int i = 0; i < n; ++i) {
                double rs = fabs(f[i]), js = 0.0;
                for (int j = 0; j < n; ++j) {
                    rs = fmax(rs, fabs(J[i * n + j] * y[j]));
                    js = fmax(js, fabs(J[i * n + j]));
                }
                bad_f += !(fabs(ff[i] - f[i]) <= 1e-12 * rs);
                for (int j = 0; j < n; ++j) bad_j += !(fabs(Jf[i * n + j] - J[i * n + j]) <= 1e-9 * fabs(J[i * n + j]) + 1e-13 * js);
            }
        }
        lsim_free(&s);
    }
    CHECK(bad_f == 0, "%d of %d fused derivatives differ beyond rounding", bad_f, trials * 15);
    CHECK(bad_j == 0, "%d fused Jacobian entries differ", bad_j);
    model_free(m);
}

// lsim_problem sets jac_full: the solver no longer clears J before asking for
// it, so each Jacobian callback must write every entry of J itself. Prefilled
// with NaN and with zeros, J must come out bit for bit the same, on the
// standard and the load-sensing crane, through every path (fused, the fast
// kernel mapped into J, the general loops), with a joint frozen or not.
static void test_jac_writes_all(void) {
    static const char* const file[2] = {CRANESIM_ASSETS "/models/hiab031.json",
                                        CRANESIM_ASSETS "/models/hiab031_ls.json"};
    srand(99);
    for (int f = 0; f < 2; ++f) {
        char err[512];
        model* m = model_load(file[f], NULL, 0, err, sizeof err);
        CHECK(m != NULL, "%s: %s", file[f], err);
        if (!m) continue;
        lsim s;
        CHECK(lsim_init(&s, m, LAGRANGE_FULL, 500, err, sizeof err) == 0, "%s", err);
        const int n = s.n;
        const hyd_problem p = lsim_problem(&s, true);
        CHECK(p.jac_full, "%s: jac_full not set", file[f]);
        static double J0[LSIM_MAX_STATES * LSIM_MAX_STATES], Jn[LSIM_MAX_STATES * LSIM_MAX_STATES];
        double y[LSIM_MAX_STATES];
        int paths = 0, bad = 0;
        for (int path = 0; path < 3; ++path) {
            if (path == 0 && !s.have_fused) continue;
            if (path == 1 && !s.fk) continue;
            const bool fast = s.use_fast;
            s.use_fast = path == 1;
            ++paths;
            for (int trial = 0; trial < 50; ++trial) {
                random_crane_state(&s, y);
                s.frozen_q[0] = trial % 5 == 1, s.frozen_q[1] = trial % 7 == 3;
                for (int i = 0; i < n * n; ++i) J0[i] = 0.0, Jn[i] = NAN;
                if (path == 0) lsim_jac_fused(&s, 0.0, y, J0), lsim_jac_fused(&s, 0.0, y, Jn);
                else lsim_jac(&s, 0.0, y, J0), lsim_jac(&s, 0.0, y, Jn);
                for (int i = 0; i < n * n; ++i) bad += memcmp(&J0[i], &Jn[i], sizeof J0[i]) != 0;
            }
            s.frozen_q[0] = s.frozen_q[1] = 0;
            s.use_fast = fast;
        }
        CHECK(paths >= 2, "%s: only %d Jacobian paths", file[f], paths);
        CHECK(bad == 0, "%s: %d entries of J depend on what J held before", file[f], bad);
        lsim_free(&s);
        model_free(m);
    }
}

// Componentwise backward error of x as a solution of W x = b (Oettli-Prager):
//   max_i |W x - b|_i / (sum_j |W_ij| |x_j| + |b_i|).
static double backward_error(const double* W, int n, const double* x, const double* b) {
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
        double r = -b[i], sc = fabs(b[i]);
        for (int j = 0; j < n; ++j) {
            r += W[i * n + j] * x[j];
            sc += fabs(W[i * n + j] * x[j]);
        }
        worst = fmax(worst, fabs(r) / sc);
    }
    return worst;
}

// The block-eliminated W of lagrange_schur_w.c against LU with partial pivoting of the
// whole W (hyd_lu_factor, an independent code path), for random crane states
// (as above) and gh from 1e-7 s to 0.2 s. Where that LU factors W (its
// unit-blind singularity test refuses about a third of these extreme random
// W), the structured one must nearly always do so too, and the two solutions
// must agree to 1e-6 of their norm in the states' natural units (1 MPa, 0.1,
// 0.01 rad; measured: 3e-8), with a componentwise backward error
// (Oettli-Prager) below 1e-6 (measured: 2.5e-7, the same as the dense LU's
// worst: the crane's W mixes Pa, rad and rad/s). Both Jacobians (fused and
// general) have the structure the elimination relies on; a coupling between
// the two actuators' interiors, or a NaN, makes it decline (the solver then
// factors W itself).
static void test_structured_w(void) {
    model* m = load_default();
    if (!m) return;
    srand(77);
    lsim s;
    char err[256];
    CHECK(lsim_init(&s, m, LAGRANGE_FULL, 700, err, sizeof err) == 0, "%s", err);
    CHECK(s.w_layout && s.use_w, "the default crane has the structured-W layout");
    const int n = s.n;
    static double J[LSIM_MAX_STATES * LSIM_MAX_STATES], W[LSIM_MAX_STATES * LSIM_MAX_STATES],
        LU[LSIM_MAX_STATES * LSIM_MAX_STATES];
    static const double ghs[] = {1e-7, 1e-5, 1e-4, 1e-3, 1e-2, 5e-2, 0.2};
    double y[LSIM_MAX_STATES], b[LSIM_MAX_STATES], x[LSIM_MAX_STATES], xd[LSIM_MAX_STATES];
    int piv[LSIM_MAX_STATES];
    double worst_ratio = 0.0, worst = 0.0, worst_diff = 0.0;
    int declined = 0, solved = 0, dense_singular = 0;
    for (int trial = 0; trial < 600; ++trial) {
        random_crane_state(&s, y);
        memset(J, 0, sizeof J);
        if (trial % 2) lsim_jac_fused(&s, 0.0, y, J);
        else lsim_jac(&s, 0.0, y, J);
        for (size_t g = 0; g < sizeof ghs / sizeof ghs[0]; ++g) {
            const double gh = ghs[g];
            for (int i = 0; i < n * n; ++i) W[i] = (i % (n + 1) == 0) - gh * J[i];
            memcpy(LU, W, sizeof W);
            if (hyd_lu_factor(LU, n, piv) != 0) {
                ++dense_singular;
                continue;
            }
            for (int i = 0; i < n; ++i) b[i] = (2 * urand01() - 1) * (s.is_pressure[i] ? 1e6 : i >= s.iq ? 1e-2 : 0.1);
            memcpy(x, b, sizeof b);
            memcpy(xd, b, sizeof b);
            hyd_lu_solve(LU, n, piv, xd);
            if (lsim_wfactor(&s, J, gh) != 0) {
                ++declined;
                continue;
            }
            lsim_wsolve(&s, x);
            ++solved;
            const double ws = backward_error(W, n, x, b), wd = backward_error(W, n, xd, b);
            worst = fmax(worst, ws);
            worst_ratio = fmax(worst_ratio, ws / (wd + 1e-14));
            // Normwise difference in the states' natural units.
            double dmax = 0.0, xmax = 0.0;
            for (int i = 0; i < n; ++i) {
                const double sc = s.is_pressure[i] ? 1e6 : i >= s.iq ? 1e-2 : 0.1;
                dmax = fmax(dmax, fabs(x[i] - xd[i]) / sc);
                xmax = fmax(xmax, fabs(xd[i]) / sc);
            }
            worst_diff = fmax(worst_diff, dmax / xmax);
        }
    }
    printf("  structured W: %d solves, %d declined, %d W singular to the dense LU; worst backward "
           "error %.3g, worst ratio to the dense LU's %.3g, worst normwise difference %.3g\n",
           solved, declined, dense_singular, worst, worst_ratio, worst_diff);
    CHECK(worst_diff <= 1e-6, "solutions differ from the dense LU's by %.3g of their norm", worst_diff);
    CHECK(worst <= 1e-6, "componentwise backward error %.3g", worst);
    CHECK(declined <= (solved + declined) / 100, "%d of %d factorisations declined that the dense LU did",
          declined, solved + declined);
    CHECK(solved > 2000, "only %d comparisons", solved);

    // Outside its assumptions it declines.
    memset(J, 0, sizeof J);
    lsim_jac_fused(&s, 0.0, y, J);
    CHECK(lsim_wfactor(&s, J, 1e-3) == 0, "accepts the crane's own J");
    J[1 * n + 7] = 1.0; // hose A of actuator 0 <- chamber A of actuator 1
    CHECK(lsim_wfactor(&s, J, 1e-3) != 0, "declines a coupling between the actuators");
    J[1 * n + 7] = 0.0;
    J[12 * n + 13] = NAN;
    CHECK(lsim_wfactor(&s, J, 1e-3) != 0, "declines a NaN");
    lsim_free(&s);
    model_free(m);
}

// lagrange_sincos against libm: within 1 ulp-ish (2.5e-16 absolute, the
// values being <= 1) from -2pi to 2pi and at the reduction's far end.
static void test_sincos(void) {
    double worst = 0.0;
    for (int i = 0; i <= 200000; ++i) {
        const double x = i < 100000 ? -6.3 + 12.6 * i / 100000.0 : (2 * urand01() - 1) * 9.9e4;
        double s, c;
        lagrange_sincos(x, &s, &c);
        worst = fmax(worst, fmax(fabs(s - sin(x)), fabs(c - cos(x))));
    }
    CHECK(worst <= 2.5e-16, "max |error| %.3g", worst);
    double s, c;
    lagrange_sincos(1e6, &s, &c);
    CHECK(s == sin(1e6) && c == cos(1e6), "large arguments go to libm");
    lagrange_sincos(NAN, &s, &c);
    CHECK(isnan(s) && isnan(c), "NaN in, NaN out");
}

int main(int argc, char** argv) {
    RUN_TEST(test_fused_matches_general);
    RUN_TEST(test_sincos);
    RUN_TEST(test_jac_writes_all);
    RUN_TEST(test_structured_w);
    RUN_TEST(test_jacobian_matches_finite_differences);
    RUN_TEST(test_static_hold_matches_torque_balance);
    RUN_TEST(test_steady_lift_speed_matches_flow);
    RUN_TEST(test_steady_speed_is_valve_flow_over_area);
    RUN_TEST(test_sanity_targets);
    RUN_TEST(test_variants_on_ramp);
    RUN_TEST(test_overload_opens_relief);
    RUN_TEST(test_all_scenarios_run);
    TEST_MAIN_END();
}
