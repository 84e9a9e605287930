// engine_ode_chain.c: scripted runs (engine_run) of the ode backend for a
// chain model, in the chain world (ode_chain.h) or, for a sandbox world, in
// the sandbox with the crane from the chain (ode_world.h opts.chain),
// engine_ode_chain.h.
#include "engine_ode_chain.h"
#include "energy_acc.h"
#include "engine_faults.h"
#include "ode_chain.h"
#include "ode_chain_row.h"
#include "ode_run.h"
#include "rcl.h"
#include "world_desc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// The rated capacity limiter of a scripted chain run (o->rcl; rcl_filter_fn
// between the scenario and the world, as engine.c has it for the stepped
// engines), its rows' chain columns from base on; NULL with the reason in
// note when the model's chain has none (rcl_check_model), or when o->rcl is
// off: a chain's limiter searches every joint for its chart (about a
// second), so a run that does not ask for it does not pay for it.
static rcl* chain_limiter(const model* m, const sim_opts* o, const char* world, int base, char* note, size_t n) {
    if (!o->rcl) return NULL;
    char why[400];
    if (rcl_check_model(m, why, sizeof why)) {
        snprintf(note, n, "%.200s: not applied, rcl_util is 0", why);
        return NULL;
    }
    char wbuf[512];
    rcl* r = rcl_create(m, world ? sim_world_path(world, wbuf, sizeof wbuf) : NULL);
    if (r && rcl_set_chain_row(r, NULL, base)) rcl_destroy(r), r = NULL;
    if (!r) snprintf(note, n, "the rated capacity limiter's chart could not be made: not applied, rcl_util is 0");
    return r;
}

// Hand a finished row to the driver's sink; non-zero: stop.
static int deliver(const engine_sink* k, const double* row) { return k->row && k->row(k->user, row); }

// An output row of either chain run: the run checks on its first ncheck
// columns, then the sink. 1 when the run ends here: a check failed
// (res->status SIM_FAILED, the message names the step), or the sink asked
// to stop (*stop).
static int emit_row(sim_checks* chk, const double* row, int ncheck, const sim_opts* o, double h, double dt,
                    const engine_sink* k, sim_result* res, int* stop) {
    char what[200];
    if (sim_check_row(chk, row, ncheck, what, sizeof what)) {
        res->status = SIM_FAILED;
        char how[96];
        snprintf(how, sizeof how, "solver %s, h = %g s, ODE step %g s", hyd_method_name(o->solver), h, dt);
        sim_check_message(res->message, sizeof res->message, what, how, false, row[COL_T], chk->bad_value);
        return 1;
    }
    *stop = deliver(k, row);
    return 0;
}

// The kind of the world o names (the validation world when none): the
// validation world runs in the chain world (the column on the ground, the
// load at the tip), the sandbox in ode_world with the crane from the chain
// (run_sandbox). -1 with the loader's message.
int engine_ode_chain_world_kind(const sim_opts* o, world_kind* kind, char* err, size_t errsz) {
    *kind = WORLD_VALIDATION;
    if (!o->world) return 0;
    char buf[512];
    const char* wp = sim_world_path(o->world, buf, sizeof buf);
    world_desc wd;
    if (world_desc_load(wp, &wd, err, errsz)) return -1;
    *kind = wd.kind;
    world_desc_free(&wd);
    return 0;
}

static int play_hook(void* user, int attach) { return ode_world_hook(user, attach); }

int engine_ode_chain_sandbox_start(ode_world* w, ode_chain_rows* r, const crane_chain* cc, const double q0[2],
                                   sim_checks* chk, double* row, char* msg, size_t msz) {
    // One row: the sandbox's base columns, then the chain's (ode_chain_row.c).
    ode_chain_sandbox_row(r, w, cc, 0.0, row);
    char what[200];
    if (sim_check_row(chk, row, SIM_NCOL, what, sizeof what)) {
        sim_check_message(msg, msz, what, NULL, false, 0.0, chk->bad_value);
        return -1;
    }
    // The start pressures against the circuit's limits, with the world's
    // rope and hook at the tip (the booms' share is not split out: the
    // two-link statics do not describe this chain).
    int nl;
    double len, lm, li, hkm, hcom, hi;
    ode_world_rope_info(w, &nl, &len, &lm, &li, &hkm, &hcom, &hi);
    const sim_start_load ld = {NULL, {q0[0], q0[1]}, nl * lm + hkm, true};
    return sim_check_start(ode_world_circuit(w), row, SIM_NCOL, &ld, msg, msz) ? -1 : 0;
}

// A scripted run in the sandbox (ode_world with the chain crane on its
// truck, ode_world.h opts.chain): the scenario's functions by name and its
// slew at each ODE step's midpoint, its hook events as the two-link
// sandbox's; rows of the sandbox's base columns (ode_world_row: the first
// two actuators, the first two boom DOFs, the slew, hook, truck, supports)
// then the chain's columns. The rated capacity limiter where o->rcl asks
// (chain_limiter; rcl_util 0 without it). What the two-link run has and this
// one does not: the tip load (the sandbox's loads hang on the hook).
static int run_sandbox(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k,
                       sim_result* res) {
    char* msg = res->message;
    const size_t msz = sizeof res->message;
    ode_world* w = ode_world_for_run(m, o, "sandbox", sc->q0, sc->slew0, 0.0, msg, msz);
    if (!w) return res->status = SIM_REFUSED;
    rcl* lim = NULL;
    double *now = NULL, *ulim = NULL;
    char lnote[sizeof res->note] = "";
    ode_chain* cw = ode_world_chain(w);
    const crane_chain* cc = &m->chain;
    const crane_chain* hc = ode_chain_chain(cw); // the hosted copy: the column slews
    hyd_model* hm = ode_world_circuit(w);
    // The outputs of the hosted chain (ode_chain_row.c, as the chain
    // world's runs read them), and a row.
    ode_chain_rows r;
    const int rows_rc = ode_chain_rows_init(&r, hc, hm, ode_chain_ndof(cw));
    double* buf = calloc(SIM_NCOL + (size_t)cc->ncol + 1, sizeof *buf);
    int* fcol = calloc((size_t)hc->nfn + 1, sizeof *fcol);
    if (rows_rc || !buf || !fcol) {
        snprintf(msg, msz, "out of memory");
        res->status = SIM_REFUSED;
        goto done;
    }
    double* row = buf;
    for (int f = 0; f < r.nf; ++f) fcol[f] = scenario_find_command(sc, hc->fn[f].name);
    // The limiter reads the model's chain columns after the sandbox's
    // channels (ode_chain_sandbox_row), and filters the functions then the slew.
    lim = chain_limiter(m, o, o->world ? o->world : "sandbox", SIM_NCOL, lnote, sizeof lnote);
    now = lim ? calloc(SIM_NCOL + (size_t)cc->ncol + 1, sizeof *now) : NULL;
    ulim = lim ? calloc(2 * ((size_t)r.nf + 1), sizeof *ulim) : NULL;
    if (lim && (!now || !ulim)) {
        snprintf(msg, msz, "out of memory");
        res->status = SIM_REFUSED;
        goto done;
    }
    const double dt = ode_world_dt(w);
    const double h = o->h < dt ? o->h : dt;
    const double t_end = k->t_end;
    if ((res->status = sim_check_fixed_step(r.hm, o, h, t_end, msg, msz)) ||
        (k->probe && (res->status = k->probe(m, o, h, msg, msz))))
        goto done;
    if (t_end / dt > 1e12) {
        snprintf(msg, msz, "%s %g s over %g s is %.3g steps, more than 1e12: use a larger %s or a shorter run",
                 sim_param_name(SIM_PARAM_DT_ODE), dt, t_end, t_end / dt, sim_param_name(SIM_PARAM_DT_ODE));
        res->status = SIM_REFUSED;
        goto done;
    }
    sim_checks chk;
    memset(&chk, 0, sizeof chk);
    const long ode_msgs = ode_world_messages(NULL);
    // The first row and the start checks (shared with the stepped engine).
    if (engine_ode_chain_sandbox_start(w, &r, cc, sc->q0, &chk, row, msg, msz)) {
        res->status = SIM_REFUSED;
        goto done;
    }
    for (int j = 0; j < 4; ++j) res->p_peak[j] = row[COL_P1A + j];
    sim_energy* en = k->energy;
    if (en && (sim_energy_bind(en, r.hm) || ode_world_follow_energy(w, en))) {
        snprintf(msg, msz, "out of memory for the energy balance");
        res->status = SIM_REFUSED;
        goto done;
    }
    if (en) sim_energy_mech(en, ode_world_energy(w));
    const long nstep = (long)floor(t_end / dt + 0.5);
    long nout = (long)floor(fmin(o->dt_out, t_end) / dt + 0.5);
    if (nout < 1) nout = 1;
    engine_faults ef;
    engine_faults_init(&ef, hm);
    const double w0 = sim_wall_time();
    int stop = deliver(k, row);
    long rows = 1;
    double t_last = 0.0;
    int ev = 0;
    for (long i = 0; i < nstep && !stop; ++i) {
        // Commands at the step's midpoint: the functions by name, the slew
        // and the hook's events as the two-link sandbox plays them.
        const double tm = ((double)i + 0.5) * dt;
        double u3[SCENARIO_NCMD];
        scenario_play(sc, tm, &ev, u3, play_hook, w);
        for (int f = 0; f < r.nf; ++f) r.u[f] = fcol[f] >= 0 ? scenario_command(sc, fcol[f], tm) : 0.0;
        engine_faults_apply(&ef, hm, sc, tm);
        double slew_u = u3[2];
        if (lim) { // the functions, then the slew, on the state now
            // (the row's outputs reuse r.u for the spools: the commands first)
            for (int f = 0; f < r.nf; ++f) ulim[f] = r.u[f];
            ulim[r.nf] = slew_u;
            ode_chain_sandbox_row(&r, w, cc, (double)i * dt, now);
            rcl_filter_fn(lim, now, r.nf + 1, ulim, ulim + r.nf + 1, r.nf);
            for (int f = 0; f < r.nf; ++f) r.u[f] = ulim[r.nf + 1 + f];
            slew_u = ulim[2 * r.nf + 1];
        }
        ode_chain_set_commands(cw, r.u);
        ode_chain_set_slew_command(cw, slew_u);
        if (ode_world_step(w, dt)) {
            res->status = SIM_FAILED;
            snprintf(msg, msz, "numerical blow-up: %s", ode_world_error(w));
            break;
        }
        if (en) sim_energy_mech(en, ode_world_energy(w));
        {
            const char* pairs[16][2];
            const int np = ode_world_collisions(w, pairs, 16);
            if (np >= 0) sim_collisions_step(&res->coll, (double)(i + 1) * dt, (const char* const(*)[2])pairs, np);
        }
        {
            double pA[ODE_NACT], pB[ODE_NACT];
            ode_world_chamber_pressures(w, pA, pB);
            const double p[4] = {pA[0], pB[0], pA[1], pB[1]};
            for (int j = 0; j < 4; ++j) res->p_peak[j] = fmax(res->p_peak[j], p[j]);
        }
        if ((i + 1) % nout && i + 1 != nstep) continue;
        ode_chain_sandbox_row(&r, w, cc, (double)(i + 1) * dt, row); // exact grid times
        if (lim) row[COL_RCL_UTIL] = rcl_utilisation(lim, row);
        if (emit_row(&chk, row, SIM_NCOL, o, h, dt, k, res, &stop)) break;
        t_last = row[COL_T];
        ++rows;
    }
    res->wall = sim_wall_time() - w0;
    res->stats.steps = (long)floor(ode_world_time(w) / dt + 0.5) * (long)floor(dt / h + 0.5);
    res->rows = rows;
    res->t_end = t_last;
    res->peak_steps = true;
    if (en) sim_energy_finish(en);
    if (stop && !res->status) {
        res->status = SIM_REFUSED;
        snprintf(msg, msz, "stopped at t = %.6g s", t_last);
    }
    if (!res->status) {
        const char* last;
        const long msgs = ode_world_messages(&last) - ode_msgs;
        if (lnote[0]) snprintf(res->note, sizeof res->note, "%s", lnote);
        if (chk.dip) sim_checks_note(&chk, false, res->note, sizeof res->note);
        else if (msgs > 0)
            snprintf(res->note, sizeof res->note,
                     "ODE reported %ld solver message%s during the run (last: %.120s): a degenerate contact set, "
                     "which ODE stepped through",
                     msgs, msgs > 1 ? "s" : "", last);
    }
done:
    ode_world_destroy(w);
    rcl_destroy(lim);
    free(now), free(ulim);
    free(buf);
    free(fcol);
    if (!rows_rc) ode_chain_rows_free(&r);
    return res->status;
}

int engine_ode_chain_check(const sim_opts* o, double* dt_ode, double* h_hyd, char* msg, size_t msz) {
    if (hyd_method_is_adaptive(o->solver)) {
        snprintf(msg, msz,
                 "solver %s is adaptive: the ODE chain world sub-steps its circuit with a fixed-step method (krus, "
                 "ros2, rk4)",
                 hyd_method_name(o->solver));
        return -1;
    }
    const double dt = o->dt_ode > 0 ? o->dt_ode : 1e-3;
    // As ode_world_for_run: the forces lag the bodies by one ODE step.
    if (dt > 0.01 + 1e-12) {
        snprintf(msg, msz,
                 "%s %g s is too long: the cylinder forces lag the bodies by one ODE step, which beyond 0.01 s "
                 "distorts the pressures by more than 15 %% and then goes unstable (docs/ode_world.md)",
                 sim_param_name(SIM_PARAM_DT_ODE), dt);
        return -1;
    }
    const double h = o->h < dt ? o->h : dt;
    const double ratio = dt / h;
    if (fabs(ratio - floor(ratio + 0.5)) > 1e-6) {
        snprintf(msg, msz, "%s %g s must divide the ODE step %g s (hydraulic sub-steps)", sim_param_name(SIM_PARAM_DT),
                 h, dt);
        return -1;
    }
    *dt_ode = dt;
    *h_hyd = h;
    return 0;
}

int engine_ode_chain_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k,
                         sim_result* res) {
    char* msg = res->message;
    const size_t msz = sizeof res->message;
    world_kind kind;
    if (engine_ode_chain_world_kind(o, &kind, msg, msz)) return res->status = SIM_REFUSED;
    if (kind == WORLD_SANDBOX) return run_sandbox(m, sc, o, k, res);
    double dt, h;
    if (engine_ode_chain_check(o, &dt, &h, msg, msz)) return res->status = SIM_REFUSED;
    // No world circuit here: a burst at a node the model lacks has nowhere to open.
    if (engine_world_bursts(m, NULL, NULL, msg, msz)) return res->status = SIM_REFUSED;
    const double ratio = dt / h;
    const double t_end = k->t_end;
    if (t_end / dt > 1e12) {
        snprintf(msg, msz, "%s %g s over %g s is %.3g steps, more than 1e12: use a larger %s or a shorter run",
                 sim_param_name(SIM_PARAM_DT_ODE), dt, t_end, t_end / dt, sim_param_name(SIM_PARAM_DT_ODE));
        return res->status = SIM_REFUSED;
    }
    const crane_chain* cc = &m->chain;
    const int nd = crane_chain_ndof(cc);
    const size_t nf = (size_t)cc->nfn;
    rcl* lim = NULL;
    double *now = NULL, *ulim = NULL;
    char lnote[sizeof res->note] = "";
    // The outputs and the row (ode_chain_row.c, shared with the stepped
    // engine); here the start pose and the row: SIM_NCOL channels, then the
    // chain's columns.
    ode_chain_rows r;
    const int rows_rc = ode_chain_rows_init(&r, cc, m->hyd, nd);
    double* buf = calloc((size_t)nd + (size_t)ode_chain_row_ncol(cc) + 1, sizeof *buf);
    int* fcol = calloc(nf + 1, sizeof *fcol);
    ode_chain* w = NULL;
    if (rows_rc || !buf || !fcol) {
        snprintf(msg, msz, "out of memory");
        res->status = SIM_REFUSED;
        goto done;
    }
    double* q0 = buf;
    double* row = q0 + nd;
    for (int f = 0; f < r.nf; ++f) fcol[f] = scenario_find_command(sc, cc->fn[f].name);
    // The limiter (the validation world: no truck) on the rows: the chain's
    // columns after SIM_NCOL (ode_chain_make_row).
    lim = chain_limiter(m, o, NULL, SIM_NCOL, lnote, sizeof lnote);
    now = lim ? calloc((size_t)ode_chain_row_ncol(cc) + 1, sizeof *now) : NULL;
    ulim = lim ? calloc(2 * ((size_t)r.nf + 1), sizeof *ulim) : NULL;
    if (lim && (!now || !ulim)) {
        snprintf(msg, msz, "out of memory");
        res->status = SIM_REFUSED;
        goto done;
    }
    // The analytic general path's start pose, so both start from one state.
    crane_chain_start_pose(cc, sc->q0, sc->slew0, q0);
    ode_chain_opts co = ode_chain_default_opts();
    co.dt_ode = dt;
    co.dt_hyd = h;
    co.solver = o->solver;
    co.jac_every = o->jac_every > 0 ? o->jac_every : 1;
    const double m3 = sim_load_mass(m, sc, o);
    co.tip_mass = m3;
    co.q0 = q0;
    co.slew0 = sc->slew0;
    co.circuit = m->hyd;
    co.p_low = 0.5e6; // as the analytic mode's start state, so both start from the same pressures
    co.model_file = m->file[0] ? m->file : "model";
    w = ode_chain_create(cc, &co, msg, msz);
    if (!w) {
        res->status = SIM_REFUSED;
        goto done;
    }
    if ((res->status = sim_check_fixed_step(m->hyd, o, h, t_end, msg, msz)) ||
        (k->probe && (res->status = k->probe(m, o, h, msg, msz))))
        goto done;
    sim_checks chk;
    memset(&chk, 0, sizeof chk);
    ode_chain_make_row(&r, w, 0.0, row);
    for (int j = 0; j < 4; ++j) res->p_peak[j] = row[COL_P1A + j];
    {
        // The start state: a model value that overflows shows at t = 0.
        char what[200];
        if (sim_check_row(&chk, row, SIM_NCOL_BASE, what, sizeof what)) {
            sim_check_message(msg, msz, what, NULL, false, 0.0, chk.bad_value);
            res->status = SIM_REFUSED;
            goto done;
        }
        const sim_start_load ld = {NULL, {sc->q0[0], sc->q0[1]}, m3, false};
        if (sim_check_start(m->hyd, row, SIM_NCOL_BASE, &ld, msg, msz)) {
            res->status = SIM_REFUSED;
            goto done;
        }
    }
    sim_energy* en = k->energy;
    if (en && (sim_energy_bind(en, m->hyd) || ode_chain_follow_energy(w, en))) {
        snprintf(msg, msz, "out of memory for the energy balance");
        res->status = SIM_REFUSED;
        goto done;
    }
    if (en) sim_energy_mech(en, ode_chain_energy(w));
    const long nstep = (long)floor(t_end / dt + 0.5);
    long nout = (long)floor(fmin(o->dt_out, t_end) / dt + 0.5);
    if (nout < 1) nout = 1;
    engine_faults ef;
    engine_faults_init(&ef, m->hyd);
    const double w0 = sim_wall_time();
    int stop = deliver(k, row);
    long rows = 1;
    double t_last = 0.0;
    for (long i = 0; i < nstep && !stop; ++i) {
        // Commands at the step's midpoint, by function name (a function the
        // scenario does not command stays at 0), as the two-link world.
        const double tm = ((double)i + 0.5) * dt;
        for (int f = 0; f < r.nf; ++f) r.u[f] = fcol[f] >= 0 ? scenario_command(sc, fcol[f], tm) : 0.0;
        engine_faults_apply(&ef, m->hyd, sc, tm);
        if (lim) { // the functions on the state now
            // (the row's outputs reuse r.u for the spools: the commands first)
            memcpy(ulim, r.u, (size_t)r.nf * sizeof *ulim);
            ode_chain_make_row(&r, w, (double)i * dt, now);
            rcl_filter_fn(lim, now, r.nf, ulim, ulim + r.nf + 1, -1);
            memcpy(r.u, ulim + r.nf + 1, (size_t)r.nf * sizeof *ulim);
        }
        ode_chain_set_commands(w, r.u);
        if (ode_chain_step(w, dt)) {
            res->status = SIM_FAILED;
            snprintf(msg, msz, "numerical blow-up: %s", ode_chain_error(w));
            break;
        }
        if (en) sim_energy_mech(en, ode_chain_energy(w));
        // Peaks at every ODE step, not only at the rows.
        for (int a = 0; a < 2 && a < r.na; ++a) {
            double pA, pB;
            ode_chain_act_force(w, a, &pA, &pB);
            res->p_peak[2 * a] = fmax(res->p_peak[2 * a], pA);
            res->p_peak[2 * a + 1] = fmax(res->p_peak[2 * a + 1], pB);
        }
        if ((i + 1) % nout && i + 1 != nstep) continue;
        ode_chain_make_row(&r, w, (double)(i + 1) * dt, row); // exact grid times
        if (lim) row[COL_RCL_UTIL] = rcl_utilisation(lim, row);
        if (emit_row(&chk, row, SIM_NCOL_BASE, o, h, dt, k, res, &stop)) break;
        t_last = row[COL_T];
        ++rows;
    }
    res->wall = sim_wall_time() - w0;
    // The fixed hydraulic sub-steps taken: nsub per ODE step done.
    res->stats.steps = (long)floor(ode_chain_time(w) / dt + 0.5) * (long)floor(ratio + 0.5);
    res->rows = rows;
    res->t_end = t_last;
    res->peak_steps = true;
    if (en) sim_energy_finish(en);
    if (stop && !res->status) {
        res->status = SIM_REFUSED;
        snprintf(msg, msz, "stopped at t = %.6g s", t_last);
    }
    if (!res->status && lnote[0]) snprintf(res->note, sizeof res->note, "%s", lnote);
    if (!res->status && chk.dip) sim_checks_note(&chk, false, res->note, sizeof res->note);
done:
    ode_chain_destroy(w);
    rcl_destroy(lim);
    free(now), free(ulim);
    free(buf);
    free(fcol);
    if (!rows_rc) ode_chain_rows_free(&r);
    return res->status;
}
