// model_chain.h: the chain form of a model file's mechanics section
// (mechanics.bodies; docs/model.md "The chain form"), read into model.chain.
// Internal to the model loader (model.c, model_chain.c).
#ifndef MODEL_CHAIN_H
#define MODEL_CHAIN_H

#include <stdbool.h>

#include <cjson/cJSON.h>

#include "json_util.h"
#include "model.h"

#ifdef __cplusplus
extern "C" {
#endif

// The mechanics value ranges both forms check against (model.c).
extern const json_range MODEL_R_GRAVITY, MODEL_R_COLUMN_HEIGHT, MODEL_R_COLUMN_MASS, MODEL_R_LINK_LENGTH,
    MODEL_R_LINK_MASS, MODEL_R_LINK_COM, MODEL_R_LINK_INERTIA, MODEL_R_LINK_SECTION, MODEL_R_LOAD,
    MODEL_R_RATED_MOMENT, MODEL_R_RATED_LOAD, MODEL_R_MOUNT, MODEL_R_CLOSED_LENGTH;

/// Whether the mechanics section is in the chain form (it has "bodies").
bool model_chain_form(const cJSON* mech);

/// Reads the chain form of mechanics into m->chain (and the scalars every
/// model has into m->mech: gravity, load, rating, the column's height and
/// mass). Returns 0, or -1 with the one-line error in c.
int model_chain_read(json_ctx* c, const cJSON* mech, model* m);

/// Binds m->chain to the compiled circuit m->hyd (every actuator's cylinder
/// and valve, every function's valve, every cylinder and valve of the
/// circuit used), builds its mechanism once (chain_create's checks) and
/// checks each cylinder can reach a pose within its joint's limits.
/// Returns 0, or -1 with the one-line error in c.
int model_chain_bind(json_ctx* c, model* m);

/// Reads the optional slew drive (mechanics.slew, either form) into *s and
/// checks the shape of its circuit fragment (root's hydraulics_slew; one
/// without the other is an error). s->present is false without one.
/// Returns 0, or -1 with the one-line error in c (model_slew.c).
int model_slew_read(json_ctx* c, const cJSON* root, const cJSON* mech, crane_slew* s);
/// Checks a present slew drive against its fragment: the cylinder and the
/// valve are the fragment's, its patch names ports of the model's circuit,
/// and the model's circuit with the fragment appended compiles. 0, or -1.
int model_slew_check(json_ctx* c, const cJSON* root, const crane_slew* s);

#ifdef __cplusplus
}
#endif
#endif
