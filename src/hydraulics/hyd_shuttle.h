// hyd_shuttle.h: the LS shuttle's record and law (shuttle.c has the
// reasoning), written once for the reference loop (shuttle.c) and the fast
// kernel (circuit_fast.c).
#ifndef HYD_SHUTTLE_H
#define HYD_SHUTTLE_H

#include "hyd_internal.h"

typedef struct hyd_shuttle_c {
    int a, b, out, comp;
    double G, w;
} hyd_shuttle_c;

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

#endif
