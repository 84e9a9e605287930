// test_panel.c: the parameter panel's C API: set by label with range checks,
// changed flags, callbacks, ambiguity, actions.
#include "check.h"
#include "panel.h"

#include <string.h>

typedef struct seen {
    int calls, last_id;
    double last_value;
} seen;

static void on_change(void* user, int id, const char* label, double value) {
    seen* s = user;
    (void)label;
    ++s->calls;
    s->last_id = id;
    s->last_value = value;
}

static void count_action(void* user) {
    ++*(int*)user;
}

static void test_set_in_range(void) {
    panel* p = panel_create();
    double bore = 0.1, mass = 500;
    panel_param_def d1 = {"bore", "lift cylinder", "m", &bore, 0.05, 0.2, 0.005, false};
    panel_param_def d2 = {"load mass", "scenario", "kg", &mass, 0, 2000, 10, false};
    int id1 = panel_add_param(p, &d1), id2 = panel_add_param(p, &d2);
    CHECK(id1 == 0 && id2 == 1, "ids %d %d", id1, id2);
    seen s = {0, -1, 0};
    panel_on_change(p, on_change, &s);
    char msg[256] = "x";
    CHECK(panel_set(p, "bore", 0.12, msg, sizeof msg) == PANEL_OK, "set bore: %s", msg);
    CHECK_NEAR(bore, 0.12, 0);
    CHECK(msg[0] == '\0', "no message on success: %s", msg);
    CHECK(s.calls == 1 && s.last_id == id1, "callback calls %d id %d", s.calls, s.last_id);
    CHECK_NEAR(s.last_value, 0.12, 0);
    CHECK(panel_take_changed(p, id1), "changed flag raised");
    CHECK(!panel_take_changed(p, id1), "changed flag cleared after take");
    CHECK(!panel_take_changed(p, id2), "other flag untouched");
    // Limits are inclusive.
    CHECK(panel_set(p, "scenario/load mass", 2000, NULL, 0) == PANEL_OK, "max is allowed");
    CHECK_NEAR(mass, 2000, 0);
    CHECK(panel_next_changed(p) == id2, "next changed is the mass");
    CHECK(panel_next_changed(p) == -1, "no more changes");
    // Setting the same value again is not a change.
    CHECK(panel_set(p, "bore", 0.12, NULL, 0) == PANEL_OK, "same value ok");
    CHECK(!panel_take_changed(p, id1), "same value raises no flag");
    CHECK_NEAR(panel_get(p, id1), 0.12, 0);
    panel_destroy(p);
}

static void test_reject_out_of_range(void) {
    panel* p = panel_create();
    double bore = 0.1;
    panel_param_def d = {"bore", "lift cylinder", "m", &bore, 0.05, 0.2, 0.005, false};
    int id = panel_add_param(p, &d);
    seen s = {0, -1, 0};
    panel_on_change(p, on_change, &s);
    char msg[256] = "";
    CHECK(panel_set(p, "bore", 0.5, msg, sizeof msg) == PANEL_OUT_OF_RANGE, "0.5 m rejected");
    CHECK_NEAR(bore, 0.1, 0);
    CHECK(strstr(msg, "bore") && strstr(msg, "outside") && strstr(msg, "0.2"), "message: %s", msg);
    CHECK(strcmp(panel_last_error(p), msg) == 0, "last error kept for the GUI: %s",
          panel_last_error(p));
    CHECK(!panel_take_changed(p, id), "no change flag on rejection");
    CHECK(s.calls == 0, "no callback on rejection");
    CHECK(panel_set(p, "bore", -1, msg, sizeof msg) == PANEL_OUT_OF_RANGE, "negative rejected");
    CHECK(panel_set(p, "bore", NAN, msg, sizeof msg) == PANEL_NOT_FINITE, "NaN rejected: %s", msg);
    CHECK_NEAR(bore, 0.1, 0);
    CHECK(panel_set(p, "stroke", 0.1, msg, sizeof msg) == PANEL_NOT_FOUND, "unknown label");
    CHECK(strstr(msg, "stroke") != NULL, "message names the label: %s", msg);
    panel_destroy(p);
}

static void test_groups_and_actions(void) {
    panel* p = panel_create();
    double b1 = 0.1, b2 = 0.08, junk = 0;
    panel_param_def d1 = {"bore", "lift cylinder", "m", &b1, 0.05, 0.2, 0, false};
    panel_param_def d2 = {"bore", "jib cylinder", "m", &b2, 0.05, 0.2, 0, false};
    CHECK(panel_add_param(p, &d1) == 0, "first bore");
    CHECK(panel_add_param(p, &d2) == 1, "same label, other group");
    CHECK(panel_add_param(p, &d2) == -1, "duplicate group/label refused");
    panel_param_def bad = {"x", NULL, "", &junk, 1, 0, 0, false};
    CHECK(panel_add_param(p, &bad) == -1, "min > max refused");
    panel_param_def nullv = {"y", NULL, "", NULL, 0, 1, 0, false};
    CHECK(panel_add_param(p, &nullv) == -1, "no value pointer refused");
    CHECK(panel_set(p, "bore", 0.1, NULL, 0) == PANEL_AMBIGUOUS, "bare label is ambiguous");
    CHECK(panel_set(p, "jib cylinder/bore", 0.09, NULL, 0) == PANEL_OK, "group/label");
    CHECK_NEAR(b2, 0.09, 0);
    CHECK_NEAR(b1, 0.1, 0);
    double mn = 0, mx = 0, st = 0;
    panel_range(p, 0, &mn, &mx, &st);
    CHECK_NEAR(st, 0.0015, 1e-12); // default step = range / 100
    int runs = 0;
    CHECK(panel_add_action(p, "reset run", count_action, &runs) == 0, "action id");
    CHECK(panel_run_action(p, "reset run") && runs == 1, "action ran %d", runs);
    CHECK(!panel_run_action(p, "save model"), "unknown action");
    CHECK(panel_count(p) == 2 && panel_action_count(p) == 1, "counts");
    panel_destroy(p);
}

// Drag steps follow the value (0.5 % per pixel), not the range: a 20..2000
// kg mass at 180 kg moves 0.9 kg per pixel (a 200 px slider over the range
// moved 10 kg); at 0 a value still moves by a small part of its range.
static void test_drag_speed_is_relative(void) {
    panel* p = panel_create();
    double mass = 180, fric = 0;
    panel_param_def d1 = {"mass", "booms", "kg", &mass, 20, 2000, 0, false};
    panel_param_def d2 = {"friction", "cyl", "kN s/m", &fric, 0, 100, 0, false};
    int im = panel_add_param(p, &d1), jf = panel_add_param(p, &d2);
    CHECK_NEAR(panel_drag_speed(p, im), 0.9, 1e-12);
    mass = 1800;
    CHECK_NEAR(panel_drag_speed(p, im), 9.0, 1e-12);
    CHECK(panel_drag_speed(p, jf) > 0 && panel_drag_speed(p, jf) <= 0.01, "friction at 0: %g per px",
          panel_drag_speed(p, jf));
    panel_destroy(p);
}

// An on-release parameter holds a drag's values as pending and reaches the
// app once, when the edit ends; a live one at every step.
static void test_on_release_applies_once(void) {
    panel* p = panel_create();
    double len = 2.3, bore = 0.1;
    panel_param_def d1 = {"length", "booms", "m", &len, 1, 5, 0, true};
    panel_param_def d2 = {"bore", "cyl", "m", &bore, 0.05, 0.2, 0, false};
    int il = panel_add_param(p, &d1), ib = panel_add_param(p, &d2);
    seen s = {0, -1, 0};
    panel_on_change(p, on_change, &s);
    for (int i = 1; i <= 10; ++i) panel_edit(p, il, 2.3 + 0.01 * i, false);
    double v = 0;
    CHECK(s.calls == 0 && len == 2.3 && panel_pending(p, il, &v) && fabs(v - 2.4) < 1e-12,
          "during the drag: %d calls, value %g, pending %g", s.calls, len, v);
    CHECK(panel_edit(p, il, 2.4, true) == PANEL_OK && s.calls == 1 && len == 2.4 && !panel_pending(p, il, NULL),
          "on release: %d calls, value %g", s.calls, len);
    for (int i = 1; i <= 3; ++i) panel_edit(p, ib, 0.1 + 0.001 * i, false);
    CHECK(s.calls == 4 && fabs(bore - 0.103) < 1e-12, "live: %d calls, bore %g", s.calls, bore);
    CHECK(panel_on_release(p, il) && !panel_on_release(p, ib), "flags");
    panel_destroy(p);
}

// A typed value reaches the app only when the edit is done, for live
// parameters too: Ctrl+click, "9" on the way to "900" set a 150 kg end arm
// to 20 kg (the clamp) while the valves were closed.
static void test_typed_value_applies_on_enter(void) {
    panel* p = panel_create();
    double mass = 150;
    panel_param_def d = {"end arm mass", "booms", "kg", &mass, 20, 5000, 0, false};
    int im = panel_add_param(p, &d);
    seen s = {0, -1, 0};
    panel_on_change(p, on_change, &s);
    panel_edit_typed(p, im, 20, false); // "9", clamped
    panel_edit_typed(p, im, 90, false);
    double v = 0;
    CHECK(s.calls == 0 && mass == 150 && panel_pending(p, im, &v) && v == 90,
          "while typing: %d calls, mass %g, pending %g", s.calls, mass, v);
    CHECK(panel_edit_typed(p, im, 900, true) == PANEL_OK && s.calls == 1 && mass == 900 &&
              !panel_pending(p, im, NULL),
          "on Enter: %d calls, mass %g", s.calls, mass);
    panel_destroy(p);
}

// A choice takes whole option indices only and names its options.
static void test_choice(void) {
    panel* p = panel_create();
    static const char* const opts[] = {"Krus", "ROS2", "RK4"};
    double m = 0;
    int id = panel_add_choice(p, "method", "solver", &m, opts, 3);
    CHECK(id >= 0 && panel_choice_count(p, id) == 3 && !strcmp(panel_choice_label(p, id, 2), "RK4"), "choice");
    char msg[256];
    CHECK(panel_set(p, "method", 1.5, msg, sizeof msg) == PANEL_OUT_OF_RANGE && m == 0, "1.5 accepted: %s", msg);
    CHECK(panel_set(p, "method", 3, msg, sizeof msg) == PANEL_OUT_OF_RANGE, "index 3 accepted");
    CHECK(panel_set(p, "method", 1, msg, sizeof msg) == PANEL_OK && m == 1, "%s", msg);
    panel_destroy(p);
}

int main(int argc, char** argv) {
    RUN_TEST(test_set_in_range);
    RUN_TEST(test_reject_out_of_range);
    RUN_TEST(test_groups_and_actions);
    RUN_TEST(test_drag_speed_is_relative);
    RUN_TEST(test_on_release_applies_once);
    RUN_TEST(test_typed_value_applies_on_enter);
    RUN_TEST(test_choice);
    TEST_MAIN_END();
}
