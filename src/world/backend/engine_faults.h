// engine_faults.h: a scenario's fault events on a circuit: the model with
// a closed orifice at each burst (engine_fault_model), the bursts a world's
// circuit must hold (engine_world_bursts), and the events applied as a
// backend steps (engine_faults_apply). Every backend and the engine use them.
#ifndef ENGINE_FAULTS_H
#define ENGINE_FAULTS_H

#include <stddef.h>

#include "hydraulics.h"
#include "model.h"
#include "scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The model a scenario with fault events runs on: a copy of m with a
/// closed orifice to the tank at each node a hose burst names (engine_run
/// makes it itself; a stepped driver passes it to engine_create). NULL with
/// "file: faults[i].at: problem" in err.
model* engine_fault_model(const model* m, const scenario* sc, char* err, size_t errsz);
/// The bursts of m at nodes the model's circuit lacks (model.world_bursts)
/// against the world circuit fragment that a backend appends (NULL: none,
/// as in the lagrange backend and the validation world): 0 when each of
/// their nodes is declared there (a volume, a hose, "<cylinder>.A"/".B"),
/// else -1 with "scenario: faults[i].at: no node 'X' in the circuit of
/// model.json" (and "or of world.json" when there is a fragment) in err.
int engine_world_bursts(const model* m, const cJSON* fragment, const char* world_file, char* err, size_t errsz);

/// Fault events of a scenario (scenario.h) applied to a running circuit:
/// each backend's scripted run calls engine_faults_apply at every step or
/// breakpoint with the circuit it integrates. The bursts' orifices were
/// added, closed, by engine_run (engine_fault_model).
typedef struct engine_faults {
    int pump;      ///< the pump component, or -1
    double qmax0;  ///< its flow before any stop [m^3/s]
} engine_faults;
void engine_faults_init(engine_faults* f, const hyd_model* hm);
/// Sets the burst areas and the pump's flow for time t [s]; only values
/// that change are set (each set re-derives the circuit). Returns 1 if any
/// changed.
int engine_faults_apply(const engine_faults* f, hyd_model* hm, const scenario* sc, double t);

#ifdef __cplusplus
}
#endif
#endif
