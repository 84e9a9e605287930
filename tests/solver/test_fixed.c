// test_fixed.c: the fixed-step methods. Convergence orders against an exact
// solution (Krus and ROS2 order 2, RK4 order 4, also with a stale or
// block-diagonal W: the W-method property), and the stability function at
// h lambda = -1e6 (Krus -> -1, ROS2 -> 0).
#include "check.h"
#include "hyd_solver.h"
#include "problems.h"

typedef enum { JAC_ANALYTIC, JAC_FD, JAC_BLOCK_STALE, JAC_BLOCK_FD } jac_mode;

// Max-norm error at t = 2 of a run from the exact initial value with step h.
static double conv_error(hyd_method m, jac_mode jm, double h) {
    static const int blocks[2] = {1, 2};
    hyd_problem p = {0};
    p.n = 3;
    p.f = conv_f;
    p.jac = (jm == JAC_ANALYTIC || jm == JAC_BLOCK_STALE) ? conv_jac : NULL;
    if (jm == JAC_BLOCK_STALE || jm == JAC_BLOCK_FD) {
        p.nblock = 2;
        p.block_size = blocks;
    }
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = h;
    if (jm == JAC_BLOCK_STALE) {
        // J from t = 0 only, and only its diagonal blocks: W is far from exact.
        o.jac_every = 1000000;
        o.jac_max_age = 0.0;
    }
    hyd_solver* s = hyd_solver_create(&p, m, &o);
    CHECK(s != NULL, "create");
    if (!s) return NAN;
    double y[3], ye[3], t = 0.0;
    conv_exact(0.0, y);
    int rc = hyd_solver_advance(s, &t, y, 2.0);
    CHECK(rc == HYD_OK, "advance rc %d", rc);
    CHECK(t == 2.0, "landed at %.17g", t);
    if (jm == JAC_BLOCK_STALE) CHECK(hyd_solver_get_stats(s)->jevals == 1, "J reused");
    conv_exact(2.0, ye);
    double e = 0.0;
    for (int i = 0; i < 3; ++i) e = fmax(e, fabs(y[i] - ye[i]));
    hyd_solver_destroy(s);
    return e;
}

// Observed order log2(e(h) / e(h/2)) on the finest pair of a halving sequence.
static void check_order(hyd_method m, jac_mode jm, double h0, int levels, double order) {
    double e_prev = conv_error(m, jm, h0), rate = 0.0;
    for (int l = 1; l < levels; ++l) {
        double e = conv_error(m, jm, h0 / (double)(1 << l));
        rate = log2(e_prev / e);
        e_prev = e;
    }
    CHECK(fabs(rate - order) < 0.2, "%s (J mode %d): observed order %.3f, expected %.0f",
          hyd_method_name(m), (int)jm, rate, order);
}

static void test_krus_order2(void) {
    check_order(HYD_KRUS, JAC_ANALYTIC, 0.1, 5, 2.0);
    check_order(HYD_KRUS, JAC_FD, 0.1, 5, 2.0);
    check_order(HYD_KRUS, JAC_BLOCK_STALE, 0.1, 5, 2.0);
    check_order(HYD_KRUS, JAC_BLOCK_FD, 0.1, 5, 2.0);
}

static void test_ros2_order2(void) {
    check_order(HYD_ROS2, JAC_ANALYTIC, 0.1, 5, 2.0);
    check_order(HYD_ROS2, JAC_FD, 0.1, 5, 2.0);
    check_order(HYD_ROS2, JAC_BLOCK_STALE, 0.1, 5, 2.0);
    check_order(HYD_ROS2, JAC_BLOCK_FD, 0.1, 5, 2.0);
}

static void test_rk4_order4(void) { check_order(HYD_RK4, JAC_FD, 0.2, 4, 4.0); }

// y' = lambda y, one step of h = 1 with h lambda = -1e6: y1 / y0 = R(-1e6).
static int lin_f(void* user, double t, const double* y, double* dy) {
    (void)t;
    dy[0] = *(const double*)user * y[0];
    return 0;
}
static int lin_jac(void* user, double t, const double* y, double* J) {
    (void)t;
    (void)y;
    J[0] = *(const double*)user;
    return 0;
}

static double stability_r(hyd_method m, double z) {
    double lambda = z;
    hyd_problem p = {0};
    p.n = 1;
    p.f = lin_f;
    p.jac = lin_jac;
    p.user = &lambda;
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 1.0;
    hyd_solver* s = hyd_solver_create(&p, m, &o);
    double y = 1.0, t = 0.0;
    int rc = hyd_solver_step(s, &t, &y, 1.0);
    CHECK(rc == HYD_OK, "%s step rc %d", hyd_method_name(m), rc);
    hyd_solver_destroy(s);
    return y;
}

static void test_stability_at_infinity(void) {
    double rk = stability_r(HYD_KRUS, -1e6);
    CHECK(fabs(rk + 1.0) < 1e-3, "Krus R(-1e6) = %.6g, expected about -1", rk);
    double r2 = stability_r(HYD_ROS2, -1e6);
    CHECK(fabs(r2) < 1e-3, "ROS2 R(-1e6) = %.6g, expected about 0", r2);
    // Krus has the trapezoidal rule's R(z) = (1 + z/2) / (1 - z/2).
    double z = -3.0, r = stability_r(HYD_KRUS, z);
    CHECK_NEAR(r, (1.0 + z / 2.0) / (1.0 - z / 2.0), 1e-14);
    // A-stability: |R| <= 1 along the negative real axis.
    for (double zz = -0.01; zz > -1e8; zz *= 3.7) {
        CHECK(fabs(stability_r(HYD_KRUS, zz)) <= 1.0 + 1e-14, "Krus |R(%g)| > 1", zz);
        CHECK(fabs(stability_r(HYD_ROS2, zz)) <= 1.0 + 1e-14, "ROS2 |R(%g)| > 1", zz);
    }
}

static void test_names(void) {
    for (int m = 0; m < HYD_METHOD_COUNT; ++m)
        CHECK(hyd_method_parse(hyd_method_name((hyd_method)m)) == m, "round trip %d", m);
    CHECK(hyd_method_parse("euler") == -1, "unknown name");
    CHECK(hyd_method_order(HYD_KRUS) == 2 && hyd_method_order(HYD_RK4) == 4 &&
              hyd_method_order(HYD_RODAS3) == 3,
          "orders");
    CHECK(!hyd_method_is_adaptive(HYD_ROS2) && hyd_method_is_adaptive(HYD_ROS34PW2), "adaptive");
}

int main(int argc, char** argv) {
    RUN_TEST(test_krus_order2);
    RUN_TEST(test_ros2_order2);
    RUN_TEST(test_rk4_order4);
    RUN_TEST(test_stability_at_infinity);
    RUN_TEST(test_names);
    TEST_MAIN_END();
}
