// cli_util.h: running the real `cranesim` binary from a test, and the small
// file helpers the command-line tests share.
//
// CRANESIM_BIN in the environment runs another binary instead (an older
// build, to see a test fail without its fix).
#ifndef CRANESIM_CLI_UTIL_H
#define CRANESIM_CLI_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#define CLI_BIN CRANESIM_BINARY_DIR "/cranesim"

/// The binary the tests run: CRANESIM_BIN if set, else this build's.
static inline const char* cli_bin(void) {
    const char* b = getenv("CRANESIM_BIN");
    return b && *b ? b : CLI_BIN;
}

/// Run `[env ENV] cranesim ARGS` (env may be NULL) with stderr merged into
/// out (n bytes, NUL-terminated). Returns the exit code, or -1 if the
/// program did not exit normally (a signal, an abort).
static inline int cli_run_env(const char* env, const char* args, char* out, size_t n) {
    char cmd[8192];
    snprintf(cmd, sizeof cmd, "%s%s%s%s %s 2>&1", env ? "env " : "", env ? env : "", env ? " " : "", cli_bin(),
             args);
    FILE* p = popen(cmd, "r");
    if (!p) return -1;
    size_t got = fread(out, 1, n - 1, p);
    out[got] = 0;
    // Read to the end so a chatty child never blocks on a full pipe.
    char sink[4096];
    while (fread(sink, 1, sizeof sink, p) > 0) {
    }
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static inline int cli_run(const char* args, char* out, size_t n) { return cli_run_env(NULL, args, out, n); }

/// Number of newline characters in s.
static inline int cli_count_lines(const char* s) {
    int k = 0;
    for (; *s; ++s) k += *s == '\n';
    return k;
}

/// The file in buf (n bytes, NUL-terminated); its length, or -1.
static inline long cli_read_file(const char* path, char* buf, size_t n) {
    FILE* f = fopen(path, "rb");
    if (!f) return -1;
    size_t got = fread(buf, 1, n - 1, f);
    buf[got] = 0;
    fclose(f);
    return (long)got;
}

/// Replace path with text; 0, or -1 if it could not be written.
static inline int cli_write_file(const char* path, const char* text) {
    FILE* f = fopen(path, "wb");
    if (!f) return -1;
    const int ok = fputs(text, f) >= 0;
    return fclose(f) == 0 && ok ? 0 : -1;
}

#endif
