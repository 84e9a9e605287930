// test_chain_hand.c: the chain library against closed forms derived by hand
// in the comments: a telescopic extension with its cylinder (issue 26's
// "single prismatic extension", alone and on a swinging boom), and the slew
// equation of a two-boom crane (d/dt(I_zz(q) theta') and the booms'
// centrifugal terms from the slew).
#include "chain.h"
#include "check.h"

#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double urand(double lo, double hi) { return lo + (hi - lo) * rand() / (double)RAND_MAX; }

/*
 * Extension on a boom. Column clamped (slew 0). Boom: revolute at J = (x0, 0,
 * z0) on the column, angle0 = 0, so its angle a is the elevation above
 * horizontal; its x axis in the boom plane is X = (cos a, sin a) and its z
 * axis Z = (-sin a, cos a) (x, z components). Mass mb, centre of mass (bx, 0,
 * bz), inertia Ib about the joint axis at the centre. Extension: prismatic
 * at (ox, 0, oz) in the boom frame, angle0 = 0, offset0 = d0, slide s; mass
 * me, centre of mass (cx, 0, cz) in its frame, Ie about y. Its centre of
 * mass in the boom frame is (rho, zeta) = (ox + d0 + s + cx, oz + cz), in
 * the world J + rho X + zeta Z, so
 *   d r / ds = X,   d r / da = rho Z - zeta X.
 * With q = (a, s):
 *   M_ss = me
 *   M_as = me X.(rho Z - zeta X) = -me zeta
 *   M_aa = Ib + mb (bx^2 + bz^2) + Ie + me (rho^2 + zeta^2)
 * Only M_aa depends on q (through s: dM_aa/ds = 2 me rho), so with
 * T = 1/2 M_aa a'^2 + M_as a' s' + 1/2 me s'^2 Lagrange's equations give
 *   C_a = 2 me rho a' s',   C_s = -me rho a'^2.
 * Heights z = z0 + bx sin a + bz cos a (boom), z0 + rho sin a + zeta cos a
 * (extension), V = g (mb z_b + me z_e):
 *   G_a = g [mb (bx cos a - bz sin a) + me (rho cos a - zeta sin a)]
 *   G_s = g me sin a.
 * Cylinder: barrel pin (ax, 0, az) on the boom, rod pin (px, 0, pz) on the
 * extension, which is (ox + d0 + s + px, oz + pz) in the boom frame. Both
 * turn with the boom, so
 *   L = sqrt(dx^2 + dz^2), dx = ox + d0 + s + px - ax, dz = oz + pz - az
 *   dL/ds = dx / L,  dL/da = 0
 *   d/dt(dL/ds) = d2L/ds2 s' = (1/L - dx^2/L^3) s' = dz^2 / L^3 s',  d/dt(dL/da) = 0.
 * With the boom fixed at a (the single prismatic DOF): M = me, G = me g sin a,
 * C = 0, L and dL/ds as above.
 */
typedef struct ext_case {
    double x0, z0, mb, bx, bz, Ib, ox, oz, d0, me, cx, cz, Ie, ax, az, px, pz, g;
} ext_case;

static ext_case random_ext(void) {
    ext_case e = {urand(-0.3, 0.3), urand(1, 2.5), urand(100, 400), urand(1, 2), urand(-0.1, 0.1), urand(20, 200),
                  urand(0.5, 1.5), urand(-0.05, 0.05), urand(0, 0.5), urand(30, 150), urand(0.5, 1.2),
                  urand(-0.05, 0.05), urand(5, 50), urand(0.2, 0.6), urand(0.15, 0.3), urand(0.8, 1.5),
                  urand(0.05, 0.15), urand(9.7, 9.9)};
    return e;
}

static chain* ext_chain(const ext_case* e, int boom_fixed, double a_fixed) {
    chain_body_def b[3];
    chain_body_init(&b[0], -1);
    b[0].fixed = 1;
    b[0].mass = 300;
    chain_body_init(&b[1], 0);
    b[1].origin[0] = e->x0, b[1].origin[2] = e->z0;
    b[1].mass = e->mb, b[1].com[0] = e->bx, b[1].com[2] = e->bz;
    // Ixx and Izz are arbitrary here: the motion stays in the boom plane.
    b[1].inertia[0][0] = 0.3 * e->Ib, b[1].inertia[1][1] = e->Ib, b[1].inertia[2][2] = e->Ib;
    b[1].fixed = boom_fixed, b[1].q_fixed = a_fixed;
    chain_body_init(&b[2], 1);
    b[2].joint = CHAIN_PRISMATIC;
    b[2].origin[0] = e->ox, b[2].origin[2] = e->oz;
    b[2].offset0 = e->d0;
    b[2].mass = e->me, b[2].com[0] = e->cx, b[2].com[2] = e->cz;
    b[2].inertia[0][0] = 0.2 * e->Ie, b[2].inertia[1][1] = e->Ie, b[2].inertia[2][2] = e->Ie;
    b[2].q_min = 0, b[2].q_max = 2.0;
    const double g[3] = {0, 0, -e->g};
    char err[200];
    chain* c = chain_create(b, 3, g, err, sizeof err);
    CHECK(c != NULL, "%s", err);
    return c;
}

static void test_extension_single_dof(void) {
    srand(21);
    for (int t = 0; t < 100; ++t) {
        const ext_case e = random_ext();
        const double a = urand(-0.5, 1.4);
        chain* c = ext_chain(&e, 1, a);
        if (!c) return;
        CHECK(chain_ndof(c) == 1 && chain_dof_body(c, 0) == 2, "one DOF, the slide");
        chain_ws* w = chain_ws_create(c);
        const double s = urand(0, 2), sd = urand(-0.5, 0.5);
        chain_update(c, w, &s, &sd);
        double M, G, C, Ld, dL, dLd;
        chain_mass_matrix(c, w, &M);
        chain_inverse_dynamics(c, w, NULL, CHAIN_GRAVITY, &G);
        chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY, &C);
        CHECK_REL(M, e.me, 1e-13);
        CHECK_REL(G, e.me * e.g * sin(a), 1e-12);
        CHECK_NEAR(C, 0, 1e-12 * e.me);
        const double pa[3] = {e.ax, 0, e.az}, pb[3] = {e.px, 0, e.pz};
        const double dx = e.ox + e.d0 + s + e.px - e.ax, dz = e.oz + e.pz - e.az, L = sqrt(dx * dx + dz * dz);
        CHECK_REL(chain_cylinder(c, w, 1, pa, 2, pb, &Ld, &dL, &dLd), L, 1e-14);
        CHECK_REL(dL, dx / L, 1e-13);
        CHECK_NEAR(Ld, dx / L * sd, 1e-13);
        CHECK_NEAR(dLd, dz * dz / (L * L * L) * sd, 1e-13 * fabs(sd) / L);
        // And it moves as m s'' = F dL/ds - G under a cylinder force F.
        const double F = urand(-2e4, 2e4), tau = F * dL;
        double sdd;
        CHECK(chain_forward_dynamics(c, w, &tau, &sdd) == 0, "forward dynamics");
        CHECK_REL(sdd, (F * dx / L - e.me * e.g * sin(a)) / e.me, 1e-12);
        chain_ws_free(w);
        chain_free(c);
    }
}

static void test_extension_on_swinging_boom(void) {
    srand(22);
    for (int t = 0; t < 200; ++t) {
        const ext_case e = random_ext();
        chain* c = ext_chain(&e, 0, 0);
        if (!c) return;
        CHECK(chain_ndof(c) == 2, "two DOF");
        chain_ws* w = chain_ws_create(c);
        const double q[2] = {urand(-1.5, 1.5), urand(0, 2)}, qd[2] = {urand(-1, 1), urand(-1, 1)};
        const double a = q[0], s = q[1], ad = qd[0], sd = qd[1];
        const double rho = e.ox + e.d0 + s + e.cx, zeta = e.oz + e.cz;
        const double H[4] = {e.Ib + e.mb * (e.bx * e.bx + e.bz * e.bz) + e.Ie + e.me * (rho * rho + zeta * zeta),
                             -e.me * zeta, -e.me * zeta, e.me};
        const double Cw[2] = {2 * e.me * rho * ad * sd, -e.me * rho * ad * ad};
        const double Gw[2] = {e.g * (e.mb * (e.bx * cos(a) - e.bz * sin(a)) + e.me * (rho * cos(a) - zeta * sin(a))),
                              e.g * e.me * sin(a)};
        chain_update(c, w, q, qd);
        double M[4], C[2], G[2];
        chain_mass_matrix(c, w, M);
        chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY, C);
        chain_inverse_dynamics(c, w, NULL, CHAIN_GRAVITY, G);
        for (int k = 0; k < 4; ++k) CHECK_NEAR(M[k], H[k], 1e-12 * H[0]);
        for (int k = 0; k < 2; ++k) {
            CHECK_NEAR(C[k], Cw[k], 1e-12 * (fabs(Cw[0]) + fabs(Cw[1]) + 1e-9));
            CHECK_NEAR(G[k], Gw[k], 1e-12 * (fabs(Gw[0]) + fabs(Gw[1])));
        }
        const double pa[3] = {e.ax, 0, e.az}, pb[3] = {e.px, 0, e.pz};
        const double dx = e.ox + e.d0 + s + e.px - e.ax, dz = e.oz + e.pz - e.az, L = sqrt(dx * dx + dz * dz);
        double dL[2], dLd[2];
        CHECK_REL(chain_cylinder(c, w, 1, pa, 2, pb, NULL, dL, dLd), L, 1e-14);
        CHECK_NEAR(dL[0], 0, 1e-13);
        CHECK_REL(dL[1], dx / L, 1e-13);
        CHECK_NEAR(dLd[0], 0, 1e-13);
        CHECK_NEAR(dLd[1], dz * dz / (L * L * L) * sd, 1e-13 / L);
        // Hessian: only d2L/ds2 = dz^2 / L^3 (L does not depend on a).
        double Hc[4];
        chain_cylinder_hessian(c, w, 1, pa, 2, pb, Hc);
        CHECK_NEAR(Hc[0], 0, 1e-13);
        CHECK_NEAR(Hc[1], 0, 1e-13);
        CHECK_NEAR(Hc[2], 0, 1e-13);
        CHECK_NEAR(Hc[3], dz * dz / (L * L * L), 1e-13 / L);
        chain_ws_free(w);
        chain_free(c);
    }
}

/*
 * Slew coupling. Column: slew theta free about z, mass m0, Izz0 about its
 * axis. Link 1: revolute at (x0, 0, h) on the column, angle0 = -pi/2 (q1 from
 * the downward vertical); link 2 at (L1, 0, 0) on link 1, angle0 = 0 (q2
 * relative). Link i: mass mi, centre of mass (ei, 0, fi), diagonal inertia
 * (Ixi, Iyi, Izi). Absolute angles from the downward vertical: p1 = q1,
 * p2 = q1 + q2; a link's x axis in the boom plane is (sin p, -cos p), its z
 * axis (cos p, sin p). The centres' distances from the slew axis:
 *   xc1 = x0 + e1 sin p1 + f1 cos p1
 *   xc2 = x0 + L1 sin p1 + e2 sin p2 + f2 cos p2.
 * Seen from the world z, link i's inertia about the vertical is
 * Ixi (x.z)^2 + Izi (z.z)^2 = Ixi cos^2 p + Izi sin^2 p, so
 *   I_zz(q) = Izz0 + sum_i [mi xci^2 + Ixi cos^2 pi + Izi sin^2 pi].
 * The slew velocity of a centre is along y (theta' z x r, r in the x-z
 * plane), the boom motion is in the x-z plane, and y is a principal axis of
 * each link, so T = 1/2 I_zz(q) theta'^2 + T_booms(q, q'): M_theta,q = 0,
 * M_theta,theta = I_zz, and (theta is cyclic, V does not depend on it)
 *   tau_theta = d/dt(I_zz theta') = I_zz theta'' + theta' sum_j dI_zz/dq_j q_j'
 * while each boom equation gains -1/2 dI_zz/dq_j theta'^2 (the centrifugal
 * pull of the slew), with
 *   dI_zz/dp   for link i: 2 mi xci dxci/dp + 2 (Izi - Ixi) sin p cos p
 *   dxc1/dq1 = e1 cos p1 - f1 sin p1
 *   dxc2/dq1 = L1 cos p1 + e2 cos p2 - f2 sin p2,   dxc2/dq2 = e2 cos p2 - f2 sin p2.
 */
static void test_slew_coupling(void) {
    srand(23);
    for (int t = 0; t < 200; ++t) {
        const double x0 = urand(-0.3, 0.3), h = urand(1, 2.5), m0 = urand(100, 400), Izz0 = urand(5, 40);
        const double L1 = urand(1.5, 3), m[2] = {urand(100, 300), urand(80, 200)};
        const double e[2] = {urand(0.5, 1.5), urand(0.5, 1.5)}, f[2] = {urand(-0.1, 0.1), urand(-0.1, 0.1)};
        double Ix[2], Iy[2], Iz[2];
        for (int i = 0; i < 2; ++i) {
            Ix[i] = urand(2, 10), Iy[i] = urand(60, 150);
            Iz[i] = Iy[i] + urand(-1, 1); // within the triangle rule
        }
        chain_body_def b[3];
        chain_body_init(&b[0], -1);
        b[0].mass = m0, b[0].com[2] = 0.5 * h;
        b[0].inertia[0][0] = b[0].inertia[1][1] = urand(50, 100), b[0].inertia[2][2] = Izz0;
        for (int i = 0; i < 2; ++i) {
            chain_body_init(&b[i + 1], i);
            b[i + 1].origin[0] = i ? L1 : x0, b[i + 1].origin[2] = i ? 0 : h;
            b[i + 1].angle0 = i ? 0 : -0.5 * M_PI;
            b[i + 1].mass = m[i], b[i + 1].com[0] = e[i], b[i + 1].com[2] = f[i];
            b[i + 1].inertia[0][0] = Ix[i], b[i + 1].inertia[1][1] = Iy[i], b[i + 1].inertia[2][2] = Iz[i];
        }
        char err[200];
        chain* c = chain_create(b, 3, NULL, err, sizeof err);
        CHECK(c != NULL, "%s", err);
        if (!c) return;
        chain_ws* w = chain_ws_create(c);
        const double q[3] = {urand(-3, 3), urand(0.5, 2.8), urand(-2.5, 0)};
        const double qd[3] = {urand(-1, 1), urand(-1, 1), urand(-1, 1)};
        const double p1 = q[1], p2 = q[1] + q[2], pd1 = qd[1], pd2 = qd[1] + qd[2];
        const double xc1 = x0 + e[0] * sin(p1) + f[0] * cos(p1);
        const double xc2 = x0 + L1 * sin(p1) + e[1] * sin(p2) + f[1] * cos(p2);
        const double Izz = Izz0 + m[0] * xc1 * xc1 + Ix[0] * cos(p1) * cos(p1) + Iz[0] * sin(p1) * sin(p1) +
                           m[1] * xc2 * xc2 + Ix[1] * cos(p2) * cos(p2) + Iz[1] * sin(p2) * sin(p2);
        const double dx1_1 = e[0] * cos(p1) - f[0] * sin(p1);
        const double dx2_2 = e[1] * cos(p2) - f[1] * sin(p2), dx2_1 = L1 * cos(p1) + dx2_2;
        const double rot1 = 2 * (Iz[0] - Ix[0]) * sin(p1) * cos(p1), rot2 = 2 * (Iz[1] - Ix[1]) * sin(p2) * cos(p2);
        const double dI_dq1 = 2 * m[0] * xc1 * dx1_1 + rot1 + 2 * m[1] * xc2 * dx2_1 + rot2;
        const double dI_dq2 = 2 * m[1] * xc2 * dx2_2 + rot2;
        const double Izz_dot = (2 * m[0] * xc1 * dx1_1 + rot1) * pd1 + 2 * m[1] * xc2 * (L1 * cos(p1) * pd1 + dx2_2 * pd2) +
                               rot2 * pd2;
        CHECK_NEAR(Izz_dot, dI_dq1 * qd[1] + dI_dq2 * qd[2], 1e-12 * fabs(Izz)); // the hand algebra itself

        chain_update(c, w, q, qd);
        double M[9], C[3], Cb[3];
        chain_mass_matrix(c, w, M);
        chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY, C);
        CHECK_REL(M[0], Izz, 1e-13);
        CHECK_NEAR(M[1], 0, 1e-13 * Izz);
        CHECK_NEAR(M[2], 0, 1e-13 * Izz);
        // The slew equation's torque from the boom motion.
        CHECK_NEAR(C[0], Izz_dot * qd[0], 1e-12 * (fabs(Izz_dot * qd[0]) + Izz * 1e-3));
        // The booms' centrifugal terms from the slew: C(theta', q') - C(0, q').
        const double qd0[3] = {0, qd[1], qd[2]};
        chain_update(c, w, q, qd0);
        chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY, Cb);
        CHECK_NEAR(Cb[0], 0, 1e-12 * Izz); // no slew rate, no slew torque
        const double th2 = qd[0] * qd[0];
        // (A difference of two biases: each rounds on its own scale.)
        const double sc = fabs(C[1]) + fabs(Cb[1]) + fabs(C[2]) + fabs(Cb[2]) + fabs(dI_dq1) * th2;
        CHECK_NEAR(C[1] - Cb[1], -0.5 * dI_dq1 * th2, 1e-12 * sc);
        CHECK_NEAR(C[2] - Cb[2], -0.5 * dI_dq2 * th2, 1e-12 * sc);
        // Gravity has no slew component on a level base.
        double G[3];
        chain_inverse_dynamics(c, w, NULL, CHAIN_GRAVITY, G);
        CHECK_NEAR(G[0], 0, 1e-12 * fabs(G[1]));
        chain_ws_free(w);
        chain_free(c);
    }
}

// Bad descriptions are refused with one line naming the body and the field.
static void test_refusals(void) {
    chain_body_def b[3];
    chain_body_init(&b[0], -1);
    b[0].mass = 100, b[0].inertia[0][0] = b[0].inertia[1][1] = b[0].inertia[2][2] = 10;
    for (int i = 1; i < 3; ++i) {
        chain_body_init(&b[i], i - 1);
        b[i].mass = 50, b[i].inertia[0][0] = 1, b[i].inertia[1][1] = b[i].inertia[2][2] = 10;
    }
    snprintf(b[2].name, sizeof b[2].name, "ext1");
    char err[256];
    chain* c = chain_create(b, 3, NULL, err, sizeof err);
    CHECK(c != NULL, "the good chain: %s", err);
    if (c) {
        CHECK(chain_find_body(c, "ext1") == 2 && chain_find_body(c, "ext2") == -1 && chain_find_body(c, "") == -1,
              "find by name");
        CHECK(chain_body(c, 2) && !strcmp(chain_body(c, 2)->name, "ext1") && chain_body(c, 3) == NULL, "bodies");
        CHECK(chain_body_dof(c, 0) == 0 && chain_dof_body(c, 2) == 2 && chain_dof_body(c, 3) == -1, "dofs");
    }
    chain_free(c);
    chain_body_def x[3];
#define REFUSE(stmt, want)                                                                             \
    do {                                                                                               \
        memcpy(x, b, sizeof x);                                                                        \
        stmt;                                                                                          \
        err[0] = 0;                                                                                    \
        chain* r_ = chain_create(x, 3, NULL, err, sizeof err);                                         \
        CHECK(r_ == NULL && strstr(err, want) != NULL, "%s: got '%s', want '%s'", #stmt, err, want); \
        chain_free(r_);                                                                                \
    } while (0)
    REFUSE(x[2].joint = CHAIN_PRISMATIC; x[2].q_min = 0.5; x[2].q_max = -0.5,
           "bodies[2] (ext1).q_max: -0.5 m is below q_min 0.5 m");
    REFUSE(x[2].parent = 2, "bodies[2] (ext1).parent: 2 is not an earlier body (0..1)");
    REFUSE(x[1].parent = -1, "bodies[1].parent: -1 is not an earlier body (0..0)");
    REFUSE(x[0].joint = CHAIN_PRISMATIC, "bodies[0].joint: body 0 (the column) must be revolute");
    REFUSE(x[1].mass = 0, "bodies[1].mass: 0 kg, must be > 0 kg");
    REFUSE(x[1].inertia[2][2] = 20, "bodies[1].inertia: principal moments");
    REFUSE(x[1].inertia[0][1] = 0.5, "bodies[1].inertia: not symmetric");
    REFUSE(x[1].com[0] = NAN, "bodies[1].com: must be finite");
    REFUSE(x[1].fixed = 1; x[1].q_min = 0; x[1].q_max = 1; x[1].q_fixed = 2,
           "bodies[1].q_fixed: 2 rad is outside the joint's range 0..1 rad");
    // A clamped massless column is fine.
    memcpy(x, b, sizeof x);
    x[0].fixed = 1, x[0].mass = 0;
    memset(x[0].inertia, 0, sizeof x[0].inertia);
    c = chain_create(x, 3, NULL, err, sizeof err);
    CHECK(c != NULL && chain_ndof(c) == 2, "clamped massless column: %s", err);
    chain_free(c);
    CHECK(chain_create(b, 0, NULL, err, sizeof err) == NULL && strstr(err, "at least one body"), "%s", err);
}

// A workspace in caller memory works as the malloc'ed one, and two
// workspaces on one chain do not share state (one chain, several threads).
static void test_workspaces(void) {
    srand(24);
    const ext_case e = random_ext();
    chain* c = ext_chain(&e, 0, 0);
    if (!c) return;
    const size_t n = chain_ws_bytes(c);
    CHECK(n > 0, "workspace size");
    double* mem = malloc(n);
    chain_ws* w1 = chain_ws_init(c, mem);
    chain_ws* w2 = chain_ws_create(c);
    const double q1[2] = {0.3, 0.5}, qd1[2] = {0.2, -0.1}, q2[2] = {-0.4, 1.2}, qd2[2] = {-0.3, 0.4};
    chain_update(c, w1, q1, qd1);
    chain_update(c, w2, q2, qd2);
    double a1[2], a2[2], b1[2], b2[2];
    CHECK(chain_forward_dynamics(c, w1, NULL, a1) == 0 && chain_forward_dynamics(c, w2, NULL, a2) == 0, "fd");
    // Again in the other order: each workspace keeps its own state.
    chain_ws* w3 = chain_ws_create(c);
    chain_update(c, w3, q2, qd2);
    CHECK(chain_forward_dynamics(c, w3, NULL, b2) == 0, "fd");
    chain_update(c, w3, q1, qd1);
    CHECK(chain_forward_dynamics(c, w3, NULL, b1) == 0, "fd");
    for (int k = 0; k < 2; ++k) {
        CHECK(a1[k] == b1[k] && a2[k] == b2[k], "workspaces differ: %g %g, %g %g", a1[k], b1[k], a2[k], b2[k]);
    }
    // qd NULL is at rest: the bias is gravity alone.
    double G[2], B[2];
    chain_update(c, w1, q1, NULL);
    chain_inverse_dynamics(c, w1, NULL, CHAIN_GRAVITY, G);
    chain_inverse_dynamics(c, w1, NULL, CHAIN_VELOCITY | CHAIN_GRAVITY, B);
    CHECK(G[0] == B[0] && G[1] == B[1] && chain_kinetic_energy(c, w1) == 0, "at rest");
    chain_ws_free(w2);
    chain_ws_free(w3);
    free(mem);
    chain_free(c);
}

// The section rule with a box's own Iyy gives the box.
static void test_section_inertia(void) {
    const double m = 180, L = 2.3, wd = 0.18, ht = 0.24;
    double box[3][3], sec[3][3];
    chain_inertia_box(m, L, wd, ht, box);
    chain_inertia_section(m, m * (L * L + ht * ht) / 12, L, wd, ht, sec);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) CHECK_NEAR(sec[i][j], box[i][j], 1e-12 * box[1][1]);
    CHECK_NEAR(box[0][0], m * (wd * wd + ht * ht) / 12, 1e-12);
    CHECK_NEAR(box[1][1], m * (L * L + ht * ht) / 12, 1e-12);
    CHECK_NEAR(box[2][2], m * (L * L + wd * wd) / 12, 1e-12);
}

int main(int argc, char** argv) {
    RUN_TEST(test_extension_single_dof);
    RUN_TEST(test_extension_on_swinging_boom);
    RUN_TEST(test_slew_coupling);
    RUN_TEST(test_refusals);
    RUN_TEST(test_workspaces);
    RUN_TEST(test_section_inertia);
    TEST_MAIN_END();
}
