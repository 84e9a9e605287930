// engine_ode_chain_step.h: the stepped engine (engine_create: drive, bench
// soak) of the ode backend for a crane chain (crane_chain.two_link false),
// in the ODE chain world (ode_chain.h, the validation world): what
// engine_ode_ops.stepped chooses for every model that is not the two-link
// shorthand in the validation world (a sandbox world takes
// engine_ode_sandbox_chain_step.h).
#ifndef ENGINE_ODE_CHAIN_STEP_H
#define ENGINE_ODE_CHAIN_STEP_H

#include "engine_impl.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Commands by function (engine_set_function_commands), rows as the
/// scripted run's (ode_chain_row.h: the SIM_NCOL channels, then the
/// chain's), the circuit, its state and the energy balance; whole ODE steps
/// (engine_advance_to ends on the step nearest its target, at least one).
/// No snapshot, limiter, boom edits, tip-load edits, hook, collisions or
/// part energies (NULL in its ops; engine.h answers each). Its create
/// refuses (one line) what the scripted run refuses (engine_ode_chain_check:
/// a world other than the validation world, adaptive solvers, an ODE step
/// above 10 ms or one the hydraulic step does not divide), CVODE, bursts at
/// nodes the model lacks and a start the run checks refuse.
extern const engine_ops engine_ode_chain_step_ops;

#ifdef __cplusplus
}
#endif
#endif
