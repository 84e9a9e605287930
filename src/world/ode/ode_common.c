// ode_common.c: what every ODE world of the process shares (ode_common.h):
// ODE's initialisation, its message and error handlers, the trap that turns
// an ODE error into a failed call, a new world with its own step threading.
// Used by the two-link and sandbox world (ode_world.c) and the chain world
// (ode_chain.c), which may be hosted in it.
#include "ode_common.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

// ODE keeps global tables (collider registry, thread-local data); it must be
// initialised once before the first world and closed after the last. A
// counter lets several worlds coexist (tests, compare runs). This is the one
// piece of global mutable state the project allows; worlds must be created
// and destroyed from one thread.
// The ODE library's state: its users, and the non-fatal messages it sends
// (dMessage: "LCP internal error, s <= 0" on a degenerate contact set),
// which it would print to stderr itself, outside our one-line messages and
// unrelated to the run. They are counted here and reported by the caller
// (ode_world_messages).
// ODE's errors and failed internal checks (dError, dDebug: an assertion such
// as "!bSafeNormalize4Fault" in dxNormalize4 on a quaternion that a 1e-300 kg
// link or a 1e308 kg truck has turned into NaN) call abort() by default, and
// their handler must not return. Every entry point that runs ODE code arms a
// trap (ow_trapped); the handler jumps back to it, the world is marked dead
// and from then on only destroyed. The caller sees an ordinary runtime
// failure (exit 1, rows kept) instead of SIGABRT.
static struct {
    int users;
    long messages;
    char last[160];
    jmp_buf* trap; ///< the armed entry point, or NULL
    char fatal[200]; ///< text of the last ODE error
} g_ode;

static void ode_message(int num, const char* msg, va_list ap) {
    (void)num;
    vsnprintf(g_ode.last, sizeof g_ode.last, msg, ap);
    g_ode.messages++;
}

static void ode_fatal(int num, const char* msg, va_list ap) {
    (void)num;
    vsnprintf(g_ode.fatal, sizeof g_ode.fatal, msg, ap);
    if (g_ode.trap) longjmp(*g_ode.trap, 1);
    // No world call is running (cannot happen through this module's API):
    // nothing to return to. exit, not abort, so the rows already written are
    // flushed.
    fprintf(stderr, "cranesim: ODE error outside a world call: %s\n", g_ode.fatal);
    exit(1);
}

void ow_ode_acquire(void) {
    if (g_ode.users++ == 0) {
        dInitODE2(0);
        dSetMessageHandler(ode_message);
        dSetErrorHandler(ode_fatal);
        dSetDebugHandler(ode_fatal);
    }
}

void ow_ode_release(void) {
    if (--g_ode.users == 0) dCloseODE();
}

int ow_ode_call(int (*fn)(void* arg), void* arg, char* fatal, size_t n) {
    jmp_buf jb;
    jmp_buf* const prev = g_ode.trap;
    if (setjmp(jb)) {
        g_ode.trap = prev;
        snprintf(fatal, n, "%s", g_ode.fatal);
        return OW_ODE_FAILED;
    }
    g_ode.trap = &jb;
    const int rc = fn(arg);
    g_ode.trap = prev;
    return rc;
}

long ow_ode_messages(const char** last) {
    if (last) *last = g_ode.last;
    return g_ode.messages;
}

dWorldID ow_world_new(double g, double erp, double cfm, dThreadingImplementationID* threading) {
    dWorldID world = dWorldCreate();
    // Each world queues its step jobs on its own self-threaded implementation,
    // not on ODE's process-wide default: an ODE error jumps out of a step
    // with jobs still queued (ow_trapped), and on the shared one those would
    // be run by the next world's step and fail ODE's check at dCloseODE.
    *threading = dThreadingAllocateSelfThreadedImplementation();
    if (*threading)
        dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(*threading), *threading);
    dWorldSetGravity(world, 0, 0, -g);
    dWorldSetERP(world, erp);
    dWorldSetCFM(world, cfm);
    return world;
}
