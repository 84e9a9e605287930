// chain_row.h: one row of the general analytic mode (chain_sim.h) for any
// crane chain, shared by its scripted run (engine_chain.c) and its stepped
// engine (engine_chain_step.c), so that both write the same columns from the
// same outputs.
#ifndef CHAIN_ROW_H
#define CHAIN_ROW_H

#include "chain_sim.h"
#include "sim_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Columns of a chain row: sim.h's base columns (SIM_NCOL_BASE), then the
/// chain's own (crane_chain_columns: cc->ncol); the row buffer must hold at
/// least chain_row_size of them (lagrange_row writes SIM_NCOL).
int chain_row_ncol(const crane_chain* cc);
int chain_row_size(const crane_chain* cc);

/// The row at (t, y): the base columns hold the first two actuators, their
/// functions and the first two boom DOFs, the tip relative to the first
/// boom's joint; then every actuator, function and DOF (crane_chain_row).
/// co's arrays are the caller's buffers (nact, nfn and ndof entries), filled
/// by chain_sim_outputs on the way.
void chain_sim_row(chain_sim* cs, double t, const double* y, chain_sim_out* co, double* row);

#ifdef __cplusplus
}
#endif
#endif
