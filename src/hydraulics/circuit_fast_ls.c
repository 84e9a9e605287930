// circuit_fast_ls.c: the load-sensing crane layout in one pass, its two
// sections side by side in the two lanes of SSE2 registers.
//
// The layout (assets/models/hiab031_ls.json): an LS pump from a tank into the
// pump line, sensing the LS line; a max-select LS shuttle of the two
// sections' LS nodes into the LS line; per section a post- or
// pre-compensator from the pump line into the valve's P, sensing the
// section's LS node and the LS line; a 4/3 valve P -> A/B -> a tank; a
// spool-mode shuttle of the valve's ports (and tank) into the section's LS
// node; hose A into the counterbalance valve's valve-side node, the valve
// into chamber A, its pilot volume fed from hose B through a damping orifice;
// hose B into chamber B; the cylinder. Reliefs and checks anywhere between
// these nodes and tanks. Recognised at hyd_fast_create / hyd_fast_map
// (hyd_fast_ls_pack) by an allow-list, ls_allowed: the exact count of each
// type above and no component of any other type, so that a component the
// pass has no place for (a type added later, with or without a fast loop)
// refuses the layout instead of being left out of the sums. Any other
// circuit keeps the per-type loops, the reason in hyd_fast_lanes_why.
//
// Why it is the loops bit for bit:
// - every law is its component header's own text: the + - * macros
//   (HYD_ORIFICE_*, HYD_SPOOL_RATE, HYD_VALVE_AREA, HYD_HOSE_Q, HYD_CYL_*,
//   HYD_SHUTTLE_*, HYD_COMP_*, HYD_LAG_RATE, HYD_CB_*, HYD_RAMP_*,
//   HYD_SMOOTHSTEP_POLY, HYD_AIR_POLY, HYD_BE_*) expanded on __m128d, which
//   GCC and Clang treat as a vector type with + - * / lane by lane. IEEE
//   add, mul, div and sqrt round the same in a lane as in a scalar register,
//   and -ffp-contract=off keeps them unfused, so each lane runs exactly the
//   scalar operations. The branches become blends of both sides on the
//   scalar law's own compare (the orifice's |x| < 1, the ramp's t <= 0 and
//   t < 1, the valve's u >= 0); a smoothstep is its cubic on t clamped to
//   [0, 1] with maxpd/minpd, which gives 0 and 1 at the clamps exactly (and
//   passes a NaN through, as the scalar cubic does). The shared parts (LS
//   pump, LS shuttle) and the seal friction (exp, tanh) run the scalar
//   functions themselves.
// - each node's net inflow is summed in the loops' order: they add the flows
//   type by type (reliefs, checks, orifices, hoses, valves, LS pump,
//   shuttles, compensators, counterbalance valves, cylinder leakage), each
//   type in record order, into a net that starts at +0.0. The sums below
//   are those sequences written out per node (the pack checks the record
//   order they assume), starting from the open reliefs' and checks' sum
//   (+0.0 when all are closed: the loops skip a closed one).
// - the common case only: no end stop touched (both stop forces +0.0) and
//   every pressure on the Be table. Otherwise hyd_fast_ls_eval returns 0
//   and the loops run.
// tests/hydraulics/test_fast.c (test_ls_lanes) compares the two paths bit
// for bit on random states in every regime.
#include "circuit_fast_ls.h"

#include "hyd_compensator.h"
#include "hyd_counterbalance.h"
#include "hyd_cylinder.h"
#include "hyd_hose.h"
#include "hyd_orifice.h"
#include "hyd_ramp.h"
#include "hyd_valve.h"

#include <float.h>
#include <math.h>
#include <string.h>

// The records of type t and how many there are.
#define RECS(m, t, T) ((const T*)(m)->rec[t])

#if defined(__SSE2__) && defined(__GNUC__)
#define LSK_LANES 1
#if defined(__x86_64__)
#define LSK_AVX 1 // an AVX form of the kernel, taken when the CPU has AVX
#endif
#endif

// The pack's helpers (the lanes only: without SSE2 the layout is never taken).
#ifdef LSK_LANES
static void set_mask(double* d, int on) {
    const uint64_t b = on ? ~0ull : 0ull;
    memcpy(d, &b, sizeof b);
}


// Doubles in order as integers (for the bisection below): a monotone map of
// the finite doubles onto int64.
static int64_t dkey(double x) {
    int64_t b;
    memcpy(&b, &x, sizeof b);
    return b >= 0 ? b : INT64_MIN - b;
}
static double dval(int64_t k) {
    const int64_t b = k >= 0 ? k : INT64_MIN - k;
    double x;
    memcpy(&x, &b, sizeof x);
    return x;
}

// The ramp's rounded t (hyd_ramp_q's HYD_RAMP_T) at pressure p of its
// volume end (the other a tank).
static double ramp_t(const hyd_fast_ls_ramp* r, double p) {
    const double pi = r->in >= 0 ? p : r->pin, po = r->out >= 0 ? p : r->pout;
    return HYD_RAMP_T(pi - po, r->pcr, r->inv_w);
}

// The closed set {p : t(p) <= 0} of a ramp from a volume to a tank (a
// relief: t rises with p) or from a tank into a volume (a check: t falls
// with p). Each rounded operation of t is monotone in p (with inv_w > 0),
// so the set is p <= b (relief) or p >= b (check) with b found by bisection
// on the doubles themselves: exactly the p the loops skip. *b = +-HUGE_VAL
// when every finite p is inside, -+HUGE_VAL when none is. Returns 0 when
// inv_w is not positive and finite (then no bound is taken).
static int ramp_bound(const hyd_fast_ls_ramp* r, int relief, double* b) {
    if (!(r->inv_w > 0.0 && r->inv_w < HUGE_VAL)) return 0;
    // inside(p): t(p) <= 0; relief: true below b; check: true above b.
    int64_t lo = dkey(-DBL_MAX), hi = dkey(DBL_MAX);
#define INSIDE(k) (ramp_t(r, dval(k)) <= 0.0)
    // The midpoint without overflow (hi - lo may exceed INT64_MAX).
#define MID(a, b) ((int64_t)((uint64_t)(a) + ((uint64_t)(b) - (uint64_t)(a)) / 2))
    if (relief) {
        if (INSIDE(hi)) return *b = HUGE_VAL, 1;
        if (!INSIDE(lo)) return *b = -HUGE_VAL, 1;
        while ((uint64_t)hi - (uint64_t)lo > 1) { // INSIDE(lo), !INSIDE(hi)
            const int64_t mid = MID(lo, hi);
            if (INSIDE(mid)) lo = mid;
            else hi = mid;
        }
        *b = dval(lo);
    } else {
        if (INSIDE(lo)) return *b = -HUGE_VAL, 1;
        if (!INSIDE(hi)) return *b = HUGE_VAL, 1;
        while ((uint64_t)hi - (uint64_t)lo > 1) { // !INSIDE(lo), INSIDE(hi)
            const int64_t mid = MID(lo, hi);
            if (INSIDE(mid)) hi = mid;
            else lo = mid;
        }
        *b = dval(hi);
    }
#undef INSIDE
#undef MID
    return 1;
}

#endif

// The layout's allow-list: how many components of type t it packs (-1: any
// number, the reliefs and checks, which the pack places by their nodes, up to
// LSK_MAXRAMP together). Every other type, and every type added to the
// library after this list, is 0: a component the pass has no place for would
// be left out of its sums, so its presence refuses the layout and the loops
// (or their fallback) run.
static int ls_allowed(hyd_type t) {
    switch (t) {
    case HYD_LS_PUMP:
        return 1;
    case HYD_SHUTTLE:
        return 3; // the LS line's max-select and one per section
    case HYD_COMPENSATOR:
        return 2;
    case HYD_COUNTERBALANCE:
        return 2;
    case HYD_VALVE:
        return 2;
    case HYD_CYLINDER:
        return 2;
    case HYD_HOSE:
        return 4;
    case HYD_ORIFICE:
        return 2; // the counterbalance valves' pilot damping
    case HYD_RELIEF:
    case HYD_CHECK:
        return -1;
    default:
        return 0;
    }
}

// The reason the layout was refused, kept for hyd_fast_lanes_why.
#define REFUSE(...) return (void)snprintf(L->why, sizeof L->why, __VA_ARGS__)

void hyd_fast_ls_pack(const hyd_model* m, const int* smap, const int* ns, hyd_fast_ls* L) {
    memset(L, 0, sizeof *L);
#ifndef LSK_LANES
    (void)m, (void)smap, (void)ns, (void)ls_allowed;
    REFUSE("the one-pass layout needs SSE2");
#else
    if (!m->air.use) REFUSE("the air tables are off (the lanes take Be from them only)");
    // The allow-list, component by component (not by the counts of the types
    // the pack knows: a type it does not know must refuse too).
    int cnt[HYD_TYPE_COUNT] = {0};
    for (int c = 0; c < m->ncomp; ++c) {
        const hyd_type t = m->comp[c].type;
        if ((unsigned)t >= HYD_TYPE_COUNT || ls_allowed(t) == 0)
            REFUSE("component '%s' (%s): the load-sensing layout has no place for this type",
                   m->comp[c].name, hyd_type_name(t));
        ++cnt[t];
    }
    for (int t = 0; t < HYD_TYPE_COUNT; ++t) {
        const int want = ls_allowed((hyd_type)t);
        if (want >= 0 && cnt[t] != want)
            REFUSE("%d components of type %s, the load-sensing layout has %d", cnt[t],
                   hyd_type_name((hyd_type)t), want);
    }
    if (m->nvol != LSK_NSLOT)
        REFUSE("%d volume nodes, the load-sensing layout has %d", m->nvol, LSK_NSLOT);
    const int* nr = m->nrec;
    const hyd_ls_pump_c* pu = RECS(m, HYD_LS_PUMP, hyd_ls_pump_c);
    const hyd_shuttle_c* sh = RECS(m, HYD_SHUTTLE, hyd_shuttle_c);
    const hyd_comp_c* co = RECS(m, HYD_COMPENSATOR, hyd_comp_c);
    const hyd_cb_c* cb = RECS(m, HYD_COUNTERBALANCE, hyd_cb_c);
    const hyd_valve_c* va = RECS(m, HYD_VALVE, hyd_valve_c);
    const hyd_cyl_c* cy = RECS(m, HYD_CYLINDER, hyd_cyl_c);
    const hyd_hose_c* ho = RECS(m, HYD_HOSE, hyd_hose_c);
    const hyd_orifice_c* orf = RECS(m, HYD_ORIFICE, hyd_orifice_c);
    const int pl = pu->out, ll = pu->ls;
    if (m->node_state[pu->in] >= 0) REFUSE("the LS pump does not draw from a tank");
    // The LS shuttle: the one in max-select mode, first among the shuttles
    // (the section LS nodes get its flow before their own shuttle's).
    if (sh[0].su >= 0 || sh[1].su < 0 || sh[2].su < 0 || sh[0].out != ll)
        REFUSE("the shuttles are not a max-select one into the LS line, then two spool-mode ones");
    L->node[LSK_PL] = pl, L->node[LSK_LL] = ll;
    for (int l = 0; l < 2; ++l) {
        // Lane l is compensator l: the pump line loses compensator 0's flow
        // before compensator 1's, as the loops subtract them.
        const hyd_comp_c* c = &co[l];
        if (c->in != pl || c->ref != ll)
            REFUSE("compensator %d is not fed from the pump line with the LS line as its reference",
                   l);
        const hyd_valve_c* v = NULL;
        for (int i = 0; i < 2; ++i)
            if (va[i].P == c->out) v = &va[i];
        if (!v || m->node_state[v->T] >= 0)
            REFUSE("compensator %d feeds no valve draining to a tank", l);
        const hyd_shuttle_c* s = NULL;
        for (int i = 1; i < 3; ++i)
            if (sh[i].su == v->adr) s = &sh[i];
        if (!s || s->a != v->A || s->b != v->B || s->t != v->T || s->out != c->load)
            REFUSE("section %d has no spool-mode shuttle of its valve's ports into its LS node", l);
        const hyd_hose_c *ha = NULL, *hb = NULL;
        for (int i = 0; i < 4; ++i) {
            if (ho[i].node == v->A) ha = &ho[i];
            if (ho[i].node == v->B) hb = &ho[i];
        }
        if (!ha || !hb) REFUSE("a valve port of section %d is not a hose", l);
        const hyd_cyl_c* y = NULL;
        for (int i = 0; i < 2; ++i)
            if (cy[i].nB == hb->to) y = &cy[i];
        const hyd_cb_c* b = NULL;
        for (int i = 0; i < 2; ++i)
            if (cb[i].v == ha->to) b = &cb[i];
        if (!y || !b || b->l != y->nA)
            REFUSE("section %d: hose A does not reach chamber A through a counterbalance valve", l);
        const hyd_orifice_c* o = NULL;
        for (int i = 0; i < 2; ++i)
            if (orf[i].in == v->B && orf[i].out == b->p) o = &orf[i];
        if (!o) REFUSE("section %d: no damping orifice from hose B to the counterbalance pilot", l);
        const int nodes[LSK_NSEC] = {v->P, c->load, v->A, v->B, b->v, b->p, y->nA, y->nB};
        for (int j = 0; j < LSK_NSEC; ++j) L->node[2 * j + l] = nodes[j];
        L->su[l] = smap[v->adr], L->sx[l] = smap[c->adr], L->sc[l] = smap[b->adr];
        L->vi[l] = m->comp_sub[v->comp], L->ci[l] = m->comp_sub[y->comp];
        L->Amax[l] = v->Amax, L->vtau[l] = v->inv_tau, L->vk[l] = v->ok.k, L->vinvP0[l] = v->ok.invP0;
        L->vkl[l] = v->ok.kl, L->pT[l] = m->node_pfix[v->T];
        L->shG[l] = s->G, L->shinv_uw[l] = s->inv_uw;
        L->GA[l] = ha->G, L->GB[l] = hb->G;
        L->oA[l] = o->A, L->osA[l] = sqrt(o->A), L->ok_[l] = o->ok.k, L->oinvP0[l] = o->ok.invP0;
        L->okl[l] = o->ok.kl;
        L->cA[l] = c->A, L->cset[l] = c->set, L->cinv_band[l] = c->inv_band, L->ctau[l] = c->inv_tau;
        L->ck[l] = c->ok.k, L->cinvP0[l] = c->ok.invP0, L->ckl[l] = c->ok.kl;
        set_mask(&L->cpost[l], c->post);
        L->bpset[l] = b->pset, L->bR[l] = b->R, L->binv_band[l] = b->inv_band, L->bA[l] = b->A;
        L->btau[l] = b->inv_tau, L->bccr[l] = b->ccr, L->binv_cw[l] = b->inv_cw, L->bcq[l] = b->cq;
        L->bk[l] = b->ok.k, L->binvP0[l] = b->ok.invP0, L->bkl[l] = b->ok.kl;
        set_mask(&L->bvent[l], !(b->pvent < 0.0));
        L->bpvent[l] = b->pvent;
        L->AA[l] = y->AA, L->AB[l] = y->AB, L->stroke[l] = y->s, L->VA0[l] = y->VA0, L->VB0[l] = y->VB0;
        L->VAmin[l] = HYD_CYL_VMIN(y->VA0), L->VBmin[l] = HYD_CYL_VMIN(y->VB0);
        L->CL[l] = y->CL, L->bv[l] = y->bv;
        L->Fc[l] = y->Fc, L->Fs[l] = y->Fs, L->vst[l] = y->vst, L->vsm[l] = y->vsm;
        L->seal_l[l] = y->Fc != 0.0 || y->Fs != 0.0;
        set_mask(&L->seal_m[l], L->seal_l[l]);
        L->seal |= L->seal_l[l];
    }
    if (sh[0].a != L->node[2 * LSK_LS] || sh[0].b != L->node[2 * LSK_LS + 1])
        REFUSE("the LS shuttle does not select between the two sections' LS nodes");
    // Every slot a distinct volume node (nvol == LSK_NSLOT: then every volume
    // node is one of them, and each flow above reaches its node only here).
    int slot_of[256];
    if (m->nnode > 256) REFUSE("more than 256 nodes");
    for (int i = 0; i < m->nnode; ++i) slot_of[i] = -1;
    for (int i = 0; i < LSK_NSLOT; ++i) {
        const int nd = L->node[i];
        if (nd < 0 || nd >= m->nnode || ns[nd] < 0 || slot_of[nd] >= 0)
            REFUSE("the layout's nodes are not %d distinct volumes", LSK_NSLOT);
        slot_of[nd] = i;
        L->s[i] = ns[nd];
        L->bel[i] = m->node_bel[nd], L->bec[i] = m->node_bec[nd], L->V0[i] = m->node_V0[nd];
    }
    // Reliefs, then checks, in record order (the loops' order).
    L->nramp = 0;
    for (int pass = 0; pass < 2; ++pass) {
        const hyd_type t = pass ? HYD_CHECK : HYD_RELIEF;
        const hyd_ramp_c* r = RECS(m, t, hyd_ramp_c);
        for (int i = 0; i < nr[t]; ++i) {
            if (L->nramp == LSK_MAXRAMP) REFUSE("more than %d reliefs and checks", LSK_MAXRAMP);
            hyd_fast_ls_ramp* q = &L->ramp[L->nramp++];
            q->in = slot_of[r[i].in], q->out = slot_of[r[i].out];
            q->pin = m->node_pfix[r[i].in], q->pout = m->node_pfix[r[i].out];
            q->pcr = r[i].pcr, q->inv_w = r[i].inv_w, q->qr = r[i].qr;
        }
    }
    for (int i = 0; i < LSK_NSLOT; ++i) L->lo[i] = -HUGE_VAL, L->hi[i] = HUGE_VAL;
    L->ramp_any = 0;
    for (int i = 0; i < L->nramp; ++i) {
        const hyd_fast_ls_ramp* q = &L->ramp[i];
        double b;
        if ((q->in >= 0) == (q->out >= 0) || !ramp_bound(q, q->in >= 0, &b)) {
            L->ramp_any |= q->in >= 0 || q->out >= 0; // between two tanks: no node sees it
            continue;
        }
        if (q->in >= 0) L->hi[q->in] = fmin(L->hi[q->in], b); // relief: closed while p <= b
        else L->lo[q->out] = fmax(L->lo[q->out], b);          // check: closed while p >= b
    }
    L->pump = *pu;
    L->pump.adr = smap[pu->adr];
    L->pump_pin = m->node_pfix[pu->in];
    L->lssh = sh[0];
    L->ok = 1;
    hyd_fast_ls_avx(L, 1);
#endif
}
#undef REFUSE

#ifdef LSK_LANES
#include "hyd_lanes.h"

// hyd_smoothstep's value: its cubic on t clamped to [0, 1]. maxpd(0, t)
// returns t unless 0 > t (so t for a NaN and for -0, whose cubic is +0), and
// minpd(1, .) likewise.
static inline v2 smooth2(v2 t) {
    return HYD_SMOOTHSTEP_POLY(_mm_min_pd(_mm_set1_pd(1.0), _mm_max_pd(_mm_setzero_pd(), t)));
}

// x > 0 ? x : 0 (a spool a rounding error below 0 is closed): maxpd(x, 0)
// returns 0 unless x > 0, also for a NaN.
static inline v2 open2(v2 x) { return _mm_max_pd(x, _mm_setzero_pd()); }

// hyd_ramp_q's flow: +0.0 while t <= 0, qr t^2 below 1, qr (2t - 1) beyond.
static inline v2 ramp2(v2 pcr, v2 inv_w, v2 qr, v2 dp) {
    const v2 t = HYD_RAMP_T(dp, pcr, inv_w);
    const v2 r = blend(_mm_cmplt_pd(t, _mm_set1_pd(1.0)), HYD_RAMP_CORNER(t), HYD_RAMP_LINE(t));
    return _mm_andnot_pd(_mm_cmple_pd(t, _mm_setzero_pd()), qr * r);
}

// P >= HYD_BE_P_LO && P < 2^64 (false for NaN), as hyd_be_nd: lane mask.
static inline int fast2(v2 p) {
    return _mm_movemask_pd(_mm_and_pd(_mm_cmpge_pd(p, _mm_set1_pd(HYD_BE_P_LO)),
                                      _mm_cmplt_pd(p, _mm_set1_pd(HYD_BE_P_HI))));
}

// Be / V of two nodes on the table path (hyd_node_c through hyd_be_nd and
// hyd_air_ratio): the header's macros on both lanes, only the table entries
// gathered lane by lane. The caller has checked fast2(P) == 3.
static inline v2 node_c2(const hyd_model* m, const double* bel, const double* bec, v2 P, v2 V) {
    const hyd_air_tab* t = &m->air;
    const __m128i bits = _mm_castpd_si128(P);
    const uint64_t b[2] = {(uint64_t)_mm_cvtsi128_si64(bits),
                           (uint64_t)_mm_cvtsi128_si64(_mm_unpackhi_epi64(bits, bits))};
    const double* c[2];
    double oct[2];
    for (int l = 0; l < 2; ++l) {
        int e, j;
        hyd_air_index(b[l], &e, &j);
        c[l] = t->seg[j];
        oct[l] = t->oct[e];
    }
    return hyd_node_c2_tab(m, bel, bec, P, V, c, oct);
}

// The open reliefs' and checks' flows into their nodes' starting sums st
// (the loops' order); 0 when all are closed (st untouched). Out of line:
// the common case is all closed.
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int ramps(const hyd_fast_ls* L, const double* y, double* st) {
    int open = 0;
    for (int i = 0; i < L->nramp; ++i) {
        const hyd_fast_ls_ramp* r = &L->ramp[i];
        const double pi = r->in >= 0 ? y[L->s[r->in]] : r->pin;
        const double po = r->out >= 0 ? y[L->s[r->out]] : r->pout;
        double g, t;
        const double q = hyd_ramp_q(r->pcr, r->inv_w, r->qr, pi - po, &g, &t);
        if (t <= 0.0) continue; // closed: the loops add nothing (a NaN goes on)
        if (!open) memset(st, 0, LSK_NSLOT * sizeof *st), open = 1;
        if (r->in >= 0) st[r->in] -= q;
        if (r->out >= 0) st[r->out] += q;
    }
    return open;
}

// The body, compiled twice below: for plain SSE2 and for AVX (the same
// 128-bit operations in VEX form; see hyd_fast_ls_eval).
static inline __attribute__((always_inline)) int ls_eval(const hyd_fast_ls* L, const hyd_model* m, hyd_data* d,
                                                         const double* y, double* ydot) {
    v2 P[LSK_NSEC];
    int ok = 3;
    for (int j = 0; j < LSK_NSEC; ++j) {
        P[j] = ld_at(y, &L->s[2 * j]);
        ok &= fast2(P[j]);
    }
    const v2 Psh = ld_at(y, &L->s[LSK_PL]); // pump line, LS line
    ok &= fast2(Psh);
    const int c0 = L->ci[0], c1 = L->ci[1];
    const v2 xs = set2(d->cyl_x[c0], d->cyl_x[c1]), vs = set2(d->cyl_v[c0], d->cyl_v[c1]);
    const v2 z = _mm_setzero_pd();
    // hyd_stop_force is +0.0 while -x <= 0 and x - s <= 0.
    ok &= _mm_movemask_pd(_mm_and_pd(_mm_cmple_pd(_mm_sub_pd(z, xs), z), _mm_cmple_pd(xs - ld(L->stroke), z)));
    if (ok != 3) return 0;

    // Reliefs and checks first (the loops' first flows into any node): all
    // closed while every slot is inside its bounds (NaN was refused above).
    int shut = 3;
    for (int j = 0; j < LSK_NSEC; ++j)
        shut &= _mm_movemask_pd(_mm_and_pd(_mm_cmple_pd(ld(&L->lo[2 * j]), P[j]), _mm_cmple_pd(P[j], ld(&L->hi[2 * j]))));
    shut &= _mm_movemask_pd(_mm_and_pd(_mm_cmple_pd(ld(&L->lo[LSK_PL]), Psh), _mm_cmple_pd(Psh, ld(&L->hi[LSK_PL]))));
    double st[LSK_NSLOT];
    const int open = shut == 3 && !L->ramp_any ? 0 : ramps(L, y, st);
    v2 S[LSK_NSEC];
    for (int j = 0; j < LSK_NSEC; ++j) S[j] = open ? ld(&st[2 * j]) : z;
    const double spl = open ? st[LSK_PL] : 0.0, sll = open ? st[LSK_LL] : 0.0;

    // The shared part, scalar: LS pump and LS shuttle.
    const double ppl = y[L->s[LSK_PL]], pll = y[L->s[LSK_LL]];
    double a1, a2;
    const double target = hyd_ls_pump_target(&L->pump, L->pump_pin, ppl, pll, &a1, &a2);
    const double eps = y[L->pump.adr];
    ydot[L->pump.adr] = HYD_LS_PUMP_RATE(target, eps, L->pump.inv_tau);
    const double qpump = HYD_LS_PUMP_Q(eps, L->pump.qmax, L->pump.cleak, ppl, L->pump_pin);
    double fls[4];
    hyd_shuttle_flows(&L->lssh, 0.0, y[L->s[2 * LSK_LS]], y[L->s[2 * LSK_LS + 1]], pll, 0.0, fls);

    // Valves: the spool lag on the clamped command (maxpd/minpd keep a NaN
    // command NaN, as hyd_spool_rate), edge 1 feeds a work port from P, edge
    // 2 drains the other to T.
    const v2 one = _mm_set1_pd(1.0), sign = _mm_set1_pd(-0.0);
    const v2 cmd = _mm_min_pd(one, _mm_max_pd(_mm_set1_pd(-1.0), set2(d->valve_cmd[L->vi[0]], d->valve_cmd[L->vi[1]])));
    const v2 u = ld_at(y, L->su);
    st_at(ydot, L->su, HYD_SPOOL_RATE(cmd, u, ld(L->vtau)));
    const v2 pos = _mm_cmpge_pd(u, z);
    const v2 A = HYD_VALVE_AREA(ld(L->Amax), _mm_andnot_pd(sign, u));
    const v2 sA = _mm_sqrt_pd(A);
    const v2 dp1 = P[LSK_P] - blend(pos, P[LSK_HA], P[LSK_HB]); // as hyd_valve_edges
    const v2 dp2 = blend(pos, P[LSK_HB], P[LSK_HA]) - ld(L->pT);
    const v2 q1 = orifice2(ld(L->vk), ld(L->vinvP0), ld(L->vkl), A, sA, dp1);
    const v2 q2 = orifice2(ld(L->vk), ld(L->vinvP0), ld(L->vkl), A, sA, dp2);
    const v2 nq2 = _mm_xor_pd(q2, sign); // x + (-q2) is x - q2 exactly
    const v2 inA = blend(pos, q1, nq2), inB = blend(pos, nq2, q1);

    // Section shuttles (spool mode): ports A, B and the tank into the LS node.
    const v2 uw = ld(L->shinv_uw), G = ld(L->shG), pls = P[LSK_LS];
    const v2 wa = smooth2(u * uw), wb = smooth2(_mm_xor_pd(u, sign) * uw);
    const v2 wt = HYD_SHUTTLE_WT(wa, wb);
    const v2 qa = HYD_SHUTTLE_QK(G, wa, P[LSK_HA], pls), qb = HYD_SHUTTLE_QK(G, wb, P[LSK_HB], pls);
    const v2 qt = HYD_SHUTTLE_QK(G, wt, ld(L->pT), pls);
    const v2 f0 = z - qa, f1 = z - qb, f2 = ((z + qa) + qb) + qt; // hyd_shuttle_flows' sums

    // Compensators: pump line -> P.
    const v2 cset = ld(L->cset);
    const v2 tgt = blend(ld(L->cpost), HYD_COMP_TARGET_POST(ppl, pll, cset), cset);
    const v2 xt = HYD_COMP_OPEN(smooth2(HYD_COMP_ARG(P[LSK_P], pls, tgt, ld(L->cinv_band))));
    const v2 xc = ld_at(y, L->sx);
    st_at(ydot, L->sx, HYD_LAG_RATE(xt, xc, ld(L->ctau)));
    const v2 Ac = ld(L->cA) * open2(xc);
    const v2 qc = orifice2(ld(L->ck), ld(L->cinvP0), ld(L->ckl), Ac, _mm_sqrt_pd(Ac), ppl - P[LSK_P]);

    // Counterbalance valves: check path valve -> load, relief path back.
    const v2 pv = P[LSK_CV], pld = P[LSK_CA];
    const v2 pr = blend(ld(L->bvent), ld(L->bpvent), pv);
    const v2 xbt = smooth2(HYD_CB_Z(pld, pr, ld(L->bR), P[LSK_PI], ld(L->bpset)) * ld(L->binv_band));
    const v2 xb = ld_at(y, L->sc);
    st_at(ydot, L->sc, HYD_LAG_RATE(xbt, xb, ld(L->btau)));
    const v2 qcc = ramp2(ld(L->bccr), ld(L->binv_cw), ld(L->bcq), pv - pld);
    const v2 Ab = ld(L->bA) * open2(xb);
    const v2 qcr = orifice2(ld(L->bk), ld(L->binvP0), ld(L->bkl), Ab, _mm_sqrt_pd(Ab), pld - pv);
    const v2 qcb = HYD_CB_Q(qcc, qcr);

    // Damping orifices hose B -> pilot, hoses, leakage, volumes.
    const v2 qo = orifice2(ld(L->ok_), ld(L->oinvP0), ld(L->okl), ld(L->oA), ld(L->osA), P[LSK_HB] - P[LSK_PI]);
    const v2 qhA = HYD_HOSE_Q(ld(L->GA), P[LSK_HA], P[LSK_CV]);
    const v2 qhB = HYD_HOSE_Q(ld(L->GB), P[LSK_HB], P[LSK_CB]);
    const v2 leak = HYD_CYL_LEAK(ld(L->CL), P[LSK_CA], P[LSK_CB]);
    const v2 AA = ld(L->AA), AB = ld(L->AB);
    // max(a, b) is a > b ? a : b, the floor of hyd_cyl_volumes.
    const v2 VA = _mm_max_pd(HYD_CYL_VA(ld(L->VA0), AA, xs), ld(L->VAmin));
    const v2 VB = _mm_max_pd(HYD_CYL_VB(ld(L->VB0), AB, ld(L->stroke), xs), ld(L->VBmin));
    const v2 dVA = AA * vs, dVB = _mm_xor_pd(AB, sign) * vs; // node_dV: A_A x', -A_B x'

    // Net inflows, each in the loops' order (see the top of the file).
    v2 n[LSK_NSEC];
    n[LSK_P] = (S[LSK_P] - q1) + qc;
    n[LSK_LS] = (S[LSK_LS] + set2(fls[0], fls[1])) + f2;
    n[LSK_HA] = ((S[LSK_HA] - qhA) + inA) + f0;
    n[LSK_HB] = (((S[LSK_HB] - qo) - qhB) + inB) + f1;
    n[LSK_CV] = (S[LSK_CV] + qhA) - qcb;
    n[LSK_PI] = S[LSK_PI] + qo;
    n[LSK_CA] = (S[LSK_CA] + qcb) - leak;
    n[LSK_CB] = (S[LSK_CB] + qhB) + leak;
    double qcs[2];
    _mm_storeu_pd(qcs, qc);
    const double npl = ((spl + qpump) - qcs[0]) - qcs[1];
    const double nll = sll + fls[2];

    // Cylinders: force with no stop touched (both stop forces +0.0), less the
    // seal friction (hyd_cyl_seal's algebra in the lanes, exp and tanh lane
    // by lane; a cylinder without it subtracts +0.0 with dseal +0.0, as
    // hyd_cyl_seal returns).
    const v2 bv = ld(L->bv);
    v2 Fv = HYD_CYL_FORCE(AA, AB, bv, P[LSK_CA], P[LSK_CB], vs, z, z);
    v2 dseal = z;
    if (L->seal) {
        const v2 r = HYD_CYL_SEAL_R(vs, ld(L->vst)), arg = HYD_CYL_SEAL_ARG(vs, ld(L->vsm));
        double mr2[2], a[2], ex[2] = {0.0, 0.0}, th[2] = {0.0, 0.0};
        _mm_storeu_pd(mr2, _mm_xor_pd(r, sign) * r); // -r * r
        _mm_storeu_pd(a, arg);
        for (int l = 0; l < 2; ++l)
            if (L->seal_l[l]) ex[l] = exp(mr2[l]), th[l] = tanh(a[l]);
        const v2 e = ld(L->Fs) * ld(ex), thv = ld(th);
        const v2 mag = HYD_CYL_SEAL_MAG(ld(L->Fc), e);
        const v2 sm = ld(L->seal_m);
        Fv = Fv - _mm_and_pd(sm, HYD_CYL_SEAL_F(mag, thv));
        dseal = _mm_and_pd(sm, HYD_CYL_SEAL_DFDV(mag, thv, ld(L->vsm), r, ld(L->vst), e));
    }
    double F[2], dFv[2];
    _mm_storeu_pd(F, Fv);
    _mm_storeu_pd(dFv, _mm_xor_pd(bv, sign) - dseal); // -b_v - fv_lo - fv_hi - dseal
    for (int l = 0; l < 2; ++l) {
        const int ic = L->ci[l];
        d->cyl_F[ic] = F[l];
        d->dFdx[ic] = -0.0; // -fd_lo - fd_hi of two untouched stops
        d->dFdv[ic] = dFv[l];
        d->cyl_stop[ic] = 0;
    }

    // Node outputs and pressure rates.
    const int nnode = m->nnode;
    memcpy(d->node_V, m->node_V0, (size_t)nnode * sizeof(double));
    memset(d->node_dV, 0, (size_t)nnode * sizeof(double));
    for (int i = 0; i < m->ntank; ++i) d->node_p[m->tank_node[i]] = m->node_pfix[m->tank_node[i]];
    st_at(d->node_V, &L->node[2 * LSK_CA], VA);
    st_at(d->node_V, &L->node[2 * LSK_CB], VB);
    st_at(d->node_dV, &L->node[2 * LSK_CA], dVA);
    st_at(d->node_dV, &L->node[2 * LSK_CB], dVB);
    // Unrolled: the chamber cases and the slot offsets become constants.
#pragma GCC unroll 8
    for (int j = 0; j < LSK_NSEC; ++j) {
        v2 V = ld(&L->V0[2 * j]), net = n[j]; // x - (+0.0) is x: the fixed nodes' dV/dt is left out
        if (j == LSK_CA) V = VA, net = n[j] - dVA;
        if (j == LSK_CB) V = VB, net = n[j] - dVB;
        const v2 c = node_c2(m, &L->bel[2 * j], &L->bec[2 * j], P[j], V);
        const int* nd = &L->node[2 * j];
        st_at(ydot, &L->s[2 * j], c * net);
        st_at(d->node_q, nd, n[j]);
        st_at(d->node_be, nd, c * V);
        st_at(d->node_p, nd, P[j]);
    }
    const v2 Vsh = ld(&L->V0[LSK_PL]), nsh = set2(npl, nll);
    const v2 csh = node_c2(m, &L->bel[LSK_PL], &L->bec[LSK_PL], Psh, Vsh);
    st_at(ydot, &L->s[LSK_PL], csh * nsh);
    st_at(d->node_q, &L->node[LSK_PL], nsh);
    st_at(d->node_be, &L->node[LSK_PL], csh * Vsh);
    st_at(d->node_p, &L->node[LSK_PL], Psh);
    return 1;
}

static int ls_eval_sse2(const hyd_fast_ls* L, const hyd_model* m, hyd_data* d, const double* y, double* ydot) {
    return ls_eval(L, m, d, y, ydot);
}

#ifdef LSK_AVX
// The same text with AVX's three-operand (VEX) forms of the same 128-bit
// instructions: no register copies before each two-operand operation (about
// 280 per evaluation in the SSE2 form). The values do not change: a VEX
// addpd, mulpd, divpd, sqrtpd, minpd, maxpd rounds and orders as its SSE2
// form, and the "avx" target has no FMA (and -ffp-contract=off forbids
// contraction anyway); test_ls_lanes runs both forms.
__attribute__((target("avx"))) static int ls_eval_avx(const hyd_fast_ls* L, const hyd_model* m, hyd_data* d,
                                                       const double* y, double* ydot) {
    return ls_eval(L, m, d, y, ydot);
}
#endif

int hyd_fast_ls_eval(const hyd_fast_ls* L, const hyd_model* m, hyd_data* d, const double* y, double* ydot) {
#ifdef LSK_AVX
    if (L->avx) return ls_eval_avx(L, m, d, y, ydot);
#endif
    return ls_eval_sse2(L, m, d, y, ydot);
}

void hyd_fast_ls_avx(hyd_fast_ls* L, int on) {
#ifdef LSK_AVX
    L->avx = on && __builtin_cpu_supports("avx");
#else
    (void)on;
    L->avx = 0;
#endif
}
#else
int hyd_fast_ls_eval(const hyd_fast_ls* L, const hyd_model* m, hyd_data* d, const double* y, double* ydot) {
    (void)L, (void)m, (void)d, (void)y, (void)ydot;
    return 0;
}
void hyd_fast_ls_avx(hyd_fast_ls* L, int on) {
    (void)on;
    L->avx = 0;
}
#endif
