// mesh_simplify.c: lossless merging of coplanar triangles for collision
// meshes (docs/ode_world.md, "CAD meshes": "Flat faces merged").
//
// CAD and scan exports often cut a flat face into thousands of triangles.
// ODE's box-trimesh collider tests every triangle the box's OBB overlaps
// (OPCODE's tree query, a separating-axis test, clipping and a contact per
// triangle), so a finely cut wall costs in proportion to its cells while the
// same wall as 12 triangles costs what a box does. This removes the vertices
// that carry no shape, by half-edge collapses (the vertex moves onto a
// neighbour, as in Garland and Heckbert's simplification, but only where the
// surface does not change):
//   * a vertex whose triangles all lie in one plane, inside that face;
//   * a vertex on a straight crease between two planes, or on a straight open
//     border of one plane, collapsed along that line.
// A collapse is taken only if no triangle flips or degenerates, each new
// triangle keeps the orientation of the original triangle it came from
// within MESH_FLAT_TOL_RAD, the removed vertex lies within MESH_FLAT_TOL_M of
// every new triangle's plane, and the mesh stays manifold (the link
// condition: the two vertices share no neighbours but the triangles on their
// edge). Corners, curved surfaces and anything non-manifold stay as they are.
#include "mesh_geom.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct vfan {
    int* f; // faces that use the vertex (dead ones dropped lazily)
    int n, cap;
} vfan;

typedef struct simp {
    const float* v;
    int* idx;           // 3 per face
    unsigned char* dead;
    double* n0;         // 3 per face: unit normal of the original triangle
    vfan* fan;
    int* mark;          // per vertex: stamp of the last neighbour scan
    int* mark2;
    int* slot;          // per vertex: its place in nb while mark is current
    int stamp;
    // scratch for one vertex
    int* nb;            // neighbours
    int* nbc;           // faces on the edge to each neighbour
    int* nbcl;          // bit 0/1: clusters of those faces
    int scap;
} simp;

static void tri_normal(const float* v, const int* t, double n[3], double* len) {
    const float* a = v + 3 * t[0];
    const float* b = v + 3 * t[1];
    const float* c = v + 3 * t[2];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = u[1] * w[2] - u[2] * w[1];
    n[1] = u[2] * w[0] - u[0] * w[2];
    n[2] = u[0] * w[1] - u[1] * w[0];
    const double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    *len = l;
    if (l > 0)
        for (int k = 0; k < 3; ++k) n[k] /= l;
}

static double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static int fan_push(vfan* f, int face) {
    if (f->n == f->cap) {
        const int cap = f->cap ? 2 * f->cap : 8;
        int* p = realloc(f->f, (size_t)cap * sizeof *p);
        if (!p) return -1;
        f->f = p;
        f->cap = cap;
    }
    f->f[f->n++] = face;
    return 0;
}

// Drop dead faces from v's fan.
static void fan_compact(simp* s, int v) {
    vfan* f = &s->fan[v];
    int k = 0;
    for (int i = 0; i < f->n; ++i)
        if (!s->dead[f->f[i]]) f->f[k++] = f->f[i];
    f->n = k;
}

static int scratch(simp* s, int n) {
    if (n <= s->scap) return 0;
    const int cap = 2 * n;
    int* a = realloc(s->nb, (size_t)cap * sizeof *a);
    if (a) s->nb = a;
    int* b = realloc(s->nbc, (size_t)cap * sizeof *b);
    if (b) s->nbc = b;
    int* c = realloc(s->nbcl, (size_t)cap * sizeof *c);
    if (c) s->nbcl = c;
    if (!a || !b || !c) return -1;
    s->scap = cap;
    return 0;
}

// Position in face t of vertex v (0..2), or -1.
static int corner(const int* t, int v) { return t[0] == v ? 0 : t[1] == v ? 1 : t[2] == v ? 2 : -1; }

// Try the collapse of v onto u; 1 if taken.
static int try_collapse(simp* s, int v, int u, double cos_tol, double tol_m) {
    const vfan* fv = &s->fan[v];
    const float* pv = s->v + 3 * v;
    // Every triangle of v that does not hold u, with v moved to u.
    for (int i = 0; i < fv->n; ++i) {
        const int f = fv->f[i];
        const int* t = s->idx + 3 * f;
        if (corner(t, u) >= 0) continue;
        int nt[3] = {t[0], t[1], t[2]};
        nt[corner(t, v)] = u;
        double n[3], len;
        tri_normal(s->v, nt, n, &len);
        // Degenerate (relative to the triangle's size) or turned away from
        // the original triangle's plane: the surface would change.
        double e2 = 0;
        for (int k = 0; k < 3; ++k) {
            const float* a = s->v + 3 * nt[k];
            const float* b = s->v + 3 * nt[(k + 1) % 3];
            const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            const double l2 = dot3(d, d);
            if (l2 > e2) e2 = l2;
        }
        if (!(len > 1e-6 * e2) || dot3(n, s->n0 + 3 * f) < cos_tol) return 0;
        const float* pu = s->v + 3 * u;
        const double d[3] = {pv[0] - pu[0], pv[1] - pu[1], pv[2] - pu[2]};
        if (fabs(dot3(n, d)) > tol_m) return 0;
    }
    // Link condition: the neighbours u and v share are exactly the third
    // corners of the triangles on edge uv (else the collapse would fold the
    // surface onto itself or make an edge of three triangles).
    const int st = ++s->stamp;
    int opp = 0;
    for (int i = 0; i < fv->n; ++i) {
        const int* t = s->idx + 3 * s->fan[v].f[i];
        for (int k = 0; k < 3; ++k) s->mark[t[k]] = st;
        if (corner(t, u) >= 0) ++opp;
    }
    fan_compact(s, u);
    const vfan* fu = &s->fan[u];
    int shared = 0;
    for (int i = 0; i < fu->n; ++i) {
        const int* t = s->idx + 3 * fu->f[i];
        for (int k = 0; k < 3; ++k) {
            const int x = t[k];
            if (x == u || x == v || s->mark[x] != st || s->mark2[x] == st) continue;
            s->mark2[x] = st;
            ++shared;
        }
    }
    if (shared != opp) return 0;
    // Take it.
    for (int i = 0; i < fv->n; ++i) {
        const int f = fv->f[i];
        int* t = s->idx + 3 * f;
        if (corner(t, u) >= 0) {
            s->dead[f] = 1;
            continue;
        }
        t[corner(t, v)] = u;
        if (fan_push(&s->fan[u], f)) return -1;
    }
    s->fan[v].n = 0;
    return 1;
}

// Try to remove vertex v; 1 if removed, 0 if not, -1 out of memory.
static int try_remove(simp* s, int v, double cos_tol, double tol_m) {
    fan_compact(s, v);
    const vfan* fv = &s->fan[v];
    if (fv->n == 0) return 0;
    // Planes: up to two normal clusters.
    double c0[3], c1[3];
    int ncl = 0;
    memcpy(c0, s->n0 + 3 * fv->f[0], sizeof c0);
    ncl = 1;
    if (scratch(s, 2 * fv->n + 2)) return -1;
    int nnb = 0;
    const int st = ++s->stamp; // mark[x] == st: x is s->nb[slot[x]]
    for (int i = 0; i < fv->n; ++i) {
        const int f = fv->f[i];
        const double* n = s->n0 + 3 * f;
        int cl;
        if (dot3(n, c0) >= cos_tol) cl = 0;
        else if (ncl == 2 && dot3(n, c1) >= cos_tol) cl = 1;
        else if (ncl == 1) {
            memcpy(c1, n, sizeof c1);
            ncl = 2;
            cl = 1;
        } else return 0; // a third plane: a corner
        const int* t = s->idx + 3 * f;
        for (int k = 0; k < 3; ++k) {
            const int x = t[k];
            if (x == v) continue;
            int j;
            if (s->mark[x] == st) j = s->slot[x];
            else {
                s->mark[x] = st;
                j = s->slot[x] = nnb;
                s->nb[nnb] = x;
                s->nbc[nnb] = 0;
                s->nbcl[nnb] = 0;
                ++nnb;
            }
            ++s->nbc[j];
            s->nbcl[j] |= 1 << cl;
        }
    }
    // Feature edges: open (one triangle) or between the two planes.
    int feat[2], nfeat = 0, nopen = 0;
    for (int j = 0; j < nnb; ++j) {
        if (s->nbc[j] > 2) return 0; // non-manifold
        const int open = s->nbc[j] == 1, crease = s->nbc[j] == 2 && s->nbcl[j] == 3;
        if (open) ++nopen;
        if (open || crease) {
            if (nfeat == 2) return 0;
            feat[nfeat++] = j;
        }
    }
    // One disc around v: as many neighbours as triangles (closed), or one
    // more with two open edges (on a border).
    if (!((nopen == 0 && nnb == fv->n) || (nopen == 2 && nnb == fv->n + 1))) return 0;
    if (ncl == 2 && (nopen || nfeat != 2)) return 0;
    if (nfeat == 1) return 0;
    if (nfeat == 2) {
        // On a line: v between its two feature neighbours, within tol_m.
        const float* a = s->v + 3 * s->nb[feat[0]];
        const float* b = s->v + 3 * s->nb[feat[1]];
        const float* p = s->v + 3 * v;
        const double pa[3] = {a[0] - p[0], a[1] - p[1], a[2] - p[2]}, pb[3] = {b[0] - p[0], b[1] - p[1], b[2] - p[2]};
        const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double cr[3] = {pa[1] * pb[2] - pa[2] * pb[1], pa[2] * pb[0] - pa[0] * pb[2], pa[0] * pb[1] - pa[1] * pb[0]};
        const double lab = sqrt(dot3(ab, ab));
        if (!(dot3(pa, pb) < 0) || sqrt(dot3(cr, cr)) > tol_m * lab) return 0;
        const int a0 = s->nb[feat[0]], b0 = s->nb[feat[1]];
        for (int k = 0; k < 2; ++k) {
            const int r = try_collapse(s, v, k ? b0 : a0, cos_tol, tol_m);
            if (r) return r;
        }
        return 0;
    }
    // Inside a flat face: the first neighbour that keeps the face valid
    // (try_collapse leaves the neighbour list alone). Picking the neighbour
    // with the smallest fan instead cost 3.6 times the instructions on the
    // 51,104-triangle wall: more vertices had to wait for a later sweep.
    for (int j = 0; j < nnb; ++j) {
        const int r = try_collapse(s, v, s->nb[j], cos_tol, tol_m);
        if (r) return r;
    }
    return 0;
}

int mesh_merge_coplanar(mesh_tri* m, double tol_rad, double tol_m) {
    if (m->nt < 2) return 0;
    const int nv = m->nv, nt = m->nt;
    simp s;
    memset(&s, 0, sizeof s);
    s.v = m->v;
    s.idx = malloc((size_t)3 * nt * sizeof *s.idx);
    s.dead = calloc((size_t)nt, 1);
    s.n0 = malloc((size_t)3 * nt * sizeof *s.n0);
    s.fan = calloc((size_t)nv, sizeof *s.fan);
    s.mark = calloc((size_t)nv, sizeof *s.mark);
    s.mark2 = calloc((size_t)nv, sizeof *s.mark2);
    s.slot = calloc((size_t)nv, sizeof *s.slot);
    int removed = -1;
    int* keep = NULL;
    if (!s.idx || !s.dead || !s.n0 || !s.fan || !s.mark || !s.mark2 || !s.slot) goto done;
    memcpy(s.idx, m->idx, (size_t)3 * nt * sizeof *s.idx);
    for (int f = 0; f < nt; ++f) {
        double len;
        tri_normal(m->v, s.idx + 3 * f, s.n0 + 3 * f, &len);
        if (!(len > 0)) s.dead[f] = 1; // mesh_load drops these; be safe
        else
            for (int k = 0; k < 3; ++k)
                if (fan_push(&s.fan[s.idx[3 * f + k]], f)) goto done;
    }
    const double cos_tol = cos(tol_rad);
    // Sweeps until nothing more goes (a collapse can free a neighbour that
    // an earlier sweep had to keep).
    for (int pass = 0; pass < 8; ++pass) {
        int any = 0;
        for (int v = 0; v < nv; ++v) {
            const int r = try_remove(&s, v, cos_tol, tol_m);
            if (r < 0) goto done;
            any += r;
        }
        if (!any) break;
    }
    // Compact the triangles and the vertices they use.
    keep = malloc((size_t)nv * sizeof *keep);
    if (!keep) goto done;
    for (int i = 0; i < nv; ++i) keep[i] = -1;
    int ntn = 0, nvn = 0;
    for (int f = 0; f < nt; ++f) {
        if (s.dead[f]) continue;
        for (int k = 0; k < 3; ++k) {
            const int x = s.idx[3 * f + k];
            if (keep[x] < 0) keep[x] = nvn++;
        }
        ++ntn;
    }
    // Vertices numbered in the order the triangles first use them.
    float* nvtx = malloc((size_t)3 * (nvn ? nvn : 1) * sizeof *nvtx);
    if (!nvtx) goto done;
    for (int i = 0; i < nv; ++i)
        if (keep[i] >= 0) memcpy(nvtx + 3 * keep[i], m->v + 3 * i, 3 * sizeof *nvtx);
    int t = 0;
    for (int f = 0; f < nt; ++f) {
        if (s.dead[f]) continue;
        for (int k = 0; k < 3; ++k) m->idx[3 * t + k] = keep[s.idx[3 * f + k]];
        ++t;
    }
    free(m->v);
    m->v = nvtx;
    m->nv = nvn;
    removed = nt - ntn;
    m->nt = ntn;
    m->merged += removed;
done:
    free(keep);
    if (s.fan)
        for (int i = 0; i < nv; ++i) free(s.fan[i].f);
    free(s.fan);
    free(s.idx);
    free(s.dead);
    free(s.n0);
    free(s.mark);
    free(s.mark2);
    free(s.slot);
    free(s.nb);
    free(s.nbc);
    free(s.nbcl);
    return removed;
}
