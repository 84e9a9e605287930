// test_ode_validation.c: the ODE validation world against the analytic
// mechanics of docs/lagrange.md (equations written out here, independently of
// the ODE code): angle conventions, static equilibrium under the analytic
// holding torque G(q), free motion against H q'' + C + G = 0, energy
// conservation, and a hydraulic hold.
#include "check.h"

#include "model.h"
#include "ode_world.h"

#include <math.h>
#include <stdlib.h>

#define DEG (3.14159265358979323846 / 180.0)

static model* load_model(void) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    if (!m) fprintf(stderr, "model: %s\n", err);
    return m;
}

static const cJSON* hyd_json(const model* m) { return cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"); }

static ode_world* make(const model* m, const ode_world_opts* o) {
    char err[512] = "";
    world_desc d;
    world_desc_default(&d, WORLD_VALIDATION);
    ode_world* w = ode_world_create(&m->mech, hyd_json(m), &d, o, err, sizeof err);
    if (!w) fprintf(stderr, "create: %s\n", err);
    return w;
}

// docs/lagrange.md terms for links with inertia and a tip point mass m3.
typedef struct terms {
    double H[2][2], C[2], G[2];
} terms;

static void spec_terms(const crane_mech* me, double m3, const double q[2], const double qd[2], terms* t) {
    const crane_link *a = &me->link[0], *b = &me->link[1];
    double L1 = a->length, L2 = b->length, e1 = a->com, e2 = b->com, m1 = a->mass, m2 = b->mass;
    double I1 = a->inertia, I2 = b->inertia, g = me->gravity;
    double c2 = cos(q[1]), s2 = sin(q[1]);
    t->H[0][0] = I1 + I2 + m1 * e1 * e1 + m2 * (L1 * L1 + e2 * e2 + 2 * L1 * e2 * c2) + m3 * (L1 * L1 + L2 * L2 + 2 * L1 * L2 * c2);
    t->H[0][1] = t->H[1][0] = I2 + m2 * (e2 * e2 + L1 * e2 * c2) + m3 * (L2 * L2 + L1 * L2 * c2);
    t->H[1][1] = I2 + m2 * e2 * e2 + m3 * L2 * L2;
    double k = (m2 * e2 + m3 * L2) * L1 * s2;
    t->C[0] = -k * (2 * qd[0] * qd[1] + qd[1] * qd[1]);
    t->C[1] = k * qd[0] * qd[0];
    t->G[0] = (m1 * e1 + (m2 + m3) * L1) * g * sin(q[0]) + (m2 * e2 + m3 * L2) * g * sin(q[0] + q[1]);
    t->G[1] = (m2 * e2 + m3 * L2) * g * sin(q[0] + q[1]);
}

static void spec_rhs(const crane_mech* me, double m3, const double y[4], double f[4]) {
    terms t;
    spec_terms(me, m3, y, y + 2, &t);
    double r0 = -t.C[0] - t.G[0], r1 = -t.C[1] - t.G[1];
    double det = t.H[0][0] * t.H[1][1] - t.H[0][1] * t.H[1][0];
    f[0] = y[2];
    f[1] = y[3];
    f[2] = (t.H[1][1] * r0 - t.H[0][1] * r1) / det;
    f[3] = (-t.H[1][0] * r0 + t.H[0][0] * r1) / det;
}

static void rk4(const crane_mech* me, double m3, double* y, double h) {
    double k1[4], k2[4], k3[4], k4[4], t[4];
    spec_rhs(me, m3, y, k1);
    for (int i = 0; i < 4; ++i) t[i] = y[i] + 0.5 * h * k1[i];
    spec_rhs(me, m3, t, k2);
    for (int i = 0; i < 4; ++i) t[i] = y[i] + 0.5 * h * k2[i];
    spec_rhs(me, m3, t, k3);
    for (int i = 0; i < 4; ++i) t[i] = y[i] + h * k3[i];
    spec_rhs(me, m3, t, k4);
    for (int i = 0; i < 4; ++i) y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
}

// q, tip and stroke agree with the paper's kinematics at the start and after
// the booms have moved (the hinge angle sign and offsets are right).
static void test_conventions(void) {
    model* m = load_model();
    if (!m) { CHECK(0, "no model"); return; }
    ode_world_opts o = ode_world_default_opts();
    o.q0[0] = 100 * DEG;
    o.q0[1] = -100 * DEG;
    o.model_file = "hiab031.json";
    ode_world* w = make(m, &o);
    CHECK(w != NULL, "create");
    if (!w) { model_free(m); return; }
    ode_world_state s;
    ode_world_get_state(w, &s);
    CHECK_NEAR(s.q[0], o.q0[0], 1e-12);
    CHECK_NEAR(s.q[1], o.q0[1], 1e-12);
    double tx, tz;
    crane_tip(&m->mech, s.q[0], s.q[1], &tx, &tz);
    CHECK_NEAR(s.tip[0], tx, 1e-9);
    CHECK_NEAR(s.tip[1], tz, 1e-9);
    for (int k = 0; k < 2; ++k) CHECK_NEAR(s.x[k], crane_stroke(&m->mech.act[k], s.q[k]), 1e-9);

    // Lift the boom: a positive q1 rate must raise the tip and grow q1.
    double qd[2] = {0.2, -0.1};
    ode_world_set_commands(w, (double[3]){0.6, -0.4, 0});
    ode_world_set_joint_rates(w, qd);
    ode_world_get_state(w, &s);
    CHECK_NEAR(s.qd[0], 0.2, 1e-9);
    CHECK_NEAR(s.qd[1], -0.1, 1e-9);
    CHECK(ode_world_step(w, 0.5) == 0, "step: %s", ode_world_error(w));
    ode_world_get_state(w, &s);
    CHECK(fabs(s.q[0] - o.q0[0]) > 0.01, "q1 moved: %g", s.q[0] - o.q0[0]);
    crane_tip(&m->mech, s.q[0], s.q[1], &tx, &tz);
    CHECK_NEAR(s.tip[0], tx, 1e-6);
    CHECK_NEAR(s.tip[1], tz, 1e-6);
    for (int k = 0; k < 2; ++k) {
        double r;
        crane_pin_length(&m->mech.act[k], s.q[k], &r);
        CHECK_NEAR(s.x[k], crane_stroke(&m->mech.act[k], s.q[k]), 1e-6);
        // Stroke rate is dx/dq times the joint rate (paper Eq. 5); the bodies
        // carry a little constraint-velocity error, hence the looser tolerance.
        CHECK_NEAR(s.v[k], r * s.qd[k], 1e-5 + 1e-3 * fabs(s.v[k]));
    }
    ode_world_destroy(w);
    model_free(m);
}

// With the analytic holding torque G(q0) at the joints and no hydraulics the
// booms stay where they are; without it they fall.
static void test_equilibrium(void) {
    model* m = load_model();
    if (!m) { CHECK(0, "no model"); return; }
    static const double poses[3][2] = {{95, -110}, {130, -60}, {75, -140}};
    for (int p = 0; p < 3; ++p) {
        ode_world_opts o = ode_world_default_opts();
        o.hydraulics = 0;
        o.q0[0] = poses[p][0] * DEG;
        o.q0[1] = poses[p][1] * DEG;
        o.load_mass = 500;
        ode_world* w = make(m, &o);
        if (!w) { CHECK(0, "create"); continue; }
        terms t;
        double zero[2] = {0, 0};
        spec_terms(&m->mech, 500, o.q0, zero, &t);
        ode_world_set_joint_torques(w, t.G);
        CHECK(ode_world_step(w, 2.0) == 0, "step");
        ode_world_state s;
        ode_world_get_state(w, &s);
        CHECK_NEAR(s.q[0], o.q0[0], 1e-5);
        CHECK_NEAR(s.q[1], o.q0[1], 1e-5);
        ode_world_destroy(w);

        // Negative control: the same pose without the torque falls.
        w = make(m, &o);
        if (!w) continue;
        ode_world_step(w, 0.5);
        ode_world_get_state(w, &s);
        CHECK(fabs(s.q[0] - o.q0[0]) + fabs(s.q[1] - o.q0[1]) > 0.05, "unheld booms fall");
        ode_world_destroy(w);
    }
    model_free(m);
}

// Free motion (tau = 0) from rest against the docs/lagrange.md equations integrated with
// RK4 at a fine step: the ODE bodies are the same mechanical system.
static void test_free_motion_matches_spec(void) {
    model* m = load_model();
    if (!m) { CHECK(0, "no model"); return; }
    ode_world_opts o = ode_world_default_opts();
    o.hydraulics = 0;
    o.dt_ode = o.dt_hyd = 1e-4;
    o.q0[0] = 110 * DEG;
    o.q0[1] = -90 * DEG;
    o.load_mass = 300;
    ode_world* w = make(m, &o);
    if (!w) { CHECK(0, "create"); model_free(m); return; }
    double y[4] = {o.q0[0], o.q0[1], 0, 0};
    double maxdiff = 0;
    for (int i = 1; i <= 8; ++i) {
        ode_world_step(w, 0.1);
        for (int j = 0; j < 1000; ++j) rk4(&m->mech, 300, y, 1e-4);
        ode_world_state s;
        ode_world_get_state(w, &s);
        double d = fabs(s.q[0] - y[0]) + fabs(s.q[1] - y[1]);
        if (d > maxdiff) maxdiff = d;
    }
    // The booms swing by radians over 0.8 s; first-order ODE integration at
    // 0.1 ms stays within a few milliradians of the exact solution.
    CHECK(maxdiff < 5e-3, "max |q_ode - q_spec| = %g rad", maxdiff);
    ode_world_state s;
    ode_world_get_state(w, &s);
    CHECK(fabs(s.q[0] - o.q0[0]) > 0.3, "the booms did swing (%g rad)", s.q[0] - o.q0[0]);
    ode_world_destroy(w);
    model_free(m);
}

// With zero forces and no damping the mechanical energy is conserved to the
// accuracy of dWorldStep at 0.1 ms.
static void test_energy(void) {
    model* m = load_model();
    if (!m) { CHECK(0, "no model"); return; }
    ode_world_opts o = ode_world_default_opts();
    o.hydraulics = 0;
    o.dt_ode = o.dt_hyd = 1e-4;
    o.q0[0] = 120 * DEG;
    o.q0[1] = -70 * DEG;
    o.load_mass = 500;
    ode_world* w = make(m, &o);
    if (!w) { CHECK(0, "create"); model_free(m); return; }
    double e0 = ode_world_energy(w), emin = e0, emax = e0;
    // Potential energy swing of the motion, the scale to judge the error by.
    double pe_swing = 0;
    for (int i = 0; i < 500; ++i) {
        ode_world_step(w, 0.01);
        double e = ode_world_energy(w);
        if (e < emin) emin = e;
        if (e > emax) emax = e;
        ode_world_state s;
        ode_world_get_state(w, &s);
        terms t;
        double zero[2] = {0, 0};
        spec_terms(&m->mech, 500, s.q, zero, &t);
        double ke = 0.5 * (t.H[0][0] * s.qd[0] * s.qd[0] + 2 * t.H[0][1] * s.qd[0] * s.qd[1] + t.H[1][1] * s.qd[1] * s.qd[1]);
        if (ke > pe_swing) pe_swing = ke;
    }
    printf("  energy band %.3f J over 5 s; max kinetic energy %.1f J\n", emax - emin, pe_swing);
    CHECK(pe_swing > 1e3, "the system moved (max KE %g J)", pe_swing);
    CHECK((emax - emin) < 1e-3 * pe_swing, "energy band %g J vs max kinetic energy %g J", emax - emin, pe_swing);
    ode_world_destroy(w);
    model_free(m);
}

// The hydraulic circuit holds the crane still from the equilibrium start, and
// a lift command extends the lift cylinder.
static void test_hydraulic_hold_and_drive(void) {
    model* m = load_model();
    if (!m) { CHECK(0, "no model"); return; }
    ode_world_opts o = ode_world_default_opts();
    o.model_file = "hiab031.json";
    ode_world* w = make(m, &o);
    if (!w) { CHECK(0, "create"); model_free(m); return; }
    ode_world_state s0, s;
    ode_world_get_state(w, &s0);
    CHECK(ode_world_step(w, 2.0) == 0, "step: %s", ode_world_error(w));
    ode_world_get_state(w, &s);
    CHECK(fabs(s.q[0] - s0.q[0]) < 2e-3 && fabs(s.q[1] - s0.q[1]) < 2e-3, "held: dq = %g, %g rad",
          s.q[0] - s0.q[0], s.q[1] - s0.q[1]);
    CHECK(s.pA[0] > 1e6 && s.pA[0] < 25e6, "lift holding pressure %g Pa", s.pA[0]);
    ode_world_set_commands(w, (double[3]){0.5, 0, 0});
    CHECK(ode_world_step(w, 2.0) == 0, "step: %s", ode_world_error(w));
    ode_world_get_state(w, &s);
    CHECK(s.x[0] - s0.x[0] > 0.02, "lift extended by %g m", s.x[0] - s0.x[0]);
    CHECK(s.v[0] > 0.005, "lift extending at %g m/s", s.v[0]);
    ode_world_destroy(w);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_conventions);
    RUN_TEST(test_equilibrium);
    RUN_TEST(test_free_motion_matches_spec);
    RUN_TEST(test_energy);
    RUN_TEST(test_hydraulic_hold_and_drive);
    TEST_MAIN_END();
}
