// test_replay.c: `cranesim drive --session` and `cranesim replay`: a replay of
// an unchanged design reproduces the recorded CSV byte for byte (sandbox,
// lagrange, with a fault event); a larger lift bore lowers the holding
// pressure as the force balance says; bad sessions are refused with exit 2
// and nothing written.
#include "check.h"
#include "cli_util.h"

#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char out[1 << 16];
static char a[1 << 22], b[1 << 22];

// Record a headless drive (args) with a session and a record, replay it and
// compare the CSVs byte for byte.
static void check_bit_for_bit(const char* what, const char* args) {
    char cmd[2048];
    unlink("rp_rec.csv");
    unlink("rp_rep.csv");
    snprintf(cmd, sizeof cmd, "drive --headless --quiet %s --record rp_rec.csv --session rp.session", args);
    int rc = cli_run(cmd, out, sizeof out);
    CHECK(rc == 0, "%s: drive exit %d: %s", what, rc, out);
    rc = cli_run("replay rp.session --quiet --out rp_rep.csv", out, sizeof out);
    CHECK(rc == 0, "%s: replay exit %d: %s", what, rc, out);
    CHECK(strstr(out, "(bit for bit)") != NULL, "%s: replay did not say its rows are identical: %s", what, out);
    long na = cli_read_file("rp_rec.csv", a, sizeof a), nb = cli_read_file("rp_rep.csv", b, sizeof b);
    CHECK(na > 1000 && na == nb && !memcmp(a, b, (size_t)na), "%s: record %ld bytes, replay %ld bytes, differ", what,
          na, nb);
}

// The value of CSV column name in data row k (0-based) of text.
static double csv_value(const char* text, const char* name, int k) {
    const char* nl = strchr(text, '\n');
    int col = -1, c = 0;
    for (const char* p = text; p < nl; ++c) {
        const char* e = strpbrk(p, ",\n");
        if ((size_t)(e - p) == strlen(name) && !strncmp(p, name, (size_t)(e - p))) col = c;
        p = e + 1;
    }
    const char* p = nl + 1;
    for (int i = 0; i < k && p; ++i) p = strchr(p, '\n'), p = p ? p + 1 : NULL;
    for (int i = 0; i < col && p; ++i) p = strchr(p, ','), p = p ? p + 1 : NULL;
    return col >= 0 && p ? strtod(p, NULL) : NAN;
}

// The holding pressure on a bigger bore, by hand: the cylinder force that
// holds the boom, F1, is the load's and the booms' moment over the lever and
// does not depend on the bore (the pose and the load are the same), so
//   p1A' = (F1 + p1B' A_B') / A_A',  A_A' = pi d'^2 / 4,  A_B' = pi (d'^2 - rod^2) / 4
// with F1 read from the recorded design's first row.
static void check_bigger_bore(void) {
    int rc = cli_run("drive --headless --quiet --mechanics lagrange --scenario hold --duration 1 --frame-rate 100 "
                     "--record rp_hold.csv --session rp_hold.session",
                     out, sizeof out);
    CHECK(rc == 0, "hold drive exit %d: %s", rc, out);
    rc = cli_run("replay rp_hold.session --quiet --set hydraulics.components.lift_cyl.bore=0.11 --out rp_hold11.csv "
                 "--metrics rp_hold11.json",
                 out, sizeof out);
    CHECK(rc == 0, "replay exit %d: %s", rc, out);
    CHECK(strstr(out, "changed design") != NULL, "the summary does not say the design changed: %s", out);
    CHECK(cli_read_file("rp_hold.csv", a, sizeof a) > 0 && cli_read_file("rp_hold11.csv", b, sizeof b) > 0,
          "csv files");
    const double F1 = csv_value(a, "F1", 0), p1A0 = csv_value(a, "p1A", 0);
    const double d = 0.11, rod = 0.06;
    const double AA = M_PI * d * d / 4, AB = M_PI * (d * d - rod * rod) / 4;
    const double p1B = csv_value(b, "p1B", 0), p1A = csv_value(b, "p1A", 0);
    const double hand = (F1 + p1B * AB) / AA;
    CHECK(p1A < p1A0, "a bigger bore did not lower the holding pressure: %.6g -> %.6g Pa", p1A0, p1A);
    CHECK(fabs(p1A - hand) < 0.01 * hand, "p1A on the 110 mm bore %.6g Pa, the force balance gives %.6g Pa", p1A, hand);
    // The peak over the run (the metrics) follows: about (0.1/0.11)^2 of the old one.
    char js[4096];
    CHECK(cli_read_file("rp_hold11.json", js, sizeof js) > 0, "metrics json");
    const char* pk = strstr(js, "\"peak_p1A\"");
    const double peak = pk ? strtod(strstr(pk, "\"value\":") + 8, NULL) : NAN;
    CHECK(fabs(peak - hand) < 0.02 * hand, "peak_p1A %.6g Pa, hand %.6g Pa", peak, hand);
}

// The largest cut of the jib command over the rows of a record: the
// operator's 1.0 less the u2_cmd the engine was given [-] (0: never cut).
static double jib_cut(const char* csv, int nrow) {
    double cut = 0;
    for (int k = 0; k < nrow; ++k) {
        const double t = csv_value(csv, "t", k), u = csv_value(csv, "u2_cmd", k);
        if (t > 0.25 && isfinite(u)) cut = fmax(cut, 1.0 - u);
    }
    return cut;
}

// A drive in which the rated capacity limiter acted (1300 kg at the tip, the
// jib out at full command in the validation world: the limiter stops it
// within 0.5 s) replays bit for bit, the limiter included; on a changed
// design the replay runs the same limiter (it cuts the same operator input
// there too); a session without the limiter's setting (written before it was
// recorded) replays with the limiter on and says so; --rcl off replays
// without it.
static void check_limiter_replay(void) {
    const char* args = "--world validation --scenario " CRANESIM_TESTDATA "/rcl_overload.json --duration 2 "
                       "--frame-rate 100";
    check_bit_for_bit("limiter acting", args);
    long na = cli_read_file("rp_rec.csv", a, sizeof a);
    const double cut = na > 0 ? jib_cut(a, 200) : 0;
    printf("  limiter acting: the jib command was cut by up to %.2f in the recorded drive\n", cut);
    CHECK(cut > 0.5, "the limiter did not act in the recorded drive (cut %.2f): the test shows nothing", cut);
    CHECK(strstr(out, "rated capacity limiter on, as recorded") != NULL, "replay does not name the limiter: %s", out);
    // A changed design: the same limiter cuts the same demand.
    int rc = cli_run("replay rp.session --quiet --set hydraulics.components.lift_cyl.bore=0.105 --out rp_rep2.csv", out,
                     sizeof out);
    CHECK(rc == 0, "changed design: exit %d: %s", rc, out);
    long nb = cli_read_file("rp_rep2.csv", b, sizeof b);
    const double cut2 = nb > 0 ? jib_cut(b, 200) : 0;
    printf("  changed design: cut by up to %.2f\n", cut2);
    CHECK(cut2 > 0.5, "the replay on a changed design ran without the limiter (cut %.2f)", cut2);
    // --rcl off: the operator's full command reaches the engine.
    rc = cli_run("replay rp.session --quiet --rcl off --out rp_rep3.csv", out, sizeof out);
    CHECK(rc == 0 && strstr(out, "rated capacity limiter off (--rcl; recorded on)"), "--rcl off: exit %d: %s", rc, out);
    nb = cli_read_file("rp_rep3.csv", b, sizeof b);
    CHECK(nb > 0 && jib_cut(b, 200) == 0, "--rcl off: the jib command was still cut by %.2f", jib_cut(b, 200));
    // An older session: no "rcl" in its settings. It replays with the
    // limiter on (drive's default), here bit for bit, and says so.
    na = cli_read_file("rp.session", a, sizeof a);
    char* key = na > 0 ? strstr(a, ",\"rcl\":true") : NULL;
    CHECK(key != NULL, "the session does not record the limiter's setting");
    if (key) {
        memmove(key, key + 11, strlen(key + 11) + 1);
        CHECK(cli_write_file("rp_old.session", a) == 0, "write");
        rc = cli_run("replay rp_old.session --quiet", out, sizeof out);
        CHECK(rc == 0 && strstr(out, "(bit for bit)") && strstr(out, "does not record its setting"),
              "old session: exit %d: %s", rc, out);
    }
}

// Bad input: one line, exit 2, no output file.
static void check_refused(const char* what, const char* session_text, const char* want) {
    CHECK(cli_write_file("rp_bad.session", session_text) == 0, "write");
    unlink("rp_bad.csv");
    int rc = cli_run("replay rp_bad.session --out rp_bad.csv", out, sizeof out);
    CHECK(rc == 2, "%s: exit %d: %s", what, rc, out);
    CHECK(cli_count_lines(out) == 1 && strstr(out, want), "%s: expected one line with '%s', got: %s", what, want, out);
    CHECK(access("rp_bad.csv", F_OK) != 0, "%s: an output was written", what);
}

static void check_bad_sessions(void) {
    int rc = cli_run("replay no_such.session --out rp_bad.csv", out, sizeof out);
    CHECK(rc == 2 && cli_count_lines(out) == 1 && strstr(out, "no_such.session: cannot read"), "unreadable: %d %s", rc,
          out);
    check_refused("not a session", "t,x1\n0,1\n", "not a cranesim session file");
    check_refused("version", "cranesim-session 99\n{}\n", "format version 99");
    // A recorded session with one value of its model changed: the hash no longer matches.
    long n = cli_read_file("rp_hold.session", a, sizeof a);
    CHECK(n > 0, "hold session");
    char* bore = strstr(a, "\"bore\":0.1,");
    CHECK(bore != NULL, "no bore in the session's model");
    if (bore) {
        memcpy(bore, "\"bore\":0.2,", 11);
        check_refused("model hash", a, "model_hash");
    }
    // A backend this build does not have (a newer build's, a corrupt file):
    // refused by name, never replayed on another.
    n = cli_read_file("rp_hold.session", a, sizeof a);
    char* mech = n > 0 ? strstr(a, "\"sim\":{\"mechanics\":") : NULL;
    CHECK(mech && (mech[19] == '0' || mech[19] == '1') && mech[20] == ',', "no sim.mechanics in the session");
    if (mech && mech[20] == ',') {
        mech[19] = '7';
        check_refused("backend", a, "header: sim.mechanics: 7 names no backend (known: lagrange, ode)");
    }
}

// compare on two designs: its CSV of both holds each design's own run rows
// (as `run` writes them), and the bigger bore's peak is the lower one.
static void check_compare_designs(void) {
    const char* bore = "hydraulics.components.lift_cyl.bore=0.11";
    char cmd[1024];
    int rc = cli_run("run --quiet --scenario hold --out cd_a.csv", out, sizeof out);
    CHECK(rc == 0, "run A: %s", out);
    snprintf(cmd, sizeof cmd, "run --quiet --scenario hold --set %s --out cd_b.csv", bore);
    rc = cli_run(cmd, out, sizeof out);
    CHECK(rc == 0, "run B: %s", out);
    snprintf(cmd, sizeof cmd, "compare --quiet --scenario hold --set-b %s --out cd_both.csv", bore);
    rc = cli_run(cmd, out, sizeof out);
    CHECK(rc == 0, "compare: %d %s", rc, out);
    const char* pk = strstr(out, "peak_p1A [MPa]");
    double pa = NAN, pb = NAN, dd = NAN;
    CHECK(pk && sscanf(pk + 14, "%lg %lg %lg", &pa, &pb, &dd) == 3, "no peak_p1A line: %s", out);
    CHECK(pb < pa && fabs(dd - (pb - pa)) < 1e-5 * pa, "peak_p1A A %.6g, B %.6g, B - A %.6g MPa", pa, pb, dd);
    static char both[1 << 23];
    CHECK(cli_read_file("cd_a.csv", a, sizeof a) > 0 && cli_read_file("cd_b.csv", b, sizeof b) > 0 &&
              cli_read_file("cd_both.csv", both, sizeof both) > 0,
          "csv files");
    for (int k = 0; k <= 10000; k += 2500) {
        CHECK(csv_value(both, "p1A_A", k) == csv_value(a, "p1A", k), "row %d: p1A_A", k);
        CHECK(csv_value(both, "p1A_B", k) == csv_value(b, "p1A", k), "row %d: p1A_B", k);
        CHECK(csv_value(both, "x1_B", k) == csv_value(b, "x1", k), "row %d: x1_B", k);
    }
    // The same design twice differs by nothing.
    rc = cli_run("compare --quiet --scenario hold --set-a mechanics.load_mass=800 --set-b mechanics.load_mass=800",
                 out, sizeof out);
    pk = strstr(out, "peak_p1A [MPa]");
    CHECK(rc == 0 && pk && sscanf(pk + 14, "%lg %lg %lg", &pa, &pb, &dd) == 3 && dd == 0, "same design: %s", out);
    // Bad input: one line, exit 2, nothing written.
    unlink("cd_bad.csv");
    rc = cli_run("compare --scenario hold --set-b hydraulics.components.lift_cyl.bor=0.11 --out cd_bad.csv", out,
                 sizeof out);
    CHECK(rc == 2 && cli_count_lines(out) == 1 && strstr(out, "design B") && access("cd_bad.csv", F_OK) != 0,
          "a typo in --set-b: %d %s", rc, out);
    rc = cli_run("compare --model a.json --model b.json --model c.json", out, sizeof out);
    CHECK(rc == 2 && cli_count_lines(out) == 1 && strstr(out, "at most two"), "three models: %d %s", rc, out);
}

int main(void) {
    check_compare_designs();
    check_bit_for_bit("sandbox", "--duration 1.5 --frame-rate 200");
    check_bit_for_bit("lagrange", "--mechanics lagrange --duration 1");
    // The burst at t = 2 s (a fault event the replay applies at the same ticks).
    check_bit_for_bit("lagrange hose burst", "--mechanics lagrange --scenario hose_burst --duration 2.5 --frame-rate 100");
    check_limiter_replay();
    check_bigger_bore();
    check_bad_sessions();
    TEST_MAIN_END();
}
