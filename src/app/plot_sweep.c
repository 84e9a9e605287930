// plot_sweep.c: the sweep's plots with PLplot: a metric against a
// parameter (one point per design) and a heat map of a metric over a
// two-parameter grid. Rendered through app_png_render (checked writes).
#include "app.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef CRANESIM_HAVE_PLPLOT
#include <plplot.h>

typedef struct scatter_plot {
    const char *title, *xlab, *ylab;
    const double *x, *y;
    long n;
} scatter_plot;

static void range(const double* v, long n, double* lo, double* hi) {
    *lo = INFINITY;
    *hi = -INFINITY;
    for (long i = 0; i < n; ++i) {
        *lo = fmin(*lo, v[i]);
        *hi = fmax(*hi, v[i]);
    }
    if (!(*hi > *lo)) { // one value, or none: a window around it
        const double c = isfinite(*lo) ? *lo : 0.0;
        const double d = fabs(c) * 0.05 + 1e-9;
        *lo = c - d;
        *hi = c + d;
    } else {
        const double pad = 0.05 * (*hi - *lo);
        *lo -= pad;
        *hi += pad;
    }
}

static void draw_scatter(void* user) {
    const scatter_plot* p = user;
    plinit();
    plschr(0, 0.9);
    double xlo, xhi, ylo, yhi;
    range(p->x, p->n, &xlo, &xhi);
    range(p->y, p->n, &ylo, &yhi);
    plcol0(15);
    plenv(xlo, xhi, ylo, yhi, 0, 2);
    pllab(p->xlab, p->ylab, p->title);
    // Points in design order, joined when the parameter only grows (a grid
    // over one parameter), else points only (a hypercube, several parameters).
    bool sorted = true;
    for (long i = 1; i < p->n && sorted; ++i) sorted = p->x[i] > p->x[i - 1];
    plcol0(1);
    if (sorted && p->n > 1) plline((PLINT)p->n, p->x, p->y);
    plpoin((PLINT)p->n, p->x, p->y, 17);
}

int app_plot_sweep(const char* png, const char* title, const char* xlab, const char* ylab, const double* x,
                   const double* y, long n, char* err, size_t errsz) {
    scatter_plot p = {title, xlab, ylab, x, y, n};
    return app_png_render(png, "1000x700", draw_scatter, &p, err, errsz);
}

typedef struct heat_plot {
    const char *title, *xlab, *ylab;
    const double* z;
    long nx, ny;
    double x0, x1, y0, y1;
} heat_plot;

static void draw_heat(void* user) {
    const heat_plot* p = user;
    plinit();
    pladv(0);
    plschr(0, 0.9);
    double lo = INFINITY, hi = -INFINITY;
    bool failed = false;
    for (long k = 0; k < p->nx * p->ny; ++k) {
        if (isfinite(p->z[k])) {
            lo = fmin(lo, p->z[k]);
            hi = fmax(hi, p->z[k]);
        } else {
            failed = true;
        }
    }
    if (!(hi > lo)) {
        lo = isfinite(lo) ? lo - 1 : 0;
        hi = lo + 2;
    }
    // One cell per design, centred on its grid values. The map leaves the
    // right of the page to its colour bar and the top to the title (the
    // title and the old one-line scale above the map ran into each other).
    const double dx = p->nx > 1 ? (p->x1 - p->x0) / (double)(p->nx - 1) : fabs(p->x0) * 0.1 + 1e-9;
    const double dy = p->ny > 1 ? (p->y1 - p->y0) / (double)(p->ny - 1) : fabs(p->y0) * 0.1 + 1e-9;
    plcol0(15);
    plvpor(0.13, 0.80, 0.11, 0.88);
    plwind(p->x0 - dx / 2, p->x1 + dx / 2, p->y0 - dy / 2, p->y1 + dy / 2);
    plspal1("cmap1_blue_red.pal", 1);
    // Each cell's value on it when the cells are large enough to read.
    const bool values = p->nx <= 12 && p->ny <= 16;
    for (long i = 0; i < p->nx; ++i)
        for (long j = 0; j < p->ny; ++j) {
            // The grid's rows have the second parameter fastest.
            const double z = p->z[(size_t)i * (size_t)p->ny + (size_t)j];
            if (!isfinite(z)) continue; // a failed design stays blank
            const double xc = p->x0 + dx * (double)i, yc = p->y0 + dy * (double)j;
            PLFLT xs[4] = {xc - dx / 2, xc + dx / 2, xc + dx / 2, xc - dx / 2};
            PLFLT ys[4] = {yc - dy / 2, yc - dy / 2, yc + dy / 2, yc + dy / 2};
            plcol1((z - lo) / (hi - lo));
            plfill(4, xs, ys);
        }
    if (values) {
        plschr(0, 0.7);
        for (long i = 0; i < p->nx; ++i)
            for (long j = 0; j < p->ny; ++j) {
                const double z = p->z[(size_t)i * (size_t)p->ny + (size_t)j];
                if (!isfinite(z)) continue;
                char v[32];
                snprintf(v, sizeof v, "%.4g", z);
                // White (colour 0, the background) on the dark blue low end.
                plcol0((z - lo) / (hi - lo) < 0.2 ? 0 : 15);
                plptex(p->x0 + dx * (double)i, p->y0 + dy * (double)j, 1, 0, 0.5, v);
            }
        plschr(0, 0.9);
    }
    plcol0(15);
    plbox("bcnst", 0, 0, "bcnstv", 0, 0);
    pllab(p->xlab, p->ylab, "");
    plmtex("t", 1.5, 0.5, 0.5, p->title);
    if (failed) plmtex("b", 3.2, 1.0, 1.0, "blank: failed design");
    // The colour bar right of the map: the metric's range, low (blue) to
    // high (red), in the title's unit.
    PLINT lopt[1] = {PL_COLORBAR_LABEL_BOTTOM};
    const char* lab[1] = {""};
    const char* axis[1] = {"bcvmst"};
    PLFLT ticks[1] = {0};
    PLINT sub[1] = {0}, nv[1] = {2};
    PLFLT range[2] = {lo, hi};
    const PLFLT* vals[1] = {range};
    PLFLT cw, ch;
    plcolorbar(&cw, &ch, PL_COLORBAR_GRADIENT, PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.03,
               0.0, 0.04, 1.0, 0, 15, 1, 0, 0, 0, 0, 1, lopt, lab, 1, axis, ticks, sub, nv, vals);
}

int app_plot_heat(const char* png, const char* title, const char* xlab, const char* ylab, const double* z,
                  long nx, long ny, double x0, double x1, double y0, double y1, char* err, size_t errsz) {
    heat_plot p = {title, xlab, ylab, z, nx, ny, x0, x1, y0, y1};
    return app_png_render(png, "1100x800", draw_heat, &p, err, errsz);
}
typedef struct conv_plot {
    const char *title, *ylab;
    const double *f;
    const bool* feasible;
    long n;
} conv_plot;

// The optimiser's convergence: every evaluation's objective (filled points
// feasible, crosses infeasible, failed designs left out) and the best
// feasible value so far as a line.
static void draw_conv(void* user) {
    const conv_plot* p = user;
    plinit();
    plschr(0, 0.9);
    double* x = calloc((size_t)(p->n > 0 ? p->n : 1), sizeof *x);
    double* y = calloc((size_t)(p->n > 0 ? p->n : 1), sizeof *y);
    double* best = malloc((size_t)(p->n > 0 ? p->n : 1) * sizeof *best);
    if (!x || !y || !best) {
        free(x), free(y), free(best);
        return;
    }
    long m = 0;
    for (long i = 0; i < p->n; ++i)
        if (isfinite(p->f[i])) x[m] = (double)(i + 1), y[m++] = p->f[i];
    double ylo, yhi, xlo, xhi;
    range(y, m, &ylo, &yhi);
    range(x, m, &xlo, &xhi);
    if (m == 0) xlo = 0, xhi = 1;
    plcol0(15);
    plenv(xlo, xhi, ylo, yhi, 0, 2);
    pllab("evaluation", p->ylab, p->title);
    for (long i = 0; i < p->n; ++i) {
        if (!isfinite(p->f[i])) continue;
        PLFLT px = (double)(i + 1), py = p->f[i];
        plcol0(p->feasible[i] ? 1 : 9);
        plpoin(1, &px, &py, p->feasible[i] ? 17 : 5);
    }
    long nb = 0;
    double b = INFINITY;
    for (long i = 0; i < p->n; ++i) {
        if (isfinite(p->f[i]) && p->feasible[i]) b = fmin(b, p->f[i]);
        if (isfinite(b)) x[nb] = (double)(i + 1), best[nb++] = b;
    }
    plcol0(3);
    if (nb > 1) plline((PLINT)nb, x, best);
    free(x), free(y), free(best);
}

int app_plot_convergence(const char* png, const char* title, const char* ylab, const double* f, const bool* feasible,
                         long n, char* err, size_t errsz) {
    conv_plot p = {title, ylab, f, feasible, n};
    return app_png_render(png, "1000x700", draw_conv, &p, err, errsz);
}
#else
int app_plot_convergence(const char* png, const char* title, const char* ylab, const double* f, const bool* feasible,
                         long n, char* err, size_t errsz) {
    (void)title, (void)ylab, (void)f, (void)feasible, (void)n;
    return app_png_render(png, "", NULL, NULL, err, errsz);
}
int app_plot_sweep(const char* png, const char* title, const char* xlab, const char* ylab, const double* x,
                   const double* y, long n, char* err, size_t errsz) {
    (void)title, (void)xlab, (void)ylab, (void)x, (void)y, (void)n;
    return app_png_render(png, "", NULL, NULL, err, errsz);
}
int app_plot_heat(const char* png, const char* title, const char* xlab, const char* ylab, const double* z,
                  long nx, long ny, double x0, double x1, double y0, double y1, char* err, size_t errsz) {
    (void)title, (void)xlab, (void)ylab, (void)z, (void)nx, (void)ny, (void)x0, (void)x1, (void)y0, (void)y1;
    return app_png_render(png, "", NULL, NULL, err, errsz);
}
#endif
