// rcl.c: the rated capacity limiter (rcl.h, docs/safety.md).
#include "rcl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lc_chain.h"
#include "sim_base.h"

// Outreach below which the load moment is divided by this lever instead
// [m]: close to the column the moment, and its measurement, go to zero.
#define RCL_R_MIN 0.5
// Slew step over which the limiter looks for a weaker sector [rad] (3 deg).
#define RCL_SLEW_LOOK 0.05

// Poses of the chart's search beyond which a chain's limiter is refused:
// the search's time grows with the product of the joints' grid points
// (about 3 us a pose: 2e6 is some 6 s at every engine's start).
#define RCL_CHAIN_MAX_POSES 2000000L

int rcl_check_model(const model* m, char* err, size_t errsz) {
    if (m->chain.two_link) return 0;
    const char* file = m->file[0] ? m->file : "model";
    if (!(m->mech.rated_moment > 0)) {
        // Without the maker's rating a chain's limiter would hold it to the
        // search's raw envelope alone, several times the load moment a crane
        // of its class is sold for (docs/safety.md).
        snprintf(err, errsz, "%s: rated capacity limiter: mechanics.rated_moment [kN m] is missing; a crane chain's "
                             "limiter needs the maker's rating",
                 file);
        return -1;
    }
    lc_chain g;
    if (lc_chain_init(&g, m, "rated capacity limiter", err, errsz)) return -1;
    const long n = lc_chain_grid_size(&g);
    lc_chain_free(&g);
    if (n > RCL_CHAIN_MAX_POSES) {
        snprintf(err, errsz, "%s: rated capacity limiter: its chart would search %ld poses of the chain's joints "
                             "(at most %ld)",
                 file, n, RCL_CHAIN_MAX_POSES);
        return -1;
    }
    return 0;
}

// The chain's part of rcl_init: the allow-list, its statics, the columns'
// buffers. The chart is rcl_init's, as the two-link crane's.
static int init_chain(rcl* r, const model* m, char* err, size_t errsz) {
    if (rcl_check_model(m, err, errsz)) return -1;
    r->chain = true, r->row_base = -1;
    r->g = calloc(1, sizeof *r->g);
    if (!r->g || lc_chain_init(r->g, m, "rated capacity limiter", err, errsz)) {
        if (!r->g) snprintf(err, errsz, "out of memory");
        free(r->g), r->g = NULL;
        return -1;
    }
    const size_t nd = (size_t)r->g->nd;
    r->col_q = calloc(nd + 1, sizeof *r->col_q), r->col_qd = calloc(nd + 1, sizeof *r->col_qd);
    r->q = calloc(nd + 1, sizeof *r->q);
    r->gain = calloc((size_t)m->chain.nfn + 1, sizeof *r->gain);
    if (!r->col_q || !r->col_qd || !r->q || !r->gain) {
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    const int k = r->g->lift;
    r->AA = r->g->AA[k], r->AB = r->g->AB[k], r->stroke = r->g->stroke[k];
    return 0;
}

static void free_chain(rcl* r) {
    if (r->g) lc_chain_free(r->g);
    free(r->g), free(r->col_q), free(r->col_qd), free(r->q), free(r->gain);
    r->g = NULL, r->col_q = r->col_qd = NULL, r->q = r->gain = NULL;
}

int rcl_set_chain_row(rcl* r, const crane_chain* cols, int base) {
    if (!r->chain) return 0;
    const crane_chain* cc = cols ? cols : &r->m->chain;
    r->row_base = -1;
    for (int j = 0; j < r->g->nd; ++j) {
        const char* b = r->m->chain.body[r->g->dof_body[j]].def.name;
        const int a = crane_chain_find_column(cc, "q", b), v = crane_chain_find_column(cc, "qd", b);
        if (a < 0 || v < 0) return -1;
        r->col_q[j] = base + a, r->col_qd[j] = base + v;
    }
    const char* lift = r->m->chain.act[r->g->lift].name;
    const int pa = crane_chain_find_column(cc, "pA", lift), pb = crane_chain_find_column(cc, "pB", lift);
    if (pa < 0 || pb < 0) return -1;
    r->col_pA = base + pa, r->col_pB = base + pb;
    r->row_base = base;
    return 0;
}

int rcl_init(rcl* r, const model* m, const world_desc* wd, char* err, size_t errsz) {
    memset(r, 0, sizeof *r);
    r->m = m;
    if (!m->chain.two_link) {
        if (init_chain(r, m, err, errsz)) {
            free_chain(r);
            return -1;
        }
    } else {
        double st;
        hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &r->AA, &r->AB, &st);
        r->stroke = st;
    }
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
        free_chain(r);
        return -1;
    }
    const int rc = loadchart_compute(m, &t, &o, &r->chart, err, errsz);
    if (rc) free_chain(r);
    return rc;
}

int rcl_init_world(rcl* r, const model* m, const char* world_path, char* err, size_t errsz) {
    if (!world_path) return rcl_init(r, m, NULL, err, errsz);
    static world_desc wd; // large; the limiter keeps none of it
    if (world_desc_load(world_path, &wd, err, errsz)) return -1;
    const int rc = rcl_init(r, m, &wd, err, errsz);
    world_desc_free(&wd);
    return rc;
}

void rcl_free(rcl* r) {
    loadchart_free(&r->chart);
    free_chain(r);
}

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
    r->chain = keep.chain, r->g = keep.g, r->row_base = keep.row_base, r->col_q = keep.col_q;
    r->col_qd = keep.col_qd, r->col_pA = keep.col_pA, r->col_pB = keep.col_pB, r->q = keep.q, r->gain = keep.gain;
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

// The slew angle of the row [rad]: a crane chain's rows without the world's
// columns (the analytic mode, no truck: one sector) have none.
static double row_slew(const rcl* r, const double* row) {
    return r->chain && r->row_base <= COL_SLEW ? 0.0 : row[COL_SLEW];
}

// A crane chain at the row's pose: the boom joints into r->q and the
// chain's statics (lc_chain_eval); false when the rows' layout is unknown.
static bool chain_pose(rcl* r, const double* row, double* R) {
    if (r->row_base < 0) return false;
    for (int j = 0; j < r->g->nd; ++j) r->q[j] = row[r->col_q[j]];
    lc_chain_eval(r->g, r->q, R, NULL);
    return true;
}

// A crane chain's measurement, as load_moment and outreach_rate for the
// two-link crane: the lift cylinder's force on its lever about the first
// boom joint, less the booms' own gravity torque there and the hook's, over
// the torque of 1 kg at the tip about that joint (g times the tip's
// horizontal distance from it): the load [kg]. *rd: the outreach rate
// from the tip Jacobian's horizontal row [m/s].
static double chain_load(rcl* r, const double* row, double* R, double* rd) {
    lc_chain* g = r->g;
    *R = 0, *rd = 0;
    if (!chain_pose(r, row, R)) return 0.0;
    const int k = g->lift, j = g->act_dof[k];
    const double F = row[r->col_pA] * r->AA - row[r->col_pB] * r->AB;
    const double M = F * g->lever[k] - g->G0[j] - r->chart.hook_mass * g->Gt[j];
    double v = 0;
    for (int d = 0; d < g->nd; ++d) v += g->J[d] * row[r->col_qd[d]];
    *rd = v;
    r->x_lift = g->x[k];
    return M / fmax(g->Gt[j], r->m->chain.gravity * RCL_R_MIN);
}

double rcl_utilisation(rcl* r, const double* row) {
    double R, rd_chain = 0, m_raw;
    if (r->chain) {
        m_raw = chain_load(r, row, &R, &rd_chain);
    } else {
        const double g = r->m->mech.gravity;
        // The load the moment implies [kg]: what is filtered is this estimate,
        // not the moment, so the outreach (known at once from the angles) acts
        // without lag and only the pressure's ringing is smoothed.
        m_raw = load_moment(r, row, &R) / (g * fmax(R, RCL_R_MIN));
        // On or near an end stop the lift pressure is load plus the stop's
        // force (with the valve still open, the pump's pressure: 20.6 MPa read
        // as 131 % of a 200 kg load on the sandbox), so it is not taken there.
        r->x_lift = crane_stroke(&r->m->mech.act[0], row[COL_Q1]);
    }
    r->R = R;
    const double t = row[COL_T];
    const bool trust = r->x_lift > RCL_STOP_BAND && r->x_lift < r->stroke - RCL_STOP_BAND;
    r->held = !trust;
    // Two first-order stages of RCL_TAU / 2: the same 1 s lag to a step as
    // one stage of RCL_TAU, but the booms' ringing on the oil (2.5 Hz on
    // the shipped crane, the lift pressure swinging by +-10 MPa) is cut to
    // 1.6 % instead of 6 %.
    const double rd = r->chain ? rd_chain : outreach_rate(r, row);
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
    const double cap = loadchart_capacity(&r->chart, R, row_slew(r, row), NULL);
    r->util = cap > 0 ? load / cap : (r->m_filt > 0 ? 1e3 : 0.0);
    if (!isfinite(r->util)) r->util = 1e3;
    // Ahead: the weakest chart point the tip can reach within RCL_LOOK_T,
    // either way, at the envelope of its outreach speed (the speed itself
    // rings with the booms, through zero twice a period). The chart can
    // drop by a third within a few centimetres (docs/safety.md: a branch of
    // poses begins at a corner of the workspace); a limiter that only looks
    // where the tip is would see the drop when it is past it.
    const double look = r->rd_env * RCL_LOOK_T;
    const double cap_ahead = capacity_min(&r->chart, R - look, R + look, row_slew(r, row));
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
        const double s = row_slew(r, row);
        const double here = loadchart_capacity(&r->chart, R, s, NULL);
        const double there = loadchart_capacity(&r->chart, R, s + (u_out[2] > 0 ? 1 : -1) * RCL_SLEW_LOOK, NULL);
        if (there < here) u_out[2] *= allow(there > 0 ? u * here / there : 1e3);
    }
    r->stopped = false;
    for (int k = 0; k < 3; ++k)
        if (u_out[k] != u_in[k]) r->stopped = true;
    return u;
}

double rcl_function_gain(rcl* r, const double* row, int f) {
    double R;
    if (!r->chain || f < 0 || f >= r->m->chain.nfn || !chain_pose(r, row, &R)) return 0.0;
    const lc_chain* g = r->g;
    // dR/ds of each of the function's cylinders (its joint's dR/dq over the
    // cylinder's dL/dq), summed: a positive command extends them all.
    double s = 0;
    for (int k = 0; k < g->na; ++k) {
        if (r->m->chain.act[k].function != f) continue;
        const double lev = g->lever[k];
        if (fabs(lev) > 1e-6) s += g->J[g->act_dof[k]] / lev;
    }
    // Below 1 mm per metre the motion leaves the moment as it is: let through.
    return fabs(s) < 1e-3 ? 0.0 : s;
}

double rcl_filter_fn(rcl* r, const double* row, int n, const double* u_in, double* u_out, int islew) {
    if (!r->chain) { // the two-link crane: its three commands
        double a[3] = {0, 0, 0}, b[3];
        for (int k = 0; k < 3 && k < n; ++k) a[k] = u_in[k];
        const double u = rcl_filter(r, row, a, b);
        for (int k = 0; k < n; ++k) u_out[k] = k < 3 ? b[k] : u_in[k];
        return u;
    }
    const double u = rcl_utilisation(r, row), t = row[COL_T];
    for (int k = 0; k < n; ++k) u_out[k] = u_in[k];
    // The slow-down, its ramp and the stop as rcl_filter's.
    double a = allow(r->util_ahead);
    if (r->t_allow > 0 && t >= r->t_allow) {
        const double da = (t - r->t_allow) / RCL_RAMP;
        if (u < 1.0) a = fmax(a, r->allow - da);
        a = fmin(a, r->allow + da);
    }
    r->allow = a, r->t_allow = t;
    const int nfn = r->m->chain.nfn;
    for (int f = 0; f < n && f < nfn; ++f) {
        if (f == islew) continue;
        r->gain[f] = rcl_function_gain(r, row, f);
        if (u_out[f] * r->gain[f] > 0) u_out[f] *= a;
    }
    if (islew >= 0 && islew < n && u_out[islew] != 0 && r->chart.stab) {
        const double R = r->R, s = row_slew(r, row);
        const double here = loadchart_capacity(&r->chart, R, s, NULL);
        const double there = loadchart_capacity(&r->chart, R, s + (u_out[islew] > 0 ? 1 : -1) * RCL_SLEW_LOOK, NULL);
        if (there < here) u_out[islew] *= allow(there > 0 ? u * here / there : 1e3);
    }
    r->stopped = false;
    for (int k = 0; k < n; ++k)
        if (u_out[k] != u_in[k]) r->stopped = true;
    return u;
}
