// lsim_split.h: what both split Krus/ROS2 steps share (lagrange_split_step.c
// for the standard circuit on the one-pass kernel, lagrange_split_gen.c for
// any circuit on the fast kernel): the mechanics once per step at the
// predicted midpoint, carried to each stage by Taylor series, the mechanics
// rows of f from there, and the closed-form W^-1 of the 1x1 and 2x2 blocks.
// The scheme and its error bounds: lagrange_split_step.c and docs/lagrange.md,
// "Split Krus step". Internal to src/world.
#ifndef LSIM_SPLIT_H
#define LSIM_SPLIT_H

#include <float.h>
#include <math.h>

#include "lagrange_sim.h"
#include "lsim_kin.h"

// Mechanics at the step's predicted midpoint.
typedef struct lsim_geo {
    double qm[2];
    double trig[4]; ///< sin q1, cos q1, sin q2, cos q2 at qm
    kin k;          ///< x, r, dr at qm (k.v unused)
} lsim_geo;

// sin and cos of the midpoint angles. From one step's midpoint to the next
// the angles move by |e| = h |q'| + O(h^2), about 1e-5 rad at h = 0.1 ms,
// so the addition identities with short series for sin e and cos e
// (remainders e^7/5040 and e^6/720, below 1.5e-21 for |e| < 1e-3) replace
// the two sincos calls. Each rotation rounds to about an ulp; the anchor is
// a fresh sincos at every new Jacobian (every jac_every steps), so the
// drift stays within a few ulp.
static inline void lsim_midpoint_trig(lsim_ks* ks, const double* qm, double* trig) {
    const double e0 = qm[0] - ks->qa[0], e1 = qm[1] - ks->qa[1];
    if (ks->have_anchor && fabs(e0) < 1e-3 && fabs(e1) < 1e-3) {
        const double e[2] = {e0, e1};
        for (int j = 0; j < 2; ++j) {
            const double e2 = e[j] * e[j];
            const double se = e[j] * (1.0 - e2 * (1.0 / 6.0 - e2 * (1.0 / 120.0)));
            const double ce = 1.0 - e2 * (0.5 - e2 * (1.0 / 24.0));
            const double sj = ks->sa[j] * ce + ks->ca[j] * se, cj = ks->ca[j] * ce - ks->sa[j] * se;
            trig[2 * j] = ks->sa[j] = sj;
            trig[2 * j + 1] = ks->ca[j] = cj;
        }
    } else {
        lagrange_sincos(qm[0], &trig[0], &trig[1]);
        lagrange_sincos(qm[1], &trig[2], &trig[3]);
        ks->sa[0] = trig[0], ks->ca[0] = trig[1], ks->sa[1] = trig[2], ks->ca[1] = trig[3];
        ks->have_anchor = true;
    }
    ks->qa[0] = qm[0], ks->qa[1] = qm[1];
}

// The midpoint q_m = q_n + (h/2) q'_n of a step from y (q = y[iq], y[iq+1],
// q' = y[iq+2], y[iq+3]), its sines and the cylinder kinematics there.
static inline void lsim_geo_at(lsim* s, const double* y, int iq, double h, lsim_geo* g) {
    for (int j = 0; j < 2; ++j) g->qm[j] = y[iq + j] + 0.5 * h * y[iq + 2 + j];
    lsim_midpoint_trig(&s->ks, g->qm, g->trig);
    static const double rest[2] = {0.0, 0.0};
    cylinder_kinematics(&s->mdl->mech, g->trig, rest, &g->k);
}

// The mechanics at a stage's q = q_m + d (q = y[iq], y[iq+1]) by Taylor
// series from the midpoint:
//   x(q_m + d) = x_m + d (r_m + d r'_m / 2),  r(q_m + d) = r_m + d r'_m,
//   sin(q_m + d) = sin q_m (1 - d^2/2) + cos q_m d, cos likewise;
// x, v = r q' [m, m/s], r [m/rad] and trig = {sin q1, cos q1, sin q2, cos q2}.
static inline void lsim_geo_carry(const lsim_geo* g, const double* y, int iq, double x[2], double v[2],
                                  double r[2], double trig[4]) {
    const double d[2] = {y[iq] - g->qm[0], y[iq + 1] - g->qm[1]};
    const double* qd = y + iq + 2;
    for (int i = 0; i < 2; ++i) {
        r[i] = g->k.r[i] + g->k.dr[i] * d[i];
        x[i] = g->k.x[i] + d[i] * (g->k.r[i] + 0.5 * g->k.dr[i] * d[i]);
        v[i] = r[i] * qd[i];
    }
    const double* tm = g->trig;
    const double e0 = 1.0 - 0.5 * d[0] * d[0], e1 = 1.0 - 0.5 * d[1] * d[1];
    trig[0] = tm[0] * e0 + tm[1] * d[0], trig[1] = tm[1] * e0 - tm[0] * d[0];
    trig[2] = tm[2] * e1 + tm[3] * d[1], trig[3] = tm[3] * e1 - tm[2] * d[1];
}

// The mechanics rows of f (f = dydt + iq) from the cylinder forces F [N]
// and lever arms r [m/rad] at a stage.
static inline void lsim_split_mech(lsim* s, const double trig[4], const double* qd, const double F[2],
                                   const double r[2], double* f) {
    const double tau[2] = {F[0] * r[0], F[1] * r[1]};
    double qdd[2];
    lagrange_accel_fast(&s->lk, trig, qd, tau, qdd);
    lsim_mech_out(s, qd, qdd, f);
}

// 1 / (1 - gh j), or 0 when W is singular to working precision (the test
// of the solver's own 1x1 blocks, lu.c).
static inline double lsim_inv1(double gh, double j) {
    const double w = 1.0 - gh * j;
    return fabs(w) > DBL_EPSILON * fmax(1.0, fabs(gh * j)) ? 1.0 / w : 0.0;
}

// W^-1 = (I - gh m)^-1 of a 2x2 block m (row-major) into w; -1 when W is
// singular to working precision (the test of lu.c's 2x2 blocks).
static inline int lsim_inv2(double gh, const double* m, double* w) {
    const double a = 1.0 - gh * m[0], b = -gh * m[1], c = -gh * m[2], d = 1.0 - gh * m[3];
    const double det = a * d - b * c;
    if (!(fabs(det) > 4.0 * DBL_EPSILON * fmax(fabs(a * d), fabs(b * c)))) return -1;
    const double id = 1.0 / det;
    w[0] = d * id, w[1] = -b * id, w[2] = -c * id, w[3] = a * id;
    return 0;
}

// W^-1 of the N x N block I - gh m by Gauss-Jordan with partial pivoting; -1
// when a pivot is at or below tol * eps * max|W_ij| (lu.c's test is tol = 1;
// a NaN fails it too). Not
// hyd_lu_factor + four hyd_lu_solve: those general, careful loops cost about
// 1,800 instructions per Jacobian against about 450 here, 5 % of a Krus step
// at one Jacobian per 10 steps (callgrind, 2026-11-23).
// One text for every size: LSIM_INV_BODY(N, NMAX) is the body with N the
// size (a constant for the fixed sizes, so each compiles to the unrolled
// code of a fixed-size inverse; nb for the one variable-size block) and NMAX
// its storage.
#define LSIM_INV_BODY(N, NMAX)                                                                         \
    {                                                                                                  \
        double a[NMAX][2 * NMAX];                                                                      \
        double amax = 0.0;                                                                             \
        for (int i = 0; i < N; ++i)                                                                    \
            for (int j = 0; j < N; ++j) {                                                              \
                a[i][j] = (i == j) - gh * m[i * N + j];                                                \
                a[i][N + j] = i == j;                                                                  \
                if (fabs(a[i][j]) > amax) amax = fabs(a[i][j]);                                        \
            }                                                                                          \
        for (int c = 0; c < N; ++c) {                                                                  \
            int p = c;                                                                                 \
            for (int i = c + 1; i < N; ++i)                                                            \
                if (fabs(a[i][c]) > fabs(a[p][c])) p = i;                                              \
            if (!(fabs(a[p][c]) > tol * DBL_EPSILON * amax)) return -1;                                \
            if (p != c)                                                                                \
                for (int j = 0; j < 2 * N; ++j) {                                                      \
                    const double tmp = a[c][j];                                                        \
                    a[c][j] = a[p][j], a[p][j] = tmp;                                                  \
                }                                                                                      \
            const double inv = 1.0 / a[c][c];                                                          \
            for (int j = 0; j < 2 * N; ++j) a[c][j] *= inv;                                            \
            for (int i = 0; i < N; ++i) {                                                              \
                if (i == c) continue;                                                                  \
                const double l = a[i][c];                                                              \
                for (int j = 0; j < 2 * N; ++j) a[i][j] -= l * a[c][j];                                \
            }                                                                                          \
        }                                                                                              \
        for (int i = 0; i < N; ++i)                                                                    \
            for (int j = 0; j < N; ++j) out[i * N + j] = a[i][N + j];                                  \
        return 0;                                                                                      \
    }
// The 3x3 blocks behind a counterbalance valve (lagrange_split_gen.c).
static inline int lsim_inv3(double gh, const double* m, double* out, double tol) LSIM_INV_BODY(3, 3)
// The mechanics block.
static inline int lsim_inv4(double gh, const double* m, double* out, double tol) LSIM_INV_BODY(4, 4)
// The LS crane's supply block (pump line, displacement, two P nodes, two
// compensator spools), unrolled.
static inline int lsim_inv6(double gh, const double* m, double* out, double tol) LSIM_INV_BODY(6, 6)
#define LSIM_MAX_VBLOCK 8
// A block of nb <= LSIM_MAX_VBLOCK states (the supply block, lagrange_sim.c).
static inline int lsim_invv(int nb, double gh, const double* m, double* out, double tol)
    LSIM_INV_BODY(nb, LSIM_MAX_VBLOCK)
#undef LSIM_INV_BODY

// What both split steps do before their stages: a new J when the solver
// asks or none is held (refresh: -1, or the first state whose block row is
// not finite: that state turns non-finite in ynew and the step is done, as
// the generic step would have it), then W^-1 when gamma h has changed by
// more than 1e-8 relatively (the generic driver's rule; form: HYD_OK or
// an error). Returns 1 when ynew is already the step's result, a negative
// HYD_ERR_* code, else 0 with *nlu the factorisations done (0 or 1).
// Always inlined, so the two callbacks are direct calls.
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline int lsim_step_prepare(lsim* s, double t, const double* y, double gh, int new_jac, int n,
                                    double* ynew, int (*refresh)(lsim*, double, const double*),
                                    int (*form)(lsim*, double), int* nlu) {
    lsim_ks* ks = &s->ks;
    *nlu = 0;
    if (new_jac || !ks->have_j) {
        ks->cmd_t = NAN; // after a reset the commands may have been changed
        ks->have_anchor = false;
        const int bad = refresh(s, t, y);
        if (bad >= 0) {
            for (int i = 0; i < n; ++i) ynew[i] = y[i];
            ynew[bad] = NAN;
            return 1;
        }
    }
    if (ks->gh == 0.0 || fabs(gh - ks->gh) > 1e-8 * fabs(gh)) {
        const int rc = form(s, gh);
        if (rc != HYD_OK) {
            ks->gh = 0.0;
            return rc;
        }
        *nlu = 1;
    }
    return 0;
}

#endif
