// test_model_controls.c: the model's "controls" section in the core (no SDL,
// so it runs in a CRANESIM_CORE_ONLY build too): parsed into plain names,
// the names checked against the lists and the model's functions, bad ones
// refused with one line naming the file, the field and the problem.
#include <stdlib.h>

#include "check.h"
#include "model.h"

#define MODEL6 CRANESIM_TESTDATA "/chain_6fn_controls.json"

static void test_section_parsed(void) {
    char err[400] = "";
    model* m = model_load(MODEL6, NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    CHECK(m->controls != NULL && m->controls->nfn == 1, "one entry");
    const controls_fn* f = controls_find(m->controls, "ext2");
    CHECK(f && f->has_controller && f->ncontroller == 2 && !strcmp(f->controller[0], "dpup") &&
              !strcmp(f->controller[1], "dpdown"),
          "ext2 on the d-pad");
    CHECK(f && f->has_keys && !strcmp(f->key[0], "Y") && !strcmp(f->key[1], "N"), "keys Y / N");
    CHECK(f && f->has_joystick_buttons && f->joystick_button[0] == 5 && f->joystick_button[1] == 4,
          "raw 5 / 4");
    CHECK(f && !f->has_joystick && !f->has_invert && isnan(f->dead_zone), "the rest not given");
    model_free(m);
    // A model without the section has none.
    m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    CHECK(m && m->controls == NULL, "hiab031: no controls");
    model_free(m);
}

// The section of MODEL6 replaced by --set (json_set_path edits a field the
// file has): each bad value refused with its field.
static void test_bad_values_refused(void) {
    static const char* const bad[][2] = {
        {"controls.axes.ext2.controller[0]=leftstick_y",
         "controls.axes.ext2.controller[0]: unknown game controller"},
        {"controls.axes.ext2.keys[0]=Return", "key \"Return\" is the window's (hook)"},
        {"controls.axes.ext2.keys[1]=Y", "controls.axes.ext2.keys: the same key for + and -"},
        {"controls.axes.ext2.joystick_buttons[0]=300",
         "controls.axes.ext2.joystick_buttons: must be a joystick button index 0..255"},
    };
    char err[400];
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        err[0] = '\0';
        const char* sets[1] = {bad[i][0]};
        model* m = model_load(MODEL6, sets, 1, err, sizeof err);
        CHECK(m == NULL, "accepted: %s", bad[i][0]);
        model_free(m);
        CHECK(strstr(err, "chain_6fn_controls.json") && strstr(err, bad[i][1]) &&
                  !strchr(err, '\n'),
              "%s: %s", bad[i][0], err);
    }
}

// controls_parse on its own: a function no model has is left to the caller
// (controls_check_functions), which names the model's functions.
static void test_functions_checked(void) {
    cJSON* o = cJSON_Parse("{\"axes\": {\"winch\": {\"keys\": [\"U\", \"J\"]}}}");
    model_controls c;
    char err[400] = "";
    CHECK(controls_parse(o, "f.json", "controls", &c, err, sizeof err) == 0, "%s", err);
    static const char* const names[3] = {"lift", "jib", "slew"};
    CHECK(controls_check_functions(&c, names, 3, "f.json", "controls", err, sizeof err) == -1 &&
              !strcmp(err, "f.json: controls.axes.winch: no function 'winch' in the model "
                           "(functions: lift, jib, slew)"),
          "%s", err);
    cJSON_Delete(o);
    o = cJSON_Parse("{\"layout\": \"four-lever\", \"keyboard_ramp_s\": 11}");
    CHECK(controls_parse(o, "f.json", "", &c, err, sizeof err) == -1 &&
              !strcmp(err, "f.json: keyboard_ramp_s: must be a number in [0, 10]"),
          "%s", err);
    cJSON_Delete(o);
}

int main(int argc, char** argv) {
    RUN_TEST(test_section_parsed);
    RUN_TEST(test_bad_values_refused);
    RUN_TEST(test_functions_checked);
    TEST_MAIN_END();
}
