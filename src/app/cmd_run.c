// cmd_run.c: `cranesim run`: a headless run of a scenario to CSV (and a plot).
#include "app.h"

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
            "  truck_tilt,contacts,max_depth (world frame, m, rad)\n"
            "\n"
            "options:\n"
            "  --out FILE           CSV output (default run.csv)\n"
            "  --plot FILE.png      also plot strokes, pressures, valve openings and tip path\n");
    app_common_help(f, true);
    fprintf(f,
            "\nexit codes: 0 ok, 1 numerical failure (rows so far are kept), 2 bad input\n"
            "example: cranesim run --scenario ramp --out ramp.csv --plot ramp.png\n");
}

typedef struct csv_sink {
    FILE* f;
    long rows;
    int ncol;
} csv_sink;

static int csv_row(void* user, const double* row) {
    csv_sink* s = user;
    sim_csv_row(s->f, row, s->ncol);
    // Flush about once a simulated second at 1 kHz, so a crash or a kill
    // keeps nearly everything already computed.
    if (++s->rows % 1000 == 0) fflush(s->f);
    return ferror(s->f) ? 1 : 0;
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
    printf("cranesim run: %s, %s/%s, solver %s", scen, o->mechanics == SIM_LAGRANGE ? "lagrange" : "ode",
           lagrange_variant_name(o->variant), o->cvode ? "cvode" : hyd_method_name(o->solver));
    // Which circuit kernel ran (cranesim run --help, --kernel).
    const char* kern = r->split ? ", split step" : r->fused ? ", fused kernel" : ", general kernel";
    if (o->cvode || hyd_method_is_adaptive(o->solver)) printf(" (rtol %g, atol %g%s)\n", o->rtol, o->atol, kern);
    else printf(" (h = %g ms%s)\n", o->h * 1e3, kern);
    if (o->mechanics == SIM_ODE)
        printf("  simulated %.3f s in %.3f s wall: %.0fx real time; ODE step %g ms, %ld hydraulic sub-steps\n",
               r->t_end, r->wall, r->wall > 0 ? r->t_end / r->wall : 0.0, o->dt_ode * 1e3, r->stats.steps);
    else
        printf("  simulated %.3f s in %.3f s wall: %.0fx real time; %ld steps, %ld rejected, %ld f evals, %ld LU\n",
               r->t_end, r->wall, r->wall > 0 ? r->t_end / r->wall : 0.0, r->stats.steps, r->stats.rejected,
               r->stats.fevals, r->stats.lus);
    printf("  strokes: lift %.1f..%.1f mm, jib %.1f..%.1f mm\n", 1e3 * xmin[0], 1e3 * xmax[0], 1e3 * xmin[1],
           1e3 * xmax[1]);
    printf("  peak pressures: p1A %.2f, p1B %.2f, p2A %.2f, p2B %.2f MPa (absolute)\n", pmax[0] * 1e-6,
           pmax[1] * 1e-6, pmax[2] * 1e-6, pmax[3] * 1e-6);
    printf("  %ld rows -> %s\n", r->rows, out);
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
        if ((!strcmp(argv[i], "--out") || !strcmp(argv[i], "--plot")) && i + 1 < argc) {
            if (argv[i][2] == 'o') out = argv[++i];
            else plot = argv[++i];
            continue;
        }
        fprintf(stderr, "cranesim run: unknown option '%s' (see cranesim run --help)\n", argv[i]);
        return EXIT_USAGE;
    }
    model* m;
    scenario sc;
    int rc = app_load(&c, &m, &sc);
    if (rc) return rc;

    csv_sink sink = {0};
    sink.f = fopen(out, "w");
    if (!sink.f) {
        fprintf(stderr, "cranesim run: cannot write %s\n", out);
        model_free(m);
        return EXIT_USAGE;
    }
    sink.ncol = sim_ncol(&c.sim);
    sim_csv_header(sink.f, sink.ncol);
    sim_trace tr = {0};
    sim_result res;
    sim_run(m, &sc, &c.sim, csv_row, &sink, &tr, c.quiet ? NULL : app_progress, NULL, &res);
    if (!c.quiet) app_progress_done();
    int bad_write = fclose(sink.f) != 0;
    int code = EXIT_OK_;
    if (res.status == 1) {
        fprintf(stderr, "cranesim run: %s; %ld rows up to t = %.6g s kept in %s\n", res.message, res.rows,
                res.t_end, out);
        code = EXIT_RUNTIME;
    } else if (res.status == 2) {
        fprintf(stderr, "cranesim run: %s\n", res.message);
        code = bad_write || sink.rows ? EXIT_RUNTIME : EXIT_USAGE;
    } else if (bad_write) {
        fprintf(stderr, "cranesim run: writing %s failed\n", out);
        code = EXIT_RUNTIME;
    }
    if (code == EXIT_OK_ && !c.quiet) print_summary(sc.name[0] ? sc.name : c.scenario_path, &c.sim, &res, &tr, out);
    if (plot && tr.nrow > 1) {
        char err[256], title[160];
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
