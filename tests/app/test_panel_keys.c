// test_panel_keys.c: Esc and the parameter panel, through the real input path
// of `cranesim drive` (SDL events into drive_session_tick, offscreen GL, the
// panel's ImGui window): Esc in the panel leaves the panel and never quits;
// quitting with panel changes not saved asks once and says which; Esc with
// nothing unsaved quits at once, as before. And the panel as drawn: its
// buttons inside its window, the load-moment bar uncovered, a value whose 0
// means "the fluid's" shown as the fluid's value.
#include "check.h"
#include "drive_session.h"
#include "panel.h"
#include "render.h"
#include "drive_test_util.h"

#include <SDL2/SDL.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static drive_session* open_session(void) {
    app_common c = {.sim = sim_default_opts()};
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

// One 240 Hz tick and a frame (the panel sees events at ticks and decides at
// frames); the tick's result: 1 when the operator quit.
static int tick_and_draw(drive_session* s, double* wall) {
    *wall += 1.0 / 240.0;
    const int rc = drive_session_tick(s, *wall);
    drive_session_render(s);
    return rc;
}

// n ticks (with frames); the first nonzero result, else 0.
static int ticks(drive_session* s, double* wall, int n) {
    int rc = 0;
    for (int i = 0; i < n && rc == 0; ++i) rc = tick_and_draw(s, wall);
    return rc;
}

// A key pressed on one tick and released on the next: the result of both.
static int tap(drive_session* s, double* wall, SDL_Scancode sc) {
    push_key(sc, 1);
    int rc = tick_and_draw(s, wall);
    push_key(sc, 0);
    if (rc == 0) rc = tick_and_draw(s, wall);
    return rc;
}

static void push_mouse(Uint32 type, int x, int y) {
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = type;
    if (type == SDL_MOUSEMOTION) {
        ev.motion.x = x, ev.motion.y = y;
        ev.motion.state = SDL_BUTTON_LMASK;
    } else {
        ev.button.button = SDL_BUTTON_LEFT;
        ev.button.state = type == SDL_MOUSEBUTTONDOWN ? SDL_PRESSED : SDL_RELEASED;
        ev.button.x = x, ev.button.y = y;
    }
    SDL_PushEvent(&ev);
}

// The panel shown, filtered to the end arm, its mass widget drawn; its rect.
static bool show_end_arm_mass(drive_session* s, double* wall, float rect[4]) {
    panel* pn = drive_session_panel(s);
    tap(s, wall, SDL_SCANCODE_TAB);
    panel_set_filter(pn, "end_arm");
    ticks(s, wall, 2);
    return panel_gui_item_rect(pn, panel_find(pn, "end_arm (link)/mass"), rect);
}

// Ticks until the renderer has drawn one more frame, a left button down
// event before each: SDL_PushEvent does not change SDL's own button state,
// which ImGui 1.86's backend polls, so a held button is a press event in
// front of every frame (ImGui counts no new click while it stays down).
static void frame_with_button_held(drive_session* s, double* wall, int x, int y) {
    const long f0 = drive_session_stats(s)->frames;
    for (int i = 0; i < 16 && drive_session_stats(s)->frames == f0; ++i) {
        render_wait(drive_session_render_ctx(s), 1.0); // the last frame done: the tick may draw the next
        push_mouse(SDL_MOUSEBUTTONDOWN, x, y);
        *wall += 1.0 / 240.0;
        drive_session_tick(s, *wall);
    }
}

// The mouse drags the widget at rect 40 px to the right, as a hand does:
// button down on it, held while it moves in steps of 5 px (a frame each),
// button up.
static void drag_right(drive_session* s, double* wall, const float rect[4]) {
    SDL_Window* win = render_window(drive_session_render_ctx(s));
    const int x = (int)(rect[0] + 0.5f * rect[2]), y = (int)(rect[1] + 0.5f * rect[3]);
    SDL_WarpMouseInWindow(win, x, y);
    push_mouse(SDL_MOUSEMOTION, x, y);
    tick_and_draw(s, wall);
    for (int dx = 0; dx <= 40; dx += 5) {
        SDL_WarpMouseInWindow(win, x + dx, y);
        push_mouse(SDL_MOUSEMOTION, x + dx, y);
        frame_with_button_held(s, wall, x + dx, y);
    }
    push_mouse(SDL_MOUSEBUTTONUP, x + 40, y);
    ticks(s, wall, 8);
}

static const char* status_now(drive_session* s, double* wall) {
    render_wait(drive_session_render_ctx(s), 1.0);
    ticks(s, wall, 2);
    return render_get_status(drive_session_render_ctx(s));
}

// A mouse drag on the end arm's mass, then Esc: the panel lets go of the
// keyboard and the drive goes on (it quit at once, and the edit was lost
// with it). Esc again: the status line says what is not saved and how to
// keep it, and nothing quits; a third Esc within the time quits.
static void test_esc_after_an_edit_leaves_the_panel(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    float rect[4];
    CHECK(show_end_arm_mass(s, &wall, rect), "end arm mass widget drawn");
    const double m0 = drive_session_model(s)->mech.link[1].mass;
    drag_right(s, &wall, rect);
    const double m1 = drive_session_model(s)->mech.link[1].mass;
    CHECK(m1 > m0, "a 40 px drag: end arm mass %g -> %g kg", m0, m1);
    CHECK(tap(s, &wall, SDL_SCANCODE_ESCAPE) == 0, "Esc in the panel after an edit quit the drive");
    CHECK(ticks(s, &wall, 4) == 0, "the drive quit after Esc in the panel");
    CHECK(drive_session_model(s)->mech.link[1].mass == m1, "the edit is gone: %g kg",
          drive_session_model(s)->mech.link[1].mass);
    CHECK(!panel_gui_has_focus(drive_session_panel(s)), "after Esc the panel still has the focus");
    // Out of the panel, Esc asks first: the change is not saved.
    CHECK(tap(s, &wall, SDL_SCANCODE_ESCAPE) == 0, "Esc with an unsaved panel change quit without a word");
    const char* st = status_now(s, &wall);
    CHECK(strstr(st, "1 panel change not saved") && strstr(st, "end_arm") && strstr(st, "Esc again") &&
              strstr(st, "save model"),
          "status after Esc with an unsaved change: '%s'", st);
    CHECK(tap(s, &wall, SDL_SCANCODE_ESCAPE) == 1, "a second Esc did not quit");
    drive_session_destroy(s);
}

// Typing a value (Ctrl+click, digits) and Esc: the typed value is dropped
// (ImGui's Esc), the keyboard goes back to the crane, the drive goes on;
// nothing changed, so the next Esc quits at once.
static void test_esc_while_typing_cancels_the_value(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    float rect[4];
    CHECK(show_end_arm_mass(s, &wall, rect), "end arm mass widget drawn");
    const double m0 = drive_session_model(s)->mech.link[1].mass;
    const int x = (int)(rect[0] + 0.5f * rect[2]), y = (int)(rect[1] + 0.5f * rect[3]);
    SDL_WarpMouseInWindow(render_window(drive_session_render_ctx(s)), x, y);
    tick_and_draw(s, &wall);
    SDL_SetModState(KMOD_LCTRL);
    push_key(SDL_SCANCODE_LCTRL, 1);
    push_mouse(SDL_MOUSEBUTTONDOWN, x, y);
    tick_and_draw(s, &wall);
    push_mouse(SDL_MOUSEBUTTONUP, x, y);
    SDL_SetModState(KMOD_NONE);
    push_key(SDL_SCANCODE_LCTRL, 0);
    tick_and_draw(s, &wall);
    panel* pn = drive_session_panel(s);
    CHECK(panel_gui_wants_keyboard(pn), "Ctrl+click: the panel has the keyboard");
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = SDL_TEXTINPUT;
    snprintf(ev.text.text, sizeof ev.text.text, "%s", "150");
    SDL_PushEvent(&ev);
    tick_and_draw(s, &wall);
    CHECK(tap(s, &wall, SDL_SCANCODE_ESCAPE) == 0, "Esc while typing quit the drive");
    CHECK(ticks(s, &wall, 4) == 0, "the drive quit after Esc while typing");
    CHECK(!panel_gui_wants_keyboard(pn) && !panel_gui_has_focus(pn), "after Esc the panel keeps the keyboard");
    CHECK(drive_session_model(s)->mech.link[1].mass == m0, "Esc applied the typed value: %g kg",
          drive_session_model(s)->mech.link[1].mass);
    CHECK(tap(s, &wall, SDL_SCANCODE_ESCAPE) == 1, "Esc out of the panel, nothing unsaved, did not quit");
    drive_session_destroy(s);
}

// "save model" keeps the changes: after it, Esc quits at once.
static void test_saved_changes_quit_at_once(void) {
    char dir[] = "/tmp/cranesim_esc_XXXXXX", cwd[1024];
    CHECK(mkdtemp(dir) != NULL && getcwd(cwd, sizeof cwd) != NULL && chdir(dir) == 0, "temp dir");
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    float rect[4];
    CHECK(show_end_arm_mass(s, &wall, rect), "end arm mass widget drawn");
    drag_right(s, &wall, rect);
    CHECK(tap(s, &wall, SDL_SCANCODE_ESCAPE) == 0, "Esc in the panel quit the drive");
    CHECK(panel_run_action(drive_session_panel(s), "save model"), "save action");
    ticks(s, &wall, 2);
    CHECK(tap(s, &wall, SDL_SCANCODE_ESCAPE) == 1, "Esc after save model did not quit");
    drive_session_destroy(s);
    remove("cranesim_model_1.json");
    CHECK(chdir(cwd) == 0 && rmdir(dir) == 0, "clean up %s", dir);
}

static bool inside(const float in[4], const float out[4]) {
    return in[0] >= out[0] && in[1] >= out[1] && in[0] + in[2] <= out[0] + out[2] && in[1] + in[3] <= out[1] + out[3];
}

static bool apart(const float a[4], const float b[4]) {
    return a[0] + a[2] <= b[0] || b[0] + b[2] <= a[0] || a[1] + a[3] <= b[1] || b[1] + b[3] <= a[1];
}

// At 1280 x 720 the panel's four buttons sat in one row and "load model" was
// cut off at the window's edge; the window reached down over the load-moment
// bar. Each button now lies inside the window, and the window clear of the bar.
static void test_panel_layout(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    tap(s, &wall, SDL_SCANCODE_TAB);
    ticks(s, &wall, 3);
    render_wait(drive_session_render_ctx(s), 1.0);
    ticks(s, &wall, 2);
    panel* pn = drive_session_panel(s);
    float win[4], bar[4], b[4];
    CHECK(panel_gui_window_rect(pn, win), "the panel's window not drawn");
    CHECK(panel_action_count(pn) == 4, "%d actions", panel_action_count(pn));
    for (int a = 0; a < panel_action_count(pn); ++a) {
        CHECK(panel_gui_action_rect(pn, a, b), "button %s not drawn", panel_action_label(pn, a));
        CHECK(inside(b, win), "button '%s' at x %.0f..%.0f, y %.0f..%.0f outside the window x %.0f..%.0f, y %.0f..%.0f",
              panel_action_label(pn, a), b[0], b[0] + b[2], b[1], b[1] + b[3], win[0], win[0] + win[2], win[1],
              win[1] + win[3]);
    }
    CHECK(render_hud_rcl_rect(drive_session_render_ctx(s), bar), "no load-moment bar drawn");
    CHECK(apart(win, bar), "the panel (y %.0f..%.0f) covers the load-moment bar (y %.0f..%.0f)", win[1],
          win[1] + win[3], bar[1], bar[1] + bar[3]);
    drive_session_destroy(s);
}

// The pump line volume's bulk_modulus is 0 in the model: "the fluid's". The
// panel showed "0 MPa" (and a drag from 0 went nowhere); it shows the fluid's
// 1200 MPa, noted "fluid's", and the model keeps its 0. Set, it is the
// volume's own (no note, saved); set to 0 it follows the fluid again; while
// it follows, a change of the fluid's moves it.
static void test_fluid_default_shown(void) {
    char dir[] = "/tmp/cranesim_fluid_XXXXXX", cwd[1024];
    CHECK(mkdtemp(dir) != NULL && getcwd(cwd, sizeof cwd) != NULL && chdir(dir) == 0, "temp dir");
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    panel* pn = drive_session_panel(s);
    const int id = panel_find(pn, "pump_line (volume)/bulk_modulus");
    const int fid = panel_find(pn, "fluid/bulk_modulus");
    CHECK(id >= 0 && fid >= 0, "entries %d %d", id, fid);
    if (id < 0 || fid < 0) return;
    CHECK(panel_get(pn, id) == 1200 && panel_get(pn, fid) == 1200 && !strcmp(panel_note(pn, id), "fluid's"),
          "pump_line bulk_modulus %g %s (%s), fluid's %g", panel_get(pn, id), panel_unit(pn, id), panel_note(pn, id),
          panel_get(pn, fid));
    char msg[256];
    // The fluid's value moves a volume that follows it.
    CHECK(panel_set(pn, "fluid/bulk_modulus", 1500, msg, sizeof msg) == PANEL_OK, "%s", msg);
    ticks(s, &wall, 2);
    CHECK(panel_get(pn, id) == 1500 && !strcmp(panel_note(pn, id), "fluid's"), "after the fluid's 1500: %g (%s)",
          panel_get(pn, id), panel_note(pn, id));
    // Saved while it follows: the file keeps 0 (the fluid's), with the fluid's new value.
    char err[512];
    CHECK(panel_run_action(pn, "save model"), "save action");
    ticks(s, &wall, 2);
    model* m = model_load("cranesim_model_1.json", NULL, 0, err, sizeof err);
    double v = -1, fv = -1;
    CHECK(m && hyd_model_get(m->hyd, "pump_line.bulk_modulus", &v) == 0 && v == 0 &&
              hyd_model_get(m->hyd, "fluid.bulk_modulus", &fv) == 0 && fv == 1.5e9,
          "saved while following: pump_line %g Pa, fluid %g Pa (%s)", v, fv, m ? "" : err);
    model_free(m);
    CHECK(panel_set(pn, "pump_line (volume)/bulk_modulus", 900, msg, sizeof msg) == PANEL_OK, "%s", msg);
    ticks(s, &wall, 2);
    v = -1;
    CHECK(hyd_model_get(engine_circuit(drive_session_engine(s)), "pump_line.bulk_modulus", &v) == 0 && v == 9e8,
          "engine pump_line bulk_modulus %g Pa", v);
    CHECK(!strcmp(panel_note(pn, id), ""), "set to 900 MPa it still says '%s'", panel_note(pn, id));
    CHECK(panel_run_action(pn, "save model"), "save action");
    ticks(s, &wall, 2);
    m = model_load("cranesim_model_2.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "saved model: %s", err);
    v = -1;
    CHECK(m && hyd_model_get(m->hyd, "pump_line.bulk_modulus", &v) == 0 && v == 9e8, "saved bulk_modulus %g Pa", v);
    model_free(m);
    // Back to 0: the fluid's again.
    CHECK(panel_set(pn, "pump_line (volume)/bulk_modulus", 0, msg, sizeof msg) == PANEL_OK, "%s", msg);
    ticks(s, &wall, 2);
    CHECK(panel_get(pn, id) == 1500 && !strcmp(panel_note(pn, id), "fluid's"), "set to 0: %g (%s)", panel_get(pn, id),
          panel_note(pn, id));
    CHECK(hyd_model_get(engine_circuit(drive_session_engine(s)), "pump_line.bulk_modulus", &v) == 0 && v == 0,
          "engine pump_line bulk_modulus %g Pa after 0", v);
    drive_session_destroy(s);
    remove("cranesim_model_1.json");
    remove("cranesim_model_2.json");
    CHECK(chdir(cwd) == 0 && rmdir(dir) == 0, "clean up %s", dir);
}

int main(int argc, char** argv) {
    setenv("SDL_VIDEODRIVER", "offscreen", 0);
    setenv("EGL_PLATFORM", "surfaceless", 0);
    setenv("SDL_AUDIODRIVER", "dummy", 0);
    RUN_TEST(test_esc_after_an_edit_leaves_the_panel);
    RUN_TEST(test_esc_while_typing_cancels_the_value);
    RUN_TEST(test_saved_changes_quit_at_once);
    RUN_TEST(test_panel_layout);
    RUN_TEST(test_fluid_default_shown);
    SDL_Quit();
    TEST_MAIN_END();
}
