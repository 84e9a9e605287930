// test_components.c: each component law against its analytic form, limits
// and continuity (no integrator needed).
#include "circuits.h"
#include "check.h"
#include "hyd_internal.h" // hyd_be: the compiled model's fast Be(p) path
#include "hydraulics.h"

#include <math.h>
#include <stdlib.h>

static const double PI = 3.14159265358979323846;

// p_tr straight from the docs/hydraulics.md formula, independent of orifice.c.
static double spec_p_tr(const hyd_fluid_def* f, double cd, double A) {
    const double Dh = sqrt(4.0 * A / PI);
    const double a = f->re_transition * f->viscosity / (cd * Dh);
    return 0.5 * f->density * a * a;
}

static void test_orifice_limits(void) {
    hyd_fluid_def f = hyd_default_fluid_def();
    const double cd = 0.65, A = 2e-5;
    const double K = cd * A * sqrt(2.0 / f.density);
    const double ptr = spec_p_tr(&f, cd, A);
    CHECK_REL(hyd_orifice_p_tr(&f, cd, A), ptr, 1e-12);
    // Turbulent: Q = K sqrt(dp), slope K / (2 sqrt(dp)).
    double g, gA;
    double q = hyd_orifice_flow(&f, cd, A, 1e6, &g, &gA);
    CHECK_REL(q, K * sqrt(1e6), 1e-12);
    CHECK_REL(g, K / (2.0 * sqrt(1e6)), 1e-12);
    // Laminar limit: Q / dp -> 5 K / (4 sqrt(p_tr)) as dp -> 0.
    const double dp = 1e-6 * ptr;
    q = hyd_orifice_flow(&f, cd, A, dp, &g, NULL);
    CHECK_REL(q / dp, 5.0 * K / (4.0 * sqrt(ptr)), 1e-9);
    CHECK_REL(g, 5.0 * K / (4.0 * sqrt(ptr)), 1e-9);
    // Continuity of value and slope at p_tr (both sides of the switch).
    double gl, gr;
    const double ql = hyd_orifice_flow(&f, cd, A, ptr * (1 - 1e-9), &gl, NULL);
    const double qr = hyd_orifice_flow(&f, cd, A, ptr * (1 + 1e-9), &gr, NULL);
    CHECK_REL(ql, K * sqrt(ptr), 1e-8);
    CHECK_REL(qr, K * sqrt(ptr), 1e-8);
    CHECK_REL(gl, K / (2.0 * sqrt(ptr)), 1e-8);
    CHECK_REL(gr, K / (2.0 * sqrt(ptr)), 1e-8);
    // Odd symmetry over both regimes.
    for (int i = -30; i <= 30; ++i) {
        const double d = ptr * pow(10.0, 0.25 * i);
        double g1, g2;
        CHECK_NEAR(hyd_orifice_flow(&f, cd, A, -d, &g1, NULL) + hyd_orifice_flow(&f, cd, A, d, &g2, NULL), 0.0, 1e-15 * fabs(K * sqrt(d)));
        CHECK_REL(g1, g2, 1e-14);
    }
    // Closed orifice: zero flow, finite (zero) slope at any pressure drop.
    double gc, gcA;
    const double qc = hyd_orifice_flow(&f, cd, 0.0, 2e7, &gc, &gcA);
    CHECK(qc == 0.0 && gc == 0.0 && isfinite(gcA), "closed: q=%g g=%g gA=%g", qc, gc, gcA);
    // Area derivative against central differences, in both regimes.
    const double dps[] = {1e6, -3e5, 0.3 * ptr, -0.9 * ptr, 1e-3};
    for (int i = 0; i < 5; ++i) {
        const double h = 1e-6 * A;
        double ga;
        hyd_orifice_flow(&f, cd, A, dps[i], NULL, &ga);
        const double fd = (hyd_orifice_flow(&f, cd, A + h, dps[i], NULL, NULL) -
                           hyd_orifice_flow(&f, cd, A - h, dps[i], NULL, NULL)) / (2 * h);
        CHECK_REL(ga, fd, 1e-6);
    }
    // The valve edge near closing: Q(A) is C1 at A = 0 (dQ/dA -> 0).
    double g0A;
    hyd_orifice_flow(&f, cd, 1e-16, 1e5, NULL, &g0A);
    CHECK(fabs(g0A) < 1e-3 * K / A * sqrt(1e5), "dQ/dA near A=0: %g", g0A);
}

// Be(p) as printed in docs/hydraulics.md (gauge pressure pg).
static double spec_be(const hyd_fluid_def* f, double bel, double pg) {
    const double n = f->polytropic_index, pa = f->p_atm, a = f->air_fraction;
    return bel * (1 + a * pow(pa / (pa + pg), 1 / n)) /
           (1 + a * bel * pow(pa, 1 / n) / (n * pow(pa + pg, (n + 1) / n)));
}

static void test_bulk_modulus(void) {
    hyd_fluid_def f = hyd_default_fluid_def();
    const double bel = f.bulk_modulus;
    for (double P = 150.0; P < 40e6; P *= 1.3) {
        const double pg = P - f.p_atm;
        double dbe;
        const double be = hyd_bulk_modulus(&f, bel, f.p_atm + pg, &dbe);
        CHECK_REL(be, spec_be(&f, bel, pg), 1e-12);
        const double h = 1e-6 * (f.p_atm + pg);
        const double fd = (hyd_bulk_modulus(&f, bel, f.p_atm + pg + h, NULL) -
                           hyd_bulk_modulus(&f, bel, f.p_atm + pg - h, NULL)) / (2 * h);
        CHECK_REL(dbe, fd, 1e-5);
    }
    // Limits: Be -> Be_l at high pressure; near vacuum the air term dominates
    // the denominator and Be -> n P (1 + alpha r) / (alpha r), r = (p_a/P)^(1/n),
    // which itself -> n P: the modulus vanishes with the absolute pressure.
    CHECK_REL(hyd_bulk_modulus(&f, bel, 1e10, NULL), bel, 1e-3);
    const double n = f.polytropic_index, ar = f.air_fraction * pow(f.p_atm / 200.0, 1 / n);
    CHECK_REL(hyd_bulk_modulus(&f, bel, 200.0, NULL), n * 200.0 * (1 + ar) / ar, 1e-5);
    // Positive, finite and C1 (value and slope) below absolute zero, too.
    double prev_be = 0, prev_d = 0;
    for (double P = -1e5; P < 1e3; P += 7.0) {
        double d;
        const double be = hyd_bulk_modulus(&f, bel, P, &d);
        CHECK(be > 0.0 && isfinite(be) && isfinite(d), "P=%g be=%g d=%g", P, be, d);
        if (P > -1e5) {
            CHECK(be >= prev_be, "monotone at P=%g", P);
            (void)prev_d;
        }
        prev_be = be;
        prev_d = d;
    }
    double dl, dr;
    const double bl = hyd_bulk_modulus(&f, bel, 100.0 - 1e-9, &dl);
    const double br = hyd_bulk_modulus(&f, bel, 100.0 + 1e-9, &dr);
    CHECK_REL(bl, br, 1e-9);
    CHECK_REL(dl, dr, 1e-6);
    // Constant-Be option.
    f.air_fraction = 0.0;
    double d0;
    CHECK(hyd_bulk_modulus(&f, bel, 3e5, &d0) == bel && d0 == 0.0, "constant Be");
}

// The compiled model evaluates Be(p) through the air-ratio table (fluid.c);
// it must agree with the plain exp/log law of hyd_bulk_modulus to round-off
// over the whole range: the rational tail below 100 Pa (and below 0), the
// low-pressure knee where air dominates, the working range, and far beyond.
// The bound 1e-12 is far below the 1e-8 an approximation would be allowed.
static void test_bulk_modulus_table(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m)
        return;
    const double ns[] = {1.0, 1.2, 1.4, 2.0};
    for (int in = 0; in < 4; ++in) {
        CHECK(hyd_model_set(m, "fluid.polytropic_index", ns[in], err, sizeof err) == 0, "%s", err);
        const hyd_fluid_def f = hyd_model_fluid(m);
        double emax = 0.0, dmax = 0.0;
        for (int ib = 0; ib < 2; ++ib) {
            const double bel = ib ? 0.8e9 : f.bulk_modulus;
            // Log sweep 1 Pa .. 1e12 Pa with an irregular ratio (hits all
            // segments), plus a linear sweep through negative pressures.
            for (int k = 0; k < 20000; ++k) {
                const double P = k < 19000 ? pow(10.0, 12.0 * k / 19000.0) * (1.0 + 1e-7 * (k % 7))
                                           : -1e6 + 1.01e6 * (k - 19000) / 1000.0;
                double d, dref, be;
                hyd_node_c(m, bel, m->be_alpha * bel * m->be_inv_n, P, 1.0, &be, &d);
                const double ref = hyd_bulk_modulus(&f, bel, P, &dref);
                emax = fmax(emax, fabs(be - ref) / ref);
                // Far above the knee dBe/dp tends to 0 by cancellation (in
                // both forms), so measure it against Be/P as well: the error
                // of the log-sensitivity d ln Be / d ln P, which is what the
                // Jacobian entry dBe/dp * net / V carries relative to Be/V.
                dmax = fmax(dmax, fabs(d - dref) / (fabs(dref) + ref / fmax(fabs(P), 1.0)));
            }
        }
        CHECK(emax <= 1e-12, "n = %g: Be relative error %.3g", ns[in], emax);
        CHECK(dmax <= 1e-12, "n = %g: dBe/dp relative error %.3g", ns[in], dmax);
        printf("  Be table n = %.1f: max rel error Be %.2g, dBe/dp %.2g\n", ns[in], emax, dmax);
    }
    // The constant-modulus option stays exact.
    CHECK(hyd_model_set(m, "fluid.air_fraction", 0.0, err, sizeof err) == 0, "%s", err);
    double d0 = 1.0, be0 = 0.0;
    CHECK(hyd_node_c(m, 1.2e9, 0.0, 3e5, 1.0, &be0, &d0) == 1.2e9 && be0 == 1.2e9 && d0 == 0.0,
          "constant Be through the model");
    CHECK(hyd_node_c(m, 1.2e9, 0.0, 0.0, 1.0, &be0, &d0) == 1.2e9 && d0 == 0.0, "constant Be at P = 0");
    hyd_model_free(m);
}

static void test_open_ramp(void) {
    const double w = 1e6;
    double dr;
    CHECK(hyd_open_ramp(-5.0, w, &dr) == 0.0 && dr == 0.0, "closed below crack");
    CHECK_NEAR(hyd_open_ramp(w, w, &dr), 1.0, 1e-15);   // rated at crack + override
    CHECK_NEAR(hyd_open_ramp(3 * w, w, &dr), 5.0, 1e-12); // linear beyond, slope 2/w
    CHECK_REL(dr, 2.0 / w, 1e-12);
    double d1, d2;
    CHECK_NEAR(hyd_open_ramp(1e-9, w, &d1), 0.0, 1e-15);
    CHECK_NEAR(d1, 0.0, 1e-12 / w);
    const double a = hyd_open_ramp(w - 1e-6, w, &d1), b = hyd_open_ramp(w + 1e-6, w, &d2);
    CHECK_NEAR(a, b, 1e-11);
    CHECK_REL(d1, d2, 1e-9);
}

// Tiny circuits built through the C API.
static hyd_model* pump_circuit(void) {
    hyd_builder* b = hyd_builder_create();
    add_tank(b, "tank", 0);
    add_volume(b, "line", 1e-3);
    add_pump(b, "pump", "tank", "line", 5e-4, 20e6); // the default band, 0.5 MPa
    char err[256];
    hyd_model* m = hyd_compile(b, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    hyd_builder_free(b);
    return m;
}

static void test_pump(void) {
    hyd_model* m = pump_circuit();
    if (!m)
        return;
    hyd_data* d = hyd_data_create(m);
    double y[1], yd[1];
    const double pt = 1e5, ps = 20e6, band = 0.5e6, qmax = 5e-4;
    y[0] = pt + ps - 1.0;
    hyd_eval(m, d, 0, y, yd);
    CHECK_REL(d->comp_q[0], qmax, 1e-15);
    y[0] = pt + ps + 0.5 * band; // mid-band: smoothstep(0.5) = 0.5
    hyd_eval(m, d, 0, y, yd);
    CHECK_REL(d->comp_q[0], 0.5 * qmax, 1e-12);
    y[0] = pt + ps + band + 1.0;
    hyd_eval(m, d, 0, y, yd);
    CHECK(d->comp_q[0] == 0.0, "zero above band: %g", d->comp_q[0]);
    // Constant Be here is not assumed: check dp/dt = Be(p)/V Q.
    y[0] = 5e6;
    hyd_eval(m, d, 0, y, yd);
    hyd_fluid_def f = hyd_model_fluid(m);
    CHECK_REL(yd[0], hyd_bulk_modulus(&f, f.bulk_modulus, 5e6, NULL) / 1e-3 * qmax, 1e-12);
    hyd_data_free(d);
    hyd_model_free(m);
}

static hyd_model* cylinder_only(double bore, double rod, double stroke, double bv) {
    hyd_builder* b = hyd_builder_create();
    hyd_cylinder_def c = hyd_default_cylinder_def();
    c.name = "cyl";
    c.bore = bore;
    c.rod = rod;
    c.stroke = stroke;
    c.friction = bv;
    hyd_add_cylinder(b, &c);
    char err[256];
    hyd_model* m = hyd_compile(b, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    hyd_builder_free(b);
    return m;
}

static void test_blocked_cylinder_force(void) {
    const double D = 0.1, dr = 0.06, s = 0.7, bv = 5e3;
    hyd_model* m = cylinder_only(D, dr, s, bv);
    if (!m)
        return;
    hyd_data* d = hyd_data_create(m);
    const double AA = PI * D * D / 4, AB = PI * (D * D - dr * dr) / 4;
    double y[2], yd[2];
    int iA, iB;
    hyd_model_cylinder_states(m, 0, &iA, &iB);
    srand(7);
    for (int k = 0; k < 200; ++k) {
        y[iA] = 3e7 * rand() / (double)RAND_MAX;
        y[iB] = 3e7 * rand() / (double)RAND_MAX;
        d->cyl_x[0] = 0.001 + (s - 0.002) * rand() / (double)RAND_MAX;
        d->cyl_v[0] = 0.4 * rand() / (double)RAND_MAX - 0.2;
        hyd_eval(m, d, 0, y, yd);
        CHECK_NEAR(d->cyl_F[0], y[iA] * AA - y[iB] * AB - bv * d->cyl_v[0], 1e-9 * 3e7 * AA);
        CHECK(d->cyl_stop[0] == 0, "stop flag inside stroke");
    }
    // End stops at rest: a spring k (delta - w/2) past the onset width w.
    hyd_cylinder_def cd = hyd_default_cylinder_def();
    y[iA] = y[iB] = 1e5;
    d->cyl_v[0] = 0.0;
    d->cyl_x[0] = -0.003;
    hyd_eval(m, d, 0, y, yd);
    const double fh = 1e5 * (AA - AB);
    CHECK_REL(d->cyl_F[0] - fh, cd.stop_stiffness * (0.003 - cd.stop_width / 2), 1e-9);
    CHECK(d->cyl_stop[0] == -1, "retract stop flag");
    d->cyl_x[0] = s + 0.003;
    hyd_eval(m, d, 0, y, yd);
    CHECK_REL(d->cyl_F[0] - fh, -cd.stop_stiffness * (0.003 - cd.stop_width / 2), 1e-9);
    CHECK(d->cyl_stop[0] == 1, "extend stop flag");
    hyd_data_free(d);
    hyd_model_free(m);
}

// Valve: A_max is set so a fully open edge passes Q_N at dp_N.
static void test_valve_rating(void) {
    hyd_builder* b = hyd_builder_create();
    const char* names[4] = {"P", "T", "A", "B"};
    const double pr[4] = {1.1e6, 1e5, 1e5, 1.1e6};
    for (int i = 0; i < 4; ++i) {
        hyd_tank_def t = hyd_default_tank_def();
        t.name = names[i];
        t.pressure = pr[i];
        hyd_add_tank(b, &t);
    }
    hyd_valve_def v = hyd_default_valve_def();
    v.name = "v";
    v.P = "P";
    v.T = "T";
    v.A = "A";
    v.B = "B";
    hyd_add_valve(b, &v);
    char err[256];
    hyd_model* m = hyd_compile(b, err, sizeof err);
    hyd_builder_free(b);
    CHECK(m != NULL, "%s", err);
    if (!m)
        return;
    hyd_data* d = hyd_data_create(m);
    double y[1], yd[1];
    const double us[] = {1.0, 0.5, 0.0, -0.25, -1.0};
    for (int k = 0; k < 5; ++k) {
        y[0] = us[k];
        d->valve_cmd[0] = 0.3;
        hyd_eval(m, d, 0, y, yd);
        // P->A and B->T both see dp_N = 1 MPa; A->T and P->B see 0.
        const double qN = v.q_nominal * (us[k] > 0 ? us[k] : 0.0);
        CHECK_REL(d->comp_q[0], qN, 1e-12);
        CHECK_REL(d->comp_q[1], qN, 1e-12);
        CHECK_REL(yd[0], (0.3 - us[k]) / v.tau, 1e-12);
    }
    d->valve_cmd[0] = 7.0; // commands saturate at 1
    y[0] = 0.0;
    hyd_eval(m, d, 0, y, yd);
    CHECK_REL(yd[0], 1.0 / v.tau, 1e-12);
    hyd_data_free(d);
    hyd_model_free(m);
}

// The component table is consistent, so a new entry that breaks a rule the
// compiler relies on fails here rather than in a run: each descriptor sits
// at its own type, names are unique, its def fits the element, its slots
// fit HYD_MAXSLOT, parameter offsets lie inside the def after the name and
// ports, and the defaults pass their own rules (required fields excepted).
static void test_component_table(void) {
    for (int t = 0; t < HYD_TYPE_COUNT; ++t) {
        const hyd_component* c = hyd_component_of((hyd_type)t);
        CHECK(c != NULL, "type %d has no descriptor", t);
        if (!c) continue;
        CHECK(c->type == (hyd_type)t && hyd_type_parse(c->name) == t, "%s: type %d", c->name, (int)c->type);
        CHECK(c->def_size <= HYD_DEF_MAX && c->defaults != NULL && c->derive != NULL, "%s: def", c->name);
        CHECK(c->nport <= HYD_MAXPORT && c->nnode + c->nport <= HYD_MAXSLOT, "%s: slots", c->name);
        CHECK(c->is_node ? (c->nport == 0 && c->rec_size == 0 && c->nnode == 1)
                         : (c->rec_size > 0 && c->eval != NULL && c->bind != NULL),
              "%s: node or component", c->name);
        const size_t data0 = sizeof(const char*) * (size_t)(1 + c->nport);
        unsigned char def[HYD_DEF_MAX];
        c->defaults(def);
        for (int k = 0; k < c->nparam; ++k) {
            const hyd_param_info* p = &c->params[k];
            CHECK(p->off >= data0 && p->off + sizeof(double) <= c->def_size, "%s.%s: offset", c->name, p->name);
            CHECK(p->lo <= p->tlo && p->tlo <= p->thi && p->thi <= p->hi, "%s.%s: ranges", c->name, p->name);
            for (int j = 0; j < k; ++j) CHECK(strcmp(p->name, c->params[j].name), "%s.%s twice", c->name, p->name);
            for (int j = 0; j < c->nport; ++j) CHECK(strcmp(p->name, c->ports[j].name), "%s.%s: port and parameter", c->name, p->name);
            double v;
            memcpy(&v, def + p->off, sizeof v);
            char msg[200];
            if (!p->required) CHECK(hyd_param_check(p, v, msg, sizeof msg) == 0, "%s.%s default: %s", c->name, p->name, msg);
        }
        for (int j = 0; j < c->nport; ++j)
            CHECK(c->ports[j].off >= sizeof(const char*) && c->ports[j].off < data0, "%s.%s: port offset", c->name,
                  c->ports[j].name);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_orifice_limits);
    RUN_TEST(test_bulk_modulus);
    RUN_TEST(test_bulk_modulus_table);
    RUN_TEST(test_open_ramp);
    RUN_TEST(test_pump);
    RUN_TEST(test_blocked_cylinder_force);
    RUN_TEST(test_valve_rating);
    RUN_TEST(test_component_table);
    TEST_MAIN_END();
}
