// camera.c: orbit / pan / zoom with the mouse, and presets that follow the
// snapshot (operator at the column, side view of the boom plane, hook).
#include <math.h>

#include "render_internal.h"

void render_camera_init(render_camera* c) {
    memset(c, 0, sizeof *c);
    c->preset = RENDER_CAM_ORBIT;
    // A three-quarter view from the right front, the way a photo of a truck
    // crane is usually taken.
    c->yaw = -1.25f;
    c->pitch = 0.42f;
    c->dist = 12.0f;
    c->fovy = 50.0f * (float)M_PI / 180.0f;
    c->target = rm_v3(0, 0, 2.5f);
}

static rm_vec3 v3d(const double p[3]) {
    return rm_v3((float)p[0], (float)p[1], (float)p[2]);
}

static const world_snap_body* find_role(const world_snapshot* s, world_role role) {
    for (int i = 0; i < s->nbody && i < WORLD_SNAP_MAX_BODIES; ++i)
        if (s->body[i].role == role) return &s->body[i];
    return NULL;
}

/// Terrain height under (x, y) [m], bilinear; 0 for flat ground.
static float ground_z(const world_snapshot* s, float x, float y) {
    const world_snap_terrain* t = &s->terrain;
    if (t->nx < 2 || t->ny < 2 || !t->height) return 0.0f;
    // Grid centred on the origin, as world_snapshot.h specifies.
    float fx = x / (float)t->dx + 0.5f * (float)(t->nx - 1),
          fy = y / (float)t->dy + 0.5f * (float)(t->ny - 1);
    if (fx < 0) fx = 0;
    if (fy < 0) fy = 0;
    if (fx > (float)(t->nx - 1)) fx = (float)(t->nx - 1);
    if (fy > (float)(t->ny - 1)) fy = (float)(t->ny - 1);
    int i = (int)fx, j = (int)fy;
    if (i > t->nx - 2) i = t->nx - 2;
    if (j > t->ny - 2) j = t->ny - 2;
    float u = fx - (float)i, v = fy - (float)j;
    const float* h = t->height;
    float h00 = h[j * t->nx + i], h10 = h[j * t->nx + i + 1];
    float h01 = h[(j + 1) * t->nx + i], h11 = h[(j + 1) * t->nx + i + 1];
    return (1 - v) * ((1 - u) * h00 + u * h10) + v * ((1 - u) * h01 + u * h11);
}

static rm_vec3 orbit_eye(const render_camera* c, rm_vec3 target) {
    float cp = cosf(c->pitch);
    return rm_add(target,
                  rm_scale(rm_v3(cp * cosf(c->yaw), cp * sinf(c->yaw), sinf(c->pitch)), c->dist));
}

// The things a camera must not stand in: the truck, outriggers, wheels,
// loads and obstacles (not the crane, the hook or the ground).
static bool is_solid(const world_snap_body* b) {
    switch (b->role) {
    case WORLD_ROLE_TRUCK:
    case WORLD_ROLE_WHEEL:
    case WORLD_ROLE_OUTRIGGER:
    case WORLD_ROLE_LOAD:
    case WORLD_ROLE_OBSTACLE:
    case WORLD_ROLE_OTHER:
        return b->shape != WORLD_SHAPE_TERRAIN;
    default:
        return false;
    }
}

/// Keep the eye out of solid bodies and above the ground: an eye inside a
/// body's drawn box (its mesh bounds or primitive, plus a margin) is lifted
/// above that box's top, along the body's up axis; then at least 0.3 m above
/// the terrain. The eye then sees the scene, not the inside of a truck bed.
static rm_vec3 eye_clear(const world_snapshot* s, render_mesh_cache* mc, rm_vec3 e) {
    const float margin = 0.3f;
    for (int pass = 0; pass < 3; ++pass) {
        bool moved = false;
        for (int i = 0; i < s->nbody && i < WORLD_SNAP_MAX_BODIES; ++i) {
            const world_snap_body* b = &s->body[i];
            double lo[3], hi[3];
            if (!is_solid(b) || !mc || !render_body_local_bounds(mc, b, lo, hi)) continue;
            // The eye in the body frame (rot is body-to-world, row-major).
            const double d[3] = {e.x - b->pos[0], e.y - b->pos[1], e.z - b->pos[2]};
            double q[3];
            for (int k = 0; k < 3; ++k) q[k] = b->rot[k] * d[0] + b->rot[3 + k] * d[1] + b->rot[6 + k] * d[2];
            bool inside = true;
            for (int k = 0; k < 3; ++k) inside = inside && q[k] > lo[k] - margin && q[k] < hi[k] + margin;
            if (!inside) continue;
            const double up = hi[2] + margin - q[2];
            e = rm_add(e, rm_scale(rm_v3((float)b->rot[2], (float)b->rot[5], (float)b->rot[8]), (float)up));
            moved = true;
        }
        if (!moved) break;
    }
    const float g = ground_z(s, e.x, e.y) + 0.3f;
    if (e.z < g) e.z = g;
    return e;
}

void render_camera_update(render_camera* c, const world_snapshot* s, int w, int h, render_mesh_cache* mc,
                          float inset_bottom) {
    const world_snap_body* col = find_role(s, WORLD_ROLE_COLUMN);
    rm_vec3 base = col ? v3d(col->pos) : rm_v3(0, 0, 1.0f);
    rm_vec3 tip = v3d(s->tip);
    rm_vec3 mid = rm_scale(rm_add(base, tip), 0.5f);
    if (rm_len(tip) < 1e-9f) mid = rm_add(base, rm_v3(0, 0, 1.5f));
    // What the operator works with: the column, the tip, and the hook with
    // its load below the tip. The free view centres on all three, so the
    // hook is not at the bottom edge (behind the strip charts).
    rm_vec3 work = mid;
    if (rm_len(tip) >= 1e-9f) work = rm_scale(rm_add(rm_add(base, tip), v3d(s->hook)), 1.0f / 3.0f);

    switch (c->preset) {
    case RENDER_CAM_OPERATOR: {
        // The operator stands on the ground beside the truck, 1 m behind the
        // column and 3.5 m out from the truck's centre line (clear of the
        // outrigger pads), eyes 1.7 m up, watching tip and hook, on the side the
        // boom works on, and at least 5 m from the tip. At 2.1 m out on the right side the view of a boom
        // slewed to the left crossed the bed wall and the cab from point-blank:
        // the picture was the inside of the truck. The side changes only
        // when the tip is 0.5 m past the centre line (no flicker over it).
        const world_snap_body* truck = find_role(s, WORLD_ROLE_TRUCK);
        rm_vec3 fwd = truck ? rm_v3((float)truck->rot[0], (float)truck->rot[3], 0) : rm_v3(1, 0, 0);
        rm_vec3 left =
            truck ? rm_v3((float)truck->rot[1], (float)truck->rot[4], 0) : rm_v3(0, 1, 0);
        fwd = rm_norm(fwd), left = rm_norm(left);
        const float lateral = rm_dot(rm_sub(tip, base), left);
        if (c->op_side == 0) c->op_side = lateral > 0 ? 1 : -1;
        if (lateral > 0.5f) c->op_side = 1;
        if (lateral < -0.5f) c->op_side = -1;
        rm_vec3 e = rm_add(base, rm_add(rm_scale(fwd, -1.0f), rm_scale(left, 3.5f * (float)c->op_side)));
        // Not under the tip: at least 5 m from it across the ground, so the
        // tip and the hook are seen at a working angle, not straight up.
        rm_vec3 away = rm_v3(e.x - tip.x, e.y - tip.y, 0);
        const float r = rm_len(away);
        if (r < 5.0f) {
            away = r > 1e-3f ? rm_scale(away, 1.0f / r) : rm_scale(left, (float)c->op_side);
            e = rm_add(rm_v3(tip.x, tip.y, 0), rm_scale(away, 5.0f));
        }
        c->eye = rm_v3(e.x, e.y, ground_z(s, e.x, e.y) + 1.7f);
        // Between the tip and the hook: both in the picture.
        c->at = rm_scale(rm_add(tip, v3d(s->hook)), 0.5f);
        break;
    }
    case RENDER_CAM_SIDE: {
        // Perpendicular to the boom plane: the plane through the column and
        // the tip (so it follows slew and truck heading alike).
        rm_vec3 d = rm_v3(tip.x - base.x, tip.y - base.y, 0);
        if (rm_len(d) < 0.3f) d = rm_v3(cosf((float)s->slew), sinf((float)s->slew), 0);
        d = rm_norm(d);
        rm_vec3 n = rm_v3(-d.y, d.x, 0);
        c->at = mid;
        c->eye = rm_add(mid, rm_add(rm_scale(n, -14.0f), rm_v3(0, 0, 0.8f)));
        break;
    }
    case RENDER_CAM_FOLLOW_HOOK:
        c->at = v3d(s->hook);
        c->eye = orbit_eye(c, c->at);
        break;
    case RENDER_CAM_ORBIT:
    default:
        if (!c->target_set) c->target = work;
        c->at = c->target;
        c->eye = orbit_eye(c, c->at);
        break;
    }
    c->eye = eye_clear(s, mc, c->eye);
    float aspect = h > 0 ? (float)w / (float)h : 1.0f;
    rm_look_at(c->view, c->eye, c->at, rm_v3(0, 0, 1));
    rm_perspective(c->proj, c->fovy, aspect, 0.1f, 600.0f);
    // Lens shift: the view's centre is the centre of the picture above the
    // strip charts, not of the whole window, so what the camera looks at is
    // not drawn behind them. NDC y moves up by inset / h (half the band).
    if (h > 0 && inset_bottom > 0) c->proj[9] = -inset_bottom / (float)h;
    rm_mul(c->viewproj, c->proj, c->view);
}

/// Leave a fixed preset for the free orbit, starting from the current view
/// so the picture does not jump.
static void to_orbit(render_camera* c) {
    if (c->preset == RENDER_CAM_ORBIT || c->preset == RENDER_CAM_FOLLOW_HOOK) return;
    rm_vec3 d = rm_sub(c->eye, c->at);
    c->dist = rm_len(d);
    if (c->dist < 0.5f) c->dist = 0.5f;
    c->pitch = asinf(d.z / c->dist);
    c->yaw = atan2f(d.y, d.x);
    c->target = c->at;
    c->target_set = true;
    c->preset = RENDER_CAM_ORBIT;
}

bool render_camera_event(render_camera* c, const SDL_Event* ev) {
    switch (ev->type) {
    case SDL_MOUSEBUTTONDOWN:
        if (ev->button.button == SDL_BUTTON_LEFT)
            c->dragging_orbit = true;
        else if (ev->button.button == SDL_BUTTON_RIGHT || ev->button.button == SDL_BUTTON_MIDDLE)
            c->dragging_pan = true;
        else
            return false;
        to_orbit(c);
        return true;
    case SDL_MOUSEBUTTONUP:
        if (ev->button.button == SDL_BUTTON_LEFT)
            c->dragging_orbit = false;
        else
            c->dragging_pan = false;
        return true;
    case SDL_MOUSEMOTION:
        if (c->dragging_orbit) {
            c->yaw -= 0.006f * (float)ev->motion.xrel;
            c->pitch += 0.006f * (float)ev->motion.yrel;
            // Stay above the ground plane and short of the zenith.
            if (c->pitch < -0.15f) c->pitch = -0.15f;
            if (c->pitch > 1.52f) c->pitch = 1.52f;
            return true;
        }
        if (c->dragging_pan && c->preset == RENDER_CAM_ORBIT) {
            // Move the target in the view plane, scaled so the ground under
            // the cursor roughly follows it.
            float k = c->dist * 0.0015f;
            rm_vec3 right = rm_v3(c->view[0], c->view[4], c->view[8]);
            rm_vec3 up = rm_v3(c->view[1], c->view[5], c->view[9]);
            c->target = rm_add(c->target, rm_add(rm_scale(right, -k * (float)ev->motion.xrel),
                                                 rm_scale(up, k * (float)ev->motion.yrel)));
            c->target_set = true;
            return true;
        }
        return false;
    case SDL_MOUSEWHEEL: {
        to_orbit(c);
        // RENDER_ZOOM_PER_NOTCH per wheel notch, by the precise amount (a
        // touchpad sends fractions of a notch; the integer field rounded
        // each to a whole 12 % step), at most 3 notches per event. It was
        // 12 % per notch: 6 notches halved the distance.
        float y = ev->wheel.preciseY != 0.0f ? ev->wheel.preciseY : (float)ev->wheel.y;
        if (ev->wheel.direction == SDL_MOUSEWHEEL_FLIPPED) y = -y;
        if (y > 3.0f) y = 3.0f;
        if (y < -3.0f) y = -3.0f;
        c->dist *= powf(RENDER_ZOOM_PER_NOTCH, y);
        if (c->dist < 2.0f) c->dist = 2.0f;
        if (c->dist > 200.0f) c->dist = 200.0f;
        return true;
    }
    default:
        return false;
    }
}
