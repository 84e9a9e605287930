// test_units.c: the metrics' units as typed and shown (app_units.c): a value
// with a suffix reads back as the SI value computed by hand, a bare number is
// refused where the metric has a unit, and the display unit and its scale are
// the run summary's (MPa, deg, kJ, kN).
#include "app.h"
#include "check.h"
#include "metrics.h"

#include <math.h>
#include <string.h>

static double parse(int met, const char* text, int* rc, char* err, size_t n) {
    double v = NAN;
    *rc = app_metric_parse_value(met, text, &v, err, n);
    return v;
}

static void test_values_in_si(void) {
    static const struct {
        int met;
        const char* text;
        double si;
    } ok[] = {
        {MET_PEAK_P1A, "24MPa", 24e6},  {MET_PEAK_P1A, "24e6Pa", 24e6}, {MET_PEAK_P1A, "240bar", 24e6},
        {MET_PEAK_P1A, "24 MPa", 24e6}, {MET_PEAK_P1A, "2.4e4kPa", 24e6},
        {MET_MAX_TILT, "5deg", 5 * 3.14159265358979323846 / 180}, {MET_MAX_TILT, "0.1rad", 0.1},
        {MET_ENERGY_IN, "1.5kJ", 1500}, {MET_ENERGY_LOSS, "1500J", 1500},
        {MET_MAX_SWAY_AMP, "30mm", 0.03}, {MET_MAX_SWAY_AMP, "0.03m", 0.03},
        {MET_RELIEF_TIME, "0.5s", 0.5}, {MET_RELIEF_TIME, "500ms", 0.5},
        {MET_MIN_PAD_F, "10kN", 1e4}, {MET_STOP_LIFT, "2", 2}, {MET_MIN_STAB_MARGIN, "0.2", 0.2},
    };
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; ++k) {
        char err[256] = "";
        int rc;
        const double v = parse(ok[k].met, ok[k].text, &rc, err, sizeof err);
        CHECK(rc == 0, "%s '%s': %s", metric_name((metric_id)ok[k].met), ok[k].text, err);
        CHECK(fabs(v - ok[k].si) <= 1e-12 * fabs(ok[k].si), "'%s' -> %.17g, expected %.17g", ok[k].text, v, ok[k].si);
    }
}

static void test_refused(void) {
    static const struct {
        int met;
        const char* text;
        const char* says;
    } bad[] = {
        {MET_PEAK_P1A, "24", "needs a unit"},        {MET_PEAK_P1A, "24psi", "'psi' is not one of"},
        {MET_MAX_TILT, "5", "deg, rad"},             {MET_ENERGY_IN, "3", "kJ"},
        {MET_MAX_SWAY_AMP, "30", "mm"},              {MET_RELIEF_TIME, "1", "needs a unit"},
        {MET_STOP_LIFT, "2s", "plain number"},       {MET_PEAK_P1A, "MPa", "finite number"},
        {MET_PEAK_P1A, "inf MPa", "finite number"},  {MET_PEAK_P1A, "24MPax", "'MPax'"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        char err[256] = "";
        int rc;
        parse(bad[k].met, bad[k].text, &rc, err, sizeof err);
        CHECK(rc != 0 && strstr(err, bad[k].says) && !strchr(err, '\n'), "'%s': rc %d, '%s'", bad[k].text, rc, err);
    }
}

// The display units are those metrics_print writes (MPa, deg, kJ, kN) with
// the factor from SI: 1 MPa = 1e6 Pa, 1 deg = pi/180 rad.
static void test_display(void) {
    char lab[80];
    CHECK(!strcmp(app_metric_label(MET_PEAK_P1A, lab, sizeof lab), "peak_p1A [MPa]"), "%s", lab);
    CHECK(!strcmp(app_metric_label(MET_MAX_TILT, lab, sizeof lab), "max_truck_tilt [deg]"), "%s", lab);
    CHECK(!strcmp(app_metric_label(MET_ENERGY_IN, lab, sizeof lab), "energy_in [kJ]"), "%s", lab);
    CHECK(!strcmp(app_metric_label(MET_MIN_PAD_F, lab, sizeof lab), "min_pad_force [kN]"), "%s", lab);
    CHECK(!strcmp(app_metric_label(MET_STOP_LIFT, lab, sizeof lab), "end_stop_hits_lift [count]"), "%s", lab);
    CHECK_REL(app_metric_disp_scale(MET_PEAK_P_PUMP), 1e-6, 1e-15);
    CHECK_REL(app_metric_disp_scale(MET_MAX_SWAY), 180 / 3.14159265358979323846, 1e-15);
    CHECK_REL(app_metric_disp_scale(MET_ENERGY_LOSS), 1e-3, 1e-15);
    CHECK_REL(app_metric_disp_scale(MET_MAX_SWAY_AMP), 1.0, 1e-15);
    CHECK_REL(app_metric_disp_scale(MET_COLLISIONS), 1.0, 1e-15);
    // A report unit: what one of it is in SI.
    double si = 0;
    char err[256];
    CHECK(app_metric_unit_scale(MET_ENERGY_IN, "J", &si, err, sizeof err) == 0 && si == 1.0, "J: %g", si);
    CHECK(app_metric_unit_scale(MET_PEAK_P1A, "bar", &si, err, sizeof err) == 0 && si == 1e5, "bar: %g", si);
    CHECK(app_metric_unit_scale(MET_PEAK_P1A, "deg", &si, err, sizeof err) != 0 && strstr(err, "MPa"), "%s", err);
}

int main(int argc, char** argv) {
    RUN_TEST(test_values_in_si);
    RUN_TEST(test_refused);
    RUN_TEST(test_display);
    TEST_MAIN_END();
}
