// test_lagrange.c: the 2-DOF equations against invariants and identities.
#include "check.h"
#include "hyd_solver.h"
#include "lagrange.h"

#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct mech_only {
    crane_mech m;
    lagrange_variant v;
    double m3;
} mech_only;

// Free motion: tau = 0, no damping. y = [q1, q2, q1', q2'].
static int free_rhs(void* user, double t, const double* y, double* f) {
    (void)t;
    const mech_only* s = user;
    lagrange_terms lt;
    lagrange_eval_terms(&s->m, s->v, s->m3, y, y + 2, &lt);
    const double tau[2] = {0, 0};
    f[0] = y[2];
    f[1] = y[3];
    lagrange_accel(&lt, tau, f + 2);
    return 0;
}

// Energy is conserved with tau = 0 in the full model (docs/lagrange.md). The
// crane swings through large angles (a double pendulum), so this exercises
// the Coriolis terms: drop them and the drift is of order 1.
static void test_energy_conservation(void) {
    mech_only s = {crane_default_mech(), LAGRANGE_FULL, 500.0};
    hyd_problem p = {.n = 4, .f = free_rhs, .user = &s};
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 1e-4;
    hyd_solver* sol = hyd_solver_create(&p, HYD_RK4, &o);
    double y[4] = {100 * M_PI / 180, -60 * M_PI / 180, 0.3, -0.5};
    double E0 = lagrange_energy(&s.m, s.m3, y, y + 2);
    double t = 0, Emax = 0;
    for (int k = 1; k <= 100; ++k) {
        CHECK(hyd_solver_advance(sol, &t, y, 0.1 * k) == HYD_OK, "advance failed at t = %g", t);
        double E = lagrange_energy(&s.m, s.m3, y, y + 2);
        Emax = fmax(Emax, fabs(E - E0));
    }
    // Scale: the potential energy swing of the crane, |E0| is not a good
    // scale when it happens to be near zero.
    double scale = (180 * 1.15 + 640 * 2.3 + 140 * 1.25 + 500 * 2.5) * 9.81;
    CHECK(Emax / scale < 1e-6, "relative energy drift %.3g over 10 s", Emax / scale);
    // And the motion really is large: the arm swung.
    CHECK(fabs(y[0] - 100 * M_PI / 180) > 0.01 || fabs(y[2]) > 0.01, "no motion");

    // Without the Coriolis terms (variant paper, plus inertias) energy is not
    // conserved: the test can tell a wrong C.
    mech_only s2 = s;
    s2.v = LAGRANGE_PAPER;
    hyd_problem p2 = {.n = 4, .f = free_rhs, .user = &s2};
    hyd_solver* sol2 = hyd_solver_create(&p2, HYD_RK4, &o);
    double y2[4] = {100 * M_PI / 180, -60 * M_PI / 180, 0.3, -0.5};
    double t2 = 0;
    hyd_solver_advance(sol2, &t2, y2, 10.0);
    // Energy of the paper model (point masses): compare with its own T + V.
    crane_mech pm = s.m;
    pm.link[0].inertia = pm.link[1].inertia = 0;
    double E20 = 0, E21 = 0;
    double y20[4] = {100 * M_PI / 180, -60 * M_PI / 180, 0.3, -0.5};
    E20 = lagrange_energy(&pm, s.m3, y20, y20 + 2);
    E21 = lagrange_energy(&pm, s.m3, y2, y2 + 2);
    CHECK(fabs(E21 - E20) / scale > 1e-3, "dropping C should break energy conservation, drift %.3g",
          fabs(E21 - E20) / scale);
    hyd_solver_destroy(sol);
    hyd_solver_destroy(sol2);
}

// H is the Hessian of T: check H against finite differences of the kinetic
// energy computed independently from the mass-centre velocities.
static double kinetic_direct(const crane_mech* m, double m3, const double q[2], const double qd[2]) {
    const double L1 = m->link[0].length, L2 = m->link[1].length, e1 = m->link[0].com, e2 = m->link[1].com;
    const double w1 = qd[0], w12 = qd[0] + qd[1];
    // Velocities of points on the chain: v = w x r in 2D.
    const double vc1[2] = {e1 * cos(q[0]) * w1, e1 * sin(q[0]) * w1};
    const double v2b[2] = {L1 * cos(q[0]) * w1, L1 * sin(q[0]) * w1};
    const double vc2[2] = {v2b[0] + e2 * cos(q[0] + q[1]) * w12, v2b[1] + e2 * sin(q[0] + q[1]) * w12};
    const double v3[2] = {v2b[0] + L2 * cos(q[0] + q[1]) * w12, v2b[1] + L2 * sin(q[0] + q[1]) * w12};
    return 0.5 * m->link[0].mass * (vc1[0] * vc1[0] + vc1[1] * vc1[1]) + 0.5 * m->link[0].inertia * w1 * w1 +
           0.5 * m->link[1].mass * (vc2[0] * vc2[0] + vc2[1] * vc2[1]) + 0.5 * m->link[1].inertia * w12 * w12 +
           0.5 * m3 * (v3[0] * v3[0] + v3[1] * v3[1]);
}

static void test_mass_matrix_from_kinetic_energy(void) {
    crane_mech m = crane_default_mech();
    srand(7);
    for (int trial = 0; trial < 20; ++trial) {
        double q[2] = {3.0 * rand() / RAND_MAX, -3.0 * rand() / RAND_MAX};
        double qd[2] = {1.0 - 2.0 * rand() / RAND_MAX, 1.0 - 2.0 * rand() / RAND_MAX};
        lagrange_terms lt;
        lagrange_eval_terms(&m, LAGRANGE_FULL, 300, q, qd, &lt);
        double T = 0.5 * (lt.H[0][0] * qd[0] * qd[0] + 2 * lt.H[0][1] * qd[0] * qd[1] + lt.H[1][1] * qd[1] * qd[1]);
        CHECK_REL(T, kinetic_direct(&m, 300, q, qd), 1e-12);
    }
}

// The variants differ exactly by the terms the paper drops (docs/lagrange.md).
static void test_variants_differ_by_dropped_terms(void) {
    crane_mech m = crane_default_mech();
    const double m3 = 500, g = m.gravity;
    const double I1 = m.link[0].inertia, I2 = m.link[1].inertia;
    double q[2] = {2.0, -1.2}, qd[2] = {0.4, -0.7};
    lagrange_terms f, p, t;
    lagrange_eval_terms(&m, LAGRANGE_FULL, m3, q, qd, &f);
    lagrange_eval_terms(&m, LAGRANGE_PAPER, m3, q, qd, &p);
    lagrange_eval_terms(&m, LAGRANGE_PAPER_TYPO, m3, q, qd, &t);
    CHECK_NEAR(f.H[0][0] - p.H[0][0], I1 + I2, 1e-9);
    CHECK_NEAR(f.H[0][1] - p.H[0][1], I2, 1e-9);
    CHECK_NEAR(f.H[1][1] - p.H[1][1], I2, 1e-9);
    CHECK(p.C[0] == 0 && p.C[1] == 0, "paper drops C");
    CHECK(f.C[0] != 0 && f.C[1] != 0, "full keeps C");
    CHECK_NEAR(f.G[0], p.G[0], 1e-9);
    CHECK_NEAR(f.G[1], p.G[1], 1e-9);
    // The typo: (m2 + m3) L2 instead of (m2 + m3) L1 in G1 only.
    double dG = (m.link[1].mass + m3) * (m.link[1].length - m.link[0].length) * g * sin(q[0]);
    CHECK_NEAR(t.G[0] - p.G[0], dG, 1e-9);
    CHECK_NEAR(t.G[1], p.G[1], 1e-12);
    // C matches the Christoffel symbols of H computed by finite differences.
    const double hq = 1e-6;
    double qa[2] = {q[0], q[1] + hq}, qb[2] = {q[0], q[1] - hq};
    lagrange_terms a, b;
    lagrange_eval_terms(&m, LAGRANGE_FULL, m3, qa, qd, &a);
    lagrange_eval_terms(&m, LAGRANGE_FULL, m3, qb, qd, &b);
    double d11 = (a.H[0][0] - b.H[0][0]) / (2 * hq), d12 = (a.H[0][1] - b.H[0][1]) / (2 * hq);
    // C_i = sum_jk (dH_ij/dq_k - 1/2 dH_jk/dq_i) qd_j qd_k, only d/dq2 non-zero.
    double C1 = d11 * qd[0] * qd[1] + d12 * qd[1] * qd[1];
    double C2 = -0.5 * d11 * qd[0] * qd[0];
    CHECK_NEAR(f.C[0], C1, 1e-5 * fabs(C1) + 1e-6);
    CHECK_NEAR(f.C[1], C2, 1e-5 * fabs(C2) + 1e-6);
    // And G is the gradient of the potential energy.
    double qz[2] = {0, 0}, q1p[2] = {q[0] + hq, q[1]}, q1m[2] = {q[0] - hq, q[1]}, q2p[2] = {q[0], q[1] + hq},
           q2m[2] = {q[0], q[1] - hq};
    double dV1 = (lagrange_energy(&m, m3, q1p, qz) - lagrange_energy(&m, m3, q1m, qz)) / (2 * hq);
    double dV2 = (lagrange_energy(&m, m3, q2p, qz) - lagrange_energy(&m, m3, q2m, qz)) / (2 * hq);
    CHECK_NEAR(f.G[0], dV1, 1e-5 * fabs(dV1));
    CHECK_NEAR(f.G[1], dV2, 1e-5 * fabs(dV2));
}

// Eq. 5: the closed form against the distance between the transformed pins.
static void test_cylinder_kinematics(void) {
    crane_mech m = crane_default_mech();
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &m.act[k];
        for (int i = 0; i <= 10; ++i) {
            double q = k == 0 ? (70 + 9.0 * i) * M_PI / 180 : (-130 + 9.0 * i) * M_PI / 180;
            // Parent frame rotation pa, child rotation ca (elevation angles).
            double ca = k == 0 ? q - M_PI / 2 : q;
            double bx = a->base_mount[0], bz = a->base_mount[1];
            double rx = a->rod_mount[0] * cos(ca) - a->rod_mount[1] * sin(ca);
            double rz = a->rod_mount[0] * sin(ca) + a->rod_mount[1] * cos(ca);
            double direct = hypot(rx - bx, rz - bz);
            double dxdq;
            double x = crane_pin_length(a, q, &dxdq);
            CHECK_NEAR(x, direct, 1e-12);
            double hq = 1e-7;
            double fd = (crane_pin_length(a, q + hq, NULL) - crane_pin_length(a, q - hq, NULL)) / (2 * hq);
            CHECK_NEAR(dxdq, fd, 1e-7);
            double st = crane_stroke(a, q);
            if (st >= 0 && st <= 0.6) CHECK_NEAR(crane_joint_for_stroke(a, st), q, 1e-9);
        }
    }
    // Default mounts: strokes cover the joint ranges of docs/model.md.
    CHECK_NEAR(crane_stroke(&m.act[0], 70 * M_PI / 180), 0.0, 2e-3);
    CHECK_NEAR(crane_stroke(&m.act[0], 160 * M_PI / 180), 0.7, 2e-3);
    CHECK_NEAR(crane_stroke(&m.act[1], -135 * M_PI / 180), 0.0, 2e-3);
    const double stroke[2] = {0.7, 0.6};
    char err[200];
    CHECK(crane_mech_check(&m, stroke, err, sizeof err) == 0, "default mounts rejected: %s", err);
    CHECK(m.act[0].closed_length >= 0.7 + 0.25 && m.act[1].closed_length >= 0.6 + 0.25, "closed lengths");
}

// crane_gravity (crane_model.c: the statics the load chart, the limiter and
// the start checks use, so they need no backend) against the analytic
// backend's G bit for bit, and against the sum of the moments m g x of each
// mass about each joint, by hand, at random poses, tip masses and
// perturbed geometries.
static void test_crane_gravity(void) {
    srand(26);
    int same = 0, n = 0;
    for (int i = 0; i < 2000; ++i) {
        crane_mech m = crane_default_mech();
        const double f = 0.5 + (double)rand() / RAND_MAX;
        m.link[0].length *= f;
        m.link[1].mass *= 2.0 - f;
        m.link[1].com *= f > 1.0 ? 1.0 / f : f;
        const double m3 = i % 4 == 0 ? 0.0 : 3000.0 * rand() / RAND_MAX;
        const double q[2] = {M_PI * (2.0 * rand() / RAND_MAX - 1.0), M_PI * (2.0 * rand() / RAND_MAX - 1.0)};
        double G[2], Gl[2];
        crane_gravity(&m, m3, q, G);
        lagrange_gravity(&m, LAGRANGE_FULL, m3, q, Gl);
        same += G[0] == Gl[0] && G[1] == Gl[1];
        ++n;
        // By hand: x of each mass from joint 1 (horizontal reach), g times
        // mass times x about joint 1; about joint 2 only the end arm and the tip.
        const double g = m.gravity, L1 = m.link[0].length, L2 = m.link[1].length;
        const double x1 = m.link[0].com * sin(q[0]), xj2 = L1 * sin(q[0]);
        const double x2 = xj2 + m.link[1].com * sin(q[0] + q[1]), xt = xj2 + L2 * sin(q[0] + q[1]);
        const double G1 = g * (m.link[0].mass * x1 + m.link[1].mass * x2 + m3 * xt);
        const double G2 = g * (m.link[1].mass * (x2 - xj2) + m3 * (xt - xj2));
        const double scale = g * (m.link[0].mass * L1 + (m.link[1].mass + m3) * (L1 + L2));
        CHECK_NEAR(G[0], G1, 1e-12 * scale);
        CHECK_NEAR(G[1], G2, 1e-12 * scale);
    }
    CHECK(same == n, "crane_gravity equals lagrange_gravity(LAGRANGE_FULL) bit for bit at %d of %d poses", same, n);
}

int main(int argc, char** argv) {
    RUN_TEST(test_energy_conservation);
    RUN_TEST(test_mass_matrix_from_kinetic_energy);
    RUN_TEST(test_variants_differ_by_dropped_terms);
    RUN_TEST(test_cylinder_kinematics);
    RUN_TEST(test_crane_gravity);
    TEST_MAIN_END();
}
