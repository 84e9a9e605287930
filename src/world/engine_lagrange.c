// engine_lagrange.c: the lagrange crane (lagrange_sim.h: the analytic
// 2-DOF crane and its full circuit as one ODE system) behind engine.h,
// stepped by an outside loop with commands set between steps.
#include "engine_impl.h"

#include "snap_reliefs.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct eng_lagrange {
    engine base;
    lsim ls;
    hyd_problem prob;
    hyd_solver* solver;
    double t;
    double y[LSIM_MAX_STATES];
} eng_lagrange;

static void lag_row(engine* e, double row[SIM_NCOL]);
static void lag_destroy(engine* e);
static const engine_ops lagrange_ops;

engine* engine_lagrange_create(const model* m, const sim_opts* o, const double q0[2], double m3, char* err,
                               size_t errsz) {
    eng_lagrange* l = calloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    l->base.ops = &lagrange_ops;
    l->base.o = *o;
    if (lsim_init(&l->ls, m, o->variant, m3, err, errsz)) {
        free(l);
        return NULL;
    }
    if (lsim_check_pose(&l->ls, q0, err, errsz) || sim_check_fixed_step(m->hyd, o, o->h, 0.0, err, errsz)) {
        lsim_free(&l->ls);
        free(l);
        return NULL;
    }
    lsim_initial_state(&l->ls, q0, 0.5e6, l->y);
    double row0[SIM_NCOL];
    lag_row(&l->base, row0);
    if (sim_check_start(m->hyd, row0, SIM_NCOL_BASE, m3, err, errsz)) {
        lsim_free(&l->ls);
        free(l);
        return NULL;
    }
    // The drive panel edits circuit parameters in place (hyd_model_set), and
    // the fused kernel holds a packed copy of them: live runs keep the
    // general path, which reads the model on every call. Real time needs 1x,
    // not the fused kernel's speed.
    l->ls.use_fused = false;
    const bool adaptive = hyd_method_is_adaptive(o->solver);
    l->prob = lsim_problem(&l->ls, !adaptive && !o->dense_jac);
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = adaptive ? 0.0 : o->h;
    so.rtol = o->rtol;
    so.atol = o->atol;
    so.jac_every = adaptive ? 1 : (o->jac_every > 0 ? o->jac_every : 1);
    l->solver = hyd_solver_create(&l->prob, o->solver, &so);
    if (!l->solver) {
        snprintf(err, errsz, "cannot create the %s solver", hyd_method_name(o->solver));
        lag_destroy(&l->base);
        return NULL;
    }
    return &l->base;
}

static void lag_destroy(engine* e) {
    eng_lagrange* l = (eng_lagrange*)e;
    hyd_solver_destroy(l->solver);
    lsim_free(&l->ls);
    free(l);
}

static hyd_model* lag_circuit(engine* e) { return ((eng_lagrange*)e)->ls.mdl->hyd; }

static void lag_set_load(engine* e, double m3) {
    eng_lagrange* l = (eng_lagrange*)e;
    if (l->ls.m3 == m3) return;
    l->ls.m3 = m3;
    lagrange_consts_init(&l->ls.mdl->mech, l->ls.variant, m3, &l->ls.lk);
    hyd_solver_inputs_changed(l->solver); // f changed at the same (t, y)
}

static int lag_set_link(engine* e, int k, const crane_link* ln) {
    eng_lagrange* l = (eng_lagrange*)e;
    // The lagrange crane reads the model's links (ln is one of them, edited
    // by the caller); the constants its fast kernels made from them at start
    // are made again.
    (void)k;
    (void)ln;
    lagrange_consts_init(&l->ls.mdl->mech, l->ls.variant, l->ls.m3, &l->ls.lk);
    hyd_solver_inputs_changed(l->solver); // f changed at the same (t, y)
    return 0;
}

static void lag_set_commands(engine* e, const double u[3]) {
    eng_lagrange* l = (eng_lagrange*)e;
    for (int k = 0; k < 2; ++k) {
        double v = u[k] < -1 ? -1 : u[k] > 1 ? 1 : u[k];
        // A command change is a kink in the input: adaptive methods restart
        // their step-size history there (decision 8).
        if (v != l->ls.u_cmd[k] && hyd_method_is_adaptive(e->o.solver)) hyd_solver_reset(l->solver);
        l->ls.u_cmd[k] = v;
    }
}

static int lag_step(engine* e, double dt) {
    eng_lagrange* l = (eng_lagrange*)e;
    int rc = hyd_solver_advance(l->solver, &l->t, l->y, l->t + dt);
    if (rc == HYD_OK) return 0;
    double tb = l->t;
    int i = hyd_solver_bad_state(l->solver, &tb);
    snprintf(e->err, sizeof e->err, "solver %s failed (code %d) at t = %.6g s, state %d", hyd_method_name(e->o.solver),
             rc, tb, i);
    return 1;
}

static double lag_time(const engine* e) { return ((const eng_lagrange*)e)->t; }

static void lag_row(engine* e, double row[SIM_NCOL]) {
    eng_lagrange* l = (eng_lagrange*)e;
    lsim_out o;
    lsim_outputs(&l->ls, l->t, l->y, &o);
    sim_lagrange_row(l->t, &o, row);
}

// Planar crane placed in the world: boom plane = x-z, joint 1 at the column
// top above the origin. Rotation about y by the elevation angle.
static void rot_y(double ang, double R[9]) {
    // The boom plane is x (reach) - z (up); a link's local x axis at elevation
    // ang points (cos, 0, sin). Rotation about -y maps x to that direction.
    const double c = cos(ang), s = sin(ang);
    const double M[9] = {c, 0, -s, 0, 1, 0, s, 0, c};
    memcpy(R, M, sizeof M);
}

static void add_body(world_snapshot* s, const char* name, world_role role, world_shape shape, const double pos[3],
                     const double R[9], double sx, double sy, double sz, const float rgba[4], const char* mesh) {
    if (s->nbody >= WORLD_SNAP_MAX_BODIES) return;
    world_snap_body* b = &s->body[s->nbody++];
    memset(b, 0, sizeof *b);
    snprintf(b->name, sizeof b->name, "%s", name);
    b->role = role;
    b->shape = shape;
    memcpy(b->pos, pos, sizeof b->pos);
    memcpy(b->rot, R, sizeof b->rot);
    b->size[0] = sx;
    b->size[1] = sy;
    b->size[2] = sz;
    memcpy(b->rgba, rgba, sizeof b->rgba);
    snprintf(b->mesh, sizeof b->mesh, "%s", mesh ? mesh : "");
    b->mesh_scale = 1.0;
    b->mesh_up = 2;
}

static void lag_snapshot(engine* e, world_snapshot* s) {
    eng_lagrange* l = (eng_lagrange*)e;
    lsim_out o;
    lsim_outputs(&l->ls, l->t, l->y, &o);
    const crane_mech* me = &l->ls.mdl->mech;
    memset(s, 0, offsetof(world_snapshot, body));
    s->nbody = 0;
    s->ncyl = 0;
    s->nrope = 0;
    s->t = l->t;
    const double H = me->column_height;
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const float grey[4] = {0.55f, 0.57f, 0.6f, 1}, orange[4] = {0.95f, 0.55f, 0.1f, 1},
                       load[4] = {0.5f, 0.35f, 0.2f, 1};
    const double colpos[3] = {0, 0, 0.5 * H};
    add_body(s, "column", WORLD_ROLE_COLUMN, WORLD_SHAPE_CYLINDER, colpos, I, 0.18, H, 0, grey, "column.obj");
    // The cylinder is centred at mid-height; the column mesh's origin is its foot.
    s->body[s->nbody - 1].mesh_offset[2] = -0.5 * H;
    // Link frames: elevation a1 = q1 - pi/2, a2 = a1 + q2; joint 1 at (0, 0, H).
    const double a1 = o.q[0] - M_PI / 2, a2 = a1 + o.q[1];
    const double j1[3] = {0, 0, H};
    const double j2[3] = {me->link[0].length * cos(a1), 0, H + me->link[0].length * sin(a1)};
    double R1[9], R2[9];
    rot_y(a1, R1);
    rot_y(a2, R2);
    const crane_link* L = me->link;
    // Box bodies sit at their centres; the boom meshes have their origin at
    // the root joint, half a length behind the centre.
    const double c1[3] = {j1[0] + 0.5 * L[0].length * cos(a1), 0, j1[2] + 0.5 * L[0].length * sin(a1)};
    const double c2[3] = {j2[0] + 0.5 * L[1].length * cos(a2), 0, j2[2] + 0.5 * L[1].length * sin(a2)};
    add_body(s, "boom1", WORLD_ROLE_BOOM1, WORLD_SHAPE_BOX, c1, R1, L[0].length, L[0].width, L[0].height, orange,
             "boom1.obj");
    s->body[s->nbody - 1].mesh_offset[0] = -0.5 * L[0].length;
    add_body(s, "boom2", WORLD_ROLE_BOOM2, WORLD_SHAPE_BOX, c2, R2, L[1].length, L[1].width, L[1].height, orange,
             "boom2.obj");
    s->body[s->nbody - 1].mesh_offset[0] = -0.5 * L[1].length;
    const double tip[3] = {j2[0] + L[1].length * cos(a2), 0, j2[2] + L[1].length * sin(a2)};
    const double lp[3] = {tip[0], 0, tip[2] - 0.35};
    // Box the size of load_block.obj (1.2 x 0.6 x 0.6, origin at its centre),
    // so mesh and fallback primitive cover the same space.
    add_body(s, "load", WORLD_ROLE_LOAD, WORLD_SHAPE_BOX, lp, I, 1.2, 0.6, 0.6, load, "load_block.obj");
    memcpy(s->tip, tip, sizeof s->tip);
    memcpy(s->hook, tip, sizeof s->hook);
    s->load_mass = l->ls.m3;
    // Cylinders: barrel pin in the parent frame, rod pin in the child frame.
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* ac = &me->act[k];
        world_snap_cylinder* c = &s->cyl[s->ncyl++];
        snprintf(c->name, sizeof c->name, "%s", ac->name);
        const double pa = k == 0 ? 0.0 : a1, ca = k == 0 ? a1 : a2;
        const double* org = k == 0 ? j1 : j2;
        c->base[0] = org[0] + ac->base_mount[0] * cos(pa) - ac->base_mount[1] * sin(pa);
        c->base[2] = org[2] + ac->base_mount[0] * sin(pa) + ac->base_mount[1] * cos(pa);
        c->rod_end[0] = org[0] + ac->rod_mount[0] * cos(ca) - ac->rod_mount[1] * sin(ca);
        c->rod_end[2] = org[2] + ac->rod_mount[0] * sin(ca) + ac->rod_mount[1] * cos(ca);
        double AA, AB, st;
        hyd_model_cylinder_geometry(l->ls.mdl->hyd, l->ls.mdl->cyl[k], &AA, &AB, &st);
        c->bore = sqrt(4 * AA / M_PI);
        c->rod = sqrt(4 * (AA - AB) / M_PI);
        c->stroke_max = st;
        c->closed_length = ac->closed_length;
        c->x = o.x[k];
        c->v = o.v[k];
        c->pA = o.pA[k];
        c->pB = o.pB[k];
        c->force = o.F[k];
        c->u = o.u[k];
        c->u_cmd = o.u_cmd[k];
        c->end_stop = (o.end_stop >> k) & 1;
    }
    s->p_supply = o.p_pump;
    // lsim_outputs evaluated the circuit at (t, y): its open flags are current.
    const int cyl_hyd[WORLD_SNAP_MAX_CYLINDERS] = {l->ls.mdl->cyl[0], l->ls.mdl->cyl[1], -1, -1};
    world_snap_reliefs(s, l->ls.mdl->hyd, l->ls.hd->comp_open, cyl_hyd);
}

static const engine_ops lagrange_ops = {
    .name = "lagrange",
    .ncol = SIM_NCOL_BASE,
    .destroy = lag_destroy,
    .set_commands = lag_set_commands,
    .hook = NULL, // no world, no hook
    .circuit = lag_circuit,
    .set_load = lag_set_load,
    .set_link = lag_set_link,
    .step = lag_step,
    .time = lag_time,
    .row = lag_row,
    .snapshot = lag_snapshot,
};
