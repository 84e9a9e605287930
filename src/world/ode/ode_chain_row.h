// ode_chain_row.h: one row of the ODE chain world (ode_chain.h) for any
// crane chain, and of the sandbox hosting the chain, shared by the scripted
// runs (engine_ode_chain.c) and the stepped engines
// (engine_ode_chain_step.c, engine_ode_sandbox_chain_step.c), so that both
// write the same columns from the same outputs.
#ifndef ODE_CHAIN_ROW_H
#define ODE_CHAIN_ROW_H

#include "ode_chain.h"
#include "sim_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The outputs of a chain world and the buffers they go through, sized by
/// the chain.
typedef struct ode_chain_rows {
    const crane_chain* cc;
    const hyd_model* hm;
    int na, nf, nd;
    int* iu;     ///< [nf] the spool state of function f's valve, or -1
    int ipump;   ///< the supply node, or -1
    double *x, *v, *pA, *pB, *F, *u, *ucmd, *q, *qd; ///< the outputs, sized by the chain
} ode_chain_rows;

/// Buffers for chain cc on circuit hm (cc bound to it) with nd degrees of
/// freedom (the world's: ode_chain_ndof). 0, or -1 when out of memory.
int ode_chain_rows_init(ode_chain_rows* r, const crane_chain* cc, const hyd_model* hm, int nd);
void ode_chain_rows_free(ode_chain_rows* r);

/// Every actuator's and function's outputs of world w now, into r's arrays
/// (x, v, pA, pB, F, u, ucmd, q, qd).
void ode_chain_rows_outputs(ode_chain_rows* r, const ode_chain* w);

/// Columns of a row: the backend's SIM_NCOL channels, then the chain's own
/// (cc->ncol).
int ode_chain_row_ncol(const crane_chain* cc);

/// The row of world w at time t [s] (ode_chain_row_ncol(cc) values): the
/// base columns hold the first two actuators, their functions and the first
/// two boom DOFs (as the analytic general path's rows, so compare pairs the
/// same quantities), the tip relative to the first boom's joint in the boom
/// plane; of the world extras the slew where the column slews, the rest 0
/// (the validation world has no hook, truck or contacts); then every
/// actuator, function and DOF under the chain's column names
/// (crane_chain_row).
void ode_chain_make_row(ode_chain_rows* r, const ode_chain* w, double t, double* row);

struct ode_world;
/// The row of the sandbox w hosting a chain crane (ode_world_chain) at time
/// t [s], as the scripted sandbox run (engine_ode_chain.c) and the stepped
/// sandbox engine (engine_ode_sandbox_chain_step.c) both write it: the
/// sandbox's SIM_NCOL base columns (ode_world_row: the first two actuators,
/// the first two boom DOFs, the slew, hook, truck, supports), then the
/// model chain cc's columns (crane_chain_row) from the hosted chain's
/// outputs, r bound to the hosted chain (ode_chain_chain). The model's DOF
/// columns start after the slew where the model's column does not slew
/// (the hosted copy always slews).
void ode_chain_sandbox_row(ode_chain_rows* r, struct ode_world* w, const crane_chain* cc, double t, double* row);

#ifdef __cplusplus
}
#endif
#endif
