// crane_chain_synth.h: synthetic crane chains of any size, built in C for
// the tests and the benchmark of the general analytic mode (chain_sim.h):
// a fixed or slewing column, then one body per function, each with its own
// cylinder and valve section of hyd_model_synthetic's circuit.
#ifndef CRANE_CHAIN_SYNTH_H
#define CRANE_CHAIN_SYNTH_H

#include <stdbool.h>
#include <stddef.h>

#include "crane_chain.h"
#include "hydraulics.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The chain of joints[i] ('R' a revolute boom, 'P' a telescopic extension
/// sliding inside the body before it; joints[0] must be 'R', the lifting
/// arm on the column) with one actuator and one function per body, named
/// f1, f2, ... on valve and cylinder act<k>_valve, act<k>_cyl of
/// hyd_model_synthetic(n) (made here, into *hm). Booms shrink outwards
/// (length 2.4 m x 0.8^k, mass 200 kg x 0.75^k); an extension is 0.8 of its
/// boom's length. q0 [n] receives the start pose (the lifting arm near
/// horizontal, the knuckles folded, the extensions at 0.3 m), and each
/// cylinder's closed length is set so its stroke there is half its
/// stroke; the joint limits put q0 in their middle (0.5 rad either side, an
/// extension [0, 0.6] m). The chain is bound to *hm. Returns 0, or -1 with one line in err.
int crane_chain_synthetic(const char* joints, bool slew_free, crane_chain* out, hyd_model** hm, double* q0,
                          char* err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
