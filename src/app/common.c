// common.c: option parsing and loading shared by the subcommands.
// realpath (X/Open) for app_out_open.
#define _XOPEN_SOURCE 700
#include "app.h"
#include "engine.h"
#include "world_desc.h"

#include <ctype.h>
#include <limits.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

int app_parse_double(const char* s, double* v) {
    // Decimal or scientific notation only: strtod also takes hex ("0x10" is
    // 16), "inf", "nan" and leading blanks, none of which a user means as a
    // step, a tolerance or a mass.
    const char* p = s;
    if (*p == '+' || *p == '-') ++p;
    bool digits = false;
    for (; isdigit((unsigned char)*p); ++p) digits = true;
    if (*p == '.')
        for (++p; isdigit((unsigned char)*p); ++p) digits = true;
    if (!digits) return -1;
    if (*p == 'e' || *p == 'E') {
        ++p;
        if (*p == '+' || *p == '-') ++p;
        if (!isdigit((unsigned char)*p)) return -1;
        while (isdigit((unsigned char)*p)) ++p;
    }
    if (*p) return -1;
    char* end;
    errno = 0;
    double x = strtod(s, &end);
    if (errno || *end || !isfinite(x)) return -1;
    *v = x;
    return 0;
}

const char* const app_opt_name[APP_OPT_COUNT] = {
    "--model", "--scenario", "--mechanics", "--variant", "--solver", "--dt", "--rtol", "--atol", "--duration",
    "--every", "--set", "--jac-every", "--load", "--world", "--dt-ode", "--kernel", "--dense-jac", "--quiet"};

// A value that is itself an option name ("--out --quiet") is a missing
// value: a file called "--quiet" is never what was meant.
static bool missing_value(int argc, char** argv, int i) {
    return i + 1 >= argc || !strncmp(argv[i + 1], "--", 2);
}

const char* app_value(int argc, char** argv, int* i) {
    if (missing_value(argc, argv, *i)) {
        fprintf(stderr, "cranesim: option %s needs a value (see --help)\n", argv[*i]);
        return NULL;
    }
    return argv[++*i];
}

// Each command's own options that take a value (the common ones are
// app_opt_name up to --kernel).
static const struct {
    const char* cmd;
    const char* opts[10];
} own_values[] = {
    {"run", {"--out", "--plot", NULL}},
    {"compare", {"--backends", "--solvers", "--variants", "--dts", "--tol-stroke", "--tol-pressure", "--plot", NULL}},
    {"study", {"--out-dir", "--repeat", NULL}},
    {"bench", {"--repeat", "--config", "--seed", NULL}},
    {"drive",
     {"--record", "--charts", "--mapping", "--screenshot", "--screenshot-at", "--size", "--frame-rate", "--save-as", NULL}},
};

int app_check_values(const char* cmd, int argc, char** argv) {
    const char* const* own = NULL;
    for (size_t k = 0; k < sizeof own_values / sizeof own_values[0]; ++k)
        if (!strcmp(cmd, own_values[k].cmd)) own = own_values[k].opts;
    for (int i = 0; i < argc; ++i) {
        const char* a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) return 0; // the command prints its help
        bool takes = false;
        for (int k = 0; k <= APP_OPT_KERNEL && !takes; ++k) takes = !strcmp(a, app_opt_name[k]);
        for (int k = 0; own && own[k] && !takes; ++k) takes = !strcmp(a, own[k]);
        if (!takes) continue;
        if (missing_value(argc, argv, i)) {
            fprintf(stderr, "cranesim %s: option %s needs a value (see cranesim %s --help)\n", cmd, a, cmd);
            return EXIT_USAGE;
        }
        ++i;
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
        c->given |= APP_GIVEN(APP_OPT_QUIET);
        return 1;
    }
    if (!strcmp(a, "--dense-jac")) {
        c->sim.dense_jac = true;
        c->given |= APP_GIVEN(APP_OPT_DENSE_JAC);
        return 1;
    }
    int k = -1;
    for (int j = 0; j <= APP_OPT_KERNEL; ++j)
        if (!strcmp(a, app_opt_name[j])) k = j;
    if (k < 0) return 0;
    const char* v = app_value(argc, argv, i);
    if (!v) return -1;
    c->given |= APP_GIVEN(k);
    double d;
    switch ((enum app_opt)k) {
    case APP_OPT_MODEL: c->model_path = v; break;
    case APP_OPT_SCENARIO: c->scenario_path = v; break;
    case APP_OPT_MECHANICS: if (app_set_mechanics(&c->sim, a, v)) return -1; break;
    case APP_OPT_VARIANT: if (app_set_variant(&c->sim, a, v)) return -1; break;
    case APP_OPT_SOLVER: if (app_set_solver(&c->sim, a, v)) return -1; break;
    case APP_OPT_DT: if (positive(a, v, &c->sim.h)) return -1; break;
    case APP_OPT_RTOL: if (positive(a, v, &c->sim.rtol)) return -1; break;
    case APP_OPT_ATOL: if (positive(a, v, &c->sim.atol)) return -1; break;
    case APP_OPT_DURATION:
    case APP_OPT_EVERY:
        // Capped before anything counts steps or rows in integers from them
        // (1e300 s made the run count wrap and exit 0 having simulated nothing).
        if (app_parse_double(v, &d) || !(d > 0) || d > SIM_MAX_DURATION) {
            fprintf(stderr, "cranesim: %s: expected %s in s, 0 < %s <= 1e6 (11.6 days), got '%s'\n", a,
                    k == APP_OPT_DURATION ? "a simulated time" : "an output period",
                    k == APP_OPT_DURATION ? "T" : "DT", v);
            return -1;
        }
        if (k == APP_OPT_DURATION) c->sim.duration = d;
        else c->sim.dt_out = d;
        break;
    case APP_OPT_SET:
        if (c->nset == APP_MAX_SET) {
            fprintf(stderr, "cranesim: at most %d --set options\n", APP_MAX_SET);
            return -1;
        }
        if (!strchr(v, '=')) {
            fprintf(stderr, "cranesim: --set '%s': expected PATH=VALUE\n", v);
            return -1;
        }
        c->sets[c->nset++] = v;
        break;
    case APP_OPT_JAC_EVERY:
        // Range-checked before the conversion: (int)4294967296.0 is undefined
        // and wrapped to 0 on this machine. A million steps (100 s at 0.1 ms)
        // is already "never" for any run we make.
        if (app_parse_double(v, &d) || d < 1 || d > 1e6 || d != floor(d)) {
            fprintf(stderr, "cranesim: --jac-every: expected a whole number of steps 1..1000000, got '%s'\n", v);
            return -1;
        }
        c->sim.jac_every = (int)d;
        break;
    case APP_OPT_LOAD:
        // The model's tip-load range (crane_model.h): 100 t on this crane
        // peaked at 1.05 GPa and still exited 0.
        if (app_parse_double(v, &d) || !(d >= 0 && d <= CRANE_LOAD_MAX)) {
            fprintf(stderr, "cranesim: --load: expected a mass in [0, %g] kg, got '%s'\n", CRANE_LOAD_MAX, v);
            return -1;
        }
        if (d > CRANE_LOAD_TYPICAL)
            fprintf(stderr, "cranesim: note: --load %g kg is outside the typical range [0, %g] kg (the port reliefs "
                            "of a HIAB-031-class crane open near 3000 kg)\n",
                    d, CRANE_LOAD_TYPICAL);
        c->sim.load_mass = d;
        break;
    case APP_OPT_WORLD: c->sim.world = v; break;
    case APP_OPT_DT_ODE: if (positive(a, v, &c->sim.dt_ode)) return -1; break;
    case APP_OPT_KERNEL:
        if (strcmp(v, "split") && strcmp(v, "fused") && strcmp(v, "general")) {
            fprintf(stderr, "cranesim: --kernel: expected split, fused or general, got '%s'\n", v);
            return -1;
        }
        c->sim.general_kernel = !strcmp(v, "general");
        c->sim.whole_step = !strcmp(v, "fused");
        break;
    default: break;
    }
    return 1;
}

// The common options' help, one entry per option (some span lines).
static const struct {
    int opt;
    const char* text;
} common_help[] = {
    {APP_OPT_MODEL, "  --model FILE         crane model JSON (default: assets/models/hiab031.json)\n"},
    {APP_OPT_SCENARIO, "  --scenario S         scenario JSON file, or a name in assets/scenarios (default ramp)\n"},
    {APP_OPT_SET, "  --set PATH=VALUE     override any model value (repeatable), e.g.\n"
                  "                       --set mechanics.links[0].mass=200 or\n"
                  "                       --set hydraulics.components.lift_cyl.bore=0.11\n"},
    {APP_OPT_LOAD, "  --load KG            tip load [kg] (default: the scenario's, else the model's;\n"
                   "                       a --set of mechanics.load_mass counts only when neither sets one);\n"
                   "                       not with the sandbox world, whose loads are world objects\n"},
    {APP_OPT_MECHANICS, "  --mechanics M        lagrange (analytic 2-DOF, default) or ode\n"},
    {APP_OPT_VARIANT, "  --variant V          lagrange equations: full (default), paper, paper-typo\n"},
    {APP_OPT_WORLD, "  --world W            ode: world file or name: validation (default for run), sandbox\n"},
    {APP_OPT_DT_ODE, "  --dt-ode H           ode: rigid-body step [s] (default 1e-3); the hydraulics sub-step\n"
                     "                       there is min(--dt, --dt-ode) and must divide it\n"},
    {APP_OPT_SOLVER, "  --solver S           fixed step: krus (default), ros2, rk4; adaptive: ros34pw2,\n"
                     "                       rodas3, cvode (SUNDIALS BDF; --mechanics lagrange only)\n"},
    {APP_OPT_DT, "  --dt H               fixed step [s] (default 1e-4)\n"},
    {APP_OPT_RTOL, "  --rtol R, --atol A   adaptive tolerances (default 1e-3, 1e-6)\n"},
    {APP_OPT_JAC_EVERY, "  --jac-every N        fixed-step: new Jacobian every N steps (1..1000000, default 10)\n"},
    {APP_OPT_DENSE_JAC, "  --dense-jac          fixed-step: dense Jacobian instead of the block pattern\n"},
    {APP_OPT_KERNEL, "  --kernel K           lagrange, when the circuit has the standard shape:\n"
                     "                       split (default): one-pass circuit, block-eliminated W, and\n"
                     "                         for krus/ros2 the mechanics once per step (docs/lagrange.md);\n"
                     "                       fused: the same, but f in full at every Krus/ROS2 stage;\n"
                     "                       general: the component loops and the solver's own sparse LU;\n"
                     "                       with --mechanics ode, split and fused both mean the one-pass\n"
                     "                         circuit in the hydraulic sub-steps, general the loops\n"},
    {APP_OPT_DURATION, "  --duration T         simulated time [s] (default: the scenario's)\n"},
    {APP_OPT_EVERY, "  --every DT           output period [s] (default 1e-3, i.e. 1 kHz); with a fixed-step\n"
                    "                       solver a whole multiple of --dt (a longer --dt: one row per step),\n"
                    "                       with ode a whole multiple of --dt-ode\n"},
    {APP_OPT_QUIET, "  --quiet              no progress bar or summary (notes and errors still go to stderr)\n"},
};

void app_options_help(FILE* f, unsigned which) {
    for (size_t k = 0; k < sizeof common_help / sizeof common_help[0]; ++k)
        if (which & APP_GIVEN(common_help[k].opt)) fputs(common_help[k].text, f);
}

void app_common_help(FILE* f, bool with_solver) {
    unsigned all = APP_GIVEN(APP_OPT_COUNT) - 1u;
    const unsigned solver = APP_GIVEN(APP_OPT_SOLVER) | APP_GIVEN(APP_OPT_DT) | APP_GIVEN(APP_OPT_RTOL) |
                            APP_GIVEN(APP_OPT_JAC_EVERY) | APP_GIVEN(APP_OPT_DENSE_JAC) |
                            APP_GIVEN(APP_OPT_KERNEL) | APP_GIVEN(APP_OPT_DURATION) | APP_GIVEN(APP_OPT_EVERY);
    app_options_help(f, with_solver ? all : all & ~solver);
}

int app_fclose_checked(FILE* f, int first) {
    int e = first;
    const int flagged = ferror(f);
    errno = 0;
    if (fflush(f) != 0 && !e) e = errno ? errno : EIO;
    errno = 0;
    if (fclose(f) != 0 && !e) e = errno ? errno : EIO;
    if (flagged && !e) e = EIO;
    return e;
}

FILE* app_out_open(app_out* o, const char* path, const char* mode) {
    memset(o, 0, sizeof *o);
    struct stat st;
    const bool exists = stat(path, &st) == 0;
    if (exists && !S_ISREG(st.st_mode)) { // a device or a pipe: in place
        snprintf(o->path, sizeof o->path, "%s", path);
        o->f = fopen(path, mode);
        return o->f;
    }
    // Through a symlink to the file it names: renaming over the link itself
    // would replace the link with a file.
    char real[PATH_MAX];
    const char* target = exists && realpath(path, real) ? real : path;
    if (strlen(target) >= sizeof o->path) {
        errno = ENAMETOOLONG;
        return NULL;
    }
    memcpy(o->path, target, strlen(target) + 1); // fits: checked above
    const char* slash = strrchr(o->path, '/');
    const int dl = slash ? (int)(slash - o->path + 1) : 0;
    snprintf(o->tmp, sizeof o->tmp, "%.*s.%s.XXXXXX", dl, o->path, o->path + dl);
    const int fd = mkstemp(o->tmp);
    if (fd < 0) {
        // A folder we may not create files in, holding a file we may write:
        // write it in place, as before (app_check_output let it through).
        const int e = errno;
        o->tmp[0] = 0;
        if (exists && access(o->path, W_OK) == 0) {
            o->f = fopen(o->path, mode);
            return o->f;
        }
        errno = e;
        return NULL;
    }
    // mkstemp makes it 0600: give it the mode the old file had, or a new
    // file's (0666 less the umask).
    mode_t mode_bits;
    if (exists) {
        mode_bits = st.st_mode & 07777;
    } else {
        const mode_t um = umask(0);
        umask(um);
        mode_bits = 0666 & ~um;
    }
    if (fchmod(fd, mode_bits)) { /* the data matters more than the mode */
    }
    o->f = fdopen(fd, mode);
    if (!o->f) {
        const int e = errno;
        close(fd);
        unlink(o->tmp);
        o->tmp[0] = 0;
        errno = e;
    }
    return o->f;
}

int app_out_close(app_out* o, int first, bool keep) {
    int e = first;
    if (o->f) e = app_fclose_checked(o->f, first);
    o->f = NULL;
    if (o->tmp[0]) {
        if (keep && !e && rename(o->tmp, o->path)) e = errno;
        if (!keep || e) unlink(o->tmp);
        o->tmp[0] = 0;
    }
    return e;
}

int app_out_commit_signal(const app_out* o) { return o->tmp[0] ? rename(o->tmp, o->path) : 0; }

int app_check_output(const char* cmd, const char* opt, const char* path, const char* ext) {
    if (!*path) {
        fprintf(stderr, "cranesim %s: %s: empty file name\n", cmd, opt);
        return -1;
    }
    struct stat st;
    const bool exists = stat(path, &st) == 0;
    if (exists && S_ISDIR(st.st_mode)) {
        fprintf(stderr, "cranesim %s: %s %s: is a directory\n", cmd, opt, path);
        return -1;
    }
    // A device or a pipe (/dev/stdout, /dev/null) takes whatever is written;
    // a file named x.jpg holding PNG data would mislead every viewer.
    const size_t L = strlen(path), le = ext ? strlen(ext) : 0;
    if (ext && !(exists && !S_ISREG(st.st_mode)) && (L <= le || strcasecmp(path + L - le, ext))) {
        fprintf(stderr, "cranesim %s: %s %s: the file is written as %s, so its name must end in %s\n", cmd, opt,
                path, ext + 1, ext);
        return -1;
    }
    if (exists) {
        if (access(path, W_OK)) {
            fprintf(stderr, "cranesim %s: %s %s: cannot write: %s\n", cmd, opt, path, strerror(errno));
            return -1;
        }
        return 0;
    }
    char dir[1024];
    const char* slash = strrchr(path, '/');
    if (!slash) snprintf(dir, sizeof dir, ".");
    else if (slash == path) snprintf(dir, sizeof dir, "/");
    else snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "cranesim %s: %s %s: no directory %s\n", cmd, opt, path, dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "cranesim %s: %s %s: cannot create a file in %s: %s\n", cmd, opt, path, dir,
                strerror(errno));
        return -1;
    }
    return 0;
}

int app_make_dir(const char* cmd, const char* opt, const char* dir) {
    char buf[1024];
    if (!*dir) {
        fprintf(stderr, "cranesim %s: %s: empty directory name\n", cmd, opt);
        return -1;
    }
    if (strlen(dir) >= sizeof buf) {
        fprintf(stderr, "cranesim %s: %s: directory name too long\n", cmd, opt);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", dir);
    // mkdir -p: each prefix ending before a '/', then the whole path.
    for (char* p = buf + 1;; ++p) {
        if (*p && *p != '/') continue;
        const char keep = *p;
        *p = 0;
        struct stat st;
        if (mkdir(buf, 0755) && errno != EEXIST) {
            fprintf(stderr, "cranesim %s: %s %s: cannot create %s: %s\n", cmd, opt, dir, buf, strerror(errno));
            return -1;
        }
        if (stat(buf, &st) || !S_ISDIR(st.st_mode)) {
            fprintf(stderr, "cranesim %s: %s %s: %s exists and is not a directory\n", cmd, opt, dir, buf);
            return -1;
        }
        *p = keep;
        if (!keep) break;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "cranesim %s: %s %s: cannot write into it: %s\n", cmd, opt, dir, strerror(errno));
        return -1;
    }
    return 0;
}

static bool is_adaptive(const sim_opts* o) { return o->cvode || hyd_method_is_adaptive(o->solver); }
static const char* solver_name(const sim_opts* o) { return o->cvode ? "cvode" : hyd_method_name(o->solver); }

// The kind of the ode world o runs on (WORLD_VALIDATION, WORLD_SANDBOX), or
// -1 with the loader's message in err.
static int world_kind_of(const sim_opts* o, char* err, size_t errsz) {
    char buf[512];
    world_desc wd;
    if (world_desc_load(sim_world_path(o->world, buf, sizeof buf), &wd, err, errsz)) return -1;
    const int kind = (int)wd.kind;
    world_desc_free(&wd);
    return kind;
}

// |a / b - round(a / b)| within 1e-9 relative: a is a whole multiple of b.
static bool whole_multiple(double a, double b) {
    const double r = a / b;
    return fabs(r - floor(r + 0.5)) <= 1e-9 * r;
}

double app_output_period(const sim_opts* o) {
    if (o->mechanics == SIM_ODE) {
        const double n = floor(o->dt_out / o->dt_ode + 0.5);
        return (n < 1 ? 1 : n) * o->dt_ode;
    }
    if (!is_adaptive(o) && o->h > o->dt_out) return o->h;
    return o->dt_out;
}

int app_check_sim(const char* cmd, const sim_opts* o, unsigned given) {
    if (o->cvode && !sim_have_cvode()) {
        fprintf(stderr, "cranesim %s: --solver cvode: this build has no CVODE (install libsundials-dev and rebuild)\n",
                cmd);
        return EXIT_USAGE;
    }
    if (o->cvode && o->mechanics == SIM_ODE) {
        fprintf(stderr,
                "cranesim %s: --solver cvode works with --mechanics lagrange only (the ode world steps its hydraulics "
                "inside each ODE step): use krus, ros2, rk4, ros34pw2 or rodas3\n",
                cmd);
        return EXIT_USAGE;
    }
    // Fixed steps land on every output time: an output period that is not a
    // whole number of steps would shorten steps (more steps, more LUs and
    // different results than the --dt asked for); the ode world writes rows
    // at whole ODE steps only. A step longer than the period gives one row
    // per step (decision 7).
    const bool ode = o->mechanics == SIM_ODE;
    const double step = ode ? o->dt_ode : o->h;
    if ((ode || !is_adaptive(o)) && o->dt_out > step && !whole_multiple(o->dt_out, step)) {
        const double lo = floor(o->dt_out / step) * step, hi = lo + step;
        const bool given_every = given & APP_GIVEN(APP_OPT_EVERY);
        fprintf(stderr,
                "cranesim %s: %s %g s is not a whole multiple of %s %g s (%s): use --every %g or %g%s\n", cmd,
                given_every ? "--every" : "the default output period --every", o->dt_out,
                ode ? "the ODE step --dt-ode" : "the fixed step --dt", step,
                ode ? "rows come at whole ODE steps" : "the solver would shorten steps to land on the output times",
                lo, hi, given_every ? "" : ode ? ", or a --dt-ode that divides it" : ", or a --dt that divides it");
        return EXIT_USAGE;
    }
    if (ode && (given & APP_GIVEN(APP_OPT_LOAD))) {
        char err[512];
        const int kind = world_kind_of(o, err, sizeof err);
        if (kind < 0) {
            fprintf(stderr, "cranesim %s: %s\n", cmd, err);
            return EXIT_USAGE;
        }
        if (kind == WORLD_SANDBOX) {
            fprintf(stderr,
                    "cranesim %s: --load: the sandbox world's loads are objects of the world file (loads[].mass); "
                    "--load sets the tip load of lagrange and the validation world\n",
                    cmd);
            return EXIT_USAGE;
        }
    }
    return 0;
}

void app_settle_unused(sim_opts* o) {
    if (o->mechanics == SIM_ODE && is_adaptive(o)) o->h = o->dt_ode;
}

void app_note_unused(const char* cmd, unsigned given, const sim_opts* o, int n) {
    // Each rule: the option, and why a run does not use it (NULL: it does).
    for (int opt = 0; opt < APP_OPT_COUNT; ++opt) {
        if (!(given & APP_GIVEN(opt))) continue;
        const char* why = NULL;
        char buf[160];
        for (int s = 0; s < n; ++s) {
            const sim_opts* r = &o[s];
            const char* w = NULL;
            switch (opt) {
            case APP_OPT_DT:
                if (is_adaptive(r)) {
                    snprintf(buf, sizeof buf, "with the adaptive solver %s (steps from --rtol/--atol)", solver_name(r));
                    w = buf;
                }
                break;
            case APP_OPT_RTOL:
            case APP_OPT_ATOL:
                if (!is_adaptive(r)) {
                    snprintf(buf, sizeof buf, "with the fixed-step solver %s (steps of --dt)", solver_name(r));
                    w = buf;
                }
                break;
            case APP_OPT_JAC_EVERY:
            case APP_OPT_DENSE_JAC:
                if (is_adaptive(r)) {
                    snprintf(buf, sizeof buf, "with the adaptive solver %s (fixed-step solvers only)", solver_name(r));
                    w = buf;
                } else if (r->solver == HYD_RK4) {
                    w = "with rk4 (an explicit method: no Jacobian)";
                }
                break;
            case APP_OPT_WORLD:
            case APP_OPT_DT_ODE:
                if (r->mechanics == SIM_LAGRANGE) w = "with --mechanics lagrange (ode only)";
                break;
            case APP_OPT_VARIANT:
                if (r->mechanics == SIM_ODE) w = "with --mechanics ode (the Lagrange equations are lagrange's)";
                break;
            default: break;
            }
            if (!w) { // this run uses the option
                why = NULL;
                break;
            }
            why = w;
        }
        if (why) fprintf(stderr, "cranesim %s: note: %s has no effect %s%s\n", cmd, app_opt_name[opt], why,
                         n > 1 ? " in both runs" : "");
    }
}

void app_note_load(const char* cmd, const app_common* c, const sim_opts* o, const scenario* sc) {
    const char* set = NULL;
    static const char path[] = "mechanics.load_mass=";
    for (int i = 0; i < c->nset; ++i)
        if (!strncmp(c->sets[i], path, sizeof path - 1)) set = c->sets[i];
    char err[512];
    // A scenario written for the tip load (overload, hold) run in the
    // sandbox: its load_mass does not apply there either.
    if (!set && sc->load_mass >= 0 && o->mechanics == SIM_ODE && world_kind_of(o, err, sizeof err) == WORLD_SANDBOX)
        fprintf(stderr,
                "cranesim %s: note: scenario %s's load_mass (%g kg) has no effect: the sandbox world's loads are "
                "world objects\n",
                cmd, sc->name, sc->load_mass);
    if (!set) return;
    const char* v = set + sizeof path - 1;
    if (o->mechanics == SIM_ODE && world_kind_of(o, err, sizeof err) == WORLD_SANDBOX)
        fprintf(stderr, "cranesim %s: note: --set %s has no effect: the sandbox world's loads are world objects\n", cmd,
                set);
    else if (o->load_mass >= 0)
        fprintf(stderr, "cranesim %s: note: --set %s has no effect: --load %g kg sets the tip load\n", cmd, set,
                o->load_mass);
    else if (sc->load_mass >= 0)
        fprintf(stderr,
                "cranesim %s: note: --set %s has no effect: scenario %s sets its own load (%g kg); use --load %s\n",
                cmd, set, sc->name, sc->load_mass, v);
}

// What in a scenario needs the sandbox (NULL: nothing): the slew, the hook.
static const char* sandbox_use(const scenario* sc) {
    if (sc->nevent > 0) return "works the hook";
    const scenario_signal* sl = &sc->cmd[2];
    for (int i = 0; i < sl->n; ++i)
        if (sl->u[i] != 0) return "slews the crane";
    return sc->slew0 != 0 ? "starts slewed" : NULL;
}

int app_scenario_world(const char* cmd, sim_opts* o, unsigned given, const scenario* sc, bool may_switch,
                       bool* switched) {
    if (switched) *switched = false;
    const char* why = sandbox_use(sc);
    if (!why) return 0;
    char err[512];
    if (o->mechanics == SIM_ODE) {
        const int kind = world_kind_of(o, err, sizeof err);
        if (kind == WORLD_SANDBOX) return 0;
        // A world file that does not load is the first thing wrong: say that,
        // not that the scenario needs another world.
        if (kind < 0) {
            fprintf(stderr, "cranesim %s: %s\n", cmd, err);
            return EXIT_USAGE;
        }
    }
    const char* name = sc->name[0] ? sc->name : "the scenario";
    // No world chosen (--world), and no backend or the ode one: its world.
    if (may_switch && !(given & APP_GIVEN(APP_OPT_WORLD)) &&
        (!(given & APP_GIVEN(APP_OPT_MECHANICS)) || o->mechanics == SIM_ODE)) {
        o->mechanics = SIM_ODE;
        o->world = "sandbox";
        if (switched) *switched = true;
        fprintf(stderr, "cranesim %s: note: scenario %s %s: it runs in its world, --mechanics ode --world sandbox\n",
                cmd, name, why);
        return 0;
    }
    fprintf(stderr,
            "cranesim %s: scenario %s %s, which the %s has not: run it with --mechanics ode --world sandbox\n", cmd,
            name, why, o->mechanics == SIM_ODE ? "validation world" : "lagrange 2-DOF crane");
    return EXIT_USAGE;
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

int app_exit_code(int status, long rows) {
    if (status == SIM_OK) return EXIT_OK_;
    if (status == SIM_FAILED || rows > 0) return EXIT_RUNTIME;
    return EXIT_USAGE;
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

// The signal number, set by the handler and read by the loops between rows.
static volatile sig_atomic_t g_signal;

static void on_signal(int sig) { g_signal = sig; }

void app_signals_catch(app_signals* s) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sa.sa_flags = SA_RESETHAND;
    sigemptyset(&sa.sa_mask);
    g_signal = 0;
    sigaction(SIGINT, &sa, &s->old_int);
    sigaction(SIGTERM, &sa, &s->old_term);
}

void app_signals_restore(const app_signals* s) {
    sigaction(SIGINT, &s->old_int, NULL);
    sigaction(SIGTERM, &s->old_term, NULL);
}

int app_signal_caught(void) { return g_signal; }

const char* app_signal_name(int sig) { return sig == SIGINT ? "SIGINT" : "SIGTERM"; }
