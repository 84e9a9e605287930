// test_panel.c: the parameter panel's C API: set by label with range checks,
// changed flags, callbacks, ambiguity, actions.
#include "check.h"
#include "panel.h"

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
    panel_param_def d1 = {"bore", "lift cylinder", "m", &bore, 0.05, 0.2, 0.005};
    panel_param_def d2 = {"load mass", "scenario", "kg", &mass, 0, 2000, 10};
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
    panel_param_def d = {"bore", "lift cylinder", "m", &bore, 0.05, 0.2, 0.005};
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
    panel_param_def d1 = {"bore", "lift cylinder", "m", &b1, 0.05, 0.2, 0};
    panel_param_def d2 = {"bore", "jib cylinder", "m", &b2, 0.05, 0.2, 0};
    CHECK(panel_add_param(p, &d1) == 0, "first bore");
    CHECK(panel_add_param(p, &d2) == 1, "same label, other group");
    CHECK(panel_add_param(p, &d2) == -1, "duplicate group/label refused");
    panel_param_def bad = {"x", NULL, "", &junk, 1, 0, 0};
    CHECK(panel_add_param(p, &bad) == -1, "min > max refused");
    panel_param_def nullv = {"y", NULL, "", NULL, 0, 1, 0};
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

int main(int argc, char** argv) {
    RUN_TEST(test_set_in_range);
    RUN_TEST(test_reject_out_of_range);
    RUN_TEST(test_groups_and_actions);
    TEST_MAIN_END();
}
