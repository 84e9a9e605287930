// rcl.h: the rated capacity limiter. The load moment is measured as a
// limiter on a real crane measures it: from the lift cylinder's chamber
// pressures and the joint angles (the booms' own moment subtracted), not
// from the load's mass; the utilisation is that moment over the load chart's
// rated moment at the current outreach (and slew sector on the truck). At
// 90 % it warns; from 90 % of the utilisation ahead (the same load at the
// weakest chart point the tip reaches within RCL_LOOK_T) it slows, with a
// ramp, and at 100 % it stops the motions that increase the load moment
// (lift down, jib out, slewing towards a weaker sector), leaving those that
// reduce it free. docs/safety.md.
#ifndef RCL_H
#define RCL_H
#include <stdbool.h>
#include <stddef.h>

#include "loadchart.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RCL_WARN 0.90  ///< utilisation of the warning [-]
#define RCL_SLOW 0.90  ///< utilisation where the increasing motions start to slow [-]
#define RCL_TAU 1.0    ///< the load moment's low-pass filter: two stages of RCL_TAU / 2 each [s]
#define RCL_LOOK_T 0.5 ///< how far ahead in time the limiter looks along the outreach [s]
#define RCL_RAMP 0.25  ///< the shortest time the limiter takes to stop a full-speed motion [s]
/// Stroke band at either end of the lift cylinder's stroke inside which its
/// pressures are not load [m]: a cylinder on its end stop carries the stop's
/// force too (with the valve open, up to the pump's pressure), which a
/// pressure-based limiter cannot tell from load.
#define RCL_STOP_BAND 0.01

struct lc_chain;
typedef struct rcl {
    const model* m;
    loadchart chart;
    double AA, AB;     ///< lift cylinder piston and annulus areas [m^2]
    double util;       ///< last utilisation [-], from the filtered load moment
    double util_ahead; ///< the utilisation the same load would have ahead, where the motion is going [-]
    double R;          ///< the outreach at the last utilisation [m]
    double allow;      ///< fraction of the increasing motions let through at the last filter [-]
    double t_allow;    ///< the time of that filter [s]
    double m_filt;     ///< the filtered load estimate, moment over outreach over g [kg]
    double m_stage;    ///< the first of the filter's two stages [kg]
    double rd_env;     ///< envelope of the outreach speed (peak, decaying by RCL_TAU) [m/s]
    double t_last;     ///< the time it was last updated [s]
    double stroke;     ///< the lift cylinder's stroke [m]
    double x_lift;     ///< the lift cylinder's stroke at the last utilisation, from q1 [m]
    bool have;         ///< t_last and rd_env hold values
    bool have_load;    ///< m_filt holds a measured value (a row with trusted pressures came)
    bool held;         ///< the last row's lift cylinder was within RCL_STOP_BAND of an end stop:
                       ///< its pressures were not used, the load estimate held
    bool warn;         ///< util >= RCL_WARN
    bool stopped;      ///< the last filter cut a command
    // A crane chain (docs/safety.md "On a crane chain"): its statics
    // (lc_chain.h) and where its columns are in the rows (rcl_set_chain_row).
    bool chain;
    struct lc_chain* g;
    int row_base;      ///< the chain's first column in a row (-1: not set: utilisation 0)
    int* col_q;        ///< [nd] q_<body> of each boom DOF (row index)
    int* col_qd;       ///< [nd] qd_<body>
    int col_pA, col_pB;///< the lift actuator's pA_, pB_
    double* q;         ///< [nd] scratch
    double* gain;      ///< [chain functions] outreach per metre of the function's stroke at the last row [m/m]
} rcl;

/// Build the limiter for model m on world wd (NULL or validation: the
/// hydraulic limit only), with the default chart options over the crane's
/// whole reach. Returns 0, or -1 with one line in err. A crane chain: the
/// chain's chart (loadchart.h) and statics, refused in one line where
/// rcl_check_model refuses it; its rows' layout comes from rcl_set_chain_row.
int rcl_init(rcl* r, const model* m, const world_desc* wd, char* err, size_t errsz);
/// The allow-list of a crane chain's limiter, without its chart (fast): 0,
/// or -1 with one line in err (the two-link crane: always 0).
int rcl_check_model(const model* m, char* err, size_t errsz);
/// A crane chain's rows carry the columns of chain cols (crane_chain_columns;
/// NULL: the model's chain; a slewing run's own chain has the slew rack's
/// besides) from index base on (the engine's nchannel): where the limiter
/// reads the boom joints, their rates and the lift cylinder's pressures. 0,
/// or -1 when a column is missing (the limiter then reads 0).
int rcl_set_chain_row(rcl* r, const crane_chain* cols, int base);
/// As rcl_init, for the world file of an ode run (NULL: no world, lagrange).
int rcl_init_world(rcl* r, const model* m, const char* world_path, char* err, size_t errsz);
void rcl_free(rcl* r);
/// rcl_init_world on a new limiter (world_path NULL: no world), or NULL
/// when its chart cannot be made or memory is short; rcl_destroy frees it
/// (NULL is fine). The engine and the ode run make theirs this way.
rcl* rcl_create(const model* m, const char* world_path);
void rcl_destroy(rcl* r);
/// Start again: the state rcl_init leaves (no measurement, nothing cut),
/// keeping the chart.
void rcl_reset(rcl* r);

/// Utilisation [-] from a CSV row (t, p1A, p1B, q1, q2, slew columns; slew
/// 0 when absent). Also stored in r->util. The load the moment implies
/// (moment / (g outreach)) is low-pass filtered (RCL_TAU) and multiplied
/// back by the current outreach, as a limiter filters its pressure
/// transducers but not its angle sensors: the
/// chamber pressures ring by several MPa when a motion starts or stops, and
/// a limiter acting on that would stop and free the crane by turns. Rows
/// at the same time as the last one leave the filter as it is; an earlier
/// time (a rewind) restarts it.
///
/// Within RCL_STOP_BAND of either end of the lift cylinder's stroke (from
/// q1, as a limiter knows it from its angle sensor) the pressures are not
/// taken: the filter's input is cut and its second stage settles on the
/// first, so the estimate holds the last load measured clear of the stop
/// (0 until one was). The jib cylinder's stop needs nothing: its force acts
/// between the two booms and cancels in the moment about joint 1.
double rcl_utilisation(rcl* r, const double* row);

/// The command filter: the operator's commands u_in (lift, jib, slew in
/// [-1, 1]; positive extends the lift and jib cylinders and increases the
/// slew angle) into u_out, from the state in row. Returns the utilisation.
double rcl_filter(rcl* r, const double* row, const double u_in[3], double u_out[3]);

/// A crane chain's command filter: n commands u_in by function (the
/// chain's functions in order, then possibly more: islew, if >= 0, is the
/// slew's) into u_out. A function whose stroke carries the tip outwards at
/// this pose (its cylinders' dR/ds summed, from the chain's Jacobian and
/// lever arms) is slowed and stopped as rcl_filter's; the slew as there;
/// anything else passes. Returns the utilisation.
double rcl_filter_fn(rcl* r, const double* row, int n, const double* u_in, double* u_out, int islew);
/// The outreach gained per metre of stroke of chain function f at the
/// row's pose [m/m] (0 below 1 mm per metre): what rcl_filter_fn cuts on.
double rcl_function_gain(rcl* r, const double* row, int f);

#ifdef __cplusplus
}
#endif
#endif
