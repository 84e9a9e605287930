// test_energy.c: the circuit's energy terms (energy.c, docs/energy.md)
// against hand calculations and their identity.
#include "check.h"
#include "hydraulics.h"

#include <math.h>
#include <stdlib.h>

// Steady flow through one orifice between two tanks at 10 MPa and 0.1 MPa:
// by hand, Q = cd A sqrt(2 dp / rho) (turbulent: dp >> p_tr) and the orifice
// dissipates Q dp, which the tanks deliver.
static void test_orifice_dissipates_q_dp(void) {
    hyd_builder* b = hyd_builder_create();
    hyd_tank_def hi = hyd_default_tank_def(), lo = hyd_default_tank_def();
    hi.name = "hi", hi.pressure = 10e6;
    lo.name = "lo", lo.pressure = 0.1e6;
    hyd_add_tank(b, &hi);
    hyd_add_tank(b, &lo);
    hyd_orifice_def o = {.name = "orf", .inlet = "hi", .outlet = "lo", .area = 1e-6, .cd = 0.6};
    hyd_add_orifice(b, &o);
    char err[256];
    hyd_model* m = hyd_compile(b, err, sizeof err);
    hyd_builder_free(b);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    hyd_data* d = hyd_data_create(m);
    hyd_eval(m, d, 0.0, NULL, NULL);
    const double rho = hyd_model_fluid(m).density, dp = 9.9e6;
    const double Q = 0.6 * 1e-6 * sqrt(2.0 * dp / rho); // 8.98e-5 m^3/s (5.4 L/min)
    const double P = hyd_comp_power(m, d, 0);
    CHECK_REL(P, Q * dp, 1e-6);                       // about 889 W
    CHECK_REL(hyd_boundary_power(m, d), Q * dp, 1e-6); // the tanks supply it
    CHECK(hyd_stored_power(m, d) == 0.0, "no volume node, got %g W", hyd_stored_power(m, d));
    hyd_data_free(d);
    hyd_model_free(m);
}

// A volume node of fixed V: the stored energy V phi(p) against its
// constant-modulus hand value V (p^2 - p_a^2) / (2 Be) (no air).
static void test_stored_energy_constant_modulus(void) {
    hyd_builder* b = hyd_builder_create();
    hyd_fluid_def f = hyd_default_fluid_def();
    f.air_fraction = 0.0;
    hyd_builder_set_fluid(b, &f);
    hyd_tank_def t = hyd_default_tank_def();
    t.name = "tank";
    hyd_add_tank(b, &t);
    hyd_volume_def v = hyd_default_volume_def();
    v.name = "line", v.volume = 2e-3;
    hyd_add_volume(b, &v);
    hyd_orifice_def o = {.name = "orf", .inlet = "line", .outlet = "tank", .area = 1e-6, .cd = 0.6};
    hyd_add_orifice(b, &o);
    char err[256];
    hyd_model* m = hyd_compile(b, err, sizeof err);
    hyd_builder_free(b);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    const int n = hyd_model_find_node(m, "line");
    const double p = 20e6, pa = f.p_atm;
    CHECK_REL(hyd_node_stored_energy(m, n, p, 2e-3), 2e-3 * (p * p - pa * pa) / (2.0 * f.bulk_modulus), 1e-7);
    hyd_model_free(m);
}

// The identity on the default crane at an arbitrary state: the components'
// power, the pistons', the stored rate and the tanks' sum to zero.
static void test_identity_default_crane(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    hyd_data* d = hyd_data_create(m);
    const int n = hyd_model_nstate(m);
    double* y = calloc((size_t)n, sizeof *y);
    double* f = calloc((size_t)n, sizeof *f);
    hyd_model_initial_state(m, y);
    for (int i = 0; i < n; ++i)
        y[i] = hyd_model_state_kind(m, i) == HYD_STATE_PRESSURE ? 1e6 + 2e6 * i : 0.3 * (i % 2 ? 1 : -1);
    for (int c = 0; c < hyd_model_ncylinder(m); ++c) d->cyl_x[c] = 0.2, d->cyl_v[c] = c ? -0.05 : 0.08;
    for (int v = 0; v < hyd_model_nvalve(m); ++v) d->valve_cmd[v] = 0.5;
    hyd_eval(m, d, 0.0, y, f);
    double sum = hyd_stored_power(m, d) - hyd_boundary_power(m, d), scale = 0.0;
    for (int c = 0; c < hyd_model_ncomp(m); ++c) {
        const double pc = hyd_comp_power(m, d, c), pp = hyd_comp_piston_power(m, d, c);
        sum += pc + pp;
        scale += fabs(pc) + fabs(pp);
        double e[2];
        if (hyd_valve_edge_power(m, d, c, e) == 2) CHECK_NEAR(e[0] + e[1], pc, 1e-9 * fabs(pc) + 1e-9);
    }
    CHECK(scale > 100.0, "the state moves no power (%g W)", scale);
    CHECK(fabs(sum) < 1e-9 * scale, "terms sum to %g W of %g W", sum, scale);
    // The one-pass form (hyd_power_terms, for a balance that follows every
    // step) gives the same terms.
    const int nc = hyd_model_ncomp(m);
    double* cp = calloc((size_t)nc, sizeof *cp);
    double* pp = calloc((size_t)nc, sizeof *pp);
    double B = NAN, S = NAN;
    if (cp && pp) {
        hyd_power_terms(m, d, cp, pp, &B, &S);
        for (int c = 0; c < nc; ++c) {
            CHECK_NEAR(cp[c], hyd_comp_power(m, d, c), 1e-12 * scale);
            CHECK_NEAR(pp[c], hyd_comp_piston_power(m, d, c), 1e-12 * scale);
        }
        CHECK_NEAR(B, hyd_boundary_power(m, d), 1e-12 * scale);
        CHECK_NEAR(S, hyd_stored_power(m, d), 1e-12 * scale);
    }
    free(cp);
    free(pp);
    free(y);
    free(f);
    hyd_data_free(d);
    hyd_model_free(m);
}

int main(void) {
    test_orifice_dissipates_q_dp();
    test_stored_energy_constant_modulus();
    test_identity_default_crane();
    printf("%d checks, %d failed\n", check_count_, check_failures_);
    return check_failures_ != 0;
}
