// test_input_map.c: the input mapping by function (issue 27): the names the
// model's "controls" section takes are SDL's, the default layouts for 4..8
// functions give every function its own device input and key pair clear of
// the window's keys, the model's section and a mapping file are read and bad
// names refused with file and field, and a virtual game controller drives
// each of the six functions of tests/world/data/chain_6fn_controls.json
// through the real input path (SDL events -> mapping -> command), one at a
// time, with the HUD box's text naming what the model says.
#include <stdlib.h>

#include "check.h"
#include "input.h"
#include "model.h"
#include "model_controls.h"

#define MODEL6 CRANESIM_ASSETS "/../tests/world/data/chain_6fn_controls.json"

static void pump(input* in) {
    SDL_Event ev;
    while (SDL_PollEvent(&ev))
        input_handle_event(in, &ev);
}

static void push_key(SDL_Scancode sc, bool down) {
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = down ? SDL_KEYDOWN : SDL_KEYUP;
    ev.key.state = down ? SDL_PRESSED : SDL_RELEASED;
    ev.key.keysym.scancode = sc;
    ev.key.keysym.sym = SDL_GetKeyFromScancode(sc);
    SDL_PushEvent(&ev);
}

// Every name the parser accepts is one SDL knows, spelt as SDL spells it
// (input.c looks them up by these names; a name SDL does not know would
// leave a function unbound without a word).
static void test_names_are_sdl_names(void) {
    for (int i = 0; controls_keys[i]; ++i) {
        const SDL_Scancode sc = SDL_GetScancodeFromName(controls_keys[i]);
        CHECK(sc != SDL_SCANCODE_UNKNOWN, "key \"%s\" unknown to SDL", controls_keys[i]);
        CHECK(!strcmp(SDL_GetScancodeName(sc), controls_keys[i]), "key \"%s\" is \"%s\" in SDL",
              controls_keys[i], SDL_GetScancodeName(sc));
    }
    for (int i = 0; controls_window_keys[i][0]; ++i)
        CHECK(SDL_GetScancodeFromName(controls_window_keys[i][0]) != SDL_SCANCODE_UNKNOWN,
              "window key \"%s\"", controls_window_keys[i][0]);
    for (int i = 0; controls_controller_axes[i]; ++i)
        CHECK(SDL_GameControllerGetAxisFromString(controls_controller_axes[i]) !=
                  SDL_CONTROLLER_AXIS_INVALID,
              "axis \"%s\"", controls_controller_axes[i]);
    for (int i = 0; controls_controller_buttons[i]; ++i)
        CHECK(SDL_GameControllerGetButtonFromString(controls_controller_buttons[i]) !=
                  SDL_CONTROLLER_BUTTON_INVALID,
              "button \"%s\"", controls_controller_buttons[i]);
}

// The default crane's mapping is exactly the one before functions came:
// left stick y lift, right stick y jib, left stick x slew (all inverted),
// raw axes 1, 3, 0; keys Up/Down, W/S, Left/Right and A/D.
static void test_default_crane_unchanged(void) {
    const input_mapping m = input_default_mapping();
    CHECK(m.naxis == 3, "3 functions, got %d", m.naxis);
    static const char* const names[3] = {"lift", "jib", "slew"};
    const int ca[3] = {SDL_CONTROLLER_AXIS_LEFTY, SDL_CONTROLLER_AXIS_RIGHTY,
                       SDL_CONTROLLER_AXIS_LEFTX};
    const int ja[3] = {1, 3, 0};
    const int keys[3][4] = {
        {SDL_SCANCODE_UP, SDL_SCANCODE_DOWN, 0, 0},
        {SDL_SCANCODE_W, SDL_SCANCODE_S, 0, 0},
        {SDL_SCANCODE_LEFT, SDL_SCANCODE_RIGHT, SDL_SCANCODE_A, SDL_SCANCODE_D}};
    for (int i = 0; i < 3; ++i) {
        const input_axis_map* a = &m.axis[i];
        CHECK(!strcmp(a->name, names[i]), "function %d is %s", i, a->name);
        CHECK(a->controller_axis == ca[i] && a->joystick_axis == ja[i] && a->invert,
              "%s: axis %d, raw %d, inv %d", names[i], a->controller_axis, a->joystick_axis,
              a->invert);
        CHECK(a->key[0] == keys[i][0] && a->key[1] == keys[i][1] && a->key_alt[0] == keys[i][2] &&
                  a->key_alt[1] == keys[i][3],
              "%s keys", names[i]);
        CHECK_NEAR(a->dead_zone, 0.08, 0);
        CHECK_NEAR(a->expo, 0.3, 0);
        CHECK_NEAR(a->scale, 1.0, 0);
    }
}

// Codes of everything a function's device inputs use, for the duplicate check.
static int device_inputs(const input_axis_map* a, int* code) {
    int n = 0;
    if (a->controller_axis >= 0) code[n++] = a->controller_axis;
    for (int k = 0; k < 2; ++k)
        if (a->controller_pair[k] >= 0) code[n++] = a->controller_pair[k];
    return n;
}

static bool is_window_key(int sc) {
    for (int i = 0; controls_window_keys[i][0]; ++i)
        if ((int)SDL_GetScancodeFromName(controls_window_keys[i][0]) == sc) return true;
    return false;
}

static void check_layout(const char* const* names, int n, const char* layout) {
    input_mapping m;
    char err[200] = "";
    CHECK(input_layout_mapping(names, n, layout, &m, err, sizeof err) == 0, "%d %s: %s", n, layout,
          err);
    int used[64], nused = 0, jused[64], njused = 0, keys[64], nkeys = 0;
    for (int i = 0; i < n; ++i) {
        const input_axis_map* a = &m.axis[i];
        CHECK(!strcmp(a->name, names[i]), "order kept");
        int code[3];
        const int nc = device_inputs(a, code);
        CHECK(nc > 0, "%s (%d, %s): no controller input", names[i], n, layout);
        for (int k = 0; k < nc; ++k) {
            for (int j = 0; j < nused; ++j)
                CHECK(used[j] != code[k], "%s (%d, %s): controller input %d twice", names[i], n,
                      layout, code[k]);
            // Not one of the buttons hook, pause, reset, screenshot, camera.
            for (int b = 0; b < INPUT_BUTTON_COUNT; ++b)
                CHECK(code[k] != INPUT_PAIR_BUTTON + m.controller_button[b], "%s: a command button",
                      names[i]);
            used[nused++] = code[k];
        }
        const int jn =
            a->joystick_axis >= 0 ? 1 : (a->joystick_button[0] >= 0) + (a->joystick_button[1] >= 0);
        CHECK(jn > 0, "%s (%d, %s): no joystick input", names[i], n, layout);
        const int jcode[3] = {a->joystick_axis,
                              a->joystick_button[0] >= 0 ? 1000 + a->joystick_button[0] : -1,
                              a->joystick_button[1] >= 0 ? 1000 + a->joystick_button[1] : -1};
        for (int k = 0; k < 3; ++k) {
            if (jcode[k] < 0) continue;
            for (int j = 0; j < njused; ++j)
                CHECK(jused[j] != jcode[k], "%s: joystick input twice", names[i]);
            for (int b = 0; b < INPUT_BUTTON_COUNT; ++b)
                CHECK(jcode[k] != 1000 + m.joystick_button[b], "%s: a command button", names[i]);
            jused[njused++] = jcode[k];
        }
        const int kk[4] = {a->key[0], a->key[1], a->key_alt[0], a->key_alt[1]};
        CHECK(kk[0] && kk[1], "%s (%d, %s): no key pair", names[i], n, layout);
        for (int k = 0; k < 4; ++k) {
            if (!kk[k]) continue;
            CHECK(!is_window_key(kk[k]), "%s: key %s is the window's", names[i],
                  SDL_GetScancodeName(kk[k]));
            for (int j = 0; j < nkeys; ++j)
                CHECK(keys[j] != kk[k], "%s (%d, %s): key %s twice", names[i], n, layout,
                      SDL_GetScancodeName(kk[k]));
            keys[nkeys++] = kk[k];
        }
    }
    // And through the input layer: each function's keys move that function
    // only and raise no edge (hook, pause, reset, camera, screenshot, quit).
    input* in = input_create(&m);
    for (int i = 0; i < n; ++i)
        for (int s = 0; s < 2; ++s) {
            push_key((SDL_Scancode)m.axis[i].key[s], true);
            pump(in);
            input_command cmd;
            input_poll(in, 10.0, &cmd); // past the keyboard ramp
            for (int j = 0; j < n; ++j)
                CHECK_NEAR(cmd.u[j], j == i ? (s ? -1.0 : 1.0) : 0.0, 0);
            CHECK(!cmd.hook_toggle && !cmd.pause && !cmd.reset && !cmd.screenshot && !cmd.quit &&
                      !cmd.camera_next && cmd.camera_preset < 0 && !cmd.mapping_box,
                  "%s key %d: an edge", names[i], s);
            push_key((SDL_Scancode)m.axis[i].key[s], false);
            pump(in);
            input_poll(in, 10.0, &cmd);
        }
    input_destroy(in);
}

static void test_default_layouts(void) {
    // Names by role (lift, jib, slew take today's places) and plain ones.
    static const char* const roles[8] = {"lift", "jib",  "ext",     "slew",
                                         "jib2", "ext2", "rotator", "grab"};
    static const char* const plain[8] = {"f1", "f2", "f3", "f4", "f5", "f6", "f7", "f8"};
    for (int n = 4; n <= 8; ++n) {
        check_layout(roles, n, "two-lever");
        check_layout(plain, n, "two-lever");
        check_layout(roles, n, "four-lever");
        check_layout(plain, n, NULL);
    }
    // Two-lever by role: lift left y, jib right y, slew left x wherever the
    // model lists them; ext takes the right stick's x (extends to the right).
    input_mapping m;
    input_layout_mapping(roles, 8, "two-lever", &m, NULL, 0);
    CHECK(m.axis[0].controller_axis == SDL_CONTROLLER_AXIS_LEFTY, "lift");
    CHECK(m.axis[1].controller_axis == SDL_CONTROLLER_AXIS_RIGHTY, "jib");
    CHECK(m.axis[3].controller_axis == SDL_CONTROLLER_AXIS_LEFTX && m.axis[3].invert, "slew");
    CHECK(m.axis[2].controller_axis == SDL_CONTROLLER_AXIS_RIGHTX && !m.axis[2].invert, "ext");
    CHECK(m.axis[3].key[0] == SDL_SCANCODE_LEFT && m.axis[3].key_alt[0] == SDL_SCANCODE_A,
          "slew keys");
    // Four-lever: in the model's order, keys by column (Q/A, W/S, E/D, ...).
    input_layout_mapping(roles, 8, "four-lever", &m, NULL, 0);
    CHECK(m.axis[0].key[0] == SDL_SCANCODE_Q && m.axis[0].key[1] == SDL_SCANCODE_A,
          "lever 1: Q / A");
    CHECK(m.axis[2].key[0] == SDL_SCANCODE_E && m.axis[2].key[1] == SDL_SCANCODE_D,
          "lever 3: E / D");
    CHECK(m.axis[3].controller_axis == SDL_CONTROLLER_AXIS_RIGHTX && m.axis[3].invert,
          "slew on x stays inverted");
    // 9..12: keys only; 13 and a bad layout refused with a reason.
    static const char* const many[13] = {"a", "b", "c", "d", "e", "f", "g",
                                         "h", "i", "j", "k", "l", "m"};
    CHECK(input_layout_mapping(many, 12, NULL, &m, NULL, 0) == 0, "12 functions");
    CHECK(m.axis[11].key[0] && m.axis[11].controller_axis < 0 && m.axis[11].controller_pair[0] < 0,
          "12th: keys");
    char err[200] = "";
    CHECK(input_layout_mapping(many, 13, NULL, &m, err, sizeof err) == -1 && strstr(err, "1 to 12"),
          "13: %s", err);
    CHECK(input_layout_mapping(many, 4, "three-lever", &m, err, sizeof err) == -1 &&
              strstr(err, "three-lever"),
          "layout: %s", err);
    static const char* const twice[2] = {"lift", "lift"};
    CHECK(input_layout_mapping(twice, 2, NULL, &m, err, sizeof err) == -1 && strstr(err, "twice"),
          "%s", err);
}

// The mapping drive builds for chain_6fn_controls.json in the sandbox: the
// chain's functions, the sandbox's slew, the two-lever defaults and the
// model's controls over them (drive_session.c build_mapping).
static int model6_mapping(input_mapping* m, char* err, size_t errsz) {
    model* md = model_load(MODEL6, NULL, 0, err, errsz);
    if (!md) return -1;
    const char* names[8];
    int n = 0;
    for (int i = 0; i < md->chain.nfn; ++i)
        names[n++] = md->chain.fn[i].name;
    names[n++] = "slew";
    int rc = input_layout_mapping(names, n, NULL, m, err, errsz);
    if (!rc)
        rc = md->controls ? input_apply_controls(m, md->controls, md->file, "controls", err, errsz)
                          : -1;
    model_free(md);
    return rc;
}

static void test_model_controls(void) {
    input_mapping m;
    char err[400] = "";
    CHECK(model6_mapping(&m, err, sizeof err) == 0, "%s", err);
    CHECK(m.naxis == 6, "six functions, got %d", m.naxis);
    const int e2 = input_find_function(&m, "ext2");
    CHECK(e2 == 4, "ext2 is function 4, got %d", e2);
    if (e2 < 0) return;
    const input_axis_map* a = &m.axis[e2];
    // The model's section: the d-pad, raw buttons 5 / 4, keys Y / N; the
    // defaults would give it the shoulder buttons and Insert / Delete.
    CHECK(a->controller_axis == -1 &&
              a->controller_pair[0] == INPUT_PAIR_BUTTON + SDL_CONTROLLER_BUTTON_DPAD_UP &&
              a->controller_pair[1] == INPUT_PAIR_BUTTON + SDL_CONTROLLER_BUTTON_DPAD_DOWN,
          "ext2 on the d-pad (%d %d)", a->controller_pair[0], a->controller_pair[1]);
    CHECK(a->joystick_button[0] == 5 && a->joystick_button[1] == 4 && a->joystick_axis == -1,
          "raw buttons instead of the default's raw axis 5 (%d)", a->joystick_axis);
    CHECK(a->key[0] == SDL_SCANCODE_Y && a->key[1] == SDL_SCANCODE_N, "keys Y / N");
    // The rest keep the defaults: jib2 the right stick's x, ext the triggers.
    const input_axis_map* j2 = &m.axis[input_find_function(&m, "jib2")];
    CHECK(j2->controller_axis == SDL_CONTROLLER_AXIS_RIGHTX, "jib2 on right x");
    const input_axis_map* ex = &m.axis[input_find_function(&m, "ext")];
    CHECK(ex->controller_pair[0] == SDL_CONTROLLER_AXIS_TRIGGERRIGHT &&
              ex->controller_pair[1] == SDL_CONTROLLER_AXIS_TRIGGERLEFT,
          "ext on RT / LT");
    // The HUD box's text: one line per function in the engine's order, each
    // with what the model gives it.
    char text[1536];
    input_mapping_text(&m, text, sizeof text);
    static const char* const want[6][3] = {{"lift", "left stick Y", "Up / Down"},
                                           {"jib", "right stick Y", "W / S"},
                                           {"jib2", "right stick X", "PageUp / PageDown"},
                                           {"ext", "RT / LT", "Home / End"},
                                           {"ext2", "d-pad up / d-pad down", "Y / N"},
                                           {"slew", "left stick X", "Left / Right (A / D)"}};
    const char* line = text;
    for (int i = 0; i < 6; ++i) {
        const char* eol = strchr(line, '\n');
        CHECK(eol != NULL, "line %d in:\n%s", i, text);
        if (!eol) break;
        char l[200];
        snprintf(l, sizeof l, "%.*s", (int)(eol - line), line);
        CHECK(!strncmp(l, want[i][0], strlen(want[i][0])) && l[strlen(want[i][0])] == ' ',
              "line %d: %s", i, l);
        CHECK(strstr(l, want[i][1]) && strstr(l, want[i][2]), "line %d: %s (want %s, %s)", i, l,
              want[i][1], want[i][2]);
        line = eol + 1;
    }
    CHECK(!*line, "six lines only:\n%s", text);
}

static void write_file(const char* path, const char* text) {
    FILE* f = fopen(path, "w");
    CHECK(f != NULL, "write %s", path);
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

// The model file with its controls section replaced by ctl (JSON text).
static model* model6_with(const char* ctl, char* err, size_t errsz) {
    char* text = NULL;
    FILE* f = fopen(MODEL6, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    text = malloc((size_t)n + 1);
    const size_t got = fread(text, 1, (size_t)n, f);
    fclose(f);
    text[got] = '\0';
    char* at = strstr(text, "\"controls\":");
    CHECK(at != NULL, "model has controls");
    if (!at) {
        free(text);
        return NULL;
    }
    *at = '\0';
    char path[512];
    snprintf(path, sizeof path, "%s/input_map_model.json", CRANESIM_BINARY_DIR);
    f = fopen(path, "w");
    fprintf(f, "%s\"controls\": %s\n}\n", text, ctl);
    fclose(f);
    free(text);
    return model_load(path, NULL, 0, err, errsz);
}

static void test_bad_names_refused(void) {
    // In the model: one line naming the file, the field and the problem.
    static const char* const bad[][2] = {
        {"{\"axes\": {\"ext2\": {\"controller\": \"stick_of_joy\"}}}",
         "controls.axes.ext2.controller: unknown"},
        {"{\"axes\": {\"ext2\": {\"controller\": [\"dpup\", \"bogus\"]}}}",
         "controls.axes.ext2.controller[1]"},
        {"{\"axes\": {\"ext2\": {\"keys\": [\"Y\", \"Hyper\"]}}}",
         "controls.axes.ext2.keys[1]: unknown key"},
        {"{\"axes\": {\"ext2\": {\"keys\": [\"H\", \"N\"]}}}",
         "controls.axes.ext2.keys[0]: key \"H\" is the window's (hook)"},
        {"{\"axes\": {\"ext2\": {\"keys\": \"Y\"}}}",
         "controls.axes.ext2.keys: must be [plus, minus]"},
        {"{\"axes\": {\"winch\": {\"keys\": [\"Y\", \"N\"]}}}",
         "controls.axes.winch: no function 'winch'"},
        {"{\"axes\": {\"ext2\": {\"dead_zone\": 1}}}",
         "controls.axes.ext2.dead_zone: must be a number in [0, 0.94]"},
        {"{\"layout\": \"three-lever\"}", "controls.layout"},
        {"{\"axis\": {}}", "controls.axis: unknown field"},
        {"{\"buttons\": {\"hook\": {\"controller\": \"leftx\"}}}",
         "controls.buttons.hook.controller"},
    };
    char err[400];
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        err[0] = '\0';
        model* m = model6_with(bad[i][0], err, sizeof err);
        CHECK(m == NULL, "accepted: %s", bad[i][0]);
        model_free(m);
        CHECK(strstr(err, "input_map_model.json") && strstr(err, bad[i][1]) && !strchr(err, '\n'),
              "%s: message: %s", bad[i][0], err);
    }
    // A good one loads, in any case of the names (SDL's spelling is kept).
    err[0] = '\0';
    model* m = model6_with(
        "{\"layout\": \"four-lever\", \"axes\": {\"jib2\": {\"controller\": \"RightY\", "
        "\"keys\": [\"keypad 8\", \"keypad 2\"]}}}",
        err, sizeof err);
    CHECK(m != NULL && m->controls && !strcmp(m->controls->layout, "four-lever") &&
              !strcmp(m->controls->fn[0].controller[0], "righty") &&
              !strcmp(m->controls->fn[0].key[0], "Keypad 8"),
          "good controls: %s", err);
    model_free(m);

    // A mapping file (the same format) over the default crane: a key that
    // another function has is refused, naming both.
    char path[512];
    snprintf(path, sizeof path, "%s/input_map_file.json", CRANESIM_BINARY_DIR);
    input_mapping dm = input_default_mapping(), before = dm;
    write_file(path, "{\"axes\": {\"jib\": {\"keys\": [\"Up\", \"N\"]}}}");
    CHECK(input_load_mapping(path, &dm, err, sizeof err) == -1 && strstr(err, "axes.jib.keys") &&
              strstr(err, "'lift'"),
          "clash: %s", err);
    CHECK(memcmp(&before, &dm, sizeof dm) == 0, "untouched on error");
    write_file(path, "{\"axes\": {\"ext\": {\"keys\": [\"Y\", \"N\"]}}}");
    CHECK(input_load_mapping(path, &dm, err, sizeof err) == -1 &&
              strstr(err, "no function 'ext'") && strstr(err, "lift, jib, slew"),
          "unknown function: %s", err);
    // The slew on the triggers and the shoulder buttons: a pair each.
    write_file(path,
               "{\"axes\": {\"slew\": {\"controller\": [\"lefttrigger\", \"righttrigger\"], "
               "\"joystick\": null, \"joystick_buttons\": [4, 5], \"keys\": [\"Z\", \"X\"]}}}");
    CHECK(input_load_mapping(path, &dm, err, sizeof err) == 0, "%s", err);
    const input_axis_map* sl = &dm.axis[INPUT_SLEW];
    CHECK(sl->controller_axis == -1 && sl->controller_pair[0] == SDL_CONTROLLER_AXIS_TRIGGERLEFT &&
              sl->controller_pair[1] == SDL_CONTROLLER_AXIS_TRIGGERRIGHT &&
              sl->joystick_axis == -1 && sl->joystick_button[0] == 4 &&
              sl->key[0] == SDL_SCANCODE_Z && sl->key_alt[0] == 0,
          "slew remapped");
}

static int attach_pad(void) {
    SDL_VirtualJoystickDesc d;
    memset(&d, 0, sizeof d);
    d.version = SDL_VIRTUAL_JOYSTICK_DESC_VERSION;
    d.type = (Uint16)SDL_JOYSTICK_TYPE_GAMECONTROLLER;
    d.naxes = SDL_CONTROLLER_AXIS_MAX;
    d.nbuttons = SDL_CONTROLLER_BUTTON_MAX;
    d.name = "virtual 6-function pad";
    return SDL_JoystickAttachVirtualEx(&d);
}

// One controller input of a function at full + deflection (on) or at rest.
static void set_input(SDL_Joystick* js, const input_axis_map* a, bool on) {
    if (a->controller_axis >= 0) {
        // SDL gives + for stick down / right: an inverted axis goes up / left.
        SDL_JoystickSetVirtualAxis(js, a->controller_axis, !on ? 0 : a->invert ? -32768 : 32767);
        return;
    }
    const int c = a->controller_pair[0]; // the + side
    if (c >= INPUT_PAIR_BUTTON)
        SDL_JoystickSetVirtualButton(js, c - INPUT_PAIR_BUTTON, on ? 1 : 0);
    else // a trigger: SDL's virtual controller maps the full axis range onto 0..32767
        SDL_JoystickSetVirtualAxis(js, c, on ? 32767 : -32768);
}

// A virtual game controller drives each of the six functions of the model in
// turn: exactly that function's command goes to +1, every other stays 0.
static void test_six_functions_on_a_virtual_pad(void) {
    input_mapping m;
    char err[400] = "";
    CHECK(model6_mapping(&m, err, sizeof err) == 0, "%s", err);
    if (m.naxis != 6) return;
    input* in = input_create(&m);
    const int idx = attach_pad();
    CHECK(idx >= 0, "attach: %s", SDL_GetError());
    if (idx < 0) {
        input_destroy(in);
        return;
    }
    pump(in);
    CHECK(input_active_source(in) == INPUT_SRC_CONTROLLER, "a game controller (%d)",
          input_active_source(in));
    SDL_Joystick* js = SDL_JoystickOpen(idx);
    // At rest (triggers released): nothing moves.
    for (int k = 0; k < 6; ++k)
        set_input(js, &m.axis[k], false);
    SDL_JoystickUpdate();
    pump(in);
    input_command cmd;
    input_poll(in, 0.016, &cmd);
    CHECK(cmd.n == 6, "six commands, got %d", cmd.n);
    for (int j = 0; j < 6; ++j)
        CHECK_NEAR(cmd.u[j], 0.0, 0);
    for (int k = 0; k < 6; ++k) {
        set_input(js, &m.axis[k], true);
        SDL_JoystickUpdate();
        pump(in);
        input_poll(in, 0.016, &cmd);
        for (int j = 0; j < 6; ++j)
            CHECK_NEAR(cmd.u[j], j == k ? 1.0 : 0.0, 1e-4);
        set_input(js, &m.axis[k], false);
        SDL_JoystickUpdate();
        pump(in);
        input_poll(in, 0.016, &cmd);
        for (int j = 0; j < 6; ++j)
            CHECK_NEAR(cmd.u[j], 0.0, 0);
    }
    // The - side of a pair: LT retracts the extension, d-pad down ext2.
    const int ex = input_find_function(&m, "ext"), e2 = input_find_function(&m, "ext2");
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_TRIGGERLEFT, 32767);
    SDL_JoystickSetVirtualButton(js, SDL_CONTROLLER_BUTTON_DPAD_DOWN, 1);
    SDL_JoystickUpdate();
    pump(in);
    input_poll(in, 0.016, &cmd);
    CHECK_NEAR(cmd.u[ex], -1.0, 1e-4);
    CHECK_NEAR(cmd.u[e2], -1.0, 1e-9);
    SDL_JoystickClose(js);
    SDL_JoystickDetachVirtual(idx);
    pump(in);
    input_destroy(in);
}

int main(int argc, char** argv) {
    (void)argc, (void)argv;
    if (SDL_Init(SDL_INIT_EVENTS | SDL_INIT_JOYSTICK | SDL_INIT_GAMECONTROLLER) != 0) {
        fprintf(stderr, "SDL_Init: %s\n", SDL_GetError());
        return 1;
    }
    RUN_TEST(test_names_are_sdl_names);
    RUN_TEST(test_default_crane_unchanged);
    RUN_TEST(test_default_layouts);
    RUN_TEST(test_model_controls);
    RUN_TEST(test_bad_names_refused);
    RUN_TEST(test_six_functions_on_a_virtual_pad);
    SDL_Quit();
    TEST_MAIN_END();
}
