// pump.c: pressure-compensated variable pump as a flow source.
//
// Full flow q_max while the pressure rise dp = p_out - p_in is at most p_set,
// then q_max (1 - smoothstep((dp - p_set)/band)): C1, zero at p_set + band.
// The cubic corner keeps dQ/dp bounded (-1.5 q_max / band at mid-band), so
// the pump-line mode stays finite for the stiff solvers.
#include "hyd_pump.h"

hyd_pump_def hyd_default_pump_def(void) {
    hyd_pump_def d = {0};
    d.band = 0.5e6;
    return d;
}

static void pump_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)m, (void)node0;
    const hyd_pump_def* d = def;
    hyd_pump_c* c = rec;
    c->qmax = d->q_max;
    c->pset = d->p_set;
    c->inv_band = 1.0 / d->band;
}

static void pumps_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                       double* ydot, double* G, const int* map) {
    (void)y, (void)ydot, (void)map;
    for (int i = 0; i < n; ++i) {
        const hyd_pump_c* c = (const hyd_pump_c*)rec + i;
        const double dp = d->node_p[c->out] - d->node_p[c->in];
        // q flows in -> out and depends on p_out - p_in.
        double g, t; // dq/d(dp), and where dp stands in the band
        const double q = hyd_pump_q(c->qmax, c->pset, c->inv_band, dp, &g, &t);
        d->comp_q[2 * c->comp] = q;
        d->comp_open[c->comp] = t > 0.0;
        hyd_flow2(m, d, G, c->comp, c->in, c->out, q, -g, g);
    }
}

static const hyd_param_info pump_params[] = {
    HYD_PARAM(hyd_pump_def, q_max, "m^3/s", HYD_R_POS, 1, 1e-7, 0.1, 1e-5, 5e-3),
    HYD_PARAM(hyd_pump_def, p_set, "Pa", HYD_R_POS, 1, 1e5, 1e8, 5e6, 4.5e7),
    HYD_PARAM(hyd_pump_def, band, "Pa", HYD_R_POS, 0, 1e3, 1e7, 1e4, 3e6),
};
static const hyd_port_info pump_ports[] = {HYD_PORT(hyd_pump_def, inlet), HYD_PORT(hyd_pump_def, outlet)};

static void pump_defaults(void* def) { *(hyd_pump_def*)def = hyd_default_pump_def(); }

static void pump_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own, (void)state;
    hyd_pump_c* c = rec;
    c->comp = comp, c->in = port[0], c->out = port[1];
}

HYD_DEF_FITS(hyd_pump_def);
const hyd_component hyd_pump_component = {
    .type = HYD_PUMP, .name = "pump", .def_size = sizeof(hyd_pump_def),
    .params = pump_params, .nparam = HYD_COUNT(pump_params),
    .ports = pump_ports, .nport = HYD_COUNT(pump_ports),
    .rec_size = sizeof(hyd_pump_c),
    .defaults = pump_defaults, .bind = pump_bind, .derive = pump_derive, .eval = pumps_eval,
};
