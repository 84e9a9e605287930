// lagrange_sim.h: the analytic crane and its full hydraulic circuit as one
// ODE system y' = f(t, y) for the generic integrators.
//
// State layout (n = nh + 4): the circuit's states in a block-friendly order
// (see docs/lagrange.md), then q1, q2 [rad], q1', q2' [rad/s].
#ifndef LAGRANGE_SIM_H
#define LAGRANGE_SIM_H

#include <stdbool.h>

#include "circuit_fast.h"
#include "hyd_fused.h"
#include "hyd_solver.h"
#include "lagrange.h"
#include "model.h"
#include "scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LSIM_MAX_STATES 64
#define LSIM_MAX_BLOCKS 64

/// Factors of W = I - gh J by block elimination (lagrange_schur_w.c): per actuator
/// the LU of its 5x5 interior block A_k, A_k^-1 B_k and C_k, and the LU of
/// the 5x5 Schur complement on [pump line, q1, q2, q1', q2'].
typedef struct lsim_w {
    double a[2][25];
    int pa[2][5];
    const int* piv[2];  ///< pa[k] when A_k needed row exchanges, else NULL
    double x[2][5][5];  ///< x[k][c] = column c of A_k^-1 B_k
    double c[2][5][5];  ///< c[k][r] = row r of C_k
    bool xnz[2][5], cnz[2][5]; ///< that column / row is not all zero
    double s[25];
    int ps[5];
} lsim_w;

/// State of the split Krus/ROS2 step kernel (lagrange_split_step.c): the diagonal
/// blocks of the last J, W^-1 of each block for the current gamma h, and the
/// last valve commands.
typedef struct lsim_ks {
    double ju[2];          ///< spool rows: d u' / d u [1/s]
    double jh[2][2][4];    ///< [actuator][side A, B]: 2x2 block on [hose, chamber], row-major
    double jpl;            ///< pump line: d p' / d p [1/s]
    double jm[16];         ///< [q1, q2, q1', q2'] block, row-major
    bool have_j;
    double gh;             ///< gamma h the inverses below were formed for [s] (0: none)
    double wu[2], wpl;     ///< 1 / W of the 1x1 blocks
    double wh[2][2][4];    ///< W^-1 of the 2x2 blocks
    double wm[16];         ///< W^-1 of the mechanics block
    double qa[2], sa[2], ca[2]; ///< last midpoint angles [rad] and their sines, cosines
    bool have_anchor;      ///< qa, sa, ca are set (cleared with each new J)
    double cmd_t;          ///< time of cmd [s] (NaN: none)
    double cmd[2];         ///< valve commands at cmd_t [-]
} lsim_ks;

/// State of the split step for any circuit on the fast kernel
/// (lagrange_split_gen.c): the diagonal blocks of the last J in the block
/// pattern of lsim (1x1 and 2x2 blocks of hydraulic states, then the 4x4
/// mechanics block) and W^-1 of each for ks.gh. The anchor of the midpoint
/// sines, the commands and gh are kept in lsim_ks, as for the standard step.
typedef struct lsim_kg {
    int n1, n2, n3;                    ///< number of 1x1, 2x2 and 3x3 blocks
    int i1[LSIM_MAX_STATES];           ///< state of each 1x1 block
    int i2[LSIM_MAX_STATES / 2];       ///< first state of each 2x2 block
    int i3[LSIM_MAX_STATES / 3];       ///< first state of each 3x3 block
    double j3[LSIM_MAX_STATES / 3][9]; ///< the 3x3 blocks, row-major [1/s]
    double w3[LSIM_MAX_STATES / 3][9]; ///< W^-1 of the 3x3 blocks
    int nv, iv;                        ///< size (0: none, 5..8) and first state of the one larger block
    double jv[64], wv[64];             ///< that block of J and its W^-1, row-major nv x nv
    double j1[LSIM_MAX_STATES];        ///< d f_i / d y_i of the 1x1 blocks [1/s]
    double j2[LSIM_MAX_STATES / 2][4]; ///< the 2x2 blocks, row-major [1/s]
    double jm[16];                     ///< [q1, q2, q1', q2'] block, row-major
    double w1[LSIM_MAX_STATES];        ///< 1 / W of the 1x1 blocks
    double w2[LSIM_MAX_STATES / 2][4]; ///< W^-1 of the 2x2 blocks
    double wm[16];                     ///< W^-1 of the mechanics block
    double* J;                         ///< n x n scratch for lsim_jac (owned)
} lsim_kg;

typedef struct lsim {
    const model* mdl;
    lagrange_variant variant;
    double m3;             ///< tip load [kg]
    hyd_data* hd;          ///< hydraulic inputs/outputs/scratch (owned)
    int nh;                ///< hydraulic states
    int n;                 ///< all states
    int iq;                ///< index of q1 (q2 = iq+1, q1' = iq+2, q2' = iq+3)
    int perm[LSIM_MAX_STATES]; ///< system index -> hydraulic state index (for i < nh)
    int hpos[LSIM_MAX_STATES]; ///< its inverse: hydraulic state -> system index
    int ip[2][2];          ///< system indices of chamber pressures pA, pB of actuator k
    int iu[2];             ///< system index of actuator k's spool
    bool is_pressure[LSIM_MAX_STATES]; ///< system state i is a pressure [Pa abs]
    int ihose[2][2];       ///< system index of the hose before chamber A, B of actuator k (-1: none)
    int nblock;            ///< Jacobian blocks for block-diagonal W-methods
    int block[LSIM_MAX_BLOCKS];
    const scenario* scn;   ///< command source, or NULL to use u_cmd
    double u_cmd[2];       ///< commands when scn is NULL, -1..1
    int scn_seg_[2];       ///< segment hints for scenario_command_hint
    bool frozen_q[2];      ///< hold joint k still (tests; q' = 0, q'' = 0)
    // Scratch: the hydraulic states in the circuit's order (Jacobian only).
    double yh_[LSIM_MAX_STATES];
    double* jh_;           ///< nh x nh hydraulic Jacobian scratch (owned)
    double inv_tau[2];     ///< 1 / spool time constant of actuator k's valve [1/s]
    long nrhs;             ///< right-hand-side calls
    // The fused circuit kernel (hyd_fused.h), in the system's state order.
    hyd_fused fz;
    lagrange_consts lk;    ///< H, C, G constants for the fused rhs (variant, m3 at init)
    bool have_fused;       ///< the circuit has the standard shape
    bool use_fused;        ///< lsim_problem hands out the fused f and J (default: have_fused)
    char fused_why[96];    ///< why not, when !have_fused
    // The fast kernel for any circuit (circuit_fast.h), in the system's state
    // order, when the circuit has no fused shape and every component has a
    // fast loop (no fallback: the fallback loops work in circuit order only).
    hyd_fast* fk;
    bool use_fast;         ///< lsim_rhs and lsim_jac evaluate the circuit with fk (default: fk != NULL)
    // Structured W (lagrange_schur_w.c) for the dense-pattern solvers.
    bool w_layout;         ///< the state layout lagrange_schur_w.c needs (standard circuit, 2 actuators)
    bool use_w;            ///< lsim_problem hands out wfactor/wsolve (default: w_layout)
    lsim_w w;
    // Split Krus/ROS2 step (lagrange_split_step.c) for the block-pattern fixed-step runs.
    bool use_split;        ///< lsim_problem(s, true) hands out lsim_wstep (w_layout) or lsim_wstep_gen (gen_layout, use_fast); default true
    lsim_ks ks;
    // Split step for any circuit on the fast kernel (lagrange_split_gen.c).
    bool gen_layout;       ///< fk and the blocks lsim_kg takes: lsim_problem(s, true) can hand out lsim_wstep_gen
    lsim_kg kg;
    /// The stage point y + k1 of the last split step (lsim_wstep,
    /// lsim_wstep_gen; hyd_problem.wstage): the energy balance integrates
    /// its powers with the step's own stages (energy_acc.h).
    double ystage[LSIM_MAX_STATES];
    hyd_fused_events ev;   ///< event counter of lsim_events
    unsigned fz_rev;       ///< hyd_model_revision that fz was packed at
    /// Cylinder k is clear of both end stops and their smoothing widths
    /// while ev_phi[k][0] < phi < ev_phi[k][1] (phi = q + phi_offset [rad];
    /// NaN: no such range): lsim_events then needs no stroke.
    double ev_phi[2][2];
} lsim;

/// Set up for model m. Returns 0, or -1 with a message.
int lsim_init(lsim* s, const model* m, lagrange_variant v, double m3, char* err, size_t errsz);
void lsim_free(lsim* s);

/// The problem for hyd_solver_create: f, analytic Jacobian (the fused ones
/// when use_fused and have_fused), and (if blocks)
/// the block-diagonal pattern [spool] [hose A, chamber A] [hose B, chamber B]
/// per actuator, 1x1 for other hydraulic states, [q1, q2, q1', q2'].
hyd_problem lsim_problem(lsim* s, bool blocks);
/// Read the scenario's commands at t into ks.cmd (lsim_commands).
void lsim_commands_read(lsim* s, double t);
/// The valve commands at t [-]: u_cmd, or the scenario's at t (the last t's
/// values kept in ks.cmd, as a scenario is a function of t). Inline: three
/// calls per step, two of them finding t cached.
static inline void lsim_commands(lsim* s, double t, double cmd[2]) {
    if (!s->scn) {
        cmd[0] = s->u_cmd[0], cmd[1] = s->u_cmd[1];
        return;
    }
    if (!(t == s->ks.cmd_t)) lsim_commands_read(s, t);
    cmd[0] = s->ks.cmd[0], cmd[1] = s->ks.cmd[1];
}

/// Initial state at joint angles q0 [rad], at rest, with chamber pressures in
/// static equilibrium with gravity (rod side or piston side at p_low [Pa abs])
/// and the pump line at its set pressure.
void lsim_initial_state(lsim* s, const double q0[2], double p_low, double* y);

/// Returns 0 when both cylinders can reach the joint angles q0 [rad] (stroke
/// in [0, s]), else -1 with one line naming the angle, the cylinder and its
/// stroke (the same rule as the ode world's: an unreachable start pose would
/// put a boom through its end stop at t = 0).
int lsim_check_pose(const lsim* s, const double q0[2], char* err, size_t errsz);

/// True when s has the layout of lagrange_schur_w.c: 15 states, actuator k at
/// 5k..5k+4 = [spool, hose A, chamber A, hose B, chamber B], then the pump
/// line and q1, q2, q1', q2'.
bool lsim_w_layout(const lsim* s);
/// hyd_problem.wfactor / wsolve for that layout (see lagrange_schur_w.c).
int lsim_wfactor(void* user, const double* J, double gh);
void lsim_wsolve(void* user, double* x);

/// hyd_problem.wstep for Krus and ROS2 with the block pattern (lagrange_split_step.c):
/// the mechanics (sines, cylinder kinematics, mass matrix) evaluated once per
/// step at the predicted midpoint and carried to both stages to first order.
/// Requires w_layout.
int lsim_wstep(void* user, double t, const double* y, double h, double gamma, int new_jac,
               double* ynew);
/// The same step for any circuit on the fast kernel (lagrange_split_gen.c):
/// f at each stage is lsim_rhs's fast-kernel f with the mechanics carried
/// from the midpoint, J is lsim_jac's, W^-1 per diagonal block. Requires
/// gen_layout.
int lsim_wstep_gen(void* user, double t, const double* y, double h, double gamma, int new_jac,
                   double* ynew);
int lsim_rhs(void* user, double t, const double* y, double* dydt);
/// hyd_problem.events (requires have_fused): counts the switches between
/// successive calls (hyd_fused_events_update): a valve command step, a
/// relief or check valve, an end stop or the pump's cut-off passing a
/// corner of its law, a pressure below the bulk modulus' knee changing
/// octave.
unsigned long lsim_events(void* user, double t, const double* y);
/// hyd_problem.settle: a valve spool within HYD_SPOOL_SETTLE of 0 while its
/// command is as close to 0 is set to exactly 0, and so is every other
/// state that closes on a lag towards 0 below 1e-10 of full (compensator
/// and counterbalance spools, a LS pump's displacement: hyd_model_flush).
int lsim_settle(void* user, double t, double* y);
/// hyd_problem.wstage: lsim.ystage, the last split step's stage point.
const double* lsim_wstage(void* user);
/// df/dt: time enters only through the valve commands of the scenario, so
/// only the spool rows are non-zero: (du_cmd/dt) / tau_s.
int lsim_dfdt(void* user, double t, const double* y, double* dfdt);
int lsim_jac(void* user, double t, const double* y, double* J);
/// The same f and J through the fused circuit kernel (requires have_fused;
/// the model's circuit parameters, mechanics and m3 must not change after
/// lsim_init: the kernel holds packed copies).
int lsim_rhs_fused(void* user, double t, const double* y, double* dydt);
int lsim_jac_fused(void* user, double t, const double* y, double* J);

/// Derived outputs at (t, y), computed fresh (calls the rhs once).
typedef struct lsim_out {
    double x[2], v[2];     ///< strokes [m], rates [m/s]
    double pA[2], pB[2];   ///< chamber pressures [Pa abs]
    double u[2], u_cmd[2]; ///< spool openings, commands [-]
    double q[2], qd[2];    ///< joint angles [rad], rates [rad/s]
    double tip[2];         ///< tip x (reach), z (height) relative to joint 1 [m]
    double F[2];           ///< cylinder forces [N]
    double tau[2];         ///< joint torques [N m]
    double p_pump;         ///< pump line pressure [Pa abs] (0 if none)
    int relief_open;       ///< number of relief valves passing flow
    int end_stop;          ///< bit k set when cylinder k is at an end stop
} lsim_out;
void lsim_outputs(lsim* s, double t, const double* y, lsim_out* o);

#ifdef __cplusplus
}
#endif
#endif
