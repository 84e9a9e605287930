// circuit_api.c: build a small circuit through the C API and run it.
//
// A pressure-compensated pump feeds a 4/3 valve that drives a cylinder
// against a constant 20 kN load (a mass on the rod). The valve opens on a
// ramp; the program prints the piston speed and chamber pressures, and checks
// the steady speed against the pump's flow limit over the piston area.
#include <math.h>
#include <stdio.h>

#include "hyd_solver.h"
#include "hydraulics.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct rig {
    const hyd_model* m;
    hyd_data* d;
    int n;          // hydraulic states; y[n] = x, y[n+1] = v
    double mass;    // moving mass [kg]
    double load;    // constant load force against extension [N]
} rig;

static int rhs(void* user, double t, const double* y, double* f) {
    rig* r = user;
    r->d->cyl_x[0] = y[r->n];
    r->d->cyl_v[0] = y[r->n + 1];
    r->d->valve_cmd[0] = t < 0.2 ? 0.0 : (t < 0.5 ? (t - 0.2) / 0.3 : 1.0); // ramp open
    hyd_eval(r->m, r->d, t, y, f);
    f[r->n] = y[r->n + 1];
    f[r->n + 1] = (r->d->cyl_F[0] - r->load) / r->mass;
    return 0;
}

int main(void) {
    hyd_builder* b = hyd_builder_create();
    hyd_tank_def tank = hyd_default_tank_def();
    tank.name = "tank";
    hyd_add_tank(b, &tank);
    hyd_volume_def line = hyd_default_volume_def();
    line.name = "pump_line";
    line.volume = 1e-3; // 1 L
    line.p0 = 5e6;
    hyd_add_volume(b, &line);
    hyd_pump_def pump = hyd_default_pump_def();
    pump.name = "pump";
    pump.inlet = "tank";
    pump.outlet = "pump_line";
    pump.q_max = 20.0 / 60000.0; // 20 L/min
    pump.p_set = 15e6;
    hyd_add_pump(b, &pump);
    hyd_relief_def relief = hyd_default_relief_def();
    relief.name = "relief";
    relief.inlet = "pump_line";
    relief.outlet = "tank";
    relief.p_crack = 17e6;
    hyd_add_relief(b, &relief);
    hyd_valve_def valve = hyd_default_valve_def();
    valve.name = "valve";
    valve.P = "pump_line";
    valve.T = "tank";
    valve.A = "cyl.A";
    valve.B = "cyl.B";
    hyd_add_valve(b, &valve);
    hyd_cylinder_def cyl = hyd_default_cylinder_def();
    cyl.name = "cyl";
    cyl.bore = 0.063;
    cyl.rod = 0.036;
    cyl.stroke = 0.5;
    cyl.p0_a = 0.1e6 + 20e3 / (M_PI * 0.063 * 0.063 / 4); // holding the load at rest
    hyd_add_cylinder(b, &cyl);

    char err[256];
    hyd_model* m = hyd_compile(b, err, sizeof err);
    hyd_builder_free(b);
    if (!m) {
        fprintf(stderr, "circuit: %s\n", err);
        return 2;
    }
    rig r = {m, hyd_data_create(m), hyd_model_nstate(m), 200.0, 20e3};
    double y[32];
    hyd_model_initial_state(m, y);
    y[r.n] = 0.05;
    y[r.n + 1] = 0.0;
    hyd_problem p = {.n = r.n + 2, .f = rhs, .user = &r}; // J by finite differences
    hyd_solver_opts o = hyd_default_solver_opts();
    o.h = 1e-4;
    hyd_solver* s = hyd_solver_create(&p, HYD_KRUS, &o);
    int iA, iB;
    hyd_model_cylinder_states(m, 0, &iA, &iB);
    printf("%d hydraulic states; Krus, h = 0.1 ms\n", r.n);
    printf("   t [s]   x [mm]  v [mm/s]  pA [MPa]  pB [MPa]\n");
    double t = 0;
    for (int k = 1; k <= 15; ++k) {
        if (hyd_solver_advance(s, &t, y, 0.1 * k) != HYD_OK) {
            fprintf(stderr, "solver failed at t = %g s\n", t);
            return 1;
        }
        printf("%8.2f %8.1f %9.1f %9.2f %9.2f\n", t, 1e3 * y[r.n], 1e3 * y[r.n + 1], 1e-6 * y[iA], 1e-6 * y[iB]);
    }
    double AA, AB, st;
    hyd_model_cylinder_geometry(m, 0, &AA, &AB, &st);
    double v_expect = pump.q_max / AA;
    printf("steady speed %.1f mm/s; pump flow / piston area = %.1f mm/s\n", 1e3 * y[r.n + 1], 1e3 * v_expect);
    int ok = fabs(y[r.n + 1] - v_expect) < 0.02 * v_expect;
    hyd_solver_destroy(s);
    hyd_data_free(r.d);
    hyd_model_free(m);
    return ok ? 0 : 1;
}
