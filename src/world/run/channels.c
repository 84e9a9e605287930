// channels.c: the engine's row plus its circuit's channels (channels.h).
#include "channels.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Where a circuit channel's value comes from.
typedef enum { SRC_NODE_P, SRC_STATE, SRC_FLOW } chan_src;

struct chan_list {
    engine* e;
    const hyd_model* hm; ///< the circuit the list was made from
    int nrow, n;
    sim_channel* ch;     ///< (n)
    char (*name)[96];    ///< (n - nrow) names of the circuit channels
    chan_src* src;       ///< (n - nrow)
    int* idx;            ///< (n - nrow) node, state or flow slot (component * 2 + entry)
    hyd_data* hd;        ///< the list's own evaluation (the engine's is its own)
    double *y, *ydot;    ///< (nstate)
    double* row;         ///< (max(nrow, SIM_NCOL)) engine_row's buffer
};

static int add(chan_list* c, int cap, const char* name, const char* unit, sim_channel_kind kind, chan_src src,
               int idx) {
    if (c->n == cap) return -1;
    const int k = c->n - c->nrow;
    snprintf(c->name[k], sizeof c->name[k], "%s", name);
    c->ch[c->n] = (sim_channel){c->name[k], unit, kind};
    c->src[k] = src;
    c->idx[k] = idx;
    ++c->n;
    return 0;
}

chan_list* chan_list_create(engine* e) {
    chan_list* c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->e = e;
    c->hm = engine_circuit(e);
    const sim_channel* row = engine_channels(e, &c->nrow);
    const hyd_model* m = c->hm;
    const int nnode = hyd_model_nnode(m), ncomp = hyd_model_ncomp(m), ns = hyd_model_nstate(m);
    // At most: a pressure per node, a spool per valve, two flows per
    // component, and every other state a component owns.
    int nother = 0;
    for (int i = 0; i < ns; ++i) nother += hyd_model_state_kind(m, i) == HYD_STATE_OTHER;
    const int cap = c->nrow + nnode + 3 * ncomp + nother;
    c->ch = calloc((size_t)cap, sizeof *c->ch);
    c->name = calloc((size_t)(cap - c->nrow) + 1, sizeof *c->name);
    c->src = calloc((size_t)(cap - c->nrow) + 1, sizeof *c->src);
    c->idx = calloc((size_t)(cap - c->nrow) + 1, sizeof *c->idx);
    c->y = calloc((size_t)ns + 1, sizeof *c->y);
    c->ydot = calloc((size_t)ns + 1, sizeof *c->ydot);
    c->row = calloc((size_t)(c->nrow > SIM_NCOL ? c->nrow : SIM_NCOL), sizeof *c->row);
    c->hd = hyd_data_create(m);
    if (!c->row || !c->ch || !c->name || !c->src || !c->idx || !c->y || !c->ydot || !c->hd) {
        chan_list_free(c);
        return NULL;
    }
    memcpy(c->ch, row, sizeof *row * (size_t)c->nrow);
    c->n = c->nrow;
    char nm[96];
    for (int i = 0; i < nnode; ++i) {
        snprintf(nm, sizeof nm, "%s.p", hyd_model_node_name(m, i));
        add(c, cap, nm, "Pa", SIM_CH_PRESSURE, SRC_NODE_P, i);
    }
    for (int v = 0; v < hyd_model_nvalve(m); ++v) {
        snprintf(nm, sizeof nm, "%s.spool", hyd_model_comp_name(m, hyd_model_valve_comp(m, v)));
        add(c, cap, nm, "-", SIM_CH_OTHER, SRC_STATE, hyd_model_valve_state(m, v));
    }
    // The states of the load-sensing components and accumulators under their
    // state names (docs/hydraulics.md): a LS pump's displacement
    // "<name>.disp", a compensator's or counterbalance valve's spool
    // "<name>.spool" (fractions of full, [-]), an accumulator's oil volume
    // "<name>.oil" [m^3].
    for (int i = 0; i < ns; ++i) {
        if (hyd_model_state_kind(m, i) != HYD_STATE_OTHER) continue;
        const char* sn = hyd_model_state_name(m, i);
        const char* dot = strrchr(sn, '.');
        add(c, cap, sn, dot && !strcmp(dot, ".oil") ? "m^3" : "-", SIM_CH_OTHER, SRC_STATE, i);
    }
    for (int k = 0; k < ncomp; ++k) {
        const char* cn = hyd_model_comp_name(m, k);
        if (hyd_model_comp_type(m, k) == HYD_VALVE) {
            snprintf(nm, sizeof nm, "%s.qA", cn);
            add(c, cap, nm, "m^3/s", SIM_CH_OTHER, SRC_FLOW, 2 * k);
            snprintf(nm, sizeof nm, "%s.qB", cn);
            add(c, cap, nm, "m^3/s", SIM_CH_OTHER, SRC_FLOW, 2 * k + 1);
        } else {
            snprintf(nm, sizeof nm, "%s.q", cn);
            add(c, cap, nm, "m^3/s", SIM_CH_OTHER, SRC_FLOW, 2 * k);
        }
    }
    return c;
}

void chan_list_free(chan_list* c) {
    if (!c) return;
    free(c->ch);
    free(c->name);
    free(c->src);
    free(c->idx);
    free(c->y);
    free(c->ydot);
    free(c->row);
    if (c->hd) hyd_data_free(c->hd);
    free(c);
}

int chan_list_count(const chan_list* c) { return c ? c->n : 0; }
int chan_list_nrow(const chan_list* c) { return c ? c->nrow : 0; }

const sim_channel* chan_list_channel(const chan_list* c, int k) {
    return c && k >= 0 && k < c->n ? &c->ch[k] : NULL;
}

int chan_list_find(const chan_list* c, const char* name) {
    for (int k = 0; c && name && k < c->n; ++k)
        if (!strcmp(c->ch[k].name, name)) return k;
    return -1;
}

void chan_list_values(chan_list* c, engine* e, double* out, bool row_done) {
    if (!row_done) {
        engine_row(e, c->row);
        memcpy(out, c->row, sizeof *out * (size_t)c->nrow);
    }
    if (c->n == c->nrow) return;
    const hyd_data* in = NULL;
    engine_circuit_state(e, c->y, &in);
    const hyd_model* m = engine_circuit(e);
    // The engine's inputs (strokes, rates, commands) as it last evaluated
    // the circuit; the flows then follow from the state now.
    if (in) {
        memcpy(c->hd->cyl_x, in->cyl_x, sizeof *c->hd->cyl_x * (size_t)hyd_model_ncylinder(m));
        memcpy(c->hd->cyl_v, in->cyl_v, sizeof *c->hd->cyl_v * (size_t)hyd_model_ncylinder(m));
        memcpy(c->hd->valve_cmd, in->valve_cmd, sizeof *c->hd->valve_cmd * (size_t)hyd_model_nvalve(m));
    }
    hyd_eval(m, c->hd, out[COL_T], c->y, c->ydot);
    for (int k = c->nrow; k < c->n; ++k) {
        const int j = k - c->nrow, i = c->idx[j];
        switch (c->src[j]) {
        case SRC_NODE_P: {
            // A state node's pressure is its state; a tank's is fixed.
            const int st = hyd_model_node_state(m, i);
            out[k] = st >= 0 ? c->y[st] : c->hd->node_p[i];
            break;
        }
        case SRC_STATE: out[k] = c->y[i]; break;
        case SRC_FLOW: out[k] = c->hd->comp_q[i]; break;
        }
    }
}
