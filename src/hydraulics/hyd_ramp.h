// hyd_ramp.h: the opening law of relief and check valves (relief.c,
// check_valve.c), written once for the reference loop and the one-pass
// kernel (circuit_kernel.c).
#ifndef HYD_RAMP_H
#define HYD_RAMP_H

#include "hyd_internal.h"

/// The ramp law as expressions of + - * only (one text for a double and the
/// two lanes of circuit_fast_ls.c): t from the pressure difference, then the
/// corner t^2 (0 < t < 1) and the line 2t - 1 (t >= 1).
#define HYD_RAMP_T(dp, pcr, inv_w) (((dp) - (pcr)) * (inv_w))
#define HYD_RAMP_CORNER(t) ((t) * (t))
#define HYD_RAMP_LINE(t) (2.0 * (t) - 1.0)

/// Relief/check opening law on t = d / w (see relief.c): 0, t^2, then 2t - 1;
/// *dr = d ramp / d d (so it includes 1/w).
static inline double hyd_open_ramp_t(double t, double inv_w, double* dr) {
    if (t <= 0.0) {
        *dr = 0.0;
        return 0.0;
    }
    if (t < 1.0) {
        *dr = 2.0 * t * inv_w;
        return HYD_RAMP_CORNER(t);
    }
    *dr = 2.0 * inv_w;
    return HYD_RAMP_LINE(t);
}

/// Flow [m^3/s] of a relief or check valve with cracking pressure pcr [Pa],
/// 1 / opening band inv_w [1/Pa] and rated flow qr [m^3/s] at pressure
/// difference dp = p_in - p_out [Pa]: qr ramp((dp - pcr) / w). *g = dq/d(dp)
/// [m^3/(s Pa)]; *t = (dp - pcr) / w [-], <= 0 while closed (0 flow, 0 partial).
static inline double hyd_ramp_q(double pcr, double inv_w, double qr, double dp, double* g, double* t) {
    const double tt = HYD_RAMP_T(dp, pcr, inv_w);
    *t = tt;
    if (tt <= 0.0) { // (a NaN takes the full path and propagates)
        *g = 0.0;
        return 0.0;
    }
    double dr;
    const double r = hyd_open_ramp_t(tt, inv_w, &dr);
    *g = qr * dr;
    return qr * r;
}

#endif
