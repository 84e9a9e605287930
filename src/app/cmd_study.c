// cmd_study.c: `cranesim study`: the solver study the paper called for.
//
// Runs one scenario with every integrator at several steps or tolerances,
// measures each against a tight-tolerance CVODE (BDF) reference, and writes a
// table (Markdown), JSON lines and a work-precision plot.
#include "app.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifdef CRANESIM_HAVE_PLPLOT
#include <plplot.h>
#endif

static void study_help(FILE* f) {
    fprintf(f,
            "usage: cranesim study [--scenario S] [--out-dir DIR] [--repeat N] [--quick]\n"
            "\n"
            "Integrates the scenario (default ramp) with Krus and ROS2 at h = 0.1, 0.2, 0.5, 1 ms,\n"
            "RK4, the adaptive ROS34PW2 and RODAS3 at rtol 1e-2, 2e-3, 1e-3, 1e-4, 1e-5, and\n"
            "SUNDIALS CVODE, and compares each with a CVODE reference at rtol 1e-10. Reports\n"
            "per configuration:\n"
            "max and RMS chamber-pressure error [MPa and %% of peak], max stroke error [mm],\n"
            "steps, f evaluations, Jacobians, LU factorisations and median wall time [s].\n"
            "Writes DIR/study.md (table), DIR/study.jsonl and DIR/work_precision.png.\n"
            "\n"
            "options:\n"
            "  --scenario S   default ramp (try step for the stiff phases)\n"
            "  --out-dir DIR  default study\n"
            "  --repeat N     timed runs per configuration, median reported (default 3)\n"
            "  --quick        fewer configurations (for tests)\n");
    app_common_help(f, false);
}

typedef struct study_cfg {
    char name[40];
    sim_opts o;
    // results
    int failed;
    char why[400];
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
// x: max pressure error in % of ppeak [Pa]; y: wall time.
static void plot_wp(const study_cfg* c, int n, double ppeak, const char* title, const char* png) {
    double xlo = 1e300, xhi = -1e300, ylo = 1e300, yhi = -1e300;
    for (int i = 0; i < n; ++i) {
        if (c[i].failed || !(c[i].p_max > 0) || !(c[i].wall > 0)) continue;
        double x = log10(100 * c[i].p_max / ppeak), y = log10(c[i].wall);
        xlo = fmin(xlo, x), xhi = fmax(xhi, x), ylo = fmin(ylo, y), yhi = fmax(yhi, y);
    }
    if (!(xhi >= xlo)) return;
    plsdev("pngcairo");
    plsfnam(png);
    plsetopt("geometry", "1200x850");
    plscolbg(255, 255, 255);
    plscol0(15, 0, 0, 0);
    plinit();
    plcol0(15);
    plenv(floor(xlo - 0.2), ceil(xhi + 0.2), floor(ylo - 0.2), ceil(yhi + 0.3), 0, 30);
    pllab("max chamber-pressure error [% of peak] (log)", "wall time [s] (log)", title);
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
    plend();
}
#endif

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
        if (!strcmp(argv[i], "--out-dir") && i + 1 < argc) {
            dir = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--quick")) {
            quick = true;
            continue;
        }
        if (!strcmp(argv[i], "--repeat") && i + 1 < argc) {
            double d;
            if (app_parse_double(argv[++i], &d) || d < 1 || d > 50) {
                fprintf(stderr, "cranesim study: --repeat: expected 1..50, got '%s'\n", argv[i]);
                return EXIT_USAGE;
            }
            repeat = (int)d;
            continue;
        }
        fprintf(stderr, "cranesim study: unknown option '%s' (see cranesim study --help)\n", argv[i]);
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
    mkdir(dir, 0755);

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
    // pressures within 1 % of peak (the SPEC's "1 % pressure accuracy").
    const double tols_all[] = {1e-2, 2e-3, 1e-3, 1e-4, 1e-5}, tols_quick[] = {1e-2, 1e-3};
    const double* tols = quick ? tols_quick : tols_all;
    const int nh = quick ? 2 : 4, nt = quick ? 2 : 5;
    for (int i = 0; i < nh; ++i) n = add_fixed(cfg, n, &c.sim, HYD_KRUS, quick ? hs[i * 3] : hs[i]);
    for (int i = 0; i < nh; ++i) n = add_fixed(cfg, n, &c.sim, HYD_ROS2, quick ? hs[i * 3] : hs[i]);
    n = add_fixed(cfg, n, &c.sim, HYD_RK4, 1e-4);
    if (!quick) n = add_fixed(cfg, n, &c.sim, HYD_RK4, 1e-5);
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

    char path[512];
    snprintf(path, sizeof path, "%s/study.md", dir);
    FILE* md = fopen(path, "w");
    snprintf(path, sizeof path, "%s/study.jsonl", dir);
    FILE* js = fopen(path, "w");
    if (!md || !js) {
        fprintf(stderr, "cranesim study: cannot write into %s\n", dir);
        if (md) fclose(md);
        if (js) fclose(js);
        model_free(m);
        sim_trace_free(&ref);
        return EXIT_USAGE;
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
            fprintf(outs[o], "| %s | %.3g | %.3g | %.3g | %.3g | %ld | %ld | %ld | %ld | %.4f | %.0f |\n", s->name,
                    s->p_max * 1e-6, 100 * s->p_max / ppeak, s->p_rms * 1e-6, s->x_max * 1e3, s->st.steps,
                    s->st.fevals, s->st.jevals, s->st.lus, s->wall, rr.t_end / s->wall); // simulated time: --duration or the scenario's
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
    fclose(md);
    fclose(js);
#ifdef CRANESIM_HAVE_PLPLOT
    snprintf(path, sizeof path, "%s/work_precision.png", dir);
    char title[160];
    snprintf(title, sizeof title, "Work-precision, scenario %s (reference CVODE rtol 1e-10)", sc.name);
    plot_wp(cfg, n, ppeak, title, path);
    printf("\nwrote %s/study.md, %s/study.jsonl, %s\n", dir, dir, path);
#else
    printf("\nwrote %s/study.md, %s/study.jsonl (no plot: built without PLplot)\n", dir, dir);
#endif
    sim_trace_free(&ref);
    model_free(m);
    return 0;
}
