// hyd_compensator.h: the section compensator's record and law
// (compensator.c has the reasoning), written once for the reference loop
// (compensator.c) and the fast kernel (circuit_fast.c).
#ifndef HYD_COMPENSATOR_H
#define HYD_COMPENSATOR_H

#include "hyd_orifice.h"

typedef struct hyd_comp_c {
    int in, out, load, ref, comp, post, adr;
    double A, set, inv_band, inv_tau;
    hyd_orif_k ok;
} hyd_comp_c;

/// The law as expressions of + - * only, one text for a double and the two
/// lanes of circuit_fast_ls.c: the post-compensated (flow-sharing) target
/// dp_t = p_in - p_ref - setting [Pa] (pre-compensated: the setting), the
/// smoothstep argument of the closing force balance on dp_m = p_out - p_load,
/// the opening it asks 1 - s(arg), and the spool lag.
#define HYD_COMP_TARGET_POST(pin, pr, set) ((pin) - (pr) - (set))
#define HYD_COMP_ARG(pout, pl, target, inv_band) (((pout) - (pl) - (target)) * (inv_band) + 0.5)
#define HYD_COMP_OPEN(s) (1.0 - (s))
#define HYD_LAG_RATE(xt, x, inv_tau) (((xt) - (x)) * (inv_tau))

/// The compensator at spool opening x [-] and inlet, outlet, load and ref
/// pressures [Pa].
typedef struct hyd_comp_flow {
    double q;       ///< flow inlet -> outlet [m^3/s]
    double dq[2];   ///< dq / dp of inlet, outlet [m^3/(s Pa)] (the sensed ports only steer x)
    double dqx;     ///< dq / dx [m^3/s]
    double xt;      ///< the opening the spool's force balance asks [-]
    double xdot;    ///< spool rate [1/s]
    double dxd[4];  ///< d x' / d p of inlet, outlet, load, ref [1/(s Pa)]
} hyd_comp_flow;

static inline void hyd_compensator_law(const hyd_comp_c* c, double x, double pin, double pout, double pl,
                                       double pr, hyd_comp_flow* o) {
    const double target = c->post ? HYD_COMP_TARGET_POST(pin, pr, c->set) : c->set;
    double ds;
    o->xt = HYD_COMP_OPEN(hyd_smoothstep(HYD_COMP_ARG(pout, pl, target, c->inv_band), &ds));
    o->xdot = HYD_LAG_RATE(o->xt, x, c->inv_tau);
    const double k = -ds * c->inv_band * c->inv_tau; // d x' / d(dp_m - dp_t)
    o->dxd[0] = c->post ? -k : 0.0, o->dxd[1] = k, o->dxd[2] = -k, o->dxd[3] = c->post ? k : 0.0;
    // A spool a rounding error below 0 is closed (the lag cannot leave [0, 1]).
    const double xo = x > 0.0 ? x : 0.0;
    double g, gA;
    o->q = hyd_orifice_q(&c->ok, c->A * xo, pin - pout, &g, &gA);
    o->dq[0] = g, o->dq[1] = -g;
    o->dqx = x > 0.0 ? gA * c->A : 0.0;
}

#endif
