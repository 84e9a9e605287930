// test_chain_crane.c: the chain library on today's two-link crane against the
// closed forms of lagrange.c (H, C, G; docs/lagrange.md) and crane_model.c
// (pin length and lever arm, paper Eq. 5), at many random states, with and
// without a tip mass and on perturbed geometries.
#include "chain.h"
#include "chain_crane.h"
#include "check.h"
#include "crane_model.h"
#include "lagrange.h"

#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double urand(double lo, double hi) { return lo + (hi - lo) * rand() / (double)RAND_MAX; }

// A crane with every length, mass, centre of mass and inertia changed, so the
// comparison does not rest on the default's numbers.
static crane_mech perturbed(void) {
    crane_mech m = crane_default_mech();
    for (int i = 0; i < 2; ++i) {
        crane_link* l = &m.link[i];
        l->length *= urand(0.7, 1.4);
        l->mass *= urand(0.5, 2.0);
        l->com = l->length * urand(0.2, 0.8);
        // With Ixx and Izz from the box (as the ODE world), the triangle rule
        // holds for Iyy within m (L^2 -+ h^2) / 12 or so: stay inside.
        l->inertia = l->mass * (l->length * l->length + urand(-0.5, 0.5) * l->height * l->height) / 12.0;
    }
    m.column_height *= urand(0.8, 1.2);
    m.gravity = urand(9.7, 9.9);
    crane_mech_derive(&m);
    return m;
}

static chain* make(const crane_mech* m, double tip, int slew_free, chain_crane* cc) {
    chain_crane_opts o = {slew_free, 0.3, 0.12};
    CHECK(chain_from_crane_mech(m, tip, &o, cc) == 0, "adapter refused the crane");
    char err[256] = "";
    double g[3] = {0, 0, -m->gravity};
    chain* c = chain_create(cc->body, 3, g, err, sizeof err);
    CHECK(c != NULL, "chain_create: %s", err);
    return c;
}

static double maxabs(const double* x, int n) {
    double s = 0;
    for (int k = 0; k < n; ++k) s = fmax(s, fabs(x[k]));
    return s;
}

// |a - b| within rel of the largest entry of b (an entry near zero, as H12
// can be, is compared on the matrix's scale, not its own).
static int close_rel(const double* a, const double* b, int n, double rel, double* worst) {
    const double s = maxabs(b, n);
    int ok = 1;
    for (int k = 0; k < n; ++k) {
        const double e = fabs(a[k] - b[k]) / (s > 0 ? s : 1.0);
        if (worst) *worst = fmax(*worst, e);
        if (!(e <= rel)) ok = 0;
    }
    return ok;
}

// M, C and G of the clamped chain equal lagrange_eval_terms(LAGRANGE_FULL).
static void test_terms_match_lagrange(void) {
    srand(11);
    double worst = 0;
    int n = 0;
    for (int geo = 0; geo < 4; ++geo) {
        crane_mech m = geo == 0 ? crane_default_mech() : perturbed();
        for (int t = 0; t < 3; ++t) {
            const double tip = t == 0 ? 0.0 : t == 1 ? 500.0 : urand(10, 3000);
            chain_crane cc;
            chain* c = make(&m, tip, 0, &cc);
            if (!c) return;
            CHECK(chain_ndof(c) == 2, "clamped crane has %d DOF", chain_ndof(c));
            chain_ws* w = chain_ws_create(c);
            for (int k = 0; k < 100; ++k) {
                const double q[2] = {urand(0, 2 * M_PI), urand(-M_PI, M_PI)};
                const double qd[2] = {urand(-2, 2), urand(-2, 2)};
                lagrange_terms lt;
                lagrange_eval_terms(&m, LAGRANGE_FULL, tip, q, qd, &lt);
                chain_update(c, w, q, qd);
                double M[4], C[2], G[2], B[2];
                chain_mass_matrix(c, w, M);
                chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY, C);
                chain_inverse_dynamics(c, w, NULL, CHAIN_GRAVITY, G);
                chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY | CHAIN_GRAVITY, B);
                const double H[4] = {lt.H[0][0], lt.H[0][1], lt.H[1][0], lt.H[1][1]};
                const double CG[2] = {lt.C[0] + lt.G[0], lt.C[1] + lt.G[1]};
                CHECK(close_rel(M, H, 4, 1e-12, &worst), "M != H at q = %g %g tip %g: %g %g %g %g vs %g %g %g %g",
                      q[0], q[1], tip, M[0], M[1], M[2], M[3], H[0], H[1], H[2], H[3]);
                CHECK(close_rel(C, lt.C, 2, 1e-12, &worst), "C at q = %g %g qd = %g %g: %g %g vs %g %g", q[0], q[1],
                      qd[0], qd[1], C[0], C[1], lt.C[0], lt.C[1]);
                CHECK(close_rel(G, lt.G, 2, 1e-12, &worst), "G at q = %g %g: %g %g vs %g %g", q[0], q[1], G[0], G[1],
                      lt.G[0], lt.G[1]);
                CHECK(close_rel(B, CG, 2, 1e-12, &worst), "C + G at q = %g %g", q[0], q[1]);
                // Forward dynamics against the closed-form 2x2 inverse.
                const double tau[2] = {urand(-5e4, 5e4), urand(-2e4, 2e4)};
                double a1[2], a2[2];
                lagrange_accel(&lt, tau, a1);
                CHECK(chain_forward_dynamics(c, w, tau, a2) == 0, "forward dynamics failed");
                CHECK(close_rel(a2, a1, 2, 1e-11, &worst), "qdd %g %g vs %g %g", a2[0], a2[1], a1[0], a1[1]);
                ++n;
            }
            chain_ws_free(w);
            chain_free(c);
        }
    }
    printf("  %d states: worst difference %.2e of the largest entry\n", n, worst);
}

// The slew free but still: the boom block of M and the boom bias equal the
// clamped crane's, at any slew angle (the slew does not change the boom plane's physics).
static void test_slew_free_at_rest_matches(void) {
    srand(12);
    crane_mech m = crane_default_mech();
    chain_crane cc;
    chain* c = make(&m, 400, 1, &cc);
    if (!c) return;
    CHECK(chain_ndof(c) == 3, "slewing crane has %d DOF", chain_ndof(c));
    chain_ws* w = chain_ws_create(c);
    for (int k = 0; k < 50; ++k) {
        const double q[3] = {urand(-4, 4), urand(0.5, 2.8), urand(-2.5, 0)};
        const double qd[3] = {0, urand(-1, 1), urand(-1, 1)};
        lagrange_terms lt;
        lagrange_eval_terms(&m, LAGRANGE_FULL, 400, q + 1, qd + 1, &lt);
        chain_update(c, w, q, qd);
        double M[9], B[3];
        chain_mass_matrix(c, w, M);
        chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY | CHAIN_GRAVITY, B);
        const double Mb[4] = {M[4], M[5], M[7], M[8]};
        const double H[4] = {lt.H[0][0], lt.H[0][1], lt.H[1][0], lt.H[1][1]};
        const double CG[2] = {lt.C[0] + lt.G[0], lt.C[1] + lt.G[1]};
        CHECK(close_rel(Mb, H, 4, 1e-12, NULL), "boom block of M at slew %g", q[0]);
        CHECK(close_rel(B + 1, CG, 2, 1e-12, NULL), "boom bias at slew %g", q[0]);
        // The booms' plane motion exerts no torque about the slew axis when
        // the slew is still (y is a principal axis of every boom).
        CHECK(fabs(B[0]) <= 1e-12 * maxabs(CG, 2) && fabs(M[1]) <= 1e-12 * M[0] && fabs(M[2]) <= 1e-12 * M[0],
              "slew coupling at rest: bias %g, M01 %g, M02 %g", B[0], M[1], M[2]);
    }
    chain_ws_free(w);
    chain_free(c);
}

// Pin length and lever arm of both cylinders equal crane_pin_length's, and
// d/dt(dL/dq) its second derivative (a b cos(phi) - r^2) / x (docs/lagrange.md) times q'.
static void test_cylinders_match_crane(void) {
    srand(13);
    double worst = 0;
    for (int geo = 0; geo < 3; ++geo) {
        crane_mech m = geo == 0 ? crane_default_mech() : perturbed();
        chain_crane cc;
        chain* c = make(&m, 0, 0, &cc);
        if (!c) return;
        chain_ws* w = chain_ws_create(c);
        for (int k = 0; k < 200; ++k) {
            const double q[2] = {urand(0.8, 2.9), urand(-2.6, -0.2)};
            const double qd[2] = {urand(-1, 1), urand(-1, 1)};
            chain_update(c, w, q, qd);
            for (int a = 0; a < 2; ++a) {
                const crane_actuator* ac = &m.act[a];
                const chain_crane_cyl* y = &cc.cyl[a];
                double r;
                const double x = crane_pin_length(ac, q[a], &r);
                const double phi = q[a] + ac->phi_offset;
                const double r2 = (ac->a * ac->b * cos(phi) - r * r) / x;
                double Ld, dL[2], dLd[2];
                const double L = chain_cylinder(c, w, y->body_a, y->pa, y->body_b, y->pb, &Ld, dL, dLd);
                CHECK_REL(L, x, 1e-12);
                const double want[2] = {a == 0 ? r : 0.0, a == 1 ? r : 0.0};
                const double wantd[2] = {a == 0 ? r2 * qd[0] : 0.0, a == 1 ? r2 * qd[1] : 0.0};
                CHECK(close_rel(dL, want, 2, 1e-12, &worst), "cyl %d dL/dq %g %g vs %g %g at q %g %g", a, dL[0],
                      dL[1], want[0], want[1], q[0], q[1]);
                CHECK(close_rel(dLd, wantd, 2, 1e-11, &worst), "cyl %d d/dt dL/dq %g %g vs %g %g", a, dLd[0], dLd[1],
                      wantd[0], wantd[1]);
                CHECK_NEAR(Ld, r * qd[a], 1e-12 * (fabs(r * qd[a]) + 1e-3));
                // Hessian: d2x/dq2 on the cylinder's own joint, nothing else.
                double H[4];
                chain_cylinder_hessian(c, w, y->body_a, y->pa, y->body_b, y->pb, H);
                const double Hw[4] = {a == 0 ? r2 : 0.0, 0.0, 0.0, a == 1 ? r2 : 0.0};
                CHECK(close_rel(H, Hw, 4, 1e-11, &worst), "cyl %d Hessian %g %g %g %g vs %g %g %g %g", a, H[0],
                      H[1], H[2], H[3], Hw[0], Hw[1], Hw[2], Hw[3]);
                // Stroke: the chain's length minus the closed length is crane_stroke's.
                CHECK_NEAR(L - y->closed_length, crane_stroke(ac, q[a]), 1e-12);
            }
            // The tip: crane_tip relative to joint 1 (on the column axis at column_height).
            double tip[3], pb[3] = {m.link[1].length, 0, 0}, R0[9], x, z;
            chain_world_point(c, w, 2, pb, tip, NULL);
            chain_body_pose(c, w, 0, R0, NULL);
            crane_tip(&m, q[0], q[1], &x, &z);
            // In the column's frame (slew 0.3 rad clamped): R0^T tip.
            const double tx = R0[0] * tip[0] + R0[3] * tip[1] + R0[6] * tip[2];
            const double ty = R0[1] * tip[0] + R0[4] * tip[1] + R0[7] * tip[2];
            CHECK_NEAR(tx, x, 1e-12);
            CHECK_NEAR(ty, 0, 1e-12);
            CHECK_NEAR(tip[2] - m.column_height, z, 1e-12);
        }
        chain_ws_free(w);
        chain_free(c);
    }
    printf("  worst lever-arm difference %.2e of the largest\n", worst);
}

// The adapter's bodies are the ODE world's (ode_world.c, boom_mass and the
// column cylinder): the end arm with the tip load merged has mass m + mt,
// centre c = (m e + mt L) / (m + mt) on its axis and, about it,
// Ixx = m (w^2 + h^2) / 12, Iyy = I + m (e - c)^2 + mt (L - c)^2,
// Izz = m (L^2 + w^2) / 12 + m (e - c)^2 + mt (L - c)^2; the column a solid
// cylinder m (3 r^2 + h^2) / 12, m r^2 / 2.
static void test_adapter_bodies(void) {
    crane_mech m = crane_default_mech();
    const double mt = 700, r = 0.12;
    chain_crane cc;
    chain_crane_opts o = {1, 0, r};
    CHECK(chain_from_crane_mech(&m, mt, &o, &cc) == 0, "adapter");
    const crane_link* l = &m.link[1];
    const double M = l->mass + mt, c = (l->mass * l->com + mt * l->length) / M;
    const double d1 = l->com - c, d2 = l->length - c, par = l->mass * d1 * d1 + mt * d2 * d2;
    const chain_body_def* b = &cc.body[2];
    CHECK_REL(b->mass, M, 1e-15);
    CHECK_REL(b->com[0], c, 1e-14);
    CHECK(b->com[1] == 0 && b->com[2] == 0, "tip load on the axis");
    CHECK_REL(b->inertia[0][0], l->mass * (l->width * l->width + l->height * l->height) / 12, 1e-14);
    CHECK_REL(b->inertia[1][1], l->inertia + par, 1e-14);
    CHECK_REL(b->inertia[2][2], l->mass * (l->length * l->length + l->width * l->width) / 12 + par, 1e-14);
    const crane_link* l0 = &m.link[0];
    b = &cc.body[1];
    CHECK_REL(b->inertia[2][2], l0->mass * (l0->length * l0->length + l0->width * l0->width) / 12, 1e-14);
    b = &cc.body[0];
    const double h = m.column_height;
    CHECK_REL(b->inertia[0][0], m.column_mass * (3 * r * r + h * h) / 12, 1e-14);
    CHECK_REL(b->inertia[2][2], m.column_mass * r * r / 2, 1e-14);
    CHECK(!b->fixed && cc.body[1].origin[2] == h, "slew free, joint 1 at the column top");
}

int main(int argc, char** argv) {
    RUN_TEST(test_terms_match_lagrange);
    RUN_TEST(test_slew_free_at_rest_matches);
    RUN_TEST(test_cylinders_match_crane);
    RUN_TEST(test_adapter_bodies);
    TEST_MAIN_END();
}
