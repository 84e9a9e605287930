// render.h: the 3D view of cranesim (SDL2 + OpenGL 3.3 core).
//
// The renderer reads a world_snapshot and nothing else from the physics. A
// frame is: render_frame(r, snap) draws the scene, shadows, HUD, pressure
// bars, strip charts and (if attached) the parameter panel; then
// render_present(r) copies the frame to the window and swaps (offscreen: only
// flushes). The frame always lives in the renderer's own FBO, which
// render_screenshot() saves at any time.
//
// Typical `cranesim drive` loop (the app owns SDL_Init and the event loop):
//
//     render_config cfg = render_default_config();
//     render* r = render_create(&cfg, err, sizeof err);
//     while (running) {
//         while (SDL_PollEvent(&ev)) { input_handle_event(in, &ev); render_handle_event(r, &ev); }
//         input_poll(in, dt, &cmd);           // valve commands, >= 75 Hz
//         ... step the world, fill snap ...
//         render_charts_sample(r, &snap);     // or render_chart_push() per variable
//         render_frame(r, &snap);
//         render_present(r);
//     }
//     render_destroy(r);
//
// All positions are world frame (x forward, y left, z up) in metres.
#ifndef CRANESIM_RENDER_H
#define CRANESIM_RENDER_H

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include <SDL2/SDL.h>

#include "world/backend/world_snapshot.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct render render;
typedef struct panel panel;

/// Camera presets (also selectable with F1..F4 through input.h).
typedef enum render_cam_preset {
    RENDER_CAM_ORBIT = 0,   ///< free orbit around the crane, mouse driven
    RENDER_CAM_OPERATOR,    ///< operator standing at the column, looking at the tip
    RENDER_CAM_SIDE,        ///< side view across the boom plane
    RENDER_CAM_FOLLOW_HOOK, ///< orbit centred on the hook, follows it
    RENDER_CAM_COUNT
} render_cam_preset;

typedef struct render_config {
    int width, height;     ///< window or FBO size [px], default 1280 x 720
    bool offscreen;        ///< render into an FBO, no visible window (tests, batch PNGs)
    bool vsync;            ///< window mode only
    int msaa;              ///< multisample count for the scene (0 = off, 4 typical)
    int shadow_size;       ///< shadow map edge [texels], default 512 (docs/render.md)
    const char* title;     ///< window title
    const char* asset_dir; ///< directory for relative mesh names, default CRANESIM_ASSETS "/meshes"
    double p_full_scale;   ///< pressure at full bar height [Pa], default 30 MPa
    double chart_seconds;  ///< strip-chart time window [s], default 10
    bool hud;              ///< draw HUD text, bars and warnings (default true)
} render_config;

/// Counters from the last frame, for the report line and for tests.
typedef struct render_stats {
    long triangles;    ///< triangles submitted in the main pass
    int draw_calls;    ///< main pass + shadow pass + HUD
    int mesh_warnings; ///< meshes that failed to load (primitive used instead)
    int meshes_loaded; ///< distinct meshes in the cache
    double frame_ms;   ///< CPU time spent in render_frame [ms]
} render_stats;

/// Filled-in defaults; change only what differs.
render_config render_default_config(void);

/// Create the window (or hidden window + FBO), the GL 3.3 core context and all
/// GPU resources. Initialises the SDL video subsystem if the app has not.
/// Returns NULL and writes a message into err on failure.
render* render_create(const render_config* cfg, char* err, size_t errsz);
/// The text render_create's message starts with (after "render: ") when the
/// window failed only for want of a screen (no display server, or a video
/// driver without a screen), as opposed to a window or GL context that would
/// not start on a real display: the caller may then run without a window.
#define RENDER_ERR_NO_SCREEN "cannot open a window"
/// True when the environment names a display a window could open on: DISPLAY,
/// or WAYLAND_DISPLAY with its socket present. Else false, with the reason in
/// why ("no display (DISPLAY and WAYLAND_DISPLAY unset)", ...).
bool render_display_available(char* why, size_t n);
/// True when err, as render_create wrote it, says there is no screen.
static inline bool render_err_no_screen(const char* err) {
    return !strncmp(err, "render: " RENDER_ERR_NO_SCREEN, 8 + sizeof RENDER_ERR_NO_SCREEN - 1);
}
void render_destroy(render* r);

/// Camera mouse control (orbit with left drag, pan with right/middle drag,
/// zoom with the wheel), window resize, and the panel's events.
/// Returns true when the event was consumed (e.g. typing into the panel).
bool render_handle_event(render* r, const SDL_Event* ev);

/// Draw one frame of the snapshot (scene, shadows, HUD, charts, panel).
void render_frame(render* r, const world_snapshot* snap);
/// Swap buffers (window mode); offscreen only flushes. Either way it marks
/// the end of the frame for render_busy().
void render_present(render* r);
/// True while the driver is still drawing the last presented frame. A loop
/// that starts the next frame only when this is false never blocks inside
/// render_frame() waiting for queued frames (llvmpipe keeps just a couple of
/// scenes in flight), so it can keep stepping physics and reading input.
bool render_busy(render* r);
/// Sleep until the driver has finished the last presented frame or
/// timeout_s has passed; returns !render_busy(). Lets a paced loop idle on
/// the frame instead of a fixed delay, so the next frame can start at once.
bool render_wait(render* r, double timeout_s);

/// Save the last rendered frame as PNG (before or after render_present).
/// Returns 0 on success, -1 on failure (message on stderr naming the file).
int render_screenshot(render* r, const char* path);
/// render_screenshot without the stderr line: on failure (no frame yet, or
/// the file cannot be opened, written, flushed or closed, e.g. a full disk)
/// returns -1 with "cannot write FILE: <strerror>" in err. Bytes written
/// before a failure stay in the file.
int render_save_png(render* r, const char* path, char* err, size_t errsz);
/// Copy the last frame as RGBA8, top row first, into a w*h*4 buffer.
/// Returns 0 on success.
int render_read_pixels(render* r, unsigned char* rgba, int w, int h);

void render_set_camera_preset(render* r, render_cam_preset p);
render_cam_preset render_get_camera_preset(const render* r);
/// Orbit parameters for the free camera: target [m], yaw/pitch [rad], distance [m].
void render_set_orbit(render* r, const double target[3], double yaw, double pitch, double dist);

/// Where the camera of the last frame was [m, world] and what it looked at.
void render_camera_eye(const render* r, double eye[3], double at[3]);
/// The free orbit's yaw, pitch [rad] and distance [m] (any NULL skipped).
void render_get_orbit(const render* r, double* yaw, double* pitch, double* dist);
/// Distance factor per mouse-wheel notch (a touchpad's fractions scale it).
#define RENDER_ZOOM_PER_NOTCH 0.94f
/// Body b's drawn extent in its own frame [m] (mesh bounds as drawn, or the
/// primitive); false for terrain. The cameras keep their eye out of these
/// boxes for the truck, outriggers, wheels, loads and obstacles.
bool render_body_bounds(render* r, const world_snap_body* b, double lo[3], double hi[3]);

/// Project a world point [m] to pixel coordinates (x right, y down, origin top
/// left) with the camera of the last frame. Returns false if it is behind the
/// camera.
bool render_project(const render* r, const double world[3], double px[2]);

/// Where the scene draws point p of body b [m, world]. With a mesh named, p is
/// in the mesh's own coordinates (mesh units, z up after the mesh_up turn)
/// and lands at pos + rot (mesh_scale p + mesh_offset); without one, p is in
/// the primitive's frame (centre at 0) [m] and lands at pos + rot p. The scene
/// places every mesh with this, so a test can check that, e.g., boom1.obj's
/// joint-2 pin (L1, 0, 0) is drawn where the physics has joint 2.
void render_body_point(const world_snap_body* b, const double p[3], double world[3]);

/// Screen rectangle (x, y, w, h [px], origin top left) of the inside of the
/// pressure bar of cylinder `cyl`, chamber 0 = A or 1 = B, as drawn in the
/// last frame; false if that bar was not drawn. The unfilled part of a bar is
/// RENDER_BAR_EMPTY_RGB.
bool render_hud_bar_rect(const render* r, int cyl, int chamber, int rect[4]);
#define RENDER_BAR_EMPTY_RGB 0x141418
/// Screen rectangle (x, y, w, h [px], origin top left) of the readouts box
/// at the top left as drawn in the last frame; false before the first HUD.
bool render_hud_readouts_rect(const render* r, float rect[4]);

/// Screen rectangle (x, y, w, h [px]) of the load-moment bar's box, bottom
/// right, as drawn in the last frame; false when it was not drawn.
bool render_hud_rcl_rect(const render* r, float rect[4]);

/// The HUD's numbers (hud_fmt.c): v with `decimals` decimals (a leading +
/// with sign), never "-0.0": a value that is zero at that precision prints
/// unsigned. render_fmt_unit takes the decimals for the unit (MPa 2, mm 1,
/// L/min 1, % 1, kN 2, ...; another unit four significant digits, at most
/// six decimals), so a readout never shows an exponent ("x2 0.0 mm", not
/// "x2 -3.81e-05 mm").
const char* render_fmt_fixed(char* buf, size_t n, double v, int decimals, bool sign);
int render_unit_decimals(const char* unit, double v);
const char* render_fmt_unit(char* buf, size_t n, double v, const char* unit);

/// Current framebuffer size [px].
void render_size(const render* r, int* w, int* h);
render_stats render_get_stats(const render* r);
SDL_Window* render_window(render* r);

/// Attach a parameter panel (panel.h); it is drawn on top of each frame and
/// gets events. NULL detaches. The panel must outlive the attachment.
/// Returns false if the ImGui backend could not start (panel still usable
/// through its C API).
bool render_attach_panel(render* r, panel* p);

/// Short status line shown under the readouts (e.g. "PAUSED", "recording").
void render_set_status(render* r, const char* text);
/// Extra HUD readouts, one line each under the fixed ones: a channel's name,
/// its value and unit as the caller shows them (display units). The app
/// takes names and units from its channel list; n <= RENDER_MAX_READOUTS
/// (more are dropped), 0 for none (the default).
#define RENDER_MAX_READOUTS 8
typedef struct render_readout {
    const char* name;
    const char* unit;
    double value;
} render_readout;
void render_set_readouts(render* r, const render_readout* v, int n);
/// Readout k as last set: its name (NULL when k is out of range), value and unit.
const char* render_get_readout(const render* r, int k, double* value, const char** unit);
/// The remote link's line (drive --connect: who controls, frames, loss,
/// latency), drawn small at the top right; NULL or "" for none. down, when
/// not NULL or "", is the first warning line (the link dropped).
void render_set_link(render* r, const char* text, const char* down);
/// The input mapping box (hud_mapping.c): a heading and one line per
/// function as input_mapping_text gives them; shown or hidden.
void render_set_mapping(render* r, const char* title, const char* text);
void render_show_mapping(render* r, bool on);
bool render_mapping_shown(const render* r);
/// The text the mapping box is drawn from ("" none).
const char* render_mapping_text(const render* r);
/// Where the last frame drew the mapping box: x, y (top left), w, h [px];
/// false when it drew none.
bool render_mapping_rect(const render* r, int rect[4]);
/// The status line as last set.
const char* render_get_status(const render* r);
/// Longest warning line and most lines render_hud_warnings gives.
#define RENDER_WARN_LEN 128
#define RENDER_WARN_MAX 12
/// The warnings the HUD draws (top centre, red) for snapshot s, as text, in
/// the order drawn: open reliefs by name with the chamber they guard, end
/// stops, tipping, collision, "cannot keep up with real time". Returns the
/// number of lines (at most max, capped at RENDER_WARN_MAX).
int render_hud_warnings(const render* r, const world_snapshot* s, char out[][RENDER_WARN_LEN], int max);
/// The truck's supports by their short names ("FL", "FR", "RL", "RR": front
/// or rear, left or right), index as world_snapshot.pad_F.
const char* render_pad_name(int i);
/// A lift-off event for the console: the supports lifted in s and not in
/// *prev (bits, updated), written as one line into buf. Returns 1 when
/// there is one (once per event: a support that stays lifted says nothing
/// more), else 0.
int render_pad_event(const world_snapshot* s, int* prev, char* buf, size_t n);
/// What the lifted supports mean for stability, appended to their names:
/// " - on three pads, not tipping (tipping margin 2.04)" for one support at
/// a margin of 1 or more, else " - tipping margin 0.95".
void render_pad_margin_text(const world_snapshot* s, char* buf, size_t n);
/// The app reports missed real-time deadlines here; any count > 0 in the last
/// second shows the "cannot keep up with real time" warning.
void render_set_missed_deadlines(render* r, int missed_last_second);

// ---- strip charts --------------------------------------------------------

/// One scrolling time history. Samples outside [ymin, ymax] are clipped.
typedef struct render_chart_def {
    const char* label; ///< e.g. "p1A"
    const char* unit;  ///< display unit, e.g. "MPa"
    double scale;      ///< SI value * scale = displayed value (1e-6 for Pa -> MPa)
    double ymin, ymax; ///< displayed range, in display units
    float rgba[4];     ///< line colour
    int group;         ///< charts with the same group share one plot box
} render_chart_def;

/// Add a chart channel; returns its id (>= 0) or -1 when full.
int render_chart_add(render* r, const render_chart_def* def);
/// Channels registered so far, and the label of channel id (NULL if none).
int render_chart_count(const render* r);
const char* render_chart_label(const render* r, int id);
/// Append a sample (t [s], SI value). Samples must come in increasing t.
void render_chart_push(render* r, int id, double t, double value);
/// Remove all samples (e.g. after a reset).
void render_chart_clear(render* r);
/// Register the standard channels: pressures of every cylinder chamber
/// (MPa), strokes (mm) and spool openings (%), grouped in three plots.
void render_charts_default(render* r, int ncyl);
/// The standard channels of every cylinder of snapshot s (as many as fit:
/// four charts each), labelled by the cylinders' names ("pA lift", "x ext1",
/// "u ext1"): a crane chain's, whose cylinders are more than three.
void render_charts_default_named(render* r, const world_snapshot* s);
/// Remove every chart (a loaded model has other cylinders and channels).
void render_charts_reset(render* r);
/// Push the standard channels from a snapshot (after render_charts_default).
void render_charts_sample(render* r, const world_snapshot* snap);

// ---- demo scene ------------------------------------------------------------

/// Parameters of the synthetic crane scene used by render_demo and tests.
typedef struct render_demo_params {
    double slew;   ///< column slew [rad]
    double q1_deg; ///< lifting-arm elevation above horizontal [deg]
    double q2_deg; ///< end-arm angle relative to the lifting arm [deg] (negative = folded down)
    double pA[2], pB[2]; ///< chamber pressures of lift and jib cylinder [Pa]
    double u[2];         ///< spool openings -1..1
    bool terrain;        ///< use a gentle heightfield instead of flat ground
    bool use_meshes;     ///< name the assets/meshes OBJ files (else primitives only)
} render_demo_params;

render_demo_params render_demo_default_params(void);
/// Fill snap with a truck-mounted crane, hook on a rope, loads and obstacles.
/// terrain_buf (>= 65*65 floats) holds the heightfield when p->terrain.
void render_demo_scene(world_snapshot* snap, const render_demo_params* p, float* terrain_buf);
/// Terrain grid used by render_demo_scene (65 x 65 samples).
#define RENDER_DEMO_TERRAIN_N 65

/// The debug view (key G): the snapshot's collision shapes drawn as
/// wireframes over the scene.
void render_show_collision(render* r, bool on);
bool render_collision_shown(const render* r);

/// The physics core's importer (world/mesh_geom.h, mesh_set_importer) for
/// the formats it does not read itself: glTF/GLB, Collada, FBX, ... through
/// assimp. Fills out (the file's own units and axes); 0, or -1 with why.
struct mesh_tri;
int render_mesh_import(const char* path, struct mesh_tri* out, char* err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
