// engine_ode_chain.h: scripted runs of the ode backend for a chain model
// (crane_chain.two_link false) in the ODE chain world (ode_chain.h) or the
// sandbox built from the chain, what engine_ode.c's run takes for every
// model that is not the two-link shorthand (docs/ode_world.md, "The chain
// world behind the engine", "The sandbox from the chain").
#ifndef ENGINE_ODE_CHAIN_H
#define ENGINE_ODE_CHAIN_H

#include "engine_impl.h"
#include "world_desc.h"

#ifdef __cplusplus
extern "C" {
#endif

/// As engine_ops.run: in the validation world the chain world, in a
/// sandbox or site world the sandbox with the crane from the chain
/// (ode_world.h opts.chain; its base columns the sandbox's, the slew rack in
/// x3 ... F3, the hook, loads and supports; the scenario's slew and hook
/// events played; rcl_util 0, the limiter not applied). The rows are the
/// analytic general path's: the base columns hold the first two actuators,
/// their functions and the first two boom DOFs; every actuator and function
/// goes to engine_sink.chain_row. The scenario commands the functions by
/// name at each ODE step's midpoint. Refuses (SIM_REFUSED, one line)
/// adaptive solvers and CVODE (the circuit is sub-stepped with a fixed
/// step), an ODE step above 10 ms or one the hydraulic step does not
/// divide, bursts at nodes the model lacks, a sandbox start pose that puts
/// the tip in the ground.
int engine_ode_chain_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k,
                         sim_result* res);

/// The options the chain world (the validation world) takes, as both its
/// scripted run and its stepped engine (engine_ode_chain_step.c) check
/// them: a fixed-step solver, an ODE step of at most 10 ms that the
/// hydraulic step divides. 0 with the ODE step and the hydraulic sub-step
/// [s] in *dt_ode, *h_hyd; -1 with one line in msg.
int engine_ode_chain_check(const sim_opts* o, double* dt_ode, double* h_hyd, char* msg, size_t msz);

/// The kind of the world o names (the validation world when none): the
/// validation world runs in the chain world, a sandbox in ode_world with
/// the crane from the chain. -1 with the world loader's message.
int engine_ode_chain_world_kind(const sim_opts* o, world_kind* kind, char* err, size_t errsz);

struct ode_world;
struct ode_chain_rows;
/// The start of a sandbox w hosting the chain crane of model chain cc
/// (ode_world_chain), as its scripted run and its stepped engine
/// (engine_ode_sandbox_chain_step.c) check it: the row at t = 0 into row
/// (ode_chain_sandbox_row, r bound to the hosted chain), the run checks
/// (sim_check_row into chk) and the start pressures with the world's rope
/// and hook at the tip (sim_check_start; q0 [rad] the scenario's pose, for
/// its message). 0, or -1 with one line in msg.
int engine_ode_chain_sandbox_start(struct ode_world* w, struct ode_chain_rows* r, const crane_chain* cc,
                                   const double q0[2], sim_checks* chk, double* row, char* msg, size_t msz);

#ifdef __cplusplus
}
#endif
#endif
