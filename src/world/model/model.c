// model.c: load and validate a crane model file.
#include "model.h"
#include "model_chain.h"
#include "param_names.h"

#include "chain_crane.h"
#include "hydraulics.h"
#include "json_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef CRANESIM_ASSETS_DIR
#define CRANESIM_ASSETS_DIR "assets"
#endif

const char* model_assets_dir(void) {
    const char* env = getenv("CRANESIM_ASSETS");
    if (env && *env) return env;
    // The source tree's assets are compiled in so a freshly built binary finds
    // its defaults from any working directory.
    if (access(CRANESIM_ASSETS_DIR "/models/hiab031.json", R_OK) == 0) return CRANESIM_ASSETS_DIR;
    return "assets";
}

const char* model_default_path(void) {
    static char path[512]; // written once per call from constant inputs
    snprintf(path, sizeof path, "%s/models/hiab031.json", model_assets_dir());
    return path;
}

// Hard and typical ranges of the mechanical values (docs/model.md, "Value
// ranges"). Hard: outside it a value is a typo or a unit slip that the
// integrators meet as an abort or a plausible wrong answer (a link mass of
// 1e-300 kg aborted ODE); typical: a crane of the HIAB 031 class and its
// relatives up to a few tonnes of lifting capacity.
// The LS signal must reach each LS pump: its "ls" node is a tank (a fixed
// signal), the output of a shuttle, or a work line itself (a node a valve,
// hose or cylinder has a port on or owns). A volume fed by nothing of that
// kind (only the pump, a bleed) would hold the pump at its margin above tank
// pressure whatever the loads: a wiring mistake, not a design. Returns the
// component index of the first such pump, or -1. (Checked for crane
// models only: the component tests build LS pumps on held volumes.)
static int ls_unreached(const hyd_model* m) {
    const int nc = hyd_model_ncomp(m);
    for (int c = 0; c < nc; ++c) {
        if (hyd_model_comp_type(m, c) != HYD_LS_PUMP) continue;
        const int ls = hyd_model_port_node(m, c, 2);
        if (ls < 0 || hyd_model_node_role(m, ls) == HYD_NODE_TANK) continue;
        const int own = hyd_model_node_owner(m, ls);
        int reached = own >= 0 && hyd_model_comp_type(m, own) != HYD_LS_PUMP;
        for (int k = 0; k < nc && !reached; ++k) {
            const hyd_type t = hyd_model_comp_type(m, k);
            if (t == HYD_SHUTTLE) reached = hyd_model_port_node(m, k, 2) == ls;
            else if (t == HYD_VALVE || t == HYD_HOSE || t == HYD_CYLINDER)
                for (int j = 0; j < 4 && !reached; ++j) reached = hyd_model_port_node(m, k, j) == ls;
        }
        if (!reached) return c;
    }
    return -1;
}

// Whether the signal at node n reaches node target through the LS network:
// n is target, or a shuttle has n as its port a or b and its out reaches
// target (a chain of shuttles, either mode). seen: nnode bytes, cleared by
// the caller.
static int ls_reaches(const hyd_model* m, int n, int target, unsigned char* seen) {
    if (n == target) return 1;
    if (n < 0 || seen[n]) return 0;
    seen[n] = 1;
    const int nc = hyd_model_ncomp(m);
    for (int k = 0; k < nc; ++k) {
        if (hyd_model_comp_type(m, k) != HYD_SHUTTLE) continue;
        if (hyd_model_port_node(m, k, 0) != n && hyd_model_port_node(m, k, 1) != n) continue;
        if (ls_reaches(m, hyd_model_port_node(m, k, 2), target, seen)) return 1;
    }
    return 0;
}

// The LS pump a section's signal must reach: the one whose outlet feeds the
// compensator's inlet (comp >= 0), else the first LS pump; -1 when none.
static int ls_pump_for(const hyd_model* m, int comp) {
    const int nc = hyd_model_ncomp(m);
    int first = -1;
    for (int c = 0; c < nc; ++c) {
        if (hyd_model_comp_type(m, c) != HYD_LS_PUMP) continue;
        if (first < 0) first = c;
        if (comp >= 0 && hyd_model_port_node(m, c, 1) == hyd_model_port_node(m, comp, 0)) return c;
    }
    return first;
}

// Every section's LS signal must reach the pump, not only the pump's own ls
// node be fed (ls_unreached): a section shuttle (spool mode: the section's
// LS port) whose out, or a compensator whose load, leads through no chain of
// shuttles to the pump's ls node is a section the pump never senses, and it
// stalls at the standby pressure under load. A post compensator's ref must
// be that ls node itself: it holds p_pump - p_ref - setting across the
// metering edge, so a ref on the tank or an orphaned node gives a drop of
// about the whole pump pressure (no flow control at all). A pre compensator
// (mode 0) does not use ref. Fails c with one line and returns 1, or 0.
static int ls_section_fault(json_ctx* c, const hyd_model* m) {
    const int nc = hyd_model_ncomp(m), nn = hyd_model_nnode(m);
    unsigned char* seen = calloc((size_t)(nn > 0 ? nn : 1), 1);
    if (!seen) return 0;
    int bad = 0;
    for (int k = 0; k < nc && !bad; ++k) {
        const hyd_type t = hyd_model_comp_type(m, k);
        const int spool_shuttle = t == HYD_SHUTTLE && hyd_model_port_node(m, k, 3) >= 0;
        if (!spool_shuttle && t != HYD_COMPENSATOR) continue;
        const int pump = ls_pump_for(m, t == HYD_COMPENSATOR ? k : -1);
        if (pump < 0) break;
        const int ls = hyd_model_port_node(m, pump, 2);
        const char* lsname = hyd_model_node_name(m, ls);
        char f[80];
        const int sig = hyd_model_port_node(m, k, 2); // shuttle out, compensator load
        memset(seen, 0, (size_t)nn);
        if (!ls_reaches(m, sig, ls, seen)) {
            snprintf(f, sizeof f, "hydraulics.components[%d].%s", k, spool_shuttle ? "out" : "load");
            json_fail(c, f, "node '%s' leads through no shuttle to the ls node '%s' of pump '%s': the pump never senses this section's load",
                      hyd_model_node_name(m, sig), lsname, hyd_model_comp_name(m, pump));
            bad = 1;
            break;
        }
        if (t != HYD_COMPENSATOR) continue;
        char path[160];
        double mode = 1.0;
        snprintf(path, sizeof path, "%s.mode", hyd_model_comp_name(m, k));
        hyd_model_get(m, path, &mode);
        const int ref = hyd_model_port_node(m, k, 3);
        if (mode != 0.0 && ref != ls) {
            snprintf(f, sizeof f, "hydraulics.components[%d].ref", k);
            json_fail(c, f, "must be the ls node '%s' of pump '%s' (a post compensator holds p_pump - p_ref - setting), got '%s'",
                      lsname, hyd_model_comp_name(m, pump), hyd_model_node_name(m, ref));
            bad = 1;
        }
    }
    free(seen);
    return bad;
}

// Whether port k of a component of type t can put oil into its node: an
// outlet of a pump, relief, check or compensator, either end of an orifice,
// hose, counterbalance valve or accumulator, and a valve's T, A or B (a
// series circuit feeds one valve from another's work port). Not: a valve's
// P (it draws from it), an inlet, and the signal ports of shuttles, LS
// pumps, compensators and counterbalance pilots.
static int port_feeds(hyd_type t, int k) {
    switch (t) {
    case HYD_PUMP:
    case HYD_LS_PUMP:
    case HYD_RELIEF:
    case HYD_CHECK:
    case HYD_COMPENSATOR: return k == 1;
    case HYD_ORIFICE:
    case HYD_HOSE:
    case HYD_ACCUMULATOR: return 1;
    case HYD_COUNTERBALANCE: return k == 0 || k == 1;
    case HYD_VALVE: return k != 0;
    default: return 0;
    }
}

// A valve's P must be fed: a node that only valves draw from (and reliefs
// drain) holds whatever it had at the start, so the valve has no supply and
// its cylinder moves only by that trapped oil. That is the load-sensing
// crane with its compensators deleted: a wiring mistake, never a design.
// A node a component owns (a hose's volume, a chamber) is fed by it; the
// tank is a fixed pressure. Returns the first such valve, or -1.
static int valve_unfed(const hyd_model* m) {
    const int nc = hyd_model_ncomp(m);
    for (int v = 0; v < nc; ++v) {
        if (hyd_model_comp_type(m, v) != HYD_VALVE) continue;
        const int p = hyd_model_port_node(m, v, 0);
        if (p < 0 || hyd_model_node_role(m, p) == HYD_NODE_TANK || hyd_model_node_owner(m, p) >= 0) continue;
        int fed = 0;
        for (int k = 0; k < nc && !fed; ++k)
            for (int j = 0; j < 4 && !fed; ++j)
                fed = hyd_model_port_node(m, k, j) == p && port_feeds(hyd_model_comp_type(m, k), j);
        if (!fed) return v;
    }
    return -1;
}

static double comp_param(const hyd_model* m, int comp, const char* field) {
    char path[160];
    double v = NAN;
    snprintf(path, sizeof path, "%s.%s", hyd_model_comp_name(m, comp), field);
    hyd_model_get(m, path, &v);
    return v;
}

// Parameter sets that are each in range but do not fit together, as notes
// (the run goes on): a relief on a LS pump's outlet that cracks below the
// pump's cut-off plus its band opens before the pump destrokes and burns the
// whole delivery at the relief (the cut-off is there to make that
// unnecessary); a post compensator whose setting is not below the pump's
// margin leaves its metering edge margin - setting <= 0, so the section
// gives no flow however far the spool opens.
static void ls_param_notes(json_ctx* c, const hyd_model* m) {
    const int nc = hyd_model_ncomp(m);
    for (int p = 0; p < nc; ++p) {
        if (hyd_model_comp_type(m, p) != HYD_LS_PUMP) continue;
        const int out = hyd_model_port_node(m, p, 1);
        const double cut = comp_param(m, p, "p_cutoff"), band = comp_param(m, p, "cutoff_band");
        const double margin = comp_param(m, p, "margin");
        for (int k = 0; k < nc; ++k) {
            char f[80], a[24], b[24], d[24];
            const hyd_type t = hyd_model_comp_type(m, k);
            if (t == HYD_RELIEF && hyd_model_port_node(m, k, 0) == out) {
                const double crack = comp_param(m, k, "p_crack");
                if (!(crack < cut + band)) continue;
                snprintf(f, sizeof f, "hydraulics.components[%d].p_crack", k);
                hyd_fmt_num(a, sizeof a, crack);
                hyd_fmt_num(b, sizeof b, cut);
                hyd_fmt_num(d, sizeof d, band);
                json_note(c, f,
                          "%s Pa is below the cut-off of LS pump '%s' plus its band (%s + %s Pa): the relief opens "
                          "before the pump destrokes and burns its delivery",
                          a, hyd_model_comp_name(m, p), b, d);
            } else if (t == HYD_COMPENSATOR && hyd_model_port_node(m, k, 0) == out && comp_param(m, k, "mode") != 0.0) {
                const double set = comp_param(m, k, "setting");
                if (!(set >= margin)) continue;
                snprintf(f, sizeof f, "hydraulics.components[%d].setting", k);
                hyd_fmt_num(a, sizeof a, set);
                hyd_fmt_num(b, sizeof b, margin);
                json_note(c, f,
                          "%s Pa is not below the margin of LS pump '%s' (%s Pa): the metering edge gets margin - "
                          "setting <= 0 and the section no flow",
                          a, hyd_model_comp_name(m, p), b);
            }
        }
    }
}

// A main relief (on a pressure-compensated pump's outlet) that cracks below
// the pump's setting plus its band opens before the pump destrokes: the
// relief, not the pump, sets the pressure, and the delivery the valves do not
// take goes over it to the tank. A note, not a refusal: that is how a fixed
// pump with a relief is modelled (a pump setting above the relief), and a
// sweep over p_crack must be able to cross the setting. The note says what
// will happen, in MPa (main relief at 5 MPa under a 20 MPa pump: open 17 s of
// the 20 s ramp, the lift pressure held near 6 MPa).
static void pump_relief_notes(json_ctx* c, const hyd_model* m) {
    const int nc = hyd_model_ncomp(m);
    for (int p = 0; p < nc; ++p) {
        if (hyd_model_comp_type(m, p) != HYD_PUMP) continue;
        const int out = hyd_model_port_node(m, p, 1);
        const double set = comp_param(m, p, "p_set"), band = comp_param(m, p, "band");
        for (int k = 0; k < nc; ++k) {
            if (hyd_model_comp_type(m, k) != HYD_RELIEF || hyd_model_port_node(m, k, 0) != out) continue;
            const double crack = comp_param(m, k, "p_crack"), over = comp_param(m, k, "dp_override");
            if (!(crack < set + band)) continue;
            char f[80];
            snprintf(f, sizeof f, "hydraulics.components[%d].p_crack", k);
            json_note(c, f,
                      "%.3g MPa is below the setting of pump '%s' plus its band (%.3g + %.3g MPa): the relief, not "
                      "the pump, limits the pressure to about %.3g MPa, and the pump's flow the valves do not take "
                      "goes over it to the tank",
                      crack / 1e6, hyd_model_comp_name(m, p), set / 1e6, band / 1e6, (crack + over) / 1e6);
        }
    }
}

const json_range MODEL_R_GRAVITY = {0, 30, 9.7, 9.9, "m/s^2"};
const json_range MODEL_R_COLUMN_HEIGHT = {0.1, 10, 0.5, 4, "m"};
const json_range MODEL_R_COLUMN_MASS = {1, 1e5, 50, 5000, "kg"};
const json_range MODEL_R_LINK_LENGTH = {0.1, 30, 0.5, 10, "m"};
const json_range MODEL_R_LINK_MASS = {1, 1e5, 20, 5000, "kg"};
const json_range MODEL_R_LINK_COM = {0, 30, 0, 10, "m"};
const json_range MODEL_R_LINK_INERTIA = {1e-3, 1e7, 1, 1e5, "kg m^2"};
const json_range MODEL_R_LINK_SECTION = {0.01, 2, 0.05, 0.6, "m"};
const json_range MODEL_R_LOAD = {0, CRANE_LOAD_MAX, 0, CRANE_LOAD_TYPICAL, "kg"};
// The maker's rating (the load chart's cap, docs/safety.md): loader cranes
// are sold from under 1 t m (10 kN m) to about 100 t m; a rated load from a
// few hundred kg to some tens of tonnes.
const json_range MODEL_R_RATED_MOMENT = {0.1, 1e4, 5, 1000, "kN m"};
const json_range MODEL_R_RATED_LOAD = {1, 1e5, 100, 30000, "kg"};
const json_range MODEL_R_MOUNT = {-10, 10, -3, 3, "m"};
const json_range MODEL_R_CLOSED_LENGTH = {0.05, 20, 0.3, 5, "m"};

static void load_link(json_ctx* c, const cJSON* arr, int i, crane_link* l) {
    char p[64];
    json_path_index(p, sizeof p, "mechanics.links", i);
    const cJSON* o = cJSON_GetArrayItem(arr, i);
    if (!cJSON_IsObject(o)) {
        json_fail(c, p, "must be an object");
        return;
    }
    static const char* const keys[] = {"name", "length", "mass", "com", "inertia", "width", "height", NULL};
    json_only_keys(c, o, p, keys);
    json_str(c, o, p, "name", false, i ? "end_arm" : "lifting_arm", l->name, sizeof l->name);
    l->length = json_num_r(c, o, p, "length", true, 0, &MODEL_R_LINK_LENGTH);
    l->mass = json_num_r(c, o, p, "mass", true, 0, &MODEL_R_LINK_MASS);
    l->com = json_num_r(c, o, p, "com", true, 0, &MODEL_R_LINK_COM);
    // A centre of mass past the link's end is a typo (a point mass beyond the
    // tip belongs in load_mass), and a zero inertia is a body ODE cannot
    // integrate (its mass matrix must be positive definite).
    char f[80];
    json_path(f, sizeof f, p, "com");
    if (!c->failed && l->com > l->length)
        json_fail(c, f, "must lie on the link (0..length %g m), got %g m", l->length, l->com);
    l->inertia = json_num_r(c, o, p, "inertia", true, 0, &MODEL_R_LINK_INERTIA);
    l->width = json_num_r(c, o, p, "width", false, 0.18, &MODEL_R_LINK_SECTION);
    l->height = json_num_r(c, o, p, "height", false, 0.24, &MODEL_R_LINK_SECTION);
    // A boom's inertia about its centre of mass is near that of a uniform
    // box, m (length^2 + height^2) / 12: a thin-walled section is at most
    // about 1.3 times it, mass gathered at both ends 3 times, a point mass
    // 0. Far outside [0.2, 4] times is more likely a slip (kg m^2 vs kg cm^2)
    // than a design.
    const double box = l->mass * (l->length * l->length + l->height * l->height) / 12.0;
    if (!c->failed && (l->inertia < 0.2 * box || l->inertia > 4.0 * box)) {
        char f2[80], v[24], b[24];
        json_path(f2, sizeof f2, p, "inertia");
        hyd_fmt_num(v, sizeof v, l->inertia);
        hyd_fmt_num(b, sizeof b, box);
        json_note(c, f2, "%s kg m^2 is outside the typical range [0.2, 4] times a uniform box of this mass and size "
                         "(%s kg m^2)", v, b);
    }
}

static void load_actuator(json_ctx* c, const cJSON* arr, int i, crane_actuator* a) {
    char p[64];
    json_path_index(p, sizeof p, "mechanics.actuators", i);
    const cJSON* o = cJSON_GetArrayItem(arr, i);
    if (!cJSON_IsObject(o)) {
        json_fail(c, p, "must be an object");
        return;
    }
    static const char* const keys[] = {"name", "joint", "cylinder", "valve", "base_mount",
                                       "rod_mount", "closed_length", NULL};
    json_only_keys(c, o, p, keys);
    json_str(c, o, p, "name", true, "", a->name, sizeof a->name);
    a->joint = json_int(c, o, p, "joint", true, 0, 0, 1);
    if (!c->failed && a->joint != i) json_fail(c, p, "actuator %d must act on joint %d", i, i);
    json_str(c, o, p, "cylinder", true, "", a->cylinder, sizeof a->cylinder);
    json_str(c, o, p, "valve", true, "", a->valve, sizeof a->valve);
    json_vec_r(c, o, p, "base_mount", true, a->base_mount, 2, &MODEL_R_MOUNT);
    json_vec_r(c, o, p, "rod_mount", true, a->rod_mount, 2, &MODEL_R_MOUNT);
    a->closed_length = json_num_r(c, o, p, "closed_length", true, 0, &MODEL_R_CLOSED_LENGTH);
}

// The two-link shorthand of the mechanics section: column, two links,
// two actuators by joint (hiab031.json). 0, or -1 with the error in c.
static int read_shorthand(json_ctx* c, const cJSON* mech, crane_mech* me) {
    static const char* const mkeys[] = {"gravity", "column", "links", "load_mass", "actuators", "rated_moment",
                                         "rated_load", "slew", NULL};
    json_only_keys(c, mech, "mechanics", mkeys);
    me->gravity = json_num_r(c, mech, "mechanics", "gravity", false, 9.81, &MODEL_R_GRAVITY);
    const cJSON* col = json_obj(c, mech, "mechanics", "column", true);
    json_only_keys(c, col, "mechanics.column", (const char* const[]){"height", "mass", NULL});
    me->column_height = json_num_r(c, col, "mechanics.column", "height", true, 0, &MODEL_R_COLUMN_HEIGHT);
    me->column_mass = json_num_r(c, col, "mechanics.column", "mass", false, 250, &MODEL_R_COLUMN_MASS);
    const cJSON* links = json_arr(c, mech, "mechanics", "links", true);
    if (links && cJSON_GetArraySize(links) != 2) json_fail(c, "mechanics.links", "must list exactly 2 links");
    for (int i = 0; i < 2 && !c->failed; ++i) load_link(c, links, i, &me->link[i]);
    // Names pick elements in --set paths (mechanics.links.end_arm.mass): two
    // equal names would make the second unreachable.
    if (!c->failed && !strcmp(me->link[0].name, me->link[1].name))
        json_fail(c, "mechanics.links[1].name", "\"%s\" is already the name of links[0]", me->link[1].name);
    me->load_mass = json_num_r(c, mech, "mechanics", "load_mass", true, 0, &MODEL_R_LOAD);
    // Optional: absent (0) means no rating, the chart is the physical envelope.
    me->rated_moment = json_num_r(c, mech, "mechanics", "rated_moment", false, 0, &MODEL_R_RATED_MOMENT);
    me->rated_load = json_num_r(c, mech, "mechanics", "rated_load", false, 0, &MODEL_R_RATED_LOAD);
    const cJSON* acts = json_arr(c, mech, "mechanics", "actuators", true);
    if (acts && cJSON_GetArraySize(acts) != 2)
        json_fail(c, "mechanics.actuators", "must list exactly 2 actuators (lift, jib)");
    for (int i = 0; i < 2 && !c->failed; ++i) load_actuator(c, acts, i, &me->act[i]);
    if (!c->failed && !strcmp(me->act[0].name, me->act[1].name))
        json_fail(c, "mechanics.actuators[1].name", "\"%s\" is already the name of actuators[0]", me->act[1].name);
    if (c->failed) return -1;
    json_flush_notes(c);
    crane_mech_derive(me);
    return 0;
}

// The optional "controls" section (model_controls.h): parsed, and every
// function it names checked against the model's (its chain's, and "slew"
// where the crane slews: the two-link crane always takes a slew command).
static int read_controls(model* m, const cJSON* root, const char* file, char* err, size_t errsz) {
    const cJSON* o = cJSON_GetObjectItemCaseSensitive(root, "controls");
    if (!o) return 0;
    model_controls* mc = malloc(sizeof *mc);
    if (!mc) {
        snprintf(err, errsz, "%s: out of memory", file);
        return -1;
    }
    m->controls = mc;
    if (controls_parse(o, file, "controls", mc, err, errsz)) return -1;
    const char* names[CONTROLS_MAX_FN + 1];
    int n = 0;
    bool slew = m->chain.two_link || m->chain.slew.present;
    for (int i = 0; i < m->chain.nfn && n < CONTROLS_MAX_FN; ++i) {
        names[n++] = m->chain.fn[i].name;
        if (!strcmp(m->chain.fn[i].name, "slew")) slew = false;
    }
    if (slew) names[n++] = "slew";
    return controls_check_functions(mc, names, n, file, "controls", err, errsz);
}

model* model_from_json(cJSON* root, const char* file, char* err, size_t errsz) {
    model* m = calloc(1, sizeof *m);
    if (!m) {
        cJSON_Delete(root);
        snprintf(err, errsz, "%s: out of memory", file);
        return NULL;
    }
    m->json = root;
    snprintf(m->file, sizeof m->file, "%s", file);
    json_ctx c = {.file = file, .err = err, .errsz = errsz};
    if (!cJSON_IsObject(root)) json_fail(&c, "", "a model must be a JSON object");
    if (json_wrong_kind(&c, root, "model")) goto fail;
    static const char* const keys[] = {"name",           "description", "mechanics", "hydraulics",
                                       "hydraulics_slew", "controls",    NULL};
    json_only_keys(&c, root, "", keys);
    json_str(&c, root, "", "name", false, "crane", m->name, sizeof m->name);

    crane_mech* me = &m->mech;
    const cJSON* mech = json_obj(&c, root, "", "mechanics", true);
    // Two forms of the mechanics section: the chain (mechanics.bodies, any
    // shape, model_chain.c) and the two-link shorthand (column, links and
    // actuators by joint) that hiab031.json and every older file use.
    const bool chain_form = model_chain_form(mech);
    if (chain_form) {
        if (model_chain_read(&c, mech, m)) goto fail;
        json_flush_notes(&c);
    } else if (read_shorthand(&c, mech, me)) {
        goto fail;
    }
    // The slew drive, the same in both forms; it joins the chain once that
    // is built (both builders start from an empty chain).
    crane_slew slew;
    if (model_slew_read(&c, root, mech, &slew)) goto fail;
    // One column, one radius: the chain form gives the column's body its own
    // (its inertia about the slew axis, 1/2 m r^2, is what the drive turns).
    if (chain_form && slew.present && 0.5 * m->chain.body[0].width != slew.column_radius) {
        json_fail(&c, "mechanics.slew.column_radius",
                  "%g m is not the column's radius (mechanics.bodies[0].radius, %g m): one column, one radius",
                  slew.column_radius, 0.5 * m->chain.body[0].width);
        goto fail;
    }

    const cJSON* hyd = json_obj(&c, root, "", "hydraulics", true);
    if (c.failed) goto fail;
    m->hyd = hyd_model_from_json(hyd, file, "hydraulics", err, errsz);
    if (!m->hyd) goto fail;
    {
        const int bad = ls_unreached(m->hyd);
        if (bad >= 0) {
            char f[64];
            snprintf(f, sizeof f, "hydraulics.components[%d].ls", bad);
            json_fail(&c, f, "node '%s' is fed by no shuttle or work line: the LS network does not reach the pump",
                      hyd_model_node_name(m->hyd, hyd_model_port_node(m->hyd, bad, 2)));
            goto fail;
        }
        if (ls_section_fault(&c, m->hyd)) goto fail;
        const int unfed = valve_unfed(m->hyd);
        if (unfed >= 0) {
            char f[64];
            snprintf(f, sizeof f, "hydraulics.components[%d].P", unfed);
            json_fail(&c, f,
                      "node '%s' is fed by nothing (no pump, compensator, hose or other line puts oil into it): "
                      "valve '%s' has no supply",
                      hyd_model_node_name(m->hyd, hyd_model_port_node(m->hyd, unfed, 0)),
                      hyd_model_comp_name(m->hyd, unfed));
            goto fail;
        }
        ls_param_notes(&c, m->hyd);
        pump_relief_notes(&c, m->hyd);
        json_flush_notes(&c);
    }
    if (model_slew_check(&c, root, &slew)) goto fail;
    json_flush_notes(&c);
    if (chain_form) {
        if (model_chain_bind(&c, m)) goto fail;
        m->chain.slew = slew;
        if (read_controls(m, root, file, err, errsz)) goto fail;
        return m;
    }

    for (int k = 0; k < 2; ++k) {
        char p[64];
        snprintf(p, sizeof p, "mechanics.actuators[%d]", k);
        m->cyl[k] = hyd_model_cylinder(m->hyd, me->act[k].cylinder);
        m->valve[k] = hyd_model_valve(m->hyd, me->act[k].valve);
        char f[80];
        snprintf(f, sizeof f, "%s.cylinder", p);
        if (m->cyl[k] < 0) json_fail(&c, f, "no cylinder named \"%s\" in hydraulics", me->act[k].cylinder);
        snprintf(f, sizeof f, "%s.valve", p);
        if (m->valve[k] < 0) json_fail(&c, f, "no valve named \"%s\" in hydraulics", me->act[k].valve);
        // One cylinder (valve) per actuator: two joints driven by one
        // cylinder are two rigid constraints on one stroke, which the
        // integrator meets as a blow-up rather than an error.
        if (k == 1 && m->cyl[1] == m->cyl[0])
            json_fail(&c, "mechanics.actuators[1].cylinder",
                      "\"%s\" is also the cylinder of actuators[0]; each actuator needs its own", me->act[1].cylinder);
        if (k == 1 && m->valve[1] == m->valve[0])
            json_fail(&c, "mechanics.actuators[1].valve",
                      "\"%s\" is also the valve of actuators[0]; each actuator needs its own", me->act[1].valve);
        if (c.failed) goto fail;
        double AA, AB;
        hyd_model_cylinder_geometry(m->hyd, m->cyl[k], &AA, &AB, &m->stroke[k]);
    }
    char cerr[512];
    if (crane_mech_check(me, m->stroke, cerr, (int)sizeof cerr)) {
        snprintf(err, errsz, "%s: %s", file, cerr);
        goto fail;
    }
    // The same crane as a chain (crane_chain.h), which the general paths use.
    if (crane_chain_from_mech(me, &m->chain, cerr, sizeof cerr) || crane_chain_bind(&m->chain, m->hyd, cerr, sizeof cerr)) {
        snprintf(err, errsz, "%s: %s", file, cerr);
        goto fail;
    }
    if (slew.present) {
        // The shorthand's column as the sandbox builds it: a solid cylinder
        // of the drive's column radius (crane_chain_from_mech's is 0.1 m),
        // so that the chain's inertia about the slew axis is the sandbox's.
        chain_crane cr;
        const chain_crane_opts co = {0, 0.0, slew.column_radius};
        chain_from_crane_mech(me, 0.0, &co, &cr); // its actuators were checked above
        m->chain.body[0].def = cr.body[0];
        m->chain.body[0].width = m->chain.body[0].height = 2.0 * slew.column_radius;
    }
    m->chain.slew = slew;
    if (read_controls(m, root, file, err, errsz)) goto fail;
    return m;
fail: // err already holds the one-line message
    model_free(m);
    return NULL;
}

static const char* optional_param(const char* assignment);

// The file with the first n overrides applied, or NULL with the message.
static cJSON* load_with_sets(const char* path, const char* const* sets, int n, char* err, size_t errsz) {
    cJSON* root = json_load_file(path, err, errsz);
    if (!root) return NULL;
    for (int i = 0; i < n; ++i) {
        char e[400];
        if (json_set_path(root, sets[i], e, sizeof e)) {
            // The file's base name, as every other message of the loader.
            const char* base = strrchr(path, '/');
            const char* opt = optional_param(sets[i]);
            if (opt && !cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "mechanics"), opt))
                // An optional field the model does not have: --set edits
                // fields, it does not add them (a typo would add one too).
                snprintf(err, errsz, "%s: %s '%s': this model has no mechanics.%s (an optional field: without it the "
                         "model gives no rating, docs/model.md); add it to the model file to set it",
                         base ? base + 1 : path, sim_param_name(SIM_PARAM_SET), sets[i], opt);
            else
                snprintf(err, errsz, "%s: %s", base ? base + 1 : path, e);
            cJSON_Delete(root);
            return NULL;
        }
    }
    return root;
}

// Which override turned a valid file into an invalid model: the first k with
// sets[0..k] failing, or -1 when the file fails on its own. Only called on
// the failure path; a model loads in well under a millisecond.
static int first_bad_set(const char* path, const char* file, const char* const* sets, int nset) {
    for (int k = 0; k <= nset; ++k) {
        char e[1024];
        cJSON* root = load_with_sets(path, sets, k, e, sizeof e);
        if (!root) return -1;
        model* m = model_from_json(root, file, e, sizeof e);
        if (!m) return k - 1;
        model_free(m);
    }
    return -1;
}

const char* model_path(const char* arg, char* buf, size_t n) {
    if (!arg) return model_default_path();
    struct stat st;
    const size_t L = strlen(arg);
    if ((stat(arg, &st) == 0 && S_ISREG(st.st_mode)) || strchr(arg, '/') || (L >= 5 && !strcmp(arg + L - 5, ".json")))
        return arg;
    snprintf(buf, n, "%s/models/%s.json", model_assets_dir(), arg);
    return buf;
}

// A name (model_path) that is no model in the assets: say which there are,
// instead of "cannot open". Returns 1 with the message, else 0.
static int missing_named_model(const char* arg, const char* path, char* err, size_t errsz) {
    struct stat st;
    if (!arg || path == arg || stat(path, &st) == 0) return 0;
    char folder[512], list[512];
    snprintf(folder, sizeof folder, "%s/models", model_assets_dir());
    json_list_files(folder, list, sizeof list);
    snprintf(err, errsz, "%s %s: no such file or model (models: %s; or the path of a model file)",
             sim_param_name(SIM_PARAM_MODEL), arg, list);
    return 1;
}

model* model_load(const char* arg, const char* const* sets, int nset, char* err, size_t errsz) {
    char buf[512];
    const char* path = model_path(arg, buf, sizeof buf);
    if (missing_named_model(arg, path, err, errsz)) return NULL;
    cJSON* root = load_with_sets(path, sets, nset, err, errsz);
    if (!root) return NULL;
    const char* base = strrchr(path, '/');
    base = base ? base + 1 : path;
    model* m = model_from_json(root, base, err, errsz);
    if (m || nset == 0) return m;
    // A range error reads like a fault of the file; say which --set it was.
    const int k = first_bad_set(path, base, sets, nset);
    if (k >= 0) {
        const size_t L = strlen(err);
        snprintf(err + L, errsz - L, " (from %s '%s')", sim_param_name(SIM_PARAM_SET), sets[k]);
    }
    return NULL;
}

void model_free(model* m) {
    if (!m) return;
    hyd_model_free(m->hyd);
    crane_chain_free(&m->chain);
    free(m->controls);
    cJSON_Delete(m->json);
    cJSON_Delete(m->world_bursts);
    free(m);
}

int model_save(const model* m, const char* path, char* err, size_t errsz) {
    char* text = cJSON_Print(m->json);
    if (!text) {
        snprintf(err, errsz, "%s: out of memory", path);
        return -1;
    }
    FILE* f = fopen(path, "w");
    if (!f) {
        snprintf(err, errsz, "%s: cannot write", path);
        free(text);
        return -1;
    }
    fputs(text, f);
    fputc('\n', f);
    int bad = ferror(f) | fclose(f);
    free(text);
    if (bad) snprintf(err, errsz, "%s: write failed", path);
    return bad ? -1 : 0;
}

// ---- the mechanics parameter table (generated parameter lists) ------------

// Every scalar the mechanics section holds, with the ranges the loader
// checks it against (the R_* above), so a panel or a sweep can list them
// without knowing the file's layout.
#define MP_(path, group, name, field, r) {path, group, name, offsetof(crane_mech, field), &r, 0}
typedef struct mech_entry {
    const char* path, *group, *name;
    size_t off;
    const json_range* r;
    int optional; // a model may lack it: 0 then
} mech_entry;
static const mech_entry k_mech[] = {
    MP_("mechanics.gravity", "mechanics", "gravity", gravity, MODEL_R_GRAVITY),
    MP_("mechanics.column.height", "mechanics", "column height", column_height, MODEL_R_COLUMN_HEIGHT),
    MP_("mechanics.column.mass", "mechanics", "column mass", column_mass, MODEL_R_COLUMN_MASS),
    MP_("mechanics.load_mass", "mechanics", "tip load", load_mass, MODEL_R_LOAD),
    // The rating (optional): the load chart's cap and so the limiter's.
    {"mechanics.rated_moment", "mechanics", "rated moment", offsetof(crane_mech, rated_moment), &MODEL_R_RATED_MOMENT, 1},
    {"mechanics.rated_load", "mechanics", "rated load", offsetof(crane_mech, rated_load), &MODEL_R_RATED_LOAD, 1},
#define MP_LINK_(i)                                                                           \
    MP_("mechanics.links[" #i "].length", "links[" #i "]", "length", link[i].length, MODEL_R_LINK_LENGTH), \
    MP_("mechanics.links[" #i "].mass", "links[" #i "]", "mass", link[i].mass, MODEL_R_LINK_MASS),         \
    MP_("mechanics.links[" #i "].com", "links[" #i "]", "com", link[i].com, MODEL_R_LINK_COM),             \
    MP_("mechanics.links[" #i "].inertia", "links[" #i "]", "inertia", link[i].inertia, MODEL_R_LINK_INERTIA), \
    MP_("mechanics.links[" #i "].width", "links[" #i "]", "width", link[i].width, MODEL_R_LINK_SECTION),   \
    MP_("mechanics.links[" #i "].height", "links[" #i "]", "height", link[i].height, MODEL_R_LINK_SECTION)
    MP_LINK_(0),
    MP_LINK_(1),
#define MP_ACT_(i)                                                                                              \
    MP_("mechanics.actuators[" #i "].base_mount[0]", "actuators[" #i "]", "base mount x", act[i].base_mount[0], MODEL_R_MOUNT), \
    MP_("mechanics.actuators[" #i "].base_mount[1]", "actuators[" #i "]", "base mount z", act[i].base_mount[1], MODEL_R_MOUNT), \
    MP_("mechanics.actuators[" #i "].rod_mount[0]", "actuators[" #i "]", "rod mount x", act[i].rod_mount[0], MODEL_R_MOUNT),   \
    MP_("mechanics.actuators[" #i "].rod_mount[1]", "actuators[" #i "]", "rod mount z", act[i].rod_mount[1], MODEL_R_MOUNT),   \
    MP_("mechanics.actuators[" #i "].closed_length", "actuators[" #i "]", "closed length", act[i].closed_length,         \
        MODEL_R_CLOSED_LENGTH)
    MP_ACT_(0),
    MP_ACT_(1),
};
#undef MP_LINK_
#undef MP_ACT_
#undef MP_

int model_param_count(void) { return (int)(sizeof k_mech / sizeof k_mech[0]); }

// The key under mechanics of the optional table entry an assignment
// PATH=VALUE sets, or NULL.
static const char* optional_param(const char* assignment) {
    const char* eq = strchr(assignment, '=');
    if (!eq) return NULL;
    for (int k = 0; k < model_param_count(); ++k) {
        const size_t L = strlen(k_mech[k].path);
        if (k_mech[k].optional && (size_t)(eq - assignment) == L && !strncmp(assignment, k_mech[k].path, L))
            return k_mech[k].path + strlen("mechanics.");
    }
    return NULL;
}

int model_param_info(int k, model_param* out) {
    if (k < 0 || k >= model_param_count()) return -1;
    const mech_entry* e = &k_mech[k];
    out->path = e->path;
    out->group = e->group;
    out->name = e->name;
    out->unit = e->r->unit;
    out->lo = e->r->lo;
    out->hi = e->r->hi;
    out->tlo = e->r->tlo;
    out->thi = e->r->thi;
    out->optional = e->optional;
    return 0;
}

int model_param_present(const crane_mech* me, int k) {
    if (k < 0 || k >= model_param_count()) return 0;
    return !k_mech[k].optional || *(const double*)((const char*)me + k_mech[k].off) != 0;
}

double* model_param_ptr(crane_mech* me, int k) {
    if (k < 0 || k >= model_param_count()) return NULL;
    return (double*)((char*)me + k_mech[k].off);
}
