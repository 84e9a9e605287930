// hyd_shuttle.h: the LS shuttle's record and law (shuttle.c has the
// reasoning), written once for the reference loop (shuttle.c) and the fast
// kernel (circuit_fast.c).
#ifndef HYD_SHUTTLE_H
#define HYD_SHUTTLE_H

#include "hyd_internal.h"

typedef struct hyd_shuttle_c {
    int a, b, out, comp;
    int t;   ///< spool mode: the drain (the valve's T node); -1 in max-select mode
    int su;  ///< spool mode: the valve's spool state; -1 in max-select mode
    double G, w;
    double inv_uw; ///< 1 / spool_width [-]
} hyd_shuttle_c;

/// Spool mode as expressions of + - * only, one text for a double and the
/// two lanes of circuit_fast_ls.c: the share of the tank port left by the
/// work ports' shares wa, wb, and the flow from port k at pk into out at po
/// through share w of G.
#define HYD_SHUTTLE_WT(wa, wb) (1.0 - (wa) - (wb))
#define HYD_SHUTTLE_QK(G, w, pk, po) ((G) * (w) * ((pk) - (po)))

/// C1 max of pa, pb with corner half-width w; *sa = d smax / d pa.
static inline double hyd_shuttle_smax(double pa, double pb, double w, double* sa) {
    const double dd = pa - pb;
    if (dd <= -w) {
        *sa = 0.0;
        return pb;
    }
    if (dd >= w) {
        *sa = 1.0;
        return pa;
    }
    *sa = (dd + w) / (2.0 * w);
    return pb + (dd + w) * (dd + w) / (4.0 * w);
}

/// Signal flow q [m^3/s] into "out" at port pressures [Pa]; it is drawn from
/// a and b in the shares *sig and 1 - *sig. *dsig = d sigma / d pa [1/Pa]
/// (= -d sigma / d pb); *sa = d smax / d pa [-].
static inline double hyd_shuttle_q(const hyd_shuttle_c* c, double pa, double pb, double po, double* sig,
                                   double* dsig, double* sa) {
    double ds;
    const double pm = hyd_shuttle_smax(pa, pb, c->w, sa);
    *sig = hyd_smoothstep((pa - pb + c->w) / (2.0 * c->w), &ds);
    *dsig = ds / (2.0 * c->w);
    return c->G * (pm - po);
}

/// Either mode as flows into the four slots a, b, out, t and their partials
/// (the t slot is 0 in max-select mode, whose flows do not depend on u).
typedef struct hyd_shuttle_flow {
    double f[4];    ///< flow into the node at a, b, out, t [m^3/s]
    double g[4][4]; ///< d f[i] / d p_j, j = a, b, out, t [m^3/(s Pa)]
    double du[4];   ///< d f[i] / d u [m^3/s] (spool mode)
} hyd_shuttle_flow;

/// The spool-mode gallery shares wa, wb, wt of G at spool position u [-]
/// (see hyd_shuttle_law) and, when dw is non-NULL, d w / d u [1/-].
static inline void hyd_shuttle_shares(const hyd_shuttle_c* c, double u, double w[3], double* dw) {
    double dsa, dsb;
    const double wa = hyd_smoothstep(u * c->inv_uw, &dsa);
    const double wb = hyd_smoothstep(-u * c->inv_uw, &dsb);
    w[0] = wa, w[1] = wb, w[2] = HYD_SHUTTLE_WT(wa, wb);
    if (dw) dw[0] = dsa * c->inv_uw, dw[1] = -dsb * c->inv_uw, dw[2] = (dsb - dsa) * c->inv_uw;
}

/// The flows alone (f of hyd_shuttle_law, the same operations in the same
/// order, so bit for bit): the plain evaluation, which needs no partials,
/// skips clearing and filling the 20 partial slots.
static inline void hyd_shuttle_flows(const hyd_shuttle_c* c, double u, double pa, double pb, double po,
                                     double pt, double f[4]) {
    if (c->su < 0) {
        double sa, sig, dsig;
        const double q = hyd_shuttle_q(c, pa, pb, po, &sig, &dsig, &sa);
        f[0] = -sig * q, f[1] = -(1.0 - sig) * q, f[2] = q, f[3] = 0.0;
        return;
    }
    double w[3];
    hyd_shuttle_shares(c, u, w, NULL);
    const double pk[3] = {pa, pb, pt};
    f[0] = f[1] = f[2] = f[3] = 0.0;
    static const int slot[3] = {0, 1, 3};
    for (int k = 0; k < 3; ++k) {
        const double q = HYD_SHUTTLE_QK(c->G, w[k], pk[k], po); // port k -> out
        f[slot[k]] -= q, f[2] += q;
    }
}

/// The law at spool position u [-] (read in spool mode only) and the
/// pressures [Pa] at a, b, out and t (pt unused in max-select mode).
/// Spool mode: the gallery connects out to a, b and t through the shares
///   wa = s(u / uw), wb = s(-u / uw), wt = 1 - wa - wb   (s: smoothstep)
/// of the conductance G: q_k = G w_k (p_k - p_out) from port k into out.
static inline void hyd_shuttle_law(const hyd_shuttle_c* c, double u, double pa, double pb, double po,
                                   double pt, hyd_shuttle_flow* o) {
    memset(o, 0, sizeof *o);
    if (c->su < 0) {
        double sa, sig, dsig;
        const double q = hyd_shuttle_q(c, pa, pb, po, &sig, &dsig, &sa);
        const double qa = c->G * sa, qb = c->G * (1.0 - sa), qo = -c->G; // dq / dp
        o->f[0] = -sig * q, o->f[1] = -(1.0 - sig) * q, o->f[2] = q;
        o->g[0][0] = -(dsig * q + sig * qa);
        o->g[0][1] = -(-dsig * q + sig * qb);
        o->g[0][2] = -sig * qo;
        o->g[1][0] = -(-dsig * q + (1.0 - sig) * qa);
        o->g[1][1] = -(dsig * q + (1.0 - sig) * qb);
        o->g[1][2] = -(1.0 - sig) * qo;
        o->g[2][0] = qa, o->g[2][1] = qb, o->g[2][2] = qo;
        return;
    }
    double w[3], dw[3]; // shares and d w / d u
    hyd_shuttle_shares(c, u, w, dw);
    const double pk[3] = {pa, pb, pt};
    static const int slot[3] = {0, 1, 3};
    for (int k = 0; k < 3; ++k) {
        const double gk = c->G * w[k];
        const double q = HYD_SHUTTLE_QK(c->G, w[k], pk[k], po); // port k -> out (gk (pk - po))
        const double qu = c->G * dw[k] * (pk[k] - po);
        const int s = slot[k];
        o->f[s] -= q, o->f[2] += q;
        o->g[s][s] -= gk, o->g[s][2] += gk;
        o->g[2][s] += gk, o->g[2][2] -= gk;
        o->du[s] -= qu, o->du[2] += qu;
    }
}

#endif
