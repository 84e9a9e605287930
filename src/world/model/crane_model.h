// crane_model.h: the mechanical description of the knuckle-boom crane.
//
// Planar geometry in the boom plane: x horizontal (reach), z up, origin at
// joint 1 (column top). Angles follow the paper: q1 is the lifting arm's angle
// from the downward vertical, q2 the end arm's angle relative to the lifting
// arm (counter-clockwise positive when seen with x right, z up). So the lifting
// arm's elevation above horizontal is q1 - pi/2. See docs/lagrange.md.
//
// Link frames: the column frame is fixed (x forward, z up, origin joint 1).
// Link i's frame has its origin at joint i and x along the link towards the
// next joint (or the tip); z is x rotated +90 degrees.
#ifndef CRANE_MODEL_H
#define CRANE_MODEL_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define CRANE_NAME 48

/// Tip load [kg] (mechanics.load_mass, a scenario's load_mass, --load): at
/// most CRANE_LOAD_MAX, a note above CRANE_LOAD_TYPICAL. 3000 kg already
/// opens the port reliefs of the HIAB-031-class crane (the overload
/// scenario); 10 t is beyond any crane of this size, and 100 t peaked at
/// 1.05 GPa in a run that exited 0.
#define CRANE_LOAD_MAX 1e4
#define CRANE_LOAD_TYPICAL 3000.0

/// One boom (rigid link).
typedef struct crane_link {
    char name[CRANE_NAME];
    double length;  ///< joint to next joint (or tip) [m]
    double mass;    ///< [kg]
    double com;     ///< distance from its joint to its centre of mass, along the link [m]
    double inertia; ///< moment of inertia about the COM, about the joint axis [kg m^2]
    double width;   ///< box-section width, for the 3D world and rendering [m]
    double height;  ///< box-section height [m]
} crane_link;

/// A cylinder acting across one joint. Mount points are 2D (x, z) coordinates
/// relative to the joint, in the parent and child link frames.
typedef struct crane_actuator {
    char name[CRANE_NAME];     ///< "lift", "jib"
    int joint;                 ///< 0: joint 1 (column-lifting arm); 1: joint 2 (lifting arm-end arm)
    char cylinder[CRANE_NAME]; ///< name of the cylinder component in the hydraulic circuit
    char valve[CRANE_NAME];    ///< name of its directional valve in the circuit
    double base_mount[2];      ///< barrel pin in the parent frame, relative to the joint [m]
    double rod_mount[2];       ///< rod pin in the child frame, relative to the joint [m]
    double closed_length;      ///< pin-to-pin length at zero stroke [m]
    /* Derived at load time (paper Eq. 5): x_pin = sqrt(a^2 + b^2 - 2ab cos(phi)),
       phi = q_joint + phi_offset. */
    double a;          ///< |base_mount| [m]
    double b;          ///< |rod_mount| [m]
    double phi_offset; ///< phi - q_joint [rad]
    double sin_offset; ///< sin(phi_offset), cos(phi_offset): phi by addition identities
    double cos_offset;
} crane_actuator;

/// Mechanical parameters of the crane (read-only during a step).
typedef struct crane_mech {
    double gravity;       ///< [m/s^2]
    double column_height; ///< joint 1 above the truck bed [m]
    double column_mass;   ///< [kg] (3D world only)
    crane_link link[2];   ///< lifting arm, end arm
    double load_mass;     ///< mass rigidly at the end-arm tip (lagrange, validation world) [kg]
    crane_actuator act[2];
    // The maker's rating, the load chart's cap (docs/safety.md), optional:
    // 0 when the model file gives none. In the file's units (the mechanics
    // parameter table writes values back to the file as they are).
    double rated_moment; ///< rated load moment m g R [kN m] (mechanics.rated_moment)
    double rated_load;   ///< rated load close in [kg] (mechanics.rated_load)
} crane_mech;

/// Fill with the built-in HIAB-031-class defaults (docs/model.md).
crane_mech crane_default_mech(void);

/// Compute the derived fields (a, b, phi_offset) from the mount points.
void crane_mech_derive(crane_mech* m);

/// Cylinder pin-to-pin length [m] and its derivative d(x_pin)/d(q_joint) [m/rad]
/// for actuator k at joint angle q [rad]. Paper Eq. 5.
double crane_pin_length(const crane_actuator* a, double q, double* dx_dq);

/// Stroke [m] (pin length minus closed length) at joint angle q [rad].
double crane_stroke(const crane_actuator* a, double q);

/// Joint angle [rad] that gives stroke x [m] (inverse of crane_stroke over the
/// branch phi in (0, pi)). Returns NAN if unreachable.
double crane_joint_for_stroke(const crane_actuator* a, double x);

/// Whether joint angle q [rad] is a pose actuator a reaches over its stroke
/// [0, stroke] m on the mounts' branch. Returns 0, or -1 with a one-line
/// message giving the joint's range in degrees.
int crane_check_pose(const crane_actuator* a, double stroke, double q, char* err, size_t errsz);

/// Tip position relative to joint 1 (x reach, z height) [m].
void crane_tip(const crane_mech* m, double q1, double q2, double* x, double* z);

/// Gravity torques G(q) about joints 1 and 2 [N m] at joint angles q [rad]
/// with mass m3 [kg] at the tip: the static holding torques, which the load
/// chart, the limiter and the start checks weigh the crane by. The same
/// expressions and order of operations as the analytic backend's G
/// (lagrange_gravity with LAGRANGE_FULL), so the two agree bit for bit; it is
/// here so that those users need the crane model, not a backend.
void crane_gravity(const crane_mech* m, double m3, const double q[2], double G[2]);

/// Problem found by crane_mech_check, written as "field: message".
/// Returns 0 if the geometry is usable: phi inside (15, 165) deg over the
/// stroke [0, stroke_k] of each actuator, positive lengths, masses and
/// inertias, each centre of mass on its link (0 <= com <= length).
int crane_mech_check(const crane_mech* m, const double stroke[2], char* err, int errsz);

#ifdef __cplusplus
}
#endif
#endif
