// bench_hydraulics.c: ns per hyd_eval and per hyd_jacobian on the default
// two-actuator crane circuit (11 states). Not a test (tests never time
// anything); run by hand: ./bench_hydraulics [iterations]
#include "hydraulics.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now_s(void) {
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char** argv) {
    const long iters = argc > 1 ? atol(argv[1]) : 2000000;
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    hyd_data* d = hyd_data_create(m);
    const int n = hyd_model_nstate(m);
    double y[64], ydot[64], J[64 * 64];
    hyd_model_initial_state(m, y);
    // A working point: both valves half open, pressures in the working range.
    for (int i = 0; i < n; ++i)
        y[i] = 8e6 + 1e5 * i;
    y[hyd_model_valve_state(m, 0)] = 0.5;
    y[hyd_model_valve_state(m, 1)] = -0.3;
    d->valve_cmd[0] = 0.5;
    d->valve_cmd[1] = -0.3;
    d->cyl_x[0] = 0.3;
    d->cyl_v[0] = 0.05;
    d->cyl_x[1] = 0.2;
    d->cyl_v[1] = -0.04;

    double sink = 0.0;
    // Vary the state a little per call so nothing is hoisted out of the loop.
    double t0 = now_s();
    for (long k = 0; k < iters; ++k) {
        y[0] = 15e6 + (double)(k & 1023);
        hyd_eval(m, d, 0.0, y, ydot);
        sink += ydot[3];
    }
    double t_eval = (now_s() - t0) / (double)iters;

    const long jit = iters / 4;
    t0 = now_s();
    for (long k = 0; k < jit; ++k) {
        y[0] = 15e6 + (double)(k & 1023);
        hyd_jacobian(m, d, 0.0, y, ydot, J, n, 0, 0);
        sink += J[3 * n + 3];
    }
    double t_jac = (now_s() - t0) / (double)jit;

    // Same with the constant bulk modulus (no pow() per node).
    hyd_model_set(m, "fluid.air_fraction", 0.0, err, sizeof err);
    t0 = now_s();
    for (long k = 0; k < iters; ++k) {
        y[0] = 15e6 + (double)(k & 1023);
        hyd_eval(m, d, 0.0, y, ydot);
        sink += ydot[3];
    }
    double t_eval_c = (now_s() - t0) / (double)iters;

    printf("states %d\n", n);
    printf("hyd_eval      %.1f ns  (entrained-air Be(p))\n", 1e9 * t_eval);
    printf("hyd_jacobian  %.1f ns  (entrained-air Be(p), includes f)\n", 1e9 * t_jac);
    printf("hyd_eval      %.1f ns  (constant Be)\n", 1e9 * t_eval_c);
    printf("(checksum %g)\n", sink);
    hyd_data_free(d);
    hyd_model_free(m);
    return 0;
}
