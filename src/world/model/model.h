// model.h: a complete crane model: mechanics plus hydraulic circuit, loaded
// from one JSON file (assets/models/hiab031.json; schema in docs/model.md).
#ifndef MODEL_H
#define MODEL_H

#include <cjson/cJSON.h>
#include <stddef.h>

#include "crane_chain.h"
#include "crane_model.h"
#include "hydraulics.h"
#include "model_controls.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct model {
    char name[96];
    char file[256];      ///< path it was loaded from ("" if built in)
    /// Mechanics of the two-link shorthand (derived fields filled) when
    /// chain.two_link; for a chain model only gravity, load_mass, the rating
    /// and the column's height and mass are set, the links' and actuators'
    /// numbers are NaN (model_require_two_link).
    crane_mech mech;
    crane_chain chain;   ///< the crane as a chain: bodies, actuators, functions (every model; owned)
    hyd_model* hyd;      ///< compiled circuit (owned)
    int cyl[2];          ///< hydraulic cylinder index of actuator k (lift, jib); -1 for a chain model
    int valve[2];        ///< hydraulic valve index of actuator k; -1 for a chain model
    double stroke[2];    ///< cylinder strokes [m]; NaN for a chain model
    cJSON* json;         ///< the document after --set overrides (owned), for saving
    /// Hose-burst orifices ("fault<i>_burst") at nodes the model's circuit
    /// lacks, for the world's circuit to add (engine_fault_model; the sandbox
    /// adds the slew's). Owned; NULL when none. A backend without a world
    /// circuit refuses a model that has them (engine_world_bursts).
    cJSON* world_bursts;
    char world_bursts_src[128]; ///< the scenario file they come from (messages)
    /// The operator's input mapping by function (the model's "controls"
    /// section, docs/render.md), NULL when the model has none: drive then
    /// lays the functions out by its defaults. Owned.
    model_controls* controls;
} model;

/// Load a model file and apply "path=value" overrides (see json_set_path) in
/// order. NULL path loads the built-in default (assets/models/hiab031.json as
/// found by model_default_path); a path without '/' that is no file and does
/// not end in .json is a name in <assets>/models (model_path). Returns NULL
/// with one line "file: field: problem" in err (a name that is no model
/// lists the models there).
model* model_load(const char* path, const char* const* sets, int nset, char* err, size_t errsz);

/// Build from a parsed document (ownership of root passes to the model, also
/// on failure). file is used in messages.
model* model_from_json(cJSON* root, const char* file, char* err, size_t errsz);

void model_free(model* m);

/// The one gate for every consumer of the two-link fields (mech's links and
/// actuators, cyl, valve, stroke): the closed-form analytic path, the ODE
/// world, the load chart, the limiter, the start-pose check. A chain model
/// (mechanics.bodies: model.chain.two_link false) leaves those fields empty,
/// so each such entry point calls this first and refuses the model rather
/// than run the wrong crane. Returns 0 for a two-link model, else -1 with
/// "model.json: a chain of 5 bodies and 4 functions; the <what> handles the
/// two-link crane (mechanics.links) only" in err. When a path
/// learns the chain, its call goes (grep model_require_two_link).
int model_require_two_link(const model* m, const char* what, char* err, size_t errsz);

/// The circuit of a model's hydraulics section (file mfile) with a fragment
/// appended (frag: {nodes, components[, patch]} from file ffile, field fpart:
/// "hydraulics_slew", a world's "circuit" or "circuit_ls"), its patch
/// ("component.field": "node") applied to the model's components first:
/// what the sandbox runs. NULL with one line "file: field: problem" in err.
hyd_model* model_circuit_with_fragment(const cJSON* hydraulics, const char* mfile, const cJSON* frag,
                                       const char* ffile, const char* fpart, char* err, size_t errsz);

/// Write the model's JSON (with overrides applied) to path. Returns 0 or -1.
int model_save(const model* m, const char* path, char* err, size_t errsz);

/// One scalar of the mechanics section, as the loader checks it.
typedef struct model_param {
    const char* path;  ///< its path in the model file ("mechanics.links[1].mass")
    const char* group; ///< "mechanics", "links[0]", "links[1]", "actuators[0]", "actuators[1]"
    const char* name;  ///< "mass", "base mount x", ...
    const char* unit;  ///< SI unit ("kg", "m", "kg m^2", "m/s^2")
    double lo, hi;     ///< hard range: outside it a file is refused [unit]
    double tlo, thi;   ///< typical range: outside it the loader notes it [unit]
    int optional;      ///< 1: a model may lack the field (the rating); it then reads 0, outside [lo, hi]
} model_param;
/// The mechanics parameter table: model_param_count() entries.
int model_param_count(void);
/// Entry k into *out; 0, or -1 when k is out of range.
int model_param_info(int k, model_param* out);
/// Whether the model has entry k's field: every required one; an optional
/// one when it is in the file (nonzero). 0 also when k is out of range.
int model_param_present(const crane_mech* me, int k);
/// The field entry k names in me, or NULL when k is out of range.
double* model_param_ptr(crane_mech* me, int k);
/// The default model file: $CRANESIM_ASSETS/models/hiab031.json, else the
/// source tree's assets folder compiled in, else ./assets/models/hiab031.json.
const char* model_default_path(void);

/// The file a model argument names: arg itself if it is a regular file, has
/// a '/' or ends in ".json", else <assets>/models/<arg>.json in buf (as
/// scenarios and worlds are named). NULL arg: model_default_path().
const char* model_path(const char* arg, char* buf, size_t n);

/// The assets folder in use (same search as model_default_path).
const char* model_assets_dir(void);

#ifdef __cplusplus
}
#endif
#endif
