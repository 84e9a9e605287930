// solver.c: solver lifetime, Jacobian and W bookkeeping, the fixed-step and
// adaptive drivers, Hermite output, and the method table. The methods' stage
// arithmetic lives in krus.c, rk4.c and rosenbrock.c.
#include "solver_internal.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

// ---------------------------------------------------------------- methods --

static const char* const method_names[HYD_METHOD_COUNT] = {"krus", "ros2", "rk4", "ros34pw2",
                                                           "rodas3"};

const char* hyd_method_name(hyd_method m) {
    if ((int)m < 0 || m >= HYD_METHOD_COUNT) return "unknown";
    return method_names[m];
}

int hyd_method_parse(const char* name) {
    if (!name) return -1;
    for (int m = 0; m < HYD_METHOD_COUNT; ++m)
        if (strcmp(name, method_names[m]) == 0) return m;
    return -1;
}

bool hyd_method_is_adaptive(hyd_method m) { return m == HYD_ROS34PW2 || m == HYD_RODAS3; }

int hyd_method_order(hyd_method m) {
    switch (m) {
    case HYD_KRUS:
    case HYD_ROS2: return 2;
    case HYD_RK4: return 4;
    case HYD_ROS34PW2:
    case HYD_RODAS3: return 3;
    default: return 0;
    }
}

hyd_solver_opts hyd_default_solver_opts(void) {
    hyd_solver_opts o;
    // Every field defined, also those added later (a missing on_step = NULL
    // was called as garbage: caught by the sanitizer build).
    memset(&o, 0, sizeof o);
    o.h = 1e-4;           // the paper's Krus step [s]
    o.rtol = 1e-3;
    o.atol = 1e-6;
    o.h_min = 1e-12;      // [s]
    o.h_max = HUGE_VAL;   // no cap; <= 0 also means no cap
    o.jac_every = 1;
    o.jac_max_age = 0.01; // older J diverged at larger h [s]; <= 0: no limit
    o.max_steps = 100000000;
    o.h_hold = 0.0;       // no step hysteresis
    o.retry_halvings = 4; // a failed fixed step is retried down to h/16
    o.out_states = NULL;  // interpolate every state at output times
    o.n_out_states = 0;
    return o;
}

// --------------------------------------------------------------- lifetime --

hyd_solver* hyd_solver_create(const hyd_problem* p, hyd_method m, const hyd_solver_opts* o) {
    if (!p || !p->f || p->n <= 0 || (int)m < 0 || m >= HYD_METHOD_COUNT) return NULL;
    const int n = p->n;
    hyd_solver_opts opts = o ? *o : hyd_default_solver_opts();
    if (!hyd_method_is_adaptive(m) && !(opts.h > 0.0)) return NULL;
    if (hyd_method_is_adaptive(m) && !(opts.rtol >= 0.0 && opts.atol >= 0.0 &&
                                       opts.rtol + opts.atol > 0.0))
        return NULL;

    int nblock = 1;
    if (p->nblock > 0) {
        if (!p->block_size) return NULL;
        int sum = 0;
        for (int b = 0; b < p->nblock; ++b) {
            if (p->block_size[b] <= 0) return NULL;
            sum += p->block_size[b];
        }
        if (sum != n) return NULL;
        nblock = p->nblock;
    }

    hyd_solver* s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->p = p;
    s->method = m;
    s->o = opts;
    s->n = n;
    s->nblock = nblock;
    if (hyd_method_is_adaptive(m)) hydRosenbrockTableau(m, &s->tab);

    s->boff = calloc((size_t)nblock + 1, sizeof *s->boff);
    s->moff = calloc((size_t)nblock, sizeof *s->moff);
    s->bblk = calloc((size_t)n, sizeof *s->bblk);
    s->piv = calloc((size_t)n, sizeof *s->piv);
    s->wswap = calloc((size_t)nblock, sizeof *s->wswap);
    s->border = calloc((size_t)nblock, sizeof *s->border);
    s->b1x = calloc((size_t)nblock, sizeof *s->b1x);
    s->b1w = calloc((size_t)nblock, sizeof *s->b1w);
    if (!s->boff || !s->moff || !s->bblk || !s->piv || !s->wswap || !s->border || !s->b1x || !s->b1w) {
        hyd_solver_destroy(s);
        return NULL;
    }
    int msize = 0;
    for (int b = 0; b < nblock; ++b) {
        const int bs = p->nblock > 0 ? p->block_size[b] : n;
        s->boff[b + 1] = s->boff[b] + bs;
        s->moff[b] = msize;
        msize += bs * bs;
        for (int i = s->boff[b]; i < s->boff[b + 1]; ++i) s->bblk[i] = b;
    }
    s->msize = msize;
    int nb = 0;
    for (int cls = 1; cls <= 3; ++cls) {
        for (int b = 0; b < nblock; ++b) {
            const int bs = s->boff[b + 1] - s->boff[b];
            if ((cls < 3 && bs == cls) || (cls == 3 && bs > 2)) s->border[nb++] = b;
        }
        if (cls == 1) {
            s->nb1 = nb;
            for (int t = 0; t < nb; ++t) s->b1x[t] = s->boff[s->border[t]];
        }
        if (cls == 2) s->nb2 = nb - s->nb1;
    }

    // One block for all vectors: jb, w, (jfull), 4 k, 4 hjk and 18 more n-vectors.
    const int dense = nblock == 1;
    const size_t nfull = (p->jac && !dense) ? (size_t)n * (size_t)n : 0;
    const size_t total = 2 * (size_t)msize + nfull + 26 * (size_t)n;
    double* mem = calloc(total, sizeof *mem);
    if (!mem) {
        hyd_solver_destroy(s);
        return NULL;
    }
    double* q = mem;
    s->jb = q, q += msize;
    s->w = q, q += msize;
    s->jfull = nfull ? q : s->jb; // dense: the callback writes straight into jb
    q += nfull;
    for (int i = 0; i < 4; ++i) s->k[i] = q, q += n;
    for (int i = 0; i < 4; ++i) s->hjk[i] = q, q += n;
    s->ys = q, q += n;
    s->fs = q, q += n;
    s->r = q, q += n;
    s->ynew = q, q += n;
    s->err = q, q += n;
    s->fdy = q, q += n;
    s->fdf = q, q += n;
    s->yout = q, q += n;
    for (int i = 0; i < 3; ++i) s->hc[i] = q, q += n;
    s->fc_y = q, q += n;
    s->fc_f = q, q += n;
    s->fnew = q, q += n;
    s->ft = q, q += n;
    s->widiag = q, q += n;
    s->bad_i = -1;
    // Sparse path of a dense W (lu.c). Lists hold at most n(n-1)/2 entries.
    if (dense && n >= 3) {
        const size_t nn = (size_t)n * (size_t)n, tri = (size_t)n * (size_t)(n - 1) / 2;
        s->sp_mask = calloc(2 * nn, 1); // the factors' pattern, then J's (sp_jmask)
        s->sp_lptr = calloc(3 * ((size_t)n + 1) + 5 * tri + 2 * (size_t)n, sizeof(int));
        s->sp_scale = calloc((size_t)n, sizeof(double));
        s->sp_zmask = calloc(nn, sizeof(uint64_t));
        s->sp_ppos = calloc(nn, sizeof(int));
        if (!s->sp_mask || !s->sp_lptr || !s->sp_scale || !s->sp_zmask || !s->sp_ppos) {
            hyd_solver_destroy(s);
            return NULL;
        }
        s->sp_jmask = s->sp_mask + nn;
        for (int i = 0; i < n; ++i) {
            s->sp_jmask[(size_t)i * (size_t)n + (size_t)i] = 1;
            s->sp_scale[i] = 1.0;
        }
        int* ip = s->sp_lptr + (n + 1);
        s->sp_uptr = ip, ip += n + 1;
        s->sp_fptr = ip, ip += n + 1;
        s->sp_lrow = ip, ip += tri;
        s->sp_ucol = ip, ip += tri;
        s->sp_upos = ip, ip += tri;
        s->sp_fpos = ip, ip += tri;
        s->sp_fcol = ip, ip += tri;
        s->sp_perm = ip, ip += n;
        s->sp_pos = ip, ip += n;
        s->sp_on = 1;
        hydSparseInit(s);
    }
    hyd_solver_reset(s);
    return s;
}

void hyd_solver_destroy(hyd_solver* s) {
    if (!s) return;
    // jb is the first vector of the single workspace block.
    free(s->jb);
    free(s->boff);
    free(s->moff);
    free(s->bblk);
    free(s->piv);
    free(s->wswap);
    free(s->border);
    free(s->b1x);
    free(s->b1w);
    free(s->sp_mask);
    free(s->sp_lptr);
    free(s->sp_scale);
    free(s->sp_zmask);
    free(s->sp_ppos);
    free(s);
}

void hyd_solver_reset(hyd_solver* s) {
    if (!s) return;
    s->j_valid = 0;
    s->j_force = 1;
    s->w_valid = 0;
    s->fc_valid = 0;
    s->h_next = 0.0;
    s->have_acc = 0;
    s->last_rejected = 0;
}

void hyd_solver_inputs_changed(hyd_solver* s) {
    if (s) s->fc_valid = 0;
}

void hyd_solver_set_on_step(hyd_solver* s, void (*on_step)(void* user, double t, const double* y), void* user) {
    s->o.on_step = on_step;
    s->o.on_step_user = user;
}

const hyd_solver_stats* hyd_solver_get_stats(const hyd_solver* s) { return &s->st; }
void hyd_solver_clear_stats(hyd_solver* s) { memset(&s->st, 0, sizeof s->st); }
double hyd_solver_last_h(const hyd_solver* s) { return s->last_h; }

const char* hyd_error_text(int code) {
    switch (code) {
    case HYD_OK: return "no error";
    case HYD_ERR_RHS: return "the right-hand side or Jacobian reported a failure";
    case HYD_ERR_SINGULAR: return "the iteration matrix W = I - gamma h J is singular";
    case HYD_ERR_NONFINITE: return "a state became NaN or infinite";
    case HYD_ERR_HMIN: return "the step size fell below its minimum (the error test kept failing)";
    case HYD_ERR_STEPS: return "the step budget ran out (more than max_steps steps in one call)";
    case HYD_ERR_DOMAIN: return "every step tried left the states' domain";
    default: return "unknown solver error";
    }
}

int hyd_solver_bad_state(const hyd_solver* s, double* t_bad) {
    if (t_bad) *t_bad = s->bad_t;
    return s->bad_i;
}

// ------------------------------------------------------- f, J and W upkeep --

int hydEvalF(hyd_solver* s, double t, const double* y, double* dydt) {
    s->st.fevals++;
    return s->p->f(s->p->user, t, y, dydt) == 0 ? HYD_OK : HYD_ERR_RHS;
}

static void mark_jacobian(hyd_solver* s, double t);

// Typical size of a state for the finite-difference increment: below
// atol / rtol the error test is absolute (atol + rtol |y| ~ atol), so that is
// the size from which on a state is resolved at all. With rtol = 0 or
// atol = 0 the tolerances say nothing about a scale: 1 (the unit floor of
// the textbook increment). docs/solvers.md, "Finite-difference Jacobian".
static double fd_typical(const hyd_solver_opts* o) {
    const double typ = o->rtol > 0.0 ? o->atol / o->rtol : 0.0;
    return typ > 0.0 && typ <= DBL_MAX ? typ : 1.0;
}

// J by the callback, or by forward differences with the per-column step
// sqrt(eps) max(|y_j|, atol / rtol); only the diagonal blocks are kept.
static int eval_jacobian(hyd_solver* s, double t, const double* y, const double* f0,
                         double h) {
    const hyd_problem* p = s->p;
    const int n = s->n;
    if (p->jac) {
        if (!p->jac_full) memset(s->jfull, 0, (size_t)n * (size_t)n * sizeof *s->jfull);
        if (p->jac(p->user, t, y, s->jfull) != 0) return HYD_ERR_RHS;
        if (s->jfull != s->jb) {
            for (int b = 0; b < s->nblock; ++b) {
                const int o = s->boff[b], m = s->boff[b + 1] - o;
                double* jb = s->jb + s->moff[b];
                for (int i = 0; i < m; ++i)
                    for (int j = 0; j < m; ++j) jb[i * m + j] = s->jfull[(o + i) * n + o + j];
            }
        }
    } else {
        // sqrt(eps) times the state's own size balances truncation (f'' d)
        // against rounding (eps |f| / d). The old floor of 1 made d = 1.5e-8
        // for a state of 1e-13 (ROBER's y2 at t = 1e11): a difference
        // across 1e5 times the state, and results with 1 or 2 correct digits.
        const double sq = sqrt(DBL_EPSILON), typ = fd_typical(&s->o);
        memcpy(s->fdy, y, (size_t)n * sizeof *y);
        for (int j = 0; j < n; ++j) {
            const double yj = y[j];
            s->fdy[j] = yj + sq * fmax(fabs(yj), typ);
            double d = s->fdy[j] - yj; // the step actually represented
            if (!(d != 0.0)) { // a floor below the resolution of yj (or NaN): the unit floor
                s->fdy[j] = yj + sq * fmax(fabs(yj), 1.0);
                d = s->fdy[j] - yj;
            }
            int rc = hydEvalF(s, t, s->fdy, s->fdf);
            s->fdy[j] = yj;
            if (rc != HYD_OK) return rc;
            const int b = s->bblk[j], o = s->boff[b], m = s->boff[b + 1] - o;
            double* jb = s->jb + s->moff[b];
            const double id = 1.0 / d;
            for (int i = 0; i < m; ++i) jb[i * m + (j - o)] = (s->fdf[o + i] - f0[o + i]) * id;
        }
    }
    // Only a classical Rosenbrock method needs df/dt (see rosenbrock.c).
    if (s->tab.needs_dfdt && !p->autonomous) {
        if (p->dfdt) {
            if (p->dfdt(p->user, t, y, s->ft) != 0) return HYD_ERR_RHS;
        } else {
            // Forward difference, kept inside the step so f is never asked
            // for a time beyond the step's end (t_end of an advance).
            const double dt = fmin(sqrt(DBL_EPSILON) * fmax(fabs(t), 1.0), 0.5 * h);
            const double t1 = t + dt;
            int rc = hydEvalF(s, t1, y, s->fdf);
            if (rc != HYD_OK) return rc;
            const double id = 1.0 / (t1 - t);
            for (int i = 0; i < n; ++i) s->ft[i] = (s->fdf[i] - f0[i]) * id;
        }
    }
    mark_jacobian(s, t);
    s->w_valid = 0;
    return HYD_OK;
}

// A new Jacobian is due: none yet, forced (reset, rejection), too many steps
// or too much simulated time since the last one, or (hyd_problem.events)
// f switched since it was taken. The event count of (t, y) is kept in
// ev_now for mark_jacobian.
static int jacobian_due(hyd_solver* s, double t, const double* y) {
    const hyd_solver_opts* o = &s->o;
    const int every = o->jac_every > 1 ? o->jac_every : 1;
    int due = !s->j_valid || s->j_force || s->j_steps >= every ||
              (o->jac_max_age > 0.0 && fabs(t - s->j_t) > o->jac_max_age);
    if (s->p->events && every > 1) {
        s->ev_now = s->p->events(s->p->user, t, y);
        if (!due && s->ev_now != s->j_events) {
            due = 1;
            s->st.jevents++;
        }
    }
    return due;
}

// Bookkeeping of a new J taken at time t.
static void mark_jacobian(hyd_solver* s, double t) {
    s->st.jevals++;
    s->j_valid = 1;
    s->j_force = 0;
    s->j_steps = 0;
    s->j_t = t;
    s->j_events = s->ev_now;
}

int hydPrepareW(hyd_solver* s, double t, const double* y, const double* f0, double gh) {
    const hyd_solver_opts* o = &s->o;
    if (jacobian_due(s, t, y)) {
        if (s->sp_on) {
            // State scales for the sparse LU's pivot test (lu.c): the error
            // weights, so the test is blind to the states' units.
            for (int i = 0; i < s->n; ++i) {
                const double d = o->atol + o->rtol * fabs(y[i]);
                s->sp_scale[i] = d > 0.0 && d <= DBL_MAX ? 1.0 / d : 1.0;
            }
        }
        int rc = eval_jacobian(s, t, y, f0, s->tab.gamma > 0.0 ? gh / s->tab.gamma : gh);
        if (rc != HYD_OK) return rc;
    }
    // W depends on h. A relative change below 1e-8 (a last step landing on an
    // output time up to rounding) keeps the old W: for a W-method that is just
    // another approximate J, and the stage algebra stays consistent with it.
    if (!s->w_valid || fabs(gh - s->w_gh) > 1e-8 * fabs(gh)) {
        int rc = hydFactorW(s, gh);
        if (rc != HYD_OK) {
            s->w_valid = 0;
            return rc;
        }
    }
    return HYD_OK;
}

// ------------------------------------------------------------------ steps --

// Index of the first NaN/Inf in v, or -1. x * 0 is 0 for finite x and NaN
// otherwise, so one sum answers for the whole vector without a branch per entry.
static int first_nonfinite(const double* v, int n) {
    double acc = 0.0;
    for (int i = 0; i < n; ++i) acc += v[i] * 0.0;
    if (acc == 0.0) return -1;
    for (int i = 0; i < n; ++i)
        if (!isfinite(v[i])) return i;
    return -1;
}

static int trial_step(hyd_solver* s, double t, const double* y, const double* f0, double h,
                      double* ynew, double* err) {
    switch (s->method) {
    case HYD_KRUS:
    case HYD_ROS2: return hydKrusStep(s, t, y, f0, h, ynew);
    case HYD_RK4: return hydRk4Step(s, t, y, f0, h, ynew);
    case HYD_ROS34PW2:
    case HYD_RODAS3: return hydRosenbrockStep(s, t, y, f0, h, ynew, err);
    default: return HYD_ERR_RHS;
    }
}

// f at (t, y): the cached value from the previous accepted adaptive step when
// the caller has not moved t or y since, else a fresh evaluation.
static int current_f(hyd_solver* s, double t, const double* y, const double** f0) {
    const int n = s->n;
    if (!(s->fc_valid && s->fc_t == t && memcmp(s->fc_y, y, (size_t)n * sizeof *y) == 0)) {
        int rc = hydEvalF(s, t, y, s->fc_f);
        if (rc != HYD_OK) return rc;
        memcpy(s->fc_y, y, (size_t)n * sizeof *y);
        s->fc_t = t;
        s->fc_valid = 1;
    }
    *f0 = s->fc_f;
    return HYD_OK;
}

// One trial of a fixed step of h from (t, y) into ynew, nothing committed.
// force_j: take a new J whatever the schedule says (a retry). Returns
// HYD_OK, an error of f or W, HYD_ERR_NONFINITE (bad_i, bad_t set) or
// HYD_ERR_DOMAIN (a finite state hyd_problem.implausible refuses; bad_i, bad_t set).
static int fixed_trial(hyd_solver* s, double t, const double* y, double h, double t_new, int force_j,
                       double* ynew) {
    const int n = s->n;
    int rc;
    if (force_j) s->j_force = 1;
    const int ws = s->p->wstep && (s->method == HYD_KRUS || s->method == HYD_ROS2);
    if (ws) {
        // The problem's own step kernel (hyd_problem.wstep).
        const int need_j = jacobian_due(s, t, y);
        rc = s->p->wstep(s->p->user, t, y, h, hydKrusGamma(s->method), need_j, ynew);
        if (rc < 0) return rc;
        s->st.fevals += 2;
        s->st.lus += rc;
        if (need_j) mark_jacobian(s, t);
    } else {
        // Fixed-step methods never leave f(t_{n+1}, y_{n+1}) behind, so skip
        // the cache check (and its copy of y) unless an adaptive run just
        // filled it.
        const double* f0 = s->fc_f;
        rc = s->fc_valid ? current_f(s, t, y, &f0) : hydEvalF(s, t, y, s->fc_f);
        if (rc != HYD_OK) return rc;
        s->fc_valid = 0; // f0 is of (t, y): a retry from the same point re-evaluates it anyway
        rc = trial_step(s, t, y, f0, h, ynew, NULL);
        if (rc != HYD_OK) return rc;
    }
    s->last_wstep = ws;
    const int bad = first_nonfinite(ynew, n);
    if (bad >= 0) {
        s->bad_i = bad;
        s->bad_t = t_new;
        return HYD_ERR_NONFINITE;
    }
    // Only a retry can do anything about an implausible state, so the test
    // costs nothing when retries are off.
    if (s->o.retry_halvings > 0 && s->p->implausible) {
        const int out = s->p->implausible(s->p->user, ynew);
        if (out) {
            s->bad_i = out - 1;
            s->bad_t = t_new;
            return HYD_ERR_DOMAIN;
        }
    }
    return HYD_OK;
}

// A failed fixed step of h from (t, y) taken again as 2, 4, ... 2^L
// sub-steps (L = retry_halvings), each with a fresh J: a stiff transient
// (a relief or a shuttle switching within one step, a mode with h lambda
// near 1/gamma that makes W singular) is legitimate physics the step is
// merely too long for. The first level whose sub-steps all pass gives the
// new state in ynew. rc0 is the full step's failure. Returns HYD_OK, or
// the failure of the finest level; a finest level that failed only by an
// implausible state (finite, W regular) is accepted with that state, as
// the full step was before retries existed: the caller's checks report it
// (the crane's runs fail there, naming the state and time). The sub-steps' own times are t + k h / m (the last
// one lands on t_new exactly).
static int fixed_retry(hyd_solver* s, double t, const double* y, double h, double t_new, int rc0,
                       double* ynew) {
    const int n = s->n;
    double* ysub = s->yout; // unused by the fixed-step methods
    int rc = rc0;
    s->st.retried++;
    for (int level = 1; level <= s->o.retry_halvings; ++level) {
        const int m = 1 << level;
        const double hs = h / m;
        memcpy(ysub, y, (size_t)n * sizeof *y);
        double ts = t;
        rc = HYD_OK;
        for (int i = 1; i <= m; ++i) {
            const double tn = i == m ? t_new : t + (double)i * hs;
            s->st.substeps++;
            rc = fixed_trial(s, ts, ysub, tn - ts, tn, 1, ynew);
            if (rc == HYD_ERR_DOMAIN && level == s->o.retry_halvings) rc = HYD_OK; // see above
            else if (rc != HYD_OK)
                break;
            memcpy(ysub, ynew, (size_t)n * sizeof *y);
            ts = tn;
        }
        if (rc == HYD_OK) {
            memcpy(ynew, ysub, (size_t)n * sizeof *y);
            s->last_split = 1;
            return HYD_OK;
        }
        if (rc == HYD_ERR_RHS) return rc;
    }
    return rc;
}

// One fixed step with the bookkeeping shared by step() and the fixed driver.
// On failure y and t are untouched.
static int fixed_step(hyd_solver* s, double* t, double* y, double h, double t_new) {
    const int n = s->n;
    s->last_split = 0;
    int rc = fixed_trial(s, *t, y, h, t_new, 0, s->ynew);
    if (rc != HYD_OK && rc != HYD_ERR_RHS && s->o.retry_halvings > 0) rc = fixed_retry(s, *t, y, h, t_new, rc, s->ynew);
    if (rc != HYD_OK) return rc;
    memcpy(y, s->ynew, (size_t)n * sizeof *y);
    *t = t_new;
    s->fc_valid = 0;
    s->st.steps++;
    s->j_steps++;
    s->last_h = h;
    if (s->p->settle) s->p->settle(s->p->user, *t, y);
    return HYD_OK;
}

int hyd_solver_step(hyd_solver* s, double* t, double* y, double h) {
    if (!s || !t || !y || !(h > 0.0)) return HYD_ERR_HMIN;
    return fixed_step(s, t, y, h, *t + h);
}

static int advance_fixed(hyd_solver* s, double* t, double* y, double t_end, long* budget) {
    const double h0 = s->o.h, t0 = *t;
    // Times as t0 + k h0, not summed step by step: over a long segment (a
    // 1 s output period is 10,000 steps of 0.1 ms) the summed rounding grows
    // past the landing tolerance below and leaves a sliver step at the end.
    for (long k = 1; *t < t_end; ++k) {
        if (*budget <= 0) return HYD_ERR_STEPS;
        --*budget;
        // Land exactly on t_end; a remainder within 1e-9 h of a full step is
        // taken as that step, so rounding never leaves a sliver step behind.
        const double rem = t_end - *t;
        const int land = rem <= h0 * (1.0 + 1e-9);
        int rc = fixed_step(s, t, y, land ? rem : h0, land ? t_end : t0 + (double)k * h0);
        if (rc != HYD_OK) return rc;
        if (s->o.on_step) s->o.on_step(s->o.on_step_user, *t, y);
    }
    return HYD_OK;
}

// ------------------------------------------------------- adaptive driver --

// Output schedule of hyd_solver_integrate: t0 + k dt for k = 1 .. nseg-1, then
// t_end itself.
typedef struct out_sched {
    hyd_output_fn fn;
    void* user;
    double t0, dt, t_end;
    long k, nseg;
    int stopped;
} out_sched;

static double sched_time(const out_sched* o) {
    return o->k >= o->nseg ? o->t_end : o->t0 + (double)o->k * o->dt;
}

static double err_norm(const hyd_solver* s, const double* y, const double* ynew,
                       const double* e) {
    const double atol = s->o.atol, rtol = s->o.rtol;
    double sum = 0.0;
    for (int i = 0; i < s->n; ++i) {
        const double a = fabs(y[i]), b = fabs(ynew[i]);
        double sc = atol + rtol * (a > b ? a : b); // not fmax: a libm call here
        double r = e[i] / sc;
        sum += r * r;
    }
    return sqrt(sum / s->n);
}

static double rms_scaled(const hyd_solver* s, const double* v, const double* y) {
    double sum = 0.0;
    for (int i = 0; i < s->n; ++i) {
        double r = v[i] / (s->o.atol + s->o.rtol * fabs(y[i]));
        sum += r * r;
    }
    return sqrt(sum / s->n);
}

// Starting step after create or reset when opts.h is 0 (Hairer, Norsett &
// Wanner, I, II.4): balance h against |y|/|f| and a second-derivative estimate.
static int initial_step(hyd_solver* s, double t, const double* y, const double* f0,
                        double h_cap, double* h_out) {
    const int n = s->n;
    const double q = 3.0;
    double d0 = rms_scaled(s, y, y), d1 = rms_scaled(s, f0, y);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    h0 = fmin(h0, h_cap);
    for (int i = 0; i < n; ++i) s->ys[i] = y[i] + h0 * f0[i];
    int rc = hydEvalF(s, t + h0, s->ys, s->fs);
    if (rc != HYD_OK) return rc;
    for (int i = 0; i < n; ++i) s->r[i] = (s->fs[i] - f0[i]) / h0;
    double d2 = rms_scaled(s, s->r, y);
    double dm = fmax(d1, d2);
    double h1 = dm <= 1e-15 ? fmax(1e-6, h0 * 1e-3) : pow(0.01 / dm, 1.0 / q);
    double h = fmin(100.0 * h0, h1);
    if (!(h > 0.0) || !isfinite(h)) h = 1e-6;
    *h_out = fmin(h, h_cap);
    return HYD_OK;
}

// Cubic Hermite interpolation on [t, t + h] from y0, f0, y1, f1, in powers of
// theta: p = y0 + theta (c1 + theta (c2 + theta c3)) with
//   c1 = h f0,  c2 = 3 d - h (2 f0 + f1),  c3 = -2 d + h (f0 + f1),  d = y1 - y0.
// The coefficients are formed once per step that has outputs in it (an
// adaptive step spans up to a few dozen 1 kHz output times), so each output
// costs three multiply-adds per state. idx lists the states to interpolate
// (m of them; NULL: states 0 .. m-1). The buffers never overlap (restrict).
static void hermite_prepare(int m, const int* restrict idx, double h, const double* restrict y0,
                            const double* restrict f0, const double* restrict y1,
                            const double* restrict f1, double* restrict c1, double* restrict c2,
                            double* restrict c3) {
    for (int k = 0; k < m; ++k) {
        const int i = idx ? idx[k] : k;
        const double d = y1[i] - y0[i], a = h * f0[i], b = h * f1[i];
        c1[i] = a;
        c2[i] = 3.0 * d - (2.0 * a + b);
        c3[i] = (a + b) - 2.0 * d;
    }
}

static void hermite(int m, const int* restrict idx, double theta, const double* restrict y0,
                    const double* restrict c1, const double* restrict c2, const double* restrict c3,
                    double* restrict out) {
    for (int k = 0; k < m; ++k) {
        const int i = idx ? idx[k] : k;
        out[i] = y0[i] + theta * (c1[i] + theta * (c2[i] + theta * c3[i]));
    }
}

// Output at y0 + theta (y1 - y0) inside an accepted step: the cubic Hermite
// interpolant, unless it leaves the problem's domain, which it can between
// two admissible end points (a pressure near zero at a loose tolerance:
// -2.5 kPa on `overload` with ROS34PW2 at rtol 1e-2). The chord cannot,
// the domain (absolute pressures >= 0) being convex, so it is used then.
static void interpolate(const hyd_solver* s, int m, const int* idx, double theta, const double* y0,
                        const double* y1, double* out) {
    hermite(m, idx, theta, y0, s->hc[0], s->hc[1], s->hc[2], out);
    if (!s->p->outside || !s->p->outside(s->p->user, out)) return;
    for (int k = 0; k < m; ++k) {
        const int i = idx ? idx[k] : k;
        out[i] = y0[i] + theta * (y1[i] - y0[i]);
    }
}

static int advance_adaptive(hyd_solver* s, double* t, double* y, double t_end, long* budget,
                            out_sched* os) {
    const int n = s->n;
    // The error of the order-2 embedded solution is O(h^3): the controller
    // exponents are 1/3 (cbrt below).
    const double h_max = s->o.h_max > 0.0 ? s->o.h_max : HUGE_VAL;
    while (*t < t_end) {
        if (*budget <= 0) return HYD_ERR_STEPS;
        const double* f0;
        int rc = current_f(s, *t, y, &f0);
        if (rc != HYD_OK) return rc;
        if (!(s->h_next > 0.0)) {
            if (s->o.h > 0.0) {
                s->h_next = s->o.h;
            } else {
                rc = initial_step(s, *t, y, f0, fmin(h_max, t_end - *t), &s->h_next);
                if (rc != HYD_OK) return rc;
            }
        }
        const double h_prop = fmin(s->h_next, h_max);
        const double rem = t_end - *t;
        const int land = h_prop >= rem;
        const double h = land ? rem : h_prop;

        rc = trial_step(s, *t, y, f0, h, s->ynew, s->err);
        if (rc == HYD_ERR_RHS) return rc;
        const int singular = rc == HYD_ERR_SINGULAR;
        const int bad = singular ? -1 : first_nonfinite(s->ynew, n);
        // A finite trial outside the problem's domain: rejected like a
        // non-finite one (largest cut), never accepted on its error estimate.
        const int out = singular || bad >= 0 || !s->p->outside ? 0 : s->p->outside(s->p->user, s->ynew);
        if (out) s->st.outside++;
        double en = (singular || bad >= 0 || out) ? HUGE_VAL : err_norm(s, y, s->ynew, s->err);
        if (!(en <= 1.0)) {
            // Reject. A singular W or a non-finite trial gets the largest cut.
            s->st.rejected++;
            double ratio = isfinite(en) ? fmax(1.0 / 6.0, 0.9 / cbrt(en)) : 1.0 / 6.0;
            s->h_next = h * ratio;
            s->last_rejected = 1;
            if (s->j_steps > 0) s->j_force = 1; // a stale J may be the cause
            if (!(s->h_next >= fmax(fmax(s->o.h_min, 16.0 * DBL_EPSILON * fabs(*t)), DBL_MIN))) {
                if (bad >= 0 || out) {
                    s->bad_i = bad >= 0 ? bad : out - 1;
                    s->bad_t = *t + h;
                    return bad >= 0 ? HYD_ERR_NONFINITE : HYD_ERR_DOMAIN;
                }
                return singular ? HYD_ERR_SINGULAR : HYD_ERR_HMIN;
            }
            continue;
        }

        // Accept. f at the new point serves the Hermite output and the next
        // step's first stage.
        --*budget;
        const double t_new = land ? t_end : *t + h;
        rc = hydEvalF(s, t_new, s->ynew, s->fnew);
        if (rc != HYD_OK) return rc;
        if (os) {
            int prepared = 0;
            while (!os->stopped && os->k <= os->nseg && sched_time(os) <= t_new) {
                const double to = sched_time(os);
                const double* yo = s->ynew;
                if (to < t_new) {
                    // Only the states the callback reads (opts.out_states), else all.
                    const int* idx = s->o.n_out_states > 0 ? s->o.out_states : NULL;
                    const int m = idx ? s->o.n_out_states : n;
                    if (!prepared) {
                        hermite_prepare(m, idx, h, y, f0, s->ynew, s->fnew, s->hc[0], s->hc[1], s->hc[2]);
                        prepared = 1;
                    }
                    interpolate(s, m, idx, (to - *t) / h, y, s->ynew, s->yout);
                    yo = s->yout;
                }
                os->k++;
                if (os->fn(os->user, to, yo) != 0) {
                    // Stop at the output time: hand back that state, in
                    // full (the callback may have seen only some states).
                    os->stopped = 1;
                    if (yo == s->yout && s->o.n_out_states > 0) {
                        hermite_prepare(n, NULL, h, y, f0, s->ynew, s->fnew, s->hc[0], s->hc[1], s->hc[2]);
                        interpolate(s, n, NULL, (to - *t) / h, y, s->ynew, s->yout);
                    }
                    memcpy(y, yo, (size_t)n * sizeof *y);
                    *t = to;
                    s->fc_valid = 0;
                    s->h_next = h;
                    return HYD_OK;
                }
            }
        }

        // Hairer-Wanner controller with Gustafsson's predictive correction.
        double e = fmax(en, 1e-10);
        double ratio = 0.9 / cbrt(e); // e^(-1/q), q = 3: cbrt is a third of pow's cost
        if (s->have_acc) {
            double gus = 0.9 * (h / s->h_acc) * cbrt(s->err_acc / (e * e));
            ratio = fmin(ratio, gus);
        }
        ratio = fmin(5.0, fmax(1.0 / 6.0, ratio));
        if (s->last_rejected) ratio = fmin(ratio, 1.0);
        double h_new = h * ratio;
        // A step cut short only to land on t_end says nothing against the
        // proposal it replaced; frame boundaries must not throttle h.
        if (land && !s->last_rejected) h_new = fmax(h_new, h_prop);
        // Hysteresis: a modest growth is not worth a new LU of W.
        else if (s->o.h_hold > 0.0 && h_new >= h && h_new <= h * (1.0 + s->o.h_hold)) h_new = h;
        s->h_acc = h;
        s->err_acc = fmax(1e-2, en);
        s->have_acc = 1;
        s->last_rejected = 0;
        s->h_next = h_new;

        memcpy(y, s->ynew, (size_t)n * sizeof *y);
        memcpy(s->fc_y, y, (size_t)n * sizeof *y);
        double* tmp = s->fc_f;
        s->fc_f = s->fnew;
        s->fnew = tmp;
        s->fc_t = t_new;
        s->fc_valid = 1;
        // A settled state: f there is not the one just computed.
        if (s->p->settle && s->p->settle(s->p->user, t_new, y)) s->fc_valid = 0;
        *t = t_new;
        s->st.steps++;
        s->j_steps++;
        s->last_h = h;
        if (s->o.on_step) s->o.on_step(s->o.on_step_user, *t, y);
    }
    return HYD_OK;
}

// ----------------------------------------------------------------- drivers --

static long step_budget(const hyd_solver* s) { return s->o.max_steps > 0 ? s->o.max_steps : LONG_MAX; }

int hyd_solver_advance(hyd_solver* s, double* t, double* y, double t_end) {
    if (!s || !t || !y) return HYD_ERR_RHS;
    long budget = step_budget(s);
    if (hyd_method_is_adaptive(s->method)) return advance_adaptive(s, t, y, t_end, &budget, NULL);
    return advance_fixed(s, t, y, t_end, &budget);
}

int hyd_solver_integrate(hyd_solver* s, double t0, double* y, double t_end, double dt_out,
                         hyd_output_fn out, void* user) {
    if (!s || !y || !(dt_out > 0.0) || !(t_end >= t0)) return HYD_ERR_RHS;
    out_sched os = {out, user, t0, dt_out, t_end, 1, 0, 0};
    // Output intervals; a last one shorter than 1e-9 dt_out merges into the one before.
    double nint = (t_end - t0) / dt_out;
    os.nseg = (long)ceil(nint - 1e-9);
    if (os.nseg < 1) os.nseg = 1;
    if (out && out(user, t0, y) != 0) return HYD_OK;
    if (t_end == t0) return HYD_OK;

    long budget = step_budget(s);
    double t = t0;
    if (hyd_method_is_adaptive(s->method)) {
        if (!out) return advance_adaptive(s, &t, y, t_end, &budget, NULL);
        return advance_adaptive(s, &t, y, t_end, &budget, &os);
    }
    // Fixed steps land on every output time; with dt_out a multiple of h that
    // costs nothing.
    for (long k = 1; k <= os.nseg; ++k) {
        double tk = k >= os.nseg ? t_end : t0 + (double)k * dt_out;
        int rc = advance_fixed(s, &t, y, tk, &budget);
        if (rc != HYD_OK) return rc;
        if (out && out(user, tk, y) != 0) return HYD_OK;
    }
    return HYD_OK;
}
