// engine_lagrange.c: the lagrange crane (lagrange_sim.h: the analytic
// 2-DOF crane and its full circuit as one ODE system) behind engine.h,
// stepped by an outside loop with commands set between steps.
#include "engine_lagrange.h"
#include "engine_chain.h"
#include "engine_chain_step.h"
#include "lagrange_row.h"
#include "lagrange_sim.h"
#include "energy_acc.h"

#include "snap_reliefs.h"
#ifdef CRANESIM_HAVE_CVODE
#include "hyd_cvode.h"
#endif

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct eng_lagrange {
    engine base;
    lsim ls;
    hyd_problem prob;
    hyd_solver* solver;
    double t;
    double y[LSIM_MAX_STATES];
    struct sim_energy* energy; ///< engine_follow_energy's balance, or NULL
} eng_lagrange;

static void lag_row(engine* e, double row[SIM_NCOL]);
static void lag_destroy(engine* e);

static engine* lag_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3,
                          char* err, size_t errsz) {
    (void)slew0; // the planar crane does not slew
    // The stepped engine is the closed form's (the fast path's allow-list:
    // the two-link shorthand, variant full, paper or paper-typo).
    if (model_require_two_link(m, "stepped closed-form analytic mode (drive, serve; a scripted run of this model "
                                  "takes the general formulation)",
                               err, errsz))
        return NULL;
    // No world circuit here: a burst at a node the model lacks has nowhere to open.
    if (engine_world_bursts(m, NULL, NULL, err, errsz)) return NULL;
    eng_lagrange* l = calloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    l->base.ops = &engine_lagrange_ops;
    l->base.o = *o;
    l->base.h_probe = o->h;
    if (lsim_init(&l->ls, m, o->variant, m3, err, errsz)) {
        free(l);
        return NULL;
    }
    // The step probe follows in engine.c (engine_create_rcl), on h_probe.
    if (lsim_check_pose(&l->ls, q0, err, errsz) || sim_check_fixed_step(m->hyd, o, o->h, 0.0, err, errsz)) {
        lsim_free(&l->ls);
        free(l);
        return NULL;
    }
    lsim_initial_state(&l->ls, q0, 0.5e6, l->y);
    double row0[SIM_NCOL];
    lag_row(&l->base, row0);
    const sim_start_load ld = {&m->mech, {q0[0], q0[1]}, m3, false};
    if (sim_check_start(m->hyd, row0, SIM_NCOL_BASE, &ld, err, errsz)) {
        lsim_free(&l->ls);
        free(l);
        return NULL;
    }
    // The drive panel edits circuit parameters in place (hyd_model_set), and
    // the fused kernel holds a packed copy of them: live runs keep the
    // general path, which reads the model on every call. Real time needs 1x,
    // not the fused kernel's speed.
    l->ls.use_fused = false;
    l->ls.use_fast = false;
    const bool adaptive = hyd_method_is_adaptive(o->solver);
    l->prob = lsim_problem(&l->ls, !adaptive && !o->dense_jac);
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = adaptive ? 0.0 : o->h;
    so.rtol = o->rtol;
    so.atol = o->atol;
    so.jac_every = adaptive ? 1 : (o->jac_every > 0 ? o->jac_every : 1);
    if (o->no_retry) so.retry_halvings = 0;
    l->solver = hyd_solver_create(&l->prob, o->solver, &so);
    if (!l->solver) {
        snprintf(err, errsz, "cannot create the %s solver", hyd_method_name(o->solver));
        lag_destroy(&l->base);
        return NULL;
    }
    return &l->base;
}

static void lag_destroy(engine* e) {
    eng_lagrange* l = (eng_lagrange*)e;
    hyd_solver_destroy(l->solver);
    lsim_free(&l->ls);
    free(l);
}

static hyd_model* lag_circuit(engine* e) { return ((eng_lagrange*)e)->ls.mdl->hyd; }

// The system state holds the circuit's states permuted (lsim.hpos).
static void lag_circuit_state(engine* e, double* y, const hyd_data** in) {
    eng_lagrange* l = (eng_lagrange*)e;
    for (int j = 0; j < l->ls.nh; ++j) y[j] = l->y[l->ls.hpos[j]];
    *in = l->ls.hd;
}

static void lag_set_load(engine* e, double m3) {
    eng_lagrange* l = (eng_lagrange*)e;
    if (l->ls.m3 == m3) return;
    l->ls.m3 = m3;
    lagrange_consts_init(&l->ls.mdl->mech, l->ls.variant, m3, &l->ls.lk);
    hyd_solver_inputs_changed(l->solver); // f changed at the same (t, y)
}

static int lag_set_link(engine* e, int k, const crane_link* ln) {
    eng_lagrange* l = (eng_lagrange*)e;
    // The lagrange crane reads the model's links (ln is one of them, edited
    // by the caller); the constants its fast kernels made from them at start
    // are made again.
    (void)k;
    (void)ln;
    lagrange_consts_init(&l->ls.mdl->mech, l->ls.variant, l->ls.m3, &l->ls.lk);
    hyd_solver_inputs_changed(l->solver); // f changed at the same (t, y)
    return 0;
}

static void lag_set_commands(engine* e, const double u[3]) {
    eng_lagrange* l = (eng_lagrange*)e;
    for (int k = 0; k < 2; ++k) {
        double v = u[k] < -1 ? -1 : u[k] > 1 ? 1 : u[k];
        // A command change is a kink in the input: adaptive methods restart
        // their step-size history there (decision 8).
        if (v != l->ls.u_cmd[k] && hyd_method_is_adaptive(e->o.solver)) hyd_solver_reset(l->solver);
        l->ls.u_cmd[k] = v;
    }
}

static int lag_step(engine* e, double dt) {
    eng_lagrange* l = (eng_lagrange*)e;
    // Commands, a load, a link or a fault may have changed since the last
    // step at the same state: the balance's next step starts from their
    // powers.
    if (l->energy) sim_energy_follow_inputs(l->energy, l->t, l->y);
    int rc = hyd_solver_advance(l->solver, &l->t, l->y, l->t + dt);
    if (rc == HYD_OK) return 0;
    double tb = l->t;
    int i = hyd_solver_bad_state(l->solver, &tb);
    snprintf(e->err, sizeof e->err, "solver %s failed (code %d) at t = %.6g s, state %d", hyd_method_name(e->o.solver),
             rc, tb, i);
    return 1;
}

static double lag_time(const engine* e) { return ((const eng_lagrange*)e)->t; }

static void lag_row(engine* e, double row[SIM_NCOL]) {
    eng_lagrange* l = (eng_lagrange*)e;
    lsim_out o;
    lsim_outputs(&l->ls, l->t, l->y, &o);
    lagrange_row(l->t, &o, row);
}

// ---- Scripted runs (sim_run) ----

typedef struct run_ctx {
    lsim* ls;
    const sim_opts* o;
    const engine_sink* sink;
    double t_end, t_last_row;
    long rows;
    int stop;
    // The run checks (sim_check_value): what failed, its text and time; the
    // dips below zero.
    sim_checks chk;
    double bad_t;
    char bad[200];
    bool all_states; ///< emit sees every state (else only the pressures are interpolated)
    // Peak chamber pressures p1A, p1B, p2A, p2B [Pa abs] (lagrange: system
    // state indices pidx), from every step and every row.
    int pidx[4];
    double peak[4];
    int npress;    ///< pressure states (emit checks only these)
    int press[LSIM_MAX_STATES];
    struct sim_energy* energy; ///< NULL, or the balance accumulated at the steps
    hyd_solver* solver;        ///< the run's solver (NULL with CVODE)
    double *q, *q_row;         ///< CVODE: the balance's columns integrated with the state, and at the last row [J]
} run_ctx;

static int check_fixed_step(const hyd_model* hm, const sim_opts* o, double h, double t_end, sim_result* res) {
    return res->status = sim_check_fixed_step(hm, o, h, t_end, res->message, sizeof res->message);
}

// Hand a finished row to the driver's sink.
static int deliver(run_ctx* c, const double* row) {
    if (c->sink->row && c->sink->row(c->sink->user, row)) return (c->stop = 2);
    return 0;
}

static void track_peaks(run_ctx* c, const double* y) {
    for (int k = 0; k < 4; ++k) c->peak[k] = fmax(c->peak[k], y[c->pidx[k]]);
}

// sim_energy_eval_fn: the circuit at (t, y) of the crane's system, through
// the general path (as lsim_outputs), which fills every output of ls->hd
// the balance reads.
static const hyd_data* energy_eval(void* user, double t, const double* y) {
    lsim* ls = user;
    double f[LSIM_MAX_STATES];
    const bool fast = ls->use_fast;
    ls->use_fast = false;
    lsim_rhs(ls, t, y, f);
    ls->use_fast = fast;
    --ls->nrhs; // an output evaluation is not solver work
    return ls->hd;
}

// The crane's mechanical energy (kinetic + potential) at y [J].
static double mech_energy(const lsim* ls, const double* y) {
    const double q[2] = {y[ls->iq], y[ls->iq + 1]}, qd[2] = {y[ls->iq + 2], y[ls->iq + 3]};
    return lagrange_energy(&ls->mdl->mech, ls->m3, q, qd);
}

// CVODE's rows: its steps are its own, and it integrates the balance's
// columns with the state (hyd_cvode_opts.q); each row adds what they grew
// since the last one.
static void energy_row(run_ctx* c, double t, const double* y) {
    const int nc = sim_energy_ncol(c->energy);
    for (int i = 0; i < nc; ++i) {
        const double q = c->q[i];
        c->q[i] -= c->q_row[i]; // the growth, passed in place
        c->q_row[i] = q;
    }
    sim_energy_follow_integrated(c->energy, t, y, mech_energy(c->ls, y), c->q);
    memcpy(c->q, c->q_row, (size_t)nc * sizeof *c->q);
}

// hyd_solver_opts.on_step: peaks between the rows too, and the energy
// balance, every step by the step's own method (energy_acc.h).
static void on_step(void* user, double t, const double* y) {
    run_ctx* c = user;
    if (c->sink->summary) track_peaks(c, y);
    if (c->energy) sim_energy_follow_step(c->energy, c->solver, t, y, mech_energy(c->ls, y));
}

static const char* state_name(const lsim* ls, int i, char* buf, size_t n);

// A failed run check: remember what and when, and stop the integration.
static int check_failed(run_ctx* c, double t) {
    c->bad_t = t;
    return (c->stop = 3);
}

static int emit(void* user, double t, const double* y) {
    run_ctx* c = user;
    track_peaks(c, y);
    // CVODE's steps are its own: its quadrature is added at the rows (after
    // the start, which the run samples itself).
    if (c->energy && c->o->cvode && c->rows > 0 && t > c->t_last_row + 1e-9 * c->o->dt_out) energy_row(c, t, y);
    // Segments share their end points: write each output time once.
    if (c->rows > 0 && t <= c->t_last_row + 1e-9 * c->o->dt_out) return 0;
    char nb[96];
    // Every state (when the solver interpolated them all), the pressures as
    // pressures; benchmarks see only the pressure states.
    for (int i = 0; i < c->ls->n; ++i) {
        const bool p = i < c->ls->nh && c->ls->is_pressure[i];
        if (!p && !c->all_states) continue;
        // The common case first, without naming the state (this runs at
        // every output time, also in benchmarks).
        if (isfinite(y[i]) && (!p || y[i] >= 0.0)) continue;
        const int rc = sim_check_value(&c->chk, state_name(c->ls, i, nb, sizeof nb), y[i], p, t, c->bad,
                                       sizeof c->bad);
        if (rc) return check_failed(c, t);
    }
    c->t_last_row = t;
    ++c->rows;
    // Benchmarks consume nothing: skip the output evaluation entirely.
    if (!c->sink->rows) return 0;
    lsim_out o;
    lsim_outputs(c->ls, t, y, &o);
    double row[SIM_NCOL];
    lagrange_row(t, &o, row);
    // The derived columns too (a force or a tip position can overflow while
    // the states are finite).
    const int rc = sim_check_row(&c->chk, row, SIM_NCOL_BASE, c->bad, sizeof c->bad);
    if (rc) {
        --c->rows;
        return check_failed(c, t);
    }
    return deliver(c, row);
}

static const char* state_name(const lsim* ls, int i, char* buf, size_t n) {
    static const char* const mech[4] = {"q1", "q2", "q1_dot", "q2_dot"};
    if (i >= ls->iq) return mech[i - ls->iq];
    snprintf(buf, n, "%s", hyd_model_state_name(ls->mdl->hyd, ls->perm[i]));
    return buf;
}

// A scripted run (engine_run): the scenario's commands read continuously
// inside f (lsim.scn), the fused kernel and the split step where they
// apply, integrated between the command breakpoints with rows at the
// output times.
static int lag_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k, sim_result* res) {
    // The closed form is the fast path of exactly the two-link shorthand
    // with a column that stands still (its allow-list); every other chain,
    // a run that slews a model with a slew drive (the slew a degree of
    // freedom) and --variant general run the general formulation
    // (docs/lagrange.md).
    if (!m->chain.two_link || o->variant == LAGRANGE_GENERAL || engine_chain_slews(m, sc))
        return engine_chain_run(m, sc, o, k, res);
    lsim ls;
    double m3 = sim_load_mass(m, sc, o);
    if (engine_world_bursts(m, NULL, NULL, res->message, sizeof res->message)) return res->status = SIM_REFUSED;
    if (lsim_init(&ls, m, o->variant, m3, res->message, sizeof res->message)) return res->status = SIM_REFUSED;
    ls.scn = sc;
    const bool reference = o->kernel == SIM_KERNEL_GENERAL;
    ls.use_fused = ls.have_fused && !reference;
    ls.use_w = ls.w_layout && !reference; // the crane-specialised W too (lagrange_schur_w.c)
    ls.use_split = (ls.w_layout || ls.gen_layout) && o->kernel == SIM_KERNEL_SPLIT;
    ls.use_fast = ls.fk && !reference; // a circuit without the fused shape (lagrange_sim.h)
    res->fused = ls.use_fused;
    res->fast = ls.use_fast;
    double y[LSIM_MAX_STATES];
    if (lsim_check_pose(&ls, sc->q0, res->message, sizeof res->message) ||
        check_fixed_step(m->hyd, o, o->h, o->duration > 0 ? o->duration : sc->duration, res) ||
        (k->probe && (res->status = k->probe(m, o, o->h, res->message, sizeof res->message)))) {
        lsim_free(&ls);
        return res->status = SIM_REFUSED;
    }
    lsim_initial_state(&ls, sc->q0, 0.5e6, y);
    {
        lsim_out lo;
        lsim_outputs(&ls, 0.0, y, &lo);
        const double row0[SIM_NCOL_BASE] = {[COL_P1A] = lo.pA[0], [COL_P1B] = lo.pB[0], [COL_P2A] = lo.pA[1],
                                            [COL_P2B] = lo.pB[1]};
        const sim_start_load ld = {&m->mech, {sc->q0[0], sc->q0[1]}, m3, false};
        if (sim_check_start(m->hyd, row0, SIM_NCOL_BASE, &ld, res->message, sizeof res->message)) {
            lsim_free(&ls);
            return res->status = SIM_REFUSED;
        }
    }

    const bool adaptive = o->cvode || hyd_method_is_adaptive(o->solver);
#ifndef CRANESIM_HAVE_CVODE
    if (o->cvode) {
        snprintf(res->message, sizeof res->message, "this build has no CVODE (install libsundials-dev)");
        lsim_free(&ls);
        return res->status = SIM_REFUSED;
    }
#endif
    hyd_problem prob = lsim_problem(&ls, !adaptive && !o->dense_jac);
    res->split = prob.wstep && (o->solver == HYD_KRUS || o->solver == HYD_ROS2) && !o->cvode;
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = adaptive ? 0.0 : o->h;
    so.rtol = o->rtol;
    so.atol = o->atol;
    so.h_max = 0.5;
    so.jac_every = adaptive ? 1 : (o->jac_every > 0 ? o->jac_every : 1);
    if (o->no_retry) so.retry_halvings = 0;
    // A fixed-step run ends by construction (check_fixed_step bounds it to
    // 1e12 steps): no per-call budget, which at 1e8 stopped a 1 ns step at
    // 0.1 s. The adaptive budget guards against a controller that stalls.
    if (!adaptive) so.max_steps = 0;
    // emit checks the pressure states at every output; when no row is
    // consumed (benchmarks) that is all it reads, so an adaptive solver
    // interpolates only those.
    int press[LSIM_MAX_STATES], npress = 0;
    for (int i = 0; i < ls.nh; ++i)
        if (ls.is_pressure[i]) press[npress++] = i;
    if (!k->rows) {
        so.out_states = press;
        so.n_out_states = npress;
    }
    // The run's context, filled below; its address goes to the solver now.
    run_ctx c;
    double* eq = NULL; // CVODE: the balance's quadrature, and its value at the last row
    if (k->energy && (sim_energy_bind(k->energy, m->hyd) || sim_energy_follow(k->energy, ls.n, energy_eval, &ls) ||
                      (o->cvode && !(eq = calloc(2 * (size_t)sim_energy_ncol(k->energy), sizeof *eq))))) {
        snprintf(res->message, sizeof res->message, "out of memory for the energy balance");
        lsim_free(&ls);
        return res->status = SIM_REFUSED;
    }
    if (k->summary || k->energy) { // someone reads the summary: peaks from every step
        so.on_step = on_step;
        so.on_step_user = &c;
    }
    // CVODE brings its own integrator; the in-house one is not created then.
    hyd_solver* s = o->cvode ? NULL : hyd_solver_create(&prob, o->solver, &so);
    if (!s && !o->cvode) {
        snprintf(res->message, sizeof res->message, "cannot create the %s solver", hyd_method_name(o->solver));
        lsim_free(&ls);
        return res->status = SIM_REFUSED;
    }

    const double t_end = o->duration > 0 ? o->duration : sc->duration;
    // A fixed step longer than the output period outputs once per step
    // (fixed-step methods land on every output time).
    sim_opts oo = *o;
    if (!adaptive && oo.h > oo.dt_out) oo.dt_out = oo.h;
    // An output period longer than the run: rows at the start and the end
    // (the breakpoints are rounded to this grid, so it must not pass t_end).
    if (oo.dt_out > t_end && t_end > 0) oo.dt_out = t_end;
    o = &oo;
    c = (run_ctx){.ls = &ls, .o = o, .sink = k, .t_end = t_end, .energy = k->energy, .solver = s, .q = eq,
                  .q_row = eq ? eq + sim_energy_ncol(k->energy) : NULL,
                  .all_states = so.out_states == NULL,
                  .pidx = {ls.ip[0][0], ls.ip[0][1], ls.ip[1][0], ls.ip[1][1]}};
    memcpy(c.press, press, sizeof press);
    c.npress = npress;
    // Integrate between command breakpoints (rounded to the output grid) and
    // reset the solver at each: a kink in a valve command is a discontinuity
    // in f' that an adaptive controller should not have to discover.
    double bp[2 * SCENARIO_MAX_POINTS * SCENARIO_NCMD + SCENARIO_MAX_EVENTS + 2];
    int nbp = scenario_breakpoints(sc, bp, (int)(sizeof bp / sizeof bp[0]) - 1);
    engine_faults ef;
    engine_faults_init(&ef, m->hyd);
    double t = 0.0;
    hyd_solver_stats cv = {0};
    double w0 = sim_wall_time();
    int rc = HYD_OK;
    if (c.energy) sim_energy_follow_sample(c.energy, 0.0, y, mech_energy(&ls, y));
    emit(&c, 0.0, y);
    for (int i = 0; i <= nbp && rc == HYD_OK && !c.stop && t < t_end; ++i) {
        double tb = i < nbp ? ceil(bp[i] / o->dt_out - 1e-9) * o->dt_out : t_end;
        if (tb > t_end) tb = t_end;
        if (tb <= t + 1e-12) continue;
        // Faults (a burst opening, a pump stop's ramp) hold over a segment:
        // their value at its midpoint, the breakpoints bound them.
        engine_faults_apply(&ef, m->hyd, sc, 0.5 * (t + tb));
        if (s) hyd_solver_reset(s);
        // A fault's new opening changes the powers at the same state: the
        // balance's next step starts from them.
        if (c.energy && t > 0.0) sim_energy_follow_inputs(c.energy, t, y);
#ifdef CRANESIM_HAVE_CVODE
        if (o->cvode) {
            hyd_cvode_opts co = hyd_cvode_default_opts();
            co.rtol = o->rtol;
            co.atol = o->atol;
            co.h_max = 0.5;
            if (c.energy) {
                co.nq = sim_energy_ncol(c.energy);
                co.qfn = sim_energy_quad;
                co.quser = c.energy;
                co.q = c.q;
            }
            hyd_solver_stats cs = {0};
            rc = hyd_cvode_integrate(&prob, &co, t, y, tb, o->dt_out, emit, &c, &cs);
            cv.steps += cs.steps;
            cv.rejected += cs.rejected;
            cv.fevals += cs.fevals;
            cv.jevals += cs.jevals;
            cv.lus += cs.lus;
        } else
#endif
            rc = hyd_solver_integrate(s, t, y, tb, o->dt_out, emit, &c);
        if (rc == HYD_OK && !c.stop) t = tb;
    }
    res->wall = sim_wall_time() - w0;
    res->stats = o->cvode ? cv : *hyd_solver_get_stats(s);
    res->rows = c.rows;
    res->t_end = c.t_last_row;
    char nb[96];
    if (c.stop == 3) {
        // A failed check at t = 0 is the model's start state (no step ran):
        // refused like bad input, nothing written.
        res->status = c.bad_t > 0 ? SIM_FAILED : SIM_REFUSED;
        // The step for fixed-step methods, the last step tried for ours, the
        // tolerance for CVODE (whose steps are its own).
        char how[96];
        if (o->cvode) snprintf(how, sizeof how, "solver cvode, rtol %g", o->rtol);
        else snprintf(how, sizeof how, "solver %s, h = %g s", hyd_method_name(o->solver),
                      adaptive && s ? hyd_solver_last_h(s) : o->h);
        sim_check_message(res->message, sizeof res->message, c.bad, res->status == SIM_REFUSED ? NULL : how,
                          adaptive, c.bad_t, c.chk.bad_value);
    } else if (c.stop) {
        res->status = SIM_REFUSED;
        snprintf(res->message, sizeof res->message, "stopped at t = %.6g s", c.t_last_row);
    } else if (rc != HYD_OK) {
        res->status = SIM_FAILED;
        double tb = c.t_last_row;
        int bi = s ? hyd_solver_bad_state(s, &tb) : -1;
        if (rc == HYD_ERR_NONFINITE && bi >= 0)
            snprintf(res->message, sizeof res->message,
                     "numerical blow-up: state %s became non-finite at t = %.6g s (solver %s, h = %g s)",
                     state_name(&ls, bi, nb, sizeof nb), tb, hyd_method_name(o->solver),
                     adaptive && s ? hyd_solver_last_h(s) : o->h);
        else if (rc == HYD_ERR_DOMAIN && bi >= 0)
            snprintf(res->message, sizeof res->message,
                     "numerical failure: every step the %s controller tried took state %s below absolute zero at "
                     "t = %.6g s, down to the smallest step",
                     hyd_method_name(o->solver), state_name(&ls, bi, nb, sizeof nb), tb);
        else
            snprintf(res->message, sizeof res->message, "solver %s stopped near t = %.6g s: %s",
                     o->cvode ? "cvode" : hyd_method_name(o->solver), c.t_last_row, hyd_error_text(rc));
    }
    memcpy(res->p_peak, c.peak, sizeof res->p_peak);
    res->peak_steps = !o->cvode && k->summary;
    if (!res->status) sim_checks_note(&c.chk, adaptive, res->note, sizeof res->note);
    if (k->energy) sim_energy_finish(k->energy);
    free(eq);
    hyd_solver_destroy(s);
    lsim_free(&ls);
    return res->status;
}

// engine_follow_energy: the solver calls the balance after every step.
static void lag_energy_step(void* user, double t, const double* y) {
    eng_lagrange* l = user;
    sim_energy_follow_step(l->energy, l->solver, t, y, mech_energy(&l->ls, y));
}

static int lag_follow_energy(engine* e, struct sim_energy* en) {
    eng_lagrange* l = (eng_lagrange*)e;
    if (sim_energy_follow(en, l->ls.n, energy_eval, &l->ls) ||
        sim_energy_follow_sample(en, l->t, l->y, mech_energy(&l->ls, l->y)))
        return -1;
    l->energy = en;
    hyd_solver_set_on_step(l->solver, lag_energy_step, l);
    return 0;
}

// ---- The renderer's picture ----

// Planar crane placed in the world: boom plane = x-z, joint 1 at the column
// top above the origin. Rotation about y by the elevation angle.
static void rot_y(double ang, double R[9]) {
    // The boom plane is x (reach) - z (up); a link's local x axis at elevation
    // ang points (cos, 0, sin). Rotation about -y maps x to that direction.
    const double c = cos(ang), s = sin(ang);
    const double M[9] = {c, 0, -s, 0, 1, 0, s, 0, c};
    memcpy(R, M, sizeof M);
}

static void add_body(world_snapshot* s, const char* name, world_role role, world_shape shape, const double pos[3],
                     const double R[9], double sx, double sy, double sz, const float rgba[4], const char* mesh) {
    if (s->nbody >= WORLD_SNAP_MAX_BODIES) return;
    world_snap_body* b = &s->body[s->nbody++];
    memset(b, 0, sizeof *b);
    snprintf(b->name, sizeof b->name, "%s", name);
    b->role = role;
    b->shape = shape;
    memcpy(b->pos, pos, sizeof b->pos);
    memcpy(b->rot, R, sizeof b->rot);
    b->size[0] = sx;
    b->size[1] = sy;
    b->size[2] = sz;
    memcpy(b->rgba, rgba, sizeof b->rgba);
    snprintf(b->mesh, sizeof b->mesh, "%s", mesh ? mesh : "");
    b->mesh_scale = 1.0;
    b->mesh_up = 2;
}

static void lag_snapshot(engine* e, world_snapshot* s) {
    eng_lagrange* l = (eng_lagrange*)e;
    lsim_out o;
    lsim_outputs(&l->ls, l->t, l->y, &o);
    const crane_mech* me = &l->ls.mdl->mech;
    memset(s, 0, offsetof(world_snapshot, body));
    s->ncoll = 0; // after the bodies: not cleared above
    s->nbody = 0;
    s->ncyl = 0;
    s->nrope = 0;
    s->t = l->t;
    const double H = me->column_height;
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const float grey[4] = {0.55f, 0.57f, 0.6f, 1}, orange[4] = {0.95f, 0.55f, 0.1f, 1},
                       load[4] = {0.5f, 0.35f, 0.2f, 1};
    const double colpos[3] = {0, 0, 0.5 * H};
    add_body(s, "column", WORLD_ROLE_COLUMN, WORLD_SHAPE_CYLINDER, colpos, I, 0.18, H, 0, grey, "column.obj");
    // The cylinder is centred at mid-height; the column mesh's origin is its foot.
    s->body[s->nbody - 1].mesh_offset[2] = -0.5 * H;
    // Link frames: elevation a1 = q1 - pi/2, a2 = a1 + q2; joint 1 at (0, 0, H).
    const double a1 = o.q[0] - M_PI / 2, a2 = a1 + o.q[1];
    const double j1[3] = {0, 0, H};
    const double j2[3] = {me->link[0].length * cos(a1), 0, H + me->link[0].length * sin(a1)};
    double R1[9], R2[9];
    rot_y(a1, R1);
    rot_y(a2, R2);
    const crane_link* L = me->link;
    // Box bodies sit at their centres; the boom meshes have their origin at
    // the root joint, half a length behind the centre.
    const double c1[3] = {j1[0] + 0.5 * L[0].length * cos(a1), 0, j1[2] + 0.5 * L[0].length * sin(a1)};
    const double c2[3] = {j2[0] + 0.5 * L[1].length * cos(a2), 0, j2[2] + 0.5 * L[1].length * sin(a2)};
    add_body(s, "boom1", WORLD_ROLE_BOOM1, WORLD_SHAPE_BOX, c1, R1, L[0].length, L[0].width, L[0].height, orange,
             "boom1.obj");
    s->body[s->nbody - 1].mesh_offset[0] = -0.5 * L[0].length;
    add_body(s, "boom2", WORLD_ROLE_BOOM2, WORLD_SHAPE_BOX, c2, R2, L[1].length, L[1].width, L[1].height, orange,
             "boom2.obj");
    s->body[s->nbody - 1].mesh_offset[0] = -0.5 * L[1].length;
    const double tip[3] = {j2[0] + L[1].length * cos(a2), 0, j2[2] + L[1].length * sin(a2)};
    const double lp[3] = {tip[0], 0, tip[2] - 0.35};
    // Box the size of load_block.obj (1.2 x 0.6 x 0.6, origin at its centre),
    // so mesh and fallback primitive cover the same space.
    add_body(s, "load", WORLD_ROLE_LOAD, WORLD_SHAPE_BOX, lp, I, 1.2, 0.6, 0.6, load, "load_block.obj");
    memcpy(s->tip, tip, sizeof s->tip);
    memcpy(s->hook, tip, sizeof s->hook);
    s->load_mass = l->ls.m3;
    // Cylinders: barrel pin in the parent frame, rod pin in the child frame.
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* ac = &me->act[k];
        world_snap_cylinder* c = &s->cyl[s->ncyl++];
        snprintf(c->name, sizeof c->name, "%s", ac->name);
        const double pa = k == 0 ? 0.0 : a1, ca = k == 0 ? a1 : a2;
        const double* org = k == 0 ? j1 : j2;
        c->base[0] = org[0] + ac->base_mount[0] * cos(pa) - ac->base_mount[1] * sin(pa);
        c->base[2] = org[2] + ac->base_mount[0] * sin(pa) + ac->base_mount[1] * cos(pa);
        c->rod_end[0] = org[0] + ac->rod_mount[0] * cos(ca) - ac->rod_mount[1] * sin(ca);
        c->rod_end[2] = org[2] + ac->rod_mount[0] * sin(ca) + ac->rod_mount[1] * cos(ca);
        double AA, AB, st;
        hyd_model_cylinder_geometry(l->ls.mdl->hyd, l->ls.mdl->cyl[k], &AA, &AB, &st);
        c->bore = sqrt(4 * AA / M_PI);
        c->rod = sqrt(4 * (AA - AB) / M_PI);
        c->stroke_max = st;
        c->closed_length = ac->closed_length;
        c->x = o.x[k];
        c->v = o.v[k];
        c->pA = o.pA[k];
        c->pB = o.pB[k];
        c->force = o.F[k];
        c->u = o.u[k];
        c->u_cmd = o.u_cmd[k];
        c->end_stop = (o.end_stop >> k) & 1;
    }
    s->p_supply = o.p_pump;
    // lsim_outputs evaluated the circuit at (t, y): its open flags are current.
    const int cyl_hyd[WORLD_SNAP_MAX_CYLINDERS] = {l->ls.mdl->cyl[0], l->ls.mdl->cyl[1], -1, -1};
    world_snap_reliefs(s, l->ls.mdl->hyd, l->ls.hd->comp_open, cyl_hyd);
}

// A lagrange run is named by its variant of the equations; no world.
static void lag_describe(const sim_opts* o, engine_desc* d) {
    d->world = "";
    snprintf(d->label, sizeof d->label, "lagrange/%s", lagrange_variant_name(o->variant));
    snprintf(d->title, sizeof d->title, "%s", lagrange_variant_name(o->variant));
    d->step_name = "step";
}

static void lag_describe_work(const sim_opts* o, const sim_result* r, char* buf, size_t n) {
    (void)o;
    const int k = snprintf(buf, n, "%ld steps, %ld rejected, %ld f evals, %ld LU", r->stats.steps,
                           r->stats.rejected, r->stats.fevals, r->stats.lus);
    // A fixed step the method could not take whole (docs/solvers.md).
    if (r->stats.retried > 0 && k >= 0 && (size_t)k < n)
        snprintf(buf + k, n - (size_t)k, ", %ld retried as %ld shorter steps", r->stats.retried, r->stats.substeps);
}

// The stepped engine for m and o: the closed form's for exactly the
// two-link shorthand (its allow-list, as lag_run's), the general
// formulation's for every other chain and for --variant general.
static const engine_ops* lag_stepped(const model* m, const sim_opts* o) {
    return !m->chain.two_link || o->variant == LAGRANGE_GENERAL ? &engine_chain_step_ops : &engine_lagrange_ops;
}

const engine_ops engine_lagrange_ops = {
    .stepped = lag_stepped,
    .describe = lag_describe,
    .describe_work = lag_describe_work,
    .name = "lagrange",
    .create = lag_create,
    .run = lag_run,
    .nchannel = SIM_NCOL_BASE, // the base list: no world
    .destroy = lag_destroy,
    .set_commands = lag_set_commands,
    .hook = NULL, // no world, no hook
    .circuit = lag_circuit,
    .circuit_state = lag_circuit_state,
    .set_load = lag_set_load,
    .set_link = lag_set_link,
    .resize_links = true, // the constants are made again from the model's links
    .step = lag_step,
    .time = lag_time,
    .row = lag_row,
    .snapshot = lag_snapshot,
    .follow_energy = lag_follow_energy,
};
