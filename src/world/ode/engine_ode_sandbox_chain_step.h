// engine_ode_sandbox_chain_step.h: the stepped engine (engine_create: drive,
// bench soak) of the ode backend for a crane chain (crane_chain.two_link
// false) in a sandbox world: the ode_world that hosts the chain on its truck
// (ode_world.h opts.chain), what engine_ode_ops.stepped chooses for a chain
// model whose world (sim_opts.world) is a sandbox.
#ifndef ENGINE_ODE_SANDBOX_CHAIN_STEP_H
#define ENGINE_ODE_SANDBOX_CHAIN_STEP_H

#include "engine_impl.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Commands by function: the model's functions, then "slew" (the slew
/// drive of the sandbox, the model's mechanics.slew or the world's) where
/// the model has no function of that name (engine.slew_function); the hook
/// (attach, release, the loads by name, the nearest load); rows as the
/// scripted sandbox run's (ode_chain_sandbox_row: the sandbox's SIM_NCOL
/// columns, then the chain's); collisions and the energy balance at every
/// ODE step; part energies; the snapshot (the chain's bodies as boxes, its
/// cylinders, the rope, hook, truck and terrain). Whole ODE steps
/// (engine_advance_to ends on the step nearest its target, at least one).
/// No limiter (rcl.h reads the two-link crane), no boom or tip-load edits
/// and no two-link commands (NULL in its ops; engine_require answers each).
/// Its create refuses (one line) CVODE and what ode_world_for_run refuses
/// for a chain (adaptive solvers, an ODE step above 10 ms, a slew drive
/// missing from the circuit, ...) and a start the run checks refuse
/// (engine_ode_chain_sandbox_start).
extern const engine_ops engine_ode_sandbox_chain_step_ops;

#ifdef __cplusplus
}
#endif
#endif
