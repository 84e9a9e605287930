// cylinder.c: double-acting hydraulic cylinder with end stops.
//
//   A_A = pi D^2/4, A_B = pi (D^2 - d^2)/4
//   V_A = V_A0 + A_A x,  V_B = V_B0 + A_B (s - x)   (dV_A/dt = A_A x', dV_B/dt = -A_B x')
//   leakage A -> B: C_L (pA - pB)
//   F = pA A_A - pB A_B - b_v x' + F_stop(x, x')
// The chambers are nodes owned by the cylinder; the pressure equation itself
// is in volume.c. The end stop is a spring-damper that acts only beyond the
// stroke, with penetration depth delta (-x below 0, x - s above s):
//   |F_stop| = k S(delta) + c W(delta) delta'
//   S = delta^2/(2w) for delta < w, delta - w/2 beyond (spring with C1 onset)
//   W = smoothstep(delta/w)                         (damper fades in, C1)
// so F is C1 in x and x': no kink for the Jacobian or finite differences.
#include "hyd_internal.h"

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
    return d;
}

int hyd_cylinder_validate(const hyd_cylinder_def* d, char* field, size_t fsz, char* msg,
                          size_t msz) {
    if (d->rod >= d->bore) {
        snprintf(field, fsz, "rod");
        snprintf(msg, msz, "must be < bore (%g), got %g", d->bore, d->rod);
        return -1;
    }
    return 0;
}

void hyd_cylinder_derive(const hyd_cylinder_def* d, hyd_cyl_c* c) {
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
}

void hyd_cylinders_eval(const hyd_model* m, hyd_data* d, double* G) {
    for (int i = 0; i < m->ncyl; ++i) {
        const hyd_cyl_c* c = &m->cyl[i];
        const double x = d->cyl_x[i], v = d->cyl_v[i];
        const double pA = d->node_p[c->nA], pB = d->node_p[c->nB];

        const double VA = c->VA0 + c->AA * x, VB = c->VB0 + c->AB * (c->s - x);
        const double VAmin = HYD_VMIN_FRAC * c->VA0, VBmin = HYD_VMIN_FRAC * c->VB0;
        d->node_V[c->nA] = VA > VAmin ? VA : VAmin;
        d->node_V[c->nB] = VB > VBmin ? VB : VBmin;
        d->node_dV[c->nA] = c->AA * v;
        d->node_dV[c->nB] = -c->AB * v;

        const double leak = c->CL * (pA - pB);
        d->comp_q[2 * c->comp] = leak;
        hyd_flow2(m, d, G, c->comp, c->nA, c->nB, leak, c->CL, -c->CL);

        // Retracted stop pushes out (+), extended stop pushes in (-).
        double fdl, fvl, fdh, fvh;
        const double flo = hyd_stop_force(c->ks, c->cs, c->ws, -x, -v, &fdl, &fvl);
        const double fhi = hyd_stop_force(c->ks, c->cs, c->ws, x - c->s, v, &fdh, &fvh);
        d->cyl_F[i] = pA * c->AA - pB * c->AB - c->bv * v + flo - fhi;
        d->cyl_stop[i] = (x > c->s) - (x < 0.0);
        d->comp_open[c->comp] = d->cyl_stop[i] != 0;
        // dF/dx and dF/dv (used by hyd_jacobian; cheap enough to always write).
        d->dFdx[i] = -fdl - fdh;
        d->dFdv[i] = -c->bv - fvl - fvh;
    }
}
