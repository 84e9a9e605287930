// problems.h: test problems with known solutions for the solver tests.
#ifndef SOLVER_TEST_PROBLEMS_H
#define SOLVER_TEST_PROBLEMS_H

#include <math.h>

// A smooth, nonlinear, non-autonomous 3-state system with exact solution
// g(t) = (sin t, cos t, 1 / (1 + t)):
//   y' = g'(t) + N(y) - N(g(t)),
//   N(y) = (-2 y1 + y2 y3,  -y1 y2 - 3 y2 + 0.5 y3,  -y3^2 - 5 y3 + y1).
// Every state is coupled to every other one, so a block-diagonal W really is
// an approximation.
static inline void conv_exact(double t, double* g) {
    g[0] = sin(t);
    g[1] = cos(t);
    g[2] = 1.0 / (1.0 + t);
}

static inline void conv_n(const double* y, double* r) {
    r[0] = -2.0 * y[0] + y[1] * y[2];
    r[1] = -y[0] * y[1] - 3.0 * y[1] + 0.5 * y[2];
    r[2] = -y[2] * y[2] - 5.0 * y[2] + y[0];
}

static inline int conv_f(void* user, double t, const double* y, double* dy) {
    (void)user;
    double g[3], ng[3], ny[3];
    conv_exact(t, g);
    conv_n(g, ng);
    conv_n(y, ny);
    const double gd[3] = {cos(t), -sin(t), -1.0 / ((1.0 + t) * (1.0 + t))};
    for (int i = 0; i < 3; ++i) dy[i] = gd[i] + ny[i] - ng[i];
    return 0;
}

static inline int conv_jac(void* user, double t, const double* y, double* J) {
    (void)user;
    (void)t;
    J[0] = -2.0, J[1] = y[2], J[2] = y[1];
    J[3] = -y[1], J[4] = -y[0] - 3.0, J[5] = 0.5;
    J[6] = 1.0, J[7] = 0.0, J[8] = -2.0 * y[2] - 5.0;
    return 0;
}

// d/dt of conv_f at fixed y (for RODAS3's df/dt term).
static inline int conv_dfdt(void* user, double t, const double* y, double* ft) {
    (void)user;
    (void)y;
    double g[3], gd[3], j[9];
    conv_exact(t, g);
    gd[0] = cos(t), gd[1] = -sin(t), gd[2] = -1.0 / ((1.0 + t) * (1.0 + t));
    const double gdd[3] = {-sin(t), -cos(t), 2.0 / ((1.0 + t) * (1.0 + t) * (1.0 + t))};
    conv_jac(NULL, t, g, j); // dN/dy at g(t)
    for (int i = 0; i < 3; ++i) {
        double jg = 0.0;
        for (int k = 0; k < 3; ++k) jg += j[i * 3 + k] * gd[k];
        ft[i] = gdd[i] - jg;
    }
    return 0;
}

// Robertson's chemical kinetics (Hairer & Wanner II, IV.1; IVP test set "rober").
static inline int rober_f(void* user, double t, const double* y, double* dy) {
    (void)user;
    (void)t;
    dy[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
    dy[2] = 3e7 * y[1] * y[1];
    dy[1] = -dy[0] - dy[2];
    return 0;
}
static inline int rober_jac(void* user, double t, const double* y, double* J) {
    (void)user;
    (void)t;
    J[0] = -0.04, J[1] = 1e4 * y[2], J[2] = 1e4 * y[1];
    J[6] = 0.0, J[7] = 6e7 * y[1], J[8] = 0.0;
    for (int j = 0; j < 3; ++j) J[3 + j] = -J[j] - J[6 + j];
    return 0;
}

// HIRES (Schaefer 1975; IVP test set "hires", 8 states).
static inline int hires_f(void* user, double t, const double* y, double* f) {
    (void)user;
    (void)t;
    f[0] = -1.71 * y[0] + 0.43 * y[1] + 8.32 * y[2] + 0.0007;
    f[1] = 1.71 * y[0] - 8.75 * y[1];
    f[2] = -10.03 * y[2] + 0.43 * y[3] + 0.035 * y[4];
    f[3] = 8.32 * y[1] + 1.71 * y[2] - 1.12 * y[3];
    f[4] = -1.745 * y[4] + 0.43 * y[5] + 0.43 * y[6];
    f[5] = -280.0 * y[5] * y[7] + 0.69 * y[3] + 1.71 * y[4] - 0.43 * y[5] + 0.69 * y[6];
    f[6] = 280.0 * y[5] * y[7] - 1.81 * y[6];
    f[7] = -f[6];
    return 0;
}
static inline int hires_jac(void* user, double t, const double* y, double* J) {
    (void)user;
    (void)t;
#define HJ(i, j) J[(i) * 8 + (j)]
    HJ(0, 0) = -1.71, HJ(0, 1) = 0.43, HJ(0, 2) = 8.32;
    HJ(1, 0) = 1.71, HJ(1, 1) = -8.75;
    HJ(2, 2) = -10.03, HJ(2, 3) = 0.43, HJ(2, 4) = 0.035;
    HJ(3, 1) = 8.32, HJ(3, 2) = 1.71, HJ(3, 3) = -1.12;
    HJ(4, 4) = -1.745, HJ(4, 5) = 0.43, HJ(4, 6) = 0.43;
    HJ(5, 3) = 0.69, HJ(5, 4) = 1.71, HJ(5, 5) = -0.43 - 280.0 * y[7], HJ(5, 6) = 0.69;
    HJ(5, 7) = -280.0 * y[5];
    HJ(6, 5) = 280.0 * y[7], HJ(6, 6) = -1.81, HJ(6, 7) = 280.0 * y[5];
    HJ(7, 5) = -HJ(6, 5), HJ(7, 6) = -HJ(6, 6), HJ(7, 7) = -HJ(6, 7);
#undef HJ
    return 0;
}

// Van der Pol in the IVP test set's scaled form ("vdpol"), eps = 1e-6:
//   y1' = y2,  y2' = ((1 - y1^2) y2 - y1) / eps,  y(0) = (2, 0), t in [0, 2].
static inline int vdpol_f(void* user, double t, const double* y, double* f) {
    (void)user;
    (void)t;
    f[0] = y[1];
    f[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / 1e-6;
    return 0;
}
static inline int vdpol_jac(void* user, double t, const double* y, double* J) {
    (void)user;
    (void)t;
    J[1] = 1.0;
    J[2] = (-2.0 * y[0] * y[1] - 1.0) / 1e-6;
    J[3] = (1.0 - y[0] * y[0]) / 1e-6;
    return 0;
}

#endif
