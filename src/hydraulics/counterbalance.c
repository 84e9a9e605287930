// counterbalance.c: counterbalance (over-centre, load-holding) valve.
//
// Two paths between the valve-side node v and the load (cylinder chamber) l:
// - a free-flow check valve v -> l, the relief/check opening law
//   q_c = q_rated ramp(p_v - p_l - p_crack, dp_open) (relief.c, C1);
// - a pilot-assisted relief l -> v, an orifice of area x A (orifice.c law).
//   The spool x in [0, 1] lags its set point with time constant tau,
//     tau x' = x_t - x,  x_t = smoothstep(z / band),
//     z = (p_l - p_v) + R (p_p - p_v) - p_setting
//   i.e. the load pressure on the seat area plus the pilot pressure on R
//   times that area push against the spring p_setting; the spring chamber
//   is referenced to the valve port (the common non-vented valve), hence
//   the p_v terms. With p_v at tank pressure the valve cracks at the pilot
//   pressure (p_setting - p_l) / R (gauge) and holds (x_t = 0, no flow) below.
// The net flow valve -> load is q = q_c - q_r. Hysteresis of a real valve
// (spool friction) is not modelled.
#include "hyd_counterbalance.h"

hyd_counterbalance_def hyd_default_counterbalance_def(void) {
    hyd_counterbalance_def d = {0};
    d.pilot_ratio = 3.0;
    d.band = 1e6;
    d.area = 2e-5;
    d.cd = 0.65;
    d.tau = 0.01;
    d.check_crack = 0.05e6;
    d.check_open = 0.2e6;
    d.check_q = 100.0 / 60000.0;
    return d;
}

static void cbs_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                     double* ydot, double* G, const int* map) {
    const int ld = m->nstate + 1;
    for (int i = 0; i < n; ++i) {
        const hyd_cb_c* c = (const hyd_cb_c*)rec + i;
        const int at = map ? map[c->adr] : c->adr;
        const double x = y[at];
        const double pv = d->node_p[c->v], pl = d->node_p[c->l], pp = d->node_p[c->p];
        hyd_cb_flow e;
        hyd_cb_law(c, x, pv, pl, pp, &e);
        if (ydot)
            ydot[at] = e.xdot;
        const double q = e.q; // valve -> load
        d->comp_q[2 * c->comp] = q;
        d->comp_open[c->comp] = e.open;
        double* fl = d->flow_ + HYD_MAXSLOT * c->comp;
        fl[0] = -q, fl[1] = q, fl[2] = 0.0;
        if (G) {
            const int sv = m->node_sidx[c->v], sl = m->node_sidx[c->l], sp = m->node_sidx[c->p];
            const double dqv = e.dqv, dql = -e.dqv; // dq / dp_v, dq / dp_l
            const double dqx = e.dqx;
            G[sv * ld + sv] -= dqv, G[sv * ld + sl] -= dql, G[sv * ld + c->adr] -= dqx;
            G[sl * ld + sv] += dqv, G[sl * ld + sl] += dql, G[sl * ld + c->adr] += dqx;
            // Spool row (hyd_state_row_from_G).
            const double k = e.k; // d x' / d z
            double* row = G + (size_t)c->adr * ld;
            row[sl] += k;
            row[sv] += e.kv;
            row[sp] += k * c->R;
            row[c->adr] -= c->inv_tau;
        }
    }
}

static void cbs_jacobian(const hyd_model* m, hyd_data* d, const void* rec, int n, double* Jb, int ldj) {
    if (!Jb)
        return;
    for (int i = 0; i < n; ++i)
        hyd_state_row_from_G(m, d, ((const hyd_cb_c*)rec)[i].adr, Jb, ldj);
}

static void cb_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)node0;
    const hyd_counterbalance_def* d = def;
    hyd_cb_c* c = rec;
    c->pset = d->p_setting;
    c->R = d->pilot_ratio;
    c->inv_band = 1.0 / d->band;
    c->A = d->area;
    c->ok = hyd_orifice_constants(&m->fluid, d->cd);
    c->inv_tau = 1.0 / d->tau;
    c->ccr = d->check_crack;
    c->inv_cw = 1.0 / d->check_open;
    c->cq = d->check_q;
    c->pvent = d->vented != 0.0 ? m->fluid.p_atm : -1.0;
}

static void cb_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own;
    hyd_cb_c* c = rec;
    c->comp = comp, c->v = port[0], c->l = port[1], c->p = port[2];
    c->adr = state[0];
}

static void cb_initial(const void* def, const void* rec, double* y0) {
    (void)def;
    y0[((const hyd_cb_c*)rec)->adr] = 0.0; // closed: it holds the load from the start
}

static const hyd_param_info cb_params[] = {
    HYD_PARAM(hyd_counterbalance_def, p_setting, "Pa", HYD_R_POS, 1, 1e6, 1e8, 5e6, 4e7),
    HYD_PARAM(hyd_counterbalance_def, pilot_ratio, "-", HYD_R_POS, 0, 0.1, 50, 3, 4),
    HYD_PARAM(hyd_counterbalance_def, band, "Pa", HYD_R_POS, 0, 1e3, 1e7, 1e5, 3e6),
    HYD_PARAM(hyd_counterbalance_def, area, "m^2", HYD_R_POS, 0, 1e-10, 0.1, 1e-6, 1e-3),
    HYD_PARAM(hyd_counterbalance_def, cd, "-", HYD_R_FRAC, 0, 0.1, 1, 0.5, 0.8),
    HYD_PARAM(hyd_counterbalance_def, tau, "s", HYD_R_POS, 0, 1e-4, 1, 2e-3, 0.05),
    HYD_PARAM(hyd_counterbalance_def, check_crack, "Pa", HYD_R_NONNEG, 0, 0, 1e7, 0, 1e6),
    HYD_PARAM(hyd_counterbalance_def, check_open, "Pa", HYD_R_POS, 0, 1e2, 1e7, 5e3, 1e6),
    HYD_PARAM(hyd_counterbalance_def, check_q, "m^3/s", HYD_R_POS, 0, 1e-7, 0.1, 1e-5, 5e-3),
    HYD_PARAM(hyd_counterbalance_def, vented, "-", HYD_R_FRAC, 0, 0, 1, 0, 1),
};

// vented selects where the spring chamber is referenced: only 0 and 1 mean something.
static int cb_validate(const void* def, char* field, size_t fsz, char* msg, size_t msz) {
    const hyd_counterbalance_def* d = def;
    if (d->vented != 0.0 && d->vented != 1.0) {
        snprintf(field, fsz, "vented");
        snprintf(msg, msz, "must be 0 (spring chamber at the valve port) or 1 (vented to atmosphere), got %g",
                 d->vented);
        return -1;
    }
    return 0;
}
static const hyd_port_info cb_ports[] = {HYD_PORT(hyd_counterbalance_def, valve),
                                         HYD_PORT(hyd_counterbalance_def, load),
                                         HYD_PORT(hyd_counterbalance_def, pilot)};
static const char* const cb_states[] = {"spool"};
// It closes on a lag towards 0: flushed to 0 below HYD_STATE_FLUSH (the spool opening, of full [-]).
static const double cb_flush[] = {HYD_STATE_FLUSH};

static void cb_defaults(void* def) { *(hyd_counterbalance_def*)def = hyd_default_counterbalance_def(); }

HYD_DEF_FITS(hyd_counterbalance_def);
const hyd_component hyd_counterbalance_component = {
    .type = HYD_COUNTERBALANCE, .name = "counterbalance", .def_size = sizeof(hyd_counterbalance_def),
    .params = cb_params, .nparam = HYD_COUNT(cb_params),
    .ports = cb_ports, .nport = HYD_COUNT(cb_ports),
    .states = cb_states, .nstate = HYD_COUNT(cb_states), .state_flush = cb_flush,
    .rec_size = sizeof(hyd_cb_c), .states_sense_ports = 1,
    .defaults = cb_defaults, .validate = cb_validate, .bind = cb_bind, .derive = cb_derive, .initial = cb_initial,
    .eval = cbs_eval, .jacobian = cbs_jacobian,
};
