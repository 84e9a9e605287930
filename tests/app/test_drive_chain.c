// test_drive_chain.c: the drive window on a crane chain (issue 27): the
// 8-function test crane and loader10 in the sandbox, headless (offscreen GL
// on llvmpipe, a virtual clock). A pressure bar group over every cylinder,
// every function's channels in the charts' choices, the panel by function
// and body with its edits (live, by rebuild, refused), the record's header,
// and the one-line refusal where the engine has no picture.
#include "channels.h"
#include "check.h"
#include "drive_session.h"
#include "panel.h"
#include "render.h"
#include "drive_test_util.h"

#include <SDL2/SDL.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CHAIN8 CRANESIM_TESTDATA "/../../world/data/chain_8fn_10link.json"
#define LOADER10 CRANESIM_ASSETS "/models/loader10.json"
enum { W = 1280, H = 720 };

static drive_session* open_chain(const char* model, const char* world, const char* charts, const char* record,
                                 char* err, size_t errsz) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = world ? world : "sandbox"; // as cmd_drive names the drive's world
    c.model_path = model;
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = true;
    o.width = W;
    o.height = H;
    o.charts = charts;
    o.record_path = record;
    return drive_session_create(&c, &o, err, errsz, NULL);
}

static drive_session* open_ok(const char* model, const char* charts, const char* record) {
    char err[600];
    drive_session* s = open_chain(model, NULL, charts, record, err, sizeof err);
    CHECK(s != NULL, "session on %s: %s", model, err);
    return s;
}

static bool disjoint(const int a[4], const int b[4]) {
    return a[0] + a[2] <= b[0] || b[0] + b[2] <= a[0] || a[1] + a[3] <= b[1] || b[1] + b[3] <= a[1];
}

// The 8-function crane: a snapshot cylinder per actuator and the slew rack,
// and over each a pressure bar per chamber whose filled height is its
// pressure on the 30 MPa full scale (read back from the frame's pixels),
// on screen, clear of the readouts box and of every other cylinder's bars.
static void test_bar_over_every_cylinder(void) {
    drive_session* s = open_ok(CHAIN8, NULL, NULL);
    if (!s) return;
    double wall = 0;
    CHECK(run_for(s, &wall, 0.3) == 0, "drive: %s", drive_session_error(s));
    drive_session_render(s);
    const model* m = drive_session_model(s);
    const world_snapshot* snap = drive_session_snapshot(s);
    CHECK(snap->ncyl == m->chain.nact + 1, "%d cylinders drawn for %d actuators and the slew rack", snap->ncyl,
          m->chain.nact);
    for (int k = 0; k < m->chain.nact && k < snap->ncyl; ++k)
        CHECK(!strcmp(snap->cyl[k].name, m->chain.act[k].name), "cylinder %d is %s, actuator %s", k, snap->cyl[k].name,
              m->chain.act[k].name);
    render* r = drive_session_render_ctx(s);
    if (getenv("DRIVE_CHAIN_SHOT")) drive_session_screenshot(s, getenv("DRIVE_CHAIN_SHOT"), NULL, 0);
    unsigned char* px = malloc((size_t)W * H * 4);
    CHECK(px && render_read_pixels(r, px, W, H) == 0, "read pixels");
    float ro[4] = {0};
    CHECK(render_hud_readouts_rect(r, ro), "readouts drawn");
    const int ro_i[4] = {(int)ro[0], (int)ro[1], (int)ceilf(ro[2]), (int)ceilf(ro[3])};
    int rect[WORLD_SNAP_MAX_CYLINDERS][2][4];
    for (int i = 0; i < snap->ncyl && px; ++i) {
        const world_snap_cylinder* c = &snap->cyl[i];
        const double mid[3] = {0.5 * (c->base[0] + c->rod_end[0]), 0.5 * (c->base[1] + c->rod_end[1]),
                               0.5 * (c->base[2] + c->rod_end[2])};
        double q[2];
        CHECK(render_project(r, mid, q) && q[0] >= 0 && q[0] < W && q[1] >= 0 && q[1] < H,
              "%s: its midpoint is not in view", c->name);
        for (int ch = 0; ch < 2; ++ch) {
            int* rc = rect[i][ch];
            if (!render_hud_bar_rect(r, i, ch, rc)) {
                CHECK(0, "%s: no bar %c", c->name, ch ? 'B' : 'A');
                memset(rc, 0, 4 * sizeof *rc);
                continue;
            }
            CHECK(rc[0] >= 0 && rc[1] >= 0 && rc[0] + rc[2] <= W && rc[1] + rc[3] <= H && rc[2] > 0 && rc[3] > 20,
                  "%s %c: bar at %d,%d %dx%d", c->name, ch ? 'B' : 'A', rc[0], rc[1], rc[2], rc[3]);
            CHECK(disjoint(rc, ro_i), "%s %c: bar under the readouts box", c->name, ch ? 'B' : 'A');
            // Filled pixels (not the empty-bar colour) as the pressure says.
            int n = 0;
            for (int y = rc[1]; y < rc[1] + rc[3] && y < H; ++y)
                for (int x = rc[0]; x < rc[0] + rc[2] && x < W; ++x) {
                    const unsigned char* p = px + ((size_t)y * W + x) * 4;
                    n += ((p[0] << 16) | (p[1] << 8) | p[2]) != RENDER_BAR_EMPTY_RGB;
                }
            double f = (ch ? c->pB : c->pA) / 30e6;
            f = f < 0 ? 0 : f > 1 ? 1 : f;
            CHECK(fabs(n - f * rc[2] * rc[3]) <= rc[2] + 1.0, "%s %c: %d filled pixels for %.2f MPa (expected %.0f; bar at %d,%d %dx%d)",
                  c->name, ch ? 'B' : 'A', n, (ch ? c->pB : c->pA) * 1e-6, f * rc[2] * rc[3], rc[0], rc[1], rc[2], rc[3]);
        }
    }
    for (int i = 0; i < snap->ncyl; ++i)
        for (int j = 0; j < i; ++j)
            for (int a = 0; a < 4; ++a)
                CHECK(disjoint(rect[i][a / 2], rect[j][a % 2]), "bars of %s and %s overlap", snap->cyl[i].name,
                      snap->cyl[j].name);
    free(px);
    drive_session_destroy(s);
}

// Every actuator's stroke and chamber pressures and every function's spool
// are channels of the session (--charts names), the default charts chart
// every cylinder by name, and --charts takes the chain's names, checked
// before the window opens (drive_opts_check) and by the session.
static void test_every_function_charted(void) {
    drive_session* s = open_ok(CHAIN8, NULL, NULL);
    if (!s) return;
    const model* m = drive_session_model(s);
    const chan_list* cl = drive_session_channels(s);
    for (int k = 0; k < m->chain.nact; ++k) {
        static const char* const what[] = {"x_", "pA_", "pB_"};
        for (int w = 0; w < 3; ++w) {
            char nm[96];
            snprintf(nm, sizeof nm, "%s%s", what[w], m->chain.act[k].name);
            CHECK(chan_list_find(cl, nm) > 0, "no channel %s", nm);
        }
    }
    for (int f = 0; f < m->chain.nfn; ++f) {
        char nm[96];
        snprintf(nm, sizeof nm, "u_%s", m->chain.fn[f].name);
        CHECK(chan_list_find(cl, nm) > 0, "no channel %s", nm);
    }
    // The default charts: pA, pB, x, u of every cylinder, named.
    render* r = drive_session_render_ctx(s);
    const world_snapshot* snap = drive_session_snapshot(s);
    CHECK(render_chart_count(r) == 4 * snap->ncyl, "%d default charts for %d cylinders", render_chart_count(r),
          snap->ncyl);
    for (int i = 0; i < snap->ncyl; ++i) {
        char nm[96];
        snprintf(nm, sizeof nm, "pB %s", snap->cyl[i].name);
        bool found = false;
        for (int k = 0; k < render_chart_count(r); ++k) found |= !strcmp(render_chart_label(r, k), nm);
        CHECK(found, "no default chart %s", nm);
    }
    drive_session_destroy(s);

    const char* list = "x_jib_ext3,pA_ext1,u_jib_ext2,q_ext3";
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "sandbox";
    c.model_path = CHAIN8;
    drive_opts o = drive_default_opts();
    o.charts = list;
    char err[600] = "";
    CHECK(drive_opts_check(&c, &o, err, sizeof err) == 0, "--charts %s: %s", list, err);
    o.charts = "x_jib_ext9";
    CHECK(drive_opts_check(&c, &o, err, sizeof err) == EXIT_USAGE && strstr(err, "'x_jib_ext9'") &&
              !strchr(err, '\n'),
          "x_jib_ext9: %s", err);
    s = open_ok(CHAIN8, list, NULL);
    if (!s) return;
    r = drive_session_render_ctx(s);
    CHECK(render_chart_count(r) == 4 && !strcmp(render_chart_label(r, 0), "x_jib_ext3") &&
              !strcmp(render_chart_label(r, 3), "q_ext3"),
          "%d charts", render_chart_count(r));
    double wall = 0;
    CHECK(run_for(s, &wall, 0.2) == 0, "drive: %s", drive_session_error(s));
    // The panel's chart slots: every channel of the session by name, the
    // --charts ones chosen; a slot set to another channel, then every slot
    // back to "(default)", gives those charts.
    panel* pn = drive_session_panel(s);
    const chan_list* ch = drive_session_channels(s);
    const int slot1 = panel_find(pn, "charts/chart 1"), slot5 = panel_find(pn, "charts/chart 5");
    CHECK(slot1 >= 0 && slot5 >= 0 && panel_choice_count(pn, slot1) == chan_list_count(ch) &&
              !strcmp(panel_choice_label(pn, slot1, (int)panel_get(pn, slot1)), "x_jib_ext3") &&
              panel_get(pn, slot5) == 0,
          "chart slots: %d options for %d channels", slot1 >= 0 ? panel_choice_count(pn, slot1) : -1,
          chan_list_count(ch));
    int want = -1;
    for (int k = 0; slot1 >= 0 && k < panel_choice_count(pn, slot1); ++k)
        if (!strcmp(panel_choice_label(pn, slot1, k), "u_jib_ext1")) want = k;
    // Every function's spool and every actuator's stroke among them.
    const model* m2 = drive_session_model(s);
    for (int f = 0; f < m2->chain.nfn + m2->chain.nact; ++f) {
        char nm[96];
        if (f < m2->chain.nfn) snprintf(nm, sizeof nm, "u_%s", m2->chain.fn[f].name);
        else snprintf(nm, sizeof nm, "x_%s", m2->chain.act[f - m2->chain.nfn].name);
        bool found = false;
        for (int k = 0; slot1 >= 0 && k < panel_choice_count(pn, slot1) && !found; ++k)
            found = !strcmp(panel_choice_label(pn, slot1, k), nm);
        CHECK(found, "%s not among the chart choices", nm);
    }
    CHECK(want > 0 && panel_set_id(pn, slot1, want, NULL, 0) == PANEL_OK, "u_jib_ext1 among the chart choices");
    run_for(s, &wall, 0.05);
    CHECK(render_chart_count(r) == 4 && !strcmp(render_chart_label(r, 0), "u_jib_ext1"), "%d charts, first %s",
          render_chart_count(r), render_chart_label(r, 0));
    for (int k = 1; k <= 8; ++k) {
        char key[32];
        snprintf(key, sizeof key, "charts/chart %d", k);
        panel_set_id(pn, panel_find(pn, key), 0, NULL, 0);
    }
    run_for(s, &wall, 0.05);
    CHECK(render_chart_count(r) == 4 * drive_session_snapshot(s)->ncyl, "%d charts back to the default set",
          render_chart_count(r));
    drive_session_destroy(s);
}

static bool has_group_prefix(const panel* pn, const char* prefix) {
    for (int id = 0; id < panel_count(pn); ++id)
        if (!strncmp(panel_group(pn, id), prefix, strlen(prefix))) return true;
    return false;
}

// The panel lists every function (its valve, its cylinders and actuators)
// and every body; a cylinder's bore applies live, a body's mass rebuilds the
// model and the world (its inertia scaled with it, the bore edit kept), a
// length is refused with one line and changes nothing.
static void test_panel_by_function_and_body(void) {
    drive_session* s = open_ok(CHAIN8, NULL, NULL);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.1);
    panel* pn = drive_session_panel(s);
    const model* m = drive_session_model(s);
    for (int f = 0; f < m->chain.nfn; ++f) {
        char g[160];
        snprintf(g, sizeof g, "%s: %s (", m->chain.fn[f].name, m->chain.fn[f].valve);
        CHECK(has_group_prefix(pn, g), "no panel group for function %s", m->chain.fn[f].name);
    }
    for (int k = 0; k < m->chain.nact; ++k) {
        char key[160];
        snprintf(key, sizeof key, "%s: %s (cylinder)/bore", m->chain.fn[m->chain.act[k].function].name,
                 m->chain.act[k].cylinder);
        CHECK(panel_find(pn, key) >= 0, "no panel entry %s", key);
        snprintf(key, sizeof key, "%s: %s (actuator)/closed length", m->chain.fn[m->chain.act[k].function].name,
                 m->chain.act[k].name);
        CHECK(panel_find(pn, key) >= 0, "no panel entry %s", key);
    }
    for (int i = 1; i < m->chain.nbody; ++i) {
        char key[160];
        snprintf(key, sizeof key, "%s (%s)/mass", m->chain.body[i].def.name,
                 m->chain.body[i].def.joint == CHAIN_PRISMATIC ? "extension" : "boom");
        CHECK(panel_find(pn, key) >= 0, "no panel entry %s", key);
    }
    // A bore: live, on the running circuit.
    const int bore = panel_find(pn, "ext1: ext1_cyl (cylinder)/bore");
    CHECK(bore >= 0 && panel_set_id(pn, bore, 75, NULL, 0) == PANEL_OK, "bore entry");
    run_for(s, &wall, 0.05);
    double D = 0;
    hyd_model_get(engine_circuit(drive_session_engine(s)), "ext1_cyl.bore", &D);
    CHECK(fabs(D - 0.075) < 1e-12 && drive_session_stats(s)->rebuilds == 0, "bore %g m, %ld rebuilds", D,
          drive_session_stats(s)->rebuilds);
    // A mass: the model built again, the world rebuilt.
    const int ib = 3; // ext1
    const double m0 = m->chain.body[ib].def.mass, I0 = m->chain.body[ib].def.inertia[1][1];
    const int mass = panel_find(pn, "ext1 (extension)/mass");
    CHECK(mass >= 0 && panel_set_id(pn, mass, 2 * m0, NULL, 0) == PANEL_OK, "mass entry");
    CHECK(run_for(s, &wall, 0.1) == 0, "drive after the rebuild: %s", drive_session_error(s));
    m = drive_session_model(s);
    CHECK(m->chain.body[ib].def.mass == 2 * m0 && fabs(m->chain.body[ib].def.inertia[1][1] - 2 * I0) < 1e-9 * I0 &&
              drive_session_stats(s)->rebuilds == 1,
          "mass %g kg (was %g), Iyy %g (was %g), %ld rebuilds", m->chain.body[ib].def.mass, m0,
          m->chain.body[ib].def.inertia[1][1], I0, drive_session_stats(s)->rebuilds);
    hyd_model_get(engine_circuit(drive_session_engine(s)), "ext1_cyl.bore", &D);
    CHECK(fabs(D - 0.075) < 1e-12, "the bore edit lost in the rebuild: %g m", D);
    // A length: refused, one line, nothing rebuilt.
    pn = drive_session_panel(s);
    const int len = panel_find(pn, "ext1 (extension)/length");
    const double L0 = m->chain.body[ib].length; // [m]; the panel shows mm
    CHECK(len >= 0 && panel_set_id(pn, len, L0 * 1e3 + 500, NULL, 0) == PANEL_OK, "length entry");
    run_for(s, &wall, 0.05);
    const char* st = panel_message(pn);
    CHECK(drive_session_model(s)->chain.body[ib].length == L0 && fabs(panel_get(pn, len) - L0 * 1e3) < 1e-9 &&
              drive_session_stats(s)->rebuilds == 1 && strstr(st, "refused: ext1 (extension)/length") &&
              !strchr(st, '\n'),
          "length %g m, panel %g, status '%s'", drive_session_model(s)->chain.body[ib].length, panel_get(pn, len), st);
    drive_session_destroy(s);
}

// The chain's bodies as the renderer gets them: the column, a boom per
// revolute body, an extension per prismatic one, each extension's drawn
// section inside its parent's; with ext1 set wider and taller than the end
// arm it slides in (--set), it is drawn at 85 % of the end arm's section
// and the extensions it carries (given smaller than ext1's model size)
// inside that.
static void test_nested_extensions(void) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "sandbox";
    c.model_path = CHAIN8;
    c.sets[c.nset++] = "mechanics.bodies[3].width=0.3";  // ext1; the end arm is 0.17 x 0.22
    c.sets[c.nset++] = "mechanics.bodies[3].height=0.25";
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = true;
    char err[600];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    drive_session_render(s);
    const model* m = drive_session_model(s);
    const world_snapshot* snap = drive_session_snapshot(s);
    int nboom = 0, next = 0;
    for (int i = 1; i < m->chain.nbody; ++i) {
        const crane_body* cb = &m->chain.body[i];
        const world_snap_body *b = NULL, *pb = NULL;
        for (int k = 0; k < snap->nbody; ++k) {
            if (!strcmp(snap->body[k].name, cb->def.name)) b = &snap->body[k];
            if (!strcmp(snap->body[k].name, m->chain.body[cb->def.parent].def.name)) pb = &snap->body[k];
        }
        CHECK(b && pb, "%s or its parent not drawn", cb->def.name);
        if (!b || !pb) continue;
        const bool ext = cb->def.joint == CHAIN_PRISMATIC;
        nboom += b->role == WORLD_ROLE_BOOM, next += b->role == WORLD_ROLE_EXTENSION;
        CHECK(b->role == (ext ? WORLD_ROLE_EXTENSION : WORLD_ROLE_BOOM), "%s: role %d", cb->def.name, (int)b->role);
        CHECK(b->shape == WORLD_SHAPE_BOX && fabs(b->size[0] - cb->length) < 1e-12, "%s: a box of its length",
              cb->def.name);
        if (!ext) continue;
        CHECK(b->size[1] < pb->size[1] && b->size[2] < pb->size[2], "%s: drawn %.3f x %.3f in %s's %.3f x %.3f",
              cb->def.name, b->size[1], b->size[2], pb->name, pb->size[1], pb->size[2]);
        if (i == 3) {
            CHECK(fabs(b->size[1] - 0.85 * pb->size[1]) < 1e-12 && fabs(b->size[2] - 0.85 * pb->size[2]) < 1e-12 &&
                      cb->width == 0.3 && cb->height == 0.25,
                  "ext1 drawn %.4f x %.4f in %.4f x %.4f (model %.2f x %.2f)", b->size[1], b->size[2], pb->size[1],
                  pb->size[2], cb->width, cb->height);
        } else {
            CHECK(b->size[1] == cb->width && b->size[2] == cb->height, "%s: drawn %.3f x %.3f, model %.3f x %.3f",
                  cb->def.name, b->size[1], b->size[2], cb->width, cb->height);
        }
    }
    CHECK(nboom == 3 && next == 6, "%d booms, %d extensions drawn (3 and 6 in the model)", nboom, next);
    drive_session_destroy(s);
}

// "load model" from the default crane to loader10 and back, in one window:
// the engine, its channels, the default charts (by the new cylinders) and
// the panel follow the model; a recording of the old columns ends there.
static void test_load_chain_in_panel(void) {
    const char* rec = "drive_chain_switch.csv";
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "sandbox";
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.scripted = true;
    o.record_path = rec;
    char err[600];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.2);
    render* r = drive_session_render_ctx(s);
    CHECK(render_chart_count(r) == 12 && !strcmp(render_chart_label(r, 0), "p1A"), "%d charts, first %s",
          render_chart_count(r), render_chart_label(r, 0));
    panel* pn = drive_session_panel(s);
    CHECK(panel_set_text(pn, "model file", LOADER10) && panel_run_action(pn, "load model"), "no model file box");
    CHECK(run_for(s, &wall, 0.3) == 0, "drive after the load: %s", drive_session_error(s));
    const model* m = drive_session_model(s);
    CHECK(!m->chain.two_link && strstr(m->file, "loader10.json"), "model now %s", m->file);
    CHECK(chan_list_find(drive_session_channels(s), "x_ext2") > 0, "no x_ext2 after the load");
    const world_snapshot* snap = drive_session_snapshot(s);
    CHECK(snap->ncyl == 5 && render_chart_count(r) == 20 && !strcmp(render_chart_label(r, 0), "pA lift"),
          "%d cylinders, %d charts, first %s", snap->ncyl, render_chart_count(r), render_chart_label(r, 0));
    pn = drive_session_panel(s);
    CHECK(panel_find(pn, "ext: ext2_cyl (cylinder)/bore") >= 0, "no ext2 bore in the new panel");
    CHECK(strstr(panel_message(pn), "recording stopped: drive_chain_switch.csv") &&
              strstr(panel_message(pn), "the new model has"),
          "panel says: %s", panel_message(pn));
    long rows = 0;
    CHECK(drive_session_finish_record(s, &rows, err, sizeof err) == 0 && rows > 0, "record: %s", err);
    CHECK(panel_set_text(pn, "model file", CRANESIM_ASSETS "/models/hiab031.json") && panel_run_action(pn, "load model"),
          "no model file box");
    CHECK(run_for(s, &wall, 0.3) == 0, "drive after loading back: %s", drive_session_error(s));
    CHECK(drive_session_model(s)->chain.two_link && render_chart_count(r) == 12 &&
              !strcmp(render_chart_label(r, 0), "p1A"),
          "back: %d charts, first %s", render_chart_count(r), render_chart_label(r, 0));
    drive_session_destroy(s);
    remove(rec);
}

// The value of channel name in the session's row now.
static double channel(drive_session* s, const char* name) {
    static double row[1024];
    const int k = chan_list_find(drive_session_channels(s), name);
    if (k < 0 || k >= 1024) return NAN;
    drive_session_row(s, row);
    return row[k];
}

// The keys on a crane chain (not scripted): the up arrow commands the
// function named lift, the others hold 0 (the mapping for every function
// is the input helper's work).
static void test_keys_drive_lift(void) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    c.sim.world = "sandbox";
    c.model_path = CHAIN8;
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    char err[600];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.3);
    const double x0 = channel(s, "x_lift");
    push_key(SDL_SCANCODE_UP, 1);
    run_for(s, &wall, 1.0);
    const double u = channel(s, "ucmd_lift"), ue = channel(s, "ucmd_ext1");
    push_key(SDL_SCANCODE_UP, 0);
    run_for(s, &wall, 0.2);
    const double x1 = channel(s, "x_lift");
    // (ext1 is not held still: its cylinder settles from the start pose and
    // with the boom's angle; its command stays 0.)
    CHECK(u > 0.5 && ue == 0 && x1 > x0 + 0.01, "up arrow: ucmd_lift %.2f, ucmd_ext1 %.2f; lift %.4f -> %.4f m", u,
          ue, x0, x1);
    drive_session_destroy(s);
}

// loader10 in the window: its record has the chain's columns in its header,
// and the validation world (no picture of a chain there) is refused in one
// line before a window opens.
static void test_record_and_refusal(void) {
    const char* rec = "drive_chain_record.csv";
    drive_session* s = open_ok(LOADER10, NULL, rec);
    if (!s) return;
    double wall = 0;
    CHECK(run_for(s, &wall, 0.3) == 0, "drive: %s", drive_session_error(s));
    long rows = 0;
    char err[600];
    CHECK(drive_session_finish_record(s, &rows, err, sizeof err) == 0 && rows > 10, "record: %ld rows", rows);
    const int ncol = engine_ncol(drive_session_engine(s));
    drive_session_destroy(s);
    FILE* f = fopen(rec, "r");
    static char line[16384];
    CHECK(f && fgets(line, sizeof line, f), "no header in %s", rec);
    if (f) fclose(f);
    int commas = 0;
    for (const char* p = line; *p; ++p) commas += *p == ',';
    CHECK(strstr(line, ",x_ext1,") && strstr(line, ",u_ext,") && strstr(line, ",segment") && commas == ncol,
          "header of %d columns + segment: %s", ncol, line);
    remove(rec);

    s = open_chain(LOADER10, "validation", NULL, NULL, err, sizeof err);
    CHECK(!s && strstr(err, "the window (--headless runs a crane chain)") && strstr(err, "picture for the renderer") &&
              !strchr(err, '\n'),
          "validation world: %s", s ? "opened" : err);
    drive_session_destroy(s);
}

int main(int argc, char** argv) {
    RUN_TEST(test_bar_over_every_cylinder);
    RUN_TEST(test_every_function_charted);
    RUN_TEST(test_panel_by_function_and_body);
    RUN_TEST(test_nested_extensions);
    RUN_TEST(test_load_chain_in_panel);
    RUN_TEST(test_keys_drive_lift);
    RUN_TEST(test_record_and_refusal);
    TEST_MAIN_END();
}
