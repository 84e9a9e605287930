// param_names.h: how the world library's messages name the settings a
// program lets its user choose. The library knows its own names (a sim_opts
// field, "h"); a program names them once as its user knows them (cranesim:
// its options, "--dt", app_name_params), and every later message uses that.
#ifndef PARAM_NAMES_H
#define PARAM_NAMES_H

#ifdef __cplusplus
extern "C" {
#endif

/// The run settings a world-library message names. The library does not
/// know how a program lets its user set them: the program names them once
/// (sim_name_params; cranesim names its options, "--dt"), else a message
/// names the sim_opts field ("h", "dt_ode", ...).
typedef enum sim_param {
    SIM_PARAM_DT,        ///< sim_opts.h, the fixed (or hydraulic sub-) step [s]
    SIM_PARAM_DT_ODE,    ///< sim_opts.dt_ode [s]
    SIM_PARAM_DURATION,  ///< sim_opts.duration [s]
    SIM_PARAM_EVERY,     ///< sim_opts.dt_out [s]
    SIM_PARAM_LOAD,      ///< sim_opts.load_mass [kg]
    SIM_PARAM_MECHANICS, ///< sim_opts.mechanics
    SIM_PARAM_RTOL,      ///< sim_opts.rtol [-]
    SIM_PARAM_SET,       ///< a model edit PATH=VALUE (json_set_path, model_load)
    SIM_PARAM_WORLD,     ///< sim_opts.world, a world file or name (world_desc_load)
    SIM_PARAM_MODEL,     ///< a model file or name (model_load)
    SIM_PARAM_NO_STEP_PROBE, ///< sim_opts.no_step_probe: run a step the probe refuses
    SIM_PARAM_COUNT
} sim_param;
/// Name the settings for every later message (names[p] may be NULL: the
/// field's name). The table is copied by pointer: it must outlive the runs.
void sim_name_params(const char* const names[SIM_PARAM_COUNT]);
/// The name messages use for setting p.
const char* sim_param_name(sim_param p);

#ifdef __cplusplus
}
#endif
#endif
