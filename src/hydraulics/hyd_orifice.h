// hyd_orifice.h: the two-regime orifice law (orifice.c has its derivation),
// written once for every caller: fixed orifices (orifice.c), valve metering
// edges (hyd_valve.h) and the one-pass kernel (circuit_kernel.c).
#ifndef HYD_ORIFICE_H
#define HYD_ORIFICE_H

#include "hyd_internal.h"

/// Orifice law on precomputed constants: Q [m^3/s], *g = dQ/ddp, *gA = dQ/dA
/// (see orifice.c). Inline: it runs twice per valve per evaluation, and the
/// caller's unused partials then cost nothing.
static inline double hyd_orifice_q(const hyd_orif_k* k, double A, double dp, double* g, double* gA) {
    const double x = dp * A * k->invP0;
    if (fabs(x) < 1.0) {
        const double sA = sqrt(A);
        const double G = k->kl * A * sA;
        const double x2 = x * x;
        const double lam = 1.0 - 0.2 * x2;
        *g = G * (1.0 - 0.6 * x2);
        // dQ/dA = dG/dA dp (1 - x^2/5) - G dp (2x/5) dx/dA, dx/dA = dp / P0
        *gA = 1.5 * k->kl * sA * dp * lam - G * dp * 0.4 * x * dp * k->invP0;
        return G * dp * lam;
    }
    const double s = sqrt(fabs(dp));
    *g = 0.5 * k->k * A / s;
    *gA = k->k * copysign(s, dp);
    return k->k * A * copysign(s, dp);
}

#endif
