// test_drive_connect.c: `cranesim drive --connect` draws the remote crane as
// a local drive draws the same state.
//
// A lockstep `cranesim serve` (the sandbox) is driven by `cranesim drive
// --connect --screenshot` (offscreen): it answers every state frame with the
// scripted operator's openings and one step, so the remote state at the
// screenshot is reproducible. Here the same scenario runs on a local engine
// frame by frame (the openings at the middle of each frame, hook events as
// the player gives them), its snapshot sampled into the charts once per frame
// as the remote view samples every state frame, and a local drive session
// renders that state at the same size. The two pictures must match: at most
// 2 % of the pixels differ by more than 40 of 255 in a channel. Not bit for
// bit, and why: the HUD's frame rate is each renderer's own wall-clock
// measure, and the remote view draws its link line (frames, latency) top
// right. The same comparison against the local state 1.5 s later must fail
// it by far: the tolerance tells states apart.
//
// Parameter changes in the remote view: the drive's --set goes to the server
// as SET through the window's link, and its answer is printed ("accepted by
// the server": the main relief's own 22 MPa, so the picture stays that of the
// unchanged run). A remote session's panel edit of a circuit parameter is
// queued for the server under its protocol path in SI units (10 MPa shown:
// main_relief.p_crack = 1e7 Pa) and leaves the idle local circuit alone; an
// edit of a mechanical value is not sent and is put back. A chart and a
// readout of a circuit channel (not in the state frames) say "not sent by
// the server"; a chart of a row channel does not.
#define _DEFAULT_SOURCE
#include "check.h"
#include "drive_session.h"
#include "panel.h"
#include "render.h"
#include "serve_util.h"

#include <math.h>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#define W 960
#define H 540
// The top line holds the two differences by design: the HUD's frame rate
// (each renderer's own wall-clock measure) and the remote view's link line.
#define TOP 24

// Pixels whose largest channel difference exceeds 40 (of 255), as a fraction;
// the mask of them to mask_png (white: differs) when not NULL, to look at.
// Rows from y0 down (y0 = 0: the whole picture).
static double differing(const unsigned char* a, const unsigned char* b, int y0, const char* mask_png) {
    long n = 0;
    unsigned char* mask = mask_png ? calloc((size_t)W * H, 1) : NULL;
    for (long i = (long)y0 * W; i < (long)W * H; ++i) {
        int d = 0;
        for (int c = 0; c < 3; ++c) {
            const int x = abs((int)a[4 * i + c] - (int)b[4 * i + c]);
            if (x > d) d = x;
        }
        if (d > 40) ++n;
        if (mask) mask[i] = d > 40 ? 255 : 0;
    }
    if (mask) stbi_write_png(mask_png, W, H, 1, mask, W);
    free(mask);
    return (double)n / ((double)W * (H - y0));
}

static unsigned char* load_png(const char* path) {
    int w = 0, h = 0, n = 0;
    unsigned char* p = stbi_load(path, &w, &h, &n, 4);
    CHECK(p && w == W && h == H, "%s: %dx%d", path, w, h);
    if (p && (w != W || h != H)) {
        stbi_image_free(p);
        return NULL;
    }
    return p;
}

// A restarted server never had the drive's --set: after the link comes back
// the drive sends it again, in the window's link (an offscreen view, with a
// screenshot early on so it draws) and in the headless one. A real-time
// server is stopped once it has accepted the value, a new one starts on the
// same port, and the drive must say "reconnected" and have the value
// accepted a second time.
static void reconnect_resends_set(bool window) {
    const char* args[] = {"--mechanics", "ode", "--scenario", "sandbox_pick_place", NULL};
    const char* accept = window ? "accepted by the server: main_relief.p_crack = 2.2e+07"
                                : "the server accepted --set hydraulics.components.main_relief.p_crack=2.2e7";
    served a = {0}, b = {0};
    CHECK(serve_start(&a, "test_drive_connect_reconnect_a.log", args) == 0, "first server started");
    char cmd[1024], line[1024];
    snprintf(cmd, sizeof cmd,
             "%s/cranesim drive --connect 127.0.0.1:%d --scenario sandbox_pick_place --duration 8 %s "
             "--set hydraulics.components.main_relief.p_crack=2.2e7 2>&1",
             CRANESIM_BINARY_DIR, a.port,
             window ? "--size 320x180 --screenshot connect_reconnect.png --screenshot-at 0.2" : "--headless");
    FILE* p = popen(cmd, "r");
    int accepted = 0, reconnected = 0, restarted = 0;
    while (p && fgets(line, sizeof line, p)) {
        fputs(line, stdout);
        if (strstr(line, accept)) ++accepted;
        if (strstr(line, "reconnected")) ++reconnected;
        if (accepted == 1 && !restarted) {
            restarted = 1;
            CHECK(serve_stop(&a) == 0, "first server exits 0");
            CHECK(serve_start_on(&b, a.port, "test_drive_connect_reconnect_b.log", args) == 0,
                  "second server started on port %d", a.port);
        }
    }
    CHECK(p && pclose(p) == 0, "%s drive --connect across a server restart exits 0", window ? "window" : "headless");
    CHECK(restarted && reconnected == 1, "%s: the drive reconnected to the restarted server (%d)",
          window ? "window" : "headless", reconnected);
    CHECK(accepted == 2, "%s: --set accepted %d times: once per server expected", window ? "window" : "headless",
          accepted);
    if (restarted) CHECK(serve_stop(&b) == 0, "second server exits 0");
    else serve_stop(&a);
}

// A server whose hello names a backend this build does not have (a newer
// build's): the view refuses it by name, exit 2, instead of drawing it as
// another backend. The server here is a fake: a child process that answers
// the client's hello with a hello naming backend "mujoco" and waits for the
// client to hang up.
static void unknown_backend_refused(void) {
    const int lfd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK), .sin_port = 0};
    socklen_t sl = sizeof sa;
    CHECK(lfd >= 0 && bind(lfd, (struct sockaddr*)&sa, sizeof sa) == 0 && listen(lfd, 1) == 0 &&
              getsockname(lfd, (struct sockaddr*)&sa, &sl) == 0,
          "listen");
    const pid_t child = fork();
    if (child == 0) {
        alarm(60); // never outlives a broken test
        const int fd = accept(lfd, NULL, NULL);
        uint8_t b[4096];
        struct pollfd pf = {.fd = fd, .events = POLLIN};
        if (fd < 0 || poll(&pf, 1, 10000) <= 0 || recv(fd, b, sizeof b, 0) <= 0) _exit(3); // the client's hello
        static const char json[] = "{\"protocol\":2,\"model\":\"x\",\"model_file\":\"\",\"backend\":\"mujoco\","
                                   "\"world\":\"\",\"world_file\":\"\",\"channels\":[],\"bodies\":[]}";
        const proto_server_hello h = {.version = PROTO_VERSION, .role = 1, .lockstep = 1, .rate = 75,
                                      .json = json, .json_len = (uint32_t)strlen(json)};
        const size_t n = proto_put_server_hello(b, sizeof b, &h);
        if (!n || send_all(fd, b, n)) _exit(4);
        while (poll(&pf, 1, 10000) > 0 && recv(fd, b, sizeof b, 0) > 0) {} // until the client hangs up
        _exit(0);
    }
    close(lfd);
    char cmd[1024], line[1024], all[8192] = "";
    snprintf(cmd, sizeof cmd,
             "%s/cranesim drive --connect 127.0.0.1:%d --size 320x180 --screenshot connect_unknown.png 2>&1",
             CRANESIM_BINARY_DIR, ntohs(sa.sin_port));
    FILE* p = popen(cmd, "r");
    while (p && fgets(line, sizeof line, p)) {
        fputs(line, stdout);
        strncat(all, line, sizeof all - strlen(all) - 1);
    }
    const int st = p ? pclose(p) : -1;
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 2, "exit %d", WIFEXITED(st) ? WEXITSTATUS(st) : -1);
    CHECK(strstr(all, "server hello: backend: unknown backend 'mujoco' (known: lagrange, ode)") != NULL, "%s", all);
    int cst = 0;
    CHECK(child > 0 && waitpid(child, &cst, 0) == child && WIFEXITED(cst) && WEXITSTATUS(cst) == 0,
          "the fake server: %d", WIFEXITED(cst) ? WEXITSTATUS(cst) : -1);
}

static void hook_cb(void* user, engine* e, int attach, int got) { (void)user, (void)e, (void)attach, (void)got; }

int main(void) {
    const char* scen = "sandbox_pick_place";
    unknown_backend_refused();
    const char* args[] = {"--mechanics", "ode", "--scenario", scen, "--lockstep", NULL};
    served sv = {0};
    CHECK(serve_start(&sv, "test_drive_connect_serve.log", args) == 0, "server started");
    // The remote view, as a user runs it.
    char addr[64], cmd[1024];
    snprintf(addr, sizeof addr, "127.0.0.1:%d", sv.port);
    remove("connect_remote.png");
    snprintf(cmd, sizeof cmd,
             "%s/cranesim drive --connect %s --scenario %s --screenshot connect_remote.png --screenshot-at 4 "
             "--size %dx%d 2>&1",
             CRANESIM_BINARY_DIR, addr, scen, W, H);
    FILE* p = popen(cmd, "r");
    char line[1024];

    double t_remote = -1;
    while (p && fgets(line, sizeof line, p)) {
        fputs(line, stdout);
        const char* at = strstr(line, "screenshot -> connect_remote.png (remote t = ");
        if (at) t_remote = atof(at + strlen("screenshot -> connect_remote.png (remote t = "));
    }
    const int prc = p ? pclose(p) : -1;
    CHECK(prc == 0 && t_remote >= 4, "drive --connect exit %d, screenshot at remote t = %g s", prc, t_remote);
    // The drive's --set through the window's link (a second view of the
    // same server, later in its run: the picture is not compared).
    snprintf(cmd, sizeof cmd,
             "%s/cranesim drive --connect %s --scenario %s --screenshot connect_set.png --screenshot-at 4.5 "
             "--size 320x180 --set hydraulics.components.main_relief.p_crack=2.2e7 --charts lift_cyl.A.p,x1 "
             "--readouts lift_cyl.A.p 2>&1",
             CRANESIM_BINARY_DIR, addr, scen);
    FILE* p2 = popen(cmd, "r");
    bool set_ok = false;
    int unsent = 0; // the circuit channel's chart and readout said not sent, and nothing else
    while (p2 && fgets(line, sizeof line, p2))
        if (strstr(line, "accepted by the server: main_relief.p_crack = 2.2e+07")) set_ok = true;
        else if (strstr(line, "chart lift_cyl.A.p: not sent by the server")) ++unsent;
        else if (strstr(line, "readout lift_cyl.A.p: not sent by the server")) ++unsent;
        else if (strstr(line, "not sent by the server")) unsent = -100; // x1 is sent
    if (p2) pclose(p2);
    CHECK(set_ok, "drive --connect --set: no 'accepted by the server: main_relief.p_crack = 2.2e+07' line");
    CHECK(unsent == 2, "chart and readout lift_cyl.A.p should say 'not sent by the server', x1 not (%d)", unsent);
    CHECK(serve_stop(&sv) == 0, "server exits 0");
    reconnect_resends_set(true);
    reconnect_resends_set(false);

    // The same run locally, rendered by a drive session at t_remote and 1.5 s later.
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "sandbox";
    char sp[512];
    snprintf(sp, sizeof sp, "%s/scenarios/%s.json", CRANESIM_ASSETS, scen);
    c.scenario_path = sp;
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = true;
    o.width = W;
    o.height = H;
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    scenario sc;
    CHECK(scenario_load(sp, &sc, err, sizeof err) == 0, "%s", err);
    if (!s || t_remote < 0) {
        TEST_MAIN_END();
    }
    engine* l = drive_session_engine(s);
    render* r = drive_session_render_ctx(s);
    world_snapshot* snap = malloc(sizeof *snap);
    const double frame = 1.0 / 75; // the server's default rate
    int ev = 0;
    engine_snapshot(l, snap);
    render_charts_sample(r, snap);
    // What the remote view's status line says for a scripted operator.
    render_set_status(r, "  [scripted]");
    const long k_shot = lround(t_remote / frame);
    double d_same = 1, d_all = 1, d_later = 0;
    for (long k = 0; k < k_shot + 113; ++k) {
        const double tm = engine_time(l) + 0.5 * frame;
        double u[3];
        engine_play(l, &sc, tm, &ev, u, hook_cb, NULL);
        for (int j = 0; j < 3; ++j) u[j] = fmax(-1, fmin(1, u[j]));
        engine_set_commands(l, u);
        CHECK(engine_advance(l, (k + 1) * frame - engine_time(l)) == 0, "local step %ld", k);
        engine_snapshot(l, snap);
        render_charts_sample(r, snap);
        if (k + 1 == k_shot || k + 1 == k_shot + 113) {
            CHECK(fabs(engine_time(l) - t_remote) < 1e-3 || k + 1 != k_shot, "local t %g, remote %g",
                  engine_time(l), t_remote);
            drive_session_render(s);
            const char* png = k + 1 == k_shot ? "connect_local.png" : "connect_later.png";
            CHECK(drive_session_screenshot(s, png, err, sizeof err) == 0, "%s", err);
        }
    }
    unsigned char* a = load_png("connect_remote.png");
    unsigned char* b = load_png("connect_local.png");
    unsigned char* later = load_png("connect_later.png");
    if (a && b && later) {
        d_all = differing(a, b, 0, "connect_diff.png");
        d_same = differing(a, b, TOP, NULL);
        d_later = differing(a, later, TOP, NULL);
    }
    printf("pixels differing by > 40/255: remote vs local at t = %.3f s: %.3f %% of the picture, %.4f %% below "
           "the top line; vs local 1.5 s later: %.3f %% below it\n",
           t_remote, 100 * d_all, 100 * d_same, 100 * d_later);
    CHECK(d_all < 0.02, "the remote view differs from the local one in %.2f %% of the pixels", 100 * d_all);
    CHECK(d_same < 1e-3, "below the top line the remote view differs in %.4f %% of the pixels", 100 * d_same);
    CHECK(d_later > 0.02, "a later state must differ (%.2f %%)", 100 * d_later);
    stbi_image_free(a), stbi_image_free(b), stbi_image_free(later);
    free(snap);
    // The panel in remote mode.
    drive_session_set_remote(s);
    char msg[256], path[128] = "";
    double v = 0, local = 0;
    panel* pn = drive_session_panel(s);
    CHECK(panel_set(pn, "main_relief (relief)/p_crack", 10.0, msg, sizeof msg) == PANEL_OK, "%s", msg);
    drive_session_tick(s, 100.0);
    CHECK(drive_session_take_set(s, path, sizeof path, &v) == 1 && !strcmp(path, "main_relief.p_crack") &&
              fabs(v - 1e7) < 1e-3,
          "queued for the server: '%s' = %g", path, v);
    CHECK(hyd_model_get(engine_circuit(drive_session_engine(s)), "main_relief.p_crack", &local) == 0 &&
              fabs(local - 22e6) < 1,
          "the idle local circuit changed: %g Pa", local);
    const double mass0 = drive_session_model(s)->mech.link[1].mass;
    CHECK(panel_set(pn, "end_arm (link)/mass", 2.0 * mass0, msg, sizeof msg) == PANEL_OK, "%s", msg);
    drive_session_tick(s, 100.1);
    // The status line is composed when a tick draws (not while the renderer is busy).
    for (int k = 0; k < 40 && !strstr(drive_session_status_line(s), "not sent"); ++k) {
        drive_session_tick(s, 100.2 + 0.05 * k);
        usleep(20000);
    }
    CHECK(drive_session_take_set(s, path, sizeof path, &v) == 0, "a link mass was queued for the server: %s", path);
    CHECK(strstr(drive_session_status_line(s), "not sent"), "status: %s", drive_session_status_line(s));
    CHECK(drive_session_model(s)->mech.link[1].mass == mass0, "the local model's end arm mass changed");
    drive_session_destroy(s);
    TEST_MAIN_END();
}
