// test_control.c: the adaptive driver around the methods. Step-size control
// through a discontinuity and a kink, Hermite output against an exact
// solution, landing on t_end without evaluating f beyond it, and the
// non-finite report (index and time).
#include <string.h>

#include "check.h"
#include "hyd_solver.h"
#include "problems.h"

// y' = 1 for t < 1, then y' = -1e3 (y - 2): y = t up to 1, then
// y = 2 - exp(-1e3 (t - 1)). The solver is not told about the jump.
static int jump_f(void* user, double t, const double* y, double* dy) {
    (void)user;
    dy[0] = t < 1.0 ? 1.0 : -1e3 * (y[0] - 2.0);
    return 0;
}
static int jump_jac(void* user, double t, const double* y, double* J) {
    (void)user;
    (void)y;
    J[0] = t < 1.0 ? 0.0 : -1e3;
    return 0;
}

// A relief-like kink in y: y' = 1 - 1e3 max(y - 1, 0); y rises at rate 1 until
// it cracks at y = 1 and then settles at 1 + 1e-3.
static int kink_f(void* user, double t, const double* y, double* dy) {
    (void)user;
    (void)t;
    dy[0] = 1.0 - 1e3 * fmax(y[0] - 1.0, 0.0);
    return 0;
}

static hyd_solver* make(hyd_problem* p, hyd_method m, double rtol, double atol) {
    hyd_solver_opts o = hyd_default_solver_opts();
    o.rtol = rtol, o.atol = atol, o.h = 0.0;
    return hyd_solver_create(p, m, &o);
}

static void test_discontinuous_rhs(void) {
    for (int m = HYD_ROS34PW2; m <= HYD_RODAS3; ++m) {
        for (int fd = 0; fd < 2; ++fd) {
            hyd_problem p = {0};
            p.n = 1, p.f = jump_f, p.jac = fd ? NULL : jump_jac;
            hyd_solver* s = make(&p, (hyd_method)m, 1e-6, 1e-9);
            double t = 0.0, y = 0.0;
            CHECK(hyd_solver_advance(s, &t, &y, 1.02) == HYD_OK, "through the jump");
            CHECK_NEAR(y, 2.0 - exp(-1e3 * 0.02), 1e-4);
            const hyd_solver_stats* st = hyd_solver_get_stats(s);
            CHECK(st->rejected >= 1, "%s: the jump should cost a rejection", hyd_method_name(m));
            CHECK(st->steps < 300, "%s: %ld steps up to t = 1.02", hyd_method_name(m), st->steps);
            // After the transient h must grow back: 1.02 .. 1000 in few steps.
            hyd_solver_clear_stats(s);
            CHECK(hyd_solver_advance(s, &t, &y, 1000.0) == HYD_OK, "long tail");
            CHECK_NEAR(y, 2.0, 1e-6);
            CHECK(st->steps < 150, "%s fd=%d: %ld steps for the flat tail", hyd_method_name(m), fd,
                  st->steps);
            CHECK(hyd_solver_last_h(s) > 10.0, "%s: last h %.3g", hyd_method_name(m),
                  hyd_solver_last_h(s));
            hyd_solver_destroy(s);
        }
    }
}

static void test_kink(void) {
    for (int m = HYD_ROS34PW2; m <= HYD_RODAS3; ++m) {
        hyd_problem p = {0};
        p.n = 1, p.f = kink_f, p.autonomous = 1; // finite-difference J across the kink
        hyd_solver* s = make(&p, (hyd_method)m, 1e-6, 1e-9);
        double t = 0.0, y = 0.0;
        int rc = hyd_solver_advance(s, &t, &y, 100.0);
        CHECK(rc == HYD_OK, "%s rc %d", hyd_method_name(m), rc);
        CHECK_NEAR(y, 1.001, 1e-7);
        const hyd_solver_stats* st = hyd_solver_get_stats(s);
        CHECK(st->steps < 300, "%s: %ld steps", hyd_method_name(m), st->steps);
        CHECK(hyd_solver_last_h(s) > 1.0, "%s: last h %.3g", hyd_method_name(m),
              hyd_solver_last_h(s));
        hyd_solver_destroy(s);
    }
}

// Output callback recording the worst deviation from the exact solution.
typedef struct out_rec {
    double t_prev, emax;
    long count;
    int monotone;
} out_rec;

static int record(void* user, double t, const double* y) {
    out_rec* r = user;
    double g[3];
    conv_exact(t, g);
    for (int i = 0; i < 3; ++i) r->emax = fmax(r->emax, fabs(y[i] - g[i]));
    if (r->count > 0 && !(t > r->t_prev)) r->monotone = 0;
    r->t_prev = t;
    r->count++;
    return 0;
}

// Refuses any evaluation beyond t = 2 (the end of the run).
static int conv_f_bounded(void* user, double t, const double* y, double* dy) {
    if (t > 2.0) return 1;
    return conv_f(user, t, y, dy);
}

static void test_hermite_output(void) {
    for (int m = HYD_ROS34PW2; m <= HYD_RODAS3; ++m) {
        hyd_problem p = {0};
        p.n = 3, p.f = conv_f_bounded, p.jac = conv_jac, p.dfdt = conv_dfdt;
        hyd_solver* s = make(&p, (hyd_method)m, 1e-6, 1e-9);
        double y[3];
        conv_exact(0.0, y);
        out_rec r = {0.0, 0.0, 0, 1};
        // dt_out = 1 ms: 2001 outputs; steps must span many of them.
        int rc = hyd_solver_integrate(s, 0.0, y, 2.0, 1e-3, record, &r);
        CHECK(rc == HYD_OK, "%s rc %d", hyd_method_name(m), rc);
        CHECK(r.count == 2001, "%ld outputs", r.count);
        CHECK(r.monotone, "output times increase");
        CHECK(r.t_prev == 2.0, "last output at %.17g", r.t_prev);
        const hyd_solver_stats* st = hyd_solver_get_stats(s);
        CHECK(st->steps < 200, "%s: %ld steps for 2000 outputs", hyd_method_name(m), st->steps);
        // Hermite is O(h^4) locally, above the methods' order: its error stays
        // at the solution's level.
        CHECK(r.emax < 2e-5, "%s: output error %.3g", hyd_method_name(m), r.emax);
        printf("  hermite %-8s: %ld steps, max output error %.3g\n", hyd_method_name(m), st->steps,
               r.emax);
        hyd_solver_destroy(s);
    }
    // Fixed-step methods land on each output time.
    hyd_problem p = {0};
    p.n = 3, p.f = conv_f_bounded, p.jac = conv_jac;
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 1e-3;
    hyd_solver* s = hyd_solver_create(&p, HYD_KRUS, &o);
    double y[3];
    conv_exact(0.0, y);
    out_rec r = {0.0, 0.0, 0, 1};
    CHECK(hyd_solver_integrate(s, 0.0, y, 2.0, 0.01, record, &r) == HYD_OK, "krus integrate");
    CHECK(r.count == 201 && r.t_prev == 2.0, "%ld outputs, last %.17g", r.count, r.t_prev);
    CHECK(r.emax < 1e-5, "krus output error %.3g", r.emax);
    CHECK(hyd_solver_get_stats(s)->steps == 2000, "%ld steps", hyd_solver_get_stats(s)->steps);
    hyd_solver_destroy(s);
}

// Output of selected states (opts.out_states): those states are exactly the
// full run's, and a stop hands back the whole interpolated state.
typedef struct sel_rec {
    double t[4096], y1[4096], full[3];
    long count;
    double t_stop;
} sel_rec;

static int record_sel(void* user, double t, const double* y) {
    sel_rec* r = user;
    if (r->count < 4096) r->t[r->count] = t, r->y1[r->count] = y[1];
    r->count++;
    return t >= r->t_stop;
}

static void test_out_states(void) {
    static const int only1[1] = {1};
    static sel_rec all, sel;
    for (int pass = 0; pass < 2; ++pass) {
        sel_rec* r = pass ? &sel : &all;
        hyd_problem p = {0};
        p.n = 3, p.f = conv_f_bounded, p.jac = conv_jac, p.dfdt = conv_dfdt;
        hyd_solver_opts o = hyd_default_solver_opts();
        o.rtol = 1e-6, o.atol = 1e-9, o.h = 0.0;
        if (pass) o.out_states = only1, o.n_out_states = 1;
        hyd_solver* s = hyd_solver_create(&p, HYD_RODAS3, &o);
        double y[3];
        conv_exact(0.0, y);
        r->count = 0;
        r->t_stop = 1.2345; // not a step end: the stop state is interpolated
        CHECK(hyd_solver_integrate(s, 0.0, y, 2.0, 1e-3, record_sel, r) == HYD_OK, "integrate");
        for (int i = 0; i < 3; ++i) r->full[i] = y[i];
        hyd_solver_destroy(s);
    }
    CHECK(sel.count == all.count && all.count > 1000, "%ld vs %ld outputs", sel.count, all.count);
    long differ = 0;
    for (long k = 0; k < all.count && k < 4096; ++k)
        differ += sel.t[k] != all.t[k] || sel.y1[k] != all.y1[k];
    CHECK(differ == 0, "%ld selected outputs differ from the full interpolation", differ);
    for (int i = 0; i < 3; ++i)
        CHECK(sel.full[i] == all.full[i], "stop state %d: %.17g vs %.17g", i, sel.full[i], all.full[i]);
}

// A problem-supplied W factorisation (hyd_problem.wfactor/wsolve): used when
// it accepts, the solver's own LU when it declines, same results either way.
typedef struct dense_w {
    double lu[9];
    int piv[3];
    long factors, solves, declined;
    int decline_every; ///< decline every Nth factorisation (0: never)
} dense_w;

static dense_w g_w;

static int dw_factor(void* user, const double* J, double gh) {
    (void)user;
    g_w.factors++;
    if (g_w.decline_every && g_w.factors % g_w.decline_every == 0) return ++g_w.declined, 1;
    for (int i = 0; i < 9; ++i) g_w.lu[i] = (i % 4 == 0) - gh * J[i];
    return hyd_lu_factor(g_w.lu, 3, g_w.piv) != 0;
}

static void dw_solve(void* user, double* x) {
    (void)user;
    g_w.solves++;
    hyd_lu_solve(g_w.lu, 3, g_w.piv, x);
}

static void test_wfactor_hook(void) {
    for (int m = HYD_KRUS; m < HYD_METHOD_COUNT; ++m) {
        if (m == HYD_RK4) continue;
        double yend[3][3];
        long lus[3];
        for (int mode = 0; mode < 3; ++mode) { // none, hook, hook declining every 3rd
            hyd_problem p = {0};
            p.n = 3, p.f = conv_f_bounded, p.jac = conv_jac, p.dfdt = conv_dfdt;
            memset(&g_w, 0, sizeof g_w);
            g_w.decline_every = mode == 2 ? 3 : 0;
            if (mode) p.wfactor = dw_factor, p.wsolve = dw_solve;
            hyd_solver_opts o = hyd_default_solver_opts();
            o.rtol = 1e-6, o.atol = 1e-9;
            o.h = hyd_method_is_adaptive((hyd_method)m) ? 0.0 : 1e-3;
            hyd_solver* s = hyd_solver_create(&p, (hyd_method)m, &o);
            double t = 0.0;
            conv_exact(0.0, yend[mode]);
            CHECK(hyd_solver_advance(s, &t, yend[mode], 2.0) == HYD_OK, "%s mode %d", hyd_method_name((hyd_method)m), mode);
            lus[mode] = hyd_solver_get_stats(s)->lus;
            hyd_solver_destroy(s);
            if (mode == 1) CHECK(g_w.factors == lus[1] && g_w.solves > 0, "%s: hook used for %ld of %ld LUs", hyd_method_name((hyd_method)m), g_w.factors, lus[1]);
            if (mode == 2) CHECK(g_w.declined > 0, "declines exercised");
        }
        for (int mode = 1; mode < 3; ++mode)
            for (int i = 0; i < 3; ++i)
                CHECK(fabs(yend[mode][i] - yend[0][i]) <= 1e-12 * (1.0 + fabs(yend[0][i])),
                      "%s mode %d state %d: %.17g vs %.17g", hyd_method_name((hyd_method)m), mode, i,
                      yend[mode][i], yend[0][i]);
    }
}

// A problem-supplied whole step (hyd_problem.wstep) for Krus and ROS2: the
// solver asks for a new J every jac_every steps and after a reset, counts
// two f per step and the factorisations the hook reports; a hook that does
// the generic stage arithmetic gives the generic result.
typedef struct ws_state {
    double J[9], lu[9];
    int piv[3];
    double gh;
    long calls, new_jacs, factors;
} ws_state;

static int ws_step(void* user, double t, const double* y, double h, double gamma, int new_jac, double* ynew) {
    ws_state* w = user;
    w->calls++;
    int nlu = 0;
    if (new_jac) {
        w->new_jacs++;
        memset(w->J, 0, sizeof w->J);
        conv_jac(NULL, t, y, w->J);
        w->gh = 0.0;
    }
    if (w->gh != gamma * h) {
        w->gh = gamma * h;
        for (int i = 0; i < 9; ++i) w->lu[i] = (i % 4 == 0) - w->gh * w->J[i];
        if (hyd_lu_factor(w->lu, 3, w->piv)) return HYD_ERR_SINGULAR;
        w->factors++;
        nlu = 1;
    }
    double f0[3], k1[3], ys[3], f1[3], k2[3];
    conv_f_bounded(NULL, t, y, f0);
    for (int i = 0; i < 3; ++i) k1[i] = h * f0[i];
    hyd_lu_solve(w->lu, 3, w->piv, k1);
    for (int i = 0; i < 3; ++i) ys[i] = y[i] + k1[i];
    conv_f_bounded(NULL, t + h, ys, f1);
    for (int i = 0; i < 3; ++i) k2[i] = h * f1[i] - 2.0 * (k1[i] - h * f0[i]);
    hyd_lu_solve(w->lu, 3, w->piv, k2);
    for (int i = 0; i < 3; ++i) ynew[i] = y[i] + 0.5 * (k1[i] + k2[i]);
    return nlu;
}

static void test_wstep_hook(void) {
    const hyd_method ms[2] = {HYD_KRUS, HYD_ROS2};
    for (int j = 0; j < 2; ++j) {
        double yend[2][3];
        hyd_solver_stats st[2];
        ws_state w = {0};
        for (int mode = 0; mode < 2; ++mode) {
            hyd_problem p = {0};
            p.n = 3, p.f = conv_f_bounded, p.jac = conv_jac, p.user = &w;
            if (mode) p.wstep = ws_step;
            hyd_solver_opts o = hyd_default_solver_opts();
            o.h = 1e-3;
            o.jac_every = 3;
            hyd_solver* s = hyd_solver_create(&p, ms[j], &o);
            double t = 0.0;
            conv_exact(0.0, yend[mode]);
            CHECK(hyd_solver_advance(s, &t, yend[mode], 1.0) == HYD_OK, "%s mode %d", hyd_method_name(ms[j]), mode);
            hyd_solver_reset(s); // forces a new J at the next step
            CHECK(hyd_solver_advance(s, &t, yend[mode], 1.0005) == HYD_OK, "%s mode %d", hyd_method_name(ms[j]), mode);
            st[mode] = *hyd_solver_get_stats(s);
            hyd_solver_destroy(s);
        }
        // 1000 steps, J at steps 0, 3, ..., 999 (334), then the reset's J
        // (the 0.5 ms landing step refactors W too).
        CHECK(w.calls == 1001 && st[1].steps == 1001, "%ld calls, %ld steps", w.calls, st[1].steps);
        CHECK(w.new_jacs == 335 && st[1].jevals == 335, "%ld new J asked, %ld counted", w.new_jacs, st[1].jevals);
        CHECK(st[1].fevals == 2 * st[1].steps, "%ld f for %ld steps", st[1].fevals, st[1].steps);
        CHECK(st[1].lus == w.factors && st[1].lus == st[0].lus, "LUs: %ld counted, %ld done, %ld generic", st[1].lus,
              w.factors, st[0].lus);
        for (int i = 0; i < 3; ++i)
            CHECK(fabs(yend[1][i] - yend[0][i]) <= 1e-13 * (1.0 + fabs(yend[0][i])), "%s state %d: %.17g vs %.17g",
                  hyd_method_name(ms[j]), i, yend[1][i], yend[0][i]);
    }
}

// hyd_problem.events: a counter that moves takes a new J at that step, as
// many times as it moves, on both step paths (generic and wstep), and a
// counter that stands still changes nothing. The switch here is y1 rising
// through 0.5 and 0.9 (conv_exact's sin t on [0, 1.5]), so the J times are
// known by hand: age 3 from t = 0, plus the two crossings.
typedef struct ev_state {
    ws_state ws;           ///< for the wstep path
    unsigned long count;
    int level, calls;
    double t_switch[4];
    int nswitch;
} ev_state;

static unsigned long ev_count(void* user, double t, const double* y) {
    ev_state* e = user;
    e->calls++;
    const int lv = (y[0] >= 0.5) + (y[0] >= 0.9);
    if (lv != e->level) {
        e->count++;
        if (e->nswitch < 4) e->t_switch[e->nswitch++] = t;
    }
    e->level = lv;
    return e->count;
}

static int ev_wstep(void* user, double t, const double* y, double h, double gamma, int new_jac, double* ynew) {
    return ws_step(&((ev_state*)user)->ws, t, y, h, gamma, new_jac, ynew);
}

static void test_events_hook(void) {
    for (int path = 0; path < 2; ++path) {
        for (int on = 0; on < 2; ++on) {
            ev_state e = {0};
            hyd_problem p = {0};
            p.n = 3, p.f = conv_f_bounded, p.jac = conv_jac, p.user = &e;
            if (path) p.wstep = ev_wstep;
            if (on) p.events = ev_count;
            hyd_solver_opts o = hyd_default_solver_opts();
            o.h = 1e-2;
            o.jac_every = 1000; // J by events alone after the first
            o.jac_max_age = 0.0;
            hyd_solver* s = hyd_solver_create(&p, HYD_KRUS, &o);
            double t = 0.0, y[3];
            conv_exact(0.0, y);
            CHECK(hyd_solver_advance(s, &t, y, 1.5) == HYD_OK, "path %d events %d", path, on);
            const hyd_solver_stats* st = hyd_solver_get_stats(s);
            // sin t crosses 0.5 near t = 0.524 and 0.9 near t = 1.120.
            CHECK(st->jevals == (on ? 3 : 1), "path %d events %d: %ld J", path, on, st->jevals);
            CHECK(st->jevents == (on ? 2 : 0), "path %d events %d: %ld J for events", path, on, st->jevents);
            if (on) {
                CHECK(e.nswitch == 2 && fabs(e.t_switch[0] - 0.53) < 0.011 && fabs(e.t_switch[1] - 1.13) < 0.011,
                      "switches %d at %.3f, %.3f", e.nswitch, e.t_switch[0], e.t_switch[1]);
                CHECK(e.calls == 150, "%d calls for 150 steps", e.calls);
                if (path) CHECK(e.ws.new_jacs == 3, "wstep asked for %ld new J", e.ws.new_jacs);
            }
            hyd_solver_destroy(s);
        }
    }
    // With a J every step the hook is not consulted.
    ev_state e = {0};
    hyd_problem p = {0};
    p.n = 3, p.f = conv_f_bounded, p.jac = conv_jac, p.user = &e, p.events = ev_count;
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 1e-2;
    hyd_solver* s = hyd_solver_create(&p, HYD_KRUS, &o);
    double t = 0.0, y[3];
    conv_exact(0.0, y);
    CHECK(hyd_solver_advance(s, &t, y, 0.1) == HYD_OK && e.calls == 0, "%d calls with jac_every 1", e.calls);
    hyd_solver_destroy(s);
}

// y' = rate, with rate an input the solver cannot see. After the input
// changes, hyd_solver_inputs_changed makes an adaptive method drop its cached
// f(t, y): every method then integrates the new rate exactly (a constant
// rate is within every method's order), and without the call the first stage
// still uses the old one.
static int rate_f(void* user, double t, const double* y, double* dy) {
    (void)t, (void)y;
    dy[0] = *(const double*)user;
    return 0;
}

static void test_inputs_changed(void) {
    for (int m = HYD_ROS34PW2; m < HYD_METHOD_COUNT; ++m) {
        double yend[2];
        for (int tell = 0; tell < 2; ++tell) {
            double rate = 1.0;
            hyd_problem p = {0};
            p.n = 1, p.f = rate_f, p.user = &rate, p.autonomous = 1;
            hyd_solver_opts o = hyd_default_solver_opts();
            o.rtol = 1e-6, o.atol = 1e-9;
            hyd_solver* s = hyd_solver_create(&p, (hyd_method)m, &o);
            double t = 0.0, y = 0.0;
            CHECK(hyd_solver_advance(s, &t, &y, 1.0) == HYD_OK, "first advance");
            rate = 2.0;
            if (tell) hyd_solver_inputs_changed(s);
            CHECK(hyd_solver_advance(s, &t, &y, 2.0) == HYD_OK, "second advance");
            yend[tell] = y;
            hyd_solver_destroy(s);
        }
        CHECK(fabs(yend[1] - 3.0) < 1e-12, "%s: y(2) = %.15g with the call, expected 3",
              hyd_method_name((hyd_method)m), yend[1]);
        CHECK(fabs(yend[0] - 3.0) > 1e-6, "%s: the stale f went unnoticed (y(2) = %.15g)",
              hyd_method_name((hyd_method)m), yend[0]);
    }
}

// Component 1 of f turns NaN for t > 0.57.
static int nan_f(void* user, double t, const double* y, double* dy) {
    (void)user;
    (void)y;
    dy[0] = 1.0;
    dy[1] = t > 0.57 ? NAN : 1.0;
    dy[2] = -y[2];
    return 0;
}

static void test_nonfinite(void) {
    for (int m = 0; m < HYD_METHOD_COUNT; ++m) {
        hyd_problem p = {0};
        p.n = 3, p.f = nan_f;
        hyd_solver_opts o = hyd_default_solver_opts();
        o.h = 0.1;
        hyd_solver* s = hyd_solver_create(&p, (hyd_method)m, &o);
        double t = 0.0, y[3] = {0.0, 0.0, 1.0};
        int rc = hyd_solver_advance(s, &t, y, 1.0);
        double t_bad = -1.0;
        int i_bad = hyd_solver_bad_state(s, &t_bad);
        CHECK(rc == HYD_ERR_NONFINITE, "%s rc %d", hyd_method_name(m), rc);
        CHECK(i_bad == 1, "%s: bad index %d", hyd_method_name(m), i_bad);
        if (hyd_method_is_adaptive((hyd_method)m)) {
            // The controller closes in on the time f breaks down.
            CHECK_NEAR(t_bad, 0.57, 1e-6);
            CHECK(t <= 0.57 && t > 0.57 - 1e-6, "%s stopped at %.12g", hyd_method_name(m), t);
        } else {
            // The step 0.5 -> 0.6 went bad, and so did its retries: the
            // time is the end of the finest sub-step (h/16) that did,
            // 0.575, the first after 0.57.
            CHECK_NEAR(t_bad, 0.575, 1e-12);
            CHECK_NEAR(t, 0.5, 1e-12); // y kept at the last good state
        }
        CHECK(isfinite(y[0]) && isfinite(y[1]) && isfinite(y[2]), "y kept finite");
        CHECK_NEAR(y[0], t, 1e-9);
        CHECK_NEAR(y[1], t, 1e-9);
        hyd_solver_destroy(s);
        if (hyd_method_is_adaptive((hyd_method)m)) continue;
        // Without retries the whole step is the one reported.
        o.retry_halvings = 0;
        s = hyd_solver_create(&p, (hyd_method)m, &o);
        t = 0.0, y[0] = y[1] = 0.0, y[2] = 1.0;
        rc = hyd_solver_advance(s, &t, y, 1.0);
        i_bad = hyd_solver_bad_state(s, &t_bad);
        CHECK(rc == HYD_ERR_NONFINITE && i_bad == 1, "%s without retries: rc %d, bad %d", hyd_method_name(m), rc,
              i_bad);
        CHECK_NEAR(t_bad, 0.6, 1e-12);
        CHECK_NEAR(t, 0.5, 1e-12);
        CHECK(hyd_solver_get_stats(s)->retried == 0, "no retry when they are off");
        hyd_solver_destroy(s);
    }
}

// y' = lam y with lam = 2 / h = 1 / (gamma h) for Krus at h = 0.1: W = 1 -
// gamma h lam is exactly singular at the step; two half steps have W = 1/2
// and amplify by R(1) = (1 + 1/2) / (1 - 1/2) = 3 each (the trapezoidal
// rule's R(z) = (1 + z/2) / (1 - z/2) at z = h lam / 2 = 1).
static int grow_f(void* user, double t, const double* y, double* dy) {
    (void)user, (void)t;
    dy[0] = 20.0 * y[0];
    return 0;
}
static int grow_jac(void* user, double t, const double* y, double* J) {
    (void)user, (void)t, (void)y;
    J[0] = 20.0;
    return 0;
}

// y' = -60 y, and a state below -0.1 is implausible: Krus at h = 0.1
// (z = -6) gives R = (1 - 3) / (1 + 3) = -0.5, h/2 gives -0.2 at once
// (still implausible), h/4 gives R(-1.5) = 0.25 / 1.75 = 1/7 four times.
static int decay_f(void* user, double t, const double* y, double* dy) {
    (void)user, (void)t;
    dy[0] = -60.0 * y[0];
    return 0;
}
static int decay_jac(void* user, double t, const double* y, double* J) {
    (void)user, (void)t, (void)y;
    J[0] = -60.0;
    return 0;
}
static int below_tenth(void* user, const double* y) {
    (void)user;
    return y[0] > -0.1 ? 0 : 1;
}

static void test_fixed_retry(void) {
    {
        hyd_problem p = {0};
        p.n = 1, p.f = decay_f, p.jac = decay_jac, p.implausible = below_tenth;
        hyd_solver_opts o = hyd_default_solver_opts();
        o.h = 0.1;
        hyd_solver* s = hyd_solver_create(&p, HYD_KRUS, &o);
        double t = 0.0, y[1] = {1.0};
        CHECK(hyd_solver_step(s, &t, y, 0.1) == HYD_OK, "implausible step retried");
        CHECK_NEAR(y[0], 1.0 / 2401.0, 1e-15);
        CHECK(hyd_solver_get_stats(s)->retried == 1 && hyd_solver_get_stats(s)->substeps == 1 + 4,
              "h/2 failed at its first sub-step, h/4 took 4: %ld", hyd_solver_get_stats(s)->substeps);
        hyd_solver_destroy(s);
        // Still implausible at the finest level (retry_halvings = 1: h/2,
        // whose first sub-step ends at -0.2): accepted there, as the
        // caller's checks judge such a state.
        o.retry_halvings = 1;
        s = hyd_solver_create(&p, HYD_KRUS, &o);
        t = 0.0, y[0] = 1.0;
        CHECK(hyd_solver_step(s, &t, y, 0.1) == HYD_OK, "accepted at the finest level");
        CHECK_NEAR(y[0], 0.04, 1e-15); // two steps of R(-3) = -0.2
        hyd_solver_destroy(s);
    }
    hyd_problem p = {0};
    p.n = 1, p.f = grow_f, p.jac = grow_jac;
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 0.1;
    hyd_solver* s = hyd_solver_create(&p, HYD_KRUS, &o);
    double t = 0.0, y[1] = {1.0};
    int rc = hyd_solver_step(s, &t, y, 0.1);
    CHECK(rc == HYD_OK, "the singular step retried in halves: rc %d", rc);
    CHECK_NEAR(t, 0.1, 1e-15);
    CHECK_NEAR(y[0], 9.0, 1e-12);
    CHECK(hyd_solver_get_stats(s)->retried == 1 && hyd_solver_get_stats(s)->substeps == 2,
          "one retry of 2 sub-steps, got %ld, %ld", hyd_solver_get_stats(s)->retried,
          hyd_solver_get_stats(s)->substeps);
    CHECK(hyd_solver_get_stats(s)->steps == 1, "counted as one step");
    hyd_solver_destroy(s);
    // Off: the singular W is reported, y and t untouched.
    o.retry_halvings = 0;
    s = hyd_solver_create(&p, HYD_KRUS, &o);
    t = 0.0, y[0] = 1.0;
    rc = hyd_solver_step(s, &t, y, 0.1);
    CHECK(rc == HYD_ERR_SINGULAR, "without retries: rc %d", rc);
    CHECK(t == 0.0 && y[0] == 1.0, "y and t untouched");
    hyd_solver_destroy(s);
}

// Reset drops step history: after it, the first step is opts.h again.
static void test_reset(void) {
    hyd_problem p = {0};
    p.n = 1, p.f = jump_f, p.jac = jump_jac;
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 1e-3, o.rtol = 1e-6, o.atol = 1e-9;
    hyd_solver* s = hyd_solver_create(&p, HYD_ROS34PW2, &o);
    double t = 0.0, y = 0.0;
    CHECK(hyd_solver_advance(s, &t, &y, 0.9) == HYD_OK, "advance");
    CHECK(hyd_solver_last_h(s) > 0.05, "h grew on y' = 1: %.3g", hyd_solver_last_h(s));
    hyd_solver_reset(s);
    long jev = hyd_solver_get_stats(s)->jevals;
    CHECK(hyd_solver_advance(s, &t, &y, 0.95) == HYD_OK, "advance");
    CHECK(hyd_solver_get_stats(s)->jevals > jev, "reset forces a new J");
    CHECK(hyd_solver_get_stats(s)->steps > 0, "steps");
    hyd_solver_destroy(s);
}

static void test_bad_arguments(void) {
    hyd_problem p = {0};
    p.n = 3, p.f = conv_f;
    CHECK(hyd_solver_create(NULL, HYD_KRUS, NULL) == NULL, "NULL problem");
    int bad_sizes[2] = {1, 1};
    p.nblock = 2, p.block_size = bad_sizes;
    CHECK(hyd_solver_create(&p, HYD_KRUS, NULL) == NULL, "blocks not summing to n");
    p.nblock = 0;
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 0.0;
    CHECK(hyd_solver_create(&p, HYD_KRUS, &o) == NULL, "fixed step needs h > 0");
    hyd_solver* s = hyd_solver_create(&p, HYD_ROS34PW2, &o);
    CHECK(s != NULL, "adaptive accepts h = 0 (automatic initial step)");
    hyd_solver_destroy(s);
}

int main(int argc, char** argv) {
    RUN_TEST(test_discontinuous_rhs);
    RUN_TEST(test_kink);
    RUN_TEST(test_hermite_output);
    RUN_TEST(test_out_states);
    RUN_TEST(test_wfactor_hook);
    RUN_TEST(test_wstep_hook);
    RUN_TEST(test_events_hook);
    RUN_TEST(test_inputs_changed);
    RUN_TEST(test_nonfinite);
    RUN_TEST(test_fixed_retry);
    RUN_TEST(test_reset);
    RUN_TEST(test_bad_arguments);
    TEST_MAIN_END();
}
