// plot.c: PNG plots of runs with PLplot (cairo driver): strokes, chamber
// pressures, valve openings and the tip path, as the paper's WinSimu showed.
//
// PLplot writes its output file itself and ignores write errors (a plot to a
// full disk "succeeds"), so the PNG is rendered into a memory stream
// (fopencookie, a GNU extension, hence _GNU_SOURCE) and written to the file
// here, where every fwrite, fflush and fclose is checked.
#define _GNU_SOURCE
#include "app.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// Write n bytes to path, replacing it only once all are written (app_out);
// on failure "cannot write FILE: reason" in err, and the previous file is
// left as it was (a partly written one would pass for a plot).
static int write_file(const char* path, const void* data, size_t n, char* err, size_t errsz) {
    app_out out;
    FILE* f = app_out_open(&out, path, "wb");
    if (!f) {
        snprintf(err, errsz, "cannot write %s: %s", path, strerror(errno));
        return -1;
    }
    errno = 0;
    const int e = app_out_close(&out, fwrite(data, 1, n, f) != n ? (errno ? errno : EIO) : 0, true);
    if (!e) return 0;
    snprintf(err, errsz, "cannot write %s: %s", path, strerror(e));
    return -1;
}

// ---------------------------------------------------------- axis ticks --
//
// PLplot's own labels print a fixed number of significant digits, so an axis
// whose range is small against its values repeats them ("3.906 3.906 3.906"
// for a stroke between 3.9060 and 3.9064 m). The axes here take their tick
// step from app_tick_step and print each label with as many decimals as the
// step needs (app_tick_label), so neighbouring labels always differ.

int app_plot_run_channels(int panel, bool slew, int cols[APP_PLOT_MAXSERIES], const char* names[APP_PLOT_MAXSERIES]) {
    // Lift and jib, then the slew where the world drives one (the sandbox:
    // its rack's stroke, chambers and valve are a function like the others).
    static const int c[3][APP_PLOT_MAXSERIES] = {{COL_X1, COL_X2, COL_X3},
                                                 {COL_P1A, COL_P1B, COL_P2A, COL_P2B, COL_P3A, COL_P3B},
                                                 {COL_U1, COL_U2, COL_U1_CMD, COL_U2_CMD, COL_U3, COL_U3_CMD}};
    static const char* const nm[3][APP_PLOT_MAXSERIES] = {
        {"x1 lift", "x2 jib", "x3 slew"},
        {"p1A", "p1B", "p2A", "p2B", "p3A", "p3B"},
        {"u1 spool", "u2 spool", "u1 cmd", "u2 cmd", "u3 spool", "u3 cmd"}};
    static const int n[3][2] = {{2, 3}, {4, 6}, {4, 6}};
    if (panel < 0 || panel > 2) return 0;
    const int k = n[panel][slew ? 1 : 0];
    for (int i = 0; i < k; ++i) cols[i] = c[panel][i], names[i] = nm[panel][i];
    return k;
}

int app_plot_chain_channels(const crane_column* col, int ncol, int off, bool slew, int panel, int* cols,
                            const char** names, int max) {
    // Each panel's column prefix (and, for the joint angles, the unit: a
    // sliding joint's q_ is the extension's stroke, already in panel 0).
    static const char* const pre[APP_PLOT_CHAIN_PANELS] = {"x_", "pA_", "pB_", "u_", "ucmd_", "q_"};
    if (panel < 0 || panel >= APP_PLOT_CHAIN_PANELS) return 0;
    const size_t L = strlen(pre[panel]);
    int n = 0;
    for (int k = 0; k < ncol && n < max; ++k) {
        if (strncmp(col[k].name, pre[panel], L)) continue;
        if (panel == 5 && strcmp(col[k].unit, "rad")) continue;
        if (!strcmp(col[k].name + L, "slew")) slew = false; // the run's chain has the rack's own columns
        cols[n] = off + k;
        names[n++] = col[k].name + L;
    }
    // The world's slew drive, in the base columns (the ode sandbox: x3 ..
    // u3_cmd, and the slew angle), after the chain's.
    static const int base[APP_PLOT_CHAIN_PANELS] = {COL_X3, COL_P3A, COL_P3B, COL_U3, COL_U3_CMD, COL_SLEW};
    if (slew && n < max) {
        cols[n] = base[panel];
        names[n++] = "slew";
    }
    return n;
}

double app_tick_step(double lo, double hi, int max_ticks) {
    const double span = fabs(hi - lo);
    if (!(span > 0) || !isfinite(span) || max_ticks < 1) return 1.0;
    const double raw = span / max_ticks;
    double p10 = pow(10.0, floor(log10(raw)));
    static const double lead[4] = {1.0, 2.0, 5.0, 10.0};
    for (int k = 0; k < 4; ++k)
        if (lead[k] * p10 >= raw * (1.0 - 1e-12)) return lead[k] * p10;
    return 10.0 * p10;
}

int app_tick_decimals(double step) {
    if (!(step > 0) || !isfinite(step)) return 0;
    // Steps are 1, 2 or 5 times 10^k: -k decimals, none for k >= 0. The
    // 1e-9 absorbs the rounding of log10 at exact powers of ten.
    const int d = (int)ceil(-log10(step) - 1e-9);
    return d < 0 ? 0 : (d > 15 ? 15 : d);
}

void app_tick_label(double v, double step, char* buf, size_t n) {
    const int d = app_tick_decimals(step);
    // A tick at zero computed as -1e-17 would print "-0.000".
    if (fabs(v) < 0.5 * step * 1e-6) v = 0.0;
    snprintf(buf, n, "%.*f", d, v);
    if (!strncmp(buf, "-0", 2) && strspn(buf + 1, "0.") == strlen(buf + 1)) memmove(buf, buf + 1, strlen(buf));
}

// ------------------------------------------------------ point labels --
//
// Labels of many points (the work-precision plot: ~30 steps and tolerances,
// a dozen of them within a decade) were set at fixed offsets per method and
// ran into each other. app_place_labels tries the positions around each
// point, nearest first, and takes the first that is free.

static void label_box(const app_label* l, double b[4]) {
    b[0] = l->lx - l->just * l->w;
    b[2] = b[0] + l->w;
    b[1] = l->ly - 0.5 * l->h;
    b[3] = l->ly + 0.5 * l->h;
}

double app_label_overlap(const app_label* a, const app_label* b) {
    double p[4], q[4];
    label_box(a, p);
    label_box(b, q);
    const double w = fmin(p[2], q[2]) - fmax(p[0], q[0]), h = fmin(p[3], q[3]) - fmax(p[1], q[1]);
    return w > 0 && h > 0 ? w * h : 0.0;
}

// How badly label k sits where it is: overlap with the labels placed before
// it, markers under it, and its part outside the area (weighted: a label cut
// by the frame is worse than one touching another).
static double label_cost(const app_label* l, int k, const double area[4], const double* px, const double* py, int np,
                         double r) {
    double b[4], c = 0;
    label_box(&l[k], b);
    for (int j = 0; j < k; ++j) c += app_label_overlap(&l[k], &l[j]);
    for (int j = 0; j < np; ++j) {
        const double w = fmin(b[2], px[j] + r) - fmax(b[0], px[j] - r);
        const double h = fmin(b[3], py[j] + r) - fmax(b[1], py[j] - r);
        if (w > 0 && h > 0) c += w * h;
    }
    if (b[0] < area[0] || b[1] < area[1] || b[2] > area[2] || b[3] > area[3]) {
        const double in_w = fmax(0, fmin(b[2], area[2]) - fmax(b[0], area[0]));
        const double in_h = fmax(0, fmin(b[3], area[3]) - fmax(b[1], area[1]));
        c += 10 * fmax(l[k].w * l[k].h - in_w * in_h, 1e-9 * l[k].w * l[k].h);
    }
    return c;
}

int app_place_labels(app_label* l, int nfixed, int n, const double area[4], const double* px, const double* py,
                     int np, double r) {
    // Directions around the point: right, left, above, below, then the
    // diagonals; (dx, dy) per unit of distance, and the justification.
    static const double dir[8][3] = {{1, 0, 0},    {-1, 0, 1},    {0, 1, 0.5},  {0, -1, 0.5},
                                     {0.7, 0.7, 0}, {0.7, -0.7, 0}, {-0.7, 0.7, 1}, {-0.7, -0.7, 1}};
    // Distances in label heights beyond the marker: beside it, then farther
    // out (with a leader line from 2 on).
    static const double dist[] = {0.35, 1.0, 2.0, 3.0, 4.5, 6.0};
    int failed = 0;
    for (int k = nfixed; k < n; ++k) {
        double best = INFINITY, bx = 0, by = 0, bj = 0;
        int bd = 0;
        for (int d = 0; d < (int)(sizeof dist / sizeof dist[0]) && best > 0; ++d)
            for (int i = 0; i < 8 && best > 0; ++i) {
                const double reach = r + dist[d] * l[k].h;
                l[k].lx = l[k].x + dir[i][0] * reach;
                // Above and below: the text's centre a half height farther.
                l[k].ly = l[k].y + dir[i][1] * (reach + (dir[i][0] == 0 ? 0.5 * l[k].h : 0));
                l[k].just = dir[i][2];
                const double c = label_cost(l, k, area, px, py, np, r);
                if (c < best) best = c, bx = l[k].lx, by = l[k].ly, bj = l[k].just, bd = d;
            }
        l[k].lx = bx, l[k].ly = by, l[k].just = bj;
        l[k].leader = bd >= 2;
        failed += best > 0;
    }
    return failed;
}

#ifdef CRANESIM_HAVE_PLPLOT
#include <plplot.h>

// Major ticks per axis at most: a 700 px wide panel holds about seven labels.
enum { MAX_TICKS = 6 };

// plslabelfunc callback: data holds the x and y tick steps.
static void tick_label_cb(PLINT axis, PLFLT value, char* label, PLINT length, PLPointer data) {
    const double* step = data;
    app_tick_label(value, axis == PL_Y_AXIS ? step[1] : step[0], label, (size_t)length);
}

// The memory stream PLplot writes the PNG into.
typedef struct png_mem {
    char* buf;
    size_t n, cap;
    bool oom, closed;
} png_mem;

static ssize_t mem_write(void* cookie, const char* b, size_t n) {
    png_mem* m = cookie;
    if (m->n + n > m->cap) {
        size_t cap = m->cap ? m->cap : 1 << 16;
        while (cap < m->n + n) cap *= 2;
        char* nb = realloc(m->buf, cap);
        if (!nb) {
            m->oom = true;
            return -1;
        }
        m->buf = nb;
        m->cap = cap;
    }
    memcpy(m->buf + m->n, b, n);
    m->n += n;
    return (ssize_t)n;
}

static int mem_close(void* cookie) {
    ((png_mem*)cookie)->closed = true;
    return 0;
}

int app_png_render(const char* png, const char* geometry, void (*draw)(void* user), void* user, char* err,
                   size_t errsz) {
    png_mem m = {0};
    cookie_io_functions_t io = {.read = NULL, .write = mem_write, .seek = NULL, .close = mem_close};
    FILE* f = fopencookie(&m, "w", io);
    if (!f) {
        snprintf(err, errsz, "cannot write %s: %s", png, strerror(errno));
        return -1;
    }
    plsdev("pngcairo");
    plsfile(f);
    plsetopt("geometry", geometry);
    plscolbg(255, 255, 255);
    plscol0(15, 0, 0, 0);
    draw(user);
    plend(); // writes the page to f; PLplot 5.15 also closes f
    if (!m.closed) fclose(f);
    int rc = 0;
    if (m.oom) {
        snprintf(err, errsz, "cannot write %s: out of memory", png);
        rc = -1;
    } else if (m.n == 0) {
        snprintf(err, errsz, "cannot write %s: PLplot produced no image (is plplot-driver-cairo installed?)", png);
        rc = -1;
    } else {
        rc = write_file(png, m.buf, m.n, err, errsz);
    }
    free(m.buf);
    return rc;
}

// The rows a panel draws from: a trace (SIM_NCOL columns a row) or a chain
// run's wider rows (stride columns: the base, then the chain's).
typedef struct psrc {
    const double* v;
    int nrow, stride;
} psrc;

static void range_of(const psrc* tr, int col, double scale, double* lo, double* hi) {
    for (int i = 0; i < tr->nrow; ++i) {
        double v = tr->v[(size_t)i * (size_t)tr->stride + (size_t)col] * scale;
        if (v < *lo) *lo = v;
        if (v > *hi) *hi = v;
    }
}

static void draw_series(const psrc* tr, int xcol, double xs, int ycol, double ys, PLFLT* xb, PLFLT* yb) {
    for (int i = 0; i < tr->nrow; ++i) {
        xb[i] = tr->v[(size_t)i * (size_t)tr->stride + (size_t)xcol] * xs;
        yb[i] = tr->v[(size_t)i * (size_t)tr->stride + (size_t)ycol] * ys;
    }
    plline(tr->nrow, xb, yb);
}

// ------------------------------------------------------ page of panels --
//
// The trace plots are a 2 x 2 grid of panels under a title that spans the
// page. PLplot's subpages (plstar(2, 2)) gave the title only the first
// panel's width, centred there: a replay's title ran off both sides of it.
// The panels are placed here instead, each in its cell of the page below
// the title band, in the order they are drawn (as pladv did).

#define PAGE_TITLE_BAND 0.055 // top band of the page for the title [page height]

static int g_cell; // the next panel's cell, row-major
static int g_rows = 2; // rows of panels on the page (2, or 3 for a chain run's page)
static bool g_legend_right; // the panels leave room on their right for a legend (chain runs)

// Start a page of 2 x 2 panels under title: as wide as the page allows,
// smaller type for a title that would not fit at the normal size.
static void page_begin(const char* title, int rows, bool legend_right) {
    plstar(1, 1);
    pladv(0);
    g_cell = 0;
    g_rows = rows;
    g_legend_right = legend_right;
    plvpor(0.0, 1.0, 0.0, 1.0);
    plwind(0.0, 1.0, 0.0, 1.0);
    // The title at 0.8 of PLplot's default size holds about 100 characters
    // across the page with a margin (measured: 182 characters at 0.8 x 105 /
    // 182 filled the 1400 px); a longer one is set smaller to fit.
    const double fit = 95.0, n = (double)strlen(title);
    plschr(0, n > fit ? fmax(0.4, 0.8 * fit / n) : 0.8);
    plcol0(15);
    plmtex("t", -1.5, 0.5, 0.5, title);
    // The panels' type: what plstar(2, 2) scaled 0.9 to.
    plschr(0, 0.6);
}

// The viewport of the next panel: its cell less room for the tick labels and
// axis titles (left, bottom) and the panel's own title (top).
static void page_panel_viewport(void) {
    const int col = g_cell % 2, row = g_cell / 2;
    ++g_cell;
    const double h = (1.0 - PAGE_TITLE_BAND) / g_rows;
    const double x0 = 0.5 * col, y1 = 1.0 - PAGE_TITLE_BAND - h * row;
    // A chain run's legend (one name per actuator or function, up to a
    // dozen) goes right of the panel: 0.08 of the page (112 px) holds a
    // name of about 14 characters.
    if (g_legend_right) plvpor(x0 + 0.07, x0 + 0.395, y1 - h + 0.06, y1 - 0.035);
    else plvpor(x0 + 0.085, x0 + 0.48, y1 - h + 0.085, y1 - 0.05);
}

// The colours of a panel's series: distinct on white (PLplot's cmap0
// without its yellow, wheat and aquamarine); beyond a dozen they repeat with
// a dotted line.
static const int k_colours[] = {1, 3, 9, 13, 8, 10, 11, 7, 14, 12, 5, 2};
#define NCOLOURS ((int)(sizeof k_colours / sizeof k_colours[0]))

// One panel: columns cols[0..nc) of up to two traces, the second dashed;
// dashed: columns drawn dashed in the same colours as cols (a chain run's
// commands beside its spools), or NULL; slot: each series' colour slot (a
// chain run's: the actuator's, so that a name keeps its colour from panel to
// panel), or NULL for the series' own index.
static void panel_ex(const psrc* a, const psrc* b, int xcol, double xs, const int* cols, const int* dashed, int nc,
                     double ys, const char* xlabel, const char* ylabel, const char* title, const char* const* names,
                     const int* slot, PLFLT* xb, PLFLT* yb) {
    double xlo = 1e300, xhi = -1e300, ylo = 1e300, yhi = -1e300;
    const psrc* trs[2] = {a, b};
    for (int t = 0; t < 2; ++t) {
        if (!trs[t]) continue;
        range_of(trs[t], xcol, xs, &xlo, &xhi);
        for (int k = 0; k < nc; ++k) range_of(trs[t], cols[k], ys, &ylo, &yhi);
        for (int k = 0; k < nc && dashed; ++k) range_of(trs[t], dashed[k], ys, &ylo, &yhi);
    }
    if (!(xhi > xlo)) xhi = xlo + 1;
    double pad = 0.05 * (yhi - ylo);
    if (!(pad > 0)) pad = fabs(yhi) * 0.05 + 1e-3;
    if (xcol != COL_T) { // tip path: equal-ish margins on both axes
        double xp = 0.05 * (xhi - xlo);
        xlo -= xp;
        xhi += xp;
    }
    plcol0(15);
    // plenv(..., 0, 2) with our own tick steps and labels: box, ticks,
    // grid and zero axes, custom labels ("o").
    static double step[2];
    step[0] = app_tick_step(xlo, xhi, MAX_TICKS);
    step[1] = app_tick_step(ylo - pad, yhi + pad, MAX_TICKS);
    page_panel_viewport();
    plwind(xlo, xhi, ylo - pad, yhi + pad);
    plslabelfunc(tick_label_cb, step);
    plbox("abcgnsto", step[0], 0, "abcgnstvo", step[1], 0);
    plslabelfunc(NULL, NULL);
    pllab(xlabel, "", title);
    // The y title clear of the widest tick label: pllab's offset, 5
    // character heights, is too little for labels of 7 or more characters
    // ("-0.4570"; a digit is about 0.75 of the character height wide here).
    int wide = 0;
    for (double v = ceil((ylo - pad) / step[1]) * step[1]; v <= yhi + pad; v += step[1]) {
        char lb[64];
        app_tick_label(v, step[1], lb, sizeof lb);
        if ((int)strlen(lb) > wide) wide = (int)strlen(lb);
    }
    plmtex("l", fmax(5.0, 1.5 + 0.75 * wide), 0.5, 0.5, ylabel);
    if (g_legend_right) {
        // A chain run: a colour per actuator or function (the same in every
        // panel, in the model's order), its spool solid and its command
        // dashed, or (compare) run A solid and run B dashed; the names in a
        // column right of the panel.
        for (int k = 0; k < nc; ++k) {
            const int sl = slot ? slot[k] : k;
            plcol0(k_colours[sl % NCOLOURS]);
            pllsty(sl < NCOLOURS ? 1 : 3);
            draw_series(a, xcol, xs, cols[k], ys, xb, yb);
            if (b) {
                pllsty(2);
                draw_series(b, xcol, xs, cols[k], ys, xb, yb);
            } else if (dashed) {
                pllsty(2);
                draw_series(a, xcol, xs, dashed[k], ys, xb, yb);
            }
        }
        pllsty(1);
        const double step = 1.0 / (nc > 12 ? nc + 1 : 13); // of the panel's height
        for (int k = 0; k < nc && names; ++k) {
            plcol0(k_colours[(slot ? slot[k] : k) % NCOLOURS]);
            plmtex("rv", 0.8, 1.0 - step * (k + 0.5), 0.0, names[k]);
        }
        plcol0(15);
        return;
    }
    static const int colours[] = {1, 3, 9, 8, 12, 13};
    for (int t = 0; t < 2; ++t) {
        if (!trs[t]) continue;
        pllsty(t == 0 ? 1 : 2);
        for (int k = 0; k < nc; ++k) {
            plcol0(colours[k % 6]);
            draw_series(trs[t], xcol, xs, cols[k], ys, xb, yb);
        }
    }
    pllsty(1);
    // A small legend: coloured names in the panel's top-left corner.
    for (int k = 0; k < nc && names; ++k) {
        plcol0(colours[k % 6]);
        plmtex("t", -1.5 - 1.2 * k, 0.02, 0.0, names[k]);
    }
}

static void panel(const sim_trace* a, const sim_trace* b, int xcol, double xs, const int* cols, int nc, double ys,
                  const char* xlabel, const char* ylabel, const char* title, const char* const* names, PLFLT* xb,
                  PLFLT* yb) {
    const psrc pa = {a->v, a->nrow, SIM_NCOL}, pb = {b ? b->v : NULL, b ? b->nrow : 0, SIM_NCOL};
    panel_ex(&pa, b ? &pb : NULL, xcol, xs, cols, NULL, nc, ys, xlabel, ylabel, title, names, NULL, xb, yb);
}

typedef struct traces_plot {
    const sim_trace *a, *b;
    const char *la, *lb, *title;
    bool slew; ///< the world has a slew drive: its channels too
    PLFLT *xb, *yb;
} traces_plot;

static void draw_traces(void* user) {
    const traces_plot* p = user;
    const sim_trace *a = p->a, *b = p->b;
    PLFLT *xb = p->xb, *yb = p->yb;
    page_begin(p->title, 2, false);
    int xs[APP_PLOT_MAXSERIES], ps[APP_PLOT_MAXSERIES], us[APP_PLOT_MAXSERIES];
    const char *xn[APP_PLOT_MAXSERIES], *pn[APP_PLOT_MAXSERIES], *un[APP_PLOT_MAXSERIES];
    const int nx = app_plot_run_channels(0, p->slew, xs, xn), np = app_plot_run_channels(1, p->slew, ps, pn),
              nu = app_plot_run_channels(2, p->slew, us, un);
    const int tz[] = {COL_TIP_Z};
    panel(a, b, COL_T, 1, xs, nx, 1e3, "t [s]", "stroke [mm]", "Cylinder strokes", xn, xb, yb);
    panel(a, b, COL_T, 1, ps, np, 1e-6, "t [s]", "pressure [MPa abs]", "Chamber pressures", pn, xb, yb);
    panel(a, b, COL_T, 1, us, nu, 100, "t [s]", "opening [%]", "Valve spools and commands", un, xb, yb);
    char t4[200];
    if (b) snprintf(t4, sizeof t4, "Tip path (solid: %s, dashed: %s)", p->la, p->lb);
    else snprintf(t4, sizeof t4, "Tip path relative to joint 1");
    panel(a, b, COL_TIP_X, 1, tz, 1, 1, "reach [m]", "height [m]", t4, NULL, xb, yb);
}

static int plot_traces(const sim_trace* a, const char* la, const sim_trace* b, const char* lb, const char* title,
                       bool slew, const char* png, char* err, size_t errsz) {
    int n = a->nrow > (b ? b->nrow : 0) ? a->nrow : b->nrow;
    PLFLT* xb = malloc(sizeof(PLFLT) * (size_t)n);
    PLFLT* yb = malloc(sizeof(PLFLT) * (size_t)n);
    if (!xb || !yb) {
        free(xb);
        free(yb);
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    traces_plot p = {a, b, la, lb, title, slew, xb, yb};
    const int rc = app_png_render(png, "1400x1000", draw_traces, &p, err, errsz);
    free(xb);
    free(yb);
    return rc;
}

int app_plot_run(const sim_trace* tr, const char* title, bool slew, const char* png, char* err, size_t errsz) {
    return plot_traces(tr, "", NULL, "", title, slew, png, err, errsz);
}

int app_plot_compare(const sim_trace* a, const char* la, const sim_trace* b, const char* lb, const char* title, bool slew,
                     const char* png, char* err, size_t errsz) {
    return plot_traces(a, la, b, lb, title, slew, png, err, errsz);
}

typedef struct chain_plot {
    psrc src;
    const psrc* b;  ///< compare: run B's rows (drawn dashed), or NULL
    bool slew;      ///< the world's slew drive, in the base columns, drawn too
    const char *la, *lb;
    const crane_column* col;
    int ncol;
    const char* title;
    PLFLT *xb, *yb;
    int* cols;          ///< scratch: 3 x ncol (columns, commands, colour slots)
    const char** names; ///< scratch: 3 x ncol (actuators, a panel's names, commands)
} chain_plot;

// A chain run's page: 3 x 2 panels, every actuator's stroke and chamber
// pressures (A and B chambers in a panel each, so that each holds one line
// per actuator), every function's spool and command, the joint angles and
// the tip path; a colour per actuator or function, legend by name.
// Each legend name's colour slot: its index among the actuators (the
// strokes' names) when it names one (a function named as its actuator),
// else after them.
static void chain_slots(const char* const* act, int na, const char* const* nm, int n, int* slot) {
    for (int k = 0; k < n; ++k) {
        slot[k] = na + k;
        for (int i = 0; i < na; ++i)
            if (!strcmp(nm[k], act[i])) slot[k] = i;
    }
}

static void draw_chain(void* user) {
    const chain_plot* p = user;
    page_begin(p->title, 3, true);
    // n: the chain's columns; m: the most series a panel has (one more for
    // the world's slew drive), the stride of the scratch arrays.
    const int off = SIM_NCOL, n = p->ncol, m = n + 1;
    int *c = p->cols, *c2 = p->cols + m, *slot = p->cols + 2 * m;
    const char **act = p->names, **nm = p->names + m, **nm2 = p->names + 2 * m;
    const int na = app_plot_chain_channels(p->col, n, off, p->slew, 0, c, act, m);
    chain_slots(act, na, act, na, slot);
    panel_ex(&p->src, p->b, COL_T, 1, c, NULL, na, 1e3, "t [s]", "stroke [mm]", "Cylinder strokes", act, slot, p->xb,
             p->yb);
    const int tz[] = {COL_TIP_Z};
    char t4[200];
    if (p->b) snprintf(t4, sizeof t4, "Tip path (solid: %s, dashed: %s)", p->la, p->lb);
    else snprintf(t4, sizeof t4, "Tip path relative to joint 1");
    panel_ex(&p->src, p->b, COL_TIP_X, 1, tz, NULL, 1, 1, "reach [m]", "height [m]", t4, NULL, NULL, p->xb, p->yb);
    for (int side = 1; side <= 2; ++side) {
        const int k = app_plot_chain_channels(p->col, n, off, p->slew, side, c, nm, m);
        chain_slots(act, na, nm, k, slot);
        panel_ex(&p->src, p->b, COL_T, 1, c, NULL, k, 1e-6, "t [s]", "pressure [MPa abs]",
                 side == 1 ? "Chamber A pressures" : "Chamber B pressures", nm, slot, p->xb, p->yb);
    }
    const int k = app_plot_chain_channels(p->col, n, off, p->slew, 3, c, nm, m);
    // The commands in the spools' order (both per function, in the model's
    // order); drawn only when every spool has its command.
    const int kc = app_plot_chain_channels(p->col, n, off, p->slew, 4, c2, nm2, m);
    chain_slots(act, na, nm, k, slot);
    panel_ex(&p->src, p->b, COL_T, 1, c, kc == k ? c2 : NULL, k, 100, "t [s]", "opening [%]",
             p->b ? "Valve spools (solid: A, dashed: B)" : "Valve spools (solid) and commands (dashed)", nm, slot,
             p->xb, p->yb);
    // The joints by their own order, but the slew (a body and an actuator
    // of one name) in its actuator's colour.
    const int kq = app_plot_chain_channels(p->col, n, off, p->slew, 5, c, nm, m);
    chain_slots(act, na, nm, kq, slot);
    for (int i = 0; i < kq; ++i)
        if (slot[i] >= na) slot[i] = i;
    panel_ex(&p->src, p->b, COL_T, 1, c, NULL, kq, 180 / M_PI, "t [s]", "angle [deg]", "Joint angles", nm, slot,
             p->xb, p->yb);
}

static int plot_chain(const psrc* a, const char* la, const psrc* b, const char* lb, const crane_column* col,
                      int ncol, bool slew, const char* title, const char* png, char* err, size_t errsz) {
    if (a->stride != SIM_NCOL + ncol || (b && b->stride != a->stride)) {
        snprintf(err, errsz, "plot: %d columns a row, expected %d", a->stride, SIM_NCOL + ncol);
        return -1;
    }
    const int nrow = a->nrow > (b ? b->nrow : 0) ? a->nrow : b->nrow;
    PLFLT* xb = malloc(sizeof(PLFLT) * (size_t)(nrow > 0 ? nrow : 1));
    PLFLT* yb = malloc(sizeof(PLFLT) * (size_t)(nrow > 0 ? nrow : 1));
    // Room for the slew's series too (one per panel).
    int* cols = malloc(sizeof(int) * 3 * (size_t)(ncol + 1));
    const char** names = malloc(sizeof(char*) * 3 * (size_t)(ncol + 1));
    int rc = -1;
    if (!xb || !yb || !cols || !names) {
        snprintf(err, errsz, "out of memory");
    } else {
        chain_plot p = {*a, b, slew, la, lb, col, ncol, title, xb, yb, cols, names};
        rc = app_png_render(png, "1400x1400", draw_chain, &p, err, errsz);
    }
    free(xb);
    free(yb);
    free(cols);
    free(names);
    return rc;
}

int app_plot_chain_run(const double* rows, int nrow, int stride, const crane_column* col, int ncol, bool slew,
                       const char* title, const char* png, char* err, size_t errsz) {
    const psrc a = {rows, nrow, stride};
    return plot_chain(&a, "", NULL, "", col, ncol, slew, title, png, err, errsz);
}

int app_plot_chain_compare(const double* a, int na, const char* la, const double* b, int nb, const char* lb,
                           int stride, const crane_column* col, int ncol, bool slew, const char* title,
                           const char* png, char* err, size_t errsz) {
    const psrc pa = {a, na, stride}, pb = {b, nb, stride};
    return plot_chain(&pa, la, &pb, lb, col, ncol, slew, title, png, err, errsz);
}

typedef struct bars_plot {
    const char* const* names;
    const double* kj;
    int n;
    const char* title;
} bars_plot;

// Horizontal bars, one per component, longest loss at the top.
static void draw_bars(void* user) {
    const bars_plot* p = user;
    plstar(1, 1);
    plschr(0, 0.8);
    double hi = 0.0;
    for (int i = 0; i < p->n; ++i) hi = fmax(hi, p->kj[i]);
    if (!(hi > 0.0)) hi = 1.0;
    pladv(0);
    plvpor(0.28, 0.95, 0.1, 0.9);
    plwind(0.0, 1.05 * hi, 0.0, (PLFLT)p->n);
    plcol0(15);
    plbox("bcgnst", 0.0, 0, "bc", 0.0, 0);
    pllab("energy [kJ]", "", p->title);
    for (int i = 0; i < p->n; ++i) {
        const PLFLT y0 = (PLFLT)(p->n - 1 - i) + 0.15, y1 = y0 + 0.7;
        PLFLT xs[4] = {0.0, p->kj[i], p->kj[i], 0.0}, ys[4] = {y0, y0, y1, y1};
        plcol0(9);
        plfill(4, xs, ys);
        plcol0(15);
        plline(4, xs, ys);
        char lab[120];
        snprintf(lab, sizeof lab, "%s  %.3g ", p->names[i], p->kj[i]);
        plmtex("lv", 0.5, 0.5 * (y0 + y1) / (PLFLT)p->n, 1.0, lab);
    }
}

int app_plot_energy(const char* const* names, const double* kj, int n, const char* title, const char* png, char* err,
                    size_t errsz) {
    bars_plot p = {names, kj, n, title};
    return app_png_render(png, "1000x700", draw_bars, &p, err, errsz);
}
#else
int app_png_render(const char* png, const char* geometry, void (*draw)(void* user), void* user, char* err,
                   size_t errsz) {
    (void)png, (void)geometry, (void)draw, (void)user, (void)write_file;
    snprintf(err, errsz, "cranesim was built without PLplot (install libplplot-dev plplot-driver-cairo)");
    return -1;
}
int app_plot_run(const sim_trace* tr, const char* title, bool slew, const char* png, char* err, size_t errsz) {
    (void)tr, (void)title, (void)slew, (void)png;
    snprintf(err, errsz, "cranesim was built without PLplot (install libplplot-dev plplot-driver-cairo)");
    return -1;
}
int app_plot_energy(const char* const* names, const double* kj, int n, const char* title, const char* png, char* err,
                    size_t errsz) {
    (void)names, (void)kj, (void)n, (void)title, (void)png;
    snprintf(err, errsz, "cranesim was built without PLplot (install libplplot-dev plplot-driver-cairo)");
    return -1;
}
int app_plot_chain_compare(const double* a, int na, const char* la, const double* b, int nb, const char* lb,
                           int stride, const crane_column* col, int ncol, bool slew, const char* title,
                           const char* png, char* err, size_t errsz) {
    (void)a, (void)na, (void)la, (void)b, (void)nb, (void)lb, (void)stride, (void)col, (void)ncol, (void)slew;
    (void)title;
    (void)png;
    snprintf(err, errsz, "cranesim was built without PLplot (install libplplot-dev plplot-driver-cairo)");
    return -1;
}
int app_plot_chain_run(const double* rows, int nrow, int stride, const crane_column* col, int ncol, bool slew,
                       const char* title, const char* png, char* err, size_t errsz) {
    (void)rows, (void)nrow, (void)stride, (void)col, (void)ncol, (void)slew, (void)title, (void)png;
    snprintf(err, errsz, "cranesim was built without PLplot (install libplplot-dev plplot-driver-cairo)");
    return -1;
}
int app_plot_compare(const sim_trace* a, const char* la, const sim_trace* b, const char* lb, const char* title, bool slew,
                     const char* png, char* err, size_t errsz) {
    (void)a, (void)la, (void)b, (void)lb, (void)title, (void)slew, (void)png;
    snprintf(err, errsz, "cranesim was built without PLplot (install libplplot-dev plplot-driver-cairo)");
    return -1;
}
#endif
