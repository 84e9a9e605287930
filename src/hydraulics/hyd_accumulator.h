// hyd_accumulator.h: the accumulator's record and gas law (accumulator.c has
// the reasoning), written once for the reference loop (accumulator.c) and
// the fast kernel (circuit_fast.c).
#ifndef HYD_ACCUMULATOR_H
#define HYD_ACCUMULATOR_H

#include "hyd_internal.h"

#include <math.h>

#define HYD_ACC_EPS 1e-4

typedef struct hyd_acc_c {
    int node, adr, comp;
    double p0, V0, n, G, Vinit;
} hyd_acc_c;

/// Gas pressure [Pa abs] at oil volume V [m^3]; *dp = dp_g / dV [Pa/m^3].
static inline double hyd_acc_pgas(const hyd_acc_c* c, double V, double* dp) {
    if (V >= 0.0) {
        const double Vg = c->V0 - V;
        const double p = c->p0 * pow(c->V0 / Vg, c->n);
        *dp = c->n * p / Vg;
        return p;
    }
    const double a = c->n * c->p0 / c->V0, k = 1.0 / (HYD_ACC_EPS * c->V0);
    *dp = a * (1.0 - 2.0 * V * k);
    return c->p0 + a * V * (1.0 - V * k);
}

#endif
