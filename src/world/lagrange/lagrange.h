// lagrange.h: the analytic 2-DOF crane (paper Eqs. 1-4; derivation in docs/lagrange.md).
//
// H(q) q'' + C(q, q') + G(q) = tau, q1 from the downward vertical, q2 relative
// to the lifting arm. Derivation in docs/lagrange.md.
#ifndef LAGRANGE_H
#define LAGRANGE_H

#include "crane_model.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lagrange_variant {
    LAGRANGE_FULL = 0,  ///< link inertias and Coriolis/centrifugal terms (default; matches ode)
    LAGRANGE_PAPER,     ///< paper Eqs. 2-3: point masses (I = 0), C = 0, G1 typo corrected
    LAGRANGE_PAPER_TYPO, ///< as printed: G1 uses (m2 + m3) L2 where L1 belongs
    /// The general formulation for any chain (chain_sim.h), asked for on the
    /// two-link crane too (whose `full` otherwise takes the closed form, the
    /// fast path): the same equations, evaluated by CRBA and RNEA. Not a
    /// variant of the closed-form terms: lagrange_eval_terms takes it as full.
    LAGRANGE_GENERAL
} lagrange_variant;

// sim_default_opts (sim_base.c, which knows no backend) leaves
// sim_opts.variant 0: the full model must stay the first.
_Static_assert(LAGRANGE_FULL == 0, "sim_opts.variant defaults to 0, which must be LAGRANGE_FULL");

const char* lagrange_variant_name(lagrange_variant v);
/// "full", "paper", "paper-typo"; -1 if unknown.
int lagrange_variant_parse(const char* s);

/// Mass-matrix, velocity and gravity terms and their partial derivatives.
typedef struct lagrange_terms {
    double H[2][2];    ///< mass matrix [kg m^2]
    double C[2];       ///< Coriolis and centrifugal generalised forces [N m]
    double G[2];       ///< gravity generalised forces [N m]
    double dH_dq2[2][2];
    double dC_dq2[2], dC_dqd1[2], dC_dqd2[2];
    double dG_dq1[2], dG_dq2[2];
} lagrange_terms;

/// Evaluate the terms at (q, qd) [rad, rad/s] for a tip load m3 [kg].
void lagrange_eval_terms(const crane_mech* m, lagrange_variant v, double m3, const double q[2],
                         const double qd[2], lagrange_terms* out);

/// Same, with sin/cos of q1 and q2 given (trig = {sin q1, cos q1, sin q2, cos q2}),
/// so a caller that also needs them for the cylinders computes them once.
void lagrange_eval_terms_trig(const crane_mech* m, lagrange_variant v, double m3, const double trig[4],
                              const double qd[2], lagrange_terms* out);

/// Accelerations qdd = H^-1 (tau - C - G) [rad/s^2].
void lagrange_accel(const lagrange_terms* t, const double tau[2], double qdd[2]);

/// The constant parts of H, C and G for one mechanics, variant and load, so a
/// right-hand side evaluates them in a couple of dozen flops
/// (lagrange_accel_fast). Same expressions as lagrange_eval_terms_trig.
typedef struct lagrange_consts {
    double H11c;  ///< H11 without its 2 kc cos q2 part [kg m^2]
    double H22;   ///< [kg m^2]
    double kc;    ///< coupling coefficient mu L1 [kg m^2]
    double A, B;  ///< gravity moments [N m]
    int coriolis; ///< 1 for LAGRANGE_FULL
} lagrange_consts;

void lagrange_consts_init(const crane_mech* m, lagrange_variant v, double m3, lagrange_consts* k);

/// qdd = H^-1 (tau - C - G) from the constants and trig = {sin q1, cos q1,
/// sin q2, cos q2}; equal to lagrange_eval_terms_trig + lagrange_accel to
/// rounding.
void lagrange_accel_fast(const lagrange_consts* k, const double trig[4], const double qd[2],
                         const double tau[2], double qdd[2]);

/// sin and cos of x together, to within about 1 ulp of libm: Cody-Waite
/// reduction by pi/2 and Taylor polynomials on [-pi/4, pi/4] (|x| >= 1e5 and
/// non-finite x go to libm). About a third of glibc's sincos on this machine,
/// which is two sincos calls per crane right-hand side.
void lagrange_sincos(double x, double* s, double* c);

/// Total mechanical energy (kinetic + potential, zero at q = 0) of the full
/// model [J]. Conserved with tau = 0 for LAGRANGE_FULL.
double lagrange_energy(const crane_mech* m, double m3, const double q[2], const double qd[2]);

/// Gravity torques G(q) for the full model [N m] (the static holding torques).
void lagrange_gravity(const crane_mech* m, lagrange_variant v, double m3, const double q[2], double G[2]);

#ifdef __cplusplus
}
#endif
#endif
