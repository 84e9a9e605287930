// circuit_fast.h: the fast kernel for any circuit built from library
// components. Type-sorted loops over packed record arrays (as MuJoCo
// evaluates its actuators) that add every flow straight into its nodes' net
// inflow and every partial straight into the Jacobian, already scaled by its
// row's Be/V: no per-port flow slots, no gather, no dense (n+1)^2 scratch.
// The laws are the components' own (hyd_pump.h, hyd_ramp.h, hyd_orifice.h,
// hyd_valve.h, hyd_hose.h, hyd_cylinder.h, and for the load-sensing types
// hyd_ls_pump.h, hyd_shuttle.h, hyd_compensator.h, hyd_counterbalance.h,
// hyd_accumulator.h), so it agrees with the reference
// loops (hyd_eval, hyd_jacobian) to rounding; only the summation order of a
// node's inflows differs.
//
// No component is left out of its sums: a component of a type it has no
// loop for is either evaluated by that type's reference loop (fallback) or
// the kernel is not built, with a message naming the component and its
// type. Its one shape-specific path, the load-sensing layout in one pass
// (circuit_fast_ls.c, hyd_fast_lanes), is an allow-list: the exact number
// of components of each type it packs and none of any other type (also a
// type with a fast loop here, or one added to the library later); any other
// circuit runs the loops, and hyd_fast_lanes_why says why.
// tests/hydraulics/test_every_type.c adds each type to each shipped circuit
// and compares every path with the reference loops.
#ifndef HYD_CIRCUIT_FAST_H
#define HYD_CIRCUIT_FAST_H

#include "hydraulics.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct hyd_fast hyd_fast;

/// Every type the fast kernel has a loop for (a mask of 1u << hyd_type).
unsigned hyd_fast_types(void);

/// Build the kernel for model m. types: the types it may take with its own
/// loops (hyd_fast_types(), or fewer); a component of any other type is
/// evaluated by its reference loop when fallback is non-zero, else the build
/// fails with "component 'name' (type): the fast kernel has no loop for this
/// type" in why. NULL on failure (also out of memory). The kernel reads the
/// model's records again after a hyd_model_set (its revision).
hyd_fast* hyd_fast_create(const hyd_model* m, unsigned types, int fallback, char* why, size_t whysz);
void hyd_fast_free(hyd_fast* k);
/// Renumber states: circuit state i lives at y[map[i]] (and its rate at
/// ydot[map[i]], its Jacobian row and column at map[i] of the caller's J)
/// from now on; map NULL is the circuit's own order. The coupling partials
/// stay in circuit order. Returns 0, or -1 when components fall back to the
/// reference loops (which work in circuit order only).
int hyd_fast_map(hyd_fast* k, const int* map);
/// Components evaluated by their reference loop.
int hyd_fast_nfallback(const hyd_fast* k);

/// The load-sensing crane layout (an LS pump, LS shuttle and two
/// compensated sections with counterbalance valves, as
/// assets/models/hiab031_ls.json, and nothing else but reliefs and checks)
/// has a one-pass evaluation with its two
/// sections in two SSE2 lanes, bit for bit the loops' (circuit_fast_ls.c);
/// hyd_fast_eval takes it whenever no end stop is touched and every pressure
/// is on the Be table (in AVX form where the CPU has it, else SSE2; the
/// same values). on = 0 switches it off, 1 on (the default), 2 on in its
/// SSE2 form even with AVX (for tests), < 0 leaves it. Returns 1 when the
/// circuit has that layout.
int hyd_fast_lanes(hyd_fast* k, int on);
/// Why the circuit does not have that layout ("" when it has): the first
/// component of a type the layout has no place for, a count or a connection
/// that differs from it (say "component 'x' (accumulator): the load-sensing
/// layout has no place for this type").
const char* hyd_fast_lanes_why(const hyd_fast* k);
/// Evaluations the one-pass layout path has taken so far.
unsigned long hyd_fast_lanes_count(const hyd_fast* k);

/// ydot = f(y) as hyd_eval, with the inputs in d. Fills d->cyl_F, cyl_stop,
/// node_p, node_V, node_dV, node_q and node_be (not comp_q or comp_open).
void hyd_fast_eval(hyd_fast* k, hyd_data* d, const double* y, double* ydot);
/// The Jacobian as hyd_jacobian: every entry of the n x n block at J (leading
/// dimension ldj) written, ydot when non-NULL, the outputs of hyd_fast_eval
/// and the coupling partials (d->dydx, dydv, dFdy, dFdx, dFdv).
void hyd_fast_jacobian(hyd_fast* k, hyd_data* d, const double* y, double* ydot, double* J, int ldj);

#ifdef __cplusplus
}
#endif
#endif
