// test_ode_engine_chain.c: the ode backend's scripted runs of chain models
// (engine_run through the ODE chain world, engine_ode_chain.c), against the
// analytic mode's general path on the same model and scenario:
// - chain_3boom_ext.json (three booms and a telescopic extension, four
//   functions) on a scenario moving every function: stroke RMS <= 0.5 mm on
//   every actuator, chamber pressure RMS <= 1 % of its peak (issue 26);
//   every actuator read from the chain's own columns after the backend's
//   channels, whose base columns x1, x2 are its first two;
// - chain_8fn_10link.json (8 functions, 10 bodies) through `cranesim run`
//   on both backends at the default solver: exit 0, every row finite; and
//   through engine_run on the ode backend: every function moves its
//   cylinders; its ext1/ext2 pair (one valve) against the analytic mode
//   within the bounds; on the analytic backend: Krus 0.1 ms against
//   ROS34PW2, and a chamber below absolute zero for 10 ms fails the run;
// - the seal friction held in ODE's solver holds that pair with its valves
//   closed, and a slider's rate on a turning boom is its position's rate;
// - refusals in one line: an adaptive solver, and the stepped engine of a
//   chain model in the sandbox (it runs the validation world).
// The two-link default's ODE runs keep the two-link world: its rows are
// byte-identical to the previous main's (ramp, every 100th row kept).
#include "check.h"
#include "app/cli_util.h"
#include "engine.h"
#include "model.h"
#include "ode_chain.h"
#include "scenario.h"
#include <stdbool.h>
#include "sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define DATA CRANESIM_TESTDATA
#define CHAIN_3BOOM DATA "/chain_3boom_ext.json"
#define CHAIN_3BOOM_SCN DATA "/chain_3boom_ext_all.json"
#define CHAIN_8FN DATA "/chain_8fn_10link.json"
#define CHAIN_8FN_SCN DATA "/chain_8fn_10link_all.json"

#define MAXA 16

// Every actuator's outputs at every row, from the chain's own columns
// after the backend's channels (x_<actuator>, pA_<actuator>, pB_<actuator>),
// and the rows' base columns x1, x2 beside them.
typedef struct trace {
    long n, cap;
    int nact;
    int base;                // the backend's channels: where the chain's columns start
    int ix[MAXA], ipA[MAXA], ipB[MAXA]; // row index of each actuator's x, pA, pB
    double *t, *x, *pA, *pB; // [cap], [cap * MAXA] ...
    double p_pump0;          // the pump pressure of row 0 [Pa]
    double base_diff;        // largest |x1 - x_<act 0>|, |x2 - x_<act 1>| over the rows [m]
    int finite;
} trace;

static int on_row(void* user, const double* row) {
    trace* tr = user;
    if (tr->n == tr->cap) {
        tr->cap = tr->cap ? 2 * tr->cap : 4096;
        tr->t = realloc(tr->t, (size_t)tr->cap * sizeof *tr->t);
        tr->x = realloc(tr->x, (size_t)tr->cap * MAXA * sizeof *tr->x);
        tr->pA = realloc(tr->pA, (size_t)tr->cap * MAXA * sizeof *tr->pA);
        tr->pB = realloc(tr->pB, (size_t)tr->cap * MAXA * sizeof *tr->pB);
        if (!tr->t || !tr->x || !tr->pA || !tr->pB) return 1;
    }
    const long i = tr->n++;
    tr->t[i] = row[COL_T];
    if (i == 0) tr->p_pump0 = row[COL_P_PUMP];
    for (int k = 0; k < tr->nact; ++k) {
        tr->x[i * MAXA + k] = row[tr->ix[k]];
        tr->pA[i * MAXA + k] = row[tr->ipA[k]];
        tr->pB[i * MAXA + k] = row[tr->ipB[k]];
    }
    for (int c = 0; c < tr->base; ++c)
        if (!isfinite(row[c])) tr->finite = 0;
    for (int k = 0; k < tr->nact; ++k)
        if (!isfinite(tr->x[i * MAXA + k]) || !isfinite(tr->pA[i * MAXA + k]) || !isfinite(tr->pB[i * MAXA + k]))
            tr->finite = 0;
    for (int k = 0; k < 2 && k < tr->nact; ++k)
        tr->base_diff = fmax(tr->base_diff, fabs(row[k ? COL_X2 : COL_X1] - tr->x[i * MAXA + k]));
    return 0;
}

static void trace_free(trace* tr) {
    free(tr->t);
    free(tr->x);
    free(tr->pA);
    free(tr->pB);
}

static int run(const model* m, const scenario* sc, sim_opts* o, trace* tr, sim_result* res) {
    memset(tr, 0, sizeof *tr);
    tr->finite = 1;
    const crane_chain* cc = &m->chain;
    tr->base = sim_ncol(o);
    tr->nact = cc->nact < MAXA ? cc->nact : MAXA;
    for (int k = 0; k < tr->nact; ++k) {
        const char* a = cc->act[k].name;
        tr->ix[k] = tr->base + crane_chain_find_column(cc, "x", a);
        tr->ipA[k] = tr->base + crane_chain_find_column(cc, "pA", a);
        tr->ipB[k] = tr->base + crane_chain_find_column(cc, "pB", a);
        CHECK(tr->ix[k] >= tr->base && tr->ipA[k] >= tr->base && tr->ipB[k] >= tr->base, "columns of %s", a);
    }
    o->no_step_probe = true; // the default step: the probe passes it anyway
    engine_sink k = {.row = on_row, .user = tr, .rows = true, .summary = true};
    k.t_end = o->duration > 0 ? o->duration : sc->duration;
    memset(res, 0, sizeof *res);
    return engine_run(m, sc, o, &k, res);
}

static model* load(const char* path) {
    char err[1024];
    model* m = model_load(path, NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    return m;
}

// One run's outputs against the analytic mode's, per actuator k: stroke
// RMS rx[k] [m], chamber pressure RMS over the analytic peak of that
// chamber rA[k], rB[k] [-], the analytic stroke range span[k] [m]; printed.
static void compare(const trace* a, const trace* b, double dt_ode, const crane_chain* cc, double* rx, double* rA,
                    double* rB, double* span) {
    const long n = a->n < b->n ? a->n : b->n;
    for (int k = 0; k < a->nact && n > 0; ++k) {
        double sx = 0, sa = 0, sb = 0, pkA = 0, pkB = 0, xmin = INFINITY, xmax = -INFINITY;
        int tbad = 0;
        for (long i = 0; i < n; ++i) {
            tbad += fabs(a->t[i] - b->t[i]) > 1e-9;
            const long j = i * MAXA + k;
            const double dx = a->x[j] - b->x[j], dA = a->pA[j] - b->pA[j], dB = a->pB[j] - b->pB[j];
            sx += dx * dx, sa += dA * dA, sb += dB * dB;
            pkA = fmax(pkA, a->pA[j]), pkB = fmax(pkB, a->pB[j]);
            xmin = fmin(xmin, a->x[j]), xmax = fmax(xmax, a->x[j]);
        }
        CHECK(tbad == 0, "%d rows at other times", tbad);
        rx[k] = sqrt(sx / n), rA[k] = sqrt(sa / n) / pkA, rB[k] = sqrt(sb / n) / pkB, span[k] = xmax - xmin;
        printf("  dt_ode %g ms, %-5s: stroke range %.1f mm, stroke RMS %.4f mm, pA RMS %.3f %% of %.2f MPa, "
               "pB RMS %.3f %% of %.2f MPa\n",
               dt_ode * 1e3, cc->act[k].name, span[k] * 1e3, rx[k] * 1e3, rA[k] * 100, pkA * 1e-6, rB[k] * 100,
               pkB * 1e-6);
    }
}

// The ODE chain world against the analytic mode on a scenario that moves
// every function (issue 26: stroke RMS <= 0.5 mm, pressure RMS <= 1 % of
// peak), on every function at the ODE world's default step of 1 ms. The
// extension is the hard one: 345 kg (its own 45 kg and the 300 kg load)
// against its seal friction's slope of 4.5e6 N s/m near zero speed, which
// the chain world holds in ODE's solver (ode_chain_opts.implicit_seal, on
// by default). With that friction applied a step late instead (main before
// this coupling) the extension crept where the analytic mode holds it:
// 2.38 mm and 2.47 % of peak at 1 ms. Every function's gap is the
// coupling's first-order error: it shrinks with the ODE step.
static void test_3boom_ext_against_analytic(void) {
    model* m = load(CHAIN_3BOOM);
    scenario sc;
    char err[512];
    CHECK(scenario_load(CHAIN_3BOOM_SCN, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    trace a, b;
    sim_result ra, rb;
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_LAGRANGE;
    CHECK(run(m, &sc, &o, &a, &ra) == SIM_OK, "lagrange: %s", ra.message);
    const double steps[2] = {1e-3, 0.5e-3};
    double rx[2][MAXA], rA[2][MAXA], rB[2][MAXA], span[2][MAXA];
    for (int h = 0; h < 2; ++h) {
        o = sim_default_opts();
        o.mechanics = SIM_ODE;
        o.dt_ode = steps[h];
        CHECK(run(m, &sc, &o, &b, &rb) == SIM_OK, "ode: %s", rb.message);
        CHECK(a.n == 12001 && b.n == a.n, "rows: lagrange %ld, ode %ld", a.n, b.n);
        CHECK(a.nact == 4 && a.base == SIM_NCOL_BASE && b.base == SIM_NCOL, "actuators %d, channels %d %d", a.nact,
              a.base, b.base);
        CHECK(a.finite && b.finite, "non-finite outputs");
        // The rows' base columns x1, x2 are the first two actuators' x_ columns.
        CHECK(a.base_diff == 0.0 && b.base_diff == 0.0, "x1, x2 against x_lift, x_jib: %g, %g", a.base_diff,
              b.base_diff);
        // One start pose (crane_chain_start_pose) and one start state: the
        // strokes and chamber pressures of row 0 agree, and its pump pressure.
        CHECK(fabs(a.p_pump0 - b.p_pump0) < 1.0 && a.p_pump0 > 1e6, "p_pump at t = 0: %.6g and %.6g Pa", a.p_pump0,
              b.p_pump0);
        for (int k = 0; k < a.nact && a.n > 0 && b.n > 0; ++k)
            CHECK(fabs(a.x[k] - b.x[k]) < 1e-9 && fabs(a.pA[k] - b.pA[k]) < 1.0 && fabs(a.pB[k] - b.pB[k]) < 1.0,
                  "%s at t = 0: x %.9g and %.9g m, pA %.6g and %.6g Pa, pB %.6g and %.6g Pa", m->chain.act[k].name,
                  a.x[k], b.x[k], a.pA[k], b.pA[k], a.pB[k], b.pB[k]);
        for (int k = 0; k < MAXA; ++k) rx[h][k] = rA[h][k] = rB[h][k] = span[h][k] = NAN;
        compare(&a, &b, o.dt_ode, &m->chain, rx[h], rA[h], rB[h], span[h]);
        trace_free(&b);
    }
    for (int k = 0; k < 4 && a.nact == 4; ++k) {
        const char* nm = m->chain.act[k].name;
        // Every function moves its cylinder (else the bounds say nothing).
        CHECK(span[0][k] > 0.03, "%s: stroke range %g m", nm, span[0][k]);
        CHECK(rx[0][k] <= 0.5e-3, "%s: stroke RMS %g mm > 0.5 mm", nm, rx[0][k] * 1e3);
        CHECK(rA[0][k] <= 0.01 && rB[0][k] <= 0.01, "%s: pressure RMS %.3f %%, %.3f %% of peak > 1 %%", nm,
              rA[0][k] * 100, rB[0][k] * 100);
        // The gap is the coupling's: it shrinks with the step.
        CHECK(rx[1][k] < 0.7 * rx[0][k], "%s: stroke RMS %g mm at 0.5 ms, %g mm at 1 ms", nm, rx[1][k] * 1e3,
              rx[0][k] * 1e3);
    }
    trace_free(&a);
    model_free(m);
}

// The 8-function model's ext1 and ext2, two cylinders on one valve (the
// second fed through tee orifices), against the analytic mode (ros34pw2 as
// the reference; Krus at 0.1 ms runs the scenario too since the general
// path's events and whole W, test_8fn_analytic_krus). Their
// valve opens at 2 s and closes at 3 s; the analytic mode then holds both
// by their seal friction. Each slider carries the light ext1 body (60 kg)
// between two oil columns: with the sliding friction applied a step late,
// or as the law's flat tangent, ODE's step overshoots zero speed and the
// pair chatters at 500 Hz and ratchets (ext1 out, ext2 in: 146 mm RMS,
// 98 mm with the tangent alone); the friction held as a saturating damper
// while sliding keeps them within the bounds.
static void test_8fn_pair_against_analytic(void) {
    model* m = load(CHAIN_8FN);
    scenario sc;
    char err[512];
    CHECK(scenario_load(CHAIN_8FN_SCN, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    trace a, b;
    sim_result ra, rb;
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_LAGRANGE;
    o.solver = HYD_ROS34PW2;
    CHECK(run(m, &sc, &o, &a, &ra) == SIM_OK, "lagrange: %s", ra.message);
    o = sim_default_opts();
    o.mechanics = SIM_ODE;
    CHECK(run(m, &sc, &o, &b, &rb) == SIM_OK, "ode: %s", rb.message);
    CHECK(a.n == 9001 && b.n == a.n && a.nact == 9, "rows: lagrange %ld, ode %ld; %d actuators", a.n, b.n, a.nact);
    double rx[MAXA], rA[MAXA], rB[MAXA], span[MAXA];
    for (int k = 0; k < MAXA; ++k) rx[k] = rA[k] = rB[k] = span[k] = NAN;
    compare(&a, &b, o.dt_ode, &m->chain, rx, rA, rB, span);
    for (int k = 2; k < 4 && a.nact == 9; ++k) {
        const char* nm = m->chain.act[k].name;
        CHECK(span[k] > 0.05, "%s: stroke range %g m", nm, span[k]);
        CHECK(rx[k] <= 0.5e-3, "%s: stroke RMS %g mm > 0.5 mm", nm, rx[k] * 1e3);
        CHECK(rA[k] <= 0.01 && rB[k] <= 0.01, "%s: pressure RMS %.3f %%, %.3f %% of peak > 1 %%", nm, rA[k] * 100,
              rB[k] * 100);
    }
    trace_free(&a);
    trace_free(&b);
    model_free(m);
}

static int csv_finite(const char* path, long* nrow, int* ncol) {
    FILE* f = fopen(path, "r");
    if (!f) return 0;
    static char line[1 << 14];
    int ok = 1;
    *nrow = 0, *ncol = 0;
    if (!fgets(line, sizeof line, f)) ok = 0;
    for (char* p = line; ok && *p; ++p) *ncol += *p == ',';
    ++*ncol;
    while (ok && fgets(line, sizeof line, f)) {
        int c = 0;
        for (char* p = line; *p && *p != '\n';) {
            char* e;
            const double v = strtod(p, &e);
            if (e == p || !isfinite(v)) ok = 0;
            ++c;
            p = *e == ',' ? e + 1 : e;
            if (e == p && *p != '\n' && *p) break;
        }
        if (c != *ncol) ok = 0;
        ++*nrow;
    }
    fclose(f);
    return ok;
}

// The 8-function, 10-body model headless on both backends through the
// command line; a scenario that moves every function.
static void test_8fn_10link_runs(void) {
    const char* tmp = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    static const char* mech[2] = {"ode", "lagrange"};
    for (int b = 0; b < 2; ++b) {
        char csv[512], args[2048], out[8192];
        snprintf(csv, sizeof csv, "%s/test_ode_engine_chain_%d_%s.csv", tmp, (int)getpid(), mech[b]);
        // Both at the default solver, Krus 0.1 ms (the analytic side blew
        // up at 7.943 s before the general path took a new J at the seal
        // friction's events and the whole W: test_8fn_analytic_krus).
        snprintf(args, sizeof args, "run --model %s --scenario %s --mechanics %s --out %s", CHAIN_8FN,
                 CHAIN_8FN_SCN, mech[b], csv);
        const int rc = cli_run(args, out, sizeof out);
        CHECK(rc == 0, "cranesim %s: exit %d: %s", args, rc, out);
        // The summary: the hydraulic sub-steps counted (9 s at 0.1 ms), and
        // no limiter claimed where a chain model has none (it has no rating:
        // the ODE run's note says the limiter was not applied, and why).
        CHECK(b || strstr(out, "ODE step 1 ms, 90000 hydraulic sub-steps"), "ode summary: %s", out);
        CHECK(!strstr(out, "utilisation max"), "a chain run reports a limiter: %s", out);
        CHECK(b || strstr(out, "mechanics.rated_moment [kN m] is missing; a crane chain's limiter needs the maker's "
                                "rating: not applied"),
              "ode: the note says why there is no limiter: %s", out);
        long nrow = 0;
        int ncol = 0;
        CHECK(csv_finite(csv, &nrow, &ncol) && nrow == 9001, "%s: %ld rows of %d columns, or not finite", csv, nrow,
              ncol);
        remove(csv);
    }
    // Every function moves its cylinders in the ODE chain world.
    model* m = load(CHAIN_8FN);
    scenario sc;
    char err[512];
    CHECK(scenario_load(CHAIN_8FN_SCN, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    trace tr;
    sim_result res;
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.dt_out = 0.01;
    CHECK(run(m, &sc, &o, &tr, &res) == SIM_OK, "ode: %s", res.message);
    CHECK(tr.nact == 9 && m->chain.nfn == 8 && tr.finite && tr.n == 901, "actuators %d, functions %d, finite %d, %ld rows",
          tr.nact, m->chain.nfn, tr.finite, tr.n);
    for (int k = 0; k < tr.nact && k < MAXA; ++k) {
        double lo = INFINITY, hi = -INFINITY;
        for (long i = 0; i < tr.n; ++i) lo = fmin(lo, tr.x[i * MAXA + k]), hi = fmax(hi, tr.x[i * MAXA + k]);
        CHECK(hi - lo > 0.01, "actuator %s: stroke range %g m", m->chain.act[k].name, hi - lo);
    }
    trace_free(&tr);
    model_free(m);
}

// The 8-function model on the analytic general path at the default solver
// (Krus 0.1 ms, J every 10 steps) against ROS34PW2 at rtol 1e-5 on the same
// path. Krus blew up here at 7.943 s (jib_ext2_cyl.pA below absolute zero;
// a light telescopic stage's seal friction steepening under a J taken while
// it moved, and the block W's explicit oil-column springs; ROS34PW2 keeps
// every chamber above 38 kPa). Bounds: every function's stroke RMS <= 0.5 mm
// (measured <= 0.14 mm), chamber pressure RMS <= 5 % of its peak (measured
// <= 3.0 %, the held stages whose friction-held rest is sensitive), and no
// chamber below 20 kPa abs at any row (the anti-cavitation checks crack at
// 50 kPa: the reference's lowest is 38 kPa).
static void test_8fn_analytic_krus(void) {
    model* m = load(CHAIN_8FN);
    scenario sc;
    char err[512];
    CHECK(scenario_load(CHAIN_8FN_SCN, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    trace t[2];
    sim_result res;
    for (int r = 0; r < 2; ++r) {
        sim_opts o = sim_default_opts();
        o.mechanics = SIM_LAGRANGE;
        o.dt_out = 0.01;
        if (r) o.solver = HYD_ROS34PW2, o.rtol = 1e-5, o.atol = 1e-8;
        CHECK(r || o.solver == HYD_KRUS, "the default solver is krus");
        CHECK(run(m, &sc, &o, &t[r], &res) == SIM_OK, "%s: %s", r ? "ros34pw2" : "krus", res.message);
        CHECK(t[r].n == 901 && t[r].finite && t[r].nact == 9, "%s: %ld rows, finite %d", r ? "ros34pw2" : "krus",
              t[r].n, t[r].finite);
    }
    double rx[MAXA], rA[MAXA], rB[MAXA], span[MAXA];
    compare(&t[1], &t[0], 0.0, &m->chain, rx, rA, rB, span);
    double pmin = INFINITY;
    const char* where = "";
    for (long i = 0; i < t[0].n; ++i)
        for (int k = 0; k < t[0].nact; ++k) {
            const double p = fmin(t[0].pA[i * MAXA + k], t[0].pB[i * MAXA + k]);
            if (p < pmin) pmin = p, where = m->chain.act[k].name;
        }
    printf("  krus: lowest chamber pressure %.1f kPa abs (%s)\n", pmin * 1e-3, where);
    CHECK(pmin > 20e3, "krus: a chamber of %s at %.1f kPa abs", where, pmin * 1e-3);
    for (int k = 0; k < t[0].nact && t[0].n == t[1].n; ++k) {
        const char* nm = m->chain.act[k].name;
        CHECK(rx[k] <= 0.5e-3, "%s: stroke RMS %g mm", nm, rx[k] * 1e3);
        CHECK(rA[k] <= 0.05 && rB[k] <= 0.05, "%s: pressure RMS %.2f %%, %.2f %% of peak", nm, rA[k] * 100,
              rB[k] * 100);
    }
    trace_free(&t[0]);
    trace_free(&t[1]);
    model_free(m);
}

// A chamber below absolute zero for 10 ms or more fails the run (the general
// path's run checks at every step, engine_chain.c), it is not a note: a
// Jacobian reused for 100 steps at Krus 0.1 ms on the 8-function model holds
// jib_ext2_cyl.pB below zero from 7.062 s (-46 kPa), which before ended with
// exit 0 and a note of a dip "at a stiff event". Checked both ways: the run
// fails naming the state and "below absolute zero", and no run that ends
// OK has a chamber below zero in 10 consecutive rows (1 ms apart).
static void test_8fn_below_zero_fails(void) {
    model* m = load(CHAIN_8FN);
    scenario sc;
    char err[512];
    CHECK(scenario_load(CHAIN_8FN_SCN, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    trace t;
    sim_result res;
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_LAGRANGE;
    o.jac_every = 100;
    o.duration = 7.5;
    const int st = run(m, &sc, &o, &t, &res);
    long run_len = 0, longest = 0;
    for (long i = 0; i < t.n; ++i) {
        bool below = false;
        for (int k = 0; k < t.nact; ++k) below |= t.pA[i * MAXA + k] < 0.0 || t.pB[i * MAXA + k] < 0.0;
        run_len = below ? run_len + 1 : 0;
        if (run_len > longest) longest = run_len;
    }
    printf("  krus, J every 100: %s; %ld rows, at most %ld consecutive with a chamber below zero\n",
           st == SIM_OK ? "ok" : res.message, t.n, longest);
    CHECK(st != SIM_OK || longest < 10, "ended OK with a chamber below zero in %ld consecutive rows", longest);
    CHECK(st == SIM_FAILED && strstr(res.message, "below absolute zero") && strstr(res.message, "jib_ext2_cyl.p"),
          "status %d: %s", st, res.message);
    trace_free(&t);
    model_free(m);
}

// The default two-link crane keeps the two-link ODE world: `cranesim run
// --mechanics ode` on ramp writes the rows of the previous main (b713729,
// every 100th row and the header kept in tests/world/data) byte for byte.
static void test_two_link_ode_unchanged(void) {
    const char* tmp = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    char csv[512], args[1024], out[4096];
    snprintf(csv, sizeof csv, "%s/test_ode_engine_chain_%d_ramp.csv", tmp, (int)getpid());
    snprintf(args, sizeof args, "run --mechanics ode --scenario ramp --out %s --quiet", csv);
    const int rc = cli_run(args, out, sizeof out);
    CHECK(rc == 0, "cranesim %s: exit %d: %s", args, rc, out);
    FILE* got = fopen(csv, "r");
    FILE* want = fopen(DATA "/ode_ramp_b713729_every100.csv", "r");
    CHECK(got && want, "open %s and the reference", csv);
    if (got && want) {
        static char g[1 << 13], w[1 << 13];
        long row = -1, checked = 0, differ = 0;
        while (fgets(g, sizeof g, got)) {
            // The header, then every 100th row.
            if (row >= 0 && row % 100) {
                ++row;
                continue;
            }
            ++row;
            if (!fgets(w, sizeof w, want)) w[0] = 0;
            ++checked;
            if (strcmp(g, w) && !differ++) printf("  first difference at row %ld:\n  got  %s  want %s", row - 1, g, w);
        }
        CHECK(checked == 202 && differ == 0 && !fgets(w, sizeof w, want), "%ld of %ld lines differ", differ, checked);
    }
    if (got) fclose(got);
    if (want) fclose(want);
    remove(csv);
}

// The seal friction held in ODE's solver (ode_chain_opts.implicit_seal):
// the 8-function model's ext1 and ext2, two cylinders on one valve, held
// still with every valve closed for 2 s. The analytic mode holds them (its
// implicit step; about 0.1 mm); the chain world with the friction applied a
// step late lets the pair trade oil (84 mm); with the friction's law
// linearised and solved by ODE at the step's end velocities the pair creeps
// as the regularised law lets it (0.17 mm): within 1 mm.
static double pair_drift(const model* m, int implicit) {
    ode_chain_opts co = ode_chain_default_opts();
    const int nd = crane_chain_ndof(&m->chain);
    double q0[32];
    const double q12[2] = {100 * M_PI / 180, -110 * M_PI / 180};
    if (nd > 32) return NAN;
    crane_chain_start_pose(&m->chain, q12, 0.0, q0);
    co.q0 = q0;
    co.circuit = m->hyd;
    co.tip_mass = 200;
    co.p_low = 0.5e6;
    co.implicit_seal = implicit;
    char err[512];
    ode_chain* w = ode_chain_create(&m->chain, &co, err, sizeof err);
    CHECK(w != NULL, "%s", err);
    if (!w) return NAN;
    const int k1 = 2, k2 = 3; // ext1, ext2 (actuators in file order)
    CHECK(!strcmp(m->chain.act[k1].name, "ext1") && !strcmp(m->chain.act[k2].name, "ext2"), "actuators %s %s",
          m->chain.act[k1].name, m->chain.act[k2].name);
    const double x1 = ode_chain_act_length(w, k1, NULL), x2 = ode_chain_act_length(w, k2, NULL);
    double u[16] = {0};
    ode_chain_set_commands(w, u);
    CHECK(ode_chain_step(w, 2.0) == 0, "%s", ode_chain_error(w));
    const double d = fmax(fabs(ode_chain_act_length(w, k1, NULL) - x1), fabs(ode_chain_act_length(w, k2, NULL) - x2));
    ode_chain_destroy(w);
    return d;
}

static void test_implicit_seal_holds(void) {
    model* m = load(CHAIN_8FN);
    if (!m) return;
    const double lag = pair_drift(m, 0), held = pair_drift(m, 1);
    printf("  ext1/ext2 drift over 2 s with the valves closed: %.2f mm (seal friction a step late), %.3f mm "
           "(implicit_seal)\n",
           lag * 1e3, held * 1e3);
    CHECK(lag > 0.02, "the lagged friction held the pair: %g mm", lag * 1e3);
    CHECK(held < 1e-3, "implicit_seal: the pair moved %g mm", held * 1e3);
    model_free(m);
}

// A slider's rate on a turning boom (ode_chain_q): the rate of its
// position. ODE's semi-implicit step moves each body by H times its new
// velocity, so (q_{i+1} - q_i)/H is the rate after the step to ODE's
// constraint error. chain_3boom_ext.json with the extension's centre of mass
// put 0.1 m off its axis, jib2 turning while the extension runs out: ODE's
// dJointGetSliderPositionRate leaves out the axis' turning, (c x ax) . w
// (here up to the jib2 rate times 0.1 m, a few mm/s), which the implicit
// seal friction's target rate must not.
static void test_slider_rate(void) {
    model* m = load(CHAIN_3BOOM);
    if (!m) return;
    crane_chain cc;
    CHECK(crane_chain_copy(&cc, &m->chain) == 0, "copy");
    const int ext = 4;
    CHECK(cc.nbody == 5 && cc.body[ext].def.joint == CHAIN_PRISMATIC, "body %d is not the extension", ext);
    cc.body[ext].def.com[2] = 0.1;
    ode_chain_opts co = ode_chain_default_opts();
    const int nd = crane_chain_ndof(&cc);
    double q0[8], q[8], qd[8];
    const double q12[2] = {100 * M_PI / 180, -110 * M_PI / 180};
    CHECK(nd <= 8, "%d DOFs", nd);
    crane_chain_start_pose(&cc, q12, 0.0, q0);
    co.q0 = q0;
    co.circuit = m->hyd;
    co.tip_mass = 100;
    char err[512];
    ode_chain* w = nd <= 8 ? ode_chain_create(&cc, &co, err, sizeof err) : NULL;
    CHECK(w != NULL, "%s", err);
    if (w) {
        const int d = nd - 1; // the extension's DOF, the last
        const double u[4] = {0, 0, 0.6, 0.7}, H = 1e-3;
        ode_chain_set_commands(w, u);
        double qprev = NAN, worst = 0, vmax = 0, wmax = 0;
        for (int s = 0; s < 1500; ++s) {
            CHECK(ode_chain_step(w, H) == 0, "%s", ode_chain_error(w));
            ode_chain_q(w, q, qd);
            if (s > 0) worst = fmax(worst, fabs(qd[d] - (q[d] - qprev) / H));
            vmax = fmax(vmax, fabs(qd[d]));
            wmax = fmax(wmax, fabs(qd[d - 1]));
            qprev = q[d];
        }
        printf("  extension rate: worst %.3g mm/s off its position's rate (up to %.0f mm/s; jib2 up to %.3f rad/s)\n",
               worst * 1e3, vmax * 1e3, wmax);
        // The turning term would be up to wmax x 0.1 m.
        CHECK(vmax > 0.05 && wmax > 0.05, "the extension and jib2 did not move: %g m/s, %g rad/s", vmax, wmax);
        CHECK(worst < 0.02 * wmax * 0.1, "slider rate %g m/s off its position's rate", worst);
        ode_chain_destroy(w);
    }
    crane_chain_free(&cc);
    model_free(m);
}

// What the chain world does not run, refused in one line.
static void test_refusals(void) {
    model* m = load(CHAIN_3BOOM);
    scenario sc;
    char err[512];
    CHECK(scenario_load(CHAIN_3BOOM_SCN, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    trace tr;
    sim_result res;
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = "sandbox";
    // The sandbox builds the chain on its truck (test_ode_sandbox_chain);
    // this scenario's start hangs the tip 4.5 m below the first boom's
    // joint, in the ground: refused in one line, not run.
    CHECK(run(m, &sc, &o, &tr, &res) == SIM_REFUSED && strstr(res.message, "leaves no room for the rope and hook") &&
              !strchr(res.message, '\n'),
          "sandbox: %s", res.message);
    trace_free(&tr);
    o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.solver = HYD_ROS34PW2;
    CHECK(run(m, &sc, &o, &tr, &res) == SIM_REFUSED && strstr(res.message, "is adaptive") &&
              !strchr(res.message, '\n'),
          "adaptive: %s", res.message);
    trace_free(&tr);
    // The stepped engine (drive, bench soak) of a chain model in the
    // sandbox (engine_ode_sandbox_chain_step.c,
    // test_engine_sandbox_chain_step.c) refuses this start as the scripted
    // run does, in one line.
    o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = "sandbox";
    const double q0[2] = {sc.q0[0], sc.q0[1]};
    engine* e = engine_create(m, &o, q0, 0.0, -1, err, sizeof err);
    CHECK(e == NULL && strstr(err, "leaves no room for the rope and hook") && !strchr(err, '\n'), "create: %s",
          err);
    engine_destroy(e);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_3boom_ext_against_analytic);
    RUN_TEST(test_8fn_10link_runs);
    RUN_TEST(test_8fn_analytic_krus);
    RUN_TEST(test_8fn_below_zero_fails);
    RUN_TEST(test_8fn_pair_against_analytic);
    RUN_TEST(test_implicit_seal_holds);
    RUN_TEST(test_slider_rate);
    RUN_TEST(test_two_link_ode_unchanged);
    RUN_TEST(test_refusals);
    TEST_MAIN_END();
}
