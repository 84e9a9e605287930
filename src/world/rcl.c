// rcl.c: the rated capacity limiter (rcl.h, docs/safety.md).
#include "rcl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lagrange.h"
#include "sim.h"

// Outreach below which the load moment is divided by this lever instead
// [m]: close to the column the moment, and its measurement, go to zero.
#define RCL_R_MIN 0.5
// Slew step over which the limiter looks for a weaker sector [rad] (3 deg).
#define RCL_SLEW_LOOK 0.05

int rcl_init(rcl* r, const model* m, const world_desc* wd, char* err, size_t errsz) {
    memset(r, 0, sizeof *r);
    r->m = m;
    double st;
    hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &r->AA, &r->AB, &st);
    lc_truck t;
    lc_truck_from_world(wd, &t);
    lc_opts o = lc_default_opts();
    double rmin, rmax;
    loadchart_reach(m, &rmin, &rmax);
    o.lo = fmax(rmin, RCL_R_MIN);
    o.hi = floor(20 * rmax - 1) / 20; // inside the reach; beyond it the last point holds
    o.sectors = 8;
    if (!(o.hi > o.lo)) {
        snprintf(err, errsz, "rated capacity limiter: the crane reaches no further than %.2f m", rmax);
        return -1;
    }
    return loadchart_compute(m, &t, &o, &r->chart, err, errsz);
}

int rcl_init_world(rcl* r, const model* m, const char* world_path, char* err, size_t errsz) {
    if (!world_path) return rcl_init(r, m, NULL, err, errsz);
    static world_desc wd; // large; the limiter keeps none of it
    if (world_desc_load(world_path, &wd, err, errsz)) return -1;
    const int rc = rcl_init(r, m, &wd, err, errsz);
    world_desc_free(&wd);
    return rc;
}

void rcl_free(rcl* r) { loadchart_free(&r->chart); }

// Load moment about joint 1 [N m] measured from the lift pressures: the
// cylinder's torque F r less the booms' own gravity torque at these angles,
// less the hook's (it hangs at the tip whatever it carries). *R: outreach [m].
static double load_moment(const rcl* r, const double* row, double* R) {
    const crane_mech* me = &r->m->mech;
    const double q[2] = {row[COL_Q1], row[COL_Q2]};
    double lever, G0[2], z;
    crane_pin_length(&me->act[0], q[0], &lever);
    lagrange_gravity(me, LAGRANGE_FULL, 0.0, q, G0);
    crane_tip(me, q[0], q[1], R, &z);
    const double F = row[COL_P1A] * r->AA - row[COL_P1B] * r->AB;
    return F * lever - G0[0] - r->chart.hook_mass * me->gravity * *R;
}

double rcl_utilisation(rcl* r, const double* row) {
    double R;
    const double g = r->m->mech.gravity;
    // The load the moment implies [kg]: what is filtered is this estimate,
    // not the moment, so the outreach (known at once from the angles) acts
    // without lag and only the pressure's ringing is smoothed.
    const double m_raw = load_moment(r, row, &R) / (g * fmax(R, RCL_R_MIN));
    const double t = row[COL_T];
    if (!r->have || t < r->t_last || !isfinite(r->m_filt)) {
        r->m_filt = m_raw, r->have = true;
    } else if (t > r->t_last) {
        r->m_filt += (1.0 - exp(-(t - r->t_last) / RCL_TAU)) * (m_raw - r->m_filt);
    }
    r->t_last = t;
    const double cap = loadchart_capacity(&r->chart, R, row[COL_SLEW], NULL);
    r->util = cap > 0 ? fmax(0.0, r->m_filt) / cap : (r->m_filt > 0 ? 1e3 : 0.0);
    if (!isfinite(r->util)) r->util = 1e3;
    r->warn = r->util >= RCL_WARN;
    return r->util;
}

// How much of a motion that raises the utilisation to u is let through:
// all below RCL_SLOW, none from 1.
static double allow(double u) {
    const double a = (1.0 - u) / (1.0 - RCL_SLOW);
    return a < 0 ? 0 : (a > 1 ? 1 : a);
}

double rcl_filter(rcl* r, const double* row, const double u_in[3], double u_out[3]) {
    const double u = rcl_utilisation(r, row);
    for (int k = 0; k < 3; ++k) u_out[k] = u_in[k];
    const double a = allow(u);
    if (u_out[0] < 0) u_out[0] *= a; // lowering the lifting arm
    if (u_out[1] > 0) u_out[1] *= a; // unfolding the end arm outwards
    if (u_out[2] != 0 && r->chart.stab) {
        double R;
        load_moment(r, row, &R);
        const double s = row[COL_SLEW];
        const double here = loadchart_capacity(&r->chart, R, s, NULL);
        const double there = loadchart_capacity(&r->chart, R, s + (u_out[2] > 0 ? 1 : -1) * RCL_SLEW_LOOK, NULL);
        if (there < here) u_out[2] *= allow(there > 0 ? u * here / there : 1e3);
    }
    r->stopped = false;
    for (int k = 0; k < 3; ++k)
        if (u_out[k] != u_in[k]) r->stopped = true;
    return u;
}
