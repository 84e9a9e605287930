// test_chain_numeric.c: general chains (slewing column, revolute and
// prismatic joints, a branch, a locked joint, 3D offsets, full inertia
// tensors) against the Lagrangian computed here, independently of the
// library: the test's own forward kinematics from the conventions of chain.h,
// velocities by the complex step (exact to rounding), T and V from them, and
//   M_ij = d2T/dqd_i dqd_j  (T is quadratic in qd: polarisation, exact)
//   C + G = d/dt dT/dqd - dT/dq + dV/dq  (central differences, Richardson)
// and the point Jacobians and cylinder lengths by complex steps.
#include "chain.h"
#include "check.h"

#include <complex.h>
#include <stdlib.h>

typedef double complex cplx;
static double urand(double lo, double hi) { return lo + (hi - lo) * rand() / (double)RAND_MAX; }

#define NB_MAX 16 // the test's chains only; the library has no maximum

typedef struct model {
    int nb, nd;
    chain_body_def b[NB_MAX];
    int dof[NB_MAX];
    double g[3];
} model;

/* ---- the test's own kinematics (chain.h's conventions, written again) ---- */

// Joint rotation: columns are the child's axes in parent coordinates.
static void joint_rot(int slew, cplx a, cplx J[9]) {
    const cplx c = ccos(a), s = csin(a);
    if (slew) { // about z, x towards y
        J[0] = c, J[1] = -s, J[2] = 0, J[3] = s, J[4] = c, J[5] = 0, J[6] = 0, J[7] = 0, J[8] = 1;
    } else { // in the boom plane, x towards z
        J[0] = c, J[1] = 0, J[2] = -s, J[3] = 0, J[4] = 1, J[5] = 0, J[6] = s, J[7] = 0, J[8] = c;
    }
}

static void fk(const model* m, const cplx* q, cplx R[][9], cplx P[][3]) {
    for (int i = 0; i < m->nb; ++i) {
        const chain_body_def* b = &m->b[i];
        const cplx qi = m->dof[i] >= 0 ? q[m->dof[i]] : b->q_fixed;
        cplx J[9], o[3];
        if (b->joint == CHAIN_PRISMATIC) {
            joint_rot(0, b->angle0, J);
            for (int k = 0; k < 3; ++k) o[k] = b->origin[k] + (b->offset0 + qi) * J[3 * k]; // along the child x
        } else {
            joint_rot(i == 0, b->angle0 + qi, J);
            for (int k = 0; k < 3; ++k) o[k] = b->origin[k];
        }
        if (b->parent < 0) {
            for (int k = 0; k < 9; ++k) R[i][k] = J[k];
            for (int k = 0; k < 3; ++k) P[i][k] = o[k];
        } else {
            const cplx* Rp = R[b->parent];
            for (int x = 0; x < 3; ++x) {
                for (int y = 0; y < 3; ++y) R[i][3 * x + y] = Rp[3 * x] * J[y] + Rp[3 * x + 1] * J[3 + y] + Rp[3 * x + 2] * J[6 + y];
                P[i][x] = P[b->parent][x] + Rp[3 * x] * o[0] + Rp[3 * x + 1] * o[1] + Rp[3 * x + 2] * o[2];
            }
        }
    }
}

static void point_c(const cplx R[9], const cplx P[3], const double pb[3], cplx p[3]) {
    for (int x = 0; x < 3; ++x) p[x] = P[x] + R[3 * x] * pb[0] + R[3 * x + 1] * pb[1] + R[3 * x + 2] * pb[2];
}

static const double EPS = 1e-30; // complex step

static double kinetic(const model* m, const double* q, const double* qd) {
    cplx qc[NB_MAX], R[NB_MAX][9], P[NB_MAX][3];
    for (int k = 0; k < m->nd; ++k) qc[k] = q[k] + I * EPS * qd[k];
    fk(m, qc, R, P);
    double T = 0;
    for (int i = 0; i < m->nb; ++i) {
        const chain_body_def* b = &m->b[i];
        cplx c[3];
        point_c(R[i], P[i], b->com, c);
        double v[3], Rr[9], Rd[9];
        for (int x = 0; x < 3; ++x) v[x] = cimag(c[x]) / EPS;
        for (int k = 0; k < 9; ++k) Rr[k] = creal(R[i][k]), Rd[k] = cimag(R[i][k]) / EPS;
        // [w]x = Rdot R^T
        double W[9];
        for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y) W[3 * x + y] = Rd[3 * x] * Rr[3 * y] + Rd[3 * x + 1] * Rr[3 * y + 1] + Rd[3 * x + 2] * Rr[3 * y + 2];
        const double w[3] = {W[7], W[2], W[3]};
        // w . (R I R^T w) = (R^T w) . I (R^T w)
        double wb[3];
        for (int x = 0; x < 3; ++x) wb[x] = Rr[x] * w[0] + Rr[3 + x] * w[1] + Rr[6 + x] * w[2];
        double Iw = 0;
        for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y) Iw += wb[x] * b->inertia[x][y] * wb[y];
        T += 0.5 * b->mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * Iw;
    }
    return T;
}

static double potential(const model* m, const double* q) {
    cplx qc[NB_MAX], R[NB_MAX][9], P[NB_MAX][3];
    for (int k = 0; k < m->nd; ++k) qc[k] = q[k];
    fk(m, qc, R, P);
    double V = 0;
    for (int i = 0; i < m->nb; ++i) {
        cplx c[3];
        point_c(R[i], P[i], m->b[i].com, c);
        V -= m->b[i].mass * (m->g[0] * creal(c[0]) + m->g[1] * creal(c[1]) + m->g[2] * creal(c[2]));
    }
    return V;
}

// dT/dqd_i: exact by central difference of a quadratic, step 1.
static double momentum(const model* m, const double* q, const double* qd, int i) {
    double a[NB_MAX], b[NB_MAX];
    memcpy(a, qd, sizeof(double) * (size_t)m->nd);
    memcpy(b, qd, sizeof(double) * (size_t)m->nd);
    a[i] += 1, b[i] -= 1;
    return 0.5 * (kinetic(m, q, a) - kinetic(m, q, b));
}

// Lagrange's left side with qdd = 0 by central differences of step h.
static double lagrange_lhs(const model* m, const double* q, const double* qd, int i, double h) {
    double qp[NB_MAX], qm[NB_MAX];
    for (int k = 0; k < m->nd; ++k) qp[k] = q[k] + h * qd[k], qm[k] = q[k] - h * qd[k];
    const double ddt = (momentum(m, qp, qd, i) - momentum(m, qm, qd, i)) / (2 * h);
    memcpy(qp, q, sizeof(double) * (size_t)m->nd);
    memcpy(qm, q, sizeof(double) * (size_t)m->nd);
    qp[i] += h, qm[i] -= h;
    const double dTdq = (kinetic(m, qp, qd) - kinetic(m, qm, qd)) / (2 * h);
    const double dVdq = (potential(m, qp) - potential(m, qm)) / (2 * h);
    return ddt - dTdq + dVdq;
}

/* ---- random chains ---- */

// Inertia Q diag(p) Q^T with principal moments obeying the triangle rule.
static void random_inertia(double mass, double In[3][3]) {
    // p1, p2 free, p0 between |p1 - p2| and p1 + p2 (the triangle rule).
    double p[3] = {0, urand(0.5, 1.5), urand(0.5, 1.5)};
    p[0] = urand(fabs(p[1] - p[2]), p[1] + p[2]);
    for (int k = 0; k < 3; ++k) p[k] *= mass * 0.3;
    double ax[3] = {urand(-1, 1), urand(-1, 1), urand(-1, 1)};
    const double n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    for (int k = 0; k < 3; ++k) ax[k] /= n;
    const double t = urand(0, 0.6), c = cos(t), s = sin(t), C = 1 - c;
    const double Q[3][3] = {{c + ax[0] * ax[0] * C, ax[0] * ax[1] * C - ax[2] * s, ax[0] * ax[2] * C + ax[1] * s},
                            {ax[1] * ax[0] * C + ax[2] * s, c + ax[1] * ax[1] * C, ax[1] * ax[2] * C - ax[0] * s},
                            {ax[2] * ax[0] * C - ax[1] * s, ax[2] * ax[1] * C + ax[0] * s, c + ax[2] * ax[2] * C}};
    for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y) {
            double v = 0;
            for (int k = 0; k < 3; ++k) v += Q[x][k] * p[k] * Q[y][k];
            In[x][y] = v;
        }
    for (int x = 0; x < 3; ++x)
        for (int y = x + 1; y < 3; ++y) In[x][y] = In[y][x]; // exactly symmetric
}

typedef struct spec {
    int parent;
    chain_joint joint;
    int fixed;
} spec;

static void random_model(model* m, const spec* s, int nb, int slew_free) {
    memset(m, 0, sizeof *m);
    m->nb = nb;
    m->g[0] = urand(-0.3, 0.3), m->g[1] = urand(-0.3, 0.3), m->g[2] = -9.81; // a slightly tilted truck
    for (int i = 0; i < nb; ++i) {
        chain_body_def* b = &m->b[i];
        chain_body_init(b, s[i].parent);
        b->joint = s[i].joint;
        b->fixed = i == 0 ? !slew_free : s[i].fixed;
        b->q_fixed = urand(-0.5, 0.5);
        for (int k = 0; k < 3; ++k) b->origin[k] = urand(-0.2, 0.2);
        b->origin[0] += i ? urand(0.5, 2.5) : 0;
        b->origin[2] += i == 1 ? 2.0 : 0;
        b->angle0 = urand(-1.5, 1.5);
        b->offset0 = urand(0, 0.5);
        b->mass = urand(50, 400);
        b->com[0] = urand(0.2, 1.5), b->com[1] = urand(-0.05, 0.05), b->com[2] = urand(-0.1, 0.1);
        random_inertia(b->mass, b->inertia);
        m->dof[i] = b->fixed ? -1 : m->nd++;
    }
}

static chain* make(const model* m) {
    char err[200];
    chain* c = chain_create(m->b, m->nb, m->g, err, sizeof err);
    CHECK(c != NULL, "%s", err);
    if (c) CHECK(chain_ndof(c) == m->nd, "ndof %d vs %d", chain_ndof(c), m->nd);
    return c;
}

static double maxabs(const double* x, int n) {
    double s = 0;
    for (int k = 0; k < n; ++k) s = fmax(s, fabs(x[k]));
    return s;
}

// Issue 26's three-link chain (revolute, revolute, prismatic on a slewing
// column) and a tree with a locked joint and a jib extension on the knuckle.
static const spec RRP[] = {{-1, CHAIN_REVOLUTE, 0}, {0, CHAIN_REVOLUTE, 0}, {1, CHAIN_REVOLUTE, 0}, {2, CHAIN_PRISMATIC, 0}};
static const spec TREE[] = {{-1, CHAIN_REVOLUTE, 0}, {0, CHAIN_REVOLUTE, 0},  {1, CHAIN_REVOLUTE, 0},
                            {2, CHAIN_PRISMATIC, 0}, {3, CHAIN_REVOLUTE, 0},  {4, CHAIN_PRISMATIC, 0},
                            {2, CHAIN_REVOLUTE, 0},  {6, CHAIN_PRISMATIC, 0}, {1, CHAIN_REVOLUTE, 1}};

static void check_model(const model* m, int trials, double* worst_M, double* worst_b) {
    chain* c = make(m);
    if (!c) return;
    chain_ws* w = chain_ws_create(c);
    const int nd = m->nd;
    for (int t = 0; t < trials; ++t) {
        double q[NB_MAX], qd[NB_MAX];
        for (int k = 0; k < nd; ++k) q[k] = urand(-2, 2), qd[k] = urand(-1.5, 1.5);
        chain_update(c, w, q, qd);
        // Poses against the test's kinematics.
        cplx qc[NB_MAX], R[NB_MAX][9], P[NB_MAX][3];
        for (int k = 0; k < nd; ++k) qc[k] = q[k];
        fk(m, qc, R, P);
        for (int i = 0; i < m->nb; ++i) {
            double Rb[9], pb[3];
            chain_body_pose(c, w, i, Rb, pb);
            for (int k = 0; k < 9; ++k) CHECK_NEAR(Rb[k], creal(R[i][k]), 1e-14);
            for (int k = 0; k < 3; ++k) CHECK_NEAR(pb[k], creal(P[i][k]), 1e-13);
        }
        // Energy.
        CHECK_REL(chain_kinetic_energy(c, w), kinetic(m, q, qd), 1e-12);
        CHECK_NEAR(chain_potential_energy(c, w), potential(m, q), 1e-12 * 1e4);
        // M against the Hessian of T in qd.
        double M[NB_MAX * NB_MAX], Mn[NB_MAX * NB_MAX];
        chain_mass_matrix(c, w, M);
        for (int i = 0; i < nd; ++i)
            for (int j = 0; j < nd; ++j) {
                double u[NB_MAX] = {0}, v[NB_MAX] = {0};
                u[i] += 1, u[j] += 1, v[i] += 1, v[j] -= 1;
                Mn[i * nd + j] = i == j ? 2 * kinetic(m, q, u) / 4 : 0.5 * (kinetic(m, q, u) - kinetic(m, q, v));
            }
        const double sM = maxabs(Mn, nd * nd);
        for (int k = 0; k < nd * nd; ++k) {
            *worst_M = fmax(*worst_M, fabs(M[k] - Mn[k]) / sM);
            CHECK_NEAR(M[k], Mn[k], 1e-12 * sM);
        }
        // Bias against numerical Lagrange (Richardson on h = 1e-3, 5e-4).
        double B[NB_MAX], Bn[NB_MAX];
        chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY | CHAIN_GRAVITY, B);
        for (int i = 0; i < nd; ++i) {
            const double a = lagrange_lhs(m, q, qd, i, 1e-3), b = lagrange_lhs(m, q, qd, i, 5e-4);
            Bn[i] = (4 * b - a) / 3;
        }
        const double sB = maxabs(Bn, nd);
        for (int k = 0; k < nd; ++k) {
            *worst_b = fmax(*worst_b, fabs(B[k] - Bn[k]) / sB);
            CHECK_NEAR(B[k], Bn[k], 1e-10 * sB);
        }
        // Inverse and forward dynamics are each other's inverse: tau = M qdd + C + G.
        double qdd[NB_MAX], tau[NB_MAX], back[NB_MAX];
        for (int k = 0; k < nd; ++k) qdd[k] = urand(-3, 3);
        chain_inverse_dynamics(c, w, qdd, CHAIN_VELOCITY | CHAIN_GRAVITY, tau);
        for (int i = 0; i < nd; ++i) {
            double s = B[i];
            for (int j = 0; j < nd; ++j) s += M[i * nd + j] * qdd[j];
            CHECK_NEAR(tau[i], s, 1e-11 * (maxabs(tau, nd) + sB));
        }
        CHECK(chain_forward_dynamics(c, w, tau, back) == 0, "forward dynamics");
        for (int k = 0; k < nd; ++k) CHECK_NEAR(back[k], qdd[k], 1e-9);

        // A point on every body: its Jacobian by complex steps, Jdot by
        // central differences along qd.
        for (int i = 0; i < m->nb; ++i) {
            const double pb[3] = {urand(-1, 2), urand(-0.2, 0.2), urand(-0.3, 0.3)};
            double J[3 * NB_MAX], Jd[3 * NB_MAX], pw[3], vw[3];
            chain_point_jacobian(c, w, i, pb, J, Jd);
            chain_world_point(c, w, i, pb, pw, vw);
            for (int k = 0; k < nd; ++k) {
                for (int x = 0; x < nd; ++x) qc[x] = q[x] + (x == k ? I * EPS : 0);
                fk(m, qc, R, P);
                cplx p[3];
                point_c(R[i], P[i], pb, p);
                for (int x = 0; x < 3; ++x) CHECK_NEAR(J[x * nd + k], cimag(p[x]) / EPS, 1e-13);
            }
            for (int x = 0; x < 3; ++x) {
                double v = 0;
                for (int k = 0; k < nd; ++k) v += J[x * nd + k] * qd[k];
                CHECK_NEAR(vw[x], v, 1e-13);
            }
            double Jp[3 * NB_MAX], Jm[3 * NB_MAX], qp[NB_MAX], qm[NB_MAX], Jd1[3 * NB_MAX];
            const double hs[2] = {1e-3, 5e-4};
            for (int r = 0; r < 2; ++r) {
                for (int k = 0; k < nd; ++k) qp[k] = q[k] + hs[r] * qd[k], qm[k] = q[k] - hs[r] * qd[k];
                chain_update(c, w, qp, qd);
                chain_point_jacobian(c, w, i, pb, Jp, NULL);
                chain_update(c, w, qm, qd);
                chain_point_jacobian(c, w, i, pb, Jm, NULL);
                for (int k = 0; k < 3 * nd; ++k) {
                    const double d = (Jp[k] - Jm[k]) / (2 * hs[r]);
                    Jd1[k] = r == 0 ? d : (4 * d - Jd1[k]) / 3;
                }
            }
            chain_update(c, w, q, qd);
            for (int k = 0; k < 3 * nd; ++k) CHECK_NEAR(Jd[k], Jd1[k], 1e-9 * (1 + fabs(Jd1[k])));
        }
        // A cylinder between two random bodies: L and dL/dq by a complex step
        // per DOF, d/dt(dL/dq) by central differences along qd.
        for (int rep = 0; rep < 4; ++rep) {
            const int a = rand() % m->nb, b = rand() % m->nb;
            const double pa[3] = {urand(-0.5, 1), urand(-0.2, 0.2), urand(-0.3, 0.3)};
            const double pbb[3] = {urand(-0.5, 1), urand(-0.2, 0.2), urand(-0.3, 0.3) + (a == b ? 1.0 : 0.0)};
            double dL[NB_MAX], dLd[NB_MAX], Ld;
            const double L = chain_cylinder(c, w, a, pa, b, pbb, &Ld, dL, dLd);
            double Lr = 0;
            for (int k = 0; k < nd; ++k) {
                for (int x = 0; x < nd; ++x) qc[x] = q[x] + (x == k ? I * EPS : 0);
                fk(m, qc, R, P);
                cplx xa[3], xb[3];
                point_c(R[a], P[a], pa, xa);
                point_c(R[b], P[b], pbb, xb);
                const cplx d[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
                const cplx Lc = csqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                Lr = creal(Lc);
                CHECK_NEAR(dL[k], cimag(Lc) / EPS, 1e-13);
            }
            if (nd) CHECK_REL(L, Lr, 1e-14);
            double ldot = 0;
            for (int k = 0; k < nd; ++k) ldot += dL[k] * qd[k];
            CHECK_NEAR(Ld, ldot, 1e-13);
            double gp[NB_MAX], gm[NB_MAX], qp[NB_MAX], qm[NB_MAX], Dn[NB_MAX];
            const double hs[2] = {1e-3, 5e-4};
            for (int r = 0; r < 2; ++r) {
                for (int k = 0; k < nd; ++k) qp[k] = q[k] + hs[r] * qd[k], qm[k] = q[k] - hs[r] * qd[k];
                chain_update(c, w, qp, qd);
                chain_cylinder(c, w, a, pa, b, pbb, NULL, gp, NULL);
                chain_update(c, w, qm, qd);
                chain_cylinder(c, w, a, pa, b, pbb, NULL, gm, NULL);
                for (int k = 0; k < nd; ++k) {
                    const double d = (gp[k] - gm[k]) / (2 * hs[r]);
                    Dn[k] = r == 0 ? d : (4 * d - Dn[k]) / 3;
                }
            }
            chain_update(c, w, q, qd);
            for (int k = 0; k < nd; ++k) CHECK_NEAR(dLd[k], Dn[k], 1e-9 * (1 + fabs(Dn[k])));
            // The Hessian: column j by central differences of dL/dq in q_j;
            // H qd is d/dt(dL/dq).
            double H[NB_MAX * NB_MAX];
            chain_cylinder_hessian(c, w, a, pa, b, pbb, H);
            for (int j = 0; j < nd; ++j) {
                for (int r = 0; r < 2; ++r) {
                    memcpy(qp, q, sizeof(double) * (size_t)nd);
                    memcpy(qm, q, sizeof(double) * (size_t)nd);
                    qp[j] += hs[r], qm[j] -= hs[r];
                    chain_update(c, w, qp, qd);
                    chain_cylinder(c, w, a, pa, b, pbb, NULL, gp, NULL);
                    chain_update(c, w, qm, qd);
                    chain_cylinder(c, w, a, pa, b, pbb, NULL, gm, NULL);
                    for (int k = 0; k < nd; ++k) {
                        const double dd = (gp[k] - gm[k]) / (2 * hs[r]);
                        Dn[k] = r == 0 ? dd : (4 * dd - Dn[k]) / 3;
                    }
                }
                for (int k = 0; k < nd; ++k) CHECK_NEAR(H[k * nd + j], Dn[k], 1e-9 * (1 + fabs(Dn[k])));
                double hq = 0;
                for (int k = 0; k < nd; ++k) hq += H[j * nd + k] * qd[k];
                CHECK_NEAR(hq, dLd[j], 1e-12 * (1 + fabs(dLd[j])));
            }
            chain_update(c, w, q, qd);
        }
    }
    chain_ws_free(w);
    chain_free(c);
}

static void test_three_links_on_slewing_column(void) {
    srand(31);
    double wM = 0, wb = 0;
    for (int k = 0; k < 10; ++k) {
        model m;
        random_model(&m, RRP, 4, 1);
        check_model(&m, 10, &wM, &wb);
    }
    printf("  M vs d2T/dqd2: worst %.2e; C + G vs numerical Lagrange: worst %.2e (of the largest entry)\n", wM, wb);
}

static void test_tree_with_locked_joints(void) {
    srand(32);
    double wM = 0, wb = 0;
    for (int k = 0; k < 6; ++k) {
        model m;
        random_model(&m, TREE, 9, k % 2);
        check_model(&m, 5, &wM, &wb);
    }
    printf("  M vs d2T/dqd2: worst %.2e; C + G vs numerical Lagrange: worst %.2e (of the largest entry)\n", wM, wb);
}

int main(int argc, char** argv) {
    RUN_TEST(test_three_links_on_slewing_column);
    RUN_TEST(test_tree_with_locked_joints);
    TEST_MAIN_END();
}
