// lagrange_sim.c: the coupled crane ODE (mechanics + circuit), its analytic
// Jacobian and its block pattern. Derivation in docs/lagrange.md.
#include "lagrange_sim.h"
#include "lsim_split.h"
#include "lsim_kin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// The pressure state of the hose feeding chamber state ic, or -1 when no
// hose ends at that chamber (the circuit's own connection, not its names).
static int hose_of_chamber(const hyd_model* hm, int ic) {
    const int hose = hyd_model_feed_hose(hm, hyd_model_state_node(hm, ic));
    return hose < 0 ? -1 : hyd_model_node_state(hm, hyd_model_comp_node(hm, hose, 0));
}

// The state of the node on the valve side of the counterbalance valve that
// holds chamber state ic (its load port at the chamber's node), or -1.
static int cbv_node_of_chamber(const hyd_model* hm, int ic) {
    const int nc = hyd_model_state_node(hm, ic);
    for (int c = 0; c < hyd_model_ncomp(hm); ++c)
        if (hyd_model_comp_type(hm, c) == HYD_COUNTERBALANCE && hyd_model_port_node(hm, c, 1) == nc)
            return hyd_model_node_state(hm, hyd_model_port_node(hm, c, 0));
    return -1;
}

// The mount angle phi at which cylinder a has stroke x [m]: phi = acos of
// the law of cosines (paper Eq. 5); the mounts keep phi in (0, pi), where
// the stroke grows with phi. NaN when x is out of the mounts' reach.
static double phi_of_stroke(const crane_actuator* a, double x) {
    const double L = x + a->closed_length;
    const double c = (a->a * a->a + a->b * a->b - L * L) / (2.0 * a->a * a->b);
    return c >= -1.0 && c <= 1.0 ? acos(c) : NAN;
}

// The block pattern lagrange_split_gen.c takes: 1x1 and 2x2 blocks of
// hydraulic states, then the 4x4 mechanics block at iq (lsim_init's
// order always has it; checked, not assumed).
static bool gen_blocks(lsim* s) {
    lsim_kg* kg = &s->kg;
    kg->n1 = kg->n2 = kg->n3 = kg->nv = 0;
    int o = 0;
    for (int b = 0; b < s->nblock; ++b) {
        const int m = s->block[b];
        if (m == 1) kg->i1[kg->n1++] = o;
        else if (m == 2) kg->i2[kg->n2++] = o;
        else if (m == 3) kg->i3[kg->n3++] = o;
        else if (m >= 5 && m <= 8 && kg->nv == 0 && o != s->iq) kg->nv = m, kg->iv = o;
        else if (!(m == 4 && o == s->iq && b == s->nblock - 1)) return false;
        o += m;
    }
    return o == s->n && s->block[s->nblock - 1] == 4;
}

// Joint ranges in which lsim_events can skip the strokes (ev_phi).
static void events_setup(lsim* s) {
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &s->mdl->mech.act[k];
        const hyd_fused_act* fa = &s->fz.act[k];
        s->ev_phi[k][0] = phi_of_stroke(a, fa->ws);
        s->ev_phi[k][1] = phi_of_stroke(a, fa->s - fa->ws);
    }
}

int lsim_init(lsim* s, const model* m, lagrange_variant v, double m3, char* err, size_t errsz) {
    memset(s, 0, sizeof *s);
    if (model_require_two_link(m, "closed-form analytic mode (--mechanics lagrange)", err, errsz)) return -1;
    s->mdl = m;
    s->variant = v;
    s->m3 = m3;
    const hyd_model* hm = m->hyd;
    s->nh = hyd_model_nstate(hm);
    s->n = s->nh + 4;
    s->iq = s->nh;
    if (s->n > LSIM_MAX_STATES) {
        snprintf(err, errsz, "%s: circuit has %d states, at most %d supported", m->file, s->nh,
                 LSIM_MAX_STATES - 4);
        return -1;
    }
    s->hd = hyd_data_create(hm);
    s->jh_ = calloc((size_t)s->nh * (size_t)s->nh, sizeof(double));
    if (!s->hd || !s->jh_) {
        snprintf(err, errsz, "out of memory");
        lsim_free(s);
        return -1;
    }

    // Order: per actuator [spool] [hose A, pA] [hose B, pB] (or [hose, valve
    // node, pA] behind a counterbalance valve); then the rest.
    bool used[LSIM_MAX_STATES] = {false};
    int n = 0;
    for (int k = 0; k < 2; ++k) {
        int iA, iB;
        hyd_model_cylinder_states(hm, m->cyl[k], &iA, &iB);
        int iu = hyd_model_valve_state(hm, m->valve[k]);
        int hA = hose_of_chamber(hm, iA);
        int hB = hose_of_chamber(hm, iB);
        s->iu[k] = n;
        s->perm[n++] = iu;
        s->block[s->nblock++] = 1;
        used[iu] = true;
        // A side behind a counterbalance valve (the LS crane): [hose, valve
        // node, chamber]. The hose feeds the valve-side node and the open
        // valve links that node to the chamber, the same chain as the
        // standard side's [hose, chamber]; with the three in 1x1 blocks
        // Krus 0.1 ms was 15.9 % of peak off a tight reference on `step`
        // (0.95 % as one block, docs/model.md).
        const int vA = hA < 0 ? cbv_node_of_chamber(hm, iA) : -1, vB = hB < 0 ? cbv_node_of_chamber(hm, iB) : -1;
        const int fA = vA >= 0 ? hose_of_chamber(hm, vA) : -1, fB = vB >= 0 ? hose_of_chamber(hm, vB) : -1;
        int pair[2][3] = {{fA, vA, iA}, {fB, vB, iB}};
        if (vA < 0) pair[0][0] = -1, pair[0][1] = hA;
        if (vB < 0) pair[1][0] = -1, pair[1][1] = hB;
        for (int c = 0; c < 2; ++c) {
            int size = 0;
            s->ihose[k][c] = -1;
            for (int e = 0; e < 3; ++e) {
                int j = pair[c][e];
                if (j < 0 || used[j]) continue;
                if (e == 1 && pair[c][0] < 0) s->ihose[k][c] = n;
                if (e == 2) s->ip[k][c] = n;
                s->perm[n++] = j;
                used[j] = true;
                ++size;
            }
            if (size) s->block[s->nblock++] = size;
        }
    }
    // The supply block of a load-sensing circuit: the pump line, the pump's
    // displacement and each compensated section's P node and compensator
    // spool, the loop through which the margin controller and the
    // compensators hold the section pressures. In 1x1 blocks the LS crane's
    // energy balance on `hold` missed by 3 % (the states themselves were off
    // in the settling to standby) and `step` was 0.95 % of peak off a tight
    // reference; as one block 0.002 % and 0.67 %, as with the dense J.
    {
        int g[LSIM_MAX_VBLOCK], ng = 0;
        const int sup = hyd_model_supply_node(hm);
        const int ss = sup >= 0 ? hyd_model_node_state(hm, sup) : -1;
        if (ss >= 0 && !used[ss]) g[ng++] = ss;
        for (int c = 0; c < hyd_model_ncomp(hm); ++c) {
            const hyd_type t = hyd_model_comp_type(hm, c);
            char name[160];
            int add[2] = {-1, -1};
            if (t == HYD_LS_PUMP && hyd_model_port_node(hm, c, 1) == sup) {
                snprintf(name, sizeof name, "%s.disp", hyd_model_comp_name(hm, c));
                add[0] = hyd_model_find_state(hm, name);
            } else if (t == HYD_COMPENSATOR && hyd_model_port_node(hm, c, 0) == sup) {
                add[0] = hyd_model_node_state(hm, hyd_model_port_node(hm, c, 1));
                snprintf(name, sizeof name, "%s.spool", hyd_model_comp_name(hm, c));
                add[1] = hyd_model_find_state(hm, name);
            }
            for (int e = 0; e < 2; ++e)
                if (add[e] >= 0 && !used[add[e]] && ng < LSIM_MAX_VBLOCK) {
                    bool dup = false;
                    for (int q = 0; q < ng; ++q) dup |= g[q] == add[e];
                    if (!dup) g[ng++] = add[e];
                }
        }
        if (ng >= 5) { // else (the standard crane's lone pump line) the 1x1 blocks below
            for (int q = 0; q < ng; ++q) s->perm[n++] = g[q], used[g[q]] = true;
            s->block[s->nblock++] = ng;
        }
    }
    for (int j = 0; j < s->nh; ++j) {
        if (used[j]) continue;
        s->perm[n++] = j;
        s->block[s->nblock++] = 1;
    }
    s->block[s->nblock++] = 4; // q1, q2, q1', q2'
    for (int k = 0; k < 2; ++k) {
        char path[96];
        double tau = 0;
        snprintf(path, sizeof path, "%s.tau", hyd_model_comp_name(hm, hyd_model_valve_comp(hm, m->valve[k])));
        s->inv_tau[k] = hyd_model_get(hm, path, &tau) == 0 && tau > 0 ? 1.0 / tau : 0.0;
    }
    for (int i = 0; i < s->nh; ++i) s->hpos[s->perm[i]] = i;
    // The fused kernel when the circuit has the standard shape (hyd_fused.h).
    const int fv[2] = {m->valve[0], m->valve[1]}, fc[2] = {m->cyl[0], m->cyl[1]};
    s->have_fused = hyd_fused_build(hm, fv, fc, 2, &s->fz, s->fused_why, sizeof s->fused_why) == 0;
    if (s->have_fused) hyd_fused_map(&s->fz, s->hpos);
    if (s->have_fused) events_setup(s);
    s->fz_rev = hyd_model_revision(hm);
    s->use_fused = s->have_fused;
    if (!s->have_fused) {
        // Not the standard shape: the fast kernel when it takes every
        // component (else the general path, which takes any circuit).
        s->fk = hyd_fast_create(hm, hyd_fast_types(), 0, NULL, 0);
        if (s->fk && hyd_fast_map(s->fk, s->hpos)) hyd_fast_free(s->fk), s->fk = NULL;
    }
    s->use_fast = s->fk != NULL;
    s->w_layout = lsim_w_layout(s);
    s->use_w = s->w_layout;
    s->gen_layout = s->fk && gen_blocks(s);
    if (s->gen_layout && !(s->kg.J = malloc((size_t)s->n * (size_t)s->n * sizeof(double)))) {
        snprintf(err, errsz, "out of memory");
        lsim_free(s);
        return -1;
    }
    s->use_split = s->w_layout || s->gen_layout;
    s->ks.cmd_t = NAN;
    lagrange_consts_init(&m->mech, v, m3, &s->lk);
    for (int i = 0; i < s->nh; ++i) s->is_pressure[i] = hyd_model_state_kind(hm, s->perm[i]) == HYD_STATE_PRESSURE;
    return 0;
}

void lsim_free(lsim* s) {
    hyd_data_free(s->hd);
    hyd_fast_free(s->fk);
    s->fk = NULL;
    free(s->jh_);
    free(s->kg.J);
    s->kg.J = NULL;
    s->hd = NULL;
    s->jh_ = NULL;
}

// hyd_problem.outside: an absolute pressure below zero. The bulk modulus
// falls to zero there, so the exact solution never crosses it; a step that
// does was too long, whatever its error estimate says.
static int lsim_outside(void* user, const double* y) {
    const lsim* s = user;
    for (int i = 0; i < s->nh; ++i)
        if (s->is_pressure[i] && !(y[i] >= 0.0)) return i + 1;
    return 0;
}

// hyd_problem.implausible: an absolute pressure more than 0.1 MPa below
// zero, where the run checks would stop the run (sim.c, P_IMPLAUSIBLE): the
// fixed step is retried shorter first (solver.c).
static int lsim_implausible(void* user, const double* y) {
    const lsim* s = user;
    for (int i = 0; i < s->nh; ++i)
        if (s->is_pressure[i] && !(y[i] > -1e5)) return i + 1;
    return 0;
}

hyd_problem lsim_problem(lsim* s, bool blocks) {
    hyd_problem p;
    memset(&p, 0, sizeof p);
    p.outside = lsim_outside;
    p.implausible = lsim_implausible;
    p.n = s->n;
    const bool fz = s->use_fused && s->have_fused;
    p.f = fz ? lsim_rhs_fused : lsim_rhs;
    p.jac = fz ? lsim_jac_fused : lsim_jac;
    // lsim_jac writes all of J: the circuit's rows (hyd_fast_jacobian clears
    // its rows' circuit columns, the coupling columns are stored), the
    // mechanics' rows (mech_jac, and the hydraulic columns stored below it).
    // lsim_jac_fused clears J itself. Checked by test_lagrange's
    // NaN-prefilled J.
    p.jac_full = 1;
    p.dfdt = lsim_dfdt;
    p.user = s;
    if (s->have_fused) p.events = lsim_events;
    p.settle = lsim_settle;
    if (blocks) {
        p.nblock = s->nblock;
        p.block_size = s->block;
        p.wstage = lsim_wstage;
        if (fz && s->use_split && s->w_layout) p.wstep = lsim_wstep;
        // Any other circuit on the fast kernel: the same step, per block.
        else if (!fz && s->use_fast && s->fk && s->use_split && s->gen_layout) p.wstep = lsim_wstep_gen;
    } else if (s->use_w && s->w_layout) {
        p.wfactor = lsim_wfactor;
        p.wsolve = lsim_wsolve;
    }
    return p;
}

// A scenario's commands are a function of t alone (the scenario is fixed
// for the run), so the last t's values are kept (lsim_ks.cmd): the events
// at the start of a step, its first stage and the previous step's last
// stage share t, and the tables are read once per step.
void lsim_commands_read(lsim* s, double t) {
    lsim_ks* ks = &s->ks;
    for (int i = 0; i < 2; ++i) ks->cmd[i] = scenario_command_hint(s->scn, i, t, &s->scn_seg_[i]);
    ks->cmd_t = t;
}

static void commands(lsim* s, double t, double cmd[2]) { lsim_commands(s, t, cmd); }

static void set_inputs(lsim* s, double t, const kin* k) {
    hyd_data* d = s->hd;
    double cmd[2];
    commands(s, t, cmd);
    for (int i = 0; i < 2; ++i) {
        d->cyl_x[s->mdl->cyl[i]] = k->x[i];
        d->cyl_v[s->mdl->cyl[i]] = k->v[i];
        d->valve_cmd[s->mdl->valve[i]] = cmd[i];
    }
}

// Shared by rhs and Jacobian: the one sincos pair of q, the cylinder
// kinematics and the circuit's inputs at t.
static void prepare(lsim* s, double t, const double* y, double trig[4], kin* k) {
    lagrange_sincos(y[s->iq], &trig[0], &trig[1]);
    lagrange_sincos(y[s->iq + 1], &trig[2], &trig[3]);
    cylinder_kinematics(&s->mdl->mech, trig, y + s->iq + 2, k);
    set_inputs(s, t, k);
}

int lsim_rhs(void* user, double t, const double* y, double* dydt) {
    lsim* s = user;
    const crane_mech* me = &s->mdl->mech;
    const int iq = s->iq;
    const double* qd = y + iq + 2;
    double trig[4];
    kin k;
    prepare(s, t, y, trig, &k);
    // The circuit reads and writes its states in place: state h is y[hpos[h]].
    if (s->use_fast && s->fk)
        hyd_fast_eval(s->fk, s->hd, y, dydt);
    else
        hyd_eval_mapped(s->mdl->hyd, s->hd, t, y, dydt, s->hpos);

    const double tau[2] = {s->hd->cyl_F[s->mdl->cyl[0]] * k.r[0], s->hd->cyl_F[s->mdl->cyl[1]] * k.r[1]};
    double qdd[2];
    if (s->use_fast && s->fk) {
        // The solver's f: the mechanics from the load's constants (s->lk), as
        // the fused f does (about 100 instructions less per call; equal to the
        // terms below to rounding).
        lagrange_accel_fast(&s->lk, trig, qd, tau, qdd);
    } else {
        lagrange_terms lt;
        lagrange_eval_terms_trig(me, s->variant, s->m3, trig, qd, &lt);
        lagrange_accel(&lt, tau, qdd);
    }
    lsim_mech_out(s, qd, qdd, dydt + iq);
    return 0;
}

unsigned long lsim_events(void* user, double t, const double* y) {
    lsim* s = user;
    double cmd[2], x[2];
    // A live edit of the circuit (the drive panel, hyd_model_set): the
    // packed thresholds are stale. (Such runs evaluate f by the general
    // path; the events still come from the packed laws.)
    if (hyd_model_revision(s->mdl->hyd) != s->fz_rev) {
        const int fv[2] = {s->mdl->valve[0], s->mdl->valve[1]}, fc[2] = {s->mdl->cyl[0], s->mdl->cyl[1]};
        s->fz_rev = hyd_model_revision(s->mdl->hyd);
        s->have_fused = hyd_fused_build(s->mdl->hyd, fv, fc, 2, &s->fz, s->fused_why, sizeof s->fused_why) == 0;
        if (s->have_fused) hyd_fused_map(&s->fz, s->hpos), events_setup(s);
    }
    if (!s->have_fused) return s->ev.count; // no packed laws: J by age only
    commands(s, t, cmd);
    // The stroke only near an end stop (a sincos and a square root); away
    // from both, any stroke inside the range has the same levels.
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &s->mdl->mech.act[k];
        const double phi = y[s->iq + k] + a->phi_offset;
        x[k] = phi > s->ev_phi[k][0] && phi < s->ev_phi[k][1] ? 0.5 * s->fz.act[k].s : crane_stroke(a, y[s->iq + k]);
    }
    return hyd_fused_events_update(&s->ev, &s->fz, y, x, cmd);
}

const double* lsim_wstage(void* user) { return ((const lsim*)user)->ystage; }

// The spool lag tau u' = cmd - u with cmd = 0 decays geometrically (Krus at
// 0.1 ms: by 0.9934 per step) and would reach the subnormal numbers about
// 20 s after the valve closed, and stay there (u1 = -7.4e-322 from t = 38 s
// on a 60 s `ramp`), making every step 45 % slower. Snapped to 0 once it is
// no opening at all, it stays exactly 0: u' = 0 there. Only while its
// command is as close to 0: a spool about to open set to 0 has J's spool
// partials of u = 0 exactly, and ROS34PW2 at rtol 1e-2 on the LS crane's
// ramp went 0.80 mm RMS off in stroke instead of 0.23. The other states
// that close on a lag towards 0 (the LS crane's compensator and
// counterbalance spools, 5e-322 after a long hold: 1.2-1.6x per step) are
// flushed by the circuit (hyd_model_flush).
int lsim_settle(void* user, double t, double* y) {
    lsim* s = user;
    int changed = hyd_model_flush(s->mdl->hyd, y, s->hpos) > 0;
    for (int k = 0; k < 2; ++k) {
        double* u = &y[s->iu[k]];
        if (*u == 0.0 || !(fabs(*u) < HYD_SPOOL_SETTLE)) continue;
        double cmd[2];
        commands(s, t, cmd);
        if (fabs(cmd[k]) < HYD_SPOOL_SETTLE) {
            *u = 0.0;
            changed = 1;
        }
    }
    return changed;
}

int lsim_dfdt(void* user, double t, const double* y, double* dfdt) {
    (void)y;
    lsim* s = user;
    for (int i = 0; i < s->n; ++i) dfdt[i] = 0.0;
    if (!s->scn) return 0; // live commands are held constant over a step
    for (int k = 0; k < 2; ++k) dfdt[s->iu[k]] = scenario_command_rate(s->scn, k, t) * s->inv_tau[k];
    return 0;
}

// Rows q1, q2, q1', q2' for the mechanical columns (j >= nh), and H^-1 for the
// hydraulic columns, which the callers fill from their own dF/dy:
//   d qdd / dz = H^-1 (d tau/dz - dC/dz - dG/dz - dH/dz qdd), column by column.
// F, dFdx, dFdv: cylinder forces and their stroke and rate partials.
static void mech_jac(const lsim* s, const double trig[4], const double* qd, const kin* k,
                     const double F[2], const double dFdx[2], const double dFdv[2], double Hi[2][2],
                     double* J) {
    const int nh = s->nh, n = s->n, iq = s->iq;
    double dtau_dq[2], dtau_dqd[2];
    for (int c = 0; c < 2; ++c) {
        const double dv_dq = k->dr[c] * qd[c];
        dtau_dq[c] = F[c] * k->dr[c] + k->r[c] * (dFdx[c] * k->r[c] + dFdv[c] * dv_dq);
        dtau_dqd[c] = k->r[c] * k->r[c] * dFdv[c];
    }
    lagrange_terms lt;
    lagrange_eval_terms_trig(&s->mdl->mech, s->variant, s->m3, trig, qd, &lt);
    const double tau[2] = {F[0] * k->r[0], F[1] * k->r[1]};
    double qdd[2];
    lagrange_accel(&lt, tau, qdd);
    const double det = lt.H[0][0] * lt.H[1][1] - lt.H[0][1] * lt.H[1][0];
    Hi[0][0] = lt.H[1][1] / det, Hi[0][1] = -lt.H[0][1] / det;
    Hi[1][0] = -lt.H[1][0] / det, Hi[1][1] = lt.H[0][0] / det;
    for (int j = nh; j < n; ++j) {
        double g0, g1; // d(tau - C - G - H qdd)/dz_j, with H fixed except via q2
        if (j == iq) {
            g0 = dtau_dq[0] - lt.dG_dq1[0];
            g1 = -lt.dG_dq1[1];
        } else if (j == iq + 1) {
            g0 = -lt.dC_dq2[0] - lt.dG_dq2[0] - (lt.dH_dq2[0][0] * qdd[0] + lt.dH_dq2[0][1] * qdd[1]);
            g1 = dtau_dq[1] - lt.dC_dq2[1] - lt.dG_dq2[1] - (lt.dH_dq2[1][0] * qdd[0] + lt.dH_dq2[1][1] * qdd[1]);
        } else if (j == iq + 2) {
            g0 = dtau_dqd[0] - lt.dC_dqd1[0];
            g1 = -lt.dC_dqd1[1];
        } else {
            g0 = -lt.dC_dqd2[0];
            g1 = dtau_dqd[1] - lt.dC_dqd2[1];
        }
        J[(iq + 2) * n + j] = Hi[0][0] * g0 + Hi[0][1] * g1;
        J[(iq + 3) * n + j] = Hi[1][0] * g0 + Hi[1][1] * g1;
        J[iq * n + j] = (j == iq + 2) ? 1.0 : 0.0;
        J[(iq + 1) * n + j] = (j == iq + 3) ? 1.0 : 0.0;
    }
}

static void freeze_rows(const lsim* s, double* J) {
    for (int c = 0; c < 2; ++c) {
        if (!s->frozen_q[c]) continue;
        for (int j = 0; j < s->n; ++j) J[(s->iq + c) * s->n + j] = J[(s->iq + 2 + c) * s->n + j] = 0.0;
    }
}

int lsim_jac(void* user, double t, const double* y, double* J) {
    lsim* s = user;
    const int nh = s->nh, n = s->n, iq = s->iq;
    const double* qd = y + iq + 2;
    double trig[4];
    kin k;
    prepare(s, t, y, trig, &k);
    hyd_data* d = s->hd;
    if (s->use_fast && s->fk) {
        // Mapped (hyd_fast_map): the hydraulic block straight into J.
        hyd_fast_jacobian(s->fk, d, y, NULL, J, n);
    } else {
        for (int i = 0; i < nh; ++i) s->yh_[s->perm[i]] = y[i]; // the circuit's own order
        hyd_jacobian(s->mdl->hyd, d, t, s->yh_, NULL, s->jh_, nh, 0, 0);
        // Hydraulic block, permuted.
        for (int i = 0; i < nh; ++i)
            for (int j = 0; j < nh; ++j) J[i * n + j] = s->jh_[s->perm[i] * nh + s->perm[j]];
    }

    const int nhs = hyd_model_nstate(s->mdl->hyd);
    double F[2], dFdx[2], dFdv[2];
    for (int c = 0; c < 2; ++c) {
        const int cyl = s->mdl->cyl[c];
        const double* dydx = d->dydx + (size_t)cyl * nhs;
        const double* dydv = d->dydv + (size_t)cyl * nhs;
        // Chain rule through x(q) and v = r(q) q'.
        const double dv_dq = k.dr[c] * qd[c];
        for (int i = 0; i < nh; ++i) {
            const int h = s->perm[i];
            J[i * n + iq + c] = dydx[h] * k.r[c] + dydv[h] * dv_dq;
            J[i * n + iq + 2 + c] = dydv[h] * k.r[c];
        }
        F[c] = d->cyl_F[cyl];
        dFdx[c] = d->dFdx[cyl];
        dFdv[c] = d->dFdv[cyl];
    }
    double Hi[2][2];
    mech_jac(s, trig, qd, &k, F, dFdx, dFdv, Hi, J);
    for (int j = 0; j < nh; ++j) {
        const int h = s->perm[j];
        const double g0 = k.r[0] * d->dFdy[(size_t)s->mdl->cyl[0] * nhs + h];
        const double g1 = k.r[1] * d->dFdy[(size_t)s->mdl->cyl[1] * nhs + h];
        J[(iq + 2) * n + j] = Hi[0][0] * g0 + Hi[0][1] * g1;
        J[(iq + 3) * n + j] = Hi[1][0] * g0 + Hi[1][1] * g1;
        J[iq * n + j] = J[(iq + 1) * n + j] = 0.0;
    }
    freeze_rows(s, J);
    return 0;
}

// ---------------------------------------------------------------------------
// Fused path: the same system through hyd_fused (one pass over the circuit)
// instead of the general component loops. Same laws, agreement to rounding
// (tests/lagrange/test_lagrange_fused.c); about 4x fewer instructions.
// ---------------------------------------------------------------------------

int lsim_rhs_fused(void* user, double t, const double* y, double* dydt) {
    lsim* s = user;
    const int iq = s->iq;
    const double* qd = y + iq + 2;
    double trig[4], cmd[2], F[2];
    kin k;
    lagrange_sincos(y[iq], &trig[0], &trig[1]);
    lagrange_sincos(y[iq + 1], &trig[2], &trig[3]);
    cylinder_kinematics(&s->mdl->mech, trig, qd, &k);
    commands(s, t, cmd);
    hyd_fused_eval2(&s->fz, y, k.x, k.v, cmd, dydt, F);
    const double tau[2] = {F[0] * k.r[0], F[1] * k.r[1]};
    double qdd[2];
    lagrange_accel_fast(&s->lk, trig, qd, tau, qdd);
    lsim_mech_out(s, qd, qdd, dydt + iq);
    return 0;
}

int lsim_jac_fused(void* user, double t, const double* y, double* J) {
    lsim* s = user;
    const int n = s->n, iq = s->iq;
    const double* qd = y + iq + 2;
    double trig[4], cmd[2], F[2], ydot[LSIM_MAX_STATES];
    kin k;
    lagrange_sincos(y[iq], &trig[0], &trig[1]); // as lsim_rhs_fused
    lagrange_sincos(y[iq + 1], &trig[2], &trig[3]);
    cylinder_kinematics(&s->mdl->mech, trig, qd, &k);
    commands(s, t, cmd);
    memset(J, 0, (size_t)n * (size_t)n * sizeof *J);
    hyd_fused_coupling cp[2];
    hyd_fused_jacobian(&s->fz, y, k.x, k.v, cmd, ydot, F, J, n, cp);
    double dFdx[2], dFdv[2];
    for (int c = 0; c < 2; ++c) {
        const double dv_dq = k.dr[c] * qd[c];
        const int iA = s->ip[c][0], iB = s->ip[c][1];
        J[iA * n + iq + c] = cp[c].dA_dx * k.r[c] + cp[c].dA_dv * dv_dq;
        J[iA * n + iq + 2 + c] = cp[c].dA_dv * k.r[c];
        J[iB * n + iq + c] = cp[c].dB_dx * k.r[c] + cp[c].dB_dv * dv_dq;
        J[iB * n + iq + 2 + c] = cp[c].dB_dv * k.r[c];
        dFdx[c] = cp[c].dF_dx;
        dFdv[c] = cp[c].dF_dv;
    }
    double Hi[2][2];
    mech_jac(s, trig, qd, &k, F, dFdx, dFdv, Hi, J);
    // Hydraulic columns of q'': only the chamber pressures move F (dF/dpA =
    // AA, dF/dpB = -AB).
    for (int c = 0; c < 2; ++c) {
        const hyd_fused_act* a = &s->fz.act[c];
        const double gA = k.r[c] * a->AA, gB = -k.r[c] * a->AB;
        const int iA = s->ip[c][0], iB = s->ip[c][1];
        J[(iq + 2) * n + iA] = Hi[0][c] * gA;
        J[(iq + 3) * n + iA] = Hi[1][c] * gA;
        J[(iq + 2) * n + iB] = Hi[0][c] * gB;
        J[(iq + 3) * n + iB] = Hi[1][c] * gB;
    }
    freeze_rows(s, J);
    return 0;
}

int lsim_check_pose(const lsim* s, const double q0[2], char* err, size_t errsz) {
    const model* m = s->mdl;
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &m->mech.act[k];
        if (crane_check_pose(a, m->stroke[k], q0[a->joint], err, errsz)) return -1;
    }
    return 0;
}

void lsim_initial_state(lsim* s, const double q0[2], double p_low, double* y) {
    const hyd_model* hm = s->mdl->hyd;
    double yh[LSIM_MAX_STATES];
    hyd_model_initial_state(hm, yh);
    for (int i = 0; i < s->nh; ++i) y[i] = yh[s->perm[i]];
    const double qd0[2] = {0, 0};
    y[s->iq] = q0[0];
    y[s->iq + 1] = q0[1];
    y[s->iq + 2] = y[s->iq + 3] = 0.0;
    kin k;
    const double trig[4] = {sin(q0[0]), cos(q0[0]), sin(q0[1]), cos(q0[1])};
    cylinder_kinematics(&s->mdl->mech, trig, qd0, &k);
    double G[2];
    lagrange_gravity(&s->mdl->mech, s->variant, s->m3, q0, G);
    for (int c = 0; c < 2; ++c) {
        // Static balance: F r = G, with the unloaded chamber at p_low.
        double AA, AB, st;
        hyd_model_cylinder_geometry(hm, s->mdl->cyl[c], &AA, &AB, &st);
        const double F = G[c] / k.r[c];
        double pA = p_low, pB = p_low;
        if (F >= 0) pA = (F + p_low * AB) / AA;
        else pB = (p_low * AA - F) / AB;
        const int iA = s->ip[c][0], iB = s->ip[c][1];
        y[iA] = pA;
        y[iB] = pB;
        // The hoses start at their chambers' pressures: no flow at t = 0.
        if (s->ihose[c][0] >= 0) y[s->ihose[c][0]] = pA;
        if (s->ihose[c][1] >= 0) y[s->ihose[c][1]] = pB;
    }
}

void lsim_outputs(lsim* s, double t, const double* y, lsim_out* o) {
    double f[LSIM_MAX_STATES];
    // The general path: it also fills the component outputs (comp_q,
    // comp_open) that the rows and the energy balance read.
    const bool fast = s->use_fast;
    s->use_fast = false;
    lsim_rhs(s, t, y, f);
    s->use_fast = fast;
    --s->nrhs; // an output evaluation is not solver work
    const crane_mech* me = &s->mdl->mech;
    const hyd_data* d = s->hd;
    memset(o, 0, sizeof *o);
    for (int c = 0; c < 2; ++c) {
        const int cyl = s->mdl->cyl[c];
        o->x[c] = d->cyl_x[cyl];
        o->v[c] = d->cyl_v[cyl];
        o->pA[c] = y[s->ip[c][0]];
        o->pB[c] = y[s->ip[c][1]];
        o->u[c] = y[s->iu[c]];
        o->u_cmd[c] = d->valve_cmd[s->mdl->valve[c]];
        o->q[c] = y[s->iq + c];
        o->qd[c] = y[s->iq + 2 + c];
        o->F[c] = d->cyl_F[cyl];
        double r;
        crane_pin_length(&me->act[c], o->q[c], &r);
        o->tau[c] = o->F[c] * r;
        if (d->cyl_stop[cyl]) o->end_stop |= 1 << c;
    }
    crane_tip(me, o->q[0], o->q[1], &o->tip[0], &o->tip[1]);
    const hyd_model* hm = s->mdl->hyd;
    for (int c = 0; c < hyd_model_ncomp(hm); ++c)
        if (hyd_model_comp_type(hm, c) == HYD_RELIEF && d->comp_open[c]) ++o->relief_open;
    const int pl = hyd_model_supply_node(hm); // the pump's delivery node, whatever its name
    if (pl >= 0) o->p_pump = d->node_p[pl];
}
