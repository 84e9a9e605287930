// relief.c: pressure relief valve with a C1 quadratic opening corner.
//
// With d = p_in - p_out - p_crack and w = dp_override:
//   q = q_rated * ramp(d, w),  ramp = 0 (d <= 0), (d/w)^2 (d < w), 1 + 2(d - w)/w (beyond).
// Value and slope match at d = 0 and d = w, so the Jacobian stays bounded when
// the valve cracks; beyond w it behaves as a linear (laminar-like) resistance
// with the slope of the corner's end, 2 q_rated / w.
#include "hyd_ramp.h"

hyd_relief_def hyd_default_relief_def(void) {
    hyd_relief_def d = {0};
    d.dp_override = 1e6;
    d.q_rated = 40.0 / 60000.0;
    return d;
}

double hyd_open_ramp(double d, double w, double* dr) {
    const double inv_w = 1.0 / w;
    return hyd_open_ramp_t(d * inv_w, inv_w, dr);
}

static void relief_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)m, (void)node0;
    const hyd_relief_def* d = def;
    hyd_ramp_c* c = rec;
    c->pcr = d->p_crack;
    c->inv_w = 1.0 / d->dp_override;
    c->qr = d->q_rated;
}

// Shared by relief and check valves (check_valve.c): both are the same
// opening law between two nodes; only their defaults and roles differ. Most
// of them are closed most of the time (d <= 0), which takes the short branch:
// zero flow, no partials.
void hyd_ramps_eval(const hyd_model* m, hyd_data* d, double* G, const hyd_ramp_c* v, int nv) {
    const double* restrict p = d->node_p;
    double* restrict cq = d->comp_q;
    int* restrict open = d->comp_open;
    double* restrict fl = d->flow_;
    for (int i = 0; i < nv; ++i) {
        const hyd_ramp_c* c = &v[i];
        double g, t;
        const double q = hyd_ramp_q(c->pcr, c->inv_w, c->qr, p[c->in] - p[c->out], &g, &t);
        if (t <= 0.0) { // closed: +0 flows (a NaN takes the full path and propagates)
            cq[2 * c->comp] = 0.0;
            open[c->comp] = 0;
            fl[4 * c->comp] = 0.0;
            fl[4 * c->comp + 1] = 0.0;
            continue;
        }
        cq[2 * c->comp] = q;
        open[c->comp] = q > 0.0;
        fl[4 * c->comp] = -q;
        fl[4 * c->comp + 1] = q;
        if (G)
            hyd_jac_flow(m, G, c->in, c->out, g, -g);
    }
}

void hyd_ramps_component_eval(const hyd_model* m, hyd_data* d, const void* rec, int n,
                              const double* y, double* ydot, double* G, const int* map) {
    (void)y, (void)ydot, (void)map;
    hyd_ramps_eval(m, d, G, rec, n);
}

void hyd_ramp_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own, (void)state;
    hyd_ramp_c* c = rec;
    c->comp = comp, c->in = port[0], c->out = port[1];
}

static const hyd_param_info relief_params[] = {
    HYD_PARAM(hyd_relief_def, p_crack, "Pa", HYD_R_POS, 1, 1e5, 1e8, 5e6, 4.5e7),
    HYD_PARAM(hyd_relief_def, dp_override, "Pa", HYD_R_POS, 0, 1e3, 1e7, 1e5, 5e6),
    HYD_PARAM(hyd_relief_def, q_rated, "m^3/s", HYD_R_POS, 0, 1e-7, 0.1, 1e-5, 5e-3),
};
static const hyd_port_info relief_ports[] = {HYD_PORT(hyd_relief_def, inlet), HYD_PORT(hyd_relief_def, outlet)};

static void relief_defaults(void* def) { *(hyd_relief_def*)def = hyd_default_relief_def(); }

HYD_DEF_FITS(hyd_relief_def);
const hyd_component hyd_relief_component = {
    .type = HYD_RELIEF, .name = "relief", .def_size = sizeof(hyd_relief_def),
    .params = relief_params, .nparam = HYD_COUNT(relief_params),
    .ports = relief_ports, .nport = HYD_COUNT(relief_ports),
    .rec_size = sizeof(hyd_ramp_c),
    .defaults = relief_defaults, .bind = hyd_ramp_bind, .derive = relief_derive,
    .eval = hyd_ramps_component_eval,
};
