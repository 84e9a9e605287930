// test_cvode_ref.c: the in-house integrators against SUNDIALS CVODE (BDF) run
// at tight tolerance, an independent reference, on a small hydraulic problem
// shaped like one crane function: a proportional valve with first-order spool
// dynamics and a piecewise-linear command, a cylinder with compressible
// chambers, and a mass load.
#include "check.h"
#include "hyd_cvode.h"
#include "hyd_solver.h"

#include <math.h>

// State: u [-], pA [Pa], pB [Pa], x [m], v [m/s].
enum { N = 5, NOUT = 101 };
static const double ps = 2e7, pt = 1e5;          // supply and tank [Pa]
static const double Be = 1.4e9;                  // bulk modulus [Pa]
static const double AA = 2e-3, AB = 1e-3;        // piston areas [m^2]
static const double VA0 = 1e-4, VB0 = 1e-4;      // dead volumes [m^3]
static const double stroke = 0.5;                // [m]
static const double mass = 500.0, bv = 2e3;      // [kg], [N s/m]
static const double Kv = 3.3e-7;                 // valve edge [m^3/(s Pa^0.5)]
static const double tau_s = 0.02;                // spool time constant [s]

// Command table: ramps up, holds, reverses (t [s], u [-]).
static double command(double t) {
    static const double tt[] = {0.0, 0.1, 0.3, 0.6, 0.8, 2.0};
    static const double uu[] = {0.0, 0.0, 1.0, 1.0, -0.5, -0.5};
    for (int i = 0; i < 5; ++i)
        if (t < tt[i + 1]) return uu[i] + (uu[i + 1] - uu[i]) * (t - tt[i]) / (tt[i + 1] - tt[i]);
    return uu[5];
}

// Orifice law smoothed near dp = 0 so the Jacobian stays bounded [m^3/s].
static double orf(double dp) { return Kv * dp / sqrt(fabs(dp) + 1e5); }

static int cyl_f(void* user, double t, const double* y, double* f) {
    (void)user;
    const double u = y[0], pA = y[1], pB = y[2], x = y[3], v = y[4];
    const double up = fmax(u, 0.0), um = fmax(-u, 0.0);
    const double qa = up * orf(ps - pA) - um * orf(pA - pt);
    const double qb = um * orf(ps - pB) - up * orf(pB - pt);
    f[0] = (command(t) - u) / tau_s;
    f[1] = Be / (VA0 + AA * x) * (qa - AA * v);
    f[2] = Be / (VB0 + AB * (stroke - x)) * (qb + AB * v);
    f[3] = v;
    f[4] = (pA * AA - pB * AB - bv * v - mass * 9.81) / mass;
    return 0;
}

static void initial(double* y) {
    y[0] = 0.0;
    y[2] = 1e6;
    y[1] = (mass * 9.81 + y[2] * AB) / AA; // static balance
    y[3] = 0.1;
    y[4] = 0.0;
}

typedef struct traj {
    double y[NOUT][N];
    int k;
} traj;

static int store(void* user, double t, const double* y) {
    (void)t;
    traj* tr = user;
    if (tr->k < NOUT) memcpy(tr->y[tr->k], y, sizeof tr->y[0]);
    tr->k++;
    return 0;
}

static traj ref, got;

// Max error over all outputs: pressures relative to the peak pressure, the
// stroke in metres.
static void compare(const char* what, double p_tol, double x_tol) {
    double pmax = 0.0, ep = 0.0, ex = 0.0;
    for (int k = 0; k < NOUT; ++k) {
        pmax = fmax(pmax, fmax(ref.y[k][1], ref.y[k][2]));
        ep = fmax(ep, fmax(fabs(got.y[k][1] - ref.y[k][1]), fabs(got.y[k][2] - ref.y[k][2])));
        ex = fmax(ex, fabs(got.y[k][3] - ref.y[k][3]));
    }
    CHECK(got.k == NOUT, "%s: %d outputs", what, got.k);
    CHECK(ep <= p_tol * pmax, "%s: pressure error %.3g of peak > %.3g", what, ep / pmax, p_tol);
    CHECK(ex <= x_tol, "%s: stroke error %.3g m > %.3g", what, ex, x_tol);
    printf("  %-28s pressure error %.2e of peak, stroke error %.2e m\n", what, ep / pmax, ex);
}

static void test_against_cvode(void) {
    hyd_problem p = {0};
    p.n = N;
    p.f = cyl_f;
    double y[N];
    initial(y);
    hyd_cvode_opts co = hyd_cvode_default_opts();
    co.rtol = 1e-11;
    co.atol = 1e-9;
    co.h_max = 0.01; // do not step over the command table's corners unseen
    hyd_solver_stats cst;
    ref.k = 0;
    int rc = hyd_cvode_integrate(&p, &co, 0.0, y, 1.0, 0.01, store, &ref, &cst);
    CHECK(rc == HYD_OK && ref.k == NOUT, "cvode rc %d, %d outputs", rc, ref.k);
    CHECK(cst.steps > 0 && cst.fevals > 0 && cst.lus > 0, "cvode stats");
    printf("  cvode reference: %ld steps, %ld f, %ld J, %ld setups\n", cst.steps, cst.fevals,
           cst.jevals, cst.lus);
    // Sanity: the cylinder really moves and the pressures really change.
    CHECK(fabs(ref.y[NOUT - 1][3] - 0.1) > 0.02, "stroke moved %.3g m", ref.y[NOUT - 1][3] - 0.1);

    for (int m = HYD_ROS34PW2; m <= HYD_RODAS3; ++m) {
        hyd_solver_opts o = hyd_default_solver_opts();
        o.rtol = 1e-7, o.atol = 1e-6, o.h = 0.0;
        hyd_solver* s = hyd_solver_create(&p, (hyd_method)m, &o);
        initial(y);
        got.k = 0;
        rc = hyd_solver_integrate(s, 0.0, y, 1.0, 0.01, store, &got);
        CHECK(rc == HYD_OK, "%s rc %d", hyd_method_name(m), rc);
        compare(hyd_method_name(m), 1e-5, 1e-7);
        printf("  %-28s %ld steps, %ld rejected\n", "", hyd_solver_get_stats(s)->steps,
               hyd_solver_get_stats(s)->rejected);
        hyd_solver_destroy(s);
    }
    for (int m = HYD_KRUS; m <= HYD_ROS2; ++m) {
        hyd_solver_opts o = hyd_default_solver_opts();
        o.h = 1e-4;
        hyd_solver* s = hyd_solver_create(&p, (hyd_method)m, &o);
        initial(y);
        got.k = 0;
        rc = hyd_solver_integrate(s, 0.0, y, 1.0, 0.01, store, &got);
        CHECK(rc == HYD_OK, "%s rc %d", hyd_method_name(m), rc);
        compare(hyd_method_name(m), 2e-4, 1e-6);
        hyd_solver_destroy(s);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_against_cvode);
    TEST_MAIN_END();
}
