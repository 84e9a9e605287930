// orifice.c: two-regime (laminar/turbulent) orifice, after Ellman and Piche.
//
// With K = cd A sqrt(2/rho) and x = dp / p_tr (our reading; docs/hydraulics.md):
//   |x| <  1:  Q = K sqrt(p_tr) x (5 - x^2) / 4
//   |x| >= 1:  Q = K sign(dp) sqrt(|dp|)
// equal in value and slope at |dp| = p_tr. p_tr = (rho/2)(Re_tr nu/(cd D_h))^2
// with D_h = sqrt(4A/pi) gives p_tr = P0 / A, P0 = rho pi Re_tr^2 nu^2 / (8 cd^2).
// The laminar branch is evaluated through its conductance
//   G = 5 K / (4 sqrt(p_tr)) = kl A^1.5,   Q = G dp (1 - x^2/5),
// and x = dp A / P0, so A -> 0 gives Q -> 0 and dQ/ddp -> 0 with no division
// by A: a closed valve edge needs no special case.
#include "hyd_orifice.h"

#include <math.h>

hyd_orifice_def hyd_default_orifice_def(void) {
    hyd_orifice_def d = {0};
    d.cd = 0.65;
    return d;
}

hyd_orif_k hyd_orifice_constants(const hyd_fluid_def* f, double cd) {
    hyd_orif_k k;
    const double re_nu = f->re_transition * f->viscosity;
    k.k = cd * sqrt(2.0 / f->density);
    k.P0 = f->density * HYD_PI * re_nu * re_nu / (8.0 * cd * cd);
    k.invP0 = 1.0 / k.P0;
    k.kl = 1.25 * k.k / sqrt(k.P0);
    return k;
}

double hyd_orifice_flow(const hyd_fluid_def* f, double cd, double A, double dp, double* dq_ddp,
                        double* dq_dA) {
    const hyd_orif_k k = hyd_orifice_constants(f, cd);
    double g, gA;
    const double q = hyd_orifice_q(&k, A, dp, &g, &gA);
    if (dq_ddp)
        *dq_ddp = g;
    if (dq_dA)
        *dq_dA = gA;
    return q;
}

double hyd_orifice_p_tr(const hyd_fluid_def* f, double cd, double A) {
    return hyd_orifice_constants(f, cd).P0 / A;
}

// Fixed orifices between two nodes.
static void orifices_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                          double* ydot, double* G, const int* map) {
    (void)y, (void)ydot, (void)map;
    for (int i = 0; i < n; ++i) {
        const hyd_orifice_c* c = (const hyd_orifice_c*)rec + i;
        double g, gA;
        const double q = hyd_orifice_q(&c->ok, c->A, d->node_p[c->in] - d->node_p[c->out], &g, &gA);
        d->comp_q[2 * c->comp] = q;
        hyd_flow2(m, d, G, c->comp, c->in, c->out, q, g, -g);
    }
}

static void orifice_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)node0;
    const hyd_orifice_def* d = def;
    hyd_orifice_c* c = rec;
    c->A = d->area;
    c->ok = hyd_orifice_constants(&m->fluid, d->cd);
}

static void orifice_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own, (void)state;
    hyd_orifice_c* c = rec;
    c->comp = comp, c->in = port[0], c->out = port[1];
}

static const hyd_param_info orifice_params[] = {
    HYD_PARAM(hyd_orifice_def, area, "m^2", HYD_R_POS, 1, 1e-10, 0.1, 1e-8, 1e-3),
    HYD_PARAM(hyd_orifice_def, cd, "-", HYD_R_FRAC, 0, 0, 1, 0.5, 0.8),
};
static const hyd_port_info orifice_ports[] = {HYD_PORT(hyd_orifice_def, inlet), HYD_PORT(hyd_orifice_def, outlet)};

static void orifice_defaults(void* def) { *(hyd_orifice_def*)def = hyd_default_orifice_def(); }

HYD_DEF_FITS(hyd_orifice_def);
const hyd_component hyd_orifice_component = {
    .type = HYD_ORIFICE, .name = "orifice", .def_size = sizeof(hyd_orifice_def),
    .params = orifice_params, .nparam = HYD_COUNT(orifice_params),
    .ports = orifice_ports, .nport = HYD_COUNT(orifice_ports),
    .rec_size = sizeof(hyd_orifice_c),
    .defaults = orifice_defaults, .bind = orifice_bind, .derive = orifice_derive, .eval = orifices_eval,
};
