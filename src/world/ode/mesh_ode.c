// mesh_ode.c: CAD meshes as ODE geoms: static triangle meshes for fixed
// obstacles and terrain, convex hulls with the closed mesh's mass properties
// for loose bodies (docs/ode_world.md, "CAD meshes").
#include "ode_world_internal.h"
#include "mesh_geom.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* coll_path(const world_obj_mesh* om) { return om->collision[0] ? om->collision : om->file; }

static ow_mesh* new_mesh(ode_world* w, char* err, size_t errsz) {
    if (w->nmesh >= OW_MAX_MESHES) {
        snprintf(err, errsz, "ode world: more than %d meshes", OW_MAX_MESHES);
        return NULL;
    }
    ow_mesh* m = &w->mesh[w->nmesh++];
    memset(m, 0, sizeof *m);
    return m;
}

dGeomID ow_mesh_trimesh(ode_world* w, dSpaceID space, const world_obj_mesh* om, const double pos[3],
                        const double R[9], char* err, size_t errsz) {
    mesh_tri t;
    char why[256];
    // A fixed mesh only collides: its flat faces merged leave the surface as
    // it is and spare ODE a test per cell of a finely cut face (a 51,104-
    // triangle wall cost 1.6 times the box, docs/ode_world.md).
    if (mesh_load_flat(coll_path(om), om->scale, om->up, &t, why, sizeof why)) {
        snprintf(err, errsz, "%s: %s", coll_path(om), why);
        return NULL;
    }
    ow_mesh* m = new_mesh(w, err, errsz);
    if (!m) {
        mesh_free(&t);
        return NULL;
    }
    m->nt_file = t.nt + t.merged;
    m->nt_merged = t.merged;
    m->v = t.v;
    m->nv = t.nv;
    m->nt = t.nt;
    m->idx = malloc((size_t)3 * t.nt * sizeof *m->idx);
    if (!m->idx) {
        free(t.idx);
        w->nmesh--;
        free(m->v);
        snprintf(err, errsz, "ode world: out of memory (mesh %s)", coll_path(om));
        return NULL;
    }
    for (int i = 0; i < 3 * t.nt; ++i) m->idx[i] = (dTriIndex)t.idx[i];
    m->di = t.idx; // kept for the debug view
    m->dv = malloc((size_t)3 * (t.nv ? t.nv : 1) * sizeof *m->dv);
    if (m->dv) memcpy(m->dv, t.v, (size_t)3 * t.nv * sizeof *m->dv);
    m->tmd = dGeomTriMeshDataCreate();
    dGeomTriMeshDataBuildSingle(m->tmd, m->v, 3 * sizeof(float), m->nv, m->idx, 3 * m->nt, 3 * sizeof(dTriIndex));
    // Face angles are what ODE's convex-vs-trimesh collider needs (without
    // them it aborts on the first hull touching the mesh); concave edges
    // keep box and sphere contacts off the mesh's inner edges.
    dGeomTriMeshDataPreprocess2(m->tmd,
                                (1U << dTRIDATAPREPROCESS_BUILD_CONCAVE_EDGES) |
                                    (1U << dTRIDATAPREPROCESS_BUILD_FACE_ANGLES),
                                NULL);
    dGeomID g = dCreateTriMesh(space, m->tmd, NULL, NULL, NULL);
    // Temporal coherence (dGeomTriMeshEnableTC) stays off: it gained 3 % at
    // most on the 50,000-triangle bench (within the noise), and ODE 0.16.2
    // does not free its OPCODE caches (LeakSanitizer, docs/performance.md).
    dGeomSetPosition(g, pos[0], pos[1], pos[2]);
    dMatrix3 M;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) M[4 * i + j] = R[3 * i + j];
        M[4 * i + 3] = 0;
    }
    dGeomSetRotation(g, M);
    return g;
}

dGeomID ow_mesh_hull(ode_world* w, dSpaceID space, const world_obj_mesh* om, double mass, dMass* dm, char* err,
                     size_t errsz) {
    mesh_tri t;
    char why[256];
    if (mesh_load(coll_path(om), om->scale, om->up, &t, why, sizeof why)) {
        snprintf(err, errsz, "%s: %s", coll_path(om), why);
        return NULL;
    }
    double V, c[3], I[9];
    if (mesh_mass_props(&t, &V, c, I)) {
        mesh_free(&t);
        snprintf(err, errsz, "%s: the mesh encloses no volume", coll_path(om));
        return NULL;
    }
    double* p = malloc((size_t)3 * (t.nv ? t.nv : 1) * sizeof *p);
    if (!p) {
        mesh_free(&t);
        snprintf(err, errsz, "ode world: out of memory (mesh %s)", coll_path(om));
        return NULL;
    }
    // Body frame: the object frame moved to the centre of mass (ODE bodies
    // have their origin there).
    for (int i = 0; i < t.nv; ++i)
        for (int k = 0; k < 3; ++k) p[3 * i + k] = t.v[3 * i + k] - c[k];
    const int nv = t.nv;
    mesh_free(&t);
    mesh_hull h;
    int rc = mesh_hull_build(p, nv, &h);
    free(p);
    if (rc == -3) {
        snprintf(err, errsz, "%s: interrupted while building its convex hull", coll_path(om));
        return NULL;
    }
    if (rc == -2) {
        snprintf(err, errsz,
                 "%s: the convex hull of its %d vertices needs more than %d faces even within 1 %% of its size; give "
                 "a simpler \"collision\" mesh",
                 coll_path(om), nv, MESH_HULL_MAX_FACES);
        return NULL;
    }
    if (rc) {
        snprintf(err, errsz, "%s: the mesh is flat: its convex hull has no volume", coll_path(om));
        return NULL;
    }
    ow_mesh* m = new_mesh(w, err, errsz);
    if (!m) {
        mesh_hull_free(&h);
        return NULL;
    }
    m->planes = malloc((size_t)4 * h.nf * sizeof *m->planes);
    m->points = malloc((size_t)3 * h.nv * sizeof *m->points);
    m->polys = malloc((size_t)4 * h.nf * sizeof *m->polys);
    if (!m->planes || !m->points || !m->polys) {
        mesh_hull_free(&h);
        snprintf(err, errsz, "ode world: out of memory (mesh %s)", coll_path(om));
        return NULL;
    }
    m->dv = malloc((size_t)3 * h.nv * sizeof *m->dv);
    m->di = malloc((size_t)3 * h.nf * sizeof *m->di);
    if (m->dv)
        for (int i = 0; i < 3 * h.nv; ++i) m->dv[i] = (float)h.v[i];
    if (m->di) memcpy(m->di, h.f, (size_t)3 * h.nf * sizeof *m->di);
    for (int i = 0; i < 4 * h.nf; ++i) m->planes[i] = h.plane[i];
    for (int i = 0; i < 3 * h.nv; ++i) m->points[i] = h.v[i];
    for (int f = 0; f < h.nf; ++f) {
        m->polys[4 * f] = 3;
        for (int k = 0; k < 3; ++k) m->polys[4 * f + 1 + k] = (unsigned)h.f[3 * f + k];
    }
    m->nv = h.nv;
    m->nt = h.nf;
    mesh_hull_free(&h);
    // Inertia per unit density times the density mass / V.
    const double rho = mass / V;
    dMassSetParameters(dm, mass, 0, 0, 0, rho * I[0], rho * I[4], rho * I[8], rho * I[1], rho * I[2], rho * I[5]);
    return dCreateConvex(space, m->planes, (unsigned)m->nt, m->points, (unsigned)m->nv, m->polys);
}

void ow_mesh_destroy_data(ode_world* w) {
    for (int i = 0; i < w->nmesh; ++i)
        if (w->mesh[i].tmd) {
            dGeomTriMeshDataDestroy(w->mesh[i].tmd);
            w->mesh[i].tmd = 0;
        }
}

void ow_mesh_free(ode_world* w) {
    for (int i = 0; i < w->nmesh; ++i) {
        ow_mesh* m = &w->mesh[i];
        free(m->v);
        free(m->idx);
        free(m->planes);
        free(m->points);
        free(m->polys);
        free(m->dv);
        free(m->di);
        memset(m, 0, sizeof *m);
    }
    w->nmesh = 0;
}

void ow_collision_snapshot(const ode_world* w, world_snapshot* s) {
    int n = 0;
    for (int i = 0; i < w->ngeom && n < WORLD_SNAP_MAX_COLL; ++i) {
        const ow_geom* e = &w->geom[i];
        world_snap_coll* c = &s->coll[n];
        memset(c, 0, sizeof *c);
        const int cls = dGeomGetClass(e->g);
        dVector3 v;
        dReal r, l;
        switch (cls) {
        case dBoxClass:
            c->shape = WORLD_SHAPE_BOX;
            dGeomBoxGetLengths(e->g, v);
            c->size[0] = v[0], c->size[1] = v[1], c->size[2] = v[2];
            break;
        case dSphereClass:
            c->shape = WORLD_SHAPE_SPHERE;
            c->size[0] = dGeomSphereGetRadius(e->g);
            break;
        case dCapsuleClass:
            c->shape = WORLD_SHAPE_CAPSULE;
            dGeomCapsuleGetParams(e->g, &r, &l);
            c->size[0] = r, c->size[1] = l;
            break;
        case dCylinderClass:
            c->shape = WORLD_SHAPE_CYLINDER;
            dGeomCylinderGetParams(e->g, &r, &l);
            c->size[0] = r, c->size[1] = l;
            break;
        case dTriMeshClass:
        case dConvexClass: {
            if (e->mesh < 0 || !w->mesh[e->mesh].dv || !w->mesh[e->mesh].di) continue;
            const ow_mesh* m = &w->mesh[e->mesh];
            c->shape = WORLD_SHAPE_TERRAIN;
            c->v = m->dv, c->idx = m->di, c->nv = m->nv, c->nt = m->nt;
            break;
        }
        default:
            continue; // the heightfield is drawn as the terrain already
        }
        const dReal* p = dGeomGetPosition(e->g);
        const dReal* R = dGeomGetRotation(e->g);
        for (int k = 0; k < 3; ++k) {
            c->pos[k] = p[k];
            for (int j = 0; j < 3; ++j) c->rot[3 * k + j] = R[4 * k + j];
        }
        ++n;
    }
    s->ncoll = n;
}

int ow_mesh_merge_contacts(dContactGeom* c, int n, double radius) {
    // Deepest first, so each cluster keeps its deepest point.
    for (int i = 0; i < n; ++i) {
        int b = i;
        for (int j = i + 1; j < n; ++j)
            if (c[j].depth > c[b].depth) b = j;
        if (b != i) {
            const dContactGeom t = c[i];
            c[i] = c[b];
            c[b] = t;
        }
    }
    int keep = 0;
    for (int i = 0; i < n; ++i) {
        int dup = 0;
        for (int k = 0; k < keep && !dup; ++k) {
            const double dx = c[i].pos[0] - c[k].pos[0], dy = c[i].pos[1] - c[k].pos[1], dz = c[i].pos[2] - c[k].pos[2];
            const double dot = c[i].normal[0] * c[k].normal[0] + c[i].normal[1] * c[k].normal[1] +
                               c[i].normal[2] * c[k].normal[2];
            dup = dx * dx + dy * dy + dz * dz < radius * radius && dot > 0.9;
        }
        if (!dup) c[keep++] = c[i];
    }
    return keep;
}
