// hyd_events.h: an event counter for hyd_problem.events on any compiled
// circuit (hyd_eval's component loops: the general analytic path of a crane
// chain, or any caller that couples a circuit to its own mechanics).
//
// Why. The fixed-step W-methods (Krus, ROS2) reuse a Jacobian for
// jac_every steps. They tolerate a J that overestimates the stiffness of a
// mode, not one that underestimates it at h |lambda| > 2: there the stage
// equations amplify the mode instead of damping it (docs/solvers.md). So J
// must be taken again when a piecewise law of the circuit gets stiffer than
// the J describes. The fused kernel of the standard circuit counts such
// switches itself (hyd_fused_events_update, circuit_kernel.h); this counter
// does the same for every circuit, from the compiled model's records, and
// adds the cylinders' seal friction, which the fused counter does not watch:
//
//   F_seal = (F_c + F_s exp(-(v/v_st)^2)) tanh(v/v_sm)      (cylinder.c)
//
// has the slope (F_c + F_s)/v_sm at rest and about 4 (F_c + F_s)/v_sm
// exp(-2|v|/v_sm) away from it: a damping that grows 5e3-fold as a piston
// slows from 5 v_sm to rest. On a light body (a telescopic stage of 20 kg
// between two sliding joints) it is a mode of (F_c + F_s)/(v_sm m) = 2.2e5
// 1/s for the seal of the test models (4.5 kN, 1 mm/s): h |lambda| = 22 at
// 0.1 ms. A J taken while the piston moved, reused as it comes to rest or
// reverses through zero, underestimates that mode 100-fold and Krus rings
// up (the 8-function model: a blow-up at 7.943 s, docs/lagrange.md).
#ifndef HYD_EVENTS_H
#define HYD_EVENTS_H

#include "hydraulics.h"

#ifdef __cplusplus
extern "C" {
#endif

/// A valve command change between two calls that counts as a command step
/// [-, of full opening]: as HYD_FUSED_CMD_EVENT (circuit_kernel.h).
#define HYD_EVENTS_CMD_STEP 0.05

typedef struct hyd_events hyd_events;

/// A counter for circuit m (its sizes; the thresholds are read from m at
/// every call, so a changed parameter counts at once). NULL when out of
/// memory.
hyd_events* hyd_events_create(const hyd_model* m);
void hyd_events_free(hyd_events* e);

/// Counts a switch that stiffens the circuit since the previous call and
/// returns the count (the first call only records where every law stands):
///   - a valve command moving by more than HYD_EVENTS_CMD_STEP (NaN counts);
///   - a cylinder's seal friction getting steeper by an octave or more: its
///     level is the octave of sech^2(v/v_sm), the tanh's slope relative to
///     its slope at rest (0 within 0.83 v_sm of rest, one more per halving);
///     also a velocity that changes sign with both levels above 0 (the step
///     went through the steep part without landing in it);
///   - an end stop engaging or pressing beyond its smoothing width;
///   - a relief or check valve reaching or passing the corner of its opening;
///   - a pump line entering its pump's cut-off band;
///   - a pressure node below the knee of its bulk-modulus law (Be < 0.9 of
///     the liquid's) rising into a higher octave of pressure (Be grows about
///     3x per octave there).
/// Switches back are not counted (an older J then overestimates).
/// y: the states in the caller's order, circuit state i at y[map[i]] (map
/// NULL: the circuit's own order); x, v: the cylinders' strokes [m] and
/// rates [m/s] (hyd_model_ncylinder of each); cmd: the valves' commands
/// (hyd_model_nvalve), or NULL to skip them.
unsigned long hyd_events_update(hyd_events* e, const hyd_model* m, const double* y, const int* map,
                                const double* x, const double* v, const double* cmd);

#ifdef __cplusplus
}
#endif

#endif
