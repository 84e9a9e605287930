// demo_scene.c: a synthetic snapshot of the truck crane (truck, outriggers,
// column, two booms, lift and jib cylinders, hook on a rope, loads and
// obstacles), built from a few joint angles with plain forward kinematics.
// The demo program and the tests draw it; no physics is involved.
//
// Geometry follows assets/worlds/sandbox.json and assets/models/hiab031.json
// (as the generated meshes do, assets/meshes/README.md): the slew axis is at
// the world origin, the truck bed at z = 1.1 m, joint 1 is 1.6 m above it.
#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdio.h>
#include <string.h>

#include "render.h"

#define DEG (M_PI / 180.0)

render_demo_params render_demo_default_params(void) {
    render_demo_params p;
    memset(&p, 0, sizeof p);
    p.slew = -128.0 * DEG;
    p.q1_deg = 38.0;
    p.q2_deg = -62.0;
    p.pA[0] = 14.5e6, p.pB[0] = 1.2e6;
    p.pA[1] = 3.0e6, p.pB[1] = 9.5e6;
    p.u[0] = 0.35, p.u[1] = -0.2;
    p.use_meshes = true;
    return p;
}

// Row-major 3x3 helpers (world_snapshot's convention).
static void rot_z(double r[9], double a) {
    double c = cos(a), s = sin(a);
    double m[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
    memcpy(r, m, sizeof m);
}
/// Elevation: turns +x toward +z by angle a (a rotation of -a about y).
static void rot_elev(double r[9], double a) {
    double c = cos(a), s = sin(a);
    double m[9] = {c, 0, -s, 0, 1, 0, s, 0, c};
    memcpy(r, m, sizeof m);
}
static void mat_mul(double o[9], const double a[9], const double b[9]) {
    double t[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            t[i * 3 + j] = a[i * 3] * b[j] + a[i * 3 + 1] * b[3 + j] + a[i * 3 + 2] * b[6 + j];
    memcpy(o, t, sizeof t);
}
/// out = pos + R * local
static void xform(double out[3], const double pos[3], const double r[9], double x, double y,
                  double z) {
    for (int i = 0; i < 3; ++i)
        out[i] = pos[i] + r[i * 3] * x + r[i * 3 + 1] * y + r[i * 3 + 2] * z;
}

static world_snap_body* add(world_snapshot* s, const char* name, world_role role, world_shape shape,
                            double sx, double sy, double sz, const float rgba[4]) {
    if (s->nbody >= WORLD_SNAP_MAX_BODIES) return NULL;
    world_snap_body* b = &s->body[s->nbody++];
    memset(b, 0, sizeof *b);
    snprintf(b->name, sizeof b->name, "%s", name);
    b->role = role;
    b->shape = shape;
    b->size[0] = sx, b->size[1] = sy, b->size[2] = sz;
    memcpy(b->rgba, rgba, sizeof b->rgba);
    b->rot[0] = b->rot[4] = b->rot[8] = 1.0;
    b->mesh_scale = 1.0;
    b->mesh_up = 2;
    return b;
}

static void set_mesh(world_snap_body* b, bool on, const char* file, double ox, double oy,
                     double oz) {
    if (!b || !on) return;
    snprintf(b->mesh, sizeof b->mesh, "%s", file);
    b->mesh_offset[0] = ox, b->mesh_offset[1] = oy, b->mesh_offset[2] = oz;
}

static void set_pose(world_snap_body* b, double x, double y, double z, double yaw) {
    if (!b) return;
    b->pos[0] = x, b->pos[1] = y, b->pos[2] = z;
    rot_z(b->rot, yaw);
}

static void cylinder(world_snap_cylinder* c, const char* name, const double base[3],
                     const double rod_end[3], double bore, double rod, double closed, double stroke,
                     double pA, double pB, double u) {
    memset(c, 0, sizeof *c);
    snprintf(c->name, sizeof c->name, "%s", name);
    memcpy(c->base, base, 3 * sizeof(double));
    memcpy(c->rod_end, rod_end, 3 * sizeof(double));
    double d[3] = {rod_end[0] - base[0], rod_end[1] - base[1], rod_end[2] - base[2]};
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    c->bore = bore, c->rod = rod, c->closed_length = closed, c->stroke_max = stroke;
    c->x = fmin(fmax(len - closed, 0.0), stroke);
    c->pA = pA, c->pB = pB;
    c->u = c->u_cmd = u;
    c->v = 0.05 * u;
    const double aa = M_PI * bore * bore / 4, ab = M_PI * (bore * bore - rod * rod) / 4;
    c->force = pA * aa - pB * ab;
}

void render_demo_scene(world_snapshot* s, const render_demo_params* p, float* terrain_buf) {
    memset(s, 0, sizeof *s);
    const bool m = p->use_meshes;
    static const float truck_rgba[4] = {0.16f, 0.32f, 0.62f, 1};
    static const float crane_rgba[4] = {0.96f, 0.58f, 0.08f, 1};
    static const float dark_rgba[4] = {0.12f, 0.12f, 0.13f, 1};
    static const float hook_rgba[4] = {0.95f, 0.80f, 0.10f, 1};
    static const float concrete_rgba[4] = {0.68f, 0.67f, 0.64f, 1};
    static const float wood_rgba[4] = {0.72f, 0.55f, 0.34f, 1};
    static const float brick_rgba[4] = {0.66f, 0.36f, 0.28f, 1};
    static const float house_rgba[4] = {0.86f, 0.84f, 0.78f, 1};
    static const float crate_rgba[4] = {0.30f, 0.50f, 0.30f, 1};
    s->t = 12.5;
    s->rt_factor = 1.0;
    s->slew = p->slew;
    s->p_supply = 20.2e6;

    if (p->terrain && terrain_buf) {
        // Flat pad under the truck, gentle hills beyond 14 m.
        const int n = RENDER_DEMO_TERRAIN_N;
        const double dx = 1.5;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                double x = (i - 0.5 * (n - 1)) * dx, y = (j - 0.5 * (n - 1)) * dx;
                double r = sqrt(x * x + y * y), k = r < 14 ? 0 : fmin((r - 14) / 10, 1.0);
                terrain_buf[j * n + i] = (float)(k * (0.9 * sin(x / 6.0) * cos(y / 8.0) + 0.6));
            }
        s->terrain.height = terrain_buf;
        s->terrain.nx = s->terrain.ny = n;
        s->terrain.dx = s->terrain.dy = dx;
    }

    // Truck, as the sandbox world builds it (assets/worlds/sandbox.json
    // "truck"; the meshes are generated from the same numbers): the truck
    // frame's origin is on the ground, column_x behind the slew axis.
    const double col_x = 0.9, bed = 1.1, chassis_h = 0.5;
    const double tx = -col_x;
    world_snap_body* b =
        add(s, "truck", WORLD_ROLE_TRUCK, WORLD_SHAPE_BOX, 6.4, 2.3, chassis_h, truck_rgba);
    // Body origin at the chassis box centre; the mesh origin is on the ground.
    set_pose(b, tx, 0, bed - 0.5 * chassis_h, 0);
    set_mesh(b, m, "truck.obj", 0, 0, -(bed - 0.5 * chassis_h));
    const double wheel_x[2] = {2.1, -1.6}, wheel_r = 0.45, wheel_z = 0.5, track = 1.9;
    for (int i = 0; i < 4; ++i) {
        char nm[16];
        snprintf(nm, sizeof nm, "wheel_%d", i);
        double y = (i & 1) ? -0.5 * track : 0.5 * track;
        b = add(s, nm, WORLD_ROLE_WHEEL, WORLD_SHAPE_CYLINDER, wheel_r, 0.3, 0, dark_rgba);
        if (!b) break;
        b->pos[0] = tx + wheel_x[i / 2], b->pos[1] = y, b->pos[2] = wheel_z;
        // Cylinder axis (body z) along world y; the wheel mesh has its axle on y already.
        double r[9] = {1, 0, 0, 0, 0, -1, 0, 1, 0};
        memcpy(b->rot, r, sizeof r);
        if (m) {
            set_mesh(b, m, "wheel.obj", 0, 0, 0);
            // The mesh is modelled axle-along-y: undo the primitive's rotation.
            rot_z(b->rot, y < 0 ? M_PI : 0.0);
        }
    }
    // Outriggers: beam from the chassis side (y 1.15) to the jack at half the
    // 4 m span, at the beam height 0.7 m; the mesh origin is on the centreline.
    const double outrigger_x[2] = {1.0, -2.9};
    for (int i = 0; i < 4; ++i) {
        char nm[16];
        snprintf(nm, sizeof nm, "outrigger_%d", i);
        b = add(s, nm, WORLD_ROLE_OUTRIGGER, WORLD_SHAPE_BOX, 0.2, 1.0, 0.2, crane_rgba);
        double sg = (i & 1) ? -1.0 : 1.0;
        set_pose(b, tx + outrigger_x[i / 2], sg * 1.65, 0.7, (i & 1) ? M_PI : 0);
        set_mesh(b, m, "outrigger.obj", 0, -1.65, 0);
    }

    // Crane (assets/models/hiab031.json mechanics): the column slews about
    // the world z axis at the origin; joint 1 is on the slew axis, 1.6 m
    // above the bed.
    const double H = 1.6;
    double rc[9], r1[9], r2[9], e[9];
    rot_z(rc, p->slew);
    b = add(s, "column", WORLD_ROLE_COLUMN, WORLD_SHAPE_CYLINDER, 0.16, H, 0, crane_rgba);
    double col_pos[3] = {0, 0, bed};
    if (b) {
        memcpy(b->pos, col_pos, sizeof col_pos);
        memcpy(b->rot, rc, sizeof rc);
        // Primitive cylinder is centred; the mesh origin is at the column foot.
        b->pos[2] = bed + 0.5 * H;
        set_mesh(b, m, "column.obj", 0, 0, -0.5 * H);
    }
    double j1[3];
    xform(j1, col_pos, rc, 0, 0, H);
    rot_elev(e, p->q1_deg * DEG);
    mat_mul(r1, rc, e);
    const double L1 = 2.3, L2 = 2.5;
    b = add(s, "boom1", WORLD_ROLE_BOOM1, WORLD_SHAPE_BOX, L1, 0.18, 0.24, crane_rgba);
    if (b) {
        xform(b->pos, j1, r1, 0.5 * L1, 0, 0);
        memcpy(b->rot, r1, sizeof r1);
        set_mesh(b, m, "boom1.obj", -0.5 * L1, 0, 0);
    }
    double j2[3];
    xform(j2, j1, r1, L1, 0, 0);
    rot_elev(e, p->q2_deg * DEG);
    mat_mul(r2, r1, e);
    b = add(s, "boom2", WORLD_ROLE_BOOM2, WORLD_SHAPE_BOX, L2, 0.15, 0.2, crane_rgba);
    if (b) {
        xform(b->pos, j2, r2, 0.5 * L2, 0, 0);
        memcpy(b->rot, r2, sizeof r2);
        set_mesh(b, m, "boom2.obj", -0.5 * L2, 0, 0);
    }
    xform(s->tip, j2, r2, L2, 0, 0);

    // Cylinders between the model's mounts: lift from the column (relative to
    // joint 1) to under the lifting arm; jib from the lifting arm (relative to
    // joint 2) to the end arm.
    double a0[3], a1[3];
    xform(a0, j1, rc, 0.2113, 0, -0.4532);
    xform(a1, j1, r1, 1.5541, 0, -0.1360);
    cylinder(&s->cyl[0], "lift", a0, a1, 0.100, 0.060, 1.2201, 0.70, p->pA[0], p->pB[0], p->u[0]);
    xform(a0, j2, r1, -1.1954, 0, 0.1046);
    xform(a1, j2, r2, 0.3864, 0, -0.1035);
    cylinder(&s->cyl[1], "jib", a0, a1, 0.080, 0.045, 0.902, 0.60, p->pA[1], p->pB[1], p->u[1]);
    s->ncyl = 2;

    // Rope and hook: hanging 1.7 m under the tip, swung slightly.
    s->nrope = 8;
    for (int i = 0; i < s->nrope; ++i) {
        double f = (double)i / (s->nrope - 1);
        s->rope[i][0] = s->tip[0] + 0.12 * f;
        s->rope[i][1] = s->tip[1] + 0.05 * f;
        s->rope[i][2] = s->tip[2] - 0.15 - 1.55 * f;
    }
    memcpy(s->hook, s->rope[s->nrope - 1], sizeof s->hook);
    b = add(s, "hook", WORLD_ROLE_HOOK, WORLD_SHAPE_SPHERE, 0.12, 0, 0, hook_rgba);
    if (b) {
        memcpy(b->pos, s->hook, sizeof s->hook);
        rot_z(b->rot, p->slew);
        set_mesh(b, m, "hook.obj", 0, 0, 0);
    }
    s->load_mass = 0;

    // Loads on the ground around the work area (reach ~4 m at slew).
    const double cs = cos(p->slew), sn = sin(p->slew);
    for (int i = 0; i < 3; ++i) {
        char nm[16];
        snprintf(nm, sizeof nm, "block_%d", i);
        b = add(s, nm, WORLD_ROLE_LOAD, WORLD_SHAPE_BOX, 1.2, 0.6, 0.6, concrete_rgba);
        double rr = 5.4 + 0.2 * i, a = p->slew + (i - 1) * 0.32;
        set_pose(b, rr * cos(a), rr * sin(a), 0.3, a + 0.1 * i);
        set_mesh(b, m, "load_block.obj", 0, 0, 0);
    }
    for (int i = 0; i < 2; ++i) {
        char nm[16];
        snprintf(nm, sizeof nm, "pallet_%d", i);
        b = add(s, nm, WORLD_ROLE_LOAD, WORLD_SHAPE_BOX, 1.2, 0.8, 0.144, wood_rgba);
        double x = 3.6 * cs - (2.2 + 1.4 * i) * sn, y = 3.6 * sn + (2.2 + 1.4 * i) * cs;
        set_pose(b, x, y, 0.072, p->slew);
        set_mesh(b, m, "pallet.obj", 0, 0, 0);
        snprintf(nm, sizeof nm, "cargo_%d", i);
        b = add(s, nm, WORLD_ROLE_LOAD, WORLD_SHAPE_BOX, 1.1, 0.75, 0.7, crate_rgba);
        set_pose(b, x, y, 0.144 + 0.35, p->slew);
        set_mesh(b, m, "crate.obj", 0, 0, 0);
    }
    // Obstacles: a wall, a building, a stack of crates.
    b = add(s, "wall", WORLD_ROLE_OBSTACLE, WORLD_SHAPE_BOX, 6.0, 0.3, 2.0, brick_rgba);
    set_pose(b, -3.0, -7.8, 1.0, 0.05);
    set_mesh(b, m, "wall.obj", 0, 0, 0);
    b = add(s, "building", WORLD_ROLE_OBSTACLE, WORLD_SHAPE_BOX, 8.0, 6.0, 5.0, house_rgba);
    set_pose(b, -9.0, 9.5, 2.5, 0);
    set_mesh(b, m, "building.obj", 0, 0, 0);
    for (int i = 0; i < 4; ++i) {
        char nm[16];
        snprintf(nm, sizeof nm, "stack_%d", i);
        b = add(s, nm, WORLD_ROLE_OBSTACLE, WORLD_SHAPE_BOX, 1.1, 0.75, 0.7, crate_rgba);
        set_pose(b, 5.0 + (i % 2) * 1.2, -6.0, 0.35 + (i / 2) * 0.7, 0.02 * i);
        set_mesh(b, m, "crate.obj", 0, 0, 0);
    }
}
