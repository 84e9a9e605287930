// engine.c: the backend-independent half of engine.h: dispatch to the
// backend's engine_ops, and the run checks every engine applies after a step.
#include "engine_impl.h"

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

// The backend o->mechanics names: the one place that chooses by it.
static const engine_ops* backend(const sim_opts* o) {
    return o->mechanics == SIM_ODE ? &engine_ode_ops : &engine_lagrange_ops;
}

engine* engine_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                      size_t errsz) {
    return backend(o)->create(m, o, q0, slew0, m3, err, errsz);
}

int engine_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k, sim_result* res) {
    return backend(o)->run(m, sc, o, k, res);
}

void engine_play(engine* e, const scenario* sc, double tm, int* ev, double u[3], engine_hook_fn on_hook,
                 void* user) {
    play_ctx pc = {e, on_hook, user};
    scenario_play(sc, tm, ev, u, play_hook, &pc);
}

void engine_destroy(engine* e) {
    if (e) e->ops->destroy(e);
}

const char* engine_backend_name(const engine* e) { return e->ops->name; }

void engine_describe(const sim_opts* o, engine_desc* d) {
    memset(d, 0, sizeof *d);
    d->backend = backend(o)->name;
    backend(o)->describe(o, d);
}

void engine_describe_work(const sim_opts* o, const sim_result* r, char* buf, size_t n) {
    backend(o)->describe_work(o, r, buf, n);
}
void engine_set_commands(engine* e, const double u[3]) { e->ops->set_commands(e, u); }
int engine_hook(engine* e, int attach) { return e->ops->hook ? e->ops->hook(e, attach) : -1; }

const char* engine_load_name(const engine* e, int i, double* mass) {
    return e->ops->hook ? e->ops->load_name(e, i, mass) : NULL;
}

bool engine_attached(const engine* e) { return e->ops->hook ? e->ops->attached(e) : false; }
hyd_model* engine_circuit(engine* e) { return e->ops->circuit(e); }

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
    *n = backend(o)->nchannel;
    return sim_channels;
}
double engine_time(const engine* e) { return e->ops->time(e); }
void engine_row(engine* e, double row[SIM_NCOL]) { e->ops->row(e, row); }
void engine_snapshot(engine* e, world_snapshot* s) { e->ops->snapshot(e, s); }
const char* engine_error(const engine* e) { return e->err; }

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
