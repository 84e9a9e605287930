// test_every_type.c: every shape-specific kernel is an allow-list. To each
// shipped circuit (assets/models/*.json alone and merged with each world's
// extra circuit, as the ode world merges them) one instance of EACH type in
// the component table is added where it carries flow or pressure; then every
// kernel that accepts the circuit is compared with the reference loops
// (hyd_eval, hyd_jacobian) on random states, and a kernel that refuses must
// say why:
//   - the fast kernel with all its loops (hyd_fast_create), and with it the
//     load-sensing one-pass layout (circuit_fast_ls.c) in its default and its
//     SSE2 form whenever it takes the circuit (hyd_fast_lanes);
//   - the fast kernel with the added type left to its reference loop
//     (fallback);
//   - the one-pass kernel of the standard shape (hyd_fused_build, _eval,
//     _eval2, _jacobian) with the circuit's valve/cylinder pairs.
// A kernel that recognised its layout by counting the types it knows would
// take a circuit with a component it has no place for and leave that
// component out of its sums. The test can see that: each added instance is
// checked to change the reference rates of the circuit it was added to (the
// rates a kernel that skipped it would give) far beyond the tolerance.
// A type the test has no instance for fails it: a new type gets its line in
// instance() below.
#include "check.h"
#include "circuit_fast.h"
#include "every_type.h"
#include "circuit_kernel.h"
#include "hydraulics.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TRIALS 300
#define TOL 1e-12 // relative, of the entry or of its row's scale (agree())
#define NMAX 128

static double urand(double a, double b) {
    return a + (b - a) * rand() / (double)RAND_MAX;
}

static void quiet(const char* line, void* user) {
    (void)line, (void)user;
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

// A random state that visits every regime (as test_fast.c's): pressures from
// near vacuum to beyond the reliefs' corners, spools closed, nearly closed or
// open, strokes in and beyond both end stops, an accumulator's oil volume
// below 0 to 0.9 V0, other fractions around 0 and 1.
static void random_state(const hyd_model* m, hyd_data* d, double* y) {
    const int n = hyd_model_nstate(m);
    for (int i = 0; i < n; ++i) {
        if (hyd_model_state_kind(m, i) == HYD_STATE_SPOOL) {
            const int um = rand() % 3;
            y[i] = um == 0 ? urand(-1, 1) : um == 1 ? urand(-1e-3, 1e-3) : urand(-1e-6, 1e-6);
            continue;
        }
        if (hyd_model_state_kind(m, i) == HYD_STATE_OTHER) {
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
                y[i] = um == 0   ? urand(-0.05, 1.05)
                       : um == 1 ? urand(-1e-6, 1e-6)
                                 : (rand() % 2) * 1.0;
            continue;
        }
        switch (rand() % 6) {
        case 0:
            y[i] = urand(1e3, 6e4);
            break;
        case 1:
            y[i] = urand(150.0, 2e3);
            break;
        case 2:
            y[i] = 1e5 + 20e6 + urand(-0.1e6, 0.6e6);
            break;
        case 3:
            y[i] = 1e5 + 25e6 + urand(-2e4, 1.2e6);
            break;
        default:
            y[i] = urand(0.2e6, 24e6);
            break;
        }
    }
    for (int c = 0; c < hyd_model_ncylinder(m); ++c) {
        double AA, AB, s;
        hyd_model_cylinder_geometry(m, c, &AA, &AB, &s);
        const int sm = rand() % 4;
        d->cyl_x[c] = sm == 0   ? urand(-2.5e-3, 2.5e-3)
                      : sm == 1 ? s + urand(-2.5e-3, 2.5e-3)
                                : urand(0, s);
        d->cyl_v[c] = urand(-0.3, 0.3);
    }
    for (int v = 0; v < hyd_model_nvalve(m); ++v)
        d->valve_cmd[v] = urand(-1.2, 1.2);
}

// The relative difference of a and b: |a - b| over the larger magnitude or
// scale (an entry that is a sum of cancelling terms is compared at the
// scale of its terms). 0 when both are the same non-finite value.
static double rel(double a, double b, double scale) {
    if (!isfinite(a) || !isfinite(b)) return a == b || (isnan(a) && isnan(b)) ? 0.0 : HUGE_VAL;
    const double mag = fmax(fmax(fabs(a), fabs(b)), scale);
    return mag > 0.0 ? fabs(a - b) / mag : 0.0;
}

// The scale of pressure state i's rate: its node's Be/V times the largest
// flow into or out of any node of the circuit (the reference's per-port
// flows, ncomp x 4 in d->flow_, and the node's dV/dt; not comp_q, whose
// second entry is a pressure for some types); 0 for other states.
static double rate_scale(const hyd_model* m, const hyd_data* d, int i) {
    const int node = hyd_model_state_node(m, i);
    if (node < 0) return 0.0;
    double qs = fabs(d->node_dV[node]);
    for (int c = 0; c < 4 * hyd_model_ncomp(m); ++c)
        qs = fmax(qs, fabs(d->flow_[c]));
    return qs * d->node_be[node] / d->node_V[node];
}

// Worst relative difference of a kernel against the reference over the
// trials, and how many values were beyond TOL.
typedef struct score {
    double worst;
    long bad, values;
    const char* where; ///< the state or output of the worst difference
} score;

static void note(score* s, double r, const char* where) {
    ++s->values;
    if (r > TOL) ++s->bad;
    if (r > s->worst) s->worst = r, s->where = where;
}

// The kernels under test, one evaluation each: ydot (circuit order), the
// cylinder forces, and (J non-NULL) the n x n Jacobian.
typedef enum { K_FAST, K_FUSED, K_FUSED2 } kind;
typedef struct kernel {
    kind kind;
    hyd_fast* fast;
    hyd_fused* fz;
    int valve[HYD_FUSED_MAXACT], cyl[HYD_FUSED_MAXACT];
} kernel;

static void kernel_eval(const kernel* k, const hyd_model* m, hyd_data* d, const double* y,
                        double* ydot, double* F, double* J) {
    const int n = hyd_model_nstate(m);
    if (k->kind == K_FAST) {
        if (J)
            hyd_fast_jacobian(k->fast, d, y, ydot, J, n);
        else
            hyd_fast_eval(k->fast, d, y, ydot);
        for (int c = 0; c < hyd_model_ncylinder(m); ++c)
            F[c] = d->cyl_F[c];
        return;
    }
    const hyd_fused* f = k->fz;
    double x[HYD_FUSED_MAXACT], v[HYD_FUSED_MAXACT], cmd[HYD_FUSED_MAXACT], Fk[HYD_FUSED_MAXACT];
    for (int a = 0; a < f->nact; ++a)
        x[a] = d->cyl_x[k->cyl[a]], v[a] = d->cyl_v[k->cyl[a]], cmd[a] = d->valve_cmd[k->valve[a]];
    if (J) {
        memset(J, 0, (size_t)n * n * sizeof *J); // hyd_fused_jacobian writes the non-zeros only
        hyd_fused_coupling cp[HYD_FUSED_MAXACT];
        hyd_fused_jacobian(f, y, x, v, cmd, ydot, Fk, J, n, cp);
    } else if (k->kind == K_FUSED2) {
        hyd_fused_eval2(f, y, x, v, cmd, ydot, Fk);
    } else {
        hyd_fused_eval(f, y, x, v, cmd, ydot, Fk);
    }
    for (int c = 0; c < hyd_model_ncylinder(m); ++c)
        F[c] = NAN;
    for (int a = 0; a < f->nact; ++a)
        F[k->cyl[a]] = Fk[a];
}

// Kernel k against the reference on TRIALS random states (seeded: every
// kernel sees the same states): rates, forces, the Jacobian.
static score compare(const hyd_model* m, const kernel* k) {
    score s = {0.0, 0, 0, ""};
    const int n = hyd_model_nstate(m), nc = hyd_model_ncylinder(m);
    hyd_data* dr = hyd_data_create(m);
    hyd_data* dk = hyd_data_create(m);
    static double y[NMAX], fr[NMAX], fk[NMAX], Fr[NMAX], Fk[NMAX], Jr[NMAX * NMAX], Jk[NMAX * NMAX];
    if (!dr || !dk || n > NMAX || nc > NMAX) {
        CHECK(0, "cannot set up the comparison (%d states)", n);
        s.worst = HUGE_VAL;
        return s;
    }
    srand(2025);
    for (int trial = 0; trial < TRIALS; ++trial) {
        random_state(m, dr, y);
        memcpy(dk->cyl_x, dr->cyl_x, (size_t)nc * sizeof(double));
        memcpy(dk->cyl_v, dr->cyl_v, (size_t)nc * sizeof(double));
        memcpy(dk->valve_cmd, dr->valve_cmd, (size_t)hyd_model_nvalve(m) * sizeof(double));
        const int jac = trial % 2; // f alone, then f with J (both entry points)
        if (jac)
            hyd_jacobian(m, dr, 0.0, y, fr, Jr, n, 0, 0);
        else
            hyd_eval(m, dr, 0.0, y, fr);
        for (int c = 0; c < nc; ++c)
            Fr[c] = dr->cyl_F[c];
        for (int i = 0; i < n * n; ++i)
            Jk[i] = 12345.0; // every entry must be written
        kernel_eval(k, m, dk, y, fk, Fk, jac ? Jk : NULL);
        for (int i = 0; i < n; ++i)
            note(&s, rel(fk[i], fr[i], rate_scale(m, dr, i)), hyd_model_state_name(m, i));
        for (int c = 0; c < nc; ++c)
            if (!isnan(Fk[c]) || k->kind == K_FAST)
                note(&s, rel(Fk[c], Fr[c], 0.0), "a cylinder force");
        if (!jac) continue;
        for (int i = 0; i < n; ++i) {
            double rowmax = 0.0;
            for (int j = 0; j < n; ++j)
                rowmax = fmax(rowmax, fabs(Jr[i * n + j]));
            for (int j = 0; j < n; ++j)
                note(&s, rel(Jk[i * n + j], Jr[i * n + j], i == j ? rowmax : 0.0),
                     hyd_model_state_name(m, i));
        }
    }
    hyd_data_free(dk);
    hyd_data_free(dr);
    return s;
}

// The reference rates of circuit b (the base, without the instance) against
// those of circuit m (with it) on the states they share (by name), at the
// same random states: what a kernel that skipped the instance would give.
static score skipped(const hyd_model* m, const hyd_model* b) {
    score s = {0.0, 0, 0, ""};
    const int n = hyd_model_nstate(m), nb = hyd_model_nstate(b);
    hyd_data* dm = hyd_data_create(m);
    hyd_data* db = hyd_data_create(b);
    static double y[NMAX], yb[NMAX], fm[NMAX], fb[NMAX];
    static int at[NMAX];
    if (!dm || !db || n > NMAX || nb > NMAX) {
        CHECK(0, "cannot set up the comparison");
        return s;
    }
    for (int i = 0; i < nb; ++i)
        at[i] = hyd_model_find_state(m, hyd_model_state_name(b, i));
    srand(2025);
    for (int trial = 0; trial < TRIALS; ++trial) {
        random_state(m, dm, y);
        for (int i = 0; i < nb; ++i)
            yb[i] = at[i] >= 0 ? y[at[i]] : 0.0;
        // The base's cylinders and valves come first, in the same order.
        memcpy(db->cyl_x, dm->cyl_x, (size_t)hyd_model_ncylinder(b) * sizeof(double));
        memcpy(db->cyl_v, dm->cyl_v, (size_t)hyd_model_ncylinder(b) * sizeof(double));
        memcpy(db->valve_cmd, dm->valve_cmd, (size_t)hyd_model_nvalve(b) * sizeof(double));
        hyd_eval(m, dm, 0.0, y, fm);
        hyd_eval(b, db, 0.0, yb, fb);
        for (int i = 0; i < nb; ++i)
            if (at[i] >= 0)
                note(&s, rel(fb[i], fm[at[i]], rate_scale(m, dm, at[i])),
                     hyd_model_state_name(b, i));
    }
    hyd_data_free(db);
    hyd_data_free(dm);
    return s;
}

// The valve that drives cylinder c: the one whose A port is the hose that
// feeds chamber A (else whose A port is chamber A itself), or -1.
static int valve_of(const hyd_model* m, int c) {
    const int cc = hyd_model_cylinder_comp(m, c), nA = hyd_model_comp_node(m, cc, 0);
    const int hose = hyd_model_feed_hose(m, nA);
    const int node = hose >= 0 ? hyd_model_comp_node(m, hose, 0) : nA;
    for (int v = 0; v < hyd_model_nvalve(m); ++v)
        if (hyd_model_port_node(m, hyd_model_valve_comp(m, v), 2) == node) return v;
    return -1;
}

// Every kernel on circuit m (t: the type of the instance added to it, -1
// for a shipped circuit itself). Returns how many kernels took the circuit.
// EVERY_TYPE_VERBOSE=1 in the environment prints each kernel's worst
// relative difference and each refusal's reason.
static int check_kernels(const char* what, const hyd_model* m, int t) {
    char why[256] = "";
    int took = 0;
    // The fast kernel with all its loops (which takes every type the library
    // has today) and with it the one-pass layouts it dispatches to.
    hyd_fast* k = hyd_fast_create(m, hyd_fast_types(), 0, why, sizeof why);
    CHECK(k != NULL || strstr(why, "no loop for this type"), "%s: fast kernel: %s", what, why);
    if (k) {
        ++took;
        const int lanes = hyd_fast_lanes(k, -1);
        const char* lwhy = hyd_fast_lanes_why(k);
        CHECK(lanes ? lwhy[0] == 0 : lwhy[0] != 0, "%s: the LS layout %s, reason '%s'", what,
              lanes ? "taken" : "refused", lwhy);
        for (int form = 0; form < (lanes ? 2 : 1); ++form) {
            if (form) hyd_fast_lanes(k, 2); // the SSE2 form (form 0: AVX where the CPU has it)
            const unsigned long before = hyd_fast_lanes_count(k);
            kernel kk = {K_FAST, k, NULL, {0}, {0}};
            const score s = compare(m, &kk);
            const unsigned long taken = hyd_fast_lanes_count(k) - before;
            CHECK(s.bad == 0,
                  "%s: fast kernel%s: %ld of %ld values differ from the reference, worst %.3g (%s)",
                  what, lanes ? (form ? " (LS layout, SSE2)" : " (LS layout)") : "", s.bad,
                  s.values, s.worst, s.where);
            // The layout path must have been compared when it was taken, and
            // never taken when refused.
            if (lanes)
                CHECK(taken > TRIALS / 10, "%s: the LS layout took %lu of %d trials", what, taken,
                      TRIALS);
            else
                CHECK(taken == 0, "%s: the refused LS layout took %lu trials", what, taken);
            if (getenv("EVERY_TYPE_VERBOSE"))
                printf("  %-58s fast%s: worst %.2g, LS layout %s%s (%lu trials)\n", what,
                       form ? " SSE2" : "", s.worst, lanes ? "taken" : "refused: ", lwhy, taken);
        }
        hyd_fast_free(k);
    }
    // The added type left to its reference loop.
    if (t >= 0 && (hyd_fast_types() >> t & 1u)) {
        k = hyd_fast_create(m, hyd_fast_types() & ~(1u << t), 1, why, sizeof why);
        CHECK(k && hyd_fast_nfallback(k) >= 1, "%s: no fallback: %s", what, why);
        if (k) {
            CHECK(hyd_fast_lanes(k, -1) == 0 && strstr(hyd_fast_lanes_why(k), "fall back"),
                  "%s: the LS layout with a fallback: '%s'", what, hyd_fast_lanes_why(k));
            kernel kk = {K_FAST, k, NULL, {0}, {0}};
            const score s = compare(m, &kk);
            CHECK(s.bad == 0,
                  "%s: fast kernel with fallback: %ld of %ld values differ, worst %.3g (%s)", what,
                  s.bad, s.values, s.worst, s.where);
            ++took;
        }
        hyd_fast_free(k);
    }
    // The one-pass kernel of the standard shape, on the circuit's actuators.
    const int nact = hyd_model_ncylinder(m);
    if (nact >= 1 && nact <= HYD_FUSED_MAXACT) {
        kernel kk = {K_FUSED, NULL, NULL, {0}, {0}};
        static hyd_fused f;
        int paired = 1;
        for (int a = 0; a < nact; ++a) {
            kk.cyl[a] = a;
            kk.valve[a] = valve_of(m, a);
            paired &= kk.valve[a] >= 0;
        }
        if (!paired) { // no valve drives some cylinder through a hose: refused by index
            for (int a = 0; a < nact; ++a)
                kk.valve[a] = a < hyd_model_nvalve(m) ? a : 0;
        }
        why[0] = 0;
        const int ok = hyd_fused_build(m, kk.valve, kk.cyl, nact, &f, why, sizeof why) == 0;
        CHECK(ok || why[0], "%s: the one-pass kernel refused without a reason", what);
        if (ok) {
            ++took;
            kk.fz = &f;
            for (int form = 0; form < 2; ++form) {
                kk.kind = form ? K_FUSED2 : K_FUSED;
                const score s = compare(m, &kk);
                CHECK(s.bad == 0,
                      "%s: one-pass kernel%s: %ld of %ld values differ, worst %.3g (%s)", what,
                      form ? " (two lanes)" : "", s.bad, s.values, s.worst, s.where);
                if (getenv("EVERY_TYPE_VERBOSE"))
                    printf("  %-58s one-pass%s: worst %.2g\n", what, form ? " lanes" : "", s.worst);
            }
        } else if (getenv("EVERY_TYPE_VERBOSE")) {
            printf("  %-58s one-pass refused: %s\n", what, why);
        }
    }
    return took;
}

// The circuits that ship: each model's, alone and with each world's extra
// circuit appended. For each, the base and then one instance per type.
static void test_every_type(void) {
    hyd_set_note_handler(quiet, NULL);
    const char* models[] = {HYD_ASSETS "/models", HYD_ASSETS "/worlds"};
    char mpath[32][512], wpath[32][512];
    int nm = 0, nw = 0;
    for (int d = 0; d < 2; ++d) {
        DIR* dp = opendir(models[d]);
        CHECK(dp != NULL, "cannot open %s", models[d]);
        if (!dp) continue;
        struct dirent* e;
        while ((e = readdir(dp))) {
            const size_t L = strlen(e->d_name);
            if (L < 6 || strcmp(e->d_name + L - 5, ".json")) continue;
            if (d == 0 && nm < 32)
                snprintf(mpath[nm++], sizeof mpath[0], "%s/%s", models[d], e->d_name);
            if (d == 1 && nw < 32)
                snprintf(wpath[nw++], sizeof wpath[0], "%s/%s", models[d], e->d_name);
        }
        closedir(dp);
    }
    CHECK(nm >= 2, "only %d model files", nm);
    int circuits = 0, layout_bases = 0, fused_bases = 0;
    for (int a = 0; a < nm; ++a) {
        for (int w = -1; w < nw; ++w) {
            cJSON* mj = read_json(mpath[a]);
            cJSON* wj = w >= 0 ? read_json(wpath[w]) : NULL;
            const cJSON* h = mj ? cJSON_GetObjectItemCaseSensitive(mj, "hydraulics") : NULL;
            const cJSON* wc = wj ? cJSON_GetObjectItemCaseSensitive(wj, "circuit") : NULL;
            if (!h || (w >= 0 && !wc)) { // not a model, or a world without a circuit
                cJSON_Delete(wj), cJSON_Delete(mj);
                continue;
            }
            char err[512], what[256];
            const char* mname = strrchr(mpath[a], '/') + 1;
            const char* wname = w >= 0 ? strrchr(wpath[w], '/') + 1 : "";
            hyd_model* base = wc ? hyd_model_from_json_extra(h, mpath[a], "hydraulics", wc,
                                                             wpath[w], "circuit", err, sizeof err)
                                 : hyd_model_from_json(h, mpath[a], "hydraulics", err, sizeof err);
            if (!base) { // a world that does not fit this model (as the ode world refuses it)
                cJSON_Delete(wj), cJSON_Delete(mj);
                continue;
            }
            ++circuits;
            snprintf(what, sizeof what, "%s%s%s", mname, w >= 0 ? "+" : "", wname);
            if (getenv("EVERY_TYPE_VERBOSE")) printf("%s\n", what);
            check_kernels(what, base, -1);
            // The base circuits themselves exercise the one-pass paths.
            {
                char why[256];
                hyd_fast* k = hyd_fast_create(base, hyd_fast_types(), 0, why, sizeof why);
                layout_bases += k && hyd_fast_lanes(k, -1);
                hyd_fast_free(k);
            }
            anchors an;
            CHECK(find_anchors(base, &an) == 0, "%s: no pump line, tank or cylinder", what);
            for (int t = 0; t < HYD_TYPE_COUNT; ++t) {
                const char* frag = instance((hyd_type)t, &an);
                CHECK(frag != NULL, "type %s has no instance in this test: add one to instance()",
                      hyd_type_name((hyd_type)t));
                if (!frag) continue;
                cJSON* x = cJSON_Parse(frag);
                CHECK(x != NULL, "instance of %s does not parse: %s", hyd_type_name((hyd_type)t),
                      frag);
                // The world's extra circuit, then the instance.
                cJSON* extra = wc ? cJSON_Duplicate(wc, 1) : cJSON_CreateObject();
                for (int part = 0; part < 2 && x && extra; ++part) {
                    const char* key = part ? "components" : "nodes";
                    cJSON* dst = cJSON_GetObjectItemCaseSensitive(extra, key);
                    if (!dst) dst = cJSON_AddArrayToObject(extra, key);
                    const cJSON* src = cJSON_GetObjectItemCaseSensitive(x, key);
                    const cJSON* it;
                    cJSON_ArrayForEach(it, src) cJSON_AddItemToArray(dst, cJSON_Duplicate(it, 1));
                }
                hyd_model* m = hyd_model_from_json_extra(h, mpath[a], "hydraulics", extra,
                                                         "instance", "circuit", err, sizeof err);
                char wt[300];
                snprintf(wt, sizeof wt, "%s + %s", what, hyd_type_name((hyd_type)t));
                CHECK(m != NULL, "%s: %s", wt, err);
                if (m) {
                    // The instance carries flow: the rates without it differ.
                    const score sk = skipped(m, base);
                    CHECK(sk.worst > 1e6 * TOL && sk.bad >= TRIALS / 20,
                          "%s: the instance changes no rate (%ld of %ld beyond %g, worst %.3g)", wt,
                          sk.bad, sk.values, TOL, sk.worst);
                    if (getenv("EVERY_TYPE_VERBOSE"))
                        printf("  %-58s skipping it: %ld of %ld rates off, worst %.3g (%s)\n", wt,
                               sk.bad, sk.values, sk.worst, sk.where);
                    CHECK(check_kernels(wt, m, t) >= 1, "%s: no kernel took the circuit", wt);
                    hyd_model_free(m);
                }
                cJSON_Delete(extra);
                cJSON_Delete(x);
            }
            {
                char why[256];
                hyd_fused f;
                int v[HYD_FUSED_MAXACT], c[HYD_FUSED_MAXACT];
                const int na = hyd_model_ncylinder(base);
                for (int i = 0; i < na && i < HYD_FUSED_MAXACT; ++i)
                    c[i] = i, v[i] = valve_of(base, i);
                fused_bases += na <= HYD_FUSED_MAXACT &&
                               hyd_fused_build(base, v, c, na, &f, why, sizeof why) == 0;
            }
            hyd_model_free(base);
            cJSON_Delete(wj), cJSON_Delete(mj);
        }
    }
    CHECK(circuits >= 2, "only %d shipped circuits", circuits);
    // Both one-pass paths were among the kernels compared.
    CHECK(layout_bases >= 1, "no shipped circuit has the LS layout");
    CHECK(fused_bases >= 1, "no shipped circuit has the one-pass kernel's standard shape");
    hyd_set_note_handler(NULL, NULL);
}

int main(int argc, char** argv) {
    RUN_TEST(test_every_type);
    TEST_MAIN_END();
}
