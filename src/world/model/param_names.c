// param_names.c: the names the world library's messages give the run
// settings (param_names.h). Kept apart from the run layer (sim.c) so that
// the loaders (json_util.c, model.c, world_desc.c), which name settings in
// their messages, do not depend on it.
#include "param_names.h"

#include <stddef.h>

static const char* const k_param_field[SIM_PARAM_COUNT] = {"h",         "dt_ode",    "duration", "dt_out",
                                                           "load_mass", "mechanics", "rtol",     "set",
                                                           "world",     "model",     "no_step_probe"};
static const char* const* g_param_names;

void sim_name_params(const char* const names[SIM_PARAM_COUNT]) { g_param_names = names; }

const char* sim_param_name(sim_param p) {
    const char* n = g_param_names ? g_param_names[p] : NULL;
    return n ? n : k_param_field[p];
}
