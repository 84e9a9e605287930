// test_step_probe.c: a run (scripted or stepped: drive, serve, replay)
// refuses a Krus or ROS2 step above 0.1 ms that blows up on the model's
// abrupt valve steps or integrates them far off the 0.1 ms run, before it
// starts, with the reason and the largest step that runs them within the
// limits (sim_check_step_probe; issue 25 item 7: the LS crane blew up at
// Krus 1 ms 3.5 s into `step` and 1.3 s into `ramp`; with a failed step
// retried in shorter ones it runs through instead, 29 % off).
// Both directions, against runs the probe does not see: the operator
// script of drive_demo played through a stepped engine made with the probe
// off, and the shipped `step` scenario (8 s, its own load) compared here
// with its 0.1 ms run. Each accepted configuration runs both through and
// stays within the limits on `step`; each refused one is outside them.
#include "check.h"
#include "crane_fixture.h"
#include "engine.h"
#include "sim.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

// Play scenario sc's lift and jib commands through a stepped engine, 1 ms
// per command update. Returns 0 when it runs through, 1 on a failure (the
// engine's message in msg), -1 when the engine is refused (err in msg).
static int play(const model* m, const scenario* sc, const sim_opts* o, char* msg, size_t msz) {
    engine* e = engine_create(m, o, sc->q0, sc->slew0, sim_load_mass(m, sc, o), msg, msz);
    if (!e) return -1;
    int rc = 0;
    for (int k = 1; k <= (int)lround(sc->duration * 1e3) && !rc; ++k) {
        const double t = 1e-3 * (k - 1);
        const double u[3] = {scenario_command(sc, 0, t), scenario_command(sc, 1, t), 0.0};
        engine_set_commands(e, u);
        rc = engine_advance_to(e, 1e-3 * k, NULL, NULL);
    }
    if (rc) snprintf(msg, msz, "%s", engine_error(e));
    engine_destroy(e);
    return rc ? 1 : 0;
}

// The largest ratio of RMS difference to limit (5 % of peak for strokes,
// 15 % for chamber pressures) of `step` at o's step against the same
// method at 0.1 ms, rows every 1 ms (or every step); a failed run is 1e9.
static double step_off(const model* m, const scenario* sc, const sim_opts* o) {
    sim_opts a = *o, r = *o;
    a.dt_out = o->h > 1e-3 ? o->h : 1e-3;
    r.h = 1e-4, r.dt_out = 1e-3;
    sim_trace ta = {0}, tr = {0};
    sim_result ra, rr;
    const int rca = sim_run(m, sc, &a, NULL, NULL, &ta, NULL, NULL, &ra);
    const int rcr = sim_run(m, sc, &r, NULL, NULL, &tr, NULL, NULL, &rr);
    double worst = rca ? 1e9 : 0.0;
    CHECK(rcr == 0, "the 0.1 ms run: %s", rr.message);
    static const int col[6] = {COL_X1, COL_X2, COL_P1A, COL_P1B, COL_P2A, COL_P2B};
    for (int k = 0; k < 6 && !rca && !rcr; ++k) {
        double ss = 0, peak = 0;
        int n = 0;
        for (int j = 0; j < tr.nrow; ++j) peak = fmax(peak, fabs(tr.v[(size_t)j * SIM_NCOL + col[k]]));
        for (int i = 0; i < ta.nrow; ++i) {
            const double t = ta.v[(size_t)i * SIM_NCOL + COL_T];
            const long j = lround(t * 1e3);
            if (j >= tr.nrow || fabs(tr.v[(size_t)j * SIM_NCOL + COL_T] - t) > 1e-9) continue;
            const double d = ta.v[(size_t)i * SIM_NCOL + col[k]] - tr.v[(size_t)j * SIM_NCOL + col[k]];
            ss += d * d, ++n;
        }
        if (n > 1 && peak > 0) worst = fmax(worst, sqrt(ss / n) / peak / (k < 2 ? 0.05 : 0.15));
    }
    sim_trace_free(&ta);
    sim_trace_free(&tr);
    return worst;
}

static void test_probe_both_directions(void) {
    static const struct {
        const char* model;
        hyd_method solver;
        double h;
        double largest; ///< 0: accepted; else the step the refusal must name [s]
    } cs[] = {
        // The LS crane: Krus rings its spools on `step` from 0.2 ms (25-35 %
        // off); ROS2 stays within the limits up to 1 ms, not at 2 ms.
        {"hiab031_ls.json", HYD_KRUS, 1e-3, 1e-4},
        {"hiab031_ls.json", HYD_KRUS, 5e-4, 1e-4},
        {"hiab031_ls.json", HYD_KRUS, 2e-4, 1e-4},
        {"hiab031_ls.json", HYD_ROS2, 2e-3, 1e-3},
        {"hiab031_ls.json", HYD_ROS2, 1e-3, 0},
        {"hiab031_ls.json", HYD_ROS2, 5e-4, 0},
        {"hiab031_ls.json", HYD_ROS2, 2e-4, 0},
        {"hiab031_ls.json", HYD_KRUS, 1e-4, 0}, // the default step: not probed
        // The standard crane runs its valve steps at 1 ms (the paper's
        // reduced-accuracy setting, with its ~5 % artefact).
        {"hiab031.json", HYD_KRUS, 1e-3, 0},
        {"hiab031.json", HYD_KRUS, 5e-4, 0},
        {"hiab031.json", HYD_ROS2, 1e-3, 0},
    };
    scenario demo, step;
    if (load_scenario("drive_demo", &demo) || load_scenario("step", &step)) return;
    for (size_t i = 0; i < sizeof cs / sizeof cs[0]; ++i) {
        model* m = load_model(cs[i].model);
        if (!m) continue;
        const char* sn = hyd_method_name(cs[i].solver);
        sim_opts o = sim_default_opts();
        o.solver = cs[i].solver;
        o.h = cs[i].h;
        char err[1024], msg[1024];
        engine* e = engine_create(m, &o, demo.q0, demo.slew0, sim_load_mass(m, &demo, &o), err, sizeof err);
        if (cs[i].largest > 0) {
            char want[96];
            snprintf(want, sizeof want, "the largest step that runs them within the limits is %g s", cs[i].largest);
            CHECK(!e && ((strstr(err, "blows up") && strstr(err, "at t = ")) || strstr(err, "is inaccurate")) &&
                      strstr(err, want),
                  "%s %s h = %g: want refused with '%s', got %s", cs[i].model, sn, cs[i].h, want, e ? "accepted" : err);
            if (!e) printf("  %s %s %g ms refused: %s\n", cs[i].model, sn, 1e3 * cs[i].h, err);
        } else {
            CHECK(e != NULL, "%s %s h = %g: refused: %s", cs[i].model, sn, cs[i].h, err);
        }
        engine_destroy(e);
        // The other direction, with the probe off: drive_demo (and `step`
        // where accepted) as an operator would play them.
        o.no_step_probe = true;
        const int rd = play(m, &demo, &o, msg, sizeof msg);
        CHECK(rd >= 0, "%s %s h = %g: engine refused: %s", cs[i].model, sn, cs[i].h, msg);
        if (cs[i].largest == 0) {
            CHECK(rd == 0, "%s %s h = %g accepted, but drive_demo fails: %s", cs[i].model, sn, cs[i].h, msg);
            const int rs = play(m, &step, &o, msg, sizeof msg);
            CHECK(rs == 0, "%s %s h = %g accepted, but step fails: %s", cs[i].model, sn, cs[i].h, msg);
        }
        printf("  %s %s %g ms, drive_demo without the probe: %s\n", cs[i].model, sn, 1e3 * cs[i].h,
               rd == 0 ? "runs through" : msg);
        // Accuracy on the shipped `step` scenario, against its 0.1 ms run,
        // computed here: within the probe's limits where accepted, outside
        // them (or failing) where refused.
        const double off = step_off(m, &step, &o);
        printf("  %s %s %g ms on step: %.1f %% of the limit\n", cs[i].model, sn, 1e3 * cs[i].h, 100 * off);
        if (cs[i].largest == 0)
            CHECK(off <= 1.0, "%s %s h = %g accepted, but `step` is %.0f %% of the limit off", cs[i].model, sn,
                  cs[i].h, 100 * off);
        else
            CHECK(off > 1.0, "%s %s h = %g refused, but `step` is within the limits (%.0f %%)", cs[i].model, sn,
                  cs[i].h, 100 * off);
        model_free(m);
    }
}

// The largest step named is one the output period accepts: the LS crane at
// ROS2 1.5 ms (off the limits) is told 0.5 ms at --every 1.5 ms, where 1 ms,
// within the limits, does not divide the output period; at --every 3 ms it
// is told 1 ms.
static void test_probe_step_divides_output(void) {
    model* m = load_model("hiab031_ls.json");
    scenario sc;
    if (!m || load_scenario("drive_demo", &sc)) {
        model_free(m);
        return;
    }
    const double every[2] = {1.5e-3, 3e-3};
    const char* want[2] = {"is 0.0005 s", "is 0.001 s"};
    for (int k = 0; k < 2; ++k) {
        sim_opts o = sim_default_opts();
        o.solver = HYD_ROS2;
        o.h = 1.5e-3;
        o.dt_out = every[k];
        char err[1024];
        engine* e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
        CHECK(!e && strstr(err, want[k]), "--every %g: want '%s': %s", every[k], want[k], e ? "accepted" : err);
        engine_destroy(e);
    }
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_probe_both_directions);
    RUN_TEST(test_probe_step_divides_output);
    TEST_MAIN_END();
}
