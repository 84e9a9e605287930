// test_drive_connect_fn.c: `cranesim drive --connect` on a crane chain sends
// the operator's input for every function of the server, by name, and the
// chain's channels beyond the two-link row reach the window.
//
// 1. A real-time `cranesim serve` on the 6-function chain whose "controls"
//    put ext2 on the d-pad; the window (drive_connect_window, offscreen, in
//    this process) reads SDL's virtual game controller with d-pad up held.
//    A watcher on the same server reads every state frame: the function
//    record of ext2 shows a command near +1 (full deflection) in many frames
//    and every other function's command stays exactly 0 in all of them. The
//    window's --record CSV (the server's row, session_row) has x_ext2, a
//    column past the two-link row's SIM_NCOL, growing as ext2 extends.
// 2. A remote session with --charts x_ext2 fed one state frame whose row
//    holds a known value per column: the chart receives x_ext2's value, and
//    drive_session_row fills the engine's ncol columns without writing past
//    a buffer of ncol + 1.
#define _DEFAULT_SOURCE
#include "check.h"
#include "channels.h"
#include "drive_connect.h"
#include "drive_session.h"
#include "serve_util.h"
#include "drive_test_util.h"

#include <SDL2/SDL.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>

#define MODEL6 CRANESIM_ASSETS "/../tests/world/data/chain_6fn_controls.json"

// The watcher's tally over the window's run.
static struct {
    int port;
    atomic_int stop;
    int fext2;          // ext2's index in the hello's functions
    dc_functions fns;
    long frames;        // state frames read
    long ext2_on;       // frames with ext2's command above 0.9
    long other_on;      // frames with another function's command not 0
    char other[64];     // the first such function
    double other_v;
    char err[256];
} g_w;

static void* watcher(void* arg) {
    (void)arg;
    static proto_state st;
    const int fd = tcp_connect(g_w.port);
    uint8_t b[32];
    const size_t n = proto_put_client_hello(b, sizeof b, PROTO_VERSION, PROTO_WATCH);
    proto_msg m;
    if (fd < 0 || send_all(fd, b, n) || recv_frame(fd, &m, &st, 5000) != PROTO_SERVER_HELLO) {
        snprintf(g_w.err, sizeof g_w.err, "watcher: no hello");
        if (fd >= 0) close(fd);
        return NULL;
    }
    if (dc_hello_functions(m.u.shello.json, m.u.shello.json_len, &g_w.fns, g_w.err, sizeof g_w.err)) {
        close(fd);
        return NULL;
    }
    g_w.fext2 = -1;
    for (int k = 0; k < g_w.fns.n; ++k)
        if (!strcmp(g_w.fns.name[k], "ext2")) g_w.fext2 = k;
    while (!atomic_load(&g_w.stop)) {
        if (next_state(fd, &st, 2000)) {
            snprintf(g_w.err, sizeof g_w.err, "watcher: no state frame within 2 s");
            break;
        }
        ++g_w.frames;
        for (int k = 0; k < st.nfn; ++k) {
            const double u = st.fn[k][0];
            if (k == g_w.fext2 && u > 0.9) ++g_w.ext2_on;
            if (k != g_w.fext2 && u != 0) {
                if (!g_w.other_on++) {
                    snprintf(g_w.other, sizeof g_w.other, "%s", k < g_w.fns.n ? g_w.fns.name[k] : "?");
                    g_w.other_v = u;
                }
            }
        }
    }
    close(fd);
    return NULL;
}

// The window on the chain server with the pad's d-pad up held.
static void window_sends_every_function(void) {
    const char* args[] = {"--model", MODEL6, NULL};
    served sv = {0};
    CHECK(serve_start(&sv, "test_drive_connect_fn_serve.log", args) == 0, "server started on the 6-function chain");
    if (!sv.port) return;
    const int idx = attach_pad("cranesim connect pad");
    CHECK(idx >= 0, "attach: %s", SDL_GetError());
    SDL_Joystick* js = idx >= 0 ? SDL_JoystickOpen(idx) : NULL;
    // The triggers' rest is the axis' bottom on SDL's virtual controller.
    if (js) {
        SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_TRIGGERLEFT, -32768);
        SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_TRIGGERRIGHT, -32768);
        SDL_JoystickSetVirtualButton(js, SDL_CONTROLLER_BUTTON_DPAD_UP, 1); // ext2 + (the model's controls)
    }
    g_w.port = sv.port;
    pthread_t th;
    CHECK(pthread_create(&th, NULL, watcher, NULL) == 0, "watcher thread");

    char addr[64], csv[512], nw[256] = "";
    snprintf(addr, sizeof addr, "127.0.0.1:%d", sv.port);
    snprintf(csv, sizeof csv, "%s/drive_connect_fn.csv", CRANESIM_BINARY_DIR);
    remove(csv);
    app_common c = {.sim = sim_default_opts()};
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.width = 480;
    o.height = 270;
    o.record_path = csv;
    const int rc = drive_connect_window(&c, &o, addr, 3.0, NULL, 0, nw, sizeof nw);
    CHECK(rc == 0, "drive_connect_window: exit %d %s", rc, nw);
    atomic_store(&g_w.stop, 1);
    pthread_join(th, NULL);
    if (js) SDL_JoystickClose(js);
    if (idx >= 0) SDL_JoystickDetachVirtual(idx);
    CHECK(serve_stop(&sv) == 0, "server exits 0");

    printf("watcher: %ld frames, ext2 commanded in %ld, another function in %ld (%s = %g) %s\n", g_w.frames,
           g_w.ext2_on, g_w.other_on, g_w.other, g_w.other_v, g_w.err);
    CHECK(!g_w.err[0], "%s", g_w.err);
    CHECK(g_w.fext2 >= 0, "the server has an ext2 function");
    CHECK(g_w.frames > 50, "%ld frames watched in 3 s (75 Hz)", g_w.frames);
    CHECK(g_w.ext2_on > g_w.frames / 2, "ext2's command above 0.9 in %ld of %ld frames", g_w.ext2_on, g_w.frames);
    CHECK(g_w.other_on == 0, "another function commanded in %ld frames: first %s = %g", g_w.other_on, g_w.other,
          g_w.other_v);

    // The record: x_ext2 (past SIM_NCOL) from the server's rows, growing.
    FILE* f = fopen(csv, "r");
    CHECK(f != NULL, "%s written", csv);
    if (!f) return;
    static char line[65536];
    int col = -1, cp = -1, ncol = 0;
    if (fgets(line, sizeof line, f)) {
        char* save = NULL;
        for (char* tok = strtok_r(line, ",\n", &save); tok; tok = strtok_r(NULL, ",\n", &save), ++ncol) {
            if (!strcmp(tok, "x_ext2")) col = ncol;
            if (!strcmp(tok, "p1A")) cp = ncol;
        }
    }
    CHECK(cp >= 0, "the record has p1A");
    CHECK(col >= SIM_NCOL, "x_ext2 is column %d of %d, past the two-link row's %d", col, ncol, SIM_NCOL);
    double first = NAN, last = NAN;
    long rows = 0, vacuum = 0; // rows whose lift chamber reads no pressure: not a state the server sent
    while (col >= 0 && fgets(line, sizeof line, f)) {
        char* save = NULL;
        int k = 0;
        for (char* tok = strtok_r(line, ",\n", &save); tok; tok = strtok_r(NULL, ",\n", &save), ++k) {
            if (k == col) {
                const double v = atof(tok);
                if (!rows++) first = v;
                last = v;
            }
            if (k == cp && !(atof(tok) > 0)) ++vacuum;
        }
    }
    CHECK(vacuum == 0, "%ld recorded rows have p1A <= 0 Pa abs (a row before the first state frame?)", vacuum);
    fclose(f);
    printf("record: %ld rows, x_ext2 %.4f -> %.4f m\n", rows, first, last);
    CHECK(rows > 30, "%ld rows recorded", rows);
    CHECK(isfinite(first) && isfinite(last) && last - first > 0.01,
          "x_ext2 grows by more than 10 mm while ext2 is held: %g -> %g m", first, last);
}

// A remote session's chart of a chain channel and its row buffer.
static void remote_chart_and_row(void) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "sandbox";
    c.model_path = MODEL6;
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.width = 480;
    o.height = 270;
    o.charts = "x_ext2";
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    drive_session_set_remote(s);
    const int ncol = engine_ncol(drive_session_engine(s));
    const int col = chan_list_find(drive_session_channels(s), "x_ext2");
    CHECK(ncol > SIM_NCOL && ncol <= PROTO_MAX_ROW && col >= SIM_NCOL && col < ncol,
          "x_ext2 column %d of %d (SIM_NCOL %d)", col, ncol, SIM_NCOL);
    proto_state* st = calloc(1, sizeof *st);
    st->nrow = (uint16_t)ncol;
    for (int k = 0; k < ncol; ++k) st->row[k] = 1000.0 + k; // a value per column, none 0
    st->nine[8] = 0.5; // t [s]
    drive_session_feed(s, st, 0, NULL);
    double last = 0;
    const long n = drive_session_chart_samples(s, 0, &last);
    CHECK(n == 1 && last == 1000.0 + col, "chart x_ext2: %ld samples, last %g (want 1 and %g)", n, last,
          1000.0 + col);
    // The row: ncol columns from the frame, nothing past the buffer.
    double* row = malloc((size_t)(ncol + 1 + PROTO_MAX_ROW) * sizeof *row);
    for (int k = 0; k < ncol + 1 + PROTO_MAX_ROW; ++k) row[k] = -7;
    drive_session_row(s, row);
    int bad = -1;
    for (int k = 0; k < ncol && bad < 0; ++k)
        if (row[k] != 1000.0 + k) bad = k;
    CHECK(bad < 0, "row column %d: %g, the frame's %g", bad, bad >= 0 ? row[bad] : 0, 1000.0 + bad);
    int over = -1;
    for (int k = ncol; k < ncol + 1 + PROTO_MAX_ROW && over < 0; ++k)
        if (row[k] != -7) over = k;
    CHECK(over < 0, "drive_session_row wrote column %d past the engine's %d", over, ncol);
    free(row);
    free(st);
    drive_session_destroy(s);
}

int main(void) {
    if (SDL_Init(SDL_INIT_EVENTS | SDL_INIT_JOYSTICK | SDL_INIT_GAMECONTROLLER) != 0) {
        fprintf(stderr, "SDL_Init: %s\n", SDL_GetError());
        return 1;
    }
    remote_chart_and_row();
    window_sends_every_function();
    SDL_Quit();
    TEST_MAIN_END();
}
