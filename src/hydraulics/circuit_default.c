// circuit_default.c: the default two-actuator crane circuit (docs/model.md,
// the same circuit as tests/hydraulics/data/crane_circuit.json, both without
// the seal friction of assets/models/hiab031.json), built through the public
// builder API.
#include "hydraulics.h"

#include <stdio.h>

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

// The supply both circuits share: tank, a 1 L pump line, a pressure-
// compensated pump of q_max [m^3/s] set to 20 MPa, a 22 MPa main relief.
// NULL (and "out of memory" in err) if no builder could be had.
static hyd_builder* supply(double q_max, char* err, size_t errsz) {
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
    p.q_max = q_max;
    p.p_set = 20e6;
    hyd_add_pump(b, &p);
    hyd_relief_def r = hyd_default_relief_def();
    r.name = "main_relief";
    r.inlet = "pump_line";
    r.outlet = "tank";
    r.p_crack = 22e6;
    hyd_add_relief(b, &r);
    return b;
}

hyd_model* hyd_model_default_crane(char* err, size_t errsz) {
    hyd_builder* b = supply(35.0 / 60000.0, err, errsz);
    if (!b) return NULL;
    add_actuator(b, "lift", 0.100, 0.060, 0.7);
    add_actuator(b, "jib", 0.080, 0.045, 0.6);
    hyd_model* m = hyd_compile(b, err, errsz);
    hyd_builder_free(b);
    return m;
}

hyd_model* hyd_model_synthetic(int nact, char* err, size_t errsz) {
    if (nact < 1 || nact > 64) {
        if (err && errsz)
            snprintf(err, errsz, "actuators: must be in [1, 64], got %d", nact);
        return NULL;
    }
    // The crane's pump per actuator (35 L/min each), at most 0.1 m^3/s.
    const double q = nact * 35.0 / 60000.0;
    hyd_builder* b = supply(q < 0.1 ? q : 0.1, err, errsz);
    if (!b) return NULL;
    for (int k = 0; k < nact; ++k) {
        char pre[16];
        snprintf(pre, sizeof pre, "act%d", k + 1);
        // Alternate the crane's two cylinder sizes.
        if (k % 2)
            add_actuator(b, pre, 0.080, 0.045, 0.6);
        else
            add_actuator(b, pre, 0.100, 0.060, 0.7);
    }
    hyd_model* m = hyd_compile(b, err, errsz);
    hyd_builder_free(b);
    return m;
}
