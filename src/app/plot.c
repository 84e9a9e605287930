// plot.c: PNG plots of runs with PLplot (cairo driver): strokes, chamber
// pressures, valve openings and the tip path, as the paper's WinSimu showed.
#include "app.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef CRANESIM_HAVE_PLPLOT
#include <plplot.h>

typedef struct series {
    const sim_trace* tr;
    int col;
    double scale;
} series;

static void range_of(const sim_trace* tr, int col, double scale, double* lo, double* hi) {
    for (int i = 0; i < tr->nrow; ++i) {
        double v = tr->v[(size_t)i * SIM_NCOL + col] * scale;
        if (v < *lo) *lo = v;
        if (v > *hi) *hi = v;
    }
}

static void draw_series(const sim_trace* tr, int xcol, double xs, int ycol, double ys, PLFLT* xb, PLFLT* yb) {
    for (int i = 0; i < tr->nrow; ++i) {
        xb[i] = tr->v[(size_t)i * SIM_NCOL + xcol] * xs;
        yb[i] = tr->v[(size_t)i * SIM_NCOL + ycol] * ys;
    }
    plline(tr->nrow, xb, yb);
}

// One panel: columns cols[0..nc) of up to two traces, the second dashed.
static void panel(const sim_trace* a, const sim_trace* b, int xcol, double xs, const int* cols, int nc,
                  double ys, const char* xlabel, const char* ylabel, const char* title, const char* const* names,
                  PLFLT* xb, PLFLT* yb) {
    double xlo = 1e300, xhi = -1e300, ylo = 1e300, yhi = -1e300;
    const sim_trace* trs[2] = {a, b};
    for (int t = 0; t < 2; ++t) {
        if (!trs[t]) continue;
        range_of(trs[t], xcol, xs, &xlo, &xhi);
        for (int k = 0; k < nc; ++k) range_of(trs[t], cols[k], ys, &ylo, &yhi);
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
    plenv(xlo, xhi, ylo - pad, yhi + pad, 0, 2);
    pllab(xlabel, ylabel, title);
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

static int plot_traces(const sim_trace* a, const char* la, const sim_trace* b, const char* lb, const char* title,
                       const char* png, char* err, size_t errsz) {
    int n = a->nrow > (b ? b->nrow : 0) ? a->nrow : b->nrow;
    PLFLT* xb = malloc(sizeof(PLFLT) * (size_t)n);
    PLFLT* yb = malloc(sizeof(PLFLT) * (size_t)n);
    if (!xb || !yb) {
        free(xb);
        free(yb);
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    FILE* probe = fopen(png, "wb");
    if (!probe) {
        free(xb);
        free(yb);
        snprintf(err, errsz, "cannot write %s", png);
        return -1;
    }
    fclose(probe);
    plsdev("pngcairo");
    plsfnam(png);
    plsetopt("geometry", "1400x1000");
    plscolbg(255, 255, 255);
    plscol0(15, 0, 0, 0);
    plstar(2, 2);
    plschr(0, 0.9);
    char sup[256];
    snprintf(sup, sizeof sup, "%s", title);
    const int xs[] = {COL_X1, COL_X2};
    const char* const xn[] = {"x1 lift", "x2 jib"};
    const int ps[] = {COL_P1A, COL_P1B, COL_P2A, COL_P2B};
    const char* const pn[] = {"p1A", "p1B", "p2A", "p2B"};
    const int us[] = {COL_U1, COL_U2, COL_U1_CMD, COL_U2_CMD};
    const char* const un[] = {"u1 spool", "u2 spool", "u1 cmd", "u2 cmd"};
    const int tz[] = {COL_TIP_Z};
    char t1[300];
    snprintf(t1, sizeof t1, "Cylinder strokes - %s", sup);
    panel(a, b, COL_T, 1, xs, 2, 1e3, "t [s]", "stroke [mm]", t1, xn, xb, yb);
    panel(a, b, COL_T, 1, ps, 4, 1e-6, "t [s]", "pressure [MPa abs]", "Chamber pressures", pn, xb, yb);
    panel(a, b, COL_T, 1, us, 4, 100, "t [s]", "opening [%]", "Valve spools and commands", un, xb, yb);
    char t4[200];
    if (b) snprintf(t4, sizeof t4, "Tip path (solid: %s, dashed: %s)", la, lb);
    else snprintf(t4, sizeof t4, "Tip path relative to joint 1");
    panel(a, b, COL_TIP_X, 1, tz, 1, 1, "reach [m]", "height [m]", t4, NULL, xb, yb);
    plend();
    free(xb);
    free(yb);
    return 0;
}

int app_plot_run(const sim_trace* tr, const char* title, const char* png, char* err, size_t errsz) {
    return plot_traces(tr, "", NULL, "", title, png, err, errsz);
}

int app_plot_compare(const sim_trace* a, const char* la, const sim_trace* b, const char* lb, const char* title,
                     const char* png, char* err, size_t errsz) {
    return plot_traces(a, la, b, lb, title, png, err, errsz);
}
#else
int app_plot_run(const sim_trace* tr, const char* title, const char* png, char* err, size_t errsz) {
    (void)tr, (void)title, (void)png;
    snprintf(err, errsz, "cranesim was built without PLplot (install libplplot-dev plplot-driver-cairo)");
    return -1;
}
int app_plot_compare(const sim_trace* a, const char* la, const sim_trace* b, const char* lb, const char* title,
                     const char* png, char* err, size_t errsz) {
    (void)a, (void)la, (void)b, (void)lb, (void)title, (void)png;
    snprintf(err, errsz, "cranesim was built without PLplot (install libplplot-dev plplot-driver-cairo)");
    return -1;
}
#endif
