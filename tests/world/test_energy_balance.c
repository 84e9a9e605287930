// test_energy_balance.c: the energy balance closes on every shipped scenario
// (assets/scenarios, read from the folder: a new scenario is covered by
// itself), on both cranes, with Krus, ROS2 and ROS34PW2 at their defaults
// (docs/energy.md). The fluid's stored energy is a state function of the end
// states and the terms are integrated by each solver step's own method, so
// the residual is the integration's own error, and it must shrink with it:
// halving the fixed step or tightening the tolerance tenfold must shrink it
// (the "order" group). One group per argument, so ctest runs them side by
// side: lagrange, ode (validation world), sandbox (the ode sandbox's own
// scenarios), order.
//
// The bound, 0.25 % of the energy turned over: the largest residual
// measured over the whole matrix was 0.18 % (hold, ROS34PW2 at rtol 1e-3,
// where the pump charges its line in the first 2 ms; with seal friction on
// the cylinders as well), 0.15 % with ROS2 at 0.1 ms (the default crane on
// ls_flow_sharing, its pump relief cracking and reseating), 0.04 % with
// Krus. That it is the integration's error, not a missing term, is what the
// order group checks: at h / 2 it is at most 0.6 of itself (first order
// through the reliefs' kinks, second between them), at rtol 1e-4 at most
// 0.2 of itself. Before the balance followed the solver's steps (samples
// every 1 ms, trapezoid between them), hold read 2.6 % with Krus and
// -5.8 % with ROS34PW2, and the ode world's `step` 1.1 %, the sandbox's
// `sandbox_swing` 0.74 %.
#include "check.h"
#include "crane_fixture.h"
#include "energy_acc.h"
#include "sim.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BOUND_PCT 0.25

typedef struct run_cfg {
    const char* model;  ///< file in assets/models
    const char* scen;   ///< name in assets/scenarios
    sim_mechanics mech;
    const char* world;  ///< ode: world name (NULL: validation)
    hyd_method solver;
    bool cvode;
    double h, rtol;     ///< 0: the defaults
} run_cfg;

// The balance of one run; 0, or -1 (the failure CHECKed).
static int balance(const run_cfg* c, sim_energy_balance* b) {
    memset(b, 0, sizeof *b);
    scenario sc;
    model* m = load_model(c->model);
    if (!m) return -1;
    if (load_scenario(c->scen, &sc)) {
        model_free(m);
        return -1;
    }
    sim_opts o = sim_default_opts();
    o.mechanics = c->mech;
    o.solver = c->solver;
    o.cvode = c->cvode;
    if (c->h > 0) o.h = c->h;
    if (c->rtol > 0) o.rtol = c->rtol;
    char wbuf[512];
    o.world = sim_world_path(c->world ? c->world : "validation", wbuf, sizeof wbuf);
    sim_energy* en = sim_energy_create();
    sim_result r;
    const int rc = sim_run_energy(m, &sc, &o, NULL, NULL, NULL, NULL, NULL, en, &r);
    CHECK(rc == 0, "%s %s: %s", c->model, c->scen, r.message);
    if (rc == 0) sim_energy_result(en, b);
    sim_energy_free(en);
    model_free(m);
    return rc ? -1 : 0;
}

static const char* name_of(const run_cfg* c, char* buf, size_t n) {
    snprintf(buf, n, "%.24s %.32s, %s%s, %s%s", c->model, c->scen, c->mech == SIM_ODE ? "ode " : "lagrange",
             c->mech == SIM_ODE ? (c->world ? "sandbox" : "validation") : "", c->cvode ? "cvode" : hyd_method_name(c->solver),
             c->h > 0 ? " (h set)" : c->rtol > 0 ? " (rtol set)" : "");
    return buf;
}

// The residual of one run as a share of its turnover [%] (NAN: failed).
static double residual(const run_cfg* c) {
    sim_energy_balance b;
    if (balance(c, &b)) return NAN;
    char nb[160];
    fprintf(stderr, "%-70s turnover %9.4f kJ, residual %+.4f %% (%+.3g J)\n", name_of(c, nb, sizeof nb),
            b.turnover * 1e-3, b.residual_pct, b.residual);
    // A balance that turned nothing over would close trivially.
    CHECK(b.turnover > 1.0, "%s: only %g J turned over", nb, b.turnover);
    return b.residual_pct;
}

// What a scenario needs the sandbox for (app_checks.c's rule): the hook, a
// slew command or a slewed start.
static bool needs_sandbox(const scenario* sc) {
    if (sc->nevent > 0 || sc->slew0 != 0) return true;
    for (int i = 0; i < sc->cmd[2].n; ++i)
        if (sc->cmd[2].u[i] != 0) return true;
    return false;
}

// The shipped scenarios of one kind (sandbox or not), by name, sorted; with
// each the model file it was written for ("" for the two-link cranes).
static int scenarios(bool sandbox, char names[][64], char own[][64], int cap) {
    DIR* d = opendir(CRANESIM_ASSETS "/scenarios");
    CHECK(d != NULL, "cannot list %s", CRANESIM_ASSETS "/scenarios");
    if (!d) return 0;
    int n = 0;
    const struct dirent* de;
    while ((de = readdir(d)) && n < cap) {
        const size_t len = strlen(de->d_name);
        if (len < 6 || len - 5 >= 64 || strcmp(de->d_name + len - 5, ".json")) continue;
        char nm[64];
        snprintf(nm, sizeof nm, "%.*s", (int)(len - 5), de->d_name);
        scenario sc;
        if (load_scenario(nm, &sc)) continue;
        if (needs_sandbox(&sc) != sandbox) continue;
        snprintf(own[n], 64, "%.63s", sc.model);
        snprintf(names[n++], 64, "%s", nm);
    }
    closedir(d);
    for (int i = 1; i < n; ++i) // insertion sort: a stable order in the log
        for (int j = i; j > 0 && strcmp(names[j], names[j - 1]) < 0; --j) {
            char t[64];
            memcpy(t, names[j], 64);
            memcpy(names[j], names[j - 1], 64);
            memcpy(names[j - 1], t, 64);
            memcpy(t, own[j], 64);
            memcpy(own[j], own[j - 1], 64);
            memcpy(own[j - 1], t, 64);
        }
    return n;
}

static const char* const models[] = {"hiab031.json", "hiab031_ls.json"};
static const hyd_method solvers[] = {HYD_KRUS, HYD_ROS2, HYD_ROS34PW2};

static void matrix(sim_mechanics mech, const char* world, bool sandbox) {
    char names[64][64], own[64][64];
    const int ns = scenarios(sandbox, names, own, 64);
    CHECK(ns >= (sandbox ? 3 : 9), "only %d %s scenarios found", ns, sandbox ? "sandbox" : "other");
    double worst = 0.0;
    for (int s = 0; s < ns; ++s)
        for (size_t mi = 0; mi < sizeof models / sizeof models[0]; ++mi)
            for (size_t k = 0; k < sizeof solvers / sizeof solvers[0]; ++k) {
                // A scenario written for another shipped crane (loader10_cycle)
                // runs on that crane only, once, with the fixed-step solvers
                // (a chain crane in the ODE world sub-steps its circuit with
                // one; it refuses an adaptive solver, test_ode_engine_chain).
                if (own[s][0] && (mi > 0 || hyd_method_is_adaptive(solvers[k]))) continue;
                const run_cfg c = {own[s][0] ? own[s] : models[mi], names[s], mech, world, solvers[k], false, 0, 0};
                const double r = residual(&c);
                char nb[160];
                CHECK(fabs(r) < BOUND_PCT, "%s: residual %.4f %% of the energy turned over (bound %g %%)",
                      name_of(&c, nb, sizeof nb), r, BOUND_PCT);
                if (fabs(r) > fabs(worst)) worst = r;
            }
    fprintf(stderr, "largest residual %.4f %% (bound %g %%)\n", worst, BOUND_PCT);
}

// The residual is the integration's error: it shrinks with the step and the
// tolerance. The runs where it is largest, on both backends.
static void order(void) {
    static const struct {
        const char* scen;
        hyd_method solver;
        sim_mechanics mech;
    } cases[] = {
        {"hold", HYD_KRUS, SIM_LAGRANGE},           {"hold", HYD_ROS2, SIM_LAGRANGE},
        {"ls_flow_sharing", HYD_KRUS, SIM_LAGRANGE}, {"ls_flow_sharing", HYD_ROS2, SIM_LAGRANGE},
        {"hold", HYD_KRUS, SIM_ODE},                {"ls_flow_sharing", HYD_ROS2, SIM_ODE},
        {"hold", HYD_ROS34PW2, SIM_LAGRANGE},       {"hold", HYD_ROS34PW2, SIM_ODE},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        const bool adaptive = hyd_method_is_adaptive(cases[i].solver);
        run_cfg c = {"hiab031.json", cases[i].scen, cases[i].mech, NULL, cases[i].solver, false, 0, 0};
        const double r0 = residual(&c);
        if (adaptive) c.rtol = 1e-4;
        else c.h = 0.5e-4;
        const double r1 = residual(&c);
        const double shrink = adaptive ? 0.2 : 0.6;
        char nb[160];
        CHECK(fabs(r1) <= shrink * fabs(r0), "%s: residual %.4f %% at %s, %.4f %% at %s: not below %g of it",
              name_of(&c, nb, sizeof nb), r0, adaptive ? "rtol 1e-3" : "h = 0.1 ms", r1,
              adaptive ? "rtol 1e-4" : "h = 0.05 ms", shrink);
    }
    // CVODE (the reference) integrates the terms with its BDF steps as
    // quadratures (hyd_cvode.h), outside its error test, so the residual is
    // its states' own error and must shrink with its tolerance. At its
    // default rtol 1e-3 its states are off on hold (the pump line overshoots
    // to 22.5 MPa and the relief opens); at 1e-5 the shipped crane's seals
    // hold the booms still and CVODE strides 85 steps over the 10 s of
    // `hold`, its pump line 53 kPa off (-1.9 % of the 0.037 kJ turned
    // over); at 1e-6 it closes within the bound.
    if (sim_have_cvode()) {
        const char* sc[] = {"hold", "step"};
        for (int i = 0; i < 2; ++i) {
            const run_cfg c = {"hiab031.json", sc[i], SIM_LAGRANGE, NULL, HYD_KRUS, true, 0, 1e-6};
            const double r = residual(&c);
            CHECK(fabs(r) < BOUND_PCT, "cvode rtol 1e-6 %s: residual %.4f %%", sc[i], r);
        }
        const run_cfg c5 = {"hiab031.json", "hold", SIM_LAGRANGE, NULL, HYD_KRUS, true, 0, 1e-5};
        const run_cfg c7 = {"hiab031.json", "hold", SIM_LAGRANGE, NULL, HYD_KRUS, true, 0, 1e-7};
        const double r5 = residual(&c5), r7 = residual(&c7);
        CHECK(fabs(r7) <= 0.2 * fabs(r5), "cvode hold: residual %.4f %% at rtol 1e-5, %.4f %% at 1e-7: not below 0.2 of it",
              r5, r7);
    }
}

int main(int argc, char** argv) {
    const char* g = argc > 1 ? argv[1] : "";
    if (!strcmp(g, "lagrange")) matrix(SIM_LAGRANGE, NULL, false);
    else if (!strcmp(g, "ode")) matrix(SIM_ODE, NULL, false);
    else if (!strcmp(g, "sandbox")) matrix(SIM_ODE, "sandbox", true);
    else if (!strcmp(g, "order")) order();
    else CHECK(0, "usage: test_energy_balance lagrange|ode|sandbox|order (got \"%s\")", g);
    printf("%d checks, %d failed\n", check_count_, check_failures_);
    return check_failures_ != 0;
}
