// compensator.c: section pressure compensator (pre- or post-compensated).
//
// Placed between the pump line (inlet) and the P port of the section's 4/3
// valve (outlet, a declared volume), it is an orifice of area x A whose
// opening x holds the valve's meter-in drop dp_m = p_outlet - p_load at a
// target dp_t:
//   mode 0, pre-compensated:  dp_t = setting
//   mode 1, post-compensated: dp_t = p_inlet - p_ref - setting
//   x = 1 - smoothstep((dp_m - dp_t) / band + 1/2)
// so at steady flow dp_m = dp_t +- band/2. Mode 1 is the flow-sharing
// (downstream, "LUDV") compensator moved upstream of the metering edge: a
// post compensator holds the pressure after the edge at p_ref + setting, so
// every section's edge sees p_pump - p_ref - setting; holding that same drop
// from upstream gives the same flows (the edge and the compensator are in
// series). When the pump cannot deliver, p_pump - p_ref falls for all
// sections together and the flows keep the ratio of their openings; with
// mode 0 the section with the highest load loses its drop first.
// load is the section's load pressure (its work port, or a section shuttle
// of A and B); ref the highest LS pressure (the LS line); both are sensed
// only. The setting range covers both uses (pre 0.5-1.5 MPa, post a few
// 0.1 MPa).
#include "hyd_compensator.h"

hyd_compensator_def hyd_default_compensator_def(void) {
    hyd_compensator_def d = {0};
    d.cd = 0.65;
    d.setting = 1e6;
    d.band = 5e4;
    d.mode = 1.0;
    d.tau = 0.005;
    return d;
}

static void compensators_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                              double* ydot, double* G, const int* map) {
    const int ld = m->nstate + 1;
    for (int i = 0; i < n; ++i) {
        const hyd_comp_c* c = (const hyd_comp_c*)rec + i;
        const int at = map ? map[c->adr] : c->adr;
        hyd_comp_flow e;
        hyd_compensator_law(c, y[at], d->node_p[c->in], d->node_p[c->out], d->node_p[c->load],
                            d->node_p[c->ref], &e);
        if (ydot)
            ydot[at] = e.xdot;
        const double q = e.q;
        d->comp_q[2 * c->comp] = q;
        d->comp_open[c->comp] = y[at] < 1.0;
        double* fl = d->flow_ + HYD_MAXSLOT * c->comp;
        fl[0] = -q, fl[1] = q, fl[2] = 0.0, fl[3] = 0.0;
        if (G) {
            const int node[4] = {c->in, c->out, c->load, c->ref};
            const int si = m->node_sidx[c->in], so = m->node_sidx[c->out];
            hyd_jac_flow(m, G, c->in, c->out, e.dq[0], e.dq[1]);
            G[si * ld + c->adr] -= e.dqx;
            G[so * ld + c->adr] += e.dqx;
            // Spool row (hyd_state_row_from_G).
            double* row = G + (size_t)c->adr * ld;
            for (int j = 0; j < 4; ++j) row[m->node_sidx[node[j]]] += e.dxd[j];
            row[c->adr] -= c->inv_tau;
        }
    }
}

static void compensators_jacobian(const hyd_model* m, hyd_data* d, const void* rec, int n, double* Jb, int ldj) {
    if (!Jb)
        return;
    for (int i = 0; i < n; ++i)
        hyd_state_row_from_G(m, d, ((const hyd_comp_c*)rec)[i].adr, Jb, ldj);
}

// mode selects a law: only 0 and 1 mean something.
static int compensator_validate(const void* def, char* field, size_t fsz, char* msg, size_t msz) {
    const hyd_compensator_def* d = def;
    if (d->mode != 0.0 && d->mode != 1.0) {
        snprintf(field, fsz, "mode");
        snprintf(msg, msz, "must be 0 (pre-compensated) or 1 (post-compensated, flow sharing), got %g",
                 d->mode);
        return -1;
    }
    return 0;
}

static void compensator_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)node0;
    const hyd_compensator_def* d = def;
    hyd_comp_c* c = rec;
    c->A = d->area;
    c->ok = hyd_orifice_constants(&m->fluid, d->cd);
    c->set = d->setting;
    c->inv_band = 1.0 / d->band;
    c->post = d->mode != 0.0;
    c->inv_tau = 1.0 / d->tau;
}

static void compensator_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own;
    hyd_comp_c* c = rec;
    c->comp = comp, c->in = port[0], c->out = port[1], c->load = port[2], c->ref = port[3];
    c->adr = state[0];
}

static void compensator_initial(const void* def, const void* rec, double* y0) {
    (void)def;
    y0[((const hyd_comp_c*)rec)->adr] = 1.0; // open: its spring holds it open at rest
}

static const hyd_param_info compensator_params[] = {
    HYD_PARAM(hyd_compensator_def, area, "m^2", HYD_R_POS, 1, 1e-10, 0.1, 1e-6, 1e-3),
    HYD_PARAM(hyd_compensator_def, cd, "-", HYD_R_FRAC, 0, 0.1, 1, 0.5, 0.8),
    HYD_PARAM(hyd_compensator_def, setting, "Pa", HYD_R_NONNEG, 0, 0, 5e6, 1e5, 1.5e6),
    HYD_PARAM(hyd_compensator_def, band, "Pa", HYD_R_POS, 0, 1e3, 2e6, 1e4, 3e5),
    HYD_PARAM(hyd_compensator_def, mode, "-", HYD_R_FRAC, 0, 0, 1, 0, 1),
    // The spool's lag (its damping orifice): below 0.1 ms it is the static
    // law's stiffness again; a compensator slower than 50 ms lags the valve.
    HYD_PARAM(hyd_compensator_def, tau, "s", HYD_R_POS, 0, 1e-4, 1, 1e-3, 0.05),
};
static const char* const compensator_states[] = {"spool"};
// It closes on a lag towards 0: flushed to 0 below HYD_STATE_FLUSH (the spool opening, of full [-]).
static const double compensator_flush[] = {HYD_STATE_FLUSH};
static const hyd_port_info compensator_ports[] = {
    HYD_PORT(hyd_compensator_def, inlet), HYD_PORT(hyd_compensator_def, outlet),
    HYD_PORT(hyd_compensator_def, load), HYD_PORT(hyd_compensator_def, ref)};

static void compensator_defaults(void* def) { *(hyd_compensator_def*)def = hyd_default_compensator_def(); }

HYD_DEF_FITS(hyd_compensator_def);
const hyd_component hyd_compensator_component = {
    .type = HYD_COMPENSATOR, .name = "compensator", .def_size = sizeof(hyd_compensator_def),
    .params = compensator_params, .nparam = HYD_COUNT(compensator_params),
    .ports = compensator_ports, .nport = HYD_COUNT(compensator_ports),
    .states = compensator_states, .nstate = HYD_COUNT(compensator_states), .state_flush = compensator_flush,
    .rec_size = sizeof(hyd_comp_c), .states_sense_ports = 1,
    .defaults = compensator_defaults, .validate = compensator_validate, .bind = compensator_bind,
    .derive = compensator_derive, .initial = compensator_initial, .eval = compensators_eval,
    .jacobian = compensators_jacobian,
};
