// world_desc.h: the description of an ODE world (validation or sandbox),
// loaded from a world JSON file (assets/worlds/*.json; schema in
// docs/ode_world.md).
//
// A world_desc is plain data with fixed capacities, except for the optional
// extra hydraulic circuit (a cJSON fragment, owned) that the sandbox appends to
// the model's circuit for the slew function. World frame: x forward, y left,
// z up, metres, radians inside (degrees only in the file).
#ifndef WORLD_DESC_H
#define WORLD_DESC_H

#include <cjson/cJSON.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define WORLD_DESC_NAME 48
#define WORLD_DESC_MAX_LOADS 8
#define WORLD_DESC_MAX_OBSTACLES 64
#define WORLD_DESC_MAX_HILLS 16
#define WORLD_DESC_MAX_ROPE 16

typedef enum world_kind {
    WORLD_VALIDATION = 0, ///< column fixed to the ground, load rigid at the tip, no contacts
    WORLD_SANDBOX         ///< truck on terrain, slewing column, rope and hook, loads, obstacles
} world_kind;

/// How the renderer should draw a body type: a mesh file plus its placement.
typedef struct world_mesh {
    char file[128];    ///< relative to assets/meshes; "" = draw the primitive
    double scale;      ///< mesh units to metres [m/unit]
    int up;            ///< 1 = mesh is y-up, 2 = z-up
    double offset[3];  ///< mesh origin in the body's primitive frame [m]
    int has_offset;    ///< 1: offset given in the world file; 0: the body's own (ode_world.c: a crane part's joint)
} world_mesh;

/// Mesh slots, one per body type.
enum {
    WORLD_MESH_TRUCK = 0, WORLD_MESH_WHEEL, WORLD_MESH_OUTRIGGER, WORLD_MESH_COLUMN,
    WORLD_MESH_BOOM1, WORLD_MESH_BOOM2, WORLD_MESH_HOOK, WORLD_MESH_LOAD, WORLD_MESH_WALL,
    WORLD_MESH_BOX, WORLD_MESH_BUILDING, WORLD_MESH_COUNT
};
/// JSON key of a mesh slot ("truck", "wheel", ..., "building").
extern const char* const world_mesh_key[WORLD_MESH_COUNT];

/// A world object's own mesh (CAD file): its drawing and its collision
/// shape share the object's transform. Paths are resolved against the world
/// file's folder (or absolute). Bounds, volume and centre are of the collision
/// mesh, in the object frame (mesh origin, world axes after scale and up) [m].
typedef struct world_obj_mesh {
    char file[256];       ///< visual mesh, resolved; "" = the object is a box
    char collision[256];  ///< collision mesh, resolved ("" = file)
    double scale;         ///< mesh units to metres [m/unit]
    int up;               ///< 1 = y-up, 2 = z-up
    double lo[3], hi[3];  ///< collision mesh bounds [m]
    double volume;        ///< enclosed volume [m^3] (loose bodies; 0 otherwise)
    double com[3];        ///< centre of mass [m] (loose bodies)
    int ntri;             ///< collision triangles
} world_obj_mesh;

/// Gaussian hill on the terrain: h = height * exp(-r^2 / (2 radius^2)).
typedef struct world_hill {
    double x, y;   ///< centre [m]
    double radius; ///< standard deviation [m]
    double height; ///< peak [m] (negative: a hollow)
} world_hill;

typedef struct world_terrain {
    double size[2];        ///< extent along x, y [m], centred on the origin
    int samples[2];        ///< grid samples along x, y (>= 2)
    double flat_radius;    ///< hills fade out inside this radius: the flat work area [m]
    double friction;       ///< Coulomb friction coefficient against terrain [-]
    int nhill;
    world_hill hill[WORLD_DESC_MAX_HILLS];
    world_obj_mesh mesh;   ///< optional static mesh on the ground (ramps, platforms); file "" = none
    double mesh_pos[3];    ///< mesh origin in the world [m]
    double mesh_yaw;       ///< [rad]
} world_terrain;

/// The truck: one rigid body (chassis, cab, outrigger pads as its geoms)
/// standing on its outrigger pads (or wheels if outriggers are retracted).
typedef struct world_truck {
    double position[2];    ///< chassis centre on the ground plane x, y [m]
    double yaw;            ///< heading, from world x [rad]
    double mass;           ///< total truck mass without the crane [kg]
    double chassis[3];     ///< chassis box length, width, height [m]
    double bed_height;     ///< chassis top (truck bed) above ground when level [m]
    double cab[3];         ///< cab box length, width, height [m]
    double cab_x;          ///< cab centre along truck x from chassis centre [m]
    double wheel_radius;   ///< [m]
    double wheel_width;    ///< [m]
    double wheel_x[2];     ///< front and rear axle positions along truck x [m]
    double track;          ///< distance between left and right wheel centres [m]
    int outriggers;        ///< 1: the truck stands on outrigger pads; 0: on its wheels
    double outrigger_x[2]; ///< front and rear outrigger beam positions along truck x [m]
    double outrigger_span; ///< distance between left and right pad centres [m]
    double pad[3];         ///< outrigger pad box length, width, height [m]
    double column_x;       ///< crane column position along truck x from chassis centre [m]
    double friction;       ///< pad and wheel friction [-]
} world_truck;

/// The slew drive: a rack-and-pinion cylinder pair acting on the column hinge
/// as torque F * pinion_radius. Its valve and cylinder are in the circuit
/// (model circuit plus the world's extra nodes/components).
typedef struct world_slew {
    double pinion_radius;           ///< [m]
    char cylinder[WORLD_DESC_NAME]; ///< slew cylinder component name
    char valve[WORLD_DESC_NAME];    ///< slew valve component name
    double column_radius;           ///< column tube radius (collision, drawing) [m]
    double damping;                 ///< slewing-ring bearing viscous friction [N m s/rad]
} world_slew;

typedef struct world_rope {
    double length;        ///< tip pin to hook pin [m]
    int links;            ///< rigid capsule links in the chain (1..WORLD_DESC_MAX_ROPE)
    double radius;        ///< rope radius (collision, drawing) [m]
    double mass_per_m;    ///< rope mass per metre [kg/m]
} world_rope;

typedef struct world_hook {
    double mass;          ///< [kg]
    double size[3];       ///< hook block box x, y, z [m]
    double reach;         ///< attach a load whose top centre is within this distance [m]
} world_hook;

typedef struct world_load {
    char name[WORLD_DESC_NAME];
    double mass;          ///< [kg]
    double size[3];       ///< box x, y, z [m]
    double position[3];   ///< centre [m]; z < 0 in the file means "rest on the ground"
    double yaw;           ///< [rad]
    double friction;      ///< [-]
    world_obj_mesh mesh;  ///< mesh.file "" = a box of size; else position is the mesh origin
} world_load;

typedef enum world_obstacle_kind { WORLD_OBST_WALL = 0, WORLD_OBST_BOX, WORLD_OBST_BUILDING } world_obstacle_kind;

typedef struct world_obstacle {
    char name[WORLD_DESC_NAME];
    world_obstacle_kind kind; ///< picks the mesh slot and colour
    double size[3];       ///< box x, y, z [m]
    double position[3];   ///< centre [m]; z < 0 in the file means "rest on the ground"
    double yaw;           ///< [rad]
    double mass;          ///< 0: static (fixed); > 0: a loose box that can be pushed [kg]
    double friction;      ///< [-]
    world_obj_mesh mesh;  ///< mesh.file "" = a box of size; else position is the mesh origin
} world_obstacle;

/// Numerical settings of the ODE world. See docs/ode_world.md for why.
typedef struct world_ode_params {
    double erp;           ///< joint error reduction per step [-]
    double cfm;           ///< joint constraint force mixing [m/N-ish, ODE units]
    double contact_erp;   ///< contact error reduction per step [-]
    double contact_cfm;   ///< contact softness [ODE units]
    double surface_layer; ///< allowed contact penetration before correction [m]
    int max_contacts;     ///< contact points per geom pair
} world_ode_params;

typedef struct world_desc {
    char name[64];
    char file[256];        ///< file it came from ("" if built in), for messages
    world_kind kind;
    double gravity;        ///< [m/s^2], 0 allowed (weightless); < 0 (absent from the file): the model's
    world_ode_params ode;
    // Sandbox only (ignored by the validation world).
    world_terrain terrain;
    world_truck truck;
    world_slew slew;
    world_rope rope;
    world_hook hook;
    int nload;
    world_load load[WORLD_DESC_MAX_LOADS];
    int nobstacle;
    world_obstacle obstacle[WORLD_DESC_MAX_OBSTACLES];
    world_mesh mesh[WORLD_MESH_COUNT];
    /// Extra hydraulic nodes/components {"nodes": [...], "components": [...]}
    /// appended to the model's circuit (owned; NULL if none).
    cJSON* circuit;
    /// The same for a model with a load-sensing pump (owned; NULL if none):
    /// the slew as a compensated LS section, plus "patch", an object of
    /// "component.field": "node" that rewires the model's own components
    /// (its LS shuttle's output) so the slew's signal joins the LS network.
    cJSON* circuit_ls;
    /// Where slew and circuit came from, for messages: "" for this world's
    /// own sections (slew, circuit, circuit_ls); else the model file whose
    /// slew drive replaced them (mechanics.slew, hydraulics_slew; see
    /// ode_world_take_model_slew).
    char slew_file[256];
} world_desc;

/// The fragment for a model's hydraulics section: circuit_ls when the
/// circuit has a load-sensing pump and the world has one, else circuit.
const cJSON* world_desc_circuit_for(const world_desc* w, const cJSON* hydraulics);

/// Defaults for a world of the given kind (the built-in validation world, or
/// the built-in sandbox without loads, obstacles or circuit extras).
void world_desc_default(world_desc* w, world_kind kind);

/// Load a world file. Returns 0, or -1 with one line "file: field: problem" in
/// err. On failure *w is left empty (nothing to free).
int world_desc_load(const char* path, world_desc* w, char* err, size_t errsz);
/// Build from a parsed document; file is used in messages. root is not kept.
int world_desc_from_json(const cJSON* root, const char* file, world_desc* w, char* err, size_t errsz);
/// Free what the desc owns (the circuit fragment). Safe on a zeroed desc.
void world_desc_free(world_desc* w);

/// Terrain height [m] at world (x, y) [m] from the analytic hill sum (the
/// heightfield samples this; between samples ODE interpolates linearly).
double world_desc_terrain_height(const world_desc* w, double x, double y);

/// Parse "validation" / "sandbox"; -1 if unknown.
int world_kind_parse(const char* s);
const char* world_kind_name(world_kind k);

#ifdef __cplusplus
}
#endif
#endif
