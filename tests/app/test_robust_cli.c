// test_robust_cli.c: `cranesim` when a run goes wrong or is cut short:
// capped durations, output files replaced only by a run that wrote rows,
// interrupted runs, a scenario run in its own world.
#include "check.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define BIN CRANESIM_BINARY_DIR "/cranesim"

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

static void write_file(const char* path, const char* text) {
    FILE* f = fopen(path, "w");
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

// The whole file in buf (NUL-terminated); its length, or -1.
static long read_file(const char* path, char* buf, size_t n) {
    FILE* f = fopen(path, "r");
    if (!f) return -1;
    size_t got = fread(buf, 1, n - 1, f);
    buf[got] = 0;
    fclose(f);
    return (long)got;
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
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        write_file("cap.csv", "old\n");
        const int rc = run(cases[i], out, sizeof out);
        CHECK(rc == 2, "%s: exit %d: %s", cases[i], rc, out);
        CHECK(strstr(out, "1e6") && strstr(out, " s") && (strstr(out, "--duration") || strstr(out, "--every")),
              "%s: %s", cases[i], out);
        CHECK(read_file("cap.csv", buf, sizeof buf) == 4 && !strcmp(buf, "old\n"), "%s: file now '%s'", cases[i],
              buf);
    }
    // An output period finer than a row per picosecond of the run.
    const int rc = run("run --quiet --solver rodas3 --every 1e-300 --out cap.csv", out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--every"), "exit %d: %s", rc, out);
}

int main(int argc, char** argv) {
    RUN_TEST(test_duration_caps);
    TEST_MAIN_END();
}
