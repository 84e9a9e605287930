// test_loadchart_cli.c: `cranesim loadchart` end to end: the chart's CSV
// (raw envelope, the model's rating by hand, the printed chart under both
// and never rising, what governs each point and its pose), its plot's lines
// told apart by colour in the PNG, and bad input (a stability factor <= 1, a
// margin outside [0, 50 %], an outreach the crane cannot reach, a rating out
// of range): one line naming the option or field, exit 2.
#include "check.h"
#include "cli_util.h"

#include <cJSON.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static char out[1 << 16];

static void test_bad_input(void) {
    static const struct {
        const char* args;
        const char* expect;
    } bad[] = {
        {"loadchart --stability-factor 1 --out lc_bad.csv", "--stability-factor"},
        {"loadchart --stability-factor 0.8 --out lc_bad.csv", "--stability-factor"},
        {"loadchart --margin 0.6 --out lc_bad.csv", "--margin"},
        {"loadchart --margin -0.1 --out lc_bad.csv", "--margin"},
        {"loadchart --outreach 1:9:20 --out lc_bad.csv", "outside the crane's reach"},
        {"loadchart --outreach 3:2:20 --out lc_bad.csv", "--outreach"},
        {"loadchart --outreach 1:2 --out lc_bad.csv", "--outreach"},
        {"loadchart --sectors 0 --out lc_bad.csv", "--sectors"},
        {"loadchart --margin abc --out lc_bad.csv", "--margin"},
        {"loadchart --set mechanics.rated_moment=1e5 --out lc_bad.csv", "mechanics.rated_moment: must be in [0.1, 1e4] kN m"},
        {"loadchart --set mechanics.rated_load=-5 --out lc_bad.csv", "mechanics.rated_load: must be > 0"},
    };
    remove("lc_bad.csv");
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        const int rc = cli_run(bad[i].args, out, sizeof out);
        CHECK(rc == 2, "%s: exit %d, expected 2 (%s)", bad[i].args, rc, out);
        CHECK(strstr(out, bad[i].expect) != NULL, "%s: message does not name %s: %s", bad[i].args, bad[i].expect, out);
        CHECK(cli_count_lines(out) == 1, "%s: %d lines, expected one: %s", bad[i].args, cli_count_lines(out), out);
    }
    FILE* f = fopen("lc_bad.csv", "r");
    CHECK(f == NULL, "a refused chart wrote its CSV");
    if (f) fclose(f);
}

// Split a CSV line (in place) into at most max fields; returns the count.
static int split(char* line, char** f, int max) {
    int n = 0;
    char* p = line;
    while (n < max) {
        f[n++] = p;
        p = strchr(p, ',');
        if (!p) break;
        *p++ = '\0';
    }
    return n;
}

// A chart over three sectors: the CSV has its header with units and a row
// per point. Per sector the raw envelope is min(hydraulic, stability); the
// capacity (what the limiter uses) is at or under the envelope and the
// model's rating (2000 kg, 29.4 kN m / (g R), less the 40.72 kg hook); the
// printed chart is empty closer than the minimum outreach (there the
// capacity is min(envelope, rating) itself; at 1.0 m the folded end arm
// holds less than the rating), from there equal to the capacity and never
// rising with outreach; each point names what governs it (lift, jib,
// stability, rated), the outreach where it does (its own closer than the
// minimum outreach, else at or before its own) and a pose that reaches it;
// the side sector (pads 2 m out) is never weaker than over the cab (pads
// 0.1 m ahead of the column).
static void test_chart_csv(void) {
    const int rc = cli_run("loadchart --outreach 1:4:7 --sectors 3 --out lc_ok.csv --quiet", out, sizeof out);
    CHECK(rc == 0, "exit %d: %s", rc, out);
    static char csv[1 << 16];
    CHECK(cli_read_file("lc_ok.csv", csv, sizeof csv) > 0, "no CSV");
    static const char k_head[] =
        "outreach_m,hydraulic_kg,hyd_cylinder,hyd_q1_deg,hyd_q2_deg,stability_s0_0_45deg_kg,stability_s1_45_135deg_kg,"
        "stability_s2_135_180deg_kg,rating_kg,envelope_s0_kg,chart_s0_kg,capacity_s0_kg,governs_s0,gov_outreach_s0_m,"
        "q1_s0_deg,q2_s0_deg,slew_s0_deg,envelope_s1_kg,";
    CHECK(strncmp(csv, k_head, sizeof k_head - 1) == 0, "header: %.300s", csv);
    CHECK(cli_count_lines(csv) == 8, "%d lines, expected 8", cli_count_lines(csv));
    double prev[3] = {INFINITY, INFINITY, INFINITY};
    int inside[3] = {0, 0, 0};
    char* line = strchr(csv, '\n');
    while (line && line[1]) {
        char* next = strchr(line + 1, '\n');
        if (next) *next = '\0';
        char* f[40];
        const int n = split(line + 1, f, 40);
        CHECK(n == 9 + 3 * 8, "row has %d fields, expected 33", n);
        if (n == 33) {
            const double R = atof(f[0]), hyd = atof(f[1]), rating = atof(f[8]);
            const double hand_rating = fmin(2000.0, 29.4e3 / (9.81 * R)) - 40.72;
            CHECK(fabs(rating - hand_rating) < 0.06, "rating %g, hand %g at %g m", rating, hand_rating, R);
            CHECK(atof(f[6]) >= atof(f[5]), "side %s kg weaker than over the cab %s kg at %g m", f[6], f[5], R);
            for (int s = 0; s < 3; ++s) {
                char** g = f + 9 + 8 * s;
                const double env = atof(g[0]), cap = atof(g[2]), at = atof(g[4]);
                const double stab = strcmp(f[5 + s], "inf") ? atof(f[5 + s]) : INFINITY;
                CHECK(fabs(env - fmin(hyd, stab)) < 0.06, "envelope %g != min(%g, %g) at %g m", env, hyd, stab, R);
                CHECK(cap <= env + 0.05 && cap <= rating + 0.05, "capacity %g over envelope %g or rating %g at %g m",
                      cap, env, rating, R);
                if (!g[1][0]) {
                    // Closer than the minimum outreach: not printed, and only
                    // before the chart's first point.
                    CHECK(isinf(prev[s]), "sector %d: chart empty at %g m after it began", s, R);
                    CHECK(fabs(cap - fmin(env, rating)) < 0.06 && fabs(at - R) < 1e-9,
                          "inside at %g m: capacity %g, min(envelope %g, rating %g), governs at %g m", R, cap, env,
                          rating, at);
                    ++inside[s];
                } else {
                    const double chart = atof(g[1]);
                    CHECK(fabs(chart - cap) < 1e-9, "chart %g, capacity %g at %g m", chart, cap, R);
                    CHECK(chart <= prev[s] + 1e-9, "sector %d: chart rises %g -> %g kg at %g m", s, prev[s], chart, R);
                    prev[s] = chart;
                }
                CHECK(!strcmp(g[3], "lift") || !strcmp(g[3], "jib") || !strcmp(g[3], "stability") ||
                          !strcmp(g[3], "rated"),
                      "governs '%s'", g[3]);
                CHECK(at <= R + 1e-9 && at >= 1.0 - 1e-9, "governs at %g m for the point at %g m", at, R);
                // The pose reaches that outreach: L1 sin q1 + L2 sin(q1 + q2).
                const double q1 = atof(g[5]) * M_PI / 180, q2 = atof(g[6]) * M_PI / 180;
                CHECK(fabs(2.3 * sin(q1) + 2.5 * sin(q1 + q2) - at) < 1e-3, "pose (%s, %s) does not reach %g m", g[5],
                      g[6], at);
                const double sl = atof(g[7]);
                CHECK(sl >= 90.0 * s - 45 - 1e-6 && sl <= 90.0 * s + 45 + 1e-6, "slew %g deg outside sector %d", sl, s);
            }
        }
        line = next;
    }
    for (int s = 0; s < 3; ++s)
        CHECK(inside[s] == 1 && isfinite(prev[s]), "sector %d: %d rows inside the minimum outreach, expected 1 (1.0 m)",
              s, inside[s]);
    remove("lc_ok.csv");
}

#ifdef LC_TEST_PLOT
#include <stb/stb_image.h>

// Pixels of the plot area (left of the legend, which sits right of 70 %
// of the width) within 10 per channel of colour c.
static int count_colour(const unsigned char* px, int w, int h, const int c[3]) {
    int n = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < (int)(0.68 * w); ++x) {
            const unsigned char* p = px + 3 * ((size_t)y * w + x);
            if (abs(p[0] - c[0]) <= 10 && abs(p[1] - c[1]) <= 10 && abs(p[2] - c[2]) <= 10) ++n;
        }
    return n;
}

// The plot draws every line so that it shows: on the shipped crane the three
// sectors' printed charts coincide over the whole range (the rating governs
// in every sector from the minimum outreach, 1.07 m) and closer in the
// limiter's capacity lies on the hydraulic limit; each must still have its
// own pixels in the plot area, not only in the legend: the three sector
// colours, the stability limits of the cab and side sectors (light), the
// hydraulic limit (red, dashed), the rating (dark gold) and the capacity
// closer than the minimum outreach (grey, under the hydraulic limit).
static void test_chart_plot_lines_visible(void) {
    remove("lc_plot.png");
    const int rc = cli_run("loadchart --out lc_plot.csv --plot lc_plot.png --quiet", out, sizeof out);
    CHECK(rc == 0, "exit %d: %s", rc, out);
    int w, h, nc;
    unsigned char* px = stbi_load("lc_plot.png", &w, &h, &nc, 3);
    CHECK(px != NULL, "cannot read lc_plot.png");
    if (!px) return;
    static const struct {
        int c[3];
        const char* what;
    } lines[] = {
        {{0, 60, 200}, "chart 0-45 deg"},      {{0, 140, 0}, "chart 45-135 deg"},
        {{190, 0, 190}, "chart 135-180 deg"},  {{140, 175, 255}, "stability 0-45 deg"},
        {{130, 220, 130}, "stability 45-135 deg"}, {{220, 0, 0}, "hydraulic limit"},
        {{150, 110, 0}, "rating"},             {{165, 155, 140}, "inside min. outreach"},
    };
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; ++i) {
        const int n = count_colour(px, w, h, lines[i].c);
        printf("  %-22s %6d pixels in the plot area\n", lines[i].what, n);
        CHECK(n >= 200, "%s: only %d pixels of its colour in the plot area: hidden", lines[i].what, n);
    }
    stbi_image_free(px);
    remove("lc_plot.png");
    remove("lc_plot.csv");
}
#endif

// A crane chain (loader10, docs/safety.md "On a crane chain"): the CSV names
// every joint coordinate of the governing poses by body (deg or m) and the
// governing actuator by name; the rating by hand (4000 kg, 98 kN m / (g R));
// each pose within its joint's limits; the chart never rising from its
// minimum outreach. What the search cannot read is refused in one line.
#define WDATA CRANESIM_TESTDATA "/../../world/data"

// lo, hi: the limits of the CSV's four pose columns (lifting_arm,
// knuckle_arm deg; ext1, ext2 m) from the model file's bodies, by name and
// joint kind. false (a failed check) when the file does not give them.
static bool chain_limits(const char* path, double lo[4], double hi[4]) {
    static char text[1 << 16];
    FILE* fp = fopen(path, "rb");
    CHECK(fp != NULL, "cannot open %s", path);
    if (!fp) return false;
    const size_t n = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[n] = '\0';
    cJSON* root = cJSON_Parse(text);
    CHECK(root != NULL, "%s: not JSON", path);
    const cJSON* bodies =
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "mechanics"), "bodies");
    static const char* const names[4] = {"lifting_arm", "knuckle_arm", "ext1", "ext2"};
    int found = 0;
    const cJSON* b;
    cJSON_ArrayForEach(b, bodies) {
        const cJSON* name = cJSON_GetObjectItemCaseSensitive(b, "name");
        const cJSON* lim = cJSON_GetObjectItemCaseSensitive(b, "limits");
        const cJSON* joint = cJSON_GetObjectItemCaseSensitive(b, "joint");
        for (int d = 0; d < 4; ++d)
            if (cJSON_IsString(name) && !strcmp(name->valuestring, names[d]) && cJSON_GetArraySize(lim) == 2) {
                // Revolute limits in rad, the CSV's angles in deg; prismatic in m both.
                const double k =
                    cJSON_IsString(joint) && !strcmp(joint->valuestring, "prismatic") ? 1.0 : 180 / M_PI;
                lo[d] = cJSON_GetArrayItem(lim, 0)->valuedouble * k;
                hi[d] = cJSON_GetArrayItem(lim, 1)->valuedouble * k;
                found |= 1 << d;
            }
    }
    cJSON_Delete(root);
    CHECK(found == 15, "%s: limits of lifting_arm, knuckle_arm, ext1, ext2 (found mask %d)", path, found);
    return found == 15;
}
static void test_chain_csv(void) {
    const int rc = cli_run("loadchart --model loader10 --world validation --outreach 1:7:7 --out lc_chain.csv --quiet",
                           out, sizeof out);
    CHECK(rc == 0, "exit %d: %s", rc, out);
    static char csv[1 << 16];
    CHECK(cli_read_file("lc_chain.csv", csv, sizeof csv) > 0, "no CSV");
    static const char k_head[] =
        "outreach_m,hydraulic_kg,hyd_cylinder,hyd_lifting_arm_deg,hyd_knuckle_arm_deg,hyd_ext1_m,hyd_ext2_m,rating_kg,"
        "envelope_s0_kg,chart_s0_kg,capacity_s0_kg,governs_s0,gov_outreach_s0_m,lifting_arm_s0_deg,knuckle_arm_s0_deg,"
        "ext1_s0_m,ext2_s0_m,slew_s0_deg\n";
    CHECK(strncmp(csv, k_head, sizeof k_head - 1) == 0, "header: %.400s", csv);
    CHECK(cli_count_lines(csv) == 8, "%d lines, expected 8", cli_count_lines(csv));
    // The joints' limits as the model file gives them (mechanics.bodies[].limits,
    // rad or m), in the CSV's units (deg or m): the model changes (the jib's
    // linkage moved the knuckle's range) and the test follows it.
    double lo[4], hi[4];
    if (!chain_limits(CRANESIM_ASSETS "/models/loader10.json", lo, hi)) return;
    double prev = INFINITY;
    char* line = strchr(csv, '\n');
    int nrow = 0;
    while (line && line[1]) {
        char* next = strchr(line + 1, '\n');
        if (next) *next = '\0';
        char* f[40];
        const int n = split(line + 1, f, 40);
        CHECK(n == 18, "row has %d fields, expected 18", n);
        if (n == 18) {
            ++nrow;
            const double R = atof(f[0]), rating = atof(f[7]);
            CHECK(fabs(rating - fmin(4000.0, 98e3 / (9.81 * R))) < 0.06, "rating %g at %g m", rating, R);
            CHECK(!strcmp(f[2], "lift") || !strcmp(f[2], "jib") || !strcmp(f[2], "ext1") || !strcmp(f[2], "ext2"),
                  "hyd_cylinder %s", f[2]);
            CHECK(!strcmp(f[11], "rated") || !strcmp(f[11], "lift") || !strcmp(f[11], "jib") ||
                      !strcmp(f[11], "ext1") || !strcmp(f[11], "ext2"),
                  "governs %s at %g m", f[11], R);
            for (int d = 0; d < 4; ++d) {
                const double v = atof(f[3 + d]), w = atof(f[13 + d]);
                CHECK(v >= lo[d] - 1e-3 && v <= hi[d] + 1e-3 && w >= lo[d] - 1e-3 && w <= hi[d] + 1e-3,
                      "pose %d: %g, %g outside [%g, %g] at %g m", d, v, w, lo[d], hi[d], R);
            }
            if (f[9][0]) {
                CHECK(atof(f[9]) <= prev + 1e-9, "the chart rises to %s at %g m", f[9], R);
                prev = atof(f[9]);
            }
        }
        line = next;
    }
    CHECK(nrow == 7 && isfinite(prev), "%d rows, chart printed: %d", nrow, isfinite(prev));
    remove("lc_chain.csv");
    static const struct {
        const char* args;
        const char* expect;
    } bad[] = {
        {"loadchart --model " WDATA "/chain_8fn_10link.json --out lc_bad.csv", "load chart: the search over every joint"},
        {"loadchart --model " WDATA "/hiab031_chain.json --out lc_bad.csv", "limits: the load chart searches every pose"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        const int r2 = cli_run(bad[i].args, out, sizeof out);
        CHECK(r2 == 2 && strstr(out, bad[i].expect) && cli_count_lines(out) == 1, "%s: exit %d: %s", bad[i].args, r2,
              out);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_bad_input);
    RUN_TEST(test_chain_csv);
    RUN_TEST(test_chart_csv);
#ifdef LC_TEST_PLOT
    RUN_TEST(test_chart_plot_lines_visible);
#endif
    TEST_MAIN_END();
}
