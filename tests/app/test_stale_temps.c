// test_stale_temps.c: the temporary files of outputs (app_out_open) left by a
// run or sweep killed with SIGKILL are removed by the next run that writes
// the same output on this host, and only those: never the temporary file of
// a cranesim still writing it, nor one of another host, another output or
// the old unnamed form. Runs the real binary (cli_util.h).
#include "check.h"
#include "cli_util.h"

#include <dirent.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static char out[1 << 16];

static void host(char* h, size_t n) {
    if (gethostname(h, n - 1)) snprintf(h, n, "localhost");
    h[n - 1] = 0;
    for (char* c = h; *c; ++c)
        if (*c == '/' || *c == '-') *c = '_';
    if (strlen(h) > 32) h[32] = 0;
}

static void touch(const char* path) {
    FILE* f = fopen(path, "w");
    if (f) fputs("partial,rows\n", f), fclose(f);
}

static bool exists(const char* path) { return access(path, F_OK) == 0; }

// A pid that was a process and is gone: a child that exited and was reaped.
static pid_t dead_pid(void) {
    fflush(stdout);
    const pid_t p = fork();
    if (p == 0) _exit(0);
    waitpid(p, NULL, 0);
    return p;
}

// The temporary file in dir of output name written by process pid ("" when
// none): ".NAME.cranesim-HOST-PID.XXXXXX".
static void find_temp(const char* dir, const char* name, pid_t pid, char* got, size_t n) {
    char pre[256], mid[32];
    snprintf(pre, sizeof pre, ".%s.cranesim-", name);
    snprintf(mid, sizeof mid, "-%ld.", (long)pid);
    got[0] = 0;
    DIR* d = opendir(dir);
    for (struct dirent* e; d && (e = readdir(d));)
        if (!strncmp(e->d_name, pre, strlen(pre)) && strstr(e->d_name, mid)) snprintf(got, n, "%s/%s", dir, e->d_name);
    if (d) closedir(d);
}

// Start `cranesim ARGS` in the background (stdout and stderr to /dev/null)
// and wait until the temporary file of dir/name has data; its pid.
static pid_t start_writing(const char* dir, const char* name, char* const* argv, char* tmp, size_t n) {
    fflush(stdout);
    const pid_t pid = fork();
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) _exit(126);
        execv(cli_bin(), argv);
        _exit(127);
    }
    struct stat st;
    for (int i = 0; i < 3000; ++i) { // up to 30 s on a loaded machine: waiting, not timing
        find_temp(dir, name, pid, tmp, n);
        if (tmp[0] && stat(tmp, &st) == 0 && st.st_size > 0) break;
        nanosleep(&(struct timespec){0, 10000000L}, NULL);
    }
    return pid;
}

static void test_only_stale_temps_are_removed(void) {
    char dir[] = "/tmp/cranesim_stale_XXXXXX", h[80], p[8][600];
    CHECK(mkdtemp(dir) != NULL, "temp dir");
    host(h, sizeof h);
    const pid_t dead = dead_pid();
    snprintf(p[0], sizeof p[0], "%s/.out.csv.cranesim-%s-%ld.AbC123", dir, h, (long)dead);       // stale: removed
    snprintf(p[1], sizeof p[1], "%s/.out.csv.cranesim-%s-%ld.DeF456", dir, h, (long)getpid());   // alive: kept
    snprintf(p[2], sizeof p[2], "%s/.out.csv.cranesim-otherhost-%ld.GhI789", dir, (long)dead);   // other host
    snprintf(p[3], sizeof p[3], "%s/.other.csv.cranesim-%s-%ld.JkL012", dir, h, (long)dead);     // other output
    snprintf(p[4], sizeof p[4], "%s/.out.csv.MnO345", dir);                                      // old form
    snprintf(p[5], sizeof p[5], "%s/.out.csv.cranesim-%s-%ldx.PqR678", dir, h, (long)dead);      // not a pid
    for (int i = 0; i < 6; ++i) touch(p[i]);
    char args[1024];
    snprintf(args, sizeof args, "run --quiet --scenario hold --duration 0.05 --out %s/out.csv", dir);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(!exists(p[0]), "the stale temporary file %s is still there", p[0]);
    CHECK(strstr(out, "removed") && strstr(out, ".out.csv.cranesim-") && strstr(out, "killed"), "no note: %s", out);
    for (int i = 1; i < 6; ++i) CHECK(exists(p[i]), "%s was removed", p[i]);
    for (int i = 1; i < 6; ++i) remove(p[i]);
    snprintf(p[6], sizeof p[6], "%s/out.csv", dir);
    remove(p[6]);
    CHECK(rmdir(dir) == 0, "clean up %s", dir);
}

// The real case: `run` and `sweep` killed with SIGKILL while writing leave
// their temporary file; the next run of the same output removes it, while a
// temporary file of a run still writing the same output stays.
static void test_killed_run_and_sweep(void) {
    char dir[] = "/tmp/cranesim_killed_XXXXXX", tmp[700], path[700], args[1024];
    CHECK(mkdtemp(dir) != NULL, "temp dir");
    snprintf(path, sizeof path, "%s/k.csv", dir);
    char* run_argv[] = {(char*)cli_bin(), "run", "--quiet", "--scenario", "ramp", "--duration", "5000", "--out", path,
                        NULL};
    pid_t pid = start_writing(dir, "k.csv", run_argv, tmp, sizeof tmp);
    CHECK(tmp[0] != 0, "no temporary file of the run");
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
    CHECK(exists(tmp), "SIGKILL: the temporary file %s is gone already", tmp);
    // The next run writing k.csv removes it as it starts; it goes on writing.
    char live[700];
    pid = start_writing(dir, "k.csv", run_argv, live, sizeof live);
    CHECK(live[0] && exists(live), "no temporary file of the second run (pid %ld)", (long)pid);
    CHECK(!exists(tmp), "the killed run's %s is still there after the next run started", tmp);
    // A third, short run of the same output while the second still writes
    // it: the second's temporary file stays.
    snprintf(args, sizeof args, "run --quiet --scenario hold --duration 0.05 --out %s", path);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(exists(live), "the running run's %s was removed", live);
    kill(pid, SIGTERM); // a clean stop renames its temporary file over k.csv
    waitpid(pid, NULL, 0);
    CHECK(!exists(live), "SIGTERM: %s left", live);
    // sweep: its results file.
    snprintf(path, sizeof path, "%s/s.csv", dir);
    char* sweep_argv[] = {(char*)cli_bin(), "sweep", "--quiet", "--scenario", "ramp", "--threads", "1", "--param",
                          "hydraulics.components.lift_cyl.bore=0.08:0.12:400", "--out", path, NULL};
    pid = start_writing(dir, "s.csv", sweep_argv, tmp, sizeof tmp);
    CHECK(tmp[0] != 0, "no temporary file of the sweep");
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
    CHECK(exists(tmp), "SIGKILL: the sweep's temporary file %s is gone already", tmp);
    snprintf(args, sizeof args,
             "sweep --quiet --scenario hold --duration 0.05 --param hydraulics.components.lift_cyl.bore=0.1:0.11:2 "
             "--out %s",
             path);
    CHECK(cli_run(args, out, sizeof out) == 0, "%s", out);
    CHECK(!exists(tmp), "the killed sweep's %s is still there after the next sweep", tmp);
    snprintf(args, sizeof args, "rm -rf %s", dir);
    CHECK(system(args) == 0, "clean up %s", dir);
}

int main(int argc, char** argv) {
    RUN_TEST(test_only_stale_temps_are_removed);
    RUN_TEST(test_killed_run_and_sweep);
    TEST_MAIN_END();
}
