// test_plot_channels.c: the run plot draws every function the run has (issue
// 25, item 15: `run --plot` of a sandbox run had no slew channel, though on
// sandbox_wall the slew relief is open 9.1 s). Pure functions, no PLplot: the
// channels of each time panel, and which runs have a slew drive (an ode world
// with a slewing column: the sandbox and the site, not the validation world
// and not the lagrange crane).
#include "app.h"
#include "check.h"

#include <stdbool.h>
#include <string.h>

static bool has(const int* cols, int n, int col) {
    for (int i = 0; i < n; ++i)
        if (cols[i] == col) return true;
    return false;
}

static void test_panels(void) {
    static const int lift_jib[3][4] = {{COL_X1, COL_X2, -1, -1},
                                       {COL_P1A, COL_P1B, COL_P2A, COL_P2B},
                                       {COL_U1, COL_U2, COL_U1_CMD, COL_U2_CMD}};
    static const int slew[3][2] = {{COL_X3, -1}, {COL_P3A, COL_P3B}, {COL_U3, COL_U3_CMD}};
    for (int p = 0; p < 3; ++p)
        for (int s = 0; s < 2; ++s) {
            int cols[APP_PLOT_MAXSERIES];
            const char* names[APP_PLOT_MAXSERIES];
            const int n = app_plot_run_channels(p, s, cols, names);
            CHECK(n > 0 && n <= APP_PLOT_MAXSERIES, "panel %d: %d series", p, n);
            for (int k = 0; k < 4; ++k)
                if (lift_jib[p][k] >= 0)
                    CHECK(has(cols, n, lift_jib[p][k]), "panel %d (slew %d): no %s", p, s,
                          sim_channels[lift_jib[p][k]].name);
            for (int k = 0; k < 2; ++k)
                if (slew[p][k] >= 0)
                    CHECK(has(cols, n, slew[p][k]) == (s == 1), "panel %d (slew %d): %s %s", p, s,
                          sim_channels[slew[p][k]].name, s ? "missing" : "drawn for a crane without a slew");
            // Each series named, no name twice (the legend tells them apart).
            for (int i = 0; i < n; ++i) {
                CHECK(names[i] && names[i][0], "panel %d: series %d unnamed", p, i);
                for (int j = 0; j < i; ++j) CHECK(strcmp(names[i], names[j]), "panel %d: '%s' twice", p, names[i]);
            }
        }
}

static void test_which_runs_slew(void) {
    static const struct {
        sim_mechanics mech;
        const char* world;
        bool slew;
    } k[] = {{SIM_ODE, "sandbox", true},     {SIM_ODE, "site", true},
             {SIM_ODE, "validation", false}, {SIM_LAGRANGE, "sandbox", false},
             {SIM_LAGRANGE, NULL, false},    {SIM_ODE, CRANESIM_ASSETS "/worlds/sandbox.json", true}};
    for (int i = 0; i < (int)(sizeof k / sizeof k[0]); ++i) {
        sim_opts o = sim_default_opts();
        o.mechanics = k[i].mech;
        o.world = k[i].world;
        CHECK(app_world_has_slew(&o) == k[i].slew, "%s, world %s: slew %d", k[i].mech == SIM_ODE ? "ode" : "lagrange",
              k[i].world ? k[i].world : "(none)", (int)!k[i].slew);
    }
}

// A chain model's page (issue 27 item 1): every actuator's stroke and
// chambers, every function's spool and command, every revolute DOF, each
// named by the model's name, in the model's order, at its column.
static void check_chain_model(const char* path) {
    char err[1024];
    model* m = model_load(path, NULL, 0, err, sizeof err);
    CHECK(m, "%s: %s", path, err);
    if (!m) return;
    const crane_chain* cc = &m->chain;
    CHECK(!cc->two_link && cc->ncol > 0, "%s: not a chain model", path);
    enum { MAX = 256 };
    int cols[MAX];
    const char* names[MAX];
    static const char* const pre[APP_PLOT_CHAIN_PANELS] = {"x_", "pA_", "pB_", "u_", "ucmd_", "q_"};
    const int off = 100; // any base width: the columns follow it
    for (int p = 0; p < APP_PLOT_CHAIN_PANELS; ++p) {
        const int n = app_plot_chain_channels(cc->col, cc->ncol, off, false, p, cols, names, MAX);
        int want = p <= 2 ? cc->nact : p <= 4 ? cc->nfn : 0;
        if (p == 5)
            for (int b = 1; b < cc->nbody; ++b) want += !cc->body[b].def.fixed && cc->body[b].def.joint != CHAIN_PRISMATIC;
        CHECK(n == want, "%s panel %d: %d series, expected %d", path, p, n, want);
        for (int i = 0, b = 0; i < n && i < want; ++i) {
            const char* nm = p <= 2 ? cc->act[i].name : p <= 4 ? cc->fn[i].name : NULL;
            if (p == 5) {
                for (++b; b < cc->nbody && (cc->body[b].def.fixed || cc->body[b].def.joint == CHAIN_PRISMATIC); ++b) {
                }
                nm = b < cc->nbody ? cc->body[b].def.name : "?";
            }
            CHECK(!strcmp(names[i], nm), "%s panel %d: series %d named '%s', expected '%s'", path, p, i, names[i], nm);
            char full[96];
            snprintf(full, sizeof full, "%s%s", pre[p], nm);
            CHECK(cols[i] >= off && cols[i] < off + cc->ncol && !strcmp(cc->col[cols[i] - off].name, full),
                  "%s panel %d: series %s at column %d", path, p, full, cols[i]);
        }
    }
    // max bounds what is filled.
    CHECK(app_plot_chain_channels(cc->col, cc->ncol, 0, false, 0, cols, names, 2) == 2, "max not honoured");
    // The world's slew drive (the ode sandbox keeps it in the base columns):
    // one more series per panel, last, named "slew", at its base column.
    static const int base[APP_PLOT_CHAIN_PANELS] = {COL_X3, COL_P3A, COL_P3B, COL_U3, COL_U3_CMD, COL_SLEW};
    for (int p = 0; p < APP_PLOT_CHAIN_PANELS; ++p) {
        const int n0 = app_plot_chain_channels(cc->col, cc->ncol, 100, false, p, cols, names, MAX);
        const int n1 = app_plot_chain_channels(cc->col, cc->ncol, 100, true, p, cols, names, MAX);
        CHECK(n1 == n0 + 1 && cols[n0] == base[p] && !strcmp(names[n0], "slew"), "%s panel %d with the slew: %d series",
              path, p, n1);
    }
    model_free(m);
}

static void test_chain_panels(void) {
    check_chain_model(CRANESIM_TESTDATA "/../../world/data/chain_3boom_ext.json");
    check_chain_model(CRANESIM_TESTDATA "/../../world/data/chain_8fn_10link.json");
}

int main(int argc, char** argv) {
    RUN_TEST(test_panels);
    RUN_TEST(test_which_runs_slew);
    RUN_TEST(test_chain_panels);
    TEST_MAIN_END();
}
