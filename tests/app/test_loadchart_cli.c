// test_loadchart_cli.c: `cranesim loadchart` end to end: the chart's CSV
// against the library's own numbers (hydraulic limit, monotone sectors), and
// bad input (a stability factor <= 1, a margin outside [0, 50 %], an
// outreach the crane cannot reach): one line naming the option, exit 2.
#include "check.h"
#include "cli_util.h"

#include <math.h>

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

// A chart over three sectors: the CSV has its header with units and a row
// per point; the rated capacity never exceeds the hydraulic limit, and the
// side sector (pads 2 m out) is never weaker than over the cab (pads 0.1 m
// ahead of the column).
static void test_chart_csv(void) {
    const int rc = cli_run("loadchart --outreach 1:4:7 --sectors 3 --out lc_ok.csv --quiet", out, sizeof out);
    CHECK(rc == 0, "exit %d: %s", rc, out);
    static char csv[1 << 16];
    CHECK(cli_read_file("lc_ok.csv", csv, sizeof csv) > 0, "no CSV");
    static const char k_head[] = "outreach_m,hydraulic_kg,hyd_cylinder,stability_s0_0_45deg_kg";
    CHECK(strncmp(csv, k_head, sizeof k_head - 1) == 0, "header: %.120s", csv);
    CHECK(cli_count_lines(csv) == 8, "%d lines, expected 8", cli_count_lines(csv));
    char* line = strchr(csv, '\n');
    while (line && line[1]) {
        double R, hyd, s0, s1, s2, r0, r1, r2;
        char cyl[8], g0[16], g1[16], g2[16];
        const int n = sscanf(line + 1, "%lf,%lf,%7[^,],%lf,%lf,%lf,%lf,%15[^,],%lf,%15[^,],%lf,%15[^,\n]", &R, &hyd, cyl,
                             &s0, &s1, &s2, &r0, g0, &r1, g1, &r2, g2);
        CHECK(n == 12, "row not parsed (%d fields): %.100s", n, line + 1);
        if (n == 12) {
            CHECK(r0 <= hyd + 0.05 && r1 <= hyd + 0.05 && r2 <= hyd + 0.05, "rated above hydraulic at %g m", R);
            CHECK(s1 >= s0, "side %g kg weaker than over the cab %g kg at %g m", s1, s0, R);
            CHECK(fabs(r0 - fmin(hyd, s0)) < 0.11, "rated %g != min(%g, %g) at %g m", r0, hyd, s0, R);
        }
        line = strchr(line + 1, '\n');
    }
    remove("lc_ok.csv");
}

int main(int argc, char** argv) {
    RUN_TEST(test_bad_input);
    RUN_TEST(test_chart_csv);
    TEST_MAIN_END();
}
