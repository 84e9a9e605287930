// test_serve_rcl.c: `cranesim serve` gives a remote operator the protection
// and the service a local one has (docs/protocol.md, docs/safety.md).
//
// 1. The rated capacity limiter over the link: a lockstep server with
//    1300 kg at the tip in the validation world, the controller's jib at full
//    command. Every state frame equals, bit for bit, the row of a local
//    stepped engine with the limiter on (as `drive` has it), the frames say
//    the limiter measures and acts, and it cuts the jib command (flag bit
//    14 set exactly in the frames where u2_cmd is below the demand); with
//    `--rcl off` the full command reaches the valve.
// 2. A burst of RESETs: 100 and then 1000 of them, sent at once by the
//    controller to a real-time sandbox server, rebuild the engine once each
//    (the rest merged into it, or refused with a notice within a second of
//    the last rebuild), and a watcher keeps getting frames all along.
// 3. A frame before the hello is refused for that ("no hello"), whatever its
//    fields: a short command frame is not "command frame too short".
#define _DEFAULT_SOURCE // usleep, in serve_util.h
#include "check.h"
#include "engine.h"
#include "model.h"
#include "scenario.h"
#include "serve_util.h"

#include <math.h>

static proto_state g_st;
#define OVERLOAD CRANESIM_TESTDATA "/rcl_overload.json"

// ---- 1. the limiter over the link ----

// Largest cut of the jib command (1 less the row's u2_cmd) over nframes
// frames of a lockstep server started with extra (NULL-terminated); *same:
// the frames equal to a local engine's with the limiter set to rcl_on;
// *flags_or: the state flags seen.
static double served_cut(const char* const* extra, bool rcl_on, int nframes, long* diff, uint32_t* flags_or) {
    const double frame = 1.0 / 75;
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = "validation";
    o.rcl = rcl_on;
    char err[512];
    model* m = model_load(NULL, NULL, 0, err, sizeof err);
    scenario sc;
    CHECK(m && scenario_load(OVERLOAD, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return NAN;
    engine* l = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
    CHECK(l != NULL, "%s", err);
    const char* args[16] = {"--world", "validation", "--scenario", OVERLOAD, "--lockstep"};
    int na = 5;
    for (int k = 0; extra && extra[k] && na < 15; ++k) args[na++] = extra[k];
    args[na] = NULL;
    served sv;
    CHECK(serve_start(&sv, NULL, args) == 0, "server started");
    int role = -1;
    const int fd = serve_join(sv.port, PROTO_CONTROL, &role);
    CHECK(fd >= 0 && role == PROTO_CONTROL, "joined as controller (role %d)", role);
    CHECK(fd >= 0 && next_state(fd, &g_st, 5000) == 0, "the state at t = 0");
    double cut = 0;
    *diff = 0;
    *flags_or = 0;
    const int col_u2_cmd = COL_U2_CMD; // the row is in the hello's channel order, sim.h's
    for (int i = 0; i < nframes && fd >= 0 && l; ++i) {
        const double u[3] = {0, 1, 0}; // the jib out, full command
        engine_set_commands(l, u);
        CHECK(engine_advance(l, (i + 1) * frame - engine_time(l)) == 0, "local step %d", i);
        double row[SIM_NCOL];
        engine_row(l, row);
        proto_command c = {.seq = 2 * (uint64_t)i + 1, .op = PROTO_OP_VALVES, .nu = 3, .u = {0, 1, 0}};
        send_cmd(fd, &c);
        c = (proto_command){.seq = 2 * (uint64_t)i + 2, .op = PROTO_OP_STEP, .frames = 1};
        send_cmd(fd, &c);
        if (next_state(fd, &g_st, 10000)) {
            CHECK(0, "no state after step %d", i);
            break;
        }
        *flags_or |= g_st.flags;
        const double nine[9] = {row[COL_X1], row[COL_X2], row[COL_P1A], row[COL_P1B], row[COL_P2A],
                                row[COL_P2B], row[COL_U1], row[COL_U2], row[COL_T]};
        if (memcmp(nine, g_st.nine, sizeof nine) || g_st.row[col_u2_cmd] != row[COL_U2_CMD] ||
            g_st.rcl_util != row[COL_RCL_UTIL])
            ++*diff;
        if (g_st.nine[8] > 0.25 && g_st.nrow > col_u2_cmd) cut = fmax(cut, 1 - g_st.row[col_u2_cmd]);
        // The frame's "jib cut" bit agrees with its u2_cmd (below the operator's 1).
        if (((g_st.flags & (PROTO_F_RCL_CUT0 << 1)) != 0) != (g_st.nrow > col_u2_cmd && g_st.row[col_u2_cmd] < 1))
            ++*diff;
    }
    if (fd >= 0) close(fd);
    CHECK(serve_stop(&sv) == 0, "server exits 0 on SIGINT");
    engine_destroy(l);
    model_free(m);
    return cut;
}

static void limiter_over_the_link(void) {
    long diff;
    uint32_t flags;
    const double cut = served_cut(NULL, true, 120, &diff, &flags);
    printf("limiter on (default): jib command cut by up to %.2f; %ld of 120 frames differ from the local drive; "
           "flags: measures %d, acts %d\n",
           cut, diff, (flags & PROTO_F_RCL_HAVE) != 0, (flags & PROTO_F_RCL_ON) != 0);
    CHECK((flags & PROTO_F_RCL_HAVE) && (flags & PROTO_F_RCL_ON), "the frames do not say the limiter acts: 0x%x",
          flags);
    CHECK(cut > 0.5, "the server's limiter did not cut the jib (cut %.2f)", cut);
    CHECK(diff == 0, "%ld frames differ from a local drive with the limiter", diff);
    const char* off[] = {"--rcl", "off", NULL};
    const double cut_off = served_cut(off, false, 120, &diff, &flags);
    printf("--rcl off: cut %.2f; %ld frames differ from the local run without the limiter; acts %d\n", cut_off, diff,
           (flags & PROTO_F_RCL_ON) != 0);
    CHECK(cut_off == 0 && !(flags & PROTO_F_RCL_ON) && (flags & PROTO_F_RCL_HAVE), "--rcl off: cut %.2f, flags 0x%x",
          cut_off, flags);
    CHECK(diff == 0, "--rcl off: %ld frames differ", diff);
}

// ---- 2. a burst of RESETs ----

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

// Frames for the watcher over secs seconds; the largest gap between two [s].
static long watch(int fd, double secs, double* gap) {
    const double t0 = now_s();
    double last = t0;
    long n = 0;
    *gap = 0;
    while (now_s() - t0 < secs) {
        if (next_state(fd, &g_st, 3000)) break;
        const double t = now_s();
        *gap = fmax(*gap, t - last);
        last = t;
        ++n;
    }
    return n;
}

// Lines of the log holding what.
static int log_count(const char* path, const char* what) {
    FILE* f = fopen(path, "r");
    char line[1024];
    int n = 0;
    while (f && fgets(line, sizeof line, f)) n += strstr(line, what) != NULL;
    if (f) fclose(f);
    return n;
}

static void reset_burst(void) {
    const char* log = "test_serve_rcl_reset.log";
    const char* args[] = {"--timeout", "2", NULL}; // the sandbox, real time at 75 frames/s
    served sv;
    CHECK(serve_start(&sv, log, args) == 0, "server started");
    int role = -1;
    const int w = serve_join(sv.port, PROTO_WATCH, &role);
    const int c = serve_join(sv.port, PROTO_CONTROL, &role);
    CHECK(w >= 0 && c >= 0 && role == PROTO_CONTROL, "watcher and controller joined");
    if (w < 0 || c < 0) {
        serve_stop(&sv);
        return;
    }
    double gap;
    CHECK(watch(w, 0.5, &gap) > 10, "frames before the burst");
    static uint8_t burst[1000 * 32];
    int notices = 0;
    long frames[2];
    double gaps[2];
    const int sizes[2] = {100, 1000};
    uint64_t seq = 0;
    for (int b = 0; b < 2; ++b) {
        size_t n = 0;
        for (int k = 0; k < sizes[b]; ++k) {
            proto_command cmd = {.seq = ++seq, .op = PROTO_OP_RESET};
            n += proto_put_command(burst + n, sizeof burst - n, &cmd);
        }
        CHECK(send_all(c, burst, n) == 0, "burst sent");
        // The watcher over the next 1.5 s: frames all along.
        frames[b] = watch(w, 1.5, &gaps[b]);
        // The controller's frames and notices meanwhile.
        // (0.2 s of them: it gets a frame every 13 ms.)
        proto_msg m;
        int t;
        for (const double t0 = now_s(); now_s() - t0 < 0.2 && (t = recv_frame(c, &m, &g_st, 200)) >= 0;)
            if (t == PROTO_NOTICE && m.u.text.code == PROTO_E_REFUSED && strstr(m.u.text.text, "at most one per"))
                ++notices;
        printf("burst of %d RESETs (%zu bytes): the watcher got %ld frames in 1.5 s, largest gap %.0f ms\n", sizes[b],
               n, frames[b], gaps[b] * 1e3);
    }
    // One more RESET now, and another 0.2 s after it: the second within a
    // second of the rebuild is refused with a notice, the connection stays.
    proto_command one = {.seq = ++seq, .op = PROTO_OP_RESET};
    send_cmd(c, &one);
    for (const double t0 = now_s(); now_s() - t0 < 0.2;) next_state(c, &g_st, 200);
    one.seq = ++seq;
    send_cmd(c, &one);
    int refused_now = 0;
    {
        proto_msg m;
        int t;
        for (const double t0 = now_s(); now_s() - t0 < 0.5 && (t = recv_frame(c, &m, &g_st, 200)) >= 0;)
            if (t == PROTO_NOTICE && m.u.text.seq == one.seq && strstr(m.u.text.text, "at most one per")) {
                refused_now = 1;
                printf("a RESET 0.2 s after one: '%s'\n", m.u.text.text);
            }
    }
    CHECK(refused_now, "a RESET 0.2 s after a rebuild was not refused");
    CHECK(next_state(c, &g_st, 2000) == 0 && next_state(w, &g_st, 2000) == 0, "both still served");
    CHECK(serve_stop(&sv) == 0, "server exits 0 on SIGINT");
    const int rebuilds = log_count(log, ": reset (rebuilt in"), all = log_count(log, ": reset");
    printf("rebuilds: %d (log lines naming a reset: %d); refused with a notice: %d\n", rebuilds, all, notices);
    CHECK(rebuilds == 3, "%d rebuilds for two bursts and a single RESET (three expected)", rebuilds);
    CHECK(all == rebuilds, "%d reset lines, %d rebuilds", all, rebuilds);
    // Not timed: a rebuild takes tens of ms; 1.5 s of a 75 Hz server that
    // rebuilt 1100 times (the old way) gives its watcher no frame at all.
    CHECK(frames[0] > 20 && frames[1] > 20, "the watcher starved: %ld and %ld frames in 1.5 s", frames[0], frames[1]);
    CHECK(log_count(log, "client limit reached") == 0 && log_count(log, "closed: no hello") == 0,
          "a client was refused or timed out during the bursts");
    close(w);
    close(c);
}

// ---- 3. a frame before the hello ----

static void before_hello(void) {
    const char* log = "test_serve_rcl_hello.log";
    const char* args[] = {"--mechanics", "lagrange", NULL};
    served sv;
    CHECK(serve_start(&sv, log, args) == 0, "server started");
    // A valves command cut short (its length leaves out 8 bytes), and a
    // whole reset command, each as the first frame.
    uint8_t b[128];
    proto_command cmd = {.seq = 1, .op = PROTO_OP_VALVES, .nu = 3};
    size_t n = proto_put_command(b, sizeof b, &cmd);
    b[0] = (uint8_t)(b[0] - 8);
    int fd = tcp_connect(sv.port);
    CHECK(fd >= 0 && send_all(fd, b, n - 8) == 0, "sent");
    proto_msg m;
    const int t = recv_frame(fd, &m, &g_st, 3000);
    CHECK(t == PROTO_ERROR && strstr(m.u.text.text, "no hello: the first frame must be a client hello, got a command"),
          "a short command before the hello: %d '%s'", t, t == PROTO_ERROR ? m.u.text.text : "");
    printf("short command before the hello: '%s'\n", t == PROTO_ERROR ? m.u.text.text : "(no error frame)");
    if (fd >= 0) close(fd);
    CHECK(serve_stop(&sv) == 0, "server exits 0 on SIGINT");
    CHECK(log_count(log, "too short") == 0 && log_count(log, "no hello: the first frame must be a client hello") == 1,
          "the log's reason");
}

int main(void) {
    signal(SIGPIPE, SIG_IGN);
    limiter_over_the_link();
    reset_burst();
    before_hello();
    TEST_MAIN_END();
}
