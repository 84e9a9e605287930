// test_robust_cli.c: `cranesim` when a run goes wrong or is cut short:
// capped durations, output files replaced only by a run that wrote rows,
// interrupted runs, a scenario run in its own world.
#include "check.h"
#include "cli_util.h"

#include <dirent.h>
#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>





// A step far too small is refused in one line naming the option given: no
// note with a 300-digit wall-time estimate before it, and --dt-ode named as
// --dt-ode (the hydraulic sub-step is min(--dt, --dt-ode)).
static void test_tiny_steps(void) {
    static char out[8192];
    int rc = cli_run("run --dt 1e-300 --out /dev/null", out, sizeof out);
    CHECK(rc == 2 && cli_count_lines(out) == 1 && strstr(out, "--dt 1e-300 s over 20 s"), "exit %d: %s", rc, out);
    rc = cli_run("run --mechanics ode --dt-ode 1e-300 --out /dev/null", out, sizeof out);
    CHECK(rc == 2 && cli_count_lines(out) == 1 && strstr(out, "--dt-ode 1e-300 s over 20 s") &&
              strstr(out, "use a larger --dt-ode"),
          "exit %d: %s", rc, out);
}

// Durations and output periods beyond 1e6 s are refused up front (exit 2,
// range and unit named, the old file untouched): before, --duration 1e300
// made the row count wrap and the run exit 0 having simulated nothing.
static void test_duration_caps(void) {
    static char out[8192], buf[256];
    const char* const cases[] = {
        "run --quiet --duration 1e300 --out cap.csv",
        "run --quiet --every 1e300 --out cap.csv",
        "run --quiet --mechanics ode --duration 1e300 --out cap.csv",
        "drive --headless --quiet --duration 1e300 --record cap.csv",
        "drive --headless --quiet --duration 0.1 --screenshot-at 1e300 --record cap.csv",
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        cli_write_file("cap.csv", "old\n");
        const int rc = cli_run(cases[i], out, sizeof out);
        CHECK(rc == 2, "%s: exit %d: %s", cases[i], rc, out);
        CHECK(strstr(out, "1e6") && strstr(out, " s") &&
                  (strstr(out, "--duration") || strstr(out, "--every") || strstr(out, "--screenshot-at")),
              "%s: %s", cases[i], out);
        CHECK(cli_read_file("cap.csv", buf, sizeof buf) == 4 && !strcmp(buf, "old\n"), "%s: file now '%s'", cases[i],
              buf);
    }
    // An output period finer than a row per picosecond of the run.
    const int rc = cli_run("run --quiet --solver rodas3 --every 1e-300 --out cap.csv", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--every"), "exit %d: %s", rc, out);
}

// The temporary file a run writes its CSV to before it replaces NAME
// (".NAME.XXXXXX" in the same folder), or "" when there is none.
static void find_temp(const char* name, char* out, size_t n) {
    out[0] = 0;
    DIR* d = opendir(".");
    char pre[256];
    snprintf(pre, sizeof pre, ".%s.", name);
    for (struct dirent* e; d && (e = readdir(d));)
        if (!strncmp(e->d_name, pre, strlen(pre))) snprintf(out, n, "%s", e->d_name);
    if (d) closedir(d);
}

// Remove temporaries an earlier, killed test run may have left.
static void remove_temps(const char* name) {
    char tmp[256];
    for (find_temp(name, tmp, sizeof tmp); tmp[0]; find_temp(name, tmp, sizeof tmp)) remove(tmp);
}

// Start `cranesim run ... --out name` as a child (stderr to errfile) and
// wait until its CSV has rows in the temporary file; returns the pid.
static pid_t start_run(const char* name, const char* errfile) {
    fflush(stdout); // a child that reopens stdout would write the buffer again
    pid_t pid = fork();
    if (pid == 0) {
        FILE* e = freopen(errfile, "w", stderr);
        (void)e;
        execl(cli_bin(), cli_bin(), "run", "--quiet", "--scenario", "ramp", "--duration", "5000", "--out", name, (char*)NULL);
        _exit(127);
    }
    // Waiting, not timing: the run writes its first rows within milliseconds;
    // give it up to 20 s on a loaded machine.
    char tmp[256];
    struct stat st;
    for (int i = 0; i < 2000; ++i) {
        find_temp(name, tmp, sizeof tmp);
        if (tmp[0] && stat(tmp, &st) == 0 && st.st_size > 4096) break;
        nanosleep(&(struct timespec){0, 10000000L}, NULL);
    }
    return pid;
}

// Every line of the CSV text ends in a newline and has the header's number
// of fields; returns the number of data rows, or -1.
static long whole_rows(const char* text) {
    const char* nl = strchr(text, '\n');
    if (!nl || strncmp(text, "t,x1,x2,", 8)) return -1;
    int fields = 1;
    for (const char* p = text; p < nl; ++p) fields += *p == ',';
    long rows = 0;
    for (const char* p = nl + 1; *p; ++rows) {
        const char* e = strchr(p, '\n');
        if (!e) return -1; // a cut line
        int f = 1;
        for (const char* q = p; q < e; ++q) f += *q == ',';
        if (f != fields) return -1;
        p = e + 1;
    }
    return rows;
}

// While a run is under way the previous CSV is intact (the rows go to a
// temporary file in the same folder); SIGINT or SIGTERM then stops it with
// every row so far, whole lines and header, under the final name, a one-line
// message and exit 128 + the signal. Before, the file was truncated at the
// first row and the signal killed the process mid-line.
static void test_interrupted_run(void) {
    static const int sigs[2] = {SIGINT, SIGTERM};
    static char buf[1 << 24], err[4096];
    for (int k = 0; k < 2; ++k) {
        cli_write_file("intr.csv", "old\n");
        remove_temps("intr.csv");
        const pid_t pid = start_run("intr.csv", "intr.err");
        CHECK(pid > 0, "fork");
        if (pid <= 0) return;
        char tmp[256];
        find_temp("intr.csv", tmp, sizeof tmp);
        CHECK(tmp[0] != 0, "no temporary CSV while the run writes rows");
        CHECK(cli_read_file("intr.csv", buf, sizeof buf) == 4 && !strcmp(buf, "old\n"),
              "the previous CSV changed while the run was under way: '%.40s'", buf);
        kill(pid, sigs[k]);
        int st = 0;
        waitpid(pid, &st, 0);
        CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 128 + sigs[k], "signal %d: status %#x (want exit %d)", sigs[k], st,
              128 + sigs[k]);
        cli_read_file("intr.err", err, sizeof err);
        CHECK(strstr(err, "interrupted") && strstr(err, "at t = ") && strstr(err, "rows kept in intr.csv"), "%s", err);
        const long got = cli_read_file("intr.csv", buf, sizeof buf);
        const long rows = got > 0 ? whole_rows(buf) : -1;
        CHECK(rows > 1, "signal %d: the CSV is not whole lines with a header (%ld bytes)", sigs[k], got);
        // The message's row count is the file's.
        char want[64];
        snprintf(want, sizeof want, "; %ld rows kept", rows);
        CHECK(strstr(err, want) != NULL, "%s (file has %ld rows)", err, rows);
        find_temp("intr.csv", tmp, sizeof tmp);
        CHECK(tmp[0] == 0, "temporary file %s left behind", tmp);
    }
}

// A run that fails at runtime keeps its rows under the final name (exit 1);
// a refused one (exit 2) leaves the previous file as it was.
static void test_failed_run_keeps_rows(void) {
    static char out[8192], buf[1 << 20];
    cli_write_file("fail.csv", "old\n");
    int rc = cli_run("run --quiet --scenario hold --duration 0.05 --set nonsense=1 --out fail.csv", out, sizeof out);
    CHECK(rc == 2 && cli_read_file("fail.csv", buf, sizeof buf) == 4, "refused run: exit %d, file '%.20s'", rc, buf);
    // 10 ms hydraulic steps in the ode world: the pump line goes far below
    // absolute zero in the first step (test_robust.c, test_live_checks),
    // unless the step is retried in shorter ones (then it runs through).
    rc = cli_run("run --quiet --mechanics ode --scenario step --dt-ode 0.01 --dt 0.01 --every 0.01 --no-retry --no-step-probe"
                 " --out fail.csv",
                 out, sizeof out);
    CHECK(rc == 1 && strstr(out, "kept in fail.csv"), "exit %d: %s", rc, out);
    CHECK(cli_read_file("fail.csv", buf, sizeof buf) > 0 && whole_rows(buf) == 1, "failed run's rows: '%.80s'", buf);
}

// Peak resident set [KB] of one cranesim run, measured in a child of its
// own: RUSAGE_CHILDREN is the largest over every child waited for, so in
// this process it would also count the earlier tests' runs. -1 on failure.
static long peak_rss_kb(const char* args, int* rc) {
    int fd[2];
    if (pipe(fd)) return -1;
    fflush(stdout); // a child that reopens stdout would write the buffer again
    const pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        static char out[8192];
        const int r = cli_run(args, out, sizeof out);
        struct rusage ru;
        getrusage(RUSAGE_CHILDREN, &ru);
        const long v[2] = {ru.ru_maxrss, r};
        _exit(write(fd[1], v, sizeof v) == (ssize_t)sizeof v ? 0 : 1);
    }
    close(fd[1]);
    long v[2] = {-1, -1};
    const ssize_t got = read(fd[0], v, sizeof v);
    close(fd[0]);
    waitpid(pid, NULL, 0);
    *rc = got == (ssize_t)sizeof v ? (int)v[1] : -1;
    return got == (ssize_t)sizeof v ? v[0] : -1;
}

// `run` without --plot keeps no rows in memory: 200,001 rows at 0.1 ms on
// `ramp` peaked at 77 MB resident (40 doubles a row, capacity doubling) before;
// now the process stays near its fixed size (17.7 MB measured in Release:
// ODE, the model, stdio; about 51 MB under AddressSanitizer, whose shadow
// memory scales the whole process). So the bound is on the growth: the full
// run against the same run cut to 0.05 s (501 rows), which the 64 MB of
// kept rows would exceed by far, with or without the sanitizer.
static void test_run_memory(void) {
    int rc_short = -1, rc_long = -1;
    const long kb_short = peak_rss_kb("run --quiet --scenario ramp --duration 0.05 --every 1e-4 --out /dev/null", &rc_short);
    const long kb_long = peak_rss_kb("run --quiet --scenario ramp --every 1e-4 --out /dev/null", &rc_long);
    CHECK(rc_short == 0 && rc_long == 0, "exit %d and %d", rc_short, rc_long);
    printf("  peak RSS: 0.05 s %ld KB, 20 s %ld KB\n", kb_short, kb_long);
    CHECK(kb_short > 0 && kb_long > 0 && kb_long - kb_short < 8 * 1024,
          "peak RSS grew from %ld KB (0.05 s) to %ld KB (20 s, 200,001 rows) without --plot", kb_short, kb_long);
}

// A sandbox scenario runs in the sandbox: `run --scenario sandbox_wall` used
// to run the 2-DOF lagrange crane and drop the slew commands without a word.
// Asked to run it where it cannot (lagrange, the validation world), run and
// compare refuse and say how.
static void test_scenario_world(void) {
    static char out[8192], buf[1 << 20];
    int rc = cli_run("run --quiet --scenario sandbox_wall --duration 1.5 --every 0.5 --out world.csv", out, sizeof out);
    CHECK(rc == 0 && strstr(out, "--mechanics ode --world sandbox"), "exit %d: %s", rc, out);
    CHECK(cli_read_file("world.csv", buf, sizeof buf) > 0 && strstr(buf, ",u3_cmd,"), "no slew columns: %.200s", buf);
    // The last row: t = 1.5 s, where the scenario commands the slew valve
    // to 0.25 (a ramp from 0 at 1 s to 0.5 at 2 s; the ode run takes the
    // command at each 1 ms step's midpoint: 0.24975).
    const char* last = buf + strlen(buf) - 1;
    while (last > buf && last[-1] != '\n') --last;
    double v[64];
    int n = 0;
    for (const char* p = last; n < 64 && *p && *p != '\n';) {
        char* e;
        v[n++] = strtod(p, &e);
        p = *e == ',' ? e + 1 : e;
        if (*e != ',') break;
    }
    CHECK(n > 38 && fabs(v[0] - 1.5) < 1e-9 && fabs(v[38] - 0.25) < 1e-3, "%d columns, t %g, u3_cmd %g", n, v[0],
          n > 38 ? v[38] : NAN);
    const char* const refused[] = {
        // The hook: the analytic crane has none (its slew it has, below).
        "run --quiet --scenario sandbox_pick_place --mechanics lagrange --out world.csv",
        "run --quiet --scenario sandbox_pick_place --mechanics ode --world validation --out world.csv",
        "compare --quiet --scenario sandbox_wall --duration 0.1",
        // Side A is on the lagrange crane because of the default pair, not
        // --mechanics: the advice must name --backends (it repeated the
        // options the user had given).
        "compare --quiet --scenario sandbox_swing --mechanics ode --world sandbox --duration 0.1",
    };
    for (int i = 0; i < 4; ++i) {
        cli_write_file("world.csv", "old\n");
        rc = cli_run(refused[i], out, sizeof out);
        const char* want = i < 2 ? "run it with --mechanics ode --world sandbox" : "the default --backends lagrange,ode";
        CHECK(rc == 2 && strstr(out, want) && cli_count_lines(out) == 1, "%s: exit %d: %s", refused[i], rc, out);
        CHECK(i < 2 || !strstr(out, "run it with"), "%s: circular advice: %s", refused[i], out);
        CHECK(cli_read_file("world.csv", buf, sizeof buf) == 4, "%s: the old file changed", refused[i]);
    }
    // An explicit pair names --backends too.
    rc = cli_run("compare --quiet --scenario sandbox_swing --backends lagrange,ode --world sandbox --duration 0.1", out,
                 sizeof out);
    CHECK(rc == 2 && strstr(out, "because of --backends"), "explicit --backends: exit %d: %s", rc, out);
    // Options consistent with the sandbox are accepted (issue 25, item 13:
    // `run --scenario sandbox_pick_place --world sandbox` was refused as if
    // it asked for the lagrange crane, while the same without --world ran). A
    // world without --mechanics is an ode run there, said once; the rows are
    // the sandbox's (a hook, a slew).
    const char* const accepted[] = {
        "run --scenario sandbox_pick_place --world sandbox --duration 0.1 --out world.csv",
        "run --scenario sandbox_pick_place --world site --duration 0.1 --out world.csv",
        "run --scenario sandbox_pick_place --mechanics ode --duration 0.1 --out world.csv",
        "run --scenario sandbox_pick_place --mechanics ode --world sandbox --duration 0.1 --out world.csv",
        "compare --scenario sandbox_pick_place --world sandbox --dts 1e-4,5e-5 --duration 0.1 --out world.csv",
        "compare --scenario sandbox_pick_place --mechanics ode --dts 1e-4,5e-5 --duration 0.1 --out world.csv",
        "compare --scenario sandbox_swing --world sandbox --set-b hydraulics.components.lift_cyl.bore=0.11 "
        "--duration 0.1 --out world.csv",
        "sweep --scenario sandbox_pick_place --world sandbox --param hydraulics.components.lift_cyl.bore=0.1:0.11:2 "
        "--duration 0.1 --out world.csv",
    };
    for (int i = 0; i < (int)(sizeof accepted / sizeof accepted[0]); ++i) {
        remove("world.csv");
        rc = cli_run(accepted[i], out, sizeof out);
        const bool noted = strstr(accepted[i], "--mechanics ode --world") == NULL;
        const char* note = strstr(out, "note: scenario sandbox_");
        CHECK(rc == 0 && !strstr(out, "has not") && (noted ? note && !strstr(note + 1, "note: scenario") : !note),
              "%s: exit %d: %s", accepted[i], rc, out);
        // run's and compare's rows have the hook (hook_z, hook_z_A), sweep's
        // designs the hook's sway.
        CHECK(cli_read_file("world.csv", buf, sizeof buf) > 0 && (strstr(buf, ",hook_z") || strstr(buf, ",max_hook_sway,")),
              "%s: no sandbox columns: %.200s", accepted[i], buf);
    }
    // A scenario that only slews, on --mechanics lagrange: the slew is a
    // degree of freedom of the analytic mode (the model's slew drive); the
    // rows carry the rack's, the slew function's and the slew's columns.
    remove("world.csv");
    rc = cli_run("run --quiet --scenario sandbox_wall --mechanics lagrange --duration 2 --out world.csv", out,
                 sizeof out);
    CHECK(rc == 0 && !strstr(out, "has not") && !strstr(out, "note: scenario"), "slew dof: exit %d: %s", rc, out);
    CHECK(cli_read_file("world.csv", buf, sizeof buf) > 0 &&
              strstr(buf, ",end_stop,x_slew,v_slew,pA_slew,pB_slew,F_slew,u_slew,ucmd_slew,q_column,qd_column\n"),
          "slew dof: columns %.400s", buf);
    {
        // At t = 2 s the command (0.5 from 1 to 2 s) has turned the column.
        const char* last = buf + strlen(buf) - 1;
        while (last > buf && last[-1] != '\n') --last;
        double v[64];
        int n = 0;
        for (const char* p = last; n < 64 && *p && *p != '\n';) {
            char* e;
            v[n++] = strtod(p, &e);
            p = *e == ',' ? e + 1 : e;
            if (*e != ',') break;
        }
        CHECK(n >= 9 && fabs(v[0] - 2.0) < 1e-9 && v[n - 2] > 0.01 && v[n - 3] == 0.5,
              "slew dof: %d columns, t %g, slew %g rad, ucmd_slew %g", n, v[0], n > 2 ? v[n - 2] : NAN,
              n > 3 ? v[n - 3] : NAN);
    }
    // Options that contradict it are still refused, saying which.
    rc = cli_run("run --quiet --scenario sandbox_pick_place --mechanics lagrange --world sandbox --out world.csv", out,
                 sizeof out);
    CHECK(rc == 2 && strstr(out, "lagrange 2-DOF crane has not") && cli_count_lines(out) == 1, "exit %d: %s", rc, out);
    // A crane chain whose model has no slew drive: the message names the
    // chain and what it lacks, not the two-link crane.
    static char cmd[1024];
    FILE* f = fopen("slew_only.json", "w");
    CHECK(f != NULL, "cannot write slew_only.json");
    if (f) {
        fputs("{\"name\": \"slew_only\", \"duration\": 1, \"initial\": {\"q1_deg\": 100, \"q2_deg\": -110},"
              " \"commands\": {\"slew\": [[0, 0], [1, 0.5]]}}\n",
              f);
        fclose(f);
    }
    snprintf(cmd, sizeof cmd,
             "run --quiet --model %s/../../world/data/chain_8fn_10link.json --scenario slew_only.json --mechanics "
             "lagrange --out world.csv",
             CRANESIM_TESTDATA);
    rc = cli_run(cmd, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "which the lagrange crane chain (its model has no slew drive: mechanics.slew) has not") &&
              cli_count_lines(out) == 1,
          "exit %d: %s", rc, out);
    remove("slew_only.json");
    rc = cli_run("run --quiet --scenario sandbox_pick_place --world validation --out world.csv", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "validation world has not") && cli_count_lines(out) == 1, "exit %d: %s", rc, out);
    remove("world.csv");
}

// The Quick start's headless drive (scripts/run.sh) wrote drive.csv into the
// folder it was started from, the checkout: without --record nothing is
// written now, and the report says how to get a record.
static void test_drive_writes_nothing_unasked(void) {
    static char out[16384];
    remove("drive.csv");
    const int rc = cli_run("drive --headless --quiet --duration 0.2", out, sizeof out);
    CHECK(rc == 0 && strstr(out, "no record (--record FILE.csv"), "exit %d: %s", rc, out);
    CHECK(access("drive.csv", F_OK) != 0, "drive wrote drive.csv unasked");
}

// The soak benchmark (`bench --config soak`) runs and is repeatable: the same
// seed gives the same run (its figures are in the JSON line, not checked
// here: benchmarks are not tests).
static void test_soak_runs(void) {
    static char a[4096], b[4096];
    int rc = cli_run("bench --config soak --duration 2 --seed 7", a, sizeof a);
    CHECK(rc == 0 && strstr(a, "\"config\":\"soak\"") && strstr(a, "\"exit_status\":0") &&
              strstr(a, "\"nonfinite_values\":0") && strstr(a, "\"ode_messages\":") && strstr(a, "\"peak_rss_kb\":"),
          "exit %d: %s", rc, a);
    rc = cli_run("bench --config soak --duration 2 --seed 7", b, sizeof b);
    // Everything but the wall time and the RSS must agree.
    const char* pa = strstr(a, "\"peak_pressure_mpa\"");
    const char* pb = strstr(b, "\"peak_pressure_mpa\"");
    const char* ea = pa ? strstr(pa, "\"peak_rss_kb\"") : NULL;
    CHECK(rc == 0 && pa && pb && ea && !strncmp(pa, pb, (size_t)(ea - pa)), "two runs differ:\n%s%s", a, b);
    CHECK(cli_run("bench --config soak --seed 0", a, sizeof a) == 2 && strstr(a, "--seed"), "%s", a);
}

// Replacing through a temporary file must not turn a symlinked output into a
// plain file, nor change the old file's permissions (a rename would do
// both if app_out did not write next to the link's target with its mode).
static void test_replace_keeps_link_and_mode(void) {
    static char out[8192], buf[1 << 16];
    remove("lnk.csv");
    cli_write_file("tgt.csv", "old\n");
    chmod("tgt.csv", 0640);
    CHECK(symlink("tgt.csv", "lnk.csv") == 0, "symlink");
    const int rc = cli_run("run --quiet --scenario hold --duration 0.01 --out lnk.csv", out, sizeof out);
    CHECK(rc == 0, "exit %d: %s", rc, out);
    struct stat st;
    CHECK(lstat("lnk.csv", &st) == 0 && S_ISLNK(st.st_mode), "lnk.csv is no longer a symlink");
    CHECK(stat("tgt.csv", &st) == 0 && (st.st_mode & 0777) == 0640, "mode now %o", (unsigned)(st.st_mode & 0777));
    CHECK(cli_read_file("tgt.csv", buf, sizeof buf) > 0 && whole_rows(buf) == 11, "target: %.60s", buf);
    remove("lnk.csv");
}

// The headless drive writes its record through a temporary file too: a
// signal must put the record in place (whole lines), not leave the
// temporary behind.
static void test_interrupted_drive(void) {
    static char buf[1 << 20], err[4096];
    cli_write_file("drv.csv", "old\n");
    remove_temps("drv.csv");
    fflush(stdout); // a child that reopens stdout would write the buffer again
    pid_t pid = fork();
    if (pid == 0) {
        FILE* e = freopen("drv.err", "w", stderr);
        FILE* o = freopen("/dev/null", "w", stdout);
        (void)e, (void)o;
        execl(cli_bin(), cli_bin(), "drive", "--headless", "--quiet", "--duration", "60", "--record", "drv.csv", (char*)NULL);
        _exit(127);
    }
    CHECK(pid > 0, "fork");
    if (pid <= 0) return;
    char tmp[256];
    struct stat st;
    for (int i = 0; i < 2000; ++i) { // waiting for rows, not timing (real time: ~0.5 s)
        find_temp("drv.csv", tmp, sizeof tmp);
        if (tmp[0] && stat(tmp, &st) == 0 && st.st_size > 0) break;
        nanosleep(&(struct timespec){0, 10000000L}, NULL);
    }
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 143, "status %#x", status);
    cli_read_file("drv.err", err, sizeof err);
    CHECK(strstr(err, "interrupted (SIGTERM) at t = ") && strstr(err, "record kept in drv.csv"), "%s", err);
    CHECK(cli_read_file("drv.csv", buf, sizeof buf) > 0 && whole_rows(buf) >= 1, "record: %.60s", buf);
    find_temp("drv.csv", tmp, sizeof tmp);
    CHECK(tmp[0] == 0, "temporary %s left behind", tmp);
}

// Two outputs of one command naming one file: the second write replaced the
// first (`run --out x.png --plot x.png` left a PNG where the CSV was). Now
// refused before anything runs, the existing file untouched; by name, by
// another spelling of the name, by a hard link; devices may be shared.
static void test_same_output_file(void) {
    static char out[8192], buf[256];
    remove("same.png");
    remove("same.csv");
    remove("same_link.png");
    int rc = cli_run("run --quiet --duration 0.05 --out same.png --plot ./same.png", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--out same.png and --plot ./same.png name the same file") && cli_count_lines(out) == 1,
          "new file twice: exit %d: %s", rc, out);
    CHECK(cli_read_file("same.png", buf, sizeof buf) < 0, "a refused run created same.png");
    cli_write_file("same.png", "old\n");
    rc = cli_run("run --quiet --duration 0.05 --out same.png --energy same.png", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--out same.png and --energy same.png name the same file"), "--energy: exit %d: %s",
          rc, out);
    mkdir("samedir", 0755);
    rc = cli_run("run --quiet --duration 0.05 --energy samedir/../same.png --plot same.png --out /dev/null", out,
                 sizeof out);
    CHECK(rc == 2 && strstr(out, "--plot same.png and --energy samedir/../same.png name the same file"),
          "--energy via ..: exit %d: %s", rc, out);
    CHECK(cli_read_file("same.png", buf, sizeof buf) == 4, "the old file changed");
    cli_write_file("same.csv", "old\n");
    CHECK(link("same.csv", "same_link.png") == 0, "hard link");
    rc = cli_run("compare --quiet --scenario hold --duration 0.05 --solvers krus,ros2 --out same.csv --plot same_link.png",
                 out, sizeof out);
    CHECK(rc == 2 && strstr(out, "cranesim compare: --out same.csv and --plot same_link.png name the same file"),
          "compare, hard link: exit %d: %s", rc, out);
    CHECK(cli_read_file("same.csv", buf, sizeof buf) == 4, "the old file changed");
    rc = cli_run("run --quiet --duration 0.05 --out /dev/null --energy /dev/null", out, sizeof out);
    CHECK(rc == 0, "/dev/null twice: exit %d: %s", rc, out);
    remove("same.png");
    remove("same.csv");
    remove("same_link.png");
}

// Small things a new user met: "--opt=value" was an unknown option; sweep
// wrote 0.080000000000000002 for 0.08; a run slower than real time said
// "0x real time"; compare labelled a side with no changes "A = A"; drive
// --replay of a missing file talked about the window; loadchart refused
// --outreach 0:6 naming a reach from -0.104 m that LO may not use.
static void test_small_things(void) {
    static char out[16384], buf[4096];
    remove("eq.csv");
    int rc = cli_run("run --quiet --scenario=hold --duration=0.05 --out=eq.csv --set=hydraulics.components.lift_cyl.bore=0.11",
                     out, sizeof out);
    CHECK(rc == 0 && cli_read_file("eq.csv", buf, sizeof buf) > 0, "--opt=value: exit %d: %s", rc, out);
    // A flag takes =1/=true/=0/=false (test_options_cli); any other value is
    // refused as one (it was "unknown option '--quiet=1'").
    rc = cli_run("run --quiet=on --out /dev/null", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--quiet takes no value"), "a flag with =: exit %d: %s", rc, out);
    remove("eq.csv");

    rc = cli_run("sweep --quiet --scenario hold --duration 0.05 --param hydraulics.components.lift_cyl.bore=0.08:0.1:3 "
                 "--metrics peak_p1A --out eq_sweep.csv",
                 out, sizeof out);
    CHECK(rc == 0 && cli_read_file("eq_sweep.csv", buf, sizeof buf) > 0, "sweep: exit %d: %s", rc, out);
    // Shortest form, and it reads back to the design's value: 0.08 + 0.01 k.
    CHECK(strstr(buf, "\n0,0.08,") && strstr(buf, "\n1,0.09,") && strstr(buf, "\n2,0.1,"), "sweep CSV: %s", buf);
    for (const char* p = strchr(buf, '\n'); p && p[1]; p = strchr(p + 1, '\n')) {
        const char* c = strchr(p + 1, ',');
        const char* e = c ? strchr(c + 1, ',') : NULL;
        CHECK(c && e && e - c - 1 <= 17, "a long number: %.60s", p + 1);
    }
    remove("eq_sweep.csv");

    // 20000 steps of 0.1 us for 2 ms: far slower than real time.
    rc = cli_run("run --scenario hold --duration 0.002 --dt 1e-7 --out /dev/null", out, sizeof out);
    const char* w = strstr(out, "s wall: ");
    const char* sim = strstr(out, "simulated ");
    double ratio = w ? strtod(w + strlen("s wall: "), NULL) : NAN;
    double t_end = sim ? strtod(sim + strlen("simulated "), NULL) : NAN;
    double wall = sim ? strtod(strstr(sim, " in ") + 4, NULL) : NAN;
    CHECK(rc == 0 && ratio > 0 && fabs(ratio - t_end / wall) <= 0.1 * t_end / wall + 0.01,
          "slower than real time: %.3g printed for %g s / %g s: %s", ratio, t_end, wall, out);

    rc = cli_run("compare --quiet --scenario hold --duration 0.05 --set-b hydraulics.components.lift_cyl.bore=0.11", out,
                 sizeof out);
    CHECK(rc == 0 && strstr(out, "(A = hiab031.json, B = bore=0.11)") && !strstr(out, "A = A"), "labels: %s", out);

    rc = cli_run("drive --replay nosuch.session", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--replay nosuch.session: cannot read: No such file") && cli_count_lines(out) == 1,
          "missing replay: exit %d: %s", rc, out);

    rc = cli_run("loadchart --outreach 0:6:10 --out /dev/null", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "must lie in [0.000, ") && !strstr(out, "[-"), "loadchart --outreach: exit %d: %s", rc,
          out);
}

int main(int argc, char** argv) {
    RUN_TEST(test_run_memory);
    RUN_TEST(test_duration_caps);
    RUN_TEST(test_tiny_steps);
    RUN_TEST(test_interrupted_run);
    RUN_TEST(test_failed_run_keeps_rows);
    RUN_TEST(test_scenario_world);
    RUN_TEST(test_drive_writes_nothing_unasked);
    RUN_TEST(test_soak_runs);
    RUN_TEST(test_replace_keeps_link_and_mode);
    RUN_TEST(test_interrupted_drive);
    RUN_TEST(test_same_output_file);
    RUN_TEST(test_small_things);
    TEST_MAIN_END();
}
