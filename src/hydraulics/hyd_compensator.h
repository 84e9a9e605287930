// hyd_compensator.h: the section compensator's record and law
// (compensator.c has the reasoning), written once for the reference loop
// (compensator.c) and the fast kernel (circuit_fast.c).
#ifndef HYD_COMPENSATOR_H
#define HYD_COMPENSATOR_H

#include "hyd_orifice.h"

typedef struct hyd_comp_c {
    int in, out, load, ref, comp, post;
    double A, set, inv_band;
    hyd_orif_k ok;
} hyd_comp_c;

/// Flow q [m^3/s] inlet -> outlet at inlet, outlet, load and ref pressures
/// [Pa]; *x the opening [-]; dq[0..3] = dq / dp of inlet, outlet, load, ref
/// [m^3/(s Pa)].
static inline double hyd_compensator_q(const hyd_comp_c* c, double pin, double pout, double pl,
                                       double pr, double* x, double dq[4]) {
    const double target = c->post ? pin - pr - c->set : c->set;
    double ds;
    *x = 1.0 - hyd_smoothstep((pout - pl - target) * c->inv_band + 0.5, &ds);
    const double dx = -ds * c->inv_band; // dx / d(dp_m - dp_t)
    double g, gA;
    const double q = hyd_orifice_q(&c->ok, c->A * *x, pin - pout, &g, &gA);
    const double k = gA * c->A * dx; // dq / d(dp_m - dp_t)
    dq[0] = g, dq[1] = -g + k, dq[2] = -k, dq[3] = 0.0;
    if (c->post)
        dq[0] -= k, dq[3] += k;
    return q;
}

#endif
