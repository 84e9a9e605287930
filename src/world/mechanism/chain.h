// chain.h: kinematics and dynamics of a crane as a chain of rigid bodies on a
// slewing column (docs/mechanism.md). libm only; no allocation per evaluation.
//
// Frames and joints (SI units throughout: m, kg, s, rad, N, N m):
//
// * The base frame ("world" here) is the truck's: x forward, y left, z up.
//   Gravity is a vector in it (default 0, 0, -9.81 m/s^2), so a tilted truck
//   is a tilted gravity vector.
// * Body 0 is the column. Its joint is the slew: a rotation about the base z
//   axis through `origin` (base coordinates). Positive slew turns x towards y
//   (counter-clockwise seen from above). It may be `fixed` (the validation
//   mode: the slew is not a degree of freedom).
// * Bodies 1..n-1 each have a parent with a smaller index (a chain, or a tree:
//   a jib extension on a knuckle) and one joint:
//   - CHAIN_REVOLUTE: a rotation about the y axis of the joint (the normal of
//     the boom plane), the child's frame at the joint origin, rotated from the
//     parent's by angle0 + q in the boom plane; positive q turns x towards z
//     (counter-clockwise seen with x right and z up, a right-hand rotation
//     about -y), as the crane's q1 and q2 do (docs/lagrange.md). The lifting
//     arm has angle0 = -pi/2 (q1 from the downward vertical), the end arm
//     angle0 = 0 (q2 relative to the lifting arm).
//   - CHAIN_PRISMATIC: a slide along the child's x axis, which is the
//     parent's x turned by the constant angle0 in the boom plane (0 for an
//     extension sliding inside its boom); the child's origin is at
//     origin + (offset0 + q) x_child (parent coordinates).
//   Every joint may be `fixed` at q_fixed (not a degree of freedom).
// * Degrees of freedom: the joints that are not fixed, in body order.
//   q, qd, qdd, tau, M and the Jacobians' columns are indexed by them.
//   tau is a torque [N m] for a rotation, a force [N] for a slide.
//
// Use: chain_create (validates and copies the bodies), chain_ws_create or
// chain_ws_init (the workspace, once per thread), then per evaluation
// chain_update(q, qd) followed by any of the queries, which read the
// workspace's kinematics. Sizes come from the bodies: no fixed maximum.
#ifndef CRANESIM_MECHANISM_CHAIN_H
#define CRANESIM_MECHANISM_CHAIN_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define CHAIN_NAME 48

typedef enum chain_joint {
    CHAIN_REVOLUTE = 0, ///< rotation in the boom plane (body 0: the slew, about base z)
    CHAIN_PRISMATIC = 1 ///< slide along the child's x (not for body 0)
} chain_joint;

/// One body and the joint to its parent (the description; chain_create copies it).
typedef struct chain_body_def {
    char name[CHAIN_NAME]; ///< for messages ("" allowed)
    int parent;            ///< body index < this one's; -1 for body 0 (the base)
    chain_joint joint;
    int fixed;             ///< 1: the joint is locked at q_fixed (not a DOF)
    double q_fixed;        ///< [rad] or [m]
    double origin[3];      ///< joint origin in the parent frame (body 0: base frame) [m]
    double angle0;         ///< revolute: the child's angle at q = 0; prismatic: the slide's angle [rad]
    double offset0;        ///< prismatic: slide at q = 0 [m] (ignored for revolute)
    double mass;           ///< [kg], > 0
    double com[3];         ///< centre of mass in the body frame [m]
    double inertia[3][3];  ///< about the centre of mass, body axes [kg m^2], symmetric positive semi-definite
    double q_min, q_max;   ///< joint limits [rad] or [m] (stored and checked, not enforced here)
} chain_body_def;

/// A body with all zeros, parent i - 1 (the caller sets it), unbounded limits.
void chain_body_init(chain_body_def* b, int parent);

/// Inertia about the centre of a uniform box of the given mass [kg] and
/// size along x, y, z [m] (a boom's box section: length, width, height).
void chain_inertia_box(double mass, double lx, double ly, double lz, double I[3][3]);

/// Inertia about the centre of a boom whose model gives only the moment
/// about its joint axis, Iyy [kg m^2]: the other two from its box, length
/// (x), width (y), height (z) [m]: Ixx = m (w^2 + h^2) / 12, Izz = m (L^2 +
/// w^2) / 12, as the ODE world builds its booms today. Only an Iyy near the
/// box's gives a rigid body's moments (chain_create refuses others).
void chain_inertia_section(double mass, double Iyy, double length, double width, double height, double I[3][3]);

/// Merges a point mass m [kg] at p (body frame) [m] into the body: new mass,
/// centre of mass and inertia about it (parallel-axis theorem). A load
/// rigidly at a boom tip.
void chain_body_add_point_mass(chain_body_def* b, double m, const double p[3]);

typedef struct chain chain;       ///< the compiled chain (read-only while evaluating)
typedef struct chain_ws chain_ws; ///< per-thread workspace: kinematics and scratch

/// Validates and copies nbody bodies; gravity [m/s^2] in the base frame
/// (NULL: 0, 0, -9.81). Returns NULL with a one-line "bodies[i] (name).field:
/// problem" in err on bad input (or "out of memory").
chain* chain_create(const chain_body_def* body, int nbody, const double gravity[3], char* err, size_t errsz);
void chain_free(chain* c);

int chain_nbody(const chain* c);
int chain_ndof(const chain* c);
/// The DOF of body i, or -1 when its joint is fixed.
int chain_body_dof(const chain* c, int i);
/// The body whose joint is DOF k.
int chain_dof_body(const chain* c, int k);
/// The copied description of body i.
const chain_body_def* chain_body(const chain* c, int i);
/// The index of the body named name (the first one), or -1 (a model file's
/// actuators name their bodies).
int chain_find_body(const chain* c, const char* name);

/// Workspace size [bytes] and set-up in caller memory (aligned as malloc's);
/// chain_ws_create does both with one malloc (free with chain_ws_free).
size_t chain_ws_bytes(const chain* c);
chain_ws* chain_ws_init(const chain* c, void* mem);
chain_ws* chain_ws_create(const chain* c);
void chain_ws_free(chain_ws* w);

/// Forward kinematics at q [ndof] and velocities qd [ndof] (NULL: at rest):
/// every body's pose and velocity, the joints' axes. Every query below reads them.
void chain_update(const chain* c, chain_ws* w, const double* q, const double* qd);

/// Pose of body i: R (row-major, its columns the body axes in the base frame)
/// and the body origin p [m]. Either may be NULL.
void chain_body_pose(const chain* c, const chain_ws* w, int i, double R[9], double p[3]);

/// The joint coordinate of body i as the last chain_update set it [rad or
/// m] (q_fixed for a locked joint) and its rate (qd may be NULL; 0 when locked).
double chain_joint_q(const chain* c, const chain_ws* w, int i, double* qd);

/// Base-frame position [m] and velocity [m/s] (either may be NULL) of the
/// point pb [m] fixed in body i.
void chain_world_point(const chain* c, const chain_ws* w, int i, const double pb[3], double p[3], double v[3]);

/// Jacobian dp/dq (3 x ndof, row-major: row x, y, z) of the point pb fixed
/// in body i [m/rad or m/m]; Jdot (may be NULL) is its time derivative at qd.
void chain_point_jacobian(const chain* c, const chain_ws* w, int i, const double pb[3], double* J, double* Jdot);

/// Joint-space mass matrix M(q) (ndof x ndof, row-major, both halves) by the
/// composite-rigid-body algorithm [kg m^2, kg m, kg].
void chain_mass_matrix(const chain* c, chain_ws* w, double* M);

enum {
    CHAIN_VELOCITY = 1, ///< Coriolis and centrifugal terms
    CHAIN_GRAVITY = 2   ///< gravity
};
/// Inverse dynamics by recursive Newton-Euler: tau = M qdd + [C(q, qd)] + [G(q)]
/// with the terms `terms` selects (qdd NULL: zero). CHAIN_VELOCITY |
/// CHAIN_GRAVITY with qdd NULL is the bias C + G; CHAIN_GRAVITY alone is G.
void chain_inverse_dynamics(const chain* c, chain_ws* w, const double* qdd, int terms, double* tau);

/// qdd = M^-1 (tau - C - G) (tau NULL: zero): CRBA, RNEA and a Cholesky
/// factorisation, kept in the workspace for chain_solve. Returns 0, or -1
/// if M is not positive definite (qdd is then left NaN).
int chain_forward_dynamics(const chain* c, chain_ws* w, const double* tau, double* qdd);

/// x = M^-1 b with the factor of the last chain_forward_dynamics (b and x may alias).
void chain_solve(const chain* c, const chain_ws* w, const double* b, double* x);

/// Kinetic energy [J] and potential energy -m g . r_com summed over the
/// bodies [J] (zero at the base origin).
double chain_kinetic_energy(const chain* c, const chain_ws* w);
double chain_potential_energy(const chain* c, const chain_ws* w);

/// A cylinder (or any two-point element) between pa fixed in body a and pb
/// fixed in body b [m]: returns the pin length L(q) [m]; optionally its rate
/// Ldot [m/s], the gradient dL/dq [ndof: m/rad or m/m] (the lever arms: a
/// force F along the pins gives tau = F dL/dq) and its time derivative
/// d/dt(dL/dq) = (d2L/dq2) qd, which equals d(Ldot)/dq (what the coupling's
/// Jacobian needs). Any output may be NULL. L must be > 0.
double chain_cylinder(const chain* c, const chain_ws* w, int a, const double pa[3], int b, const double pb[3],
                      double* Ldot, double* dL_dq, double* dLdot_dq);

/// Hessian d2L/dq2 (ndof x ndof, row-major, symmetric) of the same pin length
/// [m/rad^2, 1/rad, 1/m]: the partials of the lever arms dL/dq, for the
/// Jacobian of tau = F dL/dq. H qd equals chain_cylinder's dLdot_dq. Uses
/// the workspace's scratch (not its kinematics), hence not const.
void chain_cylinder_hessian(const chain* c, chain_ws* w, int a, const double pa[3], int b, const double pb[3],
                            double* H);

#ifdef __cplusplus
}
#endif
#endif
