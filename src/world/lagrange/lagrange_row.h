// lagrange_row.h: one CSV row of the analytic backend from its outputs,
// shared by the closed form (engine_lagrange.c) and the general path
// (engine_chain.c).
#ifndef LAGRANGE_ROW_H
#define LAGRANGE_ROW_H

#include "lagrange_sim.h"
#include "sim_base.h"

/// One row (all SIM_NCOL columns; the world extras 0) from the analytic
/// crane's outputs o at time t [s].
void lagrange_row(double t, const lsim_out* o, double* row);

#endif
