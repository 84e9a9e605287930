// circuit_params.c: parameter values. The value rules of the parameter tables
// (each component's descriptor, the fluid's table here), messages for values
// out of range, and live parameter changes ("<element>.<field>").
#include "hyd_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// Each parameter has a hard range, outside which a circuit is refused (a
// value there is a typo or a unit slip, and the integrator would meet it as
// a blow-up or, worse, as a plausible wrong answer: p_crack = 22 Pa, meant as
// MPa, let the boom sink onto its stop with exit 0), and a typical range for
// crane-sized machines, outside which the loader prints a note. The ranges
// and their reasons are documented in docs/hydraulics.md ("Parameter
// ranges").
static const hyd_param_info fluid_params[] = {
    HYD_PARAM(hyd_fluid_def, density, "kg/m^3", HYD_R_POS, 0, 500, 2000, 800, 1100),
    HYD_PARAM(hyd_fluid_def, viscosity, "m^2/s", HYD_R_POS, 0, 1e-7, 1e-2, 2e-6, 5e-4),
    HYD_PARAM(hyd_fluid_def, bulk_modulus, "Pa", HYD_R_POS, 0, 1e7, 1e10, 5e8, 2.5e9),
    HYD_PARAM(hyd_fluid_def, air_fraction, "-", HYD_R_FRAC, 0, 0, 0.5, 0, 0.02),
    HYD_PARAM(hyd_fluid_def, polytropic_index, "-", HYD_R_POS, 0, 1, 2, 1, 1.4),
    HYD_PARAM(hyd_fluid_def, p_atm, "Pa", HYD_R_POS, 0, 1e4, 2e5, 8e4, 1.1e5),
    HYD_PARAM(hyd_fluid_def, re_transition, "-", HYD_R_POS, 0, 1, 1e5, 10, 2000),
};

const hyd_param_info* hyd_fluid_params(int* count) {
    *count = HYD_COUNT(fluid_params);
    return fluid_params;
}

int hyd_param_count(hyd_type t) {
    int n;
    hyd_params_of(t, &n);
    return n;
}

const char* hyd_param_name(hyd_type t, int k) {
    int n;
    const hyd_param_info* p = hyd_params_of(t, &n);
    return (k >= 0 && k < n) ? p[k].name : NULL;
}

const char* hyd_param_unit(hyd_type t, int k) {
    int n;
    const hyd_param_info* p = hyd_params_of(t, &n);
    return (k >= 0 && k < n) ? p[k].unit : NULL;
}

// A number for a message, as a user would write it: 22, 0.005, 6000, 86400,
// 1e5, 2.5e9, 101325 (%g would give 100000 and 2.5e+09): six significant
// digits, in exponent form when that is at least two characters shorter.
void hyd_fmt_num(char* out, size_t n, double v) {
    const double a = fabs(v);
    if (!isfinite(v) || a == 0.0) {
        snprintf(out, n, "%g", v);
        return;
    }
    char ex[40], pl[400];
    snprintf(ex, sizeof ex, "%.5e", v); // d.ddddde[+-]XX, trimmed below
    char* e = strchr(ex, 'e');
    char* m = e;
    while (m > ex && m[-1] == '0') --m;
    if (m > ex && m[-1] == '.') --m;
    const char* q = e + 1;
    const int neg = *q == '-';
    if (*q == '+' || *q == '-') ++q;
    while (*q == '0' && q[1]) ++q;
    char exp_form[40];
    snprintf(exp_form, sizeof exp_form, "%.*se%s%s", (int)(m - ex), ex, neg ? "-" : "", q);
    // The plain form with the same six digits.
    int dec = 5 - (int)floor(log10(a));
    if (dec < 0) dec = 0;
    if (dec > 300) dec = 300;
    snprintf(pl, sizeof pl, "%.*f", dec, v);
    if (strchr(pl, '.')) {
        char* z = pl + strlen(pl);
        while (z[-1] == '0') *--z = 0;
        if (z[-1] == '.') z[-1] = 0;
    }
    snprintf(out, n, "%s", strlen(exp_form) + 2 <= strlen(pl) ? exp_form : pl);
}

// "[lo, hi] unit" for messages ("[1e5, 1e8] Pa"; no unit for "-").
void hyd_fmt_range(char* out, size_t n, double lo, double hi, const char* unit) {
    char a[24], b[24];
    hyd_fmt_num(a, sizeof a, lo);
    hyd_fmt_num(b, sizeof b, hi);
    const int has_unit = unit && unit[0] && strcmp(unit, "-");
    snprintf(out, n, "[%s, %s]%s%s", a, b, has_unit ? " " : "", has_unit ? unit : "");
}

int hyd_param_check(const hyd_param_info* p, double v, char* msg, size_t msgsz) {
    const char* need = NULL;
    if (!isfinite(v))
        need = "must be a finite number";
    else if (p->rule == HYD_R_POS && !(v > 0.0))
        need = "must be > 0";
    else if ((p->rule == HYD_R_NONNEG || p->rule == HYD_R_ZERO_DEF) && !(v >= 0.0))
        need = "must be >= 0";
    // A bounded rule whose hard range is narrower says the hard range (below):
    // "cd = 5: must be in [0, 1]" and then "cd = 0: must be in [0.1, 1]" named
    // two different ranges for one value.
    else if (p->rule == HYD_R_UNIT && !(v >= -1.0 && v <= 1.0) && !(p->lo >= -1.0 && p->hi <= 1.0))
        need = "must be in [-1, 1]";
    else if (p->rule == HYD_R_FRAC && !(v >= 0.0 && v <= 1.0) && !(p->lo >= 0.0 && p->hi <= 1.0))
        need = "must be in [0, 1]";
    char got[24];
    hyd_fmt_num(got, sizeof got, v);
    if (need) {
        snprintf(msg, msgsz, "%s, got %s", need, got);
        return -1;
    }
    if (p->rule == HYD_R_ZERO_DEF && v == 0.0)
        return 0; // 0: take the fluid's value
    if (v >= p->lo && v <= p->hi)
        return 0;
    char r[64];
    hyd_fmt_range(r, sizeof r, p->lo, p->hi, p->unit);
    snprintf(msg, msgsz, "must be %sin %s, got %s", p->rule == HYD_R_ZERO_DEF ? "0 (the fluid's) or " : "", r, got);
    return -1;
}

int hyd_param_typical(const hyd_param_info* p, double v, char* msg, size_t msgsz) {
    if ((p->rule == HYD_R_ZERO_DEF && v == 0.0) || (v >= p->tlo && v <= p->thi))
        return 0;
    char r[64], got[24];
    hyd_fmt_range(r, sizeof r, p->tlo, p->thi, p->unit);
    hyd_fmt_num(got, sizeof got, v);
    snprintf(msg, msgsz, "%s is outside the typical range %s", got, r);
    return -1;
}

void* hyd_elem_def(hyd_elem* e) { return &e->def; }
const void* hyd_elem_cdef(const hyd_elem* e) { return &e->def; }

static double* param_ptr(void* def, const hyd_param_info* p) {
    return (double*)((char*)def + p->off);
}

// ---------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------

int hyd_set_err(hyd_build_error* e, int where, int index, const char* field, const char* msg) {
    if (e) {
        e->where = where;
        e->index = index;
        snprintf(e->field, sizeof e->field, "%s", field);
        snprintf(e->msg, sizeof e->msg, "%s", msg);
    }
    return -1;
}

int hyd_validate_fluid(const hyd_fluid_def* f, hyd_build_error* e) {
    int np;
    const hyd_param_info* p = hyd_fluid_params(&np);
    char msg[160];
    for (int k = 0; k < np; ++k)
        if (hyd_param_check(&p[k], *param_ptr((void*)f, &p[k]), msg, sizeof msg))
            return hyd_set_err(e, 0, 0, p[k].name, msg);
    if (f->air_fraction >= 1.0)
        return hyd_set_err(e, 0, 0, "air_fraction", "must be < 1");
    return 0;
}

// Value rules of one element (not its ports or name uniqueness).
int hyd_validate_values(const hyd_elem* el, int where, int index, hyd_build_error* e) {
    int np;
    const hyd_param_info* p = hyd_params_of(el->type, &np);
    char msg[160];
    for (int k = 0; k < np; ++k)
        if (hyd_param_check(&p[k], *param_ptr((void*)&el->def, &p[k]), msg, sizeof msg))
            return hyd_set_err(e, where, index, p[k].name, msg);
    const hyd_component* c = hyd_component_of(el->type);
    if (c && c->validate) {
        char field[32];
        if (c->validate(&el->def, field, sizeof field, msg, sizeof msg))
            return hyd_set_err(e, where, index, field, msg);
    }
    return 0;
}

// ---------------------------------------------------------------------------
// Live parameters
// ---------------------------------------------------------------------------

// Resolve "<elem>.<field>" to the element and the parameter entry; for
// "fluid.<field>" *el is NULL.
static int resolve(const hyd_model* m, const char* path, hyd_elem** el,
                   const hyd_param_info** pi) {
    const char* dot = strchr(path, '.');
    if (!dot)
        return -1;
    size_t ln = (size_t)(dot - path);
    const char* field = dot + 1;
    int np;
    const hyd_param_info* p = NULL;
    *el = NULL;
    if (ln == 5 && strncmp(path, "fluid", 5) == 0) {
        p = hyd_fluid_params(&np);
    } else {
        for (int i = 0; i < m->nunode + m->ncomp && !*el; ++i) {
            hyd_elem* e = i < m->nunode ? &m->unode[i] : &m->comp[i - m->nunode];
            if (strlen(e->name) == ln && strncmp(e->name, path, ln) == 0)
                *el = e;
        }
        if (!*el)
            return -1;
        p = hyd_params_of((*el)->type, &np);
    }
    for (int k = 0; k < np; ++k)
        if (strcmp(p[k].name, field) == 0) {
            *pi = &p[k];
            return 0;
        }
    return -1;
}

int hyd_model_get(const hyd_model* m, const char* path, double* value) {
    hyd_elem* el;
    const hyd_param_info* pi;
    if (resolve(m, path, &el, &pi))
        return -1;
    *value = *param_ptr(el ? (void*)&el->def : (void*)&m->fluid, pi);
    return 0;
}

int hyd_model_set(hyd_model* m, const char* path, double value, char* err, size_t errsz) {
    hyd_elem* el;
    const hyd_param_info* pi;
    char msg[200];
    if (resolve(m, path, &el, &pi)) {
        if (err && errsz)
            snprintf(err, errsz, "%s: unknown parameter", path);
        return -1;
    }
    if (hyd_param_check(pi, value, msg, sizeof msg)) {
        if (err && errsz)
            snprintf(err, errsz, "%s: %s", path, msg);
        return -1;
    }
    // Cross-field rules are checked on a copy, so a rejected value changes nothing.
    if (el) {
        hyd_elem tmp = *el;
        *param_ptr(&tmp.def, pi) = value;
        hyd_build_error e;
        if (hyd_validate_values(&tmp, 2, 0, &e)) {
            if (err && errsz)
                snprintf(err, errsz, "%s.%s: %s", el->name, e.field, e.msg);
            return -1;
        }
        *param_ptr(&el->def, pi) = value;
    } else {
        hyd_fluid_def f = m->fluid;
        *param_ptr(&f, pi) = value;
        hyd_build_error e;
        if (hyd_validate_fluid(&f, &e)) {
            if (err && errsz)
                snprintf(err, errsz, "fluid.%s: %s", e.field, e.msg);
            return -1;
        }
        m->fluid = f;
    }
    hyd_model_derive(m, NULL);
    m->revision++;
    return 0;
}

unsigned hyd_model_revision(const hyd_model* m) { return m->revision; }

