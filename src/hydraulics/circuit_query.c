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


// ---------------------------------------------------------------------------
// Structure
// ---------------------------------------------------------------------------

int hyd_model_state_node(const hyd_model* m, int i) {
    if (i < 0 || i >= m->nstate)
        return -1;
    for (int k = 0; k < m->nvol; ++k)
        if (m->node_state[m->vol_node[k]] == i)
            return m->vol_node[k];
    return -1;
}

hyd_state_kind hyd_model_state_kind(const hyd_model* m, int i) {
    if (i < 0 || i >= m->nstate)
        return HYD_STATE_OTHER;
    if (hyd_model_state_node(m, i) >= 0)
        return HYD_STATE_PRESSURE;
    // A non-pressure state belongs to the last component whose states start
    // at or before it (states are consecutive per component).
    int owner = -1;
    for (int c = 0; c < m->ncomp; ++c)
        if (m->comp_state0[c] <= i && hyd_component_of(m->comp[c].type)->nstate)
            owner = c;
    return owner >= 0 && m->comp[owner].type == HYD_VALVE ? HYD_STATE_SPOOL : HYD_STATE_OTHER;
}

hyd_node_role hyd_model_node_role(const hyd_model* m, int i) {
    if (i < 0 || i >= m->nnode)
        return HYD_NODE_LINE;
    if (m->node_state[i] < 0)
        return HYD_NODE_TANK;
    for (int k = 0; k < m->npump; ++k)
        if (m->pump[k].out == i)
            return HYD_NODE_SUPPLY;
    // Roles other types give the nodes at their ports (descriptor port_roles).
    hyd_node_role r = HYD_NODE_LINE;
    for (int c = 0; c < m->ncomp; ++c) {
        const hyd_component* d = hyd_component_of(m->comp[c].type);
        if (!d->port_roles)
            continue;
        for (int k = 0; k < d->nport; ++k)
            if (d->port_roles[k] != HYD_NODE_LINE && hyd_model_port_node(m, c, k) == i) {
                if (d->port_roles[k] == HYD_NODE_SUPPLY)
                    return HYD_NODE_SUPPLY;
                r = d->port_roles[k];
            }
    }
    return r;
}

int hyd_model_supply_node(const hyd_model* m) {
    for (int i = 0; i < m->nnode; ++i)
        if (hyd_model_node_role(m, i) == HYD_NODE_SUPPLY)
            return i;
    return -1;
}

int hyd_model_node_owner(const hyd_model* m, int i) {
    return (i >= 0 && i < m->nnode) ? m->node_owner[i] : -1;
}

int hyd_model_comp_node(const hyd_model* m, int c, int k) {
    if (c < 0 || c >= m->ncomp)
        return -1;
    const hyd_component* d = hyd_component_of(m->comp[c].type);
    return (k >= 0 && k < d->nnode) ? m->comp_node0[c] + k : -1;
}

int hyd_model_port_node(const hyd_model* m, int c, int k) {
    if (c < 0 || c >= m->ncomp)
        return -1;
    const hyd_component* d = hyd_component_of(m->comp[c].type);
    // Flow slots are the owned nodes, then the ports (circuit_build.c).
    return (k >= 0 && k < d->nport) ? m->comp_slot[HYD_MAXSLOT * c + d->nnode + k] : -1;
}

int hyd_model_feed_hose(const hyd_model* m, int node) {
    for (int h = 0; h < m->nhose; ++h)
        if (m->hose[h].to == node)
            return m->hose[h].comp;
    return -1;
}

void hyd_model_jacobian_pattern(const hyd_model* m, unsigned char* P) {
    const int n = m->nstate;
    memset(P, 0, (size_t)n * (size_t)n);
    for (int k = 0; k < m->nvol; ++k) {
        const int s = m->node_state[m->vol_node[k]];
        P[(size_t)s * n + s] = 1; // Be(p) / V depends on p
    }
    for (int c = 0; c < m->ncomp; ++c) {
        const hyd_component* d = hyd_component_of(m->comp[c].type);
        const int* slot = m->comp_slot + HYD_MAXSLOT * c;
        // The component's own non-pressure states: after its nodes' pressures.
        int s0 = m->comp_state0[c];
        const int ns = d->nstate;
        for (int k = 0; k < d->nnode; ++k)
            s0 += m->node_state[m->comp_node0[c] + k] >= 0;
        for (int a = 0; a < HYD_MAXSLOT; ++a) {
            if (slot[a] < 0 || m->node_state[slot[a]] < 0)
                continue;
            const int sa = m->node_state[slot[a]];
            for (int b = 0; b < HYD_MAXSLOT; ++b)
                if (slot[b] >= 0 && m->node_state[slot[b]] >= 0)
                    P[(size_t)sa * n + m->node_state[slot[b]]] = 1;
            for (int k = 0; k < ns; ++k)
                P[(size_t)sa * n + s0 + k] = 1;
        }
        // A state of another component its flows follow (a shuttle's valve spool).
        const int rs = d->ref_state && d->rec_size
                           ? d->ref_state((const char*)m->rec[d->type] + (size_t)m->comp_sub[c] * d->rec_size)
                           : -1;
        for (int a = 0; a < HYD_MAXSLOT && rs >= 0; ++a)
            if (slot[a] >= 0 && m->node_state[slot[a]] >= 0)
                P[(size_t)m->node_state[slot[a]] * n + rs] = 1;
        for (int k = 0; k < ns; ++k)
            P[(size_t)(s0 + k) * n + s0 + k] = 1; // a lag on its own state
        if (d->states_sense_ports)
            for (int k = 0; k < ns; ++k) {
                for (int a = 0; a < HYD_MAXSLOT; ++a)
                    if (slot[a] >= 0 && m->node_state[slot[a]] >= 0)
                        P[(size_t)(s0 + k) * n + m->node_state[slot[a]]] = 1;
                for (int j = 0; j < ns; ++j)
                    P[(size_t)(s0 + k) * n + s0 + j] = 1;
            }
    }
}

// ---- parameter tables, for generated parameter lists (the live panel) -----

static int range_of(const hyd_param_info* p, int n, int k, double* lo, double* hi, double* tlo, double* thi) {
    if (!p || k < 0 || k >= n) return -1;
    if (lo) *lo = p[k].lo;
    if (hi) *hi = p[k].hi;
    if (tlo) *tlo = p[k].tlo;
    if (thi) *thi = p[k].thi;
    return 0;
}

int hyd_param_range(hyd_type t, int k, double* lo, double* hi, double* tlo, double* thi) {
    int n;
    const hyd_param_info* p = hyd_params_of(t, &n);
    return range_of(p, n, k, lo, hi, tlo, thi);
}

int hyd_fluid_param_count(void) {
    int n;
    hyd_fluid_params(&n);
    return n;
}

const char* hyd_fluid_param_name(int k) {
    int n;
    const hyd_param_info* p = hyd_fluid_params(&n);
    return k >= 0 && k < n ? p[k].name : NULL;
}

const char* hyd_fluid_param_unit(int k) {
    int n;
    const hyd_param_info* p = hyd_fluid_params(&n);
    return k >= 0 && k < n ? p[k].unit : NULL;
}

int hyd_fluid_param_range(int k, double* lo, double* hi, double* tlo, double* thi) {
    int n;
    const hyd_param_info* p = hyd_fluid_params(&n);
    return range_of(p, n, k, lo, hi, tlo, thi);
}

int hyd_model_nelement(const hyd_model* m) { return m->nunode + m->ncomp; }

const char* hyd_model_element(const hyd_model* m, int i, hyd_type* type) {
    if (i < 0 || i >= m->nunode + m->ncomp) return NULL;
    const hyd_elem* e = i < m->nunode ? &m->unode[i] : &m->comp[i - m->nunode];
    if (type) *type = e->type;
    return e->name;
}
