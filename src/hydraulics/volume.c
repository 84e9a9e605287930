// volume.c: volume nodes, and the pressure equation of every node with a
// pressure state (volumes, hoses, cylinder chambers).
//
//   dp/dt = Be(p) / V * (sum Q_in - dV/dt)
// V and dV/dt come from the node's fixed volume plus whatever a cylinder wrote
// for its chambers; sum Q_in is gathered here from the components' per-port flow slots.
#include "hyd_internal.h"

hyd_volume_def hyd_default_volume_def(void) {
    hyd_volume_def d = {0};
    d.p0 = 1e5;
    return d;
}

static void volume_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)rec;
    const hyd_volume_def* v = def;
    m->node_pfix[node0] = 0.0;
    m->node_p0[node0] = v->p0;
    m->node_V0[node0] = v->volume;
    m->node_bel[node0] = v->bulk_modulus > 0.0 ? v->bulk_modulus : m->fluid.bulk_modulus;
}

static const hyd_param_info volume_params[] = {
    HYD_PARAM(hyd_volume_def, volume, "m^3", HYD_R_POS, 1, 1e-9, 10, 1e-6, 0.1),
    HYD_PARAM(hyd_volume_def, bulk_modulus, "Pa", HYD_R_ZERO_DEF, 0, 1e7, 1e10, 1e8, 2.5e9),
    HYD_PARAM(hyd_volume_def, p0, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 5e7),
};
// A volume is its own node, with state "<name>.p".
static const hyd_owned_node volume_nodes[] = {{NULL, "p"}};

static void volume_defaults(void* def) { *(hyd_volume_def*)def = hyd_default_volume_def(); }

HYD_DEF_FITS(hyd_volume_def);
const hyd_component hyd_volume_component = {
    .type = HYD_VOLUME, .name = "volume", .is_node = 1, .def_size = sizeof(hyd_volume_def),
    .params = volume_params, .nparam = HYD_COUNT(volume_params),
    .nodes = volume_nodes, .nnode = HYD_COUNT(volume_nodes),
    .defaults = volume_defaults, .derive = volume_derive,
};

// The plain evaluation (no Jacobian), the hot path of every f evaluation:
// the same arithmetic as the loop below, in a loop of its own so that the
// Jacobian's locals do not crowd the registers.
// map (NULL: identity) is the caller's state order of hyd_eval_mapped.
static inline void volumes_f(const hyd_model* m, hyd_data* d, double* restrict ydot,
                             const int* restrict map) {
    const int nvol = m->nvol;
    const double* restrict flow = d->flow_;
    const int* restrict vf = m->vol_flow;
    const int* restrict vp = m->vol_ptr;
    const int* restrict vnode = m->vol_node;
    const int* restrict nstate = m->node_state;
    const double* restrict np = d->node_p;
    const double* restrict nV = d->node_V;
    const double* restrict ndV = d->node_dV;
    const double* restrict nbel = m->node_bel;
    const double* restrict nbec = m->node_bec;
    double* restrict nq = d->node_q;
    double* restrict nbe = d->node_be;
    for (int k = 0; k < nvol; ++k) {
        const int node = vnode[k];
        const double p = np[node];
        const double V = nV[node];
        const double bel = nbel[node];
        double qin = 0.0;
        const int e1 = vp[k + 1];
        for (int e = vp[k]; e < e1; ++e)
            qin += flow[vf[e]];
        nq[node] = qin;
        const double net = qin - ndV[node];
        double be;
        const double c = hyd_node_c(m, bel, nbec[node], p, V, &be, NULL);
        nbe[node] = be;
        ydot[map ? map[nstate[node]] : nstate[node]] = c * net;
    }
}

void hyd_volumes_eval_mapped(const hyd_model* m, hyd_data* d, double* ydot, const int* map) {
    volumes_f(m, d, ydot, map);
}

// Per node: gather the inflow, then Be/V through hyd_node_c with a single
// division, c = N / (D V), Be = c V. Jacobian rows (when J is non-NULL): the
// flow partials scaled by Be/V, plus the term from Be depending on the node's
// own pressure. G holds d(sum Q)/dy. Model and data arrays are taken into
// restrict locals first: the stores into hyd_data would otherwise force the
// compiler to reload every model field on each node.
void hyd_volumes_eval(const hyd_model* m, hyd_data* d, double* ydot, const double* G, double* J,
                      int ldj) {
    if (!J && ydot) {
        volumes_f(m, d, ydot, NULL);
        return;
    }
    const int n = m->nstate, ldg = n + 1, nvol = m->nvol;
    const double* restrict flow = d->flow_;
    const int* restrict vf = m->vol_flow;
    const int* restrict vp = m->vol_ptr;
    const int* restrict vnode = m->vol_node;
    const int* restrict nstate = m->node_state;
    const double* restrict np = d->node_p;
    const double* restrict nV = d->node_V;
    const double* restrict ndV = d->node_dV;
    const double* restrict nbel = m->node_bel;
    const double* restrict nbec = m->node_bec;
    double* restrict nq = d->node_q;
    double* restrict nbe = d->node_be;
    for (int k = 0; k < nvol; ++k) {
        const int node = vnode[k];
        const int i = nstate[node];
        const double p = np[node];
        const double V = nV[node];
        const double bel = nbel[node];
        double qin = 0.0;
        const int e1 = vp[k + 1];
        for (int e = vp[k]; e < e1; ++e)
            qin += flow[vf[e]];
        nq[node] = qin;
        const double net = qin - ndV[node];
        double be, dbe = 0.0;
        const double c = hyd_node_c(m, bel, nbec[node], p, V, &be, J ? &dbe : NULL);
        nbe[node] = be;
        if (ydot)
            ydot[i] = c * net;
        if (J) {
            double* row = J + (size_t)i * ldj;
            const double* grow = G + (size_t)i * ldg;
            for (int j = 0; j < n; ++j)
                row[j] = c * grow[j];
            row[i] += dbe / V * net;
        }
    }
}
