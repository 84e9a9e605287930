// test_channels.c: the output channels are one list (sim.h, SIM_CHANNELS_*)
// that each engine publishes, and the CSV header, sim_col_name and
// sim_col_unit are made from it: the header each backend writes is the one
// the README documents (these are the headers main wrote before the list).
#include "channels.h"
#include "check.h"
#include "crane_fixture.h"
#include "engine.h"
#include "sim.h"

#include <stdio.h>
#include <string.h>

static const char* const k_header_lagrange =
    "t,x1,x2,p1A,p1B,p2A,p2B,u1,u2,q1,q2,tip_x,tip_z,F1,F2,u1_cmd,u2_cmd,v1,v2,p_pump,relief_open,end_stop\n";
static const char* const k_header_ode =
    "t,x1,x2,p1A,p1B,p2A,p2B,u1,u2,q1,q2,tip_x,tip_z,F1,F2,u1_cmd,u2_cmd,v1,v2,p_pump,relief_open,end_stop,"
    "slew,hook_x,hook_y,hook_z,load_x,load_y,load_z,attached,truck_tilt,contacts,max_depth,x3,v3,p3A,p3B,u3,"
    "u3_cmd,F3";
// Columns appended since, as groups (each after F3, in any order of groups).
static const char* const k_header_ode_tip = ",tip_wx,tip_wy,tip_wz,rcl_util";
static const char* const k_header_ode_pads = ",pad_F1,pad_F2,pad_F3,pad_F4,stab_margin";

// The header sim_csv_header writes for ncol columns.
static void header(int ncol, char* buf, size_t n) {
    FILE* f = fmemopen(buf, n, "w");
    sim_csv_header(f, ncol);
    fclose(f);
}

static void test_headers_unchanged(void) {
    char buf[2048];
    sim_opts o = sim_default_opts();
    header(sim_ncol(&o), buf, sizeof buf);
    CHECK(strcmp(buf, k_header_lagrange) == 0, "lagrange header: %s", buf);
    o.mechanics = SIM_ODE;
    header(sim_ncol(&o), buf, sizeof buf);
    CHECK(strncmp(buf, k_header_ode, strlen(k_header_ode)) == 0, "ode header: %s", buf);
    CHECK(strstr(buf + strlen(k_header_ode), k_header_ode_pads) != NULL, "ode header has the pad group: %s", buf);
    CHECK(strstr(buf + strlen(k_header_ode), k_header_ode_tip) != NULL, "ode header has the tip and limiter group: %s", buf);
}

static void test_one_list(void) {
    int npress = 0;
    for (int c = 0; c < SIM_NCOL; ++c) {
        CHECK(sim_col_name[c] == sim_channels[c].name || !strcmp(sim_col_name[c], sim_channels[c].name),
              "column %d: name %s vs %s", c, sim_col_name[c], sim_channels[c].name);
        CHECK(!strcmp(sim_col_unit[c], sim_channels[c].unit), "column %d: unit", c);
        const bool p = sim_channels[c].kind == SIM_CH_PRESSURE;
        npress += p;
        // Pressures are exactly the columns in Pa: the run checks read the kind.
        CHECK(p == !strcmp(sim_channels[c].unit, "Pa"), "column %s: kind %d, unit %s", sim_channels[c].name,
              sim_channels[c].kind, sim_channels[c].unit);
    }
    CHECK(npress == 7, "%d pressure channels", npress);
    CHECK(!strcmp(sim_col_unit[COL_F3], "N") && !strcmp(sim_col_name[COL_SLEW], "slew"), "indices");
}

// Each engine publishes its channels; a run's CSV has as many columns.
static void test_engines_publish(void) {
    scenario sc;
    model* m = load_crane("ramp", &sc);
    if (!m) return;
    for (int b = 0; b < 2; ++b) {
        sim_opts o = sim_default_opts();
        o.mechanics = b ? SIM_ODE : SIM_LAGRANGE;
        o.world = CRANESIM_ASSETS "/worlds/validation.json";
        char err[512];
        engine* e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
        CHECK(e != NULL, "%s", err);
        if (!e) continue;
        int n = 0, nf = 0;
        const sim_channel* ch = engine_channels(e, &n);
        const sim_channel* cf = engine_channels_for(&o, &nf);
        CHECK(ch == sim_channels && cf == sim_channels && n == nf && n == sim_ncol(&o) && n == engine_ncol(e),
              "%s: %d channels, %d before, %d columns", engine_backend_name(e), n, nf, sim_ncol(&o));
        CHECK(n == (b ? SIM_NCOL : SIM_NCOL_BASE), "%s: %d channels", engine_backend_name(e), n);
        engine_destroy(e);
    }
    model_free(m);
}

// The LS crane's own states are channels under their state names, with the
// engine's state values: the pump's displacement, the compensators' and
// counterbalance valves' spools (docs/hydraulics.md); an accumulator's oil
// volume in m^3.
static void test_ls_state_channels(void) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    scenario sc;
    if (!m || load_scenario("ramp", &sc)) {
        model_free(m);
        return;
    }
    sim_opts o = sim_default_opts();
    engine* e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (!e) {
        model_free(m);
        return;
    }
    // Lift out for 0.3 s: the pump strokes out, the lift compensator throttles.
    const double u[3] = {0.6, 0, 0};
    engine_set_commands(e, u);
    CHECK(engine_advance(e, 0.3) == 0, "advance");
    const hyd_model* hm = engine_circuit(e);
    chan_list* cl = chan_list_create(e);
    CHECK(cl != NULL, "no channel list");
    const int n = chan_list_count(cl);
    double v[512], y[256];
    CHECK(n <= 512 && hyd_model_nstate(hm) <= 256, "%d channels", n);
    chan_list_values(cl, e, v, false);
    engine_circuit_state(e, y, NULL);
    static const char* const names[] = {"pump.disp", "lift_comp.spool", "jib_comp.spool", "lift_cbv.spool",
                                        "jib_cbv.spool"};
    for (int i = 0; i < 5; ++i) {
        const int k = chan_list_find(cl, names[i]), st = hyd_model_find_state(hm, names[i]);
        CHECK(k >= 0 && st >= 0, "no channel %s (state %d)", names[i], st);
        if (k < 0 || st < 0) continue;
        CHECK(v[k] == y[st], "%s: channel %g, state %g", names[i], v[k], y[st]);
        if (i == 0) CHECK(v[k] > 0.05, "pump.disp %g: the pump delivers while lifting", v[k]);
        CHECK(!strcmp(chan_list_channel(cl, k)->unit, "-"), "%s: unit %s", names[i], chan_list_channel(cl, k)->unit);
    }
    chan_list_free(cl);
    engine_destroy(e);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_headers_unchanged);
    RUN_TEST(test_one_list);
    RUN_TEST(test_engines_publish);
    RUN_TEST(test_ls_state_channels);
    TEST_MAIN_END();
}
