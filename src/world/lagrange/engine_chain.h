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
///
/// A run that slews (engine_chain_slews) runs the chain of
/// engine_chain_slew_setup: the column a degree of freedom driven by the
/// slew rack; its rows carry that chain's columns (the rack's, the slew
/// function's, the slew DOF's; for the two-link model only these), and it
/// says so through k->run_chain.
int engine_chain_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k, sim_result* res);

/// True when a run of scenario sc on model m slews the column: m has a
/// slew drive (chain.slew.present) and sc's slew commands are not all 0.
/// (A scenario that only starts slewed does not: the column stands still.)
bool engine_chain_slews(const model* m, const scenario* sc);

/// The chain and circuit of a slewing run of m: *cc a copy of m->chain with
/// slew_free set, bound to *hm, the model's circuit with hydraulics_slew
/// appended (model_circuit_with_fragment, from m->json: the document with
/// the run's overrides). Both the caller's to free (crane_chain_free,
/// hyd_model_free). 0, or -1 with one line in err (no slew drive, the
/// fragment does not compile).
int engine_chain_slew_setup(const model* m, crane_chain* cc, hyd_model** hm, char* err, size_t errsz);

/// The start pose of chain cc [chain_ndof of its mechanism, slew first when
/// it slews] for scenario sc: the slew at sc->slew0, the first two boom DOFs
/// at sc->q0 (the paper's q1, q2), every other DOF at the middle of its
/// joint limits (0 when either is open, clamped into the other).
void engine_chain_start_pose(const crane_chain* cc, const scenario* sc, double* q0);

#ifdef __cplusplus
}
#endif
#endif
