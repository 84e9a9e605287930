// test_energy_cli.c: `run --energy FILE.csv` (docs/energy.md): the header,
// one row per output row, and in every row the identity of the power terms:
// all columns but t and expansion sum to zero.
#include "check.h"
#include "cli_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void test_energy_csv_rows_sum_to_zero(void) {
    static char out[16384];
    const char* csv = CRANESIM_BINARY_DIR "/test_energy_cli.csv";
    const char* ecsv = CRANESIM_BINARY_DIR "/test_energy_cli_e.csv";
    char args[1024];
    snprintf(args, sizeof args, "run --scenario overload --duration 6 --every 0.01 --out %s --energy %s", csv, ecsv);
    int rc = cli_run(args, out, sizeof out);
    CHECK(rc == 0 && strstr(out, "energy: in ") && strstr(out, "residual "), "rc %d: %s", rc, out);
    const char* r = strstr(out, "residual ");
    CHECK(r && fabs(atof(r + 9)) < 1.0, "%s", r ? r : out);
    static char buf[1 << 21];
    CHECK(cli_read_file(ecsv, buf, sizeof buf) > 0, "no %s", ecsv);
    CHECK(!strncmp(buf, "t,pump,", 7), "header: %.200s", buf);
    // Which column is expansion (the last).
    char* line = strtok(buf, "\n");
    int ncol = 1;
    for (const char* p = line; *p; ++p) ncol += *p == ',';
    CHECK(strstr(line, ",tank,stored,expansion") != NULL, "header: %.300s", line);
    int rows = 0, bad = 0;
    double worst = 0.0, pump_max = 0.0;
    while ((line = strtok(NULL, "\n"))) {
        double sum = 0.0, scale = 0.0, v;
        char* p = line;
        for (int k = 0; k < ncol; ++k) {
            v = strtod(p, &p);
            if (*p == ',') ++p;
            if (k == 0 || k == ncol - 1) continue; // t, expansion
            if (k == 1) pump_max = fmax(pump_max, -v);
            sum += v;
            scale += fabs(v);
        }
        ++rows;
        worst = fmax(worst, fabs(sum) / (scale + 1.0));
        bad += fabs(sum) > 1e-6 * scale + 1e-6;
    }
    CHECK(rows == 601, "%d rows, expected 601 (0 .. 6 s every 10 ms)", rows);
    CHECK(pump_max > 1e3, "the pump delivered at most %g W", pump_max);
    CHECK(bad == 0, "%d rows do not sum to zero (worst %.3g relative)", bad, worst);
    remove(csv);
    remove(ecsv);
}

static void test_energy_bad_path(void) {
    static char out[4096];
    int rc = cli_run("run --scenario ramp --out /dev/null --energy /nonexistent-dir/e.csv", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--energy") && cli_count_lines(out) == 1, "rc %d: %s", rc, out);
}

// The summary names a group whenever the circuit has such components, also
// when its energy is exactly 0 (the LS crane's counterbalance valves stay
// shut on hold, and the group used to vanish), and never otherwise.
static void test_summary_groups(void) {
    static char out[16384];
    int rc = cli_run("run --model " CRANESIM_ASSETS "/models/hiab031_ls.json --scenario hold --duration 0.5 --out /dev/null",
                     out, sizeof out);
    const char* line = strstr(out, "energy: in ");
    CHECK(rc == 0 && line, "rc %d: %s", rc, out);
    if (!line) return;
    CHECK(strstr(line, "counterbalance valves 0.000") != NULL, "no counterbalance group: %.400s", line);
    CHECK(strstr(line, "compensators ") != NULL, "no compensator group: %.400s", line);
    rc = cli_run("run --scenario hold --duration 0.5 --out /dev/null", out, sizeof out);
    line = strstr(out, "energy: in ");
    CHECK(rc == 0 && line, "rc %d: %s", rc, out);
    if (!line) return;
    const char* eol = strchr(line, '\n');
    const char* cb = strstr(line, "counterbalance");
    CHECK(!cb || (eol && cb > eol), "the standard crane has no counterbalance valves: %.400s", line);
}

// A fixed step that rings below absolute zero at a stiff event and leaves a
// node there at the end (the standard crane on `overload` at Krus 1 ms, ten
// times the paper's step, with the seal friction the paper modelled: the
// shipped crane's seal friction stops that run at the end-stop impact
// instead): the fluid's compression energy is undefined there, and the
// summary must say so instead of printing NaN as the stored energy and the
// residual.
static void test_summary_below_zero(void) {
    static char out[16384];
    int rc = cli_run("run --scenario overload --solver krus --dt 1e-3 --out /dev/null"
                     " --set hydraulics.components.lift_cyl.coulomb=0 --set hydraulics.components.lift_cyl.stribeck=0"
                     " --set hydraulics.components.jib_cyl.coulomb=0 --set hydraulics.components.jib_cyl.stribeck=0",
                     out, sizeof out);
    CHECK(rc == 0 && strstr(out, "dipped below absolute zero"), "the run should note the dip: rc %d: %s", rc, out);
    CHECK(strstr(out, "stored in the fluid: undefined (a node ended below absolute zero") != NULL,
          "no 'undefined' stored energy: %s", out);
    CHECK(!strstr(out, "nan") && !strstr(out, "NaN"), "NaN in the summary: %s", out);
}

int main(void) {
    test_energy_csv_rows_sum_to_zero();
    test_summary_groups();
    test_energy_bad_path();
    test_summary_below_zero();
    printf("%d checks, %d failed\n", check_count_, check_failures_);
    return check_failures_ != 0;
}
