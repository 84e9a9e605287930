// app_design_metrics.c: the metrics sweep and optimize tabulate and bound,
// by name: the run metrics (metrics.h, ids 0 .. MET_COUNT-1) and, on a crane
// chain model, its metrics per actuator and function (app_chain_out.c's
// entries of run --metrics: "peak_pA.lift", "max_spool.ext"; ids from
// MET_COUNT on), so a design study of any crane names what its model has.
#include "app_design_metrics.h"
#include "crane_chain.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// What a chain metric reads from app_chain_stats (the names and units are
// those of app_chain_stats_write_json, so a sweep column and a run's JSON
// entry are the same number).
typedef enum xkind { X_STROKE_MIN, X_STROKE_MAX, X_PEAK_PA, X_PEAK_PB, X_PEAK_FORCE, X_STOPS, X_MAX_SPOOL } xkind;
static const struct {
    const char* key;
    const char* unit;
} k_xkind[] = {{"stroke_min", "m"}, {"stroke_max", "m"},        {"peak_pA", "Pa"},  {"peak_pB", "Pa"},
               {"peak_force", "N"}, {"end_stop_hits", "count"}, {"max_spool", "-"}};

typedef struct xmet {
    char name[96]; // "<key>.<actuator or function>"
    xkind kind;
    char of[40];   // the actuator's or function's name
} xmet;

// The chain metrics of the one model a command studies: set once before any
// design runs (app_design_metrics_setup), read only after, so the sweep's
// threads share it.
static xmet* g_x;
static int g_nx;

void app_design_metrics_free(void) {
    free(g_x);
    g_x = NULL;
    g_nx = 0;
}

int app_design_metrics_setup(const model* m) {
    app_design_metrics_free();
    const crane_chain* cc = &m->chain;
    // The two-link shorthand's run metrics name its two cylinders already;
    // only a chain has metrics by name (as run --metrics).
    if (cc->two_link || cc->ncol == 0) return 0;
    int na = 0, nf = 0;
    for (int k = 0; k < cc->ncol; ++k) {
        na += !strncmp(cc->col[k].name, "x_", 2);
        nf += !strncmp(cc->col[k].name, "u_", 2);
    }
    g_x = calloc((size_t)(6 * na + nf + 1), sizeof *g_x);
    if (!g_x) return -1;
    // In column order (the chain's actuators, then its functions), each
    // actuator's six metrics together, as the run's JSON lists them.
    for (int k = 0; k < cc->ncol; ++k) {
        const char* nm = cc->col[k].name;
        if (!strncmp(nm, "x_", 2)) {
            const int ia = crane_chain_find_act(cc, nm + 2);
            for (int x = X_STROKE_MIN; x <= X_STOPS; ++x) {
                // A stroke without a circuit cylinder has no stops (the run's JSON leaves it out too).
                if (x == X_STOPS && !(ia >= 0 && isfinite(cc->act[ia].stroke))) continue;
                xmet* e = &g_x[g_nx++];
                e->kind = (xkind)x;
                snprintf(e->of, sizeof e->of, "%s", nm + 2);
                snprintf(e->name, sizeof e->name, "%s.%s", k_xkind[x].key, e->of);
            }
        }
    }
    for (int k = 0; k < cc->ncol; ++k) {
        const char* nm = cc->col[k].name;
        if (!strncmp(nm, "u_", 2)) {
            xmet* e = &g_x[g_nx++];
            e->kind = X_MAX_SPOOL;
            snprintf(e->of, sizeof e->of, "%s", nm + 2);
            snprintf(e->name, sizeof e->name, "%s.%s", k_xkind[X_MAX_SPOOL].key, e->of);
        }
    }
    return 0;
}

int app_design_metric_count(void) { return MET_COUNT + g_nx; }
int app_design_metric_chain_count(void) { return g_nx; }

int app_design_metric_find(const char* name) {
    const int id = metric_find(name);
    if (id >= 0) return id;
    for (int k = 0; k < g_nx; ++k)
        if (!strcmp(g_x[k].name, name)) return MET_COUNT + k;
    return -1;
}

const char* app_design_metric_name(int id) {
    if (id >= 0 && id < MET_COUNT) return metric_name((metric_id)id);
    return id >= MET_COUNT && id < MET_COUNT + g_nx ? g_x[id - MET_COUNT].name : "?";
}

const char* app_design_metric_unit(int id) {
    if (id >= 0 && id < MET_COUNT) return metric_unit((metric_id)id);
    return id >= MET_COUNT && id < MET_COUNT + g_nx ? k_xkind[g_x[id - MET_COUNT].kind].unit : "";
}

bool app_design_metric_present(int id, int ncol) {
    if (id >= 0 && id < MET_COUNT) return metrics_present((metric_id)id, ncol);
    return id >= MET_COUNT && id < MET_COUNT + g_nx;
}

void app_design_metric_names(char* buf, size_t n) {
    metric_names(buf, n);
    size_t len = strlen(buf);
    if (g_nx && len < n) {
        // The chain's by kind, "peak_pA.<actuator>", not all of them.
        len += (size_t)snprintf(buf + len, n - len, "; by actuator: stroke_min, stroke_max, peak_pA, peak_pB, "
                                                    "peak_force, end_stop_hits .NAME (");
        const char* sep = "";
        for (int k = 0; k < g_nx && len < n; ++k)
            if (g_x[k].kind == X_STROKE_MIN) {
                len += (size_t)snprintf(buf + len, n - len, "%s%s", sep, g_x[k].of);
                sep = ", ";
            }
        if (len < n) len += (size_t)snprintf(buf + len, n - len, "); by function: max_spool.NAME (");
        sep = "";
        for (int k = 0; k < g_nx && len < n; ++k)
            if (g_x[k].kind == X_MAX_SPOOL) {
                len += (size_t)snprintf(buf + len, n - len, "%s%s", sep, g_x[k].of);
                sep = ", ";
            }
        if (len < n) snprintf(buf + len, n - len, ")");
    }
}

void app_design_run_init(app_design_run* r, const model* m, int ncol) {
    memset(r, 0, sizeof *r);
    metrics_init(&r->met, ncol);
    r->chain = &m->chain;
    r->ncol = ncol;
}

int app_design_row(void* user, const double* row) {
    app_design_run* r = user;
    metrics_row(&r->met, row);
    if (g_nx) {
        // The run's chain (the model's, or the slewing run's with its rack),
        // known by the first row; its columns follow the run's base columns.
        if (!r->cst.bound && app_chain_stats_bind(&r->cst, r->chain, r->ncol)) r->oom = true;
        app_chain_stats_row(&r->cst, row);
    }
    return app_signal_caught() != 0;
}

double app_design_value(const app_design_run* r, int id) {
    if (id >= 0 && id < MET_COUNT) return r->met.value[id];
    if (id < MET_COUNT || id >= MET_COUNT + g_nx || r->cst.rows == 0) return NAN;
    const xmet* e = &g_x[id - MET_COUNT];
    if (e->kind == X_MAX_SPOOL) {
        for (int i = 0; i < r->cst.nfn; ++i)
            if (!strcmp(r->cst.fn[i].name, e->of)) return r->cst.fn[i].umax;
        return NAN;
    }
    for (int i = 0; i < r->cst.nact; ++i) {
        const app_act_stats* a = &r->cst.act[i];
        if (strcmp(a->name, e->of)) continue;
        switch (e->kind) {
        case X_STROKE_MIN: return a->xmin;
        case X_STROKE_MAX: return a->xmax;
        case X_PEAK_PA: return a->pA;
        case X_PEAK_PB: return a->pB;
        case X_PEAK_FORCE: return a->Fabs;
        case X_STOPS: return isfinite(a->stroke) ? a->stops : NAN;
        default: return NAN;
        }
    }
    return NAN;
}

void app_design_run_free(app_design_run* r) { app_chain_stats_free(&r->cst); }
