// pump.c: pressure-compensated variable pump as a flow source.
//
// Full flow q_max while the pressure rise dp = p_out - p_in is at most p_set,
// then q_max (1 - smoothstep((dp - p_set)/band)): C1, zero at p_set + band.
// The cubic corner keeps dQ/dp bounded (-1.5 q_max / band at mid-band), so
// the pump-line mode stays finite for the stiff solvers.
#include "hyd_internal.h"

hyd_pump_def hyd_default_pump_def(void) {
    hyd_pump_def d = {0};
    d.band = 0.5e6;
    return d;
}

void hyd_pump_derive(const hyd_pump_def* d, hyd_pump_c* c) {
    c->qmax = d->q_max;
    c->pset = d->p_set;
    c->inv_band = 1.0 / d->band;
}

void hyd_pumps_eval(const hyd_model* m, hyd_data* d, double* G) {
    for (int i = 0; i < m->npump; ++i) {
        const hyd_pump_c* c = &m->pump[i];
        const double dp = d->node_p[c->out] - d->node_p[c->in];
        const double t = (dp - c->pset) * c->inv_band;
        double ds;
        const double s = hyd_smoothstep(t, &ds);
        const double q = c->qmax * (1.0 - s);
        // q flows in -> out and depends on p_out - p_in.
        const double g = -c->qmax * ds * c->inv_band; // dq/d(dp)
        d->comp_q[2 * c->comp] = q;
        d->comp_open[c->comp] = t > 0.0;
        hyd_flow2(m, d, G, c->comp, c->in, c->out, q, -g, g);
    }
}
