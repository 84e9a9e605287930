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

// A fragment appended to a circuit (a world's extra circuit on a model's):
// one circuit, errors in the fragment named by its own file and index.
static void quiet(const char* line, void* user) { (void)line, (void)user; }

static void test_extra_fragment(void) {
    const char* base = "{\"nodes\": [{\"name\": \"tank\", \"type\": \"tank\"},"
                       " {\"name\": \"line\", \"type\": \"volume\", \"volume\": 1e-3}],"
                       " \"components\": [{\"name\": \"pump\", \"type\": \"pump\", \"inlet\": \"tank\","
                       " \"outlet\": \"line\", \"q_max\": 1e-4, \"p_set\": 1e7}]}";
    const char* good = "{\"components\": [{\"name\": \"bleed\", \"type\": \"orifice\", \"inlet\": \"line\","
                       " \"outlet\": \"tank\", \"area\": 1e-6}]}";
    const char* bad = "{\"nodes\": [], \"components\": [{\"name\": \"bleed\", \"type\": \"orifice\","
                      " \"inlet\": \"line\", \"outlet\": \"tank\", \"area\": 1e-6},"
                      " {\"name\": \"bleed2\", \"type\": \"orifice\", \"inlet\": \"line\", \"outlet\": \"tank\","
                      " \"area\": -1}]}";
    const char* badkey = "{\"component\": []}";
    cJSON *jb = cJSON_Parse(base), *jg = cJSON_Parse(good), *jx = cJSON_Parse(bad), *jk = cJSON_Parse(badkey);
    char err[256] = "";
    hyd_set_note_handler(quiet, NULL);
    hyd_model* m = hyd_model_from_json_extra(jb, "model.json", "hydraulics", jg, "world.json", "circuit", err,
                                             sizeof err);
    CHECK(m != NULL, "%s", err);
    CHECK(m && hyd_model_ncomp(m) == 2 && hyd_model_find(m, "bleed") == 1, "fragment not appended");
    hyd_model_free(m);
    m = hyd_model_from_json_extra(jb, "model.json", "hydraulics", jx, "world.json", "circuit", err, sizeof err);
    CHECK(m == NULL && !strcmp(err, "world.json: circuit.components[1].area: must be > 0, got -1"), "%s", err);
    m = hyd_model_from_json_extra(jb, "model.json", "hydraulics", jk, "world.json", "circuit", err, sizeof err);
    CHECK(m == NULL && !strcmp(err, "world.json: circuit.component: unknown field (known: nodes, components)"),
          "%s", err);
    // An error in the base circuit still names the model.
    cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(jb, "components"), 0),
                                     "q_max")->valuedouble = -2;
    m = hyd_model_from_json_extra(jb, "model.json", "hydraulics", jg, "world.json", "circuit", err, sizeof err);
    CHECK(m == NULL && !strcmp(err, "model.json: hydraulics.components[0].q_max: must be > 0, got -2"), "%s", err);
    hyd_set_note_handler(NULL, NULL);
    cJSON_Delete(jb), cJSON_Delete(jg), cJSON_Delete(jx), cJSON_Delete(jk);
}

int main(int argc, char** argv) {
    RUN_TEST(test_valid_files);
    RUN_TEST(test_malformed_files);
    RUN_TEST(test_from_parsed_object);
    RUN_TEST(test_extra_fragment);
    TEST_MAIN_END();
}
