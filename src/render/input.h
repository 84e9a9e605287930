// input.h: operator input for `cranesim drive`: game controllers, plain
// joysticks and the keyboard, turned into one command struct per frame.
//
// One command per function of the crane (lift, jib, ext, slew, ...: the
// model's), each through its own mapping (which stick or pair of buttons,
// invert, dead zone, expo, scale, a key pair). The default layouts give
// four to eight functions a place like a real remote (docs/render.md); the
// model's "controls" section or a JSON file (the same format) changes it.
// Devices may come and go while running (hot-plug); with none attached, or
// after unplugging, the keyboard drives the crane. Keyboard axes ramp at a
// finite rate so a key press does not slam a valve open.
#ifndef CRANESIM_INPUT_H
#define CRANESIM_INPUT_H

#include <stdbool.h>
#include <stddef.h>

#include <SDL2/SDL.h>

#ifdef __cplusplus
extern "C" {
#endif

/// The functions of the default (two-link) crane, in input_default_mapping()'s order.
typedef enum input_axis {
    INPUT_LIFT = 0, ///< lifting-arm valve, + raises
    INPUT_JIB,      ///< end-arm valve, + raises (opens) the end arm
    INPUT_SLEW,     ///< slew valve, + turns counter-clockwise seen from above
    INPUT_AXIS_COUNT
} input_axis;

/// Most functions a mapping drives (eight on devices, four more on keys only).
#define INPUT_MAX_FN 12
/// A controller "pair" input: axes as their SDL_GameControllerAxis, buttons
/// as INPUT_PAIR_BUTTON + their SDL_GameControllerButton.
#define INPUT_PAIR_BUTTON 100

typedef enum input_button {
    INPUT_BTN_HOOK = 0, ///< attach / release the load
    INPUT_BTN_PAUSE,
    INPUT_BTN_RESET,
    INPUT_BTN_SCREENSHOT,
    INPUT_BTN_CAMERA, ///< next camera preset
    INPUT_BUTTON_COUNT
} input_button;

typedef enum input_source {
    INPUT_SRC_KEYBOARD = 0,
    INPUT_SRC_CONTROLLER, ///< an SDL GameController (known mapping)
    INPUT_SRC_JOYSTICK    ///< a plain joystick (raw axis numbers)
} input_source;

/// What the app applies each frame. Axes are valve commands in [-1, 1];
/// the booleans are edges (true once per press).
typedef struct input_command {
    int n;                  ///< functions (the mapping's naxis)
    double u[INPUT_MAX_FN]; ///< per function, in the mapping's order, in [-1, 1]
    double lift, jib, slew; ///< u of the functions of those names (0 where the mapping has none)
    bool hook_toggle, pause, reset, screenshot, quit;
    bool camera_next;    ///< cycle camera presets
    bool mapping_box;    ///< M: show / hide the HUD's mapping box
    int camera_preset;   ///< -1 = no change, else a render_cam_preset (F1..F4)
    input_source source; ///< the device that is active
    bool fine;           ///< Shift held: the keys command INPUT_FINE_SCALE of full opening
} input_command;

/// The keyboard's command in fine mode (Shift held), as a fraction of a key's full command.
#define INPUT_FINE_SCALE 0.25

typedef struct input_axis_map {
    char name[32];       ///< the function ("lift", "ext"), as the engine names it
    int controller_axis; ///< SDL_GameControllerAxis, -1 = none
    /// Or + and - inputs (triggers, shoulder buttons, d-pad), used when
    /// controller_axis is -1: an axis number, or INPUT_PAIR_BUTTON + button; -1 none.
    int controller_pair[2];
    int joystick_axis;      ///< raw joystick axis index, -1 = none
    int joystick_button[2]; ///< raw + and - buttons (joystick_axis -1), -1 = none
    int key[2];             ///< + and - keys (SDL_Scancode), 0 = none
    int key_alt[2];         ///< a second pair (slew's A / D), 0 = none
    bool invert;         ///< flip the sign (SDL sticks give + for down/right)
    double dead_zone;    ///< |raw| below this gives 0, in [0, 0.95)
    double expo;         ///< 0 = linear .. 1 = cubic, fine control near centre
    double scale;        ///< output gain, (0, 1]
} input_axis_map;

typedef struct input_mapping {
    int naxis;                        ///< functions mapped
    input_axis_map axis[INPUT_MAX_FN]; ///< one per function
    char layout[16];                  ///< "two-lever" or "four-lever" (the defaults' layout)
    int controller_button[INPUT_BUTTON_COUNT]; ///< SDL_GameControllerButton, -1 = none
    int joystick_button[INPUT_BUTTON_COUNT];   ///< raw button index, -1 = none
    double keyboard_ramp; ///< time for a key to take its axis from 0 to 1 [s], 0 = instant
} input_mapping;

typedef struct input input;

/// Defaults: left stick y = lift, right stick y = jib, left stick x = slew,
/// A = hook, Start = pause, Back = reset, Y = screenshot, X = camera.
input_mapping input_default_mapping(void);
/// The default layout for the n functions names (the engine's, in its
/// order): layout "two-lever" (NULL or "") places lift, jib, slew and the
/// rest by role, "four-lever" in order, as levers of a valve bank
/// (docs/render.md "Mapping by function"). Returns 0, or -1 with one line in
/// err (n not in 1..INPUT_MAX_FN, a name too long or twice, unknown layout).
int input_layout_mapping(const char* const* names, int n, const char* layout, input_mapping* m, char* err,
                         size_t errsz);
struct model_controls;
/// Apply a parsed controls section / mapping file over *m: only the given
/// fields change. A function c names that m does not have is refused ("file:
/// where.axes.X: no function 'X' ..."). Returns 0, or -1 with *m untouched.
int input_apply_controls(input_mapping* m, const struct model_controls* c, const char* file, const char* where,
                         char* err, size_t errsz);
/// Read a JSON mapping file over *m (fields not in the file keep their
/// values; its "layout", if any, is not applied here: see input_layout_mapping).
/// Returns 0, or -1 with a message naming the file and field.
int input_load_mapping(const char* path, input_mapping* m, char* err, size_t errsz);
/// What the HUD's mapping box shows: one line per function, "name  controller
/// | joystick | keys", with the device inputs named as on the device ("left
/// stick Y", "RT / LT", "Up / Down"). Returns the length written.
int input_mapping_text(const input_mapping* m, char* out, size_t n);
/// The index of function name in m, or -1.
int input_find_function(const input_mapping* m, const char* name);

/// Initialises SDL's joystick + game controller subsystems if needed and
/// opens the first device present. m may be NULL for the defaults.
input* input_create(const input_mapping* m);
void input_destroy(input* in);
/// Replace the mapping (another model's functions): held keys and the
/// keyboard's ramps start from rest.
void input_set_mapping(input* in, const input_mapping* m);
/// The mapping in use.
const input_mapping* input_get_mapping(const input* in);

/// Feed every SDL event (hot-plug, buttons, keys). Returns true if used.
bool input_handle_event(input* in, const SDL_Event* ev);
/// Read the axes now and collect the edges since the last call.
/// dt [s] is the time since the previous poll (for the keyboard ramp).
void input_poll(input* in, double dt, input_command* out);

/// Name of the active device, or NULL when only the keyboard is used.
const char* input_device_name(const input* in);
input_source input_active_source(const input* in);

/// Dead zone + expo shaping of a raw value in [-1, 1] (exposed for tests):
/// 0 inside the dead zone, then rescaled so the output still reaches 1,
/// then y = (1 - expo) x + expo x^3, with the sign kept.
double input_shape(double raw, double dead_zone, double expo);

#ifdef __cplusplus
}
#endif
#endif
