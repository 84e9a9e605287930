// ode_world.c: ODE world lifecycle, the crane (column, lifting arm, end arm,
// hinges, cylinder mounts), the step loop, state and snapshot.
#include "ode_world_internal.h"
#include "model.h"
#include "snap_reliefs.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// Run fn(w, arg) with ODE's errors caught (ow_ode_call). Returns fn's
// result, or OW_ODE_FAILED after an ODE error; then w is dead (w->err says
// why) and only ode_world_destroy may touch it. Nothing in fn may rely on
// running to its end (the jump skips the rest of fn and of ODE's own
// frames): fn only steps or reads the world, which is then discarded whole.
typedef int (*ow_fn)(ode_world* w, void* arg);
typedef struct trap_args {
    ode_world* w;
    ow_fn fn;
    void* arg;
} trap_args;
static int trap_call(void* p) {
    trap_args* t = p;
    return t->fn(t->w, t->arg);
}
static int ow_trapped(ode_world* w, const char* what, ow_fn fn, void* arg) {
    trap_args t = {w, fn, arg};
    char fatal[200];
    const int rc = ow_ode_call(trap_call, &t, fatal, sizeof fatal);
    if (rc != OW_ODE_FAILED) return rc;
    w->dead = 1;
    w->failed = 1;
    if (w->chain) ode_chain_host_failed(w->chain); // its bodies are this world's
    if (w->world_built)
        snprintf(w->err, sizeof w->err,
                 "ode world: ODE failed %s at t = %.6f s (%.150s): a mass, size or position far outside the "
                 "physical range; the world was stopped",
                 what, w->t, fatal);
    else
        snprintf(w->err, sizeof w->err,
                 "ode world: ODE failed %s (%.150s): a mass, size or position far outside the physical range",
                 what, fatal);
    return OW_ODE_FAILED;
}

long ode_world_messages(const char** last) { return ow_ode_messages(last); }

ode_world_opts ode_world_default_opts(void) {
    ode_world_opts o;
    memset(&o, 0, sizeof o);
    o.dt_ode = 1e-3;
    o.dt_hyd = 1e-4;
    o.solver = HYD_KRUS;
    o.jac_every = 10;
    o.q0[0] = 95.0 * M_PI / 180.0;
    o.q0[1] = -110.0 * M_PI / 180.0;
    o.slew0 = 0;
    o.load_mass = -1;
    o.hydraulics = 1;
    o.stop_limits = 1;
    o.init_hold = 1;
    o.p_low = 2e6;
    o.force_average = 0;
    o.model_file = "model";
    return o;
}

// ---- small 3x3 helpers (row-major) ----

void ow_rot_z(double yaw, double R[9]) {
    double c = cos(yaw), s = sin(yaw);
    double r[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
    memcpy(R, r, sizeof r);
}

void ow_mat_mul(const double A[9], const double B[9], double C[9]) {
    double t[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
    memcpy(C, t, sizeof t);
}

void ow_mat_vec(const double A[9], const double v[3], double out[3]) {
    double t[3];
    for (int i = 0; i < 3; ++i) t[i] = A[3 * i] * v[0] + A[3 * i + 1] * v[1] + A[3 * i + 2] * v[2];
    memcpy(out, t, sizeof t);
}

// Rotation of a link frame relative to its parent: the boom plane is x-z and
// a positive (counter-clockwise, x towards z) angle a is a rotation about -y.
static void rot_plane(double a, double R[9]) {
    double c = cos(a), s = sin(a);
    double r[9] = {c, 0, -s, 0, 1, 0, s, 0, c};
    memcpy(R, r, sizeof r);
}

static void to_dmatrix(const double R[9], dMatrix3 M) {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) M[4 * i + j] = R[3 * i + j];
        M[4 * i + 3] = 0;
    }
}

static void from_dmatrix(const dReal* M, double R[9]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R[3 * i + j] = M[4 * i + j];
}

// ---- frames ----

void ow_frame_point(const ode_world* w, int f, const double p[3], double out[3]) {
    const ow_frame* fr = &w->frame[f];
    if (fr->body) {
        dVector3 r;
        dBodyGetRelPointPos(fr->body, fr->org[0] + p[0], fr->org[1] + p[1], fr->org[2] + p[2], r);
        out[0] = r[0], out[1] = r[1], out[2] = r[2];
    } else {
        ow_mat_vec(fr->wrot, p, out);
        for (int i = 0; i < 3; ++i) out[i] += fr->wpos[i];
    }
}

void ow_frame_point_vel(const ode_world* w, int f, const double p[3], double out[3]) {
    const ow_frame* fr = &w->frame[f];
    if (fr->body) {
        dVector3 r;
        dBodyGetRelPointVel(fr->body, fr->org[0] + p[0], fr->org[1] + p[1], fr->org[2] + p[2], r);
        out[0] = r[0], out[1] = r[1], out[2] = r[2];
    } else {
        out[0] = out[1] = out[2] = 0;
    }
}

void ow_frame_rot(const ode_world* w, int f, double R[9]) {
    const ow_frame* fr = &w->frame[f];
    if (fr->body) from_dmatrix(dBodyGetRotation(fr->body), R);
    else memcpy(R, fr->wrot, sizeof fr->wrot);
}

// ---- registration of geoms and snapshot entries (fixed arrays, so the
// pointers given to ODE as geom data never move) ----

ow_geom* ow_add_geom(ode_world* w, dGeomID g, uint32_t cat, double friction) {
    if (w->ngeom >= OW_MAX_GEOMS) return NULL;
    ow_geom* e = &w->geom[w->ngeom++];
    e->g = g;
    e->cat = cat;
    e->friction = friction;
    e->support = -1;
    e->mesh = -1;
    e->name[0] = 0;
    dGeomSetData(g, e);
    return e;
}

void ow_geom_name(ow_geom* e, const char* name) {
    if (e) snprintf(e->name, sizeof e->name, "%s", name);
}

ow_vis* ow_add_vis(ode_world* w, const char* name, world_role role, world_shape shape, const double size[3],
                   const float rgba[4], int mesh, dBodyID body, const double pos[3], const double* rot) {
    if (w->nvis >= OW_MAX_VIS) return NULL;
    ow_vis* v = &w->vis[w->nvis++];
    memset(v, 0, sizeof *v);
    snprintf(v->name, sizeof v->name, "%s", name);
    v->role = role;
    v->shape = shape;
    memcpy(v->size, size, sizeof v->size);
    memcpy(v->rgba, rgba, sizeof v->rgba);
    v->mesh = mesh;
    v->body = body;
    if (pos) memcpy(v->pos, pos, sizeof v->pos);
    static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(v->rot, rot ? rot : I, sizeof v->rot);
    return v;
}

static dBodyID new_body(ode_world* w, const double pos[3], const double R[9], const dMass* m) {
    (void)w;
    dBodyID b = dBodyCreate(w->world);
    dBodySetPosition(b, pos[0], pos[1], pos[2]);
    dMatrix3 M;
    to_dmatrix(R, M);
    dBodySetRotation(b, M);
    dBodySetMass(b, m);
    return b;
}

// Mass of a boom: a box of the link's section whose inertia about the hinge
// axis (body y) is the model's I_i, with COM on the link axis at com, plus an
// optional point mass m_tip at the tip. Returns the combined COM along the
// link [m] and fills an ODE mass centred at that COM (ODE wants the COM at the
// body origin).
static double boom_mass(const crane_link* l, double m_tip, dMass* out) {
    double m = l->mass, M = m + m_tip;
    double c = (m * l->com + m_tip * l->length) / M;
    double dc1 = l->com - c, dc2 = l->length - c;
    double Ixx = m * (l->width * l->width + l->height * l->height) / 12.0;
    double Iyy = l->inertia + m * dc1 * dc1 + m_tip * dc2 * dc2;
    double Izz = m * (l->length * l->length + l->width * l->width) / 12.0 + m * dc1 * dc1 + m_tip * dc2 * dc2;
    dMassSetZero(out);
    dMassSetParameters(out, M, 0, 0, 0, Ixx, Iyy, Izz, 0, 0, 0);
    return c;
}

static const float RGBA_COLUMN[4] = {0.85f, 0.2f, 0.15f, 1};
static const float RGBA_BOOM1[4] = {0.9f, 0.25f, 0.15f, 1};
static const float RGBA_BOOM2[4] = {0.95f, 0.35f, 0.2f, 1};
static const float RGBA_LOAD[4] = {0.3f, 0.45f, 0.75f, 1};
/// A chain's telescopic extensions: lighter than the booms they slide out of.
static const float RGBA_EXT[4] = {0.98f, 0.62f, 0.3f, 1};

/// The drawn section (width, height [m]) of a chain body whose model gives
/// w x h: as given, except for an extension inside a parent drawn pw x ph
/// (0: none) that is not smaller than it, which is drawn at 85 % of it, so
/// the nested section shows inside its boom instead of through its walls
/// (a model that gives an extension as wide as its boom, or wider).
/// Collision keeps the model's size.
static void chain_draw_section(double w, double h, double pw, double ph, double* dw, double* dh) {
    *dw = pw > 0 && w >= pw ? 0.85 * pw : w;
    *dh = ph > 0 && h >= ph ? 0.85 * ph : h;
}

// Hinge stop angles (relative to the hinge's zero at build time) from the
// cylinder's stroke range, so the ODE joint limit takes the end-stop impact
// implicitly (docs/ode_world.md, "End stops").
static int joint_limits(const crane_actuator* a, double stroke, double q0, double* lo, double* hi) {
    double qa = crane_joint_for_stroke(a, 0.0), qb = crane_joint_for_stroke(a, stroke);
    if (!isfinite(qa) || !isfinite(qb)) return -1;
    if (qa > qb) {
        double t = qa;
        qa = qb;
        qb = t;
    }
    *lo = qa - q0;
    *hi = qb - q0;
    return 0;
}

int ow_build_crane(ode_world* w, const double col_pos[3], const double col_rot[9], dBodyID base, char* err,
                   size_t errsz) {
    const crane_mech* me = &w->mech;
    const double* q0 = w->opt.q0;
    const world_desc* d = &w->desc;
    double zero3[3] = {0, 0, 0};

    // Column: a body slewing on the truck (sandbox) or the fixed world frame.
    ow_frame* f0 = &w->frame[0];
    memset(f0, 0, sizeof *f0);
    double hcol = me->column_height, rcol = d->slew.column_radius;
    if (base) {
        dMass m;
        dMassSetCylinderTotal(&m, me->column_mass, 3, rcol, hcol);
        double R[9];
        memcpy(R, col_rot, sizeof R);
        double pos[3] = {col_pos[0] - R[2] * 0.5 * hcol, col_pos[1] - R[5] * 0.5 * hcol, col_pos[2] - R[8] * 0.5 * hcol};
        f0->body = new_body(w, pos, R, &m);
        f0->org[2] = 0.5 * hcol;
        dGeomID g = dCreateCylinder(w->dyn_space, rcol, hcol);
        dGeomSetBody(g, f0->body);
        ow_geom_name(ow_add_geom(w, g, OW_CAT_CRANE, 0.5), "column");
    } else {
        memcpy(f0->wpos, col_pos, sizeof f0->wpos);
        memcpy(f0->wrot, col_rot, sizeof f0->wrot);
    }
    {
        double sz[3] = {rcol, hcol, 0};
        double p[3] = {0, 0, base ? 0 : -0.5 * hcol};
        ow_vis* cv = ow_add_vis(w, "column", WORLD_ROLE_COLUMN, WORLD_SHAPE_CYLINDER, sz, RGBA_COLUMN,
                                WORLD_MESH_COLUMN, f0->body, base ? zero3 : p, NULL);
        // column.obj has its origin at the column foot, half the height below the centre [m].
        if (cv) cv->mesh_offset[2] = -0.5 * hcol;
        if (!base) {
            // Fixed column: its entry is in world coordinates.
            ow_vis* v = &w->vis[w->nvis - 1];
            double pw[3];
            ow_mat_vec(col_rot, p, pw);
            for (int i = 0; i < 3; ++i) v->pos[i] = col_pos[i] + pw[i];
            memcpy(v->rot, col_rot, sizeof v->rot);
        }
    }

    // Booms, built in the initial pose so each hinge's zero angle is q0.
    double a1 = q0[0] - 0.5 * M_PI, a2 = q0[0] + q0[1] - 0.5 * M_PI;
    double R1[9], R2[9], P[9];
    rot_plane(a1, P);
    ow_mat_mul(col_rot, P, R1);
    rot_plane(a2, P);
    ow_mat_mul(col_rot, P, R2);
    double m_tip = w->kind == WORLD_VALIDATION ? w->m3 : 0.0;
    static const char* const name[2] = {"boom1", "boom2"};
    static const world_role role[2] = {WORLD_ROLE_BOOM1, WORLD_ROLE_BOOM2};
    static const int mesh[2] = {WORLD_MESH_BOOM1, WORLD_MESH_BOOM2};
    double jpos[3];
    memcpy(jpos, col_pos, sizeof jpos);
    for (int i = 0; i < 2; ++i) {
        const crane_link* l = &me->link[i];
        const double* R = i ? R2 : R1;
        dMass m;
        double c = boom_mass(l, i == 1 ? m_tip : 0.0, &m);
        if (!dMassCheck(&m)) {
            snprintf(err, errsz, "%s: mechanics.links[%d]: inertia %g kg m^2 gives an impossible inertia tensor",
                     w->opt.model_file, i, l->inertia);
            return -1;
        }
        double off[3] = {c, 0, 0}, pos[3];
        ow_mat_vec(R, off, pos);
        for (int k = 0; k < 3; ++k) pos[k] += jpos[k];
        ow_frame* f = &w->frame[i + 1];
        memset(f, 0, sizeof *f);
        f->body = new_body(w, pos, R, &m);
        f->org[0] = -c;
        // The box covers the link from its joint to its tip.
        double sz[3] = {l->length, l->width, l->height}, gp[3] = {0.5 * l->length - c, 0, 0};
        if (w->kind == WORLD_SANDBOX) {
            dGeomID g = dCreateBox(w->dyn_space, sz[0], sz[1], sz[2]);
            dGeomSetBody(g, f->body);
            dGeomSetOffsetPosition(g, gp[0], gp[1], gp[2]);
            ow_geom_name(ow_add_geom(w, g, OW_CAT_CRANE, 0.5), name[i]);
        }
        ow_vis* bv = ow_add_vis(w, name[i], role[i], WORLD_SHAPE_BOX, sz, i ? RGBA_BOOM2 : RGBA_BOOM1, mesh[i], f->body,
                                gp, NULL);
        // boom1.obj / boom2.obj have their origin at the root joint, half a length behind the box centre [m].
        if (bv) bv->mesh_offset[0] = -0.5 * l->length;
        double step[3] = {l->length, 0, 0}, dj[3];
        ow_mat_vec(R, step, dj);
        for (int k = 0; k < 3; ++k) jpos[k] += dj[k];
    }
    if (w->kind == WORLD_VALIDATION && w->m3 > 0) {
        // The tip load is merged into the end arm's mass (a point mass, as in
        // lagrange); this entry only draws it hanging under the tip, as a
        // plain box: the load mesh is a 1.2 m pallet that would not match it.
        double s = 0.5, sz[3] = {s, s, s};
        double p[3] = {me->link[1].length + w->frame[2].org[0], 0, -0.5 * s - 0.1};
        ow_add_vis(w, "load", WORLD_ROLE_LOAD, WORLD_SHAPE_BOX, sz, RGBA_LOAD, -1, w->frame[2].body, p, NULL);
    }

    // Hinges: axis -y of the column frame, so a positive hinge angle is a
    // positive (counter-clockwise) q.
    double axis_l[3] = {0, -1, 0}, axis[3];
    ow_mat_vec(col_rot, axis_l, axis);
    w->j1 = dJointCreateHinge(w->world, 0);
    dJointAttach(w->j1, w->frame[1].body, w->frame[0].body);
    dJointSetHingeAnchor(w->j1, col_pos[0], col_pos[1], col_pos[2]);
    dJointSetHingeAxis(w->j1, axis[0], axis[1], axis[2]);
    double j2p[3], l1[3] = {me->link[0].length, 0, 0};
    ow_frame_point(w, 1, l1, j2p);
    w->j2 = dJointCreateHinge(w->world, 0);
    dJointAttach(w->j2, w->frame[2].body, w->frame[1].body);
    dJointSetHingeAnchor(w->j2, j2p[0], j2p[1], j2p[2]);
    dJointSetHingeAxis(w->j2, axis[0], axis[1], axis[2]);
    w->qoff[0] = q0[0];
    w->qoff[1] = q0[1];
    for (int k = 0; k < 2; ++k) {
        w->lim[k][0] = -dInfinity;
        w->lim[k][1] = dInfinity;
    }

    // Boom cylinders: mounts from crane_mech (planar x, z -> frame x, 0, z).
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &me->act[k];
        ow_act* c = &w->act[k];
        c->present = 1;
        c->parent = a->joint;      // joint 0: column -> lifting arm; joint 1: lifting arm -> end arm
        c->child = a->joint + 1;
        // Mounts are given relative to the joint they act across; the parent
        // frame's origin is the previous joint (joint 1 for the lifting arm),
        // so the jib's barrel pin shifts by L1 along the lifting arm.
        double shift = a->joint == 1 ? me->link[0].length : 0.0;
        c->base[0] = a->base_mount[0] + shift, c->base[1] = 0, c->base[2] = a->base_mount[1];
        c->rod[0] = a->rod_mount[0], c->rod[1] = 0, c->rod[2] = a->rod_mount[1];
        c->closed_length = a->closed_length;
        if (c->stroke > 0) {
            // Reject an initial pose the cylinder cannot reach: the hinge
            // limit would otherwise snap the boom on the first step.
            if (crane_check_pose(a, c->stroke, q0[k], err, errsz)) return -1;
            double lo, hi;
            if (w->opt.stop_limits && joint_limits(a, c->stroke, q0[k], &lo, &hi) == 0 && lo > -M_PI && hi < M_PI) {
                dJointID j = k ? w->j2 : w->j1;
                dJointSetHingeParam(j, dParamLoStop, lo);
                dJointSetHingeParam(j, dParamHiStop, hi);
                dJointSetHingeParam(j, dParamBounce, 0.0);
                w->lim[k][0] = lo;
                w->lim[k][1] = hi;
            }
        }
    }
    return 0;
}

// ---- the chain crane (opts.chain) ----

void ow_tip(const ode_world* w, double p[3], double v[3]) {
    if (w->chain) {
        ode_chain_tip(w->chain, p, v);
        return;
    }
    double tl[3] = {w->mech.link[1].length, 0, 0};
    ow_frame_point(w, 2, tl, p);
    if (v) ow_frame_point_vel(w, 2, tl, v);
}

int ow_crane_bodies(const ode_world* w, dBodyID* b, int max) {
    int n = 0;
    if (w->chain) {
        const int nb = ode_chain_chain(w->chain)->nbody;
        for (int i = 0; i < nb && n < max; ++i) {
            dBodyID x = ode_chain_body_id(w->chain, i, NULL);
            if (x) b[n++] = x;
        }
        return n;
    }
    for (int f = 0; f < 3 && n < max; ++f)
        if (w->frame[f].body) b[n++] = w->frame[f].body;
    return n;
}

int ow_build_chain_crane(ode_world* w, const double base[3], const double R[9], char* err, size_t errsz) {
    // The chain as the model gives it, with the slew drive the run uses (the
    // model's where it has one, else the world's: ode_world_take_model_slew
    // has put it into desc.slew either way), and the column slewing.
    crane_chain cc = *w->opt.chain; // shallow: ode_chain_create copies it
    const world_slew* ds = &w->desc.slew;
    cc.slew.present = true;
    snprintf(cc.slew.cylinder, sizeof cc.slew.cylinder, "%s", ds->cylinder);
    snprintf(cc.slew.valve, sizeof cc.slew.valve, "%s", ds->valve);
    cc.slew.pinion_radius = ds->pinion_radius;
    cc.slew.column_radius = ds->column_radius;
    cc.slew.damping = ds->damping;
    cc.slew_free = true;
    cc.gravity = w->g; // the world's (a world file may set its own)
    const int nd = crane_chain_ndof(&cc);
    // q and qd, then the commands of ode_world_set_commands (nfn).
    w->chain_q = calloc((size_t)(2 * nd + cc.nfn + 2), sizeof *w->chain_q);
    if (!w->chain_q) {
        snprintf(err, errsz, "ode world: out of memory");
        return -1;
    }
    {
        // The slew drive's parts in the circuit, named where they were given.
        const bool from_model = w->desc.slew_file[0] != 0;
        const char* wf = from_model ? w->desc.slew_file : w->desc.file[0] ? w->desc.file : "world";
        const char* sf = from_model ? "mechanics.slew" : "slew";
        const int nc = hyd_model_cylinder(w->chain_hm, ds->cylinder) < 0, nv = hyd_model_valve(w->chain_hm, ds->valve) < 0;
        if (nc || nv) {
            snprintf(err, errsz, "%s: %s.%s: no %s named \"%s\" in the circuit", wf, sf, nc ? "cylinder" : "valve",
                     nc ? "cylinder" : "valve", nc ? ds->cylinder : ds->valve);
            return -1;
        }
    }
    // The scenario's start (q1, q2, slew0) as the chain's start pose, every
    // other joint at the middle of its limits (crane_chain_start_pose).
    crane_chain_start_pose(&cc, w->opt.q0, w->opt.slew0, w->chain_q);
    ode_chain_opts co = ode_chain_default_opts();
    co.dt_ode = w->opt.dt_ode;
    co.dt_hyd = w->opt.dt_hyd;
    co.solver = w->opt.solver;
    co.jac_every = w->opt.jac_every > 0 ? w->opt.jac_every : 1;
    co.general_circuit = w->opt.general_circuit;
    co.q0 = w->chain_q;
    co.slew0 = w->opt.slew0;
    co.stop_limits = w->opt.stop_limits;
    co.init_hold = w->opt.init_hold;
    co.p_low = w->opt.p_low;
    co.circuit = w->chain_hm;
    co.model_file = w->opt.model_file;
    // The seal friction a step late, as the two-link sandbox applies it:
    // a design and its chain variant driven in the sandbox then differ by
    // their design, not by how the world couples friction (the chain world's
    // implicit seal, its default, is for the comparison with the analytic
    // mode in the validation world; docs/ode_world.md).
    co.implicit_seal = 0;
    co.host_world = w->world;
    co.host_base = w->truck;
    memcpy(co.base_pos, base, sizeof co.base_pos);
    memcpy(co.base_rot, R, sizeof co.base_rot);
    co.slew_drive = 1;
    // The rope and hook hang at the tip: the start pressures hold them too,
    // as the two-link sandbox's (ow_hyd_init_state).
    co.hold_tip_mass = w->desc.hook.mass + w->desc.rope.mass_per_m * w->desc.rope.length;
    w->chain = ode_chain_create(&cc, &co, err, errsz);
    if (!w->chain) return -1;
    const crane_chain* c = ode_chain_chain(w->chain);
    // A collision box (a cylinder for the column) and a drawing per body,
    // named after it: the column over its height along z, a boom or an
    // extension from its joint along x over its length, its section width
    // x height. The two-link meshes fit the two-link crane's sizes only, so
    // the chain's bodies are drawn as their primitives. An extension is drawn
    // as a section inside its parent's (chain_draw_section), so it shows
    // sliding out of the boom instead of overlapping it.
    double* drawn = calloc((size_t)(2 * c->nbody + 2), sizeof *drawn); // drawn width, height per body [m]
    if (!drawn) {
        snprintf(err, errsz, "ode world: out of memory");
        return -1;
    }
    for (int i = 0; i < c->nbody; ++i) {
        double org[3];
        dBodyID b = ode_chain_body_id(w->chain, i, org);
        const crane_body* cb = &c->body[i];
        if (!b) continue;
        const double L = cb->length;
        const double r = i == 0 ? (c->slew.column_radius > 0 ? c->slew.column_radius : 0.5 * cb->height) : 0.0;
        if (!(L > 0) || (i == 0 ? !(r > 0) : !(cb->width > 0 && cb->height > 0))) continue; // nothing to collide
        double pos[3] = {org[0], org[1], org[2]}, sz[3];
        dGeomID g;
        if (i == 0) {
            pos[2] += 0.5 * L;
            g = dCreateCylinder(w->dyn_space, r, L);
            sz[0] = r, sz[1] = L, sz[2] = 0;
        } else {
            pos[0] += 0.5 * L;
            g = dCreateBox(w->dyn_space, L, cb->width, cb->height);
            sz[0] = L, sz[1] = cb->width, sz[2] = cb->height;
        }
        dGeomSetBody(g, b);
        dGeomSetOffsetPosition(g, pos[0], pos[1], pos[2]);
        ow_geom_name(ow_add_geom(w, g, OW_CAT_CRANE, 0.5), cb->def.name);
        const bool ext = i > 0 && cb->def.joint == CHAIN_PRISMATIC;
        const world_role role = i == 0 ? WORLD_ROLE_COLUMN : ext ? WORLD_ROLE_EXTENSION : WORLD_ROLE_BOOM;
        const float* rgba = i == 0 ? RGBA_COLUMN : ext ? RGBA_EXT : (i & 1) ? RGBA_BOOM1 : RGBA_BOOM2;
        double vsz[3] = {sz[0], sz[1], sz[2]};
        const int par = cb->def.parent;
        if (i > 0) {
            const bool nest = ext && par > 0 && par < i;
            chain_draw_section(cb->width, cb->height, nest ? drawn[2 * par] : 0, nest ? drawn[2 * par + 1] : 0,
                               &vsz[1], &vsz[2]);
            drawn[2 * i] = vsz[1], drawn[2 * i + 1] = vsz[2];
        }
        ow_add_vis(w, cb->def.name, role, i == 0 ? WORLD_SHAPE_CYLINDER : WORLD_SHAPE_BOX, vsz, rgba, -1, b, pos, NULL);
    }
    free(drawn);
    // A linkage's link and rocker: drawn as bars (no collision: they sit
    // between the booms), named after the actuator.
    for (int k = 0; k < c->nact; ++k)
        for (int which = 0; which < 2; ++which) {
            double len;
            dBodyID b = ode_chain_link_body(w->chain, k, which, &len);
            if (!b) continue;
            char name[40]; // the snapshot's names hold 47 characters
            snprintf(name, sizeof name, "%.30s_%s", c->act[k].name, which ? "rocker" : "link");
            const double sz[3] = {len, 0.06, 0.06}, zero[3] = {0, 0, 0};
            ow_add_vis(w, name, WORLD_ROLE_OTHER, WORLD_SHAPE_BOX, sz, RGBA_BOOM2, -1, b, zero, NULL);
        }
    // Frames for the sandbox's column and rope (frame 1: the first boom).
    memset(w->frame, 0, sizeof w->frame);
    w->frame[0].body = ode_chain_body_id(w->chain, 0, w->frame[0].org);
    if (c->nbody > 1) w->frame[1].body = ode_chain_body_id(w->chain, 1, w->frame[1].org);
    w->frame[2].body = ode_chain_body_id(w->chain, c->tip_body, w->frame[2].org);
    if (!w->frame[0].body || !w->frame[2].body) {
        snprintf(err, errsz, "%s: mechanics: the sandbox needs a column and a tip body ODE moves", w->opt.model_file);
        return -1;
    }
    // The slew's display copy (the snapshot's rack, ow_sandbox_snapshot).
    ow_act* s = &w->act[ODE_SLEW];
    s->present = 1;
    hyd_model_cylinder_geometry(w->chain_hm, hyd_model_cylinder(w->chain_hm, c->slew.cylinder), &s->AA, &s->AB,
                                &s->stroke);
    ow_read_actuators(w);
    return 0;
}

// The chain's compiled circuit: the model's hydraulics with the world's
// part (the slew's) appended, as ow_hyd_create compiles it for the
// two-link crane; the model's own circuit when the world adds none.
static int chain_circuit(ode_world* w, const cJSON* hydraulics, const world_desc* desc, char* err, size_t errsz) {
    const cJSON* frag = world_desc_circuit_for(desc, hydraulics);
    const char* part = desc->slew_file[0] ? "hydraulics_slew" : frag && frag == desc->circuit_ls ? "circuit_ls"
                                                                                                 : "circuit";
    const char* wf = desc->slew_file[0] ? desc->slew_file : desc->file[0] ? desc->file : "world";
    if (frag) {
        if (!hydraulics) {
            snprintf(err, errsz, "%s: hydraulics: missing (required by the ode world)", w->opt.model_file);
            return -1;
        }
        w->chain_hm = model_circuit_with_fragment(hydraulics, w->opt.model_file, frag, wf, part, err, errsz);
        w->chain_own_hm = 1;
    } else if (w->opt.circuit) {
        w->chain_hm = w->opt.circuit;
    } else if (hydraulics) {
        w->chain_hm = hyd_model_from_json(hydraulics, w->opt.model_file, "hydraulics", err, errsz);
        w->chain_own_hm = 1;
    } else {
        snprintf(err, errsz, "%s: hydraulics: missing (required by the ode world)", w->opt.model_file);
    }
    return w->chain_hm ? 0 : -1;
}

// Stroke and rate of every actuator from the bodies' mount points (boom
// cylinders) or the slew hinge (rack and pinion).
static void boom_cyl_kinematics(const ode_world* w, const ow_act* c, double* x, double* v) {
    double pb[3], pr[3], vb[3], vr[3];
    ow_frame_point(w, c->parent, c->base, pb);
    ow_frame_point(w, c->child, c->rod, pr);
    ow_frame_point_vel(w, c->parent, c->base, vb);
    ow_frame_point_vel(w, c->child, c->rod, vr);
    double d[3] = {pr[0] - pb[0], pr[1] - pb[1], pr[2] - pb[2]};
    double L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    *x = L - c->closed_length;
    *v = ((vr[0] - vb[0]) * d[0] + (vr[1] - vb[1]) * d[1] + (vr[2] - vb[2]) * d[2]) / L;
}

// Rack-and-pinion slew: stroke [m] from mid-stroke at the hinge angle, rate
// [m/s].
static void slew_kinematics(const ode_world* w, const ow_act* c, double* x, double* v) {
    const double r = w->desc.slew.pinion_radius;
    *x = 0.5 * c->stroke + r * ow_slew_angle(w);
    *v = r * dJointGetHingeAngleRate(w->slew_joint);
}

// The hinge angle's turn count relative to the last read (raw: now).
static double slew_turns_at(const ode_world* w, double raw) {
    const double d = raw - w->slew_raw;
    return w->slew_turns + (d > M_PI ? -2 * M_PI : d < -M_PI ? 2 * M_PI : 0.0);
}

double ow_slew_angle(const ode_world* w) {
    if (w->chain) {
        ode_chain_q(w->chain, w->chain_q, NULL);
        return w->chain_q[0];
    }
    if (!w->slew_joint) return 0.0;
    const double raw = dJointGetHingeAngle(w->slew_joint);
    return raw + slew_turns_at(w, raw) + w->slew_off;
}

void ow_slew_stops(ode_world* w) {
    // A stop this turn's (-pi, pi] cannot reach is left to the turn that
    // can: ODE sees it once the angle has wrapped (the next read), and holds
    // it from there. A rack of more than a turn puts both stops in one turn
    // with lo > hi: the angle is then above lo or below hi, and only that
    // stop is reachable before the next wrap. Set hi before lo so ODE never
    // sees lo > hi.
    double lo = w->slew_lim[0] - w->slew_turns, hi = w->slew_lim[1] - w->slew_turns;
    if (!(fabs(lo) < M_PI)) lo = -dInfinity;
    if (!(fabs(hi) < M_PI)) hi = dInfinity;
    if (lo > -dInfinity && hi < dInfinity && lo >= hi) {
        if (w->slew_raw >= lo) hi = dInfinity;
        else lo = -dInfinity;
    }
    dJointSetHingeParam(w->slew_joint, dParamLoStop, -dInfinity);
    dJointSetHingeParam(w->slew_joint, dParamHiStop, hi);
    dJointSetHingeParam(w->slew_joint, dParamLoStop, lo);
}

void ow_read_actuators(ode_world* w) {
    if (w->chain) {
        // The slew's display copy; the chain reads its own actuators.
        ow_act* s = &w->act[ODE_SLEW];
        ode_chain_slew_state(w->chain, &s->x, &s->v, &s->F, NULL, NULL, &s->at_stop);
        return;
    }
    if (w->slew_joint) {
        const double raw = dJointGetHingeAngle(w->slew_joint);
        const double turns = slew_turns_at(w, raw);
        w->slew_raw = raw;
        if (turns != w->slew_turns) {
            w->slew_turns = turns;
            ow_slew_stops(w);
        }
    }
    for (int k = 0; k < 2; ++k) {
        ow_act* c = &w->act[k];
        boom_cyl_kinematics(w, c, &c->x, &c->v);
        dJointID j = k ? w->j2 : w->j1;
        double ang = dJointGetHingeAngle(j);
        double lo = dJointGetHingeParam(j, dParamLoStop), hi = dJointGetHingeParam(j, dParamHiStop);
        c->at_stop = (lo > -dInfinity && ang <= lo + 1e-6) || (hi < dInfinity && ang >= hi - 1e-6);
    }
    ow_act* s = &w->act[ODE_SLEW];
    if (s->present && w->slew_joint) slew_kinematics(w, s, &s->x, &s->v);
}

// Cylinder forces as equal and opposite forces at the two pins along the
// cylinder axis (exactly the hinge torque F dx/dphi, but valid in 3D and for
// any parent body), the slew force as torque F r on the slew hinge, and the
// test torques.
void ow_apply_forces(ode_world* w) {
    if (w->held || w->chain) return; // a chain applies its own (ode_chain_host_pre)
    for (int k = 0; k < 2; ++k) {
        ow_act* c = &w->act[k];
        if (c->F == 0) continue;
        double pb[3], pr[3];
        ow_frame_point(w, c->parent, c->base, pb);
        ow_frame_point(w, c->child, c->rod, pr);
        double d[3] = {pr[0] - pb[0], pr[1] - pb[1], pr[2] - pb[2]};
        double L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        double s = c->F / L;
        dBodyAddForceAtPos(w->frame[c->child].body, s * d[0], s * d[1], s * d[2], pr[0], pr[1], pr[2]);
        if (w->frame[c->parent].body)
            dBodyAddForceAtPos(w->frame[c->parent].body, -s * d[0], -s * d[1], -s * d[2], pb[0], pb[1], pb[2]);
    }
    if (w->slew_joint) {
        double tau = w->act[ODE_SLEW].F * w->desc.slew.pinion_radius -
                     w->desc.slew.damping * dJointGetHingeAngleRate(w->slew_joint);
        dJointAddHingeTorque(w->slew_joint, tau);
    }
    if (w->tau_extra[0] != 0) dJointAddHingeTorque(w->j1, w->tau_extra[0]);
    if (w->tau_extra[1] != 0) dJointAddHingeTorque(w->j2, w->tau_extra[1]);
}

// ---- create / destroy ----

typedef struct create_args {
    const cJSON* hydraulics;
    const world_desc* desc;
    char* err;
    size_t errsz;
} create_args;

// The ODE part of ode_world_create (run under ow_trapped): 0, or -1 with err set.
static int build_world(ode_world* w, void* arg) {
    const create_args* a = arg;
    w->world = ow_world_new(w->g, w->desc.ode.erp, w->desc.ode.cfm, &w->threading);
    dWorldSetContactSurfaceLayer(w->world, w->desc.ode.surface_layer);
    // No automatic disabling by default: a resting crane must react to the
    // next command at once. Loads and obstacles opt in per body
    // (ode_sandbox.c, allow_sleep).
    dWorldSetAutoDisableFlag(w->world, 0);
    w->dyn_space = dSimpleSpaceCreate(0);
    w->static_space = dSimpleSpaceCreate(0);
    w->contacts = dJointGroupCreate(0);

    if (w->opt.chain && !w->opt.chain->two_link) {
        // The chain crane: its circuit, then the sandbox with the chain on
        // the truck (ow_build_sandbox, ow_build_chain_crane).
        if (chain_circuit(w, a->hydraulics, a->desc, a->err, a->errsz)) return -1;
        return ow_build_sandbox(w, a->err, a->errsz);
    }
    // The hydraulic circuit first: cylinder strokes are needed for the limits.
    if (w->opt.hydraulics) {
        // An LS model takes the world's LS slew section where it has one.
        const cJSON* frag = world_desc_circuit_for(a->desc, a->hydraulics);
        const char* part = a->desc && a->desc->slew_file[0]                  ? "hydraulics_slew"
                           : a->desc && frag && frag == a->desc->circuit_ls ? "circuit_ls"
                                                                             : "circuit";
        if (ow_hyd_create(w, a->hydraulics, frag, part, a->err, a->errsz)) return -1;
    } else {
        // Without a circuit, strokes come from nowhere; hinge limits are off.
        for (int k = 0; k < 2; ++k) w->act[k].stroke = 0;
    }

    if (w->kind == WORLD_VALIDATION) {
        static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        double p[3] = {0, 0, w->mech.column_height};
        if (ow_build_crane(w, p, I, 0, a->err, a->errsz)) return -1;
    } else {
        if (ow_build_sandbox(w, a->err, a->errsz)) return -1;
    }
    if (w->opt.hydraulics) ow_hyd_init_state(w);
    ow_read_actuators(w);
    return 0;
}

ode_world* ode_world_create(const crane_mech* mech, const cJSON* hydraulics, const world_desc* desc,
                            const ode_world_opts* o, char* err, size_t errsz) {
    ode_world_opts opt = o ? *o : ode_world_default_opts();
    if (!opt.model_file) opt.model_file = "model";
    if (!(opt.dt_ode > 0) || !(opt.dt_hyd > 0) || opt.dt_hyd > opt.dt_ode * (1 + 1e-9)) {
        snprintf(err, errsz, "ode world: need 0 < dt_hyd <= dt_ode, got dt_hyd = %g s, dt_ode = %g s", opt.dt_hyd,
                 opt.dt_ode);
        return NULL;
    }
    double ratio = opt.dt_ode / opt.dt_hyd;
    if (fabs(ratio - floor(ratio + 0.5)) > 1e-6) {
        snprintf(err, errsz, "ode world: dt_ode = %g s must be a whole multiple of dt_hyd = %g s", opt.dt_ode, opt.dt_hyd);
        return NULL;
    }
    if (opt.hydraulics && !hydraulics && !opt.circuit) {
        snprintf(err, errsz, "%s: hydraulics: missing (required by the ode world)", opt.model_file);
        return NULL;
    }
    if (opt.chain && !opt.chain->two_link) {
        // The chain crane is built for the sandbox only, with its circuit.
        if (!desc || desc->kind != WORLD_SANDBOX) {
            snprintf(err, errsz,
                     "%s: a chain crane's validation world is the ODE chain world (ode_chain.h); this world builds "
                     "a chain in the sandbox only",
                     opt.model_file);
            return NULL;
        }
        if (!opt.hydraulics) {
            snprintf(err, errsz, "%s: the sandbox's chain crane runs with its circuit only (hydraulics on)",
                     opt.model_file);
            return NULL;
        }
        if (hyd_method_is_adaptive(opt.solver)) {
            snprintf(err, errsz,
                     "solver %s is adaptive: the sandbox's chain crane sub-steps its circuit with a fixed-step method "
                     "(krus, ros2, rk4)",
                     hyd_method_name(opt.solver));
            return NULL;
        }
    }
    ode_world* w = calloc(1, sizeof *w);
    if (!w) {
        snprintf(err, errsz, "ode world: out of memory");
        return NULL;
    }
    ow_ode_acquire();
    w->opt = opt;
    w->mech = *mech;
    crane_mech_derive(&w->mech);
    if (desc) {
        w->desc = *desc;
    } else {
        world_desc_default(&w->desc, WORLD_VALIDATION);
    }
    w->desc.circuit = w->desc.circuit_ls = NULL; // never owned here
    w->kind = w->desc.kind;
    w->g = w->desc.gravity >= 0 ? w->desc.gravity : w->mech.gravity;
    w->m3 = opt.load_mass >= 0 ? opt.load_mass : w->mech.load_mass;
    w->attached = -1;
    w->released = -1;
    w->ipump = -1;
    for (int k = 0; k < ODE_NACT; ++k) w->act[k].cyl = w->act[k].valve = -1;

    create_args ca = {hydraulics, desc, err, errsz};
    const int rc = ow_trapped(w, "while building the world", build_world, &ca);
    if (rc == OW_ODE_FAILED) snprintf(err, errsz, "%s", w->err);
    if (rc) {
        ode_world_destroy(w);
        return NULL;
    }
    w->world_built = 1;
    return w;
}


static int destroy_ode(ode_world* w, void* arg) {
    (void)arg;
    if (w->contacts) dJointGroupDestroy(w->contacts);
    if (w->dyn_space) dSpaceDestroy(w->dyn_space);
    if (w->static_space) dSpaceDestroy(w->static_space);
    if (w->hfield) dGeomHeightfieldDataDestroy(w->hfield);
    ow_mesh_destroy_data(w); // after the trimesh geoms that use them
    if (w->world) {
        dWorldSetStepThreadingImplementation(w->world, NULL, NULL);
        dWorldDestroy(w->world);
    }
    // A dead world's job queue may still hold the jobs of the step ODE left
    // (freeing it fails ODE's check): it is abandoned with the world.
    if (w->threading && !w->dead) dThreadingFreeImplementation(w->threading);
    return 0;
}

void ode_world_destroy(ode_world* w) {
    if (!w) return;
    ow_hyd_destroy(w);
    // The chain's bodies and joints are this world's (gone with it); the
    // chain frees its own memory only.
    ode_chain_destroy(w->chain);
    if (w->chain_own_hm) hyd_model_free(w->chain_hm);
    free(w->chain_q);
    // A dead world's ODE objects may fail ODE's checks once more as they are
    // torn down: then what is left of them is abandoned (a leak, once, at
    // the end of a failed run) rather than aborting.
    ow_trapped(w, "while destroying the world", destroy_ode, NULL);
    ow_mesh_free(w);
    free(w->terrain);
    free(w);
    ow_ode_release();
}

// ---- stepping ----

static int body_finite(dBodyID b) {
    const dReal* p = dBodyGetPosition(b);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* a = dBodyGetAngularVel(b);
    for (int i = 0; i < 3; ++i)
        if (!isfinite(p[i]) || !isfinite(v[i]) || !isfinite(a[i])) return 0;
    return 1;
}

static int check_finite(ode_world* w) {
    for (int f = 0; f < 3 && !w->chain; ++f) // a chain checks its own (ode_chain_host_post)
        if (w->frame[f].body && !body_finite(w->frame[f].body)) {
            static const char* const n[3] = {"column", "boom1", "boom2"};
            snprintf(w->err, sizeof w->err, "ode world: body %s became non-finite at t = %.6f s", n[f], w->t);
            return -1;
        }
    if (w->truck && !body_finite(w->truck)) {
        snprintf(w->err, sizeof w->err, "ode world: body truck became non-finite at t = %.6f s", w->t);
        return -1;
    }
    for (int i = 0; i < w->nrope; ++i)
        if (!body_finite(w->rope[i])) {
            snprintf(w->err, sizeof w->err, "ode world: body rope_%d became non-finite at t = %.6f s", i, w->t);
            return -1;
        }
    if (w->hook && !body_finite(w->hook)) {
        snprintf(w->err, sizeof w->err, "ode world: body hook became non-finite at t = %.6f s", w->t);
        return -1;
    }
    for (int i = 0; i < w->nload; ++i)
        if (!body_finite(w->load[i])) {
            snprintf(w->err, sizeof w->err, "ode world: body %s became non-finite at t = %.6f s", w->desc.load[i].name,
                     w->t);
            return -1;
        }
    return 0;
}

static int step_ode(ode_world* w, void* arg) {
    const long n = *(const long*)arg;
    const double h = w->opt.dt_ode;
    for (long i = 0; i < n; ++i) {
        ow_read_actuators(w);
        if (w->hm) {
            if (ow_hyd_step(w, h)) {
                w->failed = 1;
                return -1;
            }
        }
        if (w->chain && ode_chain_host_pre(w->chain)) {
            snprintf(w->err, sizeof w->err, "%s", ode_chain_error(w->chain));
            w->failed = 1;
            return -1;
        }
        ow_apply_forces(w);
        if (w->kind == WORLD_SANDBOX) ow_collide(w);
        dWorldStep(w->world, h);
        if (w->kind == WORLD_SANDBOX) {
            ow_support_forces(w);
            dJointGroupEmpty(w->contacts);
        }
        if (w->chain && ode_chain_host_post(w->chain)) {
            snprintf(w->err, sizeof w->err, "%s", ode_chain_error(w->chain));
            w->failed = 1;
            return -1;
        }
        ++w->nstep;
        // Time as a step count times h, so long runs do not accumulate
        // round-off and repeated runs land on identical times.
        w->t = (double)w->nstep * h;
        if (check_finite(w)) {
            w->failed = 1;
            return -1;
        }
    }
    return 0;
}

int ode_world_step(ode_world* w, double dt) {
    if (w->failed) return -1;
    // Capped before the conversion: a dt of 1e300 s is not a step count a
    // long can hold (undefined behaviour). 1e12 steps is already "never".
    const double steps = floor(dt / w->opt.dt_ode + 0.5);
    long n = steps > 1e12 ? (long)1e12 : (long)steps;
    if (n < 1) n = 1;
    return ow_trapped(w, "in a step", step_ode, &n) ? -1 : 0;
}

const char* ode_world_error(const ode_world* w) { return w->err; }
double ode_world_time(const ode_world* w) { return w->t; }
double ode_world_dt(const ode_world* w) { return w->opt.dt_ode; }
world_kind ode_world_kind(const ode_world* w) { return w->kind; }
long ode_world_hyd_steps(const ode_world* w) { return w->hyd_steps; }

hyd_solver_stats ode_world_hyd_stats(const ode_world* w) {
    hyd_solver_stats st = {0};
    if (w->hs) st = *hyd_solver_get_stats(w->hs);
    return st;
}

void ode_world_set_commands(ode_world* w, const double u_cmd[ODE_NACT]) {
    for (int k = 0; k < ODE_NACT; ++k) {
        double u = u_cmd[k];
        w->u_cmd[k] = u > 1 ? 1 : u < -1 ? -1 : (u == u ? u : 0);
    }
    if (w->chain) {
        // The functions of the chain's first two actuators, and the slew
        // (ode_world_chain: a run of every function commands the chain).
        const crane_chain* c = ode_chain_chain(w->chain);
        double* cmd = w->chain_q + 2 * ode_chain_ndof(w->chain);
        for (int f = 0; f < c->nfn; ++f) cmd[f] = 0.0;
        for (int k = 0; k < 2 && k < c->nact; ++k) cmd[c->act[k].function] = w->u_cmd[k];
        ode_chain_set_commands(w->chain, cmd);
        ode_chain_set_slew_command(w->chain, w->u_cmd[ODE_SLEW]);
    }
}

struct ode_chain* ode_world_chain(const ode_world* w) { return w->chain; }

void ode_world_set_joint_torques(ode_world* w, const double tau[2]) {
    if (w->chain) return; // two-link test hook (ode_chain_set_joint_forces for a chain)
    w->tau_extra[0] = tau[0];
    w->tau_extra[1] = tau[1];
}

void ode_world_set_joint_rates(ode_world* w, const double qd[2]) {
    if (w->dead || w->chain) return; // ODE failed on these bodies: not touched again; a two-link test hook
    // Rigid-body velocities of the booms for joint rates qd about the fixed
    // joint 1 (validation column at rest): omega along the hinge axis.
    double axis_l[3] = {0, -1, 0}, R[9], ax[3];
    ow_frame_rot(w, 0, R);
    ow_mat_vec(R, axis_l, ax);
    double j1[3], j2[3], zero[3] = {0, 0, 0}, l1[3] = {w->mech.link[0].length, 0, 0};
    ow_frame_point(w, 1, zero, j1);
    ow_frame_point(w, 1, l1, j2);
    double om1 = qd[0], om2 = qd[0] + qd[1];
    for (int i = 1; i <= 2; ++i) {
        dBodyID b = w->frame[i].body;
        const dReal* p = dBodyGetPosition(b);
        double om = i == 1 ? om1 : om2;
        // v = v_joint + omega x (p - joint); joint 2 moves with boom 1.
        double r1[3] = {p[0] - j1[0], p[1] - j1[1], p[2] - j1[2]};
        double v[3];
        if (i == 1) {
            v[0] = om * (ax[1] * r1[2] - ax[2] * r1[1]);
            v[1] = om * (ax[2] * r1[0] - ax[0] * r1[2]);
            v[2] = om * (ax[0] * r1[1] - ax[1] * r1[0]);
        } else {
            double rj[3] = {j2[0] - j1[0], j2[1] - j1[1], j2[2] - j1[2]};
            double r2[3] = {p[0] - j2[0], p[1] - j2[1], p[2] - j2[2]};
            double vj[3] = {om1 * (ax[1] * rj[2] - ax[2] * rj[1]), om1 * (ax[2] * rj[0] - ax[0] * rj[2]),
                            om1 * (ax[0] * rj[1] - ax[1] * rj[0])};
            v[0] = vj[0] + om * (ax[1] * r2[2] - ax[2] * r2[1]);
            v[1] = vj[1] + om * (ax[2] * r2[0] - ax[0] * r2[2]);
            v[2] = vj[2] + om * (ax[0] * r2[1] - ax[1] * r2[0]);
        }
        dBodySetLinearVel(b, v[0], v[1], v[2]);
        dBodySetAngularVel(b, om * ax[0], om * ax[1], om * ax[2]);
    }
}

static double body_energy(dBodyID b, double g) {
    dMass m;
    dBodyGetMass(b, &m);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* om = dBodyGetAngularVel(b);
    const dReal* p = dBodyGetPosition(b);
    double R[9], I[9], t[9], Iw[9], Rt[9];
    from_dmatrix(dBodyGetRotation(b), R);
    from_dmatrix(m.I, I);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Rt[3 * i + j] = R[3 * j + i];
    ow_mat_mul(R, I, t);
    ow_mat_mul(t, Rt, Iw);
    double o[3] = {om[0], om[1], om[2]}, Io[3];
    ow_mat_vec(Iw, o, Io);
    double ke = 0.5 * m.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * (o[0] * Io[0] + o[1] * Io[1] + o[2] * Io[2]);
    return ke + m.mass * g * p[2];
}

double ode_world_energy(const ode_world* w) {
    if (w->dead) return NAN;
    double e = 0;
    dBodyID cb[OW_MAX_GEOMS];
    const int ncb = ow_crane_bodies(w, cb, OW_MAX_GEOMS);
    for (int f = 0; f < ncb; ++f) e += body_energy(cb[f], w->g);
    if (w->truck) e += body_energy(w->truck, w->g);
    for (int i = 0; i < w->nrope; ++i) e += body_energy(w->rope[i], w->g);
    if (w->hook) e += body_energy(w->hook, w->g);
    for (int i = 0; i < w->nload; ++i) e += body_energy(w->load[i], w->g);
    return e;
}

void ode_world_part_energy(const ode_world* w, double* crane, double* hook) {
    *crane = *hook = NAN;
    if (w->dead) return;
    double c = 0, h = 0;
    dBodyID cb[OW_MAX_GEOMS];
    const int ncb = ow_crane_bodies(w, cb, OW_MAX_GEOMS);
    for (int f = 0; f < ncb; ++f) c += body_energy(cb[f], w->g);
    for (int i = 0; i < w->nrope; ++i) h += body_energy(w->rope[i], w->g);
    if (w->hook) h += body_energy(w->hook, w->g);
    *crane = c;
    *hook = h;
}

// ---- state ----

static void tip_point(const ode_world* w, double p[3], double v[3]) { ow_tip(w, p, v); }

static int get_state_ode(ode_world* w, void* arg);

void ode_world_get_state(const ode_world* w, ode_world_state* s) {
    memset(s, 0, sizeof *s);
    s->t = w->t;
    // A dead world's bodies are not asked again (ODE failed on them): the
    // hydraulic states, which are ours, are all it reports.
    if (w->dead || ow_trapped((ode_world*)w, "reading the state", get_state_ode, s)) {
        ode_world_chamber_pressures(w, s->pA, s->pB);
        s->t = w->t;
        s->attached = -1;
    }
}

static void chain_state(ode_world* w, ode_world_state* s);

static int get_state_ode(ode_world* w, void* arg) {
    ode_world_state* s = arg;
    if (w->chain) {
        chain_state(w, s);
        return 0;
    }
    for (int k = 0; k < ODE_NACT; ++k) {
        const ow_act* c = &w->act[k];
        if (!c->present) continue;
        // Strokes fresh from the current body poses (act[].x is the value
        // the last step started from).
        if (k < 2) {
            boom_cyl_kinematics(w, c, &s->x[k], &s->v[k]);
        } else if (w->slew_joint) {
            slew_kinematics(w, c, &s->x[k], &s->v[k]);
        }
        s->F[k] = c->F;
        s->u_cmd[k] = w->u_cmd[k];
        if (w->hm && c->cyl >= 0) {
            s->pA[k] = w->y[c->iA];
            s->pB[k] = w->y[c->iB];
            s->u[k] = c->iu >= 0 ? w->y[c->iu] : 0;
            if (w->hd->cyl_stop[c->cyl]) s->end_stop |= 1 << k;
        }
        if (c->at_stop) s->end_stop |= 1 << k;
    }
    s->q[0] = dJointGetHingeAngle(w->j1) + w->qoff[0];
    s->q[1] = dJointGetHingeAngle(w->j2) + w->qoff[1];
    s->qd[0] = dJointGetHingeAngleRate(w->j1);
    s->qd[1] = dJointGetHingeAngleRate(w->j2);
    if (w->slew_joint) {
        s->slew = ow_slew_angle(w);
        s->slew_rate = dJointGetHingeAngleRate(w->slew_joint);
    }
    // Tip relative to joint 1 in the column's boom plane.
    double tp[3], j1[3], zero[3] = {0, 0, 0}, R[9];
    tip_point(w, tp, NULL);
    ow_frame_point(w, 0, zero, j1);
    ow_frame_rot(w, 0, R);
    double d[3] = {tp[0] - j1[0], tp[1] - j1[1], tp[2] - j1[2]};
    s->tip[0] = R[0] * d[0] + R[3] * d[1] + R[6] * d[2];
    s->tip[1] = R[2] * d[0] + R[5] * d[1] + R[8] * d[2];
    memcpy(s->tip_world, tp, sizeof tp);
    if (w->hook) ow_hook_point(w, s->hook, s->hook_vel);
    else tip_point(w, s->hook, s->hook_vel);
    if (w->hm) {
        if (w->ipump >= 0) s->p_pump = w->y[w->ipump];
        int nc = hyd_model_ncomp(w->hm);
        for (int i = 0; i < nc; ++i)
            if (hyd_model_comp_type(w->hm, i) == HYD_RELIEF && w->hd->comp_open[i]) ++s->relief_open;
    }
    s->truck_tilt = w->truck ? ow_truck_tilt(w) : 0.0;
    s->ncontact = w->ncontact;
    s->max_depth = w->max_depth;
    s->max_depth_crane = w->max_depth_crane;
    s->attached = w->attached;
    if (w->nsupport) {
        double weight = 0;
        s->stab_margin = ow_stab_margin(w, &weight);
        for (int i = 0; i < w->nsupport; ++i) s->pad_F[i] = w->support_F[i];
        s->pad_lifted = ow_supports_lifted(w, weight);
    }
    return 0;
}

// The state of the chain crane in the two-link fields (ode_world_chain says
// which), and the sandbox's as for the two-link crane.
static void chain_state(ode_world* w, ode_world_state* s) {
    const crane_chain* c = ode_chain_chain(w->chain);
    const double* y;
    const hyd_data* hd;
    ode_chain_circuit_state(w->chain, &y, &hd);
    for (int k = 0; k < 2 && k < c->nact; ++k) {
        s->x[k] = ode_chain_act_length(w->chain, k, &s->v[k]) - c->act[k].closed_length;
        s->F[k] = ode_chain_act_force(w->chain, k, &s->pA[k], &s->pB[k]);
        const int iv = c->fn[c->act[k].function].valve_idx, iu = hyd_model_valve_state(w->chain_hm, iv);
        s->u[k] = iu >= 0 ? y[iu] : 0.0;
        s->u_cmd[k] = hd->valve_cmd[iv];
        if (ode_chain_act_at_stop(w->chain, k)) s->end_stop |= 1 << k;
    }
    int stop = 0;
    ode_chain_slew_state(w->chain, &s->x[ODE_SLEW], &s->v[ODE_SLEW], &s->F[ODE_SLEW], &s->pA[ODE_SLEW],
                         &s->pB[ODE_SLEW], &stop);
    {
        const int iv = hyd_model_valve(w->chain_hm, c->slew.valve), iu = hyd_model_valve_state(w->chain_hm, iv);
        s->u[ODE_SLEW] = iu >= 0 ? y[iu] : 0.0;
        s->u_cmd[ODE_SLEW] = hd->valve_cmd[iv];
    }
    if (stop) s->end_stop |= 1 << ODE_SLEW;
    double* q = w->chain_q;
    const int nd = ode_chain_ndof(w->chain);
    double* qd = q + nd;
    ode_chain_q(w->chain, q, qd);
    s->slew = q[0], s->slew_rate = qd[0];
    for (int k = 0; k < 2 && 1 + k < nd; ++k) s->q[k] = q[1 + k], s->qd[k] = qd[1 + k];
    // Tip relative to the first boom's joint in the column's boom plane.
    double tp[3], j1[3], R[9];
    ow_tip(w, tp, NULL);
    ode_chain_body_pose(w->chain, c->nbody > 1 ? 1 : 0, NULL, j1);
    ode_chain_body_pose(w->chain, 0, R, NULL);
    const double d[3] = {tp[0] - j1[0], tp[1] - j1[1], tp[2] - j1[2]};
    s->tip[0] = R[0] * d[0] + R[3] * d[1] + R[6] * d[2];
    s->tip[1] = R[2] * d[0] + R[5] * d[1] + R[8] * d[2];
    memcpy(s->tip_world, tp, sizeof tp);
    ow_hook_point(w, s->hook, s->hook_vel);
    const int ip = hyd_model_supply_node(w->chain_hm);
    s->p_pump = ip >= 0 ? hd->node_p[ip] : 0.0;
    for (int i = 0; i < hyd_model_ncomp(w->chain_hm); ++i)
        if (hyd_model_comp_type(w->chain_hm, i) == HYD_RELIEF && hd->comp_open[i]) ++s->relief_open;
    s->truck_tilt = ow_truck_tilt(w);
    s->ncontact = w->ncontact;
    s->max_depth = w->max_depth;
    s->max_depth_crane = w->max_depth_crane;
    s->attached = w->attached;
    double weight = 0;
    s->stab_margin = ow_stab_margin(w, &weight);
    for (int i = 0; i < w->nsupport; ++i) s->pad_F[i] = w->support_F[i];
    s->pad_lifted = ow_supports_lifted(w, weight);
}

int ode_world_nload(const ode_world* w) { return w->nload; }

void ode_world_load_state(const ode_world* w, int i, double pos[3], double vel[3]) {
    if (i < 0 || i >= w->nload) {
        memset(pos, 0, 3 * sizeof *pos);
        if (vel) memset(vel, 0, 3 * sizeof *vel);
        return;
    }
    const dReal* p = dBodyGetPosition(w->load[i]);
    const dReal* v = dBodyGetLinearVel(w->load[i]);
    for (int k = 0; k < 3; ++k) {
        pos[k] = p[k];
        if (vel) vel[k] = v[k];
    }
}

int ode_world_obstacle_pos(const ode_world* w, const char* name, double pos[3]) {
    for (int i = 0; i < w->desc.nobstacle; ++i) {
        if (strcmp(w->desc.obstacle[i].name, name)) continue;
        if (w->obst_body[i]) {
            const dReal* p = dBodyGetPosition(w->obst_body[i]);
            pos[0] = p[0], pos[1] = p[1], pos[2] = p[2];
        } else {
            memcpy(pos, w->desc.obstacle[i].position, 3 * sizeof *pos);
        }
        return 0;
    }
    return -1;
}

static int hook_ode(ode_world* w, void* arg) { return ow_attach(w, *(const int*)arg); }

int ode_world_hook(ode_world* w, int attach) {
    if (w->kind != WORLD_SANDBOX || w->dead) return -1;
    const int rc = ow_trapped(w, "attaching the hook", hook_ode, &attach);
    return rc == OW_ODE_FAILED ? -1 : rc;
}

void ode_world_hold_crane(ode_world* w, int hold) {
    if (w->dead) return;
    hold = hold != 0;
    if (hold == w->held || w->chain) return; // a two-link test hook
    w->held = hold;
    dBodyID b[4] = {w->truck, w->frame[0].body, w->frame[1].body, w->frame[2].body};
    for (int i = 0; i < 4; ++i) {
        if (!b[i]) continue;
        if (hold) {
            dBodySetKinematic(b[i]);
            dBodySetLinearVel(b[i], 0, 0, 0);
            dBodySetAngularVel(b[i], 0, 0, 0);
        } else {
            dBodySetDynamic(b[i]);
        }
    }
    // Joints between two kinematic bodies carry nothing; switch them off so the
    // solver does not see empty rows.
    dJointID j[3] = {w->slew_joint, w->j1, w->j2};
    for (int i = 0; i < 3; ++i) {
        if (!j[i]) continue;
        if (hold) dJointDisable(j[i]);
        else dJointEnable(j[i]);
    }
}

// ---- snapshot ----

static int snapshot_ode(ode_world* w, void* arg);

void ode_world_snapshot(const ode_world* w, world_snapshot* s) {
    // A dead world is not drawn again: the snapshot keeps the last picture
    // (the caller's), with the time of the failure.
    if (w->dead) {
        s->t = w->t;
        return;
    }
    ow_trapped((ode_world*)w, "drawing the world", snapshot_ode, s);
}

static int snapshot_ode(ode_world* w, void* arg) {
    world_snapshot* s = arg;
    memset(s, 0, sizeof *s);
    s->t = w->t;
    int n = 0;
    for (int i = 0; i < w->nvis && n < WORLD_SNAP_MAX_BODIES; ++i) {
        const ow_vis* v = &w->vis[i];
        world_snap_body* b = &s->body[n++];
        snprintf(b->name, sizeof b->name, "%s", v->name);
        b->role = v->role;
        b->shape = v->shape;
        memcpy(b->size, v->size, sizeof b->size);
        memcpy(b->rgba, v->rgba, sizeof b->rgba);
        if (v->body) {
            double R[9], p[3];
            from_dmatrix(dBodyGetRotation(v->body), R);
            const dReal* bp = dBodyGetPosition(v->body);
            ow_mat_vec(R, v->pos, p);
            for (int k = 0; k < 3; ++k) b->pos[k] = bp[k] + p[k];
            ow_mat_mul(R, v->rot, b->rot);
        } else {
            memcpy(b->pos, v->pos, sizeof b->pos);
            memcpy(b->rot, v->rot, sizeof b->rot);
        }
        b->mesh_scale = 1.0;
        b->mesh_up = 2;
        if (v->mesh >= 0) {
            const world_mesh* m = &w->desc.mesh[v->mesh];
            snprintf(b->mesh, sizeof b->mesh, "%s", m->file);
            b->mesh_scale = m->scale;
            b->mesh_up = m->up;
            memcpy(b->mesh_offset, m->has_offset ? m->offset : v->mesh_offset, sizeof b->mesh_offset);
        } else if (v->mesh == OW_VIS_OWN_MESH) {
            snprintf(b->mesh, sizeof b->mesh, "%s", v->mesh_file);
            b->mesh_scale = v->mesh_scale;
            b->mesh_up = v->mesh_up;
            memcpy(b->mesh_offset, v->mesh_offset, sizeof b->mesh_offset);
        }
    }
    s->nbody = n;

    // A chain crane's cylinders: as many as the snapshot holds, one place
    // kept for the slew's rack (ow_sandbox_snapshot).
    for (int k = 0; w->chain && k < ode_chain_nact(w->chain) && s->ncyl < WORLD_SNAP_MAX_CYLINDERS - 1; ++k) {
        const crane_chain* c = ode_chain_chain(w->chain);
        const crane_act* ca = &c->act[k];
        world_snap_cylinder* y = &s->cyl[s->ncyl++];
        snprintf(y->name, sizeof y->name, "%s", ca->name);
        ode_chain_act_pins(w->chain, k, y->base, y->rod_end);
        y->closed_length = ca->closed_length;
        y->stroke_max = ca->stroke;
        y->x = ode_chain_act_length(w->chain, k, &y->v) - ca->closed_length;
        y->force = ode_chain_act_force(w->chain, k, &y->pA, &y->pB);
        const int iv = c->fn[ca->function].valve_idx, iu = hyd_model_valve_state(w->chain_hm, iv);
        const double* cy;
        const hyd_data* hd;
        ode_chain_circuit_state(w->chain, &cy, &hd);
        y->u_cmd = hd->valve_cmd[iv];
        y->u = iu >= 0 ? cy[iu] : 0.0;
        double AA, AB, st;
        hyd_model_cylinder_geometry(w->chain_hm, ca->cyl, &AA, &AB, &st);
        y->bore = sqrt(4.0 * AA / M_PI);
        y->rod = sqrt(4.0 * (AA - AB) / M_PI);
        y->end_stop = (uint8_t)ode_chain_act_at_stop(w->chain, k);
    }
    // Boom cylinders.
    for (int k = 0; k < 2 && !w->chain; ++k) {
        const ow_act* c = &w->act[k];
        world_snap_cylinder* y = &s->cyl[s->ncyl++];
        snprintf(y->name, sizeof y->name, "%s", w->mech.act[k].name);
        ow_frame_point(w, c->parent, c->base, y->base);
        ow_frame_point(w, c->child, c->rod, y->rod_end);
        y->closed_length = c->closed_length;
        y->stroke_max = c->stroke;
        y->x = c->x;
        y->v = c->v;
        y->force = c->F;
        y->u_cmd = w->u_cmd[k];
        y->bore = k ? 0.08 : 0.1;
        y->rod = k ? 0.045 : 0.06;
        y->end_stop = (uint8_t)c->at_stop;
        if (w->hm && c->cyl >= 0) {
            double AA = c->AA, AB = c->AB;
            y->bore = sqrt(4.0 * AA / M_PI);
            y->rod = sqrt(4.0 * (AA - AB) / M_PI);
            y->pA = w->y[c->iA];
            y->pB = w->y[c->iB];
            y->u = c->iu >= 0 ? w->y[c->iu] : 0;
            y->end_stop |= (uint8_t)(w->hd->cyl_stop[c->cyl] != 0);
        }
    }
    double tp[3];
    tip_point(w, tp, NULL);
    memcpy(s->tip, tp, sizeof tp);
    memcpy(s->hook, tp, sizeof tp);
    s->load_mass = w->kind == WORLD_VALIDATION ? w->m3 : 0;
    if (w->hm && w->ipump >= 0) s->p_supply = w->y[w->ipump];
    if (w->chain) {
        const double* cy;
        const hyd_data* hd;
        ode_chain_circuit_state(w->chain, &cy, &hd);
        const int ip = hyd_model_supply_node(w->chain_hm);
        if (ip >= 0) s->p_supply = hd->node_p[ip];
    }
    if (w->kind == WORLD_SANDBOX) ow_sandbox_snapshot(w, s);
    ow_collision_snapshot(w, s);
    if (w->hm) {
        // Open reliefs by name, and on the cylinder whose chamber each
        // guards: snapshot cylinders are lift, jib, then the sandbox's slew.
        int cyl_hyd[WORLD_SNAP_MAX_CYLINDERS] = {w->act[0].cyl, w->act[1].cyl, -1, -1};
        if (w->act[ODE_SLEW].present) cyl_hyd[2] = w->act[ODE_SLEW].cyl;
        world_snap_reliefs(s, w->hm, w->hd->comp_open, cyl_hyd);
    }
    if (w->chain) {
        // The reliefs on the cylinders drawn (the chain's first ones, then
        // the slew's rack, in ncyl order).
        const crane_chain* c = ode_chain_chain(w->chain);
        int cyl_hyd[WORLD_SNAP_MAX_CYLINDERS] = {-1, -1, -1, -1};
        int n = 0;
        for (int k = 0; k < c->nact && n < WORLD_SNAP_MAX_CYLINDERS - 1; ++k) cyl_hyd[n++] = c->act[k].cyl;
        cyl_hyd[n] = hyd_model_cylinder(w->chain_hm, c->slew.cylinder);
        const double* cy;
        const hyd_data* hd;
        ode_chain_circuit_state(w->chain, &cy, &hd);
        world_snap_reliefs(s, w->chain_hm, hd->comp_open, cyl_hyd);
    }
    return 0;
}

void ode_world_lock_booms(ode_world* w, int lock) {
    if (w->dead || w->chain) return; // the two-link crane's hinges only
    dJointID j[2] = {w->j1, w->j2};
    for (int k = 0; k < 2; ++k) {
        // Set hi before lo (or lo before hi) so ODE never sees lo > hi.
        if (lock) {
            double a = dJointGetHingeAngle(j[k]);
            dJointSetHingeParam(j[k], dParamLoStop, -dInfinity);
            dJointSetHingeParam(j[k], dParamHiStop, a);
            dJointSetHingeParam(j[k], dParamLoStop, a);
        } else {
            dJointSetHingeParam(j[k], dParamLoStop, -dInfinity);
            dJointSetHingeParam(j[k], dParamHiStop, w->lim[k][1]);
            dJointSetHingeParam(j[k], dParamLoStop, w->lim[k][0]);
        }
    }
}

hyd_model* ode_world_circuit(ode_world* w) { return w->chain ? w->chain_hm : w->hm; }

void ode_world_circuit_state(const ode_world* w, double* y, const hyd_data** in) {
    if (w->chain) {
        const double* cy;
        ode_chain_circuit_state(w->chain, &cy, in);
        memcpy(y, cy, (size_t)hyd_model_nstate(w->chain_hm) * sizeof *y);
        return;
    }
    for (int i = 0; i < w->nh; ++i) y[i] = w->y[i];
    *in = w->hd;
}

int ode_world_set_link_mass(ode_world* w, int k, const crane_link* ln) {
    if (w->chain) return -1; // the two-link crane's links: a chain is rebuilt
    if (k < 0 || k > 1 || !w->frame[k + 1].body) return -1;
    const crane_link* old = &w->mech.link[k];
    if (ln->length != old->length || ln->width != old->width || ln->height != old->height) return -1;
    dMass m;
    const double c = boom_mass(ln, k == 1 && w->kind == WORLD_VALIDATION ? w->m3 : 0.0, &m);
    // The body origin is the combined centre of mass, -org from the joint.
    if (fabs(c + w->frame[k + 1].org[0]) > 1e-9 * ln->length || !dMassCheck(&m)) return -1;
    dBodySetMass(w->frame[k + 1].body, &m);
    w->mech.link[k] = *ln;
    return 0;
}

int ode_world_fused(const ode_world* w) { return w->hm && w->use_fused; }
int ode_world_fast(const ode_world* w) { return w->hm && w->use_fast; }

void ode_world_chamber_pressures(const ode_world* w, double pA[ODE_NACT], double pB[ODE_NACT]) {
    if (w->chain) {
        const int na = ode_chain_nact(w->chain);
        for (int k = 0; k < 2; ++k) {
            pA[k] = pB[k] = 0.0;
            if (k < na) ode_chain_act_force(w->chain, k, &pA[k], &pB[k]);
        }
        if (ode_chain_slew_state(w->chain, NULL, NULL, NULL, &pA[ODE_SLEW], &pB[ODE_SLEW], NULL))
            pA[ODE_SLEW] = pB[ODE_SLEW] = 0.0;
        return;
    }
    for (int k = 0; k < ODE_NACT; ++k) {
        const ow_act* c = &w->act[k];
        const bool on = w->hm && c->cyl >= 0;
        pA[k] = on ? w->y[c->iA] : 0.0;
        pB[k] = on ? w->y[c->iB] : 0.0;
    }
}

const char* ode_world_load_name(const ode_world* w, int i, double* mass) {
    if (i < 0 || i >= w->desc.nload) return NULL;
    if (mass) *mass = w->desc.load[i].mass;
    return w->desc.load[i].name;
}
