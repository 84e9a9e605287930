// test_sweep.c: run metrics (`run --metrics`) against the same quantities
// computed here from the run's CSV, and `cranesim sweep`: deterministic
// results files, failing designs as rows, bad input refused with nothing
// written. Runs the real binary (cli_util.h).
#include "check.h"
#include "cli_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char out[1 << 16];

// The value of metric name in a metrics JSON text, or NAN.
static double json_metric(const char* text, const char* name) {
    char key[160];
    snprintf(key, sizeof key, "\"%s\": {\"value\": ", name);
    const char* p = strstr(text, key);
    return p ? strtod(p + strlen(key), NULL) : NAN;
}

// The index of column name in a CSV header line, or -1.
static int csv_col(const char* header, const char* name) {
    int k = 0;
    const size_t n = strlen(name);
    for (const char* p = header; *p; ++k) {
        const char* e = strpbrk(p, ",\n");
        const size_t L = e ? (size_t)(e - p) : strlen(p);
        if (L == n && !strncmp(p, name, n)) return k;
        if (!e || *e == '\n') break;
        p = e + 1;
    }
    return -1;
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

// The overload scenario drives the lift into its port relief and against
// its end stop. With a row at every step (--every = --dt) the peaks over
// every step are the rows' peaks (at the CSV's 9 digits); the relief time and the end-stop hits
// follow from the relief_open and end_stop columns. Each is computed here
// from the CSV alone and must equal the metrics file.
static void test_metrics_match_csv(void) {
    const char* csv = "metrics_overload.csv";
    const char* js = "metrics_overload.json";
    char args[512];
    snprintf(args, sizeof args, "run --scenario overload --every 1e-4 --out %s --metrics %s", csv, js);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(strstr(out, "metrics: relief open") != NULL, "summary has no metrics block: %s", out);
    static char json[8192];
    CHECK(cli_read_file(js, json, sizeof json) > 0, "no %s", js);
    FILE* f = fopen(csv, "r");
    CHECK(f != NULL, "no %s", csv);
    if (!f) return;
    static char line[8192];
    if (!fgets(line, sizeof line, f)) line[0] = 0;
    const char* pn[] = {"p1A", "p1B", "p2A", "p2B", "p_pump"};
    int pc[5];
    for (int k = 0; k < 5; ++k) pc[k] = csv_col(line, pn[k]);
    const int ct = csv_col(line, "t"), cr = csv_col(line, "relief_open"), cs = csv_col(line, "end_stop");
    CHECK(ct == 0 && cr > 0 && cs > 0 && pc[0] > 0 && pc[4] > 0, "columns: %s", line);
    double peak[5] = {-INFINITY, -INFINITY, -INFINITY, -INFINITY, -INFINITY};
    double relief = 0, tprev = 0;
    long hits[2] = {0, 0}, rows = 0;
    int prev = 0;
    while (fgets(line, sizeof line, f)) {
        for (int k = 0; k < 5; ++k) peak[k] = fmax(peak[k], csv_field(line, pc[k]));
        const double t = csv_field(line, ct);
        const int stop = (int)csv_field(line, cs);
        if (rows > 0 && csv_field(line, cr) > 0) relief += t - tprev;
        for (int b = 0; b < 2; ++b)
            if ((stop >> b & 1) && !(rows > 0 && (prev >> b & 1))) ++hits[b];
        prev = stop;
        tprev = t;
        ++rows;
    }
    fclose(f);
    CHECK(rows == 120001, "rows %ld", rows);
    for (int k = 0; k < 5; ++k) {
        char name[32];
        snprintf(name, sizeof name, "peak_%s", pn[k]);
        // The CSV holds 9 significant digits (sim_csv_row): equal at that precision.
        char a9[40], b9[40];
        snprintf(a9, sizeof a9, "%.9g", json_metric(json, name));
        snprintf(b9, sizeof b9, "%.9g", peak[k]);
        CHECK(!strcmp(a9, b9), "%s: metrics %s, CSV %s", name, a9, b9);
    }
    // The scenario's own description: the lift relief caps p1A from 2.1 s on.
    CHECK(relief > 1.0, "relief time %g s", relief);
    CHECK_NEAR(json_metric(json, "relief_open_time"), relief, 1e-9);
    CHECK(hits[0] >= 1, "lift end-stop hits %ld", hits[0]);
    CHECK(json_metric(json, "end_stop_hits_lift") == (double)hits[0], "lift hits %g vs %ld",
          json_metric(json, "end_stop_hits_lift"), hits[0]);
    CHECK(json_metric(json, "end_stop_hits_jib") == (double)hits[1], "jib hits %g vs %ld",
          json_metric(json, "end_stop_hits_jib"), hits[1]);
    // Units on every value; the lagrange backend has no truck.
    CHECK(strstr(json, "\"peak_p1A\": {\"value\"") && strstr(json, "\"unit\": \"Pa\"") &&
              strstr(json, "\"unit\": \"s\"") && strstr(json, "\"unit\": \"count\""),
          "%s", json);
    CHECK(!strstr(json, "max_truck_tilt") && !strstr(json, "peak_p3A"), "absent metrics written: %s", json);
    // Rows every 1 ms (10 steps): the chamber peaks are still those of every
    // step, so at least the rows' and said to be over the steps.
    snprintf(args, sizeof args, "run --scenario overload --out %s --metrics %s -q", csv, js);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(cli_read_file(js, json, sizeof json) > 0, "no %s", js);
    CHECK(strstr(json, "\"peak_p1A\": {\"value\": ") && strstr(json, "\"unit\": \"Pa\", \"over\": \"steps\"}"),
          "%s", json);
    f = fopen(csv, "r");
    double coarse = -INFINITY;
    while (f && fgets(line, sizeof line, f))
        if (line[0] != 't') coarse = fmax(coarse, csv_field(line, pc[0]));
    if (f) fclose(f);
    CHECK(json_metric(json, "peak_p1A") >= coarse && coarse > 1e7, "step peak %.17g below the rows' %.17g",
          json_metric(json, "peak_p1A"), coarse);
}

// Energy in and losses, and each relief's open time, against the energy
// CSV (`run --energy`, the per-component powers [W] at the row period):
// energy in is minus the pump and tank columns integrated by the
// trapezoidal rule, the losses the valve, relief, check, orifice, hose and
// leakage columns; a relief counts a row interval when its power is
// positive at the row (it passes flow). The metrics come from every step,
// the CSV from the 1 ms rows: equal to 1e-4 relative (energy) and to a few
// rows (time). The overload scenario opens the lift port relief for over 1 s.
static void test_energy_and_relief_metrics_match_energy_csv(void) {
    const char* js = "metrics_energy.json";
    const char* ecsv = "metrics_energy_p.csv";
    char args[512];
    snprintf(args, sizeof args, "run --scenario overload --duration 4 --out metrics_energy.csv --energy %s "
             "--metrics %s", ecsv, js);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(strstr(out, "metrics: energy in") && strstr(out, "open per relief: lift_relief_A"), "summary: %s", out);
    static char json[8192];
    CHECK(cli_read_file(js, json, sizeof json) > 0, "no %s", js);
    FILE* f = fopen(ecsv, "r");
    CHECK(f != NULL, "no %s", ecsv);
    if (!f) return;
    static char head[8192], line[8192];
    if (!fgets(head, sizeof head, f)) head[0] = 0;
    // Column roles from the header: 1 in (pump, tank), 2 loss, 0 neither.
    enum { MAXC = 128 };
    int role[MAXC] = {0}, nc = 0;
    char names[MAXC][72];
    for (char *p = head, *e; *p && nc < MAXC; p = e + 1) {
        e = strpbrk(p, ",\n");
        const size_t L = e ? (size_t)(e - p) : strlen(p);
        snprintf(names[nc], sizeof names[nc], "%.*s", (int)L, p);
        const char* n = names[nc];
        const size_t nl = strlen(n);
        if (!strcmp(n, "pump") || !strcmp(n, "tank")) role[nc] = 1;
        else if (nc > 0 && strcmp(n, "stored") && strcmp(n, "expansion") &&
                 !(nl > 5 && !strcmp(n + nl - 5, ".work")))
            role[nc] = 2;
        ++nc;
        if (!e || *e == '\n') break;
    }
    double ein = 0, eloss = 0, tprev = 0, Tr[MAXC] = {0};
    double prev[MAXC] = {0}, cur[MAXC];
    long rows = 0;
    while (fgets(line, sizeof line, f)) {
        for (int k = 0; k < nc; ++k) cur[k] = csv_field(line, k);
        if (rows > 0) {
            const double h = cur[0] - tprev;
            for (int k = 1; k < nc; ++k) {
                const double e = 0.5 * h * (cur[k] + prev[k]);
                if (role[k] == 1) ein -= e;
                if (role[k] == 2) eloss += e;
                if (cur[k] > 0) Tr[k] += h;
            }
        }
        memcpy(prev, cur, sizeof cur);
        tprev = cur[0];
        ++rows;
    }
    fclose(f);
    CHECK(rows > 1000, "energy CSV rows %ld", rows);
    const double min = json_metric(json, "energy_in"), mloss = json_metric(json, "energy_loss");
    CHECK(ein > 1e4 && fabs(min - ein) <= 1e-4 * ein, "energy_in %.9g J, CSV %.9g J", min, ein);
    CHECK(eloss > 1e4 && fabs(mloss - eloss) <= 1e-4 * eloss, "energy_loss %.9g J, CSV %.9g J", mloss, eloss);
    CHECK(strstr(json, "\"energy_in\": {\"value\"") && strstr(json, "\"unit\": \"J\""), "%s", json);
    // Every relief of the circuit is named; each one's time as the CSV has it.
    int nrel = 0;
    for (int k = 1; k < nc; ++k) {
        if (!strstr(names[k], "relief")) continue;
        char key[96];
        snprintf(key, sizeof key, "relief_open_time.%s", names[k]);
        const double t = json_metric(json, key);
        CHECK(isfinite(t) && fabs(t - Tr[k]) <= 3e-3, "%s: metrics %.6g s, energy CSV %.6g s", key, t, Tr[k]);
        ++nrel;
    }
    CHECK(nrel == 5, "%d reliefs in the energy CSV", nrel);
    CHECK(json_metric(json, "relief_open_time.lift_relief_A") > 1.0, "%s", json);
    // The sweep tabulates the same energy on asking (one design, the same run).
    CHECK(cli_run("sweep --scenario overload --duration 4 --param hydraulics.components.lift_cyl.bore=0.1:0.1:1 "
                  "--metrics energy_in,energy_loss --out metrics_energy_sweep.csv -q",
                  out, sizeof out) == 0,
          "%s", out);
    static char tab[4096];
    CHECK(cli_read_file("metrics_energy_sweep.csv", tab, sizeof tab) > 0, "no sweep file");
    CHECK(strstr(tab, "index,hydraulics.components.lift_cyl.bore,energy_in,energy_loss,exit,error\n") != NULL, "%s",
          tab);
    const char* r1 = strchr(tab, '\n');
    CHECK(r1 && fabs(csv_field(r1 + 1, 2) - min) <= 1e-9 * min && fabs(csv_field(r1 + 1, 3) - mloss) <= 1e-9 * mloss,
          "sweep row %s vs run %.17g %.17g", r1 ? r1 + 1 : "", min, mloss);
}

// Hook sway on the sandbox's swing scenario (a slew started and stopped
// abruptly, the empty hook swinging on its rope): the largest horizontal
// offset of the hook (hook_x/y) from the end-arm tip in the world
// (tip_wx/y/z) and the rope's angle from vertical, atan2(offset, drop),
// computed here from the CSV, equal the metrics (to the CSV's 9 digits).
// The validation world hangs the hook at the tip: no sway at all.
static void test_sway_metrics_match_csv(void) {
    const char* csv = "metrics_swing.csv";
    const char* js = "metrics_swing.json";
    char args[512];
    snprintf(args, sizeof args, "run --scenario sandbox_swing --duration 6 --out %s --metrics %s -q", csv, js);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    static char json[8192], line[8192];
    CHECK(cli_read_file(js, json, sizeof json) > 0, "no %s", js);
    FILE* f = fopen(csv, "r");
    CHECK(f != NULL, "no %s", csv);
    if (!f) return;
    if (!fgets(line, sizeof line, f)) line[0] = 0;
    const int hx = csv_col(line, "hook_x"), hy = csv_col(line, "hook_y"), hz = csv_col(line, "hook_z");
    const int tx = csv_col(line, "tip_wx"), ty = csv_col(line, "tip_wy"), tz = csv_col(line, "tip_wz");
    CHECK(hx > 0 && hy > 0 && hz > 0 && tx > 0 && ty > 0 && tz > 0, "columns: %s", line);
    double amp = 0, ang = 0;
    while (fgets(line, sizeof line, f)) {
        const double dx = csv_field(line, hx) - csv_field(line, tx), dy = csv_field(line, hy) - csv_field(line, ty);
        const double drop = csv_field(line, tz) - csv_field(line, hz);
        const double off = sqrt(dx * dx + dy * dy);
        amp = fmax(amp, off);
        ang = fmax(ang, atan2(off, drop));
    }
    fclose(f);
    // The slew steps swing the hook visibly (so hard here that the chain
    // rope swings out to the horizontal: angle near 90 degrees).
    CHECK(amp > 0.05 && ang > 0.01 && ang < 3.1415927, "no swing: %g m, %g rad", amp, ang);
    CHECK_NEAR(json_metric(json, "max_hook_sway_amplitude"), amp, 1e-6);
    CHECK_NEAR(json_metric(json, "max_hook_sway"), ang, 1e-6);
    CHECK(strstr(json, "\"max_hook_sway\": {\"value\"") && strstr(json, "\"unit\": \"rad\"") &&
              strstr(json, "\"unit\": \"m\""),
          "%s", json);
    snprintf(args, sizeof args, "run --scenario ramp --mechanics ode --duration 2 --out metrics_val.csv --metrics %s -q",
             js);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(cli_read_file(js, json, sizeof json) > 0, "no %s", js);
    CHECK(json_metric(json, "max_hook_sway_amplitude") == 0 && json_metric(json, "max_hook_sway") == 0, "%s", json);
}

static const char* k_grid = "sweep --scenario ramp --duration 2 --param hydraulics.components.lift_cyl.bore=0.08:0.12:3 "
                            "--param hydraulics.components.jib_cyl.bore=0.07:0.09:2";

// The same grid on 1 and 2 threads: the same file byte for byte, one row
// per design in index order, and a design's metrics those of `cranesim run`
// with its values set.
static void test_sweep_threads_same_file(void) {
    char args[1024];
    static char a[1 << 15], b[1 << 15], json[8192];
    snprintf(args, sizeof args, "%s --threads 1 --out sweep_t1.csv", k_grid);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    snprintf(args, sizeof args, "%s --threads 2 --out sweep_t2.csv", k_grid);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(cli_read_file("sweep_t1.csv", a, sizeof a) > 0 && cli_read_file("sweep_t2.csv", b, sizeof b) > 0,
          "missing results");
    CHECK(!strcmp(a, b), "1 and 2 threads differ:\n%s\n--\n%s", a, b);
    CHECK(cli_count_lines(a) == 7, "rows: %s", a);
    const char* l = a;
    for (int i = 0; i < 6 && l; ++i) {
        l = strchr(l, '\n');
        if (l) ++l;
        CHECK(l && atoi(l) == i && csv_field(l, csv_col(a, "exit")) == 0, "row %d: %s", i, l ? l : "");
    }
    // Design 3: lift bore 0.10 (second of three), jib bore 0.09 (second of two).
    CHECK(cli_run("run --scenario ramp --duration 2 --set hydraulics.components.lift_cyl.bore=0.1 --set "
                  "hydraulics.components.jib_cyl.bore=0.09 --out sweep_d3.csv --metrics sweep_d3.json -q",
                  out, sizeof out) == 0,
          "%s", out);
    CHECK(cli_read_file("sweep_d3.json", json, sizeof json) > 0, "no sweep_d3.json");
    const char* r3 = a;
    for (int i = 0; i < 4 && r3; ++i) {
        r3 = strchr(r3, '\n');
        if (r3) ++r3;
    }
    CHECK(r3 && csv_field(r3, 1) == 0.1 && csv_field(r3, 2) == 0.09, "design 3: %s", r3 ? r3 : "");
    const char* mets[] = {"peak_p1A", "peak_p2B", "peak_p_pump", "relief_open_time", "end_stop_hits_lift"};
    for (int k = 0; k < 5 && r3; ++k)
        CHECK(csv_field(r3, csv_col(a, mets[k])) == json_metric(json, mets[k]), "%s: sweep %.17g, run %.17g",
              mets[k], csv_field(r3, csv_col(a, mets[k])), json_metric(json, mets[k]));
}

// The results file's numbers are the decimals they stand for (docs/sweep.md):
// the grid point 0.08 + 3 x 0.01 is 0.11, the value `run --set ...=0.11`
// runs (its metrics equal bit for bit), not 0.11000000000000001, a design
// 1 ulp away; the relief time of 1 ms rows is the count of open row
// intervals over 1000, counted here in the run's CSV (7.431, not
// 7.431000000000001).
static void test_sweep_numbers_are_decimals(void) {
    static char a[1 << 15], json[8192], line[8192];
    CHECK(cli_run("sweep --scenario overload --param hydraulics.components.lift_cyl.bore=0.08:0.14:7 "
                  "--out sweep_dec.csv -q",
                  out, sizeof out) == 0,
          "%s", out);
    CHECK(cli_read_file("sweep_dec.csv", a, sizeof a) > 0, "no sweep_dec.csv");
    const char* want[] = {"\n1,0.09,", "\n2,0.1,", "\n3,0.11,", "\n4,0.12,", "\n5,0.13,", "\n6,0.14,"};
    for (int k = 0; k < 6; ++k) CHECK(strstr(a, want[k]) != NULL, "no row '%s' in:\n%s", want[k] + 1, a);
    CHECK(cli_run("run --scenario overload --set hydraulics.components.lift_cyl.bore=0.11 --out sweep_dec_run.csv "
                  "--metrics sweep_dec_run.json -q",
                  out, sizeof out) == 0,
          "%s", out);
    CHECK(cli_read_file("sweep_dec_run.json", json, sizeof json) > 0, "no sweep_dec_run.json");
    const char* r3 = strstr(a, "\n3,");
    const char* mets[] = {"peak_p1A", "peak_p1B", "peak_p2A", "peak_p_pump", "relief_open_time"};
    for (int k = 0; k < 5 && r3; ++k)
        CHECK(csv_field(r3 + 1, csv_col(a, mets[k])) == json_metric(json, mets[k]), "%s: sweep %.17g, run %.17g",
              mets[k], csv_field(r3 + 1, csv_col(a, mets[k])), json_metric(json, mets[k]));
    FILE* f = fopen("sweep_dec_run.csv", "r");
    CHECK(f != NULL, "no sweep_dec_run.csv");
    if (!f) return;
    long open = 0, rows = 0;
    int cr = -1;
    while (fgets(line, sizeof line, f)) {
        if (cr < 0) {
            cr = csv_col(line, "relief_open");
            continue;
        }
        if (rows++ > 0 && csv_field(line, cr) > 0) ++open;
    }
    fclose(f);
    const double t = json_metric(json, "relief_open_time");
    CHECK(open > 100 && t == (double)open / 1000.0, "relief open %.17g s, %ld open 1 ms row intervals", t, open);
    // As text: the CSV cell is that decimal.
    char cell[64];
    snprintf(cell, sizeof cell, ",%.15g,", (double)open / 1000.0);
    CHECK(r3 && strstr(r3, cell) != NULL, "row 3 has no cell '%s': %.200s", cell, r3 ? r3 : "");
}

// A design the model refuses (a bore <= 0) is a row with exit 2 and the
// model's message, one that blows up a row with exit 1; the others run and
// the sweep exits 0. --fail-fast stops
// with exit 1.
static void test_sweep_failing_design_is_a_row(void) {
    static char a[1 << 15];
    const char* base = "sweep --scenario ramp --duration 1 --param hydraulics.components.lift_cyl.bore=-0.1:0.1:3 "
                       "--metrics peak_p1A";
    char args[1024];
    snprintf(args, sizeof args, "%s --threads 2 --out sweep_fail.csv", base);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(cli_read_file("sweep_fail.csv", a, sizeof a) > 0, "no file");
    CHECK(cli_count_lines(a) == 4, "%s", a);
    CHECK(strstr(a, "\n0,-0.1,,2,\"") && strstr(a, "must be > 0"), "%s", a);
    CHECK(strstr(a, "\n1,0,,2,\""), "%s", a);
    CHECK(strstr(a, "\n2,0.1,") && strstr(a, ",0,\n"), "%s", a);
    // A blow-up: ROS2 at 5 ms is stable on the soft oil (0.1 GPa) and not on
    // the stiff one (1 GPa) of the step scenario's valve steps: exit 1, the
    // run's message, no metrics; the sweep still exits 0 (--no-retry: with
    // the retry of a failed step in shorter ones it may run through).
    CHECK(cli_run("sweep --scenario step --duration 2 --solver ros2 --dt 5e-3 --no-retry --no-step-probe --metrics peak_p1A "
                  "--param hydraulics.fluid.bulk_modulus=1e8:1e9:2 --out sweep_blowup.csv",
                  out, sizeof out) == 0,
          "%s", out);
    CHECK(cli_read_file("sweep_blowup.csv", a, sizeof a) > 0 && cli_count_lines(a) == 3, "%s", a);
    CHECK(strstr(a, "\n0,100000000,") && strstr(a, ",0,\n1,1000000000,,1,\"numerical blow-up"), "%s", a);
    snprintf(args, sizeof args, "%s --threads 1 --fail-fast --out sweep_ff.csv", base);
    CHECK(cli_run(args, out, sizeof out) == 1 && strstr(out, "--fail-fast"), "%s", out);
    CHECK(cli_read_file("sweep_ff.csv", a, sizeof a) > 0 && cli_count_lines(a) == 2, "%s", a);
}

// Bad input: one line naming the problem, exit 2, no results file.
static void test_sweep_bad_input(void) {
    static const struct {
        const char* args;
        const char* says;
    } cases[] = {
        {"--param hydraulics.components.lift_cyl.boar=0.08:0.12:3", "boar"},
        {"--param hydraulics.components.nope.bore=0.08:0.12:3", "nope"},
        {"--param hydraulics.components.lift_cyl.bore=0.12:0.08:3", "above HI"},
        {"--param hydraulics.components.lift_cyl.bore=0.08:0.12:0", "N must be"},
        {"--param hydraulics.components.lift_cyl.bore=0.08:0.12", "PATH=LO:HI:N"},
        {"--param hydraulics.components.lift_cyl.bore=0.08:0.12:3 --metrics peak_p1A,wobble", "wobble"},
        {"--param hydraulics.components.lift_cyl.bore=0.08:0.12:3 --metrics peak_p3A", "peak_p3A"},
        {"--param hydraulics.components.lift_cyl.bore=0.08:0.12:3 --threads 0", "--threads"},
        {"--lhs 4 --param hydraulics.components.lift_cyl.bore=0.08:0.12:3", "--lhs"},
        {"--param hydraulics.components.name=1:2:2", "name"},
        {"", "--param"},
        // The parser sweep shares with optimize: a value missing, too many.
        {"--param --threads 1", "--param needs a value"},
        {"--param hydraulics.components.lift_cyl.bore=0.08:0.12:3 --plot", "--plot needs a value"},
        {"--param a=0:1:2 --param b=0:1:2 --param c=0:1:2 --param d=0:1:2 --param e=0:1:2 --param f=0:1:2 "
         "--param g=0:1:2 --param h=0:1:2 --param i=0:1:2",
         "at most 8 --param"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        unlink("sweep_bad.csv");
        char args[1024];
        snprintf(args, sizeof args, "sweep --scenario ramp --duration 1 %s --out sweep_bad.csv", cases[k].args);
        const int rc = cli_run(args, out, sizeof out);
        CHECK(rc == 2 && strstr(out, cases[k].says) && cli_count_lines(out) == 1, "%s: rc %d: %s", cases[k].args,
              rc, out);
        CHECK(access("sweep_bad.csv", F_OK) != 0, "%s: a results file was written", cases[k].args);
    }
}

// A Latin hypercube: each parameter's N strata used once each, and the
// same seed gives the same file.
static void test_sweep_lhs_strata(void) {
    static char a[1 << 15], b[1 << 15];
    const char* base = "sweep --scenario ramp --duration 0.5 --lhs 8 --seed 7 --metrics peak_p1A "
                       "--param hydraulics.components.lift_cyl.bore=0.08:0.12 "
                       "--param hydraulics.components.jib_cyl.bore=0.06:0.1";
    char args[1024];
    snprintf(args, sizeof args, "%s --threads 2 --out sweep_lhs1.csv", base);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    snprintf(args, sizeof args, "%s --threads 1 --out sweep_lhs2.csv", base);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(cli_read_file("sweep_lhs1.csv", a, sizeof a) > 0 && cli_read_file("sweep_lhs2.csv", b, sizeof b) > 0,
          "no file");
    CHECK(!strcmp(a, b), "same seed, different files");
    const double lo[2] = {0.08, 0.06}, hi[2] = {0.12, 0.1};
    for (int p = 0; p < 2; ++p) {
        int used[8] = {0};
        const char* l = a;
        for (int i = 0; i < 8 && l; ++i) {
            l = strchr(l, '\n');
            if (!l) break;
            ++l;
            const double v = csv_field(l, 1 + p);
            const int s = (int)floor((v - lo[p]) / (hi[p] - lo[p]) * 8);
            CHECK(s >= 0 && s < 8, "value %g outside [%g, %g]", v, lo[p], hi[p]);
            if (s >= 0 && s < 8) ++used[s];
        }
        for (int s = 0; s < 8; ++s) CHECK(used[s] == 1, "parameter %d stratum %d used %d times", p, s, used[s]);
    }
}

// drive's headless summary counts collisions as a scripted run does (at
// every ODE step, by pair): sandbox_wall driven headless against `cranesim
// run` of the same scenario, the same count and pairs, each first touch
// within a frame (drive sets the valves once a frame, 75 a second; run at
// every ODE step). The lagrange view has no contacts: no such line.
static void test_drive_summary_collisions_match_run(void) {
    static char json[16384], drv[1 << 15];
    CHECK(cli_run("run --scenario sandbox_wall --duration 4 --out drive_coll_run.csv --metrics drive_coll.json -q",
                  out, sizeof out) == 0,
          "%s", out);
    CHECK(cli_read_file("drive_coll.json", json, sizeof json) > 0, "no drive_coll.json");
    const double n_run = json_metric(json, "collisions");
    CHECK(n_run >= 1, "run: no collisions on sandbox_wall: %s", json);
    CHECK(cli_run("drive --headless --scenario sandbox_wall --duration 4", drv, sizeof drv) == 0, "%s", drv);
    const char* line = strstr(drv, "\n  collisions ");
    CHECK(line, "drive's summary has no collisions line:\n%s", drv);
    if (!line) return;
    line += strlen("\n  collisions ");
    const char* eol = strchr(line, '\n');
    CHECK(strtod(line, NULL) == n_run, "drive counts %g collisions, run %g", strtod(line, NULL), n_run);
    int npair = 0;
    for (const char* p = strstr(json, "\"bodies\": \""); p; p = strstr(p, "\"bodies\": \"")) {
        p += strlen("\"bodies\": \"");
        const char* q = strchr(p, '"');
        if (!q) break;
        char key[160];
        snprintf(key, sizeof key, "%.*s at ", (int)(q - p), p);
        const char* f = strstr(p, "\"first_t\": ");
        const double t_run = f ? strtod(f + strlen("\"first_t\": "), NULL) : NAN;
        const char* d = strstr(line, key);
        CHECK(d && (!eol || d < eol), "drive's line lacks the pair '%.*s': %.*s", (int)(q - p), p,
              eol ? (int)(eol - line) : 200, line);
        if (d) {
            const double t_drive = strtod(d + strlen(key), NULL);
            CHECK(fabs(t_drive - t_run) <= 1.0 / 75 + 1e-3, "'%.*s' first touched at %g s in drive, %g s in run",
                  (int)(q - p), p, t_drive, t_run);
        }
        ++npair;
        p = q;
    }
    CHECK(npair >= 1, "run's JSON has no collision_pairs: %s", json);
    CHECK(cli_run("drive --headless --mechanics lagrange --duration 0.5", drv, sizeof drv) == 0, "%s", drv);
    CHECK(!strstr(drv, "collisions"), "the lagrange view reports collisions:\n%s", drv);
}

#define LOADER10 CRANESIM_TESTDATA "/../../../assets/models/loader10.json"
#define L10_SCN CRANESIM_TESTDATA "/scn_loader10_functions.json"

// Field k of a CSV line as its text (up to the next comma or newline).
static void csv_text(const char* line, int k, char* buf, size_t n) {
    const char* p = line;
    for (int i = 0; i < k && p; ++i) {
        p = strchr(p, ',');
        if (p) ++p;
    }
    const size_t L = p ? strcspn(p, ",\n") : 0;
    snprintf(buf, n, "%.*s", (int)(L < n ? L : n - 1), p ? p : "");
}

// Each row of the sweep file text against `cranesim run --set` of its
// design (pars: the --param paths, in the file's column order; the runs
// with run_args): every metric column that the run's --metrics JSON has
// (the chain's by actuator and function included) must be the same double.
// Returns the values compared.
static int check_rows_against_runs(const char* text, const char* const* pars, int npar, const char* run_args) {
    static char json[1 << 16];
    const char* nl = strchr(text, '\n');
    int compared = 0;
    for (const char* row = nl ? nl + 1 : NULL; row && *row; row = strchr(row, '\n'), row = row ? row + 1 : NULL) {
        char cmd[2048], v[64];
        int L = snprintf(cmd, sizeof cmd, "run -q %s --out sweep_l10_run.csv --metrics sweep_l10_run.json", run_args);
        for (int k = 0; k < npar; ++k) {
            csv_text(row, 1 + k, v, sizeof v);
            L += snprintf(cmd + L, sizeof cmd - (size_t)L, " --set %s=%s", pars[k], v);
        }
        CHECK(cli_run(cmd, out, sizeof out) == 0, "%s: %s", cmd, out);
        CHECK(cli_read_file("sweep_l10_run.json", json, sizeof json) > 0, "no metrics json");
        // Every column after the parameters, up to exit.
        const int cexit = csv_col(text, "exit");
        CHECK(cexit > npar + 1 && csv_field(row, cexit) == 0, "row exit: %.120s", row);
        for (int c = 1 + npar; c < cexit; ++c) {
            char name[96];
            csv_text(text, c, name, sizeof name);
            const double want = json_metric(json, name), got = csv_field(row, c);
            CHECK(!isnan(want), "%s: not in run's metrics JSON", name);
            CHECK(got == want, "%s: sweep %.17g, run --set %.17g (%s)", name, got, want, cmd);
            ++compared;
        }
    }
    return compared;
}

// A crane chain model (loader10: lift, jib, ext; actuators lift, jib, ext1,
// ext2): sweep paths name its parts (an actuator, a body, a circuit element),
// the default table has its metrics by actuator and function, --metrics
// takes them by name, and every value is that of `cranesim run --set` of the
// same design (lagrange on threads, ode on worker processes).
static void test_sweep_chain_by_name(void) {
    static char a[1 << 16];
    const char* const pars[] = {"mechanics.actuators.lift.closed_length", "mechanics.bodies.lifting_arm.inertia"};
    unlink("sweep_l10.csv");
    CHECK(cli_run("sweep -q --model " LOADER10 " --mechanics lagrange --scenario " L10_SCN
                  " --param mechanics.actuators.lift.closed_length=1.33:1.35:3"
                  " --param mechanics.bodies.lifting_arm.inertia=182:184:2 --out sweep_l10.csv",
                  out, sizeof out) == 0,
          "%s", out);
    CHECK(cli_read_file("sweep_l10.csv", a, sizeof a) > 0, "no sweep_l10.csv");
    // The table shows every function and actuator by name.
    const char* cols[] = {"max_spool.lift", "max_spool.jib", "max_spool.ext", "peak_pA.lift", "peak_pB.jib",
                          "peak_force.ext1", "stroke_max.ext2", "end_stop_hits.ext2", "stroke_min.lift"};
    for (int k = 0; k < 9; ++k) CHECK(csv_col(a, cols[k]) > 2, "no column %s in: %.400s", cols[k], a);
    // Each function was commanded (scn_loader10_functions: lift 0.8, jib -0.6, ext 0.9 at most).
    const char* r0 = strchr(a, '\n');
    CHECK(r0 && fabs(csv_field(r0 + 1, csv_col(a, "max_spool.ext")) - 0.9) < 1e-6 &&
              fabs(csv_field(r0 + 1, csv_col(a, "max_spool.lift")) - 0.8) < 1e-6 &&
              fabs(csv_field(r0 + 1, csv_col(a, "max_spool.jib")) - 0.6) < 1e-6,
          "spool openings by function: %.300s", r0 ? r0 + 1 : "");
    int n = check_rows_against_runs(a, pars, 2,
                                    "--model " LOADER10 " --mechanics lagrange --scenario " L10_SCN);
    CHECK(n >= 6 * 30, "compared %d values", n);
    printf("  loader10 lagrange: %d sweep values equal to run --set's\n", n);
    // ode, on worker processes, a circuit element; --metrics by name.
    const char* const pars2[] = {"hydraulics.components.ext1_cyl.bore"};
    CHECK(cli_run("sweep -q --threads 2 --model " LOADER10 " --mechanics ode --world validation --scenario " L10_SCN
                  " --param hydraulics.components.ext1_cyl.bore=0.06:0.07:2"
                  " --metrics peak_pA.ext1,peak_pB.ext1,stroke_max.ext1,max_spool.ext,peak_p1A --out sweep_l10.csv",
                  out, sizeof out) == 0,
          "%s", out);
    CHECK(cli_read_file("sweep_l10.csv", a, sizeof a) > 0 &&
              !strncmp(a, "index,hydraulics.components.ext1_cyl.bore,peak_pA.ext1,peak_pB.ext1,stroke_max.ext1,"
                          "max_spool.ext,peak_p1A,exit,error\n", 100),
          "ode table: %.300s", a);
    n = check_rows_against_runs(a, pars2, 1,
                                "--model " LOADER10 " --mechanics ode --world validation --scenario " L10_SCN);
    CHECK(n == 10, "compared %d values", n);
    // The larger ext1 bore holds the same extension with less pressure.
    const char* r1 = strchr(a, '\n');
    const char* r2 = r1 ? strchr(r1 + 1, '\n') : NULL;
    CHECK(r1 && r2 && csv_field(r2 + 1, 2) < csv_field(r1 + 1, 2), "peak_pA.ext1 did not fall with the bore");
    // A name the model does not have: one line with the names it has, exit 2, no file.
    unlink("sweep_l10_bad.csv");
    int rc = cli_run("sweep --model " LOADER10 " --mechanics lagrange --scenario " L10_SCN
                     " --param hydraulics.components.ext1_cyl.bore=0.06:0.07:2 --metrics peak_pA.fold"
                     " --out sweep_l10_bad.csv",
                     out, sizeof out);
    CHECK(rc == 2 && cli_count_lines(out) == 1 && strstr(out, "unknown metric 'peak_pA.fold'") &&
              strstr(out, "by function: max_spool.NAME (lift, jib, ext)") && access("sweep_l10_bad.csv", F_OK) != 0,
          "unknown chain metric: %d %s", rc, out);
}

int main(int argc, char** argv) {
    RUN_TEST(test_metrics_match_csv);
    RUN_TEST(test_energy_and_relief_metrics_match_energy_csv);
    RUN_TEST(test_sway_metrics_match_csv);
    RUN_TEST(test_drive_summary_collisions_match_run);
    RUN_TEST(test_sweep_threads_same_file);
    RUN_TEST(test_sweep_numbers_are_decimals);
    RUN_TEST(test_sweep_failing_design_is_a_row);
    RUN_TEST(test_sweep_bad_input);
    RUN_TEST(test_sweep_lhs_strata);
    RUN_TEST(test_sweep_chain_by_name);
    TEST_MAIN_END();
}
