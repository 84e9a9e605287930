// events.c: the event counter of hyd_events.h for any compiled circuit. The
// levels and their rules are those of the fused kernel's counter
// (circuit_kernel.c, hyd_fused_events_update), read from the model's
// component records instead of a packed circuit, plus the seal friction.
#include "hyd_events.h"
#include "hyd_internal.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct hyd_events {
    unsigned long count;
    int have;                // the levels below are set
    int ncyl, nramp, npump, nnode, nvalve;
    int* seal;               // [ncyl] octave of the seal's slope (seal_level)
    signed char* vsign;      // [ncyl] sign of the rate: -1, 0, 1
    unsigned char* stop;     // [2 ncyl] end stops low, high: 0 free, 1 in the width, 2 engaged
    unsigned char* ramp;     // [nramp] reliefs then checks: corner levels
    unsigned char* pump;     // [npump] cut-off: 0 below its band, 1 in it, 2 above
    int* oct;                // [nnode] pressure octave below the knee (node_octave)
    double* knee;            // [nnode] Be(p) < 0.9 Be_l below it [Pa abs]; 0: no knee (no air, a tank)
    double* cmd;             // [nvalve] commands at the previous call
};

// Where a piecewise law stands: 0 before its corner, 1 on it (0 < t < 1),
// 2 beyond it (t >= 1; also NaN), as circuit_kernel.c's corner_level.
static unsigned char corner_level(double t) { return t <= 0.0 ? 0 : (t < 1.0 ? 1 : 2); }

// The octave of the seal friction's slope relative to its slope at rest,
// floor(-log2(sech^2(u))) = floor(2 log2 cosh u) with u = |v| / v_sm: 0 up
// to u = 0.83, then one per halving of the slope (about 0.35 v_sm each). For
// u >= 20, log2 cosh u = u / ln 2 - 1 to 1e-17. NaN: -1 (below every level,
// so it counts).
static int seal_level(double u) {
    if (!(u >= 0.0)) return -1;
    if (u < 20.0) return (int)floor(2.0 * log2(cosh(u)));
    if (u > 1e8) return INT_MAX;
    return (int)floor(2.0 * (u / 0.69314718055994530942 - 1.0)); // ln 2
}

// The octave of a pressure below its node's knee (the binary exponent), or
// INT_MAX above it (and for NaN); at or below 0: INT_MIN (the lowest), as
// circuit_kernel.c's low_octave.
static int node_octave(double knee, double p) {
    if (!(p < knee)) return INT_MAX;
    if (!(p > 0.0)) return INT_MIN;
    int e;
    frexp(p, &e);
    return e;
}

hyd_events* hyd_events_create(const hyd_model* m) {
    hyd_events* e = calloc(1, sizeof *e);
    if (!e) return NULL;
    e->ncyl = m->ncyl;
    e->nramp = m->nrelief + m->ncheck;
    e->npump = m->npump;
    e->nnode = m->nnode;
    e->nvalve = m->nvalve;
    if (!HYD_ALLOC(e->seal, e->ncyl) || !HYD_ALLOC(e->vsign, e->ncyl) || !HYD_ALLOC(e->stop, 2 * e->ncyl) ||
        !HYD_ALLOC(e->ramp, e->nramp) || !HYD_ALLOC(e->pump, e->npump) || !HYD_ALLOC(e->oct, e->nnode) ||
        !HYD_ALLOC(e->knee, e->nnode) || !HYD_ALLOC(e->cmd, e->nvalve)) {
        hyd_events_free(e);
        return NULL;
    }
    // The knee of the entrained-air law per node with a pressure state:
    // where Be(p) reaches 90 % of the liquid modulus, by bisection on log p
    // over [100 Pa, 1 GPa] (as the fused kernel's pack_node).
    for (int k = 0; k < m->nnode; ++k) {
        const double bel = m->node_bel[k];
        e->knee[k] = 0.0;
        if (m->node_state[k] < 0 || !(m->be_alpha > 0.0) || !(bel > 0.0)) continue;
        double lo = log(1e2), hi = log(1e9);
        if (hyd_be_slow(m, bel, exp(lo), NULL) >= 0.9 * bel) continue;
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (lo + hi);
            if (hyd_be_slow(m, bel, exp(mid), NULL) < 0.9 * bel) lo = mid;
            else hi = mid;
        }
        e->knee[k] = exp(hi);
    }
    return e;
}

void hyd_events_free(hyd_events* e) {
    if (!e) return;
    free(e->seal);
    free(e->vsign);
    free(e->stop);
    free(e->ramp);
    free(e->pump);
    free(e->oct);
    free(e->knee);
    free(e->cmd);
    free(e);
}

// The pressure of node k [Pa abs]: its state, or the tank's fixed pressure.
static double node_p(const hyd_model* m, const double* y, const int* map, int k) {
    const int s = m->node_state[k];
    return s < 0 ? m->node_pfix[k] : y[map ? map[s] : s];
}

unsigned long hyd_events_update(hyd_events* e, const hyd_model* m, const double* y, const int* map,
                                const double* x, const double* v, const double* cmd) {
    int sw = 0;
    if (cmd)
        for (int k = 0; k < e->nvalve; ++k) {
            if (!(fabs(cmd[k] - e->cmd[k]) <= HYD_EVENTS_CMD_STEP)) sw = 1;
            e->cmd[k] = cmd[k];
        }
    for (int i = 0; i < e->ncyl; ++i) {
        const hyd_cyl_c* c = &m->cyl[i];
        const int k = m->comp_sub[c->comp];
        // Seal friction: steeper by an octave, or through zero velocity
        // between two points off its steep part.
        if (c->Fc + c->Fs > 0.0) {
            const int lv = seal_level(fabs(v[k]) / c->vsm);
            const signed char sg = (signed char)((v[k] > 0.0) - (v[k] < 0.0));
            if (lv < e->seal[k] || (sg * e->vsign[k] < 0 && lv > 0 && e->seal[k] > 0)) sw = 1;
            e->seal[k] = lv, e->vsign[k] = sg;
        }
        // End stops: penetration over the smoothing width (cylinder.c).
        const double iw = c->ws > 0.0 ? 1.0 / c->ws : HUGE_VAL;
        const unsigned char lo = corner_level(-x[k] * iw), hi = corner_level((x[k] - c->s) * iw);
        if (lo > e->stop[2 * k] || hi > e->stop[2 * k + 1]) sw = 1;
        e->stop[2 * k] = lo, e->stop[2 * k + 1] = hi;
    }
    for (int i = 0; i < e->nramp; ++i) {
        const hyd_ramp_c* r = i < m->nrelief ? &m->relief[i] : &m->check[i - m->nrelief];
        const double d = node_p(m, y, map, r->in) - node_p(m, y, map, r->out);
        const unsigned char lv = corner_level((d - r->pcr) * r->inv_w);
        if (lv > e->ramp[i]) sw = 1;
        e->ramp[i] = lv;
    }
    for (int i = 0; i < e->npump; ++i) {
        const hyd_pump_c* p = &m->pump[i];
        const double dp = node_p(m, y, map, p->out) - node_p(m, y, map, p->in);
        const unsigned char lv = corner_level((dp - p->pset) * p->inv_band);
        if (lv == 1 && e->pump[i] != 1) sw = 1;
        e->pump[i] = lv;
    }
    for (int k = 0; k < e->nnode; ++k) {
        if (!(e->knee[k] > 0.0)) continue;
        const int o = node_octave(e->knee[k], node_p(m, y, map, k));
        if (o > e->oct[k] && o != INT_MAX) sw = 1;
        e->oct[k] = o;
    }
    if (e->have && sw) ++e->count;
    e->have = 1;
    return e->count;
}
