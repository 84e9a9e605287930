// world_snapshot.h: a read-only picture of the world at one instant.
//
// The physics fills it; the renderer and HUD only read it (MuJoCo's abstract
// scene idea). It is plain data with fixed capacities, so it can be copied
// between threads or sent over a socket, and built without any GL header.
// World frame: x forward (truck length), y left, z up, metres.
#ifndef WORLD_SNAPSHOT_H
#define WORLD_SNAPSHOT_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define WORLD_SNAP_MAX_BODIES 160
/// Cylinders drawn: a crane chain's actuators and the sandbox's slew rack
/// (the 8-function test crane has 9 + 1). The serve protocol carries at most
/// PROTO_MAX_CYL of them (it serves the two-link crane only).
#define WORLD_SNAP_MAX_CYLINDERS 16
#define WORLD_SNAP_MAX_ROPE 32
#define WORLD_SNAP_NAME 48
#define WORLD_SNAP_MAX_RELIEFS 8
#define WORLD_SNAP_MAX_COLL 256

/// Primitive shape used when a body has no mesh or its mesh failed to load.
typedef enum world_shape {
    WORLD_SHAPE_BOX = 0,   ///< size = full extents x, y, z [m]
    WORLD_SHAPE_CYLINDER,  ///< size[0] = radius, size[1] = length along local z [m]
    WORLD_SHAPE_CAPSULE,   ///< size[0] = radius, size[1] = length of the straight part along z [m]
    WORLD_SHAPE_SPHERE,    ///< size[0] = radius [m]
    WORLD_SHAPE_TERRAIN    ///< the heightfield in world_snapshot.terrain
} world_shape;

/// What a body is, so the renderer can colour, pick or label it.
typedef enum world_role {
    WORLD_ROLE_OTHER = 0,
    WORLD_ROLE_TERRAIN,
    WORLD_ROLE_TRUCK,
    WORLD_ROLE_WHEEL,
    WORLD_ROLE_OUTRIGGER,
    WORLD_ROLE_COLUMN,
    WORLD_ROLE_BOOM1, ///< lifting arm
    WORLD_ROLE_BOOM2, ///< end arm (jib)
    WORLD_ROLE_HOOK,
    WORLD_ROLE_LOAD,
    WORLD_ROLE_OBSTACLE,
    WORLD_ROLE_BOOM,     ///< a boom of a crane chain, on a revolute joint (the two-link crane's are BOOM1, BOOM2)
    WORLD_ROLE_EXTENSION ///< a telescopic extension of a crane chain, sliding in its parent boom
} world_role;

typedef struct world_snap_body {
    char name[WORLD_SNAP_NAME]; ///< unique body name, e.g. "boom1", "load_2"
    world_role role;
    world_shape shape;          ///< fallback primitive (always valid)
    double pos[3];              ///< body origin in world [m]
    double rot[9];              ///< body-to-world rotation, row-major 3x3
    double size[3];             ///< primitive dimensions, see world_shape [m]
    float rgba[4];              ///< colour, 0..1
    char mesh[256];             ///< mesh file (relative to assets/meshes or absolute); "" = primitive
    double mesh_scale;          ///< mesh units to metres (1 for metres, 0.001 for mm)
    int mesh_up;                ///< mesh up axis: 1 = y-up (glTF/OBJ default), 2 = z-up
    double mesh_offset[3];      ///< mesh origin in body frame [m]
} world_snap_body;

/// A hydraulic cylinder as seen from outside: barrel from base mount, rod to
/// rod mount, with its chamber pressures for the pressure bars.
typedef struct world_snap_cylinder {
    char name[WORLD_SNAP_NAME];
    double base[3];        ///< barrel-end pin, world [m]
    double rod_end[3];     ///< rod-end pin, world [m]
    double bore;           ///< piston diameter [m]
    double rod;            ///< rod diameter [m]
    double stroke_max;     ///< full stroke [m]
    double closed_length;  ///< pin-to-pin length fully retracted [m]
    double x;              ///< stroke [m], 0..stroke_max
    double v;              ///< stroke rate [m/s]
    double pA, pB;         ///< chamber pressures, absolute [Pa]
    double force;          ///< cylinder force, + extends [N]
    double u;              ///< spool opening of its valve, -1..1
    double u_cmd;          ///< commanded opening, -1..1
    double u_op;           ///< the operator's demand before the rated capacity limiter, -1..1 (u_cmd
                           ///< unless rcl_cut; a remote view knows it only for its own demand)
    uint8_t rcl_cut;       ///< the rated capacity limiter cut the operator's demand (u_cmd < u_op)
    uint8_t relief_open;   ///< a relief on one of its chambers is passing flow
    uint8_t end_stop;      ///< at an end stop
} world_snap_cylinder;

/// Heightfield terrain, row-major heights over a regular grid centred on the
/// world origin. Owned by the world; valid as long as the world lives.
typedef struct world_snap_terrain {
    const float* height; ///< nx*ny heights [m], height[j*nx + i]
    int nx, ny;          ///< samples along x and y
    double dx, dy;       ///< spacing [m]
} world_snap_terrain;

/// A collision shape as the physics sees it (the debug view draws these over
/// the scene). Mesh shapes point at triangles the world owns (valid while it
/// lives, like the terrain heights).
typedef struct world_snap_coll {
    world_shape shape;     ///< BOX, SPHERE, CAPSULE, CYLINDER (size as in world_shape), or TERRAIN for a mesh
    double pos[3];         ///< geom origin in world [m]
    double rot[9];         ///< geom-to-world rotation, row-major
    double size[3];        ///< see world_shape [m]
    const float* v;        ///< mesh: 3 nv coordinates in the geom frame [m]
    const int* idx;        ///< mesh: 3 nt indices
    int nv, nt;
} world_snap_coll;

typedef struct world_snapshot {
    double t;              ///< simulated time [s]
    double rt_factor;      ///< measured simulated/wall time ratio, 0 if unknown
    int nbody;
    world_snap_body body[WORLD_SNAP_MAX_BODIES];
    int ncyl;
    world_snap_cylinder cyl[WORLD_SNAP_MAX_CYLINDERS];
    int nrope;                              ///< rope polyline points, crane tip to hook
    double rope[WORLD_SNAP_MAX_ROPE][3];    ///< [m]
    world_snap_terrain terrain;             ///< nx == 0: flat ground at z = 0
    double tip[3];          ///< end-arm tip, world [m]
    double hook[3];         ///< hook position, world [m]
    double load_mass;       ///< mass on the hook or at the tip [kg]
    double slew;            ///< column slew angle [rad]
    double truck_tilt;      ///< truck tilt from upright [rad]
    double p_supply;        ///< pump line pressure, absolute [Pa]
    uint8_t attached;       ///< a load is on the hook
    uint8_t tipping;        ///< truck tilt past the warning limit
    uint8_t collision;      ///< a crane part touches an obstacle
    uint8_t main_relief_open; ///< any relief valve passing flow (see relief[] for which)
    int nrelief;              ///< relief valves passing flow, named in relief[] (0 if unknown)
    char relief[WORLD_SNAP_MAX_RELIEFS][WORLD_SNAP_NAME]; ///< their circuit names ("slew_relief_A")
    /// The snapshot cylinder each open relief guards (index into cyl[]), or -1
    /// (a pump-line relief), and the chamber: 0 = A, 1 = B.
    int relief_cyl[WORLD_SNAP_MAX_RELIEFS], relief_port[WORLD_SNAP_MAX_RELIEFS];
    uint8_t rcl_have;         ///< the rated capacity limiter measures (rcl_util is valid)
    uint8_t rcl_on;           ///< ... and cuts the motions that increase the load moment
    double rcl_util;          ///< its utilisation: load moment over the chart's rated moment [-]
    /// The truck's supports (outrigger pads, or wheels with the outriggers
    /// in): 0 without a truck, else 4, front-left, front-right, rear-left,
    /// rear-right.
    int npad;
    double pad_F[4];        ///< vertical ground reaction [N]
    double pad_pos[4][3];   ///< contact point under each, world [m]
    int pad_lifted;         ///< bit i: support i lifted off (below 1 % of the weight)
    double stab_margin;     ///< restoring over tipping moment, governing tipping line [-]
    int ncoll;                                  ///< collision shapes (0: the world gives none)
    world_snap_coll coll[WORLD_SNAP_MAX_COLL];
} world_snapshot;

#ifdef __cplusplus
}
#endif
#endif
