// ode_sandbox.c: the sandbox world: terrain heightfield, truck on outriggers,
// slewing column, rope and hook, loads, obstacles, contacts, attach/release.
#include "ode_world_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const float RGBA_TRUCK[4] = {0.95f, 0.95f, 0.92f, 1};
static const float RGBA_CAB[4] = {0.2f, 0.35f, 0.6f, 1};
static const float RGBA_WHEEL[4] = {0.1f, 0.1f, 0.1f, 1};
static const float RGBA_OUTRIGGER[4] = {0.95f, 0.75f, 0.1f, 1};
static const float RGBA_TERRAIN[4] = {0.35f, 0.5f, 0.25f, 1};
static const float RGBA_ROPE[4] = {0.25f, 0.25f, 0.25f, 1};
static const float RGBA_HOOK[4] = {0.95f, 0.8f, 0.1f, 1};
static const float RGBA_LOAD[4] = {0.3f, 0.45f, 0.75f, 1};
static const float RGBA_WALL[4] = {0.6f, 0.6f, 0.6f, 1};
static const float RGBA_BOX[4] = {0.65f, 0.5f, 0.3f, 1};
static const float RGBA_BUILDING[4] = {0.75f, 0.7f, 0.6f, 1};

// Which categories collide (symmetric). Crane parts do not touch the truck
// they stand on or the rope hanging from them; rope links do not touch each
// other (neighbours are jointed anyway).
static uint32_t collide_mask(uint32_t cat) {
    switch (cat) {
    case OW_CAT_TERRAIN: return OW_CAT_TRUCK | OW_CAT_CRANE | OW_CAT_ROPE | OW_CAT_HOOK | OW_CAT_LOAD | OW_CAT_OBST;
    case OW_CAT_TRUCK: return OW_CAT_TERRAIN | OW_CAT_HOOK | OW_CAT_LOAD | OW_CAT_OBST;
    case OW_CAT_CRANE: return OW_CAT_TERRAIN | OW_CAT_HOOK | OW_CAT_LOAD | OW_CAT_OBST;
    case OW_CAT_ROPE: return OW_CAT_TERRAIN | OW_CAT_LOAD | OW_CAT_OBST;
    case OW_CAT_HOOK: return OW_CAT_TERRAIN | OW_CAT_TRUCK | OW_CAT_CRANE | OW_CAT_LOAD | OW_CAT_OBST;
    default: return OW_CAT_TERRAIN | OW_CAT_TRUCK | OW_CAT_CRANE | OW_CAT_ROPE | OW_CAT_HOOK | OW_CAT_LOAD | OW_CAT_OBST;
    }
}

static void set_rot(dBodyID b, const double R[9]) {
    dMatrix3 M;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) M[4 * i + j] = R[3 * i + j];
        M[4 * i + 3] = 0;
    }
    dBodySetRotation(b, M);
}

static void geom_rot(dGeomID g, const double R[9]) {
    dMatrix3 M;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) M[4 * i + j] = R[3 * i + j];
        M[4 * i + 3] = 0;
    }
    dGeomSetRotation(g, M);
}

// ---- terrain ----

static int build_terrain(ode_world* w, char* err, size_t errsz) {
    const world_terrain* t = &w->desc.terrain;
    int nx = t->samples[0], ny = t->samples[1];
    w->tnx = nx;
    w->tny = ny;
    w->tdx = t->size[0] / (nx - 1);
    w->tdy = t->size[1] / (ny - 1);
    w->terrain = malloc((size_t)nx * (size_t)ny * sizeof *w->terrain);
    double* ode_h = malloc((size_t)nx * (size_t)ny * sizeof *ode_h);
    if (!w->terrain || !ode_h) {
        free(ode_h);
        snprintf(err, errsz, "ode world: out of memory (terrain)");
        return -1;
    }
    double hmin = 0, hmax = 0;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            double x = -0.5 * t->size[0] + i * w->tdx, y = -0.5 * t->size[1] + j * w->tdy;
            double h = world_desc_terrain_height(&w->desc, x, y);
            w->terrain[j * nx + i] = (float)h;
            // ODE's heightfield lies in its local x-z plane with y up; we
            // rotate it +90 deg about x (local y -> world z, local z -> world
            // -y), so its rows run towards -y: flip them.
            ode_h[(ny - 1 - j) * nx + i] = h;
            if (h < hmin) hmin = h;
            if (h > hmax) hmax = h;
        }
    w->hfield = dGeomHeightfieldDataCreate();
    dGeomHeightfieldDataBuildDouble(w->hfield, ode_h, 1, t->size[0], t->size[1], nx, ny, 1.0, 0.0, 1.0, 0);
    dGeomHeightfieldDataSetBounds(w->hfield, hmin - 1.0, hmax + 1.0);
    free(ode_h);
    dGeomID g = dCreateHeightfield(w->static_space, w->hfield, 1);
    static const double Rx[9] = {1, 0, 0, 0, 0, -1, 0, 1, 0};
    geom_rot(g, Rx);
    dGeomSetPosition(g, 0, 0, 0);
    ow_add_geom(w, g, OW_CAT_TERRAIN, t->friction);
    double sz[3] = {t->size[0], t->size[1], hmax - hmin};
    ow_add_vis(w, "terrain", WORLD_ROLE_TERRAIN, WORLD_SHAPE_TERRAIN, sz, RGBA_TERRAIN, -1, 0, NULL, NULL);
    return 0;
}

// ---- truck ----

// Attach collision geom g to the truck body at truck-frame position p
// (the body's origin is at the centre of mass, truck_org from the frame's).
static ow_geom* truck_geom(ode_world* w, dGeomID g, const double p[3]) {
    dGeomSetBody(g, w->truck);
    dGeomSetOffsetPosition(g, p[0] + w->truck_org[0], p[1] + w->truck_org[1], p[2] + w->truck_org[2]);
    return ow_add_geom(w, g, OW_CAT_TRUCK, w->desc.truck.friction);
}

// Make geom e (a sphere of radius r at truck-frame p) support i: its
// contacts' forces are measured, at the point under its centre.
static void mark_support(ode_world* w, ow_geom* e, int i, const double p[3], double r) {
    if (!e) return;
    e->support = i;
    w->support_pt[i][0] = p[0] + w->truck_org[0];
    w->support_pt[i][1] = p[1] + w->truck_org[1];
    w->support_pt[i][2] = p[2] - r + w->truck_org[2];
    w->nsupport = OW_NSUPPORT;
}

// Add a box to the truck at truck-frame position p: its drawing, and with
// collide its collision geom.
static void truck_box(ode_world* w, const char* name, world_role role, const float* rgba, int mesh,
                      const double size[3], const double p[3], int collide) {
    if (collide) truck_geom(w, dCreateBox(w->dyn_space, size[0], size[1], size[2]), p);
    const double o[3] = {p[0] + w->truck_org[0], p[1] + w->truck_org[1], p[2] + w->truck_org[2]};
    ow_add_vis(w, name, role, WORLD_SHAPE_BOX, size, rgba, mesh, w->truck, o, NULL);
}

static void build_truck(ode_world* w, const double T[3], const double R[9]) {
    const world_truck* k = &w->desc.truck;
    // COM a little below the bed: chassis, engine and axles are low; the cab
    // and the crane sit higher (the crane is its own bodies).
    double zc = k->bed_height - 0.2;
    dMass m;
    dMassSetBoxTotal(&m, k->mass, k->chassis[0], k->chassis[1], 1.5);
    w->truck = dBodyCreate(w->world);
    dBodySetMass(w->truck, &m);
    double c[3] = {0, 0, zc}, cw[3];
    ow_mat_vec(R, c, cw);
    dBodySetPosition(w->truck, T[0] + cw[0], T[1] + cw[1], T[2] + cw[2]);
    set_rot(w->truck, R);
    w->truck_org[0] = 0, w->truck_org[1] = 0, w->truck_org[2] = -zc;

    double p[3] = {0, 0, k->bed_height - 0.5 * k->chassis[2]};
    truck_box(w, "truck", WORLD_ROLE_TRUCK, RGBA_TRUCK, WORLD_MESH_TRUCK, k->chassis, p, 1);
    double pc[3] = {k->cab_x, 0, k->bed_height - k->chassis[2] + 0.5 * k->cab[2] + 0.15};
    if (w->desc.mesh[WORLD_MESH_TRUCK].file[0]) {
        // The truck mesh has its own cab (drawn on the chassis entry): the
        // cab box only collides, so it is not drawn twice.
        truck_geom(w, dCreateBox(w->dyn_space, k->cab[0], k->cab[1], k->cab[2]), pc);
    } else {
        truck_box(w, "cab", WORLD_ROLE_TRUCK, RGBA_CAB, -1, k->cab, pc, 1);
    }

    // Wheels: spheres for contact (robust on a heightfield), cylinders for
    // drawing. With outriggers out the wheels hang 5 cm clear of the ground.
    double lift = k->outriggers ? 0.05 : 0.0;
    static const double Rw[9] = {1, 0, 0, 0, 0, -1, 0, 1, 0}; // cylinder axis z -> truck y
    for (int a = 0; a < 2; ++a)
        for (int s = 0; s < 2; ++s) {
            const double wt[3] = {k->wheel_x[a], (s ? -0.5 : 0.5) * k->track, k->wheel_radius + lift};
            ow_geom* e = truck_geom(w, dCreateSphere(w->dyn_space, k->wheel_radius), wt);
            // Without outriggers the wheels carry the truck: they are its supports.
            if (!k->outriggers) mark_support(w, e, 2 * a + s, wt, k->wheel_radius);
            double wp[3] = {wt[0] + w->truck_org[0], wt[1] + w->truck_org[1], wt[2] + w->truck_org[2]};
            char nm[32];
            snprintf(nm, sizeof nm, "wheel_%d", 2 * a + s);
            double sz[3] = {k->wheel_radius, k->wheel_width, 0};
            ow_add_vis(w, nm, WORLD_ROLE_WHEEL, WORLD_SHAPE_CYLINDER, sz, RGBA_WHEEL, WORLD_MESH_WHEEL, w->truck, wp, Rw);
        }
    if (!k->outriggers) return;
    for (int a = 0; a < 2; ++a)
        for (int s = 0; s < 2; ++s) {
            double y = (s ? -0.5 : 0.5) * k->outrigger_span;
            char nm[32];
            snprintf(nm, sizeof nm, "outrigger_pad_%d", 2 * a + s);
            double pp[3] = {k->outrigger_x[a], y, 0.5 * k->pad[2]};
            truck_box(w, nm, WORLD_ROLE_OUTRIGGER, RGBA_OUTRIGGER, WORLD_MESH_OUTRIGGER, k->pad, pp, 0);
            // The pad touches the ground through one sphere under its centre:
            // four point contacts carry the truck as well as four boxes would
            // (the support polygon is the same), with a quarter of the contact
            // rows in the truck's island, which dominates the step cost.
            const double rs = 0.5 * k->pad[0], sp[3] = {pp[0], pp[1], rs};
            mark_support(w, truck_geom(w, dCreateSphere(w->dyn_space, rs), sp), 2 * a + s, sp, rs);
            // Beam and leg, drawn only: the pad carries the contact.
            double half = 0.5 * k->outrigger_span - 0.5 * k->chassis[1];
            double bz = k->bed_height - k->chassis[2] + 0.1;
            double bs[3] = {0.2, half, 0.16}, bp[3] = {k->outrigger_x[a], (s ? -1 : 1) * (0.5 * k->chassis[1] + 0.5 * half), bz};
            snprintf(nm, sizeof nm, "outrigger_beam_%d", 2 * a + s);
            truck_box(w, nm, WORLD_ROLE_OUTRIGGER, RGBA_OUTRIGGER, -1, bs, bp, 0);
            double ls[3] = {0.14, 0.14, bz - k->pad[2]}, lp[3] = {k->outrigger_x[a], y, k->pad[2] + 0.5 * ls[2]};
            snprintf(nm, sizeof nm, "outrigger_leg_%d", 2 * a + s);
            truck_box(w, nm, WORLD_ROLE_OUTRIGGER, RGBA_OUTRIGGER, -1, ls, lp, 0);
        }
}

// ---- rope and hook ----

static void build_rope(ode_world* w) {
    const world_rope* r = &w->desc.rope;
    const world_hook* hk = &w->desc.hook;
    double tip[3];
    ow_tip(w, tip, NULL);
    static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    int n = r->links;
    double l = r->length / n, ml = r->mass_per_m * l;
    w->nrope = n;
    w->rope_len = l;
    w->rope_mass = ml;
    // A taut chain of links zig-zags about its line with omega^2 <= T l / I
    // (T tension [N], l link length [m], I the link's inertia about a
    // transverse axis [kg m^2]; every transverse mode, the kinetic energy
    // taken from the links' rotation alone). ODE treats that tension
    // stiffness explicitly, stable for omega H < 2 at the ODE step H. With a
    // capsule's own I = m l^2 / 12 (1.35e-3 kg m^2 for the sandbox's 0.18 kg
    // links) that limit is T = 4 I / (l H^2) = 18 kN at 1 ms: a hook caught
    // under the truck's chassis, pulled by the lift, came apart at 20-25 kN
    // (the links flying at up to 100 m/s, the rope stretched to 1.9 m) and
    // its jolts drove a chamber below absolute zero. So the transverse
    // inertia is raised to OW_ROPE_DESIGN_TENSION l H^2: omega H <= 1 at that
    // tension, stable up to four times it. The axial inertia and the mass
    // stay the link's; the hook's swing changes by less than 0.1 % (the
    // links' rotation holds 0.12 of the chain's 73 kg m^2 about the tip).
    dMass m0;
    dMassSetCapsuleTotal(&m0, ml, 3, r->radius, l);
    const double H = w->opt.dt_ode, I_min = OW_ROPE_DESIGN_TENSION * l * H * H;
    w->rope_inertia = m0.I[0] > I_min ? m0.I[0] : I_min;
    dBodyID prev = w->frame[2].body;
    for (int i = 0; i < n; ++i) {
        dMass m = m0;
        m.I[0] = m.I[5] = w->rope_inertia; // about the link's x and y; z is its axis
        dBodyID b = dBodyCreate(w->world);
        dBodySetMass(b, &m);
        dBodySetPosition(b, tip[0], tip[1], tip[2] - (i + 0.5) * l);
        set_rot(b, I);
        // A capsule a little shorter than the link so neighbours do not overlap.
        double cl = l - 2.0 * r->radius > 0.01 ? l - 2.0 * r->radius : 0.01;
        dGeomID g = dCreateCapsule(w->dyn_space, r->radius, cl);
        dGeomSetBody(g, b);
        ow_add_geom(w, g, OW_CAT_ROPE, 0.3);
        char nm[32];
        snprintf(nm, sizeof nm, "rope_%d", i);
        double sz[3] = {r->radius, cl, 0};
        ow_add_vis(w, nm, WORLD_ROLE_OTHER, WORLD_SHAPE_CAPSULE, sz, RGBA_ROPE, -1, b, NULL, NULL);
        dJointID j = dJointCreateBall(w->world, 0);
        dJointAttach(j, b, prev);
        dJointSetBallAnchor(j, tip[0], tip[1], tip[2] - i * l);
        w->rope[i] = b;
        prev = b;
    }
    dMass m;
    dMassSetBoxTotal(&m, hk->mass, hk->size[0], hk->size[1], hk->size[2]);
    w->hook = dBodyCreate(w->world);
    dBodySetMass(w->hook, &m);
    dBodySetPosition(w->hook, tip[0], tip[1], tip[2] - r->length - 0.5 * hk->size[2]);
    set_rot(w->hook, I);
    dGeomID g = dCreateBox(w->dyn_space, hk->size[0], hk->size[1], hk->size[2]);
    dGeomSetBody(g, w->hook);
    ow_add_geom(w, g, OW_CAT_HOOK, 0.4);
    ow_add_vis(w, "hook", WORLD_ROLE_HOOK, WORLD_SHAPE_BOX, hk->size, RGBA_HOOK, WORLD_MESH_HOOK, w->hook, NULL, NULL);
    dJointID j = dJointCreateBall(w->world, 0);
    dJointAttach(j, w->hook, prev);
    dJointSetBallAnchor(j, tip[0], tip[1], tip[2] - r->length);
    // The load joint exists from the start and is only re-attached, so
    // picking up and putting down never allocates.
    w->hook_joint = dJointCreateBall(w->world, 0);
    dJointAttach(w->hook_joint, 0, 0);
    dJointDisable(w->hook_joint);
}

void ow_hook_point(const ode_world* w, double p[3], double v[3]) {
    double z = -0.5 * w->desc.hook.size[2];
    dVector3 a;
    dBodyGetRelPointPos(w->hook, 0, 0, z, a);
    p[0] = a[0], p[1] = a[1], p[2] = a[2];
    if (v) {
        dBodyGetRelPointVel(w->hook, 0, 0, z, a);
        v[0] = a[0], v[1] = a[1], v[2] = a[2];
    }
}

// Distance [m] from the hook's attach point hp to the top centre of load i.
static double load_top_dist(const ode_world* w, int i, const double hp[3]) {
    dVector3 top;
    dBodyGetRelPointPos(w->load[i], 0, 0, 0.5 * w->desc.load[i].size[2], top);
    return sqrt((top[0] - hp[0]) * (top[0] - hp[0]) + (top[1] - hp[1]) * (top[1] - hp[1]) +
                (top[2] - hp[2]) * (top[2] - hp[2]));
}

int ode_world_nearest_load(const ode_world* w, double* dist, double* reach) {
    if (reach) *reach = w->desc.hook.reach;
    *dist = INFINITY;
    if (w->dead || w->kind != WORLD_SANDBOX || w->nload == 0) return -1;
    double hp[3];
    ow_hook_point(w, hp, NULL);
    int best = -1;
    for (int i = 0; i < w->nload; ++i) {
        const double d = load_top_dist(w, i, hp);
        if (d < *dist) *dist = d, best = i;
    }
    return best;
}

// Deepest overlap [m] of the hook with load i now (0: they do not touch).
static double hook_load_overlap(const ode_world* w, int i) {
    dContactGeom c[8];
    double depth = 0;
    for (int a = 0; a < w->ngeom; ++a) {
        if (w->geom[a].cat != OW_CAT_HOOK) continue;
        for (int b = 0; b < w->ngeom; ++b) {
            if (w->geom[b].cat != OW_CAT_LOAD || dGeomGetBody(w->geom[b].g) != w->load[i]) continue;
            const int n = dCollide(w->geom[a].g, w->geom[b].g, 8, c, sizeof c[0]);
            for (int k = 0; k < n; ++k) depth = fmax(depth, c[k].depth);
        }
    }
    return depth;
}

int ow_attach(ode_world* w, int attach) {
    if (!attach) {
        if (w->attached >= 0) {
            // The hook and its load are joined, so they do not collide
            // (near_cb): when the rope is slack, as on a load set down, the
            // hook leans over about the joint at its bottom and into the load
            // (5 cm in the pick-and-place). Let go, their contacts would push
            // that overlap apart at erp depth / H (10 m/s at 1 ms): that threw
            // the hook 1.1 m up, over the tip, and shook the booms. So until
            // the overlap is gone the contacts only keep it from growing
            // (near_cb measures their depth from release_allow): the hook
            // comes out as the rope lifts it, with no energy handed to it.
            const double d = hook_load_overlap(w, w->attached);
            if (d > w->desc.ode.surface_layer) {
                w->released = w->attached;
                w->release_allow = d;
            }
            dJointAttach(w->hook_joint, 0, 0);
            dJointDisable(w->hook_joint);
            w->attached = -1;
        }
        return -1;
    }
    if (w->attached >= 0) return w->attached;
    double hp[3];
    ow_hook_point(w, hp, NULL);
    int best = -1;
    double bd = w->desc.hook.reach;
    for (int i = 0; i < w->nload; ++i) {
        dVector3 top;
        dBodyGetRelPointPos(w->load[i], 0, 0, w->load_top[i], top);
        double d = sqrt((top[0] - hp[0]) * (top[0] - hp[0]) + (top[1] - hp[1]) * (top[1] - hp[1]) +
                        (top[2] - hp[2]) * (top[2] - hp[2]));
        if (d <= bd) {
            bd = d;
            best = i;
        }
    }
    if (best < 0) return -1;
    // One anchor at the hook point for both bodies: the load hangs from where
    // the hook touched it, like a short rigid sling, with no initial joint
    // error for ERP to snap shut.
    dJointEnable(w->hook_joint);
    dJointAttach(w->hook_joint, w->hook, w->load[best]);
    dJointSetBallAnchor(w->hook_joint, hp[0], hp[1], hp[2]);
    w->attached = best;
    w->released = -1; // joined again: no contacts between them at all
    return best;
}

// ---- loads and obstacles ----

// Loose bodies (loads, movable boxes) sleep when at rest: a resting box costs
// nothing in the solver and its ground contacts are not even computed
// (near_cb). Anything enabled that touches it wakes it (ODE enables disabled
// bodies joined to enabled ones). The crane, truck, rope and hook never sleep.
static void allow_sleep(dBodyID b) {
    dBodySetAutoDisableFlag(b, 1);
    dBodySetAutoDisableLinearThreshold(b, 0.01);
    dBodySetAutoDisableAngularThreshold(b, 0.01);
    dBodySetAutoDisableSteps(b, 20);
    dBodySetAutoDisableTime(b, 0);
}

// The drawing of a meshed object: its bounding box as the fallback primitive
// (centred on the bounds), the visual mesh placed so that its origin is the
// object origin. org is the object origin in the body (or world) frame; the
// collision geom uses the same transform, so what is drawn is what is hit.
static void mesh_vis(ode_world* w, const char* name, world_role role, const float* rgba, const world_obj_mesh* om,
                     dBodyID body, const double org[3], const double* R) {
    double c[3], sz[3], p[3];
    for (int k = 0; k < 3; ++k) c[k] = 0.5 * (om->lo[k] + om->hi[k]), sz[k] = om->hi[k] - om->lo[k];
    if (body) {
        for (int k = 0; k < 3; ++k) p[k] = org[k] + c[k]; // body frame = object axes
    } else {
        double rc[3];
        ow_mat_vec(R, c, rc);
        for (int k = 0; k < 3; ++k) p[k] = org[k] + rc[k];
    }
    ow_vis* v = ow_add_vis(w, name, role, WORLD_SHAPE_BOX, sz, rgba, OW_VIS_OWN_MESH, body, p, body ? NULL : R);
    if (!v) return;
    snprintf(v->mesh_file, sizeof v->mesh_file, "%s", om->file);
    v->mesh_scale = om->scale;
    v->mesh_up = om->up;
    for (int k = 0; k < 3; ++k) v->mesh_offset[k] = -c[k]; // object origin in the primitive frame
}

// A loose meshed body (load or movable obstacle): convex hull of its
// collision mesh, the closed mesh's mass properties, origin at the centre of
// mass. Returns the body, or 0 with err.
static dBodyID mesh_body(ode_world* w, const char* name, world_role role, const float* rgba, uint32_t cat,
                         const world_obj_mesh* om, double mass, const double pos[3], double yaw, double friction,
                         char* err, size_t errsz) {
    dMass m;
    dGeomID g = ow_mesh_hull(w, w->dyn_space, om, mass, &m, err, errsz);
    if (!g) return 0;
    double R[9], rc[3];
    ow_rot_z(yaw, R);
    ow_mat_vec(R, om->com, rc);
    dBodyID b = dBodyCreate(w->world);
    dBodySetMass(b, &m);
    dBodySetPosition(b, pos[0] + rc[0], pos[1] + rc[1], pos[2] + rc[2]);
    set_rot(b, R);
    dGeomSetBody(g, b);
    ow_geom* e = ow_add_geom(w, g, cat, friction);
    if (e) e->mesh = w->nmesh - 1;
    ow_geom_name(e, name);
    const double org[3] = {-om->com[0], -om->com[1], -om->com[2]};
    mesh_vis(w, name, role, rgba, om, b, org, NULL);
    allow_sleep(b);
    return b;
}

static int build_loads(ode_world* w, char* err, size_t errsz) {
    w->nload = w->desc.nload;
    for (int i = 0; i < w->nload; ++i) {
        const world_load* L = &w->desc.load[i];
        if (L->mesh.file[0]) {
            dBodyID b = mesh_body(w, L->name, WORLD_ROLE_LOAD, RGBA_LOAD, OW_CAT_LOAD, &L->mesh, L->mass, L->position,
                                  L->yaw, L->friction, err, errsz);
            if (!b) return -1;
            w->load[i] = b;
            w->load_top[i] = L->mesh.hi[2] - L->mesh.com[2];
            continue;
        }
        dMass m;
        dMassSetBoxTotal(&m, L->mass, L->size[0], L->size[1], L->size[2]);
        dBodyID b = dBodyCreate(w->world);
        dBodySetMass(b, &m);
        dBodySetPosition(b, L->position[0], L->position[1], L->position[2]);
        double R[9];
        ow_rot_z(L->yaw, R);
        set_rot(b, R);
        dGeomID g = dCreateBox(w->dyn_space, L->size[0], L->size[1], L->size[2]);
        dGeomSetBody(g, b);
        ow_geom_name(ow_add_geom(w, g, OW_CAT_LOAD, L->friction), L->name);
        ow_add_vis(w, L->name, WORLD_ROLE_LOAD, WORLD_SHAPE_BOX, L->size, RGBA_LOAD, WORLD_MESH_LOAD, b, NULL, NULL);
        allow_sleep(b);
        w->load[i] = b;
        w->load_top[i] = 0.5 * L->size[2];
    }
    return 0;
}

static int build_obstacles(ode_world* w, char* err, size_t errsz) {
    for (int i = 0; i < w->desc.nobstacle; ++i) {
        const world_obstacle* o = &w->desc.obstacle[i];
        static const int mesh[3] = {WORLD_MESH_WALL, WORLD_MESH_BOX, WORLD_MESH_BUILDING};
        const float* col = o->kind == WORLD_OBST_WALL ? RGBA_WALL : o->kind == WORLD_OBST_BOX ? RGBA_BOX : RGBA_BUILDING;
        double R[9];
        ow_rot_z(o->yaw, R);
        if (o->mesh.file[0]) {
            if (o->mass > 0) {
                dBodyID b = mesh_body(w, o->name, WORLD_ROLE_OBSTACLE, col, OW_CAT_OBST, &o->mesh, o->mass,
                                      o->position, o->yaw, o->friction, err, errsz);
                if (!b) return -1;
                w->obst_body[i] = b;
            } else {
                dGeomID g = ow_mesh_trimesh(w, w->static_space, &o->mesh, o->position, R, err, errsz);
                if (!g) return -1;
                ow_geom* e = ow_add_geom(w, g, OW_CAT_OBST, o->friction);
                if (e) e->mesh = w->nmesh - 1;
                ow_geom_name(e, o->name);
                mesh_vis(w, o->name, WORLD_ROLE_OBSTACLE, col, &o->mesh, 0, o->position, R);
            }
        } else if (o->mass > 0) {
            dMass m;
            dMassSetBoxTotal(&m, o->mass, o->size[0], o->size[1], o->size[2]);
            dBodyID b = dBodyCreate(w->world);
            dBodySetMass(b, &m);
            dBodySetPosition(b, o->position[0], o->position[1], o->position[2]);
            set_rot(b, R);
            dGeomID g = dCreateBox(w->dyn_space, o->size[0], o->size[1], o->size[2]);
            dGeomSetBody(g, b);
            ow_geom_name(ow_add_geom(w, g, OW_CAT_OBST, o->friction), o->name);
            ow_add_vis(w, o->name, WORLD_ROLE_OBSTACLE, WORLD_SHAPE_BOX, o->size, col, mesh[o->kind], b, NULL, NULL);
            allow_sleep(b);
            w->obst_body[i] = b;
        } else {
            dGeomID g = dCreateBox(w->static_space, o->size[0], o->size[1], o->size[2]);
            dGeomSetPosition(g, o->position[0], o->position[1], o->position[2]);
            geom_rot(g, R);
            ow_geom_name(ow_add_geom(w, g, OW_CAT_OBST, o->friction), o->name);
            ow_add_vis(w, o->name, WORLD_ROLE_OBSTACLE, WORLD_SHAPE_BOX, o->size, col, mesh[o->kind], 0, o->position, R);
        }
    }
    return 0;
}

// The terrain's own mesh (ramps, platforms) as a static trimesh on the
// heightfield, colliding like the ground.
static int build_terrain_mesh(ode_world* w, char* err, size_t errsz) {
    const world_terrain* t = &w->desc.terrain;
    if (!t->mesh.file[0]) return 0;
    double R[9];
    ow_rot_z(t->mesh_yaw, R);
    dGeomID g = ow_mesh_trimesh(w, w->static_space, &t->mesh, t->mesh_pos, R, err, errsz);
    if (!g) return -1;
    ow_geom* e = ow_add_geom(w, g, OW_CAT_TERRAIN, t->friction);
    if (e) e->mesh = w->nmesh - 1;
    mesh_vis(w, "terrain_mesh", WORLD_ROLE_OTHER, RGBA_TERRAIN, &t->mesh, 0, t->mesh_pos, R);
    return 0;
}

static double settle_rope(ode_world* w);
static int build_two_link(ode_world* w, const double base[3], const double R[9], char* err, size_t errsz);

int ow_build_sandbox(ode_world* w, char* err, size_t errsz) {
    const world_truck* k = &w->desc.truck;
    if (build_terrain(w, err, errsz) || build_terrain_mesh(w, err, errsz)) return -1;
    double T[3] = {k->position[0], k->position[1], 0}, R[9];
    // Stand the truck on the ground under its centre, 0.5 mm up so it settles
    // onto its pads without an initial overlap.
    T[2] = world_desc_terrain_height(&w->desc, T[0], T[1]) + 0.5e-3;
    ow_rot_z(k->yaw, R);
    build_truck(w, T, R);

    double base_t[3] = {k->column_x, 0, k->bed_height}, base[3];
    ow_mat_vec(R, base_t, base);
    for (int i = 0; i < 3; ++i) base[i] += T[i];
    if (w->chain_hm) {
        // The crane from the model's chain, its column foot on the bed.
        if (ow_build_chain_crane(w, base, R, err, errsz)) return -1;
    } else if (build_two_link(w, base, R, err, errsz)) {
        return -1;
    }
    build_rope(w);
    if (build_loads(w, err, errsz) || build_obstacles(w, err, errsz)) return -1;
    const double overlap = settle_rope(w);
    if (overlap > 0) {
        snprintf(err, errsz,
                 "initial pose q1 = %.1f deg, q2 = %.1f deg leaves no room for the rope and hook: they would start "
                 "%.2f m inside the ground, the truck, a boom or an obstacle (raise the boom tip)",
                 w->opt.q0[0] * 180.0 / M_PI, w->opt.q0[1] * 180.0 / M_PI, overlap);
        return -1;
    }
    return 0;
}

// The two-link crane on the truck: the column slewed by slew0 about the
// truck's z axis, its foot at base [m], the slew hinge and its stops.
static int build_two_link(ode_world* w, const double base[3], const double R[9], char* err, size_t errsz) {
    const ow_act* s = &w->act[ODE_SLEW];
    double r = w->desc.slew.pinion_radius, smax = s->stroke > 0 ? 0.5 * s->stroke / r : M_PI;
    if (s->present && fabs(w->opt.slew0) > smax) {
        snprintf(err, errsz, "initial slew %.1f deg is outside the slew cylinder's range +-%.1f deg",
                 w->opt.slew0 * 180.0 / M_PI, smax * 180.0 / M_PI);
        return -1;
    }
    double Rs[9], Rc[9];
    ow_rot_z(w->opt.slew0, Rs);
    ow_mat_mul(R, Rs, Rc);
    double j1[3] = {base[0] + R[2] * w->mech.column_height, base[1] + R[5] * w->mech.column_height,
                    base[2] + R[8] * w->mech.column_height};
    if (ow_build_crane(w, j1, Rc, w->truck, err, errsz)) return -1;
    w->slew_joint = dJointCreateHinge(w->world, 0);
    dJointAttach(w->slew_joint, w->frame[0].body, w->truck);
    dJointSetHingeAnchor(w->slew_joint, base[0], base[1], base[2]);
    dJointSetHingeAxis(w->slew_joint, R[2], R[5], R[8]);
    // ODE's hinge angle is 0 at slew0 and wraps at +-pi; the slew is that
    // angle plus slew0 plus the turns counted by ow_read_actuators.
    w->slew_off = w->opt.slew0;
    w->slew_raw = 0;
    w->slew_turns = 0;
    w->slew_lim[0] = -dInfinity;
    w->slew_lim[1] = dInfinity;
    if (s->present && s->stroke > 0) {
        // The rack's end stops as hinge limits (docs/ode_world.md, "End
        // stops"), on the continuous hinge angle, however long the rack;
        // ow_slew_stops gives ODE the part of them its (-pi, pi] angle can
        // reach. (Given to ODE as they are, the +171.9 deg stop from slew0 =
        // -60 deg was 4.05 rad, which ODE never reaches: at +120 deg the
        // angle wrapped, the rack stroke jumped by -2 pi r = -0.63 m and a
        // phantom 5.9e7 N end-stop force followed.)
        w->slew_lim[0] = -smax - w->opt.slew0;
        w->slew_lim[1] = smax - w->opt.slew0;
        dJointSetHingeParam(w->slew_joint, dParamBounce, 0.0);
    }
    ow_slew_stops(w);
    return 0;
}

// Lay the rope from the tip: links 0..nv-1 straight down, the rest
// horizontally along d, the hook hanging from the last joint. Each link keeps
// its length and its joints' body-local anchors (the bodies move as rigid
// units with the anchors riding along), so it is the same chain.
static void lay_rope(ode_world* w, const double tip[3], int nv, const double d[2]) {
    static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    // Horizontal links: body z (the capsule axis, pointing back to the tip)
    // along -d, x up: columns (up, -d x up, -d).
    const double Rh[9] = {0, -d[1], -d[0], 0, d[0], -d[1], 1, 0, 0};
    const double l = w->rope_len;
    double p[3] = {tip[0], tip[1], tip[2]}; // top joint of link i
    for (int i = 0; i < w->nrope; ++i) {
        double q[3];
        if (i < nv) q[0] = p[0], q[1] = p[1], q[2] = p[2] - l;
        else q[0] = p[0] + d[0] * l, q[1] = p[1] + d[1] * l, q[2] = p[2];
        dBodySetPosition(w->rope[i], 0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2]));
        set_rot(w->rope[i], i < nv ? I : Rh);
        memcpy(p, q, sizeof p);
    }
    dBodySetPosition(w->hook, p[0], p[1], p[2] - 0.5 * w->desc.hook.size[2]);
    set_rot(w->hook, I);
}

// Deepest overlap [m] of a rope link or the hook with anything it collides
// with (collide_mask), as laid now.
static double rope_overlap(const ode_world* w) {
    double depth = 0;
    dContactGeom c[8];
    for (int i = 0; i < w->ngeom; ++i) {
        const ow_geom* a = &w->geom[i];
        if (!(a->cat & (OW_CAT_ROPE | OW_CAT_HOOK))) continue;
        for (int j = 0; j < w->ngeom; ++j) {
            const ow_geom* b = &w->geom[j];
            if (j == i || !(collide_mask(a->cat) & b->cat)) continue;
            const int n = dCollide(a->g, b->g, 8, c, sizeof c[0]);
            for (int k = 0; k < n; ++k)
                if (c[k].depth > depth) depth = c[k].depth;
        }
    }
    return depth;
}

// build_rope hangs the rope straight down from the tip. With the tip low
// (a folded or transport pose), that would start the hook and the lower
// links inside the ground, the truck or a boom, and ODE's contact correction
// would throw the crane about in the first step (the paper's start pose on
// the sandbox blew up this way). So the layouts are tried from "all links
// hanging" towards "all links lying", each with the lying part in four
// directions (away from the column, back, both sides), and the first that
// overlaps nothing by more than 5 mm (contact softness settles that) is
// kept, as a slack rope lies on the ground. With room enough nothing moves.
// Returns 0, or the overlap [m] of the least bad layout: then the start
// pose is refused (even 0.16 m jolted the hydraulics below absolute zero
// within 2 ms).
static double settle_rope(ode_world* w) {
    const int n = w->nrope;
    double tip[3];
    ow_tip(w, tip, NULL);
    if (rope_overlap(w) <= 5e-3) return 0; // hangs free: as built
    const dReal* col = dBodyGetPosition(w->frame[0].body);
    double d0[2] = {tip[0] - col[0], tip[1] - col[1]};
    const double dn = hypot(d0[0], d0[1]);
    if (dn < 1e-6) d0[0] = 1, d0[1] = 0;
    else d0[0] /= dn, d0[1] /= dn;
    const double cand[4][2] = {{d0[0], d0[1]}, {-d0[0], -d0[1]}, {-d0[1], d0[0]}, {d0[1], -d0[0]}};
    double best = INFINITY;
    int best_nv = n, best_c = 0;
    for (int nv = n - 1; nv >= 0; --nv)
        for (int c = 0; c < 4; ++c) {
            lay_rope(w, tip, nv, cand[c]);
            const double o = rope_overlap(w);
            if (o <= 5e-3) return 0;
            if (o < best) best = o, best_nv = nv, best_c = c;
        }
    lay_rope(w, tip, best_nv, cand[best_c]);
    return best;
}

// ---- contacts ----

// A collision (ode_world_collisions): a crane part (column, boom) touching
// the terrain, the truck, an obstacle or a load, or the hook touching the
// truck or an obstacle. Not collisions: the hook on the ground or on a load
// (that is how loads are picked and set down), loads on the ground or on
// each other, the truck on its pads, the rope (it lies on what it lies on).
static int is_collision(const ow_geom* a, const ow_geom* b) {
    const uint32_t other_crane = a->cat == OW_CAT_CRANE ? b->cat : b->cat == OW_CAT_CRANE ? a->cat : 0;
    if (other_crane & (OW_CAT_TERRAIN | OW_CAT_TRUCK | OW_CAT_OBST | OW_CAT_LOAD)) return 1;
    const uint32_t other_hook = a->cat == OW_CAT_HOOK ? b->cat : b->cat == OW_CAT_HOOK ? a->cat : 0;
    return (other_hook & (OW_CAT_TRUCK | OW_CAT_OBST)) != 0;
}

// Record the pair once per step, the crane's geom (or the hook) first.
static void note_pair(ode_world* w, const ow_geom* a, const ow_geom* b) {
    if (!(a->cat & (OW_CAT_CRANE | OW_CAT_HOOK)) || (b->cat == OW_CAT_CRANE && a->cat != OW_CAT_CRANE)) {
        const ow_geom* t = a;
        a = b;
        b = t;
    }
    const int ia = (int)(a - w->geom), ib = (int)(b - w->geom);
    for (int k = 0; k < w->ncoll_pair; ++k)
        if (w->coll_pair[k][0] == ia && w->coll_pair[k][1] == ib) return;
    if (w->ncoll_pair >= OW_MAX_COLL_PAIRS) return;
    w->coll_pair[w->ncoll_pair][0] = ia;
    w->coll_pair[w->ncoll_pair][1] = ib;
    ++w->ncoll_pair;
}

static const char* geom_name(const ow_geom* e) {
    if (e->name[0]) return e->name;
    switch (e->cat) {
    case OW_CAT_TERRAIN: return "terrain";
    case OW_CAT_TRUCK: return "truck";
    case OW_CAT_CRANE: return "crane";
    case OW_CAT_ROPE: return "rope";
    case OW_CAT_HOOK: return "hook";
    case OW_CAT_LOAD: return "load";
    default: return "obstacle";
    }
}

int ode_world_collisions(const ode_world* w, const char* names[][2], int max) {
    if (w->kind != WORLD_SANDBOX) return -1;
    int n = 0;
    for (int k = 0; k < w->ncoll_pair && n < max; ++k, ++n) {
        names[n][0] = geom_name(&w->geom[w->coll_pair[k][0]]);
        names[n][1] = geom_name(&w->geom[w->coll_pair[k][1]]);
    }
    return n;
}

static void near_cb(void* data, dGeomID g1, dGeomID g2) {
    ode_world* w = data;
    const ow_geom* a = dGeomGetData(g1);
    const ow_geom* b = dGeomGetData(g2);
    if (!a || !b || !(collide_mask(a->cat) & b->cat)) return;
    dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
    if (!b1 && !b2) return;
    // Nothing to do between sleeping bodies and the static world.
    if ((!b1 || !dBodyIsEnabled(b1)) && (!b2 || !dBodyIsEnabled(b2))) return;
    if (b1 && b2 && dAreConnectedExcluding(b1, b2, dJointTypeContact)) return;
    // Two frozen (kinematic) bodies cannot push each other.
    if ((!b1 || dBodyIsKinematic(b1)) && (!b2 || dBodyIsKinematic(b2))) return;
    int max = w->desc.ode.max_contacts;
    if (max > (int)(sizeof w->cbuf / sizeof w->cbuf[0])) max = (int)(sizeof w->cbuf / sizeof w->cbuf[0]);
    int n = dCollide(g1, g2, max, w->cbuf, sizeof(dContactGeom));
    if (n <= 0) return;
    if (n > 1 && (dGeomGetClass(g1) == dTriMeshClass || dGeomGetClass(g2) == dTriMeshClass))
        n = ow_mesh_merge_contacts(w->cbuf, n, OW_MESH_MERGE_RADIUS);
    double mu = sqrt(a->friction * b->friction);
    int crane = a->cat == OW_CAT_CRANE || b->cat == OW_CAT_CRANE;
    // The hook and the load it has just let go, still overlapping (ow_attach).
    const int clearing = w->released >= 0 && (a->cat | b->cat) == (OW_CAT_HOOK | OW_CAT_LOAD) &&
                         (b1 == w->load[w->released] || b2 == w->load[w->released]);
    for (int i = 0; i < n; ++i) {
        dContact c;
        memset(&c, 0, sizeof c);
        c.geom = w->cbuf[i];
        // Friction pyramid scaled by the normal force (Approx1), and the
        // world-file softness so contacts are stiff but regular.
        c.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
        c.surface.mu = mu;
        c.surface.soft_erp = w->desc.ode.contact_erp;
        c.surface.soft_cfm = w->desc.ode.contact_cfm;
        if (clearing) {
            // ODE corrects the depth beyond the surface layer; measured from
            // the overlap allowed, a contact holds that and pushes nothing.
            if (c.geom.depth > w->release_depth) w->release_depth = c.geom.depth;
            c.geom.depth -= w->release_allow;
        }
        dJointID j = dJointCreateContact(w->world, w->contacts, &c);
        dJointAttach(j, b1, b2);
        // A contact on a truck support reports its force (ow_support_forces).
        const int sup = a->support >= 0 ? a->support : b->support;
        if (sup >= 0 && w->nsupport_fb < OW_MAX_SUPPORT_FB) {
            const int f = w->nsupport_fb++;
            dJointSetFeedback(j, &w->support_fb[f]);
            w->support_fb_joint[f] = j;
            w->support_fb_of[f] = sup;
        }
        double d = w->cbuf[i].depth;
        if (d > w->max_depth) w->max_depth = d;
        if (crane) {
            if (d > w->max_depth_crane) w->max_depth_crane = d;
            if ((a->cat | b->cat) & (OW_CAT_OBST | OW_CAT_LOAD | OW_CAT_HOOK)) w->crane_contact = 1;
        }
    }
    w->ncontact += n;
    if (is_collision(a, b)) note_pair(w, a, b);
}

void ow_collide(ode_world* w) {
    w->ncontact = 0;
    w->max_depth = 0;
    w->max_depth_crane = 0;
    w->crane_contact = 0;
    w->ncoll_pair = 0;
    w->nsupport_fb = 0;
    w->release_depth = -1;
    dSpaceCollide(w->dyn_space, w, near_cb);
    dSpaceCollide2((dGeomID)w->dyn_space, (dGeomID)w->static_space, w, near_cb);
    if (w->released >= 0) {
        // The allowance follows the overlap down as the hook comes out and
        // ends with it (a contact within the surface layer is corrected by
        // nothing, so ending there pushes nothing either).
        if (w->release_depth <= w->desc.ode.surface_layer) w->released = -1;
        else if (w->release_depth < w->release_allow) w->release_allow = w->release_depth;
    }
}

void ow_support_forces(ode_world* w) {
    double F[OW_NSUPPORT] = {0};
    for (int f = 0; f < w->nsupport_fb; ++f) {
        // ODE reports f1 for the joint's first body and f2 for its second;
        // against the static world the truck is always the first (ODE moves
        // a lone body to the first slot), else it is whichever it is.
        const dJointID j = w->support_fb_joint[f];
        const dBodyID b0 = dJointGetBody(j, 0), b1 = dJointGetBody(j, 1);
        const dJointFeedback* fb = &w->support_fb[f];
        const double fz = (!b0 || !b1 || b0 == w->truck) ? fb->f1[2] : fb->f2[2];
        F[w->support_fb_of[f]] += fz;
    }
    const double a = 1.0 - exp(-w->opt.dt_ode / OW_SUPPORT_TAU);
    for (int i = 0; i < OW_NSUPPORT; ++i) w->support_F[i] += a * (F[i] - w->support_F[i]);
}

int ow_supports_lifted(const ode_world* w, double weight) {
    int bits = 0;
    if (w->t < ODE_SUPPORT_SETTLE_T - 1e-12) return 0;
    for (int i = 0; i < w->nsupport; ++i)
        if (w->support_F[i] < ODE_PAD_LIFT_FRAC * weight) bits |= 1 << i;
    return bits;
}

// Weight [N] and position of body b, into the running moments about the
// tipping line through a with horizontal inward normal n: the part inboard
// restores, the part outboard tips [N m].
static void line_moment(dBodyID b, double g, const double a[3], const double n[2], double* restore, double* tip,
                        double* weight) {
    if (!b) return;
    dMass m;
    dBodyGetMass(b, &m);
    const dReal* p = dBodyGetPosition(b);
    const double s = n[0] * (p[0] - a[0]) + n[1] * (p[1] - a[1]), W = m.mass * g;
    if (s > 0) *restore += W * s;
    else *tip -= W * s;
    *weight += W;
}

double ow_stab_margin(const ode_world* w, double* weight) {
    // The support points in the world, walked round the polygon front-left,
    // front-right, rear-right, rear-left (index 2 a + s).
    static const int ring[OW_NSUPPORT] = {0, 1, 3, 2};
    double P[OW_NSUPPORT][3], c[2] = {0, 0};
    for (int i = 0; i < OW_NSUPPORT; ++i) {
        dVector3 q;
        const double* sp = w->support_pt[ring[i]];
        dBodyGetRelPointPos(w->truck, sp[0], sp[1], sp[2], q);
        P[i][0] = q[0], P[i][1] = q[1], P[i][2] = q[2];
        c[0] += 0.25 * q[0], c[1] += 0.25 * q[1];
    }
    double margin = ODE_STAB_MARGIN_MAX, W = 0;
    dBodyID cb[OW_MAX_GEOMS];
    const int ncb = ow_crane_bodies(w, cb, OW_MAX_GEOMS);
    for (int e = 0; e < OW_NSUPPORT; ++e) {
        const double* a = P[e];
        const double* b = P[(e + 1) % OW_NSUPPORT];
        double n[2] = {-(b[1] - a[1]), b[0] - a[0]};
        const double len = hypot(n[0], n[1]);
        if (len < 1e-9) continue;
        n[0] /= len, n[1] /= len;
        if (n[0] * (c[0] - a[0]) + n[1] * (c[1] - a[1]) < 0) n[0] = -n[0], n[1] = -n[1];
        double R = 0, T = 0;
        W = 0;
        line_moment(w->truck, w->g, a, n, &R, &T, &W);
        for (int f = 0; f < ncb; ++f) line_moment(cb[f], w->g, a, n, &R, &T, &W);
        for (int i = 0; i < w->nrope; ++i) line_moment(w->rope[i], w->g, a, n, &R, &T, &W);
        line_moment(w->hook, w->g, a, n, &R, &T, &W);
        if (w->attached >= 0) line_moment(w->load[w->attached], w->g, a, n, &R, &T, &W);
        if (T > 0 && R < margin * T) margin = R / T;
    }
    if (weight) *weight = W;
    return margin;
}

double ow_truck_tilt(const ode_world* w) {
    const dReal* R = dBodyGetRotation(w->truck);
    double c = R[10]; // z component of the truck's z axis
    if (c > 1) c = 1;
    if (c < -1) c = -1;
    return acos(c);
}

// ---- snapshot extras ----

void ow_sandbox_snapshot(const ode_world* w, world_snapshot* s) {
    s->terrain.height = w->terrain;
    s->terrain.nx = w->tnx;
    s->terrain.ny = w->tny;
    s->terrain.dx = w->tdx;
    s->terrain.dy = w->tdy;
    // Rope polyline: tip pin, each link joint, hook pin.
    int n = 0;
    for (int i = 0; i < w->nrope && n < WORLD_SNAP_MAX_ROPE - 1; ++i) {
        dVector3 p;
        dBodyGetRelPointPos(w->rope[i], 0, 0, 0.5 * w->rope_len, p);
        s->rope[n][0] = p[0], s->rope[n][1] = p[1], s->rope[n][2] = p[2];
        ++n;
    }
    if (w->nrope) {
        dVector3 p;
        dBodyGetRelPointPos(w->rope[w->nrope - 1], 0, 0, -0.5 * w->rope_len, p);
        s->rope[n][0] = p[0], s->rope[n][1] = p[1], s->rope[n][2] = p[2];
        ++n;
    }
    s->nrope = n;
    ow_hook_point(w, s->hook, NULL);
    s->attached = w->attached >= 0;
    s->load_mass = w->attached >= 0 ? w->desc.load[w->attached].mass : 0;
    s->slew = ow_slew_angle(w);
    s->truck_tilt = ow_truck_tilt(w);
    s->tipping = s->truck_tilt > 5.0 * M_PI / 180.0;
    s->collision = (uint8_t)w->crane_contact;
    s->npad = w->nsupport;
    if (w->nsupport) {
        double weight = 0;
        s->stab_margin = ow_stab_margin(w, &weight);
        for (int i = 0; i < w->nsupport; ++i) {
            dVector3 q;
            dBodyGetRelPointPos(w->truck, w->support_pt[i][0], w->support_pt[i][1], w->support_pt[i][2], q);
            s->pad_pos[i][0] = q[0], s->pad_pos[i][1] = q[1], s->pad_pos[i][2] = q[2];
            s->pad_F[i] = w->support_F[i];
        }
        s->pad_lifted = ow_supports_lifted(w, weight);
    }

    // The slew rack drawn as a cylinder lying across the truck at the column
    // foot, its rod end moving with the rack travel.
    const ow_act* c = &w->act[ODE_SLEW];
    if (c->present && s->ncyl < WORLD_SNAP_MAX_CYLINDERS) {
        world_snap_cylinder* y = &s->cyl[s->ncyl++];
        snprintf(y->name, sizeof y->name, "slew");
        const world_truck* k = &w->desc.truck;
        double closed = c->stroke + 0.2;
        double o = w->truck_org[2];
        double pb[3] = {k->column_x - 0.35, -0.5 * (closed + c->stroke), k->bed_height + 0.15 + o};
        double pr[3] = {pb[0], pb[1] + closed + c->x, pb[2]};
        dVector3 a;
        dBodyGetRelPointPos(w->truck, pb[0], pb[1], pb[2], a);
        y->base[0] = a[0], y->base[1] = a[1], y->base[2] = a[2];
        dBodyGetRelPointPos(w->truck, pr[0], pr[1], pr[2], a);
        y->rod_end[0] = a[0], y->rod_end[1] = a[1], y->rod_end[2] = a[2];
        y->closed_length = closed;
        y->stroke_max = c->stroke;
        y->x = c->x;
        y->v = c->v;
        y->force = c->F;
        y->u_cmd = w->u_cmd[ODE_SLEW];
        y->end_stop = (uint8_t)c->at_stop;
        if (w->hm && c->cyl >= 0) {
            y->bore = sqrt(4.0 * c->AA / M_PI);
            y->rod = sqrt(4.0 * (c->AA - c->AB) / M_PI);
            y->pA = w->y[c->iA];
            y->pB = w->y[c->iB];
            y->u = c->iu >= 0 ? w->y[c->iu] : 0;
        }
        if (w->chain) {
            // The chain's rack: its chambers and spool from the chain's circuit.
            const crane_chain* cc = ode_chain_chain(w->chain);
            const double* cy;
            const hyd_data* hd;
            ode_chain_circuit_state(w->chain, &cy, &hd);
            ode_chain_slew_state(w->chain, NULL, NULL, NULL, &y->pA, &y->pB, NULL);
            const int iv = hyd_model_valve(w->chain_hm, cc->slew.valve), iu = hyd_model_valve_state(w->chain_hm, iv);
            y->u = iu >= 0 ? cy[iu] : 0.0;
            y->u_cmd = hd->valve_cmd[iv];
            y->bore = sqrt(4.0 * c->AA / M_PI);
            y->rod = sqrt(4.0 * (c->AA - c->AB) / M_PI);
        }
    }
}

static void set_rigid_vel(dBodyID b, const double tip[3], const double om[3]) {
    const dReal* p = dBodyGetPosition(b);
    double r[3] = {p[0] - tip[0], p[1] - tip[1], p[2] - tip[2]};
    dBodySetLinearVel(b, om[1] * r[2] - om[2] * r[1], om[2] * r[0] - om[0] * r[2], om[0] * r[1] - om[1] * r[0]);
    dBodySetAngularVel(b, om[0], om[1], om[2]);
}

void ode_world_swing_hook(ode_world* w, const double omega[3]) {
    if (w->dead) return;
    if (w->kind != WORLD_SANDBOX) return;
    double tip[3];
    ow_tip(w, tip, NULL);
    for (int i = 0; i < w->nrope; ++i) set_rigid_vel(w->rope[i], tip, omega);
    set_rigid_vel(w->hook, tip, omega);
}

void ode_world_rope_info(const ode_world* w, int* nlink, double* link_len, double* link_mass, double* link_inertia,
                         double* hook_mass, double* hook_com, double* hook_inertia) {
    const world_hook* h = &w->desc.hook;
    *nlink = w->nrope;
    *link_len = w->rope_len;
    *link_mass = w->rope_mass;
    *link_inertia = w->rope_inertia;
    *hook_mass = h->mass;
    *hook_com = 0.5 * h->size[2];
    *hook_inertia = h->mass * (h->size[0] * h->size[0] + h->size[2] * h->size[2]) / 12.0;
}
