// loadchart.c: rated capacity against outreach (loadchart.h, docs/safety.md).
#include "loadchart.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagrange.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// The chamber that does not carry the load sits at the static start's
// pressure (the run's initial state), 0.5 MPa abs.
#define LC_P_LOW 0.5e6
// Lifting-arm angles searched per outreach: 0.5 deg steps over a 90 deg range.
#define LC_NQ1 181
// Slew angles sampled per sector, bounds included.
#define LC_NSLEW 9

lc_opts lc_default_opts(void) {
    lc_opts o = {.margin = 0.10, .sf = 1.25, .lo = 0, .hi = 0, .n = 50, .sectors = 3};
    return o;
}

int lc_check_opts(const lc_opts* o, char* err, size_t errsz) {
    if (!(o->margin >= 0 && o->margin <= 0.5)) {
        snprintf(err, errsz, "--margin: must be in [0, 0.5] (a fraction of the relief setting), got %g", o->margin);
        return -1;
    }
    if (!(o->sf > 1 && o->sf <= 10)) {
        snprintf(err, errsz, "--stability-factor: must be in (1, 10] (restoring over tipping moment), got %g", o->sf);
        return -1;
    }
    if (o->n < 2 || o->n > LOADCHART_MAX_POINTS) {
        snprintf(err, errsz, "--outreach: N must be in [2, %d] points, got %d", LOADCHART_MAX_POINTS, o->n);
        return -1;
    }
    if (!(isfinite(o->lo) && isfinite(o->hi) && o->lo >= 0 && o->hi > o->lo)) {
        snprintf(err, errsz, "--outreach: need 0 <= LO < HI [m], got %g:%g", o->lo, o->hi);
        return -1;
    }
    if (o->sectors < 1 || o->sectors > LOADCHART_MAX_SECTORS) {
        snprintf(err, errsz, "--sectors: must be in [1, %d], got %d", LOADCHART_MAX_SECTORS, o->sectors);
        return -1;
    }
    return 0;
}

void lc_truck_from_world(const world_desc* wd, lc_truck* t) {
    memset(t, 0, sizeof *t);
    if (!wd || wd->kind != WORLD_SANDBOX) return;
    const world_truck* k = &wd->truck;
    t->present = true;
    t->mass = k->mass;
    t->column_x = k->column_x;
    if (k->outriggers) {
        t->edge_x[0] = fmax(k->outrigger_x[0], k->outrigger_x[1]);
        t->edge_x[1] = fmin(k->outrigger_x[0], k->outrigger_x[1]);
        t->edge_y = 0.5 * k->outrigger_span;
    } else {
        t->edge_x[0] = fmax(k->wheel_x[0], k->wheel_x[1]);
        t->edge_x[1] = fmin(k->wheel_x[0], k->wheel_x[1]);
        t->edge_y = 0.5 * k->track;
    }
    t->hook_mass = wd->hook.mass + wd->rope.mass_per_m * wd->rope.length;
}

int loadchart_reliefs(const model* m, int k, double p[2]) {
    const hyd_model* hm = m->hyd;
    for (int c = 0; c < 2; ++c) {
        p[c] = NAN;
        const int node = hyd_model_comp_node(hm, hyd_model_cylinder_comp(hm, m->cyl[k]), c);
        for (int i = 0; i < hyd_model_ncomp(hm); ++i) {
            if (hyd_model_comp_type(hm, i) != HYD_RELIEF || hyd_model_relief_inlet(hm, i) != node) continue;
            char path[160];
            double v;
            snprintf(path, sizeof path, "%s.p_crack", hyd_model_comp_name(hm, i));
            if (hyd_model_get(hm, path, &v) == 0) p[c] = isnan(p[c]) ? v : fmin(p[c], v);
        }
        if (isnan(p[c])) return -1;
    }
    return 0;
}

// Joint range of actuator k: the joint angles at zero and full stroke [rad].
static void joint_range(const model* m, int k, double* lo, double* hi) {
    double a = crane_joint_for_stroke(&m->mech.act[k], 0.0);
    double b = crane_joint_for_stroke(&m->mech.act[k], m->stroke[k]);
    *lo = fmin(a, b);
    *hi = fmax(a, b);
}

double loadchart_hyd_pose(const model* m, double q1, double q2, double margin, int* gov) {
    const double q[2] = {q1, q2};
    double G0[2], G1[2];
    lagrange_gravity(&m->mech, LAGRANGE_FULL, 0.0, q, G0);
    lagrange_gravity(&m->mech, LAGRANGE_FULL, 1.0, q, G1);
    double best = INFINITY;
    int g = 0;
    for (int k = 0; k < 2; ++k) {
        double AA, AB, st, r, pr[2];
        hyd_model_cylinder_geometry(m->hyd, m->cyl[k], &AA, &AB, &st);
        crane_pin_length(&m->mech.act[k], q[k], &r);
        if (loadchart_reliefs(m, k, pr)) return -1;
        // Holding force F = G / r [N] (F > 0: chamber A carries it). The
        // pressure stays below pmax in A while F <= pmax AA - p_low AB, and
        // in B while -F <= pmax AB - p_low AA.
        const double fmax_ = (1 - margin) * pr[0] * AA - LC_P_LOW * AB;
        const double fmin_ = -((1 - margin) * pr[1] * AB - LC_P_LOW * AA);
        const double f0 = G0[k] / r, df = (G1[k] - G0[k]) / r; // N, N/kg
        if (f0 > fmax_ || f0 < fmin_) return -1;
        double lim = INFINITY;
        if (df > 0) lim = (fmax_ - f0) / df;
        else if (df < 0) lim = (fmin_ - f0) / df;
        if (lim < best) best = lim, g = k;
    }
    if (gov) *gov = g;
    return best;
}

// Mass moment [kg m] about a support edge: mass times its distance inside
// the polygon (negative outside), for a mass at horizontal distance rho [m]
// from the slew axis along slew angle s.
static double edge_moment(const lc_truck* t, int edge, double rho, double s, double mass) {
    const double x = t->column_x + rho * cos(s), y = rho * sin(s);
    double d;
    switch (edge) {
    case 0: d = t->edge_x[0] - x; break; // front
    case 1: d = x - t->edge_x[1]; break; // rear
    case 2: d = t->edge_y - y; break;    // left
    default: d = t->edge_y + y; break;   // right
    }
    return mass * d;
}

double loadchart_stab_pose(const model* m, const lc_truck* t, double q1, double q2, double slew, double sf) {
    const crane_mech* me = &m->mech;
    const double L1 = me->link[0].length, e1 = me->link[0].com, L2 = me->link[1].length, e2 = me->link[1].com;
    const double r1 = e1 * sin(q1), r2 = L1 * sin(q1) + e2 * sin(q1 + q2), rt = L1 * sin(q1) + L2 * sin(q1 + q2);
    double best = INFINITY;
    for (int edge = 0; edge < 4; ++edge) {
        const double dl = edge_moment(t, edge, rt, slew, 1.0); // m: tip's distance inside
        if (dl >= 0) continue;                                  // a load there cannot tip over this edge
        const double restoring = edge_moment(t, edge, -t->column_x, 0.0, t->mass) // truck COM at the chassis centre
                                 + edge_moment(t, edge, 0.0, slew, me->column_mass)
                                 + edge_moment(t, edge, r1, slew, me->link[0].mass)
                                 + edge_moment(t, edge, r2, slew, me->link[1].mass)
                                 + edge_moment(t, edge, rt, slew, t->hook_mass);
        // sf * m (-dl) <= restoring
        const double lim = restoring > 0 ? restoring / (sf * -dl) : 0.0;
        best = fmin(best, lim);
    }
    return best;
}

void loadchart_reach(const model* m, double* rmin, double* rmax) {
    double q1lo, q1hi, q2lo, q2hi, x, z;
    joint_range(m, 0, &q1lo, &q1hi);
    joint_range(m, 1, &q2lo, &q2hi);
    *rmin = INFINITY, *rmax = -INFINITY;
    for (int i = 0; i <= 200; ++i)
        for (int j = 0; j <= 200; ++j) {
            crane_tip(&m->mech, q1lo + (q1hi - q1lo) * i / 200.0, q2lo + (q2hi - q2lo) * j / 200.0, &x, &z);
            *rmin = fmin(*rmin, x), *rmax = fmax(*rmax, x);
        }
}

// The poses reaching outreach R [m]: for each lifting-arm angle on the grid,
// the end-arm angles with L1 sin q1 + L2 sin(q1 + q2) = R inside q2's range;
// and, solved exactly, the poses with the end arm at either end of its
// stroke. Those edges matter: beyond about 2.9 m the weakest pose has the
// jib cylinder fully out (its smallest lever arm), a curve a grid over q1
// meets only by chance (the 0.5 deg grid alone missed it by up to 14 %).
static int poses_at(const model* m, double R, double (*pose)[2], int cap) {
    double q1lo, q1hi, q2lo, q2hi;
    joint_range(m, 0, &q1lo, &q1hi);
    joint_range(m, 1, &q2lo, &q2hi);
    const double L1 = m->mech.link[0].length, L2 = m->mech.link[1].length;
    int np = 0;
    for (int i = 0; i < LC_NQ1; ++i) {
        const double q1 = q1lo + (q1hi - q1lo) * i / (LC_NQ1 - 1);
        const double s = (R - L1 * sin(q1)) / L2;
        if (s < -1 || s > 1) continue;
        const double a0 = asin(s), cand[2] = {a0, M_PI - a0};
        for (int c = 0; c < 2; ++c)
            for (int w = -2; w <= 2; ++w) {
                const double q2 = cand[c] + 2 * M_PI * w - q1;
                if (q2 >= q2lo - 1e-12 && q2 <= q2hi + 1e-12 && np < cap) pose[np][0] = q1, pose[np][1] = q2, ++np;
            }
    }
    // q2 fixed: (L1 + L2 cos q2) sin q1 + L2 sin q2 cos q1 = rho sin(q1 + phi) = R.
    const double q2e[2] = {q2lo, q2hi};
    for (int e = 0; e < 2; ++e) {
        const double A = L1 + L2 * cos(q2e[e]), B = L2 * sin(q2e[e]), rho = hypot(A, B), phi = atan2(B, A);
        if (!(rho > 0) || fabs(R) > rho) continue;
        const double a0 = asin(R / rho), cand[2] = {a0 - phi, M_PI - a0 - phi};
        for (int c = 0; c < 2; ++c)
            for (int w = -2; w <= 2; ++w) {
                const double q1 = cand[c] + 2 * M_PI * w;
                if (q1 >= q1lo - 1e-12 && q1 <= q1hi + 1e-12 && np < cap)
                    pose[np][0] = fmin(fmax(q1, q1lo), q1hi), pose[np][1] = q2e[e], ++np;
            }
    }
    return np;
}

int loadchart_compute(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz) {
    memset(c, 0, sizeof *c);
    if (lc_check_opts(o, err, errsz)) return -1;
    for (int k = 0; k < 2; ++k) {
        double pr[2];
        if (loadchart_reliefs(m, k, pr)) {
            snprintf(err, errsz, "%s: no port relief on a chamber of cylinder '%s': no hydraulic limit",
                     m->file[0] ? m->file : "model", hyd_model_comp_name(m->hyd, hyd_model_cylinder_comp(m->hyd, m->cyl[k])));
            return -1;
        }
    }
    loadchart_reach(m, &c->reach_min, &c->reach_max);
    if (o->lo < c->reach_min - 1e-9 || o->hi > c->reach_max + 1e-9) {
        snprintf(err, errsz, "--outreach: %g:%g m is outside the crane's reach [%.3f, %.3f] m", o->lo, o->hi,
                 c->reach_min, c->reach_max);
        return -1;
    }
    c->n = o->n;
    c->truck = t && t->present;
    c->nsec = c->truck ? o->sectors : 1;
    c->hook_mass = c->truck ? t->hook_mass : 0.0;
    for (int s = 0; s < c->nsec; ++s) {
        // Sector s centred on s pi / (K - 1) (0: over the cab, pi: over the
        // rear), bounds half-way between centres.
        if (c->nsec == 1) {
            c->sec_lo[s] = 0, c->sec_hi[s] = M_PI;
        } else {
            const double w = M_PI / (c->nsec - 1);
            c->sec_lo[s] = fmax(0.0, (s - 0.5) * w), c->sec_hi[s] = fmin(M_PI, (s + 0.5) * w);
        }
    }
    if (c->truck) {
        c->stab = malloc(sizeof *c->stab * (size_t)c->n * (size_t)c->nsec);
        if (!c->stab) {
            snprintf(err, errsz, "out of memory for the load chart");
            return -1;
        }
    }
    static double pose[LC_NQ1 * 10 + 40][2];
    for (int i = 0; i < c->n; ++i) {
        const double R = o->lo + (o->hi - o->lo) * i / (c->n - 1);
        c->R[i] = R;
        const int np = poses_at(m, R, pose, LC_NQ1 * 10 + 40);
        double hyd = INFINITY;
        int gov = 0;
        for (int p = 0; p < np; ++p) {
            int g;
            const double l = loadchart_hyd_pose(m, pose[p][0], pose[p][1], o->margin, &g);
            if (l < hyd) hyd = l, gov = g, c->hyd_q[i][0] = pose[p][0], c->hyd_q[i][1] = pose[p][1];
        }
        // Every pose at this outreach must hold the rated load: the limiter
        // knows the outreach, not which pose the operator will choose.
        c->hyd[i] = np ? fmax(0.0, hyd - c->hook_mass) : NAN;
        c->hyd_cyl[i] = gov;
        if (!np) {
            snprintf(err, errsz, "--outreach: no pose of the crane reaches %g m (reach [%.3f, %.3f] m)", R,
                     c->reach_min, c->reach_max);
            loadchart_free(c);
            return -1;
        }
        for (int s = 0; s < c->nsec && c->truck; ++s) {
            double st = INFINITY;
            for (int j = 0; j < LC_NSLEW; ++j) {
                const double sl = c->sec_lo[s] + (c->sec_hi[s] - c->sec_lo[s]) * j / (LC_NSLEW - 1);
                for (int p = 0; p < np; ++p) st = fmin(st, loadchart_stab_pose(m, t, pose[p][0], pose[p][1], sl, o->sf));
            }
            c->stab[(size_t)i * c->nsec + s] = isinf(st) ? INFINITY : fmax(0.0, st - c->hook_mass);
        }
    }
    return 0;
}

void loadchart_free(loadchart* c) {
    free(c->stab);
    c->stab = NULL;
}

int loadchart_sector(const loadchart* c, double slew) {
    double a = fmod(fabs(slew), 2 * M_PI);
    if (a > M_PI) a = 2 * M_PI - a;
    for (int s = 0; s < c->nsec; ++s)
        if (a <= c->sec_hi[s] + 1e-12) return s;
    return c->nsec - 1;
}

double loadchart_capacity(const loadchart* c, double R, double slew, bool* stab_governs) {
    double f = (R - c->R[0]) / (c->R[c->n - 1] - c->R[0]) * (c->n - 1);
    if (f < 0) f = 0;
    if (f > c->n - 1) f = c->n - 1;
    int i = (int)floor(f);
    if (i >= c->n - 1) i = c->n - 2;
    const double w = f - i;
    const double h = c->hyd[i] * (1 - w) + c->hyd[i + 1] * w;
    double s = INFINITY;
    if (c->stab) {
        const int k = loadchart_sector(c, slew);
        const double a = c->stab[(size_t)i * c->nsec + k], b = c->stab[(size_t)(i + 1) * c->nsec + k];
        s = (isinf(a) || isinf(b)) ? fmin(a, b) : a * (1 - w) + b * w;
    }
    if (stab_governs) *stab_governs = s < h;
    return fmin(h, s);
}
