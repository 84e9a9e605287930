// chain_problem.c: chain_sim's problem with the event counter and the
// implausible-state test (chain_problem.h).
#include "chain_problem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cp_f(void* user, double t, const double* y, double* dydt) {
    chain_problem* cp = user;
    return cp->base.f(cp->base.user, t, y, dydt);
}

static int cp_jac(void* user, double t, const double* y, double* J) {
    chain_problem* cp = user;
    return cp->base.jac(cp->base.user, t, y, J);
}

static int cp_settle(void* user, double t, double* y) {
    chain_problem* cp = user;
    return cp->base.settle ? cp->base.settle(cp->base.user, t, y) : 0;
}

static int cp_dfdt(void* user, double t, const double* y, double* dfdt) {
    chain_problem* cp = user;
    return cp->base.dfdt(cp->base.user, t, y, dfdt);
}

static int cp_outside(void* user, const double* y) {
    chain_problem* cp = user;
    return cp->base.outside(cp->base.user, y);
}

// More than 0.1 MPa below absolute zero: as lagrange_sim.c's lsim_implausible
// (the run checks' failure threshold, sim.c).
static int cp_implausible(void* user, const double* y) {
    const chain_problem* cp = user;
    const chain_sim* s = cp->cs;
    if (cp->base.implausible) return cp->base.implausible(cp->base.user, y);
    for (int i = 0; i < s->nh; ++i)
        if (s->is_pressure[i] && !(y[i] > -1e5)) return i + 1;
    return 0;
}

unsigned long chain_problem_events(void* user, double t, const double* y) {
    chain_problem* cp = user;
    chain_sim* s = cp->cs;
    const crane_chain* cc = s->cc;
    const int nd = s->ndof;
    // The strokes and rates at y. The solver asks at the (t, y) whose f it
    // has just evaluated (solver.c: f at the step's start, then the
    // Jacobian's schedule), so the circuit's inputs that f's kinematics left
    // in hd are these, bit for bit (chain_sim_inputs_at): taken from there,
    // the kinematics run once per step instead of twice.
    if (chain_sim_inputs_at(s, t, y)) {
        for (int k = 0; k < s->nact; ++k) {
            const int c = s->acyl[k];
            cp->x[c] = s->hd->cyl_x[c];
            cp->v[c] = s->hd->cyl_v[c];
        }
    } else {
        // The kinematics alone; f and the Jacobian take their own at every
        // call, so the workspace left at y is harmless.
        chain_update(s->ch, s->ws, y + s->iq, y + s->iq + nd);
        for (int k = 0; k < cc->nact; ++k) {
            const crane_act* a = &cc->act[k];
            double Ld = 0.0;
            const double L = crane_act_length(a, s->ch, s->ws, &Ld, NULL, NULL);
            cp->x[a->cyl] = L - a->closed_length;
            cp->v[a->cyl] = Ld;
        }
        // The slew rack (chain_sim.rack, the last actuator when the column
        // slews with a drive): stroke r theta + s/2, rate r theta' (chain_sim.c).
        if (s->rack >= 0) {
            cp->x[s->acyl[s->rack]] = s->rack_r * y[s->iq] + 0.5 * s->rack_stroke;
            cp->v[s->acyl[s->rack]] = s->rack_r * y[s->iq + nd];
        }
    }
    // The commands as chain_sim's f takes them (clamped to [-1, 1]).
    for (int f = 0; f < s->nfn; ++f) {
        double u = s->cmd_fn ? s->cmd_fn(s->cmd_user, f, t) : s->cmd[f];
        u = u < -1.0 ? -1.0 : u > 1.0 ? 1.0 : u;
        cp->cmd[s->fvalve[f]] = u;
    }
    const unsigned long own = cp->base.events ? cp->base.events(cp->base.user, t, y) : 0;
    return own + hyd_events_update(cp->ev, s->hm, y, s->hpos, cp->x, cp->v, cp->cmd);
}

int chain_problem_init(chain_problem* cp, chain_sim* cs, bool blocks, hyd_problem* out) {
    memset(cp, 0, sizeof *cp);
    cp->cs = cs;
    cp->base = chain_sim_problem(cs, blocks);
    // Allow-list: the hooks forwarded below. A problem with its own step
    // kernel (wstep, wfactor, ...) would see the wrong user: refused.
    const hyd_problem* b = &cp->base;
    if (b->wfactor || b->wsolve || b->wstep || b->wstage || !b->f) return -1;
    const int nc = hyd_model_ncylinder(cs->hm), nv = hyd_model_nvalve(cs->hm);
    cp->ev = hyd_events_create(cs->hm);
    cp->x = calloc(2 * (size_t)nc + (size_t)nv + 1, sizeof *cp->x);
    if (!cp->ev || !cp->x) {
        chain_problem_free(cp);
        return -1;
    }
    cp->v = cp->x + nc;
    cp->cmd = cp->v + nc;
    *out = cp->base;
    out->user = cp;
    out->f = cp_f;
    out->jac = b->jac ? cp_jac : NULL;
    out->settle = cp_settle;
    out->dfdt = b->dfdt ? cp_dfdt : NULL;
    out->outside = b->outside ? cp_outside : NULL;
    out->implausible = cp_implausible;
    out->events = chain_problem_events;
    return 0;
}

void chain_problem_free(chain_problem* cp) {
    hyd_events_free(cp->ev);
    free(cp->x);
    memset(cp, 0, sizeof *cp);
}

// The shape whose oil-column springs were measured slow (the block W's
// allow-list below): the two-link shorthand, or a chain of that shape in the
// chain form (column, two revolute booms one on the other, two actuators:
// hiab031_chain.json), so that both forms of one crane take one W.
static bool two_link_shape(const crane_chain* cc) {
    if (cc->two_link) return true;
    return cc->nbody == 3 && cc->nact == 2 && cc->body[1].def.joint == CHAIN_REVOLUTE && !cc->body[1].def.fixed &&
           cc->body[2].def.joint == CHAIN_REVOLUTE && !cc->body[2].def.fixed && cc->body[2].def.parent == 1;
}

int chain_problem_setup(chain_problem* cp, chain_sim* cs, const crane_chain* mc, const sim_opts* o,
                        hyd_problem* prob, hyd_solver_opts* so) {
    const bool adaptive = hyd_method_is_adaptive(o->solver);
    // The block-diagonal W for the fixed-step methods only on the two-link
    // shape (an allow-list, two_link_shape): it treats the oil-column
    // springs between the chambers and the bodies explicitly, which holds
    // where they are slow (the two-link crane: 2-12 Hz, docs/lagrange.md).
    // A chain of light telescopic stages has them fast: on
    // chain_8fn_10link.json Krus at 0.1 ms with the block W, even with a new
    // J at every step, ends 5 mm RMS off ROS34PW2 in a stroke, with the
    // whole W 0.1 mm. Every other chain takes the whole W (the solver's
    // sparse LU), with the event counter and the implausible-state test.
    const bool blocks = !adaptive && !o->dense_jac && two_link_shape(mc);
    if (chain_problem_init(cp, cs, blocks, prob)) return -1;
    // The two-link shape keeps the Jacobian schedule it had (by age only):
    // its seals' modes are slow against 1/h (hundreds of kg on each
    // cylinder), and with the events its slewing runs moved by up to 4e-5
    // of the pump line's peak for 13 % more Jacobians, no closer to
    // ROS34PW2 (sandbox_swing: 3.06e-5 RMS of peak either way).
    if (blocks) prob->events = NULL;
    *so = hyd_default_solver_opts();
    so->h = adaptive ? 0.0 : o->h;
    so->rtol = o->rtol;
    so->atol = o->atol;
    so->h_max = 0.5;
    so->jac_every = adaptive ? 1 : (o->jac_every > 0 ? o->jac_every : 1);
    if (o->no_retry) so->retry_halvings = 0;
    if (!adaptive) so->max_steps = 0;
    return 0;
}
