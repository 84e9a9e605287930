// hyd_hose.h: the hose's laminar law (hose.c), written once for the
// reference loop and the one-pass kernel (circuit_kernel.c).
#ifndef HYD_HOSE_H
#define HYD_HOSE_H

/// Flow [m^3/s] from the hose volume at p [Pa] to its far end at p_to [Pa]
/// through the laminar conductance G [m^3/(s Pa)] (dq/dp = G, dq/dp_to = -G).
/// (+ - * only: one text for a double and the two lanes of circuit_kernel.c.)
#define HYD_HOSE_Q(G, p, p_to) ((G) * ((p) - (p_to)))
static inline double hyd_hose_q(double G, double p, double p_to) { return HYD_HOSE_Q(G, p, p_to); }

#endif
