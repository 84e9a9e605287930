// test_hook_release.c: letting go of a load that already rests on something
// (issue 25, item 3). The shipped pick-and-place sets its load on a stack,
// lowers until the rope is slack, waits, and releases: nothing pushes or
// pulls then, so letting go must hand neither the hook nor the booms any
// energy. Invariants, not recorded numbers:
//  - the mechanical energy (kinetic + potential) of the rope and hook does
//    not rise while the crane stands still after the release, nor does that
//    of the column, booms, rope and hook together rise above its peak of the
//    second before (closed valves: crane and oil are a passive system that
//    only rings down). The booms alone may take back what the oil held for
//    the part of the hook's weight the rope carried (1 J with seal friction:
//    the lift cylinder extends 54 um as the hook slides off the rope);
//  - the hook stays below the boom tip it hangs from (every row of the run);
//  - the rope's angle grows by no more than the hook tipping over on what it
//    rests on can make it (its bottom point moves by at most its own length);
//  - no pad's force leaves the band of the second before by more than twice
//    the weight of the hook and rope: moved wholly onto the tip or off it,
//    that weight changes a pad's reaction by at most 0.73 of itself here, by
//    statics (the tip 1.5 m outboard of the right pads' line, 4 m from the
//    left), and a load that comes off an elastic structure at once (the hook
//    sliding off the rope onto the stack) swings its reactions by up to twice
//    their static change (the dynamic factor of a step load, undamped). With
//    the shipped seal friction pad 4 dips 0.55 kN below its band as the hook
//    lands, 1.4 of the 0.40 kN weight; the throw this guards against moved a
//    rear pad by 7 kN;
//  - the run's reported figures: no pad lift-off, the largest sway below 90 deg.
// On the run path `cranesim run --scenario sandbox_pick_place` takes
// (engine_run); the energies on the stepped path (the drivers' engine), whose
// rows are checked to be the run's rows bit for bit, so they are of the same
// motion. Again with seal friction in the boom cylinders: the fix must not
// rely on damping.
#include "check.h"
#include "crane_fixture.h"
#include "engine.h"
#include "metrics.h"
#include "row_store.h"
#include "sim.h"
#include "world_desc.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)

static sim_opts sandbox_opts(void) {
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = CRANESIM_ASSETS "/worlds/sandbox.json";
    return o;
}

static const double* R(const rows* r, int i) { return r->v + (size_t)i * SIM_NCOL; }

// The rope's angle from hanging straight down [rad] and the hook's horizontal
// offset from the tip [m] in row r (as the run's sway metric measures it).
static double rope_angle(const double* r, double* off) {
    *off = hypot(r[COL_HOOK_X] - r[COL_TIP_WX], r[COL_HOOK_Y] - r[COL_TIP_WY]);
    return atan2(*off, r[COL_TIP_WZ] - r[COL_HOOK_Z]);
}

// The scenario's release time [s] and the first time after it that a
// command moves [s]: the crane stands still in between.
static void release_window(const scenario* sc, double* t_rel, double* t_move) {
    *t_rel = NAN;
    for (int i = 0; i < sc->nevent; ++i)
        if (sc->event[i].kind == SCENARIO_RELEASE) *t_rel = sc->event[i].t;
    *t_move = sc->duration;
    for (double t = *t_rel; t < sc->duration; t += 1e-3) {
        int moving = 0;
        for (int k = 0; k < SCENARIO_NCMD; ++k) moving |= scenario_command(sc, k, t) != 0.0;
        if (moving) {
            *t_move = t;
            break;
        }
    }
}

typedef struct window {
    rows r;              // the stepped rows from t_rel - 1 s to t_move
    int i_rel;           // the first of them at or after the release
    double Ec_pre, Ec_post; // the crane's (booms, rope and hook) largest energy before and after the release [J]
    double Eh_rel, Eh_post; // the rope and hook's energy at the release, and its largest after [J]
} window;

// The stepped path (one frame per ODE step, the scenario played at each
// step's midpoint as the run does) from 0 to t_move; the rows and energies of
// the window around the release into *wd.
static bool step_window(const model* m, const scenario* sc, double t_rel, double t_move, window* wd) {
    const sim_opts o = sandbox_opts();
    char err[512];
    engine* e = engine_create(m, &o, sc->q0, sc->slew0, 0, err, sizeof err);
    CHECK(e != NULL, "engine: %s", err);
    if (!e) return false;
    memset(wd, 0, sizeof *wd);
    wd->Ec_pre = wd->Ec_post = wd->Eh_post = -INFINITY;
    wd->Eh_rel = NAN;
    wd->i_rel = -1;
    const double h = o.dt_ode;
    const long n = (long)floor(t_move / h + 0.5);
    int ev = 0;
    bool ok = true;
    for (long i = 0; i < n && ok; ++i) {
        double u[3];
        engine_play(e, sc, engine_time(e) + 0.5 * h, &ev, u, NULL, NULL);
        engine_set_commands(e, u);
        const bool in = (double)(i + 1) * h >= t_rel - 1.0 - 1e-9;
        if (engine_advance_to(e, (double)(i + 1) * h, in ? keep_row : NULL, &wd->r)) {
            CHECK(0, "step %ld: %s", i, engine_error(e));
            ok = false;
        }
        if (!in) continue;
        double E[2];
        CHECK(engine_part_energy(e, E), "the ode world weighs its bodies");
        const double t = engine_time(e);
        if (t < t_rel - 1e-9) {
            wd->Ec_pre = fmax(wd->Ec_pre, E[0] + E[1]);
            wd->Eh_rel = E[1]; // the last before the release
        } else {
            if (wd->i_rel < 0) wd->i_rel = wd->r.n - 1;
            wd->Ec_post = fmax(wd->Ec_post, E[0] + E[1]);
            wd->Eh_post = fmax(wd->Eh_post, E[1]);
        }
    }
    engine_destroy(e);
    return ok && wd->i_rel > 0;
}

// The invariants of the window (see the top of the file).
static void check_window(const window* wd, const world_desc* d, const char* what) {
    const rows* r = &wd->r;
    const int b = wd->i_rel;
    printf("  %s: rope and hook %+.3f J after the release; with the booms %+.3f J over their peak before\n", what,
           wd->Eh_post - wd->Eh_rel, wd->Ec_post - wd->Ec_pre);
    // 1 J is the hook (40 kg) 2.5 mm higher: what ODE's joint correction
    // moves a body by; a throw is hundreds of joules.
    CHECK(wd->Eh_post <= wd->Eh_rel + 1.0, "%s: the release gave the rope and hook %.1f J", what,
          wd->Eh_post - wd->Eh_rel);
    CHECK(wd->Ec_post <= wd->Ec_pre + 1.0, "%s: the booms, rope and hook rang up by %.1f J after the release",
          what, wd->Ec_post - wd->Ec_pre);
    // The rope's angle.
    double a_pre = 0, off_pre = 0, drop_pre = INFINITY, a_post = 0;
    for (int i = 0; i < r->n; ++i) {
        double off;
        const double a = rope_angle(R(r, i), &off);
        if (i < b) {
            a_pre = fmax(a_pre, a), off_pre = fmax(off_pre, off);
            drop_pre = fmin(drop_pre, R(r, i)[COL_TIP_WZ] - R(r, i)[COL_HOOK_Z]);
        } else {
            a_post = fmax(a_post, a);
        }
    }
    const double a_max = atan2(off_pre + d->hook.size[2], drop_pre);
    printf("  %s: rope %.1f deg before, %.1f deg after the release (%.1f deg if the hook tipped over)\n", what,
           a_pre / DEG, a_post / DEG, a_max / DEG);
    CHECK(a_post <= a_max, "%s: the rope swung to %.1f deg after the release (before %.1f deg)", what, a_post / DEG,
          a_pre / DEG);
    // The pads.
    const double W = 9.81 * (d->hook.mass + d->rope.mass_per_m * d->rope.length);
    for (int p = 0; p < 4; ++p) {
        double lo0 = INFINITY, hi0 = -INFINITY, lo1 = INFINITY, hi1 = -INFINITY;
        for (int i = 0; i < r->n; ++i) {
            const double f = R(r, i)[COL_PAD_F1 + p];
            if (i < b) lo0 = fmin(lo0, f), hi0 = fmax(hi0, f);
            else lo1 = fmin(lo1, f), hi1 = fmax(hi1, f);
        }
        CHECK(lo1 >= lo0 - 2 * W && hi1 <= hi0 + 2 * W,
              "%s: pad %d carried %.2f..%.2f kN after the release, %.2f..%.2f kN before (allowed +-%.2f kN)", what,
              p + 1, lo1 * 1e-3, hi1 * 1e-3, lo0 * 1e-3, hi0 * 1e-3, 2 * W * 1e-3);
    }
}

static void test_release_on_stack(void) {
    scenario sc;
    model* m = load_crane("sandbox_pick_place", &sc);
    if (!m) return;
    world_desc d;
    char err[512];
    const int dl = world_desc_load(CRANESIM_ASSETS "/worlds/sandbox.json", &d, err, sizeof err);
    CHECK(dl == 0, "%s", err);
    double t_rel, t_move;
    release_window(&sc, &t_rel, &t_move);
    CHECK(isfinite(t_rel) && t_move > t_rel + 0.5, "release at %g s, the crane still until %g s", t_rel, t_move);

    // The run, as `cranesim run --scenario sandbox_pick_place` makes it.
    const sim_opts o = sandbox_opts();
    rows run = {0};
    engine_sink k = {.row = keep_row, .user = &run, .rows = true, .summary = true, .t_end = sc.duration};
    sim_result res;
    memset(&res, 0, sizeof res);
    CHECK(engine_run(m, &sc, &o, &k, &res) == 0, "run: %s", res.message);
    run_metrics met;
    metrics_init(&met, SIM_NCOL);
    int above = 0;
    for (int i = 0; i < run.n; ++i) {
        metrics_row(&met, R(&run, i));
        if (R(&run, i)[COL_HOOK_Z] >= R(&run, i)[COL_TIP_WZ] && !above++)
            CHECK(0, "t = %.3f s: the hook %.3f m above the boom tip", R(&run, i)[COL_T],
                  R(&run, i)[COL_HOOK_Z] - R(&run, i)[COL_TIP_WZ]);
    }
    metrics_finish(&met, &res);
    printf("  run: max hook sway %.2f deg, min pad force %.2f kN, pad lift-offs %.0f\n", met.value[MET_MAX_SWAY] / DEG,
           met.value[MET_MIN_PAD_F] * 1e-3, met.value[MET_PAD_LIFTOFFS]);
    CHECK(met.value[MET_PAD_LIFTOFFS] == 0, "the run reports %.0f pad lift-offs", met.value[MET_PAD_LIFTOFFS]);
    CHECK(met.value[MET_MAX_SWAY] < 90 * DEG, "the run reports a %.1f deg sway", met.value[MET_MAX_SWAY] / DEG);

    // The stepped path: the same rows, and the bodies' energies.
    window wd;
    if (!dl && step_window(m, &sc, t_rel, t_move, &wd)) {
        int first = -1, differ = 0;
        for (int i = 0; i < run.n; ++i)
            if (fabs(R(&run, i)[COL_T] - R(&wd.r, 0)[COL_T]) < 1e-9) first = i;
        CHECK(first >= 0 && first + wd.r.n <= run.n, "the window's rows in the run");
        for (int i = 0; first >= 0 && i < wd.r.n && first + i < run.n; ++i)
            differ += memcmp(R(&wd.r, i), R(&run, first + i), SIM_NCOL * sizeof(double)) != 0;
        CHECK(differ == 0, "%d of %d rows of the stepped path differ from the run's", differ, wd.r.n);
        check_window(&wd, &d, "default crane");
        free(wd.r.v);
    }
    free(run.v);
    model_free(m);

    // With Coulomb seal friction in the boom cylinders (2 kN each).
    static const char* const sets[] = {"hydraulics.components.lift_cyl.coulomb=2000",
                                       "hydraulics.components.jib_cyl.coulomb=2000"};
    m = model_load(CRANESIM_ASSETS "/models/hiab031.json", sets, 2, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (m && !dl && step_window(m, &sc, t_rel, t_move, &wd)) {
        check_window(&wd, &d, "2 kN seal friction");
        free(wd.r.v);
    }
    model_free(m);
    if (!dl) world_desc_free(&d);
}

int main(int argc, char** argv) {
    RUN_TEST(test_release_on_stack);
    TEST_MAIN_END();
}
