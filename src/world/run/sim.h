// sim.h: one headless run of a model on a scenario, whatever the backend.
// This is what `cranesim run`, `compare` and `bench` drive, and what tests use.
// The options, the result, the channels and the checks are sim_base.h's
// (what a backend is given and reports); here are the runs, the CSV and the
// step probe, which choose and drive a backend through the engine.
#ifndef SIM_H
#define SIM_H

#include <stdbool.h>
#include <stdio.h>

#include "lagrange_sim.h" // the values of sim_opts.variant (lagrange.h), and lsim for the tests and benches that drive it
#include "sim_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The fixed step above which a stepped engine's Krus or ROS2 step is
/// probed [s]: the default step, at which every shipped model and scenario
/// runs (their tests), is not.
#define SIM_PROBE_ABOVE 1e-4
/// Refuse, before a run starts (scripted, or a stepped engine: drive,
/// serve, replay), a Krus or ROS2 step h [s] above SIM_PROBE_ABOVE that
/// blows up on model m's abrupt valve steps or integrates them too far off:
/// the `step` scenario's commands (lift, jib, lowering; 500 kg, 6.5 s) are
/// run on the lagrange backend at h and at SIM_PROBE_ABOVE with o's solver
/// and Jacobian settings, and a stroke more than 5 % RMS of its peak off,
/// or a chamber pressure more than 15 %, refuses h. No bound on the
/// circuit's fastest mode separates the steps that work from those that do
/// not (docs/solvers.md: the LS crane at Krus 0.2 ms is 25 % off where the
/// standard crane at 1 ms, h|lambda| as large, is 0.2 %). The message says
/// where, and names the largest step of {5, 2, 1} x 10^k dividing
/// o->dt_out that passes (else SIM_PROBE_ABOVE). Returns SIM_OK, or
/// SIM_REFUSED with one line in err. Other methods, CVODE, h <=
/// SIM_PROBE_ABOVE and o->no_step_probe always pass.
int sim_check_step_probe(const model* m, const sim_opts* o, double h, char* err, size_t errsz);

/// A recorded run held in memory (for plots and comparisons).
typedef struct sim_trace {
    int nrow, cap;
    double* v; ///< nrow x SIM_NCOL, row-major
} sim_trace;
void sim_trace_free(sim_trace* tr);

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

/// Number of CSV columns a run with these options writes (base, or base plus
/// the world extras for the ode backend).
int sim_ncol(const sim_opts* o);
/// Write the CSV header line (the first ncol column names) to f.
void sim_csv_header(FILE* f, int ncol);
/// Write one row of ncol values; full precision, C locale.
void sim_csv_row(FILE* f, const double* row, int ncol);

#ifdef __cplusplus
}
#endif
#endif
