// test_lu.c: the dense LU solves a random well-conditioned system and reports
// singular matrices.
#include "check.h"
#include "hyd_solver.h"
#include "solver_internal.h" // the sparse path of a dense W (white-box)

#include <stdint.h>
#include <string.h>

// Deterministic uniform numbers in [-1, 1) (xorshift64*), so the test is reproducible.
static double urand(uint64_t* s) {
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ULL) >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

static void test_random_system(void) {
    uint64_t seed = 0x9E3779B97F4A7C15ULL;
    for (int n = 1; n <= 16; ++n) {
        double a[256], lu[256], x[16], b[16];
        int piv[16];
        // Random entries plus n on the diagonal: condition number O(1), and
        // pivoting is still exercised because off-diagonals can beat the
        // diagonal in a column.
        for (int i = 0; i < n * n; ++i) a[i] = urand(&seed);
        for (int i = 0; i < n; ++i) a[i * n + i] += (i % 2 ? -1.0 : 1.0) * 0.5 * n;
        for (int i = 0; i < n; ++i) x[i] = urand(&seed);
        for (int i = 0; i < n; ++i) {
            b[i] = 0.0;
            for (int j = 0; j < n; ++j) b[i] += a[i * n + j] * x[j];
        }
        memcpy(lu, a, sizeof(double) * (size_t)(n * n));
        CHECK(hyd_lu_factor(lu, n, piv) == 0, "n = %d reported singular", n);
        hyd_lu_solve(lu, n, piv, b);
        double emax = 0.0;
        for (int i = 0; i < n; ++i) emax = fmax(emax, fabs(b[i] - x[i]));
        CHECK(emax < 1e-12, "n = %d: max error %.3g", n, emax);
    }
}

static void test_pivoting_needed(void) {
    // Zero leading entry: fails without row exchange.
    double a[4] = {0.0, 1.0, 1.0, 1.0};
    int piv[2];
    double b[2] = {2.0, 3.0}; // x = (1, 2)
    CHECK(hyd_lu_factor(a, 2, piv) == 0, "permuted identity-like matrix is regular");
    hyd_lu_solve(a, 2, piv, b);
    CHECK_NEAR(b[0], 1.0, 1e-15);
    CHECK_NEAR(b[1], 2.0, 1e-15);
}

static void test_singular(void) {
    int piv[3];
    double zero[9] = {0};
    CHECK(hyd_lu_factor(zero, 3, piv) == -1, "zero matrix");
    // Row 3 = row 1 + row 2.
    double dep[9] = {1, 2, 3, 4, 5, 6, 5, 7, 9};
    CHECK(hyd_lu_factor(dep, 3, piv) == -1, "rank-2 matrix");
    double rank1[4] = {1, 2, 2, 4};
    CHECK(hyd_lu_factor(rank1, 2, piv) == -1, "rank-1 matrix");
    double nan[4] = {1, NAN, 0, 1};
    CHECK(hyd_lu_factor(nan, 2, piv) == -1, "NaN entry");
}


// ---- sparse path of a dense W (lu.c): W = I - gh J factored over J's learnt
// pattern without row exchanges when the threshold test allows, else by the
// dense partially pivoted LU. Both must solve W x = b.
typedef struct spj {
    int n;
    double J[256];
} spj;
static int spj_f(void* user, double t, const double* y, double* dy) {
    const spj* q = user;
    (void)t;
    for (int i = 0; i < q->n; ++i) {
        dy[i] = 0.0;
        for (int j = 0; j < q->n; ++j) dy[i] += q->J[i * q->n + j] * y[j];
    }
    return 0;
}
static int spj_jac(void* user, double t, const double* y, double* J) {
    const spj* q = user;
    (void)t, (void)y;
    memcpy(J, q->J, sizeof(double) * (size_t)(q->n * q->n));
    return 0;
}

// Factor W for gh, solve W x = b for a known x; returns the max error and
// whether the sparse path was taken.
static double spj_solve(hyd_solver* s, spj* q, double gh, int* sparse) {
    const int n = q->n;
    double y[16] = {0}, f0[16] = {0}, x[16] = {0}, b[16] = {0};
    uint64_t seed = 0x1234567ULL + (uint64_t)(gh * 1e6);
    for (int i = 0; i < n; ++i) y[i] = 1.0 + 0.1 * i, x[i] = urand(&seed);
    spj_f(q, 0.0, y, f0);
    s->j_force = 1;
    int rc = hydPrepareW(s, 0.0, y, f0, gh);
    CHECK(rc == HYD_OK, "prepare W rc %d", rc);
    for (int i = 0; i < n; ++i) {
        b[i] = x[i];
        for (int j = 0; j < n; ++j) b[i] -= gh * q->J[i * n + j] * x[j];
    }
    hydSolveW(s, b);
    *sparse = s->w_sparse;
    double e = 0.0;
    for (int i = 0; i < n; ++i) e = fmax(e, fabs(b[i] - x[i]));
    return e;
}

static void test_sparse_w(void) {
    uint64_t seed = 0xC0FFEEULL;
    for (int n = 3; n <= 16; ++n) {
        spj q = {.n = n};
        // A stiff, sparse J: negative diagonal, about 3 off-diagonals per row.
        for (int i = 0; i < n; ++i) {
            q.J[i * n + i] = -10.0 - 100.0 * fabs(urand(&seed));
            for (int k = 0; k < 3; ++k) {
                int j = (int)((urand(&seed) + 1.0) * 0.5 * n) % n;
                if (j != i) q.J[i * n + j] = 20.0 * urand(&seed);
            }
        }
        hyd_problem p = {0};
        p.n = n, p.f = spj_f, p.jac = spj_jac, p.user = &q, p.autonomous = 1;
        hyd_solver* s = hyd_solver_create(&p, HYD_RODAS3, NULL);
        CHECK(s && s->sp_on, "n = %d: sparse path available", n);
        if (!s) continue;
        int sparse = 0;
        double e = spj_solve(s, &q, 0.01, &sparse);
        CHECK(e < 1e-12, "n = %d sparse: error %.3g", n, e);
        CHECK(sparse, "n = %d: diagonally dominant W takes the sparse path", n);
        // A new non-zero grows the pattern (and its fill).
        q.J[(n - 1) * n] = 50.0;
        q.J[n - 1] = -30.0;
        e = spj_solve(s, &q, 0.02, &sparse);
        CHECK(e < 1e-12, "n = %d grown pattern: error %.3g", n, e);
        // Zero W's whole diagonal (J_ii = 1/gh), whatever order the states
        // are eliminated in the first pivot is zero, and give each row a
        // large entry in the next column (W stays far from singular): the
        // threshold test must hand over to the pivoting LU.
        const double gh = 0.05;
        for (int i = 0; i < n; ++i) {
            q.J[i * n + i] = 1.0 / gh;
            q.J[i * n + (i + 1) % n] = 500.0;
        }
        long fb = s->sp_fallbacks;
        e = spj_solve(s, &q, gh, &sparse);
        CHECK(e < 1e-10, "n = %d fallback: error %.3g", n, e);
        CHECK(!sparse && s->sp_fallbacks == fb + 1, "n = %d: weak pivot falls back", n);
        // Back to a strong diagonal on the same pattern: the sparse path
        // again, on a W that the dense LU had filled in every entry (those
        // off the pattern must not survive into the sparse factors).
        for (int i = 0; i < n; ++i) q.J[i * n + i] = -1e4 - 1e3 * fabs(urand(&seed)); // above the 500s
        e = spj_solve(s, &q, 0.01, &sparse);
        CHECK(e < 1e-12 && sparse, "n = %d after the fallback: error %.3g, sparse %d", n, e, sparse);
        e = spj_solve(s, &q, 0.02, &sparse); // and once more, from a sparse W
        CHECK(e < 1e-12 && sparse, "n = %d sparse again: error %.3g, sparse %d", n, e, sparse);
        // Non-finite J: W is singular, as with the dense LU.
        q.J[2] = NAN;
        double y[16] = {0}, f0[16] = {0};
        s->j_force = 1;
        CHECK(hydPrepareW(s, 0.0, y, f0, gh) == HYD_ERR_SINGULAR, "n = %d: NaN in J", n);
        hyd_solver_destroy(s);
    }
}

// An arrow matrix (state 0 coupled both ways to every other state, the
// others only to it: a pressure node feeding many branches). Eliminated in
// natural order, state 0 first, its row and column fill the whole matrix:
// n (n - 1) off-diagonal factor entries. Eliminated last, nothing fills:
// 2 (n - 1), the fill-free order any minimum-fill rule finds (the hub among
// the last two). The solve
// must be as exact either way.
static void test_sparse_order(void) {
    for (int n = 4; n <= 16; n += 4) {
        spj q = {.n = n};
        for (int i = 0; i < n; ++i) q.J[i * n + i] = -100.0 - i;
        for (int i = 1; i < n; ++i) {
            q.J[i] = 10.0 + i;          // row 0
            q.J[i * n] = -5.0 - 0.5 * i; // column 0
        }
        hyd_problem p = {0};
        p.n = n, p.f = spj_f, p.jac = spj_jac, p.user = &q, p.autonomous = 1;
        hyd_solver* s = hyd_solver_create(&p, HYD_RODAS3, NULL);
        CHECK(s && s->sp_on, "n = %d: sparse path available", n);
        if (!s) continue;
        int sparse = 0;
        const double e = spj_solve(s, &q, 0.01, &sparse);
        CHECK(e < 1e-12 && sparse, "n = %d arrow: error %.3g, sparse %d", n, e, sparse);
        const int nlu = s->sp_lptr[n] + s->sp_uptr[n];
        CHECK(nlu == 2 * (n - 1), "n = %d arrow: %d off-diagonal factor entries, want %d (natural order: %d)", n,
              nlu, 2 * (n - 1), n * (n - 1));
        // With two states left, hub and one leaf, either may go first.
        CHECK(s->sp_pos[0] >= n - 2, "n = %d arrow: the hub state eliminated at step %d, want one of the last two",
              n, s->sp_pos[0]);
        hyd_solver_destroy(s);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_random_system);
    RUN_TEST(test_pivoting_needed);
    RUN_TEST(test_singular);
    RUN_TEST(test_sparse_w);
    RUN_TEST(test_sparse_order);
    TEST_MAIN_END();
}
