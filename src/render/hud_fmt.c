// hud_fmt.c: how the HUD prints numbers (render.h): fixed decimals chosen by
// the unit, never "-0.0" and never an exponent for a value that is zero at
// the shown precision ("x2 -3.81e-05 mm" was a stroke of 38 nm).
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const char* render_fmt_fixed(char* buf, size_t n, double v, int decimals, bool sign) {
    if (!isfinite(v)) {
        snprintf(buf, n, "%s", isnan(v) ? "nan" : v > 0 ? "inf" : "-inf");
        return buf;
    }
    snprintf(buf, n, sign ? "%+.*f" : "%.*f", decimals, v);
    // Zero at this precision has no sign: -0.04 mm is 0.0 mm, not a direction.
    if (!strpbrk(buf, "123456789")) snprintf(buf, n, "%.*f", decimals, 0.0);
    return buf;
}

int render_unit_decimals(const char* unit, double v) {
    static const struct {
        const char* unit;
        int decimals;
    } k[] = {{"MPa", 2}, {"mm", 1}, {"mm/s", 1}, {"L/min", 1}, {"%", 1}, {"kN", 2}, {"deg", 1},
             {"kg", 0},  {"N", 0},  {"m", 2},    {"m/s", 3},   {"L", 3}, {"ms", 2}, {"rad", 3}};
    for (size_t i = 0; unit && i < sizeof k / sizeof k[0]; ++i)
        if (!strcmp(unit, k[i].unit)) return k[i].decimals;
    // Another unit: four significant digits, at most six decimals (a
    // smaller value reads 0.000000).
    const double a = fabs(v);
    if (!(a > 0) || !isfinite(a)) return 0;
    const int d = 3 - (int)floor(log10(a));
    return d < 0 ? 0 : d > 6 ? 6 : d;
}

const char* render_fmt_unit(char* buf, size_t n, double v, const char* unit) {
    return render_fmt_fixed(buf, n, v, render_unit_decimals(unit, v), false);
}
