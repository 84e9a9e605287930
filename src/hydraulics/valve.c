// valve.c: 4/3 closed-centre proportional directional valve.
//
// Spool: tau_s u' = clamp(u_cmd, -1, 1) - u (first order, as in the paper).
// Clamping the command keeps u inside [-1, 1] without a state limiter.
// Metering: u > 0 opens P->A and B->T, u < 0 opens P->B and A->T, each edge a
// two-regime orifice of area |u| A_max, A_max = Q_N / (cd sqrt(2 dp_N / rho))
// (the turbulent law at the rated point; exact as long as dp_N >> p_tr(A_max),
// about 0.4 Pa for the default valve). Only the two open edges are evaluated;
// port nodes are chosen by the sign of u. Because the orifice's laminar flow
// scales as A^1.5, Q(u) is C1 through u = 0 even though |u| is not.
#include "hyd_internal.h"

#include <math.h>

hyd_valve_def hyd_default_valve_def(void) {
    hyd_valve_def d = {0};
    d.q_nominal = 40.0 / 60000.0;
    d.dp_nominal = 1e6;
    d.cd = 0.65;
    d.tau = 0.03;
    d.u0 = 0.0;
    return d;
}

void hyd_valve_derive(const hyd_fluid_def* f, const hyd_valve_def* d, hyd_valve_c* c) {
    c->ok = hyd_orifice_constants(f, d->cd);
    c->Amax = d->q_nominal / (d->cd * sqrt(2.0 * d->dp_nominal / f->density));
    c->inv_tau = 1.0 / d->tau;
}

// The kernel is inlined twice, with and without G, so that the plain
// evaluation drops the dQ/dA partials and the Jacobian bookkeeping entirely.
// map (NULL: identity) is the caller's state order of hyd_eval_mapped.
static inline void valves_kernel(const hyd_model* m, hyd_data* d, const double* y, double* ydot,
                                 double* G, const int* map) {
    const int ld = m->nstate + 1;
    for (int i = 0; i < m->nvalve; ++i) {
        const hyd_valve_c* c = &m->valve[i];
        const int at = map ? map[c->adr] : c->adr;
        const double u = y[at];
        const double raw = d->valve_cmd[i];
        const double cmd = raw > 1.0 ? 1.0 : (raw < -1.0 ? -1.0 : raw);
        if (ydot)
            ydot[at] = (cmd - u) * c->inv_tau;

        const int pos = u >= 0.0;
        const double sgn = pos ? 1.0 : -1.0;
        const double A = c->Amax * fabs(u);
        // Edge 1 feeds the work port from P; edge 2 drains the other one to T.
        const int feed = pos ? c->A : c->B;
        const int drain = pos ? c->B : c->A;
        double g1, g1A, g2, g2A;
        const double q1 = hyd_orifice_q(&c->ok, A, d->node_p[c->P] - d->node_p[feed], &g1, &g1A);
        const double q2 = hyd_orifice_q(&c->ok, A, d->node_p[drain] - d->node_p[c->T], &g2, &g2A);
        const double qA = pos ? q1 : -q2; // into port A
        const double qB = pos ? q2 : -q1; // out of port B
        double* fl = d->flow_ + 4 * c->comp;
        fl[0] = -q1;
        fl[1] = q2;
        fl[2] = qA;
        fl[3] = -qB;
        d->comp_q[2 * c->comp] = qA;
        d->comp_q[2 * c->comp + 1] = qB;
        if (G) {
            hyd_jac_flow(m, G, c->P, feed, g1, -g1);
            hyd_jac_flow(m, G, drain, c->T, g2, -g2);
            // Spool column: dQ/du = dQ/dA * A_max * sign(u).
            const double du1 = g1A * c->Amax * sgn, du2 = g2A * c->Amax * sgn;
            G[m->node_sidx[c->P] * ld + c->adr] -= du1;
            G[m->node_sidx[feed] * ld + c->adr] += du1;
            G[m->node_sidx[drain] * ld + c->adr] -= du2;
            G[m->node_sidx[c->T] * ld + c->adr] += du2;
        }
    }
}

void hyd_valves_eval(const hyd_model* m, hyd_data* d, const double* y, double* ydot, double* G) {
    if (G)
        valves_kernel(m, d, y, ydot, G, NULL);
    else
        valves_kernel(m, d, y, ydot, NULL, NULL);
}

void hyd_valves_eval_mapped(const hyd_model* m, hyd_data* d, const double* y, double* ydot,
                            const int* map) {
    valves_kernel(m, d, y, ydot, NULL, map);
}
