// lu.c: small dense LU with partial pivoting, and the block-diagonal iteration
// matrix W = I - gamma h J of the linearly implicit methods.
//
// The crane's W is block diagonal with blocks of 1 to 4 states, so the hot
// path is many tiny factorisations: blocks of size 1 and 2 get closed forms,
// larger ones the general routine.
#include "solver_internal.h"

#include <float.h>
#include <math.h>

// Shared by hyd_lu_factor and the solver's blocks. Rows are unit stride, so
// the elimination update is a plain axpy the compiler vectorises (row i and
// row k never overlap, hence restrict). When idiag is non-NULL it receives
// 1/U_kk, so a solve multiplies instead of dividing; *swapped says whether any
// row exchange happened (the solve then skips the permutation replay).
static int lu_factor(double* a, int n, int* piv, double* idiag, int* swapped) {
    // A pivot at or below eps * max|a_ij| is zero to working precision: treat
    // the matrix as singular rather than return huge, meaningless factors.
    // amax sticks at NaN once it meets one (v != v), and Inf fails the
    // final test too: no separate pass for the non-finite check. Not fmax():
    // that is a libm call here.
    double amax = 0.0;
    for (int i = 0; i < n * n; ++i) {
        const double v = fabs(a[i]);
        amax = (v > amax || v != v) ? v : amax;
    }
    if (!(amax <= DBL_MAX)) return -1;
    const double tiny = amax * DBL_EPSILON;
    int sw = 0;

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
            sw = 1;
            for (int j = 0; j < n; ++j) {
                double tmp = a[k * n + j];
                a[k * n + j] = a[p * n + j];
                a[p * n + j] = tmp;
            }
        }
        const double inv = 1.0 / a[k * n + k];
        if (idiag) idiag[k] = inv;
        const double* restrict rk = a + k * n;
        for (int i = k + 1; i < n; ++i) {
            double* restrict ri = a + i * n;
            const double l = ri[k] * inv;
            ri[k] = l;
            if (l == 0.0) continue; // sparse rows cost nothing
            for (int j = k + 1; j < n; ++j) ri[j] -= l * rk[j];
        }
    }
    if (swapped) *swapped = sw;
    return 0;
}

int hyd_lu_factor(double* a, int n, int* piv) { return lu_factor(a, n, piv, NULL, NULL); }

// Forward and back substitution. With finite b the zero multipliers need no
// test: subtracting 0 * b_j changes nothing, so the branch-free loops give the
// same numbers. Only a non-finite b takes the careful loops, where zero
// multipliers are skipped so that a NaN in one component does not spread
// through 0 * NaN into decoupled ones (the non-finite report then names the
// state that actually went bad).
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
    double acc = 0.0;
    for (int i = 0; i < n; ++i) acc += b[i] * 0.0;
    if (acc == 0.0) {
        for (int i = 1; i < n; ++i) {
            const double* li = lu + i * n;
            double sum = b[i];
            for (int j = 0; j < i; ++j) sum -= li[j] * b[j];
            b[i] = sum;
        }
        for (int i = n - 1; i >= 0; --i) {
            const double* ui = lu + i * n;
            double sum = b[i];
            for (int j = i + 1; j < n; ++j) sum -= ui[j] * b[j];
            b[i] = sum / ui[i];
        }
        return;
    }
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

// The solver's blocks larger than 2: as hyd_lu_solve, but multiplying by the
// stored 1/U_ii instead of dividing, and replaying pivots only when the
// factorisation exchanged rows. Inline so that the crane's 4x4 block gets a
// fully unrolled copy (see hydSolveW).
static inline void lu_solve_blk(const double* lu, int n, const int* piv, const double* idiag,
                                int swapped, double* b) {
    double acc = 0.0;
    for (int i = 0; i < n; ++i) acc += b[i] * 0.0;
    if (acc != 0.0) {
        hyd_lu_solve(lu, n, piv, b); // non-finite b: the careful loops
        return;
    }
    if (swapped)
        for (int k = 0; k < n; ++k) {
            const int p = piv[k];
            const double tmp = b[k];
            b[k] = b[p];
            b[p] = tmp;
        }
    for (int i = 1; i < n; ++i) {
        const double* li = lu + i * n;
        double sum = b[i];
        for (int j = 0; j < i; ++j) sum -= li[j] * b[j];
        b[i] = sum;
    }
    for (int i = n - 1; i >= 0; --i) {
        const double* ui = lu + i * n;
        double sum = b[i];
        for (int j = i + 1; j < n; ++j) sum -= ui[j] * b[j];
        b[i] = sum * idiag[i];
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
            if (lu_factor(w, m, s->piv + s->boff[b], s->widiag + s->boff[b], &s->wswap[b]) != 0)
                return HYD_ERR_SINGULAR;
        }
    }
    s->w_valid = 1;
    s->w_gh = gh;
    s->st.lus++;
    return HYD_OK;
}

void hydSolveW(const hyd_solver* s, double* x) {
    const int* restrict bo = s->border;
    const int e1 = s->nb1, e2 = s->nb1 + s->nb2;
    for (int t = 0; t < e1; ++t) {
        const int b = bo[t];
        x[s->boff[b]] *= s->w[s->moff[b]];
    }
    for (int t = e1; t < e2; ++t) {
        const int b = bo[t], o = s->boff[b];
        const double* w = s->w + s->moff[b];
        const double x0 = x[o], x1 = x[o + 1];
        x[o] = w[0] * x0 + w[1] * x1;
        x[o + 1] = w[2] * x0 + w[3] * x1;
    }
    for (int t = e2; t < s->nblock; ++t) {
        const int b = bo[t], o = s->boff[b], m = s->boff[b + 1] - o;
        const double* w = s->w + s->moff[b];
        // A literal size lets the compiler unroll the loops completely: the
        // crane's mechanics block is 4x4 and small-trip loops cost more in
        // loop control than in arithmetic.
        if (m == 4)
            lu_solve_blk(w, 4, s->piv + o, s->widiag + o, s->wswap[b], x + o);
        else
            lu_solve_blk(w, m, s->piv + o, s->widiag + o, s->wswap[b], x + o);
    }
}
