// cmd_optimize.c: `cranesim optimize`: a derivative-free search (NLopt:
// BOBYQA without constraints, COBYLA with them) over model paths for the
// design that minimises a run metric (or a design value itself) subject to
// bounds on other metrics. Each evaluation is one headless run of the
// scenario, its metrics from metrics.c, as `cranesim sweep` computes them.
#include "app.h"
#include "app_design_metrics.h"
#include "energy_acc.h"
#include "json_util.h"
#include "metrics.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef CRANESIM_HAVE_NLOPT
#include <nlopt.h>
#endif

enum { OPT_MAXPAR = APP_MAX_PARAM, OPT_MAXCON = 8, OPT_MAXEVAL = 100000 };

static void optimize_help(FILE* f) {
    fprintf(f,
            "usage: cranesim optimize [--scenario S] [--model M] --param PATH=LO:HI [--param ...]\n"
            "                         --minimize METRIC|PATH [--constraint METRIC<=V ...]\n"
            "                         [--maxeval N] [--xtol X] [--out best_model.json] [--plot conv.png] [options]\n"
            "\n"
            "Searches the box of the --param ranges for the design that minimises METRIC (a run\n"
            "metric, as in cranesim sweep --metrics) or PATH (one of the --param values: \"the\n"
            "smallest bore that ...\"), subject to the constraints, with NLopt's derivative-free\n"
            "methods: COBYLA when there are constraints, else BOBYQA. One run of the scenario per\n"
            "evaluation, a progress line each. A design that fails (a blow-up, a refused value)\n"
            "counts as infeasible. Prints the best feasible design and writes the model with its\n"
            "values set, and the convergence plot. docs/optimize.md has the details.\n"
            "\n"
            "options:\n"
            "  --param PATH=LO:HI     a model path (the --set syntax, a number) and its bounds (up to %d)\n"
            "  --minimize M           the objective: a metric name, or a --param PATH; 'M[UNIT]'\n"
            "                         reports a metric in UNIT (default the run summary's unit); a\n"
            "                         crane chain model adds its metrics by actuator and function,\n"
            "                         named as run --metrics names them ('peak_pA.lift<=6MPa',\n"
            "                         'stroke_max.ext1<=1200mm', max_spool.ext; docs/sweep.md)\n"
            "  --constraint 'M<=V'    a bound on a metric, V with its unit: 'peak_p1A<=24MPa' (or\n"
            "                         24e6Pa, 240bar), deg/rad, kJ/J, m/mm, s/ms, kN/N; a count takes\n"
            "                         a plain number (also M>=V; up to %d; quoted: < and > are shell\n"
            "                         redirections)\n"
            "  --maxeval N            most evaluations (default 60)\n"
            "  --xtol X               stop when a step changes every parameter by less than X of its\n"
            "                         range (default 1e-4)\n"
            "  --out FILE             the best design's model file (default best_model.json)\n"
            "  --plot FILE.png        the objective at each evaluation and the best so far\n",
            OPT_MAXPAR, OPT_MAXCON);
    fprintf(f, "metrics:");
    int col = 999;
    for (int id = 0; id < MET_COUNT; ++id) {
        char tok[96];
        char lab[80];
        snprintf(tok, sizeof tok, " %s%s", app_metric_label(id, lab, sizeof lab), id + 1 < MET_COUNT ? "," : "");
        if (col + (int)strlen(tok) > 92) col = fprintf(f, "\n  ");
        col += fprintf(f, "%s", tok);
    }
    fprintf(f, "\n");
    app_common_help(f, true);
    fprintf(f,
            "\nexit codes: 0 done, 1 no feasible design found, NLopt failed or a failed write, 2 bad input\n"
            "(nothing is written), 130 or 143 interrupted (nothing written)\n"
            "example: cranesim optimize --scenario hold --param hydraulics.components.lift_cyl.bore=0.06:0.14 \\\n"
            "           --minimize hydraulics.components.lift_cyl.bore --constraint 'peak_p1A<=20MPa'\n");
}

typedef struct opt_con {
    int met;      ///< metric_id
    double bound; ///< V [SI: metric_unit]
    bool ge;      ///< M >= V (else M <= V)
} opt_con;

typedef struct optimizer {
    app_common c;
    model* base;
    scenario sc;
    app_range par[OPT_MAXPAR];
    int npar;
    int obj_met;  ///< metric_id of the objective, or -1: the design value obj_par
    int obj_par;
    const char* obj_unit; ///< the unit the objective metric is reported in
    double obj_scale;     ///< reported = SI * obj_scale
    opt_con con[OPT_MAXCON];
    int ncon;
    int ncol;
    bool energy;  ///< a metric needs the energy accounting
    long maxeval;
    // The evaluations so far.
    long neval;
    double* f;      ///< (maxeval) objective [its unit], NaN for a failed design
    bool* feas;     ///< (maxeval)
    double* xs;     ///< (maxeval x npar) design values
    long best;      ///< index of the best feasible evaluation, -1 none
    double fscale;  ///< the objective's scale for the optimiser (the first finite |f|)
    bool failed_eval;
    char last_err[512];
} optimizer;

static void quiet_note(const char* line, void* user) {
    (void)line;
    (void)user;
}

#ifdef CRANESIM_HAVE_NLOPT
// Everything from here to run_nlopt is the search; a build without NLopt
// has the command's parsing and checks only.
static const char* short_path(const char* p) {
    // The last two parts of a long path ("lift_cyl.bore"), for the progress lines.
    const char* a = strrchr(p, '.');
    if (!a || a == p) return p;
    const char* b = a - 1;
    while (b > p && *b != '.') --b;
    return *b == '.' ? b + 1 : b;
}

// One run of design v: 0 with the metrics in *dr (run metrics and, on a
// crane chain, its by actuator and function: app_design_metrics.h), or the
// exit code the run would have (1 failed, 2 refused) with its message in err.
// dr is the caller's to free (app_design_run_free) either way.
static int run_design(const optimizer* o, const double* v, app_design_run* dr, char* err, size_t errsz) {
    app_design_run_init(dr, o->base, o->ncol);
    cJSON* doc = cJSON_Duplicate(o->base->json, 1);
    if (!doc) {
        snprintf(err, errsz, "out of memory");
        return EXIT_RUNTIME;
    }
    for (int k = 0; k < o->npar; ++k) {
        char asg[320], num[40];
        snprintf(asg, sizeof asg, "%s=%s", o->par[k].path, app_fmt_double(num, sizeof num, v[k]));
        if (json_set_path(doc, asg, err, errsz)) {
            cJSON_Delete(doc);
            return EXIT_USAGE;
        }
    }
    model* m = model_from_json(doc, o->base->file, err, errsz); // owns doc, also on failure
    if (!m) return EXIT_USAGE;
    sim_energy* en = o->energy ? sim_energy_create() : NULL;
    sim_result res;
    dr->chain = &m->chain; // the run's own (with the slewing run's rack) from its first row
    sim_run_energy_chain(m, &o->sc, &o->c.sim, app_design_row, dr, NULL, NULL, NULL, en, &dr->chain, &res);
    model_free(m);
    dr->chain = NULL;
    metrics_finish(&dr->met, &res);
    if (en) metrics_energy(&dr->met, en);
    sim_energy_free(en);
    if (res.status != SIM_OK) {
        snprintf(err, errsz, "%s", res.message);
        return res.status == SIM_FAILED ? EXIT_RUNTIME : EXIT_USAGE;
    }
    if (dr->oom) {
        snprintf(err, errsz, "out of memory");
        return EXIT_RUNTIME;
    }
    return 0;
}

// The design values of the optimiser's unit box point u (each parameter
// scaled to [0, 1] over its range, so every direction has the same scale).
static void design_of(const optimizer* o, const double* u, double* v) {
    for (int k = 0; k < o->npar; ++k) {
        const app_range* p = &o->par[k];
        v[k] = p->lo + (p->hi - p->lo) * fmin(1.0, fmax(0.0, u[k]));
    }
}

// Evaluate unit point u: the objective (scaled) and the constraints
// (scaled, <= 0 when met) for NLopt; the evaluation is recorded.
static double evaluate(optimizer* o, const double* u, double* cval) {
    double v[OPT_MAXPAR];
    design_of(o, u, v);
    const long e = o->neval;
    app_design_run dr;
    char err[1024] = "";
    const int code = run_design(o, v, &dr, err, sizeof err);
    memcpy(o->xs + (size_t)e * (size_t)o->npar, v, (size_t)o->npar * sizeof *v);
    double f = NAN;
    bool feas = code == 0;
    if (code == 0) {
        f = o->obj_met >= 0 ? app_design_value(&dr, o->obj_met) : v[o->obj_par];
        for (int j = 0; j < o->ncon; ++j) {
            const opt_con* c = &o->con[j];
            const double x = app_design_value(&dr, c->met);
            // Relative to the bound, so constraints of any unit weigh alike.
            const double scale = c->bound != 0.0 ? fabs(c->bound) : 1.0;
            cval[j] = (c->ge ? c->bound - x : x - c->bound) / scale;
            if (cval[j] > 0) feas = false;
        }
    } else {
        snprintf(o->last_err, sizeof o->last_err, "%s", err);
        o->failed_eval = true;
    }
    o->f[e] = f;
    o->feas[e] = feas;
    ++o->neval;
    if (feas && (o->best < 0 || f < o->f[o->best])) o->best = e;
    if (isfinite(f) && !(o->fscale > 0)) o->fscale = fabs(f) > 0 ? fabs(f) : 1.0;
    if (!o->c.quiet) {
        printf("optimize: eval %ld:", e + 1);
        for (int k = 0; k < o->npar; ++k) printf(" %s=%.6g", short_path(o->par[k].path), v[k]);
        if (code) {
            printf(" -> failed (exit %d): %s\n", code, err);
        } else {
            // The objective when it is a metric (a design value is on the line already).
            printf(" ->");
            // In the summary's units (the objective in its report unit).
            if (o->obj_met >= 0)
                printf(" %s %.6g %s%s", app_design_metric_name(o->obj_met), f * o->obj_scale, o->obj_unit,
                       o->ncon ? "," : "");
            for (int j = 0; j < o->ncon; ++j) {
                const int cm = o->con[j].met;
                printf(" %s %.6g %s%s", app_design_metric_name(cm), app_design_value(&dr, cm) * app_metric_disp_scale(cm),
                       app_metric_disp_unit(cm), j + 1 < o->ncon ? "," : "");
            }
            printf("%s\n", feas ? "" : " (infeasible)");
        }
        fflush(stdout);
    }
    app_design_run_free(&dr);
    if (code) {
        // A failed design is infeasible: every constraint violated by a
        // margin, and (BOBYQA, no constraints) an objective above anything
        // seen, so the search turns away from it instead of stopping.
        double worst = 0.0;
        bool any = false;
        for (long k = 0; k < o->neval; ++k)
            if (isfinite(o->f[k])) worst = any ? fmax(worst, o->f[k]) : o->f[k], any = true;
        for (int j = 0; j < o->ncon; ++j) cval[j] = 1.0;
        const double sc = o->fscale > 0 ? o->fscale : 1.0;
        return any ? worst / sc + 1.0 : 1.0;
    }
    return f / (o->fscale > 0 ? o->fscale : 1.0);
}

typedef struct nl_user {
    optimizer* o;
    nlopt_opt opt;
    double cval[OPT_MAXCON]; ///< the constraints of the last evaluation
    double cx[OPT_MAXPAR];   ///< its point
    bool have_c;
} nl_user;

static double nl_objective(unsigned n, const double* u, double* grad, void* data) {
    (void)grad; // derivative-free methods only
    nl_user* w = data;
    optimizer* o = w->o;
    if (app_signal_caught() || o->neval >= o->maxeval) {
        nlopt_force_stop(w->opt);
        return HUGE_VAL;
    }
    const double f = evaluate(o, u, w->cval);
    memcpy(w->cx, u, n * sizeof *u);
    w->have_c = true;
    return f;
}

// NLopt asks for the constraints at the point it just evaluated the
// objective at (COBYLA does); else run the design again.
static void nl_constraints(unsigned m, double* result, unsigned n, const double* u, double* grad, void* data) {
    (void)grad;
    nl_user* w = data;
    if (!w->have_c || memcmp(w->cx, u, n * sizeof *u)) {
        double scratch[OPT_MAXCON];
        if (app_signal_caught() || w->o->neval >= w->o->maxeval) {
            nlopt_force_stop(w->opt);
            for (unsigned j = 0; j < m; ++j) result[j] = 1.0;
            return;
        }
        evaluate(w->o, u, scratch);
        memcpy(w->cval, scratch, sizeof scratch);
        memcpy(w->cx, u, n * sizeof *u);
        w->have_c = true;
    }
    memcpy(result, w->cval, m * sizeof *result);
}

static int run_nlopt(optimizer* o, double xtol, const char** method, char* err, size_t errsz) {
    const unsigned n = (unsigned)o->npar;
    nlopt_opt opt = nlopt_create(o->ncon > 0 ? NLOPT_LN_COBYLA : NLOPT_LN_BOBYQA, n);
    if (!opt) {
        snprintf(err, errsz, "NLopt could not be set up");
        return -1;
    }
    *method = o->ncon > 0 ? "COBYLA" : "BOBYQA";
    nl_user w = {.o = o, .opt = opt};
    double lb[OPT_MAXPAR], ub[OPT_MAXPAR], u[OPT_MAXPAR], step[OPT_MAXPAR], tol[OPT_MAXCON];
    for (unsigned k = 0; k < n; ++k) {
        // A fixed parameter (LO = HI) is a box of zero width, which NLopt holds.
        const bool fixed = o->par[k].lo == o->par[k].hi;
        lb[k] = 0.0;
        ub[k] = fixed ? 0.0 : 1.0;
        u[k] = fixed ? 0.0 : 0.5;  // the middle of the box
        step[k] = fixed ? 0.0 : 0.25; // a quarter of the range: the first steps sample the box broadly
    }
    for (int j = 0; j < o->ncon; ++j) tol[j] = 0.0;
    nlopt_set_lower_bounds(opt, lb);
    nlopt_set_upper_bounds(opt, ub);
    nlopt_set_initial_step(opt, step);
    nlopt_set_min_objective(opt, nl_objective, &w);
    if (o->ncon > 0) nlopt_add_inequality_mconstraint(opt, (unsigned)o->ncon, nl_constraints, &w, tol);
    nlopt_set_xtol_abs1(opt, xtol);
    nlopt_set_maxeval(opt, (int)o->maxeval);
    double fmin;
    const nlopt_result r = nlopt_optimize(opt, u, &fmin);
    nlopt_destroy(opt);
    if (r < 0 && r != NLOPT_FORCED_STOP && r != NLOPT_ROUNDOFF_LIMITED) {
        snprintf(err, errsz, "NLopt stopped with error %d (%s)", (int)r, nlopt_result_to_string(r));
        return -1;
    }
    return 0;
}
#endif

// Every number of the document as its shortest round-trip text: cJSON
// prints a value that 15 digits do not carry with 17 (0.081531047980044041
// for 0.08153104798004404), so the design values read as typed, and back
// equal. 0, or -1 out of memory.
static int shortest_numbers(cJSON* node) {
    for (cJSON* c = node->child; c; c = c->next) {
        if (cJSON_IsNumber(c) && isfinite(c->valuedouble)) {
            char num[40];
            // The node becomes raw text in place (its key and siblings kept);
            // the text is allocated by cJSON, which frees it with the node.
            cJSON* raw = cJSON_CreateRaw(app_fmt_double(num, sizeof num, c->valuedouble));
            if (!raw) return -1;
            c->type = cJSON_Raw | (c->type & cJSON_StringIsConst);
            c->valuestring = raw->valuestring;
            raw->valuestring = NULL;
            cJSON_Delete(raw);
        } else if (shortest_numbers(c)) {
            return -1;
        }
    }
    return 0;
}

// Write the model with the best design's values to path (temporary file
// renamed over it). 0, or an errno.
static int write_model(const optimizer* o, const double* v, const char* path) {
    cJSON* doc = cJSON_Duplicate(o->base->json, 1);
    if (!doc) return ENOMEM;
    char err[512];
    for (int k = 0; k < o->npar; ++k) {
        char asg[320], num[40];
        snprintf(asg, sizeof asg, "%s=%s", o->par[k].path, app_fmt_double(num, sizeof num, v[k]));
        if (json_set_path(doc, asg, err, sizeof err)) {
            cJSON_Delete(doc);
            return EINVAL;
        }
    }
    char* text = shortest_numbers(doc) ? NULL : cJSON_Print(doc);
    cJSON_Delete(doc);
    if (!text) return ENOMEM;
    app_out out;
    FILE* f = app_out_open(&out, path, "w");
    int e = f ? 0 : errno;
    if (f && (fputs(text, f) < 0 || fputc('\n', f) < 0)) e = errno ? errno : EIO;
    free(text);
    if (f) e = app_out_close(&out, e, true);
    return e;
}

// "METRIC<=V" or "METRIC>=V". 0, or -1 after one line.
static int parse_constraint(const char* arg, int ncol, opt_con* c) {
    const char* op = strstr(arg, "<=");
    const char* op2 = strstr(arg, ">=");
    if (!op || (op2 && op2 < op)) op = op2;
    if (!op || op == arg) {
        fprintf(stderr, "cranesim optimize: --constraint '%s': expected METRIC<=V or METRIC>=V\n", arg);
        return -1;
    }
    char name[96];
    snprintf(name, sizeof name, "%.*s", (int)(op - arg), arg);
    const int id = app_design_metric_find(name);
    if (id < 0) {
        char names[2048];
        app_design_metric_names(names, sizeof names);
        fprintf(stderr, "cranesim optimize: --constraint: unknown metric '%s' (metrics: %s)\n", name, names);
        return -1;
    }
    if (!app_design_metric_present(id, ncol)) {
        fprintf(stderr, "cranesim optimize: --constraint: this run has no %s (the ode world's channels)\n", name);
        return -1;
    }
    char err[256];
    if (app_metric_parse_value(id, op + 2, &c->bound, err, sizeof err)) {
        fprintf(stderr, "cranesim optimize: --constraint '%s': %s\n", arg, err);
        return -1;
    }
    c->met = id;
    c->ge = op[0] == '>';
    return 0;
}

int cmd_optimize(int argc, char** argv) {
    optimizer o = {.c = {.sim = sim_default_opts()}, .obj_met = -1, .obj_par = -1, .maxeval = 60, .best = -1};
    app_design_opts d = {.out = "best_model.json"};
    const char* minimize = NULL;
    const char* cons[OPT_MAXCON];
    int ncons = 0;
    double xtol = 1e-4;
    for (int i = 0; i < argc; ++i) {
        const char* a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            optimize_help(stdout);
            return 0;
        }
        int rc = app_parse_common(&o.c, argc, argv, &i);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        rc = app_parse_design_opt("optimize", argc, argv, &i, &d);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        const bool known = !strcmp(a, "--minimize") || !strcmp(a, "--constraint") || !strcmp(a, "--maxeval") ||
                           !strcmp(a, "--xtol");
        if (!known) {
            fprintf(stderr, "cranesim optimize: unknown option '%s' (see cranesim optimize --help)\n", a);
            return EXIT_USAGE;
        }
        const char* v = app_value(argc, argv, &i);
        if (!v) return EXIT_USAGE;
        if (!strcmp(a, "--constraint")) {
            if (ncons == OPT_MAXCON) {
                fprintf(stderr, "cranesim optimize: at most %d --constraint\n", OPT_MAXCON);
                return EXIT_USAGE;
            }
            cons[ncons++] = v;
        } else if (!strcmp(a, "--minimize")) {
            minimize = v;
        } else if (!strcmp(a, "--xtol")) {
            if (app_parse_double(v, &xtol) || !(xtol > 0 && xtol < 1)) {
                fprintf(stderr, "cranesim optimize: --xtol must be in (0, 1) (a share of each range), got '%s'\n", v);
                return EXIT_USAGE;
            }
        } else {
            char* end;
            errno = 0;
            const long n = strtol(v, &end, 10);
            if (!*v || *end || errno || n < 1 || n > OPT_MAXEVAL) {
                fprintf(stderr, "cranesim optimize: --maxeval must be a whole number in [1, %d], got '%s'\n",
                        OPT_MAXEVAL, v);
                return EXIT_USAGE;
            }
            o.maxeval = n;
        }
    }
    o.npar = d.nparam;
    const char* const* params = d.param;
    const char* out = d.out;
    const char* plot = d.plot;
    if (o.npar == 0) {
        fprintf(stderr, "cranesim optimize: give at least one --param PATH=LO:HI (see cranesim optimize --help)\n");
        return EXIT_USAGE;
    }
    if (!minimize) {
        fprintf(stderr, "cranesim optimize: give --minimize METRIC or --minimize PATH (see cranesim optimize --help)\n");
        return EXIT_USAGE;
    }
    for (int k = 0; k < o.npar; ++k) {
        if (app_parse_range("optimize", params[k], false, &o.par[k])) return EXIT_USAGE;
        for (int j = 0; j < k; ++j)
            if (!strcmp(o.par[j].path, o.par[k].path)) {
                fprintf(stderr, "cranesim optimize: --param %s given twice\n", o.par[k].path);
                return EXIT_USAGE;
            }
    }
    if (app_check_output("optimize", "--out", out, ".json") || (plot && app_check_output("optimize", "--plot", plot, ".png")) ||
        app_check_distinct("optimize", (const char* const[]){"--out", "--plot"}, (const char* const[]){out, plot}, 2))
        return EXIT_USAGE;
    int rc = app_check_sim("optimize", &o.c.sim, o.c.given);
    if (rc) return rc;
    rc = app_load(&o.c, &o.base, &o.sc);
    if (rc) return rc;
    bool switched;
    rc = app_scenario_world("optimize", &o.c.sim, o.c.given, o.base, &o.sc, true, &switched);
    if (!rc && switched) rc = app_check_sim("optimize", &o.c.sim, o.c.given);
    o.ncol = sim_ncol(&o.c.sim);
    // A chain model's metrics by actuator and function, by name (app_design_metrics.h).
    if (!rc && app_design_metrics_setup(o.base)) {
        fprintf(stderr, "cranesim optimize: out of memory\n");
        rc = EXIT_RUNTIME;
    }
    // Every path must name a number in the model: a typo is bad input.
    for (int k = 0; k < o.npar && !rc; ++k) {
        cJSON* doc = cJSON_Duplicate(o.base->json, 1);
        char asg[320], num[40], err[1024];
        snprintf(asg, sizeof asg, "%s=%s", o.par[k].path, app_fmt_double(num, sizeof num, o.par[k].lo));
        if (!doc || json_set_path(doc, asg, err, sizeof err)) {
            fprintf(stderr, "cranesim optimize: --param %s: %s\n", o.par[k].path, doc ? err : "out of memory");
            rc = EXIT_USAGE;
        }
        cJSON_Delete(doc);
    }
    char objmet[96] = "";
    const char* objunit_arg = NULL;
    if (!rc) {
        // "METRIC[UNIT]": the metric, reported in UNIT.
        const char* br = strchr(minimize, '[');
        const size_t L = strlen(minimize);
        if (br && br > minimize && L > 0 && minimize[L - 1] == ']' && (size_t)(br - minimize) < sizeof objmet) {
            // (A prefix that is no metric leaves it to the path lookup: a
            // model path may end in an index.)
            snprintf(objmet, sizeof objmet, "%.*s", (int)(br - minimize), minimize);
            o.obj_met = app_design_metric_find(objmet);
            static char unit[32];
            snprintf(unit, sizeof unit, "%.*s", (int)(L - 1 - (size_t)(br - minimize) - 1), br + 1);
            if (o.obj_met >= 0) objunit_arg = unit;
        }
    }
    if (!rc && objunit_arg) {
        double si;
        char err[256];
        if (app_metric_unit_scale(o.obj_met, objunit_arg, &si, err, sizeof err)) {
            fprintf(stderr, "cranesim optimize: --minimize '%s': %s\n", minimize, err);
            rc = EXIT_USAGE;
        } else {
            o.obj_unit = objunit_arg;
            o.obj_scale = 1.0 / si;
        }
    }
    if (!rc && !objunit_arg) {
        o.obj_met = app_design_metric_find(minimize);
        for (int k = 0; k < o.npar && o.obj_met < 0; ++k)
            if (!strcmp(minimize, o.par[k].path)) o.obj_par = k;
        if (o.obj_met < 0 && o.obj_par < 0) {
            char names[2048];
            app_design_metric_names(names, sizeof names);
            fprintf(stderr, "cranesim optimize: --minimize: '%s' is neither a metric (%s) nor a --param path\n",
                    minimize, names);
            rc = EXIT_USAGE;
        } else if (o.obj_met >= 0) {
            o.obj_unit = app_metric_disp_unit(o.obj_met);
            o.obj_scale = app_metric_disp_scale(o.obj_met);
        }
    }
    if (!rc && o.obj_met >= 0) {
        if (!app_design_metric_present(o.obj_met, o.ncol)) {
            fprintf(stderr, "cranesim optimize: --minimize: this run has no %s (the ode world's channels)\n", minimize);
            rc = EXIT_USAGE;
        }
    }
    for (int j = 0; j < ncons && !rc; ++j) rc = parse_constraint(cons[j], o.ncol, &o.con[o.ncon++]) ? EXIT_USAGE : 0;
    if (!rc) {
        o.energy = o.obj_met == MET_ENERGY_IN || o.obj_met == MET_ENERGY_LOSS;
        for (int j = 0; j < o.ncon; ++j) o.energy |= o.con[j].met == MET_ENERGY_IN || o.con[j].met == MET_ENERGY_LOSS;
    }
#ifndef CRANESIM_HAVE_NLOPT
    if (!rc) {
        fprintf(stderr, "cranesim optimize: this cranesim is built without NLopt (install libnlopt-dev, "
                        "scripts/deps.sh, and rebuild)\n");
        rc = EXIT_USAGE;
    }
#endif
    if (rc) {
        model_free(o.base);
        return rc;
    }
    app_note_unused("optimize", o.c.given, &o.c.sim, 1);
    app_settle_unused(&o.c.sim);
    o.f = malloc((size_t)o.maxeval * sizeof *o.f);
    o.feas = malloc((size_t)o.maxeval * sizeof *o.feas);
    o.xs = malloc((size_t)o.maxeval * (size_t)o.npar * sizeof *o.xs);
    if (!o.f || !o.feas || !o.xs) {
        fprintf(stderr, "cranesim optimize: out of memory\n");
        free(o.f), free(o.feas), free(o.xs);
        model_free(o.base);
        return EXIT_RUNTIME;
    }
    void* note_user;
    hyd_note_fn old_note = hyd_get_note_handler(&note_user);
    hyd_set_note_handler(quiet_note, NULL);
    app_signals sig;
    app_signals_catch(&sig);
    const char* method = "?";
    int code = EXIT_OK_;
#ifdef CRANESIM_HAVE_NLOPT
    char err[512] = "";
    if (run_nlopt(&o, xtol, &method, err, sizeof err)) {
        fprintf(stderr, "cranesim optimize: %s\n", err);
        code = EXIT_RUNTIME;
    }
#else
    (void)xtol;
#endif
    app_signals_restore(&sig);
    hyd_set_note_handler(old_note, note_user);
    const char* objname = o.obj_met >= 0 ? app_design_metric_name(o.obj_met) : o.par[o.obj_par].path;
    const char* objunit = o.obj_met >= 0 ? o.obj_unit : "";
    const double objscale = o.obj_met >= 0 ? o.obj_scale : 1.0;
    if (app_signal_caught()) {
        fprintf(stderr, "cranesim optimize: interrupted (%s) after %ld evaluations; nothing written\n",
                app_signal_name(app_signal_caught()), o.neval);
        code = 128 + app_signal_caught();
    } else if (!code && o.best < 0) {
        fprintf(stderr, "cranesim optimize: no feasible design in %ld evaluations%s%s; nothing written\n", o.neval,
                o.failed_eval ? " (last failure: " : "", o.failed_eval ? o.last_err : "");
        if (o.failed_eval) fprintf(stderr, ")\n");
        code = EXIT_RUNTIME;
    }
    if (!code) {
        const double* v = o.xs + (size_t)o.best * (size_t)o.npar;
        printf("cranesim optimize: %s, %s, %ld evaluations; best feasible design (evaluation %ld):\n",
               o.sc.name[0] ? o.sc.name : o.c.scenario_path, method, o.neval, o.best + 1);
        for (int k = 0; k < o.npar; ++k) printf("  %s = %.9g\n", o.par[k].path, v[k]);
        if (o.obj_met >= 0) printf("  %s = %.9g %s\n", objname, o.f[o.best] * objscale, objunit);
        const int e = write_model(&o, v, out);
        if (e) {
            fprintf(stderr, "cranesim optimize: cannot write %s: %s\n", out, strerror(e));
            code = EXIT_RUNTIME;
        } else {
            printf("  model -> %s\n", out);
        }
    }
    if (plot && o.neval > 0 && code != EXIT_USAGE && !app_signal_caught()) {
        char perr[512], title[256], ylab[160];
        snprintf(title, sizeof title, "%s: %s", o.sc.name, method);
        snprintf(ylab, sizeof ylab, "%s%s%s%s", objname, objunit[0] ? " [" : "", objunit, objunit[0] ? "]" : "");
        // The objective in its report unit (o.f is not read after the plot).
        for (long k = 0; k < o.neval; ++k) o.f[k] *= objscale;
        if (app_plot_convergence(plot, title, ylab, o.f, o.feas, o.neval, perr, sizeof perr)) {
            fprintf(stderr, "cranesim optimize: plot: %s\n", perr);
            if (code == EXIT_OK_) code = EXIT_RUNTIME;
        } else if (!o.c.quiet) {
            printf("  plot -> %s\n", plot);
        }
    }
    free(o.f), free(o.feas), free(o.xs);
    model_free(o.base);
    return code;
}
