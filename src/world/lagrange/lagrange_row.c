// lagrange_row.c: the analytic backend's CSV row (lagrange_row.h).
#include "lagrange_row.h"

#include <string.h>

// One row (all SIM_NCOL columns; the world extras 0) from the lagrange
// crane's outputs o at time t [s]: the one place its rows are assembled
// (the closed form's, engine_lagrange.c, and the general path's, engine_chain.c).
void lagrange_row(double t, const lsim_out* o, double* row) {
    const double v[SIM_NCOL] = {
        t, o->x[0], o->x[1], o->pA[0], o->pB[0], o->pA[1], o->pB[1], o->u[0], o->u[1], o->q[0], o->q[1],
        o->tip[0], o->tip[1], o->F[0], o->F[1], o->u_cmd[0], o->u_cmd[1],
        o->v[0], o->v[1], o->p_pump, o->relief_open, o->end_stop};
    memcpy(row, v, sizeof v);
}

