// hyd_cvode.h: solve a hyd_problem with SUNDIALS CVODE (BDF, Newton, dense
// linear solver), as an independent reference for the in-house integrators.
// Lives in its own library (hydraulics_cvode) so the core needs only libm.
#ifndef HYD_CVODE_H
#define HYD_CVODE_H

#include "hyd_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Options of a CVODE run. Get defaults from hyd_cvode_default_opts().
typedef struct hyd_cvode_opts {
    double rtol;    ///< relative tolerance [-]
    double atol;    ///< absolute tolerance [state units]
    double h_max;   ///< largest step [s]; <= 0: no limit
    long max_steps; ///< step cap for the whole run
    int max_order;  ///< BDF order cap, 1..5 (0: CVODE's default, 5)
    /// Optional quadrature: nq integrals q' = qfn(quser, t, y) taken by the
    /// same BDF steps (CVODES' quadratures: after each step's nonlinear
    /// solve, left out of the error test, so y and the steps are those of a
    /// run without them). For an energy balance's powers, which samples at
    /// the outputs integrate badly: the steps inside an output period are
    /// CVODE's own. q: nq values, q(t0) on entry, updated before each call
    /// of out and at return. 0 / NULL: none.
    int nq;
    hyd_quad_fn qfn;
    void* quser;
    double* q;
} hyd_cvode_opts;

hyd_cvode_opts hyd_cvode_default_opts(void);

/// Integrate p from t0 to t_end with CVODE, calling out() at t0, t0 + dt_out,
/// ..., t_end (CVODE's own interpolation; it never steps past t_end). The block
/// pattern of p is ignored: CVODE gets the full analytic Jacobian when p->jac
/// is set, else its own difference quotients. y holds y(t0) on entry and
/// y(t_end) on return. stats (may be NULL) receives steps, error-test failures
/// (as rejected), f evaluations (including those for difference Jacobians),
/// Jacobian evaluations, and linear-solver setups (as lus). Returns HYD_OK,
/// HYD_ERR_RHS, HYD_ERR_STEPS, or HYD_ERR_HMIN for any other CVODE failure.
int hyd_cvode_integrate(const hyd_problem* p, const hyd_cvode_opts* o, double t0, double* y,
                        double t_end, double dt_out, hyd_output_fn out, void* user,
                        hyd_solver_stats* stats);

#ifdef __cplusplus
}
#endif
#endif
