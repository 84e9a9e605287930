// ode_world_internal.h: module-private layout of ode_world, shared by
// ode_world.c (crane), ode_sandbox.c (truck, terrain, rope, loads, contacts)
// and ode_coupling.c (hydraulics). Include only from those files.
#ifndef ODE_WORLD_INTERNAL_H
#define ODE_WORLD_INTERNAL_H

#include <ode/ode.h>
#include <stdint.h>

#include "hydraulics.h"
#include "circuit_fast.h"
#include "hyd_fused.h"
#include "hyd_solver.h"
#include "ode_chain.h"
#include "ode_common.h"
#include "ode_world.h"

#define OW_MAX_GEOMS 256
#define OW_MAX_VIS WORLD_SNAP_MAX_BODIES
#define OW_MAX_CONTACT_JOINTS 4096
#define OW_MAX_HYD 96
/// Rope tension [N] up to which the rope's links are given the transverse
/// inertia that keeps their zig-zag modes at omega H <= 1 (build_rope). The
/// sandbox's hook caught under the chassis and pulled by the lift loads it
/// to 45 kN; the chain then holds up to 4e5 N, twice the lift cylinder's
/// push at its port relief (7.85e-3 m^2 x 26 MPa = 204 kN).
#define OW_ROPE_DESIGN_TENSION 1e5
/// Truck supports whose ground reaction is measured: the four outrigger pads
/// (the four wheels when the outriggers are in), index 2 a + s with a = 0
/// front, 1 rear and s = 0 left (+y), 1 right (-y).
#define OW_NSUPPORT 4
/// Contact joints on the supports whose forces ODE reports per step
/// (dJointSetFeedback); a sphere on the heightfield makes one or two.
#define OW_MAX_SUPPORT_FB 64
/// Time constant [s] of the first-order filter on the support reactions.
/// ODE's contact solver now and then hands one step's load to fewer pads
/// (the pick-and-place: three pads at 0 N for one 1 ms step at 25.409 s, the
/// next step catching the truck with 5 % more); unfiltered, every such step
/// read as a lift-off. 5 ms lets one such step move a reading by 18 %, and a
/// real lift-off reads below 1 % of the load within 25 ms.
#define OW_SUPPORT_TAU 5e-3

/// Collision categories (bits); which pairs collide is a table in ode_sandbox.c.
enum {
    OW_CAT_TERRAIN = 1, OW_CAT_TRUCK = 2, OW_CAT_CRANE = 4, OW_CAT_ROPE = 8,
    OW_CAT_HOOK = 16, OW_CAT_LOAD = 32, OW_CAT_OBST = 64
};

/// Per-geom data, pointed to by dGeomGetData.
typedef struct ow_geom {
    dGeomID g;
    uint32_t cat;     ///< OW_CAT_*
    double friction;  ///< Coulomb coefficient [-]; a pair uses the geometric mean
    int support;      ///< truck support (OW_NSUPPORT) this geom carries, else -1
    int mesh;         ///< index into ode_world.mesh for trimesh and hull geoms, else -1
    char name[WORLD_SNAP_NAME]; ///< the body's name for collision reports ("boom1", a load's or an
                                ///< obstacle's own); "" reads as its category ("terrain", "truck", "hook")
} ow_geom;
/// Colliding pairs one step records (ode_world_collisions); more are dropped.
#define OW_MAX_COLL_PAIRS 16

/// Mesh data ODE keeps pointers to while its geoms live (mesh_ode.c).
typedef struct ow_mesh {
    dTriMeshDataID tmd;  ///< static trimesh data (0 for a hull)
    float* v;            ///< trimesh vertices [m], object frame
    dTriIndex* idx;      ///< trimesh indices
    int nv, nt;          ///< trimesh or hull vertices, triangles (the debug view draws them)
    dReal* planes;       ///< hull planes (nx, ny, nz, d), body frame
    dReal* points;       ///< hull vertices, body frame [m]
    unsigned* polys;     ///< hull polygons (3, a, b, c)
    float* dv;           ///< the shape's triangles for the debug view: vertices in the geom frame [m]
    int* di;             ///< and indices (nv, nt of them)
    int nt_file;         ///< static trimesh: triangles as loaded, before flat faces were merged
    int nt_merged;       ///< and how many of them mesh_merge_coplanar removed
} ow_mesh;
#define OW_MAX_MESHES (WORLD_DESC_MAX_LOADS + WORLD_DESC_MAX_OBSTACLES + 1)
/// Trimesh contacts closer than this are one (ow_mesh_merge_contacts) [m]:
/// well under a load's or a boom's width, so a face keeps its corners.
#define OW_MESH_MERGE_RADIUS 0.1
/// ow_vis.mesh: the entry draws its own mesh file (ow_vis.mesh_file).
#define OW_VIS_OWN_MESH (-2)

/// One entry of the snapshot: a primitive placed in a body's frame (or in the
/// world when body is 0, e.g. static obstacles).
typedef struct ow_vis {
    char name[WORLD_SNAP_NAME];
    world_role role;
    world_shape shape;
    double size[3];     ///< see world_shape [m]
    float rgba[4];
    int mesh;           ///< WORLD_MESH_* slot, or -1
    dBodyID body;       ///< 0: pose is in the world
    double pos[3];      ///< primitive centre in the body frame (or world) [m]
    double rot[9];      ///< primitive-to-body rotation, row-major
    double mesh_offset[3]; ///< mesh origin in the primitive frame [m] when the world file gives none
    char mesh_file[256];   ///< mesh == OW_VIS_OWN_MESH: the object's own visual mesh (absolute path)
    double mesh_scale;     ///< its scale [m/unit]
    int mesh_up;           ///< its up axis (1 y, 2 z)
} ow_vis;

/// A crane frame (column, lifting arm, end arm) carried by an ODE body: the
/// body's axes are the frame's axes; org is the frame origin (the joint) in
/// body coordinates, because ODE bodies have their origin at the COM.
typedef struct ow_frame {
    dBodyID body;       ///< 0: fixed to the world (validation column)
    double org[3];      ///< frame origin in body coordinates [m]
    double wpos[3];     ///< body == 0: frame origin in the world [m]
    double wrot[9];     ///< body == 0: frame-to-world rotation, row-major
} ow_frame;

/// One hydraulic actuator as the mechanics sees it.
typedef struct ow_act {
    int present;
    int cyl;            ///< hydraulic cylinder index, -1 if none
    int valve;          ///< hydraulic valve index, -1 if none
    int iA, iB, iu;     ///< state indices of pA, pB, spool
    double AA, AB, stroke; ///< piston area, annulus area [m^2], stroke [m]
    // Boom cylinders: mount points in the parent and child crane frames.
    int parent, child;  ///< frame indices (0 column, 1 lifting arm, 2 end arm)
    double base[3], rod[3]; ///< in frame coordinates [m]
    double closed_length; ///< [m]
    // Latest kinematics and force.
    double x, v;        ///< stroke [m], rate [m/s] at the start of the step
    double F;           ///< force applied over the step [N]
    int at_stop;        ///< hinge limit or hydraulic stop active
} ow_act;

struct ode_world {
    world_kind kind;
    crane_mech mech;
    world_desc desc;     ///< copy (circuit fragment not kept: circuit = NULL)
    ode_world_opts opt;
    double g;            ///< gravity [m/s^2]
    double m3;           ///< validation: tip mass [kg]
    double t;            ///< [s]
    long nstep;          ///< ODE steps taken
    int failed;
    int world_built;     ///< ode_world_create finished
    int dead;            ///< ODE itself failed (ow_trapped): only ode_world_destroy may touch ODE
    char err[384];

    dWorldID world;
    dThreadingImplementationID threading; ///< the world's own (self-threaded) step jobs, see ow_trapped
    dSpaceID dyn_space;    ///< moving geoms
    dSpaceID static_space; ///< terrain and fixed obstacles
    dJointGroupID contacts;
    dHeightfieldDataID hfield;

    // Crane: frames 0 column, 1 lifting arm, 2 end arm.
    ow_frame frame[3];
    dJointID slew_joint, j1, j2, column_fix;
    double qoff[2];      ///< q = hinge angle + qoff [rad]
    double lim[2][2];    ///< stroke-derived hinge stops lo, hi [rad] (+-dInfinity if none)
    // The slew angle [rad], continuous: ODE's hinge angle wraps at +-pi, so
    // slew = hinge angle + slew_turns + slew_off, with slew_turns (a multiple
    // of 2 pi) moved whenever the hinge angle jumps by more than pi between
    // two reads (ow_read_actuators, every ODE step; a step turns the column
    // far less than pi).
    double slew_off;     ///< slew at hinge angle 0 (slew0) [rad]
    double slew_turns;
    double slew_raw;     ///< hinge angle at the last read [rad]
    double slew_lim[2];  ///< the rack's end stops on the continuous hinge angle [rad] (+-dInfinity: none)
    double tau_extra[2]; ///< test torques [N m]
    ow_act act[ODE_NACT];

    // Sandbox bodies.
    dBodyID truck;
    double truck_org[3]; ///< truck frame origin (ground under chassis centre) in body coordinates [m]
    int nrope;
    dBodyID rope[WORLD_DESC_MAX_ROPE];
    double rope_len;     ///< one link [m]
    double rope_mass;    ///< one link [kg]
    double rope_inertia; ///< one link about a transverse axis through its centre [kg m^2] (see build_rope)
    dBodyID hook;
    dJointID hook_joint; ///< pre-created ball joint for attaching a load
    int attached;        ///< load index or -1
    /// The load the hook let go while the two still overlap, or -1: their
    /// contacts may stop the overlap growing but not push it apart (ow_attach).
    int released;
    double release_allow;  ///< overlap [m] those contacts leave alone: its depth at the release, only ever smaller
    double release_depth;  ///< their deepest contact in this step's collision [m], -1: none
    int nload;
    dBodyID load[WORLD_DESC_MAX_LOADS];
    dBodyID obst_body[WORLD_DESC_MAX_OBSTACLES]; ///< 0 for static obstacles
    double load_top[WORLD_DESC_MAX_LOADS]; ///< load's top above its body origin (COM) [m], for the hook
    int nmesh;
    ow_mesh mesh[OW_MAX_MESHES];
    int held;            ///< crane frozen (kinematic)

    // Geoms and snapshot entries.
    int ngeom;
    ow_geom geom[OW_MAX_GEOMS];
    int nvis;
    ow_vis vis[OW_MAX_VIS];
    float* terrain;      ///< nx*ny heights, world row order (snapshot)
    int tnx, tny;
    double tdx, tdy;

    // Contacts of the last step.
    dContactGeom cbuf[32];
    int ncontact;
    double max_depth, max_depth_crane;
    int crane_contact;
    int ncoll_pair;                          ///< collision pairs touching in the last step
    int coll_pair[OW_MAX_COLL_PAIRS][2];     ///< their geoms (index into geom), the crane's first
    // Ground reactions on the truck's supports (ode_sandbox.c, ow_support_forces).
    int nsupport;                            ///< OW_NSUPPORT, or 0 (validation world)
    double support_pt[OW_NSUPPORT][3];       ///< contact point under each support, truck body coordinates [m]
    double support_F[OW_NSUPPORT];           ///< vertical reaction on each, low-passed (OW_SUPPORT_TAU) [N]
    int nsupport_fb;                         ///< feedback slots used in this step
    dJointFeedback support_fb[OW_MAX_SUPPORT_FB];
    dJointID support_fb_joint[OW_MAX_SUPPORT_FB];
    int support_fb_of[OW_MAX_SUPPORT_FB];    ///< the support each slot's contact is on

    // Hydraulics (ode_coupling.c).
    hyd_model* hm;       ///< compiled circuit, NULL without hydraulics
    int own_hm;          ///< 1: hm compiled here (freed with the world); 0: opts.circuit, borrowed
    hyd_data* hd;
    hyd_solver* hs;
    hyd_problem hp;
    int nblock;               ///< block-diagonal W pattern of the circuit (fixed-step methods)
    int block[OW_MAX_HYD];
    int nh;
    double y[OW_MAX_HYD];
    int npres;           ///< node pressure states, listed in pres (hyd_problem.outside)
    int pres[OW_MAX_HYD];
    double th;           ///< hydraulic time [s]
    int nsub;            ///< sub-steps per ODE step
    double u_cmd[ODE_NACT];
    double step_t0;      ///< start of the current ODE step [s] (for extrapolation)
    double x0[ODE_NACT], v0[ODE_NACT]; ///< strokes and rates at the step start
    int ipump;           ///< state index of the pump-line pressure, or -1
    long hyd_steps;
    // The energy balance (ode_world_follow_energy), integrated at every
    // hydraulic step; NULL: none.
    struct sim_energy* energy;
    int hyd_started;     ///< ow_hyd_step has set x0, v0 and step_t0 at least once
    // The straight-line circuit kernel (hyd_fused.h) for the solver's f and
    // J, when the circuit has the standard shape and opts.general_circuit is
    // 0. Lane j drives actuator fz_act[j]. Rebuilt when the circuit's
    // revision moves (live parameter edits).
    hyd_fused fz;
    int use_fused, nfz;
    int fz_act[ODE_NACT];
    unsigned fz_rev;
    hyd_fused_events fz_ev; ///< the fused path's event counter (hyd_problem.events)
    // The fast kernel (circuit_fast.h) for any other circuit, unless
    // opts.general_circuit asks for the reference loops. It follows live
    // edits by itself (the circuit's revision).
    hyd_fast* fk;
    int use_fast;

    // A chain crane (opts.chain, not two_link): its bodies, joints and
    // circuit are ode_chain's, hosted in this world on the truck; frame[0]
    // is its column, frame[1] its first boom, frame[2] the tip's body (the
    // rope's anchor). The two-link fields above (act[] except the slew's
    // display copy, j1, j2, hm, y) stay unused.
    ode_chain* chain;
    hyd_model* chain_hm;   ///< its circuit (the model's with the world's part appended)
    int chain_own_hm;      ///< 1: compiled here, freed with the world
    double* chain_q;       ///< scratch: joint coordinates and rates (2 ndof)
};

// ode_world.c
void ow_frame_point(const ode_world* w, int f, const double p[3], double out[3]);
void ow_frame_point_vel(const ode_world* w, int f, const double p[3], double out[3]);
void ow_frame_rot(const ode_world* w, int f, double R[9]);
ow_geom* ow_add_geom(ode_world* w, dGeomID g, uint32_t cat, double friction);
ow_vis* ow_add_vis(ode_world* w, const char* name, world_role role, world_shape shape, const double size[3],
                   const float rgba[4], int mesh, dBodyID body, const double pos[3], const double* rot);
void ow_rot_z(double yaw, double R[9]);
void ow_mat_mul(const double A[9], const double B[9], double C[9]);
void ow_mat_vec(const double A[9], const double v[3], double out[3]);
int ow_build_crane(ode_world* w, const double col_pos[3], const double col_rot[9], dBodyID base,
                   char* err, size_t errsz);
void ow_read_actuators(ode_world* w);
/// The slew angle [rad], continuous through +-pi (0 without a slew hinge).
double ow_slew_angle(const ode_world* w);
/// Give ODE the slew stops (slew_lim) as hinge angles of the current turn.
void ow_slew_stops(ode_world* w);
void ow_apply_forces(ode_world* w);

/// The sandbox's chain crane (w->chain) on the truck, its column foot at
/// base [m] with the truck's rotation R: the hosted ode_chain, a collision
/// geom and a drawing per body, frames 0 to 2 for the rope and the column.
int ow_build_chain_crane(ode_world* w, const double base[3], const double R[9], char* err, size_t errsz);
/// The crane's tip (the rope's anchor) in the world [m] and its velocity
/// (v may be NULL).
void ow_tip(const ode_world* w, double p[3], double v[3]);
/// The crane's moving bodies (column and booms, of either crane) into b;
/// returns their count (at most max).
int ow_crane_bodies(const ode_world* w, dBodyID* b, int max);

// ode_sandbox.c
int ow_build_sandbox(ode_world* w, char* err, size_t errsz);
void ow_collide(ode_world* w);
void ow_sandbox_snapshot(const ode_world* w, world_snapshot* s);
double ow_truck_tilt(const ode_world* w);
/// After dWorldStep, before the contact group is emptied: support_F from the
/// contact joints' feedback.
void ow_support_forces(ode_world* w);
/// The static stability margin of the current pose (ode_world.h,
/// ode_world_state.stab_margin) and the total weight the supports carry [N].
double ow_stab_margin(const ode_world* w, double* weight);
/// Bits of the supports lifted off now (ode_world_state.pad_lifted), weight
/// the total the supports carry [N].
int ow_supports_lifted(const ode_world* w, double weight);
void ow_hook_point(const ode_world* w, double p[3], double v[3]);
int ow_attach(ode_world* w, int attach);

// mesh_ode.c
/// A static ODE trimesh of om's collision mesh in space, its object frame at
/// pos with rotation R. NULL with err on failure.
dGeomID ow_mesh_trimesh(ode_world* w, dSpaceID space, const world_obj_mesh* om, const double pos[3],
                        const double R[9], char* err, size_t errsz);
/// A convex hull geom (not in a space yet: space given) of om's collision
/// mesh in the body frame (origin at the centre of mass), and the body's
/// mass of total mass [kg] with the closed mesh's inertia. NULL with err.
dGeomID ow_mesh_hull(ode_world* w, dSpaceID space, const world_obj_mesh* om, double mass, dMass* m, char* err,
                     size_t errsz);
/// Destroy the trimesh data (inside ODE's trap) and free the arrays.
void ow_mesh_destroy_data(ode_world* w);
void ow_mesh_free(ode_world* w);
/// Merge a trimesh pair's contacts closer than radius [m] with nearly the same
/// normal into the deepest of them (ODE gives one per touched triangle, and
/// each contact is three more rows in the island's LCP). Returns the count.
int ow_mesh_merge_contacts(dContactGeom* c, int n, double radius);
/// The collision shapes into the snapshot (debug view).
void ow_collision_snapshot(const ode_world* w, world_snapshot* s);
/// Name geom e for collision reports (NULL e: nothing).
void ow_geom_name(ow_geom* e, const char* name);

// ode_coupling.c
int ow_hyd_create(ode_world* w, const cJSON* hydraulics, const cJSON* extra, const char* part, char* err,
                  size_t errsz);
void ow_hyd_destroy(ode_world* w);
void ow_hyd_init_state(ode_world* w);
int ow_hyd_step(ode_world* w, double dt);

#endif
