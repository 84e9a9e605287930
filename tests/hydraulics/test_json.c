// test_json.c: the circuit JSON loader. A valid file loads; each malformed
// fixture in data/ is rejected with ONE line naming the file, the field path
// and the problem.
#include "check.h"
#include "hydraulics.h"

#include <cjson/cJSON.h>
#include <string.h>

typedef struct bad_case {
    const char* file;
    const char* path;    // expected field path in the message
    const char* problem; // expected words of the problem
} bad_case;

static const bad_case cases[] = {
    {"bad_bore.json", "hydraulics.components[2].bore", "must be > 0, got -0.08"},
    {"unknown_type.json", "hydraulics.components[0].type", "unknown component type 'pumpp'"},
    {"unknown_node.json", "hydraulics.components[1].A", "unknown node 'cyl.C'"},
    {"missing_field.json", "hydraulics.components[2].stroke", "missing required field"},
    {"wrong_type.json", "hydraulics.components[2].bore", "must be a number, got string"},
    {"negative_volume.json", "hydraulics.nodes[1].volume", "must be > 0, got -0.001"},
    {"duplicate_name.json", "hydraulics.components[3].name", "duplicate name 'pump'"},
    {"rod_ge_bore.json", "hydraulics.components[2].rod", "must be < bore"},
    {"unknown_key.json", "hydraulics.components[2].borre", "unknown field for cylinder"},
    {"same_port.json", "hydraulics.components[3].outlet", "same node 'line' as inlet"},
    {"missing_nodes.json", "hydraulics.nodes", "missing required array"},
    {"bad_fluid.json", "hydraulics.fluid.density", "must be > 0, got 0"},
    {"name_with_dot.json", "hydraulics.nodes[1].name", "must not contain '.'"},
    {"missing_port.json", "hydraulics.components[0].outlet", "missing required port"},
    {"syntax_error.json", "", "JSON syntax error near line 3"},
};

static void test_valid_files(void) {
    char err[512] = "";
    hyd_model* m = hyd_model_load_json(HYD_TESTDATA "/valid_small.json", err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (m)
        CHECK(hyd_model_nstate(m) == 4, "line.p, valve.spool, cyl.pA, cyl.pB: %d", hyd_model_nstate(m));
    hyd_model_free(m);
    m = hyd_model_load_json(HYD_TESTDATA "/crane_circuit.json", err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (m)
        CHECK(hyd_model_nstate(m) == 11, "crane states %d", hyd_model_nstate(m));
    hyd_model_free(m);
}

static void test_malformed_files(void) {
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char path[512], err[512] = "";
        snprintf(path, sizeof path, "%s/%s", HYD_TESTDATA, cases[i].file);
        hyd_model* m = hyd_model_load_json(path, err, sizeof err);
        CHECK(m == NULL, "%s was accepted", cases[i].file);
        hyd_model_free(m);
        // "<file>: <path>: <problem>", one line.
        char expect[1100];
        if (cases[i].path[0])
            snprintf(expect, sizeof expect, "%s: %s: %s", path, cases[i].path, cases[i].problem);
        else
            snprintf(expect, sizeof expect, "%s: %s", path, cases[i].problem);
        CHECK(strncmp(err, expect, strlen(expect)) == 0, "%s:\n  got      '%s'\n  expected '%s...'",
              cases[i].file, err, expect);
        CHECK(strchr(err, '\n') == NULL, "message is one line: %s", err);
    }
}

// The in-memory API with a caller's prefix and file name.
static void test_from_parsed_object(void) {
    cJSON* root = cJSON_Parse("{\"nodes\": [{\"name\": \"t\", \"type\": \"tank\"}],"
                              " \"components\": [{\"name\": \"o\", \"type\": \"orifice\","
                              " \"inlet\": \"t\", \"outlet\": \"u\", \"area\": 1e-6}]}");
    char err[256];
    hyd_model* m = hyd_model_from_json(root, "model.json", "circuits[2]", err, sizeof err);
    CHECK(m == NULL, "accepted");
    CHECK(!strcmp(err, "model.json: circuits[2].components[0].outlet: unknown node 'u'"), "%s", err);
    cJSON_Delete(root);
    m = hyd_model_from_json(NULL, "model.json", "hydraulics", err, sizeof err);
    CHECK(m == NULL && strstr(err, "model.json: hydraulics: circuit must be an object"), "%s", err);
    m = hyd_model_load_json(HYD_TESTDATA "/does_not_exist.json", err, sizeof err);
    CHECK(m == NULL && strstr(err, "does_not_exist.json: cannot open file"), "%s", err);
}

int main(int argc, char** argv) {
    RUN_TEST(test_valid_files);
    RUN_TEST(test_malformed_files);
    RUN_TEST(test_from_parsed_object);
    TEST_MAIN_END();
}
