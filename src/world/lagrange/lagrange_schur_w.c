// lagrange_schur_w.c: W = I - gh J for the crane's standard layout, by block
// elimination onto a 5x5 Schur complement (hyd_problem.wfactor/wsolve).
//
// Layout (lsim_w_layout checks it): actuator k owns the interior states
// 5k .. 5k+4 = [spool, hose A, chamber A, hose B, chamber B]; the interface is
// z = [pump line, q1, q2, q1', q2'] at 10 .. 14. The two actuators' interior
// states never meet directly, only through the pump line (valve P ports) and
// the mechanics (strokes, forces), so with W = [A B; C D], A = diag(A_0, A_1)
// (5x5 each),
//   S = D - sum_k C_k A_k^-1 B_k            (5x5)
//   W x = b:  y_k = A_k^-1 b_k,  S x_z = b_z - sum_k C_k y_k,
//             x_k = y_k - (A_k^-1 B_k) x_z.
// That is two 5x5 LUs, five 5x5 solves per actuator and one 5x5 LU, in
// straight-line code: about 1,000 instructions per factorisation and 250 per
// solve, against about 5,000 and 900 for the general sparse LU with its
// index lists (docs/performance.md).
//
// Every block is factored with partial pivoting, so no pivot order is
// assumed. The one structural assumption, no J entry between the two
// actuators' interior states, is checked on every factorisation (50 compares);
// a J that breaks it, or a pivot below eps * max |block|, hands W back to the
// solver's own LU (wfactor returns 1).
#include "lagrange_sim.h"

#include <float.h>
#include <math.h>
#include <string.h>

enum { NI = 5, NZ = 5, IZ = 10, NW = 15 };

// Interface order inside S: the velocities first. Eliminating q' before q
// keeps the multipliers small at large h (a joint-angle column against a
// joint-velocity row grows like gh times the oil-column stiffness), so
// partial pivoting on S rarely exchanges rows.
static const int zmap[NZ] = {IZ + 3, IZ + 4, IZ, IZ + 1, IZ + 2};

// The small dense kernels below work on local copies (fully unrolled, the
// entries live in registers): through the caller's arrays every update
// would be a store and a dependent reload, which on this tiny, chained
// arithmetic costs more than the arithmetic itself.
#if defined(__GNUC__) && !defined(__clang__)
#define UNROLL _Pragma("GCC unroll 16")
#else
#define UNROLL
#endif

// Step k of an LU in place: store 1/U_kk on the diagonal, the multipliers
// below it, and update the trailing block.
static inline void eliminate(double* a, int m, int k) {
    const double inv = 1.0 / a[k * m + k];
    a[k * m + k] = inv;
    UNROLL for (int i = k + 1; i < m; ++i) {
        const double l = a[i * m + k] * inv;
        a[i * m + k] = l;
        UNROLL for (int j = k + 1; j < m; ++j) a[i * m + j] -= l * a[k * m + j];
    }
}

// Dense LU with partial pivoting of an m x m row-major matrix (m a literal at
// every call site); U's diagonal is stored inverted. Returns 0, or -1 when a
// pivot is at or below eps * max|a| (or a is not finite).
static inline int lu_pivot(double* out, int m, int* piv) {
    double a[NZ * NZ];
    UNROLL for (int i = 0; i < m * m; ++i) a[i] = out[i];
    double amax = 0.0;
    UNROLL for (int i = 0; i < m * m; ++i) {
        const double v = fabs(a[i]);
        amax = (v > amax || v != v) ? v : amax;
    }
    if (!(amax <= DBL_MAX)) return -1;
    const double tiny = amax * DBL_EPSILON;
    UNROLL for (int k = 0; k < m; ++k) {
        int p = k;
        double pmax = fabs(a[k * m + k]);
        UNROLL for (int i = k + 1; i < m; ++i) {
            const double v = fabs(a[i * m + k]);
            p = v > pmax ? i : p;
            pmax = v > pmax ? v : pmax;
        }
        piv[k] = p;
        if (!(pmax > tiny)) return -1;
        if (p != k)
            UNROLL for (int j = 0; j < m; ++j) {
                const double t = a[k * m + j];
                a[k * m + j] = a[p * m + j];
                a[p * m + j] = t;
            }
        eliminate(a, m, k);
    }
    UNROLL for (int i = 0; i < m * m; ++i) out[i] = a[i];
    return 0;
}

// The interior block without row exchanges, when that is safe: every pivot
// at least a tenth of the largest entry below it (threshold pivoting; the
// chamber and hose rows share units, Pa/s). The spool column is exempt when
// the spool row has no off-diagonal entry (the usual u' = (u_cmd - u) / tau):
// eliminating it then changes no other entry, whatever the multipliers.
// Returns 0 (factors in out), or 1 when a pivot fails (out untouched; the
// caller pivots instead).
static inline int lu_interior(double* out) {
    enum { m = NI };
    double a[NI * NI];
    UNROLL for (int i = 0; i < m * m; ++i) a[i] = out[i];
    const int spool_free = a[1] == 0.0 && a[2] == 0.0 && a[3] == 0.0 && a[4] == 0.0;
    int ok = 1;
    UNROLL for (int k = 0; k < m; ++k) {
        const double pk = fabs(a[k * m + k]);
        double cmax = 0.0;
        UNROLL for (int i = k + 1; i < m; ++i) {
            const double v = fabs(a[i * m + k]);
            cmax = v > cmax ? v : cmax;
        }
        ok &= ((pk >= 0.1 * cmax) | (k == 0 && spool_free)) & (pk > 0.0);
        eliminate(a, m, k);
    }
    if (!ok) return 1;
    UNROLL for (int i = 0; i < m * m; ++i) out[i] = a[i];
    return 0;
}

// Solve with the factors of lu_pivot (piv non-NULL) or lu_interior (NULL).
static inline void lu_apply(const double* restrict lu, int m, const int* piv, double* restrict out) {
    double b[NZ];
    UNROLL for (int k = 0; k < m; ++k) b[k] = out[k];
    if (piv)
        for (int k = 0; k < m; ++k) {
            const double t = b[k];
            b[k] = b[piv[k]];
            b[piv[k]] = t;
        }
    UNROLL for (int i = 1; i < m; ++i)
        UNROLL for (int j = 0; j < i; ++j) b[i] -= lu[i * m + j] * b[j];
    UNROLL for (int i = m - 1; i >= 0; --i) {
        double s = b[i];
        UNROLL for (int j = i + 1; j < m; ++j) s -= lu[i * m + j] * b[j];
        b[i] = s * lu[i * m + i];
    }
    UNROLL for (int k = 0; k < m; ++k) out[k] = b[k];
}

bool lsim_w_layout(const lsim* s) {
    if (s->n != NW || s->iq != IZ + 1 || !s->have_fused || s->fz.pl.s != IZ) return false;
    for (int k = 0; k < 2; ++k) {
        const int b = NI * k;
        if (s->iu[k] != b || s->ihose[k][0] != b + 1 || s->ip[k][0] != b + 2 ||
            s->ihose[k][1] != b + 3 || s->ip[k][1] != b + 4)
            return false;
    }
    return true;
}

static int factor_actuator(lsim_w* w, int k, const double* J, double gh, double* S) {
    const int b = NI * k;
    double* A = w->a[k];
    for (int i = 0; i < NI; ++i)
        for (int j = 0; j < NI; ++j) A[i * NI + j] = (i == j) - gh * J[(b + i) * NW + b + j];
    w->piv[k] = NULL;
    if (lu_interior(A) != 0) { // A is left as it was
        if (lu_pivot(A, NI, w->pa[k]) != 0) return 1;
        w->piv[k] = w->pa[k];
    }
    // X = A^-1 B column by column; columns of B that are zero (the other
    // joint's q, q') give zero columns and are skipped here and below.
    for (int c = 0; c < NZ; ++c) {
        double* x = w->x[k][c];
        double any = 0.0;
        for (int i = 0; i < NI; ++i) {
            x[i] = -gh * J[(b + i) * NW + zmap[c]];
            any += fabs(x[i]);
        }
        w->xnz[k][c] = any != 0.0;
        if (w->xnz[k][c]) lu_apply(A, NI, w->piv[k], x);
    }
    for (int r = 0; r < NZ; ++r) {
        double any = 0.0;
        for (int j = 0; j < NI; ++j) {
            w->c[k][r][j] = -gh * J[zmap[r] * NW + b + j];
            any += fabs(w->c[k][r][j]);
        }
        w->cnz[k][r] = any != 0.0;
        if (!w->cnz[k][r]) continue;
        for (int c = 0; c < NZ; ++c) {
            if (!w->xnz[k][c]) continue;
            double acc = 0.0;
            for (int j = 0; j < NI; ++j) acc += w->c[k][r][j] * w->x[k][c][j];
            S[r * NZ + c] -= acc;
        }
    }
    return 0;
}

int lsim_wfactor(void* user, const double* J, double gh) {
    lsim_w* w = &((lsim*)user)->w;
    // The assumption: no coupling between the two actuators' interiors.
    double cross = 0.0;
    for (int i = 0; i < NI; ++i)
        for (int j = 0; j < NI; ++j) cross += fabs(J[i * NW + NI + j]) + fabs(J[(NI + i) * NW + j]);
    if (cross != 0.0) return 1; // also NaN

    double* S = w->s;
    for (int i = 0; i < NZ; ++i)
        for (int j = 0; j < NZ; ++j) S[i * NZ + j] = (i == j) - gh * J[zmap[i] * NW + zmap[j]];
    for (int k = 0; k < 2; ++k)
        if (factor_actuator(w, k, J, gh, S) != 0) return 1;
    return lu_pivot(S, NZ, w->ps) != 0;
}

void lsim_wsolve(void* user, double* x) {
    const lsim_w* w = &((const lsim*)user)->w;
    double z[NZ];
    for (int r = 0; r < NZ; ++r) z[r] = x[zmap[r]];
    for (int k = 0; k < 2; ++k) {
        double* y = x + NI * k;
        lu_apply(w->a[k], NI, w->piv[k], y);
        for (int r = 0; r < NZ; ++r) {
            if (!w->cnz[k][r]) continue;
            double acc = 0.0;
            for (int j = 0; j < NI; ++j) acc += w->c[k][r][j] * y[j];
            z[r] -= acc;
        }
    }
    lu_apply(w->s, NZ, w->ps, z);
    for (int k = 0; k < 2; ++k) {
        double* y = x + NI * k;
        for (int c = 0; c < NZ; ++c) {
            if (!w->xnz[k][c]) continue;
            for (int i = 0; i < NI; ++i) y[i] -= w->x[k][c][i] * z[c];
        }
    }
    for (int r = 0; r < NZ; ++r) x[zmap[r]] = z[r];
}
