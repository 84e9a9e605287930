// cmd_run.c: `cranesim run`: a headless run of a scenario to CSV (and a plot).
#include "app.h"
#include "energy_acc.h"
#include "engine.h"
#include "metrics.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include "rcl.h"
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
            "  x3,v3,p3A,p3B,u3,u3_cmd,F3 (zeros in the validation world), tip_wx,tip_wy,tip_wz\n"
            "  (the end-arm tip in the world frame, where the rope hangs from), rcl_util (the rated\n"
            "  capacity limiter's utilisation), pad_F1..pad_F4 (N, ground reaction on the outrigger\n"
            "  pads front-left, front-right, rear-left, rear-right) and stab_margin (restoring over\n"
            "  tipping moment, < 1 tips)\n"
            "\n"
            "options:\n"
            "  --out FILE           CSV output (default run.csv); written to a temporary file in its\n"
            "                       folder and renamed over FILE when the run ends (also a failed or\n"
            "                       interrupted one, with the rows so far): until then FILE is untouched\n"
            "  --plot FILE.png      also plot strokes, pressures, valve openings (lift, jib, and the\n"
            "                       slew where the world has one; a chain model: every actuator,\n"
            "                       function and joint by name) and tip path, and the energy per\n"
            "                       component as a bar chart to FILE_energy.png\n"
            "  --metrics FILE.json  also write the run's metrics (peak pressures, relief time, per-relief\n"
            "                       open time, end-stop hits, energy in and losses, hook sway,\n"
            "                       collisions with the bodies involved (ode sandbox), per actuator\n"
            "                       and function of a chain model (peak_pA.NAME, ...), ...;\n"
            "                       docs/sweep.md), replaced as --out is\n"
            "  --energy FILE.csv    per-component hydraulic power [W] at the output period: t, then\n"
            "                       per pump, valve edge (.meter_in, .meter_out), relief, check,\n"
            "                       orifice, hose, cylinder (.leak, .work), shuttle, compensator,\n"
            "                       counterbalance valve, accumulator (.gas), then tank, stored and\n"
            "                       expansion; power taken from the fluid is positive (a pump's is\n"
            "                       negative) and all columns but expansion sum to zero (docs/energy.md)\n"
            "  --rcl on|off         the rated capacity limiter (default on): at 100 %% of the load\n"
            "                       chart it stops lift down, jib out and slewing towards a weaker\n"
            "                       sector (ode runs; a lagrange run only measures); rcl_util is the\n"
            "                       last CSV column of ode runs (docs/safety.md)\n"
            "The summary prints the energy balance of the run in kJ (docs/energy.md); on a chain\n"
            "model its strokes, peak pressures, forces and end-stop hits name every actuator.\n");
    app_common_help(f, true);
    fprintf(f,
            "\nexit codes: 0 ok, 1 runtime failure (a numerical blow-up keeps the rows so far; a failed\n"
            "write), 2 bad input or usage (nothing is written), 130 or 143 stopped by SIGINT (Ctrl-C) or\n"
            "SIGTERM (the rows so far kept; a second signal kills at once)\n"
            "example: cranesim run --scenario ramp --out ramp.csv --plot ramp.png\n");
}


// The rows the plot needs, decimated to a bounded number: a run of up to
// PLOT_FULL rows (every shipped scenario at 1 kHz) keeps every row; a longer
// one keeps, for each bucket of `stride` rows, two rows holding each
// column's minimum and maximum over the bucket (at the bucket's first and
// last time), so a one-row pressure spike still reaches the plot. Without
// --plot nothing is kept (a 600 s sandbox run held 203 MB of rows).
enum { PLOT_FULL = 100000 };
// A chain model's rows are kept wider: the SIM_NCOL base columns, then its
// own (every actuator, function and DOF by name: the plot's page by
// function, app_plot_chain_run).
typedef struct plot_keep {
    sim_trace* tr; ///< NULL: no plot
    long stride;   ///< rows per bucket (1: every row)
    long inb;      ///< rows in the current bucket
    int width;     ///< values a kept row holds: SIM_NCOL + next (0 until the first row)
    int next;      ///< the chain's columns kept after the base ones (0: the two-link crane)
    crane_column* col; ///< their names (a copy: the run's chain lives only until the run returns)
    double *full, *lo, *hi; ///< width values each
    double t0, t1;
    bool oom;
} plot_keep;

// At the first row: the row width, from the chain whose columns the run
// writes (NULL or the two-link shorthand: the base columns only).
static void keep_bind(plot_keep* k, const crane_chain* cc) {
    if (!k->tr || k->width) return;
    if (cc && !cc->two_link && cc->ncol > 0) {
        k->col = malloc((size_t)cc->ncol * sizeof *k->col);
        if (!k->col) {
            k->oom = true;
            return;
        }
        memcpy(k->col, cc->col, (size_t)cc->ncol * sizeof *k->col);
        k->next = cc->ncol;
    }
    k->width = SIM_NCOL + k->next;
    k->full = malloc(3 * (size_t)k->width * sizeof(double));
    if (!k->full) {
        k->oom = true;
        return;
    }
    k->lo = k->full + k->width;
    k->hi = k->lo + k->width;
}

static void keep_free(plot_keep* k) {
    free(k->col);
    free(k->full);
    k->col = NULL;
    k->full = NULL;
}

static void keep_push(plot_keep* k, const double* row) {
    sim_trace* tr = k->tr;
    if (tr->nrow == tr->cap) {
        const int cap = tr->cap ? 2 * tr->cap : 4096;
        double* v = realloc(tr->v, (size_t)cap * (size_t)k->width * sizeof(double));
        if (!v) {
            k->oom = true;
            return;
        }
        tr->v = v;
        tr->cap = cap;
    }
    memcpy(tr->v + (size_t)tr->nrow * (size_t)k->width, row, (size_t)k->width * sizeof(double));
    ++tr->nrow;
}

static void keep_flush(plot_keep* k) {
    if (!k->tr || k->inb == 0) return;
    if (k->inb == 1) {
        keep_push(k, k->lo);
    } else {
        k->lo[COL_T] = k->t0;
        k->hi[COL_T] = k->t1;
        keep_push(k, k->lo);
        keep_push(k, k->hi);
    }
    k->inb = 0;
}

static void keep_row(plot_keep* k, const double* row, int ncol) {
    if (!k->tr || k->oom) return;
    double* full = k->full;
    memset(full, 0, (size_t)k->width * sizeof(double));
    memcpy(full, row, (size_t)ncol * sizeof(double));
    if (k->next) memcpy(full + SIM_NCOL, row + ncol, (size_t)k->next * sizeof(double));
    if (k->stride <= 1) {
        keep_push(k, full);
        return;
    }
    if (k->inb == 0) {
        memcpy(k->lo, full, (size_t)k->width * sizeof(double));
        memcpy(k->hi, full, (size_t)k->width * sizeof(double));
        k->t0 = full[COL_T];
    } else {
        for (int c = 0; c < k->width; ++c) {
            k->lo[c] = fmin(k->lo[c], full[c]);
            k->hi[c] = fmax(k->hi[c], full[c]);
        }
    }
    k->t1 = full[COL_T];
    if (++k->inb == k->stride) keep_flush(k);
}

// The summary's extremes, from every row.
typedef struct row_stats {
    double pmax[4], xmin[2], xmax[2];
    double rcl_max;   ///< largest rated capacity utilisation [-]
    double rcl_t90;   ///< time at or above 90 % of it [s]
    double t_prev;    ///< the previous row's time [s]
    bool rcl_have;
} row_stats;

typedef struct csv_sink {
    const char* path;
    app_out out;
    FILE* f;     ///< opened at the first row
    long rows;
    int ncol;
    /// A chain model's own columns (per actuator, function and degree of
    /// freedom), which its rows carry after the ncol base columns; NULL for
    /// the two-link crane, unless the run slews it in the analytic mode
    /// (then the run's chain, with the slew rack's columns, set by the run).
    const crane_chain* chain;
    int err;     ///< errno of the first failed open or write, 0 if none
    bool opened; ///< the file was created (as a temporary, renamed at the end)
    plot_keep keep;
    row_stats st;
    run_metrics met;
    double t_last; ///< time of the last row written [s]
    rcl* mon;      ///< the limiter's measurement where the rows have no rcl_util (lagrange), or NULL
    bool mon_bound;  ///< a chain's mon was given its rows' layout (rcl_set_chain_row)
    bool chain_util; ///< a chain run whose rows carry the limiter's rcl_util (ode, --rcl on, the chain has one)
    app_chain_stats cst; ///< a chain model's summary and metrics by actuator and function
    bool cst_oom;
} csv_sink;

// The CSV is opened at the first row (t = 0, before any step): a run refused
// while it sets up (a bad world, a start pose, an option sim_run rejects)
// then creates nothing. It is written to a temporary file in the same
// folder, renamed over --out when the run ends (app_out): the previous file
// stays whole until the run has rows to replace it with. A failed write
// stops the run, and so does SIGINT or SIGTERM (after a whole row).
static int csv_row(void* user, const double* row) {
    csv_sink* s = user;
    if (!s->f) {
        s->f = app_out_open(&s->out, s->path, "w");
        if (!s->f) {
            s->err = errno;
            return 1;
        }
        s->opened = true;
        if (s->chain) sim_csv_header_ext(s->f, s->ncol, s->chain->col, s->chain->ncol);
        else sim_csv_header(s->f, s->ncol);
    }
    errno = 0;
    sim_csv_row(s->f, row, s->ncol + (s->chain ? s->chain->ncol : 0));
    ++s->rows;
    s->t_last = row[COL_T];
    if (ferror(s->f)) {
        s->err = errno ? errno : EIO;
        return 1;
    }
    for (int k = 0; k < 4; ++k) s->st.pmax[k] = fmax(s->st.pmax[k], row[COL_P1A + k]);
    for (int k = 0; k < 2; ++k) {
        s->st.xmin[k] = fmin(s->st.xmin[k], row[COL_X1 + k]);
        s->st.xmax[k] = fmax(s->st.xmax[k], row[COL_X1 + k]);
    }
    {
        // The limiter's utilisation: the rows' column (ode), else measured
        // from the row as the limiter measures it (lagrange). A chain run's
        // column is the limiter's only where the run had one (chain_util;
        // else 0, not a measurement); a chain's rows are read from their
        // chain columns on, bound at the first row (the slewing run's
        // columns are set up by then).
        double u = NAN;
        if (s->ncol > COL_RCL_UTIL && (!s->chain || s->chain_util)) u = row[COL_RCL_UTIL];
        else if (s->mon) {
            if (s->mon->chain && !s->mon_bound) s->mon_bound = true, rcl_set_chain_row(s->mon, s->chain, s->ncol);
            if (!s->mon->chain || s->mon->row_base >= 0) u = rcl_utilisation(s->mon, row);
        }
        if (isfinite(u)) {
            if (s->st.rcl_have && u >= RCL_WARN) s->st.rcl_t90 += row[COL_T] - s->st.t_prev;
            s->st.rcl_max = s->st.rcl_have ? fmax(s->st.rcl_max, u) : u;
            s->st.rcl_have = true;
        }
        s->st.t_prev = row[COL_T];
    }
    // Bound at the first row to the columns the run writes (its chain's,
    // which may have the slew rack's besides the model's).
    if (!s->cst.bound && app_chain_stats_bind(&s->cst, s->chain, s->ncol)) s->cst_oom = true;
    app_chain_stats_row(&s->cst, row);
    keep_bind(&s->keep, s->chain);
    keep_row(&s->keep, row, s->ncol);
    metrics_row(&s->met, row);
    return app_signal_caught() != 0;
}

// Close the CSV and put it in place; 0, or the errno of the first failure
// (a full disk often shows only when the last buffer is flushed).
static int csv_close(csv_sink* s) {
    if (!s->f) return s->err;
    s->err = app_out_close(&s->out, s->err, true);
    s->f = NULL;
    return s->err;
}

static void print_summary(const char* scen, const sim_opts* o, const sim_result* r, const row_stats* st,
                          const run_metrics* met, const app_chain_stats* cst, const char* out) {
    const double *pmax = st->pmax, *xmin = st->xmin, *xmax = st->xmax;
    const bool adaptive = o->cvode || hyd_method_is_adaptive(o->solver);
    // The backend names the run and its work (engine_describe).
    engine_desc d;
    engine_describe(o, &d);
    printf("cranesim run: %s, %s", scen, d.label);
    printf(", solver %s", o->cvode ? "cvode" : hyd_method_name(o->solver));
    // Which circuit kernel ran (cranesim run --help, --kernel).
    // The split step runs on the one-pass circuit (standard crane) or on the
    // fast kernel (any other circuit, lagrange_split_gen.c).
    const char* kern = r->split ? (r->fast ? ", split step on the fast kernel" : ", split step")
                       : r->fused ? ", fused kernel" : r->fast ? ", fast kernel" : ", general kernel";
    if (adaptive) printf(" (rtol %g, atol %g%s)\n", o->rtol, o->atol, kern);
    else if (d.h_reduced) // sub-stepped at min(--dt, the outer step)
        printf(" (h = %g ms: --dt %g ms reduced to the ODE step%s)\n", d.dt_outer * 1e3, o->h * 1e3, kern);
    else printf(" (h = %g ms%s)\n", o->h * 1e3, kern);
    char work[200];
    engine_describe_work(o, r, work, sizeof work);
    char speed[32];
    printf("  simulated %.3f s in %.3f s wall: %sx real time; %s\n", r->t_end, r->wall,
           app_fmt_speed(speed, sizeof speed, r->wall > 0 ? r->t_end / r->wall : 0.0), work);
    // A chain model: every actuator by name (its strokes, peak pressures,
    // forces and end-stop hits) instead of the first two by position.
    const bool by_act = cst->nact > 0;
    if (!by_act)
        printf("  strokes: lift %.1f..%.1f mm, jib %.1f..%.1f mm\n", 1e3 * xmin[0], 1e3 * xmax[0], 1e3 * xmin[1],
               1e3 * xmax[1]);
    char rcl_scripted_off[96]; // a backend whose scripted runs only measure the limiter
    snprintf(rcl_scripted_off, sizeof rcl_scripted_off, "measuring only (%s scripted run)", app_backend(o)->name);
    if (st->rcl_have)
        printf("  rated capacity limiter %s: utilisation max %.0f %%, %.3f s at or above 90 %%\n",
               !o->rcl ? "off (measuring only)"
                       : (!app_backend(o)->rcl_scripted ? rcl_scripted_off : "on"),
               100 * st->rcl_max, st->rcl_t90);
    // The peaks over every integration step when sim.c tracked them (between
    // coarse rows the true peak can be far higher than any row's); else
    // (CVODE) over the rows, and said so.
    const double every = app_output_period(o);
    if (by_act) {
        app_chain_stats_print(cst, every, r->t_end, stdout);
    } else if (r->peak_steps) {
        printf("  peak pressures: p1A %.2f, p1B %.2f, p2A %.2f, p2B %.2f MPa (absolute, over every %s)",
               r->p_peak[0] * 1e-6, r->p_peak[1] * 1e-6, r->p_peak[2] * 1e-6, r->p_peak[3] * 1e-6, d.step_name);
    } else {
        printf("  peak pressures at the output rows: p1A %.2f, p1B %.2f, p2A %.2f, p2B %.2f MPa (absolute)",
               pmax[0] * 1e-6, pmax[1] * 1e-6, pmax[2] * 1e-6, pmax[3] * 1e-6);
        // The rows come every `every`, but never farther apart than the run.
        if (every > 1e-3 * (1 + 1e-9)) printf(", rows every %g ms", fmin(every, r->t_end) * 1e3);
    }
    if (!by_act) printf("\n");
    app_chain_metrics_print(cst, met, stdout);
    printf("  %ld rows -> %s\n", r->rows, out);
}

// FILE.png -> FILE_energy.png (the bar chart next to the run's plot);
// false for a plot that is not a .png file name (a device or a pipe such
// as /dev/stdout, which app_check_output lets through): no chart then.
static bool energy_png(const char* plot, char* buf, size_t n) {
    const size_t len = strlen(plot);
    if (len < 4 || strcmp(plot + len - 4, ".png")) return false;
    snprintf(buf, n, "%.*s_energy.png", (int)(len - 4), plot);
    return true;
}

// The losses per component over the run [kJ], largest first (valve edges
// and a cylinder's leakage are summed per component).
static int plot_energy(const sim_energy* en, const char* title, const char* png, char* err, size_t errsz) {
    enum { MAXBAR = 64 };
    static char names[MAXBAR][72];
    const char* np[MAXBAR];
    double kj[MAXBAR];
    int n = 0;
    for (int i = 0; i < sim_energy_ncol(en); ++i) {
        const sim_energy_group g = sim_energy_col_group(en, i);
        if (g < SIM_EG_VALVE_IN || g > SIM_EG_OTHER) continue;
        char base[72];
        snprintf(base, sizeof base, "%s", sim_energy_col_name(en, i));
        char* dot = g == SIM_EG_VALVE_IN || g == SIM_EG_VALVE_OUT || g == SIM_EG_LEAK ? strrchr(base, '.') : NULL;
        if (dot) *dot = 0;
        int k = 0;
        while (k < n && strcmp(names[k], base)) ++k;
        if (k == n) {
            if (n == MAXBAR) continue;
            snprintf(names[n], sizeof names[n], "%s", base);
            kj[n++] = 0.0;
        }
        kj[k] += 1e-3 * sim_energy_col_energy(en, i);
    }
    for (int i = 1; i < n; ++i) // insertion sort, largest first
        for (int j = i; j > 0 && kj[j] > kj[j - 1]; --j) {
            char t[72];
            memcpy(t, names[j], sizeof t);
            memcpy(names[j], names[j - 1], sizeof t);
            memcpy(names[j - 1], t, sizeof t);
            const double v = kj[j];
            kj[j] = kj[j - 1];
            kj[j - 1] = v;
        }
    for (int i = 0; i < n; ++i) np[i] = names[i];
    return app_plot_energy(np, kj, n, title, png, err, errsz);
}

int cmd_run(int argc, char** argv) {
    app_common c = {.sim = sim_default_opts()};
    const char* out = "run.csv";
    const char* plot = NULL;
    const char* energy_csv = NULL;
    const char* metrics_out = NULL;
    bool rcl_on = true;
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
        if (!strcmp(argv[i], "--energy")) {
            energy_csv = app_value(argc, argv, &i);
            if (!energy_csv) return EXIT_USAGE;
            continue;
        }
        if (!strcmp(argv[i], "--metrics")) {
            if (!(metrics_out = app_value(argc, argv, &i))) return EXIT_USAGE;
            continue;
        }
        if (!strcmp(argv[i], "--rcl")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if (strcmp(v, "on") && strcmp(v, "off")) {
                fprintf(stderr, "cranesim run: --rcl: expected on or off, got '%s'\n", v);
                return EXIT_USAGE;
            }
            rcl_on = !strcmp(v, "on");
            continue;
        }
        fprintf(stderr, "cranesim run: unknown option '%s' (see cranesim run --help)\n", argv[i]);
        return EXIT_USAGE;
    }
    // Everything that can be checked is checked before a file is touched.
    if (app_check_output("run", "--out", out, NULL) || (plot && app_check_output("run", "--plot", plot, ".png")) ||
        (energy_csv && app_check_output("run", "--energy", energy_csv, NULL)) ||
        (metrics_out && app_check_output("run", "--metrics", metrics_out, ".json")) ||
        app_check_distinct("run", (const char* const[]){"--out", "--plot", "--energy", "--metrics"},
                           (const char* const[]){out, plot, energy_csv, metrics_out}, 4))
        return EXIT_USAGE;
    int rc = app_check_sim("run", &c.sim, c.given);
    if (rc) return rc;
    model* m;
    scenario sc;
    rc = app_load(&c, &m, &sc);
    if (rc) return rc;
    // A sandbox scenario runs in the sandbox unless the options say otherwise.
    bool switched;
    rc = app_scenario_world("run", &c.sim, c.given, m, &sc, true, &switched);
    if (!rc && switched) rc = app_check_sim("run", &c.sim, c.given);
    if (rc) {
        model_free(m);
        return rc;
    }
    app_note_unused("run", c.given, &c.sim, 1);
    app_note_load("run", &c, &c.sim, &sc);
    {
        // A fixed step so small that the run takes minutes: say so up front
        // (a Krus step of the crane costs at least 0.25 us on this class of
        // machine, docs/performance.md), rather than leave a silent terminal.
        const double dur = c.sim.duration > 0 ? c.sim.duration : sc.duration;
        const bool fixed = !c.sim.cvode && !hyd_method_is_adaptive(c.sim.solver);
        const double steps = fixed ? dur / c.sim.h : 0.0;
        // Beyond 1e12 steps the run is refused below, with its own line.
        if (steps > 1e8 && steps <= 1e12)
            fprintf(stderr, "cranesim run: note: %.3g steps of %g s: at least %.3g s of wall time\n", steps, c.sim.h,
                    steps * 0.25e-6);
    }
    app_settle_unused(&c.sim);
    c.sim.rcl = rcl_on;

    csv_sink sink = {.path = out, .ncol = sim_ncol(&c.sim), .chain = m->chain.ncol > 0 ? &m->chain : NULL,
                     .st = {.xmin = {INFINITY, INFINITY}, .xmax = {-INFINITY, -INFINITY}}};
    static rcl mon;
    // A crane chain's limiter searches every joint for its chart (about a
    // second): measured only where the run asks for the limiter.
    const bool chain_model = !m->chain.two_link;
    char lerr[400];
    if (sink.ncol <= COL_RCL_UTIL && (!chain_model || c.sim.rcl)) {
        if (rcl_init(&mon, m, NULL, lerr, sizeof lerr) == 0) sink.mon = &mon;
    }
    sink.chain_util = chain_model && sink.ncol > COL_RCL_UTIL && c.sim.rcl && !rcl_check_model(m, lerr, sizeof lerr);
    metrics_init(&sink.met, sink.ncol);
    sim_trace tr = {0};
    if (plot) {
        sink.keep.tr = &tr;
        // Rows the run will write: one per output period, plus the first.
        const double dur = c.sim.duration > 0 ? c.sim.duration : sc.duration;
        const double rows = dur / app_output_period(&c.sim) + 1.0;
        sink.keep.stride = rows > PLOT_FULL ? (long)ceil(rows / (PLOT_FULL / 2)) : 1;
    }
    sim_result res;
    // The energy balance for the summary, the --energy CSV and the bar chart
    // (docs/energy.md says what it costs).
    sim_energy* en = sim_energy_create();
    app_out eout = {0};
    FILE* ef = NULL;
    if (!en) {
        fprintf(stderr, "cranesim run: out of memory\n");
        model_free(m);
        return EXIT_RUNTIME;
    }
    if (energy_csv) {
        ef = app_out_open(&eout, energy_csv, "w");
        if (!ef) {
            fprintf(stderr, "cranesim run: cannot write %s: %s\n", energy_csv, strerror(errno));
            sim_energy_free(en);
            model_free(m);
            return EXIT_USAGE;
        }
        sim_energy_csv(en, ef, app_output_period(&c.sim));
    }
    // SIGINT (Ctrl-C) or SIGTERM: the run stops after the row being written
    // and the CSV is closed and put in place with every row so far; a second
    // signal kills at once (SA_RESETHAND).
    app_signals sig;
    app_signals_catch(&sig);
    // A run with columns of its own (the analytic mode's slewing run: the
    // slew rack's) puts its chain in sink.chain before the first row.
    const crane_chain* model_chain = sink.chain;
    sim_run_energy_chain(m, &sc, &c.sim, csv_row, &sink, NULL, c.quiet ? NULL : app_progress, NULL, en, &sink.chain,
                         &res);
    sink.chain = model_chain; // the run's chain lives only until the run returns
    keep_flush(&sink.keep);
    metrics_finish(&sink.met, &res);
    metrics_energy(&sink.met, en);
    if (!c.quiet) app_progress_done();
    if (res.note[0] && !app_signal_caught()) fprintf(stderr, "cranesim run: note: %s\n", res.note);
    const int werr = csv_close(&sink);
    // The energy CSV is kept when the run's CSV is (a run refused at its
    // start leaves neither).
    int eerr = ef ? app_out_close(&eout, ferror(ef) ? EIO : 0, sink.opened) : 0;
    app_signals_restore(&sig);
    int code = EXIT_OK_;
    if (werr && !sink.opened) {
        // The path passed app_check_output, yet could not be created: still
        // bad input, and nothing was written.
        fprintf(stderr, "cranesim run: cannot write %s: %s\n", out, strerror(werr));
        code = EXIT_USAGE;
    } else if (app_signal_caught() && res.status == SIM_REFUSED && sink.opened) {
        // Interrupted: 128 + the signal, as a shell reports a process the
        // signal ended, but with the rows in place (decision in docs).
        if (werr) fprintf(stderr, "cranesim run: cannot write %s: %s\n", out, strerror(werr));
        else
            fprintf(stderr, "cranesim run: interrupted (%s) at t = %.6g s; %ld rows kept in %s\n",
                    app_signal_name(app_signal_caught()), sink.t_last, sink.rows, out);
        code = 128 + app_signal_caught();
    } else if (app_signal_caught() && res.status == SIM_REFUSED) {
        // Interrupted while setting up (a long mesh load): nothing written.
        fprintf(stderr, "cranesim run: interrupted (%s) while setting up; nothing written\n",
                app_signal_name(app_signal_caught()));
        code = 128 + app_signal_caught();
    } else if (res.status == SIM_FAILED) {
        fprintf(stderr, "cranesim run: %s; %ld rows up to t = %.6g s kept in %s\n", res.message, res.rows,
                res.t_end, out);
        if (werr) fprintf(stderr, "cranesim run: cannot write %s: %s\n", out, strerror(werr));
        code = EXIT_RUNTIME;
    } else if (werr) {
        fprintf(stderr, "cranesim run: cannot write %s: %s\n", out, strerror(werr));
        code = EXIT_RUNTIME;
    } else if (res.status == SIM_REFUSED) {
        // Refused while setting up: no row was written, so no file exists.
        fprintf(stderr, "cranesim run: %s\n", res.message);
        code = app_exit_code(res.status, sink.rows);
    }
    if (eerr && code == EXIT_OK_) {
        fprintf(stderr, "cranesim run: cannot write %s: %s\n", energy_csv, strerror(eerr));
        code = EXIT_RUNTIME;
    }
    if (sink.cst_oom && code == EXIT_OK_) {
        fprintf(stderr, "cranesim run: out of memory for the summary by actuator\n");
        code = EXIT_RUNTIME;
    }
    if (sink.keep.oom && code == EXIT_OK_) {
        fprintf(stderr, "cranesim run: plot: out of memory for the plotted rows\n");
        code = EXIT_RUNTIME;
    }
    sim_energy_balance eb;
    sim_energy_result(en, &eb);
    if (code == EXIT_OK_ && !c.quiet) {
        print_summary(sc.name[0] ? sc.name : c.scenario_path, &c.sim, &res, &sink.st, &sink.met, &sink.cst, out);
        if (eb.samples > 1) app_print_energy(en, &eb, NULL);
        if (energy_csv) printf("  energy -> %s\n", energy_csv);
    }
    // The metrics of the rows written (also of a failed or interrupted run's).
    if (metrics_out && sink.rows > 0 && code != EXIT_USAGE) {
        app_out mo;
        FILE* f = app_out_open(&mo, metrics_out, "w");
        int e = f ? 0 : errno;
        if (f && app_chain_stats_write_json(&sink.cst, &sink.met, f)) e = errno ? errno : EIO;
        if (f) e = app_out_close(&mo, e, true);
        if (e) {
            fprintf(stderr, "cranesim run: cannot write %s: %s\n", metrics_out, strerror(e));
            if (code == EXIT_OK_) code = EXIT_RUNTIME;
        } else if (!c.quiet && code == EXIT_OK_) {
            printf("  metrics -> %s\n", metrics_out);
        }
    }
    if (plot && tr.nrow > 1 && code != EXIT_USAGE && !app_signal_caught()) {
        char err[512], title[256];
        engine_desc d;
        engine_describe(&c.sim, &d);
        snprintf(title, sizeof title, "%s: %s, %s", sc.name, d.title,
                 c.sim.cvode ? "cvode" : hyd_method_name(c.sim.solver));
        // A chain model: its page by actuator and function; else the
        // two-link crane's plot as it always was.
        const int prc = sink.keep.next
                            ? app_plot_chain_run(tr.v, tr.nrow, sink.keep.width, sink.keep.col, sink.keep.next,
                                                 app_world_has_slew(&c.sim), title, plot, err, sizeof err)
                            : app_plot_run(&tr, title, app_world_has_slew(&c.sim), plot, err, sizeof err);
        if (prc) {
            fprintf(stderr, "cranesim run: plot: %s\n", err);
            if (code == EXIT_OK_) code = EXIT_RUNTIME;
        } else if (!c.quiet) {
            printf("  plot -> %s\n", plot);
        }
        char epng[1100];
        if (energy_png(plot, epng, sizeof epng) && eb.samples > 1 && code == EXIT_OK_) {
            snprintf(title + strlen(title), sizeof title - strlen(title), ": losses per component");
            if (plot_energy(en, title, epng, err, sizeof err)) {
                fprintf(stderr, "cranesim run: plot: %s\n", err);
                code = EXIT_RUNTIME;
            } else if (!c.quiet) {
                printf("  energy plot -> %s\n", epng);
            }
        }
    }
    app_chain_stats_free(&sink.cst);
    keep_free(&sink.keep);
    sim_energy_free(en);
    sim_trace_free(&tr);
    if (sink.mon) rcl_free(sink.mon);
    model_free(m);
    return code;
}
