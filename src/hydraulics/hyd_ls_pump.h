// hyd_ls_pump.h: the load-sensing pump's record and controller law (ls_pump.c
// has the reasoning), written once for the reference loop (ls_pump.c) and
// the fast kernel (circuit_fast.c).
#ifndef HYD_LS_PUMP_H
#define HYD_LS_PUMP_H

#include "hyd_internal.h"

typedef struct hyd_ls_pump_c {
    int in, out, ls, adr, comp;
    double qmax, margin, inv_band, pcut, inv_cband, inv_tau;
} hyd_ls_pump_c;

/// Displacement set point eps_t = e_ls e_co [-] at inlet, outlet and LS
/// pressures [Pa]; *a1 = d eps_t / d(p_out - p_ls), *a2 = d eps_t / d(p_out
/// - p_in) [1/Pa].
static inline double hyd_ls_pump_target(const hyd_ls_pump_c* c, double pin, double pout, double pls,
                                        double* a1, double* a2) {
    double ds1, ds2;
    const double e_ls = 1.0 - hyd_smoothstep((pout - pls - c->margin) * c->inv_band + 0.5, &ds1);
    const double e_co = 1.0 - hyd_smoothstep((pout - pin - c->pcut) * c->inv_cband, &ds2);
    *a1 = -ds1 * c->inv_band * e_co;
    *a2 = -ds2 * c->inv_cband * e_ls;
    return e_ls * e_co;
}

#endif
