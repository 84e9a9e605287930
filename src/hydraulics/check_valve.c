// check_valve.c: anti-cavitation check valve, tank -> cylinder port.
//
// It opens when the port pressure falls p_crack below the tank (d = p_in -
// p_out - p_crack > 0) and follows the same C1 quadratic corner as the relief
// (relief.c), reaching q_rated after a further dp_open. Refilling a chamber
// that is pulled open keeps its pressure near p_tank - p_crack instead of
// letting it sink towards absolute zero.
#include "hyd_internal.h"

hyd_check_def hyd_default_check_def(void) {
    hyd_check_def d = {0};
    d.p_crack = 0.05e6;
    d.dp_open = 0.02e6;
    d.q_rated = 40.0 / 60000.0;
    return d;
}

static void check_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)m, (void)node0;
    const hyd_check_def* d = def;
    hyd_ramp_c* c = rec;
    c->pcr = d->p_crack;
    c->inv_w = 1.0 / d->dp_open;
    c->qr = d->q_rated;
}

static const hyd_param_info check_params[] = {
    HYD_PARAM(hyd_check_def, p_crack, "Pa", HYD_R_NONNEG, 0, 0, 1e7, 0, 1e6),
    HYD_PARAM(hyd_check_def, dp_open, "Pa", HYD_R_POS, 0, 1e2, 1e7, 5e3, 1e6),
    HYD_PARAM(hyd_check_def, q_rated, "m^3/s", HYD_R_POS, 0, 1e-7, 0.1, 1e-5, 5e-3),
};
static const hyd_port_info check_ports[] = {HYD_PORT(hyd_check_def, inlet), HYD_PORT(hyd_check_def, outlet)};

static void check_defaults(void* def) { *(hyd_check_def*)def = hyd_default_check_def(); }

// The same opening law and record as the relief (relief.c).
HYD_DEF_FITS(hyd_check_def);
const hyd_component hyd_check_component = {
    .type = HYD_CHECK, .name = "check", .def_size = sizeof(hyd_check_def),
    .params = check_params, .nparam = HYD_COUNT(check_params),
    .ports = check_ports, .nport = HYD_COUNT(check_ports),
    .rec_size = sizeof(hyd_ramp_c),
    .defaults = check_defaults, .bind = hyd_ramp_bind, .derive = check_derive,
    .eval = hyd_ramps_component_eval,
};
