// cmd_loadchart.c: `cranesim loadchart`: the rated capacity against outreach
// (src/world/safety/loadchart.h) as a CSV and a PNG chart.
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
            "  raw envelope: the smaller of the two, per sector (what the crane can do);\n"
            "  chart: the raw envelope capped by the model's rating (mechanics.rated_load [kg] and\n"
            "    rated_moment [kN m], less the hook), from the minimum outreach (where that is largest)\n"
            "    outward, never rising with outreach; closer in not printed (empty), the capacity column\n"
            "    (what the limiter uses) is the capped envelope there.\n"
            "  Each point names what governs it (lift, jib, stability, rated), at which outreach, and\n"
            "    the pose (q1, q2, slew in deg) to check it by simulation. A crane chain (a model with\n"
            "    mechanics.bodies): every joint coordinate searched within its limits, extensions\n"
            "    included; the governing actuator by name and the whole pose (<body>_deg or _m).\n"
            "  --world W     sandbox (default) or validation (no truck: hydraulic limit only), or a file\n"
            "  --outreach    LO:HI:N metres and points (default: the crane's reach from 0.5 m, 50 points)\n"
            "  --out FILE    CSV (default loadchart.csv); --plot FILE: PNG of the charts and the raw limits\n"
            "  --set PATH=V  change a model value (as for run)\n"
            "See docs/safety.md.\n");
}

// A crane chain's poses in the CSV: angles in deg, slides in m.
#define LC_CSV_MAX_DOF 64
static double pose_value(const loadchart* c, int d, double v) { return c->dof_prismatic[d] ? v : v * 180 / M_PI; }

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

#ifdef CRANESIM_HAVE_PLPLOT
#include <plplot.h>
typedef struct chart_plot {
    const loadchart* c;
    const char* title;
} chart_plot;

// Colours (cmap0 entries set here): per sector a dark one for its printed
// chart and a light tint of it for its raw stability limit; the hydraulic
// limit red, the rating dark gold. Dark enough to read on white.
#define LC_NCOL 6
static const int k_dark[LC_NCOL][3] = {{0, 60, 200}, {0, 140, 0}, {190, 0, 190}, {220, 120, 0}, {0, 140, 150}, {110, 60, 20}};
static const int k_light[LC_NCOL][3] = {{140, 175, 255}, {130, 220, 130}, {245, 150, 245}, {255, 200, 120}, {120, 220, 225}, {205, 165, 120}};
#define LC_COL_HYD 1    // red: the hydraulic limit
#define LC_COL_RATING 2 // dark gold: the model's rating
#define LC_COL_DARK 3   // 3..8: the sectors' printed charts
#define LC_COL_LIGHT 9  // 9..14: the sectors' stability limits
#define LC_COL_INSIDE 16 // warm grey: closer than the minimum outreach (not printed; what the limiter uses)

// Width of sector s's printed chart [PLplot width units, about a pixel]:
// nested, widest first, so where the sectors' charts coincide (where the
// hydraulic limit or the rating governs in each) every one shows as a
// stripe of its own instead of the last one hiding the others.
static double sector_width(int s, int nsec) {
    return nsec > 1 ? 5.0 + 9.0 * (nsec - 1 - s) / (nsec - 1) : 5.0;
}

static void legend_line(double y, int col, int style, double width, const char* text) {
    const PLFLT x[2] = {0.02, 0.16}, yy[2] = {y, y};
    plcol0(col);
    pllsty(style);
    plwidth(width);
    plline(2, x, yy);
    pllsty(1);
    plwidth(1);
    plcol0(15);
    plptex(0.19, y, 1, 0, 0, text);
}

// A crane chain's governing pose per point (sector 0's; what the CSV's
// <body>_s0 columns hold), under the chart: each joint coordinate as its
// place within its limits, 0 at the lower limit and 1 at the upper, so
// angles and slides share one axis.
static void draw_pose(const loadchart* c) {
    static PLFLT x[LOADCHART_MAX_POINTS], y[LOADCHART_MAX_POINTS];
    plvpor(0.08, 0.68, 0.10, 0.34);
    plwind(c->R[0], c->R[c->n - 1], -0.05, 1.05);
    plcol0(15);
    plbox("bcgnst", 0, 0, "bcgnstv", 0.5, 0);
    pllab("outreach [m]", "pose in range", "");
    plmtex("t", 0.8, 0.0, 0.0, "the governing pose (sector 0): each joint 0 at its lower limit, 1 at its upper");
    double q[LC_CSV_MAX_DOF], sl;
    for (int d = 0; d < c->nd; ++d) {
        for (int i = 0; i < c->n; ++i) {
            loadchart_point_pose_chain(c, i, 0, q, &sl);
            x[i] = c->R[i];
            y[i] = (q[d] - c->dof_range[d][0]) / (c->dof_range[d][1] - c->dof_range[d][0]);
        }
        plcol0(LC_COL_DARK + d % LC_NCOL);
        pllsty(1 + (d / LC_NCOL) % 8);
        plwidth(2);
        plline(c->n, x, y);
    }
    pllsty(1);
    plwidth(1);
}

static void draw_chart(void* user) {
    const chart_plot* p = user;
    const loadchart* c = p->c;
    plscmap0n(17);
    plscol0(15, 0, 0, 0);
    plscol0(LC_COL_INSIDE, 165, 155, 140); // warm grey: not the neutral grey of antialiased black lines
    plscol0(LC_COL_HYD, 220, 0, 0);
    plscol0(LC_COL_RATING, 150, 110, 0);
    for (int k = 0; k < LC_NCOL; ++k) {
        plscol0(LC_COL_DARK + k, k_dark[k][0], k_dark[k][1], k_dark[k][2]);
        plscol0(LC_COL_LIGHT + k, k_light[k][0], k_light[k][1], k_light[k][2]);
    }
    plinit();
    pladv(0);
    plschr(0, 0.9);
    // The y range: the hydraulic limit's and the charts' largest values
    // (the stability limits close to the column run to tens of tonnes:
    // clipped).
    double ymax = 0;
    for (int i = 0; i < c->n; ++i) {
        if (isfinite(c->hyd[i])) ymax = fmax(ymax, c->hyd[i]);
        if (isfinite(c->rating[i]) && c->rating[i] < 2 * ymax) ymax = fmax(ymax, c->rating[i]);
    }
    if (!(ymax > 0)) ymax = 1;
    // The plot on the left, its legend in a column of its own on the right
    // (nothing drawn over the curves).
    // A crane chain: the governing pose under the chart (draw_pose).
    plvpor(0.08, 0.68, c->chain ? 0.50 : 0.10, 0.90);
    plwind(c->R[0], c->R[c->n - 1], 0, 1.08 * ymax);
    plcol0(15);
    plbox("bcgnst", 0, 0, "bcgnstv", 0, 0);
    pllab("outreach [m]", "payload [kg]", p->title);
    static PLFLT x[LOADCHART_MAX_POINTS], y[LOADCHART_MAX_POINTS];
    for (int i = 0; i < c->n; ++i) x[i] = c->R[i];
    // 1. The printed chart of each sector, bold, nested widths, from the
    // sector's minimum outreach; closer in (not printed) what the limiter
    // uses there, min(envelope, rating), grey (drawn first), and the minimum
    // outreach marked by a vertical dashed line of the sector's colour.
    for (int s = 0; s < c->nsec; ++s) {
        if (c->imin[s] < 1) continue;
        for (int i = 0; i < c->n; ++i) y[i] = c->cap[(size_t)i * c->nsec + s];
        // Wide, under the thin raw lines (the hydraulic limit often lies on
        // it), and first: a sector's bold chart is never covered by another's
        // inside part.
        plcol0(LC_COL_INSIDE);
        plwidth(6);
        plline(c->imin[s] + 1, x, y);
    }
    for (int s = 0; s < c->nsec; ++s) {
        const int i0 = c->imin[s];
        plcol0(LC_COL_DARK + s % LC_NCOL);
        plwidth(sector_width(s, c->nsec));
        for (int i = 0; i < c->n; ++i) y[i] = c->cap[(size_t)i * c->nsec + s];
        if (c->n - i0 > 1) plline(c->n - i0, x + i0, y + i0);
        PLFLT tx[2] = {c->R[i0], c->R[i0]}, ty[2] = {0, y[i0]};
        plwidth(1.5);
        pllsty(3);
        plline(2, tx, ty);
        pllsty(1);
    }
    plwidth(1);
    // 2. The raw envelope's parts over it, thin and light: each sector's
    // stability limit (the envelope is the lower of it and the hydraulic
    // limit), the model's rating dash-dotted dark gold, the hydraulic limit
    // dashed red last: one line shared by all sectors.
    for (int s = 0; s < c->nsec && c->stab; ++s) {
        plcol0(LC_COL_LIGHT + s % LC_NCOL);
        plwidth(2);
        int n = 0;
        for (int i = 0; i <= c->n; ++i) {
            const double v = i < c->n ? c->stab[(size_t)i * c->nsec + s] : INFINITY;
            if (isfinite(v)) {
                x[n] = c->R[i], y[n] = fmin(v, 2 * ymax), ++n;
            } else { // a gap where the tip is inside the support polygon
                if (n > 1) plline(n, x, y);
                n = 0;
            }
        }
    }
    for (int i = 0; i < c->n; ++i) x[i] = c->R[i];
    if (isfinite(c->rating[0]) || isfinite(c->rating[c->n - 1])) {
        for (int i = 0; i < c->n; ++i) y[i] = fmin(c->rating[i], 2 * ymax);
        plcol0(LC_COL_RATING);
        plwidth(2);
        pllsty(5);
        plline(c->n, x, y);
        pllsty(1);
    }
    for (int i = 0; i < c->n; ++i) y[i] = c->hyd[i];
    plcol0(LC_COL_HYD);
    plwidth(2);
    pllsty(2);
    plline(c->n, x, y);
    pllsty(1);
    plwidth(1);
    // Circles where stability governs a sector's printed chart.
    for (int s = 0; s < c->nsec; ++s)
        for (int i = 0; i < c->n; ++i) {
            const size_t k = (size_t)i * c->nsec + s;
            if (c->gov[k] != LC_GOV_STAB || c->gov_at[k] != i) continue;
            PLFLT px = c->R[i], py = c->chart[k];
            plcol0(LC_COL_DARK + s % LC_NCOL);
            plpoin(1, &px, &py, 4);
        }
    if (c->chain) draw_pose(c);
    // The legend.
    plvpor(0.70, 0.99, 0.10, 0.90);
    plwind(0, 1, 0, 1);
    plschr(0, 0.75);
    double yl = 0.97;
    char nm[96];
    // Up to 6 sectors named (their colours repeat beyond 6).
    const int nleg = c->nsec < LC_NCOL ? c->nsec : LC_NCOL;
    for (int s = 0; s < nleg; ++s, yl -= 0.05) {
        snprintf(nm, sizeof nm, "chart %.0f-%.0f, from %.2f m", c->sec_lo[s] * 180 / M_PI,
                 c->sec_hi[s] * 180 / M_PI, c->R[c->imin[s]]);
        legend_line(yl, LC_COL_DARK + s % LC_NCOL, 1, sector_width(s, c->nsec), nm);
    }
    bool inside = false;
    for (int s = 0; s < c->nsec; ++s) inside = inside || c->imin[s] > 0;
    if (inside) legend_line(yl, LC_COL_INSIDE, 1, 6, "inside it: the limiter's"), yl -= 0.05;
    for (int s = 0; s < nleg && c->stab; ++s, yl -= 0.05) {
        // A stability limit that stays above the plot everywhere says so.
        bool shown = false;
        for (int i = 0; i < c->n; ++i) shown = shown || c->stab[(size_t)i * c->nsec + s] <= 1.08 * ymax;
        snprintf(nm, sizeof nm, shown ? "stability %.0f-%.0f (raw)" : "stability %.0f-%.0f: above", c->sec_lo[s] * 180 / M_PI,
                 c->sec_hi[s] * 180 / M_PI);
        legend_line(yl, LC_COL_LIGHT + s % LC_NCOL, 1, 2, nm);
    }
    if (c->nsec > nleg) {
        snprintf(nm, sizeof nm, "(%d sectors: colours repeat)", c->nsec);
        plcol0(15);
        plptex(0.02, yl, 1, 0, 0, nm), yl -= 0.05;
    }
    legend_line(yl, LC_COL_HYD, 2, 2, "hydraulic limit (raw)"), yl -= 0.05;
    if (isfinite(c->rating[0]) || isfinite(c->rating[c->n - 1])) {
        snprintf(nm, sizeof nm, "rating %.0f kg / %.1f kN m", c->rated_load, c->rated_moment / 1e3);
        legend_line(yl, LC_COL_RATING, 5, 2, nm), yl -= 0.05;
    }
    plcol0(15);
    if (c->stab) plptex(0.02, yl, 1, 0, 0, "o: stability governs"), yl -= 0.05;
    plptex(0.02, yl, 1, 0, 0, "chart: min(raw, rating), from its"), yl -= 0.04;
    plptex(0.02, yl, 1, 0, 0, "peak (vertical: minimum outreach)"), yl -= 0.04;
    plptex(0.02, yl, 1, 0, 0, "outward never rising"), yl = fmin(yl - 0.06, 0.25);
    // The pose panel's lines: each joint by its body and range.
    for (int d = 0; c->chain && d < c->nd; ++d, yl -= 0.045) {
        const double f = c->dof_prismatic[d] ? 1.0 : 180 / M_PI;
        snprintf(nm, sizeof nm, "%s %.3g..%.3g %s", c->dof_name[d], c->dof_range[d][0] * f,
                 c->dof_range[d][1] * f, c->dof_prismatic[d] ? "m" : "deg");
        legend_line(yl, LC_COL_DARK + d % LC_NCOL, 1 + (d / LC_NCOL) % 8, 2, nm);
    }
}

static int plot_chart(const char* png, const loadchart* c, const char* title, char* err, size_t errsz) {
    chart_plot p = {c, title};
    return app_png_render(png, "1200x700", draw_chart, &p, err, errsz);
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
        model_free(m);
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
    if (!(rmin <= rmax)) { // a chain the chart cannot read: loadchart_compute says why
        lo.lo = 0.5, lo.hi = 1.0;
    } else if (!range_given) {
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
    if (!m->chain.two_link && m->chain.nbody > LC_CSV_MAX_DOF) {
        fprintf(stderr, "cranesim loadchart: %s: %d bodies; the chart's output takes at most %d\n", m->file,
                m->chain.nbody, LC_CSV_MAX_DOF);
        model_free(m);
        return EXIT_USAGE;
    }
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
    // Per point: the hydraulic limit with its weakest pose, the stability
    // limit per sector, the model's rating; per sector the raw envelope, the
    // printed chart, what governs it, at which outreach, and the pose to
    // check it by simulation (loadchart_point_pose).
    // A crane chain's poses: every boom joint coordinate, an angle in deg, a
    // slide in m, named by its body.
    fprintf(f, "outreach_m,hydraulic_kg,hyd_cylinder");
    if (ch.chain)
        for (int d = 0; d < ch.nd; ++d) fprintf(f, ",hyd_%s_%s", ch.dof_name[d], ch.dof_prismatic[d] ? "m" : "deg");
    else fprintf(f, ",hyd_q1_deg,hyd_q2_deg");
    for (int s = 0; s < ch.nsec && ch.truck; ++s) {
        fprintf(f, ",stability_s%d_%.0f_%.0fdeg_kg", s, ch.sec_lo[s] * 180 / M_PI, ch.sec_hi[s] * 180 / M_PI);
    }
    fprintf(f, ",rating_kg");
    for (int s = 0; s < ch.nsec; ++s) {
        fprintf(f, ",envelope_s%d_kg,chart_s%d_kg,capacity_s%d_kg,governs_s%d,gov_outreach_s%d_m", s, s, s, s, s);
        if (ch.chain)
            for (int d = 0; d < ch.nd; ++d)
                fprintf(f, ",%s_s%d_%s", ch.dof_name[d], s, ch.dof_prismatic[d] ? "m" : "deg");
        else fprintf(f, ",q1_s%d_deg,q2_s%d_deg", s, s);
        fprintf(f, ",slew_s%d_deg", s);
    }
    fprintf(f, "\n");
    for (int i = 0; i < ch.n; ++i) {
        if (ch.chain) {
            fprintf(f, "%.4f,%.1f,%s", ch.R[i], ch.hyd[i], ch.act_name[ch.hyd_cyl[i]]);
            for (int d = 0; d < ch.nd; ++d) fprintf(f, ",%.4f", pose_value(&ch, d, ch.pose[(size_t)i * ch.nd + d]));
        } else {
            fprintf(f, "%.4f,%.1f,%s,%.3f,%.3f", ch.R[i], ch.hyd[i], ch.hyd_cyl[i] ? "jib" : "lift",
                    ch.hyd_q[i][0] * 180 / M_PI, ch.hyd_q[i][1] * 180 / M_PI);
        }
        for (int s = 0; s < ch.nsec && ch.truck; ++s) {
            const double v = ch.stab[(size_t)i * ch.nsec + s];
            if (isinf(v)) fprintf(f, ",inf");
            else fprintf(f, ",%.1f", v);
        }
        if (isinf(ch.rating[i])) fprintf(f, ",inf");
        else fprintf(f, ",%.1f", ch.rating[i]);
        for (int s = 0; s < ch.nsec; ++s) {
            const size_t k = (size_t)i * ch.nsec + s;
            // Closer than the sector's minimum outreach the chart is not
            // printed (an empty field); the capacity is what the limiter
            // uses there, min(envelope, rating) at that outreach.
            fprintf(f, ",%.1f,", ch.env[k]);
            if (i >= ch.imin[s]) fprintf(f, "%.1f", ch.chart[k]);
            fprintf(f, ",%.1f,%s,%.4f", ch.cap[k], loadchart_gov_name(&ch, ch.gov[k]), ch.R[ch.gov_at[k]]);
            if (ch.chain) {
                double qc[LC_CSV_MAX_DOF], sl;
                loadchart_point_pose_chain(&ch, i, s, qc, &sl);
                for (int d = 0; d < ch.nd; ++d) fprintf(f, ",%.4f", pose_value(&ch, d, qc[d]));
                fprintf(f, ",%.3f", sl * 180 / M_PI);
            } else {
                double q[3];
                loadchart_point_pose(&ch, i, s, q);
                fprintf(f, ",%.3f,%.3f,%.3f", q[0] * 180 / M_PI, q[1] * 180 / M_PI, q[2] * 180 / M_PI);
            }
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
        if (ch.truck)
            snprintf(title, sizeof title, "load chart: truck on outriggers, relief margin %.0f %%, stability factor %.2f",
                     100 * lo.margin, lo.sf);
        else
            snprintf(title, sizeof title, "load chart: no truck, relief margin %.0f %%", 100 * lo.margin);
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
        if (ch.rated_moment > 0 || ch.rated_load > 0)
            printf("  rating (the model's): %.0f kg, %.1f kN m; chart = min(raw envelope, rating), from its peak (the "
                   "minimum outreach) never rising with outreach\n",
                   ch.rated_load, ch.rated_moment / 1e3);
        else
            printf("  no rating in the model (mechanics.rated_load, rated_moment): chart = raw envelope, from its peak "
                   "(the minimum outreach) never rising with outreach\n");
        printf("  minimum outreach:");
        for (int s = 0; s < ch.nsec; ++s)
            printf("%s sector %d %.2f m (%.0f kg)", s ? "," : "", s, ch.R[ch.imin[s]],
                   ch.chart[(size_t)ch.imin[s] * ch.nsec + s]);
        printf("\n");
        const int idx[3] = {0, ch.n / 2, ch.n - 1};
        for (int j = 0; j < 3; ++j) {
            const int i = idx[j];
            printf("  at %.2f m: hydraulic %.0f kg", ch.R[i], ch.hyd[i]);
            for (int s = 0; s < ch.nsec; ++s) {
                const size_t k = (size_t)i * ch.nsec + s;
                if (i < ch.imin[s]) printf(", sector %d inside the minimum outreach: %.0f kg (%s", s, ch.cap[k],
                                           loadchart_gov_name(&ch, ch.gov[k]));
                else printf(", sector %d chart %.0f kg (%s", s, ch.chart[k], loadchart_gov_name(&ch, ch.gov[k]));
                if (ch.gov_at[k] != i) printf(" at %.2f m", ch.R[ch.gov_at[k]]);
                printf(")");
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
