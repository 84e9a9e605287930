// sim.h: one headless run of a model on a scenario, whatever the backend.
// This is what `cranesim run`, `compare` and `bench` drive, and what tests use.
// The options, the result, the channels and the checks are sim_base.h's
// (what a backend is given and reports), the step probe step_probe.h's;
// here are the runs and the CSV, which drive a backend through the engine.
#ifndef SIM_H
#define SIM_H

#include <stdbool.h>
#include <stdio.h>

#include "lagrange_sim.h" // the values of sim_opts.variant (lagrange.h), and lsim for the tests and benches that drive it
#include "sim_base.h"
#include "step_probe.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Called for every output row; return non-zero to stop the run.
typedef int (*sim_row_fn)(void* user, const double* row);

/// Run the scenario. Rows go to row_fn (may be NULL) and to trace (may be
/// NULL). progress (may be NULL) is called about every 0.1 s of wall time.
typedef void (*sim_progress_fn)(void* user, double t, double t_end);
int sim_run(const model* m, const scenario* sc, const sim_opts* o, sim_row_fn row_fn, void* row_user,
            sim_trace* trace, sim_progress_fn progress, void* progress_user, sim_result* res);

struct sim_energy;
/// sim_run that also accumulates the energy balance into energy
/// (energy_acc.h; NULL: none, which is sim_run). energy must have been made
/// for the circuit the run uses (model_circuit_for).
int sim_run_energy(const model* m, const scenario* sc, const sim_opts* o, sim_row_fn row_fn, void* row_user,
                   sim_trace* trace, sim_progress_fn progress, void* progress_user, struct sim_energy* energy,
                   sim_result* res);
/// sim_run_energy that also says which chain the rows' own columns follow
/// when it is not the model's (engine_sink.run_chain): *run_chain is set
/// before the first row where the run adds columns (the analytic mode's
/// slewing run, the slew rack's) and left as it is otherwise; the chain it
/// points to lives until the run returns.
int sim_run_energy_chain(const model* m, const scenario* sc, const sim_opts* o, sim_row_fn row_fn, void* row_user,
                         sim_trace* trace, sim_progress_fn progress, void* progress_user, struct sim_energy* energy,
                         const crane_chain** run_chain, sim_result* res);

/// Number of CSV columns a run with these options writes (base, or base plus
/// the world extras for the ode backend).
int sim_ncol(const sim_opts* o);
/// Write the CSV header line (the first ncol column names) to f.
void sim_csv_header(FILE* f, int ncol);
/// The header of ncol base columns followed by a chain model's own columns
/// (crane_chain.col, next of them: per actuator, function and degree of
/// freedom), as a chain backend's rows carry them after its base columns.
void sim_csv_header_ext(FILE* f, int ncol, const crane_column* ext, int next);
/// Write one row of ncol values; full precision, C locale.
void sim_csv_row(FILE* f, const double* row, int ncol);

#ifdef __cplusplus
}
#endif
#endif
