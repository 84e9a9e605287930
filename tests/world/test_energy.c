// test_energy.c: the energy balance of a run (docs/energy.md). The fluid's
// stored energy is taken from the end states as a state function, not from
// the integrated rates, so a missing or wrong power term shows as a
// residual: the balance must close within 1 % on the ramp scenario on both
// backends.
#include "check.h"
#include "crane_fixture.h"
#include "energy_acc.h"
#include "sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// The run's balance on scenario scen with model file model_file in
// assets/models (NULL: the default crane).
static void run_balance_with(const char* model_file, const char* scen, sim_mechanics mech, hyd_method solver,
                             sim_energy_balance* b) {
    scenario sc;
    memset(b, 0, sizeof *b);
    model* m = NULL;
    if (model_file) {
        m = load_model(model_file);
        if (m && load_scenario(scen, &sc)) {
            model_free(m);
            m = NULL;
        }
    } else {
        m = load_crane(scen, &sc);
    }
    if (!m) return;
    sim_opts o = sim_default_opts();
    o.mechanics = mech;
    o.solver = solver;
    o.world = CRANESIM_ASSETS "/worlds/validation.json";
    sim_energy* en = sim_energy_create();
    CHECK(en != NULL, "out of memory");
    sim_result r;
    CHECK(sim_run_energy(m, &sc, &o, NULL, NULL, NULL, NULL, NULL, en, &r) == 0, "%s", r.message);
    sim_energy_result(en, b);
    sim_energy_free(en);
    model_free(m);
}

static void run_balance_of(const char* model_file, const char* scen, sim_mechanics mech, sim_energy_balance* b) {
    run_balance_with(model_file, scen, mech, sim_default_opts().solver, b);
}

static void run_balance(const char* scen, sim_mechanics mech, sim_energy_balance* b) {
    run_balance_of(NULL, scen, mech, b);
}

static void print_balance(const char* name, const sim_energy_balance* b0) {
    const sim_energy_balance b = *b0;
        fprintf(stderr, "%s: in %.4f kJ (pump %.4f, tank %.4f), losses %.4f kJ (valves %.4f + %.4f, relief %.4f, "
                        "check %.4f, hose %.4f, leak %.4f), expansion %.4f kJ, work %.4f kJ, stored %.5f kJ (rate %.5f), mech %.4f kJ, "
                        "residual %.4f %%, %ld samples\n",
                name, b.in * 1e-3, b.pump * 1e-3, b.tank * 1e-3, b.loss * 1e-3, b.group[SIM_EG_VALVE_IN] * 1e-3,
                b.group[SIM_EG_VALVE_OUT] * 1e-3, b.group[SIM_EG_RELIEF] * 1e-3, b.group[SIM_EG_CHECK] * 1e-3,
                b.group[SIM_EG_HOSE] * 1e-3, b.group[SIM_EG_LEAK] * 1e-3, b.expansion * 1e-3, b.work * 1e-3, b.stored * 1e-3,
                b.stored_rate * 1e-3, b.mech * 1e-3, b.residual_pct, b.samples);
}

static void test_ramp_balance(void) {
    for (int k = 0; k < 2; ++k) {
        sim_energy_balance b;
        run_balance("ramp", k ? SIM_ODE : SIM_LAGRANGE, &b);
        const char* name = k ? "ode ramp" : "lagrange ramp";
        print_balance(name, &b);
        // The ramp really moves the crane with the pump delivering (else
        // the balance would be trivially closed). The work term must count:
        // above 1 % of the energy in, 50 times the 0.02 % residual allowed
        // below, so that a balance without it would fail. (With the seal
        // friction the cylinders' work on ramp is 2.6 % of the energy in:
        // of the 5.1 kJ the booms give up, 3.8 kJ go to friction, 0.55 kJ
        // without the seals' Coulomb and Stribeck terms.)
        CHECK(b.pump > 10e3, "%s: the pump delivered only %g J", name, b.pump);
        CHECK(fabs(b.work) > 0.01 * b.in && fabs(b.mech) > 0.05 * b.in, "%s: work %g J, mechanics %g J of %g J in", name, b.work, b.mech, b.in);
        CHECK(fabs(b.residual_pct) < 1.0, "%s: residual %.3f %% of the energy in", name, b.residual_pct);
        // Tighter than asked (measured: below 0.001 %): the smallest term,
        // the check valves' 0.05 %, must be in it too.
        CHECK(fabs(b.residual_pct) < 0.02, "%s: residual %.4f %% of the energy in", name, b.residual_pct);
    }
}

// The load-sensing crane on ramp: the LS pump is the energy in, and the
// compensators and counterbalance valves (group "other") take their share
// of the losses; the balance closes within 1 % on both backends.
static void test_ls_ramp_balance(void) {
    for (int k = 0; k < 2; ++k) {
        sim_energy_balance b;
        run_balance_of("hiab031_ls.json", "ramp", k ? SIM_ODE : SIM_LAGRANGE, &b);
        const char* name = k ? "ode ramp, LS crane" : "lagrange ramp, LS crane";
        print_balance(name, &b);
        CHECK(b.pump > 10e3, "%s: the LS pump delivered only %g J", name, b.pump);
        CHECK(b.group[SIM_EG_COMPENSATOR] > 0.01 * b.in && b.group[SIM_EG_COUNTERBALANCE] > 0.05 * b.in,
              "%s: compensators took %g J, counterbalance valves %g J of %g J", name, b.group[SIM_EG_COMPENSATOR],
              b.group[SIM_EG_COUNTERBALANCE], b.in);
        CHECK(fabs(b.residual_pct) < 1.0, "%s: residual %.3f %% of the energy in", name, b.residual_pct);
    }
}

// Load sensing is there to save energy: on ramp the LS crane must take
// less energy in than the constant-pressure crane (docs/energy.md). Both
// numbers come from balances that close within 1 % (the stored energy a
// state function, so the accounting is checked independently of the
// integrated pump power). The LS crane's counterbalance valves make
// lowering a powered motion; with the 5 mm^2 valves it shipped with before
// the pilot damping orifice it took 57.7 kJ against 49.3.
static void test_ls_uses_less(void) {
    sim_energy_balance s, l;
    run_balance("ramp", SIM_LAGRANGE, &s);
    run_balance_of("hiab031_ls.json", "ramp", SIM_LAGRANGE, &l);
    fprintf(stderr, "ramp, lagrange: energy in %.3f kJ standard crane, %.3f kJ LS crane (%.1f %%)\n", s.in * 1e-3,
            l.in * 1e-3, 100.0 * (l.in - s.in) / s.in);
    CHECK(fabs(s.residual_pct) < 1.0 && fabs(l.residual_pct) < 1.0, "residuals %.3f %%, %.3f %%", s.residual_pct,
          l.residual_pct);
    CHECK(s.in > 10e3 && l.in > 10e3, "energy in %g J, %g J", s.in, l.in);
    CHECK(l.in < s.in, "the LS crane takes %.3f kJ in on ramp, the standard crane %.3f kJ", l.in * 1e-3, s.in * 1e-3);
}

// overload: the lift relief opens and dissipates a large part of the pump's
// energy, so the relief's term must be in the balance for it to close.
static void test_overload_balance(void) {
    for (int k = 0; k < 2; ++k) {
        sim_energy_balance b;
        run_balance("overload", k ? SIM_ODE : SIM_LAGRANGE, &b);
        const char* name = k ? "ode overload" : "lagrange overload";
        print_balance(name, &b);
        CHECK(b.group[SIM_EG_RELIEF] > 0.05 * b.in, "%s: relief took %g J of %g J in", name,
              b.group[SIM_EG_RELIEF], b.in);
        CHECK(fabs(b.residual_pct) < 1.0, "%s: residual %.3f %% of the energy in", name, b.residual_pct);
    }
}

// Runs whose pump delivers almost nothing: the fluid's energy comes from the
// loads sinking (work < 0), and "in" is a few J or negative. The residual is
// a share of the energy turned over (docs/energy.md); over "in" it read
// -6.4 % on hose_burst (2 J of 13 kJ turned over) and 17 % on the LS
// crane's hold. The turnover is checked against its definition (the larger
// of the sources' and the sinks' sums) from the terms themselves.
static void test_low_input_balance(void) {
    static const struct {
        const char *model, *scen;
        hyd_method solver;
    } cases[] = {
        {NULL, "hose_burst", HYD_KRUS},
        {"hiab031_ls.json", "hose_burst", HYD_KRUS},
        // Krus 0.1 ms with the supply in 1x1 blocks of W left 0.86 J of the
        // LS standby's start transient in the residual (3 % of 28 J): the
        // states themselves were off; with the supply block it closes
        // (docs/energy.md). ROS34PW2 (dense J) as the cross-check.
        {"hiab031_ls.json", "hold", HYD_KRUS},
        {"hiab031_ls.json", "hose_burst_line", HYD_KRUS},
        {"hiab031_ls.json", "hold", HYD_ROS34PW2},
        {"hiab031_ls.json", "hose_burst_line", HYD_ROS34PW2},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        sim_energy_balance b;
        run_balance_with(cases[i].model, cases[i].scen, SIM_LAGRANGE, cases[i].solver, &b);
        char name[96];
        snprintf(name, sizeof name, "%s %s", cases[i].model ? cases[i].model : "hiab031.json", cases[i].scen);
        print_balance(name, &b);
        CHECK(fabs(b.in) < 0.2 * fabs(b.work), "%s: in %g J, work %g J: not a low-input run", name, b.in, b.work);
        const double src = fmax(b.in, 0) + fmax(-b.loss, 0) + fmax(-b.expansion, 0) + fmax(-b.work, 0) +
                           fmax(-b.stored, 0);
        const double snk = fmax(-b.in, 0) + fmax(b.loss, 0) + fmax(b.expansion, 0) + fmax(b.work, 0) +
                           fmax(b.stored, 0);
        CHECK(fabs(b.turnover - fmax(src, snk)) <= 1e-9 * b.turnover, "%s: turnover %g J, sources %g J, sinks %g J",
              name, b.turnover, src, snk);
        CHECK(fabs(src - snk - b.residual) <= 1e-9 * b.turnover, "%s: sources - sinks %g J, residual %g J", name,
              src - snk, b.residual);
        CHECK(fabs(b.residual_pct) < 1.0, "%s: residual %.3f %% of the energy turned over", name, b.residual_pct);
    }
}

static int last_row(void* user, const double* row) {
    *(double*)user = row[COL_P_PUMP];
    return 0;
}

// An accumulator on the LS crane's pump line (1 L, precharge 1 MPa, n 1.4),
// charged on ramp: its gas energy is stored energy, not a loss ("other").
// Hand value: the polytropic work from the precharge (oil volume 0 at the
// start) to the gas pressure at the end, p0 V0 ((p/p0)^((n-1)/n) - 1)/(n - 1),
// with p the pump line's pressure at rest at the end of ramp.
static void test_accumulator_gas_is_stored(void) {
    char* text = NULL;
    {
        FILE* f = fopen(CRANESIM_ASSETS "/models/hiab031_ls.json", "rb");
        CHECK(f != NULL, "cannot read the LS crane");
        if (!f) return;
        fseek(f, 0, SEEK_END);
        const long n = ftell(f);
        fseek(f, 0, SEEK_SET);
        text = calloc((size_t)n + 1, 1);
        if (text && fread(text, 1, (size_t)n, f) != (size_t)n) text[0] = 0;
        fclose(f);
    }
    cJSON* root = cJSON_Parse(text);
    free(text);
    cJSON* comps = cJSON_GetObjectItem(cJSON_GetObjectItem(root, "hydraulics"), "components");
    CHECK(cJSON_IsArray(comps), "no components");
    if (!cJSON_IsArray(comps)) {
        cJSON_Delete(root);
        return;
    }
    const double p0 = 1e6, V0 = 1e-3, n = 1.4;
    cJSON_AddItemToArray(comps, cJSON_Parse("{\"name\": \"acc\", \"type\": \"accumulator\", \"port\": \"pump_line\", "
                                            "\"p0\": 1e6, \"V0\": 1e-3, \"n\": 1.4}"));
    char err[512];
    model* m = model_from_json(root, "ls_acc.json", err, sizeof err);
    CHECK(m != NULL, "%s", err);
    scenario sc;
    if (!m || load_scenario("ramp", &sc)) {
        model_free(m);
        return;
    }
    sim_opts o = sim_default_opts();
    sim_energy* en = sim_energy_create();
    sim_result r;
    double p_end = 0.0;
    CHECK(sim_run_energy(m, &sc, &o, last_row, &p_end, NULL, NULL, NULL, en, &r) == 0, "%s", r.message);
    sim_energy_balance b;
    sim_energy_result(en, &b);
    sim_energy_free(en);
    model_free(m);
    print_balance("lagrange ramp, LS crane with an accumulator", &b);
    const double hand = p0 * V0 * (pow(p_end / p0, (n - 1.0) / n) - 1.0) / (n - 1.0);
    fprintf(stderr, "accumulator: pump line %.4f MPa at the end, gas %.4f kJ (hand %.4f kJ), other %.4f kJ\n",
            p_end * 1e-6, b.gas * 1e-3, hand * 1e-3, b.group[SIM_EG_OTHER] * 1e-3);
    CHECK(p_end > 3.0 * p0, "the accumulator was hardly charged: %g Pa", p_end);
    CHECK(fabs(b.gas - hand) < 0.01 * hand, "gas energy %g J, hand %g J", b.gas, hand);
    // What stays in "other" is the accumulator inlet's loss alone, a fraction of
    // the gas energy at its 1e-9 m^3/(s Pa) conductance.
    CHECK(b.group[SIM_EG_OTHER] >= 0.0 && b.group[SIM_EG_OTHER] < 0.5 * b.gas, "other %g J, gas %g J",
          b.group[SIM_EG_OTHER], b.gas);
    CHECK(fabs(b.residual_pct) < 1.0, "residual %.3f %%", b.residual_pct);
}

int main(void) {
    test_accumulator_gas_is_stored();
    test_low_input_balance();
    test_ramp_balance();
    test_ls_ramp_balance();
    test_ls_uses_less();
    test_overload_balance();
    printf("%d checks, %d failed\n", check_count_, check_failures_);
    return check_failures_ != 0;
}
