// test_chain_energy.c: free chains of 3, 4 and 5 bodies (slewing column free,
// revolute and prismatic joints, 3D offsets, full inertia tensors), no
// friction: the mechanical energy T + V is conserved over 10 s of RK4. With
// no forces at all, and with ideal springs on the slides (the hydraulics
// replaced by conservative ideal forces, their energy 1/2 k (s - s0)^2 added).
// A wrong Coriolis or centrifugal term, a wrong mass matrix or a wrong
// gravity term shows as a drift of order one.
#include "chain.h"
#include "check.h"

#include <stdlib.h>

static double urand(double lo, double hi) { return lo + (hi - lo) * rand() / (double)RAND_MAX; }

typedef struct sys {
    chain* c;
    chain_ws* w;
    int nd;
    double k;   // slide spring stiffness [N/m] (0: no forces)
    double* s0; // spring rest positions [m], per DOF (NAN: not a slide)
    double* tau;
} sys;

static void rhs(sys* s, const double* y, double* yd) {
    const int nd = s->nd;
    chain_update(s->c, s->w, y, y + nd);
    for (int k = 0; k < nd; ++k) s->tau[k] = isnan(s->s0[k]) ? 0.0 : -s->k * (y[k] - s->s0[k]);
    memcpy(yd, y + nd, sizeof(double) * (size_t)nd);
    if (chain_forward_dynamics(s->c, s->w, s->tau, yd + nd)) CHECK(0, "forward dynamics failed");
}

static double energy(sys* s, const double* y, double* T) {
    chain_update(s->c, s->w, y, y + s->nd);
    *T = chain_kinetic_energy(s->c, s->w);
    double E = *T + chain_potential_energy(s->c, s->w);
    for (int k = 0; k < s->nd; ++k)
        if (!isnan(s->s0[k])) E += 0.5 * s->k * (y[k] - s->s0[k]) * (y[k] - s->s0[k]);
    return E;
}

static void random_inertia(double mass, double In[3][3]) {
    const double a = urand(0.5, 1.5), b = urand(0.5, 1.5), p[3] = {urand(fabs(a - b), a + b), a, b};
    const double t = urand(0, 0.5), c = cos(t), sn = sin(t); // turned about x
    const double Q[3][3] = {{1, 0, 0}, {0, c, -sn}, {0, sn, c}};
    for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y) {
            double v = 0;
            for (int k = 0; k < 3; ++k) v += Q[x][k] * p[k] * 0.3 * mass * Q[y][k];
            In[x][y] = v;
        }
    for (int x = 0; x < 3; ++x)
        for (int y = x + 1; y < 3; ++y) In[x][y] = In[y][x];
}

// Runs one chain for 10 s at step h; returns max |E - E0| / T0, the initial
// kinetic energy (a few hundred J: a stricter scale than the run's largest T
// when a free slide falls out of its boom).
static double run(const int* parent, const chain_joint* joint, int nb, double k, double h, double* travel) {
    chain_body_def b[8];
    for (int i = 0; i < nb; ++i) {
        chain_body_init(&b[i], parent[i]);
        b[i].joint = joint[i];
        b[i].origin[0] = i ? urand(0.8, 2.0) : 0, b[i].origin[1] = urand(-0.1, 0.1);
        b[i].origin[2] = i == 1 ? 2.0 : urand(-0.1, 0.1);
        b[i].angle0 = joint[i] == CHAIN_PRISMATIC ? urand(-0.1, 0.1) : urand(-1, 1);
        b[i].offset0 = urand(0.1, 0.5);
        b[i].mass = urand(50, 300);
        b[i].com[0] = urand(0.3, 1.2), b[i].com[1] = urand(-0.05, 0.05), b[i].com[2] = urand(-0.1, 0.1);
        random_inertia(b[i].mass, b[i].inertia);
    }
    b[0].com[0] = 0.1, b[0].com[2] = 1.0;
    char err[200];
    chain* c = chain_create(b, nb, NULL, err, sizeof err);
    CHECK(c != NULL, "%s", err);
    if (!c) return INFINITY;
    const int nd = chain_ndof(c);
    sys s = {c, chain_ws_create(c), nd, k, calloc((size_t)nd, sizeof(double)), calloc((size_t)nd, sizeof(double))};
    double* y = calloc((size_t)(2 * nd) * 6, sizeof(double));
    double *k1 = y + 2 * nd, *k2 = k1 + 2 * nd, *k3 = k2 + 2 * nd, *k4 = k3 + 2 * nd, *yt = k4 + 2 * nd;
    for (int d = 0; d < nd; ++d) {
        const int slide = joint[chain_dof_body(c, d)] == CHAIN_PRISMATIC;
        y[d] = slide ? urand(0.2, 0.6) : urand(-1, 1);
        y[nd + d] = slide ? urand(-0.3, 0.3) : urand(-0.8, 0.8);
        s.s0[d] = slide ? urand(0.2, 0.6) : NAN;
    }
    double T, Tmax = 0, dEmax = 0;
    const double E0 = energy(&s, y, &T), T0 = T;
    const double y0 = y[nd - 1];
    *travel = 0;
    const int steps = (int)lround(10.0 / h);
    for (int n = 0; n < steps; ++n) {
        rhs(&s, y, k1);
        for (int i = 0; i < 2 * nd; ++i) yt[i] = y[i] + 0.5 * h * k1[i];
        rhs(&s, yt, k2);
        for (int i = 0; i < 2 * nd; ++i) yt[i] = y[i] + 0.5 * h * k2[i];
        rhs(&s, yt, k3);
        for (int i = 0; i < 2 * nd; ++i) yt[i] = y[i] + h * k3[i];
        rhs(&s, yt, k4);
        for (int i = 0; i < 2 * nd; ++i) y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
        const double E = energy(&s, y, &T);
        Tmax = fmax(Tmax, T);
        dEmax = fmax(dEmax, fabs(E - E0));
        *travel = fmax(*travel, fabs(y[nd - 1] - y0));
    }
    chain_ws_free(s.w);
    free(s.s0);
    free(s.tau);
    free(y);
    chain_free(c);
    printf("  (T0 %.0f J, max T %.0f J) ", T0, Tmax);
    return dEmax / T0;
}

static void test_energy_conserved(void) {
    srand(41);
    // 3: column, boom, extension in the boom. 4: column, boom, jib, extension
    // in the jib. 5: column, boom, extension, a jib on the extension, the
    // jib's extension.
    static const int p3[] = {-1, 0, 1}, p4[] = {-1, 0, 1, 2}, p5[] = {-1, 0, 1, 2, 3};
    static const chain_joint j3[] = {CHAIN_REVOLUTE, CHAIN_REVOLUTE, CHAIN_PRISMATIC};
    static const chain_joint j4[] = {CHAIN_REVOLUTE, CHAIN_REVOLUTE, CHAIN_REVOLUTE, CHAIN_PRISMATIC};
    static const chain_joint j5[] = {CHAIN_REVOLUTE, CHAIN_REVOLUTE, CHAIN_PRISMATIC, CHAIN_REVOLUTE,
                                     CHAIN_PRISMATIC};
    const int* P[3] = {p3, p4, p5};
    const chain_joint* J[3] = {j3, j4, j5};
    const double h = 5e-4; // [s]
    for (int n = 0; n < 3; ++n)
        for (int spring = 0; spring < 2; ++spring) {
            double travel;
            const double drift = run(P[n], J[n], n + 3, spring ? 2e4 : 0.0, h, &travel);
            printf("%d bodies, %s: energy drift %.2e of T0 over 10 s at h = %g s (last slide travelled %.2f m)\n",
                   n + 3, spring ? "springs on the slides" : "no forces", drift, h, travel);
            CHECK(drift < 1e-6, "%d bodies: drift %.3g", n + 3, drift);
            CHECK(travel > 0.05, "the slide hardly moved (%.3g m)", travel);
        }
}

int main(int argc, char** argv) {
    RUN_TEST(test_energy_conserved);
    TEST_MAIN_END();
}
