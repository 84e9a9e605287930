// render_internal.h: the renderer's private state, shared by its .c files.
//
// GL entry points come from GL_GLEXT_PROTOTYPES and GLVND's libOpenGL: with
// Mesa, GLVND dispatches them to whichever context SDL made current, whether
// it came from GLX, Wayland EGL or the offscreen EGL device, so no loader
// table is needed.
#ifndef RENDER_INTERNAL_H
#define RENDER_INTERNAL_H

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include "render.h"
#include "render_math.h"

// ---- shaders (shader.c) ----------------------------------------------------

/// Compile and link a vertex + fragment program; 0 on failure (log on stderr).
GLuint render_shader_build(const char* name, const char* vs, const char* fs);

// ---- meshes (mesh.c) -------------------------------------------------------

/// Vertex layout of every scene mesh: position [m], normal, colour tint.
typedef struct render_vertex {
    float p[3];
    float n[3];
    float c[3];
} render_vertex;

typedef struct render_mesh {
    GLuint vao, vbo, ibo;
    int nidx;  ///< index count (triangles * 3)
    bool cull; ///< winding agrees with the normals everywhere: back faces may be culled
    float bmin[3], bmax[3];
} render_mesh;

/// Upload vertices/indices into a new VAO (static, uploaded once).
render_mesh render_mesh_upload(const render_vertex* v, int nv, const unsigned* idx, int ni);
void render_mesh_free(render_mesh* m);
void render_mesh_draw(const render_mesh* m);

/// Built-in primitives, all unit sized so a model matrix scales them.
typedef enum render_prim {
    RENDER_PRIM_BOX = 0,    ///< -0.5..0.5 on every axis
    RENDER_PRIM_CYLINDER,   ///< radius 1, z from -0.5 to 0.5
    RENDER_PRIM_SPHERE,     ///< radius 1
    RENDER_PRIM_HEMISPHERE, ///< radius 1, z >= 0 (capsule ends)
    RENDER_PRIM_TUBE_X,     ///< radius 1, x from 0 to 1 (cylinder barrel/rod fallback)
    RENDER_PRIM_COUNT
} render_prim;

void render_prims_create(render_mesh prims[RENDER_PRIM_COUNT]);

/// A loaded mesh file; ok == false means it failed and the primitive is used.
typedef struct render_mesh_entry {
    char key[272];
    bool ok;
    render_mesh mesh;
} render_mesh_entry;

typedef struct render_mesh_cache {
    /// One allocation per entry, so a render_mesh_get pointer stays valid
    /// while later loads grow the array.
    render_mesh_entry** e;
    int n, cap;
    int warnings;  ///< files that failed (each warned once on stderr)
    char dir[512]; ///< asset dir for relative names
} render_mesh_cache;

/// Find or load a mesh file (relative to the asset dir, or absolute).
/// up: 1 = y-up, 2 or 0 = z-up. Returns NULL if it cannot be loaded, after
/// one warning line on stderr naming the file (the first time only).
const render_mesh* render_mesh_get(render_mesh_cache* c, const char* file, int up);
/// Body b's drawn extent in its own frame [m]: its mesh's bounds (scaled and
/// offset as drawn) or its primitive's. False for terrain or nothing known.
bool render_body_local_bounds(render_mesh_cache* mc, const world_snap_body* b, double lo[3], double hi[3]);
void render_mesh_cache_free(render_mesh_cache* c);

// ---- camera (camera.c) ---------------------------------------------------

typedef struct render_camera {
    render_cam_preset preset;
    rm_vec3 target;         ///< orbit centre [m]
    float yaw, pitch, dist; ///< orbit angles [rad] and distance [m]
    float fovy;             ///< vertical field of view [rad]
    bool dragging_orbit, dragging_pan;
    bool target_set; ///< orbit target chosen by user / set_orbit
    int op_side;     ///< operator preset: +1 left of the truck, -1 right, 0 not chosen yet
    rm_vec3 eye, at; ///< resolved this frame
    float view[16], proj[16], viewproj[16];
} render_camera;

void render_camera_init(render_camera* c);
/// Resolve the preset against the snapshot and build the matrices.
/// mc: the mesh cache (for the bodies' drawn boxes the eye keeps out of), or
/// NULL; inset_bottom: pixels at the bottom covered by the strip charts.
struct render_mesh_cache;
void render_camera_update(render_camera* c, const world_snapshot* s, int w, int h, struct render_mesh_cache* mc,
                          float inset_bottom);
bool render_camera_event(render_camera* c, const SDL_Event* ev);

// ---- shadow map (shadow.c) -----------------------------------------------

typedef struct render_shadow {
    GLuint fbo, tex;
    int size;
    float light_vp[16]; ///< world -> light clip
    rm_vec3 light_dir;  ///< unit vector toward the sun
} render_shadow;

bool render_shadow_create(render_shadow* s, int size);
void render_shadow_free(render_shadow* s);
/// Fit the light's orthographic box around a bounding sphere of the scene.
void render_shadow_fit(render_shadow* s, rm_vec3 centre, float radius);

// ---- scene (scene.c) -----------------------------------------------------

/// A lit program (objects or ground) and its uniform locations.
typedef struct render_lit_prog {
    GLuint id;
    GLint u_model, u_normal, u_vp, u_light_vp, u_color, u_light_dir, u_eye, u_shadow;
} render_lit_prog;

typedef struct render_scene {
    render_lit_prog obj, ground_prog;
    GLuint depth_prog, sky_prog;
    GLint ud_model, ud_vp;
    GLint us_top, us_bottom;
    GLuint sky_vao;
    render_mesh prim[RENDER_PRIM_COUNT];
    render_mesh ground;  ///< flat ground quad
    render_mesh terrain; ///< heightfield, rebuilt when the source changes
    const float* terrain_src;
    int terrain_nx, terrain_ny;
    double terrain_dx, terrain_dy;
    struct render_draw_item* items; ///< this frame's draw list (allocated once)
    int nitems, capitems;
    long triangles;
    int draw_calls;
    bool show_collision;  ///< debug view: collision shapes as wireframes over the scene (key G)
    int ncmesh;           ///< uploaded collision meshes, by the world's triangle pointer
    struct { const float* key; render_mesh mesh; } cmesh[64];
} render_scene;

bool render_scene_create(render_scene* sc);
void render_scene_free(render_scene* sc);
/// Both passes: depth into the shadow map, then the lit colour pass.
void render_scene_draw(render_scene* sc, render_mesh_cache* mc, render_shadow* sh,
                       const render_camera* cam, const world_snapshot* s, int w, int h);

// ---- HUD (hud.c) -----------------------------------------------------------

/// 2D batch: triangles and lines in pixel coordinates, one draw each per frame.
typedef struct render_hud_vertex {
    float x, y;
    unsigned char rgba[4];
} render_hud_vertex;

typedef struct render_hud {
    GLuint prog, vao, vbo;
    size_t vbo_bytes; ///< allocated size of vbo
    GLint u_screen;
    render_hud_vertex* tri;
    int ntri, captri;
    render_hud_vertex* line;
    int nline, capline;
    char* font_scratch; ///< stb_easy_font output, allocated once
    int font_scratch_size;
    int w, h;
    int bar_rect[WORLD_SNAP_MAX_CYLINDERS][2][4]; ///< last frame's bar frames, x y w h [px]
    bool bar_valid[WORLD_SNAP_MAX_CYLINDERS];
    float readouts_rect[4]; ///< last frame's readouts box, x y w h [px]
    float rcl_rect[4];      ///< last frame's load-moment bar box, x y w h [px] (w 0: none)
} render_hud;

bool render_hud_create(render_hud* h);
void render_hud_free(render_hud* h);
void render_hud_begin(render_hud* h, int w, int h_px);
void render_hud_rect(render_hud* h, float x, float y, float w, float hh, const float rgba[4]);
void render_hud_line(render_hud* h, float x0, float y0, float x1, float y1, const float rgba[4]);
/// Text with stb_easy_font at an integer-ish scale; returns the width [px].
float render_hud_text(render_hud* h, float x, float y, float scale, const float rgba[4],
                      const char* s);
float render_hud_text_width(const char* s, float scale);
void render_hud_flush(render_hud* h);

/// Everything the HUD shows for one snapshot (bars, readouts, warnings).
void render_hud_draw_overlay(render* r, const world_snapshot* s);
/// The input mapping box, when shown (hud_mapping.c).
void render_hud_draw_mapping(render* r);

// ---- strip charts (strip_chart.c) ------------------------------------------

/// Charts at most: the standard four of every cylinder a crane chain has
/// (WORLD_SNAP_MAX_CYLINDERS).
#define RENDER_MAX_CHARTS (4 * WORLD_SNAP_MAX_CYLINDERS)
#define RENDER_CHART_CAP 1024

typedef struct render_chart {
    render_chart_def def;
    char label[32], unit[16];
    double t[RENDER_CHART_CAP];
    float v[RENDER_CHART_CAP]; ///< display units
    int head, count;           ///< ring buffer: next write index, valid samples
} render_chart;

typedef struct render_charts {
    render_chart ch[RENDER_MAX_CHARTS];
    int n;
    double window; ///< seconds shown
    int std_ncyl;  ///< cylinders registered by render_charts_default, 0 = none
    int std_first; ///< id of the first standard channel
} render_charts;

void render_charts_draw(render_hud* h, const render_charts* c, float x, float y, float w, float hh);

// ---- the renderer ----------------------------------------------------------

struct render {
    render_config cfg;
    char asset_dir[512];
    char title[128];
    SDL_Window* win;
    SDL_GLContext gl;
    bool own_video;                   ///< we initialised SDL video, so we quit it
    int w, h;                         ///< framebuffer size [px]
    GLuint fbo, fbo_color, fbo_depth; ///< the frame (resolved, single-sample), also in a window
    GLuint msfbo, ms_color, ms_depth; ///< multisampled scene target, 0 if msaa off
    render_camera cam;
    render_shadow shadow;
    render_scene scene;
    render_hud hud;
    render_mesh_cache meshes;
    render_charts charts;
    render_stats stats;
    panel* panel;
    bool panel_gui;
    char status[128];
    char link[160];    ///< the remote link line (drive --connect), "" none
    char link_down[RENDER_WARN_LEN]; ///< the link is down: this warning, "" while it is up
    char mapping_title[96];          ///< the input mapping box (hud_mapping.c): its heading
    char mapping_text[1536];         ///< its lines (input_mapping_text), "" none
    bool mapping_shown;
    float mapping_rect[4];           ///< where the box was last drawn (x, y, w, h from top left) [px]; w 0: not drawn
    struct {
        char name[64], unit[16];
        double value;
    } readout[RENDER_MAX_READOUTS]; ///< render_set_readouts
    int nreadout;
    int missed_deadlines;
    bool have_frame;
    double frame_dt_avg; ///< smoothed wall time between frames [s]; the HUD shows 1 / it
    Uint64 last_frame_ticks;
    GLsync frame_fence; ///< signalled when the last presented frame is drawn, 0 if none
    bool swap_pending;  ///< window mode: the presented frame is swapped once its fence signals
};

/// Resize the offscreen/multisample targets to w x h.
bool render_targets_resize(render* r, int w, int h);

#endif
