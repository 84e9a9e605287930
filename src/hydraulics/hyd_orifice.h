// hyd_orifice.h: the two-regime orifice law (orifice.c has its derivation),
// written once for every caller: fixed orifices (orifice.c), valve metering
// edges (hyd_valve.h) and the one-pass kernel (circuit_kernel.c).
#ifndef HYD_ORIFICE_H
#define HYD_ORIFICE_H

#include "hyd_internal.h"

/// The law's flow in each regime, as expressions of + - * only, so that one
/// text serves a double and the two-lane vectors of circuit_kernel.c (GCC and
/// Clang vector types take these operators, a scalar operand applying to
/// both lanes): x = dp A / P0 is the regime variable (laminar while |x| < 1),
/// sA = sqrt(A), sdp = copysign(sqrt(|dp|), dp).
#define HYD_ORIFICE_X(invP0, A, dp) ((dp) * (A) * (invP0))
#define HYD_ORIFICE_LAMINAR(kl, A, sA, dp, x) ((kl) * (A) * (sA) * (dp) * (1.0 - 0.2 * ((x) * (x))))
#define HYD_ORIFICE_TURBULENT(k, A, sdp) ((k) * (A) * (sdp))

/// Orifice law on precomputed constants: Q [m^3/s], *g = dQ/ddp, *gA = dQ/dA
/// (see orifice.c). Inline: it runs twice per valve per evaluation, and the
/// caller's unused partials then cost nothing.
static inline double hyd_orifice_q(const hyd_orif_k* k, double A, double dp, double* g, double* gA) {
    const double x = HYD_ORIFICE_X(k->invP0, A, dp);
    if (fabs(x) < 1.0) {
        const double sA = sqrt(A);
        const double G = k->kl * A * sA; // Q = G dp lam
        const double x2 = x * x;
        const double lam = 1.0 - 0.2 * x2;
        *g = G * (1.0 - 0.6 * x2);
        // dQ/dA = dG/dA dp (1 - x^2/5) - G dp (2x/5) dx/dA, dx/dA = dp / P0
        *gA = 1.5 * k->kl * sA * dp * lam - G * dp * 0.4 * x * dp * k->invP0;
        return HYD_ORIFICE_LAMINAR(k->kl, A, sA, dp, x);
    }
    const double s = sqrt(fabs(dp));
    *g = 0.5 * k->k * A / s;
    *gA = k->k * copysign(s, dp);
    return HYD_ORIFICE_TURBULENT(k->k, A, copysign(s, dp));
}

#endif
