// main.c: the cranesim command line.
#include "app.h"

#include <string.h>

#ifndef CRANESIM_VERSION
#define CRANESIM_VERSION "0.1.0"
#endif

static void usage(FILE* f) {
    fprintf(f,
            "cranesim %s: virtual prototyping of hydraulically driven mobile cranes\n"
            "\n"
            "usage: cranesim <command> [options]    (cranesim <command> --help for details)\n"
            "\n"
            "commands:\n"
            "  drive     drive the crane in real time in a 3D sandbox (joystick or keyboard);\n"
            "            without a display, a headless real-time run that reports what it did\n"
            "  run       run a scenario headless, faster than real time, to CSV (and a plot)\n"
            "  compare   run one scenario two ways (backends or solvers); error metrics, overlay plots\n"
            "  bench     real-time factors as JSON lines\n"
            "  study     solver study: every integrator against a CVODE reference, work-precision plot\n"
            "  help      this text\n"
            "\n"
            "examples:\n"
            "  cranesim drive\n"
            "  cranesim run --scenario ramp --out ramp.csv --plot ramp.png\n"
            "  cranesim run --scenario hold --set mechanics.load_mass=2000\n"
            "  cranesim compare --scenario ramp --solvers krus,ros34pw2 --plot cmp.png\n",
            CRANESIM_VERSION);
}

int main(int argc, char** argv) {
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    const char* cmd = argv[1];
    if (!strcmp(cmd, "help") || !strcmp(cmd, "--help") || !strcmp(cmd, "-h")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(cmd, "--version")) {
        printf("cranesim %s\n", CRANESIM_VERSION);
        return 0;
    }
    if (!strcmp(cmd, "run")) return cmd_run(argc - 2, argv + 2);
    if (!strcmp(cmd, "bench")) return cmd_bench(argc - 2, argv + 2);
    if (!strcmp(cmd, "compare")) return cmd_compare(argc - 2, argv + 2);
    if (!strcmp(cmd, "drive")) return cmd_drive(argc - 2, argv + 2);
    if (!strcmp(cmd, "study")) return cmd_study(argc - 2, argv + 2);
    fprintf(stderr, "cranesim: unknown command '%s' (try cranesim help)\n", cmd);
    return EXIT_USAGE;
}
