// common.c: option parsing and loading shared by the subcommands.
#include "app.h"
#include "live.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

int app_parse_double(const char* s, double* v) {
    char* end;
    errno = 0;
    double x = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(x)) return -1;
    *v = x;
    return 0;
}

static int need_value(int argc, char** argv, int i) {
    if (i + 1 >= argc) {
        fprintf(stderr, "cranesim: option %s needs a value (see --help)\n", argv[i]);
        return -1;
    }
    return 0;
}

static int positive(const char* opt, const char* s, double* v) {
    if (app_parse_double(s, v) || !(*v > 0)) {
        fprintf(stderr, "cranesim: %s: expected a positive number, got '%s'\n", opt, s);
        return -1;
    }
    return 0;
}

static int cmp_double(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

void app_sort(double* v, int n) { qsort(v, (size_t)n, sizeof *v, cmp_double); }

double app_median(double* v, int n) {
    app_sort(v, n);
    return v[n / 2];
}

const char* app_default_drive_scenario(sim_mechanics mech) {
    return mech == SIM_ODE ? "sandbox_pick_place" : "drive_demo";
}

int app_set_mechanics(sim_opts* o, const char* opt, const char* v) {
    if (!strcmp(v, "lagrange")) o->mechanics = SIM_LAGRANGE;
    else if (!strcmp(v, "ode")) o->mechanics = SIM_ODE;
    else {
        fprintf(stderr, "cranesim: %s: expected lagrange or ode, got '%s'\n", opt, v);
        return -1;
    }
    return 0;
}

int app_set_variant(sim_opts* o, const char* opt, const char* v) {
    const int var = lagrange_variant_parse(v);
    if (var < 0) {
        fprintf(stderr, "cranesim: %s: expected full, paper or paper-typo, got '%s'\n", opt, v);
        return -1;
    }
    o->variant = (lagrange_variant)var;
    return 0;
}

int app_set_solver(sim_opts* o, const char* opt, const char* v) {
    o->cvode = !strcmp(v, "cvode");
    if (o->cvode) return 0;
    const int m = hyd_method_parse(v);
    if (m < 0) {
        fprintf(stderr, "cranesim: %s: expected krus, ros2, rk4, ros34pw2, rodas3 or cvode, got '%s'\n", opt, v);
        return -1;
    }
    o->solver = (hyd_method)m;
    return 0;
}

int app_parse_common(app_common* c, int argc, char** argv, int* i) {
    const char* a = argv[*i];
    if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
        c->quiet = true;
        return 1;
    }
    if (!strcmp(a, "--dense-jac")) {
        c->sim.dense_jac = true;
        return 1;
    }
    static const char* const with_value[] = {"--model", "--scenario", "--mechanics", "--variant", "--solver",
                                             "--dt", "--rtol", "--atol", "--duration", "--every",
                                             "--set", "--jac-every", "--load", "--world", "--dt-ode", "--kernel", NULL};
    int k = -1;
    for (int j = 0; with_value[j]; ++j)
        if (!strcmp(a, with_value[j])) k = j;
    if (k < 0) return 0;
    if (need_value(argc, argv, *i)) return -1;
    const char* v = argv[++*i];
    double d;
    switch (k) {
    case 0: c->model_path = v; break;
    case 1: c->scenario_path = v; break;
    case 2: if (app_set_mechanics(&c->sim, a, v)) return -1; break;
    case 3: if (app_set_variant(&c->sim, a, v)) return -1; break;
    case 4: if (app_set_solver(&c->sim, a, v)) return -1; break;
    case 5: if (positive(a, v, &c->sim.h)) return -1; break;
    case 6: if (positive(a, v, &c->sim.rtol)) return -1; break;
    case 7: if (positive(a, v, &c->sim.atol)) return -1; break;
    case 8: if (positive(a, v, &c->sim.duration)) return -1; break;
    case 9: if (positive(a, v, &c->sim.dt_out)) return -1; break;
    case 10:
        if (c->nset == APP_MAX_SET) {
            fprintf(stderr, "cranesim: at most %d --set options\n", APP_MAX_SET);
            return -1;
        }
        if (!strchr(v, '=')) {
            fprintf(stderr, "cranesim: --set: expected path=value, got '%s'\n", v);
            return -1;
        }
        c->sets[c->nset++] = v;
        break;
    case 11:
        if (app_parse_double(v, &d) || d < 1 || d != floor(d)) {
            fprintf(stderr, "cranesim: --jac-every: expected a whole number >= 1, got '%s'\n", v);
            return -1;
        }
        c->sim.jac_every = (int)d;
        break;
    case 12:
        if (app_parse_double(v, &d) || d < 0 || d > 1e5) {
            fprintf(stderr, "cranesim: --load: expected a mass in kg (0..100000), got '%s'\n", v);
            return -1;
        }
        c->sim.load_mass = d;
        break;
    case 13: c->sim.world = v; break;
    case 14: if (positive(a, v, &c->sim.dt_ode)) return -1; break;
    case 15:
        if (strcmp(v, "split") && strcmp(v, "fused") && strcmp(v, "general")) {
            fprintf(stderr, "cranesim: --kernel: expected split, fused or general, got '%s'\n", v);
            return -1;
        }
        c->sim.general_kernel = !strcmp(v, "general");
        c->sim.whole_step = !strcmp(v, "fused");
        break;
    }
    return 1;
}

void app_common_help(FILE* f, bool with_solver) {
    fprintf(f,
            "  --model FILE         crane model JSON (default: assets/models/hiab031.json)\n"
            "  --scenario S         scenario JSON file, or a name in assets/scenarios (e.g. ramp)\n"
            "  --set PATH=VALUE     override any model value, e.g. --set mechanics.load_mass=800\n"
            "                       or --set hydraulics.components.lift_cyl.bore=0.11 (repeatable)\n"
            "  --load KG            tip load [kg] (default: the scenario's, else the model's)\n"
            "  --mechanics M        lagrange (analytic 2-DOF, default) or ode\n"
            "  --variant V          lagrange equations: full (default), paper, paper-typo\n"
            "  --world W            ode: world file or name: validation (default for run), sandbox\n"
            "  --dt-ode H           ode: rigid-body step [s] (default 1e-3; hydraulics sub-step at --dt)\n");
    if (with_solver)
        fprintf(f,
                "  --solver S           krus (default), ros2, rk4, ros34pw2, rodas3, cvode (SUNDIALS BDF)\n"
                "  --dt H               fixed step [s] (default 1e-4)\n"
                "  --rtol R, --atol A   adaptive tolerances (default 1e-3, 1e-6)\n"
                "  --jac-every N        fixed-step: new Jacobian every N steps (default 10)\n"
                "  --dense-jac          fixed-step: dense Jacobian instead of the block pattern\n"
                "  --kernel K           lagrange, when the circuit has the standard shape:\n"
                "                       split (default): one-pass circuit, block-eliminated W, and\n"
                "                         for krus/ros2 the mechanics once per step (docs/lagrange.md);\n"
                "                       fused: the same, but f in full at every Krus/ROS2 stage;\n"
                "                       general: the component loops and the solver's own sparse LU;\n"
                "                       with --mechanics ode, split and fused both mean the one-pass\n"
                "                         circuit in the hydraulic sub-steps, general the loops\n"
                "  --duration T         simulated time [s] (default: the scenario's)\n"
                "  --every DT           output period [s] (default 1e-3, i.e. 1 kHz)\n");
    fprintf(f, "  --quiet              no progress bar or summary\n");
}

const char* app_scenario_path(const char* arg, char* buf, size_t n) {
    // A path if it looks like one or is a readable file; else a name in the
    // assets (a folder called "step" in the working directory is not a file).
    struct stat st;
    bool file = stat(arg, &st) == 0 && S_ISREG(st.st_mode);
    if (file || strchr(arg, '/') || strstr(arg, ".json")) return arg;
    snprintf(buf, n, "%s/scenarios/%s.json", model_assets_dir(), arg);
    return buf;
}

int app_load(const app_common* c, model** m, scenario* sc) {
    char err[1024];
    const int rc = app_load_msg(c, m, sc, err, sizeof err);
    if (rc) fprintf(stderr, "cranesim: %s\n", err);
    return rc;
}

int app_load_msg(const app_common* c, model** m, scenario* sc, char* err, size_t errsz) {
    *m = model_load(c->model_path, c->sets, c->nset, err, errsz);
    if (!*m) return EXIT_USAGE;
    char buf[512];
    const char* arg = c->scenario_path ? c->scenario_path : "ramp";
    const char* sp = app_scenario_path(arg, buf, sizeof buf);
    if (sp == buf && access(sp, R_OK) != 0) {
        // A name that is not in the assets: say which names there are.
        char names[512] = "";
        char dir[512];
        snprintf(dir, sizeof dir, "%s/scenarios", model_assets_dir());
        DIR* d = opendir(dir);
        for (struct dirent* e; d && (e = readdir(d));) {
            size_t L = strlen(e->d_name);
            if (L < 6 || strcmp(e->d_name + L - 5, ".json")) continue;
            size_t k = strlen(names);
            snprintf(names + k, sizeof names - k, "%s%.*s", k ? ", " : "", (int)(L - 5), e->d_name);
        }
        if (d) closedir(d);
        snprintf(err, errsz, "--scenario %s: no such file or scenario (scenarios: %s)", arg, names);
        model_free(*m);
        *m = NULL;
        return EXIT_USAGE;
    }
    if (scenario_load(sp, sc, err, errsz)) {
        model_free(*m);
        *m = NULL;
        return EXIT_USAGE;
    }
    return 0;
}

void app_scripted_input(const scenario* sc, live* l, double tm, int* ev, double u[3],
                        void (*on_hook)(void* user, live* l, int attach, int got), void* user) {
    for (int k = 0; k < 3; ++k) u[k] = scenario_command(sc, k, tm);
    for (; *ev < sc->nevent && sc->event[*ev].t <= tm; ++*ev) {
        const int attach = sc->event[*ev].kind == SCENARIO_ATTACH;
        const int got = live_hook(l, attach);
        if (on_hook) on_hook(user, l, attach, got);
    }
}

void app_progress(void* user, double t, double t_end) {
    (void)user;
    if (!isatty(2)) return;
    const int width = 40;
    double f = t_end > 0 ? t / t_end : 1.0;
    if (f > 1) f = 1;
    int n = (int)(f * width + 0.5);
    fprintf(stderr, "\r  [%.*s%*s] %5.1f %%  t = %.2f / %.2f s", n,
            "########################################", width - n, "", 100.0 * f, t, t_end);
    fflush(stderr);
}

void app_progress_done(void) {
    if (isatty(2)) fprintf(stderr, "\r%*s\r", 78, "");
}
