// shuttle.c: LS shuttle valve, the element of the load-sensing signal network.
//
// The shuttle passes the higher of two pressures to the LS line. With
// d = p_a - p_b and w the corner half-width, the selected pressure is
//   smax = p_b (d <= -w),  p_b + (d + w)^2 / (4 w) (|d| < w),  p_a (d >= w)
// (value and slope continuous at d = +-w: C1), and the signal path is a
// laminar resistance, q = G (smax - p_out) into the LS line "out" (negative
// when the line is higher: it drains back through the shuttle, as a real
// one does into the loaded port). The flow is drawn from a and b in the
// shares sigma and 1 - sigma, sigma = smoothstep((d + w) / (2 w)), so the
// port flows are C1 as well and their sum is q (mass is kept). The LS line
// is a declared volume node; its bleed to tank is a fixed orifice
// (orifice.c), which the LS pump needs to see a falling load.
#include "hyd_shuttle.h"

hyd_shuttle_def hyd_default_shuttle_def(void) {
    hyd_shuttle_def d = {0};
    d.conductance = 2e-11;
    d.width = 1e5;
    d.spool_width = 0.2;
    return d;
}

static void shuttles_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                          double* ydot, double* G, const int* map) {
    (void)ydot;
    const int ld = m->nstate + 1;
    for (int i = 0; i < n; ++i) {
        const hyd_shuttle_c* c = (const hyd_shuttle_c*)rec + i;
        const int spool = c->su >= 0;
        const double u = spool ? y[map ? map[c->su] : c->su] : 0.0;
        const double pt = spool ? d->node_p[c->t] : 0.0;
        hyd_shuttle_flow e;
        hyd_shuttle_law(c, u, d->node_p[c->a], d->node_p[c->b], d->node_p[c->out], pt, &e);
        d->comp_q[2 * c->comp] = e.f[2];
        double* fl = d->flow_ + HYD_MAXSLOT * c->comp;
        fl[0] = e.f[0], fl[1] = e.f[1], fl[2] = e.f[2], fl[3] = e.f[3];
        if (G) {
            const int ns = spool ? 4 : 3;
            const int node[4] = {c->a, c->b, c->out, spool ? c->t : c->out};
            for (int r = 0; r < ns; ++r) {
                double* row = G + (size_t)m->node_sidx[node[r]] * ld;
                for (int j = 0; j < ns; ++j) row[m->node_sidx[node[j]]] += e.g[r][j];
                if (spool) row[c->su] += e.du[r];
            }
        }
    }
}

static void shuttle_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)m, (void)node0;
    const hyd_shuttle_def* d = def;
    hyd_shuttle_c* c = rec;
    c->G = d->conductance;
    c->w = d->width;
    c->inv_uw = 1.0 / d->spool_width;
}

static void shuttle_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own, (void)state;
    hyd_shuttle_c* c = rec;
    c->comp = comp, c->a = port[0], c->b = port[1], c->out = port[2];
    c->t = -1, c->su = -1; // max-select unless a valve is named (shuttle_bind_ref)
}

// Spool mode: the valve named by "valve" must be a 4/3 valve whose work
// ports are a (sensed for u > 0) and b (u < 0); the drain is its T port.
static int shuttle_bind_ref(const hyd_model* m, void* rec, int ref, char* msg, size_t msz) {
    hyd_shuttle_c* c = rec;
    const char* name = m->comp[ref].name;
    if (m->comp[ref].type != HYD_VALVE) {
        snprintf(msg, msz, "'%s' is a %s, not a valve (a shuttle in spool mode follows a 4/3 valve's spool)",
                 name, hyd_type_name(m->comp[ref].type));
        return -1;
    }
    const hyd_valve_c* v = &m->valve[m->comp_sub[ref]];
    if (v->A != c->a || v->B != c->b) {
        snprintf(msg, msz,
                 "valve '%s' has work ports A '%s', B '%s': in spool mode the shuttle's a and b must be "
                 "them (a sensed for a positive spool, b for a negative)",
                 name, m->node_name[v->A], m->node_name[v->B]);
        return -1;
    }
    c->t = v->T;
    c->su = v->adr;
    return v->T;
}

static int shuttle_ref_state(const void* rec) { return ((const hyd_shuttle_c*)rec)->su; }

static const hyd_param_info shuttle_params[] = {
    HYD_PARAM(hyd_shuttle_def, conductance, "m^3/(s Pa)", HYD_R_POS, 0, 1e-15, 1e-8, 1e-12, 1e-10),
    HYD_PARAM(hyd_shuttle_def, width, "Pa", HYD_R_POS, 0, 1e2, 2e6, 1e4, 5e5),
    // Spool travel over which the LS edge opens (a fraction of full stroke):
    // below 1e-3 the switch is a step to the stiff solvers; above 0.5 the
    // signal lags most of the metering range.
    HYD_PARAM(hyd_shuttle_def, spool_width, "-", HYD_R_POS, 0, 1e-3, 0.5, 0.02, 0.3),
};
static const hyd_port_info shuttle_ports[] = {HYD_PORT(hyd_shuttle_def, a), HYD_PORT(hyd_shuttle_def, b),
                                              HYD_PORT(hyd_shuttle_def, out),
                                              HYD_PORT_REF(hyd_shuttle_def, valve)};
static const hyd_node_role shuttle_roles[] = {HYD_NODE_LINE, HYD_NODE_LINE, HYD_NODE_LS, HYD_NODE_LINE};

static void shuttle_defaults(void* def) { *(hyd_shuttle_def*)def = hyd_default_shuttle_def(); }

HYD_DEF_FITS(hyd_shuttle_def);
const hyd_component hyd_shuttle_component = {
    .type = HYD_SHUTTLE, .name = "shuttle", .def_size = sizeof(hyd_shuttle_def),
    .params = shuttle_params, .nparam = HYD_COUNT(shuttle_params),
    .ports = shuttle_ports, .nport = HYD_COUNT(shuttle_ports),
    .rec_size = sizeof(hyd_shuttle_c), .port_roles = shuttle_roles,
    .defaults = shuttle_defaults, .bind = shuttle_bind, .bind_ref = shuttle_bind_ref,
    .ref_state = shuttle_ref_state, .derive = shuttle_derive, .eval = shuttles_eval,
};
