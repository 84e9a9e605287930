// snap_reliefs.h: which relief valves are open, by name, for the snapshot
// (the drive HUD names them; both backends fill it the same way).
#ifndef SNAP_RELIEFS_H
#define SNAP_RELIEFS_H

#include "hydraulics.h"
#include "world_snapshot.h"

/// Fill s->nrelief, relief[], relief_cyl[], relief_port[] and
/// main_relief_open from the open flags of circuit hm (comp_open of its
/// hyd_data, as of the last evaluation), and raise relief_open on each
/// snapshot cylinder whose chamber an open relief guards. cyl_hyd[i] is the
/// circuit's cylinder index drawn as s->cyl[i] (-1: none), for i < s->ncyl.
void world_snap_reliefs(world_snapshot* s, const hyd_model* hm, const int* comp_open, const int* cyl_hyd);

#endif
