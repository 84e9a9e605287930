// ode_common.h: what every ODE world of the process shares (ode_common.c):
// ODE's process-wide set-up and its error trap, and a new world. Include
// from the ODE worlds' own files (ode_world.c and its parts, ode_chain.c).
#ifndef ODE_COMMON_H
#define ODE_COMMON_H

#include <ode/ode.h>
#include <stddef.h>

/// ODE's process-wide set-up, counted: the first user initialises ODE and
/// installs its message and error handlers, the last one closes it. Every
/// ODE world (ode_world, ode_chain) holds one use while it lives.
void ow_ode_acquire(void);
void ow_ode_release(void);
/// ow_ode_call's result after an ODE error.
enum { OW_ODE_FAILED = -1000 };
/// Runs fn(arg) with ODE's errors caught: fn's result, or OW_ODE_FAILED
/// when ODE failed inside it (its message in fatal). The jump skips the rest
/// of fn: its world must then only be destroyed. Calls nest.
int ow_ode_call(int (*fn)(void* arg), void* arg, char* fatal, size_t n);
/// Non-fatal messages ODE has sent so far in this process, and the last
/// one's text in *last (may be NULL): ode_world_messages.
long ow_ode_messages(const char** last);
/// A new ODE world with gravity g [m/s^2] along -z, ERP and CFM, stepping on
/// a self-threaded implementation of its own (*threading; NULL when none
/// could be made): an ODE error jumps out of a step with jobs still queued,
/// and on ODE's shared default those would reach the next world's step.
dWorldID ow_world_new(double g, double erp, double cfm, dThreadingImplementationID* threading);

#endif
