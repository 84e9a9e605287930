// drive_session.c: the real-time loop of `cranesim drive` (see drive_session.h).
#include "drive_session.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <SDL2/SDL.h>

#include "channels.h"
#include "input.h"
#include "model_controls.h"
#include "json_util.h"
#include "panel.h"
#include "protocol.h"
#include "render.h"
#include "session.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// How a panel parameter reaches the simulation.
typedef enum param_kind {
    PK_HYD,  ///< a circuit parameter: hyd_model_set on the live circuit, at once
    PK_MECH, ///< a mechanical parameter: live where the engine can set it, else a rebuilt world
    PK_LOAD, ///< the tip load, where the engine can set it live [kg]
    PK_SOLVER, ///< hydraulic integrator, an index into k_solver (a rebuilt world/solver at the current pose)
    PK_STEP,   ///< hydraulic step [s] (rebuilt likewise)
    PK_CHAIN,  ///< a crane chain's body or actuator field (chain_field): the model rebuilt from its document
    PK_CHART,  ///< a strip-chart slot (mech: 0..DRIVE_CHART_SLOTS-1): an index into the session's chart_opt
} param_kind;

/// The panel's strip-chart slots, as many as --charts takes.
#define DRIVE_CHART_SLOTS 8

// The fields of a crane chain the panel shows (a chain model's mechanics;
// the two-link crane's are the mechanics table's, PK_MECH).
typedef enum chain_field {
    CF_MASS,   ///< a body's mass [kg]
    CF_LENGTH, ///< a body's length (the column's height) [m]: shown, not edited (it places the children)
    CF_WIDTH,  ///< a boom's section across the boom plane [m]
    CF_HEIGHT, ///< a boom's section in the boom plane [m]
    CF_CLOSED, ///< an actuator's closed (pin-to-pin) length [m]
} chain_field;

// One panel entry, generated from the parameter tables (build_params).
typedef struct drive_param {
    param_kind kind;
    char group[112], label[48], unit[16]; // group: a crane chain's "function: element (type)"
    double value;      ///< shown value, display units (edited by the panel)
    double scale;      ///< SI value = value * scale
    double min, max;   ///< hard range, display units: a typed value outside it is refused
    double tmin, tmax; ///< typical range, display units: what a drag covers
    char hyd_path[96]; ///< PK_HYD: "lift_cyl.bore", "fluid.bulk_modulus"
    char json[160];    ///< path in the model file, for saving
    int mech;          ///< PK_MECH, PK_LOAD: entry of the mechanics table (model_param_info); PK_CHAIN:
                       ///< the body's or actuator's index
    int field;         ///< PK_CHAIN: its chain_field
    bool on_release;   ///< applied when the edit ends: it rebuilds the world
    bool world_only;   ///< PK_HYD of the world's circuit, not the model's (not saved)
    /// PK_HYD whose 0 means "the fluid's value" (a volume's bulk_modulus) and
    /// is 0: the panel shows the fluid's value it runs with, noted "fluid's",
    /// until it is set (it showed "0 MPa", and a drag from 0 went nowhere).
    char inherit[96];  ///< the fluid's path it follows ("fluid.bulk_modulus"), or ""
} drive_param;

// The solver choice of the panel: the in-house integrators drive can step.
static const hyd_method k_solver[] = {HYD_KRUS, HYD_ROS2, HYD_RK4, HYD_ROS34PW2, HYD_RODAS3};
static const char* const k_solver_name[] = {"Krus", "ROS2", "RK4", "ROS34PW2", "RODAS3"};
#define NSOLVER ((int)(sizeof k_solver / sizeof k_solver[0]))

struct drive_session {
    app_common c;
    drive_opts o;
    model* m;
    scenario sc;
    engine* l;
    render* r;
    input* in;
    panel* pn;
    world_snapshot* snap; // large: heap
    int pad_lifted;       // the supports lifted at the last snapshot (render_pad_event)
    drive_param* param;  // the panel's entries (build_params)
    int nparam, capparam;
    int* pid;            // their panel ids
    struct {
        int i;
        double v;
    } * changed;         // (capparam) the entries a tick changes, and their new values
    bool paused, rebuild;
    bool load_pending;     // "load model" was pressed: load s->load_path at the next tick
    char load_path[256];   // the panel's model file box
    char rebuild_why[160]; // the change that asked for the rebuild
    sim_opts sim_live;     // the options the running world was built with
    crane_mech mech_live;  // the mechanics the running world has (built with, or set in place since)
    double wall_last, wall_next_frame;
    double wall_last_frame; ///< wall time the last timed frame started [s] (< 0: none yet)
    double sim_offset;   // simulated time = wall - sim_offset while running
    // The world is rebuilt by a reset, a solver change or a parameter that
    // cannot change in place; each build is a "piece" with its own clock
    // (engine_time from 0). The session's time is t_base + engine_time: a reset
    // starts it again at 0, a rebuild continues it.
    double t_base;       // session time at which the current piece started [s]
    double sim_done;     // simulated time of the earlier pieces [s]
    double piece_wall0;  // wall time the current piece started [s]
    double piece_paused; // wall time paused during the current piece [s]
    int segment;         // pieces so far - 1: the record's `segment` column
    FILE* rec;
    char rec_path[256];
    long rec_rows;       // rows written to the open recording
    double rec_t_last;   // time of the last row written [s] (with rec_seg_last)
    int rec_seg_last;
    int rec_seg0;        // s->segment when it started: its rows count segments from 0
    char rec_err[320];   // first recording failure ("cannot write FILE: ..."), "" if none
    int ncol;
    double* row;         // (rowcap) one row of the engine's ncol columns and a segment column
    int rowcap;
    double* ufn;         // (engine_nfunction) a crane chain's commands by function (scripted)
    int ev;              // next scripted hook event
    chan_list* chans;    // the engine's channels: its row, then its circuit's (channels.h)
    double* chan_v;      // (chan_list_count) their values at the last charted frame
    bool chart_circuit;  // a chart shows a circuit channel: evaluate them per frame
    int nreadout;        // HUD readouts (--readouts)
    int readout_col[8];  // their channels (index into chans)
    double readout_scale[8]; // shown = value / scale
    char readout_unit[8][16];
    char readout_name[8][96];
    char** chart_opt;    // (nchart_opt) the panel's chart choices: "(default)", then every channel's name
    int nchart_opt;
    char chart_pick[DRIVE_CHART_SLOTS][96]; // the channel each chart slot shows ("" none)
    int nchart;          // user-chosen strip-chart channels (0: the default set)
    int chart_col[8];    // their channels (index into chans)
    int chart_id[8];     // their render chart ids
    long chart_n[8];     // samples each has received (chart_push)
    double chart_last[8]; // and the last one, SI
    int missed_window;   // missed ticks in the current second
    double missed_t0;
    drive_stats st;
    session_writer sw;   // --session: the operator's input stream, until the first reset or rebuild
    char sess_end[160];  // why it ended ("" while it runs)
    int sess_err;        // errno of a failed session write (0: none)
    session* rp;         // --replay: the session whose commands drive instead of the devices
    long rp_next;        // its next tick
    int* rp_map;         // the session's command of each of the engine's functions (session_function_map)
    double* rp_u;        // one tick's commands by the engine's functions
    char err[400];
    char status[512];
    char rec_stop[400];  // why the last rebuild ended the recording ("" if it did not)
    // Remote mode (drive --connect): the snapshot and row come from the server.
    double mapbox_off;   // wall time [s] the mapping box hides by itself (DRIVE_MAPPING_S), < 0: M decides
    bool remote;
    bool remote_fed;              // a state has arrived
    double remote_row[PROTO_MAX_ROW]; // its row (the server's channels, checked equal to the engine's)
    int remote_nrow;
    bool remote_mapped;           // the mapping is the server's functions' (drive_session_remote_functions)
    drive_remote_input rin;       // the operator's input of the last tick
    struct { char path[128]; double v; } rset[16]; // panel edits for the server (SET), oldest first
    int nrset;
    // Panel changes of the model not saved ("save model") since the start or
    // the last load: how many entries, and their names for the messages.
    int unsaved;
    char unsaved_names[240];
    double esc_armed; // wall time Esc asked to confirm a quit with unsaved changes [s] (< 0: not asked)
};

drive_opts drive_default_opts(void) {
    drive_opts o;
    memset(&o, 0, sizeof o);
    o.width = 1280;
    o.height = 720;
    o.fps_cap = 65.0;
    o.hud = true;
    o.replay_rcl = -1;
    return o;
}

// Display units: what an operator reads (MPa, L/min, mm) for the SI unit a
// table gives, one scale per unit (SI value = shown value * scale).
static const struct {
    const char *si, *shown;
    double scale;
} k_units[] = {
    {"Pa", "MPa", 1e6},         {"m^3/s", "L/min", 1.0 / 60000.0}, {"m", "mm", 1e-3},
    {"m^3", "L", 1e-3},         {"m^2", "mm^2", 1e-6},              {"s", "ms", 1e-3},
    {"N s/m", "kN s/m", 1e3},   {"N/m", "kN/m", 1e3},
};

static double display_unit(const char* si, char* shown, size_t n) {
    for (size_t k = 0; k < sizeof k_units / sizeof k_units[0]; ++k)
        if (!strcmp(si, k_units[k].si)) {
            snprintf(shown, n, "%s", k_units[k].shown);
            return k_units[k].scale;
        }
    snprintf(shown, n, "%s", strcmp(si, "-") ? si : "");
    return 1.0;
}

static drive_param* new_param(drive_session* s) {
    if (s->nparam == s->capparam) {
        const int nc = s->capparam ? 2 * s->capparam : 64;
        drive_param* np = realloc(s->param, (size_t)nc * sizeof *np);
        int* ni = realloc(s->pid, (size_t)nc * sizeof *ni);
        if (ni) s->pid = ni;
        void* nch = realloc(s->changed, (size_t)nc * sizeof *s->changed);
        if (nch) s->changed = nch;
        if (!np || !ni || !nch) {
            if (np) s->param = np;
            return NULL;
        }
        s->param = np;
        s->capparam = nc;
    }
    drive_param* p = &s->param[s->nparam++];
    memset(p, 0, sizeof *p);
    p->mech = -1;
    return p;
}

// An entry with SI unit si, hard range [lo, hi] and typical range [tlo,
// thi] in that unit, at SI value v.
static drive_param* add_param(drive_session* s, param_kind k, const char* group, const char* label, const char* si,
                              double lo, double hi, double tlo, double thi, double v) {
    drive_param* p = new_param(s);
    if (!p) return NULL;
    p->kind = k;
    snprintf(p->group, sizeof p->group, "%s", group);
    snprintf(p->label, sizeof p->label, "%s", label);
    p->scale = display_unit(si, p->unit, sizeof p->unit);
    p->min = lo / p->scale;
    p->max = hi / p->scale;
    p->tmin = tlo / p->scale;
    p->tmax = thi / p->scale;
    p->value = v / p->scale;
    // A value outside the hard range (a world file's, or one loaded with a
    // note) must still be shown: the range stretches to it.
    if (p->value < p->min) p->min = p->value;
    if (p->value > p->max) p->max = p->value;
    return p;
}

// Every parameter of one circuit element (its type's table), read from the
// running circuit. An element of the model's circuit is saved under its path
// in the model file; one of the world's own circuit (the sandbox's slew
// valve) lives in the world file: set on the running circuit only (and again
// after a rebuild), not saved.
// fn: the crane chain's function the element belongs to (its valve, an
// actuator's cylinder), which heads its group, or NULL.
static void add_element(drive_session* s, const hyd_model* live, const char* name, hyd_type t, const char* fn) {
    char group[112];
    if (fn) snprintf(group, sizeof group, "%s: %s (%s)", fn, name, hyd_type_name(t));
    else snprintf(group, sizeof group, "%s (%s)", name, hyd_type_name(t));
    const int is_node = t == HYD_TANK || t == HYD_VOLUME;
    for (int k = 0; k < hyd_param_count(t); ++k) {
        double lo, hi, tlo, thi, v;
        char hp[96];
        snprintf(hp, sizeof hp, "%s.%s", name, hyd_param_name(t, k));
        if (hyd_param_range(t, k, &lo, &hi, &tlo, &thi) || hyd_model_get(live, hp, &v)) continue;
        drive_param* p = add_param(s, PK_HYD, group, hyd_param_name(t, k), hyd_param_unit(t, k), lo, hi, tlo, thi, v);
        if (!p) return;
        snprintf(p->hyd_path, sizeof p->hyd_path, "%s", hp);
        // 0 below a hard range that starts above 0 is the "0 = the fluid's
        // value" of the component table (nothing else passes the loader).
        char fp[96];
        double fv;
        snprintf(fp, sizeof fp, "fluid.%s", hyd_param_name(t, k));
        if (v == 0 && lo > 0 && hyd_model_get(live, fp, &fv) == 0) {
            snprintf(p->inherit, sizeof p->inherit, "%s", fp);
            p->value = fv / p->scale;
        }
        double mv;
        if (hyd_model_get(s->m->hyd, hp, &mv) == 0)
            snprintf(p->json, sizeof p->json, "hydraulics.%s.%s", is_node ? "nodes" : "components", hp);
        else
            p->world_only = true;
    }
}

// Set the world-only circuit parameters on a new world's circuit, which
// starts from the world file's values.
static void reapply_world_params(drive_session* s) {
    char e[256];
    for (int i = 0; i < s->nparam; ++i) {
        const drive_param* p = &s->param[i];
        if (p->world_only) hyd_model_set(engine_circuit(s->l), p->hyd_path, p->value * p->scale, e, sizeof e);
    }
}

// The group header of a mechanics table entry: the link's or actuator's name.
static void mech_group(const crane_mech* me, const model_param* mp, char* out, size_t n) {
    int k = 0;
    if (sscanf(mp->group, "links[%d]", &k) == 1 && k >= 0 && k < 2)
        snprintf(out, n, "%s (link)", me->link[k].name);
    else if (sscanf(mp->group, "actuators[%d]", &k) == 1 && k >= 0 && k < 2)
        snprintf(out, n, "%s (actuator)", me->act[k].name);
    else
        snprintf(out, n, "%s", mp->group);
}

// The value of a crane chain's field (PK_CHAIN) in model m [SI].
static double chain_value(const model* m, int i, chain_field f) {
    const crane_chain* c = &m->chain;
    if (f == CF_CLOSED) return i >= 0 && i < c->nact ? c->act[i].closed_length : NAN;
    if (i < 0 || i >= c->nbody) return NAN;
    const crane_body* b = &c->body[i];
    return f == CF_MASS ? b->def.mass : f == CF_LENGTH ? b->length : f == CF_WIDTH ? b->width : b->height;
}

// like: the two-link mechanics table's entry whose range a chain field
// shares (the loader checks a chain's bodies against the same ranges):
// "mechanics.links[0].mass", "mechanics.column.height", ...
static void add_chain_param(drive_session* s, const char* group, const char* label, const char* like, int i,
                            chain_field f, const char* json) {
    model_param r = {.unit = "-", .lo = 0, .hi = INFINITY, .tlo = 0, .thi = 1};
    for (int k = 0; k < model_param_count(); ++k) {
        model_param mp;
        if (!model_param_info(k, &mp) && !strcmp(mp.path, like)) r = mp;
    }
    drive_param* p = add_param(s, PK_CHAIN, group, label, r.unit, r.lo, r.hi, r.tlo, r.thi,
                               chain_value(s->m, i, f));
    if (!p) return;
    p->mech = i;
    p->field = (int)f;
    // Every edit rebuilds the world (the chain engine has no edits in
    // place): once, when the drag or the typing ends.
    p->on_release = true;
    snprintf(p->json, sizeof p->json, "%s", json);
}

// A crane chain's entries, grouped by function and body: each function's
// valve, then per actuator of it its cylinder (bore, rod, stroke) and its
// closed length; the rest of the circuit as the two-link crane's; the
// bodies' masses and sizes after the fluid (chain_bodies). done[i]: circuit
// element i is listed.
static void chain_functions(drive_session* s, const hyd_model* live, bool* done) {
    const crane_chain* c = &s->m->chain;
    const int ne = hyd_model_nelement(live);
    for (int f = 0; f < c->nfn; ++f) {
        const char* fn = c->fn[f].name;
        for (int i = 0; i < ne; ++i) {
            hyd_type t;
            const char* name = hyd_model_element(live, i, &t);
            if (done[i] || strcmp(name, c->fn[f].valve)) continue;
            add_element(s, live, name, t, fn);
            done[i] = true;
        }
        for (int k = 0; k < c->nact; ++k) {
            const crane_act* a = &c->act[k];
            if (a->function != f) continue;
            for (int i = 0; i < ne; ++i) {
                hyd_type t;
                const char* name = hyd_model_element(live, i, &t);
                if (done[i] || strcmp(name, a->cylinder)) continue;
                add_element(s, live, name, t, fn);
                done[i] = true;
            }
            char group[112], json[96];
            snprintf(group, sizeof group, "%s: %s (actuator)", fn, a->name);
            snprintf(json, sizeof json, "mechanics.actuators[%d].closed_length", k);
            add_chain_param(s, group, "closed length", "mechanics.actuators[0].closed_length", k, CF_CLOSED, json);
        }
    }
}

static void chain_bodies(drive_session* s) {
    const crane_chain* c = &s->m->chain;
    for (int i = 0; i < c->nbody; ++i) {
        const crane_body* b = &c->body[i];
        char group[112], json[96];
        snprintf(group, sizeof group, "%s (%s)", b->def.name,
                 i == 0 ? "column" : b->def.joint == CHAIN_PRISMATIC ? "extension" : "boom");
        snprintf(json, sizeof json, "mechanics.bodies[%d].mass", i);
        add_chain_param(s, group, "mass", i ? "mechanics.links[0].mass" : "mechanics.column.mass", i, CF_MASS, json);
        snprintf(json, sizeof json, "mechanics.bodies[%d].%s", i, i ? "length" : "height");
        add_chain_param(s, group, i ? "length" : "height",
                        i ? "mechanics.links[0].length" : "mechanics.column.height", i, CF_LENGTH, json);
        if (i == 0) continue; // the column's section is its radius, drawn and collided as the slew's
        snprintf(json, sizeof json, "mechanics.bodies[%d].width", i);
        add_chain_param(s, group, "width", "mechanics.links[0].width", i, CF_WIDTH, json);
        snprintf(json, sizeof json, "mechanics.bodies[%d].height", i);
        add_chain_param(s, group, "height", "mechanics.links[0].height", i, CF_HEIGHT, json);
    }
}

// The panel's list, generated from the tables: every element of the running
// circuit with its type's parameters, the fluid, the mechanics table (a
// crane chain: its functions and bodies) and the run's own settings
// (solver). No component name is known here.
static void build_params(drive_session* s) {
    s->nparam = 0;
    const hyd_model* live = engine_circuit(s->l);
    const bool chain = !s->m->chain.two_link;
    bool* done = calloc((size_t)hyd_model_nelement(live) + 1, sizeof *done);
    if (!done) return;
    if (chain) chain_functions(s, live, done);
    for (int i = 0; i < hyd_model_nelement(live); ++i) {
        hyd_type t;
        const char* name = hyd_model_element(live, i, &t);
        if (!done[i]) add_element(s, live, name, t, NULL);
    }
    free(done);
    for (int k = 0; k < hyd_fluid_param_count(); ++k) {
        double lo, hi, tlo, thi, v;
        char hp[96];
        snprintf(hp, sizeof hp, "fluid.%s", hyd_fluid_param_name(k));
        if (hyd_fluid_param_range(k, &lo, &hi, &tlo, &thi) || hyd_model_get(live, hp, &v)) continue;
        drive_param* p = add_param(s, PK_HYD, "fluid", hyd_fluid_param_name(k), hyd_fluid_param_unit(k), lo, hi, tlo,
                                   thi, v);
        if (!p) return;
        snprintf(p->hyd_path, sizeof p->hyd_path, "%s", hp);
        snprintf(p->json, sizeof p->json, "hydraulics.%s", hp);
    }
    crane_mech* me = &s->m->mech;
    if (chain) chain_bodies(s);
    // A crane chain's mechanics are its bodies' (the table's links and
    // actuators are the two-link crane's).
    for (int k = 0; k < model_param_count() && !chain; ++k) {
        model_param mp;
        model_param_info(k, &mp);
        if (!model_param_present(me, k)) continue; // an optional field the model lacks (its rating)
        char group[64];
        mech_group(me, &mp, group, sizeof group);
        const bool load = !strcmp(mp.path, "mechanics.load_mass");
        // The tip load drives with the scenario's or --load's value where the
        // engine takes it live; elsewhere it is the model's field.
        const double v = load && engine_can_set_load(s->l) ? sim_load_mass(s->m, &s->sc, &s->c.sim)
                                                           : *model_param_ptr(me, k);
        drive_param* p = add_param(s, load && engine_can_set_load(s->l) ? PK_LOAD : PK_MECH, group, mp.name, mp.unit,
                                   mp.lo, mp.hi, mp.tlo, mp.thi, v);
        if (!p) return;
        p->mech = k;
        snprintf(p->json, sizeof p->json, "%s", mp.path);
    }
    int method = 0;
    for (int k = 0; k < NSOLVER; ++k)
        if (k_solver[k] == s->c.sim.solver) method = k;
    drive_param* p = add_param(s, PK_SOLVER, "solver", "method", "-", 0, NSOLVER - 1, 0, NSOLVER - 1, method);
    if (p) p->scale = 1, p->unit[0] = 0;
    add_param(s, PK_STEP, "solver", "step", "s", 0.05e-3, 1e-3, 0.05e-3, 1e-3, s->c.sim.h);
    // The strip charts: a slot per chart, each a choice among the engine's
    // channels by name (a crane chain's every actuator and function too),
    // "(default)" for none; all "(default)": the default set.
    for (int k = 0; k < DRIVE_CHART_SLOTS && s->nchart_opt > 0; ++k) {
        int pick = 0;
        for (int j = 1; j < s->nchart_opt && s->chart_pick[k][0] && !pick; ++j)
            if (!strcmp(s->chart_opt[j], s->chart_pick[k])) pick = j;
        char label[16];
        snprintf(label, sizeof label, "chart %d", k + 1);
        drive_param* q = add_param(s, PK_CHART, "charts", label, "-", 0, s->nchart_opt - 1, 0, s->nchart_opt - 1, pick);
        if (!q) return;
        q->scale = 1, q->unit[0] = 0, q->mech = k;
    }
    // What cannot change in place rebuilds the world (loads back at their
    // start): applied once when the drag or the typing ends, not at every
    // pixel. A link's mass, inertia and centre of mass go to engine_set_link
    // (in place where the engine can); a length only where the engine can
    // resize a boom (not the ode world's bodies). A tip load merged into the
    // end arm (the ode validation world's: no load parameter, no load bodies)
    // moves the end arm's centre of mass with its mass: a rebuild too. Every
    // other mechanical value (gravity, column, mounts, sections) rebuilds.
    const bool resize = engine_can_resize_links(s->l);
    const bool tip_load = !engine_can_set_load(s->l) && !engine_load_name(s->l, 0, NULL) &&
                          sim_load_mass(s->m, &s->sc, &s->c.sim) > 0;
    for (int i = 0; i < s->nparam; ++i) {
        drive_param* q = &s->param[i];
        if (q->kind == PK_STEP || q->kind == PK_SOLVER) q->on_release = true;
        if (q->kind != PK_MECH) continue;
        const bool link = !strncmp(q->json, "mechanics.links[", 16);
        const bool live_field = link && (strstr(q->json, ".mass") || strstr(q->json, ".inertia") ||
                                         strstr(q->json, ".com") || (resize && strstr(q->json, ".length")));
        q->on_release = !live_field || (tip_load && strstr(q->json, "links[1].mass"));
    }
}

// Keep the model document in step with a changed parameter, so "save model"
// writes what is being driven.
static void sync_json(drive_session* s, const drive_param* p) {
    if (!p->json[0] || p->kind == PK_SOLVER || p->kind == PK_STEP) return;
    char a[240], e[200];
    // An entry that follows the fluid is 0 in the file (the fluid's value is shown).
    snprintf(a, sizeof a, "%s=%.10g", p->json, p->inherit[0] ? 0.0 : p->value * p->scale);
    json_set_path(s->m->json, a, e, sizeof e);
}

// The model document's mechanics as the model has them (after an edit that
// scaled other fields, or a revert).
static void sync_mech_json(drive_session* s) {
    if (!s->m->chain.two_link) return; // a chain's fields are edited in its document (apply_chain)
    for (int k = 0; k < model_param_count(); ++k) {
        model_param mp;
        model_param_info(k, &mp);
        if (!model_param_present(&s->m->mech, k)) continue; // not in the file; --set adds no field
        char a[240], e[200];
        snprintf(a, sizeof a, "%s=%.10g", mp.path, *model_param_ptr(&s->m->mech, k));
        json_set_path(s->m->json, a, e, sizeof e);
    }
}

// Panel values of the mechanics from the model (after an edit moved other
// fields with it, or a revert).
static void refresh_mech_params(drive_session* s) {
    if (!s->m->chain.two_link) return; // no PK_MECH entries
    for (int i = 0; i < s->nparam; ++i) {
        drive_param* p = &s->param[i];
        if (p->kind == PK_MECH) p->value = *model_param_ptr(&s->m->mech, p->mech) / p->scale;
    }
}

static engine* make_engine(drive_session* s, const double q0[2], double slew0) {
    char err[400];
    const double m3 = s->rp ? s->rp->m3 : sim_load_mass(s->m, &s->sc, &s->c.sim);
    // The window draws the engine's snapshot, with a HUD, charts and panel
    // sized by it: an engine with a picture (the two-link crane, a crane
    // chain in the sandbox). Without one (a chain in the validation world or
    // the lagrange view) it is refused here, before the window opens (drive
    // --headless runs it). Session files carry one command per function
    // (session.h, format 2), so recording and replaying need no more.
    const unsigned need = ENGINE_CAP_SNAPSHOT;
    if (engine_require(s->m, &s->c.sim, need, "the window (--headless runs a crane chain)", s->err, sizeof s->err))
        return NULL;
    engine* l = engine_create(s->m, &s->c.sim, q0, slew0, m3, err, sizeof err);
    if (!l) snprintf(s->err, sizeof s->err, "%s", err);
    return l;
}

// The row buffers for the running engine: its ncol columns (a crane
// chain's are more than SIM_NCOL) and the record's segment column, and its
// commands by function. -1: out of memory (the old buffers stay).
static int size_buffers(drive_session* s) {
    const int ncol = engine_ncol(s->l), need = (ncol > SIM_NCOL ? ncol : SIM_NCOL) + 1;
    const int nfn = engine_nfunction(s->l) > 0 ? engine_nfunction(s->l) : 1;
    if (need > s->rowcap) {
        double* r = realloc(s->row, (size_t)need * sizeof *r);
        if (!r) return -1;
        s->row = r;
        s->rowcap = need;
    }
    double* u = realloc(s->ufn, (size_t)nfn * sizeof *u);
    if (!u) return -1;
    s->ufn = u;
    for (int k = 0; k < nfn; ++k) s->ufn[k] = 0;
    s->ncol = ncol;
    return 0;
}

static void say(drive_session* s, const char* text) {
    snprintf(s->status, sizeof s->status, "%s", text);
    if (s->pn) panel_set_message(s->pn, s->status);
}

int drive_session_queue_set(drive_session* s, const char* path, double v) {
    if (s->nrset == 16 || strlen(path) >= sizeof s->rset[0].path) return -1;
    snprintf(s->rset[s->nrset].path, sizeof s->rset[0].path, "%s", path);
    s->rset[s->nrset++].v = v;
    return 0;
}

int drive_session_take_set(drive_session* s, char* path, size_t np, double* v) {
    if (!s->nrset) return 0;
    snprintf(path, np, "%s", s->rset[0].path);
    *v = s->rset[0].v;
    memmove(s->rset, s->rset + 1, (size_t)--s->nrset * sizeof s->rset[0]);
    return 1;
}

void drive_session_set_answer(drive_session* s, const char* text) { say(s, text); }

// Remote mode: a panel edit goes to the server as SET (the protocol takes
// circuit parameters by their model path and, where the backend carries it
// as a parameter, the load); the server's answer comes back through
// drive_session_set_answer. Anything else would only edit the idle local
// engine: it is put back and the panel says why.
static void remote_param(drive_session* s, drive_param* p) {
    const double si = p->value * p->scale;
    char t[300];
    if ((p->kind == PK_HYD && !p->world_only) || p->kind == PK_LOAD) {
        const char* path = p->kind == PK_LOAD ? "mechanics.load_mass" : p->hyd_path;
        // The panel shows the asked value until the server answers.
        if (drive_session_queue_set(s, path, si))
            snprintf(t, sizeof t, "not sent: %s (16 changes already waiting for the link)", path);
        else
            snprintf(t, sizeof t, "sent to the server: %s = %.6g", path, si);
        say(s, t);
        return;
    }
    if (p->kind == PK_MECH) p->value = *model_param_ptr(&s->m->mech, p->mech) / p->scale;
    if (p->kind == PK_CHAIN) p->value = chain_value(s->m, p->mech, (chain_field)p->field) / p->scale;
    if (p->kind == PK_STEP) p->value = s->c.sim.h / p->scale;
    if (p->kind == PK_SOLVER)
        for (int k = 0; k < NSOLVER; ++k)
            if (k_solver[k] == s->c.sim.solver) p->value = k;
    snprintf(t, sizeof t, "not sent: %s/%s is set where the server starts (the link takes circuit parameters%s)",
             p->group, p->label, engine_can_set_load(s->l) ? " and the load" : "");
    say(s, t);
}

// An applied panel change of the model document (not the solver or its
// step, which a saved model does not hold): one more unsaved entry.
static void note_unsaved(drive_session* s, const drive_param* p) {
    if (!p->json[0] || p->kind == PK_SOLVER || p->kind == PK_STEP) return;
    char name[160];
    snprintf(name, sizeof name, "%s/%s", p->group, p->label);
    // Each entry once, however many steps its drag took.
    for (const char* q = s->unsaved_names; (q = strstr(q, name)) != NULL; q += strlen(name)) {
        const char end = q[strlen(name)];
        if ((q == s->unsaved_names || q[-1] == ' ') && (end == ',' || end == '\0')) return;
    }
    const size_t n = strlen(s->unsaved_names);
    if (n + strlen(name) + 3 < sizeof s->unsaved_names)
        snprintf(s->unsaved_names + n, sizeof s->unsaved_names - n, "%s%s", n ? ", " : "", name);
    ++s->unsaved;
}

static void saved(drive_session* s) {
    s->unsaved = 0;
    s->unsaved_names[0] = '\0';
}

// After a circuit entry was set to si: an entry that followed the fluid has
// its own value now (or follows it again when set to 0); a fluid value moves
// the entries that follow it.
static void follow_fluid(drive_session* s, drive_param* p, double si) {
    char fp[96];
    snprintf(fp, sizeof fp, "fluid.%s", p->label);
    for (int i = 0; i < s->nparam; ++i) {
        drive_param* q = &s->param[i];
        if (q->kind != PK_HYD) continue;
        if (q == p && si != 0 && q->inherit[0]) {
            q->inherit[0] = '\0';
            panel_set_note(s->pn, s->pid[i], "");
        } else if (q == p && si == 0) {
            double fv;
            if (hyd_model_get(engine_circuit(s->l), fp, &fv) == 0 && strcmp(fp, p->hyd_path)) {
                snprintf(q->inherit, sizeof q->inherit, "%s", fp);
                q->value = fv / q->scale;
                panel_set_note(s->pn, s->pid[i], "fluid's");
            }
        } else if (q != p && q->inherit[0] && !strcmp(q->inherit, p->hyd_path)) {
            q->value = si / q->scale;
        }
    }
}

static void rebuild_world(drive_session* s, bool at_start);
static void rebind_charts(drive_session* s);
static void take_snapshot(drive_session* s);
static void apply_chart_picks(drive_session* s);

// A crane chain's body or actuator field set to si [SI]: the model is built
// again from its document with the new value (so the chain, its columns and
// its circuit stay one model), and the world rebuilt with it at the current
// pose (the first two boom angles and the slew; every other joint back at
// the middle of its limits, as a run starts: engine_create). A body's mass
// carries its inertia with it (the same distribution). A length is refused:
// it places the children's joints and the pins on the body, which the file
// gives separately. -1 with the reason in the status line, the old value
// shown again, and the running world untouched.
static int apply_chain(drive_session* s, drive_param* p, double si) {
    const chain_field f = (chain_field)p->field;
    const double old = chain_value(s->m, p->mech, f);
    if (f == CF_LENGTH) {
        p->value = old / p->scale;
        char t[512];
        snprintf(t, sizeof t, "refused: %s/%s: it places the joints of the bodies on it and the actuators' pins, "
                 "which the model file gives: edit %s there and load it", p->group, p->label, p->json);
        say(s, t);
        return -1;
    }
    char a[240], e[320];
    cJSON* doc = cJSON_Duplicate(s->m->json, 1);
    int rc = doc ? 0 : -1;
    snprintf(e, sizeof e, "out of memory");
    if (!rc) {
        snprintf(a, sizeof a, "%s=%.10g", p->json, si);
        rc = json_set_path(doc, a, e, sizeof e);
    }
    if (!rc && f == CF_MASS && old > 0) {
        // The file's moment of inertia (a boom's Iyy) scales with the mass.
        const cJSON* b = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(
                                                cJSON_GetObjectItemCaseSensitive(doc, "mechanics"), "bodies"),
                                            p->mech);
        const cJSON* in = cJSON_GetObjectItemCaseSensitive(b, "inertia");
        if (cJSON_IsNumber(in)) {
            snprintf(a, sizeof a, "mechanics.bodies[%d].inertia=%.10g", p->mech, in->valuedouble * si / old);
            rc = json_set_path(doc, a, e, sizeof e);
        }
    }
    model* nm = NULL;
    if (!rc) {
        nm = model_from_json(doc, s->m->file, e, sizeof e); // owns doc from here
        doc = NULL;
    }
    cJSON_Delete(doc);
    if (!nm) {
        p->value = old / p->scale;
        char t[512];
        snprintf(t, sizeof t, "refused: %s/%s: %s", p->group, p->label, e);
        say(s, t);
        return -1;
    }
    // What the scenario added to the model (its bursts) goes along.
    if (s->m->world_bursts) nm->world_bursts = cJSON_Duplicate(s->m->world_bursts, 1);
    snprintf(nm->world_bursts_src, sizeof nm->world_bursts_src, "%s", s->m->world_bursts_src);
    model* om = s->m;
    const int seg = s->segment;
    const double t_at = s->t_base + engine_time(s->l);
    s->m = nm;
    rebuild_world(s, false);
    if (s->segment == seg) { // rebuild_world said why; the old world runs on
        s->m = om;
        model_free(nm);
        p->value = old / p->scale;
        return -1;
    }
    model_free(om);
    ++s->st.rebuilds;
    rebind_charts(s);
    char t[512];
    snprintf(t, sizeof t, "%s/%s = %.4g %s: world rebuilt at t = %.2f s (the joints past the first two booms at "
             "mid-limits)", p->group, p->label, p->value, p->unit, t_at);
    say(s, t);
    return 0;
}

// Apply one accepted panel change to the running simulation; -1 when the
// circuit rejected it (the panel shows the old value again).
static int apply_param(drive_session* s, int i) {
    drive_param* p = &s->param[i];
    if (p->kind == PK_CHART) { // the window's own charts, local and remote alike
        const int k = (int)p->value;
        snprintf(s->chart_pick[p->mech], sizeof s->chart_pick[0], "%s",
                 k > 0 && k < s->nchart_opt ? s->chart_opt[k] : "");
        apply_chart_picks(s);
        return 0;
    }
    if (s->remote) {
        remote_param(s, p); // set on the server, not in this drive's model
        return 0;
    }
    const double si = p->value * p->scale;
    char e[256];
    switch (p->kind) {
    case PK_HYD:
        // Once, on the run's circuit: the model's own unless the world adds
        // components to it (then a rebuilt world compiles the model document,
        // which sync_json below updates; a saved file is that document).
        if (hyd_model_set(engine_circuit(s->l), p->hyd_path, si, e, sizeof e)) {
            snprintf(s->status, sizeof s->status, "rejected: %s", e);
            double old;
            if (!hyd_model_get(engine_circuit(s->l), p->hyd_path, &old)) p->value = old / p->scale;
            if (p->inherit[0] && old == 0 && !hyd_model_get(engine_circuit(s->l), p->inherit, &old))
                p->value = old / p->scale; // still the fluid's
            return -1;
        }
        follow_fluid(s, p, si);
        break;
    case PK_MECH: {
        crane_mech* me = &s->m->mech;
        double* f = model_param_ptr(me, p->mech);
        int k = -1;
        if (sscanf(p->json, "mechanics.links[%d]", &k) == 1 && k >= 0 && k < 2) {
            // Only the edited link changes, and it keeps its own mass
            // distribution: a new mass scales its inertia, a new length
            // scales its centre of mass and (squared) its inertia.
            crane_link* ln = &me->link[k];
            if (f == &ln->mass && ln->mass > 0) ln->inertia *= si / ln->mass;
            if (f == &ln->length && ln->length > 0) {
                const double r = si / ln->length;
                ln->com *= r;
                ln->inertia *= r * r;
            }
            *f = si;
            crane_mech_derive(me);
            // In place where the backend can (the lagrange crane; an ode
            // boom's mass and inertia), else one rebuild at the current pose.
            if (f == &ln->width || f == &ln->height || engine_set_link(s->l, k, ln)) {
                s->rebuild = true;
                snprintf(s->rebuild_why, sizeof s->rebuild_why, "%s/%s", p->group, p->label);
            } else {
                s->mech_live.link[k] = *ln; // the running world has it now
            }
        } else {
            *f = si;
            crane_mech_derive(me);
            s->rebuild = true;
            snprintf(s->rebuild_why, sizeof s->rebuild_why, "%s/%s", p->group, p->label);
        }
        // The model file's fields that moved with it follow, so "save
        // model" saves what is being driven; the panel shows them.
        sync_mech_json(s);
        refresh_mech_params(s);
        break;
    }
    case PK_CHART: // applied above
        return 0;
    case PK_CHAIN:
        if (apply_chain(s, p, si)) return -1; // the status line says why
        note_unsaved(s, p);
        return 0;
    case PK_LOAD:
        engine_set_load(s->l, si);
        s->c.sim.load_mass = si;
        break;
    case PK_SOLVER: {
        const int k = (int)p->value;
        s->c.sim.solver = k_solver[k >= 0 && k < NSOLVER ? k : 0];
        s->rebuild = true;
        snprintf(s->rebuild_why, sizeof s->rebuild_why, "solver %s", k_solver_name[k >= 0 && k < NSOLVER ? k : 0]);
        snprintf(s->status, sizeof s->status, "solver/method = %s", k_solver_name[k >= 0 && k < NSOLVER ? k : 0]);
        return 0;
    }
    case PK_STEP: {
        // A backend that sub-steps the hydraulics in a rigid-body step (the
        // ode world's 1 ms) needs the hydraulic step to divide it.
        engine_desc d;
        engine_describe(&s->c.sim, &d);
        double sub = d.dt_outer > 0 ? floor(d.dt_outer / si + 0.5) : 0;
        s->c.sim.h = sub > 0 ? d.dt_outer / sub : si;
        p->value = s->c.sim.h / p->scale;
        s->rebuild = true;
        snprintf(s->rebuild_why, sizeof s->rebuild_why, "solver step %.4g ms", p->value);
        break;
    }
    }
    sync_json(s, p);
    note_unsaved(s, p);
    snprintf(s->status, sizeof s->status, "%s/%s = %.4g %s", p->group, p->label, p->value, p->unit);
    return 0;
}

static void stop_recording(drive_session* s);

static void rebuild_world(drive_session* s, bool at_start) {
    double* row = s->row; // the running engine's columns (size_buffers)
    engine_row(s->l, row);
    double q0[2] = {row[COL_Q1], row[COL_Q2]}, slew0 = row[COL_SLEW]; // 0 where the crane does not slew
    if (at_start) {
        q0[0] = s->sc.q0[0];
        q0[1] = s->sc.q0[1];
        slew0 = s->sc.slew0;
    }
    engine* l = make_engine(s, q0, slew0);
    if (!l) {
        // The running world goes on with the options it was built with, and
        // the panel shows them again.
        snprintf(s->status, sizeof s->status, "rebuild failed (%s kept): %s",
                 hyd_method_name(s->sim_live.solver), s->err);
        // The HUD's status line holds about 120 characters; the whole reason
        // goes to the terminal too.
        fprintf(stderr, "cranesim drive: %s\n", s->status);
        s->c.sim.solver = s->sim_live.solver;
        s->c.sim.h = s->sim_live.h;
        // The mechanics too: a length the world could not be built with must
        // not stay in the model (and the panel, and "save model") to come in
        // unasked with the next rebuild.
        s->m->mech = s->mech_live;
        sync_mech_json(s);
        refresh_mech_params(s);
        for (int i = 0; i < s->nparam; ++i) {
            drive_param* p = &s->param[i];
            if (p->kind == PK_STEP) p->value = s->c.sim.h / p->scale;
            if (p->kind == PK_SOLVER)
                for (int k = 0; k < NSOLVER; ++k)
                    if (k_solver[k] == s->c.sim.solver) p->value = k;
        }
        return;
    }
    s->sim_live = s->c.sim;
    s->mech_live = s->m->mech;
    // The real-time factor is the new piece's simulated time over its own
    // wall time: dividing it by the wall time since the session started read
    // "RT 0.42x" (and "cannot keep up") for ever after a reset. The totals
    // (drive_stats) add the pieces up.
    const double t_old = engine_time(s->l);
    s->sim_done += t_old;
    s->t_base = at_start ? 0.0 : s->t_base + t_old;
    s->piece_wall0 = s->wall_last;
    s->piece_paused = 0.0;
    ++s->segment;
    engine_destroy(s->l);
    s->l = l;
    // A loaded model may have other columns (a crane chain's): the record
    // holds one header, so it stops there.
    const int ncol_old = s->ncol;
    s->rec_stop[0] = '\0';
    if (size_buffers(s)) {
        snprintf(s->status, sizeof s->status, "out of memory");
    } else if (s->ncol != ncol_old && s->rec) {
        stop_recording(s);
        snprintf(s->rec_stop, sizeof s->rec_stop, "%.300s (the new model has %d columns, the recording %d)", s->status,
                 s->ncol, ncol_old);
        snprintf(s->status, sizeof s->status, "%s", s->rec_stop);
    }
    // The same circuit, so the same channels in the same order (the charts
    // keep their indices); the list reads the new engine.
    chan_list* cl = chan_list_create(l);
    if (cl) {
        chan_list_free(s->chans);
        s->chans = cl;
    }
    reapply_world_params(s);
    s->sim_offset = s->wall_last; // the new world's clock starts at 0 now
    if (at_start) {
        // A new run: the script and the charts start again. A rebuild keeps
        // the session's time running, so charts and script continue.
        s->ev = 0;
        render_chart_clear(s->r);
    }
}

// Strip-chart channel list: channel names (not t), comma-separated, 1 to 8
// of them: the engine's columns (among the first ncol) and, when cl is not
// NULL, its circuit's channels ("lift_cyl.A.p"). Without cl a name with a
// dot is taken as a circuit channel, checked when the session has its
// circuit. Without cl, cc (may be NULL) is the crane chain the model has:
// its own columns (crane_chain_columns: x_<actuator>, u_<function>, ...) are
// names too, checked again when the session has its engine. Fills col[]
// (indices into cl, or columns; -1 for a deferred name) and returns the
// count, or -1 with a one-line message.
static int parse_charts(const char* opt, const char* list, int ncol, const chan_list* cl, const crane_chain* cc,
                        int col[8], char* err, size_t errsz) {
    int n = 0;
    for (const char* p = list;; ++p) {
        const char* e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == 0) {
            snprintf(err, errsz, "%s: expected column names separated by commas, got '%s'", opt, list);
            return -1;
        }
        int c = -1;
        const int nch = cl ? chan_list_count(cl) : ncol;
        for (int k = 1; k < nch; ++k) {
            const char* nm = cl ? chan_list_channel(cl, k)->name : sim_col_name[k];
            if (k >= ncol && k < chan_list_nrow(cl)) continue; // a world column the engine does not write
            if (strlen(nm) == len && !strncmp(p, nm, len)) c = k;
        }
        bool deferred = !cl && memchr(p, '.', len);
        for (int k = 0; !cl && cc && k < cc->ncol && !deferred; ++k)
            deferred = strlen(cc->col[k].name) == len && !strncmp(p, cc->col[k].name, len);
        if (c < 0 && !deferred) {
            // A circuit channel is named after the model's nodes and
            // components (docs/render.md), a column is in run --help.
            const bool circ = memchr(p, '.', len) != NULL;
            snprintf(err, errsz, "%s: no %s '%.*s'%s (see %s for the names)", opt, circ ? "circuit channel" : "column",
                     (int)len, p, ncol < SIM_NCOL && !circ ? " in the lagrange view" : "",
                     circ ? "the model's node and component names, docs/render.md"
                     : (cc || (cl && chan_list_nrow(cl) > SIM_NCOL)) ? "cranesim run --help and the crane chain's "
                                                                       "columns x_<actuator>, pA_<actuator>, "
                                                                       "u_<function>, ... in docs/render.md"
                                                                     : "cranesim run --help");
            return -1;
        }
        if (n == 8) {
            snprintf(err, errsz, "%s: at most 8 channels, got more in '%s'", opt, list);
            return -1;
        }
        col[n++] = c;
        if (!e) return n;
        p = e;
    }
}

int drive_opts_check(const app_common* c, const drive_opts* o, char* err, size_t errsz) {
    if (c->sim.cvode) {
        // engine_lagrange.c steps the hydraulics with the in-house solvers only; run
        // says the same for the ode world (sim.c).
        snprintf(err, errsz, "--solver cvode: drive steps the hydraulics in real time with the in-house solvers: use "
                             "krus, ros2, rk4, ros34pw2 or rodas3");
        return EXIT_USAGE;
    }
    // A crane chain's columns are named after its actuators and functions:
    // the model says which (a model that does not load is said by the load
    // that follows; here the names are then the base columns).
    model* m = NULL;
    if (o->charts || o->readouts) {
        char me[300];
        m = model_load(c->model_path, c->sets, c->nset, me, sizeof me);
    }
    const crane_chain* cc = m && !m->chain.two_link ? &m->chain : NULL;
    int col[8], rc = 0;
    if (o->charts && parse_charts("--charts", o->charts, sim_ncol(&c->sim), NULL, cc, col, err, errsz) < 0)
        rc = EXIT_USAGE;
    if (!rc && o->readouts && parse_charts("--readouts", o->readouts, sim_ncol(&c->sim), NULL, cc, col, err, errsz) < 0)
        rc = EXIT_USAGE;
    model_free(m);
    if (rc) return rc;
    if (o->mapping_file) {
        // Read and checked here; its function names against the model's
        // functions when the session builds the mapping (setup_mapping).
        model_controls* mc = malloc(sizeof *mc);
        const int rc = !mc || controls_load_file(o->mapping_file, mc, err, errsz);
        if (!mc) snprintf(err, errsz, "%s: out of memory", o->mapping_file);
        free(mc);
        if (rc) return EXIT_USAGE;
    }
    return 0;
}

// The operator's mapping for the functions names[n] (in that order, so
// command k of input_poll is function k): the default layout (the mapping
// file's "layout", else the model's, else two-lever), then the model's
// "controls" section (controls, or NULL) as far as names has its functions,
// then the --mapping file over it. 0, or -1 with one line naming the file and
// field in err. what names the crane for the "too many functions" message.
static int build_mapping_for(const drive_session* s, const char* const* names, int n, const model_controls* controls,
                             const char* what, input_mapping* map, char* err, size_t errsz) {
    if (n > INPUT_MAX_FN) {
        snprintf(err, errsz, "%s: %d functions; the drive's input mapping takes at most %d", what, n, INPUT_MAX_FN);
        return -1;
    }
    model_controls* fc = NULL;
    int rc = 0;
    if (s->o.mapping_file) {
        fc = malloc(sizeof *fc);
        rc = !fc || controls_load_file(s->o.mapping_file, fc, err, errsz);
        if (!fc) snprintf(err, errsz, "%s: out of memory", s->o.mapping_file);
    }
    // The model's section, as far as names has its functions: the loader
    // checked its names against the model's, and a slewing chain's "slew" has
    // no function in a world without a slew drive (validation).
    model_controls* mc = NULL;
    if (!rc && controls) {
        mc = malloc(sizeof *mc);
        if (!mc) {
            snprintf(err, errsz, "%s: out of memory", s->m->file);
            rc = -1;
        } else {
            *mc = *controls;
            int keep = 0;
            for (int i = 0; i < mc->nfn; ++i)
                for (int k = 0; k < n; ++k)
                    if (!strcmp(names[k], mc->fn[i].function)) {
                        mc->fn[keep++] = mc->fn[i];
                        break;
                    }
            mc->nfn = keep;
        }
    }
    const char* layout = fc && fc->layout[0] ? fc->layout : mc && mc->layout[0] ? mc->layout : NULL;
    if (!rc) rc = input_layout_mapping(names, n, layout, map, err, errsz);
    if (!rc && mc) rc = input_apply_controls(map, mc, s->m->file, "controls", err, errsz);
    if (!rc && fc) rc = input_apply_controls(map, fc, s->o.mapping_file, "", err, errsz);
    free(mc);
    free(fc);
    return rc ? -1 : 0;
}

// The mapping for the engine's functions (engine_nfunction, in its order)
// and the model's "controls".
static int build_mapping(const drive_session* s, input_mapping* map, char* err, size_t errsz) {
    const int n = engine_nfunction(s->l);
    const char* names[INPUT_MAX_FN];
    for (int k = 0; k < n && k < INPUT_MAX_FN; ++k) names[k] = engine_function_name(s->l, k);
    return build_mapping_for(s, names, n, s->m->controls, s->m->file, map, err, errsz);
}

// The mapping into the input layer and the HUD's box (its text, heading).
// model_controls: the model's "controls" section is in it.
static void show_mapping(drive_session* s, const input_mapping* map, bool model_controls) {
    char text[1536], title[96];
    input_mapping_text(map, text, sizeof text);
    snprintf(title, sizeof title, "controls (%s%s) - M hides", map->layout, model_controls ? ", the model's" : "");
    render_set_mapping(s->r, title, text);
}

// Chosen strip-chart channels: CSV column names, shown in display units
// (MPa, mm, %, deg, kN), one plot per unit.
static int setup_charts(drive_session* s, const char* list, char* err, size_t errsz) {
    static const float colours[8][4] = {{0.95f, 0.35f, 0.3f, 1}, {0.3f, 0.75f, 0.95f, 1}, {0.95f, 0.8f, 0.25f, 1},
                                        {0.5f, 0.9f, 0.4f, 1},   {0.8f, 0.5f, 0.95f, 1},  {0.95f, 0.6f, 0.2f, 1},
                                        {0.6f, 0.9f, 0.9f, 1},   {0.9f, 0.9f, 0.9f, 1}};
    int cols[8];
    const int n = parse_charts("--charts", list, s->ncol, s->chans, NULL, cols, err, errsz);
    if (n < 0) return -1;
    for (int i = 0; i < n; ++i) {
        const int col = cols[i];
        const sim_channel* ch = chan_list_channel(s->chans, col);
        const char* u = ch->unit;
        render_chart_def d = {.label = ch->name, .unit = u, .scale = 1, .ymin = -1, .ymax = 1, .group = 5};
        if (!strcmp(u, "Pa")) d.unit = "MPa", d.scale = 1e-6, d.ymin = 0, d.ymax = 30, d.group = 0;
        else if (!strcmp(u, "m")) d.unit = "mm", d.scale = 1e3, d.ymin = -5000, d.ymax = 5000, d.group = 1;
        else if (!strcmp(u, "-")) d.unit = "%", d.scale = 100, d.ymin = -100, d.ymax = 100, d.group = 2;
        else if (!strcmp(u, "rad")) d.unit = "deg", d.scale = 180 / M_PI, d.ymin = -180, d.ymax = 180, d.group = 3;
        else if (!strcmp(u, "N")) d.unit = "kN", d.scale = 1e-3, d.ymin = -200, d.ymax = 200, d.group = 4;
        else if (!strcmp(u, "m^3/s")) d.unit = "L/min", d.scale = 60000, d.ymin = -50, d.ymax = 50, d.group = 6;
        if (col >= chan_list_nrow(s->chans)) s->chart_circuit = true;
        if (col == COL_X1 || col == COL_X2) d.ymin = 0, d.ymax = 700;
        memcpy(d.rgba, colours[s->nchart], sizeof d.rgba);
        s->chart_col[s->nchart] = col;
        s->chart_id[s->nchart] = render_chart_add(s->r, &d);
        ++s->nchart;
    }
    return 0;
}

static void act_load(void* user) {
    drive_session* s = user;
    if (s->remote) {
        say(s, "load model: not over the link (start the server with --model)");
        return;
    }
    s->load_pending = true; // at the next tick: not from inside the panel's own drawing
}

static void act_reset(void* user);
static void act_save(void* user);
static void act_pause(void* user);

static void free_chart_opt(drive_session* s) {
    for (int k = 0; k < s->nchart_opt; ++k) free(s->chart_opt[k]);
    free(s->chart_opt);
    s->chart_opt = NULL;
    s->nchart_opt = 0;
}

// The panel for the model and engine as they are: generated entries, the
// model file box and the actions. Replaces the old panel (a loaded model has
// other components); the window stays shown or hidden as it was.
static int setup_panel(drive_session* s) {
    const bool shown = s->pn ? panel_gui_visible(s->pn) : false;
    char filter[64] = "";
    if (s->pn) {
        snprintf(filter, sizeof filter, "%s", panel_filter(s->pn));
        render_attach_panel(s->r, NULL);
        panel_destroy(s->pn);
    }
    // The chart choices of the engine's channels (they outlive the panel:
    // freed only once it is gone).
    free_chart_opt(s);
    const int nch = s->chans ? chan_list_count(s->chans) : 0;
    s->chart_opt = calloc((size_t)nch + 1, sizeof *s->chart_opt);
    if (s->chart_opt) {
        s->chart_opt[s->nchart_opt++] = strdup("(default)");
        for (int k = 1; k < nch; ++k) // not t
            if ((s->chart_opt[s->nchart_opt] = strdup(chan_list_channel(s->chans, k)->name))) ++s->nchart_opt;
    }
    s->pn = panel_create();
    if (!s->pn) return -1;
    build_params(s);
    for (int i = 0; i < s->nparam; ++i) {
        drive_param* p = &s->param[i];
        panel_param_def d = {p->label, p->group, p->unit, &p->value, p->min, p->max, 0, p->on_release};
        s->pid[i] = p->kind == PK_SOLVER ? panel_add_choice(s->pn, p->label, p->group, &p->value, k_solver_name, NSOLVER)
                    : p->kind == PK_CHART
                        ? panel_add_choice(s->pn, p->label, p->group, &p->value, (const char* const*)s->chart_opt,
                                           s->nchart_opt)
                        : panel_add_param(s->pn, &d);
        if (p->kind != PK_SOLVER && p->kind != PK_CHART) panel_set_slider_range(s->pn, s->pid[i], p->tmin, p->tmax);
        if (p->inherit[0]) panel_set_note(s->pn, s->pid[i], "fluid's");
    }
    panel_add_text(s->pn, "model file", s->load_path, sizeof s->load_path);
    panel_add_action(s->pn, "reset run", act_reset, s);
    panel_add_action(s->pn, "save model", act_save, s);
    panel_add_action(s->pn, "pause / resume", act_pause, s);
    panel_add_action(s->pn, "load model", act_load, s);
    panel_set_filter(s->pn, filter);
    render_attach_panel(s->r, s->pn);
    panel_gui_show(s->pn, shown);
    return 0;
}

// The charts without --charts: one set of channels per cylinder the world
// has (the sandbox's slew rack is the third; the validation world and the
// lagrange view have only the two boom cylinders); a crane chain's every
// actuator and the slew rack, by name.
static void default_charts(drive_session* s) {
    if (s->m->chain.two_link) render_charts_default(s->r, s->snap->ncyl);
    else render_charts_default_named(s->r, s->snap);
}

static int setup_charts(drive_session* s, const char* list, char* err, size_t errsz);

// The charts the panel's slots name, in slot order; none: the default set.
static void apply_chart_picks(drive_session* s) {
    char list[DRIVE_CHART_SLOTS * 97] = "", err[400];
    size_t n = 0;
    for (int k = 0; k < DRIVE_CHART_SLOTS; ++k)
        if (s->chart_pick[k][0] && n < sizeof list)
            n += (size_t)snprintf(list + n, sizeof list - n, "%s%s", n ? "," : "", s->chart_pick[k]);
    render_charts_reset(s->r);
    s->nchart = 0;
    memset(s->chart_n, 0, sizeof s->chart_n); // the slots' channels change
    s->chart_circuit = false;
    for (int i = 0; i < s->nreadout; ++i) // the readouts keep theirs
        if (s->readout_col[i] >= chan_list_nrow(s->chans)) s->chart_circuit = true;
    if (!list[0] || setup_charts(s, list, err, sizeof err)) {
        if (list[0]) say(s, err); // a name the channels lost (not from the panel's list)
        render_charts_reset(s->r);
        s->nchart = 0;
        default_charts(s);
        if (!list[0]) say(s, "charts: the default set");
        return;
    }
    char t[sizeof s->status];
    snprintf(t, sizeof t, "charts: %.500s", list);
    say(s, t);
}

// Charts on channels by name again, in a list that may have changed (a
// loaded model): a channel the new circuit lacks is left empty. The
// default charts follow the new model's cylinders.
static void rebind_charts(drive_session* s) {
    if (!s->nchart) {
        render_charts_reset(s->r);
        take_snapshot(s);
        default_charts(s);
    }
    s->chart_circuit = false;
    for (int i = 0; i < s->nchart; ++i) {
        s->chart_col[i] = chan_list_find(s->chans, render_chart_label(s->r, s->chart_id[i]));
        if (s->chart_col[i] >= chan_list_nrow(s->chans)) s->chart_circuit = true;
    }
    for (int i = 0; i < s->nreadout; ++i) {
        s->readout_col[i] = chan_list_find(s->chans, s->readout_name[i]);
        if (s->readout_col[i] >= chan_list_nrow(s->chans)) s->chart_circuit = true;
    }
    free(s->chan_v);
    s->chan_v = calloc((size_t)chan_list_count(s->chans), sizeof *s->chan_v);
}

static void rebuild_world(drive_session* s, bool at_start);

// Load the panel's model file and drive on with it in the same world, from
// the current pose: a new engine, a new panel. A file that does not load, or
// a model the world cannot be built with, leaves the running model as it
// is, with the one-line reason in the panel and the status line.
static void load_model(drive_session* s) {
    char e[400];
    model* nm = model_load(s->load_path[0] ? s->load_path : NULL, NULL, 0, e, sizeof e);
    // A crane chain loads as the two-link crane does; the engine for it must
    // have a picture for the window (make_engine refuses one without).
    if (!nm) {
        snprintf(s->status, sizeof s->status, "load failed (model kept): %s", e);
        panel_set_message(s->pn, s->status);
        fprintf(stderr, "cranesim drive: %s\n", s->status);
        return;
    }
    model* old = s->m;
    const int seg = s->segment;
    s->m = nm;
    rebuild_world(s, false);
    if (s->segment == seg) {
        // rebuild_world said why in the status line; the old engine runs on.
        s->m = old;
        model_free(nm);
        snprintf(s->status, sizeof s->status, "load failed (model kept): %s", s->err);
        panel_set_message(s->pn, s->status);
        return;
    }
    model_free(old);
    ++s->st.rebuilds;
    // The loaded model's functions and controls; a mapping it refuses
    // (its controls against the --mapping file) keeps the one in use.
    input_mapping map;
    char me[400];
    if (build_mapping(s, &map, me, sizeof me) == 0) {
        input_set_mapping(s->in, &map);
        show_mapping(s, &map, s->m->controls != NULL);
    } else {
        fprintf(stderr, "cranesim drive: input mapping kept: %s\n", me);
    }
    rebind_charts(s);
    setup_panel(s);
    saved(s); // the panel now edits the loaded file's model
    snprintf(s->status, sizeof s->status, "loaded %.200s (%.96s)%s%.200s", nm->file, nm->name, s->rec_stop[0] ? "; " : "",
             s->rec_stop);
    panel_set_message(s->pn, s->status);
}

// End the session file (docs/replay.md): it holds one world from its start,
// so a reset, a rebuild or a panel change ends it; the window goes on.
static void session_end(drive_session* s, const char* why) {
    if (!s->sw.f) return;
    snprintf(s->sess_end, sizeof s->sess_end, "%s at t = %.6g s", why, s->t_base + engine_time(s->l));
    s->sess_err = session_writer_close(&s->sw, s->sess_end);
}

static void session_hook(void* user, engine* e, int attach, int got) {
    (void)e, (void)got;
    session_writer_hook(&((drive_session*)user)->sw, attach);
}

static void act_reset(void* user) {
    drive_session* s = user;
    if (s->remote) { // the server resets, asked once by the link
        s->rin.reset = 1;
        return;
    }
    session_end(s, "reset");
    s->rp_next = 0; // a replay starts again with the world
    rebuild_world(s, true);
    snprintf(s->status, sizeof s->status, "run reset");
}

int drive_save_name(char* path, size_t n) {
    // "wx" (C11) creates the file only if no file of that name exists, so a
    // name is taken atomically and nothing is ever overwritten; model_save
    // then fills the empty file.
    for (int k = 1; k <= 9999; ++k) {
        snprintf(path, n, "cranesim_model_%d.json", k);
        FILE* f = fopen(path, "wx");
        if (f) {
            fclose(f);
            return 0;
        }
        if (errno != EEXIST) return -1;
    }
    errno = EEXIST;
    return -1;
}

static void act_save(void* user) {
    drive_session* s = user;
    char e[320], path[256];
    if (s->o.save_as) {
        // The user named the file (--save-as): each save replaces it, and
        // the status line says so.
        snprintf(path, sizeof path, "%s", s->o.save_as);
    } else if (drive_save_name(path, sizeof path)) {
        snprintf(s->status, sizeof s->status, "save failed: cannot create %s: %s", path, strerror(errno));
        return;
    }
    if (model_save(s->m, path, e, sizeof e)) {
        snprintf(s->status, sizeof s->status, "save failed: %s", e);
        if (!s->o.save_as) remove(path); // the empty file reserved for it
    } else {
        snprintf(s->status, sizeof s->status, "model saved to %s%s", path, s->o.save_as ? " (--save-as, replaced)" : "");
        saved(s);
    }
}

static void act_pause(void* user) {
    drive_session* s = user;
    if (s->remote) {
        s->rin.pause = 1;
        return;
    }
    s->paused = !s->paused;
}

// A recording that cannot be written is stopped at once and remembered
// (drive_session_finish_record reports it): a CSV that silently stops
// growing is output lost. What was written before stays in the file.
static void record_failed(drive_session* s, int e) {
    if (!s->rec_err[0])
        snprintf(s->rec_err, sizeof s->rec_err, "cannot write %s: %s", s->rec_path, strerror(e ? e : EIO));
    snprintf(s->status, sizeof s->status, "recording failed: cannot write %s: %s", s->rec_path, strerror(e ? e : EIO));
    fclose(s->rec);
    s->rec = NULL;
}

// Close the recording, checking that the buffered rows reached the file.
static void stop_recording(drive_session* s) {
    if (!s->rec) return;
    const int e = app_fclose_checked(s->rec, 0);
    s->rec = NULL;
    if (e) {
        if (!s->rec_err[0]) snprintf(s->rec_err, sizeof s->rec_err, "cannot write %s: %s", s->rec_path, strerror(e));
        snprintf(s->status, sizeof s->status, "recording failed: %s", s->rec_err);
        return;
    }
    snprintf(s->status, sizeof s->status, "recording stopped: %s (%ld rows)", s->rec_path, s->rec_rows);
}

static int start_recording(drive_session* s, const char* path) {
    snprintf(s->rec_path, sizeof s->rec_path, "%s", path);
    s->rec_rows = 0;
    s->rec_seg0 = s->segment;
    s->rec = fopen(path, "w");
    if (!s->rec) {
        // Remembered like a failed write: the session's end must not report
        // a record that was never opened (F5 in an unwritable folder).
        snprintf(s->rec_err, sizeof s->rec_err, "cannot write %s: %s", path, strerror(errno));
        snprintf(s->status, sizeof s->status, "%s", s->rec_err);
        return -1;
    }
    errno = 0;
    // The world's columns and `segment`: 0 from the start, one more at each
    // reset or rebuild (a reset starts t at 0 again, a rebuild puts the
    // loads back), so a reader can split the record where the world jumped.
    // The engine's channels by name (a crane chain's columns after the base
    // ones), as a scripted run's CSV header.
    for (int c = 0; c < s->ncol; ++c) fprintf(s->rec, "%s,", chan_list_channel(s->chans, c)->name);
    fputs("segment\n", s->rec);
    if (ferror(s->rec)) {
        record_failed(s, errno);
        return -1;
    }
    return 0;
}

// row: ncol columns in a buffer of ncol + 1 (s->row): the segment goes last.
static void record_row(drive_session* s, double* row) {
    // One row per simulated instant: paused (or a tick too short to step)
    // the time stands still, and a row per tick repeated it (196 rows at the
    // same t over a 4 s pause). A reset starts a new segment, whose time may
    // begin again at 0.
    if (s->rec_rows > 0 && s->segment == s->rec_seg_last && !(row[COL_T] > s->rec_t_last)) return;
    s->rec_t_last = row[COL_T];
    s->rec_seg_last = s->segment;
    errno = 0;
    row[s->ncol] = s->segment - s->rec_seg0;
    sim_csv_row(s->rec, row, s->ncol + 1);
    if (ferror(s->rec)) record_failed(s, errno);
    else ++s->rec_rows;
}

int drive_session_finish_record(drive_session* s, long* rows, char* err, size_t errsz) {
    stop_recording(s);
    if (rows) *rows = s->rec_rows;
    if (!s->rec_err[0]) return 0;
    snprintf(err, errsz, "%s", s->rec_err);
    return -1;
}

// The world's row, on the session's clock.
static void session_row(drive_session* s, double* row) {
    if (s->remote) {
        // The local engine's ncol columns (the record's header, the buffer's
        // size: size_buffers), from the server's row of the same channels; a
        // column past the protocol's PROTO_MAX_ROW is not sent (NaN).
        for (int k = 0; k < s->ncol; ++k) row[k] = k < PROTO_MAX_ROW ? s->remote_row[k] : NAN;
        return;
    }
    engine_row(s->l, row);
    row[COL_T] += s->t_base;
}

static void take_snapshot(drive_session* s) {
    if (s->remote) return; // drive_session_feed fills it
    engine_snapshot(s->l, s->snap);
    s->snap->t += s->t_base;
    char note[192];
    if (render_pad_event(s->snap, &s->pad_lifted, note, sizeof note)) fprintf(stderr, "cranesim drive: %s\n", note);
}

drive_session* drive_session_create(const app_common* c, const drive_opts* o, char* err, size_t errsz,
                                    int* code) {
    int dummy;
    if (!code) code = &dummy;
    *code = EXIT_RUNTIME;
    drive_session* s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    s->c = *c;
    s->o = *o;
    s->snap = calloc(1, sizeof *s->snap);
    // Options first: a bad chart name or mapping file is bad input whatever
    // else happens (and before a window opens).
    if ((*code = drive_opts_check(c, o, err, errsz)) != 0 || !s->snap) {
        if (!s->snap) {
            snprintf(err, errsz, "out of memory");
            *code = EXIT_RUNTIME;
        }
        drive_session_destroy(s);
        return NULL;
    }
    *code = EXIT_RUNTIME;
    if (!s->c.scenario_path)
        s->c.scenario_path = app_default_drive_scenario(&s->c.sim);
    if (app_load_msg(&s->c, &s->m, &s->sc, err, errsz)) {
        drive_session_destroy(s);
        *code = EXIT_USAGE;
        return NULL;
    }
    if (o->replay_path) {
        // The session's design (with --model, --set), settings and start;
        // its commands replace the devices (drive_session_tick).
        s->rp = calloc(1, sizeof *s->rp);
        model* rm = NULL;
        if (!s->rp || session_load(o->replay_path, s->rp, err, errsz) ||
            !(rm = session_model(s->rp, s->c.model_path, s->c.sets, s->c.nset, err, errsz))) {
            drive_session_destroy(s);
            *code = EXIT_USAGE;
            return NULL;
        }
        model_free(s->m);
        s->m = rm;
        s->c.sim = s->rp->sim; // the limiter's setting too (drive --rcl overrides it)
        if (o->replay_rcl >= 0) s->c.sim.rcl = o->replay_rcl != 0;
        memcpy(s->sc.q0, s->rp->q0, sizeof s->sc.q0);
        s->sc.slew0 = s->rp->slew0;
        s->sc.nfault = 0;
    }
    s->l = make_engine(s, s->sc.q0, s->sc.slew0);
    s->sim_live = s->c.sim;
    s->mech_live = s->m->mech;
    if (!s->l) {
        // A world file or model the world cannot be built from.
        snprintf(err, errsz, "%s", s->err);
        drive_session_destroy(s);
        *code = EXIT_USAGE;
        return NULL;
    }
    if (size_buffers(s)) {
        snprintf(err, errsz, "out of memory");
        drive_session_destroy(s);
        return NULL;
    }
    if (s->rp && s->rp->ncol != s->ncol) {
        snprintf(err, errsz, "session %s: ncol: the session has %d channels, this engine writes %d", s->rp->path,
                 s->rp->ncol, s->ncol);
        drive_session_destroy(s);
        *code = EXIT_USAGE;
        return NULL;
    }
    // The recorded commands by function name (session.h).
    if (s->rp) {
        const int nfn = engine_nfunction(s->l);
        s->rp_map = calloc((size_t)nfn + 1, sizeof *s->rp_map);
        s->rp_u = calloc((size_t)nfn + 3, sizeof *s->rp_u);
        if (!s->rp_map || !s->rp_u) snprintf(err, errsz, "out of memory");
        if (!s->rp_map || !s->rp_u || session_function_map(s->rp, s->l, s->rp_map, NULL, 0, err, errsz) < 0) {
            drive_session_destroy(s);
            *code = EXIT_USAGE;
            return NULL;
        }
    }
    // The window's faults are not in the session (its scripted operator
    // applies no bursts: the engine has no burst orifices).
    if (o->session_path && !s->rp &&
        session_writer_open(&s->sw, o->session_path, s->m->json, s->m->file, s->l, &s->c.sim, NULL, s->sc.q0, s->sc.slew0,
                            sim_load_mass(s->m, &s->sc, &s->c.sim), true, s->ncol, err, errsz)) {
        drive_session_destroy(s);
        *code = EXIT_USAGE;
        return NULL;
    }
    s->chans = chan_list_create(s->l);
    s->chan_v = s->chans ? calloc((size_t)chan_list_count(s->chans), sizeof *s->chan_v) : NULL;
    if (!s->chans || !s->chan_v) {
        snprintf(err, errsz, "out of memory");
        drive_session_destroy(s);
        return NULL;
    }
    // Keep reading the sticks when the 3D window is not focused (the operator
    // may click a plot or a terminal; and an offscreen view never has focus).
    SDL_SetHint(SDL_HINT_JOYSTICK_ALLOW_BACKGROUND_EVENTS, "1");
    render_config rc = render_default_config();
    rc.width = o->width;
    rc.height = o->height;
    rc.offscreen = o->offscreen;
    rc.hud = o->hud;
    rc.title = "cranesim drive";
    // No vsync: a swap that waits for the display's refresh would stall the
    // loop's 240 Hz ticks (valve commands); the 65 fps cap paces the frames.
    rc.vsync = false;
    char asset_dir[512];
    snprintf(asset_dir, sizeof asset_dir, "%s/meshes", model_assets_dir());
    rc.asset_dir = asset_dir;
    s->r = render_create(&rc, err, errsz);
    if (s->r && o->collision_view) render_show_collision(s->r, true);
    if (!s->r) {
        // No screen to open a window on: the caller may run headless
        // instead. A window or GL context that fails on a real display is a
        // runtime failure (exit 1), not a reason to drive unseen.
        if (!o->offscreen && render_err_no_screen(err)) *code = DRIVE_NO_WINDOW;
        drive_session_destroy(s);
        return NULL;
    }
    input_mapping map;
    if (build_mapping(s, &map, err, errsz)) {
        drive_session_destroy(s);
        *code = EXIT_USAGE;
        return NULL;
    }
    s->in = input_create(&map);
    // The box for the first DRIVE_MAPPING_S of the drive (M toggles it).
    show_mapping(s, &map, s->m->controls != NULL);
    render_show_mapping(s->r, true);
    s->mapbox_off = DRIVE_MAPPING_S;
    snprintf(s->load_path, sizeof s->load_path, "%s", s->m->file);
    // The chart slots of the panel show --charts' channels.
    for (const char* q = o->charts; q && *q;) {
        const char* e = strchr(q, ',');
        const size_t len = e ? (size_t)(e - q) : strlen(q);
        for (int k = 0; k < DRIVE_CHART_SLOTS; ++k)
            if (!s->chart_pick[k][0]) {
                snprintf(s->chart_pick[k], sizeof s->chart_pick[k], "%.*s", (int)len, q);
                break;
            }
        q = e ? e + 1 : q + len;
    }
    // The panel starts hidden (Tab shows it): on llvmpipe it costs ~4 fps at
    // 1280x720 (56 vs 60 fps, cranesim bench --config drive), and the scene
    // is what an operator watches while driving.
    if (setup_panel(s)) {
        snprintf(err, errsz, "out of memory");
        drive_session_destroy(s);
        return NULL;
    }
    take_snapshot(s);
    if (o->charts) {
        if (setup_charts(s, o->charts, err, errsz)) {
            drive_session_destroy(s);
            *code = EXIT_USAGE;
            return NULL;
        }
    } else {
        default_charts(s);
    }
    if (o->readouts) {
        s->nreadout = parse_charts("--readouts", o->readouts, s->ncol, s->chans, NULL, s->readout_col, err, errsz);
        if (s->nreadout < 0) {
            drive_session_destroy(s);
            *code = EXIT_USAGE;
            return NULL;
        }
        for (int i = 0; i < s->nreadout; ++i) {
            const sim_channel* ch = chan_list_channel(s->chans, s->readout_col[i]);
            snprintf(s->readout_name[i], sizeof s->readout_name[i], "%s", ch->name);
            s->readout_scale[i] = display_unit(ch->unit, s->readout_unit[i], sizeof s->readout_unit[i]);
            // A channel's fraction (spool, displacement) in %, as its strip
            // chart shows it (a panel's unitless parameter stays as it is).
            if (!strcmp(ch->unit, "-")) {
                snprintf(s->readout_unit[i], sizeof s->readout_unit[i], "%%");
                s->readout_scale[i] = 0.01;
            }
            if (s->readout_col[i] >= chan_list_nrow(s->chans)) s->chart_circuit = true;
        }
    }
    if (o->record_path && start_recording(s, o->record_path)) {
        snprintf(err, errsz, "%s", s->status);
        drive_session_destroy(s);
        *code = EXIT_USAGE;
        return NULL;
    }
    s->wall_last_frame = -1.0;
    s->esc_armed = -1.0;
    // Warm-up frame before the caller starts its clock: the first frame
    // compiles the shaders and loads the meshes (well over 100 ms on
    // llvmpipe), which would otherwise count as a missed deadline.
    render_frame(s->r, s->snap);
    render_present(s->r);
    render_wait(s->r, 1.0);
    return s;
}

void drive_session_destroy(drive_session* s) {
    if (!s) return;
    if (s->rec) fclose(s->rec); // drive_session_finish_record checks it; here only freed
    if (s->sw.f) session_writer_close(&s->sw, "the window closed");
    if (s->rp) session_free(s->rp);
    free(s->rp);
    free(s->rp_map);
    free(s->rp_u);
    if (s->pn) {
        if (s->r) render_attach_panel(s->r, NULL);
        panel_destroy(s->pn);
    }
    if (s->in) input_destroy(s->in);
    if (s->r) render_destroy(s->r);
    engine_destroy(s->l);
    model_free(s->m);
    chan_list_free(s->chans);
    free(s->chan_v);
    free(s->param);
    free(s->pid);
    free(s->changed);
    free(s->row);
    free(s->ufn);
    free_chart_opt(s); // after the panel, which pointed at them
    free(s->snap);
    free(s);
}

// Draw s->snap as it stands (the caller took the snapshot).
static void render_snapshot(drive_session* s) {
    // Over less than 0.1 s of wall time the ratio means nothing (a frame at
    // t = 0 would read thousands); 0 is "unknown" (world_snapshot.h).
    if (!s->remote) s->snap->rt_factor = drive_session_rt_factor(s);
    render_frame(s->r, s->snap);
    render_present(s->r);
    s->st.triangles = render_get_stats(s->r).triangles;
    ++s->st.frames;
}

// One sample t [s], v (SI) into the session's chart i, counted.
static void chart_push(drive_session* s, int i, double t, double v) {
    render_chart_push(s->r, s->chart_id[i], t, v);
    ++s->chart_n[i];
    s->chart_last[i] = v;
}

long drive_session_chart_samples(const drive_session* s, int i, double* last) {
    if (i < 0 || i >= s->nchart) return -1;
    if (last) *last = s->chart_last[i];
    return s->chart_n[i];
}

void drive_session_set_remote(drive_session* s) {
    s->remote = true; // the panel stays: its circuit edits go to the server (remote_param)
    // The state frames carry the row's channels, not the circuit's: say so
    // once for a chart of one (its readout says it on the HUD).
    // (The HUD's readout box holds about 30 characters: it says "not sent".)
    for (int i = 0; i < s->nchart; ++i)
        if (s->chart_col[i] >= chan_list_nrow(s->chans)) {
            const sim_channel* ch = chan_list_channel(s->chans, s->chart_col[i]);
            printf("cranesim drive: chart %s: not sent by the server (the state frames carry the row's channels, "
                   "not the circuit's): it stays empty\n", ch ? ch->name : "?");
        }
    for (int i = 0; i < s->nreadout; ++i)
        if (s->readout_col[i] >= chan_list_nrow(s->chans))
            printf("cranesim drive: readout %s: not sent by the server (the state frames carry the row's channels, "
                   "not the circuit's): it reads \"not sent\"\n", s->readout_name[i]);
    // The local engine's collision shapes would stand still while the
    // remote crane moves: the remote view has none.
    s->snap->ncoll = 0;
    s->rin = (drive_remote_input){.hook = -1, .pause = -1, .reset = -1};
}

void drive_session_feed(drive_session* s, const proto_state* st, double rt_factor, const double* demand) {
    world_snapshot* w = s->snap;
    // The static parts (names, shapes, meshes, terrain) stay the local
    // engine's, built from the same files; the caller checked the bodies match.
    const int nb = st->nbody < w->nbody ? st->nbody : w->nbody;
    for (int i = 0; i < nb; ++i) {
        memcpy(w->body[i].pos, st->pose[i], 3 * sizeof(double));
        memcpy(w->body[i].rot, st->pose[i] + 3, 9 * sizeof(double));
    }
    w->ncyl = st->ncyl < WORLD_SNAP_MAX_CYLINDERS ? st->ncyl : WORLD_SNAP_MAX_CYLINDERS;
    for (int i = 0; i < w->ncyl; ++i) {
        world_snap_cylinder* y = &w->cyl[i];
        const double* d = st->cyl[i];
        memcpy(y->base, d, 3 * sizeof(double));
        memcpy(y->rod_end, d + 3, 3 * sizeof(double));
        y->x = d[6], y->pA = d[7], y->pB = d[8], y->u = d[9], y->u_cmd = d[10], y->force = d[11], y->v = d[12];
        y->relief_open = (st->cyl_bits[i] & PROTO_CYL_RELIEF) != 0;
        y->end_stop = (st->cyl_bits[i] & PROTO_CYL_END_STOP) != 0;
        // Where the server's limiter cut a command: the operator's demand is
        // this drive's own when it controls, else not known here (NaN).
        y->rcl_cut = i < 3 && (st->flags & (PROTO_F_RCL_CUT0 << i)) != 0;
        y->u_op = !y->rcl_cut ? y->u_cmd : demand ? demand[i] : NAN;
    }
    w->nrope = st->nrope < WORLD_SNAP_MAX_ROPE ? st->nrope : WORLD_SNAP_MAX_ROPE;
    memcpy(w->rope, st->rope, (size_t)w->nrope * sizeof w->rope[0]);
    w->t = st->nine[8];
    w->rt_factor = rt_factor;
    memcpy(w->tip, st->tip, sizeof w->tip);
    memcpy(w->hook, st->hook, sizeof w->hook);
    w->load_mass = st->load_mass;
    w->slew = st->slew;
    w->truck_tilt = acos(cos(st->roll) * cos(st->pitch)); // the world's acos(R22), within rounding
    w->p_supply = st->p_supply;
    w->attached = (st->flags & PROTO_F_ATTACHED) != 0;
    w->tipping = (st->flags & PROTO_F_TIPPING) != 0;
    w->collision = (st->flags & PROTO_F_COLLISION) != 0;
    w->main_relief_open = (st->flags & PROTO_F_RELIEF) != 0;
    w->nrelief = st->nrelief < WORLD_SNAP_MAX_RELIEFS ? st->nrelief : WORLD_SNAP_MAX_RELIEFS;
    for (int i = 0; i < w->nrelief; ++i) {
        snprintf(w->relief[i], sizeof w->relief[i], "%s", st->relief[i].name);
        w->relief_cyl[i] = st->relief[i].cyl;
        w->relief_port[i] = st->relief[i].port;
    }
    w->rcl_have = (st->flags & PROTO_F_RCL_HAVE) != 0;
    w->rcl_on = (st->flags & PROTO_F_RCL_ON) != 0;
    w->rcl_util = st->rcl_util;
    w->npad = st->npad;
    memcpy(w->pad_F, st->pad_F, sizeof w->pad_F);
    w->pad_lifted = (int)(st->flags / PROTO_F_PAD_LIFTED0) & 15;
    w->stab_margin = st->stab_margin;
    w->ncoll = 0;
    memset(s->remote_row, 0, sizeof s->remote_row);
    // A chain's row is longer than SIM_NCOL: every channel the frame carries
    // (up to PROTO_MAX_ROW) reaches the charts, readouts and the record.
    s->remote_nrow = st->nrow < PROTO_MAX_ROW ? st->nrow : PROTO_MAX_ROW;
    memcpy(s->remote_row, st->row, (size_t)s->remote_nrow * sizeof(double));
    s->remote_fed = true;
    s->st.sim_time = w->t;
    char note[192];
    if (render_pad_event(w, &s->pad_lifted, note, sizeof note)) fprintf(stderr, "cranesim drive: %s\n", note);
    // The charts take every state frame (a local drive samples every drawn
    // frame): the remote's own time axis, no frame left out.
    if (s->nchart) {
        for (int i = 0; i < s->nchart; ++i)
            if (s->chart_col[i] >= 0 && s->chart_col[i] < s->remote_nrow)
                chart_push(s, i, w->t, s->remote_row[s->chart_col[i]]);
    } else {
        render_charts_sample(s->r, w);
    }
    if (s->nreadout)
        for (int i = 0; i < s->nreadout; ++i) {
            const int k = s->readout_col[i];
            s->chan_v[k >= 0 ? k : 0] = k >= 0 && k < s->remote_nrow ? s->remote_row[k] : NAN;
        }
}

// drive_remote_input holds every function a mapping can drive, by its name.
_Static_assert(INPUT_MAX_FN <= (int)(sizeof((drive_remote_input*)0)->u / sizeof(double)), "drive_remote_input.u");
_Static_assert(sizeof((drive_remote_input*)0)->name[0] >= sizeof((input_axis_map*)0)->name, "drive_remote_input.name");

int drive_session_remote_functions(drive_session* s, const char* const* names, int n, bool model_controls,
                                   char* err, size_t errsz) {
    const input_mapping* cur = input_get_mapping(s->in);
    bool same = s->remote_mapped && cur->naxis == n;
    for (int k = 0; same && k < n; ++k) same = !strcmp(cur->axis[k].name, names[k]);
    if (same) return 0; // a reconnection: held keys and ramps go on
    input_mapping map;
    char e[400];
    if (build_mapping_for(s, names, n, model_controls ? s->m->controls : NULL, "the server's crane", &map, e,
                          sizeof e)) {
        snprintf(err, errsz, "input mapping for the server's functions: %s", e);
        return -1;
    }
    input_set_mapping(s->in, &map);
    show_mapping(s, &map, model_controls && s->m->controls);
    s->remote_mapped = true;
    s->rin.n = 0; // no command until the next tick reads the new mapping
    return 0;
}

void drive_session_remote_input(drive_session* s, drive_remote_input* in) {
    *in = s->rin;
    s->rin.hook = s->rin.pause = s->rin.reset = -1; // requests are taken once
}

void drive_session_set_link(drive_session* s, const char* text, const char* down) { render_set_link(s->r, text, down); }

double drive_session_time(const drive_session* s) {
    return s->remote ? s->snap->t : s->t_base + engine_time(s->l);
}

const char* drive_session_status_line(const drive_session* s) { return render_get_status(s->r); }

double drive_session_rt_factor(const drive_session* s) {
    // The current piece only, and only the time it ran: a pause holds the
    // simulated time, so counting it would read "cannot keep up" too.
    const double run = s->wall_last - s->piece_wall0 - s->piece_paused;
    return run >= DRIVE_MIN_RATE_S ? engine_time(s->l) / run : 0.0;
}

void drive_session_render(drive_session* s) {
    take_snapshot(s);
    render_snapshot(s);
}

int drive_session_screenshot(drive_session* s, const char* png, char* err, size_t errsz) {
    return render_save_png(s->r, png, err, errsz);
}

const world_snapshot* drive_session_snapshot(const drive_session* s) { return s->snap; }

// Esc out of the panel quits; with panel changes not saved, the first Esc
// says which and how to keep them, and only a second one within
// DRIVE_QUIT_CONFIRM_S quits.
static bool quit_confirmed(drive_session* s, double wall) {
    if (!s->unsaved || (s->esc_armed >= 0 && wall - s->esc_armed <= DRIVE_QUIT_CONFIRM_S)) return true;
    s->esc_armed = wall;
    snprintf(s->status, sizeof s->status, "%d panel change%s not saved (%s): Esc again quits without %s, "
             "the panel's \"save model\" keeps %s", s->unsaved, s->unsaved == 1 ? "" : "s", s->unsaved_names,
             s->unsaved == 1 ? "it" : "them", s->unsaved == 1 ? "it" : "them");
    return false;
}

int drive_session_tick(drive_session* s, double wall) {
    double dt_wall = wall - s->wall_last;
    if (dt_wall < 0) dt_wall = 0;
    s->wall_last = wall;
    s->st.wall_time = wall;

    // Events: devices (hot-plug, keys), camera and panel, window close.
    SDL_Event ev;
    bool quit = false;
    while (SDL_PollEvent(&ev)) {
        if (ev.type == SDL_QUIT) quit = true;
        if (ev.type == SDL_KEYDOWN && ev.key.keysym.scancode == SDL_SCANCODE_TAB && !ev.key.repeat) {
            panel_gui_show(s->pn, !panel_gui_visible(s->pn));
            continue;
        }
        if (ev.type == SDL_KEYDOWN && ev.key.keysym.scancode == SDL_SCANCODE_F5 && !ev.key.repeat) {
            if (s->rec) {
                stop_recording(s); // says "stopped" or "failed" in the status line
            } else {
                char path[64];
                snprintf(path, sizeof path, "cranesim_record_%ld.csv", (long)time(NULL));
                // On failure it says so in the status line.
                if (start_recording(s, path) == 0) snprintf(s->status, sizeof s->status, "recording to %s", path);
            }
            continue;
        }
        if (ev.type == SDL_KEYDOWN && ev.key.keysym.scancode == SDL_SCANCODE_ESCAPE) {
            if (ev.key.repeat) continue; // a held Esc is one Esc
            // Esc in the panel (its window clicked, dragged in or typed in)
            // only leaves the panel: ImGui drops a value being typed, and the
            // panel gives the keyboard back at its next frame. It quit the
            // drive at once, and the panel's edits with it.
            if (panel_gui_has_focus(s->pn) || panel_gui_wants_keyboard(s->pn)) {
                render_handle_event(s->r, &ev);
                continue;
            }
            if (!quit_confirmed(s, wall)) continue;
        }
        // The panel may take an event (typing a value); a key release still
        // goes to the input layer, or a crane axis held when the panel took
        // focus would stay held.
        if (render_handle_event(s->r, &ev) && ev.type != SDL_KEYUP) continue;
        input_handle_event(s->in, &ev);
    }
    input_command cmd;
    input_poll(s->in, dt_wall, &cmd);
    if (cmd.quit) quit = true;
    if (s->remote) { // the server pauses and resets: asked once, by drive_connect
        if (cmd.pause) s->rin.pause = 1;
        if (cmd.reset) s->rin.reset = 1;
    } else {
        if (cmd.pause) s->paused = !s->paused;
        if (cmd.reset) act_reset(s); // ends the session file
    }
    if (cmd.mapping_box) {
        render_show_mapping(s->r, !render_mapping_shown(s->r));
        s->mapbox_off = -1; // the operator decides from now on
    }
    if (s->mapbox_off >= 0 && wall >= s->mapbox_off) {
        render_show_mapping(s->r, false);
        s->mapbox_off = -1;
    }
    if (cmd.camera_next) render_set_camera_preset(s->r, (render_get_camera_preset(s->r) + 1) % RENDER_CAM_COUNT);
    if (cmd.camera_preset >= 0) render_set_camera_preset(s->r, (render_cam_preset)cmd.camera_preset);
    if (cmd.screenshot) {
        char path[64], e[320];
        snprintf(path, sizeof path, "cranesim_%ld.png", (long)time(NULL));
        if (render_save_png(s->r, path, e, sizeof e)) snprintf(s->status, sizeof s->status, "screenshot failed: %s", e);
        else snprintf(s->status, sizeof s->status, "saved %s", path);
    }
    // Every change of this tick first, then applied one by one: applying one
    // refreshes the mechanics entries it moves (a length scales its link's
    // centre of mass), which must not undo another entry's new value.
    int nchanged = 0;
    for (int id; (id = panel_next_changed(s->pn)) >= 0;)
        for (int i = 0; i < s->nparam; ++i)
            if (s->pid[i] == id) {
                s->changed[nchanged].i = i;
                s->changed[nchanged++].v = s->param[i].value;
            }
    if (nchanged) session_end(s, "a panel change");
    for (int k = 0; k < nchanged; ++k) {
        s->param[s->changed[k].i].value = s->changed[k].v;
        apply_param(s, s->changed[k].i); // a rejection says so in the status line
    }
    if (s->load_pending) {
        s->load_pending = false;
        session_end(s, "a model loaded");
        load_model(s);
    }
    if (s->rebuild) {
        s->rebuild = false;
        session_end(s, "a rebuild");
        const double t_at = s->t_base + engine_time(s->l);
        const int seg = s->segment;
        rebuild_world(s, false);
        // Say it: a rebuild puts the loads back and is a new segment of the
        // record.
        if (s->segment != seg) {
            char seg_note[48] = "";
            if (s->rec) snprintf(seg_note, sizeof seg_note, " (record segment %d)", s->segment - s->rec_seg0);
            snprintf(s->status, sizeof s->status, "%s: world rebuilt at t = %.2f s%s%s", s->rebuild_why, t_at,
                     engine_load_name(s->l, 0, NULL) ? ", loads back at their start" : "", seg_note);
            ++s->st.rebuilds;
        }
    }

    double t = engine_time(s->l);
    if (s->remote) {
        // The sticks (or the script, which drive_connect plays at the remote
        // time) go to the server; nothing steps here.
        // One command per function of the mapping (the server's functions
        // once its hello came: drive_session_remote_functions), by name.
        const input_mapping* im = input_get_mapping(s->in);
        s->rin.n = cmd.n < im->naxis ? cmd.n : im->naxis;
        for (int k = 0; k < s->rin.n; ++k) {
            s->rin.u[k] = cmd.u[k];
            snprintf(s->rin.name[k], sizeof s->rin.name[k], "%s", im->axis[k].name);
        }
        if (cmd.hook_toggle) s->rin.hook = !s->snap->attached;
        ++s->st.input_samples;
    } else if (s->paused) {
        // Hold simulated time: the clock offset grows with the paused time.
        s->sim_offset += dt_wall;
        s->piece_paused += dt_wall;
        s->st.paused_time += dt_wall;
    } else if (s->rp) {
        // Replay: every recorded tick due by wall time, applied as the drive
        // applied it (hooks, commands, the same advance), so the world moves
        // bit for bit as recorded; at its end the window closes.
        const double due = wall - s->sim_offset;
        while (s->rp_next < s->rp->ntick && s->rp->tick[s->rp_next].target <= due) {
            const session_tick* tk = &s->rp->tick[s->rp_next];
            for (int k = 0; k < tk->nhook; ++k) engine_hook(s->l, tk->hook[k]);
            const int nfn = engine_nfunction(s->l);
            session_tick_commands(s->rp, s->rp_next++, s->rp_map, nfn, s->rp_u);
            if (engine_caps(s->l) & ENGINE_CAP_TWO_LINK) engine_set_commands(s->l, s->rp_u);
            else engine_set_function_commands(s->l, s->rp_u, nfn, NULL, 0);
            ++s->st.input_samples;
            const double now = engine_time(s->l);
            if (tk->target > now && engine_advance(s->l, tk->target - now)) {
                snprintf(s->err, sizeof s->err, "%s", engine_error(s->l));
                return -1;
            }
        }
        if (s->rp_next >= s->rp->ntick) quit = true;
    } else {
        double u[3] = {cmd.lift, cmd.jib, cmd.slew};
        // A crane chain's scenario commands every function by name; the
        // operator's input drives every function by the mapping (input.h).
        const bool by_function = !(engine_caps(s->l) & ENGINE_CAP_TWO_LINK);
        if (s->o.scripted && by_function) {
            engine_play_functions(s->l, &s->sc, s->t_base + t + 0.5 * dt_wall, &s->ev, s->ufn,
                                  s->sw.f ? session_hook : NULL, s);
        } else if (s->o.scripted) {
            engine_play(s->l, &s->sc, s->t_base + t + 0.5 * dt_wall, &s->ev, u, s->sw.f ? session_hook : NULL, s);
        } else if (cmd.hook_toggle) {
            const int want = !engine_attached(s->l); // what H asks; a failed attach is said on the console too
            session_writer_hook(&s->sw, want);
            if (engine_hook_report(s->l, want, s->status, sizeof s->status) < 0 && want)
                fprintf(stderr, "cranesim drive: %s\n", s->status);
        }
        if (s->o.scripted && by_function) {
            engine_set_function_commands(s->l, s->ufn, engine_nfunction(s->l), NULL, 0);
        } else if (by_function) {
            // The operator's commands by function: the mapping was built from
            // engine_nfunction's list (build_mapping), so cmd.u[k] is function k.
            char fe[200];
            if (engine_set_function_commands(s->l, cmd.u, cmd.n, fe, sizeof fe))
                snprintf(s->status, sizeof s->status, "input: %s", fe);
        } else {
            engine_set_commands(s->l, u);
        }
        ++s->st.input_samples;
        // Keep simulated time on wall time. More than 0.1 s behind means the
        // machine cannot keep up: count it and let the clock slip rather than
        // run a long catch-up burst the operator would feel.
        double target = wall - s->sim_offset;
        if (target - t > 0.1) {
            ++s->st.missed;
            ++s->missed_window;
            s->sim_offset += target - t - 0.1;
            target = t + 0.1;
        }
        const int adv = target > t ? engine_advance(s->l, target - t) : 0;
        if (s->sw.f) {
            // The tick, and the row the record keeps after it (one per
            // simulated instant, as record_row; `segment` 0).
            double* r = s->row; // ncol + 1 columns (size_buffers): a chain's row is longer than SIM_NCOL
            session_row(s, r);
            const bool keep = !adv && (s->sw.rows == 0 || r[COL_T] > s->sw.t_last);
            if (keep) s->sw.t_last = r[COL_T];
            r[s->ncol] = 0;
            // The commands as the engine holds them, one per function
            // (session.h): the sticks' lift, jib, slew on the two-link crane.
            session_writer_tick_engine(&s->sw, s->l, s->t_base + t + 0.5 * dt_wall, target, keep ? r : NULL,
                                       s->ncol + 1);
        }
        if (adv) {
            snprintf(s->err, sizeof s->err, "%s", engine_error(s->l));
            return -1;
        }
    }
    if (!s->remote) s->st.sim_time = s->sim_done + engine_time(s->l);
    if (wall - s->missed_t0 >= 1.0) {
        render_set_missed_deadlines(s->r, s->missed_window);
        s->missed_window = 0;
        s->missed_t0 = wall;
    }
    // A frame is due, and the driver has finished the last one: starting a
    // frame while llvmpipe still draws earlier ones blocks inside the GL
    // calls until its scene queue drains (40-100 ms at 720p), and no physics
    // or input runs meanwhile. Waiting here instead keeps the 240 Hz ticks.
    const bool frame = wall >= s->wall_next_frame && !render_busy(s->r);
    // One CSV row per tick at most, shared by the recording and the charts.
    double* row = s->row;
    if (s->rec || (frame && (s->nchart || s->nreadout))) session_row(s, row);
    if (frame && (s->nchart || s->nreadout) && !s->remote) {
        memcpy(s->chan_v, row, sizeof *row * (size_t)chan_list_nrow(s->chans));
        if (s->chart_circuit) chan_list_values(s->chans, s->l, s->chan_v, true);
    }
    // A remote view records the server's states only: before the first one
    // its row is all zeros (no crane has 0 Pa in a chamber at t = 0).
    if (s->rec && (!s->remote || s->remote_fed)) record_row(s, row);
    if (frame) {
        char status[640];
        // Who drives: the scenario, a named device, or the keyboard alone.
        // A replay is driven by the session's recorded commands, not by the
        // scenario: it says which session.
        char rp_src[160] = "";
        if (s->rp) {
            const char* base = strrchr(s->rp->path, '/');
            snprintf(rp_src, sizeof rp_src, "  [replay of %.120s]", base ? base + 1 : s->rp->path);
        }
        const char* src = s->rp ? rp_src : s->o.scripted ? "  [scripted]" : input_device_name(s->in) ? "" : "  [keyboard]";
        // While a value is typed the keys go to the panel, not the crane:
        // say so where the operator looks.
        const char* keys = panel_gui_wants_keyboard(s->pn) ? "  [keys: panel - Enter/Esc gives them back]" : "";
        snprintf(status, sizeof status, "%s%s%s%s%s%s", s->paused ? "PAUSED  " : "", s->rec ? "REC  " : "", s->status,
                 src, panel_gui_visible(s->pn) || s->remote ? "" : "  [Tab: parameters]", keys);
        render_set_status(s->r, status);
        take_snapshot(s);
        if (s->nreadout) {
            render_readout rd[8];
            for (int i = 0; i < s->nreadout; ++i) {
                const int k = s->readout_col[i];
                // No value: a channel a loaded model lacks, or (remote) a
                // circuit channel, which the state frames do not carry.
                const bool unsent = s->remote && (!s->remote_fed || k < 0 || k >= s->remote_nrow);
                rd[i] = (render_readout){s->readout_name[i],
                                         !unsent ? (k < 0 ? "not in this model" : s->readout_unit[i])
                                         : s->remote_fed ? "not sent" : "waiting",
                                         k >= 0 && !unsent ? s->chan_v[k] / s->readout_scale[i] : NAN};
            }
            render_set_readouts(s->r, rd, s->nreadout);
        }
        if (s->remote) {
            // drive_session_feed sampled the charts with every state
        } else if (s->nchart) {
            for (int i = 0; i < s->nchart; ++i)
                if (s->chart_col[i] >= 0) chart_push(s, i, row[COL_T], s->chan_v[s->chart_col[i]]);
        } else
            render_charts_sample(s->r, s->snap);
        render_snapshot(s);
        // Interval between frame starts; the first frame has none.
        if (s->wall_last_frame >= 0.0) s->st.frame_ms[s->st.nframe_ms++ % 4096] = 1e3 * (wall - s->wall_last_frame);
        s->wall_last_frame = wall;
        s->wall_next_frame += 1.0 / s->o.fps_cap;
        if (s->wall_next_frame < wall) s->wall_next_frame = wall; // do not queue up frames
    }
    return quit ? 1 : 0;
}

void drive_session_idle(drive_session* s, double left) {
    if (left <= 0) return;
    // While a frame is in flight, sleep on it rather than for a fixed time:
    // if the driver finishes early, the next tick can start the next frame.
    if (render_busy(s->r)) render_wait(s->r, left);
    else SDL_Delay((Uint32)(left * 1e3));
}

const char* drive_session_error(const drive_session* s) { return s->err; }
const drive_stats* drive_session_stats(const drive_session* s) { return &s->st; }
engine* drive_session_engine(drive_session* s) { return s->l; }
const model* drive_session_model(const drive_session* s) { return s->m; }
render* drive_session_render_ctx(drive_session* s) { return s->r; }
input* drive_session_input(drive_session* s) { return s->in; }
panel* drive_session_panel(drive_session* s) { return s->pn; }
void drive_session_row(drive_session* s, double* row) { session_row(s, row); }
const chan_list* drive_session_channels(const drive_session* s) { return s->chans; }

// "%.1f fps" of n events over wall seconds, or "n/a" when the interval is too
// short for a rate to mean anything (a screenshot at t = 0).
static const char* rate_str(char* buf, size_t n, double count, double wall, const char* fmt) {
    if (wall >= DRIVE_MIN_RATE_S) snprintf(buf, n, fmt, count / wall);
    else snprintf(buf, n, "n/a");
    return buf;
}

int drive_window_main(const app_common* c, const drive_opts* o, double duration, const char* screenshot,
                      double screenshot_at, char* no_window, size_t no_window_sz) {
    char err[512];
    int code;
    drive_session* s = drive_session_create(c, o, err, sizeof err, &code);
    if (!s) {
        if (code == DRIVE_NO_WINDOW) {
            snprintf(no_window, no_window_sz, "%s", err);
            return code;
        }
        fprintf(stderr, "cranesim drive: %s\n", err);
        return code;
    }
    char where[96];
    const engine_backend* be = app_backend(&c->sim);
    if (!be->world) snprintf(where, sizeof where, "the %s view", be->crane);
    else snprintf(where, sizeof where, "the %s world", o->world_name ? o->world_name : be->drive_world);
    printf("cranesim drive: %s in %s%s; %s%s%s\n", s->m->name, where, o->offscreen ? " (offscreen)" : "",
           o->replay_path ? "replaying " : "", o->replay_path ? o->replay_path : o->scripted ? "scripted operator" : "joystick or keyboard (arrows/WS/AD, H hook, Tab parameters, P pause, "
                                               "R reset, C camera, F5 record, F12 screenshot, Esc quit)",
           !s->rp ? ""
           : o->replay_rcl >= 0 ? (s->c.sim.rcl ? ", rated capacity limiter on (--rcl)" : ", rated capacity limiter off (--rcl)")
           : s->rp->rcl_recorded ? (s->c.sim.rcl ? ", rated capacity limiter on as recorded" : ", rated capacity limiter off as recorded")
                                 : ", rated capacity limiter on (the session does not record its setting)");
    // Ticks at 240 Hz: between rendered frames the loop still pumps events,
    // reads the sticks and commands the valves, so commands run faster than
    // frames (>= 75 Hz, the paper's rate, even while a frame takes 12 ms).
    const double tick = 1.0 / 240.0;
    const uint64_t f = SDL_GetPerformanceFrequency(), t0 = SDL_GetPerformanceCounter();
    code = 0;
    bool shot_done = false;
    for (;;) {
        double wall = (double)(SDL_GetPerformanceCounter() - t0) / (double)f;
        int rc = drive_session_tick(s, wall);
        if (rc < 0) {
            fprintf(stderr, "cranesim drive: %s\n", drive_session_error(s));
            code = EXIT_RUNTIME;
            break;
        }
        if (screenshot && !shot_done && s->t_base + engine_time(s->l) >= screenshot_at) {
            drive_session_render(s);
            if (drive_session_screenshot(s, screenshot, err, sizeof err)) {
                fprintf(stderr, "cranesim drive: %s\n", err);
                code = EXIT_RUNTIME;
            } else {
                printf("  screenshot -> %s\n", screenshot);
            }
            shot_done = true;
            if (duration <= 0) break;
        }
        if (rc > 0 || (duration > 0 && wall >= duration)) break;
        double next = (double)(SDL_GetPerformanceCounter() - t0) / (double)f;
        drive_session_idle(s, wall + tick - next);
    }
    const drive_stats* st = drive_session_stats(s);
    char fps[32], hz[32];
    // Simulated time over every piece (resets, rebuilds); paused wall time
    // said, so the two figures can be compared.
    char extra[96] = "";
    if (st->paused_time > 0 || s->segment > 0)
        snprintf(extra, sizeof extra, " (%.2f s of it paused; %d resets or rebuilds)", st->paused_time, s->segment);
    printf("  simulated %.2f s in %.2f s wall%s; %ld frames (%s fps), %ld command updates (%s Hz), missed %ld; "
           "%ld triangles\n",
           st->sim_time, st->wall_time, extra, st->frames, rate_str(fps, sizeof fps, (double)st->frames, st->wall_time, "%.1f"),
           st->input_samples, rate_str(hz, sizeof hz, (double)st->input_samples, st->wall_time, "%.0f"), st->missed,
           st->triangles);
    if (o->session_path) {
        session_end(s, "the window closed");
        if (s->sess_err) {
            fprintf(stderr, "cranesim drive: cannot write %s: %s\n", o->session_path, strerror(s->sess_err));
            code = EXIT_RUNTIME;
        } else {
            printf("  session -> %s (%ld rows, %s)\n", o->session_path, s->sw.rows, s->sess_end);
        }
    }
    if (s->rp)
        printf("  replayed %ld of %ld command updates of %s\n", s->rp_next, s->rp->ntick, s->rp->path);
    if (s->unsaved) // closed by Esc twice, the window's close button or a signal
        fprintf(stderr, "cranesim drive: quit with %d panel change%s not saved: %s\n", s->unsaved,
                s->unsaved == 1 ? "" : "s", s->unsaved_names);
    long rows = 0;
    if (drive_session_finish_record(s, &rows, err, sizeof err)) {
        fprintf(stderr, "cranesim drive: %s\n", err);
        code = EXIT_RUNTIME;
    } else if (s->rec_path[0]) {
        printf("  record -> %s (%ld rows)\n", s->rec_path, rows);
    }
    drive_session_destroy(s);
    return code;
}

// Process CPU time, all threads (llvmpipe's rasterisers too) [s].
static double process_cpu_s(void) {
    struct timespec t;
    return clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) ? 0.0 : (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int drive_bench(const app_common* c, int w, int h, double seconds, const char* config, double* fps_mean,
                double* cpu_ms) {
    if (fps_mean) *fps_mean = 0;
    if (cpu_ms) *cpu_ms = 0;
    drive_opts o = drive_default_opts();
    o.width = w;
    o.height = h;
    o.offscreen = true;
    o.scripted = true;
    o.fps_cap = 1000; // uncapped: measure what the renderer can do
    char err[512];
    int code;
    drive_session* s = drive_session_create(c, &o, err, sizeof err, &code);
    if (!s) {
        printf("{\"config\":\"%s\",\"error\":\"%s\"}\n", config, err);
        return code;
    }
    // The same 240 Hz ticks as the window loop. Spinning instead would take
    // a core from the driver's rasteriser threads on a small machine.
    const double tick = 1.0 / 240.0;
    const uint64_t f = SDL_GetPerformanceFrequency(), t0 = SDL_GetPerformanceCounter();
    // CPU per frame does not depend on what else the machine runs (the fps
    // does): the figure to compare runs by on a loaded machine.
    const double cpu0 = process_cpu_s();
    code = 0;
    for (;;) {
        double wall = (double)(SDL_GetPerformanceCounter() - t0) / (double)f;
        if (wall >= seconds) break;
        if (drive_session_tick(s, wall) < 0) {
            code = EXIT_RUNTIME;
            break;
        }
        double next = (double)(SDL_GetPerformanceCounter() - t0) / (double)f;
        drive_session_idle(s, wall + tick - next);
    }
    const drive_stats* st = drive_session_stats(s);
    const double cpu_frame = st->frames > 0 ? 1e3 * (process_cpu_s() - cpu0) / (double)st->frames : 0.0;
    // The world the engine was built on (c->sim.world, the sandbox when
    // none is named), and the bodies of its last snapshot, so a reader can
    // tell the worlds apart by what ran, not only by name.
    const engine_backend* be = app_backend(&c->sim);
    const char* world = !be->world ? be->name : c->sim.world ? c->sim.world : be->drive_world;
    take_snapshot(s);
    int n = st->nframe_ms < 4096 ? st->nframe_ms : 4096;
    double* ms = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
    // Skip the first frames (shader compilation, mesh upload).
    int skip = n > 20 ? 10 : 0, m = 0;
    for (int i = skip; i < n; ++i) ms[m++] = st->frame_ms[i];
    app_sort(ms, m);
    double p50 = m ? ms[m / 2] : 0, p95 = m ? ms[(int)(0.95 * (m - 1))] : 0;
    // The model file's name, JSON-safe (a quote, backslash or control
    // character in it would end the string: '_' instead).
    char mname[256];
    const char* base = s->m->file[0] ? s->m->file : s->m->name;
    if (strrchr(base, '/')) base = strrchr(base, '/') + 1;
    snprintf(mname, sizeof mname, "%s", base);
    for (char* q = mname; *q; ++q)
        if (*q == '"' || *q == '\\' || (unsigned char)*q < 0x20) *q = '_';
    printf("{\"config\":\"%s\",\"model\":\"%s\",\"width\":%d,\"height\":%d,\"world\":\"%s\",\"wall_s\":%.3f,"
           "\"sim_time_s\":%.3f,\"rt_factor\":%.3f,\"frames\":%ld,\"fps_mean\":%.1f,\"fps_median\":%.1f,"
           "\"fps_p5\":%.1f,\"frame_ms_p50\":%.2f,\"frame_ms_p95\":%.2f,\"missed_deadlines\":%ld,"
           "\"command_rate_hz\":%.1f,\"cpu_ms_per_frame\":%.1f,\"triangles\":%ld,\"bodies\":%d%s}\n",
           config, mname, w, h, world, st->wall_time, st->sim_time,
           st->wall_time > 0 ? st->sim_time / st->wall_time : 0, st->frames,
           st->wall_time > 0 ? st->frames / st->wall_time : 0, p50 > 0 ? 1e3 / p50 : 0, p95 > 0 ? 1e3 / p95 : 0,
           p50, p95, st->missed, st->wall_time > 0 ? st->input_samples / st->wall_time : 0, cpu_frame, st->triangles,
           s->snap->nbody, code ? ",\"error\":\"numerical failure\"" : "");
    fflush(stdout);
    if (fps_mean && !code && st->wall_time > 0) *fps_mean = st->frames / st->wall_time;
    if (cpu_ms && !code) *cpu_ms = cpu_frame;
    free(ms);
    drive_session_destroy(s);
    return code;
}
