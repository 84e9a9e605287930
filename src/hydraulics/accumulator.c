// accumulator.c: gas-charged (bladder or piston) accumulator.
//
// The gas follows the polytropic law p V_g^n = p0 V0^n (n = 1 isothermal,
// slow cycles; n = 1.4 adiabatic, fast ones). With the oil volume V = V0 - V_g
// as the state,
//   p_g(V) = p0 (V0 / (V0 - V))^n,  dp_g/dV = n p_g / (V0 - V)   (V >= 0)
// and the oil flows in from the node it is mounted on through a laminar
// conductance G:  V' = q = G (p_port - p_g(V)).
// Below the precharge the bladder lies on the poppet (V = 0): there the law
// is continued by p_g = p0 + a V (1 - V / (eps V0)), a = n p0 / V0,
// eps = 1e-4 (value and slope continuous at V = 0, monotonic), which
// stands for the poppet closing: at p_port = 0 the oil volume settles at
// about -V0 sqrt(eps / n), under 1 % of V0.
#include "hyd_accumulator.h"

#include <math.h>

hyd_accumulator_def hyd_default_accumulator_def(void) {
    hyd_accumulator_def d = {0};
    d.n = 1.4;
    d.conductance = 1e-9;
    d.p_init = 0.0;
    return d;
}

static void accs_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                      double* ydot, double* G, const int* map) {
    const int ld = m->nstate + 1;
    for (int i = 0; i < n; ++i) {
        const hyd_acc_c* c = (const hyd_acc_c*)rec + i;
        const int at = map ? map[c->adr] : c->adr;
        double dpg;
        const double pg = hyd_acc_pgas(c, y[at], &dpg);
        const double q = c->G * (d->node_p[c->node] - pg); // into the accumulator
        if (ydot)
            ydot[at] = q;
        d->comp_q[2 * c->comp] = q;
        d->comp_q[2 * c->comp + 1] = pg;
        d->flow_[HYD_MAXSLOT * c->comp] = -q;
        if (G) {
            const int s = m->node_sidx[c->node];
            G[s * ld + s] -= c->G;
            G[s * ld + c->adr] += c->G * dpg;
            double* row = G + (size_t)c->adr * ld; // hyd_state_row_from_G
            row[s] += c->G;
            row[c->adr] -= c->G * dpg;
        }
    }
}

static void accs_jacobian(const hyd_model* m, hyd_data* d, const void* rec, int n, double* Jb, int ldj) {
    if (!Jb)
        return;
    for (int i = 0; i < n; ++i)
        hyd_state_row_from_G(m, d, ((const hyd_acc_c*)rec)[i].adr, Jb, ldj);
}

static void acc_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)m, (void)node0;
    const hyd_accumulator_def* d = def;
    hyd_acc_c* c = rec;
    c->p0 = d->p0, c->V0 = d->V0, c->n = d->n, c->G = d->conductance;
    // Oil volume at the initial gas pressure: V0 (1 - (p0 / p)^(1/n)).
    c->Vinit = d->p_init > d->p0 ? d->V0 * (1.0 - pow(d->p0 / d->p_init, 1.0 / d->n)) : 0.0;
}

static void acc_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own;
    hyd_acc_c* c = rec;
    c->comp = comp, c->node = port[0], c->adr = state[0];
}

static void acc_initial(const void* def, const void* rec, double* y0) {
    (void)def;
    const hyd_acc_c* c = rec;
    y0[c->adr] = c->Vinit;
}

static const hyd_param_info acc_params[] = {
    HYD_PARAM(hyd_accumulator_def, p0, "Pa", HYD_R_POS, 1, 1e5, 1e8, 1e6, 3e7),
    HYD_PARAM(hyd_accumulator_def, V0, "m^3", HYD_R_POS, 1, 1e-6, 1, 1e-4, 0.05),
    HYD_PARAM(hyd_accumulator_def, n, "-", HYD_R_POS, 0, 1, 1.7, 1, 1.4),
    HYD_PARAM(hyd_accumulator_def, conductance, "m^3/(s Pa)", HYD_R_POS, 0, 1e-14, 1e-5, 1e-11, 1e-8),
    HYD_PARAM(hyd_accumulator_def, p_init, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 3.5e7),
};
static const hyd_port_info acc_ports[] = {HYD_PORT(hyd_accumulator_def, port)};
static const char* const acc_states[] = {"oil"};

static void acc_defaults(void* def) { *(hyd_accumulator_def*)def = hyd_default_accumulator_def(); }

HYD_DEF_FITS(hyd_accumulator_def);
const hyd_component hyd_accumulator_component = {
    .type = HYD_ACCUMULATOR, .name = "accumulator", .def_size = sizeof(hyd_accumulator_def),
    .params = acc_params, .nparam = HYD_COUNT(acc_params),
    .ports = acc_ports, .nport = HYD_COUNT(acc_ports),
    .states = acc_states, .nstate = HYD_COUNT(acc_states),
    .rec_size = sizeof(hyd_acc_c), .states_sense_ports = 1,
    .defaults = acc_defaults, .bind = acc_bind, .derive = acc_derive, .initial = acc_initial,
    .eval = accs_eval, .jacobian = accs_jacobian,
};
