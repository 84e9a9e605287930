// test_collisions.c: the collision metric (metrics.h MET_COLLISIONS). The
// sandbox_wall scenario slews the end arm into the radial wall: at least one
// collision, a pair naming the wall and a crane body. The pick-and-place
// hooks a load, lifts it over the truck and sets it down again: the hook on
// its load and the load on the ground are no collisions, and nothing of the
// crane touches anything, so 0. The validation world has no contacts: the
// metric is absent (not 0), in the JSON too. And the event count by hand:
// a touch that breaks for less than SIM_COLL_GAP is the same collision.
#include "check.h"
#include "crane_fixture.h"
#include "metrics.h"
#include "sim.h"

#include <stdlib.h>
#include <string.h>

static void run_metrics_of(const char* scen, const char* world, run_metrics* met) {
    scenario sc;
    model* m = load_crane(scen, &sc);
    memset(met, 0, sizeof *met);
    if (!m) return;
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = world;
    metrics_init(met, sim_ncol(&o));
    sim_trace tr = {0};
    sim_result r;
    CHECK(sim_run(m, &sc, &o, NULL, NULL, &tr, NULL, NULL, &r) == 0, "%s: %s", scen, r.message);
    for (int i = 0; i < tr.nrow; ++i) metrics_row(met, tr.v + (size_t)i * SIM_NCOL);
    metrics_finish(met, &r);
    sim_trace_free(&tr);
    model_free(m);
}

// The JSON the run writes (metrics_write_json), malloc'd.
static char* json_of(const run_metrics* met) {
    char* buf = NULL;
    size_t n = 0;
    FILE* f = open_memstream(&buf, &n);
    CHECK(f != NULL, "open_memstream");
    if (!f) return NULL;
    CHECK(metrics_write_json(met, f) == 0, "metrics_write_json");
    fclose(f);
    return buf;
}

static void test_wall(void) {
    run_metrics met;
    run_metrics_of("sandbox_wall", CRANESIM_ASSETS "/worlds/sandbox.json", &met);
    CHECK(met.present[MET_COLLISIONS], "sandbox_wall: collision_count absent");
    CHECK(met.value[MET_COLLISIONS] >= 1, "sandbox_wall: %g collisions, the end arm hits the wall",
          met.value[MET_COLLISIONS]);
    int wall = 0;
    for (int k = 0; k < met.coll.npair; ++k) {
        const char* p = met.coll.pair[k];
        printf("  sandbox_wall: %s at %.3f s\n", p, met.coll.first_t[k]);
        const int crane = !strncmp(p, "boom1 x ", 8) || !strncmp(p, "boom2 x ", 8) || !strncmp(p, "column x ", 9) ||
                          !strncmp(p, "hook x ", 7);
        if (crane && strstr(p, " x wall")) ++wall;
        // The slew starts at 1 s (2 s at half speed); the arm is clear of
        // the wall at the start.
        CHECK(met.coll.first_t[k] > 1.0, "%s first at %g s, before the crane moved", p, met.coll.first_t[k]);
    }
    CHECK(wall >= 1, "sandbox_wall: no pair names the wall and a crane body (%d pairs)", met.coll.npair);
    char* js = json_of(&met);
    CHECK(js && strstr(js, "\"collisions\": {\"value\": ") && strstr(js, "\"collision_pairs\": [") &&
              strstr(js, "{\"bodies\": \"boom2 x wall_slew\", \"first_t\": "),
          "sandbox_wall: the JSON lacks the collisions: %s", js ? js : "");
    free(js);
}

static void test_pick_place(void) {
    run_metrics met;
    run_metrics_of("sandbox_pick_place", CRANESIM_ASSETS "/worlds/sandbox.json", &met);
    CHECK(met.present[MET_COLLISIONS], "sandbox_pick_place: collision_count absent");
    CHECK(met.value[MET_COLLISIONS] == 0 && met.coll.npair == 0, "sandbox_pick_place: %g collisions (first: %s)",
          met.value[MET_COLLISIONS], met.coll.npair ? met.coll.pair[0] : "-");
}

static void test_validation_absent(void) {
    run_metrics met;
    run_metrics_of("ramp", CRANESIM_ASSETS "/worlds/validation.json", &met);
    CHECK(met.rows > 0, "ramp: no rows");
    CHECK(!met.present[MET_COLLISIONS], "validation world: collision_count present (%g)", met.value[MET_COLLISIONS]);
    char* js = json_of(&met);
    CHECK(js && !strstr(js, "collision"), "validation world: the JSON names collisions: %s", js ? js : "");
    free(js);
}

static void test_events_by_hand(void) {
    sim_collisions c;
    memset(&c, 0, sizeof c);
    const char* const touch[2][2] = {{"boom2", "wall"}, {"hook", "truck"}};
    // boom2 x wall touches 0.010-0.020 s, breaks 0.05 s (< SIM_COLL_GAP),
    // touches again 0.070-0.080 s (the same collision), breaks 0.2 s and
    // touches at 0.280 s (a second). hook x truck once at 0.5 s. Steps of 1 ms.
    for (int i = 0; i <= 600; ++i) {
        const double t = i * 1e-3;
        const int on = (i >= 10 && i <= 20) || (i >= 70 && i <= 80) || i == 280;
        sim_collisions_step(&c, t, on ? touch : NULL, on);
        if (i == 500) sim_collisions_step(&c, t, touch + 1, 1);
    }
    CHECK(c.have, "no collisions recorded");
    CHECK(c.count == 3, "%ld events, 3 by hand", c.count);
    CHECK(c.npair == 2 && !strcmp(c.pair[0], "boom2 x wall") && !strcmp(c.pair[1], "hook x truck"),
          "pairs %d: %s, %s", c.npair, c.pair[0], c.npair > 1 ? c.pair[1] : "-");
    CHECK(c.npair == 2 && c.first_t[0] == 10e-3 && c.first_t[1] == 0.5, "first times %g, %g s", c.first_t[0],
          c.first_t[1]);
}

int main(void) {
    test_events_by_hand();
    test_wall();
    test_pick_place();
    test_validation_absent();
    printf("%d checks, %d failed\n", check_count_, check_failures_);
    return check_failures_ != 0;
}
