// rcl_soak.c: random sandbox drives with the rated capacity limiter on
// (random_drive.h), one JSON line per seed. A measuring tool, not a test
// (never registered with ctest: a long drive is minutes):
//   build/tests/world/rcl_soak [FIRST_SEED [NSEEDS [DURATION_S [-v]]]]
// defaults 1 1 600.
#include "random_drive.h"

#include <stdlib.h>

int main(int argc, char** argv) {
    const unsigned long long first = argc > 1 ? strtoull(argv[1], NULL, 10) : 1;
    const int nseed = argc > 2 ? atoi(argv[2]) : 1;
    const double duration = argc > 3 ? atof(argv[3]) : 600;
    const bool verbose = argc > 4 && !strcmp(argv[4], "-v");
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    if (!m) {
        fprintf(stderr, "rcl_soak: %s\n", err);
        return 2;
    }
    int bad = 0;
    for (int k = 0; k < nseed; ++k) {
        rd_result r;
        const uint64_t seed = first + (uint64_t)k;
        if (random_drive(m, seed, duration, verbose, &r)) {
            fprintf(stderr, "rcl_soak: seed %llu: %s\n", (unsigned long long)seed, r.err);
            bad = 1;
            continue;
        }
        printf("{\"seed\":%llu,\"t_end_s\":%.2f,\"failed\":%d,\"util_max\":%.3f,\"t_util_max_s\":%.2f,"
               "\"t90_s\":%.2f,\"t90_near_stop_s\":%.2f,\"t90_load_over_chart_s\":%.2f,\"t90_contact_s\":%.2f,"
               "\"t90_other_s\":%.2f,\"t90_longest_s\":%.2f,\"t90_longest_end_s\":%.2f,\"t_near_stop_s\":%.2f,"
               "\"t_cut_s\":%.2f,\"hooked_over_capacity_max\":%.3f,\"picks\":%d,\"error\":\"%s\"}\n",
               (unsigned long long)seed, r.t_end, r.failed, r.util_max, r.t_util_max, r.t90, r.t90_stop, r.t90_over, r.t90_contact, r.t90_other, r.t90_run, r.t90_run_at,
               r.t_stop, r.u_cut, r.true_max, r.picks, r.failed ? "see stderr" : "");
        if (r.failed) fprintf(stderr, "rcl_soak: seed %llu: %s\n", (unsigned long long)seed, r.err);
        fflush(stdout);
    }
    model_free(m);
    return bad;
}
