// world_fixture.h: the shipped crane in an ODE world, for the world tests.
// Each test program sets g_model (the shipped model, loaded in main) and
// then makes worlds from it.
#ifndef CRANESIM_WORLD_FIXTURE_H
#define CRANESIM_WORLD_FIXTURE_H

#include "model.h"
#include "ode_world.h"

#include <stdio.h>

#define PI 3.14159265358979323846

static model* g_model;

static const cJSON* hyd_json(void) { return cJSON_GetObjectItemCaseSensitive(g_model->json, "hydraulics"); }

// An ODE world of mechanics me in world d (NULL: validation); in the
// sandbox at the pick-and-place start pose.
static ode_world* make(const crane_mech* me, const world_desc* d, char* err, size_t errsz) {
    ode_world_opts o = ode_world_default_opts();
    o.model_file = "hiab031.json";
    if (d && d->kind == WORLD_SANDBOX) {
        o.q0[0] = 117.3 * PI / 180, o.q0[1] = -65.8 * PI / 180;
        o.slew0 = -60 * PI / 180;
    }
    return ode_world_create(me, hyd_json(), d, &o, err, errsz);
}

// The shipped sandbox world into d; 0, or -1 after printing why.
static int load_sandbox(world_desc* d) {
    char err[512];
    if (world_desc_load(CRANESIM_ASSETS "/worlds/sandbox.json", d, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    return 0;
}

#endif
