// circuit.c: the circuit as data. Parameter tables, the builder, compilation
// into index arrays, live parameter changes, hyd_data, and the evaluation and
// Jacobian drivers that call the per-type kernels.
//
// Why per-type kernels instead of one switch per component in the hot loop:
// each kernel runs a tight loop over one record type, so branches are
// predictable and there is no per-component dispatch. The switch on type
// lives where it is cheap: in building, validation and the parameter tables.
#include "hyd_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// ---------------------------------------------------------------------------
// Type names, parameter and port tables (one place for the schema: the C API,
// the JSON loader, hyd_model_set and the docs all follow these tables).
// ---------------------------------------------------------------------------

static const char* const type_names[HYD_TYPE_COUNT] = {
    "tank", "volume", "pump", "relief", "check", "orifice", "hose", "valve", "cylinder"};

const char* hyd_type_name(hyd_type t) {
    return (t >= 0 && t < HYD_TYPE_COUNT) ? type_names[t] : "?";
}

int hyd_type_parse(const char* name) {
    for (int t = 0; t < HYD_TYPE_COUNT; ++t)
        if (strcmp(name, type_names[t]) == 0)
            return t;
    return -1;
}

// Each parameter has a hard range, outside which a circuit is refused (a
// value there is a typo or a unit slip, and the integrator would meet it as
// a blow-up or, worse, as a plausible wrong answer: p_crack = 22 Pa, meant as
// MPa, let the boom sink onto its stop with exit 0), and a typical range for
// crane-sized machines, outside which the loader prints a note. The ranges
// and their reasons are documented in docs/hydraulics.md ("Parameter
// ranges").
#define P_(T, f, unit, rule, req, lo, hi, tlo, thi) {#f, unit, offsetof(T, f), rule, req, lo, hi, tlo, thi}

static const hyd_param_info fluid_params[] = {
    P_(hyd_fluid_def, density, "kg/m^3", HYD_R_POS, 0, 500, 2000, 800, 1100),
    P_(hyd_fluid_def, viscosity, "m^2/s", HYD_R_POS, 0, 1e-7, 1e-2, 2e-6, 5e-4),
    P_(hyd_fluid_def, bulk_modulus, "Pa", HYD_R_POS, 0, 1e7, 1e10, 5e8, 2.5e9),
    P_(hyd_fluid_def, air_fraction, "-", HYD_R_FRAC, 0, 0, 0.5, 0, 0.02),
    P_(hyd_fluid_def, polytropic_index, "-", HYD_R_POS, 0, 1, 2, 1, 1.4),
    P_(hyd_fluid_def, p_atm, "Pa", HYD_R_POS, 0, 1e4, 2e5, 8e4, 1.1e5),
    P_(hyd_fluid_def, re_transition, "-", HYD_R_POS, 0, 1, 1e5, 10, 2000),
};
static const hyd_param_info tank_params[] = {
    P_(hyd_tank_def, pressure, "Pa", HYD_R_NONNEG, 0, 0, 1e7, 5e4, 1e6),
};
static const hyd_param_info volume_params[] = {
    P_(hyd_volume_def, volume, "m^3", HYD_R_POS, 1, 1e-9, 10, 1e-6, 0.1),
    P_(hyd_volume_def, bulk_modulus, "Pa", HYD_R_ZERO_DEF, 0, 1e7, 1e10, 1e8, 2.5e9),
    P_(hyd_volume_def, p0, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 5e7),
};
static const hyd_param_info pump_params[] = {
    P_(hyd_pump_def, q_max, "m^3/s", HYD_R_POS, 1, 1e-7, 0.1, 1e-5, 5e-3),
    P_(hyd_pump_def, p_set, "Pa", HYD_R_POS, 1, 1e5, 1e8, 5e6, 4.5e7),
    P_(hyd_pump_def, band, "Pa", HYD_R_POS, 0, 1e3, 1e7, 1e4, 3e6),
};
static const hyd_param_info relief_params[] = {
    P_(hyd_relief_def, p_crack, "Pa", HYD_R_POS, 1, 1e5, 1e8, 5e6, 4.5e7),
    P_(hyd_relief_def, dp_override, "Pa", HYD_R_POS, 0, 1e3, 1e7, 1e5, 5e6),
    P_(hyd_relief_def, q_rated, "m^3/s", HYD_R_POS, 0, 1e-7, 0.1, 1e-5, 5e-3),
};
static const hyd_param_info check_params[] = {
    P_(hyd_check_def, p_crack, "Pa", HYD_R_NONNEG, 0, 0, 1e7, 0, 1e6),
    P_(hyd_check_def, dp_open, "Pa", HYD_R_POS, 0, 1e2, 1e7, 5e3, 1e6),
    P_(hyd_check_def, q_rated, "m^3/s", HYD_R_POS, 0, 1e-7, 0.1, 1e-5, 5e-3),
};
static const hyd_param_info orifice_params[] = {
    P_(hyd_orifice_def, area, "m^2", HYD_R_POS, 1, 1e-10, 0.1, 1e-8, 1e-3),
    P_(hyd_orifice_def, cd, "-", HYD_R_FRAC, 0, 0, 1, 0.5, 0.8),
};
static const hyd_param_info hose_params[] = {
    P_(hyd_hose_def, length, "m", HYD_R_POS, 1, 0.01, 100, 0.2, 20),
    P_(hyd_hose_def, diameter, "m", HYD_R_POS, 1, 1e-3, 0.2, 4e-3, 0.05),
    P_(hyd_hose_def, bulk_modulus, "Pa", HYD_R_ZERO_DEF, 0, 1e7, 1e10, 1e8, 2.5e9),
    P_(hyd_hose_def, p0, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 5e7),
};
static const hyd_param_info valve_params[] = {
    P_(hyd_valve_def, q_nominal, "m^3/s", HYD_R_POS, 0, 1e-7, 0.1, 1e-5, 5e-3),
    P_(hyd_valve_def, dp_nominal, "Pa", HYD_R_POS, 0, 1e4, 1e7, 2e5, 3.5e6),
    // cd divides the rated flow into the largest opening: 0 would be infinite.
    P_(hyd_valve_def, cd, "-", HYD_R_FRAC, 0, 0.1, 1, 0.5, 0.8),
    P_(hyd_valve_def, tau, "s", HYD_R_POS, 0, 1e-4, 10, 5e-3, 0.2),
    P_(hyd_valve_def, u0, "-", HYD_R_UNIT, 0, -1, 1, -1, 1),
};
static const hyd_param_info cylinder_params[] = {
    P_(hyd_cylinder_def, bore, "m", HYD_R_POS, 1, 0.005, 1, 0.03, 0.3),
    P_(hyd_cylinder_def, rod, "m", HYD_R_POS, 1, 0.002, 1, 0.015, 0.2),
    P_(hyd_cylinder_def, stroke, "m", HYD_R_POS, 1, 0.01, 10, 0.1, 3),
    P_(hyd_cylinder_def, dead_volume_a, "m^3", HYD_R_POS, 0, 1e-8, 0.1, 1e-6, 1e-3),
    P_(hyd_cylinder_def, dead_volume_b, "m^3", HYD_R_POS, 0, 1e-8, 0.1, 1e-6, 1e-3),
    // 1e-10 m^3/(s Pa) leaks 60 L/min at 10 bar: the piston seal is gone.
    P_(hyd_cylinder_def, leakage, "m^3/(s Pa)", HYD_R_NONNEG, 0, 0, 1e-10, 0, 1e-11),
    P_(hyd_cylinder_def, friction, "N s/m", HYD_R_NONNEG, 0, 0, 1e7, 0, 1e5),
    P_(hyd_cylinder_def, stop_stiffness, "N/m", HYD_R_POS, 0, 1e5, 1e11, 1e7, 5e9),
    P_(hyd_cylinder_def, stop_damping, "N s/m", HYD_R_NONNEG, 0, 0, 1e9, 0, 1e7),
    P_(hyd_cylinder_def, stop_width, "m", HYD_R_POS, 0, 1e-5, 0.05, 1e-4, 1e-2),
    P_(hyd_cylinder_def, p0_a, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 5e7),
    P_(hyd_cylinder_def, p0_b, "Pa", HYD_R_NONNEG, 0, 0, 1e8, 0, 5e7),
};
#undef P_

#define N_(a) ((int)(sizeof(a) / sizeof(a[0])))

const hyd_param_info* hyd_fluid_params(int* count) {
    *count = N_(fluid_params);
    return fluid_params;
}

const hyd_param_info* hyd_params_of(hyd_type t, int* count) {
    switch (t) {
    case HYD_TANK: *count = N_(tank_params); return tank_params;
    case HYD_VOLUME: *count = N_(volume_params); return volume_params;
    case HYD_PUMP: *count = N_(pump_params); return pump_params;
    case HYD_RELIEF: *count = N_(relief_params); return relief_params;
    case HYD_CHECK: *count = N_(check_params); return check_params;
    case HYD_ORIFICE: *count = N_(orifice_params); return orifice_params;
    case HYD_HOSE: *count = N_(hose_params); return hose_params;
    case HYD_VALVE: *count = N_(valve_params); return valve_params;
    case HYD_CYLINDER: *count = N_(cylinder_params); return cylinder_params;
    default: *count = 0; return NULL;
    }
}

#define PORT_(T, f) {#f, offsetof(T, f)}
static const hyd_port_info pump_ports[] = {PORT_(hyd_pump_def, inlet), PORT_(hyd_pump_def, outlet)};
static const hyd_port_info relief_ports[] = {PORT_(hyd_relief_def, inlet),
                                             PORT_(hyd_relief_def, outlet)};
static const hyd_port_info check_ports[] = {PORT_(hyd_check_def, inlet),
                                            PORT_(hyd_check_def, outlet)};
static const hyd_port_info orifice_ports[] = {PORT_(hyd_orifice_def, inlet),
                                              PORT_(hyd_orifice_def, outlet)};
static const hyd_port_info hose_ports[] = {PORT_(hyd_hose_def, to)};
static const hyd_port_info valve_ports[] = {PORT_(hyd_valve_def, P), PORT_(hyd_valve_def, T),
                                            PORT_(hyd_valve_def, A), PORT_(hyd_valve_def, B)};
#undef PORT_

const hyd_port_info* hyd_ports_of(hyd_type t, int* count) {
    switch (t) {
    case HYD_PUMP: *count = 2; return pump_ports;
    case HYD_RELIEF: *count = 2; return relief_ports;
    case HYD_CHECK: *count = 2; return check_ports;
    case HYD_ORIFICE: *count = 2; return orifice_ports;
    case HYD_HOSE: *count = 1; return hose_ports;
    case HYD_VALVE: *count = 4; return valve_ports;
    default: *count = 0; return NULL;
    }
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
static void range_text(char* out, size_t n, double lo, double hi, const char* unit) {
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
    else if (p->rule == HYD_R_UNIT && !(v >= -1.0 && v <= 1.0))
        need = "must be in [-1, 1]";
    else if (p->rule == HYD_R_FRAC && !(v >= 0.0 && v <= 1.0))
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
    range_text(r, sizeof r, p->lo, p->hi, p->unit);
    snprintf(msg, msgsz, "must be %sin %s, got %s", p->rule == HYD_R_ZERO_DEF ? "0 (the fluid's) or " : "", r, got);
    return -1;
}

int hyd_param_typical(const hyd_param_info* p, double v, char* msg, size_t msgsz) {
    if ((p->rule == HYD_R_ZERO_DEF && v == 0.0) || (v >= p->tlo && v <= p->thi))
        return 0;
    char r[64], got[24];
    range_text(r, sizeof r, p->tlo, p->thi, p->unit);
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
// Builder
// ---------------------------------------------------------------------------

struct hyd_builder {
    hyd_fluid_def fluid;
    hyd_elem* node;
    int nnode, capnode;
    hyd_elem* comp;
    int ncomp, capcomp;
    int oom; ///< an add failed for lack of memory; compile reports it
};

static char* dupstr(const char* s) {
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char* r = malloc(n);
    if (r)
        memcpy(r, s, n);
    return r;
}

static void elem_free(hyd_elem* e) {
    free(e->name);
    for (int k = 0; k < HYD_MAXPORT; ++k)
        free(e->port[k]);
}

// Deep copy: the def's name and port pointers are redirected to owned strings.
static int elem_copy(hyd_elem* dst, const hyd_elem* src) {
    *dst = *src;
    dst->name = dupstr(src->name);
    int np;
    const hyd_port_info* pi = hyd_ports_of(src->type, &np);
    for (int k = 0; k < HYD_MAXPORT; ++k)
        dst->port[k] = (k < np) ? dupstr(src->port[k]) : NULL;
    char* base = hyd_elem_def(dst);
    *(const char**)base = dst->name; // every def starts with name
    for (int k = 0; k < np; ++k)
        *(const char**)(base + pi[k].off) = dst->port[k];
    if ((src->name && !dst->name))
        return -1;
    for (int k = 0; k < np; ++k)
        if (src->port[k] && !dst->port[k])
            return -1;
    return 0;
}

hyd_builder* hyd_builder_create(void) {
    hyd_builder* b = calloc(1, sizeof *b);
    if (b)
        b->fluid = hyd_default_fluid_def();
    return b;
}

void hyd_builder_free(hyd_builder* b) {
    if (!b)
        return;
    for (int i = 0; i < b->nnode; ++i)
        elem_free(&b->node[i]);
    for (int i = 0; i < b->ncomp; ++i)
        elem_free(&b->comp[i]);
    free(b->node);
    free(b->comp);
    free(b);
}

void hyd_builder_set_fluid(hyd_builder* b, const hyd_fluid_def* fluid) { b->fluid = *fluid; }

static int builder_add(hyd_builder* b, hyd_type t, const void* def, size_t size) {
    const int is_node = t == HYD_TANK || t == HYD_VOLUME;
    hyd_elem** arr = is_node ? &b->node : &b->comp;
    int* n = is_node ? &b->nnode : &b->ncomp;
    int* cap = is_node ? &b->capnode : &b->capcomp;
    if (*n == *cap) {
        int nc = *cap ? 2 * *cap : 16;
        hyd_elem* na = realloc(*arr, (size_t)nc * sizeof **arr);
        if (!na) {
            b->oom = 1;
            return -1;
        }
        *arr = na;
        *cap = nc;
    }
    hyd_elem src;
    memset(&src, 0, sizeof src);
    src.type = t;
    memcpy(&src.def, def, size);
    src.name = (char*)*(const char* const*)def;
    int np;
    const hyd_port_info* pi = hyd_ports_of(t, &np);
    for (int k = 0; k < np; ++k)
        src.port[k] = (char*)*(const char* const*)((const char*)def + pi[k].off);
    if (elem_copy(&(*arr)[*n], &src) != 0) {
        elem_free(&(*arr)[*n]);
        b->oom = 1;
        return -1;
    }
    return (*n)++;
}

int hyd_add_tank(hyd_builder* b, const hyd_tank_def* d) { return builder_add(b, HYD_TANK, d, sizeof *d); }
int hyd_add_volume(hyd_builder* b, const hyd_volume_def* d) { return builder_add(b, HYD_VOLUME, d, sizeof *d); }
int hyd_add_pump(hyd_builder* b, const hyd_pump_def* d) { return builder_add(b, HYD_PUMP, d, sizeof *d); }
int hyd_add_relief(hyd_builder* b, const hyd_relief_def* d) { return builder_add(b, HYD_RELIEF, d, sizeof *d); }
int hyd_add_check(hyd_builder* b, const hyd_check_def* d) { return builder_add(b, HYD_CHECK, d, sizeof *d); }
int hyd_add_orifice(hyd_builder* b, const hyd_orifice_def* d) { return builder_add(b, HYD_ORIFICE, d, sizeof *d); }
int hyd_add_hose(hyd_builder* b, const hyd_hose_def* d) { return builder_add(b, HYD_HOSE, d, sizeof *d); }
int hyd_add_valve(hyd_builder* b, const hyd_valve_def* d) { return builder_add(b, HYD_VALVE, d, sizeof *d); }
int hyd_add_cylinder(hyd_builder* b, const hyd_cylinder_def* d) { return builder_add(b, HYD_CYLINDER, d, sizeof *d); }

// ---------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------

static int set_err(hyd_build_error* e, int where, int index, const char* field, const char* msg) {
    if (e) {
        e->where = where;
        e->index = index;
        snprintf(e->field, sizeof e->field, "%s", field);
        snprintf(e->msg, sizeof e->msg, "%s", msg);
    }
    return -1;
}

static int validate_fluid(const hyd_fluid_def* f, hyd_build_error* e) {
    int np;
    const hyd_param_info* p = hyd_fluid_params(&np);
    char msg[160];
    for (int k = 0; k < np; ++k)
        if (hyd_param_check(&p[k], *param_ptr((void*)f, &p[k]), msg, sizeof msg))
            return set_err(e, 0, 0, p[k].name, msg);
    if (f->air_fraction >= 1.0)
        return set_err(e, 0, 0, "air_fraction", "must be < 1");
    return 0;
}

// Value rules of one element (not its ports or name uniqueness).
static int validate_values(const hyd_elem* el, int where, int index, hyd_build_error* e) {
    int np;
    const hyd_param_info* p = hyd_params_of(el->type, &np);
    char msg[160];
    for (int k = 0; k < np; ++k)
        if (hyd_param_check(&p[k], *param_ptr((void*)&el->def, &p[k]), msg, sizeof msg))
            return set_err(e, where, index, p[k].name, msg);
    if (el->type == HYD_CYLINDER) {
        char field[32];
        if (hyd_cylinder_validate(&el->def.cylinder, field, sizeof field, msg, sizeof msg))
            return set_err(e, where, index, field, msg);
    }
    return 0;
}

static int validate_name(const hyd_elem* el, int where, int index, hyd_build_error* e) {
    if (!el->name || !el->name[0])
        return set_err(e, where, index, "name", "missing or empty");
    if (strchr(el->name, '.'))
        return set_err(e, where, index, "name", "must not contain '.' (used in state names)");
    if (strcmp(el->name, "fluid") == 0)
        return set_err(e, where, index, "name", "'fluid' is reserved");
    return 0;
}

// ---------------------------------------------------------------------------
// Compile
// ---------------------------------------------------------------------------

static int find_name(char* const* names, int n, const char* s) {
    for (int i = 0; i < n; ++i)
        if (strcmp(names[i], s) == 0)
            return i;
    return -1;
}

static char* joinname(const char* a, const char* b) {
    size_t la = strlen(a), lb = strlen(b);
    char* r = malloc(la + lb + 2);
    if (r) {
        memcpy(r, a, la);
        r[la] = '.';
        memcpy(r + la + 1, b, lb + 1);
    }
    return r;
}

void hyd_model_free(hyd_model* m) {
    if (!m)
        return;
    for (int i = 0; i < m->nunode; ++i)
        elem_free(&m->unode[i]);
    for (int i = 0; i < m->ncomp; ++i)
        elem_free(&m->comp[i]);
    if (m->node_name)
        for (int i = 0; i < m->nnode; ++i)
            free(m->node_name[i]);
    if (m->state_name)
        for (int i = 0; i < m->nstate; ++i)
            free(m->state_name[i]);
    free(m->unode);
    free(m->comp);
    free(m->node_name);
    free(m->node_state);
    free(m->node_sidx);
    free(m->node_V0);
    free(m->node_bel);
    free(m->node_bec);
    free(m->node_pfix);
    free(m->node_p0);
    free(m->vol_node);
    free(m->tank_node);
    free(m->pump);
    free(m->relief);
    free(m->check);
    free(m->orifice);
    free(m->hose);
    free(m->valve);
    free(m->cyl);
    free(m->comp_sub);
    free(m->vol_ptr);
    free(m->vol_flow);
    free(m->state_name);
    free(m->y0);
    free(m);
}

#define ALLOC_(p, n) ((p) = calloc((size_t)((n) > 0 ? (n) : 1), sizeof *(p)), (p) != NULL)

// Node at each flow slot of component c (4 slots, -1 if unused), in the port
// order documented at hyd_model.vol_ptr.
static void comp_slots(const hyd_model* m, int c, int* node) {
    const int s = m->comp_sub[c];
    node[0] = node[1] = node[2] = node[3] = -1;
    switch (m->comp[c].type) {
    case HYD_PUMP: node[0] = m->pump[s].in; node[1] = m->pump[s].out; break;
    case HYD_RELIEF: node[0] = m->relief[s].in; node[1] = m->relief[s].out; break;
    case HYD_CHECK: node[0] = m->check[s].in; node[1] = m->check[s].out; break;
    case HYD_ORIFICE: node[0] = m->orifice[s].in; node[1] = m->orifice[s].out; break;
    case HYD_HOSE: node[0] = m->hose[s].node; node[1] = m->hose[s].to; break;
    case HYD_VALVE:
        node[0] = m->valve[s].P;
        node[1] = m->valve[s].T;
        node[2] = m->valve[s].A;
        node[3] = m->valve[s].B;
        break;
    case HYD_CYLINDER: node[0] = m->cyl[s].nA; node[1] = m->cyl[s].nB; break;
    default: break;
    }
}

// CSR lists of the flow slots that feed each volume node (tanks get none:
// their inflow is never needed).
static int build_incidence(hyd_model* m) {
    if (!ALLOC_(m->vol_ptr, m->nvol + 1) || !ALLOC_(m->vol_flow, 4 * m->ncomp))
        return -1;
    int ne = 0;
    for (int k = 0; k < m->nvol; ++k) {
        m->vol_ptr[k] = ne;
        for (int c = 0; c < m->ncomp; ++c) {
            int node[4];
            comp_slots(m, c, node);
            for (int j = 0; j < 4; ++j)
                if (node[j] == m->vol_node[k])
                    m->vol_flow[ne++] = 4 * c + j;
        }
    }
    m->vol_ptr[m->nvol] = ne;
    return 0;
}

hyd_model* hyd_compile_ex(const hyd_builder* b, hyd_build_error* e) {
    if (e) {
        e->where = -1;
        e->index = 0;
        e->field[0] = e->msg[0] = 0;
    }
    if (b->oom)
        return set_err(e, -1, 0, "", "out of memory while building"), NULL;
    if (validate_fluid(&b->fluid, e))
        return NULL;
    for (int i = 0; i < b->nnode; ++i)
        if (validate_name(&b->node[i], 1, i, e) || validate_values(&b->node[i], 1, i, e))
            return NULL;
    for (int i = 0; i < b->ncomp; ++i)
        if (validate_name(&b->comp[i], 2, i, e) || validate_values(&b->comp[i], 2, i, e))
            return NULL;
    // Element names are unique across nodes and components, so a path
    // "<name>.<field>" is never ambiguous.
    for (int i = 0; i < b->nnode + b->ncomp; ++i) {
        const hyd_elem* ei = i < b->nnode ? &b->node[i] : &b->comp[i - b->nnode];
        for (int j = 0; j < i; ++j) {
            const hyd_elem* ej = j < b->nnode ? &b->node[j] : &b->comp[j - b->nnode];
            if (strcmp(ei->name, ej->name) == 0) {
                char msg[160];
                snprintf(msg, sizeof msg, "duplicate name '%s' (also %s[%d])", ei->name,
                         j < b->nnode ? "nodes" : "components", j < b->nnode ? j : j - b->nnode);
                return set_err(e, i < b->nnode ? 1 : 2, i < b->nnode ? i : i - b->nnode,
                               "name", msg),
                       NULL;
            }
        }
    }

    hyd_model* m = calloc(1, sizeof *m);
    if (!m)
        return set_err(e, -1, 0, "", "out of memory"), NULL;
    m->fluid = b->fluid;
    m->nunode = b->nnode;
    m->ncomp = b->ncomp;

    // Count nodes and states per type.
    int nnode = b->nnode, nstate = 0;
    for (int i = 0; i < b->nnode; ++i)
        nstate += b->node[i].type == HYD_VOLUME;
    for (int i = 0; i < b->ncomp; ++i) {
        switch (b->comp[i].type) {
        case HYD_PUMP: m->npump++; break;
        case HYD_RELIEF: m->nrelief++; break;
        case HYD_CHECK: m->ncheck++; break;
        case HYD_ORIFICE: m->norifice++; break;
        case HYD_HOSE: m->nhose++; nnode += 1; nstate += 1; break;
        case HYD_VALVE: m->nvalve++; nstate += 1; break;
        case HYD_CYLINDER: m->ncyl++; nnode += 2; nstate += 2; break;
        default: break;
        }
    }
    m->nnode = nnode;
    m->nstate = nstate;
    int ok = ALLOC_(m->unode, b->nnode) && ALLOC_(m->comp, b->ncomp) &&
             ALLOC_(m->node_name, nnode) && ALLOC_(m->node_state, nnode) &&
             ALLOC_(m->node_sidx, nnode) && ALLOC_(m->node_V0, nnode) &&
             ALLOC_(m->node_bel, nnode) && ALLOC_(m->node_pfix, nnode) &&
             ALLOC_(m->node_bec, nnode) &&
             ALLOC_(m->node_p0, nnode) && ALLOC_(m->vol_node, nnode) &&
             ALLOC_(m->tank_node, nnode) && ALLOC_(m->pump, m->npump) &&
             ALLOC_(m->relief, m->nrelief) && ALLOC_(m->check, m->ncheck) &&
             ALLOC_(m->orifice, m->norifice) && ALLOC_(m->hose, m->nhose) &&
             ALLOC_(m->valve, m->nvalve) && ALLOC_(m->cyl, m->ncyl) &&
             ALLOC_(m->comp_sub, b->ncomp) && ALLOC_(m->state_name, nstate) &&
             ALLOC_(m->y0, nstate);
    // Elements are copied one by one and counted, so a failed copy frees cleanly.
    int nu = 0, nc = 0;
    if (ok) {
        for (; nu < b->nnode && ok; ++nu)
            ok = elem_copy(&m->unode[nu], &b->node[nu]) == 0;
        for (; nc < b->ncomp && ok; ++nc)
            ok = elem_copy(&m->comp[nc], &b->comp[nc]) == 0;
    }
    m->nunode = nu;
    m->ncomp = nc;
    if (!ok) {
        hyd_model_free(m);
        return set_err(e, -1, 0, "", "out of memory"), NULL;
    }

    // Node names: user nodes, then owned nodes in component order.
    int in = 0;
    for (int i = 0; i < b->nnode; ++i)
        m->node_name[in++] = dupstr(b->node[i].name);
    for (int i = 0; i < b->ncomp; ++i) {
        if (b->comp[i].type == HYD_HOSE)
            m->node_name[in++] = dupstr(b->comp[i].name);
        else if (b->comp[i].type == HYD_CYLINDER) {
            m->node_name[in++] = joinname(b->comp[i].name, "A");
            m->node_name[in++] = joinname(b->comp[i].name, "B");
        }
    }
    for (int i = 0; i < nnode; ++i)
        if (!m->node_name[i]) {
            hyd_model_free(m);
            return set_err(e, -1, 0, "", "out of memory"), NULL;
        }

    // States and owned-node bookkeeping, in the documented order.
    int is = 0, owned = b->nnode;
    for (int i = 0; i < nnode; ++i)
        m->node_state[i] = -1;
    for (int i = 0; i < b->nnode; ++i)
        if (b->node[i].type == HYD_VOLUME) {
            m->node_state[i] = is;
            m->state_name[is++] = joinname(b->node[i].name, "p");
        }
    int ip = 0, ir = 0, ic = 0, io = 0, ih = 0, iv = 0, iy = 0;
    for (int i = 0; i < b->ncomp; ++i) {
        const hyd_elem* el = &b->comp[i];
        switch (el->type) {
        case HYD_PUMP: m->comp_sub[i] = ip; m->pump[ip++].comp = i; break;
        case HYD_RELIEF: m->comp_sub[i] = ir; m->relief[ir++].comp = i; break;
        case HYD_CHECK: m->comp_sub[i] = ic; m->check[ic++].comp = i; break;
        case HYD_ORIFICE: m->comp_sub[i] = io; m->orifice[io++].comp = i; break;
        case HYD_HOSE:
            m->comp_sub[i] = ih;
            m->hose[ih].comp = i;
            m->hose[ih].node = owned;
            m->node_state[owned++] = is;
            m->state_name[is++] = joinname(el->name, "p");
            ih++;
            break;
        case HYD_VALVE:
            m->comp_sub[i] = iv;
            m->valve[iv].comp = i;
            m->valve[iv].adr = is;
            m->state_name[is++] = joinname(el->name, "spool");
            iv++;
            break;
        case HYD_CYLINDER:
            m->comp_sub[i] = iy;
            m->cyl[iy].comp = i;
            m->cyl[iy].nA = owned;
            m->cyl[iy].sA = is;
            m->node_state[owned++] = is;
            m->state_name[is++] = joinname(el->name, "pA");
            m->cyl[iy].nB = owned;
            m->cyl[iy].sB = is;
            m->node_state[owned++] = is;
            m->state_name[is++] = joinname(el->name, "pB");
            iy++;
            break;
        default: break;
        }
    }
    for (int i = 0; i < nstate; ++i)
        if (!m->state_name[i]) {
            hyd_model_free(m);
            return set_err(e, -1, 0, "", "out of memory"), NULL;
        }
    for (int i = 0; i < nnode; ++i) {
        m->node_sidx[i] = m->node_state[i] >= 0 ? m->node_state[i] : nstate;
        if (m->node_state[i] >= 0)
            m->vol_node[m->nvol++] = i;
        else
            m->tank_node[m->ntank++] = i;
    }

    // Resolve ports by node name, counting the ports on each user node.
    int* conn = calloc((size_t)(nnode > 0 ? nnode : 1), sizeof *conn);
    if (!conn) {
        hyd_model_free(m);
        return set_err(e, -1, 0, "", "out of memory"), NULL;
    }
    for (int i = 0; i < b->ncomp; ++i) {
        const hyd_elem* el = &b->comp[i];
        int np;
        const hyd_port_info* pi = hyd_ports_of(el->type, &np);
        int node[HYD_MAXPORT] = {0};
        for (int k = 0; k < np; ++k) {
            char msg[200];
            if (!el->port[k]) {
                free(conn);
                hyd_model_free(m);
                return set_err(e, 2, i, pi[k].name, "missing node name"), NULL;
            }
            node[k] = find_name(m->node_name, nnode, el->port[k]);
            if (node[k] < 0) {
                snprintf(msg, sizeof msg, "unknown node '%s'", el->port[k]);
                free(conn);
                hyd_model_free(m);
                return set_err(e, 2, i, pi[k].name, msg), NULL;
            }
            for (int j = 0; j < k; ++j)
                if (node[j] == node[k]) {
                    snprintf(msg, sizeof msg, "same node '%s' as %s", el->port[k], pi[j].name);
                    free(conn);
                    hyd_model_free(m);
                    return set_err(e, 2, i, pi[k].name, msg), NULL;
                }
        }
        for (int k = 0; k < np; ++k)
            ++conn[node[k]];
        const int s = m->comp_sub[i];
        // A valve's T port returns to the tank; on a cylinder chamber it
        // would drain that chamber whenever the spool opens (a swapped port).
        if (el->type == HYD_VALVE)
            for (int c = 0; c < m->ncyl; ++c)
                if (node[1] == m->cyl[c].nA || node[1] == m->cyl[c].nB) {
                    char msg[200];
                    snprintf(msg, sizeof msg,
                             "'%s' is a cylinder chamber; T is the return to the tank (P, A or B meant?)",
                             el->port[1]);
                    free(conn);
                    hyd_model_free(m);
                    return set_err(e, 2, i, "T", msg), NULL;
                }
        switch (el->type) {
        case HYD_PUMP: m->pump[s].in = node[0]; m->pump[s].out = node[1]; break;
        case HYD_RELIEF: m->relief[s].in = node[0]; m->relief[s].out = node[1]; break;
        case HYD_CHECK: m->check[s].in = node[0]; m->check[s].out = node[1]; break;
        case HYD_ORIFICE: m->orifice[s].in = node[0]; m->orifice[s].out = node[1]; break;
        case HYD_HOSE:
            if (node[0] == m->hose[s].node) {
                free(conn);
                hyd_model_free(m);
                return set_err(e, 2, i, "to", "a hose cannot end at its own node"), NULL;
            }
            m->hose[s].to = node[0];
            break;
        case HYD_VALVE:
            m->valve[s].P = node[0];
            m->valve[s].T = node[1];
            m->valve[s].A = node[2];
            m->valve[s].B = node[3];
            break;
        default: break;
        }
    }
    // A user node that nothing connects to is a typo or a leftover (its
    // pressure would be a state that never changes). One port is enough: a
    // pump charging a closed volume is a proper circuit.
    for (int i = 0; i < b->nnode; ++i)
        if (!conn[i]) {
            char msg[200];
            snprintf(msg, sizeof msg, "'%s' is connected to no component (an isolated %s)", b->node[i].name,
                     b->node[i].type == HYD_VOLUME ? "volume" : "tank");
            free(conn);
            hyd_model_free(m);
            return set_err(e, 1, i, "name", msg), NULL;
        }
    free(conn);
    if (build_incidence(m)) {
        hyd_model_free(m);
        return set_err(e, -1, 0, "", "out of memory"), NULL;
    }
    hyd_model_derive(m, e);
    return m;
}

hyd_model* hyd_compile(const hyd_builder* b, char* err, size_t errsz) {
    hyd_build_error e;
    hyd_model* m = hyd_compile_ex(b, &e);
    if (!m && err && errsz) {
        const char* name = "fluid";
        if (e.where == 1 && e.index < b->nnode && b->node[e.index].name)
            name = b->node[e.index].name;
        else if (e.where == 2 && e.index < b->ncomp && b->comp[e.index].name)
            name = b->comp[e.index].name;
        if (e.where == -1)
            snprintf(err, errsz, "%s", e.msg);
        else if ((e.where == 1 || e.where == 2) && !strcmp(e.field, "name"))
            snprintf(err, errsz, "%s[%d].name: %s", e.where == 1 ? "nodes" : "components",
                     e.index, e.msg);
        else
            snprintf(err, errsz, "%s.%s: %s", name, e.field, e.msg);
    }
    return m;
}

// ---------------------------------------------------------------------------
// Derived arrays
// ---------------------------------------------------------------------------

int hyd_model_derive(hyd_model* m, hyd_build_error* e) {
    (void)e;
    const hyd_fluid_def* f = &m->fluid;
    m->be_alpha = f->air_fraction;
    m->be_inv_n = 1.0 / f->polytropic_index;
    for (int i = 0; i < m->nunode; ++i) {
        const hyd_elem* el = &m->unode[i];
        if (el->type == HYD_TANK) {
            m->node_pfix[i] = el->def.tank.pressure;
            m->node_p0[i] = el->def.tank.pressure;
            m->node_V0[i] = 0.0;
            m->node_bel[i] = f->bulk_modulus;
        } else {
            const hyd_volume_def* v = &el->def.volume;
            m->node_pfix[i] = 0.0;
            m->node_p0[i] = v->p0;
            m->node_V0[i] = v->volume;
            m->node_bel[i] = v->bulk_modulus > 0.0 ? v->bulk_modulus : f->bulk_modulus;
        }
    }
    for (int i = 0; i < m->ncomp; ++i) {
        const hyd_elem* el = &m->comp[i];
        const int s = m->comp_sub[i];
        switch (el->type) {
        case HYD_PUMP: hyd_pump_derive(&el->def.pump, &m->pump[s]); break;
        case HYD_RELIEF: hyd_relief_derive(&el->def.relief, &m->relief[s]); break;
        case HYD_CHECK: hyd_check_derive(&el->def.check, &m->check[s]); break;
        case HYD_ORIFICE:
            m->orifice[s].A = el->def.orifice.area;
            m->orifice[s].ok = hyd_orifice_constants(f, el->def.orifice.cd);
            break;
        case HYD_HOSE: {
            const hyd_hose_def* h = &el->def.hose;
            const int nd = m->hose[s].node;
            hyd_hose_derive(f, h, &m->hose[s]);
            m->node_V0[nd] = hyd_hose_volume(h);
            m->node_bel[nd] = h->bulk_modulus > 0.0 ? h->bulk_modulus : f->bulk_modulus;
            m->node_p0[nd] = h->p0;
            m->node_pfix[nd] = 0.0;
            break;
        }
        case HYD_VALVE: hyd_valve_derive(f, &el->def.valve, &m->valve[s]); break;
        case HYD_CYLINDER: {
            hyd_cyl_c* c = &m->cyl[s];
            hyd_cylinder_derive(&el->def.cylinder, c);
            // The chamber volume is written by the cylinder kernel each call.
            m->node_V0[c->nA] = m->node_V0[c->nB] = 0.0;
            m->node_bel[c->nA] = m->node_bel[c->nB] = f->bulk_modulus;
            m->node_p0[c->nA] = el->def.cylinder.p0_a;
            m->node_p0[c->nB] = el->def.cylinder.p0_b;
            break;
        }
        default: break;
        }
    }
    hyd_air_tab_init(&m->air, f);
    for (int i = 0; i < m->nnode; ++i) {
        m->node_bec[i] = m->be_alpha * m->node_bel[i] * m->be_inv_n;
    }
    for (int k = 0; k < m->nvol; ++k)
        m->y0[m->node_state[m->vol_node[k]]] = m->node_p0[m->vol_node[k]];
    for (int v = 0; v < m->nvalve; ++v)
        m->y0[m->valve[v].adr] = m->comp[m->valve[v].comp].def.valve.u0;
    return 0;
}

// ---------------------------------------------------------------------------
// Queries
// ---------------------------------------------------------------------------

int hyd_model_nstate(const hyd_model* m) { return m->nstate; }
int hyd_model_nnode(const hyd_model* m) { return m->nnode; }
int hyd_model_ncomp(const hyd_model* m) { return m->ncomp; }
int hyd_model_ncylinder(const hyd_model* m) { return m->ncyl; }
int hyd_model_nvalve(const hyd_model* m) { return m->nvalve; }

int hyd_model_find(const hyd_model* m, const char* name) {
    for (int i = 0; i < m->ncomp; ++i)
        if (strcmp(m->comp[i].name, name) == 0)
            return i;
    return -1;
}

int hyd_model_find_node(const hyd_model* m, const char* name) {
    return find_name(m->node_name, m->nnode, name);
}

int hyd_model_cylinder(const hyd_model* m, const char* name) {
    int c = hyd_model_find(m, name);
    return (c >= 0 && m->comp[c].type == HYD_CYLINDER) ? m->comp_sub[c] : -1;
}

int hyd_model_valve(const hyd_model* m, const char* name) {
    int c = hyd_model_find(m, name);
    return (c >= 0 && m->comp[c].type == HYD_VALVE) ? m->comp_sub[c] : -1;
}

int hyd_model_find_state(const hyd_model* m, const char* name) {
    return find_name(m->state_name, m->nstate, name);
}

const char* hyd_model_comp_name(const hyd_model* m, int c) {
    return (c >= 0 && c < m->ncomp) ? m->comp[c].name : NULL;
}
hyd_type hyd_model_comp_type(const hyd_model* m, int c) {
    return (c >= 0 && c < m->ncomp) ? m->comp[c].type : HYD_TYPE_COUNT;
}
const char* hyd_model_node_name(const hyd_model* m, int i) {
    return (i >= 0 && i < m->nnode) ? m->node_name[i] : NULL;
}
int hyd_model_node_state(const hyd_model* m, int i) {
    return (i >= 0 && i < m->nnode) ? m->node_state[i] : -1;
}
const char* hyd_model_state_name(const hyd_model* m, int i) {
    return (i >= 0 && i < m->nstate) ? m->state_name[i] : NULL;
}
void hyd_model_cylinder_states(const hyd_model* m, int c, int* iA, int* iB) {
    *iA = m->cyl[c].sA;
    *iB = m->cyl[c].sB;
}
int hyd_model_valve_state(const hyd_model* m, int v) { return m->valve[v].adr; }
int hyd_model_cylinder_comp(const hyd_model* m, int c) { return m->cyl[c].comp; }
int hyd_model_valve_comp(const hyd_model* m, int v) { return m->valve[v].comp; }
int hyd_model_relief_inlet(const hyd_model* m, int c) {
    if (c < 0 || c >= m->ncomp || m->comp[c].type != HYD_RELIEF) return -1;
    return m->relief[m->comp_sub[c]].in;
}
void hyd_model_cylinder_geometry(const hyd_model* m, int c, double* AA, double* AB, double* s) {
    *AA = m->cyl[c].AA;
    *AB = m->cyl[c].AB;
    *s = m->cyl[c].s;
}
void hyd_model_initial_state(const hyd_model* m, double* y) {
    memcpy(y, m->y0, (size_t)m->nstate * sizeof *y);
}
hyd_fluid_def hyd_model_fluid(const hyd_model* m) { return m->fluid; }

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
        if (validate_values(&tmp, 2, 0, &e)) {
            if (err && errsz)
                snprintf(err, errsz, "%s.%s: %s", el->name, e.field, e.msg);
            return -1;
        }
        *param_ptr(&el->def, pi) = value;
    } else {
        hyd_fluid_def f = m->fluid;
        *param_ptr(&f, pi) = value;
        hyd_build_error e;
        if (validate_fluid(&f, &e)) {
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

// ---------------------------------------------------------------------------
// Data
// ---------------------------------------------------------------------------

void hyd_data_free(hyd_data* d) {
    if (!d)
        return;
    free(d->cyl_x);
    free(d->cyl_v);
    free(d->valve_cmd);
    free(d->cyl_F);
    free(d->cyl_stop);
    free(d->comp_q);
    free(d->comp_open);
    free(d->node_p);
    free(d->node_V);
    free(d->node_be);
    free(d->node_q);
    free(d->node_dV);
    free(d->dydx);
    free(d->dydv);
    free(d->dFdy);
    free(d->dFdx);
    free(d->dFdv);
    free(d->scratch_);
    free(d->flow_);
    free(d);
}

hyd_data* hyd_data_create(const hyd_model* m) {
    hyd_data* d = calloc(1, sizeof *d);
    if (!d)
        return NULL;
    const int n = m->nstate, nc = m->ncyl;
    d->n_ = n;
    d->nnode_ = m->nnode;
    d->ncomp_ = m->ncomp;
    d->ncyl_ = nc;
    d->nvalve_ = m->nvalve;
    int ok = ALLOC_(d->cyl_x, nc) && ALLOC_(d->cyl_v, nc) && ALLOC_(d->valve_cmd, m->nvalve) &&
             ALLOC_(d->cyl_F, nc) && ALLOC_(d->cyl_stop, nc) &&
             ALLOC_(d->comp_q, 2 * m->ncomp) && ALLOC_(d->comp_open, m->ncomp) &&
             ALLOC_(d->node_p, m->nnode) && ALLOC_(d->node_V, m->nnode) &&
             ALLOC_(d->node_be, m->nnode) && ALLOC_(d->node_q, m->nnode) &&
             ALLOC_(d->node_dV, m->nnode) && ALLOC_(d->dydx, nc * n) &&
             ALLOC_(d->dydv, nc * n) && ALLOC_(d->dFdy, nc * n) && ALLOC_(d->dFdx, nc) &&
             ALLOC_(d->dFdv, nc) && ALLOC_(d->scratch_, (n + 1) * (n + 1)) &&
             ALLOC_(d->flow_, 4 * m->ncomp);
    if (!ok) {
        hyd_data_free(d);
        return NULL;
    }
    return d;
}

// ---------------------------------------------------------------------------
// Evaluation
// ---------------------------------------------------------------------------

// Shared by hyd_eval and hyd_jacobian: node pressures, then every kernel.
// G (flow partials) is NULL for a plain evaluation.
// map (NULL: identity; only without G) is the state order of hyd_eval_mapped.
// Node pressures from y. Restrict locals: the stores into node_p would
// otherwise force a reload of every model array on each node. In a function
// of its own, so that the restrict promise ends before the kernels read
// node_p through d (C11 6.7.3.1).
static void fill_pressures(const hyd_model* m, double* restrict p, const double* restrict y,
                           const int* restrict map) {
    const int* restrict tn = m->tank_node;
    const int* restrict vn = m->vol_node;
    const int* restrict ns = m->node_state;
    const double* restrict pfix = m->node_pfix;
    const int ntank = m->ntank, nvol = m->nvol;
    for (int k = 0; k < ntank; ++k)
        p[tn[k]] = pfix[tn[k]];
    if (map)
        for (int k = 0; k < nvol; ++k)
            p[vn[k]] = y[map[ns[vn[k]]]];
    else
        for (int k = 0; k < nvol; ++k)
            p[vn[k]] = y[ns[vn[k]]];
}

static void run_kernels(const hyd_model* m, hyd_data* d, const double* y, double* ydot,
                        double* G, const int* restrict map) {
    fill_pressures(m, d->node_p, y, map);
    const size_t nb = (size_t)m->nnode * sizeof(double);
    memset(d->node_dV, 0, nb);
    memcpy(d->node_V, m->node_V0, nb);

    hyd_cylinders_eval(m, d, G);
    hyd_pumps_eval(m, d, G);
    hyd_reliefs_eval(m, d, G);
    hyd_checks_eval(m, d, G);
    hyd_orifices_eval(m, d, G);
    hyd_hoses_eval(m, d, G);
    if (map)
        hyd_valves_eval_mapped(m, d, y, ydot, map);
    else
        hyd_valves_eval(m, d, y, ydot, G);
}

void hyd_eval(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot) {
    (void)t;
    run_kernels(m, d, y, ydot, NULL, NULL);
    hyd_volumes_eval(m, d, ydot, NULL, NULL, 0);
}

void hyd_eval_mapped(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot,
                     const int* map) {
    (void)t;
    if (!map) {
        hyd_eval(m, d, t, y, ydot);
        return;
    }
    run_kernels(m, d, y, ydot, NULL, map);
    hyd_volumes_eval_mapped(m, d, ydot, map);
}

void hyd_jacobian(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot,
                  double* J, int ldj, int row0, int col0) {
    (void)t;
    const int n = m->nstate;
    double* G = d->scratch_;
    memset(G, 0, (size_t)(n + 1) * (size_t)(n + 1) * sizeof *G);
    run_kernels(m, d, y, ydot, G, NULL);
    double* Jb = J ? J + (size_t)row0 * ldj + col0 : NULL;
    hyd_volumes_eval(m, d, ydot, G, Jb, ldj);
    if (Jb) {
        for (int v = 0; v < m->nvalve; ++v) {
            double* row = Jb + (size_t)m->valve[v].adr * ldj;
            memset(row, 0, (size_t)n * sizeof *row);
            row[m->valve[v].adr] = -m->valve[v].inv_tau;
        }
    }
    // Coupling partials: x and x' enter only through the chamber volumes.
    const size_t cb = (size_t)m->ncyl * (size_t)n * sizeof(double);
    memset(d->dydx, 0, cb);
    memset(d->dydv, 0, cb);
    memset(d->dFdy, 0, cb);
    for (int i = 0; i < m->ncyl; ++i) {
        const hyd_cyl_c* c = &m->cyl[i];
        const double x = d->cyl_x[i];
        const double VA = d->node_V[c->nA], VB = d->node_V[c->nB];
        const double cA = d->node_be[c->nA] / VA, cB = d->node_be[c->nB] / VB;
        const double netA = d->node_q[c->nA] - d->node_dV[c->nA];
        const double netB = d->node_q[c->nB] - d->node_dV[c->nB];
        // The volume floor (cylinder.c) makes V constant in x once reached.
        const double dVA = (c->VA0 + c->AA * x > HYD_VMIN_FRAC * c->VA0) ? c->AA : 0.0;
        const double dVB = (c->VB0 + c->AB * (c->s - x) > HYD_VMIN_FRAC * c->VB0) ? -c->AB : 0.0;
        d->dydx[i * n + c->sA] = -cA / VA * dVA * netA;
        d->dydx[i * n + c->sB] = -cB / VB * dVB * netB;
        d->dydv[i * n + c->sA] = -cA * c->AA;
        d->dydv[i * n + c->sB] = cB * c->AB;
        d->dFdy[i * n + c->sA] = c->AA;
        d->dFdy[i * n + c->sB] = -c->AB;
    }
}

// ---------------------------------------------------------------------------
// The SPEC section 4 default circuit (the same circuit as
// tests/hydraulics/data/crane_circuit.json).
// ---------------------------------------------------------------------------

// One actuator: valve -> two hoses -> cylinder, port reliefs and
// anti-cavitation checks on both chambers.
static void add_actuator(hyd_builder* b, const char* pre, double bore, double rod,
                         double stroke) {
    char nv[64], nha[64], nhb[64], nc[64], nca[64], ncb[64], tmp[64];
    snprintf(nv, sizeof nv, "%s_valve", pre);
    snprintf(nha, sizeof nha, "%s_hose_A", pre);
    snprintf(nhb, sizeof nhb, "%s_hose_B", pre);
    snprintf(nc, sizeof nc, "%s_cyl", pre);
    snprintf(nca, sizeof nca, "%s_cyl.A", pre);
    snprintf(ncb, sizeof ncb, "%s_cyl.B", pre);

    hyd_valve_def v = hyd_default_valve_def();
    v.name = nv;
    v.P = "pump_line";
    v.T = "tank";
    v.A = nha;
    v.B = nhb;
    hyd_add_valve(b, &v);

    hyd_hose_def h = hyd_default_hose_def();
    h.length = 2.0;
    h.diameter = 0.0127;
    h.name = nha;
    h.to = nca;
    hyd_add_hose(b, &h);
    h.name = nhb;
    h.to = ncb;
    hyd_add_hose(b, &h);

    hyd_cylinder_def c = hyd_default_cylinder_def();
    c.name = nc;
    c.bore = bore;
    c.rod = rod;
    c.stroke = stroke;
    hyd_add_cylinder(b, &c);

    for (int k = 0; k < 2; ++k) {
        const char* port = k ? ncb : nca;
        hyd_relief_def r = hyd_default_relief_def();
        snprintf(tmp, sizeof tmp, "%s_relief_%c", pre, k ? 'B' : 'A');
        r.name = tmp;
        r.inlet = port;
        r.outlet = "tank";
        r.p_crack = 25e6;
        hyd_add_relief(b, &r);
    }
    for (int k = 0; k < 2; ++k) {
        const char* port = k ? ncb : nca;
        hyd_check_def a = hyd_default_check_def();
        snprintf(tmp, sizeof tmp, "%s_check_%c", pre, k ? 'B' : 'A');
        a.name = tmp;
        a.inlet = "tank";
        a.outlet = port;
        hyd_add_check(b, &a);
    }
}

hyd_model* hyd_model_default_crane(char* err, size_t errsz) {
    hyd_builder* b = hyd_builder_create();
    if (!b) {
        if (err && errsz)
            snprintf(err, errsz, "out of memory");
        return NULL;
    }
    hyd_tank_def t = hyd_default_tank_def();
    t.name = "tank";
    hyd_add_tank(b, &t);
    hyd_volume_def pl = hyd_default_volume_def();
    pl.name = "pump_line";
    pl.volume = 1e-3;
    hyd_add_volume(b, &pl);

    hyd_pump_def p = hyd_default_pump_def();
    p.name = "pump";
    p.inlet = "tank";
    p.outlet = "pump_line";
    p.q_max = 35.0 / 60000.0;
    p.p_set = 20e6;
    hyd_add_pump(b, &p);
    hyd_relief_def r = hyd_default_relief_def();
    r.name = "main_relief";
    r.inlet = "pump_line";
    r.outlet = "tank";
    r.p_crack = 22e6;
    hyd_add_relief(b, &r);

    add_actuator(b, "lift", 0.100, 0.060, 0.7);
    add_actuator(b, "jib", 0.080, 0.045, 0.6);
    hyd_model* m = hyd_compile(b, err, errsz);
    hyd_builder_free(b);
    return m;
}

// Spectral radius by repeated squaring: rho(J) = lim ||J^k||^(1/k). B = J /
// ||J||_F keeps the entries in range; after m squarings B^(2^m) carries a
// scale 2^-m in its log. ||A^k||^(1/k) overshoots rho by at most
// cond(V)^(1/k) for a diagonalisable J (V its eigenvectors), so 12 squarings
// (k = 4096) bring even a factor 1e6 of conditioning to within 0.4 %.
static double spectral_radius(double* A, double* T, int n) {
    double f = 0.0;
    for (int i = 0; i < n * n; ++i) f += A[i] * A[i];
    f = sqrt(f);
    if (!isfinite(f)) return -1.0; // NaN or Inf in J: no rate to give
    if (f == 0.0) return 0.0;
    for (int i = 0; i < n * n; ++i) A[i] /= f;
    double logscale = 0.0; // log of the factor divided out of A^(2^m) so far, over 2^m
    double k = 1.0;
    for (int m = 0; m < 12; ++m) {
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                double s = 0.0;
                for (int l = 0; l < n; ++l) s += A[i * n + l] * A[l * n + j];
                T[i * n + j] = s;
            }
        k *= 2.0;
        double g = 0.0;
        for (int i = 0; i < n * n; ++i) g += T[i] * T[i];
        g = sqrt(g);
        if (!(g > 0.0)) return 0.0; // nilpotent: every mode at rest
        for (int i = 0; i < n * n; ++i) A[i] = T[i] / g;
        logscale = 2.0 * logscale + log(g); // log ||J_scaled^k|| so far
    }
    return f * exp(logscale / k);
}

double hyd_model_fastest_rate(const hyd_model* m, double p, double u) {
    const int n = m->nstate;
    if (n == 0) return 0.0;
    hyd_data* d = hyd_data_create(m);
    double* y = calloc((size_t)n, sizeof *y);
    double* J = calloc((size_t)n * (size_t)n, sizeof *J);
    double* T = calloc((size_t)n * (size_t)n, sizeof *T);
    double rate = -1.0;
    if (d && y && J && T) {
        hyd_model_initial_state(m, y);
        for (int i = 0; i < m->nnode; ++i)
            if (m->node_state[i] >= 0) y[m->node_state[i]] = p;
        for (int v = 0; v < m->nvalve; ++v) {
            y[hyd_model_valve_state(m, v)] = u;
            d->valve_cmd[v] = u;
        }
        for (int c = 0; c < m->ncyl; ++c) {
            d->cyl_x[c] = 0.5 * m->cyl[c].s;
            d->cyl_v[c] = 0.0;
        }
        hyd_jacobian(m, d, 0.0, y, NULL, J, n, 0, 0);
        rate = spectral_radius(J, T, n);
    }
    free(T);
    free(J);
    free(y);
    hyd_data_free(d);
    return rate;
}
