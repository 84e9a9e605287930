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
#include "lsim_split.h"

#include <float.h>
#include <math.h>
#include <string.h>

enum { IPL = 10, IQ = 11, NS = 15 };

typedef lsim_geo geo;

static void geo_at(lsim* s, const double* y, double h, geo* g) { lsim_geo_at(s, y, IQ, h, g); }

// Valve commands at t (lsim_commands: stage 2 of one step and stage 1 of
// the next share t, so the scenario's tables are read once per step).
static void commands_at(lsim* s, double t, double cmd[2]) { lsim_commands(s, t, cmd); }

// f at a stage (t, y) with the mechanics carried from the midpoint.
static void stage_f(lsim* s, const geo* g, double t, const double* y, double* f) {
    double x[2], v[2], r[2], trig[4], cmd[2], F[2];
    lsim_geo_carry(g, y, IQ, x, v, r, trig);
    commands_at(s, t, cmd);
    hyd_fused_eval2(&s->fz, y, x, v, cmd, f, F);
    lsim_split_mech(s, trig, y + IQ + 2, F, r, f + IQ);
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

static int form_w(lsim_ks* ks, double gh);
// form_w as lsim_step_prepare calls it.
static int form_w_of(lsim* s, double gh) { return form_w(&s->ks, gh); }

static int form_w(lsim_ks* ks, double gh) {
    for (int k = 0; k < 2; ++k) {
        if ((ks->wu[k] = lsim_inv1(gh, ks->ju[k])) == 0.0) return HYD_ERR_SINGULAR;
        for (int c = 0; c < 2; ++c)
            if (lsim_inv2(gh, ks->jh[k][c], ks->wh[k][c])) return HYD_ERR_SINGULAR;
    }
    if ((ks->wpl = lsim_inv1(gh, ks->jpl)) == 0.0) return HYD_ERR_SINGULAR;
    if (lsim_inv4(gh, ks->jm, ks->wm, 64.0)) return HYD_ERR_SINGULAR;
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
    int nlu;
    const int rc = lsim_step_prepare(s, t, y, gamma * h, new_jac, NS, ynew, refresh_j, form_w_of, &nlu);
    if (rc) return rc > 0 ? 0 : rc;
    geo g;
    geo_at(s, y, h, &g);
    double f[NS], hf0[NS], k1[NS];
    double* ys = s->ystage; // kept for hyd_problem.wstage
    stage_f(s, &g, t, y, f);
    solve_stage(ks, 1, h, f, y, hf0, k1, ys);
    stage_f(s, &g, t + h, ys, f);
    // g21 h J k1 = -2 (k1 - h f0) for both gammas (krus.c).
    solve_stage(ks, 2, h, f, y, hf0, k1, ynew);
    return nlu;
}
