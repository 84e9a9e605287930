// test_compare.c: `compare`'s pressure figure as functions, on hand-made
// traces. The "% of peak" is of the reference's peak: the side run by
// CVODE, else the one with the shorter fixed step, else A. It used to be
// side A's peak whatever A was.
#include "app.h"
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// n rows at 1 kHz; p1A = peak * (i / (n-1)), the other pressures 1 bar,
// plus offset on p1A.
static sim_trace make_trace(int n, double peak, double offset) {
    sim_trace tr = {0};
    tr.v = calloc((size_t)n * SIM_NCOL, sizeof(double));
    tr.nrow = tr.cap = n;
    for (int i = 0; i < n; ++i) {
        double* r = tr.v + (size_t)i * SIM_NCOL;
        r[COL_T] = 1e-3 * i;
        r[COL_P1A] = peak * i / (n - 1) + offset;
        r[COL_P1B] = r[COL_P2A] = r[COL_P2B] = 1e5;
    }
    return tr;
}

static void test_percent_of_reference_peak(void) {
    // A peaks at 10 MPa, B at 10 MPa + 2 MPa: B - A = 2 MPa on every row of
    // p1A, so the RMS difference is 2 MPa: 20 % of A's peak, 16.67 % of B's
    // (12 MPa).
    sim_trace a = make_trace(101, 10e6, 0.0), b = make_trace(101, 10e6, 2e6);
    double rms, peak, pct;
    app_compare_pressure(&a, &b, 1, &rms, &peak, &pct);
    CHECK_NEAR(rms, 2e6, 1e-6);
    CHECK_NEAR(peak, 12e6, 1e-6);
    CHECK_NEAR(pct, 100.0 * 2.0 / 12.0, 1e-9);
    app_compare_pressure(&a, &b, 0, &rms, &peak, &pct);
    CHECK_NEAR(peak, 10e6, 1e-6);
    CHECK_NEAR(pct, 20.0, 1e-9);
    sim_trace_free(&a);
    sim_trace_free(&b);
}

static void test_reference_side(void) {
    sim_opts a = sim_default_opts(), b = sim_default_opts();
    CHECK(app_compare_reference(&a, &b) == 0, "same settings: A");
    b.cvode = true;
    CHECK(app_compare_reference(&a, &b) == 1, "B is cvode");
    a.cvode = true, b.cvode = false;
    CHECK(app_compare_reference(&a, &b) == 0, "A is cvode");
    a = sim_default_opts(), b = sim_default_opts();
    a.h = 1e-3, b.h = 1e-4;
    CHECK(app_compare_reference(&a, &b) == 1, "B has the shorter step");
    a.h = 1e-4, b.h = 1e-3;
    CHECK(app_compare_reference(&a, &b) == 0, "A has the shorter step");
    // An adaptive side has no step to compare: the first named.
    a.solver = HYD_RODAS3, b.h = 1e-5;
    CHECK(app_compare_reference(&a, &b) == 0, "adaptive A vs fixed B: A");
}

int main(int argc, char** argv) {
    RUN_TEST(test_percent_of_reference_peak);
    RUN_TEST(test_reference_side);
    TEST_MAIN_END();
}
