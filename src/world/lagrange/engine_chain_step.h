// engine_chain_step.h: the stepped engine (engine_create: drive, bench soak)
// of the general analytic mode (chain_sim.h) for any crane chain: what the
// lagrange backend's engine_ops.stepped chooses for every model that is not
// the two-link shorthand, and for the two-link one with --variant general.
#ifndef ENGINE_CHAIN_STEP_H
#define ENGINE_CHAIN_STEP_H

#include "engine_impl.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Commands by function (engine_set_function_commands), rows as the
/// scripted run's (chain_row.h: base columns, then the chain's), the
/// circuit, its state and the energy balance. No snapshot, limiter, boom
/// edits, tip-load edits or hook (NULL in its ops; engine.h answers each).
/// Its create refuses (one line) the variants paper and paper-typo, CVODE,
/// bursts at nodes the model lacks, a start pose out of stroke and a start
/// the run checks refuse.
extern const engine_ops engine_chain_step_ops;

#ifdef __cplusplus
}
#endif
#endif
