// engine_chain_step.c: the general analytic mode (chain_sim.h) behind
// engine.h as a stepped engine: the chain and its circuit integrated by an
// outside loop, with the functions' commands held between steps
// (engine_chain_step.h). The scripted run (engine_chain.c) reads a
// scenario's commands continuously inside f; this engine holds what the
// driver set, as the closed form's stepped engine does.
#include "engine_chain_step.h"
#include "chain_problem.h"
#include "chain_row.h"
#include "chain_sim.h"
#include "energy_acc.h"
#include "lagrange.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct eng_chain {
    engine base;
    chain_sim cs;
    hyd_model* hm;             ///< the model's circuit (engine_circuit)
    chain_problem cp;          ///< the problem's events and checks (chain_problem.h), as the scripted runs'
    bool cp_ready;             ///< cp is set up (chain_problem_free)
    hyd_problem prob;
    hyd_solver* solver;
    double t;                  ///< [s]
    double* y;                 ///< [cs.n] the system state (chain_sim.h's order)
    chain_sim_out co;          ///< output buffers for the rows, sized by the chain
    double* obuf;              ///< their storage
    struct sim_energy* energy; ///< engine_follow_energy's balance, or NULL
} eng_chain;

static eng_chain* C(engine* e) { return (eng_chain*)e; }

static void ch_destroy(engine* e) {
    eng_chain* c = C(e);
    hyd_solver_destroy(c->solver);
    if (c->cp_ready) chain_problem_free(&c->cp);
    chain_sim_free(&c->cs);
    free(c->y);
    free(c->obuf);
    free(c);
}

static void ch_row(engine* e, double* row) {
    eng_chain* c = C(e);
    chain_sim_row(&c->cs, c->t, c->y, &c->co, row);
}

static engine* ch_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                         size_t errsz) {
    if (o->variant == LAGRANGE_PAPER || o->variant == LAGRANGE_PAPER_TYPO) {
        snprintf(err, errsz,
                 "--variant %s: the paper's equations are for the two-link crane only; this crane chain takes the "
                 "general formulation (full or general)",
                 lagrange_variant_name(o->variant));
        return NULL;
    }
    if (o->cvode) {
        snprintf(err, errsz, "--solver cvode: the general analytic mode runs the in-house solvers");
        return NULL;
    }
    // No world circuit here: a burst at a node the model lacks has nowhere to open.
    if (engine_world_bursts(m, NULL, NULL, err, errsz)) return NULL;
    eng_chain* c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    c->base.ops = &engine_chain_step_ops;
    c->base.o = *o;
    c->base.h_probe = o->h; // the step probe follows in engine.c (engine_create_rcl)
    c->base.ncol = chain_row_ncol(&m->chain);
    c->hm = m->hyd;
    chain_sim* cs = &c->cs;
    if (chain_sim_init(cs, &m->chain, m->hyd, m3, slew0, err, errsz)) {
        free(c);
        return NULL;
    }
    const size_t na = (size_t)cs->nact, nf = (size_t)cs->nfn, nd = (size_t)cs->ndof;
    c->y = calloc((size_t)cs->n + 1, sizeof *c->y);
    c->obuf = calloc(5 * na + 2 * nf + 3 * nd + (size_t)chain_row_size(&m->chain) + 1, sizeof *c->obuf);
    if (!c->y || !c->obuf) {
        snprintf(err, errsz, "out of memory");
        ch_destroy(&c->base);
        return NULL;
    }
    double* b = c->obuf;
    c->co.x = b, c->co.v = b + na, c->co.pA = b + 2 * na, c->co.pB = b + 3 * na, c->co.F = b + 4 * na;
    c->co.u = b + 5 * na, c->co.u_cmd = c->co.u + nf, c->co.q = c->co.u_cmd + nf, c->co.qd = c->co.q + nd;
    double* qs = c->co.qd + nd;   // the start pose [nd]
    double* row0 = qs + nd;       // a row [chain_row_size]
    // The scripted run's start (engine_chain_start_pose): the first two boom
    // DOFs at q0, the slew at slew0, the others mid-limits.
    crane_chain_start_pose(&m->chain, q0, slew0, qs);
    if (chain_sim_check_pose(cs, qs, err, errsz) || chain_sim_initial_state(cs, qs, 0.5e6, c->y, err, errsz) ||
        sim_check_fixed_step(m->hyd, o, o->h, 0.0, err, errsz)) {
        ch_destroy(&c->base);
        return NULL;
    }
    chain_sim_row(cs, 0.0, c->y, &c->co, row0);
    const sim_start_load ld = {m->chain.two_link ? &m->mech : NULL, {q0[0], q0[1]}, m3, false};
    if (sim_check_start(m->hyd, row0, SIM_NCOL_BASE, &ld, err, errsz)) {
        ch_destroy(&c->base);
        return NULL;
    }
    // The scripted run's solver options (engine_chain.c), so that the same
    // commands give the same steps.
    hyd_solver_opts so;
    if (chain_problem_setup(&c->cp, cs, &m->chain, o, &c->prob, &so)) {
        snprintf(err, errsz, "out of memory for the chain's problem");
        ch_destroy(&c->base);
        return NULL;
    }
    c->cp_ready = true;
    c->solver = hyd_solver_create(&c->prob, o->solver, &so);
    if (!c->solver) {
        snprintf(err, errsz, "cannot create the %s solver", hyd_method_name(o->solver));
        ch_destroy(&c->base);
        return NULL;
    }
    return &c->base;
}

// Commands by function: engine_nfunction of them; the chain's first cs.nfn
// (the two-link crane with --variant general has the sandbox's slew after
// them, which this planar crane does not have).
static void ch_set_function_commands(engine* e, const double* u) {
    eng_chain* c = C(e);
    for (int f = 0; f < c->cs.nfn; ++f) {
        const double v = u[f] < -1 ? -1 : u[f] > 1 ? 1 : u[f] == u[f] ? u[f] : 0.0;
        // A command change is a kink in the input: adaptive methods restart
        // their step-size history there (decision 8).
        if (v != c->cs.cmd[f] && hyd_method_is_adaptive(e->o.solver)) hyd_solver_reset(c->solver);
        c->cs.cmd[f] = v;
    }
}

static int ch_step(engine* e, double dt) {
    eng_chain* c = C(e);
    // Commands or a fault may have changed since the last step at the same
    // state: the balance's next step starts from their powers.
    if (c->energy) sim_energy_follow_inputs(c->energy, c->t, c->y);
    const int rc = hyd_solver_advance(c->solver, &c->t, c->y, c->t + dt);
    if (rc == HYD_OK) return 0;
    double tb = c->t;
    const int i = hyd_solver_bad_state(c->solver, &tb);
    const char* name = i < 0                       ? "?"
                       : i < c->cs.nh              ? hyd_model_state_name(c->hm, c->cs.perm[i])
                       : i < c->cs.iq + c->cs.ndof ? "q"
                                                   : "q_dot";
    snprintf(e->err, sizeof e->err, "solver %s failed (%s) at t = %.6g s, state %s", hyd_method_name(e->o.solver),
             hyd_error_text(rc), tb, name);
    return 1;
}

static double ch_time(const engine* e) { return ((const eng_chain*)e)->t; }
static hyd_model* ch_circuit(engine* e) { return C(e)->hm; }

// The system state holds the circuit's states permuted (chain_sim.hpos).
static void ch_circuit_state(engine* e, double* y, const hyd_data** in) {
    eng_chain* c = C(e);
    for (int j = 0; j < c->cs.nh; ++j) y[j] = c->y[c->cs.hpos[j]];
    *in = c->cs.hd;
}

// sim_energy_eval_fn: the circuit at (t, y) with every output filled.
static const hyd_data* energy_eval(void* user, double t, const double* y) {
    chain_sim* cs = user;
    chain_sim_rhs(cs, t, y, cs->ydot);
    --cs->nrhs; // not solver work
    return cs->hd;
}

static void energy_step(void* user, double t, const double* y) {
    eng_chain* c = user;
    sim_energy_follow_step(c->energy, c->solver, t, y, chain_sim_energy(&c->cs, y));
}

static int ch_follow_energy(engine* e, struct sim_energy* en) {
    eng_chain* c = C(e);
    if (sim_energy_follow(en, c->cs.n, energy_eval, &c->cs) ||
        sim_energy_follow_sample(en, c->t, c->y, chain_sim_energy(&c->cs, c->y)))
        return -1;
    c->energy = en;
    hyd_solver_set_on_step(c->solver, energy_step, c);
    return 0;
}

const engine_ops engine_chain_step_ops = {
    .name = "lagrange",
    .create = ch_create,
    .nchannel = SIM_NCOL_BASE, // the base list (no world), then the chain's columns (engine.ncol)
    .destroy = ch_destroy,
    .set_function_commands = ch_set_function_commands,
    .circuit = ch_circuit,
    .circuit_state = ch_circuit_state,
    .step = ch_step,
    .time = ch_time,
    .row = ch_row,
    .follow_energy = ch_follow_energy,
    // Not yet for chains (engine.h answers each): no hook or loads, no
    // snapshot for the renderer, no two-link booms to edit, the tip load
    // built into the mechanism (chain_sim_init), no limiter (rcl.h refuses
    // chains), no scripted run here (engine_lagrange_ops.run takes it).
};
