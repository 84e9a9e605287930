// chain_row.c: the general analytic mode's row (chain_row.h), factored out
// of engine_chain.c's scripted run so that the stepped engine writes the
// same columns.
#include "chain_row.h"
#include "lagrange_row.h"

#include <math.h>
#include <string.h>

int chain_row_ncol(const crane_chain* cc) { return SIM_NCOL_BASE + cc->ncol; }

int chain_row_size(const crane_chain* cc) {
    const int n = chain_row_ncol(cc);
    return n > SIM_NCOL ? n : SIM_NCOL;
}

void chain_sim_row(chain_sim* cs, double t, const double* y, chain_sim_out* co, double* row) {
    chain_sim_outputs(cs, t, y, co);
    lsim_out o;
    memset(&o, 0, sizeof o);
    // The chain's actuators only: the slew rack of a slewing run (index
    // cc->nact) has its own columns (crane_chain_row).
    for (int k = 0; k < 2 && k < cs->cc->nact; ++k) {
        o.x[k] = co->x[k], o.v[k] = co->v[k], o.pA[k] = co->pA[k], o.pB[k] = co->pB[k], o.F[k] = co->F[k];
        const int f = cs->cc->act[k].function;
        o.u[k] = co->u[f], o.u_cmd[k] = co->u_cmd[f];
        if (cs->hd->cyl_stop[cs->cc->act[k].cyl]) o.end_stop |= 1 << k;
    }
    const int d0 = cs->cc->slew_free ? 1 : 0;
    // (The rack's lever arm is 0 on every DOF but the slew's: no share here.)
    for (int k = 0; k < 2 && d0 + k < cs->ndof; ++k) {
        o.q[k] = co->q[d0 + k], o.qd[k] = co->qd[d0 + k];
        // tau of the joint: sum over the actuators of F dL/dq.
        for (int a = 0; a < cs->nact; ++a) o.tau[k] += co->F[a] * cs->dL[(size_t)a * cs->ndof + d0 + k];
    }
    double p1[3];
    chain_body_pose(cs->ch, cs->ws, cs->cc->nbody > 1 ? 1 : 0, NULL, p1);
    o.tip[0] = hypot(co->tip[0] - p1[0], co->tip[1] - p1[1]);
    o.tip[1] = co->tip[2] - p1[2];
    o.p_pump = co->p_pump;
    const hyd_model* hm = cs->hm;
    for (int i = 0; i < hyd_model_ncomp(hm); ++i)
        if (hyd_model_comp_type(hm, i) == HYD_RELIEF && cs->hd->comp_open[i]) ++o.relief_open;
    lagrange_row(t, &o, row);
    // The chain's own columns right after the backend's (engine_sink.row).
    const crane_chain_sample s = {co->x, co->v, co->pA, co->pB, co->F, co->u, co->u_cmd, co->q, co->qd};
    crane_chain_row(cs->cc, &s, row + SIM_NCOL_BASE);
}
