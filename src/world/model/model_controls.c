// model_controls.c: the "controls" section / mapping file parser (see
// model_controls.h for the why). No SDL: names are checked against lists in
// SDL's spelling, and input.c (tests/render/test_input_map.c) checks that SDL
// knows every one of them.
#include "model_controls.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "json_util.h"

const char* const controls_controller_axes[] = {"leftx",       "lefty",        "rightx", "righty",
                                                "lefttrigger", "righttrigger", NULL};
const char* const controls_controller_buttons[] = {"a",
                                                   "b",
                                                   "x",
                                                   "y",
                                                   "back",
                                                   "guide",
                                                   "start",
                                                   "leftstick",
                                                   "rightstick",
                                                   "leftshoulder",
                                                   "rightshoulder",
                                                   "dpup",
                                                   "dpdown",
                                                   "dpleft",
                                                   "dpright",
                                                   "misc1",
                                                   "paddle1",
                                                   "paddle2",
                                                   "paddle3",
                                                   "paddle4",
                                                   "touchpad",
                                                   NULL};
// Keys a function may have: letters and digits the window does not use,
// arrows, the navigation block, the keypad and punctuation. SDL's scancode
// names (SDL_GetScancodeName), so input.c finds each with SDL_GetScancodeFromName.
const char* const controls_keys[] = {
    "A",        "B",        "D",        "E",        "F",        "I",        "J",        "K",
    "L",        "N",        "O",        "Q",        "S",        "T",        "U",        "V",
    "W",        "X",        "Y",        "Z",        "1",        "2",        "3",        "4",
    "5",        "6",        "7",        "8",        "9",        "0",        "Up",       "Down",
    "Left",     "Right",    "Insert",   "Home",     "PageUp",   "Delete",   "End",      "PageDown",
    "Keypad 0", "Keypad 1", "Keypad 2", "Keypad 3", "Keypad 4", "Keypad 5", "Keypad 6", "Keypad 7",
    "Keypad 8", "Keypad 9", "Keypad +", "Keypad -", "Keypad *", "Keypad /", "[",        "]",
    ";",        "'",        ",",        ".",        "/",        "-",        "=",        NULL};
// The drive window's own keys (input.c, drive_session.c, render.c): a
// function on one of them would move a valve each time the operator hooks,
// pauses or opens the panel.
const char* const controls_window_keys[][2] = {{"H", "hook"},           {"Return", "hook"},
                                               {"P", "pause"},          {"Space", "pause"},
                                               {"R", "reset"},          {"Backspace", "reset"},
                                               {"C", "next camera"},    {"G", "collision view"},
                                               {"Tab", "panel"},        {"Escape", "quit"},
                                               {"Left Shift", "fine"},  {"Right Shift", "fine"},
                                               {"F1", "camera preset"}, {"F2", "camera preset"},
                                               {"F3", "camera preset"}, {"F4", "camera preset"},
                                               {"F5", "record"},        {"M", "mapping box"},
                                               {"F12", "screenshot"},   {NULL, NULL}};
const char* const controls_button_names[CONTROLS_NBUTTON] = {"hook", "pause", "reset", "screenshot",
                                                             "camera"};
const char* const controls_layouts[] = {"two-lever", "four-lever", NULL};

const char* controls_lookup(const char* const* list, const char* name) {
    for (int i = 0; name && list[i]; ++i)
        if (!strcasecmp(list[i], name)) return list[i];
    return NULL;
}

typedef struct pctx {
    const char* file;
    const char* where; // "controls" or ""
    char* err;
    size_t errsz;
} pctx;

// "where.a.b" or "a.b" at the top of a mapping file.
static void fail(const pctx* p, const char* field, const char* problem) {
    snprintf(p->err, p->errsz, "%s: %s%s%s: %s", p->file, p->where,
             p->where[0] && field[0] ? "." : "", field, problem);
}

static void list_of(const char* const* list, char* out, size_t n) {
    out[0] = '\0';
    for (int i = 0; list[i]; ++i)
        snprintf(out + strlen(out), n - strlen(out), "%s%s", i ? ", " : "", list[i]);
}

/// Every key of o must be one of the names in allowed (NULL-terminated): a
/// field the format does not have is a typo, and skipping it would leave the
/// setting the user meant at its default.
static int only_keys(const pctx* p, const cJSON* o, const char* const* allowed, const char* field) {
    for (const cJSON* k = o->child; k; k = k->next) {
        bool ok = false;
        for (int i = 0; allowed[i] && !ok; ++i)
            ok = k->string && !strcmp(k->string, allowed[i]);
        if (ok) continue;
        char list[200], f[96], msg[300];
        list_of(allowed, list, sizeof list);
        snprintf(f, sizeof f, "%s%s%s", field, field[0] ? "." : "", k->string ? k->string : "?");
        snprintf(msg, sizeof msg, "unknown field (expected %s)", list);
        fail(p, f, msg);
        return -1;
    }
    return 0;
}

static int get_num(const pctx* p, const cJSON* o, const char* field, const char* key, double lo,
                   double hi, double* out) {
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v) return 0;
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= lo && v->valuedouble <= hi)) {
        char f[96], msg[96];
        snprintf(f, sizeof f, "%s%s%s", field, field[0] ? "." : "", key);
        snprintf(msg, sizeof msg, "must be a number in [%g, %g]", lo, hi);
        fail(p, f, msg);
        return -1;
    }
    *out = v->valuedouble;
    return 0;
}

static bool is_none(const cJSON* v) {
    return cJSON_IsNull(v) || (cJSON_IsString(v) && !strcmp(v->valuestring, "none"));
}

// A raw joystick index 0..255 into *out, or -1 for none.
static int get_index(const pctx* p, const cJSON* v, const char* field, const char* what, int* out) {
    if (is_none(v)) {
        *out = -1;
        return 0;
    }
    if (!cJSON_IsNumber(v) || v->valuedouble < 0 || v->valuedouble > 255 ||
        v->valuedouble != floor(v->valuedouble)) {
        char msg[80];
        snprintf(msg, sizeof msg, "must be a joystick %s index 0..255 or null", what);
        fail(p, field, msg);
        return -1;
    }
    *out = v->valueint;
    return 0;
}

// A controller name of one of the lists into out ("" for none).
static int get_name(const pctx* p, const cJSON* v, const char* field, bool axis_ok, bool button_ok,
                    char* out, size_t n) {
    if (is_none(v)) {
        out[0] = '\0';
        return 0;
    }
    const char* s = cJSON_IsString(v) ? v->valuestring : NULL;
    const char* hit = axis_ok ? controls_lookup(controls_controller_axes, s) : NULL;
    if (!hit && button_ok) hit = controls_lookup(controls_controller_buttons, s);
    if (!hit) {
        char msg[200];
        snprintf(msg, sizeof msg, "unknown game controller %s \"%s\" (e.g. %s)",
                 axis_ok && button_ok ? "axis or button"
                 : axis_ok            ? "axis"
                                      : "button",
                 s ? s : "?",
                 axis_ok ? "leftx, lefty, rightx, righty, lefttrigger" : "a, b, x, y, start, back");
        if (axis_ok && button_ok)
            snprintf(msg + strlen(msg) - 1, sizeof msg - strlen(msg) + 1, "; leftshoulder, dpup)");
        fail(p, field, msg);
        return -1;
    }
    snprintf(out, n, "%s", hit);
    return 0;
}

static int get_key(const pctx* p, const cJSON* v, const char* field, char* out, size_t n) {
    if (is_none(v)) {
        out[0] = '\0';
        return 0;
    }
    const char* s = cJSON_IsString(v) ? v->valuestring : NULL;
    for (int i = 0; s && controls_window_keys[i][0]; ++i)
        if (!strcasecmp(s, controls_window_keys[i][0])) {
            char msg[160];
            snprintf(msg, sizeof msg, "key \"%s\" is the window's (%s); choose another",
                     controls_window_keys[i][0], controls_window_keys[i][1]);
            fail(p, field, msg);
            return -1;
        }
    const char* hit = controls_lookup(controls_keys, s);
    if (!hit) {
        char msg[200];
        snprintf(msg, sizeof msg,
                 "unknown key \"%s\" (SDL key names: A..Z, 0..9, Up, Down, Left, Right, PageUp, "
                 "Home, Insert, Keypad 8, ...)",
                 s ? s : "?");
        fail(p, field, msg);
        return -1;
    }
    snprintf(out, n, "%s", hit);
    return 0;
}

// A pair [+, -] (array of 2) of what get_one reads.
static int get_pair_len(const pctx* p, const cJSON* v, const char* field) {
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2) {
        fail(p, field, "must be [plus, minus] (two entries) or null");
        return -1;
    }
    return 0;
}

static int parse_fn(const pctx* p, const cJSON* a, const char* name, controls_fn* f) {
    char field[64];
    snprintf(field, sizeof field, "axes.%s", name);
    memset(f, 0, sizeof *f);
    snprintf(f->function, sizeof f->function, "%s", name);
    f->dead_zone = f->expo = f->scale = NAN;
    f->joystick = -1;
    f->joystick_button[0] = f->joystick_button[1] = -1;
    if (!cJSON_IsObject(a)) {
        fail(p, field, "must be an object");
        return -1;
    }
    static const char* const fields[] = {"controller", "joystick", "joystick_buttons",
                                         "keys",       "invert",   "dead_zone",
                                         "expo",       "scale",    NULL};
    if (only_keys(p, a, fields, field)) return -1;
    char sub[96];
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(a, "controller");
    if (v) {
        f->has_controller = true;
        snprintf(sub, sizeof sub, "%s.controller", field);
        if (cJSON_IsArray(v)) {
            if (get_pair_len(p, v, sub)) return -1;
            for (int k = 0; k < 2; ++k) {
                char one[104];
                snprintf(one, sizeof one, "%s[%d]", sub, k);
                if (get_name(p, cJSON_GetArrayItem(v, k), one, true, true, f->controller[k],
                             sizeof f->controller[k]))
                    return -1;
            }
            f->ncontroller = 2;
            if (!f->controller[0][0] && !f->controller[1][0]) f->ncontroller = 0;
        } else {
            if (get_name(p, v, sub, true, false, f->controller[0], sizeof f->controller[0]))
                return -1;
            f->ncontroller = f->controller[0][0] ? 1 : 0;
        }
    }
    v = cJSON_GetObjectItemCaseSensitive(a, "joystick");
    if (v) {
        f->has_joystick = true;
        snprintf(sub, sizeof sub, "%s.joystick", field);
        if (get_index(p, v, sub, "axis", &f->joystick)) return -1;
    }
    v = cJSON_GetObjectItemCaseSensitive(a, "joystick_buttons");
    if (v) {
        f->has_joystick_buttons = true;
        snprintf(sub, sizeof sub, "%s.joystick_buttons", field);
        if (!is_none(v)) {
            if (get_pair_len(p, v, sub)) return -1;
            for (int k = 0; k < 2; ++k)
                if (get_index(p, cJSON_GetArrayItem(v, k), sub, "button", &f->joystick_button[k]))
                    return -1;
        }
    }
    v = cJSON_GetObjectItemCaseSensitive(a, "keys");
    if (v) {
        f->has_keys = true;
        snprintf(sub, sizeof sub, "%s.keys", field);
        if (!is_none(v)) {
            if (get_pair_len(p, v, sub)) return -1;
            for (int k = 0; k < 2; ++k) {
                char one[104];
                snprintf(one, sizeof one, "%s[%d]", sub, k);
                if (get_key(p, cJSON_GetArrayItem(v, k), one, f->key[k], sizeof f->key[k]))
                    return -1;
            }
            if (f->key[0][0] && !strcmp(f->key[0], f->key[1])) {
                fail(p, sub, "the same key for + and -");
                return -1;
            }
        }
    }
    if (get_num(p, a, field, "dead_zone", 0.0, 0.94, &f->dead_zone)) return -1;
    if (get_num(p, a, field, "expo", 0.0, 1.0, &f->expo)) return -1;
    if (get_num(p, a, field, "scale", 0.01, 1.0, &f->scale)) return -1;
    v = cJSON_GetObjectItemCaseSensitive(a, "invert");
    if (v) {
        if (!cJSON_IsBool(v)) {
            snprintf(sub, sizeof sub, "%s.invert", field);
            fail(p, sub, "must be true or false");
            return -1;
        }
        f->has_invert = true;
        f->invert = cJSON_IsTrue(v);
    }
    return 0;
}

int controls_parse(const cJSON* o, const char* file, const char* where, model_controls* out,
                   char* err, size_t errsz) {
    char dummy[8];
    if (!err || !errsz) err = dummy, errsz = sizeof dummy;
    const pctx p = {file, where ? where : "", err, errsz};
    memset(out, 0, sizeof *out);
    out->keyboard_ramp_s = NAN;
    for (int i = 0; i < CONTROLS_NBUTTON; ++i)
        out->button_joystick[i] = -1;
    if (!cJSON_IsObject(o)) {
        fail(&p, "", "must be an object");
        return -1;
    }
    static const char* const top[] = {"layout", "axes", "buttons", "keyboard_ramp_s", NULL};
    if (only_keys(&p, o, top, "")) return -1;
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, "layout");
    if (v) {
        const char* hit =
            cJSON_IsString(v) ? controls_lookup(controls_layouts, v->valuestring) : NULL;
        if (!hit) {
            fail(&p, "layout", "must be \"two-lever\" or \"four-lever\"");
            return -1;
        }
        snprintf(out->layout, sizeof out->layout, "%s", hit);
    }
    const cJSON* axes = cJSON_GetObjectItemCaseSensitive(o, "axes");
    const cJSON* buttons = cJSON_GetObjectItemCaseSensitive(o, "buttons");
    if ((axes && !cJSON_IsObject(axes)) || (buttons && !cJSON_IsObject(buttons))) {
        fail(&p, axes && !cJSON_IsObject(axes) ? "axes" : "buttons", "must be an object");
        return -1;
    }
    for (const cJSON* a = axes ? axes->child : NULL; a; a = a->next) {
        if (!a->string || !a->string[0] || strlen(a->string) >= CONTROLS_NAME) {
            fail(&p, "axes", "a function name must have 1 to 31 characters");
            return -1;
        }
        if (out->nfn == CONTROLS_MAX_FN) {
            char msg[80];
            snprintf(msg, sizeof msg, "more than %d functions", CONTROLS_MAX_FN);
            fail(&p, "axes", msg);
            return -1;
        }
        if (parse_fn(&p, a, a->string, &out->fn[out->nfn])) return -1;
        ++out->nfn;
    }
    static const char* const bnames[CONTROLS_NBUTTON + 1] = {"hook",       "pause",  "reset",
                                                             "screenshot", "camera", NULL};
    if (buttons && only_keys(&p, buttons, bnames, "buttons")) return -1;
    for (int i = 0; buttons && i < CONTROLS_NBUTTON; ++i) {
        const cJSON* b = cJSON_GetObjectItemCaseSensitive(buttons, controls_button_names[i]);
        if (!b) continue;
        char field[48], sub[64];
        snprintf(field, sizeof field, "buttons.%s", controls_button_names[i]);
        if (!cJSON_IsObject(b)) {
            fail(&p, field, "must be an object");
            return -1;
        }
        static const char* const bf[] = {"controller", "joystick", NULL};
        if (only_keys(&p, b, bf, field)) return -1;
        if ((v = cJSON_GetObjectItemCaseSensitive(b, "controller"))) {
            snprintf(sub, sizeof sub, "%s.controller", field);
            if (get_name(&p, v, sub, false, true, out->button_controller[i],
                         sizeof out->button_controller[i]))
                return -1;
            out->has_button_controller[i] = true;
        }
        if ((v = cJSON_GetObjectItemCaseSensitive(b, "joystick"))) {
            snprintf(sub, sizeof sub, "%s.joystick", field);
            if (get_index(&p, v, sub, "button", &out->button_joystick[i])) return -1;
            out->has_button_joystick[i] = true;
        }
    }
    if (get_num(&p, o, "", "keyboard_ramp_s", 0.0, 10.0, &out->keyboard_ramp_s)) return -1;
    return 0;
}

int controls_load_file(const char* path, model_controls* out, char* err, size_t errsz) {
    cJSON* root = json_load_file(path, err, errsz);
    if (!root) return -1;
    const int rc = controls_parse(root, path, "", out, err, errsz);
    cJSON_Delete(root);
    return rc;
}

const controls_fn* controls_find(const model_controls* c, const char* name) {
    for (int i = 0; c && i < c->nfn; ++i)
        if (!strcmp(c->fn[i].function, name)) return &c->fn[i];
    return NULL;
}

int controls_check_functions(const model_controls* c, const char* const* names, int n,
                             const char* file, const char* where, char* err, size_t errsz) {
    for (int i = 0; i < c->nfn; ++i) {
        bool ok = false;
        for (int k = 0; k < n && !ok; ++k)
            ok = !strcmp(c->fn[i].function, names[k]);
        if (ok) continue;
        char list[400] = "";
        for (int k = 0; k < n; ++k)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? ", " : "",
                     names[k]);
        snprintf(err, errsz, "%s: %s%saxes.%s: no function '%s' in the model (functions: %s)", file,
                 where ? where : "", where && where[0] ? "." : "", c->fn[i].function,
                 c->fn[i].function, list);
        return -1;
    }
    return 0;
}
