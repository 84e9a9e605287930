// test_chain_sim.c: the general analytic mode (chain_sim.h) against the
// closed-form two-link crane (lagrange_sim.h), an energy invariant on a
// five-body chain, and its analytic Jacobian against finite differences.
#include "chain_problem.h"
#include "chain_sim.h"
#include "engine_chain.h"
#include "engine.h"
#include "check.h"
#include "crane_chain_synth.h"
#include "crane_fixture.h"
#include "lagrange_sim.h"

#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// A few seconds moving both functions together and apart, both ways.
static void two_link_scenario(scenario* sc) {
    memset(sc, 0, sizeof *sc);
    snprintf(sc->name, sizeof sc->name, "both");
    sc->duration = 4.0;
    sc->load_mass = 500.0;
    sc->q0[0] = 100 * M_PI / 180;
    sc->q0[1] = -110 * M_PI / 180;
    const double tl[] = {0, 0.3, 1.3, 1.8, 2.8, 3.2}, ul[] = {0, 0.7, 0.7, -0.5, -0.5, 0};
    const double tj[] = {0, 0.6, 1.6, 2.2, 3.0, 3.6}, uj[] = {0, 0.6, 0.6, -0.6, -0.6, 0};
    sc->cmd[0].n = sc->cmd[1].n = 6;
    for (int i = 0; i < 6; ++i) {
        sc->cmd[0].t[i] = tl[i], sc->cmd[0].u[i] = ul[i];
        sc->cmd[1].t[i] = tj[i], sc->cmd[1].u[i] = uj[i];
    }
}

// chain_sim's commands from the scenario column named as the function.
typedef struct scn_cmds {
    const scenario* sc;
    int col[8];
} scn_cmds;
static double scn_cmd(void* user, int k, double t) {
    const scn_cmds* c = user;
    return c->col[k] < 0 ? 0.0 : scenario_command(c->sc, c->col[k], t);
}

typedef struct cmp {
    double x, p, q; // largest difference relative to the largest value of the run
    double xmax, pmax, qmax, dx, dp, dq, dE;
} cmp;

// The two-link crane through both paths with method meth (RK4 at 20 us, else 0.1 ms); the
// largest differences of strokes, chamber pressures and angles over the run.
static cmp two_link_compare(hyd_method meth, bool blocks) {
    cmp r = {0};
    scenario sc;
    two_link_scenario(&sc);
    model* m = load_model("hiab031.json");
    if (!m) return r;
    char err[256];
    lsim ls;
    CHECK(lsim_init(&ls, m, LAGRANGE_FULL, sc.load_mass, err, sizeof err) == 0, "%s", err);
    ls.scn = &sc;
    chain_sim cs;
    CHECK(m->chain.two_link, "the default model is the two-link shorthand");
    CHECK(chain_sim_init(&cs, &m->chain, m->hyd, sc.load_mass, 0.0, err, sizeof err) == 0, "%s", err);
    CHECK(cs.ndof == 2 && cs.nact == 2 && cs.nfn == 2, "sizes %d %d %d", cs.ndof, cs.nact, cs.nfn);
    scn_cmds sk = {&sc, {-1, -1, -1, -1, -1, -1, -1, -1}};
    for (int k = 0; k < cs.nfn; ++k)
        for (int c = 0; c < SCENARIO_NCMD; ++c)
            if (!strcmp(m->chain.fn[k].name, scenario_cmd_name[c])) sk.col[k] = c;
    CHECK(sk.col[0] == 0 && sk.col[1] == 1, "functions lift, jib");
    cs.cmd_fn = scn_cmd;
    cs.cmd_user = &sk;
    double* yl = calloc(LSIM_MAX_STATES, sizeof *yl);
    double* yc = calloc((size_t)cs.n, sizeof *yc);
    lsim_initial_state(&ls, sc.q0, 0.5e6, yl);
    CHECK(chain_sim_check_pose(&cs, sc.q0, err, sizeof err) == 0, "%s", err);
    CHECK(chain_sim_initial_state(&cs, sc.q0, 0.5e6, yc, err, sizeof err) == 0, "%s", err);
    for (int h = 0; h < cs.nh; ++h) CHECK_REL(yc[cs.hpos[h]], yl[ls.hpos[h]], 1e-12);
    // The closed form with its fused kernel; blocks: its split step (as the
    // engine runs Krus) against the general path's block-diagonal W, else
    // the full W on both sides (the closed form's structured elimination).
    hyd_problem pl = lsim_problem(&ls, blocks);
    hyd_problem pc = chain_sim_problem(&cs, blocks);
    hyd_solver_opts so = hyd_default_solver_opts();
    // RK4 is unstable at 0.1 ms on this circuit (its fastest mode, the hoses
    // and chambers, needs h < 2.785 / rate: both paths ring to 9 MPa
    // differences there), so at 20 us; Krus at 0.1 ms.
    so.h = meth == HYD_RK4 ? 2e-5 : 1e-4;
    hyd_solver* sl = hyd_solver_create(&pl, meth, &so);
    hyd_solver* sg = hyd_solver_create(&pc, meth, &so);
    double tl = 0, tg = 0;
    double diff[3] = {0}, peak[3] = {0};
    for (int i = 1; i <= 40; ++i) {
        const double t1 = 0.1 * i;
        CHECK(hyd_solver_advance(sl, &tl, yl, t1) == HYD_OK, "closed form failed at %g", tl);
        CHECK(hyd_solver_advance(sg, &tg, yc, t1) == HYD_OK, "general failed at %g", tg);
        lsim_out lo;
        lsim_outputs(&ls, tl, yl, &lo);
        double x[2], pA[2], pB[2], q[2];
        chain_sim_out co = {.x = x, .pA = pA, .pB = pB, .q = q};
        chain_sim_outputs(&cs, tg, yc, &co);
        for (int k = 0; k < 2; ++k) {
            diff[0] = fmax(diff[0], fabs(x[k] - lo.x[k]));
            peak[0] = fmax(peak[0], fabs(lo.x[k]));
            diff[1] = fmax(diff[1], fmax(fabs(pA[k] - lo.pA[k]), fabs(pB[k] - lo.pB[k])));
            peak[1] = fmax(peak[1], fmax(lo.pA[k], lo.pB[k]));
            diff[2] = fmax(diff[2], fabs(q[k] - lo.q[k]));
            peak[2] = fmax(peak[2], fabs(lo.q[k]));
        }
    }
    r.x = diff[0] / peak[0], r.p = diff[1] / peak[1], r.q = diff[2] / peak[2];
    r.dx = diff[0], r.dp = diff[1], r.dq = diff[2];
    r.xmax = peak[0], r.pmax = peak[1], r.qmax = peak[2];
    // The mechanical energy's change over the run: the same on both paths
    // (the chain's potential has another zero, so the changes).
    {
        double yl0[LSIM_MAX_STATES], yc0[64];
        lsim_initial_state(&ls, sc.q0, 0.5e6, yl0);
        chain_sim_initial_state(&cs, sc.q0, 0.5e6, yc0, err, sizeof err);
        const double dEl = lagrange_energy(&m->mech, sc.load_mass, yl + ls.iq, yl + ls.iq + 2) -
                           lagrange_energy(&m->mech, sc.load_mass, yl0 + ls.iq, yl0 + ls.iq + 2);
        const double dEc = chain_sim_energy(&cs, yc) - chain_sim_energy(&cs, yc0);
        printf("  mechanical energy change: closed form %.9g J, general %.9g J\n", dEl, dEc);
        r.dE = fabs(dEl - dEc) / fabs(dEl);
    }
    // The run moved both cylinders.
    lsim_out lo;
    lsim_outputs(&ls, tl, yl, &lo);
    CHECK(fabs(lo.q[0] - sc.q0[0]) > 0.05 && fabs(lo.q[1] - sc.q0[1]) > 0.05, "both joints moved: %g %g",
          lo.q[0] - sc.q0[0], lo.q[1] - sc.q0[1]);
    printf("  %s %g ms%s: general vs closed form: stroke %.3g m (%.3g rel), pressure %.3g Pa (%.3g rel), "
           "angle %.3g rad (%.3g rel)\n",
           hyd_method_name(meth), so.h * 1e3, blocks ? " (closed form: split step)" : "", r.dx, r.x, r.dp, r.p, r.dq, r.q);
    hyd_solver_destroy(sl);
    hyd_solver_destroy(sg);
    free(yl);
    free(yc);
    chain_sim_free(&cs);
    lsim_free(&ls);
    model_free(m);
    return r;
}

// RK4 (explicit: the Jacobians do not enter): the same trajectory to rounding.
// The 1e-9 bound is far above rounding (1e-15 measured), far below any
// modelling difference (a lever arm off by 1e-6 of itself fails it).
static void test_two_link_rk4(void) {
    const cmp r = two_link_compare(HYD_RK4, false);
    CHECK(r.x < 1e-9 && r.p < 1e-9 && r.q < 1e-9, "relative differences %.3g %.3g %.3g", r.x, r.p, r.q);
    CHECK(r.dE < 1e-9, "mechanical energy changes differ by %.3g relative", r.dE);
}

// Krus at 0.1 ms with the full W on both sides: the Jacobians differ only
// by the general path's differences of the inverse dynamics (1e-10 of a
// row), which a W-method's result depends on at second order: close to
// rounding. The closed form's split step (block-diagonal W, the mechanics
// at the step's midpoint) against the general path with the same
// block-diagonal W (what the engine runs on each): the same W-method to
// 5e-11 (measured), the midpoint mechanics' first-order carry being exact
// to that level here.
static void test_two_link_krus(void) {
    cmp r = two_link_compare(HYD_KRUS, false);
    CHECK(r.x < 1e-7 && r.p < 1e-7 && r.q < 1e-7, "relative differences %.3g %.3g %.3g", r.x, r.p, r.q);
    r = two_link_compare(HYD_KRUS, true);
    CHECK(r.x < 1e-9 && r.p < 1e-9 && r.q < 1e-9, "relative differences %.3g %.3g %.3g", r.x, r.p, r.q);
}

// The five-body chain of the tests: a column, a lifting arm, an end arm, a
// jib and a telescopic extension in the jib, each moved by its own cylinder.
static int five_body(bool slew_free, crane_chain* cc, hyd_model** hm, double* q0) {
    char err[256];
    const int rc = crane_chain_synthetic("RRRP", slew_free, cc, hm, q0, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    return rc;
}

// Moving every function at once: sines of different periods.
static double wave(void* user, int k, double t) {
    (void)user;
    return 0.6 * sin(2 * M_PI * t / (3.0 + k));
}

// Energy: the cylinders replaced by ideal springs along their pins, F_k =
// F0_k - K_k x_k, conservative (potential -F0 x + K x^2 / 2): E_mech -
// sum (F0 x - K x^2 / 2) stays constant. The springs hold the start pose
// (F0 from its chamber pressures), each as stiff as its load over 50 mm;
// started with every joint moving, the column slewing: all five bodies
// swing, the extension slides.
static void test_energy_ideal_forces(void) {
    crane_chain cc;
    hyd_model* hm;
    double qb[4];
    if (five_body(true, &cc, &hm, qb)) return;
    chain_sim cs;
    char err[256];
    CHECK(chain_sim_init(&cs, &cc, hm, 100.0, 0.0, err, sizeof err) == 0, "%s", err);
    CHECK(cs.ndof == 5, "ndof %d", cs.ndof);
    const double q0[5] = {0.0, qb[0], qb[1], qb[2], qb[3]};
    double* y = calloc((size_t)cs.n, sizeof *y);
    CHECK(chain_sim_initial_state(&cs, q0, 0.5e6, y, err, sizeof err) == 0, "%s", err);
    double F0[4], K[4], x[4];
    chain_sim_out o = {.x = x};
    chain_sim_outputs(&cs, 0.0, y, &o);
    for (int k = 0; k < 4; ++k) {
        double AA, AB, st;
        hyd_model_cylinder_geometry(hm, cc.act[k].cyl, &AA, &AB, &st);
        const double Feq = y[cs.ipA[k]] * AA - y[cs.ipB[k]] * AB;
        K[k] = fabs(Feq) / 0.05;
        F0[k] = Feq + K[k] * x[k];
    }
    cs.ideal_F = F0;
    cs.ideal_K = K;
    const double qd0[5] = {0.3, 0.2, -0.3, 0.4, 0.1};
    for (int i = 0; i < 5; ++i) y[cs.iq + 5 + i] = qd0[i];
    double E0 = 0, Emax = 0, Kmax = 0, travel[5] = {0};
    hyd_problem p = chain_sim_problem(&cs, false);
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = 1e-3;
    hyd_solver* s = hyd_solver_create(&p, HYD_RK4, &so);
    double t = 0;
    for (int i = 0; i <= 100; ++i) {
        if (i) CHECK(hyd_solver_advance(s, &t, y, 0.1 * i) == HYD_OK, "advance at %g", t);
        chain_sim_outputs(&cs, t, y, &o);
        double E = chain_sim_energy(&cs, y);
        Kmax = fmax(Kmax, chain_kinetic_energy(cs.ch, cs.ws));
        for (int k = 0; k < 4; ++k) E -= F0[k] * x[k] - 0.5 * K[k] * x[k] * x[k];
        for (int j = 0; j < 5; ++j) travel[j] = fmax(travel[j], fabs(y[cs.iq + j] - q0[j]));
        if (!i) E0 = E;
        Emax = fmax(Emax, fabs(E - E0));
    }
    // Relative to the largest kinetic energy, the energy that moved.
    CHECK(Emax / Kmax < 1e-6, "energy drift %.3g J of %.3g J kinetic (%.3g relative)", Emax, Kmax, Emax / Kmax);
    for (int j = 0; j < 5; ++j) CHECK(travel[j] > 0.01, "joint %d moved only %g", j, travel[j]);
    printf("  energy drift %.3g relative over 10 s (kinetic up to %.3g J)\n", Emax / Kmax, Kmax);
    hyd_solver_destroy(s);
    free(y);
    chain_sim_free(&cs);
    crane_chain_free(&cc);
    hyd_model_free(hm);
}

// The five-body chain with its circuit, every function moving, 10 s of
// Krus at 0.1 ms (the analytic Jacobian in every W): no blow-up, every
// joint moved, and the Jacobian at t = 5 s against central differences.
static void test_chain_run_and_jacobian(void) {
    crane_chain cc;
    hyd_model* hm;
    double q0[4];
    if (five_body(false, &cc, &hm, q0)) return;
    chain_sim cs;
    char err[256];
    CHECK(chain_sim_init(&cs, &cc, hm, 100.0, 0.0, err, sizeof err) == 0, "%s", err);
    cs.cmd_fn = wave;
    const int n = cs.n;
    double* y = calloc((size_t)n, sizeof *y);
    CHECK(chain_sim_check_pose(&cs, q0, err, sizeof err) == 0, "%s", err);
    CHECK(chain_sim_initial_state(&cs, q0, 0.5e6, y, err, sizeof err) == 0, "%s", err);
    // The start is one the circuit can hold: every chamber below the reliefs.
    for (int k = 0; k < 4; ++k)
        CHECK(y[cs.ipA[k]] < 20e6 && y[cs.ipB[k]] < 20e6, "act %d starts at %g / %g Pa", k, y[cs.ipA[k]], y[cs.ipB[k]]);
    // At rest at t = 0 with closed valves: q'' = 0 (the equilibrium holds).
    double* f = calloc((size_t)n, sizeof *f);
    cs.cmd_fn = NULL;
    chain_sim_rhs(&cs, 0.0, y, f);
    for (int i = 0; i < 4; ++i) CHECK(fabs(f[cs.iq + 4 + i]) < 1e-6, "q''[%d] = %g at the start", i, f[cs.iq + 4 + i]);
    cs.cmd_fn = wave;
    hyd_problem p = chain_sim_problem(&cs, true); // as the engine's fixed-step runs
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = 1e-4;
    hyd_solver* s = hyd_solver_create(&p, HYD_KRUS, &so);
    double t = 0, travel[4] = {0};
    for (int i = 1; i <= 100; ++i) {
        const int rc = hyd_solver_advance(s, &t, y, 0.1 * i);
        CHECK(rc == HYD_OK, "advance failed at %g (%d)", t, rc);
        if (rc) break;
        for (int k = 0; k < 4; ++k) travel[k] = fmax(travel[k], fabs(y[cs.iq + k] - q0[k]));
        if (i == 50) {
            // Jacobian at t = 5 s against central differences of f.
            double* Ja = calloc((size_t)n * n, sizeof *Ja);
            double* fp = calloc((size_t)n, sizeof *fp);
            double* fm = calloc((size_t)n, sizeof *fm);
            double* yy = calloc((size_t)n, sizeof *yy);
            CHECK(chain_sim_jac(&cs, t, y, Ja) == 0, "jac");
            double worst = 0;
            int wi = 0, wj = 0;
            for (int j = 0; j < n; ++j) {
                memcpy(yy, y, (size_t)n * sizeof *yy);
                const double h = 1e-6 * (1.0 + fabs(y[j]));
                yy[j] = y[j] + h;
                chain_sim_rhs(&cs, t, yy, fp);
                yy[j] = y[j] - h;
                chain_sim_rhs(&cs, t, yy, fm);
                for (int i2 = 0; i2 < n; ++i2) {
                    double rowmax = 0;
                    for (int c = 0; c < n; ++c) rowmax = fmax(rowmax, fabs(Ja[i2 * n + c]) * (1.0 + fabs(y[c])));
                    const double fd = (fp[i2] - fm[i2]) / (2 * h);
                    // Scaled by the row's largest term |J_ic| (1 + |y_c|): a
                    // change of 1e-6 in every state moves f_i by about that.
                    const double e = fabs(Ja[i2 * n + j] - fd) * (1.0 + fabs(y[j])) / (rowmax + 1e-300);
                    if (e > worst) worst = e, wi = i2, wj = j;
                }
            }
            CHECK(worst < 1e-6, "Jacobian entry (%d, %d): %.6g analytic vs differences, %.3g of its row", wi, wj,
                  Ja[wi * n + wj], worst);
            printf("  Jacobian vs central differences at t = 5 s: worst %.3g of its row (n = %d)\n", worst, n);
            free(Ja), free(fp), free(fm), free(yy);
        }
    }
    for (int k = 0; k < 4; ++k) CHECK(travel[k] > 0.02, "joint %d moved only %g", k, travel[k]);
    for (int i = 0; i < n; ++i) CHECK(isfinite(y[i]), "state %d not finite", i);
    hyd_solver_destroy(s);
    free(y);
    free(f);
    chain_sim_free(&cs);
    crane_chain_free(&cc);
    hyd_model_free(hm);
}

typedef struct csv_rows {
    FILE* ref;    // the previous main's CSV, every 100th row
    long row;     // rows seen
    long checked; // rows compared
    long differ;  // of them, not byte-identical
    char first[600];
} csv_rows;

static int compare_row(void* user, const double* row) {
    csv_rows* c = user;
    if (c->row++ % 100) return 0;
    char* got = NULL;
    size_t n = 0;
    FILE* m = open_memstream(&got, &n);
    sim_csv_row(m, row, SIM_NCOL_BASE);
    fclose(m);
    char want[1024];
    if (!fgets(want, sizeof want, c->ref)) want[0] = 0;
    ++c->checked;
    if (strcmp(got, want) && !c->differ++) snprintf(c->first, sizeof c->first, "got  %swant %s", got, want);
    free(got);
    return 0;
}

// The default scripted run (hiab031, ramp, Krus 0.1 ms, rows at 1 ms) takes
// the closed form's fast path unchanged: its CSV rows byte-identical to
// those of the previous main (b752397, `cranesim run`, every 100th row
// kept in tests/lagrange/data).
static void test_default_run_unchanged(void) {
    scenario sc;
    model* m = load_crane("ramp", &sc);
    if (!m) return;
    csv_rows c = {fopen(CRANESIM_TESTDATA "/ramp_b752397_every100.csv", "r"), 0, 0, 0, ""};
    CHECK(c.ref != NULL, "reference CSV");
    if (!c.ref) return;
    char hdr[1024];
    CHECK(fgets(hdr, sizeof hdr, c.ref) != NULL, "header");
    sim_opts o = sim_default_opts();
    sim_result res;
    CHECK(sim_run(m, &sc, &o, compare_row, &c, NULL, NULL, NULL, &res) == 0, "%s", res.message);
    CHECK(res.fused && res.split, "the fast path ran (fused %d, split %d)", res.fused, res.split);
    CHECK(c.checked == 201 && c.differ == 0, "%ld of %ld rows differ; first:\n%s", c.differ, c.checked, c.first);
    fclose(c.ref);
    model_free(m);
}

// The general path refuses the paper's equations, which are the two-link
// crane's, with one line that says so.
static void test_general_refuses_paper(void) {
    scenario sc;
    model* m = load_crane("ramp", &sc);
    if (!m) return;
    sim_opts o = sim_default_opts();
    o.variant = LAGRANGE_PAPER;
    engine_sink k = {.t_end = 1.0};
    sim_result res;
    memset(&res, 0, sizeof res);
    CHECK(engine_chain_run(m, &sc, &o, &k, &res) == SIM_REFUSED, "refused");
    CHECK(strstr(res.message, "two-link") && !strchr(res.message, '\n'), "message: %s", res.message);
    model_free(m);
}

typedef struct rows_seen {
    long n;
    double x0[2], xmin[2], xmax[2];
} rows_seen;

static int see_row(void* user, const double* row) {
    rows_seen* r = user;
    for (int k = 0; k < 2; ++k) {
        const double x = row[k == 0 ? COL_X1 : COL_X2];
        if (!r->n) r->x0[k] = r->xmin[k] = r->xmax[k] = x;
        r->xmin[k] = fmin(r->xmin[k], x), r->xmax[k] = fmax(r->xmax[k], x);
    }
    ++r->n;
    return 0;
}

// A four-function chain (lifting arm, knuckle, jib, extension) through the
// engine (engine_run on the lagrange backend: the general path, as the
// chain is not the two-link shorthand), commanded by a scenario whose
// columns name the functions; a column naming no function is refused with
// one line naming the file and the column.
static void test_engine_named_functions(void) {
    model* m = load_model("hiab031.json");
    if (!m) return;
    crane_chain cc;
    hyd_model* hm;
    double q0[4];
    if (five_body(false, &cc, &hm, q0)) return;
    // The model's chain and circuit swapped for the synthetic ones (and back).
    const crane_chain keep_cc = m->chain;
    hyd_model* keep_hm = m->hyd;
    m->chain = cc;
    m->hyd = hm;
    char js[1024], err[256];
    snprintf(js, sizeof js,
             "{\"name\": \"fns\", \"duration\": 2, \"load_mass\": 100,"
             " \"initial\": {\"q1_deg\": %.9g, \"q2_deg\": %.9g},"
             " \"commands\": {\"f1\": [[0, 0], [0.2, 0.5], [1, 0.5], [1.2, 0]],"
             " \"f2\": [[0, 0], [0.3, -0.5], [1.5, -0.5], [1.7, 0]],"
             " \"f3\": [[0, 0.4]], \"f4\": [[0, -0.4]]}}",
             q0[0] * 180 / M_PI, q0[1] * 180 / M_PI);
    cJSON* root = cJSON_Parse(js);
    scenario sc;
    CHECK(scenario_from_json(root, "fns.json", &sc, err, sizeof err) == 0, "%s", err);
    cJSON_Delete(root);
    CHECK(scenario_ncmd(&sc) == 7 && scenario_find_command(&sc, "f3") == 5, "columns %d", scenario_ncmd(&sc));
    sim_opts o = sim_default_opts();
    o.no_step_probe = true;
    rows_seen r = {0};
    engine_sink k = {.row = see_row, .user = &r, .rows = true, .t_end = 2.0};
    sim_result res;
    memset(&res, 0, sizeof res);
    CHECK(engine_run(m, &sc, &o, &k, &res) == SIM_OK, "%s", res.message);
    CHECK(r.n == 2001, "rows %ld", r.n);
    // f1 raises its cylinder (+0.5), f2 retracts its own (-0.5).
    CHECK(r.xmax[0] - r.x0[0] > 0.02 && r.x0[1] - r.xmin[1] > 0.02, "x1 up %g, x2 in %g", r.xmax[0] - r.x0[0],
          r.x0[1] - r.xmin[1]);
    // The same scenario with a column the chain has no function for.
    snprintf(sc.cmd_name[6], sizeof sc.cmd_name[6], "winch");
    memset(&res, 0, sizeof res);
    CHECK(engine_run(m, &sc, &o, &k, &res) == SIM_REFUSED, "refused");
    CHECK(strstr(res.message, "fns.json: commands.winch: unknown field 'winch'") && strstr(res.message, "f4"),
          "message: %s", res.message);
    m->chain = keep_cc;
    m->hyd = keep_hm;
    crane_chain_free(&cc);
    hyd_model_free(hm);
    model_free(m);
}

// The stepped engine's functions are the model chain's (lift, jib) and the
// slew; their commands by function land on the valves engine_set_commands
// drives; --variant general steps the general formulation
// (engine_chain_step.c; test_engine_chain_step.c tests it further).
static void test_engine_function_commands(void) {
    model* m = load_model("hiab031.json");
    if (!m) return;
    sim_opts o = sim_default_opts();
    o.no_step_probe = true;
    const double q0[2] = {100 * M_PI / 180, -110 * M_PI / 180};
    char err[512];
    engine* e = engine_create(m, &o, q0, 0.0, 500.0, err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (!e) return;
    CHECK(engine_nfunction(e) == 3, "functions %d", engine_nfunction(e));
    CHECK(!strcmp(engine_function_name(e, 0), "lift") && !strcmp(engine_function_name(e, 1), "jib") &&
              !strcmp(engine_function_name(e, 2), "slew") && engine_function_name(e, 3) == NULL,
          "names");
    const double u[3] = {0.4, -0.3, 0.2};
    CHECK(engine_set_function_commands(e, u, 3, err, sizeof err) == 0, "%s", err);
    CHECK(engine_advance(e, 0.01) == 0, "%s", engine_error(e));
    double row[SIM_NCOL];
    engine_row(e, row);
    CHECK(row[COL_U1_CMD] == 0.4 && row[COL_U2_CMD] == -0.3, "commands %g %g", row[COL_U1_CMD], row[COL_U2_CMD]);
    engine_destroy(e);
    o.variant = LAGRANGE_GENERAL;
    e = engine_create(m, &o, q0, 0.0, 500.0, err, sizeof err);
    CHECK(e != NULL, "general stepped: %s", err);
    if (e) {
        CHECK(engine_nfunction(e) == 3 && !(engine_caps(e) & ENGINE_CAP_TWO_LINK), "general: %d functions",
              engine_nfunction(e));
        CHECK(engine_set_function_commands(e, u, 3, err, sizeof err) == 0, "%s", err);
        CHECK(engine_advance(e, 0.01) == 0, "%s", engine_error(e));
        engine_row(e, row);
        CHECK(row[COL_U1_CMD] == 0.4 && row[COL_U2_CMD] == -0.3, "general commands %g %g", row[COL_U1_CMD],
              row[COL_U2_CMD]);
    }
    engine_destroy(e);
    model_free(m);
}

// Eight functions (booms, knuckles, three extensions, a knuckle on an
// extension) on a slewing column: the start holds (q'' = 0, the slew no
// actuator moves carries no gravity load), 2 s of Krus at 0.1 ms with the
// block W and every function moving stays finite and moves every joint.
static void test_eight_functions_slewing(void) {
    crane_chain cc;
    hyd_model* hm;
    double qb[8];
    char err[256];
    CHECK(crane_chain_synthetic("RRRPRPRP", true, &cc, &hm, qb, err, sizeof err) == 0, "%s", err);
    if (!hm) return;
    chain_sim cs;
    CHECK(chain_sim_init(&cs, &cc, hm, 50.0, 0.0, err, sizeof err) == 0, "%s", err);
    CHECK(cs.ndof == 9 && cs.nact == 8 && cs.nfn == 8, "sizes %d %d %d", cs.ndof, cs.nact, cs.nfn);
    double q0[9] = {0.3};
    for (int i = 0; i < 8; ++i) q0[i + 1] = qb[i];
    double* y = calloc((size_t)cs.n, sizeof *y);
    double* f = calloc((size_t)cs.n, sizeof *f);
    CHECK(chain_sim_check_pose(&cs, q0, err, sizeof err) == 0, "%s", err);
    CHECK(chain_sim_initial_state(&cs, q0, 0.5e6, y, err, sizeof err) == 0, "%s", err);
    chain_sim_rhs(&cs, 0.0, y, f);
    for (int i = 0; i < 9; ++i) CHECK(fabs(f[cs.iq + 9 + i]) < 1e-6, "q''[%d] = %g at the start", i, f[cs.iq + 9 + i]);
    for (int k = 0; k < 8; ++k) CHECK(y[cs.ipA[k]] < 20e6 && y[cs.ipB[k]] < 20e6, "act %d start pressure", k);
    cs.cmd_fn = wave;
    hyd_problem p = chain_sim_problem(&cs, true);
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = 1e-4;
    so.jac_every = 10;
    hyd_solver* sol = hyd_solver_create(&p, HYD_KRUS, &so);
    double t = 0;
    CHECK(hyd_solver_advance(sol, &t, y, 2.0) == HYD_OK, "advance failed at %g", t);
    for (int i = 0; i < cs.n; ++i) CHECK(isfinite(y[i]), "state %d", i);
    for (int i = 1; i < 9; ++i) CHECK(fabs(y[cs.iq + i] - q0[i]) > 1e-3, "joint %d moved %g", i, y[cs.iq + i] - q0[i]);
    hyd_solver_destroy(sol);
    free(y), free(f);
    chain_sim_free(&cs);
    crane_chain_free(&cc);
    hyd_model_free(hm);
}

// A chain model file (tests/world/data/chain_3boom_ext.json: three booms and
// a telescopic extension, each with its own cylinder and valve section)
// through engine_run on the analytic backend: the general path, every
// function commanded by its name, one after the other (together, the
// lightly loaded extension takes the pump's flow and the lift sinks: no
// load-holding valve in this circuit); its rows carry the chain's own
// columns after the base ones, and each function's stroke moves the way its
// command says in its window.
typedef struct chain_rows {
    const crane_chain* cc;
    long n;
    double* at[5]; // the chain columns at t = 0, 0.75, 1.5, 2.25, 3 s
} chain_rows;

static int keep_chain_row(void* user, const double* row) {
    chain_rows* r = user;
    if (r->n % 750 == 0 && r->n / 750 < 5)
        memcpy(r->at[r->n / 750], row + SIM_NCOL_BASE, (size_t)r->cc->ncol * sizeof *row);
    ++r->n;
    return 0;
}

static void test_chain_model_file(void) {
    char err[512];
    model* m = model_load(CRANESIM_TESTDATA "/../../world/data/chain_3boom_ext.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    CHECK(!m->chain.two_link && m->chain.nfn == 4 && m->chain.ncol == 5 * m->chain.nact + 2 * 4 + 2 * 4,
          "a chain of %d functions, %d columns", m->chain.nfn, m->chain.ncol);
    const char* js = "{\"name\": \"each\", \"duration\": 3, \"load_mass\": 100,"
                     " \"initial\": {\"q1_deg\": 110, \"q2_deg\": -90},"
                     " \"commands\": {\"lift\": [[0, 0], [0.1, 0.5], [0.6, 0.5], [0.7, 0]],"
                     " \"jib\": [[0.75, 0], [0.85, -0.5], [1.35, -0.5], [1.45, 0]],"
                     " \"jib2\": [[1.5, 0], [1.6, 0.5], [2.1, 0.5], [2.2, 0]],"
                     " \"ext\": [[2.25, 0], [2.35, 0.5], [2.85, 0.5], [2.95, 0]]}}";
    const double sign[4] = {1, -1, 1, 1};
    cJSON* root = cJSON_Parse(js);
    scenario sc;
    CHECK(scenario_from_json(root, "each.json", &sc, err, sizeof err) == 0, "%s", err);
    cJSON_Delete(root);
    sim_opts o = sim_default_opts();
    o.no_step_probe = true;
    chain_rows r = {&m->chain, 0, {NULL}};
    for (int i = 0; i < 5; ++i) r.at[i] = calloc((size_t)m->chain.ncol, sizeof(double));
    engine_sink k = {.row = keep_chain_row, .user = &r, .rows = true, .t_end = 3.0};
    sim_result res;
    memset(&res, 0, sizeof res);
    const int rc = engine_run(m, &sc, &o, &k, &res);
    CHECK(rc == SIM_OK, "%s", res.message);
    if (rc == SIM_OK) {
        CHECK(r.n == 3001, "rows %ld", r.n);
        // x_<actuator> is the first of its five columns; actuator a is
        // function a's here (checked).
        for (int a = 0; a < 4; ++a) {
            CHECK(m->chain.act[a].function == a, "actuator %d's function", a);
            const double dx = r.at[a + 1][5 * a] - r.at[a][5 * a];
            CHECK(dx * sign[a] > 0.01, "actuator %s in its window (command %+g): stroke moved %g m",
                  m->chain.act[a].name, 0.5 * sign[a], dx);
        }
    }
    for (int i = 0; i < 5; ++i) free(r.at[i]);
    model_free(m);
}

typedef struct finite_rows {
    int ncol;
    long n, bad;
} finite_rows;

static int check_finite_row(void* user, const double* row) {
    finite_rows* r = user;
    for (int i = 0; i < SIM_NCOL_BASE + r->ncol; ++i) r->bad += !isfinite(row[i]);
    ++r->n;
    return 0;
}

// The eight-function, ten-link model file (tests/world/data) runs headless
// on the analytic backend's general path, every function commanded by name
// at once for 2 s: every row finite, with every function's columns.
static void test_eight_function_model_file(void) {
    char err[512];
    model* m = model_load(CRANESIM_TESTDATA "/../../world/data/chain_8fn_10link.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    const crane_chain* cc = &m->chain;
    CHECK(cc->nfn == 8 && cc->nbody == 10 && cc->ncol == 5 * cc->nact + 2 * cc->nfn + 2 * crane_chain_ndof(cc),
          "%d functions, %d bodies, %d columns", cc->nfn, cc->nbody, cc->ncol);
    scenario sc;
    memset(&sc, 0, sizeof sc);
    snprintf(sc.file, sizeof sc.file, "eight.json");
    sc.duration = 2.0;
    sc.load_mass = 50.0;
    sc.q0[0] = 110 * M_PI / 180, sc.q0[1] = -90 * M_PI / 180;
    sc.ncmd = SCENARIO_NCMD;
    for (int f = 0; f < cc->nfn; ++f) {
        int k = scenario_find_command(&sc, cc->fn[f].name);
        if (k < 0) k = sc.ncmd++, snprintf(sc.cmd_name[k], sizeof sc.cmd_name[k], "%s", cc->fn[f].name);
        sc.cmd[k].n = 2;
        sc.cmd[k].t[0] = 0.0, sc.cmd[k].t[1] = 0.5;
        sc.cmd[k].u[0] = 0.0, sc.cmd[k].u[1] = (f % 2) ? -0.3 : 0.3;
    }
    sim_opts o = sim_default_opts();
    o.no_step_probe = true;
    finite_rows r = {cc->ncol, 0, 0};
    engine_sink k = {.row = check_finite_row, .user = &r, .rows = true, .t_end = 2.0};
    sim_result res;
    memset(&res, 0, sizeof res);
    CHECK(engine_run(m, &sc, &o, &k, &res) == SIM_OK, "%s", res.message);
    CHECK(r.n == 2001 && r.bad == 0, "%ld rows, %ld values not finite", r.n, r.bad);
    model_free(m);
}

// The Jacobian events (chain_problem_events) take the strokes and rates that
// f's kinematics left in hd when f was last evaluated at the same (t, q, q')
// (chain_sim_inputs_at), else run the kinematics themselves: both ways give
// the same inputs bit for bit, and a different q, q' or t is never served
// from the last evaluation. On the slewing 8-function chain in motion.
static void events_inputs(chain_problem* cp, double t, const double* y, double* x, double* v, int nc) {
    chain_problem_events(cp, t, y);
    memcpy(x, cp->x, (size_t)nc * sizeof *x);
    memcpy(v, cp->v, (size_t)nc * sizeof *v);
}

static void test_events_reuse_kinematics(void) {
    crane_chain cc;
    hyd_model* hm;
    double qb[8];
    char err[256];
    CHECK(crane_chain_synthetic("RRRPRPRP", true, &cc, &hm, qb, err, sizeof err) == 0, "%s", err);
    if (!hm) return;
    chain_sim cs;
    CHECK(chain_sim_init(&cs, &cc, hm, 50.0, 0.0, err, sizeof err) == 0, "%s", err);
    double q0[9] = {0.3};
    for (int i = 0; i < 8; ++i) q0[i + 1] = qb[i];
    const int n = cs.n, nc = hyd_model_ncylinder(hm);
    double* buf = calloc(3 * (size_t)n + 8 * (size_t)nc, sizeof *buf);
    double *y = buf, *y2 = y + n, *f = y2 + n;
    double *xa = f + n, *va = xa + nc, *xb = va + nc, *vb = xb + nc, *xc = vb + nc, *vc = xc + nc, *xd = vc + nc,
           *vd = xd + nc;
    CHECK(chain_sim_initial_state(&cs, q0, 0.5e6, y, err, sizeof err) == 0, "%s", err);
    // The start state writes hd's inputs outside an evaluation: no reuse after it.
    chain_sim_rhs(&cs, 0.0, y, f);
    CHECK(chain_sim_inputs_at(&cs, 0.0, y), "f's inputs at the start not recognised");
    CHECK(chain_sim_initial_state(&cs, q0, 0.5e6, y, err, sizeof err) == 0, "%s", err);
    CHECK(!chain_sim_inputs_at(&cs, 0.0, y), "inputs reused across chain_sim_initial_state");
    cs.cmd_fn = wave;
    // In motion: 0.3 s of Krus from the start.
    hyd_problem p = chain_sim_problem(&cs, true);
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = 1e-4;
    hyd_solver* sol = hyd_solver_create(&p, HYD_KRUS, &so);
    double t = 0;
    CHECK(sol && hyd_solver_advance(sol, &t, y, 0.3) == HYD_OK, "advance failed at %g", t);
    hyd_solver_destroy(sol);
    double vmax = 0.0;
    for (int i = 0; i < cs.ndof; ++i) vmax = fmax(vmax, fabs(y[cs.iq + cs.ndof + i]));
    CHECK(vmax > 1e-3, "the chain moves (largest joint rate %g)", vmax);
    // y2: every q and q' a little off y's.
    memcpy(y2, y, (size_t)n * sizeof *y);
    for (int i = 0; i < 2 * cs.ndof; ++i) y2[cs.iq + i] += 1e-3 * (1 + i % 3);
    chain_problem cp;
    hyd_problem prob;
    CHECK(chain_problem_init(&cp, &cs, false, &prob) == 0, "chain_problem_init");
    // Fresh: the last evaluation elsewhere, so the events run the kinematics.
    chain_sim_rhs(&cs, t, y2, f);
    CHECK(!chain_sim_inputs_at(&cs, t, y), "inputs of y2 taken for y");
    events_inputs(&cp, t, y, xa, va, nc);
    chain_sim_rhs(&cs, t, y, f);
    CHECK(!chain_sim_inputs_at(&cs, t, y2), "inputs of y taken for y2");
    events_inputs(&cp, t, y2, xc, vc, nc);
    // Reused: f at the same (t, y) just before, as the solver calls them.
    chain_sim_rhs(&cs, t, y, f);
    CHECK(chain_sim_inputs_at(&cs, t, y), "f's inputs at (t, y) not recognised");
    CHECK(!chain_sim_inputs_at(&cs, t + 1e-4, y), "inputs of t taken for another t");
    events_inputs(&cp, t, y, xb, vb, nc);
    chain_sim_rhs(&cs, t, y2, f);
    events_inputs(&cp, t, y2, xd, vd, nc);
    CHECK(!memcmp(xa, xb, (size_t)nc * sizeof *xa) && !memcmp(va, vb, (size_t)nc * sizeof *va),
          "strokes or rates at y differ between the reused and the fresh kinematics");
    CHECK(!memcmp(xc, xd, (size_t)nc * sizeof *xc) && !memcmp(vc, vd, (size_t)nc * sizeof *vc),
          "strokes or rates at y2 differ between the reused and the fresh kinematics");
    double dx = 0.0;
    for (int k = 0; k < cs.nact; ++k) dx = fmax(dx, fabs(xa[cs.acyl[k]] - xc[cs.acyl[k]]));
    CHECK(dx > 1e-5, "y and y2 give the same strokes (largest difference %g m): the test cannot tell them apart", dx);
    printf("  %d actuators (slew rack: %s), largest stroke difference y2 - y %.3g mm\n", cs.nact,
           cs.rack >= 0 ? "yes" : "no", dx * 1e3);
    chain_problem_free(&cp);
    free(buf);
    chain_sim_free(&cs);
    crane_chain_free(&cc);
    hyd_model_free(hm);
}

int main(int argc, char** argv) {
    RUN_TEST(test_events_reuse_kinematics);
    RUN_TEST(test_eight_function_model_file);
    RUN_TEST(test_chain_model_file);
    RUN_TEST(test_eight_functions_slewing);
    RUN_TEST(test_engine_function_commands);
    RUN_TEST(test_engine_named_functions);
    RUN_TEST(test_default_run_unchanged);
    RUN_TEST(test_general_refuses_paper);
    RUN_TEST(test_two_link_rk4);
    RUN_TEST(test_two_link_krus);
    RUN_TEST(test_energy_ideal_forces);
    RUN_TEST(test_chain_run_and_jacobian);
    TEST_MAIN_END();
}
