// lc_chain.c: a crane chain read for the load chart and the limiter (lc_chain.h).
#include "lc_chain.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "loadchart.h"

// The chamber that does not carry the load sits at the static start's
// pressure (the run's initial state), 0.5 MPa abs, as loadchart.c's.
#define LCC_P_LOW 0.5e6

void lc_chain_free(lc_chain* g) {
    chain_ws_free(g->ws);
    chain_free(g->ch);
    free(g->act_dof), free(g->dof_act), free(g->dof_body), free(g->q_lo), free(g->q_hi);
    free(g->AA), free(g->AB), free(g->stroke), free(g->relief);
    free(g->J), free(g->G0), free(g->Gt), free(g->dL), free(g->lever), free(g->x);
    memset(g, 0, sizeof *g);
}

// The boom DOF the joint of body i is (-1: fixed, or the column).
static int dof_of_body(const lc_chain* g, int i) {
    for (int j = 0; j < g->nd; ++j)
        if (g->dof_body[j] == i) return j;
    return -1;
}

// The boom DOFs between bodies a and b in the tree (the joints on the path,
// each body's own joint up to their common ancestor): their count, the
// last one in *dof.
static int joints_between(const lc_chain* g, int a, int b, int* dof) {
    const crane_body* B = g->cc->body;
    int n = 0;
    while (a != b) {
        // Step up from the deeper one (a parent's index is smaller).
        int* hi = a > b ? &a : &b;
        const int d = dof_of_body(g, *hi);
        if (d >= 0) ++n, *dof = d;
        *hi = B[*hi].def.parent;
        if (*hi < 0) return -1; // not in one tree (chain_create refuses that already)
    }
    return n;
}

int lc_chain_init(lc_chain* g, const model* m, const char* what, char* err, size_t errsz) {
    memset(g, 0, sizeof *g);
    const crane_chain* cc = &m->chain;
    const char* file = m->file[0] ? m->file : "model";
    g->cc = cc;
    g->lift = -1;
    if (cc->two_link) {
        snprintf(err, errsz, "%s: %s: the two-link crane takes the closed form, not the chain's", file, what);
        return -1;
    }
    for (int i = 1; i < cc->nbody; ++i) g->nd += !cc->body[i].def.fixed;
    g->na = cc->nact;
    const size_t nd = (size_t)g->nd, na = (size_t)g->na;
    g->ch = crane_chain_mechanism(cc, 0.0, false, 0.0, err, errsz);
    g->act_dof = calloc(na + 1, sizeof *g->act_dof);
    g->dof_act = calloc(nd + 1, sizeof *g->dof_act);
    g->dof_body = calloc(nd + 1, sizeof *g->dof_body);
    g->q_lo = calloc(nd + 1, sizeof *g->q_lo), g->q_hi = calloc(nd + 1, sizeof *g->q_hi);
    g->AA = calloc(na + 1, sizeof *g->AA), g->AB = calloc(na + 1, sizeof *g->AB);
    g->stroke = calloc(na + 1, sizeof *g->stroke), g->relief = calloc(na + 1, sizeof *g->relief);
    g->J = calloc(3 * nd + 1, sizeof *g->J), g->G0 = calloc(nd + 1, sizeof *g->G0);
    g->Gt = calloc(nd + 1, sizeof *g->Gt), g->dL = calloc(na * nd + 1, sizeof *g->dL);
    g->lever = calloc(na + 1, sizeof *g->lever), g->x = calloc(na + 1, sizeof *g->x);
    if (!g->ch) goto fail_msg;
    g->ws = chain_ws_create(g->ch);
    if (!g->ws || !g->act_dof || !g->dof_act || !g->dof_body || !g->q_lo || !g->q_hi || !g->AA || !g->AB ||
        !g->stroke || !g->relief || !g->J || !g->G0 || !g->Gt || !g->dL || !g->lever || !g->x) {
        snprintf(err, errsz, "out of memory");
        goto fail_msg;
    }
    if (chain_ndof(g->ch) != g->nd) {
        snprintf(err, errsz, "%s: %s: the mechanism has %d boom DOFs, the chain %d", file, what, chain_ndof(g->ch), g->nd);
        goto fail_msg;
    }
    for (int j = 0; j < g->nd; ++j) {
        const int b = chain_dof_body(g->ch, j);
        const chain_body_def* d = &cc->body[b].def;
        g->dof_body[j] = b, g->dof_act[j] = -1;
        if (!(isfinite(d->q_min) && isfinite(d->q_max) && d->q_max > d->q_min)) {
            snprintf(err, errsz, "%s: mechanics.bodies[%d] (%s).limits: the %s searches every pose within the joint "
                                 "limits and needs them finite",
                     file, b, d->name, what);
            goto fail_msg;
        }
        g->q_lo[j] = d->q_min, g->q_hi[j] = d->q_max;
    }
    g->axis_x = cc->body[0].def.origin[0];
    for (int k = 0; k < g->na; ++k) {
        const crane_act* a = &cc->act[k];
        if (a->kind != CRANE_ACT_CYLINDER && a->kind != CRANE_ACT_LINKAGE) {
            snprintf(err, errsz, "%s: mechanics.actuators[%d] (%s): the %s reads pin cylinders and linkages only", file, k, a->name,
                     what);
            goto fail_msg;
        }
        int d = -1;
        const int n = joints_between(g, a->body_a, a->body_b, &d);
        if (n != 1) {
            snprintf(err, errsz, "%s: mechanics.actuators[%d] (%s): moves %d boom joints; the %s needs each actuator "
                                 "on exactly one",
                     file, k, a->name, n < 0 ? 0 : n, what);
            goto fail_msg;
        }
        if (g->dof_act[d] >= 0) {
            snprintf(err, errsz, "%s: mechanics.actuators[%d] (%s): the joint of body '%s' already has actuator '%s'; "
                                 "the %s needs one actuator per boom joint",
                     file, k, a->name, cc->body[g->dof_body[d]].def.name, cc->act[g->dof_act[d]].name, what);
            goto fail_msg;
        }
        g->act_dof[k] = d, g->dof_act[d] = k;
        hyd_model_cylinder_geometry(m->hyd, a->cyl, &g->AA[k], &g->AB[k], &g->stroke[k]);
        if (loadchart_cylinder_reliefs(m->hyd, a->cyl, g->relief[k])) {
            snprintf(err, errsz, "%s: %s: no port relief on a chamber of cylinder '%s': no hydraulic limit", file, what,
                     a->cylinder);
            goto fail_msg;
        }
        if (cc->body[g->dof_body[d]].def.parent == 0 && g->lift < 0) g->lift = k;
    }
    for (int j = 0; j < g->nd; ++j)
        if (g->dof_act[j] < 0) {
            snprintf(err, errsz, "%s: mechanics.bodies[%d] (%s): no actuator moves its joint; the %s needs one per "
                                 "boom joint",
                     file, g->dof_body[j], cc->body[g->dof_body[j]].def.name, what);
            goto fail_msg;
        }
    if (g->lift < 0) {
        snprintf(err, errsz, "%s: %s: no actuator on the joint of a boom on the column (the lift cylinder, whose "
                             "pressures measure the load moment)",
                 file, what);
        goto fail_msg;
    }
    return 0;
fail_msg:
    lc_chain_free(g);
    return -1;
}

bool lc_chain_eval(lc_chain* g, const double* q, double* R, double* z) {
    const crane_chain* cc = g->cc;
    const int nd = g->nd;
    chain_update(g->ch, g->ws, q, NULL);
    double p[3];
    chain_world_point(g->ch, g->ws, cc->tip_body, cc->tip, p, NULL);
    *R = p[0] - g->axis_x; // the column fixed at slew 0: the boom plane is x-z
    if (z) *z = p[2];
    chain_point_jacobian(g->ch, g->ws, cc->tip_body, cc->tip, g->J, NULL);
    // 1 kg at the tip: its potential -g . p, so its gravity force on DOF j
    // is -g . dp/dq_j = gravity J_zj (the base frame's g is (0, 0, -gravity)).
    for (int j = 0; j < nd; ++j) g->Gt[j] = cc->gravity * g->J[2 * nd + j];
    chain_inverse_dynamics(g->ch, g->ws, NULL, CHAIN_GRAVITY, g->G0);
    bool ok = true;
    for (int k = 0; k < g->na; ++k) {
        const crane_act* a = &cc->act[k];
        double* dL = g->dL + (size_t)k * nd;
        // A linkage's length and lever from its loop (crane_act_length), the
        // links lumped at their pins by crane_chain_mechanism.
        const double L = crane_act_length(a, g->ch, g->ws, NULL, dL, NULL);
        g->x[k] = L - a->closed_length;
        g->lever[k] = dL[g->act_dof[k]];
        // 0.1 mm of tolerance: the grid's ends are the joint limits, whose
        // strokes the model's closed lengths match to their printed digits.
        if (g->x[k] < -1e-4 || g->x[k] > g->stroke[k] + 1e-4) ok = false;
    }
    return ok;
}

double lc_chain_hyd(const lc_chain* g, double margin, int* gov) {
    double best = INFINITY;
    int gk = 0;
    for (int k = 0; k < g->na; ++k) {
        const int j = g->act_dof[k];
        const double r = g->lever[k];
        if (!(fabs(r) > 1e-9)) return -1; // a dead centre: no holding force
        // Holding force F = G / r [N] (F > 0: chamber A carries it), each
        // actuator alone on its joint (lc_chain_init's allow-list).
        const double fmax_ = (1 - margin) * g->relief[k][0] * g->AA[k] - LCC_P_LOW * g->AB[k];
        const double fmin_ = -((1 - margin) * g->relief[k][1] * g->AB[k] - LCC_P_LOW * g->AA[k]);
        const double f0 = g->G0[j] / r, df = g->Gt[j] / r; // N, N/kg
        if (f0 > fmax_ || f0 < fmin_) return -1;
        double lim = INFINITY;
        if (df > 0) lim = (fmax_ - f0) / df;
        else if (df < 0) lim = (fmin_ - f0) / df;
        if (lim < best) best = lim, gk = k;
    }
    if (gov) *gov = gk;
    return best;
}

void lc_chain_mass_moment(const lc_chain* g, double* S1, double* M) {
    double s = 0, mm = 0;
    for (int b = 0; b < g->cc->nbody; ++b) {
        const chain_body_def* d = chain_body(g->ch, b);
        double Rb[9], p[3];
        chain_body_pose(g->ch, g->ws, b, Rb, p);
        const double x = p[0] + Rb[0] * d->com[0] + Rb[1] * d->com[1] + Rb[2] * d->com[2];
        s += d->mass * (x - g->axis_x), mm += d->mass;
    }
    *S1 = s, *M = mm;
}

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// The search's grid over every boom joint, ends included (the weakest
// poses sit at the ends of a stroke: docs/safety.md): an angle in steps of
// at most 2.5 deg, a slide in steps of at most 0.1 m. loader10 (lift 89
// deg, knuckle 138 deg, two 1.3 m extensions): 37 x 57 x 14 x 14 = 413k
// poses, about 1 s (the limiter makes its chart once per engine). What a
// finer grid changes is in docs/safety.md.
#define LCC_STEP_REV (2.5 * M_PI / 180)
#define LCC_STEP_PRI 0.1

int lc_chain_grid_n(const lc_chain* g, int j) {
    const bool pri = g->cc->body[g->dof_body[j]].def.joint == CHAIN_PRISMATIC;
    const double n = ceil((g->q_hi[j] - g->q_lo[j]) / (pri ? LCC_STEP_PRI : LCC_STEP_REV));
    return (int)fmax(1.0, n) + 1;
}

// The next pose of the odometer over the grid (idx [nd]); false after the last.
static bool grid_next(const lc_chain* g, int* idx, double* q) {
    for (int j = 0; j < g->nd; ++j) {
        const int n = lc_chain_grid_n(g, j);
        if (++idx[j] < n) {
            q[j] = g->q_lo[j] + (g->q_hi[j] - g->q_lo[j]) * idx[j] / (n - 1);
            return true;
        }
        idx[j] = 0, q[j] = g->q_lo[j];
    }
    return false;
}

static void grid_first(const lc_chain* g, int* idx, double* q) {
    for (int j = 0; j < g->nd; ++j) idx[j] = 0, q[j] = g->q_lo[j];
}

long lc_chain_grid_size(const lc_chain* g) {
    long total = 1;
    for (int j = 0; j < g->nd; ++j) total *= lc_chain_grid_n(g, j);
    return total;
}

void lc_chain_grid_pose(const lc_chain* g, long at, double* q) {
    for (int j = 0; j < g->nd; ++j) {
        const int n = lc_chain_grid_n(g, j);
        const long i = at % n;
        at /= n;
        q[j] = n > 1 ? g->q_lo[j] + (g->q_hi[j] - g->q_lo[j]) * (double)i / (n - 1) : g->q_lo[j];
    }
}

lcc_pose* lc_chain_search(lc_chain* g, double margin, bool masses, long* np) {
    const long total = lc_chain_grid_size(g);
    lcc_pose* P = malloc((size_t)total * sizeof *P + 1);
    int* idx = calloc((size_t)g->nd + 1, sizeof *idx);
    double* q = calloc((size_t)g->nd + 1, sizeof *q);
    long n = 0, at = 0;
    if (P && idx && q) {
        grid_first(g, idx, q);
        do {
            lcc_pose* p = &P[n];
            if (lc_chain_eval(g, q, &p->R, NULL)) {
                p->hyd = lc_chain_hyd(g, margin, &p->gov);
                p->S1 = p->M = 0;
                if (masses) lc_chain_mass_moment(g, &p->S1, &p->M);
                p->at = at;
                ++n;
            }
            ++at;
        } while (grid_next(g, idx, q));
    } else {
        free(P), P = NULL;
    }
    free(idx), free(q);
    *np = n;
    return P;
}
