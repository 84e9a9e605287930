// app_console.c: the terminal side of a long run: the progress bar and the
// SIGINT/SIGTERM catcher that stops it cleanly.
#include "app.h"
#include "engine.h"
#include "world_desc.h"

#include <ctype.h>
#include <limits.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

void app_progress(void* user, double t, double t_end) {
    (void)user;
    if (!isatty(2)) return;
    const int width = 40;
    double f = t_end > 0 ? t / t_end : 1.0;
    if (f > 1) f = 1;
    int n = (int)(f * width + 0.5);
    fprintf(stderr, "\r  [%.*s%*s] %5.1f %%  t = %.2f / %.2f s", n,
            "########################################", width - n, "", 100.0 * f, t, t_end);
    fflush(stderr);
}

void app_progress_done(void) {
    if (isatty(2)) fprintf(stderr, "\r%*s\r", 78, "");
}

// The signal number, set by the handler and read by the loops between rows.
static volatile sig_atomic_t g_signal;

static void on_signal(int sig) { g_signal = sig; }

void app_signals_catch(app_signals* s) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sa.sa_flags = SA_RESETHAND;
    sigemptyset(&sa.sa_mask);
    g_signal = 0;
    sigaction(SIGINT, &sa, &s->old_int);
    sigaction(SIGTERM, &sa, &s->old_term);
}

void app_signals_restore(const app_signals* s) {
    sigaction(SIGINT, &s->old_int, NULL);
    sigaction(SIGTERM, &s->old_term, NULL);
}

int app_signal_caught(void) { return g_signal; }

const char* app_signal_name(int sig) { return sig == SIGINT ? "SIGINT" : "SIGTERM"; }
