// circuits.h: shorthands for building small test circuits through the C
// API. Each adds one component with the library's defaults except the
// fields named; the tests set anything else on a def of their own.
#ifndef TEST_CIRCUITS_H
#define TEST_CIRCUITS_H

#include "hydraulics.h"

/// A tank at pressure p [Pa abs]; p <= 0 keeps the default (atmospheric).
static inline void add_tank(hyd_builder* b, const char* name, double p) {
    hyd_tank_def t = hyd_default_tank_def();
    t.name = name;
    if (p > 0) t.pressure = p;
    hyd_add_tank(b, &t);
}

/// A volume node of V [m^3].
static inline void add_volume(hyd_builder* b, const char* name, double V) {
    hyd_volume_def v = hyd_default_volume_def();
    v.name = name;
    v.volume = V;
    hyd_add_volume(b, &v);
}

/// A pressure-compensated pump, q_max [m^3/s] up to p_set [Pa].
static inline void add_pump(hyd_builder* b, const char* name, const char* in, const char* out, double q_max,
                            double p_set) {
    hyd_pump_def p = hyd_default_pump_def();
    p.name = name;
    p.inlet = in;
    p.outlet = out;
    p.q_max = q_max;
    p.p_set = p_set;
    hyd_add_pump(b, &p);
}

/// A 4/3 valve P, T, A, B with initial spool opening u0 [-].
static inline void add_valve(hyd_builder* b, const char* name, const char* P, const char* T, const char* A,
                             const char* B, double u0) {
    hyd_valve_def v = hyd_default_valve_def();
    v.name = name;
    v.P = P;
    v.T = T;
    v.A = A;
    v.B = B;
    v.u0 = u0;
    hyd_add_valve(b, &v);
}

/// A fixed orifice from in to out of area A [m^2] (default discharge
/// coefficient, hyd_default_orifice_def().cd).
static inline void add_orifice(hyd_builder* b, const char* name, const char* in, const char* out, double A) {
    hyd_orifice_def o = hyd_default_orifice_def();
    o.name = name;
    o.inlet = in;
    o.outlet = out;
    o.area = A;
    hyd_add_orifice(b, &o);
}

/// A relief from in to out cracking at p_crack [Pa]; q_rated [m^3/s] <= 0
/// keeps the default.
static inline void add_relief(hyd_builder* b, const char* name, const char* in, const char* out, double p_crack,
                              double q_rated) {
    hyd_relief_def r = hyd_default_relief_def();
    r.name = name;
    r.inlet = in;
    r.outlet = out;
    r.p_crack = p_crack;
    if (q_rated > 0) r.q_rated = q_rated;
    hyd_add_relief(b, &r);
}

#endif
