/* client.c: a small cranesim serve client in plain C (libc and POSIX sockets
 * only, no cranesim headers: the wire format is docs/protocol.md, version 3).
 * It asks for control and prints the functions the server's hello lists
 * (read from its JSON with the small scanner below), then for every tenth
 * state frame the time, the crane tip in the world, the truck's roll and
 * pitch, the supply pressure and every function's values: its first
 * actuator's stroke and chamber pressures, its spool and its command. It
 * lifts (the first function) for half of its frames and lowers for the
 * other half, one opening per function, and prints at the end the
 * command-to-echo delay.
 *
 *   cc -O2 -o client examples/client.c -lm
 *   cranesim serve &            # listens on 127.0.0.1:7575
 *   ./client 127.0.0.1 7575 150
 */
#include <math.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void put32(uint8_t* p, uint32_t v) { for (int i = 0; i < 4; ++i) p[i] = (uint8_t)(v >> (8 * i)); }
static void put64(uint8_t* p, uint64_t v) { for (int i = 0; i < 8; ++i) p[i] = (uint8_t)(v >> (8 * i)); }
static uint32_t get32(const uint8_t* p) { return p[0] | p[1] << 8 | p[2] << 16 | (uint32_t)p[3] << 24; }
static uint64_t get64(const uint8_t* p) { return get32(p) | (uint64_t)get32(p + 4) << 32; }
static double getf(const uint8_t* p) { uint64_t v = get64(p); double d; memcpy(&d, &v, 8); return d; }
static void putf(uint8_t* p, double d) { uint64_t v; memcpy(&v, &d, 8); put64(p, v); }
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }

static int read_all(int fd, uint8_t* b, size_t n) {
    for (size_t k = 0; k < n;) {
        ssize_t r = recv(fd, b + k, n - k, 0);
        if (r <= 0) return -1;
        k += (size_t)r;
    }
    return 0;
}

/* One frame into b (cap bytes); returns its type, or -1 when the link closed. */
static int read_frame(int fd, uint8_t* b, size_t cap, uint32_t* len) {
    uint8_t h[4];
    if (read_all(fd, h, 4)) return -1;
    *len = get32(h);
    if (*len == 0 || *len > cap) return -1;
    if (read_all(fd, b, *len)) return -1;
    return b[0];
}

#define MAX_FN 16
#define MAX_CYL 16
static int nfn;
static char fn_name[MAX_FN][48];
static int fn_cyl[MAX_FN]; /* the first cylinder record each function drives, -1 none */

/* The hello's "functions": each one's "name" and its first actuator's
 * "cylinder". A scanner for the JSON the server writes: strings are
 * skipped whole, nesting is counted, keys are the strings before a colon.
 * Depth 1 is the functions array, 2 a function, 3 its actuators, 4 one. */
static int scan_functions(const char* j, size_t n) {
    const char* end = j + n;
    const char* p = NULL;
    for (const char* q = j; q + 13 <= end; ++q)
        if (!memcmp(q, "\"functions\":[", 13)) { p = q + 12; break; }
    if (!p) return -1;
    int depth = 0;
    char key[32] = "";
    nfn = 0;
    for (; p < end; ++p) {
        if (*p == '"') { /* a string: a key when a colon follows */
            const char* s0 = ++p;
            while (p < end && *p != '"') p += *p == '\\' ? 2 : 1;
            const size_t len = (size_t)(p - s0);
            if (p + 1 < end && p[1] == ':') {
                snprintf(key, sizeof key, "%.*s", (int)len, s0);
            } else if (depth == 2 && !strcmp(key, "name") && nfn < MAX_FN) {
                snprintf(fn_name[nfn], sizeof fn_name[nfn], "%.*s", (int)len, s0);
                fn_cyl[nfn++] = -1;
            }
        } else if (*p == '[' || *p == '{') {
            ++depth;
        } else if (*p == ']' || *p == '}') {
            if (--depth == 0) return nfn; /* the end of the functions array */
        } else if (depth == 4 && !strcmp(key, "cylinder") && nfn && fn_cyl[nfn - 1] < 0 &&
                   (*p == '-' || (*p >= '0' && *p <= '9'))) {
            fn_cyl[nfn - 1] = atoi(p);
            while (p + 1 < end && p[1] >= '0' && p[1] <= '9') ++p;
        }
    }
    return -1;
}

/* VALVES: seq, op 1, the count, one opening per function. */
static int send_valves(int fd, uint64_t seq, const double* u, int n) {
    uint8_t f[15 + 8 * MAX_FN];
    const size_t len = 15 + 8 * (size_t)n;
    put32(f, (uint32_t)(len - 4)); f[4] = 4; put64(f + 5, seq); f[13] = 1; f[14] = (uint8_t)n;
    for (int k = 0; k < n; ++k) putf(f + 15 + 8 * k, u[k]);
    return send(fd, f, len, 0) == (ssize_t)len ? 0 : -1;
}

int main(int argc, char** argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: %s HOST PORT [FRAMES]\n", argv[0]);
        return 2;
    }
    const long frames = argc > 3 ? atol(argv[3]) : 150;
    struct addrinfo hints = {.ai_socktype = SOCK_STREAM}, *res;
    if (getaddrinfo(argv[1], argv[2], &hints, &res)) {
        fprintf(stderr, "client: cannot resolve %s:%s\n", argv[1], argv[2]);
        return 1;
    }
    int fd = socket(res->ai_family, SOCK_STREAM, 0);
    if (fd < 0 || connect(fd, res->ai_addr, res->ai_addrlen)) {
        fprintf(stderr, "client: cannot connect to %s:%s\n", argv[1], argv[2]);
        return 1;
    }
    freeaddrinfo(res);
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    /* CLIENT_HELLO: magic "CSIM", version 3, role 1 (control). */
    uint8_t hello[12];
    put32(hello, 8); hello[4] = 1; memcpy(hello + 5, "CSIM", 4); hello[9] = 3; hello[10] = 0; hello[11] = 1;
    send(fd, hello, sizeof hello, 0);
    static uint8_t b[1 << 20];
    uint32_t len;
    int type = read_frame(fd, b, sizeof b, &len);
    if (type != 2) {
        fprintf(stderr, "client: no server hello (frame type %d%s%.*s)\n", type, type == 5 ? ": " : "",
                type == 5 ? (int)(len - 13) : 0, (const char*)b + 13);
        return 1;
    }
    printf("connected: protocol %u, role %s, %.0f frames/s\n", b[5] | b[6] << 8, b[7] ? "control" : "watch",
           getf(b + 9));
    const uint32_t jlen = get32(b + 17);
    if (jlen > len - 21 || scan_functions((const char*)b + 21, jlen) < 1) {
        fprintf(stderr, "client: the hello lists no functions\n");
        return 1;
    }
    printf("%d functions (VALVES takes one opening each, in this order):\n", nfn);
    for (int k = 0; k < nfn; ++k) printf("  %d %s (cylinder %d)\n", k, fn_name[k], fn_cyl[k]);
    uint64_t seq = 0, sent_seq = 0, last_echo = 0;
    double sent_at = 0, worst = 0;
    long got = 0, lost = 0;
    uint64_t last_frame = 0;
    while (got < frames) {
        type = read_frame(fd, b, sizeof b, &len);
        if (type < 0) {
            fprintf(stderr, "client: the link closed\n");
            return 1;
        }
        if (type == 5 || type == 6) {
            fprintf(stderr, "client: server says: %.*s\n", (int)(len - 13), (const char*)b + 13);
            if (type == 5) return 1;
            continue;
        }
        if (type != 3) continue;
        const double t = getf(b + 1 + 8 * 8); /* the nine values first: x1 x2 p1A p1B p2A p2B u1 u2 t */
        const uint64_t fseq = get64(b + 73), echo = get64(b + 81);
        /* After flags, slew, hook, load mass and attached: the tip (world, m),
         * the truck's roll and pitch (rad), the supply pressure (Pa). */
        double x[6];
        for (int k = 0; k < 6; ++k) x[k] = getf(b + 137 + 8 * k);
        /* Then the variable part, walked to the cylinders and the functions. */
        size_t o = 201;
        o += 1 + 8 * (size_t)b[o];                       /* supports */
        o += 2 + 8 * (size_t)(b[o] | b[o + 1] << 8);     /* the row */
        o += 2 + 96 * (size_t)(b[o] | b[o + 1] << 8);    /* body poses */
        const size_t cyl0 = o + 1;                       /* 13 f64 + 1 byte each */
        const int ncyl = b[o];
        o += 1 + 105 * (size_t)ncyl;
        o += 1 + 24 * (size_t)b[o];                      /* the rope */
        const int nrelief = b[o++];
        for (int k = 0; k < nrelief; ++k) o += 3 + (size_t)b[o + 2];
        const int nf = b[o++];
        if (nf != nfn || o + 16 * (size_t)nf != len) {
            fprintf(stderr, "client: a state frame with %d functions (the hello has %d) or of another length\n", nf,
                    nfn);
            return 1;
        }
        if (last_frame && fseq > last_frame + 1) lost += (long)(fseq - last_frame - 1);
        last_frame = fseq;
        if (echo == sent_seq && echo != last_echo) {
            worst = fmax(worst, now() - sent_at);
            last_echo = echo;
        }
        if (got % 10 == 0) {
            printf("t %.3f s: tip %.2f %.2f %.2f m, roll %.2f pitch %.2f deg, p_s %.3f MPa\n", t, x[0], x[1], x[2],
                   x[3] * 180 / M_PI, x[4] * 180 / M_PI, x[5] * 1e-6);
            for (int k = 0; k < nfn; ++k) {
                const double cmd = getf(b + o + 16 * k), spool = getf(b + o + 16 * k + 8);
                const int c = fn_cyl[k];
                if (c >= 0 && c < ncyl) {
                    const uint8_t* r = b + cyl0 + 105 * (size_t)c;
                    printf("  %-10s stroke %8.1f mm  pA %8.3f MPa  pB %8.3f MPa  u %+.3f  command %+.3f\n",
                           fn_name[k], getf(r + 48) * 1e3, getf(r + 56) * 1e-6, getf(r + 64) * 1e-6, spool, cmd);
                } else {
                    printf("  %-10s u %+.3f  command %+.3f\n", fn_name[k], spool, cmd);
                }
            }
        }
        ++got;
        /* A new command every frame: the first function up, then down. */
        double u[MAX_FN] = {0};
        u[0] = got < frames / 2 ? 0.6 : -0.6;
        if (send_valves(fd, ++seq, u, nfn)) return 1;
        sent_seq = seq;
        sent_at = now();
    }
    printf("%ld frames, %ld lost, last command echoed: %llu of %llu, worst command-to-echo %.2f ms\n", got, lost,
           (unsigned long long)last_echo, (unsigned long long)seq, worst * 1e3);
    close(fd);
    return last_echo > 0 ? 0 : 1;
}
