// snap_reliefs.c: open relief valves into the snapshot (see snap_reliefs.h).
#include "snap_reliefs.h"

#include <stdio.h>

void world_snap_reliefs(world_snapshot* s, const hyd_model* hm, const int* comp_open, const int* cyl_hyd) {
    s->nrelief = 0;
    s->main_relief_open = 0;
    if (!hm || !comp_open) return;
    const int nc = hyd_model_ncomp(hm);
    for (int c = 0; c < nc; ++c) {
        if (hyd_model_comp_type(hm, c) != HYD_RELIEF || !comp_open[c]) continue;
        s->main_relief_open = 1;
        // The chamber it guards: its inlet is a cylinder chamber node (a
        // relief on the pump line or elsewhere guards no cylinder).
        const int st = hyd_model_node_state(hm, hyd_model_relief_inlet(hm, c));
        int cyl = -1, port = 0;
        for (int i = 0; i < s->ncyl && i < WORLD_SNAP_MAX_CYLINDERS && cyl < 0 && st >= 0; ++i) {
            if (cyl_hyd[i] < 0) continue;
            int iA, iB;
            hyd_model_cylinder_states(hm, cyl_hyd[i], &iA, &iB);
            if (st == iA || st == iB) cyl = i, port = st == iB;
        }
        if (cyl >= 0) s->cyl[cyl].relief_open = 1;
        if (s->nrelief < WORLD_SNAP_MAX_RELIEFS) {
            const int k = s->nrelief++;
            snprintf(s->relief[k], sizeof s->relief[k], "%s", hyd_model_comp_name(hm, c));
            s->relief_cyl[k] = cyl;
            s->relief_port[k] = port;
        }
    }
}
