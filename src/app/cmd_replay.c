// cmd_replay.c: `cranesim replay SESSION`: a recorded drive run again
// headless, on the recorded design or a changed one, compared with the
// recorded rows (docs/replay.md).
#include "app.h"
#include "app_design_metrics.h"
#include "engine.h"
#include "metrics.h"
#include "session.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static void replay_help(FILE* f) {
    fprintf(f,
            "usage: cranesim replay SESSION [--model M] [--set PATH=V ...] [--out FILE.csv] [--metrics FILE.json]\n"
            "                       [--plot FILE.png] [--rcl on|off] [--quiet]\n"
            "\n"
            "Runs a session recorded by `cranesim drive --session FILE` (window or headless) again,\n"
            "headless: the same commands at the same command updates, the same hook events, the same\n"
            "world, solver, rated capacity limiter and start. On the recorded design the rows are those\n"
            "of the drive, bit for bit; with --model or --set the same operator input (the operator's\n"
            "own demands, through the same limiter) drives another design. Prints the\n"
            "recorded and the replayed run's metrics side by side with their differences, how many\n"
            "rows are identical to the recording, and the replay's energy balance (as run prints it;\n"
            "a session records no balance of the drive; docs/energy.md).\n"
            "\n"
            "options:\n"
            "  --model FILE        replay on this model file instead of the one recorded in the session\n"
            "                      (the recorded commands go to its functions by name; a function the\n"
            "                      session commands and the model lacks is refused)\n"
            "  --set PATH=VALUE    change a model value (on the recorded model, or on --model's)\n"
            "  --out FILE.csv      the replay's rows, in the record's format (drive --record)\n"
            "  --metrics FILE.json the replay's metrics (as cranesim run --metrics)\n"
            "  --plot FILE.png     overlay plot: recorded (solid) and replayed (dashed)\n"
            "  --rcl on|off        the rated capacity limiter: default as recorded (a session written before\n"
            "                      the setting was recorded: on, drive's default; docs/replay.md)\n"
            "  --quiet             no progress bar\n");
}

// A recorded row's text back to numbers; the count read.
static int parse_row(const char* text, double* row, int n) {
    int k = 0;
    for (const char* p = text; k < n && *p;) {
        char* end;
        row[k++] = strtod(p, &end);
        if (end == p) return -1;
        p = *end == ',' ? end + 1 : end;
    }
    return k;
}

static int trace_push(sim_trace* tr, const double* row, int ncol) {
    if (tr->nrow == tr->cap) {
        int nc = tr->cap ? 2 * tr->cap : 1024;
        double* v = realloc(tr->v, sizeof(double) * SIM_NCOL * (size_t)nc);
        if (!v) return -1;
        tr->v = v;
        tr->cap = nc;
    }
    double* d = tr->v + (size_t)tr->nrow * SIM_NCOL;
    memset(d, 0, sizeof(double) * SIM_NCOL);
    memcpy(d, row, sizeof(double) * (size_t)(ncol < SIM_NCOL ? ncol : SIM_NCOL));
    ++tr->nrow;
    return 0;
}

// A metric in the unit a reader compares: MPa for pressures, degrees for
// angles; the rest as they are.
static double shown(int id, const char** unit) {
    const char* u = metric_unit((metric_id)id);
    if (!strcmp(u, "Pa")) {
        *unit = "MPa";
        return 1e-6;
    }
    if (!strcmp(u, "rad")) {
        *unit = "deg";
        return 57.29577951308232;
    }
    *unit = u;
    return 1.0;
}

int cmd_replay(int argc, char** argv) {
    const char* path = NULL;
    const char* model_path = NULL;
    const char* out = NULL;
    const char* metrics_out = NULL;
    const char* plot = NULL;
    const char* sets[APP_MAX_SET];
    int nset = 0;
    bool quiet = false;
    int rcl = -1; // --rcl: 1 on, 0 off, -1 as recorded
    for (int i = 0; i < argc; ++i) {
        const char* a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            replay_help(stdout);
            return 0;
        }
        if (!strcmp(a, "--quiet")) {
            quiet = true;
            continue;
        }
        if (!strcmp(a, "--rcl")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if (strcmp(v, "on") && strcmp(v, "off")) {
                fprintf(stderr, "cranesim replay: --rcl: expected on or off, got '%s'\n", v);
                return EXIT_USAGE;
            }
            rcl = !strcmp(v, "on");
            continue;
        }
        const char** dst = !strcmp(a, "--model") ? &model_path : !strcmp(a, "--out") ? &out
                           : !strcmp(a, "--metrics") ? &metrics_out : !strcmp(a, "--plot") ? &plot : NULL;
        if (dst || !strcmp(a, "--set")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if (dst) *dst = v;
            else if (nset == APP_MAX_SET) {
                fprintf(stderr, "cranesim replay: --set: at most %d\n", APP_MAX_SET);
                return EXIT_USAGE;
            } else
                sets[nset++] = v;
            continue;
        }
        if (a[0] == '-' || path) {
            fprintf(stderr, "cranesim replay: %s '%s' (see cranesim replay --help)\n",
                    a[0] == '-' ? "unknown option" : "one session only, got another", a);
            return EXIT_USAGE;
        }
        path = a;
    }
    if (!path) {
        fprintf(stderr, "cranesim replay: which session? (cranesim replay SESSION; drive --session FILE records one)\n");
        return EXIT_USAGE;
    }
    if ((out && app_check_output("replay", "--out", out, NULL)) ||
        (metrics_out && app_check_output("replay", "--metrics", metrics_out, ".json")) ||
        (plot && app_check_output("replay", "--plot", plot, ".png")) ||
        app_check_distinct("replay", (const char* const[]){"SESSION", "--out", "--metrics", "--plot"},
                           (const char* const[]){path, out, metrics_out, plot}, 4))
        return EXIT_USAGE;
    char err[1200];
    session s;
    if (session_load(path, &s, err, sizeof err)) {
        fprintf(stderr, "cranesim replay: %s\n", err);
        return EXIT_USAGE;
    }
    // The limiter as the drive had it (the session's setting), unless --rcl.
    const bool rcl_recorded = s.rcl_recorded, rcl_as_recorded = s.sim.rcl;
    if (rcl >= 0) s.sim.rcl = rcl != 0;
    model* m = session_model(&s, model_path, sets, nset, err, sizeof err);
    if (!m) {
        fprintf(stderr, "cranesim replay: %s\n", err);
        session_free(&s);
        return EXIT_USAGE;
    }
    scenario sc;
    bool faults = false;
    if (s.scenario) {
        char sname[600];
        snprintf(sname, sizeof sname, "session %s: scenario", path);
        if (scenario_from_json(s.scenario, sname, &sc, err, sizeof err)) {
            fprintf(stderr, "cranesim replay: %s\n", err);
            model_free(m);
            session_free(&s);
            return EXIT_USAGE;
        }
        faults = sc.nfault > 0;
    }
    if (faults) {
        model* fm = engine_fault_model(m, &sc, err, sizeof err);
        model_free(m);
        if (!fm) {
            fprintf(stderr, "cranesim replay: %s\n", err);
            session_free(&s);
            return EXIT_USAGE;
        }
        m = fm;
    }
    engine* l = engine_create(m, &s.sim, s.q0, s.slew0, s.m3, err, sizeof err);
    if (!l) {
        fprintf(stderr, "cranesim replay: %s\n", err);
        model_free(m);
        session_free(&s);
        return EXIT_USAGE;
    }
    const bool changed = model_path || nset;
    const int ncol = engine_ncol(l);
    // The recorded design gives the recorded columns; a changed one may have
    // other functions and so other chain columns: its rows are then compared
    // as text (none identical) and its metrics over the common base columns.
    if (ncol != s.ncol && !changed) {
        fprintf(stderr, "cranesim replay: session %s: ncol: the session has %d channels, this engine writes %d\n", path,
                s.ncol, ncol);
        engine_destroy(l);
        model_free(m);
        session_free(&s);
        return EXIT_USAGE;
    }
    // The recorded commands by function name: a function the session
    // commands must be one of this model's (session_function_map).
    const int nfn = engine_nfunction(l);
    const bool two_link = engine_caps(l) & ENGINE_CAP_TWO_LINK;
    int* fmap = calloc((size_t)nfn + 1, sizeof *fmap);
    double* uf = calloc((size_t)nfn + 3, sizeof *uf);
    char dropped[512];
    const int ncommanded = fmap && uf ? session_function_map(&s, l, fmap, dropped, sizeof dropped, err, sizeof err) : -2;
    if (ncommanded < 0) {
        if (ncommanded == -2) snprintf(err, sizeof err, "out of memory");
        fprintf(stderr, "cranesim replay: %s\n", err);
        free(fmap);
        free(uf);
        engine_destroy(l);
        model_free(m);
        session_free(&s);
        return EXIT_USAGE;
    }
    // The base columns (the backend's, what the metrics and the plot read);
    // a chain engine's own come after them.
    const int bcol = ncol < sim_ncol(&s.sim) ? ncol : sim_ncol(&s.sim);
    const int rcol = ncol + (s.window ? 1 : 0); // the window's record adds `segment`
    const int scol = s.ncol + (s.window ? 1 : 0); // the recorded rows'
    const int maxcol = (rcol > scol ? rcol : scol) > SIM_NCOL + 1 ? (rcol > scol ? rcol : scol) : SIM_NCOL + 1;
    double* row = calloc((size_t)maxcol, sizeof *row);
    double* rec = calloc((size_t)maxcol, sizeof *rec);
    app_out o_csv = {.f = NULL};
    FILE* f = row && rec && out ? app_out_open(&o_csv, out, "w") : NULL;
    if (!row || !rec || (out && !f)) {
        if (!row || !rec) fprintf(stderr, "cranesim replay: out of memory\n");
        else fprintf(stderr, "cranesim replay: cannot write %s: %s\n", out, strerror(errno));
        free(row);
        free(rec);
        free(fmap);
        free(uf);
        engine_destroy(l);
        model_free(m);
        session_free(&s);
        return EXIT_USAGE;
    }
    if (f) session_csv_header(&s, l, f);
    struct sim_energy* en = app_energy_follow("replay", l); // the replay's energy balance, as run's
    sim_trace tr[2] = {{0}, {0}}; // recorded, replayed
    // The table compares both runs' rows as written (%.9g text), so rows that
    // are identical give a difference of exactly 0; --metrics writes the
    // replay's own values.
    run_metrics met[2], exact;
    metrics_init(&met[0], bcol);
    metrics_init(&met[1], bcol);
    metrics_init(&exact, bcol);
    // A chain's metrics by actuator and function (as run --metrics names
    // them: app_design_metrics.h), where the engine's rows carry the model's
    // chain columns right after the base ones (checked by name: else none);
    // the recorded rows' too when they have the same columns.
    bool chain_cols = !m->chain.two_link && m->chain.ncol > 0 && ncol == bcol + m->chain.ncol;
    {
        int nch;
        const sim_channel* ch = engine_channels(l, &nch);
        for (int k = 0; chain_cols && k < m->chain.ncol; ++k)
            chain_cols = bcol + k < nch && !strcmp(ch[bcol + k].name, m->chain.col[k].name);
    }
    if (chain_cols && app_design_metrics_setup(m)) chain_cols = false; // out of memory: the base metrics only
    const bool chain_rec = chain_cols && s.ncol == ncol;
    app_design_run cmet[3]; // recorded, replayed (both as written), replayed exactly (--metrics)
    for (int k = 0; k < 3; ++k) app_design_run_init(&cmet[k], m, bcol);
    long same = 0, first_diff = -1, nrow = 0;
    int code = 0;
    char* line = NULL;
    size_t linecap = 0;
    FILE* mem = NULL;
    for (long i = 0; i < s.ntick; ++i) {
        const session_tick* t = &s.tick[i];
        // As the drive did: hook events, faults at the sampling time, the
        // commands, then the advance to the same target.
        for (int k = 0; k < t->nhook; ++k) engine_hook(l, t->hook[k]);
        if (faults) engine_apply_faults(l, &sc, t->tm);
        // The commands by function as recorded, through the same path as
        // the drive's: the two-link crane's with its limiter.
        session_tick_commands(&s, i, fmap, nfn, uf);
        if (two_link) engine_set_commands(l, uf);
        else engine_set_function_commands(l, uf, nfn, NULL, 0);
        const double now = engine_time(l);
        // The window advances only when its target is ahead; the headless
        // drive always asks.
        if ((!s.window || t->target > now) && engine_advance(l, t->target - now)) {
            fprintf(stderr, "cranesim replay: %s (at tick %ld of %ld)\n", engine_error(l), i + 1, s.ntick);
            code = EXIT_RUNTIME;
            break;
        }
        if (!t->row) continue;
        engine_row(l, row);
        if (s.window) row[ncol] = 0; // segment 0: a session ends at the first reset or rebuild
        // The row's text exactly as the record wrote it.
        // A fresh stream per row: fclose leaves its buffer in line, which
        // open_memstream would otherwise overwrite (a leak per row).
        if (mem) fclose(mem);
        mem = NULL;
        free(line);
        line = NULL;
        mem = open_memstream(&line, &linecap);
        if (!mem) {
            code = EXIT_RUNTIME;
            break;
        }
        sim_csv_row(mem, row, rcol);
        fflush(mem);
        if (f) fputs(line, f);
        const char* recorded = t->row_line >= 0 ? s.rows[t->row_line] : NULL;
        const size_t L = strlen(line);
        if (recorded && L > 0 && !strncmp(line, recorded, L - 1) && recorded[L - 1] == 0) ++same;
        else if (first_diff < 0) first_diff = nrow;
        ++nrow;
        metrics_row(&exact, row);
        if (chain_cols) app_design_row(&cmet[2], row);
        parse_row(line, row, rcol);
        trace_push(&tr[1], row, bcol);
        metrics_row(&met[1], row);
        if (chain_cols) app_design_row(&cmet[1], row);
        if (recorded && parse_row(recorded, rec, scol) >= s.ncol) {
            trace_push(&tr[0], rec, bcol);
            metrics_row(&met[0], rec);
            if (chain_rec) app_design_row(&cmet[0], rec);
        }
        if (!quiet) app_progress(NULL, t->target, s.tick[s.ntick - 1].target);
    }
    if (mem) fclose(mem);
    free(line);
    if (!quiet) app_progress_done();
    int we = app_out_close(&o_csv, 0, true);
    if (we) {
        fprintf(stderr, "cranesim replay: cannot write %s: %s\n", out, strerror(we));
        code = EXIT_RUNTIME;
    }
    // The design replayed on: the recorded one, or what changed.
    char design[1024] = "recorded design";
    if (model_path || nset) {
        size_t L = (size_t)snprintf(design, sizeof design, "changed design:%s%s", model_path ? " --model " : "",
                                    model_path ? model_path : "");
        for (int k = 0; k < nset && L < sizeof design; ++k)
            L += (size_t)snprintf(design + L, sizeof design - L, " --set %s", sets[k]);
    }
    printf("cranesim replay: %s (recorded by the %s drive; %s), %s\n", path, s.window ? "window" : "headless", s.end,
           design);
    printf("  %ld command updates, %ld rows; t = %.6g s\n", s.ntick, nrow, engine_time(l));
    // The functions commanded, by name; one this model has and the session
    // does not command is held at 0 (said, never silent).
    printf("  commands by function (%d):", s.nfn);
    for (int j = 0; j < s.nfn; ++j) printf("%s %s", j ? "," : "", s.fn[j]);
    if (ncommanded < nfn) {
        printf("; held at 0 (not in the session):");
        for (int k = 0, c = 0; k < nfn; ++k)
            if (fmap[k] < 0) printf("%s %s", c++ ? "," : "", engine_function_name(l, k));
    }
    if (dropped[0]) printf("; left out, not in this model and 0 throughout: %s", dropped);
    printf("\n");
    if (!(engine_caps(l) & ENGINE_CAP_LIMITER))
        printf("  rated capacity limiter: none for this crane chain yet (the session records it %s)\n",
               !rcl_recorded ? "not" : rcl_as_recorded ? "on" : "off");
    else if (rcl >= 0 && rcl_recorded)
        printf("  rated capacity limiter %s (--rcl; recorded %s)\n", s.sim.rcl ? "on" : "off",
               rcl_as_recorded ? "on" : "off");
    else if (rcl >= 0)
        printf("  rated capacity limiter %s (--rcl; the session does not record its setting)\n",
               s.sim.rcl ? "on" : "off");
    else if (rcl_recorded)
        printf("  rated capacity limiter %s, as recorded\n", s.sim.rcl ? "on" : "off (measuring only)");
    else
        printf("  rated capacity limiter on: the session does not record its setting (written before it was), "
               "so drive's default; if it was recorded with --rcl off, replay with --rcl off\n");
    if (nrow == s.nrow && same == nrow)
        printf("  rows identical to the recording: %ld of %ld (bit for bit)\n", same, s.nrow);
    else
        printf("  rows identical to the recording: %ld of %ld; first difference at row %ld (t = %.6g s)\n", same,
               s.nrow, first_diff + 1, first_diff >= 0 && first_diff < tr[1].nrow ? tr[1].v[(size_t)first_diff * SIM_NCOL + COL_T] : 0.0);
    // The name column: 27 wide, or the longest chain metric's label.
    const bool chain_table = chain_rec && cmet[0].cst.rows && cmet[1].cst.rows;
    int wname = 27;
    for (int k = 0; chain_table && k < app_design_metric_chain_count(); ++k) {
        const int id = MET_COUNT + k;
        const int L = (int)(strlen(app_design_metric_name(id)) + strlen(app_metric_disp_unit(id)) + 3);
        if (L > wname) wname = L;
    }
    printf("  %-*s %14s %14s %14s\n", wname, "metric (over rows)", "recorded", "replay", "difference");
    for (int id = 0; id < MET_COUNT; ++id) {
        if (!met[1].present[id] || !met[0].rows || !met[1].rows) continue;
        const char* unit;
        const double k = shown(id, &unit);
        char name[64];
        snprintf(name, sizeof name, "%s [%s]", metric_name((metric_id)id), unit);
        printf("  %-*s %14.6g %14.6g %+14.6g\n", wname, name, met[0].value[id] * k, met[1].value[id] * k,
               (met[1].value[id] - met[0].value[id]) * k);
    }
    // Then the chain's by actuator and function, in the summary's units.
    for (int k = 0; chain_table && k < app_design_metric_chain_count(); ++k) {
        const int id = MET_COUNT + k;
        const double sc = app_metric_disp_scale(id);
        const double r0 = app_design_value(&cmet[0], id), r1 = app_design_value(&cmet[1], id);
        char name[128];
        snprintf(name, sizeof name, "%s [%s]", app_design_metric_name(id), app_metric_disp_unit(id));
        printf("  %-*s %14.6g %14.6g %+14.6g\n", wname, name, r0 * sc, r1 * sc, (r1 - r0) * sc);
    }
    app_energy_report(en, "energy of the replay (a session records no balance of the drive):");
    if (out && !we) printf("  %ld rows -> %s\n", nrow, out);
    if (metrics_out) {
        app_out mo = {.f = NULL};
        FILE* mf = app_out_open(&mo, metrics_out, "w");
        int e = mf ? 0 : errno;
        // With a chain's entries by actuator and function, as run --metrics writes them.
        if (mf && (chain_cols ? app_chain_stats_write_json(&cmet[2].cst, &exact, mf) : metrics_write_json(&exact, mf)))
            e = errno ? errno : EIO;
        e = mf ? app_out_close(&mo, e, true) : e;
        if (e) {
            fprintf(stderr, "cranesim replay: cannot write %s: %s\n", metrics_out, strerror(e));
            code = EXIT_RUNTIME;
        } else {
            printf("  metrics -> %s\n", metrics_out);
        }
    }
    if (plot) {
        char title[640];
        snprintf(title, sizeof title, "replay of %s: recorded vs %s", path, model_path || nset ? "changed design" : "replay");
        if (app_plot_compare(&tr[0], "recorded", &tr[1], "replay", title, app_world_has_slew(&s.sim), plot, err, sizeof err)) {
            fprintf(stderr, "cranesim replay: plot: %s\n", err);
            code = EXIT_RUNTIME;
        } else {
            printf("  plot -> %s\n", plot);
        }
    }
    sim_trace_free(&tr[0]);
    sim_trace_free(&tr[1]);
    for (int k = 0; k < 3; ++k) app_design_run_free(&cmet[k]);
    free(row);
    free(rec);
    free(fmap);
    free(uf);
    engine_destroy(l);
    model_free(m);
    session_free(&s);
    return code;
}
