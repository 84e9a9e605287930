// engine_ode.h: the ode backend's engine_ops (engine_ode.c), which
// engine.c chooses by sim_opts.mechanics.
#ifndef ENGINE_ODE_H
#define ENGINE_ODE_H

#include "engine_impl.h"

extern const engine_ops engine_ode_ops;

#endif
