// main.c: the cranesim command line.
#include "app.h"
#include "mesh_geom.h"
#ifdef CRANESIM_HAVE_RENDER
#include "render.h"
#endif

#include <stdlib.h>
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
            "  sweep     one scenario on many designs (a grid or a Latin hypercube over model values),\n"
            "            in parallel (threads, MPI ranks): a results table and plots\n"
            "  optimize  the design (model values in bounds) that minimises a run metric under\n"
            "            constraints on others (NLopt, derivative-free): best model file, plot\n"
            "  replay    run a recorded drive session again headless, on its design or a changed one\n"
            "  loadchart rated capacity against outreach: hydraulic and (on the truck) stability limits,\n"
            "            per slew sector, as CSV and PNG (docs/safety.md)\n"
            "  serve     the simulation computer: run the model in real time and stream its state over\n"
            "            TCP to viewers and valve controllers (docs/protocol.md)\n"
            "  help      this text; cranesim help <command>: that command's help\n"
            "\n"
            "examples:\n"
            "  cranesim drive\n"
            "  cranesim run --scenario ramp --out ramp.csv --plot ramp.png\n"
            "  cranesim run --scenario hold --load 2000 --out hold.csv\n"
            "  cranesim run --scenario step --set hydraulics.components.lift_cyl.bore=0.11\n"
            "  cranesim compare --scenario ramp --solvers krus,ros34pw2 --plot cmp.png\n",
            CRANESIM_VERSION);
}

static const struct {
    const char* name;
    int (*fn)(int argc, char** argv);
} commands[] = {
    {"run", cmd_run}, {"bench", cmd_bench}, {"compare", cmd_compare}, {"drive", cmd_drive}, {"study", cmd_study},
    {"sweep", cmd_sweep}, {"optimize", cmd_optimize}, {"replay", cmd_replay}, {"loadchart", cmd_loadchart},
    {"serve", cmd_serve},
};

static int (*find_command(const char* name))(int, char**) {
    for (size_t k = 0; k < sizeof commands / sizeof commands[0]; ++k)
        if (!strcmp(name, commands[k].name)) return commands[k].fn;
    return NULL;
}

int main(int argc, char** argv) {
    app_name_params();
#ifdef CRANESIM_HAVE_RENDER
    // World meshes in glTF, Collada, FBX... come through assimp (the core
    // reads OBJ and STL itself).
    mesh_set_importer(render_mesh_import);
#endif
    // A long mesh load (parsing, a loose body's hull) stops at SIGINT or
    // SIGTERM while a command catches them, as a run's steps do.
    mesh_set_cancel(app_signal_caught);
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    const char* cmd = argv[1];
    if (!strcmp(cmd, "help") || !strcmp(cmd, "--help") || !strcmp(cmd, "-h")) {
        if (argc < 3) {
            usage(stdout);
            return 0;
        }
        // cranesim help run = cranesim run --help
        int (*fn)(int, char**) = find_command(argv[2]);
        if (!fn) {
            fprintf(stderr, "cranesim help: unknown command '%s' (try cranesim help)\n", argv[2]);
            return EXIT_USAGE;
        }
        char help[] = "--help";
        char* args[] = {help, NULL};
        return fn(1, args);
    }
    if (!strcmp(cmd, "--version")) {
        printf("cranesim %s\n", CRANESIM_VERSION);
        return 0;
    }
    int (*fn)(int, char**) = find_command(cmd);
    if (!fn) {
        fprintf(stderr, "cranesim: unknown command '%s' (try cranesim help)\n", cmd);
        return EXIT_USAGE;
    }
    int n = argc - 2;
    char** args = app_split_equals(cmd, &n, argv + 2);
    if (!args) {
        fprintf(stderr, "cranesim: out of memory\n");
        return EXIT_RUNTIME;
    }
    int rc = app_check_values(cmd, n, args);
    if (!rc) rc = fn(n, args);
    free(args);
    return rc;
}
