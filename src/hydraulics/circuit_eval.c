// circuit_eval.c: evaluation of a compiled circuit. hyd_data (inputs,
// outputs, scratch), the reference right-hand side and analytic Jacobian
// that run each type's kernel (its descriptor's eval hook), and the
// circuit's fastest mode.
//
// Why per-type kernels instead of one switch per component in the hot loop:
// each kernel runs a tight loop over one record type, so branches are
// predictable and there is no per-component dispatch; the loop over the
// table costs one indirect call per type.
#include "hyd_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void hyd_data_free(hyd_data* d) {
    if (!d)
        return;
    free(d->cyl_x);
    free(d->cyl_v);
    free(d->valve_cmd);
    free(d->cyl_F);
    free(d->cyl_stop);
    free(d->comp_q);
    free(d->comp_open);
    free(d->node_p);
    free(d->node_V);
    free(d->node_be);
    free(d->node_q);
    free(d->node_dV);
    free(d->dydx);
    free(d->dydv);
    free(d->dFdy);
    free(d->dFdx);
    free(d->dFdv);
    free(d->scratch_);
    free(d->flow_);
    free(d);
}

hyd_data* hyd_data_create(const hyd_model* m) {
    hyd_data* d = calloc(1, sizeof *d);
    if (!d)
        return NULL;
    const int n = m->nstate, nc = m->ncyl;
    d->n_ = n;
    d->nnode_ = m->nnode;
    d->ncomp_ = m->ncomp;
    d->ncyl_ = nc;
    d->nvalve_ = m->nvalve;
    int ok = HYD_ALLOC(d->cyl_x, nc) && HYD_ALLOC(d->cyl_v, nc) && HYD_ALLOC(d->valve_cmd, m->nvalve) &&
             HYD_ALLOC(d->cyl_F, nc) && HYD_ALLOC(d->cyl_stop, nc) &&
             HYD_ALLOC(d->comp_q, 2 * m->ncomp) && HYD_ALLOC(d->comp_open, m->ncomp) &&
             HYD_ALLOC(d->node_p, m->nnode) && HYD_ALLOC(d->node_V, m->nnode) &&
             HYD_ALLOC(d->node_be, m->nnode) && HYD_ALLOC(d->node_q, m->nnode) &&
             HYD_ALLOC(d->node_dV, m->nnode) && HYD_ALLOC(d->dydx, nc * n) &&
             HYD_ALLOC(d->dydv, nc * n) && HYD_ALLOC(d->dFdy, nc * n) && HYD_ALLOC(d->dFdx, nc) &&
             HYD_ALLOC(d->dFdv, nc) && HYD_ALLOC(d->scratch_, (n + 1) * (n + 1)) &&
             HYD_ALLOC(d->flow_, HYD_MAXSLOT * m->ncomp);
    if (!ok) {
        hyd_data_free(d);
        return NULL;
    }
    return d;
}

// ---------------------------------------------------------------------------
// Evaluation
// ---------------------------------------------------------------------------

// Shared by hyd_eval and hyd_jacobian: node pressures, then every kernel.
// G (flow partials) is NULL for a plain evaluation.
// map (NULL: identity; only without G) is the state order of hyd_eval_mapped.
// Node pressures from y. Restrict locals: the stores into node_p would
// otherwise force a reload of every model array on each node. In a function
// of its own, so that the restrict promise ends before the kernels read
// node_p through d (C11 6.7.3.1).
static void fill_pressures(const hyd_model* m, double* restrict p, const double* restrict y,
                           const int* restrict map) {
    const int* restrict tn = m->tank_node;
    const int* restrict vn = m->vol_node;
    const int* restrict ns = m->node_state;
    const double* restrict pfix = m->node_pfix;
    const int ntank = m->ntank, nvol = m->nvol;
    for (int k = 0; k < ntank; ++k)
        p[tn[k]] = pfix[tn[k]];
    if (map)
        for (int k = 0; k < nvol; ++k)
            p[vn[k]] = y[map[ns[vn[k]]]];
    else
        for (int k = 0; k < nvol; ++k)
            p[vn[k]] = y[ns[vn[k]]];
}

static void run_kernels(const hyd_model* m, hyd_data* d, const double* y, double* ydot,
                        double* G, const int* restrict map) {
    fill_pressures(m, d->node_p, y, map);
    const size_t nb = (size_t)m->nnode * sizeof(double);
    memset(d->node_dV, 0, nb);
    memcpy(d->node_V, m->node_V0, nb);

    // Each type's kernel over all its records. They write disjoint outputs
    // (their own flow slots, comp_q, their own states' ydot), so the order
    // of types does not change a bit of the result.
    for (int t = 0; t < HYD_TYPE_COUNT; ++t) {
        const hyd_component* c = hyd_component_of((hyd_type)t);
        if (c && c->eval && m->nrec[t])
            c->eval(m, d, m->rec[t], m->nrec[t], y, ydot, G, map);
    }
}

void hyd_eval(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot) {
    (void)t;
    run_kernels(m, d, y, ydot, NULL, NULL);
    hyd_volumes_eval(m, d, ydot, NULL, NULL, 0);
}

void hyd_eval_mapped(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot,
                     const int* map) {
    (void)t;
    if (!map) {
        hyd_eval(m, d, t, y, ydot);
        return;
    }
    run_kernels(m, d, y, ydot, NULL, map);
    hyd_volumes_eval_mapped(m, d, ydot, map);
}

void hyd_jacobian(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot,
                  double* J, int ldj, int row0, int col0) {
    (void)t;
    const int n = m->nstate;
    double* G = d->scratch_;
    memset(G, 0, (size_t)(n + 1) * (size_t)(n + 1) * sizeof *G);
    run_kernels(m, d, y, ydot, G, NULL);
    double* Jb = J ? J + (size_t)row0 * ldj + col0 : NULL;
    hyd_volumes_eval(m, d, ydot, G, Jb, ldj);
    // Coupling partials are written by the types that have them (cylinders);
    // every other entry is 0.
    const size_t cb = (size_t)m->ncyl * (size_t)n * sizeof(double);
    memset(d->dydx, 0, cb);
    memset(d->dydv, 0, cb);
    memset(d->dFdy, 0, cb);
    for (int t = 0; t < HYD_TYPE_COUNT; ++t) {
        const hyd_component* c = hyd_component_of((hyd_type)t);
        if (c && c->jacobian && m->nrec[t])
            c->jacobian(m, d, m->rec[t], m->nrec[t], Jb, ldj);
    }
}

// Spectral radius by repeated squaring: rho(J) = lim ||J^k||^(1/k). B = J /
// ||J||_F keeps the entries in range; after m squarings B^(2^m) carries a
// scale 2^-m in its log. ||A^k||^(1/k) overshoots rho by at most
// cond(V)^(1/k) for a diagonalisable J (V its eigenvectors), so 12 squarings
// (k = 4096) bring even a factor 1e6 of conditioning to within 0.4 %.
static double spectral_radius(double* A, double* T, int n) {
    double f = 0.0;
    for (int i = 0; i < n * n; ++i) f += A[i] * A[i];
    f = sqrt(f);
    if (!isfinite(f)) return -1.0; // NaN or Inf in J: no rate to give
    if (f == 0.0) return 0.0;
    for (int i = 0; i < n * n; ++i) A[i] /= f;
    double logscale = 0.0; // log of the factor divided out of A^(2^m) so far, over 2^m
    double k = 1.0;
    for (int m = 0; m < 12; ++m) {
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                double s = 0.0;
                for (int l = 0; l < n; ++l) s += A[i * n + l] * A[l * n + j];
                T[i * n + j] = s;
            }
        k *= 2.0;
        double g = 0.0;
        for (int i = 0; i < n * n; ++i) g += T[i] * T[i];
        g = sqrt(g);
        if (!(g > 0.0)) return 0.0; // nilpotent: every mode at rest
        for (int i = 0; i < n * n; ++i) A[i] = T[i] / g;
        logscale = 2.0 * logscale + log(g); // log ||J_scaled^k|| so far
    }
    return f * exp(logscale / k);
}

double hyd_model_fastest_rate(const hyd_model* m, double p, double u) {
    const int n = m->nstate;
    if (n == 0) return 0.0;
    hyd_data* d = hyd_data_create(m);
    double* y = calloc((size_t)n, sizeof *y);
    double* J = calloc((size_t)n * (size_t)n, sizeof *J);
    double* T = calloc((size_t)n * (size_t)n, sizeof *T);
    double rate = -1.0;
    if (d && y && J && T) {
        hyd_model_initial_state(m, y);
        for (int i = 0; i < m->nnode; ++i)
            if (m->node_state[i] >= 0) y[m->node_state[i]] = p;
        for (int v = 0; v < m->nvalve; ++v) {
            y[hyd_model_valve_state(m, v)] = u;
            d->valve_cmd[v] = u;
        }
        for (int c = 0; c < m->ncyl; ++c) {
            d->cyl_x[c] = 0.5 * m->cyl[c].s;
            d->cyl_v[c] = 0.0;
        }
        hyd_jacobian(m, d, 0.0, y, NULL, J, n, 0, 0);
        rate = spectral_radius(J, T, n);
    }
    free(T);
    free(J);
    free(y);
    hyd_data_free(d);
    return rate;
}

int hyd_model_flush(const hyd_model* m, double* y, const int* pos) {
    int changed = 0;
    for (int k = 0; k < m->nflush; ++k) {
        double* v = &y[pos ? pos[m->flush_state[k]] : m->flush_state[k]];
        // Exactly 0 already is the common case once settled.
        if (*v != 0.0 && fabs(*v) < m->flush_below[k]) {
            *v = 0.0;
            ++changed;
        }
    }
    return changed;
}
