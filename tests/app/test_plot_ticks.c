// test_plot_ticks.c: the plots' axis labels as pure functions (no PLplot).
// PLplot's own labels print a fixed number of significant digits, so an axis
// with a small range against its values repeated them: the tip reach of
// `hold` between 3.9060 and 3.9064 m was labelled "3.906 3.906 3.906". Here
// the decimals follow the tick step: on every range, labels one step apart
// differ and read back as their tick values.
#include "app.h"
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void check_axis(double lo, double hi) {
    const double step = app_tick_step(lo, hi, 6);
    CHECK(step > 0 && isfinite(step), "[%g, %g]: step %g", lo, hi, step);
    // A 1-2-5 step: mantissa 1, 2 or 5.
    const double mant = step / pow(10.0, floor(log10(step) + 1e-12));
    CHECK(fabs(mant - 1) < 1e-9 || fabs(mant - 2) < 1e-9 || fabs(mant - 5) < 1e-9, "[%g, %g]: step %g", lo, hi,
          step);
    char labels[64][40];
    int n = 0;
    for (double v = ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step && n < 64; v += step, ++n) {
        app_tick_label(v, step, labels[n], sizeof labels[n]);
        CHECK(fabs(atof(labels[n]) - v) <= 0.5 * step, "[%g, %g]: tick %.17g labelled '%s'", lo, hi, v, labels[n]);
        CHECK(strncmp(labels[n], "-0", 2) || strspn(labels[n] + 1, "0.") != strlen(labels[n] + 1),
              "[%g, %g]: negative zero '%s'", lo, hi, labels[n]);
        for (int j = 0; j < n; ++j)
            CHECK(strcmp(labels[j], labels[n]) != 0, "[%g, %g]: '%s' twice (ticks %d and %d, step %g)", lo, hi,
                  labels[n], j, n, step);
    }
    CHECK(n >= 2 && n <= 7, "[%g, %g]: %d ticks at step %g", lo, hi, n, step);
}

static void test_labels_distinct(void) {
    static const double r[][2] = {
        {3.9060, 3.9064},    // the tip reach of `hold`
        {-0.45748, -0.45697}, // its height
        {16.08, 16.08001},   // a held pressure in MPa
        {-0.001, 0.001},     // a closed spool in %
        {0.0, 20.0},         // time
        {1e-7, 3e-7},
        {-1234.5, 5678.0},
        {417.9, 427.2},
    };
    for (size_t k = 0; k < sizeof r / sizeof r[0]; ++k) check_axis(r[k][0], r[k][1]);
    char b[40];
    app_tick_label(3.9061, 1e-4, b, sizeof b);
    CHECK(!strcmp(b, "3.9061"), "3.9061 at step 1e-4: '%s'", b);
    app_tick_label(-1e-17, 5e-4, b, sizeof b);
    CHECK(!strcmp(b, "0.0000"), "a zero tick off by rounding: '%s'", b);
    app_tick_label(15.0, 5.0, b, sizeof b);
    CHECK(!strcmp(b, "15"), "15 at step 5: '%s'", b);
    CHECK(app_tick_decimals(0.1) == 1 && app_tick_decimals(0.05) == 2 && app_tick_decimals(1e-4) == 4 &&
              app_tick_decimals(10) == 0,
          "decimals %d %d %d %d", app_tick_decimals(0.1), app_tick_decimals(0.05), app_tick_decimals(1e-4),
          app_tick_decimals(10));
    CHECK(app_tick_step(1.0, 1.0, 6) == 1.0 && app_tick_step(0, NAN, 6) == 1.0, "degenerate ranges");
}

int main(int argc, char** argv) {
    RUN_TEST(test_labels_distinct);
    TEST_MAIN_END();
}
