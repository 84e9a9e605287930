// live.h: a crane stepped in real time by an outside loop (drive), with
// commands set between steps, whatever the backend.
#ifndef LIVE_H
#define LIVE_H

#include "sim.h"
#include "world_snapshot.h"

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct live live;

/// A live lagrange crane at joint angles q0 [rad] with tip load m3 [kg].
live* live_create_lagrange(const model* m, const sim_opts* o, const double q0[2], double m3, char* err,
                           size_t errsz);
/// A live ode world (o->world: file or name, default sandbox) starting at
/// joint angles q0 [rad] and slew angle slew0 [rad]; m3 [kg] is the tip load
/// of the validation world (the sandbox picks loads up with the hook).
live* live_create_ode(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                      size_t errsz);
/// live_create_ode or live_create_lagrange, as o->mechanics says (slew0 is
/// used by the ode world only).
live* live_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3, char* err,
                  size_t errsz);
/// Hook: 1 attach the nearest load in reach, 0 release (ode sandbox only).
/// Returns the load index attached, or -1.
int live_hook(live* l, int attach);
/// Name and mass [kg] of load i of the world, or NULL.
const char* live_load_name(const live* l, int i, double* mass);
/// True while a load hangs on the hook.
bool live_attached(const live* l);
/// The circuit the running simulation uses (the model's for lagrange, the
/// world's own copy for ode): hyd_model_set on it takes effect at the next step.
hyd_model* live_circuit(live* l);
/// Set the tip load [kg] (lagrange; takes effect at the next step).
void live_set_load(live* l, double m3);
/// Boom k (0 lifting arm, 1 end arm) now has link ln (mass, com, inertia,
/// length), applied in place at the next step where the backend can: the
/// lagrange crane always (its constants are recomputed; ln is the model's
/// link it reads), the ode world for a new mass and inertia about the same
/// centre of mass (dBodySetMass). Returns 0 when applied, 1 when the world
/// must be rebuilt for it (a new length, or a centre of mass that moves).
int live_set_link(live* l, int k, const crane_link* ln);

/// Columns live_row fills (base, or base plus world extras for ode).
int live_ncol(const live* l);
void live_destroy(live* l);

/// Valve commands lift, jib, slew in [-1, 1] (slew ignored by lagrange).
void live_set_commands(live* l, const double u[3]);

/// Advance dt [s] of simulated time, then apply the run checks of sim.h
/// (sim_check_row) to the state reached. Returns 0, or 1 on a numerical
/// failure or a failed check (message from live_error); then the crane stays
/// stopped and every further call returns 1.
int live_advance(live* l, double dt);
/// The note for a dip below absolute zero the checks saw (sim_checks_note),
/// or "".
void live_note(const live* l, char* note, size_t n);
const char* live_error(const live* l);

double live_time(const live* l);
/// The CSV row at the current time (sim.h columns).
void live_row(live* l, double row[SIM_NCOL]);
/// Fill a snapshot for the renderer.
void live_snapshot(live* l, world_snapshot* s);

#ifdef __cplusplus
}
#endif
#endif
