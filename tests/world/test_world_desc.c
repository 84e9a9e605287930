// test_world_desc.c: world files load, and bad ones get one clear line naming
// the file and the field.
#include "check.h"

#include "model.h"
#include "ode_world.h"
#include "world_desc.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static int write_file(const char* path, const char* text) {
    FILE* f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

// Load text as file name; expect failure with every needle in the message.
static void expect_error(const char* name, const char* text, const char* needle1, const char* needle2) {
    char err[512] = "";
    world_desc d;
    CHECK(write_file(name, text) == 0, "write %s", name);
    int rc = world_desc_load(name, &d, err, sizeof err);
    CHECK(rc == -1, "%s must fail", name);
    CHECK(strstr(err, name) != NULL, "message names the file: \"%s\"", err);
    CHECK(strstr(err, needle1) != NULL, "message names \"%s\": \"%s\"", needle1, err);
    if (needle2) CHECK(strstr(err, needle2) != NULL, "message says \"%s\": \"%s\"", needle2, err);
    CHECK(strchr(err, '\n') == NULL, "one line: \"%s\"", err);
    printf("  %s -> %s\n", name, err);
    world_desc_free(&d);
}

static void test_shipped_worlds_load(void) {
    char err[512];
    world_desc d;
    CHECK(world_desc_load(CRANESIM_ASSETS "/worlds/validation.json", &d, err, sizeof err) == 0, "%s", err);
    CHECK(d.kind == WORLD_VALIDATION, "validation kind");
    world_desc_free(&d);
    CHECK(world_desc_load(CRANESIM_ASSETS "/worlds/sandbox.json", &d, err, sizeof err) == 0, "%s", err);
    CHECK(d.kind == WORLD_SANDBOX, "sandbox kind");
    CHECK(d.nload >= 3, "%d loads", d.nload);
    CHECK(d.nobstacle >= 10, "%d obstacles", d.nobstacle);
    CHECK(d.circuit != NULL, "slew circuit present");
    // Loads given as [x, y] rest on the ground: centre at half their height.
    CHECK_NEAR(d.load[0].position[2], world_desc_terrain_height(&d, d.load[0].position[0], d.load[0].position[1]) +
                                          0.5 * d.load[0].size[2], 1e-12);
    world_desc_free(&d);
}

static void test_bad_files(void) {
    expect_error("bad_syntax.json", "{\"type\": \"sandbox\" \"rope\": {}}", "line 1", NULL);
    expect_error("bad_type.json", "{\"type\": \"moon\"}", "type", "\"moon\"");
    expect_error("bad_missing_type.json", "{\"name\": \"x\"}", "type", "missing");
    expect_error("bad_key.json", "{\"type\": \"sandbox\", \"trcuk\": {}}", "trcuk", NULL);
    // Sandbox sections in a validation world would be ignored.
    expect_error("bad_validation_truck.json", "{\"type\": \"validation\", \"truck\": {}}", "truck",
                 "only a sandbox world");
    expect_error("bad_mass.json",
                 "{\"type\": \"sandbox\", \"loads\": [{\"mass\": 200, \"size\": [1,1,1], \"position\": [3, 3]},"
                 " {\"mass\": -5, \"size\": [1,1,1], \"position\": [4, 4]}]}",
                 "loads[1].mass", "must be > 0");
    expect_error("bad_size.json",
                 "{\"type\": \"sandbox\", \"obstacles\": [{\"size\": [1, 0, 2], \"position\": [5, 5]}]}",
                 "obstacles[0].size", "> 0");
    expect_error("bad_position.json",
                 "{\"type\": \"sandbox\", \"obstacles\": [{\"size\": [1, 1, 2], \"position\": [5]}]}",
                 "obstacles[0].position", NULL);
    expect_error("bad_span.json", "{\"type\": \"sandbox\", \"truck\": {\"track\": 2.0, \"outrigger_span\": 1.5}}",
                 "truck.outrigger_span", NULL);
    expect_error("bad_links.json", "{\"type\": \"sandbox\", \"rope\": {\"links\": 0}}", "rope.links", ">= 1");
    expect_error("bad_up.json", "{\"type\": \"sandbox\", \"meshes\": {\"boom1\": {\"up\": \"x\"}}}", "meshes.boom1.up",
                 NULL);
    expect_error("bad_dup.json",
                 "{\"type\": \"sandbox\", \"obstacles\": [{\"name\": \"a\", \"size\": [1,1,1], \"position\": [5, 5]},"
                 " {\"name\": \"a\", \"size\": [1,1,1], \"position\": [8, 8]}]}",
                 "obstacles[1].name", "duplicate");
    expect_error("bad_kind.json",
                 "{\"type\": \"sandbox\", \"obstacles\": [{\"kind\": \"tree\", \"size\": [1,1,1], \"position\": [5, 5]}]}",
                 "obstacles[0].kind", "\"tree\"");
}

// A broken slew circuit in the world file is blamed on the world file.
static void test_bad_circuit(void) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    if (!m) { CHECK(0, "%s", err); return; }
    const char* text =
        "{\"type\": \"sandbox\", \"circuit\": {\"components\": ["
        "{\"name\": \"slew_valve\", \"type\": \"valve\", \"P\": \"pump_line\", \"T\": \"tank\", \"A\": \"sA\", \"B\": \"sB\"},"
        "{\"name\": \"sA\", \"type\": \"hose\", \"to\": \"slew_cyl.A\", \"length\": 1, \"diameter\": 0.01},"
        "{\"name\": \"sB\", \"type\": \"hose\", \"to\": \"slew_cyl.B\", \"length\": 1, \"diameter\": 0.01},"
        "{\"name\": \"slew_cyl\", \"type\": \"cylinder\", \"bore\": -0.06, \"rod\": 0.02, \"stroke\": 0.6}]}}";
    world_desc d;
    CHECK(write_file("bad_circuit.json", text) == 0, "write");
    CHECK(world_desc_load("bad_circuit.json", &d, err, sizeof err) == 0, "the fragment itself parses: %s", err);
    ode_world_opts o = ode_world_default_opts();
    o.model_file = "hiab031.json";
    ode_world* w = ode_world_create(&m->mech, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"), &d, &o, err, sizeof err);
    CHECK(w == NULL, "must fail");
    CHECK(strstr(err, "bad_circuit.json") && strstr(err, "circuit") && strstr(err, "bore"), "message: \"%s\"", err);
    printf("  bad_circuit.json -> %s\n", err);
    ode_world_destroy(w);
    world_desc_free(&d);

    // A world naming a slew cylinder the circuit lacks.
    CHECK(write_file("bad_slew.json", "{\"type\": \"sandbox\", \"slew\": {\"cylinder\": \"nope\"}}") == 0, "write");
    CHECK(world_desc_load("bad_slew.json", &d, err, sizeof err) == 0, "%s", err);
    w = ode_world_create(&m->mech, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"), &d, &o, err, sizeof err);
    CHECK(w == NULL, "must fail");
    CHECK(strstr(err, "bad_slew.json") && strstr(err, "slew.cylinder") && strstr(err, "nope"), "message: \"%s\"", err);
    printf("  bad_slew.json -> %s\n", err);
    ode_world_destroy(w);
    world_desc_free(&d);

    // A slew on the lifting arm's cylinder (the QA pass found it accepted,
    // and the slew then moved the boom).
    CHECK(write_file("slew_on_lift.json",
                     "{\"type\": \"sandbox\", \"slew\": {\"cylinder\": \"lift_cyl\", \"valve\": \"lift_valve\"}}") == 0,
          "write");
    CHECK(world_desc_load("slew_on_lift.json", &d, err, sizeof err) == 0, "%s", err);
    w = ode_world_create(&m->mech, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"), &d, &o, err, sizeof err);
    CHECK(w == NULL, "must fail");
    CHECK(strstr(err, "slew_on_lift.json") && strstr(err, "slew.cylinder") && strstr(err, "already drives"),
          "message: \"%s\"", err);
    printf("  slew_on_lift.json -> %s\n", err);
    ode_world_destroy(w);
    world_desc_free(&d);
    model_free(m);
}

// "gravity": 0 in a world file is a weightless world, not "the model's"
// (which absent means). Unpowered booms (no hydraulic forces) then stay
// where they start; with the model's gravity they fall.
static void test_zero_gravity(void) {
    char err[512];
    CHECK(write_file("g0.json", "{\"type\": \"validation\", \"gravity\": 0}") == 0, "write");
    world_desc d0, dm;
    CHECK(world_desc_load("g0.json", &d0, err, sizeof err) == 0, "%s", err);
    CHECK(world_desc_load(CRANESIM_ASSETS "/worlds/validation.json", &dm, err, sizeof err) == 0, "%s", err);
    CHECK(d0.gravity == 0.0 && dm.gravity < 0.0, "gravity %g (file says 0), %g (absent)", d0.gravity, dm.gravity);
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    double drop[2];
    for (int k = 0; k < 2; ++k) {
        ode_world_opts o = ode_world_default_opts();
        o.hydraulics = 0;
        ode_world* w = ode_world_create(&m->mech, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"),
                                        k ? &dm : &d0, &o, err, sizeof err);
        CHECK(w != NULL, "%s", err);
        if (!w) continue;
        ode_world_state s0, s1;
        ode_world_get_state(w, &s0);
        ode_world_step(w, 0.1);
        ode_world_get_state(w, &s1);
        drop[k] = fabs(s1.q[0] - s0.q[0]) + fabs(s1.q[1] - s0.q[1]);
        ode_world_destroy(w);
    }
    printf("  joint motion in 0.1 s unpowered: %.3g rad weightless, %.3g rad with the model's gravity\n", drop[0],
           drop[1]);
    CHECK(drop[0] < 1e-9, "weightless booms moved %.3g rad", drop[0]);
    CHECK(drop[1] > 1e-2, "booms under gravity moved only %.3g rad", drop[1]);
    model_free(m);
    world_desc_free(&d0);
    world_desc_free(&dm);
}

int main(int argc, char** argv) {
    RUN_TEST(test_shipped_worlds_load);
    RUN_TEST(test_bad_files);
    RUN_TEST(test_bad_circuit);
    RUN_TEST(test_zero_gravity);
    TEST_MAIN_END();
}
