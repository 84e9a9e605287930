// hyd_pump.h: the pressure-compensated pump's law (pump.c has the
// reasoning), written once for the reference loop (pump.c) and the one-pass
// kernel (circuit_kernel.c).
#ifndef HYD_PUMP_H
#define HYD_PUMP_H

#include "hyd_internal.h"

/// Delivery [m^3/s] at pressure rise dp = p_out - p_in [Pa] of a pump with
/// maximum flow qmax [m^3/s], setting pset [Pa] and 1 / band inv_band [1/Pa]:
/// qmax (1 - smoothstep((dp - pset) / band)). *g = dq/d(dp) [m^3/(s Pa)];
/// *t = (dp - pset) / band [-], > 0 while the compensator regulates.
static inline double hyd_pump_q(double qmax, double pset, double inv_band, double dp, double* g,
                                double* t) {
    const double tt = (dp - pset) * inv_band;
    double ds;
    const double s = hyd_smoothstep(tt, &ds);
    *t = tt;
    *g = -qmax * ds * inv_band;
    return qmax * (1.0 - s);
}

#endif
