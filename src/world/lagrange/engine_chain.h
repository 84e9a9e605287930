// engine_chain.h: scripted runs (engine_run) of the general analytic mode,
// chain_sim.h, for any crane chain: what engine_lagrange.c runs for every
// model that is not the two-link shorthand, and for the two-link one with
// the variant "general" (docs/lagrange.md, "The general formulation").
#ifndef ENGINE_CHAIN_H
#define ENGINE_CHAIN_H

#include "engine_impl.h"

#ifdef __cplusplus
extern "C" {
#endif

/// As engine_ops.run. The rows are sim.h's base columns (the first two
/// actuators and functions in the x1 .. F2 columns, the first two boom DOFs
/// in q1, q2), then for a chain model the chain's own columns
/// (crane_chain_row: per actuator, function and DOF). Refuses (SIM_REFUSED, one line) CVODE and the
/// variants paper and paper-typo (the paper's two-link equations).
int engine_chain_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k, sim_result* res);

/// The start pose of chain cc [chain_ndof of its mechanism, slew first when
/// it slews] for scenario sc: the slew at sc->slew0, the first two boom DOFs
/// at sc->q0 (the paper's q1, q2), every other DOF at the middle of its
/// joint limits (0 when either is open, clamped into the other).
void engine_chain_start_pose(const crane_chain* cc, const scenario* sc, double* q0);

#ifdef __cplusplus
}
#endif
#endif
