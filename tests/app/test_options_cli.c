// test_options_cli.c: option hygiene through the binary (cli_util.h): a value
// option given twice is refused unless it is documented as repeatable, a
// window-only option of a headless drive gets a note naming it, compare says
// when a design pair and a setting pair are mixed, and refuses --dt beside
// --dts.
#include "check.h"
#include "cli_util.h"

#include <string.h>

static char out[1 << 16];

static void test_repeated_option_refused(void) {
    static const struct {
        const char* args;
        const char* opt;
    } cases[] = {
        {"run --scenario hold --duration 0.1 --dt 1e-5 --dt 1e-4 --out /dev/null -q", "--dt"},
        {"run --scenario hold --scenario ramp --duration 0.1 --out /dev/null -q", "--scenario"},
        {"run --scenario hold --duration 0.1 --out a.csv --out /dev/null -q", "--out"},
        {"compare --scenario hold --duration 0.1 --solvers krus,ros2 --solvers krus,rk4 -q", "--solvers"},
        {"sweep --scenario hold --duration 0.1 --param hydraulics.fluid.bulk_modulus=1e9:1.2e9:2 --threads 1 "
         "--threads 2 --out /dev/null -q",
         "--threads"},
        // The = form is the same option.
        {"run --scenario hold --duration 0.1 --dt=1e-5 --dt 1e-4 --out /dev/null -q", "--dt"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        const int rc = cli_run(cases[k].args, out, sizeof out);
        CHECK(rc == 2 && strstr(out, cases[k].opt) && strstr(out, "given twice") && cli_count_lines(out) == 1,
              "%s: rc %d: %s", cases[k].args, rc, out);
    }
    // Documented as repeatable: --set (every command), sweep's --param.
    int rc = cli_run("run --scenario hold --duration 0.1 --set hydraulics.fluid.bulk_modulus=1.1e9 "
                     "--set hydraulics.components.lift_cyl.bore=0.1 --out /dev/null -q",
                     out, sizeof out);
    CHECK(rc == 0 && !strstr(out, "twice"), "--set twice: rc %d: %s", rc, out);
    rc = cli_run("sweep --scenario hold --duration 0.1 --param hydraulics.fluid.bulk_modulus=1e9:1.2e9:2 "
                 "--param hydraulics.components.lift_cyl.bore=0.1:0.11:2 --metrics peak_p1A --threads 1 "
                 "--out /dev/null -q",
                 out, sizeof out);
    CHECK(rc == 0 && !strstr(out, "twice"), "--param twice: rc %d: %s", rc, out);
}

static void test_headless_window_options_noted(void) {
    int rc = cli_run("drive --headless --mechanics lagrange --duration 0.2 --readouts p1A --size 800x600 --charts x1",
                     out, sizeof out);
    CHECK(rc == 0, "rc %d: %s", rc, out);
    const char* note = strstr(out, "note: ");
    CHECK(note && strstr(note, "--charts") && strstr(note, "--readouts") && strstr(note, "--size") &&
              strstr(note, "no effect headless"),
          "%s", out);
    // Without them: no such note.
    rc = cli_run("drive --headless --mechanics lagrange --duration 0.2", out, sizeof out);
    CHECK(rc == 0 && !strstr(out, "no effect headless"), "rc %d: %s", rc, out);
}

static void test_compare_mixed_pairs(void) {
    int rc = cli_run("compare --scenario hold --duration 0.1 --set-b hydraulics.components.lift_cyl.bore=0.11 "
                     "--solvers krus,ros2 -q",
                     out, sizeof out);
    CHECK(rc == 0 && strstr(out, "note: A and B differ in design") && strstr(out, "--solvers"), "rc %d: %s", rc, out);
    rc = cli_run("compare --scenario hold --duration 0.1 --set-b hydraulics.components.lift_cyl.bore=0.11 -q", out,
                 sizeof out);
    CHECK(rc == 0 && !strstr(out, "differ in design"), "one change only: rc %d: %s", rc, out);
    rc = cli_run("compare --scenario hold --duration 0.1 --solvers krus,ros2 --dts 1e-4,2e-4 --dt 1e-5 -q", out,
                 sizeof out);
    CHECK(rc == 2 && strstr(out, "--dt and --dts") && cli_count_lines(out) == 1, "rc %d: %s", rc, out);
}

// A flag takes =1/=true (the flag) and =0/=false (not given); any other
// value says the flag takes none. "--quiet=1" was an unknown option.
static void test_flag_values(void) {
    // Quiet: no summary on stdout+stderr but for notes; not quiet: a summary.
    int rc = cli_run("run --scenario hold --duration 0.05 --out /dev/null --quiet=1", out, sizeof out);
    CHECK(rc == 0 && !strstr(out, "unknown") && !strstr(out, "energy:"), "--quiet=1: rc %d: %s", rc, out);
    rc = cli_run("run --scenario hold --duration 0.05 --out /dev/null --quiet=true --dense-jac=true", out, sizeof out);
    CHECK(rc == 0 && !strstr(out, "energy:"), "--quiet=true: rc %d: %s", rc, out);
    rc = cli_run("run --scenario hold --duration 0.05 --out /dev/null --quiet=0", out, sizeof out);
    CHECK(rc == 0 && strstr(out, "energy:"), "--quiet=0 is not quiet: rc %d: %s", rc, out);
    rc = cli_run("run --scenario hold --duration 0.05 --out /dev/null --quiet=false", out, sizeof out);
    CHECK(rc == 0 && strstr(out, "energy:"), "--quiet=false is not quiet: rc %d: %s", rc, out);
    rc = cli_run("run --scenario hold --duration 0.05 --out /dev/null --quiet=yes", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--quiet takes no value") && strstr(out, "'yes'") && cli_count_lines(out) == 1,
          "--quiet=yes: rc %d: %s", rc, out);
    // A command's own flag, and an unknown one stays unknown (=0 too: never
    // dropped without a word).
    rc = cli_run("sweep --scenario hold --duration 0.05 --param hydraulics.fluid.bulk_modulus=1e9:1.2e9:2 "
                 "--threads 1 --out /dev/null --fail-fast=1 -q",
                 out, sizeof out);
    CHECK(rc == 0 && !strstr(out, "unknown"), "--fail-fast=1: rc %d: %s", rc, out);
    rc = cli_run("run --scenario hold --duration 0.05 --out /dev/null --nosuch=0", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "unknown option '--nosuch=0'"), "--nosuch=0: rc %d: %s", rc, out);
    rc = cli_run("run --scenario hold --duration 0.05 --out /dev/null --fail-fast=0", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "unknown option"), "run has no --fail-fast: rc %d: %s", rc, out);
}

// An unknown backend name: one line naming the option, the name and the
// known ones, exit 2, before anything runs (issue 26: never run as another
// backend). Every command that takes a backend.
static void test_unknown_backend_refused(void) {
    static const struct {
        const char* args;
        const char* want;
    } cases[] = {
        {"run --mechanics foo --scenario hold --duration 0.1 --out /dev/null -q",
         "cranesim: --mechanics: unknown backend 'foo' (known: lagrange, ode)"},
        {"compare --mechanics foo --scenario hold --duration 0.1 -q",
         "cranesim: --mechanics: unknown backend 'foo' (known: lagrange, ode)"},
        {"compare --backends lagrange,bar --scenario hold --duration 0.1 -q",
         "cranesim: --backends: unknown backend 'bar' (known: lagrange, ode)"},
        {"sweep --mechanics Ode --scenario hold --duration 0.1 --param hydraulics.fluid.bulk_modulus=1e9:1.2e9:2 "
         "--out /dev/null -q",
         "cranesim: --mechanics: unknown backend 'Ode' (known: lagrange, ode)"},
        {"drive --headless --mechanics mujoco --duration 0.1",
         "cranesim: --mechanics: unknown backend 'mujoco' (known: lagrange, ode)"},
        {"serve --mechanics foo --listen 127.0.0.1:0",
         "cranesim: --mechanics: unknown backend 'foo' (known: lagrange, ode)"},
        {"study --mechanics foo", "cranesim: --mechanics: unknown backend 'foo' (known: lagrange, ode)"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        const int rc = cli_run(cases[k].args, out, sizeof out);
        CHECK(rc == 2 && cli_count_lines(out) == 1 && !strncmp(out, cases[k].want, strlen(cases[k].want)),
              "%s: rc %d: %s", cases[k].args, rc, out);
    }
    // The known names still run.
    int rc = cli_run("run --mechanics lagrange --scenario hold --duration 0.05 --out /dev/null -q", out, sizeof out);
    CHECK(rc == 0, "lagrange: rc %d: %s", rc, out);
    rc = cli_run("run --mechanics ode --scenario hold --duration 0.05 --out /dev/null -q", out, sizeof out);
    CHECK(rc == 0, "ode: rc %d: %s", rc, out);
}

int main(int argc, char** argv) {
    RUN_TEST(test_repeated_option_refused);
    RUN_TEST(test_headless_window_options_noted);
    RUN_TEST(test_compare_mixed_pairs);
    RUN_TEST(test_flag_values);
    RUN_TEST(test_unknown_backend_refused);
    TEST_MAIN_END();
}
