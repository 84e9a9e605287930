// sim.c: headless runs of a model on a scenario (their rows to a callback,
// a trace, a progress bar; the CSV), whatever the backend: sim_run drives
// engine_run. The run checks, the channel list and the trace are
// sim_base.c's, the step probe step_probe.c's.
#include "sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "engine.h"

int sim_ncol(const sim_opts* o) {
    int n;
    engine_channels_for(o, &n);
    return n;
}

void sim_csv_header(FILE* f, int ncol) {
    for (int c = 0; c < ncol; ++c) fprintf(f, "%s%s", c ? "," : "", sim_channels[c].name);
    fputc('\n', f);
}

void sim_csv_header_ext(FILE* f, int ncol, const crane_column* ext, int next) {
    for (int c = 0; c < ncol; ++c) fprintf(f, "%s%s", c ? "," : "", sim_channels[c].name);
    for (int c = 0; c < next; ++c) fprintf(f, ",%s", ext[c].name);
    fputc('\n', f);
}

void sim_csv_row(FILE* f, const double* row, int ncol) {
    // %.9g keeps 1e-9 relative precision: sub-micrometre strokes, mPa pressures.
    for (int c = 0; c < ncol; ++c) fprintf(f, "%s%.9g", c ? "," : "", row[c]);
    fputc('\n', f);
}

// What a run's rows go to: the trace, the row callback, the progress bar.
typedef struct run_out {
    sim_row_fn row_fn;
    void* row_user;
    sim_trace* trace;
    sim_progress_fn progress;
    void* progress_user;
    double t_end, wall_next;
} run_out;

// Hand a finished row to the trace, the row callback and the progress bar.
static int deliver(void* user, const double* row) {
    run_out* c = user;
    const double t = row[COL_T];
    if (c->trace && sim_trace_push(c->trace, row)) return 1;
    if (c->row_fn && c->row_fn(c->row_user, row)) return 1;
    if (c->progress) {
        double w = sim_wall_time();
        if (w >= c->wall_next) {
            c->wall_next = w + 0.1;
            c->progress(c->progress_user, t, c->t_end);
        }
    }
    return 0;
}

int sim_run(const model* m, const scenario* sc, const sim_opts* o, sim_row_fn row_fn, void* row_user,
            sim_trace* trace, sim_progress_fn progress, void* progress_user, sim_result* res) {
    return sim_run_energy(m, sc, o, row_fn, row_user, trace, progress, progress_user, NULL, res);
}

int sim_run_energy(const model* m, const scenario* sc, const sim_opts* o, sim_row_fn row_fn, void* row_user,
                   sim_trace* trace, sim_progress_fn progress, void* progress_user, struct sim_energy* energy,
                   sim_result* res) {
    return sim_run_energy_chain(m, sc, o, row_fn, row_user, trace, progress, progress_user, energy, NULL, res);
}

int sim_run_energy_chain(const model* m, const scenario* sc, const sim_opts* o, sim_row_fn row_fn, void* row_user,
                         sim_trace* trace, sim_progress_fn progress, void* progress_user, struct sim_energy* energy,
                         const crane_chain** run_chain, sim_result* res) {
    memset(res, 0, sizeof *res);
    const double t_end = o->duration > 0 ? o->duration : sc->duration;
    if (sim_check_times(t_end, o->dt_out, res->message, sizeof res->message)) return res->status = SIM_REFUSED;
    run_out out = {.row_fn = row_fn, .row_user = row_user, .trace = trace, .progress = progress,
                   .progress_user = progress_user, .t_end = t_end};
    const engine_sink k = {.row = deliver, .user = &out, .rows = trace || row_fn || progress,
                           .summary = trace || row_fn, .t_end = t_end, .energy = energy, .run_chain = run_chain};
    return engine_run(m, sc, o, &k, res);
}
