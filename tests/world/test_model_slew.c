// test_model_slew.c: the slew drive in the crane model (mechanics.slew and
// hydraulics_slew, issue 26): it loads in both forms of the mechanics
// section, bad ones get one line naming the file and the field, and the ODE
// sandbox runs the same crane with the slew in the model as with the slew in
// the world, the model's winning over a different one in the world.
#include "check.h"

#include "chain.h"
#include "json_util.h"
#include "model.h"
#include "ode_run.h"
#include "ode_world.h"
#include "world_desc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cJSON* load_json(const char* path) {
    char err[512];
    cJSON* j = json_load_file(path, err, sizeof err);
    if (!j) fprintf(stderr, "%s\n", err);
    return j;
}

static cJSON* shipped(const char* name) {
    char p[512];
    snprintf(p, sizeof p, "%s/models/%s", CRANESIM_ASSETS, name);
    return load_json(p);
}

// --set on a parsed document; the test's own edits must apply.
static void set(cJSON* root, const char* assignment) {
    char err[400];
    const int rc = json_set_path(root, assignment, err, sizeof err);
    CHECK(rc == 0, "%s", err);
}

static void test_shipped_models_have_the_slew(void) {
    static const char* const names[] = {"hiab031.json", "hiab031_ls.json"};
    for (int i = 0; i < 2; ++i) {
        char err[512] = "";
        model* m = model_from_json(shipped(names[i]), names[i], err, sizeof err);
        CHECK(m != NULL, "%s: %s", names[i], err);
        if (!m) continue;
        const crane_slew* s = &m->chain.slew;
        CHECK(s->present, "%s: slew present", names[i]);
        // The values the worlds carried (assets/worlds/sandbox.json slew).
        CHECK(s->pinion_radius == 0.1 && s->column_radius == 0.16 && s->damping == 2000, "%s: %g %g %g", names[i],
              s->pinion_radius, s->column_radius, s->damping);
        CHECK(!strcmp(s->cylinder, "slew_cyl") && !strcmp(s->valve, "slew_valve"), "%s: %s %s", names[i], s->cylinder,
              s->valve);
        // Not in the model's own circuit: the analytic runs keep theirs.
        CHECK(hyd_model_cylinder(m->hyd, "slew_cyl") < 0 && hyd_model_valve(m->hyd, "slew_valve") < 0,
              "%s: the slew is not in model.hyd", names[i]);
        // Nothing drives the slew joint of the analytic mechanism yet.
        CHECK(!m->chain.slew_free, "%s: slew_free stays false", names[i]);
        // The conventions of the rack (stroke r theta + s/2, torque F r).
        CHECK_NEAR(crane_slew_stroke(s, 0.0, 0.6), 0.3, 1e-15);
        CHECK_NEAR(crane_slew_stroke(s, 1.0, 0.6), 0.4, 1e-15);
        CHECK_NEAR(crane_slew_torque(s, 1000.0), 100.0, 1e-12);
        model_free(m);
    }
}

// The chain form takes the same slew section (hiab031_chain.json, the
// default crane in the chain form, carries hiab031.json's).
static void test_chain_form(void) {
    cJSON* c = load_json(CRANESIM_TESTDATA "/hiab031_chain.json");
    if (!c) {
        CHECK(0, "hiab031_chain.json");
        return;
    }
    char err[512] = "";
    model* m = model_from_json(c, "hiab031_chain.json", err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    CHECK(!m->chain.two_link && m->chain.slew.present && m->chain.slew.pinion_radius == 0.1 &&
              m->chain.slew.column_radius == 0.16 && m->chain.slew.damping == 2000,
          "chain form slew");
    // A copy of the chain carries it.
    crane_chain cc;
    CHECK(crane_chain_copy(&cc, &m->chain) == 0, "copy");
    CHECK(cc.slew.present && !strcmp(cc.slew.cylinder, "slew_cyl") && !strcmp(cc.slew.valve, "slew_valve"),
          "copied slew");
    crane_chain_free(&cc);
    model_free(m);
    // One column, one radius.
    cJSON* two = load_json(CRANESIM_TESTDATA "/hiab031_chain.json");
    set(two, "mechanics.slew.column_radius=0.2");
    m = model_from_json(two, "chain_bad.json", err, sizeof err);
    CHECK(m == NULL && strstr(err, "chain_bad.json: mechanics.slew.column_radius: 0.2 m is not the column's radius "
                                   "(mechanics.bodies[0].radius, 0.16 m)"),
          "chain form radius: \"%s\"", err);
    model_free(m);
    // The chain form's errors name the same fields.
    cJSON* bad = load_json(CRANESIM_TESTDATA "/hiab031_chain.json");
    set(bad, "mechanics.slew.cylinder=lift_cyl");
    m = model_from_json(bad, "chain_bad.json", err, sizeof err);
    CHECK(m == NULL && strstr(err, "chain_bad.json: mechanics.slew.cylinder: no cylinder named \"lift_cyl\""),
          "chain form: \"%s\"", err);
    model_free(m);
}

// The model edited by the assignments (NULL-terminated; "-path" deletes a
// member, "@key" adds a patch entry, "+name" a component) must fail with every needle in one line.
static void expect_error(const char* base, const char* const* edits, const char* needle1, const char* needle2) {
    cJSON* root = shipped(base);
    if (!root) {
        CHECK(0, "%s", base);
        return;
    }
    for (const char* const* e = edits; *e; ++e) {
        if ((*e)[0] == '-') {
            // "-a.b.c" deletes member c of object a.b.
            char path[128];
            snprintf(path, sizeof path, "%s", *e + 1);
            cJSON* o = root;
            char* key = path;
            for (char* dot; (dot = strchr(key, '.')); key = dot + 1) {
                *dot = 0;
                o = cJSON_GetObjectItemCaseSensitive(o, key);
            }
            CHECK(cJSON_GetObjectItemCaseSensitive(o, key) != NULL, "%s exists", *e);
            cJSON_DeleteItemFromObjectCaseSensitive(o, key);
        } else if ((*e)[0] == '@') {
            // "@key" patches a port of a component the model does not have.
            cJSON* patch = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "hydraulics_slew"),
                                                            "patch");
            cJSON_AddStringToObject(patch, *e + 1, "slew_ls");
        } else if ((*e)[0] == '+') {
            // "+name" adds a component of that name (a copy of the slew hose).
            cJSON* comps = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "hydraulics_slew"),
                                                            "components");
            cJSON* c = cJSON_Duplicate(cJSON_GetArrayItem(comps, 1), 1);
            cJSON_ReplaceItemInObjectCaseSensitive(c, "name", cJSON_CreateString(*e + 1));
            cJSON_AddItemToArray(comps, c);
        } else {
            set(root, *e);
        }
    }
    char err[512] = "";
    model* m = model_from_json(root, "slew_bad.json", err, sizeof err);
    CHECK(m == NULL, "%s must fail (%s)", needle1, edits[0]);
    model_free(m);
    CHECK(strstr(err, "slew_bad.json: ") == err, "names the file: \"%s\"", err);
    CHECK(strstr(err, needle1) != NULL, "names \"%s\": \"%s\"", needle1, err);
    if (needle2) CHECK(strstr(err, needle2) != NULL, "says \"%s\": \"%s\"", needle2, err);
    CHECK(strchr(err, '\n') == NULL, "one line: \"%s\"", err);
    printf("  %s -> %s\n", edits[0], err);
}

#define E(...) ((const char* const[]){__VA_ARGS__, NULL})

static void test_bad_slew(void) {
    expect_error("hiab031.json", E("-hydraulics_slew"), "mechanics.slew", "hydraulics_slew");
    expect_error("hiab031.json", E("-mechanics.slew"), "hydraulics_slew", "mechanics has no slew");
    expect_error("hiab031.json", E("mechanics.slew.pinion_radius=5"), "mechanics.slew.pinion_radius", "1] m");
    expect_error("hiab031.json", E("mechanics.slew.column_radius=0"), "mechanics.slew.column_radius", "m");
    expect_error("hiab031.json", E("-mechanics.slew.pinion_radius"), "mechanics.slew.pinion_radius", "missing");
    expect_error("hiab031.json", E("mechanics.slew.damping=-1"), "mechanics.slew.damping", "N m s/rad");
    expect_error("hiab031.json", E("mechanics.slew.cylinder=nope"), "mechanics.slew.cylinder",
                 "no cylinder named \"nope\" in hydraulics_slew");
    // The booms' own cylinder is not the slew's: the slew's parts are the fragment's.
    expect_error("hiab031.json", E("mechanics.slew.cylinder=lift_cyl"), "mechanics.slew.cylinder",
                 "no cylinder named \"lift_cyl\"");
    expect_error("hiab031.json", E("mechanics.slew.valve=slew_hose_A"), "mechanics.slew.valve",
                 "is a hose, not a valve");
    expect_error("hiab031.json", E("hydraulics_slew.components.slew_cyl.bore=-1"), "hydraulics_slew.components[3]",
                 "bore");
    // A component name the model's circuit already has.
    expect_error("hiab031.json", E("+lift_valve"), "hydraulics_slew", "lift_valve");
    expect_error("hiab031_ls.json", E("@nope.out"), "hydraulics_slew.patch.nope.out", "no component nope");
    expect_error("hiab031_ls.json", E("@ls_shuttle.spool"), "hydraulics_slew.patch.ls_shuttle.spool",
                 "no port field spool");
    expect_error("hiab031_ls.json", E("@noport"), "hydraulics_slew.patch.noport", "component.field");
}

// A misspelt member of mechanics.slew, or of the fragment.
static void test_unknown_keys(void) {
    static const char* const cases[][2] = {{"mechanics", "pinon_radius"}, {"hydraulics_slew", "extra"}};
    for (int i = 0; i < 2; ++i) {
        cJSON* root = shipped("hiab031.json");
        cJSON* o = !strcmp(cases[i][0], "mechanics")
                       ? cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "mechanics"), "slew")
                       : cJSON_GetObjectItemCaseSensitive(root, "hydraulics_slew");
        cJSON_AddNumberToObject(o, cases[i][1], 1);
        char err[512] = "";
        model* m = model_from_json(root, "slew_bad.json", err, sizeof err);
        CHECK(m == NULL && strstr(err, cases[i][1]) && strstr(err, cases[i][0]), "%s: \"%s\"", cases[i][1], err);
        model_free(m);
    }
}

// ---- the sandbox: slew in the model against slew in the world ----

static int g_notes;
static char g_note[1024];
static void on_note(const char* line, void* user) {
    (void)user;
    if (strstr(line, "slew drive")) {
        ++g_notes;
        snprintf(g_note, sizeof g_note, "%s", line);
    }
}

static model* load_model(cJSON* root, const char* name) {
    char err[512] = "";
    model* m = model_from_json(root, name, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    return m;
}

// The model without its slew (a model file of before): the world's is used.
static model* without_slew(const char* name) {
    cJSON* root = shipped(name);
    cJSON_DeleteItemFromObjectCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "mechanics"), "slew");
    cJSON_DeleteItemFromObjectCaseSensitive(root, "hydraulics_slew");
    return load_model(root, name);
}

// A slew-and-lift command on the sandbox for 1.5 s; every state after each
// 10 ms into out (nrow rows of NV). NULL world: -1.
enum { NV = 12, NROW = 150 };
static int run(const model* m, world_desc* wd, double out[NROW][NV]) {
    char err[512] = "";
    if (ode_world_take_model_slew(m, wd, err, sizeof err)) {
        CHECK(0, "%s", err);
        return -1;
    }
    ode_world_opts o = ode_world_default_opts();
    // sandbox_swing's pose (q1 125 deg, q2 -60 deg; paper convention).
    o.q0[0] = 125 * 3.14159265358979323846 / 180;
    o.q0[1] = -60 * 3.14159265358979323846 / 180;
    o.model_file = m->file;
    ode_world* w = ode_world_create(&m->mech, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"), wd, &o, err,
                                    sizeof err);
    CHECK(w != NULL, "create: %s", err);
    if (!w) return -1;
    for (int i = 0; i < NROW; ++i) {
        const double u[3] = {i < 80 ? 0.3 : 0.0, 0.0, i < 100 ? 0.8 : -0.5};
        ode_world_set_commands(w, u);
        if (ode_world_step(w, 0.01)) {
            CHECK(0, "step: %s", ode_world_error(w));
            ode_world_destroy(w);
            return -1;
        }
        ode_world_state s;
        ode_world_get_state(w, &s);
        const double v[NV] = {s.slew, s.slew_rate, s.x[2], s.v[2], s.pA[2], s.pB[2], s.F[2], s.x[0], s.pA[0],
                              s.hook[0], s.hook[1], s.tip_world[1]};
        memcpy(out[i], v, sizeof v);
    }
    ode_world_destroy(w);
    return 0;
}

static world_desc sandbox(void) {
    world_desc d;
    char err[512];
    if (world_desc_load(CRANESIM_ASSETS "/worlds/sandbox.json", &d, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    return d;
}

// Every value of b equals a's (the same floating-point operations).
static void same_runs(double a[NROW][NV], double b[NROW][NV], const char* what) {
    int diff = 0;
    for (int i = 0; i < NROW; ++i)
        for (int k = 0; k < NV; ++k)
            if (a[i][k] != b[i][k] && !diff) {
                diff = 1;
                CHECK(0, "%s: row %d value %d: %.17g vs %.17g", what, i, k, a[i][k], b[i][k]);
            }
    CHECK(!diff, "%s identical", what);
}

static void test_sandbox_same_crane(const char* name) {
    static double ref[NROW][NV], got[NROW][NV];
    hyd_set_note_handler(on_note, NULL);
    // The world's slew, on a model without one: as every run before.
    model* m0 = without_slew(name);
    world_desc d0 = sandbox();
    g_notes = 0;
    const int r0 = run(m0, &d0, ref);
    CHECK(d0.slew_file[0] == 0 && g_notes == 0, "%s without a slew: the world's, no note", name);
    world_desc_free(&d0);
    // The model's slew on the same world (the same slew): no note.
    model* m = load_model(shipped(name), name);
    world_desc d1 = sandbox();
    g_notes = 0;
    const int r1 = run(m, &d1, got);
    CHECK(!strcmp(d1.slew_file, name) && g_notes == 0, "%s: the model's slew, the same as the world's: no note (%s)",
          name, g_note);
    world_desc_free(&d1);
    if (!r0 && !r1) same_runs(ref, got, "model's slew = world's slew");
    // A world whose slew differs everywhere: the model's wins, with a note.
    world_desc d2 = sandbox();
    d2.slew.pinion_radius = 0.15;
    d2.slew.damping = 9000;
    cJSON* frag = (cJSON*)world_desc_circuit_for(&d2, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"));
    cJSON* cyl = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(frag, "components"), 0);
    cJSON* e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(frag, "components"))
        if (!strcmp(cJSON_GetObjectItemCaseSensitive(e, "name")->valuestring, "slew_cyl")) cyl = e;
    cJSON_ReplaceItemInObjectCaseSensitive(cyl, "bore", cJSON_CreateNumber(0.08));
    g_notes = 0;
    g_note[0] = 0;
    const int r2 = run(m, &d2, got);
    CHECK(g_notes == 1 && strstr(g_note, "sandbox.json") && strstr(g_note, "is used instead"), "%s: note \"%s\"",
          name, g_note);
    printf("  %s: %s\n", name, g_note);
    world_desc_free(&d2);
    if (!r0 && !r2) same_runs(ref, got, "model's slew over a different world slew");
    // A world without a slew drive of its own (no slew section, no circuit):
    // the model brings it, no note; the same crane.
    world_desc d4 = sandbox();
    cJSON_Delete(d4.circuit);
    cJSON_Delete(d4.circuit_ls);
    d4.circuit = d4.circuit_ls = NULL;
    d4.slew.pinion_radius = 0.2;
    g_notes = 0;
    const int r4 = run(m, &d4, got);
    CHECK(g_notes == 0, "%s: no note on a world without a slew (%s)", name, g_note);
    world_desc_free(&d4);
    if (!r0 && !r4) same_runs(ref, got, "model's slew on a world without one");
    // Neither has one: the sandbox's refusal, as before, naming the world.
    {
        world_desc d5 = sandbox();
        cJSON_Delete(d5.circuit);
        cJSON_Delete(d5.circuit_ls);
        d5.circuit = d5.circuit_ls = NULL;
        char err[512] = "";
        CHECK(ode_world_take_model_slew(m0, &d5, err, sizeof err) == 0, "%s", err);
        ode_world_opts o = ode_world_default_opts();
        o.q0[0] = 125 * 3.14159265358979323846 / 180;
        o.q0[1] = -60 * 3.14159265358979323846 / 180;
        o.model_file = m0->file;
        ode_world* w = ode_world_create(&m0->mech, cJSON_GetObjectItemCaseSensitive(m0->json, "hydraulics"), &d5, &o,
                                        err, sizeof err);
        CHECK(w == NULL && strstr(err, "sandbox.json: slew.cylinder: no cylinder named \"slew_cyl\""),
              "%s: neither has a slew: \"%s\"", name, err);
        ode_world_destroy(w);
        world_desc_free(&d5);
    }
    // And that world's own slew does change the crane (the check above can fail).
    world_desc d3 = sandbox();
    d3.slew.pinion_radius = 0.15;
    const int r3 = run(m0, &d3, got);
    world_desc_free(&d3);
    CHECK(!r3 && !r0 && got[NROW - 1][0] != ref[NROW - 1][0], "%s: a different pinion slews differently", name);
    // The run slewed at all: over 5 deg.
    CHECK(fabs(ref[99][0]) > 5 * 3.14159265358979 / 180, "%s: slewed %g rad", name, ref[99][0]);
    model_free(m0);
    model_free(m);
    hyd_set_note_handler(NULL, NULL);
}


// The slew by hand: a slew-only command on the sandbox with the model's
// slew drive changed (pinion 0.12 m, bearing damping 500 N m s/rad, neither
// the world's). Over the first 0.15 s the slew rate follows
//   I_zz dw/dt = F r - c w,
// F the rack force as applied, I_zz the crane's inertia about the slew axis
// by hand from the model: the column a solid cylinder (1/2 m r^2), each boom
// a box of its section whose inertia about the hinge is the model's (the ODE
// world's bodies) at its pose, plus m d^2 of its centre of mass. The hook
// (40 kg on 1.2 m of rope) hangs from the tip and pulls on it only as the
// rope tilts: below 0.3 % of the torque over this window.
static void test_slew_by_hand(void) {
    cJSON* root = shipped("hiab031.json");
    set(root, "mechanics.slew.pinion_radius=0.12");
    set(root, "mechanics.slew.damping=500");
    model* m = load_model(root, "hiab031.json");
    if (!m) return;
    world_desc d = sandbox();
    char err[512] = "";
    CHECK(ode_world_take_model_slew(m, &d, err, sizeof err) == 0, "%s", err);
    const double PI_ = 3.14159265358979323846;
    ode_world_opts o = ode_world_default_opts();
    o.q0[0] = 125 * PI_ / 180;
    o.q0[1] = -60 * PI_ / 180;
    o.model_file = m->file;
    ode_world* w = ode_world_create(&m->mech, cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics"), &d, &o, err,
                                    sizeof err);
    CHECK(w != NULL, "%s", err);
    if (!w) {
        model_free(m);
        world_desc_free(&d);
        return;
    }
    // I_zz by hand [kg m^2].
    const crane_mech* me = &m->mech;
    const double rc = m->chain.slew.column_radius;
    double I = 0.5 * me->column_mass * rc * rc;
    const double a[2] = {o.q0[0] - 0.5 * PI_, o.q0[0] + o.q0[1] - 0.5 * PI_}; // from horizontal
    double x_joint = 0; // joint's horizontal distance from the slew axis [m]
    for (int i = 0; i < 2; ++i) {
        const crane_link* l = &me->link[i];
        // Box section w x h: about the boom's own axis and the in-plane normal.
        const double Ixx = l->mass * (l->width * l->width + l->height * l->height) / 12;
        const double Izz = l->mass * (l->length * l->length + l->width * l->width) / 12;
        const double r = x_joint + l->com * cos(a[i]);
        I += Ixx * sin(a[i]) * sin(a[i]) + Izz * cos(a[i]) * cos(a[i]) + l->mass * r * r;
        x_joint += l->length * cos(a[i]);
    }
    // The model's chain with its column freed (the analytic mode's, once
    // the slew is its degree of freedom), q = {slew, q1, q2}: M[0][0] is
    // I_zz. Its column is the drive's (column_radius), as the sandbox's.
    {
        char cerr[256] = "";
        chain* ch = crane_chain_mechanism(&m->chain, 0.0, true, 0.0, cerr, sizeof cerr);
        CHECK(ch != NULL, "%s", cerr);
        if (ch) {
            chain_ws* ws = chain_ws_create(ch);
            const double q[3] = {0.0, o.q0[0], o.q0[1]}, qd[3] = {0, 0, 0};
            chain_update(ch, ws, q, qd);
            double M[9];
            chain_mass_matrix(ch, ws, M);
            printf("  slew inertia: by hand %.6f, the model's chain M[0][0] %.6f kg m^2\n", I, M[0]);
            CHECK_REL(M[0], I, 1e-12);
            chain_ws_free(ws);
            chain_free(ch);
        }
    }
    const double r = 0.12, c = 500, h = 1e-3;
    const double u[3] = {0, 0, 1.0};
    ode_world_set_commands(w, u);
    double dw_sim = 0, dw_hand = 0, w_prev = 0, f_prev = 0;
    int ok = 1;
    for (int k = 1; k <= 150 && ok; ++k) {
        ok = ode_world_step(w, h) == 0;
        ode_world_state st;
        ode_world_get_state(w, &st);
        // From 20 ms on (the truck has landed on its pads): the change of
        // the rate against the trapezoid of the torque over I.
        if (k > 20) {
            dw_sim += st.slew_rate - w_prev;
            dw_hand += 0.5 * h * ((f_prev * r - c * w_prev) + (st.F[2] * r - c * st.slew_rate)) / I;
        }
        w_prev = st.slew_rate;
        f_prev = st.F[2];
    }
    CHECK(ok, "%s", ode_world_error(w));
    printf("  slew by hand: I_zz %.1f kg m^2; rate change over 20..150 ms %.5f rad/s, by hand %.5f rad/s (%.2f %%)\n", I,
           dw_sim, dw_hand, 100 * (dw_sim - dw_hand) / dw_hand);
    CHECK(dw_sim > 0.05, "slewed: %g rad/s", dw_sim);
    CHECK_REL(dw_sim, dw_hand, 0.02);
    ode_world_destroy(w);
    world_desc_free(&d);
    model_free(m);
}

int main(void) {
    test_shipped_models_have_the_slew();
    test_chain_form();
    test_bad_slew();
    test_unknown_keys();
    test_sandbox_same_crane("hiab031.json");
    test_sandbox_same_crane("hiab031_ls.json");
    test_slew_by_hand();
    TEST_MAIN_END();
}
