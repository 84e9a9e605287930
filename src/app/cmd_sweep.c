// cmd_sweep.c: `cranesim sweep`: one scenario run on many designs (a full
// grid or a Latin hypercube over model paths), the designs in parallel on
// threads (on the ode backend: worker processes; and on MPI ranks when built
// with MPI and started by mpirun or srun), one results row per design in
// design-index order.
#define _DEFAULT_SOURCE // strsep
#include "app.h"
#include "app_design_metrics.h"
#include "energy_acc.h"
#include "json_util.h"
#include "metrics.h"

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#ifdef CRANESIM_HAVE_MPI
#include <mpi.h>
#endif

// SW_MAXMET: the run metrics and a chain model's per actuator and function
// (six per actuator, one per function: far more than any crane has).
enum { SW_MAXPAR = APP_MAX_PARAM, SW_MAXDESIGN = 10000000, SW_MAXMET = MET_COUNT + 2048 };

static void sweep_help(FILE* f) {
    fprintf(f,
            "usage: cranesim sweep [--scenario S] [--model M] --param PATH=LO:HI:N [--param ...]\n"
            "                      [--lhs N [--seed K]] [--metrics m1,m2] [--threads T] [--fail-fast]\n"
            "                      [--out sweep.csv] [--plot DIR|FILE.png] [options]\n"
            "\n"
            "Runs the scenario once per design and writes one CSV row per design, in design-index\n"
            "order: index, the parameter values, the metrics, exit (0 ok, 1 failed: a numerical\n"
            "blow-up, 2 refused: a value the model or the run does not accept) and the error text.\n"
            "A failing design is a row, not the end of the sweep. Designs run in parallel on\n"
            "threads; under mpirun or srun (a build with MPI) they are spread over the ranks and\n"
            "rank 0 writes the same file. docs/sweep.md has the details and a Slurm script.\n"
            "\n"
            "options:\n"
            "  --param PATH=LO:HI:N a model path (the --set syntax, a number) from LO to HI in N\n"
            "                       equal steps (a full grid over every --param, the last one\n"
            "                       varying fastest); with --lhs: PATH=LO:HI (up to %d)\n"
            "  --lhs N              a Latin hypercube of N designs instead of the grid\n"
            "  --seed K             its random seed (default 1; same seed, same designs)\n"
            "  --metrics LIST       the metrics to tabulate, comma separated (default: every metric\n"
            "                       the run has but energy_in, energy_loss and collision_count; p3A,\n"
            "                       p3B, slew, tilt, sway and collision_count: ode only):",
            SW_MAXPAR);
    // Each name with its unit (the CSV's, SI), wrapped under the option's text.
    int col = 999;
    for (int id = 0; id < MET_COUNT; ++id) {
        char tok[96];
        snprintf(tok, sizeof tok, " %s [%s]%s", metric_name((metric_id)id), metric_unit((metric_id)id),
                 id + 1 < MET_COUNT ? "," : "");
        if (col + (int)strlen(tok) > 92) col = fprintf(f, "\n                      ");
        col += fprintf(f, "%s", tok);
    }
    fprintf(f, "\n");
    fprintf(f,
            "                       a crane chain model (mechanics.bodies) adds its metrics by actuator\n"
            "                       and function, named as run --metrics names them: stroke_min,\n"
            "                       stroke_max [m], peak_pA, peak_pB [Pa], peak_force [N], end_stop_hits\n"
            "                       .ACTUATOR and max_spool.FUNCTION [-] (peak_pA.lift, max_spool.ext);\n"
            "                       the default table has every one\n");
    fprintf(f,
            "  --threads T          designs run at once (default: every core; 1 per rank under MPI):\n"
            "                       threads, or on the ode backend T worker processes (ODE is\n"
            "                       process-wide); a worker that dies fails its design (exit 1)\n"
            "  --fail-fast          stop at the first failing design (exit 1)\n"
            "  --out FILE           results CSV (default sweep.csv), replaced when the sweep ends\n"
            "  --plot DIR|FILE.png  plots: each metric against each parameter, and a heat map of\n"
            "                       each metric for a two-parameter grid (a .png name: the first);\n"
            "                       the metrics in the run summary's units (MPa, deg, kJ, kN), the\n"
            "                       CSV's in the SI units listed above\n");
    app_common_help(f, true);
    fprintf(f,
            "\nexit codes: 0 done (also with failing designs), 1 --fail-fast stopped or a failed write,\n"
            "2 bad input (nothing is written), 130 or 143 interrupted (the rows finished so far kept)\n"
            "example: cranesim sweep --scenario ramp --param hydraulics.components.lift_cyl.bore=0.08:0.12:5\n");
}

typedef app_range sweep_param;

typedef struct sweep {
    app_common c;
    model* base;
    scenario sc;
    sweep_param par[SW_MAXPAR];
    int npar;
    long ndesign;
    long lhs;           ///< > 0: Latin hypercube of this many designs
    double* lhs_v;      ///< npar x ndesign values of the hypercube
    int met[SW_MAXMET]; ///< the metrics tabulated (app_design_metrics.h ids)
    int nmet;
    int ncol;
    bool fail_fast;
    bool process_wide;  ///< the backend's library is process-wide (engine_backend.h): one design at a time per process
    bool energy;        ///< a tabulated metric needs the energy accounting
    // Dispatch and results (under mu).
    pthread_mutex_t mu;
    pthread_cond_t cv;
    long next, stride;  ///< next design of this process, and the step (the MPI ranks interleave)
    char** line;        ///< finished rows by design index, NULL until done (or once written)
    long* fin;          ///< queue of designs finished here, not yet handed to the writer
    long nfin;
    int active;         ///< worker threads still running
    bool stop;          ///< --fail-fast hit or a signal: no more designs
    long failed;
} sweep;

// A backend whose library is process-wide (engine_backend.process_wide: the
// ODE library and the ode world's error trap): one design at a time per
// process (threads still overlap loading and writing).
static pthread_mutex_t g_process_wide_mu = PTHREAD_MUTEX_INITIALIZER;

// The design values drop the model's range notes ("outside the typical
// range"): thousands of designs would repeat them, and the row has the value.
static void quiet_note(const char* line, void* user) {
    (void)line;
    (void)user;
}

static double design_value(const sweep* s, long i, int k) {
    const sweep_param* p = &s->par[k];
    if (s->lhs > 0) return s->lhs_v[(size_t)k * (size_t)s->ndesign + (size_t)i];
    long stride = 1;
    for (int j = s->npar - 1; j > k; --j) stride *= s->par[j].n;
    const long j = (i / stride) % p->n;
    if (p->n == 1) return p->lo;
    if (j == p->n - 1) return p->hi;
    // The grid point as the decimal it stands for: the design then is the
    // run of `--set PATH=0.11`, bit for bit, and the file says 0.11.
    return app_snap_decimal(p->lo + (p->hi - p->lo) * ((double)j / (double)(p->n - 1)));
}

// A 64-bit generator the same on every machine (splitmix64), so a seed
// gives the same hypercube everywhere.
static uint64_t mix_next(uint64_t* s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double mix_unit(uint64_t* s) { return (double)(mix_next(s) >> 11) * 0x1.0p-53; }

// Latin hypercube: each parameter's range cut into N equal strata, each
// stratum used by exactly one design, at a uniform point inside it; the
// strata of different parameters paired by independent random permutations.
static int make_lhs(sweep* s, uint64_t seed) {
    const size_t n = (size_t)s->ndesign;
    s->lhs_v = malloc((size_t)s->npar * n * sizeof(double));
    long* perm = malloc(n * sizeof(long));
    if (!s->lhs_v || !perm) {
        free(perm);
        return -1;
    }
    uint64_t st = seed;
    for (int k = 0; k < s->npar; ++k) {
        for (size_t i = 0; i < n; ++i) perm[i] = (long)i;
        for (size_t i = n - 1; i > 0; --i) {
            const size_t j = (size_t)(mix_next(&st) % (uint64_t)(i + 1));
            const long t = perm[i];
            perm[i] = perm[j];
            perm[j] = t;
        }
        const sweep_param* p = &s->par[k];
        for (size_t i = 0; i < n; ++i)
            s->lhs_v[(size_t)k * n + i] = p->lo + (p->hi - p->lo) * (((double)perm[i] + mix_unit(&st)) / (double)n);
    }
    free(perm);
    return 0;
}

// A growing text buffer for one row.
typedef struct sbuf {
    char* p;
    size_t n, cap;
} sbuf;
static void sb_printf(sbuf* b, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_printf(sbuf* b, const char* fmt, ...) {
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        const size_t room = b->cap - b->n;
        const int k = b->p ? vsnprintf(b->p + b->n, room, fmt, ap) : -1;
        va_end(ap);
        if (k >= 0 && (size_t)k < room) {
            b->n += (size_t)k;
            return;
        }
        const size_t cap = b->cap ? 2 * b->cap + (k > 0 ? (size_t)k : 0) : 512;
        char* p = realloc(b->p, cap);
        if (!p) abort(); // a few hundred bytes: nothing sensible is left to do
        b->p = p;
        b->cap = cap;
    }
}

static char* format_row(const sweep* s, long i, const app_design_run* dr, int code, const char* err);

// Run design i; its CSV row (malloc'd, with the newline), or NULL when a
// signal cut it short (it is then not a finished design). *failed: exit != 0.
static char* run_design(const sweep* s, long i, bool* failed) {
    double v[SW_MAXPAR];
    for (int k = 0; k < s->npar; ++k) v[k] = design_value(s, i, k);
    char err[1024] = "";
    int code = 0;
    app_design_run dr;
    app_design_run_init(&dr, s->base, s->ncol);
    cJSON* doc = cJSON_Duplicate(s->base->json, 1);
    if (!doc) {
        snprintf(err, sizeof err, "out of memory");
        code = EXIT_RUNTIME;
    }
    for (int k = 0; k < s->npar && !code; ++k) {
        char asg[320];
        char num[32];
        snprintf(asg, sizeof asg, "%s=%s", s->par[k].path, app_fmt_double(num, sizeof num, v[k]));
        if (json_set_path(doc, asg, err, sizeof err)) code = EXIT_USAGE;
    }
    model* m = NULL;
    if (!code) {
        m = model_from_json(doc, s->base->file, err, sizeof err);
        doc = NULL; // the model owns it now, also on failure
        if (!m) code = EXIT_USAGE;
    }
    cJSON_Delete(doc);
    if (m) {
        sim_result res;
        sim_energy* en = s->energy ? sim_energy_create() : NULL;
        if (s->process_wide) pthread_mutex_lock(&g_process_wide_mu);
        // The design's own chain gives its rows' chain columns (the slewing
        // run's, with its rack, from the first row): metrics by actuator and
        // function (app_design_metrics.h).
        dr.chain = &m->chain;
        sim_run_energy_chain(m, &s->sc, &s->c.sim, app_design_row, &dr, NULL, NULL, NULL, en, &dr.chain, &res);
        if (s->process_wide) pthread_mutex_unlock(&g_process_wide_mu);
        model_free(m);
        dr.chain = NULL; // the run's chain lived until the run returned; the stats copied what they need
        if (res.status == SIM_REFUSED && app_signal_caught()) {
            sim_energy_free(en);
            app_design_run_free(&dr);
            return NULL;
        }
        metrics_finish(&dr.met, &res);
        if (en) metrics_energy(&dr.met, en);
        sim_energy_free(en);
        if (res.status != SIM_OK) {
            code = res.status == SIM_FAILED ? EXIT_RUNTIME : EXIT_USAGE;
            snprintf(err, sizeof err, "%s", res.message);
        }
    }
    if (!code && dr.oom) {
        snprintf(err, sizeof err, "out of memory");
        code = EXIT_RUNTIME;
    }
    *failed = code != 0;
    char* line = format_row(s, i, &dr, code, err);
    app_design_run_free(&dr);
    return line;
}

// The CSV row of design i (malloc'd, with the newline): its values, the
// metrics (empty when code != 0 or met is NULL), the exit code and err.
static char* format_row(const sweep* s, long i, const app_design_run* dr, int code, const char* err) {
    const run_metrics* met = dr ? &dr->met : NULL;
    double v[SW_MAXPAR];
    for (int k = 0; k < s->npar; ++k) v[k] = design_value(s, i, k);
    sbuf b = {0};
    sb_printf(&b, "%ld", i);
    char num[32];
    for (int k = 0; k < s->npar; ++k) sb_printf(&b, ",%s", app_fmt_double(num, sizeof num, v[k]));
    // A failed design's metrics are left empty: those of a run cut short
    // by a blow-up are not the design's.
    for (int k = 0; k < s->nmet; ++k) {
        // A metric the run's world does not have (collisions in the
        // validation world) is empty too, not 0.
        const double v = met ? app_design_value(dr, s->met[k]) : NAN;
        if (code || !met || (s->met[k] == MET_COLLISIONS && !met->present[MET_COLLISIONS]) || !isfinite(v))
            sb_printf(&b, ",");
        else sb_printf(&b, ",%s", app_fmt_double(num, sizeof num, v));
    }
    sb_printf(&b, ",%d,", code);
    if (code) {
        // The error as one quoted CSV field (quotes doubled, no newlines).
        sb_printf(&b, "\"");
        for (const char* p = err; *p; ++p) {
            if (*p == '"') sb_printf(&b, "\"\"");
            else sb_printf(&b, "%c", *p == '\n' || *p == '\r' ? ' ' : *p);
        }
        sb_printf(&b, "\"");
    }
    sb_printf(&b, "\n");
    return b.p;
}

// The exit field of a row (after index, the parameters and the metrics).
static int line_exit(const sweep* s, const char* line) {
    const char* p = line;
    for (int k = 0; k < 1 + s->npar + s->nmet && p; ++k) {
        p = strchr(p, ',');
        if (p) ++p;
    }
    return p ? atoi(p) : 0;
}

static void* worker(void* arg) {
    sweep* s = arg;
    for (;;) {
        pthread_mutex_lock(&s->mu);
        if (s->stop || app_signal_caught() || s->next >= s->ndesign) {
            --s->active;
            pthread_cond_broadcast(&s->cv);
            pthread_mutex_unlock(&s->mu);
            return NULL;
        }
        const long i = s->next;
        s->next += s->stride;
        pthread_mutex_unlock(&s->mu);
        bool failed = false;
        char* line = run_design(s, i, &failed);
        pthread_mutex_lock(&s->mu);
        if (line) {
            s->line[i] = line;
            s->fin[s->nfin++] = i;
            if (failed) {
                ++s->failed;
                if (s->fail_fast) s->stop = true;
            }
        }
        pthread_cond_broadcast(&s->cv);
        pthread_mutex_unlock(&s->mu);
    }
}

// ---------------------------------------------------------------------------
// Parsing
// ---------------------------------------------------------------------------

// app.h: "PATH=LO:HI:N" (want_n) or "PATH=LO:HI"; shared with cmd_optimize.c.
int app_parse_range(const char* cmd, const char* arg, bool want_n, app_range* p) {
    const char* eq = strrchr(arg, '=');
    if (!eq || eq == arg || (size_t)(eq - arg) >= sizeof p->path) {
        fprintf(stderr, "cranesim %s: --param '%s': expected PATH=LO:HI%s\n", cmd, arg, want_n ? ":N" : "");
        return -1;
    }
    snprintf(p->path, sizeof p->path, "%.*s", (int)(eq - arg), arg);
    char buf[256];
    snprintf(buf, sizeof buf, "%s", eq + 1);
    char* f[4];
    int nf = 0;
    for (char *q = buf, *tok; nf < 4 && (tok = strsep(&q, ":"));) f[nf++] = tok;
    if (nf != (want_n ? 3 : 2) || app_parse_double(f[0], &p->lo) || app_parse_double(f[1], &p->hi) ||
        !isfinite(p->lo) || !isfinite(p->hi)) {
        if (nf == 3 && !want_n && !strcmp(cmd, "sweep"))
            fprintf(stderr, "cranesim %s: --param '%s': with --lhs give PATH=LO:HI (--lhs sets the count)\n",
                    cmd, arg);
        else
            fprintf(stderr, "cranesim %s: --param '%s': expected PATH=LO:HI%s with finite numbers\n", cmd, arg,
                    want_n ? ":N" : "");
        return -1;
    }
    if (p->lo > p->hi) {
        fprintf(stderr, "cranesim %s: --param '%s': LO %g is above HI %g\n", cmd, arg, p->lo, p->hi);
        return -1;
    }
    p->n = 1;
    if (want_n) {
        char* end;
        errno = 0;
        const long n = strtol(f[2], &end, 10);
        if (!*f[2] || *end || errno || n < 1 || n > SW_MAXDESIGN) {
            fprintf(stderr, "cranesim %s: --param '%s': N must be a whole number in [1, %d], got '%s'\n", cmd, arg,
                    SW_MAXDESIGN, f[2]);
            return -1;
        }
        if (n == 1 && p->lo != p->hi) {
            fprintf(stderr, "cranesim %s: --param '%s': N = 1 needs LO = HI (one value)\n", cmd, arg);
            return -1;
        }
        p->n = n;
    }
    return 0;
}

// app.h: --param, --out, --plot of sweep and optimize; one table, one loop.
int app_parse_design_opt(const char* cmd, int argc, char** argv, int* i, app_design_opts* d) {
    static const char* const names[] = {"--param", "--out", "--plot"};
    const char* a = argv[*i];
    int k = 0;
    while (k < 3 && strcmp(a, names[k])) ++k;
    if (k == 3) return 0;
    const char* v = app_value(argc, argv, i);
    if (!v) return -1;
    if (k == 0) {
        if (d->nparam == APP_MAX_PARAM) {
            fprintf(stderr, "cranesim %s: at most %d --param\n", cmd, APP_MAX_PARAM);
            return -1;
        }
        d->param[d->nparam++] = v;
    } else if (k == 1) {
        d->out = v;
    } else {
        d->plot = v;
    }
    return 1;
}

static int parse_metrics(sweep* s, const char* list) {
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", list);
    s->nmet = 0;
    for (char *q = buf, *tok; (tok = strsep(&q, ","));) {
        const int id = app_design_metric_find(tok);
        if (id < 0) {
            char names[2048];
            app_design_metric_names(names, sizeof names);
            fprintf(stderr, "cranesim sweep: --metrics: unknown metric '%s' (metrics: %s)\n", tok, names);
            return -1;
        }
        if (!app_design_metric_present(id, s->ncol)) {
            fprintf(stderr, "cranesim sweep: --metrics: this run has no %s (the ode world's channels)\n", tok);
            return -1;
        }
        for (int k = 0; k < s->nmet; ++k)
            if (s->met[k] == id) {
                fprintf(stderr, "cranesim sweep: --metrics: '%s' given twice\n", tok);
                return -1;
            }
        if (s->nmet == SW_MAXMET) return -1;
        s->met[s->nmet++] = id;
    }
    return 0;
}

// ---------------------------------------------------------------------------
// The run
// ---------------------------------------------------------------------------

typedef struct sweep_out {
    app_out out;
    FILE* f;
    int err;
    long written, next_write;
    double* plotv;     ///< ndesign x (npar + nmet) when plotting, NaN for none
} sweep_out;

static void out_line(sweep* s, sweep_out* o, long i, char* line) {
    if (o->f && !o->err) {
        if (fputs(line, o->f) < 0) o->err = errno ? errno : EIO;
    }
    if (o->plotv) {
        // The values back from the row, exactly (17 digits round-trip).
        const size_t w = (size_t)(s->npar + s->nmet);
        double* v = o->plotv + (size_t)i * w;
        const char* p = strchr(line, ',');
        for (size_t k = 0; k < w && p; ++k) {
            char* end;
            v[k] = p[1] == ',' ? NAN : strtod(p + 1, &end);
            p = strchr(p + 1, ',');
        }
    }
    ++o->written;
    free(line);
}

// Write the finished rows in index order as far as they go without a gap.
static void out_flush(sweep* s, sweep_out* o) {
    while (o->next_write < s->ndesign && s->line[o->next_write]) {
        out_line(s, o, o->next_write, s->line[o->next_write]);
        s->line[o->next_write] = NULL;
        ++o->next_write;
    }
}

static void progress(const sweep* s, long done, long failed, double t0) {
    if (!isatty(2)) return;
    const double el = sim_wall_time() - t0;
    const int width = 30;
    const double f = s->ndesign ? (double)done / (double)s->ndesign : 1.0;
    const int n = (int)(f * width + 0.5);
    char eta[32] = "";
    if (done > 0 && done < s->ndesign) snprintf(eta, sizeof eta, ", ETA %.0f s", el * (1.0 / f - 1.0));
    fprintf(stderr, "\r  [%.*s%*s] %ld/%ld designs (%ld failed), %.0f s%s   ", n,
            "##############################", width - n, "", done, s->ndesign, failed, el, eta);
    fflush(stderr);
}

// After a signal or --fail-fast: the finished rows beyond a gap, still in
// index order; and the progress bar cleared.
static void out_rest(sweep* s, sweep_out* o) {
    for (long i = o->next_write; i < s->ndesign; ++i)
        if (s->line[i]) {
            out_line(s, o, i, s->line[i]);
            s->line[i] = NULL;
        }
    if (!s->c.quiet && isatty(2)) fprintf(stderr, "\r%*s\r", 78, "");
}

// ---------------------------------------------------------------------------
// designs of a process-wide backend (ode) on worker processes
// ---------------------------------------------------------------------------

// The ODE library is process-wide, so threads run ode designs one at a time.
// To use every core without MPI, a sweep on such a backend forks worker
// processes instead (after the setup: each inherits the loaded model, the
// scenario and the options, copy-on-write). The parent stays single-threaded
// (fork is then safe, also to replace a worker that died) and keeps the
// bookkeeping of the thread path: it hands one design index at a time to an
// idle worker over a pipe and gets its finished row back, so the results
// file, the progress bar and --fail-fast are those of a local run.
//
// Messages, worker -> parent: long index, uint32 length, the row's bytes.
// Parent -> worker: long index; end of file: no more designs, exit.

typedef struct sw_proc {
    pid_t pid;    ///< 0: no worker in this slot (yet); -1: none could be started, left empty
    int req, res; ///< the parent's ends: requests out, rows in (res non-blocking)
    long busy;    ///< the design it runs, -1 idle
    char* buf;    ///< the bytes of the row being received
    size_t n, cap;
} sw_proc;

static int write_all(int fd, const void* p, size_t n) {
    const char* c = p;
    while (n > 0) {
        const ssize_t k = write(fd, c, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return -1;
        c += k;
        n -= (size_t)k;
    }
    return 0;
}

static int read_all(int fd, void* p, size_t n) {
    char* c = p;
    while (n > 0) {
        const ssize_t k = read(fd, c, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return -1; // end of file: the parent is done (or gone)
        c += k;
        n -= (size_t)k;
    }
    return 0;
}

// The worker's loop: a design index in, its row out, until end of file.
static void __attribute__((noreturn)) proc_worker(const sweep* s, int req, int res) {
    for (long i; read_all(req, &i, sizeof i) == 0;) {
        if (i < 0 || i >= s->ndesign) break;
        bool failed;
        char* line = run_design(s, i, &failed);
        if (!line) break;
        const uint32_t L = (uint32_t)strlen(line);
        const int e = write_all(res, &i, sizeof i) || write_all(res, &L, sizeof L) || write_all(res, line, L);
        free(line);
        if (e) break;
    }
    // _exit: the stdio buffers are the parent's (the results file's among them).
    _exit(0);
}

// Start a worker in slot p. 0, or -1 (errno set).
static int proc_start(sweep* s, sweep_out* o, sw_proc* all, int nproc, sw_proc* p) {
    int rq[2], rs[2];
    if (pipe(rq)) return -1;
    if (pipe(rs)) {
        close(rq[0]);
        close(rq[1]);
        return -1;
    }
    // Nothing buffered may be written twice (by the parent and the child).
    fflush(stdout);
    fflush(stderr);
    if (o->f && fflush(o->f) && !o->err) o->err = errno ? errno : EIO;
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid < 0) {
        const int e = errno;
        close(rq[0]), close(rq[1]), close(rs[0]), close(rs[1]);
        errno = e;
        return -1;
    }
    if (pid == 0) {
        // Its own process group: Ctrl-C at the terminal reaches the parent
        // only, which then stops the workers itself (the finished rows kept).
        setpgid(0, 0);
        // Gone with the parent (a SIGKILL gives it no chance to stop them).
#ifdef __linux__
        prctl(PR_SET_PDEATHSIG, SIGKILL);
#endif
        if (getppid() != parent) _exit(0);
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        signal(SIGPIPE, SIG_DFL);
        // The other workers' pipe ends: held open here, they would hide
        // the end of file from those workers.
        for (int k = 0; k < nproc; ++k)
            if (all[k].pid > 0) close(all[k].req), close(all[k].res);
        close(rq[1]);
        close(rs[0]);
        proc_worker(s, rq[0], rs[1]);
    }
    close(rq[0]);
    close(rs[1]);
    fcntl(rs[0], F_SETFL, fcntl(rs[0], F_GETFL) | O_NONBLOCK);
    fcntl(rq[1], F_SETFD, FD_CLOEXEC);
    fcntl(rs[0], F_SETFD, FD_CLOEXEC);
    *p = (sw_proc){.pid = pid, .req = rq[1], .res = rs[0], .busy = -1};
    return 0;
}

// Close slot p's pipes and reap its worker (after a SIGKILL when kill).
// Returns its wait status.
static int proc_end(sw_proc* p, bool kill_it) {
    int st = 0;
    if (p->pid <= 0) return 0;
    close(p->req);
    if (kill_it) kill(p->pid, SIGKILL);
    while (waitpid(p->pid, &st, 0) < 0 && errno == EINTR) {
    }
    close(p->res);
    free(p->buf);
    *p = (sw_proc){.busy = -1};
    return st;
}

// A finished row from a worker (or a failure row): into the table.
static void proc_row(sweep* s, long i, char* line, long* done) {
    if (i < 0 || i >= s->ndesign || s->line[i]) { // cannot happen: each design goes to one worker once
        free(line);
        return;
    }
    s->line[i] = line;
    ++*done;
    if (line_exit(s, line)) {
        ++s->failed;
        if (s->fail_fast) s->stop = true;
    }
}

// Take what worker p has sent: a whole row makes it idle. Returns 1 when
// it has closed its end (it died), else 0.
static int proc_read(sweep* s, sw_proc* p, long* done) {
    for (;;) {
        if (p->cap - p->n < 4096) {
            const size_t cap = p->cap ? 2 * p->cap : 8192;
            char* b = realloc(p->buf, cap);
            if (!b) abort(); // a row is a few hundred bytes
            p->buf = b;
            p->cap = cap;
        }
        const ssize_t k = read(p->res, p->buf + p->n, p->cap - p->n);
        if (k < 0 && errno == EINTR) continue;
        if (k < 0) break; // EAGAIN: the rest later
        if (k == 0) return 1;
        p->n += (size_t)k;
        const size_t hd = sizeof(long) + sizeof(uint32_t);
        while (p->n >= hd) {
            long i;
            uint32_t L;
            memcpy(&i, p->buf, sizeof i);
            memcpy(&L, p->buf + sizeof i, sizeof L);
            if (p->n < hd + L) break;
            char* line = malloc((size_t)L + 1);
            if (!line) abort();
            memcpy(line, p->buf + hd, L);
            line[L] = 0;
            memmove(p->buf, p->buf + hd + L, p->n - hd - L);
            p->n -= hd + L;
            if (i == p->busy) {
                proc_row(s, i, line, done);
                p->busy = -1;
            } else {
                free(line);
            }
        }
    }
    return 0;
}

// What became of a worker, for its design's error field.
static void proc_death(int st, char* msg, size_t n) {
    if (WIFSIGNALED(st))
        snprintf(msg, n, "the worker process running this design was killed by signal %d (%s)", WTERMSIG(st),
                 strsignal(WTERMSIG(st)));
    else if (WIFEXITED(st))
        snprintf(msg, n, "the worker process running this design exited with status %d", WEXITSTATUS(st));
    else
        snprintf(msg, n, "the worker process running this design ended");
}

// Give design i to worker p, starting it if the slot is empty, once more
// if it died idle. 0, or -1 with p's slot empty (errno set).
static int proc_give(sweep* s, sweep_out* o, sw_proc* all, int nproc, sw_proc* p, long i) {
    for (int attempt = 0; attempt < 2; ++attempt) {
        if (p->pid <= 0 && proc_start(s, o, all, nproc, p)) return -1;
        if (write_all(p->req, &i, sizeof i) == 0) {
            p->busy = i;
            return 0;
        }
        proc_end(p, false);
    }
    errno = EPIPE;
    return -1;
}

static int sweep_procs(sweep* s, int nproc, sweep_out* o) {
    sw_proc* w = calloc((size_t)nproc, sizeof *w);
    struct pollfd* pf = calloc((size_t)nproc, sizeof *pf);
    int* of = calloc((size_t)nproc, sizeof *of);
    if (!w || !pf || !of) {
        free(w), free(pf), free(of);
        fprintf(stderr, "cranesim sweep: out of memory\n");
        return EXIT_RUNTIME;
    }
    for (int k = 0; k < nproc; ++k) w[k].busy = -1;
    // A worker gone (its pipe closed) must show up as a row, not kill us.
    struct sigaction ign, old_pipe;
    memset(&ign, 0, sizeof ign);
    ign.sa_handler = SIG_IGN;
    sigemptyset(&ign.sa_mask);
    sigaction(SIGPIPE, &ign, &old_pipe);
    int rc = 0, start_err = 0;
    const double t0 = sim_wall_time();
    long done = 0;
    for (;;) {
        const bool halt = s->stop || app_signal_caught();
        // Hand out designs to idle workers. A slot whose worker cannot be
        // started (fork refused) stays empty (pid -1); the others go on.
        int npoll = 0;
        bool running = false;
        for (int k = 0; k < nproc; ++k) {
            sw_proc* p = &w[k];
            if (p->pid >= 0 && p->busy < 0 && !halt && s->next < s->ndesign) {
                if (proc_give(s, o, w, nproc, p, s->next) == 0) {
                    ++s->next;
                } else {
                    start_err = errno;
                    p->pid = -1;
                }
            }
            if (p->pid > 0) {
                pf[npoll] = (struct pollfd){.fd = p->res, .events = POLLIN};
                of[npoll++] = k;
            }
            running |= p->busy >= 0;
        }
        if (app_signal_caught()) break;
        if (!running) {
            if (!halt && s->next < s->ndesign) {
                fprintf(stderr, "cranesim sweep: cannot start a worker process: %s\n", strerror(start_err));
                rc = EXIT_RUNTIME;
            }
            break;
        }
        const int np = poll(pf, (nfds_t)npoll, 100); // 100 ms: the progress bar and the signal flag
        if (np < 0 && errno != EINTR) {
            fprintf(stderr, "cranesim sweep: poll: %s\n", strerror(errno));
            rc = EXIT_RUNTIME;
            break;
        }
        for (int j = 0; j < npoll && np > 0; ++j) {
            if (!pf[j].revents) continue;
            sw_proc* p = &w[of[j]];
            if (!proc_read(s, p, &done)) continue;
            const long i = p->busy;
            const int st = proc_end(p, false);
            if (i >= 0 && !app_signal_caught()) {
                // A worker that crashed (or was killed) in a design: that
                // design failed; the slot gets a new worker for the rest.
                char msg[160];
                proc_death(st, msg, sizeof msg);
                proc_row(s, i, format_row(s, i, NULL, EXIT_RUNTIME, msg), &done);
            }
        }
        out_flush(s, o);
        if (!s->c.quiet) progress(s, done, s->failed, t0);
    }
    // Done, or stopped: idle workers exit at the end of file; after a
    // signal (or an error) the running designs are abandoned, their
    // workers killed. Every worker is reaped here.
    const bool abandon = app_signal_caught() != 0 || rc != 0;
    for (int k = 0; k < nproc; ++k) proc_end(&w[k], abandon);
    sigaction(SIGPIPE, &old_pipe, NULL);
    free(w), free(pf), free(of);
    out_flush(s, o);
    if (!s->c.quiet) progress(s, done, s->failed, t0);
    return rc;
}

#ifdef CRANESIM_HAVE_MPI
// Ranks > 0 send TAG_ROW (a design's index and row) and, when their designs
// are done, TAG_DONE; rank 0 sends TAG_STOP (--fail-fast met a failure
// anywhere) and, once every rank is done, TAG_END, which each rank waits
// for, so no message is left unreceived at MPI_Finalize.
enum { TAG_ROW = 1, TAG_DONE = 2, TAG_STOP = 3, TAG_END = 4 };
#endif

static int sweep_run(sweep* s, int threads, int rank, int nrank, const char* out_path, sweep_out* o) {
    s->next = rank;
    s->stride = nrank;
    s->line = calloc((size_t)s->ndesign, sizeof(char*));
    s->fin = malloc((size_t)s->ndesign * sizeof(long));
    if (!s->line || !s->fin) {
        fprintf(stderr, "cranesim sweep: out of memory for %ld designs\n", s->ndesign);
        return EXIT_RUNTIME;
    }
    if (rank == 0) {
        o->f = app_out_open(&o->out, out_path, "w");
        if (!o->f) {
            fprintf(stderr, "cranesim sweep: cannot write %s: %s\n", out_path, strerror(errno));
            return EXIT_USAGE;
        }
        fprintf(o->f, "index");
        for (int k = 0; k < s->npar; ++k) fprintf(o->f, ",%s", s->par[k].path);
        for (int k = 0; k < s->nmet; ++k) fprintf(o->f, ",%s", app_design_metric_name(s->met[k]));
        fprintf(o->f, ",exit,error\n");
    }
    if (s->process_wide && nrank == 1 && threads > 1) {
        const int rc = sweep_procs(s, threads, o);
        out_rest(s, o);
        return rc;
    }
    pthread_t* tid = calloc((size_t)threads, sizeof(pthread_t));
    if (!tid) return EXIT_RUNTIME;
    // Counted before each start: a worker can finish before pthread_create returns.
    int started = 0;
    for (int t = 0; t < threads; ++t) {
        pthread_mutex_lock(&s->mu);
        ++s->active;
        pthread_mutex_unlock(&s->mu);
        if (pthread_create(&tid[t], NULL, worker, s)) {
            pthread_mutex_lock(&s->mu);
            --s->active;
            pthread_mutex_unlock(&s->mu);
            break;
        }
        ++started;
    }
    if (started == 0) {
        fprintf(stderr, "cranesim sweep: cannot start a thread\n");
        free(tid);
        return EXIT_RUNTIME;
    }
    const double t0 = sim_wall_time();
    long done = 0;
    int remote_left = nrank - 1; // ranks that have not said they are done
#ifdef CRANESIM_HAVE_MPI
    bool stop_sent = false;
#endif
    long* batch = malloc((size_t)s->ndesign * sizeof(long));
    if (!batch) abort();
    for (;;) {
        pthread_mutex_lock(&s->mu);
        if (s->nfin == 0 && s->active > 0) {
            struct timespec ts;
            clock_gettime(CLOCK_REALTIME, &ts);
            ts.tv_nsec += 20 * 1000000L; // also the MPI polling period
            if (ts.tv_nsec >= 1000000000L) {
                ts.tv_nsec -= 1000000000L;
                ++ts.tv_sec;
            }
            pthread_cond_timedwait(&s->cv, &s->mu, &ts);
        }
        const long nb = s->nfin;
        memcpy(batch, s->fin, (size_t)nb * sizeof(long));
        s->nfin = 0;
        const bool local_done = s->active == 0;
        pthread_mutex_unlock(&s->mu);
        done += nb;
#ifdef CRANESIM_HAVE_MPI
        if (rank > 0) {
            for (long k = 0; k < nb; ++k) {
                const long i = batch[k];
                pthread_mutex_lock(&s->mu);
                char* line = s->line[i];
                s->line[i] = NULL;
                pthread_mutex_unlock(&s->mu);
                const size_t L = strlen(line) + 1;
                char* msg = malloc(sizeof(long) + L);
                if (!msg) abort();
                memcpy(msg, &i, sizeof(long));
                memcpy(msg + sizeof(long), line, L);
                MPI_Send(msg, (int)(sizeof(long) + L), MPI_CHAR, 0, TAG_ROW, MPI_COMM_WORLD);
                free(msg);
                free(line);
            }
            for (int flag = 1; flag;) {
                MPI_Iprobe(0, TAG_STOP, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
                if (!flag) break;
                MPI_Recv(NULL, 0, MPI_CHAR, 0, TAG_STOP, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                pthread_mutex_lock(&s->mu);
                s->stop = true;
                pthread_mutex_unlock(&s->mu);
            }
            if (local_done) {
                MPI_Send(NULL, 0, MPI_CHAR, 0, TAG_DONE, MPI_COMM_WORLD);
                for (;;) { // a late TAG_STOP, then TAG_END
                    MPI_Status st;
                    MPI_Recv(NULL, 0, MPI_CHAR, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
                    if (st.MPI_TAG == TAG_END) break;
                }
                break;
            }
            continue;
        }
        if (nrank > 1) {
            for (int flag = 1; flag;) {
                MPI_Status st;
                MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
                if (!flag) break;
                int cnt = 0;
                MPI_Get_count(&st, MPI_CHAR, &cnt);
                char* msg = malloc((size_t)cnt + 1);
                if (!msg) abort();
                MPI_Recv(msg, cnt, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                if (st.MPI_TAG == TAG_DONE) {
                    --remote_left;
                } else {
                    long i;
                    memcpy(&i, msg, sizeof(long));
                    const size_t L = (size_t)cnt - sizeof(long);
                    char* line = malloc(L);
                    if (!line) abort();
                    memcpy(line, msg + sizeof(long), L);
                    if (i >= 0 && i < s->ndesign && !s->line[i]) {
                        pthread_mutex_lock(&s->mu);
                        s->line[i] = line;
                        if (line_exit(s, line)) ++s->failed;
                        pthread_mutex_unlock(&s->mu);
                        ++done;
                    } else {
                        free(line);
                    }
                }
                free(msg);
            }
            pthread_mutex_lock(&s->mu);
            const bool stop_now = s->fail_fast && s->failed > 0;
            if (stop_now) s->stop = true;
            pthread_mutex_unlock(&s->mu);
            if (stop_now && !stop_sent) {
                for (int r = 1; r < nrank; ++r) MPI_Send(NULL, 0, MPI_CHAR, r, TAG_STOP, MPI_COMM_WORLD);
                stop_sent = true;
            }
            if (local_done && remote_left <= 0)
                for (int r = 1; r < nrank; ++r) MPI_Send(NULL, 0, MPI_CHAR, r, TAG_END, MPI_COMM_WORLD);
        }
#endif
        pthread_mutex_lock(&s->mu);
        out_flush(s, o);
        const long failed = s->failed;
        pthread_mutex_unlock(&s->mu);
        if (!s->c.quiet) progress(s, done, failed, t0);
        if (local_done && remote_left <= 0) break;
    }
    free(batch);
    for (int t = 0; t < started; ++t) pthread_join(tid[t], NULL);
    free(tid);
    if (rank > 0) return 0;
    out_rest(s, o);
    return 0;
}

// ---------------------------------------------------------------------------
// Plots
// ---------------------------------------------------------------------------

static int sweep_plots(const sweep* s, const sweep_out* o, const char* plot) {
    const size_t L = strlen(plot);
    const bool one = L > 4 && !strcmp(plot + L - 4, ".png");
    int dirlen = (int)L; // the folder without its trailing slashes
    while (dirlen > 1 && plot[dirlen - 1] == '/') --dirlen;
    const size_t w = (size_t)(s->npar + s->nmet);
    double* x = malloc((size_t)s->ndesign * sizeof(double));
    double* y = malloc((size_t)s->ndesign * sizeof(double));
    if (!x || !y) {
        free(x);
        free(y);
        return -1;
    }
    int rc = 0;
    int nplot = 0;
    char err[512], png[1400], title[400];
    for (int mk = 0; mk < s->nmet && !rc && !(one && nplot); ++mk) {
        const char* mn = app_design_metric_name(s->met[mk]);
        // The axis and the colours in the run summary's units (MPa, deg, kJ),
        // as a user reads the runs; the CSV stays SI.
        char ylab[96];
        app_metric_label(s->met[mk], ylab, sizeof ylab);
        const double ysc = app_metric_disp_scale(s->met[mk]);
        if (s->npar == 2 && s->lhs == 0) {
            // Heat map over the grid (row-major: the second parameter fastest).
            const long nx = s->par[0].n, ny = s->par[1].n;
            double* z = malloc((size_t)nx * (size_t)ny * sizeof(double));
            if (!z) break;
            for (long i = 0; i < s->ndesign; ++i) z[i] = o->plotv[(size_t)i * w + 2 + (size_t)mk] * ysc;
            if (one) snprintf(png, sizeof png, "%s", plot);
            else snprintf(png, sizeof png, "%.*s/%s_heat.png", dirlen, plot, mn);
            snprintf(title, sizeof title, "%s: %s", s->sc.name, ylab);
            if (app_plot_heat(png, title, s->par[0].path, s->par[1].path, z, nx, ny, s->par[0].lo, s->par[0].hi,
                              s->par[1].lo, s->par[1].hi, err, sizeof err)) {
                fprintf(stderr, "cranesim sweep: plot: %s\n", err);
                rc = -1;
            } else {
                ++nplot;
                if (!s->c.quiet) printf("  plot -> %s\n", png);
            }
            free(z);
            if (one) break;
        }
        for (int pk = 0; pk < s->npar && !rc && !(one && nplot); ++pk) {
            long n = 0;
            for (long i = 0; i < s->ndesign; ++i) {
                const double* v = o->plotv + (size_t)i * w;
                if (isfinite(v[pk]) && isfinite(v[s->npar + mk])) {
                    x[n] = v[pk];
                    y[n] = v[s->npar + mk] * ysc;
                    ++n;
                }
            }
            if (one) snprintf(png, sizeof png, "%s", plot);
            else snprintf(png, sizeof png, "%.*s/%s_vs_%s.png", dirlen, plot, mn, s->par[pk].path);
            snprintf(title, sizeof title, "%s: %s against %s", s->sc.name, mn, s->par[pk].path);
            if (app_plot_sweep(png, title, s->par[pk].path, ylab, x, y, n, err, sizeof err)) {
                fprintf(stderr, "cranesim sweep: plot: %s\n", err);
                rc = -1;
            } else {
                ++nplot;
                if (!s->c.quiet) printf("  plot -> %s\n", png);
            }
        }
    }
    free(x);
    free(y);
    return rc;
}

// ---------------------------------------------------------------------------
// The command
// ---------------------------------------------------------------------------

static int sweep_main(int argc, char** argv, int rank, int nrank) {
    sweep s;
    memset(&s, 0, sizeof s);
    s.c.sim = sim_default_opts();
    app_design_opts d = {.out = "sweep.csv"};
    const char* metrics = NULL;
    long lhs = 0, threads = 0;
    uint64_t seed = 1;
    for (int i = 0; i < argc; ++i) {
        const char* a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            if (rank == 0) sweep_help(stdout);
            return 0;
        }
        int rc = app_parse_common(&s.c, argc, argv, &i);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        if (!strcmp(a, "--fail-fast")) {
            s.fail_fast = true;
            continue;
        }
        rc = app_parse_design_opt("sweep", argc, argv, &i, &d);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        const bool known = !strcmp(a, "--lhs") || !strcmp(a, "--seed") || !strcmp(a, "--metrics") ||
                           !strcmp(a, "--threads");
        if (!known) {
            fprintf(stderr, "cranesim sweep: unknown option '%s' (see cranesim sweep --help)\n", a);
            return EXIT_USAGE;
        }
        const char* v = app_value(argc, argv, &i);
        if (!v) return EXIT_USAGE;
        if (!strcmp(a, "--metrics")) {
            metrics = v;
        } else {
            char* end;
            errno = 0;
            const long long n = strtoll(v, &end, 10);
            const long long hi = !strcmp(a, "--seed") ? LLONG_MAX : !strcmp(a, "--threads") ? 1024 : SW_MAXDESIGN;
            const long long lo = !strcmp(a, "--seed") ? 0 : 1;
            if (!*v || *end || errno || n < lo || n > hi) {
                fprintf(stderr, "cranesim sweep: %s must be a whole number in [%lld, %lld], got '%s'\n", a, lo, hi,
                        v);
                return EXIT_USAGE;
            }
            if (!strcmp(a, "--seed")) seed = (uint64_t)n;
            else if (!strcmp(a, "--lhs")) lhs = (long)n;
            else threads = (long)n;
        }
    }
    const int nparam = d.nparam;
    const char* const* params = d.param;
    const char* out = d.out;
    const char* plot = d.plot;
    if (nparam == 0) {
        fprintf(stderr, "cranesim sweep: give at least one --param PATH=LO:HI:N (see cranesim sweep --help)\n");
        return EXIT_USAGE;
    }
    s.npar = nparam;
    s.lhs = lhs;
    double nd = 1;
    for (int k = 0; k < nparam; ++k) {
        if (app_parse_range("sweep", params[k], lhs == 0, &s.par[k])) return EXIT_USAGE;
        for (int j = 0; j < k; ++j)
            if (!strcmp(s.par[j].path, s.par[k].path)) {
                fprintf(stderr, "cranesim sweep: --param %s given twice\n", s.par[k].path);
                return EXIT_USAGE;
            }
        nd *= (double)s.par[k].n;
    }
    if (lhs > 0) nd = (double)lhs;
    if (nd > SW_MAXDESIGN) {
        fprintf(stderr, "cranesim sweep: %.0f designs: at most %d\n", nd, SW_MAXDESIGN);
        return EXIT_USAGE;
    }
    s.ndesign = (long)nd;
    if (app_check_output("sweep", "--out", out, NULL)) return EXIT_USAGE;
    if (plot) {
        const size_t L = strlen(plot);
        if (L > 4 && !strcmp(plot + L - 4, ".png")) {
            if (app_check_output("sweep", "--plot", plot, ".png") ||
                app_check_distinct("sweep", (const char* const[]){"--out", "--plot"}, (const char* const[]){out, plot}, 2))
                return EXIT_USAGE;
        }
    }
    int rc = app_check_sim("sweep", &s.c.sim, s.c.given);
    if (rc) return rc;
    // The base design: the model with the --set changes; each design copies it.
    rc = app_load(&s.c, &s.base, &s.sc);
    if (rc) return rc;
    bool switched;
    rc = app_scenario_world("sweep", &s.c.sim, s.c.given, s.base, &s.sc, true, &switched);
    if (!rc && switched) rc = app_check_sim("sweep", &s.c.sim, s.c.given);
    if (rc) {
        model_free(s.base);
        return rc;
    }
    s.process_wide = app_backend(&s.c.sim)->process_wide;
    s.ncol = sim_ncol(&s.c.sim);
    // Every path must name a number in the model: a typo is bad input, not
    // a sweep of refused designs. (Its values are checked per design.)
    for (int k = 0; k < nparam && !rc; ++k) {
        cJSON* doc = cJSON_Duplicate(s.base->json, 1);
        char asg[320], err[1024], num[32];
        snprintf(asg, sizeof asg, "%s=%s", s.par[k].path, app_fmt_double(num, sizeof num, s.par[k].lo));
        if (!doc || json_set_path(doc, asg, err, sizeof err)) {
            fprintf(stderr, "cranesim sweep: --param %s: %s\n", s.par[k].path, doc ? err : "out of memory");
            rc = EXIT_USAGE;
        }
        cJSON_Delete(doc);
    }
    // A chain model's metrics by actuator and function, by name.
    if (!rc && app_design_metrics_setup(s.base)) {
        fprintf(stderr, "cranesim sweep: out of memory\n");
        rc = EXIT_RUNTIME;
    }
    if (!rc && metrics) rc = parse_metrics(&s, metrics) ? EXIT_USAGE : 0;
    else if (!rc) {
        for (int id = 0; id < MET_COUNT; ++id)
            // The energy metrics only when asked: the accounting costs a
            // circuit evaluation per step, and the default table stays as it was.
            // collision_count too, so the default columns stay those they were.
            if (metrics_present((metric_id)id, s.ncol) && id != MET_ENERGY_IN && id != MET_ENERGY_LOSS &&
                id != MET_COLLISIONS)
                s.met[s.nmet++] = id;
        // Then a chain's by actuator and function: the table shows each one
        // the model has (a two-link model has none: its table as it was).
        for (int k = 0; k < app_design_metric_chain_count() && s.nmet < SW_MAXMET; ++k) s.met[s.nmet++] = MET_COUNT + k;
    }
    for (int k = 0; k < s.nmet; ++k)
        if (s.met[k] == MET_ENERGY_IN || s.met[k] == MET_ENERGY_LOSS) s.energy = true;
    if (!rc && plot && !(strlen(plot) > 4 && !strcmp(plot + strlen(plot) - 4, ".png")) && rank == 0)
        rc = app_make_dir("sweep", "--plot", plot) ? EXIT_USAGE : 0;
    if (!rc && lhs > 0 && make_lhs(&s, seed)) {
        fprintf(stderr, "cranesim sweep: out of memory for %ld designs\n", s.ndesign);
        rc = EXIT_RUNTIME;
    }
    if (rc) {
        model_free(s.base);
        free(s.lhs_v);
        return rc;
    }
    app_note_unused("sweep", s.c.given, &s.c.sim, 1);
    {
        // A swept load mass the scenario's or --load overrides: the note run gives for --set.
        app_common cn = s.c;
        char asg[SW_MAXPAR][320];
        for (int k = 0; k < nparam && cn.nset < APP_MAX_SET; ++k) {
            char num[32];
            snprintf(asg[k], sizeof asg[k], "%s=%s", s.par[k].path, app_fmt_double(num, sizeof num, s.par[k].lo));
            cn.sets[cn.nset++] = asg[k];
        }
        if (rank == 0) app_note_load("sweep", &cn, &s.c.sim, &s.sc);
    }
    app_settle_unused(&s.c.sim);
    if (threads == 0) {
        // Every core; under MPI one thread per rank (mpirun places one rank per core).
        const long cores = sysconf(_SC_NPROCESSORS_ONLN);
        threads = nrank > 1 ? 1 : cores > 0 ? cores : 1;
    }
    const long mine = (s.ndesign - rank + nrank - 1) / nrank; // designs of this rank
    if (threads > mine) threads = mine > 0 ? mine : 1;
    pthread_mutex_init(&s.mu, NULL);
    pthread_cond_init(&s.cv, NULL);
    void* note_user;
    hyd_note_fn old_note = hyd_get_note_handler(&note_user);
    hyd_set_note_handler(quiet_note, NULL);
    sweep_out o = {0};
    if (plot && rank == 0) {
        const size_t w = (size_t)(s.npar + s.nmet);
        o.plotv = malloc((size_t)s.ndesign * w * sizeof(double));
        if (o.plotv)
            for (size_t k = 0; k < (size_t)s.ndesign * w; ++k) o.plotv[k] = NAN;
    }
    app_signals sig;
    app_signals_catch(&sig);
    const double t0 = sim_wall_time();
    rc = sweep_run(&s, (int)threads, rank, nrank, out, &o);
    const double wall = sim_wall_time() - t0;
    int code = rc;
    if (rank == 0 && o.f) {
        const int e = app_out_close(&o.out, o.err, true);
        if (e) {
            fprintf(stderr, "cranesim sweep: cannot write %s: %s\n", out, strerror(e));
            if (!code) code = EXIT_RUNTIME;
        }
    }
    app_signals_restore(&sig);
    hyd_set_note_handler(old_note, note_user);
    if (rank == 0 && !code) {
        const int sg = app_signal_caught();
        if (sg) {
            fprintf(stderr, "cranesim sweep: interrupted (%s); %ld of %ld designs kept in %s\n",
                    app_signal_name(sg), o.written, s.ndesign, out);
            code = 128 + sg;
        } else {
            const long nfail = s.failed; // with MPI: every rank's, from the rows
            if (!s.c.quiet) {
                char shape[128] = "";
                if (lhs > 0) snprintf(shape, sizeof shape, "Latin hypercube, seed %llu", (unsigned long long)seed);
                else
                    for (int k = 0; k < s.npar; ++k) {
                        const size_t n = strlen(shape);
                        snprintf(shape + n, sizeof shape - n, "%s%ld", k ? " x " : "grid ", s.par[k].n);
                    }
                // ode designs on more than one thread run on worker processes (sweep_procs).
                const char* unit = s.process_wide && nrank == 1 && threads > 1 ? "worker process" : "thread";
                printf("cranesim sweep: %s, %ld designs (%s) on %ld %s%s%s in %.2f s -> %s\n", s.sc.name, s.ndesign,
                       shape, threads, unit, threads == 1 ? "" : strcmp(unit, "thread") ? "es" : "s",
                       nrank > 1 ? " per rank" : "", wall, out);
                if (nrank > 1) printf("  %d MPI ranks\n", nrank);
                if (nfail)
                    printf("  %ld design%s failed (exit and error in %s rows)\n", nfail, nfail == 1 ? "" : "s",
                           nfail == 1 ? "its" : "their");
            }
            if (s.fail_fast && (nfail || o.written < s.ndesign)) {
                fprintf(stderr, "cranesim sweep: --fail-fast: stopped at a failing design; %ld of %ld rows in %s\n",
                        o.written, s.ndesign, out);
                code = EXIT_RUNTIME;
            }
            if (plot && o.plotv && sweep_plots(&s, &o, plot) && !code) code = EXIT_RUNTIME;
        }
    }
    for (long i = 0; s.line && i < s.ndesign; ++i) free(s.line[i]);
    free(s.line);
    free(s.fin);
    free(o.plotv);
    free(s.lhs_v);
    pthread_mutex_destroy(&s.mu);
    pthread_cond_destroy(&s.cv);
    model_free(s.base);
    return code;
}

int cmd_sweep(int argc, char** argv) {
    int rank = 0, nrank = 1;
#ifdef CRANESIM_HAVE_MPI
    // MPI only when a launcher started this process (mpirun, srun): a plain
    // `cranesim sweep` stays a local run.
    const bool launched = getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
    if (launched) {
        int prov;
        MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &prov);
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
        MPI_Comm_size(MPI_COMM_WORLD, &nrank);
    }
#endif
    // Every rank checks the input the same way; only rank 0 says what is wrong.
    if (rank > 0 && (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr))) return EXIT_RUNTIME;
    int rc = sweep_main(argc, argv, rank, nrank);
#ifdef CRANESIM_HAVE_MPI
    if (launched) {
        // Ranks agree on the outcome: the worst exit code.
        int worst = rc;
        MPI_Allreduce(&rc, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
        MPI_Finalize();
        rc = rank == 0 ? rc : 0;
        (void)worst;
    }
#endif
    return rc;
}
