// test_drive_functions.c: the input mapping by function through the real
// loop of `cranesim drive` (offscreen GL, SDL's virtual game controller, a
// virtual clock): each function's own input moves that function's command
// in the engine and no other; the HUD's mapping box shows the model's
// mapping, for the first DRIVE_MAPPING_S of the drive and on M.
#include "check.h"
#include "drive_session.h"
#include "input.h"
#include "render.h"
#include "drive_test_util.h"

#include <SDL2/SDL.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MODEL6 CRANESIM_ASSETS "/../tests/world/data/chain_6fn_controls.json"

static drive_session* open_with(const char* model, const char* mapping, char* err, size_t errsz,
                                int* code) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "sandbox"; // as cmd_drive names the drive's world
    c.model_path = model;
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.width = 960;
    o.height = 540;
    o.mapping_file = mapping;
    return drive_session_create(&c, &o, err, errsz, code);
}

// One function's controller input at full + deflection (on) or at rest.
static void set_input(SDL_Joystick* js, const input_axis_map* a, bool on) {
    if (a->controller_axis >= 0) {
        SDL_JoystickSetVirtualAxis(js, a->controller_axis, !on ? 0 : a->invert ? -32768 : 32767);
        return;
    }
    const int c = a->controller_pair[0];
    if (c >= INPUT_PAIR_BUTTON)
        SDL_JoystickSetVirtualButton(js, c - INPUT_PAIR_BUTTON, on ? 1 : 0);
    else // a trigger's rest is the axis' bottom on SDL's virtual controller
        SDL_JoystickSetVirtualAxis(js, c, on ? 32767 : -32768);
}

// Through the session: each of the engine's functions in turn on its mapped
// controller input; the engine's command of exactly that function goes to
// +1 (full deflection through dead zone and expo), the others stay 0.
static void drive_each_function(drive_session* s, double* wall, int nwant) {
    engine* e = drive_session_engine(s);
    const input_mapping* m = input_get_mapping(drive_session_input(s));
    const int n = engine_nfunction(e);
    CHECK(n == nwant && m->naxis == n, "%d functions (mapping %d), want %d", n, m->naxis, nwant);
    for (int k = 0; k < n; ++k)
        CHECK(!strcmp(m->axis[k].name, engine_function_name(e, k)), "mapping %d is %s, engine's %s",
              k, m->axis[k].name, engine_function_name(e, k));
    const int idx = attach_pad("cranesim function pad");
    CHECK(idx >= 0, "attach: %s", SDL_GetError());
    if (idx < 0) return;
    SDL_Joystick* js = SDL_JoystickOpen(idx);
    for (int k = 0; k < n; ++k)
        set_input(js, &m->axis[k], false);
    CHECK(run_for(s, wall, 0.1) == 0, "loop: %s", drive_session_error(s));
    CHECK(input_active_source(drive_session_input(s)) == INPUT_SRC_CONTROLLER,
          "the pad is a game controller");
    for (int j = 0; j < n; ++j)
        CHECK_NEAR(engine_function_command(e, j), 0.0, 0);
    for (int k = 0; k < n; ++k) {
        set_input(js, &m->axis[k], true);
        CHECK(run_for(s, wall, 0.05) == 0, "loop: %s", drive_session_error(s));
        for (int j = 0; j < n; ++j)
            CHECK(fabs(engine_function_command(e, j) - (j == k ? 1.0 : 0.0)) < 1e-4,
                  "%s on: %s = %g", m->axis[k].name, engine_function_name(e, j),
                  engine_function_command(e, j));
        set_input(js, &m->axis[k], false);
        CHECK(run_for(s, wall, 0.05) == 0, "loop: %s", drive_session_error(s));
        for (int j = 0; j < n; ++j)
            CHECK_NEAR(engine_function_command(e, j), 0.0, 0);
    }
    SDL_JoystickClose(js);
    SDL_JoystickDetachVirtual(idx);
    run_for(s, wall, 0.05);
}

// Pixels inside rect (x, y, w, h from the top) that differ between frame a
// and the frame now.
static long pixels_differ(drive_session* s, const unsigned char* a, const int rect[4]) {
    render* r = drive_session_render_ctx(s);
    int w, h;
    render_size(r, &w, &h);
    unsigned char* b = malloc((size_t)w * h * 4);
    render_read_pixels(r, b, w, h);
    long n = 0;
    for (int y = rect[1]; y < rect[1] + rect[3] && y < h; ++y)
        for (int x = rect[0]; x < rect[0] + rect[2] && x < w; ++x)
            n += memcmp(a + ((size_t)y * w + x) * 4, b + ((size_t)y * w + x) * 4, 3) != 0;
    free(b);
    return n;
}

// The default crane with a mapping file: lift on the triggers, jib on the
// shoulder buttons, the slew where it was. Each through the pad moves its
// own command only; the HUD's box shows what the file says.
static void test_default_crane_mapping_file(void) {
    char path[512], err[512] = "";
    snprintf(path, sizeof path, "%s/drive_functions_map.json", CRANESIM_BINARY_DIR);
    FILE* f = fopen(path, "w");
    CHECK(f != NULL, "write %s", path);
    if (!f) return;
    fputs("{\"axes\": {\"lift\": {\"controller\": [\"righttrigger\", \"lefttrigger\"]},\n"
          "          \"jib\": {\"controller\": [\"rightshoulder\", \"leftshoulder\"], \"keys\": "
          "[\"I\", \"K\"]}}}\n",
          f);
    fclose(f);
    drive_session* s = open_with(NULL, path, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.2);
    render* r = drive_session_render_ctx(s);
    // The box's text is the mapping the input layer uses, line by line.
    char want[1536];
    input_mapping_text(input_get_mapping(drive_session_input(s)), want, sizeof want);
    CHECK(!strcmp(render_mapping_text(r), want), "HUD box:\n%s\nmapping:\n%s",
          render_mapping_text(r), want);
    CHECK(strstr(render_mapping_text(r), "lift     RT / LT") &&
              strstr(render_mapping_text(r), "jib      RB / LB") &&
              strstr(render_mapping_text(r), "I / K") &&
              strstr(render_mapping_text(r), "slew     left stick X"),
          "the file's mapping:\n%s", render_mapping_text(r));
    drive_each_function(s, &wall, 3);
    // The box: shown at the start, gone after DRIVE_MAPPING_S, back on M.
    CHECK(render_mapping_shown(r), "shown at the start (t = %.1f s)", wall);
    // Drawn: the same state rendered with and without it differs where it sits.
    int w, h;
    render_size(r, &w, &h);
    unsigned char* shown = malloc((size_t)w * h * 4);
    drive_session_render(s);
    if (getenv("MAPBOX_PNG")) drive_session_screenshot(s, getenv("MAPBOX_PNG"), err, sizeof err);
    render_read_pixels(r, shown, w, h);
    int rect[4] = {0, 0, 0, 0};
    CHECK(render_mapping_rect(r, rect) && rect[0] >= 0 && rect[1] >= 0 && rect[0] + rect[2] <= w &&
              rect[1] + rect[3] <= h,
          "drawn inside the frame: %d %d %d %d", rect[0], rect[1], rect[2], rect[3]);
    render_show_mapping(r, false);
    drive_session_render(s);
    CHECK(!render_mapping_rect(r, (int[4]){0}), "hidden: not drawn");
    const long differ = pixels_differ(s, shown, rect);
    CHECK(differ > rect[2] * rect[3] / 4, "the box is drawn (%ld px of %d x %d differ)", differ,
          rect[2], rect[3]);
    render_show_mapping(r, true);
    run_for(s, &wall, DRIVE_MAPPING_S - wall + 0.1);
    CHECK(!render_mapping_shown(r), "hidden after %.0f s", DRIVE_MAPPING_S);
    push_key(SDL_SCANCODE_M, 1);
    push_key(SDL_SCANCODE_M, 0);
    run_for(s, &wall, 0.05);
    CHECK(render_mapping_shown(r), "M shows it");
    run_for(s, &wall, DRIVE_MAPPING_S);
    CHECK(render_mapping_shown(r), "and it stays (the operator asked)");
    push_key(SDL_SCANCODE_M, 1);
    push_key(SDL_SCANCODE_M, 0);
    run_for(s, &wall, 0.05);
    CHECK(!render_mapping_shown(r), "M hides it");
    free(shown);
    drive_session_destroy(s);
}

// A model with a controls section (hiab031 with lift on Y / N and the
// d-pad): the session uses it, the HUD says it, a bad one is exit 2.
static void test_model_controls_in_the_session(void) {
    char path[512], err[512] = "";
    snprintf(path, sizeof path, "%s/drive_functions_model.json", CRANESIM_BINARY_DIR);
    FILE* in = fopen(CRANESIM_ASSETS "/models/hiab031.json", "rb");
    CHECK(in != NULL, "hiab031.json");
    if (!in) return;
    static char text[1 << 17];
    const size_t n = fread(text, 1, sizeof text - 1, in);
    fclose(in);
    text[n] = '\0';
    const char* brace = strchr(text, '{');
    FILE* f = fopen(path, "w");
    fprintf(f,
            "{\"controls\": {\"axes\": {\"lift\": {\"controller\": [\"dpup\", \"dpdown\"], "
            "\"keys\": [\"Y\", \"N\"]}}},%s",
            brace + 1);
    fclose(f);
    drive_session* s = open_with(path, NULL, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.2);
    const char* t = render_mapping_text(drive_session_render_ctx(s));
    CHECK(strstr(t, "lift     d-pad up / d-pad down |") && strstr(t, "| Y / N\n"),
          "the model's lift:\n%s", t);
    // Y raises through the keyboard path (Up no longer does).
    engine* e = drive_session_engine(s);
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 0.5);
    CHECK_NEAR(engine_function_command(e, 0), 0.0, 0);
    push_key(SDL_SCANCODE_UP, 0);
    push_key(SDL_SCANCODE_Y, 1);
    run_for(s, &wall, 0.5);
    CHECK_NEAR(engine_function_command(e, 0), 1.0, 1e-9);
    push_key(SDL_SCANCODE_Y, 0);
    run_for(s, &wall, 0.5);
    drive_each_function(s, &wall, 3);
    drive_session_destroy(s);

    // The model's controls and a mapping file that clash: exit 2, one line.
    char mpath[512];
    snprintf(mpath, sizeof mpath, "%s/drive_functions_clash.json", CRANESIM_BINARY_DIR);
    f = fopen(mpath, "w");
    fputs("{\"axes\": {\"jib\": {\"keys\": [\"Y\", \"S\"]}}}", f);
    fclose(f);
    int code = 0;
    s = open_with(path, mpath, err, sizeof err, &code);
    CHECK(s == NULL && code == 2 && strstr(err, "drive_functions_clash.json: axes.jib.keys") &&
              strstr(err, "'lift'") && !strchr(err, '\n'),
          "clash: code %d, %s", code, err);
    drive_session_destroy(s);
}

// The six functions of chain_6fn_controls.json (five on the chain, the
// sandbox's slew) through the session, and the box shows the model's ext2.
static void test_six_functions_in_the_session(void) {
    char err[512] = "";
    int code = 0;
    drive_session* s = open_with(MODEL6, NULL, err, sizeof err, &code);
    CHECK(s != NULL, "session (code %d): %s", code, err);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.2);
    const char* t = render_mapping_text(drive_session_render_ctx(s));
    CHECK(strstr(t, "ext2     d-pad up / d-pad down | btn 5 / 4 | Y / N\n") != NULL,
          "the model's ext2:\n%s", t);
    drive_each_function(s, &wall, 6);
    drive_session_destroy(s);
}

int main(int argc, char** argv) {
    if (SDL_Init(SDL_INIT_EVENTS | SDL_INIT_JOYSTICK | SDL_INIT_GAMECONTROLLER) != 0) {
        fprintf(stderr, "SDL_Init: %s\n", SDL_GetError());
        return 1;
    }
    RUN_TEST(test_default_crane_mapping_file);
    RUN_TEST(test_model_controls_in_the_session);
    RUN_TEST(test_six_functions_in_the_session);
    SDL_Quit();
    TEST_MAIN_END();
}
