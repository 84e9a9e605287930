// engine_chain.c: scripted runs of the general analytic mode (engine_chain.h).
#include "engine_chain.h"
#include "chain_problem.h"
#include "chain_row.h"
#include "chain_sim.h"
#include "energy_acc.h"
#include "engine_impl.h"
#include "lagrange_row.h"
#include "lagrange_sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void engine_chain_start_pose(const crane_chain* cc, const scenario* sc, double* q0) {
    // One rule for both backends' chain runs (crane_chain.h).
    crane_chain_start_pose(cc, sc->q0, sc->slew0, q0);
}

bool engine_chain_slews(const model* m, const scenario* sc) {
    return m->chain.slew.present && scenario_commands(sc, "slew");
}

int engine_chain_slew_setup(const model* m, crane_chain* cc, hyd_model** hm, char* err, size_t errsz) {
    memset(cc, 0, sizeof *cc);
    *hm = NULL;
    const char* file = m->file[0] ? m->file : "model";
    const cJSON* h = m->json ? cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics") : NULL;
    const cJSON* frag = m->json ? cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics_slew") : NULL;
    if (!m->chain.slew.present || !h || !frag) {
        snprintf(err, errsz, "%s: mechanics.slew: the model has no slew drive (mechanics.slew and hydraulics_slew)",
                 file);
        return -1;
    }
    // A scenario's hose bursts at nodes of the slew's circuit (engine_fault_model
    // left them in world_bursts) open there, as in the sandbox (ode_run.c):
    // their orifices join the fragment; a node it lacks too is refused.
    if (engine_world_bursts(m, frag, "its hydraulics_slew", err, errsz)) return -1;
    cJSON* fx = NULL;
    if (m->world_bursts) {
        fx = cJSON_Duplicate(frag, 1);
        cJSON* comps = fx ? cJSON_GetObjectItemCaseSensitive(fx, "components") : NULL;
        if (!cJSON_IsArray(comps)) {
            snprintf(err, errsz, "out of memory");
            cJSON_Delete(fx);
            return -1;
        }
        const cJSON* o;
        cJSON_ArrayForEach(o, m->world_bursts) cJSON_AddItemToArray(comps, cJSON_Duplicate(o, 1));
        frag = fx;
    }
    // The circuit as the sandbox compiles it (model_slew_check checked it
    // at load), from the document with the run's overrides.
    *hm = model_circuit_with_fragment(h, file, frag, file, "hydraulics_slew", err, errsz);
    cJSON_Delete(fx);
    if (!*hm) return -1;
    if (crane_chain_copy(cc, &m->chain)) {
        snprintf(err, errsz, "out of memory");
        hyd_model_free(*hm);
        *hm = NULL;
        return -1;
    }
    cc->slew_free = true;
    cc->slew_rack_columns = true; // chain_sim's outputs have the rack last
    // Bound anew: the indices are the merged circuit's; the columns gain
    // the rack's (crane_chain_columns).
    char e[300];
    if (crane_chain_bind(cc, *hm, e, sizeof e)) {
        snprintf(err, errsz, "%s: %s", file, e);
        crane_chain_free(cc);
        hyd_model_free(*hm);
        *hm = NULL;
        return -1;
    }
    return 0;
}

typedef struct chain_run_ctx {
    chain_sim* cs;
    const scenario* sc;
    int* fcol;              // [nfn] scenario column of function k, or -1
    const sim_opts* o;
    const engine_sink* sink;
    sim_checks chk;
    double t_last_row, bad_t;
    long rows;
    int stop;
    int step_bad; ///< a step's state failed the run checks (on_step)
    double* below_since; ///< [nh] since when each pressure state is below absolute zero [s], NaN: it is not
    char bad[200];
    double peak[4];
    struct sim_energy* energy; ///< NULL, or the balance accumulated at the steps
    hyd_solver* solver;
    // Output buffers, sized by the chain.
    double *x, *v, *pA, *pB, *F, *u, *ucmd, *q, *qd;
    double* row; ///< SIM_NCOL_BASE base columns, then the chain's (crane_chain_row), at least SIM_NCOL
} chain_run_ctx;

// The scenario's commands by function name (scenario_find_command: lift,
// jib, slew and the file's named columns); a function without one stays at 0.
static double scn_cmd(void* user, int k, double t) {
    const chain_run_ctx* c = user;
    return c->fcol[k] < 0 ? 0.0 : scenario_command(c->sc, c->fcol[k], t);
}

// The row (chain_row.c, shared with the stepped engine).
static void make_row(chain_run_ctx* c, double t, const double* y, double* row) {
    chain_sim_out co = {.x = c->x, .v = c->v, .pA = c->pA, .pB = c->pB, .F = c->F, .u = c->u, .u_cmd = c->ucmd,
                        .q = c->q, .qd = c->qd};
    chain_sim_row(c->cs, t, y, &co, row);
}

static void track_peaks(chain_run_ctx* c, const double* y) {
    const chain_sim* cs = c->cs;
    for (int k = 0; k < 2 && k < cs->cc->nact; ++k) {
        c->peak[2 * k] = fmax(c->peak[2 * k], y[cs->ipA[k]]);
        c->peak[2 * k + 1] = fmax(c->peak[2 * k + 1], y[cs->ipB[k]]);
    }
}

// sim_energy_eval_fn: the circuit at (t, y) with every output filled.
static const hyd_data* energy_eval(void* user, double t, const double* y) {
    chain_sim* cs = user;
    chain_sim_rhs(cs, t, y, cs->ydot);
    --cs->nrhs; // not solver work
    return cs->hd;
}

// The run checks (sim_check_value) on the state at t: 1 when a value fails
// them (c->bad, c->bad_t set), else 0; a dip below absolute zero is
// remembered for the note.
static int check_state(chain_run_ctx* c, double t, const double* y) {
    const chain_sim* cs = c->cs;
    for (int i = 0; i < cs->n; ++i) {
        const bool p = i < cs->nh && cs->is_pressure[i];
        if (isfinite(y[i]) && (!p || y[i] >= 0.0)) continue;
        const char* name = i < cs->nh                ? hyd_model_state_name(cs->hm, cs->perm[i])
                           : i < cs->iq + cs->ndof ? "q"
                                                   : "q_dot";
        if (sim_check_value(&c->chk, name, y[i], p, t, c->bad, sizeof c->bad)) {
            c->bad_t = t;
            return 1;
        }
    }
    return 0;
}

// A pressure state below absolute zero for this long [s] is a failure, not
// a dip: a fixed step ringing at a stiff event dips for a step or a few
// (0.1-0.3 ms at 0.1 ms); a node that stays there is frozen in the bulk
// modulus' continuation below zero (Be of tens of Pa: fluid.c), a vacuum
// the model does not describe. Krus 0.1 ms on chain_8fn_10link.json before
// chain_problem.c held jib_ext1_cyl.pB at -5.3 kPa from 7.067 s for 0.87 s
// while the stage slid free, and ended with a note only (at a 10 ms output
// period: exit 0, "displaced fluid released 296 kJ").
#define BELOW_ZERO_FAIL 0.01

// The states below absolute zero for BELOW_ZERO_FAIL or longer: 1 with
// c->bad, c->bad_t set, else 0.
static int check_below_zero(chain_run_ctx* c, double t, const double* y) {
    const chain_sim* cs = c->cs;
    for (int i = 0; i < cs->nh; ++i) {
        if (!cs->is_pressure[i] || !(y[i] < 0.0)) {
            c->below_since[i] = NAN;
            continue;
        }
        if (isnan(c->below_since[i])) c->below_since[i] = t;
        if (t - c->below_since[i] >= BELOW_ZERO_FAIL) {
            c->chk.bad_value = y[i];
            snprintf(c->bad, sizeof c->bad,
                     "state %s below absolute zero for %.3g s (since t = %.6g s; %.4g Pa at t = %.6g s)",
                     hyd_model_state_name(cs->hm, cs->perm[i]), t - c->below_since[i], c->below_since[i], y[i], t);
            c->bad_t = t;
            return 1;
        }
    }
    return 0;
}

// hyd_solver_opts.on_step: the run checks, the peaks and the energy balance
// at every step. The checks at every step, not only at the rows (which see
// one step in dt_out / h), so neither a value between two rows nor how long
// a node stays below zero depends on the output period. A failure stops
// the run at the next output (emit), with the rows before it.
static void on_step(void* user, double t, const double* y) {
    chain_run_ctx* c = user;
    if (!c->step_bad && (check_state(c, t, y) || check_below_zero(c, t, y))) c->step_bad = 1;
    track_peaks(c, y);
    if (c->energy) sim_energy_follow_step(c->energy, c->solver, t, y, chain_sim_energy(c->cs, y));
}

static int emit(void* user, double t, const double* y) {
    chain_run_ctx* c = user;
    if (c->step_bad) return (c->stop = 3);
    if (c->rows > 0 && t <= c->t_last_row + 1e-9 * c->o->dt_out) return 0;
    if (check_state(c, t, y)) return (c->stop = 3);
    track_peaks(c, y);
    c->t_last_row = t;
    ++c->rows;
    if (!c->sink->rows) return 0;
    double* row = c->row;
    make_row(c, t, y, row);
    if (sim_check_row(&c->chk, row, SIM_NCOL_BASE, c->bad, sizeof c->bad)) {
        --c->rows;
        c->bad_t = t;
        return (c->stop = 3);
    }
    if (c->sink->row && c->sink->row(c->sink->user, row)) return (c->stop = 2);
    return 0;
}

int engine_chain_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k, sim_result* res) {
    char* msg = res->message;
    const size_t msz = sizeof res->message;
    // A slewing run (the slew a degree of freedom, driven by the model's
    // slew drive): the model's chain with the rack, on the model's circuit
    // with hydraulics_slew appended.
    const bool slews = engine_chain_slews(m, sc);
    if (o->variant == LAGRANGE_PAPER || o->variant == LAGRANGE_PAPER_TYPO) {
        if (slews && m->chain.two_link)
            snprintf(msg, msz,
                     "--variant %s: the paper's equations are for the planar two-link crane; scenario %s slews it, "
                     "which takes the general formulation (full or general)",
                     lagrange_variant_name(o->variant), sc->name[0] ? sc->name : "the scenario");
        else
            snprintf(msg, msz,
                     "--variant %s: the paper's equations are for the two-link crane only; this run takes the "
                     "general formulation (full or general)",
                     lagrange_variant_name(o->variant));
        return res->status = SIM_REFUSED;
    }
    if (o->cvode) {
        snprintf(msg, msz, "--solver cvode: the general analytic mode runs the in-house solvers");
        return res->status = SIM_REFUSED;
    }
    // (A slewing run checks the bursts against the slew's circuit, which it appends.)
    if (!slews && engine_world_bursts(m, NULL, NULL, msg, msz)) return res->status = SIM_REFUSED;
    const double m3 = sim_load_mass(m, sc, o);
    crane_chain slew_cc;
    hyd_model* slew_hm = NULL;
    const crane_chain* cc = &m->chain;
    hyd_model* hm = m->hyd;
    if (slews) {
        if (engine_chain_slew_setup(m, &slew_cc, &slew_hm, msg, msz)) return res->status = SIM_REFUSED;
        cc = &slew_cc, hm = slew_hm;
    }
    chain_sim cs;
    if (chain_sim_init(&cs, cc, hm, m3, sc->slew0, msg, msz)) {
        if (slews) crane_chain_free(&slew_cc), hyd_model_free(slew_hm);
        return res->status = SIM_REFUSED;
    }
    const int nd = cs.ndof, na = cs.nact, nf = cs.nfn;
    chain_run_ctx c;
    memset(&c, 0, sizeof c);
    chain_problem cp;
    memset(&cp, 0, sizeof cp);
    const size_t nrow = (size_t)chain_row_size(cc);
    double* buf = calloc((size_t)cs.n + 5 * (size_t)na + 2 * (size_t)nf + 3 * (size_t)nd + nrow + (size_t)cs.nh + 1,
                         sizeof *buf);
    c.fcol = calloc((size_t)nf + 1, sizeof *c.fcol);
    hyd_solver* s = NULL;
    if (!buf || !c.fcol) {
        snprintf(msg, msz, "out of memory");
        res->status = SIM_REFUSED;
        goto done;
    }
    double* y = buf;
    double* q0 = y + cs.n;
    c.x = q0 + nd, c.v = c.x + na, c.pA = c.v + na, c.pB = c.pA + na, c.F = c.pB + na;
    c.u = c.F + na, c.ucmd = c.u + nf, c.q = c.ucmd + nf, c.qd = c.q + nd;
    c.row = c.qd + nd;
    c.below_since = c.row + nrow;
    for (int i = 0; i < cs.nh; ++i) c.below_since[i] = NAN;
    for (int f = 0; f < nf; ++f) c.fcol[f] = scenario_find_command(sc, chain_sim_function_name(&cs, f));
    c.cs = &cs;
    c.sc = sc;
    c.sink = k;
    cs.cmd_fn = scn_cmd;
    cs.cmd_user = &c;
    engine_chain_start_pose(cc, sc, q0);
    const double t_end = o->duration > 0 ? o->duration : sc->duration;
    engine_faults ef;
    engine_faults_init(&ef, hm);
    // The merged circuit is compiled from the document, where a scenario's
    // hose bursts load open: closed (and the other faults set) as at t = 0.
    if (slews) engine_faults_apply(&ef, hm, sc, 0.0);
    if (chain_sim_check_pose(&cs, q0, msg, msz) || chain_sim_initial_state(&cs, q0, 0.5e6, y, msg, msz) ||
        sim_check_fixed_step(hm, o, o->h, t_end, msg, msz) || (k->probe && k->probe(m, o, o->h, msg, msz))) {
        res->status = SIM_REFUSED;
        goto done;
    }
    {
        chain_run_ctx c0 = c;
        double* row0 = c.row;
        make_row(&c0, 0.0, y, row0);
        const sim_start_load ld = {m->chain.two_link ? &m->mech : NULL, {sc->q0[0], sc->q0[1]}, m3, false};
        if (sim_check_start(hm, row0, SIM_NCOL_BASE, &ld, msg, msz)) {
            res->status = SIM_REFUSED;
            goto done;
        }
    }
    const bool adaptive = hyd_method_is_adaptive(o->solver);
    hyd_problem prob;
    hyd_solver_opts so;
    if (chain_problem_setup(&cp, &cs, &m->chain, o, &prob, &so)) {
        snprintf(msg, msz, "cannot set up the chain's problem (out of memory, or a hook of chain_sim's problem "
                           "that chain_problem.c does not forward)");
        res->status = SIM_REFUSED;
        goto done;
    }
    if (k->energy && (sim_energy_bind(k->energy, hm) || sim_energy_follow(k->energy, cs.n, energy_eval, &cs))) {
        snprintf(msg, msz, "out of memory for the energy balance");
        res->status = SIM_REFUSED;
        goto done;
    }
    c.energy = k->energy;
    so.on_step = on_step;
    so.on_step_user = &c;
    s = hyd_solver_create(&prob, o->solver, &so);
    c.solver = s;
    if (!s) {
        snprintf(msg, msz, "cannot create the %s solver", hyd_method_name(o->solver));
        res->status = SIM_REFUSED;
        goto done;
    }
    sim_opts oo = *o;
    if (!adaptive && oo.h > oo.dt_out) oo.dt_out = oo.h;
    if (oo.dt_out > t_end && t_end > 0) oo.dt_out = t_end;
    c.o = &oo;
    // Between the command breakpoints (rounded to the output grid), the
    // solver reset at each, as engine_lagrange.c's run.
    double bp[SCENARIO_MAX_POINTS * SCENARIO_MAX_CMD + SCENARIO_MAX_EVENTS + 9 * SCENARIO_MAX_FAULTS + 2];
    const int nbp = scenario_breakpoints(sc, bp, (int)(sizeof bp / sizeof bp[0]) - 1);
    double t = 0.0;
    int rc = HYD_OK;
    const double w0 = sim_wall_time();
    if (slews && k->run_chain) *k->run_chain = cc;
    if (c.energy) sim_energy_follow_sample(c.energy, 0.0, y, chain_sim_energy(&cs, y));
    emit(&c, 0.0, y);
    for (int i = 0; i <= nbp && rc == HYD_OK && !c.stop && t < t_end; ++i) {
        double tb = i < nbp ? ceil(bp[i] / oo.dt_out - 1e-9) * oo.dt_out : t_end;
        if (tb > t_end) tb = t_end;
        if (tb <= t + 1e-12) continue;
        engine_faults_apply(&ef, hm, sc, 0.5 * (t + tb));
        hyd_solver_reset(s);
        if (c.energy && t > 0.0) sim_energy_follow_inputs(c.energy, t, y);
        rc = hyd_solver_integrate(s, t, y, tb, oo.dt_out, emit, &c);
        if (rc == HYD_OK && !c.stop) t = tb;
    }
    res->wall = sim_wall_time() - w0;
    res->stats = *hyd_solver_get_stats(s);
    res->rows = c.rows;
    res->t_end = c.t_last_row;
    if (c.stop == 3) {
        res->status = c.bad_t > 0 ? SIM_FAILED : SIM_REFUSED;
        char how[96];
        snprintf(how, sizeof how, "solver %s, h = %g s", hyd_method_name(o->solver),
                 adaptive ? hyd_solver_last_h(s) : o->h);
        sim_check_message(msg, msz, c.bad, res->status == SIM_REFUSED ? NULL : how, adaptive, c.bad_t,
                          c.chk.bad_value);
    } else if (c.stop) {
        res->status = SIM_REFUSED;
        snprintf(msg, msz, "stopped at t = %.6g s", c.t_last_row);
    } else if (rc != HYD_OK) {
        res->status = SIM_FAILED;
        snprintf(msg, msz, "solver %s stopped near t = %.6g s: %s", hyd_method_name(o->solver), c.t_last_row,
                 hyd_error_text(rc));
    } else {
        res->status = SIM_OK;
    }
    memcpy(res->p_peak, c.peak, sizeof res->p_peak);
    res->peak_steps = k->summary;
    if (!res->status) sim_checks_note(&c.chk, adaptive, res->note, sizeof res->note);
    if (k->energy) sim_energy_finish(k->energy);
done:
    hyd_solver_destroy(s);
    chain_problem_free(&cp);
    free(buf);
    free(c.fcol);
    chain_sim_free(&cs);
    if (slews) {
        crane_chain_free(&slew_cc);
        hyd_model_free(slew_hm);
    }
    return res->status;
}
