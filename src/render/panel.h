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
    /// Changes reach the app only when the edit is finished (the drag is
    /// released, Enter typed), not at every pixel: for a parameter whose
    /// change is costly (it rebuilds the world). The window marks these.
    bool on_release;
} panel_param_def;

/// Drag speed of the widgets: this fraction of the value per pixel (0.5 %),
/// so a drag is as fine at 180 kg as at 1800 kg; near 0 at least
/// PANEL_DRAG_REL of the slider range's lower end, or PANEL_DRAG_FLOOR of it,
/// per pixel (a value at 0 still moves).
#define PANEL_DRAG_REL 0.005
#define PANEL_DRAG_FLOOR 1e-4

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
/// Register a choice among n named options (a combo box): *value holds the
/// index 0..n-1 as a double; panel_set accepts only whole indices. The option
/// names must outlive the panel. Returns its id (>= 0) or -1.
int panel_add_choice(panel* p, const char* label, const char* group, double* value, const char* const* options,
                     int n);
/// Options of a choice (n = 0 for a plain parameter) and the name of option k.
int panel_choice_count(const panel* p, int id);
const char* panel_choice_label(const panel* p, int id, int k);
/// Whether the parameter applies on release (panel_param_def.on_release).
bool panel_on_release(const panel* p, int id);
/// Value change per pixel of mouse drag at the parameter's current value.
double panel_drag_speed(const panel* p, int id);
/// What the window calls while the user edits a parameter: value v, and
/// whether the edit is finished (drag released, Enter). A live parameter is
/// set at once (panel_set_id); an on-release one only when done, its value in
/// between held as pending (shown, not applied). Returns panel_set_id's
/// status, or PANEL_OK while pending.
panel_status panel_edit(panel* p, int id, double v, bool done);
/// The same for a value being typed (Ctrl+click, then digits): every
/// parameter, live or not, is held pending until the edit is done (Enter,
/// or the field losing focus), so the half-typed "9" of "900" never reaches
/// the crane; Escape drops it.
panel_status panel_edit_typed(panel* p, int id, double v, bool done);
/// The pending (shown but not applied) value of an on-release parameter
/// being edited; false if none.
bool panel_pending(const panel* p, int id, double* v);
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
/// Range a drag covers (e.g. a parameter's typical range, within [min, max]),
/// within which the widget keeps a dragged value; a typed value may leave
/// it and is checked against [min, max] only. By default [min, max].
void panel_set_slider_range(panel* p, int id, double min, double max);
/// A note shown after the value and unit ("1400 MPa (fluid's)"), or NULL or
/// "" for none: a value that follows another one until it is set.
void panel_set_note(panel* p, int id, const char* note);
const char* panel_note(const panel* p, int id);
void panel_slider_range(const panel* p, int id, double* min, double* max);
/// Register a one-line text field (a file path) of n bytes at buf, shown
/// above the parameters; the app reads buf when one of its actions runs.
/// Returns its id (>= 0) or -1.
int panel_add_text(panel* p, const char* label, char* buf, size_t n);
int panel_text_count(const panel* p);
const char* panel_text_label(const panel* p, int id);
/// Set a text field by label (what typing into it does); false if absent.
bool panel_set_text(panel* p, const char* label, const char* text);
/// The filter box: parameters whose group or label contains it (ignoring
/// case) are shown; "" shows all.
void panel_set_filter(panel* p, const char* text);
const char* panel_filter(const panel* p);
/// Whether parameter id passes the filter.
bool panel_matches(const panel* p, int id);
/// A message shown under the actions (a failed load), "" for none.
void panel_set_message(panel* p, const char* text);
const char* panel_message(const panel* p);
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
/// Whether the window has the keyboard (a value is being typed): keys then
/// go to it, not to the crane. Enter or Escape gives the keyboard back.
bool panel_gui_wants_keyboard(const panel* p);
/// The panel's window has the focus (it was clicked, or a value is typed):
/// Esc then leaves the panel instead of reaching the crane's keys.
bool panel_gui_has_focus(const panel* p);
/// Screen rectangle (x, y, w, h [px]) of parameter id's widget as last drawn;
/// false if it was not drawn (hidden window, collapsed group).
bool panel_gui_item_rect(const panel* p, int id, float rect[4]);
/// The same for action button id, and for the panel's window.
bool panel_gui_action_rect(const panel* p, int id, float rect[4]);
bool panel_gui_window_rect(const panel* p, float rect[4]);
/// The panel's window ends this far above the bottom of the view [px]: the
/// strip charts (124 px and margins) and the load-moment bar above them (its
/// box starts 182 px above the bottom, hud.c) stay uncovered.
#define PANEL_BOTTOM_CLEAR 196.0f

#ifdef __cplusplus
}
#endif
#endif
