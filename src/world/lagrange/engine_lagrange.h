// engine_lagrange.h: the lagrange backend's engine_ops (engine_lagrange.c), which
// engine.c chooses by sim_opts.mechanics.
#ifndef ENGINE_LAGRANGE_H
#define ENGINE_LAGRANGE_H

#include "engine_impl.h"

extern const engine_ops engine_lagrange_ops;

#endif
