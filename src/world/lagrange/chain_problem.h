// chain_problem.h: the general analytic mode's ODE problem as the fixed-step
// runs take it: chain_sim_problem (chain_sim.h) with the two hooks the
// closed form's problem has (lsim_problem, lagrange_sim.c) and chain_sim
// does not give:
//   - events (hyd_problem.events): the circuit's switches that stiffen it,
//     by hyd_events_update (hyd_events.h) at the chain's strokes, rates and
//     commands, so a reused Jacobian is taken again when the circuit gets
//     stiffer than it describes. Without it Krus at 0.1 ms rang up on the
//     8-function model's telescopic stages (a seal's friction steepening
//     100-fold as a light stage came to rest under a J taken while it
//     moved) and blew up at 7.943 s (docs/lagrange.md);
//   - implausible (hyd_problem.implausible): an absolute pressure more than
//     0.1 MPa below zero, where the run checks stop the run, so that such a
//     fixed step is retried in shorter ones first (solver.c).
// f, the Jacobian, the block pattern and settle are chain_sim's own.
#ifndef CHAIN_PROBLEM_H
#define CHAIN_PROBLEM_H

#include <stdbool.h>

#include "chain_sim.h"
#include "hyd_events.h"
#include "hyd_solver.h"
#include "sim_base.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct chain_problem {
    chain_sim* cs;
    hyd_problem base;  ///< chain_sim_problem(cs, blocks)
    hyd_events* ev;    ///< owned
    double *x, *v;     ///< [ncylinder] strokes [m] and rates [m/s] at the events' state (scratch)
    double* cmd;       ///< [nvalve] the valves' commands [-] (scratch)
} chain_problem;

/// Sets up cp for cs (initialised, and alive while cp is used) and returns
/// the problem to hand to hyd_solver_create (its user is cp). 0, or -1 when
/// out of memory or when chain_sim's problem has a hook this wrapper does
/// not forward (a step kernel of its own); cp then needs no
/// chain_problem_free. Hooks chain_sim's problem has itself (events,
/// implausible, outside, dfdt) are kept: its own events count on top of
/// these, its own implausible replaces this one.
int chain_problem_init(chain_problem* cp, chain_sim* cs, bool blocks, hyd_problem* out);
void chain_problem_free(chain_problem* cp);

/// hyd_problem.events of chain_problem_init's problem (user: the
/// chain_problem), for callers that step the chain themselves.
unsigned long chain_problem_events(void* user, double t, const double* y);

/// The problem and the solver options of a run of options o on cs, for the
/// model's chain mc (its shape chooses the W): one set-up for the scripted
/// runs (engine_chain.c) and the stepped engine (engine_chain_step.c), so the
/// same commands give the same steps. The block-diagonal W and no Jacobian
/// events on the two-link shape (the shorthand or that shape in chain form)
/// with a fixed-step method, else the whole W with the events. 0, or -1 as
/// chain_problem_init (cp then needs no chain_problem_free).
int chain_problem_setup(chain_problem* cp, chain_sim* cs, const crane_chain* mc, const sim_opts* o,
                        hyd_problem* prob, hyd_solver_opts* so);

#ifdef __cplusplus
}
#endif

#endif
