// input.c: game controllers, plain joysticks and the keyboard -> one
// input_command per frame (see input.h for the why).
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "input.h"

struct input {
    input_mapping map;
    SDL_GameController* gc; ///< active device if it is a game controller
    SDL_Joystick* js;       ///< active device's joystick (also set for gc)
    SDL_JoystickID id;      ///< its instance id, -1 if none
    char name[128];
    Uint32 own_subsystems; ///< SDL subsystems we started, to quit them again
    bool key_pos[INPUT_AXIS_COUNT], key_neg[INPUT_AXIS_COUNT];
    double kb[INPUT_AXIS_COUNT]; ///< ramped keyboard contribution
    bool shift[2];               ///< left, right Shift held: fine mode (INPUT_FINE_SCALE)
    // Edges collected between polls.
    bool hook, pause, reset, screenshot, quit, camera_next;
    int camera_preset;
};

input_mapping input_default_mapping(void) {
    input_mapping m;
    memset(&m, 0, sizeof m);
    // SDL reports stick "up" as negative y: invert so pushing up raises.
    const int ca[INPUT_AXIS_COUNT] = {SDL_CONTROLLER_AXIS_LEFTY, SDL_CONTROLLER_AXIS_RIGHTY,
                                      SDL_CONTROLLER_AXIS_LEFTX};
    const int ja[INPUT_AXIS_COUNT] = {1, 3, 0};
    for (int i = 0; i < INPUT_AXIS_COUNT; ++i) {
        m.axis[i].controller_axis = ca[i];
        m.axis[i].joystick_axis = ja[i];
        // Stick right should turn clockwise seen from above (negative slew).
        m.axis[i].invert = true;
        m.axis[i].dead_zone = 0.08;
        m.axis[i].expo = 0.3;
        m.axis[i].scale = 1.0;
    }
    const int cb[INPUT_BUTTON_COUNT] = {SDL_CONTROLLER_BUTTON_A, SDL_CONTROLLER_BUTTON_START,
                                        SDL_CONTROLLER_BUTTON_BACK, SDL_CONTROLLER_BUTTON_Y,
                                        SDL_CONTROLLER_BUTTON_X};
    const int jb[INPUT_BUTTON_COUNT] = {0, 7, 6, 3, 2};
    for (int i = 0; i < INPUT_BUTTON_COUNT; ++i) {
        m.controller_button[i] = cb[i];
        m.joystick_button[i] = jb[i];
    }
    m.keyboard_ramp = 0.25;
    return m;
}

double input_shape(double raw, double dead_zone, double expo) {
    if (!isfinite(raw)) return 0.0;
    double a = fabs(raw);
    if (a > 1) a = 1;
    if (a <= dead_zone) return 0.0;
    double x = (a - dead_zone) / (1.0 - dead_zone);
    double y = (1.0 - expo) * x + expo * x * x * x;
    return raw < 0 ? -y : y;
}

// ---- mapping file ----------------------------------------------------------------

static const char* const k_axis_names[INPUT_AXIS_COUNT] = {"lift", "jib", "slew"};
static const char* const k_button_names[INPUT_BUTTON_COUNT] = {"hook",       "pause", "reset",
                                                               "screenshot", "camera"};

/// Every key of object o must be one of the n names in allowed: a field the
/// format does not have is a typo, and skipping it would leave the setting
/// the user meant at its default. where: the object's path ("" at the top).
static int only_keys(const cJSON* o, const char* const* allowed, int n, const char* path,
                     const char* where, char* err, size_t errsz) {
    for (const cJSON* k = o->child; k; k = k->next) {
        bool ok = false;
        for (int i = 0; i < n && !ok; ++i) ok = k->string && strcmp(k->string, allowed[i]) == 0;
        if (ok) continue;
        char list[160] = "";
        for (int i = 0; i < n; ++i)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "",
                     allowed[i]);
        snprintf(err, errsz, "%s: %s%s%s: unknown field (expected %s)", path, where,
                 where[0] ? "." : "", k->string ? k->string : "?", list);
        return -1;
    }
    return 0;
}

/// Reads an optional number field within [lo, hi].
static int get_num(const cJSON* o, const char* key, double lo, double hi, double* out,
                   const char* path, const char* where, char* err, size_t errsz) {
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v) return 0;
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= lo && v->valuedouble <= hi)) {
        snprintf(err, errsz, "%s: %s.%s: must be a number in [%g, %g]", path, where, key, lo, hi);
        return -1;
    }
    *out = v->valuedouble;
    return 0;
}

/// A device reference: a name (controller), an integer (joystick), or
/// null / "none" for unbound.
static int get_ref(const cJSON* o, const char* key, bool controller, bool is_axis, int* out,
                   const char* path, const char* where, char* err, size_t errsz) {
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v) return 0;
    if (cJSON_IsNull(v) || (cJSON_IsString(v) && strcmp(v->valuestring, "none") == 0)) {
        *out = -1;
        return 0;
    }
    if (controller) {
        int k = -1;
        if (cJSON_IsString(v))
            k = is_axis ? (int)SDL_GameControllerGetAxisFromString(v->valuestring)
                        : (int)SDL_GameControllerGetButtonFromString(v->valuestring);
        if (k < 0) {
            snprintf(
                err, errsz, "%s: %s.%s: unknown game controller %s \"%s\" (e.g. %s)", path, where,
                key, is_axis ? "axis" : "button", cJSON_IsString(v) ? v->valuestring : "?",
                is_axis ? "leftx, lefty, rightx, righty, lefttrigger" : "a, b, x, y, start, back");
            return -1;
        }
        *out = k;
        return 0;
    }
    if (!cJSON_IsNumber(v) || v->valuedouble < 0 || v->valuedouble > 255 ||
        v->valuedouble != floor(v->valuedouble)) {
        snprintf(err, errsz, "%s: %s.%s: must be a joystick %s index 0..255 or null", path, where,
                 key, is_axis ? "axis" : "button");
        return -1;
    }
    *out = v->valueint;
    return 0;
}

int input_load_mapping(const char* path, input_mapping* m, char* err, size_t errsz) {
    char dummy[8];
    if (!err || !errsz) err = dummy, errsz = sizeof dummy;
    FILE* f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errsz, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char* text = n >= 0 ? malloc((size_t)n + 1) : NULL;
    size_t got = text ? fread(text, 1, (size_t)n, f) : 0;
    fclose(f);
    if (!text) {
        snprintf(err, errsz, "%s: cannot read", path);
        return -1;
    }
    text[got] = '\0';
    cJSON* root = cJSON_Parse(text);
    if (!root || !cJSON_IsObject(root)) {
        // cJSON's error pointer points into text: quote it before freeing.
        const char* at = root ? NULL : cJSON_GetErrorPtr();
        if (at) {
            int line = 1;
            for (const char* c = text; c < at; ++c) line += *c == '\n';
            int n = 0; // quote up to 20 characters, on one line
            while (n < 20 && at[n] && at[n] != '\n' && at[n] != '\r') ++n;
            snprintf(err, errsz, "%s: line %d: not valid JSON near \"%.*s\"", path, line, n, at);
        } else {
            snprintf(err, errsz, "%s: must be a JSON object", path);
        }
        free(text);
        cJSON_Delete(root);
        return -1;
    }
    free(text);
    // Work on a copy so a bad file leaves the caller's mapping untouched.
    input_mapping t = *m;
    static const char* const k_top[] = {"axes", "buttons", "keyboard_ramp_s"};
    static const char* const k_axis_fields[] = {"controller", "joystick", "invert",
                                                "dead_zone",  "expo",     "scale"};
    static const char* const k_button_fields[] = {"controller", "joystick"};
    int rc = only_keys(root, k_top, 3, path, "", err, errsz);
    const cJSON* axes = cJSON_GetObjectItemCaseSensitive(root, "axes");
    const cJSON* buttons = cJSON_GetObjectItemCaseSensitive(root, "buttons");
    if (rc == 0 && ((axes && !cJSON_IsObject(axes)) || (buttons && !cJSON_IsObject(buttons)))) {
        snprintf(err, errsz, "%s: %s: must be an object", path,
                 axes && !cJSON_IsObject(axes) ? "axes" : "buttons");
        rc = -1;
    }
    if (rc == 0 && axes) rc = only_keys(axes, k_axis_names, INPUT_AXIS_COUNT, path, "axes", err, errsz);
    if (rc == 0 && buttons)
        rc = only_keys(buttons, k_button_names, INPUT_BUTTON_COUNT, path, "buttons", err, errsz);
    for (int i = 0; axes && rc == 0 && i < INPUT_AXIS_COUNT; ++i) {
        const cJSON* a = cJSON_GetObjectItemCaseSensitive(axes, k_axis_names[i]);
        if (!a) continue;
        char where[48];
        snprintf(where, sizeof where, "axes.%s", k_axis_names[i]);
        if (!cJSON_IsObject(a)) {
            snprintf(err, errsz, "%s: %s: must be an object", path, where);
            rc = -1;
            break;
        }
        input_axis_map* x = &t.axis[i];
        rc |= only_keys(a, k_axis_fields, 6, path, where, err, errsz);
        if (!rc) rc |= get_ref(a, "controller", true, true, &x->controller_axis, path, where, err, errsz);
        if (!rc)
            rc |= get_ref(a, "joystick", false, true, &x->joystick_axis, path, where, err, errsz);
        if (!rc) rc |= get_num(a, "dead_zone", 0.0, 0.94, &x->dead_zone, path, where, err, errsz);
        if (!rc) rc |= get_num(a, "expo", 0.0, 1.0, &x->expo, path, where, err, errsz);
        if (!rc) rc |= get_num(a, "scale", 0.01, 1.0, &x->scale, path, where, err, errsz);
        const cJSON* inv = cJSON_GetObjectItemCaseSensitive(a, "invert");
        if (!rc && inv) {
            if (!cJSON_IsBool(inv)) {
                snprintf(err, errsz, "%s: %s.invert: must be true or false", path, where);
                rc = -1;
            } else {
                x->invert = cJSON_IsTrue(inv);
            }
        }
    }
    for (int i = 0; buttons && rc == 0 && i < INPUT_BUTTON_COUNT; ++i) {
        const cJSON* b = cJSON_GetObjectItemCaseSensitive(buttons, k_button_names[i]);
        if (!b) continue;
        char where[48];
        snprintf(where, sizeof where, "buttons.%s", k_button_names[i]);
        if (!cJSON_IsObject(b)) {
            snprintf(err, errsz, "%s: %s: must be an object", path, where);
            rc = -1;
            break;
        }
        rc |= only_keys(b, k_button_fields, 2, path, where, err, errsz);
        if (!rc)
            rc |= get_ref(b, "controller", true, false, &t.controller_button[i], path, where, err,
                          errsz);
        if (!rc)
            rc |= get_ref(b, "joystick", false, false, &t.joystick_button[i], path, where, err,
                          errsz);
    }
    if (rc == 0)
        rc = get_num(root, "keyboard_ramp_s", 0.0, 10.0, &t.keyboard_ramp, path, "(top)", err,
                     errsz);
    cJSON_Delete(root);
    if (rc == 0) *m = t;
    return rc;
}

// ---- devices ---------------------------------------------------------------------

static void close_device(input* in) {
    if (in->gc)
        SDL_GameControllerClose(in->gc);
    else if (in->js)
        SDL_JoystickClose(in->js);
    in->gc = NULL;
    in->js = NULL;
    in->id = -1;
    in->name[0] = '\0';
}

static bool open_device(input* in, int index) {
    if (SDL_IsGameController(index)) {
        in->gc = SDL_GameControllerOpen(index);
        if (in->gc) in->js = SDL_GameControllerGetJoystick(in->gc);
    } else {
        in->js = SDL_JoystickOpen(index);
    }
    if (!in->js) {
        in->gc = NULL;
        return false;
    }
    in->id = SDL_JoystickInstanceID(in->js);
    const char* nm = in->gc ? SDL_GameControllerName(in->gc) : SDL_JoystickName(in->js);
    snprintf(in->name, sizeof in->name, "%s", nm ? nm : "joystick");
    return true;
}

static void open_first(input* in) {
    for (int i = 0; i < SDL_NumJoysticks() && !in->js; ++i)
        open_device(in, i);
}

input* input_create(const input_mapping* m) {
    input* in = calloc(1, sizeof *in);
    if (!in) return NULL;
    in->map = m ? *m : input_default_mapping();
    in->id = -1;
    in->camera_preset = -1;
    const Uint32 need[2] = {SDL_INIT_JOYSTICK, SDL_INIT_GAMECONTROLLER};
    for (int k = 0; k < 2; ++k)
        if (!SDL_WasInit(need[k])) {
            if (SDL_InitSubSystem(need[k]) == 0)
                in->own_subsystems |= need[k];
            else
                fprintf(stderr, "input: %s; keyboard only\n", SDL_GetError());
        }
    open_first(in);
    return in;
}

void input_destroy(input* in) {
    if (!in) return;
    close_device(in);
    if (in->own_subsystems) SDL_QuitSubSystem(in->own_subsystems);
    free(in);
}

static void press(input* in, int button) {
    switch (button) {
    case INPUT_BTN_HOOK:
        in->hook = true;
        break;
    case INPUT_BTN_PAUSE:
        in->pause = true;
        break;
    case INPUT_BTN_RESET:
        in->reset = true;
        break;
    case INPUT_BTN_SCREENSHOT:
        in->screenshot = true;
        break;
    case INPUT_BTN_CAMERA:
        in->camera_next = true;
        break;
    default:
        break;
    }
}

/// Keys: arrows up/down = lift, W/S = jib, arrows left/right (or A/D) = slew.
static void key_axis(input* in, SDL_Scancode sc, bool down) {
    switch (sc) {
    case SDL_SCANCODE_LSHIFT:
        in->shift[0] = down;
        break;
    case SDL_SCANCODE_RSHIFT:
        in->shift[1] = down;
        break;
    case SDL_SCANCODE_UP:
        in->key_pos[INPUT_LIFT] = down;
        break;
    case SDL_SCANCODE_DOWN:
        in->key_neg[INPUT_LIFT] = down;
        break;
    case SDL_SCANCODE_W:
        in->key_pos[INPUT_JIB] = down;
        break;
    case SDL_SCANCODE_S:
        in->key_neg[INPUT_JIB] = down;
        break;
    case SDL_SCANCODE_LEFT:
    case SDL_SCANCODE_A:
        in->key_pos[INPUT_SLEW] = down;
        break;
    case SDL_SCANCODE_RIGHT:
    case SDL_SCANCODE_D:
        in->key_neg[INPUT_SLEW] = down;
        break;
    default:
        break;
    }
}

// The keys that do what a device button does (press).
static int key_button(SDL_Scancode sc) {
    switch (sc) {
    case SDL_SCANCODE_H:
    case SDL_SCANCODE_RETURN:
        return INPUT_BTN_HOOK;
    case SDL_SCANCODE_P:
    case SDL_SCANCODE_SPACE:
        return INPUT_BTN_PAUSE;
    case SDL_SCANCODE_R:
    case SDL_SCANCODE_BACKSPACE:
        return INPUT_BTN_RESET;
    case SDL_SCANCODE_F12:
        return INPUT_BTN_SCREENSHOT;
    case SDL_SCANCODE_C:
        return INPUT_BTN_CAMERA;
    default:
        return -1;
    }
}

static bool key_edge(input* in, SDL_Scancode sc) {
    const int b = key_button(sc);
    if (b >= 0) {
        press(in, b);
        return true;
    }
    switch (sc) {
    case SDL_SCANCODE_F1:
        in->camera_preset = 0;
        return true;
    case SDL_SCANCODE_F2:
        in->camera_preset = 1;
        return true;
    case SDL_SCANCODE_F3:
        in->camera_preset = 2;
        return true;
    case SDL_SCANCODE_F4:
        in->camera_preset = 3;
        return true;
    case SDL_SCANCODE_ESCAPE:
        in->quit = true;
        return true;
    default:
        return false;
    }
}

bool input_handle_event(input* in, const SDL_Event* ev) {
    switch (ev->type) {
    case SDL_QUIT:
        in->quit = true;
        return true;
    case SDL_KEYDOWN:
        key_axis(in, ev->key.keysym.scancode, true);
        // Auto-repeat must not toggle the hook or pause again.
        if (!ev->key.repeat) key_edge(in, ev->key.keysym.scancode);
        return true;
    case SDL_KEYUP:
        key_axis(in, ev->key.keysym.scancode, false);
        return true;
    case SDL_WINDOWEVENT:
        // Key-up events go to the new focus: drop held keys so no axis sticks.
        if (ev->window.event != SDL_WINDOWEVENT_FOCUS_LOST) return false;
        memset(in->key_pos, 0, sizeof in->key_pos);
        memset(in->key_neg, 0, sizeof in->key_neg);
        memset(in->shift, 0, sizeof in->shift);
        return true;
    case SDL_JOYDEVICEADDED:
        // Game controllers also send CONTROLLERDEVICEADDED; this one covers both.
        if (!in->js) open_device(in, ev->jdevice.which);
        return true;
    case SDL_JOYDEVICEREMOVED:
        if (in->js && ev->jdevice.which == in->id) {
            close_device(in);
            // Another device may still be plugged in; else the keyboard rules.
            open_first(in);
        }
        return true;
    case SDL_CONTROLLERBUTTONDOWN:
        if (!in->gc || ev->cbutton.which != in->id) return false;
        for (int b = 0; b < INPUT_BUTTON_COUNT; ++b)
            if (in->map.controller_button[b] == ev->cbutton.button) press(in, b);
        return true;
    case SDL_JOYBUTTONDOWN:
        // Controllers report through CONTROLLERBUTTON events with names.
        if (in->gc || !in->js || ev->jbutton.which != in->id) return false;
        for (int b = 0; b < INPUT_BUTTON_COUNT; ++b)
            if (in->map.joystick_button[b] == ev->jbutton.button) press(in, b);
        return true;
    default:
        return false;
    }
}

static double device_axis(const input* in, int a) {
    const input_axis_map* m = &in->map.axis[a];
    double raw = 0;
    if (in->gc) {
        if (m->controller_axis < 0 || m->controller_axis >= SDL_CONTROLLER_AXIS_MAX) return 0;
        raw =
            SDL_GameControllerGetAxis(in->gc, (SDL_GameControllerAxis)m->controller_axis) / 32767.0;
    } else if (in->js) {
        if (m->joystick_axis < 0 || m->joystick_axis >= SDL_JoystickNumAxes(in->js)) return 0;
        raw = SDL_JoystickGetAxis(in->js, m->joystick_axis) / 32767.0;
    } else {
        return 0;
    }
    double y = input_shape(raw, m->dead_zone, m->expo) * m->scale;
    return m->invert ? -y : y;
}

void input_poll(input* in, double dt, input_command* out) {
    memset(out, 0, sizeof *out);
    double* dst[INPUT_AXIS_COUNT] = {&out->lift, &out->jib, &out->slew};
    // Fine mode: on/off keys open a valve fully, which swings the load by
    // about a metre; with Shift held they open it to INPUT_FINE_SCALE. The
    // ramp keeps its rate, so a key reaches the smaller opening sooner.
    out->fine = in->shift[0] || in->shift[1];
    const double key_gain = out->fine ? INPUT_FINE_SCALE : 1.0;
    for (int a = 0; a < INPUT_AXIS_COUNT; ++a) {
        double target = key_gain * ((in->key_pos[a] ? 1.0 : 0.0) - (in->key_neg[a] ? 1.0 : 0.0));
        // Rate-limit the keyboard so a key opens the valve over keyboard_ramp.
        double rate = in->map.keyboard_ramp > 0 ? dt / in->map.keyboard_ramp : 2.0;
        double d = target - in->kb[a];
        if (d > rate) d = rate;
        if (d < -rate) d = -rate;
        in->kb[a] += d;
        double v = device_axis(in, a) + in->kb[a];
        if (v > 1) v = 1;
        if (v < -1) v = -1;
        *dst[a] = v;
    }
    out->hook_toggle = in->hook;
    out->pause = in->pause;
    out->reset = in->reset;
    out->screenshot = in->screenshot;
    out->quit = in->quit;
    out->camera_next = in->camera_next;
    out->camera_preset = in->camera_preset;
    out->source = input_active_source(in);
    in->hook = in->pause = in->reset = in->screenshot = in->quit = in->camera_next = false;
    in->camera_preset = -1;
}

const char* input_device_name(const input* in) {
    return in->js ? in->name : NULL;
}

input_source input_active_source(const input* in) {
    return in->gc ? INPUT_SRC_CONTROLLER : in->js ? INPUT_SRC_JOYSTICK : INPUT_SRC_KEYBOARD;
}
