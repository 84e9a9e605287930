// engine_ode_chain_step.c: the ODE chain world (ode_chain.h) behind engine.h
// as a stepped engine (engine_ode_chain_step.h): the functions' commands
// held between steps, set by the driver; the scripted run
// (engine_ode_chain.c) sets them from its scenario at each ODE step's
// midpoint, which a driver stepping one ODE step at a time with
// engine_play_functions reproduces.
#include "engine_ode_chain_step.h"
#include "energy_acc.h"
#include "engine_ode_chain.h"
#include "ode_chain.h"
#include "ode_chain_row.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct eng_ode_chain {
    engine base;
    ode_chain* w;
    ode_chain_rows r;          ///< outputs and row (shared with the scripted run)
    bool rows_ready;
    hyd_model* hm;             ///< the model's circuit, the world's (ode_chain_opts.circuit)
    double dt;                 ///< the ODE step [s]
    struct sim_energy* energy; ///< engine_follow_energy's balance, or NULL
} eng_ode_chain;

static eng_ode_chain* OC(engine* e) { return (eng_ode_chain*)e; }

static void oc_destroy(engine* e) {
    eng_ode_chain* c = OC(e);
    ode_chain_destroy(c->w);
    if (c->rows_ready) ode_chain_rows_free(&c->r);
    free(c);
}

static void oc_row(engine* e, double* row) {
    eng_ode_chain* c = OC(e);
    ode_chain_make_row(&c->r, c->w, ode_chain_time(c->w), row);
}

static engine* oc_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                         size_t errsz) {
    if (o->cvode) {
        snprintf(err, errsz, "--solver cvode: the ODE chain world sub-steps its circuit with a fixed-step method "
                             "(krus, ros2, rk4)");
        return NULL;
    }
    // The chain world is the validation world; ode_stepped takes a sandbox
    // to engine_ode_sandbox_chain_step.c. A world that is neither (or a
    // world file that does not load) is refused here.
    world_kind kind;
    if (engine_ode_chain_world_kind(o, &kind, err, errsz)) return NULL;
    if (kind != WORLD_VALIDATION) {
        snprintf(err, errsz, "%s %s: the ODE chain world is the validation world (a sandbox world runs the chain on "
                             "its truck)",
                 sim_param_name(SIM_PARAM_WORLD), o->world);
        return NULL;
    }
    double dt, h;
    if (engine_ode_chain_check(o, &dt, &h, err, errsz)) return NULL;
    // No world circuit here: a burst at a node the model lacks has nowhere to open.
    if (engine_world_bursts(m, NULL, NULL, err, errsz)) return NULL;
    const crane_chain* cc = &m->chain;
    eng_ode_chain* c = calloc(1, sizeof *c);
    const int nd = crane_chain_ndof(cc), nc = ode_chain_row_ncol(cc);
    double* buf = calloc((size_t)nd + (size_t)nc + 1, sizeof *buf);
    if (!c || !buf || ode_chain_rows_init(&c->r, cc, m->hyd, nd)) {
        snprintf(err, errsz, "out of memory");
        free(c);
        free(buf);
        return NULL;
    }
    c->rows_ready = true;
    c->base.ops = &engine_ode_chain_step_ops;
    c->base.o = *o;
    c->base.h_probe = h; // the step probe follows in engine.c (engine_create_rcl)
    c->base.ncol = nc;
    c->hm = m->hyd;
    c->dt = dt;
    double* qs = buf;      // the start pose [nd]
    double* row0 = qs + nd; // a row [nc]
    // The scripted run's world (engine_ode_chain_run): the analytic general
    // path's start pose, the same start pressures.
    crane_chain_start_pose(cc, q0, slew0, qs);
    ode_chain_opts co = ode_chain_default_opts();
    co.dt_ode = dt;
    co.dt_hyd = h;
    co.solver = o->solver;
    co.jac_every = o->jac_every > 0 ? o->jac_every : 1;
    co.tip_mass = m3;
    co.q0 = qs;
    co.slew0 = slew0;
    co.circuit = m->hyd;
    co.p_low = 0.5e6;
    co.model_file = m->file[0] ? m->file : "model";
    c->w = ode_chain_create(cc, &co, err, errsz);
    int rc = c->w ? 0 : -1;
    if (!rc) rc = sim_check_fixed_step(m->hyd, o, h, 0.0, err, errsz);
    if (!rc) {
        // The start state, as the scripted run checks it.
        ode_chain_make_row(&c->r, c->w, 0.0, row0);
        sim_checks chk;
        memset(&chk, 0, sizeof chk);
        char what[200];
        if (sim_check_row(&chk, row0, SIM_NCOL_BASE, what, sizeof what)) {
            sim_check_message(err, errsz, what, NULL, false, 0.0, chk.bad_value);
            rc = -1;
        }
    }
    if (!rc) {
        const sim_start_load ld = {NULL, {q0[0], q0[1]}, m3, false};
        rc = sim_check_start(m->hyd, row0, SIM_NCOL_BASE, &ld, err, errsz);
    }
    free(buf);
    if (rc) {
        oc_destroy(&c->base);
        return NULL;
    }
    return &c->base;
}

static void oc_set_function_commands(engine* e, const double* u) { ode_chain_set_commands(OC(e)->w, u); }

static int oc_step(engine* e, double dt) {
    eng_ode_chain* c = OC(e);
    // One ODE step at a time, the bodies' energy after each (as the
    // scripted run); the count is ode_chain_step's for dt.
    const double steps = floor(dt / c->dt + 0.5);
    long n = steps > 1e12 ? (long)1e12 : (long)steps;
    if (n < 1) n = 1;
    for (long i = 0; i < n; ++i) {
        if (ode_chain_step(c->w, c->dt)) {
            snprintf(e->err, sizeof e->err, "numerical blow-up: %s", ode_chain_error(c->w));
            return 1;
        }
        if (c->energy) sim_energy_mech(c->energy, ode_chain_energy(c->w));
    }
    return 0;
}

static double oc_time(const engine* e) { return ode_chain_time(((const eng_ode_chain*)e)->w); }
static hyd_model* oc_circuit(engine* e) { return OC(e)->hm; }

static void oc_circuit_state(engine* e, double* y, const hyd_data** in) {
    eng_ode_chain* c = OC(e);
    const double* yw;
    ode_chain_circuit_state(c->w, &yw, in);
    memcpy(y, yw, (size_t)hyd_model_nstate(c->hm) * sizeof *y);
}

static int oc_follow_energy(engine* e, struct sim_energy* en) {
    eng_ode_chain* c = OC(e);
    if (ode_chain_follow_energy(c->w, en)) return -1;
    sim_energy_mech(en, ode_chain_energy(c->w));
    c->energy = en;
    return 0;
}

const engine_ops engine_ode_chain_step_ops = {
    .name = "ode",
    .create = oc_create,
    .nchannel = SIM_NCOL, // the ode backend's channels, then the chain's columns (engine.ncol)
    .destroy = oc_destroy,
    .set_function_commands = oc_set_function_commands,
    .circuit = oc_circuit,
    .circuit_state = oc_circuit_state,
    .step = oc_step,
    .time = oc_time,
    .row = oc_row,
    .follow_energy = oc_follow_energy,
    // Not yet for chains (engine.h answers each): the validation world has
    // no hook, loads, collisions or rope; no snapshot for the renderer; no
    // two-link booms to edit; the tip load merged into the tip body; no
    // limiter (rcl.h refuses chains); no scripted run here
    // (engine_ode_ops.run takes it).
};
