// bench_solver.c: per-step cost of Krus at h = 0.1 ms on a 15-state problem
// shaped like the crane (docs/hydraulics.md, docs/solvers.md): two actuators with spool, hose and
// chamber pressures, a pump line, and two joints. Not a test (tests never time
// anything); run by hand:  ./bench_solver [seconds_simulated]
// Prints ns per step for each Jacobian strategy.

#include "hyd_solver.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

// State layout per actuator a (base 5a): u, pHA, pA, pHB, pB; then pP (10),
// q1, q2 (11, 12), w1, w2 (13, 14). Units: Pa, rad, rad/s.
enum { NS = 15 };
static const double Be = 1.4e9;      // bulk modulus [Pa]
static const double Vh = 2e-4;       // hose volume [m^3]
static const double Vc = 1e-3;       // chamber volume (held constant here) [m^3]
static const double Vp = 1e-3;       // pump line volume [m^3]
static const double G = 7e-9;        // hose-chamber laminar conductance [m^3/(s Pa)]
static const double Kv = 6.7e-7;     // valve edge coefficient [m^3/(s Pa^0.5)]
static const double ptr = 1e5;       // smoothing pressure of the orifice law [Pa]
static const double ps = 2e7;        // pump regulation pressure [Pa]
static const double Qp = 1.5e-3;     // pump flow [m^3/s]
static const double pt = 1e5;        // tank [Pa]
static const double AA = 3e-3, AB = 1.5e-3; // piston areas [m^2]
static const double tau_s = 0.01;    // spool time constant [s]
static const double arm = 0.3;       // cylinder lever arm [m]
static const double inertia = 2e3;   // joint inertia [kg m^2]
static const double cvisc = 2e3;     // joint damping [N m s]
static const double mgl = 5e3;       // gravity moment [N m]

static double orifice(double dp) { return Kv * dp / sqrt(fabs(dp) + ptr); }
static double d_orifice(double dp) {
    double a = fabs(dp) + ptr;
    return Kv * (a - 0.5 * fabs(dp)) / (a * sqrt(a));
}

static int crane_f(void* user, double t, const double* y, double* f) {
    (void)user;
    const double pP = y[10];
    double qv = 0.0;
    double s1 = sin(y[11]), c1 = cos(y[11]);
    double s12 = sin(y[11] + y[12]);
    for (int a = 0; a < 2; ++a) {
        const double* x = y + 5 * a;
        double* d = f + 5 * a;
        double ucmd = a == 0 ? 0.5 * sin(2.0 * t) : 0.3;
        double u = x[0];
        d[0] = (ucmd - u) / tau_s;
        double up = fmax(u, 0.0), um = fmax(-u, 0.0);
        double qa = up * orifice(pP - x[1]) - um * orifice(x[1] - pt);
        double qb = um * orifice(pP - x[3]) - up * orifice(x[3] - pt);
        qv += up * orifice(pP - x[1]) + um * orifice(pP - x[3]);
        double xd = arm * y[13 + a];
        d[1] = Be / Vh * (qa - G * (x[1] - x[2]));
        d[2] = Be / Vc * (G * (x[1] - x[2]) - AA * xd);
        d[3] = Be / Vh * (qb - G * (x[3] - x[4]));
        d[4] = Be / Vc * (G * (x[3] - x[4]) + AB * xd);
    }
    f[10] = Be / Vp * (Qp * 0.5 * (1.0 - tanh((pP - ps) / 5e5)) - qv);
    f[11] = y[13];
    f[12] = y[14];
    double F1 = y[2] * AA - y[4] * AB, F2 = y[7] * AA - y[9] * AB;
    f[13] = (arm * F1 - mgl * c1 - cvisc * y[13]) / inertia;
    f[14] = (arm * F2 - 0.5 * mgl * s12 - cvisc * y[14] + 0.1 * mgl * s1) / inertia;
    return 0;
}

// Analytic diagonal blocks only (what the block-diagonal W uses).
static int crane_jac_blocks(void* user, double t, const double* y, double* J) {
    (void)user;
    (void)t;
    const double pP = y[10];
#define JJ(i, j) J[(i) * NS + (j)]
    double dqv = 0.0;
    for (int a = 0; a < 2; ++a) {
        const int o = 5 * a;
        double u = y[o], up = fmax(u, 0.0), um = fmax(-u, 0.0);
        JJ(o, o) = -1.0 / tau_s;
        double dqa = -up * d_orifice(pP - y[o + 1]) - um * d_orifice(y[o + 1] - pt);
        double dqb = -um * d_orifice(pP - y[o + 3]) - up * d_orifice(y[o + 3] - pt);
        JJ(o + 1, o + 1) = Be / Vh * (dqa - G), JJ(o + 1, o + 2) = Be / Vh * G;
        JJ(o + 2, o + 1) = Be / Vc * G, JJ(o + 2, o + 2) = -Be / Vc * G;
        JJ(o + 3, o + 3) = Be / Vh * (dqb - G), JJ(o + 3, o + 4) = Be / Vh * G;
        JJ(o + 4, o + 3) = Be / Vc * G, JJ(o + 4, o + 4) = -Be / Vc * G;
        dqv += up * d_orifice(pP - y[o + 1]) + um * d_orifice(pP - y[o + 3]);
    }
    double th = tanh((pP - ps) / 5e5);
    JJ(10, 10) = Be / Vp * (-Qp * 0.5 * (1.0 - th * th) / 5e5 - dqv);
    JJ(13, 13) = -cvisc / inertia;
    JJ(14, 14) = -cvisc / inertia;
#undef JJ
    return 0;
}

static const int blocks[] = {1, 2, 2, 1, 2, 2, 1, 1, 1, 1, 1};

// A nearly free right-hand side with the same size and block pattern: its
// timings are the solver's own overhead per step.
static int cheap_f(void* user, double t, const double* y, double* f) {
    (void)user;
    (void)t;
    for (int i = 0; i < NS; ++i) f[i] = -y[i];
    f[1] += 0.5 * y[2], f[2] += 0.5 * y[1];
    return 0;
}
static int cheap_jac(void* user, double t, const double* y, double* J) {
    (void)user, (void)t, (void)y;
    for (int i = 0; i < NS; ++i) J[i * NS + i] = -1.0;
    J[1 * NS + 2] = J[2 * NS + 1] = 0.5;
    return 0;
}

static void initial(double* y) {
    for (int a = 0; a < 2; ++a) {
        y[5 * a] = 0.0;
        y[5 * a + 1] = y[5 * a + 2] = 6e6;
        y[5 * a + 3] = y[5 * a + 4] = 3e6;
    }
    y[10] = 2e7;
    y[11] = 0.5, y[12] = -0.3, y[13] = y[14] = 0.0;
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void bench(const char* name, hyd_method m, int block, int analytic, int jac_every,
                  double sim_s, int cheap) {
    hyd_problem p = {0};
    p.n = NS;
    p.f = cheap ? cheap_f : crane_f;
    p.jac = analytic ? (cheap ? cheap_jac : crane_jac_blocks) : NULL;
    if (block) p.nblock = (int)(sizeof blocks / sizeof blocks[0]), p.block_size = blocks;
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 1e-4;
    o.jac_every = jac_every;
    hyd_solver* s = hyd_solver_create(&p, m, &o);
    double y[NS], t = 0.0;
    initial(y);
    hyd_solver_advance(s, &t, y, 0.1); // warm up
    hyd_solver_clear_stats(s);
    double t0 = now();
    int rc = hyd_solver_advance(s, &t, y, 0.1 + sim_s);
    double wall = now() - t0;
    const hyd_solver_stats* st = hyd_solver_get_stats(s);
    if (st->steps == 0) {
        printf("%-36s %-5s rc=%d: failed at once (unstable at this h)\n", name, hyd_method_name(m),
               rc);
        hyd_solver_destroy(s);
        return;
    }
    printf("%-36s %-5s rc=%d %8.1f ns/step  %6.0fx real time  f/step %.2f  J/step %.2f  "
           "LU/step %.2f  pP=%.4g\n",
           name, hyd_method_name(m), rc, 1e9 * wall / (double)st->steps, sim_s / wall,
           (double)st->fevals / st->steps, (double)st->jevals / st->steps,
           (double)st->lus / st->steps, y[10]);
    hyd_solver_destroy(s);
}

int main(int argc, char** argv) {
    double sim = argc > 1 ? atof(argv[1]) : 5.0;
    // The cost of f itself is (crane-like - near-free) / 2 per step: timing f
    // alone in a loop on fixed inputs understates it (libm fast paths, hoisting).
    for (int cheap = 0; cheap < 2; ++cheap) {
        printf(cheap ? "\nsolver overhead alone (near-free linear f, same sizes):\n"
                     : "\ncrane-like f:\n");
        bench("dense FD J every step", HYD_KRUS, 0, 0, 1, sim, cheap);
        bench("dense FD J every 10 steps", HYD_KRUS, 0, 0, 10, sim, cheap);
        bench("dense analytic J every step", HYD_KRUS, 0, 1, 1, sim, cheap);
        bench("block-diag FD J every 10 steps", HYD_KRUS, 1, 0, 10, sim, cheap);
        bench("block-diag analytic J every step", HYD_KRUS, 1, 1, 1, sim, cheap);
        bench("block-diag analytic J every 10 steps", HYD_KRUS, 1, 1, 10, sim, cheap);
        bench("block-diag analytic J every 10 steps", HYD_ROS2, 1, 1, 10, sim, cheap);
        bench("RK4 (no J)", HYD_RK4, 0, 0, 1, sim, cheap);
    }
    return 0;
}
