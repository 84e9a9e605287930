// ode_coupling.c: the hydraulic circuit driving the ODE bodies.
//
// Scheme (docs/ode_world.md, "Coupling"): at the start of each ODE step of
// length H the cylinders' strokes x0 and rates v0 are read from the bodies'
// mount points. The circuit is then advanced over H in sub-steps h (default
// 0.1 ms) with the mechanical inputs extrapolated linearly, x(t) = x0 +
// v0 (t - t0), x'(t) = v0. The cylinder force at the end of the sub-steps is
// applied to the bodies during the ODE step (opts.force_average applies their
// mean instead, unstable for light booms). The stiff oil-column and hose
// modes stay inside the implicit hydraulic integrator; the mechanics sees a
// force lagged by at most one ODE step.
#include "ode_world_internal.h"
#include "energy_acc.h"


#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void set_inputs(ode_world* w, double t) {
    double tau = t - w->step_t0;
    for (int k = 0; k < ODE_NACT; ++k) {
        const ow_act* c = &w->act[k];
        if (c->cyl < 0) continue;
        w->hd->cyl_x[c->cyl] = w->x0[k] + w->v0[k] * tau;
        w->hd->cyl_v[c->cyl] = w->v0[k];
        if (c->valve >= 0) w->hd->valve_cmd[c->valve] = w->u_cmd[k];
    }
}

// The general path: the circuit's component loops, which also set the
// flags the state readout uses (end stops, open reliefs).
static int rhs(void* user, double t, const double* y, double* dydt) {
    ode_world* w = user;
    set_inputs(w, t);
    hyd_eval(w->hm, w->hd, t, y, dydt);
    return 0;
}

static int jac(void* user, double t, const double* y, double* J) {
    ode_world* w = user;
    set_inputs(w, t);
    hyd_jacobian(w->hm, w->hd, t, y, NULL, J, w->nh, 0, 0);
    return 0;
}

// The fast kernel for any circuit (circuit_fast.h): the same laws as the
// component loops in type-sorted loops, the inputs as set_inputs writes them.
static int rhs_fast(void* user, double t, const double* y, double* dydt) {
    ode_world* w = user;
    set_inputs(w, t);
    hyd_fast_eval(w->fk, w->hd, y, dydt);
    return 0;
}

static int jac_fast(void* user, double t, const double* y, double* J) {
    ode_world* w = user;
    set_inputs(w, t);
    hyd_fast_jacobian(w->fk, w->hd, y, NULL, J, w->nh);
    return 0;
}

// The straight-line kernel: the same laws in one pass (hyd_fused.h), about a
// third of hyd_eval's instructions on the sandbox circuit. Its inputs per
// lane are what set_inputs writes into hd.
static void fused_inputs(const ode_world* w, double t, double* x, double* v, double* cmd) {
    const double tau = t - w->step_t0;
    for (int j = 0; j < w->nfz; ++j) {
        const int k = w->fz_act[j];
        x[j] = w->x0[k] + w->v0[k] * tau;
        v[j] = w->v0[k];
        cmd[j] = w->u_cmd[k];
    }
}

static int rhs_fused(void* user, double t, const double* y, double* dydt) {
    ode_world* w = user;
    double x[ODE_NACT], v[ODE_NACT], cmd[ODE_NACT], F[ODE_NACT];
    fused_inputs(w, t, x, v, cmd);
    hyd_fused_eval(&w->fz, y, x, v, cmd, dydt, F);
    return 0;
}

static int jac_fused(void* user, double t, const double* y, double* J) {
    ode_world* w = user;
    double x[ODE_NACT], v[ODE_NACT], cmd[ODE_NACT], F[ODE_NACT], ydot[OW_MAX_HYD];
    hyd_fused_coupling cpl[HYD_FUSED_MAXACT]; // partials for a mechanics in the state; unused here
    fused_inputs(w, t, x, v, cmd);
    memset(J, 0, (size_t)w->nh * (size_t)w->nh * sizeof *J);
    hyd_fused_jacobian(&w->fz, y, x, v, cmd, ydot, F, J, w->nh, cpl);
    return 0;
}

// hyd_problem.events on the fused path: switches of the circuit's regime or
// of a command (hyd_fused_events_update), so the sub-steps' reused J is
// renewed at them as in the lagrange runs.
static unsigned long events_fused(void* user, double t, const double* y) {
    ode_world* w = user;
    double x[ODE_NACT], v[ODE_NACT], cmd[ODE_NACT];
    fused_inputs(w, t, x, v, cmd);
    return hyd_fused_events_update(&w->fz_ev, &w->fz, y, x, cmd);
}

// hyd_problem.settle: a spool whose command is 0 decays towards 0 for ever,
// into subnormal numbers that slow every step; within HYD_SPOOL_SETTLE of
// 0 it is set to 0 (as lsim_settle), and so are the other states that
// close on a lag towards 0 (compensator and counterbalance spools:
// hyd_model_flush).
static int settle(void* user, double t, double* y) {
    (void)t;
    ode_world* w = user;
    int changed = hyd_model_flush(w->hm, y, NULL) > 0;
    for (int k = 0; k < ODE_NACT; ++k) {
        const ow_act* c = &w->act[k];
        if (c->valve < 0) continue;
        double* u = &y[hyd_model_valve_state(w->hm, c->valve)];
        if (*u != 0.0 && fabs(*u) < HYD_SPOOL_SETTLE && fabs(w->u_cmd[k]) < HYD_SPOOL_SETTLE) {
            *u = 0.0;
            changed = 1;
        }
    }
    return changed;
}

// hyd_problem.outside: a node pressure below absolute zero (the adaptive
// methods then retry with a shorter step; see lagrange_sim.c).
// Every fixed sub-step asks too (the solver's retry of a failed step), so
// the node pressure states are listed once (w->pres) and tested in one
// pass without a branch per state.
static int outside(void* user, const double* y) {
    const ode_world* w = user;
    int any = 0;
    for (int k = 0; k < w->npres; ++k) any |= !(y[w->pres[k]] >= 0.0);
    if (!any) return 0;
    for (int k = 0; k < w->npres; ++k)
        if (!(y[w->pres[k]] >= 0.0)) return w->pres[k] + 1;
    return 0;
}

// hyd_problem.implausible: a node pressure more than 0.1 MPa below absolute
// zero, where the run checks would stop the run (sim.c, P_IMPLAUSIBLE): the
// fixed sub-step is retried shorter first (solver.c).
static int implausible(void* user, const double* y) {
    const ode_world* w = user;
    int any = 0;
    for (int k = 0; k < w->npres; ++k) any |= !(y[w->pres[k]] > -1e5);
    if (!any) return 0;
    for (int k = 0; k < w->npres; ++k)
        if (!(y[w->pres[k]] > -1e5)) return w->pres[k] + 1;
    return 0;
}

// (Re)pack the straight-line kernel for the present parameters, or take
// the fast kernel when the circuit does not have its shape.
static void fused_setup(ode_world* w) {
    w->use_fused = 0;
    w->use_fast = 0;
    w->hp.f = rhs;
    w->hp.jac = jac;
    w->hp.events = NULL;
    int valve[ODE_NACT], cyl[ODE_NACT];
    w->nfz = 0;
    for (int k = 0; k < ODE_NACT; ++k) {
        if (w->act[k].cyl < 0) continue;
        valve[w->nfz] = w->act[k].valve;
        cyl[w->nfz] = w->act[k].cyl;
        w->fz_act[w->nfz++] = k;
    }
    char why[160];
    if (hyd_fused_build(w->hm, valve, cyl, w->nfz, &w->fz, why, sizeof why)) {
        // Not the standard shape: the fast kernel, unless the reference loops
        // are asked for. A component type it has no loop for is evaluated by
        // that type's loop (fallback), so it takes every circuit.
        if (w->opt.general_circuit) return;
        if (!w->fk) w->fk = hyd_fast_create(w->hm, hyd_fast_types(), 1, why, sizeof why);
        if (!w->fk) return; // out of memory: the reference loops, still correct
        w->use_fast = 1;
        w->hp.f = rhs_fast;
        w->hp.jac = jac_fast;
        return;
    }
    w->fz_rev = hyd_model_revision(w->hm);
    // The event counter reads the packed laws whichever kernel evaluates f,
    // so both kernels follow the same Jacobian schedule.
    w->hp.events = events_fused;
    if (w->opt.general_circuit) return;
    w->use_fused = 1;
    w->hp.f = rhs_fused;
    w->hp.jac = jac_fused;
}

static int bind_actuator(ode_world* w, int k, const char* cyl, const char* valve, const char* file,
                         const char* field, char* err, size_t errsz) {
    ow_act* c = &w->act[k];
    c->cyl = hyd_model_cylinder(w->hm, cyl);
    c->valve = hyd_model_valve(w->hm, valve);
    if (c->cyl < 0) {
        snprintf(err, errsz, "%s: %s.cylinder: no cylinder named \"%s\" in the circuit", file, field, cyl);
        return -1;
    }
    if (c->valve < 0) {
        snprintf(err, errsz, "%s: %s.valve: no valve named \"%s\" in the circuit", file, field, valve);
        return -1;
    }
    hyd_model_cylinder_states(w->hm, c->cyl, &c->iA, &c->iB);
    c->iu = hyd_model_valve_state(w->hm, c->valve);
    hyd_model_cylinder_geometry(w->hm, c->cyl, &c->AA, &c->AB, &c->stroke);
    return 0;
}

// Block-diagonal pattern for W = I - gamma h J. Any partition keeps the
// order of the W-methods (Krus, ROS2); what matters for stability is that
// the stiff couplings (hose <-> chamber, |J_ij| h >> 1) sit inside blocks.
// At a nominal state (5 MPa, mid-stroke) every pair with |J_ij| h > 0.05
// joins one block, and each block is widened to the contiguous index range
// it spans (the solver wants contiguous blocks).
static void block_pattern(ode_world* w) {
    const int n = w->nh;
    double y[OW_MAX_HYD];
    double* J = calloc((size_t)n * (size_t)n, sizeof *J);
    w->nblock = 0;
    if (!J) return; // dense W then: slower, still correct
    hyd_model_initial_state(w->hm, y);
    for (int i = 0; i < n; ++i)
        if (hyd_model_state_kind(w->hm, i) == HYD_STATE_PRESSURE) y[i] = 5e6;
    for (int k = 0; k < ODE_NACT; ++k)
        if (w->act[k].cyl >= 0) w->hd->cyl_x[w->act[k].cyl] = 0.5 * w->act[k].stroke;
    hyd_jacobian(w->hm, w->hd, 0.0, y, NULL, J, n, 0, 0);
    int reach[OW_MAX_HYD]; // furthest index each state is stiffly tied to
    for (int i = 0; i < n; ++i) {
        reach[i] = i;
        for (int j = 0; j < n; ++j)
            if (j != i && (fabs(J[i * n + j]) + fabs(J[j * n + i])) * w->opt.dt_hyd > 0.05) {
                int a = i < j ? i : j, b = i < j ? j : i;
                if (b > reach[a]) reach[a] = b;
            }
    }
    free(J);
    // A counterbalance valve is shut at the nominal state (its setting is
    // far above 5 MPa) but a stiff link from its valve-side node into the
    // chamber once open: its two nodes always share a block, as on the
    // lagrange backend (lagrange_sim.c). Sampled alone, the LS crane's
    // pressures on `step` were 4.5 % of peak off the dense J's.
    for (int c = 0; c < hyd_model_ncomp(w->hm); ++c) {
        if (hyd_model_comp_type(w->hm, c) != HYD_COUNTERBALANCE) continue;
        const int sv = hyd_model_node_state(w->hm, hyd_model_port_node(w->hm, c, 0));
        const int sl = hyd_model_node_state(w->hm, hyd_model_port_node(w->hm, c, 1));
        if (sv < 0 || sl < 0) continue;
        const int a = sv < sl ? sv : sl, b = sv < sl ? sl : sv;
        if (b > reach[a]) reach[a] = b;
    }
    for (int i = 0; i < n;) {
        int end = reach[i];
        for (int k = i; k <= end; ++k)
            if (reach[k] > end) end = reach[k];
        w->block[w->nblock++] = end - i + 1;
        i = end + 1;
    }
}

// The world fragment's "patch" ("component.field": "node") applied to a copy
// of the model's hydraulics section: each named component must exist there
// and the field must already name a node (a string), so a patch can rewire
// a port and nothing else. Returns the copy, or NULL with the error.
static cJSON* patched_hydraulics(const cJSON* hydraulics, const cJSON* patch, const char* wf, const char* part,
                                 const char* mfile, char* err, size_t errsz) {
    cJSON* h = cJSON_Duplicate(hydraulics, 1);
    if (!h) {
        snprintf(err, errsz, "ode world: out of memory");
        return NULL;
    }
    const cJSON* it;
    cJSON_ArrayForEach(it, patch) {
        char comp[128];
        const char* dot = strchr(it->string, '.');
        snprintf(comp, sizeof comp, "%.*s", (int)(dot - it->string), it->string);
        cJSON* c = NULL;
        cJSON* e;
        cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(h, "components")) {
            const cJSON* n = cJSON_GetObjectItemCaseSensitive(e, "name");
            if (cJSON_IsString(n) && !strcmp(n->valuestring, comp)) c = e;
        }
        const cJSON* f = c ? cJSON_GetObjectItemCaseSensitive(c, dot + 1) : NULL;
        if (!c || !cJSON_IsString(f)) {
            snprintf(err, errsz, "%s: %s.patch.%s: %s %s in %s", wf, part, it->string,
                     c ? "no port field" : "no component", c ? dot + 1 : comp, mfile);
            cJSON_Delete(h);
            return NULL;
        }
        cJSON_ReplaceItemInObjectCaseSensitive(c, dot + 1, cJSON_CreateString(it->valuestring));
    }
    return h;
}

// The run's one compiled circuit. A world that adds components (the
// sandbox's slew) compiles the model's circuit with them appended, so an
// error in the world's part names the world file and its own index; else
// the model's compiled circuit is used as it is (opts.circuit), and the
// panel's edits reach the world and the model at once.
// hyd_solver_opts.on_step of the adaptive methods: the energy balance of
// each step they take.
static void on_step(void* user, double t, const double* y) {
    ode_world* w = user;
    if (w->energy) sim_energy_follow_step(w->energy, w->hs, t, y, NAN);
}

// sim_energy_eval_fn: the circuit at (t, y) with the inputs the hydraulic
// steps integrate there (set_inputs; before the first ODE step, the
// actuators as read at creation), into the balance's own data.
static const hyd_data* energy_eval(void* user, double t, const double* y) {
    ode_world* w = user;
    hyd_data* d = sim_energy_data(w->energy);
    const double tau = t - w->step_t0;
    for (int k = 0; k < ODE_NACT; ++k) {
        const ow_act* c = &w->act[k];
        if (c->cyl < 0) continue;
        d->cyl_x[c->cyl] = w->hyd_started ? w->x0[k] + w->v0[k] * tau : c->x;
        d->cyl_v[c->cyl] = w->hyd_started ? w->v0[k] : c->v;
        if (c->valve >= 0) d->valve_cmd[c->valve] = w->u_cmd[k];
    }
    double ydot[OW_MAX_HYD];
    hyd_eval(w->hm, d, t, y, ydot);
    return d;
}

int ode_world_follow_energy(ode_world* w, struct sim_energy* e) {
    if (w->chain) return ode_chain_follow_energy(w->chain, e); // its own circuit
    if (!w->hm || !e) return -1;
    w->energy = e;
    if (sim_energy_follow(e, w->nh, energy_eval, w) || sim_energy_follow_sample(e, w->th, w->y, NAN)) {
        w->energy = NULL;
        return -1;
    }
    return 0;
}

int ow_hyd_create(ode_world* w, const cJSON* hydraulics, const cJSON* extra, const char* part, char* err,
                  size_t errsz) {
    const char* mfile = w->opt.model_file;
    const int sandbox = w->kind == WORLD_SANDBOX;
    if (!sandbox) extra = NULL;
    if (!extra && w->opt.circuit) {
        w->hm = w->opt.circuit;
        w->own_hm = 0;
    } else if (!hydraulics) {
        snprintf(err, errsz, "%s: hydraulics: missing (required by the ode world)", mfile);
        return -1;
    } else {
        const char* wf = w->desc.slew_file[0] ? w->desc.slew_file : w->desc.file[0] ? w->desc.file : "world";
        const cJSON* patch = extra ? cJSON_GetObjectItemCaseSensitive(extra, "patch") : NULL;
        cJSON* ph = NULL; // the patched model section, and the fragment without its patch
        cJSON* fx = NULL;
        if (patch) {
            if (!(ph = patched_hydraulics(hydraulics, patch, wf, part, mfile, err, errsz))) return -1;
            fx = cJSON_Duplicate(extra, 1);
            if (fx) cJSON_DeleteItemFromObjectCaseSensitive(fx, "patch");
            hydraulics = ph, extra = fx;
        }
        w->hm = extra ? hyd_model_from_json_extra(hydraulics, mfile, "hydraulics", extra, wf, part, err, errsz)
                      : hyd_model_from_json(hydraulics, mfile, "hydraulics", err, errsz);
        cJSON_Delete(ph);
        cJSON_Delete(fx);
        w->own_hm = 1;
        if (!w->hm) return -1;
    }
    w->nh = hyd_model_nstate(w->hm);
    if (w->nh > OW_MAX_HYD) {
        snprintf(err, errsz, "%s: hydraulics: %d states, at most %d supported", mfile, w->nh, OW_MAX_HYD);
        return -1;
    }
    for (int k = 0; k < 2; ++k) {
        char f[48];
        snprintf(f, sizeof f, "mechanics.actuators[%d]", k);
        if (bind_actuator(w, k, w->mech.act[k].cylinder, w->mech.act[k].valve, mfile, f, err, errsz)) return -1;
    }
    if (sandbox) {
        // The slew drive is the world's, or the model's where it has one.
        const bool from_model = w->desc.slew_file[0] != 0;
        const char* wf = from_model ? w->desc.slew_file : w->desc.file[0] ? w->desc.file : "world";
        const char* sf = from_model ? "mechanics.slew" : "slew";
        if (bind_actuator(w, ODE_SLEW, w->desc.slew.cylinder, w->desc.slew.valve, wf, sf, err, errsz)) return -1;
        // One cylinder or valve driving two functions would couple them
        // through one set of states: a slew that moves the boom.
        for (int k = 0; k < 2; ++k) {
            const char* what = w->act[ODE_SLEW].cyl == w->act[k].cyl     ? "cylinder"
                               : w->act[ODE_SLEW].valve == w->act[k].valve ? "valve"
                                                                           : NULL;
            if (what) {
                snprintf(err, errsz, "%s: %s.%s: \"%s\" already drives the %s boom (%s mechanics.actuators[%d])", wf,
                         sf, what, what[0] == 'c' ? w->desc.slew.cylinder : w->desc.slew.valve, k ? "end" : "lifting",
                         mfile, k);
                return -1;
            }
        }
        w->act[ODE_SLEW].present = 1;
    }
    // The pump's delivery node, whatever the circuit calls it.
    w->ipump = hyd_model_node_state(w->hm, hyd_model_supply_node(w->hm));

    w->hd = hyd_data_create(w->hm);
    if (!w->hd) {
        snprintf(err, errsz, "ode world: out of memory");
        return -1;
    }
    w->hp.n = w->nh;
    w->hp.user = w;
    w->npres = 0;
    for (int i = 0; i < hyd_model_nnode(w->hm); ++i) {
        const int st = hyd_model_node_state(w->hm, i);
        if (st >= 0 && w->npres < OW_MAX_HYD) w->pres[w->npres++] = st;
    }
    w->hp.outside = outside;
    w->hp.implausible = implausible;
    w->hp.settle = settle;
    fused_setup(w);
    const int adaptive = hyd_method_is_adaptive(w->opt.solver);
    if (!adaptive && !w->opt.dense_jac) {
        block_pattern(w);
        w->hp.nblock = w->nblock;
        w->hp.block_size = w->block;
    }
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = adaptive ? 0.0 : w->opt.dt_hyd;
    so.h_max = w->opt.dt_ode;
    so.on_step = on_step;
    so.on_step_user = w;
    if (w->opt.rtol > 0) so.rtol = w->opt.rtol;
    if (w->opt.atol > 0) so.atol = w->opt.atol;
    so.jac_every = adaptive ? 1 : (w->opt.jac_every > 0 ? w->opt.jac_every : 1);
    if (w->opt.no_retry) so.retry_halvings = 0;
    w->hs = hyd_solver_create(&w->hp, w->opt.solver, &so);
    if (!w->hs) {
        snprintf(err, errsz, "ode world: cannot create the %s solver", hyd_method_name(w->opt.solver));
        return -1;
    }
    w->nsub = (int)floor(w->opt.dt_ode / w->opt.dt_hyd + 0.5);
    return 0;
}

void ow_hyd_destroy(ode_world* w) {
    if (w->hs) hyd_solver_destroy(w->hs);
    if (w->hd) hyd_data_free(w->hd);
    if (w->fk) hyd_fast_free(w->fk);
    w->fk = NULL;
    if (w->hm && w->own_hm) hyd_model_free(w->hm);
    w->hs = NULL;
    w->hd = NULL;
    w->hm = NULL;
}

// The pressure state of the hose feeding chamber state ic, or -1 when no
// hose ends at that chamber (the circuit's own connection, not its names).
static int hose_of(const ode_world* w, int ic) {
    const int hose = hyd_model_feed_hose(w->hm, hyd_model_state_node(w->hm, ic));
    return hose < 0 ? -1 : hyd_model_node_state(w->hm, hyd_model_comp_node(w->hm, hose, 0));
}

// Initial hydraulic state: the model's, then (init_hold) each boom cylinder's
// chambers and hoses at the static pressures that hold the crane still, the
// unloaded side at p_low. Same rule as lagrange's lsim_initial_state so the
// two backends start from the same state.
void ow_hyd_init_state(ode_world* w) {
    hyd_model_initial_state(w->hm, w->y);
    w->th = 0;
    if (!w->opt.init_hold) return;
    ow_read_actuators(w);
    for (int k = 0; k < ODE_NACT; ++k) {
        if (w->act[k].cyl < 0) continue;
        w->hd->cyl_x[w->act[k].cyl] = w->act[k].x;
        w->hd->cyl_v[w->act[k].cyl] = 0;
    }
    // Static gravity torques at the joints from the masses beyond each joint
    // (lagrange's G(q) for the validation world; with rope and hook hanging
    // at the tip in the sandbox).
    const crane_mech* me = &w->mech;
    double m3 = w->kind == WORLD_VALIDATION ? w->m3 : w->desc.hook.mass + w->desc.rope.mass_per_m * w->desc.rope.length;
    double q1 = w->opt.q0[0], q2 = w->opt.q0[1], g = w->g;
    const crane_link *l1 = &me->link[0], *l2 = &me->link[1];
    double G2 = (l2->mass * l2->com + m3 * l2->length) * g * sin(q1 + q2);
    double G1 = (l1->mass * l1->com + (l2->mass + m3) * l1->length) * g * sin(q1) + G2;
    double G[2] = {G1, G2};
    for (int k = 0; k < 2; ++k) {
        ow_act* c = &w->act[k];
        double r;
        crane_pin_length(&me->act[k], w->opt.q0[k], &r);
        double F = G[k] / r, p = w->opt.p_low;
        double pA = p, pB = p;
        if (F >= 0) pA = (F + p * c->AB) / c->AA;
        else pB = (p * c->AA - F) / c->AB;
        w->y[c->iA] = pA;
        w->y[c->iB] = pB;
        int hA = hose_of(w, c->iA), hB = hose_of(w, c->iB);
        if (hA >= 0) w->y[hA] = pA;
        if (hB >= 0) w->y[hB] = pB;
        c->F = F;
    }
    // The slew is balanced with both chambers at p_low (no static torque on a
    // level truck).
    ow_act* s = &w->act[ODE_SLEW];
    if (s->cyl >= 0) {
        double p = w->opt.p_low;
        w->y[s->iA] = p;
        w->y[s->iB] = p * s->AA / s->AB;
        int hA = hose_of(w, s->iA), hB = hose_of(w, s->iB);
        if (hA >= 0) w->y[hA] = w->y[s->iA];
        if (hB >= 0) w->y[hB] = w->y[s->iB];
    }
}

int ow_hyd_step(ode_world* w, double H) {
    for (int k = 0; k < ODE_NACT; ++k) {
        w->x0[k] = w->act[k].x;
        w->v0[k] = w->act[k].v;
    }
    w->step_t0 = w->th;
    w->hyd_started = 1;
    // The strokes, rates and commands this step integrates start here: the
    // balance's next step starts from their powers, and the chambers'
    // volumes re-anchored to the bodies' strokes are its coupling term.
    if (w->energy) sim_energy_follow_inputs(w->energy, w->th, w->y);
    // A live parameter edit (hyd_model_set) since the last step: the packed
    // constants are stale. (The solver reads f and jac through &w->hp.)
    if (w->hp.events && hyd_model_revision(w->hm) != w->fz_rev) fused_setup(w);
    // New strokes and rates: f at (th, y) is not what the solver cached.
    hyd_solver_inputs_changed(w->hs);
    double Fsum[ODE_NACT] = {0, 0, 0};
    double ydot[OW_MAX_HYD];
    const double h = H / w->nsub;
    const int adaptive = hyd_method_is_adaptive(w->opt.solver);
    // Adaptive methods take their own steps over the whole ODE step, landing
    // on its end; fixed-step ones take nsub sub-steps.
    const int nloop = adaptive ? 1 : w->nsub;
    for (int i = 0; i < nloop; ++i) {
        int rc = adaptive ? hyd_solver_advance(w->hs, &w->th, w->y, w->step_t0 + H)
                          : hyd_solver_step(w->hs, &w->th, w->y, h);
        // (hyd_solver_step calls no on_step: the fixed sub-step's balance here.)
        if (rc == HYD_OK && !adaptive && w->energy) sim_energy_follow_step(w->energy, w->hs, w->th, w->y, NAN);
        if (rc != HYD_OK) {
            double tb = w->th;
            int bad = rc == HYD_ERR_NONFINITE || rc == HYD_ERR_DOMAIN ? hyd_solver_bad_state(w->hs, &tb) : -1;
            if (bad >= 0)
                snprintf(w->err, sizeof w->err, "hydraulics: state %s %s at t = %.6f s",
                         hyd_model_state_name(w->hm, bad),
                         rc == HYD_ERR_DOMAIN ? "went below absolute zero at every step size tried" : "became non-finite",
                         tb);
            else
                snprintf(w->err, sizeof w->err, "hydraulics: %s solver stopped at t = %.6f s: %s",
                         hyd_method_name(w->opt.solver), w->th, hyd_error_text(rc));
            return -1;
        }
        // Force at the end of the sub-step (the solver's last f call was at a
        // stage point, not at the new state); only the last one is needed
        // unless averaging.
        if (w->opt.force_average || i == nloop - 1) {
            rhs(w, w->th, w->y, ydot);
            for (int k = 0; k < ODE_NACT; ++k)
                if (w->act[k].cyl >= 0) Fsum[k] += w->hd->cyl_F[w->act[k].cyl];
        }
    }
    w->hyd_steps = adaptive ? hyd_solver_get_stats(w->hs)->steps : w->hyd_steps + w->nsub;
    // Re-anchor hydraulic time on the step count so it never drifts from the
    // mechanical clock.
    w->th = (double)(w->nstep + 1) * H;
    for (int k = 0; k < ODE_NACT; ++k) {
        ow_act* c = &w->act[k];
        if (c->cyl < 0) continue;
        c->F = w->opt.force_average ? Fsum[k] / nloop : w->hd->cyl_F[c->cyl];
        if (!isfinite(c->F)) {
            snprintf(w->err, sizeof w->err, "hydraulics: cylinder force %d became non-finite at t = %.6f s", k, w->th);
            return -1;
        }
    }
    return 0;
}
