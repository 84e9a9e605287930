// app_energy.c: the energy balance's summary lines (docs/energy.md), one
// wording for run, compare and replay.
#include "app.h"
#include "energy_acc.h"
#include "engine.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

// Number of columns of group g (the circuit's components of that kind; the
// fluid's own "stored" column counts in SIM_EG_STORED).
static int group_columns(const sim_energy* en, sim_energy_group g) {
    int n = 0;
    for (int i = 0; i < sim_energy_ncol(en); ++i) n += sim_energy_col_group(en, i) == g;
    return n;
}

// The load-sensing components' groups and "other", only where a circuit has
// them (whenever it has them, also at exactly 0: a counterbalance valve that
// stayed shut on hold is a result, not a missing group). has[k]: the group
// is printed; one of SIM_EG_COMPENSATOR, SIM_EG_COUNTERBALANCE, SIM_EG_OTHER.
static const sim_energy_group extra_group[3] = {SIM_EG_COMPENSATOR, SIM_EG_COUNTERBALANCE, SIM_EG_OTHER};
static const char* const extra_name[3] = {"compensators", "counterbalance valves", "other"};

// J to kJ for a "%.3f" field, with what rounds to zero as 0 (never "-0.000").
static double kj(double J) { return fabs(J) < 0.5 ? 0.0 : 1e-3 * J; }

void app_print_energy(const sim_energy* en, const sim_energy_balance* b, const char* who) {
    const char* sp = who ? " " : "";
    if (!who) who = "";
    const int has_gas = group_columns(en, SIM_EG_STORED) > 1;
    printf("  energy%s%s: in %.3f kJ (pump %.3f, tanks %.3f); losses %.3f kJ (valves %.3f meter-in + %.3f "
           "meter-out, relief %.3f, check %.3f, orifice %.3f, hose %.3f, cylinder leakage %.3f",
           sp, who, kj(b->in), kj(b->pump), kj(b->tank), kj(b->loss), kj(b->group[SIM_EG_VALVE_IN]),
           kj(b->group[SIM_EG_VALVE_OUT]), kj(b->group[SIM_EG_RELIEF]), kj(b->group[SIM_EG_CHECK]),
           kj(b->group[SIM_EG_ORIFICE]), kj(b->group[SIM_EG_HOSE]), kj(b->group[SIM_EG_LEAK]));
    for (int k = 0; k < 3; ++k)
        if (group_columns(en, extra_group[k])) printf(", %s %.3f", extra_name[k], kj(b->group[extra_group[k]]));
    printf(")\n  energy%s%s: released by displaced fluid %.3f kJ; work on mechanics %.3f kJ", sp, who,
           kj(b->expansion), kj(b->work));
    // The ode world's strokes re-anchored to the bodies at each ODE step
    // (docs/energy.md); 0 on the lagrange crane, and then not printed.
    if (b->coupling != 0.0) printf("; put in by the ODE coupling %+.3f kJ", kj(b->coupling));
    // The fluid's compression energy is a function of each node's pressure
    // on (0, inf): a node that ended below absolute zero (a fixed step that
    // rang at a stiff event, which the run noted) has none, so the balance
    // cannot be closed, and the summary says so instead of printing NaN.
    if (!isfinite(b->stored)) {
        printf("; stored in the fluid: undefined (a node ended below absolute zero, see the note above); no "
               "residual\n");
    } else {
        printf("; stored in the fluid %+.3f kJ", kj(b->stored - b->gas));
        if (has_gas) printf(", in accumulator gas %+.3f kJ", kj(b->gas));
        printf("; residual %.3f %% of %.3f kJ turned over", fabs(b->residual_pct) < 5e-4 ? 0.0 : b->residual_pct,
               kj(b->turnover));
        // Every term is integrated by the solver's own steps, so a large
        // residual is the integration's error (docs/energy.md): say how to
        // close it rather than leave a number to puzzle over.
        if (fabs(b->residual_pct) > 1.0)
            printf(" (above 1 %%: the integration's own error; a smaller --dt or --rtol closes it)");
        printf("\n");
    }
    if (isfinite(b->mech))
        printf("  energy%s%s: mechanics (kinetic + potential) %+.3f kJ, so %.3f kJ of the work went to friction, "
               "end stops and joints\n",
               sp, who, kj(b->mech), kj(b->work - b->mech));
}

void app_print_energy_diff(const sim_energy* const en[2], const sim_energy_balance* b, const char* who) {
#define D(x) kj(b[1].x - b[0].x)
    printf("  energy %s: in %+.3f kJ (pump %+.3f, tanks %+.3f); losses %+.3f kJ (valves meter-in %+.3f, "
           "meter-out %+.3f, relief %+.3f, check %+.3f, orifice %+.3f, hose %+.3f, cylinder leakage %+.3f",
           who, D(in), D(pump), D(tank), D(loss), D(group[SIM_EG_VALVE_IN]), D(group[SIM_EG_VALVE_OUT]),
           D(group[SIM_EG_RELIEF]), D(group[SIM_EG_CHECK]), D(group[SIM_EG_ORIFICE]), D(group[SIM_EG_HOSE]),
           D(group[SIM_EG_LEAK]));
    for (int k = 0; k < 3; ++k)
        if (group_columns(en[0], extra_group[k]) || group_columns(en[1], extra_group[k]))
            printf(", %s %+.3f", extra_name[k], D(group[extra_group[k]]));
    printf(")\n  energy %s: released by displaced fluid %+.3f kJ; work on mechanics %+.3f kJ", who, D(expansion),
           D(work));
    if (b[0].coupling != 0.0 || b[1].coupling != 0.0) printf("; put in by the ODE coupling %+.3f kJ", D(coupling));
    if (isfinite(b[0].stored) && isfinite(b[1].stored)) {
        printf("; stored in the fluid %+.3f kJ", kj((b[1].stored - b[1].gas) - (b[0].stored - b[0].gas)));
        if (group_columns(en[0], SIM_EG_STORED) > 1 || group_columns(en[1], SIM_EG_STORED) > 1)
            printf(", in accumulator gas %+.3f kJ", D(gas));
    }
    if (isfinite(b[0].mech) && isfinite(b[1].mech)) printf("; mechanics (kinetic + potential) %+.3f kJ", D(mech));
    printf("\n");
#undef D
}

sim_energy* app_energy_follow(const char* cmd, engine* e) {
    sim_energy* en = sim_energy_create();
    if (en && !engine_follow_energy(e, en)) return en;
    fprintf(stderr, "cranesim %s: note: no energy balance (out of memory)\n", cmd);
    sim_energy_free(en);
    return NULL;
}

void app_energy_report(sim_energy* en, const char* title) {
    if (!en) return;
    sim_energy_finish(en);
    sim_energy_balance b;
    sim_energy_result(en, &b);
    if (b.samples > 1) {
        if (title) printf("  %s\n", title);
        app_print_energy(en, &b, NULL);
    }
    sim_energy_free(en);
}
