// app_units.c: the units of the run metrics as a user reads and writes
// them. Metrics are kept in SI (Pa, rad, J, m, s, N: the CSV and JSON files);
// the run summary shows them in MPa, deg, kJ, kN. optimize's constraints and
// objective and sweep's plots use these helpers, so a value typed in the
// summary's unit means what it says and a plot axis reads like the summary.
#include "app.h"
#include "app_design_metrics.h"
#include "metrics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct unit_def {
    const char* name;
    double si; ///< one of this unit in the SI unit
} unit_def;

typedef struct dim_def {
    const char* si;      ///< metric_unit's string
    const char* display; ///< the run summary's unit
    unit_def units[5];   ///< the accepted suffixes, NULL-terminated
} dim_def;

static const dim_def k_dims[] = {
    {"Pa", "MPa", {{"MPa", 1e6}, {"kPa", 1e3}, {"bar", 1e5}, {"Pa", 1.0}, {NULL, 0}}},
    {"rad", "deg", {{"deg", 3.14159265358979323846 / 180.0}, {"rad", 1.0}, {NULL, 0}}},
    {"J", "kJ", {{"kJ", 1e3}, {"MJ", 1e6}, {"J", 1.0}, {NULL, 0}}},
    {"m", "m", {{"m", 1.0}, {"mm", 1e-3}, {"cm", 1e-2}, {NULL, 0}}},
    {"s", "s", {{"s", 1.0}, {"ms", 1e-3}, {NULL, 0}}},
    {"N", "kN", {{"kN", 1e3}, {"N", 1.0}, {"MN", 1e6}, {NULL, 0}}},
};

// The dimension of a metric, or NULL for a unitless one (count, "-"); a
// chain's per actuator too (app_design_metrics.h).
static const dim_def* dim_of(int met) {
    const char* u = app_design_metric_unit(met);
    for (size_t k = 0; k < sizeof k_dims / sizeof k_dims[0]; ++k)
        if (!strcmp(k_dims[k].si, u)) return &k_dims[k];
    return NULL;
}

static const unit_def* unit_named(const dim_def* d, const char* name) {
    for (const unit_def* u = d->units; u->name; ++u)
        if (!strcmp(u->name, name)) return u;
    return NULL;
}

static void unit_list(const dim_def* d, char* buf, size_t n) {
    size_t len = 0;
    buf[0] = 0;
    for (const unit_def* u = d->units; u->name && len < n; ++u)
        len += (size_t)snprintf(buf + len, n - len, "%s%s", u == d->units ? "" : ", ", u->name);
}

const char* app_metric_disp_unit(int met) {
    const dim_def* d = dim_of(met);
    return d ? d->display : app_design_metric_unit(met);
}

double app_metric_disp_scale(int met) {
    const dim_def* d = dim_of(met);
    return d ? 1.0 / unit_named(d, d->display)->si : 1.0;
}

const char* app_metric_label(int met, char* buf, size_t n) {
    snprintf(buf, n, "%s [%s]", app_design_metric_name(met), app_metric_disp_unit(met));
    return buf;
}

int app_metric_unit_scale(int met, const char* unit, double* si, char* err, size_t errsz) {
    const dim_def* d = dim_of(met);
    const unit_def* u = d ? unit_named(d, unit) : NULL;
    if (!u) {
        char list[96];
        if (d) unit_list(d, list, sizeof list);
        snprintf(err, errsz, "%s: unit '%s' is not one of %s", app_design_metric_name(met), unit,
                 d ? list : "(none: the metric is a plain number)");
        return -1;
    }
    *si = u->si;
    return 0;
}

int app_metric_parse_value(int met, const char* text, double* si, char* err, size_t errsz) {
    const dim_def* d = dim_of(met);
    const char* name = app_design_metric_name(met);
    char* end;
    const double v = strtod(text, &end);
    if (end == text || !isfinite(v)) {
        snprintf(err, errsz, "'%s' is not a finite number", text);
        return -1;
    }
    while (*end == ' ') ++end; // "24 MPa" as well as "24MPa"
    if (!d) {
        if (*end) {
            snprintf(err, errsz, "%s is a plain number (%s), got the unit '%s'", name, app_design_metric_unit(met),
                     end);
            return -1;
        }
        *si = v;
        return 0;
    }
    char list[96];
    unit_list(d, list, sizeof list);
    if (!*end) {
        // A bare number for a pressure is ambiguous (24 meant as MPa is 24
        // Pa in SI): the unit is required.
        snprintf(err, errsz, "%s needs a unit: '%s' followed by one of %s (e.g. %g%s)", name, text, list, v,
                 d->display);
        return -1;
    }
    const unit_def* u = unit_named(d, end);
    if (!u) {
        snprintf(err, errsz, "%s: unit '%s' is not one of %s", name, end, list);
        return -1;
    }
    *si = v * u->si;
    return 0;
}
