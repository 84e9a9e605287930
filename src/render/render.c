// render.c: the renderer object: create/destroy, one frame, events, and the
// small queries the app and tests use.
#include <stdio.h>
#include <stdlib.h>

#include "gl_context.h"
#include "panel.h"
#include "render_internal.h"

#ifndef CRANESIM_ASSETS
#define CRANESIM_ASSETS "assets"
#endif

render_config render_default_config(void) {
    render_config c;
    memset(&c, 0, sizeof c);
    c.width = 1280;
    c.height = 720;
    c.offscreen = false;
    c.vsync = true;
    c.msaa = 0;           // llvmpipe pays ~2x per sample; see docs/render.md
    c.shadow_size = 512;  // llvmpipe: a few % faster than 1024 in drive (docs/render.md), 2048 ~6 ms more
    c.title = "cranesim";
    c.asset_dir = CRANESIM_ASSETS "/meshes";
    c.p_full_scale = 30e6;
    c.chart_seconds = 10.0;
    c.hud = true;
    return c;
}

render* render_create(const render_config* cfg, char* err, size_t errsz) {
    render* r = calloc(1, sizeof *r);
    if (!r) {
        if (err && errsz) snprintf(err, errsz, "render: out of memory");
        return NULL;
    }
    r->cfg = cfg ? *cfg : render_default_config();
    if (r->cfg.width <= 0) r->cfg.width = 1280;
    if (r->cfg.height <= 0) r->cfg.height = 720;
    if (r->cfg.shadow_size < 256) r->cfg.shadow_size = render_default_config().shadow_size;
    if (!(r->cfg.p_full_scale > 0)) r->cfg.p_full_scale = 30e6;
    if (!(r->cfg.chart_seconds > 0)) r->cfg.chart_seconds = 10.0;
    // Copy the strings: the caller's config may be a temporary.
    snprintf(r->title, sizeof r->title, "%s", r->cfg.title ? r->cfg.title : "cranesim");
    snprintf(r->asset_dir, sizeof r->asset_dir, "%s", r->cfg.asset_dir ? r->cfg.asset_dir : "");
    r->cfg.title = r->title;
    r->cfg.asset_dir = r->asset_dir;
    snprintf(r->meshes.dir, sizeof r->meshes.dir, "%s", r->asset_dir);
    r->charts.window = r->cfg.chart_seconds;

    if (!render_gl_open(r, err, errsz)) {
        render_destroy(r);
        return NULL;
    }
    if (!render_scene_create(&r->scene) || !render_hud_create(&r->hud) ||
        !render_shadow_create(&r->shadow, r->cfg.shadow_size)) {
        if (err && errsz) snprintf(err, errsz, "render: cannot create GL resources (see stderr)");
        render_destroy(r);
        return NULL;
    }
    render_camera_init(&r->cam);
    return r;
}

void render_destroy(render* r) {
    if (!r) return;
    if (r->gl) {
        SDL_GL_MakeCurrent(r->win, r->gl);
        if (r->frame_fence) glDeleteSync(r->frame_fence);
        if (r->panel_gui) panel_gui_shutdown(r->panel);
        render_mesh_cache_free(&r->meshes);
        render_scene_free(&r->scene);
        render_hud_free(&r->hud);
        render_shadow_free(&r->shadow);
    }
    render_gl_close(r);
    free(r);
}

void render_show_collision(render* r, bool on) { r->scene.show_collision = on; }
bool render_collision_shown(const render* r) { return r->scene.show_collision; }

bool render_handle_event(render* r, const SDL_Event* ev) {
    if (r->panel_gui && panel_gui_event(r->panel, ev)) return true;
    if (ev->type == SDL_WINDOWEVENT && ev->window.event == SDL_WINDOWEVENT_SIZE_CHANGED &&
        !r->cfg.offscreen) {
        int w, h;
        SDL_GL_GetDrawableSize(r->win, &w, &h);
        render_targets_resize(r, w, h);
        return true;
    }
    // G: the collision shapes over the scene (what the physics hits).
    if (ev->type == SDL_KEYDOWN && !ev->key.repeat && ev->key.keysym.scancode == SDL_SCANCODE_G) {
        r->scene.show_collision = !r->scene.show_collision;
        return true;
    }
    return render_camera_event(&r->cam, ev);
}

void render_frame(render* r, const world_snapshot* snap) {
    Uint64 t0 = SDL_GetPerformanceCounter();
    SDL_GL_MakeCurrent(r->win, r->gl);
    // A frame still waiting for its swap is shown first: no frame is lost,
    // whoever drives the loop.
    if (r->swap_pending) render_wait(r, 1.0);
    if (!r->cfg.offscreen) {
        int w, h;
        SDL_GL_GetDrawableSize(r->win, &w, &h);
        if (w != r->w || h != r->h) render_targets_resize(r, w, h);
    }
    // The strip charts cover the bottom 124 px plus margins (hud.c): the
    // camera centres the picture on the rest.
    const float inset = r->cfg.hud && r->charts.n > 0 ? 144.0f : 0.0f;
    render_camera_update(&r->cam, snap, r->w, r->h, &r->meshes, inset);

    glBindFramebuffer(GL_FRAMEBUFFER, render_target_fbo(r));
    render_scene_draw(&r->scene, &r->meshes, &r->shadow, &r->cam, snap, r->w, r->h);
    render_resolve(r);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glViewport(0, 0, r->w, r->h);

    render_hud_begin(&r->hud, r->w, r->h);
    if (r->cfg.hud) render_hud_draw_overlay(r, snap);
    render_hud_flush(&r->hud);
    if (r->panel_gui) panel_gui_draw(r->panel);

    // Frame rate from the smoothed wall time between frames. Average the
    // interval, not its inverse: frames that only queue work in the driver
    // alternate with frames that wait, and 1/dt would overweight the short ones.
    Uint64 now = SDL_GetPerformanceCounter();
    if (r->last_frame_ticks) {
        double dt = (double)(now - r->last_frame_ticks) / (double)SDL_GetPerformanceFrequency();
        r->frame_dt_avg = r->frame_dt_avg > 0 ? 0.95 * r->frame_dt_avg + 0.05 * dt : dt;
    }
    r->last_frame_ticks = now;
    r->have_frame = true;
    r->stats.triangles = r->scene.triangles;
    r->stats.draw_calls = r->scene.draw_calls + 2;
    r->stats.mesh_warnings = r->meshes.warnings;
    r->stats.meshes_loaded = r->meshes.n - r->meshes.warnings;
    r->stats.frame_ms =
        1e3 * (double)(SDL_GetPerformanceCounter() - t0) / (double)SDL_GetPerformanceFrequency();
}

void render_present(render* r) {
    SDL_GL_MakeCurrent(r->win, r->gl);
    if (!r->cfg.offscreen) render_blit_to_window(r);
    // A fence after the frame's last command tells render_busy() when the
    // driver has finished it. One at a time: the previous one is signalled or
    // superseded (fences complete in order).
    if (r->frame_fence) glDeleteSync(r->frame_fence);
    r->frame_fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    // Flush (not finish): the driver starts drawing now and the caller goes
    // on; read-back (render_read_pixels) waits for the frame by itself. In a
    // window the swap is deferred until the frame is drawn (render_wait): on
    // llvmpipe a swap right away blocks for the whole frame, and the drive
    // loop would then read the sticks only once per frame.
    glFlush();
    if (!r->cfg.offscreen) r->swap_pending = true;
}

bool render_busy(render* r) {
    return !render_wait(r, 0.0);
}

bool render_wait(render* r, double timeout_s) {
    if (!r->frame_fence) return true;
    SDL_GL_MakeCurrent(r->win, r->gl);
    // The frame was flushed in render_present, so no flush bit is needed.
    GLuint64 ns = timeout_s > 0 ? (GLuint64)(timeout_s * 1e9) : 0;
    GLenum st = glClientWaitSync(r->frame_fence, 0, ns);
    if (st == GL_TIMEOUT_EXPIRED) return false;
    glDeleteSync(r->frame_fence);
    r->frame_fence = 0;
    if (r->swap_pending) {
        r->swap_pending = false;
        SDL_GL_SwapWindow(r->win);
    }
    return true;
}

void render_set_camera_preset(render* r, render_cam_preset p) {
    if (p < 0 || p >= RENDER_CAM_COUNT) return;
    if (p == RENDER_CAM_ORBIT) {
        // The preset is the default view again (F1 after the hook view's
        // 7 m, or after zooming), keeping the operator's side.
        const int side = r->cam.op_side;
        render_camera_init(&r->cam);
        r->cam.op_side = side;
    }
    r->cam.preset = p;
    if (p == RENDER_CAM_FOLLOW_HOOK) r->cam.dist = 7.0f;
}

void render_camera_eye(const render* r, double eye[3], double at[3]) {
    const rm_vec3 e = r->cam.eye, a = r->cam.at;
    eye[0] = e.x, eye[1] = e.y, eye[2] = e.z;
    at[0] = a.x, at[1] = a.y, at[2] = a.z;
}

void render_get_orbit(const render* r, double* yaw, double* pitch, double* dist) {
    if (yaw) *yaw = r->cam.yaw;
    if (pitch) *pitch = r->cam.pitch;
    if (dist) *dist = r->cam.dist;
}

bool render_body_bounds(render* r, const world_snap_body* b, double lo[3], double hi[3]) {
    return render_body_local_bounds(&r->meshes, b, lo, hi);
}

render_cam_preset render_get_camera_preset(const render* r) {
    return r->cam.preset;
}

void render_set_orbit(render* r, const double target[3], double yaw, double pitch, double dist) {
    r->cam.preset = RENDER_CAM_ORBIT;
    r->cam.target = rm_v3((float)target[0], (float)target[1], (float)target[2]);
    r->cam.target_set = true;
    r->cam.yaw = (float)yaw;
    r->cam.pitch = (float)pitch;
    r->cam.dist = (float)dist;
}

bool render_project(const render* r, const double world[3], double px[2]) {
    float c[4];
    rm_xform4(c, r->cam.viewproj, (float)world[0], (float)world[1], (float)world[2]);
    if (c[3] <= 1e-6f) return false;
    px[0] = (c[0] / c[3] * 0.5 + 0.5) * r->w;
    px[1] = (0.5 - c[1] / c[3] * 0.5) * r->h;
    return true;
}

bool render_hud_bar_rect(const render* r, int cyl, int chamber, int rect[4]) {
    if (cyl < 0 || cyl >= WORLD_SNAP_MAX_CYLINDERS || chamber < 0 || chamber > 1) return false;
    if (!r->hud.bar_valid[cyl]) return false;
    memcpy(rect, r->hud.bar_rect[cyl][chamber], 4 * sizeof(int));
    return true;
}

bool render_hud_rcl_rect(const render* r, float rect[4]) {
    if (!(r->hud.rcl_rect[2] > 0)) return false;
    memcpy(rect, r->hud.rcl_rect, 4 * sizeof(float));
    return true;
}

bool render_hud_readouts_rect(const render* r, float rect[4]) {
    if (!(r->hud.readouts_rect[2] > 0)) return false;
    memcpy(rect, r->hud.readouts_rect, 4 * sizeof(float));
    return true;
}

void render_size(const render* r, int* w, int* h) {
    if (w) *w = r->w;
    if (h) *h = r->h;
}

render_stats render_get_stats(const render* r) {
    return r->stats;
}
SDL_Window* render_window(render* r) {
    return r->win;
}

bool render_attach_panel(render* r, panel* p) {
    if (r->panel_gui) panel_gui_shutdown(r->panel);
    r->panel_gui = false;
    r->panel = p;
    if (!p) return true;
    SDL_GL_MakeCurrent(r->win, r->gl);
    r->panel_gui = panel_gui_init(p, r->win, r->gl);
    return r->panel_gui;
}

void render_set_status(render* r, const char* text) {
    snprintf(r->status, sizeof r->status, "%s", text ? text : "");
}

const char* render_get_status(const render* r) { return r->status; }

void render_set_link(render* r, const char* text, const char* down) {
    snprintf(r->link, sizeof r->link, "%s", text ? text : "");
    snprintf(r->link_down, sizeof r->link_down, "%s", down ? down : "");
}

const char* render_get_readout(const render* r, int k, double* value, const char** unit) {
    if (k < 0 || k >= r->nreadout) return NULL;
    if (value) *value = r->readout[k].value;
    if (unit) *unit = r->readout[k].unit;
    return r->readout[k].name;
}

void render_set_readouts(render* r, const render_readout* v, int n) {
    r->nreadout = 0;
    for (int i = 0; i < n && i < RENDER_MAX_READOUTS; ++i) {
        snprintf(r->readout[i].name, sizeof r->readout[i].name, "%s", v[i].name ? v[i].name : "");
        snprintf(r->readout[i].unit, sizeof r->readout[i].unit, "%s", v[i].unit ? v[i].unit : "");
        r->readout[i].value = v[i].value;
        ++r->nreadout;
    }
}

void render_set_missed_deadlines(render* r, int missed) {
    r->missed_deadlines = missed;
}
