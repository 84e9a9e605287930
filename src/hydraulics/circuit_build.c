// circuit_build.c: from definitions to a compiled circuit. The builder (a
// list of element definitions), validation of names and ports, compilation
// into index arrays (nodes, states, packed records per type, flow slots),
// and the derived values recomputed after every parameter change.
//
// Nothing here knows a component type: each type's descriptor
// (hyd_component, component_table.c) says which nodes and states it owns,
// which ports it has, how its record is bound and derived.
#include "hyd_internal.h"

#include <stdlib.h>
#include <string.h>

// ---------------------------------------------------------------------------
// Builder
// ---------------------------------------------------------------------------

struct hyd_builder {
    hyd_fluid_def fluid;
    hyd_elem* node;
    int nnode, capnode;
    hyd_elem* comp;
    int ncomp, capcomp;
    int oom; ///< an add failed for lack of memory; compile reports it
};

char* hyd_strdup(const char* s) {
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char* r = malloc(n);
    if (r)
        memcpy(r, s, n);
    return r;
}

void hyd_elem_free(hyd_elem* e) {
    free(e->name);
    for (int k = 0; k < HYD_MAXPORT; ++k)
        free(e->port[k]);
}

// Deep copy: the def's name and port pointers are redirected to owned strings.
int hyd_elem_copy(hyd_elem* dst, const hyd_elem* src) {
    *dst = *src;
    dst->name = hyd_strdup(src->name);
    int np;
    const hyd_port_info* pi = hyd_ports_of(src->type, &np);
    for (int k = 0; k < HYD_MAXPORT; ++k)
        dst->port[k] = (k < np) ? hyd_strdup(src->port[k]) : NULL;
    char* base = hyd_elem_def(dst);
    *(const char**)base = dst->name; // every def starts with name
    for (int k = 0; k < np; ++k)
        *(const char**)(base + pi[k].off) = dst->port[k];
    if ((src->name && !dst->name))
        return -1;
    for (int k = 0; k < np; ++k)
        if (src->port[k] && !dst->port[k])
            return -1;
    return 0;
}

hyd_builder* hyd_builder_create(void) {
    hyd_builder* b = calloc(1, sizeof *b);
    if (b)
        b->fluid = hyd_default_fluid_def();
    return b;
}

void hyd_builder_free(hyd_builder* b) {
    if (!b)
        return;
    for (int i = 0; i < b->nnode; ++i)
        hyd_elem_free(&b->node[i]);
    for (int i = 0; i < b->ncomp; ++i)
        hyd_elem_free(&b->comp[i]);
    free(b->node);
    free(b->comp);
    free(b);
}

void hyd_builder_set_fluid(hyd_builder* b, const hyd_fluid_def* fluid) { b->fluid = *fluid; }

int hyd_add(hyd_builder* b, hyd_type t, const void* def) {
    const hyd_component* desc = hyd_component_of(t);
    if (!desc)
        return -1;
    hyd_elem** arr = desc->is_node ? &b->node : &b->comp;
    int* n = desc->is_node ? &b->nnode : &b->ncomp;
    int* cap = desc->is_node ? &b->capnode : &b->capcomp;
    if (*n == *cap) {
        int nc = *cap ? 2 * *cap : 16;
        hyd_elem* na = realloc(*arr, (size_t)nc * sizeof **arr);
        if (!na) {
            b->oom = 1;
            return -1;
        }
        *arr = na;
        *cap = nc;
    }
    hyd_elem src;
    memset(&src, 0, sizeof src);
    src.type = t;
    memcpy(&src.def, def, desc->def_size);
    src.name = (char*)*(const char* const*)def;
    for (int k = 0; k < desc->nport; ++k)
        src.port[k] = (char*)*(const char* const*)((const char*)def + desc->ports[k].off);
    if (hyd_elem_copy(&(*arr)[*n], &src) != 0) {
        hyd_elem_free(&(*arr)[*n]);
        b->oom = 1;
        return -1;
    }
    return (*n)++;
}

int hyd_add_tank(hyd_builder* b, const hyd_tank_def* d) { return hyd_add(b, HYD_TANK, d); }
int hyd_add_volume(hyd_builder* b, const hyd_volume_def* d) { return hyd_add(b, HYD_VOLUME, d); }
int hyd_add_pump(hyd_builder* b, const hyd_pump_def* d) { return hyd_add(b, HYD_PUMP, d); }
int hyd_add_relief(hyd_builder* b, const hyd_relief_def* d) { return hyd_add(b, HYD_RELIEF, d); }
int hyd_add_check(hyd_builder* b, const hyd_check_def* d) { return hyd_add(b, HYD_CHECK, d); }
int hyd_add_orifice(hyd_builder* b, const hyd_orifice_def* d) { return hyd_add(b, HYD_ORIFICE, d); }
int hyd_add_hose(hyd_builder* b, const hyd_hose_def* d) { return hyd_add(b, HYD_HOSE, d); }
int hyd_add_valve(hyd_builder* b, const hyd_valve_def* d) { return hyd_add(b, HYD_VALVE, d); }
int hyd_add_cylinder(hyd_builder* b, const hyd_cylinder_def* d) { return hyd_add(b, HYD_CYLINDER, d); }

// ---------------------------------------------------------------------------
// Compile
// ---------------------------------------------------------------------------

static int validate_name(const hyd_elem* el, int where, int index, hyd_build_error* e) {
    if (!el->name || !el->name[0])
        return hyd_set_err(e, where, index, "name", "missing or empty");
    if (strchr(el->name, '.'))
        return hyd_set_err(e, where, index, "name", "must not contain '.' (used in state names)");
    if (strcmp(el->name, "fluid") == 0)
        return hyd_set_err(e, where, index, "name", "'fluid' is reserved");
    return 0;
}

static int find_name(char* const* names, int n, const char* s) {
    for (int i = 0; i < n; ++i)
        if (strcmp(names[i], s) == 0)
            return i;
    return -1;
}

static char* joinname(const char* a, const char* b) {
    size_t la = strlen(a), lb = strlen(b);
    char* r = malloc(la + lb + 2);
    if (r) {
        memcpy(r, a, la);
        r[la] = '.';
        memcpy(r + la + 1, b, lb + 1);
    }
    return r;
}

void hyd_model_free(hyd_model* m) {
    if (!m)
        return;
    for (int i = 0; i < m->nunode; ++i)
        hyd_elem_free(&m->unode[i]);
    for (int i = 0; i < m->ncomp; ++i)
        hyd_elem_free(&m->comp[i]);
    if (m->node_name)
        for (int i = 0; i < m->nnode; ++i)
            free(m->node_name[i]);
    if (m->state_name)
        for (int i = 0; i < m->nstate; ++i)
            free(m->state_name[i]);
    free(m->unode);
    free(m->comp);
    free(m->node_name);
    free(m->node_state);
    free(m->node_sidx);
    free(m->node_V0);
    free(m->node_bel);
    free(m->node_bec);
    free(m->node_pfix);
    free(m->node_p0);
    free(m->vol_node);
    free(m->tank_node);
    for (int t = 0; t < HYD_TYPE_COUNT; ++t)
        free(m->rec[t]); // the typed views (m->pump, ...) point into these
    free(m->node_owner);
    free(m->comp_node0);
    free(m->comp_slot);
    free(m->comp_state0);
    free(m->comp_sub);
    free(m->vol_ptr);
    free(m->vol_flow);
    free(m->state_name);
    free(m->y0);
    free(m->flush_state);
    free(m->flush_below);
    free(m);
}

// The packed record of component c.
static void* comp_rec(const hyd_model* m, int c) {
    const hyd_component* d = hyd_component_of(m->comp[c].type);
    return d->rec_size ? (char*)m->rec[d->type] + (size_t)m->comp_sub[c] * d->rec_size : NULL;
}

// States an element owns: its nodes' pressures, then its other states.
static int elem_nstate(const hyd_component* d) {
    int n = d->nstate;
    for (int k = 0; k < d->nnode; ++k)
        n += d->nodes[k].state != NULL;
    return n;
}

// CSR lists of the flow slots that feed each volume node (tanks get none:
// their inflow is never needed).
static int build_incidence(hyd_model* m) {
    if (!HYD_ALLOC(m->vol_ptr, m->nvol + 1) || !HYD_ALLOC(m->vol_flow, HYD_MAXSLOT * m->ncomp))
        return -1;
    int ne = 0;
    for (int k = 0; k < m->nvol; ++k) {
        m->vol_ptr[k] = ne;
        for (int c = 0; c < m->ncomp; ++c)
            for (int j = 0; j < HYD_MAXSLOT; ++j)
                if (m->comp_slot[HYD_MAXSLOT * c + j] == m->vol_node[k])
                    m->vol_flow[ne++] = HYD_MAXSLOT * c + j;
    }
    m->vol_ptr[m->nvol] = ne;
    return 0;
}

// Typed views of the record arrays, for the kernels and queries that know
// their type.
static void set_views(hyd_model* m) {
    m->pump = m->rec[HYD_PUMP], m->npump = m->nrec[HYD_PUMP];
    m->relief = m->rec[HYD_RELIEF], m->nrelief = m->nrec[HYD_RELIEF];
    m->check = m->rec[HYD_CHECK], m->ncheck = m->nrec[HYD_CHECK];
    m->orifice = m->rec[HYD_ORIFICE], m->norifice = m->nrec[HYD_ORIFICE];
    m->hose = m->rec[HYD_HOSE], m->nhose = m->nrec[HYD_HOSE];
    m->valve = m->rec[HYD_VALVE], m->nvalve = m->nrec[HYD_VALVE];
    m->cyl = m->rec[HYD_CYLINDER], m->ncyl = m->nrec[HYD_CYLINDER];
}

static hyd_model* fail(hyd_model* m, int* tmp, hyd_build_error* e, int where, int index,
                       const char* field, const char* msg) {
    free(tmp);
    hyd_model_free(m);
    hyd_set_err(e, where, index, field, msg);
    return NULL;
}

hyd_model* hyd_compile_ex(const hyd_builder* b, hyd_build_error* e) {
    if (e) {
        e->where = -1;
        e->index = 0;
        e->field[0] = e->msg[0] = 0;
    }
    if (b->oom)
        return hyd_set_err(e, -1, 0, "", "out of memory while building"), NULL;
    if (hyd_validate_fluid(&b->fluid, e))
        return NULL;
    for (int i = 0; i < b->nnode; ++i)
        if (validate_name(&b->node[i], 1, i, e) || hyd_validate_values(&b->node[i], 1, i, e))
            return NULL;
    for (int i = 0; i < b->ncomp; ++i)
        if (validate_name(&b->comp[i], 2, i, e) || hyd_validate_values(&b->comp[i], 2, i, e))
            return NULL;
    // Element names are unique across nodes and components, so a path
    // "<name>.<field>" is never ambiguous.
    for (int i = 0; i < b->nnode + b->ncomp; ++i) {
        const hyd_elem* ei = i < b->nnode ? &b->node[i] : &b->comp[i - b->nnode];
        for (int j = 0; j < i; ++j) {
            const hyd_elem* ej = j < b->nnode ? &b->node[j] : &b->comp[j - b->nnode];
            if (strcmp(ei->name, ej->name) == 0) {
                char msg[160];
                snprintf(msg, sizeof msg, "duplicate name '%s' (also %s[%d])", ei->name,
                         j < b->nnode ? "nodes" : "components", j < b->nnode ? j : j - b->nnode);
                return hyd_set_err(e, i < b->nnode ? 1 : 2, i < b->nnode ? i : i - b->nnode,
                                   "name", msg),
                       NULL;
            }
        }
    }

    hyd_model* m = calloc(1, sizeof *m);
    if (!m)
        return hyd_set_err(e, -1, 0, "", "out of memory"), NULL;
    m->fluid = b->fluid;

    // Count nodes, states and records, from each type's descriptor.
    int nnode = 0, nstate = 0;
    for (int i = 0; i < b->nnode + b->ncomp; ++i) {
        const hyd_elem* el = i < b->nnode ? &b->node[i] : &b->comp[i - b->nnode];
        const hyd_component* d = hyd_component_of(el->type);
        nnode += d->nnode;
        nstate += elem_nstate(d);
        if (d->nnode + d->nport > HYD_MAXSLOT)
            return fail(m, NULL, e, -1, 0, "", "a component type has more than HYD_MAXSLOT flow slots");
        if (i >= b->nnode)
            m->nrec[el->type]++;
    }
    m->nnode = nnode;
    m->nstate = nstate;
    int ok = HYD_ALLOC(m->unode, b->nnode) && HYD_ALLOC(m->comp, b->ncomp) &&
             HYD_ALLOC(m->node_name, nnode) && HYD_ALLOC(m->node_state, nnode) &&
             HYD_ALLOC(m->node_sidx, nnode) && HYD_ALLOC(m->node_V0, nnode) &&
             HYD_ALLOC(m->node_bel, nnode) && HYD_ALLOC(m->node_pfix, nnode) &&
             HYD_ALLOC(m->node_bec, nnode) && HYD_ALLOC(m->node_owner, nnode) &&
             HYD_ALLOC(m->node_p0, nnode) && HYD_ALLOC(m->vol_node, nnode) &&
             HYD_ALLOC(m->tank_node, nnode) && HYD_ALLOC(m->comp_node0, b->ncomp) &&
             HYD_ALLOC(m->comp_slot, HYD_MAXSLOT * b->ncomp) && HYD_ALLOC(m->comp_state0, b->ncomp) &&
             HYD_ALLOC(m->comp_sub, b->ncomp) && HYD_ALLOC(m->state_name, nstate) &&
             HYD_ALLOC(m->y0, nstate) && HYD_ALLOC(m->flush_state, nstate) &&
             HYD_ALLOC(m->flush_below, nstate);
    for (int t = 0; t < HYD_TYPE_COUNT && ok; ++t) {
        const hyd_component* d = hyd_component_of((hyd_type)t);
        if (d && d->rec_size) {
            m->rec[t] = calloc((size_t)(m->nrec[t] > 0 ? m->nrec[t] : 1), d->rec_size);
            ok = m->rec[t] != NULL;
        }
    }
    set_views(m);
    // Elements are copied one by one and counted, so a failed copy frees cleanly.
    int nu = 0, nc = 0;
    if (ok) {
        for (; nu < b->nnode && ok; ++nu)
            ok = hyd_elem_copy(&m->unode[nu], &b->node[nu]) == 0;
        for (; nc < b->ncomp && ok; ++nc)
            ok = hyd_elem_copy(&m->comp[nc], &b->comp[nc]) == 0;
    }
    m->nunode = nu;
    m->ncomp = nc;
    if (!ok)
        return fail(m, NULL, e, -1, 0, "", "out of memory");

    // Nodes and states in the documented order: user nodes, then owned
    // nodes in component order; volume pressures, then component states.
    int* state0 = m->comp_state0;
    int in = 0, is = 0;
    int nsub[HYD_TYPE_COUNT] = {0};
    for (int i = 0; i < b->nnode + b->ncomp; ++i) {
        const int c = i - b->nnode; // component index, or < 0 for a user node
        const hyd_elem* el = c < 0 ? &b->node[i] : &b->comp[c];
        const hyd_component* d = hyd_component_of(el->type);
        if (c >= 0) {
            m->comp_node0[c] = in;
            m->comp_sub[c] = nsub[el->type]++;
            state0[c] = is;
        }
        for (int k = 0; k < d->nnode; ++k, ++in) {
            const hyd_owned_node* on = &d->nodes[k];
            m->node_name[in] = on->suffix ? joinname(el->name, on->suffix) : hyd_strdup(el->name);
            m->node_owner[in] = c;
            m->node_state[in] = -1;
            if (on->state) {
                m->node_state[in] = is;
                m->state_name[is++] = joinname(el->name, on->state);
            }
        }
        for (int k = 0; k < d->nstate; ++k) {
            if (d->state_flush && d->state_flush[k] > 0.0) {
                m->flush_state[m->nflush] = is;
                m->flush_below[m->nflush++] = d->state_flush[k];
            }
            m->state_name[is++] = joinname(el->name, d->states[k]);
        }
    }
    for (int i = 0; i < nnode; ++i)
        if (!m->node_name[i])
            return fail(m, NULL, e, -1, 0, "", "out of memory");
    for (int i = 0; i < nstate; ++i)
        if (!m->state_name[i])
            return fail(m, NULL, e, -1, 0, "", "out of memory");
    for (int i = 0; i < nnode; ++i) {
        m->node_sidx[i] = m->node_state[i] >= 0 ? m->node_state[i] : nstate;
        if (m->node_state[i] >= 0)
            m->vol_node[m->nvol++] = i;
        else
            m->tank_node[m->ntank++] = i;
    }

    // Resolve ports by node name, counting the ports on each user node, and
    // bind each record to its nodes and states.
    int* conn = calloc((size_t)(nnode > 0 ? nnode : 1), sizeof *conn);
    if (!conn)
        return fail(m, NULL, e, -1, 0, "", "out of memory");
    for (int i = 0; i < b->ncomp; ++i) {
        const hyd_elem* el = &b->comp[i];
        const hyd_component* d = hyd_component_of(el->type);
        const hyd_port_info* pi = d->ports;
        const int np = d->nport;
        int node[HYD_MAXPORT] = {0};
        char msg[200];
        for (int k = 0; k < np; ++k) {
            if (pi[k].ref) {
                node[k] = -1; // a component, resolved below once every record is bound
                continue;
            }
            if (!el->port[k]) {
                free(conn);
                return fail(m, NULL, e, 2, i, pi[k].name, "missing node name");
            }
            node[k] = find_name(m->node_name, nnode, el->port[k]);
            if (node[k] < 0) {
                snprintf(msg, sizeof msg, "unknown node '%s'", el->port[k]);
                free(conn);
                return fail(m, NULL, e, 2, i, pi[k].name, msg);
            }
            for (int j = 0; j < k; ++j)
                if (!pi[j].ref && node[j] == node[k]) {
                    snprintf(msg, sizeof msg, "same node '%s' as %s", el->port[k], pi[j].name);
                    free(conn);
                    return fail(m, NULL, e, 2, i, pi[k].name, msg);
                }
        }
        for (int k = 0; k < np; ++k)
            if (node[k] >= 0)
                ++conn[node[k]];
        int own[HYD_MAXSLOT], st[HYD_MAXSLOT + 4];
        for (int k = 0; k < d->nnode; ++k)
            own[k] = m->comp_node0[i] + k;
        for (int k = 0; k < elem_nstate(d) && k < HYD_MAXSLOT + 4; ++k)
            st[k] = state0[i] + k;
        if (d->check_ports) {
            char field[32];
            if (d->check_ports(m, (const char* const*)el->port, node, own, field, sizeof field, msg,
                               sizeof msg)) {
                free(conn);
                return fail(m, NULL, e, 2, i, field, msg);
            }
        }
        if (d->bind)
            d->bind(comp_rec(m, i), i, node, own, st);
        // Flow slots: the owned nodes, then the ports.
        int* slot = m->comp_slot + HYD_MAXSLOT * i;
        for (int j = 0; j < HYD_MAXSLOT; ++j)
            slot[j] = j < d->nnode ? own[j] : (j - d->nnode < np ? node[j - d->nnode] : -1);
    }
    // A user node that nothing connects to is a typo or a leftover (its
    // pressure would be a state that never changes). One port is enough: a
    // pump charging a closed volume is a proper circuit.
    for (int i = 0; i < b->nnode; ++i)
        if (!conn[i]) {
            char msg[200];
            snprintf(msg, sizeof msg, "'%s' is connected to no component (an isolated %s)", b->node[i].name,
                     hyd_type_name(b->node[i].type));
            free(conn);
            return fail(m, NULL, e, 1, i, "name", msg);
        }
    free(conn);
    // Component references (a shuttle's valve): by name, after every record
    // is bound, so the one named may come later in the list.
    for (int i = 0; i < b->ncomp; ++i) {
        const hyd_elem* el = &b->comp[i];
        const hyd_component* d = hyd_component_of(el->type);
        for (int k = 0; k < d->nport; ++k) {
            if (!d->ports[k].ref || !el->port[k])
                continue;
            int r = -1;
            for (int j = 0; j < b->ncomp && r < 0; ++j)
                if (b->comp[j].name && !strcmp(b->comp[j].name, el->port[k]))
                    r = j;
            char msg[200];
            if (r < 0 || r == i) {
                snprintf(msg, sizeof msg, r < 0 ? "unknown component '%s'" : "'%s' is the component itself",
                         el->port[k]);
                return fail(m, NULL, e, 2, i, d->ports[k].name, msg);
            }
            const int node = d->bind_ref(m, comp_rec(m, i), r, msg, sizeof msg);
            if (node < 0)
                return fail(m, NULL, e, 2, i, d->ports[k].name, msg);
            m->comp_slot[HYD_MAXSLOT * i + d->nnode + k] = node;
        }
    }
    if (build_incidence(m))
        return fail(m, NULL, e, -1, 0, "", "out of memory");
    hyd_model_derive(m, e);
    return m;
}

hyd_model* hyd_compile(const hyd_builder* b, char* err, size_t errsz) {
    hyd_build_error e;
    hyd_model* m = hyd_compile_ex(b, &e);
    if (!m && err && errsz) {
        const char* name = "fluid";
        if (e.where == 1 && e.index < b->nnode && b->node[e.index].name)
            name = b->node[e.index].name;
        else if (e.where == 2 && e.index < b->ncomp && b->comp[e.index].name)
            name = b->comp[e.index].name;
        if (e.where == -1)
            snprintf(err, errsz, "%s", e.msg);
        else if ((e.where == 1 || e.where == 2) && !strcmp(e.field, "name"))
            snprintf(err, errsz, "%s[%d].name: %s", e.where == 1 ? "nodes" : "components",
                     e.index, e.msg);
        else
            snprintf(err, errsz, "%s.%s: %s", name, e.field, e.msg);
    }
    return m;
}

// ---------------------------------------------------------------------------
// Derived arrays
// ---------------------------------------------------------------------------

int hyd_model_derive(hyd_model* m, hyd_build_error* e) {
    (void)e;
    const hyd_fluid_def* f = &m->fluid;
    m->be_alpha = f->air_fraction;
    m->be_inv_n = 1.0 / f->polytropic_index;
    for (int i = 0; i < m->nunode; ++i) {
        const hyd_elem* el = &m->unode[i];
        hyd_component_of(el->type)->derive(m, &el->def, NULL, i);
    }
    for (int i = 0; i < m->ncomp; ++i) {
        const hyd_elem* el = &m->comp[i];
        hyd_component_of(el->type)->derive(m, &el->def, comp_rec(m, i), m->comp_node0[i]);
    }
    hyd_air_tab_init(&m->air, f);
    for (int i = 0; i < m->nnode; ++i) {
        m->node_bec[i] = m->be_alpha * m->node_bel[i] * m->be_inv_n;
    }
    for (int k = 0; k < m->nvol; ++k)
        m->y0[m->node_state[m->vol_node[k]]] = m->node_p0[m->vol_node[k]];
    for (int i = 0; i < m->ncomp; ++i) {
        const hyd_component* d = hyd_component_of(m->comp[i].type);
        if (d->initial)
            d->initial(&m->comp[i].def, comp_rec(m, i), m->y0);
    }
    return 0;
}
