// test_fast.c: the fast kernel for any circuit (circuit_fast.h) against the
// reference loops (hyd_eval, hyd_jacobian), on every circuit that ships
// (assets/models, the world circuits merged as the ode world merges them,
// tests/hydraulics/data) and on synthetic circuits of 1, 2, 4 and 8
// actuators; a type without a fast loop either falls back or is refused;
// and the structure queries (state kinds, node roles, Jacobian pattern).
#include "check.h"
#include "circuit_fast.h"
#include "hydraulics.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TRIALS 3000
#define TOL 1e-12

static double urand(double a, double b) { return a + (b - a) * rand() / (double)RAND_MAX; }

// A random state that visits every regime: pressures from near vacuum (Be
// near 0, checks open) to beyond the reliefs' corners, spools closed, nearly
// closed or open, strokes in and beyond both end stops.
static void random_state(const hyd_model* m, hyd_data* d, double* y) {
    const int n = hyd_model_nstate(m);
    for (int i = 0; i < n; ++i) {
        if (hyd_model_state_kind(m, i) == HYD_STATE_SPOOL) {
            const int um = rand() % 3;
            y[i] = um == 0 ? urand(-1, 1) : um == 1 ? urand(-1e-3, 1e-3) : urand(-1e-6, 1e-6);
            continue;
        }
        if (hyd_model_state_kind(m, i) == HYD_STATE_OTHER) {
            // An accumulator's oil volume [m^3]: below 0 (the poppet law)
            // to 0.9 V0. Else a fraction (LS pump displacement, counter-
            // balance spool): closed, a rounding error either side of it,
            // open, and the lag's overshoot a little past 1.
            const char* nm = hyd_model_state_name(m, i);
            const char* dot = strrchr(nm, '.');
            double V0 = 0.0;
            if (dot && !strcmp(dot, ".oil")) {
                char path[128];
                snprintf(path, sizeof path, "%.*s.V0", (int)(dot - nm), nm);
                hyd_model_get(m, path, &V0);
            }
            const int um = rand() % 3;
            if (V0 > 0.0)
                y[i] = um == 0 ? urand(-1e-4 * V0, 0) : urand(0, 0.9 * V0);
            else
                y[i] = um == 0 ? urand(-0.05, 1.05) : um == 1 ? urand(-1e-6, 1e-6) : (rand() % 2) * 1.0;
            continue;
        }
        switch (rand() % 6) {
        case 0: y[i] = urand(1e3, 6e4); break;
        case 1: y[i] = urand(150.0, 2e3); break;
        case 2: y[i] = 1e5 + 20e6 + urand(-0.1e6, 0.6e6); break;
        case 3: y[i] = 1e5 + 25e6 + urand(-2e4, 1.2e6); break;
        default: y[i] = urand(0.2e6, 24e6); break;
        }
    }
    for (int c = 0; c < hyd_model_ncylinder(m); ++c) {
        double AA, AB, s;
        hyd_model_cylinder_geometry(m, c, &AA, &AB, &s);
        const int sm = rand() % 3;
        d->cyl_x[c] = sm == 0 ? urand(-2.5e-3, 2.5e-3) : sm == 1 ? s + urand(-2.5e-3, 2.5e-3) : urand(0, s);
        d->cyl_v[c] = urand(-0.3, 0.3);
    }
    for (int v = 0; v < hyd_model_nvalve(m); ++v) d->valve_cmd[v] = urand(-1.2, 1.2);
}

// |a - b| within TOL of the larger magnitude (both 0 passes), and of a
// scale for entries that are sums of cancelling terms.
static int agree(double a, double b, double scale) {
    if (!isfinite(a) || !isfinite(b)) return a == b || (isnan(a) && isnan(b));
    const double mag = fmax(fmax(fabs(a), fabs(b)), scale);
    return fabs(a - b) <= TOL * mag;
}

// Fast against reference on TRIALS random states; returns the mismatches.
// With low, every trial also puts one pressure state (trial by trial each in
// turn) below the Be table's range (HYD_BE_P_LO = 100 Pa, the exact law), so
// the plain evaluation's two-node Be pairs meet a node off the table in
// either position of a pair, and compares f only (the Jacobian takes Be node
// by node, which the trials without low check).
static int compare_ex(const char* what, const hyd_model* m, hyd_fast* k, int low) {
    const int n = hyd_model_nstate(m);
    hyd_data* dr = hyd_data_create(m);
    hyd_data* df = hyd_data_create(m);
    double* y = calloc((size_t)n, sizeof *y);
    double* fr = calloc((size_t)n, sizeof *fr);
    double* ff = calloc((size_t)n, sizeof *ff);
    double* Jr = calloc((size_t)n * n, sizeof *Jr);
    double* Jf = calloc((size_t)n * n, sizeof *Jf);
    int bad = 0;
    for (int trial = 0; trial < TRIALS && dr && df && y && fr && ff && Jr && Jf; ++trial) {
        random_state(m, dr, y);
        if (low && hyd_model_state_kind(m, trial % n) == HYD_STATE_PRESSURE) y[trial % n] = urand(1.0, 99.0);
        memcpy(df->cyl_x, dr->cyl_x, (size_t)hyd_model_ncylinder(m) * sizeof(double));
        memcpy(df->cyl_v, dr->cyl_v, (size_t)hyd_model_ncylinder(m) * sizeof(double));
        memcpy(df->valve_cmd, dr->valve_cmd, (size_t)hyd_model_nvalve(m) * sizeof(double));
        hyd_eval(m, dr, 0.0, y, fr);
        hyd_fast_eval(k, df, y, ff);
        for (int i = 0; i < n; ++i) {
            // A pressure rate is c times a sum of flows: its scale is c times
            // the largest flow magnitude of the circuit.
            const int node = hyd_model_state_node(m, i);
            double qs = 0.0;
            if (node >= 0) {
                for (int c = 0; c < 2 * hyd_model_ncomp(m); ++c) qs = fmax(qs, fabs(dr->comp_q[c]));
                qs = fmax(qs, fabs(dr->node_dV[node]));
                qs *= dr->node_be[node] / dr->node_V[node];
            }
            if (!agree(ff[i], fr[i], qs)) {
                if (bad < 5)
                    fprintf(stderr, "%s trial %d: f[%s] fast %.17g ref %.17g\n", what, trial,
                            hyd_model_state_name(m, i), ff[i], fr[i]);
                ++bad;
            }
        }
        for (int c = 0; c < hyd_model_ncylinder(m); ++c)
            if (!agree(df->cyl_F[c], dr->cyl_F[c], 0.0)) {
                if (bad < 5)
                    fprintf(stderr, "%s trial %d: cylinder %d force fast %.17g ref %.17g\n", what, trial, c,
                            df->cyl_F[c], dr->cyl_F[c]);
                ++bad;
            }
        // Each pressure node's modulus and net inflow, which the energy
        // balance and the chamber coupling read after the evaluation.
        for (int i = 0; i < n; ++i) {
            const int node = hyd_model_state_node(m, i);
            if (node < 0) continue;
            if (!agree(df->node_be[node], dr->node_be[node], 0.0)) {
                if (bad < 5)
                    fprintf(stderr, "%s trial %d: Be[%s] fast %.17g ref %.17g\n", what, trial,
                            hyd_model_state_name(m, i), df->node_be[node], dr->node_be[node]);
                ++bad;
            }
            double qs = 0.0;
            for (int c = 0; c < 2 * hyd_model_ncomp(m); ++c) qs = fmax(qs, fabs(dr->comp_q[c]));
            if (!agree(df->node_q[node], dr->node_q[node], qs)) {
                if (bad < 5)
                    fprintf(stderr, "%s trial %d: net inflow of %s fast %.17g ref %.17g\n", what, trial,
                            hyd_model_state_name(m, i), df->node_q[node], dr->node_q[node]);
                ++bad;
            }
        }
        if (low) continue;
        hyd_jacobian(m, dr, 0.0, y, NULL, Jr, n, 0, 0);
        // The force partials the mechanics takes (seal friction's dF/dx').
        // hyd_fast_jacobian writes them; hyd_fast_eval may not.
        const int ncyl = hyd_model_ncylinder(m);
        for (int i = 0; i < n * n; ++i) Jf[i] = 12345.0; // every entry must be written
        hyd_fast_jacobian(k, df, y, NULL, Jf, n);
        for (int c = 0; c < ncyl; ++c)
            if (!agree(df->dFdv[c], dr->dFdv[c], 0.0) || !agree(df->dFdx[c], dr->dFdx[c], 0.0)) {
                if (bad < 5)
                    fprintf(stderr, "%s trial %d: cylinder %d dF/dv fast %.17g ref %.17g\n", what, trial, c,
                            df->dFdv[c], dr->dFdv[c]);
                ++bad;
            }
        for (int i = 0; i < n; ++i) {
            double rowmax = 0.0;
            for (int j = 0; j < n; ++j) rowmax = fmax(rowmax, fabs(Jr[i * n + j]));
            for (int j = 0; j < n; ++j)
                if (!agree(Jf[i * n + j], Jr[i * n + j], i == j ? rowmax : 0.0)) {
                    if (bad < 5)
                        fprintf(stderr, "%s trial %d: J[%s][%s] fast %.17g ref %.17g\n", what, trial,
                                hyd_model_state_name(m, i), hyd_model_state_name(m, j), Jf[i * n + j],
                                Jr[i * n + j]);
                    ++bad;
                }
        }
        for (int i = 0; i < hyd_model_ncylinder(m) * n; ++i)
            if (!agree(df->dydx[i], dr->dydx[i], 0.0) || !agree(df->dydv[i], dr->dydv[i], 0.0) ||
                !agree(df->dFdy[i], dr->dFdy[i], 0.0)) {
                if (bad < 5)
                    fprintf(stderr, "%s trial %d: coupling partial %d (cylinder %d, state %s) fast %.17g %.17g %.17g"
                            " ref %.17g %.17g %.17g\n", what, trial, i, i / n, hyd_model_state_name(m, i % n),
                            df->dydx[i], df->dydv[i], df->dFdy[i], dr->dydx[i], dr->dydv[i], dr->dFdy[i]);
                ++bad;
            }
    }
    CHECK(bad == 0, "%s: %d values of the fast kernel differ from the reference", what, bad);
    free(Jf);
    free(Jr);
    free(ff);
    free(fr);
    free(y);
    hyd_data_free(df);
    hyd_data_free(dr);
    return bad;
}

static int compare(const char* what, const hyd_model* m, hyd_fast* k) { return compare_ex(what, m, k, 0); }

static void check_circuit(const char* what, const hyd_model* m) {
    char why[256] = "";
    // Components of a type without a fast loop (the load-sensing ones) run
    // their reference loops: exactly those fall back, nothing else.
    int want_fb = 0;
    for (int c = 0; c < hyd_model_ncomp(m); ++c)
        want_fb += !(hyd_fast_types() >> hyd_model_comp_type(m, c) & 1u);
    hyd_fast* k = hyd_fast_create(m, hyd_fast_types(), want_fb > 0, why, sizeof why);
    CHECK(k != NULL, "%s: fast kernel refused: %s", what, why);
    if (!k) return;
    CHECK(hyd_fast_nfallback(k) == want_fb, "%s: %d components fell back, %d expected", what,
          hyd_fast_nfallback(k), want_fb);
    compare(what, m, k);
    hyd_fast_free(k);
}

static cJSON* read_json(const char* path) {
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    static char buf[1 << 20];
    const size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    return cJSON_Parse(buf);
}

// Every JSON file in dir that holds a circuit that compiles.
static int check_dir(const char* dir) {
    DIR* dp = opendir(dir);
    CHECK(dp != NULL, "cannot open %s", dir);
    if (!dp) return 0;
    int count = 0;
    struct dirent* e;
    while ((e = readdir(dp))) {
        const size_t L = strlen(e->d_name);
        if (L < 6 || strcmp(e->d_name + L - 5, ".json")) continue;
        char path[1024], err[512];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        hyd_set_note_handler(NULL, NULL);
        hyd_model* m = hyd_model_load_json(path, err, sizeof err);
        if (!m) continue; // a bad-circuit fixture
        check_circuit(path, m);
        hyd_model_free(m);
        ++count;
    }
    closedir(dp);
    return count;
}

static void quiet(const char* line, void* user) { (void)line, (void)user; }

// Each shipped model's circuit with each world's extra circuit appended, as
// the ode world merges them (nodes and components appended in order).
static void test_world_circuits(void) {
    const char* models[] = {HYD_ASSETS "/models/hiab031.json"};
    const char* worlds[] = {HYD_ASSETS "/worlds/sandbox.json", HYD_ASSETS "/worlds/validation.json"};
    int merged = 0;
    for (size_t a = 0; a < sizeof models / sizeof *models; ++a)
        for (size_t w = 0; w < sizeof worlds / sizeof *worlds; ++w) {
            cJSON* mj = read_json(models[a]);
            cJSON* wj = read_json(worlds[w]);
            CHECK(mj && wj, "cannot read %s or %s", models[a], worlds[w]);
            const cJSON* extra = wj ? cJSON_GetObjectItemCaseSensitive(wj, "circuit") : NULL;
            cJSON* h = mj ? cJSON_GetObjectItemCaseSensitive(mj, "hydraulics") : NULL;
            if (h && extra) {
                static const char* const lists[2] = {"nodes", "components"};
                for (int l = 0; l < 2; ++l) {
                    const cJSON* add = cJSON_GetObjectItemCaseSensitive(extra, lists[l]);
                    cJSON* dst = cJSON_GetObjectItemCaseSensitive(h, lists[l]);
                    const cJSON* it;
                    cJSON_ArrayForEach(it, add) cJSON_AddItemToArray(dst, cJSON_Duplicate(it, 1));
                }
                char err[512];
                hyd_set_note_handler(quiet, NULL);
                hyd_model* m = hyd_model_from_json(h, worlds[w], "hydraulics", err, sizeof err);
                hyd_set_note_handler(NULL, NULL);
                CHECK(m != NULL, "merged circuit of %s: %s", worlds[w], err);
                if (m) {
                    char what[600];
                    snprintf(what, sizeof what, "%s + %s", models[a], worlds[w]);
                    check_circuit(what, m);
                    hyd_model_free(m);
                    ++merged;
                }
            }
            cJSON_Delete(mj);
            cJSON_Delete(wj);
        }
    CHECK(merged >= 1, "no world circuit merged");
}

static void test_shipped(void) {
    CHECK(check_dir(HYD_ASSETS "/models") >= 1, "no shipped model circuit");
    CHECK(check_dir(HYD_TESTDATA) >= 2, "fewer than 2 valid test circuits");
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (m) check_circuit("default crane", m), hyd_model_free(m);
}

// The default crane with seal friction on both cylinders, and velocities
// within a few v_sm of zero (where the tanh law bends) in a third of the states.
static void test_seal_friction(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    static const char* const set[] = {"lift_cyl.coulomb", "lift_cyl.stribeck", "jib_cyl.coulomb", "jib_cyl.stribeck"};
    static const double val[] = {3000.0, 1500.0, 2000.0, 1000.0};
    for (int i = 0; i < 4; ++i) CHECK(hyd_model_set(m, set[i], val[i], err, sizeof err) == 0, "%s", err);
    CHECK(hyd_model_set(m, "lift_cyl.v_smooth", 0.1, err, sizeof err) == 0, "%s", err); // 0.3 m/s spans it
    check_circuit("default crane with seal friction", m);
    hyd_model_free(m);
}

// The load-sensing crane: every one of its components (LS pump, shuttles,
// compensators, counterbalance valves with the rest) has a fast loop: no
// fallback, and the same numbers as the reference loops. The accumulator,
// which no shipped circuit has, is added on the pump line and on a
// counterbalance valve's load line.
static void test_ls_crane(void) {
    static const char* const path = HYD_ASSETS "/models/hiab031_ls.json";
    for (int acc = 0; acc < 2; ++acc) {
        cJSON* mj = read_json(path);
        CHECK(mj != NULL, "cannot read %s", path);
        cJSON* h = mj ? cJSON_GetObjectItemCaseSensitive(mj, "hydraulics") : NULL;
        cJSON* comps = h ? cJSON_GetObjectItemCaseSensitive(h, "components") : NULL;
        if (acc && comps) {
            static const char* const json[2] = {
                "{\"name\":\"acc_p\",\"type\":\"accumulator\",\"port\":\"pump_line\",\"p0\":5e6,"
                "\"V0\":1e-3,\"n\":1.4,\"conductance\":1e-9,\"p_init\":8e6}",
                "{\"name\":\"acc_l\",\"type\":\"accumulator\",\"port\":\"lift_cyl.A\",\"p0\":2e6,"
                "\"V0\":2e-4,\"n\":1,\"conductance\":1e-10}"};
            for (int j = 0; j < 2; ++j) cJSON_AddItemToArray(comps, cJSON_Parse(json[j]));
        }
        char err[512], why[256] = "";
        hyd_set_note_handler(quiet, NULL);
        hyd_model* m = h ? hyd_model_from_json(h, path, "hydraulics", err, sizeof err) : NULL;
        hyd_set_note_handler(NULL, NULL);
        CHECK(m != NULL, "%s%s: %s", path, acc ? " with accumulators" : "", err);
        cJSON_Delete(mj);
        if (!m) continue;
        unsigned seen = 0;
        for (int c = 0; c < hyd_model_ncomp(m); ++c) seen |= 1u << hyd_model_comp_type(m, c);
        const unsigned ls = 1u << HYD_LS_PUMP | 1u << HYD_SHUTTLE | 1u << HYD_COMPENSATOR |
                            1u << HYD_COUNTERBALANCE | (acc ? 1u << HYD_ACCUMULATOR : 0u);
        CHECK((seen & ls) == ls, "the circuit lacks a load-sensing type: %#x of %#x", seen & ls, ls);
        hyd_fast* k = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
        CHECK(k != NULL, "LS crane%s: fast kernel refused without fallback: %s", acc ? " with accumulators" : "",
              why);
        if (k) {
            CHECK(hyd_fast_nfallback(k) == 0, "%d components fell back", hyd_fast_nfallback(k));
            compare(acc ? "LS crane with accumulators" : "LS crane", m, k);
        }
        hyd_fast_free(k);
        hyd_model_free(m);
    }
}

// The plain evaluation's Be two nodes at a time, with one node off the
// table (the exact law) in every position, on the shipped LS crane.
static void test_off_table(void) {
    static const char* const path = HYD_ASSETS "/models/hiab031_ls.json";
    char err[512], why[256] = "";
    cJSON* mj = read_json(path);
    cJSON* h = mj ? cJSON_GetObjectItemCaseSensitive(mj, "hydraulics") : NULL;
    hyd_set_note_handler(quiet, NULL);
    hyd_model* m = h ? hyd_model_from_json(h, path, "hydraulics", err, sizeof err) : NULL;
    hyd_set_note_handler(NULL, NULL);
    cJSON_Delete(mj);
    CHECK(m != NULL, "%s: %s", path, err);
    if (!m) return;
    hyd_fast* k = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
    CHECK(k != NULL, "LS crane: fast kernel refused: %s", why);
    if (k) compare_ex("LS crane, a node off the Be table", m, k, 1);
    hyd_fast_free(k);
    hyd_model_free(m);
}

// The shipped LS crane's model (quiet: its load notes are not under test).
static hyd_model* ls_model(void) {
    static const char* const path = HYD_ASSETS "/models/hiab031_ls.json";
    char err[512];
    cJSON* mj = read_json(path);
    cJSON* h = mj ? cJSON_GetObjectItemCaseSensitive(mj, "hydraulics") : NULL;
    hyd_set_note_handler(quiet, NULL);
    hyd_model* m = h ? hyd_model_from_json(h, path, "hydraulics", err, sizeof err) : NULL;
    hyd_set_note_handler(NULL, NULL);
    cJSON_Delete(mj);
    CHECK(m != NULL, "%s: %s", path, err);
    return m;
}

// Every output hyd_fast_eval promises, bit for bit (memcmp: -0 and +0
// differ, NaNs must have the same bits): rates at the caller's places (Y of
// N entries, circuit state i at map[i]), cylinder forces and stops (and the
// force partials both paths also write), and per node p, V, dV/dt, and for
// the pressure nodes the net inflow and Be.
static int same_outputs(const hyd_model* m, const hyd_data* a, const hyd_data* b, const double* fa,
                        const double* fb, int N, const char* what, int trial) {
    int bad = 0;
#define SAME(x, y, name, i)                                                                               \
    do {                                                                                                  \
        if (memcmp(&(x), &(y), sizeof(x))) {                                                              \
            if (bad++ < 3)                                                                                \
                fprintf(stderr, "%s trial %d: %s[%d] lanes %.17g loops %.17g\n", what, trial, name, i,    \
                        (double)(x), (double)(y));                                                        \
        }                                                                                                 \
    } while (0)
    for (int i = 0; i < N; ++i) SAME(fa[i], fb[i], "ydot", i);
    for (int c = 0; c < hyd_model_ncylinder(m); ++c) {
        SAME(a->cyl_F[c], b->cyl_F[c], "cyl_F", c);
        SAME(a->cyl_stop[c], b->cyl_stop[c], "cyl_stop", c);
        // Not promised by hyd_fast_eval, but written by both paths: the same.
        SAME(a->dFdx[c], b->dFdx[c], "dFdx", c);
        SAME(a->dFdv[c], b->dFdv[c], "dFdv", c);
    }
    for (int nd = 0; nd < hyd_model_nnode(m); ++nd) {
        SAME(a->node_p[nd], b->node_p[nd], "node_p", nd);
        SAME(a->node_V[nd], b->node_V[nd], "node_V", nd);
        SAME(a->node_dV[nd], b->node_dV[nd], "node_dV", nd);
        if (hyd_model_node_state(m, nd) < 0) continue;
        SAME(a->node_q[nd], b->node_q[nd], "node_q", nd);
        SAME(a->node_be[nd], b->node_be[nd], "node_be", nd);
    }
#undef SAME
    return bad;
}

// The LS crane's one-pass evaluation (circuit_fast_ls.c) against the fast
// kernel's own loops (the same kernel with it switched off), bit for bit,
// on random states in every regime: spools closed, cracking and open both
// ways, reliefs and checks closed, on their corner and open, the anti-
// cavitation checks at near vacuum, counterbalance valves shut and relieving,
// strokes free and in the stops (those go to the loops); in the circuit's
// order and in a scattered caller order (hyd_fast_map); pressures swept ulp
// by ulp across every relief's and check's opening (the pack's closed bounds
// are exact); after a parameter change (the records are packed again).
// The reference loops (hyd_eval) are compared at TOL in test_ls_crane.
static void test_ls_lanes(void) {
    hyd_model* m = ls_model();
    if (!m) return;
    char why[256] = "", err[256];
    const int n = hyd_model_nstate(m), N = 2 * n + 3;
    int* map = malloc((size_t)n * sizeof *map);
    double *y = calloc((size_t)n, sizeof *y), *Y = calloc((size_t)N, sizeof *Y);
    double *fa = calloc((size_t)N, sizeof *fa), *fb = calloc((size_t)N, sizeof *fb);
    hyd_data* da = hyd_data_create(m);
    hyd_data* db = hyd_data_create(m);
    if (!map || !y || !Y || !fa || !fb || !da || !db) return;
    for (int i = 0; i < n; ++i) map[i] = N - 1 - 2 * i;
    int bad = 0;
    // Pass 0: circuit order; 1: mapped; 2: circuit order, the kernel's
    // SSE2 form (passes 0 and 1 take its AVX form where the CPU has AVX).
    for (int pass = 0; pass < 3; ++pass) {
        const int mapped = pass == 1;
        hyd_fast* ka = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
        hyd_fast* kb = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
        CHECK(ka && kb, "LS crane: fast kernel refused: %s", why);
        if (!ka || !kb) return;
        if (mapped) CHECK(hyd_fast_map(ka, map) == 0 && hyd_fast_map(kb, map) == 0, "map refused");
        CHECK(hyd_fast_lanes(ka, pass == 2 ? 2 : -1) == 1, "the LS crane layout is not recognised");
        hyd_fast_lanes(kb, 0);
        const int M = mapped ? N : n;
        const char* what = pass == 2 ? "LS lanes, SSE2 form" : mapped ? "LS lanes, mapped" : "LS lanes";
        // Regimes seen on the lane path: [0] a chamber's relief or check
        // open, [1] a spool negative (the valve reversed), [2] a pressure
        // below 2 kPa (Be near its floor).
        int seen[3] = {0, 0, 0};
        unsigned long before = hyd_fast_lanes_count(ka);
        int taken = 0;
        for (int trial = 0; trial < 4 * TRIALS; ++trial) {
            random_state(m, da, y);
            // Mostly free strokes, so most trials take the lane path.
            for (int c = 0; c < hyd_model_ncylinder(m); ++c) {
                double AA, AB, s;
                hyd_model_cylinder_geometry(m, c, &AA, &AB, &s);
                if (rand() % 4) da->cyl_x[c] = urand(0.0, s);
            }
            memcpy(db->cyl_x, da->cyl_x, (size_t)hyd_model_ncylinder(m) * sizeof(double));
            memcpy(db->cyl_v, da->cyl_v, (size_t)hyd_model_ncylinder(m) * sizeof(double));
            memcpy(db->valve_cmd, da->valve_cmd, (size_t)hyd_model_nvalve(m) * sizeof(double));
            for (int i = 0; i < M; ++i) Y[i] = 0.0;
            for (int i = 0; i < n; ++i) Y[mapped ? map[i] : i] = y[i];
            for (int i = 0; i < M; ++i) fa[i] = fb[i] = 7.0;
            const unsigned long c0 = hyd_fast_lanes_count(ka);
            hyd_fast_eval(ka, da, Y, fa);
            hyd_fast_eval(kb, db, Y, fb);
            const int lane = hyd_fast_lanes_count(ka) != c0;
            taken += lane;
            bad += same_outputs(m, da, db, fa, fb, M, what, trial);
            if (!lane) continue;
            for (int i = 0; i < n; ++i) {
                const int node = hyd_model_state_node(m, i);
                const char* nm = node >= 0 ? hyd_model_node_name(m, node) : "";
                if (node >= 0 && (y[i] > 25.1e6 || y[i] < 0.5e5) && strstr(nm, "_cyl.")) seen[0] = 1;
                if (node >= 0 && y[i] < 2e3) seen[2] = 1;
                if (hyd_model_state_kind(m, i) == HYD_STATE_SPOOL && y[i] < -1e-3) seen[1] = 1;
            }
        }
        CHECK(hyd_fast_lanes_count(ka) - before == (unsigned long)taken, "lane count off");
        CHECK(taken > TRIALS, "%s: only %d of %d trials took the lane path", what, taken, 4 * TRIALS);
        CHECK(seen[0] && seen[1] && seen[2], "%s: a regime was not visited (%d %d %d)", what, seen[0], seen[1],
              seen[2]);
        CHECK(hyd_fast_lanes_count(kb) == 0, "the switched-off kernel took the lane path");
        hyd_fast_free(kb);
        hyd_fast_free(ka);
    }
    CHECK(bad == 0, "LS lanes: %d outputs differ from the loops", bad);

    // Ulp by ulp across each relief's and check's opening (p_tank + p_crack,
    // p_tank - p_crack), on the lane path: a section's chambers, hose B and
    // counterbalance valve side all at the swept pressure and every spool,
    // compensator, counterbalance valve and the pump's displacement at 0, so
    // that the chambers' reliefs or checks are their nodes' only flows (and
    // the pump line's main relief its only one): an opening taken one ulp
    // late or early shows in the rates. Every other pressure mid-range.
    hyd_fast* ka = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
    hyd_fast* kb = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
    if (!ka || !kb) return;
    hyd_fast_lanes(kb, 0);
    static const char* const sec[2][4] = {{"lift_cyl.A", "lift_cyl.B", "lift_hose_B", "lift_cbv_A"},
                                          {"jib_cyl.A", "jib_cyl.B", "jib_hose_B", "jib_cbv_A"}};
    static const char* const pl[4] = {"pump_line", NULL, NULL, NULL};
    const struct { const char* const* nodes; double edge; } sweep[5] = {
        {sec[0], 1e5 + 25e6}, {sec[0], 1e5 - 5e4}, {sec[1], 1e5 + 25e6}, {sec[1], 1e5 - 5e4}, {pl, 1e5 + 23e6}};
    int swept = 0, moved = 0;
    bad = 0;
    for (int e = 0; e < 5; ++e) {
        int at[4] = {-1, -1, -1, -1};
        for (int j = 0; j < 4 && sweep[e].nodes[j]; ++j) {
            for (int nd = 0; nd < hyd_model_nnode(m); ++nd)
                if (!strcmp(hyd_model_node_name(m, nd), sweep[e].nodes[j])) at[j] = hyd_model_node_state(m, nd);
            CHECK(at[j] >= 0, "no pressure node %s", sweep[e].nodes[j]);
        }
        double f_lo = 0.0, f_hi = 0.0;
        for (int k = -40; k <= 40; ++k) {
            random_state(m, da, y);
            for (int i = 0; i < n; ++i)
                y[i] = hyd_model_state_kind(m, i) == HYD_STATE_PRESSURE ? urand(1e6, 15e6) : 0.0;
            double p = sweep[e].edge;
            for (int s = 0; s < (k < 0 ? -k : k); ++s) p = nextafter(p, k < 0 ? 0.0 : HUGE_VAL);
            for (int j = 0; j < 4; ++j)
                if (at[j] >= 0) y[at[j]] = p;
            for (int c = 0; c < hyd_model_ncylinder(m); ++c) {
                double AA, AB, s;
                hyd_model_cylinder_geometry(m, c, &AA, &AB, &s);
                da->cyl_x[c] = db->cyl_x[c] = 0.5 * s;
                db->cyl_v[c] = da->cyl_v[c];
            }
            memcpy(db->valve_cmd, da->valve_cmd, (size_t)hyd_model_nvalve(m) * sizeof(double));
            const unsigned long c0 = hyd_fast_lanes_count(ka);
            hyd_fast_eval(ka, da, y, fa);
            hyd_fast_eval(kb, db, y, fb);
            swept += hyd_fast_lanes_count(ka) != c0;
            bad += same_outputs(m, da, db, fa, fb, n, sweep[e].nodes[0], k);
            if (k == -40) f_lo = db->node_q[hyd_model_state_node(m, at[0])];
            if (k == 40) f_hi = db->node_q[hyd_model_state_node(m, at[0])];
        }
        moved += f_lo != f_hi; // the valve did open (or close) inside the sweep
    }
    CHECK(moved == 5, "only %d of 5 sweeps crossed an opening", moved);
    CHECK(swept == 5 * 81, "the sweep took the lane path %d of %d times", swept, 5 * 81);
    CHECK(bad == 0, "LS lanes at the reliefs' and checks' openings: %d outputs differ", bad);

    // After a parameter change the lane path packs the new records.
    CHECK(hyd_model_set(m, "lift_relief_A.p_crack", 12e6, err, sizeof err) == 0, "%s", err);
    CHECK(hyd_model_set(m, "jib_cbv.pilot_ratio", 3.0, err, sizeof err) == 0, "%s", err);
    CHECK(hyd_model_set(m, "lift_comp.setting", 3e5, err, sizeof err) == 0, "%s", err);
    bad = 0;
    int taken = 0;
    for (int trial = 0; trial < TRIALS; ++trial) {
        random_state(m, da, y);
        for (int c = 0; c < hyd_model_ncylinder(m); ++c) {
            double AA, AB, s;
            hyd_model_cylinder_geometry(m, c, &AA, &AB, &s);
            da->cyl_x[c] = db->cyl_x[c] = urand(0.0, s);
            db->cyl_v[c] = da->cyl_v[c];
        }
        memcpy(db->valve_cmd, da->valve_cmd, (size_t)hyd_model_nvalve(m) * sizeof(double));
        const unsigned long c0 = hyd_fast_lanes_count(ka);
        hyd_fast_eval(ka, da, y, fa);
        hyd_fast_eval(kb, db, y, fb);
        taken += hyd_fast_lanes_count(ka) != c0;
        bad += same_outputs(m, da, db, fa, fb, n, "after hyd_model_set", trial);
    }
    CHECK(taken > TRIALS / 2, "after hyd_model_set: %d of %d trials took the lane path", taken, TRIALS);
    CHECK(bad == 0, "LS lanes after hyd_model_set: %d outputs differ", bad);
    if (ka) compare("LS crane after hyd_model_set", m, ka);
    hyd_fast_free(kb);
    hyd_fast_free(ka);

    // Any other layout keeps the loops: the standard crane, and the LS crane
    // with an accumulator (a type the layout has no place for).
    char e2[256];
    hyd_model* sm = hyd_model_default_crane(e2, sizeof e2);
    hyd_fast* ks = sm ? hyd_fast_create(sm, hyd_fast_types(), 0, why, sizeof why) : NULL;
    CHECK(ks && hyd_fast_lanes(ks, -1) == 0, "the standard crane taken for the LS layout");
    hyd_fast_free(ks);
    hyd_model_free(sm);

    hyd_data_free(db);
    hyd_data_free(da);
    free(fb), free(fa), free(Y), free(y), free(map);
    hyd_model_free(m);
}

static void test_synthetic(void) {
    const int sizes[] = {1, 2, 4, 8};
    for (int s = 0; s < 4; ++s) {
        char err[256], what[64];
        hyd_model* m = hyd_model_synthetic(sizes[s], err, sizeof err);
        CHECK(m != NULL, "synthetic %d: %s", sizes[s], err);
        if (!m) continue;
        CHECK(hyd_model_ncylinder(m) == sizes[s] && hyd_model_nstate(m) == 1 + 5 * sizes[s],
              "synthetic %d: %d cylinders, %d states", sizes[s], hyd_model_ncylinder(m), hyd_model_nstate(m));
        snprintf(what, sizeof what, "synthetic %d actuators", sizes[s]);
        check_circuit(what, m);
        hyd_model_free(m);
    }
}

// A circuit with a type the kernel does not take (here: told so by the mask)
// is refused with a message naming the component, or evaluated correctly by
// the reference loop of that type.
static void test_unsupported(void) {
    char err[256], why[256] = "";
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    const unsigned types[3] = {hyd_fast_types() & ~(1u << HYD_VALVE), hyd_fast_types() & ~(1u << HYD_CYLINDER),
                               hyd_fast_types() & ~(1u << HYD_RELIEF | 1u << HYD_HOSE)};
    for (int t = 0; t < 3; ++t) {
        hyd_fast* k = hyd_fast_create(m, types[t], 0, why, sizeof why);
        CHECK(k == NULL, "mask %u: accepted without fallback", types[t]);
        CHECK(strstr(why, "component '") && strstr(why, "no loop for this type"), "message: %s", why);
        hyd_fast_free(k);
        k = hyd_fast_create(m, types[t], 1, why, sizeof why);
        CHECK(k != NULL && hyd_fast_nfallback(k) > 0, "mask %u: no fallback", types[t]);
        if (k) compare("fallback", m, k);
        hyd_fast_free(k);
    }
    hyd_fast* k = hyd_fast_create(m, hyd_fast_types() & ~(1u << HYD_VALVE), 0, why, sizeof why);
    CHECK(!k && strstr(why, "'lift_valve' (valve)"), "message: %s", why);
    hyd_fast_free(k);
    hyd_model_free(m);
}

// A parameter change reaches the kernel's record copies.
static void test_live_change(void) {
    char err[256], why[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m) return;
    hyd_fast* k = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
    CHECK(hyd_model_set(m, "lift_cyl.bore", 0.12, err, sizeof err) == 0, "%s", err);
    CHECK(hyd_model_set(m, "jib_hose_A.length", 5.0, err, sizeof err) == 0, "%s", err);
    if (k) compare("after hyd_model_set", m, k);
    hyd_fast_free(k);
    hyd_model_free(m);
}

// In a caller's state order (hyd_fast_map) the same numbers, bit for bit,
// at the mapped places: a state vector of 3 n entries with the circuit's
// states scattered in reverse.
static void test_mapped(void) {
    char err[256], why[256];
    hyd_model* m = hyd_model_synthetic(3, err, sizeof err);
    if (!m) return;
    const int n = hyd_model_nstate(m), N = 3 * n;
    hyd_fast* k = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
    hyd_fast* km = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
    int* map = malloc((size_t)n * sizeof *map);
    double *y = calloc((size_t)n, sizeof *y), *f = calloc((size_t)n, sizeof *f);
    double *J = calloc((size_t)n * n, sizeof *J), *Y = calloc((size_t)N, sizeof *Y);
    double *F = calloc((size_t)N, sizeof *F), *JM = calloc((size_t)N * N, sizeof *JM);
    hyd_data* d = hyd_data_create(m);
    if (!k || !km || !map || !y || !f || !J || !Y || !F || !JM || !d) return;
    for (int i = 0; i < n; ++i) map[i] = N - 1 - 2 * i;
    CHECK(hyd_fast_map(km, map) == 0, "map refused");
    int bad = 0, outside = 0;
    for (int trial = 0; trial < 300; ++trial) {
        random_state(m, d, y);
        for (int i = 0; i < n; ++i) Y[map[i]] = y[i];
        for (int i = 0; i < N * N; ++i) JM[i] = 7.0;
        hyd_fast_jacobian(k, d, y, f, J, n);
        hyd_fast_jacobian(km, d, Y, F, JM, N);
        for (int i = 0; i < n; ++i) {
            bad += memcmp(&F[map[i]], &f[i], sizeof *f) != 0;
            for (int j = 0; j < n; ++j) bad += memcmp(&JM[map[i] * N + map[j]], &J[i * n + j], sizeof *J) != 0;
        }
        int in_block = 0;
        for (int i = 0; i < N * N; ++i) in_block += JM[i] != 7.0;
        outside += in_block > n * n;
    }
    CHECK(bad == 0, "%d mapped values differ", bad);
    CHECK(outside == 0, "entries written outside the mapped block in %d trials", outside);
    hyd_fast* kf = hyd_fast_create(m, hyd_fast_types() & ~(1u << HYD_HOSE), 1, why, sizeof why);
    CHECK(kf && hyd_fast_map(kf, map) == -1, "map accepted with fallback components");
    hyd_fast_free(kf);
    hyd_data_free(d);
    free(JM), free(F), free(Y), free(J), free(f), free(y), free(map);
    hyd_fast_free(km);
    hyd_fast_free(k);
    hyd_model_free(m);
}

static void test_structure(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m) return;
    const int n = hyd_model_nstate(m);
    for (int i = 0; i < n; ++i) {
        const char* nm = hyd_model_state_name(m, i);
        const hyd_state_kind k = hyd_model_state_kind(m, i);
        const int spool = strstr(nm, ".spool") != NULL;
        CHECK(k == (spool ? HYD_STATE_SPOOL : HYD_STATE_PRESSURE), "kind of %s: %d", nm, (int)k);
        CHECK((hyd_model_state_node(m, i) < 0) == spool, "node of %s", nm);
        if (!spool) CHECK(hyd_model_node_state(m, hyd_model_state_node(m, i)) == i, "node state of %s", nm);
    }
    const int pl = hyd_model_find_node(m, "pump_line"), tank = hyd_model_find_node(m, "tank");
    CHECK(hyd_model_supply_node(m) == pl, "supply node %d, pump line %d", hyd_model_supply_node(m), pl);
    CHECK(hyd_model_node_role(m, pl) == HYD_NODE_SUPPLY && hyd_model_node_role(m, tank) == HYD_NODE_TANK &&
              hyd_model_node_role(m, hyd_model_find_node(m, "lift_cyl.A")) == HYD_NODE_LINE,
          "node roles");
    const int cyl = hyd_model_find(m, "jib_cyl");
    const int chB = hyd_model_comp_node(m, cyl, 1);
    CHECK(chB == hyd_model_find_node(m, "jib_cyl.B") && hyd_model_node_owner(m, chB) == cyl, "chamber B");
    const int hose = hyd_model_feed_hose(m, chB);
    CHECK(hose == hyd_model_find(m, "jib_hose_B"), "feed hose of jib_cyl.B: %d", hose);
    CHECK(hyd_model_node_state(m, hyd_model_comp_node(m, hose, 0)) == hyd_model_find_state(m, "jib_hose_B.p"),
          "hose state");
    const int valve = hyd_model_find(m, "lift_valve");
    CHECK(hyd_model_port_node(m, valve, 0) == pl && hyd_model_port_node(m, valve, 1) == tank &&
              hyd_model_port_node(m, valve, 2) == hyd_model_find_node(m, "lift_hose_A"),
          "valve ports");
    CHECK(hyd_model_port_node(m, valve, 4) == -1 && hyd_model_comp_node(m, valve, 0) == -1 &&
              hyd_model_node_owner(m, pl) == -1,
          "out of range");

    // No Jacobian entry outside the pattern, at random states; and the
    // pattern is not full (the point of a block pattern).
    unsigned char* P = malloc((size_t)n * n);
    double* y = calloc((size_t)n, sizeof *y);
    double* J = calloc((size_t)n * n, sizeof *J);
    hyd_data* d = hyd_data_create(m);
    int outside = 0, nnz = 0;
    hyd_model_jacobian_pattern(m, P);
    for (int i = 0; i < n * n; ++i) nnz += P[i];
    for (int trial = 0; trial < 300; ++trial) {
        random_state(m, d, y);
        hyd_jacobian(m, d, 0.0, y, NULL, J, n, 0, 0);
        for (int i = 0; i < n * n; ++i) outside += J[i] != 0.0 && !P[i];
    }
    CHECK(outside == 0, "%d Jacobian entries outside the pattern", outside);
    CHECK(nnz > n && nnz < n * n / 2, "pattern has %d of %d entries", nnz, n * n);
    CHECK(P[hyd_model_find_state(m, "lift_valve.spool") * n + hyd_model_find_state(m, "pump_line.p")] == 0 &&
              P[hyd_model_find_state(m, "pump_line.p") * n + hyd_model_find_state(m, "lift_valve.spool")] == 1,
          "spool row and column");
    hyd_data_free(d);
    free(J);
    free(y);
    free(P);
    hyd_model_free(m);
}

int main(int argc, char** argv) {
    srand(14);
    RUN_TEST(test_structure);
    RUN_TEST(test_shipped);
    RUN_TEST(test_seal_friction);
    RUN_TEST(test_world_circuits);
    RUN_TEST(test_ls_crane);
    RUN_TEST(test_synthetic);
    RUN_TEST(test_unsupported);
    RUN_TEST(test_live_change);
    RUN_TEST(test_mapped);
    RUN_TEST(test_off_table);
    RUN_TEST(test_ls_lanes);
    TEST_MAIN_END();
}
