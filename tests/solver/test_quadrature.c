// test_quadrature.c: hyd_solver_step_quadrature, the integral of q' = P(t, y)
// by the method that took each step (quadrature.c). Checked against exact
// integrals: the method's order on a smooth non-autonomous problem, and the
// stiff limit, where a step does not resolve a decay and the trapezoid of P
// at the step's ends is off by h P0 / 2 while the method's own quadrature
// gives c y0 (1 - R(-lambda h)) / lambda, R its stability function.
#include "check.h"
#include "hyd_solver.h"

#include <math.h>
#include <stdio.h>

typedef struct lin {
    double lambda;
} lin;

// y' = -lambda y.
static int f_lin(void* user, double t, const double* y, double* dydt) {
    (void)t;
    dydt[0] = -((const lin*)user)->lambda * y[0];
    return 0;
}

static int j_lin(void* user, double t, const double* y, double* J) {
    (void)t, (void)y;
    J[0] = -((const lin*)user)->lambda;
    return 0;
}

// q' = (y, y^2 + t): linear and nonlinear in y, and non-autonomous.
static int p_quad(void* user, double t, const double* y, double* P) {
    (void)user;
    P[0] = y[0];
    P[1] = y[0] * y[0] + t;
    return 0;
}

// Integrate y' = -lambda y, y(0) = 1 from 0 to T in n equal steps of method m,
// adding each step's quadrature into q[2].
static int run(hyd_method m, double lambda, double T, int n, double q[2]) {
    lin L = {lambda};
    hyd_problem p = {0};
    p.n = 1;
    p.f = f_lin;
    p.jac = j_lin;
    p.user = &L;
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = T / n;
    o.jac_every = 1;
    hyd_solver* s = hyd_solver_create(&p, m, &o);
    if (!s) return -1;
    double t = 0.0, y[1] = {1.0}, P0[2], P1[2], work[2], dq[2];
    q[0] = q[1] = 0.0;
    p_quad(NULL, t, y, P0);
    for (int k = 0; k < n; ++k) {
        const double t0 = t, y0[1] = {y[0]};
        if (hyd_solver_step(s, &t, y, T / n)) {
            hyd_solver_destroy(s);
            return -1;
        }
        p_quad(NULL, t, y, P1);
        if (hyd_solver_step_quadrature(s, t0, y0, y, P0, P1, 2, p_quad, NULL, work, dq)) {
            hyd_solver_destroy(s);
            return -1;
        }
        q[0] += dq[0];
        q[1] += dq[1];
        P0[0] = P1[0], P0[1] = P1[1];
    }
    hyd_solver_destroy(s);
    return 0;
}

// The order of the quadrature on y' = -y over [0, 1]: exact integrals
// 1 - 1/e of y and (1 - e^-2)/2 + 1/2 of y^2 + t. Halving h divides the
// error by 2^p.
static void test_order(void) {
    const struct {
        hyd_method m;
        int p;
    } ms[] = {{HYD_KRUS, 2}, {HYD_ROS2, 2}, {HYD_RK4, 4}, {HYD_ROS34PW2, 3}, {HYD_RODAS3, 3}};
    const double ex[2] = {1.0 - exp(-1.0), 0.5 * (1.0 - exp(-2.0)) + 0.5};
    for (size_t i = 0; i < sizeof ms / sizeof ms[0]; ++i) {
        double e[3][2];
        for (int r = 0; r < 3; ++r) {
            double q[2] = {NAN, NAN};
            CHECK(run(ms[i].m, 1.0, 1.0, 10 << r, q) == 0, "%s: run failed", hyd_method_name(ms[i].m));
            for (int k = 0; k < 2; ++k) e[r][k] = fabs(q[k] - ex[k]);
        }
        for (int k = 0; k < 2; ++k) {
            const double order = log2(e[1][k] / e[2][k]);
            fprintf(stderr, "%s, q%d: errors %.3g %.3g %.3g, observed order %.2f\n", hyd_method_name(ms[i].m), k,
                    e[0][k], e[1][k], e[2][k], order);
            CHECK(order > ms[i].p - 0.3, "%s q%d: observed order %.2f, expected %d", hyd_method_name(ms[i].m), k,
                  order, ms[i].p);
        }
    }
}

// One step of h = 1 ms over a decay of lambda = 1e6 1/s (lambda h = 1000):
// the integral of y is (1 - e^(-lambda h)) / lambda = 1e-6 s, where the
// trapezoid of the ends gives h (1 + R) / 2, about 5e-4 s for the L-stable
// methods (R -> 0). Their quadrature is c (1 - R) / lambda: within 1 % of
// the exact value. Krus (R -> -1) gives 2 / lambda: not exact in this limit
// (its own solution rings), but bounded by it and far from h / 2.
static void test_stiff_limit(void) {
    const double lambda = 1e6, h = 1e-3, ex = (1.0 - exp(-lambda * h)) / lambda;
    const hyd_method ms[] = {HYD_ROS2, HYD_ROS34PW2, HYD_RODAS3, HYD_KRUS};
    for (size_t i = 0; i < sizeof ms / sizeof ms[0]; ++i) {
        double q[2] = {NAN, NAN};
        CHECK(run(ms[i], lambda, h, 1, q) == 0, "%s: run failed", hyd_method_name(ms[i]));
        fprintf(stderr, "%s, lambda h = 1000: integral of y %.6g s, exact %.6g s\n", hyd_method_name(ms[i]), q[0], ex);
        if (ms[i] == HYD_KRUS) CHECK(fabs(q[0]) <= 2.0 * ex * 1.01, "krus: %g s against %g s", q[0], ex);
        else CHECK_REL(q[0], ex, 0.01);
    }
}

int main(void) {
    test_order();
    test_stiff_limit();
    printf("%d checks, %d failed\n", check_count_, check_failures_);
    return check_failures_ != 0;
}
