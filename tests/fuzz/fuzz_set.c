// fuzz_set.c: libFuzzer target for --set: the input is one "PATH=VALUE"
// assignment applied (json_set_path) to the shipped model, which is then
// loaded. Any assignment must end in the model or in a one-line refusal.
#include "fuzz_common.h"
#include "model.h"

#include <stdio.h>

static cJSON* g_doc;

int LLVMFuzzerInitialize(int* argc, char*** argv) {
    (void)argc;
    (void)argv;
    hyd_set_note_handler(fuzz_silent_note, NULL);
    char err[1024];
    g_doc = json_load_file(model_default_path(), err, sizeof err);
    if (!g_doc) {
        fprintf(stderr, "fuzz_set: %s (set CRANESIM_ASSETS)\n", err);
        abort();
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 4096) return 0; // a command-line argument, not a file
    char arg[4097];
    memcpy(arg, data, size);
    arg[size] = 0;
    cJSON* doc = cJSON_Duplicate(g_doc, 1);
    char err[1024];
    if (doc && json_set_path(doc, arg, err, sizeof err) == 0) {
        model* m = model_from_json(doc, "hiab031.json", err, sizeof err); // owns doc
        model_free(m);
    } else {
        cJSON_Delete(doc);
    }
    return 0;
}
