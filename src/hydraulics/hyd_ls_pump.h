// hyd_ls_pump.h: the load-sensing pump's record and controller law (ls_pump.c
// has the reasoning), written once for the reference loop (ls_pump.c) and
// the fast kernel (circuit_fast.c).
#ifndef HYD_LS_PUMP_H
#define HYD_LS_PUMP_H

#include "hyd_internal.h"

typedef struct hyd_ls_pump_c {
    int in, out, ls, adr, comp;
    double qmax, margin, inv_band, pcut, inv_cband, inv_tau;
    double cleak; ///< internal leakage [m^3/(s Pa)]
} hyd_ls_pump_c;

/// The controller as expressions of + - * only (one text for a double and a
/// lane of circuit_fast_ls.c): the smoothstep arguments of the LS margin
/// (p_out - p_ls against the margin) and the pressure cut-off (p_out - p_in
/// against p_cut), the set point from their complements, the displacement
/// lag, and the delivery eps q_max less the internal leakage
/// c_leak (p_out - p_in) [m^3/s] (with c_leak = 0 exactly eps q_max).
#define HYD_LS_PUMP_ARG_LS(pout, pls, margin, inv_band) (((pout) - (pls) - (margin)) * (inv_band) + 0.5)
#define HYD_LS_PUMP_ARG_CO(pout, pin, pcut, inv_cband) (((pout) - (pin) - (pcut)) * (inv_cband))
#define HYD_LS_PUMP_TARGET(sls, sco) ((1.0 - (sls)) * (1.0 - (sco)))
#define HYD_LS_PUMP_RATE(target, eps, inv_tau) (((target) - (eps)) * (inv_tau))
#define HYD_LS_PUMP_Q(eps, qmax, cleak, pout, pin) ((eps) * (qmax) - (cleak) * ((pout) - (pin)))

/// Displacement set point eps_t = e_ls e_co [-] at inlet, outlet and LS
/// pressures [Pa]; *a1 = d eps_t / d(p_out - p_ls), *a2 = d eps_t / d(p_out
/// - p_in) [1/Pa].
static inline double hyd_ls_pump_target(const hyd_ls_pump_c* c, double pin, double pout, double pls,
                                        double* a1, double* a2) {
    double ds1, ds2;
    const double sls = hyd_smoothstep(HYD_LS_PUMP_ARG_LS(pout, pls, c->margin, c->inv_band), &ds1);
    const double sco = hyd_smoothstep(HYD_LS_PUMP_ARG_CO(pout, pin, c->pcut, c->inv_cband), &ds2);
    const double e_ls = 1.0 - sls, e_co = 1.0 - sco;
    *a1 = -ds1 * c->inv_band * e_co;
    *a2 = -ds2 * c->inv_cband * e_ls;
    return HYD_LS_PUMP_TARGET(sls, sco);
}

#endif
