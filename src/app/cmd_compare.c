// cmd_compare.c: `cranesim compare`: one scenario run two ways, difference
// metrics, overlay plots, and a pass/fail against given tolerances.
#include "app.h"
#include "energy_acc.h"
#include "metrics.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void compare_help(FILE* f) {
    fprintf(f,
            "usage: cranesim compare [--scenario S] [--backends A,B] [--solvers A,B] [--variants A,B]\n"
            "                        [--dts H1,H2] [--tol-stroke MM] [--tol-pressure PCT] [--plot FILE.png]\n"
            "       cranesim compare [--scenario S] --model A.json --model B.json | --set-a PATH=V ... --set-b PATH=V ...\n"
            "                        [--mechanics M] [--plot FILE.png] [--out FILE.csv]\n"
            "\n"
            "Runs the scenario twice, differing in what the pair options say (the rest is\n"
            "shared), and prints RMS and maximum differences of strokes [mm], chamber\n"
            "pressures [MPa and %% of the higher of the two peaks], joint angles [deg] and tip\n"
            "position [mm] (a chain model: every actuator's stroke and chambers and every\n"
            "joint, by name). Neither side is taken as right: the figures are differences\n"
            "between the two runs (cvode at its default --rtol 1e-3 is further from the\n"
            "converged peak pressure than krus at 0.1 ms; README.md). Then each side's energy\n"
            "balance [kJ] as run prints it, and B - A term by term (docs/energy.md).\n"
            "Default: --backends lagrange,ode (lagrange full vs the ode validation world).\n"
            "Two designs: two --model files, or --set-a / --set-b changes (on the one --model), run on\n"
            "the same backend and settings; adds their metrics side by side with B - A (docs/replay.md).\n"
            "\n"
            "options:\n"
            "  --backends A,B      lagrange | ode\n"
            "  --solvers A,B       krus | ros2 | rk4 | ros34pw2 | rodas3 | cvode (lagrange only)\n"
            "  --variants A,B      full | paper | paper-typo\n"
            "  --dts H1,H2         fixed steps [s]\n"
            "  --tol-stroke MM     fail (exit 1) if the stroke RMS difference exceeds MM millimetres\n"
            "  --tol-pressure PCT  fail (exit 1) if the pressure RMS difference exceeds PCT %% of the\n"
            "                      higher peak\n"
            "  --plot FILE.png     overlay plot (solid: A, dashed: B)\n"
            "  --model FILE        given twice: design A's and design B's model files\n"
            "  --set-a PATH=VALUE  a change of design A's model (repeatable; --set changes both)\n"
            "  --set-b PATH=VALUE  a change of design B's model (repeatable)\n"
            "  --out FILE.csv      both runs' rows side by side: t, then each column as NAME_A, NAME_B\n");
    app_common_help(f, true);
}

static int split_pair(const char* opt, const char* v, char a[64], char b[64]) {
    const char* comma = strchr(v, ',');
    if (!comma || comma == v || !comma[1] || (size_t)(comma - v) >= 64 || strlen(comma + 1) >= 64) {
        fprintf(stderr, "cranesim compare: %s: expected two values A,B, got '%s'\n", opt, v);
        return -1;
    }
    memcpy(a, v, (size_t)(comma - v));
    a[comma - v] = 0;
    snprintf(b, 64, "%s", comma + 1);
    return 0;
}

typedef struct diff {
    double rms, max;
} diff;

static diff column_diff(const sim_trace* a, const sim_trace* b, int col, double scale) {
    int n = a->nrow < b->nrow ? a->nrow : b->nrow;
    double s2 = 0, mx = 0;
    for (int i = 0; i < n; ++i) {
        double d = (a->v[(size_t)i * SIM_NCOL + col] - b->v[(size_t)i * SIM_NCOL + col]) * scale;
        s2 += d * d;
        if (fabs(d) > mx) mx = fabs(d);
    }
    diff r = {n ? sqrt(s2 / n) : 0, mx};
    return r;
}

static double peak_pressure(const sim_trace* r) {
    double peak = 0;
    for (int i = 0; i < r->nrow; ++i)
        for (int k = 0; k < 4; ++k) peak = fmax(peak, r->v[(size_t)i * SIM_NCOL + COL_P1A + k]);
    return peak;
}

void app_compare_pressure(const sim_trace* a, const sim_trace* b, double* rms_pa, double* peak_pa, double* pct,
                          int* peak_side) {
    // The higher peak: a scale both sides share, whichever is named first.
    const double pa = peak_pressure(a), pb = peak_pressure(b);
    const double peak = fmax(pa, pb);
    double worst = 0;
    for (int k = 0; k < 4; ++k) worst = fmax(worst, column_diff(a, b, COL_P1A + k, 1.0).rms);
    *rms_pa = worst;
    *peak_pa = peak;
    *peak_side = pb > pa ? 1 : 0;
    *pct = peak > 0 ? 100.0 * worst / peak : 0.0;
}

// A chain column's difference between the sides (ia in a, ib in b).
static diff ext_diff(const app_ext_rows* a, int ia, const app_ext_rows* b, int ib, double scale) {
    const long n = a->nrow < b->nrow ? a->nrow : b->nrow;
    double s2 = 0, mx = 0;
    for (long i = 0; i < n; ++i) {
        const double d = (a->v[(size_t)i * (size_t)a->ncol + (size_t)ia] -
                          b->v[(size_t)i * (size_t)b->ncol + (size_t)ib]) * scale;
        s2 += d * d;
        mx = fmax(mx, fabs(d));
    }
    diff r = {n ? sqrt(s2 / (double)n) : 0, mx};
    return r;
}

static double ext_peak(const app_ext_rows* r, int k) {
    double peak = 0;
    for (long i = 0; i < r->nrow; ++i) peak = fmax(peak, r->v[(size_t)i * (size_t)r->ncol + (size_t)k]);
    return peak;
}

// The difference table of two chain runs by name: every actuator's stroke
// (x_) [mm], then its chamber pressures (pA_, pB_) [MPa], then every degree
// of freedom (q_) [deg, or mm for a sliding one], then the tip; columns only
// one side has (two designs of different shape) are listed as such. The
// worst stroke RMS [mm], the worst pressure RMS [Pa], the higher peak of the
// pressure columns [Pa] and whose it is (0 A, 1 B) come back.
static void print_ext_table(const app_ext_rows ext[2], const sim_trace tr[2], double* stroke_rms, double* prms,
                            double* ppeak, int* pside) {
    int w = 8;
    for (int s = 0; s < 2; ++s)
        for (int k = 0; k < ext[s].ncol; ++k) w = w > (int)strlen(ext[s].col[k].name) ? w : (int)strlen(ext[s].col[k].name);
    printf("  %-*s %12s %12s\n", w, "column", "RMS diff", "max diff");
    static const char* const kinds[3][2] = {{"x_", NULL}, {"pA_", "pB_"}, {"q_", NULL}};
    double pk[2] = {0, 0};
    *stroke_rms = *prms = 0;
    for (int g = 0; g < 3; ++g) {
        for (int k = 0; k < ext[0].ncol; ++k) {
            const crane_column* c = &ext[0].col[k];
            const bool in = !strncmp(c->name, kinds[g][0], strlen(kinds[g][0])) ||
                            (kinds[g][1] && !strncmp(c->name, kinds[g][1], strlen(kinds[g][1])));
            if (!in) continue;
            const int kb = app_ext_rows_find(&ext[1], c->name);
            if (kb < 0) {
                printf("  %-*s only in A\n", w, c->name);
                continue;
            }
            double scale = 1e3;
            const char* unit = "mm";
            if (g == 1) scale = 1e-6, unit = "MPa";
            else if (g == 2 && !strcmp(c->unit, "rad")) scale = 180 / M_PI, unit = "deg";
            const diff d = ext_diff(&ext[0], k, &ext[1], kb, scale);
            printf("  %-*s %9.4g %-3s %9.4g %-3s\n", w, c->name, d.rms, unit, d.max, unit);
            if (g == 0) *stroke_rms = fmax(*stroke_rms, d.rms);
            if (g == 1) {
                *prms = fmax(*prms, d.rms / scale);
                pk[0] = fmax(pk[0], ext_peak(&ext[0], k));
                pk[1] = fmax(pk[1], ext_peak(&ext[1], kb));
            }
        }
    }
    for (int k = 0; k < ext[1].ncol; ++k)
        if (app_ext_rows_find(&ext[0], ext[1].col[k].name) < 0 &&
            (!strncmp(ext[1].col[k].name, "x_", 2) || !strncmp(ext[1].col[k].name, "pA_", 3) ||
             !strncmp(ext[1].col[k].name, "pB_", 3) || !strncmp(ext[1].col[k].name, "q_", 2)))
            printf("  %-*s only in B\n", w, ext[1].col[k].name);
    for (int c = COL_TIP_X; c <= COL_TIP_Z; ++c) {
        const diff d = column_diff(&tr[0], &tr[1], c, 1e3);
        printf("  %-*s %9.4g %-3s %9.4g %-3s\n", w, sim_col_name[c], d.rms, "mm", d.max, "mm");
    }
    *ppeak = fmax(pk[0], pk[1]);
    *pside = pk[1] > pk[0] ? 1 : 0;
}

// Both sides have the same chain columns, name for name (one model on two
// backends or settings, or two designs of one shape).
static bool same_columns(const app_ext_rows ext[2]) {
    if (ext[0].ncol == 0 || ext[0].ncol != ext[1].ncol) return false;
    for (int k = 0; k < ext[0].ncol; ++k)
        if (strcmp(ext[0].col[k].name, ext[1].col[k].name)) return false;
    return true;
}

// A side's rows as the chain plot takes them: SIM_NCOL base columns, then
// its chain columns. NULL when out of memory.
static double* wide_rows(const sim_trace* tr, const app_ext_rows* e, int* nrow) {
    const int n = tr->nrow < e->nrow ? tr->nrow : (int)e->nrow, w = SIM_NCOL + e->ncol;
    double* v = malloc((size_t)(n > 0 ? n : 1) * (size_t)w * sizeof *v);
    if (!v) return NULL;
    for (int i = 0; i < n; ++i) {
        memcpy(v + (size_t)i * (size_t)w, tr->v + (size_t)i * SIM_NCOL, SIM_NCOL * sizeof *v);
        memcpy(v + (size_t)i * (size_t)w + SIM_NCOL, e->v + (size_t)i * (size_t)e->ncol, (size_t)e->ncol * sizeof *v);
    }
    *nrow = n;
    return v;
}

// The designs' metrics side by side, B - A, in the units a reader compares.
static void print_metrics(const sim_trace tr[2], const sim_result res[2], const sim_opts side[2], char label[2][96],
                          sim_energy* const en[2]) {
    run_metrics met[2];
    for (int s = 0; s < 2; ++s) {
        metrics_init(&met[s], sim_ncol(&side[s]));
        for (int i = 0; i < tr[s].nrow; ++i) metrics_row(&met[s], tr[s].v + (size_t)i * SIM_NCOL);
        metrics_finish(&met[s], &res[s]);
        if (en[s]) metrics_energy(&met[s], en[s]);
    }
    printf("  %-27s %14s %14s %14s\n", "metric", "A", "B", "B - A");
    for (int id = 0; id < MET_COUNT; ++id) {
        if (!met[0].present[id] || !met[1].present[id]) continue;
        const char* unit = metric_unit((metric_id)id);
        double k = 1.0;
        if (!strcmp(unit, "Pa")) k = 1e-6, unit = "MPa";
        else if (!strcmp(unit, "rad")) k = 180 / M_PI, unit = "deg";
        char name[64];
        snprintf(name, sizeof name, "%s [%s]", metric_name((metric_id)id), unit);
        printf("  %-27s %14.6g %14.6g %+14.6g\n", name, met[0].value[id] * k, met[1].value[id] * k,
               (met[1].value[id] - met[0].value[id]) * k);
    }
    printf("  (A = %s, B = %s)\n", label[0], label[1]);
}

// Both runs' rows side by side by index: t (A's), then NAME_A, NAME_B for
// every column both write, then for every chain column both have by name
// (ext: the sides' chain columns; none for the two-link crane). Returns 0,
// or -1 after one line on stderr.
static int write_both(const char* path, const sim_trace tr[2], const sim_opts side[2], const app_ext_rows ext[2]) {
    const int na = sim_ncol(&side[0]), nb = sim_ncol(&side[1]);
    const int ncol = na < nb ? na : nb, n = tr[0].nrow < tr[1].nrow ? tr[0].nrow : tr[1].nrow;
    app_out o = {.f = NULL};
    FILE* f = app_out_open(&o, path, "w");
    int e = f ? 0 : errno;
    if (f) {
        fputs("t", f);
        for (int c = 1; c < ncol; ++c) fprintf(f, ",%s_A,%s_B", sim_col_name[c], sim_col_name[c]);
        // A's chain columns that B has too, in A's order.
        int* kb = malloc((size_t)(ext[0].ncol > 0 ? ext[0].ncol : 1) * sizeof *kb);
        if (!kb) e = ENOMEM;
        for (int k = 0; kb && k < ext[0].ncol; ++k) {
            kb[k] = app_ext_rows_find(&ext[1], ext[0].col[k].name);
            if (kb[k] >= 0) fprintf(f, ",%s_A,%s_B", ext[0].col[k].name, ext[0].col[k].name);
        }
        fputc('\n', f);
        for (int i = 0; i < n; ++i) {
            const double* a = tr[0].v + (size_t)i * SIM_NCOL;
            const double* b = tr[1].v + (size_t)i * SIM_NCOL;
            fprintf(f, "%.9g", a[COL_T]);
            for (int c = 1; c < ncol; ++c) fprintf(f, ",%.9g,%.9g", a[c], b[c]);
            for (int k = 0; kb && k < ext[0].ncol; ++k)
                if (kb[k] >= 0 && i < ext[0].nrow && i < ext[1].nrow)
                    fprintf(f, ",%.9g,%.9g", ext[0].v[(size_t)i * (size_t)ext[0].ncol + (size_t)k],
                            ext[1].v[(size_t)i * (size_t)ext[1].ncol + (size_t)kb[k]]);
                else if (kb[k] >= 0)
                    fputs(",,", f); // a row a side's chain columns lack: empty fields, the row stays whole
            fputc('\n', f);
        }
        free(kb);
        if (ferror(f)) e = errno ? errno : EIO;
        e = app_out_close(&o, e, true);
    }
    if (e) fprintf(stderr, "cranesim compare: cannot write %s: %s\n", path, strerror(e));
    return e ? -1 : 0;
}

// An adaptive side that failed: whether a tighter --rtol runs it, so the
// error can say which one does ("try a smaller --rtol" left the user to
// guess; cvode at 1e-2 blows up on ramp, 1e-3 runs). Tries rtol/10 and
// rtol/100 (not below 1e-6), quietly; writes "; ..." to say, or nothing.
static void loose_tolerance(const model* m, const scenario* sc, const sim_opts* o, char* out, size_t n) {
    out[0] = 0;
    if (!o->cvode && !hyd_method_is_adaptive(o->solver)) return;
    sim_opts t = *o;
    int tried = 0;
    for (; tried < 2 && t.rtol / 10 >= 1e-6 * (1 - 1e-9); ++tried) {
        t.rtol /= 10;
        sim_result r;
        sim_run(m, sc, &t, NULL, NULL, NULL, NULL, NULL, &r);
        if (r.status == SIM_OK) {
            snprintf(out, n, "; --rtol %g runs it on this circuit (tried; it applies to both sides)", t.rtol);
            return;
        }
    }
    if (tried) snprintf(out, n, "; --rtol %g down to %g failed as well (tried)", o->rtol / 10, t.rtol);
}

int cmd_compare(int argc, char** argv) {
    app_common c = {.sim = sim_default_opts()};
    sim_opts side[2];
    char label[2][96] = {"", ""};
    bool any_pair = false;
    double tol_stroke = -1, tol_pressure = -1;
    const char* plot = NULL;
    char pa[64], pb[64];
    const char* pairs[4] = {NULL, NULL, NULL, NULL}; // backends, solvers, variants, dts
    // Two designs: two model files, or per-side --set changes.
    const char* models[2] = {NULL, NULL};
    int nmodel = 0;
    const char* side_set[2][APP_MAX_SET];
    int nside_set[2] = {0, 0};
    const char* out = NULL;
    for (int i = 0; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            compare_help(stdout);
            return 0;
        }
        if (!strcmp(argv[i], "--model")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if (nmodel == 2) {
                fprintf(stderr, "cranesim compare: --model: at most two (design A's and design B's), got a third '%s'\n", v);
                return EXIT_USAGE;
            }
            models[nmodel++] = v;
            continue;
        }
        if (!strcmp(argv[i], "--set-a") || !strcmp(argv[i], "--set-b")) {
            const int sd = argv[i][6] == 'b';
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if (!strchr(v, '=') || nside_set[sd] + c.nset >= APP_MAX_SET) {
                fprintf(stderr, "cranesim compare: --set-%c: expected PATH=VALUE (at most %d), got '%s'\n", 'a' + sd,
                        APP_MAX_SET, v);
                return EXIT_USAGE;
            }
            side_set[sd][nside_set[sd]++] = v;
            continue;
        }
        if (!strcmp(argv[i], "--out")) {
            if (!(out = app_value(argc, argv, &i))) return EXIT_USAGE;
            continue;
        }
        int rc = app_parse_common(&c, argc, argv, &i);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        static const char* const popt[] = {"--backends", "--solvers", "--variants", "--dts"};
        int pk = -1;
        for (int k = 0; k < 4; ++k)
            if (!strcmp(argv[i], popt[k])) pk = k;
        if (pk >= 0) {
            if (!(pairs[pk] = app_value(argc, argv, &i))) return EXIT_USAGE;
            continue;
        }
        if (!strcmp(argv[i], "--tol-stroke") || !strcmp(argv[i], "--tol-pressure")) {
            const char* opt = argv[i];
            const char* v = app_value(argc, argv, &i);
            double d;
            if (!v) return EXIT_USAGE;
            if (app_parse_double(v, &d) || d < 0) {
                fprintf(stderr, "cranesim compare: %s: expected a number >= 0, got '%s'\n", opt, v);
                return EXIT_USAGE;
            }
            if (opt[6] == 's') tol_stroke = d;
            else tol_pressure = d;
            continue;
        }
        if (!strcmp(argv[i], "--plot")) {
            if (!(plot = app_value(argc, argv, &i))) return EXIT_USAGE;
            continue;
        }
        fprintf(stderr, "cranesim compare: unknown option '%s' (see cranesim compare --help)\n", argv[i]);
        return EXIT_USAGE;
    }
    // --dts sets both sides' steps: a --dt beside it would be overridden
    // on both, so one of them was not meant.
    if (pairs[3] && (c.given & APP_GIVEN(APP_OPT_DT))) {
        fprintf(stderr, "cranesim compare: --dt and --dts both given: --dts H1,H2 sets each side's step; drop --dt\n");
        return EXIT_USAGE;
    }
    side[0] = side[1] = c.sim;
    label[0][0] = label[1][0] = 0;
    for (int k = 0; k < 4; ++k) {
        if (!pairs[k]) continue;
        static const char* const popt[] = {"--backends", "--solvers", "--variants", "--dts"};
        if (split_pair(popt[k], pairs[k], pa, pb)) return EXIT_USAGE;
        any_pair = true;
        const char* v[2] = {pa, pb};
        for (int s = 0; s < 2; ++s) {
            if (k == 0) {
                if (app_set_mechanics(&side[s], "--backends", v[s])) return EXIT_USAGE;
            } else if (k == 1) {
                if (app_set_solver(&side[s], "--solvers", v[s])) return EXIT_USAGE;
            } else if (k == 2) {
                if (app_set_variant(&side[s], "--variants", v[s])) return EXIT_USAGE;
            } else if (app_parse_double(v[s], &side[s].h) || !(side[s].h > 0)) {
                fprintf(stderr, "cranesim compare: --dts: expected positive steps [s], got '%s'\n", v[s]);
                return EXIT_USAGE;
            }
            size_t L = strlen(label[s]);
            snprintf(label[s] + L, sizeof label[s] - L, "%s%s", L ? "/" : "", v[s]);
        }
    }
    const bool designs = nmodel == 2 || nside_set[0] || nside_set[1];
    if (nmodel == 1) c.model_path = models[0];
    if (designs) {
        // Each side's label: its model file and its own changes, short
        // (file base names, the last path element) unless the short labels
        // are equal; a side with no file and no change of its own is named
        // by the model file both share ("A = A" said nothing).
        char pair_label[2][96];
        memcpy(pair_label, label, sizeof pair_label);
        for (int full = 0; full < 2; ++full) {
            for (int s = 0; s < 2; ++s) {
                memcpy(label[s], pair_label[s], sizeof label[s]);
                size_t L = strlen(label[s]);
                if (nmodel == 2) {
                    const char* base = full ? NULL : strrchr(models[s], '/');
                    L += (size_t)snprintf(label[s] + L, sizeof label[s] - L, "%s%s", L ? "/" : "",
                                          base ? base + 1 : models[s]);
                }
                for (int k = 0; k < nside_set[s] && L < sizeof label[s]; ++k) {
                    const char* dot = full ? side_set[s][k] : strchr(side_set[s][k], '=');
                    while (!full && dot > side_set[s][k] && dot[-1] != '.') --dot; // the last path element
                    L += (size_t)snprintf(label[s] + L, sizeof label[s] - L, "%s%s", L ? " " : "", dot);
                }
                if (!label[s][0]) {
                    const char* file = c.model_path ? c.model_path : model_default_path();
                    const char* base = full ? NULL : strrchr(file, '/');
                    snprintf(label[s], sizeof label[s], "%s", base ? base + 1 : file);
                }
            }
            if (strcmp(label[0], label[1])) break;
        }
    }
    if (any_pair && designs) {
        // Two designs and a setting pair: the differences are the sum of the
        // design's effect and the setting's, which the table cannot separate.
        static const char* const popt[] = {"--backends", "--solvers", "--variants", "--dts"};
        char which[80] = "";
        size_t L = 0;
        for (int k = 0; k < 4; ++k)
            if (pairs[k]) L += (size_t)snprintf(which + L, sizeof which - L, "%s%s", L ? ", " : "", popt[k]);
        fprintf(stderr,
                "cranesim compare: note: A and B differ in design (%s) and in %s: the differences mix both; "
                "compare one change at a time to tell them apart\n",
                nmodel == 2 ? "--model A --model B" : "--set-a/--set-b", which);
    }
    // The default comparison: the default backend (the analytic reference,
    // lagrange full) against the backend with a world (ode, its validation
    // world).
    const engine_backend* pair[2] = {engine_backend_default(), engine_backend_with_world()};
    if (!any_pair && !designs) {
        if (!pair[1] || pair[1] == pair[0]) {
            fprintf(stderr, "cranesim compare: no second backend to compare with: give --backends A,B\n");
            return EXIT_USAGE;
        }
        for (int s = 0; s < 2; ++s) {
            app_use_backend(&side[s], pair[s]);
            snprintf(label[s], sizeof label[s], "%s", pair[s]->name);
        }
    }
    // Both runs and the plot file are checked before anything runs.
    if (plot && app_check_output("compare", "--plot", plot, ".png")) return EXIT_USAGE;
    if (out && app_check_output("compare", "--out", out, ".csv")) return EXIT_USAGE;
    if (app_check_distinct("compare", (const char* const[]){"--out", "--plot"}, (const char* const[]){out, plot}, 2))
        return EXIT_USAGE;
    for (int s = 0; s < 2; ++s) {
        // A side's own choice (--backends, --solvers) counts as given.
        unsigned given = c.given;
        if (pairs[0]) given |= APP_GIVEN(APP_OPT_MECHANICS);
        if (pairs[1]) given |= APP_GIVEN(APP_OPT_SOLVER);
        if (pairs[3]) given |= APP_GIVEN(APP_OPT_DT);
        const int rc = app_check_sim("compare", &side[s], given);
        if (rc) return rc;
    }
    // Rows are compared by index, so both runs must write them on one grid:
    // a fixed step longer than --every writes one row per step (decision 7).
    const double per_a = app_output_period(&side[0]), per_b = app_output_period(&side[1]);
    if (fabs(per_a - per_b) > 1e-9 * fmax(per_a, per_b)) {
        fprintf(stderr,
                "cranesim compare: %s writes rows every %g ms and %s every %g ms: they cannot be compared row by "
                "row; give --every %g (a multiple of both steps)\n",
                label[0][0] ? label[0] : "A", per_a * 1e3, label[1][0] ? label[1] : "B", per_b * 1e3, fmax(per_a, per_b));
        return EXIT_USAGE;
    }
    model* m;
    model* mb = NULL; // design B's model (designs only; else both run m)
    scenario sc;
    app_common ca = c;
    if (designs) {
        // Side A: its file, the shared --set, then its own.
        if (nmodel == 2) ca.model_path = models[0];
        for (int k = 0; k < nside_set[0]; ++k) ca.sets[ca.nset++] = side_set[0][k];
    }
    int rc = app_load(&ca, &m, &sc);
    if (!rc && designs) {
        const char* sets[APP_MAX_SET];
        int n = 0;
        for (int k = 0; k < c.nset; ++k) sets[n++] = c.sets[k];
        for (int k = 0; k < nside_set[1] && n < APP_MAX_SET; ++k) sets[n++] = side_set[1][k];
        char err[1024];
        mb = model_load(nmodel == 2 ? models[1] : c.model_path, sets, n, err, sizeof err);
        if (!mb) {
            fprintf(stderr, "cranesim compare: design B: %s\n", err);
            rc = EXIT_USAGE;
        }
    }
    // Both sides must run the scenario as written: a backend the pair (or
    // the default pair) chose is never switched; a side's options that leave
    // the backend or the world open go to the sandbox as run's do, said once.
    // The advice must name what put a side on the wrong crane: the default
    // pair or the user's --backends (--mechanics alone is overridden by them).
    bool switched[2] = {false, false};
    for (int s = 0; s < 2 && !rc; ++s) {
        char remedy[400];
        const char* ab = s ? "B" : "A";
        const engine_backend* b = app_backend(&side[s]);
        const engine_backend* wb = engine_backend_with_world();
        char dflt[96];
        snprintf(dflt, sizeof dflt, "the default --backends %s,%s", pair[0]->name, pair[1] ? pair[1]->name : "?");
        if (b->world)
            snprintf(remedy, sizeof remedy, "give --world %s (side %s runs the %s backend)", b->drive_world, ab,
                     b->name);
        else if (!wb)
            snprintf(remedy, sizeof remedy, "no backend has a world");
        else if (pairs[0] || (!any_pair && !designs))
            snprintf(remedy, sizeof remedy,
                     "side %s runs there because of %s; to compare in the %s, keep both sides there: "
                     "--mechanics %s --world %s with another pair (--dts H1,H2, or --set-a/--set-b)",
                     ab, pairs[0] ? "--backends" : dflt, wb->drive_world, wb->name, wb->drive_world);
        else
            snprintf(remedy, sizeof remedy, "run it with --mechanics %s --world %s", wb->name, wb->drive_world);
        const unsigned given =
            c.given | (pairs[0] || (!any_pair && !designs) ? APP_GIVEN(APP_OPT_MECHANICS) : 0u);
        // No model: a slewing scenario stays refused or goes to the sandbox
        // as before (compare's sides are the validation world's crane; the
        // analytic slew is for run, sweep and optimize).
        rc = app_scenario_world_remedy("compare", &side[s], given, NULL, &sc, true, &switched[s], remedy,
                                       s == 1 && switched[0]);
        if (!rc && switched[s]) rc = app_check_sim("compare", &side[s], given);
    }
    if (rc && m) {
        model_free(m);
        model_free(mb);
        return rc;
    }
    if (rc) return rc;
    app_note_unused("compare", c.given, side, 2);
    app_note_load("compare", &c, &side[0], &sc);
    app_settle_unused(&side[0]);
    app_settle_unused(&side[1]);
    sim_trace tr[2] = {{0}, {0}};
    sim_result res[2];
    // A chain model's own columns (every actuator, function and DOF by
    // name), which the traces do not hold.
    app_ext_rows ext[2] = {{.off = 0}, {.off = 0}};
    // Each side's energy balance, as run keeps it (docs/energy.md); NULL
    // when out of memory (the comparison runs without it).
    sim_energy* en[2] = {sim_energy_create(), sim_energy_create()};
    for (int s = 0; s < 2; ++s) {
        if (!c.quiet && isatty(2)) fprintf(stderr, "run %s:\n", label[s]);
        ext[s].off = sim_ncol(&side[s]);
        ext[s].model_chain = &(s && mb ? mb : m)->chain;
        sim_run_energy_chain(s && mb ? mb : m, &sc, &side[s], app_ext_rows_cb, &ext[s], &tr[s],
                             c.quiet ? NULL : app_progress, NULL, en[s], &ext[s].run_chain, &res[s]);
        ext[s].run_chain = NULL; // it lived until the run returned
        if (ext[s].oom && !res[s].status) {
            res[s].status = SIM_FAILED;
            snprintf(res[s].message, sizeof res[s].message, "out of memory for the chain columns");
        }
        if (!c.quiet) app_progress_done();
        if (res[s].note[0]) fprintf(stderr, "cranesim compare: %s: note: %s\n", label[s], res[s].note);
        if (res[s].status) {
            char works[200] = "";
            if (res[s].status == SIM_FAILED) loose_tolerance(s && mb ? mb : m, &sc, &side[s], works, sizeof works);
            fprintf(stderr, "cranesim compare: %s: %s%s\n", label[s], res[s].message, works);
            sim_energy_free(en[0]);
            sim_energy_free(en[1]);
            sim_trace_free(&tr[0]);
            sim_trace_free(&tr[1]);
            app_ext_rows_free(&ext[0]);
            app_ext_rows_free(&ext[1]);
            model_free(m);
            model_free(mb);
            return app_exit_code(res[s].status, 0);
        }
    }
    printf("cranesim compare: %s, A = %s, B = %s, %d rows\n", sc.name, label[0], label[1],
           tr[0].nrow < tr[1].nrow ? tr[0].nrow : tr[1].nrow);
    // Two chain runs: by name, every actuator and DOF; else the two-link
    // crane's table by position, as it always was.
    const bool by_name = ext[0].ncol > 0 && ext[1].ncol > 0;
    double stroke_rms = 0, prms, ppeak, press_pct;
    int pside;
    if (by_name) {
        print_ext_table(ext, tr, &stroke_rms, &prms, &ppeak, &pside);
        press_pct = ppeak > 0 ? 100.0 * prms / ppeak : 0.0;
    } else {
        printf("  %-8s %12s %12s\n", "column", "RMS diff", "max diff");
        struct {
            int col;
            double scale;
            const char* unit;
        } rows[] = {{COL_X1, 1e3, "mm"},  {COL_X2, 1e3, "mm"},         {COL_P1A, 1e-6, "MPa"},
                    {COL_P1B, 1e-6, "MPa"}, {COL_P2A, 1e-6, "MPa"},    {COL_P2B, 1e-6, "MPa"},
                    {COL_Q1, 180 / M_PI, "deg"}, {COL_Q2, 180 / M_PI, "deg"}, {COL_TIP_X, 1e3, "mm"},
                    {COL_TIP_Z, 1e3, "mm"}};
        for (size_t k = 0; k < sizeof rows / sizeof rows[0]; ++k) {
            diff d = column_diff(&tr[0], &tr[1], rows[k].col, rows[k].scale);
            printf("  %-8s %9.4g %-3s %9.4g %-3s\n", sim_col_name[rows[k].col], d.rms, rows[k].unit, d.max,
                   rows[k].unit);
            if (rows[k].col == COL_X1 || rows[k].col == COL_X2) stroke_rms = fmax(stroke_rms, d.rms);
        }
        // No side is the reference: the figure is a difference between two
        // runs, as a share of the higher peak (README.md, "compare").
        app_compare_pressure(&tr[0], &tr[1], &prms, &ppeak, &press_pct, &pside);
    }
    printf("  worst stroke RMS %.4g mm; worst pressure RMS %.4g MPa = %.3g %% of the higher peak %.2f MPa (%s = %s; "
           "no side is taken as the reference)\n",
           stroke_rms, prms * 1e-6, press_pct, ppeak * 1e-6, pside ? "B" : "A", label[pside]);
    if (designs) print_metrics(tr, res, side, label, en);
    if (en[0] && en[1]) {
        // Each side's balance as run prints it, then B - A term by term.
        sim_energy_balance eb[2];
        sim_energy_result(en[0], &eb[0]);
        sim_energy_result(en[1], &eb[1]);
        if (eb[0].samples > 1 && eb[1].samples > 1) {
            app_print_energy(en[0], &eb[0], "A");
            app_print_energy(en[1], &eb[1], "B");
            app_print_energy_diff((const sim_energy* const[2]){en[0], en[1]}, eb, "B - A");
        }
    }
    int code = 0;
    if (out && write_both(out, tr, side, ext)) code = EXIT_RUNTIME;
    else if (out) printf("  rows of both -> %s\n", out);
    if (tol_stroke >= 0 && stroke_rms > tol_stroke) {
        printf("  FAIL: stroke RMS %.4g mm > tolerance %.4g mm\n", stroke_rms, tol_stroke);
        code = EXIT_RUNTIME;
    }
    if (tol_pressure >= 0 && press_pct > tol_pressure) {
        printf("  FAIL: pressure RMS %.3g %% > tolerance %.3g %%\n", press_pct, tol_pressure);
        code = EXIT_RUNTIME;
    }
    if (plot) {
        char err[512], title[320];
        snprintf(title, sizeof title, "%s: %s vs %s", sc.name, label[0], label[1]);
        // Two chain runs of one shape: the chain page by actuator and
        // function, A solid and B dashed; else the two-link overlay (for two
        // shapes, said: its first two cylinders are the models' first two).
        int prc;
        if (same_columns(ext)) {
            int na = 0, nb = 0;
            double* wa = wide_rows(&tr[0], &ext[0], &na);
            double* wb = wide_rows(&tr[1], &ext[1], &nb);
            if (wa && wb) {
                prc = app_plot_chain_compare(wa, na, label[0], wb, nb, label[1], SIM_NCOL + ext[0].ncol, ext[0].col,
                                             ext[0].ncol,
                                             app_world_has_slew(&side[0]) && app_world_has_slew(&side[1]), title,
                                             plot, err, sizeof err);
            } else {
                snprintf(err, sizeof err, "out of memory");
                prc = -1;
            }
            free(wa);
            free(wb);
        } else {
            if (ext[0].ncol || ext[1].ncol)
                fprintf(stderr, "cranesim compare: note: the sides' models differ in shape: the plot shows their "
                                "first two cylinders (x1, x2) by position\n");
            prc = app_plot_compare(&tr[0], label[0], &tr[1], label[1], title,
                                   app_world_has_slew(&side[0]) && app_world_has_slew(&side[1]), plot, err, sizeof err);
        }
        if (prc) {
            fprintf(stderr, "cranesim compare: plot: %s\n", err);
            code = EXIT_RUNTIME;
        } else {
            printf("  plot -> %s\n", plot);
        }
    }
    sim_energy_free(en[0]);
    sim_energy_free(en[1]);
    sim_trace_free(&tr[0]);
    sim_trace_free(&tr[1]);
    app_ext_rows_free(&ext[0]);
    app_ext_rows_free(&ext[1]);
    model_free(m);
    model_free(mb);
    return code;
}
