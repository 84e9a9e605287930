// chain_sim.c: the crane chain and its circuit as one ODE system, its
// analytic Jacobian and its start state. Derivation in docs/lagrange.md,
// "The general formulation".
#include "chain_sim.h"
#include "circuit_kernel.h" // HYD_SPOOL_SETTLE

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// The pressure state of the hose feeding chamber state ic, or -1 when no
// hose ends at that chamber (as lagrange_sim.c: by the circuit's
// connections, not by names).
static int hose_of_chamber(const hyd_model* hm, int ic) {
    const int hose = hyd_model_feed_hose(hm, hyd_model_state_node(hm, ic));
    return hose < 0 ? -1 : hyd_model_node_state(hm, hyd_model_comp_node(hm, hose, 0));
}

int chain_sim_init(chain_sim* s, const crane_chain* cc, const hyd_model* hm, double m3, double slew, char* err,
                   size_t errsz) {
    memset(s, 0, sizeof *s);
    s->cc = cc;
    s->hm = hm;
    s->m3 = m3;
    s->nact = cc->nact;
    s->nfn = cc->nfn;
    s->rack = s->rack_fn = -1;
    const int ncyl = hyd_model_ncylinder(hm), nvalve = hyd_model_nvalve(hm);
    // The slew drive's rack: an actuator and a function more, after the
    // chain's (chain_sim.h). Its parts by name in hm, the circuit with
    // hydraulics_slew appended.
    int rack_cyl = -1, rack_valve = -1;
    if (cc->slew_free && cc->slew.present) {
        rack_cyl = hyd_model_cylinder(hm, cc->slew.cylinder);
        rack_valve = hyd_model_valve(hm, cc->slew.valve);
        if (rack_cyl < 0 || rack_valve < 0) {
            snprintf(err, errsz, "mechanics.slew.%s: no %s '%s' in the run's circuit (the model's hydraulics with "
                     "hydraulics_slew appended)", rack_cyl < 0 ? "cylinder" : "valve",
                     rack_cyl < 0 ? "cylinder" : "valve", rack_cyl < 0 ? cc->slew.cylinder : cc->slew.valve);
            return -1;
        }
        // The rack's function is "slew" (the scenario's command column):
        // a chain function of that name would be a second slew.
        if (crane_chain_find_function(cc, "slew") >= 0) {
            snprintf(err, errsz, "mechanics.functions: a function is named \"slew\", the name of the slew drive's "
                     "function (mechanics.slew)");
            return -1;
        }
        for (int k = 0; k < cc->nact; ++k)
            if (cc->act[k].cyl == rack_cyl || !strcmp(cc->act[k].valve, cc->slew.valve)) {
                snprintf(err, errsz, "mechanics.slew: its %s is also actuator '%s''s",
                         cc->act[k].cyl == rack_cyl ? "cylinder" : "valve", cc->act[k].name);
                return -1;
            }
        s->rack = s->nact++;
        s->rack_fn = s->nfn++;
        s->rack_r = cc->slew.pinion_radius;
        s->slew_c = cc->slew.damping;
        double AA, AB;
        hyd_model_cylinder_geometry(hm, rack_cyl, &AA, &AB, &s->rack_stroke);
    }
    // Bound and one actuator per cylinder: two actuators writing one
    // cylinder's stroke would silently keep only the last.
    for (int k = 0; k < cc->nact; ++k) {
        const crane_act* a = &cc->act[k];
        if (a->cyl < 0 || a->cyl >= ncyl || a->function < 0 || a->function >= cc->nfn) {
            snprintf(err, errsz, "mechanics.actuators[%d] (%s): not bound to the circuit", k, a->name);
            return -1;
        }
        if (a->body_a < 0 || a->body_a >= cc->nbody || a->body_b < 0 || a->body_b >= cc->nbody) {
            snprintf(err, errsz, "mechanics.actuators[%d] (%s): a mount on a body not in the chain", k, a->name);
            return -1;
        }
        for (int j = 0; j < k; ++j)
            if (cc->act[j].cyl == a->cyl) {
                snprintf(err, errsz,
                         "mechanics.actuators[%d].cylinder: '%s' already drives actuator '%s' (one actuator per "
                         "cylinder)",
                         k, a->cylinder, cc->act[j].name);
                return -1;
            }
    }
    for (int f = 0; f < cc->nfn; ++f)
        if (cc->fn[f].valve_idx < 0 || cc->fn[f].valve_idx >= nvalve) {
            snprintf(err, errsz, "mechanics.functions[%d] (%s): not bound to the circuit", f, cc->fn[f].name);
            return -1;
        }
    s->ch = crane_chain_mechanism(cc, m3, cc->slew_free, slew, err, errsz);
    if (!s->ch) return -1;
    s->ndof = chain_ndof(s->ch);
    // The rack turns DOF 0, the column's (its joint is the chain's first).
    if (s->rack >= 0 && !(s->ndof > 0 && chain_dof_body(s->ch, 0) == 0)) {
        snprintf(err, errsz, "mechanics.slew: the column does not slew in this mechanism");
        chain_sim_free(s);
        return -1;
    }
    s->nh = hyd_model_nstate(hm);
    s->iq = s->nh;
    s->n = s->nh + 2 * s->ndof;
    const size_t nd = (size_t)s->ndof, na = (size_t)s->nact;
    s->ws = chain_ws_create(s->ch);
    s->hd = hyd_data_create(hm);
    s->cmd = calloc((size_t)s->nfn + 1, sizeof *s->cmd);
    s->iu = calloc((size_t)s->nfn + 1, sizeof *s->iu);
    s->ipA = calloc(na + 1, sizeof *s->ipA);
    s->ipB = calloc(na + 1, sizeof *s->ipB);
    s->is_pressure = calloc((size_t)s->nh + 1, sizeof *s->is_pressure);
    s->perm = calloc(2 * (size_t)s->nh + 1, sizeof *s->perm);
    s->block = calloc((size_t)s->nh + 2, sizeof *s->block);
    s->jh = calloc((size_t)s->nh * (size_t)s->nh + (size_t)s->nh + 1, sizeof *s->jh);
    s->L = calloc(2 * na + 2 * na * nd + 1, sizeof(double));
    s->tau = calloc(10 * nd + 3 * nd * nd + (size_t)s->nh + 1, sizeof(double));
    s->acyl = calloc(2 * na + (size_t)s->nfn + 1, sizeof *s->acyl);
    s->kin_y = calloc(2 * nd + 1, sizeof *s->kin_y);
    if (!s->ws || !s->hd || !s->cmd || !s->iu || !s->ipA || !s->ipB || !s->is_pressure || !s->L || !s->tau || !s->perm ||
        !s->block || !s->jh || !s->acyl || !s->kin_y) {
        snprintf(err, errsz, "out of memory");
        chain_sim_free(s);
        return -1;
    }
    // The joint-limit stops (chain_stops.h), as the ODE world's joints.
    if (chain_stops_init(&s->stops, s->ch, s->ws, err, errsz)) {
        chain_sim_free(s);
        return -1;
    }
    s->Ld = s->L + na;
    s->dL = s->Ld + na;
    s->dLd = s->dL + na * nd;
    s->qdd = s->tau + nd;
    s->id0 = s->qdd + nd;
    s->id1 = s->id0 + nd;
    s->qp = s->id1 + nd; // 2 nd: q and q' perturbed
    s->g = s->qp + 2 * nd; // 2 nd: a right-hand side and its solution
    s->H = s->g + 2 * nd;  // 3 nd^2: a Hessian, d tau/dq, d tau/dq'
    s->ydot = s->H + 3 * nd * nd; // n = nh + 2 nd: a whole f for the outputs
    s->hpos = s->perm + s->nh;
    s->yh = s->jh + (size_t)s->nh * (size_t)s->nh;
    s->afn = s->acyl + na;
    s->fvalve = s->afn + na;
    for (int k = 0; k < cc->nact; ++k) s->acyl[k] = cc->act[k].cyl, s->afn[k] = cc->act[k].function;
    for (int f = 0; f < cc->nfn; ++f) s->fvalve[f] = cc->fn[f].valve_idx;
    if (s->rack >= 0) {
        s->acyl[s->rack] = rack_cyl, s->afn[s->rack] = s->rack_fn;
        s->fvalve[s->rack_fn] = rack_valve;
    }
    // The block order (as lagrange_sim.c's for the standard circuit): per
    // actuator its valve's spool, then [hose, chamber] on each side; the
    // other circuit states after, each its own block.
    bool* used = calloc((size_t)s->nh + 1, sizeof *used);
    if (!used) {
        snprintf(err, errsz, "out of memory");
        chain_sim_free(s);
        return -1;
    }
    int o = 0;
    for (int k = 0; k < s->nact; ++k) {
        int iA, iB;
        hyd_model_cylinder_states(hm, s->acyl[k], &iA, &iB);
        const int iu = hyd_model_valve_state(hm, s->fvalve[s->afn[k]]);
        if (iu >= 0 && !used[iu]) used[iu] = true, s->perm[o++] = iu, s->block[s->nblock++] = 1;
        const int side[2] = {iA, iB};
        for (int e = 0; e < 2; ++e) {
            const int ic = side[e], ih = hose_of_chamber(hm, ic);
            int m = 0;
            if (ih >= 0 && !used[ih]) used[ih] = true, s->perm[o++] = ih, ++m;
            if (ic >= 0 && !used[ic]) used[ic] = true, s->perm[o++] = ic, ++m;
            if (m) s->block[s->nblock++] = m;
        }
    }
    for (int h = 0; h < s->nh; ++h)
        if (!used[h]) s->perm[o++] = h, s->block[s->nblock++] = 1;
    free(used);
    if (s->ndof > 0) s->block[s->nblock++] = 2 * s->ndof;
    for (int i = 0; i < s->nh; ++i) s->hpos[s->perm[i]] = i;
    for (int f = 0; f < s->nfn; ++f) {
        const int iu = hyd_model_valve_state(hm, s->fvalve[f]);
        s->iu[f] = iu >= 0 ? s->hpos[iu] : -1;
    }
    for (int k = 0; k < s->nact; ++k) {
        int iA, iB;
        hyd_model_cylinder_states(hm, s->acyl[k], &iA, &iB);
        s->ipA[k] = s->hpos[iA], s->ipB[k] = s->hpos[iB];
    }
    for (int i = 0; i < s->nh; ++i) s->is_pressure[i] = hyd_model_state_kind(hm, s->perm[i]) == HYD_STATE_PRESSURE;
    return 0;
}

void chain_sim_free(chain_sim* s) {
    chain_stops_free(&s->stops);
    chain_ws_free(s->ws);
    chain_free(s->ch);
    hyd_data_free(s->hd);
    free(s->cmd);
    free(s->iu);
    free(s->ipA);
    free(s->ipB);
    free(s->is_pressure);
    free(s->perm);
    free(s->block);
    free(s->jh);
    free(s->L);
    free(s->tau);
    free(s->acyl);
    free(s->kin_y);
    memset(s, 0, sizeof *s);
}

static double command(const chain_sim* s, int k, double t) {
    const double u = s->cmd_fn ? s->cmd_fn(s->cmd_user, k, t) : s->cmd[k];
    return u < -1.0 ? -1.0 : u > 1.0 ? 1.0 : u;
}

// The slew rack (chain_sim.rack): its "pin length" is its stroke x = r
// theta + s/2 [m] (crane_slew_stroke), its rate r theta' [m/s], its lever
// arm dx/dq = r on DOF 0 (the column's) and 0 elsewhere, d(x')/dq = 0 (the
// rate does not depend on the pose).
static void rack_kinematics(chain_sim* s, const double* y, bool jac) {
    const int nd = s->ndof, k = s->rack;
    const double th = y[s->iq], thd = y[s->iq + nd];
    double* r = s->dL + (size_t)k * nd;
    for (int i = 0; i < nd; ++i) r[i] = 0.0;
    r[0] = s->rack_r;
    if (jac)
        for (int i = 0; i < nd; ++i) s->dLd[(size_t)k * nd + i] = 0.0;
    s->L[k] = s->rack_r * th + 0.5 * s->rack_stroke;
    s->Ld[k] = s->rack_r * thd;
    s->hd->cyl_x[s->acyl[k]] = s->L[k];
    s->hd->cyl_v[s->acyl[k]] = s->Ld[k];
}

// Shared by rhs and Jacobian: the kinematics at (q, q'), every actuator's
// pin length, rate, lever arms and (jac: only the Jacobian needs them)
// d(L')/dq, and the circuit's inputs at t.
static void prepare(chain_sim* s, double t, const double* y, bool jac) {
    const crane_chain* cc = s->cc;
    const int nd = s->ndof;
    chain_update(s->ch, s->ws, y + s->iq, y + s->iq + nd);
    hyd_data* d = s->hd;
    for (int k = 0; k < cc->nact; ++k) {
        const crane_act* a = &cc->act[k];
        s->L[k] = crane_act_length(a, s->ch, s->ws, &s->Ld[k], s->dL + (size_t)k * nd,
                                   jac ? s->dLd + (size_t)k * nd : NULL);
        d->cyl_x[a->cyl] = s->L[k] - a->closed_length;
        d->cyl_v[a->cyl] = s->Ld[k];
    }
    if (s->rack >= 0) rack_kinematics(s, y, jac);
    for (int f = 0; f < s->nfn; ++f) d->valve_cmd[s->fvalve[f]] = command(s, f, t);
    s->kin_valid = true;
    s->kin_t = t;
    memcpy(s->kin_y, y + s->iq, 2 * (size_t)nd * sizeof *s->kin_y);
}

bool chain_sim_inputs_at(const chain_sim* s, double t, const double* y) {
    // Bitwise: the same doubles give the same kinematics (a -0.0 against
    // 0.0 merely misses the reuse).
    return s->kin_valid && memcmp(&s->kin_t, &t, sizeof t) == 0 &&
           memcmp(s->kin_y, y + s->iq, 2 * (size_t)s->ndof * sizeof *s->kin_y) == 0;
}

// The ideal forces of the energy tests (chain_sim.ideal_F) into cyl_F.
static void ideal_forces(chain_sim* s) {
    for (int k = 0; k < s->nact; ++k) {
        const int c = s->acyl[k];
        s->hd->cyl_F[c] = s->ideal_F[k] - (s->ideal_K ? s->ideal_K[k] * s->hd->cyl_x[c] : 0.0);
    }
}

// tau = sum_k F_k dL_k/dq [N m or N] from the circuit's last forces (the
// rack's F r on the column among them), the slewing ring's damping -c
// theta' [N m] at the rates qd, and the joint stops at (q, qd)
// (chain_stops.h; nothing for a joint within its limits).
static void joint_forces(chain_sim* s, const double* q, const double* qd) {
    const int nd = s->ndof;
    for (int i = 0; i < nd; ++i) s->tau[i] = 0.0;
    for (int k = 0; k < s->nact; ++k) {
        const double F = s->hd->cyl_F[s->acyl[k]];
        const double* r = s->dL + (size_t)k * nd;
        for (int i = 0; i < nd; ++i) s->tau[i] += F * r[i];
    }
    if (s->rack >= 0) s->tau[0] -= s->slew_c * qd[0];
    if (s->stops.n) chain_stops_add(&s->stops, nd, q, qd, s->tau, NULL, NULL);
}

int chain_sim_rhs(void* user, double t, const double* y, double* dydt) {
    chain_sim* s = user;
    const int nd = s->ndof, iq = s->iq;
    ++s->nrhs;
    prepare(s, t, y, false);
    if (s->ideal_F) {
        memset(dydt, 0, (size_t)s->nh * sizeof *dydt);
        ideal_forces(s);
    } else {
        hyd_eval_mapped(s->hm, s->hd, t, y, dydt, s->hpos);
    }
    const double* qd = y + iq + nd;
    joint_forces(s, y + iq, qd);
    for (int i = 0; i < nd; ++i) dydt[iq + i] = qd[i];
    // M not positive definite (a body of no mass on a DOF): no finite q''.
    if (chain_forward_dynamics(s->ch, s->ws, s->tau, dydt + iq + nd)) return 1;
    return 0;
}

// Forward differences of the inverse dynamics ID(q, q', a) = M(q) a +
// C(q, q') + G(q) at a = q'' in coordinate j of q (which = 0) or q' (which =
// 1), into out [ndof], from base = ID at y. One evaluation per coordinate
// (central differences took two, a fifth of an 8-function chain's whole
// step): with the step 3e-8 (1 + |z_j|) [rad, m, rad/s or m/s] the
// truncation (C is quadratic in q', smooth in q) and the rounding are both
// near 3e-8 of the term, far inside what a W-method's Jacobian needs (its
// accuracy does not enter the order; test_chain_sim checks the Jacobian
// against central differences of f to 1e-6 of its row).
static void id_partial(chain_sim* s, const double* y, int which, int j, const double* base, double* out) {
    const int nd = s->ndof;
    double* q = s->qp;
    double* qd = s->qp + nd;
    memcpy(q, y + s->iq, (size_t)nd * sizeof *q);
    memcpy(qd, y + s->iq + nd, (size_t)nd * sizeof *qd);
    double* z = which ? qd : q;
    const double z0 = z[j], h = 3e-8 * (1.0 + fabs(z0));
    z[j] = z0 + h;
    const double hp = z[j] - z0; // the step as represented
    chain_update(s->ch, s->ws, q, qd);
    chain_inverse_dynamics(s->ch, s->ws, s->qdd, CHAIN_VELOCITY | CHAIN_GRAVITY, s->id0);
    for (int i = 0; i < nd; ++i) out[i] = (s->id0[i] - base[i]) / hp;
}

int chain_sim_jac(void* user, double t, const double* y, double* J) {
    chain_sim* s = user;
    const int nd = s->ndof, iq = s->iq, n = s->n, nh = s->nh;
    const crane_chain* cc = s->cc;
    hyd_data* d = s->hd;
    // Zero only what is not written in full below: the circuit's rows in
    // the mechanics' columns (the coupling adds into them) and the
    // mechanics' rows; the circuit's block is written entry by entry (the
    // permuted copy; zeroed here for the ideal forces, which have none).
    // The whole n x n clear was a fifth of the Jacobian's instructions on
    // loader10 (nh = 47 of n = 57 states).
    for (int i = 0; i < nh; ++i) memset(J + (size_t)i * n + nh, 0, (size_t)(n - nh) * sizeof *J);
    memset(J + (size_t)nh * n, 0, (size_t)(n - nh) * (size_t)n * sizeof *J);
    prepare(s, t, y, true);
    if (s->ideal_F) { // constant forces: no partials, the circuit stands still
        for (int i = 0; i < nh; ++i) memset(J + (size_t)i * n, 0, (size_t)nh * sizeof *J);
        const size_t nc = (size_t)hyd_model_ncylinder(s->hm);
        memset(d->dydx, 0, nc * (size_t)nh * sizeof *d->dydx);
        memset(d->dydv, 0, nc * (size_t)nh * sizeof *d->dydv);
        memset(d->dFdy, 0, nc * (size_t)nh * sizeof *d->dFdy);
        memset(d->dFdx, 0, nc * sizeof *d->dFdx);
        memset(d->dFdv, 0, nc * sizeof *d->dFdv);
        ideal_forces(s);
        for (int k = 0; k < s->nact; ++k) d->dFdx[s->acyl[k]] = s->ideal_K ? -s->ideal_K[k] : 0.0;
    } else {
        // In the circuit's order, then permuted into the system's.
        for (int h = 0; h < nh; ++h) s->yh[h] = y[s->hpos[h]];
        hyd_jacobian(s->hm, d, t, s->yh, NULL, s->jh, nh, 0, 0);
        for (int i = 0; i < nh; ++i) {
            const double* src = s->jh + (size_t)s->perm[i] * nh;
            double* row = J + (size_t)i * n;
            for (int j = 0; j < nh; ++j) row[j] = src[s->perm[j]];
        }
    }
    const double* qd = y + iq + nd;
    joint_forces(s, y + iq, qd);
    if (chain_forward_dynamics(s->ch, s->ws, s->tau, s->qdd)) return 1;
    double* dtq = s->H + (size_t)nd * nd;  // d tau / dq
    double* dtqd = dtq + (size_t)nd * nd;  // d tau / dq'
    memset(dtq, 0, 2 * (size_t)nd * nd * sizeof *dtq);
    for (int k = 0; k < s->nact; ++k) {
        const int c = s->acyl[k];
        const double* r = s->dL + (size_t)k * nd;
        const double* rd = s->dLd + (size_t)k * nd;
        const double* dydx = d->dydx + (size_t)c * nh;
        const double* dydv = d->dydv + (size_t)c * nh;
        // The circuit's rows: x = L(q) - closed, v = L'(q, q') = dL/dq q'.
        for (int h = 0; h < nh; ++h) {
            if (dydx[h] == 0.0 && dydv[h] == 0.0) continue;
            const int i = h; // dydx, dydv are in the circuit's order
            double* row = J + (size_t)s->hpos[h] * n;
            for (int j = 0; j < nd; ++j) {
                row[iq + j] += dydx[i] * r[j] + dydv[i] * rd[j];
                row[iq + nd + j] += dydv[i] * r[j];
            }
        }
        // tau's partials through F(x, v) and the lever arms' Hessian.
        const double F = d->cyl_F[c], Fx = d->dFdx[c], Fv = d->dFdv[c];
        // The rack's lever arm r is constant: no Hessian.
        if (k == s->rack) {
            memset(s->H, 0, (size_t)nd * nd * sizeof *s->H);
        } else {
            const crane_act* a = &cc->act[k];
            crane_act_hessian(a, s->ch, s->ws, s->H);
        }
        for (int i = 0; i < nd; ++i)
            for (int j = 0; j < nd; ++j) {
                dtq[i * nd + j] += F * s->H[i * nd + j] + r[i] * (Fx * r[j] + Fv * rd[j]);
                dtqd[i * nd + j] += r[i] * Fv * r[j];
            }
    }
    if (s->rack >= 0) dtqd[0] -= s->slew_c; // the ring's damping -c theta'
    // The joint stops' partials (their force is in tau already; id0 takes
    // it again as scratch).
    if (s->stops.n) chain_stops_add(&s->stops, nd, y + iq, qd, s->id0, dtq, dtqd);
    for (int i = 0; i < nd; ++i) J[(size_t)(iq + i) * n + iq + nd + i] = 1.0;
    // The mechanics' rows: d q''/dz = M^-1 (d tau/dz - d ID/dz at fixed q'').
    // The kinematics are perturbed by id_partial and restored after; the
    // Cholesky factor of M at y stays in the workspace for chain_solve.
    double* b = s->g;
    double* x = s->g + nd;
    // ID at y itself, from the kinematics chain_forward_dynamics left at y.
    chain_inverse_dynamics(s->ch, s->ws, s->qdd, CHAIN_VELOCITY | CHAIN_GRAVITY, s->id1);
    for (int which = 0; which < 2; ++which)
        for (int j = 0; j < nd; ++j) {
            id_partial(s, y, which, j, s->id1, b);
            const double* dt = which ? dtqd : dtq;
            for (int i = 0; i < nd; ++i) b[i] = dt[i * nd + j] - b[i];
            chain_solve(s->ch, s->ws, b, x);
            for (int i = 0; i < nd; ++i) J[(size_t)(iq + nd + i) * n + iq + which * nd + j] = x[i];
        }
    chain_update(s->ch, s->ws, y + iq, qd);
    // The circuit's columns: only states the forces depend on (the chamber
    // pressures, typically).
    for (int m = 0; m < nh; ++m) {
        bool any = false;
        for (int i = 0; i < nd; ++i) b[i] = 0.0;
        for (int k = 0; k < s->nact; ++k) {
            const double dF = d->dFdy[(size_t)s->acyl[k] * nh + m];
            if (dF == 0.0) continue;
            any = true;
            const double* r = s->dL + (size_t)k * nd;
            for (int i = 0; i < nd; ++i) b[i] += r[i] * dF;
        }
        if (!any) continue;
        chain_solve(s->ch, s->ws, b, x);
        for (int i = 0; i < nd; ++i) J[(size_t)(iq + nd + i) * n + s->hpos[m]] = x[i];
    }
    return 0;
}

// hyd_problem.settle (as lsim_settle): a spool within HYD_SPOOL_SETTLE of 0
// while its command is as close is set to exactly 0, and the circuit's other
// lags towards 0 are flushed (hyd_model_flush): a geometric decay otherwise
// ends in subnormal numbers, on which every step is slower.
static int chain_sim_settle(void* user, double t, double* y) {
    chain_sim* s = user;
    int changed = hyd_model_flush(s->hm, y, s->hpos) > 0;
    for (int f = 0; f < s->nfn; ++f) {
        double* u = s->iu[f] >= 0 ? &y[s->iu[f]] : NULL;
        if (!u || *u == 0.0 || !(fabs(*u) < HYD_SPOOL_SETTLE)) continue;
        if (fabs(command(s, f, t)) < HYD_SPOOL_SETTLE) *u = 0.0, changed = 1;
    }
    return changed;
}

// hyd_problem.events: a joint stop engaging or pressing past its width
// (chain_stops_events), so that a reused Jacobian is taken again when the
// stop stiffens the mechanics.
static unsigned long chain_sim_events(void* user, double t, const double* y) {
    chain_sim* s = user;
    (void)t;
    return chain_stops_events(&s->stops, y + s->iq);
}

hyd_problem chain_sim_problem(chain_sim* s, bool blocks) {
    hyd_problem p;
    memset(&p, 0, sizeof p);
    p.n = s->n;
    p.f = chain_sim_rhs;
    p.jac = chain_sim_jac;
    p.jac_full = 1;
    p.user = s;
    p.settle = chain_sim_settle;
    if (s->stops.n) p.events = chain_sim_events;
    if (blocks) {
        p.nblock = s->nblock;
        p.block_size = s->block;
    }
    return p;
}

int chain_sim_check_pose(chain_sim* s, const double* q0, char* err, size_t errsz) {
    chain_update(s->ch, s->ws, q0, NULL);
    for (int k = 0; k < s->cc->nact; ++k) {
        const crane_act* a = &s->cc->act[k];
        const double x = crane_act_length(a, s->ch, s->ws, NULL, NULL, NULL) - a->closed_length;
        // The same tolerance as crane_check_pose: a stroke a rounding
        // outside its range is at its end stop, not beyond it.
        if (!(x >= -1e-9 && x <= a->stroke + 1e-9)) {
            snprintf(err, errsz,
                     "start pose: actuator '%s' (cylinder '%s') would need a stroke of %.4f m, outside [0, %.4f] m",
                     a->name, a->cylinder, x, a->stroke);
            return -1;
        }
    }
    if (s->rack >= 0) {
        const double x = s->rack_r * q0[0] + 0.5 * s->rack_stroke;
        if (!(x >= -1e-9 && x <= s->rack_stroke + 1e-9)) {
            const double lim = 0.5 * s->rack_stroke / s->rack_r * 180.0 / M_PI;
            snprintf(err, errsz,
                     "start pose: slew %.1f deg needs a slew rack ('%s') stroke of %.4f m, outside [0, %.4f] m "
                     "(slew within +-%.1f deg)",
                     q0[0] * 180.0 / M_PI, s->cc->slew.cylinder, x, s->rack_stroke, lim);
            return -1;
        }
    }
    return 0;
}

// Solves the r x r system A x = b (row-major, overwritten) by Gaussian
// elimination with partial pivoting; -1 when a pivot is below 1e-12 of the
// largest entry (singular to working accuracy).
static int solve_dense(double* A, double* b, int r) {
    double amax = 0.0;
    for (int i = 0; i < r * r; ++i) amax = fmax(amax, fabs(A[i]));
    for (int c = 0; c < r; ++c) {
        int p = c;
        for (int i = c + 1; i < r; ++i)
            if (fabs(A[i * r + c]) > fabs(A[p * r + c])) p = i;
        if (!(fabs(A[p * r + c]) > 1e-12 * amax)) return -1;
        if (p != c) {
            for (int j = 0; j < r; ++j) {
                const double tmp = A[c * r + j];
                A[c * r + j] = A[p * r + j], A[p * r + j] = tmp;
            }
            const double tb = b[c];
            b[c] = b[p], b[p] = tb;
        }
        for (int i = c + 1; i < r; ++i) {
            const double f = A[i * r + c] / A[c * r + c];
            for (int j = c; j < r; ++j) A[i * r + j] -= f * A[c * r + j];
            b[i] -= f * b[c];
        }
    }
    for (int i = r - 1; i >= 0; --i) {
        double v = b[i];
        for (int j = i + 1; j < r; ++j) v -= A[i * r + j] * b[j];
        b[i] = v / A[i * r + i];
    }
    return 0;
}

int chain_sim_initial_state(chain_sim* s, const double* q0, double p_low, double* y, char* err, size_t errsz) {
    const int nd = s->ndof, na = s->nact, iq = s->iq;
    const hyd_model* hm = s->hm;
    hyd_model_initial_state(hm, s->yh);
    for (int h = 0; h < s->nh; ++h) y[s->hpos[h]] = s->yh[h];
    for (int i = 0; i < nd; ++i) y[iq + i] = q0[i], y[iq + nd + i] = 0.0;
    s->kin_valid = false; // rack_kinematics below writes hd at q0, not at an evaluation's (t, y)
    chain_update(s->ch, s->ws, q0, NULL);
    double* G = s->id0;
    chain_inverse_dynamics(s->ch, s->ws, NULL, CHAIN_GRAVITY, G);
    for (int k = 0; k < s->cc->nact; ++k) {
        const crane_act* a = &s->cc->act[k];
        crane_act_length(a, s->ch, s->ws, NULL, s->dL + (size_t)k * nd, NULL);
    }
    if (s->rack >= 0) rack_kinematics(s, y, false);
    // The DOFs some actuator moves (a lever arm above 1e-12 of the largest)
    // take the square system; the others must carry no gravity load.
    double gmax = 0.0, amax = 0.0;
    for (int i = 0; i < nd; ++i) gmax = fmax(gmax, fabs(G[i]));
    for (int i = 0; i < na * nd; ++i) amax = fmax(amax, fabs(s->dL[i]));
    int* rows = malloc(((size_t)nd + 1) * sizeof *rows);
    double* A = malloc(((size_t)nd * (size_t)(na > nd ? na : nd) + 1) * sizeof *A);
    double* F = malloc(((size_t)(na > nd ? na : nd) + 1) * sizeof *F);
    int rc = -1;
    if (!rows || !A || !F) {
        snprintf(err, errsz, "out of memory");
        goto done;
    }
    int r = 0;
    for (int i = 0; i < nd; ++i) {
        bool moved = false;
        for (int k = 0; k < na; ++k) moved |= fabs(s->dL[(size_t)k * nd + i]) > 1e-12 * amax;
        if (moved) {
            rows[r++] = i;
        } else if (fabs(G[i]) > 1e-9 * gmax && gmax > 0.0) {
            snprintf(err, errsz,
                     "start state: the joint of body '%s' carries a gravity load of %.6g and no actuator moves it",
                     chain_body(s->ch, chain_dof_body(s->ch, i))->name, G[i]);
            goto done;
        }
    }
    if (r != na) {
        snprintf(err, errsz,
                 "start state: %d actuators for %d actuated degrees of freedom; the analytic mode's start "
                 "equilibrium takes one actuator per actuated degree of freedom",
                 na, r);
        goto done;
    }
    for (int i = 0; i < r; ++i) {
        for (int k = 0; k < na; ++k) A[i * na + k] = s->dL[(size_t)k * nd + rows[i]];
        F[i] = G[rows[i]];
    }
    if (solve_dense(A, F, r)) {
        snprintf(err, errsz, "start state: the actuators' lever arms are singular at the start pose");
        goto done;
    }
    for (int k = 0; k < na; ++k) {
        // Static balance with the unloaded chamber at p_low (as lsim_initial_state).
        double AA, AB, st;
        hyd_model_cylinder_geometry(hm, s->acyl[k], &AA, &AB, &st);
        double pA = p_low, pB = p_low;
        if (k == s->rack) pB = p_low * AA / AB; // no force, as the ODE sandbox starts it (ode_coupling.c)
        else if (F[k] >= 0) pA = (F[k] + p_low * AB) / AA;
        else pB = (p_low * AA - F[k]) / AB;
        y[s->ipA[k]] = pA;
        y[s->ipB[k]] = pB;
        // The hoses start at their chambers' pressures: no flow at t = 0.
        const int hA = hose_of_chamber(hm, s->perm[s->ipA[k]]), hB = hose_of_chamber(hm, s->perm[s->ipB[k]]);
        if (hA >= 0) y[s->hpos[hA]] = pA;
        if (hB >= 0) y[s->hpos[hB]] = pB;
    }
    rc = 0;
done:
    free(rows);
    free(A);
    free(F);
    return rc;
}

void chain_sim_outputs(chain_sim* s, double t, const double* y, chain_sim_out* o) {
    const int nd = s->ndof;
    chain_sim_rhs(s, t, y, s->ydot);
    --s->nrhs; // an output evaluation is not solver work
    const hyd_data* d = s->hd;
    for (int k = 0; k < s->nact; ++k) {
        const int c = s->acyl[k];
        if (o->x) o->x[k] = d->cyl_x[c];
        if (o->v) o->v[k] = d->cyl_v[c];
        if (o->pA) o->pA[k] = y[s->ipA[k]];
        if (o->pB) o->pB[k] = y[s->ipB[k]];
        if (o->F) o->F[k] = d->cyl_F[c];
    }
    for (int f = 0; f < s->nfn; ++f) {
        if (o->u) o->u[f] = s->iu[f] >= 0 ? y[s->iu[f]] : 0.0;
        if (o->u_cmd) o->u_cmd[f] = d->valve_cmd[s->fvalve[f]];
    }
    for (int i = 0; i < nd; ++i) {
        if (o->q) o->q[i] = y[s->iq + i];
        if (o->qd) o->qd[i] = y[s->iq + nd + i];
    }
    if (s->cc->tip_body >= 0 && s->cc->tip_body < s->cc->nbody)
        chain_world_point(s->ch, s->ws, s->cc->tip_body, s->cc->tip, o->tip, NULL);
    else
        o->tip[0] = o->tip[1] = o->tip[2] = 0.0;
    const int pl = hyd_model_supply_node(s->hm);
    o->p_pump = pl >= 0 ? d->node_p[pl] : 0.0;
}

double chain_sim_energy(chain_sim* s, const double* y) {
    chain_update(s->ch, s->ws, y + s->iq, y + s->iq + s->ndof);
    return chain_kinetic_energy(s->ch, s->ws) + chain_potential_energy(s->ch, s->ws);
}

const char* chain_sim_function_name(const chain_sim* s, int k) {
    if (k >= 0 && k < s->cc->nfn) return s->cc->fn[k].name;
    return k >= 0 && k == s->rack_fn ? "slew" : NULL;
}

const char* chain_sim_actuator_name(const chain_sim* s, int k) {
    if (k >= 0 && k < s->cc->nact) return s->cc->act[k].name;
    return k >= 0 && k == s->rack ? "slew" : NULL;
}

double chain_sim_slew_damping_power(const chain_sim* s, const double* y) {
    if (s->rack < 0) return 0.0;
    const double w = y[s->iq + s->ndof];
    return s->slew_c * w * w;
}
