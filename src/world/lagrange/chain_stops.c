// chain_stops.c: the joint-limit stops of the general analytic mode
// (chain_stops.h has the law and its reasons).
#include "chain_stops.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int chain_stops_init(chain_stops* st, const chain* ch, chain_ws* w, char* err, size_t errsz) {
    memset(st, 0, sizeof *st);
    st->w = CHAIN_STOP_WIDTH;
    const int nd = chain_ndof(ch);
    int n = 0;
    for (int i = 0; i < nd; ++i) {
        const chain_body_def* b = chain_body(ch, chain_dof_body(ch, i));
        n += isfinite(b->q_min) || isfinite(b->q_max);
    }
    if (n == 0) return 0;
    st->dof = calloc((size_t)n, sizeof *st->dof);
    st->lo = calloc(4 * (size_t)n, sizeof *st->lo);
    st->level = calloc(2 * (size_t)n, sizeof *st->level);
    double* q = calloc(3 * (size_t)nd, sizeof *q);
    if (!st->dof || !st->lo || !st->level || !q) {
        free(q);
        chain_stops_free(st);
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    st->hi = st->lo + n;
    st->k = st->hi + n;
    st->c = st->k + n;
    // The reference pose: mid-limits, or 0 clamped into a one-sided range.
    for (int i = 0; i < nd; ++i) {
        const chain_body_def* b = chain_body(ch, chain_dof_body(ch, i));
        if (isfinite(b->q_min) && isfinite(b->q_max)) q[i] = 0.5 * (b->q_min + b->q_max);
        else q[i] = fmin(fmax(0.0, b->q_min), b->q_max);
    }
    chain_update(ch, w, q, NULL);
    double* e = q + nd;
    double* x = e + nd;
    if (chain_forward_dynamics(ch, w, NULL, x)) {
        free(q);
        chain_stops_free(st);
        snprintf(err, errsz, "joint stops: the mass matrix is not positive definite at the mid-limits pose");
        return -1;
    }
    for (int i = 0; i < nd; ++i) {
        const chain_body_def* b = chain_body(ch, chain_dof_body(ch, i));
        if (!(isfinite(b->q_min) || isfinite(b->q_max))) continue;
        // (M^-1)_ii: the joint's acceleration per unit force with the others
        // free; its inverse is the least inertia the stop can meet, so the
        // stop's mode is at most w0 whatever the other joints do (M_ii, the
        // inertia with the others held, is up to 50 times more on a folded
        // chain: a stop built on it rang Krus up at 0.1 ms).
        memset(e, 0, (size_t)nd * sizeof *e);
        e[i] = 1.0;
        chain_solve(ch, w, e, x);
        const double m = 1.0 / x[i];
        const int j = st->n++;
        st->dof[j] = i;
        st->lo[j] = b->q_min;
        st->hi[j] = b->q_max;
        st->k[j] = m * CHAIN_STOP_OMEGA * CHAIN_STOP_OMEGA;
        st->c[j] = 2.0 * CHAIN_STOP_ZETA * m * CHAIN_STOP_OMEGA;
    }
    free(q);
    return 0;
}

void chain_stops_free(chain_stops* st) {
    free(st->dof);
    free(st->lo);
    free(st->level);
    memset(st, 0, sizeof *st);
}

// C1 smoothstep 3t^2 - 2t^3 on [0, 1] and its slope.
static double smoothstep(double t, double* dW) {
    if (t >= 1.0) {
        *dW = 0.0;
        return 1.0;
    }
    *dW = 6.0 * t * (1.0 - t);
    return t * t * (3.0 - 2.0 * t);
}

// The stop's spring S(d) [m or rad] and dS/dd.
static double spring(double w, double d, double* dS) {
    if (d < w) {
        *dS = d / w;
        return 0.5 * d * d / w;
    }
    *dS = 1.0;
    return d - 0.5 * w;
}

// Force magnitude f >= 0 at penetration d > 0 and its rate dd, with
// df/dd (*fd) and df/d(dd) (*fv); 0 with zero partials where the max cuts.
static double stop_force(const chain_stops* st, int j, double d, double dd, double* fd, double* fv) {
    double dS, dW;
    const double S = spring(st->w, d, &dS);
    const double W = smoothstep(d / st->w, &dW);
    const double f = st->k[j] * S + st->c[j] * W * dd;
    if (!(f > 0.0)) {
        *fd = *fv = 0.0;
        return 0.0;
    }
    *fd = st->k[j] * dS + st->c[j] * dW / st->w * dd;
    *fv = st->c[j] * W;
    return f;
}

int chain_stops_add(const chain_stops* st, int nd, const double* q, const double* qd, double* tau, double* dtq,
                    double* dtqd) {
    int on = 0;
    for (int j = 0; j < st->n; ++j) {
        const int i = st->dof[j];
        double fd, fv, f;
        // Below: d = q_min - q, d' = -q', the force pushes +; above: d = q
        // - q_max, d' = q', the force pushes -. Either way d tau/dq = -fd,
        // d tau/dq' = -fv.
        if (q[i] < st->lo[j]) {
            f = stop_force(st, j, st->lo[j] - q[i], -qd[i], &fd, &fv);
        } else if (q[i] > st->hi[j]) {
            f = -stop_force(st, j, q[i] - st->hi[j], qd[i], &fd, &fv);
        } else {
            continue;
        }
        ++on;
        tau[i] += f;
        if (dtq) dtq[(size_t)i * nd + i] -= fd;
        if (dtqd) dtqd[(size_t)i * nd + i] -= fv;
    }
    return on;
}

// The spring's energy k integral_0^d S: d^3 / (6 w) within the width,
// w^2/6 + (d - w/2)^2/2 - w^2/8 beyond (continuous at d = w: w^2/6).
static double spring_energy(double w, double d) {
    if (d <= 0.0) return 0.0;
    if (d < w) return d * d * d / (6.0 * w);
    const double a = d - 0.5 * w;
    return w * w / 6.0 + 0.5 * a * a - 0.125 * w * w;
}

double chain_stops_energy(const chain_stops* st, const double* q) {
    double E = 0.0;
    for (int j = 0; j < st->n; ++j) {
        const int i = st->dof[j];
        E += st->k[j] * (spring_energy(st->w, st->lo[j] - q[i]) + spring_energy(st->w, q[i] - st->hi[j]));
    }
    return E;
}

double chain_stops_dissipation(const chain_stops* st, const double* q, const double* qd) {
    double P = 0.0;
    for (int j = 0; j < st->n; ++j) {
        const int i = st->dof[j];
        double d, dd;
        if (q[i] < st->lo[j]) d = st->lo[j] - q[i], dd = -qd[i];
        else if (q[i] > st->hi[j]) d = q[i] - st->hi[j], dd = qd[i];
        else continue;
        double fd, fv, dS;
        const double f = stop_force(st, j, d, dd, &fd, &fv);
        P += (f - st->k[j] * spring(st->w, d, &dS)) * dd;
    }
    return P;
}

unsigned long chain_stops_events(chain_stops* st, const double* q) {
    unsigned long ev = 0;
    for (int j = 0; j < st->n; ++j) {
        const int i = st->dof[j];
        const double d[2] = {st->lo[j] - q[i], q[i] - st->hi[j]};
        for (int e = 0; e < 2; ++e) {
            const unsigned char lv = d[e] <= 0.0 ? 0 : d[e] < st->w ? 1 : 2;
            if (st->primed && lv > st->level[2 * j + e]) ++ev;
            st->level[2 * j + e] = lv;
        }
    }
    st->primed = 1;
    return ev;
}
