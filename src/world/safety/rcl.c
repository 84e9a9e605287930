// rcl.c: the rated capacity limiter (rcl.h, docs/safety.md).
#include "rcl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim_base.h"

// Outreach below which the load moment is divided by this lever instead
// [m]: close to the column the moment, and its measurement, go to zero.
#define RCL_R_MIN 0.5
// Slew step over which the limiter looks for a weaker sector [rad] (3 deg).
#define RCL_SLEW_LOOK 0.05

int rcl_init(rcl* r, const model* m, const world_desc* wd, char* err, size_t errsz) {
    memset(r, 0, sizeof *r);
    r->m = m;
    if (model_require_two_link(m, "rated capacity limiter", err, errsz)) return -1;
    double st;
    hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &r->AA, &r->AB, &st);
    r->stroke = st;
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

rcl* rcl_create(const model* m, const char* world_path) {
    char err[300];
    rcl* r = malloc(sizeof *r);
    if (r && rcl_init_world(r, m, world_path, err, sizeof err)) {
        free(r);
        r = NULL;
    }
    return r;
}

void rcl_destroy(rcl* r) {
    if (r) rcl_free(r), free(r);
}

void rcl_reset(rcl* r) {
    const rcl keep = *r;
    memset(r, 0, sizeof *r);
    r->m = keep.m, r->chart = keep.chart, r->AA = keep.AA, r->AB = keep.AB, r->stroke = keep.stroke;
}

// Load moment about joint 1 [N m] measured from the lift pressures: the
// cylinder's torque F r less the booms' own gravity torque at these angles,
// less the hook's (it hangs at the tip whatever it carries). *R: outreach [m].
static double load_moment(const rcl* r, const double* row, double* R) {
    const crane_mech* me = &r->m->mech;
    const double q[2] = {row[COL_Q1], row[COL_Q2]};
    double lever, G0[2], z;
    crane_pin_length(&me->act[0], q[0], &lever);
    crane_gravity(me, 0.0, q, G0);
    crane_tip(me, q[0], q[1], R, &z);
    const double F = row[COL_P1A] * r->AA - row[COL_P1B] * r->AB;
    return F * lever - G0[0] - r->chart.hook_mass * me->gravity * *R;
}

// Outreach rate [m/s]: the tip's horizontal speed from the cylinder speeds
// (v = dx/dq qdot for each cylinder).
static double outreach_rate(const rcl* r, const double* row) {
    const crane_mech* me = &r->m->mech;
    const double q[2] = {row[COL_Q1], row[COL_Q2]}, v[2] = {row[COL_V1], row[COL_V2]};
    double qd[2];
    for (int k = 0; k < 2; ++k) {
        double dxdq;
        crane_pin_length(&me->act[k], q[k], &dxdq);
        qd[k] = fabs(dxdq) > 1e-6 ? v[k] / dxdq : 0.0;
    }
    const double c12 = me->link[1].length * cos(q[0] + q[1]);
    return (me->link[0].length * cos(q[0]) + c12) * qd[0] + c12 * qd[1];
}

// Outreach gained per metre of stroke of cylinder k [m/m] at the row's
// pose: dR/dq_k / (dx_k/dq_k), R = L1 sin q1 + L2 sin(q1 + q2). A positive
// command extends the cylinder, so a command of this sign moves the tip out.
// Below 1 mm per metre the motion leaves the moment as it is: let through.
static double outreach_per_stroke(const rcl* r, const double* row, int k) {
    const crane_mech* me = &r->m->mech;
    const double q1 = row[COL_Q1], q2 = row[COL_Q2];
    const double c12 = me->link[1].length * cos(q1 + q2);
    const double dRdq = k == 0 ? me->link[0].length * cos(q1) + c12 : c12;
    double dxdq;
    crane_pin_length(&me->act[k], k == 0 ? q1 : q2, &dxdq);
    const double g = fabs(dxdq) > 1e-6 ? dRdq / dxdq : 0.0;
    return fabs(g) < 1e-3 ? 0.0 : g;
}

// Smallest capacity [kg] over the outreaches [a, b] at slew s [rad]: the
// chart is linear between its points, so its value at both ends and at the
// points inside.
static double capacity_min(const loadchart* c, double a, double b, double s) {
    double cap = fmin(loadchart_capacity(c, a, s, NULL), loadchart_capacity(c, b, s, NULL));
    for (int i = 0; i < c->n; ++i)
        if (c->R[i] > a && c->R[i] < b) cap = fmin(cap, loadchart_capacity(c, c->R[i], s, NULL));
    return cap;
}

double rcl_utilisation(rcl* r, const double* row) {
    double R;
    const double g = r->m->mech.gravity;
    // The load the moment implies [kg]: what is filtered is this estimate,
    // not the moment, so the outreach (known at once from the angles) acts
    // without lag and only the pressure's ringing is smoothed.
    const double m_raw = load_moment(r, row, &R) / (g * fmax(R, RCL_R_MIN));
    r->R = R;
    const double t = row[COL_T];
    // On or near an end stop the lift pressure is load plus the stop's
    // force (with the valve still open, the pump's pressure: 20.6 MPa read
    // as 131 % of a 200 kg load on the sandbox), so it is not taken there.
    r->x_lift = crane_stroke(&r->m->mech.act[0], row[COL_Q1]);
    const bool trust = r->x_lift > RCL_STOP_BAND && r->x_lift < r->stroke - RCL_STOP_BAND;
    r->held = !trust;
    // Two first-order stages of RCL_TAU / 2: the same 1 s lag to a step as
    // one stage of RCL_TAU, but the booms' ringing on the oil (2.5 Hz on
    // the shipped crane, the lift pressure swinging by +-10 MPa) is cut to
    // 1.6 % instead of 6 %.
    const double rd = outreach_rate(r, row);
    if (!r->have || t < r->t_last || !isfinite(r->m_filt) || !isfinite(r->m_stage)) {
        r->have = true, r->have_load = false;
        r->m_filt = r->m_stage = 0.0;
        r->rd_env = fabs(rd);
    } else if (t > r->t_last) {
        const double k = 1.0 - exp(-(t - r->t_last) / (0.5 * RCL_TAU));
        // Off the stop the first stage takes the measurement; on it, its
        // input is cut and the second stage still settles on the first: the
        // estimate becomes the last load measured clear of the stop.
        if (trust && r->have_load) r->m_stage += k * (m_raw - r->m_stage);
        r->m_filt += k * (r->m_stage - r->m_filt);
        r->rd_env = fmax(fabs(rd), r->rd_env * exp(-(t - r->t_last) / RCL_TAU));
    }
    // The first trusted row starts the filter at its value (at the start of a
    // run, or when a run that began on a stop leaves it).
    if (trust && !r->have_load) r->m_filt = r->m_stage = m_raw, r->have_load = true;
    r->t_last = t;
    const double load = fmax(0.0, r->m_filt);
    const double cap = loadchart_capacity(&r->chart, R, row[COL_SLEW], NULL);
    r->util = cap > 0 ? load / cap : (r->m_filt > 0 ? 1e3 : 0.0);
    if (!isfinite(r->util)) r->util = 1e3;
    // Ahead: the weakest chart point the tip can reach within RCL_LOOK_T,
    // either way, at the envelope of its outreach speed (the speed itself
    // rings with the booms, through zero twice a period). The chart can
    // drop by a third within a few centimetres (docs/safety.md: a branch of
    // poses begins at a corner of the workspace); a limiter that only looks
    // where the tip is would see the drop when it is past it.
    const double look = r->rd_env * RCL_LOOK_T;
    const double cap_ahead = capacity_min(&r->chart, R - look, R + look, row[COL_SLEW]);
    r->util_ahead = cap_ahead > 0 ? load / cap_ahead : (r->m_filt > 0 ? 1e3 : 0.0);
    if (!isfinite(r->util_ahead)) r->util_ahead = 1e3;
    r->util_ahead = fmax(r->util_ahead, r->util);
    r->warn = r->util >= RCL_WARN;
    return r->util;
}

// How much of a motion that raises the utilisation to u is let through:
// all below RCL_SLOW, none from 1.
static double allow(double u) {
    const double a = (1.0 - u) / (1.0 - RCL_SLOW);
    // Below 1e-9: 100 % within the round-off of the pressure-to-load arithmetic.
    return a < 1e-9 ? 0 : (a > 1 ? 1 : a);
}

double rcl_filter(rcl* r, const double* row, const double u_in[3], double u_out[3]) {
    const double u = rcl_utilisation(r, row), t = row[COL_T];
    for (int k = 0; k < 3; ++k) u_out[k] = u_in[k];
    // The slow-down acts on the utilisation ahead, so the motion slows
    // before the limit rather than at it. It ramps: the fraction let through
    // falls no faster than from all to nothing in RCL_RAMP (a step to zero
    // would stop the loaded booms at once and set them ringing on the oil),
    // the look-ahead covers the distance run meanwhile. At 100 % it is
    // nothing at once.
    double a = allow(r->util_ahead);
    if (r->t_allow > 0 && t >= r->t_allow) {
        const double da = (t - r->t_allow) / RCL_RAMP;
        if (u < 1.0) a = fmax(a, r->allow - da);
        a = fmin(a, r->allow + da); // and back up as gently
    }
    r->allow = a, r->t_allow = t;
    // A boom motion raises the load moment when it carries the tip
    // outwards. Which command that is depends on the pose: lowering the
    // lifting arm does while the tip is above the arm's pin, but with the
    // end arm hanging below the pin, lifting swings the tip out as well.
    for (int k = 0; k < 2; ++k)
        if (u_out[k] * outreach_per_stroke(r, row, k) > 0) u_out[k] *= a;
    if (u_out[2] != 0 && r->chart.stab) {
        const double R = r->R; // this row's, from rcl_utilisation above
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
