// drive_session.h: the interactive simulator's loop, as a library so tests can
// drive it headless (offscreen GL, virtual joystick, virtual clock).
//
// One session = one model + one live world (ode sandbox by default) + the
// renderer, the input devices and the parameter panel. drive_session_tick()
// is one iteration of the real-time loop: events, operator input, physics up
// to the given wall time (0.1 ms hydraulics inside), and a rendered frame
// when one is due.
#ifndef DRIVE_SESSION_H
#define DRIVE_SESSION_H

#include <stdbool.h>
#include <stddef.h>

#include "app.h"
#include "engine.h"

struct render;
struct input;
struct panel;

/// drive_session_create's code (never an exit code) when the renderer could
/// not open a window (no X server or compositor behind DISPLAY or
/// WAYLAND_DISPLAY, or SDL only has a driver with no screen): the caller may
/// fall back to a headless run.
#define DRIVE_NO_WINDOW (-2)
/// Rates (fps, command updates per second, the HUD's real-time factor) are
/// not given over less wall time than this [s]: a ratio of two tiny times
/// reads millions.
#define DRIVE_MIN_RATE_S 0.1
/// With panel changes not saved, Esc asks first: a second Esc within this
/// wall time quits [s].
#define DRIVE_QUIT_CONFIRM_S 3.0
/// The HUD's input mapping box shows for this much wall time at the start
/// of a drive [s], then hides; M shows or hides it any time.
#define DRIVE_MAPPING_S 8.0

typedef struct drive_opts {
    int width, height;        ///< window or offscreen size [px] (default 1280 x 720)
    bool offscreen;           ///< render into an FBO, no window
    double fps_cap;           ///< render at most this many frames per second (default 65)
    const char* mapping_file; ///< input mapping by function (JSON, docs/render.md), or NULL: the model's / defaults
    const char* record_path;  ///< start recording to this CSV at once, or NULL (F5 toggles)
    bool scripted;            ///< operator input from the scenario instead of devices
    bool hud;                 ///< draw the HUD (default true)
    const char* charts;       ///< strip-chart channels: CSV column names, comma-separated
                              ///< ("p1A,p2A,x1,u1"); NULL: pressures, strokes, spools
    const char* readouts;     ///< HUD readouts: channel names as charts, comma-separated; NULL: none
    const char* world_name;   ///< the ode world's name for the banner ("validation"); NULL: "sandbox"
    const char* session_path; ///< record the operator's input stream to this session file (docs/replay.md), or NULL
    const char* replay_path;  ///< drive by this session's commands instead of the devices, or NULL
    const char* save_as;      ///< "save model" writes (and replaces) this file; NULL: a new
                              ///< cranesim_model_N.json each time (drive_save_name)
    bool collision_view;      ///< start with the collision shapes drawn over the scene (key G toggles)
    int replay_rcl;           ///< with replay_path: the limiter 1 on, 0 off (--rcl), -1 as the session recorded it
} drive_opts;

drive_opts drive_default_opts(void);

/// Check what drive cannot use, before anything starts, in every mode: the
/// solver (cvode cannot step in real time), the chart names (o->charts), and
/// the mapping file (o->mapping_file, read and validated). Returns 0, or
/// EXIT_USAGE with one line naming the option, file or field.
int drive_opts_check(const app_common* c, const drive_opts* o, char* err, size_t errsz);

typedef struct drive_stats {
    long frames;          ///< frames rendered
    long input_samples;   ///< valve-command updates applied
    long missed;          ///< ticks whose physics could not catch up with wall time
    double sim_time;      ///< simulated time, summed over resets and rebuilds [s]
    double wall_time;     ///< wall time since start [s]
    double paused_time;   ///< wall time spent paused [s]
    long rebuilds;        ///< world rebuilds for a parameter (not resets)
    long triangles;       ///< triangles in the last frame
    double frame_ms[4096];///< recent frame intervals [ms] (ring buffer)
    int nframe_ms;
} drive_stats;

typedef struct drive_session drive_session;

/// Load the model, build the world, open the renderer and devices. c holds the
/// model, world, scenario and solver options (drive's defaults: ode sandbox).
/// Returns NULL with a message, and (when code is not NULL) the exit code it
/// calls for: 2 for bad input (model, scenario, mapping, chart names, a
/// record file that cannot be opened), 1 when the renderer or the world
/// cannot start, DRIVE_NO_WINDOW when a window (not offscreen) cannot open.
drive_session* drive_session_create(const app_common* c, const drive_opts* o, char* err, size_t errsz,
                                    int* code);
void drive_session_destroy(drive_session* s);

/// One loop iteration at wall time `wall` [s] since the session started
/// (real clock in the app, a virtual one in tests). Returns 1 when the
/// operator asked to quit, -1 on a numerical failure (message in
/// drive_session_error), else 0.
int drive_session_tick(drive_session* s, double wall);
/// Idle for up to `left` seconds until the next tick: on the frame in flight
/// if there is one (returning when the driver has finished it), else sleep.
void drive_session_idle(drive_session* s, double left);

/// The real-time factor the HUD shows: simulated over running (not paused)
/// wall time since the last reset or rebuild; 0 (unknown) before
/// DRIVE_MIN_RATE_S of it.
double drive_session_rt_factor(const drive_session* s);
/// Force a rendered frame now (e.g. before a screenshot).
void drive_session_render(drive_session* s);
/// Save the last frame as PNG. Returns 0, or -1 with "cannot write FILE:
/// <strerror>" in err (the file is checked to the last byte: a full disk fails).
int drive_session_screenshot(drive_session* s, const char* png, char* err, size_t errsz);
/// The snapshot the last frame was drawn from (as given to the renderer).
const world_snapshot* drive_session_snapshot(const drive_session* s);
/// Close the CSV recording, if any, and say whether every recording of the
/// session reached its file. Returns 0 (rows: rows of the last recording), or
/// -1 with "cannot write FILE: <strerror>" in err; rows written before the
/// failure stay in the file.
int drive_session_finish_record(drive_session* s, long* rows, char* err, size_t errsz);

const char* drive_session_error(const drive_session* s);
const drive_stats* drive_session_stats(const drive_session* s);
engine* drive_session_engine(drive_session* s);
struct render* drive_session_render_ctx(drive_session* s);
struct input* drive_session_input(drive_session* s);
struct panel* drive_session_panel(drive_session* s);
/// The model being driven (edited in place by the panel; "save model" writes it).
const model* drive_session_model(const drive_session* s);
struct chan_list;
/// The channels the session can chart (--charts names): the engine's
/// columns, then its circuit's (channels.h).
const struct chan_list* drive_session_channels(const drive_session* s);
/// The samples the i-th --charts channel has received since the charts were
/// last chosen (a remote view: one per state frame that carries its
/// channel), the last one (SI) into *last (may be NULL); -1: no such chart.
long drive_session_chart_samples(const drive_session* s, int i, double* last);
/// The row (CSV columns) at the current simulated time: the engine's ncol
/// columns (remote mode: the server's values of them).
void drive_session_row(drive_session* s, double* row);

struct proto_state;
/// Remote mode (drive --connect): the session draws a crane simulated
/// elsewhere. Its engine, built from the server's model and world files,
/// gives the scene (bodies, meshes, terrain) and the channel names and is
/// never stepped; drive_session_feed gives each state. The parameter panel
/// stays: its circuit edits are queued for the server (drive_session_take_set),
/// the rest are put back (they would only edit the idle local engine).
void drive_session_set_remote(drive_session* s);
/// Remote mode: a parameter change for the server (a panel edit, or the
/// drive's --set), queued until the link sends it as SET: path as the
/// protocol's (lift_cyl.bore, mechanics.load_mass), value SI. -1: queue full.
int drive_session_queue_set(drive_session* s, const char* path, double v);
/// The oldest queued change into path and *v: 1, or 0 when none.
int drive_session_take_set(drive_session* s, char* path, size_t np, double* v);
/// The server's answer to a change (accepted, refused and why): the status
/// line and the panel's message.
void drive_session_set_answer(drive_session* s, const char* text);
/// One state frame (protocol.h): poses, cylinders, rope and HUD values into
/// the snapshot the next frame draws, and one sample for the charts.
/// rt_factor: the remote simulated time over wall time, 0 unknown.
/// demand: per cylinder of the picture, the opening this drive last sent
/// to its function as the server's controller (the operator's demand the HUD
/// shows beside a command the server's limiter cut; NaN: none), or NULL
/// (watching: not known here).
void drive_session_feed(drive_session* s, const struct proto_state* st, double rt_factor, const double* demand);
/// The operator's input of the last tick, remote mode: n commands in [-1,
/// 1], command k for the function name[k] (the mapping's: the server's
/// functions once drive_session_remote_functions took them), and the
/// requests (each -1: none): hook (0 release, 1 attach), pause (toggle: 1),
/// reset (1).
typedef struct drive_remote_input {
    int n;
    double u[16];       // INPUT_MAX_FN (input.h) at most
    char name[16][32];  // the function of each (input_axis_map.name)
    int hook, pause, reset;
} drive_remote_input;
/// Remote mode: map the operator's sticks and keys to the server's functions
/// names[n] (its hello, VALVES' order) by name: the default layout, the
/// model's "controls" when model_controls (the local model is the server's
/// file), then --mapping. A list equal to the one mapped keeps the mapping
/// (a reconnection to the same server). 0, or -1 with one line in err (more
/// functions than the mapping takes, a mapping file naming a function the
/// server does not have); the mapping in use is kept then.
int drive_session_remote_functions(drive_session* s, const char* const* names, int n, bool model_controls,
                                   char* err, size_t errsz);
void drive_session_remote_input(drive_session* s, drive_remote_input* in);
/// The link's HUD line and, when the link is down, its warning (NULL: up).
void drive_session_set_link(drive_session* s, const char* text, const char* down);
/// Simulated time the session shows [s] (remote mode: the last state's).
double drive_session_time(const drive_session* s);
/// The status line the next frame shows (as composed by the tick).
const char* drive_session_status_line(const drive_session* s);

/// Take a new file name for "save model" in the working directory:
/// cranesim_model_N.json with the smallest N >= 1 no file has, created empty
/// so no other writer gets it. Returns 0, or -1 with errno.
int drive_save_name(char* path, size_t n);

/// Run the interactive loop on the real clock until quit (the `drive` command).
/// Returns an exit code, or DRIVE_NO_WINDOW (nothing printed, the reason in
/// no_window) when the window cannot open.
int drive_window_main(const app_common* c, const drive_opts* o, double duration, const char* screenshot,
                      double screenshot_at, char* no_window, size_t no_window_sz);

/// drive --connect HOST:PORT in the window (drive_connect_window.c): the
/// remote crane drawn by a remote-mode session. Returns an exit code, or
/// DRIVE_NO_WINDOW (the reason in no_window) when no window opens.
int drive_connect_window(const app_common* c, const drive_opts* o, const char* addr, double duration,
                         const char* screenshot, double screenshot_at, char* no_window, size_t no_window_sz);

/// Benchmark: the real-time loop offscreen at w x h with the scripted
/// operator for `seconds` of wall time; prints one JSON line (fps median and
/// 5th percentile, frame-time p50/p95 [ms], missed deadlines, command rate,
/// triangles, real-time factor, the process CPU time per frame [ms], the
/// model). config names the line ("drive"); *fps_mean and *cpu_ms (may be
/// NULL) get its mean frame rate [1/s] and CPU per frame [ms] (0 on failure).
/// Returns 0 or an exit code.
int drive_bench(const app_common* c, int w, int h, double seconds, const char* config, double* fps_mean,
                double* cpu_ms);

#endif
