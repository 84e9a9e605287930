// ode_run.c: the ODE world of a run or a live session from the model and
// the run's options, and its rows (ode_run.h). Moved out of sim.c, so the
// backend-neutral run layer knows no backend.
#include "ode_run.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "engine_faults.h"

void ode_world_row(ode_world* w, double* row) {
    ode_world_state st;
    ode_world_get_state(w, &st);
    const double v[SIM_NCOL] = {
        st.t, st.x[0], st.x[1], st.pA[0], st.pB[0], st.pA[1], st.pB[1], st.u[0], st.u[1], st.q[0], st.q[1],
        st.tip[0], st.tip[1], st.F[0], st.F[1], st.u_cmd[0], st.u_cmd[1],
        st.v[0], st.v[1], st.p_pump, st.relief_open, st.end_stop,
        st.slew, st.hook[0], st.hook[1], st.hook[2], 0, 0, 0, st.attached, st.truck_tilt, st.ncontact,
        st.max_depth, st.x[2], st.v[2], st.pA[2], st.pB[2], st.u[2], st.u_cmd[2], st.F[2],
        st.tip_world[0], st.tip_world[1], st.tip_world[2]};
    memcpy(row, v, sizeof v);
    for (int i = 0; i < 4; ++i) row[COL_PAD_F1 + i] = st.pad_F[i];
    row[COL_STAB_MARGIN] = st.stab_margin;
    // The attached load, else the first one: where the payload is.
    int li = st.attached >= 0 ? st.attached : (ode_world_nload(w) > 0 ? 0 : -1);
    if (li >= 0) {
        double pos[3], vel[3];
        ode_world_load_state(w, li, pos, vel);
        row[COL_LOAD_X] = pos[0];
        row[COL_LOAD_Y] = pos[1];
        row[COL_LOAD_Z] = pos[2];
    }
}

// The slew parameters of a world's slew section and a model's drive agree.
static bool same_slew(const world_slew* w, const crane_slew* m) {
    return w->pinion_radius == m->pinion_radius && w->column_radius == m->column_radius && w->damping == m->damping &&
           !strcmp(w->cylinder, m->cylinder) && !strcmp(w->valve, m->valve);
}

int ode_world_take_model_slew(const model* m, world_desc* wd, char* err, size_t errsz) {
    const crane_slew* sl = &m->chain.slew;
    if (!sl->present || wd->kind != WORLD_SANDBOX) return 0;
    const cJSON* frag = cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics_slew");
    const cJSON* hyd = cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics");
    // The model's drive wins: it is the crane's hardware, the world's is the
    // fallback for models without one. Said once where it changes something.
    const cJSON* own = world_desc_circuit_for(wd, hyd);
    const char* wf = wd->file[0] ? wd->file : "world";
    const char* part = own == wd->circuit_ls ? "circuit_ls" : "circuit";
    if (own) {
        // The world's own fragment is still checked against this model, as
        // it was when it was used: a world file that was refused before is
        // refused now, whichever slew runs.
        hyd_model* hm = model_circuit_with_fragment(hyd, m->file, own, wf, part, err, errsz);
        if (!hm) return -1;
        hyd_model_free(hm);
    }
    if (own && (!same_slew(&wd->slew, sl) || !cJSON_Compare(own, frag, 1))) {
        char line[768];
        snprintf(line, sizeof line,
                 "%s: slew, %s: the model's slew drive (%s: mechanics.slew, hydraulics_slew) is used instead", wf,
                 part, m->file);
        hyd_note(line);
    }
    cJSON* dup = cJSON_Duplicate(frag, 1);
    if (!dup) {
        snprintf(err, errsz, "%s: hydraulics_slew: out of memory", m->file);
        return -1;
    }
    cJSON_Delete(wd->circuit);
    cJSON_Delete(wd->circuit_ls);
    // One fragment made for this model's circuit (its patch included): the
    // sandbox appends it whatever the pump (world_desc_circuit_for falls back
    // to circuit when there is no circuit_ls).
    wd->circuit = dup;
    wd->circuit_ls = NULL;
    wd->slew.pinion_radius = sl->pinion_radius;
    wd->slew.column_radius = sl->column_radius;
    wd->slew.damping = sl->damping;
    snprintf(wd->slew.cylinder, sizeof wd->slew.cylinder, "%s", sl->cylinder);
    snprintf(wd->slew.valve, sizeof wd->slew.valve, "%s", sl->valve);
    snprintf(wd->slew_file, sizeof wd->slew_file, "%s", m->file);
    return 0;
}

ode_world* ode_world_for_run(const model* m, const sim_opts* o, const char* default_world, const double q0[2],
                              double slew0, double m3, char* err, size_t errsz) {
    char wbuf[512];
    const char* wpath = sim_world_path(o->world ? o->world : default_world, wbuf, sizeof wbuf);
    world_desc wd;
    if (world_desc_load(wpath, &wd, err, errsz)) return NULL;
    // The validation world is built from the two-link crane_mech (a chain
    // model's is the chain world, ode_chain.h); the sandbox from either (a
    // chain that is not two_link: its crane from the chain, opts.chain).
    if (wd.kind != WORLD_SANDBOX && model_require_two_link(m, "ODE world (--mechanics ode)", err, errsz)) {
        world_desc_free(&wd);
        return NULL;
    }
    if (ode_world_take_model_slew(m, &wd, err, errsz)) {
        world_desc_free(&wd);
        return NULL;
    }
    ode_world_opts wo = ode_world_default_opts();
    wo.dt_ode = o->dt_ode > 0 ? o->dt_ode : 1e-3;
    // The bodies feel the cylinder forces one ODE step late (explicit
    // coupling, docs/ode_world.md). Against the lagrange backend on `step`:
    // 0.8 % of peak pressure at 1 ms, 15 % at 10 ms, 36 % at 20 ms; `hold`
    // goes unstable between 30 and 50 ms and reported 27 MPa in every
    // chamber as a success. Beyond 10 ms the result is not worth having.
    if (wo.dt_ode > 0.01 + 1e-12) {
        snprintf(err, errsz,
                 "%s %g s is too long: the cylinder forces lag the bodies by one ODE step, which beyond "
                 "0.01 s distorts the pressures by more than 15 %% and then goes unstable (docs/ode_world.md)",
                 sim_param_name(SIM_PARAM_DT_ODE), wo.dt_ode);
        world_desc_free(&wd);
        return NULL;
    }
    // Adaptive hydraulics choose their own steps inside each ODE step and
    // never use dt_hyd: --dt does not apply, so it cannot be wrong.
    wo.dt_hyd = hyd_method_is_adaptive(o->solver) || o->h >= wo.dt_ode ? wo.dt_ode : o->h;
    const double ratio = wo.dt_ode / wo.dt_hyd;
    if (fabs(ratio - floor(ratio + 0.5)) > 1e-6) {
        // ode_world_create checks this too; here it is said in the options' words.
        snprintf(err, errsz, "%s %g s must divide the ODE step %g s (hydraulic sub-steps)",
                 sim_param_name(SIM_PARAM_DT), wo.dt_hyd, wo.dt_ode);
        world_desc_free(&wd);
        return NULL;
    }
    wo.solver = o->solver;
    wo.jac_every = o->jac_every > 0 ? o->jac_every : 1;
    wo.no_retry = o->no_retry;
    wo.rtol = o->rtol;
    wo.atol = o->atol;
    wo.dense_jac = o->dense_jac;
    wo.general_circuit = o->kernel == SIM_KERNEL_GENERAL;
    wo.q0[0] = q0[0];
    wo.q0[1] = q0[1];
    wo.slew0 = slew0;
    wo.load_mass = m3;
    wo.p_low = 0.5e6; // as the lagrange backend, so both start from the same state
    wo.model_file = m->file;
    wo.circuit = m->hyd; // the run's one circuit unless the world adds to it
    wo.chain = m->chain.two_link ? NULL : &m->chain;
    const cJSON* hyd = cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics");
    if (m->world_bursts) {
        // Bursts at nodes of the world's circuit (the sandbox's slew) open
        // there: their orifices join the world's part of the circuit, which
        // only the sandbox appends (ow_hyd_create).
        cJSON* frag = wd.kind == WORLD_SANDBOX ? (cJSON*)world_desc_circuit_for(&wd, hyd) : NULL;
        // The world's part of the circuit, or the model's hydraulics_slew
        // where the model's slew drive replaced it.
        const char* wf = wd.slew_file[0] ? "its hydraulics_slew" : strrchr(wpath, '/') ? strrchr(wpath, '/') + 1 : wpath;
        cJSON* comps = frag ? cJSON_GetObjectItemCaseSensitive(frag, "components") : NULL;
        if (engine_world_bursts(m, cJSON_IsArray(comps) ? frag : NULL, wf, err, errsz)) {
            world_desc_free(&wd);
            return NULL;
        }
        const cJSON* o;
        cJSON_ArrayForEach(o, m->world_bursts) cJSON_AddItemToArray(comps, cJSON_Duplicate(o, 1));
    }
    ode_world* w = ode_world_create(&m->mech, hyd, &wd, &wo, err, errsz);
    world_desc_free(&wd);
    return w;
}
