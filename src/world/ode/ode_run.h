// ode_run.h: the ODE world of a run or a live session, built from the model
// and the run's options (world file, steps, solver), and its row of the
// run's channels (sim_base.h). The ode engine (engine_ode.c) is its user.
#ifndef ODE_RUN_H
#define ODE_RUN_H

#include "model.h"
#include "ode_world.h"
#include "sim_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/// One row (all SIM_NCOL columns) from an ode world's current state.
void ode_world_row(ode_world* w, double* row);
/// The ode world for a run or a live session: world file o->world (else
/// default_world, a name in assets/worlds), steps, solver and tolerances from
/// o, joints at q0 [rad], slew at slew0 [rad], tip load m3 [kg]. NULL with a
/// one-line message naming the file or option at fault.
ode_world* ode_world_for_run(const model* m, const sim_opts* o, const char* default_world, const double q0[2],
                             double slew0, double m3, char* err, size_t errsz);

/// Where the model has a slew drive (model.chain.slew) and wd is a sandbox:
/// the world's slew section and circuit fragments are replaced by the
/// model's (mechanics.slew, hydraulics_slew; wd->slew_file names the model
/// for messages). The model's wins over a world's own; where they differ a
/// note says so once. A model without one keeps the world's. 0, or -1 (out
/// of memory) with the message in err.
int ode_world_take_model_slew(const model* m, world_desc* wd, char* err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
