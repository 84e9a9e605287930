// test_hud_fmt.c: the HUD's numbers (render_fmt_fixed, render_fmt_unit), which
// every readout, table cell and status number of the HUD goes through: no
// "-0.0" for a value that rounds to zero (a stroke rate of -0.03 mm/s read
// "-0.0"), no exponent in a readout ("x2 -3.81e-05 mm" was a stroke of 38 nm),
// decimals by unit as the fixed table prints them.
#include "check.h"
#include "render.h"

#include <math.h>
#include <string.h>

static void expect_fixed(double v, int d, bool sign, const char* want) {
    char b[64];
    render_fmt_fixed(b, sizeof b, v, d, sign);
    CHECK(!strcmp(b, want), "fixed(%.17g, %d, %d) = '%s', want '%s'", v, d, sign, b, want);
}

static void expect_unit(double v, const char* unit, const char* want) {
    char b[64];
    render_fmt_unit(b, sizeof b, v, unit);
    CHECK(!strcmp(b, want), "unit(%.17g, %s) = '%s', want '%s'", v, unit, b, want);
}

static void test_no_negative_zero(void) {
    expect_fixed(-0.04, 1, false, "0.0");
    expect_fixed(-0.0, 2, false, "0.00");
    expect_fixed(-0.004, 2, false, "0.00");
    expect_fixed(-0.3, 0, true, "0"); // a spool at -0.3 %: "0", not "-0"
    expect_fixed(0.2, 0, true, "0");
    expect_fixed(-0.05, 1, false, "-0.1"); // rounds away from zero: a real value keeps its sign
    expect_fixed(-12.345, 2, false, "-12.35");
    expect_fixed(25, 0, true, "+25");
    expect_fixed(-7, 0, true, "-7");
    expect_fixed(NAN, 1, false, "nan");
}

static void test_readouts_by_unit(void) {
    expect_unit(-3.81e-05, "mm", "0.0");
    expect_unit(452.94, "mm", "452.9");
    expect_unit(2.5631, "MPa", "2.56");
    expect_unit(-0.001, "MPa", "0.00");
    expect_unit(34.97, "L/min", "35.0");
    expect_unit(12.34, "%", "12.3");
    // Another unit: four significant digits, never an exponent.
    expect_unit(0.012345, "kg/m^3", "0.01235");
    expect_unit(1234.6, "kg/m^3", "1235");
    expect_unit(123456789.0, "Pa s", "123456789");
    expect_unit(-2e-9, "m^3", "0.000000");
    for (double v = 1e-12; v < 1e12; v *= 7.3) {
        char b[64];
        render_fmt_unit(b, sizeof b, -v, "J");
        CHECK(!strchr(b, 'e') && strcmp(b, "-0") && strncmp(b, "-0.000000", 9), "%.3g J as '%s'", -v, b);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_no_negative_zero);
    RUN_TEST(test_readouts_by_unit);
    TEST_MAIN_END();
}
