// test_ode_failures.c: ODE's own failures (a failed internal check, which
// aborts the process by default) become a failed step or a refused world,
// never SIGABRT. Inputs bypass the loaders on purpose (their ranges refuse
// them up front; this is the safety net behind).
//
// A world ODE failed in is dead: what ODE left half done (queued step jobs,
// a space still locked by the collision pass, step arenas) cannot be torn
// down through ODE's API without failing its checks again, so it is
// abandoned, once per failure. This program therefore runs without leak
// detection (tests/world/CMakeLists.txt); every other test keeps it.
#include "check.h"

#include "model.h"
#include "ode_chain.h"
#include "ode_world.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "world_fixture.h"

// The end arm's state after n ODE steps of the validation world at rest
// (valves closed): a fingerprint to compare runs by.
static void healthy_run(int n, double out[4]) {
    char err[512] = "";
    ode_world* w = make(&g_model->mech, NULL, err, sizeof err);
    CHECK(w != NULL, "create: %s", err);
    if (!w) return;
    const double u[3] = {0.5, -0.3, 0};
    ode_world_set_commands(w, u);
    CHECK(ode_world_step(w, n * ode_world_dt(w)) == 0, "%s", ode_world_error(w));
    ode_world_state s;
    ode_world_get_state(w, &s);
    out[0] = s.q[0], out[1] = s.q[1], out[2] = s.pA[0], out[3] = s.pB[1];
    ode_world_destroy(w);
}

// A 1e-300 kg end arm: ODE's quaternion normalisation fails its own check
// inside the first step (dxNormalize4). ODE's default handler aborts the
// process; the world's handler turns it into a failed step with a message,
// the world is dead, and the next world of the same process runs as if
// nothing had happened (its step jobs are its own).
static void test_ode_error_in_step(void) {
    double before[4], after[4];
    healthy_run(50, before);
    crane_mech me = g_model->mech;
    me.link[1].mass = 1e-300;
    char err[512] = "";
    ode_world* w = make(&me, NULL, err, sizeof err);
    CHECK(w != NULL, "create: %s", err);
    if (!w) return;
    int rc = 0;
    for (int i = 0; i < 100 && rc == 0; ++i) rc = ode_world_step(w, ode_world_dt(w));
    CHECK(rc == -1, "a 1e-300 kg link should fail the step");
    CHECK(strstr(ode_world_error(w), "ODE failed") && strstr(ode_world_error(w), "t = "), "%s",
          ode_world_error(w));
    // Dead: every further call answers without touching ODE.
    CHECK(ode_world_step(w, ode_world_dt(w)) == -1, "a dead world must stay stopped");
    ode_world_state s;
    ode_world_get_state(w, &s);
    CHECK(s.t == ode_world_time(w), "state time %g", s.t);
    CHECK(ode_world_hook(w, 1) == -1, "hook on a dead world");
    ode_world_destroy(w);
    healthy_run(50, after);
    for (int k = 0; k < 4; ++k) CHECK(before[k] == after[k], "k %d: %.17g then %.17g", k, before[k], after[k]);
}

// Sandbox worlds ODE cannot step or build: a 1e308 kg truck (dxNormalize4
// in the step), a 1e308 m load (dCollideHeightfield), a truck 1e30 m out
// (dxNormalize3 while the rope is laid, inside ode_world_create).
static void test_ode_error_sandbox(void) {
    static world_desc d;
    if (load_sandbox(&d)) {
        CHECK(0, "sandbox world");
        return;
    }
    static world_desc a, b, c;
    a = d, b = d, c = d;
    a.truck.mass = 1e308;
    b.load[0].size[0] = 1e308;
    c.truck.position[0] = 1e30, c.truck.position[1] = 1e30;
    c.slew.column_radius = 5;
    const world_desc* const cases[2] = {&a, &b};
    for (int i = 0; i < 2; ++i) {
        char err[512] = "";
        ode_world* w = make(&g_model->mech, cases[i], err, sizeof err);
        if (!w) {
            CHECK(strstr(err, "ODE failed") != NULL, "case %d: %s", i, err);
            continue;
        }
        int rc = 0;
        for (int k = 0; k < 200 && rc == 0; ++k) rc = ode_world_step(w, ode_world_dt(w));
        CHECK(rc == -1, "case %d should fail", i);
        CHECK(strstr(ode_world_error(w), "ODE failed") || strstr(ode_world_error(w), "non-finite"), "case %d: %s",
              i, ode_world_error(w));
        ode_world_destroy(w);
    }
    char err[512] = "";
    ode_world* w = make(&g_model->mech, &c, err, sizeof err);
    CHECK(w == NULL && strstr(err, "ODE failed while building"), "far truck: %s", err);
    ode_world_destroy(w);
    world_desc_free(&d);
}

// The sandbox with a chain crane (ode_world_opts.chain, the chain hosted in
// the world) whose truck ODE cannot step (1e308 kg): the step fails, and
// the dead world's state is read without asking ODE about the chain's
// bodies again (its hosted chain is marked dead with the world).
static void test_ode_error_sandbox_chain(void) {
    char err[512] = "";
    model* m = model_load(CRANESIM_TESTDATA "/chain_3boom_ext.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "model: %s", err);
    static world_desc d;
    if (!m || load_sandbox(&d)) {
        CHECK(0, "model or sandbox world");
        model_free(m);
        return;
    }
    d.truck.mass = 1e308;
    ode_world_opts o = ode_world_default_opts();
    o.model_file = "chain_3boom_ext.json";
    o.q0[0] = 155 * PI / 180, o.q0[1] = -95 * PI / 180;
    o.circuit = m->hyd;
    o.chain = &m->chain;
    ode_world* w = ode_world_create(&m->mech, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"), &d, &o, err,
                                    sizeof err);
    if (!w) {
        CHECK(strstr(err, "ODE failed") != NULL, "create: %s", err);
    } else {
        CHECK(ode_world_chain(w) != NULL, "the crane is not the chain");
        int rc = 0;
        for (int k = 0; k < 200 && rc == 0; ++k) rc = ode_world_step(w, ode_world_dt(w));
        CHECK(rc == -1, "a 1e308 kg truck should fail the step");
        printf("  %s\n", ode_world_error(w));
        CHECK(strstr(ode_world_error(w), "ODE failed") || strstr(ode_world_error(w), "non-finite"), "%s",
              ode_world_error(w));
        ode_world_state s;
        ode_world_get_state(w, &s);
        CHECK(s.t == ode_world_time(w), "state time %g", s.t);
        CHECK(ode_world_step(w, ode_world_dt(w)) == -1, "a dead world must stay stopped");
        // The chain's readers answer NaN: its bodies are not asked.
        double x = 0, tip[3] = {0, 0, 0};
        ode_chain_slew_state(ode_world_chain(w), &x, NULL, NULL, NULL, NULL, NULL);
        ode_chain_tip(ode_world_chain(w), tip, NULL);
        CHECK(isnan(x) && isnan(tip[0]), "the dead chain read its bodies: slew rack %g m, tip x %g m", x, tip[0]);
        ode_world_destroy(w);
    }
    d.truck.mass = 6500;
    world_desc_free(&d);
    model_free(m);
}

int main(int argc, char** argv) {
    char err[512];
    g_model = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    if (!g_model) {
        fprintf(stderr, "model: %s\n", err);
        return 1;
    }
    RUN_TEST(test_ode_error_in_step);
    RUN_TEST(test_ode_error_sandbox);
    RUN_TEST(test_ode_error_sandbox_chain);
    model_free(g_model);
    TEST_MAIN_END();
}
