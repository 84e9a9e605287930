// ode_world.h: the Open Dynamics Engine backend of the crane world.
//
// Two worlds (world_desc.h): "validation" (column fixed to the ground, the
// load merged rigidly into the end arm at its tip, no contacts: the same
// system as lagrange "full") and "sandbox" (truck on outriggers on a terrain
// heightfield, slewing column, rope and hook, loads to pick up, obstacles).
// The hydraulic circuit (hydraulics.h) drives the cylinders; ode_coupling.c
// sub-steps it inside each ODE step (docs/ode_world.md, "Coupling").
//
// Model/data split: the crane_mech, the world_desc and the circuit are read
// at create time and copied/compiled; the ode_world then holds only state.
// Nothing allocates inside ode_world_step (ODE's own step arena is reserved
// at create time and reused; see docs/ode_world.md).
//
// Angle conventions are the paper's (crane_model.h): q1 from the downward
// vertical, q2 relative to the lifting arm, counter-clockwise positive seen
// with the boom plane's x to the right and z up. The slew angle is about the
// truck's z axis, 0 = boom plane along the truck's +x.
#ifndef ODE_WORLD_H
#define ODE_WORLD_H

#include <cjson/cJSON.h>
#include <stddef.h>

#include "crane_chain.h"
#include "crane_model.h"
#include "hyd_solver.h"
#include "world_desc.h"
#include "world_snapshot.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ode_world ode_world;

/// Actuator indices in ode_world_state arrays and in commands.
enum { ODE_LIFT = 0, ODE_JIB = 1, ODE_SLEW = 2, ODE_NACT = 3 };

/// Options of an ODE world run. Get defaults from ode_world_default_opts().
typedef struct ode_world_opts {
    double dt_ode;        ///< ODE step [s]; default 1e-3
    double dt_hyd;        ///< hydraulic sub-step [s]; default 1e-4; dt_ode must be a whole multiple
    hyd_method solver;    ///< hydraulic integrator; default HYD_KRUS. Fixed-step methods take
                          ///< dt_hyd sub-steps; adaptive ones (ros34pw2, rodas3) choose their
                          ///< own steps, bounded by and landing on each ODE step
    double rtol, atol;    ///< adaptive hydraulics: tolerances [-], [state units]; 0: 1e-3, 1e-6
    int dense_jac;        ///< fixed-step: 1 = dense W; 0 (default) = block-diagonal W from the
                          ///< circuit's stiff couplings (W-methods keep their order for any W)
    int no_retry;         ///< fixed-step methods: no retry of a failed sub-step in shorter ones (sim_opts.no_retry)
    int jac_every;        ///< reuse the hydraulic Jacobian for this many sub-steps; default 10 (1 ms of J age at 0.1 ms; up to 10 ms of age is allowed)
    double q0[2];         ///< initial joint angles q1, q2 [rad], paper convention; default 95, -130 deg
    double slew0;         ///< initial slew angle [rad]; default 0
    double load_mass;     ///< validation world: tip mass [kg]; < 0 (default) uses mech->load_mass
    int hydraulics;       ///< 1 (default): cylinders driven by the circuit; 0: no hydraulic forces
    int stop_limits;      ///< 1 (default): cylinder end stops as ODE hinge limits; 0: none
    int init_hold;        ///< 1 (default): initial chamber pressures hold the crane still
    double p_low;         ///< init_hold: pressure of the unloaded chamber side [Pa abs]; default 2e6
    int force_average;    ///< 0 (default): apply the force at the end of the sub-steps (symplectic, stable); 1: their mean (unstable for light booms, see docs/ode_world.md)
    const char* model_file; ///< name used in circuit error messages; default "model"
    int general_circuit;  ///< 1: the circuit's component loops (hyd_eval) for the hydraulic
                          ///< solver even when the straight-line kernel applies (hyd_fused.h);
                          ///< 0 (default): that kernel when the circuit has its shape
    hyd_model* circuit;   ///< the model's compiled circuit (borrowed, not freed): used as the
                          ///< world's own when the world adds no circuit of its own, so a run
                          ///< and its panel share one hyd_model; NULL (default) compiles the
                          ///< "hydraulics" section
    /// The model's chain (borrowed while the world is created). A chain that
    /// is not two_link builds the sandbox's crane from it (ode_chain.h,
    /// hosted on the truck, the model's or the world's slew drive on the
    /// column; docs/ode_world.md "The sandbox from the chain"); NULL
    /// (default) or a two_link chain: the two-link crane from mech, as
    /// always. Only the sandbox takes a chain (the validation world of a
    /// chain is ode_chain's own).
    const crane_chain* chain;
} ode_world_opts;

ode_world_opts ode_world_default_opts(void);

/// Everything the CSV and the tests read, in SI units. Actuator arrays are
/// indexed ODE_LIFT, ODE_JIB, ODE_SLEW (slew entries are 0 in validation).
typedef struct ode_world_state {
    double t;                 ///< simulated time [s]
    double x[ODE_NACT];       ///< cylinder strokes [m] (pin length - closed length; slew: rack travel)
    double v[ODE_NACT];       ///< stroke rates [m/s]
    double pA[ODE_NACT];      ///< chamber A pressures [Pa abs]
    double pB[ODE_NACT];      ///< chamber B pressures [Pa abs]
    double u[ODE_NACT];       ///< spool openings [-]
    double u_cmd[ODE_NACT];   ///< spool commands [-]
    double F[ODE_NACT];       ///< cylinder forces as applied to the bodies [N], + extends
    double q[2];              ///< joint angles [rad], paper convention
    double qd[2];             ///< joint rates [rad/s]
    double slew;              ///< slew angle [rad]
    double slew_rate;         ///< [rad/s]
    double tip[2];            ///< end-arm tip relative to joint 1 in the boom plane: reach x, height z [m]
    double tip_world[3];      ///< end-arm tip in the world [m]
    double hook[3];           ///< hook attach point (bottom of the hook block) [m]; tip in validation
    double hook_vel[3];       ///< its velocity [m/s]
    double p_pump;            ///< pump-line pressure [Pa abs] (0 if the circuit has none)
    double truck_tilt;        ///< angle of the truck's z axis from vertical [rad]
    double max_depth_crane;   ///< deepest contact of a crane part (column, booms) in the last step [m]
    double max_depth;         ///< deepest contact of any pair in the last step [m]
    int ncontact;             ///< contact points in the last step
    int attached;             ///< index of the load on the hook, or -1
    int end_stop;             ///< bit k: cylinder k at an end stop (hinge limit active or hydraulic stop)
    int relief_open;          ///< number of relief valves passing flow
    // Sandbox: the truck's supports (the outrigger pads; the wheels when the
    // outriggers are in), index 2 a + s: a = 0 front, 1 rear; s = 0 left
    // (+y of the truck), 1 right. Zeros in the validation world.
    double pad_F[4];          ///< vertical ground reaction on each support [N], low-passed over about 5 ms
    int pad_lifted;           ///< bit i: support i carries less than ODE_PAD_LIFT_FRAC of the weight
                              ///< (never before ODE_SUPPORT_SETTLE_T)
    /// Static stability margin of the current pose: the restoring over the
    /// tipping moment of the weights of truck, crane, rope, hook and the
    /// hooked load about the governing tipping line (the support polygon's
    /// edge with the least ratio). Below 1 the truck tips over that line.
    /// ODE_STAB_MARGIN_MAX when nothing is outboard of any line.
    double stab_margin;
} ode_world_state;

/// A support counts as lifted off below this fraction of the total weight
/// it and the others carry (1 %: about 0.9 kN on the shipped sandbox, where
/// each pad carries about 23 kN at rest).
#define ODE_PAD_LIFT_FRAC 0.01
/// The truck starts 0.5 mm above the ground, lands within 10 ms and stops
/// rocking on its pads within 60 ms (the sandbox): no support counts as
/// lifted off before this time [s] (metrics likewise).
#define ODE_SUPPORT_SETTLE_T 0.1
/// The stability margin reported when no weight is outboard of a tipping line.
#define ODE_STAB_MARGIN_MAX 10.0

/// Build a world. mech: crane mechanics (copied). hydraulics: the model's
/// "hydraulics" JSON section (read, not kept); may be NULL when
/// o->hydraulics == 0 or when o->circuit is given and the world adds no
/// circuit. The world's circuit extras are compiled with it as one circuit
/// (an error in them names the world file); without extras the world runs on
/// o->circuit when given. Returns NULL with one line "file: field: problem" in err.
ode_world* ode_world_create(const crane_mech* mech, const cJSON* hydraulics, const world_desc* w,
                            const ode_world_opts* o, char* err, size_t errsz);
void ode_world_destroy(ode_world* w);

/// Valve commands lift, jib, slew in [-1, 1] (clamped), held until changed.
void ode_world_set_commands(ode_world* w, const double u_cmd[ODE_NACT]);
/// 1: attach the nearest load whose top centre is within hook.reach of the
/// hook's attach point (no-op if none or already attached); 0: release.
/// Returns the load index attached, or -1.
int ode_world_hook(ode_world* w, int attach);
/// The load nearest the hook: its index (-1 when the world has none) and
/// the distance [m] from the hook's attach point to its top centre, the
/// distance ode_world_hook compares with hook.reach [m] (*reach, may be NULL).
int ode_world_nearest_load(const ode_world* w, double* dist, double* reach);

/// Advance by dt [s] (rounded to a whole number of ODE steps, at least one).
/// Returns 0, or -1 when a body or hydraulic state became non-finite; then
/// ode_world_error() names it and the time, and the world stays stopped.
int ode_world_step(ode_world* w, double dt);
const char* ode_world_error(const ode_world* w);
/// The collision pairs touching in the last ODE step (a crane part against
/// the terrain, the truck, an obstacle or a load; the hook against the truck
/// or an obstacle): body names into names[i][0] (the crane's, or the hook)
/// and names[i][1], at most max of them (the world records up to 16 a step).
/// Returns their number, or -1 in a world without contacts (validation).
/// The names live as long as the world.
int ode_world_collisions(const ode_world* w, const char* names[][2], int max);

/// Fill the renderer's picture completely (all bodies, cylinders, rope, terrain, flags).
void ode_world_snapshot(const ode_world* w, world_snapshot* s);
/// Current state for CSV and tests.
void ode_world_get_state(const ode_world* w, ode_world_state* s);

/// The run's compiled circuit (model plus world extras, or opts.circuit
/// itself), for live parameter changes with hyd_model_set between steps;
/// NULL without hydraulics.
hyd_model* ode_world_circuit(ode_world* w);
/// Its state now (hyd_model_nstate entries) into y, and the hydraulic data
/// of its last evaluation (strokes, rates, commands) in *in (NULL without
/// hydraulics): what the engine publishes as circuit channels.
void ode_world_circuit_state(const ode_world* w, double* y, const hyd_data** in);
/// Give boom k (0 lifting arm, 1 end arm) link ln's mass and inertia in
/// place (dBodySetMass), keeping its motion. Returns 0, or -1 (nothing
/// changed) when that needs a rebuild: another length, section or centre of
/// mass than the body was built with (its origin is its centre of mass), or
/// a chain crane (ode_world_chain).
int ode_world_set_link_mass(ode_world* w, int k, const crane_link* ln);
/// 1 when the hydraulic solver runs on the straight-line circuit kernel
/// (hyd_fused.h), 0 on the component loops (opts.general_circuit, or a
/// circuit of another shape).
int ode_world_fused(const ode_world* w);
/// 1 when the hydraulic sub-steps evaluate the circuit with the fast kernel
/// (circuit_fast.h: a circuit without the one-pass kernel's shape), 0 otherwise.
int ode_world_fast(const ode_world* w);
/// Chamber pressures pA, pB [Pa abs] of the actuators (ODE_LIFT, ODE_JIB,
/// ODE_SLEW; 0 where there is none), straight from the hydraulic state:
/// cheap enough for every step.
void ode_world_chamber_pressures(const ode_world* w, double pA[ODE_NACT], double pB[ODE_NACT]);
/// Non-fatal messages ODE has sent so far in this process (a degenerate
/// contact LCP), and the last one's text in *last (may be NULL).
long ode_world_messages(const char** last);

/// The chain crane's world (opts.chain), for its per-actuator and per-DOF
/// state (ode_chain_q, ode_chain_act_length, ...; read only, never stepped
/// alone); NULL for the two-link crane. With a chain, ode_world_state's
/// two-link fields hold: x, v, F, pA, pB, u, u_cmd [ODE_LIFT], [ODE_JIB] the
/// chain's first two actuators, [ODE_SLEW] the slew rack; q, qd the first
/// two boom DOFs; tip relative to body 1's joint. ode_world_set_commands
/// then drives the functions of the first two actuators and the slew.
struct ode_chain* ode_world_chain(const ode_world* w);

/// Simulated time [s].
double ode_world_time(const ode_world* w);
/// ODE step actually used [s].
double ode_world_dt(const ode_world* w);
world_kind ode_world_kind(const ode_world* w);

/// Loads (sandbox): count, and centre position [m] and velocity [m/s] of load i.
int ode_world_nload(const ode_world* w);
void ode_world_load_state(const ode_world* w, int i, double pos[3], double vel[3]);
/// Name and mass [kg] of load i (from the world file); NULL if i is out of range.
const char* ode_world_load_name(const ode_world* w, int i, double* mass);
/// Body centre [m] of the obstacle named name; returns 0, or -1 if not found.
int ode_world_obstacle_pos(const ode_world* w, const char* name, double pos[3]);

// ---- Test and study hooks (not needed for ordinary runs) ----

/// Extra joint torques [N m] added every step at joints 1, 2 (in the q
/// directions), e.g. the analytic holding torque G(q) with hydraulics off.
/// The two-link crane only, as the other hooks of joints 1, 2 below
/// (hold_crane, lock_booms, set_joint_rates): they do nothing for a chain
/// crane (ode_world_chain; ode_chain_set_joint_forces for this one).
void ode_world_set_joint_torques(ode_world* w, const double tau[2]);
/// 1: freeze the truck, column and booms (kinematic, at rest) so only rope,
/// hook and loads move; 0: release them.
void ode_world_hold_crane(ode_world* w, int hold);
/// 1: lock both boom hinges at their current angles (hinge stops lo = hi),
/// as if the load-holding valves were shut on an incompressible column, to
/// study the truck's stability alone; 0: restore the stroke-derived limits.
void ode_world_lock_booms(ode_world* w, int lock);
/// Mechanical energy of all dynamic bodies [J]: kinetic (translation and
/// rotation) plus gravitational potential relative to z = 0.
double ode_world_energy(const ode_world* w);
/// The same for parts of the crane [J]: its column and booms into *crane,
/// its rope links and hook into *hook (0 where the world has none; NAN for
/// both once ODE has failed in the world).
void ode_world_part_energy(const ode_world* w, double* crane, double* hook);
/// Set the joint rates q1', q2' [rad/s] (rigidly moving the distal bodies), for tests.
void ode_world_set_joint_rates(ode_world* w, const double qd[2]);
/// Rope model for analytic checks: number of rope links, link length [m],
/// mass [kg] and inertia about a transverse axis through its centre [kg m^2]
/// (raised above the capsule's own for the ODE step, see build_rope), hook
/// mass [kg], hook pin-to-COM distance [m] and hook inertia about its COM
/// about the body y axis [kg m^2].
void ode_world_rope_info(const ode_world* w, int* nlink, double* link_len, double* link_mass, double* link_inertia,
                         double* hook_mass, double* hook_com, double* hook_inertia);
/// Set rope links and hook moving as one rigid body rotating with angular
/// velocity omega [rad/s] (world axes) about the end-arm tip pin: starts a
/// clean pendulum swing (sandbox only).
void ode_world_swing_hook(ode_world* w, const double omega[3]);
/// Per-step hydraulic sub-steps taken since create (for benchmarks).
long ode_world_hyd_steps(const ode_world* w);
struct sim_energy;
/// Integrate the energy balance e (energy_acc.h, bound to ode_world_circuit)
/// at every hydraulic step by the step's own method, starting with a
/// sample at the present state; the caller passes the mechanics' energy
/// after each ODE step (sim_energy_mech). e must outlive the world's steps.
/// 0, or -1 (no circuit, out of memory).
int ode_world_follow_energy(ode_world* w, struct sim_energy* e);
/// The hydraulic solver's work counters (steps, rejections, f evaluations,
/// Jacobians, factorisations) since the world was created; zeros without
/// hydraulics.
hyd_solver_stats ode_world_hyd_stats(const ode_world* w);

#ifdef __cplusplus
}
#endif
#endif
