// test_replay.c: `cranesim drive --session` and `cranesim replay`: a replay of
// an unchanged design reproduces the recorded CSV byte for byte (sandbox,
// lagrange, with a fault event, a crane chain of 8 functions); a larger lift
// bore lowers the holding pressure as the force balance says; a session
// written by the previous format (version 1, by an older cranesim) replays
// unchanged; a chain replays by function name; bad sessions are refused with
// exit 2 and nothing written.
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

#define CHAIN_8FN CRANESIM_TESTDATA "/../../world/data/chain_8fn_10link.json"
#define LOADER10 CRANESIM_TESTDATA "/../../../assets/models/loader10.json"

// The column of CSV text whose header names name, or -1.
static int csv_col(const char* text, const char* name) {
    const char* nl = strchr(text, '\n');
    int c = 0;
    for (const char* p = text; nl && p < nl; ++c) {
        const char* e = strpbrk(p, ",\n");
        if ((size_t)(e - p) == strlen(name) && !strncmp(p, name, (size_t)(e - p))) return c;
        p = e + 1;
    }
    return -1;
}

// Sessions written by the previous format (version 1: three commands, lift,
// jib, slew, per tick), recorded by main's cranesim before the format named
// its functions, with the drive's record beside them: each replays to the
// same CSV, byte for byte.
static void check_old_format(const char* name) {
    char cmd[1024], rec[512];
    snprintf(cmd, sizeof cmd, "replay %s/session_v1_%s.session --quiet --out rp_v1.csv", CRANESIM_TESTDATA, name);
    snprintf(rec, sizeof rec, "%s/session_v1_%s.csv", CRANESIM_TESTDATA, name);
    unlink("rp_v1.csv");
    long n = cli_read_file(rec, a, sizeof a);
    CHECK(n > 1000 && !strncmp(a, "t,x1,x2,", 8), "%s: the recorded CSV %s", name, rec);
    int rc = cli_run(cmd, out, sizeof out);
    CHECK(rc == 0 && strstr(out, "(bit for bit)") && strstr(out, "commands by function (3): lift, jib, slew"),
          "old format %s: exit %d: %s", name, rc, out);
    long nb = cli_read_file("rp_v1.csv", b, sizeof b);
    CHECK(n == nb && !memcmp(a, b, (size_t)n), "old format %s: recorded %ld bytes, replayed %ld bytes, differ", name,
          n, nb);
}

// A crane chain of 8 functions (and the sandbox's slew): a headless drive
// commanding every function at its own times records a session whose
// header names every function; its replay is the drive's CSV byte for byte.
static void check_chain_8fn(const char* what, const char* args, int nfn) {
    static const char* const fn[] = {"lift", "fold", "ext1", "ext3", "jib", "jib_ext1", "jib_ext2", "jib_ext3",
                                     "slew"};
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "--model %s --scenario %s/scn_8fn_every_function.json --frame-rate 50 %s", CHAIN_8FN,
             CRANESIM_TESTDATA, args);
    check_bit_for_bit(what, cmd);
    // The replay's table has the chain's metrics by actuator and function,
    // recorded and replayed alike (identical rows: difference 0).
    for (int k = 0; k < 8; ++k) {
        char lab[96];
        snprintf(lab, sizeof lab, "  max_spool.%s [-] ", fn[k]);
        const char* p = strstr(out, lab);
        double r0 = NAN, r1 = NAN, dd = NAN;
        CHECK(p && sscanf(p + strlen(lab), "%lg %lg %lg", &r0, &r1, &dd) == 3 && r0 == r1 && dd == 0 && r0 > 0,
              "%s: replay table row '%s': %.300s", what, lab, p ? p : out);
    }
    // Its --metrics has them too: the peaks of the record's columns.
    int rc = cli_run("replay rp.session --quiet --metrics rp_chain.json", out, sizeof out);
    static char js[1 << 16];
    CHECK(rc == 0 && cli_read_file("rp_chain.json", js, sizeof js) > 0, "%s: replay --metrics: %s", what, out);
    long nr = cli_read_file("rp_rec.csv", a, sizeof a);
    double pk = 0, um = 0;
    for (int r = 0; nr > 0 && r < 60; ++r) {
        pk = fmax(pk, csv_value(a, "pA_fold", r));
        um = fmax(um, fabs(csv_value(a, "u_jib_ext3", r)));
    }
    const char* jp = strstr(js, "\"peak_pA.fold\": {\"value\": ");
    const char* ju = strstr(js, "\"max_spool.jib_ext3\": {\"value\": ");
    const double jpk = jp ? strtod(jp + 26, NULL) : NAN, jum = ju ? strtod(ju + 32, NULL) : NAN;
    CHECK(fabs(jpk - pk) <= 1e-8 * pk && fabs(jum - um) <= 1e-8 && um > 0.5,
          "%s: --metrics peak_pA.fold %.9g (record %.9g), max_spool.jib_ext3 %.9g (record %.9g)", what, jpk, pk, jum,
          um);
    // The header (line 2) lists the functions, each once, in the engine's order.
    long n = cli_read_file("rp.session", a, sizeof a);
    char* l2 = n > 0 ? strchr(a, '\n') : NULL;
    char* l3 = l2 ? strchr(l2 + 1, '\n') : NULL;
    if (l3) *l3 = 0;
    const char* fl = l2 ? strstr(l2, "\"functions\":[") : NULL;
    char want[256] = "\"functions\":[";
    for (int k = 0; k < nfn; ++k)
        snprintf(want + strlen(want), sizeof want - strlen(want), "%s\"%s\"", k ? "," : "", fn[k]);
    strcat(want, "]");
    CHECK(fl && !strncmp(fl, want, strlen(want)), "%s: the header does not list %s: %.200s", what, want,
          fl ? fl : "(no functions)");
    CHECK(l2 && strstr(l2, "\"model_name\":\"Ten-body crane") && strstr(l2, "\"engine\":"),
          "%s: the header does not name the model and the engine", what);
    // Every function's command varied in the drive (the record's ucmd_ column
    // takes more than one value), so the bit-for-bit replay carried each.
    long na = cli_read_file("rp_rec.csv", a, sizeof a);
    for (int k = 0; k < nfn && na > 0; ++k) {
        char col[64];
        snprintf(col, sizeof col, "ucmd_%s", fn[k]);
        // The sandbox's slew (not a function of the model) is the base column's.
        if (csv_col(a, col) < 0 && !strcmp(fn[k], "slew")) snprintf(col, sizeof col, "u3_cmd");
        const double first = csv_value(a, col, 10);
        int differ = 0;
        for (int r = 11; r < 55; ++r) differ += csv_value(a, col, r) != first;
        CHECK(csv_col(a, col) >= 0 && differ > 5, "%s: the command of %s did not vary (%d rows differ)", what, fn[k],
              differ);
    }
}

// Replay on a changed design by function name: loader10 with its functions
// in another order (jib before lift) is the same crane, so the replay by
// name gives every recorded value of each function's columns (a replay by
// position would swap the lift's and the jib's commands); a function the
// session commands that the model lacks is refused in one line.
static void check_by_name(void) {
    int rc = cli_run("drive --headless --quiet --mechanics lagrange --model " LOADER10
                     " --scenario drive_demo --duration 1.5 --frame-rate 50 --record rp_l10.csv --session rp_l10.session",
                     out, sizeof out);
    CHECK(rc == 0, "loader10 drive: exit %d: %s", rc, out);
    long n = cli_read_file(LOADER10, a, sizeof a);
    const char* lift = "{\"name\": \"lift\", \"valve\": \"lift_valve\"},";
    const char* jib = "{\"name\": \"jib\", \"valve\": \"jib_valve\"},";
    char* pl = n > 0 ? strstr(a, lift) : NULL;
    char* pj = pl ? strstr(pl, jib) : NULL;
    CHECK(pl && pj && pj > pl, "loader10's functions lift, jib not found");
    if (pl && pj) {
        // Swap the two entries (and keep the text between them): the
        // functions are then jib, lift, ext.
        const size_t ll = strlen(lift), lj = strlen(jib), nm = (size_t)(pj - pl) - ll;
        char mid[256];
        CHECK(nm < sizeof mid, "text between the functions");
        memcpy(mid, pl + ll, nm);
        memcpy(pl, jib, lj);
        memcpy(pl + lj, mid, nm);
        memcpy(pl + lj + nm, lift, ll);
        CHECK(cli_write_file("rp_l10_swapped.json", a) == 0, "write");
        rc = cli_run("replay rp_l10.session --quiet --model rp_l10_swapped.json --out rp_l10_sw.csv", out, sizeof out);
        CHECK(rc == 0 && strstr(out, "changed design") && strstr(out, "commands by function (3): lift, jib, ext"),
              "swapped functions: exit %d: %s", rc, out);
        long na = cli_read_file("rp_l10.csv", a, sizeof a), nb = cli_read_file("rp_l10_sw.csv", b, sizeof b);
        CHECK(na > 0 && nb > 0, "csv");
        static const char* const cols[] = {"ucmd_lift", "ucmd_jib", "ucmd_ext", "x_lift", "x_jib", "x_ext1", "p1A"};
        int diff = 0;
        for (int c = 0; c < 7; ++c)
            for (int r = 0; r < 75; ++r) diff += csv_value(a, cols[c], r) != csv_value(b, cols[c], r);
        const double lift_max = csv_value(a, "ucmd_lift", 50);
        CHECK(diff == 0 && lift_max > 0.5, "by name: %d values differ from the recording (ucmd_lift %.3g at row 50)",
              diff, lift_max);
    }
    // The 8-function session on loader10: it has no function fold.
    check_chain_8fn("chain lagrange", "--mechanics lagrange", 8);
    unlink("rp_bad.csv");
    rc = cli_run("replay rp.session --model " LOADER10 " --out rp_bad.csv", out, sizeof out);
    CHECK(rc == 2 && cli_count_lines(out) == 1 && strstr(out, "functions: 'fold' is not a function of this model") &&
              access("rp_bad.csv", F_OK) != 0,
          "a function the model lacks: exit %d: %s", rc, out);
    // A session naming a function no model has (its header edited).
    n = cli_read_file("rp.session", a, sizeof a);
    char* f = n > 0 ? strstr(a, "\"functions\":[") : NULL;
    f = f ? strstr(f, "\"jib_ext2\"") : NULL;
    CHECK(f != NULL, "no jib_ext2 in the header");
    if (f) {
        memcpy(f, "\"winch_x2\"", 10);
        check_refused("unknown function", a, "functions: 'winch_x2' is not a function of this model");
    }
}

// A format 2 session with a bad functions list or a tick line whose
// commands do not match it: one line naming the file and line, exit 2,
// nothing written.
static void check_bad_v2(void) {
    long n = cli_read_file("rp_l10.session", a, sizeof a);
    const char* fl = "\"functions\":[\"lift\",\"jib\",\"ext\"]";
    char* f = n > 0 ? strstr(a, fl) : NULL;
    CHECK(f != NULL, "no functions list in rp_l10.session");
    if (!f) return;
    memcpy(f, "\"functions\":[\"lift\",\"lift\",\"ex\"]", strlen(fl));
    check_refused("a function twice", a, "line 2: header: functions: expected an array of the functions' names, each once");
    memcpy(f, fl, strlen(fl));
    // The fourth tick line without its last command.
    char* t = a;
    for (int k = 0; k < 4 && t; ++k) t = strstr(t + 1, "\nt ");
    char* eol = t ? strchr(t + 1, '\n') : NULL;
    char* last = eol ? eol - 2 : NULL; // " 0" or " 1": the row flag
    char* cut = last ? last - 1 : NULL;
    while (cut && cut > t && *cut != ' ') --cut;
    CHECK(cut && cut > t && last[0] == ' ', "tick line");
    if (cut && cut > t) {
        memmove(cut, last, strlen(last) + 1); // drop the last command, keep the row flag
        check_refused("a command short", a, "expected 't TM TARGET' then 3 commands (lift ...) and ROW 0 or 1");
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
    check_old_format("lagrange");
    check_old_format("ode");
    check_chain_8fn("chain sandbox", "", 9);
    check_by_name();
    check_bad_v2();
    // A crane chain with a fault event: the burst at 2 s replayed at the same tick.
    check_bit_for_bit("chain hose burst", "--mechanics lagrange --model " LOADER10
                                          " --scenario hose_burst --duration 2.5 --frame-rate 100");
    TEST_MAIN_END();
}
