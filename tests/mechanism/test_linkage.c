// test_linkage.c: the knuckle's four-bar linkage (linkage.h) against a loop
// solved by hand, against central differences on a crane-like linkage, its
// inverse, and its refusals.
#include "check.h"
#include "linkage.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/*
 * The hand-solved loop (all in the parent frame, (x, z), metres):
 *   J = (0, 0), angle0 = 0, rocker pin c = (0.3, 0) in the child, so
 *   C(q) = (0.3 cos q, 0.3 sin q);
 *   A = (0, 0.2), link l1 = 0.3, rocker l2 = 0.2; cylinder base B = (0, -0.8).
 * Since l1 = |JC| and l2 = |JA|, J-C-P-A closes as a parallelogram:
 *   P = A + (C - J) = (0.3 cos q, 0.2 + 0.3 sin q)
 * (|P - A| = 0.3 = l1 and |P - C| = |A - J| = 0.2 = l2). This P is on the
 * counter-clockwise side of A->C: cross(C - A, P - A)
 *   = 0.3 cos q * 0.3 sin q - (0.3 sin q - 0.2) * 0.3 cos q = 0.06 cos q > 0
 * for |q| < pi/2, so branch = +1 (the toggle, where the cross is 0, is at
 * q = +-pi/2: the range is [-1.2, 1.2]).
 * The cylinder: P - B = (0.3 cos q, 1.0 + 0.3 sin q), so
 *   L^2 = 0.09 cos^2 q + 1 + 0.6 sin q + 0.09 sin^2 q = 1.09 + 0.6 sin q
 *   q = 0:     L^2 = 1.09, P = (0.3, 0.2)
 *   q = pi/6:  L^2 = 1.09 + 0.3 = 1.39, P = (0.15 sqrt 3, 0.35)
 *   q = -pi/6: L^2 = 1.09 - 0.3 = 0.79, P = (0.15 sqrt 3, 0.05)
 * Differentiating L^2: 2 L L' = 0.6 cos q, so L' = 0.3 cos q / L; again:
 *   L'^2 + L L'' = -0.3 sin q, so L'' = (-0.3 sin q - L'^2) / L.
 * The link A->P points along q, the rocker C->P straight up (pi/2).
 */
static linkage_def hand_def(void) {
    linkage_def d;
    memset(&d, 0, sizeof d);
    d.rocker_pin[0] = 0.3;
    d.link_pin[1] = 0.2;
    d.link_len = 0.3;
    d.rocker_len = 0.2;
    d.base[1] = -0.8;
    d.branch = 1;
    d.q_min = -1.2;
    d.q_max = 1.2;
    return d;
}

static void test_hand_three_angles(void) {
    linkage_def d = hand_def();
    linkage lk;
    char err[256] = "";
    CHECK(linkage_init(&lk, &d, err, sizeof err) == 0, "%s", err);
    const double qs[3] = {0, M_PI / 6, -M_PI / 6};
    const double L2[3] = {1.09, 1.39, 0.79};
    const double Px[3] = {0.3, 0.15 * sqrt(3.0), 0.15 * sqrt(3.0)};
    const double Pz[3] = {0.2, 0.35, 0.05};
    for (int i = 0; i < 3; i++) {
        double q = qs[i], L = sqrt(L2[i]);
        double dL = 0.3 * cos(q) / L;
        double d2L = (-0.3 * sin(q) - dL * dL) / L;
        linkage_state s;
        CHECK(linkage_eval(&lk, q, &s) == 0, "q = %g", q);
        CHECK_NEAR(s.P[0], Px[i], 1e-12);
        CHECK_NEAR(s.P[1], Pz[i], 1e-12);
        CHECK_NEAR(s.L, L, 1e-9);
        CHECK_NEAR(linkage_length(&lk, q), L, 1e-9);
        CHECK_NEAR(s.dL, dL, 1e-9);
        CHECK_NEAR(s.d2L, d2L, 1e-9);
        CHECK_NEAR(s.link_angle, q, 1e-12);
        CHECK_NEAR(s.rocker_angle, M_PI / 2, 1e-12);
    }
}

/*
 * The other branch of the same loop at q = 0: A = (0, 0.2), C = (0.3, 0), and
 * P is the mirror of the parallelogram's (0.3, 0.2) in the line A-C. With
 * X - A = (0.3, 0) and the line's direction v = (0.3, -0.2), |v|^2 = 0.13:
 *   P = A + 2 ((X - A).v / |v|^2) v - (X - A)
 *     = (0, 0.2) + (18/13) (0.3, -0.2) - (0.3, 0) = (3/26, -1/13)
 * (check: |P - A|^2 = 9/676 + (18/65)^2 = 0.09, |P - C|^2 = (0.3 - 3/26)^2 +
 * (1/13)^2 = (24/130)^2 + (10/130)^2 = 676/16900 = 0.04). It is on the
 * clockwise side of A->C: branch = -1. L = |P - B| = |(3/26, 47/65)|.
 */
static void test_hand_other_branch(void) {
    linkage_def d = hand_def();
    d.branch = -1;
    d.q_min = -0.1;
    d.q_max = 0.1;
    linkage lk;
    char err[256] = "";
    CHECK(linkage_init(&lk, &d, err, sizeof err) == 0, "%s", err);
    linkage_state s;
    CHECK(linkage_eval(&lk, 0, &s) == 0, "q = 0");
    CHECK_NEAR(s.P[0], 3.0 / 26, 1e-12);
    CHECK_NEAR(s.P[1], -1.0 / 13, 1e-12);
    CHECK_NEAR(s.L, hypot(3.0 / 26, 47.0 / 65), 1e-9);
}

/*
 * A crane-like knuckle (numbers of a 10 t m class crane's knuckle, for shape
 * only): the lifting arm's tip joint J = (4.2, 0) in its frame, the end arm
 * at angle0 = 0; cylinder base B = (1.2, 0.45) on top of the lifting arm;
 * link pin A = (4.10, 0.27); rocker pin c = (0.39, 0.07) on the end arm;
 * link 0.60 m, rocker 0.37 m, P on the clockwise side of A->C (branch -1);
 * the end arm from -2.6 rad (folded under) to 0.3 rad. Over that range the
 * cylinder runs 2.448 .. 3.354 m, its lever arm stays above 0.25 m and the
 * transmission angle's sine above 0.76 (a scan made while choosing the
 * numbers, not a checked value). Derivatives against central differences of
 * L(q) itself (step 1e-4 rad: truncation ~ h^2 L'''/6 ~ 1e-9, rounding
 * ~ 1e-16 / 1e-4 = 1e-12).
 */
static linkage_def crane_def(void) {
    linkage_def d;
    memset(&d, 0, sizeof d);
    d.joint[0] = 4.2;
    d.base[0] = 1.2;
    d.base[1] = 0.45;
    d.link_pin[0] = 4.10;
    d.link_pin[1] = 0.27;
    d.rocker_pin[0] = 0.39;
    d.rocker_pin[1] = 0.07;
    d.link_len = 0.60;
    d.rocker_len = 0.37;
    d.branch = -1;
    d.q_min = -2.6;
    d.q_max = 0.3;
    d.link_mass = 18;
    d.rocker_mass = 15;
    return d;
}

static void test_central_differences(void) {
    linkage_def d = crane_def();
    linkage lk;
    char err[256] = "";
    CHECK(linkage_init(&lk, &d, err, sizeof err) == 0, "%s", err);
    const double h = 1e-4;
    for (int i = 0; i <= 20; i++) {
        double q = d.q_min + 0.01 + (d.q_max - d.q_min - 0.02) * i / 20;
        linkage_state s, sp, sm;
        CHECK(linkage_eval(&lk, q, &s) == 0 && linkage_eval(&lk, q + h, &sp) == 0 &&
                  linkage_eval(&lk, q - h, &sm) == 0,
              "q = %g", q);
        // The loop's constraints hold at the solved pin.
        CHECK_NEAR(hypot(s.P[0] - d.link_pin[0], s.P[1] - d.link_pin[1]), d.link_len, 1e-12);
        CHECK_NEAR(hypot(s.P[0] - s.C[0], s.P[1] - s.C[1]), d.rocker_len, 1e-12);
        double cr = (s.C[0] - d.link_pin[0]) * (s.P[1] - d.link_pin[1]) -
                    (s.C[1] - d.link_pin[1]) * (s.P[0] - d.link_pin[0]);
        CHECK(cr < 0, "branch -1 left at q = %g (cross %g)", q, cr);
        double dL = (sp.L - sm.L) / (2 * h);
        double d2L = (sp.L - 2 * s.L + sm.L) / (h * h);
        CHECK_NEAR(s.dL, dL, 1e-8);
        CHECK_NEAR(s.d2L, d2L, 2e-6); // rounding of the second difference: ~ 1e-16 / h^2 = 1e-8
        CHECK_NEAR(s.d2L, (sp.dL - sm.dL) / (2 * h), 1e-8);
        for (int k = 0; k < 2; k++) {
            CHECK_NEAR(s.dP[k], (sp.P[k] - sm.P[k]) / (2 * h), 1e-8);
            CHECK_NEAR(s.d2P[k], (sp.dP[k] - sm.dP[k]) / (2 * h), 1e-8);
        }
    }
}

static void test_inverse(void) {
    linkage_def dd[2] = {hand_def(), crane_def()};
    for (int j = 0; j < 2; j++) {
        linkage lk;
        char err[256] = "";
        CHECK(linkage_init(&lk, &dd[j], err, sizeof err) == 0, "%s", err);
        for (int i = 0; i <= 50; i++) {
            double q = dd[j].q_min + (dd[j].q_max - dd[j].q_min) * i / 50, qb = NAN;
            double L = linkage_length(&lk, q);
            CHECK(linkage_angle(&lk, L, &qb) == 0, "L = %g", L);
            CHECK_NEAR(qb, q, 1e-12);
        }
        double Lmin = fmin(lk.L_qmin, lk.L_qmax), Lmax = fmax(lk.L_qmin, lk.L_qmax), qb = 7;
        CHECK(linkage_angle(&lk, Lmin - 1e-6, &qb) == -1 && qb == 7, "below the stroke");
        CHECK(linkage_angle(&lk, Lmax + 1e-6, &qb) == -1 && qb == 7, "above the stroke");
        CHECK(linkage_angle(&lk, NAN, &qb) == -1, "NaN length");
    }
}

/*
 * Invariants of the description: (1) moving J, A and B together by any
 * vector moves C and P by it and leaves L, its derivatives and the angles
 * alone; (2) turning the child's frame, angle0 + a with the rocker's pin
 * turned by -a in it, describes the same linkage (the same C for every q).
 * The hand loop has J = 0 and angle0 = 0, so these cover the joint offset
 * and angle0 that it cannot.
 */
static void test_frame_invariance(void) {
    linkage_def d0 = crane_def(), d1 = d0, d2 = d0;
    const double t[2] = {-1.7, 0.45};
    for (int k = 0; k < 2; k++) {
        d1.joint[k] += t[k];
        d1.link_pin[k] += t[k];
        d1.base[k] += t[k];
    }
    double a = 0.7, ca = cos(a), sa = sin(a);
    d2.angle0 = a;
    // c' = R(-a) c, so R(angle0 + a + q) c' = R(q) c.
    d2.rocker_pin[0] = ca * d0.rocker_pin[0] + sa * d0.rocker_pin[1];
    d2.rocker_pin[1] = -sa * d0.rocker_pin[0] + ca * d0.rocker_pin[1];
    linkage l0, l1, l2;
    char err[256] = "";
    CHECK(linkage_init(&l0, &d0, err, sizeof err) == 0, "%s", err);
    CHECK(linkage_init(&l1, &d1, err, sizeof err) == 0, "%s", err);
    CHECK(linkage_init(&l2, &d2, err, sizeof err) == 0, "%s", err);
    for (int i = 0; i <= 10; i++) {
        double q = d0.q_min + (d0.q_max - d0.q_min) * i / 10;
        linkage_state s0, s1, s2;
        linkage_eval(&l0, q, &s0);
        linkage_eval(&l1, q, &s1);
        linkage_eval(&l2, q, &s2);
        for (int k = 0; k < 2; k++) {
            CHECK_NEAR(s1.P[k], s0.P[k] + t[k], 1e-12);
            CHECK_NEAR(s1.C[k], s0.C[k] + t[k], 1e-12);
            CHECK_NEAR(s2.P[k], s0.P[k], 1e-12);
            CHECK_NEAR(s2.C[k], s0.C[k], 1e-12);
        }
        CHECK_NEAR(s1.L, s0.L, 1e-12);
        CHECK_NEAR(s1.dL, s0.dL, 1e-12);
        CHECK_NEAR(s1.d2L, s0.d2L, 1e-11);
        CHECK_NEAR(s2.L, s0.L, 1e-12);
        CHECK_NEAR(s2.dL, s0.dL, 1e-12);
        CHECK_NEAR(s2.d2L, s0.d2L, 1e-11);
        CHECK_NEAR(s1.link_angle, s0.link_angle, 1e-12);
        CHECK_NEAR(s2.rocker_angle, s0.rocker_angle, 1e-12);
    }
}

static void expect_refusal(const linkage_def* d, const char* field, const char* words) {
    linkage lk;
    char err[256] = "";
    CHECK(linkage_init(&lk, d, err, sizeof err) == -1, "accepted, expected %s", field);
    CHECK(strstr(err, field) != NULL && strstr(err, words) != NULL, "err '%s' lacks '%s' / '%s'", err, field, words);
    CHECK(strchr(err, '\n') == NULL, "one line: '%s'", err);
}

static void test_refusals(void) {
    linkage_def d;
    // Too short to reach: the link pin to rocker pin distance at q = 0 is
    // |(0.3, -0.2)| = 0.36 m, more than 0.1 + 0.2 m.
    d = hand_def();
    d.link_len = 0.1;
    expect_refusal(&d, "linkage.link_len", "cannot close");
    // Closes at q = 0 but not over the whole range: the distance A-C is
    // D^2 = 0.09 cos^2 q + (0.3 sin q - 0.2)^2 = 0.13 - 0.12 sin q. With
    // l2 = 0.45 the loop needs D > |0.3 - 0.45| = 0.15 m, i.e. sin q <
    // (0.13 - 0.0225) / 0.12 = 0.8958, q < 1.111 rad: refused on [-1.2, 1.2],
    // named at the range's end where D is least.
    d = hand_def();
    d.rocker_len = 0.45;
    expect_refusal(&d, "linkage.rocker_len", "cannot close at q = 1.2 rad");
    // A range through the toggle at q = pi/2 (A, C, P collinear).
    d = hand_def();
    d.q_max = 2.0;
    expect_refusal(&d, "linkage.", "cannot close");
    // A dead centre: P moves on the circle of radius 0.3 about A, so dL/dq
    // = 0 where B, A and P are in line; B = (-0.8, 0.2) puts it at q = 0
    // (P = (0.3, 0.2), P' = (0, 0.3) normal to P - B = (1.1, 0)).
    d = hand_def();
    d.base[0] = -0.8;
    d.base[1] = 0.2;
    expect_refusal(&d, "linkage.base", "dead centre at q = ");
    {
        linkage lk;
        char err[256] = "";
        linkage_init(&lk, &d, err, sizeof err);
        const char* at = strstr(err, "q = ");
        double qd = at ? atof(at + 4) : NAN;
        CHECK(fabs(qd) < 1e-5, "dead centre named at %g rad, expected 0: %s", qd, err);
    }
    // The cylinder's base on the common pin's path: at q = 1.2 rad P =
    // (0.3 cos 1.2, 0.2 + 0.3 sin 1.2), so L = 0 there.
    d = hand_def();
    d.base[0] = 0.3 * cos(1.2);
    d.base[1] = 0.2 + 0.3 * sin(1.2);
    expect_refusal(&d, "linkage.base", "at q = 1.2 rad, must be > 0 m");
    // Inside the range, where P(0) = (0.3, 0.2) = B, L has a kink (|P - B|
    // falls to 0 and rises again): a dead centre.
    d.base[0] = 0.3;
    d.base[1] = 0.2;
    expect_refusal(&d, "linkage.base", "dead centre at q = ");
    d = hand_def();
    d.link_len = 0;
    expect_refusal(&d, "linkage.link_len", "> 0");
    d = hand_def();
    d.rocker_len = -1;
    expect_refusal(&d, "linkage.rocker_len", "> 0");
    d = hand_def();
    d.branch = 0;
    expect_refusal(&d, "linkage.branch", "+1 or -1");
    d = hand_def();
    d.q_min = 1.2;
    expect_refusal(&d, "linkage.q_min", "< q_max");
    d = hand_def();
    d.base[0] = NAN;
    expect_refusal(&d, "linkage.base[0]", "finite");
    d = hand_def();
    d.link_mass = -1;
    expect_refusal(&d, "linkage.link_mass", ">= 0");
}

/*
 * The lumped masses: the link's at A on the parent, the rocker's at c on the
 * child. A parent of 100 kg at com (1, 0, 0) with the 18 kg link at
 * (4.10, 0, 0.27) gets 118 kg at ((100 + 18 * 4.10) / 118, 0, 18 * 0.27 / 118);
 * a child of 50 kg at its origin with the 15 kg rocker at (0.39, 0, 0.07)
 * gets 65 kg at (15 * 0.39 / 65, 0, 15 * 0.07 / 65).
 */
static void test_lump(void) {
    linkage_def d = crane_def();
    linkage lk;
    char err[256] = "";
    CHECK(linkage_init(&lk, &d, err, sizeof err) == 0, "%s", err);
    chain_body_def p, c;
    chain_body_init(&p, 0);
    chain_body_init(&c, 1);
    p.mass = 100;
    p.com[0] = 1;
    c.mass = 50;
    linkage_lump(&lk, &p, &c);
    CHECK_NEAR(p.mass, 118, 1e-12);
    CHECK_NEAR(p.com[0], (100 + 18 * 4.10) / 118, 1e-12);
    CHECK_NEAR(p.com[2], 18 * 0.27 / 118, 1e-12);
    CHECK_NEAR(c.mass, 65, 1e-12);
    CHECK_NEAR(c.com[0], 15 * 0.39 / 65, 1e-12);
    CHECK_NEAR(c.com[2], 15 * 0.07 / 65, 1e-12);
}

/*
 * The links' exact share against the energies computed here from the pins
 * alone: V(q) = -g.(m1 (A + P)/2 + m2 (C + P)/2) and, at qd = 1 rad/s,
 * T = 1/2 [m1 |d(A + P)/2|^2 + m1 l1^2/12 (d phi1)^2 + m2 |d(C + P)/2|^2 +
 * m2 l2^2/12 (d phi2)^2] with every d a central difference in q of the
 * solved pins and the links' angles (atan2 of the pins here), so G = dV/dq
 * and I = 2 T. The lumped terms: the rocker's mass at C, -m2 g.C' and
 * m2 |C'|^2. Gravity is tilted in the parent frame (a raised lifting arm).
 */
static void test_links_terms(void) {
    linkage_def d = crane_def();
    linkage lk;
    char err[256] = "";
    CHECK(linkage_init(&lk, &d, err, sizeof err) == 0, "%s", err);
    const double g[2] = {-9.81 * sin(0.6), -9.81 * cos(0.6)};
    const double h = 1e-5;
    double m1 = d.link_mass, m2 = d.rocker_mass, l1 = d.link_len, l2 = d.rocker_len;
    for (int i = 0; i <= 12; i++) {
        double q = d.q_min + 0.01 + (d.q_max - d.q_min - 0.02) * i / 12;
        linkage_state sp, sm;
        linkage_links_terms t;
        CHECK(linkage_links(&lk, q, g, &t) == 0, "q = %g", q);
        linkage_eval(&lk, q + h, &sp);
        linkage_eval(&lk, q - h, &sm);
        double r1p[2], r1m[2], r2p[2], r2m[2], v1[2], v2[2], vc[2];
        for (int k = 0; k < 2; k++) {
            r1p[k] = 0.5 * (d.link_pin[k] + sp.P[k]);
            r1m[k] = 0.5 * (d.link_pin[k] + sm.P[k]);
            r2p[k] = 0.5 * (sp.C[k] + sp.P[k]);
            r2m[k] = 0.5 * (sm.C[k] + sm.P[k]);
            v1[k] = (r1p[k] - r1m[k]) / (2 * h);
            v2[k] = (r2p[k] - r2m[k]) / (2 * h);
            vc[k] = (sp.C[k] - sm.C[k]) / (2 * h);
        }
        double Vp = -(g[0] * (m1 * r1p[0] + m2 * r2p[0]) + g[1] * (m1 * r1p[1] + m2 * r2p[1]));
        double Vm = -(g[0] * (m1 * r1m[0] + m2 * r2m[0]) + g[1] * (m1 * r1m[1] + m2 * r2m[1]));
        double w1 = (atan2(sp.P[1] - d.link_pin[1], sp.P[0] - d.link_pin[0]) -
                     atan2(sm.P[1] - d.link_pin[1], sm.P[0] - d.link_pin[0])) / (2 * h);
        double w2 = (atan2(sp.P[1] - sp.C[1], sp.P[0] - sp.C[0]) - atan2(sm.P[1] - sm.C[1], sm.P[0] - sm.C[0])) /
                    (2 * h);
        double I = m1 * (v1[0] * v1[0] + v1[1] * v1[1]) + m1 * l1 * l1 / 12 * w1 * w1 +
                   m2 * (v2[0] * v2[0] + v2[1] * v2[1]) + m2 * l2 * l2 / 12 * w2 * w2;
        CHECK_NEAR(t.G, (Vp - Vm) / (2 * h), 1e-6);
        CHECK_NEAR(t.I, I, 1e-7);
        CHECK_NEAR(t.G_lumped, -m2 * (g[0] * vc[0] + g[1] * vc[1]), 1e-6);
        CHECK_NEAR(t.I_lumped, m2 * (vc[0] * vc[0] + vc[1] * vc[1]), 1e-7);
    }
}

/*
 * The lengths and branch from a drawing's common pin: the crane linkage's P
 * at q_ref gives back its lengths and branch (and so the same L(q)); for
 * the hand loop at q = 0, P = (0.3, 0.2) gives l1 = 0.3, l2 = 0.2, branch
 * +1, and its mirror (3/26, -1/13) branch -1 with the same lengths. A pin
 * on the line A-C (the midpoint of A = (0, 0.2) and C = (0.3, 0)) is refused.
 */
static void test_from_pose(void) {
    linkage_def d = crane_def(), e = crane_def();
    linkage lk, lk2;
    char err[256] = "";
    CHECK(linkage_init(&lk, &d, err, sizeof err) == 0, "%s", err);
    linkage_state s;
    linkage_eval(&lk, -1.0, &s);
    e.link_len = e.rocker_len = 0;
    e.branch = 0;
    CHECK(linkage_def_from_pose(&e, s.P, -1.0, err, sizeof err) == 0, "%s", err);
    CHECK_NEAR(e.link_len, d.link_len, 1e-12);
    CHECK_NEAR(e.rocker_len, d.rocker_len, 1e-12);
    CHECK(e.branch == d.branch, "branch %d, expected %d", e.branch, d.branch);
    CHECK(linkage_init(&lk2, &e, err, sizeof err) == 0, "%s", err);
    CHECK_NEAR(linkage_length(&lk2, 0.2), linkage_length(&lk, 0.2), 1e-12);

    linkage_def h = hand_def();
    const double P1[2] = {0.3, 0.2}, P2[2] = {3.0 / 26, -1.0 / 13}, Pm[2] = {0.15, 0.1};
    CHECK(linkage_def_from_pose(&h, P1, 0, err, sizeof err) == 0, "%s", err);
    CHECK(h.branch == 1, "branch %d", h.branch);
    CHECK_NEAR(h.link_len, 0.3, 1e-15);
    CHECK_NEAR(h.rocker_len, 0.2, 1e-15);
    CHECK(linkage_def_from_pose(&h, P2, 0, err, sizeof err) == 0, "%s", err);
    CHECK(h.branch == -1, "branch %d", h.branch);
    CHECK_NEAR(h.link_len, 0.3, 1e-15);
    CHECK_NEAR(h.rocker_len, 0.2, 1e-15);
    err[0] = 0;
    CHECK(linkage_def_from_pose(&h, Pm, 0, err, sizeof err) == -1, "midpoint accepted");
    CHECK(strstr(err, "linkage.common_pin") && strstr(err, "toggle"), "err '%s'", err);
}

/*
 * Random linkages (pins within 1 m, lengths 0.1..1 m, either branch, any
 * angle0, ranges up to 3 rad): every accepted one closes at 2,001 angles
 * over its range with the loop equations holding and L' of one sign (no
 * dead centre missed between the scan's samples), its L' and L'' match
 * central differences (Richardson, to 1e-8 of 1 + |L'| + |L''|) and
 * q(L(q)) = q;
 * every one refused as "cannot close" fails to close at the angle its
 * message names, or is within 1e-5 m of the limit there (the message gives
 * q to 6 digits); every dead centre named has |dL/dq| ~ 0 or L's extremum
 * there.
 */
static double urand(double lo, double hi) { return lo + (hi - lo) * rand() / (double)RAND_MAX; }

static void test_random_linkages(void) {
    srand(27);
    int accepted = 0, refused_close = 0, refused_dead = 0;
    for (int n = 0; n < 400; n++) {
        linkage_def d;
        memset(&d, 0, sizeof d);
        for (int k = 0; k < 2; k++) {
            d.joint[k] = urand(-1, 1);
            d.base[k] = urand(-1, 1);
            d.link_pin[k] = urand(-1, 1);
            d.rocker_pin[k] = urand(-0.5, 0.5);
        }
        d.angle0 = urand(-3, 3);
        d.link_len = urand(0.1, 1);
        d.rocker_len = urand(0.1, 1);
        d.branch = rand() % 2 ? 1 : -1;
        d.q_min = urand(-2, 1);
        d.q_max = d.q_min + urand(0.1, 3);
        linkage lk;
        char err[256] = "";
        if (linkage_init(&lk, &d, err, sizeof err)) {
            const char* at = strstr(err, "at q = ");
            if (strstr(err, "cannot close") && at) {
                ++refused_close;
                double q = atof(at + 7);
                double C[2], th = d.angle0 + q;
                C[0] = d.joint[0] + cos(th) * d.rocker_pin[0] - sin(th) * d.rocker_pin[1];
                C[1] = d.joint[1] + sin(th) * d.rocker_pin[0] + cos(th) * d.rocker_pin[1];
                double D = hypot(C[0] - d.link_pin[0], C[1] - d.link_pin[1]);
                double lo = fabs(d.link_len - d.rocker_len), hi = d.link_len + d.rocker_len;
                CHECK(q >= d.q_min - 1e-5 && q <= d.q_max + 1e-5, "named q %g outside [%g, %g]", q, d.q_min,
                      d.q_max);
                CHECK(D <= lo + 1e-5 || D >= hi - 1e-5, "refused at q = %g but D = %g in (%g, %g): %s", q, D, lo, hi,
                      err);
            } else if (strstr(err, "dead centre")) {
                ++refused_dead;
                double q = atof(at + 7), h = 1e-7;
                linkage lk2 = {.d = d};
                double Lp = linkage_length(&lk2, q + h), Lm = linkage_length(&lk2, q - h);
                double L0 = linkage_length(&lk2, q);
                CHECK(fabs(Lp - Lm) / (2 * h) < 1e-5 || (Lp - L0) * (L0 - Lm) <= 0,
                      "dead centre at q = %g but dL/dq = %g", q, (Lp - Lm) / (2 * h));
            }
            continue;
        }
        ++accepted;
        const double h = 1e-3;
        for (int i = 0; i <= 2000; i++) {
            double q = d.q_min + (d.q_max - d.q_min) * i / 2000;
            linkage_state s;
            CHECK(linkage_eval(&lk, q, &s) == 0, "linkage %d does not close at q = %g", n, q);
            CHECK_NEAR(hypot(s.P[0] - d.link_pin[0], s.P[1] - d.link_pin[1]), d.link_len, 1e-12);
            CHECK_NEAR(hypot(s.P[0] - s.C[0], s.P[1] - s.C[1]), d.rocker_len, 1e-12);
            CHECK(s.dL * lk.sign > 0, "linkage %d: dL/dq = %g at q = %g against the stroke's sign %d", n, s.dL, q,
                  lk.sign);
            if (i % 100) continue;
            // Central differences at h and h/2, Richardson-extrapolated
            // (4 D(h/2) - D(h)) / 3: truncation O(h^4), so the large higher
            // derivatives of a random loop near its toggle do not swamp it.
            linkage_state sp, sm, sp2, sm2;
            linkage_eval(&lk, q + h, &sp);
            linkage_eval(&lk, q - h, &sm);
            linkage_eval(&lk, q + h / 2, &sp2);
            linkage_eval(&lk, q - h / 2, &sm2);
            if (!(sp.sin_mu > 0.05 && sm.sin_mu > 0.05 && s.sin_mu > 0.05)) continue; // at a toggle's edge
            double dL = (4 * (sp2.L - sm2.L) / h - (sp.L - sm.L) / (2 * h)) / 3;
            double d2L = (4 * (sp2.dL - sm2.dL) / h - (sp.dL - sm.dL) / (2 * h)) / 3;
            double scale = 1 + fabs(s.dL) + fabs(s.d2L);
            CHECK_NEAR(s.dL, dL, 1e-8 * scale);
            CHECK_NEAR(s.d2L, d2L, 1e-8 * scale);
            double qb = NAN;
            CHECK(linkage_angle(&lk, s.L, &qb) == 0, "L = %g", s.L);
            CHECK_NEAR(qb, q, 1e-9 / fmax(lk.min_lever, 1e-3));
        }
    }
    printf("random linkages: %d accepted, %d refused as not closing, %d with a dead centre\n", accepted, refused_close,
           refused_dead);
    CHECK(accepted >= 20 && refused_close >= 20 && refused_dead >= 5, "too few of a kind: %d %d %d", accepted,
          refused_close, refused_dead);
}

// The linkage as a chain's cylinder (linkage_cylinder, _hessian): a column,
// a lifting arm (revolute) and the knuckle (revolute, its joint at the
// crane-like linkage's J); the chain's L, rate, lever arms and their rates
// against linkage_eval at the knuckle's q (exact: the same formula, the
// chain only supplies q and qd), 0 in every other DOF; the knuckle locked
// (not a DOF): L at its q_fixed and no lever anywhere.
static void test_as_chain_cylinder(void) {
    linkage_def d = crane_def();
    linkage lk;
    char err[256] = "";
    CHECK(linkage_init(&lk, &d, err, sizeof err) == 0, "%s", err);
    chain_body_def b[3];
    for (int i = 0; i < 3; ++i) {
        chain_body_init(&b[i], i - 1);
        b[i].mass = 100;
        b[i].com[0] = 0.5;
        chain_inertia_box(100, 1, 0.2, 0.2, b[i].inertia);
    }
    b[0].fixed = 1;
    b[1].origin[2] = 2.0;
    b[1].angle0 = -M_PI / 2;
    b[2].origin[0] = d.joint[0];
    for (int locked = 0; locked < 2; ++locked) {
        b[2].fixed = locked;
        b[2].q_fixed = -1.1;
        chain* c = chain_create(b, 3, NULL, err, sizeof err);
        CHECK(c != NULL, "%s", err);
        if (!c) return;
        chain_ws* w = chain_ws_create(c);
        const int nd = chain_ndof(c), kn = chain_body_dof(c, 2);
        CHECK(nd == 2 - locked && kn == (locked ? -1 : 1), "dofs %d, knuckle %d", nd, kn);
        double worst = 0;
        for (int i = 0; i <= 10; ++i) {
            const double qk = locked ? -1.1 : d.q_min + (d.q_max - d.q_min) * i / 10.0;
            const double q[2] = {1.3 + 0.1 * i, qk}, qd[2] = {0.2, -0.45};
            chain_update(c, w, q, qd);
            double qdk;
            CHECK(chain_joint_q(c, w, 2, &qdk) == qk && qdk == (locked ? 0.0 : qd[1]), "chain_joint_q");
            double Ld, dL[2], dLd[2], H[4];
            const double L = linkage_cylinder(&lk, c, w, 2, &Ld, dL, dLd);
            linkage_cylinder_hessian(&lk, c, w, 2, H);
            linkage_state st;
            CHECK(linkage_eval(&lk, qk, &st) == 0, "eval at %g", qk);
            worst = fmax(worst, fabs(L - st.L));
            CHECK(dL[0] == 0 && dLd[0] == 0 && H[0] == 0, "the lifting arm's lever %g, %g, H %g", dL[0], dLd[0], H[0]);
            if (locked) {
                CHECK(Ld == 0, "rate %g with the knuckle locked", Ld);
            } else {
                worst = fmax(worst, fabs(Ld - st.dL * qd[1]));
                worst = fmax(worst, fabs(dL[1] - st.dL) + fabs(dLd[1] - st.d2L * qd[1]));
                worst = fmax(worst, fabs(H[3] - st.d2L));
                CHECK(H[1] == 0 && H[2] == 0, "H off-diagonal %g %g", H[1], H[2]);
            }
        }
        CHECK(worst == 0, "%s: %g from linkage_eval", locked ? "locked" : "free", worst);
        chain_ws_free(w);
        chain_free(c);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_hand_three_angles);
    RUN_TEST(test_hand_other_branch);
    RUN_TEST(test_central_differences);
    RUN_TEST(test_inverse);
    RUN_TEST(test_frame_invariance);
    RUN_TEST(test_refusals);
    RUN_TEST(test_lump);
    RUN_TEST(test_links_terms);
    RUN_TEST(test_from_pose);
    RUN_TEST(test_random_linkages);
    RUN_TEST(test_as_chain_cylinder);
    TEST_MAIN_END();
}
