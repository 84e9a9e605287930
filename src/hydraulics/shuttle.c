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
    return d;
}

static void shuttles_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                          double* ydot, double* G, const int* map) {
    (void)y, (void)ydot, (void)map;
    const int ld = m->nstate + 1;
    for (int i = 0; i < n; ++i) {
        const hyd_shuttle_c* c = (const hyd_shuttle_c*)rec + i;
        const double pa = d->node_p[c->a], pb = d->node_p[c->b], po = d->node_p[c->out];
        double sa, sig, dsig; // dsig = d sigma / d pa = - d sigma / d pb
        const double q = hyd_shuttle_q(c, pa, pb, po, &sig, &dsig, &sa);
        d->comp_q[2 * c->comp] = q;
        double* fl = d->flow_ + HYD_MAXSLOT * c->comp;
        fl[0] = -sig * q, fl[1] = -(1.0 - sig) * q, fl[2] = q;
        if (G) {
            const int s_a = m->node_sidx[c->a], s_b = m->node_sidx[c->b], s_o = m->node_sidx[c->out];
            const double qa = c->G * sa, qb = c->G * (1.0 - sa), qo = -c->G; // dq / dp
            // Inflows: -sigma q at a, -(1 - sigma) q at b, q at out.
            G[s_a * ld + s_a] -= dsig * q + sig * qa;
            G[s_a * ld + s_b] -= -dsig * q + sig * qb;
            G[s_a * ld + s_o] -= sig * qo;
            G[s_b * ld + s_a] -= -dsig * q + (1.0 - sig) * qa;
            G[s_b * ld + s_b] -= dsig * q + (1.0 - sig) * qb;
            G[s_b * ld + s_o] -= (1.0 - sig) * qo;
            G[s_o * ld + s_a] += qa;
            G[s_o * ld + s_b] += qb;
            G[s_o * ld + s_o] += qo;
        }
    }
}

static void shuttle_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)m, (void)node0;
    const hyd_shuttle_def* d = def;
    hyd_shuttle_c* c = rec;
    c->G = d->conductance;
    c->w = d->width;
}

static void shuttle_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own, (void)state;
    hyd_shuttle_c* c = rec;
    c->comp = comp, c->a = port[0], c->b = port[1], c->out = port[2];
}

static const hyd_param_info shuttle_params[] = {
    HYD_PARAM(hyd_shuttle_def, conductance, "m^3/(s Pa)", HYD_R_POS, 0, 1e-15, 1e-8, 1e-12, 1e-10),
    HYD_PARAM(hyd_shuttle_def, width, "Pa", HYD_R_POS, 0, 1e2, 2e6, 1e4, 5e5),
};
static const hyd_port_info shuttle_ports[] = {HYD_PORT(hyd_shuttle_def, a), HYD_PORT(hyd_shuttle_def, b),
                                              HYD_PORT(hyd_shuttle_def, out)};
static const hyd_node_role shuttle_roles[] = {HYD_NODE_LINE, HYD_NODE_LINE, HYD_NODE_LS};

static void shuttle_defaults(void* def) { *(hyd_shuttle_def*)def = hyd_default_shuttle_def(); }

HYD_DEF_FITS(hyd_shuttle_def);
const hyd_component hyd_shuttle_component = {
    .type = HYD_SHUTTLE, .name = "shuttle", .def_size = sizeof(hyd_shuttle_def),
    .params = shuttle_params, .nparam = HYD_COUNT(shuttle_params),
    .ports = shuttle_ports, .nport = HYD_COUNT(shuttle_ports),
    .rec_size = sizeof(hyd_shuttle_c), .port_roles = shuttle_roles,
    .defaults = shuttle_defaults, .bind = shuttle_bind, .derive = shuttle_derive, .eval = shuttles_eval,
};
