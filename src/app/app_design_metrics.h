// app_design_metrics.h: the metrics sweep and optimize tabulate and bound,
// by name: the run metrics (metrics.h, ids 0 .. MET_COUNT-1) and a crane
// chain model's per actuator and function (ids MET_COUNT and up), named as
// run --metrics names them ("peak_pA.lift", "end_stop_hits.ext1",
// "max_spool.ext"; app_chain_out.c). docs/sweep.md lists them.
#ifndef APP_DESIGN_METRICS_H
#define APP_DESIGN_METRICS_H

#include <stdbool.h>
#include <stddef.h>

#include "app.h"
#include "metrics.h"

/// The chain metrics of model m (none for the two-link shorthand): set once,
/// before any design runs; the ids below refer to them. 0, or -1 out of memory.
int app_design_metrics_setup(const model* m);
void app_design_metrics_free(void);
/// MET_COUNT plus the chain's; the chain's alone.
int app_design_metric_count(void);
int app_design_metric_chain_count(void);
/// The id of a metric by name (a run metric, or "<what>.<name>" of the
/// chain), or -1.
int app_design_metric_find(const char* name);
/// Its name and SI unit (metric_unit's strings: "Pa", "m", "N", "count", "-").
const char* app_design_metric_name(int id);
const char* app_design_metric_unit(int id);
/// True when a run of ncol base columns has it (a chain metric: always, on its model).
bool app_design_metric_present(int id, int ncol);
/// The names, for a message: the run metrics, then the chain's by kind and name.
void app_design_metric_names(char* buf, size_t n);

/// One design's run: its metrics (over the base columns) and its chain's.
typedef struct app_design_run {
    run_metrics met;
    app_chain_stats cst;
    const struct crane_chain* chain; ///< pass &chain to sim_run_energy_chain (the run's, from its first row)
    int ncol;                        ///< the run's base columns (sim_ncol): the chain's follow
    bool oom;
} app_design_run;
void app_design_run_init(app_design_run* r, const model* m, int ncol);
/// The row callback (sim_row_fn): stops when a signal was caught.
int app_design_row(void* user, const double* row);
/// Metric id's value after the run [SI], NaN when the run has none.
double app_design_value(const app_design_run* r, int id);
void app_design_run_free(app_design_run* r);

#endif
