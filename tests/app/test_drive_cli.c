// test_drive_cli.c: `cranesim drive` as a user meets it: what happens when the
// display named in the environment has no server, options checked in every
// mode (exit 2, one line), write failures reported (exit 1, never "-> FILE"),
// no rates over an instant, and a report that says only what the world has.
// Each case runs the real binary; the ctest environment gives it Mesa's
// surfaceless EGL, so offscreen views work without a GPU.
#define _POSIX_C_SOURCE 200809L
#include "check.h"
#include "cli_util.h"

#include <errno.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define WDATA CRANESIM_TESTDATA "/../../world/data"


static char out[65536];

// Run `env ENV cranesim drive ARGS` with stderr merged into out. Returns the
// exit code (-1 if it did not exit normally).
static int drive(const char* env, const char* args) {
    char a[4096];
    snprintf(a, sizeof a, "drive %s", args);
    return cli_run_env(env, a, out, sizeof out);
}

// No display at all (the QA machine's case) and the offscreen driver for
// screenshots.
#define NO_DISPLAY "-u DISPLAY -u WAYLAND_DISPLAY SDL_VIDEODRIVER=offscreen"


static int file_lines(const char* path) {
    FILE* f = fopen(path, "r");
    if (!f) return -1;
    int n = 0;
    for (int c; (c = fgetc(f)) != EOF;) n += c == '\n';
    fclose(f);
    return n;
}

static long file_size(const char* path) {
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

static int occurrences(const char* s, const char* what) {
    int n = 0;
    for (const char* p = s; (p = strstr(p, what)); p += strlen(what)) ++n;
    return n;
}

// An X display number nothing listens on: no socket file and no abstract
// socket of that name (xvfb-run -a, used by another test, starts at :99).
static int dead_display(void) {
    for (int n = 4711; n < 4811; ++n) {
        char path[64], name[64];
        snprintf(path, sizeof path, "/tmp/.X11-unix/X%d", n);
        snprintf(name, sizeof name, "/tmp/.X11-unix/X%d\n", n);
        if (access(path, F_OK) == 0) continue;
        bool used = false;
        FILE* f = fopen("/proc/net/unix", "r");
        char line[512];
        while (f && fgets(line, sizeof line, f))
            if (strstr(line, name)) used = true;
        if (f) fclose(f);
        if (!used) return n;
    }
    return -1;
}

// DISPLAY names an X server that is not there: SDL used to fall back to its
// offscreen driver and run an invisible interactive session. Now it runs
// headless (scripted, with the record) and says why in one line.
static void test_dead_display_runs_headless(void) {
    const int n = dead_display();
    CHECK(n > 0, "no free display number found");
    if (n < 0) return;
    char env[256];
    snprintf(env, sizeof env, "-u SDL_VIDEODRIVER -u WAYLAND_DISPLAY DISPLAY=:%d", n);
    remove("dead_display.csv");
    int rc = drive(env, "--duration 1 --record dead_display.csv");
    char disp[32];
    snprintf(disp, sizeof disp, "DISPLAY=:%d", n);
    CHECK(rc == 0, "exit %d: %s", rc, out);
    CHECK(strstr(out, "headless") && strstr(out, "cannot open a window") && strstr(out, disp),
          "no headless fallback naming the display: %s", out);
    CHECK(!strstr(out, "joystick or keyboard"), "an interactive session nobody sees: %s", out);
    // 1 s at the headless 75 commands per second, plus the header.
    CHECK(file_lines("dead_display.csv") == 76, "record has %d lines", file_lines("dead_display.csv"));

    // The same with SDL forced onto its offscreen driver: no screen, no window.
    snprintf(env, sizeof env, "-u WAYLAND_DISPLAY SDL_VIDEODRIVER=offscreen DISPLAY=:%d", n);
    rc = drive(env, "--duration 0.3 --record dead_display.csv");
    CHECK(rc == 0 && strstr(out, "headless") && strstr(out, "has no screen"), "exit %d: %s", rc, out);

    // A screenshot was asked for: it is rendered offscreen instead.
    snprintf(env, sizeof env, "-u SDL_VIDEODRIVER -u WAYLAND_DISPLAY DISPLAY=:%d", n);
    remove("dead_display.png");
    rc = drive(env, "--screenshot dead_display.png --screenshot-at 0.2");
    CHECK(rc == 0 && strstr(out, "rendering offscreen") && strstr(out, "screenshot -> dead_display.png"),
          "exit %d: %s", rc, out);
    CHECK(file_size("dead_display.png") > 1000, "screenshot of %ld bytes", file_size("dead_display.png"));
}

// WAYLAND_DISPLAY names a socket that does not exist: headless, with the
// reason, and without libwayland's own "XDG_RUNTIME_DIR is invalid" line.
static void test_dead_wayland_runs_headless(void) {
    int rc = drive("-u SDL_VIDEODRIVER -u DISPLAY -u XDG_RUNTIME_DIR WAYLAND_DISPLAY=wayland-9",
                   "--duration 0.3 --record dead_wayland.csv");
    CHECK(rc == 0 && strstr(out, "headless") && strstr(out, "WAYLAND_DISPLAY=wayland-9"), "exit %d: %s", rc, out);
    CHECK(!strstr(out, "XDG_RUNTIME_DIR is invalid"), "libwayland's message leaked: %s", out);
}

typedef struct bad_opt {
    const char* args;
    const char* names; // the message must contain this
} bad_opt;

// Options drive cannot use are rejected in every mode, headless included,
// with exit 2 and one line naming the option, file or field.
static void test_bad_options_rejected_in_every_mode(void) {
    FILE* f = fopen("map_not_json.json", "w");
    if (f) fputs("not json\n", f), fclose(f);
    f = fopen("map_bogus_key.json", "w");
    if (f) fputs("{\"bogus\": 1}\n", f), fclose(f);
    static const bad_opt cases[] = {
        {"--solver cvode", "cvode"},
        {"--mechanics lagrange --solver cvode", "cvode"},
        {"--charts bogus", "bogus"},
        {"--charts p1A,,x1", "--charts"},
        {"--mechanics lagrange --charts slew", "slew"},
        {"--mapping /nonexistent/map.json", "/nonexistent/map.json"},
        {"--mapping map_not_json.json", "map_not_json.json"},
        {"--mapping map_bogus_key.json", "bogus"},
        {"--every 0.01", "--every"},
        {"--load 500", "--load"},                                 // the sandbox's loads are world objects
        {"--solver rk4", "rk4 is unstable"},                      // as run refuses it
        {"--record /nonexistent/dir/r.csv", "/nonexistent/dir"}, // checked before driving, not after
        {"--save-as /nonexistent/dir/m.json", "--save-as"},      // the panel's "save model" file
        {"--save-as model.txt", "must end in .json"},
    };
    // Headless by option, headless for want of a display, and offscreen.
    static const char* const modes[] = {"--headless --duration 0.2", "--duration 0.2",
                                        "--screenshot bad_opt.png --screenshot-at 0"};
    for (size_t m = 0; m < sizeof modes / sizeof modes[0]; ++m)
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
            char a[512];
            snprintf(a, sizeof a, "%s --record bad_opt.csv %s", modes[m], cases[i].args);
            int rc = drive(NO_DISPLAY, a);
            CHECK(rc == 2, "drive %s: exit %d, want 2: %s", a, rc, out);
            CHECK(strstr(out, cases[i].names) != NULL, "drive %s: message does not name %s: %s", a, cases[i].names,
                  out);
            CHECK(cli_count_lines(out) == 1, "drive %s: want one line, got: %s", a, out);
        }
}

// A record or screenshot that cannot be written: exit 1, the file and the
// system's reason on stderr, and no "-> FILE" line claiming it was written.
static void test_write_failures_reported(void) {
    CHECK(access("/dev/full", W_OK) == 0, "/dev/full is needed to simulate a full disk");
    const char* nospace = strerror(ENOSPC);
    int rc = drive(NO_DISPLAY, "--headless --duration 0.3 --record /dev/full");
    CHECK(rc == 1, "headless record to /dev/full: exit %d: %s", rc, out);
    CHECK(strstr(out, "cranesim drive: cannot write /dev/full: ") && strstr(out, nospace), "message: %s", out);
    CHECK(!strstr(out, "record -> /dev/full"), "claims the record was written: %s", out);

    rc = drive(NO_DISPLAY, "--screenshot /dev/full --screenshot-at 0.1");
    CHECK(rc == 1, "screenshot to /dev/full: exit %d: %s", rc, out);
    CHECK(strstr(out, "cranesim drive: cannot write /dev/full: ") && strstr(out, nospace), "message: %s", out);
    CHECK(!strstr(out, "screenshot -> /dev/full"), "claims the screenshot was written: %s", out);

    // The offscreen view's record.
    rc = drive(NO_DISPLAY, "--screenshot write_ok.png --screenshot-at 0.3 --record /dev/full");
    CHECK(rc == 1, "offscreen record to /dev/full: exit %d: %s", rc, out);
    CHECK(strstr(out, "cranesim drive: cannot write /dev/full: ") && strstr(out, nospace), "message: %s", out);
    CHECK(!strstr(out, "record -> /dev/full"), "claims the record was written: %s", out);

    // And when all is well, both are said.
    remove("write_ok.csv");
    rc = drive(NO_DISPLAY, "--screenshot write_ok.png --screenshot-at 0.3 --record write_ok.csv");
    CHECK(rc == 0 && strstr(out, "screenshot -> write_ok.png") && strstr(out, "record -> write_ok.csv"),
          "exit %d: %s", rc, out);
    // The rows reported are the rows in the file (one per tick: how many
    // depends on the machine's speed), after the header.
    long rows = -1;
    const char* r = strstr(out, "record -> write_ok.csv (");
    if (r) rows = strtol(r + strlen("record -> write_ok.csv ("), NULL, 10);
    CHECK(rows >= 1 && file_lines("write_ok.csv") == rows + 1, "%ld rows reported, %d lines in the file", rows,
          file_lines("write_ok.csv"));
}

// A screenshot at t = 0 ends the session within milliseconds: no rate over
// that (it read millions of fps).
static void test_no_rates_over_an_instant(void) {
    int rc = drive(NO_DISPLAY, "--screenshot instant.png --screenshot-at 0");
    CHECK(rc == 0, "exit %d: %s", rc, out);
    CHECK(strstr(out, "(n/a fps)") && strstr(out, "(n/a Hz)"), "rates over an instant: %s", out);
}

// The validation world (column and booms only) is named as such, is driven by
// the 2-DOF demo, and its report has no slew, load, truck or hook.
static void test_validation_world_report(void) {
    int rc = drive(NO_DISPLAY, "--world validation --screenshot validation.png --screenshot-at 0.2");
    CHECK(rc == 0 && strstr(out, "in the validation world") && !strstr(out, "sandbox"), "exit %d: %s", rc, out);

    rc = drive(NO_DISPLAY, "--headless --world validation --duration 0.5 --record validation.csv");
    CHECK(rc == 0, "exit %d: %s", rc, out);
    CHECK(strstr(out, "world: validation") && strstr(out, "drive_demo"), "world or operator: %s", out);
    static const char* const absent[] = {"slew", "load at", "truck tilt", "hook"};
    for (int i = 0; i < 4; ++i) CHECK(!strstr(out, absent[i]), "validation report mentions '%s': %s", absent[i], out);
    CHECK(strstr(out, "record -> validation.csv"), "%s", out);

    // --help gives drive's own defaults (the sandbox and its operator), not
    // run's (lagrange, ramp), and each option once.
    rc = drive("", "--help");
    CHECK(rc == 0 && strstr(out, "sandbox (default)") && strstr(out, "default sandbox_pick_place") &&
              !strstr(out, "(default ramp)") && !strstr(out, "lagrange (analytic 2-DOF, default)") &&
              occurrences(out, "  --duration") == 1,
          "drive --help: %s", out);

    // A scenario that slews, driven where nothing slews: said once, not
    // dropped silently (the slew commands of sandbox_wall and sandbox_swing).
    rc = drive(NO_DISPLAY, "--headless --mechanics lagrange --scenario sandbox_wall --duration 0.3");
    // The stepped analytic crane does not slew; a scripted run does, by the
    // model's slew drive, where the scenario does not work the hook.
    CHECK(rc == 0 &&
              occurrences(out, "slews the crane, which the lagrange 2-DOF crane has not when driven: its slew is "
                               "ignored (the sandbox has one: --mechanics ode --world sandbox; cranesim run "
                               "--mechanics lagrange slews it)") == 1,
          "exit %d: %s", rc, out);
    rc = drive(NO_DISPLAY, "--headless --mechanics lagrange --scenario sandbox_pick_place --duration 0.3");
    CHECK(rc == 0 && occurrences(out, "slews the crane, which the lagrange 2-DOF crane has not: its slew is ignored "
                                      "(the sandbox has one: --mechanics ode --world sandbox)\n") == 1,
          "exit %d: %s", rc, out);
    rc = drive(NO_DISPLAY, "--headless --world validation --scenario sandbox_swing --duration 0.3");
    CHECK(rc == 0 && occurrences(out, "which the validation world has not: its slew is ignored") == 1, "exit %d: %s",
          rc, out);
    rc = drive(NO_DISPLAY, "--headless --scenario sandbox_swing --duration 0.3");
    CHECK(rc == 0 && !strstr(out, "slew is ignored"), "in the sandbox: exit %d: %s", rc, out);

    // A scenario with hook events: said once that there is no hook.
    rc = drive(NO_DISPLAY, "--headless --world validation --scenario sandbox_pick_place --duration 1 "
                           "--record validation.csv");
    CHECK(rc == 0 && occurrences(out, "has no hook") == 1 && !strstr(out, "found no load"), "exit %d: %s", rc, out);

    // The sandbox still reports all it has.
    rc = drive(NO_DISPLAY, "--headless --duration 1 --record sandbox.csv");
    CHECK(rc == 0, "exit %d: %s", rc, out);
    static const char* const present[] = {"world: sandbox", "hook picked up", "slew", "load at", "truck tilt"};
    for (int i = 0; i < 5; ++i) CHECK(strstr(out, present[i]), "sandbox report lacks '%s': %s", present[i], out);
}

// bench --config drive runs the world --world names and says so: the name,
// and the bodies of its last snapshot, counted by hand from the world files.
// Both worlds have 26 bodies of their own (terrain, truck, 4 wheels, 4
// outriggers of pad, beam and leg, column, 2 booms, 4 rope links, hook);
// the sandbox adds 3 loads and 12 obstacles (41), the site its terrain mesh
// (the dock), 2 loads and 3 obstacles (32).
static void test_bench_drive_world(void) {
    static const struct {
        const char* opt;
        const char* world;
        int bodies;
    } k[] = {{"", "sandbox", 41}, {"--world site", "site", 32}};
    long tris[2] = {0, 0};
    for (int i = 0; i < 2; ++i) {
        char a[256], want[64];
        snprintf(a, sizeof a, "bench --config drive --duration 1 %s", k[i].opt);
        int rc = cli_run_env(NO_DISPLAY, a, out, sizeof out);
        snprintf(want, sizeof want, "\"world\":\"%s\"", k[i].world);
        const char* b = strstr(out, "\"bodies\":");
        const char* t = strstr(out, "\"triangles\":");
        CHECK(rc == 0 && strstr(out, want) && b && atoi(b + 9) == k[i].bodies && t,
              "%s: want world %s with %d bodies: exit %d: %s", a, k[i].world, k[i].bodies, rc, out);
        CHECK(!strstr(out, "has no effect"), "%s: a note that --world does nothing: %s", a, out);
        if (t) tris[i] = atol(t + 12);
    }
    CHECK(tris[0] > 0 && tris[1] > 0 && tris[0] != tris[1], "the same triangles in both worlds: %ld", tris[0]);
    // Only sandbox-type worlds: the pick-and-place needs a hook and loads.
    int rc = cli_run_env(NO_DISPLAY, "bench --config drive --duration 1 --world validation", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--world validation") && cli_count_lines(out) == 1, "exit %d: %s", rc, out);
    rc = cli_run_env(NO_DISPLAY, "bench --config drive --duration 1 --world nosuch", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "nosuch") && cli_count_lines(out) == 1, "exit %d: %s", rc, out);
}

// A crane chain in the window (offscreen for a screenshot): it drives; its
// limiter asked for by name runs when the model has a rating (loader10) and
// is refused in one line when it has none (the 8-function chain), as the
// headless drive does.
static void test_chain_window(void) {
    int rc = drive(NO_DISPLAY, "--model loader10 --scenario loader10_cycle --screenshot chain_window.png "
                               "--screenshot-at 0.2");
    CHECK(rc == 0 && strstr(out, "screenshot -> chain_window.png"), "exit %d: %s", rc, out);
    remove("chain_window.png");
    rc = drive(NO_DISPLAY, "--model loader10 --scenario loader10_cycle --rcl on --screenshot chain_rcl.png "
                           "--screenshot-at 0.2");
    CHECK(rc == 0 && strstr(out, "screenshot -> chain_rcl.png"), "exit %d: %s", rc, out);
    remove("chain_rcl.png");
    rc = drive(NO_DISPLAY, "--model " WDATA "/chain_8fn_10link.json --rcl on --screenshot never.png");
    const char* l = strstr(out, "cranesim drive: --rcl on: chain_8fn_10link.json: ");
    CHECK(rc == 2 && l && cli_count_lines(l) == 1 && strstr(l, "rated"), "exit %d: %s", rc, out);
}

// --help: the keys come last, after the shared options.
static void test_help_keys_last(void) {
    int rc = drive("", "--help");
    const char* keys = strstr(out, "keys:");
    const char* shared = strstr(out, "--quiet");
    CHECK(rc == 0 && keys && shared && keys > shared, "keys before the shared options: %s", out);
}

// The headless drive and run are two drivers of one engine with one
// scripted operator: on the ode world at one frame per ODE step (1000
// frames/s, 1 ms) the drive's record is the run's CSV, line for line, after
// the run's t = 0 row (the drive records each frame's end). Checked in the
// sandbox (truck, slew, hook) for 1.5 s of wall time (the commands move from 1 s).
static void test_drive_record_is_the_run(void) {
    static char run_csv[1 << 21], drv_csv[1 << 21];
    remove("drv_same_run.csv");
    remove("drv_same_drive.csv");
    CHECK(cli_run("run --quiet --mechanics ode --world sandbox --scenario sandbox_pick_place --duration 1.5 "
                  "--out drv_same_run.csv",
                  out, sizeof out) == 0,
          "run: %s", out);
    CHECK(drive(NULL, "--headless --quiet --world sandbox --scenario sandbox_pick_place --duration 1.5 "
                      "--frame-rate 1000 --record drv_same_drive.csv") == 0,
          "drive: %s", out);
    const long nr = cli_read_file("drv_same_run.csv", run_csv, sizeof run_csv);
    const long nd = cli_read_file("drv_same_drive.csv", drv_csv, sizeof drv_csv);
    CHECK(nr > 0 && nd > 0, "files: run %ld, drive %ld bytes", nr, nd);
    if (nr <= 0 || nd <= 0) return;
    CHECK(cli_count_lines(run_csv) == 1502 && cli_count_lines(drv_csv) == 1501, "lines: run %d, drive %d",
          cli_count_lines(run_csv), cli_count_lines(drv_csv));
    // Header, then the run's second row on against the drive's first.
    const char* r = strchr(run_csv, '\n');
    const char* d = strchr(drv_csv, '\n');
    CHECK(r && d && r - run_csv == d - drv_csv && !memcmp(run_csv, drv_csv, (size_t)(r - run_csv)),
          "the headers differ");
    if (r) r = strchr(r + 1, '\n');
    CHECK(r && d && strcmp(r + 1, d + 1) == 0, "the drive's record is not the run's CSV");
    remove("drv_same_run.csv");
    remove("drv_same_drive.csv");
}

// The same with fault events: hose_burst (the lift chamber bursts at 2 s)
// on the validation world. The drive plays the faults through engine_play,
// the run through the ode backend's loop: the same rows, and the boom sinks
// in both (the burst reached the drive's circuit).
static void test_drive_plays_faults(void) {
    static char run_csv[1 << 21], drv_csv[1 << 21];
    remove("drv_fault_run.csv");
    remove("drv_fault_drive.csv");
    CHECK(cli_run("run --quiet --mechanics ode --world validation --scenario hose_burst --duration 3 "
                  "--out drv_fault_run.csv",
                  out, sizeof out) == 0,
          "run: %s", out);
    CHECK(drive(NULL, "--headless --quiet --mechanics ode --world validation --scenario hose_burst --duration 3 "
                      "--frame-rate 1000 --record drv_fault_drive.csv") == 0,
          "drive: %s", out);
    const long nr = cli_read_file("drv_fault_run.csv", run_csv, sizeof run_csv);
    const long nd = cli_read_file("drv_fault_drive.csv", drv_csv, sizeof drv_csv);
    CHECK(nr > 0 && nd > 0, "files: run %ld, drive %ld bytes", nr, nd);
    if (nr <= 0 || nd <= 0) return;
    const char* r = strchr(run_csv, '\n');
    const char* d = strchr(drv_csv, '\n');
    if (r) r = strchr(r + 1, '\n'); // the run's t = 0 row
    CHECK(r && d && strcmp(r + 1, d + 1) == 0, "the drive's record is not the run's CSV");
    // Last row: lift stroke x1 (column 2) below its 418.1 mm before the burst.
    long i = nd - 2; // before the final newline
    while (i > 0 && drv_csv[i] != '\n') --i;
    const char* last = drv_csv + i;
    double t = 0, x1 = 1;
    CHECK(last && sscanf(last + 1, "%lf,%lf", &t, &x1) == 2 && x1 < 0.40, "the boom did not sink: t %g x1 %g", t, x1);
    remove("drv_fault_run.csv");
    remove("drv_fault_drive.csv");
}

static int write_text(const char* path, const char* text) {
    FILE* f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

// The headless drive says what the scenario's hook did and only that (issue
// 25, item 29: a drive whose hook never reached a load printed "hook released
// the load" at each of its 16 release events): a release of a load that was
// on the hook names it; a release with nothing on the hook is said once; an
// attach while the load is already on the hook says nothing.
static void test_hook_report(void) {
    // Slewed to -90 deg the hook hangs 2 m from the nearest load (reach 0.5 m).
    CHECK(write_text("drv_hook_empty.json",
                     "{\"name\": \"hook_empty\", \"duration\": 0.8, "
                     "\"initial\": {\"q1_deg\": 125, \"q2_deg\": -60, \"slew_deg\": -90}, \"commands\": {}, "
                     "\"hook\": [[0.1, \"attach\"], [0.2, \"release\"], [0.3, \"release\"], [0.4, \"attach\"], "
                     "[0.5, \"release\"], [0.6, \"release\"]]}\n") == 0,
          "scenario file");
    int rc = drive(NO_DISPLAY, "--headless --scenario drv_hook_empty.json");
    CHECK(rc == 0 && !strstr(out, "released") && occurrences(out, "releases the hook with nothing on it") == 1 &&
              occurrences(out, "hook found no load in reach") == 2,
          "exit %d: %s", rc, out);
    // The pick-and-place's start: load_200 under the hook.
    CHECK(write_text("drv_hook_load.json",
                     "{\"name\": \"hook_load\", \"duration\": 0.8, "
                     "\"initial\": {\"q1_deg\": 117.3, \"q2_deg\": -65.8, \"slew_deg\": -60}, \"commands\": {}, "
                     "\"hook\": [[0.1, \"attach\"], [0.2, \"attach\"], [0.4, \"release\"], [0.5, \"release\"]]}\n") ==
              0,
          "scenario file");
    rc = drive(NO_DISPLAY, "--headless --scenario drv_hook_load.json");
    CHECK(rc == 0 && occurrences(out, "hook picked up load_200 (200 kg)") == 1 &&
              occurrences(out, "hook released load_200 (200 kg)") == 1 && occurrences(out, "released") == 1 &&
              occurrences(out, "releases the hook with nothing on it") == 1,
          "exit %d: %s", rc, out);
    remove("drv_hook_empty.json");
    remove("drv_hook_load.json");
}

int main(int argc, char** argv) {
    RUN_TEST(test_dead_display_runs_headless);
    RUN_TEST(test_dead_wayland_runs_headless);
    RUN_TEST(test_bad_options_rejected_in_every_mode);
    RUN_TEST(test_write_failures_reported);
    RUN_TEST(test_no_rates_over_an_instant);
    RUN_TEST(test_validation_world_report);
    RUN_TEST(test_help_keys_last);
    RUN_TEST(test_bench_drive_world);
    RUN_TEST(test_drive_record_is_the_run);
    RUN_TEST(test_drive_plays_faults);
    RUN_TEST(test_hook_report);
    RUN_TEST(test_chain_window);
    TEST_MAIN_END();
}
