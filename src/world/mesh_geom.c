// mesh_geom.c: closedness, mass properties and convex hulls of meshes.
//
// Mass properties by the divergence theorem: the solid is the signed sum of
// the tetrahedra (r0, a, b, c) over its surface triangles, r0 the mean of the
// vertices (near the solid, so the sums do not cancel large numbers). For a
// tetrahedron (0, a, b, c) of signed volume V = a.(b x c)/6 the first moment
// is V (a+b+c)/4 and the second moment
//   int x x^T dV = V/20 (a a^T + b b^T + c c^T + s s^T),  s = a+b+c
// (Tonon, "Explicit exact formulas for the 3-D tetrahedron inertia tensor in
// terms of its vertex coordinates", J. Math. Stat. 1 (2005); the same sums as
// Mirtich's and Eberly's polyhedral mass property papers).
#include "mesh_geom.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int cmp_u64(const void* a, const void* b) {
    const uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
    return x < y ? -1 : x > y;
}

int mesh_open_edges(const mesh_tri* m) {
    const size_t ne = 3 * (size_t)m->nt;
    uint64_t* e = malloc((ne ? ne : 1) * sizeof *e);
    if (!e) return m->nt ? m->nt : 1;
    // Key: lower index, higher index, and one bit for the direction.
    for (int t = 0; t < m->nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = (uint32_t)m->idx[3 * t + k], b = (uint32_t)m->idx[3 * t + (k + 1) % 3];
            const uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
            e[3 * t + k] = ((uint64_t)lo << 33) | ((uint64_t)hi << 1) | (a < b ? 0u : 1u);
        }
    qsort(e, ne, sizeof *e, cmp_u64);
    int open = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && (e[j] >> 1) == (e[i] >> 1)) ++j;
        // Closed and consistently wound: once each way.
        if (!(j - i == 2 && (e[i] & 1) == 0 && (e[i + 1] & 1) == 1)) ++open;
        i = j;
    }
    free(e);
    return open;
}

int mesh_mass_props(const mesh_tri* m, double* volume, double com[3], double I[9]) {
    double r0[3] = {0, 0, 0};
    for (int i = 0; i < m->nv; ++i)
        for (int k = 0; k < 3; ++k) r0[k] += m->v[3 * i + k];
    for (int k = 0; k < 3; ++k) r0[k] /= m->nv > 0 ? m->nv : 1;
    double V = 0, S[3] = {0, 0, 0}, C[9] = {0};
    for (int t = 0; t < m->nt; ++t) {
        double p[3][3];
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) p[j][k] = m->v[3 * m->idx[3 * t + j] + k] - r0[k];
        const double* a = p[0];
        const double* b = p[1];
        const double* c = p[2];
        const double v = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                          a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
        const double s[3] = {a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]};
        V += v;
        for (int k = 0; k < 3; ++k) S[k] += v * s[k] / 4.0;
        for (int r = 0; r < 3; ++r)
            for (int q = 0; q < 3; ++q)
                C[3 * r + q] += v / 20.0 * (a[r] * a[q] + b[r] * b[q] + c[r] * c[q] + s[r] * s[q]);
    }
    // Inside-out winding flips every term's sign together.
    if (V < 0) {
        V = -V;
        for (int k = 0; k < 3; ++k) S[k] = -S[k];
        for (int k = 0; k < 9; ++k) C[k] = -C[k];
    }
    if (!(V > 0) || !isfinite(V)) return -1;
    double g[3];
    for (int k = 0; k < 3; ++k) g[k] = S[k] / V;
    // Second moment about the centre (parallel axis), then I = tr(C) E - C.
    for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) C[3 * r + q] -= V * g[r] * g[q];
    const double tr = C[0] + C[4] + C[8];
    for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) I[3 * r + q] = (r == q ? tr : 0.0) - C[3 * r + q];
    *volume = V;
    for (int k = 0; k < 3; ++k) com[k] = g[k] + r0[k];
    return 0;
}

// ---- convex hull: incremental, O(n f) ---------------------------------------
//
// Start from a tetrahedron of four extreme points; add each further point
// that lies outside: delete the faces it sees and close the hole with a fan
// of new faces from the point to the horizon (the edges between seen and
// unseen faces). eps is relative to the points' extent.

typedef struct hface {
    int a, b, c;
    double n[3], d; // unit outward normal, n.x = d on the plane
    int alive;
} hface;

static void sub3(const double* a, const double* b, double* o) { o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2]; }
static void cross3(const double* a, const double* b, double* o) {
    o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static int set_face(hface* f, const double* P, int a, int b, int c) {
    double e1[3], e2[3], n[3];
    sub3(P + 3 * b, P + 3 * a, e1);
    sub3(P + 3 * c, P + 3 * a, e2);
    cross3(e1, e2, n);
    const double l = sqrt(dot3(n, n));
    if (!(l > 0)) return -1;
    f->a = a, f->b = b, f->c = c;
    for (int k = 0; k < 3; ++k) f->n[k] = n[k] / l;
    f->d = dot3(f->n, P + 3 * a);
    f->alive = 1;
    return 0;
}

void mesh_hull_free(mesh_hull* h) {
    if (!h) return;
    free(h->v);
    free(h->f);
    free(h->plane);
    memset(h, 0, sizeof *h);
}

int mesh_hull_build(const double* P, int n, mesh_hull* h) {
    memset(h, 0, sizeof *h);
    if (n < 4) return -1;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    int i0 = 0;
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            if (P[3 * i + k] < lo[k]) lo[k] = P[3 * i + k];
            if (P[3 * i + k] > hi[k]) hi[k] = P[3 * i + k];
        }
    for (int i = 1; i < n; ++i)
        if (P[3 * i] < P[3 * i0]) i0 = i;
    const double size = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    const double eps = 1e-9 * (size > 0 ? size : 1);
    // Farthest from i0, from the line i0-i1, from the plane i0-i1-i2.
    int i1 = -1, i2 = -1, i3 = -1;
    double best = 0;
    for (int i = 0; i < n; ++i) {
        double d[3];
        sub3(P + 3 * i, P + 3 * i0, d);
        if (dot3(d, d) > best) best = dot3(d, d), i1 = i;
    }
    if (i1 < 0 || sqrt(best) < 1e3 * eps) return -1;
    double u[3];
    sub3(P + 3 * i1, P + 3 * i0, u);
    best = 0;
    for (int i = 0; i < n; ++i) {
        double d[3], c[3];
        sub3(P + 3 * i, P + 3 * i0, d);
        cross3(u, d, c);
        if (dot3(c, c) > best) best = dot3(c, c), i2 = i;
    }
    if (i2 < 0 || sqrt(best) / sqrt(dot3(u, u)) < 1e3 * eps) return -1;
    double v[3], nrm[3];
    sub3(P + 3 * i2, P + 3 * i0, v);
    cross3(u, v, nrm);
    const double nl = sqrt(dot3(nrm, nrm));
    best = 0;
    for (int i = 0; i < n; ++i) {
        double d[3];
        sub3(P + 3 * i, P + 3 * i0, d);
        const double s = fabs(dot3(d, nrm)) / nl;
        if (s > best) best = s, i3 = i;
    }
    if (i3 < 0 || best < 1e3 * eps) return -1; // flat: no volume

    int cap = 64, nf = 0;
    hface* F = malloc((size_t)cap * sizeof *F);
    int ecap = 64;
    int* edges = malloc((size_t)ecap * 2 * sizeof *edges);
    if (!F || !edges) goto fail;
    double centre[3];
    for (int k = 0; k < 3; ++k) centre[k] = 0.25 * (P[3 * i0 + k] + P[3 * i1 + k] + P[3 * i2 + k] + P[3 * i3 + k]);
    const int tet[4][3] = {{i0, i1, i2}, {i0, i1, i3}, {i0, i2, i3}, {i1, i2, i3}};
    for (int t = 0; t < 4; ++t) {
        if (set_face(&F[nf], P, tet[t][0], tet[t][1], tet[t][2])) goto fail;
        if (dot3(F[nf].n, centre) > F[nf].d) set_face(&F[nf], P, tet[t][0], tet[t][2], tet[t][1]);
        ++nf;
    }
    for (int p = 0; p < n; ++p) {
        if (p == i0 || p == i1 || p == i2 || p == i3) continue;
        const double* x = P + 3 * p;
        int seen = 0;
        for (int f = 0; f < nf; ++f)
            if (F[f].alive && dot3(F[f].n, x) - F[f].d > eps) {
                F[f].alive = 2; // seen from p
                ++seen;
            }
        if (!seen) continue;
        // Horizon: a seen face's edge whose reverse is not on a seen face.
        int ne = 0;
        for (int f = 0; f < nf; ++f) {
            if (F[f].alive != 2) continue;
            const int vv[3] = {F[f].a, F[f].b, F[f].c};
            for (int k = 0; k < 3; ++k) {
                const int a = vv[k], b = vv[(k + 1) % 3];
                int shared = 0;
                for (int g = 0; g < nf && !shared; ++g) {
                    if (g == f || F[g].alive != 2) continue;
                    const int w3[3] = {F[g].a, F[g].b, F[g].c};
                    for (int q = 0; q < 3; ++q)
                        if (w3[q] == b && w3[(q + 1) % 3] == a) shared = 1;
                }
                if (shared) continue;
                if (ne == ecap) {
                    ecap *= 2;
                    int* ne2 = realloc(edges, (size_t)ecap * 2 * sizeof *edges);
                    if (!ne2) goto fail;
                    edges = ne2;
                }
                edges[2 * ne] = a, edges[2 * ne + 1] = b;
                ++ne;
            }
        }
        // Remove the seen faces (compacting), then fan the horizon to p.
        int m2 = 0;
        for (int f = 0; f < nf; ++f)
            if (F[f].alive == 1) F[m2++] = F[f];
        nf = m2;
        for (int e = 0; e < ne; ++e) {
            if (nf == cap) {
                cap *= 2;
                hface* F2 = realloc(F, (size_t)cap * sizeof *F);
                if (!F2) goto fail;
                F = F2;
            }
            if (set_face(&F[nf], P, edges[2 * e], edges[2 * e + 1], p) == 0) ++nf;
        }
    }
    // Compact the vertices the faces use.
    int* map = malloc((size_t)n * sizeof *map);
    if (!map) goto fail;
    for (int i = 0; i < n; ++i) map[i] = -1;
    h->v = malloc((size_t)3 * n * sizeof *h->v);
    h->f = malloc((size_t)3 * nf * sizeof *h->f);
    h->plane = malloc((size_t)4 * nf * sizeof *h->plane);
    if (!h->v || !h->f || !h->plane) {
        free(map);
        goto fail;
    }
    for (int f = 0; f < nf; ++f) {
        const int vv[3] = {F[f].a, F[f].b, F[f].c};
        for (int k = 0; k < 3; ++k) {
            if (map[vv[k]] < 0) {
                map[vv[k]] = h->nv;
                memcpy(h->v + 3 * h->nv++, P + 3 * vv[k], 3 * sizeof(double));
            }
            h->f[3 * f + k] = map[vv[k]];
        }
        memcpy(h->plane + 4 * f, F[f].n, 3 * sizeof(double));
        h->plane[4 * f + 3] = F[f].d;
    }
    h->nf = nf;
    free(map);
    free(F);
    free(edges);
    return 0;
fail:
    free(F);
    free(edges);
    mesh_hull_free(h);
    return -1;
}
