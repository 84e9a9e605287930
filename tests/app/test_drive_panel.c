// test_drive_panel.c: the drive panel generated from the parameter tables,
// loading a model from it, and the circuit's channels (headless: offscreen
// GL on llvmpipe, a virtual clock).
#include "channels.h"
#include "check.h"
#include "drive_session.h"
#include "panel.h"
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static drive_session* open_with(sim_mechanics mech, const char* model_path, const char* charts, char* err,
                                size_t errsz) {
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = mech;
    c.model_path = model_path;
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.width = 640;
    o.height = 360;
    o.charts = charts;
    return drive_session_create(&c, &o, err, errsz, NULL);
}

static drive_session* open_ok(sim_mechanics mech, const char* model_path, const char* charts) {
    char err[512];
    drive_session* s = open_with(mech, model_path, charts, err, sizeof err);
    CHECK(s != NULL, "session: %s", err);
    return s;
}

static int run_for(drive_session* s, double* wall, double seconds) {
    int rc = 0;
    for (double end = *wall + seconds; *wall < end && rc == 0;) {
        *wall += 1.0 / 240.0;
        rc = drive_session_tick(s, *wall);
    }
    return rc;
}

static char* read_text(const char* path) {
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char* t = malloc((size_t)n + 1);
    if (t) t[t && fread(t, 1, (size_t)n, f) == (size_t)n ? n : 0] = 0;
    fclose(f);
    return t;
}

// Replace every "from" in t by "to" (a new string; t is freed).
static char* replace_all(char* t, const char* from, const char* to) {
    const size_t lf = strlen(from), lt = strlen(to);
    size_t cnt = 0;
    for (const char* p = t; (p = strstr(p, from)); p += lf) ++cnt;
    char* o = malloc(strlen(t) + cnt * (lt > lf ? lt - lf : 0) + 1), *w = o;
    const char* p = t;
    for (const char* q; (q = strstr(p, from)); p = q + lf) {
        memcpy(w, p, (size_t)(q - p));
        w += q - p;
        memcpy(w, to, lt);
        w += lt;
    }
    strcpy(w, p);
    free(t);
    return o;
}

static int write_text(const char* path, const char* t) {
    FILE* f = fopen(path, "w");
    if (!f) return -1;
    fputs(t, f);
    return fclose(f);
}

// The shipped model with every component renamed: the panel code knows no
// component name, so its panel must be as complete as the original's.
static const char* renamed_model(void) {
    static const char* path = "test_drive_panel_renamed.json";
    char* t = read_text(CRANESIM_ASSETS "/models/hiab031.json");
    if (!t) return NULL;
    t = replace_all(t, "\"lift_", "\"boomA_");
    t = replace_all(t, "\"jib_", "\"boomB_");
    t = replace_all(t, "main_relief", "limiter");
    t = replace_all(t, "\"pump\"", "\"supply\"");
    t = replace_all(t, "\"type\": \"supply\"", "\"type\": \"pump\""); // the type keeps its name
    const int rc = write_text(path, t);
    free(t);
    return rc ? NULL : path;
}

// What the tables hold for this session: each element of the running
// circuit with its type's parameters, the fluid's, the mechanics table, and
// the solver's method and step.
static int table_count(drive_session* s) {
    const hyd_model* hm = engine_circuit(drive_session_engine(s));
    int n = 0;
    for (int i = 0; i < hyd_model_nelement(hm); ++i) {
        hyd_type t;
        hyd_model_element(hm, i, &t);
        n += hyd_param_count(t);
    }
    // + the solver's two, + the eight strip-chart slots (a choice of channel each)
    return n + hyd_fluid_param_count() + model_param_count() + 2 + 8;
}

// Every table entry is in the panel, under "<element> (<type>)".
static void check_every_entry(drive_session* s) {
    const panel* pn = drive_session_panel(s);
    const hyd_model* hm = engine_circuit(drive_session_engine(s));
    CHECK(panel_count(pn) == table_count(s), "panel has %d entries, the tables %d", panel_count(pn), table_count(s));
    int missing = 0;
    for (int i = 0; i < hyd_model_nelement(hm); ++i) {
        hyd_type t;
        const char* name = hyd_model_element(hm, i, &t);
        for (int k = 0; k < hyd_param_count(t); ++k) {
            char key[160];
            snprintf(key, sizeof key, "%s (%s)/%s", name, hyd_type_name(t), hyd_param_name(t, k));
            if (panel_find(pn, key) < 0 && missing++ < 3) CHECK(0, "no panel entry %s", key);
        }
    }
    CHECK(missing == 0, "%d circuit parameters missing", missing);
}

static void test_panel_lists_every_parameter(void) {
    drive_session* s = open_ok(SIM_ODE, NULL, NULL);
    if (!s) return;
    check_every_entry(s);
    const panel* pn = drive_session_panel(s);
    // The sandbox's slew valve (the world's circuit) and the fluid are there;
    // units are display units, the slider covers the typical range.
    const int q = panel_find(pn, "slew_valve (valve)/q_nominal");
    CHECK(q >= 0 && !strcmp(panel_unit(pn, q), "L/min"), "slew valve q_nominal unit %s", q >= 0 ? panel_unit(pn, q) : "-");
    const int p = panel_find(pn, "pump (pump)/p_set");
    double lo, hi, slo, shi;
    panel_range(pn, p, &lo, &hi, NULL);
    panel_slider_range(pn, p, &slo, &shi);
    // pump.c: hard [1e5, 1e8] Pa, typical [5e6, 4.5e7] Pa, shown in MPa.
    CHECK(p >= 0 && !strcmp(panel_unit(pn, p), "MPa") && fabs(lo - 0.1) < 1e-12 && fabs(hi - 100) < 1e-12 &&
              fabs(slo - 5) < 1e-12 && fabs(shi - 45) < 1e-12,
          "p_set [%g, %g], slider [%g, %g] %s", lo, hi, slo, shi, p >= 0 ? panel_unit(pn, p) : "");
    CHECK(panel_find(pn, "fluid/bulk_modulus") >= 0, "no fluid entry");
    // The filter: a substring of the component or the parameter name.
    panel* pw = drive_session_panel(s);
    panel_set_filter(pw, "JIB_CYL");
    int shown = 0;
    for (int i = 0; i < panel_count(pn); ++i) shown += panel_matches(pn, i);
    CHECK(shown == hyd_param_count(HYD_CYLINDER), "filter 'JIB_CYL' shows %d entries, want %d", shown,
          hyd_param_count(HYD_CYLINDER));
    panel_set_filter(pw, "p_crack");
    shown = 0;
    for (int i = 0; i < panel_count(pn); ++i) shown += panel_matches(pn, i);
    int reliefs = 0; // every relief and check valve has a p_crack
    const hyd_model* hm = engine_circuit(drive_session_engine(s));
    for (int c = 0; c < hyd_model_ncomp(hm); ++c)
        reliefs += hyd_model_comp_type(hm, c) == HYD_RELIEF || hyd_model_comp_type(hm, c) == HYD_CHECK;
    CHECK(shown == reliefs, "filter 'p_crack' shows %d, the circuit has %d reliefs and checks", shown, reliefs);
    // A typed value outside the typical range but inside the hard one is
    // taken; outside the hard range it is refused.
    char msg[256];
    CHECK(panel_set(pw, "pump (pump)/p_set", 50.0, msg, sizeof msg) == PANEL_OK, "%s", msg);
    CHECK(panel_set(pw, "pump (pump)/p_set", 150.0, msg, sizeof msg) == PANEL_OUT_OF_RANGE, "150 MPa taken");
    drive_session_destroy(s);
}

static void test_renamed_components_get_a_full_panel(void) {
    const char* path = renamed_model();
    CHECK(path != NULL, "cannot write the renamed model");
    if (!path) return;
    drive_session* s = open_ok(SIM_LAGRANGE, path, NULL);
    if (!s) return;
    check_every_entry(s);
    const panel* pn = drive_session_panel(s);
    CHECK(panel_find(pn, "boomA_cyl (cylinder)/bore") >= 0 && panel_find(pn, "limiter (relief)/p_crack") >= 0 &&
              panel_find(pn, "supply (pump)/q_max") >= 0,
          "renamed components missing");
    CHECK(panel_find(pn, "lift_cyl (cylinder)/bore") < 0, "an old name in the panel");
    drive_session_destroy(s);
    remove(path);
}

// Lift bore 100 -> 120 mm in the panel: the lift force the engine computes
// is pA A_A - pB A_B - b v - F_seal(v) with the new areas (cylinder law,
// away from the stops), A_A = pi D^2 / 4, A_B = pi (D^2 - d^2) / 4, the
// seal friction F_seal = (F_c + F_s exp(-(v/v_st)^2)) tanh(v/v_sm) as
// docs/hydraulics.md writes it (the bore does not change it).
static void test_bore_edit_changes_the_force(void) {
    drive_session* s = open_ok(SIM_LAGRANGE, NULL, NULL);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.3);
    char msg[256];
    CHECK(panel_set(drive_session_panel(s), "lift_cyl (cylinder)/bore", 120.0, msg, sizeof msg) == PANEL_OK, "%s",
          msg);
    run_for(s, &wall, 0.2);
    const hyd_model* hm = engine_circuit(drive_session_engine(s));
    double D = 0, d = 0, bv = 0;
    hyd_model_get(hm, "lift_cyl.bore", &D);
    hyd_model_get(hm, "lift_cyl.rod", &d);
    hyd_model_get(hm, "lift_cyl.friction", &bv);
    double Fc = 0, Fs = 0, vst = 1, vsm = 1;
    hyd_model_get(hm, "lift_cyl.coulomb", &Fc);
    hyd_model_get(hm, "lift_cyl.stribeck", &Fs);
    hyd_model_get(hm, "lift_cyl.v_stribeck", &vst);
    hyd_model_get(hm, "lift_cyl.v_smooth", &vsm);
    CHECK(D == 0.12, "engine bore %g m", D);
    double row[SIM_NCOL];
    drive_session_row(s, row);
    const double v = row[COL_V1];
    const double seal = (Fc + Fs * exp(-(v / vst) * (v / vst))) * tanh(v / vsm);
    const double F = row[COL_P1A] * M_PI * D * D / 4 - row[COL_P1B] * M_PI * (D * D - d * d) / 4 - bv * v - seal;
    const double F_old = row[COL_P1A] * M_PI * 0.01 / 4 - row[COL_P1B] * M_PI * (0.01 - d * d) / 4 - bv * v - seal;
    CHECK(fabs(row[COL_F1] - F) <= 1e-9 * fabs(F), "F1 %.9g N, hand %.9g N (old bore %.6g N)", row[COL_F1], F, F_old);
    CHECK(fabs(F - F_old) > 0.2 * fabs(F), "the new bore makes no difference: %g vs %g N", F, F_old);
    drive_session_destroy(s);
}

// "load model" in the panel: a model with another lift bore replaces the
// running one in the same (sandbox) world and driving goes on; a bad file
// leaves the running model, with the reason in the panel.
static void test_load_model_from_the_panel(void) {
    char* t = read_text(CRANESIM_ASSETS "/models/hiab031.json");
    CHECK(t != NULL, "no shipped model");
    if (!t) return;
    t = replace_all(t, "\"bore\": 0.1,", "\"bore\": 0.11,"); // the lift cylinder (the jib's differs)
    const char* good = "test_drive_panel_load.json", *bad = "test_drive_panel_bad.json";
    CHECK(write_text(good, t) == 0 && write_text(bad, "{\"name\": \"broken\", \"mechanics\": 3}") == 0, "write");
    free(t);
    drive_session* s = open_ok(SIM_ODE, NULL, NULL);
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.3);
    panel* pn = drive_session_panel(s);
    CHECK(panel_set_text(pn, "model file", good) && panel_run_action(pn, "load model"), "no model file box");
    CHECK(run_for(s, &wall, 0.5) == 0, "drive after the load: %s", drive_session_error(s));
    double D = 0;
    hyd_model_get(engine_circuit(drive_session_engine(s)), "lift_cyl.bore", &D);
    CHECK(D == 0.11 && strstr(drive_session_model(s)->file, good), "after the load: bore %g m, file %s", D,
          drive_session_model(s)->file);
    pn = drive_session_panel(s); // a new panel for the new model
    const int id = panel_find(pn, "lift_cyl (cylinder)/bore");
    CHECK(id >= 0 && fabs(panel_get(pn, id) - 110) < 1e-9, "panel bore %g mm", id >= 0 ? panel_get(pn, id) : NAN);
    CHECK(panel_count(pn) == table_count(s), "panel %d entries, tables %d", panel_count(pn), table_count(s));
    // The bad file.
    CHECK(panel_set_text(pn, "model file", bad) && panel_run_action(pn, "load model"), "no model file box");
    CHECK(run_for(s, &wall, 0.2) == 0, "drive after the failed load: %s", drive_session_error(s));
    CHECK(strstr(drive_session_model(s)->file, good) != NULL, "model is now %s", drive_session_model(s)->file);
    const char* m = panel_message(drive_session_panel(s));
    CHECK(strstr(m, "load failed") && strstr(m, bad) && !strchr(m, '\n'), "panel says '%s'", m);
    hyd_model_get(engine_circuit(drive_session_engine(s)), "lift_cyl.bore", &D);
    CHECK(D == 0.11, "bore %g m after the failed load", D);
    drive_session_destroy(s);
    remove(good);
    remove(bad);
}

// The circuit's channels: a node pressure equals the engine's state (and the
// row's column for the same chamber), a spool equals the row's spool.
static void test_circuit_channels(void) {
    drive_session* s = open_ok(SIM_ODE, NULL, "p1A,lift_cyl.A.p,lift_valve.qA");
    if (!s) return;
    double wall = 0;
    run_for(s, &wall, 0.5);
    engine* e = drive_session_engine(s);
    const chan_list* cl0 = drive_session_channels(s);
    const hyd_model* hm = engine_circuit(e);
    // Its size: the row, a pressure per node, a spool per valve, a flow per
    // component and a second one per valve.
    const int want = engine_ncol(e) + hyd_model_nnode(hm) + 2 * hyd_model_nvalve(hm) + hyd_model_ncomp(hm);
    CHECK(chan_list_count(cl0) == want, "%d channels, want %d", chan_list_count(cl0), want);
    chan_list* cl = chan_list_create(e);
    double* v = calloc((size_t)chan_list_count(cl), sizeof *v);
    chan_list_values(cl, e, v, false);
    double y[256];
    engine_circuit_state(e, y, NULL);
    const int kA = chan_list_find(cl, "lift_cyl.A.p");
    const int st = hyd_model_node_state(hm, hyd_model_find_node(hm, "lift_cyl.A"));
    CHECK(kA >= 0 && v[kA] == y[st] && v[kA] == v[COL_P1A] && !strcmp(chan_list_channel(cl, kA)->unit, "Pa"),
          "lift_cyl.A.p %g, state %g, p1A %g", kA >= 0 ? v[kA] : NAN, y[st], v[COL_P1A]);
    const int kp = chan_list_find(cl, "pump_line.p");
    CHECK(kp >= 0 && v[kp] == v[COL_P_PUMP], "pump_line.p %g, p_pump %g", kp >= 0 ? v[kp] : NAN, v[COL_P_PUMP]);
    const int ku = chan_list_find(cl, "lift_valve.spool");
    CHECK(ku >= 0 && v[ku] == v[COL_U1], "lift_valve.spool %g, u1 %g", ku >= 0 ? v[ku] : NAN, v[COL_U1]);
    // A tank's pressure is its fixed one.
    const int kt = chan_list_find(cl, "tank.p");
    double pt = 0;
    hyd_model_get(hm, "tank.pressure", &pt);
    CHECK(kt >= 0 && v[kt] == pt, "tank.p %g, tank.pressure %g", kt >= 0 ? v[kt] : NAN, pt);
    free(v);
    chan_list_free(cl);
    // The charts took the circuit channels by name.
    render* r = drive_session_render_ctx(s);
    CHECK(render_chart_count(r) == 3 && !strcmp(render_chart_label(r, 1), "lift_cyl.A.p") &&
              !strcmp(render_chart_label(r, 2), "lift_valve.qA"),
          "%d charts", render_chart_count(r));
    drive_session_destroy(s);
    // A circuit channel the circuit lacks is refused, naming it.
    char err[512];
    drive_session* b = open_with(SIM_ODE, NULL, "p1A,nope.p", err, sizeof err);
    CHECK(b == NULL && strstr(err, "no circuit channel 'nope.p'"), "bad chart name: %s", b ? "accepted" : err);
    drive_session_destroy(b);
}

// HUD readouts of named channels (--readouts): names and units from the
// channel list, values in display units; the readout box grows a line each.
static void test_hud_readouts(void) {
    drive_session* plain = open_ok(SIM_ODE, NULL, NULL);
    if (!plain) return;
    double wall = 0;
    run_for(plain, &wall, 0.3);
    drive_session_render(plain);
    float r0[4];
    CHECK(render_hud_readouts_rect(drive_session_render_ctx(plain), r0), "no readouts box");
    drive_session_destroy(plain);
    app_common c = {.sim = sim_default_opts()};
    c.sim.mechanics = SIM_ODE;
    drive_opts o = drive_default_opts();
    o.offscreen = true;
    o.width = 640;
    o.height = 360;
    o.readouts = "lift_cyl.A.p,pump.q";
    char err[512];
    drive_session* s = drive_session_create(&c, &o, err, sizeof err, NULL);
    CHECK(s != NULL, "session: %s", err);
    if (!s) return;
    wall = 0;
    run_for(s, &wall, 0.3);
    // Paused, the frames show the state that stands still.
    panel_run_action(drive_session_panel(s), "pause / resume");
    render* r = drive_session_render_ctx(s);
    run_for(s, &wall, 0.05);
    // A frame is drawn only when the driver has finished the last one.
    render_wait(r, 5.0);
    run_for(s, &wall, 0.05);
    float r1[4];
    CHECK(render_hud_readouts_rect(r, r1) && fabs(r1[3] - r0[3] - 2 * 14.0f) < 1e-3f, "box %g px, without %g px",
          r1[3], r0[3]);
    double v = 0;
    const char* unit = NULL;
    const char* name = render_get_readout(r, 0, &v, &unit);
    // The chamber pressure in MPa, as the state gives it in Pa.
    chan_list* cl = chan_list_create(drive_session_engine(s));
    double* cv = calloc((size_t)chan_list_count(cl), sizeof *cv);
    chan_list_values(cl, drive_session_engine(s), cv, false);
    const int k = chan_list_find(cl, "lift_cyl.A.p");
    CHECK(name && !strcmp(name, "lift_cyl.A.p") && !strcmp(unit, "MPa") && fabs(v - cv[k] * 1e-6) < 1e-9 * fabs(v),
          "readout %s = %g %s, channel %g Pa (p1A %g Pa)", name ? name : "-", v, unit ? unit : "", cv[k], cv[COL_P1A]);
    name = render_get_readout(r, 1, &v, &unit);
    CHECK(name && !strcmp(name, "pump.q") && !strcmp(unit, "L/min"), "readout 1 %s %s", name ? name : "-",
          unit ? unit : "");
    free(cv);
    chan_list_free(cl);
    drive_session_destroy(s);
}

int main(int argc, char** argv) {
    setenv("SDL_VIDEODRIVER", "offscreen", 0);
    setenv("EGL_PLATFORM", "surfaceless", 0);
    setenv("SDL_AUDIODRIVER", "dummy", 0);
    RUN_TEST(test_panel_lists_every_parameter);
    RUN_TEST(test_renamed_components_get_a_full_panel);
    RUN_TEST(test_bore_edit_changes_the_force);
    RUN_TEST(test_load_model_from_the_panel);
    RUN_TEST(test_circuit_channels);
    RUN_TEST(test_hud_readouts);
    TEST_MAIN_END();
}
