// lagrange_split_step.c: the split Krus / ROS2 step for the crane (hyd_problem.wstep).
//
// The same W-method as krus.c (docs/solvers.md),
//   W k1 = h f(t, y),  W k2 = h f(t + h, y + k1) - 2 (k1 - h f(t, y)),
//   y_new = y + (k1 + k2) / 2,  W = I - gamma h J,
// with the same block-diagonal J (spool, [hose, chamber] x 2 per actuator,
// pump line, [q1, q2, q1', q2']), but with the mechanics evaluated once per
// step, where most of a step's time went:
//
// - At the predicted midpoint q_m = q_n + (h/2) q'_n the kernel takes the
//   sines and cosines (rotated on from the previous midpoint, see
//   midpoint_trig), the cylinder kinematics (Eq. 5: a square root and two
//   divisions per cylinder) and nothing else.
// - Each stage carries them to its own q = q_m + d by Taylor series:
//     sin(q_m + d) = sin q_m (1 - d^2/2) + cos q_m d,  cos likewise,
//     x(q_m + d) = x_m + d (r_m + d r'_m / 2),   r(q_m + d) = r_m + d r'_m,
//   with r = dx/dq and r' = d^2x/dq^2 at q_m. Then f at the stage is the
//   exact circuit (hyd_fused_eval) and the exact mass-matrix solve on these
//   values.
//
// |d| <= (h/2)|q'| + O(h^2): at h = 0.1 ms and the crane's joint rates
// (< 0.5 rad/s), |d| < 3e-5 rad, so the sines err by |d|^3/6 < 5e-15, the
// stroke by |x'''| |d|^3/6 and the lever arm r by |x'''| d^2/2 (below
// 1e-9 m/rad). Formally f at each stage is off by O(h^2) (the lever arm), the
// local error of the step stays O(h^3), and the method stays of order 2
// (docs/lagrange.md, "Split Krus step"; tests/lagrange/test_split.c measures
// the order and the distance from the whole-f step).
//
// W^-1 of every block is formed explicitly when J or gamma h changes (1x1
// and 2x2 in closed form with the tests of the solver's block path, lu.c;
// the 4x4 mechanics block by Gauss-Jordan with partial pivoting), so each
// solve is a handful of multiply-adds fused with the stage update. The
// solver's own block solve (hydSolveW) would do the same algebra in about
// 280 instructions a solve against 120 here.
#include "lagrange_sim.h"
#include "lsim_kin.h"

#include <float.h>
#include <math.h>
#include <string.h>

enum { IPL = 10, IQ = 11, NS = 15 };

// Mechanics at the step's predicted midpoint.
typedef struct geo {
    double qm[2];
    double trig[4]; ///< sin q1, cos q1, sin q2, cos q2 at qm
    kin k;          ///< x, r, dr at qm (k.v unused)
} geo;

// sin and cos of the midpoint angles. From one step's midpoint to the next
// the angles move by |e| = h |q'| + O(h^2), about 1e-5 rad at h = 0.1 ms,
// so the addition identities with short series for sin e and cos e
// (remainders e^7/5040 and e^6/720, below 1.5e-21 for |e| < 1e-3) replace
// the two sincos calls. Each rotation rounds to about an ulp; the anchor is
// a fresh sincos at every new Jacobian (every jac_every steps), so the
// drift stays within a few ulp.
static void midpoint_trig(lsim_ks* ks, const double* qm, double* trig) {
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

static void geo_at(lsim* s, const double* y, double h, geo* g) {
    for (int j = 0; j < 2; ++j) g->qm[j] = y[IQ + j] + 0.5 * h * y[IQ + 2 + j];
    midpoint_trig(&s->ks, g->qm, g->trig);
    static const double rest[2] = {0.0, 0.0};
    cylinder_kinematics(&s->mdl->mech, g->trig, rest, &g->k);
}

// Valve commands at t (lsim_commands: stage 2 of one step and stage 1 of
// the next share t, so the scenario's tables are read once per step).
static void commands_at(lsim* s, double t, double cmd[2]) { lsim_commands(s, t, cmd); }

// f at a stage (t, y) with the mechanics carried from the midpoint.
static void stage_f(lsim* s, const geo* g, double t, const double* y, double* f) {
    const double d[2] = {y[IQ] - g->qm[0], y[IQ + 1] - g->qm[1]};
    const double* qd = y + IQ + 2;
    double x[2], v[2], r[2], cmd[2], F[2];
    for (int i = 0; i < 2; ++i) {
        r[i] = g->k.r[i] + g->k.dr[i] * d[i];
        x[i] = g->k.x[i] + d[i] * (g->k.r[i] + 0.5 * g->k.dr[i] * d[i]);
        v[i] = r[i] * qd[i];
    }
    commands_at(s, t, cmd);
    hyd_fused_eval2(&s->fz, y, x, v, cmd, f, F);

    const double* tm = g->trig;
    const double e0 = 1.0 - 0.5 * d[0] * d[0], e1 = 1.0 - 0.5 * d[1] * d[1];
    const double trig[4] = {tm[0] * e0 + tm[1] * d[0], tm[1] * e0 - tm[0] * d[0],
                            tm[2] * e1 + tm[3] * d[1], tm[3] * e1 - tm[2] * d[1]};
    const double tau[2] = {F[0] * r[0], F[1] * r[1]};
    double qdd[2];
    lagrange_accel_fast(&s->lk, trig, qd, tau, qdd);
    lsim_mech_out(s, qd, qdd, f + IQ);
}

// The diagonal blocks of J at (t, y), from the fused analytic Jacobian.
// Returns -1, or the first state whose block row is not finite.
static int refresh_j(lsim* s, double t, const double* y) {
    double J[NS * NS];
    lsim_jac_fused(s, t, y, J);
    lsim_ks* ks = &s->ks;
    for (int k = 0; k < 2; ++k) {
        const int b = 5 * k;
        ks->ju[k] = J[b * NS + b];
        for (int c = 0; c < 2; ++c) {
            const int i = b + 1 + 2 * c; // hose; its chamber is i + 1
            double* m = ks->jh[k][c];
            m[0] = J[i * NS + i], m[1] = J[i * NS + i + 1];
            m[2] = J[(i + 1) * NS + i], m[3] = J[(i + 1) * NS + i + 1];
        }
    }
    ks->jpl = J[IPL * NS + IPL];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) ks->jm[i * 4 + j] = J[(IQ + i) * NS + IQ + j];
    ks->gh = 0.0;
    ks->have_j = false;
    // Columns [lo, hi) of each row's diagonal block.
    static const int lo[NS] = {0, 1, 1, 3, 3, 5, 6, 6, 8, 8, 10, 11, 11, 11, 11};
    static const int hi[NS] = {1, 3, 3, 5, 5, 6, 8, 8, 10, 10, 11, 15, 15, 15, 15};
    for (int i = 0; i < NS; ++i)
        for (int j = lo[i]; j < hi[i]; ++j)
            if (!isfinite(J[i * NS + j])) return i;
    ks->have_j = true;
    return -1;
}

// 1 / (1 - gh j), or 0 when W is singular to working precision (the test
// of the solver's own 1x1 blocks, lu.c).
static double inv1(double gh, double j) {
    const double w = 1.0 - gh * j;
    return fabs(w) > DBL_EPSILON * fmax(1.0, fabs(gh * j)) ? 1.0 / w : 0.0;
}

// W^-1 of the 4x4 block I - gh m by Gauss-Jordan with partial pivoting. Not
// hyd_lu_factor + four hyd_lu_solve: those general, careful loops cost about
// 1,800 instructions per Jacobian against about 450 here, 5 % of a Krus step
// at one Jacobian per 10 steps (callgrind, 2026-11-23).
static int inv4(double gh, const double* m, double* out) {
    double a[4][8];
    double amax = 0.0;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            a[i][j] = (i == j) - gh * m[i * 4 + j];
            a[i][4 + j] = i == j;
            if (fabs(a[i][j]) > amax) amax = fabs(a[i][j]);
        }
    for (int c = 0; c < 4; ++c) {
        int p = c;
        for (int i = c + 1; i < 4; ++i)
            if (fabs(a[i][c]) > fabs(a[p][c])) p = i;
        if (!(fabs(a[p][c]) > 64.0 * DBL_EPSILON * amax)) return -1;
        if (p != c)
            for (int j = 0; j < 8; ++j) {
                const double tmp = a[c][j];
                a[c][j] = a[p][j], a[p][j] = tmp;
            }
        const double inv = 1.0 / a[c][c];
        for (int j = 0; j < 8; ++j) a[c][j] *= inv;
        for (int i = 0; i < 4; ++i) {
            if (i == c) continue;
            const double l = a[i][c];
            for (int j = 0; j < 8; ++j) a[i][j] -= l * a[c][j];
        }
    }
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) out[i * 4 + j] = a[i][4 + j];
    return 0;
}

static int form_w(lsim_ks* ks, double gh) {
    for (int k = 0; k < 2; ++k) {
        if ((ks->wu[k] = inv1(gh, ks->ju[k])) == 0.0) return HYD_ERR_SINGULAR;
        for (int c = 0; c < 2; ++c) {
            const double* m = ks->jh[k][c];
            const double a = 1.0 - gh * m[0], b = -gh * m[1], cc = -gh * m[2], d = 1.0 - gh * m[3];
            const double det = a * d - b * cc;
            // The singularity test of lu.c's 2x2 blocks.
            if (!(fabs(det) > 4.0 * DBL_EPSILON * fmax(fabs(a * d), fabs(b * cc)))) return HYD_ERR_SINGULAR;
            const double id = 1.0 / det;
            double* w = ks->wh[k][c];
            w[0] = d * id, w[1] = -b * id, w[2] = -cc * id, w[3] = a * id;
        }
    }
    if ((ks->wpl = inv1(gh, ks->jpl)) == 0.0) return HYD_ERR_SINGULAR;
    if (inv4(gh, ks->jm, ks->wm)) return HYD_ERR_SINGULAR;
    ks->gh = gh;
    return HYD_OK;
}

// k = W^-1 b block by block, where b = h f + c2 (k1 - h f0) (c2 = 0 for
// stage 1), and the stage's output: stage 1 writes h f0 and y + k1, stage 2
// y + (k1 + k2) / 2. One pass, every block's values in registers.
static inline void solve_stage(const lsim_ks* restrict ks, int stage, double h, const double* restrict f,
                               const double* restrict y, double* restrict hf0, double* restrict k1,
                               double* restrict out) {
#define RHS(i) (stage == 1 ? (hf0[i] = h * f[i]) : h * f[i] - 2.0 * (k1[i] - hf0[i]))
#define PUT(i, k)                                                                                       \
    do {                                                                                                \
        if (stage == 1) k1[i] = (k), out[i] = y[i] + (k);                                               \
        else out[i] = y[i] + 0.5 * (k1[i] + (k));                                                       \
    } while (0)
    for (int a = 0; a < 2; ++a) {
        const int b = 5 * a;
        const double ku = ks->wu[a] * RHS(b);
        PUT(b, ku);
        for (int c = 0; c < 2; ++c) {
            const double* w = ks->wh[a][c];
            const int i = b + 1 + 2 * c;
            const double r0 = RHS(i), r1 = RHS(i + 1);
            const double x0 = w[0] * r0 + w[1] * r1, x1 = w[2] * r0 + w[3] * r1;
            PUT(i, x0);
            PUT(i + 1, x1);
        }
    }
    const double kp = ks->wpl * RHS(IPL);
    PUT(IPL, kp);
    const double m0 = RHS(IQ), m1 = RHS(IQ + 1), m2 = RHS(IQ + 2), m3 = RHS(IQ + 3);
    const double* w = ks->wm;
    for (int i = 0; i < 4; ++i) {
        const double x = w[4 * i] * m0 + w[4 * i + 1] * m1 + w[4 * i + 2] * m2 + w[4 * i + 3] * m3;
        PUT(IQ + i, x);
    }
#undef RHS
#undef PUT
}

int lsim_wstep(void* user, double t, const double* y, double h, double gamma, int new_jac,
               double* ynew) {
    lsim* s = user;
    lsim_ks* ks = &s->ks;
    if (new_jac || !ks->have_j) {
        ks->cmd_t = NAN; // after a reset the commands may have been changed
        ks->have_anchor = false;
        const int bad = refresh_j(s, t, y);
        if (bad >= 0) {
            // As the generic step would: the state whose row broke down
            // turns non-finite, and the solver reports it at t + h.
            for (int i = 0; i < NS; ++i) ynew[i] = y[i];
            ynew[bad] = NAN;
            return 0;
        }
    }
    int nlu = 0;
    const double gh = gamma * h;
    // As the generic driver: a relative change below 1e-8 keeps W.
    if (ks->gh == 0.0 || fabs(gh - ks->gh) > 1e-8 * fabs(gh)) {
        const int rc = form_w(ks, gh);
        if (rc != HYD_OK) {
            ks->gh = 0.0;
            return rc;
        }
        nlu = 1;
    }
    geo g;
    geo_at(s, y, h, &g);
    double f[NS], hf0[NS], k1[NS], ys[NS];
    stage_f(s, &g, t, y, f);
    solve_stage(ks, 1, h, f, y, hf0, k1, ys);
    stage_f(s, &g, t + h, ys, f);
    // g21 h J k1 = -2 (k1 - h f0) for both gammas (krus.c).
    solve_stage(ks, 2, h, f, y, hf0, k1, ynew);
    return nlu;
}
