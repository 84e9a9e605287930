// engine_backend.c: the table of backends (engine_backend.h). Each row says
// what a driver needs to know about a backend before it runs one; the
// drivers read these rows instead of testing which backend runs.
#include "engine_backend.h"
#include "engine_impl.h"
#include "engine_lagrange.h"
#include "engine_ode.h"

#include <stdio.h>
#include <string.h>

// The order is the sim_mechanics enum's (engine_backend_by_id checks it):
// the first row is sim_default_opts' backend.
static const engine_backend backends[] = {
    {
        .id = SIM_LAGRANGE,
        .name = "lagrange",
        .help = "analytic 2-DOF",
        .crane = "lagrange 2-DOF",
        .ops = &engine_lagrange_ops,
        .world = false,
        .run_world = NULL,
        .drive_world = NULL,
        // The scripted lift-and-jib demo: no hook, no slew.
        .drive_scenario = "drive_demo",
        // The general formulation slews the column by the model's drive.
        .slew_dof = true,
        .outer_step_opt = NULL,
        .step_name = "step",
        .variant = true,
        .no_cvode = NULL,
        // Its scripted run (lagrange_sim) takes the scenario's commands as
        // they are; the limiter measures rcl_util only.
        .rcl_scripted = false,
        .process_wide = false,
    },
    {
        .id = SIM_ODE,
        .name = "ode",
        .help = "3D rigid bodies in a world",
        .crane = "ode",
        .ops = &engine_ode_ops,
        .world = true,
        .run_world = "validation", // the column and booms alone, as the lagrange crane
        .drive_world = "sandbox",  // the truck, the hook, the loads, the slew
        .drive_scenario = "sandbox_pick_place",
        .slew_dof = false, // it slews in its sandbox world
        .outer_step_opt = "--dt-ode",
        .step_name = "ODE step",
        .variant = false,
        .no_cvode = "the ode world steps its hydraulics inside each ODE step",
        .rcl_scripted = true,
        // The ODE library and the ode world's error trap are global.
        .process_wide = true,
    },
};
#define NBACKEND ((int)(sizeof backends / sizeof backends[0]))

int engine_backend_count(void) { return NBACKEND; }

const engine_backend* engine_backend_at(int i) { return i >= 0 && i < NBACKEND ? &backends[i] : NULL; }

const engine_backend* engine_backend_find(const char* name) {
    for (int i = 0; name && i < NBACKEND; ++i)
        if (!strcmp(backends[i].name, name)) return &backends[i];
    return NULL;
}

const engine_backend* engine_backend_by_id(int id) {
    for (int i = 0; i < NBACKEND; ++i)
        if ((int)backends[i].id == id) return &backends[i];
    return NULL;
}

const engine_backend* engine_backend_of(const sim_opts* o) { return engine_backend_by_id((int)o->mechanics); }

const engine_backend* engine_backend_default(void) {
    const sim_opts o = sim_default_opts();
    return engine_backend_of(&o);
}

const engine_backend* engine_backend_with_world(void) {
    for (int i = 0; i < NBACKEND; ++i)
        if (backends[i].world) return &backends[i];
    return NULL;
}

const char* engine_backend_names(char* buf, size_t n, bool (*filter)(const engine_backend* b)) {
    size_t L = 0;
    if (n) buf[0] = 0;
    for (int i = 0; i < NBACKEND && L < n; ++i) {
        if (filter && !filter(&backends[i])) continue;
        const int k = snprintf(buf + L, n - L, "%s%s", L ? ", " : "", backends[i].name);
        if (k < 0) break;
        L += (size_t)k;
    }
    return buf;
}

int engine_backend_select(sim_opts* o, const char* name, char* err, size_t errsz) {
    const engine_backend* b = engine_backend_find(name);
    if (!b) {
        char known[128];
        snprintf(err, errsz, "unknown backend '%s' (known: %s)", name ? name : "",
                 engine_backend_names(known, sizeof known, NULL));
        return -1;
    }
    o->mechanics = b->id;
    return 0;
}
