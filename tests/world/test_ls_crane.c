// test_ls_crane.c: every solver integrates the load-sensing crane
// (assets/models/hiab031_ls.json). The reference is Krus at 0.01 ms (it
// agrees with RODAS3 at rtol 1e-6 to 0.06 % RMS of peak p1A on ramp,
// docs/model.md); ROS34PW2 and RODAS3 at the paper's 1 % tolerance and
// Krus at the paper's 0.1 ms must stay within 1 % RMS (each chamber's
// pressure, of the highest chamber peak of the reference, as cranesim
// compare) over the whole ramp, and their strokes within 0.5 mm RMS. The
// draft LS crane failed this: its lowering rang (12 % RMS) and Krus 0.1 ms
// rang in the P nodes behind the 50 kPa compensators.
#include "check.h"
#include "crane_fixture.h"
#include "engine.h"
#include "sim.h"

#include <math.h>
#include <string.h>

static int run(model* m, const scenario* sc, hyd_method solver, double h, double rtol, sim_trace* tr) {
    sim_opts o = sim_default_opts();
    o.solver = solver;
    if (h > 0) o.h = h;
    if (rtol > 0) o.rtol = rtol;
    sim_result r;
    const int rc = sim_run(m, sc, &o, NULL, NULL, tr, NULL, NULL, &r);
    CHECK(rc == 0, "%s", r.message);
    return rc;
}

static void test_solvers_agree(void) {
    scenario sc;
    if (load_scenario("ramp", &sc)) return;
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    sim_trace ref = {0};
    if (run(m, &sc, HYD_KRUS, 1e-5, 0, &ref)) {
        model_free(m);
        return;
    }
    static const int pc[4] = {COL_P1A, COL_P1B, COL_P2A, COL_P2B};
    double peak[4] = {0, 0, 0, 0};
    for (int i = 0; i < ref.nrow; ++i)
        for (int k = 0; k < 4; ++k) peak[k] = fmax(peak[k], ref.v[(size_t)i * SIM_NCOL + pc[k]]);
    const struct { const char* name; hyd_method s; double h, rtol; } runs[] = {
        {"krus 0.1 ms", HYD_KRUS, 1e-4, 0},
        {"ros34pw2 rtol 1e-2", HYD_ROS34PW2, 0, 1e-2},
        {"rodas3 rtol 1e-2", HYD_RODAS3, 0, 1e-2},
    };
    for (size_t j = 0; j < sizeof runs / sizeof runs[0]; ++j) {
        sim_trace tr = {0};
        if (run(m, &sc, runs[j].s, runs[j].h, runs[j].rtol, &tr)) continue;
        CHECK(tr.nrow == ref.nrow, "%s: %d rows, the reference %d", runs[j].name, tr.nrow, ref.nrow);
        const int n = tr.nrow < ref.nrow ? tr.nrow : ref.nrow;
        double sp[4] = {0, 0, 0, 0}, sx = 0.0;
        for (int i = 0; i < n; ++i) {
            const double* a = tr.v + (size_t)i * SIM_NCOL;
            const double* b = ref.v + (size_t)i * SIM_NCOL;
            for (int k = 0; k < 4; ++k) sp[k] += (a[pc[k]] - b[pc[k]]) * (a[pc[k]] - b[pc[k]]);
            sx += (a[COL_X1] - b[COL_X1]) * (a[COL_X1] - b[COL_X1]) + (a[COL_X2] - b[COL_X2]) * (a[COL_X2] - b[COL_X2]);
        }
        // As cranesim compare: RMS of each chamber against the highest
        // chamber peak of the reference.
        const double pk = fmax(fmax(peak[0], peak[1]), fmax(peak[2], peak[3]));
        double worst = 0.0;
        for (int k = 0; k < 4; ++k) {
            worst = fmax(worst, 100.0 * sqrt(sp[k] / n) / pk);
        }
        const double xr = 1e3 * sqrt(sx / (2.0 * n));
        printf("  %s: worst chamber-pressure RMS %.3f %% of peak, strokes %.4f mm RMS\n", runs[j].name, worst, xr);
        CHECK(worst < 1.0, "%s: chamber pressure RMS %.3f %% of peak against Krus 0.01 ms", runs[j].name, worst);
        CHECK(xr < 0.5, "%s: strokes %.4f mm RMS against Krus 0.01 ms", runs[j].name, xr);
        sim_trace_free(&tr);
    }
    sim_trace_free(&ref);
    model_free(m);
}

// Lowering through the counterbalance valve, in the full crane. 1000 kg
// held (hose_burst_line's pose), valves closed; then the lift command ramps
// slowly to -0.3 over 4 s, so the rod side (the valve's pilot) charges
// slowly. The valve's opening balance (docs/hydraulics.md) says it cracks
// when (p_l - p_v) + R (p_p - p_v) = p_setting: with the load pressure p_l
// and the valve-port pressure p_v read at that moment, the pilot pressure
// must be p_v + (p_setting - (p_l - p_v)) / R (25 MPa, R = 3: about 4 MPa),
// within 5 %. And by hand from the holding state alone: raising the rod
// side by p_p pushes the piston down, and the load side rises by
// (A_B p_p - F_b) / A_A (area ratio 0.64; F_b = 4.5 kN, the seal's
// breakaway, resists the creeping piston), so p_p = (p_setting - p_hold +
// F_b / A_A) / (R + A_B / A_A) in gauge pressures, within 5 %. Before the
// crack the lift only creeps by the load column's compression (about
// 3.2 L x 1.7 MPa / Be over A_A: under 1 mm).
static void test_lowering_pilot(void) {
    scenario sc;
    if (load_scenario("hose_burst_line", &sc)) return;
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    sim_opts o = sim_default_opts();
    engine* e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (!e) {
        model_free(m);
        return;
    }
    const hyd_model* h = engine_circuit(e);
    const int sl = hyd_model_node_state(h, hyd_model_find_node(h, "lift_cyl.A"));
    const int sv = hyd_model_node_state(h, hyd_model_find_node(h, "lift_cbv_A"));
    const int sp = hyd_model_node_state(h, hyd_model_find_node(h, "lift_hose_B"));
    const int sx = hyd_model_find_state(h, "lift_cbv.spool");
    CHECK(sl >= 0 && sv >= 0 && sp >= 0 && sx >= 0, "states %d %d %d %d", sl, sv, sp, sx);
    const double pset = 25e6, R = 3.0, pt = 1e5;
    const double AA = 0.25 * 3.14159265358979 * 0.1 * 0.1, AB = 0.25 * 3.14159265358979 * (0.1 * 0.1 - 0.06 * 0.06);
    double y[256], row[SIM_NCOL];
    CHECK(hyd_model_nstate(h) <= 256, "%d states", hyd_model_nstate(h));
    // Settle for 1 s with the valves closed.
    double u[3] = {0, 0, 0};
    engine_set_commands(e, u);
    CHECK(engine_advance_to(e, 1.0, NULL, NULL) == 0, "%s", engine_error(e));
    engine_circuit_state(e, y, NULL);
    const double p_hold = y[sl];
    engine_row(e, row);
    const double x0 = row[COL_X1];
    int cracked = 0;
    for (int k = 1; k <= 4000 && !cracked && sl >= 0 && sv >= 0 && sp >= 0 && sx >= 0; ++k) {
        u[0] = -0.3 * k / 4000.0;
        engine_set_commands(e, u);
        if (engine_advance_to(e, 1.0 + 1e-3 * k, NULL, NULL)) break;
        engine_circuit_state(e, y, NULL);
        if (y[sx] < 0.01) continue;
        cracked = 1;
        const double pl = y[sl], pv = y[sv], pp = y[sp];
        const double pred = pv + (pset - (pl - pv)) / R;
        const double Fb = 4500.0; // lift_cyl coulomb + stribeck [N]
        const double hand = pt + (pset - (p_hold - pt) + Fb / AA) / (R + AB / AA);
        engine_row(e, row);
        printf("  cracks at u = %.4f: pilot %.3f MPa; balance %.3f MPa (p_l %.3f, p_v %.3f); by hand from the "
               "holding %.3f MPa: %.3f MPa; lift moved %.3f mm\n",
               u[0], pp / 1e6, pred / 1e6, pl / 1e6, pv / 1e6, p_hold / 1e6, hand / 1e6, 1e3 * (row[COL_X1] - x0));
        CHECK_REL(pp - pt, pred - pt, 0.05);
        CHECK_REL(pp - pt, hand - pt, 0.05);
        CHECK(fabs(row[COL_X1] - x0) < 1e-3, "the lift moved %g m before the valve cracked", row[COL_X1] - x0);
    }
    CHECK(cracked, "the counterbalance valve did not open while lowering");
    engine_destroy(e);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_lowering_pilot);
    RUN_TEST(test_solvers_agree);
    TEST_MAIN_END();
}
