// circuit_query.c: what a compiled circuit tells about itself (sizes, names,
// indices, geometry). Cheap lookups, not for the hot loop.
#include "hyd_internal.h"

#include <string.h>

static int find_name(char* const* names, int n, const char* s) {
    for (int i = 0; i < n; ++i)
        if (strcmp(names[i], s) == 0)
            return i;
    return -1;
}

int hyd_model_nstate(const hyd_model* m) { return m->nstate; }
int hyd_model_nnode(const hyd_model* m) { return m->nnode; }
int hyd_model_ncomp(const hyd_model* m) { return m->ncomp; }
int hyd_model_ncylinder(const hyd_model* m) { return m->ncyl; }
int hyd_model_nvalve(const hyd_model* m) { return m->nvalve; }

int hyd_model_find(const hyd_model* m, const char* name) {
    for (int i = 0; i < m->ncomp; ++i)
        if (strcmp(m->comp[i].name, name) == 0)
            return i;
    return -1;
}

int hyd_model_find_node(const hyd_model* m, const char* name) {
    return find_name(m->node_name, m->nnode, name);
}

int hyd_model_cylinder(const hyd_model* m, const char* name) {
    int c = hyd_model_find(m, name);
    return (c >= 0 && m->comp[c].type == HYD_CYLINDER) ? m->comp_sub[c] : -1;
}

int hyd_model_valve(const hyd_model* m, const char* name) {
    int c = hyd_model_find(m, name);
    return (c >= 0 && m->comp[c].type == HYD_VALVE) ? m->comp_sub[c] : -1;
}

int hyd_model_find_state(const hyd_model* m, const char* name) {
    return find_name(m->state_name, m->nstate, name);
}

const char* hyd_model_comp_name(const hyd_model* m, int c) {
    return (c >= 0 && c < m->ncomp) ? m->comp[c].name : NULL;
}
hyd_type hyd_model_comp_type(const hyd_model* m, int c) {
    return (c >= 0 && c < m->ncomp) ? m->comp[c].type : HYD_TYPE_COUNT;
}
const char* hyd_model_node_name(const hyd_model* m, int i) {
    return (i >= 0 && i < m->nnode) ? m->node_name[i] : NULL;
}
int hyd_model_node_state(const hyd_model* m, int i) {
    return (i >= 0 && i < m->nnode) ? m->node_state[i] : -1;
}
const char* hyd_model_state_name(const hyd_model* m, int i) {
    return (i >= 0 && i < m->nstate) ? m->state_name[i] : NULL;
}
void hyd_model_cylinder_states(const hyd_model* m, int c, int* iA, int* iB) {
    *iA = m->cyl[c].sA;
    *iB = m->cyl[c].sB;
}
int hyd_model_valve_state(const hyd_model* m, int v) { return m->valve[v].adr; }
int hyd_model_cylinder_comp(const hyd_model* m, int c) { return m->cyl[c].comp; }
int hyd_model_valve_comp(const hyd_model* m, int v) { return m->valve[v].comp; }
int hyd_model_relief_inlet(const hyd_model* m, int c) {
    if (c < 0 || c >= m->ncomp || m->comp[c].type != HYD_RELIEF) return -1;
    return m->relief[m->comp_sub[c]].in;
}
void hyd_model_cylinder_geometry(const hyd_model* m, int c, double* AA, double* AB, double* s) {
    *AA = m->cyl[c].AA;
    *AB = m->cyl[c].AB;
    *s = m->cyl[c].s;
}
void hyd_model_initial_state(const hyd_model* m, double* y) {
    memcpy(y, m->y0, (size_t)m->nstate * sizeof *y);
}
hyd_fluid_def hyd_model_fluid(const hyd_model* m) { return m->fluid; }

