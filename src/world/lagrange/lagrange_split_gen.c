// lagrange_split_gen.c: the split Krus / ROS2 step (hyd_problem.wstep) for
// any circuit on the fast kernel (circuit_fast.h), e.g. the load-sensing
// crane. The same W-method and the same mechanics scheme as
// lagrange_split_step.c (lsim_split.h: sines and cylinder kinematics once
// per step at the predicted midpoint, carried to each stage by Taylor
// series; docs/lagrange.md, "Split Krus step"), with what differs for a
// circuit of no fixed shape:
//
// - f at a stage is lsim_rhs's fast-kernel f (hyd_fast_eval with the
//   carried strokes and rates as inputs, then lagrange_accel_fast), so it is
//   the generic step's f at that stage up to the O(d^2) Taylor terms;
// - J is lsim_jac's, exactly the one the generic stages would take, at the
//   times the solver's schedule asks for (jac_every, jac_max_age; the LS
//   crane has no events, as lsim_problem gives events only to the fused
//   circuit), and only its diagonal blocks in lsim's block pattern are kept:
//   the 1x1, 2x2 and 3x3 blocks of the circuit's states, the one larger
//   block of the supply (5-8 states) and the 4x4 mechanics;
// - W^-1 of each block is formed explicitly when J or gamma h changes, with
//   the singularity tests of the solver's own block LU (lu.c: 1x1, 2x2 and
//   the pivot test tiny = eps max|W_ij| of its general blocks), and each
//   stage's solve is fused with its update in one pass.
//
// The circuit itself (about 2,800 instructions an evaluation for the LS
// crane) is unchanged; what goes is the generic stage arithmetic around it:
// the solver's stage loops and block solves, two sincos pairs and the full
// kinematics per f.
#include "lagrange_sim.h"
#include "lsim_split.h"

#include <math.h>

// The diagonal blocks of J at (t, y), from lsim_jac (the fast kernel's
// Jacobian). Returns -1, or the first state whose block row is not finite.
static int refresh_j(lsim* s, double t, const double* y) {
    lsim_kg* kg = &s->kg;
    lsim_ks* ks = &s->ks;
    const int n = s->n, iq = s->iq;
    const double* J = kg->J;
    lsim_jac(s, t, y, kg->J);
    ks->gh = 0.0;
    ks->have_j = false;
    for (int k = 0; k < kg->n1; ++k) kg->j1[k] = J[kg->i1[k] * (n + 1)];
    for (int k = 0; k < kg->n2; ++k) {
        const int i = kg->i2[k];
        double* m = kg->j2[k];
        m[0] = J[i * n + i], m[1] = J[i * n + i + 1];
        m[2] = J[(i + 1) * n + i], m[3] = J[(i + 1) * n + i + 1];
    }
    for (int k = 0; k < kg->n3; ++k)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) kg->j3[k][i * 3 + j] = J[(kg->i3[k] + i) * n + kg->i3[k] + j];
    for (int i = 0; i < kg->nv; ++i)
        for (int j = 0; j < kg->nv; ++j) kg->jv[i * kg->nv + j] = J[(kg->iv + i) * n + kg->iv + j];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) kg->jm[i * 4 + j] = J[(iq + i) * n + iq + j];
    // x * 0 is 0 for finite x, NaN otherwise: one sum answers for every
    // block entry; only a broken J takes the row scan.
    double bad = 0.0;
    for (int k = 0; k < kg->n1; ++k) bad += kg->j1[k] * 0.0;
    for (int k = 0; k < kg->n2; ++k)
        for (int e = 0; e < 4; ++e) bad += kg->j2[k][e] * 0.0;
    for (int k = 0; k < kg->n3; ++k)
        for (int e = 0; e < 9; ++e) bad += kg->j3[k][e] * 0.0;
    for (int e = 0; e < kg->nv * kg->nv; ++e) bad += kg->jv[e] * 0.0;
    for (int e = 0; e < 16; ++e) bad += kg->jm[e] * 0.0;
    if (bad != 0.0) {
        // Rows in order, so the state reported is the first one broken.
        for (int b = 0, o = 0; b < s->nblock; o += s->block[b++])
            for (int i = o; i < o + s->block[b]; ++i)
                for (int j = o; j < o + s->block[b]; ++j)
                    if (!isfinite(J[i * n + j])) return i;
    }
    ks->have_j = true;
    return -1;
}

static int form_w(lsim* s, double gh) {
    lsim_kg* kg = &s->kg;
    for (int k = 0; k < kg->n1; ++k)
        if ((kg->w1[k] = lsim_inv1(gh, kg->j1[k])) == 0.0) return HYD_ERR_SINGULAR;
    for (int k = 0; k < kg->n2; ++k)
        if (lsim_inv2(gh, kg->j2[k], kg->w2[k])) return HYD_ERR_SINGULAR;
    // tol 1: lu.c's test for its general blocks, which take the 3x3 and the
    // mechanics blocks on the generic path.
    for (int k = 0; k < kg->n3; ++k)
        if (lsim_inv3(gh, kg->j3[k], kg->w3[k], 1.0)) return HYD_ERR_SINGULAR;
    if (kg->nv && (kg->nv == 6 ? lsim_inv6(gh, kg->jv, kg->wv, 1.0) : lsim_invv(kg->nv, gh, kg->jv, kg->wv, 1.0)))
        return HYD_ERR_SINGULAR;
    if (lsim_inv4(gh, kg->jm, kg->wm, 1.0)) return HYD_ERR_SINGULAR;
    s->ks.gh = gh;
    return HYD_OK;
}

// f at a stage (t, y) with the mechanics carried from the midpoint; the
// circuit as lsim_rhs evaluates it on the fast kernel.
static void stage_f(lsim* s, const lsim_geo* g, double t, const double* y, double* f) {
    const int iq = s->iq;
    const int *cyl = s->mdl->cyl, *valve = s->mdl->valve;
    hyd_data* d = s->hd;
    double x[2], v[2], r[2], trig[4], cmd[2];
    lsim_geo_carry(g, y, iq, x, v, r, trig);
    lsim_commands(s, t, cmd);
    for (int i = 0; i < 2; ++i) {
        d->cyl_x[cyl[i]] = x[i];
        d->cyl_v[cyl[i]] = v[i];
        d->valve_cmd[valve[i]] = cmd[i];
    }
    hyd_fast_eval(s->fk, d, y, f);
    const double F[2] = {d->cyl_F[cyl[0]], d->cyl_F[cyl[1]]};
    lsim_split_mech(s, trig, y + iq + 2, F, r, f + iq);
}

// k = W^-1 b block by block, where b = h f + c2 (k1 - h f0) (c2 = 0 for
// stage 1), and the stage's output: stage 1 writes h f0 and y + k1, stage 2
// y + (k1 + k2) / 2. One pass over the blocks.
// Always inlined: each call's constant stage selects its RHS and PUT at
// compile time (out of line, with the branch per state, it cost 40 % more).
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void solve_stage(const lsim_kg* restrict kg, int iq, int stage, double h,
                               const double* restrict f, const double* restrict y, double* restrict hf0,
                               double* restrict k1, double* restrict out) {
#define RHS(i) (stage == 1 ? (hf0[i] = h * f[i]) : h * f[i] - 2.0 * (k1[i] - hf0[i]))
#define PUT(i, k)                                                                                       \
    do {                                                                                                \
        if (stage == 1) k1[i] = (k), out[i] = y[i] + (k);                                               \
        else out[i] = y[i] + 0.5 * (k1[i] + (k));                                                       \
    } while (0)
    for (int t = 0; t < kg->n1; ++t) {
        const int i = kg->i1[t];
        const double k = kg->w1[t] * RHS(i);
        PUT(i, k);
    }
    for (int t = 0; t < kg->n2; ++t) {
        const int i = kg->i2[t];
        const double* w = kg->w2[t];
        const double r0 = RHS(i), r1 = RHS(i + 1);
        const double x0 = w[0] * r0 + w[1] * r1, x1 = w[2] * r0 + w[3] * r1;
        PUT(i, x0);
        PUT(i + 1, x1);
    }
    for (int t = 0; t < kg->n3; ++t) {
        const int i = kg->i3[t];
        const double* w = kg->w3[t];
        const double r0 = RHS(i), r1 = RHS(i + 1), r2 = RHS(i + 2);
        const double x0 = w[0] * r0 + w[1] * r1 + w[2] * r2, x1 = w[3] * r0 + w[4] * r1 + w[5] * r2,
                     x2 = w[6] * r0 + w[7] * r1 + w[8] * r2;
        PUT(i, x0);
        PUT(i + 1, x1);
        PUT(i + 2, x2);
    }
    // The supply block: its size a constant for the LS crane's 6 (unrolled).
#define VBLOCK(NV)                                                                                      \
    do {                                                                                                \
        double r[LSIM_MAX_VBLOCK];                                                                      \
        const int i0 = kg->iv;                                                                          \
        for (int i = 0; i < (NV); ++i) r[i] = RHS(i0 + i);                                              \
        for (int i = 0; i < (NV); ++i) {                                                                \
            double x = 0.0;                                                                             \
            for (int j = 0; j < (NV); ++j) x += kg->wv[i * (NV) + j] * r[j];                            \
            PUT(i0 + i, x);                                                                             \
        }                                                                                               \
    } while (0)
    if (kg->nv == 6) VBLOCK(6);
    else if (kg->nv) VBLOCK(kg->nv);
#undef VBLOCK
    const double m0 = RHS(iq), m1 = RHS(iq + 1), m2 = RHS(iq + 2), m3 = RHS(iq + 3);
    const double* w = kg->wm;
    for (int i = 0; i < 4; ++i) {
        const double x = w[4 * i] * m0 + w[4 * i + 1] * m1 + w[4 * i + 2] * m2 + w[4 * i + 3] * m3;
        PUT(iq + i, x);
    }
#undef RHS
#undef PUT
}

int lsim_wstep_gen(void* user, double t, const double* y, double h, double gamma, int new_jac,
                   double* ynew) {
    lsim* s = user;
    int nlu;
    const int rc = lsim_step_prepare(s, t, y, gamma * h, new_jac, s->n, ynew, refresh_j, form_w, &nlu);
    if (rc) return rc > 0 ? 0 : rc;
    lsim_geo g;
    lsim_geo_at(s, y, s->iq, h, &g);
    double f[LSIM_MAX_STATES], hf0[LSIM_MAX_STATES], k1[LSIM_MAX_STATES];
    double* ys = s->ystage; // kept for hyd_problem.wstage
    stage_f(s, &g, t, y, f);
    solve_stage(&s->kg, s->iq, 1, h, f, y, hf0, k1, ys);
    stage_f(s, &g, t + h, ys, f);
    // g21 h J k1 = -2 (k1 - h f0) for both gammas (krus.c).
    solve_stage(&s->kg, s->iq, 2, h, f, y, hf0, k1, ynew);
    return nlu;
}
