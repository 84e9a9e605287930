// test_ode_sandbox_chain.c: the sandbox with the crane built from the
// model's chain (ode_world_opts.chain, a hosted ode_chain on the truck):
// - the default crane in its chain form (tests/world/data/hiab031_chain.json,
//   value for value assets' hiab031.json) against the two-link sandbox on a
//   lift, jib and slew scenario and on the pick-and-place (hook attach,
//   carry, release): strokes, slew, hook and load positions, supports;
// - the 3-boom + extension model picking up a load with the hook: the
//   cylinder forces holding it at rest against the statics of the chain
//   (the mechanism's gravity load with load, hook and rope at the tip,
//   solved for the four cylinders' forces through their lever arms) and
//   against the same mass as a tip load in the validation world;
// - every function and the slew of that model in the sandbox: the rows carry
//   the chain's columns, the collisions are named after the chain's bodies;
// - what the chain sandbox does not build is refused in one line.
#include "check.h"

#include "chain.h"
#include "crane_chain.h"
#include "engine.h"
#include "model.h"
#include "ode_chain.h"
#include "ode_run.h"
#include "ode_world.h"
#include "scenario.h"
#include "sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DATA CRANESIM_TESTDATA
#define PI 3.14159265358979323846

// Every row of a run, all columns.
typedef struct rows {
    long n, cap;
    int ncol;
    double* v;
} rows;

static int on_row(void* user, const double* row) {
    rows* r = user;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 8192;
        r->v = realloc(r->v, (size_t)r->cap * (size_t)r->ncol * sizeof *r->v);
    }
    memcpy(r->v + (size_t)r->n * (size_t)r->ncol, row, (size_t)r->ncol * sizeof *row);
    ++r->n;
    return 0;
}

static int run(const model* m, const char* scn, const char* world, rows* r, sim_result* res) {
    scenario sc;
    char err[512];
    CHECK(scenario_load(scn, &sc, err, sizeof err) == 0, "scenario: %s", err);
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = world;
    o.no_step_probe = true;
    memset(r, 0, sizeof *r);
    r->ncol = sim_ncol(&o) + m->chain.ncol;
    engine_sink k = {.row = on_row, .user = r, .rows = true, .summary = true};
    k.t_end = sc.duration;
    memset(res, 0, sizeof *res);
    const int rc = engine_run(m, &sc, &o, &k, res);
    return rc;
}

static double at(const rows* r, long i, int c) { return r->v[(size_t)i * (size_t)r->ncol + (size_t)c]; }

static model* load(const char* path) {
    char err[1024];
    model* m = model_load(path, NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    return m;
}

// ---- 1. the default crane as a chain against the two-link sandbox ----

static void chain_vs_two_link(const char* scn, double tol_x, double tol_slew, double tol_hook) {
    model* mc = load(DATA "/hiab031_chain.json");
    model* mt = load(CRANESIM_ASSETS "/models/hiab031.json");
    if (!mc || !mt) return;
    CHECK(!mc->chain.two_link && mt->chain.two_link, "the chain form is not two_link");
    rows a, b;
    sim_result ra, rb;
    CHECK(run(mc, scn, "sandbox", &a, &ra) == SIM_OK, "chain: %s", ra.message);
    CHECK(run(mt, scn, "sandbox", &b, &rb) == SIM_OK, "two-link: %s", rb.message);
    CHECK(a.n == b.n && a.n > 1000, "rows %ld, %ld", a.n, b.n);
    const int cols[] = {COL_X1, COL_X2, COL_X3, COL_SLEW, COL_HOOK_X, COL_HOOK_Y, COL_HOOK_Z, COL_LOAD_X, COL_LOAD_Y,
                        COL_LOAD_Z, COL_ATTACHED, COL_P1A, COL_P2A, COL_P3A, COL_PAD_F1, COL_STAB_MARGIN};
    const char* names[] = {"x1", "x2", "x3", "slew", "hook_x", "hook_y", "hook_z", "load_x", "load_y", "load_z",
                           "attached", "p1A", "p2A", "p3A", "pad_F1", "stab_margin"};
    const int nc = (int)(sizeof cols / sizeof cols[0]);
    double d[32] = {0}, ref[32] = {0};
    const long n = a.n < b.n ? a.n : b.n;
    for (long i = 0; i < n; ++i)
        for (int c = 0; c < nc; ++c) {
            d[c] = fmax(d[c], fabs(at(&a, i, cols[c]) - at(&b, i, cols[c])));
            ref[c] = fmax(ref[c], fabs(at(&b, i, cols[c])));
        }
    for (int c = 0; c < nc; ++c) printf("  %-12s max |chain - two-link| %.3g (max |two-link| %.3g)\n", names[c], d[c], ref[c]);
    CHECK(d[0] <= tol_x && d[1] <= tol_x && d[2] <= tol_x, "strokes differ by %g, %g, %g m", d[0], d[1], d[2]);
    CHECK(d[3] <= tol_slew, "slew differs by %g rad", d[3]);
    CHECK(d[4] <= tol_hook && d[5] <= tol_hook && d[6] <= tol_hook, "hook differs by %g, %g, %g m", d[4], d[5], d[6]);
    CHECK(d[7] <= tol_hook && d[8] <= tol_hook && d[9] <= tol_hook, "load differs by %g, %g, %g m", d[7], d[8], d[9]);
    CHECK(d[10] == 0, "the hook held a different load");
    // Pressures: the strokes' agreement over the cylinders' stiffness
    // (1 um of a 0.1 m bore's oil column is about 10 kPa); supports likewise.
    CHECK(d[11] <= 1e-3 * ref[11] && d[12] <= 1e-3 * ref[12] && d[13] <= 1e-3 * ref[13], "pressures %g %g %g Pa",
          d[11], d[12], d[13]);
    CHECK(d[14] <= 1e-3 * ref[14], "pad force %g N", d[14]);
    CHECK(d[15] <= 1e-5, "stability margin %g", d[15]);
    free(a.v);
    free(b.v);
    model_free(mc);
    model_free(mt);
}

// The same crane, the same physics: hinges, pins, forces and rack are the
// same numbers in another order. What is left is round-off that ODE's
// solver, fed its bodies and joints in another order (the chain creates
// the slew hinge first, the two-link world last), carries from step to
// step: on these smooth ramps 1.1e-6 m in the strokes, 1.1e-7 rad in the
// slew, 5.8e-6 m at the hook (measured); the pick-and-place, with its hook
// contacts, 1.7e-6 m, 5e-6 rad and 4.1e-4 m at the hook as it lets go of
// the load on the stack (contacts amplify the ordering). The bounds are
// ten times those. (On sandbox_swing, valve steps that throw the empty
// hook to 83 deg of sway, the same round-off grows to 0.25 mm and 7 cm: a
// chaotic pendulum, not a bound worth a test.)
static void test_default_crane_lift_jib_slew(void) { chain_vs_two_link(DATA "/sandbox_lift_jib_slew.json", 1e-5, 1e-6, 6e-5); }
static void test_default_crane_pick_place(void) {
    chain_vs_two_link(CRANESIM_ASSETS "/scenarios/sandbox_pick_place.json", 2e-5, 5e-5, 4e-3);
}

// ---- 2. a load picked up: the cylinder forces against statics ----

static int solve(int n, double* A, double* b) {
    for (int c = 0; c < n; ++c) {
        int p = c;
        for (int r = c + 1; r < n; ++r)
            if (fabs(A[r * n + c]) > fabs(A[p * n + c])) p = r;
        if (!(fabs(A[p * n + c]) > 1e-12)) return -1;
        for (int j = 0; j < n; ++j) {
            const double t = A[c * n + j];
            A[c * n + j] = A[p * n + j], A[p * n + j] = t;
        }
        const double t = b[c];
        b[c] = b[p], b[p] = t;
        for (int r = c + 1; r < n; ++r) {
            const double f = A[r * n + c] / A[c * n + c];
            for (int j = c; j < n; ++j) A[r * n + j] -= f * A[c * n + j];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; --c) {
        double s = b[c];
        for (int j = c + 1; j < n; ++j) s -= A[c * n + j] * b[j];
        b[c] = s / A[c * n + c];
    }
    return 0;
}

static void test_pick_statics(void) {
    model* m = load(DATA "/chain_3boom_ext.json");
    if (!m) return;
    char err[1024] = "";
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = DATA "/sandbox_chain_pick.json";
    const double q12[2] = {150 * PI / 180, -100 * PI / 180};
    ode_world* w = ode_world_for_run(m, &o, "sandbox", q12, 0.0, 0.0, err, sizeof err);
    CHECK(w != NULL, "world: %s", err);
    if (!w) {
        model_free(m);
        return;
    }
    ode_chain* cw = ode_world_chain(w);
    CHECK(cw != NULL, "the sandbox's crane is not the chain");
    const crane_chain* cc = ode_chain_chain(cw);
    const int nd = ode_chain_ndof(cw), na = ode_chain_nact(cw), nf = ode_chain_nfn(cw);
    CHECK(nd == 5 && na == 4 && nf == 4, "sizes %d %d %d", nd, na, nf);
    int lift = crane_chain_find_function(cc, "lift");
    double u[8] = {0}, q[8], qm[8] = {0}, Fm[8] = {0};
    const double dt = ode_world_dt(w);
    int attached = -1, nmean = 0;
    ode_world_state st;
    double load0[3], load1[3];
    ode_world_load_state(w, 0, load0, NULL);
    // Hook the load at 0.5 s, lift it 0.6 m (lift at 0.2 from 1 to 2.7 s on
    // ramps), then hold: the rope's pendulum (1.5 m, 2.5 s) and the booms
    // settle; the forces are averaged over 6..14 s.
    for (long s = 0; s < (long)(14.0 / dt + 0.5); ++s) {
        const double t = (s + 0.5) * dt;
        if (s == (long)(0.5 / dt)) attached = ode_world_hook(w, 1);
        u[lift] = t < 1.0 ? 0.0 : t < 1.5 ? 0.4 * (t - 1.0) : t < 2.2 ? 0.2 : t < 2.7 ? 0.2 - 0.4 * (t - 2.2) : 0.0;
        ode_chain_set_commands(cw, u);
        if (ode_world_step(w, dt)) {
            CHECK(0, "step: %s", ode_world_error(w));
            break;
        }
        if (t < 6.0) continue;
        ode_chain_q(cw, q, NULL);
        for (int k = 0; k < nd; ++k) qm[k] += q[k];
        for (int k = 0; k < na; ++k) Fm[k] += ode_chain_act_force(cw, k, NULL, NULL);
        ++nmean;
    }
    CHECK(attached == 0, "the hook did not take the load (%d)", attached);
    ode_world_load_state(w, 0, load1, NULL);
    printf("  the load rose %.3f m\n", load1[2] - load0[2]);
    CHECK(load1[2] - load0[2] > 0.3, "the load rose only %g m", load1[2] - load0[2]);
    ode_world_get_state(w, &st);
    CHECK(st.attached == 0 && st.stab_margin > 1 && st.stab_margin < ODE_STAB_MARGIN_MAX, "attached %d, margin %g",
          st.attached, st.stab_margin);
    CHECK(st.pad_lifted == 0, "a support lifted off: %d", st.pad_lifted);
    for (int k = 0; k < nd; ++k) qm[k] /= nmean;
    for (int k = 0; k < na; ++k) Fm[k] /= nmean;
    // Statics: the mechanism with the load, the hook and the rope as a point
    // mass at the tip (they hang from it at rest), its gravity load G(q) at
    // the mean pose; the cylinders' forces F with sum_k F_k dL_k/dq_j = G_j
    // over the four boom DOFs (the slew carries no gravity on level ground;
    // the truck tilts by 4e-4 rad, a 0.04 % change of G).
    int n;
    double len, lm, li, hm, hc, hi, lmass;
    ode_world_rope_info(w, &n, &len, &lm, &li, &hm, &hc, &hi);
    ode_world_load_name(w, 0, &lmass);
    const double m_tip = lmass + hm + n * lm;
    chain* c = crane_chain_mechanism(cc, m_tip, true, qm[0], err, sizeof err);
    CHECK(c != NULL, "mechanism: %s", err);
    if (c) {
        chain_ws* ws = chain_ws_create(c);
        chain_update(c, ws, qm, NULL);
        double G[8], A[16], dL[8];
        chain_inverse_dynamics(c, ws, NULL, CHAIN_GRAVITY, G);
        for (int k = 0; k < na; ++k) {
            const crane_act* a = &cc->act[k];
            chain_cylinder(c, ws, a->body_a, a->pa, a->body_b, a->pb, NULL, dL, NULL);
            for (int j = 0; j < 4; ++j) A[j * 4 + k] = dL[1 + j];
        }
        double F[4] = {G[1], G[2], G[3], G[4]};
        CHECK(solve(4, A, F) == 0, "lever arms dependent");
        printf("  slew gravity load %.3g N m (level ground: 0)\n", G[0]);
        for (int k = 0; k < na; ++k) {
            printf("  %-5s held by %10.1f N, statics %10.1f N (%.3f %%)\n", cc->act[k].name, Fm[k], F[k],
                   100 * (Fm[k] - F[k]) / fabs(F[k]));
        }
        // Averaged over 8 s the sway's and the solver's ripple cancel: held
        // and statics agree to 24 N of the lift's 82 kN and 2 N of the
        // extension's 0.9 kN (measured; the seal friction at the creep rates
        // left, below 0.1 mm/s, and the truck's 4e-4 rad tilt are of that
        // order). Bound: 0.2 % of the largest force, 165 N, for each
        // cylinder; a cylinder holding the load's weight alone, or the
        // booms' without it, is off by kilonewtons.
        const double Fmax = fmax(fmax(fabs(F[0]), fabs(F[1])), fmax(fabs(F[2]), fabs(F[3])));
        for (int k = 0; k < na; ++k)
            CHECK(fabs(Fm[k] - F[k]) <= 0.002 * Fmax, "%s: %g N held, statics %g N", cc->act[k].name, Fm[k], F[k]);
        chain_ws_free(ws);
        chain_free(c);
        // The same mass as a tip load in the validation world (the chain
        // world on the ground, the column fixed at the slew, the load merged
        // into the tip body) at the sandbox's mean pose, valves closed: its
        // cylinders hold it with the same forces as the hook's load.
        ode_chain_opts vo = ode_chain_default_opts();
        vo.tip_mass = m_tip;
        vo.q0 = qm + 1; // the boom DOFs (the model's column does not slew)
        vo.slew0 = qm[0];
        vo.circuit = m->hyd;
        vo.p_low = 0.5e6;
        vo.model_file = "chain_3boom_ext.json";
        CHECK(!m->chain.slew_free && crane_chain_ndof(&m->chain) == nd - 1, "the model's column is fixed");
        ode_chain* vw = ode_chain_create(&m->chain, &vo, err, sizeof err);
        CHECK(vw != NULL, "validation: %s", err);
        if (vw) {
            double Fv[8] = {0};
            const double zero[8] = {0};
            ode_chain_set_commands(vw, zero);
            int nv = 0;
            for (int s = 0; s < 3000; ++s) {
                if (ode_chain_step(vw, 1e-3)) {
                    CHECK(0, "validation step: %s", ode_chain_error(vw));
                    break;
                }
                if (s < 1000) continue;
                for (int k = 0; k < na; ++k) Fv[k] += ode_chain_act_force(vw, k, NULL, NULL);
                ++nv;
            }
            for (int k = 0; k < na; ++k) {
                Fv[k] /= nv;
                printf("  %-5s tip load in the validation world %10.1f N, hook load in the sandbox %10.1f N\n",
                       cc->act[k].name, Fv[k], Fm[k]);
                CHECK(fabs(Fv[k] - Fm[k]) <= 0.002 * Fmax, "%s: %g N validation, %g N sandbox", cc->act[k].name,
                      Fv[k], Fm[k]);
            }
        }
        ode_chain_destroy(vw);
    }
    {
        // The picture: every chain body drawn under its name, at its pose;
        // every actuator's cylinder and then the slew's rack between their
        // pins (the snapshot holds 16: issue 27); the rope from the tip to
        // the hook.
        static world_snapshot snap;
        ode_world_snapshot(w, &snap);
        for (int i = 0; i < cc->nbody; ++i) {
            int found = -1;
            for (int j = 0; j < snap.nbody; ++j)
                if (!strcmp(snap.body[j].name, cc->body[i].def.name)) found = j;
            CHECK(found >= 0, "body %s not drawn", cc->body[i].def.name);
            if (found < 0) continue;
            // The primitive's centre: half the length from the joint along
            // the body's x (the column: along z).
            double R[9], p[3];
            ode_chain_body_pose(cw, i, R, p);
            const double h = 0.5 * cc->body[i].length;
            for (int k = 0; k < 3; ++k)
                CHECK_NEAR(snap.body[found].pos[k], p[k] + h * R[3 * k + (i == 0 ? 2 : 0)], 1e-9);
        }
        CHECK(snap.ncyl == cc->nact + 1, "cylinders drawn: %d for %d actuators and the rack", snap.ncyl, cc->nact);
        for (int k = 0; k < cc->nact && k < snap.ncyl; ++k) {
            double pa[3], pb[3];
            ode_chain_act_pins(cw, k, pa, pb);
            CHECK(!strcmp(snap.cyl[k].name, cc->act[k].name), "cylinder %d is %s", k, snap.cyl[k].name);
            for (int j = 0; j < 3; ++j) {
                CHECK_NEAR(snap.cyl[k].base[j], pa[j], 1e-12);
                CHECK_NEAR(snap.cyl[k].rod_end[j], pb[j], 1e-12);
            }
        }
        CHECK(snap.ncyl == cc->nact + 1 && !strcmp(snap.cyl[cc->nact].name, "slew"), "the slew's rack");
        double tip[3];
        ode_chain_tip(cw, tip, NULL);
        CHECK(snap.nrope >= 2, "rope points %d", snap.nrope);
        for (int j = 0; j < 3; ++j) CHECK_NEAR(snap.tip[j], tip[j], 1e-12);
        // The rope's top joint at the tip (ODE's joint error: well below 1 mm).
        if (snap.nrope >= 2)
            CHECK(hypot(hypot(snap.rope[0][0] - tip[0], snap.rope[0][1] - tip[1]), snap.rope[0][2] - tip[2]) < 1e-3,
                  "rope top %g %g %g, tip %g %g %g", snap.rope[0][0], snap.rope[0][1], snap.rope[0][2], tip[0], tip[1],
                  tip[2]);
        CHECK(snap.attached == 1, "the snapshot's hook holds no load");
    }
    ode_world_destroy(w);
    model_free(m);
}

// ---- 3. every function and the slew: the chain's columns, named collisions ----

static void test_every_function(void) {
    model* m = load(DATA "/chain_3boom_ext.json");
    if (!m) return;
    rows r;
    sim_result res;
    CHECK(run(m, DATA "/chain_3boom_ext_sandbox.json", "sandbox", &r, &res) == SIM_OK, "run: %s", res.message);
    const crane_chain* cc = &m->chain;
    CHECK(cc->ncol > 0 && r.n == 14001, "columns %d, rows %ld", cc->ncol, r.n);
    const int base = r.ncol - cc->ncol;
    // Every actuator's stroke moved, and its column equals what the base
    // columns say for the first two.
    for (int k = 0; k < cc->nact; ++k) {
        char want[64];
        snprintf(want, sizeof want, "x_%s", cc->act[k].name);
        const int c = crane_chain_find_column(cc, "x", cc->act[k].name);
        const int col = c < 0 ? -1 : base + c;
        CHECK(col >= 0, "no column %s", want);
        if (col < 0) continue;
        double lo = INFINITY, hi = -INFINITY;
        for (long i = 0; i < r.n; ++i) lo = fmin(lo, at(&r, i, col)), hi = fmax(hi, at(&r, i, col));
        printf("  %-6s stroke %.4f..%.4f m\n", cc->act[k].name, lo, hi);
        CHECK(hi - lo > 0.02, "%s moved %g m only", cc->act[k].name, hi - lo);
        if (k < 2)
            for (long i = 0; i < r.n; i += 97)
                CHECK_NEAR(at(&r, i, col), at(&r, i, k ? COL_X2 : COL_X1), 1e-12);
    }
    double smax = 0;
    for (long i = 0; i < r.n; ++i) smax = fmax(smax, fabs(at(&r, i, COL_SLEW)));
    CHECK(smax > 0.5, "the column slewed %g rad only", smax);
    // The slewing end arm meets the wall by the column (this scenario's
    // slew out): the pair is named after the chain's body.
    int named = 0;
    for (int i = 0; i < res.coll.npair; ++i) {
        printf("  collision %s\n", res.coll.pair[i]);
        for (int b = 0; b < cc->nbody; ++b) {
            const size_t l = strlen(cc->body[b].def.name);
            if (!strncmp(res.coll.pair[i], cc->body[b].def.name, l) && !strncmp(res.coll.pair[i] + l, " x ", 3))
                named = 1;
        }
    }
    CHECK(res.coll.have && named, "no collision of a chain body named (%d pairs)", res.coll.npair);
    free(r.v);
    model_free(m);
}

// ---- 4. refusals ----

static void test_refusals(void) {
    model* m = load(DATA "/chain_3boom_ext.json");
    if (!m) return;
    char err[512];
    world_desc wd;
    world_desc_default(&wd, WORLD_VALIDATION);
    ode_world_opts wo = ode_world_default_opts();
    wo.chain = &m->chain;
    wo.circuit = m->hyd;
    wo.model_file = "chain_3boom_ext.json";
    ode_world* w = ode_world_create(&m->mech, NULL, &wd, &wo, err, sizeof err);
    CHECK(w == NULL && strstr(err, "validation world is the ODE chain world") && !strchr(err, '\n'), "%s", err);
    ode_world_destroy(w);
    world_desc_default(&wd, WORLD_SANDBOX);
    wo.hydraulics = 0;
    w = ode_world_create(&m->mech, NULL, &wd, &wo, err, sizeof err);
    CHECK(w == NULL && strstr(err, "with its circuit only") && !strchr(err, '\n'), "%s", err);
    ode_world_destroy(w);
    wo.hydraulics = 1;
    wo.solver = HYD_ROS34PW2;
    w = ode_world_create(&m->mech, NULL, &wd, &wo, err, sizeof err);
    CHECK(w == NULL && strstr(err, "is adaptive") && !strchr(err, '\n'), "%s", err);
    ode_world_destroy(w);
    model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_default_crane_lift_jib_slew);
    RUN_TEST(test_default_crane_pick_place);
    RUN_TEST(test_pick_statics);
    RUN_TEST(test_every_function);
    RUN_TEST(test_refusals);
    TEST_MAIN_END();
}
