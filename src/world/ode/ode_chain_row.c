// ode_chain_row.c: the ODE chain world's row and the sandbox's row of a
// hosted chain (ode_chain_row.h), factored out of engine_ode_chain.c's
// scripted runs so that the stepped engines write the same columns.
#include "ode_chain_row.h"
#include "ode_run.h"
#include "ode_world.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int ode_chain_rows_init(ode_chain_rows* r, const crane_chain* cc, const hyd_model* hm, int ndof) {
    memset(r, 0, sizeof *r);
    r->cc = cc;
    r->hm = hm;
    r->na = cc->nact, r->nf = cc->nfn, r->nd = ndof;
    const size_t na = (size_t)r->na, nf = (size_t)r->nf, nd = (size_t)r->nd;
    double* buf = calloc(5 * na + 2 * nf + 2 * nd + 1, sizeof *buf);
    r->iu = calloc(nf + 1, sizeof *r->iu);
    if (!buf || !r->iu) {
        free(buf);
        free(r->iu);
        r->iu = NULL;
        return -1;
    }
    r->x = buf, r->v = r->x + na, r->pA = r->v + na, r->pB = r->pA + na, r->F = r->pB + na;
    r->u = r->F + na, r->ucmd = r->u + nf, r->q = r->ucmd + nf, r->qd = r->q + nd;
    for (int f = 0; f < r->nf; ++f) r->iu[f] = hyd_model_valve_state(hm, cc->fn[f].valve_idx);
    r->ipump = hyd_model_supply_node(hm);
    return 0;
}

void ode_chain_rows_free(ode_chain_rows* r) {
    free(r->x);
    free(r->iu);
    memset(r, 0, sizeof *r);
}

int ode_chain_row_ncol(const crane_chain* cc) { return SIM_NCOL + cc->ncol; }

void ode_chain_rows_outputs(ode_chain_rows* r, const ode_chain* w) {
    const double* y;
    const hyd_data* hd;
    ode_chain_circuit_state(w, &y, &hd);
    for (int k = 0; k < r->na; ++k) {
        r->x[k] = ode_chain_act_length(w, k, &r->v[k]) - r->cc->act[k].closed_length;
        r->F[k] = ode_chain_act_force(w, k, &r->pA[k], &r->pB[k]);
    }
    for (int f = 0; f < r->nf; ++f) {
        r->u[f] = r->iu[f] >= 0 ? y[r->iu[f]] : 0.0;
        r->ucmd[f] = hd->valve_cmd[r->cc->fn[f].valve_idx];
    }
    ode_chain_q(w, r->q, r->qd);
}

void ode_chain_make_row(ode_chain_rows* r, const ode_chain* w, double t, double* row) {
    ode_chain_rows_outputs(r, w);
    memset(row, 0, SIM_NCOL * sizeof *row);
    const crane_chain_sample smp = {r->x, r->v, r->pA, r->pB, r->F, r->u, r->ucmd, r->q, r->qd};
    crane_chain_row(r->cc, &smp, row + SIM_NCOL);
    row[COL_T] = t;
    const int colx[2] = {COL_X1, COL_X2}, colv[2] = {COL_V1, COL_V2}, colF[2] = {COL_F1, COL_F2};
    const int colA[2] = {COL_P1A, COL_P2A}, colB[2] = {COL_P1B, COL_P2B};
    const int colu[2] = {COL_U1, COL_U2}, colc[2] = {COL_U1_CMD, COL_U2_CMD}, colq[2] = {COL_Q1, COL_Q2};
    int end_stop = 0;
    for (int k = 0; k < 2 && k < r->na; ++k) {
        row[colx[k]] = r->x[k], row[colv[k]] = r->v[k], row[colF[k]] = r->F[k];
        row[colA[k]] = r->pA[k], row[colB[k]] = r->pB[k];
        const int f = r->cc->act[k].function;
        row[colu[k]] = r->u[f], row[colc[k]] = r->ucmd[f];
        if (ode_chain_act_at_stop(w, k)) end_stop |= 1 << k;
    }
    const int d0 = r->cc->slew_free ? 1 : 0;
    for (int k = 0; k < 2 && d0 + k < r->nd; ++k) row[colq[k]] = r->q[d0 + k];
    if (d0) row[COL_SLEW] = r->q[0];
    double tip[3], p1[3];
    ode_chain_tip(w, tip, NULL);
    ode_chain_body_pose(w, r->cc->nbody > 1 ? 1 : 0, NULL, p1);
    row[COL_TIP_X] = hypot(tip[0] - p1[0], tip[1] - p1[1]);
    row[COL_TIP_Z] = tip[2] - p1[2];
    const double* y;
    const hyd_data* hd;
    ode_chain_circuit_state(w, &y, &hd);
    row[COL_P_PUMP] = r->ipump >= 0 ? hd->node_p[r->ipump] : 0.0;
    int open = 0;
    for (int i = 0; i < hyd_model_ncomp(r->hm); ++i)
        if (hyd_model_comp_type(r->hm, i) == HYD_RELIEF && hd->comp_open[i]) ++open;
    row[COL_RELIEF_OPEN] = open;
    row[COL_END_STOP] = end_stop;
}

void ode_chain_sandbox_row(ode_chain_rows* r, struct ode_world* w, const crane_chain* cc, double t, double* row) {
    ode_world_row(w, row);
    ode_chain_rows_outputs(r, ode_world_chain(w));
    // The model's DOF columns: the slew's only where the model's column slews.
    const int d0 = cc->slew_free ? 0 : 1;
    const crane_chain_sample smp = {r->x, r->v, r->pA, r->pB, r->F, r->u, r->ucmd, r->q + d0, r->qd + d0};
    crane_chain_row(cc, &smp, row + SIM_NCOL);
    row[COL_T] = t;
}
