// energy.c: energy accounting of a circuit, generically from its compiled
// structure (docs/energy.md). Every component writes "flow into the node at
// slot k" (hyd_data.flow_); the hydraulic power a component takes from the
// fluid is therefore
//   P_c = - sum_k p(node at slot k) * flow_[c][k]            [W]
// whatever its type: a pump gives P_c < 0 (it delivers power), a valve,
// relief, check, orifice or hose P_c >= 0 (it dissipates). A component that
// owns nodes whose volume moves (a cylinder's chambers) takes the piston
// power sum p dV/dt from them. Nodes store compression energy at the rate
// p V/Be dp/dt = p (Q_in - dV/dt), and fixed-pressure nodes (tanks) exchange
// p Q_t with the circuit. These terms sum to zero exactly at every
// evaluation (the identity of docs/energy.md), so a new component type needs
// no code here.
#include "hyd_accumulator.h"
#include "hyd_internal.h"

#include <math.h>

int hyd_comp_flows(const hyd_model* m, const hyd_data* d, int c, int* node, double* q) {
    if (c < 0 || c >= m->ncomp) return 0;
    int n = 0;
    for (int k = 0; k < HYD_MAXSLOT; ++k) {
        const int nd = m->comp_slot[HYD_MAXSLOT * c + k];
        if (nd < 0) continue;
        node[n] = nd;
        q[n++] = d->flow_[HYD_MAXSLOT * c + k];
    }
    return n;
}

// Power the component c takes from the fluid through its flow slots [W].
double hyd_comp_power(const hyd_model* m, const hyd_data* d, int c) {
    double P = 0.0;
    for (int k = 0; k < HYD_MAXSLOT; ++k) {
        const int node = m->comp_slot[HYD_MAXSLOT * c + k];
        if (node >= 0) P -= d->node_p[node] * d->flow_[HYD_MAXSLOT * c + k];
    }
    return P;
}

// Power handed through the moving volume of the nodes c owns [W]:
// sum p dV/dt (a cylinder's piston work; 0 for a hose, whose volume is fixed).
double hyd_comp_piston_power(const hyd_model* m, const hyd_data* d, int c) {
    double P = 0.0;
    for (int n = 0; n < m->nnode; ++n)
        if (m->node_owner[n] == c && m->node_state[n] >= 0) P += d->node_p[n] * d->node_dV[n];
    return P;
}

// A valve's loss per metering edge [W]: e[0] the edge that feeds the work
// port from P (meter-in), e[1] the edge that drains the other work port to T
// (meter-out). Slots are [P, T, A, B] (valve.c): flow into P is -q1, into T
// +q2, and the work ports take q1 and -q2 in the order the spool's sign
// gives. Returns 2, or 0 (e untouched) when c is not a valve.
int hyd_valve_edge_power(const hyd_model* m, const hyd_data* d, int c, double e[2]) {
    if (m->comp[c].type != HYD_VALVE) return 0;
    const double* f = d->flow_ + HYD_MAXSLOT * c;
    const int* s = m->comp_slot + HYD_MAXSLOT * c;
    const double q1 = -f[0], q2 = f[1];
    // u >= 0: A is fed (f[2] = q1) and B drained (f[3] = -q2); else the
    // reverse. The assignments in valve.c make this test exact.
    const int pos = f[2] == q1 && f[3] == -q2;
    const int feed = pos ? s[2] : s[3], drain = pos ? s[3] : s[2];
    e[0] = q1 * (d->node_p[s[0]] - d->node_p[feed]);
    e[1] = q2 * (d->node_p[drain] - d->node_p[s[1]]);
    return 2;
}

// Power the fixed-pressure nodes deliver into the circuit [W]: - sum p_t Q_t
// with Q_t the net flow into tank t from the components.
double hyd_boundary_power(const hyd_model* m, const hyd_data* d) {
    double P = 0.0;
    for (int c = 0; c < m->ncomp; ++c)
        for (int k = 0; k < HYD_MAXSLOT; ++k) {
            const int node = m->comp_slot[HYD_MAXSLOT * c + k];
            if (node >= 0 && m->node_state[node] < 0) P -= d->node_p[node] * d->flow_[HYD_MAXSLOT * c + k];
        }
    return P;
}

// Rate of compression energy stored in the fluid [W]: sum over pressure
// nodes of p V/Be dp/dt = p (Q_in - dV/dt).
double hyd_stored_power(const hyd_model* m, const hyd_data* d) {
    double P = 0.0;
    for (int k = 0; k < m->nvol; ++k) {
        const int n = m->vol_node[k];
        P += d->node_p[n] * (d->node_q[n] - d->node_dV[n]);
    }
    return P;
}

void hyd_power_terms(const hyd_model* m, const hyd_data* d, double* comp_P, double* piston_P, double* boundary,
                     double* stored) {
    double B = 0.0;
    for (int c = 0; c < m->ncomp; ++c) {
        double P = 0.0;
        for (int k = 0; k < HYD_MAXSLOT; ++k) {
            const int node = m->comp_slot[HYD_MAXSLOT * c + k];
            if (node < 0) continue;
            const double pq = d->node_p[node] * d->flow_[HYD_MAXSLOT * c + k];
            P -= pq;
            if (m->node_state[node] < 0) B -= pq; // a tank's side of the same flow
        }
        comp_P[c] = P;
        piston_P[c] = 0.0;
    }
    for (int n = 0; n < m->nnode; ++n)
        if (m->node_owner[n] >= 0 && m->node_state[n] >= 0) piston_P[m->node_owner[n]] += d->node_p[n] * d->node_dV[n];
    *boundary = B;
    *stored = hyd_stored_power(m, d);
}

// s / Be(s) * s: the integrand of phi in ln s (ds = s du).
static double phi_integrand(const hyd_model* m, int n, double s) {
    double be;
    hyd_node_c(m, m->node_bel[n], m->node_bec[n], s, 1.0, &be, NULL);
    return s * s / be;
}

// phi_n(p) = integral from p_atm to p of s / Be_n(s) ds [J/m^3], by composite
// Simpson in u = ln s (Be varies by orders of magnitude at low pressure when
// the fluid carries air; in ln s the integrand is smooth). 512 panels: the
// relative error is far below 1e-9 on the shipped fluids.
static double phi_n(const hyd_model* m, int n, double p, int N) {
    const double pa = m->fluid.p_atm > 0 ? m->fluid.p_atm : 101325.0;
    if (!(p > 0.0) || !isfinite(p)) return NAN;
    const double a = log(pa), b = log(p);
    const double h = (b - a) / N;
    double sum = phi_integrand(m, n, pa) + phi_integrand(m, n, p);
    for (int i = 1; i < N; ++i) sum += (i & 1 ? 4.0 : 2.0) * phi_integrand(m, n, exp(a + h * i));
    return sum * h / 3.0;
}

static double phi(const hyd_model* m, int n, double p) { return phi_n(m, n, p, 512); }

double hyd_node_phi(const hyd_model* m, int node, double p) {
    if (node < 0 || node >= m->nnode || m->node_state[node] < 0) return 0.0;
    return phi(m, node, p);
}

// phi(p1) - phi(p0) by one Simpson panel in p: for the small pressure change
// of one step the error is O((p1 - p0)^5), so a caller can follow phi along
// a trajectory at three table evaluations of Be per step.
double hyd_node_phi_increment(const hyd_model* m, int node, double p0, double p1) {
    if (node < 0 || node >= m->nnode || m->node_state[node] < 0) return 0.0;
    const double pm = 0.5 * (p0 + p1);
    double b0, bm, b1;
    hyd_node_c(m, m->node_bel[node], m->node_bec[node], p0, 1.0, &b0, NULL);
    hyd_node_c(m, m->node_bel[node], m->node_bec[node], pm, 1.0, &bm, NULL);
    hyd_node_c(m, m->node_bel[node], m->node_bec[node], p1, 1.0, &b1, NULL);
    return (p1 - p0) / 6.0 * (p0 / b0 + 4.0 * pm / bm + p1 / b1);
}

double hyd_node_stored_energy(const hyd_model* m, int node, double p, double V) {
    if (node < 0 || node >= m->nnode || m->node_state[node] < 0) return 0.0;
    return V * phi(m, node, p);
}

// Compression energy stored in the fluid [J], a state function of the node
// pressures p (nnode) [Pa abs] and volumes V (nnode) [m^3]: sum V phi(p).
double hyd_stored_energy(const hyd_model* m, const double* p, const double* V) {
    double E = 0.0;
    for (int k = 0; k < m->nvol; ++k) {
        const int n = m->vol_node[k];
        E += V[n] * phi(m, n, p[n]);
    }
    return E;
}

// The compression energy the model's volumetric flows do not carry [W]:
// sum over nodes whose volume moves of - phi(p) dV/dt. The node equation
// conserves volume flow, not mass, so p V/Be dp/dt (hyd_stored_power) is
// d(V phi)/dt - phi dV/dt: a chamber that shrinks at pressure p pushes out
// fluid whose compression energy phi per unit volume leaves the account
// (it is released where the fluid expands, downstream). With this term the
// balance holds with the stored energy as the state function sum V phi(p)
// (docs/energy.md). phi by 24 Simpson panels here (relative error below
// 1e-6; the term is about p/(2 Be) of the piston work).
double hyd_expansion_power(const hyd_model* m, const hyd_data* d) {
    double P = 0.0;
    for (int k = 0; k < m->nvol; ++k) {
        const int n = m->vol_node[k];
        const double dV = d->node_dV[n];
        if (dV != 0.0) P -= dV * phi_n(m, n, d->node_p[n], 24);
    }
    return P;
}

// The accumulator's record of component c, or NULL for any other type.
static const hyd_acc_c* acc_rec(const hyd_model* m, int c) {
    if (c < 0 || c >= m->ncomp || m->comp[c].type != HYD_ACCUMULATOR) return NULL;
    return (const hyd_acc_c*)m->rec[HYD_ACCUMULATOR] + m->comp_sub[c];
}

// p_g q: accumulator.c writes q (into the accumulator) and p_g as its two
// flows.
double hyd_comp_gas_power(const hyd_model* m, const hyd_data* d, int c) {
    return acc_rec(m, c) ? d->comp_q[2 * c] * d->comp_q[2 * c + 1] : 0.0;
}

// The gas's compression energy, integral of p_g dV over the oil volume from
// 0 (the precharge): with p_g V_g^n = p0 V0^n, V = V0 - V_g, it is
// p0 V0 (r^((n-1)/n) - 1)/(n - 1), r = p_g/p0 (n = 1: p0 V0 ln r). Below
// the precharge (V < 0, the poppet law p_g = p0 + a V (1 - k V) of
// hyd_accumulator.h) V is the root of that quadratic near 0 and the
// integral is p0 V + a V^2/2 - a k V^3/3 (< 0: the oil was drawn out
// against the poppet).
double hyd_comp_gas_energy(const hyd_model* m, const hyd_data* d, int c) {
    const hyd_acc_c* a = acc_rec(m, c);
    if (!a) return 0.0;
    const double pg = d->comp_q[2 * c + 1];
    if (pg >= a->p0) {
        const double r = pg / a->p0;
        if (fabs(a->n - 1.0) < 1e-9) return a->p0 * a->V0 * log(r);
        return a->p0 * a->V0 * (pow(r, (a->n - 1.0) / a->n) - 1.0) / (a->n - 1.0);
    }
    const double s = a->n * a->p0 / a->V0, k = 1.0 / (HYD_ACC_EPS * a->V0), dp = pg - a->p0;
    // V = (1 - sqrt(1 - 4 k dp / s)) / (2 k), in the form without cancellation.
    const double V = 2.0 * dp / s / (1.0 + sqrt(1.0 - 4.0 * k * dp / s));
    return a->p0 * V + 0.5 * s * V * V - s * k * V * V * V / 3.0;
}
