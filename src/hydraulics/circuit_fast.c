// circuit_fast.c: the fast kernel for any circuit (see circuit_fast.h).
//
// One evaluation, in this order:
//   1. node pressures from y; fixed volumes; net inflows zeroed
//   2. components without a fast loop: their reference loop, whose per-port
//      flow slots (and dense partials G) are then added to their nodes
//   3. cylinders: chamber volumes and their rates (they set V for step 4)
//   4. per pressure node c = Be(p)/V, and with the Jacobian dBe/dp
//   5. type by type, every flow added to its nodes' net inflow, every
//      partial to J scaled by its row's c
//   6. per pressure node ydot = c (net - dV/dt), and the diagonal term
//      dBe/dp / V (net - dV/dt)
#include "circuit_fast.h"
#include "circuit_fast_ls.h"

#include "hyd_accumulator.h"
#include "hyd_compensator.h"
#include "hyd_counterbalance.h"
#include "hyd_cylinder.h"
#include "hyd_hose.h"
#include "hyd_internal.h"
#include "hyd_ls_pump.h"
#include "hyd_orifice.h"
#include "hyd_pump.h"
#include "hyd_shuttle.h"
#include "hyd_ramp.h"
#include "hyd_valve.h"

#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__)
#define FAST_INLINE static inline __attribute__((always_inline))
#else
#define FAST_INLINE static inline
#endif

struct hyd_fast {
    const hyd_model* m;
    unsigned rev;        ///< model revision the record copies were taken at
    unsigned types;      ///< types with a fast loop here
    int fallback;
    void* rec[HYD_TYPE_COUNT]; ///< records the fast loops take, per type
    int nrec[HYD_TYPE_COUNT];
    void* fb[HYD_TYPE_COUNT];  ///< records left to the reference loops, per type
    int nfb[HYD_TYPE_COUNT];
    int* fb_comp;        ///< components of fb[], for gathering their flow slots
    int nfb_comp;
    double* c;           ///< (nnode) Be/V [Pa/m^3], 0 for tanks
    double* dbe;         ///< (nnode) dBe/dp [-]
    double* net;         ///< (nnode) net inflow [m^3/s]
    double* f;           ///< (nstate) rates when the Jacobian's caller wants none
    int* smap;           ///< (nstate) circuit state i lives at y[smap[i]] (hyd_fast_map)
    int* ns;             ///< (nnode) a node's state in the caller's order, -1 for a tank
    int perm;            ///< smap is a permutation of 0..nstate-1 (the circuit's columns of J are 0..nstate-1)
    /// (nvol) the pressure nodes in vol_node order with their state and modulus
    /// constants side by side: the plain evaluation's node loops read one record.
    struct fast_node {
        int node, s;
        double bel, bec; ///< liquid modulus, air weight [Pa] (hyd_model node_bel, node_bec)
    } * pn;
    /// The load-sensing crane layout in one pass (circuit_fast_ls.c), when
    /// recognised and not switched off (hyd_fast_lanes); nls counts the
    /// evaluations it took.
    hyd_fast_ls ls;
    int lanes;
    unsigned long nls;
};

unsigned hyd_fast_types(void) {
    return 1u << HYD_PUMP | 1u << HYD_RELIEF | 1u << HYD_CHECK | 1u << HYD_ORIFICE |
           1u << HYD_HOSE | 1u << HYD_VALVE | 1u << HYD_CYLINDER | 1u << HYD_LS_PUMP |
           1u << HYD_SHUTTLE | 1u << HYD_COMPENSATOR | 1u << HYD_COUNTERBALANCE | 1u << HYD_ACCUMULATOR;
}

// The copies of the model's records, sorted into fast and fallback (again
// after a parameter change, which rewrites the model's records).
static void take_records(hyd_fast* k) {
    const hyd_model* m = k->m;
    int nr[HYD_TYPE_COUNT] = {0}, nf[HYD_TYPE_COUNT] = {0};
    k->nfb_comp = 0;
    for (int c = 0; c < m->ncomp; ++c) {
        const hyd_type t = m->comp[c].type;
        const hyd_component* d = hyd_component_of(t);
        const void* src = (const char*)m->rec[t] + (size_t)m->comp_sub[c] * d->rec_size;
        if (k->types >> t & 1u) {
            memcpy((char*)k->rec[t] + (size_t)nr[t]++ * d->rec_size, src, d->rec_size);
        } else {
            memcpy((char*)k->fb[t] + (size_t)nf[t]++ * d->rec_size, src, d->rec_size);
            k->fb_comp[k->nfb_comp++] = c;
        }
    }
    // The copies' own state indices in the caller's order (the model's
    // records, which the reference hooks read, stay in circuit order).
    hyd_valve_c* va = k->rec[HYD_VALVE];
    for (int i = 0; i < k->nrec[HYD_VALVE]; ++i) va[i].adr = k->smap[va[i].adr];
    hyd_ls_pump_c* lp = k->rec[HYD_LS_PUMP];
    for (int i = 0; i < k->nrec[HYD_LS_PUMP]; ++i) lp[i].adr = k->smap[lp[i].adr];
    hyd_cb_c* cb = k->rec[HYD_COUNTERBALANCE];
    for (int i = 0; i < k->nrec[HYD_COUNTERBALANCE]; ++i) cb[i].adr = k->smap[cb[i].adr];
    hyd_comp_c* co = k->rec[HYD_COMPENSATOR];
    for (int i = 0; i < k->nrec[HYD_COMPENSATOR]; ++i) co[i].adr = k->smap[co[i].adr];
    hyd_acc_c* ac = k->rec[HYD_ACCUMULATOR];
    for (int i = 0; i < k->nrec[HYD_ACCUMULATOR]; ++i) ac[i].adr = k->smap[ac[i].adr];
    for (int i = 0; i < m->nvol; ++i) {
        const int node = m->vol_node[i];
        k->pn[i].node = node;
        k->pn[i].s = k->ns[node];
        k->pn[i].bel = m->node_bel[node];
        k->pn[i].bec = m->node_bec[node];
    }
    hyd_shuttle_c* sh = k->rec[HYD_SHUTTLE];
    for (int i = 0; i < k->nrec[HYD_SHUTTLE]; ++i)
        if (sh[i].su >= 0) sh[i].su = k->smap[sh[i].su]; // spool mode: the valve's spool
    if (k->nfb_comp) {
        memset(&k->ls, 0, sizeof k->ls);
        snprintf(k->ls.why, sizeof k->ls.why, "%d components fall back to their reference loops",
                 k->nfb_comp);
    } else {
        hyd_fast_ls_pack(m, k->smap, k->ns, &k->ls);
    }
    if (k->lanes == 2) hyd_fast_ls_avx(&k->ls, 0);
    k->rev = m->revision;
}

void hyd_fast_free(hyd_fast* k) {
    if (!k)
        return;
    for (int t = 0; t < HYD_TYPE_COUNT; ++t) {
        free(k->rec[t]);
        free(k->fb[t]);
    }
    free(k->fb_comp);
    free(k->c);
    free(k->dbe);
    free(k->net);
    free(k->f);
    free(k->smap);
    free(k->ns);
    free(k->pn);
    free(k);
}

hyd_fast* hyd_fast_create(const hyd_model* m, unsigned types, int fallback, char* why, size_t whysz) {
    types &= hyd_fast_types();
    for (int c = 0; c < m->ncomp && !fallback; ++c)
        if (!(types >> m->comp[c].type & 1u)) {
            if (why && whysz)
                snprintf(why, whysz, "component '%s' (%s): the fast kernel has no loop for this type",
                         m->comp[c].name, hyd_type_name(m->comp[c].type));
            return NULL;
        }
    hyd_fast* k = calloc(1, sizeof *k);
    int ok = k != NULL;
    if (ok) {
        k->m = m;
        k->types = types;
        k->fallback = fallback;
        for (int t = 0; t < HYD_TYPE_COUNT && ok; ++t) {
            const hyd_component* d = hyd_component_of((hyd_type)t);
            if (!d || !d->rec_size)
                continue;
            const size_t n = (size_t)(m->nrec[t] > 0 ? m->nrec[t] : 1);
            if (types >> t & 1u) {
                k->nrec[t] = m->nrec[t];
                ok = (k->rec[t] = calloc(n, d->rec_size)) != NULL;
            } else {
                k->nfb[t] = m->nrec[t];
                ok = (k->fb[t] = calloc(n, d->rec_size)) != NULL;
            }
        }
        ok = ok && HYD_ALLOC(k->fb_comp, m->ncomp) && HYD_ALLOC(k->c, m->nnode) &&
             HYD_ALLOC(k->dbe, m->nnode) && HYD_ALLOC(k->net, m->nnode) && HYD_ALLOC(k->f, m->nstate) &&
             HYD_ALLOC(k->smap, m->nstate) && HYD_ALLOC(k->ns, m->nnode) &&
             HYD_ALLOC(k->pn, m->nvol > 0 ? m->nvol : 1);
    }
    if (!ok) {
        hyd_fast_free(k);
        if (why && whysz)
            snprintf(why, whysz, "out of memory");
        return NULL;
    }
    for (int i = 0; i < m->nstate; ++i) k->smap[i] = i;
    k->perm = 1;
    k->lanes = 1;
    memcpy(k->ns, m->node_state, (size_t)m->nnode * sizeof *k->ns);
    take_records(k);
    return k;
}

int hyd_fast_map(hyd_fast* k, const int* map) {
    const hyd_model* m = k->m;
    if (k->nfb_comp) return -1; // the reference loops work in circuit order
    for (int i = 0; i < m->nstate; ++i) k->smap[i] = map ? map[i] : i;
    // A permutation of 0..n-1 (the lagrange crane's: its circuit states come
    // first) lets the Jacobian clear each row's n circuit columns in one
    // memset instead of n scattered stores.
    k->perm = 1;
    for (int i = 0; i < m->nstate && k->perm; ++i) {
        int seen = 0;
        for (int j = 0; j < m->nstate; ++j) seen += k->smap[j] == i;
        k->perm = seen == 1;
    }
    for (int i = 0; i < m->nnode; ++i)
        k->ns[i] = m->node_state[i] >= 0 ? k->smap[m->node_state[i]] : -1;
    take_records(k);
    return 0;
}

int hyd_fast_nfallback(const hyd_fast* k) { return k->nfb_comp; }

// A flow q from node a to node b with partials ga = dq/dp_a, gb = dq/dp_b:
// net inflows, and (J non-NULL) the Jacobian rows of both nodes scaled by
// their c. Tanks have no row and no column.
FAST_INLINE void flow(const hyd_fast* k, double* J, int ldj, int a, int b, double q, double ga,
                      double gb) {
    k->net[a] -= q;
    k->net[b] += q;
    if (J) {
        const int* ns = k->ns;
        const int sa = ns[a], sb = ns[b];
        if (sa >= 0) {
            double* r = J + (size_t)sa * ldj;
            r[sa] -= k->c[a] * ga;
            if (sb >= 0) r[sb] -= k->c[a] * gb;
        }
        if (sb >= 0) {
            double* r = J + (size_t)sb * ldj;
            r[sb] += k->c[b] * gb;
            if (sa >= 0) r[sa] += k->c[b] * ga;
        }
    }
}

// J[row of node a][col] += c_a g (nothing for a tank).
FAST_INLINE void jcol(const hyd_fast* k, double* J, int ldj, int a, int col, double g) {
    const int sa = k->ns[a];
    if (sa >= 0) J[(size_t)sa * ldj + col] += k->c[a] * g;
}

// J[row of node a][state of node b] += c_a g (nothing when either is a tank).
FAST_INLINE void jent(const hyd_fast* k, double* J, int ldj, int a, int b, double g) {
    const int sa = k->ns[a], sb = k->ns[b];
    if (sa >= 0 && sb >= 0) J[(size_t)sa * ldj + sb] += k->c[a] * g;
}

// A component state's own row (unscaled: its rate is no pressure rate):
// J[row][state of node b] += g (nothing for a tank).
FAST_INLINE void jrow(const hyd_fast* k, double* row, int b, double g) {
    const int sb = k->ns[b];
    if (sb >= 0) row[sb] += g;
}

#if defined(__SSE2__) && defined(__GNUC__)
#include <emmintrin.h>
#define FAST_LANES 1
typedef __m128d fast_v2;

// Be / V of two pressure nodes on the table path (hyd_node_c through
// hyd_be_nd and hyd_air_ratio), node i in lane i. The law is the header's
// macros (HYD_AIR_POLY, HYD_BE_N, HYD_BE_D, HYD_BE_C) expanded on __m128d:
// each lane runs the scalar operations in the same order (IEEE + - * / round
// the same in a lane; -ffp-contract=off keeps them unfused), so the values
// are bit for bit hyd_node_c's. Only the table entries are gathered lane by
// lane. The caller has checked both P are on the table path.
FAST_INLINE fast_v2 node_c2(const hyd_model* m, double P0, double P1, double bel0, double bel1,
                            double bec0, double bec1, double V0, double V1) {
    const hyd_air_tab* t = &m->air;
    const double P[2] = {P0, P1};
    const double* c[2];
    double oct[2], mant[2];
    for (int l = 0; l < 2; ++l) {
        uint64_t b;
        memcpy(&b, &P[l], sizeof b);
        int e, j;
        hyd_air_index(b, &e, &j);
        c[l] = t->seg[j];
        oct[l] = t->oct[e];
        const uint64_t mb = (b & HYD_AIR_MANT_MASK) | HYD_AIR_ONE_BITS;
        memcpy(&mant[l], &mb, sizeof mant[l]);
    }
    const fast_v2 Pv = _mm_set_pd(P1, P0);
#define CO(i) _mm_set_pd(c[1][i], c[0][i])
    const fast_v2 x = _mm_set_pd(mant[1], mant[0]) - CO(HYD_AIR_DEG + 1);
    const fast_v2 x2 = x * x;
    const fast_v2 poly = HYD_AIR_POLY(CO, x, x2);
#undef CO
    const fast_v2 rr = _mm_set_pd(oct[1], oct[0]) * poly;
    const fast_v2 N = HYD_BE_N(_mm_set_pd(bel1, bel0), m->be_alpha, rr, Pv);
    const fast_v2 D = HYD_BE_D(_mm_set_pd(bec1, bec0), rr, Pv);
    return HYD_BE_C(N, D, _mm_set_pd(V1, V0));
}
#endif

FAST_INLINE void run(hyd_fast* k, hyd_data* d, const double* y, double* ydot, double* J, int ldj) {
    const hyd_model* m = k->m;
    if (k->rev != m->revision)
        take_records(k);
    const int nnode = m->nnode;
    double* p = d->node_p;
    for (int i = 0; i < m->ntank; ++i) p[m->tank_node[i]] = m->node_pfix[m->tank_node[i]];
    const struct fast_node* pn = k->pn;
    for (int i = 0; i < m->nvol; ++i) p[pn[i].node] = y[pn[i].s];
    memcpy(d->node_V, m->node_V0, (size_t)nnode * sizeof(double));
    memset(d->node_dV, 0, (size_t)nnode * sizeof(double));
    memset(k->net, 0, (size_t)nnode * sizeof(double));
    const int n = m->nstate;
    if (J) {
        for (int i = 0; i < n; ++i) {
            double* r = J + (size_t)k->smap[i] * ldj;
            if (k->perm)
                memset(r, 0, (size_t)n * sizeof *J);
            else
                for (int j = 0; j < n; ++j) r[k->smap[j]] = 0.0;
        }
    }

    // 2. Reference loops for the components without a fast loop.
    double* G = NULL;
    if (k->nfb_comp) {
        if (J) {
            G = d->scratch_;
            memset(G, 0, (size_t)(n + 1) * (size_t)(n + 1) * sizeof *G);
        }
        for (int t = 0; t < HYD_TYPE_COUNT; ++t) {
            const hyd_component* c = hyd_component_of((hyd_type)t);
            if (c && c->eval && k->nfb[t])
                c->eval(m, d, k->fb[t], k->nfb[t], y, ydot, G, NULL);
        }
        for (int i = 0; i < k->nfb_comp; ++i) {
            const int c = k->fb_comp[i];
            for (int j = 0; j < HYD_MAXSLOT; ++j) {
                const int node = m->comp_slot[HYD_MAXSLOT * c + j];
                if (node >= 0) k->net[node] += d->flow_[HYD_MAXSLOT * c + j];
            }
        }
    }

    // 3. Cylinders: volumes, volume rates, force.
    const hyd_cyl_c* cyl = k->rec[HYD_CYLINDER];
    for (int i = 0; i < k->nrec[HYD_CYLINDER]; ++i) {
        const hyd_cyl_c* c = &cyl[i];
        const int ic = m->comp_sub[c->comp];
        const double x = d->cyl_x[ic], v = d->cyl_v[ic];
        double VA, VB, dVA, dVB;
        hyd_cyl_volumes(c->VA0, c->VB0, c->AA, c->AB, c->s, x, &VA, &VB, &dVA, &dVB);
        d->node_V[c->nA] = VA;
        d->node_V[c->nB] = VB;
        d->node_dV[c->nA] = c->AA * v;
        d->node_dV[c->nB] = -c->AB * v;
        d->cyl_F[ic] = hyd_cyl_force(c->AA, c->AB, c->bv, c->ks, c->cs, c->ws, c->s,
                                     p[c->nA], p[c->nB], x, v, &d->dFdx[ic], &d->dFdv[ic]);
        double dseal;
        d->cyl_F[ic] -= hyd_cyl_seal(c->Fc, c->Fs, c->vst, c->vsm, v, &dseal);
        d->dFdv[ic] -= dseal;
        d->cyl_stop[ic] = (x > c->s) - (x < 0.0);
    }

    // 4. Be/V per pressure node, before the flows when their partials are
    // scaled by it (the plain evaluation takes it in step 6).
    for (int kk = 0; kk < m->nvol && J; ++kk) {
        const int node = m->vol_node[kk];
        double be;
        k->c[node] = hyd_node_c(m, m->node_bel[node], m->node_bec[node], p[node], d->node_V[node],
                                &be, J ? &k->dbe[node] : NULL);
        d->node_be[node] = be;
    }

    // 5. Flows, type by type.
    const hyd_pump_c* pu = k->rec[HYD_PUMP];
    for (int i = 0; i < k->nrec[HYD_PUMP]; ++i) {
        double g, t;
        const double q = hyd_pump_q(pu[i].qmax, pu[i].pset, pu[i].inv_band,
                                    p[pu[i].out] - p[pu[i].in], &g, &t);
        flow(k, J, ldj, pu[i].in, pu[i].out, q, -g, g);
    }
    for (int pass = 0; pass < 2; ++pass) {
        const hyd_type t = pass ? HYD_CHECK : HYD_RELIEF;
        const hyd_ramp_c* r = k->rec[t];
        for (int i = 0; i < k->nrec[t]; ++i) {
            double g, tt;
            const double q = hyd_ramp_q(r[i].pcr, r[i].inv_w, r[i].qr, p[r[i].in] - p[r[i].out], &g, &tt);
            if (tt <= 0.0) continue; // closed: no flow, no partial
            flow(k, J, ldj, r[i].in, r[i].out, q, g, -g);
        }
    }
    const hyd_orifice_c* o = k->rec[HYD_ORIFICE];
    for (int i = 0; i < k->nrec[HYD_ORIFICE]; ++i) {
        double g, gA;
        const double q = hyd_orifice_q(&o[i].ok, o[i].A, p[o[i].in] - p[o[i].out], &g, &gA);
        flow(k, J, ldj, o[i].in, o[i].out, q, g, -g);
    }
    const hyd_hose_c* h = k->rec[HYD_HOSE];
    for (int i = 0; i < k->nrec[HYD_HOSE]; ++i) {
        const double q = hyd_hose_q(h[i].G, p[h[i].node], p[h[i].to]);
        flow(k, J, ldj, h[i].node, h[i].to, q, h[i].G, -h[i].G);
    }
    const hyd_valve_c* va = k->rec[HYD_VALVE];
    for (int i = 0; i < k->nrec[HYD_VALVE]; ++i) {
        const hyd_valve_c* c = &va[i];
        const double u = y[c->adr];
        ydot[c->adr] = hyd_spool_rate(d->valve_cmd[m->comp_sub[c->comp]], u, c->inv_tau);
        hyd_valve_flow e;
        hyd_valve_edges(&c->ok, c->Amax, u, p[c->P], p[c->T], p[c->A], p[c->B], &e);
        const int feed = e.pos ? c->A : c->B, drain = e.pos ? c->B : c->A;
        flow(k, J, ldj, c->P, feed, e.q1, e.g1, -e.g1);
        flow(k, J, ldj, drain, c->T, e.q2, e.g2, -e.g2);
        if (J) {
            // Spool column: dq/du = dq/dA A_max sign(u); the spool row is a lag.
            const double sgn = e.pos ? 1.0 : -1.0;
            const double du1 = e.g1A * c->Amax * sgn, du2 = e.g2A * c->Amax * sgn;
            jcol(k, J, ldj, c->P, c->adr, -du1);
            jcol(k, J, ldj, feed, c->adr, du1);
            jcol(k, J, ldj, drain, c->adr, -du2);
            jcol(k, J, ldj, c->T, c->adr, du2);
            J[(size_t)c->adr * ldj + c->adr] = -c->inv_tau;
        }
    }
    // Load-sensing components (their laws: hyd_ls_pump.h, hyd_shuttle.h,
    // hyd_compensator.h, hyd_counterbalance.h, hyd_accumulator.h).
    const hyd_ls_pump_c* lp = k->rec[HYD_LS_PUMP];
    for (int i = 0; i < k->nrec[HYD_LS_PUMP]; ++i) {
        const hyd_ls_pump_c* c = &lp[i];
        double a1, a2;
        const double target = hyd_ls_pump_target(c, p[c->in], p[c->out], p[c->ls], &a1, &a2);
        const double eps = y[c->adr];
        ydot[c->adr] = HYD_LS_PUMP_RATE(target, eps, c->inv_tau);
        const double q = HYD_LS_PUMP_Q(eps, c->qmax, c->cleak, p[c->out], p[c->in]);
        flow(k, J, ldj, c->in, c->out, q, c->cleak, -c->cleak); // the leak's pressure partials
        if (J) {
            jcol(k, J, ldj, c->in, c->adr, -c->qmax);
            jcol(k, J, ldj, c->out, c->adr, c->qmax);
            double* row = J + (size_t)c->adr * ldj; // displacement row
            jrow(k, row, c->out, (a1 + a2) * c->inv_tau);
            jrow(k, row, c->ls, -a1 * c->inv_tau);
            jrow(k, row, c->in, -a2 * c->inv_tau);
            row[c->adr] -= c->inv_tau;
        }
    }
    const hyd_shuttle_c* sh = k->rec[HYD_SHUTTLE];
    for (int i = 0; i < k->nrec[HYD_SHUTTLE]; ++i) {
        const hyd_shuttle_c* c = &sh[i];
        const int spool = c->su >= 0;
        const double u = spool ? y[c->su] : 0.0, pt = spool ? p[c->t] : 0.0;
        const int ns = spool ? 4 : 3;
        const int node[4] = {c->a, c->b, c->out, c->t};
        if (!J) { // the flows alone
            double f[4];
            hyd_shuttle_flows(c, u, p[c->a], p[c->b], p[c->out], pt, f);
            for (int r = 0; r < ns; ++r) k->net[node[r]] += f[r];
            continue;
        }
        hyd_shuttle_flow e;
        hyd_shuttle_law(c, u, p[c->a], p[c->b], p[c->out], pt, &e);
        for (int r = 0; r < ns; ++r) k->net[node[r]] += e.f[r];
        for (int r = 0; r < ns; ++r) {
            for (int j = 0; j < ns; ++j) jent(k, J, ldj, node[r], node[j], e.g[r][j]);
            if (spool) jcol(k, J, ldj, node[r], c->su, e.du[r]);
        }
    }
    const hyd_comp_c* co = k->rec[HYD_COMPENSATOR];
    for (int i = 0; i < k->nrec[HYD_COMPENSATOR]; ++i) {
        const hyd_comp_c* c = &co[i];
        hyd_comp_flow e;
        hyd_compensator_law(c, y[c->adr], p[c->in], p[c->out], p[c->load], p[c->ref], &e);
        ydot[c->adr] = e.xdot;
        flow(k, J, ldj, c->in, c->out, e.q, e.dq[0], e.dq[1]);
        if (J) {
            jcol(k, J, ldj, c->in, c->adr, -e.dqx);
            jcol(k, J, ldj, c->out, c->adr, e.dqx);
            const int node[4] = {c->in, c->out, c->load, c->ref};
            double* row = J + (size_t)c->adr * ldj; // spool row
            for (int j = 0; j < 4; ++j) jrow(k, row, node[j], e.dxd[j]);
            row[c->adr] -= c->inv_tau;
        }
    }
    const hyd_cb_c* cb = k->rec[HYD_COUNTERBALANCE];
    for (int i = 0; i < k->nrec[HYD_COUNTERBALANCE]; ++i) {
        const hyd_cb_c* c = &cb[i];
        hyd_cb_flow e;
        hyd_cb_law(c, y[c->adr], p[c->v], p[c->l], p[c->p], &e);
        ydot[c->adr] = e.xdot;
        flow(k, J, ldj, c->v, c->l, e.q, e.dqv, -e.dqv);
        if (J) {
            jcol(k, J, ldj, c->v, c->adr, -e.dqx);
            jcol(k, J, ldj, c->l, c->adr, e.dqx);
            double* row = J + (size_t)c->adr * ldj; // spool row
            jrow(k, row, c->l, e.k);
            jrow(k, row, c->v, e.kv);
            jrow(k, row, c->p, e.k * c->R);
            row[c->adr] -= c->inv_tau;
        }
    }
    const hyd_acc_c* ac = k->rec[HYD_ACCUMULATOR];
    for (int i = 0; i < k->nrec[HYD_ACCUMULATOR]; ++i) {
        const hyd_acc_c* c = &ac[i];
        double dpg;
        const double pg = hyd_acc_pgas(c, y[c->adr], &dpg);
        const double q = c->G * (p[c->node] - pg); // into the accumulator
        ydot[c->adr] = q;
        k->net[c->node] -= q;
        if (J) {
            jent(k, J, ldj, c->node, c->node, -c->G);
            jcol(k, J, ldj, c->node, c->adr, c->G * dpg);
            double* row = J + (size_t)c->adr * ldj; // oil volume row
            jrow(k, row, c->node, c->G);
            row[c->adr] -= c->G * dpg;
        }
    }
    for (int i = 0; i < k->nrec[HYD_CYLINDER]; ++i) {
        const hyd_cyl_c* c = &cyl[i];
        const double q = hyd_cyl_leak(c->CL, p[c->nA], p[c->nB]);
        flow(k, J, ldj, c->nA, c->nB, q, c->CL, -c->CL);
    }

    // 6. Pressure rates.
    int kk0 = 0;
#ifdef FAST_LANES
    // The plain evaluation's Be / V two nodes at a time (the Jacobian took
    // c in step 4). A pair with either pressure off the table path goes
    // node by node below, in order, so the result does not depend on the
    // pairing.
    if (!J && m->air.use) {
        for (; kk0 + 1 < m->nvol; kk0 += 2) {
            const struct fast_node* a = &pn[kk0];
            const struct fast_node* b = a + 1;
            const int n0 = a->node, n1 = b->node;
            const double P0 = y[a->s], P1 = y[b->s];
            // Both on the table path (as hyd_be_nd: false for NaN).
            const fast_v2 Pv = _mm_set_pd(P1, P0);
            if (_mm_movemask_pd(_mm_and_pd(_mm_cmpge_pd(Pv, _mm_set1_pd(HYD_BE_P_LO)),
                                           _mm_cmplt_pd(Pv, _mm_set1_pd(HYD_BE_P_HI)))) != 3)
                break;
            const double V0 = d->node_V[n0], V1 = d->node_V[n1];
            const fast_v2 c2 = node_c2(m, P0, P1, a->bel, b->bel, a->bec, b->bec, V0, V1);
            double c[2];
            _mm_storeu_pd(c, c2);
            const double q0 = k->net[n0], q1 = k->net[n1];
            d->node_be[n0] = c[0] * V0;
            d->node_be[n1] = c[1] * V1;
            d->node_q[n0] = q0;
            d->node_q[n1] = q1;
            ydot[a->s] = c[0] * (q0 - d->node_dV[n0]);
            ydot[b->s] = c[1] * (q1 - d->node_dV[n1]);
        }
    }
#endif
    for (int kk = kk0; kk < m->nvol; ++kk) {
        const int node = m->vol_node[kk];
        const int s = k->ns[node];
        d->node_q[node] = k->net[node];
        const double net = k->net[node] - d->node_dV[node];
        if (J) {
            ydot[s] = k->c[node] * net;
            J[(size_t)s * ldj + s] += k->dbe[node] / d->node_V[node] * net;
        } else {
            double be;
            const double c = hyd_node_c(m, m->node_bel[node], m->node_bec[node], p[node],
                                        d->node_V[node], &be, NULL);
            d->node_be[node] = be;
            ydot[s] = c * net;
        }
    }
    if (G) {
        // The fallback components' partials, scaled by their rows' c.
        const int ldg = n + 1;
        for (int kk = 0; kk < m->nvol; ++kk) {
            const int node = m->vol_node[kk];
            const int s = m->node_state[node];
            const double* g = G + (size_t)s * ldg;
            double* r = J + (size_t)s * ldj;
            for (int j = 0; j < n; ++j) r[j] += k->c[node] * g[j];
        }
        for (int t = 0; t < HYD_TYPE_COUNT; ++t) {
            const hyd_component* c = hyd_component_of((hyd_type)t);
            if (c && c->jacobian && k->nfb[t] && t != HYD_CYLINDER)
                c->jacobian(m, d, k->fb[t], k->nfb[t], J, ldj);
        }
    }
}

// The plain evaluation by the loops, out of line: inlined into
// hyd_fast_eval its prologue (the loops' registers and stack) ran before the
// one-pass path could return, about 30 instructions per evaluation.
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static void eval_loops(hyd_fast* k, hyd_data* d, const double* y, double* ydot) {
    run(k, d, y, ydot, NULL, 0);
}

void hyd_fast_eval(hyd_fast* k, hyd_data* d, const double* y, double* ydot) {
    if (k->rev != k->m->revision) take_records(k);
    if (k->ls.ok && k->lanes && hyd_fast_ls_eval(&k->ls, k->m, d, y, ydot)) {
        ++k->nls;
        return;
    }
    eval_loops(k, d, y, ydot);
}

int hyd_fast_lanes(hyd_fast* k, int on) {
    if (on >= 0) {
        k->lanes = on == 2 ? 2 : on != 0;
        if (k->ls.ok) hyd_fast_ls_avx(&k->ls, on != 2);
    }
    return k->ls.ok;
}

unsigned long hyd_fast_lanes_count(const hyd_fast* k) { return k->nls; }

const char* hyd_fast_lanes_why(const hyd_fast* k) { return k->ls.ok ? "" : k->ls.why; }

void hyd_fast_jacobian(hyd_fast* k, hyd_data* d, const double* y, double* ydot, double* J, int ldj) {
    const hyd_model* m = k->m;
    const int n = m->nstate;
    run(k, d, y, ydot ? ydot : k->f, J, ldj);
    const size_t cb = (size_t)m->ncyl * (size_t)n * sizeof(double);
    memset(d->dydx, 0, cb);
    memset(d->dydv, 0, cb);
    memset(d->dFdy, 0, cb);
    // Coupling partials from the cylinder's own hook, on the outputs above.
    const hyd_component* cy = hyd_component_of(HYD_CYLINDER);
    if (m->ncyl) cy->jacobian(m, d, m->cyl, m->ncyl, NULL, 0);
}
