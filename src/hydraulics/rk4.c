// rk4.c: classical explicit Runge-Kutta of order 4, the non-stiff reference.
// Its stability region ends near h lambda = -2.8, so on the crane's hose and
// chamber modes (lambda ~ -9e4 1/s) it needs h < ~30 us: the point of having it.
#include "solver_internal.h"

int hydRk4Step(hyd_solver* s, double t, const double* y, const double* f0, double h,
               double* ynew) {
    const int n = s->n;
    double* restrict ys = s->ys;
    double* restrict k2 = s->k[1];
    double* restrict k3 = s->k[2];
    double* restrict k4 = s->k[3];
    const double h2 = 0.5 * h;
    int rc;

    for (int i = 0; i < n; ++i) ys[i] = y[i] + h2 * f0[i];
    if ((rc = hydEvalF(s, t + h2, ys, k2)) != HYD_OK) return rc;
    for (int i = 0; i < n; ++i) ys[i] = y[i] + h2 * k2[i];
    if ((rc = hydEvalF(s, t + h2, ys, k3)) != HYD_OK) return rc;
    for (int i = 0; i < n; ++i) ys[i] = y[i] + h * k3[i];
    if ((rc = hydEvalF(s, t + h, ys, k4)) != HYD_OK) return rc;
    const double h6 = h / 6.0;
    for (int i = 0; i < n; ++i)
        ynew[i] = y[i] + h6 * (f0[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
    return HYD_OK;
}
