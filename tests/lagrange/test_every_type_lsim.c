// test_every_type_lsim.c: the lagrange backend's circuit paths on circuits
// with one instance of each component type added (tests/hydraulics/
// every_type.h) to each shipped model. lsim_init chooses the one-pass kernel
// (have_fused, the standard shape) or else the fast kernel in the system's
// state order (fk, with the load-sensing one-pass layout inside it) or else
// the general loops; whichever it chose, its f and J must be the general
// loops' (use_fast off) to rounding on random crane states, and a refused
// one-pass kernel must say why. A path that took a circuit with a component
// it has no place for would leave that component out of f.
#include "check.h"
#include "hydraulics/every_type.h"
#include "sim.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define TRIALS 200

static double urand01(void) {
    return rand() / (double)RAND_MAX;
}

static void quiet(const char* line, void* user) {
    (void)line, (void)user;
}

// A random crane state at the circuit's regime switches (as test_crane.c's):
// angles over the workspace, pressures near vacuum, near the reliefs or
// anywhere between, other states in [-1, 1] (an accumulator's oil volume:
// 0 to its V0 / 2), random joint rates and commands.
static void random_crane_state(lsim* s, double* y) {
    const double q0[2] = {(70 + 90 * urand01()) * M_PI / 180,
                          (-130 + 100 * urand01()) * M_PI / 180};
    lsim_initial_state(s, q0, 0.5e6, y);
    const hyd_model* hm = s->mdl->hyd;
    for (int i = 0; i < s->nh; ++i) {
        if (!s->is_pressure[i]) {
            const char* nm = hyd_model_state_name(hm, s->perm[i]);
            const char* dot = strrchr(nm, '.');
            double V0 = 0.0;
            if (dot && !strcmp(dot, ".oil")) {
                char path[128];
                snprintf(path, sizeof path, "%.*s.V0", (int)(dot - nm), nm);
                hyd_model_get(hm, path, &V0);
            }
            y[i] = V0 > 0.0 ? 0.5 * V0 * urand01() : 2 * urand01() - 1;
            continue;
        }
        const int r = rand() % 4;
        y[i] = r == 0   ? 1e3 + 5e4 * urand01()
               : r == 1 ? 24.5e6 + 2e6 * urand01()
                        : 0.2e6 + 22e6 * urand01();
    }
    y[s->iq + 2] = 0.3 * (2 * urand01() - 1);
    y[s->iq + 3] = 0.3 * (2 * urand01() - 1);
    s->u_cmd[0] = 1.2 * (2 * urand01() - 1);
    s->u_cmd[1] = 1.2 * (2 * urand01() - 1);
}

// The chosen path's f and J against the general loops' at TRIALS states:
// derivatives within 1e-12 of their row's largest term, Jacobian entries
// within 1e-9 of themselves plus 1e-13 of their row's largest entry (the
// one-pass kernel sums in another order; test_crane.c's bounds). Returns
// the mismatches.
static int compare(lsim* s, const char* what) {
    const int n = s->n;
    static double J[LSIM_MAX_STATES * LSIM_MAX_STATES], Jk[LSIM_MAX_STATES * LSIM_MAX_STATES];
    double y[LSIM_MAX_STATES], f[LSIM_MAX_STATES], fk[LSIM_MAX_STATES];
    const bool fused = s->have_fused, fast = s->use_fast;
    int bad_f = 0, bad_j = 0;
    double worst = 0.0;
    srand(7);
    for (int trial = 0; trial < TRIALS; ++trial) {
        random_crane_state(s, y);
        s->use_fast = false; // the general loops
        lsim_rhs(s, 0.0, y, f);
        lsim_jac(s, 0.0, y, J);
        s->use_fast = fast;
        if (fused) {
            lsim_rhs_fused(s, 0.0, y, fk);
            lsim_jac_fused(s, 0.0, y, Jk);
        } else {
            lsim_rhs(s, 0.0, y, fk);
            lsim_jac(s, 0.0, y, Jk);
        }
        for (int i = 0; i < n; ++i) {
            double rs = fabs(f[i]), js = 0.0;
            for (int j = 0; j < n; ++j) {
                rs = fmax(rs, fabs(J[i * n + j] * y[j]));
                js = fmax(js, fabs(J[i * n + j]));
            }
            const double e = fabs(fk[i] - f[i]) / (rs > 0.0 ? rs : 1.0);
            if (e > worst || isnan(e)) worst = isnan(e) ? HUGE_VAL : e;
            bad_f += !(fabs(fk[i] - f[i]) <= 1e-12 * rs);
            for (int j = 0; j < n; ++j)
                bad_j +=
                    !(fabs(Jk[i * n + j] - J[i * n + j]) <= 1e-9 * fabs(J[i * n + j]) + 1e-13 * js);
        }
    }
    CHECK(bad_f == 0 && bad_j == 0,
          "%s (%s): %d derivatives and %d Jacobian entries differ from the general loops, "
          "worst derivative %.3g of its row's scale",
          what, fused ? "one-pass kernel" : "fast kernel", bad_f, bad_j, worst);
    if (getenv("EVERY_TYPE_VERBOSE"))
        printf("  %-40s %s: worst %.2g%s%s\n", what,
               fused  ? "one-pass"
               : fast ? "fast"
                      : "general",
               worst, fused ? "" : ", one-pass refused: ", fused ? "" : s->fused_why);
    return bad_f + bad_j;
}

static void test_every_type_lsim(void) {
    hyd_set_note_handler(quiet, NULL);
    const char* dir = CRANESIM_ASSETS "/models";
    DIR* dp = opendir(dir);
    CHECK(dp != NULL, "cannot open %s", dir);
    if (!dp) return;
    char files[16][512];
    int nf = 0;
    struct dirent* e;
    while ((e = readdir(dp)) && nf < 16) {
        const size_t L = strlen(e->d_name);
        if (L > 5 && !strcmp(e->d_name + L - 5, ".json"))
            snprintf(files[nf++], sizeof files[0], "%s/%s", dir, e->d_name);
    }
    closedir(dp);
    int models = 0, fused_paths = 0, fast_paths = 0, lanes = 0;
    for (int f = 0; f < nf; ++f) {
        char err[512];
        model* base = model_load(files[f], NULL, 0, err, sizeof err);
        if (!base) continue; // not a model file
        if (!base->chain.two_link) {
            // The closed-form analytic mode (lsim) is the two-link crane's;
            // a chain model (loader10) runs the general path and must be
            // refused here in one line, not run as a wrong crane. Its
            // circuit's kernels are test_hyd_every_type's.
            lsim s;
            const int rc = lsim_init(&s, base, LAGRANGE_FULL, 500, err, sizeof err);
            CHECK(rc != 0 && strstr(err, "two-link crane") && !strchr(err, '\n'), "%s: chain model: lsim_init %d: %s",
                  files[f], rc, err);
            if (rc == 0) lsim_free(&s);
            printf("  %s: a chain model, refused by the closed-form mode: %s\n", strrchr(files[f], '/') + 1, err);
            model_free(base);
            continue;
        }
        ++models;
        anchors an;
        CHECK(find_anchors(base->hyd, &an) == 0, "%s: no pump line, tank or cylinder", files[f]);
        const char* name = strrchr(files[f], '/') + 1;
        for (int t = -1; t < HYD_TYPE_COUNT; ++t) {
            char what[128];
            snprintf(what, sizeof what, "%s%s%s", name, t >= 0 ? " + " : "",
                     t >= 0 ? hyd_type_name((hyd_type)t) : "");
            cJSON* doc = cJSON_Duplicate(base->json, 1);
            cJSON* h = cJSON_GetObjectItemCaseSensitive(doc, "hydraulics");
            if (t >= 0) {
                const char* frag = instance((hyd_type)t, &an);
                CHECK(frag != NULL, "type %s has no instance: add one to every_type.h",
                      hyd_type_name((hyd_type)t));
                cJSON* x = frag ? cJSON_Parse(frag) : NULL;
                for (int part = 0; part < 2 && x && h; ++part) {
                    const char* key = part ? "components" : "nodes";
                    cJSON* dst = cJSON_GetObjectItemCaseSensitive(h, key);
                    const cJSON* it;
                    cJSON_ArrayForEach(it, cJSON_GetObjectItemCaseSensitive(x, key))
                        cJSON_AddItemToArray(dst, cJSON_Duplicate(it, 1));
                }
                cJSON_Delete(x);
            }
            model* m = model_from_json(doc, what, err, sizeof err);
            CHECK(m != NULL, "%s: %s", what, err);
            if (!m) continue;
            lsim s;
            if (lsim_init(&s, m, LAGRANGE_FULL, 500, err, sizeof err) == 0) {
                CHECK(s.have_fused || s.fused_why[0],
                      "%s: one-pass kernel refused without a reason", what);
                // The instance is in the circuit the backend integrates.
                if (t >= 0)
                    CHECK(s.nh > 0 && hyd_model_ncomp(m->hyd) > hyd_model_ncomp(base->hyd), "%s",
                          what);
                fused_paths += s.have_fused;
                fast_paths += !s.have_fused && s.use_fast;
                if (s.fk) {
                    const unsigned long c0 = hyd_fast_lanes_count(s.fk);
                    compare(&s, what);
                    lanes += hyd_fast_lanes_count(s.fk) > c0;
                } else {
                    compare(&s, what);
                }
                lsim_free(&s);
            } else {
                CHECK(0, "%s: lsim_init: %s", what, err);
            }
            model_free(m);
        }
        model_free(base);
    }
    CHECK(models >= 2, "only %d models", models);
    // Every path of the backend was among those compared.
    CHECK(fused_paths >= 1 && fast_paths >= 1 && lanes >= 1,
          "paths compared: one-pass %d, fast %d, of which the LS layout %d", fused_paths,
          fast_paths, lanes);
    hyd_set_note_handler(NULL, NULL);
}

int main(int argc, char** argv) {
    RUN_TEST(test_every_type_lsim);
    TEST_MAIN_END();
}
