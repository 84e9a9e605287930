// engine.h: one crane engine, whatever the backend: the lagrange crane
// (engine_lagrange.c, on lagrange_sim) or the ODE world (engine_ode.c, on
// ode_world), and for a crane chain of any shape their chain engines
// (engine_chain_step.c on chain_sim, engine_ode_chain_step.c on ode_chain,
// engine_ode_sandbox_chain_step.c on the sandbox hosting the chain), sized
// by the model. Drivers (drive, the window's tick, the soak bench) create one
// from the model and the options, set commands, advance it on the simulated
// clock, read its row and its snapshot, and never ask which backend runs:
// what differs is behind engine_ops (engine_impl.h). Scripted runs (run,
// compare, study, bench) go through engine_run, which plays a scenario.
// What they must know of a backend before one exists (its options, its
// world, its defaults) is its row in engine_backend.h.
#ifndef ENGINE_H
#define ENGINE_H

#include "engine_backend.h"
#include "engine_faults.h"
#include "engine_types.h"
#include "scenario.h"
#include "sim_base.h"
#include "world_snapshot.h"

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

/// The engine o->mechanics names, at joint angles q0 [rad], slew angle
/// slew0 [rad] (ode only) and tip load m3 [kg] (lagrange, and the ode
/// validation world; the sandbox picks loads up with the hook). The ode world
/// is o->world, else the sandbox. For a crane chain (not the two-link
/// shorthand; lagrange also with --variant general) the backend's engine for
/// chains (engine_ops.stepped): q0 are the first two boom DOFs, the others
/// start mid-limits (crane_chain_start_pose), as the scripted runs start;
/// it has what engine_caps says. NULL with one line in err: the start the
/// run checks refuse (an unreachable pose, a step the method cannot take, a
/// load the reliefs cannot hold), or the world file at fault.
engine* engine_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                      size_t errsz);
void engine_destroy(engine* e);
/// "lagrange" or "ode".
const char* engine_backend_name(const engine* e);

void engine_describe(const sim_opts* o, engine_desc* d);
/// The work a finished run r did, as its summary says it after "real time; ":
/// "ODE step 1 ms, 30000 hydraulic sub-steps" or "200000 steps, 0 rejected,
/// 400000 f evals, 20065 LU".
void engine_describe_work(const sim_opts* o, const sim_result* r, char* buf, size_t n);

/// Valve commands lift, jib, slew in [-1, 1] (clamped; slew ignored where
/// the crane does not slew), held until changed. On an engine that takes
/// commands by function (a chain engine) each goes to the function of that
/// name, if the model has one (else it is dropped); the other functions
/// keep their commands.
void engine_set_commands(engine* e, const double u[3]);
/// The functions the operator commands: the model chain's (lift, jib,
/// ...), for the two-link crane and for a chain in the sandbox then "slew"
/// where the chain has no function of that name (engine_set_commands' third
/// command, the sandbox's slew drive); their count and names (NULL out of
/// range). The two-link crane: lift, jib, slew; a chain model: its
/// functions, in the model file's order (then slew in the sandbox).
int engine_nfunction(const engine* e);
const char* engine_function_name(const engine* e, int k);
/// The index of the function called name, or -1.
int engine_find_function(const engine* e, const char* name);
/// Commands of the engine_nfunction functions in [-1, 1] (clamped), n of
/// them in their order, held until changed. 0, or -1 with one line in err
/// (may be NULL) and nothing set when n is not engine_nfunction(e): "N
/// commands for the M functions lift, jib, ...". The two-link crane's go
/// through engine_set_commands (and its limiter).
int engine_set_function_commands(engine* e, const double* u, int n, char* err, size_t errsz);
/// The command of the function called name in [-1, 1], held; the others
/// keep theirs. 0, or -1 with "no function 'X' (functions: lift, ...)" in
/// err (may be NULL) and nothing set.
int engine_set_function_command(engine* e, const char* name, double u, char* err, size_t errsz);
/// The operator's last command of function k as given [-], or NaN out of range.
double engine_function_command(const engine* e, int k);

/// What a stepped engine supplies besides stepping, its rows and its
/// commands by function: a driver whose output needs one asks before it
/// starts (engine_require) instead of finding a NULL later.
typedef enum engine_cap {
    /// A picture for the renderer (engine_snapshot): the window, serve's frames.
    ENGINE_CAP_SNAPSHOT = 1u << 0,
    /// The rated capacity limiter (engine_rcl): its chart, the cut commands.
    ENGINE_CAP_LIMITER = 1u << 1,
    /// Boom edits in place or by rebuild (engine_set_link): the drive panel.
    ENGINE_CAP_SET_LINK = 1u << 2,
    /// The two-link shape: commands lift, jib, slew (u[3]) and rows of
    /// SIM_NCOL columns, what the HUD, the serve protocol and session files
    /// carry (issue 27 sizes them by the model).
    ENGINE_CAP_TWO_LINK = 1u << 3,
} engine_cap;
/// The engine_cap bits of engine e, and of the engine engine_create would
/// make for model m with options o (0 when o names no backend).
unsigned engine_caps(const engine* e);
unsigned engine_caps_for(const model* m, const sim_opts* o);
/// 0 when the stepped engine for m and o has every bit of caps; else -1
/// with one line in err: "WHAT: <model file>: the stepped <backend> engine
/// for this crane chain (N functions) has no <first missing part> yet".
/// what names the caller ("the window", "the serve protocol").
int engine_require(const model* m, const sim_opts* o, unsigned caps, const char* what, char* err, size_t errsz);
/// 0 when every command column of sc names a function of m (lift, jib and
/// slew always do), else -1 with "FILE: commands.X: unknown field 'X': the
/// model has no function of that name (its functions: ...)" in err. engine_run checks it.
int engine_check_scenario(const model* m, const scenario* sc, char* err, size_t errsz);
/// Hook: 1 attach the nearest load in reach, 0 release. Returns the load
/// index attached, or -1 (also where the world has no hook).
int engine_hook(engine* e, int attach);
/// engine_hook for an operator: attach (1) or release (0), and say what
/// happened in msg, one line: "hooked load_500 (500 kg)", "released
/// load_500", or why nothing was hooked: "H: no load in reach of the hook
/// (nearest: load_500, 3.21 m away; reach 0.50 m)", "H: this world has no
/// hook". Returns engine_hook's answer.
int engine_hook_report(engine* e, int attach, char* msg, size_t n);
/// The mechanical energy [J] (kinetic + potential from z = 0) of the
/// crane's column and booms into E[0] and of its rope and hook into E[1],
/// where the backend has bodies for them (the ode world); false, E
/// untouched, where it has not (the lagrange crane).
bool engine_part_energy(const engine* e, double E[2]);
/// Name and mass [kg] of load i of the world, or NULL.
const char* engine_load_name(const engine* e, int i, double* mass);
/// True while a load hangs on the hook.
bool engine_attached(const engine* e);
/// The circuit the running engine uses (the model's for lagrange, the
/// world's own copy for ode): hyd_model_set on it takes effect at the next step.
hyd_model* engine_circuit(engine* e);
struct sim_energy;
/// Keep the energy balance en (a new sim_energy_create, energy_acc.h) of
/// this engine from now on: bound to its circuit, integrated at every step
/// of its solver by the step's own method, as the scripted runs do
/// (docs/energy.md). The caller reads it (sim_energy_result) and frees it
/// after engine_destroy, or calls sim_energy_finish first. 0, or -1 (out of
/// memory, already bound). Costs an evaluation of the circuit per step.
int engine_follow_energy(engine* e, struct sim_energy* en);
/// Set the tip load [kg] where the engine carries it as a parameter
/// (lagrange; takes effect at the next step).
void engine_set_load(engine* e, double m3);
/// True when the tip load is a parameter engine_set_load changes (else the
/// world's loads are bodies, or the load is merged into the end arm).
bool engine_can_set_load(const engine* e);
/// True when engine_set_link applies a new boom length in place (else the
/// engine must be rebuilt for one).
bool engine_can_resize_links(const engine* e);
/// Boom k (0 lifting arm, 1 end arm) of the two-link crane now has link ln (mass, com, inertia,
/// length), applied in place at the next step where the engine can: the
/// lagrange crane always (its constants are recomputed; ln is the model's
/// link it reads), the ode world for a new mass and inertia about the same
/// centre of mass. Returns 0 when applied, 1 when the engine must be
/// rebuilt for it (a new length, or a centre of mass that moves); -1 when
/// the engine has no such booms (a chain engine: no ENGINE_CAP_SET_LINK).
int engine_set_link(engine* e, int k, const crane_link* ln);

/// The output channels the engine publishes, by name, unit and kind, which
/// are the columns engine_row fills: the first entries of sim_channels
/// (the base list; the ode world adds its extras), then for a chain engine
/// the chain's own columns (crane_chain_columns: per actuator, function and
/// degree of freedom), as the scripted runs' rows. *n = engine_ncol(e).
const sim_channel* engine_channels(const engine* e, int* n);
/// The channels of the engine o->mechanics names, before one exists (a run
/// writes its CSV header from them).
const sim_channel* engine_channels_for(const sim_opts* o, int* n);
/// The circuit's state now, in the circuit's order (hyd_model_nstate of
/// engine_circuit entries), into y; *in (may be NULL): the hydraulic data
/// the engine last evaluated with (strokes, rates, valve commands).
void engine_circuit_state(engine* e, double* y, const hyd_data** in);
/// The number of engine_channels: the columns of engine_row (SIM_NCOL at
/// most for the two-link crane; a chain engine's more, sized by the model).
int engine_ncol(const engine* e);

/// Advance to simulated time t_to [s] (the ode world takes whole ODE steps:
/// it ends on the step nearest t_to), then apply the run checks of sim_base.h
/// (sim_check_row) to the state reached and hand its row to row_fn (may be
/// NULL). Returns 0; 1 on a numerical failure or a failed check (message
/// from engine_error), after which the engine stays stopped and every
/// further call returns 1; 2 when row_fn asked to stop.
int engine_advance_to(engine* e, double t_to, engine_row_fn row_fn, void* user);
/// Advance by dt [s], as engine_advance_to without a row callback.
int engine_advance(engine* e, double dt);

/// A scripted run from t = 0 to k->t_end: the engine o->mechanics names,
/// built for scenario sc (its start pose, load and world), plays the
/// scenario and hands a row every o->dt_out to k. The run checks and their
/// messages are sim_base.h's; res as sim_run's (status 0, 1 numerical failure,
/// 2 refused or stopped).
int engine_run(const model* m, const scenario* sc, const sim_opts* o, const engine_sink* k, sim_result* res);
/// The note for a dip below absolute zero the checks saw (sim_checks_note),
/// or "".
void engine_note(const engine* e, char* note, size_t n);
const char* engine_error(const engine* e);
/// The collisions since the engine was created (the ode sandbox: checked at
/// every ODE step, as a scripted run counts them; sim_base.h), or NULL where the
/// world reports none (the lagrange view, the ode validation world).
const sim_collisions* engine_collisions(const engine* e);

/// Hears a hook event the scripted operator applied: attach or release,
/// and engine_hook's answer.
typedef void (*engine_hook_fn)(void* user, engine* e, int attach, int got);
/// The scripted operator (scenario_play) at simulated time tm [s]: the
/// stick positions into u[3] (the caller sets them), and every hook event
/// due by tm, from *ev on, applied to e (*ev advances); on_hook (may be
/// NULL) hears each.
void engine_play(engine* e, const scenario* sc, double tm, int* ev, double u[3], engine_hook_fn on_hook,
                 void* user);

/// engine_play by function: the commands of sc at time tm [s] for each of
/// the engine_nfunction functions into u (the scenario's column of that
/// name, lift, jib, slew or a named one; 0 for a function it does not
/// command), hook and fault events as engine_play. The two-link crane's u is
/// engine_play's lift, jib, slew.
void engine_play_functions(engine* e, const scenario* sc, double tm, int* ev, double* u, engine_hook_fn on_hook,
                           void* user);

/// The scenario's fault events as engine_play applies them at time tm [s]
/// (a replay applies them at the recorded ticks, without the scenario's commands).
void engine_apply_faults(engine* e, const scenario* sc, double tm);

/// Simulated time [s].
double engine_time(const engine* e);
/// The CSV row at the current time: engine_ncol(e) columns
/// (engine_channels). row must hold max(engine_ncol(e), SIM_NCOL) values: a
/// caller with a SIM_NCOL buffer requires ENGINE_CAP_TWO_LINK.
void engine_row(engine* e, double* row);
struct rcl;
/// The engine's rated capacity limiter (rcl.h), or NULL: it filters
/// engine_set_commands when o->rcl, and fills the rows' rcl_util either way.
const struct rcl* engine_rcl(const engine* e);
/// A limiter for model m on the world of options o (default_world when
/// o->world is NULL; no world for lagrange), or NULL when its chart cannot
/// be made. engine_rcl_destroy frees it.
struct rcl* engine_rcl_create(const model* m, const sim_opts* o, const char* default_world);
void engine_rcl_destroy(struct rcl* r);
/// Take the engine's limiter (NULL if it has none); the engine then has none.
/// Its chart is most of what building an engine costs (the sandbox: about
/// 80 %), and it depends only on the model and the world.
struct rcl* engine_rcl_detach(engine* e);
/// As engine_create, with limiter r (from engine_rcl_detach of an engine of
/// the same model, options and world) instead of a new one: its filter
/// starts again (rcl_reset), so the engine steps exactly as a new one. The
/// engine owns r from then; on failure (NULL) r is still the caller's. r NULL:
/// as engine_create.
engine* engine_create_rcl(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3,
                          struct rcl* r, char* err, size_t errsz);
/// Fill a snapshot for the renderer; false, s untouched, where the engine
/// has none (no ENGINE_CAP_SNAPSHOT: a chain engine outside the sandbox).
bool engine_snapshot(engine* e, world_snapshot* s);

#ifdef __cplusplus
}
#endif
#endif
