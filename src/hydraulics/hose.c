// hose.c: hose or short pipe between a valve and a cylinder port.
//
// The hose is a pressure node of volume pi d^2 L / 4 with its own effective
// bulk modulus (oil plus wall compliance, lower than the oil's), joined to the
// node "to" by a laminar Hagen-Poiseuille resistance
//   Q = G (p_hose - p_to),  G = pi d^4 / (128 mu L),  mu = rho nu.
// Hose and chamber then form each actuator's fastest (stiff) modes.
#include "hyd_hose.h"
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

static void hose_derive(hyd_model* m, const void* def, void* rec, int node0) {
    const hyd_fluid_def* f = &m->fluid;
    const hyd_hose_def* d = def;
    hyd_hose_c* c = rec;
    const double d2 = d->diameter * d->diameter;
    c->G = HYD_PI * d2 * d2 / (128.0 * f->density * f->viscosity * d->length);
    m->node_V0[node0] = hyd_hose_volume(d);
    m->node_bel[node0] = d->bulk_modulus > 0.0 ? d->bulk_modulus : f->bulk_modulus;
    m->node_p0[node0] = d->p0;
    m->node_pfix[node0] = 0.0;
}

static void hoses_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                       double* ydot, double* G, const int* map) {
    (void)y, (void)ydot, (void)map;
    for (int i = 0; i < n; ++i) {
        const hyd_hose_c* c = (const hyd_hose_c*)rec + i;
        const double q = hyd_hose_q(c->G, d->node_p[c->node], d->node_p[c->to]);
        d->comp_q[2 * c->comp] = q;
        hyd_flow2(m, d, G, c->comp, c->node, c->to, q, c->G, -c->G);
    }
}

static int hose_check_ports(const hyd_model* m, const char* const* port_name, const int* port,
                            const int* own, char* field, size_t fsz, char* msg, size_t msz) {
    (void)m, (void)port_name;
    if (port[0] == own[0]) {
        snprintf(field, fsz, "to");
        snprintf(msg, msz, "a hose cannot end at its own node");
        return -1;
    }
    return 0;
}

static void hose_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)state;
    hyd_hose_c* c = rec;
    c->comp = comp, c->node = own[0], c->to = port[0];
}

static const hyd_param_info hose_params[] = {
    HYD_PARAM(hyd_hose_def, length, "m", HYD_R_POS, 1, 0.01, 100, 0.2, 20),
    HYD_PARAM(hyd_hose_def, diameter, "m", HYD_R_POS, 1, 1e-3, 0.2, 4e-3, 0.05),
    HYD_PARAM(hyd_hose_def, bulk_modulus, "Pa", HYD_R_ZERO_DEF, 0, 1e7, 1e10, 1e8, 2.5e9),
    HYD_PARAM(hyd_hose_def, p0, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 5e7),
};
static const hyd_port_info hose_ports[] = {HYD_PORT(hyd_hose_def, to)};
// The hose's volume is a node named after the hose, with state "<name>.p".
static const hyd_owned_node hose_nodes[] = {{NULL, "p"}};

static void hose_defaults(void* def) { *(hyd_hose_def*)def = hyd_default_hose_def(); }

HYD_DEF_FITS(hyd_hose_def);
const hyd_component hyd_hose_component = {
    .type = HYD_HOSE, .name = "hose", .def_size = sizeof(hyd_hose_def),
    .params = hose_params, .nparam = HYD_COUNT(hose_params),
    .ports = hose_ports, .nport = HYD_COUNT(hose_ports),
    .nodes = hose_nodes, .nnode = HYD_COUNT(hose_nodes),
    .rec_size = sizeof(hyd_hose_c),
    .defaults = hose_defaults, .check_ports = hose_check_ports, .bind = hose_bind,
    .derive = hose_derive, .eval = hoses_eval,
};
