// test_engine_chain_step.c: the stepped engines of crane chains
// (engine_create of a chain model: lagrange/engine_chain_step.c on
// chain_sim, ode/engine_ode_chain_step.c on the ODE chain world), on
// chain_3boom_ext.json (4 functions) and chain_8fn_10link.json (8 functions,
// 10 bodies), both backends:
// (a) the scripted operator (engine_play_functions) stepping the engine
//     through the model's *_all scenario gives the rows of engine_run's
//     scripted run of that scenario. The ode world: one frame per ODE step,
//     commands at its midpoint, as the run's own player: the same rows to
//     1e-12 of each column's peak (bit for bit in fact). The analytic mode's
//     scripted run reads the ramps continuously inside f, a stepped engine
//     holds each frame's command: on a scenario whose commands are held
//     (constant from t = 0) the two agree to 1e-12 of each column's peak; on
//     the ramps the difference is measured and printed (held vs continuous
//     commands, O(h) in the command), not asserted;
// (b) with every valve closed from the start-hold pressures the crane stays
//     at rest: every actuator's stroke within 0.1 mm over 5 s (equilibrium;
//     checked on the 3-boom model, printed on the 8-function one, whose two
//     cylinders on one valve trade oil);
// (c) a command vector of the wrong length, an unknown function: refused,
//     one line, nothing set; the channels and columns are the chain's.
#include "check.h"
#include "app/cli_util.h"
#include "channels.h"
#include "engine.h"
#include "lagrange.h"
#include "model.h"
#include "scenario.h"
#include "sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define DATA CRANESIM_TESTDATA

typedef struct chain_case {
    const char* model;
    const char* scenario;
} chain_case;

static const chain_case g_cases[] = {
    {DATA "/chain_3boom_ext.json", DATA "/chain_3boom_ext_all.json"},
    {DATA "/chain_8fn_10link.json", DATA "/chain_8fn_10link_all.json"},
};

// Rows of ncol columns, as they come.
typedef struct rows {
    int ncol;
    long n, cap;
    double* v;
} rows;

static int keep(void* user, const double* row) {
    rows* r = user;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 1024;
        double* v = realloc(r->v, (size_t)r->cap * (size_t)r->ncol * sizeof *v);
        if (!v) return 1;
        r->v = v;
    }
    memcpy(r->v + (size_t)r->n * (size_t)r->ncol, row, (size_t)r->ncol * sizeof *row);
    ++r->n;
    return 0;
}

static model* load(const char* path) {
    char err[1024];
    model* m = model_load(path, NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    return m;
}

static sim_opts opts(sim_mechanics mech) {
    sim_opts o = sim_default_opts();
    o.mechanics = mech;
    o.no_step_probe = true; // the default step; test_step_probe tests the probe
    return o;
}

static const char* bname(sim_mechanics mech) { return mech == SIM_ODE ? "ode" : "lagrange"; }

// The scripted run's rows (engine_run), every dt_out.
static int scripted(const model* m, const scenario* sc, const sim_opts* o, rows* out, char* err, size_t n) {
    int nc;
    engine_channels_for(o, &nc);
    out->ncol = nc + m->chain.ncol;
    engine_sink k = {.row = keep, .user = out, .rows = true, .t_end = o->duration > 0 ? o->duration : sc->duration};
    sim_result res;
    memset(&res, 0, sizeof res);
    const int rc = engine_run(m, sc, o, &k, &res);
    if (rc) snprintf(err, n, "%s", res.message);
    return rc;
}

// The stepped engine driven by the scripted operator: commands of every
// function at each frame's middle (engine_play_functions), advance to the
// frame's end; a row every frame.
static int stepped(const model* m, const scenario* sc, const sim_opts* o, double frame, rows* out, char* err,
                   size_t n) {
    engine* e = engine_create(m, o, sc->q0, sc->slew0, sim_load_mass(m, sc, o), err, n);
    if (!e) return -1;
    out->ncol = engine_ncol(e);
    const int nfn = engine_nfunction(e);
    double* u = calloc((size_t)nfn + 1, sizeof *u);
    const double t_end = o->duration > 0 ? o->duration : sc->duration;
    const long nframes = (long)(t_end / frame + 0.5);
    int ev = 0, rc = u ? 0 : -1;
    for (long i = 0; i < nframes && !rc; ++i) {
        // The frame's middle as the ode run computes it, (i + 1/2) dt: not
        // engine_time + dt/2, which rounds differently.
        engine_play_functions(e, sc, ((double)i + 0.5) * frame, &ev, u, NULL, NULL);
        rc = engine_set_function_commands(e, u, nfn, err, n);
        if (!rc) rc = engine_advance_to(e, (double)(i + 1) * frame, keep, out);
        if (rc > 0) snprintf(err, n, "%s", engine_error(e));
    }
    free(u);
    engine_destroy(e);
    return rc;
}

// The largest difference of the scripted rows s (every dt_out, from t = 0)
// and the stepped rows d (every frame, from the first frame's end), at the
// scripted times, over each column's peak |value| in s; *at: that column.
static double max_rel_diff(const rows* s, const rows* d, double dt_out, double frame, int* at, long* compared) {
    const int nc = s->ncol < d->ncol ? s->ncol : d->ncol;
    double* peak = calloc((size_t)nc, sizeof *peak);
    double worst = 0.0;
    *compared = 0;
    *at = -1;
    if (!peak) return INFINITY;
    for (long i = 0; i < s->n; ++i)
        for (int c = 0; c < nc; ++c) peak[c] = fmax(peak[c], fabs(s->v[(size_t)i * (size_t)s->ncol + (size_t)c]));
    const long per = (long)(dt_out / frame + 0.5);
    for (long i = 1; i < s->n; ++i) {
        const long j = i * per - 1;
        if (j >= d->n) break;
        const double* a = s->v + (size_t)i * (size_t)s->ncol;
        const double* b = d->v + (size_t)j * (size_t)d->ncol;
        ++*compared;
        for (int c = 0; c < nc; ++c) {
            const double r = fabs(a[c] - b[c]) / (peak[c] > 0 ? peak[c] : 1.0);
            if (!(r <= worst)) worst = r, *at = c;
        }
    }
    free(peak);
    return worst;
}

// The engine's channels: the backend's, then the chain's own columns by
// name, as many as its rows have (engine_ncol), as the scripted run's CSV.
static void check_channels(const model* m, const sim_opts* o, const engine* e) {
    int n, nb;
    const sim_channel* ch = engine_channels(e, &n);
    engine_channels_for(o, &nb);
    CHECK(n == engine_ncol(e) && n == nb + m->chain.ncol, "%s: %d channels, ncol %d, expected %d + %d",
          bname(o->mechanics), n, engine_ncol(e), nb, m->chain.ncol);
    int bad = 0;
    for (int c = 0; c < n && c < nb; ++c) bad += strcmp(ch[c].name, sim_channels[c].name) != 0;
    for (int c = nb; c < n; ++c) bad += strcmp(ch[c].name, m->chain.col[c - nb].name) != 0;
    CHECK(bad == 0, "%s: %d channel names differ from the run's columns", bname(o->mechanics), bad);
}

// (a) on the ramps of the *_all scenario.
static void test_play_matches_run(void) {
    for (size_t ci = 0; ci < sizeof g_cases / sizeof g_cases[0]; ++ci) {
        const chain_case* cs = &g_cases[ci];
        model* m = load(cs->model);
        scenario sc;
        char err[1024];
        CHECK(scenario_load(cs->scenario, &sc, err, sizeof err) == 0, "%s", err);
        if (!m) continue;
        for (int b = 0; b < 2; ++b) {
            const sim_mechanics mech = b ? SIM_ODE : SIM_LAGRANGE;
            sim_opts o = opts(mech);
            // The analytic mode on the 8-function scenario: from t = 3 s
            // (ext3 moving) the motion amplifies the difference of held and
            // continuous commands a thousandfold within 50 ms, and Krus at
            // 0.1 ms fails near 4.8 s (stepped) and 7.9 s (run): compared
            // up to 2.9 s (held commands agree exactly throughout,
            // test_held_commands_match_run).
            if (!b && ci == 1) o.duration = 2.9;
            // ode: one frame per ODE step, the run's own player; lagrange:
            // one frame per solver step (the closest a held command comes
            // to the run's continuous one).
            const double frame = b ? (o.dt_ode > 0 ? o.dt_ode : 1e-3) : o.h;
            rows s = {0}, d = {0};
            const int rs = scripted(m, &sc, &o, &s, err, sizeof err);
            CHECK(rs == 0, "%s %s: run: %s", m->name, bname(mech), err);
            const int rd = stepped(m, &sc, &o, frame, &d, err, sizeof err);
            CHECK(rd == 0, "%s %s: stepped: %s", m->name, bname(mech), err);
            CHECK(s.ncol == d.ncol, "%s: columns: run %d, stepped %d", bname(mech), s.ncol, d.ncol);
            int at;
            long nc;
            const double r = max_rel_diff(&s, &d, o.dt_out, frame, &at, &nc);
            printf("  %-28.28s %-8s %ld rows compared: largest difference %.3g of the column's peak (%s)\n",
                   cs->model + strlen(DATA) + 1, bname(mech), nc, r, at >= 0 && at < sim_ncol(&o) ? sim_col_name[at]
                   : at >= 0 ? m->chain.col[at - sim_ncol(&o)].name : "-");
            CHECK(nc >= (long)((o.duration > 0 ? o.duration : sc.duration) / o.dt_out) - 1, "%s: %ld rows compared",
                  bname(mech), nc);
            if (b) CHECK(r <= 1e-12, "ode: stepped and scripted rows differ by %g of the peak", r);
            // The analytic mode's ramps: held against continuous commands.
            // Bounded only loosely (the same motion: 2 % of any column's
            // peak), the figure is printed.
            else CHECK(r < 0.02, "lagrange: stepped and scripted rows differ by %g of the peak", r);
            free(s.v);
            free(d.v);
        }
        model_free(m);
    }
}

// (a) with held commands: every function at a constant opening from t = 0
// (no ramp): the analytic mode's stepped and scripted paths take the same
// steps with the same commands.
static void test_held_commands_match_run(void) {
    for (size_t ci = 0; ci < sizeof g_cases / sizeof g_cases[0]; ++ci) {
        const chain_case* cs = &g_cases[ci];
        model* m = load(cs->model);
        scenario sc0;
        char err[1024];
        CHECK(scenario_load(cs->scenario, &sc0, err, sizeof err) == 0, "%s", err);
        if (!m) continue;
        // The same start and load; each function at +-0.3, 0.4, ... held.
        char path[512];
        snprintf(path, sizeof path, "held_%zu.json", ci);
        FILE* f = fopen(path, "w");
        CHECK(f != NULL, "cannot write %s", path);
        if (!f) {
            model_free(m);
            continue;
        }
        fprintf(f, "{\"name\": \"held\", \"duration\": 1.5, \"load_mass\": %g, \"initial\": {\"q1_deg\": %.17g, "
                   "\"q2_deg\": %.17g}, \"commands\": {",
                sc0.load_mass, sc0.q0[0] * 180 / M_PI, sc0.q0[1] * 180 / M_PI);
        for (int k = 0; k < m->chain.nfn; ++k)
            fprintf(f, "%s\"%s\": [[0, %g], [10, %g]]", k ? ", " : "", m->chain.fn[k].name,
                    (k % 2 ? -1 : 1) * (0.3 + 0.05 * k), (k % 2 ? -1 : 1) * (0.3 + 0.05 * k));
        fprintf(f, "}}\n");
        fclose(f);
        scenario sc;
        CHECK(scenario_load(path, &sc, err, sizeof err) == 0, "%s", err);
        remove(path);
        sim_opts o = opts(SIM_LAGRANGE);
        rows s = {0}, d = {0};
        CHECK(scripted(m, &sc, &o, &s, err, sizeof err) == 0, "run: %s", err);
        CHECK(stepped(m, &sc, &o, o.dt_out, &d, err, sizeof err) == 0, "stepped: %s", err);
        int at;
        long nc;
        const double r = max_rel_diff(&s, &d, o.dt_out, o.dt_out, &at, &nc);
        printf("  %-28.28s lagrange held commands, %ld rows: largest difference %.3g of the column's peak\n",
               cs->model + strlen(DATA) + 1, nc, r);
        CHECK(nc >= 140 && r <= 1e-12, "lagrange held: %ld rows, difference %g of the peak (column %d)", nc, r, at);
        free(s.v);
        free(d.v);
        model_free(m);
    }
}

// (b) every valve closed from the start-hold pressures: at rest for 5 s.
static void test_closed_valves_hold(void) {
    for (size_t ci = 0; ci < sizeof g_cases / sizeof g_cases[0]; ++ci) {
        const chain_case* cs = &g_cases[ci];
        model* m = load(cs->model);
        scenario sc;
        char err[1024];
        CHECK(scenario_load(cs->scenario, &sc, err, sizeof err) == 0, "%s", err);
        if (!m) continue;
        for (int b = 0; b < 2; ++b) {
            const sim_opts o = opts(b ? SIM_ODE : SIM_LAGRANGE);
            engine* e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
            CHECK(e != NULL, "%s: %s", bname(o.mechanics), err);
            if (!e) continue;
            const int nc = engine_ncol(e), nb = nc - m->chain.ncol;
            int nch;
            const sim_channel* ch = engine_channels(e, &nch);
            double* row = calloc((size_t)(nc > SIM_NCOL ? nc : SIM_NCOL), sizeof *row);
            double* x0 = calloc((size_t)nc, sizeof *x0);
            double* u = calloc((size_t)engine_nfunction(e) + 1, sizeof *u);
            if (!row || !x0 || !u) {
                free(row), free(x0), free(u);
                engine_destroy(e);
                continue;
            }
            engine_row(e, row);
            memcpy(x0, row, (size_t)nc * sizeof *x0);
            CHECK(engine_set_function_commands(e, u, engine_nfunction(e), err, sizeof err) == 0, "%s", err);
            double worst = 0;
            int wc = -1;
            for (int i = 0; i < 500; ++i) {
                CHECK(engine_advance_to(e, 0.01 * (i + 1), NULL, NULL) == 0, "%s", engine_error(e));
                engine_row(e, row);
                for (int c = nb; c < nc; ++c)
                    if (!strncmp(ch[c].name, "x_", 2) && !(fabs(row[c] - x0[c]) <= worst))
                        worst = fabs(row[c] - x0[c]), wc = c;
            }
            printf("  %-28.28s %-8s valves closed 5 s: largest stroke change %.4f mm (%s)\n",
                   cs->model + strlen(DATA) + 1, bname(o.mechanics), worst * 1e3, wc >= 0 ? ch[wc].name : "-");
            CHECK(engine_time(e) > 4.999, "%s: stopped at %g s", bname(o.mechanics), engine_time(e));
            // A known gap of the model, not of the engines (the scripted
            // runs do the same; measured, printed, reported, not checked):
            // the 8-function model's ext1 and ext2 share a valve and trade
            // oil under the smoothed friction (0.74 mm analytic, 0.46 mm in
            // the chain world with its seal friction held by ODE).
            const bool gap = ci == 1;
            if (gap) printf("  (known gap, not checked: two cylinders on one valve trade oil)\n");
            else CHECK(worst <= 1e-4, "%s %s: a stroke moved %.4f mm with every valve closed", m->name,
                       bname(o.mechanics), worst * 1e3);
            free(row);
            free(x0);
            free(u);
            engine_destroy(e);
        }
        model_free(m);
    }
}

static const char* out_dir(void) {
    static char d[512];
    if (!d[0]) {
        snprintf(d, sizeof d, "%s/tests/world/engine_chain_step", CRANESIM_BINARY_DIR);
        mkdir(d, 0755);
    }
    return d;
}

// The first line of file path into buf; "" when it cannot be read.
static const char* first_line(const char* path, char* buf, size_t n) {
    buf[0] = 0;
    FILE* f = fopen(path, "r");
    if (f) {
        if (!fgets(buf, (int)n, f)) buf[0] = 0;
        fclose(f);
    }
    return buf;
}

// The command line: a chain model drives headless (its CSV has the run's
// columns) and soaks; what is two-link shaped refuses it, one line, exit 2,
// before anything starts.
static void test_command_line(void) {
    const char* mdl = g_cases[0].model;
    const char* scn = g_cases[0].scenario;
    static char args[4096], out[8192], h1[8192], h2[8192];
    char drv[600], run[600];
    snprintf(drv, sizeof drv, "%s/drive.csv", out_dir());
    snprintf(run, sizeof run, "%s/run.csv", out_dir());
    for (int b = 0; b < 2; ++b) {
        const char* mech = b ? "ode --world validation" : "lagrange";
        snprintf(args, sizeof args,
                 "drive --headless --quiet --model %s --scenario %s --mechanics %s --duration 0.2 --frame-rate 100 "
                 "--rcl off --record %s",
                 mdl, scn, mech, drv);
        int rc = cli_run(args, out, sizeof out);
        CHECK(rc == 0 && strstr(out, "final: strokes lift "), "drive %s: exit %d: %s", mech, rc, out);
        snprintf(args, sizeof args, "run --quiet --model %s --scenario %s --mechanics %s --duration 0.2 --out %s", mdl,
                 scn, mech, run);
        rc = cli_run(args, out, sizeof out);
        CHECK(rc == 0, "run %s: exit %d: %s", mech, rc, out);
        CHECK(first_line(drv, h1, sizeof h1)[0] && !strcmp(h1, first_line(run, h2, sizeof h2)) &&
                  strstr(h1, ",x_ext,") && strstr(h1, ",ucmd_jib2,"),
              "drive %s header:\n%s\nrun header:\n%s", mech, h1, h2);
    }
    // Default --rcl on: this chain has no rating, so it runs without a
    // limiter, and says why.
    snprintf(args, sizeof args, "drive --headless --model %s --scenario %s --mechanics lagrange --duration 0.1", mdl,
             scn);
    int rc = cli_run(args, out, sizeof out);
    CHECK(rc == 0 && strstr(out, "rated capacity limiter: none for this crane chain (") &&
                  strstr(out, "mechanics.rated_moment"), "exit %d: %s", rc, out);
    static const struct {
        const char* args;
        const char* says;
    } refuse[] = {
        {"drive --headless --mechanics lagrange --rcl on", "cranesim drive: --rcl on: "},
        {"serve --mechanics lagrange --listen 127.0.0.1:0", "cranesim serve: the serve protocol: "},
        {"serve --world validation --listen 127.0.0.1:0", "cranesim serve: the serve protocol: "},
    };
    for (size_t i = 0; i < sizeof refuse / sizeof refuse[0]; ++i) {
        snprintf(args, sizeof args, "%s --model %s --scenario %s --duration 0.1", refuse[i].args, mdl, scn);
        rc = cli_run(args, out, sizeof out);
        const char* line = strstr(out, refuse[i].says);
        CHECK(rc == 2 && line && cli_count_lines(line) == 1, "%s: exit %d: %s", refuse[i].args, rc, out);
    }
    // Session files carry commands by function (docs/replay.md; test_replay
    // replays chain drives bit for bit): a two-link drive's session on the
    // chain model gives lift and jib to the functions of those names, holds
    // the chain's others at 0 and leaves out its slew, never commanded
    // outside the sandbox and not a function of this lagrange chain.
    char sess[600];
    snprintf(sess, sizeof sess, "%s/two_link.session", out_dir());
    snprintf(args, sizeof args, "drive --headless --quiet --mechanics lagrange --duration 0.2 --session %s", sess);
    rc = cli_run(args, out, sizeof out);
    CHECK(rc == 0, "two-link session: exit %d: %s", rc, out);
    snprintf(args, sizeof args, "replay %s --quiet --model %s", sess, mdl);
    rc = cli_run(args, out, sizeof out);
    CHECK(rc == 0 && strstr(out, "held at 0 (not in the session): jib2, ext") &&
              strstr(out, "left out, not in this model and 0 throughout: slew"),
          "replay: exit %d: %s", rc, out);
    // The window, before it opens (a build without the render module says
    // that instead).
    snprintf(args, sizeof args, "drive --screenshot %s/never.png --model %s --world validation", out_dir(), mdl);
    rc = cli_run(args, out, sizeof out);
    const char* wl = strstr(out, "cranesim drive: the window (--headless runs a crane chain): ");
    if (!wl) wl = strstr(out, "needs the render module");
    CHECK(rc == 2 && wl && cli_count_lines(wl) == 1, "window: exit %d: %s", rc, out);
    // The soak runs the chain in the sandbox (four functions and the slew):
    // test_engine_sandbox_chain_step.
    snprintf(args, sizeof args, "bench --config soak --model %s --duration 1", mdl);
    rc = cli_run(args, out, sizeof out);
    CHECK(rc == 0 && strstr(out, "\"functions\":5") && strstr(out, "\"nonfinite_values\":0") &&
              strstr(out, "\"exit_status\":0"),
          "soak: exit %d: %s", rc, out);
}

// (c) commands of the wrong length and unknown functions are refused, one
// line, nothing set; what the engine does not have yet answers clearly.
static void test_refusals(void) {
    model* m = load(g_cases[0].model);
    scenario sc;
    char err[1024];
    CHECK(scenario_load(g_cases[0].scenario, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    for (int b = 0; b < 2; ++b) {
        const sim_opts o = opts(b ? SIM_ODE : SIM_LAGRANGE);
        engine* e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
        CHECK(e != NULL, "%s: %s", bname(o.mechanics), err);
        if (!e) continue;
        check_channels(m, &o, e);
        CHECK(engine_nfunction(e) == 4 && !strcmp(engine_function_name(e, 3), "ext") &&
                  engine_function_name(e, 4) == NULL && engine_find_function(e, "jib2") == 2,
              "%s: functions %d", bname(o.mechanics), engine_nfunction(e));
        const double u[5] = {0.1, 0.2, 0.3, 0.4, 0.5};
        CHECK(engine_set_function_commands(e, u, 4, err, sizeof err) == 0, "%s", err);
        err[0] = 0;
        CHECK(engine_set_function_commands(e, (const double[5]){-1, -1, -1, -1, -1}, 5, err, sizeof err) == -1 &&
                  !strcmp(err, "5 commands for the 4 functions lift, jib, jib2, ext"),
              "%s: too many: %s", bname(o.mechanics), err);
        CHECK(engine_set_function_commands(e, u, 3, err, sizeof err) == -1 && strstr(err, "3 commands for the 4"),
              "too few: %s", err);
        CHECK(engine_set_function_command(e, "winch", 1.0, err, sizeof err) == -1 &&
                  !strcmp(err, "no function 'winch' (functions: lift, jib, jib2, ext)"),
              "unknown: %s", err);
        int same = 0;
        for (int k = 0; k < 4; ++k) same += engine_function_command(e, k) == u[k];
        CHECK(same == 4, "a refused command changed the held ones");
        // By name, and the two-link call onto the functions of those names.
        CHECK(engine_set_function_command(e, "ext", -0.7, err, sizeof err) == 0 &&
                  engine_function_command(e, 3) == -0.7 && engine_function_command(e, 2) == 0.3,
              "by name: %s", err);
        engine_set_commands(e, (const double[3]){0.9, -0.8, 0.5});
        CHECK(engine_function_command(e, 0) == 0.9 && engine_function_command(e, 1) == -0.8 &&
                  engine_function_command(e, 2) == 0.3 && engine_function_command(e, 3) == -0.7,
              "lift, jib, slew onto a chain");
        CHECK(engine_advance(e, 0.01) == 0, "%s", engine_error(e));
        double row[SIM_NCOL + 64];
        CHECK(engine_ncol(e) <= (int)(sizeof row / sizeof row[0]), "ncol %d", engine_ncol(e));
        engine_row(e, row);
        CHECK(row[COL_U1_CMD] == 0.9 && row[COL_U2_CMD] == -0.8, "commands in the row: %g %g", row[COL_U1_CMD],
              row[COL_U2_CMD]);
        // The channel list drive's charts read: the row's columns, then the
        // circuit's; its row part is engine_row's.
        chan_list* cl = chan_list_create(e);
        CHECK(cl && chan_list_nrow(cl) == engine_ncol(e) && chan_list_count(cl) > engine_ncol(e) &&
                  chan_list_find(cl, "x_ext") >= SIM_NCOL_BASE && chan_list_find(cl, "ext_valve.spool") > 0,
              "%s: channel list", bname(o.mechanics));
        if (cl) {
            double* v = calloc((size_t)chan_list_count(cl), sizeof *v);
            if (v) {
                chan_list_values(cl, e, v, false);
                CHECK(!memcmp(v, row, (size_t)engine_ncol(e) * sizeof *v), "%s: channel values differ from the row",
                      bname(o.mechanics));
                const int k = chan_list_find(cl, "ext_valve.spool");
                CHECK(k < 0 || fabs(v[k] - v[chan_list_find(cl, "u_ext")]) < 1e-15, "%s: spool %g, u_ext %g",
                      bname(o.mechanics), k < 0 ? 0 : v[k], v[chan_list_find(cl, "u_ext")]);
                free(v);
            }
            chan_list_free(cl);
        }
        // What a chain engine does not have yet: answered, not a crash.
        world_snapshot* snap = calloc(1, sizeof *snap);
        CHECK(snap && !engine_snapshot(e, snap), "a chain engine gave a snapshot");
        free(snap);
        CHECK(engine_rcl(e) == NULL && engine_hook(e, 1) == -1 && !engine_can_set_load(e) &&
                  engine_set_link(e, 0, NULL) == -1 && !(engine_caps(e) & ENGINE_CAP_TWO_LINK),
              "%s: limiter, hook, load, links", bname(o.mechanics));
        char msg[200];
        CHECK(engine_hook_report(e, 1, msg, sizeof msg) == -1 && strstr(msg, "no hook"), "%s", msg);
        engine_destroy(e);
        CHECK(engine_require(m, &o, ENGINE_CAP_TWO_LINK, "serve", err, sizeof err) == -1 &&
                  strstr(err, "serve: ") == err && strstr(err, "chain_3boom_ext.json") && !strchr(err, '\n'),
              "require: %s", err);
    }
    model_free(m);
}

// The general formulation's stepped engine (--variant general) against the
// closed form's on the two-link crane: the same held commands from the same
// ramp. With RK4 (explicit: the Jacobians, which the two paths form
// differently, do not enter) the same trajectory to rounding: 1e-9 of each
// column's peak, as test_chain_sim's scripted comparison, far above
// rounding and far below any modelling difference. With Krus (a W-method,
// whose result depends on the Jacobian at second order) the difference is
// printed.
static double closed_vs_general(hyd_method meth, double h, double t_end) {
    char err[1024];
    model* m = model_load(NULL, NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    scenario sc;
    CHECK(scenario_load(CRANESIM_ASSETS "/scenarios/ramp.json", &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return INFINITY;
    sim_opts o = opts(SIM_LAGRANGE);
    o.duration = t_end;
    o.solver = meth;
    o.h = h;
    rows a = {0}, g = {0};
    CHECK(stepped(m, &sc, &o, 0.01, &a, err, sizeof err) == 0, "closed form: %s", err);
    o.variant = LAGRANGE_GENERAL;
    CHECK(stepped(m, &sc, &o, 0.01, &g, err, sizeof err) == 0, "general: %s", err);
    const long n = (long)(t_end / 0.01 + 0.5);
    CHECK(a.n == g.n && a.n == n && a.ncol == SIM_NCOL_BASE && g.ncol == SIM_NCOL_BASE, "rows %ld %ld, cols %d %d",
          a.n, g.n, a.ncol, g.ncol);
    double* peak = calloc((size_t)a.ncol, sizeof *peak);
    double worst = peak ? 0 : INFINITY;
    int wc = -1;
    for (long i = 0; peak && i < a.n && i < g.n; ++i)
        for (int c = 0; c < a.ncol; ++c) peak[c] = fmax(peak[c], fabs(a.v[(size_t)i * (size_t)a.ncol + (size_t)c]));
    for (long i = 0; peak && i < a.n && i < g.n; ++i)
        for (int c = 0; c < a.ncol; ++c) {
            const double va = a.v[(size_t)i * (size_t)a.ncol + (size_t)c];
            const double vg = g.v[(size_t)i * (size_t)g.ncol + (size_t)c];
            const double d = fabs(va - vg) / (peak[c] > 0 ? peak[c] : 1.0);
            if (!(d <= worst)) worst = d, wc = c;
        }
    printf("  hiab031 ramp, %s %g ms, %g s: stepped closed form against stepped general: largest difference %.3g "
           "of the column's peak (%s)\n",
           hyd_method_name(meth), h * 1e3, t_end, worst, wc >= 0 ? sim_col_name[wc] : "-");
    free(peak);
    free(a.v);
    free(g.v);
    model_free(m);
    return worst;
}

static void test_general_matches_closed_form(void) {
    const double rk4 = closed_vs_general(HYD_RK4, 5e-6, 1.0); // the step the run checks accept for RK4 here
    CHECK(rk4 <= 1e-9, "RK4: closed form and general differ by %g of the peak", rk4);
    closed_vs_general(HYD_KRUS, 1e-4, 3.0); // printed: the W-methods' Jacobians differ
}

int main(int argc, char** argv) {
    RUN_TEST(test_refusals);
    RUN_TEST(test_command_line);
    RUN_TEST(test_held_commands_match_run);
    RUN_TEST(test_closed_valves_hold);
    RUN_TEST(test_play_matches_run);
    RUN_TEST(test_general_matches_closed_form);
    TEST_MAIN_END();
}
