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
            "usage: cranesim study [--scenario S] [--out-dir DIR] [--repeat N] [--quick] [--only TEXT]\n"
            "                      [options]\n"
            "\n"
            "Integrates the scenario (default ramp) with Krus and ROS2 at h = 0.1, 0.2, 0.5, 1 ms,\n"
            "RK4 at 0.1 and 0.01 ms (a step beyond RK4's stability limit on the model's circuit is\n"
            "refused and the table says why: 0.1 ms on either shipped crane, 0.01 ms too on the\n"
            "load-sensing one, whose fastest mode, 1.5e6 1/s, needs h < 1.9 us), the adaptive\n"
            "ROS34PW2 and RODAS3 and SUNDIALS CVODE at rtol 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4,\n"
            "1e-4, 5e-5, 2e-5, 1e-5, and compares each with a CVODE reference at\n"
            "rtol 1e-10, on the lagrange model and the 1 ms output grid. Reports per configuration:\n"
            "max and RMS chamber-pressure error [MPa and %% of peak], max stroke error [mm],\n"
            "steps, rejected steps, f evaluations, Jacobians, LU factorisations and median wall\n"
            "time [s] (the timed runs of all configurations interleaved, so that a change in the\n"
            "machine's load hits them alike). Then, per adaptive method, the cheapest run within\n"
            "1 %% of peak against the cheapest CVODE run at least as accurate: wall-time ratio\n"
            "(CVODE over the method) at matched accuracy.\n"
            "Writes DIR/study.md (table), DIR/study.jsonl and DIR/work_precision.png.\n"
            "\n"
            "options:\n"
            "  --out-dir DIR        default study (created with its parents before the runs)\n"
            "  --repeat N           timed runs per configuration, median reported (1..50, default 3)\n"
            "  --quick              fewer configurations (for tests)\n"
            "  --only TEXT          only the configurations whose name contains TEXT (repeatable:\n"
            "                       any of them), e.g. --only rtol= for the adaptive ones, or\n"
            "                       --only rodas3 --only cvode\n");
    app_options_help(f, study_opts);
}

typedef struct study_cfg {
    char name[40];
    sim_opts o;
    // results
    int failed;
    int ran;     ///< the untimed run succeeded: timed runs follow
    char why[512];
    double wall, p_max, p_rms, x_max;
    hyd_solver_stats st;
} study_cfg;

// Each configuration starts from zero: the results (failed, the error maxima
// taken with fmax) accumulate into its fields.
static int add_fixed(study_cfg* c, int n, const sim_opts* base, hyd_method m, double h) {
    c[n] = (study_cfg){.o = *base};
    c[n].o.solver = m;
    c[n].o.h = h;
    snprintf(c[n].name, sizeof c[n].name, "%s h=%gms", hyd_method_name(m), h * 1e3);
    return n + 1;
}

static int add_adaptive(study_cfg* c, int n, const sim_opts* base, hyd_method m, bool cvode, double rtol) {
    c[n] = (study_cfg){.o = *base};
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

// A point's label: the step or the tolerance alone ("0.1 ms", "1e-5"); the
// legend says which the family varies.
static void wp_label(const char* name, char* out, size_t n) {
    if (!strncmp(name, "h=", 2)) {
        snprintf(out, n, "%.*s ms", (int)(strlen(name) - 4), name + 2); // "h=0.1ms"
        return;
    }
    const char* v = strncmp(name, "rtol=", 5) ? name : name + 5;
    snprintf(out, n, "%s", v);
    char* e = strstr(out, "e-0"); // 1e-05 -> 1e-5
    if (e) memmove(e + 2, e + 3, strlen(e + 3) + 1);
}

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
    // One colour per method family, a line through its points and a legend
    // (bottom left: no method is both fast and accurate there); each point
    // carries its step or tolerance, placed clear of the others
    // (app_place_labels: ros34pw2 and rodas3 lie on top of each other).
    const char* fam[] = {"krus", "ros2", "rk4", "ros34pw2", "rodas3", "cvode"};
    const char* legend[] = {"krus (h)", "ros2 (h)", "rk4 (h)", "ros34pw2 (rtol)", "rodas3 (rtol)", "cvode (rtol)"};
    enum { MAXP = 96 };
    PLFLT ax[MAXP], ay[MAXP];
    char lab[MAXP][24];
    int lfam[MAXP], np = 0;
    int shown[6], nshown = 0;
    for (int f = 0; f < 6; ++f) {
        PLFLT xs[MAXP], ys[MAXP];
        int k = 0;
        const size_t lf = strlen(fam[f]);
        for (int i = 0; i < n && np < MAXP; ++i) {
            if (c[i].failed || !(c[i].p_max > 0) || !(c[i].wall > 0) || strncmp(c[i].name, fam[f], lf) ||
                c[i].name[lf] != ' ')
                continue;
            xs[k] = ax[np] = log10(100 * c[i].p_max / ppeak);
            ys[k] = ay[np] = log10(c[i].wall);
            wp_label(c[i].name + lf + 1, lab[np], sizeof lab[np]);
            lfam[np++] = f;
            ++k;
        }
        if (!k) continue;
        shown[nshown++] = f;
        plcol0(col[f]);
        plline(k, xs, ys);
        plpoin(k, xs, ys, 17);
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
        text[i] = legend[f];
    }
    PLFLT lw = 0, lh = 0;
    plschr(0, 0.8);
    pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
             PL_POSITION_BOTTOM | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0.02, 0.02, 0.08, 0, 15, 1, 0, 0, nshown,
             opt, 1.0, 1.0, 2.0, 0.0, tcol, text, NULL, NULL, NULL, NULL, lcol, lsty, lwid, scol, sscale, snum, sym);
    // The labels, placed in mm on the page: world -> mm through the
    // viewport (normalised) and the page size.
    plschr(0, 0.7);
    PLFLT wx0, wx1, wy0, wy1, vx0, vx1, vy0, vy1, sx0, sx1, sy0, sy1, def, ht;
    plgvpw(&wx0, &wx1, &wy0, &wy1);
    plgvpd(&vx0, &vx1, &vy0, &vy1);
    plgspa(&sx0, &sx1, &sy0, &sy1);
    plgchr(&def, &ht);
    const double mx = (vx1 - vx0) * (sx1 - sx0) / (wx1 - wx0), my = (vy1 - vy0) * (sy1 - sy0) / (wy1 - wy0);
    const double ox = sx0 + vx0 * (sx1 - sx0), oy = sy0 + vy0 * (sy1 - sy0);
    static app_label l[MAXP + 1];
    double px[MAXP], py[MAXP];
    // Label 0: the legend's box (lw, lh: fractions of the viewport), fixed.
    const double vw = (vx1 - vx0) * (sx1 - sx0), vh = (vy1 - vy0) * (sy1 - sy0);
    l[0] = (app_label){.w = lw * vw + 2.0, .h = lh * vh + 2.0};
    l[0].lx = ox + 0.02 * vw - 1.0, l[0].ly = oy + 0.02 * vh + 0.5 * l[0].h - 1.0, l[0].just = 0;
    for (int i = 0; i < np; ++i) {
        px[i] = ox + (ax[i] - wx0) * mx, py[i] = oy + (ay[i] - wy0) * my;
        // A character is about 0.62 character heights wide in the cairo sans font.
        l[i + 1] = (app_label){.x = px[i], .y = py[i], .w = (0.62 * (double)strlen(lab[i]) + 0.4) * ht,
                               .h = 1.3 * ht};
    }
    const double area[4] = {ox, oy, ox + vw, oy + vh};
    app_place_labels(l, 1, np + 1, area, px, py, np, 0.6 * ht);
    for (int i = 0; i < np; ++i) {
        const app_label* q = &l[i + 1];
        plcol0(col[lfam[i]]);
        const double lx = wx0 + (q->lx - ox) / mx, ly = wy0 + (q->ly - oy) / my;
        if (q->leader) {
            // A dotted line from the point to the nearest point of the label's box.
            const double b0 = q->lx - q->just * q->w, b1 = q->ly - 0.5 * q->h;
            const double nx = fmin(fmax(px[i], b0), b0 + q->w), ny = fmin(fmax(py[i], b1), b1 + q->h);
            PLFLT xs[2] = {ax[i], wx0 + (nx - ox) / mx}, ys[2] = {ay[i], wy0 + (ny - oy) / my};
            pllsty(3);
            plline(2, xs, ys);
            pllsty(1);
        }
        // plptex's reference point is the text's vertical centre.
        plptex(lx, ly, 1, 0, q->just, lab[i]);
    }
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

// One timed run, no output captured: the wall time [s]. A function of its
// own, never inlined, so that callgrind can count the timed runs alone:
//   valgrind --tool=callgrind --toggle-collect=study_timed_run
//       cranesim study --only 'rodas3 rtol=0.0001' --repeat 1
__attribute__((noinline)) static double study_timed_run(const model* m, const scenario* sc, const sim_opts* o) {
    sim_result rt;
    sim_run(m, sc, o, NULL, NULL, NULL, NULL, NULL, &rt);
    return rt.wall;
}

// The configuration of family fam ("rodas3", "cvode": the name up to its
// space) with the least wall time among the runs whose max pressure error is
// at most p_lim [Pa]; -1 when none.
static int cheapest_within(const study_cfg* c, int n, const char* fam, double p_lim) {
    const size_t lf = strlen(fam);
    int best = -1;
    for (int i = 0; i < n; ++i) {
        if (!c[i].ran || strncmp(c[i].name, fam, lf) || c[i].name[lf] != ' ' || !(c[i].p_max <= p_lim)) continue;
        if (best < 0 || c[i].wall < c[best].wall) best = i;
    }
    return best;
}

// The matched-accuracy comparison of one adaptive method with CVODE: the
// method's cheapest run within 1 % of peak, against CVODE's cheapest run
// whose error is no larger. One line to each of outs[0..nout-1] (Markdown),
// one JSON object to js (NULL: none).
static void compare_cvode(const study_cfg* c, int n, const char* fam, double ppeak, const char* mname,
                          const char* scen, FILE* const* outs, int nout, FILE* js) {
    const int a = cheapest_within(c, n, fam, 0.01 * ppeak);
    const int v = a < 0 ? -1 : cheapest_within(c, n, "cvode", c[a].p_max);
    // The most accurate CVODE run, for the line that says none was enough.
    int best = -1;
    for (int i = 0; i < n; ++i)
        if (c[i].ran && !strncmp(c[i].name, "cvode ", 6) && (best < 0 || c[i].p_max < c[best].p_max)) best = i;
    for (int o = 0; o < nout; ++o) {
        if (a < 0) fprintf(outs[o], "* %s: no run within 1 %% of peak.\n", fam);
        else if (v < 0 && best < 0)
            fprintf(outs[o], "* %s: %s (%.3g %% of peak, %.4f s); no CVODE run succeeded.\n", fam, c[a].name,
                    100 * c[a].p_max / ppeak, c[a].wall);
        else if (v < 0)
            fprintf(outs[o], "* %s: %s (%.3g %% of peak, %.4f s); no CVODE run was as accurate (the most accurate: "
                             "%s, %.3g %%).\n",
                    fam, c[a].name, 100 * c[a].p_max / ppeak, c[a].wall, c[best].name, 100 * c[best].p_max / ppeak);
        else
            fprintf(outs[o],
                    "* %s at <= 1 %% of peak: %s (%.3g %% of peak, %.4f s) against %s (%.3g %%, %.4f s): "
                    "**%.1fx** less wall time than CVODE at matched accuracy.\n",
                    fam, c[a].name, 100 * c[a].p_max / ppeak, c[a].wall, c[v].name, 100 * c[v].p_max / ppeak,
                    c[v].wall, c[v].wall / c[a].wall);
    }
    if (!js) return;
    fprintf(js, "{\"model\":\"%s\",\"scenario\":\"%s\",\"comparison\":\"%s vs cvode at 1 %% of peak\",", mname,
            scen, fam);
    if (a < 0) fprintf(js, "\"adaptive\":null,");
    else fprintf(js, "\"adaptive\":\"%s\",\"adaptive_p_err_pct\":%.6g,\"adaptive_wall_s\":%.6g,", c[a].name,
                 100 * c[a].p_max / ppeak, c[a].wall);
    if (v < 0) fprintf(js, "\"cvode\":null,\"ratio\":null}\n");
    else fprintf(js, "\"cvode\":\"%s\",\"cvode_p_err_pct\":%.6g,\"cvode_wall_s\":%.6g,\"ratio\":%.6g}\n",
                 c[v].name, 100 * c[v].p_max / ppeak, c[v].wall, c[v].wall / c[a].wall);
}

int cmd_study(int argc, char** argv) {
    app_common c = {.sim = sim_default_opts()};
    // No step probe: the study measures each step's error against its reference itself, so a long
    // step is what it measures, not a refusal.
    c.sim.no_step_probe = true;
    const char* dir = "study";
    int repeat = 3;
    bool quick = false;
    enum { MAX_ONLY = 16 };
    const char* only[MAX_ONLY];
    int nonly = 0;
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
        if (!strcmp(argv[i], "--only")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if (!*v || nonly == MAX_ONLY) {
                fprintf(stderr, "cranesim study: --only: %s\n",
                        *v ? "at most 16 of them" : "expected part of a configuration name, got ''");
                return EXIT_USAGE;
            }
            only[nonly++] = v;
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
        // The study runs the default backend (its CVODE reference is that
        // backend's): --mechanics naming it is what it runs anyway.
        const engine_backend* ref = engine_backend_default();
        if (k == APP_OPT_MECHANICS && app_backend(&c.sim) == ref) continue;
        char ref_only[128];
        snprintf(ref_only, sizeof ref_only, "the study's CVODE reference runs the %s model only", ref->name);
        const char* why = k == APP_OPT_MECHANICS || k == APP_OPT_WORLD || k == APP_OPT_DT_ODE
                              ? ref_only
                          : k == APP_OPT_EVERY ? "the study compares every configuration with the reference on the "
                                                 "1 ms output grid"
                                               : "the study sets the solver, step and tolerances of each "
                                                 "configuration itself";
        if (k == APP_OPT_MECHANICS)
            fprintf(stderr, "cranesim study: --mechanics %s: %s\n", app_backend(&c.sim)->name, why);
        else fprintf(stderr, "cranesim study: %s is not an option of study: %s\n", app_opt_name[k], why);
        return EXIT_USAGE;
    }
    if (!sim_have_cvode()) {
        fprintf(stderr, "cranesim study: needs the CVODE reference (install libsundials-dev and rebuild)\n");
        return EXIT_USAGE;
    }
    study_cfg cfg[48];
    int n = 0;
    const double hs[] = {1e-4, 2e-4, 5e-4, 1e-3};
    // 2e-3: the loosest tolerance at which RODAS3 keeps the ramp's chamber
    // pressures within 1 % of peak (the "1 % pressure accuracy" of
    // docs/solver_study.md). Three steps per decade, so that the matched-
    // accuracy comparison below does not hand either side a run up to 10x
    // more accurate (and dearer) than it needs.
    const double tols_all[] = {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5},
                 tols_quick[] = {1e-2, 1e-3};
    const double* tols = quick ? tols_quick : tols_all;
    const int nh = quick ? 2 : 4, nt = quick ? 2 : 10;
    for (int i = 0; i < nh; ++i) n = add_fixed(cfg, n, &c.sim, HYD_KRUS, quick ? hs[i * 3] : hs[i]);
    for (int i = 0; i < nh; ++i) n = add_fixed(cfg, n, &c.sim, HYD_ROS2, quick ? hs[i * 3] : hs[i]);
    // RK4 at 0.1 ms is refused (beyond its stability interval on the hose
    // modes, decision 6): the full study keeps the row, whose text says why
    // stiffness matters; the quick one runs it only where it is stable on
    // the standard crane (the LS crane's fastest mode, 1.5e6 1/s, refuses
    // 0.01 ms too, also a row that says why).
    if (!quick) n = add_fixed(cfg, n, &c.sim, HYD_RK4, 1e-4);
    n = add_fixed(cfg, n, &c.sim, HYD_RK4, 1e-5);
    for (int i = 0; i < nt; ++i) n = add_adaptive(cfg, n, &c.sim, HYD_ROS34PW2, false, tols[i]);
    for (int i = 0; i < nt; ++i) n = add_adaptive(cfg, n, &c.sim, HYD_RODAS3, false, tols[i]);
    for (int i = 0; i < nt; ++i) n = add_adaptive(cfg, n, &c.sim, HYD_RODAS3, true, tols[i]);
    if (nonly) {
        int kept = 0;
        for (int i = 0; i < n; ++i) {
            int keep = 0;
            for (int k = 0; k < nonly && !keep; ++k) keep = strstr(cfg[i].name, only[k]) != NULL;
            if (keep) cfg[kept++] = cfg[i];
        }
        if (!kept) {
            fprintf(stderr, "cranesim study: --only: no configuration name contains '%s'%s (names such as "
                            "'krus h=0.1ms', 'rodas3 rtol=0.0001', 'cvode rtol=1e-05')\n",
                    only[0], nonly > 1 ? " or the others given" : "");
            return EXIT_USAGE;
        }
        n = kept;
    }

    model* m;
    scenario sc;
    int rc = app_load(&c, &m, &sc);
    if (rc) return rc;
    {
        // The reference is CVODE, which the chain's analytic mode does not
        // run, and the errors are measured on the two-link columns (x1, x2,
        // p1A..p2B): a chain model is refused before anything is made,
        // rather than fail after the folder exists.
        char err[600];
        if (model_require_two_link(m, "solver study (its CVODE reference and its lift and jib errors)", err,
                                   sizeof err)) {
            fprintf(stderr, "cranesim study: %s\n", err);
            model_free(m);
            return EXIT_USAGE;
        }
    }
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

    // First an untimed run of each, whose trace gives the errors.
    for (int i = 0; i < n; ++i) {
        study_cfg* s = &cfg[i];
        if (!c.quiet) fprintf(stderr, "[%2d/%d] %s\n", i + 1, n, s->name);
        sim_trace tr = {0};
        sim_result r;
        int ok = sim_run(m, &sc, &s->o, NULL, NULL, &tr, NULL, NULL, &r) == 0;
        if (!ok) {
            s->failed = 1;
            snprintf(s->why, sizeof s->why, "%s", r.message);
            sim_trace_free(&tr);
            continue;
        }
        s->ran = 1;
        s->st = r.stats;
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
    // Then the timed runs, without output capture, interleaved: round k runs
    // every configuration once, so that a change in the machine's load
    // (other processes on a shared machine) hits all configurations alike
    // rather than the few that happened to run then.
    static double walls[48][50];
    if (!c.quiet) fprintf(stderr, "timing: %d rounds ...\n", repeat);
    for (int k = 0; k < repeat; ++k)
        for (int i = 0; i < n; ++i)
            if (cfg[i].ran) walls[i][k] = study_timed_run(m, &sc, &cfg[i].o);
    for (int i = 0; i < n; ++i)
        if (cfg[i].ran) cfg[i].wall = app_median(walls[i], repeat);

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
    // The model's file name: the same scenario on another crane is another study.
    const char* mpath = c.model_path ? c.model_path : "hiab031.json";
    const char* mname = strrchr(mpath, '/') ? strrchr(mpath, '/') + 1 : mpath;
    for (int o = 0; o < 2; ++o) {
        fprintf(outs[o],
                "Model %s, scenario %s, %.1f s; reference CVODE rtol 1e-10 (%ld steps); peak chamber pressure "
                "%.2f MPa.\n\n",
                mname, sc.name, rr.t_end, rr.stats.steps, ppeak * 1e-6);
        fprintf(outs[o], "| configuration | max p error [MPa] | [%% of peak] | RMS p error [MPa] | max stroke error "
                         "[mm] | steps | rejected | f evals | Jacobians | LUs | wall [s] | x real time |\n");
        fprintf(outs[o], "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (int i = 0; i < n; ++i) {
            const study_cfg* s = &cfg[i];
            if (s->failed) {
                fprintf(outs[o], "| %s | failed: %s | | | | | | | | | | |\n", s->name, s->why);
                continue;
            }
            char speed[32];
            fprintf(outs[o], "| %s | %.3g | %.3g | %.3g | %.3g | %ld | %ld | %ld | %ld | %ld | %.4f | %s |\n",
                    s->name, s->p_max * 1e-6, 100 * s->p_max / ppeak, s->p_rms * 1e-6, s->x_max * 1e3,
                    s->st.steps, s->st.rejected, s->st.fevals, s->st.jevals, s->st.lus, s->wall,
                    app_fmt_speed(speed, sizeof speed, rr.t_end / s->wall)); // simulated time: --duration or the scenario's
        }
        fprintf(outs[o], "\nAdaptive against CVODE at matched accuracy (wall times: medians of %d interleaved "
                         "rounds):\n\n", repeat);
    }
    for (int i = 0; i < n; ++i) {
        const study_cfg* s = &cfg[i];
        fprintf(js,
                "{\"model\":\"%s\",\"scenario\":\"%s\",\"config\":\"%s\",\"failed\":%d,\"p_err_max_pa\":%.6g,"
                "\"p_err_pct\":%.6g,\"p_err_rms_pa\":%.6g,\"x_err_max_m\":%.6g,\"steps\":%ld,\"rejected\":%ld,"
                "\"fevals\":%ld,\"jevals\":%ld,\"lus\":%ld,\"wall_s\":%.6g}\n",
                mname, sc.name, s->name, s->failed, s->p_max, 100 * s->p_max / ppeak, s->p_rms, s->x_max,
                s->st.steps, s->st.rejected, s->st.fevals, s->st.jevals, s->st.lus, s->wall);
    }
    static const char* const adaptive_fam[2] = {"ros34pw2", "rodas3"};
    for (int f = 0; f < 2; ++f) compare_cvode(cfg, n, adaptive_fam[f], ppeak, mname, sc.name, outs, 2, js);
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
