// circuit_kernel.c: the one-pass circuit kernel, the standard actuator
// circuit in one pass (see circuit_kernel.h).
//
// Every law here is the component's own, from its header: hyd_pump_q
// (hyd_pump.h), hyd_ramp_q (hyd_ramp.h), hyd_valve_edges and hyd_spool_rate
// (hyd_valve.h), hyd_hose_q (hyd_hose.h), hyd_cyl_volumes, hyd_cyl_leak and
// hyd_cyl_force (hyd_cylinder.h), hyd_node_c / hyd_be_slow (fluid.c). The
// reference loops call the same functions. What changes is the bookkeeping: flows stay in registers and each node's net inflow is summed
// where it is known, instead of through per-port slots and a CSR gather.
// Summation order differs from volume.c, so results agree to rounding.
#include "circuit_kernel.h"

#include "hyd_cylinder.h"
#include "hyd_hose.h"
#include "hyd_internal.h"
#include "hyd_pump.h"
#include "hyd_ramp.h"
#include "hyd_valve.h"

#include <limits.h>
#include <string.h>

static void set_why(char* why, size_t n, const char* msg) {
    if (why && n) snprintf(why, n, "%s", msg);
}

// GCC and Clang: inline the actuator kernel into both callers, so the plain
// evaluation sheds every partial (the flag is a compile-time constant there).
#if defined(__GNUC__)
#define FUSED_INLINE static inline __attribute__((always_inline))
#else
#define FUSED_INLINE static inline
#endif

static int node_is_tank(const hyd_model* m, int node) { return m->node_state[node] < 0; }

static void pack_node(const hyd_model* m, int node, hyd_fused_node* n) {
    n->s = m->node_state[node];
    n->V0 = m->node_V0[node];
    n->bel = m->node_bel[node];
    n->bec = m->node_bec[node];
    n->nramp = 0;
    n->p_lo = -HUGE_VAL;
    n->p_hi = HUGE_VAL;
    // The knee of the entrained-air law: the pressure where Be(p) reaches
    // 90 % of the liquid modulus (2.6 MPa for the default hoses, 3.2 MPa
    // for the oil-only nodes; Be is 1 % of it at 0.05 MPa). Bisection on
    // log p over [100 Pa, 1 GPa]; no air: no knee.
    n->p_knee = 0.0;
    if (m->be_alpha > 0.0 && n->bel > 0.0) {
        double lo = log(1e2), hi = log(1e9);
        if (hyd_be_slow(m, n->bel, exp(lo), NULL) >= 0.9 * n->bel) return;
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (lo + hi);
            if (hyd_be_slow(m, n->bel, exp(mid), NULL) < 0.9 * n->bel) lo = mid;
            else hi = mid;
        }
        n->p_knee = exp(hi);
    }
}

// The hose whose own node is `node`, or -1.
static int hose_at(const hyd_model* m, int node) {
    for (int i = 0; i < m->nhose; ++i)
        if (m->hose[i].node == node) return i;
    return -1;
}

// The lane copy of a two-actuator circuit (hyd_fused_lanes) and the node
// list of the events, refreshed whenever the records change (build, map).
static void pack_lanes(hyd_fused* f) {
    // The nodes' state indices in the order of hyd_fused_events' slots.
    f->nev = 0;
    for (int k = 0; k < f->nact; ++k) {
        const hyd_fused_act* a = &f->act[k];
        f->ev_s[f->nev++] = a->hA.s, f->ev_s[f->nev++] = a->hB.s;
        f->ev_s[f->nev++] = a->cA.s, f->ev_s[f->nev++] = a->cB.s;
    }
    f->ev_s[f->nev++] = f->pl.s;
    f->stops_plain = f->nact == 2;
    for (int k = 0; k < f->nact && k < 2; ++k) {
        f->stroke2[k] = f->act[k].s;
        f->stops_plain &= f->act[k].inv_ws > 0.0 && f->act[k].inv_ws < HUGE_VAL;
    }
    f->lanes_ok = f->nact == 2 && f->m->air.use;
    if (!f->lanes_ok) return;
    hyd_fused_lanes* L = &f->ln;
    for (int k = 0; k < 2; ++k) {
        const hyd_fused_act* a = &f->act[k];
        L->Amax[k] = a->Amax, L->inv_tau[k] = a->inv_tau, L->ok[k] = a->ok, L->oinvP0[k] = a->oinvP0;
        L->okl[k] = a->okl, L->pT[k] = a->pT, L->GA[k] = a->GA, L->GB[k] = a->GB;
        L->AA[k] = a->AA, L->AB[k] = a->AB, L->s[k] = a->s, L->VA0[k] = a->VA0, L->VB0[k] = a->VB0;
        L->VAmin[k] = HYD_CYL_VMIN(a->VA0), L->VBmin[k] = HYD_CYL_VMIN(a->VB0);
        L->CL[k] = a->CL, L->bv[k] = a->bv;
        L->hV0[0][k] = a->hA.V0, L->hV0[1][k] = a->hB.V0;
        L->su[k] = a->su;
        const hyd_fused_node* nd[4] = {&a->hA, &a->hB, &a->cA, &a->cB};
        for (int j = 0; j < 4; ++j) {
            L->bel[j][k] = nd[j]->bel, L->bec[j][k] = nd[j]->bec;
            L->p_lo[j][k] = nd[j]->p_lo, L->p_hi[j][k] = nd[j]->p_hi;
            L->s_node[j][k] = nd[j]->s;
        }
    }
}

int hyd_fused_build(const hyd_model* m, const int* valve, const int* cyl, int nact, hyd_fused* f,
                    char* why, size_t whysz) {
    memset(f, 0, sizeof *f);
    f->m = m;
    f->nact = nact;
    if (nact < 1 || nact > HYD_FUSED_MAXACT) return set_why(why, whysz, "too many actuators"), -1;
    if (m->norifice) return set_why(why, whysz, "the circuit has fixed orifices"), -1;
    // Only the types below are packed: any other component would be left
    // out of the sum and give plausible wrong numbers, so it is refused.
    for (int c = 0; c < m->ncomp; ++c) {
        const hyd_type t = m->comp[c].type;
        if (t != HYD_PUMP && t != HYD_RELIEF && t != HYD_CHECK && t != HYD_HOSE && t != HYD_VALVE &&
            t != HYD_CYLINDER) {
            if (why && whysz)
                snprintf(why, whysz, "component '%s' (%s): the one-pass kernel has no place for this type",
                         m->comp[c].name, hyd_type_name(t));
            return -1;
        }
    }
    if (m->npump != 1) return set_why(why, whysz, "the circuit needs exactly one pump"), -1;
    if (m->nvalve != nact || m->ncyl != nact || m->nhose != 2 * nact)
        return set_why(why, whysz, "not one valve, two hoses and one cylinder per actuator"), -1;
    if (m->nvol != 1 + 4 * nact) return set_why(why, whysz, "volume nodes other than the pump line"), -1;
    const hyd_pump_c* pu = &m->pump[0];
    if (!node_is_tank(m, pu->in) || node_is_tank(m, pu->out))
        return set_why(why, whysz, "the pump does not feed a volume from a tank"), -1;
    const int pl = pu->out;
    pack_node(m, pl, &f->pl);
    f->qmax = pu->qmax;
    f->pset = pu->pset;
    f->inv_band = pu->inv_band;
    f->p_in = m->node_pfix[pu->in];

    // Node -> its packed record, for assigning the ramps below.
    hyd_fused_node* at[256];
    if (m->nnode > 256) return set_why(why, whysz, "too many nodes"), -1;
    for (int i = 0; i < m->nnode; ++i) at[i] = NULL;
    at[pl] = &f->pl;

    for (int k = 0; k < nact; ++k) {
        hyd_fused_act* a = &f->act[k];
        if (valve[k] < 0 || valve[k] >= m->nvalve || cyl[k] < 0 || cyl[k] >= m->ncyl)
            return set_why(why, whysz, "actuator index out of range"), -1;
        const hyd_valve_c* v = &m->valve[valve[k]];
        const hyd_cyl_c* c = &m->cyl[cyl[k]];
        if (v->P != pl || !node_is_tank(m, v->T))
            return set_why(why, whysz, "a valve is not fed from the pump line to a tank"), -1;
        const int ha = hose_at(m, v->A), hb = hose_at(m, v->B);
        if (ha < 0 || hb < 0 || m->hose[ha].to != c->nA || m->hose[hb].to != c->nB)
            return set_why(why, whysz, "a valve port does not reach its cylinder through a hose"), -1;
        a->su = v->adr;
        a->Amax = v->Amax;
        a->inv_tau = v->inv_tau;
        a->ok = v->ok.k;
        a->oinvP0 = v->ok.invP0;
        a->okl = v->ok.kl;
        a->pT = m->node_pfix[v->T];
        a->GA = m->hose[ha].G;
        a->GB = m->hose[hb].G;
        a->AA = c->AA, a->AB = c->AB, a->s = c->s, a->VA0 = c->VA0, a->VB0 = c->VB0;
        a->CL = c->CL, a->bv = c->bv, a->ks = c->ks, a->cs = c->cs, a->ws = c->ws;
        a->Fc = c->Fc, a->Fs = c->Fs, a->vst = c->vst, a->vsm = c->vsm;
        a->inv_ws = 1.0 / c->ws;
        const int nodes[4] = {v->A, v->B, c->nA, c->nB};
        hyd_fused_node* recs[4] = {&a->hA, &a->hB, &a->cA, &a->cB};
        for (int j = 0; j < 4; ++j) {
            if (at[nodes[j]]) return set_why(why, whysz, "two actuators share a node"), -1;
            pack_node(m, nodes[j], recs[j]);
            at[nodes[j]] = recs[j];
        }
    }
    // Without seal friction the two-lane path skips its per-lane loop (it
    // would subtract +0.0; about 20 instructions per evaluation).
    f->seal = 0;
    for (int k = 0; k < f->nact; ++k) f->seal |= f->act[k].Fc != 0.0 || f->act[k].Fs != 0.0;
    // Reliefs and checks: between a tank and one of the packed nodes.
    for (int pass = 0; pass < 2; ++pass) {
        const hyd_ramp_c* r = pass ? m->check : m->relief;
        const int nr = pass ? m->ncheck : m->nrelief;
        for (int i = 0; i < nr; ++i) {
            const int tin = node_is_tank(m, r[i].in), tout = node_is_tank(m, r[i].out);
            if (tin == tout) return set_why(why, whysz, "a relief or check valve is not between a tank and a volume"), -1;
            const int node = tin ? r[i].out : r[i].in;
            hyd_fused_node* n = at[node];
            if (!n || n->nramp == HYD_FUSED_MAXRAMP)
                return set_why(why, whysz, "too many reliefs or checks on one node"), -1;
            hyd_fused_ramp* q = &n->ramp[n->nramp++];
            q->pcr = r[i].pcr;
            q->inv_w = r[i].inv_w;
            q->qr = r[i].qr;
            q->p_tank = m->node_pfix[tin ? r[i].in : r[i].out];
            q->into = tin;
            // Open when t = (d - pcr) / w > 0, d = p_tank - p (check) or p - p_tank.
            if (tin) n->p_lo = fmax(n->p_lo, q->p_tank - q->pcr);
            else n->p_hi = fmin(n->p_hi, q->p_tank + q->pcr);
        }
    }
    pack_lanes(f);
    return 0;
}

void hyd_fused_map(hyd_fused* f, const int* map) {
    f->pl.s = map[f->pl.s];
    for (int k = 0; k < f->nact; ++k) {
        hyd_fused_act* a = &f->act[k];
        a->su = map[a->su];
        a->hA.s = map[a->hA.s];
        a->hB.s = map[a->hB.s];
        a->cA.s = map[a->cA.s];
        a->cB.s = map[a->cB.s];
    }
    pack_lanes(f);
}

// Net inflow through the node's reliefs and checks, and its pressure partial
// (both signs give -qr dr: a relief's outflow and a check's inflow both fall
// as p rises). Closed valves (the usual case) cost one compare; a NaN takes
// the open branch and propagates, as in relief.c.
FUSED_INLINE double ramps_in(const hyd_fused_node* n, double p, double* g) {
    double q = 0.0, gs = 0.0;
    if (n->p_lo < p && p < n->p_hi) { // all closed (false for NaN)
        *g = 0.0;
        return 0.0;
    }
    for (int i = 0; i < n->nramp; ++i) {
        const hyd_fused_ramp* r = &n->ramp[i];
        const double d = r->into ? r->p_tank - p : p - r->p_tank;
        double gr, t;
        const double o = hyd_ramp_q(r->pcr, r->inv_w, r->qr, d, &gr, &t);
        if (t <= 0.0) continue;
        q += r->into ? o : -o;
        gs -= gr;
    }
    *g = gs;
    return q;
}

// Be(p) / V with the model's kernel (volume.c does the same).
FUSED_INLINE double node_c(const hyd_model* m, const hyd_fused_node* n, double p, double V) {
    return hyd_node_c(m, n->bel, n->bec, p, V, NULL, NULL);
}

// Net inflows [m^3/s] of an actuator's nodes (the volume law's sum Q_in -
// dV/dt): a hose from its valve port (in) less what it passes on (qh), a
// chamber from its hose less the leakage A -> B, less dV/dt = A_A x' (A) or
// -A_B x' (B); rq the node's reliefs and checks. One text for actuator() and
// the two lanes.
#define NET_HOSE(in, qh, rq) ((in) - (qh) + (rq))
#define NET_CHAMBER_A(qh, leak, rq, AA, v) ((qh) - (leak) + (rq) - (AA) * (v))
#define NET_CHAMBER_B(qh, leak, rq, AB, v) ((qh) + (leak) + (rq) + (AB) * (v))

// Everything one actuator contributes, with or without partials. The
// partials are "G": d(net inflow)/d(state), before scaling by Be/V.
typedef struct act_out {
    double q_pl;                 ///< flow taken from the pump line [m^3/s]
    double nA, nB, nhA, nhB;     ///< net inflows (incl. -dV/dt) of the chambers and hoses
    double VA, VB;
    double F;
    // Partials (jacobian only).
    double g1, du1, g2, du2;     ///< valve edges: dq/ddp, dq/du
    int pos;
    double gA, gB, ghA, ghB;     ///< ramp partials of chamber A, B, hose A, B
    double dFdx, dFdv;           ///< force partials [N/m], [N s/m]
    double dVA, dVB;             ///< dV/dx of the chambers (0 once the volume floor holds V, cylinder.c)
} act_out;

FUSED_INLINE void actuator(const hyd_fused_act* a, const double* y, double pPL, double x, double v,
                            double cmd, double* ydot_u, act_out* o, int partials) {
    const double u = y[a->su];
    *ydot_u = hyd_spool_rate(cmd, u, a->inv_tau);
    const double phA = y[a->hA.s], phB = y[a->hB.s], pA = y[a->cA.s], pB = y[a->cB.s];

    // Valve: edge 1 feeds a work port from P, edge 2 drains the other to T.
    const hyd_orif_k ok = {a->ok, 0.0, a->oinvP0, a->okl};
    hyd_valve_flow e;
    hyd_valve_edges(&ok, a->Amax, u, pPL, a->pT, phA, phB, &e);
    const int pos = e.pos;
    const double q1 = e.q1, q2 = e.q2;
    o->q_pl = q1;
    const double inA = pos ? q1 : -q2, inB = pos ? -q2 : q1;

    // Hoses, leakage and volumes.
    const double qhA = hyd_hose_q(a->GA, phA, pA), qhB = hyd_hose_q(a->GB, phB, pB);
    const double leak = hyd_cyl_leak(a->CL, pA, pB);
    double dVA, dVB;
    hyd_cyl_volumes(a->VA0, a->VB0, a->AA, a->AB, a->s, x, &o->VA, &o->VB, &dVA, &dVB);

    double gA, gB, ghA, ghB;
    o->nhA = NET_HOSE(inA, qhA, ramps_in(&a->hA, phA, &ghA));
    o->nhB = NET_HOSE(inB, qhB, ramps_in(&a->hB, phB, &ghB));
    o->nA = NET_CHAMBER_A(qhA, leak, ramps_in(&a->cA, pA, &gA), a->AA, v);
    o->nB = NET_CHAMBER_B(qhB, leak, ramps_in(&a->cB, pB, &gB), a->AB, v);

    // Force with the end stops.
    double dFdx, dFdv;
    o->F = hyd_cyl_force(a->AA, a->AB, a->bv, a->ks, a->cs, a->ws, a->s, pA, pB, x, v, &dFdx, &dFdv);
    double dseal;
    o->F -= hyd_cyl_seal(a->Fc, a->Fs, a->vst, a->vsm, v, &dseal);
    dFdv -= dseal;
    if (partials) {
        const double sgn = pos ? 1.0 : -1.0;
        o->g1 = e.g1, o->g2 = e.g2, o->pos = pos;
        o->du1 = e.g1A * a->Amax * sgn;
        o->du2 = e.g2A * a->Amax * sgn;
        o->gA = gA, o->gB = gB, o->ghA = ghA, o->ghB = ghB;
        o->dFdx = dFdx, o->dFdv = dFdv;
        o->dVA = dVA, o->dVB = dVB;
    }
}

static inline double pump_in(const hyd_fused* f, double pPL, double* g) {
    double t;
    return hyd_pump_q(f->qmax, f->pset, f->inv_band, pPL - f->p_in, g, &t);
}

// ---------------------------------------------------------------- events --
//
// hyd_fused_events_update counts the moments at which the circuit gets
// stiffer than a Jacobian taken before them describes. The fixed-step
// W-methods (Krus, ROS2) tolerate a W that overestimates the stiffness of
// a mode (|R| stays below 1) but not one that underestimates it by a few
// times at h |lambda| > 2: there the stage equations amplify the mode. So
// the events are the switches that stiffen: a relief or check valve
// reaching its corner or passing beyond it, an end stop engaging or
// pressing beyond its smoothing width, the pump line entering the band of
// the pump's cut-off, a pressure rising into a higher octave below the knee
// of its bulk-modulus law. Switches the other way are not counted: there the
// older J overestimates. Counting both ways was tried: ROS2 at 1 ms on
// `overload`, which finishes with J by age alone, then blew up at 5.74 s
// (a J taken at the end stop's first touch, kept as it pressed in), and
// Krus at 1 ms on `step` failed at 1.26 s instead of 3.63 s
// (docs/solver_study.md).

// Where a piecewise law stands: 0 before its corner, 1 on it (0 < t < 1),
// 2 beyond it (t >= 1; also NaN).
static inline unsigned char corner_level(double t) { return t <= 0.0 ? 0 : (t < 1.0 ? 1 : 2); }

// The octave of a pressure below the knee of its node's bulk-modulus law
// (the binary exponent: no log), or INT_MAX above it (and for NaN). Be(p)
// grows about 3x per octave there (the default hose: 8.4 MPa at 0.05 MPa,
// 27 at 0.1, 82 at 0.2, 283 at 0.5), and so does the stiffness of the
// node's modes.
static inline int low_octave(const hyd_fused_node* n, double p) {
    if (!(p < n->p_knee)) return INT_MAX;
    uint64_t b;
    memcpy(&b, &p, sizeof b);
    return p > 0.0 ? (int)(b >> 52) : INT_MIN; // at or below 0: lowest
}

// The interval (lo, hi) of pressures in which a node's octave and ramp
// levels stay what node_events just stored, so that a later call with p
// inside it would change nothing and count nothing (hyd_fused_events_update
// then skips the node). Exact, with strict bounds on both sides: an
// inclusive bound L becomes nextafter(L, -inf). Only the all-closed case
// gets an interval (its bounds are pressures the laws compare with); a node
// with an open relief or check gets an empty one (NaN) and is re-evaluated
// at every call, as before.
static void node_hold(const hyd_fused_node* n, double p, int o, double* lo, double* hi) {
    if (!(n->p_lo < p && p < n->p_hi)) {
        *lo = *hi = NAN;
        return;
    }
    double l = n->p_lo, h = n->p_hi;
    if (o == INT_MAX) { // p >= p_knee (or no air)
        const double k = nextafter(n->p_knee, -HUGE_VAL);
        if (k > l) l = k;
    } else {
        if (n->p_knee < h) h = n->p_knee;
        if (o == INT_MIN) { // p <= 0
            const double z = nextafter(0.0, HUGE_VAL);
            if (z < h) h = z;
        } else { // one binade: biased exponent o, [2^(o-1023), 2^(o-1022))
            const uint64_t b0 = (uint64_t)o << 52, b1 = (uint64_t)(o + 1) << 52;
            double L, U;
            if (o == 0) L = 0.0; // subnormals: p > 0
            else {
                const uint64_t bl = b0 - 1; // the largest double below 2^(o-1023)
                memcpy(&L, &bl, sizeof L);
            }
            memcpy(&U, &b1, sizeof U);
            if (L > l) l = L;
            if (U < h) h = U;
        }
    }
    *lo = l, *hi = h;
}

// One node: its octave (slot *io of e->oct) and its ramps' levels (slots
// from *il of e->lv), and the interval in which they hold. Returns 1 when
// either stiffened since the last call.
static int node_events(hyd_fused_events* e, const hyd_fused_node* n, double p, int io, int il) {
    int sw = 0;
    const int o = low_octave(n, p);
    if (o > e->oct[io] && o != INT_MAX) sw = 1;
    e->oct[io] = o;
    node_hold(n, p, o, &e->hold_lo[io], &e->hold_hi[io]);
    if (n->p_lo < p && p < n->p_hi) { // every ramp closed: the common case
        for (int i = 0; i < n->nramp; ++i) e->lv[il + i] = 0;
        return sw;
    }
    for (int i = 0; i < n->nramp; ++i) {
        const hyd_fused_ramp* r = &n->ramp[i];
        const double d = r->into ? r->p_tank - p : p - r->p_tank;
        const unsigned char lv = corner_level((d - r->pcr) * r->inv_w);
        if (lv > e->lv[il + i]) sw = 1;
        e->lv[il + i] = lv;
    }
    return sw;
}

// A node inside its hold interval changes nothing (node_hold); the usual
// case is two compares per node. NaN bounds (or p) take node_events.
FUSED_INLINE int node_check(hyd_fused_events* e, const hyd_fused_node* n, double p, int* io, int* il,
                            int fresh) {
    const int i = (*io)++, l = *il;
    *il += n->nramp;
    if (!fresh && e->hold_lo[i] < p && p < e->hold_hi[i]) return 0;
    return node_events(e, n, p, i, l);
}

// 1 when every node's pressure is strictly inside its hold interval (false
// for NaN). With SSE2 two nodes per compare: this runs once per step.
#if defined(__SSE2__)
#include <emmintrin.h>
static inline int nodes_held(const hyd_fused_events* e, const hyd_fused* f, const double* y) {
    __m128d in = _mm_castsi128_pd(_mm_set1_epi32(-1));
    int i = 0;
    for (; i + 1 < f->nev; i += 2) {
        const __m128d p = _mm_loadh_pd(_mm_load_sd(&y[f->ev_s[i]]), &y[f->ev_s[i + 1]]);
        in = _mm_and_pd(in, _mm_and_pd(_mm_cmplt_pd(_mm_loadu_pd(&e->hold_lo[i]), p),
                                       _mm_cmplt_pd(p, _mm_loadu_pd(&e->hold_hi[i]))));
    }
    int held = _mm_movemask_pd(in) == 3;
    if (i < f->nev) {
        const double p = y[f->ev_s[i]];
        held &= e->hold_lo[i] < p && p < e->hold_hi[i];
    }
    return held;
}
#else
static inline int nodes_held(const hyd_fused_events* e, const hyd_fused* f, const double* y) {
    for (int i = 0; i < f->nev; ++i) {
        const double p = y[f->ev_s[i]];
        if (!(e->hold_lo[i] < p && p < e->hold_hi[i])) return 0;
    }
    return 1;
}
#endif

// The command steps, end stops and the pump band: what every call looks
// at. Returns 1 when one of them stiffened.
FUSED_INLINE int other_events(hyd_fused_events* e, const hyd_fused* f, const double* y, const double* x,
                              const double* cmd) {
    int sw = 0;
#if defined(__SSE2__)
    // Two actuators, both strokes inside [0, s] and both stops free at the
    // last call (the usual case): with 1/ws finite and > 0, -x/ws <= 0 and
    // (x - s)/ws <= 0 exactly, so both levels stay 0; only the commands are
    // compared, in one two-lane compare (false for NaN: a step).
    if (f->nact == 2 && f->stops_plain) {
        uint32_t st;
        memcpy(&st, e->stop, sizeof st);
        const __m128d xs = _mm_loadu_pd(x);
        if (st == 0 && _mm_movemask_pd(_mm_and_pd(_mm_cmpge_pd(xs, _mm_setzero_pd()),
                                                  _mm_cmple_pd(xs, _mm_loadu_pd(f->stroke2)))) == 3) {
            const __m128d c = _mm_loadu_pd(cmd);
            const __m128d d = _mm_andnot_pd(_mm_set1_pd(-0.0), _mm_sub_pd(c, _mm_loadu_pd(e->cmd)));
            if (_mm_movemask_pd(_mm_cmple_pd(d, _mm_set1_pd(HYD_FUSED_CMD_EVENT))) != 3) sw = 1;
            _mm_storeu_pd(e->cmd, c);
            goto pump;
        }
    }
#endif
    for (int k = 0; k < f->nact; ++k) {
        const hyd_fused_act* a = &f->act[k];
        if (!(fabs(cmd[k] - e->cmd[k]) <= HYD_FUSED_CMD_EVENT)) sw = 1;
        e->cmd[k] = cmd[k];
        // End stops: penetration over the smoothing width ws (cylinder.c).
        const double iw = a->inv_ws;
        const unsigned char lo = corner_level(-x[k] * iw), hi = corner_level((x[k] - a->s) * iw);
        if (lo > e->stop[2 * k] || hi > e->stop[2 * k + 1]) sw = 1;
        e->stop[2 * k] = lo, e->stop[2 * k + 1] = hi;
    }
#if defined(__SSE2__)
pump:
#endif
    // The pump's cut-off: a smoothstep over its band above pset, steep only
    // inside the band (level 1).
    {}
    const unsigned char lp = corner_level((y[f->pl.s] - f->p_in - f->pset) * f->inv_band);
    if (lp == 1 && e->pump != 1) sw = 1;
    e->pump = lp;
    return sw;
}

// A call with some node outside its hold interval (or none taken yet):
// every node by node_check. Out of line, so that the common case keeps few
// registers.
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static unsigned long events_nodes(hyd_fused_events* e, const hyd_fused* f, const double* y,
                                  const double* x, const double* cmd, int fresh) {
    int sw = 0, io = 0, il = 0;
    for (int k = 0; k < f->nact; ++k) {
        const hyd_fused_act* a = &f->act[k];
        sw |= node_check(e, &a->hA, y[a->hA.s], &io, &il, fresh);
        sw |= node_check(e, &a->hB, y[a->hB.s], &io, &il, fresh);
        sw |= node_check(e, &a->cA, y[a->cA.s], &io, &il, fresh);
        sw |= node_check(e, &a->cB, y[a->cB.s], &io, &il, fresh);
    }
    sw |= node_check(e, &f->pl, y[f->pl.s], &io, &il, fresh);
    sw |= other_events(e, f, y, x, cmd);
    if (e->have && sw) ++e->count;
    e->have = 1;
    return e->count;
}

unsigned long hyd_fused_events_update(hyd_fused_events* e, const hyd_fused* f, const double* y,
                                      const double* x, const double* cmd) {
    // The hold intervals come from f's thresholds: taken afresh for another
    // circuit record or a new model revision (a rebuilt f).
    const int fresh = !e->have || e->hold_f != f || e->hold_rev != f->m->revision;
    e->hold_f = f;
    e->hold_rev = f->m->revision;
    // Every node inside its interval (nearly every step): no node changes.
    if (fresh || !nodes_held(e, f, y)) return events_nodes(e, f, y, x, cmd, fresh);
    if (other_events(e, f, y, x, cmd)) ++e->count; // (have is set: not fresh)
    return e->count;
}

void hyd_fused_eval(const hyd_fused* f, const double* y, const double* x, const double* v,
                    const double* cmd, double* ydot, double* F) {
    const hyd_model* m = f->m;
    const double pPL = y[f->pl.s];
    double g;
    double qpl = pump_in(f, pPL, &g);
    for (int k = 0; k < f->nact; ++k) {
        const hyd_fused_act* a = &f->act[k];
        act_out o;
        actuator(a, y, pPL, x[k], v[k], cmd[k], &ydot[a->su], &o, 0);
        qpl -= o.q_pl;
        ydot[a->hA.s] = node_c(m, &a->hA, y[a->hA.s], a->hA.V0) * o.nhA;
        ydot[a->hB.s] = node_c(m, &a->hB, y[a->hB.s], a->hB.V0) * o.nhB;
        ydot[a->cA.s] = node_c(m, &a->cA, y[a->cA.s], o.VA) * o.nA;
        ydot[a->cB.s] = node_c(m, &a->cB, y[a->cB.s], o.VB) * o.nB;
        F[k] = o.F;
    }
    qpl += ramps_in(&f->pl, pPL, &g);
    ydot[f->pl.s] = node_c(m, &f->pl, pPL, f->pl.V0) * qpl;
}

// Be/V and the diagonal term d(Be/V)/dp * net of one node's Jacobian row.
static inline double node_c_d(const hyd_model* m, const hyd_fused_node* n, double p, double V,
                              double net, double* diag) {
    double dbe;
    const double c = hyd_node_c(m, n->bel, n->bec, p, V, NULL, &dbe);
    *diag = dbe / V * net;
    return c;
}

void hyd_fused_jacobian(const hyd_fused* f, const double* y, const double* x, const double* v,
                        const double* cmd, double* ydot, double* F, double* J, int ldj,
                        hyd_fused_coupling* cpl) {
    const hyd_model* m = f->m;
#define J_(i, j) J[(size_t)(i) * (size_t)ldj + (size_t)(j)]
    const int spl = f->pl.s;
    const double pPL = y[spl];
    double gp, gr;
    double qpl = pump_in(f, pPL, &gp);
    double g_pl_pl = gp; // d(net inflow of the pump line)/d pPL
    for (int k = 0; k < f->nact; ++k) {
        const hyd_fused_act* a = &f->act[k];
        act_out o;
        actuator(a, y, pPL, x[k], v[k], cmd[k], &ydot[a->su], &o, 1);
        qpl -= o.q_pl;
        F[k] = o.F;
        const int su = a->su, shA = a->hA.s, shB = a->hB.s, sA = a->cA.s, sB = a->cB.s;
        J_(su, su) = -a->inv_tau;

        // Flow partials (before Be/V). Into the feed hose: +q1; into the drain
        // hose: -q2; into the pump line: -q1.
        const int sfeed = o.pos ? shA : shB;
        g_pl_pl -= o.g1;
        J_(spl, sfeed) = o.g1; // scaled with the pump line row at the end
        J_(spl, su) = -o.du1;
        double G_hA[4] = {0}, G_hB[4] = {0}; // columns: pPL, own, chamber, spool
        double* Gf = o.pos ? G_hA : G_hB;
        double* Gd = o.pos ? G_hB : G_hA;
        Gf[0] = o.g1, Gf[1] = -o.g1, Gf[3] = o.du1;
        Gd[1] = -o.g2, Gd[3] = -o.du2;
        G_hA[1] += -a->GA + o.ghA, G_hA[2] = a->GA;
        G_hB[1] += -a->GB + o.ghB, G_hB[2] = a->GB;

        double dg;
        double c = node_c_d(m, &a->hA, y[shA], a->hA.V0, o.nhA, &dg);
        ydot[shA] = c * o.nhA;
        J_(shA, spl) = c * G_hA[0], J_(shA, shA) = c * G_hA[1] + dg, J_(shA, sA) = c * G_hA[2];
        J_(shA, su) = c * G_hA[3];
        c = node_c_d(m, &a->hB, y[shB], a->hB.V0, o.nhB, &dg);
        ydot[shB] = c * o.nhB;
        J_(shB, spl) = c * G_hB[0], J_(shB, shB) = c * G_hB[1] + dg, J_(shB, sB) = c * G_hB[2];
        J_(shB, su) = c * G_hB[3];

        // Chambers: hose, leakage, ramps; x and x' through V and dV/dt.
        const double cA = node_c_d(m, &a->cA, y[sA], o.VA, o.nA, &dg);
        ydot[sA] = cA * o.nA;
        J_(sA, shA) = cA * a->GA, J_(sA, sA) = cA * (-a->GA - a->CL + o.gA) + dg, J_(sA, sB) = cA * a->CL;
        const double cB = node_c_d(m, &a->cB, y[sB], o.VB, o.nB, &dg);
        ydot[sB] = cB * o.nB;
        J_(sB, shB) = cB * a->GB, J_(sB, sB) = cB * (-a->GB - a->CL + o.gB) + dg, J_(sB, sA) = cB * a->CL;

        hyd_fused_coupling* cp = &cpl[k];
        cp->dA_dx = -cA / o.VA * o.dVA * o.nA;
        cp->dB_dx = -cB / o.VB * o.dVB * o.nB;
        cp->dA_dv = -cA * a->AA;
        cp->dB_dv = cB * a->AB;
        cp->dF_dx = o.dFdx;
        cp->dF_dv = o.dFdv;
    }
    qpl += ramps_in(&f->pl, pPL, &gr);
    g_pl_pl += gr;
    double dg;
    const double c = node_c_d(m, &f->pl, pPL, f->pl.V0, qpl, &dg);
    ydot[spl] = c * qpl;
    J_(spl, spl) = c * g_pl_pl + dg;
    for (int k = 0; k < f->nact; ++k) {
        const hyd_fused_act* a = &f->act[k];
        J_(spl, a->hA.s) *= c;
        J_(spl, a->hB.s) *= c;
        J_(spl, a->su) *= c;
    }
#undef J_
}

// ------------------------------------------------------------------------
// Two lanes: hyd_fused_eval for two actuators with actuator k in lane k of
// SSE2 registers. The laws are not written again here: every formula is the
// component header's own macro (HYD_ORIFICE_*, HYD_SPOOL_RATE, HYD_HOSE_Q,
// HYD_CYL_*, HYD_AIR_POLY, HYD_BE_*), expanded on __m128d, which GCC and
// Clang treat as a vector type with + - * / lane by lane (a scalar operand
// applies to both lanes). So every lane runs exactly the scalar operations of
// actuator() / node_c() in the same order (IEEE add, mul, div and sqrt round
// the same in a lane as in a scalar register, and -ffp-contract=off keeps
// them unfused), and the result is bit for bit hyd_fused_eval's
// (test_fused in tests/hydraulics/test_circuit.c). Only the branches are replaced: both
// orifice regimes are computed and blended, open reliefs and checks are
// evaluated lane by lane, and the rare cases (an end stop, a pressure off the
// Be table) send the whole evaluation to the scalar kernel.
// ------------------------------------------------------------------------
#if defined(__SSE2__) && defined(__GNUC__)
#include "hyd_lanes.h"

// node_c for two nodes with the table path (hyd_be_nd, hyd_air_ratio):
// Be(P) / V. The caller has checked P is on the fast path in both lanes.
// P holds y[idx[0]], y[idx[1]]; the table indices are read from y.
static inline v2 node_c2(const hyd_model* m, const double* bel, const double* bec, v2 P, v2 V,
                         const double* y, const int* idx) {
    const hyd_air_tab* t = &m->air;
    const double* c[2];
    double oct[2];
    for (int l = 0; l < 2; ++l) {
        uint64_t b;
        memcpy(&b, &y[idx[l]], sizeof b);
        int e, j;
        hyd_air_index(b, &e, &j);
        c[l] = t->seg[j];
        oct[l] = t->oct[e];
    }
    return hyd_node_c2_tab(m, bel, bec, P, V, c, oct);
}

// Flows of the open reliefs and checks, lane by lane with the scalar law;
// closed lanes keep +0.0. Out of line (cold): keeping it out of the hot path
// keeps the register allocation of hyd_fused_eval2's common case tight.
#if defined(__GNUC__)
__attribute__((noinline, cold))
#endif
static void open_ramps2(const hyd_fused* f, const double* y, const int* cl, v2* rq) {
    const hyd_fused_lanes* L = &f->ln;
    for (int j = 0; j < 4; ++j) {
        if (cl[j] == 3) continue;
        double r[2] = {0.0, 0.0};
        for (int l = 0; l < 2; ++l) {
            const hyd_fused_act* a = &f->act[l];
            const hyd_fused_node* nd[4] = {&a->hA, &a->hB, &a->cA, &a->cB};
            double gr;
            if (!(cl[j] >> l & 1)) r[l] = ramps_in(nd[j], y[L->s_node[j][l]], &gr);
        }
        rq[j] = set2(r[0], r[1]);
    }
}

// Lane mask (bits 0, 1) of p_lo < p < p_hi: every relief and check of the
// node closed.
static inline int closed2(const double* lo, const double* hi, v2 p) {
    return _mm_movemask_pd(_mm_and_pd(_mm_cmplt_pd(ld(lo), p), _mm_cmplt_pd(p, ld(hi))));
}

// P >= HYD_BE_P_LO && P < 2^64 (false for NaN), as hyd_be_nd.
static inline int fast2(v2 p) {
    return _mm_movemask_pd(_mm_and_pd(_mm_cmpge_pd(p, _mm_set1_pd(HYD_BE_P_LO)),
                                      _mm_cmplt_pd(p, _mm_set1_pd(HYD_BE_P_HI))));
}

void hyd_fused_eval2(const hyd_fused* f, const double* y, const double* x, const double* v,
                     const double* cmd, double* ydot, double* F) {
    const hyd_fused_lanes* L = &f->ln;
    if (!f->lanes_ok) {
        hyd_fused_eval(f, y, x, v, cmd, ydot, F);
        return;
    }
    const hyd_model* m = f->m;
    const v2 ph[2] = {ld_at(y, L->s_node[0]), ld_at(y, L->s_node[1])}; // hoses A, B
    const v2 pc[2] = {ld_at(y, L->s_node[2]), ld_at(y, L->s_node[3])}; // chambers A, B
    const v2 xs = set2(x[0], x[1]), vs = set2(v[0], v[1]);
    // The common case in every lane, else the scalar kernel decides. Open
    // reliefs and checks (an anti-cavitation valve while an overrunning load
    // is lowered) are taken lane by lane with the scalar ramps_in.
    int ok = 3, shut = 3;
    int cl[4];
    for (int j = 0; j < 2; ++j) {
        ok &= fast2(ph[j]) & fast2(pc[j]);
        shut &= (cl[j] = closed2(L->p_lo[j], L->p_hi[j], ph[j]));
        shut &= (cl[2 + j] = closed2(L->p_lo[2 + j], L->p_hi[2 + j], pc[j]));
    }
    // hyd_stop_force is zero while -x <= 0 and x - s <= 0.
    ok &= _mm_movemask_pd(_mm_and_pd(_mm_cmple_pd(_mm_sub_pd(_mm_setzero_pd(), xs), _mm_setzero_pd()),
                                     _mm_cmple_pd(_mm_sub_pd(xs, ld(L->s)), _mm_setzero_pd())));
    if (ok != 3) {
        hyd_fused_eval(f, y, x, v, cmd, ydot, F);
        return;
    }
    const double pPL = y[f->pl.s];
    double g;
    double qpl = pump_in(f, pPL, &g);

    // Spools. The command clamped to [-1, 1]: maxpd/minpd return their
    // second operand unless the first compares greater/less, so a NaN
    // command stays NaN, as in actuator().
    const v2 one = _mm_set1_pd(1.0);
    const v2 c2 = _mm_min_pd(one, _mm_max_pd(_mm_set1_pd(-1.0), set2(cmd[0], cmd[1])));
    const v2 u = ld_at(y, L->su);
    st_at(ydot, L->su, HYD_SPOOL_RATE(c2, u, ld(L->inv_tau)));

    // Valve edges: 1 feeds a work port from P, 2 drains the other to T.
    const v2 sign = _mm_set1_pd(-0.0);
    const v2 pos = _mm_cmpge_pd(u, _mm_setzero_pd());
    const v2 A = HYD_VALVE_AREA(ld(L->Amax), _mm_andnot_pd(sign, u));
    const v2 sA = _mm_sqrt_pd(A);
    const v2 dp1 = pPL - blend(pos, ph[0], ph[1]); // as hyd_valve_edges
    const v2 dp2 = blend(pos, ph[1], ph[0]) - ld(L->pT);
    const v2 k = ld(L->ok), invP0 = ld(L->oinvP0), kl = ld(L->okl);
    const v2 q1 = orifice2(k, invP0, kl, A, sA, dp1);
    const v2 q2 = orifice2(k, invP0, kl, A, sA, dp2);
    const v2 nq2 = _mm_xor_pd(q2, sign);
    const v2 inA = blend(pos, q1, nq2), inB = blend(pos, nq2, q1);

    // Hoses, leakage, volumes.
    const v2 qhA = HYD_HOSE_Q(ld(L->GA), ph[0], pc[0]);
    const v2 qhB = HYD_HOSE_Q(ld(L->GB), ph[1], pc[1]);
    const v2 leak = HYD_CYL_LEAK(ld(L->CL), pc[0], pc[1]);
    const v2 AA = ld(L->AA), AB = ld(L->AB);
    // max(a, b) is a > b ? a : b, the floor of hyd_cyl_volumes.
    const v2 VA = _mm_max_pd(HYD_CYL_VA(ld(L->VA0), AA, xs), ld(L->VAmin));
    const v2 VB = _mm_max_pd(HYD_CYL_VB(ld(L->VB0), AB, ld(L->s), xs), ld(L->VBmin));
    // Reliefs and checks: closed ones add +0.0, as ramps_in returns.
    const v2 z = _mm_setzero_pd();
    v2 rq[4] = {z, z, z, z};
    if (shut != 3) open_ramps2(f, y, cl, rq);
    const v2 nhA = NET_HOSE(inA, qhA, rq[0]);
    const v2 nhB = NET_HOSE(inB, qhB, rq[1]);
    const v2 nA = NET_CHAMBER_A(qhA, leak, rq[2], AA, vs);
    const v2 nB = NET_CHAMBER_B(qhB, leak, rq[3], AB, vs);
    // No end stop touched (checked above): both stop forces are +0.0.
    const v2 Fv = HYD_CYL_FORCE(AA, AB, ld(L->bv), pc[0], pc[1], vs, z, z);
    _mm_storeu_pd(F, Fv);
    // Seal friction lane by lane, after the store as the scalar kernel
    // subtracts it after hyd_cyl_force (+0.0 when a cylinder has none).
    for (int k2 = 0; k2 < 2 && f->seal; ++k2) {
        const hyd_fused_act* a = &f->act[k2];
        double dseal;
        F[k2] -= hyd_cyl_seal(a->Fc, a->Fs, a->vst, a->vsm, v[k2], &dseal);
    }

    st_at(ydot, L->s_node[0], node_c2(m, L->bel[0], L->bec[0], ph[0], ld(L->hV0[0]), y, L->s_node[0]) * nhA);
    st_at(ydot, L->s_node[1], node_c2(m, L->bel[1], L->bec[1], ph[1], ld(L->hV0[1]), y, L->s_node[1]) * nhB);
    st_at(ydot, L->s_node[2], node_c2(m, L->bel[2], L->bec[2], pc[0], VA, y, L->s_node[2]) * nA);
    st_at(ydot, L->s_node[3], node_c2(m, L->bel[3], L->bec[3], pc[1], VB, y, L->s_node[3]) * nB);

    double q1s[2];
    _mm_storeu_pd(q1s, q1);
    qpl -= q1s[0];
    qpl -= q1s[1];
    qpl += ramps_in(&f->pl, pPL, &g);
    ydot[f->pl.s] = node_c(m, &f->pl, pPL, f->pl.V0) * qpl;
}
#else
void hyd_fused_eval2(const hyd_fused* f, const double* y, const double* x, const double* v,
                     const double* cmd, double* ydot, double* F) {
    hyd_fused_eval(f, y, x, v, cmd, ydot, F);
}
#endif
