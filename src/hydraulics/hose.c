// hose.c: hose or short pipe between a valve and a cylinder port.
//
// The hose is a pressure node of volume pi d^2 L / 4 with its own effective
// bulk modulus (oil plus wall compliance, lower than the oil's), joined to the
// node "to" by a laminar Hagen-Poiseuille resistance
//   Q = G (p_hose - p_to),  G = pi d^4 / (128 mu L),  mu = rho nu.
// Hose and chamber then form each actuator's fastest (stiff) modes.
#include "hyd_internal.h"

hyd_hose_def hyd_default_hose_def(void) {
    hyd_hose_def d = {0};
    d.bulk_modulus = 0.8e9;
    d.p0 = 1e5;
    return d;
}

double hyd_hose_volume(const hyd_hose_def* d) {
    return 0.25 * HYD_PI * d->diameter * d->diameter * d->length;
}

void hyd_hose_derive(const hyd_fluid_def* f, const hyd_hose_def* d, hyd_hose_c* c) {
    const double d2 = d->diameter * d->diameter;
    c->G = HYD_PI * d2 * d2 / (128.0 * f->density * f->viscosity * d->length);
}

void hyd_hoses_eval(const hyd_model* m, hyd_data* d, double* G) {
    for (int i = 0; i < m->nhose; ++i) {
        const hyd_hose_c* c = &m->hose[i];
        const double q = c->G * (d->node_p[c->node] - d->node_p[c->to]);
        d->comp_q[2 * c->comp] = q;
        hyd_flow2(m, d, G, c->comp, c->node, c->to, q, c->G, -c->G);
    }
}
