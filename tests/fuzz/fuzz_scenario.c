// fuzz_scenario.c: libFuzzer target for the scenario loader, and the command
// tables it accepts (interpolation, breakpoints).
#include "fuzz_common.h"
#include "scenario.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    cJSON* root = fuzz_parse(data, size);
    if (!root) return 0;
    static scenario s;
    char err[1024];
    if (scenario_from_json(root, "fuzz.json", &s, err, sizeof err) == 0) {
        double bp[3 * SCENARIO_MAX_POINTS + SCENARIO_MAX_EVENTS];
        int n = scenario_breakpoints(&s, bp, (int)(sizeof bp / sizeof bp[0]));
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < SCENARIO_NCMD; ++k) {
                double u = scenario_command(&s, k, bp[i]) + scenario_command_rate(&s, k, bp[i]);
                (void)u;
            }
    }
    cJSON_Delete(root);
    return 0;
}
