// app_options.c: the command line: the options common to the subcommands
// (parsing, values, help) and their value words (mechanics, variant, solver).
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
    "--every", "--set", "--jac-every", "--load", "--world", "--dt-ode", "--kernel", "--dense-jac", "--no-retry",
    "--no-step-probe", "--quiet"};

void app_name_params(void) {
    static const char* names[SIM_PARAM_COUNT];
    names[SIM_PARAM_DT] = app_opt_name[APP_OPT_DT];
    names[SIM_PARAM_DT_ODE] = app_opt_name[APP_OPT_DT_ODE];
    names[SIM_PARAM_DURATION] = app_opt_name[APP_OPT_DURATION];
    names[SIM_PARAM_EVERY] = app_opt_name[APP_OPT_EVERY];
    names[SIM_PARAM_LOAD] = app_opt_name[APP_OPT_LOAD];
    names[SIM_PARAM_MECHANICS] = app_opt_name[APP_OPT_MECHANICS];
    names[SIM_PARAM_RTOL] = app_opt_name[APP_OPT_RTOL];
    names[SIM_PARAM_SET] = app_opt_name[APP_OPT_SET];
    names[SIM_PARAM_WORLD] = app_opt_name[APP_OPT_WORLD];
    names[SIM_PARAM_MODEL] = app_opt_name[APP_OPT_MODEL];
    names[SIM_PARAM_NO_STEP_PROBE] = app_opt_name[APP_OPT_NO_STEP_PROBE];
    sim_name_params(names);
}

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
    const char* opts[16];
} own_values[] = {
    {"run", {"--out", "--plot", "--metrics", "--energy", "--rcl", NULL}},
    {"loadchart", {"--margin", "--stability-factor", "--outreach", "--sectors", "--out", "--plot", NULL}},
    {"sweep", {"--param", "--lhs", "--seed", "--metrics", "--threads", "--out", "--plot", NULL}},
    {"optimize", {"--param", "--minimize", "--constraint", "--maxeval", "--xtol", "--out", "--plot", NULL}},
    {"compare", {"--backends", "--solvers", "--variants", "--dts", "--tol-stroke", "--tol-pressure", "--plot",
                 "--set-a", "--set-b", "--out", NULL}},
    {"replay", {"--out", "--metrics", "--plot", "--rcl", NULL}},
    {"study", {"--out-dir", "--repeat", "--only", NULL}},
    {"bench", {"--repeat", "--config", "--seed", NULL}},
    {"drive",
     {"--record", "--charts", "--mapping", "--screenshot", "--screenshot-at", "--size", "--frame-rate", "--save-as",
      "--readouts", "--session", "--replay", "--rcl", "--connect", NULL}},
    {"serve", {"--listen", "--rate", "--max-clients", "--queue", "--timeout", "--rcl", "--spin", NULL}},
};

// The value options a command documents as repeatable (each use adds one);
// "*": every command. Any other value option given twice is refused: the
// last value used to win silently (--dt 1e-5 --dt 1e-4 ran at 1e-4).
static const struct {
    const char* cmd;
    const char* opts[4];
} repeatable[] = {
    {"*", {"--set", NULL}},
    {"sweep", {"--param", NULL}},
    {"optimize", {"--param", "--constraint", NULL}},
    {"compare", {"--model", "--set-a", "--set-b", NULL}}, // --model: design A's and B's
    {"bench", {"--config", NULL}},
    {"study", {"--only", NULL}},
};

static bool is_repeatable(const char* cmd, const char* a) {
    for (size_t k = 0; k < sizeof repeatable / sizeof repeatable[0]; ++k) {
        if (strcmp(repeatable[k].cmd, "*") && strcmp(repeatable[k].cmd, cmd)) continue;
        for (int j = 0; repeatable[k].opts[j]; ++j)
            if (!strcmp(repeatable[k].opts[j], a)) return true;
    }
    return false;
}

// Each command's flags (options without a value). A flag may also be given
// as --flag=1|true (the flag) or --flag=0|false (as if not given): scripts
// write flags that way, and "--quiet=1" used to be an unknown option. Every
// flag is off unless given, so =0 is the default. "*": every command that
// parses the common options (all but replay, which has --quiet only).
static const struct {
    const char* cmd;
    const char* opts[6];
} own_flags[] = {
    {"*", {"--quiet", "--dense-jac", "--no-retry", "--no-step-probe", NULL}},
    {"study", {"--quick", NULL}},
    {"sweep", {"--fail-fast", NULL}},
    {"drive", {"--headless", "--scripted", "--collision-view", NULL}},
    {"serve", {"--lockstep", "--realtime", "--log-misses", NULL}},
};

// Whether the first len characters of a are a flag of cmd.
static bool is_flag(const char* cmd, const char* a, size_t len) {
    const bool replay = !strcmp(cmd, "replay");
    if (replay) return len == 7 && !strncmp(a, "--quiet", 7);
    for (size_t k = 0; k < sizeof own_flags / sizeof own_flags[0]; ++k) {
        if (strcmp(own_flags[k].cmd, "*") && strcmp(own_flags[k].cmd, cmd)) continue;
        for (int j = 0; own_flags[k].opts[j]; ++j)
            if (strlen(own_flags[k].opts[j]) == len && !strncmp(a, own_flags[k].opts[j], len)) return true;
    }
    return false;
}

// 1 for "1"/"true", 0 for "0"/"false", -1 for anything else.
static int flag_word(const char* v) {
    if (!strcmp(v, "1") || !strcmp(v, "true")) return 1;
    if (!strcmp(v, "0") || !strcmp(v, "false")) return 0;
    return -1;
}

int app_check_values(const char* cmd, int argc, char** argv) {
    const char* const* own = NULL;
    for (size_t k = 0; k < sizeof own_values / sizeof own_values[0]; ++k)
        if (!strcmp(cmd, own_values[k].cmd)) own = own_values[k].opts;
    for (int i = 0; i < argc; ++i) {
        const char* a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) return 0; // the command prints its help
        const char* eq = strncmp(a, "--", 2) ? NULL : strchr(a, '=');
        if (eq && is_flag(cmd, a, (size_t)(eq - a))) {
            // app_split_equals took 1/true/0/false; this is another word.
            fprintf(stderr, "cranesim %s: %.*s takes no value (or 1, 0, true, false), got '%s'\n", cmd,
                    (int)(eq - a), a, eq + 1);
            return EXIT_USAGE;
        }
        bool takes = false;
        for (int k = 0; k <= APP_OPT_KERNEL && !takes; ++k) takes = !strcmp(a, app_opt_name[k]);
        for (int k = 0; own && own[k] && !takes; ++k) takes = !strcmp(a, own[k]);
        if (!takes) continue;
        if (missing_value(argc, argv, i)) {
            fprintf(stderr, "cranesim %s: option %s needs a value (see cranesim %s --help)\n", cmd, a, cmd);
            return EXIT_USAGE;
        }
        if (!is_repeatable(cmd, a))
            for (int j = 0; j < i; ++j)
                if (!strcmp(argv[j], a)) {
                    fprintf(stderr, "cranesim %s: option %s given twice (%s, then %s): give it once\n", cmd, a,
                            argv[j + 1], argv[i + 1]);
                    return EXIT_USAGE;
                }
        ++i;
    }
    return 0;
}

// Whether a is an option of cmd that takes a value (common or its own).
static bool takes_value(const char* const* own, const char* a, size_t len) {
    for (int k = 0; k <= APP_OPT_KERNEL; ++k)
        if (strlen(app_opt_name[k]) == len && !strncmp(a, app_opt_name[k], len)) return true;
    for (int k = 0; own && own[k]; ++k)
        if (strlen(own[k]) == len && !strncmp(a, own[k], len)) return true;
    return false;
}

char** app_split_equals(const char* cmd, int* argc, char** argv) {
    const char* const* own = NULL;
    for (size_t k = 0; k < sizeof own_values / sizeof own_values[0]; ++k)
        if (!strcmp(cmd, own_values[k].cmd)) own = own_values[k].opts;
    // At most one extra word per argument, plus the terminating NULL.
    char** out = malloc(sizeof *out * (2 * (size_t)*argc + 1));
    if (!out) return NULL;
    int n = 0;
    bool value_next = false; // argv[i] is the value of the option before it
    for (int i = 0; i < *argc; ++i) {
        char* a = argv[i];
        char* eq = strncmp(a, "--", 2) ? NULL : strchr(a, '=');
        // A value option is split; the value of a value option never is.
        if (!value_next && eq && takes_value(own, a, (size_t)(eq - a))) {
            *eq = 0; // argv's strings are ours to change (C11 5.1.2.2.1)
            out[n++] = a;
            out[n++] = eq + 1;
            continue;
        }
        // A flag with 1/true is the flag, with 0/false it is left out; any
        // other word stays as it is for app_check_values to refuse.
        if (!value_next && eq && is_flag(cmd, a, (size_t)(eq - a)) && flag_word(eq + 1) >= 0) {
            if (flag_word(eq + 1) == 0) continue;
            *eq = 0;
            out[n++] = a;
            continue;
        }
        value_next = !value_next && takes_value(own, a, strlen(a));
        out[n++] = a;
    }
    out[n] = NULL;
    *argc = n;
    return out;
}

static int positive(const char* opt, const char* s, double* v) {
    if (app_parse_double(s, v) || !(*v > 0)) {
        fprintf(stderr, "cranesim: %s: expected a positive number, got '%s'\n", opt, s);
        return -1;
    }
    return 0;
}

const engine_backend* app_backend(const sim_opts* o) {
    const engine_backend* b = engine_backend_of(o);
    if (!b) {
        char known[128];
        fprintf(stderr, "cranesim: internal error: backend %d is none of %s\n", (int)o->mechanics,
                engine_backend_names(known, sizeof known, NULL));
        exit(EXIT_RUNTIME);
    }
    return b;
}

void app_use_backend(sim_opts* o, const engine_backend* b) { o->mechanics = b->id; }

const char* app_default_drive_scenario(const sim_opts* o) { return app_backend(o)->drive_scenario; }

int app_set_mechanics(sim_opts* o, const char* opt, const char* v) {
    char err[256];
    if (engine_backend_select(o, v, err, sizeof err)) {
        fprintf(stderr, "cranesim: %s: %s\n", opt, err);
        return -1;
    }
    return 0;
}

int app_set_variant(sim_opts* o, const char* opt, const char* v) {
    const int var = lagrange_variant_parse(v);
    if (var < 0) {
        fprintf(stderr, "cranesim: %s: expected full, general, paper or paper-typo, got '%s'\n", opt, v);
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
    if (!strcmp(a, "--no-retry")) {
        c->sim.no_retry = 1;
        c->given |= APP_GIVEN(APP_OPT_NO_RETRY);
        return 1;
    }
    if (!strcmp(a, "--no-step-probe")) {
        c->sim.no_step_probe = true;
        c->given |= APP_GIVEN(APP_OPT_NO_STEP_PROBE);
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
        // "fast" and "reference" name the two ends of the one choice.
        if (!strcmp(v, "split") || !strcmp(v, "fast")) c->sim.kernel = SIM_KERNEL_SPLIT;
        else if (!strcmp(v, "fused")) c->sim.kernel = SIM_KERNEL_FUSED;
        else if (!strcmp(v, "general") || !strcmp(v, "reference")) c->sim.kernel = SIM_KERNEL_GENERAL;
        else {
            fprintf(stderr, "cranesim: --kernel: expected split, fused or general, got '%s'\n", v);
            return -1;
        }
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
    {APP_OPT_MODEL, "  --model M            crane model JSON file, or a name in assets/models (default hiab031)\n"},
    {APP_OPT_SCENARIO, "  --scenario S         scenario JSON file, or a name in assets/scenarios (default ramp)\n"},
    {APP_OPT_SET, "  --set PATH=VALUE     override any model value (repeatable), e.g.\n"
                  "                       --set mechanics.links[0].mass=200 or\n"
                  "                       --set hydraulics.components.lift_cyl.bore=0.11\n"},
    {APP_OPT_LOAD, "  --load KG            tip load [kg] (default: the scenario's, else the model's;\n"
                   "                       a --set of mechanics.load_mass counts only when neither sets one);\n"
                   "                       not with the sandbox world, whose loads are world objects\n"},
    {APP_OPT_MECHANICS, NULL}, // from the backend table: mechanics_help
    {APP_OPT_VARIANT, "  --variant V          lagrange equations: full (default), general, paper, paper-typo\n"},
    {APP_OPT_WORLD, "  --world W            ode: world file or name: validation (default for run), sandbox\n"},
    {APP_OPT_DT_ODE, "  --dt-ode H           ode: rigid-body step [s] (default 1e-3); the hydraulics sub-step\n"
                     "                       there is min(--dt, --dt-ode) and must divide it\n"},
    {APP_OPT_SOLVER, "  --solver S           fixed step: krus (default), ros2, rk4; adaptive: ros34pw2,\n"
                     "                       rodas3, cvode (SUNDIALS BDF; --mechanics lagrange only)\n"},
    {APP_OPT_DT, "  --dt H               fixed step [s] (default 1e-4)\n"},
    {APP_OPT_RTOL, "  --rtol R, --atol A   adaptive tolerances (default 1e-3, 1e-6)\n"},
    {APP_OPT_JAC_EVERY, "  --jac-every N        fixed-step: new Jacobian every N steps (1..1000000, default 10)\n"},
    {APP_OPT_DENSE_JAC, "  --dense-jac          fixed-step: dense Jacobian instead of the block pattern\n"},
    {APP_OPT_NO_RETRY, "  --no-retry           fixed-step: report a step that fails (singular W, a non-finite state,\n"
                       "                       a pressure below -0.1 MPa) at once instead of retrying it as\n"
                       "                       2..16 shorter steps (docs/solvers.md)\n"},
    {APP_OPT_NO_STEP_PROBE, "  --no-step-probe      krus/ros2 above 0.1 ms: run the step even where the probe of the\n"
                            "                       model's abrupt valve steps refuses it (it blows up there or is\n"
                            "                       off the 0.1 ms run by more than 5 % in a stroke, 15 % in a\n"
                            "                       pressure); the results are then unchecked (docs/solvers.md)\n"},
    {APP_OPT_KERNEL, "  --kernel K           lagrange, when the circuit has the standard shape:\n"
                     "                       split (default): one-pass circuit, block-eliminated W, and\n"
                     "                         for krus/ros2 the mechanics once per step (docs/lagrange.md);\n"
                     "                       fused: the same, but f in full at every Krus/ROS2 stage;\n"
                     "                       general: the component loops and the solver's own sparse LU;\n"
                     "                       lagrange without that shape: the fast kernel when it has a\n"
                     "                         loop for every component (else the loops), with split also\n"
                     "                         the mechanics once per krus/ros2 step; fused the fast kernel\n"
                     "                         with f in full at every stage; general the loops;\n"
                     "                       with --mechanics ode, split and fused both mean the one-pass\n"
                     "                         circuit in the hydraulic sub-steps (the fast kernel for a\n"
                     "                         circuit without its shape), general the loops;\n"
                     "                       fast = split, reference = general\n"},
    {APP_OPT_DURATION, "  --duration T         simulated time [s] (default: the scenario's)\n"},
    {APP_OPT_EVERY, "  --every DT           output period [s] (default 1e-3, i.e. 1 kHz); with a fixed-step\n"
                    "                       solver a whole multiple of --dt (a longer --dt: one row per step),\n"
                    "                       with ode a whole multiple of --dt-ode\n"},
    {APP_OPT_QUIET, "  --quiet              no progress bar or summary (notes and errors still go to stderr)\n"},
};

// --mechanics: every backend of the table with its phrase, the default
// marked: "lagrange (analytic 2-DOF, default) or ode (3D rigid bodies in a world)".
static void mechanics_help(FILE* f) {
    fputs("  --mechanics M        ", f);
    const int n = engine_backend_count();
    for (int i = 0; i < n; ++i) {
        const engine_backend* b = engine_backend_at(i);
        fprintf(f, "%s%s (%s%s)", i == 0 ? "" : i == n - 1 ? " or " : ", ", b->name, b->help,
                b == engine_backend_default() ? ", default" : "");
    }
    fputc('\n', f);
}

void app_options_help(FILE* f, unsigned which) {
    for (size_t k = 0; k < sizeof common_help / sizeof common_help[0]; ++k) {
        if (!(which & APP_GIVEN(common_help[k].opt))) continue;
        if (common_help[k].opt == APP_OPT_MECHANICS) mechanics_help(f);
        else fputs(common_help[k].text, f);
    }
}

void app_common_help(FILE* f, bool with_solver) {
    unsigned all = APP_GIVEN(APP_OPT_COUNT) - 1u;
    const unsigned solver = APP_GIVEN(APP_OPT_SOLVER) | APP_GIVEN(APP_OPT_DT) | APP_GIVEN(APP_OPT_RTOL) |
                            APP_GIVEN(APP_OPT_JAC_EVERY) | APP_GIVEN(APP_OPT_DENSE_JAC) |
                            APP_GIVEN(APP_OPT_NO_RETRY) |
                            APP_GIVEN(APP_OPT_NO_STEP_PROBE) | APP_GIVEN(APP_OPT_KERNEL) | APP_GIVEN(APP_OPT_DURATION) | APP_GIVEN(APP_OPT_EVERY);
    app_options_help(f, with_solver ? all : all & ~solver);
}

const char* app_fmt_double(char* buf, size_t n, double v) {
    // The shortest of 15, 16, 17 significant digits that reads back to the
    // same double: 0.08 prints as 0.08, not 0.080000000000000002, and every
    // value still round-trips (17 digits always do, IEEE 754 binary64).
    for (int p = 15; p <= 17; ++p) {
        snprintf(buf, n, "%.*g", p, v);
        if (p == 17 || strtod(buf, NULL) == v) break;
    }
    return buf;
}

double app_snap_decimal(double v) {
    if (!isfinite(v) || v == 0) return v;
    char b[32];
    snprintf(b, sizeof b, "%.15g", v);
    const double d = strtod(b, NULL);
    const double ulp = nextafter(fabs(v), INFINITY) - fabs(v);
    return fabs(d - v) <= 4 * ulp ? d : v;
}

const char* app_fmt_speed(char* buf, size_t n, double ratio) {
    // Whole numbers from 1x up (as before); below, two significant digits:
    // a run at 0.42x real time printed "0x".
    if (!(ratio >= 0) || !isfinite(ratio)) snprintf(buf, n, "-");
    else if (ratio >= 1) snprintf(buf, n, "%.0f", ratio);
    else snprintf(buf, n, "%.2g", ratio);
    return buf;
}
