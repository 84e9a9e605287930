// live.c: the lagrange crane stepped by a real-time loop.
#include "live.h"

#include "ode_world.h"
#include "snap_reliefs.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

struct live {
    ode_world* ode; ///< the ode backend, or NULL for lagrange
    lsim ls;
    hyd_problem prob;
    hyd_solver* solver;
    sim_opts o;
    double t;
    double y[LSIM_MAX_STATES];
    char err[512];
    sim_checks chk; ///< the run checks every driver applies (sim.h)
    bool failed;    ///< a check or the solver failed: the crane stays stopped
};

live* live_create_lagrange(const model* m, const sim_opts* o, const double q0[2], double m3, char* err,
                           size_t errsz) {
    live* l = calloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    l->o = *o;
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
    live_row(l, row0);
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
        live_destroy(l);
        return NULL;
    }
    return l;
}

live* live_create_ode(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                      size_t errsz) {
    live* l = calloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    l->o = *o;
    l->ode = sim_ode_world_create(m, o, "sandbox", q0, slew0, m3, err, errsz);
    if (!l->ode) {
        free(l);
        return NULL;
    }
    // The hydraulic sub-step is min(--dt, ODE step), as sim_ode_world_create sets it.
    const double dt = ode_world_dt(l->ode), h = o->h < dt ? o->h : dt;
    double row0[SIM_NCOL];
    sim_ode_row(l->ode, row0);
    if (sim_check_fixed_step(ode_world_circuit(l->ode), o, h, 0.0, err, errsz) ||
        sim_check_start(ode_world_circuit(l->ode), row0, SIM_NCOL, m3, err, errsz)) {
        ode_world_destroy(l->ode);
        free(l);
        return NULL;
    }
    return l;
}

live* live_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                  size_t errsz) {
    return o->mechanics == SIM_ODE ? live_create_ode(m, o, q0, slew0, m3, err, errsz)
                                   : live_create_lagrange(m, o, q0, m3, err, errsz);
}

void live_destroy(live* l) {
    if (!l) return;
    if (l->ode) ode_world_destroy(l->ode);
    hyd_solver_destroy(l->solver);
    if (!l->ode) lsim_free(&l->ls);
    free(l);
}

int live_hook(live* l, int attach) { return l->ode ? ode_world_hook(l->ode, attach) : -1; }

const char* live_load_name(const live* l, int i, double* mass) {
    return l->ode ? ode_world_load_name(l->ode, i, mass) : NULL;
}

bool live_attached(const live* l) {
    if (!l->ode) return false;
    ode_world_state st;
    ode_world_get_state(l->ode, &st);
    return st.attached >= 0;
}

hyd_model* live_circuit(live* l) { return l->ode ? ode_world_circuit(l->ode) : l->ls.mdl->hyd; }

void live_set_load(live* l, double m3) {
    if (l->ode || l->ls.m3 == m3) return;
    l->ls.m3 = m3;
    lagrange_consts_init(&l->ls.mdl->mech, l->ls.variant, m3, &l->ls.lk);
    hyd_solver_inputs_changed(l->solver); // f changed at the same (t, y)
}

int live_set_link(live* l, int k, const crane_link* ln) {
    if (l->ode) return ode_world_set_link_mass(l->ode, k, ln) ? 1 : 0;
    // The lagrange crane reads the model's links (ln is one of them, edited
    // by the caller); the constants its fast kernels made from them at start
    // are made again.
    (void)ln;
    lagrange_consts_init(&l->ls.mdl->mech, l->ls.variant, l->ls.m3, &l->ls.lk);
    hyd_solver_inputs_changed(l->solver); // f changed at the same (t, y)
    return 0;
}

int live_ncol(const live* l) { return l->ode ? SIM_NCOL : SIM_NCOL_BASE; }

void live_set_commands(live* l, const double u[3]) {
    if (l->ode) {
        ode_world_set_commands(l->ode, u);
        return;
    }
    for (int k = 0; k < 2; ++k) {
        double v = u[k] < -1 ? -1 : u[k] > 1 ? 1 : u[k];
        // A command change is a kink in the input: adaptive methods restart
        // their step-size history there (decision 8).
        if (v != l->ls.u_cmd[k] && hyd_method_is_adaptive(l->o.solver)) hyd_solver_reset(l->solver);
        l->ls.u_cmd[k] = v;
    }
}

static int advance(live* l, double dt) {
    if (l->ode) {
        if (ode_world_step(l->ode, dt) == 0) return 0;
        snprintf(l->err, sizeof l->err, "%s", ode_world_error(l->ode));
        return 1;
    }
    int rc = hyd_solver_advance(l->solver, &l->t, l->y, l->t + dt);
    if (rc == HYD_OK) return 0;
    double tb = l->t;
    int i = hyd_solver_bad_state(l->solver, &tb);
    snprintf(l->err, sizeof l->err, "solver %s failed (code %d) at t = %.6g s, state %d", hyd_method_name(l->o.solver),
             rc, tb, i);
    return 1;
}

int live_advance(live* l, double dt) {
    if (l->failed) return 1;
    if (advance(l, dt)) {
        l->failed = true;
        return 1;
    }
    // The same checks as run's, on the row the loop records and shows: a
    // drive that exits 0 while recording -26 MPa absolute is a wrong result
    // passing as valid.
    double row[SIM_NCOL];
    live_row(l, row);
    char what[200];
    const int rc = sim_check_row(&l->chk, row, live_ncol(l), what, sizeof what);
    if (!rc) return 0;
    const bool adaptive = hyd_method_is_adaptive(l->o.solver);
    snprintf(l->err, sizeof l->err, "numerical blow-up: %s (solver %s): %s", what, hyd_method_name(l->o.solver),
             sim_blowup_hint(adaptive, row[COL_T], l->chk.bad_value));
    l->failed = true;
    return 1;
}

void live_note(const live* l, char* note, size_t n) {
    sim_checks_note(&l->chk, hyd_method_is_adaptive(l->o.solver), note, n);
}

const char* live_error(const live* l) { return l->err; }
double live_time(const live* l) { return l->ode ? ode_world_time(l->ode) : l->t; }
void live_row(live* l, double row[SIM_NCOL]) {
    if (l->ode) {
        sim_ode_row(l->ode, row);
        return;
    }
    lsim_out o;
    lsim_outputs(&l->ls, l->t, l->y, &o);
    double v[SIM_NCOL] = {
        l->t, o.x[0], o.x[1], o.pA[0], o.pB[0], o.pA[1], o.pB[1], o.u[0], o.u[1], o.q[0], o.q[1],
        o.tip[0], o.tip[1], o.F[0], o.F[1], o.u_cmd[0], o.u_cmd[1],
        o.v[0], o.v[1], o.p_pump, o.relief_open, o.end_stop};
    memcpy(row, v, sizeof v);
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

void live_snapshot(live* l, world_snapshot* s) {
    if (l->ode) {
        ode_world_snapshot(l->ode, s);
        return;
    }
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
