// ode_chain.h: the ODE world built from a crane chain (crane_chain.h): one
// ODE body per chain body, a hinge per revolute joint, a slider per
// prismatic one, the column fixed (or slewing on a hinge about z), joint
// limits and the cylinders' end stops as ODE stops, each actuator's force
// applied at its two pins; the model's circuit sub-stepped inside each ODE
// step as ode_coupling.c does for the two-link world (docs/ode_world.md,
// "The chain world").
//
// The validation world only: the column stands on the fixed ground, the tip
// load is merged into the tip body, no contacts. Units SI (m, kg, s, rad, N);
// joint coordinates and their order are the mechanism's (chain.h: the DOFs
// are the joints that are not fixed, in body order; q from each joint's
// angle0 and offset0, as chain_update reads it).
#ifndef ODE_CHAIN_H
#define ODE_CHAIN_H

#include <stddef.h>

#include "crane_chain.h"
#include "hyd_solver.h"
#include "hydraulics.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ode_chain ode_chain;

typedef struct ode_chain_opts {
    double dt_ode;         ///< ODE step [s]; default 1e-3
    double dt_hyd;         ///< hydraulic sub-step [s]; default 1e-4; dt_ode must be a whole multiple
    hyd_method solver;     ///< hydraulic integrator, a fixed-step one; default HYD_KRUS
    int jac_every;         ///< reuse the hydraulic Jacobian for this many sub-steps; default 1 (see docs)
    int general_circuit;   ///< 1: the sub-steps on the circuit's component loops (hyd_eval), else the fast kernel (circuit_fast.h); default 0
    double tip_mass;       ///< point mass at the chain's tip, merged into its body [kg]; default 0
    const double* q0;      ///< start joint coordinates [rad or m], one per DOF; NULL: all 0
    double slew0;          ///< a fixed column: its slew [rad]; default 0
    double erp, cfm;       ///< ODE's joint error reduction and mixing; default 0.2, 1e-10 (the validation world's)
    int stop_limits;       ///< 1 (default): the cylinders' stroke ends as joint stops where they can be
    hyd_model* circuit;    ///< the compiled circuit (borrowed); NULL: no hydraulics (forces from
                           ///< ode_chain_set_forces)
    int init_hold;         ///< 1 (default): start pressures that hold the start pose under gravity
    double p_low;          ///< init_hold: pressure of the unloaded side [Pa abs]; default 2e6
    const char* model_file; ///< in messages; default "model"
    /// 1 (default): a cylinder across one joint has its seal friction
    /// (hyd_cyl_seal: Coulomb + Stribeck, tanh over v_smooth) held by
    /// ODE's solver at the step's end velocity: the law as a line (its
    /// tangent at the step's rate; a damper saturating at its magnitude
    /// once sliding) in a joint motor whose constraint force mixing is the
    /// line's damping, so a step that would stop or reverse the cylinder
    /// meets the friction of the new rate (docs/ode_world.md, "The chain
    /// world"). 0: every force through the coupling, the seal friction at
    /// the step's start rate a step late (the two-link world's coupling).
    int implicit_seal;
    /// Hosted (the sandbox, docs/ode_world.md "The sandbox from the chain"):
    /// the bodies and joints are built into this world instead of a world
    /// of the chain's own, which the chain then never steps (the host calls
    /// ode_chain_host_pre and ode_chain_host_post around its own collide
    /// and dWorldStep) nor destroys. NULL (default): the chain's own world.
    struct dxWorld* host_world;
    /// Hosted: the body the column stands on (the truck; NULL: the ground),
    /// and the column foot's pose in the world: base_pos [m] and base_rot
    /// (base frame to world, row-major; all zeros reads as the identity).
    /// The column is always a body then, on a hinge about the base's z
    /// (slewing) or a fixed joint, so it moves with the base.
    struct dxBody* host_base;
    double base_pos[3];
    double base_rot[9];
    /// 1: the model's slew drive (crane_chain.slew, its rack cylinder and
    /// valve in the circuit) turns the column, which then slews whatever
    /// cc->slew_free says: rack stroke r (slew) + s/2 from the hinge, torque
    /// F r minus the bearing's damping on it, the rack's ends as the hinge's
    /// stops; commanded by ode_chain_set_slew_command. 0 (default): none.
    int slew_drive;
    /// init_hold: a point mass [kg] at the tip counted in the start's
    /// holding forces only (the sandbox's rope and hook, which hang from
    /// the tip as bodies of their own); default 0.
    double hold_tip_mass;
} ode_chain_opts;

ode_chain_opts ode_chain_default_opts(void);

/// Builds the world from cc (copied; its actuators bound to o->circuit when
/// given). NULL with one line "file: field: problem" in err: a chain the
/// mechanism refuses, a body ODE cannot move (no mass), a joint limit more
/// than half a turn from a hinge's start, an actuator's start stroke outside
/// [0, stroke], two actuators on one cylinder, a q0 ODE cannot build.
ode_chain* ode_chain_create(const crane_chain* cc, const ode_chain_opts* o, char* err, size_t errsz);
void ode_chain_destroy(ode_chain* w);

int ode_chain_ndof(const ode_chain* w);
int ode_chain_nact(const ode_chain* w);
int ode_chain_nfn(const ode_chain* w);

/// Valve commands, one per function, in [-1, 1] (clamped; NaN reads 0), held.
void ode_chain_set_commands(ode_chain* w, const double* u);
/// Actuator forces [N] (+ pushes the pins apart), held; only without a
/// circuit (the circuit's forces replace them at every step).
void ode_chain_set_forces(ode_chain* w, const double* F);
/// Extra generalized joint forces, one per DOF (torque [N m] about a
/// revolute joint in the direction of +q, force [N] along a slide), held.
void ode_chain_set_joint_forces(ode_chain* w, const double* tau);

/// Advance by dt [s] (a whole number of ODE steps, at least one). 0, or -1
/// once a body or a hydraulic state went non-finite or ODE failed
/// (ode_chain_error says which and when); the world then stays stopped.
int ode_chain_step(ode_chain* w, double dt);

/// Hosted worlds (opts.host_world), one ODE step of opts.dt_ode, both
/// called inside the host's own ODE error trap: ode_chain_host_pre reads the
/// strokes, runs the hydraulic sub-steps and adds the cylinder forces (and
/// the slew torque) to the bodies; the host then collides and steps its
/// world; ode_chain_host_post advances the chain's clock, counts the
/// hinges' wraps and checks its bodies. 0, or -1 (ode_chain_error says
/// which); the chain then stays stopped.
int ode_chain_host_pre(ode_chain* w);
int ode_chain_host_post(ode_chain* w);
/// The host's world failed inside ODE: the chain's bodies are not asked
/// again (its readers give NaN, as after a failure of its own world).
void ode_chain_host_failed(ode_chain* w);
/// The ODE body of chain body i (NULL for a column fixed to the ground), and
/// the frame origin (the joint) in that body's coordinates [m] (org may be
/// NULL): a point p of the frame is org + p in the body.
struct dxBody* ode_chain_body_id(const ode_chain* w, int i, double org[3]);
/// Actuator k's linkage bodies (CRANE_ACT_LINKAGE): which 0 the link (A-P),
/// 1 the rocker (C-P), each a bar along its body x centred on its origin,
/// its length [m] in len (may be NULL). NULL for a pin pair's actuator.
struct dxBody* ode_chain_link_body(const ode_chain* w, int k, int which, double* len);
/// The chain as built (the copy: slew_free set where a slew drive turns the
/// column; its actuators bound to the circuit).
const crane_chain* ode_chain_chain(const ode_chain* w);
/// Actuator k's barrel and rod pins in the world [m] (hosted) or the base
/// frame; NaN once ODE failed.
void ode_chain_act_pins(const ode_chain* w, int k, double pa[3], double pb[3]);
/// The slew command [-1, 1] (opts.slew_drive), held.
void ode_chain_set_slew_command(ode_chain* w, double u);
/// The slew drive now: rack stroke [m] and rate [m/s] (from the hinge),
/// force [N], chamber pressures [Pa abs] (any pointer may be NULL); -1
/// without a slew drive, else 0. at_stop: 1 at a rack end.
int ode_chain_slew_state(const ode_chain* w, double* x, double* v, double* F, double* pA, double* pB, int* at_stop);
const char* ode_chain_error(const ode_chain* w);
double ode_chain_time(const ode_chain* w);

/// Joint coordinates q and rates qd (ndof each; either may be NULL).
void ode_chain_q(const ode_chain* w, double* q, double* qd);
/// Actuator k's pin length [m] and its rate [m/s] (rate may be NULL);
/// stroke = length - closed_length.
double ode_chain_act_length(const ode_chain* w, int k, double* rate);
/// Actuator k's force as applied over the last step [N], and its chamber
/// pressures [Pa abs] (0 without a circuit; pA, pB may be NULL).
double ode_chain_act_force(const ode_chain* w, int k, double* pA, double* pB);
/// The tip in the world [m] (the base frame unhosted) and its velocity [m/s]
/// (v may be NULL).
void ode_chain_tip(const ode_chain* w, double p[3], double v[3]);
/// Body i's pose: rotation R (row-major, columns its axes) and origin p [m]
/// (its joint, not its centre of mass), as chain_body_pose gives them (in the
/// world when hosted).
void ode_chain_body_pose(const ode_chain* w, int i, double R[9], double p[3]);
/// 1 when actuator k is at an end stop (its joint's stop or the cylinder's own).
int ode_chain_act_at_stop(const ode_chain* w, int k);

/// The circuit's state now (hyd_model_nstate of the circuit) and the
/// hydraulic data of the last evaluation (its strokes, commands, flows,
/// relief states); both NULL without a circuit. Borrowed, valid until the
/// next step.
void ode_chain_circuit_state(const ode_chain* w, const double** y, const hyd_data** hd);
struct sim_energy;
/// Integrate the energy balance e (energy_acc.h, bound to the circuit) at
/// every hydraulic sub-step from now on; 0, or -1 (no circuit, no memory).
int ode_chain_follow_energy(ode_chain* w, struct sim_energy* e);
/// The bodies' kinetic and potential energy (m g z, z up from the ground)
/// [J]; NaN once ODE failed.
double ode_chain_energy(const ode_chain* w);

#ifdef __cplusplus
}
#endif
#endif
