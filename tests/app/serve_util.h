// serve_util.h: start a real `cranesim serve` for a test, on a free port
// (--listen 127.0.0.1:0: the kernel picks it, the server prints it), and
// talk to it with the protocol module. Every wait has a deadline in poll,
// so a server that stops answering fails the test instead of hanging it.
#ifndef SERVE_UTIL_H
#define SERVE_UTIL_H
#ifndef _DEFAULT_SOURCE
#define _DEFAULT_SOURCE // usleep
#endif

#include "protocol.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef struct served {
    pid_t pid;
    int port;
    FILE* out; // the server's stdout
} served;

// Start `cranesim serve --listen 127.0.0.1:PORT ARGS...` (args NULL-terminated;
// port 0: the kernel picks one) with its stderr to errlog (or inherited when
// NULL). Returns 0 with the port.
static inline int serve_start_on(served* sv, int port, const char* errlog, const char* const* args) {
    int p[2];
    if (pipe(p)) return -1;
    pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        dup2(p[1], 1);
        close(p[0]);
        close(p[1]);
        if (errlog) {
            FILE* e = fopen(errlog, "w");
            if (e) dup2(fileno(e), 2);
        }
        char listen[32];
        snprintf(listen, sizeof listen, "127.0.0.1:%d", port);
        const char* argv[64] = {CRANESIM_BINARY_DIR "/cranesim", "serve", "--listen", listen};
        int n = 4;
        for (int k = 0; args && args[k] && n < 62; ++k) argv[n++] = args[k];
        argv[n] = NULL;
        execv(argv[0], (char* const*)argv);
        _exit(127);
    }
    close(p[1]);
    sv->pid = pid;
    sv->out = fdopen(p[0], "r");
    char line[512];
    while (fgets(line, sizeof line, sv->out)) {
        const char* at = strstr(line, "listening on 127.0.0.1:");
        if (at) {
            sv->port = atoi(at + strlen("listening on 127.0.0.1:"));
            return 0;
        }
    }
    return -1;
}

static inline int serve_start(served* sv, const char* errlog, const char* const* args) {
    return serve_start_on(sv, 0, errlog, args);
}

// SIGINT, then the exit status (-1: it did not end by itself within 20 s).
static inline int serve_stop(served* sv) {
    kill(sv->pid, SIGINT);
    for (int k = 0; k < 2000; ++k) {
        int st;
        if (waitpid(sv->pid, &st, WNOHANG) == sv->pid) {
            fclose(sv->out);
            return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
        }
        usleep(10000);
    }
    kill(sv->pid, SIGKILL);
    waitpid(sv->pid, NULL, 0);
    fclose(sv->out);
    return -1;
}

static inline int tcp_connect(int port) {
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(fd, (struct sockaddr*)&a, sizeof a)) {
        close(fd);
        return -1;
    }
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    return fd;
}

static inline int send_all(int fd, const void* b, size_t n) {
    const uint8_t* p = b;
    while (n) {
        ssize_t k = send(fd, p, n, MSG_NOSIGNAL);
        if (k <= 0) return -1;
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

// Bytes into b[0..n) within ms milliseconds: 0, -1 closed (EOF or reset), -2 timed out.
static inline int recv_all(int fd, uint8_t* b, size_t n, int ms) {
    size_t k = 0;
    while (k < n) {
        struct pollfd pf = {.fd = fd, .events = POLLIN};
        if (poll(&pf, 1, ms) <= 0) return -2;
        ssize_t r = recv(fd, b + k, n - k, 0);
        if (r <= 0) return -1;
        k += (size_t)r;
    }
    return 0;
}

// One frame parsed into *m (state frames into st). Returns its type, -1 closed, -2 timed out, -3 malformed.
static inline int recv_frame(int fd, proto_msg* m, proto_state* st, int ms) {
    static _Thread_local uint8_t b[PROTO_MAX_SERVER_FRAME + 8]; // the hostile test reads on two threads
    int rc = recv_all(fd, b, 4, ms);
    if (rc) return rc;
    const uint32_t len = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    if (len == 0 || len > PROTO_MAX_SERVER_FRAME) return -3;
    rc = recv_all(fd, b + 4, len, ms);
    if (rc) return rc;
    memset(m, 0, sizeof *m);
    m->u.state = st;
    size_t used;
    char err[256];
    if (proto_parse(b, 4 + len, PROTO_MAX_SERVER_FRAME, &used, m, err, sizeof err) != 1) return -3;
    return m->type;
}

// Connect and say hello with role; returns the fd with the server's hello read (role granted in *granted).
static inline int serve_join(int port, int role, int* granted) {
    int fd = tcp_connect(port);
    if (fd < 0) return -1;
    uint8_t b[32];
    size_t n = proto_put_client_hello(b, sizeof b, PROTO_VERSION, (uint8_t)role);
    proto_msg m;
    static proto_state st;
    if (send_all(fd, b, n) || recv_frame(fd, &m, &st, 5000) != PROTO_SERVER_HELLO) {
        close(fd);
        return -1;
    }
    if (granted) *granted = m.u.shello.role;
    return fd;
}

static inline int send_cmd(int fd, const proto_command* c) {
    uint8_t b[PROTO_MAX_CLIENT_FRAME + 8];
    size_t n = proto_put_command(b, sizeof b, c);
    return n ? send_all(fd, b, n) : -1;
}

// The next state frame within ms (notices skipped into *notice when given). Returns 0, or the recv_frame failure.
static inline int next_state(int fd, proto_state* st, int ms) {
    proto_msg m;
    for (;;) {
        int t = recv_frame(fd, &m, st, ms);
        if (t == PROTO_STATE) return 0;
        if (t < 0) return t;
        if (t == PROTO_ERROR) return -1;
    }
}

// Wait until the server closes fd (EOF or reset) within ms; frames before it are read and dropped.
// Returns 1 closed, 0 still open after ms.
static inline int closed_within(int fd, int ms) {
    static uint8_t b[65536];
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        clock_gettime(CLOCK_MONOTONIC, &t1);
        if ((t1.tv_sec - t0.tv_sec) * 1000.0 + (t1.tv_nsec - t0.tv_nsec) * 1e-6 > ms) break;
        struct pollfd pf = {.fd = fd, .events = POLLIN};
        if (poll(&pf, 1, 50) > 0) {
            ssize_t r = recv(fd, b, sizeof b, 0);
            if (r <= 0) return 1;
        }
    }
    return 0;
}

#endif
