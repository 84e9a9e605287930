// ls_pump.c: load-sensing variable displacement pump.
//
// State eps in [0, 1], the displacement fraction; delivery q = eps q_max
// (q_max: full displacement at the shaft speed), inlet -> outlet. The
// displacement controller is a first-order lag towards the setting the
// LS spool and the cut-off spool ask for:
//   tau eps' = eps_t - eps,   eps_t = e_ls e_co
//   e_ls = 1 - smoothstep((p_out - p_ls - margin) / band + 1/2)
//   e_co = 1 - smoothstep((p_out - p_in - p_cutoff) / cutoff_band)
// e_ls is 1 while the margin is not reached and 0 once it is exceeded by
// band/2, so at any steady flow between 0 and q_max the controller holds
// p_out - p_ls within margin +- band/2. e_co takes the flow away above the
// cut-off, whatever the LS signal asks (a product: either spool alone can
// destroke the pump; where both are inside their bands it is C1 as well).
// tau is the stroke time constant; eps_t in [0, 1] keeps eps in [0, 1]
// without a limiter.
//
// Internal leakage (the pump's volumetric loss, laminar: gaps of the
// pistons and the valve plate) takes q_leak = c_leak (p_out - p_in) back to
// the inlet, so q = eps q_max - q_leak. It is what brings a dead-headed
// pump line down to standby: once every section is closed, the controller
// has destroked the pump (eps -> 0) and without a leak the line keeps the
// pressure the last stroke left (up to the relief setting); with it the line
// falls, with the time constant V_line / (Be c_leak), until the controller
// strokes again to hold p_out = p_ls + margin. A real pump leaks some 1-5 %
// of its rated flow at its rated pressure: c_leak = 0.02 q_max / p_cutoff is
// about 5.6e-13 m^3/(s Pa) for 35 L/min and 21 MPa (default 0, the ideal
// pump). The energy accounts count the net delivery: the leak is a loss
// inside the pump, before its outlet. The LS port draws no flow: the LS line's own bleed
// orifice (a fixed orifice to tank) empties it.
#include "hyd_ls_pump.h"

hyd_ls_pump_def hyd_default_ls_pump_def(void) {
    hyd_ls_pump_def d = {0};
    d.margin = 2e6;
    d.band = 5e4;
    d.p_cutoff = 22e6;
    d.cutoff_band = 0.5e6;
    d.tau = 0.08;
    d.eps0 = 0.0;
    return d;
}

static void ls_pump_derive(hyd_model* m, const void* def, void* rec, int node0) {
    (void)m, (void)node0;
    const hyd_ls_pump_def* d = def;
    hyd_ls_pump_c* c = rec;
    c->qmax = d->q_max;
    c->margin = d->margin;
    c->inv_band = 1.0 / d->band;
    c->pcut = d->p_cutoff;
    c->inv_cband = 1.0 / d->cutoff_band;
    c->inv_tau = 1.0 / d->tau;
    c->cleak = d->leakage;
}

static void ls_pumps_eval(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                          double* ydot, double* G, const int* map) {
    const int ld = m->nstate + 1;
    for (int i = 0; i < n; ++i) {
        const hyd_ls_pump_c* c = (const hyd_ls_pump_c*)rec + i;
        const int at = map ? map[c->adr] : c->adr;
        const double eps = y[at];
        const double pin = d->node_p[c->in], pout = d->node_p[c->out], pls = d->node_p[c->ls];
        double a1, a2; // d e_ls e_co / d(p_out - p_ls), d(p_out - p_in)
        const double target = hyd_ls_pump_target(c, pin, pout, pls, &a1, &a2);
        if (ydot)
            ydot[at] = HYD_LS_PUMP_RATE(target, eps, c->inv_tau);
        const double q = HYD_LS_PUMP_Q(eps, c->qmax, c->cleak, pout, pin);
        d->comp_q[2 * c->comp] = q;
        d->comp_open[c->comp] = target < 1.0;
        double* fl = d->flow_ + HYD_MAXSLOT * c->comp;
        fl[0] = -q, fl[1] = q, fl[2] = 0.0;
        if (G) {
            const int si = m->node_sidx[c->in], so = m->node_sidx[c->out], sl = m->node_sidx[c->ls];
            // Flow column: dq/deps = q_max; the leak's dq/dp_out = -c_leak,
            // dq/dp_in = c_leak.
            G[si * ld + c->adr] -= c->qmax;
            G[so * ld + c->adr] += c->qmax;
            G[si * ld + si] -= c->cleak;
            G[si * ld + so] += c->cleak;
            G[so * ld + si] += c->cleak;
            G[so * ld + so] -= c->cleak;
            // Displacement row (hyd_state_row_from_G): d eps' / d p and d eps.
            double* row = G + (size_t)c->adr * ld;
            row[so] += (a1 + a2) * c->inv_tau;
            row[sl] -= a1 * c->inv_tau;
            row[si] -= a2 * c->inv_tau;
            row[c->adr] -= c->inv_tau;
        }
    }
}

static void ls_pumps_jacobian(const hyd_model* m, hyd_data* d, const void* rec, int n, double* Jb,
                              int ldj) {
    if (!Jb)
        return;
    for (int i = 0; i < n; ++i)
        hyd_state_row_from_G(m, d, ((const hyd_ls_pump_c*)rec)[i].adr, Jb, ldj);
}

// A pump that senses its own outlet would hold p_out - p_out = margin: never.
static int ls_pump_check_ports(const hyd_model* m, const char* const* port_name, const int* port,
                               const int* own, char* field, size_t fsz, char* msg, size_t msz) {
    (void)m, (void)own;
    if (port[2] == port[1]) {
        snprintf(field, fsz, "ls");
        snprintf(msg, msz, "'%s' is the pump's own outlet; ls must be the load-sensing line", port_name[2]);
        return -1;
    }
    return 0;
}

// The cut-off must lie above the margin: at standby the pump holds p_out -
// p_ls = margin with p_ls at tank, so a cut-off at or below the margin
// destrokes it before it reaches even its standby pressure; the LS control
// never acts and the pump delivers nothing above p_cutoff (1 MPa: no crane
// load). Refused as a slip, not a design (a margin/cut-off swap, MPa vs bar).
static int ls_pump_validate(const void* def, char* field, size_t fsz, char* msg, size_t msz) {
    const hyd_ls_pump_def* d = def;
    if (!(d->p_cutoff > d->margin)) {
        char a[24], b[24];
        hyd_fmt_num(a, sizeof a, d->p_cutoff);
        hyd_fmt_num(b, sizeof b, d->margin);
        snprintf(field, fsz, "p_cutoff");
        snprintf(msg, msz,
                 "must be above the margin (%s Pa), got %s Pa: the pump would cut off before it reaches its standby "
                 "pressure and deliver nothing against a load",
                 b, a);
        return -1;
    }
    return 0;
}

static void ls_pump_bind(void* rec, int comp, const int* port, const int* own, const int* state) {
    (void)own;
    hyd_ls_pump_c* c = rec;
    c->comp = comp, c->in = port[0], c->out = port[1], c->ls = port[2];
    c->adr = state[0];
}

static void ls_pump_initial(const void* def, const void* rec, double* y0) {
    y0[((const hyd_ls_pump_c*)rec)->adr] = ((const hyd_ls_pump_def*)def)->eps0;
}

static const hyd_param_info ls_pump_params[] = {
    HYD_PARAM(hyd_ls_pump_def, q_max, "m^3/s", HYD_R_POS, 1, 1e-7, 0.1, 1e-5, 5e-3),
    HYD_PARAM(hyd_ls_pump_def, margin, "Pa", HYD_R_POS, 0, 1e5, 1e7, 1e6, 3e6),
    HYD_PARAM(hyd_ls_pump_def, band, "Pa", HYD_R_POS, 0, 1e3, 2e6, 1e4, 3e5),
    HYD_PARAM(hyd_ls_pump_def, p_cutoff, "Pa", HYD_R_POS, 0, 1e6, 1e8, 1e7, 4.5e7),
    HYD_PARAM(hyd_ls_pump_def, cutoff_band, "Pa", HYD_R_POS, 0, 1e3, 1e7, 1e5, 3e6),
    HYD_PARAM(hyd_ls_pump_def, tau, "s", HYD_R_POS, 0, 1e-3, 10, 0.05, 0.15),
    HYD_PARAM(hyd_ls_pump_def, eps0, "-", HYD_R_FRAC, 0, 0, 1, 0, 1),
    HYD_PARAM(hyd_ls_pump_def, leakage, "m^3/(s Pa)", HYD_R_NONNEG, 0, 0, 1e-10, 0, 5e-12),
};
static const hyd_port_info ls_pump_ports[] = {HYD_PORT(hyd_ls_pump_def, inlet),
                                              HYD_PORT(hyd_ls_pump_def, outlet),
                                              HYD_PORT(hyd_ls_pump_def, ls)};
static const hyd_node_role ls_pump_roles[] = {HYD_NODE_LINE, HYD_NODE_SUPPLY, HYD_NODE_LS};
static const char* const ls_pump_states[] = {"disp"};
// It closes on a lag towards 0: flushed to 0 below HYD_STATE_FLUSH (the displacement, of full [-]).
static const double ls_pump_flush[] = {HYD_STATE_FLUSH};

static void ls_pump_defaults(void* def) { *(hyd_ls_pump_def*)def = hyd_default_ls_pump_def(); }

HYD_DEF_FITS(hyd_ls_pump_def);
const hyd_component hyd_ls_pump_component = {
    .type = HYD_LS_PUMP, .name = "ls_pump", .def_size = sizeof(hyd_ls_pump_def),
    .params = ls_pump_params, .nparam = HYD_COUNT(ls_pump_params),
    .ports = ls_pump_ports, .nport = HYD_COUNT(ls_pump_ports),
    .states = ls_pump_states, .nstate = HYD_COUNT(ls_pump_states), .state_flush = ls_pump_flush,
    .rec_size = sizeof(hyd_ls_pump_c), .states_sense_ports = 1, .port_roles = ls_pump_roles,
    .defaults = ls_pump_defaults, .validate = ls_pump_validate, .check_ports = ls_pump_check_ports,
    .bind = ls_pump_bind,
    .derive = ls_pump_derive, .initial = ls_pump_initial, .eval = ls_pumps_eval,
    .jacobian = ls_pumps_jacobian,
};
