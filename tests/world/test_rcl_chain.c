// test_rcl_chain.c: the rated capacity limiter and the load chart on a crane
// chain (issue 27 item 3; docs/safety.md "On a crane chain"), on the second
// shipped crane, assets/models/loader10.json:
// - the sign (and size) of each function's outreach per metre of stroke,
//   which the limiter cuts on, against central differences of the chain's
//   kinematics (the mechanism library's tip and pin lengths, solved here for
//   a stroke of the function's cylinders, independent of rcl.c);
// - an overload with the extensions run out (the limiter off while they
//   run out, then on): the functions that carry the tip outwards are cut
//   (spool command 0, strokes stay within 2 mm over 1 s), the reducing ones
//   pass whole and move, on the analytic mode's and the ODE's stepped engine;
// - the load the limiter reads from the lift pressure against the load put
//   at the tip, held still (the chart's check by simulation is in
//   test_loadchart_chain.c).
#include "check.h"
#include "engine.h"
#include "engine_impl.h"
#include "lc_chain.h"
#include "loadchart.h"
#include "model.h"
#include "rcl.h"
#include "scenario.h"
#include "sim.h"

#include <cJSON.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MODEL CRANESIM_ASSETS "/models/loader10.json"
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180)

static model* load(void) {
    char err[1024];
    model* m = model_load(MODEL, NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    return m;
}

// The tip's outreach [m] at boom pose q (the mechanism's own kinematics).
static double tip_R(chain* ch, chain_ws* w, const crane_chain* cc, const double* q) {
    chain_update(ch, w, q, NULL);
    double p[3];
    chain_world_point(ch, w, cc->tip_body, cc->tip, p, NULL);
    return p[0] - cc->body[0].def.origin[0];
}

// Pin length of actuator k at pose q [m], through crane_act_length: a
// linkage's (loader10's jib) is its barrel pin to the loop's common pin, which
// a pin pair (chain_cylinder with pb) does not give (pb is unused, 0, for a
// linkage: that is the knuckle's joint, which does not move with the knuckle).
static double pin_L(chain* ch, chain_ws* w, const crane_chain* cc, int k, const double* q) {
    chain_update(ch, w, q, NULL);
    return crane_act_length(&cc->act[k], ch, w, NULL, NULL, NULL);
}

// Solves A x = b (n x n, row-major) by Gaussian elimination with pivoting; 0 or -1.
static int solve(double* A, double* b, int n) {
    for (int c = 0; c < n; ++c) {
        int p = c;
        for (int i = c + 1; i < n; ++i)
            if (fabs(A[i * n + c]) > fabs(A[p * n + c])) p = i;
        if (fabs(A[p * n + c]) < 1e-12) return -1;
        for (int j = 0; j < n; ++j) {
            const double t = A[c * n + j];
            A[c * n + j] = A[p * n + j], A[p * n + j] = t;
        }
        const double t = b[c];
        b[c] = b[p], b[p] = t;
        for (int i = c + 1; i < n; ++i) {
            const double f = A[i * n + c] / A[c * n + c];
            for (int j = c; j < n; ++j) A[i * n + j] -= f * A[c * n + j];
            b[i] -= f * b[c];
        }
    }
    for (int i = n - 1; i >= 0; --i) {
        double v = b[i];
        for (int j = i + 1; j < n; ++j) v -= A[i * n + j] * b[j];
        b[i] = v / A[i * n + i];
    }
    return 0;
}

// dR/ds of function f at pose q by central differences: the joint motion dq
// that strokes each of f's cylinders by h and leaves the others' lengths as
// they are (dL/dq of every cylinder over every boom joint by central
// differences of the pin lengths), then R(q + dq) - R(q - dq) over 2 h.
static double fd_gain(chain* ch, chain_ws* w, const crane_chain* cc, const double* q0, int nd, int f) {
    const int na = cc->nact;
    const double e = 1e-6, h = 1e-5;
    double A[64], b[8], qp[8], qm[8];
    for (int k = 0; k < na; ++k) {
        for (int j = 0; j < nd; ++j) {
            memcpy(qp, q0, (size_t)nd * sizeof *q0), memcpy(qm, q0, (size_t)nd * sizeof *q0);
            qp[j] += e, qm[j] -= e;
            A[k * nd + j] = (pin_L(ch, w, cc, k, qp) - pin_L(ch, w, cc, k, qm)) / (2 * e);
        }
        b[k] = cc->act[k].function == f ? h : 0.0;
    }
    if (na != nd || solve(A, b, nd)) return NAN;
    for (int j = 0; j < nd; ++j) qp[j] = q0[j] + b[j], qm[j] = q0[j] - b[j];
    return (tip_R(ch, w, cc, qp) - tip_R(ch, w, cc, qm)) / (2 * h);
}

// The limiter's gain of every function against the central differences, at
// poses over the joints' ranges: the knuckle hanging down and back, level,
// raised; the extensions in, half, out.
static void test_gain_against_central_differences(void) {
    model* m = load();
    if (!m) return;
    const crane_chain* cc = &m->chain;
    char err[300];
    rcl r;
    CHECK(rcl_init(&r, m, NULL, err, sizeof err) == 0, "%s", err);
    const int base = SIM_NCOL_BASE;
    CHECK(rcl_set_chain_row(&r, NULL, base) == 0, "the chain's columns");
    chain* ch = crane_chain_mechanism(cc, 0.0, false, 0.0, err, sizeof err);
    chain_ws* w = ch ? chain_ws_create(ch) : NULL;
    CHECK(ch && w, "%s", err);
    const int nd = chain_ndof(ch);
    CHECK(nd == 4, "loader10 has 4 boom joints, got %d", nd);
    double* row = calloc((size_t)(base + cc->ncol) + 1, sizeof *row);
    // The poses at fractions of each joint's limits as the model gives them
    // (a linkage's loop closes only within its knuckle's range): the lift
    // low, middle, high; the knuckle folded back past the vertical to
    // pointing out; the extensions in, half, out.
    double lim[4][2];
    for (int j = 0; j < nd; ++j) {
        const chain_body_def* d = &cc->body[chain_dof_body(ch, j)].def;
        CHECK(isfinite(d->q_min) && isfinite(d->q_max) && d->q_min < d->q_max, "DOF %d (%s) has limits", j,
              d->name);
        lim[j][0] = d->q_min, lim[j][1] = d->q_max;
    }
    const double flift[3] = {0.1, 0.45, 0.9}, fknuckle[4] = {0.1, 0.35, 0.65, 0.9}, fext_[3] = {0.04, 0.5, 0.96};
#define AT(j, f) (lim[j][0] + (f) * (lim[j][1] - lim[j][0]))
    int n = 0, nout = 0, nin = 0, nposes = 0, fext = crane_chain_find_function(cc, "ext");
    double worst = 0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 4; ++b)
            for (int c = 0; c < 3; ++c) {
                const double q[4] = {AT(0, flift[a]), AT(1, fknuckle[b]), AT(2, fext_[c]), AT(3, fext_[c])};
                // A pose of the crane: every stroke within its range.
                bool ok = true;
                for (int k = 0; k < cc->nact; ++k) {
                    const double x = pin_L(ch, w, cc, k, q) - cc->act[k].closed_length;
                    ok = ok && isfinite(x) && x >= 0 && x <= cc->act[k].stroke;
                }
                if (!ok) continue;
                ++nposes;
                for (int j = 0; j < nd; ++j)
                    row[base + crane_chain_find_column(cc, "q", cc->body[chain_dof_body(ch, j)].def.name)] = q[j];
                for (int f = 0; f < cc->nfn; ++f) {
                    const double g = rcl_function_gain(&r, row, f), fd = fd_gain(ch, w, cc, q, nd, f);
                    ++n;
                    if (fabs(fd) < 2e-3) continue; // neutral within the limiter's 1 mm/m band: either is right
                    CHECK(g * fd > 0, "pose %.0f %.0f deg, ext %.2f m: function %s: limiter %+.4f, central "
                                      "differences %+.4f m/m",
                          q[0] / DEG, q[1] / DEG, q[2], cc->fn[f].name, g, fd);
                    worst = fmax(worst, fabs(g - fd) / fabs(fd));
                    if (f == fext) nout += fd > 0, nin += fd < 0;
                }
            }
    // Both signs met: with the knuckle pointing out the extension carries the
    // tip out; folded back past the vertical it brings it in.
#undef AT
    CHECK(nout > 0 && nin > 0, "the extension's gain of both signs over the poses (%d out, %d in)", nout, nin);
    // Most of the 36 poses are the crane's (strokes within range): a check
    // that skipped them all would not be one.
    CHECK(nposes >= 18, "%d of 36 sampled poses within every stroke", nposes);
    CHECK(worst < 1e-4, "largest relative difference %.3g", worst);
    printf("gain: %d poses, %d function-poses, largest relative difference to central differences %.2g; extension "
           "outwards at %d poses, inwards at %d\n",
           nposes, n, worst, nout, nin);
    free(row);
    chain_ws_free(w);
    chain_free(ch);
    rcl_free(&r);
    model_free(m);
}

typedef struct cols {
    int base, x[8];
} cols;

// The overload: loader10 at lift 100 deg, knuckle -40 deg (pointing 30 deg
// down), the extensions half out at the start; a tip load that is 115 % of
// the chart's capacity where the extensions reach 1.1 m each. The limiter
// off, the extensions run out to 1.1 m (the load over the chart on the way:
// nothing stops them); then on.
static void test_overload_extended(sim_mechanics mech) {
    const char* bn = mech == SIM_ODE ? "ode" : "lagrange";
    model* m = load();
    if (!m) return;
    const crane_chain* cc = &m->chain;
    char err[600];
    sim_opts o = sim_default_opts();
    o.mechanics = mech;
    o.no_step_probe = true;
    o.rcl = true;
    // The capacity at the pose the test drives to (no world: no truck, the
    // chart's hydraulic limit and the rating).
    rcl r0;
    CHECK(rcl_init(&r0, m, NULL, err, sizeof err) == 0, "%s", err);
    lc_chain g;
    CHECK(lc_chain_init(&g, m, "test", err, sizeof err) == 0, "%s", err);
    const double qt[4] = {100 * DEG, -40 * DEG, 1.1, 1.1};
    double Rt;
    lc_chain_eval(&g, qt, &Rt, NULL);
    const double cap = loadchart_capacity(&r0.chart, Rt, 0.0, NULL), m3 = 1.15 * cap;
    lc_chain_free(&g);
    const double q0[2] = {100 * DEG, -40 * DEG};
    engine* e = engine_create(m, &o, q0, 0.0, m3, err, sizeof err);
    CHECK(e != NULL, "%s: %s", bn, err);
    if (!e) {
        rcl_free(&r0);
        model_free(m);
        return;
    }
    CHECK(engine_caps(e) & ENGINE_CAP_LIMITER, "%s: the chain engine has the limiter", bn);
    CHECK(engine_rcl(e) != NULL, "%s: the limiter was made", bn);
    const int nfn = engine_nfunction(e), ncol = engine_ncol(e), base = ncol - cc->ncol;
    double* row = calloc((size_t)ncol + 1, sizeof *row);
    double u[8] = {0};
    int ix[8];
    for (int k = 0; k < cc->nact; ++k) ix[k] = base + crane_chain_find_column(cc, "x", cc->act[k].name);
    const int fl = engine_find_function(e, "lift"), fj = engine_find_function(e, "jib"),
              fe = engine_find_function(e, "ext");
    const int ke1 = crane_chain_find_act(cc, "ext1");
    // Run the extensions out with the limiter off (measuring only).
    e->o.rcl = false;
    double t = 0;
    for (int i = 0; i < 400; ++i) {
        engine_row(e, row);
        if (row[ix[ke1]] >= 1.1) break;
        u[fe] = 0.6;
        engine_set_function_commands(e, u, nfn, err, sizeof err);
        t += 0.025;
        CHECK(engine_advance_to(e, t, NULL, NULL) == 0, "%s: %s", bn, engine_error(e));
    }
    u[fe] = 0;
    engine_set_function_commands(e, u, nfn, err, sizeof err);
    t += 1.0;
    CHECK(engine_advance_to(e, t, NULL, NULL) == 0, "%s: %s", bn, engine_error(e));
    engine_row(e, row);
    const double x_e1 = row[ix[ke1]];
    CHECK(x_e1 > 1.05, "%s: ext1 ran out to %.3f m", bn, x_e1);
    const rcl* r = engine_rcl(e);
    CHECK(r->util >= 1.0, "%s: overloaded: util %.3f at %.2f m (load %.0f kg, chart %.0f kg)", bn, r->util, r->R, m3,
          cap);
    // Against the chart of the engine's world (no truck: the validation
    // world), not the backend's drive world (the sandbox's truck).
    CHECK_REL(r->util, r->m_filt / loadchart_capacity(&r0.chart, r->R, 0.0, NULL), 1e-9);
    rcl_free(&r0);
    // The measured load against the load at the tip (the lift pressure,
    // its lever and the booms' gravity: the booms still, the seals' friction
    // within its band).
    CHECK_REL(r->m_filt, m3, 0.05);
    printf("%s: at %.2f m util %.3f, the lift pressure reads %.1f kg for %.1f kg at the tip\n", bn, r->R, r->util,
           r->m_filt, m3);
    e->o.rcl = true;
    // Each function each way from here, 1 s each, increasing ones first.
    const int fs[3] = {fl, fj, fe};
    double gain[3];
    for (int i = 0; i < 3; ++i) gain[i] = rcl_function_gain((rcl*)r, row, fs[i]);
    CHECK(gain[2] > 0, "%s: the extension carries the tip out here (%.3f m/m)", bn, gain[2]);
    for (int pass = 0; pass < 2; ++pass)
        for (int i = 0; i < 3; ++i) {
            const double dir = (pass == 0) == (gain[i] > 0) ? 1.0 : -1.0; // pass 0: outwards
            if (gain[i] == 0) continue;
            double x0[8];
            engine_row(e, row);
            for (int k = 0; k < cc->nact; ++k) x0[k] = row[ix[k]];
            memset(u, 0, sizeof u);
            u[fs[i]] = dir;
            double moved = 0;
            bool cut_ok = true;
            for (int s = 0; s < 40; ++s) { // a command each frame, as a driver sets it
                engine_set_function_commands(e, u, nfn, err, sizeof err);
                if (pass == 0) cut_ok = cut_ok && e->u_lim[fs[i]] == 0.0;
                else cut_ok = cut_ok && e->u_lim[fs[i]] == dir;
                t += 0.025;
                CHECK(engine_advance_to(e, t, NULL, NULL) == 0, "%s: %s", bn, engine_error(e));
            }
            engine_row(e, row);
            for (int k = 0; k < cc->nact; ++k)
                if (cc->act[k].function == fs[i]) moved = fmax(moved, dir * (row[ix[k]] - x0[k]));
            memset(u, 0, sizeof u);
            engine_set_function_commands(e, u, nfn, err, sizeof err);
            t += 0.5;
            CHECK(engine_advance_to(e, t, NULL, NULL) == 0, "%s: %s", bn, engine_error(e));
            if (pass == 0) {
                CHECK(cut_ok, "%s: %s %+.0f (outwards) cut to 0 at every frame", bn, cc->fn[fs[i]].name, dir);
                CHECK(fabs(moved) < 2e-3, "%s: %s outwards: stroke moved %.4f m", bn, cc->fn[fs[i]].name, moved);
            } else {
                CHECK(cut_ok, "%s: %s %+.0f (inwards) passes whole", bn, cc->fn[fs[i]].name, dir);
                CHECK(moved > 5e-3, "%s: %s inwards: stroke moved %.4f m", bn, cc->fn[fs[i]].name, moved);
            }
            printf("%s: %s %+.0f (%s): stroke %+.4f m, util %.3f\n", bn, cc->fn[fs[i]].name, dir,
                   pass ? "inwards, passes" : "outwards, cut", moved, engine_rcl(e)->util);
        }
    free(row);
    engine_destroy(e);
    model_free(m);
}

typedef struct srows {
    int ix, ncol;
    double x0, xmax, xmin, umax;
    long n;
} srows;

static int keep_row(void* user, const double* row) {
    srows* r = user;
    if (!r->n++) r->x0 = row[r->ix];
    r->xmax = fmax(r->xmax, row[r->ix] - r->x0);
    r->xmin = fmin(r->xmin, row[r->ix] - r->x0);
    r->umax = fmax(r->umax, row[COL_RCL_UTIL]);
    return 0;
}

// The scripted ODE run (validation world; run --mechanics ode --rcl on):
// the scenario's extension out at 60 % for 1 s, then in at 60 % for 1.4 s,
// with 115 % of the chart's capacity at the tip: with the limiter it does
// not move out, comes in, and rcl_util reads the overload; without it
// (measuring nothing) it runs out.
static void test_scripted_ode_run(void) {
    model* m = load();
    if (!m) return;
    const crane_chain* cc = &m->chain;
    char err[600];
    rcl r0;
    CHECK(rcl_init(&r0, m, NULL, err, sizeof err) == 0, "%s", err);
    lc_chain g;
    CHECK(lc_chain_init(&g, m, "test", err, sizeof err) == 0, "%s", err);
    const double qs[4] = {100 * DEG, -40 * DEG, 0.65, 0.65}; // the start: the extensions mid-range
    double Rs;
    lc_chain_eval(&g, qs, &Rs, NULL);
    lc_chain_free(&g);
    const double m3 = 1.15 * loadchart_capacity(&r0.chart, Rs, 0.0, NULL);
    rcl_free(&r0);
    char text[600];
    snprintf(text, sizeof text,
             "{\"name\": \"ext_overload\", \"duration\": 3, \"load_mass\": %.1f, \"initial\": {\"q1_deg\": 100, "
             "\"q2_deg\": -40}, \"commands\": {\"ext\": [[0, 0], [0.5, 0], [0.6, 0.6], [1.5, 0.6], [1.6, -0.6], [3, -0.6]]}}",
             m3);
    cJSON* j = cJSON_Parse(text);
    scenario sc;
    CHECK(j && scenario_from_json(j, "test scenario", &sc, err, sizeof err) == 0, "%s", err);
    cJSON_Delete(j);
    for (int on = 1; on >= 0; --on) {
        sim_opts o = sim_default_opts();
        o.mechanics = SIM_ODE;
        o.world = "validation";
        o.no_step_probe = true;
        o.rcl = on;
        int nc;
        engine_channels_for(&o, &nc);
        srows rw = {.ix = nc + crane_chain_find_column(cc, "x", "ext1"), .ncol = nc + cc->ncol, .xmin = INFINITY};
        engine_sink k = {.row = keep_row, .user = &rw, .rows = true, .t_end = 3.0};
        sim_result res;
        memset(&res, 0, sizeof res);
        CHECK(engine_run(m, &sc, &o, &k, &res) == 0, "%s", res.message);
        printf("scripted ode, limiter %s, %.0f kg at %.2f m: ext1 runs out %.4f m, comes in to %.4f m, rcl_util max "
               "%.3f\n",
               on ? "on" : "off", m3, Rs, rw.xmax, rw.xmin, rw.umax);
        if (on) {
            CHECK(rw.xmax < 2e-3, "limiter on: the extension stays (%.4f m)", rw.xmax);
            CHECK(rw.xmin < -0.1, "limiter on: the extension comes in (%.4f m)", rw.xmin);
            CHECK(rw.umax >= 1.0 && rw.umax < 1.3, "limiter on: rcl_util %.3f", rw.umax);
        } else {
            CHECK(rw.xmax > 0.05, "limiter off: the extension runs out (%.4f m)", rw.xmax);
        }
    }
    model_free(m);
}

// The sandbox file with one load of `mass` [kg] at (x, y, z) [m] and no
// other (meshes left out: the test's world file is not beside them), written
// to path. 0, or -1.
static int sandbox_with_load(const char* path, double mass, const double pos[3]) {
    FILE* f = fopen(CRANESIM_ASSETS "/worlds/sandbox.json", "rb");
    if (!f) return -1;
    static char buf[1 << 17];
    const size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    cJSON* j = cJSON_Parse(buf);
    if (!j) return -1;
    cJSON_DeleteItemFromObject(j, "meshes");
    cJSON_DeleteItemFromObject(j, "loads");
    cJSON* loads = cJSON_AddArrayToObject(j, "loads");
    cJSON* L = cJSON_CreateObject();
    cJSON_AddStringToObject(L, "name", "test_load");
    cJSON_AddNumberToObject(L, "mass", mass);
    const double size[3] = {0.8, 0.8, 0.6};
    cJSON_AddItemToObject(L, "size", cJSON_CreateDoubleArray(size, 3));
    cJSON_AddItemToObject(L, "position", cJSON_CreateDoubleArray(pos, 3));
    cJSON_AddItemToArray(loads, L);
    char* text = cJSON_Print(j);
    cJSON_Delete(j);
    f = text ? fopen(path, "w") : NULL;
    const int rc = f && fputs(text, f) >= 0 ? 0 : -1;
    if (f) fclose(f);
    free(text);
    return rc;
}

// The stepped sandbox engine (drive's default world): loader10 slewed over
// the side (92 deg, 2 deg into the limiter's sector 90..116 deg) at lift 130
// deg, knuckle -50 deg, the extensions mid-range, a load of 115 % of the
// limiter's chart hooked in the air under the tip at t = 0; after 5 s (the
// rope takes it, the filter settles) the limiter reads over 1 and cuts the
// extension out, lets the slew towards the cab through (the rating governs
// the chart there in both sectors: slewing does not lower the capacity) and
// the extension in. The two extension
// cylinders share their valve's lines: with it closed, oil passes between
// them (one creeps out as the other goes in), so the extension is judged by
// the sum of their strokes.
static void test_sandbox_engine(void) {
    model* m = load();
    if (!m) return;
    const crane_chain* cc = &m->chain;
    char err[600];
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.no_step_probe = true;
    o.rcl = true;
    o.world = CRANESIM_ASSETS "/worlds/sandbox.json";
    const double q0[2] = {130 * DEG, -50 * DEG}, slew0 = 92 * DEG;
    // Where the hook hangs, and the chart there (no load yet).
    engine* e = engine_create(m, &o, q0, slew0, 0.0, err, sizeof err);
    CHECK(e != NULL && engine_rcl(e) != NULL, "%s", err);
    if (!e || !engine_rcl(e)) {
        if (e) engine_destroy(e);
        model_free(m);
        return;
    }
    double* row = calloc((size_t)engine_ncol(e) + 1, sizeof *row);
    CHECK(engine_advance_to(e, 0.001, NULL, NULL) == 0, "%s", engine_error(e)); // one ODE step: the hook's place
    engine_row(e, row);
    const double hook[3] = {row[COL_HOOK_X], row[COL_HOOK_Y], row[COL_HOOK_Z]};
    const double cap = loadchart_capacity(&engine_rcl(e)->chart, engine_rcl(e)->R, slew0, NULL);
    const double R0 = engine_rcl(e)->R;
    const double mass = 1.15 * cap, pos[3] = {hook[0], hook[1], hook[2] - 0.3 - 0.005};
    engine_destroy(e);
    free(row);
    const char* wpath = "rcl_chain_sandbox.json";
    CHECK(sandbox_with_load(wpath, mass, pos) == 0, "cannot write %s", wpath);
    o.world = wpath;
    e = engine_create(m, &o, q0, slew0, 0.0, err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (!e) {
        model_free(m);
        return;
    }
    char hmsg[200];
    CHECK(engine_hook_report(e, 1, hmsg, sizeof hmsg) == 0, "the load is hooked: %s", hmsg);
    const int nfn = engine_nfunction(e), ncol = engine_ncol(e), base = ncol - cc->ncol;
    const int fe = engine_find_function(e, "ext"), fs = engine_find_function(e, "slew");
    const int ix = base + crane_chain_find_column(cc, "x", "ext1"), ix2 = base + crane_chain_find_column(cc, "x", "ext2");
    row = calloc((size_t)ncol + 1, sizeof *row);
    double u[8] = {0}, t = 0;
    for (int i = 0; i < 200; ++i) { // 5 s
        engine_set_function_commands(e, u, nfn, err, sizeof err);
        t += 0.025;
        CHECK(engine_advance_to(e, t, NULL, NULL) == 0, "%s", engine_error(e));
    }
    const rcl* r = engine_rcl(e);
    engine_row(e, row);
    printf("sandbox engine: %.0f kg (115 %% of %.0f kg at %.2f m, slew 92 deg): util %.3f, the lift reads %.0f kg\n", mass,
           cap, R0, r->util, r->m_filt);
    CHECK_REL(r->m_filt, mass, 0.03);
    CHECK(r->util >= 1.1 && r->util < 1.2, "sandbox: util %.3f", r->util);
    // Extension out: cut; slew towards the cab (the side's chart is above
    // the cab's): cut; the extension in: passes and moves.
    const struct {
        int f;
        double dir;
        bool cut;
    } step[3] = {{fe, 1, true}, {fs, -1, false}, {fe, -1, false}};
    for (int k = 0; k < 3; ++k) {
        const double x0 = row[ix] + row[ix2], s0 = row[COL_SLEW];
        memset(u, 0, sizeof u);
        u[step[k].f] = step[k].dir;
        bool ok = true;
        for (int i = 0; i < 40; ++i) {
            engine_set_function_commands(e, u, nfn, err, sizeof err);
            ok = ok && (step[k].cut ? e->u_lim[step[k].f] == 0.0 : e->u_lim[step[k].f] == step[k].dir);
            t += 0.025;
            CHECK(engine_advance_to(e, t, NULL, NULL) == 0, "%s", engine_error(e));
        }
        engine_row(e, row);
        const double dx = row[ix] + row[ix2] - x0;
        printf("sandbox engine: %s %+.0f: %s, ext1 + ext2 %+.4f m, slew %+.4f rad, util %.3f\n",
               engine_function_name(e, step[k].f), step[k].dir, step[k].cut ? "cut" : "passes", dx, row[COL_SLEW] - s0,
               r->util);
        CHECK(ok, "sandbox: %s %+.0f %s at every frame", engine_function_name(e, step[k].f), step[k].dir,
              step[k].cut ? "cut" : "passes whole");
        if (step[k].f == fe && step[k].cut) CHECK(fabs(dx) < 2e-3, "sandbox: ext out moved %.4f m", dx);
        if (step[k].f == fs) CHECK(row[COL_SLEW] - s0 < -0.05, "sandbox: slew moved %.4f rad", row[COL_SLEW] - s0);
        if (step[k].f == fe && !step[k].cut) CHECK(dx < -0.05, "sandbox: ext in moved %.4f m", dx);
        memset(u, 0, sizeof u);
        engine_set_function_commands(e, u, nfn, err, sizeof err);
        t += 0.5;
        CHECK(engine_advance_to(e, t, NULL, NULL) == 0, "%s", engine_error(e));
        engine_row(e, row);
    }
    free(row);
    engine_destroy(e);
    remove(wpath);
    model_free(m);
}

// What cannot be read is refused in one line: no rating; a two-link model
// is not a chain (its limiter is the closed form's).
static void test_allow_list(void) {
    char err[600];
    model* m = load();
    if (!m) return;
    m->mech.rated_moment = 0;
    CHECK(rcl_check_model(m, err, sizeof err) == -1 && strstr(err, "rated_moment"), "no rating refused: %s", err);
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_LAGRANGE;
    CHECK(engine_require(m, &o, ENGINE_CAP_LIMITER, "--rcl on", err, sizeof err) == -1 && strstr(err, "rated_moment"),
          "engine_require says why: %s", err);
    model_free(m);
}

int main(void) {
    test_gain_against_central_differences();
    test_allow_list();
    test_overload_extended(SIM_LAGRANGE);
    test_overload_extended(SIM_ODE);
    test_scripted_ode_run();
    test_sandbox_engine();
    TEST_MAIN_END();
}
