// energy_acc.c: the run's energy balance (energy_acc.h, docs/energy.md).
#include "energy_acc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct sim_energy {
    const hyd_model* m;
    hyd_data* d;
    double* ydot; ///< (nstate) scratch for hyd_eval
    int ncol;
    char (*name)[72];
    int* group;
    int* comp; ///< component of the column, -1 for tank and stored
    double *P, *Pprev, *E; ///< (ncol) power now, at the last sample [W]; energy [J]
    double* Topen; ///< (ncol) time its component was open [s] (reliefs; 0 for the others)
    long n;
    double t0, tprev;
    double es0, es1, em0, em1;
    double gas0, gas1; ///< accumulators' gas energy at the first and the last sample [J]
    int finished;
    double *p1, *V1; ///< (nnode) node pressures and volumes at the last sample
    double* phi;     ///< (nnode) phi(p1) of nodes whose volume has moved (NAN: not followed yet)
    FILE* csv;
    double csv_dt, csv_next;
};

static const char* const group_names[SIM_EG_COUNT] = {
    "pump", "valve meter-in", "valve meter-out", "relief", "check", "orifice", "hose", "cylinder leakage",
    "compensator", "counterbalance", "other", "work on mechanics", "tank", "stored", "expansion"};

const char* sim_energy_group_name(sim_energy_group g) { return g < SIM_EG_COUNT ? group_names[g] : "?"; }

static void unbind(sim_energy* e);

void sim_energy_free(sim_energy* e) {
    if (!e) return;
    unbind(e);
    free(e->name);
    free(e->group);
    free(e->comp);
    free(e->P);
    free(e->Pprev);
    free(e->E);
    free(e->Topen);
    free(e);
}

static int add_col(sim_energy* e, int comp, int group, const char* suffix) {
    const int i = e->ncol++;
    const char* base = comp >= 0 ? hyd_model_comp_name(e->m, comp) : "";
    snprintf(e->name[i], sizeof e->name[i], "%s%s", base, suffix);
    e->group[i] = group;
    e->comp[i] = comp;
    return i;
}

sim_energy* sim_energy_create(void) {
    sim_energy* e = calloc(1, sizeof *e);
    if (e) e->em0 = e->em1 = NAN;
    return e;
}

static void unbind(sim_energy* e) {
    hyd_data_free(e->d);
    free(e->ydot);
    free(e->p1);
    free(e->V1);
    free(e->phi);
    e->d = NULL, e->ydot = e->p1 = e->V1 = e->phi = NULL;
    e->m = NULL;
}

int sim_energy_bind(sim_energy* e, const hyd_model* m) {
    if (e->m || e->ncol) return -1; // one run per accumulator
    e->m = m;
    const int nc = hyd_model_ncomp(m), nn = hyd_model_nnode(m), ns = hyd_model_nstate(m);
    const size_t cap = (size_t)(2 * nc + 3);
    e->d = hyd_data_create(m);
    e->ydot = calloc((size_t)(ns > 0 ? ns : 1), sizeof *e->ydot);
    e->name = calloc(cap, sizeof *e->name);
    e->group = calloc(cap, sizeof *e->group);
    e->comp = calloc(cap, sizeof *e->comp);
    e->P = calloc(cap, sizeof *e->P);
    e->Pprev = calloc(cap, sizeof *e->Pprev);
    e->E = calloc(cap, sizeof *e->E);
    e->Topen = calloc(cap, sizeof *e->Topen);
    e->p1 = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->p1);
    e->V1 = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->V1);
    e->phi = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->phi);
    if (!e->d || !e->ydot || !e->name || !e->group || !e->comp || !e->P || !e->Pprev || !e->E || !e->Topen || !e->p1 || !e->V1 ||
        !e->phi) {
        unbind(e);
        return -1;
    }
    for (int c = 0; c < nc; ++c) {
        switch (hyd_model_comp_type(m, c)) {
        // Both pump kinds deliver the energy in; the LS pump used to fall
        // into "other" as a negative loss, so the balance had no input.
        case HYD_PUMP:
        case HYD_LS_PUMP: add_col(e, c, SIM_EG_SUPPLY, ""); break;
        case HYD_VALVE:
            add_col(e, c, SIM_EG_VALVE_IN, ".meter_in");
            add_col(e, c, SIM_EG_VALVE_OUT, ".meter_out");
            break;
        case HYD_RELIEF: add_col(e, c, SIM_EG_RELIEF, ""); break;
        case HYD_CHECK: add_col(e, c, SIM_EG_CHECK, ""); break;
        case HYD_ORIFICE: add_col(e, c, SIM_EG_ORIFICE, ""); break;
        case HYD_HOSE: add_col(e, c, SIM_EG_HOSE, ""); break;
        case HYD_CYLINDER:
            add_col(e, c, SIM_EG_LEAK, ".leak");
            add_col(e, c, SIM_EG_WORK, ".work");
            break;
        case HYD_COMPENSATOR: add_col(e, c, SIM_EG_COMPENSATOR, ""); break;
        case HYD_COUNTERBALANCE: add_col(e, c, SIM_EG_COUNTERBALANCE, ""); break;
        // The gas compression is stored energy (it comes back when the
        // accumulator discharges), not a loss; the column <name> keeps the
        // loss in its inlet only.
        case HYD_ACCUMULATOR:
            add_col(e, c, SIM_EG_OTHER, "");
            add_col(e, c, SIM_EG_STORED, ".gas");
            break;
        default: add_col(e, c, SIM_EG_OTHER, ""); break;
        }
    }
    add_col(e, -1, SIM_EG_TANK, "tank");
    add_col(e, -1, SIM_EG_STORED, "stored");
    add_col(e, -1, SIM_EG_EXPANSION, "expansion");
    for (int n = 0; n < nn; ++n) e->phi[n] = NAN;
    if (e->csv) {
        fprintf(e->csv, "t");
        for (int i = 0; i < e->ncol; ++i) fprintf(e->csv, ",%s", e->name[i]);
        fputc('\n', e->csv);
    }
    return 0;
}

void sim_energy_finish(sim_energy* e) {
    if (!e->m) return;
    e->es1 = e->n ? hyd_stored_energy(e->m, e->p1, e->V1) : e->es0;
    e->finished = 1;
    unbind(e);
}

hyd_data* sim_energy_data(sim_energy* e) { return e->d; }
int sim_energy_ncol(const sim_energy* e) { return e->ncol; }
const char* sim_energy_col_name(const sim_energy* e, int i) { return e->name[i]; }
sim_energy_group sim_energy_col_group(const sim_energy* e, int i) { return (sim_energy_group)e->group[i]; }
double sim_energy_col_energy(const sim_energy* e, int i) { return e->E[i]; }
double sim_energy_col_open_time(const sim_energy* e, int i) { return e->Topen[i]; }

// Every column's power taken from the fluid at the last evaluation [W].
static void powers(sim_energy* e, const hyd_data* d) {
    const hyd_model* m = e->m;
    for (int i = 0; i < e->ncol; ++i) {
        const int c = e->comp[i];
        switch (e->group[i]) {
        case SIM_EG_VALVE_IN:
        case SIM_EG_VALVE_OUT: {
            double ed[2];
            hyd_valve_edge_power(m, d, c, ed);
            e->P[i] = ed[e->group[i] == SIM_EG_VALVE_OUT];
            break;
        }
        case SIM_EG_WORK: e->P[i] = hyd_comp_piston_power(m, d, c); break;
        case SIM_EG_TANK: e->P[i] = -hyd_boundary_power(m, d); break;
        case SIM_EG_STORED: e->P[i] = c >= 0 ? hyd_comp_gas_power(m, d, c) : hyd_stored_power(m, d); break;
        case SIM_EG_EXPANSION: {
            // hyd_expansion_power, with phi followed along the run (one
            // Simpson panel per step) instead of integrated afresh.
            double P = 0.0;
            for (int n = 0; n < hyd_model_nnode(m); ++n) {
                const double dV = d->node_dV[n];
                if (hyd_model_node_state(m, n) < 0) continue;
                if (isnan(e->phi[n])) {
                    if (dV == 0.0) continue;
                    e->phi[n] = hyd_node_phi(m, n, d->node_p[n]);
                } else if (e->n > 0) {
                    e->phi[n] += hyd_node_phi_increment(m, n, e->p1[n], d->node_p[n]);
                }
                P -= dV * e->phi[n];
            }
            e->P[i] = P;
            break;
        }
        default: e->P[i] = hyd_comp_power(m, d, c) - hyd_comp_gas_power(m, d, c); break;
        }
    }
}

static void csv_row(sim_energy* e, double t) {
    fprintf(e->csv, "%.9g", t);
    for (int i = 0; i < e->ncol; ++i) fprintf(e->csv, ",%.9g", e->P[i]);
    fputc('\n', e->csv);
}

void sim_energy_csv(sim_energy* e, FILE* f, double dt) {
    e->csv = f;
    e->csv_dt = dt;
    e->csv_next = 0.0;
}

void sim_energy_sample(sim_energy* e, double t, const double* y, double e_mech) {
    if (!e->m) return;
    hyd_eval(e->m, e->d, t, y, e->ydot);
    sim_energy_sample_data(e, t, e->d, e_mech);
}

void sim_energy_sample_data(sim_energy* e, double t, const hyd_data* d, double e_mech) {
    const hyd_model* m = e->m;
    if (!m) return;
    powers(e, d);
    double gas = 0.0;
    for (int i = 0; i < e->ncol; ++i)
        if (e->group[i] == SIM_EG_STORED && e->comp[i] >= 0) gas += hyd_comp_gas_energy(m, d, e->comp[i]);
    e->gas1 = gas;
    if (e->n == 0) {
        e->gas0 = gas;
        e->t0 = t;
        e->es0 = hyd_stored_energy(m, d->node_p, d->node_V);
        e->em0 = e_mech;
    } else {
        const double h = t - e->tprev;
        for (int i = 0; i < e->ncol; ++i) e->E[i] += 0.5 * h * (e->P[i] + e->Pprev[i]);
        // A relief's open time: the step counts when the relief passes flow
        // at its end (the rows' relief_open convention, at step resolution).
        for (int i = 0; i < e->ncol; ++i)
            if (e->group[i] == SIM_EG_RELIEF && d->comp_open && d->comp_open[e->comp[i]]) e->Topen[i] += h;
    }
    memcpy(e->Pprev, e->P, (size_t)e->ncol * sizeof *e->P);
    const int nn = hyd_model_nnode(m);
    memcpy(e->p1, d->node_p, (size_t)nn * sizeof *e->p1);
    memcpy(e->V1, d->node_V, (size_t)nn * sizeof *e->V1);
    e->em1 = e_mech;
    e->tprev = t;
    ++e->n;
    if (e->csv && t >= e->csv_next - 1e-9 * e->csv_dt) {
        csv_row(e, t);
        // The next row one period on, on the grid (a step that lands a
        // little early still writes the row of its grid time).
        e->csv_next = (floor(t / e->csv_dt + 1e-6) + 1.0) * e->csv_dt;
    }
}

void sim_energy_result(const sim_energy* e, sim_energy_balance* b) {
    memset(b, 0, sizeof *b);
    for (int i = 0; i < e->ncol; ++i) b->group[e->group[i]] += e->E[i];
    b->pump = -b->group[SIM_EG_SUPPLY];
    b->tank = -b->group[SIM_EG_TANK];
    b->in = b->pump + b->tank;
    for (int g = SIM_EG_VALVE_IN; g <= SIM_EG_OTHER; ++g) b->loss += b->group[g];
    b->work = b->group[SIM_EG_WORK];
    b->stored_rate = b->group[SIM_EG_STORED];
    const double es1 = e->finished ? e->es1 : e->m && e->n ? hyd_stored_energy(e->m, e->p1, e->V1) : e->es0;
    b->gas = e->gas1 - e->gas0;
    b->stored = es1 - e->es0 + b->gas;
    b->expansion = b->group[SIM_EG_EXPANSION];
    b->residual = b->in - b->loss - b->expansion - b->work - b->stored;
    // Normalised by the energy turned over, not by "in": with the pump near
    // standby (hold, a burst line) the fluid's energy comes from the loads
    // sinking (work < 0) and its stored energy, and "in" can be near 0 or
    // negative, so 1 J over 5 J in read 17 %. Each term of the balance is a
    // source (in > 0, or loss, X, work, stored < 0) or a sink; the turnover
    // is the larger of the two sums (they differ by the residual).
    const double terms[5] = {b->in, -b->loss, -b->expansion, -b->work, -b->stored};
    double src = 0.0, snk = 0.0;
    for (int k = 0; k < 5; ++k) {
        if (terms[k] > 0.0) src += terms[k];
        else snk -= terms[k];
    }
    b->turnover = fmax(src, snk);
    b->residual_pct = b->turnover > 0.0 ? 100.0 * b->residual / b->turnover : 0.0;
    b->mech = e->em1 - e->em0;
    b->t0 = e->t0;
    b->t1 = e->tprev;
    b->samples = e->n;
}
