// relief.c: pressure relief valve with a C1 quadratic opening corner.
//
// With d = p_in - p_out - p_crack and w = dp_override:
//   q = q_rated * ramp(d, w),  ramp = 0 (d <= 0), (d/w)^2 (d < w), 1 + 2(d - w)/w (beyond).
// Value and slope match at d = 0 and d = w, so the Jacobian stays bounded when
// the valve cracks; beyond w it behaves as a linear (laminar-like) resistance
// with the slope of the corner's end, 2 q_rated / w.
#include "hyd_internal.h"

hyd_relief_def hyd_default_relief_def(void) {
    hyd_relief_def d = {0};
    d.dp_override = 1e6;
    d.q_rated = 40.0 / 60000.0;
    return d;
}

// On 1/w so the kernel needs no division.
static inline double open_ramp(double d, double inv_w, double* dr) {
    const double t = d * inv_w;
    if (t <= 0.0) {
        *dr = 0.0;
        return 0.0;
    }
    if (t < 1.0) {
        *dr = 2.0 * t * inv_w;
        return t * t;
    }
    *dr = 2.0 * inv_w;
    return 2.0 * t - 1.0;
}

double hyd_open_ramp(double d, double w, double* dr) { return open_ramp(d, 1.0 / w, dr); }

void hyd_relief_derive(const hyd_relief_def* d, hyd_ramp_c* c) {
    c->pcr = d->p_crack;
    c->inv_w = 1.0 / d->dp_override;
    c->qr = d->q_rated;
}

// Shared by relief and check valves (check_valve.c): both are the same
// opening law between two nodes; only their defaults and roles differ.
void hyd_ramps_eval(const hyd_model* m, hyd_data* d, double* G, const hyd_ramp_c* v, int nv) {
    for (int i = 0; i < nv; ++i) {
        const hyd_ramp_c* c = &v[i];
        double dr;
        const double r = open_ramp(d->node_p[c->in] - d->node_p[c->out] - c->pcr, c->inv_w, &dr);
        const double q = c->qr * r;
        const double g = c->qr * dr;
        d->comp_q[2 * c->comp] = q;
        d->comp_open[c->comp] = q > 0.0;
        hyd_flow2(m, d, G, c->comp, c->in, c->out, q, g, -g);
    }
}

void hyd_reliefs_eval(const hyd_model* m, hyd_data* d, double* G) {
    hyd_ramps_eval(m, d, G, m->relief, m->nrelief);
}
