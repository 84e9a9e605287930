// test_lu.c: the dense LU solves a random well-conditioned system and reports
// singular matrices.
#include "check.h"
#include "hyd_solver.h"

#include <stdint.h>

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

int main(int argc, char** argv) {
    RUN_TEST(test_random_system);
    RUN_TEST(test_pivoting_needed);
    RUN_TEST(test_singular);
    TEST_MAIN_END();
}
