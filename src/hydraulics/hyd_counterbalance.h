// hyd_counterbalance.h: the counterbalance valve's record and law
// (counterbalance.c has the reasoning), written once for the reference loop
// (counterbalance.c) and the fast kernel (circuit_fast.c).
#ifndef HYD_COUNTERBALANCE_H
#define HYD_COUNTERBALANCE_H

#include "hyd_orifice.h"
#include "hyd_ramp.h"

typedef struct hyd_cb_c {
    int v, l, p, adr, comp;
    double pset, R, inv_band, A, inv_tau, ccr, inv_cw, cq;
    double pvent; ///< vented spring chamber: its pressure [Pa abs]; < 0: referenced to the valve port
    hyd_orif_k ok;
} hyd_cb_c;

/// The opening signal z [Pa] = (p_l - p_r) + R (p_p - p_r) - p_setting and
/// the net flow valve -> load (check path qc less relief path qr), + - *
/// only: one text for a double and the two lanes of circuit_fast_ls.c (the
/// spool lag is hyd_compensator.h's HYD_LAG_RATE, the paths hyd_ramp.h's and
/// hyd_orifice.h's laws).
#define HYD_CB_Z(pl, pr, R, pp, pset) (((pl) - (pr)) + (R) * ((pp) - (pr)) - (pset))
#define HYD_CB_Q(qc, qr) ((qc) - (qr))
#ifndef HYD_LAG_RATE
#define HYD_LAG_RATE(xt, x, inv_tau) (((xt) - (x)) * (inv_tau))
#endif

/// The valve at spool x [-] and valve, load, pilot pressures [Pa].
typedef struct hyd_cb_flow {
    double q;        ///< net flow valve -> load [m^3/s]
    double xdot;     ///< spool rate [1/s]
    double dqv;      ///< dq / dp_v [m^3/(s Pa)] (dq / dp_l = -dqv)
    double dqx;      ///< dq / dx [m^3/s]
    double k;        ///< d x' / d z [1/(s Pa)], z = (p_l - p_r) + R (p_p - p_r) - p_setting
    double kv;       ///< d x' / d p_v [1/(s Pa)]: -(1 + R) k with the chamber at the valve port, 0 vented
    int open;        ///< either path passes flow
} hyd_cb_flow;

static inline void hyd_cb_law(const hyd_cb_c* c, double x, double pv, double pl, double pp, hyd_cb_flow* o) {
    double ds;
    // The spring chamber's pressure p_r: the valve port, or the drain it is vented to.
    const double pr = c->pvent < 0.0 ? pv : c->pvent;
    const double z = HYD_CB_Z(pl, pr, c->R, pp, c->pset);
    const double xt = hyd_smoothstep(z * c->inv_band, &ds);
    o->xdot = HYD_LAG_RATE(xt, x, c->inv_tau);
    double gc, tc;
    const double qc = hyd_ramp_q(c->ccr, c->inv_cw, c->cq, pv - pl, &gc, &tc);
    // A spool a rounding error below 0 is closed (the lag cannot leave [0, 1]).
    const double xo = x > 0.0 ? x : 0.0;
    double gr, gA;
    const double qr = hyd_orifice_q(&c->ok, c->A * xo, pl - pv, &gr, &gA);
    o->q = HYD_CB_Q(qc, qr);
    o->open = qr != 0.0 || tc > 0.0;
    o->dqv = gc + gr;
    o->dqx = x > 0.0 ? -gA * c->A : 0.0;
    o->k = ds * c->inv_band * c->inv_tau;
    o->kv = c->pvent < 0.0 ? -(1.0 + c->R) * o->k : 0.0;
}

#endif
