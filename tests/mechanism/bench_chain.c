// bench_chain.c: nanoseconds per evaluation of the chain library for chains
// of n = 2..10 bodies, all joints free (the slewing column, then booms and
// extensions in the pattern R R P P R P P R P). Not a test: it only prints.
//   build/tests/mechanism/bench_chain [evaluations per size, default 200000]
#include "chain.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    // CPU time of this thread: the machine is shared, wall time would count others' work.
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static int cmp(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char** argv) {
    const long N = argc > 1 ? atol(argv[1]) : 200000;
    static const chain_joint pattern[10] = {CHAIN_REVOLUTE,  CHAIN_REVOLUTE,  CHAIN_REVOLUTE, CHAIN_PRISMATIC,
                                            CHAIN_PRISMATIC, CHAIN_REVOLUTE,  CHAIN_PRISMATIC, CHAIN_PRISMATIC,
                                            CHAIN_REVOLUTE,  CHAIN_PRISMATIC};
    printf("bodies  dof  update  mass matrix  bias  update+forward dynamics  cylinder  [ns per call]\n");
    volatile double sink = 0;
    for (int n = 2; n <= 10; ++n) {
        chain_body_def b[10];
        for (int i = 0; i < n; ++i) {
            chain_body_init(&b[i], i - 1);
            b[i].joint = pattern[i];
            b[i].origin[0] = i ? 1.5 : 0, b[i].origin[2] = i == 1 ? 2 : 0.05;
            b[i].angle0 = i == 1 ? -1.2 : 0;
            b[i].mass = 100 + 10 * i;
            b[i].com[0] = 0.7, b[i].com[2] = 0.02;
            chain_inertia_box(b[i].mass, 1.5, 0.2, 0.25, b[i].inertia);
        }
        char err[200];
        chain* c = chain_create(b, n, NULL, err, sizeof err);
        if (!c) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        chain_ws* w = chain_ws_create(c);
        const int nd = chain_ndof(c);
        double q[10], qd[10], qdd[10], tau[10], dL[10], dLd[10];
        for (int k = 0; k < nd; ++k) q[k] = 0.3 + 0.1 * k, qd[k] = 0.2, tau[k] = 100.0 * k;
        const double pa[3] = {0.3, 0, 0.2}, pb[3] = {0.9, 0, -0.1};
        double t_up[5], t_fd[5], t_cy[5], t_m[5], t_b[5], M[100], B[10];
        for (int rep = 0; rep < 5; ++rep) {
            // The angles move a little each call, as in a run, so nothing is constant.
            double t0 = now();
            for (long k = 0; k < N; ++k) {
                q[0] += 1e-9;
                chain_update(c, w, q, qd);
            }
            double t1 = now();
            for (long k = 0; k < N; ++k) {
                q[0] += 1e-9;
                chain_update(c, w, q, qd);
                chain_forward_dynamics(c, w, tau, qdd);
                sink += qdd[nd - 1];
            }
            double t2 = now();
            for (long k = 0; k < N; ++k) {
                sink += chain_cylinder(c, w, n - 2, pa, n - 1, pb, NULL, dL, dLd);
            }
            double t3 = now();
            for (long k = 0; k < N; ++k) {
                chain_mass_matrix(c, w, M);
                sink += M[nd * nd - 1];
            }
            double t4 = now();
            for (long k = 0; k < N; ++k) {
                chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY | CHAIN_GRAVITY, B);
                sink += B[0];
            }
            double t5 = now();
            t_m[rep] = (t4 - t3) / N * 1e9;
            t_b[rep] = (t5 - t4) / N * 1e9;
            t_up[rep] = (t1 - t0) / N * 1e9;
            t_fd[rep] = (t2 - t1) / N * 1e9;
            t_cy[rep] = (t3 - t2) / N * 1e9;
        }
        qsort(t_up, 5, sizeof(double), cmp);
        qsort(t_fd, 5, sizeof(double), cmp);
        qsort(t_cy, 5, sizeof(double), cmp);
        qsort(t_m, 5, sizeof(double), cmp);
        qsort(t_b, 5, sizeof(double), cmp);
        printf("%6d  %3d  %6.0f  %11.0f  %4.0f  %23.0f  %8.0f\n", n, nd, t_up[2], t_m[2], t_b[2], t_fd[2], t_cy[2]);
        chain_ws_free(w);
        chain_free(c);
    }
    return sink == 12345.678; // keep the work
}
