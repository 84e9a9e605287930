// scene.c: turn a world_snapshot into draws: terrain or flat ground, every
// body (its mesh, or its primitive shape as a fallback), each hydraulic
// cylinder as barrel + rod between its pins, and the rope.
//
// A frame first builds a flat draw list (mesh, model matrix, colour), then
// runs it twice: depth-only from the sun into the shadow map, and lit from
// the camera. No buffer is written per frame except uniforms.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render_internal.h"

typedef struct render_draw_item {
    const render_mesh* mesh; ///< a primitive or a cache entry (both stable)
    float model[16];
    float rgba[4];
    float depth; ///< squared distance from the eye, for sorting
    bool casts_shadow;
} render_draw_item;

static int nearer_first(const void* a, const void* b) {
    float da = ((const render_draw_item*)a)->depth, db = ((const render_draw_item*)b)->depth;
    return da < db ? -1 : da > db;
}

// ---- shaders ---------------------------------------------------------------

static const char* k_scene_vs = "#version 330 core\n"
                                "layout(location = 0) in vec3 a_pos;\n"
                                "layout(location = 1) in vec3 a_nrm;\n"
                                "layout(location = 2) in vec3 a_tint;\n"
                                "uniform mat4 u_model;\n"
                                "uniform mat3 u_normal;\n"
                                "uniform mat4 u_vp;\n"
                                "uniform mat4 u_light_vp;\n"
                                "uniform vec3 u_light_dir;\n"
                                "uniform vec3 u_eye;\n"
                                "out vec3 v_half;\n"

                                "out vec3 v_world;\n"
                                "out vec3 v_nrm;\n"
                                "out vec3 v_tint;\n"
                                "out vec4 v_lightpos;\n"
                                "void main() {\n"
                                "    vec4 w = u_model * vec4(a_pos, 1.0);\n"
                                "    v_world = w.xyz;\n"
                                "    v_nrm = u_normal * a_nrm;\n"
                                "    v_tint = a_tint;\n"
                                "    v_lightpos = u_light_vp * w;\n"
                                // Per-vertex terms: interpolating them is close enough and saves
                                // per-pixel work, which is what llvmpipe pays for.
                                "    vec3 to_eye = u_eye - w.xyz;\n"
                                "    float d = length(to_eye);\n"
                                "    v_half = normalize(u_light_dir + to_eye / d);\n"

                                "    gl_Position = u_vp * w;\n"
                                "}\n";

// Objects: Lambert + Blinn with a sky/ground hemisphere ambient. Written
// for llvmpipe, where every ALU op is paid per pixel on the CPU: one shadow
// lookup (the depth comparison + linear filter give 2x2 PCF in hardware),
// the specular power by repeated squaring instead of pow(), the half vector
// from the vertex shader, no haze (objects are near).
static const char* k_obj_fs =
    "#version 330 core\n"
    "in vec3 v_world;\n"
    "in vec3 v_nrm;\n"
    "in vec3 v_tint;\n"
    "in vec4 v_lightpos;\n"
    "in vec3 v_half;\n"
    "uniform vec4 u_color;\n"
    "uniform vec3 u_light_dir;\n"
    "uniform sampler2DShadow u_shadow;\n"
    "out vec4 o_color;\n"
    "void main() {\n"
    // Normals are trusted as given (not flipped by winding): CAD exports
    // often have inconsistent winding but sound normals.
    "    vec3 n = normalize(v_nrm);\n"
    "    vec3 l = u_light_dir;\n"
    "    float ndl = max(dot(n, l), 0.0);\n"
    "    vec3 q = v_lightpos.xyz * 0.5 + 0.5;\n"
    "    float sh = texture(u_shadow, vec3(q.xy, q.z - 0.0015 - 0.003 * (1.0 - ndl)));\n"
    "    float s = max(dot(n, v_half), 0.0);\n"
    "    s *= s; s *= s; s *= s; s *= s; s *= s;\n"
    "    vec3 amb = mix(vec3(0.18, 0.165, 0.15), vec3(0.31, 0.35, 0.41), 0.5 + 0.5 * n.z);\n"
    "    vec3 c = u_color.rgb * v_tint * (amb + (0.80 * ndl * sh) * vec3(1.0, 0.97, 0.90)) + (0.22 "
    "* s * sh);\n"
    "    o_color = vec4(c, u_color.a);\n"
    "}\n";

// Ground and terrain: a 1 m grid to judge distance and motion, the shadow,
// and aerial haze toward the horizon. No specular.
static const char* k_ground_fs =
    "#version 330 core\n"
    "in vec3 v_world;\n"
    "in vec3 v_nrm;\n"
    "in vec4 v_lightpos;\n"
    "uniform vec4 u_color;\n"
    "uniform vec3 u_light_dir;\n"
    "uniform vec3 u_eye;\n"
    "uniform sampler2DShadow u_shadow;\n"
    "out vec4 o_color;\n"
    "void main() {\n"
    "    vec2 g = abs(fract(v_world.xy + 0.5) - 0.5) / max(fwidth(v_world.xy), vec2(1e-4));\n"
    "    float line = 0.12 * (1.0 - clamp(min(g.x, g.y), 0.0, 1.0));\n"
    "    float ndl = max(dot(v_nrm, u_light_dir), 0.0);\n"
    "    vec3 q = v_lightpos.xyz * 0.5 + 0.5;\n"
    "    float sh = texture(u_shadow, vec3(q.xy, q.z - 0.002));\n"
    "    vec3 c = u_color.rgb * (1.0 - line) * (vec3(0.30, 0.33, 0.38) + (0.80 * ndl * sh) * "
    "vec3(1.0, 0.97, 0.90));\n"
    // Haze: a rational stand-in for 1 - exp(-k d), cheaper on llvmpipe.
    "    float kd = 0.0035 * length(u_eye - v_world);\n"
    "    o_color = vec4(mix(c, vec3(0.74, 0.80, 0.88), kd / (1.0 + kd)), 1.0);\n"
    "}\n";

static const char* k_depth_vs =
    "#version 330 core\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "uniform mat4 u_model;\n"
    "uniform mat4 u_vp;\n"
    "void main() { gl_Position = u_vp * (u_model * vec4(a_pos, 1.0)); }\n";

static const char* k_depth_fs = "#version 330 core\n"
                                "void main() {}\n";

// Sky: one triangle covering the screen, vertical gradient.
static const char* k_sky_vs =
    "#version 330 core\n"
    "out float v_y;\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID >> 1) * 4 - 1));\n"
    "    v_y = p.y * 0.5 + 0.5;\n"
    "    gl_Position = vec4(p, 1.0, 1.0);\n"
    "}\n";

static const char* k_sky_fs =
    "#version 330 core\n"
    "in float v_y;\n"
    "uniform vec3 u_top;\n"
    "uniform vec3 u_bottom;\n"
    "out vec4 o_color;\n"
    "void main() { o_color = vec4(mix(u_bottom, u_top, clamp(v_y, 0.0, 1.0)), 1.0); }\n";

// ---- setup -----------------------------------------------------------------

static render_mesh make_ground(void) {
    // One big quad: the fragment shader draws the grid, haze hides the edge.
    const float e = 600.0f;
    render_vertex v[4];
    memset(v, 0, sizeof v);
    const float xy[4][2] = {{-e, -e}, {e, -e}, {e, e}, {-e, e}};
    for (int i = 0; i < 4; ++i) {
        v[i].p[0] = xy[i][0], v[i].p[1] = xy[i][1];
        v[i].n[2] = 1.0f;
        v[i].c[0] = v[i].c[1] = v[i].c[2] = 1.0f;
    }
    const unsigned idx[6] = {0, 1, 2, 0, 2, 3};
    return render_mesh_upload(v, 4, idx, 6);
}

static bool lit_prog(render_lit_prog* p, const char* name, const char* fs) {
    p->id = render_shader_build(name, k_scene_vs, fs);
    if (!p->id) return false;
    p->u_model = glGetUniformLocation(p->id, "u_model");
    p->u_normal = glGetUniformLocation(p->id, "u_normal");
    p->u_vp = glGetUniformLocation(p->id, "u_vp");
    p->u_light_vp = glGetUniformLocation(p->id, "u_light_vp");
    p->u_color = glGetUniformLocation(p->id, "u_color");
    p->u_light_dir = glGetUniformLocation(p->id, "u_light_dir");
    p->u_eye = glGetUniformLocation(p->id, "u_eye");
    p->u_shadow = glGetUniformLocation(p->id, "u_shadow");
    return true;
}

bool render_scene_create(render_scene* sc) {
    memset(sc, 0, sizeof *sc);
    if (!lit_prog(&sc->obj, "objects", k_obj_fs) ||
        !lit_prog(&sc->ground_prog, "ground", k_ground_fs))
        return false;
    sc->depth_prog = render_shader_build("depth", k_depth_vs, k_depth_fs);
    sc->sky_prog = render_shader_build("sky", k_sky_vs, k_sky_fs);
    if (!sc->depth_prog || !sc->sky_prog) return false;
    sc->ud_model = glGetUniformLocation(sc->depth_prog, "u_model");
    sc->ud_vp = glGetUniformLocation(sc->depth_prog, "u_vp");
    sc->us_top = glGetUniformLocation(sc->sky_prog, "u_top");
    sc->us_bottom = glGetUniformLocation(sc->sky_prog, "u_bottom");
    glGenVertexArrays(1, &sc->sky_vao);
    render_prims_create(sc->prim);
    sc->ground = make_ground();
    // Worst case: a capsule is 3 draws per body, plus cylinders and rope.
    sc->capitems =
        3 * WORLD_SNAP_MAX_BODIES + 2 * WORLD_SNAP_MAX_CYLINDERS + WORLD_SNAP_MAX_ROPE + 4;
    sc->items = calloc((size_t)sc->capitems, sizeof *sc->items);
    return sc->items != NULL;
}

void render_scene_free(render_scene* sc) {
    for (int i = 0; i < RENDER_PRIM_COUNT; ++i)
        render_mesh_free(&sc->prim[i]);
    render_mesh_free(&sc->ground);
    render_mesh_free(&sc->terrain);
    for (int i = 0; i < sc->ncmesh; ++i) render_mesh_free(&sc->cmesh[i].mesh);
    sc->ncmesh = 0;
    if (sc->sky_vao) glDeleteVertexArrays(1, &sc->sky_vao);
    if (sc->obj.id) glDeleteProgram(sc->obj.id);
    if (sc->ground_prog.id) glDeleteProgram(sc->ground_prog.id);
    if (sc->depth_prog) glDeleteProgram(sc->depth_prog);
    if (sc->sky_prog) glDeleteProgram(sc->sky_prog);
    free(sc->items);
    memset(sc, 0, sizeof *sc);
}

// ---- terrain -----------------------------------------------------------------

/// Rebuild the heightfield mesh only when the snapshot points at a different
/// grid: the world owns the heights and they do not change during a run.
/// Cells per side of the drawn terrain mesh at most (see update_terrain).
#define TERRAIN_MAX_CELLS 64

static void update_terrain(render_scene* sc, const world_snap_terrain* t) {
    if (t->nx < 2 || t->ny < 2 || !t->height) return;
    if (sc->terrain.vao && sc->terrain_src == t->height && sc->terrain_nx == t->nx &&
        sc->terrain_ny == t->ny && sc->terrain_dx == t->dx && sc->terrain_dy == t->dy)
        return;
    render_mesh_free(&sc->terrain);
    int nx = t->nx, ny = t->ny;
    render_vertex* v = calloc((size_t)nx * (size_t)ny, sizeof *v);
    unsigned* idx = malloc((size_t)(nx - 1) * (size_t)(ny - 1) * 6 * sizeof *idx);
    if (!v || !idx) {
        free(v);
        free(idx);
        return;
    }
    float x0 = -0.5f * (float)(nx - 1) * (float)t->dx, y0 = -0.5f * (float)(ny - 1) * (float)t->dy;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            render_vertex* p = &v[j * nx + i];
            p->p[0] = x0 + (float)i * (float)t->dx;
            p->p[1] = y0 + (float)j * (float)t->dy;
            p->p[2] = t->height[j * nx + i];
            // Central differences (one-sided at the border) for the normal.
            int i0 = i > 0 ? i - 1 : i, i1 = i < nx - 1 ? i + 1 : i;
            int j0 = j > 0 ? j - 1 : j, j1 = j < ny - 1 ? j + 1 : j;
            float dzdx = (t->height[j * nx + i1] - t->height[j * nx + i0]) /
                         ((float)(i1 - i0) * (float)t->dx);
            float dzdy = (t->height[j1 * nx + i] - t->height[j0 * nx + i]) /
                         ((float)(j1 - j0) * (float)t->dy);
            rm_vec3 n = rm_norm(rm_v3(-dzdx, -dzdy, 1.0f));
            p->n[0] = n.x, p->n[1] = n.y, p->n[2] = n.z;
            p->c[0] = p->c[1] = p->c[2] = 1.0f;
        }
    // Triangles over every s-th sample (s chosen for at most 64 cells per
    // side, plus the last row/column), vertices keep their exact heights and
    // full-resolution normals. The sandbox's 121 x 121 field drew 28,800
    // mostly sub-pixel triangles out to the horizon, about 4.5 ms per frame
    // of llvmpipe setup; at stride 2 its flat work area is unchanged and the
    // gentle hills differ by centimetres between samples.
    int sx = (nx - 1 + TERRAIN_MAX_CELLS - 1) / TERRAIN_MAX_CELLS;
    int sy = (ny - 1 + TERRAIN_MAX_CELLS - 1) / TERRAIN_MAX_CELLS;
    int k = 0;
    for (int j = 0; j < ny - 1; j += sy) {
        int j1 = j + sy < ny - 1 ? j + sy : ny - 1;
        for (int i = 0; i < nx - 1; i += sx) {
            int i1 = i + sx < nx - 1 ? i + sx : nx - 1;
            unsigned a = (unsigned)(j * nx + i), b = (unsigned)(j * nx + i1);
            unsigned c = (unsigned)(j1 * nx + i), d = (unsigned)(j1 * nx + i1);
            idx[k++] = a, idx[k++] = b, idx[k++] = d;
            idx[k++] = a, idx[k++] = d, idx[k++] = c;
        }
    }
    sc->terrain = render_mesh_upload(v, nx * ny, idx, k);
    free(v);
    free(idx);
    sc->terrain_src = t->height;
    sc->terrain_nx = nx, sc->terrain_ny = ny;
    sc->terrain_dx = t->dx, sc->terrain_dy = t->dy;
}

// ---- draw list -----------------------------------------------------------------

static render_draw_item* push_item(render_scene* sc, const render_mesh* m, const float rgba[4]) {
    if (sc->nitems >= sc->capitems) return NULL;
    render_draw_item* it = &sc->items[sc->nitems++];
    it->mesh = m;
    memcpy(it->rgba, rgba, 4 * sizeof(float));
    it->casts_shadow = true;
    return it;
}

/// Model matrix whose local x runs from a to b, scaled to |b - a| along x
/// and by radius across (for the unit barrel/rod/tube meshes).
static void segment_matrix(float m[16], rm_vec3 a, rm_vec3 b, float radius, float length) {
    rm_vec3 x = rm_norm(rm_sub(b, a));
    rm_vec3 hint = fabsf(x.z) < 0.95f ? rm_v3(0, 0, 1) : rm_v3(1, 0, 0);
    rm_vec3 y = rm_norm(rm_cross(hint, x));
    rm_vec3 z = rm_cross(x, y);
    rm_identity(m);
    m[0] = x.x * length, m[1] = x.y * length, m[2] = x.z * length;
    m[4] = y.x * radius, m[5] = y.y * radius, m[6] = y.z * radius;
    m[8] = z.x * radius, m[9] = z.y * radius, m[10] = z.z * radius;
    m[12] = a.x, m[13] = a.y, m[14] = a.z;
}

static rm_vec3 v3d(const double p[3]) {
    return rm_v3((float)p[0], (float)p[1], (float)p[2]);
}

static void add_body_items(render_scene* sc, render_mesh_cache* mc, const world_snap_body* b);

void render_body_point(const world_snap_body* b, const double p[3], double world[3]) {
    // Mesh: p in mesh units, scaled to metres and shifted by the mesh origin's
    // place in the body frame; primitive: p already in the body frame [m].
    const bool mesh = b->mesh[0] != 0;
    const double s = mesh && b->mesh_scale > 0 ? b->mesh_scale : 1.0;
    double q[3];
    for (int k = 0; k < 3; ++k) q[k] = s * p[k] + (mesh ? b->mesh_offset[k] : 0.0);
    for (int r = 0; r < 3; ++r)
        world[r] = b->pos[r] + b->rot[r * 3 + 0] * q[0] + b->rot[r * 3 + 1] * q[1] + b->rot[r * 3 + 2] * q[2];
}

bool render_body_local_bounds(render_mesh_cache* mc, const world_snap_body* b, double lo[3], double hi[3]) {
    if (b->shape == WORLD_SHAPE_TERRAIN || b->role == WORLD_ROLE_TERRAIN) return false;
    const render_mesh* mesh = b->mesh[0] ? render_mesh_get(mc, b->mesh, b->mesh_up) : NULL;
    if (mesh) {
        // As drawn: s p + offset in the body frame (render_body_point).
        const double s = b->mesh_scale > 0 ? b->mesh_scale : 1.0;
        for (int k = 0; k < 3; ++k) {
            lo[k] = s * mesh->bmin[k] + b->mesh_offset[k];
            hi[k] = s * mesh->bmax[k] + b->mesh_offset[k];
        }
        return true;
    }
    double e[3];
    switch (b->shape) {
    case WORLD_SHAPE_BOX:
        e[0] = 0.5 * b->size[0], e[1] = 0.5 * b->size[1], e[2] = 0.5 * b->size[2];
        break;
    case WORLD_SHAPE_CYLINDER:
        e[0] = e[1] = b->size[0], e[2] = 0.5 * b->size[1];
        break;
    case WORLD_SHAPE_CAPSULE:
        e[0] = e[1] = b->size[0], e[2] = 0.5 * b->size[1] + b->size[0];
        break;
    case WORLD_SHAPE_SPHERE:
        e[0] = e[1] = e[2] = b->size[0];
        break;
    default:
        return false;
    }
    for (int k = 0; k < 3; ++k) lo[k] = -e[k], hi[k] = e[k];
    return true;
}

static void add_body(render_scene* sc, render_mesh_cache* mc, const world_snap_body* b) {
    if (b->shape == WORLD_SHAPE_TERRAIN || b->role == WORLD_ROLE_TERRAIN) return;
    int first = sc->nitems;
    add_body_items(sc, mc, b);
    // Wheels stand in the truck's own shadow and are the densest meshes;
    // leaving them out of the shadow pass halves its vertex work.
    if (b->role == WORLD_ROLE_WHEEL)
        for (int i = first; i < sc->nitems; ++i)
            sc->items[i].casts_shadow = false;
}

static void add_body_items(render_scene* sc, render_mesh_cache* mc, const world_snap_body* b) {
    const render_mesh* mesh = b->mesh[0] ? render_mesh_get(mc, b->mesh, b->mesh_up) : NULL;
    if (mesh) {
        // world = R (s p + offset) + pos: the mesh origin goes where
        // render_body_point puts p = 0, so tests can check what is drawn.
        float s = b->mesh_scale > 0 ? (float)b->mesh_scale : 1.0f;
        float sc3[3] = {s, s, s};
        static const double origin[3] = {0, 0, 0};
        double pos[3];
        render_body_point(b, origin, pos);
        render_draw_item* it = push_item(sc, mesh, b->rgba);
        if (it) rm_model(it->model, b->rot, sc3, pos);
        return;
    }
    float sx = (float)b->size[0], sy = (float)b->size[1], sz = (float)b->size[2];
    switch (b->shape) {
    case WORLD_SHAPE_BOX: {
        float s3[3] = {sx, sy, sz};
        render_draw_item* it = push_item(sc, &sc->prim[RENDER_PRIM_BOX], b->rgba);
        if (it) rm_model(it->model, b->rot, s3, b->pos);
        break;
    }
    case WORLD_SHAPE_CYLINDER: {
        float s3[3] = {sx, sx, sy};
        render_draw_item* it = push_item(sc, &sc->prim[RENDER_PRIM_CYLINDER], b->rgba);
        if (it) rm_model(it->model, b->rot, s3, b->pos);
        break;
    }
    case WORLD_SHAPE_SPHERE: {
        float s3[3] = {sx, sx, sx};
        render_draw_item* it = push_item(sc, &sc->prim[RENDER_PRIM_SPHERE], b->rgba);
        if (it) rm_model(it->model, b->rot, s3, b->pos);
        break;
    }
    case WORLD_SHAPE_CAPSULE: {
        float s3[3] = {sx, sx, sy};
        render_draw_item* it = push_item(sc, &sc->prim[RENDER_PRIM_CYLINDER], b->rgba);
        if (it) rm_model(it->model, b->rot, s3, b->pos);
        // Two hemispheres at +-length/2 along the body z; the lower one is
        // mirrored (negative z scale) so it bulges downward.
        for (int end = 0; end < 2; ++end) {
            float sgn = end ? 1.0f : -1.0f;
            float e3[3] = {sx, sx, sgn * sx};
            double p[3];
            for (int r = 0; r < 3; ++r)
                p[r] = b->pos[r] + b->rot[r * 3 + 2] * sgn * 0.5 * sy;
            render_draw_item* h = push_item(sc, &sc->prim[RENDER_PRIM_HEMISPHERE], b->rgba);
            if (h) rm_model(h->model, b->rot, e3, p);
        }
        break;
    }
    default:
        break;
    }
}

static void add_cylinder(render_scene* sc, render_mesh_cache* mc, const world_snap_cylinder* c) {
    rm_vec3 a = v3d(c->base), b = v3d(c->rod_end);
    float len = rm_len(rm_sub(b, a));
    if (len < 1e-4f || c->bore <= 0) return;
    // Barrel: from the base pin, nearly the closed length (the rod eye and
    // gland make up the rest); rod: from the rod-end pin back into the barrel.
    float barrel_len = (float)(c->closed_length > 0 ? 0.9 * c->closed_length : 0.6 * len);
    if (barrel_len > len) barrel_len = len;
    float rod_len = len - barrel_len + 0.15f * barrel_len;
    if (rod_len > len) rod_len = len;
    float barrel_r = 0.5f * (float)c->bore * 1.28f; // bore + wall
    float rod_r = 0.5f * (float)(c->rod > 0 ? c->rod : 0.6 * c->bore);
    const render_mesh* barrel = render_mesh_get(mc, "cyl_barrel.obj", 2);
    const render_mesh* rod = render_mesh_get(mc, "cyl_rod.obj", 2);
    static const float barrel_rgba[4] = {0.23f, 0.25f, 0.28f, 1.0f};
    static const float rod_rgba[4] = {0.86f, 0.88f, 0.90f, 1.0f};
    render_draw_item* it =
        push_item(sc, barrel ? barrel : &sc->prim[RENDER_PRIM_TUBE_X], barrel_rgba);
    if (it) segment_matrix(it->model, a, b, barrel_r, barrel_len);
    it = push_item(sc, rod ? rod : &sc->prim[RENDER_PRIM_TUBE_X], rod_rgba);
    if (it) segment_matrix(it->model, b, a, rod_r, rod_len);
}

static void add_rope(render_scene* sc, const world_snapshot* s) {
    static const float rope_rgba[4] = {0.10f, 0.10f, 0.10f, 1.0f};
    // Thicker than a real 10 mm rope so it stays visible from 20 m away.
    const float r = 0.018f;
    int n = s->nrope < WORLD_SNAP_MAX_ROPE ? s->nrope : WORLD_SNAP_MAX_ROPE;
    if (n >= 2) {
        for (int i = 0; i + 1 < n; ++i) {
            rm_vec3 a = v3d(s->rope[i]), b = v3d(s->rope[i + 1]);
            float l = rm_len(rm_sub(b, a));
            if (l < 1e-5f) continue;
            render_draw_item* it = push_item(sc, &sc->prim[RENDER_PRIM_TUBE_X], rope_rgba);
            if (it) segment_matrix(it->model, a, b, r, l);
        }
    } else {
        // No rope polyline: a straight rope from tip to hook, if they differ.
        rm_vec3 a = v3d(s->tip), b = v3d(s->hook);
        float l = rm_len(rm_sub(b, a));
        if (l > 0.05f) {
            render_draw_item* it = push_item(sc, &sc->prim[RENDER_PRIM_TUBE_X], rope_rgba);
            if (it) segment_matrix(it->model, a, b, r, l);
        }
    }
}

/// Bounding sphere of the machine and nearby things, for the shadow box.
static void scene_bounds(const world_snapshot* s, rm_vec3* centre, float* radius) {
    rm_vec3 lo = rm_v3(1e30f, 1e30f, 1e30f), hi = rm_scale(lo, -1.0f);
    int n = 0;
    for (int i = 0; i < s->nbody && i < WORLD_SNAP_MAX_BODIES; ++i) {
        const world_snap_body* b = &s->body[i];
        if (b->shape == WORLD_SHAPE_TERRAIN || b->role == WORLD_ROLE_TERRAIN) continue;
        float e = (float)fmax(fmax(b->size[0], b->size[1]), b->size[2]);
        if (b->shape != WORLD_SHAPE_BOX) e = (float)fmax(b->size[0], b->size[1]);
        rm_vec3 p = v3d(b->pos);
        lo = rm_v3(fminf(lo.x, p.x - e), fminf(lo.y, p.y - e), fminf(lo.z, p.z - e));
        hi = rm_v3(fmaxf(hi.x, p.x + e), fmaxf(hi.y, p.y + e), fmaxf(hi.z, p.z + e));
        ++n;
    }
    if (!n) {
        *centre = rm_v3(0, 0, 2);
        *radius = 10;
        return;
    }
    lo.z = fminf(lo.z, 0.0f);
    *centre = rm_scale(rm_add(lo, hi), 0.5f);
    *radius = 0.5f * rm_len(rm_sub(hi, lo));
    // Too small a box clips shadows; too big a box blurs them.
    if (*radius < 6.0f) *radius = 6.0f;
    if (*radius > 40.0f) *radius = 40.0f;
}

// ---- the two passes ---------------------------------------------------------------

/// Cull back faces only for meshes with consistent winding; a mirrored
/// model matrix (negative determinant, e.g. the lower capsule cap) turns
/// the winding around.
static void set_cull(const render_mesh* mesh, const float m[16]) {
    if (!mesh->cull) {
        glDisable(GL_CULL_FACE);
        return;
    }
    float det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
                m[8] * (m[1] * m[6] - m[5] * m[2]);
    glEnable(GL_CULL_FACE);
    glFrontFace(det < 0 ? GL_CW : GL_CCW);
}

static void use_lit(const render_lit_prog* p, const render_camera* cam, const render_shadow* sh) {
    glUseProgram(p->id);
    glUniformMatrix4fv(p->u_vp, 1, GL_FALSE, cam->viewproj);
    glUniformMatrix4fv(p->u_light_vp, 1, GL_FALSE, sh->light_vp);
    glUniform3f(p->u_light_dir, sh->light_dir.x, sh->light_dir.y, sh->light_dir.z);
    glUniform3f(p->u_eye, cam->eye.x, cam->eye.y, cam->eye.z);
    glUniform1i(p->u_shadow, 0);
}

// ---- debug view: collision shapes -------------------------------------------

// The GL mesh of a world collision mesh (uploaded the first time it is seen;
// the world's arrays do not change while it lives).
static const render_mesh* coll_mesh(render_scene* sc, const world_snap_coll* c) {
    for (int i = 0; i < sc->ncmesh; ++i)
        if (sc->cmesh[i].key == c->v) return &sc->cmesh[i].mesh;
    if (sc->ncmesh >= (int)(sizeof sc->cmesh / sizeof sc->cmesh[0])) return NULL;
    render_vertex* v = calloc((size_t)(c->nv ? c->nv : 1), sizeof *v);
    unsigned* idx = malloc((size_t)3 * (c->nt ? c->nt : 1) * sizeof *idx);
    if (!v || !idx) {
        free(v);
        free(idx);
        return NULL;
    }
    for (int i = 0; i < c->nv; ++i) {
        memcpy(v[i].p, c->v + 3 * i, sizeof v[i].p);
        v[i].n[2] = 1.0f;
        v[i].c[0] = v[i].c[1] = v[i].c[2] = 1.0f;
    }
    for (int i = 0; i < 3 * c->nt; ++i) idx[i] = (unsigned)c->idx[i];
    sc->cmesh[sc->ncmesh].key = c->v;
    sc->cmesh[sc->ncmesh].mesh = render_mesh_upload(v, c->nv, idx, 3 * c->nt);
    free(v);
    free(idx);
    return &sc->cmesh[sc->ncmesh++].mesh;
}

// Collision shapes as wireframes drawn over everything (depth test off), in
// the same world transform the physics uses, so a visual mesh that does not
// sit on its collision shape shows at once.
static void draw_collision(render_scene* sc, const render_camera* cam, render_shadow* sh, const world_snapshot* s) {
    static const float rgba[4] = {1.0f, 0.1f, 0.9f, 1.0f};
    const int first = sc->nitems;
    for (int i = 0; i < s->ncoll && i < WORLD_SNAP_MAX_COLL; ++i) {
        const world_snap_coll* c = &s->coll[i];
        world_snap_body b;
        memset(&b, 0, sizeof b);
        memcpy(b.pos, c->pos, sizeof b.pos);
        memcpy(b.rot, c->rot, sizeof b.rot);
        memcpy(b.size, c->size, sizeof b.size);
        memcpy(b.rgba, rgba, sizeof b.rgba);
        if (c->shape == WORLD_SHAPE_TERRAIN) {
            const render_mesh* m = coll_mesh(sc, c);
            render_draw_item* it = m ? push_item(sc, m, rgba) : NULL;
            const float one[3] = {1, 1, 1};
            if (it) rm_model(it->model, c->rot, one, c->pos);
        } else {
            b.shape = c->shape;
            add_body_items(sc, NULL, &b);
        }
    }
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    use_lit(&sc->obj, cam, sh);
    float nm[9];
    for (int i = first; i < sc->nitems; ++i) {
        const render_draw_item* it = &sc->items[i];
        rm_normal_matrix(nm, it->model);
        glUniformMatrix4fv(sc->obj.u_model, 1, GL_FALSE, it->model);
        glUniformMatrix3fv(sc->obj.u_normal, 1, GL_FALSE, nm);
        glUniform4fv(sc->obj.u_color, 1, it->rgba);
        render_mesh_draw(it->mesh);
        ++sc->draw_calls;
    }
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glEnable(GL_DEPTH_TEST);
    sc->nitems = first;
}

void render_scene_draw(render_scene* sc, render_mesh_cache* mc, render_shadow* sh,
                       const render_camera* cam, const world_snapshot* s, int w, int h) {
    sc->nitems = 0;
    sc->triangles = 0;
    sc->draw_calls = 0;
    update_terrain(sc, &s->terrain);
    for (int i = 0; i < s->nbody && i < WORLD_SNAP_MAX_BODIES; ++i)
        add_body(sc, mc, &s->body[i]);
    int ncyl = s->ncyl < WORLD_SNAP_MAX_CYLINDERS ? s->ncyl : WORLD_SNAP_MAX_CYLINDERS;
    for (int i = 0; i < ncyl; ++i)
        add_cylinder(sc, mc, &s->cyl[i]);
    add_rope(sc, s);

    rm_vec3 centre;
    float radius;
    scene_bounds(s, &centre, &radius);
    render_shadow_fit(sh, centre, radius);

    // Caller has the scene target bound; remember it for after the shadow pass.
    GLint target = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target);

    // Shadow pass: depth only, polygon offset against acne on the booms.
    glBindFramebuffer(GL_FRAMEBUFFER, sh->fbo);
    glViewport(0, 0, sh->size, sh->size);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);
    glUseProgram(sc->depth_prog);
    glUniformMatrix4fv(sc->ud_vp, 1, GL_FALSE, sh->light_vp);
    for (int i = 0; i < sc->nitems; ++i) {
        const render_draw_item* it = &sc->items[i];
        if (!it->casts_shadow) continue;
        glUniformMatrix4fv(sc->ud_model, 1, GL_FALSE, it->model);
        set_cull(it->mesh, it->model);
        render_mesh_draw(it->mesh);
        ++sc->draw_calls;
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_CULL_FACE);
    glFrontFace(GL_CCW);

    // Colour pass.
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)target);
    glViewport(0, 0, w, h);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);

    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, sh->tex);
    // Opaque things nearest the camera first, so the early depth test
    // skips shading most of the ground and sky behind them (llvmpipe is
    // fill-rate bound).
    for (int i = 0; i < sc->nitems; ++i) {
        const float* t = &sc->items[i].model[12];
        rm_vec3 d = rm_sub(rm_v3(t[0], t[1], t[2]), cam->eye);
        sc->items[i].depth = rm_dot(d, d);
    }
    qsort(sc->items, (size_t)sc->nitems, sizeof *sc->items, nearer_first);
    use_lit(&sc->obj, cam, sh);
    float nm[9];
    for (int i = 0; i < sc->nitems; ++i) {
        const render_draw_item* it = &sc->items[i];
        rm_normal_matrix(nm, it->model);
        glUniformMatrix4fv(sc->obj.u_model, 1, GL_FALSE, it->model);
        glUniformMatrix3fv(sc->obj.u_normal, 1, GL_FALSE, nm);
        glUniform4fv(sc->obj.u_color, 1, it->rgba);
        set_cull(it->mesh, it->model);
        render_mesh_draw(it->mesh);
        sc->triangles += it->mesh->nidx / 3;
        ++sc->draw_calls;
    }
    // Ground: the heightfield if there is one, and a flat plane beyond it.
    // Drawn both sides: the camera may dip below a hill.
    glDisable(GL_CULL_FACE);
    glFrontFace(GL_CCW);
    use_lit(&sc->ground_prog, cam, sh);
    float m[16];
    rm_identity(m);
    rm_normal_matrix(nm, m);
    glUniformMatrix3fv(sc->ground_prog.u_normal, 1, GL_FALSE, nm);
    const bool has_terrain = s->terrain.nx >= 2 && s->terrain.ny >= 2 && sc->terrain.vao;
    if (has_terrain) {
        static const float terrain_rgba[4] = {0.55f, 0.58f, 0.42f, 1.0f};
        glUniformMatrix4fv(sc->ground_prog.u_model, 1, GL_FALSE, m);
        glUniform4fv(sc->ground_prog.u_color, 1, terrain_rgba);
        render_mesh_draw(&sc->terrain);
        sc->triangles += sc->terrain.nidx / 3;
        ++sc->draw_calls;
    }
    {
        static const float ground_rgba[4] = {0.60f, 0.60f, 0.55f, 1.0f};
        // Under a heightfield, sink the plane to its lowest point.
        if (has_terrain) m[14] = sc->terrain.bmin[2] - 0.02f;
        glUniformMatrix4fv(sc->ground_prog.u_model, 1, GL_FALSE, m);
        glUniform4fv(sc->ground_prog.u_color, 1, ground_rgba);
        render_mesh_draw(&sc->ground);
        sc->triangles += 2;
        ++sc->draw_calls;
    }
    // Sky last, at the far plane: only pixels nothing else covered.
    glUseProgram(sc->sky_prog);
    glUniform3f(sc->us_top, 0.36f, 0.55f, 0.82f);
    glUniform3f(sc->us_bottom, 0.78f, 0.84f, 0.90f);
    glBindVertexArray(sc->sky_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    ++sc->draw_calls;
    glDepthFunc(GL_LESS);
    if (sc->show_collision) draw_collision(sc, cam, sh, s);
    glBindVertexArray(0);
}
