// test_cli.c: the cranesim command line as a user meets it: exit codes, one-line
// errors naming file and field, CSV contract, no lost output on a blow-up.
#include "check.h"

#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#define BIN CRANESIM_BINARY_DIR "/cranesim"
#define DATA CRANESIM_TESTDATA

// Run cranesim with args (stderr merged into out). Returns the exit code.
static int run(const char* args, char* out, size_t n) {
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s %s 2>&1", BIN, args);
    FILE* p = popen(cmd, "r");
    if (!p) return -1;
    size_t got = fread(out, 1, n - 1, p);
    out[got] = 0;
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int count_lines(const char* s) {
    int n = 0;
    for (; *s; ++s) n += *s == '\n';
    return n;
}

static void test_help_and_usage(void) {
    static char out[16384];
    CHECK(run("help", out, sizeof out) == 0, "help: %s", out);
    CHECK(strstr(out, "drive") && strstr(out, "run") && strstr(out, "compare") && strstr(out, "bench"), "%s", out);
    const char* const cmds[] = {"run", "bench", "compare", "drive"};
    for (int i = 0; i < 4; ++i) {
        char a[64];
        snprintf(a, sizeof a, "%s --help", cmds[i]);
        CHECK(run(a, out, sizeof out) == 0 && strstr(out, "usage: cranesim"), "%s: %s", a, out);
    }
    CHECK(run("", out, sizeof out) == 2, "no command should exit 2");
    CHECK(run("fly", out, sizeof out) == 2 && strstr(out, "unknown command"), "%s", out);
    CHECK(run("run --bogus", out, sizeof out) == 2 && strstr(out, "--bogus"), "%s", out);
    CHECK(run("run --dt -1", out, sizeof out) == 2 && strstr(out, "--dt"), "%s", out);
    CHECK(run("run --solver euler", out, sizeof out) == 2 && strstr(out, "euler"), "%s", out);
}

typedef struct bad_case {
    const char* file;
    const char* field; // must appear in the message
} bad_case;

static void test_bad_models(void) {
    static const bad_case cases[] = {
        {"bad_bore.json", "bore"},
        {"missing_links.json", "mechanics.links"},
        {"typo_key.json", "load_mas"},
        {"unknown_cylinder.json", "actuators[1].cylinder"},
        {"rod_ge_bore.json", "rod"},
        {"mass_string.json", "links[0].mass"},
        {"bad_mount.json", "actuators[0]"},
        {"bad_port.json", "components[2].A"},
        {"syntax_error.json", "line"},
    };
    static char out[8192];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char a[1024];
        snprintf(a, sizeof a, "run --quiet --model %s/%s --scenario hold --duration 0.01 --out /dev/null", DATA,
                 cases[i].file);
        int rc = run(a, out, sizeof out);
        CHECK(rc == 2, "%s: exit %d, want 2: %s", cases[i].file, rc, out);
        CHECK(strstr(out, cases[i].file) != NULL, "%s: message does not name the file: %s", cases[i].file, out);
        CHECK(strstr(out, cases[i].field) != NULL, "%s: message does not name %s: %s", cases[i].file,
              cases[i].field, out);
        CHECK(count_lines(out) == 1, "%s: want one line, got: %s", cases[i].file, out);
    }
}

static void test_bad_scenarios(void) {
    static const bad_case cases[] = {
        {"scn_time_order.json", "commands.lift[2]"},
        {"scn_range.json", "commands.jib[1]"},
        {"scn_no_duration.json", "duration"},
        {"scn_unknown_channel.json", "commands.swing"},
        {"scn_bad_angle.json", "initial.q1_deg"},
    };
    static char out[8192];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char a[1024];
        snprintf(a, sizeof a, "run --quiet --scenario %s/%s --out /dev/null", DATA, cases[i].file);
        int rc = run(a, out, sizeof out);
        CHECK(rc == 2, "%s: exit %d, want 2: %s", cases[i].file, rc, out);
        CHECK(strstr(out, cases[i].file) && strstr(out, cases[i].field), "%s: want file and %s in: %s",
              cases[i].file, cases[i].field, out);
        CHECK(count_lines(out) == 1, "%s: want one line: %s", cases[i].file, out);
    }
}

static void test_bad_set(void) {
    static char out[8192];
    const char* const bad[] = {"mechanics.load_mas=3", "mechanics.load_mass=heavy",
                               "hydraulics.components.lift_cyl.bore=-0.1", "nonsense"};
    const char* const want[] = {"load_mas", "load_mass", "bore", "nonsense"};
    for (int i = 0; i < 4; ++i) {
        char a[512];
        snprintf(a, sizeof a, "run --quiet --scenario hold --duration 0.01 --out /dev/null --set %s", bad[i]);
        int rc = run(a, out, sizeof out);
        CHECK(rc == 2 && strstr(out, want[i]) && count_lines(out) == 1, "--set %s: exit %d: %s", bad[i], rc, out);
    }
    // A good --set takes effect: a heavier load needs more lift pressure.
    char a[512];
    snprintf(a, sizeof a, "run --quiet --scenario hold --duration 0.01 --out /dev/null --set mechanics.load_mass=800");
    CHECK(run(a, out, sizeof out) == 0, "good --set failed: %s", out);
}

static int read_file(const char* path, char* buf, size_t n) {
    FILE* f = fopen(path, "r");
    if (!f) return -1;
    size_t got = fread(buf, 1, n - 1, f);
    buf[got] = 0;
    fclose(f);
    return (int)got;
}

static void test_csv_contract(void) {
    static char out[8192];
    static char csv[1 << 16];
    CHECK(run("run --quiet --scenario ramp --duration 0.05 --out cli_ramp.csv", out, sizeof out) == 0, "%s", out);
    CHECK(read_file("cli_ramp.csv", csv, sizeof csv) > 0, "no csv");
    const char* contract = "t,x1,x2,p1A,p1B,p2A,p2B,u1,u2,q1,q2,tip_x,tip_z,F1,F2,u1_cmd,u2_cmd";
    CHECK(strncmp(csv, contract, strlen(contract)) == 0, "header: %.120s", csv);
    CHECK(count_lines(csv) == 1 + 51, "want header + 51 rows at 1 kHz over 0.05 s, got %d lines", count_lines(csv));
    // --every sets the output period.
    CHECK(run("run --quiet --scenario ramp --duration 0.05 --every 0.01 --out cli_ramp10.csv", out, sizeof out) == 0,
          "%s", out);
    read_file("cli_ramp10.csv", csv, sizeof csv);
    CHECK(count_lines(csv) == 1 + 6, "want 6 rows at 100 Hz, got %d", count_lines(csv) - 1);
}

// Krus (A-stable, R(-inf) = -1) at 20 times its step rings on the valve
// steps until a pressure leaves the physical range: exit 1, a message naming
// the state and the time, and the rows before the failure kept. (RK4 beyond
// its stability limit is refused up front: test_rk4_refused.)
static void test_blow_up_keeps_output(void) {
    static char out[8192];
    static char csv[1 << 20];
    int rc = run("run --quiet --scenario step --solver krus --dt 2e-3 --out cli_blowup.csv", out, sizeof out);
    CHECK(rc == 1, "exit %d, want 1: %s", rc, out);
    CHECK(strstr(out, "state ") && strstr(out, "t = "), "message should name state and time: %s", out);
    CHECK(strstr(out, "kept in cli_blowup.csv"), "message should say where the rows are: %s", out);
    int n = read_file("cli_blowup.csv", csv, sizeof csv);
    CHECK(n > 0 && count_lines(csv) >= 2, "rows lost: %d lines", count_lines(csv));
    CHECK(strstr(csv, "nan") == NULL && strstr(csv, "inf") == NULL, "non-finite values written");
}

static int files_equal(const char* a, const char* b) {
    FILE* fa = fopen(a, "rb");
    FILE* fb = fopen(b, "rb");
    int eq = fa && fb;
    while (eq) {
        int ca = fgetc(fa), cb = fgetc(fb);
        if (ca != cb) eq = 0;
        if (ca == EOF || cb == EOF) break;
    }
    if (fa) fclose(fa);
    if (fb) fclose(fb);
    return eq;
}

// The sandbox (contacts, rope, hook events) run twice gives byte-identical CSV.
// RK4 at the default 0.1 ms is outside its stability interval on the
// hose/chamber modes (about 5e4 1/s): refused as bad input, naming the limit,
// with no CSV written; at 10 us it runs.
static void test_rk4_refused(void) {
    static char out[8192];
    remove("cli_rk4.csv");
    int rc = run("run --quiet --scenario step --solver rk4 --duration 0.2 --out cli_rk4.csv", out, sizeof out);
    CHECK(rc == 2, "exit %d, want 2: %s", rc, out);
    CHECK(strstr(out, "rk4 is unstable at h = 0.0001 s") && strstr(out, "needs h <") && count_lines(out) == 1,
          "message: %s", out);
    rc = run("run --quiet --scenario step --solver rk4 --dt 1e-5 --duration 0.2 --out cli_rk4.csv", out, sizeof out);
    CHECK(rc == 0, "rk4 at 10 us: exit %d: %s", rc, out);
    remove("cli_rk4.csv");
}

static void test_ode_runs_are_deterministic(void) {
    static char out[8192];
    const char* args = "run --quiet --mechanics ode --world sandbox --scenario sandbox_pick_place --duration 6";
    char a[512];
    snprintf(a, sizeof a, "%s --out cli_det1.csv", args);
    CHECK(run(a, out, sizeof out) == 0, "%s", out);
    snprintf(a, sizeof a, "%s --out cli_det2.csv", args);
    CHECK(run(a, out, sizeof out) == 0, "%s", out);
    CHECK(files_equal("cli_det1.csv", "cli_det2.csv"), "two identical runs wrote different CSV");
    static char csv[4096];
    read_file("cli_det1.csv", csv, sizeof csv);
    CHECK(strstr(csv, ",hook_x,hook_y,hook_z,") && strstr(csv, "truck_tilt"), "ode extras missing: %.300s", csv);
}

// The paper's scenarios start folded (q = 100, -110 deg); on the sandbox
// the hook used to start inside the ground and the run blew up at 0.01 s.
// A pose with no room at all is bad input: one line naming the pose, exit 2.
static void test_sandbox_start_poses(void) {
    static char out[8192];
    CHECK(run("run --quiet --mechanics ode --world sandbox --scenario ramp --duration 1 --out /dev/null", out,
              sizeof out) == 0,
          "ramp on the sandbox: %s", out);
    CHECK(out[0] == 0, "no output with --quiet: %s", out);
    char a[1024];
    snprintf(a, sizeof a, "run --quiet --mechanics ode --world sandbox --scenario %s/scn_tip_low.json --out /dev/null",
             DATA);
    CHECK(run(a, out, sizeof out) == 2, "want exit 2: %s", out);
    CHECK(strstr(out, "q1 = 80.0 deg, q2 = -110.0 deg leaves no room for the rope") && count_lines(out) == 1,
          "want one line naming the pose: %s", out);
}

static void test_bad_world_and_compare_tolerance(void) {
    static char out[8192];
    int rc = run("run --quiet --mechanics ode --world " DATA "/missing_world.json --scenario ramp --out /dev/null", out,
                 sizeof out);
    CHECK(rc == 2 && strstr(out, "missing_world.json") && count_lines(out) == 1, "exit %d: %s", rc, out);
    rc = run("run --quiet --mechanics ode --scenario ramp --solver cvode --out /dev/null", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "ode"), "cvode in ode mode: exit %d: %s", rc, out);
    // compare fails (exit 1) when a difference exceeds the given tolerance.
    rc = run("compare --quiet --scenario hold --duration 1 --solvers krus,ros2 --dts 1e-4,1e-3 --tol-pressure 1e-9",
             out, sizeof out);
    CHECK(rc == 1 && strstr(out, "FAIL"), "compare beyond tolerance: exit %d: %s", rc, out);
    // --solvers overrides a common --solver cvode on both sides (both ran
    // CVODE, labelled krus and ros2, and agreed).
    rc = run("compare --quiet --scenario hold --duration 1 --solver cvode --solvers krus,ros2 --dts 1e-4,1e-3 "
             "--tol-pressure 1e-9",
             out, sizeof out);
    CHECK(rc == 1 && strstr(out, "FAIL"), "--solvers after --solver cvode: exit %d: %s", rc, out);
    rc = run("compare --quiet --scenario ramp --duration 4 --tol-stroke 0.5 --tol-pressure 1", out, sizeof out);
    CHECK(rc == 0 && strstr(out, "x1") && strstr(out, "p2B"), "lagrange vs ode within tolerance: exit %d: %s", rc,
          out);
}

int main(int argc, char** argv) {
    RUN_TEST(test_help_and_usage);
    RUN_TEST(test_bad_models);
    RUN_TEST(test_bad_scenarios);
    RUN_TEST(test_bad_set);
    RUN_TEST(test_csv_contract);
    RUN_TEST(test_blow_up_keeps_output);
    RUN_TEST(test_rk4_refused);
    RUN_TEST(test_ode_runs_are_deterministic);
    RUN_TEST(test_sandbox_start_poses);
    RUN_TEST(test_bad_world_and_compare_tolerance);
    TEST_MAIN_END();
}
