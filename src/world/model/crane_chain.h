// crane_chain.h: the crane as data: a chain of bodies (the column, booms,
// telescopic extensions), the hydraulic actuators between them and the
// functions the operator commands (docs/model.md "The crane as a chain").
//
// Every model has one, whatever its file says: the two-link shorthand
// (mechanics.links, mechanics.actuators by joint) is converted by
// crane_chain_from_mech, a chain file (mechanics.bodies) is read as it is.
// Both backends build their mechanics from it (the analytic mode through
// the mechanism library, chain.h; the ODE world as hinges and sliders), so
// nothing downstream assumes a count: every array here is sized by the file.
//
// Units are SI: m, kg, s, rad, N. Body frames and joints are chain.h's: body
// 0 is the column (its joint the slew, about the base z axis), every other
// body has a parent with a smaller index and a revolute joint (in the boom
// plane) or a prismatic one (sliding along its x axis inside the parent).
#ifndef CRANE_CHAIN_H
#define CRANE_CHAIN_H

#include <stdbool.h>
#include <stddef.h>

#include "chain.h"
#include "crane_model.h"
#include "linkage.h"

#ifdef __cplusplus
extern "C" {
#endif

/// One body of the chain: the mechanism's description (joint, mass, centre of
/// mass, inertia, limits; def.name is the body's name) and what the ODE world
/// and the renderer need besides.
typedef struct crane_body {
    chain_body_def def;
    double length; ///< extent along the body's x from its origin [m] (a boom: joint to tip; the
                   ///< column: its height, along z)
    double width;  ///< box section across the boom plane (y) [m]
    double height; ///< box section in the boom plane (z) [m]; the column: its diameter
} crane_body;

typedef enum crane_act_kind {
    CRANE_ACT_CYLINDER = 0, ///< a hydraulic cylinder between two pins (force along the pins)
    /// A cylinder whose rod pushes the common pin of a four-bar linkage on a
    /// knuckle (linkage.h, docs/model.md "A cylinder through a linkage"):
    /// body_a is the knuckle's parent (the barrel pin pa there is the
    /// linkage's base B), body_b the knuckle; pb is unused (0) and lk is
    /// the loop, in body_a's frame.
    CRANE_ACT_LINKAGE = 1
} crane_act_kind;

/// One actuator: a circuit's cylinder between a pin on body_a (the barrel)
/// and a pin on body_b (the rod). Any two bodies of the chain; several may act
/// across one joint. stroke = |pin_b - pin_a| - closed_length.
typedef struct crane_act {
    char name[CRANE_NAME];     ///< "lift", "jib", "ext1"
    crane_act_kind kind;
    char cylinder[CRANE_NAME]; ///< the circuit's cylinder component
    char valve[CRANE_NAME];    ///< the circuit's directional valve that feeds it (its function's)
    int body_a;                ///< barrel pin's body
    double pa[3];              ///< barrel pin in body_a's frame [m]
    int body_b;                ///< rod pin's body
    double pb[3];              ///< rod pin in body_b's frame [m]
    double closed_length;      ///< pin-to-pin length at zero stroke [m]
    linkage lk;                ///< CRANE_ACT_LINKAGE: the checked loop (the barrel pin to the common pin P is L)
    // Resolved against the circuit by crane_chain_bind:
    int cyl;                   ///< the circuit's cylinder index
    int function;              ///< the function with the same valve
    double stroke;             ///< the cylinder's stroke [m]
} crane_act;

/// One function: what the operator commands, a valve section of the circuit.
typedef struct crane_function {
    char name[CRANE_NAME];  ///< "lift", "jib", "ext", "slew"
    char valve[CRANE_NAME]; ///< the circuit's directional valve
    int valve_idx;          ///< its index (crane_chain_bind)
} crane_function;

/// The slew drive: a rack-and-pinion cylinder on the column's slew joint
/// (body 0's joint, about the base z axis). The rack is the cylinder's rod: a
/// stroke x turns the pinion (radius r) to slew = (x - stroke/2) / r, so
/// mid-stroke is slew 0 (crane_slew_stroke), and a rack force F [N] is a
/// torque F r [N m] on the column (crane_slew_torque). It is kept apart from
/// act[] (cylinders between two pins): every consumer of act[] handles pin
/// cylinders only, and the drive is used where a run slews (the ODE sandbox).
typedef struct crane_slew {
    bool present;              ///< the model has a slew drive (mechanics.slew)
    char cylinder[CRANE_NAME]; ///< the rack cylinder, a component of hydraulics_slew
    char valve[CRANE_NAME];    ///< its directional valve (the slew function), in hydraulics_slew
    double pinion_radius;      ///< [m]
    double column_radius;      ///< column tube radius (collision, drawing) [m]
    double damping;            ///< slewing-ring bearing viscous friction [N m s/rad]
} crane_slew;

/// Rack stroke [m] at slew angle theta [rad] for a cylinder of full stroke
/// s [m]: r theta + s/2 (the ODE world's convention).
static inline double crane_slew_stroke(const crane_slew* sl, double theta, double s) {
    return sl->pinion_radius * theta + 0.5 * s;
}
/// Torque [N m] about the slew axis of a rack force F [N].
static inline double crane_slew_torque(const crane_slew* sl, double F) { return F * sl->pinion_radius; }

/// One output column of a chain crane beyond the run's base columns
/// (crane_chain_columns): per actuator x_<a> [m], v_<a> [m/s], pA_<a>,
/// pB_<a> [Pa], F_<a> [N]; per function u_<f>, ucmd_<f> [-]; per degree of
/// freedom q_<body> [rad or m] and qd_<body> [rad/s or m/s]. Where the
/// column slews by its drive (slew_rack_columns) the slew rack is
/// one more actuator and function, both named "slew", after the chain's
/// (x_slew .. F_slew, u_slew, ucmd_slew), and the slew its first DOF.
typedef struct crane_column {
    char name[CRANE_NAME + 8];
    const char* unit;
    bool pressure; ///< an absolute pressure (the run checks judge it as one)
} crane_column;

/// The values of one row's chain columns, as a backend has them (arrays of
/// nact, nfn and ndof entries; ndof as crane_chain_ndof).
typedef struct crane_chain_sample {
    const double *x, *v, *pA, *pB, *F; ///< per actuator [m, m/s, Pa, Pa, N]
    const double *u, *ucmd;            ///< per function: spool, command [-]
    const double *q, *qd;              ///< per degree of freedom
} crane_chain_sample;

/// The crane: bodies in chain order (body 0 the column), actuators, functions.
typedef struct crane_chain {
    int nbody;
    crane_body* body;
    int nact;
    crane_act* act;
    int nfn;
    crane_function* fn;
    int tip_body;     ///< the body that carries the tip (the hook point, the tip load)
    double tip[3];    ///< the tip in that body's frame [m]
    double gravity;   ///< [m/s^2], along -z of the base frame
    bool slew_free;   ///< the column slews (a degree of freedom where the model has a slew drive)
    crane_slew slew;  ///< the slew drive, if the model has one (slew.present)
    /// The rows carry the slew rack's columns (crane_chain_columns, with
    /// slew_free and slew.present): set by the analytic mode's slewing run
    /// (engine_chain_slew_setup), whose samples have the rack last. A
    /// backend that frees the column otherwise keeps its columns as they were.
    bool slew_rack_columns;
    /// True when the chain came from the two-link shorthand: the analytic
    /// backend may then run its closed-form fast path (lagrange.h), which
    /// handles exactly that shape and nothing else.
    bool two_link;
    /// The chain's own output columns (crane_chain_columns; none for the
    /// two-link shorthand, whose base columns say everything). Owned.
    int ncol;
    crane_column* col;
} crane_chain;

/// The chain of a two-link crane_mech: the column (fixed at slew 0, a solid
/// cylinder of radius 0.1 m), the lifting arm and the end arm as
/// chain_from_crane_mech builds them (without the tip load: the tip is the
/// end arm's tip), both actuators with their mounts, and one function per
/// actuator named as the actuator, on its valve. Returns 0, or -1 with one
/// line in err (out of memory, an actuator's joint not 0 or 1).
int crane_chain_from_mech(const crane_mech* m, crane_chain* out, char* err, size_t errsz);

/// Resolves the actuators' cylinders and the functions' valves in circuit h
/// (struct hyd_model, hydraulics.h): cyl, stroke, valve_idx, and each
/// actuator's function (the one on the same valve). Returns 0, or -1 with
/// "mechanics.actuators[i].cylinder: no cylinder 'x' in the circuit" (or
/// .valve, or functions[i].valve; or an actuator whose valve no function
/// commands) in err.
struct hyd_model;
int crane_chain_bind(crane_chain* cc, const struct hyd_model* h, char* err, size_t errsz);

/// The mechanism of the chain (chain.h) with a point mass tip_mass [kg] at
/// the tip, the column free to slew when slew_free (else fixed at slew
/// [rad]). NULL with chain_create's message in err.
chain* crane_chain_mechanism(const crane_chain* cc, double tip_mass, bool slew_free, double slew, char* err,
                             size_t errsz);

/// As crane_chain_mechanism; lump_links false leaves the masses of the
/// linkages' links out of the booms (the ODE world makes them bodies),
/// true (crane_chain_mechanism) lumps them at their pins (linkage_lump).
chain* crane_chain_mechanism_links(const crane_chain* cc, double tip_mass, bool slew_free, double slew,
                                   bool lump_links, char* err, size_t errsz);

/// Actuator a's pin length L [m] on mechanism ch at the workspace's last
/// chain_update, its rate, lever arms dL/dq [ndof] and their rate, as
/// chain_cylinder (any output may be NULL): a pin pair's from its two pins,
/// a linkage's from its loop (linkage_cylinder). The one place that knows
/// the actuator kinds' geometry; every backend asks it.
double crane_act_length(const crane_act* a, const chain* ch, const chain_ws* w, double* Ldot, double* dL_dq,
                        double* dLdot_dq);
/// Its Hessian d2L/dq2 (ndof x ndof), as chain_cylinder_hessian.
void crane_act_hessian(const crane_act* a, const chain* ch, chain_ws* w, double* H);

/// The degrees of freedom of the chain as the backends integrate it: every
/// body whose joint is not fixed, the column only when slew_free.
int crane_chain_ndof(const crane_chain* cc);
/// Body of DOF k (crane_chain_ndof order), or -1.
int crane_chain_dof_body(const crane_chain* cc, int k);

/// The start pose of the chain's DOFs [crane_chain_ndof of them, rad or m,
/// slew first when the column slews] for a scenario's start: the slew at
/// slew0, the first two boom DOFs at q12 (the paper's q1, q2), every other
/// DOF at the middle of its joint limits (0 clamped into them when either
/// is open). Both backends' chain runs start from it.
void crane_chain_start_pose(const crane_chain* cc, const double q12[2], double slew0, double* q0);

/// Makes the chain's output columns (cc->col, cc->ncol): none when
/// two_link, else per actuator, per function and per DOF as crane_column
/// says; with the slew rack (slew_rack_columns) the rack's too,
/// and for two_link only the rack's, its function's and the slew DOF's (the
/// base columns have the rest). 0, or -1 when out of memory.
/// crane_chain_bind calls it.
int crane_chain_columns(crane_chain* cc);
/// Writes one row's chain columns (cc->ncol values) from s into out; with
/// the slew rack, s's actuator and function arrays have it last (index
/// nact, nfn), as chain_sim's outputs.
void crane_chain_row(const crane_chain* cc, const crane_chain_sample* s, double* out);

/// A deep copy (dst's arrays are new). 0, or -1 when out of memory.
int crane_chain_copy(crane_chain* dst, const crane_chain* src);
void crane_chain_free(crane_chain* cc);

/// Index of the body, actuator or function of that name, or -1.
int crane_chain_find_body(const crane_chain* cc, const char* name);
int crane_chain_find_act(const crane_chain* cc, const char* name);
int crane_chain_find_function(const crane_chain* cc, const char* name);
/// Index in cc->col of the chain column "<what>_<name>" (what: "x", "pA",
/// "ucmd", "q", ...; name: an actuator's, a function's or a body's), or -1.
int crane_chain_find_column(const crane_chain* cc, const char* what, const char* name);

#ifdef __cplusplus
}
#endif
#endif
