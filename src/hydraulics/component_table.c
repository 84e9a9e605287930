// component_table.c: the element types, indexed by hyd_type. Adding a
// component: its hyd_type value and def struct in hydraulics.h, its file
// with a hyd_component descriptor, and one line here (docs/architecture.md).
#include "hyd_internal.h"

extern const hyd_component hyd_tank_component, hyd_volume_component, hyd_pump_component,
    hyd_relief_component, hyd_check_component, hyd_orifice_component, hyd_hose_component,
    hyd_valve_component, hyd_cylinder_component, hyd_ls_pump_component,
    hyd_shuttle_component, hyd_compensator_component, hyd_counterbalance_component,
    hyd_accumulator_component;

// Designated by type, so the order of lines cannot disagree with hyd_type.
static const hyd_component* const table[HYD_TYPE_COUNT] = {
    [HYD_TANK] = &hyd_tank_component,
    [HYD_VOLUME] = &hyd_volume_component,
    [HYD_PUMP] = &hyd_pump_component,
    [HYD_RELIEF] = &hyd_relief_component,
    [HYD_CHECK] = &hyd_check_component,
    [HYD_ORIFICE] = &hyd_orifice_component,
    [HYD_HOSE] = &hyd_hose_component,
    [HYD_VALVE] = &hyd_valve_component,
    [HYD_CYLINDER] = &hyd_cylinder_component,
    [HYD_LS_PUMP] = &hyd_ls_pump_component,
    [HYD_SHUTTLE] = &hyd_shuttle_component,
    [HYD_COMPENSATOR] = &hyd_compensator_component,
    [HYD_COUNTERBALANCE] = &hyd_counterbalance_component,
    [HYD_ACCUMULATOR] = &hyd_accumulator_component,
};

const hyd_component* hyd_component_of(hyd_type t) {
    return (t >= 0 && t < HYD_TYPE_COUNT) ? table[t] : NULL;
}

const char* hyd_type_name(hyd_type t) {
    const hyd_component* c = hyd_component_of(t);
    return c ? c->name : "?";
}

int hyd_type_parse(const char* name) {
    for (int t = 0; t < HYD_TYPE_COUNT; ++t)
        if (table[t] && strcmp(name, table[t]->name) == 0)
            return t;
    return -1;
}

const hyd_param_info* hyd_params_of(hyd_type t, int* count) {
    const hyd_component* c = hyd_component_of(t);
    *count = c ? c->nparam : 0;
    return c ? c->params : NULL;
}

const hyd_port_info* hyd_ports_of(hyd_type t, int* count) {
    const hyd_component* c = hyd_component_of(t);
    *count = c ? c->nport : 0;
    return c ? c->ports : NULL;
}
