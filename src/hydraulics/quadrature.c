// quadrature.c: hyd_solver_step_quadrature (hyd_solver.h), the quadrature of
// extra states q' = P(t, y) (an energy balance's powers) by the method that
// took the last step, as if q had been integrated with y.
//
// For the linearly implicit methods (Krus, ROS2, ROS34PW2, RODAS3) the
// augmented system (y, q) has the Jacobian [[J, 0], [J_q, 0]] with J_q =
// dP/dy, and q feeds nothing back, so its rows of the stage equations
//   W k_i = h f(Y_i) + h J sum_j g_ij k_j (+ gs_i h^2 df/dt)
// solve explicitly once the k_i of y are known:
//   kq_i = h P(Y_i) + h J_q (gamma k_i + sum_j g_ij k_j) (+ gs_i h^2 dP/dt),
// so that
//   q_new - q = sum_i b_i kq_i = h sum_i b_i P(Y_i) + h J_q v (+ h^2 sum_i b_i gs_i dP/dt),
//   v = sum_i b_i (gamma k_i + sum_j g_ij k_j).
// One directional derivative J_q v (a forward difference at the step's start,
// where the method's J belongs) serves every stage. Why not the trapezoid of
// P over the step: on a transient the step does not resolve (an L-stable
// method damps a stiff mode in one step) P at the ends says nothing about
// its integral, while this quadrature is what the method did to y. For
// y' = -lambda y, P = c y it gives q_new - q = c y (1 - R(-lambda h)) /
// lambda with the method's own stability function R: exact as lambda h ->
// infinity for the L-stable methods, where the trapezoid is off by h c y / 2
// (docs/energy.md). With gamma = 1/2 (Krus) and J_q taken as the secant
// between the stage point and the new state, the same formula is the
// trapezoid of P at the step's ends.
#include "solver_internal.h"

#include <math.h>
#include <string.h>

// q += w P(t, y) into acc (nq values), P evaluated into tmp.
static int add_eval(hyd_quad_fn fn, void* user, double t, const double* y, int nq, double w, double* tmp,
                    double* acc) {
    if (fn(user, t, y, tmp)) return HYD_ERR_RHS;
    for (int l = 0; l < nq; ++l) acc[l] += w * tmp[l];
    return HYD_OK;
}

int hyd_solver_step_quadrature(hyd_solver* s, double t0, const double* y0, const double* y1, const double* P0,
                               const double* P1, int nq, hyd_quad_fn fn, void* user, double* work, double* dq) {
    if (!s || !y0 || !y1 || !P0 || !P1 || nq < 0 || !fn || !work || !dq) return HYD_ERR_RHS;
    const int n = s->n;
    const double h = s->last_h;
    double* restrict tmp = work;
    double* restrict ys = s->fdy; // free between steps
    for (int l = 0; l < nq; ++l) dq[l] = 0.0;
    if (!(h > 0.0)) return HYD_OK; // no step taken yet

    if (s->last_split) {
        // A fixed step retried in sub-steps (solver.c, fixed_retry): no one
        // set of stages describes it, so the trapezoid of P at its ends,
        // which is what Krus's own quadrature is (below). Rare: a step the
        // method could not take whole.
        for (int l = 0; l < nq; ++l) dq[l] = 0.5 * h * (P0[l] + P1[l]);
        return HYD_OK;
    }
    if (s->method == HYD_RK4) {
        // The explicit method's own weights at its stage points; its k_2..k_4
        // hold f there and fc_f the f0 of the step (fixed_step).
        static const double c[4] = {0.0, 0.5, 0.5, 1.0}, b[4] = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0};
        for (int l = 0; l < nq; ++l) dq[l] = h * b[0] * P0[l];
        for (int i = 1; i < 4; ++i) {
            const double* fprev = i == 1 ? s->fc_f : s->k[i - 1];
            for (int l = 0; l < n; ++l) ys[l] = y0[l] + c[i] * h * fprev[l];
            const int rc = add_eval(fn, user, t0 + c[i] * h, ys, nq, h * b[i], tmp, dq);
            if (rc) return rc;
        }
        return HYD_OK;
    }

    if (s->method == HYD_KRUS || s->method == HYD_ROS2) {
        // The two-stage W-methods (krus.c: a21 = 1, g21 = -2 gamma, b =
        // (1/2, 1/2)): v = gamma (k1 + k2) / 2 - gamma k1 = gamma (y1 - Y2),
        // and for J_q along it the secant from the stage point Y2 = y0 + k1
        // to the new state, whose P the caller has: h J_q v = h gamma (P1 -
        // P(Y2)), so
        //   q_new - q = h P0 / 2 + h (1/2 - gamma) P(Y2) + h gamma P1.
        // With gamma = 1/2 (Krus) the stage point drops out: the trapezoid.
        // (A forward difference at y0 instead moved the residuals of `hold`,
        // `ramp`, `overload` and `step` by at most 0.013 % of the energy
        // turned over, at an evaluation more per step.)
        const double gamma = hydKrusGamma(s->method);
        for (int l = 0; l < nq; ++l) dq[l] = 0.5 * h * P0[l] + gamma * h * P1[l];
        if (gamma == 0.5) return HYD_OK;
        // The stage point: the generic step's k1, or the problem's own
        // step kernel's y + k1.
        const double* st = s->last_wstep ? (s->p->wstage ? s->p->wstage(s->p->user) : NULL) : NULL;
        if (s->last_wstep && !st) return HYD_ERR_RHS;
        if (!st) {
            for (int l = 0; l < n; ++l) ys[l] = y0[l] + s->k[0][l];
            st = ys;
        }
        return add_eval(fn, user, t0 + h, st, nq, (0.5 - gamma) * h, tmp, dq);
    }

    // The four-stage methods, from their tableau and the stage vectors k_i
    // the step left in the solver.
    const hyd_tableau* t = &s->tab;
    double* const* k = s->k;
    // v = sum_i b_i (gamma k_i + sum_j g_ij k_j), into r (free between steps).
    double* restrict v = s->r;
    for (int l = 0; l < n; ++l) v[l] = 0.0;
    double vmax = 0.0;
    for (int i = 0; i < t->stages; ++i) {
        const double bi = t->b[i];
        for (int l = 0; l < n; ++l) {
            double x = t->gamma * k[i][l];
            for (int j = 0; j < i; ++j) x += t->g[i][j] * k[j][l];
            v[l] += bi * x;
        }
    }
    for (int l = 0; l < n; ++l) vmax = fmax(vmax, fabs(v[l]));
    // h sum_i b_i P(Y_i), Y_i = y + sum_j a_ij k_j.
    for (int i = 0; i < t->stages; ++i) {
        int at_start = t->c[i] == 0.0;
        for (int j = 0; j < i; ++j) at_start = at_start && t->a[i][j] == 0.0;
        if (at_start) {
            for (int l = 0; l < nq; ++l) dq[l] += h * t->b[i] * P0[l];
            continue;
        }
        memcpy(ys, y0, (size_t)n * sizeof *ys);
        for (int j = 0; j < i; ++j)
            if (t->a[i][j] != 0.0)
                for (int l = 0; l < n; ++l) ys[l] += t->a[i][j] * k[j][l];
        const int rc = add_eval(fn, user, t0 + t->c[i] * h, ys, nq, h * t->b[i], tmp, dq);
        if (rc) return rc;
    }
    if (vmax > 0.0) {
        // h J_q v by a forward difference at (t0, y0) along v, a step of
        // 1e-7 of v itself: v is of the size of the step's own change of y,
        // so every state moves by a small fraction of what it moved anyway
        // (state units differ by ten orders: Pa, m, -). The residual of
        // `hold` with ROS34PW2 was the same from 1e-7 to 1e-4.
        const double sg = 1e-7;
        for (int l = 0; l < n; ++l) ys[l] = y0[l] + sg * v[l];
        if (fn(user, t0, ys, tmp)) return HYD_ERR_RHS;
        for (int l = 0; l < nq; ++l) dq[l] += h * (tmp[l] - P0[l]) / sg;
    }
    // The df/dt term of the classical Rosenbrock method (RODAS3), as its
    // states get it: h^2 sum_i b_i gs_i dP/dt, dP/dt by a forward difference.
    if (t->needs_dfdt && !s->p->autonomous) {
        double wsum = 0.0;
        for (int i = 0; i < t->stages; ++i) wsum += t->b[i] * t->gs[i];
        const double dt = 1e-7 * h;
        if (wsum != 0.0) {
            if (fn(user, t0 + dt, y0, tmp)) return HYD_ERR_RHS;
            for (int l = 0; l < nq; ++l) dq[l] += h * h * wsum * (tmp[l] - P0[l]) / dt;
        }
    }
    return HYD_OK;
}
