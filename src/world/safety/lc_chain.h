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
#include "loadchart.h"
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
/// The chain's outreach over every pose of the search (lc_chain_compute's
/// grid) [m]; NaN both when lc_chain_init refuses the chain.
void lc_chain_reach(const model* m, double* rmin, double* rmax);
/// loadchart_compute for a crane chain (docs/safety.md "On a crane chain").
int lc_chain_compute(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz);

// loadchart.c's parts the chain's chart shares:
/// Sizes c for o's points and sectors (t's truck), the sectors' bounds and
/// the rating; 0, or -1 with err (c freed).
int lc_chart_alloc(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz);
/// The printed chart from hyd, stab and rating: env, cap, chart, gov, imin.
void lc_chart_print(loadchart* c);
/// Mass moment [kg m] about support edge `edge` (0 front, 1 rear, 2 left,
/// 3 right) of a mass at horizontal distance rho [m] from the slew axis
/// along slew angle s [rad]: mass times its distance inside the polygon.
double lc_edge_moment(const lc_truck* t, int edge, double rho, double s, double mass);

#ifdef __cplusplus
}
#endif
#endif
