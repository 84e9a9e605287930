// valve.c: 4/3 closed-centre proportional directional valve.
//
// Spool: tau_s u' = clamp(u_cmd, -1, 1) - u (first order, as in the paper).
// Clamping the command keeps u inside [-1, 1] without a state limiter.
// Metering: u > 0 opens P->A and B->T, u < 0 opens P->B and A->T, each edge a
// two-regime orifice of area |u| A_max, A_max = Q_N / (cd sqrt(2 dp_N / rho))
// (the turbulent law at the rated point; exact as long as dp_N >> p_tr(A_max),
// about 0.4 Pa for the default valve). Only the two open edges are evaluated;
// port nodes are chosen by the sign of u. Because the orifice's laminar flow
// scales as A^1.5, Q(u) is C1 through u = 0 even though |u| is not.
#include "hyd_valve.h"

#include <math.h>

hyd_valve_def hyd_default_valve_def(void) {
    hyd_valve_def d = {0};
    d.q_nominal = 40.0 / 60000.0;
    d.dp_nominal = 1e6;
    d.cd = 0.65;
    d.tau = 0.03;
    d.u0 = 0.0;
    return d;
}

static void valve_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)node0;
    const hyd_fluid_def* f = &m->fluid;
    const hyd_valve_def* d = def;
    hyd_valve_c* c = rec;
    c->ok = hyd_orifice_constants(f, d->cd);
    c->Amax = d->q_nominal / (d->cd * sqrt(2.0 * d->dp_nominal / f->density));
    c->inv_tau = 1.0 / d->tau;
}

// The kernel is inlined twice, with and without G, so that the plain
// evaluation drops the dQ/dA partials and the Jacobian bookkeeping entirely.
// map (NULL: identity) is the caller's state order of hyd_eval_mapped.
static inline void valves_kernel(const hyd_model* m, hyd_data* d, const hyd_valve_c* rec, int n,
                                 const double* y, double* ydot, double* G, const int* map) {
    const int ld = m->nstate + 1;
    for (int i = 0; i < n; ++i) {
        const hyd_valve_c* c = &rec[i];
        const int at = map ? map[c->adr] : c->adr;
        const double u = y[at];
        // The valve's own index (rec may be a subset of the model's valves).
        if (ydot)
            ydot[at] = hyd_spool_rate(d->valve_cmd[m->comp_sub[c->comp]], u, c->inv_tau);

        // Edge 1 feeds the work port from P; edge 2 drains the other one to T.
        hyd_valve_flow e;
        hyd_valve_edges(&c->ok, c->Amax, u, d->node_p[c->P], d->node_p[c->T], d->node_p[c->A],
                        d->node_p[c->B], &e);
        const int pos = e.pos;
        const double sgn = pos ? 1.0 : -1.0;
        const int feed = pos ? c->A : c->B;
        const int drain = pos ? c->B : c->A;
        const double q1 = e.q1, q2 = e.q2, g1 = e.g1, g2 = e.g2, g1A = e.g1A, g2A = e.g2A;
        const double qA = pos ? q1 : -q2; // into port A
        const double qB = pos ? q2 : -q1; // out of port B
        double* fl = d->flow_ + 4 * c->comp;
        fl[0] = -q1;
        fl[1] = q2;
        fl[2] = qA;
        fl[3] = -qB;
        d->comp_q[2 * c->comp] = qA;
        d->comp_q[2 * c->comp + 1] = qB;
        if (G) {
            hyd_jac_flow(m, G, c->P, feed, g1, -g1);
            hyd_jac_flow(m, G, drain, c->T, g2, -g2);
            // Spool column: dQ/du = dQ/dA * A_max * sign(u).
            const double du1 = g1A * c->Amax * sgn, du2 = g2A * c->Amax * sgn;
            G[m->node_sidx[c->P] * ld + c->adr] -= du1;
            G[m->node_sidx[feed] * ld + c->adr] += du1;
            G[m->node_sidx[drain] * ld + c->adr] -= du2;
            G[m->node_sidx[c->T] * ld + c->adr] += du2;
        }
    }
}

static void valves_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                        double* ydot, double* G, const int* map) {
    if (map)
        valves_kernel(m, d, rec, n, y, ydot, NULL, map);
    else if (G)
        valves_kernel(m, d, rec, n, y, ydot, G, NULL);
    else
        valves_kernel(m, d, rec, n, y, ydot, NULL, NULL);
}

// The spool rows: u' = (cmd - u) / tau depends on u only.
static void valves_jacobian(const hyd_model* m, hyd_data* d, const void* rec, int n, double* Jb,
                            int ldj) {
    (void)d;
    if (!Jb)
        return;
    for (int v = 0; v < n; ++v) {
        const hyd_valve_c* c = (const hyd_valve_c*)rec + v;
        double* row = Jb + (size_t)c->adr * ldj;
        memset(row, 0, (size_t)m->nstate * sizeof *row);
        row[c->adr] = -c->inv_tau;
    }
}

// A valve's T port returns to the tank; on a cylinder chamber it would
// drain that chamber whenever the spool opens (a swapped port).
static int valve_check_ports(const hyd_model* m, const char* const* port_name, const int* port,
                             const int* own, char* field, size_t fsz, char* msg, size_t msz) {
    (void)own;
    const int owner = m->node_owner[port[1]];
    if (owner >= 0 && m->comp[owner].type == HYD_CYLINDER) {
        snprintf(field, fsz, "T");
        snprintf(msg, msz, "'%s' is a cylinder chamber; T is the return to the tank (P, A or B meant?)",
                 port_name[1]);
        return -1;
    }
    return 0;
}

static void valve_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own;
    hyd_valve_c* c = rec;
    c->comp = comp, c->P = port[0], c->T = port[1], c->A = port[2], c->B = port[3];
    c->adr = state[0];
}

static void valve_initial(const void* def, const void* rec, double* y0) {
    y0[((const hyd_valve_c*)rec)->adr] = ((const hyd_valve_def*)def)->u0;
}

static const hyd_param_info valve_params[] = {
    HYD_PARAM(hyd_valve_def, q_nominal, "m^3/s", HYD_R_POS, 0, 1e-7, 0.1, 1e-5, 5e-3),
    HYD_PARAM(hyd_valve_def, dp_nominal, "Pa", HYD_R_POS, 0, 1e4, 1e7, 2e5, 3.5e6),
    // cd divides the rated flow into the largest opening: 0 would be infinite.
    HYD_PARAM(hyd_valve_def, cd, "-", HYD_R_FRAC, 0, 0.1, 1, 0.5, 0.8),
    HYD_PARAM(hyd_valve_def, tau, "s", HYD_R_POS, 0, 1e-4, 10, 5e-3, 0.2),
    HYD_PARAM(hyd_valve_def, u0, "-", HYD_R_UNIT, 0, -1, 1, -1, 1),
};
static const hyd_port_info valve_ports[] = {HYD_PORT(hyd_valve_def, P), HYD_PORT(hyd_valve_def, T),
                                            HYD_PORT(hyd_valve_def, A), HYD_PORT(hyd_valve_def, B)};
static const char* const valve_states[] = {"spool"};

static void valve_defaults(void* def) { *(hyd_valve_def*)def = hyd_default_valve_def(); }

HYD_DEF_FITS(hyd_valve_def);
const hyd_component hyd_valve_component = {
    .type = HYD_VALVE, .name = "valve", .def_size = sizeof(hyd_valve_def),
    .params = valve_params, .nparam = HYD_COUNT(valve_params),
    .ports = valve_ports, .nport = HYD_COUNT(valve_ports),
    .states = valve_states, .nstate = HYD_COUNT(valve_states),
    .rec_size = sizeof(hyd_valve_c),
    .defaults = valve_defaults, .check_ports = valve_check_ports, .bind = valve_bind,
    .derive = valve_derive, .initial = valve_initial, .eval = valves_eval, .jacobian = valves_jacobian,
};
