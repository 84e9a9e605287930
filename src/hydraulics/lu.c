// lu.c: small dense LU with partial pivoting, and the block-diagonal iteration
// matrix W = I - gamma h J of the linearly implicit methods.
//
// The crane's W is block diagonal with blocks of 1 to 4 states, so the hot
// path is many tiny factorisations: blocks of size 1 and 2 get closed forms,
// larger ones the general routine.
#include "solver_internal.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

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

// ------------------------------------------------ sparse path, dense W --
//
// The crane's 15x15 J has about 60 non-zeros and LU in natural order adds
// about 10 fill-ins: some 60 multiply-adds instead of the ~1100 of a dense
// factorisation, and some 70 per solve instead of ~210. The pattern is not
// declared by the problem; it is learnt from the J values (the union of every
// non-zero seen), so a new non-zero only costs one symbolic pass.
//
// The order of elimination matters more on larger circuits: the load-sensing
// crane's 25x25 J (126 non-zeros) fills to 247 off-diagonal entries of L + U
// in natural order, 778 multiply-adds per factorisation, because its
// pressure nodes couple to every later state. Eliminating first the states
// of fewest couplings (Markowitz's criterion, the product of the remaining
// row and column counts, on the diagonal so that the threshold test keeps
// its meaning; Duff, Erisman & Reid, "Direct methods for sparse matrices",
// ch. 7) gives 140 entries and 208 multiply-adds.

// A diagonal pivot is accepted when |a_kk| >= HYD_SP_THRESH max_{i>k} |a_ik|
// on the scaled matrix (threshold partial pivoting, as in sparse direct
// solvers; 0.01 is MA48's default): growth stays bounded by
// (1 + 1/HYD_SP_THRESH) per elimination step. Otherwise the dense, partially
// pivoted LU factors that W. On the crane about 4 % of the factorisations
// fall back (a joint-angle column against a joint-velocity row, whose error
// weight is atol-sized).
#define HYD_SP_THRESH 0.01

// The pivot order from J's pattern (sp_jmask), the fill of an LU without
// row exchanges in that order (sp_mask), then the index lists. O(n^3) for
// the order; it runs only when J shows a non-zero outside the pattern.
static void sp_symbolic(hyd_solver* s) {
    const int n = s->n;
    unsigned char* m = s->sp_mask;
    memcpy(m, s->sp_jmask, (size_t)n * (size_t)n);
    int* perm = s->sp_perm;
    int* pos = s->sp_pos;
    for (int i = 0; i < n; ++i) pos[i] = -1; // not eliminated yet
    for (int k = 0; k < n; ++k) {
        // The remaining state whose elimination fills least: (r - 1)(c - 1)
        // off-diagonal entries of its row and column among the remaining
        // states; ties by r + c, then by index (a fixed order).
        int best = -1;
        long bcost = 0, bsum = 0;
        for (int v = 0; v < n; ++v) {
            if (pos[v] >= 0) continue;
            long r = 0, c = 0;
            for (int j = 0; j < n; ++j) {
                if (pos[j] >= 0 || j == v) continue;
                r += m[v * n + j];
                c += m[j * n + v];
            }
            if (best < 0 || r * c < bcost || (r * c == bcost && r + c < bsum)) {
                best = v;
                bcost = r * c;
                bsum = r + c;
            }
        }
        perm[k] = best;
        pos[best] = k;
        for (int i = 0; i < n; ++i) {
            if (pos[i] >= 0 || !m[i * n + best]) continue;
            for (int j = 0; j < n; ++j)
                if (pos[j] < 0 && m[best * n + j]) m[i * n + j] = 1;
        }
    }
    int nl = 0, nu = 0, nf = 0;
    for (int k = 0; k < n; ++k) {
        const int pk = perm[k];
        s->sp_lptr[k] = nl;
        for (int i = 0; i < n; ++i)
            if (pos[i] > k && m[i * n + pk]) s->sp_lrow[nl++] = i;
        s->sp_uptr[k] = nu;
        s->sp_fptr[k] = nf;
        for (int j = 0; j < n; ++j) {
            if (!m[pk * n + j] || j == pk) continue;
            if (pos[j] > k) {
                s->sp_ucol[nu] = j;
                s->sp_upos[nu++] = pk * n + j;
            } else {
                s->sp_fcol[nf] = j;
                s->sp_fpos[nf++] = pk * n + j;
            }
        }
    }
    s->sp_lptr[n] = nl;
    s->sp_uptr[n] = nu;
    s->sp_fptr[n] = nf;
    // Positions inside the pattern (W's checks) and the off-pattern mask.
    int np = 0;
    for (int i = 0; i < n * n; ++i) {
        s->sp_zmask[i] = m[i] ? 0 : ~(UINT64_C(1) << 63); // magnitude bits only: -0.0 is 0
        if (m[i]) s->sp_ppos[np++] = i;
    }
    s->sp_np = np;
}

void hydSparseInit(hyd_solver* s) { sp_symbolic(s); }

// W = I - gh J, dense storage, factored over the learnt pattern in the pivot
// order. Returns 0, 1 when a pivot fails the threshold test (the caller falls
// back), or -1 when W is singular or not finite.
static int sp_factor(hyd_solver* s, double gh) {
    const int n = s->n, nn = n * n;
    const double* restrict jb = s->jb;
    double* restrict w = s->w;
    // Two cheap checks instead of one branchy pass over n^2 entries: (1)
    // any non-zero outside the known pattern (integer OR of the magnitude
    // bits, masked to the off-pattern positions: vectorises), (2) max |J| and
    // non-finiteness over the pattern's positions only (off the pattern every
    // entry is then an exact zero). The magnitude bits of doubles order like
    // unsigned integers, Inf and NaN above every finite.
    const uint64_t* restrict zm = s->sp_zmask;
    uint64_t off = 0;
    for (int i = 0; i < nn; ++i) {
        uint64_t b;
        memcpy(&b, &jb[i], sizeof b);
        off |= b & zm[i];
    }
    if (off) {
        // New non-zeros (or NaN/Inf off the pattern): grow J's pattern, and
        // with it the order and the fill.
        unsigned char* jm = s->sp_jmask;
        for (int i = 0; i < nn; ++i)
            if (jb[i] != 0.0 || jb[i] != jb[i]) jm[i] = 1;
        sp_symbolic(s);
    }
    // W's entries on the pattern only (on the LS crane 165 of 625), in the
    // pass that finds max |J|: the elimination and the solves read no other
    // entry (the pattern holds the fill), so whatever the dense fallback left
    // off the pattern is never read. Fill positions get -gh * 0 = 0.
    const int* restrict pp = s->sp_ppos;
    const int np = s->sp_np;
    uint64_t bmax = 0;
    for (int p = 0; p < np; ++p) {
        const int i = pp[p];
        const double v = jb[i];
        w[i] = -gh * v;
        uint64_t b;
        memcpy(&b, &v, sizeof b);
        b &= ~(UINT64_C(1) << 63);
        bmax = b > bmax ? b : bmax;
    }
    if (bmax >= UINT64_C(0x7ff0000000000000)) return -1; // Inf or NaN in J
    double jmax;
    memcpy(&jmax, &bmax, sizeof jmax);
    for (int i = 0; i < n; ++i) w[i * n + i] += 1.0;
    // The scale of W for the singularity test: max |W_ij| <= 1 + |gh| max |J|.
    const double tiny = (1.0 + fabs(gh) * jmax) * DBL_EPSILON;
    const int* restrict perm = s->sp_perm;
    const int* restrict lptr = s->sp_lptr;
    const int* restrict lrow = s->sp_lrow;
    const int* restrict uptr = s->sp_uptr;
    const int* restrict ucol = s->sp_ucol;
    const double* restrict sc = s->sp_scale;
    double* restrict idiag = s->widiag;
    for (int k = 0; k < n; ++k) {
        const int pk = perm[k];
        const double akk = w[pk * n + pk];
        // The test runs on D^-1 W D, D = diag(1 / sc): W's factors without
        // row exchanges are that matrix's factors scaled back, and its
        // entries compare like with like (a spool column against pressure
        // rows differs by ~1e10 in raw units).
        double cmax = 0.0;
        for (int p = lptr[k]; p < lptr[k + 1]; ++p) {
            const int i = lrow[p];
            const double v = fabs(w[i * n + pk]) * sc[i];
            cmax = v > cmax ? v : cmax;
        }
        const double pkv = fabs(akk);
        if (!(pkv * sc[pk] >= HYD_SP_THRESH * cmax) || !(pkv > tiny)) return 1;
        const double inv = 1.0 / akk;
        idiag[k] = inv;
        const double* rk = w + pk * n;
        for (int p = lptr[k]; p < lptr[k + 1]; ++p) {
            double* ri = w + lrow[p] * n;
            const double l = ri[pk] * inv;
            ri[pk] = l;
            if (l == 0.0) continue;
            for (int q = uptr[k]; q < uptr[k + 1]; ++q) {
                const int j = ucol[q];
                ri[j] -= l * rk[j];
            }
        }
    }
    return 0;
}

// Forward and back substitution in the pivot order. careful (a non-finite
// b): zero factors are skipped, so that a NaN in one component does not
// spread through 0 * NaN into decoupled ones (the non-finite report then
// names the state that actually went bad). Inline with a constant flag: two
// branch-free copies.
static inline void sp_subst(const hyd_solver* s, double* restrict b, int careful) {
    const int n = s->n;
    const double* restrict w = s->w;
    const int* restrict perm = s->sp_perm;
    const int* restrict fptr = s->sp_fptr;
    const int* restrict fpos = s->sp_fpos;
    const int* restrict fcol = s->sp_fcol;
    for (int k = 1; k < n; ++k) {
        const int i = perm[k];
        double sum = b[i];
        for (int p = fptr[k]; p < fptr[k + 1]; ++p) {
            const double l = w[fpos[p]];
            if (careful && l == 0.0) continue;
            sum -= l * b[fcol[p]];
        }
        b[i] = sum;
    }
    const int* restrict uptr = s->sp_uptr;
    const int* restrict upos = s->sp_upos;
    const int* restrict ucol = s->sp_ucol;
    const double* restrict idiag = s->widiag;
    for (int k = n - 1; k >= 0; --k) {
        const int i = perm[k];
        double sum = b[i];
        for (int p = uptr[k]; p < uptr[k + 1]; ++p) {
            const double u = w[upos[p]];
            if (careful && u == 0.0) continue;
            sum -= u * b[ucol[p]];
        }
        b[i] = sum * idiag[k];
    }
}

static void sp_solve(const hyd_solver* s, double* restrict b) {
    const int n = s->n;
    double acc = 0.0;
    for (int i = 0; i < n; ++i) acc += b[i] * 0.0;
    if (acc != 0.0) sp_subst(s, b, 1);
    else sp_subst(s, b, 0);
}

// W now holds a factorisation for gh.
static int w_factored(hyd_solver* s, double gh) {
    s->w_valid = 1;
    s->w_gh = gh;
    s->st.lus++;
    return HYD_OK;
}

int hydFactorW(hyd_solver* s, double gh) {
    s->w_sparse = 0;
    s->w_custom = 0;
    const hyd_problem* p = s->p;
    if (p->wfactor && p->wsolve && s->nblock == 1) {
        if (p->wfactor(p->user, s->jb, gh) == 0) {
            s->w_custom = 1;
            return w_factored(s, gh);
        }
        // The problem declined: our own LU below.
    }
    if (s->sp_on) {
        const int rc = sp_factor(s, gh);
        if (rc < 0) return HYD_ERR_SINGULAR;
        if (rc == 0) {
            s->w_sparse = 1;
            return w_factored(s, gh);
        }
        s->sp_fallbacks++; // a weak diagonal pivot: the dense LU below
    }
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
    for (int t = 0; t < s->nb1; ++t) s->b1w[t] = s->w[s->moff[s->border[t]]];
    return w_factored(s, gh);
}

void hydSolveW(const hyd_solver* s, double* x) {
    if (s->w_custom) {
        s->p->wsolve(s->p->user, x);
        return;
    }
    if (s->w_sparse) {
        sp_solve(s, x);
        return;
    }
    const int* restrict bo = s->border;
    const int e1 = s->nb1, e2 = s->nb1 + s->nb2;
    const int* restrict x1 = s->b1x;
    const double* restrict w1 = s->b1w;
    for (int t = 0; t < e1; ++t) x[x1[t]] *= w1[t];
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
