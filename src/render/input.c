// input.c: game controllers, plain joysticks and the keyboard -> one
// input_command per frame (see input.h for the why).
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "input.h"
#include "model_controls.h"

struct input {
    input_mapping map;
    SDL_GameController* gc; ///< active device if it is a game controller
    SDL_Joystick* js;       ///< active device's joystick (also set for gc)
    SDL_JoystickID id;      ///< its instance id, -1 if none
    char name[128];
    Uint32 own_subsystems; ///< SDL subsystems we started, to quit them again
    bool key_pos[INPUT_MAX_FN], key_neg[INPUT_MAX_FN];
    double kb[INPUT_MAX_FN]; ///< ramped keyboard contribution
    bool shift[2];               ///< left, right Shift held: fine mode (INPUT_FINE_SCALE)
    // Edges collected between polls.
    bool hook, pause, reset, screenshot, quit, camera_next, mapping_box;
    int camera_preset;
};

// ---- default layouts ---------------------------------------------------------------

// A place on the remote: one controller input (an axis, or a + / - pair),
// one on a plain joystick, a key pair. The two-lever layout's slots 0..7, in
// the order functions take them (docs/render.md "Mapping by function").
typedef struct slot {
    int controller_axis, pair[2]; // SDL axis, or the pair (INPUT_PAIR_BUTTON + button)
    bool invert;                  // stick y: SDL gives + for down, the crane wants up = +
    int joystick_axis, joystick_button[2];
    SDL_Scancode key[2], key_alt[2];
} slot;

#define PB(b) (INPUT_PAIR_BUTTON + (b))
// Two-lever: the left lever (stick) carries the main boom (y) and the slew
// (x), the right one the outer boom (y) and the extension (x), as on the
// common two-lever radio remote; more functions go to the triggers, the
// shoulder buttons and the d-pad. Slot 0..2 are today's lift, jib, slew.
static const slot k_two_lever[8] = {
    {SDL_CONTROLLER_AXIS_LEFTY, {-1, -1}, true, 1, {-1, -1}, {SDL_SCANCODE_UP, SDL_SCANCODE_DOWN}, {0, 0}},
    {SDL_CONTROLLER_AXIS_RIGHTY, {-1, -1}, true, 3, {-1, -1}, {SDL_SCANCODE_W, SDL_SCANCODE_S}, {0, 0}},
    // Slew: stick left turns counter-clockwise seen from above (+), so inverted.
    {SDL_CONTROLLER_AXIS_LEFTX, {-1, -1}, true, 0, {-1, -1}, {SDL_SCANCODE_LEFT, SDL_SCANCODE_RIGHT},
     {SDL_SCANCODE_A, SDL_SCANCODE_D}},
    // Extension: stick right extends (SDL x is + to the right).
    {SDL_CONTROLLER_AXIS_RIGHTX, {-1, -1}, false, 2, {-1, -1}, {SDL_SCANCODE_PAGEUP, SDL_SCANCODE_PAGEDOWN}, {0, 0}},
    {-1, {SDL_CONTROLLER_AXIS_TRIGGERRIGHT, SDL_CONTROLLER_AXIS_TRIGGERLEFT}, false, 4, {-1, -1},
     {SDL_SCANCODE_HOME, SDL_SCANCODE_END}, {0, 0}},
    {-1, {PB(SDL_CONTROLLER_BUTTON_RIGHTSHOULDER), PB(SDL_CONTROLLER_BUTTON_LEFTSHOULDER)}, false, 5, {-1, -1},
     {SDL_SCANCODE_INSERT, SDL_SCANCODE_DELETE}, {0, 0}},
    // Plain joysticks: raw buttons 4, 5 (shoulders on most pads) and 9, 10
    // (stick clicks): none of them a default button (0, 2, 3, 6, 7).
    {-1, {PB(SDL_CONTROLLER_BUTTON_DPAD_UP), PB(SDL_CONTROLLER_BUTTON_DPAD_DOWN)}, false, -1, {5, 4},
     {SDL_SCANCODE_I, SDL_SCANCODE_K}, {0, 0}},
    {-1, {PB(SDL_CONTROLLER_BUTTON_DPAD_RIGHT), PB(SDL_CONTROLLER_BUTTON_DPAD_LEFT)}, false, -1, {10, 9},
     {SDL_SCANCODE_O, SDL_SCANCODE_L}, {0, 0}},
};
// Functions 9..12: keys only (a gamepad has no ninth two-way input left).
static const SDL_Scancode k_extra_keys[4][2] = {{SDL_SCANCODE_U, SDL_SCANCODE_J},
                                                {SDL_SCANCODE_KP_8, SDL_SCANCODE_KP_2},
                                                {SDL_SCANCODE_KP_9, SDL_SCANCODE_KP_3},
                                                {SDL_SCANCODE_KP_7, SDL_SCANCODE_KP_1}};
// Four-lever (linear levers of a valve bank, one per function, left to
// right in the model's order): keys in keyboard columns, + on the upper row.
static const SDL_Scancode k_four_lever_keys[INPUT_MAX_FN][2] = {
    {SDL_SCANCODE_Q, SDL_SCANCODE_A},         {SDL_SCANCODE_W, SDL_SCANCODE_S},
    {SDL_SCANCODE_E, SDL_SCANCODE_D},         {SDL_SCANCODE_T, SDL_SCANCODE_F},
    {SDL_SCANCODE_U, SDL_SCANCODE_J},         {SDL_SCANCODE_I, SDL_SCANCODE_K},
    {SDL_SCANCODE_O, SDL_SCANCODE_L},         {SDL_SCANCODE_PAGEUP, SDL_SCANCODE_PAGEDOWN},
    {SDL_SCANCODE_HOME, SDL_SCANCODE_END},    {SDL_SCANCODE_INSERT, SDL_SCANCODE_DELETE},
    {SDL_SCANCODE_UP, SDL_SCANCODE_DOWN},     {SDL_SCANCODE_LEFT, SDL_SCANCODE_RIGHT}};

// The sense that feels right for function name on controller axis axis (-1:
// a + / - pair, which says its sense itself). SDL gives + for a stick down
// or right: up raises (inverted); on an x axis a function extends to the
// right, but the slew turns counter-clockwise seen from above (+) to the
// left, so only the slew is inverted there.
static bool natural_invert(const char* name, int axis) {
    switch (axis) {
    case SDL_CONTROLLER_AXIS_LEFTY:
    case SDL_CONTROLLER_AXIS_RIGHTY:
        return true;
    case SDL_CONTROLLER_AXIS_LEFTX:
    case SDL_CONTROLLER_AXIS_RIGHTX:
        return !strcmp(name, "slew");
    default:
        return false;
    }
}

static void set_common(input_mapping* m) {
    const int cb[INPUT_BUTTON_COUNT] = {SDL_CONTROLLER_BUTTON_A, SDL_CONTROLLER_BUTTON_START,
                                        SDL_CONTROLLER_BUTTON_BACK, SDL_CONTROLLER_BUTTON_Y,
                                        SDL_CONTROLLER_BUTTON_X};
    const int jb[INPUT_BUTTON_COUNT] = {0, 7, 6, 3, 2};
    for (int i = 0; i < INPUT_BUTTON_COUNT; ++i) {
        m->controller_button[i] = cb[i];
        m->joystick_button[i] = jb[i];
    }
    m->keyboard_ramp = 0.25;
}

static void put_slot(input_axis_map* a, const slot* sl) {
    a->controller_axis = sl->controller_axis;
    a->controller_pair[0] = sl->pair[0];
    a->controller_pair[1] = sl->pair[1];
    a->invert = sl->invert;
    a->joystick_axis = sl->joystick_axis;
    a->joystick_button[0] = sl->joystick_button[0];
    a->joystick_button[1] = sl->joystick_button[1];
    a->key[0] = sl->key[0];
    a->key[1] = sl->key[1];
    a->key_alt[0] = sl->key_alt[0];
    a->key_alt[1] = sl->key_alt[1];
}

static void unbound(input_axis_map* a) {
    a->controller_axis = a->joystick_axis = -1;
    a->controller_pair[0] = a->controller_pair[1] = -1;
    a->joystick_button[0] = a->joystick_button[1] = -1;
    a->key[0] = a->key[1] = a->key_alt[0] = a->key_alt[1] = 0;
    a->invert = false;
}

int input_layout_mapping(const char* const* names, int n, const char* layout, input_mapping* m, char* err,
                         size_t errsz) {
    char dummy[8];
    if (!err || !errsz) err = dummy, errsz = sizeof dummy;
    const bool four = layout && !strcmp(layout, "four-lever");
    if (layout && layout[0] && !four && strcmp(layout, "two-lever")) {
        snprintf(err, errsz, "layout \"%s\": must be two-lever or four-lever", layout);
        return -1;
    }
    if (n < 1 || n > INPUT_MAX_FN) {
        snprintf(err, errsz, "%d functions: the input mapping takes 1 to %d", n, INPUT_MAX_FN);
        return -1;
    }
    input_mapping t;
    memset(&t, 0, sizeof t);
    snprintf(t.layout, sizeof t.layout, "%s", four ? "four-lever" : "two-lever");
    t.naxis = n;
    for (int i = 0; i < n; ++i) {
        if (!names[i] || !names[i][0] || strlen(names[i]) >= sizeof t.axis[i].name) {
            snprintf(err, errsz, "function %d: a name of 1 to %zu characters", i + 1, sizeof t.axis[i].name - 1);
            return -1;
        }
        for (int k = 0; k < i; ++k)
            if (!strcmp(names[k], names[i])) {
                snprintf(err, errsz, "function '%s' twice", names[i]);
                return -1;
            }
        snprintf(t.axis[i].name, sizeof t.axis[i].name, "%s", names[i]);
        unbound(&t.axis[i]);
        t.axis[i].dead_zone = 0.08;
        t.axis[i].expo = 0.3;
        t.axis[i].scale = 1.0;
    }
    // Slot of each function: two-lever by role first (lift, jib, slew keep
    // today's sticks and keys whatever the model's order), then the rest in
    // order into the free slots; four-lever strictly in order.
    int slot_of[INPUT_MAX_FN];
    bool taken[INPUT_MAX_FN] = {false};
    static const char* const roles[3] = {"lift", "jib", "slew"};
    for (int i = 0; i < n; ++i) {
        slot_of[i] = -1;
        for (int r = 0; r < 3 && !four; ++r)
            if (!strcmp(names[i], roles[r])) slot_of[i] = r, taken[r] = true;
    }
    for (int i = 0, next = 0; i < n; ++i) {
        if (slot_of[i] >= 0) continue;
        while (taken[next]) ++next;
        slot_of[i] = next;
        taken[next] = true;
    }
    for (int i = 0; i < n; ++i) {
        const int k = slot_of[i];
        input_axis_map* a = &t.axis[i];
        if (k < 8) put_slot(a, &k_two_lever[k]);
        if (four) {
            // The same device inputs in order, keys by lever column.
            a->key_alt[0] = a->key_alt[1] = 0;
            a->key[0] = k_four_lever_keys[k][0];
            a->key[1] = k_four_lever_keys[k][1];
        } else if (k >= 8) {
            a->key[0] = k_extra_keys[k - 8][0];
            a->key[1] = k_extra_keys[k - 8][1];
        }
        a->invert = natural_invert(names[i], a->controller_axis);
    }
    set_common(&t);
    *m = t;
    return 0;
}

input_mapping input_default_mapping(void) {
    static const char* const names[INPUT_AXIS_COUNT] = {"lift", "jib", "slew"};
    input_mapping m;
    input_layout_mapping(names, INPUT_AXIS_COUNT, NULL, &m, NULL, 0);
    return m;
}

int input_find_function(const input_mapping* m, const char* name) {
    for (int i = 0; i < m->naxis; ++i)
        if (!strcmp(m->axis[i].name, name)) return i;
    return -1;
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

// ---- mapping file and the model's controls ------------------------------------------

// A controller input name (model_controls checked it against its lists, and
// test_input_map that SDL knows each) as an axis number or INPUT_PAIR_BUTTON
// + button; -1 for "" (unbound).
static int controller_code(const char* name, bool axis_first) {
    if (!name[0]) return -1;
    const int a = axis_first ? (int)SDL_GameControllerGetAxisFromString(name) : -1;
    if (a >= 0) return a;
    const int b = (int)SDL_GameControllerGetButtonFromString(name);
    return b >= 0 ? INPUT_PAIR_BUTTON + b : -1;
}

int input_apply_controls(input_mapping* m, const model_controls* c, const char* file, const char* where,
                         char* err, size_t errsz) {
    char dummy[8];
    if (!err || !errsz) err = dummy, errsz = sizeof dummy;
    const char* names[INPUT_MAX_FN];
    for (int i = 0; i < m->naxis; ++i) names[i] = m->axis[i].name;
    if (controls_check_functions(c, names, m->naxis, file, where, err, errsz)) return -1;
    // Work on a copy so a refused mapping leaves the caller's untouched.
    input_mapping t = *m;
    for (int i = 0; i < c->nfn; ++i) {
        const controls_fn* f = &c->fn[i];
        input_axis_map* a = &t.axis[input_find_function(&t, f->function)];
        if (f->has_controller) {
            a->controller_axis = a->controller_pair[0] = a->controller_pair[1] = -1;
            if (f->ncontroller == 1) a->controller_axis = controller_code(f->controller[0], true);
            for (int k = 0; k < 2 && f->ncontroller == 2; ++k)
                a->controller_pair[k] = controller_code(f->controller[k], true);
        }
        // A raw axis and a raw button pair replace each other, as a
        // controller axis and a pair do: given one alone, the other goes.
        if (f->has_joystick || f->has_joystick_buttons) {
            a->joystick_axis = f->has_joystick ? f->joystick : -1;
            a->joystick_button[0] = f->has_joystick_buttons ? f->joystick_button[0] : -1;
            a->joystick_button[1] = f->has_joystick_buttons ? f->joystick_button[1] : -1;
        }
        if (f->has_keys) {
            // A function's keys given are its keys: the default's second pair goes.
            for (int k = 0; k < 2; ++k)
                a->key[k] = f->key[k][0] ? (int)SDL_GetScancodeFromName(f->key[k]) : 0;
            a->key_alt[0] = a->key_alt[1] = 0;
        }
        if (f->has_invert) a->invert = f->invert;
        if (!isnan(f->dead_zone)) a->dead_zone = f->dead_zone;
        if (!isnan(f->expo)) a->expo = f->expo;
        if (!isnan(f->scale)) a->scale = f->scale;
    }
    for (int b = 0; b < INPUT_BUTTON_COUNT; ++b) {
        if (c->has_button_controller[b])
            t.controller_button[b] = c->button_controller[b][0]
                                         ? (int)SDL_GameControllerGetButtonFromString(c->button_controller[b])
                                         : -1;
        if (c->has_button_joystick[b]) t.joystick_button[b] = c->button_joystick[b];
    }
    if (!isnan(c->keyboard_ramp_s)) t.keyboard_ramp = c->keyboard_ramp_s;
    // One key, one function: a key pair of the mapping that another function
    // also has would move both valves at once.
    for (int i = 0; i < t.naxis; ++i)
        for (int k = 0; k < 4; ++k) {
            const int key = k < 2 ? t.axis[i].key[k] : t.axis[i].key_alt[k - 2];
            for (int j = 0; key && j <= i; ++j)
                for (int l = 0; l < 4; ++l) {
                    const int other = l < 2 ? t.axis[j].key[l] : t.axis[j].key_alt[l - 2];
                    if (other != key || (j == i && l >= k)) continue;
                    snprintf(err, errsz, "%s: %s%saxes.%s.keys: key \"%s\" is also a key of '%s'", file, where,
                             where[0] ? "." : "", t.axis[i].name, SDL_GetScancodeName((SDL_Scancode)key),
                             t.axis[j].name);
                    return -1;
                }
        }
    *m = t;
    return 0;
}

int input_load_mapping(const char* path, input_mapping* m, char* err, size_t errsz) {
    char dummy[8];
    if (!err || !errsz) err = dummy, errsz = sizeof dummy;
    model_controls* c = malloc(sizeof *c);
    if (!c) {
        snprintf(err, errsz, "%s: out of memory", path);
        return -1;
    }
    int rc = controls_load_file(path, c, err, errsz);
    if (rc == 0) rc = input_apply_controls(m, c, path, "", err, errsz);
    free(c);
    return rc;
}

// "left stick Y" for the HUD: what the operator sees on the pad.
static const char* controller_input_name(int code) {
    switch (code) {
    case SDL_CONTROLLER_AXIS_LEFTX: return "left stick X";
    case SDL_CONTROLLER_AXIS_LEFTY: return "left stick Y";
    case SDL_CONTROLLER_AXIS_RIGHTX: return "right stick X";
    case SDL_CONTROLLER_AXIS_RIGHTY: return "right stick Y";
    case SDL_CONTROLLER_AXIS_TRIGGERLEFT: return "LT";
    case SDL_CONTROLLER_AXIS_TRIGGERRIGHT: return "RT";
    case PB(SDL_CONTROLLER_BUTTON_LEFTSHOULDER): return "LB";
    case PB(SDL_CONTROLLER_BUTTON_RIGHTSHOULDER): return "RB";
    case PB(SDL_CONTROLLER_BUTTON_DPAD_UP): return "d-pad up";
    case PB(SDL_CONTROLLER_BUTTON_DPAD_DOWN): return "d-pad down";
    case PB(SDL_CONTROLLER_BUTTON_DPAD_LEFT): return "d-pad left";
    case PB(SDL_CONTROLLER_BUTTON_DPAD_RIGHT): return "d-pad right";
    default:
        if (code >= INPUT_PAIR_BUTTON) {
            const char* b = SDL_GameControllerGetStringForButton((SDL_GameControllerButton)(code - INPUT_PAIR_BUTTON));
            return b ? b : "?";
        }
        return "-";
    }
}

static void cat(char* out, size_t n, size_t* len, const char* fmt, const char* a, const char* b) {
    if (*len >= n) return;
    const int w = snprintf(out + *len, n - *len, fmt, a, b);
    if (w > 0) *len += (size_t)w < n - *len ? (size_t)w : n - *len - 1;
}

int input_mapping_text(const input_mapping* m, char* out, size_t n) {
    if (!n) return 0;
    size_t len = 0;
    out[0] = '\0';
    for (int i = 0; i < m->naxis; ++i) {
        const input_axis_map* a = &m->axis[i];
        char dev[48], js[32], keys[64];
        // The device input, with the side that gives + first for a pair.
        if (a->controller_axis >= 0)
            snprintf(dev, sizeof dev, "%s%s", controller_input_name(a->controller_axis), a->invert ? " (inv)" : "");
        else if (a->controller_pair[0] >= 0 || a->controller_pair[1] >= 0)
            snprintf(dev, sizeof dev, "%s / %s", controller_input_name(a->controller_pair[0]),
                     controller_input_name(a->controller_pair[1]));
        else
            snprintf(dev, sizeof dev, "-");
        if (a->joystick_axis >= 0)
            snprintf(js, sizeof js, "axis %d", a->joystick_axis);
        else if (a->joystick_button[0] >= 0 || a->joystick_button[1] >= 0)
            snprintf(js, sizeof js, "btn %d / %d", a->joystick_button[0], a->joystick_button[1]);
        else
            snprintf(js, sizeof js, "-");
        if (a->key[0] || a->key[1]) {
            snprintf(keys, sizeof keys, "%s / %s", a->key[0] ? SDL_GetScancodeName((SDL_Scancode)a->key[0]) : "-",
                     a->key[1] ? SDL_GetScancodeName((SDL_Scancode)a->key[1]) : "-");
            if (a->key_alt[0] || a->key_alt[1])
                snprintf(keys + strlen(keys), sizeof keys - strlen(keys), " (%s / %s)",
                         a->key_alt[0] ? SDL_GetScancodeName((SDL_Scancode)a->key_alt[0]) : "-",
                         a->key_alt[1] ? SDL_GetScancodeName((SDL_Scancode)a->key_alt[1]) : "-");
        } else {
            snprintf(keys, sizeof keys, "-");
        }
        cat(out, n, &len, "%-8s %s", a->name, dev);
        cat(out, n, &len, " | %s | %s\n", js, keys);
    }
    return (int)len;
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

void input_set_mapping(input* in, const input_mapping* m) {
    in->map = *m;
    memset(in->key_pos, 0, sizeof in->key_pos);
    memset(in->key_neg, 0, sizeof in->key_neg);
    memset(in->kb, 0, sizeof in->kb);
}

const input_mapping* input_get_mapping(const input* in) { return &in->map; }

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

/// A function's key pair (and its second pair) held or released; Shift for fine mode.
static void key_axis(input* in, SDL_Scancode sc, bool down) {
    if (sc == SDL_SCANCODE_LSHIFT || sc == SDL_SCANCODE_RSHIFT) {
        in->shift[sc == SDL_SCANCODE_RSHIFT] = down;
        return;
    }
    for (int i = 0; i < in->map.naxis; ++i) {
        const input_axis_map* a = &in->map.axis[i];
        if ((int)sc == a->key[0] || (int)sc == a->key_alt[0]) in->key_pos[i] = down;
        if ((int)sc == a->key[1] || (int)sc == a->key_alt[1]) in->key_neg[i] = down;
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
    case SDL_SCANCODE_M:
        in->mapping_box = true;
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

// A controller pair input in [0, 1]: a trigger's travel or a button.
static double pair_input(const input* in, int code) {
    if (code < 0) return 0;
    if (code >= INPUT_PAIR_BUTTON)
        return SDL_GameControllerGetButton(in->gc, (SDL_GameControllerButton)(code - INPUT_PAIR_BUTTON)) ? 1.0 : 0.0;
    if (code >= SDL_CONTROLLER_AXIS_MAX) return 0;
    const double v = SDL_GameControllerGetAxis(in->gc, (SDL_GameControllerAxis)code) / 32767.0;
    return v > 0 ? v : 0; // a trigger reads 0..32767; a stick half as a pair gives its + side
}

static double device_axis(const input* in, int a) {
    const input_axis_map* m = &in->map.axis[a];
    double raw = 0;
    bool pair = false;
    if (in->gc) {
        pair = m->controller_axis < 0;
        if (m->controller_axis >= 0 && m->controller_axis < SDL_CONTROLLER_AXIS_MAX)
            raw = SDL_GameControllerGetAxis(in->gc, (SDL_GameControllerAxis)m->controller_axis) / 32767.0;
        else if (pair)
            raw = pair_input(in, m->controller_pair[0]) - pair_input(in, m->controller_pair[1]);
    } else if (in->js) {
        pair = m->joystick_axis < 0;
        if (m->joystick_axis >= 0) {
            if (m->joystick_axis >= SDL_JoystickNumAxes(in->js)) return 0;
            raw = SDL_JoystickGetAxis(in->js, m->joystick_axis) / 32767.0;
        } else {
            const int nb = SDL_JoystickNumButtons(in->js);
            for (int k = 0; k < 2; ++k) {
                const int b = m->joystick_button[k];
                if (b >= 0 && b < nb && SDL_JoystickGetButton(in->js, b)) raw += k ? -1.0 : 1.0;
            }
        }
    } else {
        return 0;
    }
    double y = input_shape(raw, m->dead_zone, m->expo) * m->scale;
    // invert is an axis' sense; a pair says its sense by its order (+ first).
    return m->invert && !pair ? -y : y;
}

void input_poll(input* in, double dt, input_command* out) {
    memset(out, 0, sizeof *out);
    // Fine mode: on/off keys open a valve fully, which swings the load by
    // about a metre; with Shift held they open it to INPUT_FINE_SCALE. The
    // ramp keeps its rate, so a key reaches the smaller opening sooner.
    out->fine = in->shift[0] || in->shift[1];
    const double key_gain = out->fine ? INPUT_FINE_SCALE : 1.0;
    out->n = in->map.naxis;
    for (int a = 0; a < in->map.naxis; ++a) {
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
        out->u[a] = v;
        const char* nm = in->map.axis[a].name;
        if (!strcmp(nm, "lift")) out->lift = v;
        else if (!strcmp(nm, "jib")) out->jib = v;
        else if (!strcmp(nm, "slew")) out->slew = v;
    }
    out->hook_toggle = in->hook;
    out->pause = in->pause;
    out->reset = in->reset;
    out->screenshot = in->screenshot;
    out->quit = in->quit;
    out->camera_next = in->camera_next;
    out->camera_preset = in->camera_preset;
    out->mapping_box = in->mapping_box;
    out->source = input_active_source(in);
    in->hook = in->pause = in->reset = in->screenshot = in->quit = in->camera_next = in->mapping_box = false;
    in->camera_preset = -1;
}

const char* input_device_name(const input* in) {
    return in->js ? in->name : NULL;
}

input_source input_active_source(const input* in) {
    return in->gc ? INPUT_SRC_CONTROLLER : in->js ? INPUT_SRC_JOYSTICK : INPUT_SRC_KEYBOARD;
}
