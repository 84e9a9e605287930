// cmd_loadchart.c: `cranesim loadchart`: the rated capacity against outreach
// (src/world/loadchart.h) as a CSV and a PNG chart.
#include "app.h"
#include "loadchart.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void help(FILE* f) {
    fprintf(f,
            "usage: cranesim loadchart [--model M] [--world W] [--margin 0.10] [--stability-factor 1.25]\n"
            "                          [--outreach LO:HI:N] [--sectors K] [--out chart.csv] [--plot chart.png]\n"
            "\n"
            "Rated capacity (payload under the hook, kg) against outreach (m, tip from the slew axis):\n"
            "  hydraulic limit: the largest load whose static holding pressure in each cylinder stays\n"
            "    below its port relief setting less --margin (a fraction, in [0, 0.5]; default 0.10),\n"
            "    in every pose of the booms that reaches the outreach;\n"
            "  stability limit (sandbox truck only): the largest load whose tipping moment about the\n"
            "    support polygon's edges, times --stability-factor (> 1; default 1.25), stays below the\n"
            "    restoring moment of truck and crane, in K slew sectors over 0..180 deg (centred on\n"
            "    0 = over the cab, ..., 180 = over the rear; default 3: cab, side, rear).\n"
            "  --world W     sandbox (default) or validation (no truck: hydraulic limit only), or a file\n"
            "  --outreach    LO:HI:N metres and points (default: the crane's reach from 0.5 m, 50 points)\n"
            "  --out FILE    CSV (default loadchart.csv); --plot FILE: PNG chart, governing limit marked\n"
            "  --set PATH=V  change a model value (as for run)\n"
            "See docs/safety.md.\n");
}

static int parse_range(const char* s, lc_opts* o) {
    char* end;
    o->lo = strtod(s, &end);
    if (*end != ':') return -1;
    o->hi = strtod(end + 1, &end);
    if (*end != ':') return -1;
    const long n = strtol(end + 1, &end, 10);
    if (*end || n < -1000000 || n > 1000000) return -1;
    o->n = (int)n;
    return 0;
}

static void sector_name(const loadchart* c, int s, char* buf, size_t n) {
    snprintf(buf, n, "%.0f-%.0f deg", c->sec_lo[s] * 180 / M_PI, c->sec_hi[s] * 180 / M_PI);
}

#ifdef CRANESIM_HAVE_PLPLOT
#include <plplot.h>
typedef struct chart_plot {
    const loadchart* c;
    const char* title;
} chart_plot;

static void draw_chart(void* user) {
    const chart_plot* p = user;
    const loadchart* c = p->c;
    plinit();
    plschr(0, 0.9);
    double ymax = 0;
    for (int i = 0; i < c->n; ++i) {
        if (isfinite(c->hyd[i])) ymax = fmax(ymax, c->hyd[i]);
    }
    if (!(ymax > 0)) ymax = 1;
    plcol0(15);
    plenv(c->R[0], c->R[c->n - 1], 0, 1.05 * ymax, 0, 2);
    pllab("outreach [m]", "rated capacity [kg]", p->title);
    static PLFLT x[LOADCHART_MAX_POINTS], y[LOADCHART_MAX_POINTS];
    for (int i = 0; i < c->n; ++i) x[i] = c->R[i], y[i] = c->hyd[i];
    // The hydraulic limit alone, dashed; the rated capacity of each sector
    // solid, with a circle where the stability limit governs.
    // Dark colours of the default map (blue, brown, magenta, ...): the light
    // ones (yellow, aquamarine) do not read on white.
    static const int sec_col[] = {9, 8, 13, 10, 12, 14, 11, 3};
    for (int s = 0; s < c->nsec; ++s) {
        plcol0(sec_col[s % 8]);
        for (int i = 0; i < c->n; ++i) y[i] = loadchart_capacity(c, c->R[i], 0.5 * (c->sec_lo[s] + c->sec_hi[s]), NULL);
        plwidth(2);
        plline(c->n, x, y);
        plwidth(1);
        for (int i = 0; i < c->n; ++i) {
            bool st;
            loadchart_capacity(c, c->R[i], 0.5 * (c->sec_lo[s] + c->sec_hi[s]), &st);
            if (st) plpoin(1, &x[i], &y[i], 4);
        }
        char nm[64];
        sector_name(c, s, nm, sizeof nm);
        plmtex("t", -1.5 - 1.2 * s, 0.98, 1.0, nm);
    }
    // The hydraulic limit last, dashed red over the sectors it governs.
    for (int i = 0; i < c->n; ++i) y[i] = c->hyd[i];
    pllsty(2);
    plcol0(1);
    plline(c->n, x, y);
    pllsty(1);
    plmtex("t", -1.5 - 1.2 * c->nsec, 0.98, 1.0, "dashed: hydraulic limit; o: stability governs");
}

static int plot_chart(const char* png, const loadchart* c, const char* title, char* err, size_t errsz) {
    chart_plot p = {c, title};
    return app_png_render(png, "1000x700", draw_chart, &p, err, errsz);
}
#else
static int plot_chart(const char* png, const loadchart* c, const char* title, char* err, size_t errsz) {
    (void)c, (void)title;
    return app_png_render(png, "", NULL, NULL, err, errsz);
}
#endif

int cmd_loadchart(int argc, char** argv) {
    app_common c = {0};
    c.sim = sim_default_opts();
    lc_opts lo = lc_default_opts();
    bool range_given = false;
    const char* out = "loadchart.csv";
    const char* png = NULL;
    for (int i = 0; i < argc; ++i) {
        const char* a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help(stdout);
            return 0;
        }
        if (!strcmp(a, "--margin") || !strcmp(a, "--stability-factor") || !strcmp(a, "--outreach") ||
            !strcmp(a, "--sectors") || !strcmp(a, "--out") || !strcmp(a, "--plot")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            double d = 0;
            if (!strcmp(a, "--out")) out = v;
            else if (!strcmp(a, "--plot")) png = v;
            else if (!strcmp(a, "--outreach")) {
                if (parse_range(v, &lo)) {
                    fprintf(stderr, "cranesim loadchart: --outreach: expected LO:HI:N (metres, points), got '%s'\n", v);
                    return EXIT_USAGE;
                }
                range_given = true;
            } else if (app_parse_double(v, &d)) {
                fprintf(stderr, "cranesim loadchart: %s: not a number: '%s'\n", a, v);
                return EXIT_USAGE;
            } else if (!strcmp(a, "--margin")) lo.margin = d;
            else if (!strcmp(a, "--stability-factor")) lo.sf = d;
            else if (d != floor(d) || fabs(d) > 1e6) {
                fprintf(stderr, "cranesim loadchart: --sectors: expected a whole number, got '%s'\n", v);
                return EXIT_USAGE;
            } else lo.sectors = (int)d;
            continue;
        }
        const int r = app_parse_common(&c, argc, argv, &i);
        if (r < 0) return EXIT_USAGE;
        if (r == 0 || (c.given & ~(APP_GIVEN(APP_OPT_MODEL) | APP_GIVEN(APP_OPT_WORLD) | APP_GIVEN(APP_OPT_SET) |
                                   APP_GIVEN(APP_OPT_QUIET)))) {
            fprintf(stderr, "cranesim loadchart: unknown option '%s' (try --help)\n", a);
            return EXIT_USAGE;
        }
    }
    char err[600];
    if (!range_given) lo.lo = 0.5, lo.hi = 1.0; // placeholders: checked below once the model is known
    if (lc_check_opts(&lo, err, sizeof err)) {
        fprintf(stderr, "cranesim loadchart: %s\n", err);
        return EXIT_USAGE;
    }
    if (app_check_output("loadchart", "--out", out, ".csv")) return EXIT_USAGE;
    if (png && app_check_output("loadchart", "--plot", png, ".png")) return EXIT_USAGE;
    if (app_check_distinct("loadchart", (const char* const[]){"--out", "--plot"}, (const char* const[]){out, png}, 2))
        return EXIT_USAGE;
    model* m = model_load(c.model_path, c.sets, c.nset, err, sizeof err);
    if (!m) {
        fprintf(stderr, "cranesim loadchart: %s\n", err);
        return EXIT_USAGE;
    }
    char wbuf[512];
    const char* wpath = sim_world_path(c.sim.world ? c.sim.world : "sandbox", wbuf, sizeof wbuf);
    static world_desc wd;
    if (world_desc_load(wpath, &wd, err, sizeof err)) {
        fprintf(stderr, "cranesim loadchart: %s\n", err);
        model_free(m);
        return EXIT_USAGE;
    }
    lc_truck t;
    lc_truck_from_world(&wd, &t);
    world_desc_free(&wd);
    double rmin, rmax;
    loadchart_reach(m, &rmin, &rmax);
    if (!range_given) {
        lo.lo = fmax(0.5, rmin), lo.hi = floor(20 * rmax - 1) / 20; // 5 cm steps, inside the reach
    } else if (lo.lo < fmax(0.0, rmin) - 1e-9 || lo.hi > rmax + 1e-9) {
        // The range a user may give: outreaches are >= 0 (a tip behind the
        // slew axis, where the folded crane can reach, is no outreach), so
        // the bound said is the one LO must meet, not the bare reach.
        fprintf(stderr, "cranesim loadchart: --outreach: %g:%g m is outside the crane's reach: LO:HI must lie in "
                        "[%.3f, %.3f] m\n",
                lo.lo, lo.hi, fmax(0.0, rmin), rmax);
        model_free(m);
        return EXIT_USAGE;
    }
    static loadchart ch;
    const double w0 = sim_wall_time();
    if (loadchart_compute(m, &t, &lo, &ch, err, sizeof err)) {
        fprintf(stderr, "cranesim loadchart: %s\n", err);
        model_free(m);
        return EXIT_USAGE;
    }
    const double wall = sim_wall_time() - w0;
    FILE* f = fopen(out, "w");
    if (!f) {
        fprintf(stderr, "cranesim loadchart: --out %s: cannot write\n", out);
        loadchart_free(&ch);
        model_free(m);
        return EXIT_RUNTIME;
    }
    fprintf(f, "outreach_m,hydraulic_kg,hyd_cylinder");
    for (int s = 0; s < ch.nsec && ch.truck; ++s) {
        fprintf(f, ",stability_s%d_%.0f_%.0fdeg_kg", s, ch.sec_lo[s] * 180 / M_PI, ch.sec_hi[s] * 180 / M_PI);
    }
    for (int s = 0; s < ch.nsec; ++s) fprintf(f, ",rated_s%d_kg,governs_s%d", s, s);
    fprintf(f, "\n");
    for (int i = 0; i < ch.n; ++i) {
        fprintf(f, "%.4f,%.1f,%s", ch.R[i], ch.hyd[i], ch.hyd_cyl[i] ? "jib" : "lift");
        for (int s = 0; s < ch.nsec && ch.truck; ++s) {
            const double v = ch.stab[(size_t)i * ch.nsec + s];
            if (isinf(v)) fprintf(f, ",inf");
            else fprintf(f, ",%.1f", v);
        }
        for (int s = 0; s < ch.nsec; ++s) {
            bool st;
            const double cap = loadchart_capacity(&ch, ch.R[i], 0.5 * (ch.sec_lo[s] + ch.sec_hi[s]), &st);
            fprintf(f, ",%.1f,%s", cap, st ? "stability" : "hydraulic");
        }
        fprintf(f, "\n");
    }
    const int werr = app_fclose_checked(f, 0);
    if (werr) {
        fprintf(stderr, "cranesim loadchart: --out %s: write failed\n", out);
        loadchart_free(&ch);
        model_free(m);
        return EXIT_RUNTIME;
    }
    int rc = 0;
    if (png) {
        char title[200];
        snprintf(title, sizeof title, "load chart: %s, relief margin %.0f %%, stability factor %.2f",
                 ch.truck ? "truck on outriggers" : "no truck", 100 * lo.margin, lo.sf);
        if (plot_chart(png, &ch, title, err, sizeof err)) {
            fprintf(stderr, "cranesim loadchart: %s\n", err);
            rc = EXIT_RUNTIME;
        }
    }
    if (!c.quiet) {
        printf("cranesim loadchart: %s, %s, margin %.0f %% of the port reliefs, stability factor %.2f\n", m->name,
               ch.truck ? "sandbox truck" : "no truck (hydraulic limit only)", 100 * lo.margin, lo.sf);
        printf("  %d outreach points %.2f..%.2f m, %d slew sector%s, computed in %.3f s\n", ch.n, ch.R[0],
               ch.R[ch.n - 1], ch.nsec, ch.nsec > 1 ? "s" : "", wall);
        const int idx[3] = {0, ch.n / 2, ch.n - 1};
        for (int j = 0; j < 3; ++j) {
            const int i = idx[j];
            printf("  at %.2f m: hydraulic %.0f kg", ch.R[i], ch.hyd[i]);
            for (int s = 0; s < ch.nsec && ch.truck; ++s) {
                const double cap = loadchart_capacity(&ch, ch.R[i], 0.5 * (ch.sec_lo[s] + ch.sec_hi[s]), NULL);
                printf(", sector %d %.0f kg", s, cap);
            }
            printf("\n");
        }
        printf("  chart -> %s\n", out);
        if (png && !rc) printf("  plot -> %s\n", png);
    }
    loadchart_free(&ch);
    model_free(m);
    return rc;
}
