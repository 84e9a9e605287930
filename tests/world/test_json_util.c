// test_json_util.c: the strict JSON reader on hostile input: numbers that do
// not fit the integer they become, objects with very many keys, files over
// the size limit.
#include "check.h"
#include "json_util.h"
#include "model.h"
#include "world_desc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* tmpfile_path(const char* name) {
    static char p[512];
    snprintf(p, sizeof p, "%s/%s", CRANESIM_BINARY_DIR, name);
    return p;
}

// A field that cannot be an int must not become one: (int)2e67 is undefined
// behaviour and gave INT_MIN on x86; the getter must hand back the default.
static void test_int_out_of_range(void) {
    const char* vals[] = {"2E67", "-2E67", "1e300", "4294967296", "2147483648"};
    for (int i = 0; i < 5; ++i) {
        char text[64], err[256] = "";
        snprintf(text, sizeof text, "{\"joint\": %s}", vals[i]);
        cJSON* o = cJSON_Parse(text);
        json_ctx c = {.file = "t.json", .err = err, .errsz = sizeof err};
        int v = json_int(&c, o, "a", "joint", true, 7, 0, 1);
        CHECK(c.failed && v == 7, "%s: failed %d, value %d (want the default 7)", vals[i], c.failed, v);
        CHECK(strstr(err, "t.json: a.joint: must be <=") || strstr(err, "t.json: a.joint: must be >="), "%s: %s",
              vals[i], err);
        cJSON_Delete(o);
    }
}

// The world's integer fields through the whole loader: a refused value
// never reaches the description (ode.max_contacts, rope.links, terrain.samples).
static void test_world_ints(void) {
    const char* docs[] = {
        "{\"type\": \"sandbox\", \"ode\": {\"max_contacts\": 1e300}}",
        "{\"type\": \"sandbox\", \"rope\": {\"links\": -1e300}}",
        "{\"type\": \"sandbox\", \"terrain\": {\"samples\": [1e300, 121]}}",
        "{\"type\": \"sandbox\", \"terrain\": {\"samples\": [121, -3e9]}}",
    };
    const char* field[] = {"ode.max_contacts", "rope.links", "terrain.samples", "terrain.samples"};
    for (int i = 0; i < 4; ++i) {
        cJSON* root = cJSON_Parse(docs[i]);
        world_desc w;
        char err[256] = "";
        int rc = world_desc_from_json(root, "w.json", &w, err, sizeof err);
        CHECK(rc == -1 && strstr(err, field[i]), "%s: rc %d: %s", docs[i], rc, err);
        CHECK(w.ode.max_contacts >= 1 && w.ode.max_contacts <= 32 && w.rope.links >= 1 &&
                  w.rope.links <= WORLD_DESC_MAX_ROPE && w.terrain.samples[0] >= 2 && w.terrain.samples[0] <= 1024 &&
                  w.terrain.samples[1] >= 2 && w.terrain.samples[1] <= 1024,
              "%s: out-of-range value stored: contacts %d, links %d, samples %d x %d", docs[i], w.ode.max_contacts,
              w.rope.links, w.terrain.samples[0], w.terrain.samples[1]);
        cJSON_Delete(root);
    }
}

// {"k0": 0, "k1": 1, ..., "k<n-1>": n-1} plus an optional repeat of key
// "k<dup>" at the end (malloc'ed).
static char* many_keys(int n, int dup) {
    size_t cap = (size_t)n * 24 + 64, len = 0;
    char* s = malloc(cap);
    s[len++] = '{';
    for (int i = 0; i < n; ++i) len += (size_t)snprintf(s + len, cap - len, "%s\"k%d\": %d", i ? ", " : "", i, i);
    if (dup >= 0) len += (size_t)snprintf(s + len, cap - len, ", \"k%d\": 0", dup);
    snprintf(s + len, cap - len, "}");
    return s;
}

// 200,000 keys (3.4 MB of text, so in memory: a file that large is over the
// limit): the pairwise duplicate search took minutes on such objects.
// ctest's TIMEOUT on this test guards against a hang; nothing is timed.
static void test_many_keys(void) {
    char err[512] = "";
    char* text = many_keys(200000, -1);
    cJSON* root = json_parse(text, "big.json", err, sizeof err);
    CHECK(root && cJSON_GetArraySize(root) == 200000, "%s", err);
    cJSON_Delete(root);
    free(text);
    // A duplicate at the very end is found, and named.
    text = many_keys(200000, 123456);
    root = json_parse(text, "big.json", err, sizeof err);
    CHECK(!root && strstr(err, "big.json: k123456: given twice (duplicate field)"), "%s", err);
    cJSON_Delete(root);
    free(text);
    // The first duplicate in document order is the one reported, nested too.
    char small[2048] = "{\"a\": {";
    for (int i = 0; i < 40; ++i) snprintf(small + strlen(small), sizeof small - strlen(small), "\"x%d\": 1, ", i);
    strcat(small, "\"x30\": 2, \"x3\": 3}}");
    root = json_parse(small, "n.json", err, sizeof err);
    CHECK(!root && strstr(err, "n.json: a.x3: given twice"), "%s", err);
    cJSON_Delete(root);
}

// Over the limit documented in docs/files.md (1 MiB = 1048576 bytes):
// refused before reading, one line naming the file.
static void test_size_limit(void) {
    const long limit = 1048576;
    const char* p = tmpfile_path("too_large.json");
    FILE* f = fopen(p, "w");
    fputs("{\"name\": \"", f);
    for (long i = 0; i < limit; ++i) fputc('x', f);
    fputs("\"}\n", f);
    fclose(f);
    char err[512] = "";
    cJSON* root = json_load_file(p, err, sizeof err);
    CHECK(!root && strstr(err, "too_large.json: too large (") && !strchr(err, '\n'), "%s", err);
    cJSON_Delete(root);
    // Just under the limit loads.
    f = fopen(p, "w");
    fputs("{\"name\": \"", f);
    for (long i = 0; i < limit - 64; ++i) fputc('x', f);
    fputs("\"}\n", f);
    fclose(f);
    root = json_load_file(p, err, sizeof err);
    CHECK(root != NULL, "%s", err);
    cJSON_Delete(root);
    remove(p);
}

// Live changes (the drive panel's hyd_model_set) get the hard ranges of the
// parameter tables too, and a refused value changes nothing.
static void test_live_ranges(void) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    int rc = hyd_model_set(m->hyd, "main_relief.p_crack", 22, err, sizeof err);
    CHECK(rc == -1 && strstr(err, "main_relief.p_crack: must be in [1e5, 1e8] Pa, got 22"), "rc %d: %s", rc, err);
    double v = 0;
    CHECK(hyd_model_get(m->hyd, "main_relief.p_crack", &v) == 0 && v == 22e6, "p_crack now %g", v);
    rc = hyd_model_set(m->hyd, "fluid.bulk_modulus", 1e20, err, sizeof err);
    CHECK(rc == -1 && strstr(err, "[1e7, 1e10] Pa"), "rc %d: %s", rc, err);
    CHECK(hyd_model_set(m->hyd, "main_relief.p_crack", 21e6, err, sizeof err) == 0, "%s", err);
    model_free(m);
}

// --set of a field the element's type has but the file leaves at its default
// (the LS pump's band): added and range-checked like a value in the file; a
// field no type has is still refused, and every --set message names the file
// by its base name.
static void test_set_absent_field(void) {
    char err[512];
    const char* ok = "hydraulics.components.pump.band=1e5";
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", &ok, 1, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    double v = 0;
    CHECK(m && hyd_model_get(m->hyd, "pump.band", &v) == 0 && v == 1e5, "pump.band %g", v);
    model_free(m);
    const char* fl = "hydraulics.fluid.re_transition=200";
    m = model_load(CRANESIM_ASSETS "/models/hiab031.json", &fl, 1, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    model_free(m);
    const char* lo = "hydraulics.components.pump.band=1";
    m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", &lo, 1, err, sizeof err);
    CHECK(!m && !strncmp(err, "hiab031_ls.json: hydraulics.components[0].band: must be in [1000, 2e6] Pa, got 1", 80),
          "%s", m ? "accepted" : err);
    model_free(m);
    const char* bad = "hydraulics.components.pump.bnd=1";
    m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", &bad, 1, err, sizeof err);
    CHECK(!m && !strncmp(err, "hiab031_ls.json: ", 17) && strstr(err, "no field 'bnd'"), "%s", m ? "accepted" : err);
    model_free(m);
    const char* word = "hydraulics.components.pump.band=wide";
    m = model_load(CRANESIM_ASSETS "/models/hiab031_ls.json", &word, 1, err, sizeof err);
    CHECK(!m && strstr(err, "must be a number, got 'wide'"), "%s", m ? "accepted" : err);
    model_free(m);
}

// Numbers in messages as a user writes them.
static void test_number_format(void) {
    const double v[] = {22, 0.005, 6000, 86400, 1e5, 2.5e9, 101325, 1e-7, 3.2e-5, -9.81, 1e300, 0};
    const char* want[] = {"22", "0.005", "6000", "86400", "1e5", "2.5e9", "101325", "1e-7", "3.2e-5", "-9.81",
                          "1e300", "0"};
    for (int i = 0; i < 12; ++i) {
        char b[32];
        hyd_fmt_num(b, sizeof b, v[i]);
        CHECK(!strcmp(b, want[i]), "%g -> '%s', want '%s'", v[i], b, want[i]);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_live_ranges);
    RUN_TEST(test_set_absent_field);
    RUN_TEST(test_number_format);
    RUN_TEST(test_int_out_of_range);
    RUN_TEST(test_world_ints);
    RUN_TEST(test_many_keys);
    RUN_TEST(test_size_limit);
    TEST_MAIN_END();
}
