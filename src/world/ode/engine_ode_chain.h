// engine_ode_chain.h: scripted runs of the ode backend for a chain model
// (crane_chain.two_link false) in the ODE chain world (ode_chain.h), what
// engine_ode.c's run takes for every model that is not the two-link
// shorthand (docs/ode_world.md, "The chain world behind the engine").
#ifndef ENGINE_ODE_CHAIN_H
#define ENGINE_ODE_CHAIN_H

#include "engine_impl.h"

#ifdef __cplusplus
extern "C" {
#endif

/// As engine_ops.run, in the validation world only. The rows are the
/// analytic general path's: the base columns hold the first two actuators,
/// their functions and the first two boom DOFs; every actuator and function
/// goes to engine_sink.chain_row. The scenario commands the functions by
/// name at each ODE step's midpoint. Refuses (SIM_REFUSED, one line) a
/// world other than the validation world, adaptive solvers and CVODE (the
/// circuit is sub-stepped with a fixed step), an ODE step above 10 ms or
/// one the hydraulic step does not divide, bursts at nodes the model lacks.
int engine_ode_chain_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k,
                         sim_result* res);

/// The options a chain world takes, as both its scripted run and its
/// stepped engine (engine_ode_chain_step.c) check them: the validation world,
/// a fixed-step solver, an ODE step of at most 10 ms that the hydraulic
/// step divides. 0 with the ODE step and the hydraulic sub-step [s] in
/// *dt_ode, *h_hyd; -1 with one line in msg.
int engine_ode_chain_check(const sim_opts* o, double* dt_ode, double* h_hyd, char* msg, size_t msz);

#ifdef __cplusplus
}
#endif
#endif
