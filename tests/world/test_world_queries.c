// test_world_queries.c: the world layer reads the circuit's structure from
// the circuit (its supply node, the hose feeding a chamber, its state kinds),
// not from names, and a run compiles one circuit.
//  - The shipped model with its pump line renamed ("pump_line" ->
//    "supply_rail", in the model and in the sandbox's extra circuit) is the
//    same circuit: every row of every backend agrees bit for bit with the
//    shipped model's, p_pump included.
//  - The ode world without circuit extras runs on the model's own compiled
//    circuit (the panel's edit reaches the run once).
//  - An error in the world's extra circuit names the world file and its own
//    index, also for a problem found only by joining the two circuits.
#include "check.h"
#include "crane_fixture.h"
#include "engine.h"
#include "sim.h"
#include "row_store.h"

#include <stdlib.h>
#include <string.h>

// Text of a file (NULL on failure), and a copy with every `from` replaced by `to`.
static char* slurp(const char* path) {
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char* s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) n = 0;
    if (s) s[n] = 0;
    fclose(f);
    return s;
}

static char* replace_all(const char* s, const char* from, const char* to) {
    size_t nf = strlen(from), nt = strlen(to), count = 0;
    for (const char* p = strstr(s, from); p; p = strstr(p + nf, from)) ++count;
    char* out = malloc(strlen(s) + count * (nt > nf ? nt - nf : 0) + 1), *o = out;
    for (const char* p = s;;) {
        const char* q = strstr(p, from);
        if (!q) {
            strcpy(o, p);
            break;
        }
        memcpy(o, p, (size_t)(q - p));
        o += q - p;
        memcpy(o, to, nt);
        o += nt;
        p = q + nf;
    }
    return out;
}

static int write_text(const char* path, const char* text) {
    FILE* f = fopen(path, "wb");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

static model* model_from_text(const char* text, const char* file) {
    char err[512];
    cJSON* root = cJSON_Parse(text);
    CHECK(root != NULL, "%s: not JSON", file);
    if (!root) return NULL;
    model* m = model_from_json(root, file, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    return m;
}


static void test_renamed_pump_line(void) {
    char* mtext = slurp(CRANESIM_ASSETS "/models/hiab031.json");
    char* wtext = slurp(CRANESIM_ASSETS "/worlds/sandbox.json");
    CHECK(mtext && wtext && strstr(mtext, "\"pump_line\"") && strstr(wtext, "\"pump_line\""),
          "the shipped model and sandbox name their pump line pump_line");
    if (!mtext || !wtext) return;
    char* mren = replace_all(mtext, "\"pump_line\"", "\"supply_rail\"");
    char* wren = replace_all(wtext, "\"pump_line\"", "\"supply_rail\"");
    const char* wfile = "world_queries_sandbox.json";
    CHECK(write_text(wfile, wren) == 0, "cannot write %s", wfile);
    model* m0 = model_from_text(mtext, "hiab031.json");
    model* m1 = model_from_text(mren, "renamed.json");
    CHECK(m1 && hyd_model_find_node(m1->hyd, "pump_line") < 0 && hyd_model_find_node(m1->hyd, "supply_rail") >= 0,
          "the renamed model has no pump_line");
    static const struct {
        const char* name;
        sim_mechanics mech;
        const char *world0, *world1, *scenario;
        double duration;
    } b[] = {
        {"lagrange", SIM_LAGRANGE, NULL, NULL, "ramp", 2.0},
        {"ode validation", SIM_ODE, CRANESIM_ASSETS "/worlds/validation.json",
         CRANESIM_ASSETS "/worlds/validation.json", "ramp", 2.0},
        {"ode sandbox", SIM_ODE, CRANESIM_ASSETS "/worlds/sandbox.json", "world_queries_sandbox.json",
         "sandbox_pick_place", 2.0},
    };
    for (size_t k = 0; m0 && m1 && k < sizeof b / sizeof b[0]; ++k) {
        scenario sc;
        if (load_scenario(b[k].scenario, &sc)) continue;
        sim_opts o = sim_default_opts();
        o.mechanics = b[k].mech;
        o.duration = b[k].duration;
        rows r0 = {0}, r1 = {0};
        sim_result s0, s1;
        o.world = b[k].world0;
        CHECK(sim_run(m0, &sc, &o, keep_row, &r0, NULL, NULL, NULL, &s0) == 0, "%s: %s", b[k].name, s0.message);
        o.world = b[k].world1;
        CHECK(sim_run(m1, &sc, &o, keep_row, &r1, NULL, NULL, NULL, &s1) == 0, "%s renamed: %s", b[k].name,
              s1.message);
        CHECK(r0.n == r1.n && r0.n > 10, "%s: rows %d vs %d", b[k].name, r0.n, r1.n);
        int diff = -1;
        for (int i = 0; i < r0.n && i < r1.n && diff < 0; ++i)
            if (memcmp(r0.v + (size_t)i * SIM_NCOL, r1.v + (size_t)i * SIM_NCOL, SIM_NCOL * sizeof(double)))
                diff = i;
        CHECK(diff < 0, "%s: the renamed circuit's rows differ from row %d (p_pump %g vs %g Pa)", b[k].name, diff,
              diff >= 0 ? r0.v[(size_t)diff * SIM_NCOL + COL_P_PUMP] : 0.0,
              diff >= 0 ? r1.v[(size_t)diff * SIM_NCOL + COL_P_PUMP] : 0.0);
        // The pump line is pressurised (p0 20.1 MPa in the model): a
        // supply node not found would read 0.
        CHECK(r1.n > 0 && r1.v[(size_t)(r1.n - 1) * SIM_NCOL + COL_P_PUMP] > 1e6, "%s: p_pump %g Pa", b[k].name,
              r1.n > 0 ? r1.v[(size_t)(r1.n - 1) * SIM_NCOL + COL_P_PUMP] : 0.0);
        free(r0.v);
        free(r1.v);
    }
    model_free(m0);
    model_free(m1);
    remove(wfile);
    free(mtext);
    free(wtext);
    free(mren);
    free(wren);
}

// The validation world adds no circuit: its engine's circuit is the model's.
// The sandbox adds the slew: one circuit compiled for the run, holding the
// model's components and the world's.
static void test_one_circuit(void) {
    scenario sc;
    model* m = load_crane("ramp", &sc);
    if (!m) return;
    char err[512];
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = CRANESIM_ASSETS "/worlds/validation.json";
    engine* e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (e) {
        CHECK(engine_circuit(e) == m->hyd, "the validation world compiled a circuit of its own");
        engine_destroy(e);
    }
    o.world = CRANESIM_ASSETS "/worlds/sandbox.json";
    e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (e) {
        hyd_model* c = engine_circuit(e);
        CHECK(c != m->hyd && hyd_model_ncomp(c) > hyd_model_ncomp(m->hyd) && hyd_model_find(c, "slew_valve") >= 0 &&
                  hyd_model_find(c, "lift_valve") >= 0,
              "the sandbox's circuit is the model's plus the world's");
        engine_destroy(e);
    }
    model_free(m);
}

// A world circuit whose error shows only once it is joined to the model's:
// its valve's P names a node neither circuit declares, and a component of
// the world reuses a model component's name.
static void test_world_circuit_errors(void) {
    scenario sc;
    model* m = load_crane("ramp", &sc);
    char* wtext = slurp(CRANESIM_ASSETS "/worlds/sandbox.json");
    if (!m || !wtext) return;
    static const struct {
        const char *from, *to, *want;
    } c[] = {
        {"\"P\": \"pump_line\"", "\"P\": \"no_such_node\"",
         "world_queries_bad.json: circuit.components[0].P: unknown node 'no_such_node'"},
        {"\"name\": \"slew_hose_A\"", "\"name\": \"lift_hose_A\"",
         "world_queries_bad.json: circuit.components[1].name: duplicate name 'lift_hose_A'"},
    };
    for (size_t k = 0; k < sizeof c / sizeof c[0]; ++k) {
        char* bad = replace_all(wtext, c[k].from, c[k].to);
        CHECK(write_text("world_queries_bad.json", bad) == 0, "cannot write the world");
        sim_opts o = sim_default_opts();
        o.mechanics = SIM_ODE;
        o.world = "world_queries_bad.json";
        char err[512] = "";
        engine* e = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
        CHECK(e == NULL, "case %zu: the world was built", k);
        if (e) engine_destroy(e);
        // The start of the line: what follows the duplicate's name is the
        // circuit loader's (it says where the first one is).
        CHECK(!strncmp(err, c[k].want, strlen(c[k].want)), "case %zu:\n  got  %s\n  want %s", k, err, c[k].want);
        free(bad);
    }
    remove("world_queries_bad.json");
    free(wtext);
    model_free(m);
}

// A circuit without the one-pass kernel's shape (the shipped one plus a
// fixed orifice, a 1e-8 m^2 leak from the pump line to tank) runs its
// hydraulic sub-steps on the fast kernel, and agrees with the reference
// loops (--kernel general) to rounding grown over the run.
static void test_fast_kernel_on_ode(void) {
    scenario sc;
    model* m0 = load_crane("ramp", &sc);
    if (!m0) return;
    cJSON* doc = cJSON_Duplicate(m0->json, 1);
    cJSON* comps = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "hydraulics"), "components");
    cJSON* leak = cJSON_Parse("{\"name\": \"leak\", \"type\": \"orifice\", \"inlet\": \"pump_line\", "
                              "\"outlet\": \"tank\", \"area\": 1e-8}");
    cJSON_AddItemToArray(comps, leak);
    char err[512];
    model* m = model_from_json(doc, "leak.json", err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) {
        model_free(m0);
        return;
    }
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = CRANESIM_ASSETS "/worlds/validation.json";
    o.duration = 2.0;
    rows rf = {0}, rr = {0};
    sim_result sf, sr;
    CHECK(sim_run(m, &sc, &o, keep_row, &rf, NULL, NULL, NULL, &sf) == 0, "fast: %s", sf.message);
    CHECK(sf.fast && !sf.fused, "the leaky circuit ran fast %d fused %d", sf.fast, sf.fused);
    o.kernel = SIM_KERNEL_GENERAL;
    CHECK(sim_run(m, &sc, &o, keep_row, &rr, NULL, NULL, NULL, &sr) == 0, "reference: %s", sr.message);
    CHECK(!sr.fast && !sr.fused, "--kernel general ran fast %d fused %d", sr.fast, sr.fused);
    CHECK(rf.n == rr.n && rf.n > 10, "rows %d vs %d", rf.n, rr.n);
    double worst = 0;
    for (int i = 0; i < rf.n && i < rr.n; ++i)
        for (int c = COL_P1A; c <= COL_P2B; ++c) {
            const double a = rf.v[(size_t)i * SIM_NCOL + c], b = rr.v[(size_t)i * SIM_NCOL + c];
            const double d = fabs(a - b) / fmax(fabs(b), 1e5);
            if (!(d <= worst)) worst = d;
        }
    CHECK(worst < 1e-9, "chamber pressures of fast and reference differ by %.3g relative", worst);
    printf("fast vs reference, ode validation ramp 2 s with a leak: max relative chamber-pressure difference %.3g\n",
           worst);
    free(rf.v);
    free(rr.v);
    model_free(m);
    model_free(m0);
}

// The drivers' report fields come from the backend: the words cranesim run
// printed when it chose them itself (docs/README examples).
static void test_describe(void) {
    sim_opts o = sim_default_opts();
    engine_desc d;
    engine_describe(&o, &d);
    CHECK(!strcmp(d.backend, "lagrange") && !strcmp(d.label, "lagrange/full") && !strcmp(d.title, "full") &&
              !strcmp(d.world, "") && d.dt_outer == 0 && !d.h_reduced && !strcmp(d.step_name, "step"),
          "lagrange: %s %s %s '%s' %g %d %s", d.backend, d.label, d.title, d.world, d.dt_outer, d.h_reduced,
          d.step_name);
    sim_result r;
    memset(&r, 0, sizeof r);
    r.stats.steps = 200000, r.stats.rejected = 3, r.stats.fevals = 400000, r.stats.lus = 20065;
    char work[200];
    engine_describe_work(&o, &r, work, sizeof work);
    CHECK(!strcmp(work, "200000 steps, 3 rejected, 400000 f evals, 20065 LU"), "%s", work);
    o.mechanics = SIM_ODE;
    engine_describe(&o, &d);
    CHECK(!strcmp(d.backend, "ode") && !strcmp(d.label, "ode/validation") && !strcmp(d.title, "ode/validation") &&
              !strcmp(d.world, "validation") && d.dt_outer == 1e-3 && !d.h_reduced && !strcmp(d.step_name, "ODE step"),
          "ode: %s %s %s %s %g %d %s", d.backend, d.label, d.title, d.world, d.dt_outer, d.h_reduced, d.step_name);
    engine_describe_work(&o, &r, work, sizeof work);
    CHECK(!strcmp(work, "ODE step 1 ms, 200000 hydraulic sub-steps"), "%s", work);
    o.world = "/tmp/w.json";
    o.h = 2e-3; // longer than the ODE step: cut to it
    engine_describe(&o, &d);
    CHECK(!strcmp(d.label, "ode world /tmp/w.json") && !strcmp(d.title, "ode//tmp/w.json") && d.h_reduced, "%s %s %d",
          d.label, d.title, d.h_reduced);
    o.solver = HYD_RODAS3; // adaptive: its own steps, no fixed step to cut
    engine_describe(&o, &d);
    engine_describe_work(&o, &r, work, sizeof work);
    CHECK(!d.h_reduced && !strcmp(work, "ODE step 1 ms, 200000 hydraulic steps"), "%d %s", d.h_reduced, work);
}

int main(void) {
    test_renamed_pump_line();
    test_one_circuit();
    test_world_circuit_errors();
    test_fast_kernel_on_ode();
    test_describe();
    TEST_MAIN_END();
}
