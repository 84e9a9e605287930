/* client.c: a small cranesim serve client in plain C (libc and POSIX sockets
 * only, no cranesim headers: the wire format is docs/protocol.md). It asks
 * for control, lifts the boom for half of its frames and lowers it for the
 * other half, and prints for every tenth state frame the paper's nine values,
 * the crane tip in the world, the truck's roll and pitch and the supply
 * pressure, and at the end the command-to-echo delay (protocol version 2).
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

static int send_valves(int fd, uint64_t seq, double lift, double jib, double slew) {
    uint8_t f[38];
    put32(f, 34); f[4] = 4; put64(f + 5, seq); f[13] = 1; /* COMMAND, op VALVES */
    putf(f + 14, lift); putf(f + 22, jib); putf(f + 30, slew);
    return send(fd, f, sizeof f, 0) == (ssize_t)sizeof f ? 0 : -1;
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
    /* CLIENT_HELLO: magic "CSIM", version 2, role 1 (control). */
    uint8_t hello[12];
    put32(hello, 8); hello[4] = 1; memcpy(hello + 5, "CSIM", 4); hello[9] = 2; hello[10] = 0; hello[11] = 1;
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
    uint64_t seq = 0, sent_seq = 0, last_echo = 0;
    double sent_at = 0, worst = 0;
    long got = 0, lost = 0;
    uint64_t last_frame = 0;
    printf("      t [s]    x1 [mm]    x2 [mm]  p1A [MPa]  p1B [MPa]  p2A [MPa]  p2B [MPa]      u1      u2"
           "         tip x, y, z [m]  roll, pitch [deg] p_s [MPa]\n");
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
        double v[9]; /* the nine values: x1 x2 p1A p1B p2A p2B u1 u2 t */
        for (int k = 0; k < 9; ++k) v[k] = getf(b + 1 + 8 * k);
        const uint64_t fseq = get64(b + 73), echo = get64(b + 81);
        /* After flags, slew, hook, load mass and attached: the tip (world, m),
         * the truck's roll and pitch (rad), the supply pressure (Pa). */
        double x[6];
        for (int k = 0; k < 6; ++k) x[k] = getf(b + 137 + 8 * k);
        if (last_frame && fseq > last_frame + 1) lost += (long)(fseq - last_frame - 1);
        last_frame = fseq;
        if (echo == sent_seq && echo != last_echo) {
            worst = fmax(worst, now() - sent_at);
            last_echo = echo;
        }
        if (got % 10 == 0)
            printf("%11.3f %10.1f %10.1f %10.3f %10.3f %10.3f %10.3f %7.3f %7.3f %7.2f %7.2f %7.2f %8.2f %8.2f %9.3f\n",
                   v[8], v[0] * 1e3, v[1] * 1e3, v[2] * 1e-6, v[3] * 1e-6, v[4] * 1e-6, v[5] * 1e-6, v[6], v[7], x[0],
                   x[1], x[2], x[3] * 180 / M_PI, x[4] * 180 / M_PI, x[5] * 1e-6);
        ++got;
        /* A new command every frame: lift up, then down. */
        const double lift = got < frames / 2 ? 0.6 : -0.6;
        if (send_valves(fd, ++seq, lift, 0.0, 0.0)) return 1;
        sent_seq = seq;
        sent_at = now();
    }
    printf("%ld frames, %ld lost, last command echoed: %llu of %llu, worst command-to-echo %.2f ms\n", got, lost,
           (unsigned long long)last_echo, (unsigned long long)seq, worst * 1e3);
    close(fd);
    return last_echo > 0 ? 0 : 1;
}
