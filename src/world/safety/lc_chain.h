// lc_chain.h: what the load chart and the rated capacity limiter need of a
// crane chain (model.chain, crane_chain.h), from the mechanism library
// (chain.h): the tip's outreach, the booms' gravity torques, each
// actuator's lever on the one joint it moves, the holding force per kg at
// the tip. The allow-list is lc_chain_init's: a chain it cannot read is
// refused in one line, never guessed at. docs/safety.md, "On a crane chain".
#ifndef LC_CHAIN_H
#define LC_CHAIN_H
#include <stdbool.h>
#include <stddef.h>

#include "chain.h"
#include "model.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lc_chain {
    const crane_chain* cc;
    chain* ch;        ///< the booms with the column fixed at slew 0, no tip mass
    chain_ws* ws;
    int nd;           ///< the boom DOFs (every non-column joint that is not fixed)
    int na;           ///< actuators (pin cylinders), one per boom DOF
    int* act_dof;     ///< [na] the DOF actuator k moves
    int* dof_act;     ///< [nd] the actuator that moves DOF j
    int* dof_body;    ///< [nd] the body of DOF j
    int lift;         ///< the actuator on the first boom joint (the column's child): the one whose
                      ///< pressures measure the load moment
    double* q_lo;     ///< [nd] joint limits [rad or m] (the body's)
    double* q_hi;
    double* AA;       ///< [na] piston area [m^2]
    double* AB;       ///< [na] annulus area [m^2]
    double* stroke;   ///< [na] [m]
    double (*relief)[2]; ///< [na] port relief settings of chambers A, B [Pa]
    double axis_x;    ///< the slew axis's x in the base frame [m] (the column's origin)
    // Per evaluation (lc_chain_eval):
    double* J;        ///< [3 nd] tip Jacobian
    double* G0;       ///< [nd] gravity forces of the booms alone [N m or N]
    double* Gt;       ///< [nd] gravity forces of 1 kg at the tip [N m/kg or N/kg]
    double* dL;       ///< [na nd] the actuators' dL/dq
    double* lever;    ///< [na] dL_k/dq of its own DOF [m/rad or m/m]
    double* x;        ///< [na] strokes [m]
} lc_chain;

/// Reads the chain of model m for `what` ("load chart", "rated capacity
/// limiter"). Refuses (-1, one line "FILE: what: problem" in err): a chain
/// that is the two-link shorthand (the closed form serves it), an actuator
/// that is not a pin cylinder or moves other than exactly one boom joint, a
/// boom joint no actuator (or more than one) moves, a boom joint without
/// finite limits, an actuator chamber without a port relief.
int lc_chain_init(lc_chain* g, const model* m, const char* what, char* err, size_t errsz);
void lc_chain_free(lc_chain* g);

/// Kinematics and statics at boom pose q [nd]: *R the tip's outreach (signed
/// horizontal distance from the slew axis in the boom plane) [m], *z its
/// height [m]; fills J, G0, Gt, dL, lever, x. Returns false when an
/// actuator's stroke at q is outside [0, stroke] (not a pose of the crane).
bool lc_chain_eval(lc_chain* g, const double* q, double* R, double* z);

/// After lc_chain_eval: the largest tip mass [kg] every actuator holds with
/// its load side chamber at (1 - margin) of its port relief (the other at
/// the static start's 0.5 MPa), *gov the governing actuator; -1 when the
/// booms alone overload one.
double lc_chain_hyd(const lc_chain* g, double margin, int* gov);

/// After lc_chain_eval: the first moment of the crane's masses about the
/// slew axis along the boom, sum m_b x_b [kg m], and their sum [kg].
void lc_chain_mass_moment(const lc_chain* g, double* S1, double* M);

/// The poses the chart's grid holds (within limits or not).
long lc_chain_grid_size(const lc_chain* g);
/// Grid points of boom DOF j in the search (its limits in steps of at most
/// 2.5 deg or 0.1 m, both ends included).
int lc_chain_grid_n(const lc_chain* g, int j);
/// The pose at place `at` of the grid (DOF 0 varying fastest) into q [nd].
void lc_chain_grid_pose(const lc_chain* g, long at, double* q);
/// Searches beyond this many grid poses are refused (about 3 us and 48
/// bytes a pose: some 12 s and 190 MB).
#define LC_CHAIN_MAX_POSES 4000000L

/// One pose of the search: its outreach, hydraulic limit and governing
/// actuator, the first moment and sum of the crane's masses.
typedef struct lcc_pose {
    double R;   ///< the tip's outreach [m]
    double hyd; ///< lc_chain_hyd [kg] (-1: the booms alone overload an actuator)
    double S1;  ///< sum m_b x_b about the slew axis [kg m] (0 unless asked for)
    double M;   ///< sum m_b [kg] (0 unless asked for)
    long at;    ///< its place in the grid (lc_chain_grid_pose)
    int gov;    ///< the actuator that governs hyd
} lcc_pose;
/// Every pose of the grid within the joint limits and the strokes, once, in
/// grid order: *np of them (malloc'd), NULL when out of memory; masses:
/// fill S1 and M (the stability limit needs them).
lcc_pose* lc_chain_search(lc_chain* g, double margin, bool masses, long* np);

#ifdef __cplusplus
}
#endif
#endif
