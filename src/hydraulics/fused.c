// fused.c: the standard actuator circuit in one pass (see hyd_fused.h).
//
// Every law here is the component's own: hyd_orifice_q (orifice.c),
// hyd_open_ramp_t (relief.c), hyd_stop_force (cylinder.c), hyd_be_nd /
// hyd_be_slow (fluid.c), the pump's smoothstep (pump.c). What changes is the
// bookkeeping: flows stay in registers and each node's net inflow is summed
// where it is known, instead of through per-port slots and a CSR gather.
// Summation order differs from volume.c, so results agree to rounding.
#include "hyd_fused.h"

#include "hyd_internal.h"

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
}

// The hose whose own node is `node`, or -1.
static int hose_at(const hyd_model* m, int node) {
    for (int i = 0; i < m->nhose; ++i)
        if (m->hose[i].node == node) return i;
    return -1;
}

int hyd_fused_build(const hyd_model* m, const int* valve, const int* cyl, int nact, hyd_fused* f,
                    char* why, size_t whysz) {
    memset(f, 0, sizeof *f);
    f->m = m;
    f->nact = nact;
    f->nstate = m->nstate;
    if (nact < 1 || nact > HYD_FUSED_MAXACT) return set_why(why, whysz, "too many actuators"), -1;
    if (m->norifice) return set_why(why, whysz, "the circuit has fixed orifices"), -1;
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
        a->valve = valve[k];
        a->cyl = cyl[k];
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
        const int nodes[4] = {v->A, v->B, c->nA, c->nB};
        hyd_fused_node* recs[4] = {&a->hA, &a->hB, &a->cA, &a->cB};
        for (int j = 0; j < 4; ++j) {
            if (at[nodes[j]]) return set_why(why, whysz, "two actuators share a node"), -1;
            pack_node(m, nodes[j], recs[j]);
            at[nodes[j]] = recs[j];
        }
    }
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
        const double t = (d - r->pcr) * r->inv_w;
        if (t <= 0.0) continue;
        double dr;
        const double o = r->qr * hyd_open_ramp_t(t, r->inv_w, &dr);
        q += r->into ? o : -o;
        gs -= r->qr * dr;
    }
    *g = gs;
    return q;
}

// Be(p) / V with the model's kernel (volume.c does the same).
FUSED_INLINE double node_c(const hyd_model* m, const hyd_fused_node* n, double p, double V) {
    double N, D, r;
    if (hyd_be_nd(m, n->bel, n->bec, p, &N, &D, &r)) return N / (D * V);
    return hyd_be_slow(m, n->bel, p, NULL) / V;
}

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
    double fdl, fvl, fdh, fvh;   ///< end-stop partials
} act_out;

FUSED_INLINE void actuator(const hyd_fused_act* a, const double* y, double pPL, double x, double v,
                            double cmd, double* ydot_u, act_out* o, int partials) {
    const double u = y[a->su];
    const double c = cmd > 1.0 ? 1.0 : (cmd < -1.0 ? -1.0 : cmd);
    *ydot_u = (c - u) * a->inv_tau;
    const double phA = y[a->hA.s], phB = y[a->hB.s], pA = y[a->cA.s], pB = y[a->cB.s];

    // Valve (valve.c): edge 1 feeds a work port from P, edge 2 drains the other to T.
    const int pos = u >= 0.0;
    const double A = a->Amax * fabs(u);
    const hyd_orif_k ok = {a->ok, 0.0, a->oinvP0, a->okl};
    double g1, g1A, g2, g2A;
    const double q1 = hyd_orifice_q(&ok, A, pPL - (pos ? phA : phB), &g1, &g1A);
    const double q2 = hyd_orifice_q(&ok, A, (pos ? phB : phA) - a->pT, &g2, &g2A);
    o->q_pl = q1;
    const double inA = pos ? q1 : -q2, inB = pos ? -q2 : q1;

    // Hoses (hose.c), leakage and volumes (cylinder.c).
    const double qhA = a->GA * (phA - pA), qhB = a->GB * (phB - pB);
    const double leak = a->CL * (pA - pB);
    const double VA = a->VA0 + a->AA * x, VB = a->VB0 + a->AB * (a->s - x);
    const double VAmin = HYD_VMIN_FRAC * a->VA0, VBmin = HYD_VMIN_FRAC * a->VB0;
    o->VA = VA > VAmin ? VA : VAmin;
    o->VB = VB > VBmin ? VB : VBmin;

    double gA, gB, ghA, ghB;
    o->nhA = inA - qhA + ramps_in(&a->hA, phA, &ghA);
    o->nhB = inB - qhB + ramps_in(&a->hB, phB, &ghB);
    o->nA = qhA - leak + ramps_in(&a->cA, pA, &gA) - a->AA * v;
    o->nB = qhB + leak + ramps_in(&a->cB, pB, &gB) + a->AB * v;

    // Force with the end stops (cylinder.c).
    const hyd_cyl_c cc = {.s = a->s, .ks = a->ks, .cs = a->cs, .ws = a->ws};
    double fdl, fvl, fdh, fvh;
    const double flo = hyd_stop_force(&cc, -x, -v, &fdl, &fvl);
    const double fhi = hyd_stop_force(&cc, x - a->s, v, &fdh, &fvh);
    o->F = pA * a->AA - pB * a->AB - a->bv * v + flo - fhi;
    if (partials) {
        const double sgn = pos ? 1.0 : -1.0;
        o->g1 = g1, o->g2 = g2, o->pos = pos;
        o->du1 = g1A * a->Amax * sgn;
        o->du2 = g2A * a->Amax * sgn;
        o->gA = gA, o->gB = gB, o->ghA = ghA, o->ghB = ghB;
        o->fdl = fdl, o->fvl = fvl, o->fdh = fdh, o->fvh = fvh;
    }
}

static inline double pump_in(const hyd_fused* f, double pPL, double* g) {
    double ds;
    const double s = hyd_smoothstep((pPL - f->p_in - f->pset) * f->inv_band, &ds);
    *g = -f->qmax * ds * f->inv_band;
    return f->qmax * (1.0 - s);
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
    const double c = node_c(m, n, p, V);
    double dbe;
    hyd_be(m, n->bel, p, &dbe);
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

        // The volume floor makes V constant in x once reached (cylinder.c).
        const double dVA = (a->VA0 + a->AA * x[k] > HYD_VMIN_FRAC * a->VA0) ? a->AA : 0.0;
        const double dVB = (a->VB0 + a->AB * (a->s - x[k]) > HYD_VMIN_FRAC * a->VB0) ? -a->AB : 0.0;
        hyd_fused_coupling* cp = &cpl[k];
        cp->dA_dx = -cA / o.VA * dVA * o.nA;
        cp->dB_dx = -cB / o.VB * dVB * o.nB;
        cp->dA_dv = -cA * a->AA;
        cp->dB_dv = cB * a->AB;
        cp->dF_dx = -o.fdl - o.fdh;
        cp->dF_dv = -a->bv - o.fvl - o.fvh;
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
