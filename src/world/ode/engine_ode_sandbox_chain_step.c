// engine_ode_sandbox_chain_step.c: a crane chain in the sandbox (ode_world
// with the chain on its truck, ode_world.h opts.chain) behind engine.h as a
// stepped engine (engine_ode_sandbox_chain_step.h). The scripted sandbox run
// (engine_ode_chain.c, run_sandbox) sets the functions' commands and the
// slew at each ODE step's midpoint and plays the hook events there; a driver
// stepping one ODE step at a time with engine_play_functions sets the same
// commands at the same times, and both write their rows with
// ode_chain_sandbox_row, so the two give the same rows.
#include "engine_ode_sandbox_chain_step.h"
#include "energy_acc.h"
#include "engine_ode_chain.h"
#include "ode_chain.h"
#include "ode_chain_row.h"
#include "ode_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/// Collision pairs read from the world per ODE step (it records at most 16).
#define OSC_COLL_REPORT 16

typedef struct eng_osc {
    engine base;
    ode_world* w;
    ode_chain* cw;             ///< the hosted chain (ode_world_chain), the world's
    const crane_chain* cc;     ///< the model's chain (its columns; the model outlives the engine)
    ode_chain_rows r;          ///< the hosted chain's outputs (shared with the scripted run)
    bool rows_ready;
    int islew;                 ///< the command that drives the slew rack: "slew"'s index
    sim_collisions coll;       ///< the sandbox's collisions since create, every ODE step
    struct sim_energy* energy; ///< engine_follow_energy's balance, or NULL
} eng_osc;

static eng_osc* SC(engine* e) { return (eng_osc*)e; }
static const eng_osc* SCc(const engine* e) { return (const eng_osc*)e; }

static void osc_destroy(engine* e) {
    eng_osc* c = SC(e);
    if (c->rows_ready) ode_chain_rows_free(&c->r);
    ode_world_destroy(c->w);
    free(c);
}

static engine* osc_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3,
                          char* err, size_t errsz) {
    (void)m3; // the sandbox's loads hang on the hook: no tip load (as the scripted run)
    if (o->cvode) {
        snprintf(err, errsz, "--solver cvode: the sandbox's chain crane sub-steps its circuit with a fixed-step "
                             "method (krus, ros2, rk4)");
        return NULL;
    }
    eng_osc* c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    c->base.ops = &engine_ode_sandbox_chain_step_ops;
    c->base.o = *o;
    c->cc = &m->chain;
    // The scripted run's world (run_sandbox): the same start, no tip load.
    c->w = ode_world_for_run(m, o, "sandbox", q0, slew0, 0.0, err, errsz);
    if (!c->w) {
        free(c);
        return NULL;
    }
    c->cw = ode_world_chain(c->w);
    if (!c->cw) { // ode_world_for_run builds every chain that is not two_link from the chain
        snprintf(err, errsz, "%s: the sandbox built no chain crane for this model", m->file[0] ? m->file : "model");
        osc_destroy(&c->base);
        return NULL;
    }
    const crane_chain* hc = ode_chain_chain(c->cw); // the hosted copy: the column slews
    hyd_model* hm = ode_world_circuit(c->w);
    const int nc = ode_chain_row_ncol(c->cc);
    double* row0 = calloc((size_t)nc + 1, sizeof *row0);
    if (!row0 || ode_chain_rows_init(&c->r, hc, hm, ode_chain_ndof(c->cw))) {
        snprintf(err, errsz, "out of memory");
        free(row0);
        osc_destroy(&c->base);
        return NULL;
    }
    c->rows_ready = true;
    // The slew: the model's function of that name, else one more command
    // after the model's (engine.slew_function, engine_nfunction).
    c->islew = crane_chain_find_function(c->cc, "slew");
    if (c->islew < 0) {
        c->islew = c->cc->nfn;
        c->base.slew_function = true;
    }
    c->base.ncol = nc;
    // The hydraulic sub-step is min(--dt, ODE step), as ode_world_for_run sets it.
    const double dt = ode_world_dt(c->w), h = o->h < dt ? o->h : dt;
    c->base.h_probe = h; // the step probe follows in engine.c (engine_create_rcl)
    sim_checks chk;
    memset(&chk, 0, sizeof chk);
    int rc = sim_check_fixed_step(hm, o, h, 0.0, err, errsz);
    if (!rc) rc = engine_ode_chain_sandbox_start(c->w, &c->r, c->cc, q0, &chk, row0, err, errsz);
    free(row0);
    if (rc) {
        osc_destroy(&c->base);
        return NULL;
    }
    return &c->base;
}

static void osc_set_function_commands(engine* e, const double* u) {
    eng_osc* c = SC(e);
    // The model's functions, and the slew rack (as the scripted run: the
    // scenario's slew column on the rack, by name).
    ode_chain_set_commands(c->cw, u);
    ode_chain_set_slew_command(c->cw, u[c->islew]);
}

static int osc_step(engine* e, double dt) {
    eng_osc* c = SC(e);
    ode_world* w = c->w;
    // One ODE step at a time, the collisions and the bodies' energy after
    // each (as the scripted run: a touch shorter than a frame counts). The
    // step count is ode_world_step's for dt, so the motion is the same.
    const double h = ode_world_dt(w), steps = floor(dt / h + 0.5);
    long n = steps > 1e12 ? (long)1e12 : (long)steps;
    if (n < 1) n = 1;
    for (long i = 0; i < n; ++i) {
        if (ode_world_step(w, h)) {
            snprintf(e->err, sizeof e->err, "numerical blow-up: %s", ode_world_error(w));
            return 1;
        }
        if (c->energy) sim_energy_mech(c->energy, ode_world_energy(w));
        const char* pairs[OSC_COLL_REPORT][2];
        const int np = ode_world_collisions(w, pairs, OSC_COLL_REPORT);
        if (np >= 0) sim_collisions_step(&c->coll, ode_world_time(w), (const char* const(*)[2])pairs, np);
    }
    return 0;
}

static void osc_row(engine* e, double* row) {
    eng_osc* c = SC(e);
    ode_chain_sandbox_row(&c->r, c->w, c->cc, ode_world_time(c->w), row);
}

static double osc_time(const engine* e) { return ode_world_time(SCc(e)->w); }
static hyd_model* osc_circuit(engine* e) { return ode_world_circuit(SC(e)->w); }
static void osc_circuit_state(engine* e, double* y, const hyd_data** in) {
    ode_world_circuit_state(SC(e)->w, y, in);
}

static int osc_hook(engine* e, int attach) { return ode_world_hook(SC(e)->w, attach); }
static const char* osc_load_name(const engine* e, int i, double* mass) {
    return ode_world_load_name(SCc(e)->w, i, mass);
}
static int osc_nearest_load(const engine* e, double* dist, double* reach) {
    return ode_world_nearest_load(SCc(e)->w, dist, reach);
}
static bool osc_attached(const engine* e) {
    ode_world_state st;
    ode_world_get_state(SCc(e)->w, &st);
    return st.attached >= 0;
}

static void osc_part_energy(const engine* e, double E[2]) { ode_world_part_energy(SCc(e)->w, &E[0], &E[1]); }
static const sim_collisions* osc_collisions(const engine* e) { return &SCc(e)->coll; }
static void osc_snapshot(engine* e, world_snapshot* s) { ode_world_snapshot(SC(e)->w, s); }

static int osc_follow_energy(engine* e, struct sim_energy* en) {
    eng_osc* c = SC(e);
    if (ode_world_follow_energy(c->w, en)) return -1;
    sim_energy_mech(en, ode_world_energy(c->w));
    c->energy = en;
    return 0;
}

const engine_ops engine_ode_sandbox_chain_step_ops = {
    .name = "ode",
    .create = osc_create,
    .nchannel = SIM_NCOL, // the sandbox's channels, then the chain's columns (engine.ncol)
    .destroy = osc_destroy,
    .set_function_commands = osc_set_function_commands,
    .hook = osc_hook,
    .load_name = osc_load_name,
    .attached = osc_attached,
    .nearest_load = osc_nearest_load,
    .circuit = osc_circuit,
    .circuit_state = osc_circuit_state,
    .part_energy = osc_part_energy,
    .step = osc_step,
    .time = osc_time,
    .row = osc_row,
    .snapshot = osc_snapshot,
    .collisions = osc_collisions,
    .follow_energy = osc_follow_energy,
    // Not yet for chains (engine.h answers each): no limiter (rcl.h reads
    // the two-link crane), no two-link commands (set_commands: by function),
    // no boom edits (set_link), no tip load (the loads hang on the hook), no
    // scripted run here (engine_ode_ops.run takes it).
};
