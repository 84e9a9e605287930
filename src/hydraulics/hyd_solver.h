// hyd_solver.h: generic ODE integrators for y' = f(t, y).
//
// Works on any problem, not only hydraulic circuits: n states, a right-hand
// side, an optional analytic Jacobian. Methods:
//   HYD_KRUS      2-stage linearly implicit W-method, gamma = 1/2 (our reading of
//                 Krus's method: A-stable, R(-inf) = -1), fixed step, order 2
//   HYD_ROS2      same scheme with gamma = 1 + 1/sqrt(2): L-stable, order 2
//   HYD_RK4       classical explicit Runge-Kutta, order 4
//   HYD_ROS34PW2  Rang & Angermann W-method 3(2), adaptive
//   HYD_RODAS3    Sandu et al. stiffly accurate 3(2), adaptive
// All memory is allocated in hyd_solver_create; no step allocates.
#ifndef HYD_SOLVER_H
#define HYD_SOLVER_H

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Right-hand side dydt = f(t, y). Return 0 on success; non-zero aborts the step
/// (the solver returns HYD_ERR_RHS).
typedef int (*hyd_rhs_fn)(void* user, double t, const double* y, double* dydt);

/// Jacobian df/dy at (t, y), dense row-major n x n: J[i*n + j] = d f_i / d y_j.
/// The solver zeroes J before the call, so a callback writes only non-zeros.
/// Return 0 on success.
typedef int (*hyd_jac_fn)(void* user, double t, const double* y, double* J);

/// Partial derivative df/dt at (t, y), n values. Return 0 on success.
typedef int (*hyd_dfdt_fn)(void* user, double t, const double* y, double* dfdt);

/// The problem: sizes and callbacks. Kept by pointer; must outlive the solver.
typedef struct hyd_problem {
    int n;            ///< number of states
    hyd_rhs_fn f;     ///< right-hand side (required)
    hyd_jac_fn jac;   ///< analytic Jacobian, or NULL for forward differences
    void* user;       ///< passed to f and jac
    /// jac writes every one of the n x n entries (it adds into none), so the
    /// solver need not clear J before each call (5 kB at n = 25, every
    /// Jacobian). 0: J is zeroed first, and jac may write only its non-zeros.
    int jac_full;
    /// Optional block-diagonal Jacobian pattern. When nblock > 0, the solver
    /// uses only the diagonal blocks of J (sizes block_size[0..nblock-1], summing
    /// to n) to form W = I - gamma h J and factors each block on its own. All
    /// methods here are W-methods or tolerate this, so the order is kept; only
    /// stability and error constants change. NULL/0: dense J.
    int nblock;
    const int* block_size;
    /// Optional df/dt at (t, y), n values (added by the solver module). Only
    /// RODAS3 needs it: it is a classical Rosenbrock method, whose order for a
    /// non-autonomous f relies on the gamma_i h^2 df/dt term. The W-methods
    /// (Krus, ROS2, ROS34PW2) evaluate stages at t + alpha_i h and need no
    /// df/dt (see docs/solvers.md). NULL: RODAS3 takes a forward difference in
    /// t, one extra f evaluation per Jacobian evaluation.
    hyd_dfdt_fn dfdt;
    /// Non-zero when f does not depend on t: RODAS3 then skips df/dt.
    int autonomous;
    /// Optional structured linear algebra for W = I - gh J, used only with a
    /// dense pattern (nblock == 0). wfactor receives the J of the last
    /// Jacobian evaluation (row-major n x n) and gh; it returns 0 when it has
    /// factored W (wsolve then solves W x = b in place), or non-zero when it
    /// cannot (a structure it does not know, a weak pivot, non-finite
    /// entries): the solver then factors that W itself. For problems whose
    /// structure allows a cheaper elimination than the general sparse LU
    /// (the crane: lagrange_sim.c). NULL: the solver's own LU.
    int (*wfactor)(void* user, const double* J, double gh);
    void (*wsolve)(void* user, double* x);
    /// Optional whole-step kernel for the fixed-step W-methods Krus and ROS2:
    /// from (t, y) take one step of size h with W = I - gamma h J and write
    /// y(t + h) to ynew. new_jac asks for a new J at (t, y) first (the solver
    /// keeps the jac_every / jac_max_age / reset bookkeeping); otherwise the
    /// kernel keeps its last J, and re-forms W itself when gamma h changed.
    /// Returns the number of W factorisations it did (>= 0, for the stats), or
    /// a negative HYD_ERR_* code. The solver counts two f evaluations per
    /// step. For problems that can share work between the two stages (the
    /// crane: lagrange_split_step.c). NULL: the generic stage arithmetic (krus.c).
    int (*wstep)(void* user, double t, const double* y, double h, double gamma, int new_jac,
                 double* ynew);
    /// Optional, with wstep: the stage point y + k1 of the last step wstep
    /// took (n values), for hyd_solver_step_quadrature. NULL: not kept (the
    /// quadrature then refuses a wstep step).
    const double* (*wstage)(void* user);
    /// Optional domain of the states: returns 0 when y is admissible, else
    /// 1 + the index of a state outside it. The adaptive methods reject a
    /// trial step that leaves the domain and retry with a smaller h, as they
    /// do for a non-finite one (absolute pressures below zero: the exact
    /// solution never gets there, a step too long for its error estimate
    /// can). NULL: every finite y is admissible.
    int (*outside)(void* user, const double* y);
    /// Optional, for the fixed-step methods: returns 0, else 1 + the index
    /// of a state no step may produce at all (the crane's circuits: an
    /// absolute pressure more than 0.1 MPa below zero, where the run checks
    /// fail a run). Such a step is retried in sub-steps like a non-finite
    /// one (hyd_solver_opts.retry_halvings). Shallower exits from the
    /// domain (a Krus step ringing a few kPa below zero at a stiff event)
    /// are left to the caller, as before. NULL: only W and finiteness.
    int (*implausible)(void* user, const double* y);
    /// Optional event counter for the Jacobian schedule. Called with the
    /// state (t, y) at the start of a step, it returns a count that the
    /// problem increases whenever f has switched since its previous call: a
    /// command step, a relief or check valve passing a corner of its
    /// opening law, an end stop engaging or releasing. When the count
    /// differs from its value at the last J, that step takes a new J, as it
    /// would at jac_every steps or jac_max_age: a J of one regime reused in
    /// another can make W a poor, even unstable, approximation (Krus at
    /// 1 ms on `step`, docs/solver_study.md). Only consulted while J is
    /// reused (jac_every > 1). NULL: J by age only.
    unsigned long (*events)(void* user, double t, const double* y);
    /// Optional: called after every accepted step with the new (t, y); it
    /// may set a state that has come within a negligible distance of its
    /// resting value to exactly that value, and returns non-zero when it
    /// changed y. A first-order lag towards 0 (a valve spool after its
    /// command went to 0) otherwise decays geometrically for ever, into
    /// subnormal numbers, on which every operation is slow (45 % more per
    /// crane step). NULL: y is never touched.
    int (*settle)(void* user, double t, double* y);
} hyd_problem;

typedef enum hyd_method {
    HYD_KRUS = 0,
    HYD_ROS2,
    HYD_RK4,
    HYD_ROS34PW2,
    HYD_RODAS3,
    HYD_METHOD_COUNT
} hyd_method;

/// Name of a method ("krus", "ros2", "rk4", "ros34pw2", "rodas3").
const char* hyd_method_name(hyd_method m);
/// Parse a method name; returns -1 if unknown.
int hyd_method_parse(const char* name);
/// True for the adaptive (error-controlled) methods.
bool hyd_method_is_adaptive(hyd_method m);
/// Classical order of the method (2, 2, 4, 3, 3).
int hyd_method_order(hyd_method m);

/// Solver options. Get defaults from hyd_default_solver_opts() and change only
/// what differs.
typedef struct hyd_solver_opts {
    double h;           ///< fixed step [s] (fixed-step methods); initial step for adaptive (0: automatic)
    double rtol;        ///< relative tolerance [-] (adaptive)
    double atol;        ///< absolute tolerance [state units] (adaptive)
    double h_min;       ///< smallest step [s] before giving up (adaptive)
    double h_max;       ///< largest step [s] (adaptive; also capped by output/frame period)
    int jac_every;      ///< recompute J every N accepted steps (1: every step)
    double jac_max_age; ///< recompute J if older than this simulated time [s]
    long max_steps;     ///< hard cap on steps per hyd_solver_advance call
    /// Step hysteresis (adaptive; 0: off, today's behaviour). After an
    /// accepted step, a proposal h_new with h <= h_new <= (1 + h_hold) h keeps
    /// h unchanged, so W = I - gamma h J need not be refactored while J is
    /// reused (W-methods with jac_every > 1). Shrinking is never held back.
    /// 0.2 to 0.5 are typical.
    double h_hold;
    /// Adaptive output (hyd_solver_integrate): interpolate only these
    /// n_out_states states (indices into y) at output times; the callback
    /// must then read only them (the other entries of the y it receives are
    /// unspecified). NULL/0: all states. For callers that only check a few
    /// states between rows nobody consumes (benchmarks).
    const int* out_states;
    int n_out_states;
    /// Optional: called after every accepted step with the new (t, y), for a
    /// caller that tracks something between output times (sim.c: the peak
    /// pressures of a run summary). NULL (default): no call, no cost.
    void (*on_step)(void* user, double t, const double* y);
    void* on_step_user;
    /// Fixed-step methods: a step whose W is singular, whose new state is
    /// not finite or (hyd_problem.implausible) implausible is taken
    /// again as 2, 4, ... 2^retry_halvings sub-steps with a fresh J each
    /// (default 4: down to h/16); 0: no retry. A singular or non-finite
    /// step that still fails at the finest level is reported as before
    /// (hyd_solver_bad_state names the state and time); one that is only
    /// implausible is accepted at the finest level (docs/solvers.md,
    /// "Step failures of the fixed-step methods").
    int retry_halvings;
} hyd_solver_opts;

hyd_solver_opts hyd_default_solver_opts(void);

/// Work counters, cumulative since create (or hyd_solver_clear_stats).
typedef struct hyd_solver_stats {
    long steps;     ///< accepted steps
    long rejected;  ///< rejected steps (adaptive)
    long fevals;    ///< right-hand-side evaluations (including finite-difference ones)
    long jevals;    ///< Jacobian evaluations
    long jevents;   ///< of them, taken early because hyd_problem.events reported a switch
    long lus;       ///< LU factorisations of W (a block-diagonal W counts once)
    long outside;   ///< trial steps rejected for leaving the domain (hyd_problem.outside; adaptive)
    long retried;   ///< fixed steps retried in sub-steps (hyd_solver_opts.retry_halvings)
    long substeps;  ///< sub-steps those retries took (all levels tried)
} hyd_solver_stats;

enum {
    HYD_OK = 0,
    HYD_ERR_RHS = -1,      ///< f or jac returned non-zero
    HYD_ERR_SINGULAR = -2, ///< W is singular
    HYD_ERR_NONFINITE = -3,///< a state became NaN/Inf; see hyd_solver_bad_state
    HYD_ERR_HMIN = -4,     ///< adaptive step fell below h_min
    HYD_ERR_STEPS = -5,    ///< max_steps reached
    HYD_ERR_DOMAIN = -6    ///< adaptive: even the smallest step leaves the domain; see hyd_solver_bad_state
};

/// What a HYD_ERR_* code means, in a few words for a message.
const char* hyd_error_text(int code);

typedef struct hyd_solver hyd_solver;

/// Allocates all workspace. Returns NULL on bad arguments.
hyd_solver* hyd_solver_create(const hyd_problem* p, hyd_method m, const hyd_solver_opts* o);
void hyd_solver_destroy(hyd_solver* s);

/// One step of size h from (t, y), in place. Works for every method (adaptive
/// ones take the step without error control). Returns HYD_OK or an error.
int hyd_solver_step(hyd_solver* s, double* t, double* y, double h);

/// Advance from *t to exactly t_end, in place. Fixed-step methods take steps of
/// opts.h (the last one shortened to land on t_end); adaptive methods control
/// the step, never stepping past t_end.
int hyd_solver_advance(hyd_solver* s, double* t, double* y, double t_end);

/// Output callback for hyd_solver_integrate: called at every output time with
/// the (interpolated, for adaptive methods) state. Return non-zero to stop.
typedef int (*hyd_output_fn)(void* user, double t, const double* y);

/// Integrate from t0 to t_end calling out() at t0, t0+dt_out, ..., t_end.
/// Adaptive methods step freely across output times and interpolate (cubic
/// Hermite on y and f at both step ends), so output rate does not limit h.
/// y holds y(t0) on entry and y(t_end) (or the last good state) on return.
int hyd_solver_integrate(hyd_solver* s, double t0, double* y, double t_end, double dt_out,
                         hyd_output_fn out, void* user);

/// Forget step-size history and force a new Jacobian: call at a known
/// discontinuity (a command step, an end stop, a relief cracking).
void hyd_solver_reset(hyd_solver* s);

/// f has changed at the current (t, y) without a discontinuity (an input
/// the problem reads outside y, such as the strokes an ODE step hands the
/// circuit, or a load): drop the cached f(t, y) an adaptive method would
/// reuse as its next first stage, and keep the step-size history and J.
void hyd_solver_inputs_changed(hyd_solver* s);

/// Set (or with NULL clear) opts.on_step after create: a caller that decides
/// later to follow the steps (an energy balance attached to a running engine).
void hyd_solver_set_on_step(hyd_solver* s, void (*on_step)(void* user, double t, const double* y), void* user);

const hyd_solver_stats* hyd_solver_get_stats(const hyd_solver* s);
void hyd_solver_clear_stats(hyd_solver* s);
/// Last accepted step size [s].
double hyd_solver_last_h(const hyd_solver* s);
/// After HYD_ERR_NONFINITE: index of the first non-finite state, and its time [s].
int hyd_solver_bad_state(const hyd_solver* s, double* t_bad);

/// Quadrature callback: nq values P(t, y) into P. Return 0 on success.
typedef int (*hyd_quad_fn)(void* user, double t, const double* y, double* P);

/// The quadrature of nq extra states q' = P(t, y) over the last accepted step
/// by the method that took it, as if q had been integrated together with y
/// (quadrature.c): the stage points and stage vectors of that step, and for
/// the linearly implicit methods one directional derivative of P. Call it
/// before the next step (from on_step, or after hyd_solver_step). (t0, y0) is
/// where the step started, y1 where it ended (the solver's y now), P0 =
/// P(t0, y0) and P1 = P(t1, y1); work holds nq doubles. dq receives the
/// increments of q. Evaluations of fn per step: none for Krus (it is the
/// trapezoid), 1 for ROS2, 4 for the four-stage methods, 3 for RK4. 0 (dq
/// set; all zero before any step), or HYD_ERR_RHS (fn failed, or a wstep
/// step whose problem keeps no wstage).
int hyd_solver_step_quadrature(hyd_solver* s, double t0, const double* y0, const double* y1, const double* P0,
                               const double* P1, int nq, hyd_quad_fn fn, void* user, double* work, double* dq);

/// Small dense LU with partial pivoting, in place on row-major a (n x n).
/// Returns 0, or -1 if singular. Exposed for tests and for callers that build
/// their own implicit updates.
int hyd_lu_factor(double* a, int n, int* piv);
void hyd_lu_solve(const double* lu, int n, const int* piv, double* b);

#ifdef __cplusplus
}
#endif
#endif
