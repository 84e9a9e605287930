// test_drive.c: the interactive simulator end to end, headless (offscreen GL
// on Mesa llvmpipe, SDL virtual joystick, a virtual clock): the real loop of
// `cranesim drive` with the real world, renderer, input path and panel.
#include "check.h"
#include "drive_session.h"
#include "input.h"
#include "panel.h"
#include "render.h"
#include "drive_test_util.h"

#include <SDL2/SDL.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

// sets: model overrides (--set path=value), nset of them.
static drive_session* open_session_with(const char* const* sets, int nset) {
    app_common c = {.sim = sim_default_opts()};
    for (int i = 0; i < nset; ++i) c.sets[c.nset++] = sets[i];
    c.sim.mechanics = SIM_ODE; // the default sandbox
    c.scenario_path = CRANESIM_ASSETS "/scenarios/sandbox_pick_place.json"; // initial pose only
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.width = 1280;
    o.height = 720;
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    return s;
}

static drive_session* open_session(void) { return open_session_with(NULL, 0); }

static int run_for(drive_session* s, double* wall, double seconds);

// A session in the validation world (column on the ground at the origin,
// booms on hinges, no truck), driven by the 2-DOF demo as `cranesim drive
// --world validation` does.
// record: the CSV to record to, or NULL.
static drive_session* open_validation(bool scripted, const char* record) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "validation";
    c.scenario_path = CRANESIM_ASSETS "/scenarios/drive_demo.json";
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = scripted;
    o.record_path = record;
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "validation session: %s", err);
    return s;
}

static const world_snap_body* find_role(const world_snapshot* snap, world_role role) {
    for (int i = 0; i < snap->nbody; ++i)
        if (snap->body[i].role == role) return &snap->body[i];
    return NULL;
}

static double dist3(const double a[3], const double b[3]) {
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// Where the renderer draws point p (metres, in the body's mesh or primitive
// frame) of body b, against where it should be, within tol [m].
static void check_drawn(const world_snap_body* b, double px, double py, double pz, const double want[3], double tol,
                        const char* what) {
    const double p[3] = {px, py, pz};
    double got[3];
    render_body_point(b, p, got);
    double d = dist3(got, want);
    CHECK(d <= tol, "%s: drawn at (%.3f, %.3f, %.3f) m, joint at (%.3f, %.3f, %.3f) m: %.3f m apart", what, got[0],
          got[1], got[2], want[0], want[1], want[2], d);
}

// The drawn crane is one piece: each boom mesh starts at the pin the previous
// part ends at (assets/meshes/README.md: column.obj has its foot at the
// origin and joint 1 at (0, 0, H); boom1.obj joint 1 at the origin, joint 2
// at (L1, 0, 0); boom2.obj joint 2 at the origin, the tip at (L2, 0, 0)),
// and every cylinder pin lies on the part that carries it.
static void check_crane_drawn_in_one_piece(const world_snapshot* snap, const crane_mech* me, const char* world) {
    const world_snap_body* col = find_role(snap, WORLD_ROLE_COLUMN);
    const world_snap_body* b1 = find_role(snap, WORLD_ROLE_BOOM1);
    const world_snap_body* b2 = find_role(snap, WORLD_ROLE_BOOM2);
    CHECK(col && b1 && b2, "%s: column, lifting arm and end arm in the snapshot", world);
    if (!col || !b1 || !b2) return;
    CHECK(col->mesh[0] && b1->mesh[0] && b2->mesh[0], "%s: crane drawn with its meshes", world);
    const double H = me->column_height, L1 = me->link[0].length, L2 = me->link[1].length;
    const double o[3] = {0, 0, 0};
    double j1[3], j2[3];
    // Joint 1 as the column draws it, joint 2 as the lifting arm draws it.
    const double pin1[3] = {0, 0, H}, pin2[3] = {L1, 0, 0};
    render_body_point(col, pin1, j1);
    render_body_point(b1, pin2, j2);
    char what[96];
    snprintf(what, sizeof what, "%s: lifting arm root at the column's joint-1 pin", world);
    check_drawn(b1, o[0], o[1], o[2], j1, 0.01, what);
    snprintf(what, sizeof what, "%s: end arm root at the lifting arm's joint-2 pin", world);
    check_drawn(b2, o[0], o[1], o[2], j2, 0.01, what);
    snprintf(what, sizeof what, "%s: end arm tip at the snapshot's tip", world);
    check_drawn(b2, L2, 0, 0, snap->tip, 0.01, what);
    // Cylinder pins: base in the parent part, rod end in the child part
    // (mounts relative to the joint; the lift's parent is the column, whose
    // mesh origin is H below joint 1; the jib's is the lifting arm, whose
    // mesh origin is joint 1, L1 behind joint 2).
    CHECK(snap->ncyl >= 2, "%s: two boom cylinders", world);
    const crane_actuator* lift = &me->act[0];
    const crane_actuator* jib = &me->act[1];
    snprintf(what, sizeof what, "%s: lift barrel pin on the column", world);
    check_drawn(col, lift->base_mount[0], 0, lift->base_mount[1] + H, snap->cyl[0].base, 0.01, what);
    snprintf(what, sizeof what, "%s: lift rod pin on the lifting arm", world);
    check_drawn(b1, lift->rod_mount[0], 0, lift->rod_mount[1], snap->cyl[0].rod_end, 0.01, what);
    snprintf(what, sizeof what, "%s: jib barrel pin on the lifting arm", world);
    check_drawn(b1, L1 + jib->base_mount[0], 0, jib->base_mount[1], snap->cyl[1].base, 0.01, what);
    snprintf(what, sizeof what, "%s: jib rod pin on the end arm", world);
    check_drawn(b2, jib->rod_mount[0], 0, jib->rod_mount[1], snap->cyl[1].rod_end, 0.01, what);
}

// `drive --world validation` drew the booms apart (QA): the meshes must be
// drawn where the joints are. In the validation world the column stands on
// the ground at the origin, so the joints also follow from the joint angles
// alone (paper convention: q1 from the downward vertical, q2 relative to the
// lifting arm, boom plane x-z): an independent check of the whole chain.
static void test_validation_world_drawn_at_the_joints(void) {
    drive_session* s = open_validation(true, NULL);
    if (!s) return;
    double wall = 0;
    const crane_mech* me = &drive_session_model(s)->mech;
    // At the start and after the demo has moved both booms.
    for (int pass = 0; pass < 2; ++pass) {
        if (pass) CHECK(run_for(s, &wall, 3.0) == 0, "loop: %s", drive_session_error(s));
        drive_session_render(s);
        const world_snapshot* snap = drive_session_snapshot(s);
        check_crane_drawn_in_one_piece(snap, me, "validation");
        double row[SIM_NCOL];
        drive_session_row(s, row);
        const double q1 = row[COL_Q1], q12 = row[COL_Q1] + row[COL_Q2];
        const double H = me->column_height, L1 = me->link[0].length, L2 = me->link[1].length;
        const double j1[3] = {0, 0, H};
        const double j2[3] = {L1 * sin(q1), 0, H - L1 * cos(q1)};
        const double tip[3] = {j2[0] + L2 * sin(q12), 0, j2[2] - L2 * cos(q12)};
        // The angles and the CSV's tip agree (reach and height from joint 1).
        CHECK_NEAR(tip[0], row[COL_TIP_X], 1e-3);
        CHECK_NEAR(tip[2] - H, row[COL_TIP_Z], 1e-3);
        const world_snap_body* col = find_role(snap, WORLD_ROLE_COLUMN);
        const world_snap_body* b1 = find_role(snap, WORLD_ROLE_BOOM1);
        const world_snap_body* b2 = find_role(snap, WORLD_ROLE_BOOM2);
        if (!col || !b1 || !b2) break;
        const double ground[3] = {0, 0, 0};
        check_drawn(col, 0, 0, 0, ground, 0.01, "column foot on the ground");
        check_drawn(col, 0, 0, H, j1, 0.01, "column's joint-1 pin");
        check_drawn(b1, 0, 0, 0, j1, 0.01, "lifting arm at joint 1");
        check_drawn(b1, L1, 0, 0, j2, 0.01, "lifting arm at joint 2");
        check_drawn(b2, 0, 0, 0, j2, 0.01, "end arm at joint 2");
        check_drawn(b2, L2, 0, 0, tip, 0.01, "end arm at the tip");
    }
    drive_session_destroy(s);
}

// The sandbox's crane (on the truck, slewed) is drawn in one piece too.
static void test_sandbox_crane_drawn_in_one_piece(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    CHECK(run_for(s, &wall, 0.5) == 0, "loop: %s", drive_session_error(s));
    drive_session_render(s);
    check_crane_drawn_in_one_piece(drive_session_snapshot(s), &drive_session_model(s)->mech, "sandbox");
    drive_session_destroy(s);
}

static bool has_chart(render* r, const char* label) {
    for (int i = 0; i < render_chart_count(r); ++i)
        if (!strcmp(render_chart_label(r, i), label)) return true;
    return false;
}

// Strip charts for the cylinders the world has: the sandbox's third is the
// slew rack; the validation world has none, so no empty p3A/x3/u3 traces.
// The HUD names who drives: the scenario when scripted.
static void test_charts_and_status_follow_the_world(void) {
    drive_session* s = open_validation(true, NULL);
    if (!s) return;
    render* r = drive_session_render_ctx(s);
    const int ncyl = drive_session_snapshot(s)->ncyl;
    CHECK(ncyl == 2, "validation world: %d cylinders", ncyl);
    CHECK(has_chart(r, "p1A") && has_chart(r, "x2") && has_chart(r, "u2"), "boom channels present");
    CHECK(!has_chart(r, "p3A") && !has_chart(r, "x3") && !has_chart(r, "u3"), "validation world charts p3A/x3/u3");
    CHECK(render_chart_count(r) == 4 * ncyl, "%d channels for %d cylinders", render_chart_count(r), ncyl);
    double wall = 0;
    run_for(s, &wall, 0.1);
    const char* st = render_get_status(r);
    CHECK(strstr(st, "[scripted]") && !strstr(st, "[keyboard]"), "status while scripted: '%s'", st);
    drive_session_destroy(s);

    s = open_session();
    if (!s) return;
    r = drive_session_render_ctx(s);
    CHECK(drive_session_snapshot(s)->ncyl == 3 && has_chart(r, "p3A") && has_chart(r, "u3"),
          "sandbox: the slew's channels");
    wall = 0;
    run_for(s, &wall, 0.1);
    st = render_get_status(r);
    CHECK(strstr(st, "[keyboard]") && !strstr(st, "[scripted]"), "status with no device, not scripted: '%s'", st);
    drive_session_destroy(s);
}

// The real-time factor is simulated over wall time; over a few milliseconds
// (a frame at t = 0) the ratio means nothing and the HUD must not show it.
static void test_no_rate_over_an_instant(void) {
    drive_session* s = open_validation(true, NULL);
    if (!s) return;
    // 0.1 ms of wall time: the world still steps a whole 1 ms ODE step.
    CHECK(drive_session_tick(s, 1e-4) == 0, "tick");
    drive_session_render(s);
    const double rt0 = drive_session_snapshot(s)->rt_factor;
    CHECK(rt0 == 0, "real-time factor over 0.1 ms of wall time: %g (want 0 = unknown)", rt0);
    double wall = 1e-4;
    run_for(s, &wall, 1.0);
    drive_session_render(s);
    const double rt1 = drive_session_snapshot(s)->rt_factor;
    CHECK(rt1 > 0.95 && rt1 < 1.05, "real-time factor over 1 s on a virtual clock: %g", rt1);
    drive_session_destroy(s);
}

// A record that cannot be written is reported, with the error, and the rows
// written before stay counted; one that can is complete.
static void test_record_write_failure(void) {
    char err[512] = "";
    drive_session* s = open_validation(true, "/dev/full"); // every write fails with ENOSPC
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.5);
    long rows = -1;
    CHECK(drive_session_finish_record(s, &rows, err, sizeof err) != 0, "writing to /dev/full reported success");
    CHECK(strstr(err, "cannot write /dev/full") && strstr(err, strerror(ENOSPC)), "message: %s", err);
    drive_session_destroy(s);

    s = open_validation(true, "drive_session_record.csv");
    if (!s) return;
    for (int i = 1; i <= 120; ++i) drive_session_tick(s, i / 240.0); // 0.5 s of ticks
    CHECK(drive_session_finish_record(s, &rows, err, sizeof err) == 0, "record: %s", err);
    drive_session_destroy(s);
    // One row per tick, plus the header.
    FILE* f = fopen("drive_session_record.csv", "r");
    int lines = 0;
    for (int ch; f && (ch = fgetc(f)) != EOF;) lines += ch == '\n';
    if (f) fclose(f);
    CHECK(rows == 120 && lines == rows + 1, "%ld rows reported, %d lines in the file", rows, lines);
}

// Run the loop for `seconds` of virtual wall time at 240 ticks per second.
static double lift_stroke(drive_session* s) {
    double row[SIM_NCOL];
    drive_session_row(s, row);
    return row[COL_X1];
}

// Count bar pixels that are not the empty-bar colour.
static int bar_fill(drive_session* s, int cyl, int chamber) {
    render* r = drive_session_render_ctx(s);
    int rect[4], w, h;
    if (!render_hud_bar_rect(r, cyl, chamber, rect)) return -1;
    render_size(r, &w, &h);
    unsigned char* px = malloc((size_t)w * h * 4);
    render_read_pixels(r, px, w, h);
    int n = 0;
    for (int y = rect[1]; y < rect[1] + rect[3]; ++y)
        for (int x = rect[0]; x < rect[0] + rect[2]; ++x) {
            const unsigned char* p = px + ((size_t)y * w + x) * 4;
            int rgb = (p[0] << 16) | (p[1] << 8) | p[2];
            n += rgb != RENDER_BAR_EMPTY_RGB;
        }
    free(px);
    return n;
}

// The default scene renders: not blank, crane-coloured pixels where the
// crane's lifting arm projects.
static void test_default_scene_frame(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    CHECK(run_for(s, &wall, 0.5) == 0, "loop failed: %s", drive_session_error(s));
    drive_session_render(s);
    render* r = drive_session_render_ctx(s);
    int w, h;
    render_size(r, &w, &h);
    unsigned char* px = malloc((size_t)w * h * 4);
    CHECK(render_read_pixels(r, px, w, h) == 0, "read pixels");
    double mean = 0, var = 0;
    for (int i = 0; i < w * h; ++i) mean += px[4 * i + 1];
    mean /= w * h;
    for (int i = 0; i < w * h; ++i) var += (px[4 * i + 1] - mean) * (px[4 * i + 1] - mean);
    var /= w * h;
    CHECK(var > 100, "frame looks blank: green variance %.1f", var);
    // Find the lifting arm in the snapshot and look at its projected centre.
    world_snapshot* snap = calloc(1, sizeof *snap);
    engine_snapshot(drive_session_engine(s), snap);
    int found = 0;
    for (int b = 0; b < snap->nbody; ++b) {
        if (snap->body[b].role != WORLD_ROLE_BOOM1) continue;
        found = 1;
        double pt[2];
        CHECK(render_project(r, snap->body[b].pos, pt), "boom behind the camera");
        int x = (int)pt[0], y = (int)pt[1];
        CHECK(x >= 0 && x < w && y >= 0 && y < h, "boom projects off screen (%d, %d)", x, y);
        if (x >= 0 && x < w && y >= 0 && y < h) {
            // The booms are painted orange: red-dominant hue, bright in the
            // sun, dark in their own shadow. Terrain is green-grey, sky blue.
            // Search a few pixels around the centre for that hue.
            int hit = 0;
            for (int dy = -3; dy <= 3; ++dy)
                for (int dx = -3; dx <= 3; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    const unsigned char* p = px + ((size_t)yy * w + xx) * 4;
                    hit |= p[0] >= 30 && p[0] > 1.8 * p[1] && p[0] > 2.5 * p[2];
                }
            CHECK(hit, "no boom-coloured pixel at (%d, %d)", x, y);
        }
    }
    CHECK(found, "no lifting arm in the snapshot");
    char err[320];
    CHECK(drive_session_screenshot(s, "drive_default_scene.png", err, sizeof err) == 0, "screenshot: %s", err);
    free(snap);
    free(px);
    drive_session_destroy(s);
}

// A virtual joystick on the lift axis extends the lift cylinder through the
// real input path (mapping, dead zone, expo) and the real world; the lift's
// pressure bar changes height as the chamber pressure changes. Then the
// keyboard does the same after the stick is unplugged.
static void test_joystick_and_keyboard_drive_the_lift(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.5);
    drive_session_render(s);
    int bar0 = bar_fill(s, 0, 0);
    double x0 = lift_stroke(s);

    int idx = attach_pad("cranesim test stick");
    CHECK(idx >= 0, "attach virtual joystick: %s", SDL_GetError());
    SDL_Joystick* js = SDL_JoystickOpen(idx);
    run_for(s, &wall, 0.2); // hot-plug event reaches the input layer
    CHECK(input_device_name(drive_session_input(s)) != NULL, "virtual joystick not opened on hot-plug");
    CHECK(input_active_source(drive_session_input(s)) == INPUT_SRC_CONTROLLER, "not a game controller");
    // Stick pulled back (negative y in SDL's convention) = lift up.
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, -32767);
    CHECK(run_for(s, &wall, 2.0) == 0, "loop: %s", drive_session_error(s));
    double x1 = lift_stroke(s);
    CHECK(x1 > x0 + 0.02, "joystick lift: stroke %.4f -> %.4f m", x0, x1);
    drive_session_render(s);
    int bar1 = bar_fill(s, 0, 0);
    CHECK(bar0 >= 0 && bar1 >= 0 && bar1 != bar0, "lift A pressure bar did not change (%d -> %d px)", bar0, bar1);
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, 0);
    SDL_JoystickClose(js);
    SDL_JoystickDetachVirtual(idx);
    run_for(s, &wall, 0.5); // unplugged: back to the keyboard

    double x2 = lift_stroke(s);
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 2.0);
    push_key(SDL_SCANCODE_UP, 0);
    run_for(s, &wall, 0.2);
    double x3 = lift_stroke(s);
    CHECK(x3 > x2 + 0.02, "keyboard lift: stroke %.4f -> %.4f m", x2, x3);
    const drive_stats* st = drive_session_stats(s);
    CHECK(st->input_samples / st->wall_time >= 75, "valve commands at %.0f Hz < 75 Hz",
          st->input_samples / st->wall_time);
    drive_session_destroy(s);
}

// A parameter changed through the panel's C API acts on the next step: the
// pump's pressure setting, seen in the pump-line pressure.
static void test_panel_change_takes_effect(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.3);
    double row[SIM_NCOL];
    drive_session_row(s, row);
    CHECK(row[COL_P_PUMP] > 19e6, "pump line starts at %.2f MPa", row[COL_P_PUMP] * 1e-6);
    char msg[256];
    CHECK(panel_set(drive_session_panel(s), "pump (pump)/p_set", 12.0, msg, sizeof msg) == PANEL_OK, "%s", msg);
    // The next tick applies it. The pump then stops delivering above its new
    // setting; open a valve so the pump line drains down to it.
    run_for(s, &wall, 1.0 / 240.0);
    double v;
    CHECK(hyd_model_get(engine_circuit(drive_session_engine(s)), "pump.p_set", &v) == 0 && fabs(v - 12e6) < 1,
          "circuit p_set = %g", v);
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 1.5);
    push_key(SDL_SCANCODE_UP, 0);
    drive_session_row(s, row);
    CHECK(row[COL_P_PUMP] < 13.0e6, "pump line %.2f MPa after lowering the setting to 12 MPa",
          row[COL_P_PUMP] * 1e-6);
    // Out of range is refused with a message, and nothing changes.
    CHECK(panel_set(drive_session_panel(s), "pump (pump)/p_set", 150.0, msg, sizeof msg) == PANEL_OUT_OF_RANGE,
          "out of range accepted");
    CHECK(strstr(msg, "p_set") != NULL, "message: %s", msg);
    drive_session_destroy(s);
}

// A boom's mass or length edited in the panel rescales that boom's own
// inertia (and centre of mass) and leaves the other boom as the model file
// gave it; the model's JSON follows, so "save model" saves what is driven.
static void test_panel_boom_edit(void) {
    // Booms that are not uniform beams, so a recomputed m L^2 / 12 or L / 2
    // would show.
    static const char* const sets[] = {"mechanics.links[1].inertia=50", "mechanics.links[0].com=1.0"};
    drive_session* s = open_session_with(sets, 2);
    if (!s) return;
    const model* m = drive_session_model(s);
    const crane_link l0 = m->mech.link[0], l1 = m->mech.link[1];
    char msg[256];
    CHECK(panel_set(drive_session_panel(s), "end_arm (link)/mass", 2.0 * l1.mass, msg, sizeof msg) == PANEL_OK, "%s",
          msg);
    CHECK(panel_set(drive_session_panel(s), "lifting_arm (link)/length", 1.1e3 * l0.length, msg, sizeof msg) == PANEL_OK,
          "%s", msg);
    double wall = 0;
    run_for(s, &wall, 2.0 / 240.0); // the ticks apply the changes
    const crane_link n0 = m->mech.link[0], n1 = m->mech.link[1];
    CHECK(fabs(n1.inertia - 2.0 * l1.inertia) < 1e-9 * l1.inertia && n1.com == l1.com && n1.length == l1.length,
          "end arm: inertia %g -> %g kg m^2, com %g -> %g m", l1.inertia, n1.inertia, l1.com, n1.com);
    CHECK(fabs(n0.com - 1.1 * l0.com) < 1e-12 && fabs(n0.inertia - 1.21 * l0.inertia) < 1e-9 * l0.inertia &&
              n0.mass == l0.mass,
          "lifting arm: com %g -> %g m, inertia %g -> %g kg m^2", l0.com, n0.com, l0.inertia, n0.inertia);
    double jv = 0.0;
    const cJSON* links = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m->json, "mechanics"), "links");
    const cJSON* inertia1 = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(links, 1), "inertia");
    if (inertia1) jv = inertia1->valuedouble;
    CHECK(fabs(jv - n1.inertia) < 1e-6 * n1.inertia, "model JSON end-arm inertia %g vs %g", jv, n1.inertia);
    drive_session_destroy(s);
}


// The HUD's warning lines for the last frame, joined with " | ".
static void hud_warnings(drive_session* s, char* out, size_t n) {
    char w[RENDER_WARN_MAX][RENDER_WARN_LEN];
    drive_session_render(s);
    const int k = render_hud_warnings(drive_session_render_ctx(s), drive_session_snapshot(s), w, RENDER_WARN_MAX);
    size_t len = 0;
    for (int i = 0; i < k; ++i) {
        const char* parts[2] = {i ? " | " : "", w[i]};
        for (int j = 0; j < 2; ++j)
            for (const char* p = parts[j]; *p && len + 1 < n; ++p) out[len++] = *p;
    }
    out[len] = '\0';
}

// An open relief is named, with the chamber it guards: slewing into the
// sandbox's wall opens a slew port relief (16 MPa, below the 20 MPa pump),
// which the HUD called "MAIN RELIEF OPEN"; the slew's own relief flag
// stayed 0. In the lagrange view an overload opens the lift's A-side relief.
static void test_open_relief_is_named(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    // The scenario's start pose has the boom at -60 deg; wall_slew stands at
    // +60 deg (sandbox.json): hold "slew left" (A) until the boom is against it.
    push_key(SDL_SCANCODE_A, 1);
    CHECK(run_for(s, &wall, 5.0) == 0, "loop: %s", drive_session_error(s));
    char text[1024];
    hud_warnings(s, text, sizeof text);
    const world_snapshot* snap = drive_session_snapshot(s);
    CHECK(strstr(text, "RELIEF OPEN: slew_relief_") && strstr(text, "(slew "), "slewing into the wall: '%s'", text);
    CHECK(!strstr(text, "MAIN RELIEF") && !strstr(text, "main_relief"), "slewing into the wall: '%s'", text);
    CHECK(snap->ncyl == 3 && snap->cyl[2].relief_open && !snap->cyl[0].relief_open && !snap->cyl[1].relief_open,
          "per-cylinder relief flags lift %d jib %d slew %d", snap->cyl[0].relief_open, snap->cyl[1].relief_open,
          snap->ncyl > 2 ? snap->cyl[2].relief_open : -1);
    // The pressure bars stay clear of the warnings stacked at the top centre
    // (they were drawn under them, the jib's hidden by the relief line).
    {
        char w[RENDER_WARN_MAX][RENDER_WARN_LEN];
        render* r = drive_session_render_ctx(s);
        const int nw = render_hud_warnings(r, snap, w, RENDER_WARN_MAX);
        int covered = 0;
        for (int cyl = 0; cyl < snap->ncyl; ++cyl)
            for (int ch = 0; ch < 2; ++ch) {
                int rc[4];
                // The widest line (35 characters at 2x stb_easy_font) spans
                // about 640 +- 200 px; each line is 30 px high from y = 5.
                if (render_hud_bar_rect(r, cyl, ch, rc) && rc[0] < 840 && rc[0] + rc[2] > 440 &&
                    rc[1] - 14 < 5 + 30 * nw)
                    ++covered;
            }
        CHECK(covered == 0, "%d pressure bars under the %d warning lines", covered, nw);
    }
    push_key(SDL_SCANCODE_A, 0);
    drive_session_destroy(s);

    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_LAGRANGE;
    // The overload scenario: 3 t taken out until the lift's trapped A
    // chamber reaches its 25 MPa port relief.
    c.scenario_path = CRANESIM_ASSETS "/scenarios/overload.json";
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = true;
    char err[512];
    s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "lagrange session: %s", err);
    if (!s) return;
    wall = 0;
    bool named = false;
    for (int i = 0; i < 16 && !named; ++i) {
        CHECK(run_for(s, &wall, 0.5) == 0, "loop: %s", drive_session_error(s));
        hud_warnings(s, text, sizeof text);
        named = strstr(text, "RELIEF OPEN: lift_relief_A (lift A)") != NULL;
    }
    snap = drive_session_snapshot(s);
    CHECK(named, "lagrange, overload scenario to t = %.1f s: '%s'", snap->t, text);
    CHECK(snap->cyl[0].relief_open, "lift relief flag");
    drive_session_destroy(s);
}


// Tap a key: down on one tick, up on the next.
static void tap_key(drive_session* s, double* wall, SDL_Scancode sc) {
    push_key(sc, 1);
    run_for(s, wall, 1.0 / 240.0);
    push_key(sc, 0);
    run_for(s, wall, 1.0 / 240.0);
}

// H with no load in reach says so in the status line (the HUD), naming the
// nearest load and its distance; the hook stays empty. The pads' forces and
// the margin reach the snapshot, no pad is flagged at rest, and a flagged
// pad gives the HUD's warning and one console line per event.
// The status line the next frame shows (a frame is drawn only when the
// last one has finished).
static const char* status_now(drive_session* s, double* wall) {
    render_wait(drive_session_render_ctx(s), 1.0);
    run_for(s, wall, 2.0 / 240.0);
    return render_get_status(drive_session_render_ctx(s));
}

static void test_hook_feedback_and_pads(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    CHECK(run_for(s, &wall, 0.5) == 0, "loop: %s", drive_session_error(s));
    // The pick-and-place start has load_200 under the hook: H hooks it and
    // says so, H again lets it go.
    tap_key(s, &wall, SDL_SCANCODE_H);
    const char* st = status_now(s, &wall);
    CHECK(strstr(st, "hooked load_200 (200 kg)"), "status after H: '%s'", st);
    tap_key(s, &wall, SDL_SCANCODE_H);
    st = status_now(s, &wall);
    CHECK(strstr(st, "released the load"), "status after H again: '%s'", st);
    // Lift for 2 s: the hook rises out of reach; H then says so.
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 2.0);
    push_key(SDL_SCANCODE_UP, 0);
    run_for(s, &wall, 1.0);
    tap_key(s, &wall, SDL_SCANCODE_H);
    st = status_now(s, &wall);
    CHECK(strstr(st, "no load in reach of the hook (nearest: load_200,") && strstr(st, "m away; reach 0.50 m)"),
          "status after H out of reach: '%s'", st);
    const world_snapshot* snap = drive_session_snapshot(s);
    CHECK(!snap->attached, "nothing hooked");
    CHECK(snap->npad == 4, "four pads: %d", snap->npad);
    const double sum = snap->pad_F[0] + snap->pad_F[1] + snap->pad_F[2] + snap->pad_F[3];
    CHECK(sum > 6.5e4 && sum < 7.5e4, "pads carry the rig: %.0f N", sum);
    CHECK(snap->pad_lifted == 0 && snap->stab_margin > 1, "at rest: lifted %d, margin %.2f", snap->pad_lifted,
          snap->stab_margin);
    char text[1024];
    hud_warnings(s, text, sizeof text);
    CHECK(!strstr(text, "PAD LIFTED"), "no pad warning at rest: '%s'", text);
    // A copy with the rear-left pad flagged: the warning names it, and the
    // console event comes once.
    static world_snapshot lifted;
    lifted = *snap;
    lifted.pad_lifted = 1 << 2;
    char w[RENDER_WARN_MAX][RENDER_WARN_LEN];
    const int k = render_hud_warnings(drive_session_render_ctx(s), &lifted, w, RENDER_WARN_MAX);
    int found = 0;
    for (int i = 0; i < k; ++i) found |= strstr(w[i], "PAD LIFTED OFF: RL") != NULL;
    CHECK(found, "the HUD warns of the lifted pad");
    int prev = 0;
    char note[192];
    CHECK(render_pad_event(&lifted, &prev, note, sizeof note) == 1 && strstr(note, "RL"), "event: '%s'", note);
    CHECK(render_pad_event(&lifted, &prev, note, sizeof note) == 0, "once per event");
    drive_session_destroy(s);
}

// The limiter's HUD line (issue 25, item 19): where it cuts a command, the
// operator's own demand beside what went through. 1300 kg at the tip in the
// validation world, the jib out at full command (tests/app/data): the
// limiter stops the jib within 0.5 s, before the chart's cliff. And the pad
// line says what a lifted pad means for stability, instead of "PAD LIFTED
// OFF (margin 2.04)", which read as a contradiction.
static void test_limiter_hud_shows_demand(void) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "validation";
    c.sim.rcl = true; // as `drive` has it
    c.scenario_path = CRANESIM_TESTDATA "/rcl_overload.json";
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = true;
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    double wall = 0;
    CHECK(run_for(s, &wall, 1.6) == 0, "loop: %s", drive_session_error(s));
    char text[1024];
    hud_warnings(s, text, sizeof text);
    const world_snapshot* snap = drive_session_snapshot(s);
    printf("  limiter cutting the jib: '%s'\n", text);
    CHECK(snap->ncyl >= 2 && snap->cyl[1].rcl_cut && snap->cyl[1].u_op == 1.0 && snap->cyl[1].u_cmd < 0.5,
          "jib: cut %d, demand %g, let through %g", snap->cyl[1].rcl_cut, snap->cyl[1].u_op, snap->cyl[1].u_cmd);
    char want[128];
    snprintf(want, sizeof want, "%s: demand +100 %%, let through %+.0f %%", snap->cyl[1].name, 100 * snap->cyl[1].u_cmd);
    CHECK(strstr(text, "RATED CAPACITY") && strstr(text, want), "the warning lacks '%s': '%s'", want, text);
    CHECK(!snap->cyl[0].rcl_cut, "the lift was not commanded, yet flagged as cut");
    // The pad line on copies of a snapshot: one pad at a margin of 2.04, two at 0.95.
    static world_snapshot p;
    p = *snap;
    p.npad = 4;
    p.pad_lifted = 1 << 2;
    p.stab_margin = 2.04;
    char w[RENDER_WARN_MAX][RENDER_WARN_LEN];
    int k = render_hud_warnings(drive_session_render_ctx(s), &p, w, RENDER_WARN_MAX);
    int found = 0;
    for (int i = 0; i < k; ++i)
        found |= strstr(w[i], "PAD LIFTED OFF: RL - on three pads, not tipping (tipping margin 2.04)") != NULL;
    CHECK(found, "one pad lifted at a margin of 2.04: no or another pad line");
    p.pad_lifted = (1 << 2) | (1 << 3);
    p.stab_margin = 0.95;
    k = render_hud_warnings(drive_session_render_ctx(s), &p, w, RENDER_WARN_MAX);
    found = 0;
    for (int i = 0; i < k; ++i) found |= strstr(w[i], "PAD LIFTED OFF: RL RR - tipping margin 0.95") != NULL;
    CHECK(found, "two pads lifted at 0.95: no or another pad line");
    drive_session_destroy(s);
}

// The real-time factor after a reset (R), a rebuild (a solver change) and a
// pause is the simulation's own rate, 1.00 on a virtual clock that the loop
// keeps up with: it divided the time since the reset by the wall time since
// the start ("RT 0.33x" and "CANNOT KEEP UP" for ever). The session's totals
// add the pieces up (the exit summary).
static void test_rt_factor_after_reset_rebuild_and_pause(void) {
    drive_session* s = open_validation(true, NULL);
    if (!s) return;
    double wall = 0;
    char text[1024];
    CHECK(run_for(s, &wall, 2.0) == 0, "loop: %s", drive_session_error(s));
    tap_key(s, &wall, SDL_SCANCODE_R);
    double row[SIM_NCOL];
    drive_session_row(s, row);
    CHECK(row[COL_T] < 0.05, "after R the run starts again: t = %.3f s", row[COL_T]);
    CHECK(run_for(s, &wall, 1.0) == 0, "loop: %s", drive_session_error(s));
    hud_warnings(s, text, sizeof text);
    double rt = drive_session_snapshot(s)->rt_factor;
    CHECK(rt > 0.97 && rt < 1.03, "RT after a reset: %.3f", rt);
    CHECK(!strstr(text, "CANNOT KEEP UP"), "after a reset: '%s'", text);
    // A solver change rebuilds the world; time goes on.
    char msg[256];
    CHECK(panel_set(drive_session_panel(s), "solver/method", 1, msg, sizeof msg) == PANEL_OK, "%s", msg);
    const double t_before = drive_session_snapshot(s)->t;
    CHECK(run_for(s, &wall, 1.0) == 0, "loop: %s", drive_session_error(s));
    hud_warnings(s, text, sizeof text);
    rt = drive_session_snapshot(s)->rt_factor;
    CHECK(rt > 0.97 && rt < 1.03, "RT after a solver change: %.3f", rt);
    CHECK(drive_session_snapshot(s)->t > t_before + 0.9, "time after the rebuild %.3f s, before %.3f s",
          drive_session_snapshot(s)->t, t_before);
    CHECK(!strstr(text, "CANNOT KEEP UP"), "after a solver change: '%s'", text);
    // Paused for 1 s, then 1 s running: still 1.00.
    tap_key(s, &wall, SDL_SCANCODE_P);
    run_for(s, &wall, 1.0);
    tap_key(s, &wall, SDL_SCANCODE_P);
    run_for(s, &wall, 1.0);
    hud_warnings(s, text, sizeof text);
    rt = drive_session_snapshot(s)->rt_factor;
    CHECK(rt > 0.97 && rt < 1.03, "RT after a pause: %.3f", rt);
    CHECK(!strstr(text, "CANNOT KEEP UP"), "after a pause: '%s'", text);
    // Totals: every piece's simulated time, against the wall time less the pause.
    const drive_stats* st = drive_session_stats(s);
    CHECK(fabs(st->sim_time - (st->wall_time - st->paused_time)) < 0.05 && fabs(st->paused_time - 1.0) < 0.02,
          "summary: simulated %.3f s in %.3f s wall, %.3f s paused", st->sim_time, st->wall_time, st->paused_time);
    drive_session_destroy(s);
}


static bool file_is(const char* path, const char* text) {
    char buf[64] = "";
    FILE* f = fopen(path, "r");
    if (!f) return false;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return !strcmp(buf, text);
}

// "save model" wrote ./cranesim_model_saved.json over whatever was there.
// Now each save takes a new name (cranesim_model_N.json, N past the files
// that exist), says it in the status line, and never touches an existing
// file; with --save-as it writes the named file.
static void test_save_model_never_overwrites(void) {
    char dir[] = "/tmp/cranesim_save_XXXXXX", cwd[1024];
    CHECK(mkdtemp(dir) != NULL && getcwd(cwd, sizeof cwd) != NULL, "temp dir");
    CHECK(chdir(dir) == 0, "chdir %s", dir);
    FILE* f = fopen("cranesim_model_1.json", "w");
    if (f) fputs("keep me", f), fclose(f);
    f = fopen("cranesim_model_saved.json", "w");
    if (f) fputs("keep me too", f), fclose(f);
    drive_session* s = open_validation(true, NULL);
    if (s) {
        render* r = drive_session_render_ctx(s);
        double wall = 0;
        CHECK(panel_run_action(drive_session_panel(s), "save model"), "save action");
        render_wait(drive_session_render_ctx(s), 1.0); // the next tick draws a frame with the status
        run_for(s, &wall, 0.05);
        CHECK(strstr(render_get_status(r), "model saved to cranesim_model_2.json") != NULL, "status: '%s'",
              render_get_status(r));
        CHECK(panel_run_action(drive_session_panel(s), "save model"), "save action");
        render_wait(drive_session_render_ctx(s), 1.0); // the next tick draws a frame with the status
        run_for(s, &wall, 0.05);
        CHECK(strstr(render_get_status(r), "cranesim_model_3.json") != NULL, "status: '%s'", render_get_status(r));
        CHECK(file_is("cranesim_model_1.json", "keep me") && file_is("cranesim_model_saved.json", "keep me too"),
              "an existing file was overwritten");
        // The saved file is the model: it loads back.
        char err[512];
        model* m = model_load("cranesim_model_2.json", NULL, 0, err, sizeof err);
        CHECK(m != NULL, "saved model loads: %s", err);
        model_free(m);
        drive_session_destroy(s);
    }
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "validation";
    c.scenario_path = CRANESIM_ASSETS "/scenarios/drive_demo.json";
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.save_as = "mine.json";
    char err[512];
    s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (s) {
        CHECK(panel_run_action(drive_session_panel(s), "save model"), "save action");
        double wall = 0;
        render_wait(drive_session_render_ctx(s), 1.0); // the next tick draws a frame with the status
        run_for(s, &wall, 0.05);
        const char* st = render_get_status(drive_session_render_ctx(s));
        CHECK(strstr(st, "model saved to mine.json") != NULL, "status: '%s'", st);
        model* m = model_load("mine.json", NULL, 0, err, sizeof err);
        CHECK(m != NULL, "--save-as model loads: %s", err);
        model_free(m);
        CHECK(access("cranesim_model_4.json", F_OK) != 0, "--save-as also took a new name");
        drive_session_destroy(s);
    }
    const char* names[] = {"cranesim_model_1.json", "cranesim_model_2.json", "cranesim_model_3.json",
                           "cranesim_model_saved.json", "mine.json"};
    for (int i = 0; i < 5; ++i) remove(names[i]);
    CHECK(chdir(cwd) == 0 && rmdir(dir) == 0, "clean up %s", dir);
}


static void push_text(const char* text) {
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = SDL_TEXTINPUT;
    snprintf(ev.text.text, sizeof ev.text.text, "%s", text);
    SDL_PushEvent(&ev);
}

// A tick, then a frame (the panel sees events at ticks and decides at frames).
static void tick_and_draw(drive_session* s, double* wall) {
    run_for(s, wall, 1.0 / 240.0);
    drive_session_render(s);
}

// Ctrl+click a value in the panel, type, Enter: the value is set, and the
// keyboard goes back to the crane at once (it stayed with the panel, and the
// crane ignored every key until the 3D view was clicked, with nothing
// saying why: an Enter pressed and released between two frames never
// reached ImGui). While typing, the panel says it has the keyboard.
static void test_panel_gives_the_keyboard_back(void) {
    drive_session* s = open_session();
    if (!s) return;
    panel* pn = drive_session_panel(s);
    render* r = drive_session_render_ctx(s);
    double wall = 0;
    tap_key(s, &wall, SDL_SCANCODE_TAB); // show the panel
    // The whole model's list is longer than the window: the filter box
    // brings the end arm up, as an operator would.
    panel_set_filter(pn, "end_arm");
    tick_and_draw(s, &wall);
    tick_and_draw(s, &wall);
    const int id = panel_find(pn, "end_arm (link)/mass");
    float rect[4];
    CHECK(panel_gui_item_rect(pn, id, rect), "end arm mass widget drawn");
    // The mouse over the widget (SDL's own state, which the ImGui backend
    // polls), Ctrl held, a click.
    SDL_WarpMouseInWindow(render_window(r), (int)(rect[0] + 0.5f * rect[2]), (int)(rect[1] + 0.5f * rect[3]));
    tick_and_draw(s, &wall);
    SDL_SetModState(KMOD_LCTRL);
    push_key(SDL_SCANCODE_LCTRL, 1);
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = SDL_MOUSEBUTTONDOWN;
    ev.button.button = SDL_BUTTON_LEFT;
    ev.button.state = SDL_PRESSED;
    ev.button.x = (int)(rect[0] + 0.5f * rect[2]);
    ev.button.y = (int)(rect[1] + 0.5f * rect[3]);
    SDL_PushEvent(&ev);
    tick_and_draw(s, &wall);
    ev.type = SDL_MOUSEBUTTONUP;
    ev.button.state = SDL_RELEASED;
    SDL_PushEvent(&ev);
    SDL_SetModState(KMOD_NONE);
    push_key(SDL_SCANCODE_LCTRL, 0);
    tick_and_draw(s, &wall);
    CHECK(panel_gui_wants_keyboard(pn), "Ctrl+click: the panel has the keyboard");
    render_wait(r, 1.0); // the next tick draws a frame with the status
    run_for(s, &wall, 0.05);
    CHECK(strstr(render_get_status(r), "[keys: panel") != NULL, "status while typing: '%s'", render_get_status(r));
    push_text("150");
    tick_and_draw(s, &wall);
    // A quick key press, as a fast typist or xdotool makes it: down and up
    // between two frames. ImGui 1.86 reads key states once per frame, so it
    // never saw this Enter, the field stayed active and kept the keyboard.
    push_key(SDL_SCANCODE_RETURN, 1);
    push_key(SDL_SCANCODE_RETURN, 0);
    tick_and_draw(s, &wall);
    tick_and_draw(s, &wall);
    tick_and_draw(s, &wall);
    const double m2 = drive_session_model(s)->mech.link[1].mass;
    CHECK(m2 == 150, "typed 150 kg: end arm mass %g kg", m2);
    CHECK(!panel_gui_wants_keyboard(pn), "after Enter the panel still has the keyboard");
    // The crane's keys work again: Up lifts.
    const double x0 = lift_stroke(s);
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 1.5);
    push_key(SDL_SCANCODE_UP, 0);
    run_for(s, &wall, 0.1);
    CHECK(lift_stroke(s) > x0 + 0.02, "Up after Enter: lift stroke %.4f -> %.4f m", x0, lift_stroke(s));
    drive_session_destroy(s);
}


// What the panel's window does for a mouse drag of n pixels to the right on
// parameter id: the widget moves by panel_drag_speed per pixel and reports
// each step (done = false), then the release (done = true). A tick per pixel.
static double drag(drive_session* s, double* wall, int id, int pixels) {
    panel* pn = drive_session_panel(s);
    double v = panel_get(pn, id);
    for (int i = 0; i < pixels; ++i) {
        v += panel_drag_speed(pn, id);
        panel_edit(pn, id, v, false);
        run_for(s, wall, 1.0 / 240.0);
    }
    panel_edit(pn, id, v, true);
    run_for(s, wall, 1.0 / 240.0);
    return v;
}

// A session holding still (hold scenario's pose, valves closed, no tip
// load) in the lagrange view or the validation world.
static drive_session* open_hold(bool ode, const char* record) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = ode ? SIM_ODE : SIM_LAGRANGE;
    if (ode) c.sim.world = "validation";
    c.sim.load_mass = 0;
    c.scenario_path = CRANESIM_ASSETS "/scenarios/hold.json";
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = true;
    o.record_path = record;
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "hold session: %s", err);
    return s;
}

// A 50 px drag on the lifting arm's mass: 0.5 % of the value per pixel
// (180 kg * 1.005^50 = 231 kg; the slider gave 664 kg through 11 rebuilds),
// applied in place in both backends (no rebuild: time and loads go on; the
// ode world rebuilt at every pixel), and it acts: the trapped lift chamber's
// pressure rises by the same amount in the ode world (dBodySetMass) as in
// the lagrange model (measured: 0.1036 and 0.1037 MPa).
static void test_boom_mass_drag_in_place(void) {
    double dp[2] = {0, 0};
    for (int ode = 0; ode < 2; ++ode) {
        drive_session* s = open_hold(ode, NULL);
        if (!s) return;
        double wall = 0, row[SIM_NCOL];
        CHECK(run_for(s, &wall, 2.0) == 0, "loop: %s", drive_session_error(s));
        drive_session_row(s, row);
        const double p0 = row[COL_P1A], t0 = row[COL_T];
        const int id = panel_find(drive_session_panel(s), "lifting_arm (link)/mass");
        const double m0 = panel_get(drive_session_panel(s), id);
        const double m1 = drag(s, &wall, id, 50);
        CHECK(fabs(m1 / m0 - pow(1.0 + PANEL_DRAG_REL, 50)) < 1e-9 && m1 < 1.3 * m0, "%s: 50 px took %.1f to %.1f kg",
              ode ? "ode" : "lagrange", m0, m1);
        CHECK(drive_session_model(s)->mech.link[0].mass == m1, "model mass %g", drive_session_model(s)->mech.link[0].mass);
        CHECK(drive_session_stats(s)->rebuilds == 0, "%s: %ld rebuilds for a mass", ode ? "ode" : "lagrange",
              drive_session_stats(s)->rebuilds);
        drive_session_row(s, row);
        CHECK(row[COL_T] > t0 + 0.2, "%s: time went on: %.3f -> %.3f s", ode ? "ode" : "lagrange", t0, row[COL_T]);
        CHECK(run_for(s, &wall, 3.0) == 0, "loop: %s", drive_session_error(s));
        drive_session_row(s, row);
        dp[ode] = row[COL_P1A] - p0;
        drive_session_destroy(s);
    }
    // About 51 kg more on the lifting arm: a few tenths of a MPa in the
    // 100 mm bore at this pose; the two backends within 5 %.
    CHECK(dp[0] > 0.05e6, "lagrange: lift pA rose by %.3f MPa", dp[0] * 1e-6);
    CHECK(fabs(dp[1] - dp[0]) < 0.05 * dp[0], "lift pA rise: ode %.4f MPa, lagrange %.4f MPa", dp[1] * 1e-6,
          dp[0] * 1e-6);
}

// A length cannot change in place in the ode world: a drag shows the value
// and applies it once, on release (one rebuild, not one per pixel), the
// status says so, time goes on, and the record marks it: `segment` 0 before,
// 1 after, t never going back.
static void test_length_rebuilds_once_on_release(void) {
    const char* rec = "drive_rebuild_record.csv";
    drive_session* s = open_hold(true, rec);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 1.0);
    panel* pn = drive_session_panel(s);
    const int id = panel_find(pn, "lifting_arm (link)/length");
    CHECK(panel_on_release(pn, id), "length applies on release in the ode world");
    const double L0 = drive_session_model(s)->mech.link[0].length;
    // Half the drag, not released: nothing applied yet.
    double v = panel_get(pn, id);
    for (int i = 0; i < 10; ++i) {
        v += panel_drag_speed(pn, id);
        panel_edit(pn, id, v, false);
        run_for(s, &wall, 1.0 / 240.0);
    }
    double pend = 0;
    CHECK(panel_pending(pn, id, &pend) && pend == v, "pending %g", pend);
    CHECK(drive_session_model(s)->mech.link[0].length == L0 && drive_session_stats(s)->rebuilds == 0,
          "applied before release: %g m, %ld rebuilds", drive_session_model(s)->mech.link[0].length,
          drive_session_stats(s)->rebuilds);
    panel_edit(pn, id, v, true);
    run_for(s, &wall, 1.0 / 240.0);
    CHECK(fabs(drive_session_model(s)->mech.link[0].length - v * 1e-3) < 1e-12 && drive_session_stats(s)->rebuilds == 1,
          "after release: %g m, %ld rebuilds", drive_session_model(s)->mech.link[0].length,
          drive_session_stats(s)->rebuilds);
    render_wait(drive_session_render_ctx(s), 1.0);
    run_for(s, &wall, 0.5);
    const char* st = render_get_status(drive_session_render_ctx(s));
    CHECK(strstr(st, "world rebuilt at t = ") && strstr(st, "lifting_arm (link)/length"), "status: '%s'", st);
    char err[320];
    long rows = 0;
    CHECK(drive_session_finish_record(s, &rows, err, sizeof err) == 0, "record: %s", err);
    drive_session_destroy(s);
    FILE* f = fopen(rec, "r");
    CHECK(f != NULL, "record %s", rec);
    if (!f) return;
    char line[4096];
    CHECK(fgets(line, sizeof line, f) && strstr(line, ",segment\n"), "header ends in segment: %s", line);
    double t_prev = -1;
    int seg_prev = 0, changes = 0, back = 0, n = 0;
    while (fgets(line, sizeof line, f)) {
        const double t = strtod(line, NULL);
        const char* last = strrchr(line, ',');
        const int seg = last ? atoi(last + 1) : -1;
        back += t < t_prev;
        changes += seg != seg_prev;
        t_prev = t, seg_prev = seg, ++n;
    }
    fclose(f);
    remove(rec);
    CHECK(n == rows && changes == 1 && seg_prev == 1 && back == 0,
          "%d rows (%ld reported), segment changes %d, last segment %d, t went back %d times", n, rows, changes,
          seg_prev, back);
}

// A rebuild that fails leaves the running world as it was, and the panel
// and the model say so: a longer lifting arm with the lift on its end stop
// cannot be built at that pose; the model kept the new length, the panel
// showed it, and the next rebuild (a solver change) brought it in unasked.
static void test_failed_rebuild_keeps_the_running_world(void) {
    drive_session* s = open_session();
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.5);
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 9.0);
    push_key(SDL_SCANCODE_UP, 0);
    run_for(s, &wall, 0.5);
    panel* pn = drive_session_panel(s);
    const int id = panel_find(pn, "lifting_arm (link)/length");
    const double L0 = drive_session_model(s)->mech.link[0].length;
    panel_edit(pn, id, (L0 + 0.33) / 1e-3, true); // the panel shows mm
    run_for(s, &wall, 1.0 / 240.0);
    render_wait(drive_session_render_ctx(s), 1.0);
    run_for(s, &wall, 0.5);
    const char* st = render_get_status(drive_session_render_ctx(s));
    CHECK(strstr(st, "rebuild failed"), "lift at x1 = %.4f m: the longer arm was built: '%s'", lift_stroke(s), st);
    CHECK(drive_session_model(s)->mech.link[0].length == L0 && panel_get(pn, id) == L0 / 1e-3,
          "after the failed rebuild: model %g m, panel %g m, want %g", drive_session_model(s)->mech.link[0].length,
          panel_get(pn, id), L0);
    double before[SIM_NCOL], after[SIM_NCOL];
    drive_session_row(s, before);
    const int is = panel_find(pn, "solver/method");
    panel_edit(pn, is, 1, true); // ROS2: one rebuild at the current pose
    run_for(s, &wall, 1.0 / 240.0);
    render_wait(drive_session_render_ctx(s), 1.0);
    run_for(s, &wall, 0.5);
    drive_session_row(s, after);
    CHECK(drive_session_model(s)->mech.link[0].length == L0 && fabs(after[COL_TIP_X] - before[COL_TIP_X]) < 0.01,
          "the solver's rebuild: arm %g m, tip_x %.3f -> %.3f m", drive_session_model(s)->mech.link[0].length,
          before[COL_TIP_X], after[COL_TIP_X]);
    drive_session_destroy(s);
}

// A pause holds simulated time, and the record has no row for the held
// instants: a 4 s pause wrote 196 rows at the same t.
static void test_pause_writes_no_rows(void) {
    const char* rec = "drive_pause_record.csv";
    drive_session* s = open_hold(true, rec);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.5);
    tap_key(s, &wall, SDL_SCANCODE_P);
    run_for(s, &wall, 1.0);
    tap_key(s, &wall, SDL_SCANCODE_P);
    run_for(s, &wall, 0.5);
    char err[320];
    long rows = 0;
    CHECK(drive_session_finish_record(s, &rows, err, sizeof err) == 0, "record: %s", err);
    drive_session_destroy(s);
    FILE* f = fopen(rec, "r");
    CHECK(f != NULL, "record %s", rec);
    if (!f) return;
    char line[4096];
    int n = 0, repeated = 0;
    double t_prev = -1;
    if (fgets(line, sizeof line, f))
        while (fgets(line, sizeof line, f)) {
            const double t = strtod(line, NULL);
            repeated += !(t > t_prev);
            t_prev = t, ++n;
        }
    fclose(f);
    remove(rec);
    CHECK(n == rows && n > 100 && repeated == 0, "%d rows (%ld reported), %d at a time not after the one before", n,
          rows, repeated);
}

// The solver is a choice of names, not a slider: five options, half an
// index is refused, and a choice that cannot run here (RK4 at the 0.1 ms
// step is unstable for this circuit) keeps the running solver and says why.
static void test_solver_is_a_choice(void) {
    drive_session* s = open_hold(true, NULL);
    if (!s) return;
    panel* pn = drive_session_panel(s);
    const int id = panel_find(pn, "solver/method");
    CHECK(panel_choice_count(pn, id) == 5 && !strcmp(panel_choice_label(pn, id, 0), "Krus") &&
              !strcmp(panel_choice_label(pn, id, 1), "ROS2"),
          "solver options: %d", panel_choice_count(pn, id));
    char msg[256];
    CHECK(panel_set(pn, "solver/method", 0.5, msg, sizeof msg) == PANEL_OUT_OF_RANGE, "half an option accepted");
    double wall = 0;
    CHECK(panel_set(pn, "solver/method", 2, msg, sizeof msg) == PANEL_OK, "%s", msg); // RK4
    run_for(s, &wall, 1.0 / 240.0);
    render_wait(drive_session_render_ctx(s), 1.0);
    run_for(s, &wall, 0.1);
    const char* st = render_get_status(drive_session_render_ctx(s));
    CHECK(strstr(st, "rebuild failed (krus kept)") != NULL, "status: '%s'", st);
    CHECK(panel_get(pn, id) == 0, "the panel shows option %g, the world runs Krus", panel_get(pn, id));
    CHECK(run_for(s, &wall, 0.5) == 0, "still running: %s", drive_session_error(s));
    drive_session_destroy(s);
}


// The strip charts cover the bottom 144 px of a 720 px frame (hud.c).
#define CHART_TOP (720 - 144)

static const world_snap_body* nearest_load(const world_snapshot* snap) {
    const world_snap_body* best = NULL;
    double bd = 1e30;
    for (int i = 0; i < snap->nbody; ++i)
        if (snap->body[i].role == WORLD_ROLE_LOAD) {
            const double d = dist3(snap->body[i].pos, snap->hook);
            if (d < bd) bd = d, best = &snap->body[i];
        }
    return best;
}

// The default view shows the hook and the load it works with above the
// strip charts, at the start and with the 200 kg block hanging at 8 s of the
// pick-and-place (it was drawn behind the charts).
static void test_default_view_shows_hook_and_load(void) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = true;
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    render* r = drive_session_render_ctx(s);
    double wall = 0;
    const double at[] = {0.5, 4, 8, 12, 16, 20, 24};
    for (int k = 0; k < (int)(sizeof at / sizeof at[0]); ++k) {
        CHECK(run_for(s, &wall, at[k] - wall) == 0, "loop: %s", drive_session_error(s));
        drive_session_render(s);
        const world_snapshot* snap = drive_session_snapshot(s);
        const world_snap_body* load = nearest_load(snap);
        CHECK(load != NULL, "a load");
        if (!load) break;
        double ph[2], pl[2];
        const bool okh = render_project(r, snap->hook, ph), okl = render_project(r, load->pos, pl);
        CHECK(okh && ph[0] > 0 && ph[0] < 1280 && ph[1] > 0 && ph[1] < CHART_TOP - 20,
              "t = %.1f s: hook at (%.0f, %.0f) px, charts from y = %d", snap->t, ph[0], ph[1], CHART_TOP);
        CHECK(okl && pl[0] > 0 && pl[0] < 1280 && pl[1] > 0 && pl[1] < CHART_TOP - 20,
              "t = %.1f s: %s at (%.0f, %.0f) px, charts from y = %d", snap->t, load->name, pl[0], pl[1], CHART_TOP);
    }
    drive_session_destroy(s);
}

// Segment p-q against body b's drawn box (its frame), grown by m [m].
static bool segment_hits_box(render* r, const world_snap_body* b, const double p[3], const double q[3], double m) {
    double lo[3], hi[3];
    if (!render_body_bounds(r, b, lo, hi)) return false;
    double a[3], d[3];
    for (int k = 0; k < 3; ++k) {
        const double u[3] = {p[0] - b->pos[0], p[1] - b->pos[1], p[2] - b->pos[2]};
        const double v[3] = {q[0] - b->pos[0], q[1] - b->pos[1], q[2] - b->pos[2]};
        a[k] = b->rot[k] * u[0] + b->rot[3 + k] * u[1] + b->rot[6 + k] * u[2];
        d[k] = b->rot[k] * v[0] + b->rot[3 + k] * v[1] + b->rot[6 + k] * v[2] - a[k];
    }
    double t0 = 0, t1 = 1;
    for (int k = 0; k < 3; ++k) {
        const double l = lo[k] - m, h = hi[k] + m;
        if (fabs(d[k]) < 1e-12) {
            if (a[k] < l || a[k] > h) return false;
            continue;
        }
        double ta = (l - a[k]) / d[k], tb = (h - a[k]) / d[k];
        if (ta > tb) {
            const double t = ta;
            ta = tb, tb = t;
        }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
        if (t0 > t1) return false;
    }
    return true;
}

// No preset puts the eye inside the truck, an outrigger, a load or an
// obstacle, and the operator sees tip and hook past the truck, not through
// its bed and cab from a metre away (it stood 2.1 m out on the right side
// whatever the slew: with the boom slewed left, against the wall, the
// picture was the inside of the truck).
static void test_presets_keep_out_of_the_truck(void) {
    drive_session* s = open_session();
    if (!s) return;
    render* r = drive_session_render_ctx(s);
    double wall = 0;
    // Start pose (boom right, -60 deg), then slewed left against wall_slew.
    for (int pass = 0; pass < 2; ++pass) {
        if (pass) {
            push_key(SDL_SCANCODE_A, 1);
            run_for(s, &wall, 5.0);
            push_key(SDL_SCANCODE_A, 0);
        }
        run_for(s, &wall, 0.5);
        for (int p = 0; p < RENDER_CAM_COUNT; ++p) {
            render_set_camera_preset(r, (render_cam_preset)p);
            drive_session_render(s);
            const world_snapshot* snap = drive_session_snapshot(s);
            double eye[3], look[3];
            render_camera_eye(r, eye, look);
            for (int i = 0; i < snap->nbody; ++i) {
                const world_snap_body* b = &snap->body[i];
                const world_role ro = b->role;
                if (ro != WORLD_ROLE_TRUCK && ro != WORLD_ROLE_OUTRIGGER && ro != WORLD_ROLE_WHEEL &&
                    ro != WORLD_ROLE_LOAD && ro != WORLD_ROLE_OBSTACLE)
                    continue;
                CHECK(!segment_hits_box(r, b, eye, eye, 0.2), "pass %d preset %d: eye (%.2f, %.2f, %.2f) in %s", pass,
                      p, eye[0], eye[1], eye[2], b->name);
                if (p == RENDER_CAM_OPERATOR && ro == WORLD_ROLE_TRUCK)
                    CHECK(!segment_hits_box(r, b, eye, look, 0.0),
                          "pass %d: the operator at (%.2f, %.2f, %.2f) looks through the truck at (%.2f, %.2f, %.2f)",
                          pass, eye[0], eye[1], eye[2], look[0], look[1], look[2]);
            }
        }
    }
    render_set_camera_preset(r, RENDER_CAM_ORBIT);
    drive_session_destroy(s);
}


// The sandbox's slew valve belongs to the world's circuit, not the model's:
// the panel lacked it. Now it is there, acts on the running circuit, and
// survives a reset (a new world from the world file).
static void test_slew_valve_in_the_panel(void) {
    drive_session* s = open_session();
    if (!s) return;
    panel* pn = drive_session_panel(s);
    CHECK(panel_find(pn, "slew_valve (valve)/q_nominal") >= 0, "no slew valve in the panel");
    char msg[256];
    CHECK(panel_set(pn, "slew_valve (valve)/q_nominal", 12.0, msg, sizeof msg) == PANEL_OK, "%s", msg);
    double wall = 0, v = 0;
    run_for(s, &wall, 0.1);
    CHECK(hyd_model_get(engine_circuit(drive_session_engine(s)), "slew_valve.q_nominal", &v) == 0 &&
              fabs(v - 12.0 / 60000.0) < 1e-12,
          "slew valve q_nominal %g m^3/s", v);
    tap_key(s, &wall, SDL_SCANCODE_R);
    v = 0;
    CHECK(hyd_model_get(engine_circuit(drive_session_engine(s)), "slew_valve.q_nominal", &v) == 0 &&
              fabs(v - 12.0 / 60000.0) < 1e-12,
          "after a reset: slew valve q_nominal %g m^3/s", v);
    drive_session_destroy(s);
}

int main(int argc, char** argv) {
    // Headless: SDL's offscreen video driver on Mesa's EGL (llvmpipe).
    setenv("SDL_VIDEODRIVER", "offscreen", 0);
    setenv("EGL_PLATFORM", "surfaceless", 0);
    setenv("SDL_AUDIODRIVER", "dummy", 0);
    RUN_TEST(test_default_scene_frame);
    RUN_TEST(test_hook_feedback_and_pads);
    RUN_TEST(test_joystick_and_keyboard_drive_the_lift);
    RUN_TEST(test_panel_change_takes_effect);
    RUN_TEST(test_panel_boom_edit);
    RUN_TEST(test_validation_world_drawn_at_the_joints);
    RUN_TEST(test_sandbox_crane_drawn_in_one_piece);
    RUN_TEST(test_charts_and_status_follow_the_world);
    RUN_TEST(test_no_rate_over_an_instant);
    RUN_TEST(test_record_write_failure);
    RUN_TEST(test_open_relief_is_named);
    RUN_TEST(test_rt_factor_after_reset_rebuild_and_pause);
    RUN_TEST(test_pause_writes_no_rows);
    RUN_TEST(test_save_model_never_overwrites);
    RUN_TEST(test_panel_gives_the_keyboard_back);
    RUN_TEST(test_boom_mass_drag_in_place);
    RUN_TEST(test_length_rebuilds_once_on_release);
    RUN_TEST(test_solver_is_a_choice);
    RUN_TEST(test_failed_rebuild_keeps_the_running_world);
    RUN_TEST(test_default_view_shows_hook_and_load);
    RUN_TEST(test_presets_keep_out_of_the_truck);
    RUN_TEST(test_slew_valve_in_the_panel);
    RUN_TEST(test_limiter_hud_shows_demand);
    SDL_Quit();
    TEST_MAIN_END();
}
