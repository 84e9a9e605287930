// test_plots.c: the plots' layout, read back from the PNGs they write
// (stb_image) and from the label placement (pure): a trace plot's title is
// whole on the page, the heat map has a colour bar and its title clear of
// the map, the work-precision plot's labels do not overlap.
#include "app.h"
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <stb/stb_image.h>

typedef struct image {
    unsigned char* px;
    int w, h;
} image;

static bool load(const char* path, image* im) {
    int n;
    im->px = stbi_load(path, &im->w, &im->h, &n, 3);
    return im->px != NULL;
}

static const unsigned char* at(const image* im, int x, int y) { return im->px + 3 * ((size_t)y * im->w + x); }
// Ink: text and lines (dark grey to black).
static bool dark(const image* im, int x, int y) {
    const unsigned char* p = at(im, x, y);
    return p[0] < 110 && p[1] < 110 && p[2] < 110;
}
// A colour of the heat map's scale (saturated), not text or background.
static bool coloured(const image* im, int x, int y) {
    const unsigned char* p = at(im, x, y);
    const int mx = p[0] > p[1] ? (p[0] > p[2] ? p[0] : p[2]) : (p[1] > p[2] ? p[1] : p[2]);
    const int mn = p[0] < p[1] ? (p[0] < p[2] ? p[0] : p[2]) : (p[1] < p[2] ? p[1] : p[2]);
    return mx - mn > 120;
}

// A run's traces with a ramp on every column, t from 0 to 4 s.
static sim_trace ramp_trace(double k) {
    sim_trace tr = {0};
    tr.nrow = tr.cap = 200;
    tr.v = calloc((size_t)tr.nrow * SIM_NCOL, sizeof *tr.v);
    for (int i = 0; i < tr.nrow && tr.v; ++i) {
        double* r = tr.v + (size_t)i * SIM_NCOL;
        const double t = 4.0 * i / (tr.nrow - 1);
        for (int c = 0; c < SIM_NCOL; ++c) r[c] = k * (1 + c) * (0.1 + 0.01 * t);
        r[COL_T] = t;
        r[COL_P1A] = r[COL_P1B] = r[COL_P2A] = r[COL_P2B] = 1e6 * (1 + k * t);
    }
    return tr;
}

// The title of a compare or replay plot spans the page, centred, whole: it
// was set over the first of four panels and ran off both sides of the page
// (a replay's "Cylinder strokes - replay of ...: recorded vs changed
// design"). Checked on a title of 60 and one of 180 characters.
static void test_trace_title_whole(void) {
    sim_trace a = ramp_trace(1), b = ramp_trace(1.1);
    const char* titles[] = {"replay of /tmp/sessions/pick.session: recorded vs changed design",
                            "replay of /tmp/a_rather_long_folder_name_for_sessions/another_long_folder_name_for_the_test"
                            "/yet_more_text_here/pick_and_place_session.session: recorded vs changed design"};
    for (int t = 0; t < 2; ++t) {
        char err[256];
        CHECK(app_plot_compare(&a, "recorded", &b, "replay", titles[t], t == 1, "test_plots_traces.png", err,
                               sizeof err) ==
                  0,
              "%s", err);
        image im;
        CHECK(load("test_plots_traces.png", &im), "cannot read test_plots_traces.png");
        if (!im.px) continue;
        // The title's ink: the top rows down to the first blank band.
        int x0 = im.w, x1 = -1, y = 0, seen = 0;
        for (; y < im.h / 8; ++y) {
            int row = 0;
            for (int x = 0; x < im.w; ++x)
                if (dark(&im, x, y)) {
                    row = 1;
                    if (x < x0) x0 = x;
                    if (x > x1) x1 = x;
                }
            if (row) seen = 1;
            else if (seen) break;
        }
        CHECK(seen, "no title ink at the top of the page");
        CHECK(x0 >= 3 && x1 <= im.w - 4, "title %d cut by the page: ink from x = %d to %d of %d px", t, x0, x1, im.w);
        CHECK(fabs(0.5 * (x0 + x1) - 0.5 * im.w) < 0.03 * im.w, "title %d not centred: %d..%d of %d px", t, x0, x1,
              im.w);
        stbi_image_free(im.px);
    }
    free(a.v);
    free(b.v);
}

// The heat map: a colour bar beside the map (a narrow coloured strip apart
// from it, graded top to bottom: many colours down one column), and the
// title's ink ends above the map. The old map had no bar, and its second
// title line (the range in words) sat on the map's top edge.
static void test_heat_map_colour_bar(void) {
    enum { NX = 5, NY = 3 };
    double z[NX * NY];
    for (int i = 0; i < NX; ++i)
        for (int j = 0; j < NY; ++j) z[i * NY + j] = 13.5 + 1.9 * (NX - 1 - i) + 0.3 * j;
    char err[256];
    CHECK(app_plot_heat("test_plots_heat.png", "ramp: peak_p1A [MPa]", "hydraulics.components.lift_cyl.bore",
                        "hydraulics.components.jib_cyl.bore", z, NX, NY, 0.08, 0.12, 0.07, 0.09, err, sizeof err) == 0,
          "%s", err);
    image im;
    CHECK(load("test_plots_heat.png", &im), "cannot read test_plots_heat.png");
    if (!im.px) return;
    // Columns with coloured pixels, in runs: the map, then the bar.
    int run0[8], run1[8], nrun = 0, in = 0;
    for (int x = 0; x < im.w; ++x) {
        int n = 0;
        for (int y = 0; y < im.h; ++y) n += coloured(&im, x, y);
        if (n > im.h / 4 && !in && nrun < 8) run0[nrun] = x, in = 1;
        if (n <= im.h / 4 && in) run1[nrun++] = x - 1, in = 0;
    }
    if (in && nrun < 8) run1[nrun++] = im.w - 1;
    CHECK(nrun == 2, "%d coloured column runs (want the map and its colour bar)", nrun);
    if (nrun == 2) {
        CHECK(run1[0] - run0[0] > 10 * (run1[1] - run0[1]), "map %d..%d, bar %d..%d px", run0[0], run1[0], run0[1],
              run1[1]);
        // Down the bar's middle column: a gradient of many colours.
        const int xb = (run0[1] + run1[1]) / 2;
        int distinct = 0;
        const unsigned char* prev = NULL;
        for (int y = 0; y < im.h; ++y) {
            if (!coloured(&im, xb, y)) continue;
            const unsigned char* p = at(&im, xb, y);
            if (!prev || memcmp(prev, p, 3)) ++distinct;
            prev = p;
        }
        CHECK(distinct >= 50, "the bar holds %d colours down its middle", distinct);
        // The map's top row, and the title's ink above it over the map's width.
        int top = -1;
        for (int y = 0; y < im.h && top < 0; ++y)
            if (coloured(&im, (run0[0] + run1[0]) / 2, y)) top = y;
        // The frame's own line takes the 3 rows above the cells.
        int ink_bottom = -1;
        for (int y = 0; y < top - 3; ++y)
            for (int x = run0[0] + 3; x <= run1[0] - 3; ++x)
                if (dark(&im, x, y)) ink_bottom = y;
        CHECK(top > 0 && ink_bottom >= 0 && ink_bottom < top - 10, "title ink down to row %d, map from row %d",
              ink_bottom, top);
    }
    stbi_image_free(im.px);
}

// The work-precision plot's labels: a cluster like the study of `ramp`
// (ROS34PW2 and RODAS3 on top of each other at 1, 2 and 5 per decade, 7 and
// 9 points within 1.5 decades, CVODE beside them) placed by
// app_place_labels: no two labels overlap, none covers a point, all inside
// the plot, and a label without a leader line sits beside its point.
static void test_labels_apart(void) {
    enum { N = 30 };
    double px[N], py[N];
    app_label l[N + 1];
    // The legend's box, bottom left (fixed), in mm as the plot has it.
    l[0] = (app_label){.w = 80, .h = 25, .lx = 63, .ly = 52, .just = 0};
    int n = 0;
    for (int f = 0; f < 3; ++f)
        for (int k = 0; k < 10; ++k, ++n) {
            // Along a falling line, the families 2 mm apart: ~7 mm between points.
            px[n] = 230 + 6.0 * k + 2.0 * f;
            py[n] = 150 - 5.5 * k + (f == 2 ? 40 : 1.5 * f);
            l[n + 1] = (app_label){.x = px[n], .y = py[n], .w = (0.62 * 6 + 0.4) * 3.5, .h = 1.3 * 3.5};
        }
    const double area[4] = {58, 36, 387, 264};
    const int failed = app_place_labels(l, 1, N + 1, area, px, py, N, 0.6 * 3.5);
    CHECK(failed == 0, "%d labels could not be placed apart", failed);
    for (int i = 1; i <= N; ++i) {
        for (int j = 0; j < i; ++j)
            CHECK(app_label_overlap(&l[i], &l[j]) == 0, "labels %d and %d overlap by %.3g mm^2", i, j,
                  app_label_overlap(&l[i], &l[j]));
        const double b0 = l[i].lx - l[i].just * l[i].w, b1 = l[i].ly - 0.5 * l[i].h;
        CHECK(b0 >= area[0] && b0 + l[i].w <= area[2] && b1 >= area[1] && b1 + l[i].h <= area[3],
              "label %d outside the plot", i);
        for (int k = 0; k < N; ++k)
            CHECK(!(px[k] + 2.1 > b0 && px[k] - 2.1 < b0 + l[i].w && py[k] + 2.1 > b1 && py[k] - 2.1 < b1 + l[i].h),
                  "label %d covers point %d", i, k);
        // A label without a leader sits beside its point: its box within a
        // marker radius and one label height of it.
        const double nx = fmin(fmax(l[i].x, b0), b0 + l[i].w), ny = fmin(fmax(l[i].y, b1), b1 + l[i].h);
        const double d = hypot(nx - l[i].x, ny - l[i].y);
        CHECK(l[i].leader || d <= 2.1 + 1.01 * l[i].h, "label %d, no leader, %.1f mm from its point", i, d);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_trace_title_whole);
    RUN_TEST(test_heat_map_colour_bar);
    RUN_TEST(test_labels_apart);
    TEST_MAIN_END();
}
