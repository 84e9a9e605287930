// hyd_fused.h: the former name of circuit_kernel.h (the one-pass circuit
// kernel), kept so that callers that include it build unchanged.
#ifndef HYD_FUSED_H
#define HYD_FUSED_H
#include "circuit_kernel.h"
#endif
