// chain_sim.h: the analytic mode for any chain (docs/lagrange.md, "The
// general formulation"): the crane chain of the model (crane_chain.h) and
// its full hydraulic circuit as one ODE system y' = f(t, y) for the generic
// integrators (hyd_solver.h).
//
// State layout (n = nh + 2 ndof): the circuit's states in a block order
// (per actuator its valve's spool, [hose A, chamber A], [hose B, chamber
// B], then the other circuit states; perm and hpos map it), then the joint
// coordinates q [rad or m] of the chain's degrees of freedom (chain.h: the
// joints that are not fixed, in body order), then their rates q' [rad/s or
// m/s].
//
// Per evaluation: the chain's kinematics at (q, q'); per actuator the pin
// length L, its rate and lever arms dL/dq (chain_cylinder), the stroke
// x = L - closed_length and rate into the circuit's inputs; the circuit
// (hyd_eval); the joint forces tau = sum_k F_k dL_k/dq; and
// q'' = M^-1 (tau - C - G) by CRBA, RNEA and Cholesky
// (chain_forward_dynamics). Sizes come from the chain: no fixed maximum.
//
// The slew drive (docs/lagrange.md, "The slew as a degree of freedom"):
// when the column slews (cc->slew_free) and the model has a slew drive
// (cc->slew.present), the drive's rack is one more actuator, the last
// (index cc->nact), on the slew DOF (DOF 0): stroke x = r theta + s/2 and
// rate r theta' (crane_slew_stroke), lever arm dx/dtheta = r, so its force F
// is the torque F r (crane_slew_torque) on the column; the slewing ring's
// viscous damping c adds -c theta'. Its valve is one more function, the
// last (index cc->nfn), named "slew". Its cylinder and valve are looked up
// by name in hm, which must then be the model's circuit with
// hydraulics_slew appended (engine_chain_slew_setup). Without a drive
// (chain_sim.rack < 0) nact and nfn are the chain's.
#ifndef CHAIN_SIM_H
#define CHAIN_SIM_H

#include <stdbool.h>
#include <stddef.h>

#include "chain.h"
#include "chain_stops.h"
#include "crane_chain.h"
#include "hydraulics.h"
#include "hyd_solver.h"
#include "scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Where a function's command comes from at time t [s]: NULL uses
/// chain_sim.cmd (held between calls); else cmd_fn(cmd_user, k, t) for
/// function k, in [-1, 1].
typedef double (*chain_sim_cmd_fn)(void* user, int k, double t);

typedef struct chain_sim {
    const crane_chain* cc;  ///< bound (crane_chain_bind) to hm
    const hyd_model* hm;
    chain* ch;              ///< the mechanism with the tip load (owned)
    chain_ws* ws;           ///< its workspace (owned)
    hyd_data* hd;           ///< the circuit's inputs, outputs and partials (owned)
    double m3;              ///< tip load [kg]
    int nh;                 ///< circuit states (y[0 .. nh))
    int ndof;               ///< degrees of freedom (q = y[iq ..], q' = y[iq + ndof ..])
    int n;                  ///< all states
    int iq;                 ///< index of q[0] (= nh)
    int nact, nfn;          ///< actuators and functions: the chain's, plus the slew rack and its function
    double* cmd;            ///< [nfn] the functions' commands when cmd_fn is NULL [-]
    chain_sim_cmd_fn cmd_fn;
    void* cmd_user;
    int* iu;                ///< [nfn] system index of the function's valve spool (-1: none)
    int* ipA;               ///< [nact] system index of the actuator's chamber A pressure
    int* ipB;               ///< [nact] chamber B
    bool* is_pressure;      ///< [nh] system state i is a pressure [Pa abs]
    int* perm;              ///< [nh] system index -> circuit state
    int* hpos;              ///< [nh] circuit state -> system index
    int nblock;             ///< diagonal blocks of the block pattern (chain_sim_problem(s, true))
    int* block;             ///< their sizes: 1 (spool), 2 (hose, chamber), 1 (others), 2 ndof (q, q')
    double* jh;             ///< [nh x nh] the circuit's Jacobian in its own order (scratch)
    double* yh;             ///< [nh] the circuit's states in its own order (scratch)
    /// NULL, or [nact] ideal cylinder forces in place of the circuit's: F_k
    /// = ideal_F[k] - ideal_K[k] x_k [N] (x the stroke; ideal_K NULL: 0), a
    /// spring along the pins, conservative: E_mech - sum (ideal_F x -
    /// ideal_K x^2 / 2) is constant (the energy tests). The circuit is then
    /// not evaluated: its states stand still (f = 0).
    const double* ideal_F;
    const double* ideal_K; ///< [nact] [N/m], or NULL
    long nrhs;              ///< right-hand-side calls
    // Per evaluation (chain_sim_rhs): each actuator's pin length [m], its
    // rate [m/s], lever arms dL/dq [nact x ndof] and d(L')/dq [nact x ndof].
    double *L, *Ld, *dL, *dLd;
    // Scratch: tau, q'', two RNEA results [ndof each]; q, q' perturbed and a
    // right-hand side with its solution [2 ndof each]; a Hessian, d tau/dq,
    // d tau/dq' [ndof x ndof each]; a whole f [n].
    double *tau, *qdd, *g, *H, *id0, *id1, *qp, *ydot;
    // The actuators' and functions' binding to the circuit, the chain's
    // followed by the slew rack's (when rack >= 0).
    int* acyl;              ///< [nact] circuit cylinder of actuator k
    int* afn;               ///< [nact] function of actuator k
    int* fvalve;            ///< [nfn] circuit valve of function k
    int rack;               ///< the slew rack's actuator index (= cc->nact), or -1: no slew drive
    int rack_fn;            ///< its function's index (= cc->nfn), or -1
    double rack_r;          ///< pinion radius [m]
    double rack_stroke;     ///< rack cylinder's full stroke [m]
    double slew_c;          ///< slewing-ring viscous damping [N m s/rad]
    // Where the circuit's inputs in hd (strokes cyl_x, rates cyl_v) were
    // last set from the kinematics: the time and q, q' [2 ndof] of that
    // evaluation (chain_sim_inputs_at).
    bool kin_valid;
    double kin_t;
    double* kin_y;
    chain_stops stops;      ///< the joint-limit stops (chain_stops.h), added to tau
} chain_sim;

/// Set up for chain cc (bound to circuit hm by crane_chain_bind) with a tip
/// load m3 [kg] at the chain's tip; the column slews when cc->slew_free, else
/// it is fixed at slew [rad]; with slew_free and a slew drive
/// (cc->slew.present) the rack drives it (see above). Refuses (-1, one line
/// in err) a chain whose actuators share a cylinder, an actuator or function
/// not bound, or a slew drive whose cylinder or valve hm lacks.
int chain_sim_init(chain_sim* s, const crane_chain* cc, const hyd_model* hm, double m3, double slew, char* err,
                   size_t errsz);
void chain_sim_free(chain_sim* s);

/// The problem for hyd_solver_create: f and the analytic Jacobian; blocks:
/// with the block-diagonal pattern (per actuator [spool] [hose A, chamber
/// A] [hose B, chamber B], 1x1 for the other circuit states, [q, q']), as
/// the closed form's for its fixed-step runs; else W is dense.
hyd_problem chain_sim_problem(chain_sim* s, bool blocks);
int chain_sim_rhs(void* user, double t, const double* y, double* dydt);
/// True when hd's strokes and rates (cyl_x, cyl_v) of every actuator are
/// those of (t, y): the last evaluation (f, the Jacobian or the outputs) set
/// them at this t and these q, q' bit for bit, so a caller that needs them
/// at (t, y) (the Jacobian events, chain_problem.c) can take them instead
/// of running the kinematics again.
bool chain_sim_inputs_at(const chain_sim* s, double t, const double* y);
/// The analytic Jacobian (docs/lagrange.md): the circuit block by
/// hyd_jacobian; the coupling columns from its dydx, dydv with dL/dq and
/// d(L')/dq; the mechanics rows by M^-1 (chain_solve) of d tau (from dFdy,
/// dFdx, dFdv and the lever arms' Hessian) minus the partials of
/// M(q) q'' + C(q, q') + G(q) at fixed q'', which are taken by central
/// differences of the inverse dynamics (RNEA). Writes every entry.
int chain_sim_jac(void* user, double t, const double* y, double* J);

/// Returns 0 when every actuator's stroke at q0 [ndof] is within [0, its
/// stroke] (the slew rack's too), else -1 with one line naming the actuator,
/// its stroke and range.
int chain_sim_check_pose(chain_sim* s, const double* q0, char* err, size_t errsz);

/// Initial state at q0 [ndof], at rest, with the chamber pressures that hold
/// the chain against gravity (the unloaded chamber of each cylinder at p_low
/// [Pa abs]) and the other circuit states at their initial values. The
/// actuators' forces F solve sum_k F_k dL_k/dq = G (the gravity forces):
/// with as many actuators as the DOFs gravity loads, that square system; a
/// DOF no actuator moves (the slew) must carry no gravity load. The slew
/// rack carries none either: its chambers start as the ODE sandbox's, A at
/// p_low and B at p_low A_A / A_B (no force). Returns 0,
/// or -1 with one line in err when there is no such F (more actuators than
/// loaded DOFs, a loaded DOF without an actuator, a singular system).
int chain_sim_initial_state(chain_sim* s, const double* q0, double p_low, double* y, char* err, size_t errsz);

/// Outputs at (t, y), computed fresh (calls the rhs once; not counted).
/// Arrays are the caller's, sized as noted; any may be NULL.
typedef struct chain_sim_out {
    double* x;     ///< [nact] strokes [m]
    double* v;     ///< [nact] stroke rates [m/s]
    double* pA;    ///< [nact] chamber A pressure [Pa abs]
    double* pB;    ///< [nact] chamber B [Pa abs]
    double* F;     ///< [nact] cylinder forces [N], + extends
    double* u;     ///< [nfn] spool opening of the function's valve [-]
    double* u_cmd; ///< [nfn] its command [-]
    double* q;     ///< [ndof] joint coordinates [rad or m]
    double* qd;    ///< [ndof] their rates
    double tip[3]; ///< the tip in the base frame [m]
    double p_pump; ///< pump line pressure [Pa abs] (0: no pump)
} chain_sim_out;
void chain_sim_outputs(chain_sim* s, double t, const double* y, chain_sim_out* o);

/// Mechanical energy (kinetic + potential from the base origin) at y [J].
double chain_sim_energy(chain_sim* s, const double* y);

/// The name of function k (0 .. nfn - 1): the chain's, or "slew" for the
/// slew rack's; the name of actuator k likewise.
const char* chain_sim_function_name(const chain_sim* s, int k);
const char* chain_sim_actuator_name(const chain_sim* s, int k);

/// Power dissipated in the slewing ring's damping at y [W] (0 without a
/// slew drive): c theta'^2.
double chain_sim_slew_damping_power(const chain_sim* s, const double* y);

#ifdef __cplusplus
}
#endif
#endif
