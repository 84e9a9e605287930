// chain_stops.h: the joint-limit stops of the general analytic mode
// (chain_sim.h; docs/lagrange.md, "Joint-limit stops").
//
// The ODE chain world stops each joint at its limits with ODE's hard,
// inelastic joint stop (dParamLoStop/HiStop, bounce 0, ERP 0.2 and CFM
// 1e-10: a spring of 2e12 N/m behind a Baumgarte correction, rigid for a
// crane). The analytic mode integrates one smooth ODE system with
// W-methods, so the stop is a unilateral spring-damper that acts only
// beyond the limit, stiff and critically damped, so that it stops the
// joint within a fraction of a millimetre and hardly bounces (a free
// contact leaves at e^-2 = 0.135 of its approach speed, where the damper
// would start to pull, which the max forbids; ODE's leaves at 0): with
// penetration d (q_min - q below, q - q_max above) and its rate d',
//
//   f = max(0, k S(d) + c W(d) d')      (the generalised force [N m or N],
//                                        pushing the joint back inside)
//   S = d^2 / (2 w) for d < w, d - w/2 beyond (spring with a C1 onset)
//   W = smoothstep(d / w)                (damper fades in, C1)
//   k = m w0^2, c = 2 m w0               (zeta = 1)
//
// m is the joint's effective inertia with every other joint free, 1 /
// (M^-1)_ii [kg m^2 or kg], at the mechanism's reference pose (every DOF
// with two finite limits at their middle, the others at 0 clamped into
// theirs): the least inertia the stop can meet, so its mode is at most w0
// = 5000 rad/s (800 Hz) on every joint whatever the others do. That is the
// regime of the cylinders' end stops (5e8 N/m on a 20 kg telescopic stage
// of the 8-function model: 5000 rad/s), which Krus at 0.1 ms integrates
// stably once its Jacobian knows the stop (chain_stops_events); jib_ext3 of
// the 8-function model rests 0.13 mm past its limit against its stalled
// cylinder (0.05 mm of it the onset w/2). w = 1e-4 [m or rad]. M_ii (the
// inertia with the others held) in place of 1 / (M^-1)_ii is up to 50
// times stiffer on a folded chain and rang Krus up at 0.1 ms.
// A DOF without a finite limit has no stop (an allow-list: nothing is
// added for it).
#ifndef CHAIN_STOPS_H
#define CHAIN_STOPS_H

#include <stddef.h>

#include "chain.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The stop's undamped angular frequency w0 [rad/s], its smoothing width
/// [m or rad] and its damping ratio [-].
#define CHAIN_STOP_OMEGA 5000.0
#define CHAIN_STOP_WIDTH 1e-4
#define CHAIN_STOP_ZETA 1.0

typedef struct chain_stops {
    int n;               ///< DOFs with a stop (at least one finite limit)
    int* dof;            ///< [n] their DOF index
    double *lo, *hi;     ///< [n] limits [rad or m] (+-INFINITY: none on that side)
    double *k, *c;       ///< [n] stiffness [N m/rad or N/m], damping [N m s/rad or N s/m]
    double w;            ///< smoothing width [rad or m]
    unsigned char* level; ///< [2 n] event levels (low, high): 0 free, 1 in the width, 2 beyond it
    int primed;          ///< the levels hold a state (chain_stops_events)
} chain_stops;

/// The stops of chain ch (w: a workspace of it, left at the reference
/// pose). 0, or -1 with one line in err (out of memory, M not positive
/// definite at the reference pose). A chain without finite limits gets n =
/// 0 and nothing allocated.
int chain_stops_init(chain_stops* st, const chain* ch, chain_ws* w, char* err, size_t errsz);
void chain_stops_free(chain_stops* st);

/// Adds the stops' generalised forces at (q, qd) [ndof each] to tau
/// [ndof], and their partials to dtq = d tau/dq and dtqd = d tau/dq'
/// [nd x nd, row-major] unless NULL. Returns the number of stops engaged.
int chain_stops_add(const chain_stops* st, int nd, const double* q, const double* qd, double* tau, double* dtq,
                    double* dtqd);

/// The springs' stored energy at q [J]: sum k integral S dd.
double chain_stops_energy(const chain_stops* st, const double* q);

/// Power the stops dissipate at (q, qd) [W], >= 0: the power the joints put
/// into the stops, f d', less the springs' energy rate k S d' (the damper's
/// c W d'^2, or when the max cuts f to 0 on the way out, the spring energy
/// that is not given back, -k S d').
double chain_stops_dissipation(const chain_stops* st, const double* q, const double* qd);

/// hyd_problem.events for the stops: counts a stop engaging (from free) or
/// pressing beyond its smoothing width (the spring's full stiffness) since
/// the last call; the first call only records. Switches back are not
/// counted (an older Jacobian then overestimates the stiffness).
unsigned long chain_stops_events(chain_stops* st, const double* q);

#ifdef __cplusplus
}
#endif

#endif
