// input.h: operator input for `cranesim drive`: game controllers, plain
// joysticks and the keyboard, turned into one command struct per frame.
//
// Axes go through a per-axis mapping (which stick, invert, dead zone, expo,
// scale) that can be loaded from a JSON file (format in docs/render.md).
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

typedef enum input_axis {
    INPUT_LIFT = 0, ///< lifting-arm valve, + raises
    INPUT_JIB,      ///< end-arm valve, + raises (opens) the end arm
    INPUT_SLEW,     ///< slew valve, + turns counter-clockwise seen from above
    INPUT_AXIS_COUNT
} input_axis;

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
    double lift, jib, slew;
    bool hook_toggle, pause, reset, screenshot, quit;
    bool camera_next;    ///< cycle camera presets
    int camera_preset;   ///< -1 = no change, else a render_cam_preset (F1..F4)
    input_source source; ///< the device that is active
    bool fine;           ///< Shift held: the keys command INPUT_FINE_SCALE of full opening
} input_command;

/// The keyboard's command in fine mode (Shift held), as a fraction of a key's full command.
#define INPUT_FINE_SCALE 0.25

typedef struct input_axis_map {
    int controller_axis; ///< SDL_GameControllerAxis, -1 = none
    int joystick_axis;   ///< raw joystick axis index, -1 = none
    bool invert;         ///< flip the sign (SDL sticks give + for down/right)
    double dead_zone;    ///< |raw| below this gives 0, in [0, 0.95)
    double expo;         ///< 0 = linear .. 1 = cubic, fine control near centre
    double scale;        ///< output gain, (0, 1]
} input_axis_map;

typedef struct input_mapping {
    input_axis_map axis[INPUT_AXIS_COUNT];
    int controller_button[INPUT_BUTTON_COUNT]; ///< SDL_GameControllerButton, -1 = none
    int joystick_button[INPUT_BUTTON_COUNT];   ///< raw button index, -1 = none
    double keyboard_ramp; ///< time for a key to take its axis from 0 to 1 [s], 0 = instant
} input_mapping;

typedef struct input input;

/// Defaults: left stick y = lift, right stick y = jib, left stick x = slew,
/// A = hook, Start = pause, Back = reset, Y = screenshot, X = camera.
input_mapping input_default_mapping(void);
/// Read a JSON mapping file over *m (fields not in the file keep their
/// values). Returns 0, or -1 with a message naming the file and field.
int input_load_mapping(const char* path, input_mapping* m, char* err, size_t errsz);

/// Initialises SDL's joystick + game controller subsystems if needed and
/// opens the first device present. m may be NULL for the defaults.
input* input_create(const input_mapping* m);
void input_destroy(input* in);

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
