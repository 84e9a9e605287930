// lsim_kin.h: cylinder kinematics of the 2-DOF crane and the mechanics rows
// of f, shared by the right-hand sides (lagrange_sim.c) and the split step
// kernel (lagrange_split_step.c). Internal to src/world.
#ifndef LSIM_KIN_H
#define LSIM_KIN_H

#include <math.h>

#include "crane_model.h"
#include "lagrange_sim.h"

// Kinematics of both cylinders: stroke, rate, lever r = dx/dq and dr/dq.
typedef struct kin {
    double x[2], v[2], r[2], dr[2];
} kin;

// trig = {sin q1, cos q1, sin q2, cos q2}; phi = q + phi_offset by the
// addition identities, so the whole rhs needs only the two sincos of q.
static inline void cylinder_kinematics(const crane_mech* me, const double* trig, const double* qd, kin* k) {
    for (int i = 0; i < 2; ++i) {
        const crane_actuator* a = &me->act[i];
        const double so = a->sin_offset, co = a->cos_offset;
        const double sq = trig[2 * i], cq = trig[2 * i + 1];
        const double sp = sq * co + cq * so, cp = cq * co - sq * so;
        const double ab = a->a * a->b;
        const double xp = sqrt(a->a * a->a + a->b * a->b - 2.0 * ab * cp); // paper Eq. 5
        const double r = ab * sp / xp;                                      // dx/dphi
        k->x[i] = xp - a->closed_length;
        k->r[i] = r;
        k->v[i] = r * qd[i];
        k->dr[i] = (ab * cp - r * r) / xp; // d^2 x / dphi^2
    }
}

// q' and q'' into the last four slots (d = dydt + iq), honouring frozen
// joints; counts one right-hand side.
static inline void lsim_mech_out(lsim* s, const double* qd, double qdd[2], double* d) {
    for (int j = 0; j < 2; ++j) {
        if (s->frozen_q[j]) qdd[j] = 0.0;
        d[j] = s->frozen_q[j] ? 0.0 : qd[j];
        d[2 + j] = qdd[j];
    }
    ++s->nrhs;
}

#endif
