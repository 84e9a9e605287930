// app_chain_out.c: a chain model's outputs by function (issue 27): the run
// summary's strokes and peak pressures, the end-stop hits and the metrics
// file's per-actuator entries, read from the rows' chain columns
// (crane_chain_columns: x_<a>, pA_<a>, pB_<a> per actuator, u_<f> per
// function) by name, so every actuator the model has is named, none by
// position.
#define _GNU_SOURCE // open_memstream
#include "app.h"
#include "crane_chain.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// The column index (in a row, base columns first) of "<what>_<name>"; -1.
static int col_of(const crane_chain* cc, int off, const char* what, const char* name) {
    const int k = crane_chain_find_column(cc, what, name);
    return k < 0 ? -1 : off + k;
}

void app_chain_stats_free(app_chain_stats* s) {
    free(s->act);
    free(s->fn);
    s->act = NULL;
    s->fn = NULL;
    s->nact = s->nfn = 0;
}

int app_chain_stats_bind(app_chain_stats* s, const crane_chain* cc, int off) {
    app_chain_stats_free(s);
    s->bound = true;
    // The two-link shorthand's base columns name its two cylinders already
    // (the default crane's summary stays as it was): nothing here.
    if (!cc || cc->two_link || cc->ncol == 0) return 0;
    // An actuator per x_ column, a function per u_ column, in column order
    // (the slew rack's, where the run has one, after the chain's).
    int na = 0, nf = 0;
    for (int k = 0; k < cc->ncol; ++k) {
        na += !strncmp(cc->col[k].name, "x_", 2);
        nf += !strncmp(cc->col[k].name, "u_", 2);
    }
    s->act = calloc((size_t)(na ? na : 1), sizeof *s->act);
    s->fn = calloc((size_t)(nf ? nf : 1), sizeof *s->fn);
    if (!s->act || !s->fn) {
        app_chain_stats_free(s);
        return -1;
    }
    for (int k = 0; k < cc->ncol; ++k) {
        const char* nm = cc->col[k].name;
        if (!strncmp(nm, "x_", 2)) {
            app_act_stats* a = &s->act[s->nact];
            snprintf(a->name, sizeof a->name, "%s", nm + 2);
            a->cx = off + k;
            a->cA = col_of(cc, off, "pA", a->name);
            a->cB = col_of(cc, off, "pB", a->name);
            a->cF = col_of(cc, off, "F", a->name);
            // The stroke of the circuit's cylinder (crane_chain_bind); the
            // slew rack's is not in act[]: its stops are not counted here.
            const int ia = crane_chain_find_act(cc, a->name);
            a->stroke = ia >= 0 ? cc->act[ia].stroke : NAN;
            a->xmin = INFINITY, a->xmax = -INFINITY;
            if (a->cA >= 0 && a->cB >= 0 && a->cF >= 0) ++s->nact;
        } else if (!strncmp(nm, "u_", 2)) {
            app_fn_stats* f = &s->fn[s->nfn++];
            snprintf(f->name, sizeof f->name, "%s", nm + 2);
            f->cu = off + k;
        }
    }
    return 0;
}

void app_chain_stats_row(app_chain_stats* s, const double* row) {
    for (int i = 0; i < s->nact; ++i) {
        app_act_stats* a = &s->act[i];
        const double x = row[a->cx];
        a->xmin = fmin(a->xmin, x);
        a->xmax = fmax(a->xmax, x);
        a->pA = fmax(a->pA, row[a->cA]);
        a->pB = fmax(a->pB, row[a->cB]);
        a->Fabs = fmax(a->Fabs, fabs(row[a->cF]));
        // At a stop as the circuit's cylinder is (x < 0 or x > stroke,
        // cylinder.c), seen at the rows: a hit is an entry (a run that
        // starts at a stop counts one), as the two-link crane's metrics.
        const bool stop = isfinite(a->stroke) && (x < 0.0 || x > a->stroke);
        if (stop && !a->at_stop) ++a->stops;
        a->at_stop = stop;
    }
    for (int i = 0; i < s->nfn; ++i) s->fn[i].umax = fmax(s->fn[i].umax, fabs(row[s->fn[i].cu]));
    ++s->rows;
}

void app_chain_stats_print(const app_chain_stats* s, double every, double t_end, FILE* f) {
    if (s->nact == 0 || s->rows == 0) return;
    fprintf(f, "  strokes:");
    for (int i = 0; i < s->nact; ++i)
        fprintf(f, "%s %s %.1f..%.1f mm", i ? "," : "", s->act[i].name, 1e3 * s->act[i].xmin,
                1e3 * s->act[i].xmax);
    fprintf(f, "\n  peak pressures at the output rows:");
    for (int i = 0; i < s->nact; ++i)
        fprintf(f, "%s %s A %.2f B %.2f", i ? "," : "", s->act[i].name, 1e-6 * s->act[i].pA, 1e-6 * s->act[i].pB);
    fprintf(f, " MPa (absolute)");
    if (every > 1e-3 * (1 + 1e-9)) fprintf(f, ", rows every %g ms", fmin(every, t_end) * 1e3);
    fprintf(f, "\n  per actuator: peak force");
    for (int i = 0; i < s->nact; ++i) fprintf(f, "%s %s %.1f", i ? "," : "", s->act[i].name, 1e-3 * s->act[i].Fabs);
    fprintf(f, " kN; end-stop hits");
    for (int i = 0; i < s->nact; ++i) {
        if (isfinite(s->act[i].stroke)) fprintf(f, "%s %s %d", i ? "," : "", s->act[i].name, s->act[i].stops);
        else fprintf(f, "%s %s -", i ? "," : "", s->act[i].name);
    }
    fprintf(f, "\n");
}

static void json_entry(FILE* f, const char* key, const char* name, double v, const char* unit) {
    fprintf(f, ",\n    \"%s.%s\": {\"value\": %.17g, \"unit\": \"%s\", \"over\": \"rows\"}", key, name, v, unit);
}

int app_chain_stats_write_json(const app_chain_stats* s, const run_metrics* met, FILE* f) {
    if (s->nact == 0 && s->nfn == 0) return metrics_write_json(met, f);
    // metrics_write_json's document, with the chain's entries added at the
    // end of its "metrics" object (whose entries are one per line: the
    // object ends at the first "\n  }").
    char* buf = NULL;
    size_t len = 0;
    FILE* m = open_memstream(&buf, &len);
    if (!m) return -1;
    const int rc = metrics_write_json(met, m);
    if (fclose(m) || rc || !buf) {
        free(buf);
        return -1;
    }
    const char* end = strstr(buf, "\n  }");
    if (!end || s->rows == 0) {
        fputs(buf, f);
        free(buf);
        return ferror(f) ? -1 : 0;
    }
    fwrite(buf, 1, (size_t)(end - buf), f);
    // An empty "metrics" object has no entry to follow: the first comes
    // without its comma.
    const bool empty = end > buf && end[-1] == '{';
    FILE* g = f;
    char* tmp = NULL;
    size_t tl = 0;
    if (empty && !(g = open_memstream(&tmp, &tl))) {
        free(buf);
        return -1;
    }
    for (int i = 0; i < s->nact; ++i) {
        const app_act_stats* a = &s->act[i];
        json_entry(g, "stroke_min", a->name, a->xmin, "m");
        json_entry(g, "stroke_max", a->name, a->xmax, "m");
        json_entry(g, "peak_pA", a->name, a->pA, "Pa");
        json_entry(g, "peak_pB", a->name, a->pB, "Pa");
        json_entry(g, "peak_force", a->name, a->Fabs, "N");
        if (isfinite(a->stroke)) json_entry(g, "end_stop_hits", a->name, a->stops, "count");
    }
    for (int i = 0; i < s->nfn; ++i) json_entry(g, "max_spool", s->fn[i].name, s->fn[i].umax, "-");
    if (empty) {
        fclose(g);
        if (tmp) fputs(tmp + 1, f); // without the leading comma
        free(tmp);
    }
    fputs(end, f);
    free(buf);
    return ferror(f) ? -1 : 0;
}

// ---- A run's chain columns kept for compare (its sim_trace holds the base
// columns only).

int app_ext_rows_cb(void* user, const double* row) {
    app_ext_rows* r = user;
    if (!r->bound) {
        r->bound = true;
        const struct crane_chain* cc = r->run_chain ? r->run_chain : r->model_chain;
        // The two-link shorthand's base columns are all compare needs.
        if (cc && !cc->two_link && cc->ncol > 0) {
            r->col = malloc((size_t)cc->ncol * sizeof *r->col);
            if (!r->col) {
                r->oom = true;
                return 1;
            }
            memcpy(r->col, cc->col, (size_t)cc->ncol * sizeof *r->col);
            r->ncol = cc->ncol;
        }
    }
    if (r->ncol == 0) return 0;
    if (r->nrow == r->cap) {
        const long cap = r->cap ? 2 * r->cap : 4096;
        double* v = realloc(r->v, (size_t)cap * (size_t)r->ncol * sizeof *v);
        if (!v) {
            r->oom = true;
            return 1;
        }
        r->v = v;
        r->cap = cap;
    }
    memcpy(r->v + (size_t)r->nrow * (size_t)r->ncol, row + r->off, (size_t)r->ncol * sizeof(double));
    ++r->nrow;
    return 0;
}

int app_ext_rows_find(const app_ext_rows* r, const char* name) {
    for (int k = 0; k < r->ncol; ++k)
        if (!strcmp(r->col[k].name, name)) return k;
    return -1;
}

void app_ext_rows_free(app_ext_rows* r) {
    free(r->col);
    free(r->v);
    r->col = NULL;
    r->v = NULL;
    r->ncol = 0;
    r->nrow = r->cap = 0;
}

void app_chain_metrics_print(const app_chain_stats* s, const run_metrics* met, FILE* f) {
    if (s->nact == 0) {
        metrics_print(met, f);
        return;
    }
    // metrics_print's block, less its end-stop hits of the first two
    // actuators by position ("lift N, jib N": on a chain model the second
    // may be any actuator), which the per-actuator line has by name; the
    // slew's stays.
    char* buf = NULL;
    size_t len = 0;
    FILE* m = open_memstream(&buf, &len);
    if (!m) {
        metrics_print(met, f);
        return;
    }
    metrics_print(met, m);
    if (fclose(m) || !buf) {
        free(buf);
        metrics_print(met, f);
        return;
    }
    char* a = strstr(buf, "; end-stop hits lift ");
    char* semi = a ? strchr(a + 1, ';') : NULL;
    char* nl = a ? strchr(a, '\n') : NULL;
    char* end = semi && (!nl || semi < nl) ? semi : nl;
    if (a && end) {
        char* sl = strstr(a, ", slew ");
        if (sl && sl < end) {
            // "; end-stop hits slew N" from "; end-stop hits lift N, jib N, slew N".
            fwrite(buf, 1, (size_t)(a - buf), f);
            fprintf(f, "; end-stop hits slew%.*s", (int)(end - (sl + 6)), sl + 6);
        } else {
            fwrite(buf, 1, (size_t)(a - buf), f);
        }
        fputs(end, f);
    } else {
        fputs(buf, f);
    }
    free(buf);
}
