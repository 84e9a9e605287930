// cylinder.c: double-acting hydraulic cylinder with end stops.
//
//   A_A = pi D^2/4, A_B = pi (D^2 - d^2)/4
//   V_A = V_A0 + A_A x,  V_B = V_B0 + A_B (s - x)   (dV_A/dt = A_A x', dV_B/dt = -A_B x')
//   leakage A -> B: C_L (pA - pB)
//   F = pA A_A - pB A_B - b_v x' + F_stop(x, x') - F_seal(x')
//   F_seal = (F_c + F_s exp(-(x'/v_st)^2)) tanh(x'/v_sm)   (seal friction)
// The chambers are nodes owned by the cylinder; the pressure equation itself
// is in volume.c. The end stop is a spring-damper that acts only beyond the
// stroke, with penetration depth delta (-x below 0, x - s above s):
//   |F_stop| = k S(delta) + c W(delta) delta'
//   S = delta^2/(2w) for delta < w, delta - w/2 beyond (spring with C1 onset)
//   W = smoothstep(delta/w)                         (damper fades in, C1)
// so F is C1 in x and x': no kink for the Jacobian or finite differences.
// The seal friction is the Coulomb + Stribeck law of lumped friction models
// (Olsson et al. 1998, the static part of the LuGre model without its bristle
// state) with sign(x') replaced by tanh(x'/v_sm): smooth (C-infinity) through
// zero velocity, so a held cylinder creeps at about v_sm atanh(F/F_break)
// instead of sticking exactly. Its slope at rest, (F_c + F_s)/v_sm, is a
// stiff viscous term the coupled Jacobian carries through dF/dx'.
#include "hyd_cylinder.h"

#include <math.h>

hyd_cylinder_def hyd_default_cylinder_def(void) {
    hyd_cylinder_def d = {0};
    d.dead_volume_a = 1e-4;
    d.dead_volume_b = 1e-4;
    d.leakage = 1e-14;
    d.friction = 5e3;
    d.stop_stiffness = 5e8;
    d.stop_damping = 1e6;
    d.stop_width = 1e-3;
    d.p0_a = 1e5;
    d.p0_b = 1e5;
    // Seal friction off by default (old circuits keep their numbers); the
    // velocities are the usual Stribeck and regularisation widths.
    d.coulomb = 0.0;
    d.stribeck = 0.0;
    d.v_stribeck = 0.01;
    d.v_smooth = 1e-3;
    return d;
}

static int cylinder_validate(const void* def, char* field, size_t fsz, char* msg, size_t msz) {
    const hyd_cylinder_def* d = def;
    if (d->rod >= d->bore) {
        snprintf(field, fsz, "rod");
        snprintf(msg, msz, "must be < bore (%g), got %g", d->bore, d->rod);
        return -1;
    }
    return 0;
}

static void cylinder_derive(hyd_model* m, const void* def, void* rec, int node0) {
    const hyd_cylinder_def* d = def;
    hyd_cyl_c* c = rec;
    c->AA = 0.25 * HYD_PI * d->bore * d->bore;
    c->AB = 0.25 * HYD_PI * (d->bore * d->bore - d->rod * d->rod);
    c->s = d->stroke;
    c->VA0 = d->dead_volume_a;
    c->VB0 = d->dead_volume_b;
    c->CL = d->leakage;
    c->bv = d->friction;
    c->ks = d->stop_stiffness;
    c->cs = d->stop_damping;
    c->ws = d->stop_width;
    c->Fc = d->coulomb;
    c->Fs = d->stribeck;
    c->vst = d->v_stribeck;
    c->vsm = d->v_smooth;
    // The chamber volume is written by the cylinder kernel each call.
    m->node_V0[node0] = m->node_V0[node0 + 1] = 0.0;
    m->node_bel[node0] = m->node_bel[node0 + 1] = m->fluid.bulk_modulus;
    m->node_p0[node0] = d->p0_a;
    m->node_p0[node0 + 1] = d->p0_b;
    m->node_pfix[node0] = m->node_pfix[node0 + 1] = 0.0;
}

static void cylinders_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                           double* ydot, double* G, const int* map) {
    (void)y, (void)ydot, (void)map;
    for (int i = 0; i < n; ++i) {
        const hyd_cyl_c* c = (const hyd_cyl_c*)rec + i;
        // The cylinder's own index (rec may be a subset of the model's cylinders).
        const int k = m->comp_sub[c->comp];
        const double x = d->cyl_x[k], v = d->cyl_v[k];
        const double pA = d->node_p[c->nA], pB = d->node_p[c->nB];

        double VA, VB, dVA, dVB;
        hyd_cyl_volumes(c->VA0, c->VB0, c->AA, c->AB, c->s, x, &VA, &VB, &dVA, &dVB);
        d->node_V[c->nA] = VA;
        d->node_V[c->nB] = VB;
        d->node_dV[c->nA] = c->AA * v;
        d->node_dV[c->nB] = -c->AB * v;

        const double leak = hyd_cyl_leak(c->CL, pA, pB);
        d->comp_q[2 * c->comp] = leak;
        hyd_flow2(m, d, G, c->comp, c->nA, c->nB, leak, c->CL, -c->CL);

        // dF/dx and dF/dv (used by hyd_jacobian; cheap enough to always write).
        d->cyl_F[k] = hyd_cyl_force(c->AA, c->AB, c->bv, c->ks, c->cs, c->ws, c->s, pA, pB, x, v,
                                    &d->dFdx[k], &d->dFdv[k]);
        double dseal;
        d->cyl_F[k] -= hyd_cyl_seal(c->Fc, c->Fs, c->vst, c->vsm, v, &dseal);
        d->dFdv[k] -= dseal;
        d->cyl_stop[k] = (x > c->s) - (x < 0.0);
        d->comp_open[c->comp] = d->cyl_stop[k] != 0;
    }
}

// Coupling partials: x and x' enter only through the chamber volumes.
static void cylinders_jacobian(const hyd_model* m, hyd_data* d, const void* rec, int nc, double* Jb,
                               int ldj) {
    (void)Jb, (void)ldj;
    const int n = m->nstate;
    for (int ii = 0; ii < nc; ++ii) {
        const hyd_cyl_c* c = (const hyd_cyl_c*)rec + ii;
        const int i = m->comp_sub[c->comp]; // its index among the model's cylinders
        const double x = d->cyl_x[i];
        const double VA = d->node_V[c->nA], VB = d->node_V[c->nB];
        const double cA = d->node_be[c->nA] / VA, cB = d->node_be[c->nB] / VB;
        const double netA = d->node_q[c->nA] - d->node_dV[c->nA];
        const double netB = d->node_q[c->nB] - d->node_dV[c->nB];
        // The volume floor makes V constant in x once reached.
        double VAf, VBf, dVA, dVB;
        hyd_cyl_volumes(c->VA0, c->VB0, c->AA, c->AB, c->s, x, &VAf, &VBf, &dVA, &dVB);
        d->dydx[i * n + c->sA] = -cA / VA * dVA * netA;
        d->dydx[i * n + c->sB] = -cB / VB * dVB * netB;
        d->dydv[i * n + c->sA] = -cA * c->AA;
        d->dydv[i * n + c->sB] = cB * c->AB;
        d->dFdy[i * n + c->sA] = c->AA;
        d->dFdy[i * n + c->sB] = -c->AB;
    }
}

static void cylinder_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)port;
    hyd_cyl_c* c = rec;
    c->comp = comp, c->nA = own[0], c->nB = own[1], c->sA = state[0], c->sB = state[1];
}

static const hyd_param_info cylinder_params[] = {
    HYD_PARAM(hyd_cylinder_def, bore, "m", HYD_R_POS, 1, 0.005, 1, 0.03, 0.3),
    HYD_PARAM(hyd_cylinder_def, rod, "m", HYD_R_POS, 1, 0.002, 1, 0.015, 0.2),
    HYD_PARAM(hyd_cylinder_def, stroke, "m", HYD_R_POS, 1, 0.01, 10, 0.1, 3),
    HYD_PARAM(hyd_cylinder_def, dead_volume_a, "m^3", HYD_R_POS, 0, 1e-8, 0.1, 1e-6, 1e-3),
    HYD_PARAM(hyd_cylinder_def, dead_volume_b, "m^3", HYD_R_POS, 0, 1e-8, 0.1, 1e-6, 1e-3),
    // 1e-10 m^3/(s Pa) leaks 60 L/min at 10 bar: the piston seal is gone.
    HYD_PARAM(hyd_cylinder_def, leakage, "m^3/(s Pa)", HYD_R_NONNEG, 0, 0, 1e-10, 0, 1e-11),
    HYD_PARAM(hyd_cylinder_def, friction, "N s/m", HYD_R_NONNEG, 0, 0, 1e7, 0, 1e5),
    HYD_PARAM(hyd_cylinder_def, stop_stiffness, "N/m", HYD_R_POS, 0, 1e5, 1e11, 1e7, 5e9),
    HYD_PARAM(hyd_cylinder_def, stop_damping, "N s/m", HYD_R_NONNEG, 0, 0, 1e9, 0, 1e7),
    HYD_PARAM(hyd_cylinder_def, stop_width, "m", HYD_R_POS, 0, 1e-5, 0.05, 1e-4, 1e-2),
    HYD_PARAM(hyd_cylinder_def, p0_a, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 5e7),
    HYD_PARAM(hyd_cylinder_def, p0_b, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 5e7),
    // Seal friction: typical Coulomb forces are 0.5-5 % of a crane cylinder's
    // maximum force (a few kN for 100-200 kN cylinders); 1 MN is no seal.
    HYD_PARAM(hyd_cylinder_def, coulomb, "N", HYD_R_NONNEG, 0, 0, 1e6, 0, 2e4),
    HYD_PARAM(hyd_cylinder_def, stribeck, "N", HYD_R_NONNEG, 0, 0, 1e6, 0, 2e4),
    HYD_PARAM(hyd_cylinder_def, v_stribeck, "m/s", HYD_R_POS, 0, 1e-5, 1, 1e-3, 0.1),
    HYD_PARAM(hyd_cylinder_def, v_smooth, "m/s", HYD_R_POS, 0, 1e-7, 0.1, 1e-5, 1e-2),
};
// Chambers "<name>.A" (piston side) and "<name>.B", states "<name>.pA", "<name>.pB".
static const hyd_owned_node cylinder_nodes[] = {{"A", "pA"}, {"B", "pB"}};

static void cylinder_defaults(void* def) { *(hyd_cylinder_def*)def = hyd_default_cylinder_def(); }

HYD_DEF_FITS(hyd_cylinder_def);
const hyd_component hyd_cylinder_component = {
    .type = HYD_CYLINDER, .name = "cylinder", .def_size = sizeof(hyd_cylinder_def),
    .params = cylinder_params, .nparam = HYD_COUNT(cylinder_params),
    .nodes = cylinder_nodes, .nnode = HYD_COUNT(cylinder_nodes),
    .rec_size = sizeof(hyd_cyl_c),
    .defaults = cylinder_defaults, .validate = cylinder_validate, .bind = cylinder_bind,
    .derive = cylinder_derive, .eval = cylinders_eval, .jacobian = cylinders_jacobian,
};
