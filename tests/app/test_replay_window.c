// test_replay_window.c: a session recorded by the drive window (offscreen GL,
// an SDL virtual joystick, the keyboard, a virtual clock) replays bit for bit:
// `cranesim replay` writes the window's record byte for byte, and
// `drive --replay` in the window records it again byte for byte. The same for
// a crane chain of six functions (chain_6fn_controls.json) driven by function
// on the pad (its session carries one command per function).
#include "app.h"
#include "check.h"
#include "drive_session.h"
#include "render.h"
#include "drive_test_util.h"

#include <SDL2/SDL.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char a[1 << 23], b[1 << 23];

static long read_file(const char* path, char* buf, size_t n) {
    FILE* f = fopen(path, "rb");
    if (!f) return -1;
    size_t got = fread(buf, 1, n - 1, f);
    buf[got] = 0;
    fclose(f);
    return (long)got;
}

#define MODEL6 CRANESIM_ASSETS "/../tests/world/data/chain_6fn_controls.json"

static const char* g_model; // NULL: the default crane

static drive_session* open_window(const char* record, const char* session_path, const char* replay) {
    app_common c = {.sim = sim_default_opts()};
    c.model_path = g_model;
    c.sim.mechanics = SIM_ODE; // the sandbox: truck, slew, hook, loads
    c.sim.world = "sandbox";
    c.scenario_path = CRANESIM_ASSETS "/scenarios/sandbox_pick_place.json"; // the start pose
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.width = 320;
    o.height = 240;
    o.record_path = record;
    o.session_path = session_path;
    o.replay_path = replay;
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "window: %s", err);
    return s;
}

// The hook key pressed and released, `after` s more of driving, then the
// record and the session closed (both recordings end this way).
static void hook_and_finish(drive_session* s, double* wall, double after) {
    push_key(SDL_SCANCODE_H, 1);
    run_for(s, wall, 0.05);
    push_key(SDL_SCANCODE_H, 0);
    CHECK(run_for(s, wall, after) == 0, "loop: %s", drive_session_error(s));
    long rows = 0;
    char err[400];
    CHECK(drive_session_finish_record(s, &rows, err, sizeof err) == 0 && rows > 100, "record: %ld rows %s", rows, err);
    drive_session_destroy(s); // closes the session file
}

static void record_in_the_window(void) {
    drive_session* s = open_window("rw_rec.csv", "rw.session", NULL);
    if (!s) return;
    double wall = 0;
    int idx = attach_pad("cranesim replay stick");
    CHECK(idx >= 0, "attach virtual joystick: %s", SDL_GetError());
    SDL_Joystick* js = SDL_JoystickOpen(idx);
    run_for(s, &wall, 0.2);
    // Lift up and slew on the stick, then the jib and the hook on the keyboard.
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, -32767);
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTX, 20000);
    CHECK(run_for(s, &wall, 0.8) == 0, "loop: %s", drive_session_error(s));
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, 0);
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTX, 0);
    SDL_JoystickClose(js);
    SDL_JoystickDetachVirtual(idx);
    push_key(SDL_SCANCODE_W, 1);
    run_for(s, &wall, 0.5);
    push_key(SDL_SCANCODE_W, 0);
    hook_and_finish(s, &wall, 0.4);
}

// The chain: the pad's sticks and d-pad (the six-function model's controls:
// lift, jib, slew, ext, ext2 among them) moved in turn, so the session's
// commands vary on several functions, then the hook key.
static void record_chain_in_the_window(void) {
    drive_session* s = open_window("rw_rec.csv", "rw.session", NULL);
    if (!s) return;
    double wall = 0;
    int idx = attach_pad("cranesim replay stick");
    CHECK(idx >= 0, "attach virtual joystick: %s", SDL_GetError());
    SDL_Joystick* js = SDL_JoystickOpen(idx);
    run_for(s, &wall, 0.2);
    static const int axes[] = {SDL_CONTROLLER_AXIS_LEFTY, SDL_CONTROLLER_AXIS_RIGHTY, SDL_CONTROLLER_AXIS_LEFTX,
                               SDL_CONTROLLER_AXIS_RIGHTX, SDL_CONTROLLER_AXIS_TRIGGERRIGHT};
    for (size_t k = 0; k < sizeof axes / sizeof axes[0]; ++k) {
        SDL_JoystickSetVirtualAxis(js, axes[k], k & 1 ? 24000 : -28000);
        CHECK(run_for(s, &wall, 0.3) == 0, "loop: %s", drive_session_error(s));
        SDL_JoystickSetVirtualAxis(js, axes[k], 0);
    }
    SDL_JoystickSetVirtualButton(js, SDL_CONTROLLER_BUTTON_DPAD_UP, 1);
    CHECK(run_for(s, &wall, 0.3) == 0, "loop: %s", drive_session_error(s));
    SDL_JoystickSetVirtualButton(js, SDL_CONTROLLER_BUTTON_DPAD_UP, 0);
    SDL_JoystickClose(js);
    SDL_JoystickDetachVirtual(idx);
    hook_and_finish(s, &wall, 0.3);
    // The session names the functions (ext2 among them).
    long n = read_file("rw.session", a, sizeof a);
    CHECK(n > 0 && strstr(a, "\"functions\":[") && strstr(a, "\"ext2\""), "session header: %.300s", a);
}

static void replay_headless(void) {
    unlink("rw_rep.csv");
    char* argv[] = {"rw.session", "--quiet", "--out", "rw_rep.csv", NULL};
    CHECK(cmd_replay(4, argv) == 0, "replay failed");
    long na = read_file("rw_rec.csv", a, sizeof a), nb = read_file("rw_rep.csv", b, sizeof b);
    CHECK(na > 1000 && na == nb && !memcmp(a, b, (size_t)na), "window record %ld bytes, headless replay %ld: differ",
          na, nb);
}

static void replay_in_the_window(void) {
    unlink("rw_rep2.csv");
    drive_session* s = open_window("rw_rep2.csv", NULL, "rw.session");
    if (!s) return;
    double wall = 0;
    int rc = 0;
    // A replay ends the window when its ticks are done (rc 1); 10 s at most.
    for (int i = 0; i < 2400 && rc == 0; ++i) {
        wall += 1.0 / 240.0;
        rc = drive_session_tick(s, wall);
    }
    CHECK(rc == 1, "the replay did not end the window (rc %d): %s", rc, drive_session_error(s));
    // The status line names the session that drives (it said "[scripted]"
    // in `drive --replay`, "[keyboard]" here).
    const char* st = render_get_status(drive_session_render_ctx(s));
    CHECK(strstr(st, "[replay of rw.session]") && !strstr(st, "[scripted]") && !strstr(st, "[keyboard]"),
          "status while replaying: '%s'", st);
    long rows = 0;
    char err[400];
    CHECK(drive_session_finish_record(s, &rows, err, sizeof err) == 0, "record: %s", err);
    drive_session_destroy(s);
    long na = read_file("rw_rec.csv", a, sizeof a), nb = read_file("rw_rep2.csv", b, sizeof b);
    CHECK(na > 1000 && na == nb && !memcmp(a, b, (size_t)na), "window record %ld bytes, window replay %ld: differ",
          na, nb);
}

int main(void) {
    // Headless: SDL's offscreen video driver on Mesa's EGL (llvmpipe).
    setenv("SDL_VIDEODRIVER", "offscreen", 0);
    setenv("EGL_PLATFORM", "surfaceless", 0);
    setenv("SDL_AUDIODRIVER", "dummy", 0);
    app_name_params();
    record_in_the_window();
    replay_headless();
    replay_in_the_window();
    g_model = MODEL6;
    record_chain_in_the_window();
    replay_headless();
    replay_in_the_window();
    TEST_MAIN_END();
}
