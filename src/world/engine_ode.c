// engine_ode.c: the ODE world (ode_world.h: truck, slewing column, booms,
// rope, hook, loads, terrain; the circuit sub-stepped inside each ODE step)
// behind engine.h.
#include "engine_impl.h"

#include "ode_world.h"

#include <stdio.h>
#include <stdlib.h>

typedef struct eng_ode {
    engine base;
    ode_world* w;
} eng_ode;

static const engine_ops ode_ops;

static ode_world* W(const engine* e) { return ((const eng_ode*)e)->w; }

engine* engine_ode_create(const model* m, const sim_opts* o, const double q0[2], double slew0, double m3,
                          char* err, size_t errsz) {
    eng_ode* l = calloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    l->base.ops = &ode_ops;
    l->base.o = *o;
    l->w = sim_ode_world_create(m, o, "sandbox", q0, slew0, m3, err, errsz);
    if (!l->w) {
        free(l);
        return NULL;
    }
    // The hydraulic sub-step is min(--dt, ODE step), as sim_ode_world_create sets it.
    const double dt = ode_world_dt(l->w), h = o->h < dt ? o->h : dt;
    double row0[SIM_NCOL];
    sim_ode_row(l->w, row0);
    if (sim_check_fixed_step(ode_world_circuit(l->w), o, h, 0.0, err, errsz) ||
        sim_check_start(ode_world_circuit(l->w), row0, SIM_NCOL, m3, err, errsz)) {
        ode_world_destroy(l->w);
        free(l);
        return NULL;
    }
    return &l->base;
}

static void ode_destroy(engine* e) {
    ode_world_destroy(W(e));
    free(e);
}

static void ode_set_commands(engine* e, const double u[3]) { ode_world_set_commands(W(e), u); }
static int ode_hook(engine* e, int attach) { return ode_world_hook(W(e), attach); }

static const char* ode_load_name(const engine* e, int i, double* mass) {
    return ode_world_load_name(W(e), i, mass);
}

static bool ode_attached(const engine* e) {
    ode_world_state st;
    ode_world_get_state(W(e), &st);
    return st.attached >= 0;
}

static hyd_model* ode_circuit(engine* e) { return ode_world_circuit(W(e)); }

static int ode_set_link(engine* e, int k, const crane_link* ln) {
    return ode_world_set_link_mass(W(e), k, ln) ? 1 : 0;
}

static int ode_step(engine* e, double dt) {
    if (ode_world_step(W(e), dt) == 0) return 0;
    snprintf(e->err, sizeof e->err, "%s", ode_world_error(W(e)));
    return 1;
}

static double ode_time(const engine* e) { return ode_world_time(W(e)); }
static void ode_row(engine* e, double row[SIM_NCOL]) { sim_ode_row(W(e), row); }
static void ode_snapshot(engine* e, world_snapshot* s) { ode_world_snapshot(W(e), s); }

static const engine_ops ode_ops = {
    .name = "ode",
    .ncol = SIM_NCOL,
    .destroy = ode_destroy,
    .set_commands = ode_set_commands,
    .hook = ode_hook,
    .load_name = ode_load_name,
    .attached = ode_attached,
    .circuit = ode_circuit,
    .set_load = NULL, // the world's loads are bodies, picked up with the hook
    .set_link = ode_set_link,
    .step = ode_step,
    .time = ode_time,
    .row = ode_row,
    .snapshot = ode_snapshot,
};
