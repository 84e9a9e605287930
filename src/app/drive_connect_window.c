// drive_connect_window.c: `cranesim drive --connect HOST:PORT` in the 3D
// window: the visual computer of the paper's split. The scene, HUD, bars and
// charts are the local drive's (drive_session in remote mode): its engine is
// built from the model and world files the server's hello names and is
// never stepped; every state frame replaces the snapshot's poses and values.
// The sticks and keys (or the scripted operator, at the remote time) go back
// as commands; the HUD shows who controls, frames received and lost, and the
// command-to-echo latency. When the link drops it says so on screen and on
// stderr, keeps the last picture, and reconnects with a doubling back-off
// (0.25 s to 4 s) until the server is back.
#define _GNU_SOURCE
#include "app.h"
#include "drive_connect.h"
#include "drive_session.h"
#include "protocol.h"
#include "render.h"

#include <cJSON.h>
#include <errno.h>
#include <math.h>
#include <netdb.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

typedef struct rlink {
    const char* addr;
    char host[256], port[16];
    int fd;                  // -1: down
    uint8_t* rx;
    size_t len;
    proto_state* st;
    proto_state* view;       // st with its cylinder records in the local picture's order (lk_feed)
    dc_functions fns;        // the server's functions (its hello), in VALVES' order
    int fcol[PROTO_MAX_FN];  // the scripted operator's column of each, -1: none (0)
    int cmap[WORLD_SNAP_MAX_CYLINDERS]; // the local picture's cylinder i: record cmap[i] of the frames, -1 none
    int role;                // granted, -1 before the hello
    bool lockstep, ever;
    double rate;             // frames per simulated second [Hz]
    uint64_t seq, last_seq;  // our last command; the last frame's number
    double sent_at;          // wall time of our last command, 0: none in flight [s]
    long frames, lost, drops, links, nlat;
    double lat_sum, lat_max, lat_avg; // [s]; lat_avg smoothed for the HUD
    double last_frame_wall, retry_at, backoff;
    double rt_w0, rt_t0;     // wall and remote time at the start of the rate window [s]
    double rt;               // remote simulated over wall time, 0 unknown
    char why[600];
    int nbody_local;
    int ev;                  // the scripted operator's next hook event
    const scenario* sc;
    bool scripted;
    double u_sent[PROTO_MAX_FN]; // the openings last sent, per function (the operator's demand, for the HUD)
    bool same_model;         // the local model is the server's file: its "controls" map the sticks
    bool bad_mapping;        // the last hello's functions refused the input mapping (bad input: exit 2)
    bool have_sent;
    char* hjson;             // the first hello's description (a copy)
    struct { uint64_t seq; char path[128]; double v; } pend[16]; // SETs sent, no answer yet
    int npend;
    const char* const* sets; // the drive's --set values, sent on every link
    int nset;
} rlink;

static int lk_connect(rlink* k, char* err, size_t errsz) {
    struct addrinfo hints = {.ai_socktype = SOCK_STREAM}, *res;
    int g = getaddrinfo(k->host, k->port, &hints, &res);
    if (g) {
        snprintf(err, errsz, "%s: %s", k->addr, gai_strerror(g));
        return -1;
    }
    int fd = socket(res->ai_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
    // A connect to a host that does not answer must not freeze the window:
    // Linux takes SO_SNDTIMEO as the connect timeout (0.5 s).
    struct timeval tv = {0, 500000};
    if (fd >= 0) setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    if (fd < 0 || connect(fd, res->ai_addr, res->ai_addrlen)) {
        snprintf(err, errsz, "%s: %s", k->addr, strerror(errno));
        if (fd >= 0) close(fd);
        freeaddrinfo(res);
        return -1;
    }
    freeaddrinfo(res);
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one); // a command goes out at once
    uint8_t b[16];
    const size_t n = proto_put_client_hello(b, sizeof b, PROTO_VERSION, PROTO_CONTROL);
    if (send(fd, b, n, MSG_NOSIGNAL) != (ssize_t)n) {
        snprintf(err, errsz, "%s: %s", k->addr, strerror(errno));
        close(fd);
        return -1;
    }
    return fd;
}

// Read one whole frame within ms milliseconds (the hello, before the window opens).
static int lk_read_frame(rlink* k, proto_msg* m, int ms, char* err, size_t errsz) {
    const double t_end = sim_wall_time() + ms * 1e-3;
    for (;;) {
        size_t used;
        memset(m, 0, sizeof *m);
        m->u.state = k->st;
        int rc = proto_parse(k->rx, k->len, PROTO_MAX_SERVER_FRAME, &used, m, err, errsz);
        if (rc < 0) return -1;
        if (rc == 1) {
            // The hello's JSON points into rx, which moves on: keep a copy.
            if (m->type == PROTO_SERVER_HELLO) {
                free(k->hjson);
                k->hjson = malloc(m->u.shello.json_len + 1);
                if (!k->hjson) {
                    snprintf(err, errsz, "out of memory");
                    return -1;
                }
                memcpy(k->hjson, m->u.shello.json, m->u.shello.json_len);
                k->hjson[m->u.shello.json_len] = 0;
                m->u.shello.json = k->hjson;
            }
            k->len -= used;
            memmove(k->rx, k->rx + used, k->len);
            return 1;
        }
        const double left = t_end - sim_wall_time();
        struct pollfd pf = {.fd = k->fd, .events = POLLIN};
        if (left <= 0 || poll(&pf, 1, (int)(left * 1e3) + 1) <= 0) {
            snprintf(err, errsz, "no answer from the server within %d ms", ms);
            return -1;
        }
        ssize_t r = recv(k->fd, k->rx + k->len, PROTO_MAX_SERVER_FRAME + 8 - k->len, 0);
        if (r <= 0) {
            snprintf(err, errsz, "%s", r == 0 ? "the server closed the link" : strerror(errno));
            return -1;
        }
        k->len += (size_t)r;
    }
}

static void lk_send(rlink* k, const proto_command* c) {
    uint8_t b[PROTO_MAX_CLIENT_FRAME + 8];
    const size_t n = proto_put_command(b, sizeof b, c);
    if (n && k->fd >= 0) send(k->fd, b, n, MSG_NOSIGNAL); // a failure shows as a closed link at the next read
}

static void lk_down(rlink* k, drive_session* s, const char* why) {
    if (k->fd < 0) return;
    close(k->fd);
    k->fd = -1;
    k->len = 0;
    k->sent_at = 0;
    k->role = -1;
    ++k->drops;
    snprintf(k->why, sizeof k->why, "%s", why);
    fprintf(stderr, "cranesim drive: link to %s lost: %s; reconnecting\n", k->addr, why);
    k->backoff = 0.25;
    k->retry_at = sim_wall_time() + k->backoff;
    if (k->npend) { // sent on the lost link: the server may or may not have applied them
        drive_session_set_answer(s, "link lost before the server answered a parameter change");
        k->npend = 0;
    }
    char down[RENDER_WARN_LEN];
    snprintf(down, sizeof down, "LINK LOST: %.90s", why);
    drive_session_set_link(s, "link down: showing the last state received; reconnecting", down);
}

static int scripted_hook(void* user, int attach) {
    rlink* k = user;
    proto_command c = {.seq = ++k->seq, .op = PROTO_OP_HOOK, .flag = (uint8_t)attach};
    lk_send(k, &c);
    return -1;
}

// The state to the session: its cylinder records reordered to the local
// picture's cylinders by name (a chain's frames carry every actuator, the
// picture draws those it has), the open reliefs' cylinders with them.
static void lk_feed(rlink* k, drive_session* s) {
    const proto_state* st = k->st;
    proto_state* v = k->view;
    memcpy(v, st, sizeof *v);
    const int nloc = drive_session_snapshot(s)->ncyl;
    v->ncyl = 0;
    for (int i = 0; i < nloc && i < WORLD_SNAP_MAX_CYLINDERS && i < PROTO_MAX_CYL; ++i) {
        const int r = k->cmap[i];
        if (r >= 0 && r < st->ncyl) {
            memcpy(v->cyl[i], st->cyl[r], sizeof v->cyl[i]);
            v->cyl_bits[i] = st->cyl_bits[r];
        } else {
            memset(v->cyl[i], 0, sizeof v->cyl[i]);
            v->cyl_bits[i] = PROTO_CYL_NO_PINS;
        }
        v->ncyl = (uint8_t)(i + 1);
    }
    for (int q = 0; q < v->nrelief; ++q) {
        int loc = -1;
        for (int i = 0; i < v->ncyl && loc < 0; ++i)
            if (st->relief[q].cyl >= 0 && k->cmap[i] == st->relief[q].cyl) loc = i;
        v->relief[q].cyl = (int8_t)loc;
    }
    // The demand of each picture cylinder: the opening last sent to the
    // function its record belongs to (NaN: none).
    double demand[WORLD_SNAP_MAX_CYLINDERS];
    for (int i = 0; i < WORLD_SNAP_MAX_CYLINDERS; ++i) {
        const int r = i < v->ncyl ? k->cmap[i] : -1;
        const int f = r >= 0 && r < k->fns.ncyl ? k->fns.cyl_fn[r] : -1;
        demand[i] = f >= 0 && f < k->fns.n ? k->u_sent[f] : NAN;
    }
    drive_session_feed(s, v, k->rt, k->role == PROTO_CONTROL && k->have_sent ? demand : NULL);
}

// A state frame arrived: draw it, count it, and answer it with the operator's commands.
static void lk_state(rlink* k, drive_session* s) {
    const proto_state* st = k->st;
    const double now = sim_wall_time();
    ++k->frames;
    if (k->last_seq && st->seq > k->last_seq + 1) k->lost += (long)(st->seq - k->last_seq - 1);
    k->last_seq = st->seq;
    k->last_frame_wall = now;
    if (k->sent_at > 0 && st->cmd_seq >= k->seq) {
        const double l = now - k->sent_at;
        k->lat_sum += l, k->lat_max = fmax(k->lat_max, l), ++k->nlat;
        k->lat_avg = k->lat_avg > 0 ? 0.9 * k->lat_avg + 0.1 * l : l;
        k->sent_at = 0;
    }
    // The remote real-time factor over at least 0.5 s of wall time; none in
    // lockstep (the server runs as fast as it is stepped).
    if (k->rt_w0 == 0 || st->nine[8] < k->rt_t0) k->rt_w0 = now, k->rt_t0 = st->nine[8];
    else if (now - k->rt_w0 >= 0.5) {
        k->rt = k->lockstep ? 0 : (st->nine[8] - k->rt_t0) / (now - k->rt_w0);
        k->rt_w0 = now, k->rt_t0 = st->nine[8];
    }
    lk_feed(k, s);
    // A SET not refused by the time the echo passes it was applied.
    for (int i = 0; i < k->npend; ++i)
        if (st->cmd_seq >= k->pend[i].seq) {
            char t[300];
            snprintf(t, sizeof t, "accepted by the server: %s = %.6g", k->pend[i].path, k->pend[i].v);
            printf("cranesim drive: %s\n", t);
            fflush(stdout);
            drive_session_set_answer(s, t);
            k->pend[i--] = k->pend[--k->npend];
        }
    {
        char path[128];
        double v;
        while (k->npend < 16 && drive_session_take_set(s, path, sizeof path, &v)) {
            if (k->role != PROTO_CONTROL) {
                drive_session_set_answer(s, "not sent: this view watches (another client controls)");
                continue;
            }
            proto_command c = {.seq = ++k->seq, .op = PROTO_OP_SET, .value = v};
            snprintf(c.path, sizeof c.path, "%s", path);
            lk_send(k, &c);
            k->pend[k->npend].seq = c.seq;
            snprintf(k->pend[k->npend].path, sizeof k->pend[0].path, "%s", path);
            k->pend[k->npend++].v = v;
        }
    }
    if (k->role != PROTO_CONTROL) return;
    // The operator's positions: the devices of the last tick, or the script
    // at the middle of the coming frame (as the headless drive and the
    // server's lockstep test play it).
    drive_remote_input in;
    drive_session_remote_input(s, &in);
    if (in.reset == 1) {
        lk_send(k, &(proto_command){.seq = ++k->seq, .op = PROTO_OP_RESET});
        k->ev = 0;
    }
    if (in.pause == 1)
        lk_send(k, &(proto_command){.seq = ++k->seq, .op = PROTO_OP_PAUSE, .flag = !(st->flags & PROTO_F_PAUSED)});
    if (in.hook >= 0) lk_send(k, &(proto_command){.seq = ++k->seq, .op = PROTO_OP_HOOK, .flag = (uint8_t)in.hook});
    // One opening per server function, by name: the operator's command of
    // that function (the session's mapping is built from the hello's list:
    // drive_session_remote_functions), or the script's column of that name;
    // a function neither gives stays at 0.
    proto_command c = {.op = PROTO_OP_VALVES, .nu = (uint8_t)k->fns.n};
    double u3[3];
    if (k->scripted) scenario_play(k->sc, st->nine[8] + 0.5 / k->rate, &k->ev, u3, scripted_hook, k);
    for (int j = 0; j < k->fns.n; ++j) {
        double v = 0;
        if (k->scripted) {
            const int col = k->fcol[j];
            if (col >= 0 && col < 3) v = u3[col];
            else if (col >= 0) v = scenario_command(k->sc, col, st->nine[8] + 0.5 / k->rate);
        } else {
            for (int i = 0; i < in.n; ++i)
                if (!strcmp(in.name[i], k->fns.name[j])) {
                    v = in.u[i];
                    break;
                }
        }
        c.u[j] = fmax(-1, fmin(1, isfinite(v) ? v : 0));
    }
    // One command in flight in real time (its echo times the link); in
    // lockstep every frame is answered with the openings and one step.
    if (k->lockstep || k->sent_at == 0) {
        c.seq = ++k->seq;
        if (k->sent_at == 0) k->sent_at = now;
        lk_send(k, &c);
        // The demand the server's limiter acts on, per function (the HUD
        // shows it beside a command the limiter cut: lk_feed).
        memcpy(k->u_sent, c.u, (size_t)k->fns.n * sizeof c.u[0]);
        k->have_sent = true;
    }
    if (k->lockstep) lk_send(k, &(proto_command){.seq = ++k->seq, .op = PROTO_OP_STEP, .frames = 1});
}

// The drive's --set values go to the server with the first frames of every
// link, as a panel edit does (the local model has them already, for the
// panel): the server at the other end of a new link may be a restarted one
// that never had them, and one that had them takes the same values again.
static void lk_queue_sets(const rlink* k, drive_session* s) {
    for (int i = 0; i < k->nset; ++i) {
        char path[128];
        double v;
        if (drive_set_path(k->sets[i], path, sizeof path, &v) || drive_session_queue_set(s, path, v))
            printf("cranesim drive: --set %s: not sent to the server\n", k->sets[i]);
    }
}

// The server's hello on a (re)connection: the role, the rate, and the same world.
static int lk_hello(rlink* k, drive_session* s, const proto_msg* m, char* err, size_t errsz) {
    k->role = m->u.shello.role;
    k->have_sent = false; // a new link: nothing sent on it yet
    k->lockstep = m->u.shello.lockstep;
    k->rate = m->u.shello.rate;
    // The functions VALVES carries, and the picture's cylinders by name.
    if (dc_hello_functions(m->u.shello.json, m->u.shello.json_len, &k->fns, err, errsz)) return -1;
    for (int f = 0; f < k->fns.n; ++f) k->fcol[f] = k->sc ? scenario_find_command(k->sc, k->fns.name[f]) : -1;
    // The sticks and keys map to the server's functions by name (a chain's
    // ext, ext2, rotator... as well as lift, jib, slew).
    {
        const char* names[PROTO_MAX_FN];
        for (int f = 0; f < k->fns.n; ++f) names[f] = k->fns.name[f];
        k->bad_mapping = drive_session_remote_functions(s, names, k->fns.n, k->same_model, err, errsz) != 0;
        if (k->bad_mapping) return -1;
    }
    const world_snapshot* pic = drive_session_snapshot(s);
    for (int i = 0; i < WORLD_SNAP_MAX_CYLINDERS; ++i) {
        k->cmap[i] = -1;
        for (int r = 0; i < pic->ncyl && r < k->fns.ncyl && k->cmap[i] < 0; ++r)
            if (!strcmp(k->fns.cyl_name[r], pic->cyl[i].name)) k->cmap[i] = r;
    }
    cJSON* j = cJSON_ParseWithLength(m->u.shello.json, m->u.shello.json_len);
    const int nb = cJSON_GetArraySize(cJSON_GetObjectItem(j, "bodies"));
    cJSON_Delete(j);
    if (k->nbody_local >= 0 && nb != k->nbody_local) {
        snprintf(err, errsz, "the server now runs another world (%d bodies, this view has %d): restart drive --connect",
                 nb, k->nbody_local);
        return -1;
    }
    printf("cranesim drive: connected to %s (%s%s)%s\n", k->addr,
           k->role == PROTO_CONTROL ? "controlling" : "watching: another client controls",
           k->lockstep ? ", lockstep" : "", k->ever ? ", reconnected" : "");
    fflush(stdout);
    k->ever = true;
    ++k->links;
    k->last_seq = 0;
    k->last_frame_wall = sim_wall_time();
    k->rt_w0 = 0;
    lk_queue_sets(k, s);
    return 0;
}

// Everything the socket has now (up to wait_s for the first byte); the
// bytes already buffered (frames that came with the hello) first.
static void lk_pump(rlink* k, drive_session* s, double wait_s) {
    if (k->fd < 0) return;
    bool polled = false;
    for (;;) {
        if (polled) {
            ssize_t r = recv(k->fd, k->rx + k->len, PROTO_MAX_SERVER_FRAME + 8 - k->len, MSG_DONTWAIT);
            if (r == 0 || (r < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
                lk_down(k, s, r == 0 ? "the server closed the link" : strerror(errno));
                return;
            }
            if (r < 0) break;
            k->len += (size_t)r;
        }
        size_t off = 0;
        char err[512];
        for (;;) {
            proto_msg m;
            memset(&m, 0, sizeof m);
            m.u.state = k->st;
            size_t used;
            int rc = proto_parse(k->rx + off, k->len - off, PROTO_MAX_SERVER_FRAME, &used, &m, err, sizeof err);
            if (rc < 0) {
                lk_down(k, s, err);
                return;
            }
            if (rc == 0) break;
            off += used;
            if (m.type == PROTO_SERVER_HELLO) {
                if (lk_hello(k, s, &m, err, sizeof err)) {
                    lk_down(k, s, err);
                    return;
                }
            } else if (m.type == PROTO_ERROR) {
                char why[600];
                snprintf(why, sizeof why, "the server says: %s", m.u.text.text);
                lk_down(k, s, why);
                return;
            } else if (m.type == PROTO_NOTICE) {
                fprintf(stderr, "cranesim drive: the server says: %s\n", m.u.text.text);
                for (int i = 0; i < k->npend; ++i)
                    if (k->pend[i].seq == m.u.text.seq) {
                        char t[700];
                        snprintf(t, sizeof t, "refused by the server: %s = %.6g: %s", k->pend[i].path, k->pend[i].v,
                                 m.u.text.text);
                        printf("cranesim drive: %s\n", t);
                        fflush(stdout);
                        drive_session_set_answer(s, t);
                        k->pend[i--] = k->pend[--k->npend];
                    }
            } else if (m.type == PROTO_STATE) {
                lk_state(k, s);
            }
        }
        memmove(k->rx, k->rx + off, k->len - off);
        k->len -= off;
        if (!polled) {
            struct pollfd pf = {.fd = k->fd, .events = POLLIN};
            const int pr = poll(&pf, 1, wait_s > 0 ? (int)ceil(wait_s * 1e3) : 0);
            if (pr <= 0) {
                if (sim_wall_time() - k->last_frame_wall > 2.0) lk_down(k, s, "no frame for 2 s");
                return;
            }
            polled = true;
        }
    }
}

static void lk_hud(rlink* k, drive_session* s) {
    if (k->fd < 0) return;
    char t[160];
    const double pct = k->frames + k->lost ? 100.0 * (double)k->lost / (double)(k->frames + k->lost) : 0;
    snprintf(t, sizeof t, "link %s %s: %ld frames, %ld lost (%.1f %%), latency %.1f ms (max %.1f)", k->addr,
             k->role == PROTO_CONTROL ? "controlling" : "watching", k->frames, k->lost, pct, 1e3 * k->lat_avg,
             1e3 * k->lat_max);
    drive_session_set_link(s, t, NULL);
}

static bool file_exists(const char* p) { return p && p[0] && access(p, R_OK) == 0; }

int drive_connect_window(const app_common* c0, const drive_opts* o, const char* addr, double duration,
                         const char* shot, double shot_at, char* no_window, size_t no_window_sz) {
    rlink k = {.addr = addr, .fd = -1, .role = -1, .nbody_local = -1, .backoff = 0.25, .scripted = o->scripted};
    const char* colon = strrchr(addr, ':');
    if (!colon || colon == addr || !colon[1] || (size_t)(colon - addr) >= sizeof k.host ||
        strlen(colon + 1) >= sizeof k.port) {
        fprintf(stderr, "cranesim drive: --connect: expected HOST:PORT (127.0.0.1:7575), got '%s'\n", addr);
        return EXIT_USAGE;
    }
    memcpy(k.host, addr, (size_t)(colon - addr));
    k.host[colon - addr] = 0;
    snprintf(k.port, sizeof k.port, "%s", colon + 1);
    if (k.host[0] == '[' && k.host[strlen(k.host) - 1] == ']') {
        memmove(k.host, k.host + 1, strlen(k.host));
        k.host[strlen(k.host) - 1] = 0;
    }
    k.rx = malloc(PROTO_MAX_SERVER_FRAME + 8);
    k.st = malloc(sizeof *k.st);
    k.view = malloc(sizeof *k.view);
    char err[700];
    int code = EXIT_RUNTIME;
    drive_session* s = NULL;
    cJSON* desc = NULL;
    if (!k.rx || !k.st || !k.view) {
        fprintf(stderr, "cranesim drive: out of memory\n");
        goto done;
    }
    // The hello first: the scene is built from the files it names.
    k.fd = lk_connect(&k, err, sizeof err);
    proto_msg m;
    if (k.fd < 0 || lk_read_frame(&k, &m, 5000, err, sizeof err) < 0) {
        fprintf(stderr, "cranesim drive: --connect %s: %s\n", addr, err);
        goto done;
    }
    if (m.type == PROTO_ERROR) {
        fprintf(stderr, "cranesim drive: --connect %s: the server says: %s\n", addr, m.u.text.text);
        goto done;
    }
    if (m.type != PROTO_SERVER_HELLO) {
        fprintf(stderr, "cranesim drive: --connect %s: the server's first frame is not its hello\n", addr);
        goto done;
    }
    desc = cJSON_ParseWithLength(m.u.shello.json, m.u.shello.json_len);
    const char* model_file = cJSON_GetStringValue(cJSON_GetObjectItem(desc, "model_file"));
    const char* world_file = cJSON_GetStringValue(cJSON_GetObjectItem(desc, "world_file"));
    const char* backend = cJSON_GetStringValue(cJSON_GetObjectItem(desc, "backend"));
    if (!desc || !backend) {
        fprintf(stderr, "cranesim drive: --connect %s: server hello: no JSON description with a \"backend\"\n", addr);
        goto done;
    }
    app_common c = *c0;
    char model_buf[1024], world_buf[1024]; // the session keeps the paths: not into the JSON
    snprintf(model_buf, sizeof model_buf, "%s", model_file ? model_file : "");
    snprintf(world_buf, sizeof world_buf, "%s", world_file ? world_file : "");
    model_file = model_buf, world_file = world_buf;
    // The server's backend by name: one this build does not know is refused,
    // not drawn as another.
    char berr[256];
    if (engine_backend_select(&c.sim, backend, berr, sizeof berr)) {
        fprintf(stderr, "cranesim drive: --connect %s: server hello: backend: %s\n", addr, berr);
        code = EXIT_USAGE;
        goto done;
    }
    const engine_backend* be = app_backend(&c.sim);
    // The server's files where this computer has them (the same install);
    // else this drive's --model and --world, which must describe the same crane.
    // Version 2 servers before "model_asset" sent the model's bare base name:
    // that one is still taken as the shipped default when it is its name.
    const char* dflt = model_default_path();
    const char* base = strrchr(dflt, '/') ? strrchr(dflt, '/') + 1 : dflt;
    const char* asset = cJSON_GetStringValue(cJSON_GetObjectItem(desc, "model_asset"));
    char asset_buf[1024];
    snprintf(asset_buf, sizeof asset_buf, "%s/%s", model_assets_dir(), asset ? asset : "");
    // k.same_model: the local model is the server's file, so its "controls"
    // section maps the sticks to the server's functions as a local drive would.
    k.same_model = true;
    if (file_exists(model_file)) c.model_path = model_file;
    else if (asset && asset[0] && file_exists(asset_buf)) { // the same file in this install's assets
        snprintf(model_buf, sizeof model_buf, "%s", asset_buf);
        c.model_path = model_buf;
    } else if (!strcmp(model_file, base) || !strcmp(model_file, dflt)) c.model_path = NULL; // the shipped model, by name
    else {
        k.same_model = false;
        if (model_file && model_file[0])
            printf("cranesim drive: the server's model %s is not here: drawing %s\n", model_file,
                   c.model_path ? c.model_path : "the default model");
    }
    if (be->world) {
        if (file_exists(world_file)) c.sim.world = world_file;
        else {
            if (!c.sim.world) c.sim.world = be->drive_world;
            printf("cranesim drive: the server's world %s is not here: drawing %s\n", world_file ? world_file : "?",
                   c.sim.world);
        }
    }
    if (!c.scenario_path) c.scenario_path = app_default_drive_scenario(&c.sim);
    int ccode;
    s = drive_session_create(&c, o, err, sizeof err, &ccode);
    if (!s) {
        if (ccode == DRIVE_NO_WINDOW) snprintf(no_window, no_window_sz, "%s", err);
        else fprintf(stderr, "cranesim drive: %s\n", err);
        code = ccode;
        goto done;
    }
    // The same world: the hello's bodies by name, in order.
    const world_snapshot* w = drive_session_snapshot(s);
    cJSON* bodies = cJSON_GetObjectItem(desc, "bodies");
    const int nb = cJSON_GetArraySize(bodies);
    if (nb != w->nbody) {
        fprintf(stderr, "cranesim drive: --connect %s: the server's world has %d bodies, this one (%s) %d: give "
                        "--model and --world as the server runs them\n", addr, nb,
                be->world ? c.sim.world : be->name, w->nbody);
        code = EXIT_USAGE;
        goto done;
    }
    for (int i = 0; i < nb; ++i) {
        const char* bn = cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(bodies, i), "name"));
        if (!bn || strcmp(bn, w->body[i].name)) {
            fprintf(stderr, "cranesim drive: --connect %s: body %d is '%s' on the server, '%s' here: give --model "
                            "and --world as the server runs them\n", addr, i, bn ? bn : "?", w->body[i].name);
            code = EXIT_USAGE;
            goto done;
        }
    }
    k.nbody_local = nb;
    scenario* sc = malloc(sizeof *sc);
    model* dm = NULL;
    if (!sc || app_load_msg(&c, &dm, sc, err, sizeof err)) {
        fprintf(stderr, "cranesim drive: %s\n", sc ? err : "out of memory");
        free(sc);
        code = EXIT_USAGE;
        goto done;
    }
    model_free(dm);
    k.sc = sc;
    drive_session_set_remote(s);
    k.sets = (const char* const*)c0->sets;
    k.nset = c0->nset;
    if (lk_hello(&k, s, &m, err, sizeof err)) { // nbody checked above: a hello without functions, a bad --mapping
        fprintf(stderr, "cranesim drive: %s\n", err);
        if (k.bad_mapping) code = EXIT_USAGE;
        goto done_sc;
    }
    cJSON_Delete(desc);
    desc = NULL;
    printf("cranesim drive: %s from %s%s; %s\n", o->offscreen ? "offscreen view" : "window", addr,
           k.lockstep ? " (lockstep: every frame answered with a step)" : "",
           o->scripted ? "scripted operator" : "joystick or keyboard (the server pauses, resets, hooks)");
    const double tick = 1.0 / 240.0;
    const double w0 = sim_wall_time();
    code = 0;
    bool shot_done = false;
    app_signals sig;
    app_signals_catch(&sig);
    for (;;) {
        const double wall = sim_wall_time() - w0;
        int rc = drive_session_tick(s, wall);
        if (rc < 0) {
            fprintf(stderr, "cranesim drive: %s\n", drive_session_error(s));
            code = EXIT_RUNTIME;
            break;
        }
        if (shot && !shot_done && k.frames > 0 && drive_session_time(s) >= shot_at) {
            drive_session_render(s);
            if (drive_session_screenshot(s, shot, err, sizeof err)) {
                fprintf(stderr, "cranesim drive: %s\n", err);
                code = EXIT_RUNTIME;
            } else {
                printf("  screenshot -> %s (remote t = %.3f s)\n", shot, drive_session_time(s));
            }
            shot_done = true;
            if (duration <= 0) break;
        }
        if (rc > 0 || (duration > 0 && wall >= duration) || app_signal_caught()) break;
        // Reconnect when the back-off is over (doubling to 4 s).
        if (k.fd < 0 && sim_wall_time() >= k.retry_at) {
            k.fd = lk_connect(&k, err, sizeof err);
            if (k.fd < 0) {
                k.backoff = fmin(2 * k.backoff, 4.0);
                k.retry_at = sim_wall_time() + k.backoff;
                char line[200];
                snprintf(line, sizeof line, "link down: %.80s; next try in %.2g s", err, k.backoff);
                char down[RENDER_WARN_LEN];
                snprintf(down, sizeof down, "LINK LOST: %.90s", k.why);
                drive_session_set_link(s, line, down);
            } else {
                k.len = 0;
                k.last_frame_wall = sim_wall_time();
            }
        }
        // Wait for the next tick on the socket, not in a sleep: a frame that
        // arrives is drawn and answered at once (the command-to-echo latency
        // is the link's, not the tick's).
        const double left = w0 + wall + tick - sim_wall_time();
        if (k.fd >= 0) lk_pump(&k, s, left);
        else if (left > 0) drive_session_idle(s, left);
        lk_hud(&k, s);
    }
    app_signals_restore(&sig);
    {
        const drive_stats* st = drive_session_stats(s);
        printf("  drew %ld frames in %.2f s wall; link: %ld frames received, %ld lost, %ld drop%s, %ld connection%s; "
               "command-to-echo latency mean %.2f ms, max %.2f ms (%ld commands); remote t = %.3f s\n",
               st->frames, sim_wall_time() - w0, k.frames, k.lost, k.drops, k.drops == 1 ? "" : "s", k.links,
               k.links == 1 ? "" : "s", k.nlat ? 1e3 * k.lat_sum / k.nlat : 0.0, 1e3 * k.lat_max, k.nlat,
               drive_session_time(s));
    }
done_sc:
    free(sc);
done:
    cJSON_Delete(desc);
    if (k.fd >= 0) close(k.fd);
    if (s) drive_session_destroy(s);
    free(k.rx);
    free(k.st);
    free(k.view);
    free(k.hjson);
    return code;
}
