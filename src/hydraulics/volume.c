// volume.c: pressure nodes (fixed volumes, tanks, and the pressure equation
// shared by hoses and cylinder chambers).
//
//   dp/dt = Be(p) / V * (sum Q_in - dV/dt)
// V and dV/dt come from the node's fixed volume plus whatever a cylinder wrote
// for its chambers; sum Q_in is gathered here from the components' per-port flow slots.
#include "hyd_internal.h"

hyd_tank_def hyd_default_tank_def(void) {
    hyd_tank_def d = {0};
    d.pressure = 1e5;
    return d;
}

hyd_volume_def hyd_default_volume_def(void) {
    hyd_volume_def d = {0};
    d.p0 = 1e5;
    return d;
}

// Jacobian rows of a node state i: the flow partials scaled by Be/V, plus the
// term from Be depending on the node's own pressure. G holds d(sum Q)/dy.
void hyd_volumes_eval(const hyd_model* m, hyd_data* d, double* ydot, const double* G, double* J,
                      int ldj) {
    const int n = m->nstate, ldg = n + 1;
    for (int k = 0; k < m->nvol; ++k) {
        const int node = m->vol_node[k];
        const int i = m->node_state[node];
        const double p = d->node_p[node];
        const double V = d->node_V[node];
        double dbe;
        const double be = hyd_be(m, m->node_bel[node], p, &dbe);
        double qin = 0.0;
        for (int e = m->vol_ptr[k]; e < m->vol_ptr[k + 1]; ++e)
            qin += d->flow_[m->vol_flow[e]];
        d->node_q[node] = qin;
        const double net = qin - d->node_dV[node];
        const double iV = 1.0 / V;
        const double c = be * iV;
        d->node_be[node] = be;
        if (ydot)
            ydot[i] = c * net;
        if (J) {
            double* row = J + (size_t)i * ldj;
            const double* grow = G + (size_t)i * ldg;
            for (int j = 0; j < n; ++j)
                row[j] = c * grow[j];
            row[i] += dbe * iV * net;
        }
    }
}
