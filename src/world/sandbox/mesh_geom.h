// mesh_geom.h: triangle meshes for the physics core (no assimp here).
//
// The core reads OBJ and STL itself; other formats (glTF/GLB, Collada, FBX)
// come through an importer the application installs (mesh_set_importer,
// assimp in src/render), so the physics core builds and tests without it.
// A mesh is converted to the world's z-up metres on load (scale, up axis),
// its identical vertices are welded (STL repeats them per facet) and its
// degenerate triangles are dropped. On it: closedness, volume, centre of
// mass and inertia (divergence theorem), and the convex hull for loose bodies.
// See docs/ode_world.md, "CAD meshes".
#ifndef MESH_GEOM_H
#define MESH_GEOM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Most triangles a world mesh may have (a CAD obstacle of 50,000 triangles
/// costs ODE well under a millisecond per contact query; a million would cost
/// memory and load time for no gain in a crane yard).
#define MESH_MAX_TRIANGLES 200000
/// Largest mesh file [bytes] (256 MiB): an ASCII STL of MESH_MAX_TRIANGLES
/// facets takes about 60 MB, an OBJ with normals and texture coordinates
/// less. Checked, with the file being a regular file, before anything reads
/// it (a link to /dev/zero would otherwise be read for ever).
#define MESH_MAX_FILE_BYTES (256L << 20)

typedef struct mesh_tri {
    int nv, nt;
    float* v;       ///< 3 nv coordinates [m], z up
    int* idx;       ///< 3 nt vertex indices
    int dropped;    ///< degenerate triangles removed on load
    int merged;     ///< triangles removed by mesh_merge_coplanar
} mesh_tri;

/// An importer for formats the core does not read: fill out->v/idx (mesh
/// units, the file's own axes; malloc'd) and return 0, or -1 with why in err
/// (no file name; the caller adds it).
typedef int (*mesh_import_fn)(const char* path, mesh_tri* out, char* err, size_t errsz);
void mesh_set_importer(mesh_import_fn fn);

/// A function the long mesh loops (parsing, the hull) poll: when it returns
/// non-zero they stop and the load fails with "interrupted" (mesh_hull_build
/// returns -3). NULL (the default): never. The application installs its
/// SIGINT/SIGTERM flag, so Ctrl-C stops a load within milliseconds.
typedef int (*mesh_cancel_fn)(void);
void mesh_set_cancel(mesh_cancel_fn fn);
/// Non-zero when the installed function says stop.
int mesh_cancelled(void);

/// Load path (OBJ/STL here, others through the importer), scale [m/unit],
/// up 1 = y-up (mesh y becomes z, mesh z becomes -y), 2 = z-up. Returns 0, or
/// -1 with the problem in err (without the file name).
int mesh_load(const char* path, double scale, int up, mesh_tri* out, char* err, size_t errsz);
void mesh_free(mesh_tri* m);

/// mesh_load keeps each finished mesh per process (key: path, modification
/// time, size, scale, up; a few files, least recently used evicted), so a
/// world file loaded by several steps parses its meshes once. Safe from
/// several threads. Freed at exit; mesh_cache_clear frees it now.
void mesh_cache_clear(void);
/// Files parsed by mesh_load so far (cache misses), for tests.
unsigned long long mesh_cache_parses(void);

/// Coplanar triangles of a static collision mesh merged without changing the
/// surface: vertices inside a flat face, or on a straight crease or border,
/// are collapsed onto a neighbour when every triangle keeps its original
/// plane within tol_rad [rad] and the removed vertex lies within tol_m [m]
/// of the new triangles (mesh_simplify.c). Corners, curved parts and
/// non-manifold places stay. Returns the triangles removed, or -1 when memory
/// ran out (m unchanged then).
#define MESH_FLAT_TOL_RAD 1e-4
#define MESH_FLAT_TOL_M 1e-5
int mesh_merge_coplanar(mesh_tri* m, double tol_rad, double tol_m);
/// mesh_load, then mesh_merge_coplanar at the MESH_FLAT_ tolerances, the
/// merged mesh cached beside the loaded one (a static trimesh's shape).
int mesh_load_flat(const char* path, double scale, int up, mesh_tri* out, char* err, size_t errsz);

/// Axis-aligned bounds [m].
void mesh_bounds(const mesh_tri* m, double lo[3], double hi[3]);

/// Edges used by other than exactly two triangles in opposite directions
/// (0 for a closed, consistently wound surface).
int mesh_open_edges(const mesh_tri* m);

/// Volume [m^3], centre of mass [m] and the inertia tensor about it per unit
/// density [m^5] (row-major 3x3) of a closed mesh. Returns 0, or -1 if the
/// volume is not positive after orienting (flat or open). Inside-out winding
/// is accepted (the signs flip together).
int mesh_mass_props(const mesh_tri* m, double* volume, double com[3], double I[9]);

/// A convex hull: vertices, and triangles wound counter-clockwise seen from
/// outside with their planes n.x = d (n unit, outward).
typedef struct mesh_hull {
    int nv, nf;
    double* v;      ///< 3 nv [m]
    int* f;         ///< 3 nf
    double* plane;  ///< 4 nf: nx, ny, nz, d
    double tol;     ///< points at most this far outside may be left out [m]
} mesh_hull;

/// Most faces a loose body's hull may have. ODE's convex colliders test
/// every face and edge pair (a 1,000-face hull against a box is about 1e7
/// operations a contact query); a finely tessellated round load is kept under
/// it by the tolerance below, a hull that needs more is refused.
#define MESH_HULL_MAX_FACES 2000
/// The hull's first tolerance, relative to the points' extent: a point less
/// than this above the hull of the others is left out (float coordinates of
/// a flat face scatter by 6e-8 of the size); multiplied by sqrt(10) while the
/// hull has more than MESH_HULL_MAX_FACES faces, up to 1e-2 (100,000 points
/// on a sphere then have about 1,370 faces at 3.2e-3 of the size, in about 2 s).
#define MESH_HULL_TOL_REL 1e-7

/// Hull of the points (quickhull on exact predicates, mesh_geom.c). Returns
/// 0; -1 if the points are flat (no volume), not finite or memory ran out;
/// -2 if even at 1e-2 of the extent the hull has more than
/// MESH_HULL_MAX_FACES faces; -3 if mesh_cancelled() said stop.
int mesh_hull_build(const double* pts, int n, mesh_hull* h);
void mesh_hull_free(mesh_hull* h);

#ifdef __cplusplus
}
#endif
#endif
