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

engine* engine_create_rcl(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3,
                          struct rcl* r, char* err, size_t errsz) {
    if (!backend(o)) {
        unknown_backend(o, err, errsz);
        return NULL;
    }
    engine* e = backend(o)->create(m, o, q0, slew0, m3, err, errsz);
    if (!e) return NULL;
    e->mdl = m;
    // The step probe on the backend's hydraulic step, after its own start
    // checks: it runs the analytic backend (step_probe.c), which a backend
    // may not call, so the engine applies it for every backend.
    if (sim_check_step_probe(m, o, e->h_probe, err, errsz)) {
        e->ops->destroy(e);
        return NULL;
    }
    // The limiter filters every command a stepped driver sets (drive, the
    // window's tick, the soak bench, serve): one place for all of them.
    if (r) rcl_reset(r);
    // A stepped engine's world, when o names none, is its drive world.
    e->rcl = r ? r : engine_rcl_create(m, o, engine_backend_of(o)->drive_world);
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
    return cc->nfn + (crane_chain_find_function(cc, "slew") < 0 ? 1 : 0);
}

const char* engine_function_name(const engine* e, int k) {
    const crane_chain* cc = &e->mdl->chain;
    if (k >= 0 && k < cc->nfn) return cc->fn[k].name;
    return k == cc->nfn && crane_chain_find_function(cc, "slew") < 0 ? "slew" : NULL;
}

void engine_set_function_commands(engine* e, const double* u) {
    // The stepped engines are the two-link crane's (lift, jib) and the
    // world's slew: their commands go through engine_set_commands (and its
    // limiter). A function of another name has no stepped engine yet.
    double u3[3] = {e->u_op[0], e->u_op[1], e->u_op[2]};
    for (int k = 0; k < engine_nfunction(e); ++k) {
        const char* nm = engine_function_name(e, k);
        for (int c = 0; c < SCENARIO_NCMD; ++c)
            if (!strcmp(nm, scenario_cmd_name[c])) u3[c] = u[k];
    }
    engine_set_commands(e, u3);
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
    e->ops->destroy(e);
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
    // The operator's demand and what was let through, for the HUD (it shows
    // both where the limiter cut).
    memcpy(e->u_op, u, sizeof e->u_op);
    memcpy(e->u_lim, u, sizeof e->u_lim);
    if (!e->rcl || !e->o.rcl) {
        if (e->rcl) { // still measured, for the HUD and the record
            double row[SIM_NCOL];
            e->ops->row(e, row);
            rcl_utilisation(e->rcl, row);
        }
        e->ops->set_commands(e, u);
        return;
    }
    double row[SIM_NCOL], v[3];
    e->ops->row(e, row);
    rcl_filter(e->rcl, row, u, v);
    memcpy(e->u_lim, v, sizeof e->u_lim);
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

int engine_set_link(engine* e, int k, const crane_link* ln) { return e->ops->set_link(e, k, ln); }
int engine_ncol(const engine* e) { return e->ops->nchannel; }

void engine_circuit_state(engine* e, double* y, const hyd_data** in) {
    const hyd_data* d = NULL;
    e->ops->circuit_state(e, y, &d);
    if (in) *in = d;
}

const sim_channel* engine_channels(const engine* e, int* n) {
    *n = e->ops->nchannel;
    return sim_channels;
}

const sim_channel* engine_channels_for(const sim_opts* o, int* n) {
    // None for a value that names no backend (engine_run refuses it).
    *n = backend(o) ? backend(o)->nchannel : 0;
    return sim_channels;
}
double engine_time(const engine* e) { return e->ops->time(e); }
void engine_row(engine* e, double row[SIM_NCOL]) {
    e->ops->row(e, row);
    fill_rcl(e, row);
}
void engine_snapshot(engine* e, world_snapshot* s) {
    e->ops->snapshot(e, s);
    s->rcl_have = e->rcl != NULL;
    s->rcl_on = e->rcl && e->o.rcl;
    s->rcl_util = e->rcl ? e->rcl->util : 0.0;
    // Cylinder k (lift, jib, slew) carries command k.
    for (int k = 0; k < s->ncyl && k < WORLD_SNAP_MAX_CYLINDERS; ++k) {
        world_snap_cylinder* c = &s->cyl[k];
        c->rcl_cut = k < 3 && s->rcl_on && e->u_lim[k] != e->u_op[k];
        c->u_op = c->rcl_cut ? e->u_op[k] : c->u_cmd;
    }
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
    double row[SIM_NCOL];
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
