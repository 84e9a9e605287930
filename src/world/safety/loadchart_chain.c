// loadchart_chain.c: the load chart of a crane chain (loadchart_compute's
// part for a model whose chain is not the two-link shorthand; docs/safety.md
// "On a crane chain"): the search over every joint (lc_chain.h) into the
// chart's points, the stability limit per sector, the governing poses.
#include "lc_chain.h"
#include "loadchart.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Slew angles sampled per sector, bounds included (as loadchart.c's).
#define LCC_NSLEW 9

// A pose in a point of the chart, for the stability limit's front (below):
// ordered by point, side of the slew axis, then |R| and sign(R) S1 falling.
typedef struct lcc_entry {
    long i;         ///< the point
    int neg;        ///< R < 0
    double key, s1; ///< |R| [m], sign(R) S1 [kg m]
    long p;         ///< the pose (search's index)
} lcc_entry;

static int entry_cmp(const void* a_, const void* b_) {
    const lcc_entry *a = a_, *b = b_;
    if (a->i != b->i) return a->i < b->i ? -1 : 1;
    if (a->neg != b->neg) return a->neg - b->neg;
    if (a->key != b->key) return a->key > b->key ? -1 : 1;
    if (a->s1 != b->s1) return a->s1 > b->s1 ? -1 : 1;
    return a->p < b->p ? -1 : a->p > b->p;
}

void lc_chain_reach(const model* m, double* rmin, double* rmax) {
    lc_chain g;
    char err[300];
    *rmin = *rmax = NAN;
    if (lc_chain_init(&g, m, "load chart", err, sizeof err) || lc_chain_grid_size(&g) > LC_CHAIN_MAX_POSES) {
        lc_chain_free(&g);
        return;
    }
    long n;
    lcc_pose* P = lc_chain_search(&g, 0.0, false, &n);
    double lo = INFINITY, hi = -INFINITY;
    for (long i = 0; P && i < n; ++i) lo = fmin(lo, P[i].R), hi = fmax(hi, P[i].R);
    if (lo <= hi) *rmin = lo, *rmax = hi;
    free(P);
    lc_chain_free(&g);
}

// Stability limit [kg at the tip] of a pose whose tip is at outreach Rt [m]
// and whose crane masses M [kg] have first moment S1 [kg m] along the boom,
// at slew s [rad]: as loadchart_stab_pose, the crane's bodies at their
// centres of mass (the moment about an edge is linear in the distance, so
// the bodies sum to M at S1 / M).
static double stab_lim(const lc_truck* t, double Rt, double S1, double M, double s, double sf) {
    double best = INFINITY;
    for (int edge = 0; edge < 4; ++edge) {
        const double dl = lc_edge_moment(t, edge, Rt, s, 1.0);
        if (dl >= 0) continue;
        const double restoring =
            lc_edge_moment(t, edge, -t->column_x, 0.0, t->mass) + (M > 0 ? lc_edge_moment(t, edge, S1 / M, s, M) : 0.0);
        best = fmin(best, restoring > 0 ? restoring / (sf * -dl) : 0.0);
    }
    return best;
}

int lc_chain_compute(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz) {
    lc_chain g;
    if (lc_chain_init(&g, m, "load chart", err, errsz)) return -1;
    const int nd = g.nd;
    if (lc_chain_grid_size(&g) > LC_CHAIN_MAX_POSES) {
        char grid[200] = "";
        for (int j = 0, w = 0; j < nd && w >= 0 && (size_t)w < sizeof grid; ++j)
            w += snprintf(grid + w, sizeof grid - (size_t)w, "%s%d", j ? " x " : "", lc_chain_grid_n(&g, j));
        snprintf(err, errsz, "%s: load chart: the search over every joint of its %d booms would cover %ld poses (%s); "
                             "at most %ld",
                 m->file[0] ? m->file : "model", nd, lc_chain_grid_size(&g), grid, LC_CHAIN_MAX_POSES);
        lc_chain_free(&g);
        return -1;
    }
    const bool truck = t && t->present;
    long np = 0;
    lcc_pose* P = lc_chain_search(&g, o->margin, truck, &np);
    if (!P) {
        snprintf(err, errsz, "out of memory for the load chart's search");
        lc_chain_free(&g);
        return -1;
    }
    double rmin = INFINITY, rmax = -INFINITY;
    for (long p = 0; p < np; ++p) rmin = fmin(rmin, P[p].R), rmax = fmax(rmax, P[p].R);
    if (!(o->lo >= rmin - 1e-9 && o->hi <= rmax + 1e-9)) {
        snprintf(err, errsz, "--outreach: %g:%g m is outside the crane's reach [%.3f, %.3f] m", o->lo, o->hi, rmin,
                 rmax);
        free(P);
        lc_chain_free(&g);
        return -1;
    }
    if (lc_chart_alloc(m, t, o, c, err, errsz)) {
        free(P);
        lc_chain_free(&g);
        return -1;
    }
    c->reach_min = rmin, c->reach_max = rmax;
    c->gravity = m->chain.gravity;
    c->chain = true, c->nd = nd, c->nact = g.na, c->nsearch = np;
    const size_t n = (size_t)c->n, ns = (size_t)c->nsec;
    c->dof_name = calloc((size_t)nd + 1, sizeof *c->dof_name);
    c->act_name = calloc((size_t)g.na + 1, sizeof *c->act_name);
    c->dof_prismatic = calloc((size_t)nd + 1, sizeof *c->dof_prismatic);
    c->dof_range = calloc((size_t)nd + 1, sizeof *c->dof_range);
    c->pose = calloc(n * (size_t)nd + 1, sizeof *c->pose);
    c->stab_pose = calloc(n * ns * (size_t)nd + 1, sizeof *c->stab_pose);
    c->npose = calloc(n + 1, sizeof *c->npose);
    long* hyd_at = calloc(n + 1, sizeof *hyd_at);
    long* stab_at = calloc(n * ns + 1, sizeof *stab_at);
    double* cs = malloc(ns * LCC_NSLEW * sizeof *cs + 1);
    if (!c->dof_name || !c->act_name || !c->dof_prismatic || !c->dof_range || !c->pose || !c->stab_pose ||
        !c->npose || !hyd_at || !stab_at || !cs) {
        snprintf(err, errsz, "out of memory for the load chart");
        free(P), free(hyd_at), free(stab_at), free(cs);
        loadchart_free(c);
        lc_chain_free(&g);
        return -1;
    }
    for (int j = 0; j < nd; ++j) {
        const chain_body_def* d = &m->chain.body[g.dof_body[j]].def;
        snprintf(c->dof_name[j], sizeof c->dof_name[j], "%s", d->name);
        c->dof_prismatic[j] = d->joint == CHAIN_PRISMATIC;
        c->dof_range[j][0] = g.q_lo[j], c->dof_range[j][1] = g.q_hi[j];
    }
    for (int k = 0; k < g.na; ++k) snprintf(c->act_name[k], sizeof c->act_name[k], "%s", m->chain.act[k].name);
    for (size_t s = 0; s < ns; ++s)
        for (int j = 0; j < LCC_NSLEW; ++j)
            cs[s * LCC_NSLEW + j] = c->sec_lo[s] + (c->sec_hi[s] - c->sec_lo[s]) * j / (LCC_NSLEW - 1);
    const double step = (o->hi - o->lo) / (c->n - 1);
    for (size_t i = 0; i < n; ++i) {
        c->R[i] = o->lo + step * (double)i;
        c->hyd[i] = INFINITY, c->hyd_cyl[i] = 0, hyd_at[i] = -1;
        for (size_t s = 0; s < ns && c->truck; ++s) c->stab[i * ns + s] = INFINITY, stab_at[i * ns + s] = -1;
    }
    // Each pose into the points within one step of its outreach: point i
    // takes the weakest pose with |R - R_i| < step, so the chart
    // interpolated between two points is never above a pose between them
    // (the limiter knows the outreach, not the pose the operator chose).
    // The stability limit of a pose depends on its outreach R and the first
    // moment S1 of the crane's masses only (stab_lim; their sum M is the same
    // in every pose), and for R >= 0 it never rises as R or S1 grows (an edge
    // the tip is beyond lies on the tip's side of the slew axis, so the
    // tipping lever grows with R and the restoring moment falls with S1;
    // mirrored for R < 0). So the weakest pose of a point lies on the front
    // of poses no other pose of the point exceeds in both |R| and sign(R) S1:
    // only those are rated over the sectors' slew angles (the same minimum
    // as all of them, a few dozen poses a point instead of thousands).
    lcc_entry* E = c->truck ? malloc((size_t)np * 2 * sizeof *E + 1) : NULL;
    if (c->truck && !E) {
        snprintf(err, errsz, "out of memory for the load chart");
        free(P), free(hyd_at), free(stab_at), free(cs);
        loadchart_free(c);
        lc_chain_free(&g);
        return -1;
    }
    size_t ne = 0;
    for (long p = 0; p < np; ++p) {
        const lcc_pose* P_ = &P[p];
        const long i0 = (long)floor((P_->R - o->lo) / step);
        for (long i = i0; i <= i0 + 1; ++i) {
            if (i < 0 || i >= c->n || fabs(P_->R - c->R[i]) >= step) continue;
            ++c->npose[i];
            // hyd -1: the booms alone overload an actuator here (a chart of 0).
            if (P_->hyd < c->hyd[i]) c->hyd[i] = P_->hyd, c->hyd_cyl[i] = P_->gov, hyd_at[i] = P_->at;
            if (E) {
                const double sg = P_->R >= 0 ? 1.0 : -1.0;
                E[ne++] = (lcc_entry){.i = i, .neg = P_->R < 0, .key = sg * P_->R, .s1 = sg * P_->S1, .p = p};
            }
        }
    }
    if (E) {
        qsort(E, ne, sizeof *E, entry_cmp);
        double run = -INFINITY;
        for (size_t e = 0; e < ne; ++e) {
            if (e == 0 || E[e].i != E[e - 1].i || E[e].neg != E[e - 1].neg) run = -INFINITY;
            if (!(E[e].s1 > run)) continue; // another pose of the point exceeds it in both
            run = E[e].s1;
            const lcc_pose* P_ = &P[E[e].p];
            const size_t i = (size_t)E[e].i;
            for (size_t s = 0; s < ns; ++s) {
                const size_t k = i * ns + s;
                for (int j = 0; j < LCC_NSLEW; ++j) {
                    const double sl = cs[s * LCC_NSLEW + j], l = stab_lim(t, P_->R, P_->S1, P_->M, sl, o->sf);
                    if (l < c->stab[k]) c->stab[k] = l, c->stab_q[k][2] = sl, stab_at[k] = P_->at;
                }
            }
        }
        free(E);
    }
    free(P), free(cs);
    int rc = 0;
    for (size_t i = 0; i < n && !rc; ++i) {
        if (!c->npose[i]) {
            snprintf(err, errsz, "--outreach: no pose of the crane reaches %g m (reach [%.3f, %.3f] m)", c->R[i],
                     c->reach_min, c->reach_max);
            rc = -1;
            break;
        }
        double* q = c->pose + i * (size_t)nd;
        lc_chain_grid_pose(&g, hyd_at[i], q);
        // The payload: the hook and rope hang at the tip with it, once.
        c->hyd[i] = fmax(0.0, c->hyd[i] - c->hook_mass);
        c->hyd_q[i][0] = q[0], c->hyd_q[i][1] = nd > 1 ? q[1] : 0.0;
        for (size_t s = 0; s < ns && c->truck; ++s) {
            const size_t k = i * ns + s;
            double* qs = c->stab_pose + k * (size_t)nd;
            if (stab_at[k] < 0) { // the tip inside the polygon at every pose: the hydraulic limit's pose
                memcpy(qs, q, (size_t)nd * sizeof *q);
                c->stab_q[k][2] = 0.5 * (c->sec_lo[s] + c->sec_hi[s]);
            } else {
                lc_chain_grid_pose(&g, stab_at[k], qs);
                c->stab[k] = fmax(0.0, c->stab[k] - c->hook_mass);
            }
            c->stab_q[k][0] = qs[0], c->stab_q[k][1] = nd > 1 ? qs[1] : 0.0;
        }
        c->rating[i] = loadchart_rating(c, c->R[i]);
    }
    free(hyd_at), free(stab_at);
    lc_chain_free(&g);
    if (rc) {
        loadchart_free(c);
        return -1;
    }
    lc_chart_print(c);
    return 0;
}
