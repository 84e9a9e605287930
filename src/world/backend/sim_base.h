// sim_base.h: what a backend is given and reports, whatever the backend:
// the run's options (sim_opts), its result (sim_result), the output channel
// list and its columns (COL_*), the run checks every driver and engine
// applies, collisions. The half of sim.h the backends need; sim.h adds the
// runs themselves (sim_run), the CSV and the step probe, which choose and
// drive a backend (docs/architecture.md, "Folders of src/world").
#ifndef SIM_BASE_H
#define SIM_BASE_H

#include <stdbool.h>
#include <stddef.h>

#include "hyd_solver.h"
#include "model.h"
#include "param_names.h"
#include "scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum sim_mechanics { SIM_LAGRANGE = 0, SIM_ODE } sim_mechanics;

/// What a run or a check of the world library reports, with its text in a
/// message buffer. The library does not choose exit codes: src/app maps these
/// (app_exit_code).
typedef enum sim_status {
    SIM_OK = 0,      ///< done
    SIM_FAILED = 1,  ///< a numerical failure during the run (the rows so far are valid)
    SIM_REFUSED = 2, ///< refused before it started (bad input, an impossible setting), or stopped by
                     ///< the row callback
} sim_status;

/// The one choice of circuit evaluation (--kernel). Fast paths are taken
/// where the circuit allows them and reported in sim_result (fused, split,
/// fast); the reference is the component loops (hyd_eval, hyd_jacobian).
typedef enum sim_kernel {
    SIM_KERNEL_SPLIT = 0, ///< fastest: lagrange the one-pass circuit, block-eliminated W and (Krus,
                          ///< ROS2) the split step; ode the one-pass circuit, or the fast kernel for
                          ///< any other circuit (circuit_fast.h)
    SIM_KERNEL_FUSED,     ///< the same, but lagrange's Krus/ROS2 evaluate f in full at every stage
                          ///< (the generic stage arithmetic; for comparisons)
    SIM_KERNEL_GENERAL    ///< the reference: the component loops and the solver's own sparse LU
} sim_kernel;

typedef struct sim_opts {
    sim_mechanics mechanics;
    int variant;       ///< the lagrange backend's variant, a lagrange_variant (lagrange.h); 0, the
                       ///< default, is LAGRANGE_FULL
    hyd_method solver;
    double h;          ///< fixed step [s] (default 1e-4)
    double rtol, atol; ///< adaptive tolerances [-], [state units]
    double dt_out;     ///< output period [s] (default 1e-3)
    double duration;   ///< [s]; 0 = the scenario's
    bool dense_jac;    ///< fixed-step methods: dense J instead of the block pattern
    int jac_every;     ///< fixed-step methods: J every N steps (default 10)
    int no_retry;      ///< fixed-step methods: report a failed step at once instead of retrying it in sub-steps (hyd_solver_opts.retry_halvings = 0; tests)
    double load_mass;  ///< tip load [kg]; < 0: the scenario's, else the model's
    const char* world; ///< ode: world file (NULL: assets/worlds/validation.json)
    double dt_ode;     ///< ode: rigid-body step [s] (default 1e-3; hydraulics sub-step at h)
    bool cvode;        ///< integrate with SUNDIALS CVODE (BDF) instead of `solver`
                       ///< (the outside reference; rtol/atol apply)
    sim_kernel kernel;   ///< how the circuit is evaluated (default SIM_KERNEL_SPLIT, the fastest)
    bool rcl;            ///< the rated capacity limiter cuts commands (rcl.h); off (the library default):
                         ///< it only measures rcl_util. run and drive turn it on unless --rcl off
    bool no_step_probe;  ///< no step probe (sim_check_step_probe): the probe's own runs, --no-step-probe, study, bench
} sim_opts;

// The settings its messages name: sim_param, sim_name_params, sim_param_name (param_names.h).

/// Refuse a fixed-step run the method cannot do, before it starts: RK4
/// beyond its stability interval on the circuit hm's fastest mode, a step h
/// [s] longer than the run t_end [s], or more than 1e12 steps (t_end <= 0:
/// an open-ended run, only the stability test). Returns SIM_OK, or SIM_REFUSED with one
/// line in err. Adaptive solvers and CVODE always pass.
int sim_check_fixed_step(const hyd_model* hm, const sim_opts* o, double h, double t_end, char* err, size_t errsz);

/// Longest simulated time and output period a run accepts [s]: 1e6 s (11.6
/// days). Beyond, a step or row count no longer fits the integers that count
/// them, and no run of a crane needs more.
#define SIM_MAX_DURATION 1e6
/// Refuse a run's duration t_end [s] or output period dt_out [s] outside
/// (0, SIM_MAX_DURATION], or more than 1e12 rows. Returns SIM_OK, or SIM_REFUSED with one
/// line in err naming the setting (sim_param_name), the range and the unit.
int sim_check_times(double t_end, double dt_out, char* err, size_t errsz);

/// The checks every driver (run, compare, bench, study, drive) applies to the
/// state it records, so no driver lets through what another refuses: every
/// value finite, no absolute pressure more than 0.1 MPa below zero
/// (decision 6). A shallower dip below zero is remembered for a note.
typedef struct sim_checks {
    bool dip;            ///< a dip below absolute zero was seen
    char dip_name[96];   ///< its state or column
    double dip_value;    ///< deepest value [Pa abs]
    double dip_t;        ///< when [s]
    double bad_value;    ///< the value of the last failed check (for sim_blowup_hint)
} sim_checks;
void sim_checks_init(sim_checks* k);
/// Check one value v of the state named name at time t [s]; pressure: an
/// absolute pressure [Pa]. Returns 0, 1 when v is not finite, 2 when it is a
/// pressure more than 0.1 MPa below absolute zero; then msg holds
/// "state NAME = VALUE ... at t = T s" (the caller adds the solver and
/// sim_blowup_hint(adaptive, t, k->bad_value)).
int sim_check_value(sim_checks* k, const char* name, double v, bool pressure, double t, char* msg, size_t n);
/// sim_check_value on every column of a CSV row of ncol columns (the
/// chamber and pump pressures as pressures).
int sim_check_row(sim_checks* k, const double* row, int ncol, char* msg, size_t n);
/// The note for the deepest dip below absolute zero, or "" when there was
/// none; adaptive: the run's steps were the solver's (the advice is then a
/// smaller --rtol, not --dt).
void sim_checks_note(const sim_checks* k, bool adaptive, char* note, size_t n);
/// The advice of a failed check: a value [Pa abs, or any state's] found
/// implausible at time t [s] of a run with an adaptive (or CVODE) or a
/// fixed-step solver. "Try a smaller --dt" only where a shorter step is the
/// likely cure: a fixed step, after steps were taken (t > 0), from a finite
/// value; a smaller --rtol for adaptive runs; else a check of the model.
/// The settings are named by sim_param_name; the text lives until the next
/// call.
const char* sim_blowup_hint(bool adaptive, double t, double value);

/// The one message of a failed run check (sim_check_value, sim_check_row):
/// what failed, where the run stood (how: "solver krus, h = 0.0001 s", the
/// solver and its step as the driver knows them) and the advice of
/// sim_blowup_hint for a failure at time t [s] of value bad [state units].
/// With how == NULL the failure is in the start state (nothing was
/// integrated): "WHAT: ADVICE"; else "numerical blow-up: WHAT (HOW): ADVICE".
void sim_check_message(char* out, size_t n, const char* what, const char* how, bool adaptive, double t,
                       double bad);

/// Refuse a start state the circuit cannot hold: a chamber pressure of row
/// (the CSV row at t = 0: p1A..p2B, and p3A, p3B when ncol has them) above
/// the highest relief setting of circuit hm (p_crack + dp_override). The
/// static start (decision 5) gives each chamber the pressure that holds the
/// crane still; with a load too heavy for the pose that is more than any
/// relief lets the circuit reach (100 t at the tip: 459 MPa), a state the
/// reliefs cannot cap because it is set, not integrated. ld: what the crane
/// holds, for the message, which says what takes the holding torque of the
/// joint at fault (the booms' own weight, the mass at the tip) and so what
/// to change. Returns SIM_OK, or SIM_REFUSED with one line in err.
typedef struct sim_start_load {
    const crane_mech* mech; ///< the booms (NULL: their share is not said)
    double q[2];            ///< the start pose [rad], the paper's convention
    double m_tip;           ///< the mass at the tip [kg]: the tip load, or the world's hook and rope
    bool world_tip;         ///< m_tip is the world's hook and rope (the sandbox), not a tip load
} sim_start_load;
int sim_check_start(const hyd_model* hm, const double* row, int ncol, const sim_start_load* ld, char* err,
                    size_t errsz);

/// True when this build has the CVODE reference solver.
bool sim_have_cvode(void);

/// The tip load a run uses [kg]: the option, else the scenario's, else the model's.
double sim_load_mass(const model* m, const scenario* sc, const sim_opts* o);

sim_opts sim_default_opts(void);

/// The output channels: one list (name, unit, kind) from which the CSV
/// columns, their header, sim_col_name and sim_col_unit, the run checks'
/// pressure columns and the channels an engine publishes (engine_channels)
/// are all made. The first 17 are the columns every backend has written
/// from the start (README, "The CSV columns"): their order is fixed. A new
/// channel is one X(...) line in the list its backends write.
typedef enum sim_channel_kind {
    SIM_CH_OTHER = 0,
    SIM_CH_PRESSURE, ///< an absolute pressure [Pa]: the run checks refuse one below -0.1 MPa
} sim_channel_kind;
typedef struct sim_channel {
    const char* name; ///< CSV column name
    const char* unit; ///< SI unit, "-" for none, "count", "bits", "index"
    sim_channel_kind kind;
} sim_channel;

/// Every backend's channels.
#define SIM_CHANNELS_BASE(X) \
    X(T, "t", "s", SIM_CH_OTHER) \
    X(X1, "x1", "m", SIM_CH_OTHER) \
    X(X2, "x2", "m", SIM_CH_OTHER) \
    X(P1A, "p1A", "Pa", SIM_CH_PRESSURE) \
    X(P1B, "p1B", "Pa", SIM_CH_PRESSURE) \
    X(P2A, "p2A", "Pa", SIM_CH_PRESSURE) \
    X(P2B, "p2B", "Pa", SIM_CH_PRESSURE) \
    X(U1, "u1", "-", SIM_CH_OTHER) \
    X(U2, "u2", "-", SIM_CH_OTHER) \
    X(Q1, "q1", "rad", SIM_CH_OTHER) \
    X(Q2, "q2", "rad", SIM_CH_OTHER) \
    X(TIP_X, "tip_x", "m", SIM_CH_OTHER) \
    X(TIP_Z, "tip_z", "m", SIM_CH_OTHER) \
    X(F1, "F1", "N", SIM_CH_OTHER) \
    X(F2, "F2", "N", SIM_CH_OTHER) \
    X(U1_CMD, "u1_cmd", "-", SIM_CH_OTHER) \
    X(U2_CMD, "u2_cmd", "-", SIM_CH_OTHER) \
    X(V1, "v1", "m/s", SIM_CH_OTHER) \
    X(V2, "v2", "m/s", SIM_CH_OTHER) \
    X(P_PUMP, "p_pump", "Pa", SIM_CH_PRESSURE) \
    X(RELIEF_OPEN, "relief_open", "count", SIM_CH_OTHER) \
    X(END_STOP, "end_stop", "bits", SIM_CH_OTHER)
/// World extras, written by the ode backend only.
#define SIM_CHANNELS_WORLD(X) \
    X(SLEW, "slew", "rad", SIM_CH_OTHER) \
    X(HOOK_X, "hook_x", "m", SIM_CH_OTHER) \
    X(HOOK_Y, "hook_y", "m", SIM_CH_OTHER) \
    X(HOOK_Z, "hook_z", "m", SIM_CH_OTHER) \
    X(LOAD_X, "load_x", "m", SIM_CH_OTHER) \
    X(LOAD_Y, "load_y", "m", SIM_CH_OTHER) \
    X(LOAD_Z, "load_z", "m", SIM_CH_OTHER) \
    X(ATTACHED, "attached", "index", SIM_CH_OTHER) \
    X(TRUCK_TILT, "truck_tilt", "rad", SIM_CH_OTHER) \
    X(CONTACTS, "contacts", "count", SIM_CH_OTHER) \
    X(MAX_DEPTH, "max_depth", "m", SIM_CH_OTHER) \
    /* The slew function's actuator (sandbox; zeros in the validation world). */ \
    X(X3, "x3", "m", SIM_CH_OTHER) \
    X(V3, "v3", "m/s", SIM_CH_OTHER) \
    X(P3A, "p3A", "Pa", SIM_CH_PRESSURE) \
    X(P3B, "p3B", "Pa", SIM_CH_PRESSURE) \
    X(U3, "u3", "-", SIM_CH_OTHER) \
    X(U3_CMD, "u3_cmd", "-", SIM_CH_OTHER) \
    X(F3, "F3", "N", SIM_CH_OTHER) \
    /* The end-arm tip in the world frame, where the rope hangs from (hook sway). */ \
    X(TIP_WX, "tip_wx", "m", SIM_CH_OTHER) \
    X(TIP_WY, "tip_wy", "m", SIM_CH_OTHER) \
    X(TIP_WZ, "tip_wz", "m", SIM_CH_OTHER) \
    /* Rated capacity limiter: load moment over the chart's rated moment (rcl.h). */ \
    X(RCL_UTIL, "rcl_util", "-", SIM_CH_OTHER) \
    /* The truck's supports (sandbox: outrigger pads, or wheels with the outriggers in; \
       zeros in the validation world): vertical ground reaction front-left, front-right, \
       rear-left, rear-right, and the static stability margin (ode_world_state). */ \
    X(PAD_F1, "pad_F1", "N", SIM_CH_OTHER) \
    X(PAD_F2, "pad_F2", "N", SIM_CH_OTHER) \
    X(PAD_F3, "pad_F3", "N", SIM_CH_OTHER) \
    X(PAD_F4, "pad_F4", "N", SIM_CH_OTHER) \
    X(STAB_MARGIN, "stab_margin", "-", SIM_CH_OTHER)

#define SIM_COL_ENUM_(id, name, unit, kind) COL_##id,
/// CSV column indices, in the order of the list.
enum {
    SIM_CHANNELS_BASE(SIM_COL_ENUM_)
    SIM_NCOL_BASE, ///< columns every backend writes
    SIM_COL_WORLD_ = SIM_NCOL_BASE - 1, // the world extras follow the base columns directly
    SIM_CHANNELS_WORLD(SIM_COL_ENUM_)
    SIM_NCOL
};
#undef SIM_COL_ENUM_
/// The list, indexed by column (COL_T .. SIM_NCOL - 1).
extern const sim_channel sim_channels[SIM_NCOL];
extern const char* const sim_col_name[SIM_NCOL];
extern const char* const sim_col_unit[SIM_NCOL];


/// Distinct collision pairs a run tracks; the events of further pairs are
/// not counted (32 is far more than a crane has parts times obstacles touching).
#define SIM_MAXCOLL 32
/// A contact between a pair that breaks for less than this and touches again
/// is the same collision [s]: ODE's contacts come and go from step to step
/// while a boom scrapes along a wall or rests on one.
#define SIM_COLL_GAP 0.1
/// Collisions of a run (the ode sandbox): events are a pair starting to
/// touch, after SIM_COLL_GAP or more apart (sim_collisions_step).
typedef struct sim_collisions {
    bool have;           ///< the world reports collisions (else the run has no such metric)
    long count;          ///< collision events [count]
    int npair;           ///< distinct pairs named
    char pair[SIM_MAXCOLL][2 * 48 + 4];  ///< "boom2 x wall_1", the crane's body first
    double first_t[SIM_MAXCOLL];         ///< when each first touched [s]
    double last_t[SIM_MAXCOLL];          ///< when each last touched [s]
} sim_collisions;
/// One step's touching pairs (names[i][0] x names[i][1]) at time t [s],
/// n >= 0, into c (zeroed before the run's first step): counts each pair
/// that starts to touch.
void sim_collisions_step(sim_collisions* c, double t, const char* const names[][2], int n);
/// "collisions N (A x B at T s, ...)" into buf (n bytes, SIM_COLL_TEXT
/// holds every pair): each distinct pair with the time it first touched, no
/// newline (the run's metrics line, drive's and serve's summary).
#define SIM_COLL_TEXT (32 + SIM_MAXCOLL * (2 * 48 + 4 + 24))
void sim_collisions_text(const sim_collisions* c, char* buf, size_t n);

typedef struct sim_result {
    int status;          ///< a sim_status: SIM_OK, SIM_FAILED, SIM_REFUSED (also: stopped by the callback)
    char message[512];   ///< failure description: state name, time
    char note[256];
    double p_peak[4];    ///< peak chamber pressures p1A, p1B, p2A, p2B [Pa abs]: over every step
                         ///< when peak_steps, else over the output rows (CVODE)
    bool peak_steps;     ///< p_peak saw every integration step (ode: every ODE step)      ///< something the run noticed but went on with (ode: ODE solver messages), else ""
    double t_end;        ///< simulated time reached [s]
    double wall;         ///< wall time of the integration [s]
    hyd_solver_stats stats;
    long rows;
    bool fused;          ///< the run used the fused circuit kernel (lagrange or ode)
    bool split;          ///< lagrange: ... and the split Krus/ROS2 step (lagrange_split_step.c; with fast: lagrange_split_gen.c)
    bool fast;           ///< ode: the fast kernel for any circuit (circuit_fast.h), the circuit
                         ///< not having the fused kernel's shape
    sim_collisions coll; ///< ode sandbox: the collisions at every ODE step (else coll.have is false)
} sim_result;


/// The world file a name resolves to: an existing path, or
/// assets/worlds/<name>.json ("validation", "sandbox").
const char* sim_world_path(const char* arg, char* buf, size_t n);

/// Wall clock [s], monotonic.
double sim_wall_time(void);

/// A recorded run held in memory (for plots and comparisons).
typedef struct sim_trace {
    int nrow, cap;
    double* v; ///< nrow x SIM_NCOL, row-major
} sim_trace;
void sim_trace_free(sim_trace* tr);
/// Append one row (SIM_NCOL values) to tr; 0, or -1 when out of memory.
int sim_trace_push(sim_trace* tr, const double* row);

#ifdef __cplusplus
}
#endif
#endif
