// panel.h: the live parameter panel, as a C API.
//
// The app registers parameters (a label, a group, a unit, a pointer to its
// double, a range and a step) and actions (reset run, save model, pause).
// A value changes either in the Dear ImGui window (drawn by the renderer when
// attached with render_attach_panel) or programmatically with panel_set(),
// e.g. from tests or a future network interface. Both go through the same
// range check; an accepted change writes the double and raises that
// parameter's "changed" flag (and calls the change callback, if any), so the
// app can apply it before its next step. ImGui itself lives only in
// panel_imgui.cpp.
#ifndef CRANESIM_PANEL_H
#define CRANESIM_PANEL_H

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct panel panel;
struct SDL_Window;
union SDL_Event;

typedef struct panel_param_def {
    const char* label; ///< unique within its group, e.g. "bore"
    const char* group; ///< e.g. "lift cylinder"; NULL = "general"
    const char* unit;  ///< display unit, e.g. "m", "kg", "MPa"
    double* value;     ///< the app's variable, edited in place
    double min, max;   ///< accepted range, inclusive (same units as *value)
    double step;       ///< widget step, 0 = range/100
} panel_param_def;

/// Result of panel_set().
typedef enum panel_status {
    PANEL_OK = 0,
    PANEL_NOT_FOUND = -1,    ///< no parameter with that label
    PANEL_OUT_OF_RANGE = -2, ///< value outside [min, max]; nothing changed
    PANEL_NOT_FINITE = -3,   ///< NaN or infinity; nothing changed
    PANEL_AMBIGUOUS = -4     ///< label used in several groups; use "group/label"
} panel_status;

typedef void (*panel_change_fn)(void* user, int id, const char* label, double value);
typedef void (*panel_action_fn)(void* user);

panel* panel_create(void);
void panel_destroy(panel* p);

/// Register a parameter. Returns its id (>= 0), or -1 if the definition is
/// invalid (no value pointer, min > max, duplicate group/label).
int panel_add_param(panel* p, const panel_param_def* def);
/// Register a button. Returns its id (>= 0) or -1.
int panel_add_action(panel* p, const char* label, panel_action_fn fn, void* user);

/// Find a parameter by "label" or "group/label"; -1 if absent or ambiguous.
int panel_find(const panel* p, const char* label);
/// Set a parameter by label ("label" or "group/label") with range checking.
/// On failure nothing changes and msg (if given) says why, naming the label,
/// the value and the allowed range.
panel_status panel_set(panel* p, const char* label, double value, char* msg, size_t msgsz);
/// Same by id (the ImGui window uses this).
panel_status panel_set_id(panel* p, int id, double value, char* msg, size_t msgsz);
/// Current value by id (reads the app's double).
double panel_get(const panel* p, int id);

/// True if the parameter changed since the last call for it; clears the flag.
bool panel_take_changed(panel* p, int id);
/// Next changed parameter id (clearing its flag), or -1 when none is left.
int panel_next_changed(panel* p);
/// Called synchronously on every accepted change (GUI or panel_set).
void panel_on_change(panel* p, panel_change_fn fn, void* user);

/// Run an action by label; returns false if there is none.
bool panel_run_action(panel* p, const char* label);

int panel_count(const panel* p);
const char* panel_label(const panel* p, int id);
const char* panel_group(const panel* p, int id);
const char* panel_unit(const panel* p, int id);
void panel_range(const panel* p, int id, double* min, double* max, double* step);
int panel_action_count(const panel* p);
const char* panel_action_label(const panel* p, int id);
bool panel_run_action_id(panel* p, int id);
/// Last rejection message (shown in the GUI), "" if none.
const char* panel_last_error(const panel* p);

// ---- the ImGui window (panel_imgui.cpp); used by render.c ------------------

/// Start Dear ImGui with its SDL2 + OpenGL3 backends on this window/context.
bool panel_gui_init(panel* p, struct SDL_Window* win, void* gl_context);
void panel_gui_shutdown(panel* p);
/// Feed an event; true if ImGui wants it (mouse over the panel, typing).
bool panel_gui_event(panel* p, const union SDL_Event* ev);
/// Build and draw the panel into the current framebuffer.
void panel_gui_draw(panel* p);
/// Show or hide the window (it starts visible).
void panel_gui_show(panel* p, bool show);
/// Whether the window is shown.
bool panel_gui_visible(const panel* p);

#ifdef __cplusplus
}
#endif
#endif
