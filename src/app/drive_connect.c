// drive_connect.c: `cranesim drive --connect HOST:PORT` without the window:
// the visual computer's link, headless. It joins a `cranesim serve` as the
// controller (a watcher when another client controls), sends the scripted
// operator's stick positions at the remote simulated time on every state
// frame, and reports the link: frames received and lost (sequence gaps),
// command-to-echo latency, and when the link drops, which it then tries to
// reconnect once a second until the drive's time is up.
#define _GNU_SOURCE
#include "app.h"
#include "drive_connect.h"
#include "protocol.h"

#include <cJSON.h>
#include <errno.h>
#include <math.h>
#include <netdb.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

static int dc_connect(const char* host, const char* port, char* err, size_t errsz) {
    struct addrinfo hints = {.ai_socktype = SOCK_STREAM}, *res;
    int g = getaddrinfo(host, port, &hints, &res);
    if (g) {
        snprintf(err, errsz, "%s:%s: %s", host, port, gai_strerror(g));
        return -1;
    }
    int fd = socket(res->ai_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || connect(fd, res->ai_addr, res->ai_addrlen)) {
        snprintf(err, errsz, "%s:%s: %s", host, port, strerror(errno));
        if (fd >= 0) close(fd);
        freeaddrinfo(res);
        return -1;
    }
    freeaddrinfo(res);
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    uint8_t b[16];
    const size_t n = proto_put_client_hello(b, sizeof b, PROTO_VERSION, PROTO_CONTROL);
    if (send(fd, b, n, MSG_NOSIGNAL) != (ssize_t)n) {
        snprintf(err, errsz, "%s:%s: %s", host, port, strerror(errno));
        close(fd);
        return -1;
    }
    return fd;
}

// A --set of the drive as the protocol's SET path: a circuit parameter
// without "hydraulics.components." (the fluid without "hydraulics."); any
// other path as given, for the server to accept or refuse.
int drive_set_path(const char* set, char* path, size_t np, double* v) {
    const char* eq = strrchr(set, '=');
    if (!eq) return -1;
    char* end;
    *v = strtod(eq + 1, &end);
    if (end == eq + 1 || *end) return -1;
    const char* p = set;
    if (!strncmp(p, "hydraulics.components.", 22)) p += 22;
    else if (!strncmp(p, "hydraulics.fluid.", 17)) p += 11;
    const size_t n = (size_t)(eq - p);
    if (n == 0 || n >= np || n > PROTO_MAX_PATH) return -1;
    memcpy(path, p, n);
    path[n] = 0;
    return 0;
}

int dc_hello_functions(const char* json, size_t len, dc_functions* f, char* err, size_t errsz) {
    memset(f, 0, sizeof *f);
    cJSON* j = json ? cJSON_ParseWithLength(json, len) : NULL;
    const cJSON* fa = cJSON_GetObjectItem(j, "functions");
    const cJSON* ca = cJSON_GetObjectItem(j, "cylinders");
    int rc = -1;
    const int n = cJSON_GetArraySize(fa), nc = cJSON_GetArraySize(ca);
    if (!j) snprintf(err, errsz, "server hello: the description is not JSON");
    else if (!cJSON_IsArray(fa) || n < 1)
        snprintf(err, errsz, "server hello: no \"functions\" (a server before protocol version 3?)");
    else if (n > PROTO_MAX_FN)
        snprintf(err, errsz, "server hello: %d functions, at most %d", n, PROTO_MAX_FN);
    else if (nc > PROTO_MAX_CYL)
        snprintf(err, errsz, "server hello: %d cylinders, at most %d", nc, PROTO_MAX_CYL);
    else {
        rc = 0;
        for (int k = 0; k < n && !rc; ++k) {
            const cJSON* o = cJSON_GetArrayItem(fa, k);
            const char* name = cJSON_GetStringValue(cJSON_GetObjectItem(o, "name"));
            if (!name || !name[0] || strlen(name) >= DC_FN_NAME) {
                snprintf(err, errsz, "server hello: functions[%d].name missing, empty or longer than %d bytes", k,
                         DC_FN_NAME - 1);
                rc = -1;
                break;
            }
            snprintf(f->name[k], DC_FN_NAME, "%s", name);
            const cJSON* a0 = cJSON_GetArrayItem(cJSON_GetObjectItem(o, "actuators"), 0);
            const cJSON* ci = cJSON_GetObjectItem(a0, "cylinder");
            f->cyl[k] = cJSON_IsNumber(ci) && ci->valuedouble >= 0 && ci->valuedouble < nc ? ci->valueint : -1;
        }
        for (int i = 0; i < nc && !rc; ++i) {
            const cJSON* co = cJSON_GetArrayItem(ca, i);
            const char* name = cJSON_GetStringValue(cJSON_GetObjectItem(co, "name"));
            snprintf(f->cyl_name[i], DC_FN_NAME, "%s", name ? name : "");
            const cJSON* fi = cJSON_GetObjectItem(co, "function");
            f->cyl_fn[i] = cJSON_IsNumber(fi) && fi->valuedouble >= 0 && fi->valuedouble < n ? fi->valueint : -1;
        }
        f->n = rc ? 0 : n;
        f->ncyl = rc ? 0 : nc;
    }
    cJSON_Delete(j);
    return rc;
}

int drive_connect(const char* addr, const scenario* sc, double duration, const char* const* sets, int nset) {
    char host[256], port[16];
    const char* colon = strrchr(addr, ':');
    if (!colon || colon == addr || !colon[1] || (size_t)(colon - addr) >= sizeof host || strlen(colon + 1) >= sizeof port) {
        fprintf(stderr, "cranesim drive: --connect: expected HOST:PORT (127.0.0.1:7575), got '%s'\n", addr);
        return EXIT_USAGE;
    }
    memcpy(host, addr, (size_t)(colon - addr));
    host[colon - addr] = 0;
    snprintf(port, sizeof port, "%s", colon + 1);
    if (host[0] == '[' && host[strlen(host) - 1] == ']') {
        memmove(host, host + 1, strlen(host));
        host[strlen(host) - 1] = 0;
    }
    uint8_t* rx = malloc(PROTO_MAX_SERVER_FRAME + 8);
    proto_state* st = malloc(sizeof *st);
    if (!rx || !st) {
        free(rx);
        free(st);
        fprintf(stderr, "cranesim drive: out of memory\n");
        return EXIT_RUNTIME;
    }
    char err[512], said[600];
    const double w0 = sim_wall_time();
    long frames = 0, lost = 0, drops = 0, links = 0, nlat = 0;
    double lat_sum = 0, lat_max = 0, sent_at = 0, last_t = 0;
    uint64_t seq = 0, last_seq = 0, set_seq[64] = {0}; // set_seq: a SET sent, not answered yet
    int role = -1, code = 0;
    bool ever = false;
    dc_functions fns = {.n = 0};
    int fcol[PROTO_MAX_FN]; // the scenario's column for each of the server's functions, -1: none (0)
    double fmax_cmd[PROTO_MAX_FN] = {0}; // the largest |command| the frames showed per function [-]
    app_signals sig;
    app_signals_catch(&sig);
    while (sim_wall_time() - w0 < duration && !app_signal_caught()) {
        int fd = dc_connect(host, port, err, sizeof err);
        if (fd < 0) {
            if (!ever) { // nothing there at the start: say so, do not wait
                fprintf(stderr, "cranesim drive: --connect %s\n", err);
                code = EXIT_RUNTIME;
                break;
            }
            sleep(1);
            continue;
        }
        ++links;
        size_t len = 0;
        last_seq = 0;
        bool up = true;
        const char* why = "the server closed the link";
        while (up && sim_wall_time() - w0 < duration && !app_signal_caught()) {
            struct pollfd pf = {.fd = fd, .events = POLLIN};
            if (poll(&pf, 1, 2000) <= 0) {
                why = "no frame for 2 s";
                up = false;
                break;
            }
            ssize_t r = recv(fd, rx + len, PROTO_MAX_SERVER_FRAME + 8 - len, 0);
            if (r <= 0) {
                why = r == 0 ? "the server closed the link" : strerror(errno);
                break;
            }
            len += (size_t)r;
            size_t off = 0;
            for (;;) {
                proto_msg m;
                memset(&m, 0, sizeof m);
                m.u.state = st;
                size_t used;
                int rc = proto_parse(rx + off, len - off, PROTO_MAX_SERVER_FRAME, &used, &m, err, sizeof err);
                if (rc < 0) {
                    why = err;
                    up = false;
                    break;
                }
                if (rc == 0) break;
                off += used;
                if (m.type == PROTO_SERVER_HELLO) {
                    // The functions, in the order VALVES takes them; the
                    // scripted operator's column of each name (lift, jib,
                    // slew, or the scenario's own), 0 where it has none.
                    if (dc_hello_functions(m.u.shello.json, m.u.shello.json_len, &fns, err, sizeof err)) {
                        fprintf(stderr, "cranesim drive: --connect %s: %s\n", addr, err);
                        code = EXIT_RUNTIME;
                        up = false;
                        why = err;
                        break;
                    }
                    for (int k = 0; k < fns.n; ++k) fcol[k] = scenario_find_command(sc, fns.name[k]);
                    role = m.u.shello.role;
                    printf("cranesim drive: connected to %s (%s)%s\n", addr,
                           role == PROTO_CONTROL ? "controlling" : "watching: another client controls",
                           ever ? ", reconnected" : "");
                    if (!ever) {
                        printf("cranesim drive: the server's %d function%s:", fns.n, fns.n == 1 ? "" : "s");
                        for (int k = 0; k < fns.n; ++k)
                            printf("%s %s%s", k ? "," : "", fns.name[k], fcol[k] < 0 ? " (not in the scenario: 0)" : "");
                        printf("\n");
                    }
                    fflush(stdout);
                    ever = true;
                    // The drive's --set values go to the server once per
                    // link (a reset server keeps them; a new one has not had them).
                    for (int k = 0; k < nset && k < 64 && role == PROTO_CONTROL; ++k) {
                        proto_command c = {.seq = ++seq, .op = PROTO_OP_SET};
                        set_seq[k] = 0;
                        if (drive_set_path(sets[k], c.path, sizeof c.path, &c.value)) {
                            printf("cranesim drive: --set %s: not sent (expected PATH=VALUE)\n", sets[k]);
                            --seq;
                            continue;
                        }
                        uint8_t b[PROTO_MAX_CLIENT_FRAME + 8];
                        const size_t n = proto_put_command(b, sizeof b, &c);
                        if (n && send(fd, b, n, MSG_NOSIGNAL) == (ssize_t)n) set_seq[k] = seq;
                    }
                } else if (m.type == PROTO_NOTICE) {
                    for (int k = 0; k < nset && k < 64; ++k)
                        if (set_seq[k] && m.u.text.seq == set_seq[k]) {
                            printf("cranesim drive: the server refused --set %s: %s\n", sets[k], m.u.text.text);
                            set_seq[k] = 0;
                        }
                    fflush(stdout);
                } else if (m.type == PROTO_ERROR) {
                    snprintf(said, sizeof said, "the server says: %s", m.u.text.text);
                    why = said;
                    up = false;
                    break;
                } else if (m.type == PROTO_STATE) {
                    ++frames;
                    // A SET is applied (not refused) when the echo passes it.
                    for (int k = 0; k < nset && k < 64; ++k)
                        if (set_seq[k] && st->cmd_seq >= set_seq[k]) {
                            printf("cranesim drive: the server accepted --set %s\n", sets[k]);
                            fflush(stdout);
                            set_seq[k] = 0;
                        }
                    if (last_seq && st->seq > last_seq + 1) lost += (long)(st->seq - last_seq - 1);
                    last_seq = st->seq;
                    last_t = st->nine[8];
                    for (int k = 0; k < st->nfn && k < fns.n; ++k) fmax_cmd[k] = fmax(fmax_cmd[k], fabs(st->fn[k][0]));
                    if (seq && st->cmd_seq == seq && sent_at > 0) {
                        const double l = sim_wall_time() - sent_at;
                        lat_sum += l, lat_max = fmax(lat_max, l), ++nlat;
                        sent_at = 0;
                    }
                    if (role == PROTO_CONTROL && sent_at == 0) {
                        proto_command c = {.seq = ++seq, .op = PROTO_OP_VALVES, .nu = (uint8_t)fns.n};
                        for (int k = 0; k < fns.n; ++k)
                            c.u[k] = fcol[k] < 0 ? 0 : fmax(-1, fmin(1, scenario_command(sc, fcol[k], last_t)));
                        uint8_t b[128];
                        const size_t n = proto_put_command(b, sizeof b, &c);
                        sent_at = sim_wall_time();
                        send(fd, b, n, MSG_NOSIGNAL);
                    }
                }
            }
            memmove(rx, rx + off, len - off);
            len -= off;
        }
        close(fd);
        sent_at = 0;
        if (code) break; // a hello this drive cannot work with: said above
        if (!up || (sim_wall_time() - w0 < duration && !app_signal_caught())) {
            ++drops;
            printf("cranesim drive: link to %s lost: %s; reconnecting\n", addr, why);
            fflush(stdout);
        }
    }
    app_signals_restore(&sig);
    if (ever)
        printf("  link: %ld frames received, %ld lost, %ld drop%s, %ld connection%s; command-to-echo latency mean "
               "%.2f ms, max %.2f ms (%ld commands); remote t = %.3f s\n",
               frames, lost, drops, drops == 1 ? "" : "s", links, links == 1 ? "" : "s",
               nlat ? 1e3 * lat_sum / nlat : 0.0, 1e3 * lat_max, nlat, last_t);
    if (ever) { // what reached the crane, by function (the state frames' function records)
        printf("  functions, the largest |command| the server applied:");
        for (int k = 0; k < fns.n; ++k) printf("%s %s %.2f", k ? "," : "", fns.name[k], fmax_cmd[k]);
        printf("\n");
    }
    free(rx);
    free(st);
    return code;
}
