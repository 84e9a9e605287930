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

// ---- convex hull: quickhull on exact predicates --------------------------
//
// The earlier incremental hull decided "point above face" with a tolerance
// in floating point. Points a little off a flat face (a finely cut CAD face
// in float coordinates) were then seen from faces that do not form one
// patch, the hole it cut had more than one border, and the hull grew faces
// without end: 505 points gave 79,151 faces in 13.6 s (issue 25, item 23).
//
// Here every combinatorial decision is exact. The points are snapped to an
// integer grid of 2^26 steps over their extent (a step of 1.5e-8 of the size:
// 15 nm on a 1 m load, below float resolution), so each face's normal
// (b-a)x(c-a) is an exact 64-bit integer vector (|components| < 2^55) and
// "q above the face" is the sign of n.(q-a) in 128-bit integers. On exact
// signs the faces a point sees form one patch with one border, each new face
// is non-degenerate, and the hull of n points has at most 2n - 4 faces
// (Euler). Quickhull (Barber, Dobkin and Huhdanpaa, ACM TOMS 22, 1996):
// every face keeps the points above it; the farthest of them is added, its
// patch replaced by a fan to the border, and the patch's points go to the
// new face they are farthest above, or are dropped (inside).
//
// tol [m]: a face whose farthest point is within tol of its plane drops its
// points, so float noise on a flat face makes no slivers; the hull then may
// leave out points at most tol outside it. mesh_hull_build starts at
// MESH_HULL_TOL_REL of the size and, while the hull has more than
// MESH_HULL_MAX_FACES faces, tries sqrt(10) times that (up to 1e-2 of the size).

#define GRID_STEPS 67108864.0 // 2^26

typedef struct qface {
    int v[3];       // corners, counter-clockwise seen from outside
    int adj[3];     // face across edge (v[k], v[k+1])
    long long ni[3]; // exact normal on the grid
    __int128 di;     // ni . v[0] on the grid
    double n[3], d; // unit outward normal, n.x = d [m]
    int head;       // first point above this face (list through qh.next), -1 none
    int alive, stamp;
} qface;

typedef struct qhull {
    const double* P;
    long long* Q;   // grid points
    int n, nf, cap;
    qface* F;
    int* next;      // per point: the next in its face's list
    double lo[3], step; // grid: x = lo + Q step [m]
    double tol;
} qhull;

static void sub3(const double* a, const double* b, double* o) { o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2]; }
static void cross3(const double* a, const double* b, double* o) {
    o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Sign of (q - a) . n on the grid: > 0 above the face.
static int above(const qhull* h, const qface* f, int q) {
    const long long* x = h->Q + 3 * q;
    const __int128 s = (__int128)f->ni[0] * x[0] + (__int128)f->ni[1] * x[1] + (__int128)f->ni[2] * x[2] - f->di;
    return s > 0;
}

static double dist(const qhull* h, const qface* f, int q) { return dot3(f->n, h->P + 3 * q) - f->d; }

// Face (a, b, c) appended; -1 when out of memory.
static int add_face(qhull* h, int a, int b, int c) {
    if (h->nf == h->cap) {
        const int cap = 2 * h->cap;
        qface* F = realloc(h->F, (size_t)cap * sizeof *F);
        if (!F) return -1;
        h->F = F, h->cap = cap;
    }
    qface* f = &h->F[h->nf];
    memset(f, 0, sizeof *f);
    f->v[0] = a, f->v[1] = b, f->v[2] = c;
    const long long *A = h->Q + 3 * a, *B = h->Q + 3 * b, *C = h->Q + 3 * c;
    const long long u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]}, w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
    f->ni[0] = u[1] * w[2] - u[2] * w[1], f->ni[1] = u[2] * w[0] - u[0] * w[2], f->ni[2] = u[0] * w[1] - u[1] * w[0];
    f->di = (__int128)f->ni[0] * A[0] + (__int128)f->ni[1] * A[1] + (__int128)f->ni[2] * A[2];
    // The plane in metres is the grid plane's, not one through the three
    // points as given: on a sliver (three points almost on a line) the
    // snapping tilts the plane a lot, and a plane through the given points
    // would disagree with the exact decisions (a point 8e-5 of the size
    // above it, found by a stress test). Through the grid point of a, every
    // point is within half a grid diagonal (1.3e-8 of the size) of the
    // exact hull's planes.
    double nn[3], ga[3];
    for (int k = 0; k < 3; ++k) nn[k] = (double)f->ni[k], ga[k] = h->lo[k] + (double)A[k] * h->step;
    const double l = sqrt(dot3(nn, nn));
    if (!(l > 0)) return -1; // cannot happen: the caller's faces are not degenerate on the grid
    for (int k = 0; k < 3; ++k) f->n[k] = nn[k] / l;
    f->d = dot3(f->n, ga);
    f->head = -1;
    f->alive = 1;
    return h->nf++;
}

// Point q to the face among F[from..nf) it is farthest above, or dropped.
static void assign(qhull* h, int q, int from) {
    int best = -1;
    double bd = -INFINITY;
    for (int f = from; f < h->nf; ++f)
        if (h->F[f].alive && above(h, &h->F[f], q)) {
            const double d = dist(h, &h->F[f], q);
            if (d > bd) bd = d, best = f;
        }
    if (best >= 0) h->next[q] = h->F[best].head, h->F[best].head = q;
}

// One hull at tolerance tol; 0, -1 out of memory, -2 more than max_faces,
// -3 cancelled.
static int quickhull(qhull* h, const int i4[4], int max_faces) {
    h->nf = 0;
    const int tet[4][3] = {{i4[0], i4[1], i4[2]}, {i4[0], i4[3], i4[1]}, {i4[1], i4[3], i4[2]}, {i4[0], i4[2], i4[3]}};
    for (int t = 0; t < 4; ++t)
        if (add_face(h, tet[t][0], tet[t][1], tet[t][2]) < 0) return -1;
    // Orient the tetrahedron outward: its fourth corner below the first face.
    if (above(h, &h->F[0], i4[3])) {
        h->nf = 0;
        for (int t = 0; t < 4; ++t)
            if (add_face(h, tet[t][0], tet[t][2], tet[t][1]) < 0) return -1;
    }
    // Neighbours: the face sharing each edge reversed.
    for (int f = 0; f < 4; ++f)
        for (int k = 0; k < 3; ++k) {
            const int a = h->F[f].v[k], b = h->F[f].v[(k + 1) % 3];
            for (int g = 0; g < 4; ++g)
                for (int j = 0; j < 3; ++j)
                    if (g != f && h->F[g].v[j] == b && h->F[g].v[(j + 1) % 3] == a) h->F[f].adj[k] = g;
        }
    for (int q = 0; q < h->n; ++q) {
        if (q % 65536 == 65535 && mesh_cancelled()) return -3;
        if (q != i4[0] && q != i4[1] && q != i4[2] && q != i4[3]) assign(h, q, 0);
    }
    int alive = 4, stamp = 0;
    int *stack = NULL, *vis = NULL, *hor = NULL;
    int scap = 0, vcap = 0, hcap = 0, rc = 0;
#define PUSH(arr, n, cap, x)                                                   \
    do {                                                                       \
        if ((n) == (cap)) {                                                    \
            const int c2_ = (cap) ? 2 * (cap) : 64;                            \
            int* a2_ = realloc((arr), (size_t)c2_ * sizeof *a2_);              \
            if (!a2_) { rc = -1; goto done; }                                  \
            (arr) = a2_, (cap) = c2_;                                          \
        }                                                                      \
        (arr)[(n)++] = (x);                                                    \
    } while (0)
    int again = 1;
rescan:
    while (again) {
    again = 0;
    for (int cur = 0; cur < h->nf; ++cur) {
        if (!h->F[cur].alive || h->F[cur].head < 0) continue;
        if (mesh_cancelled()) { rc = -3; goto done; }
        // The farthest point above this face.
        int p = -1;
        double pd = -INFINITY;
        for (int q = h->F[cur].head; q >= 0; q = h->next[q]) {
            const double d = dist(h, &h->F[cur], q);
            if (d > pd) pd = d, p = q;
        }
        if (pd <= h->tol) {
            // Within tol of this face: dropped, unless the point is farther
            // above another face (the faces a point is above form one patch
            // with this one; near a crease it may be above a neighbour by
            // more). Then it goes there, and the scan runs again if that
            // face is behind it.
            int q = h->F[cur].head, nx;
            h->F[cur].head = -1;
            for (; q >= 0; q = nx) {
                nx = h->next[q];
                ++stamp;
                int nst = 0, best = -1;
                double bd = h->tol;
                h->F[cur].stamp = stamp;
                PUSH(stack, nst, scap, cur);
                while (nst) {
                    const int f = stack[--nst];
                    const double d = dist(h, &h->F[f], q);
                    if (d > bd) bd = d, best = f;
                    for (int k = 0; k < 3; ++k) {
                        const int g = h->F[f].adj[k];
                        if (h->F[g].stamp != stamp && above(h, &h->F[g], q)) {
                            h->F[g].stamp = stamp;
                            PUSH(stack, nst, scap, g);
                        }
                    }
                }
                if (best >= 0 && best != cur) {
                    h->next[q] = h->F[best].head, h->F[best].head = q;
                    if (best < cur) again = 1;
                }
            }
            continue;
        }
        // The patch p sees: faces reached through faces p is above (exact).
        ++stamp;
        int nvis = 0, sp = 0;
        h->F[cur].stamp = stamp;
        PUSH(stack, sp, scap, cur);
        while (sp) {
            const int f = stack[--sp];
            PUSH(vis, nvis, vcap, f);
            for (int k = 0; k < 3; ++k) {
                const int g = h->F[f].adj[k];
                if (h->F[g].stamp != stamp && above(h, &h->F[g], p)) {
                    h->F[g].stamp = stamp;
                    PUSH(stack, sp, scap, g);
                }
            }
        }
        // Its border, in order: start at a visible face's edge to an unseen
        // face and walk around the patch (counter-clockwise from outside).
        int nh = 0;
        {
            int f0 = -1, k0 = -1;
            for (int i = 0; i < nvis && f0 < 0; ++i)
                for (int k = 0; k < 3; ++k)
                    if (h->F[h->F[vis[i]].adj[k]].stamp != stamp) {
                        f0 = vis[i], k0 = k;
                        break;
                    }
            int f = f0, k = k0;
            do {
                PUSH(hor, nh, hcap, f);
                PUSH(hor, nh, hcap, k);
                // Next border edge: from the end vertex of (f, k), turn
                // around that vertex through visible faces.
                int kk = (k + 1) % 3;
                for (;;) {
                    const int g = h->F[f].adj[kk];
                    if (h->F[g].stamp != stamp) break;
                    // Enter g through the edge it shares with f; its next edge
                    // around the shared vertex.
                    int j = 0;
                    while (j < 3 && h->F[g].adj[j] != f) ++j;
                    if (j == 3) { rc = -1; goto done; } // cannot happen on exact signs
                    f = g, kk = (j + 1) % 3;
                }
                k = kk;
                if (nh > 2 * 3 * nvis + 6) { rc = -1; goto done; } // cannot happen on exact signs
            } while (!(f == f0 && k == k0));
            nh /= 2;
        }
        // Fan from p over the border.
        const int first = h->nf;
        for (int e = 0; e < nh; ++e) {
            const qface* fv = &h->F[hor[2 * e]];
            const int k = hor[2 * e + 1];
            const int a = fv->v[k], b = fv->v[(k + 1) % 3], out = fv->adj[k];
            const int nf = add_face(h, a, b, p);
            if (nf < 0) { rc = -1; goto done; }
            h->F[nf].adj[0] = out;
            for (int j = 0; j < 3; ++j)
                if (h->F[out].v[j] == b && h->F[out].v[(j + 1) % 3] == a) h->F[out].adj[j] = nf;
        }
        for (int e = 0; e < nh; ++e) {
            const int f = first + e, g = first + (e + 1) % nh;
            h->F[f].adj[1] = g; // edge (b, p) of this face is (p, a) of the next
            h->F[g].adj[2] = f;
        }
        // The patch goes; its points to the new faces.
        for (int i = 0; i < nvis; ++i) h->F[vis[i]].alive = 0;
        alive += nh - nvis;
        for (int i = 0; i < nvis; ++i)
            for (int q = h->F[vis[i]].head, nx; q >= 0; q = nx) {
                nx = h->next[q];
                if (q != p) assign(h, q, first);
            }
        if (alive > max_faces) { rc = -2; goto done; }
    }
    }
    // Points were dropped by their distance to the planes of the hull so far;
    // a point just off a sharp edge may be farther from a plane the hull
    // gets later. Every point is checked against the final planes; one more
    // than tol above a face goes back to it, and the scan runs again. The
    // hull only grows, so this ends. O(n f): 0.1 s for 100,000 points and
    // 1,400 faces.
    for (int q = 0; q < h->n; ++q) {
        if (q % 4096 == 4095 && mesh_cancelled()) { rc = -3; goto done; }
        int best = -1;
        double bd = h->tol;
        for (int f = 0; f < h->nf; ++f)
            if (h->F[f].alive) {
                const double d = dist(h, &h->F[f], q);
                if (d > bd && above(h, &h->F[f], q)) bd = d, best = f;
            }
        if (best >= 0) {
            h->next[q] = h->F[best].head, h->F[best].head = q;
            again = 1;
        }
    }
    if (again) goto rescan;
#undef PUSH
done:
    free(stack);
    free(vis);
    free(hor);
    return rc;
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
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            if (!isfinite(P[3 * i + k])) return -1;
            if (P[3 * i + k] < lo[k]) lo[k] = P[3 * i + k];
            if (P[3 * i + k] > hi[k]) hi[k] = P[3 * i + k];
        }
    const double size = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    if (!(size > 0)) return -1;
    const double step = size / GRID_STEPS;
    qhull q = {.P = P, .n = n, .lo = {lo[0], lo[1], lo[2]}, .step = step};
    q.Q = malloc((size_t)3 * n * sizeof *q.Q);
    q.next = malloc((size_t)n * sizeof *q.next);
    q.cap = 64;
    q.F = malloc((size_t)q.cap * sizeof *q.F);
    int rc = -1;
    if (!q.Q || !q.next || !q.F) goto out;
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) q.Q[3 * i + k] = llround((P[3 * i + k] - lo[k]) / step);
    // A first tetrahedron of far-apart points: the lowest x, the farthest
    // from it, the farthest from their line, the farthest from their plane
    // (a later point replaces an earlier one only if it is farther by more
    // than the first tolerance: float noise does not pick a point just off a
    // corner). Thinner than 1e-6 of the size counts as flat (no volume).
    const double flat = 1e-6 * size, tie = MESH_HULL_TOL_REL * size;
    int i4[4] = {0, -1, -1, -1};
    for (int i = 1; i < n; ++i)
        if (P[3 * i] < P[3 * i4[0]] - tie) i4[0] = i;
    double best = -1, u[3], v[3], nrm[3];
    for (int i = 0; i < n; ++i) {
        double d[3];
        sub3(P + 3 * i, P + 3 * i4[0], d);
        if (sqrt(dot3(d, d)) > best + tie) best = sqrt(dot3(d, d)), i4[1] = i;
    }
    if (i4[1] < 0 || best < flat) goto out;
    sub3(P + 3 * i4[1], P + 3 * i4[0], u);
    const double ul = sqrt(dot3(u, u));
    best = -1;
    for (int i = 0; i < n; ++i) {
        double d[3], c[3];
        sub3(P + 3 * i, P + 3 * i4[0], d);
        cross3(u, d, c);
        const double s = sqrt(dot3(c, c)) / ul;
        if (s > best + tie) best = s, i4[2] = i;
    }
    if (i4[2] < 0 || best < flat) goto out;
    sub3(P + 3 * i4[2], P + 3 * i4[0], v);
    cross3(u, v, nrm);
    const double nl = sqrt(dot3(nrm, nrm));
    best = -1;
    for (int i = 0; i < n; ++i) {
        double d[3];
        sub3(P + 3 * i, P + 3 * i4[0], d);
        const double s = fabs(dot3(d, nrm)) / nl;
        if (s > best + tie) best = s, i4[3] = i;
    }
    if (i4[3] < 0 || best < flat) goto out; // flat: no volume
    rc = -2;
    for (double rel = MESH_HULL_TOL_REL; rc == -2 && rel <= 1.001e-2; rel *= 3.1622776601683795) {
        q.tol = rel * size;
        rc = quickhull(&q, i4, MESH_HULL_MAX_FACES);
    }
    if (rc) goto out;
    // The live faces, and the vertices they use, compacted.
    int nf = 0;
    for (int f = 0; f < q.nf; ++f) nf += q.F[f].alive;
    int* map = malloc((size_t)n * sizeof *map);
    h->v = malloc((size_t)3 * n * sizeof *h->v);
    h->f = malloc((size_t)3 * nf * sizeof *h->f);
    h->plane = malloc((size_t)4 * nf * sizeof *h->plane);
    if (!map || !h->v || !h->f || !h->plane) {
        free(map);
        mesh_hull_free(h);
        rc = -1;
        goto out;
    }
    for (int i = 0; i < n; ++i) map[i] = -1;
    for (int f = 0; f < q.nf; ++f) {
        const qface* F = &q.F[f];
        if (!F->alive) continue;
        for (int k = 0; k < 3; ++k) {
            if (map[F->v[k]] < 0) {
                map[F->v[k]] = h->nv;
                memcpy(h->v + 3 * h->nv++, P + 3 * F->v[k], 3 * sizeof(double));
            }
            h->f[3 * h->nf + k] = map[F->v[k]];
        }
        memcpy(h->plane + 4 * h->nf, F->n, 3 * sizeof(double));
        h->plane[4 * h->nf + 3] = F->d;
        ++h->nf;
    }
    h->tol = q.tol;
    free(map);
out:
    free(q.Q);
    free(q.next);
    free(q.F);
    return rc;
}
