// chain_crane.h: today's two-link crane (crane_model.h) as a chain
// (chain.h): the column, the lifting arm and the end arm, and the two
// cylinders' mount points on them. Kept apart from chain.c so the mechanism
// library itself needs nothing of the world library.
#ifndef CRANESIM_MECHANISM_CHAIN_CRANE_H
#define CRANESIM_MECHANISM_CHAIN_CRANE_H

#include "chain.h"
#include "crane_model.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct chain_crane_opts {
    int slew_free;        ///< 1: the slew is DOF 0 (then q = {slew, q1, q2}); 0: clamped at `slew` (q = {q1, q2})
    double slew;          ///< slew angle of the clamped column [rad]
    double column_radius; ///< the column as a solid cylinder of this radius, for its inertia [m]
} chain_crane_opts;

/// A cylinder between two bodies: barrel pin pa on body a, rod pin pb on body
/// b (body frames) [m]; stroke = L - closed_length.
typedef struct chain_crane_cyl {
    int body_a;
    double pa[3];
    int body_b;
    double pb[3];
    double closed_length; ///< [m]
} chain_crane_cyl;

typedef struct chain_crane {
    chain_body_def body[3]; ///< column, lifting arm, end arm (the tip mass merged into the end arm)
    chain_crane_cyl cyl[2]; ///< m->act[0], m->act[1]
} chain_crane;

/// Fills out from m and a point mass tip_mass [kg] at the end-arm tip. The
/// column's origin is the base origin (the truck bed), joint 1 is at
/// column_height above it; q1 and q2 keep their meaning (angle0 = -pi/2 and
/// 0). The booms' inertia: the link's about the joint axis (y), about x and
/// z the box's (chain_inertia_section, as the ODE world's booms). opt NULL: clamped at
/// slew 0, column radius 0.1 m. Returns 0, or -1 if an actuator's joint is
/// not 0 or 1.
int chain_from_crane_mech(const crane_mech* m, double tip_mass, const chain_crane_opts* opt, chain_crane* out);

#ifdef __cplusplus
}
#endif
#endif
