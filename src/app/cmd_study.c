// cmd_study.c: `cranesim study`: the solver study the paper called for.
//
// Runs one scenario with every integrator at several steps or tolerances,
// measures each against a tight-tolerance CVODE (BDF) reference, and writes a
// table (Markdown), JSON lines and a work-precision plot.
#include "app.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef CRANESIM_HAVE_PLPLOT
#include <plplot.h>
#endif

// The common options the study honours. The solver, step, tolerances and
// output grid are the study's own choice per configuration, and its CVODE
// reference runs the lagrange model only, so the rest are refused.
static const unsigned study_opts = APP_GIVEN(APP_OPT_MODEL) | APP_GIVEN(APP_OPT_SCENARIO) | APP_GIVEN(APP_OPT_SET) |
                                   APP_GIVEN(APP_OPT_LOAD) | APP_GIVEN(APP_OPT_VARIANT) |
                                   APP_GIVEN(APP_OPT_DURATION) | APP_GIVEN(APP_OPT_JAC_EVERY) |
                                   APP_GIVEN(APP_OPT_DENSE_JAC) | APP_GIVEN(APP_OPT_KERNEL) | APP_GIVEN(APP_OPT_QUIET);

static void study_help(FILE* f) {
    fprintf(f,
            "usage: cranesim study [--scenario S] [--out-dir DIR] [--repeat N] [--quick] [options]\n"
            "\n"
            "Integrates the scenario (default ramp) with Krus and ROS2 at h = 0.1, 0.2, 0.5, 1 ms,\n"
            "RK4 at 0.1 ms (refused: beyond its stability limit, the table says why) and 0.01 ms,\n"
            "the adaptive ROS34PW2 and RODAS3 at rtol 1e-2, 2e-3, 1e-3, 1e-4, 1e-5, and\n"
            "SUNDIALS CVODE, and compares each with a CVODE reference at rtol 1e-10, on the\n"
            "lagrange model and the 1 ms output grid. Reports per configuration:\n"
            "max and RMS chamber-pressure error [MPa and %% of peak], max stroke error [mm],\n"
            "steps, f evaluations, Jacobians, LU factorisations and median wall time [s].\n"
            "Writes DIR/study.md (table), DIR/study.jsonl and DIR/work_precision.png.\n"
            "\n"
            "options:\n"
            "  --out-dir DIR        default study (created with its parents before the runs)\n"
            "  --repeat N           timed runs per configuration, median reported (1..50, default 3)\n"
            "  --quick              fewer configurations (for tests)\n");
    app_options_help(f, study_opts);
}

typedef struct study_cfg {
    char name[40];
    sim_opts o;
    // results
    int failed;
    char why[512];
    double wall, p_max, p_rms, x_max;
    hyd_solver_stats st;
} study_cfg;

static int add_fixed(study_cfg* c, int n, const sim_opts* base, hyd_method m, double h) {
    c[n].o = *base;
    c[n].o.solver = m;
    c[n].o.h = h;
    snprintf(c[n].name, sizeof c[n].name, "%s h=%gms", hyd_method_name(m), h * 1e3);
    return n + 1;
}

static int add_adaptive(study_cfg* c, int n, const sim_opts* base, hyd_method m, bool cvode, double rtol) {
    c[n].o = *base;
    c[n].o.solver = m;
    c[n].o.cvode = cvode;
    c[n].o.rtol = rtol;
    c[n].o.atol = 1e-6;
    snprintf(c[n].name, sizeof c[n].name, "%s rtol=%g", cvode ? "cvode" : hyd_method_name(m), rtol);
    return n + 1;
}

#ifdef CRANESIM_HAVE_PLPLOT
typedef struct wp_plot {
    const study_cfg* c;
    int n;
    double ppeak; ///< [Pa]
    const char* title;
    double xlo, xhi, ylo, yhi;
} wp_plot;

// x: max pressure error in % of ppeak [Pa]; y: wall time.
static void draw_wp(void* user) {
    const wp_plot* p = user;
    const study_cfg* c = p->c;
    const int n = p->n;
    const double ppeak = p->ppeak;
    plinit();
    plcol0(15);
    plenv(floor(p->xlo - 0.2), ceil(p->xhi + 0.2), floor(p->ylo - 0.2), ceil(p->yhi + 0.3), 0, 30);
    pllab("max chamber-pressure error [% of peak] (log)", "wall time [s] (log)", p->title);
    plschr(0, 0.7);
    static const int col[] = {1, 3, 9, 8, 12, 13};
    // One colour per method family, a line through its points and a legend;
    // each point carries only its step or tolerance, offset per family so
    // neighbouring families (ROS34PW2 and RODAS3 lie on top of each other)
    // keep their labels apart. Offsets in decades of the log axes.
    const char* fam[] = {"krus", "ros2", "rk4", "ros34pw2", "rodas3", "cvode"};
    static const double dx[] = {0.06, 0.06, 0.06, -0.06, 0.06, 0.06};
    static const double dy[] = {-0.07, 0.07, 0.0, -0.03, 0.07, 0.07};
    static const double just[] = {0.0, 0.0, 0.0, 1.0, 0.0, 0.0};
    int shown[6], nshown = 0;
    for (int f = 0; f < 6; ++f) {
        PLFLT xs[16], ys[16];
        const char* lab[16];
        int k = 0;
        const size_t lf = strlen(fam[f]);
        for (int i = 0; i < n && k < 16; ++i) {
            if (c[i].failed || !(c[i].p_max > 0) || !(c[i].wall > 0) || strncmp(c[i].name, fam[f], lf) ||
                c[i].name[lf] != ' ')
                continue;
            xs[k] = log10(100 * c[i].p_max / ppeak);
            ys[k] = log10(c[i].wall);
            lab[k] = c[i].name + lf + 1; // "h=0.1ms", "rtol=0.001"
            ++k;
        }
        if (!k) continue;
        shown[nshown++] = f;
        plcol0(col[f]);
        plline(k, xs, ys);
        plpoin(k, xs, ys, 17);
        // CVODE's loose tolerances bunch up: alternate above and below.
        for (int j = 0; j < k; ++j)
            plptex(xs[j] + dx[f], ys[j] + (f == 5 && j % 2 ? -dy[f] - 0.05 : dy[f]), 1, 0, just[f], lab[j]);
    }
    PLINT opt[6], tcol[6], lcol[6], lsty[6], scol[6], snum[6];
    PLFLT lwid[6], sscale[6];
    const char* text[6];
    const char* sym[6];
    for (int i = 0; i < nshown; ++i) {
        const int f = shown[i];
        opt[i] = PL_LEGEND_LINE | PL_LEGEND_SYMBOL;
        tcol[i] = 15, lcol[i] = scol[i] = col[f], lsty[i] = 1, lwid[i] = 1.0;
        sscale[i] = 1.0, snum[i] = 1, sym[i] = "•";
        text[i] = fam[f];
    }
    PLFLT lw, lh;
    plschr(0, 0.8);
    pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, PL_POSITION_TOP | PL_POSITION_RIGHT | PL_POSITION_INSIDE,
             0.02, 0.02, 0.08, 0, 15, 1, 0, 0, nshown, opt, 1.0, 1.0, 2.0, 0.0, tcol, text, NULL, NULL, NULL, NULL,
             lcol, lsty, lwid, scol, sscale, snum, sym);
}

// The work-precision plot; 1 when no configuration has a point to plot
// (nothing written), 0 when written, -1 with the reason in err.
static int plot_wp(const study_cfg* c, int n, double ppeak, const char* title, const char* png, char* err,
                   size_t errsz) {
    wp_plot p = {c, n, ppeak, title, 1e300, -1e300, 1e300, -1e300};
    for (int i = 0; i < n; ++i) {
        if (c[i].failed || !(c[i].p_max > 0) || !(c[i].wall > 0)) continue;
        double x = log10(100 * c[i].p_max / ppeak), y = log10(c[i].wall);
        p.xlo = fmin(p.xlo, x), p.xhi = fmax(p.xhi, x), p.ylo = fmin(p.ylo, y), p.yhi = fmax(p.yhi, y);
    }
    if (!(p.xhi >= p.xlo)) return 1;
    return app_png_render(png, "1200x850", draw_wp, &p, err, errsz);
}
#endif

// Close a result file, reporting a failed write: "cannot write FILE: reason".
static int close_checked(app_out* o, const char* path) {
    const int e = app_out_close(o, 0, true);
    if (e) fprintf(stderr, "cranesim study: cannot write %s: %s\n", path, strerror(e));
    return e ? -1 : 0;
}

int cmd_study(int argc, char** argv) {
    app_common c = {.sim = sim_default_opts()};
    const char* dir = "study";
    int repeat = 3;
    bool quick = false;
    for (int i = 0; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            study_help(stdout);
            return 0;
        }
        int rc = app_parse_common(&c, argc, argv, &i);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        if (!strcmp(argv[i], "--out-dir")) {
            if (!(dir = app_value(argc, argv, &i))) return EXIT_USAGE;
            continue;
        }
        if (!strcmp(argv[i], "--quick")) {
            quick = true;
            continue;
        }
        if (!strcmp(argv[i], "--repeat")) {
            const char* v = app_value(argc, argv, &i);
            double d;
            if (!v) return EXIT_USAGE;
            if (app_parse_double(v, &d) || d < 1 || d > 50 || d != floor(d)) {
                fprintf(stderr, "cranesim study: --repeat: expected a whole number 1..50, got '%s'\n", v);
                return EXIT_USAGE;
            }
            repeat = (int)d;
            continue;
        }
        fprintf(stderr, "cranesim study: unknown option '%s' (see cranesim study --help)\n", argv[i]);
        return EXIT_USAGE;
    }
    // Refuse, before any run, what the study cannot honour.
    for (int k = 0; k < APP_OPT_COUNT; ++k) {
        if (!(c.given & APP_GIVEN(k)) || (study_opts & APP_GIVEN(k))) continue;
        if (k == APP_OPT_MECHANICS && c.sim.mechanics == SIM_LAGRANGE) continue; // what it runs anyway
        const char* why = k == APP_OPT_MECHANICS || k == APP_OPT_WORLD || k == APP_OPT_DT_ODE
                              ? "the study's CVODE reference runs the lagrange model only"
                          : k == APP_OPT_EVERY ? "the study compares every configuration with the reference on the "
                                                 "1 ms output grid"
                                               : "the study sets the solver, step and tolerances of each "
                                                 "configuration itself";
        if (k == APP_OPT_MECHANICS) fprintf(stderr, "cranesim study: --mechanics ode: %s\n", why);
        else fprintf(stderr, "cranesim study: %s is not an option of study: %s\n", app_opt_name[k], why);
        return EXIT_USAGE;
    }
    if (!sim_have_cvode()) {
        fprintf(stderr, "cranesim study: needs the CVODE reference (install libsundials-dev and rebuild)\n");
        return EXIT_USAGE;
    }
    model* m;
    scenario sc;
    int rc = app_load(&c, &m, &sc);
    if (rc) return rc;
    app_note_load("study", &c, &c.sim, &sc);
    // The output folder exists and takes files before hours of runs.
    char path_md[1024], path_js[1024], path_png[1024];
    snprintf(path_md, sizeof path_md, "%s/study.md", dir);
    snprintf(path_js, sizeof path_js, "%s/study.jsonl", dir);
    snprintf(path_png, sizeof path_png, "%s/work_precision.png", dir);
    if (app_make_dir("study", "--out-dir", dir) || app_check_output("study", "--out-dir", path_md, NULL) ||
        app_check_output("study", "--out-dir", path_js, NULL) ||
        app_check_output("study", "--out-dir", path_png, ".png")) {
        model_free(m);
        return EXIT_USAGE;
    }

    // The reference: CVODE (variable-order BDF, an independent code) at a
    // tolerance far below every configuration's error.
    sim_opts ro = c.sim;
    ro.cvode = true;
    ro.rtol = 1e-10;
    ro.atol = 1e-8;
    sim_trace ref = {0};
    sim_result rr;
    if (!c.quiet) fprintf(stderr, "reference: cvode rtol 1e-10 ...\n");
    if (sim_run(m, &sc, &ro, NULL, NULL, &ref, NULL, NULL, &rr)) {
        fprintf(stderr, "cranesim study: reference run failed: %s\n", rr.message);
        model_free(m);
        return EXIT_RUNTIME;
    }
    double ppeak = 0;
    for (int i = 0; i < ref.nrow; ++i)
        for (int k = COL_P1A; k <= COL_P2B; ++k) ppeak = fmax(ppeak, ref.v[(size_t)i * SIM_NCOL + k]);

    study_cfg cfg[40];
    int n = 0;
    const double hs[] = {1e-4, 2e-4, 5e-4, 1e-3};
    // 2e-3: the loosest tolerance at which RODAS3 keeps the ramp's chamber
    // pressures within 1 % of peak (the "1 % pressure accuracy" of docs/solver_study.md).
    const double tols_all[] = {1e-2, 2e-3, 1e-3, 1e-4, 1e-5}, tols_quick[] = {1e-2, 1e-3};
    const double* tols = quick ? tols_quick : tols_all;
    const int nh = quick ? 2 : 4, nt = quick ? 2 : 5;
    for (int i = 0; i < nh; ++i) n = add_fixed(cfg, n, &c.sim, HYD_KRUS, quick ? hs[i * 3] : hs[i]);
    for (int i = 0; i < nh; ++i) n = add_fixed(cfg, n, &c.sim, HYD_ROS2, quick ? hs[i * 3] : hs[i]);
    // RK4 at 0.1 ms is refused (beyond its stability interval on the hose
    // modes, decision 6): the full study keeps the row, whose text says why
    // stiffness matters; the quick one runs it only where it is stable.
    if (!quick) n = add_fixed(cfg, n, &c.sim, HYD_RK4, 1e-4);
    n = add_fixed(cfg, n, &c.sim, HYD_RK4, 1e-5);
    for (int i = 0; i < nt; ++i) n = add_adaptive(cfg, n, &c.sim, HYD_ROS34PW2, false, tols[i]);
    for (int i = 0; i < nt; ++i) n = add_adaptive(cfg, n, &c.sim, HYD_RODAS3, false, tols[i]);
    for (int i = 0; i < nt; ++i) n = add_adaptive(cfg, n, &c.sim, HYD_RODAS3, true, tols[i]);

    for (int i = 0; i < n; ++i) {
        study_cfg* s = &cfg[i];
        if (!c.quiet) fprintf(stderr, "[%2d/%d] %s\n", i + 1, n, s->name);
        sim_trace tr = {0};
        sim_result r;
        double walls[50];
        int ok = sim_run(m, &sc, &s->o, NULL, NULL, &tr, NULL, NULL, &r) == 0;
        if (!ok) {
            s->failed = 1;
            snprintf(s->why, sizeof s->why, "%s", r.message);
            sim_trace_free(&tr);
            continue;
        }
        s->st = r.stats;
        // Timed runs without output capture: the trace is for the error only.
        for (int k = 0; k < repeat; ++k) {
            sim_result rt;
            sim_run(m, &sc, &s->o, NULL, NULL, NULL, NULL, NULL, &rt);
            walls[k] = rt.wall;
        }
        s->wall = app_median(walls, repeat);
        int rows = tr.nrow < ref.nrow ? tr.nrow : ref.nrow;
        double s2 = 0;
        for (int j = 0; j < rows; ++j) {
            const double* a = tr.v + (size_t)j * SIM_NCOL;
            const double* b = ref.v + (size_t)j * SIM_NCOL;
            for (int k = COL_P1A; k <= COL_P2B; ++k) {
                double d = fabs(a[k] - b[k]);
                s->p_max = fmax(s->p_max, d);
                s2 += d * d;
            }
            for (int k = COL_X1; k <= COL_X2; ++k) s->x_max = fmax(s->x_max, fabs(a[k] - b[k]));
        }
        s->p_rms = sqrt(s2 / (4.0 * rows));
        sim_trace_free(&tr);
    }

    // Each replaces the previous study's file only once written in full.
    app_out out_md, out_js;
    FILE* md = app_out_open(&out_md, path_md, "w");
    FILE* js = md ? app_out_open(&out_js, path_js, "w") : NULL;
    if (!md || !js) {
        fprintf(stderr, "cranesim study: cannot write %s: %s\n", md ? path_js : path_md, strerror(errno));
        if (md) app_out_close(&out_md, 0, false);
        model_free(m);
        sim_trace_free(&ref);
        return EXIT_RUNTIME;
    }
    FILE* outs[2] = {stdout, md};
    for (int o = 0; o < 2; ++o) {
        fprintf(outs[o],
                "Scenario %s, %.1f s; reference CVODE rtol 1e-10 (%ld steps); peak chamber pressure %.2f MPa.\n\n",
                sc.name, rr.t_end, rr.stats.steps, ppeak * 1e-6);
        fprintf(outs[o], "| configuration | max p error [MPa] | [%% of peak] | RMS p error [MPa] | max stroke error "
                         "[mm] | steps | f evals | Jacobians | LUs | wall [s] | x real time |\n");
        fprintf(outs[o], "|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (int i = 0; i < n; ++i) {
            const study_cfg* s = &cfg[i];
            if (s->failed) {
                fprintf(outs[o], "| %s | failed: %s | | | | | | | | | |\n", s->name, s->why);
                continue;
            }
            char speed[32];
            fprintf(outs[o], "| %s | %.3g | %.3g | %.3g | %.3g | %ld | %ld | %ld | %ld | %.4f | %s |\n", s->name,
                    s->p_max * 1e-6, 100 * s->p_max / ppeak, s->p_rms * 1e-6, s->x_max * 1e3, s->st.steps,
                    s->st.fevals, s->st.jevals, s->st.lus, s->wall,
                    app_fmt_speed(speed, sizeof speed, rr.t_end / s->wall)); // simulated time: --duration or the scenario's
        }
    }
    for (int i = 0; i < n; ++i) {
        const study_cfg* s = &cfg[i];
        fprintf(js,
                "{\"scenario\":\"%s\",\"config\":\"%s\",\"failed\":%d,\"p_err_max_pa\":%.6g,\"p_err_pct\":%.6g,"
                "\"p_err_rms_pa\":%.6g,\"x_err_max_m\":%.6g,\"steps\":%ld,\"fevals\":%ld,\"jevals\":%ld,\"lus\":%ld,"
                "\"wall_s\":%.6g}\n",
                sc.name, s->name, s->failed, s->p_max, 100 * s->p_max / ppeak, s->p_rms, s->x_max, s->st.steps,
                s->st.fevals, s->st.jevals, s->st.lus, s->wall);
    }
    int code = 0;
    if (close_checked(&out_md, path_md)) code = EXIT_RUNTIME;
    if (close_checked(&out_js, path_js)) code = EXIT_RUNTIME;
#ifdef CRANESIM_HAVE_PLPLOT
    char title[160], err[512];
    snprintf(title, sizeof title, "Work-precision, scenario %s (reference CVODE rtol 1e-10)", sc.name);
    const int prc = plot_wp(cfg, n, ppeak, title, path_png, err, sizeof err);
    if (prc < 0) {
        fprintf(stderr, "cranesim study: plot: %s\n", err);
        code = EXIT_RUNTIME;
    }
    if (!code) printf("\nwrote %s, %s%s%s\n", path_md, path_js, prc == 0 ? ", " : " (no plot: no configuration succeeded)",
                      prc == 0 ? path_png : "");
#else
    if (!code) printf("\nwrote %s, %s (no plot: built without PLplot)\n", path_md, path_js);
#endif
    sim_trace_free(&ref);
    model_free(m);
    return code;
}
