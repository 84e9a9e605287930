// fuzz_world.c: libFuzzer target for the world-file loader (world_desc).
#include "fuzz_common.h"
#include "world_desc.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    cJSON* root = fuzz_parse(data, size);
    if (!root) return 0;
    static world_desc w;
    char err[1024];
    if (world_desc_from_json(root, "fuzz.json", &w, err, sizeof err) == 0) {
        // The terrain function the heightfield is sampled from.
        double h = world_desc_terrain_height(&w, w.truck.position[0], w.truck.position[1]);
        (void)h;
        world_desc_free(&w);
    }
    cJSON_Delete(root);
    return 0;
}
