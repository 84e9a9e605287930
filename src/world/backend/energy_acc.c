// energy_acc.c: the run's energy balance (energy_acc.h, docs/energy.md).
#include "energy_acc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct sim_energy {
    const hyd_model* m;
    hyd_data* d;
    int ncol;
    char (*name)[72];
    int* group;
    int* comp; ///< component of the column, -1 for tank and stored
    double *P, *E; ///< (ncol) power at the last sample [W]; energy [J]
    double* Topen; ///< (ncol) time its component was open [s] (reliefs; 0 for the others)
    long n;
    double t0, tprev;
    double es0, es1, em0, em1;
    double gas0, gas1; ///< accumulators' gas energy at the first and the last sample [J]
    double coupling;   ///< compression energy the volumes' jumps between steps put in (sim_energy_follow_inputs) [J]
    int finished;
    double *p1, *V1; ///< (nnode) node pressures and volumes at the last sample
    double* phi;     ///< (nnode) phi(p1) of nodes whose volume has moved (NAN: not followed yet)
    // The next sample, taken (capture) before it is added (commit): a step's
    // quadrature evaluates its stage points against the last sample.
    double *Pn, *pn, *Vn, *phin; ///< (ncol, nnode x 3) as P, p1, V1, phi
    unsigned char* openn;        ///< (ncol) its component passes flow (reliefs)
    double gasn;
    double *compP, *pistP;       ///< (ncomp) scratch: hyd_power_terms
    int nvn, *vn;                ///< the nodes with a pressure state (expansion)
    unsigned char* acc;          ///< (ncol) the column's component is an accumulator
    FILE* csv;
    double csv_dt, csv_next;
    // Following the solver's steps (sim_energy_follow): the system's state
    // at the last sample, and scratch for the step's quadrature.
    int ny;              ///< size of the solver's state (0: not following)
    sim_energy_eval_fn eval;
    void* eval_user;
    double* yprev;       ///< (ny) the state at the last sample
    double *dq, *work;   ///< (ncol) the step's energies [J]; quadrature scratch
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
    free(e->Pn);
    free(e->openn);
    free(e->E);
    free(e->Topen);
    free(e->acc);
    free(e->yprev);
    free(e->dq);
    free(e->work);
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
    free(e->p1);
    free(e->V1);
    free(e->phi);
    free(e->pn);
    free(e->Vn);
    free(e->phin);
    free(e->compP);
    free(e->pistP);
    free(e->vn);
    e->compP = e->pistP = NULL;
    e->vn = NULL;
    e->d = NULL, e->p1 = e->V1 = e->phi = e->pn = e->Vn = e->phin = NULL;
    e->m = NULL;
}

int sim_energy_bind(sim_energy* e, const hyd_model* m) {
    if (e->m || e->ncol) return -1; // one run per accumulator
    e->m = m;
    const int nc = hyd_model_ncomp(m), nn = hyd_model_nnode(m);
    const size_t cap = (size_t)(2 * nc + 3);
    e->d = hyd_data_create(m);
    e->name = calloc(cap, sizeof *e->name);
    e->group = calloc(cap, sizeof *e->group);
    e->comp = calloc(cap, sizeof *e->comp);
    e->P = calloc(cap, sizeof *e->P);
    e->Pn = calloc(cap, sizeof *e->Pn);
    e->openn = calloc(cap, sizeof *e->openn);
    e->E = calloc(cap, sizeof *e->E);
    e->Topen = calloc(cap, sizeof *e->Topen);
    e->acc = calloc(cap, sizeof *e->acc);
    e->p1 = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->p1);
    e->V1 = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->V1);
    e->phi = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->phi);
    e->pn = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->pn);
    e->Vn = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->Vn);
    e->phin = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->phin);
    e->compP = calloc((size_t)(nc > 0 ? nc : 1), sizeof *e->compP);
    e->pistP = calloc((size_t)(nc > 0 ? nc : 1), sizeof *e->pistP);
    e->vn = calloc((size_t)(nn > 0 ? nn : 1), sizeof *e->vn);
    if (!e->d || !e->acc || !e->name || !e->group || !e->comp || !e->P || !e->Pn || !e->openn || !e->E || !e->Topen ||
        !e->p1 || !e->V1 || !e->phi || !e->pn || !e->Vn || !e->phin || !e->compP || !e->pistP || !e->vn) {
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
    for (int i = 0; i < e->ncol; ++i) e->acc[i] = e->comp[i] >= 0 && hyd_model_comp_type(m, e->comp[i]) == HYD_ACCUMULATOR;
    for (int n = 0; n < nn; ++n) {
        e->phi[n] = NAN;
        if (hyd_model_node_state(m, n) >= 0) e->vn[e->nvn++] = n;
    }
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

// Every column's power taken from the fluid at the evaluation d into P
// [W]; phi of the moving nodes at d's pressures, followed from the last
// sample's, into phiout (NULL: a stage point of a step, not kept).
static void powers(sim_energy* e, const hyd_data* d, double* P, double* phiout) {
    const hyd_model* m = e->m;
    double boundary, stored;
    hyd_power_terms(m, d, e->compP, e->pistP, &boundary, &stored);
    for (int i = 0; i < e->ncol; ++i) {
        const int c = e->comp[i];
        switch (e->group[i]) {
        case SIM_EG_VALVE_IN:
        case SIM_EG_VALVE_OUT: {
            double ed[2];
            hyd_valve_edge_power(m, d, c, ed);
            P[i] = ed[e->group[i] == SIM_EG_VALVE_OUT];
            break;
        }
        case SIM_EG_WORK: P[i] = e->pistP[c]; break;
        case SIM_EG_TANK: P[i] = -boundary; break;
        case SIM_EG_STORED: P[i] = c >= 0 ? hyd_comp_gas_power(m, d, c) : stored; break;
        case SIM_EG_EXPANSION: {
            // hyd_expansion_power, with phi followed along the run (one
            // Simpson panel per step) instead of integrated afresh.
            double X = 0.0;
            for (int j = 0; j < e->nvn; ++j) {
                const int n = e->vn[j];
                const double dV = d->node_dV[n];
                double ph = e->phi[n];
                if (isnan(ph)) {
                    if (dV == 0.0) {
                        if (phiout) phiout[n] = NAN;
                        continue;
                    }
                    ph = hyd_node_phi(m, n, d->node_p[n]);
                } else if (e->n > 0) {
                    ph += hyd_node_phi_increment(m, n, e->p1[n], d->node_p[n]);
                }
                if (phiout) phiout[n] = ph;
                X -= dV * ph;
            }
            P[i] = X;
            break;
        }
        // The gas's share of an accumulator's power is stored (its .gas column).
        default: P[i] = e->compP[c] - (e->acc[i] ? hyd_comp_gas_power(m, d, c) : 0.0); break;
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

// Take the next sample from the evaluation d (every output filled).
static void capture(sim_energy* e, const hyd_data* d) {
    const hyd_model* m = e->m;
    const int nn = hyd_model_nnode(m);
    // phi of nodes that are not followed stays NaN (powers writes only the
    // nodes of a volume state).
    memcpy(e->phin, e->phi, (size_t)nn * sizeof *e->phin);
    powers(e, d, e->Pn, e->phin);
    memcpy(e->pn, d->node_p, (size_t)nn * sizeof *e->pn);
    memcpy(e->Vn, d->node_V, (size_t)nn * sizeof *e->Vn);
    double gas = 0.0;
    for (int i = 0; i < e->ncol; ++i) {
        if (e->group[i] == SIM_EG_STORED && e->comp[i] >= 0) gas += hyd_comp_gas_energy(m, d, e->comp[i]);
        e->openn[i] = e->group[i] == SIM_EG_RELIEF && d->comp_open && d->comp_open[e->comp[i]];
    }
    e->gasn = gas;
}

// Add the captured sample at t: dE (NULL: the trapezoid from the last
// sample) the energies since the last sample [J].
static void commit(sim_energy* e, double t, double e_mech, const double* dE) {
    const hyd_model* m = e->m;
    e->gas1 = e->gasn;
    if (e->n == 0) {
        e->gas0 = e->gasn;
        e->t0 = t;
        e->es0 = hyd_stored_energy(m, e->pn, e->Vn);
        e->em0 = e_mech;
    } else {
        const double h = t - e->tprev;
        for (int i = 0; i < e->ncol; ++i) e->E[i] += dE ? dE[i] : 0.5 * h * (e->P[i] + e->Pn[i]);
        // A relief's open time: the step counts when the relief passes flow
        // at its end (the rows' relief_open convention, at step resolution).
        for (int i = 0; i < e->ncol; ++i)
            if (e->openn[i]) e->Topen[i] += h;
    }
    const int nn = hyd_model_nnode(m);
    memcpy(e->P, e->Pn, (size_t)e->ncol * sizeof *e->P);
    memcpy(e->p1, e->pn, (size_t)nn * sizeof *e->p1);
    memcpy(e->V1, e->Vn, (size_t)nn * sizeof *e->V1);
    memcpy(e->phi, e->phin, (size_t)nn * sizeof *e->phi);
    if (!isnan(e_mech) || e->n == 0) e->em1 = e_mech;
    e->tprev = t;
    ++e->n;
    if (e->csv && t >= e->csv_next - 1e-9 * e->csv_dt) {
        csv_row(e, t);
        // The next row one period on, on the grid (a step that lands a
        // little early still writes the row of its grid time).
        e->csv_next = (floor(t / e->csv_dt + 1e-6) + 1.0) * e->csv_dt;
    }
}

int sim_energy_follow(sim_energy* e, int n, sim_energy_eval_fn eval, void* user) {
    if (!e->m || n <= 0 || !eval) return -1;
    free(e->yprev);
    free(e->dq);
    free(e->work);
    e->yprev = calloc((size_t)n, sizeof *e->yprev);
    e->dq = calloc((size_t)e->ncol, sizeof *e->dq);
    e->work = calloc((size_t)e->ncol, sizeof *e->work);
    if (!e->yprev || !e->dq || !e->work) return -1;
    e->ny = n;
    e->eval = eval;
    e->eval_user = user;
    return 0;
}

int sim_energy_quad(void* user, double t, const double* y, double* P) {
    sim_energy* e = user;
    const hyd_data* d = e->eval(e->eval_user, t, y);
    if (!d) return -1;
    powers(e, d, P, NULL);
    return 0;
}

int sim_energy_follow_sample(sim_energy* e, double t, const double* y, double e_mech) {
    return sim_energy_follow_integrated(e, t, y, e_mech, NULL);
}

int sim_energy_follow_integrated(sim_energy* e, double t, const double* y, double e_mech, const double* dE) {
    if (!e->m || !e->ny) return -1;
    const hyd_data* d = e->eval(e->eval_user, t, y);
    if (!d) return -1;
    capture(e, d);
    commit(e, t, e_mech, dE);
    memcpy(e->yprev, y, (size_t)e->ny * sizeof *y);
    return 0;
}

int sim_energy_follow_inputs(sim_energy* e, double t, const double* y) {
    if (!e->m || !e->ny) return -1;
    if (e->n == 0) return sim_energy_follow_sample(e, t, y, NAN);
    const hyd_data* d = e->eval(e->eval_user, t, y);
    if (!d) return -1;
    // The pressures are the last sample's (the state did not move); a volume
    // that changed holds V phi(p) more compression energy at them, which no
    // flow brought. phi as followed (the moving chambers), else afresh.
    const hyd_model* m = e->m;
    for (int n = 0; n < hyd_model_nnode(m); ++n) {
        const double dV = d->node_V[n] - e->V1[n];
        if (dV == 0.0 || hyd_model_node_state(m, n) < 0) continue;
        const double ph = isnan(e->phi[n]) ? hyd_node_phi(m, n, d->node_p[n]) : e->phi[n];
        e->coupling += dV * ph;
    }
    capture(e, d);
    for (int i = 0; i < e->ncol; ++i) e->dq[i] = 0.0;
    commit(e, t, NAN, e->dq);
    return 0;
}

void sim_energy_mech(sim_energy* e, double e_mech) {
    if (e->n <= 1) e->em0 = e_mech; // at the first sample: the start too
    e->em1 = e_mech;
}

int sim_energy_follow_step(sim_energy* e, hyd_solver* s, double t, const double* y, double e_mech) {
    if (!e->m || !e->ny) return -1;
    if (e->n == 0) return sim_energy_follow_sample(e, t, y, e_mech);
    // The end first (its powers are the quadrature's P1), then the step's
    // stage points, evaluated against the last sample (phi, P0 = its
    // powers), which the end then replaces.
    const hyd_data* d = e->eval(e->eval_user, t, y);
    if (!d) return -1;
    capture(e, d);
    const int rc = hyd_solver_step_quadrature(s, e->tprev, e->yprev, y, e->P, e->Pn, e->ncol, sim_energy_quad, e,
                                              e->work, e->dq);
    if (rc) return -1;
    commit(e, t, e_mech, e->dq);
    memcpy(e->yprev, y, (size_t)e->ny * sizeof *y);
    return 0;
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
    b->coupling = e->coupling;
    b->residual = b->in + b->coupling - b->loss - b->expansion - b->work - b->stored;
    // Normalised by the energy turned over, not by "in": with the pump near
    // standby (hold, a burst line) the fluid's energy comes from the loads
    // sinking (work < 0) and its stored energy, and "in" can be near 0 or
    // negative, so 1 J over 5 J in read 17 %. Each term of the balance is a
    // source (in > 0, or loss, X, work, stored < 0) or a sink; the turnover
    // is the larger of the two sums (they differ by the residual).
    const double terms[6] = {b->in, b->coupling, -b->loss, -b->expansion, -b->work, -b->stored};
    double src = 0.0, snk = 0.0;
    for (int k = 0; k < 6; ++k) {
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
