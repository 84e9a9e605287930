// engine_faults.c: a scenario's fault events on a circuit (engine_faults.h):
// the bursts' orifices added to a copy of the model, the bursts a world's
// circuit must hold, the events applied at each step. Moved whole out of
// engine.c: every backend applies them, and a backend may not use the
// layer that chooses it.
#include "engine_faults.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

// A burst's orifice while the hose holds: the smallest area an orifice
// accepts, 1e-10 m^2, leaks 0.7 mL/min at 15 MPa (the cylinder's own
// internal leakage at that pressure is 9 mL/min).
#define BURST_CLOSED_AREA 1e-10
// A stopped pump: the smallest flow the pump accepts (6 mL/min).
#define PUMP_STOPPED_Q 1e-7

// The orifice of scenario fault i: "fault<i>_burst".
static void burst_name(char* out, size_t n, int i) { snprintf(out, n, "fault%d_burst", i); }

// Whether the circuit fragment declares a pressure node called name: one
// of its volumes, a hose (its own node) or a cylinder's chamber.
static bool fragment_has_node(const cJSON* frag, const char* name) {
    const cJSON* e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(frag, "nodes")) {
        const cJSON* n = cJSON_GetObjectItemCaseSensitive(e, "name");
        const cJSON* t = cJSON_GetObjectItemCaseSensitive(e, "type");
        if (cJSON_IsString(n) && !strcmp(n->valuestring, name) && !(cJSON_IsString(t) && !strcmp(t->valuestring, "tank")))
            return true;
    }
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(frag, "components")) {
        const cJSON* n = cJSON_GetObjectItemCaseSensitive(e, "name");
        const cJSON* t = cJSON_GetObjectItemCaseSensitive(e, "type");
        if (!cJSON_IsString(n) || !cJSON_IsString(t)) continue;
        const size_t L = strlen(n->valuestring);
        if (!strcmp(t->valuestring, "hose") && !strcmp(n->valuestring, name)) return true;
        if (!strcmp(t->valuestring, "cylinder") && !strncmp(name, n->valuestring, L) &&
            (!strcmp(name + L, ".A") || !strcmp(name + L, ".B")))
            return true;
    }
    return false;
}

int engine_world_bursts(const model* m, const cJSON* fragment, const char* world_file, char* err, size_t errsz) {
    const cJSON* o;
    cJSON_ArrayForEach(o, m->world_bursts) {
        const cJSON* at = cJSON_GetObjectItemCaseSensitive(o, "inlet");
        const cJSON* nm = cJSON_GetObjectItemCaseSensitive(o, "name");
        if (!cJSON_IsString(at) || !cJSON_IsString(nm)) continue;
        if (fragment && fragment_has_node(fragment, at->valuestring)) continue;
        int i = -1;
        sscanf(nm->valuestring, "fault%d_burst", &i);
        snprintf(err, errsz, "%s: faults[%d].at: no node '%s' in the circuit of %s%s%s (a burst needs a hose or a "
                             "cylinder chamber)",
                 m->world_bursts_src[0] ? m->world_bursts_src : "scenario", i, at->valuestring,
                 m->file[0] ? m->file : "the model", fragment ? " or of " : "", fragment ? world_file : "");
        return -1;
    }
    return 0;
}

// The model with a closed orifice to the tank at each node a burst names
// (so model files stay clean), or NULL with "file: faults[i].at: problem".
// A node the model's circuit lacks may be one a world adds (the sandbox's
// slew_cyl.A): its orifice waits in world_bursts for the ode world to append
// to the world's part of the circuit, and a backend without that part
// refuses it (engine_world_bursts) with the message a missing node had here.
model* engine_fault_model(const model* m, const scenario* sc, char* err, size_t errsz) {
    const hyd_model* hm = m->hyd;
    const char* tank = NULL;
    for (int i = 0; i < hyd_model_nnode(hm) && !tank; ++i)
        if (hyd_model_node_state(hm, i) < 0) tank = hyd_model_node_name(hm, i);
    for (int i = 0; i < sc->nfault; ++i) {
        const scenario_fault* f = &sc->fault[i];
        if (f->kind != SCENARIO_HOSE_BURST) continue;
        const int node = hyd_model_find_node(hm, f->at);
        if (node >= 0 && hyd_model_node_state(hm, node) < 0) {
            snprintf(err, errsz, "%s: faults[%d].at: a burst cannot open at the tank node '%s' in the circuit of %s "
                                 "(a burst needs a hose or a cylinder chamber)",
                     sc->file[0] ? sc->file : "scenario", i, f->at, m->file[0] ? m->file : "the model");
            return NULL;
        }
        if (!tank) {
            snprintf(err, errsz, "%s: faults[%d]: the circuit has no tank for the burst to drain to",
                     sc->file[0] ? sc->file : "scenario", i);
            return NULL;
        }
    }
    cJSON* doc = cJSON_Duplicate(m->json, 1);
    cJSON* comps = doc ? cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "hydraulics"), "components") : NULL;
    if (!cJSON_IsArray(comps)) {
        cJSON_Delete(doc);
        snprintf(err, errsz, "%s: the model document has no hydraulics.components to add the bursts to", m->file);
        return NULL;
    }
    cJSON* world = NULL; // the orifices at nodes the model's circuit lacks
    for (int i = 0; i < sc->nfault; ++i) {
        const scenario_fault* f = &sc->fault[i];
        if (f->kind != SCENARIO_HOSE_BURST) continue;
        char name[32];
        burst_name(name, sizeof name, i);
        const bool in_model = hyd_model_find_node(hm, f->at) >= 0;
        if (!in_model && !world && !(world = cJSON_CreateArray())) {
            cJSON_Delete(doc);
            snprintf(err, errsz, "out of memory");
            return NULL;
        }
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", name);
        cJSON_AddStringToObject(o, "type", "orifice");
        cJSON_AddStringToObject(o, "inlet", f->at);
        cJSON_AddStringToObject(o, "outlet", tank);
        // Loaded open (its area is in the orifice's typical range, so the
        // loader has nothing to note), closed below once compiled.
        cJSON_AddNumberToObject(o, "area", f->area);
        cJSON_AddNumberToObject(o, "cd", f->cd);
        cJSON_AddItemToArray(in_model ? comps : world, o);
    }
    model* fm = model_from_json(doc, m->file, err, errsz);
    if (!fm) {
        cJSON_Delete(world);
        return NULL;
    }
    fm->world_bursts = world;
    snprintf(fm->world_bursts_src, sizeof fm->world_bursts_src, "%s", sc->file[0] ? sc->file : "scenario");
    for (int i = 0; fm && i < sc->nfault; ++i) {
        if (sc->fault[i].kind != SCENARIO_HOSE_BURST || hyd_model_find_node(hm, sc->fault[i].at) < 0) continue;
        char path[64];
        burst_name(path, sizeof path, i);
        strcat(path, ".area");
        if (hyd_model_set(fm->hyd, path, BURST_CLOSED_AREA, err, errsz)) {
            model_free(fm);
            return NULL;
        }
    }
    return fm;
}

void engine_faults_init(engine_faults* f, const hyd_model* hm) {
    f->pump = -1;
    f->qmax0 = 0.0;
    for (int c = 0; c < hyd_model_ncomp(hm) && f->pump < 0; ++c)
        // Both pumps deliver at most q_max (the LS pump eps q_max), so a
        // stop takes q_max away from either.
        if (hyd_model_comp_type(hm, c) == HYD_PUMP || hyd_model_comp_type(hm, c) == HYD_LS_PUMP) f->pump = c;
    if (f->pump >= 0) {
        char path[160];
        snprintf(path, sizeof path, "%s.q_max", hyd_model_comp_name(hm, f->pump));
        hyd_model_get(hm, path, &f->qmax0);
    }
}

// Set path to v if it differs; 1 if it changed.
static int set_if(hyd_model* hm, const char* path, double v) {
    double now;
    if (hyd_model_get(hm, path, &now) || now == v) return 0;
    char err[200];
    return hyd_model_set(hm, path, v, err, sizeof err) == 0;
}

// Every value is set from the scenario and t alone, so the first call also
// closes the bursts of a circuit a backend compiled itself from the model's
// document (the ode world's, where they load open).
int engine_faults_apply(const engine_faults* f, hyd_model* hm, const scenario* sc, double t) {
    // Nothing to do without faults: the ode run calls this every ODE step,
    // and the pump line below is a name lookup.
    if (sc->nfault == 0) return 0;
    int changed = 0;
    double q = f->qmax0; // the lowest any stop allows by t
    for (int i = 0; i < sc->nfault; ++i) {
        const scenario_fault* ft = &sc->fault[i];
        if (ft->kind == SCENARIO_HOSE_BURST) {
            char path[64];
            burst_name(path, sizeof path, i);
            strcat(path, ".area");
            changed |= set_if(hm, path, t >= ft->t ? ft->area : BURST_CLOSED_AREA);
        } else if (ft->kind == SCENARIO_PUMP_STOP && f->pump >= 0 && t >= ft->t) {
            // Linear ramp from the pump's flow down to the floor over ramp [s].
            const double w = ft->ramp > 0 ? (t - ft->t) / ft->ramp : 1.0;
            const double qi = w >= 1.0 ? PUMP_STOPPED_Q : fmax(PUMP_STOPPED_Q, f->qmax0 * (1.0 - w));
            q = fmin(q, qi);
        }
    }
    if (f->pump >= 0 && f->qmax0 > 0) {
        char path[160];
        snprintf(path, sizeof path, "%s.q_max", hyd_model_comp_name(hm, f->pump));
        changed |= set_if(hm, path, q);
    }
    return changed;
}
