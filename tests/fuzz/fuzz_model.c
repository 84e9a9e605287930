// fuzz_model.c: libFuzzer target for the model loader (mechanics and circuit).
#include "fuzz_common.h"
#include "model.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    cJSON* root = fuzz_parse(data, size);
    if (!root) return 0;
    char err[1024];
    model* m = model_from_json(root, "fuzz.json", err, sizeof err); // owns root, also on failure
    model_free(m);
    return 0;
}
