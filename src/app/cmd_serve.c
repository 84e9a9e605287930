// cmd_serve.c: `cranesim serve`: the simulation computer (docs/protocol.md).
//
// A stepped driver on an engine: per frame, apply the controlling client's
// last commands, advance the engine one frame on the simulated clock, and
// queue the state frame to every client. One thread, non-blocking sockets
// and ppoll: the loop never waits on a client. Each client's send queue is
// bounded, so a viewer that cannot keep up loses frames (its own only);
// malformed input closes that connection, with the reason logged and sent.
#define _GNU_SOURCE // ppoll
#include "app.h"
#include "engine.h"
#include "protocol.h"

#include <cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <malloc.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define SERVE_MAX_CLIENTS 64
#define SERVE_MAX_SETS 64
#define SERVE_READ_PER_FRAME 65536 // bytes read from one client per frame: a flood cannot starve the others
// The shortest wall time between two engine rebuilds (RESET) [s]. A rebuild
// of the sandbox takes about 7 ms with the limiter's chart kept (95 ms when
// it was computed again), during which no client gets a frame: one per
// second at most, so a stream of RESETs cannot take the frames of every
// client (before: 100 RESETs stopped them for 9.4 s).
#define SERVE_RESET_INTERVAL 1.0

static void serve_help(FILE* f) {
    fprintf(f,
            "usage: cranesim serve [--model M] [--world W] [--mechanics ode|lagrange] [--listen ADDR:PORT]\n"
            "                      [--rate HZ] [--max-clients N] [--lockstep] [--duration T]\n"
            "\n"
            "The simulation computer: runs the model headless in real time and streams its state over\n"
            "TCP to clients (a viewer, `cranesim drive --connect`, a valve controller, examples/), which\n"
            "send valve, hook, pause, reset and parameter commands back (docs/protocol.md). One client\n"
            "controls; the others watch. SIGINT or SIGTERM stop it cleanly (exit 0). Any crane shape:\n"
            "the hello lists its functions, the valve commands carry one opening per function\n"
            "(protocol version 3; a crane chain runs on ode in the sandbox).\n"
            "\n"
            "options:\n"
            "  --listen ADDR:PORT  where to listen (default 127.0.0.1:7575, loopback only; another\n"
            "                      address, e.g. 0.0.0.0:7575, only when asked; port 0: any free port)\n"
            "  --rate HZ           state frames per second, 1..5000 (default 75, the paper's rate)\n"
            "  --max-clients N     clients at once, 1..64 (default 8); one more is refused\n"
            "  --queue N           frames queued per client before it loses frames, 2..4096 (default 64)\n"
            "  --timeout S         a client that sends no hello, or reads nothing, for S seconds is\n"
            "                      closed, 0.05..3600 (default 5)\n"
            "  --lockstep          advance only on the controller's STEP commands (as fast as it asks:\n"
            "                      reproduces a scripted run bit for bit)\n"
            "  --realtime          real-time priority: SCHED_FIFO (or else nice -10) where permitted, memory\n"
            "                      locked and pre-faulted; a note says what was not granted (not with --lockstep)\n"
            "  --spin US           spin the last US microseconds before each frame instead of sleeping,\n"
            "                      0..2000 (default 500): the timer's wake-up is late by the scheduler's latency\n"
            "  --log-misses        log each missed frame deadline: how late it started, its step and send\n"
            "                      times, and the page faults and context switches during it\n"
            "  --rcl on|off        the rated capacity limiter (default on, as a local drive): it stops the\n"
            "                      motions that carry the load outwards at 100 %% of the load chart, on the\n"
            "                      controller's commands at every frame (docs/safety.md)\n"
            "  --duration T        stop after T simulated seconds (default: run until SIGINT)\n"
            "  --scenario S        the start pose and load (default as drive); its commands are not played\n"
            "  --mechanics M       ode (default: the sandbox world) or lagrange (analytic 2-DOF; not for a\n"
            "                      crane chain)\n"
            "  --world W           ode: world file or name: sandbox (default), validation\n");
    const unsigned all = APP_GIVEN(APP_OPT_COUNT) - 1u;
    app_options_help(f, all & ~(APP_GIVEN(APP_OPT_SCENARIO) | APP_GIVEN(APP_OPT_MECHANICS) | APP_GIVEN(APP_OPT_WORLD) |
                                APP_GIVEN(APP_OPT_DURATION) | APP_GIVEN(APP_OPT_EVERY)));
    fprintf(f, "It prints \"listening on ADDR:PORT\" on stdout once ready, and logs clients on stderr.\n");
}

typedef struct client {
    int fd, id;
    char peer[80];
    bool hello;            // handshake done
    int role;              // proto_role
    double t_open;         // wall time of the accept [s]
    double t_partial;      // wall time a partial frame began waiting, 0: none
    double stall_since;    // wall time its queue first overflowed, 0: keeping up
    uint8_t rx[4096];      // > PROTO_MAX_CLIENT_FRAME + 4: a whole frame always fits
    size_t rx_len;
    uint8_t* out;
    size_t out_cap, out_off, out_len;
    size_t read_frame;     // bytes read during this frame
    uint64_t frames, lost, cmds;
} client;

// One cylinder record of the state frame (the hello's "cylinders"): a
// chain actuator, its values from the row's chain columns and its pins from
// the world's picture where it draws it; or a cylinder of the picture (the
// two-link crane's, the sandbox's slew rack), all from the picture.
typedef struct serve_cyl {
    char name[WORLD_SNAP_NAME];
    int fn;     // the function that drives it (index in the hello's "functions"), -1: none
    int act;    // the chain actuator, -1: a cylinder of the picture
    int col[5]; // chain actuator: row columns x, v, pA, pB, F
    double bore, rod, stroke_max, closed_length; // [m]
} serve_cyl;

// One function of the hello's "functions" (engine_nfunction's order).
typedef struct serve_fn {
    char name[WORLD_SNAP_NAME];
    int ucol[2]; // its spool and command columns (u_<f>, ucmd_<f>) of a chain function, else -1
    int cyl;     // the first cylinder record it drives, -1: none
} serve_fn;

typedef struct serve_set {
    char path[PROTO_MAX_PATH + 1];
    double value;
} serve_set;

typedef struct server {
    // the simulation
    const model* m;
    sim_opts* o;
    const scenario* sc;
    double m3;
    engine* e;
    world_snapshot* snap;
    double frame;     // [s]
    long k;           // frames since the (re)start: the engine advances to (k + 1) * frame
    bool paused, lockstep, stopped;
    // The commands by function (nfn of them, the hello's order). The
    // two-link crane's are lift, jib, slew (engine_set_commands' u[3]).
    double u[PROTO_MAX_FN];
    int nfn;
    bool chain;     // a crane chain (commands by function, its columns), not the two-link crane
    serve_fn fn[PROTO_MAX_FN];
    int ncyl;
    serve_cyl cyl[PROTO_MAX_CYL];
    double* row;    // engine_row's, max(engine_ncol, SIM_NCOL) values
    uint64_t cmd_seq, seq;
    serve_set sets[SERVE_MAX_SETS]; // parameters set by clients, applied again after a reset
    int nset;
    // RESET: marked when it arrives, done once before the engine is next
    // used (commands that need it, the frame): a run of RESETs is one rebuild
    bool reset_pending;
    int reset_client;     // the client that asked (the log's)
    long reset_merged;    // RESETs merged into the pending one
    double t_reset;       // wall time of the last rebuild [s] (0: none yet)
    // the clients
    client* c[SERVE_MAX_CLIENTS];
    int nclient, max_clients, next_id, queue;
    int controller; // client id, 0: none
    double timeout;
    proto_state* st;
    uint8_t* frame_buf;
    size_t frame_cap;
    size_t queue_bytes; // a client's send queue: --queue state frames, plus room for the hello and notices
    double w0;
    bool quiet;
    // real-time pacing
    double spin;      // the last part of each wait spent spinning instead of sleeping [s]
    bool log_misses;  // a line per missed deadline with its times and the thread's faults and switches
} server;

static void logf_(const server* s, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "cranesim serve: [%9.3f s] ", sim_wall_time() - s->w0);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

// The controller's commands to the engine: the two-link crane's lift, jib,
// slew through engine_set_commands (and its limiter) as before version 3,
// a chain's by function.
static void set_commands(server* s) {
    if (!s->chain) engine_set_commands(s->e, s->u);
    else engine_set_function_commands(s->e, s->u, s->nfn, NULL, 0);
}

// ---- sending ----

static void flush_client(client* c) {
    while (c->out_off < c->out_len) {
        ssize_t n = send(c->fd, c->out + c->out_off, c->out_len - c->out_off, MSG_NOSIGNAL);
        if (n <= 0) break; // EAGAIN: the rest waits for POLLOUT; an error shows as a failed read
        c->out_off += (size_t)n;
    }
    if (c->out_off == c->out_len) c->out_off = c->out_len = 0;
    else if (c->out_off > c->out_cap / 2) {
        memmove(c->out, c->out + c->out_off, c->out_len - c->out_off);
        c->out_len -= c->out_off;
        c->out_off = 0;
    }
}

// Queue n bytes; false when they do not fit (the frame is lost for this client).
static bool enqueue(client* c, const uint8_t* b, size_t n) {
    if (c->out_off > 0 && c->out_len + n > c->out_cap) {
        memmove(c->out, c->out + c->out_off, c->out_len - c->out_off);
        c->out_len -= c->out_off;
        c->out_off = 0;
    }
    if (c->out_len + n > c->out_cap) return false;
    memcpy(c->out + c->out_len, b, n);
    c->out_len += n;
    return true;
}

static void send_text(client* c, uint8_t type, uint64_t seq, uint16_t code, const char* text) {
    uint8_t b[PROTO_MAX_TEXT + 32];
    size_t n = proto_put_text(b, sizeof b, type, seq, code, text);
    if (n) enqueue(c, b, n);
    flush_client(c);
}

static void drop_client(server* s, int idx, uint16_t code, const char* why) {
    client* c = s->c[idx];
    if (code) send_text(c, PROTO_ERROR, 0, code, why);
    logf_(s, "client %d (%s) closed: %s (%llu frames sent, %llu lost, %llu commands)", c->id, c->peer, why,
          (unsigned long long)c->frames, (unsigned long long)c->lost, (unsigned long long)c->cmds);
    if (s->controller == c->id) {
        // Dead-man: a controller that left (or whose link timed out) can no
        // longer stop what it started, so its last openings must not stay
        // applied. Every function's spool goes to neutral (0) at once.
        s->controller = 0;
        memset(s->u, 0, sizeof s->u);
        if (s->e) set_commands(s);
        logf_(s, "no client controls the crane now (valves to neutral)");
    }
    shutdown(c->fd, SHUT_WR);
    close(c->fd);
    free(c->out);
    free(c);
    s->c[idx] = s->c[--s->nclient];
}

// ---- the simulation ----

static int apply_set(server* s, const char* path, double value, char* err, size_t errsz) {
    if (!strcmp(path, "mechanics.load_mass")) {
        if (!engine_can_set_load(s->e)) {
            snprintf(err, errsz, "set mechanics.load_mass: this engine's loads are bodies (use the hook)");
            return -1;
        }
        if (!(value >= 0 && value <= 1e5)) {
            snprintf(err, errsz, "set mechanics.load_mass: expected 0..1e5 kg, got %g", value);
            return -1;
        }
        engine_set_load(s->e, value);
        return 0;
    }
    const char* p = path;
    if (!strncmp(p, "hydraulics.components.", 22)) p += 22;
    else if (!strncmp(p, "hydraulics.", 11)) p += 11;
    return hyd_model_set(engine_circuit(s->e), p, value, err, errsz);
}

// The collisions of the engine's run (since it was built: the start or
// the last reset), as a scripted run's metrics line counts them; the
// sandbox only.
static void log_collisions(const server* s, const char* when) {
    const sim_collisions* coll = s->e ? engine_collisions(s->e) : NULL;
    if (!coll) return;
    char t[SIM_COLL_TEXT];
    sim_collisions_text(coll, t, sizeof t);
    logf_(s, "%s: %s", when, t);
}

// The engine at the start pose; lim: the previous engine's limiter (its
// chart depends only on the model and the world, neither of which a SET
// changes: a SET acts on the engine's circuit), or NULL.
static int build_engine(server* s, struct rcl* lim, char* err, size_t errsz) {
    // The frames carry the world's picture (poses, pins, rope, HUD): an
    // engine without one (a chain outside the sandbox) is refused here, in
    // one line; any crane shape with one is served by function.
    if (engine_require(s->m, s->o, ENGINE_CAP_SNAPSHOT, "the serve protocol", err, errsz)) {
        engine_rcl_destroy(lim);
        return -1;
    }
    s->e = engine_create_rcl(s->m, s->o, s->sc->q0, s->sc->slew0, s->m3, lim, err, errsz);
    if (!s->e) {
        engine_rcl_destroy(lim);
        return -1;
    }
    s->k = 0;
    s->stopped = false;
    // The controller's commands (all 0 at the first build: serve_layout
    // has not run, so even a chain takes engine_set_commands' neutral).
    set_commands(s);
    for (int i = 0; i < s->nset; ++i) {
        char e2[320];
        if (apply_set(s, s->sets[i].path, s->sets[i].value, e2, sizeof e2)) logf_(s, "after reset: %s", e2);
    }
    return 0;
}

// The layout of the frames, from the engine just built (the model's: the
// same after every reset): its functions, its cylinder records (a chain's
// actuators with their columns, then the picture's other cylinders: the
// slew rack; the two-link crane's: the picture's, as before), and the row.
// 0, or -1 with one line in err for a crane the frames cannot carry.
static int serve_layout(server* s, char* err, size_t errsz) {
    engine* e = s->e;
    const crane_chain* cc = &s->m->chain;
    const char* file = s->m->file[0] ? s->m->file : "model";
    s->chain = !(engine_caps(e) & ENGINE_CAP_TWO_LINK);
    const int ncol = engine_ncol(e);
    if (ncol > PROTO_MAX_ROW) {
        snprintf(err, errsz, "the serve protocol: %s: its rows have %d columns; a state frame carries at most %d",
                 file, ncol, PROTO_MAX_ROW);
        return -1;
    }
    s->nfn = engine_nfunction(e);
    if (s->nfn > PROTO_MAX_FN) {
        snprintf(err, errsz, "the serve protocol: %s: %d functions; VALVES carries at most %d", file, s->nfn,
                 PROTO_MAX_FN);
        return -1;
    }
    s->row = calloc((size_t)(ncol > SIM_NCOL ? ncol : SIM_NCOL), sizeof *s->row);
    if (!s->row) {
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    engine_snapshot(e, s->snap);
    const world_snapshot* w = s->snap;
    s->ncyl = 0;
    const int base = ncol - cc->ncol; // the chain's columns come after the backend's (engine_channels)
    if (s->chain) {
        for (int a = 0; a < cc->nact; ++a) {
            if (s->ncyl == PROTO_MAX_CYL) break;
            const crane_act* ca = &cc->act[a];
            serve_cyl* y = &s->cyl[s->ncyl++];
            snprintf(y->name, sizeof y->name, "%s", ca->name);
            y->act = a;
            y->fn = engine_find_function(e, cc->fn[ca->function].name);
            static const char* const what[5] = {"x", "v", "pA", "pB", "F"};
            for (int k = 0; k < 5; ++k) {
                const int c = crane_chain_find_column(cc, what[k], ca->name);
                y->col[k] = c < 0 ? -1 : base + c;
                if (c < 0) {
                    snprintf(err, errsz, "the serve protocol: %s: actuator %s has no %s_%s column", file, ca->name,
                             what[k], ca->name);
                    return -1;
                }
            }
            double AA, AB, st;
            hyd_model_cylinder_geometry(engine_circuit(e), ca->cyl, &AA, &AB, &st);
            y->bore = sqrt(4.0 * AA / M_PI);
            y->rod = sqrt(4.0 * (AA - AB) / M_PI);
            y->stroke_max = ca->stroke;
            y->closed_length = ca->closed_length;
        }
    }
    for (int j = 0; j < w->ncyl && j < WORLD_SNAP_MAX_CYLINDERS; ++j) {
        const world_snap_cylinder* c = &w->cyl[j];
        if (s->chain && crane_chain_find_act(cc, c->name) >= 0) continue; // a chain actuator: above
        if (s->ncyl == PROTO_MAX_CYL) {
            snprintf(err, errsz, "the serve protocol: %s: more than %d cylinders", file, PROTO_MAX_CYL);
            return -1;
        }
        serve_cyl* y = &s->cyl[s->ncyl++];
        snprintf(y->name, sizeof y->name, "%s", c->name);
        y->act = -1;
        // The two-link crane's actuators are named as their functions
        // (crane_chain_from_mech), the slew rack "slew".
        const int a = crane_chain_find_act(cc, c->name);
        y->fn = engine_find_function(e, a >= 0 ? cc->fn[cc->act[a].function].name : c->name);
        y->bore = c->bore, y->rod = c->rod, y->stroke_max = c->stroke_max, y->closed_length = c->closed_length;
    }
    if (s->chain && s->ncyl < cc->nact) {
        snprintf(err, errsz, "the serve protocol: %s: %d actuators; a state frame carries at most %d cylinders", file,
                 cc->nact, PROTO_MAX_CYL);
        return -1;
    }
    for (int k = 0; k < s->nfn; ++k) {
        serve_fn* f = &s->fn[k];
        snprintf(f->name, sizeof f->name, "%s", engine_function_name(e, k));
        f->ucol[0] = f->ucol[1] = -1;
        const int cf = s->chain ? crane_chain_find_function(cc, f->name) : -1;
        if (cf >= 0) {
            const int cu = crane_chain_find_column(cc, "u", f->name), cm = crane_chain_find_column(cc, "ucmd", f->name);
            if (cu < 0 || cm < 0) {
                snprintf(err, errsz, "the serve protocol: %s: function %s has no u_%s or ucmd_%s column", file,
                         f->name, f->name, f->name);
                return -1;
            }
            f->ucol[0] = base + cu, f->ucol[1] = base + cm;
        }
        f->cyl = -1;
        for (int i = 0; i < s->ncyl && f->cyl < 0; ++i)
            if (s->cyl[i].fn == k) f->cyl = i;
    }
    return 0;
}

// A pending RESET: the engine rebuilt at the start pose (the clock at 0),
// once for every RESET that came since the last frame or command that used
// the engine. Returns false when the rebuild failed.
static bool do_reset(server* s) {
    if (!s->reset_pending) return true;
    s->reset_pending = false;
    log_collisions(s, "before the reset");
    struct rcl* lim = engine_rcl_detach(s->e);
    engine_destroy(s->e);
    s->e = NULL;
    char err[400];
    const double t0 = sim_wall_time();
    const int rc = build_engine(s, lim, err, sizeof err);
    s->t_reset = sim_wall_time();
    if (rc) {
        // The model built once already: only memory can fail here.
        logf_(s, "reset failed: %s", err);
        s->stopped = true;
        return false;
    }
    char merged[64] = "";
    if (s->reset_merged) snprintf(merged, sizeof merged, ", %ld more merged into it", s->reset_merged);
    logf_(s, "client %d: reset (rebuilt in %.1f ms%s)", s->reset_client, (s->t_reset - t0) * 1e3, merged);
    s->reset_merged = 0;
    return true;
}

// Advance one frame. Returns false once the engine has stopped.
static bool step_frame(server* s) {
    if (!do_reset(s) || s->stopped) return false;
    // The controller's commands again at every frame, not only when they
    // change: the limiter (engine_set_commands) cuts them from the state
    // reached, as a local drive's ticks have it.
    set_commands(s);
    if (engine_advance(s->e, (s->k + 1) * s->frame - engine_time(s->e))) {
        s->stopped = true;
        logf_(s, "the simulation stopped: %s (RESET starts it again)", engine_error(s->e));
        return false;
    }
    ++s->k;
    return true;
}

// The picture's cylinder called name, or -1.
static int snap_cyl(const world_snapshot* w, const char* name) {
    for (int j = 0; j < w->ncyl && j < WORLD_SNAP_MAX_CYLINDERS; ++j)
        if (!strcmp(w->cyl[j].name, name)) return j;
    return -1;
}

static double clamp_opening(double v) { return !(v >= -1) ? -1 : v > 1 ? 1 : v; }

// Every function's command and spool [-] into the state frame: a chain
// function's from its columns, another's (the two-link crane's, the slew
// rack) from its cylinder in the picture; a function with neither (the
// lagrange crane's slew: it does not slew) carries its command as given
// in both.
static void fill_functions(server* s, const double* row, const world_snapshot* w) {
    proto_state* st = s->st;
    st->nfn = (uint8_t)s->nfn;
    for (int k = 0; k < s->nfn; ++k) {
        const serve_fn* f = &s->fn[k];
        double* v = st->fn[k];
        const int j = f->ucol[0] < 0 && f->cyl >= 0 ? snap_cyl(w, s->cyl[f->cyl].name) : -1;
        if (f->ucol[0] >= 0) v[0] = row[f->ucol[1]], v[1] = row[f->ucol[0]];
        else if (j >= 0) v[0] = w->cyl[j].u_cmd, v[1] = w->cyl[j].u;
        else v[0] = v[1] = clamp_opening(engine_function_command(s->e, k));
    }
}

static void fill_state(server* s) {
    do_reset(s);
    proto_state* st = s->st;
    double* row = s->row;
    engine_row(s->e, row);
    engine_snapshot(s->e, s->snap);
    const world_snapshot* w = s->snap;
    st->seq = ++s->seq;
    st->cmd_seq = s->cmd_seq;
    st->flags = (s->paused ? PROTO_F_PAUSED : 0) | (w->attached ? PROTO_F_ATTACHED : 0) |
                (s->stopped ? PROTO_F_STOPPED : 0) | (s->lockstep ? PROTO_F_LOCKSTEP : 0) |
                (w->tipping ? PROTO_F_TIPPING : 0) | (w->main_relief_open ? PROTO_F_RELIEF : 0) |
                (w->collision ? PROTO_F_COLLISION : 0) | (w->rcl_have ? PROTO_F_RCL_HAVE : 0) |
                (w->rcl_on ? PROTO_F_RCL_ON : 0) | (uint32_t)(w->npad ? (w->pad_lifted & 15) : 0) * PROTO_F_PAD_LIFTED0;
    for (int k = 0; k < 3 && k < w->ncyl; ++k)
        if (w->cyl[k].rcl_cut) st->flags |= PROTO_F_RCL_CUT0 << k;
    st->slew = w->slew;
    memcpy(st->hook, w->hook, sizeof st->hook);
    st->load_mass = w->load_mass;
    memcpy(st->tip, w->tip, sizeof st->tip);
    st->roll = st->pitch = 0;
    for (int i = 0; i < w->nbody; ++i)
        if (w->body[i].role == WORLD_ROLE_TRUCK) {
            proto_roll_pitch(w->body[i].rot, &st->roll, &st->pitch);
            break;
        }
    st->p_supply = w->p_supply;
    st->rcl_util = w->rcl_util;
    st->stab_margin = w->stab_margin;
    st->npad = (uint8_t)(w->npad > 0 && w->npad <= PROTO_MAX_PADS ? w->npad : 0);
    memcpy(st->pad_F, w->pad_F, st->npad * sizeof w->pad_F[0]);
    const int ncol = engine_ncol(s->e);
    st->attached = ncol > COL_ATTACHED ? (int32_t)row[COL_ATTACHED] : -1;
    st->nrow = (uint16_t)(ncol < PROTO_MAX_ROW ? ncol : PROTO_MAX_ROW);
    memcpy(st->row, row, st->nrow * sizeof row[0]);
    st->nbody = (uint16_t)(w->nbody < PROTO_MAX_BODIES ? w->nbody : PROTO_MAX_BODIES);
    for (int i = 0; i < st->nbody; ++i) {
        memcpy(st->pose[i], w->body[i].pos, 3 * sizeof(double));
        memcpy(st->pose[i] + 3, w->body[i].rot, 9 * sizeof(double));
    }
    fill_functions(s, row, w);
    st->ncyl = (uint8_t)s->ncyl;
    int rec_of_snap[WORLD_SNAP_MAX_CYLINDERS]; // the record of each cylinder of the picture, -1
    for (int j = 0; j < WORLD_SNAP_MAX_CYLINDERS; ++j) rec_of_snap[j] = -1;
    for (int i = 0; i < s->ncyl; ++i) {
        const serve_cyl* sc = &s->cyl[i];
        const int j = snap_cyl(w, sc->name);
        const world_snap_cylinder* y = j >= 0 ? &w->cyl[j] : NULL;
        if (j >= 0) rec_of_snap[j] = i;
        double* d = st->cyl[i];
        if (sc->act < 0 && !y) { // not in this picture (it drew it at the start): nothing known
            memset(d, 0, PROTO_CYL_VALUES * sizeof(double));
        } else if (sc->act < 0) { // a cylinder of the picture: all of it from there (the two-link crane as before)
            memcpy(d, y->base, 3 * sizeof(double));
            memcpy(d + 3, y->rod_end, 3 * sizeof(double));
            d[6] = y->x, d[7] = y->pA, d[8] = y->pB, d[9] = y->u, d[10] = y->u_cmd, d[11] = y->force, d[12] = y->v;
        } else { // a chain actuator: the row's values, the picture's pins where it draws it
            if (y) {
                memcpy(d, y->base, 3 * sizeof(double));
                memcpy(d + 3, y->rod_end, 3 * sizeof(double));
            } else {
                memset(d, 0, 6 * sizeof(double));
            }
            d[6] = row[sc->col[0]], d[7] = row[sc->col[2]], d[8] = row[sc->col[3]];
            d[9] = sc->fn >= 0 ? st->fn[sc->fn][1] : 0, d[10] = sc->fn >= 0 ? st->fn[sc->fn][0] : 0;
            d[11] = row[sc->col[4]], d[12] = row[sc->col[1]];
        }
        st->cyl_bits[i] = (uint8_t)(y ? (y->relief_open ? PROTO_CYL_RELIEF : 0) | (y->end_stop ? PROTO_CYL_END_STOP : 0)
                                      : PROTO_CYL_NO_PINS);
    }
    // The paper's nine: the two-link crane's columns as before; a chain's
    // first two functions (their first actuators' strokes and chamber
    // pressures, their spools), docs/protocol.md.
    if (!s->chain) {
        const int cols[9] = {COL_X1, COL_X2, COL_P1A, COL_P1B, COL_P2A, COL_P2B, COL_U1, COL_U2, COL_T};
        for (int k = 0; k < 9; ++k) st->nine[k] = row[cols[k]];
    } else {
        memset(st->nine, 0, sizeof st->nine);
        for (int f = 0; f < 2 && f < s->nfn; ++f) {
            const int c = s->fn[f].cyl;
            if (c >= 0) {
                st->nine[f] = st->cyl[c][6];
                st->nine[2 + 2 * f] = st->cyl[c][7];
                st->nine[3 + 2 * f] = st->cyl[c][8];
            }
            st->nine[6 + f] = st->fn[f][1];
        }
        st->nine[8] = row[COL_T];
    }
    st->nrelief = 0;
    for (int i = 0; i < w->nrelief && i < WORLD_SNAP_MAX_RELIEFS && st->nrelief < PROTO_MAX_RELIEFS; ++i) {
        proto_relief* q = &st->relief[st->nrelief];
        const int cyl = w->relief_cyl[i];
        if (!w->relief[i][0]) continue;
        q->cyl = (int8_t)(cyl >= 0 && cyl < WORLD_SNAP_MAX_CYLINDERS ? rec_of_snap[cyl] : -1);
        q->port = (uint8_t)(w->relief_port[i] ? 1 : 0);
        snprintf(q->name, sizeof q->name, "%s", w->relief[i]);
        ++st->nrelief;
    }
    st->nrope = (uint8_t)(w->nrope < PROTO_MAX_ROPE ? w->nrope : PROTO_MAX_ROPE);
    memcpy(st->rope, w->rope, st->nrope * sizeof w->rope[0]);
}

// The state now, to every client that finished its hello.
static void broadcast(server* s) {
    fill_state(s);
    const size_t n = proto_put_state(s->frame_buf, s->frame_cap, s->st);
    const double now = sim_wall_time();
    for (int i = 0; i < s->nclient; ++i) {
        client* c = s->c[i];
        if (!c->hello) continue;
        if (n && enqueue(c, s->frame_buf, n)) {
            ++c->frames;
        } else {
            ++c->lost;
            if (!c->stall_since) c->stall_since = now;
        }
        flush_client(c);
        if (c->out_len == 0) c->stall_since = 0;
    }
}

// ---- the hello's description ----

static char* describe(server* s, const char* model_file, const char* model_asset) {
    cJSON* j = cJSON_CreateObject();
    cJSON_AddNumberToObject(j, "protocol", PROTO_VERSION);
    cJSON_AddStringToObject(j, "model", s->m->name);
    cJSON_AddStringToObject(j, "model_file", model_file);
    cJSON_AddStringToObject(j, "model_asset", model_asset);
    cJSON_AddStringToObject(j, "backend", engine_backend_name(s->e));
    engine_desc d;
    engine_describe(s->o, &d);
    cJSON_AddStringToObject(j, "world", d.world);
    char wb[512];
    const engine_backend* be = app_backend(s->o);
    cJSON_AddStringToObject(j, "world_file", be->world ? sim_world_path(s->o->world, wb, sizeof wb) : "");
    cJSON_AddStringToObject(j, "solver", hyd_method_name(s->o->solver));
    cJSON_AddNumberToObject(j, "h", s->o->h);
    cJSON_AddNumberToObject(j, "dt_ode", be->outer_step_opt ? s->o->dt_ode : 0);
    cJSON_AddNumberToObject(j, "frame", s->frame);
    cJSON* ch = cJSON_AddArrayToObject(j, "channels");
    int nch = 0;
    const sim_channel* chs = engine_channels(s->e, &nch);
    for (int i = 0; i < nch && i < PROTO_MAX_ROW; ++i) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", chs[i].name);
        cJSON_AddStringToObject(o, "unit", chs[i].unit);
        cJSON_AddItemToArray(ch, o);
    }
    cJSON* lo = cJSON_AddArrayToObject(j, "loads");
    double mass;
    const char* ln;
    for (int i = 0; (ln = engine_load_name(s->e, i, &mass)) != NULL; ++i) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", ln);
        cJSON_AddNumberToObject(o, "mass", mass);
        cJSON_AddItemToArray(lo, o);
    }
    engine_snapshot(s->e, s->snap);
    const world_snapshot* w = s->snap;
    cJSON* bo = cJSON_AddArrayToObject(j, "bodies");
    for (int i = 0; i < w->nbody && i < PROTO_MAX_BODIES; ++i) {
        const world_snap_body* b = &w->body[i];
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", b->name);
        cJSON_AddNumberToObject(o, "role", b->role);
        cJSON_AddNumberToObject(o, "shape", b->shape);
        cJSON_AddItemToObject(o, "size", cJSON_CreateDoubleArray(b->size, 3));
        const double rgba[4] = {b->rgba[0], b->rgba[1], b->rgba[2], b->rgba[3]};
        cJSON_AddItemToObject(o, "rgba", cJSON_CreateDoubleArray(rgba, 4));
        cJSON_AddStringToObject(o, "mesh", b->mesh);
        cJSON_AddNumberToObject(o, "mesh_scale", b->mesh_scale);
        cJSON_AddNumberToObject(o, "mesh_up", b->mesh_up);
        cJSON_AddItemToObject(o, "mesh_offset", cJSON_CreateDoubleArray(b->mesh_offset, 3));
        cJSON_AddItemToArray(bo, o);
    }
    cJSON* cy = cJSON_AddArrayToObject(j, "cylinders");
    for (int i = 0; i < s->ncyl; ++i) {
        const serve_cyl* y = &s->cyl[i];
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", y->name);
        cJSON_AddNumberToObject(o, "bore", y->bore);
        cJSON_AddNumberToObject(o, "rod", y->rod);
        cJSON_AddNumberToObject(o, "stroke_max", y->stroke_max);
        cJSON_AddNumberToObject(o, "closed_length", y->closed_length);
        cJSON_AddNumberToObject(o, "function", y->fn);
        cJSON_AddItemToArray(cy, o);
    }
    // The functions, in the order of VALVES' openings and of the state
    // frame's function records, each with the cylinder records it drives.
    cJSON* fa = cJSON_AddArrayToObject(j, "functions");
    for (int k = 0; k < s->nfn; ++k) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", s->fn[k].name);
        cJSON_AddStringToObject(o, "unit", "-");
        cJSON_AddItemToObject(o, "range", cJSON_CreateDoubleArray((const double[2]){-1, 1}, 2));
        cJSON* ac = cJSON_AddArrayToObject(o, "actuators");
        for (int i = 0; i < s->ncyl; ++i) {
            if (s->cyl[i].fn != k) continue;
            cJSON* a = cJSON_CreateObject();
            cJSON_AddStringToObject(a, "name", s->cyl[i].name);
            cJSON_AddNumberToObject(a, "cylinder", i);
            cJSON* u = cJSON_AddObjectToObject(a, "units");
            cJSON_AddStringToObject(u, "stroke", "m");
            cJSON_AddStringToObject(u, "rate", "m/s");
            cJSON_AddStringToObject(u, "pA", "Pa abs");
            cJSON_AddStringToObject(u, "pB", "Pa abs");
            cJSON_AddStringToObject(u, "force", "N");
            cJSON_AddItemToArray(ac, a);
        }
        cJSON_AddItemToArray(fa, o);
    }
    // The crane's bodies in chain order (body 0 the column), each with its
    // joint's coordinate and unit, and its pose in "bodies" (-1: not drawn).
    const crane_chain* cc = &s->m->chain;
    cJSON* cb = cJSON_AddArrayToObject(j, "crane_bodies");
    for (int i = 0; i < cc->nbody; ++i) {
        const chain_body_def* d = &cc->body[i].def;
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", d->name);
        const bool prismatic = d->joint == CHAIN_PRISMATIC;
        cJSON_AddStringToObject(o, "joint", prismatic ? "prismatic" : "revolute");
        cJSON_AddStringToObject(o, "unit", prismatic ? "m" : "rad");
        cJSON_AddBoolToObject(o, "fixed", d->fixed != 0);
        int pose = -1;
        for (int b = 0; b < w->nbody && b < PROTO_MAX_BODIES && pose < 0; ++b)
            if (!strcmp(w->body[b].name, d->name)) pose = b;
        cJSON_AddNumberToObject(o, "pose", pose);
        cJSON_AddItemToArray(cb, o);
    }
    char* txt = cJSON_PrintUnformatted(j);
    cJSON_Delete(j);
    return txt;
}

// ---- a client's frames ----

static void handle_command(server* s, client* c, const proto_command* cmd) {
    ++c->cmds;
    if (c->role != PROTO_CONTROL) {
        char t[160];
        snprintf(t, sizeof t, "command %llu (%s) refused: this client watches (another one controls)",
                 (unsigned long long)cmd->seq, proto_op_name(cmd->op));
        send_text(c, PROTO_NOTICE, cmd->seq, PROTO_E_READONLY, t);
        return;
    }
    char err[400] = "";
    int refused = 0;
    // Every command but VALVES, PAUSE and RESET acts on the engine: a
    // pending reset first, so the commands take effect in their order.
    if (cmd->op == PROTO_OP_HOOK || cmd->op == PROTO_OP_SET || cmd->op == PROTO_OP_STEP) do_reset(s);
    switch (cmd->op) {
    case PROTO_OP_VALVES:
        if (cmd->nu != s->nfn) {
            int n = snprintf(err, sizeof err, "valves: %u openings for the %d functions", cmd->nu, s->nfn);
            for (int k = 0; k < s->nfn && n > 0 && (size_t)n < sizeof err; ++k)
                n += snprintf(err + n, sizeof err - (size_t)n, "%s%s", k ? ", " : " ", s->fn[k].name);
            if (n > 0 && (size_t)n < sizeof err)
                snprintf(err + n, sizeof err - (size_t)n, " (one per function, in the hello's order)");
            refused = 1;
            break;
        }
        memcpy(s->u, cmd->u, (size_t)s->nfn * sizeof s->u[0]);
        set_commands(s);
        break;
    case PROTO_OP_HOOK: {
        int got = engine_hook(s->e, cmd->flag);
        if (cmd->flag && got < 0) {
            snprintf(err, sizeof err, "hook: no load in reach (or this world has no hook)");
            refused = 1;
        } else {
            logf_(s, "client %d: hook %s", c->id, cmd->flag ? "attached" : "released");
        }
        break;
    }
    case PROTO_OP_PAUSE:
        if (s->paused != (cmd->flag != 0)) logf_(s, "client %d: %s", c->id, cmd->flag ? "paused" : "running");
        s->paused = cmd->flag != 0;
        break;
    case PROTO_OP_RESET: {
        // Merged into one that has not been done yet; else at most one
        // rebuild per SERVE_RESET_INTERVAL.
        const double since = sim_wall_time() - s->t_reset;
        if (s->reset_pending) {
            ++s->reset_merged;
        } else if (s->t_reset > 0 && since < SERVE_RESET_INTERVAL) {
            snprintf(err, sizeof err,
                     "reset: the last one was %.2f s ago; at most one per %g s (a rebuild stops the frames of every "
                     "client)",
                     since, SERVE_RESET_INTERVAL);
            refused = 1;
        } else {
            s->reset_pending = true;
            s->reset_client = c->id;
        }
        break;
    }
    case PROTO_OP_SET:
        if (apply_set(s, cmd->path, cmd->value, err, sizeof err)) {
            refused = 1;
            break;
        }
        logf_(s, "client %d: set %s = %g", c->id, cmd->path, cmd->value);
        {
            int i = 0;
            while (i < s->nset && strcmp(s->sets[i].path, cmd->path)) ++i;
            if (i < SERVE_MAX_SETS) {
                snprintf(s->sets[i].path, sizeof s->sets[i].path, "%s", cmd->path);
                s->sets[i].value = cmd->value;
                if (i == s->nset) ++s->nset;
            }
        }
        break;
    case PROTO_OP_STEP:
        if (!s->lockstep) {
            snprintf(err, sizeof err, "step: this server runs in real time (start it with --lockstep)");
            refused = 1;
            break;
        }
        s->cmd_seq = cmd->seq;
        for (uint32_t k = 0; k < cmd->frames && !s->paused; ++k)
            if (!step_frame(s)) break;
        broadcast(s);
        return;
    }
    if (refused) {
        char t[PROTO_MAX_TEXT];
        snprintf(t, sizeof t, "command %llu refused: %s", (unsigned long long)cmd->seq, err);
        send_text(c, PROTO_NOTICE, cmd->seq, PROTO_E_REFUSED, t);
        return;
    }
    s->cmd_seq = cmd->seq;
}

static char g_desc_file[PATH_MAX];
static char* g_desc;

// Returns false when the client was closed.
static bool handle_frame(server* s, int idx, const proto_msg* msg) {
    client* c = s->c[idx];
    char why[320];
    if (!c->hello) {
        if (msg->type != PROTO_CLIENT_HELLO) {
            drop_client(s, idx, PROTO_E_MALFORMED, "the first frame must be a client hello");
            return false;
        }
        if (msg->u.chello.version != PROTO_VERSION) {
            // A client of an older version would misread every frame (a
            // chain's functions, VALVES by function): it gets this line.
            snprintf(why, sizeof why,
                     "protocol version %u not supported: this server speaks version %u, which lists the functions "
                     "in its hello and takes one valve opening per function: update the client (docs/protocol.md)",
                     msg->u.chello.version, PROTO_VERSION);
            drop_client(s, idx, PROTO_E_VERSION, why);
            return false;
        }
        c->role = PROTO_WATCH;
        if (msg->u.chello.role == PROTO_CONTROL && !s->controller) {
            c->role = PROTO_CONTROL;
            s->controller = c->id;
        }
        proto_server_hello h = {.version = PROTO_VERSION, .role = (uint8_t)c->role, .lockstep = s->lockstep,
                                .rate = 1.0 / s->frame, .json = g_desc, .json_len = (uint32_t)strlen(g_desc)};
        const size_t n = proto_put_server_hello(s->frame_buf, s->frame_cap, &h);
        if (!n || !enqueue(c, s->frame_buf, n)) {
            drop_client(s, idx, PROTO_E_FULL, "the description does not fit the send queue");
            return false;
        }
        c->hello = true;
        logf_(s, "client %d (%s): hello, %s%s", c->id, c->peer, c->role == PROTO_CONTROL ? "controls" : "watches",
              msg->u.chello.role == PROTO_CONTROL && c->role != PROTO_CONTROL ? " (control asked: held by another)"
                                                                                 : "");
        if (s->lockstep) { // a lockstep client sees the state before its first STEP
            fill_state(s);
            const size_t k = proto_put_state(s->frame_buf, s->frame_cap, s->st);
            if (k && enqueue(c, s->frame_buf, k)) ++c->frames;
        }
        flush_client(c);
        return true;
    }
    if (msg->type != PROTO_COMMAND) {
        snprintf(why, sizeof why, "unexpected frame type %u after the hello (only commands)", msg->type);
        drop_client(s, idx, PROTO_E_MALFORMED, why);
        return false;
    }
    handle_command(s, c, &msg->u.cmd);
    return true;
}

// Read what the client sent and act on each whole frame. Returns false when it was closed.
static bool read_client(server* s, int idx) {
    client* c = s->c[idx];
    while (c->read_frame < SERVE_READ_PER_FRAME) {
        ssize_t n = recv(c->fd, c->rx + c->rx_len, sizeof c->rx - c->rx_len, 0);
        if (n == 0) {
            drop_client(s, idx, 0, c->rx_len ? "disconnected in the middle of a frame" : "disconnected");
            return false;
        }
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) break;
            char why[160];
            snprintf(why, sizeof why, "connection failed: %s", strerror(errno));
            drop_client(s, idx, 0, why);
            return false;
        }
        c->read_frame += (size_t)n;
        c->rx_len += (size_t)n;
        // The parser refuses a length above PROTO_MAX_CLIENT_FRAME from its
        // header, so a full buffer means a parser fault: never wait on it.
        if (c->rx_len == sizeof c->rx && proto_parse(c->rx, c->rx_len, PROTO_MAX_CLIENT_FRAME, &(size_t){0},
                                                     &(proto_msg){0}, (char[8]){0}, 8) == 0) {
            drop_client(s, idx, PROTO_E_MALFORMED, "malformed frame: longer than the receive buffer");
            return false;
        }
        size_t off = 0;
        for (;;) {
            // Before the hello only a hello is heard: any other frame is
            // refused for that, whatever its fields (a command frame checked
            // first was "command frame too short" for a client that simply
            // had not said hello).
            if (!c->hello && c->rx_len - off >= PROTO_HEADER && c->rx[off + 4] != PROTO_CLIENT_HELLO) {
                static const char* const k_type[] = {"", "client hello", "server hello", "state", "command", "error",
                                                     "notice"};
                const uint8_t ty = c->rx[off + 4];
                char why[160];
                snprintf(why, sizeof why, "no hello: the first frame must be a client hello, got %s%s frame (type %u)",
                         ty >= 1 && ty <= 6 ? "a " : "an unknown", ty >= 1 && ty <= 6 ? k_type[ty] : "", ty);
                drop_client(s, idx, PROTO_E_MALFORMED, why);
                return false;
            }
            proto_msg msg;
            memset(&msg, 0, sizeof msg); // u.state NULL: a client may not send state frames
            size_t used;
            char err[256];
            int rc = proto_parse(c->rx + off, c->rx_len - off, PROTO_MAX_CLIENT_FRAME, &used, &msg, err, sizeof err);
            if (rc < 0) {
                char why[300];
                snprintf(why, sizeof why, "malformed frame: %s", err);
                drop_client(s, idx, PROTO_E_MALFORMED, why);
                return false;
            }
            if (rc == 0) break;
            off += used;
            if (!handle_frame(s, idx, &msg)) return false;
        }
        memmove(c->rx, c->rx + off, c->rx_len - off);
        c->rx_len -= off;
        c->t_partial = c->rx_len ? (c->t_partial ? c->t_partial : sim_wall_time()) : 0;
    }
    return true;
}

static void accept_clients(server* s, int lfd) {
    for (;;) {
        struct sockaddr_storage a;
        socklen_t al = sizeof a;
        int fd = accept(lfd, (struct sockaddr*)&a, &al);
        if (fd < 0) return; // EAGAIN: none left (or a transient error: the next poll retries)
        fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
        fcntl(fd, F_SETFD, FD_CLOEXEC);
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one); // a frame goes out at once
        // A small kernel buffer: frames a slow viewer cannot take are lost
        // here, not queued for seconds behind it (256 KiB).
        int sb = 256 * 1024;
        setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &sb, sizeof sb);
        char host[64] = "?", port[16] = "?";
        getnameinfo((struct sockaddr*)&a, al, host, sizeof host, port, sizeof port, NI_NUMERICHOST | NI_NUMERICSERV);
        client* c = calloc(1, sizeof *c);
        const size_t cap = s->queue_bytes;
        if (c) c->out = malloc(cap);
        if (!c || !c->out) {
            free(c);
            close(fd);
            logf_(s, "connection from %s:%s refused: out of memory", host, port);
            continue;
        }
        c->fd = fd;
        c->id = ++s->next_id;
        c->out_cap = cap;
        c->t_open = sim_wall_time();
        snprintf(c->peer, sizeof c->peer, "%s:%s", host, port);
        if (s->nclient >= s->max_clients) {
            char why[120];
            snprintf(why, sizeof why, "client limit reached (%d, --max-clients)", s->max_clients);
            s->c[s->nclient++] = c;
            drop_client(s, s->nclient - 1, PROTO_E_FULL, why);
            continue;
        }
        s->c[s->nclient++] = c;
        logf_(s, "client %d (%s) connected (%d of %d)", c->id, c->peer, s->nclient, s->max_clients);
    }
}

// Close clients that sent no hello, left a frame half sent, or read nothing, for the timeout.
static void check_timeouts(server* s) {
    const double now = sim_wall_time();
    for (int i = s->nclient - 1; i >= 0; --i) {
        client* c = s->c[i];
        char why[160];
        if (!c->hello && now - c->t_open > s->timeout) {
            snprintf(why, sizeof why, "no hello within %g s (--timeout)", s->timeout);
            drop_client(s, i, PROTO_E_TIMEOUT, why);
        } else if (c->t_partial && now - c->t_partial > s->timeout) {
            snprintf(why, sizeof why, "a frame left incomplete for %g s (--timeout)", s->timeout);
            drop_client(s, i, PROTO_E_TIMEOUT, why);
        } else if (c->stall_since && now - c->stall_since > s->timeout) {
            snprintf(why, sizeof why, "not reading: its queue was full for %g s (--timeout)", s->timeout);
            drop_client(s, i, PROTO_E_SLOW, why);
        }
    }
}

static int open_listener(const char* addr, char* bound, size_t nb, char* err, size_t errsz) {
    char host[256];
    const char* colon = strrchr(addr, ':');
    if (!colon || colon == addr || !colon[1] || (size_t)(colon - addr) >= sizeof host) {
        snprintf(err, errsz, "--listen: expected ADDR:PORT (127.0.0.1:7575, [::1]:7575), got '%s'", addr);
        return -1;
    }
    memcpy(host, addr, (size_t)(colon - addr));
    host[colon - addr] = 0;
    char* h = host;
    if (h[0] == '[' && h[strlen(h) - 1] == ']') {
        h[strlen(h) - 1] = 0;
        ++h;
    }
    char* endp;
    long port = strtol(colon + 1, &endp, 10);
    if (*endp || port < 0 || port > 65535) {
        snprintf(err, errsz, "--listen: port must be 0..65535, got '%s'", colon + 1);
        return -1;
    }
    struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM,
                             .ai_flags = AI_PASSIVE | AI_NUMERICSERV}, *res;
    int g = getaddrinfo(h, colon + 1, &hints, &res);
    if (g) {
        snprintf(err, errsz, "--listen %s: %s", addr, gai_strerror(g));
        return -1;
    }
    int fd = socket(res->ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    int one = 1;
    if (fd >= 0) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (fd < 0 || bind(fd, res->ai_addr, res->ai_addrlen) || listen(fd, 16)) {
        snprintf(err, errsz, "--listen %s: %s", addr, strerror(errno));
        if (fd >= 0) close(fd);
        freeaddrinfo(res);
        return -1;
    }
    freeaddrinfo(res);
    struct sockaddr_storage a;
    socklen_t al = sizeof a;
    getsockname(fd, (struct sockaddr*)&a, &al);
    char hs[64], ps[16];
    getnameinfo((struct sockaddr*)&a, al, hs, sizeof hs, ps, sizeof ps, NI_NUMERICHOST | NI_NUMERICSERV);
    snprintf(bound, nb, strchr(hs, ':') ? "[%s]:%s" : "%s:%s", hs, ps);
    return fd;
}

// --realtime: what the process may have of a real-time task, each step
// logged with what was granted. Memory first: a page fault inside a frame
// costs a few us (minor) to ms (major), so the heap is kept (no trimming, no
// mmap for big blocks: a freed block is not unmapped and faulted in again),
// the pages locked, and the stack touched now. Then the scheduler: SCHED_FIFO
// at a low real-time priority (10 of 1..99) wakes the server ahead of every
// normal task, so the other processes on the cores no longer delay its
// frames; the kernel's real-time throttling still leaves them 5 % of a core.
static void go_realtime(server* s) {
    mallopt(M_TRIM_THRESHOLD, -1);
    mallopt(M_MMAP_MAX, 0);
    char mem[160];
    if (mlockall(MCL_CURRENT | MCL_FUTURE))
        snprintf(mem, sizeof mem, "memory not locked (mlockall: %s)", strerror(errno));
    else
        snprintf(mem, sizeof mem, "memory locked");
    volatile char stack[256 * 1024]; // 256 KiB of stack faulted in now, not in a frame
    for (size_t i = 0; i < sizeof stack; i += 4096) stack[i] = 0;
    struct sched_param sp = {.sched_priority = 10};
    if (!sched_setscheduler(0, SCHED_FIFO, &sp)) {
        logf_(s, "real time: SCHED_FIFO priority 10, %s", mem);
        return;
    }
    const int fifo_errno = errno;
    if (!setpriority(PRIO_PROCESS, 0, -10)) {
        logf_(s, "real time: SCHED_FIFO not permitted (%s): nice -10 instead, %s", strerror(fifo_errno), mem);
        return;
    }
    logf_(s, "real time: not permitted (SCHED_FIFO: %s; nice -10: %s): normal priority, %s (root, or "
             "CAP_SYS_NICE and CAP_IPC_LOCK, or rtprio and memlock limits, grant them)",
          strerror(fifo_errno), strerror(errno), mem);
}

static int serve_loop(server* s, int lfd, double duration) {
    struct pollfd pf[SERVE_MAX_CLIENTS + 1];
    double next = sim_wall_time() + s->frame; // wall time of the next frame
    long missed = 0, frames = 0;
    double worst = 0, busy = 0;
    // How late each frame starts after its deadline, in 0.05 ms bins to
    // 100 ms (the last bin: later): the wake-ups the machine grants, apart
    // from the frame's own work.
    enum { LATE_BINS = 2001 };
    static long late[LATE_BINS];
    memset(late, 0, sizeof late);
    while (!app_signal_caught()) {
        if (duration > 0 && s->k * s->frame >= duration - 1e-9) break;
        pf[0] = (struct pollfd){.fd = lfd, .events = POLLIN};
        for (int i = 0; i < s->nclient; ++i)
            pf[i + 1] = (struct pollfd){.fd = s->c[i]->fd,
                                        .events = POLLIN | (s->c[i]->out_len > s->c[i]->out_off ? POLLOUT : 0)};
        // Sleep until `spin` before the deadline: a wake-up from the timer
        // comes late by the scheduler's latency (tens of us idle, ms under
        // load), so the last stretch is a poll with no timeout, repeated.
        double wait = s->lockstep ? 0.1 : next - s->spin - sim_wall_time();
        if (wait < 0) wait = 0;
        struct timespec ts = {(time_t)wait, (long)((wait - floor(wait)) * 1e9)};
        const int np = s->nclient + 1;
        int r = ppoll(pf, (nfds_t)np, &ts, NULL);
        if (r < 0 && errno != EINTR) {
            logf_(s, "poll failed: %s", strerror(errno));
            return EXIT_RUNTIME;
        }
        if (r > 0) {
            // Clients first (by fd: the array shifts as clients close), then new ones.
            for (int p = np - 1; p >= 1; --p) {
                if (!pf[p].revents) continue;
                int idx = -1;
                for (int i = 0; i < s->nclient; ++i)
                    if (s->c[i]->fd == pf[p].fd) idx = i;
                if (idx < 0) continue;
                if (pf[p].revents & POLLOUT) flush_client(s->c[idx]);
                if (pf[p].revents & (POLLIN | POLLHUP | POLLERR)) read_client(s, idx);
            }
            if (pf[0].revents & POLLIN) accept_clients(s, lfd);
        }
        check_timeouts(s);
        if (s->reset_pending) {
            // Between frames: the clock starts again at 0, so the frames
            // start again from now (no catch-up burst, no deadline counted
            // as missed for the rebuild's time).
            do_reset(s);
            next = sim_wall_time() + s->frame;
        }
        if (s->lockstep) continue;
        double now = sim_wall_time();
        if (now < next - s->spin) continue;
        // Within `spin` of the deadline: spin to it (clients are polled
        // again on the next pass, a frame later at most).
        while (now < next) now = sim_wall_time();
        const long lb = (long)((now - next) / 5e-5);
        ++late[lb < LATE_BINS - 1 ? lb : LATE_BINS - 1];
        struct rusage ru0, ru1;
        if (s->log_misses) getrusage(RUSAGE_THREAD, &ru0);
        // One frame: step (unless paused), then the state to everyone.
        if (!s->paused) step_frame(s);
        const double stepped = sim_wall_time();
        broadcast(s);
        for (int i = 0; i < s->nclient; ++i) s->c[i]->read_frame = 0;
        ++frames;
        const double done = sim_wall_time();
        // Worst frame from its scheduled start (next), so a late wake-up
        // counts as it does for a missed deadline: missed > 0 exactly when
        // worst > the frame period. busy stays the work alone.
        worst = fmax(worst, done - next);
        busy += done - now;
        const double due = next;
        next += s->frame;
        if (done > next) { // the frame's work ran past the next frame's start
            ++missed;
            if (s->log_misses) {
                getrusage(RUSAGE_THREAD, &ru1);
                logf_(s, "missed deadline: frame %ld at %.3f s: started %.3f ms late, step %.3f ms, send %.3f ms; "
                         "during the frame %ld minor + %ld major page faults, %ld involuntary + %ld voluntary "
                         "context switches",
                      frames, due - s->w0, (now - due) * 1e3, (stepped - now) * 1e3, (done - stepped) * 1e3,
                      ru1.ru_minflt - ru0.ru_minflt, ru1.ru_majflt - ru0.ru_majflt, ru1.ru_nivcsw - ru0.ru_nivcsw,
                      ru1.ru_nvcsw - ru0.ru_nvcsw);
            }
            if (done > next + 10 * s->frame) next = done + s->frame; // far behind: start again from now
        }
    }
    double late_q[2] = {0, 0};
    for (int q = 0; q < 2 && frames; ++q) {
        const long want = (long)ceil((q ? 0.99 : 0.5) * (double)frames);
        long acc = 0;
        for (int b = 0; b < LATE_BINS; ++b)
            if ((acc += late[b]) >= want) {
                late_q[q] = (b + 1) * 0.05; // the bin's upper edge [ms]
                break;
            }
    }
    if (!s->quiet)
        logf_(s, "%ld frames, %ld missed deadlines, worst frame %.3f ms, mean frame %.3f ms; simulated %.3f s; "
                 "frame start after its deadline p50 %.2f ms, p99 %.2f ms",
              frames, missed, worst * 1e3, frames ? busy / frames * 1e3 : 0.0, s->e ? engine_time(s->e) : 0.0,
              late_q[0], late_q[1]);
    return 0;
}

int cmd_serve(int argc, char** argv) {
    app_common c = {.sim = sim_default_opts()};
    // serve's default, as drive's: the backend with a world, in its drive world
    app_use_backend(&c.sim, engine_backend_with_world() ? engine_backend_with_world() : engine_backend_default());
    c.sim.rcl = true; // the rated capacity limiter, as a local drive's, unless --rcl off
    const char* listen_at = "127.0.0.1:7575";
    double rate = 75, timeout = 5;
    int max_clients = 8, queue = 64;
    bool lockstep = false, realtime = false, log_misses = false, rcl_given = false;
    double spin_us = 500;
    for (int i = 0; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            serve_help(stdout);
            return 0;
        }
        if (!strcmp(argv[i], "--every")) {
            fprintf(stderr, "cranesim serve: --every: serve sends one state frame per frame (use --rate)\n");
            return EXIT_USAGE;
        }
        int rc = app_parse_common(&c, argc, argv, &i);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        if (!strcmp(argv[i], "--lockstep")) {
            lockstep = true;
            continue;
        }
        if (!strcmp(argv[i], "--realtime")) {
            realtime = true;
            continue;
        }
        if (!strcmp(argv[i], "--log-misses")) {
            log_misses = true;
            continue;
        }
        if (!strcmp(argv[i], "--rcl")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if (strcmp(v, "on") && strcmp(v, "off")) {
                fprintf(stderr, "cranesim serve: --rcl: expected on or off, got '%s'\n", v);
                return EXIT_USAGE;
            }
            c.sim.rcl = !strcmp(v, "on");
            rcl_given = true;
            continue;
        }
        if (!strcmp(argv[i], "--spin")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            double d = NAN;
            if (app_parse_double(v, &d) || !(d >= 0 && d <= 2000)) {
                fprintf(stderr, "cranesim serve: --spin: expected 0..2000 us, got '%s'\n", v);
                return EXIT_USAGE;
            }
            spin_us = d;
            continue;
        }
        const char* opt = argv[i];
        if (!strcmp(opt, "--listen") || !strcmp(opt, "--rate") || !strcmp(opt, "--max-clients") ||
            !strcmp(opt, "--timeout") || !strcmp(opt, "--queue")) {
            const char* v = app_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            double d = 0;
            if (strcmp(opt, "--listen") && app_parse_double(v, &d)) d = NAN;
            if (!strcmp(opt, "--listen")) {
                listen_at = v;
            } else if (!strcmp(opt, "--rate")) {
                if (!(d >= 1 && d <= 5000)) {
                    fprintf(stderr, "cranesim serve: --rate: expected 1..5000 frames/s, got '%s'\n", v);
                    return EXIT_USAGE;
                }
                rate = d;
            } else if (!strcmp(opt, "--max-clients")) {
                if (!(d >= 1 && d <= SERVE_MAX_CLIENTS) || d != floor(d)) {
                    fprintf(stderr, "cranesim serve: --max-clients: expected a whole number 1..%d, got '%s'\n",
                            SERVE_MAX_CLIENTS, v);
                    return EXIT_USAGE;
                }
                max_clients = (int)d;
            } else if (!strcmp(opt, "--queue")) {
                if (!(d >= 2 && d <= 4096) || d != floor(d)) {
                    fprintf(stderr, "cranesim serve: --queue: expected a whole number of frames 2..4096, got '%s'\n",
                            v);
                    return EXIT_USAGE;
                }
                queue = (int)d;
            } else {
                if (!(d >= 0.05 && d <= 3600)) {
                    fprintf(stderr, "cranesim serve: --timeout: expected 0.05..3600 s, got '%s'\n", v);
                    return EXIT_USAGE;
                }
                timeout = d;
            }
            continue;
        }
        fprintf(stderr, "cranesim serve: unknown option '%s' (see cranesim serve --help)\n", argv[i]);
        return EXIT_USAGE;
    }
    if (realtime && lockstep) {
        fprintf(stderr, "cranesim serve: --realtime: a --lockstep server has no frame deadlines (drop one of them)\n");
        return EXIT_USAGE;
    }
    const engine_backend* be = app_backend(&c.sim);
    if (be->world && !c.sim.world) c.sim.world = be->drive_world;
    if (c.sim.cvode) {
        fprintf(stderr, "cranesim serve: --solver cvode: serve steps the hydraulics in real time with the in-house "
                        "solvers: use krus, ros2, rk4, ros34pw2 or rodas3\n");
        return EXIT_USAGE;
    }
    if (app_check_sim("serve", &c.sim, c.given)) return EXIT_USAGE;
    app_note_unused("serve", c.given, &c.sim, 1);
    app_settle_unused(&c.sim);
    if (!c.scenario_path) {
        // Its drive scenario in its drive world; another world may have no
        // hook or slew: the lift-and-jib demo.
        c.scenario_path = app_default_drive_scenario(&c.sim);
        if (be->world && strcmp(c.sim.world, be->drive_world)) c.scenario_path = APP_DEMO_SCENARIO;
    }
    model* m;
    scenario sc;
    int rc = app_load(&c, &m, &sc);
    if (rc) return rc;
    server s = {.m = m, .o = &c.sim, .sc = &sc, .frame = 1.0 / rate, .lockstep = lockstep, .max_clients = max_clients,
                .queue = queue, .timeout = timeout, .quiet = c.quiet, .w0 = sim_wall_time(),
                .spin = lockstep ? 0 : spin_us * 1e-6, .log_misses = log_misses};
    s.m3 = sim_load_mass(m, &sc, &c.sim);
    s.snap = malloc(sizeof *s.snap);
    s.st = malloc(sizeof *s.st);
    s.frame_cap = PROTO_MAX_SERVER_FRAME + 8;
    s.frame_buf = malloc(s.frame_cap);
    char err[600];
    if (!s.snap || !s.st || !s.frame_buf) {
        fprintf(stderr, "cranesim serve: out of memory\n");
        rc = EXIT_RUNTIME;
        goto done;
    }
    // A limiter asked for by name on a crane that has none is refused (on
    // by default, it is then "unavailable" in the first line).
    if ((rcl_given && c.sim.rcl &&
         engine_require(m, &c.sim, ENGINE_CAP_LIMITER, "--rcl on", err, sizeof err)) ||
        build_engine(&s, NULL, err, sizeof err) || serve_layout(&s, err, sizeof err)) {
        fprintf(stderr, "cranesim serve: %s\n", err);
        rc = EXIT_USAGE;
        goto done;
    }
    // The model as a path the viewer can resolve: absolute (the model keeps
    // only its file's base name, which names no file from another working
    // directory), and relative to the assets folder when it is in it.
    char mbuf[512]; // a model name (--model hiab031_ls) is its file in the assets
    const char* mpath = model_path(c.model_path, mbuf, sizeof mbuf);
    if (!realpath(mpath, g_desc_file)) snprintf(g_desc_file, sizeof g_desc_file, "%s", mpath);
    char assets[PATH_MAX];
    const char* asset = "";
    if (realpath(model_assets_dir(), assets)) {
        const size_t L = strlen(assets);
        if (!strncmp(g_desc_file, assets, L) && g_desc_file[L] == '/') asset = g_desc_file + L + 1;
    }
    g_desc = describe(&s, g_desc_file, asset);
    // The state frame's size sets the queue's (a whole number of frames).
    fill_state(&s);
    s.seq = 0;
    const size_t fl = proto_put_state(s.frame_buf, s.frame_cap, s.st);
    s.queue_bytes = (size_t)queue * fl + strlen(g_desc) + 65536;
    char bound[128];
    int lfd = open_listener(listen_at, bound, sizeof bound, err, sizeof err);
    if (lfd < 0) {
        fprintf(stderr, "cranesim serve: %s\n", err);
        rc = EXIT_USAGE;
        goto done;
    }
    printf("cranesim serve: listening on %s (%s, %s, %g frames/s%s, state frame %zu bytes, rated capacity limiter "
           "%s)\n",
           bound, m->name, engine_backend_name(s.e), rate, lockstep ? ", lockstep" : "", fl,
           !engine_rcl(s.e) ? "unavailable" : c.sim.rcl ? "on" : "off (measuring only)");
    fflush(stdout);
    // The frames are paced by ppoll timeouts: the default 50 us timer slack
    // would let every wake-up come up to 50 us late on top of scheduling.
    prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0);
    if (realtime) go_realtime(&s);
    app_signals sig;
    app_signals_catch(&sig);
    rc = serve_loop(&s, lfd, c.sim.duration);
    app_signals_restore(&sig);
    if (app_signal_caught()) logf_(&s, "%s: stopping", app_signal_name(app_signal_caught()));
    log_collisions(&s, "at the stop");
    while (s.nclient) drop_client(&s, s.nclient - 1, PROTO_E_SHUTDOWN, "the server stops");
    close(lfd);
done:
    free(g_desc);
    g_desc = NULL;
    if (s.e) engine_destroy(s.e);
    free(s.row);
    free(s.snap);
    free(s.st);
    free(s.frame_buf);
    model_free(m);
    return rc;
}
