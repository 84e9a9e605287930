// check_valve.c: anti-cavitation check valve, tank -> cylinder port.
//
// It opens when the port pressure falls p_crack below the tank (d = p_in -
// p_out - p_crack > 0) and follows the same C1 quadratic corner as the relief
// (relief.c), reaching q_rated after a further dp_open. Refilling a chamber
// that is pulled open keeps its pressure near p_tank - p_crack instead of
// letting it sink towards absolute zero.
#include "hyd_internal.h"

hyd_check_def hyd_default_check_def(void) {
    hyd_check_def d = {0};
    d.p_crack = 0.05e6;
    d.dp_open = 0.02e6;
    d.q_rated = 40.0 / 60000.0;
    return d;
}

void hyd_check_derive(const hyd_check_def* d, hyd_ramp_c* c) {
    c->pcr = d->p_crack;
    c->inv_w = 1.0 / d->dp_open;
    c->qr = d->q_rated;
}

void hyd_checks_eval(const hyd_model* m, hyd_data* d, double* G) {
    hyd_ramps_eval(m, d, G, m->check, m->ncheck);
}
