// engine_impl.h: what a backend supplies to engine.h. A backend's engine
// struct starts with a struct engine (the part engine.c owns: options,
// checks, failure state) and points it at its engine_ops.
#ifndef ENGINE_IMPL_H
#define ENGINE_IMPL_H

#include "engine_faults.h"
#include "engine_types.h"
#include "model.h"
#include "scenario.h"
#include "sim_base.h"
#include "world_snapshot.h"

typedef struct engine_ops {
    const char* name; ///< "lagrange", "ode"
    /// NULL: create makes every stepped engine of this backend. Else the
    /// ops whose create engine_create calls for model m and options o (this
    /// backend's own, or its engine for crane chains): the one place that
    /// chooses, also asked before an engine exists (engine_caps_for).
    const struct engine_ops* (*stepped)(const model* m, const sim_opts* o);
    /// A stepped engine at q0 [rad], slew0 [rad] (where the crane slews), tip load m3 [kg].
    engine* (*create)(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                      size_t errsz);
    /// A scripted run of scenario sc (engine_run).
    int (*run)(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k, sim_result* res);
    /// The report fields of a run with options o (engine_describe), and its work.
    void (*describe)(const sim_opts* o, engine_desc* d);
    void (*describe_work)(const sim_opts* o, const sim_result* r, char* buf, size_t n);
    int nchannel;     ///< the channels it publishes: sim_channels[0 .. nchannel), the columns its rows fill
    void (*destroy)(engine* e);
    /// The commands lift, jib, slew (the two-link crane's); NULL where the
    /// engine takes commands by function only (set_function_commands).
    void (*set_commands)(engine* e, const double u[3]);
    /// NULL: the commands are set_commands'. Else the engine's commands by
    /// function, engine_nfunction(e) of them in [-1, 1] (a chain engine).
    void (*set_function_commands)(engine* e, const double* u);
    /// NULL: the backend has no hook (engine_hook returns -1, no loads).
    int (*hook)(engine* e, int attach);
    const char* (*load_name)(const engine* e, int i, double* mass);
    bool (*attached)(const engine* e);
    /// NULL with hook: no distances known. The load nearest the hook, its
    /// distance and the hook's reach [m] (ode_world_nearest_load).
    int (*nearest_load)(const engine* e, double* dist, double* reach);
    hyd_model* (*circuit)(engine* e);
    /// The circuit's state now, in its own order (hyd_model_nstate of
    /// circuit()), into y; *in: the hydraulic data the engine last
    /// evaluated with (its cylinder strokes, rates and valve commands).
    void (*circuit_state)(engine* e, double* y, const hyd_data** in);
    /// NULL: the tip load is not a parameter of this backend.
    void (*set_load)(engine* e, double m3);
    /// NULL: no two-link booms to edit (a chain engine; engine_set_link returns -1).
    int (*set_link)(engine* e, int k, const crane_link* ln);
    bool resize_links; ///< set_link applies a new boom length in place
    /// Advance dt [s]; 0, or 1 with the reason in e->err.
    int (*step)(engine* e, double dt);
    double (*time)(const engine* e);
    /// The row now: engine.ncol values (at least SIM_NCOL are written to).
    void (*row)(engine* e, double* row);
    /// NULL: no picture for the renderer (a chain engine; engine_snapshot returns false).
    void (*snapshot)(engine* e, world_snapshot* s);
    /// NULL: no bodies to weigh (engine_part_energy).
    void (*part_energy)(const engine* e, double E[2]);
    /// NULL (or a NULL result): the world reports no collisions.
    const sim_collisions* (*collisions)(const engine* e);
    /// Integrate the energy balance en (bound by engine_follow_energy to
    /// circuit()) at every step from now on; 0, or -1.
    int (*follow_energy)(engine* e, struct sim_energy* en);
} engine_ops;

struct engine {
    const engine_ops* ops;
    sim_opts o;
    char err[512];
    sim_checks chk; ///< the run checks every driver applies (sim_base.h)
    bool failed;    ///< a check or the step failed: the engine stays stopped
    engine_faults faults; ///< for engine_play's fault events (faults_ready once initialised)
    bool faults_ready;
    struct rcl* rcl;      ///< the rated capacity limiter (engine.c), or NULL where its chart failed
    double h_probe;       ///< the fixed hydraulic step the backend integrates with [s], set by its create:
                          ///< engine.c applies the step probe (sim_check_step_probe) to it
    const model* mdl;     ///< the model it was made from (its chain's functions: engine_function_name)
    // Set by engine.c after the backend's create, sized by the model:
    int nfn;              ///< engine_nfunction: the commands it takes
    double* u_op;         ///< [nfn] the operator's last commands by function (lift, jib, slew for the
                          ///< two-link crane), as given to engine_set_commands or by function [-]
    double* u_lim;        ///< [nfn] what the limiter let through of them [-] (u_op when it cut nothing)
    /// Columns of its rows (engine_ncol): set by the backend's create when
    /// its rows carry more than ops->nchannel (a chain engine: the chain's
    /// columns after the backend's); 0: ops->nchannel.
    int ncol;
    /// Set by the backend's create: its commands by function end with a
    /// "slew" the model's chain does not list (a chain crane in the sandbox,
    /// whose slew drive is the world's or the model's mechanics.slew), as
    /// the two-link crane's third command.
    bool slew_function;
    sim_channel* chan;    ///< [ncol] its channels when ncol > ops->nchannel (engine.c), else NULL
    double* rowbuf;       ///< [max(ncol, SIM_NCOL)] a row for the checks after each step (engine.c)
};

// Each backend declares its engine_ops in its own folder (engine_lagrange.h,
// engine_ode.h); engine.c, which chooses among them, includes those.


#endif
