// test_drive.c: the interactive simulator end to end, headless (offscreen GL
// on Mesa llvmpipe, SDL virtual joystick, a virtual clock): the real loop of
// `cranesim drive` with the real world, renderer, input path and panel.
#include "check.h"
#include "drive_session.h"
#include "input.h"
#include "panel.h"
#include "render.h"

#include <SDL2/SDL.h>
#include <stdlib.h>
#include <string.h>

// sets: model overrides (--set path=value), nset of them.
static drive_session* open_session_with(const char* const* sets, int nset) {
    app_common c = {.sim = sim_default_opts()};
    for (int i = 0; i < nset; ++i) c.sets[c.nset++] = sets[i];
    c.sim.mechanics = SIM_ODE; // the default sandbox
    c.scenario_path = CRANESIM_ASSETS "/scenarios/sandbox_pick_place.json"; // initial pose only
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.width = 1280;
    o.height = 720;
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    return s;
}

static drive_session* open_session(void) { return open_session_with(NULL, 0); }

// Run the loop for `seconds` of virtual wall time at 240 ticks per second.
static int run_for(drive_session* s, double* wall, double seconds) {
    int rc = 0;
    for (double end = *wall + seconds; *wall < end && rc == 0;) {
        *wall += 1.0 / 240.0;
        rc = drive_session_tick(s, *wall);
    }
    return rc;
}

static double lift_stroke(drive_session* s) {
    double row[SIM_NCOL];
    drive_session_row(s, row);
    return row[COL_X1];
}

static void push_key(SDL_Scancode sc, int down) {
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = down ? SDL_KEYDOWN : SDL_KEYUP;
    ev.key.state = down ? SDL_PRESSED : SDL_RELEASED;
    ev.key.keysym.scancode = sc;
    ev.key.keysym.sym = SDL_GetKeyFromScancode(sc);
    SDL_PushEvent(&ev);
}

// Count bar pixels that are not the empty-bar colour.
static int bar_fill(drive_session* s, int cyl, int chamber) {
    render* r = drive_session_render_ctx(s);
    int rect[4], w, h;
    if (!render_hud_bar_rect(r, cyl, chamber, rect)) return -1;
    render_size(r, &w, &h);
    unsigned char* px = malloc((size_t)w * h * 4);
    render_read_pixels(r, px, w, h);
    int n = 0;
    for (int y = rect[1]; y < rect[1] + rect[3]; ++y)
        for (int x = rect[0]; x < rect[0] + rect[2]; ++x) {
            const unsigned char* p = px + ((size_t)y * w + x) * 4;
            int rgb = (p[0] << 16) | (p[1] << 8) | p[2];
            n += rgb != RENDER_BAR_EMPTY_RGB;
        }
    free(px);
    return n;
}

// The default scene renders: not blank, crane-coloured pixels where the
// crane's lifting arm projects.
static void test_default_scene_frame(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    CHECK(run_for(s, &wall, 0.5) == 0, "loop failed: %s", drive_session_error(s));
    drive_session_render(s);
    render* r = drive_session_render_ctx(s);
    int w, h;
    render_size(r, &w, &h);
    unsigned char* px = malloc((size_t)w * h * 4);
    CHECK(render_read_pixels(r, px, w, h) == 0, "read pixels");
    double mean = 0, var = 0;
    for (int i = 0; i < w * h; ++i) mean += px[4 * i + 1];
    mean /= w * h;
    for (int i = 0; i < w * h; ++i) var += (px[4 * i + 1] - mean) * (px[4 * i + 1] - mean);
    var /= w * h;
    CHECK(var > 100, "frame looks blank: green variance %.1f", var);
    // Find the lifting arm in the snapshot and look at its projected centre.
    world_snapshot* snap = calloc(1, sizeof *snap);
    live_snapshot(drive_session_live(s), snap);
    int found = 0;
    for (int b = 0; b < snap->nbody; ++b) {
        if (snap->body[b].role != WORLD_ROLE_BOOM1) continue;
        found = 1;
        double pt[2];
        CHECK(render_project(r, snap->body[b].pos, pt), "boom behind the camera");
        int x = (int)pt[0], y = (int)pt[1];
        CHECK(x >= 0 && x < w && y >= 0 && y < h, "boom projects off screen (%d, %d)", x, y);
        if (x >= 0 && x < w && y >= 0 && y < h) {
            // The booms are painted orange: red-dominant hue, bright in the
            // sun, dark in their own shadow. Terrain is green-grey, sky blue.
            // Search a few pixels around the centre for that hue.
            int hit = 0;
            for (int dy = -3; dy <= 3; ++dy)
                for (int dx = -3; dx <= 3; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    const unsigned char* p = px + ((size_t)yy * w + xx) * 4;
                    hit |= p[0] >= 30 && p[0] > 1.8 * p[1] && p[0] > 2.5 * p[2];
                }
            CHECK(hit, "no boom-coloured pixel at (%d, %d)", x, y);
        }
    }
    CHECK(found, "no lifting arm in the snapshot");
    CHECK(drive_session_screenshot(s, "drive_default_scene.png") == 0, "screenshot");
    free(snap);
    free(px);
    drive_session_destroy(s);
}

// A virtual joystick on the lift axis extends the lift cylinder through the
// real input path (mapping, dead zone, expo) and the real world; the lift's
// pressure bar changes height as the chamber pressure changes. Then the
// keyboard does the same after the stick is unplugged.
static void test_joystick_and_keyboard_drive_the_lift(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.5);
    drive_session_render(s);
    int bar0 = bar_fill(s, 0, 0);
    double x0 = lift_stroke(s);

    SDL_VirtualJoystickDesc d;
    memset(&d, 0, sizeof d);
    d.version = SDL_VIRTUAL_JOYSTICK_DESC_VERSION;
    d.type = SDL_JOYSTICK_TYPE_GAMECONTROLLER;
    d.naxes = 6;
    d.nbuttons = 15;
    d.name = "cranesim test stick";
    int idx = SDL_JoystickAttachVirtualEx(&d);
    CHECK(idx >= 0, "attach virtual joystick: %s", SDL_GetError());
    SDL_Joystick* js = SDL_JoystickOpen(idx);
    run_for(s, &wall, 0.2); // hot-plug event reaches the input layer
    CHECK(input_device_name(drive_session_input(s)) != NULL, "virtual joystick not opened on hot-plug");
    CHECK(input_active_source(drive_session_input(s)) == INPUT_SRC_CONTROLLER, "not a game controller");
    // Stick pulled back (negative y in SDL's convention) = lift up.
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, -32767);
    CHECK(run_for(s, &wall, 2.0) == 0, "loop: %s", drive_session_error(s));
    double x1 = lift_stroke(s);
    CHECK(x1 > x0 + 0.02, "joystick lift: stroke %.4f -> %.4f m", x0, x1);
    drive_session_render(s);
    int bar1 = bar_fill(s, 0, 0);
    CHECK(bar0 >= 0 && bar1 >= 0 && bar1 != bar0, "lift A pressure bar did not change (%d -> %d px)", bar0, bar1);
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, 0);
    SDL_JoystickClose(js);
    SDL_JoystickDetachVirtual(idx);
    run_for(s, &wall, 0.5); // unplugged: back to the keyboard

    double x2 = lift_stroke(s);
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 2.0);
    push_key(SDL_SCANCODE_UP, 0);
    run_for(s, &wall, 0.2);
    double x3 = lift_stroke(s);
    CHECK(x3 > x2 + 0.02, "keyboard lift: stroke %.4f -> %.4f m", x2, x3);
    const drive_stats* st = drive_session_stats(s);
    CHECK(st->input_samples / st->wall_time >= 75, "valve commands at %.0f Hz < 75 Hz",
          st->input_samples / st->wall_time);
    drive_session_destroy(s);
}

// A parameter changed through the panel's C API acts on the next step: the
// pump's pressure setting, seen in the pump-line pressure.
static void test_panel_change_takes_effect(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.3);
    double row[SIM_NCOL];
    drive_session_row(s, row);
    CHECK(row[COL_P_PUMP] > 19e6, "pump line starts at %.2f MPa", row[COL_P_PUMP] * 1e-6);
    char msg[256];
    CHECK(panel_set(drive_session_panel(s), "supply/pump pressure", 12.0, msg, sizeof msg) == PANEL_OK, "%s", msg);
    // The next tick applies it. The pump then stops delivering above its new
    // setting; open a valve so the pump line drains down to it.
    run_for(s, &wall, 1.0 / 240.0);
    double v;
    CHECK(hyd_model_get(live_circuit(drive_session_live(s)), "pump.p_set", &v) == 0 && fabs(v - 12e6) < 1,
          "circuit p_set = %g", v);
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 1.5);
    push_key(SDL_SCANCODE_UP, 0);
    drive_session_row(s, row);
    CHECK(row[COL_P_PUMP] < 13.0e6, "pump line %.2f MPa after lowering the setting to 12 MPa",
          row[COL_P_PUMP] * 1e-6);
    // Out of range is refused with a message, and nothing changes.
    CHECK(panel_set(drive_session_panel(s), "supply/pump pressure", 99.0, msg, sizeof msg) == PANEL_OUT_OF_RANGE,
          "out of range accepted");
    CHECK(strstr(msg, "pump pressure") != NULL, "message: %s", msg);
    drive_session_destroy(s);
}

// A boom's mass or length edited in the panel rescales that boom's own
// inertia (and centre of mass) and leaves the other boom as the model file
// gave it; the model's JSON follows, so "save model" saves what is driven.
static void test_panel_boom_edit(void) {
    // Booms that are not uniform beams, so a recomputed m L^2 / 12 or L / 2
    // would show.
    static const char* const sets[] = {"mechanics.links[1].inertia=50", "mechanics.links[0].com=1.0"};
    drive_session* s = open_session_with(sets, 2);
    if (!s) return;
    const model* m = drive_session_model(s);
    const crane_link l0 = m->mech.link[0], l1 = m->mech.link[1];
    char msg[256];
    CHECK(panel_set(drive_session_panel(s), "booms/end arm mass", 2.0 * l1.mass, msg, sizeof msg) == PANEL_OK, "%s",
          msg);
    CHECK(panel_set(drive_session_panel(s), "booms/lifting arm length", 1.1 * l0.length, msg, sizeof msg) == PANEL_OK,
          "%s", msg);
    double wall = 0;
    run_for(s, &wall, 2.0 / 240.0); // the ticks apply the changes
    const crane_link n0 = m->mech.link[0], n1 = m->mech.link[1];
    CHECK(fabs(n1.inertia - 2.0 * l1.inertia) < 1e-9 * l1.inertia && n1.com == l1.com && n1.length == l1.length,
          "end arm: inertia %g -> %g kg m^2, com %g -> %g m", l1.inertia, n1.inertia, l1.com, n1.com);
    CHECK(fabs(n0.com - 1.1 * l0.com) < 1e-12 && fabs(n0.inertia - 1.21 * l0.inertia) < 1e-9 * l0.inertia &&
              n0.mass == l0.mass,
          "lifting arm: com %g -> %g m, inertia %g -> %g kg m^2", l0.com, n0.com, l0.inertia, n0.inertia);
    double jv = 0.0;
    const cJSON* links = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m->json, "mechanics"), "links");
    const cJSON* inertia1 = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(links, 1), "inertia");
    if (inertia1) jv = inertia1->valuedouble;
    CHECK(fabs(jv - n1.inertia) < 1e-6 * n1.inertia, "model JSON end-arm inertia %g vs %g", jv, n1.inertia);
    drive_session_destroy(s);
}

int main(int argc, char** argv) {
    // Headless: SDL's offscreen video driver on Mesa's EGL (llvmpipe).
    setenv("SDL_VIDEODRIVER", "offscreen", 0);
    setenv("EGL_PLATFORM", "surfaceless", 0);
    setenv("SDL_AUDIODRIVER", "dummy", 0);
    RUN_TEST(test_default_scene_frame);
    RUN_TEST(test_joystick_and_keyboard_drive_the_lift);
    RUN_TEST(test_panel_change_takes_effect);
    RUN_TEST(test_panel_boom_edit);
    SDL_Quit();
    TEST_MAIN_END();
}
