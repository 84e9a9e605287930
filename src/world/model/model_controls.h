// model_controls.h: the operator's input mapping by function, as written in a
// model's "controls" section or a drive --mapping file (one format, docs/render.md
// "Mapping by function"). Parsed and validated here without SDL: device axes,
// buttons and keys are plain names checked against the lists below; the
// render library's input.c turns them into SDL codes.
#ifndef MODEL_CONTROLS_H
#define MODEL_CONTROLS_H

#include <cjson/cJSON.h>
#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Functions a mapping can name (and the input layer can drive): the
/// eight of the default layouts plus four key-only ones.
#define CONTROLS_MAX_FN 12
#define CONTROLS_NAME 32
/// Device buttons that are not functions: hook, pause, reset, screenshot, camera.
#define CONTROLS_NBUTTON 5

/// One function's entry ("axes": {"<function>": {...}}). Every field is
/// optional: has_* says it was given (a given null unbinds).
typedef struct controls_fn {
    char function[CONTROLS_NAME];
    /// controller: 1 name = one (bipolar) axis; 2 names = the + and - inputs,
    /// each an axis (a trigger) or a button; 0 = unbound.
    bool has_controller;
    int ncontroller;
    char controller[2][24];
    bool has_joystick; ///< raw axis index, -1 unbound
    int joystick;
    bool has_joystick_buttons; ///< raw + and - buttons, -1 unbound
    int joystick_button[2];
    bool has_keys; ///< + and - key names (SDL scancode names), "" unbound
    char key[2][24];
    bool has_invert, invert;
    double dead_zone, expo, scale; ///< NaN: not given
} controls_fn;

typedef struct model_controls {
    char layout[16]; ///< "" (not given), "two-lever" or "four-lever"
    int nfn;
    controls_fn fn[CONTROLS_MAX_FN];
    bool has_button_controller[CONTROLS_NBUTTON];
    char button_controller[CONTROLS_NBUTTON][24]; ///< "" unbound
    bool has_button_joystick[CONTROLS_NBUTTON];
    int button_joystick[CONTROLS_NBUTTON]; ///< -1 unbound
    double keyboard_ramp_s;                ///< [s], NaN: not given
} model_controls;

/// The names the format accepts (NULL-terminated lists, SDL's spelling).
extern const char* const controls_controller_axes[];    ///< leftx .. righttrigger
extern const char* const controls_controller_buttons[]; ///< a, b, x, y, back, ...
extern const char* const controls_keys[];               ///< keys a function may have
/// Keys the drive window uses for itself (hook, pause, panel, ...): never a
/// function's; each with what it does.
extern const char* const controls_window_keys[][2];
extern const char* const
    controls_button_names[CONTROLS_NBUTTON]; ///< hook, pause, reset, screenshot, camera
extern const char* const controls_layouts[]; ///< two-lever, four-lever

/// The canonical spelling of a name of list (case-insensitive match), or NULL.
const char* controls_lookup(const char* const* list, const char* name);

/// Parse a controls object o (the model's "controls", or a mapping file's
/// root) into *out (zeroed first). file and where ("controls" in a model, ""
/// in a mapping file) name the place in messages. Function names are not
/// checked against a model here (controls_check_functions does). Returns 0,
/// or -1 with one line "file: where.field: problem" in err.
int controls_parse(const cJSON* o, const char* file, const char* where, model_controls* out,
                   char* err, size_t errsz);
/// Read and parse a mapping file. Returns 0, or -1 with one line in err.
int controls_load_file(const char* path, model_controls* out, char* err, size_t errsz);
/// Every function named in c must be one of the n names: else -1 with
/// "file: where.axes.X: no function 'X' in the model (functions: a, b, ...)".
int controls_check_functions(const model_controls* c, const char* const* names, int n,
                             const char* file, const char* where, char* err, size_t errsz);
/// The entry of function name in c, or NULL.
const controls_fn* controls_find(const model_controls* c, const char* name);

#ifdef __cplusplus
}
#endif
#endif
