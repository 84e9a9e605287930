// fuzz_mesh.c: libFuzzer target for the physics core's own mesh readers
// (mesh_io.c: OBJ, ASCII and binary STL) and what a loose body does with the
// mesh (closedness, mass properties, the convex hull). Each input is written
// to a file and loaded both as .stl and as .obj (the readers pick the format
// by extension), so the shipped OBJ meshes and the STL seeds in
// tests/fuzz/mesh_seeds seed both. A refusal is a correct answer; a crash,
// a sanitizer report, a leak or a hang (libFuzzer's -timeout) is a finding.
#include "mesh_geom.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static void load_one(const char* path, const uint8_t* data, size_t size) {
    FILE* f = fopen(path, "wb");
    if (!f) return;
    const size_t put = fwrite(data, 1, size, f);
    fclose(f);
    if (put != size) return;
    mesh_tri t;
    char err[512];
    if (mesh_load(path, 1.0, (int)(size & 1) + 1, &t, err, sizeof err)) return;
    double lo[3], hi[3];
    mesh_bounds(&t, lo, hi);
    if (mesh_open_edges(&t) == 0) {
        double V, c[3], I[9];
        (void)mesh_mass_props(&t, &V, c, I);
    }
    // The hull of the vertices, as a loose body's collision shape is built.
    double* p = malloc((size_t)3 * (t.nv ? t.nv : 1) * sizeof *p);
    if (p) {
        for (int i = 0; i < 3 * t.nv; ++i) p[i] = t.v[i];
        mesh_hull h;
        if (mesh_hull_build(p, t.nv, &h) == 0) mesh_hull_free(&h);
        free(p);
    }
    mesh_merge_coplanar(&t, MESH_FLAT_TOL_RAD, MESH_FLAT_TOL_M);
    mesh_free(&t);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static char stl[64], obj[64];
    if (!stl[0]) {
        snprintf(stl, sizeof stl, "/tmp/fuzz_mesh_%ld.stl", (long)getpid());
        snprintf(obj, sizeof obj, "/tmp/fuzz_mesh_%ld.obj", (long)getpid());
    }
    load_one(stl, data, size);
    load_one(obj, data, size);
    // Each input is new; the per-process cache would only hold copies.
    mesh_cache_clear();
    return 0;
}
