// engine.c: the backend-independent half of engine.h: dispatch to the
// backend's engine_ops, and the run checks every engine applies after a step.
#include "engine.h"
#include "engine_impl.h"
#include "energy_acc.h"
#include "engine_backend.h"
#include "step_probe.h"

#include "model.h"
#include "rcl.h"
#include <stdlib.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct play_ctx {
    engine* e;
    engine_hook_fn on_hook;
    void* user;
} play_ctx;

static int play_hook(void* user, int attach) {
    play_ctx* pc = user;
    const int got = engine_hook(pc->e, attach);
    if (pc->on_hook) pc->on_hook(pc->user, pc->e, attach, got);
    return got;
}

// The backend o->mechanics names (engine_backend.c's table), or NULL for a
// value that names none: every caller refuses that, none picks a default.
static const engine_ops* backend(const sim_opts* o) {
    const engine_backend* b = engine_backend_of(o);
    return b ? b->ops : NULL;
}

// The one line for a value of sim_opts.mechanics that names no backend.
static void unknown_backend(const sim_opts* o, char* err, size_t errsz) {
    char known[128];
    snprintf(err, errsz, "sim_opts.mechanics: %d names no backend (known: %s)", (int)o->mechanics,
             engine_backend_names(known, sizeof known, NULL));
}

engine* engine_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                      size_t errsz) {
    return engine_create_rcl(m, o, q0, slew0, m3, NULL, err, errsz);
}

// The ops engine_create uses for m and o: the backend's own, or the one its
// stepped() chooses (its engine for crane chains).
static const engine_ops* stepped_ops(const model* m, const sim_opts* o) {
    const engine_ops* b = backend(o);
    if (!b) return NULL;
    return b->stepped ? b->stepped(m, o) : b;
}

// The sizes engine.c owns: the commands by function, the channels and a
// row buffer. 0, or -1 when out of memory.
static int size_engine(engine* e, const model* m) {
    e->mdl = m;
    e->nfn = engine_nfunction(e);
    e->u_op = calloc(2 * (size_t)e->nfn + 1, sizeof *e->u_op);
    e->u_lim = e->u_op ? e->u_op + e->nfn : NULL;
    const int nc = engine_ncol(e);
    e->rowbuf = calloc((size_t)(nc > SIM_NCOL ? nc : SIM_NCOL), sizeof *e->rowbuf);
    if (!e->u_op || !e->rowbuf) return -1;
    const int nb = e->ops->nchannel;
    if (nc > nb) {
        // The backend's channels, then the chain's own (crane_chain_columns),
        // named by the model (which outlives the engine).
        e->chan = calloc((size_t)nc, sizeof *e->chan);
        if (!e->chan) return -1;
        memcpy(e->chan, sim_channels, (size_t)nb * sizeof *e->chan);
        for (int c = nb; c < nc && c - nb < m->chain.ncol; ++c) {
            const crane_column* cl = &m->chain.col[c - nb];
            e->chan[c] = (sim_channel){cl->name, cl->unit, cl->pressure ? SIM_CH_PRESSURE : SIM_CH_OTHER};
        }
    }
    return 0;
}

// Frees what size_engine allocated, then the backend's engine.
static void free_engine(engine* e) {
    free(e->u_op);
    free(e->rowbuf);
    free(e->chan);
    e->ops->destroy(e);
}

engine* engine_create_rcl(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3,
                          struct rcl* r, char* err, size_t errsz) {
    const engine_ops* ops = stepped_ops(m, o);
    if (!ops) {
        unknown_backend(o, err, errsz);
        return NULL;
    }
    engine* e = ops->create(m, o, q0, slew0, m3, err, errsz);
    if (!e) return NULL;
    if (size_engine(e, m)) {
        snprintf(err, errsz, "out of memory");
        free_engine(e);
        return NULL;
    }
    // The step probe on the backend's hydraulic step, after its own start
    // checks: it runs the analytic backend (step_probe.c), which a backend
    // may not call, so the engine applies it for every backend.
    if (sim_check_step_probe(m, o, e->h_probe, err, errsz)) {
        free_engine(e);
        return NULL;
    }
    // The limiter filters every command a stepped driver sets (drive, the
    // window's tick, the soak bench, serve): one place for all of them. A
    // crane chain's engine makes its limiter only when o->rcl asks for it
    // (its chart searches every joint of the chain, about a second): the
    // library's default runs measure nothing there.
    const bool chain = e->ops->set_function_commands != NULL;
    if (!(engine_caps(e) & ENGINE_CAP_LIMITER) || (chain && !o->rcl && !r)) {
        rcl_destroy(r);
        return e;
    }
    if (r) rcl_reset(r);
    // A stepped engine's world, when o names none, is its drive world; a
    // crane chain's engine without a hook runs in no world (the ODE's
    // validation world: no truck), whatever the backend's drive world.
    const char* dw = chain && !e->ops->hook ? NULL : engine_backend_of(o)->drive_world;
    e->rcl = r ? r : engine_rcl_create(m, o, dw);
    // A chain's rows carry its columns after the backend's channels.
    if (e->rcl && chain && rcl_set_chain_row(e->rcl, NULL, e->ops->nchannel)) {
        snprintf(err, errsz, "rated capacity limiter: the rows of this engine lack the chain's q, qd or pressure "
                             "columns");
        engine_destroy(e);
        return NULL;
    }
    return e;
}

struct rcl* engine_rcl_detach(engine* e) {
    struct rcl* r = e->rcl;
    e->rcl = NULL;
    return r;
}

struct rcl* engine_rcl_create(const model* m, const sim_opts* o, const char* default_world) {
    char buf[512];
    const char* wp = NULL;
    const engine_backend* b = engine_backend_of(o);
    if (!b) return NULL;
    if (b->world) wp = sim_world_path(o->world ? o->world : default_world, buf, sizeof buf);
    return rcl_create(m, wp);
}

void engine_rcl_destroy(struct rcl* r) { rcl_destroy(r); }

// The limiter's utilisation into the row's rcl_util column, where the
// backend publishes it.
static void fill_rcl(engine* e, double* row) {
    if (e->rcl && e->ops->nchannel > COL_RCL_UTIL) row[COL_RCL_UTIL] = rcl_utilisation(e->rcl, row);
}

int engine_check_scenario(const model* m, const scenario* sc, char* err, size_t errsz) {
    for (int k = SCENARIO_NCMD; k < scenario_ncmd(sc); ++k) {
        if (crane_chain_find_function(&m->chain, sc->cmd_name[k]) >= 0) continue;
        int n = snprintf(err, errsz,
                         "%s: commands.%s: unknown field '%s': the model has no function of that name (its functions: "
                         "lift, jib, slew",
                         sc->file[0] ? sc->file : "scenario", sc->cmd_name[k], sc->cmd_name[k]);
        for (int f = 0; f < m->chain.nfn && n > 0 && (size_t)n < errsz; ++f) {
            const char* fn = m->chain.fn[f].name;
            if (strcmp(fn, "lift") && strcmp(fn, "jib") && strcmp(fn, "slew"))
                n += snprintf(err + n, errsz - (size_t)n, ", %s", fn);
        }
        if (n > 0 && (size_t)n < errsz) snprintf(err + n, errsz - (size_t)n, ")");
        return -1;
    }
    return 0;
}

int engine_nfunction(const engine* e) {
    const crane_chain* cc = &e->mdl->chain;
    // The two-link crane's third command is the slew (of the sandbox
    // world), as a chain engine's in the sandbox (engine.slew_function);
    // elsewhere a chain engine takes exactly the model's functions.
    return cc->nfn + ((cc->two_link || e->slew_function) && crane_chain_find_function(cc, "slew") < 0 ? 1 : 0);
}

const char* engine_function_name(const engine* e, int k) {
    const crane_chain* cc = &e->mdl->chain;
    if (k >= 0 && k < cc->nfn) return cc->fn[k].name;
    return k >= 0 && k == engine_nfunction(e) - 1 ? "slew" : NULL;
}

int engine_find_function(const engine* e, const char* name) {
    for (int k = 0; k < e->nfn; ++k)
        if (!strcmp(engine_function_name(e, k), name)) return k;
    return -1;
}

// The names of e's functions, ", "-separated, into buf.
static void function_list(const engine* e, char* buf, size_t n) {
    int w = 0;
    for (int k = 0; k < e->nfn && w >= 0 && (size_t)w < n; ++k)
        w += snprintf(buf + w, n - (size_t)w, "%s%s", k ? ", " : "", engine_function_name(e, k));
}

static double clamp1(double v) { return v < -1 ? -1 : v > 1 ? 1 : isnan(v) ? 0 : v; }

// The commands by function, all nfn of them, to the engine.
static void apply_function_commands(engine* e, const double* u) {
    if (!e->ops->set_function_commands) {
        // The two-link engines: lift, jib, slew through engine_set_commands
        // (and its limiter), whatever the chain's function order.
        double u3[3] = {e->u_op[0], e->u_op[1], e->u_op[2]};
        for (int k = 0; k < e->nfn; ++k)
            for (int c = 0; c < SCENARIO_NCMD; ++c)
                if (!strcmp(engine_function_name(e, k), scenario_cmd_name[c])) u3[c] = u[k];
        engine_set_commands(e, u3);
        return;
    }
    for (int k = 0; k < e->nfn; ++k) e->u_op[k] = e->u_lim[k] = clamp1(u[k]);
    // A crane chain's limiter (rcl_filter_fn): on the row as it stands,
    // the functions that carry the tip outwards are slowed and stopped.
    if (e->rcl) {
        e->ops->row(e, e->rowbuf);
        if (e->o.rcl)
            rcl_filter_fn(e->rcl, e->rowbuf, e->nfn, e->u_op, e->u_lim, engine_find_function(e, "slew"));
        else rcl_utilisation(e->rcl, e->rowbuf); // still measured, for the HUD and the record
    }
    e->ops->set_function_commands(e, e->u_lim);
}

int engine_set_function_commands(engine* e, const double* u, int n, char* err, size_t errsz) {
    if (n != e->nfn) {
        if (err && errsz) {
            char names[400];
            function_list(e, names, sizeof names);
            snprintf(err, errsz, "%d commands for the %d functions %s", n, e->nfn, names);
        }
        return -1;
    }
    apply_function_commands(e, u);
    return 0;
}

int engine_set_function_command(engine* e, const char* name, double u, char* err, size_t errsz) {
    const int k = engine_find_function(e, name);
    if (k < 0) {
        if (err && errsz) {
            char names[400];
            function_list(e, names, sizeof names);
            snprintf(err, errsz, "no function '%s' (functions: %s)", name, names);
        }
        return -1;
    }
    double* v = malloc(((size_t)e->nfn + 1) * sizeof *v);
    if (!v) {
        if (err && errsz) snprintf(err, errsz, "out of memory");
        return -1;
    }
    memcpy(v, e->u_op, (size_t)e->nfn * sizeof *v);
    v[k] = u;
    apply_function_commands(e, v);
    free(v);
    return 0;
}

double engine_function_command(const engine* e, int k) { return k >= 0 && k < e->nfn ? e->u_op[k] : NAN; }

unsigned engine_caps(const engine* e) {
    const engine_ops* p = e->ops;
    unsigned c = 0;
    if (p->snapshot) c |= ENGINE_CAP_SNAPSHOT;
    if (p->set_link) c |= ENGINE_CAP_SET_LINK;
    // The limiter and everything shaped lift, jib, slew with SIM_NCOL
    // columns: the engines that take set_commands' three commands.
    if (p->set_commands && !p->set_function_commands) c |= ENGINE_CAP_TWO_LINK | ENGINE_CAP_LIMITER;
    // A crane chain's engine filters its commands by function (rcl_filter_fn);
    // which chains it can read, engine_require asks rcl_check_model.
    if (p->set_function_commands) c |= ENGINE_CAP_LIMITER;
    return c;
}

unsigned engine_caps_for(const model* m, const sim_opts* o) {
    const engine_ops* p = stepped_ops(m, o);
    if (!p) return 0;
    // engine_caps reads only the ops: a stand-in engine with them.
    engine tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.ops = p;
    return engine_caps(&tmp);
}

int engine_require(const model* m, const sim_opts* o, unsigned caps, const char* what, char* err, size_t errsz) {
    if (!stepped_ops(m, o)) {
        unknown_backend(o, err, errsz);
        return -1;
    }
    const unsigned miss = caps & ~engine_caps_for(m, o);
    // The limiter on a crane chain: the chain's shape and rating decide.
    if (!miss && (caps & ENGINE_CAP_LIMITER)) {
        char why[400];
        if (rcl_check_model(m, why, sizeof why)) {
            snprintf(err, errsz, "%s: %s", what, why);
            return -1;
        }
    }
    if (!miss) return 0;
    // The first missing part, in the order a driver meets them.
    const char* part = (miss & ENGINE_CAP_SNAPSHOT)   ? "picture for the renderer"
                       : (miss & ENGINE_CAP_TWO_LINK) ? "fixed three commands and two-link rows (lift, jib, slew; "
                                                        "a headless drive runs it by function)"
                       : (miss & ENGINE_CAP_LIMITER)  ? "rated capacity limiter"
                                                      : "boom edits (the drive panel)";
    char crane[64];
    if (m->chain.two_link) snprintf(crane, sizeof crane, "the two-link crane in the general formulation");
    else snprintf(crane, sizeof crane, "this crane chain (%d functions)", m->chain.nfn);
    snprintf(err, errsz, "%s: %s: the stepped %s engine for %s has no %s yet", what, m->file[0] ? m->file : "model",
             engine_backend_of(o)->name, crane, part);
    return -1;
}

int engine_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k0, sim_result* res) {
    // Every scripted run is probed (engine_sink.probe): the backend applies
    // it after its own start checks.
    engine_sink kp = *k0;
    kp.probe = sim_check_step_probe;
    const engine_sink* k = &kp;
    if (!backend(o)) {
        unknown_backend(o, res->message, sizeof res->message);
        return res->status = SIM_REFUSED;
    }
    if (engine_check_scenario(m, sc, res->message, sizeof res->message)) return res->status = SIM_REFUSED;
    if (sc->nfault == 0) return backend(o)->run(m, sc, o, k, res);
    // The bursts' orifices go into a copy; the caller's model stays as it is
    // (compare and study run it again).
    model* fm = engine_fault_model(m, sc, res->message, sizeof res->message);
    if (!fm) return res->status = SIM_REFUSED;
    const int rc = backend(o)->run(fm, sc, o, k, res);
    model_free(fm);
    return rc;
}

void engine_play(engine* e, const scenario* sc, double tm, int* ev, double u[3], engine_hook_fn on_hook,
                 void* user) {
    play_ctx pc = {e, on_hook, user};
    scenario_play(sc, tm, ev, u, play_hook, &pc);
    engine_apply_faults(e, sc, tm);
}

void engine_play_functions(engine* e, const scenario* sc, double tm, int* ev, double* u, engine_hook_fn on_hook,
                           void* user) {
    double u3[SCENARIO_NCMD];
    engine_play(e, sc, tm, ev, u3, on_hook, user);
    // By name, as the scripted runs read them (scenario_find_command).
    for (int k = 0; k < e->nfn; ++k) {
        const int c = scenario_find_command(sc, engine_function_name(e, k));
        u[k] = c < 0 ? 0.0 : c < SCENARIO_NCMD ? u3[c] : scenario_command(sc, c, tm);
    }
}

void engine_apply_faults(engine* e, const scenario* sc, double tm) {
    // Faults act on the engine's circuit at the same time as the commands
    // (bursts only if the engine was made from engine_fault_model's model).
    if (sc->nfault) {
        hyd_model* hm = engine_circuit(e);
        if (!e->faults_ready) engine_faults_init(&e->faults, hm), e->faults_ready = true;
        engine_faults_apply(&e->faults, hm, sc, tm);
    }
}

void engine_destroy(engine* e) {
    if (!e) return;
    engine_rcl_destroy(e->rcl);
    free_engine(e);
}

const char* engine_backend_name(const engine* e) { return e->ops->name; }

void engine_describe(const sim_opts* o, engine_desc* d) {
    memset(d, 0, sizeof *d);
    if (!backend(o)) { // reported as what it is, never as another backend
        d->backend = d->world = d->step_name = "";
        unknown_backend(o, d->label, sizeof d->label);
        unknown_backend(o, d->title, sizeof d->title);
        return;
    }
    d->backend = backend(o)->name;
    backend(o)->describe(o, d);
}

void engine_describe_work(const sim_opts* o, const sim_result* r, char* buf, size_t n) {
    if (!backend(o)) unknown_backend(o, buf, n);
    else backend(o)->describe_work(o, r, buf, n);
}
void engine_set_commands(engine* e, const double u[3]) {
    if (e->ops->set_function_commands) {
        // By name onto the functions the model has (a chain engine).
        double* v = malloc(((size_t)e->nfn + 1) * sizeof *v);
        if (!v) return; // nothing set: the commands held stay
        memcpy(v, e->u_op, (size_t)e->nfn * sizeof *v);
        for (int c = 0; c < SCENARIO_NCMD; ++c) {
            const int k = engine_find_function(e, scenario_cmd_name[c]);
            if (k >= 0) v[k] = u[c];
        }
        apply_function_commands(e, v);
        free(v);
        return;
    }
    // The operator's demand and what was let through, for the HUD (it shows
    // both where the limiter cut).
    memcpy(e->u_op, u, 3 * sizeof *e->u_op);
    memcpy(e->u_lim, u, 3 * sizeof *e->u_lim);
    if (!e->rcl || !e->o.rcl) {
        if (e->rcl) { // still measured, for the HUD and the record
            e->ops->row(e, e->rowbuf);
            rcl_utilisation(e->rcl, e->rowbuf);
        }
        e->ops->set_commands(e, u);
        return;
    }
    double v[3];
    e->ops->row(e, e->rowbuf);
    rcl_filter(e->rcl, e->rowbuf, u, v);
    memcpy(e->u_lim, v, 3 * sizeof *e->u_lim);
    e->ops->set_commands(e, v);
}

const struct rcl* engine_rcl(const engine* e) { return e->rcl; }
int engine_hook(engine* e, int attach) { return e->ops->hook ? e->ops->hook(e, attach) : -1; }

int engine_hook_report(engine* e, int attach, char* msg, size_t n) {
    if (!e->ops->hook) {
        snprintf(msg, n, "H: this world has no hook (the sandbox has one)");
        return -1;
    }
    const bool had = engine_attached(e);
    // The nearest load as the hook stands before it acts: what a failed
    // attach names.
    double dist = INFINITY, reach = 0;
    const int near = e->ops->nearest_load ? e->ops->nearest_load(e, &dist, &reach) : -1;
    const int got = engine_hook(e, attach);
    double mass = 0;
    if (attach && got >= 0) {
        const char* nm = engine_load_name(e, got, &mass);
        snprintf(msg, n, "hooked %s (%.0f kg)", nm ? nm : "a load", mass);
    } else if (attach) {
        const char* nm = near >= 0 ? engine_load_name(e, near, NULL) : NULL;
        if (nm)
            snprintf(msg, n, "H: no load in reach of the hook (nearest: %s, %.2f m away; reach %.2f m)", nm, dist,
                     reach);
        else snprintf(msg, n, "H: no load in reach of the hook (this world has no loads)");
    } else {
        snprintf(msg, n, had ? "released the load" : "nothing on the hook to release");
    }
    return got;
}

const char* engine_load_name(const engine* e, int i, double* mass) {
    return e->ops->hook ? e->ops->load_name(e, i, mass) : NULL;
}

bool engine_part_energy(const engine* e, double E[2]) {
    if (!e->ops->part_energy) return false;
    e->ops->part_energy(e, E);
    return true;
}

bool engine_attached(const engine* e) { return e->ops->hook ? e->ops->attached(e) : false; }
hyd_model* engine_circuit(engine* e) { return e->ops->circuit(e); }

int engine_follow_energy(engine* e, struct sim_energy* en) {
    if (!en || !e->ops->follow_energy || sim_energy_bind(en, engine_circuit(e))) return -1;
    return e->ops->follow_energy(e, en);
}

void engine_set_load(engine* e, double m3) {
    if (e->ops->set_load) e->ops->set_load(e, m3);
}

bool engine_can_set_load(const engine* e) { return e->ops->set_load != NULL; }
bool engine_can_resize_links(const engine* e) { return e->ops->resize_links; }

int engine_set_link(engine* e, int k, const crane_link* ln) {
    return e->ops->set_link ? e->ops->set_link(e, k, ln) : -1; // -1: no two-link booms (a chain engine)
}
int engine_ncol(const engine* e) { return e->ncol > 0 ? e->ncol : e->ops->nchannel; }

void engine_circuit_state(engine* e, double* y, const hyd_data** in) {
    const hyd_data* d = NULL;
    e->ops->circuit_state(e, y, &d);
    if (in) *in = d;
}

const sim_channel* engine_channels(const engine* e, int* n) {
    *n = engine_ncol(e);
    return e->chan ? e->chan : sim_channels;
}

const sim_channel* engine_channels_for(const sim_opts* o, int* n) {
    // None for a value that names no backend (engine_run refuses it).
    *n = backend(o) ? backend(o)->nchannel : 0;
    return sim_channels;
}
double engine_time(const engine* e) { return e->ops->time(e); }
void engine_row(engine* e, double* row) {
    e->ops->row(e, row);
    fill_rcl(e, row);
}
bool engine_snapshot(engine* e, world_snapshot* s) {
    if (!e->ops->snapshot) return false;
    e->ops->snapshot(e, s);
    s->rcl_have = e->rcl != NULL;
    s->rcl_on = e->rcl && e->o.rcl;
    s->rcl_util = e->rcl ? e->rcl->util : 0.0;
    // Cylinder k (lift, jib, slew) carries command k.
    for (int k = 0; k < s->ncyl && k < WORLD_SNAP_MAX_CYLINDERS; ++k) {
        world_snap_cylinder* c = &s->cyl[k];
        // A crane chain's cylinders: the chain's actuators first, each on its function.
        const crane_chain* cc = e->mdl ? &e->mdl->chain : NULL;
        const int f = !e->ops->set_function_commands ? k : (cc && k < cc->nact ? cc->act[k].function : -1);
        c->rcl_cut = f >= 0 && f < e->nfn && (f < 3 || e->ops->set_function_commands) && s->rcl_on &&
                     e->u_lim[f] != e->u_op[f];
        if (c->rcl_cut) {
            c->u_op = e->u_op[f];
            continue;
        }
        c->u_op = c->rcl_cut ? e->u_op[k] : c->u_cmd;
    }
    return true;
}
const char* engine_error(const engine* e) { return e->err; }
const sim_collisions* engine_collisions(const engine* e) {
    return e->ops->collisions ? e->ops->collisions(e) : NULL;
}

void engine_note(const engine* e, char* note, size_t n) {
    sim_checks_note(&e->chk, hyd_method_is_adaptive(e->o.solver), note, n);
}

// Advance dt [s], check the state reached, hand its row on.
static int advance(engine* e, double dt, engine_row_fn row_fn, void* user) {
    if (e->failed) return 1;
    if (e->ops->step(e, dt)) {
        e->failed = true;
        return 1;
    }
    // The same checks as run's, on the row the driver records and shows: a
    // drive that exits 0 while recording -26 MPa absolute is a wrong result
    // passing as valid.
    double* row = e->rowbuf;
    e->ops->row(e, row);
    fill_rcl(e, row);
    char what[200];
    const int rc = sim_check_row(&e->chk, row, e->ops->nchannel, what, sizeof what);
    if (rc) {
        char how[64];
        snprintf(how, sizeof how, "solver %s", hyd_method_name(e->o.solver));
        sim_check_message(e->err, sizeof e->err, what, how, hyd_method_is_adaptive(e->o.solver), row[COL_T],
                          e->chk.bad_value);
        e->failed = true;
        return 1;
    }
    return row_fn && row_fn(user, row) ? 2 : 0;
}

int engine_advance_to(engine* e, double t_to, engine_row_fn row_fn, void* user) {
    return advance(e, t_to - e->ops->time(e), row_fn, user);
}

// dt is passed on as given (not as a target time and back), so a driver
// that steps by dt takes exactly the steps it took before the engine existed.
int engine_advance(engine* e, double dt) { return advance(e, dt, NULL, NULL); }
