// bench_serve.c: `cranesim bench --config serve`: a real `cranesim serve`
// (this binary, a child process) streaming the sandbox at 1 kHz over
// loopback to one controlling and two watching clients for --duration
// seconds of wall time (default 60). The controller sends a valve command
// on every frame it receives; the time from sending command n to the first
// state frame echoing n is its latency. One JSON line: frames per second
// each client received, frames lost, p50/p99/max latency, and the server's
// own count of missed frame deadlines and how late its frames started (from
// its log), then the machine's floor without any simulation (bs_baseline)
// and the load average before and after: whether a p99 is the machine's or ours.
#define _GNU_SOURCE
#include "app.h"
#include "protocol.h"

#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef struct bconn {
    int fd;
    uint8_t* rx;
    size_t len;
    long frames, lost;
    uint64_t last_seq, echo;
    bool closed;
} bconn;

#define BS_RX (2u << 20)
#define BS_MAXLAT 200000

static int bs_connect(int port, int role) {
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || connect(fd, (struct sockaddr*)&a, sizeof a)) {
        if (fd >= 0) close(fd);
        return -1;
    }
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    uint8_t b[16];
    size_t n = proto_put_client_hello(b, sizeof b, PROTO_VERSION, (uint8_t)role);
    if (send(fd, b, n, MSG_NOSIGNAL) != (ssize_t)n) {
        close(fd);
        return -1;
    }
    return fd;
}

// Read what is there and count its state frames; the controller's echo in c->echo.
static void bs_read(bconn* c, proto_state* st) {
    ssize_t r = recv(c->fd, c->rx + c->len, BS_RX - c->len, MSG_DONTWAIT);
    if (r == 0 || (r < 0 && errno != EAGAIN && errno != EINTR)) {
        c->closed = true;
        return;
    }
    if (r > 0) c->len += (size_t)r;
    size_t off = 0;
    for (;;) {
        proto_msg m;
        memset(&m, 0, sizeof m);
        m.u.state = st;
        size_t used;
        char err[256];
        int rc = proto_parse(c->rx + off, c->len - off, PROTO_MAX_SERVER_FRAME, &used, &m, err, sizeof err);
        if (rc < 0) {
            c->closed = true;
            return;
        }
        if (rc == 0) break;
        off += used;
        if (m.type == PROTO_STATE) {
            ++c->frames;
            if (c->last_seq && st->seq > c->last_seq + 1) c->lost += (long)(st->seq - c->last_seq - 1);
            c->last_seq = st->seq;
            c->echo = st->cmd_seq;
        } else if (m.type == PROTO_ERROR) {
            c->closed = true;
        }
    }
    memmove(c->rx, c->rx + off, c->len - off);
    c->len -= off;
}

static int cmp_d(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

// The machine's own floor, with no simulation: a child process echoes 8
// bytes over TCP loopback (TCP_NODELAY), and this process sends them once per
// millisecond on an absolute timer, as the server paces its frames. p[0],
// p[1]: round trip p50, p99 [s]; p[2]: how late the timer woke, p99 [s].
static void bs_baseline(double seconds, double p[3]) {
    p[0] = p[1] = p[2] = NAN;
    int lfd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t al = sizeof a;
    if (lfd < 0 || bind(lfd, (struct sockaddr*)&a, sizeof a) || listen(lfd, 1) ||
        getsockname(lfd, (struct sockaddr*)&a, &al)) {
        if (lfd >= 0) close(lfd);
        return;
    }
    pid_t pid = fork();
    if (pid == 0) {
        int fd = accept(lfd, NULL, NULL);
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        uint8_t b[8];
        while (recv(fd, b, 8, MSG_WAITALL) == 8 && send(fd, b, 8, MSG_NOSIGNAL) == 8) {
        }
        _exit(0);
    }
    close(lfd);
    int fd = pid > 0 ? socket(AF_INET, SOCK_STREAM, 0) : -1;
    if (fd < 0 || connect(fd, (struct sockaddr*)&a, sizeof a)) {
        if (fd >= 0) close(fd);
        if (pid > 0) waitpid(pid, NULL, 0);
        return;
    }
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    const long n = (long)(seconds * 1000);
    double* rtt = malloc((size_t)n * sizeof *rtt);
    double* late = malloc((size_t)n * sizeof *late);
    long k = 0;
    struct timespec next;
    clock_gettime(CLOCK_MONOTONIC, &next);
    while (rtt && late && k < n) {
        next.tv_nsec += 1000000;
        if (next.tv_nsec >= 1000000000) next.tv_nsec -= 1000000000, ++next.tv_sec;
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL);
        const double t0 = sim_wall_time();
        late[k] = t0 - ((double)next.tv_sec + 1e-9 * (double)next.tv_nsec);
        uint8_t b[8] = {0};
        if (send(fd, b, 8, MSG_NOSIGNAL) != 8 || recv(fd, b, 8, MSG_WAITALL) != 8) break;
        rtt[k++] = sim_wall_time() - t0;
        // Far behind (a long stall): start the timer again from now.
        struct timespec now;
        clock_gettime(CLOCK_MONOTONIC, &now);
        if ((double)now.tv_sec + 1e-9 * (double)now.tv_nsec > (double)next.tv_sec + 1e-9 * (double)next.tv_nsec + 0.01)
            next = now;
    }
    close(fd);
    waitpid(pid, NULL, 0);
    if (k > 0) {
        qsort(rtt, (size_t)k, sizeof *rtt, cmp_d);
        qsort(late, (size_t)k, sizeof *late, cmp_d);
        p[0] = rtt[k / 2], p[1] = rtt[(long)(0.99 * (k - 1))], p[2] = late[(long)(0.99 * (k - 1))];
    }
    free(rtt);
    free(late);
}

int bench_serve(const app_common* c, double duration, bool realtime) {
    (void)c;
    int out[2];
    if (pipe(out)) return EXIT_RUNTIME;
    char logpath[] = "/tmp/cranesim_bench_serve_XXXXXX";
    int logfd = mkstemp(logpath);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, out[1], 1);
    if (logfd >= 0) posix_spawn_file_actions_adddup2(&fa, logfd, 2);
    posix_spawn_file_actions_addclose(&fa, out[0]);
    char* args[] = {"cranesim", "serve", "--listen", "127.0.0.1:0", "--rate", "1000", "--queue", "256",
                    "--log-misses", realtime ? "--realtime" : NULL, NULL};
    pid_t pid;
    extern char** environ;
    if (posix_spawn(&pid, "/proc/self/exe", &fa, NULL, args, environ)) {
        printf("{\"config\":\"serve\",\"error\":\"cannot start cranesim serve\"}\n");
        return EXIT_RUNTIME;
    }
    posix_spawn_file_actions_destroy(&fa);
    close(out[1]);
    FILE* so = fdopen(out[0], "r");
    char line[512];
    int port = 0;
    while (!port && so && fgets(line, sizeof line, so)) {
        const char* at = strstr(line, "listening on 127.0.0.1:");
        if (at) port = atoi(at + strlen("listening on 127.0.0.1:"));
    }
    double load0[3] = {NAN, NAN, NAN};
    getloadavg(load0, 3);
    bconn cs[3];
    memset(cs, 0, sizeof cs);
    proto_state* st = malloc(sizeof *st);
    double* sent = calloc(BS_MAXLAT + 1, sizeof *sent); // wall time command n went out [s]
    double* lat = malloc(BS_MAXLAT * sizeof *lat);
    int code = 0;
    for (int k = 0; k < 3 && port; ++k) {
        cs[k].fd = bs_connect(port, k == 0 ? PROTO_CONTROL : PROTO_WATCH);
        cs[k].rx = malloc(BS_RX);
        if (cs[k].fd < 0 || !cs[k].rx) port = 0;
    }
    if (!port || !st || !sent || !lat) {
        printf("{\"config\":\"serve\",\"error\":\"cannot connect to cranesim serve\"}\n");
        code = EXIT_RUNTIME;
    }
    long nlat = 0;
    uint64_t seq = 0, echoed = 0;
    const double w0 = sim_wall_time();
    double t_first = 0;
    while (!code && sim_wall_time() - w0 < duration) {
        struct pollfd pf[3];
        for (int k = 0; k < 3; ++k) pf[k] = (struct pollfd){.fd = cs[k].fd, .events = POLLIN};
        if (poll(pf, 3, 100) <= 0) continue;
        for (int k = 0; k < 3; ++k)
            if (pf[k].revents) bs_read(&cs[k], st);
        if (cs[0].closed || cs[1].closed || cs[2].closed) {
            printf("{\"config\":\"serve\",\"error\":\"the server closed a client\"}\n");
            code = EXIT_RUNTIME;
            break;
        }
        if (!t_first && cs[0].frames) t_first = sim_wall_time();
        const double now = sim_wall_time();
        // Every command the echo passed is done: its latency is now - sent.
        while (echoed < cs[0].echo && echoed < seq) {
            ++echoed;
            if (echoed == cs[0].echo && nlat < BS_MAXLAT && echoed <= BS_MAXLAT) lat[nlat++] = now - sent[echoed];
        }
        // A new command once the last one came back (one in flight: its
        // latency is not queued behind the previous ones).
        if (pf[0].revents && echoed == seq && seq < BS_MAXLAT) {
            proto_command cmd = {.seq = ++seq, .op = PROTO_OP_VALVES, .nu = 3,
                                 .u = {0.5 * sin(now - w0), 0.5 * cos(now - w0), 0.3 * sin(0.5 * (now - w0))}};
            uint8_t b[128];
            size_t n = proto_put_command(b, sizeof b, &cmd);
            sent[seq] = sim_wall_time();
            if (send(cs[0].fd, b, n, MSG_NOSIGNAL) != (ssize_t)n) {
                code = EXIT_RUNTIME;
                break;
            }
        }
    }
    const double span = sim_wall_time() - (t_first ? t_first : w0);
    kill(pid, SIGINT);
    int wst = 0;
    waitpid(pid, &wst, 0);
    long missed = -1, sframes = -1;
    double worst = NAN, mean = NAN, late50 = NAN, late99 = NAN;
    long cause[5] = {0, 0, 0, 0, 0}; // woke late, page faults, preempted, long step, other
    char rt[16] = "off";
    if (logfd >= 0) {
        FILE* lf = fdopen(logfd, "r");
        rewind(lf);
        while (fgets(line, sizeof line, lf)) {
            const char* p = strstr(line, "] ");
            long a, b;
            double w, mn;
            if (p && sscanf(p + 2, "%ld frames, %ld missed deadlines, worst frame %lf ms, mean frame %lf ms", &a, &b,
                            &w, &mn) == 4)
                sframes = a, missed = b, worst = w, mean = mn;
            // Each missed deadline's line: sort it by its cause. Started
            // late by more than half a frame: the wake-up (the scheduler);
            // else a page fault in it, else a step longer than a frame, else
            // the send; with an involuntary switch in it: preempted.
            double sl, stp, snd;
            long fmin_, fmaj, ivc, vc, fr;
            double at;
            if (p && sscanf(p + 2,
                            "missed deadline: frame %ld at %lf s: started %lf ms late, step %lf ms, send %lf ms; "
                            "during the frame %ld minor + %ld major page faults, %ld involuntary + %ld voluntary",
                            &fr, &at, &sl, &stp, &snd, &fmin_, &fmaj, &ivc, &vc) == 9) {
                if (sl > 0.5) ++cause[0];
                else if (fmin_ + fmaj > 0) ++cause[1];
                else if (ivc > 0) ++cause[2];
                else if (stp > 1.0) ++cause[3];
                else ++cause[4];
            }
            if (p && !strncmp(p + 2, "real time: ", 11))
                snprintf(rt, sizeof rt, "%s", !strncmp(p + 13, "SCHED_FIFO priority", 19) ? "SCHED_FIFO"
                                              : strstr(p, "nice -10 instead") ? "nice -10" : "none");
            const char* q = p ? strstr(p, "after its deadline p50 ") : NULL;
            if (q) sscanf(q, "after its deadline p50 %lf ms, p99 %lf ms", &late50, &late99);
        }
        fclose(lf);
        unlink(logpath);
    }
    // The machine's floor right after, for 10 s (or the run's length if shorter).
    double base[3] = {NAN, NAN, NAN}, load1[3] = {NAN, NAN, NAN};
    if (!code) bs_baseline(fmin(10.0, duration), base);
    getloadavg(load1, 3);
    if (!code) {
        qsort(lat, (size_t)nlat, sizeof *lat, cmp_d);
        const double p50 = nlat ? lat[nlat / 2] : NAN, p99 = nlat ? lat[(long)(0.99 * (nlat - 1))] : NAN,
                     mx = nlat ? lat[nlat - 1] : NAN;
        printf("{\"config\":\"%s\",\"world\":\"sandbox\",\"rate_hz\":1000,\"clients\":3,\"wall_s\":%.3f,"
               "\"frames_per_s_controller\":%.1f,\"frames_per_s_watcher1\":%.1f,\"frames_per_s_watcher2\":%.1f,"
               "\"frames_lost\":[%ld,%ld,%ld],\"commands\":%ld,\"latency_ms_p50\":%.3f,\"latency_ms_p99\":%.3f,"
               "\"latency_ms_max\":%.3f,\"server_frames\":%ld,\"missed_deadlines\":%ld,\"server_frame_ms_mean\":%.3f,"
               "\"server_frame_ms_worst\":%.3f,\"server_start_late_ms_p50\":%.2f,\"server_start_late_ms_p99\":%.2f,"
               "\"baseline_rtt_ms_p50\":%.3f,\"baseline_rtt_ms_p99\":%.3f,\"baseline_timer_late_ms_p99\":%.3f,"
               "\"missed_woke_late\":%ld,\"missed_page_faults\":%ld,\"missed_preempted\":%ld,"
               "\"missed_long_step\":%ld,\"missed_other\":%ld,\"server_realtime\":\"%s\","
               "\"loadavg_1min_start\":%.2f,\"loadavg_1min_end\":%.2f,\"server_exit\":%d}\n",
               realtime ? "serve" : "serve-plain", span, cs[0].frames / span, cs[1].frames / span, cs[2].frames / span, cs[0].lost, cs[1].lost,
               cs[2].lost, nlat, p50 * 1e3, p99 * 1e3, mx * 1e3, sframes, missed, mean, worst, late50, late99,
               base[0] * 1e3, base[1] * 1e3, base[2] * 1e3, cause[0], cause[1], cause[2], cause[3], cause[4], rt,
               load0[0], load1[0], WIFEXITED(wst) ? WEXITSTATUS(wst) : -1);
        fflush(stdout);
    }
    for (int k = 0; k < 3; ++k) {
        if (cs[k].fd > 0) close(cs[k].fd);
        free(cs[k].rx);
    }
    if (so) fclose(so);
    free(st);
    free(sent);
    free(lat);
    return code;
}
