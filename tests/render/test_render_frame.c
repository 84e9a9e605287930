// test_render_frame.c: headless frames of the synthetic crane scene: not
// blank, crane colours where the crane projects, pressure bars that follow
// the pressure, camera presets that keep the crane in view, mesh fallback
// with a warning, and the ImGui panel drawing offscreen.
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdlib.h>
#include <unistd.h>

#include "check.h"
#include "panel.h"
#include "render.h"
#include "render_internal.h" // render_hud_text_width: the HUD font's metrics

enum { W = 1280, H = 720 };

static world_snapshot snap; // big: keep off the stack
static float terrain[RENDER_DEMO_TERRAIN_N * RENDER_DEMO_TERRAIN_N];
static unsigned char px[W * H * 4];

static render* make(bool hud) {
    render_config cfg = render_default_config();
    cfg.offscreen = true;
    cfg.hud = hud;
    char err[256] = "";
    render* r = render_create(&cfg, err, sizeof err);
    CHECK(r != NULL, "render_create: %s", err);
    return r;
}

static const unsigned char* at(int x, int y) {
    return &px[((size_t)y * W + (size_t)x) * 4];
}

/// Orange crane paint, lit or in shadow: a saturated red-over-green-over-blue
/// hue (grey ground, blue truck, brick and wood are less saturated).
static bool is_crane(const unsigned char* p) {
    return p[0] > 35 && p[0] >= p[1] && p[1] > p[2] && (p[0] - p[2]) > 0.68 * p[0];
}

static int count_crane_near(double cx, double cy, int rad) {
    int n = 0;
    for (int y = (int)cy - rad; y <= (int)cy + rad; ++y)
        for (int x = (int)cx - rad; x <= (int)cx + rad; ++x)
            if (x >= 0 && y >= 0 && x < W && y < H && is_crane(at(x, y))) ++n;
    return n;
}

static const world_snap_body* body(const char* name) {
    for (int i = 0; i < snap.nbody; ++i)
        if (strcmp(snap.body[i].name, name) == 0) return &snap.body[i];
    return NULL;
}

static void test_frame_not_blank_and_png(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    render_charts_default(r, snap.ncyl);
    render_charts_sample(r, &snap);
    render_frame(r, &snap);
    CHECK(render_read_pixels(r, px, W, H) == 0, "read pixels");
    double sum = 0, sum2 = 0;
    for (int i = 0; i < W * H; ++i) {
        double l = 0.3 * px[4 * i] + 0.59 * px[4 * i + 1] + 0.11 * px[4 * i + 2];
        sum += l, sum2 += l * l;
    }
    double mean = sum / (W * H), var = sum2 / (W * H) - mean * mean;
    CHECK(var > 400.0, "luminance variance %g (a blank frame is ~0)", var);
    render_stats st = render_get_stats(r);
    CHECK(st.triangles >= 14000, "default scene has %ld triangles, want >= 14000", st.triangles);
    CHECK(st.mesh_warnings == 0, "all shipped meshes load (%d warnings)", st.mesh_warnings);
    char path[512];
    snprintf(path, sizeof path, "%s/render_frame.png", CRANESIM_BINARY_DIR);
    remove(path);
    CHECK(render_screenshot(r, path) == 0, "screenshot");
    FILE* f = fopen(path, "rb");
    CHECK(f != NULL, "png written: %s", path);
    if (f) {
        unsigned char sig[8] = {0};
        CHECK(fread(sig, 1, 8, f) == 8 && sig[1] == 'P' && sig[2] == 'N' && sig[3] == 'G',
              "PNG signature");
        fclose(f);
    }
    render_destroy(r);
}

static void test_crane_where_it_projects(void) {
    render* r = make(false);
    if (!r) return;
    for (int meshes = 0; meshes < 2; ++meshes) {
        render_demo_params p = render_demo_default_params();
        p.use_meshes = meshes;
        render_demo_scene(&snap, &p, terrain);
        render_frame(r, &snap);
        render_read_pixels(r, px, W, H);
        // The middle of each boom and the column lie on the crane.
        const char* parts[] = {"boom1", "boom2", "column"};
        for (int k = 0; k < 3; ++k) {
            const world_snap_body* b = body(parts[k]);
            double q[2];
            CHECK(b && render_project(r, b->pos, q), "%s projects", parts[k]);
            if (!b) continue;
            CHECK(q[0] > 0 && q[0] < W && q[1] > 0 && q[1] < H, "%s on screen at %.0f,%.0f",
                  parts[k], q[0], q[1]);
            int n = count_crane_near(q[0], q[1], 3);
            const unsigned char* c = at((int)q[0], (int)q[1]);
            CHECK(
                n >= 10,
                "%s (meshes %d): %d/49 crane-coloured pixels near %.0f,%.0f (centre rgb %d %d %d)",
                parts[k], meshes, n, q[0], q[1], c[0], c[1], c[2]);
        }
        // High up in the sky there is no crane.
        double sky[3] = {snap.tip[0], snap.tip[1], snap.tip[2] + 30};
        double q[2];
        if (render_project(r, sky, q) && q[1] > 5)
            CHECK(count_crane_near(q[0], q[1], 3) == 0, "no crane colour in the sky");
    }
    render_destroy(r);
}

/// Pixels inside the bar that are not the empty-bar colour.
static int bar_fill(render* r, int cyl, int chamber) {
    int rc[4];
    if (!render_hud_bar_rect(r, cyl, chamber, rc)) return -1;
    render_read_pixels(r, px, W, H);
    int n = 0;
    for (int y = rc[1]; y < rc[1] + rc[3]; ++y)
        for (int x = rc[0]; x < rc[0] + rc[2]; ++x) {
            const unsigned char* c = at(x, y);
            int rgb = (c[0] << 16) | (c[1] << 8) | c[2];
            if (rgb != RENDER_BAR_EMPTY_RGB) ++n;
        }
    return n;
}

// The readouts box holds the status line, the widest text it shows: the
// panel's "[keys: panel - ...]" ran past its edge and was cut off.
static void test_status_line_inside_readouts(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    const char* st = "REC   [keyboard]  [keys: panel - Enter/Esc gives them back]  1 resets or rebuilds";
    render_set_status(r, st);
    render_frame(r, &snap);
    float rc[4] = {0};
    CHECK(render_hud_readouts_rect(r, rc), "readouts drawn");
    const float need = render_hud_text_width(st, 1.5f);
    CHECK(rc[0] + rc[2] >= 10 + need, "box ends at %.0f px, the status line at %.0f px", rc[0] + rc[2], 10 + need);
    render_destroy(r);
}

static void test_pressure_bars_follow_pressure(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    p.pA[0] = 5e6;
    render_demo_scene(&snap, &p, terrain);
    render_frame(r, &snap);
    int rc[4] = {0};
    CHECK(render_hud_bar_rect(r, 0, 0, rc), "lift bar A drawn");
    int area = rc[2] * rc[3];
    int low = bar_fill(r, 0, 0), other = bar_fill(r, 1, 1);
    p.pA[0] = 20e6;
    render_demo_scene(&snap, &p, terrain);
    render_frame(r, &snap);
    int high = bar_fill(r, 0, 0), other2 = bar_fill(r, 1, 1);
    CHECK(high > low, "bar grows with pressure: %d -> %d px", low, high);
    // Height proportional to pressure on a 30 MPa full scale (one row slack).
    CHECK_NEAR(low, area * 5.0 / 30.0, rc[2] + 1.0);
    CHECK_NEAR(high, area * 20.0 / 30.0, rc[2] + 1.0);
    CHECK(other == other2 && other > 0, "jib bar B unchanged: %d vs %d", other, other2);
    // Over full scale clips to a full bar.
    p.pA[0] = 45e6;
    render_demo_scene(&snap, &p, terrain);
    render_frame(r, &snap);
    CHECK(bar_fill(r, 0, 0) == area, "full bar above full scale");
    render_destroy(r);
}

static void test_camera_presets(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    p.terrain = true;
    render_demo_scene(&snap, &p, terrain);
    const render_cam_preset presets[] = {RENDER_CAM_OPERATOR, RENDER_CAM_SIDE,
                                         RENDER_CAM_FOLLOW_HOOK, RENDER_CAM_ORBIT};
    for (int k = 0; k < 4; ++k) {
        render_set_camera_preset(r, presets[k]);
        render_frame(r, &snap);
        CHECK(render_get_camera_preset(r) == presets[k], "preset kept");
        double q[2];
        const double* pt = presets[k] == RENDER_CAM_FOLLOW_HOOK ? snap.hook : snap.tip;
        CHECK(render_project(r, pt, q) && q[0] >= 0 && q[0] < W && q[1] >= 0 && q[1] < H,
              "preset %d: point in view at %.0f,%.0f", (int)presets[k], q[0], q[1]);
    }
    render_destroy(r);
}

// The default view keeps the hook and its load above the strip charts
// (144 px at the bottom) when the crane works in front of the camera: the
// load set down on the ground by stack_b at (6, -6) m, the hook 1 m up. The
// view centred on column and tip, on the whole window, put the load behind
// the charts (the load's centre at y = 569 px of 720; now 448, the hook 402).
static void test_default_view_above_the_charts(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    render_charts_default(r, snap.ncyl);
    const double tip[3] = {5.6, -5.6, 2.2}, hook[3] = {5.6, -5.6, 1.0}, load[3] = {5.6, -5.6, 0.35};
    memcpy(snap.tip, tip, sizeof tip);
    memcpy(snap.hook, hook, sizeof hook);
    for (int i = 0; i < snap.nbody; ++i)
        if (snap.body[i].role == WORLD_ROLE_LOAD) {
            memcpy(snap.body[i].pos, load, sizeof load);
            break;
        }
    render_set_camera_preset(r, RENDER_CAM_ORBIT);
    render_frame(r, &snap);
    const double* pts[2] = {hook, load};
    for (int k = 0; k < 2; ++k) {
        double q[2];
        CHECK(render_project(r, pts[k], q) && q[0] > 0 && q[0] < W && q[1] > 0 && q[1] < H - 144 - 10,
              "%s at (%.0f, %.0f) px; the charts start at y = %d", k ? "load" : "hook", q[0], q[1], H - 144);
    }
    render_destroy(r);
}

// The wheel zooms RENDER_ZOOM_PER_NOTCH (6 %) per notch, a touchpad's
// fraction of a notch by that fraction, and one event at most 3 notches. It
// was 12 % per whole notch: 6 notches halved the distance.
static void test_zoom_per_notch(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    render_frame(r, &snap);
    double d0, d1;
    render_get_orbit(r, NULL, NULL, &d0);
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = SDL_MOUSEWHEEL;
    ev.wheel.y = 1;
    ev.wheel.preciseY = 1.0f;
    CHECK(render_handle_event(r, &ev), "wheel taken");
    render_get_orbit(r, NULL, NULL, &d1);
    CHECK_NEAR(d1 / d0, 0.94, 1e-5);
    ev.wheel.y = 0;
    ev.wheel.preciseY = 0.25f;
    render_handle_event(r, &ev);
    render_get_orbit(r, NULL, NULL, &d0);
    CHECK_NEAR(d0 / d1, pow(0.94, 0.25), 1e-5);
    ev.wheel.y = -40;
    ev.wheel.preciseY = -40.0f;
    render_handle_event(r, &ev);
    render_get_orbit(r, NULL, NULL, &d1);
    CHECK_NEAR(d1 / d0, pow(0.94, -3.0), 1e-4);
    render_destroy(r);
}

static void test_missing_mesh_falls_back(void) {
    // A garbage file and a missing one: one warning line each, primitives drawn.
    char bad[512];
    snprintf(bad, sizeof bad, "%s/render_broken_mesh.obj", CRANESIM_BINARY_DIR);
    FILE* f = fopen(bad, "w");
    if (f) {
        fputs("this is not an OBJ file\nf 1 2 3 4 5 nonsense\n", f);
        fclose(f);
    }
    render* r = make(false);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    p.use_meshes = false;
    render_demo_scene(&snap, &p, terrain);
    world_snap_body* b = &snap.body[snap.nbody++];
    memset(b, 0, sizeof *b);
    snprintf(b->name, sizeof b->name, "magenta_box");
    b->role = WORLD_ROLE_OBSTACLE;
    b->shape = WORLD_SHAPE_BOX;
    b->size[0] = b->size[1] = b->size[2] = 1.5;
    b->pos[0] = 4, b->pos[1] = -3, b->pos[2] = 0.75;
    b->rot[0] = b->rot[4] = b->rot[8] = 1;
    b->rgba[0] = 1, b->rgba[1] = 0, b->rgba[2] = 1, b->rgba[3] = 1;
    snprintf(b->mesh, sizeof b->mesh, "does_not_exist.obj");
    world_snap_body* b2 = &snap.body[snap.nbody++];
    *b2 = *b;
    snprintf(b2->name, sizeof b2->name, "broken");
    b2->pos[1] = 3;
    snprintf(b2->mesh, sizeof b2->mesh, "%.127s", bad);

    // Capture stderr in a file around two frames.
    char log[512];
    snprintf(log, sizeof log, "%s/render_mesh_warn.log", CRANESIM_BINARY_DIR);
    fflush(stderr);
    int saved = dup(fileno(stderr));
    FILE* lf = fopen(log, "w");
    if (lf) dup2(fileno(lf), fileno(stderr));
    render_frame(r, &snap);
    render_frame(r, &snap);
    fflush(stderr);
    dup2(saved, fileno(stderr));
    close(saved);
    if (lf) fclose(lf);

    render_stats st = render_get_stats(r);
    CHECK(st.mesh_warnings == 2, "two failed meshes counted, got %d", st.mesh_warnings);
    char text[4096] = "";
    f = fopen(log, "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    text[n] = '\0';
    if (f) fclose(f);
    const char* w1 = strstr(text, "does_not_exist.obj");
    CHECK(w1 != NULL, "warning names the missing file: [%s]", text);
    CHECK(w1 && !strstr(w1 + 1, "does_not_exist.obj"), "warned once, not every frame: [%s]", text);
    CHECK(strstr(text, "render_broken_mesh.obj") != NULL, "warning names the broken file: [%s]",
          text);
    int lines = 0;
    for (const char* c = text; *c; ++c)
        lines += *c == '\n';
    CHECK(lines == 2, "one line per file, got %d: [%s]", lines, text);
    // The primitive box is drawn in its colour where the body is.
    render_read_pixels(r, px, W, H);
    double q[2];
    CHECK(render_project(r, b->pos, q), "box projects");
    const unsigned char* c = at((int)q[0], (int)q[1]);
    CHECK(c[0] > 40 && c[2] > 40 && c[1] < c[0] / 2 && c[1] < c[2] / 2,
          "magenta box drawn, rgb %d %d %d", c[0], c[1], c[2]);
    render_destroy(r);
}

static void test_cad_mesh_formats(void) {
    // assimp is asked per extension (aiGetExtensionList is broken in 5.2).
    // A user's STL in millimetres, y-up, replaces a body's mesh.
    char stl[512];
    snprintf(stl, sizeof stl, "%s/render_cube_mm.stl", CRANESIM_BINARY_DIR);
    FILE* f = fopen(stl, "w");
    CHECK(f != NULL, "write %s", stl);
    if (!f) return;
    // A 1000 mm cube from (-500, 0, -500) to (500, 1000, 500): y is up.
    static const float v[8][3] = {{-500, 0, -500},    {500, 0, -500},   {500, 1000, -500},
                                  {-500, 1000, -500}, {-500, 0, 500},   {500, 0, 500},
                                  {500, 1000, 500},   {-500, 1000, 500}};
    static const int q[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                {2, 3, 7, 6}, {1, 2, 6, 5}, {3, 0, 4, 7}};
    fputs("solid cube\n", f);
    for (int k = 0; k < 6; ++k)
        for (int t = 0; t < 2; ++t) {
            int a = q[k][0], b = q[k][1 + t], c = q[k][2 + t];
            fprintf(f, " facet normal 0 0 0\n  outer loop\n");
            fprintf(f, "   vertex %g %g %g\n   vertex %g %g %g\n   vertex %g %g %g\n", v[a][0],
                    v[a][1], v[a][2], v[b][0], v[b][1], v[b][2], v[c][0], v[c][1], v[c][2]);
            fprintf(f, "  endloop\n endfacet\n");
        }
    fputs("endsolid cube\n", f);
    fclose(f);
    render* r = make(false);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    world_snap_body* b = &snap.body[snap.nbody++];
    memset(b, 0, sizeof *b);
    snprintf(b->name, sizeof b->name, "cad_cube");
    b->role = WORLD_ROLE_OBSTACLE;
    b->shape = WORLD_SHAPE_SPHERE; // a different fallback, to tell them apart
    b->size[0] = 0.1;
    b->pos[0] = 4, b->pos[1] = -3, b->pos[2] = 0;
    b->rot[0] = b->rot[4] = b->rot[8] = 1;
    b->rgba[0] = 0.1f, b->rgba[1] = 0.9f, b->rgba[2] = 0.9f, b->rgba[3] = 1;
    snprintf(b->mesh, sizeof b->mesh, "%.127s", stl);
    b->mesh_scale = 0.001;
    b->mesh_up = 1;
    render_frame(r, &snap);
    render_stats st = render_get_stats(r);
    CHECK(st.mesh_warnings == 0, "STL loads (%d warnings)", st.mesh_warnings);
    render_read_pixels(r, px, W, H);
    // Its top face is 1 m up once y-up becomes z-up; sample 0.9 m up.
    double top[3] = {4, -3, 0.9}, q2[2];
    CHECK(render_project(r, top, q2), "projects");
    const unsigned char* c = at((int)q2[0], (int)q2[1]);
    CHECK(c[1] > c[0] + 30 && c[2] > c[0] + 30,
          "cyan cube 0.9 m up (y-up, mm scaled), rgb %d %d %d", c[0], c[1], c[2]);
    render_destroy(r);
}

static void test_warnings_shown(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    render_frame(r, &snap);
    static unsigned char calm[W * H * 4];
    render_read_pixels(r, calm, W, H);
    snap.tipping = 1;
    snap.cyl[0].relief_open = 1;
    snap.rt_factor = 0.8;
    render_frame(r, &snap);
    render_read_pixels(r, px, W, H);
    // Warning boxes are red and stacked at the top centre.
    int red = 0, red_calm = 0;
    for (int y = 0; y < 120; ++y)
        for (int x = W / 2 - 200; x < W / 2 + 200; ++x) {
            const unsigned char* c = at(x, y);
            const unsigned char* d = &calm[((size_t)y * W + x) * 4];
            red += c[0] > 140 && c[1] < 60 && c[2] < 60;
            red_calm += d[0] > 140 && d[1] < 60 && d[2] < 60;
        }
    CHECK(red > 3000 && red_calm == 0, "warning boxes: %d red pixels (calm frame %d)", red,
          red_calm);
    render_destroy(r);
}

// The rated capacity bar, bottom right (docs/safety.md): the fill grows
// with rcl_util, full at 120 %, a white mark at 100 %; green below 90 %,
// amber from 90 % to 100 %, red beyond.
typedef struct bar_scan {
    int green, amber, red; ///< fill length in the bar's middle row, per colour [px]
    int x0;                ///< where the fill starts [px], -1 if none
    int mark;              ///< the 100 % mark's column [px], -1 if none
} bar_scan;

static bool near_rgb(const unsigned char* c, int r, int g, int b) {
    return abs(c[0] - r) <= 3 && abs(c[1] - g) <= 3 && abs(c[2] - b) <= 3;
}

// The row of the bottom-right quarter with the most fill pixels, and on it
// the fill's length per colour and the white mark right of where it starts.
static bar_scan scan_rcl_bar(void) {
    bar_scan best = {0, 0, 0, -1, -1};
    for (int y = H / 2; y < H; ++y) {
        bar_scan b = {0, 0, 0, -1, -1};
        for (int x = W / 2; x < W; ++x) {
            const unsigned char* c = at(x, y);
            // The HUD's colours (hud.c): green 0.2 0.8 0.3, amber 1 0.7 0.15, red 1 0.1 0.1.
            const bool g = near_rgb(c, 51, 204, 77), a = near_rgb(c, 255, 178, 38), r = near_rgb(c, 255, 26, 26);
            if ((g || a || r) && b.x0 < 0) b.x0 = x;
            b.green += g, b.amber += a, b.red += r;
        }
        if (b.green + b.amber + b.red > best.green + best.amber + best.red) best = b;
    }
    return best;
}

// The white 100 % mark: the first white column right of x0 in rows y.
static int find_mark(int x0) {
    for (int x = x0 > 0 ? x0 : W / 2; x < W; ++x) {
        int n = 0;
        for (int y = H / 2; y < H; ++y) n += near_rgb(at(x, y), 255, 255, 255);
        if (n >= 14 && n <= 24) return x; // the mark is the bar's height plus 4 px; text is scattered
    }
    return -1;
}

static void test_rcl_bar(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    snap.rcl_have = false;
    render_frame(r, &snap);
    render_read_pixels(r, px, W, H);
    const bar_scan none = scan_rcl_bar();
    static const double util[3] = {0.5, 0.95, 1.1};
    bar_scan b[3];
    int mark[3];
    for (int k = 0; k < 3; ++k) {
        render_demo_scene(&snap, &p, terrain);
        snap.rcl_have = true, snap.rcl_on = true, snap.rcl_util = util[k];
        render_frame(r, &snap);
        render_read_pixels(r, px, W, H);
        b[k] = scan_rcl_bar();
        mark[k] = find_mark(b[k].x0);
        printf("  rcl_util %.2f: green %d, amber %d, red %d px from x %d, 100 %% mark at x %d\n", util[k], b[k].green,
               b[k].amber, b[k].red, b[k].x0, mark[k]);
    }
    CHECK(none.green + none.amber + none.red < 20, "no limiter: %d bar-coloured pixels in a row",
          none.green + none.amber + none.red);
    CHECK(b[0].green > 20 && b[0].amber == 0 && b[0].red == 0, "50 %%: green %d, amber %d, red %d", b[0].green,
          b[0].amber, b[0].red);
    CHECK(b[1].amber > 20 && b[1].green == 0 && b[1].red == 0, "95 %%: green %d, amber %d, red %d", b[1].green,
          b[1].amber, b[1].red);
    CHECK(b[2].red > 20 && b[2].green == 0 && b[2].amber == 0, "110 %%: green %d, amber %d, red %d", b[2].green,
          b[2].amber, b[2].red);
    // Length: the fill from its start to the 100 % mark is 100 %.
    CHECK(mark[0] > b[0].x0 && mark[0] == mark[1], "100 %% mark at %d and %d px", mark[0], mark[1]);
    if (mark[0] > b[0].x0) {
        const double full = mark[0] + 1 - b[0].x0; // the mark is 2 px wide, centred on 100 %
        CHECK_NEAR(b[0].green, 0.5 * full, 2.0);
        CHECK_NEAR(b[1].amber, 0.95 * full, 2.0);
        // Beyond the mark the fill runs on (the mark covers 2 px of it).
        CHECK_NEAR(b[2].red, 1.1 * full - 2, 3.0);
    }
    render_destroy(r);
}

static void test_panel_draws_offscreen(void) {
    render* r = make(true);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    render_frame(r, &snap);
    static unsigned char before[W * H * 4];
    render_read_pixels(r, before, W, H);
    panel* pn = panel_create();
    double bore = 0.1;
    panel_param_def d = {"bore", "lift cylinder", "m", &bore, 0.05, 0.2, 0.005, false};
    panel_add_param(pn, &d);
    CHECK(render_attach_panel(r, pn), "ImGui panel starts on the offscreen context");
    // ImGui needs a frame or two to lay out its window.
    for (int i = 0; i < 3; ++i)
        render_frame(r, &snap);
    render_read_pixels(r, px, W, H);
    int diff = 0;
    for (int y = 20; y < 200; ++y)
        for (int x = W - 330; x < W - 20; ++x)
            diff += memcmp(at(x, y), &before[((size_t)y * W + x) * 4], 3) != 0;
    CHECK(diff > 1000, "panel window drawn top right (%d pixels changed)", diff);
    render_attach_panel(r, NULL);
    render_destroy(r);
    panel_destroy(pn);
}

// A mesh is drawn where render_body_point says: its origin at pos + R
// offset, not at the primitive's centre pos. (The drive tests check the
// crane's joints through render_body_point, so it must be what the scene does.)
static void test_mesh_drawn_where_body_point_says(void) {
    render* r = make(false);
    if (!r) return;
    memset(&snap, 0, sizeof snap);
    snap.nbody = 1;
    world_snap_body* b = &snap.body[0];
    snprintf(b->name, sizeof b->name, "probe");
    b->role = WORLD_ROLE_OBSTACLE;
    b->shape = WORLD_SHAPE_BOX;
    b->size[0] = b->size[1] = b->size[2] = 0.3;
    b->pos[2] = 1.0;
    // Turned 90 degrees about z: the offset along body x goes to world y.
    b->rot[1] = -1, b->rot[3] = 1, b->rot[8] = 1;
    b->rgba[0] = 1, b->rgba[1] = 0.1f, b->rgba[2] = 1, b->rgba[3] = 1;
    snprintf(b->mesh, sizeof b->mesh, "load_block.obj"); // 1.2 x 0.6 x 0.6 m, origin at its centre
    b->mesh_scale = 1;
    b->mesh_up = 2;
    b->mesh_offset[0] = 2.5;
    const double o[3] = {0, 0, 0};
    double centre[3];
    render_body_point(b, o, centre);
    CHECK(fabs(centre[0]) < 1e-12 && fabs(centre[1] - 2.5) < 1e-12 && fabs(centre[2] - 1.0) < 1e-12,
          "mesh origin at (%g, %g, %g), want (0, 2.5, 1)", centre[0], centre[1], centre[2]);
    const double target[3] = {0, 1.25, 1};
    render_set_orbit(r, target, 0.3, 0.25, 9.0);
    render_frame(r, &snap);
    CHECK(render_get_stats(r).mesh_warnings == 0, "load_block.obj loads");
    render_read_pixels(r, px, W, H);
    double q[2];
    CHECK(render_project(r, centre, q), "mesh centre projects");
    const unsigned char* c = at((int)q[0], (int)q[1]);
    CHECK(c[0] > c[1] + 40 && c[2] > c[1] + 40, "magenta block at its mesh origin, rgb %d %d %d", c[0], c[1],
          c[2]);
    CHECK(render_project(r, b->pos, q), "body origin projects");
    c = at((int)q[0], (int)q[1]);
    CHECK(!(c[0] > c[1] + 40 && c[2] > c[1] + 40), "block drawn at the primitive's centre, rgb %d %d %d", c[0],
          c[1], c[2]);
    render_destroy(r);
}

// A PNG that cannot be written fully (a full disk: /dev/full) is an error
// with the system's reason, not a saved picture.
static void test_png_write_failure(void) {
    render* r = make(false);
    if (!r) return;
    render_demo_params p = render_demo_default_params();
    render_demo_scene(&snap, &p, terrain);
    render_frame(r, &snap);
    char err[512] = "";
    CHECK(render_save_png(r, "/dev/full", err, sizeof err) == -1, "PNG to /dev/full reported written");
    CHECK(strstr(err, "/dev/full") && strstr(err, strerror(ENOSPC)), "message: %s", err);
    CHECK(render_save_png(r, "/nonexistent/dir/x.png", err, sizeof err) == -1 && strstr(err, strerror(ENOENT)),
          "missing directory: %s", err);
    char path[512];
    snprintf(path, sizeof path, "%s/render_save.png", CRANESIM_BINARY_DIR);
    CHECK(render_save_png(r, path, err, sizeof err) == 0, "save: %s", err);
    render_destroy(r);
}

// A window asked for where SDL has no screen (its offscreen driver, which
// these tests run under) is refused: it would be a window nobody sees.
static void test_window_needs_a_screen(void) {
    render_config cfg = render_default_config();
    cfg.offscreen = false;
    cfg.vsync = false;
    char err[256] = "";
    render* r = render_create(&cfg, err, sizeof err);
    CHECK(r == NULL, "window created under SDL's '%s' video driver", SDL_GetCurrentVideoDriver());
    CHECK(strstr(err, "cannot open a window") && strstr(err, "has no screen"), "message: %s", err);
    render_destroy(r);
    // Offscreen still works afterwards.
    r = make(false);
    render_destroy(r);
}

int main(int argc, char** argv) {
    RUN_TEST(test_frame_not_blank_and_png);
    RUN_TEST(test_crane_where_it_projects);
    RUN_TEST(test_pressure_bars_follow_pressure);
    RUN_TEST(test_status_line_inside_readouts);
    RUN_TEST(test_camera_presets);
    RUN_TEST(test_zoom_per_notch);
    RUN_TEST(test_default_view_above_the_charts);
    RUN_TEST(test_missing_mesh_falls_back);
    RUN_TEST(test_cad_mesh_formats);
    RUN_TEST(test_warnings_shown);
    RUN_TEST(test_rcl_bar);
    RUN_TEST(test_panel_draws_offscreen);
    RUN_TEST(test_mesh_drawn_where_body_point_says);
    RUN_TEST(test_png_write_failure);
    RUN_TEST(test_window_needs_a_screen);
    SDL_Quit();
    TEST_MAIN_END();
}
