// engine_ode.c: the ODE world (ode_world.h: truck, slewing column, booms,
// rope, hook, loads, terrain; the circuit sub-stepped inside each ODE step)
// behind engine.h.
#include "engine_ode.h"
#include "energy_acc.h"

#include "engine_ode_chain.h"
#include "engine_ode_chain_step.h"
#include "engine_ode_sandbox_chain_step.h"
#include "ode_run.h"
#include "rcl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/// Collision pairs read from the world per ODE step (it records at most 16).
#define OW_COLL_REPORT 16

typedef struct eng_ode {
    engine base;
    ode_world* w;
    sim_collisions coll; ///< the sandbox's collisions since create, every ODE step
    struct sim_energy* energy; ///< engine_follow_energy's balance, or NULL
} eng_ode;


static ode_world* W(const engine* e) { return ((const eng_ode*)e)->w; }

// What the crane holds at the start (sim_check_start): in the sandbox the
// world's hook and rope hang at the tip (the tip mass its start state is
// set for), in the validation world the tip load m3 [kg].
static sim_start_load start_load(const model* m, const ode_world* w, const double q0[2], double m3) {
    sim_start_load ld = {&m->mech, {q0[0], q0[1]}, m3, false};
    if (ode_world_kind(w) == WORLD_SANDBOX) {
        int n;
        double len, lm, li, hm, hc, hi;
        ode_world_rope_info(w, &n, &len, &lm, &li, &hm, &hc, &hi);
        ld.m_tip = n * lm + hm;
        ld.world_tip = true;
    }
    return ld;
}

// A model whose crane is a chain of other shape than the two-link one
// (crane_chain.two_link false): its crane_mech does not describe it, and
// the ODE world of ode_world.h builds that two-link crane alone. Scripted
// runs take the chain world or the sandbox hosting the chain
// (engine_ode_chain.c), stepped engines engine_ode_chain_step.c or
// engine_ode_sandbox_chain_step.c (ode_stepped chooses); this create refuses a
// chain in one line should it ever be called with one, rather than run the
// wrong crane.
static int refuse_chain(const model* m, char* err, size_t errsz) {
    return model_require_two_link(m,
                                  "stepped engine of the ode backend (a chain model runs scripted in the ODE chain "
                                  "world: cranesim run)",
                                  err, errsz);
}

static engine* ode_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3,
                          char* err, size_t errsz) {
    if (refuse_chain(m, err, errsz)) return NULL;
    eng_ode* l = calloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    l->base.ops = &engine_ode_ops;
    l->base.o = *o;
    l->w = ode_world_for_run(m, o, "sandbox", q0, slew0, m3, err, errsz);
    if (!l->w) {
        free(l);
        return NULL;
    }
    // The hydraulic sub-step is min(--dt, ODE step), as ode_world_for_run sets it.
    const double dt = ode_world_dt(l->w), h = o->h < dt ? o->h : dt;
    double row0[SIM_NCOL];
    ode_world_row(l->w, row0);
    const sim_start_load ld = start_load(m, l->w, q0, m3);
    l->base.h_probe = h; // the step probe follows in engine.c (engine_create_rcl)
    if (sim_check_fixed_step(ode_world_circuit(l->w), o, h, 0.0, err, errsz) ||
        sim_check_start(ode_world_circuit(l->w), row0, SIM_NCOL, &ld, err, errsz)) {
        ode_world_destroy(l->w);
        free(l);
        return NULL;
    }
    return &l->base;
}

static void ode_destroy(engine* e) {
    ode_world_destroy(W(e));
    free(e);
}

static void ode_set_commands(engine* e, const double u[3]) { ode_world_set_commands(W(e), u); }
static int ode_hook(engine* e, int attach) { return ode_world_hook(W(e), attach); }

static const char* ode_load_name(const engine* e, int i, double* mass) {
    return ode_world_load_name(W(e), i, mass);
}

static int ode_nearest_load(const engine* e, double* dist, double* reach) {
    return ode_world_nearest_load(W(e), dist, reach);
}

static bool ode_attached(const engine* e) {
    ode_world_state st;
    ode_world_get_state(W(e), &st);
    return st.attached >= 0;
}

static hyd_model* ode_circuit(engine* e) { return ode_world_circuit(W(e)); }
static void ode_circuit_state(engine* e, double* y, const hyd_data** in) { ode_world_circuit_state(W(e), y, in); }

static int ode_set_link(engine* e, int k, const crane_link* ln) {
    return ode_world_set_link_mass(W(e), k, ln) ? 1 : 0;
}

static int ode_step(engine* e, double dt) {
    ode_world* w = W(e);
    int rc = 0;
    if (ode_world_kind(w) != WORLD_SANDBOX) {
        rc = ode_world_step(w, dt);
    } else {
        // One ODE step at a time, the collisions read after each (as the
        // scripted run does: a touch shorter than a frame counts). The
        // step count is ode_world_step's for dt, so the motion is the same.
        const double h = ode_world_dt(w), steps = floor(dt / h + 0.5);
        long n = steps > 1e12 ? (long)1e12 : (long)steps;
        if (n < 1) n = 1;
        for (long i = 0; i < n && !rc; ++i) {
            rc = ode_world_step(w, h);
            const char* pairs[OW_COLL_REPORT][2];
            const int np = rc ? -1 : ode_world_collisions(w, pairs, OW_COLL_REPORT);
            if (np >= 0)
                sim_collisions_step(&((eng_ode*)e)->coll, ode_world_time(w), (const char* const(*)[2])pairs, np);
        }
    }
    // The bodies' energy at the end (the world integrates the circuit's
    // terms at its hydraulic sub-steps).
    if (rc == 0 && ((eng_ode*)e)->energy) sim_energy_mech(((eng_ode*)e)->energy, ode_world_energy(w));
    if (rc == 0) return 0;
    snprintf(e->err, sizeof e->err, "%s", ode_world_error(w));
    return 1;
}

static int ode_follow_energy(engine* e, struct sim_energy* en) {
    if (ode_world_follow_energy(W(e), en)) return -1;
    sim_energy_mech(en, ode_world_energy(W(e)));
    ((eng_ode*)e)->energy = en;
    return 0;
}

static const sim_collisions* ode_collisions(const engine* e) {
    const eng_ode* l = (const eng_ode*)e;
    return ode_world_kind(l->w) == WORLD_SANDBOX ? &l->coll : NULL;
}

static void ode_part_energy(const engine* e, double E[2]) { ode_world_part_energy(W(e), &E[0], &E[1]); }

static double ode_time(const engine* e) { return ode_world_time(W(e)); }
static void ode_row(engine* e, double row[SIM_NCOL]) { ode_world_row(W(e), row); }
static void ode_snapshot(engine* e, world_snapshot* s) { ode_world_snapshot(W(e), s); }

// ---- Scripted runs (sim_run) ----

typedef struct run_ctx {
    const engine_sink* sink;
    double t_end, t_last_row;
    long rows;
    int stop;
    sim_checks chk; ///< the run checks (sim_check_row) and the dips below zero
} run_ctx;

// Hand a finished row to the driver's sink.
static int deliver(run_ctx* c, const double* row) {
    if (c->sink->row && c->sink->row(c->sink->user, row)) return (c->stop = 2);
    return 0;
}

static int play_hook(void* user, int attach) { return ode_world_hook(user, attach); }

// A scripted run (engine_run): the scenario played at each ODE step's
// midpoint (scenario_play), rows every dt_out on the step grid.
static int ode_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k, sim_result* res) {
    run_ctx cc = {.sink = k, .t_end = k->t_end}, *c = &cc;
    if (o->cvode) {
        snprintf(res->message, sizeof res->message,
                 "%s ode steps the hydraulics inside each ODE step: use krus, ros2, rk4, ros34pw2 or rodas3",
                 sim_param_name(SIM_PARAM_MECHANICS));
        return res->status = SIM_REFUSED;
    }
    // Every chain that is not the two-link shorthand runs in the chain world.
    if (!m->chain.two_link) return engine_ode_chain_run(m, sc, o, k, res);
    ode_world* w = ode_world_for_run(m, o, "validation", sc->q0, sc->slew0, sim_load_mass(m, sc, o), res->message,
                                        sizeof res->message);
    if (!w) return res->status = SIM_REFUSED;
    res->fused = ode_world_fused(w);
    res->fast = ode_world_fast(w);
    const long ode_msgs = ode_world_messages(NULL);
    const double h_hyd = o->h < ode_world_dt(w) ? o->h : ode_world_dt(w); // as ode_world_for_run
    if ((res->status = sim_check_fixed_step(ode_world_circuit(w), o, h_hyd, c->t_end, res->message,
                                            sizeof res->message)) ||
        (k->probe && (res->status = k->probe(m, o, h_hyd, res->message, sizeof res->message)))) {
        ode_world_destroy(w);
        return res->status;
    }

    const double dt = ode_world_dt(w);
    // Counted in longs: refused before a conversion could overflow (the
    // output period is at most the run, sim_check_times).
    if (c->t_end / dt > 1e12) {
        snprintf(res->message, sizeof res->message,
                 "%s %g s over %g s is %.3g steps, more than 1e12: use a larger %s or a shorter run",
                 sim_param_name(SIM_PARAM_DT_ODE), dt, c->t_end, c->t_end / dt, sim_param_name(SIM_PARAM_DT_ODE));
        ode_world_destroy(w);
        return res->status = SIM_REFUSED;
    }
    const long nstep = (long)floor(c->t_end / dt + 0.5);
    long nout = (long)floor(fmin(o->dt_out, c->t_end) / dt + 0.5);
    if (nout < 1) nout = 1;
    double row[SIM_NCOL];
    int ev = 0;
    engine_faults ef;
    engine_faults_init(&ef, ode_world_circuit(w));
    double w0 = sim_wall_time();
    ode_world_row(w, row);
    for (int k = 0; k < 4; ++k) res->p_peak[k] = row[COL_P1A + k];
    {
        // The start state too: a model value that overflows shows at t = 0.
        char what[200];
        const int rc = sim_check_row(&c->chk, row, SIM_NCOL, what, sizeof what);
        if (rc) {
            sim_check_message(res->message, sizeof res->message, what, NULL, hyd_method_is_adaptive(o->solver),
                              0.0, c->chk.bad_value);
            ode_world_destroy(w);
            return res->status = SIM_REFUSED;
        }
        // In the sandbox the tip carries the world's hook and rope, not a
        // tip load (start_load).
        const sim_start_load ld = start_load(m, w, sc->q0, sim_load_mass(m, sc, o));
        if (sim_check_start(ode_world_circuit(w), row, SIM_NCOL, &ld, res->message, sizeof res->message)) {
            ode_world_destroy(w);
            return res->status = SIM_REFUSED;
        }
    }
    sim_energy* en = k->energy && ode_world_circuit(w) ? k->energy : NULL;
    if (en && sim_energy_bind(en, ode_world_circuit(w))) {
        snprintf(res->message, sizeof res->message, "out of memory for the energy balance");
        ode_world_destroy(w);
        return res->status = SIM_REFUSED;
    }
    // The balance at every hydraulic step (ode_coupling.c), the mechanics'
    // energy after every ODE step.
    if (en && ode_world_follow_energy(w, en)) {
        snprintf(res->message, sizeof res->message, "out of memory for the energy balance");
        ode_world_destroy(w);
        return res->status = SIM_REFUSED;
    }
    if (en) sim_energy_mech(en, ode_world_energy(w));
    // The rated capacity limiter between the scenario and the world, as
    // engine_set_commands has it for the stepped drivers.
    char wbuf[512];
    struct rcl* lim = rcl_create(m, sim_world_path(o->world ? o->world : "validation", wbuf, sizeof wbuf));
    if (lim) row[COL_RCL_UTIL] = rcl_utilisation(lim, row);
    deliver(c, row);
    ++c->rows;
    for (long i = 0; i < nstep && !c->stop; ++i) {
        const double t = (double)i * dt;
        // Commands at the step's midpoint: second-order accurate for ramps,
        // and steps land within half an ODE step of their time.
        const double tm = t + 0.5 * dt;
        double u[3];
        scenario_play(sc, tm, &ev, u, play_hook, w);
        engine_faults_apply(&ef, ode_world_circuit(w), sc, tm);
        if (lim && o->rcl) {
            double now[SIM_NCOL], v[3];
            ode_world_row(w, now);
            rcl_filter(lim, now, u, v);
            memcpy(u, v, sizeof u);
        }
        ode_world_set_commands(w, u);
        if (ode_world_step(w, dt)) {
            res->status = SIM_FAILED;
            snprintf(res->message, sizeof res->message, "numerical blow-up: %s", ode_world_error(w));
            break;
        }
        if (en) sim_energy_mech(en, ode_world_energy(w));
        {
            // Collisions at every ODE step (a touch shorter than a row counts).
            const char* pairs[OW_COLL_REPORT][2];
            const int np = ode_world_collisions(w, pairs, OW_COLL_REPORT);
            if (np >= 0) sim_collisions_step(&res->coll, (double)(i + 1) * dt, (const char* const(*)[2])pairs, np);
        }
        {
            // Peaks at every ODE step, not only at the rows.
            double pA[ODE_NACT], pB[ODE_NACT];
            ode_world_chamber_pressures(w, pA, pB);
            const double p[4] = {pA[0], pB[0], pA[1], pB[1]};
            for (int k = 0; k < 4; ++k) res->p_peak[k] = fmax(res->p_peak[k], p[k]);
        }
        if ((i + 1) % nout && i + 1 != nstep) continue;
        ode_world_row(w, row);
        row[COL_T] = (double)(i + 1) * dt; // exact grid times, no accumulated round-off
        if (lim) row[COL_RCL_UTIL] = rcl_utilisation(lim, row);
        {
            char what[200];
            const int rc = sim_check_row(&c->chk, row, SIM_NCOL, what, sizeof what);
            if (rc) {
                res->status = SIM_FAILED;
                char how[96];
                snprintf(how, sizeof how, "solver %s, h = %g s, ODE step %g s", hyd_method_name(o->solver),
                         o->h < dt ? o->h : dt, dt);
                sim_check_message(res->message, sizeof res->message, what, how, hyd_method_is_adaptive(o->solver),
                                  row[COL_T], c->chk.bad_value);
            }
        }
        if (res->status) break;
        c->t_last_row = row[COL_T];
        ++c->rows;
        deliver(c, row);
    }
    res->wall = sim_wall_time() - w0;
    res->stats = ode_world_hyd_stats(w);
    res->stats.steps = ode_world_hyd_steps(w); // fixed-step sub-steps are counted by the world
    res->rows = c->rows;
    res->t_end = c->t_last_row;
    if (en) sim_energy_finish(en);
    rcl_destroy(lim);
    ode_world_destroy(w);
    res->peak_steps = true;
    const char* last;
    const long msgs = ode_world_messages(&last) - ode_msgs;
    if (!res->status && c->chk.dip)
        sim_checks_note(&c->chk, hyd_method_is_adaptive(o->solver), res->note, sizeof res->note);
    else if (msgs > 0)
        snprintf(res->note, sizeof res->note,
                 "ODE reported %ld solver message%s during the run (last: %.120s): a degenerate contact set, which "
                 "ODE stepped through",
                 msgs, msgs > 1 ? "s" : "", last);
    if (c->stop && !res->status) {
        res->status = SIM_REFUSED;
        snprintf(res->message, sizeof res->message, "stopped at t = %.6g s", c->t_last_row);
    }
    return res->status;
}

// An ode run is named by its world: a world given as a file path reads
// "ode world FILE", a name "ode/NAME". The hydraulics are sub-stepped at
// min(h, ODE step) (ode_world_for_run).
static void ode_describe(const sim_opts* o, engine_desc* d) {
    d->world = o->world ? o->world : "validation";
    snprintf(d->label, sizeof d->label, "ode%s%s", o->world && strchr(o->world, '/') ? " world " : "/", d->world);
    snprintf(d->title, sizeof d->title, "ode/%s", d->world);
    d->dt_outer = o->dt_ode;
    d->h_reduced = !o->cvode && !hyd_method_is_adaptive(o->solver) && o->h > o->dt_ode;
    d->step_name = "ODE step";
}

static void ode_describe_work(const sim_opts* o, const sim_result* r, char* buf, size_t n) {
    const bool adaptive = o->cvode || hyd_method_is_adaptive(o->solver);
    const int k = snprintf(buf, n, "ODE step %g ms, %ld hydraulic %s", o->dt_ode * 1e3, r->stats.steps,
                           adaptive ? "steps" : "sub-steps");
    // A fixed step the method could not take whole (docs/solvers.md).
    if (r->stats.retried > 0 && k >= 0 && (size_t)k < n)
        snprintf(buf + k, n - (size_t)k, ", %ld retried as %ld shorter steps", r->stats.retried, r->stats.substeps);
}

// The stepped engine for m: the two-link world's for exactly the two-link
// shorthand (as ode_run's); for every other chain, as its scripted run
// (engine_ode_chain_run) chooses, the sandbox hosting the chain where o's
// world is a sandbox, else the chain world (the validation world; a world
// file that does not load goes there too, whose create then refuses it
// with the loader's message).
static const engine_ops* ode_stepped(const model* m, const sim_opts* o) {
    if (m->chain.two_link) return &engine_ode_ops;
    world_kind kind;
    char err[512];
    if (!engine_ode_chain_world_kind(o, &kind, err, sizeof err) && kind == WORLD_SANDBOX)
        return &engine_ode_sandbox_chain_step_ops;
    return &engine_ode_chain_step_ops;
}

const engine_ops engine_ode_ops = {
    .stepped = ode_stepped,
    .describe = ode_describe,
    .describe_work = ode_describe_work,
    .name = "ode",
    .create = ode_create,
    .run = ode_run,
    .nchannel = SIM_NCOL, // the base list and the world extras
    .destroy = ode_destroy,
    .set_commands = ode_set_commands,
    .hook = ode_hook,
    .load_name = ode_load_name,
    .attached = ode_attached,
    .nearest_load = ode_nearest_load,
    .circuit = ode_circuit,
    .circuit_state = ode_circuit_state,
    .set_load = NULL, // the world's loads are bodies, picked up with the hook
    .set_link = ode_set_link,
    .part_energy = ode_part_energy,
    .resize_links = false, // a body's geometry is fixed when it is built
    .step = ode_step,
    .time = ode_time,
    .row = ode_row,
    .snapshot = ode_snapshot,
    .collisions = ode_collisions,
    .follow_energy = ode_follow_energy,
};
