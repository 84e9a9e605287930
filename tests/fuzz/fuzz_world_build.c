// fuzz_world_build.c: libFuzzer target that builds the ODE world from a
// fuzzed world file with the shipped crane model, takes a few steps with
// the valves open and destroys it. Anything the loader accepts must build
// and step without an abort (ODE's dDebug on degenerate geometry was the
// finding that led to the value ranges) or undefined behaviour; a runtime
// failure reported by ode_world_step is a correct answer.
#include "fuzz_common.h"
#include "model.h"
#include "ode_world.h"
#include "world_desc.h"

#include <stdio.h>

static model* g_model;

int LLVMFuzzerInitialize(int* argc, char*** argv) {
    (void)argc;
    (void)argv;
    hyd_set_note_handler(fuzz_silent_note, NULL);
    char err[1024];
    g_model = model_load(NULL, NULL, 0, err, sizeof err);
    if (!g_model) {
        fprintf(stderr, "fuzz_world_build: %s (set CRANESIM_ASSETS)\n", err);
        abort();
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    cJSON* root = fuzz_parse(data, size);
    if (!root) return 0;
    static world_desc d;
    char err[1024];
    int rc = world_desc_from_json(root, "fuzz.json", &d, err, sizeof err);
    cJSON_Delete(root);
    if (rc) return 0;
    ode_world_opts o = ode_world_default_opts();
    o.model_file = "hiab031.json";
    ode_world* w = ode_world_create(&g_model->mech, cJSON_GetObjectItemCaseSensitive(g_model->json, "hydraulics"), &d,
                                    &o, err, sizeof err);
    if (w) {
        const double u[ODE_NACT] = {0.5, -0.5, 0.5};
        ode_world_set_commands(w, u);
        ode_world_hook(w, 1);
        for (int i = 0; i < 5 && ode_world_step(w, o.dt_ode) == 0; ++i) {
        }
        ode_world_destroy(w);
    }
    world_desc_free(&d);
    return 0;
}
