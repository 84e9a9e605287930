// engine_types.h: the types a backend and the engine's users share
// (engine.h, engine_impl.h): the engine handle, what a backend says about a
// run (engine_desc), where a scripted run's rows go (engine_sink).
#ifndef ENGINE_TYPES_H
#define ENGINE_TYPES_H

#include <stdbool.h>
#include <stddef.h>

#include "model.h"
#include "sim_base.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct engine engine;

/// What the backend o->mechanics chooses says about a run with options o,
/// for the drivers' reports: they print these fields instead of asking which
/// backend runs.
typedef struct engine_desc {
    const char* backend;   ///< "lagrange", "ode"
    const char* world;     ///< the world the options name ("validation" when none); "" without a world
    char label[320];       ///< the run in summaries: "ode/validation", "ode world FILE" (a path), "lagrange/full"
    char title[160];       ///< the run in plot titles: "ode/validation", "full"
    double dt_outer;       ///< the rigid-body step the hydraulics are sub-stepped in [s] (the
                           ///< options' value); 0: no such step
    bool h_reduced;        ///< the fixed hydraulic step asked for is longer than dt_outer, which is used
    const char* step_name; ///< what a peak over every step is taken over: "ODE step", "step"
} engine_desc;
/// Called for each row engine_advance_to produces; non-zero stops it.
typedef int (*engine_row_fn)(void* user, const double* row);
/// A check of a run's fixed hydraulic step h [s] on model m with options
/// o: SIM_OK, or SIM_REFUSED with one line in err (sim_check_step_probe).
typedef int (*engine_probe_fn)(const model* m, const sim_opts* o, double h, char* err, size_t errsz);

/// Where a scripted run's rows go (engine_run).
typedef struct engine_sink {
    /// Each output row (may be NULL); non-zero stops the run. A row holds the
    /// backend's channels (engine_channels_for), and for a chain model
    /// (model.chain.ncol > 0) the chain's own columns right after them
    /// (crane_chain_row: per actuator, function and degree of freedom).
    engine_row_fn row;
    void* user;
    bool rows;         ///< someone consumes rows: else (benchmarks) the output evaluation is skipped
    bool summary;      ///< someone reads the summary: peaks over every step, not only the rows
    double t_end;      ///< the run's end [s] (> 0; checked by the caller, sim_check_times)
    /// NULL, or the energy balance to accumulate at every integration step
    /// (energy_acc.h; at the rows with CVODE, whose steps are its own).
    struct sim_energy* energy;
    /// The step probe a backend's scripted run applies to its fixed
    /// hydraulic step h [s] after its own start checks, before it
    /// integrates (NULL: none). engine_run sets it to sim_check_step_probe
    /// (sim.h), which runs the analytic backend through the run layer: passed
    /// in here, so a backend needs nothing of the layer that chooses it.
    engine_probe_fn probe;
    /// NULL, or where a run whose rows carry other chain columns than the
    /// model's (model.chain.col) puts the chain they follow, before its
    /// first row; it lives until the run returns. The analytic mode's
    /// slewing run (engine_chain.h) adds the slew rack's columns. Untouched
    /// by a run whose columns are the model's.
    const crane_chain** run_chain;
} engine_sink;

#ifdef __cplusplus
}
#endif
#endif
