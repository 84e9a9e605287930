// test_engine_backend.c: the backend table (engine_backend.h) against the
// backends themselves, and a sim_opts.mechanics value that names no backend:
// refused by every entry of the engine (issue 26: an unknown backend is an
// error, never an `else` that runs another).
#include "check.h"
#include "crane_fixture.h"
#include "engine.h"
#include "engine_impl.h"
#include "world_desc.h"

#include <stdio.h>
#include <string.h>

// Each row is found by its name and its id, and says what its
// implementation says of itself (engine_describe, engine_ops).
static void test_table_matches_backends(void) {
    const int n = engine_backend_count();
    CHECK(n >= 2, "%d backends", n);
    char names[256];
    engine_backend_names(names, sizeof names, NULL);
    size_t len = 0;
    for (int i = 0; i < n; ++i) {
        const engine_backend* b = engine_backend_at(i);
        CHECK(b && b->name && b->ops, "row %d", i);
        if (!b || !b->name || !b->ops) continue;
        CHECK(engine_backend_find(b->name) == b, "%s by name", b->name);
        CHECK(engine_backend_by_id((int)b->id) == b, "%s by id %d", b->name, (int)b->id);
        CHECK(!strcmp(b->ops->name, b->name), "row %s, ops %s", b->name, b->ops->name);
        // A world: a world for scripted runs and one for drivers; none without.
        CHECK(b->world == (b->run_world != NULL) && b->world == (b->drive_world != NULL), "%s: worlds", b->name);
        CHECK(b->drive_scenario && b->step_name && b->help && b->crane, "%s: texts", b->name);
        sim_opts o = sim_default_opts();
        o.mechanics = b->id;
        CHECK(engine_backend_of(&o) == b, "%s", b->name);
        engine_desc d;
        engine_describe(&o, &d);
        CHECK(!strcmp(d.backend, b->name), "describe says %s for %s", d.backend, b->name);
        // The world the engine runs when none is named is the table's.
        CHECK(b->world ? !strcmp(d.world, b->run_world) : !d.world[0], "%s: world '%s'", b->name, d.world);
        // Rows at whole outer steps where the table names one.
        CHECK((d.dt_outer > 0) == (b->outer_step_opt != NULL), "%s: dt_outer %g", b->name, d.dt_outer);
        CHECK(!strcmp(d.step_name, b->step_name), "%s: step '%s' vs '%s'", b->name, d.step_name, b->step_name);
        // Listed once, in order.
        CHECK(strstr(names, b->name) != NULL, "%s not in '%s'", b->name, names);
        len += strlen(b->name) + (i ? 2 : 0);
        for (int j = 0; j < i; ++j) CHECK(strcmp(engine_backend_at(j)->name, b->name), "%s twice", b->name);
    }
    CHECK(strlen(names) == len, "names '%s'", names);
    CHECK(engine_backend_at(-1) == NULL && engine_backend_at(n) == NULL, "rows beyond the table");
    const sim_opts d = sim_default_opts();
    CHECK(engine_backend_default() == engine_backend_of(&d), "default");
    const engine_backend* w = engine_backend_with_world();
    CHECK(w && w->world, "a backend with a world");
}

// The defaults a row names exist, and fit each other: its worlds load, and
// the scenario drive plays by default needs no hook where its drive world
// (or the lack of one) has none.
static void test_defaults_exist(void) {
    for (int i = 0; i < engine_backend_count(); ++i) {
        const engine_backend* b = engine_backend_at(i);
        char path[512], err[512];
        scenario sc;
        snprintf(path, sizeof path, "%s/scenarios/%s.json", CRANESIM_ASSETS, b->drive_scenario);
        const int sc_rc = scenario_load(path, &sc, err, sizeof err);
        CHECK(sc_rc == 0, "%s: drive_scenario: %s", b->name, err);
        int drive_kind = -1;
        const char* worlds[2] = {b->run_world, b->drive_world};
        for (int k = 0; k < 2; ++k) {
            if (!worlds[k]) continue;
            world_desc wd;
            snprintf(path, sizeof path, "%s/worlds/%s.json", CRANESIM_ASSETS, worlds[k]);
            const int rc = world_desc_load(path, &wd, err, sizeof err);
            CHECK(rc == 0, "%s: %s: %s", b->name, worlds[k], err);
            if (rc) continue;
            if (k == 1) drive_kind = (int)wd.kind;
            world_desc_free(&wd);
        }
        if (sc_rc == 0)
            CHECK(sc.nevent == 0 || drive_kind == WORLD_SANDBOX, "%s: %s works the hook, its drive world has none",
                  b->name, b->drive_scenario);
    }
}

// An unknown name: refused with the known ones listed, the options untouched.
static void test_unknown_name_refused(void) {
    CHECK(engine_backend_find("foo") == NULL && engine_backend_find("") == NULL && engine_backend_find(NULL) == NULL,
          "found");
    CHECK(engine_backend_find("ODE") == NULL, "names are exact");
    sim_opts o = sim_default_opts();
    const sim_mechanics before = o.mechanics;
    char err[256], names[128], want[256];
    CHECK(engine_backend_select(&o, "foo", err, sizeof err) == -1, "selected foo");
    snprintf(want, sizeof want, "unknown backend 'foo' (known: %s)", engine_backend_names(names, sizeof names, NULL));
    CHECK(!strcmp(err, want), "'%s' vs '%s'", err, want);
    CHECK(o.mechanics == before, "options changed");
    for (int i = 0; i < engine_backend_count(); ++i) {
        const engine_backend* b = engine_backend_at(i);
        CHECK(engine_backend_select(&o, b->name, err, sizeof err) == 0 && engine_backend_of(&o) == b, "%s",
              b->name);
    }
}

// A value of sim_opts.mechanics that is no row (a cast, a corrupt session):
// every entry refuses it in words; none runs a backend.
static void test_unknown_id_refused(void) {
    const int bad[] = {-1, engine_backend_count(), 99};
    scenario sc;
    model* m = load_crane("ramp", &sc);
    if (!m) return;
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        CHECK(engine_backend_by_id(bad[k]) == NULL, "id %d", bad[k]);
        sim_opts o = sim_default_opts();
        o.mechanics = (sim_mechanics)bad[k];
        o.duration = 0.01;
        CHECK(engine_backend_of(&o) == NULL, "id %d", bad[k]);
        char err[512] = "";
        const double q0[2] = {0.3, -0.5};
        engine* e = engine_create(m, &o, q0, 0.0, 0.0, err, sizeof err);
        CHECK(!e && strstr(err, "names no backend"), "create %d: %s", bad[k], err);
        engine_destroy(e);
        sim_result r;
        memset(&r, 0, sizeof r);
        engine_sink sink = {.t_end = 0.01};
        CHECK(engine_run(m, &sc, &o, &sink, &r) == SIM_REFUSED && r.status == SIM_REFUSED &&
                  strstr(r.message, "names no backend"),
              "run %d: status %d: %s", bad[k], r.status, r.message);
        engine_desc d;
        engine_describe(&o, &d);
        CHECK(strstr(d.label, "names no backend") && !d.backend[0], "describe %d: %s", bad[k], d.label);
        int nch = -1;
        engine_channels_for(&o, &nch);
        CHECK(nch == 0, "channels %d", nch);
        CHECK(engine_rcl_create(m, &o, "sandbox") == NULL, "a limiter for backend %d", bad[k]);
    }
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_table_matches_backends);
    RUN_TEST(test_defaults_exist);
    RUN_TEST(test_unknown_name_refused);
    RUN_TEST(test_unknown_id_refused);
    TEST_MAIN_END();
}
