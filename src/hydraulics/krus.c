// krus.c: the 2-stage linearly implicit W-method of docs/solvers.md,
//   W k1 = h f(t, y)
//   W k2 = h f(t + h, y + k1) + g21 h J k1
//   y_new = y + (k1 + k2) / 2,            W = I - gamma h J,  g21 = -2 gamma
// gamma = 1/2 is our reading of Krus's method (trapezoidal stability, R(-inf) = -1);
// gamma = 1 + 1/sqrt(2) is the L-stable ROS2. The order conditions are
// b1 + b2 = 1, b2 a21 = 1/2 and gamma + b2 g21 = 0, none of which involve J, so
// the method is of order 2 for any W: a stale or block-diagonal J costs no order.
//
// The term h J k1 is never formed as a product. From the first stage,
// W k1 = h f0 gives h J k1 = (k1 - h f0) / gamma, which uses exactly the J that
// is inside W, whatever approximation that is. Then g21 h J k1 = -2 (k1 - h f0)
// for both gammas.
#include "solver_internal.h"

#include <math.h>

int hydKrusStep(hyd_solver* s, double t, const double* y, const double* f0, double h,
                double* ynew) {
    const int n = s->n;
    const double gamma = hydKrusGamma(s->method);
    int rc = hydPrepareW(s, t, y, f0, gamma * h);
    if (rc != HYD_OK) return rc;

    double* restrict k1 = s->k[0];
    double* restrict k2 = s->k[1];
    double* restrict ys = s->ys;
    double* restrict fs = s->fs;

    for (int i = 0; i < n; ++i) k1[i] = h * f0[i];
    hydSolveW(s, k1);
    for (int i = 0; i < n; ++i) ys[i] = y[i] + k1[i];
    rc = hydEvalF(s, t + h, ys, fs);
    if (rc != HYD_OK) return rc;
    for (int i = 0; i < n; ++i) k2[i] = h * fs[i] - 2.0 * (k1[i] - h * f0[i]);
    hydSolveW(s, k2);
    for (int i = 0; i < n; ++i) ynew[i] = y[i] + 0.5 * (k1[i] + k2[i]);
    return HYD_OK;
}
