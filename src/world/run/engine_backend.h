// engine_backend.h: what a driver may know about a backend before it runs
// one, asked by name or by sim_opts.mechanics. The drivers (src/app) never
// test which backend runs: they read these fields (does it take a world
// file, which options apply, its default world and scenario, its output
// step, whether a sweep needs worker processes), so a new backend is one
// more row of the table in engine_backend.c (docs/architecture.md, "Adding
// a backend") and no driver falls into an `else` written for another.
#ifndef ENGINE_BACKEND_H
#define ENGINE_BACKEND_H

#include "sim_base.h"

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

struct engine_ops;

typedef struct engine_backend {
    sim_mechanics id;             ///< the sim_opts.mechanics value that selects it
    const char* name;             ///< "lagrange", "ode": --mechanics, --backends, a server's hello
    const char* help;             ///< one phrase for --help: "analytic 2-DOF"
    /// What runs where it has no world, in messages: "lagrange 2-DOF" ("the
    /// lagrange 2-DOF crane", "the lagrange 2-DOF view").
    const char* crane;
    const struct engine_ops* ops; ///< its implementation (engine_impl.h)

    // ---- the world ----
    /// It runs in a world file (--world): the crane on a truck, with loads,
    /// obstacles and (in a sandbox world) a hook and a slewing column. false:
    /// no world; --world and the world's loads do not apply.
    bool world;
    /// The world of a scripted run (run, compare, sweep, study) when --world
    /// names none (sim_world_path(NULL)), and of a stepped driver (drive,
    /// serve); NULL without a world.
    const char* run_world;
    const char* drive_world;
    /// The scenario a stepped driver's scripted operator plays when none is
    /// given, on its drive world (or without a world).
    const char* drive_scenario;
    /// Without a world, its scripted runs (run, sweep, optimize) slew the
    /// column as a degree of freedom where the model has a slew drive
    /// (mechanics.slew) and the scenario commands the slew
    /// (engine_chain_slews); its stepped engine (drive, serve) does not.
    bool slew_dof;

    // ---- its options ----
    /// The option of its own rigid-body step ("--dt-ode", sim_opts.dt_ode):
    /// it writes rows at whole steps of it and sub-steps the hydraulics
    /// within it. NULL: the hydraulic step is the only step.
    const char* outer_step_opt;
    /// That step in messages ("ODE step"); what a peak over every step is
    /// taken over (engine_desc.step_name): "step" without an outer step.
    const char* step_name;
    bool variant;                 ///< --variant selects its equations (lagrange_variant)
    /// Why it refuses --solver cvode, after "works with --mechanics X only";
    /// NULL: it runs CVODE.
    const char* no_cvode;
    /// The rated capacity limiter cuts commands in its scripted runs (run,
    /// compare) with --rcl on; false: it only measures them there (the
    /// stepped drivers, drive and serve, cut with every backend).
    bool rcl_scripted;
    /// Its library keeps process-wide state: threads run its designs one at
    /// a time, so a sweep on more than one thread forks worker processes.
    bool process_wide;
} engine_backend;

/// The number of backends, and backend i (0 .. count - 1; else NULL).
int engine_backend_count(void);
const engine_backend* engine_backend_at(int i);
/// The backend called name, or NULL.
const engine_backend* engine_backend_find(const char* name);
/// The backend sim_opts.mechanics value id selects, or NULL for a value
/// that names none (a corrupt session file, a cast): never a default.
const engine_backend* engine_backend_by_id(int id);
/// engine_backend_by_id(o->mechanics).
const engine_backend* engine_backend_of(const sim_opts* o);
/// The backend of sim_default_opts (run's default, the analytic reference
/// of compare and study).
const engine_backend* engine_backend_default(void);
/// The first backend with a world (drive's and serve's default; the one
/// --world asks for when no --mechanics is given), or NULL.
const engine_backend* engine_backend_with_world(void);
/// The names of the backends, ", "-separated ("lagrange, ode"), into buf
/// of n bytes; with filter (may be NULL) only those it returns true for.
/// Returns buf.
const char* engine_backend_names(char* buf, size_t n, bool (*filter)(const engine_backend* b));
/// Select the backend called name: o->mechanics set, 0; -1 with
/// "unknown backend 'NAME' (known: lagrange, ode)" in err, o untouched.
int engine_backend_select(sim_opts* o, const char* name, char* err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
