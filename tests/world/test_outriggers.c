// test_outriggers.c: the sandbox truck's support forces and stability
// margin against hand calculations: at rest the pads carry the weight of
// truck, crane, rope, hook and load (masses from the model and world files);
// over the side, a load below the hand-calculated tipping load leaves the
// truck standing with the margin the moment balance gives, a load above it
// unloads the far pads, drops the margin below 1 and tips the truck.
#include "check.h"

#include "metrics.h"
#include "model.h"
#include "ode_world.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)

static model* g_model;

static int load_world(world_desc* d) {
    char err[512];
    if (world_desc_load(CRANESIM_ASSETS "/worlds/sandbox.json", d, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    d->nobstacle = 0; // nothing near the truck: only the ground carries it
    return 0;
}

static ode_world* make(const world_desc* d, const double q0[2], double slew0) {
    char err[512] = "";
    ode_world_opts o = ode_world_default_opts();
    o.q0[0] = q0[0];
    o.q0[1] = q0[1];
    o.slew0 = slew0;
    o.model_file = "hiab031.json";
    ode_world* w = ode_world_create(&g_model->mech, cJSON_GetObjectItemCaseSensitive(g_model->json, "hydraulics"), d,
                                    &o, err, sizeof err);
    if (!w) fprintf(stderr, "create: %s\n", err);
    return w;
}

// Truck, column, both booms, rope and hook [kg], from the files.
static double rig_mass(const world_desc* d) {
    const crane_mech* m = &g_model->mech;
    return d->truck.mass + m->column_mass + m->link[0].mass + m->link[1].mass + d->rope.mass_per_m * d->rope.length +
           d->hook.mass;
}

// A world with one load of mass [kg] hanging right under the hook at pose q0
// and slew, hooked; NULL on failure. *hook0 gets the hook point as built.
static ode_world* make_hooked(world_desc* d, const double q0[2], double slew, double mass, double hook0[3]) {
    d->nload = 0;
    ode_world* w = make(d, q0, slew);
    if (!w) return NULL;
    ode_world_state s;
    ode_world_get_state(w, &s);
    ode_world_destroy(w);
    memcpy(hook0, s.hook, sizeof s.hook);
    d->nload = 1;
    world_load* L = &d->load[0];
    memset(L, 0, sizeof *L);
    snprintf(L->name, sizeof L->name, "test_load");
    L->mass = mass;
    L->size[0] = L->size[1] = 0.8;
    L->size[2] = 0.6;
    L->position[0] = s.hook[0];
    L->position[1] = s.hook[1];
    L->position[2] = s.hook[2] - 0.3 - 0.005;
    L->friction = 0.6;
    w = make(d, q0, slew);
    if (w && ode_world_hook(w, 1) != 0) {
        fprintf(stderr, "the load did not hook\n");
        ode_world_destroy(w);
        return NULL;
    }
    return w;
}

// Mean pad-force sum [N] over [t0, t1] s of stepping (10 ms rows).
static double mean_sum(ode_world* w, double t0, double t1, ode_world_state* last) {
    double acc = 0;
    int n = 0;
    for (double t = 0.01; t <= t1 + 1e-9; t += 0.01) {
        if (ode_world_step(w, 0.01)) {
            fprintf(stderr, "%s\n", ode_world_error(w));
            return NAN;
        }
        ode_world_get_state(w, last);
        if (t >= t0) {
            acc += last->pad_F[0] + last->pad_F[1] + last->pad_F[2] + last->pad_F[3];
            ++n;
        }
    }
    return acc / n;
}

// At rest (valves closed) the four pads carry every weight within 1 %:
// empty hook, and a 500 kg load hooked.
static void test_weight_at_rest(void) {
    world_desc d;
    if (load_world(&d)) return;
    const double g = g_model->mech.gravity;
    const double q0[2] = {117.3 * DEG, -65.8 * DEG};
    d.nload = 0;
    ode_world* w = make(&d, q0, -60 * DEG);
    CHECK(w != NULL, "world");
    if (w) {
        ode_world_state s;
        const double F = mean_sum(w, 2.0, 3.0, &s), W = rig_mass(&d) * g;
        printf("  empty hook: pads carry %.1f N, weight %.1f N (%.3f %%); pads %.0f %.0f %.0f %.0f N, margin %.2f\n", F,
               W, 100 * (F / W - 1), s.pad_F[0], s.pad_F[1], s.pad_F[2], s.pad_F[3], s.stab_margin);
        CHECK_REL(F, W, 0.01);
        CHECK(s.pad_lifted == 0, "no pad lifted at rest: bits %d", s.pad_lifted);
        for (int i = 0; i < 4; ++i) CHECK(s.pad_F[i] > 0.05 * W, "pad %d carries %.0f N", i + 1, s.pad_F[i]);
        ode_world_destroy(w);
    }
    double hook0[3];
    w = make_hooked(&d, q0, -60 * DEG, 500, hook0);
    CHECK(w != NULL, "hooked world");
    if (w) {
        ode_world_state s;
        const double F = mean_sum(w, 2.0, 3.0, &s), W = (rig_mass(&d) + 500) * g;
        printf("  500 kg hooked: pads carry %.1f N, weight %.1f N (%.3f %%)\n", F, W, 100 * (F / W - 1));
        CHECK_REL(F, W, 0.01);
        ode_world_destroy(w);
    }
    world_desc_free(&d);
}

// Over the right side (slew -90 deg: the booms along -y) at 4.66 m reach,
// booms locked on their hinges (the port reliefs would let a tipping load
// down first: this tests the truck). Hand calculation about the right pads'
// line y = -span/2: the truck and the column (on y = 0) and whatever of the
// booms is inboard restore; the rest of the booms, the rope and hook and the
// load tip. The load that balances them is the tipping load m*.
typedef struct side_run {
    double margin0;   ///< margin after 0.2 s
    double far_min;   ///< smallest far-side (left) pad force over the last second [N]
    double far_end;   ///< far-side pads' sum, mean over the last second [N]
    double sum_end;   ///< all pads' sum, mean over the last second [N]
    double tilt;      ///< largest truck tilt [rad]
    double margin_min;
    int lifted_far;   ///< both far pads flagged lifted at some row
} side_run;

static double hand_moments(const world_desc* d, const double q0[2], double reach_hook, double m_load, double* R,
                           double* T) {
    const crane_mech* m = &g_model->mech;
    const double e = 0.5 * d->truck.outrigger_span; // the line's distance from the column axis [m]
    // Horizontal reach of each weight from the column axis [m], its mass [kg].
    const double L1 = m->link[0].length;
    const double r[5] = {0, m->link[0].com * sin(q0[0]), L1 * sin(q0[0]) + m->link[1].com * sin(q0[0] + q0[1]),
                         reach_hook, reach_hook};
    const double mm[5] = {d->truck.mass + m->column_mass, m->link[0].mass, m->link[1].mass,
                          d->rope.mass_per_m * d->rope.length + d->hook.mass, m_load};
    *R = *T = 0;
    for (int i = 0; i < 5; ++i) {
        const double s = e - r[i]; // inboard distance [m]
        if (s > 0) *R += mm[i] * s;
        else *T -= mm[i] * s;
    }
    return *R / *T;
}

static side_run run_side(double mass, const double q0[2]) {
    side_run out = {NAN, INFINITY, 0, 0, 0, INFINITY, 0};
    world_desc d;
    if (load_world(&d)) return out;
    double hook0[3];
    ode_world* w = make_hooked(&d, q0, -90 * DEG, mass, hook0);
    if (!w) {
        world_desc_free(&d);
        return out;
    }
    ode_world_lock_booms(w, 1);
    ode_world_state s;
    for (int i = 1; i <= 300; ++i) {
        if (ode_world_step(w, 0.01)) break;
        ode_world_get_state(w, &s);
        if (i == 20) out.margin0 = s.stab_margin;
        if (i > 200) {
            out.far_end += 0.01 * (s.pad_F[0] + s.pad_F[2]);
            out.sum_end += 0.01 * (s.pad_F[0] + s.pad_F[1] + s.pad_F[2] + s.pad_F[3]);
        }
        if (i > 200) out.far_min = fmin(out.far_min, fmin(s.pad_F[0], s.pad_F[2]));
        if ((s.pad_lifted & 5) == 5) out.lifted_far = 1;
        out.tilt = fmax(out.tilt, s.truck_tilt);
        if (i >= 20) out.margin_min = fmin(out.margin_min, s.stab_margin);
    }
    ode_world_destroy(w);
    world_desc_free(&d);
    return out;
}

static void test_side_tipping(void) {
    world_desc d;
    if (load_world(&d)) return;
    const double q0[2] = {110 * DEG, -40 * DEG};
    double hook0[3];
    ode_world* w = make_hooked(&d, q0, -90 * DEG, 100, hook0);
    if (!w) {
        world_desc_free(&d);
        CHECK(0, "world");
        return;
    }
    ode_world_destroy(w);
    // The truck stands at the origin, yaw 0: the hook's reach from the
    // column axis is -y.
    const double reach = -hook0[1];
    double R, T;
    hand_moments(&d, q0, reach, 0, &R, &T);
    const double e = 0.5 * d.truck.outrigger_span, m_star = (R - T) / (reach - e);
    const double lo = 0.85 * m_star, hi = 1.15 * m_star;
    const double margin_lo = hand_moments(&d, q0, reach, lo, &R, &T);
    const double margin_hi = hand_moments(&d, q0, reach, hi, &R, &T);
    printf("  hook reach %.3f m; hand tipping load %.0f kg; margins by hand %.4f at %.0f kg, %.4f at %.0f kg\n", reach,
           m_star, margin_lo, lo, margin_hi, hi);
    side_run a = run_side(lo, q0), b = run_side(hi, q0);
    side_run z = run_side(100, q0);
    printf("  %.0f kg: margin %.4f, far pads %.0f N (%.0f N with 100 kg), pads %.0f N, tilt %.2f deg\n", lo,
           a.margin0, a.far_end, z.far_end, a.sum_end, a.tilt / DEG);
    printf("  %.0f kg: margin %.4f (min %.4f), min far pad %.0f N, lifted %d, tilt %.2f deg\n", hi, b.margin0,
           b.margin_min, b.far_min, b.lifted_far, b.tilt / DEG);
    // Below the tipping load: the margin the moment balance gives (the
    // positions are the files' and the pose's, the ODE bodies' sag aside),
    // the far pads lighter than with a light load but down, the truck level.
    CHECK_REL(a.margin0, margin_lo, 0.02);
    CHECK(a.margin0 > 1, "margin %.4f > 1 below the tipping load", a.margin0);
    // (A rigid truck on four pads lifts the one diagonally opposite the load
    // first, the rear-left here, and stands on three until the margin is 1.)
    CHECK(a.far_end < 0.3 * z.far_end, "far pads unload: %.0f N against %.0f N with 100 kg", a.far_end, z.far_end);
    CHECK_REL(a.sum_end, (rig_mass(&d) + lo) * g_model->mech.gravity, 0.01);
    CHECK(a.tilt < 1 * DEG, "stands: tilt %.2f deg", a.tilt / DEG);
    // Above it: margin below 1 (by hand too), both far pads off the ground,
    // the truck tipping.
    CHECK(margin_hi < 1, "hand margin %.4f", margin_hi);
    CHECK_REL(b.margin0, margin_hi, 0.02);
    CHECK(b.margin0 < 1, "margin %.4f < 1 above the tipping load", b.margin0);
    CHECK(b.lifted_far, "both far pads lift off");
    CHECK(b.tilt > 5 * DEG, "tips: tilt %.2f deg", b.tilt / DEG);
    world_desc_free(&d);
}

// The validation world has no truck: zeros, no lift-off flags.
static void test_validation_zeros(void) {
    char err[512];
    world_desc d;
    if (world_desc_load(CRANESIM_ASSETS "/worlds/validation.json", &d, err, sizeof err)) {
        CHECK(0, "%s", err);
        return;
    }
    const double q0[2] = {117.3 * DEG, -65.8 * DEG};
    ode_world* w = make(&d, q0, 0);
    CHECK(w != NULL, "validation world");
    if (w) {
        ode_world_step(w, 0.05);
        ode_world_state s;
        ode_world_get_state(w, &s);
        CHECK(s.pad_F[0] == 0 && s.pad_F[3] == 0 && s.stab_margin == 0 && s.pad_lifted == 0, "zeros");
        ode_world_destroy(w);
    }
    world_desc_free(&d);
}

// The metrics from rows by hand: rows before ODE_SUPPORT_SETTLE_T do not
// count; the smallest pad force and margin; a lift-off is a pad entering
// "below 1 % of the pads' sum", counted once while it stays there.
static void test_metrics(void) {
    run_metrics m;
    metrics_init(&m, SIM_NCOL);
    CHECK(m.present[MET_MIN_PAD_F] && m.present[MET_MIN_STAB_MARGIN] && m.present[MET_PAD_LIFTOFFS], "present");
    CHECK(!metrics_present(MET_MIN_PAD_F, SIM_NCOL_BASE), "absent from lagrange rows");
    static const double rows[][6] = {
        // t, pad_F1..4 [N], stab_margin
        {0.0, 0, 0, 0, 0, 10},          // landing: not counted
        {0.2, 1e4, 2e4, 3e4, 4e4, 2.0}, // min 10 kN
        {0.3, 5e4, 2e4, 3e4, 50, 1.5},  // pad 4 at 50 N < 1 % of 100 kN: lift-off 1
        {0.4, 5e4, 2e4, 3e4, 60, 1.4},  // still lifted: no new event
        {0.5, 5e4, 2e4, 3e4, 5e3, 1.8}, // down again
        {0.6, 80, 2e4, 3e4, 40, 1.2},   // pads 1 and 4 lift: 3 in all
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i) {
        double r[SIM_NCOL] = {0};
        r[COL_T] = rows[i][0];
        for (int k = 0; k < 4; ++k) r[COL_PAD_F1 + k] = rows[i][1 + k];
        r[COL_STAB_MARGIN] = rows[i][5];
        metrics_row(&m, r);
    }
    CHECK_NEAR(m.value[MET_MIN_PAD_F], 40, 0);
    CHECK_NEAR(m.value[MET_MIN_STAB_MARGIN], 1.2, 0);
    CHECK_NEAR(m.value[MET_PAD_LIFTOFFS], 3, 0);
}

int main(int argc, char** argv) {
    char err[512];
    g_model = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    if (!g_model) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    RUN_TEST(test_weight_at_rest);
    RUN_TEST(test_side_tipping);
    RUN_TEST(test_validation_zeros);
    RUN_TEST(test_metrics);
    model_free(g_model);
    TEST_MAIN_END();
}
