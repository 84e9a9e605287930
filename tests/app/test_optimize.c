// test_optimize.c: `cranesim optimize` finds an optimum computed by hand
// from the model, treats failing designs as infeasible, and refuses bad
// input with nothing written. Runs the real binary (cli_util.h).
#include "check.h"
#include "cli_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static char out[1 << 16];

#define BORE "hydraulics.components.lift_cyl.bore"

// The value after "<BORE> = " in the optimiser's summary, or NAN.
static double best_bore(const char* text) {
    const char* key = "  " BORE " = ";
    const char* p = strstr(text, key);
    return p ? strtod(p + strlen(key), NULL) : NAN;
}

// Field k of a CSV line as a number.
static double csv_field(const char* line, int k) {
    const char* p = line;
    for (int i = 0; i < k && p; ++i) {
        p = strchr(p, ',');
        if (p) ++p;
    }
    return p ? strtod(p, NULL) : NAN;
}

// Every "bore": value of a model file written by optimize is the shortest
// of 15, 16, 17 significant digits that reads back to the same double (the
// written design reads as a user would type it); the count checked.
static int check_shortest_bores(const char* js) {
    int n = 0;
    for (const char* p = strstr(js, "\"bore\":"); p; p = strstr(p + 1, "\"bore\":")) {
        const char* t = p + strlen("\"bore\":");
        while (*t == ' ' || *t == '\t') ++t;
        char tok[64];
        const size_t L = strcspn(t, ",\n}");
        snprintf(tok, sizeof tok, "%.*s", (int)L, t);
        const double v = strtod(tok, NULL);
        char best[64];
        for (int d = 15; d <= 17; ++d) {
            snprintf(best, sizeof best, "%.*g", d, v);
            if (strtod(best, NULL) == v) break;
        }
        CHECK(!strcmp(tok, best), "bore written as '%s', shortest round trip '%s'", tok, best);
        ++n;
    }
    return n;
}

// The hand solution. On `hold` the crane starts static (the chamber
// pressures that hold the load still) and stays so: the lift cylinder's
// force F = p1A A_A - p1B A_B is set by the load and the pose, not by the
// bore, and the rod side sits at its start pressure. So F comes from one run
// at the model's bore (100 mm, rod 60 mm), and the bore b at which p1A = V
// follows from F = V pi b^2/4 - p1B pi (b^2 - d^2)/4:
//   b^2 = (4 F / pi - p1B d^2) / (V - p1B).
// The smallest bore with peak_p1A <= V is that b (a smaller bore needs more
// pressure). The run's peak is a little above the static value (the start
// settles by 0.1 %), so the optimum agrees to 0.2 % of the bore.
static void test_optimize_finds_hand_bore(void) {
    CHECK(cli_run("run --scenario hold --duration 0.5 --out opt_hold.csv -q", out, sizeof out) == 0, "%s", out);
    static char csv[1 << 20];
    CHECK(cli_read_file("opt_hold.csv", csv, sizeof csv) > 0, "no CSV");
    const char* r0 = strchr(csv, '\n');
    CHECK(r0 && !strncmp(csv, "t,x1,x2,p1A,p1B,", 16), "header %.40s", csv);
    if (!r0) return;
    const double p1A = csv_field(r0 + 1, 3), p1B = csv_field(r0 + 1, 4);
    const double b0 = 0.1, d = 0.06, V = 18e6;
    const double F = p1A * M_PI * b0 * b0 / 4 - p1B * M_PI * (b0 * b0 - d * d) / 4;
    const double b_hand = sqrt((4 * F / M_PI - p1B * d * d) / (V - p1B));
    CHECK(F > 5e4 && b_hand > 0.07 && b_hand < 0.09, "F %g N, bore %g m", F, b_hand);
    unlink("opt_best.json");
    unlink("opt_conv.png");
    const int rc = cli_run("optimize --scenario hold --duration 0.5 --param " BORE "=0.05:0.15 --minimize " BORE
                           " --constraint 'peak_p1A<=18MPa' --out opt_best.json --plot opt_conv.png",
                           out, sizeof out);
    CHECK(rc == 0, "rc %d: %s", rc, out);
    CHECK(strstr(out, "COBYLA") && strstr(out, "optimize: eval 1:"), "%s", out);
    // The progress lines give the constrained pressure in the summary's unit.
    const char* pl = strstr(out, "peak_p1A ");
    const double shown = pl ? strtod(pl + strlen("peak_p1A "), NULL) : NAN;
    CHECK(pl && shown > 5 && shown < 100 && !strncmp(strchr(pl + 9, ' '), " MPa", 4), "progress: %.80s", pl ? pl : out);
    const double b = best_bore(out);
    CHECK(fabs(b - b_hand) <= 2e-3 * b_hand, "optimum %.6g m, by hand %.6g m", b, b_hand);
    // The model file is the model with that bore: a run of it is feasible.
    CHECK(access("opt_best.json", F_OK) == 0, "no model file");
    static char model_js[1 << 16];
    CHECK(cli_read_file("opt_best.json", model_js, sizeof model_js) > 0 && check_shortest_bores(model_js) >= 2,
          "no bores in the written model");
    CHECK(cli_run("run --model opt_best.json --scenario hold --duration 0.5 --out opt_check.csv "
                  "--metrics opt_check.json -q",
                  out, sizeof out) == 0,
          "%s", out);
    static char js[8192];
    CHECK(cli_read_file("opt_check.json", js, sizeof js) > 0, "no metrics");
    const char* p = strstr(js, "\"peak_p1A\": {\"value\": ");
    const double peak = p ? strtod(p + strlen("\"peak_p1A\": {\"value\": "), NULL) : NAN;
    CHECK(peak <= V && peak > 0.99 * V, "peak_p1A of the best model %.9g Pa", peak);
#ifdef CRANESIM_TEST_PLPLOT
    CHECK(access("opt_conv.png", F_OK) == 0, "no convergence plot");
#endif
}

// A range whose lower part the model refuses (a negative bore): those
// designs are infeasible evaluations, the search goes on and finds the
// same optimum as from a clean range. Minimising a metric without
// constraints (BOBYQA): the smallest peak p1A in the range is at its
// largest bore.
static void test_optimize_failing_designs_infeasible(void) {
    int rc = cli_run("optimize --scenario hold --duration 0.3 --param " BORE "=-0.06:0.15 --minimize " BORE
                     " --constraint 'peak_p1A<=18e6Pa' --out opt_fail.json",
                     out, sizeof out);
    CHECK(rc == 0, "rc %d: %s", rc, out);
    CHECK(strstr(out, "failed (exit 2)") && strstr(out, "must be"), "no refused design seen: %s", out);
    const double b = best_bore(out);
    CHECK(b > 0.07 && b < 0.09, "optimum %g m", b);
    rc = cli_run("optimize --scenario hold --duration 0.3 --param " BORE "=0.08:0.12 --minimize peak_p1A "
                 "--out opt_bobyqa.json -q",
                 out, sizeof out);
    CHECK(rc == 0 && strstr(out, "BOBYQA"), "rc %d: %s", rc, out);
    CHECK(fabs(best_bore(out) - 0.12) <= 1e-4, "minimum of peak_p1A at %g m, expected the range's top 0.12", best_bore(out));
}

// Bad input: one line naming the problem, exit 2, nothing written.
static void test_optimize_bad_input(void) {
    static const struct {
        const char* args;
        const char* says;
    } cases[] = {
        {"--param " BORE "=0.05:0.15 --minimize wobble", "wobble"},
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --constraint 'wobble<=1'", "wobble"},
        {"--param " BORE "=0.15:0.05 --minimize " BORE, "above HI"},
        {"--param hydraulics.components.lift_cyl.boar=0.05:0.15 --minimize peak_p1A", "boar"},
        {"--param " BORE "=0.05:0.15 --minimize peak_p3A", "peak_p3A"},
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --constraint 'peak_p1A<20e6'", "METRIC<=V"},
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --constraint 'peak_p1A<=abc'", "finite number"},
        // A pressure needs its unit: 24 meant as MPa would be 24 Pa.
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --constraint 'peak_p1A<=24'", "needs a unit"},
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --constraint 'peak_p1A<=24'", "MPa, kPa, bar, Pa"},
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --constraint 'peak_p1A<=24psi'", "'psi' is not one of"},
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --constraint 'end_stop_hits_lift<=1s'", "plain number"},
        {"--param " BORE "=0.05:0.15 --minimize 'peak_p1A[deg]'", "'deg' is not one of"},
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --maxeval 0", "--maxeval"},
        {"--param " BORE "=0.05:0.15", "--minimize"},
        {"--minimize peak_p1A", "--param"},
        // The parser optimize shares with sweep: a value missing, too many, a bad range.
        {"--param --minimize peak_p1A", "--param needs a value"},
        {"--param " BORE "=0.05:0.15 --minimize " BORE " --out", "--out needs a value"},
        {"--param a=0:1 --param b=0:1 --param c=0:1 --param d=0:1 --param e=0:1 --param f=0:1 --param g=0:1 "
         "--param h=0:1 --param i=0:1 --minimize a",
         "at most 8 --param"},
        {"--param " BORE "=0.05 --minimize " BORE, "expected PATH=LO:HI"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        unlink("opt_bad.json");
        unlink("opt_bad.png");
        char args[1024];
        snprintf(args, sizeof args, "optimize --scenario hold --duration 0.2 %s --out opt_bad.json --plot opt_bad.png",
                 cases[k].args);
        const int rc = cli_run(args, out, sizeof out);
        CHECK(rc == 2 && strstr(out, cases[k].says) && cli_count_lines(out) == 1, "%s: rc %d: %s", cases[k].args,
              rc, out);
        CHECK(access("opt_bad.json", F_OK) != 0 && access("opt_bad.png", F_OK) != 0, "%s: a file was written",
              cases[k].args);
    }
}

#define LOADER10 CRANESIM_TESTDATA "/../../../assets/models/loader10.json"

// The value of metric name in a metrics JSON text, or NAN.
static double json_metric(const char* text, const char* name) {
    char key[160];
    snprintf(key, sizeof key, "\"%s\": {\"value\": ", name);
    const char* p = strstr(text, key);
    return p ? strtod(p + strlen(key), NULL) : NAN;
}

// The hand solution on a crane chain model, by actuator name: loader10 on
// `hold` (lagrange) holds its load still, so the lift cylinder's force
// F = pA A_A - pB A_B (pA_lift, pB_lift of one run at its 140 mm bore, rod
// 84 mm) does not depend on the bore, and the smallest bore whose
// peak_pA.lift (the chain's metric, by name) stays at V is
//   b^2 = (4 F / pi - pB d^2) / (V - pB),
// as for the two-link crane above. The progress lines name the metric and
// give it in MPa; the written model runs to a peak just under V.
static void test_optimize_chain_by_name(void) {
    CHECK(cli_run("run -q --model " LOADER10 " --mechanics lagrange --scenario hold --duration 0.5 --out opt_l10.csv",
                  out, sizeof out) == 0,
          "%s", out);
    static char csv[1 << 20];
    CHECK(cli_read_file("opt_l10.csv", csv, sizeof csv) > 0, "no CSV");
    // The columns by name (the chain's follow the base columns).
    int cA = -1, cB = -1, k = 0;
    for (const char* p = csv; *p && *p != '\n'; ++k) {
        const size_t L = strcspn(p, ",\n");
        if (L == 7 && !strncmp(p, "pA_lift", 7)) cA = k;
        if (L == 7 && !strncmp(p, "pB_lift", 7)) cB = k;
        p += L + (p[L] == ',');
    }
    const char* r0 = strchr(csv, '\n');
    CHECK(r0 && cA > 0 && cB > 0, "no pA_lift, pB_lift columns");
    if (!r0 || cA < 0 || cB < 0) return;
    const double pA = csv_field(r0 + 1, cA), pB = csv_field(r0 + 1, cB);
    const double b0 = 0.14, d = 0.084, V = 8e6;
    const double F = pA * M_PI * b0 * b0 / 4 - pB * M_PI * (b0 * b0 - d * d) / 4;
    const double b_hand = sqrt((4 * F / M_PI - pB * d * d) / (V - pB));
    CHECK(F > 5e4 && b_hand > 0.11 && b_hand < 0.135, "F %g N, bore %g m", F, b_hand);
    unlink("opt_l10_best.json");
    const int rc = cli_run("optimize --model " LOADER10 " --mechanics lagrange --scenario hold --duration 0.5 --param " BORE
                           "=0.10:0.16 --minimize " BORE " --constraint 'peak_pA.lift<=8MPa' --out opt_l10_best.json",
                           out, sizeof out);
    CHECK(rc == 0, "rc %d: %s", rc, out);
    const char* pl = strstr(out, "peak_pA.lift ");
    const double shown = pl ? strtod(pl + strlen("peak_pA.lift "), NULL) : NAN;
    CHECK(pl && shown > 3 && shown < 20 && !strncmp(strchr(pl + 13, ' '), " MPa", 4), "progress: %.80s",
          pl ? pl : out);
    const double b = best_bore(out);
    CHECK(fabs(b - b_hand) <= 2e-3 * b_hand, "optimum %.6g m, by hand %.6g m", b, b_hand);
    printf("  loader10: smallest lift bore for peak_pA.lift <= 8 MPa %.6g m, by hand %.6g m\n", b, b_hand);
    CHECK(cli_run("run -q --model opt_l10_best.json --mechanics lagrange --scenario hold --duration 0.5 --out "
                  "opt_l10_check.csv --metrics opt_l10_check.json",
                  out, sizeof out) == 0,
          "%s", out);
    static char js[1 << 15];
    CHECK(cli_read_file("opt_l10_check.json", js, sizeof js) > 0, "no metrics");
    const double peak = json_metric(js, "peak_pA.lift");
    CHECK(peak <= V && peak > 0.99 * V, "peak_pA.lift of the best model %.9g Pa", peak);
    // A name loader10 does not have: one line, exit 2, nothing written.
    unlink("opt_l10_bad.json");
    const int rc2 = cli_run("optimize --model " LOADER10 " --mechanics lagrange --scenario hold --param " BORE
                            "=0.10:0.16 --minimize " BORE " --constraint 'peak_pA.fold<=8MPa' --out opt_l10_bad.json",
                            out, sizeof out);
    CHECK(rc2 == 2 && cli_count_lines(out) == 1 && strstr(out, "unknown metric 'peak_pA.fold'") &&
              access("opt_l10_bad.json", F_OK) != 0,
          "unknown chain metric: %d %s", rc2, out);
}

int main(int argc, char** argv) {
    RUN_TEST(test_optimize_finds_hand_bore);
    RUN_TEST(test_optimize_failing_designs_infeasible);
    RUN_TEST(test_optimize_bad_input);
    RUN_TEST(test_optimize_chain_by_name);
    TEST_MAIN_END();
}
