// step_probe.h: the step probe (issue 25 item 7): a Krus or ROS2 step is
// tried on the model's abrupt valve steps before a run or a stepped engine
// uses it. engine.c applies it to every engine and scripted run.
#ifndef STEP_PROBE_H
#define STEP_PROBE_H

#include <stddef.h>

#include "model.h"
#include "sim_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The fixed step above which a stepped engine's Krus or ROS2 step is
/// probed [s]: the default step, at which every shipped model and scenario
/// runs (their tests), is not.
#define SIM_PROBE_ABOVE 1e-4
/// Refuse, before a run starts (scripted, or a stepped engine: drive,
/// serve, replay), a Krus or ROS2 step h [s] above SIM_PROBE_ABOVE that
/// blows up on model m's abrupt valve steps or integrates them too far off:
/// the `step` scenario's commands (lift, jib, lowering; 500 kg, 6.5 s) are
/// run on the lagrange backend at h and at SIM_PROBE_ABOVE with o's solver
/// and Jacobian settings, and a stroke more than 5 % RMS of its peak off,
/// or a chamber pressure more than 15 %, refuses h. No bound on the
/// circuit's fastest mode separates the steps that work from those that do
/// not (docs/solvers.md: the LS crane at Krus 0.2 ms is 25 % off where the
/// standard crane at 1 ms, h|lambda| as large, is 0.2 %). The message says
/// where, and names the largest step of {5, 2, 1} x 10^k dividing
/// o->dt_out that passes (else SIM_PROBE_ABOVE). Returns SIM_OK, or
/// SIM_REFUSED with one line in err. Other methods, CVODE, h <=
/// SIM_PROBE_ABOVE and o->no_step_probe always pass.
int sim_check_step_probe(const model* m, const sim_opts* o, double h, char* err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
