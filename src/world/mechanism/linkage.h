// linkage.h: a cylinder acting on a revolute joint (the knuckle) through a
// planar four-bar linkage (docs/mechanism.md, "A cylinder through a
// linkage"). libm only; no allocation.
//
// The loop, in the boom plane of the joint's PARENT body, coordinates (x, z)
// of the parent frame [m] (x along the parent boom, z its normal in the
// plane; the chain's frames, chain.h):
//
//   J  the knuckle joint (the child's frame origin),
//   A  the link's pin on the parent (fixed in the parent),
//   C  the rocker's pin on the child (fixed in the child, so it turns with q
//      about J),
//   P  the common pin of the link (A-P, length l1) and the rocker (C-P,
//      length l2), where the cylinder's rod pushes,
//   B  the cylinder's base pin on the parent.
//
// The child's angle is angle0 + q, positive q turning x towards z (chain.h's
// revolute), so C = J + R(angle0 + q) c with c the pin in the child frame.
// The loop J-A-P-C is the four-bar (the parent is its ground link); the
// cylinder length is L(q) = |P(q) - B|. Of the two ways the loop assembles
// (P on either side of the line A-C) the `branch` fixed here picks one, and
// P never leaves it: the range is refused if the loop would pass through a
// toggle (A, C, P collinear) where the branches meet.
//
// The links' masses are not part of the transmission: linkage_lump merges
// them into the two booms at their pins (docs/mechanism.md says the error).
#ifndef CRANESIM_MECHANISM_LINKAGE_H
#define CRANESIM_MECHANISM_LINKAGE_H

#include <stddef.h>

#include "chain.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The linkage's description (all points in the boom plane, (x, z)).
typedef struct linkage_def {
    double joint[2];      ///< J: the knuckle joint in the parent frame [m]
    double angle0;        ///< the child's angle at q = 0 in the parent frame [rad] (the chain body's angle0)
    double base[2];       ///< B: the cylinder's base pin on the parent, parent frame [m]
    double link_pin[2];   ///< A: the link's pin on the parent, parent frame [m]
    double rocker_pin[2]; ///< c: the rocker's pin on the child, CHILD frame [m]
    double link_len;      ///< l1 = |P - A| [m], > 0
    double rocker_len;    ///< l2 = |P - C| [m], > 0
    int branch;           ///< +1: P on the counter-clockwise side of A->C (x right, z up); -1: the other
    double q_min, q_max;  ///< the joint's range [rad], q_min < q_max
    double link_mass;     ///< [kg] >= 0 (for linkage_lump only)
    double rocker_mass;   ///< [kg] >= 0 (for linkage_lump only)
} linkage_def;

/// A checked linkage (linkage_init): the description and its stroke.
typedef struct linkage {
    linkage_def d;
    double L_qmin, L_qmax; ///< cylinder length at q_min and q_max [m]
    int sign;              ///< +1: L grows with q over the range; -1: it shrinks
    double min_lever;      ///< min |dL/dq| over the range's samples [m/rad] (> 0: no dead centre)
    double min_sin_mu;     ///< min sin of the transmission angle (link to rocker at P) over the range, in (0, 1]
} linkage;

/// The loop at one angle: positions in the parent frame (x, z) [m].
typedef struct linkage_state {
    double C[2];        ///< the rocker's pin on the child [m]
    double P[2];        ///< the common pin (the cylinder's rod pin) [m]
    double L;           ///< cylinder length |P - B| [m]
    double dL;          ///< dL/dq [m/rad]: the lever arm (torque = force * dL/dq)
    double d2L;         ///< d2L/dq2 [m/rad^2]
    double dP[2];       ///< dP/dq [m/rad]
    double d2P[2];      ///< d2P/dq2 [m/rad^2]
    double link_angle;  ///< angle of A->P from the parent's x [rad]
    double rocker_angle;///< angle of C->P from the parent's x [rad]
    double sin_mu;      ///< sin of the angle between the link and the rocker at P (0: toggle)
} linkage_state;

/// Checks d and fills lk: finite numbers, lengths > 0, branch +-1, q_min <
/// q_max, masses >= 0; the loop closes at every q in [q_min, q_max] (exact:
/// the distance A-C over the range against |l1 - l2| .. l1 + l2); the
/// cylinder length stays > 0; no dead centre (dL/dq = 0) inside the range.
/// Returns 0, or -1 with one line "linkage.field: problem" in err.
int linkage_init(linkage* lk, const linkage_def* d, char* err, size_t errsz);

/// The lengths and the branch from the common pin's position P_ref (parent
/// frame, (x, z)) [m] at the angle q_ref [rad], as a drawing gives them:
/// link_len = |P_ref - A|, rocker_len = |P_ref - C(q_ref)|, branch the side
/// of A->C(q_ref) P_ref is on. Reads joint, angle0, link_pin and
/// rocker_pin from d and writes the three fields. Returns 0, or -1 with
/// "linkage.common_pin: ..." when P_ref is on the line A-C (no branch: a
/// toggle) or on A or C.
int linkage_def_from_pose(linkage_def* d, const double P_ref[2], double q_ref, char* err, size_t errsz);

/// The loop at q [rad] (any q, not only the range): returns 0, or -1 when
/// the loop cannot close there or is at a toggle (s is then NaN).
int linkage_eval(const linkage* lk, double q, linkage_state* s);

/// Cylinder length L(q) [m] (NaN where the loop cannot close).
double linkage_length(const linkage* lk, double q);

/// The inverse: the q in [q_min, q_max] with L(q) = L (safeguarded Newton on
/// the exact L(q), to rounding). Returns 0, or -1 when L is outside the
/// stroke [min(L_qmin, L_qmax), max(...)] (q is then left unchanged).
int linkage_angle(const linkage* lk, double L, double* q);

/// The links' masses lumped into the booms: the link's at its pin A on the
/// parent, the rocker's at its pin c on the child (chain_body_add_point_mass,
/// y = 0). The links' own inertia and the shift of their centres of mass
/// with q are left out (docs/mechanism.md bounds the error).
void linkage_lump(const linkage* lk, chain_body_def* parent, chain_body_def* child);

/// The links' own share of the knuckle's equation with the parent boom held
/// still, exactly (uniform links: the centre of mass at mid-length, m l^2 / 12
/// about it) and as lumped by linkage_lump, so a caller can see what the
/// lumping leaves out.
typedef struct linkage_links_terms {
    double I;         ///< effective inertia about the knuckle (kinetic energy 1/2 I qd^2) [kg m^2]
    double G;         ///< gravity's generalized force dV/dq [N m]
    double I_lumped;  ///< the same with the masses lumped at A and C [kg m^2]
    double G_lumped;  ///< [N m]
} linkage_links_terms;

/// The terms at q for gravity g (x, z) in the parent frame [m/s^2]. Returns
/// 0, or -1 where the loop cannot close (t is then NaN).
int linkage_links(const linkage* lk, double q, const double g[2], linkage_links_terms* t);

/// The linkage as a cylinder of chain c (chain.h), the chain_cylinder of a
/// cylinder through the loop: the knuckle is body `child` of c (a revolute
/// joint; the linkage is described in its parent's frame, its joint and
/// angle0 the child's), L depends on that joint alone. From the workspace's
/// last chain_update: returns L [m]; Ldot = L' qd [m/s], dL_dq [ndof]
/// (L' in the knuckle's DOF, 0 elsewhere), dLdot_dq [ndof] (L'' qd there).
/// Any output may be NULL. NaN where the loop cannot close.
double linkage_cylinder(const linkage* lk, const chain* c, const chain_ws* w, int child, double* Ldot,
                        double* dL_dq, double* dLdot_dq);

/// Its Hessian d2L/dq2 (ndof x ndof, row-major): L'' on the knuckle's
/// diagonal entry, 0 elsewhere.
void linkage_cylinder_hessian(const linkage* lk, const chain* c, const chain_ws* w, int child, double* H);

#ifdef __cplusplus
}
#endif
#endif
