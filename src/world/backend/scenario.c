// scenario.c: scenario loading and command interpolation.
#include "scenario.h"

#include "crane_model.h"
#include "json_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// Ranges (docs/files.md, "Value ranges"): a day of simulated time is far
// beyond any study (the longest shipped scenario is 60 s), and the tip load
// shares the model's range.
static const json_range R_DURATION = {1e-3, 86400, 1e-3, 3600, "s"};
static const json_range R_TIME = {0, 86400, 0, 86400, "s"};
static const json_range R_LOAD = {0, CRANE_LOAD_MAX, 0, CRANE_LOAD_TYPICAL, "kg"};
// A burst: from a pinhole (1e-8 m^2, 0.1 mm across) to 5e-5 m^2 (8 mm
// across, 40 % of a 1/2" hose's bore). Larger holes blew up the runs at the
// default step (measured on ramp with a burst at 2, 5, 8 or 12 s, both
// cranes, six sites, lagrange krus/ros2 and ode krus): 1e-2 and 1e-3 at the
// first step after the burst (the line's compressed oil is gone in tens of
// microseconds, within one 0.1 ms step), and from 1e-4 (3 of 16 ode runs)
// up to 2e-4 (8 of 108) about a second later, when the boom falls onto its
// stop with the burst chamber empty (p1A below -0.1 MPa in the ode world).
// 7e-5 and 5e-5 ran through. The adaptive solvers get through 1e-2, but
// one range holds for every solver.
static const json_range R_BURST_AREA = {1e-8, 5e-5, 1e-7, 2e-5, "m^2"};
static const json_range R_BURST_CD = {0.1, 1, 0.5, 0.8, "-"};
// Pump stop: a drive motor winding down takes 0.05-1 s; 0 is a step.
static const json_range R_STOP_RAMP = {0, 10, 0, 2, "s"};

static void load_faults(json_ctx* c, const cJSON* arr, scenario* s) {
    if (!arr || c->failed) return;
    const int n = cJSON_GetArraySize(arr);
    if (n > SCENARIO_MAX_FAULTS) {
        json_fail(c, "faults", "at most %d faults, got %d", SCENARIO_MAX_FAULTS, n);
        return;
    }
    for (int i = 0; i < n && !c->failed; ++i) {
        const cJSON* e = cJSON_GetArrayItem(arr, i);
        char p[64];
        json_path_index(p, sizeof p, "faults", i);
        if (!cJSON_IsObject(e)) {
            json_fail(c, p, "must be an object {\"t\": s, \"kind\": \"hose_burst\" | \"pump_stop\", ...}");
            return;
        }
        scenario_fault* f = &s->fault[i];
        char kind[32];
        json_str(c, e, p, "kind", true, "", kind, sizeof kind);
        if (c->failed) return;
        char pk[96];
        json_path(pk, sizeof pk, p, "kind");
        if (!strcmp(kind, "hose_burst")) {
            f->kind = SCENARIO_HOSE_BURST;
            json_only_keys(c, e, p, (const char* const[]){"t", "kind", "at", "area", "cd", NULL});
            json_str(c, e, p, "at", true, "", f->at, sizeof f->at);
            if (!c->failed && !f->at[0]) {
                char pa[96];
                json_path(pa, sizeof pa, p, "at");
                json_fail(c, pa, "must name a circuit node (a hose, or \"<cylinder>.A\" / \".B\")");
            }
            f->area = json_num_r(c, e, p, "area", true, 0, &R_BURST_AREA);
            f->cd = json_num_r(c, e, p, "cd", false, 0.65, &R_BURST_CD);
        } else if (!strcmp(kind, "pump_stop")) {
            f->kind = SCENARIO_PUMP_STOP;
            json_only_keys(c, e, p, (const char* const[]){"t", "kind", "ramp", NULL});
            f->ramp = json_num_r(c, e, p, "ramp", false, 0.05, &R_STOP_RAMP);
        } else {
            json_fail(c, pk, "must be \"hose_burst\" or \"pump_stop\", got \"%s\"", kind);
            return;
        }
        f->t = json_num_r(c, e, p, "t", true, 0, &R_TIME);
        if (!c->failed && i > 0 && f->t < s->fault[i - 1].t) {
            char pt[96];
            json_path(pt, sizeof pt, p, "t");
            json_fail(c, pt, "fault times must not decrease (%g after %g)", f->t, s->fault[i - 1].t);
        }
        for (int j = 0; j < i && !c->failed; ++j)
            if (f->kind == SCENARIO_HOSE_BURST && s->fault[j].kind == SCENARIO_HOSE_BURST && !strcmp(f->at, s->fault[j].at)) {
                char pa[96];
                json_path(pa, sizeof pa, p, "at");
                json_fail(c, pa, "node '%s' already bursts in faults[%d]", f->at, j);
            }
        if (!c->failed) s->nfault = i + 1;
    }
}

const char* const scenario_cmd_name[SCENARIO_NCMD] = {"lift", "jib", "slew"};

static void load_signal(json_ctx* c, const cJSON* arr, const char* path, scenario_signal* sig) {
    sig->n = 0;
    if (!arr) return;
    int n = cJSON_GetArraySize(arr);
    if (n > SCENARIO_MAX_POINTS) {
        json_fail(c, path, "at most %d points, got %d", SCENARIO_MAX_POINTS, n);
        return;
    }
    for (int i = 0; i < n && !c->failed; ++i) {
        const cJSON* pt = cJSON_GetArrayItem(arr, i);
        char p[160];
        json_path_index(p, sizeof p, path, i);
        if (!cJSON_IsArray(pt) || cJSON_GetArraySize(pt) != 2 ||
            !cJSON_IsNumber(cJSON_GetArrayItem(pt, 0)) || !cJSON_IsNumber(cJSON_GetArrayItem(pt, 1))) {
            json_fail(c, p, "must be a [t, u] pair of numbers");
            return;
        }
        double t = cJSON_GetArrayItem(pt, 0)->valuedouble, u = cJSON_GetArrayItem(pt, 1)->valuedouble;
        // inf (a time of 1e400) is not a time at all; say so rather than
        // "must be >= 0, got inf".
        if (!isfinite(t) || !isfinite(u)) json_fail(c, p, "must be a finite number (a [t, u] pair)");
        else if (t < 0 || t > R_TIME.hi) json_fail(c, p, "time must be in [0, %g] s, got %g", R_TIME.hi, t);
        else if (i > 0 && t < sig->t[i - 1]) json_fail(c, p, "times must not decrease (%g after %g)", t, sig->t[i - 1]);
        else if (!isfinite(u) || u < -1 || u > 1) json_fail(c, p, "command must be in [-1, 1], got %g", u);
        sig->t[i] = t;
        sig->u[i] = u;
        sig->n = i + 1;
    }
}

int scenario_from_json(const cJSON* root, const char* file, scenario* s, char* err, size_t errsz) {
    memset(s, 0, sizeof *s);
    json_ctx c = {.file = file, .err = err, .errsz = errsz};
    if (!cJSON_IsObject(root)) {
        json_fail(&c, "", "a scenario must be a JSON object");
        return -1;
    }
    if (json_wrong_kind(&c, root, "scenario")) return -1;
    static const char* const keys[] = {"name", "description", "model", "duration", "load_mass",
                                       "initial", "commands", "hook", "faults", NULL};
    json_only_keys(&c, root, "", keys);
    json_str(&c, root, "", "name", false, "", s->name, sizeof s->name);
    json_str(&c, root, "", "description", false, "", s->description, sizeof s->description);
    json_str(&c, root, "", "model", false, "", s->model, sizeof s->model);
    s->duration = json_num_r(&c, root, "", "duration", true, 0, &R_DURATION);
    s->load_mass = json_num_r(&c, root, "", "load_mass", false, -1.0, &R_LOAD);

    const cJSON* ini = json_obj(&c, root, "", "initial", true);
    static const char* const ikeys[] = {"q1_deg", "q2_deg", "slew_deg", NULL};
    json_only_keys(&c, ini, "initial", ikeys);
    s->q0[0] = json_num(&c, ini, "initial", "q1_deg", true, 0, 0, 360) * M_PI / 180.0;
    s->q0[1] = json_num(&c, ini, "initial", "q2_deg", true, 0, -360, 360) * M_PI / 180.0;
    s->slew0 = json_num(&c, ini, "initial", "slew_deg", false, 0, -360, 360) * M_PI / 180.0;

    // Optional: a scenario that only holds the start pose (a fault, a
    // settling test) has no command to give; absent, every valve is centred.
    const cJSON* cmds = json_obj(&c, root, "", "commands", false);
    for (int k = 0; k < SCENARIO_NCMD; ++k) {
        char p[64];
        json_path(p, sizeof p, "commands", scenario_cmd_name[k]);
        load_signal(&c, json_arr(&c, cmds, "commands", scenario_cmd_name[k], false), p, &s->cmd[k]);
    }
    s->ncmd = SCENARIO_NCMD;
    // Any other column names a function of the model's chain (checked
    // against the model when a run starts: engine_check_scenario).
    const cJSON* col = cmds ? cmds->child : NULL;
    for (; col && !c.failed; col = col->next) {
        const char* nm = col->string ? col->string : "";
        bool std = false;
        for (int k = 0; k < SCENARIO_NCMD; ++k) std |= !strcmp(nm, scenario_cmd_name[k]);
        if (std) continue;
        char p[160];
        json_path(p, sizeof p, "commands", nm);
        if (!*nm || strlen(nm) >= SCENARIO_CMD_NAME) {
            json_fail(&c, p, "a function name of 1 to %d characters", SCENARIO_CMD_NAME - 1);
            break;
        }
        if (s->ncmd >= SCENARIO_MAX_CMD) {
            json_fail(&c, p, "at most %d command columns besides lift, jib and slew", SCENARIO_MAX_CMD - SCENARIO_NCMD);
            break;
        }
        if (!cJSON_IsArray(col)) {
            json_fail(&c, p, "must be an array of [t, u] pairs");
            break;
        }
        snprintf(s->cmd_name[s->ncmd], SCENARIO_CMD_NAME, "%s", nm);
        load_signal(&c, col, p, &s->cmd[s->ncmd]);
        ++s->ncmd;
    }

    const cJSON* hook = json_arr(&c, root, "", "hook", false);
    if (hook && !c.failed) {
        int n = cJSON_GetArraySize(hook);
        if (n > SCENARIO_MAX_EVENTS) json_fail(&c, "hook", "at most %d events", SCENARIO_MAX_EVENTS);
        for (int i = 0; i < n && !c.failed; ++i) {
            const cJSON* e = cJSON_GetArrayItem(hook, i);
            char p[64];
            json_path_index(p, sizeof p, "hook", i);
            const cJSON* t = cJSON_GetArrayItem(e, 0);
            const cJSON* k = cJSON_GetArrayItem(e, 1);
            if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 2 || !cJSON_IsNumber(t) || !cJSON_IsString(k)) {
                json_fail(&c, p, "must be a [t, \"attach\" | \"release\"] pair");
                break;
            }
            if (strcmp(k->valuestring, "attach") && strcmp(k->valuestring, "release")) {
                json_fail(&c, p, "event must be \"attach\" or \"release\", got \"%s\"", k->valuestring);
                break;
            }
            if (!isfinite(t->valuedouble)) {
                json_fail(&c, p, "time must be a finite number");
                break;
            }
            if (t->valuedouble < 0 || (i > 0 && t->valuedouble < s->event[i - 1].t)) {
                json_fail(&c, p, "event times must be >= 0 and not decrease");
                break;
            }
            s->event[i].t = t->valuedouble;
            s->event[i].kind = strcmp(k->valuestring, "attach") ? SCENARIO_RELEASE : SCENARIO_ATTACH;
            s->nevent = i + 1;
        }
    }
    load_faults(&c, json_arr(&c, root, "", "faults", false), s);
    snprintf(s->file, sizeof s->file, "%s", file ? file : "");
    json_flush_notes(&c);
    return c.failed ? -1 : 0;
}

int scenario_load(const char* path, scenario* s, char* err, size_t errsz) {
    cJSON* root = json_load_file(path, err, errsz);
    if (!root) return -1;
    const char* base = strrchr(path, '/');
    int rc = scenario_from_json(root, base ? base + 1 : path, s, err, errsz);
    cJSON_Delete(root);
    return rc;
}

// The segment search shared by scenario_command and scenario_command_hint:
// the last i with t[i+1] <= t, scanning up from i0. Starting at any i0 with
// t[i0] <= t gives the same i as starting at 0, since the times never
// decrease (the scan from 0 would pass through i0).
static inline double command_from(const scenario_signal* g, double t, int* seg) {
    if (g->n == 0) return 0.0;
    if (t <= g->t[0]) return g->u[0];
    if (t >= g->t[g->n - 1]) return g->u[g->n - 1];
    // Tables are short (< 64 points): a linear scan is cheaper than bisection
    // bookkeeping. The last segment containing t wins, so a step (two points at
    // the same time) takes its new value exactly at the step time.
    int i = *seg;
    if (i < 0 || i + 1 >= g->n || !(g->t[i] <= t)) i = 0;
    while (i + 1 < g->n && g->t[i + 1] <= t) ++i;
    *seg = i;
    if (i + 1 >= g->n) return g->u[g->n - 1];
    double dt = g->t[i + 1] - g->t[i];
    double w = dt > 0 ? (t - g->t[i]) / dt : 1.0;
    return g->u[i] + w * (g->u[i + 1] - g->u[i]);
}

double scenario_command(const scenario* s, int k, double t) {
    int seg = 0;
    return command_from(&s->cmd[k], t, &seg);
}

double scenario_command_seg(const scenario* s, int k, double t, int* seg) {
    return command_from(&s->cmd[k], t, seg);
}

double scenario_command_rate(const scenario* s, int k, double t) {
    const scenario_signal* g = &s->cmd[k];
    if (g->n < 2 || t < g->t[0] || t >= g->t[g->n - 1]) return 0.0;
    // The last segment starting at or before t (a step at t takes its new
    // slope). Loaded tables hold commands in [-1, 1] only (checked above), so
    // no clamp can flatten the slope.
    int i = 0;
    while (i + 1 < g->n && g->t[i + 1] <= t) ++i;
    if (i + 1 >= g->n) return 0.0;
    double dt = g->t[i + 1] - g->t[i];
    return dt > 0 ? (g->u[i + 1] - g->u[i]) / dt : 0.0;
}

static int cmp_double(const void* a, const void* b) {
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

int scenario_ncmd(const scenario* s) { return s->ncmd > SCENARIO_NCMD ? s->ncmd : SCENARIO_NCMD; }

int scenario_find_command(const scenario* s, const char* name) {
    for (int k = 0; k < SCENARIO_NCMD; ++k)
        if (!strcmp(name, scenario_cmd_name[k])) return k;
    for (int k = SCENARIO_NCMD; k < s->ncmd && k < SCENARIO_MAX_CMD; ++k)
        if (!strcmp(name, s->cmd_name[k])) return k;
    return -1;
}

bool scenario_commands(const scenario* s, const char* name) {
    const int k = scenario_find_command(s, name);
    if (k < 0) return false;
    for (int i = 0; i < s->cmd[k].n; ++i)
        if (s->cmd[k].u[i] != 0.0) return true;
    return false;
}

int scenario_breakpoints(const scenario* s, double* t, int cap) {
    int n = 0;
    for (int k = 0; k < scenario_ncmd(s); ++k)
        for (int i = 0; i < s->cmd[k].n && n < cap; ++i) t[n++] = s->cmd[k].t[i];
    for (int i = 0; i < s->nevent && n < cap; ++i) t[n++] = s->event[i].t;
    // Faults change the circuit: a run reapplies them at each breakpoint
    // (engine_faults_apply), so a pump stop's ramp gets 8 of them.
    for (int i = 0; i < s->nfault && n < cap; ++i) {
        t[n++] = s->fault[i].t;
        if (s->fault[i].kind == SCENARIO_PUMP_STOP && s->fault[i].ramp > 0)
            for (int j = 1; j <= 8 && n < cap; ++j) t[n++] = s->fault[i].t + s->fault[i].ramp * j / 8.0;
    }
    qsort(t, (size_t)n, sizeof *t, cmp_double);
    int m = 0;
    for (int i = 0; i < n; ++i)
        if (m == 0 || t[i] > t[m - 1]) t[m++] = t[i];
    return m;
}

void scenario_play(const scenario* s, double tm, int* ev, double u[SCENARIO_NCMD], scenario_hook_fn hook,
                   void* user) {
    for (int k = 0; k < SCENARIO_NCMD; ++k) u[k] = scenario_command(s, k, tm);
    for (; *ev < s->nevent && s->event[*ev].t <= tm; ++*ev)
        if (hook) hook(user, s->event[*ev].kind == SCENARIO_ATTACH);
}
