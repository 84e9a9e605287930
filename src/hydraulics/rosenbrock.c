// rosenbrock.c: the adaptive 4-stage linearly implicit methods of docs/solvers.md,
// ROS34PW2 (Rang & Angermann 2005, a W-method) and RODAS3 (Sandu et al. 1997,
// stiffly accurate), both order 3 with an embedded order-2 solution.
//
// Original form, as in the sources below:
//   W k_i = h f(t + c_i h, y + sum_j a_ij k_j) + h J sum_j g_ij k_j + gs_i h^2 df/dt
// with W = I - gamma h J. The products h J k_j are not formed: stage j's own
// equation gives h J k_j = (k_j - r_j) / gamma, where r_j is its right-hand
// side. That costs O(n) per stage and uses exactly the J inside W, which is
// what a W-method needs when J is stale or block-diagonal.
#include "solver_internal.h"

#include <string.h>

static hyd_tableau make_tableau(int needs_dfdt, double gamma, const double a[4][4],
                                const double g[4][4], const double b[4], const double bh[4]) {
    hyd_tableau t;
    memset(&t, 0, sizeof t);
    t.stages = 4;
    t.gamma = gamma;
    t.needs_dfdt = needs_dfdt;
    for (int i = 0; i < 4; ++i) {
        t.c[i] = 0.0;
        t.gs[i] = gamma;
        for (int j = 0; j < i; ++j) {
            t.a[i][j] = a[i][j];
            t.g[i][j] = g[i][j];
            t.c[i] += a[i][j];
            t.gs[i] += g[i][j];
        }
        t.b[i] = b[i];
        t.e[i] = b[i] - bh[i];
    }
    return t;
}

// Coefficients exactly as published (Rang & Angermann 2005, table
// "ROS34PW2"). Copied into each solver at create: no shared mutable state.
static hyd_tableau ros34pw2(void) {
    static const double a[4][4] = {
        {0, 0, 0, 0},
        {0.87173304301691801, 0, 0, 0},
        {0.84457060015369423, -0.11299064236484185, 0, 0},
        {0, 0, 1, 0},
    };
    static const double g[4][4] = {
        {0, 0, 0, 0},
        {-0.87173304301691801, 0, 0, 0},
        {-0.90338057013044082, 0.054180672388095326, 0, 0},
        {0.24212380706095346, -1.2232505839045147, 0.54526025533510214, 0},
    };
    static const double b[4] = {0.24212380706095346, -1.2232505839045147, 1.5452602553351020,
                                0.43586652150845900};
    static const double bh[4] = {0.37810903145819369, -0.096042292212423178, 0.5,
                                 0.21793326075422950};
    return make_tableau(0, 0.43586652150845900, a, g, b, bh);
}

// RODAS3 (Sandu et al. 1997). Not a W-method: it keeps order 3
// only with the exact J and the df/dt term.
static hyd_tableau rodas3(void) {
    static const double a[4][4] = {
        {0, 0, 0, 0},
        {0, 0, 0, 0},
        {1, 0, 0, 0},
        {0.75, -0.25, 0.5, 0},
    };
    static const double g[4][4] = {
        {0, 0, 0, 0},
        {1, 0, 0, 0},
        {-0.25, -0.25, 0, 0},
        {1.0 / 12.0, 1.0 / 12.0, -2.0 / 3.0, 0},
    };
    static const double b[4] = {5.0 / 6.0, -1.0 / 6.0, -1.0 / 6.0, 0.5};
    static const double bh[4] = {0.75, -0.25, 0.5, 0};
    return make_tableau(1, 0.5, a, g, b, bh);
}

int hydRosenbrockTableau(hyd_method m, hyd_tableau* out) {
    if (m == HYD_ROS34PW2) *out = ros34pw2();
    else if (m == HYD_RODAS3) *out = rodas3();
    else return -1;
    return 0;
}

int hydRosenbrockStep(hyd_solver* s, double t, const double* y, const double* f0, double h,
                      double* ynew, double* err) {
    const hyd_tableau* tb = &s->tab;
    const int n = s->n;
    const double gamma = tb->gamma;
    int rc = hydPrepareW(s, t, y, f0, gamma * h);
    if (rc != HYD_OK) return rc;
    const int use_ft = tb->needs_dfdt && !s->p->autonomous;
    const double h2 = h * h;
    double* restrict r = s->r;

    for (int i = 0; i < tb->stages; ++i) {
        // Stage argument; a stage at the step's start point reuses f0.
        const double* fi = f0;
        int at_start = tb->c[i] == 0.0;
        for (int j = 0; j < i; ++j) at_start = at_start && tb->a[i][j] == 0.0;
        if (!at_start) {
            double* restrict ys = s->ys;
            memcpy(ys, y, (size_t)n * sizeof *ys);
            for (int j = 0; j < i; ++j) {
                const double aij = tb->a[i][j];
                if (aij == 0.0) continue;
                const double* kj = s->k[j];
                for (int l = 0; l < n; ++l) ys[l] += aij * kj[l];
            }
            rc = hydEvalF(s, t + tb->c[i] * h, ys, s->fs);
            if (rc != HYD_OK) return rc;
            fi = s->fs;
        }
        for (int l = 0; l < n; ++l) r[l] = h * fi[l];
        for (int j = 0; j < i; ++j) {
            const double gij = tb->g[i][j];
            if (gij == 0.0) continue;
            const double* hjk = s->hjk[j];
            for (int l = 0; l < n; ++l) r[l] += gij * hjk[l];
        }
        if (use_ft) {
            const double c = tb->gs[i] * h2;
            if (c != 0.0)
                for (int l = 0; l < n; ++l) r[l] += c * s->ft[l];
        }
        double* restrict ki = s->k[i];
        memcpy(ki, r, (size_t)n * sizeof *ki);
        hydSolveW(s, ki);
        if (i + 1 < tb->stages) {
            double* restrict hjk = s->hjk[i];
            const double ig = 1.0 / gamma;
            for (int l = 0; l < n; ++l) hjk[l] = (ki[l] - r[l]) * ig;
        }
    }

    for (int l = 0; l < n; ++l) {
        double yn = y[l], e = 0.0;
        for (int i = 0; i < tb->stages; ++i) {
            yn += tb->b[i] * s->k[i][l];
            e += tb->e[i] * s->k[i][l];
        }
        ynew[l] = yn;
        if (err) err[l] = e;
    }
    return HYD_OK;
}
