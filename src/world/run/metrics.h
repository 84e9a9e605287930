// metrics.h: the metrics of one run (peak pressures, relief time, end-stop
// hits, truck tilt), accumulated from its rows through the one channel list
// (sim_channels), whatever the backend. `cranesim run` prints them in its
// summary and writes them with --metrics; `cranesim sweep` tabulates them.
#ifndef METRICS_H
#define METRICS_H

#include <stdbool.h>
#include <stdio.h>

#include "sim.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The metrics a run can have, by id. Which ones a run has depends only on
/// its channel count (metrics_present): a metric whose channels the backend
/// does not write is absent, not zero.
typedef enum metric_id {
    MET_PEAK_P1A, MET_PEAK_P1B, MET_PEAK_P2A, MET_PEAK_P2B, ///< [Pa abs], over every step when the run tracked them
    MET_PEAK_P3A, MET_PEAK_P3B,                             ///< slew chambers [Pa abs], over the rows (ode)
    MET_PEAK_P_PUMP,                                        ///< [Pa abs], over the rows
    MET_RELIEF_TIME,     ///< time with any relief valve passing flow [s], at row resolution
    MET_STOP_LIFT, MET_STOP_JIB, MET_STOP_SLEW, ///< end-stop hits (entries into a stop) [count]
    MET_MAX_TILT,        ///< largest truck tilt from vertical [rad] (ode)
    // From the energy accounting (metrics_energy), over every integration
    // step: absent until a run's balance is added.
    MET_ENERGY_IN,       ///< energy delivered by the pumps and tanks [J]
    MET_ENERGY_LOSS,     ///< energy lost in valves, reliefs, checks, orifices, hoses, leakage [J]
    // The hook against the end-arm tip it hangs from (ode): the rope's angle
    // from vertical and the hook's horizontal offset from the tip.
    MET_MAX_SWAY,        ///< largest hook sway angle [rad]
    MET_MAX_SWAY_AMP,    ///< largest hook sway amplitude (horizontal offset) [m]
    // The truck's supports (ode; zeros in the validation world), over the
    // rows from ODE_SUPPORT_SETTLE_T on (the truck lands on its pads first).
    MET_MIN_PAD_F,       ///< smallest vertical reaction on any support [N]
    MET_MIN_STAB_MARGIN, ///< smallest stability margin [-]
    MET_PAD_LIFTOFFS,    ///< supports lifting off: entries below ODE_PAD_LIFT_FRAC of the pads' sum [count]
    // From the run's collisions (sim_result.coll, every ODE step; the ode
    // sandbox): absent where the world has no contacts (validation).
    MET_COLLISIONS,      ///< collision events, a pair starting to touch [count]
    MET_COUNT
} metric_id;

/// Reliefs whose open time a run's metrics name (more are summed into none).
#define METRICS_MAXRELIEF 16

typedef struct run_metrics {
    int ncol;                   ///< the run's channel count
    double value[MET_COUNT];    ///< in the unit of metric_unit
    bool present[MET_COUNT];
    bool per_step[MET_COUNT];   ///< a peak over every integration step (else over the rows)
    long rows;
    double t_prev;              ///< the previous row's time [s]
    double relief_sum, relief_c;  ///< the relief time's row intervals, compensated sum [s]
    int stop_prev;              ///< the previous row's end_stop bits
    int nrelief;                ///< reliefs named (metrics_energy)
    char relief_name[METRICS_MAXRELIEF][64]; ///< component names
    double relief_time[METRICS_MAXRELIEF];   ///< time each passed flow [s], over every step
    long pad_rows;              ///< rows that counted for the support metrics
    int pad_lift_prev;          ///< the previous such row's lifted supports (bits)
    bool pads_seen;             ///< a row had support forces (a truck on the ground)
    sim_collisions coll;        ///< the pairs behind MET_COLLISIONS (metrics_finish)
} run_metrics;

/// Start the metrics of a run that writes ncol channels (sim_ncol).
void metrics_init(run_metrics* m, int ncol);
/// Add one output row (ncol values). Relief time: the interval since the
/// previous row counts when this row has a relief open; the sum is given to
/// 1 ns (metric_time), so 7431 rows of 1 ms read 7.431 s. End-stop hits: a
/// bit of end_stop that is set in this row and was clear in the previous one
/// (a run that starts at a stop counts one).
void metrics_row(run_metrics* m, const double* row);
/// After the run: the chamber peaks over every step from r when it tracked
/// them (r->peak_steps) and they are higher than the rows' (they always are
/// when every step is a row, and equal). The collisions (count and pairs)
/// from r->coll, where the world reports them.
void metrics_finish(run_metrics* m, const sim_result* r);

struct sim_energy;
/// After a run with the energy accounting (sim_run_energy): energy in and
/// losses from its balance, and each relief's open time (by component name).
void metrics_energy(run_metrics* m, const struct sim_energy* e);

/// Which metrics a run of ncol channels has (before it runs: for a table's
/// header). Energy in and losses: every run that has the energy accounting.
bool metrics_present(metric_id id, int ncol);
/// The name used in --metrics lists, the JSON file and the sweep's CSV
/// ("peak_p1A"), and the unit ("Pa", "s", "count", "rad").
const char* metric_name(metric_id id);
const char* metric_unit(metric_id id);
/// The id of a name, or -1.
int metric_find(const char* name);
/// The names, comma separated, for messages.
void metric_names(char* buf, size_t n);

/// The summary's block: a few lines, each starting with two spaces.
void metrics_print(const run_metrics* m, FILE* f);
/// The JSON document: {"metrics": {"NAME": {"value": V, "unit": U, "over": "steps"|"rows"}, ...}}
/// and, after metrics_energy, "relief_open_time.COMPONENT" for each relief; with collisions,
/// "collisions" (the collision_count metric) and "collision_pairs": [{"bodies": "A x B", "first_t": T}, ...].
/// (absent metrics left out; numbers with 17 significant digits). Returns 0, or -1 on a write error.
int metrics_write_json(const run_metrics* m, FILE* f);

#ifdef __cplusplus
}
#endif
#endif
