// test_drivers.c: the same scenario through each driver on each backend
// gives the same rows, bit for bit, where the drivers are meant to agree:
//  - run (rows to a callback), compare and study (rows into a trace) and a
//    run with only a progress bar all run engine_run: the same rows on both
//    backends;
//  - the headless drive and the window's tick step an engine with the
//    scripted operator (engine_play) once per frame; on the ode world at one
//    frame per ODE step that is the run's own player, so the drive's rows
//    are the run's rows after t = 0.
// The lagrange drive is not meant to agree with the lagrange run: the run
// reads the commands continuously inside f and uses the fused kernel, a
// drive holds each frame's command and keeps the general circuit path (the
// panel edits the circuit in place).
#include "check.h"
#include "crane_fixture.h"
#include "engine.h"
#include "sim.h"
#include "row_store.h"

#include <stdlib.h>
#include <string.h>


static int g_progress;
static void on_progress(void* user, double t, double t_end) {
    (void)user;
    (void)t;
    (void)t_end;
    ++g_progress;
}

// Rows a and b agree bit for bit in their first ncol columns from row a0,
// b0 on, for n rows; 0 when they do, else the first row that differs.
static int first_diff(const double* a, const double* b, int n, int ncol) {
    for (int i = 0; i < n; ++i)
        if (memcmp(a + (size_t)i * SIM_NCOL, b + (size_t)i * SIM_NCOL, (size_t)ncol * sizeof(double)))
            return i + 1;
    return 0;
}

typedef struct backend {
    const char* name;
    sim_mechanics mech;
    const char* world;
    const char* scenario;
    double duration;
} backend;

static const backend g_backends[] = {
    {"lagrange", SIM_LAGRANGE, NULL, "ramp", 3.0},
    {"ode validation", SIM_ODE, CRANESIM_ASSETS "/worlds/validation.json", "ramp", 3.0},
    {"ode sandbox", SIM_ODE, CRANESIM_ASSETS "/worlds/sandbox.json", "sandbox_pick_place", 6.0},
};

static sim_opts opts_for(const backend* b) {
    sim_opts o = sim_default_opts();
    o.mechanics = b->mech;
    o.world = b->world;
    o.duration = b->duration;
    return o;
}

// run, compare and a progress-only run: one engine_run, the same rows.
static void test_run_compare_agree(void) {
    for (size_t bi = 0; bi < sizeof g_backends / sizeof g_backends[0]; ++bi) {
        const backend* b = &g_backends[bi];
        scenario sc;
        model* m = load_crane(b->scenario, &sc);
        if (!m) return;
        const sim_opts o = opts_for(b);
        rows run = {0};
        sim_trace tr = {0};
        sim_result r1, r2, r3;
        CHECK(sim_run(m, &sc, &o, keep_row, &run, NULL, NULL, NULL, &r1) == 0, "%s run: %s", b->name, r1.message);
        CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r2) == 0, "%s compare: %s", b->name, r2.message);
        g_progress = 0;
        CHECK(sim_run(m, &sc, &o, NULL, NULL, NULL, on_progress, NULL, &r3) == 0, "%s progress: %s", b->name,
              r3.message);
        CHECK(g_progress > 0, "%s: the progress bar was never called", b->name);
        CHECK(run.n == tr.nrow && run.n == (int)(b->duration / o.dt_out + 0.5) + 1, "%s: rows %d vs %d", b->name,
              run.n, tr.nrow);
        const int n = run.n < tr.nrow ? run.n : tr.nrow;
        const int d = first_diff(run.v, tr.v, n, SIM_NCOL);
        CHECK(d == 0, "%s: run and compare differ at row %d", b->name, d - 1);
        CHECK(r1.rows == r2.rows && r2.rows == r3.rows && r1.stats.steps == r3.stats.steps,
              "%s: rows %ld %ld %ld, steps %ld %ld", b->name, r1.rows, r2.rows, r3.rows, (long)r1.stats.steps,
              (long)r3.stats.steps);
        CHECK(memcmp(r1.p_peak, r2.p_peak, sizeof r1.p_peak) == 0, "%s: peaks differ", b->name);
        free(run.v);
        sim_trace_free(&tr);
        model_free(m);
    }
}

// The headless drive's loop (cmd_drive.c): commands at each frame's middle
// through engine_play, advance to the frame's end, record the row.
static int drive_rows(const model* m, const scenario* sc, const sim_opts* o, double frame, double duration,
                      rows* out, char* err, size_t n) {
    engine* e = engine_create(m, o, sc->q0, sc->slew0, sim_load_mass(m, sc, o), err, n);
    if (!e) return -1;
    const long nframes = (long)(duration / frame + 0.5);
    int ev = 0, rc = 0;
    for (long i = 0; i < nframes && !rc; ++i) {
        double u[3];
        engine_play(e, sc, engine_time(e) + 0.5 * frame, &ev, u, NULL, NULL);
        engine_set_commands(e, u);
        rc = engine_advance_to(e, (double)(i + 1) * frame, keep_row, out);
    }
    if (rc) snprintf(err, n, "%s", engine_error(e));
    engine_destroy(e);
    return rc;
}

static void test_drive_agrees_with_run_on_ode(void) {
    for (size_t bi = 1; bi < sizeof g_backends / sizeof g_backends[0]; ++bi) {
        const backend* b = &g_backends[bi];
        scenario sc;
        model* m = load_crane(b->scenario, &sc);
        if (!m) return;
        const sim_opts o = opts_for(b);
        rows run = {0}, drv = {0};
        sim_result r;
        char err[512];
        CHECK(sim_run(m, &sc, &o, keep_row, &run, NULL, NULL, NULL, &r) == 0, "%s run: %s", b->name, r.message);
        CHECK(drive_rows(m, &sc, &o, o.dt_ode, b->duration, &drv, err, sizeof err) == 0, "%s drive: %s", b->name,
              err);
        CHECK(drv.n + 1 == run.n, "%s: drive %d rows, run %d", b->name, drv.n, run.n);
        const int n = drv.n + 1 < run.n ? drv.n : run.n - 1;
        const int d = first_diff(run.v + SIM_NCOL, drv.v, n, SIM_NCOL);
        CHECK(d == 0, "%s: drive and run differ at t = %g s", b->name, d ? run.v[(size_t)d * SIM_NCOL] : 0.0);
        if (bi == 2) { // the sandbox: the scenario's hook really picked a load up
            int attached = 0;
            for (int i = 0; i < run.n; ++i) attached |= run.v[(size_t)i * SIM_NCOL + COL_ATTACHED] >= 0;
            CHECK(attached, "the sandbox scenario never attached a load");
        }
        free(run.v);
        free(drv.v);
        model_free(m);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_run_compare_agree);
    RUN_TEST(test_drive_agrees_with_run_on_ode);
    TEST_MAIN_END();
}
