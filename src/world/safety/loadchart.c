// loadchart.c: rated capacity against outreach (loadchart.h, docs/safety.md).
#include "loadchart.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


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

int loadchart_cylinder_reliefs(const hyd_model* hm, int cyl, double p[2]) {
    for (int c = 0; c < 2; ++c) {
        p[c] = NAN;
        const int node = hyd_model_comp_node(hm, hyd_model_cylinder_comp(hm, cyl), c);
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

int loadchart_reliefs(const model* m, int k, double p[2]) { return loadchart_cylinder_reliefs(m->hyd, m->cyl[k], p); }

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
    crane_gravity(&m->mech, 0.0, q, G0);
    crane_gravity(&m->mech, 1.0, q, G1);
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
double lc_edge_moment(const lc_truck* t, int edge, double rho, double s, double mass) {
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
        const double dl = lc_edge_moment(t, edge, rt, slew, 1.0); // m: tip's distance inside
        if (dl >= 0) continue;                                  // a load there cannot tip over this edge
        // Truck and crane only: the hook and rope hang at the tip with the
        // payload, so they are part of the tipping mass m (and of its
        // factor), subtracted once from the chart (loadchart_compute).
        // Counting them here too, as a negative restoring moment, had the
        // chart 40.7 / 1.25 = 32.6 kg low at every outreach.
        const double restoring = lc_edge_moment(t, edge, -t->column_x, 0.0, t->mass) // truck COM at the chassis centre
                                 + lc_edge_moment(t, edge, 0.0, slew, me->column_mass)
                                 + lc_edge_moment(t, edge, r1, slew, me->link[0].mass)
                                 + lc_edge_moment(t, edge, r2, slew, me->link[1].mass);
        // sf * m (-dl) <= restoring
        const double lim = restoring > 0 ? restoring / (sf * -dl) : 0.0;
        best = fmin(best, lim);
    }
    return best;
}

void loadchart_reach(const model* m, double* rmin, double* rmax) {
    if (!m->chain.two_link) {
        lc_chain_reach(m, rmin, rmax);
        return;
    }
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

int lc_chart_alloc(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz) {
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
    c->rated_moment = 1e3 * m->mech.rated_moment, c->rated_load = m->mech.rated_load, c->gravity = m->mech.gravity;
    const size_t nn = (size_t)c->n * (size_t)c->nsec;
    c->env = malloc(sizeof *c->env * nn);
    c->chart = malloc(sizeof *c->chart * nn);
    c->cap = malloc(sizeof *c->cap * nn);
    c->gov = malloc(sizeof *c->gov * nn);
    c->gov_at = malloc(sizeof *c->gov_at * nn);
    if (c->truck) {
        c->stab = malloc(sizeof *c->stab * nn);
        c->stab_q = malloc(sizeof *c->stab_q * nn);
    }
    if (!c->env || !c->chart || !c->cap || !c->gov || !c->gov_at || (c->truck && (!c->stab || !c->stab_q))) {
        snprintf(err, errsz, "out of memory for the load chart");
        loadchart_free(c);
        return -1;
    }
    return 0;
}

void lc_chart_print(loadchart* c) {
    // The printed chart, per sector. First min(raw envelope, rating) at each
    // point, what the crane may lift there. The chart starts at the
    // sector's minimum working outreach, where that value is largest (the
    // first such point: a plateau at the rated load starts where the crane
    // first holds it), and from there outward it is the running minimum
    // (held down by every closer outreach of the chart): a chart that rises
    // with outreach invites the operator to reach out to lift more (the
    // limiter rates outreach, not the way the booms got there), and the
    // running minimum is the largest non-increasing curve under the capped
    // envelope. Closer in than the peak the value falls towards the column
    // (on the shipped crane the folded jib: 1183 kg at 0.5 m); a running
    // minimum from there would hold the whole chart down to it (out to
    // 2.45 m), so those points are not printed (NAN) and the limiter takes
    // min(envelope, rating) at the point itself (cap). The raw envelope is
    // kept beside it.
    for (int s = 0; s < c->nsec; ++s) {
        int i0 = 0;
        for (int i = 0; i < c->n; ++i) {
            const size_t k = (size_t)i * c->nsec + s;
            const double st = c->stab ? c->stab[k] : INFINITY;
            const int gh = c->chain ? LC_GOV_ACT + c->hyd_cyl[i] : (c->hyd_cyl[i] ? LC_GOV_JIB : LC_GOV_LIFT);
            int g = st < c->hyd[i] ? LC_GOV_STAB : gh;
            c->env[k] = fmin(c->hyd[i], st);
            double v = c->env[k];
            if (c->rating[i] < v) v = c->rating[i], g = LC_GOV_RATED;
            c->cap[k] = v, c->gov[k] = g, c->gov_at[k] = i;
            if (v > c->cap[(size_t)i0 * c->nsec + s]) i0 = i;
        }
        c->imin[s] = i0;
        for (int i = 0; i < c->n; ++i) {
            const size_t k = (size_t)i * c->nsec + s;
            if (i < i0) {
                c->chart[k] = NAN;
                continue;
            }
            if (i > i0 && c->cap[k - c->nsec] < c->cap[k]) {
                c->cap[k] = c->cap[k - c->nsec];
                c->gov[k] = c->gov[k - c->nsec], c->gov_at[k] = c->gov_at[k - c->nsec];
            }
            c->chart[k] = c->cap[k];
        }
    }
}

int loadchart_compute(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz) {
    memset(c, 0, sizeof *c);
    if (lc_check_opts(o, err, errsz)) return -1;
    if (!m->chain.two_link) return lc_chain_compute(m, t, o, c, err, errsz);
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
    if (lc_chart_alloc(m, t, o, c, err, errsz)) return -1;
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
            const size_t k = (size_t)i * c->nsec + s;
            double st = INFINITY;
            c->stab_q[k][0] = c->hyd_q[i][0], c->stab_q[k][1] = c->hyd_q[i][1];
            c->stab_q[k][2] = 0.5 * (c->sec_lo[s] + c->sec_hi[s]);
            for (int j = 0; j < LC_NSLEW; ++j) {
                const double sl = c->sec_lo[s] + (c->sec_hi[s] - c->sec_lo[s]) * j / (LC_NSLEW - 1);
                for (int p = 0; p < np; ++p) {
                    const double l = loadchart_stab_pose(m, t, pose[p][0], pose[p][1], sl, o->sf);
                    if (l < st) st = l, c->stab_q[k][0] = pose[p][0], c->stab_q[k][1] = pose[p][1], c->stab_q[k][2] = sl;
                }
            }
            // The hook and rope once: the pose's limit is the whole tip mass.
            c->stab[k] = isinf(st) ? INFINITY : fmax(0.0, st - c->hook_mass);
        }
        c->rating[i] = loadchart_rating(c, R);
    }
    lc_chart_print(c);
    return 0;
}

double loadchart_rating(const loadchart* c, double R) {
    double r = INFINITY;
    if (c->rated_load > 0) r = c->rated_load;
    // The rated moment is the maker's load moment M = m g R, about the slew
    // axis (R: outreach [m], g from the model).
    if (c->rated_moment > 0 && R > 0) r = fmin(r, c->rated_moment / (c->gravity * R));
    return isinf(r) ? r : fmax(0.0, r - c->hook_mass);
}

void loadchart_point_pose(const loadchart* c, int i, int s, double q[3]) {
    const size_t k = (size_t)i * c->nsec + s;
    const int j = c->gov_at[k];
    const size_t kj = (size_t)j * c->nsec + s;
    const bool stab = c->gov[k] == LC_GOV_STAB || (c->gov[k] == LC_GOV_RATED && c->stab && c->stab[kj] < c->hyd[j]);
    if (stab) {
        q[0] = c->stab_q[kj][0], q[1] = c->stab_q[kj][1], q[2] = c->stab_q[kj][2];
    } else {
        q[0] = c->hyd_q[j][0], q[1] = c->hyd_q[j][1], q[2] = 0.5 * (c->sec_lo[s] + c->sec_hi[s]);
    }
}

const char* lc_gov_name(int gov) {
    switch (gov) {
    case LC_GOV_LIFT: return "lift";
    case LC_GOV_JIB: return "jib";
    case LC_GOV_STAB: return "stability";
    case LC_GOV_RATED: return "rated";
    default: return gov >= LC_GOV_ACT ? "actuator" : "?";
    }
}

void loadchart_free(loadchart* c) {
    free(c->stab), free(c->stab_q), free(c->env), free(c->chart), free(c->cap), free(c->gov), free(c->gov_at);
    c->stab = NULL, c->stab_q = NULL, c->env = c->chart = c->cap = NULL, c->gov = c->gov_at = NULL;
    free(c->dof_name), free(c->act_name), free(c->dof_prismatic), free(c->dof_range), free(c->pose), free(c->stab_pose), free(c->npose);
    c->dof_name = c->act_name = NULL, c->dof_prismatic = NULL, c->dof_range = NULL, c->pose = c->stab_pose = NULL, c->npose = NULL;
}

const char* loadchart_gov_name(const loadchart* c, int gov) {
    if (c->chain && gov >= LC_GOV_ACT && gov < LC_GOV_ACT + c->nact) return c->act_name[gov - LC_GOV_ACT];
    return lc_gov_name(gov);
}

void loadchart_point_pose_chain(const loadchart* c, int i, int s, double* q, double* slew) {
    const size_t k = (size_t)i * c->nsec + s;
    const int j = c->gov_at[k];
    const size_t kj = (size_t)j * c->nsec + s;
    // As loadchart_point_pose: the stability limit's pose where it governs
    // (or where the rating does over a stability limit below the hydraulic
    // one), else the hydraulic limit's at the sector's middle.
    const bool stab = c->gov[k] == LC_GOV_STAB || (c->gov[k] == LC_GOV_RATED && c->stab && c->stab[kj] < c->hyd[j]);
    const double* p = stab ? c->stab_pose + kj * (size_t)c->nd : c->pose + (size_t)j * (size_t)c->nd;
    for (int d = 0; d < c->nd; ++d) q[d] = p[d];
    *slew = stab ? c->stab_q[kj][2] : 0.5 * (c->sec_lo[s] + c->sec_hi[s]);
}

int loadchart_sector(const loadchart* c, double slew) {
    double a = fmod(fabs(slew), 2 * M_PI);
    if (a > M_PI) a = 2 * M_PI - a;
    for (int s = 0; s < c->nsec; ++s)
        if (a <= c->sec_hi[s] + 1e-12) return s;
    return c->nsec - 1;
}

// The chart's interval for outreach R: i and the weight w of point i + 1.
static int interval(const loadchart* c, double R, double* w) {
    double f = (R - c->R[0]) / (c->R[c->n - 1] - c->R[0]) * (c->n - 1);
    if (!(f > 0)) f = 0;
    if (f > c->n - 1) f = c->n - 1;
    int i = (int)floor(f);
    if (i >= c->n - 1) i = c->n - 2;
    *w = f - i;
    return i;
}

// Linear interpolation of an n x nsec column, INFINITY kept as such.
static double interp(const loadchart* c, const double* col, int i, double w, int s) {
    const double a = col[(size_t)i * c->nsec + s], b = col[(size_t)(i + 1) * c->nsec + s];
    return (isinf(a) || isinf(b)) ? fmin(a, b) : a * (1 - w) + b * w;
}

double loadchart_capacity(const loadchart* c, double R, double slew, int* gov) {
    double w;
    const int i = interval(c, R, &w), s = loadchart_sector(c, slew);
    // From the minimum outreach on the chart is non-increasing, so is its
    // interpolation; closer in, min(envelope, rating) interpolated as the
    // envelope always was. The rating is convex in R (M / (g R)), so its
    // chord lies above it: capped by the rating at R itself.
    const double v = fmin(interp(c, c->cap, i, w, s), loadchart_rating(c, R));
    if (gov) *gov = c->gov[(size_t)(w >= 1 ? i + 1 : i) * c->nsec + s];
    return v;
}

double loadchart_envelope(const loadchart* c, double R, double slew) {
    double w;
    const int i = interval(c, R, &w);
    return interp(c, c->env, i, w, loadchart_sector(c, slew));
}
