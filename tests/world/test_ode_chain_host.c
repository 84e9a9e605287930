// test_ode_chain_host.c: the chain world (ode_chain.h) hosted in a world
// it does not own (opts.host_world: the sandbox's way of building a chain
// crane on its truck) against the same chain in its own validation world:
// - the rigid 3-boom + extension chain on a slewing column, no hydraulics,
//   given joint forces, hosted on a kinematic base body at the origin: the
//   same joint motion to 1e-9 (on one moved and turned about z, to the
//   round-off the swinging chain amplifies);
// - the default crane in its chain form with its circuit and the model's
//   slew drive (the rack on the column's hinge), every function commanded:
//   the same strokes, slew and pressures, hosted or not; the rack's stroke is
//   r slew + s/2 and its end stops hold the column;
// - refusals: a hosted chain is not stepped by ode_chain_step, a slew drive
//   needs the circuit.
#include "check.h"

#include "crane_chain.h"
#include "model.h"
#include "ode_chain.h"
#include "ode_world_internal.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DATA CRANESIM_TESTDATA
#define PI 3.14159265358979323846

// A host: a world of its own with a kinematic base body (a truck that does
// not move) at pos, turned by yaw about z.
typedef struct host {
    dWorldID world;
    dThreadingImplementationID thr;
    dBodyID base;
    double R[9], p[3];
} host;

static void host_make(host* h, double g, double yaw, const double pos[3]) {
    ow_ode_acquire();
    h->world = ow_world_new(g, 0.2, 1e-10, &h->thr);
    dWorldSetAutoDisableFlag(h->world, 0);
    h->base = dBodyCreate(h->world);
    dBodySetKinematic(h->base);
    dBodySetPosition(h->base, pos[0], pos[1], pos[2] - 0.3); // its centre below the column foot
    dMatrix3 M;
    dRFromAxisAndAngle(M, 0, 0, 1, yaw);
    dBodySetRotation(h->base, M);
    ow_rot_z(yaw, h->R);
    memcpy(h->p, pos, sizeof h->p);
}

static void host_free(host* h) {
    dWorldSetStepThreadingImplementation(h->world, NULL, NULL);
    dWorldDestroy(h->world);
    if (h->thr) dThreadingFreeImplementation(h->thr);
    ow_ode_release();
}

static int host_step(host* h, ode_chain* w, double H) {
    if (ode_chain_host_pre(w)) return -1;
    dWorldStep(h->world, H);
    return ode_chain_host_post(w);
}

static void hosted_opts(ode_chain_opts* o, host* h) {
    o->host_world = h->world;
    o->host_base = h->base;
    memcpy(o->base_pos, h->p, sizeof o->base_pos);
    memcpy(o->base_rot, h->R, sizeof o->base_rot);
}

// ---- 1. the rigid chain ----

static double rigid_compare(double yaw, const double pos[3], double* moved, double* worst_1s) {
    char err[512] = "";
    model* m = model_load(DATA "/chain_3boom_ext.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "model: %s", err);
    if (!m) return INFINITY;
    crane_chain cc;
    CHECK(crane_chain_copy(&cc, &m->chain) == 0, "copy");
    cc.slew_free = true;
    const int n = crane_chain_ndof(&cc);
    double* q0 = calloc((size_t)n, sizeof *q0);
    double* q = calloc((size_t)n, sizeof *q);
    double* qh = calloc((size_t)n, sizeof *qh);
    double* tau = calloc((size_t)n, sizeof *tau);
    const double q12[2] = {100 * PI / 180, -110 * PI / 180};
    crane_chain_start_pose(&cc, q12, 0.2, q0);
    ode_chain_opts o = ode_chain_default_opts();
    o.q0 = q0;
    o.slew0 = 0.2;
    o.tip_mass = 100;
    o.model_file = "chain_3boom_ext.json";
    ode_chain* wv = ode_chain_create(&cc, &o, err, sizeof err);
    CHECK(wv != NULL, "validation: %s", err);
    host h;
    host_make(&h, cc.gravity, yaw, pos);
    hosted_opts(&o, &h);
    ode_chain* wh = ode_chain_create(&cc, &o, err, sizeof err);
    CHECK(wh != NULL, "hosted: %s", err);
    double worst = 0.0;
    *moved = 0.0;
    *worst_1s = 0.0;
    if (wv && wh) {
        CHECK(ode_chain_ndof(wv) == n && ode_chain_ndof(wh) == n, "ndof %d %d %d", n, ode_chain_ndof(wv),
              ode_chain_ndof(wh));
        // The tip in the world: the base's pose applied to the validation one.
        double tv[3], th[3];
        ode_chain_tip(wv, tv, NULL);
        ode_chain_tip(wh, th, NULL);
        for (int i = 0; i < 3; ++i) {
            double x = h.p[i];
            for (int k = 0; k < 3; ++k) x += h.R[3 * i + k] * tv[k];
            CHECK_NEAR(th[i], x, 1e-12);
        }
        const double H = 1e-3;
        for (long s = 0; s < 2000; ++s) {
            // Joint forces that swing every joint (the slew by 0.3 rad).
            for (int k = 0; k < n; ++k) tau[k] = (k == 0 ? 3000.0 : 2e4 / (1 + k)) * sin(2 * PI * (0.7 + 0.3 * k) * s * H);
            ode_chain_set_joint_forces(wv, tau);
            ode_chain_set_joint_forces(wh, tau);
            const int a = ode_chain_step(wv, H), b = host_step(&h, wh, H);
            CHECK(a == 0 && b == 0, "step %ld: %s / %s", s, ode_chain_error(wv), ode_chain_error(wh));
            if (a || b) break;
            ode_chain_q(wv, q, NULL);
            ode_chain_q(wh, qh, NULL);
            for (int k = 0; k < n; ++k) {
                worst = fmax(worst, fabs(q[k] - qh[k]));
                *moved = fmax(*moved, fabs(q[k] - q0[k]));
            }
            if (s < 1000) *worst_1s = worst;
        }
    }
    ode_chain_destroy(wh);
    ode_chain_destroy(wv);
    host_free(&h);
    free(q0), free(q), free(qh), free(tau);
    crane_chain_free(&cc);
    model_free(m);
    return worst;
}

static void test_host_rigid(void) {
    const double o[3] = {0, 0, 0}, p[3] = {3.0, -2.0, 1.2};
    double moved, d0_1s, d1_1s;
    const double d0 = rigid_compare(0.0, o, &moved, &d0_1s);
    printf("  rigid, base at the origin: max |q - q_hosted| = %.3g over 2 s (joints moved up to %.3g)\n", d0, moved);
    CHECK(moved > 0.05, "the joints barely moved: %g", moved);
    CHECK(d0 <= 1e-9, "hosted at the origin differs by %g", d0);
    const double d1 = rigid_compare(0.7, p, &moved, &d1_1s);
    printf("  rigid, base moved and turned: max |q - q_hosted| = %.3g over 1 s, %.3g over 2 s\n", d1_1s, d1);
    // Moved and turned, every body coordinate carries other round-off
    // (1e-16 of a 3 m position) and the free chain, swinging by a radian
    // and striking its joint stops, amplifies it (measured: 3e-15 rad at
    // 0.2 s, 1.2e-12 at 1 s, 1e-9 at 1.6 s, 7.3e-8 at 2 s, growing tenfold
    // every 0.2 s): 1e-9 over the first second, 1e-6 over two. The
    // circuit-driven crane below, on a moved base, agrees to 2e-13. A wrong
    // pose transform would be off by the base's offset, metres.
    CHECK(d1_1s <= 1e-9, "hosted on a moved base differs by %g in the first second", d1_1s);
    CHECK(d1 <= 1e-6, "hosted on a moved base differs by %g", d1);
}

// ---- 2. the default crane's chain with its circuit and slew drive ----

static hyd_model* slew_circuit(const model* m, char* err, size_t errsz) {
    const cJSON* hy = cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics");
    const cJSON* sl = cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics_slew");
    return model_circuit_with_fragment(hy, m->file, sl, m->file, "hydraulics_slew", err, errsz);
}

static void test_host_slew_circuit(void) {
    char err[512] = "";
    model* m = model_load(DATA "/hiab031_chain.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "model: %s", err);
    if (!m) return;
    hyd_model* hv = slew_circuit(m, err, sizeof err);
    CHECK(hv != NULL, "circuit: %s", err);
    hyd_model* hh = slew_circuit(m, err, sizeof err);
    if (!hv || !hh) {
        model_free(m);
        return;
    }
    crane_chain cc;
    CHECK(crane_chain_copy(&cc, &m->chain) == 0, "copy");
    cc.slew_free = true;
    double q0[3];
    const double q12[2] = {100 * PI / 180, -110 * PI / 180};
    crane_chain_start_pose(&cc, q12, 0.0, q0);
    ode_chain_opts o = ode_chain_default_opts();
    o.q0 = q0;
    o.slew_drive = 1;
    o.model_file = m->file;
    o.circuit = hv;
    ode_chain* wv = ode_chain_create(&cc, &o, err, sizeof err);
    CHECK(wv != NULL, "validation: %s", err);
    host h;
    const double p[3] = {1.0, 0.5, 1.1};
    host_make(&h, cc.gravity, -0.4, p);
    hosted_opts(&o, &h);
    o.circuit = hh;
    ode_chain* wh = ode_chain_create(&cc, &o, err, sizeof err);
    CHECK(wh != NULL, "hosted: %s", err);
    if (wv && wh) {
        const double r = cc.slew.pinion_radius;
        double x, v, F, pA, pB, S = 0.6; // hydraulics_slew's slew_cyl stroke [m]
        int stop;
        CHECK(ode_chain_slew_state(wv, &x, &v, &F, &pA, &pB, &stop) == 0, "slew state");
        CHECK_NEAR(x, 0.5 * S, 1e-12); // slew 0: mid-stroke
        double worst_q = 0, worst_x = 0, worst_p = 0, slew_max = 0, rack_err = 0;
        int at_end = 0;
        const double H = 1e-3, u_fn[2] = {0.6, -0.5};
        for (long s = 0; s < 9000; ++s) {
            const double t = s * H;
            const double u[2] = {t < 3 ? u_fn[0] : 0, t < 3 ? u_fn[1] : 0};
            ode_chain_set_commands(wv, u);
            ode_chain_set_commands(wh, u);
            // The slew runs out to its rack's end (+-S/(2r) = 3 rad) and back.
            const double us = t < 6.0 ? 1.0 : -1.0;
            ode_chain_set_slew_command(wv, us);
            ode_chain_set_slew_command(wh, us);
            const int a = ode_chain_step(wv, H), b = host_step(&h, wh, H);
            CHECK(a == 0 && b == 0, "step %ld: %s / %s", s, ode_chain_error(wv), ode_chain_error(wh));
            if (a || b) break;
            double qv[3], qh[3];
            ode_chain_q(wv, qv, NULL);
            ode_chain_q(wh, qh, NULL);
            for (int k = 0; k < 3; ++k) worst_q = fmax(worst_q, fabs(qv[k] - qh[k]));
            for (int k = 0; k < 2; ++k) {
                double pav, pah;
                worst_x = fmax(worst_x, fabs(ode_chain_act_length(wv, k, NULL) - ode_chain_act_length(wh, k, NULL)));
                ode_chain_act_force(wv, k, &pav, NULL);
                ode_chain_act_force(wh, k, &pah, NULL);
                worst_p = fmax(worst_p, fabs(pav - pah));
            }
            double xh, pAh;
            ode_chain_slew_state(wv, &x, &v, &F, &pA, &pB, &stop);
            ode_chain_slew_state(wh, &xh, NULL, NULL, &pAh, NULL, NULL);
            worst_x = fmax(worst_x, fabs(x - xh));
            worst_p = fmax(worst_p, fabs(pA - pAh));
            rack_err = fmax(rack_err, fabs(x - (r * qv[0] + 0.5 * S)));
            slew_max = fmax(slew_max, qv[0]);
            at_end |= stop;
        }
        printf("  slew drive: hosted vs own world: q %.3g, strokes %.3g m, pressures %.3g Pa; slew up to %.4f rad "
               "(rack end %.4f rad)\n",
               worst_q, worst_x, worst_p, slew_max, 0.5 * S / r);
        CHECK(worst_q <= 1e-9, "joint coordinates differ by %g", worst_q);
        CHECK(worst_x <= 1e-9, "strokes differ by %g m", worst_x);
        CHECK(worst_p <= 1e-9 * 2.5e7, "pressures differ by %g Pa", worst_p);
        CHECK(rack_err < 1e-12, "rack stroke is not r slew + s/2: %g m off", rack_err);
        CHECK(at_end, "the rack never reached its end");
        // The hinge stop at +S/(2r); ODE's stop is soft by its ERP/CFM.
        CHECK(slew_max > 0.5 * S / r - 0.01 && slew_max < 0.5 * S / r + 0.01, "slew peak %g, rack end %g", slew_max,
              0.5 * S / r);
    }
    ode_chain_destroy(wh);
    ode_chain_destroy(wv);
    host_free(&h);
    crane_chain_free(&cc);
    hyd_model_free(hv);
    hyd_model_free(hh);
    model_free(m);
}

// ---- 3. refusals ----

static void test_host_refusals(void) {
    char err[512] = "";
    model* m = model_load(DATA "/hiab031_chain.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "model: %s", err);
    if (!m) return;
    ode_chain_opts o = ode_chain_default_opts();
    o.slew_drive = 1;
    ode_chain* w = ode_chain_create(&m->chain, &o, err, sizeof err);
    CHECK(w == NULL && strstr(err, "slew drive needs the circuit"), "slew drive without a circuit: %s", err);
    ode_chain_destroy(w);
    host h;
    const double p[3] = {0, 0, 1};
    host_make(&h, 9.81, 0.0, p);
    o = ode_chain_default_opts();
    hosted_opts(&o, &h);
    w = ode_chain_create(&m->chain, &o, err, sizeof err);
    CHECK(w != NULL, "hosted: %s", err);
    if (w) {
        CHECK(ode_chain_step(w, 1e-3) == -1 && strstr(ode_chain_error(w), "hosted"), "stepped a hosted chain: %s",
              ode_chain_error(w));
        CHECK(ode_chain_body_id(w, 0, NULL) != NULL, "the column is a body when hosted on a base");
    }
    ode_chain_destroy(w);
    host_free(&h);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_host_rigid);
    RUN_TEST(test_host_slew_circuit);
    RUN_TEST(test_host_refusals);
    TEST_MAIN_END();
}
