// lu.c: small dense LU with partial pivoting, and the block-diagonal iteration
// matrix W = I - gamma h J of the linearly implicit methods.
//
// The crane's W is block diagonal with blocks of 1 to 4 states, so the hot
// path is many tiny factorisations: blocks of size 1 and 2 get closed forms,
// larger ones the general routine.
#include "solver_internal.h"

#include <float.h>
#include <math.h>

int hyd_lu_factor(double* a, int n, int* piv) {
    // A pivot at or below eps * max|a_ij| is zero to working precision: treat
    // the matrix as singular rather than return huge, meaningless factors.
    double amax = 0.0, sum = 0.0;
    for (int i = 0; i < n * n; ++i) {
        amax = fmax(amax, fabs(a[i]));
        sum += a[i] * 0.0; // NaN if any entry is NaN or Inf
    }
    if (sum != 0.0) return -1;
    const double tiny = amax * DBL_EPSILON;

    for (int k = 0; k < n; ++k) {
        int p = k;
        double pmax = fabs(a[k * n + k]);
        for (int i = k + 1; i < n; ++i) {
            double v = fabs(a[i * n + k]);
            if (v > pmax) {
                pmax = v;
                p = i;
            }
        }
        piv[k] = p;
        if (!(pmax > tiny)) return -1;
        if (p != k) {
            for (int j = 0; j < n; ++j) {
                double tmp = a[k * n + j];
                a[k * n + j] = a[p * n + j];
                a[p * n + j] = tmp;
            }
        }
        const double inv = 1.0 / a[k * n + k];
        for (int i = k + 1; i < n; ++i) {
            double l = a[i * n + k] * inv;
            a[i * n + k] = l;
            if (l == 0.0) continue; // sparse rows cost nothing
            for (int j = k + 1; j < n; ++j) a[i * n + j] -= l * a[k * n + j];
        }
    }
    return 0;
}

void hyd_lu_solve(const double* lu, int n, const int* piv, double* b) {
    // Row swaps were applied in order during the factorisation; replay them.
    for (int k = 0; k < n; ++k) {
        int p = piv[k];
        if (p != k) {
            double tmp = b[k];
            b[k] = b[p];
            b[p] = tmp;
        }
    }
    // L has a unit diagonal. Zero multipliers are skipped so that a NaN in one
    // component does not spread through 0 * NaN into decoupled ones (the
    // non-finite report then names the state that actually went bad).
    for (int i = 1; i < n; ++i) {
        double sum = b[i];
        for (int j = 0; j < i; ++j) {
            double l = lu[i * n + j];
            if (l != 0.0) sum -= l * b[j];
        }
        b[i] = sum;
    }
    for (int i = n - 1; i >= 0; --i) {
        double sum = b[i];
        for (int j = i + 1; j < n; ++j) {
            double u = lu[i * n + j];
            if (u != 0.0) sum -= u * b[j];
        }
        b[i] = sum / lu[i * n + i];
    }
}

int hydFactorW(hyd_solver* s, double gh) {
    for (int b = 0; b < s->nblock; ++b) {
        const int m = s->boff[b + 1] - s->boff[b];
        const double* jb = s->jb + s->moff[b];
        double* w = s->w + s->moff[b];
        if (m == 1) {
            // Store 1/W so the solve is one multiply.
            double d = 1.0 - gh * jb[0];
            if (!(fabs(d) > DBL_EPSILON * fmax(1.0, fabs(gh * jb[0])))) return HYD_ERR_SINGULAR;
            w[0] = 1.0 / d;
        } else if (m == 2) {
            // Explicit inverse of the 2x2 block: [d -b; -c a] / det. W is
            // close to I or dominated by a stiff block; both are well
            // conditioned here, and this is the crane's common case.
            double a = 1.0 - gh * jb[0], bb = -gh * jb[1];
            double c = -gh * jb[2], d = 1.0 - gh * jb[3];
            double det = a * d - bb * c;
            double scale = fmax(fabs(a * d), fabs(bb * c));
            if (!(fabs(det) > 4.0 * DBL_EPSILON * scale)) return HYD_ERR_SINGULAR;
            double inv = 1.0 / det;
            w[0] = d * inv;
            w[1] = -bb * inv;
            w[2] = -c * inv;
            w[3] = a * inv;
        } else {
            for (int i = 0; i < m * m; ++i) w[i] = -gh * jb[i];
            for (int i = 0; i < m; ++i) w[i * m + i] += 1.0;
            if (hyd_lu_factor(w, m, s->piv + s->boff[b]) != 0) return HYD_ERR_SINGULAR;
        }
    }
    s->w_valid = 1;
    s->w_gh = gh;
    s->st.lus++;
    return HYD_OK;
}

void hydSolveW(const hyd_solver* s, double* x) {
    for (int b = 0; b < s->nblock; ++b) {
        const int o = s->boff[b];
        const int m = s->boff[b + 1] - o;
        const double* w = s->w + s->moff[b];
        if (m == 1) {
            x[o] *= w[0];
        } else if (m == 2) {
            double x0 = x[o], x1 = x[o + 1];
            x[o] = w[0] * x0 + w[1] * x1;
            x[o + 1] = w[2] * x0 + w[3] * x1;
        } else {
            hyd_lu_solve(w, m, s->piv + o, x + o);
        }
    }
}
