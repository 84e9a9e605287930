// cmd_run.c: `cranesim run`: a headless run of a scenario to CSV (and a plot).
#include "app.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static void run_help(FILE* f) {
    fprintf(f,
            "usage: cranesim run [--scenario S] [--model M] [options] [--out run.csv] [--plot run.png]\n"
            "\n"
            "Runs the crane model headless on a scripted scenario and writes one CSV row per\n"
            "output period (SI units: s, m, Pa, rad, N). Columns:\n"
            "  t,x1,x2,p1A,p1B,p2A,p2B,u1,u2,q1,q2,tip_x,tip_z,F1,F2,u1_cmd,u2_cmd,\n"
            "  v1,v2,p_pump,relief_open,end_stop\n"
            "(x: cylinder strokes, p: absolute chamber pressures, u: spool openings,\n"
            " q: joint angles in the paper's convention, tip: end-arm tip from joint 1, F: forces)\n"
            "With --mechanics ode also: slew,hook_x,hook_y,hook_z,load_x,load_y,load_z,attached,\n"
            "  truck_tilt,contacts,max_depth (world frame, m, rad), and the slew actuator's\n"
            "  x3,v3,p3A,p3B,u3,u3_cmd,F3 (zeros in the validation world)\n"
            "\n"
            "options:\n"
            "  --out FILE           CSV output (default run.csv); created when the run starts\n"
            "  --plot FILE.png      also plot strokes, pressures, valve openings and tip path\n");
    app_common_help(f, true);
    fprintf(f,
            "\nexit codes: 0 ok, 1 runtime failure (a numerical blow-up keeps the rows so far; a failed\n"
            "write), 2 bad input or usage (nothing is written)\n"
            "example: cranesim run --scenario ramp --out ramp.csv --plot ramp.png\n");
}

typedef struct csv_sink {
    const char* path;
    FILE* f;     ///< opened at the first row
    long rows;
    int ncol;
    int err;     ///< errno of the first failed open or write, 0 if none
    bool opened; ///< the file was created (or truncated)
} csv_sink;

// The CSV is opened at the first row (t = 0, before any step): a run refused
// while it sets up (a bad world, a start pose, an option sim_run rejects)
// then creates or truncates nothing. A failed write stops the run.
static int csv_row(void* user, const double* row) {
    csv_sink* s = user;
    if (!s->f) {
        s->f = fopen(s->path, "w");
        if (!s->f) {
            s->err = errno;
            return 1;
        }
        s->opened = true;
        sim_csv_header(s->f, s->ncol);
    }
    errno = 0;
    sim_csv_row(s->f, row, s->ncol);
    // Flush about once a simulated second at 1 kHz, so a crash or a kill
    // keeps nearly everything already computed.
    if (++s->rows % 1000 == 0) fflush(s->f);
    if (ferror(s->f)) {
        s->err = errno ? errno : EIO;
        return 1;
    }
    return 0;
}

// Close the CSV; 0, or the errno of the first failure (a full disk often
// shows only when the last buffer is flushed).
static int csv_close(csv_sink* s) {
    if (!s->f) return s->err;
    s->err = app_fclose_checked(s->f, s->err);
    s->f = NULL;
    return s->err;
}

static void print_summary(const char* scen, const sim_opts* o, const sim_result* r, const sim_trace* tr,
                          const char* out) {
    double pmax[4] = {0}, xmin[2] = {1e9, 1e9}, xmax[2] = {-1e9, -1e9};
    for (int i = 0; i < tr->nrow; ++i) {
        const double* v = tr->v + (size_t)i * SIM_NCOL;
        for (int k = 0; k < 4; ++k) pmax[k] = fmax(pmax[k], v[COL_P1A + k]);
        for (int k = 0; k < 2; ++k) {
            xmin[k] = fmin(xmin[k], v[COL_X1 + k]);
            xmax[k] = fmax(xmax[k], v[COL_X1 + k]);
        }
    }
    const bool ode = o->mechanics == SIM_ODE;
    const bool adaptive = o->cvode || hyd_method_is_adaptive(o->solver);
    // The variant is the lagrange backend's; an ode run is named by its world.
    // A world given as a file path reads "ode world FILE", a name "ode/NAME".
    if (ode) printf("cranesim run: %s, ode%s%s", scen, o->world && strchr(o->world, '/') ? " world " : "/",
                    o->world ? o->world : "validation");
    else printf("cranesim run: %s, lagrange/%s", scen, lagrange_variant_name(o->variant));
    printf(", solver %s", o->cvode ? "cvode" : hyd_method_name(o->solver));
    // Which circuit kernel ran (cranesim run --help, --kernel).
    const char* kern = r->split ? ", split step" : r->fused ? ", fused kernel" : ", general kernel";
    if (adaptive) printf(" (rtol %g, atol %g%s)\n", o->rtol, o->atol, kern);
    else if (ode && o->h > o->dt_ode) // the ode world sub-steps at min(--dt, --dt-ode)
        printf(" (h = %g ms: --dt %g ms reduced to the ODE step%s)\n", o->dt_ode * 1e3, o->h * 1e3, kern);
    else printf(" (h = %g ms%s)\n", o->h * 1e3, kern);
    if (ode)
        printf("  simulated %.3f s in %.3f s wall: %.0fx real time; ODE step %g ms, %ld hydraulic %s\n", r->t_end,
               r->wall, r->wall > 0 ? r->t_end / r->wall : 0.0, o->dt_ode * 1e3, r->stats.steps,
               adaptive ? "steps" : "sub-steps");
    else
        printf("  simulated %.3f s in %.3f s wall: %.0fx real time; %ld steps, %ld rejected, %ld f evals, %ld LU\n",
               r->t_end, r->wall, r->wall > 0 ? r->t_end / r->wall : 0.0, r->stats.steps, r->stats.rejected,
               r->stats.fevals, r->stats.lus);
    printf("  strokes: lift %.1f..%.1f mm, jib %.1f..%.1f mm\n", 1e3 * xmin[0], 1e3 * xmax[0], 1e3 * xmin[1],
           1e3 * xmax[1]);
    // The peaks over every integration step when sim.c tracked them (between
    // coarse rows the true peak can be far higher than any row's); else
    // (CVODE) over the rows, and said so.
    const double every = app_output_period(o);
    if (r->peak_steps) {
        printf("  peak pressures: p1A %.2f, p1B %.2f, p2A %.2f, p2B %.2f MPa (absolute, over every %s)",
               r->p_peak[0] * 1e-6, r->p_peak[1] * 1e-6, r->p_peak[2] * 1e-6, r->p_peak[3] * 1e-6,
               o->mechanics == SIM_ODE ? "ODE step" : "step");
    } else {
        printf("  peak pressures at the output rows: p1A %.2f, p1B %.2f, p2A %.2f, p2B %.2f MPa (absolute)",
               pmax[0] * 1e-6, pmax[1] * 1e-6, pmax[2] * 1e-6, pmax[3] * 1e-6);
        // The rows come every `every`, but never farther apart than the run.
        if (every > 1e-3 * (1 + 1e-9)) printf(", rows every %g ms", fmin(every, r->t_end) * 1e3);
    }
    printf("\n  %ld rows -> %s\n", r->rows, out);
}

int cmd_run(int argc, char** argv) {
    app_common c = {.sim = sim_default_opts()};
    const char* out = "run.csv";
    const char* plot = NULL;
    for (int i = 0; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            run_help(stdout);
            return 0;
        }
        int rc = app_parse_common(&c, argc, argv, &i);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        if (!strcmp(argv[i], "--out") || !strcmp(argv[i], "--plot")) {
            const bool is_out = argv[i][2] == 'o';
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if (is_out) out = v;
            else plot = v;
            continue;
        }
        fprintf(stderr, "cranesim run: unknown option '%s' (see cranesim run --help)\n", argv[i]);
        return EXIT_USAGE;
    }
    // Everything that can be checked is checked before a file is touched.
    if (app_check_output("run", "--out", out, NULL) || (plot && app_check_output("run", "--plot", plot, ".png")))
        return EXIT_USAGE;
    int rc = app_check_sim("run", &c.sim, c.given);
    if (rc) return rc;
    model* m;
    scenario sc;
    rc = app_load(&c, &m, &sc);
    if (rc) return rc;
    app_note_unused("run", c.given, &c.sim, 1);
    app_note_load("run", &c, &c.sim, &sc);
    {
        // A fixed step so small that the run takes minutes: say so up front
        // (a Krus step of the crane costs at least 0.25 us on this class of
        // machine, docs/performance.md), rather than leave a silent terminal.
        const double dur = c.sim.duration > 0 ? c.sim.duration : sc.duration;
        const bool fixed = !c.sim.cvode && !hyd_method_is_adaptive(c.sim.solver);
        const double steps = fixed ? dur / c.sim.h : 0.0;
        if (steps > 1e8)
            fprintf(stderr, "cranesim run: note: %.3g steps of %g s: at least %.0f s of wall time\n", steps, c.sim.h,
                    steps * 0.25e-6);
    }
    app_settle_unused(&c.sim);

    csv_sink sink = {.path = out, .ncol = sim_ncol(&c.sim)};
    sim_trace tr = {0};
    sim_result res;
    sim_run(m, &sc, &c.sim, csv_row, &sink, &tr, c.quiet ? NULL : app_progress, NULL, &res);
    if (!c.quiet) app_progress_done();
    if (res.note[0]) fprintf(stderr, "cranesim run: note: %s\n", res.note);
    const int werr = csv_close(&sink);
    int code = EXIT_OK_;
    if (werr && !sink.opened) {
        // The path passed app_check_output, yet could not be created: still
        // bad input, and nothing was written.
        fprintf(stderr, "cranesim run: cannot write %s: %s\n", out, strerror(werr));
        code = EXIT_USAGE;
    } else if (res.status == 1) {
        fprintf(stderr, "cranesim run: %s; %ld rows up to t = %.6g s kept in %s\n", res.message, res.rows,
                res.t_end, out);
        if (werr) fprintf(stderr, "cranesim run: cannot write %s: %s\n", out, strerror(werr));
        code = EXIT_RUNTIME;
    } else if (werr) {
        fprintf(stderr, "cranesim run: cannot write %s: %s\n", out, strerror(werr));
        code = EXIT_RUNTIME;
    } else if (res.status == 2) {
        // Refused while setting up: no row was written, so no file exists.
        fprintf(stderr, "cranesim run: %s\n", res.message);
        code = sink.rows ? EXIT_RUNTIME : EXIT_USAGE;
    }
    if (code == EXIT_OK_ && !c.quiet) print_summary(sc.name[0] ? sc.name : c.scenario_path, &c.sim, &res, &tr, out);
    if (plot && tr.nrow > 1 && code != EXIT_USAGE) {
        char err[512], title[160];
        if (c.sim.mechanics == SIM_ODE)
            snprintf(title, sizeof title, "%s: ode/%s, %s", sc.name, c.sim.world ? c.sim.world : "validation",
                     c.sim.cvode ? "cvode" : hyd_method_name(c.sim.solver));
        else
            snprintf(title, sizeof title, "%s: %s, %s", sc.name, lagrange_variant_name(c.sim.variant),
                     c.sim.cvode ? "cvode" : hyd_method_name(c.sim.solver));
        if (app_plot_run(&tr, title, plot, err, sizeof err)) {
            fprintf(stderr, "cranesim run: plot: %s\n", err);
            if (code == EXIT_OK_) code = EXIT_RUNTIME;
        } else if (!c.quiet) {
            printf("  plot -> %s\n", plot);
        }
    }
    sim_trace_free(&tr);
    model_free(m);
    return code;
}
