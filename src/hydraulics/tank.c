// tank.c: fixed-pressure nodes (the tank, or an ideal supply). A tank has no
// state; components see it as a node whose pressure never changes, and the
// flow slots of a tank are never gathered (volume.c skips it).
#include "hyd_internal.h"

hyd_tank_def hyd_default_tank_def(void) {
    hyd_tank_def d = {0};
    d.pressure = 1e5;
    return d;
}

static void tank_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)rec;
    const hyd_tank_def* t = def;
    m->node_pfix[node0] = t->pressure;
    m->node_p0[node0] = t->pressure;
    m->node_V0[node0] = 0.0;
    m->node_bel[node0] = m->fluid.bulk_modulus;
}

static const hyd_param_info tank_params[] = {
    HYD_PARAM(hyd_tank_def, pressure, "Pa", HYD_R_NONNEG, 0, 0, 1e7, 5e4, 1e6),
};
// A tank is its own node, without a state.
static const hyd_owned_node tank_nodes[] = {{NULL, NULL}};

static void tank_defaults(void* def) { *(hyd_tank_def*)def = hyd_default_tank_def(); }

HYD_DEF_FITS(hyd_tank_def);
const hyd_component hyd_tank_component = {
    .type = HYD_TANK, .name = "tank", .is_node = 1, .def_size = sizeof(hyd_tank_def),
    .params = tank_params, .nparam = HYD_COUNT(tank_params),
    .nodes = tank_nodes, .nnode = HYD_COUNT(tank_nodes),
    .defaults = tank_defaults, .derive = tank_derive,
};
