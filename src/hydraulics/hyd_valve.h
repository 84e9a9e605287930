// hyd_valve.h: the 4/3 valve's laws (valve.c has the reasoning), written
// once for the reference loop (valve.c) and the one-pass kernel
// (circuit_kernel.c).
#ifndef HYD_VALVE_H
#define HYD_VALVE_H

#include "hyd_orifice.h"

/// The spool lag on the clamped command c [-] (+ - * only: one text for a
/// double and the two lanes of circuit_kernel.c).
#define HYD_SPOOL_RATE(c, u, inv_tau) (((c) - (u)) * (inv_tau))
/// A valve edge's opening area [m^2] at |u| of full opening Amax.
#define HYD_VALVE_AREA(Amax, abs_u) ((Amax) * (abs_u))

/// Spool rate u' [1/s] = (clamp(cmd, -1, 1) - u) / tau; a NaN command stays NaN.
static inline double hyd_spool_rate(double cmd, double u, double inv_tau) {
    const double c = cmd > 1.0 ? 1.0 : (cmd < -1.0 ? -1.0 : cmd);
    return HYD_SPOOL_RATE(c, u, inv_tau);
}

/// The two open metering edges of a valve at spool position u [-].
typedef struct hyd_valve_flow {
    int pos;        ///< u >= 0: edge 1 is P -> A and edge 2 B -> T; else P -> B and A -> T
    double q1, q2;  ///< edge flows [m^3/s]: q1 from P into the feed port, q2 from the drain port to T
    double g1, g2;  ///< dq/d(dp) of each edge [m^3/(s Pa)]
    double g1A, g2A; ///< dq/dA of each edge [m/s]
} hyd_valve_flow;

/// Edge flows with orifice constants ok and full opening Amax [m^2], at port
/// pressures pP, pT, pA, pB [Pa abs]. Each edge opens |u| Amax; only the two
/// open edges are evaluated.
static inline void hyd_valve_edges(const hyd_orif_k* ok, double Amax, double u, double pP,
                                   double pT, double pA, double pB, hyd_valve_flow* o) {
    const int pos = u >= 0.0;
    const double A = HYD_VALVE_AREA(Amax, fabs(u));
    o->pos = pos;
    o->q1 = hyd_orifice_q(ok, A, pP - (pos ? pA : pB), &o->g1, &o->g1A);
    o->q2 = hyd_orifice_q(ok, A, (pos ? pB : pA) - pT, &o->g2, &o->g2A);
}

#endif
