// chain.c: forward kinematics, point Jacobians, the composite-rigid-body mass
// matrix, recursive Newton-Euler bias forces, forward dynamics and cylinder
// kinematics of a chain of revolute and prismatic joints on a slewing column
// (chain.h, docs/mechanism.md).
//
// Spatial vectors in body coordinates: a motion (w, v) is the angular velocity
// and the velocity of the point at the body origin; a force (n, f) the moment
// about the body origin and the force. The transform from parent to child
// coordinates is (E, r): E turns parent coordinates into child ones, r is the
// child origin in parent coordinates. A body's spatial inertia is (m, h = m c,
// Ib = inertia about the body origin). Each joint's motion subspace S is one
// signed unit axis in child coordinates, so S^T f and I S are one component
// or one column.
#include "chain.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { K_SLEW = 0, K_REV = 1, K_PRIS = 2 };

struct chain {
    int nbody, ndof;
    chain_body_def* def;
    int* parent;         // [nbody]
    int* dof;            // [nbody] DOF index or -1
    int* dof_body;       // [ndof]
    unsigned char* kind; // [nbody] K_*
    unsigned char* anc;  // [nbody * nbody]: anc[i * nbody + k] = 1 if body k is i or an ancestor of i
    double* m;           // [nbody] mass [kg]
    double* h;           // [3 nbody] m c [kg m]
    double* Ib;          // [9 nbody] inertia about the body origin, body axes [kg m^2]
    double* Ep;          // [9 nbody] prismatic: the constant E of the slide's angle
    double* cs0;         // [2 nbody] its cosine and sine
    double g[3];         // gravity [m/s^2], base frame
};

struct chain_ws {
    int nbody, ndof;
    double *q, *qd;       // [ndof] as given to chain_update
    double* qdb;          // [nbody] joint rate (0 when fixed)
    double *E, *r;        // [9 nbody], [3 nbody] parent -> child
    double* cs;           // [2 nbody] cosine and sine of E's angle (erot)
    double *R, *P;        // [9 nbody], [3 nbody] body axes and origin in the base frame
    double *wb, *vb;      // [3 nbody] body velocity in body coordinates (angular, origin)
    double *W, *V;        // [3 nbody] the same in base coordinates
    double* s;            // [3 nbody] joint axis in base coordinates
    double *a, *f;        // [6 nbody] Newton-Euler scratch
    double* Ic;           // [13 nbody] composite inertia: m, h[3], I[9]
    double *M, *L, *tmp;  // [ndof^2], [ndof^2], [ndof]
    double* dinv;         // [ndof] 1 / L_ii
    int factored;         // L holds the Cholesky factor of M
};

/* ---- small 3-vector helpers ---- */

static inline void cross(const double a[3], const double b[3], double o[3]) {
    const double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    o[0] = x, o[1] = y, o[2] = z;
}
static inline double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
// o = A x (A row-major 3x3)
static inline void mv(const double* A, const double x[3], double o[3]) {
    const double a = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
    const double b = A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
    const double c = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
    o[0] = a, o[1] = b, o[2] = c;
}
// o = A^T x
static inline void mtv(const double* A, const double x[3], double o[3]) {
    const double a = A[0] * x[0] + A[3] * x[1] + A[6] * x[2];
    const double b = A[1] * x[0] + A[4] * x[1] + A[7] * x[2];
    const double c = A[2] * x[0] + A[5] * x[1] + A[8] * x[2];
    o[0] = a, o[1] = b, o[2] = c;
}

// Every joint's E is a rotation about one axis: z for the slew (body 0),
// y for the boom-plane joints (a slide's constant angle too). With its
// cosine and sine cs = {c, s}, E x and E^T x take 4 products instead of 9.
static inline void erot(int slew, const double* cs, const double x[3], double o[3]) {
    const double c = cs[0], s = cs[1];
    if (slew) {
        const double a = c * x[0] + s * x[1], b = -s * x[0] + c * x[1];
        o[0] = a, o[1] = b, o[2] = x[2];
    } else {
        const double a = c * x[0] + s * x[2], b = -s * x[0] + c * x[2];
        o[0] = a, o[1] = x[1], o[2] = b;
    }
}
static inline void erot_t(int slew, const double* cs, const double x[3], double o[3]) {
    const double c = cs[0], s = cs[1];
    if (slew) {
        const double a = c * x[0] - s * x[1], b = s * x[0] + c * x[1];
        o[0] = a, o[1] = b, o[2] = x[2];
    } else {
        const double a = c * x[0] - s * x[2], b = s * x[0] + c * x[2];
        o[0] = a, o[1] = x[1], o[2] = b;
    }
}

// E of a boom-plane rotation by al (x towards z, about -y): rows are the
// child's axes in parent coordinates.
static void rot_plane(double al, double* E) {
    const double c = cos(al), s = sin(al);
    E[0] = c, E[1] = 0, E[2] = s;
    E[3] = 0, E[4] = 1, E[5] = 0;
    E[6] = -s, E[7] = 0, E[8] = c;
}

/* ---- description helpers ---- */

void chain_body_init(chain_body_def* b, int parent) {
    memset(b, 0, sizeof *b);
    b->parent = parent;
    b->joint = CHAIN_REVOLUTE;
    b->q_min = -INFINITY;
    b->q_max = INFINITY;
}

void chain_inertia_box(double mass, double lx, double ly, double lz, double I[3][3]) {
    memset(I, 0, 9 * sizeof(double));
    I[0][0] = mass * (ly * ly + lz * lz) / 12.0;
    I[1][1] = mass * (lx * lx + lz * lz) / 12.0;
    I[2][2] = mass * (lx * lx + ly * ly) / 12.0;
}

void chain_inertia_section(double mass, double Iyy, double length, double width, double height, double I[3][3]) {
    chain_inertia_box(mass, length, width, height, I);
    I[1][1] = Iyy;
}

void chain_body_add_point_mass(chain_body_def* b, double m, const double p[3]) {
    const double M = b->mass + m;
    if (!(M > 0)) return;
    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = (b->mass * b->com[k] + m * p[k]) / M;
    // Parallel axis: each mass's offset d from the new centre adds
    // mass (|d|^2 1 - d d^T).
    double d1[3], d2[3];
    for (int k = 0; k < 3; ++k) d1[k] = b->com[k] - c[k], d2[k] = p[k] - c[k];
    const double s1 = dot(d1, d1), s2 = dot(d2, d2);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            b->inertia[i][j] += b->mass * ((i == j) * s1 - d1[i] * d1[j]) + m * ((i == j) * s2 - d2[i] * d2[j]);
    b->mass = M;
    memcpy(b->com, c, sizeof c);
}

/* ---- creation and validation ---- */

static int fail(char* err, size_t errsz, const chain_body_def* b, int i, const char* field, const char* fmt, ...)
    __attribute__((format(printf, 6, 7)));
static int fail(char* err, size_t errsz, const chain_body_def* b, int i, const char* field, const char* fmt, ...) {
    if (!err || !errsz) return -1;
    int n = b && b->name[0] ? snprintf(err, errsz, "bodies[%d] (%.*s).%s: ", i, CHAIN_NAME, b->name, field)
                            : snprintf(err, errsz, "bodies[%d].%s: ", i, field);
    if (n < 0 || (size_t)n >= errsz) return -1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err + n, errsz - (size_t)n, fmt, ap);
    va_end(ap);
    return -1;
}

static int all_finite(const double* x, int n) {
    for (int k = 0; k < n; ++k)
        if (!isfinite(x[k])) return 0;
    return 1;
}

// Eigenvalues of a symmetric 3x3 (the trigonometric closed form).
static void sym_eig3(const double A[3][3], double ev[3]) {
    const double p1 = A[0][1] * A[0][1] + A[0][2] * A[0][2] + A[1][2] * A[1][2];
    const double tr = (A[0][0] + A[1][1] + A[2][2]) / 3.0;
    if (p1 == 0) {
        ev[0] = A[0][0], ev[1] = A[1][1], ev[2] = A[2][2];
        return;
    }
    const double p2 = (A[0][0] - tr) * (A[0][0] - tr) + (A[1][1] - tr) * (A[1][1] - tr) +
                      (A[2][2] - tr) * (A[2][2] - tr) + 2.0 * p1;
    const double p = sqrt(p2 / 6.0);
    double B[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) B[i][j] = (A[i][j] - (i == j) * tr) / p;
    const double detB = B[0][0] * (B[1][1] * B[2][2] - B[1][2] * B[2][1]) -
                        B[0][1] * (B[1][0] * B[2][2] - B[1][2] * B[2][0]) +
                        B[0][2] * (B[1][0] * B[2][1] - B[1][1] * B[2][0]);
    double rr = 0.5 * detB;
    rr = rr < -1 ? -1 : rr > 1 ? 1 : rr;
    const double phi = acos(rr) / 3.0;
    ev[0] = tr + 2.0 * p * cos(phi);
    ev[2] = tr + 2.0 * p * cos(phi + 2.0943951023931957); // + 2 pi / 3
    ev[1] = 3.0 * tr - ev[0] - ev[2];
}

static int check_body(const chain_body_def* b, int i, char* err, size_t errsz) {
    if (i == 0) {
        if (b->parent != -1)
            return fail(err, errsz, b, i, "parent", "%d, body 0 (the column) must have parent -1 (the base)", b->parent);
        if (b->joint != CHAIN_REVOLUTE)
            return fail(err, errsz, b, i, "joint", "body 0 (the column) must be revolute (the slew about the base z)");
    } else {
        if (b->parent < 0 || b->parent >= i)
            return fail(err, errsz, b, i, "parent", "%d is not an earlier body (0..%d)", b->parent, i - 1);
        if (b->joint != CHAIN_REVOLUTE && b->joint != CHAIN_PRISMATIC)
            return fail(err, errsz, b, i, "joint", "unknown joint type %d (revolute 0, prismatic 1)", (int)b->joint);
    }
    if (!all_finite(b->origin, 3)) return fail(err, errsz, b, i, "origin", "must be finite [m]");
    if (!isfinite(b->angle0)) return fail(err, errsz, b, i, "angle0", "must be finite [rad]");
    if (!isfinite(b->offset0)) return fail(err, errsz, b, i, "offset0", "must be finite [m]");
    if (!all_finite(b->com, 3)) return fail(err, errsz, b, i, "com", "must be finite [m]");
    // A clamped body may be massless (a column that only carries the booms);
    // a moving one needs mass for M to be positive definite.
    if (!isfinite(b->mass) || b->mass < 0 || (!b->fixed && !(b->mass > 0)))
        return fail(err, errsz, b, i, "mass", "%g kg, must be > 0 kg (>= 0 when the joint is fixed)", b->mass);
    if (!all_finite(&b->inertia[0][0], 9)) return fail(err, errsz, b, i, "inertia", "must be finite [kg m^2]");
    double scale = 0;
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) scale = fmax(scale, fabs(b->inertia[r][k]));
    const double tol = 1e-9 * scale;
    for (int r = 0; r < 3; ++r)
        for (int k = r + 1; k < 3; ++k)
            if (fabs(b->inertia[r][k] - b->inertia[k][r]) > tol)
                return fail(err, errsz, b, i, "inertia", "not symmetric: [%d][%d] = %g, [%d][%d] = %g kg m^2", r, k,
                            b->inertia[r][k], k, r, b->inertia[k][r]);
    double ev[3];
    sym_eig3(b->inertia, ev);
    for (int k = 0; k < 3; ++k) {
        if (ev[k] < -tol)
            return fail(err, errsz, b, i, "inertia", "principal moment %g kg m^2 is negative", ev[k]);
        // A rigid body's principal moments obey the triangle inequality.
        if (ev[k] > ev[(k + 1) % 3] + ev[(k + 2) % 3] + tol)
            return fail(err, errsz, b, i, "inertia",
                        "principal moments %g, %g, %g kg m^2 break the triangle inequality (no rigid body has them)",
                        ev[0], ev[1], ev[2]);
    }
    const char* unit = b->joint == CHAIN_PRISMATIC ? "m" : "rad";
    if (isnan(b->q_min) || isnan(b->q_max))
        return fail(err, errsz, b, i, "q_min", "limits must be numbers [%s]", unit);
    if (b->q_max < b->q_min)
        return fail(err, errsz, b, i, "q_max", "%g %s is below q_min %g %s (the range must not be negative)", b->q_max,
                    unit, b->q_min, unit);
    if (b->fixed && !(b->q_fixed >= b->q_min && b->q_fixed <= b->q_max))
        return fail(err, errsz, b, i, "q_fixed", "%g %s is outside the joint's range %g..%g %s", b->q_fixed, unit,
                    b->q_min, b->q_max, unit);
    return 0;
}

void chain_free(chain* c) {
    if (!c) return;
    free(c->def);
    free(c->parent);
    free(c->dof);
    free(c->dof_body);
    free(c->kind);
    free(c->anc);
    free(c->m);
    free(c->h);
    free(c->Ib);
    free(c->Ep);
    free(c->cs0);
    free(c);
}

chain* chain_create(const chain_body_def* body, int nbody, const double gravity[3], char* err, size_t errsz) {
    if (!body || nbody < 1) {
        if (err && errsz) snprintf(err, errsz, "bodies: a chain needs at least one body (the column), got %d", nbody);
        return NULL;
    }
    for (int i = 0; i < nbody; ++i)
        if (check_body(&body[i], i, err, errsz)) return NULL;
    const double gdef[3] = {0, 0, -9.81};
    if (!gravity) gravity = gdef;
    if (!all_finite(gravity, 3)) {
        if (err && errsz) snprintf(err, errsz, "gravity: must be finite [m/s^2]");
        return NULL;
    }
    chain* c = calloc(1, sizeof *c);
    if (!c) goto oom;
    const size_t n = (size_t)nbody;
    c->nbody = nbody;
    c->def = malloc(n * sizeof *c->def);
    c->parent = malloc(n * sizeof *c->parent);
    c->dof = malloc(n * sizeof *c->dof);
    c->dof_body = malloc(n * sizeof *c->dof_body);
    c->kind = malloc(n);
    c->anc = calloc(n * n, 1);
    c->m = malloc(n * sizeof(double));
    c->h = malloc(3 * n * sizeof(double));
    c->Ib = malloc(9 * n * sizeof(double));
    c->Ep = malloc(9 * n * sizeof(double));
    c->cs0 = malloc(2 * n * sizeof(double));
    if (!c->def || !c->parent || !c->dof || !c->dof_body || !c->kind || !c->anc || !c->m || !c->h || !c->Ib || !c->Ep ||
        !c->cs0)
        goto oom;
    memcpy(c->def, body, n * sizeof *body);
    memcpy(c->g, gravity, sizeof c->g);
    for (int i = 0; i < nbody; ++i) {
        const chain_body_def* b = &body[i];
        c->parent[i] = b->parent;
        c->kind[i] = i == 0 ? K_SLEW : b->joint == CHAIN_PRISMATIC ? K_PRIS : K_REV;
        c->dof[i] = b->fixed ? -1 : c->ndof;
        if (!b->fixed) c->dof_body[c->ndof++] = i;
        for (int k = i; k >= 0; k = c->parent[k]) c->anc[(size_t)i * n + (size_t)k] = 1;
        // Spatial inertia about the body origin: Ib = Ic + m (|c|^2 1 - c c^T).
        const double m = b->mass, cc = dot(b->com, b->com);
        c->m[i] = m;
        for (int k = 0; k < 3; ++k) c->h[3 * i + k] = m * b->com[k];
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k)
                c->Ib[9 * i + 3 * r + k] = 0.5 * (b->inertia[r][k] + b->inertia[k][r]) +
                                           m * ((r == k) * cc - b->com[r] * b->com[k]);
        rot_plane(b->angle0, &c->Ep[9 * i]);
        c->cs0[2 * i] = c->Ep[9 * i], c->cs0[2 * i + 1] = c->Ep[9 * i + 2];
    }
    return c;
oom:
    if (err && errsz) snprintf(err, errsz, "bodies: out of memory for %d bodies", nbody);
    chain_free(c);
    return NULL;
}

int chain_nbody(const chain* c) { return c->nbody; }
int chain_ndof(const chain* c) { return c->ndof; }
int chain_body_dof(const chain* c, int i) { return i >= 0 && i < c->nbody ? c->dof[i] : -1; }
int chain_dof_body(const chain* c, int k) { return k >= 0 && k < c->ndof ? c->dof_body[k] : -1; }
const chain_body_def* chain_body(const chain* c, int i) { return i >= 0 && i < c->nbody ? &c->def[i] : NULL; }

int chain_find_body(const chain* c, const char* name) {
    if (!name || !name[0]) return -1;
    for (int i = 0; i < c->nbody; ++i)
        if (!strncmp(c->def[i].name, name, CHAIN_NAME)) return i;
    return -1;
}

/* ---- workspace ---- */

// Doubles in the workspace after its header.
static size_t ws_doubles(int nb, int nd) {
    const size_t b = (size_t)nb, d = (size_t)nd;
    // q, qd, tmp, dinv; qdb; E, r; cs; R, P; wb, vb, W, V, s; a, f; Ic; M, L (as chain_ws_init takes them).
    return 4 * d + b + 12 * b + 2 * b + 12 * b + 15 * b + 12 * b + 13 * b + 2 * d * d;
}

size_t chain_ws_bytes(const chain* c) {
    // The header rounded up to a multiple of sizeof(double) (it holds pointers and ints).
    const size_t head = (sizeof(chain_ws) + sizeof(double) - 1) / sizeof(double) * sizeof(double);
    return head + ws_doubles(c->nbody, c->ndof) * sizeof(double);
}

chain_ws* chain_ws_init(const chain* c, void* mem) {
    if (!mem) return NULL;
    chain_ws* w = mem;
    memset(w, 0, chain_ws_bytes(c));
    const size_t head = (sizeof(chain_ws) + sizeof(double) - 1) / sizeof(double) * sizeof(double);
    double* p = (double*)((char*)mem + head);
    const size_t b = (size_t)c->nbody, d = (size_t)c->ndof;
    w->nbody = c->nbody;
    w->ndof = c->ndof;
#define TAKE(field, count) (w->field = p, p += (count))
    TAKE(q, d);
    TAKE(qd, d);
    TAKE(qdb, b);
    TAKE(E, 9 * b);
    TAKE(r, 3 * b);
    TAKE(cs, 2 * b);
    TAKE(R, 9 * b);
    TAKE(P, 3 * b);
    TAKE(wb, 3 * b);
    TAKE(vb, 3 * b);
    TAKE(W, 3 * b);
    TAKE(V, 3 * b);
    TAKE(s, 3 * b);
    TAKE(a, 6 * b);
    TAKE(f, 6 * b);
    TAKE(Ic, 13 * b);
    TAKE(M, d * d);
    TAKE(L, d * d);
    TAKE(tmp, d);
    TAKE(dinv, d);
#undef TAKE
    return w;
}

chain_ws* chain_ws_create(const chain* c) { return chain_ws_init(c, malloc(chain_ws_bytes(c))); }
void chain_ws_free(chain_ws* w) { free(w); }

/* ---- kinematics ---- */

void chain_update(const chain* c, chain_ws* w, const double* q, const double* qd) {
    const int nb = c->nbody;
    for (int k = 0; k < c->ndof; ++k) {
        w->q[k] = q[k];
        w->qd[k] = qd ? qd[k] : 0.0;
    }
    w->factored = 0;
    for (int i = 0; i < nb; ++i) {
        const chain_body_def* b = &c->def[i];
        const int d = c->dof[i], kind = c->kind[i];
        const double qi = d >= 0 ? q[d] : b->q_fixed;
        const double qdi = d >= 0 && qd ? qd[d] : 0.0;
        w->qdb[i] = qdi;
        double* E = &w->E[9 * i];
        double* r = &w->r[3 * i];
        double* cs = &w->cs[2 * i];
        if (kind == K_SLEW) {
            const double th = b->angle0 + qi, ct = cos(th), st = sin(th);
            E[0] = ct, E[1] = st, E[2] = 0;
            E[3] = -st, E[4] = ct, E[5] = 0;
            E[6] = 0, E[7] = 0, E[8] = 1;
            cs[0] = ct, cs[1] = st;
            memcpy(r, b->origin, 3 * sizeof(double));
        } else if (kind == K_REV) {
            rot_plane(b->angle0 + qi, E);
            cs[0] = E[0], cs[1] = E[2];
            memcpy(r, b->origin, 3 * sizeof(double));
        } else {
            memcpy(E, &c->Ep[9 * i], 9 * sizeof(double));
            cs[0] = c->cs0[2 * i], cs[1] = c->cs0[2 * i + 1];
            // The slide runs along the child's x: row 0 of E in parent coordinates.
            const double sl = b->offset0 + qi;
            for (int k = 0; k < 3; ++k) r[k] = b->origin[k] + sl * E[k];
        }
        double* R = &w->R[9 * i];
        double* P = &w->P[3 * i];
        double* wi = &w->wb[3 * i];
        double* vi = &w->vb[3 * i];
        const int p = c->parent[i];
        if (p < 0) {
            for (int x = 0; x < 3; ++x)
                for (int y = 0; y < 3; ++y) R[3 * x + y] = E[3 * y + x];
            memcpy(P, r, 3 * sizeof(double));
            wi[0] = wi[1] = wi[2] = 0;
            vi[0] = vi[1] = vi[2] = 0;
        } else {
            const double* Rp = &w->R[9 * p];
            // R = Rp E^T: E turns about y here (only body 0 slews), so
            // R's x and z columns are Rp's turned, its y column Rp's.
            const double ce = cs[0], se = cs[1];
            for (int x = 0; x < 3; ++x) {
                const double r0 = Rp[3 * x], r2 = Rp[3 * x + 2];
                R[3 * x] = ce * r0 + se * r2;
                R[3 * x + 1] = Rp[3 * x + 1];
                R[3 * x + 2] = -se * r0 + ce * r2;
            }
            double t[3];
            mv(Rp, r, t);
            for (int k = 0; k < 3; ++k) P[k] = w->P[3 * p + k] + t[k];
            // Velocity of the child origin: vp + wp x r, in child coordinates.
            const double* wp = &w->wb[3 * p];
            const double* vp = &w->vb[3 * p];
            double u[3];
            cross(wp, r, u);
            for (int k = 0; k < 3; ++k) u[k] += vp[k];
            erot(0, cs, wp, wi);
            erot(0, cs, u, vi);
        }
        // Joint axis in the body's coordinates -> base.
        double* s = &w->s[3 * i];
        if (kind == K_SLEW) {
            wi[2] += qdi;
            s[0] = R[2], s[1] = R[5], s[2] = R[8];
        } else if (kind == K_REV) {
            wi[1] -= qdi;
            s[0] = -R[1], s[1] = -R[4], s[2] = -R[7];
        } else {
            vi[0] += qdi;
            s[0] = R[0], s[1] = R[3], s[2] = R[6];
        }
        mv(R, wi, &w->W[3 * i]);
        mv(R, vi, &w->V[3 * i]);
    }
}

void chain_body_pose(const chain* c, const chain_ws* w, int i, double R[9], double p[3]) {
    (void)c;
    if (R) memcpy(R, &w->R[9 * i], 9 * sizeof(double));
    if (p) memcpy(p, &w->P[3 * i], 3 * sizeof(double));
}

void chain_world_point(const chain* c, const chain_ws* w, int i, const double pb[3], double p[3], double v[3]) {
    (void)c;
    double t[3];
    mv(&w->R[9 * i], pb, t);
    if (v) {
        double u[3];
        cross(&w->W[3 * i], t, u);
        for (int k = 0; k < 3; ++k) v[k] = w->V[3 * i + k] + u[k];
    }
    if (p)
        for (int k = 0; k < 3; ++k) p[k] = w->P[3 * i + k] + t[k];
}

// Column of joint body k in the Jacobian of the point p (base frame) moving
// with velocity pv, and its time derivative (jd may be NULL).
static void jac_col(const chain* c, const chain_ws* w, int k, const double p[3], const double pv[3], double j[3],
                    double* jd) {
    const double* s = &w->s[3 * k];
    const double* Wk = &w->W[3 * k];
    if (c->kind[k] == K_PRIS) {
        memcpy(j, s, 3 * sizeof(double));
        if (jd) cross(Wk, s, jd); // the slide's axis turns with its body
        return;
    }
    // Rotation about the axis s through the body origin P: j = s x (p - P);
    // d/dt: (W x s) x (p - P) + s x (pv - V).
    const double* P = &w->P[3 * k];
    const double d[3] = {p[0] - P[0], p[1] - P[1], p[2] - P[2]};
    cross(s, d, j);
    if (jd) {
        double sd[3], t1[3], t2[3];
        const double dv[3] = {pv[0] - w->V[3 * k], pv[1] - w->V[3 * k + 1], pv[2] - w->V[3 * k + 2]};
        cross(Wk, s, sd);
        cross(sd, d, t1);
        cross(s, dv, t2);
        for (int x = 0; x < 3; ++x) jd[x] = t1[x] + t2[x];
    }
}

void chain_point_jacobian(const chain* c, const chain_ws* w, int i, const double pb[3], double* J, double* Jdot) {
    const int nd = c->ndof;
    double p[3], pv[3];
    chain_world_point(c, w, i, pb, p, pv);
    for (int k = 0; k < nd; ++k) {
        const int b = c->dof_body[k];
        double j[3] = {0, 0, 0}, jd[3] = {0, 0, 0};
        if (c->anc[(size_t)i * (size_t)c->nbody + (size_t)b]) jac_col(c, w, b, p, pv, j, Jdot ? jd : NULL);
        for (int x = 0; x < 3; ++x) {
            J[x * nd + k] = j[x];
            if (Jdot) Jdot[x * nd + k] = jd[x];
        }
    }
}

double chain_joint_q(const chain* c, const chain_ws* w, int i, double* qd) {
    const int k = c->dof[i];
    if (qd) *qd = k >= 0 ? w->qdb[i] : 0.0;
    return k >= 0 ? w->q[k] : c->def[i].q_fixed;
}

double chain_cylinder(const chain* c, const chain_ws* w, int a, const double pa[3], int b, const double pb[3],
                      double* Ldot, double* dL_dq, double* dLdot_dq) {
    double xa[3], va[3], xb[3], vb[3];
    chain_world_point(c, w, a, pa, xa, va);
    chain_world_point(c, w, b, pb, xb, vb);
    const double d[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
    const double dd[3] = {vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]};
    const double L = sqrt(dot(d, d));
    const double u[3] = {d[0] / L, d[1] / L, d[2] / L};
    const double Ld = dot(u, dd);
    if (Ldot) *Ldot = Ld;
    if (!dL_dq && !dLdot_dq) return L;
    // d/dt of the unit vector: the part of the relative velocity across it, over L.
    const double ud[3] = {(dd[0] - u[0] * Ld) / L, (dd[1] - u[1] * Ld) / L, (dd[2] - u[2] * Ld) / L};
    const size_t nb = (size_t)c->nbody;
    for (int k = 0; k < c->ndof; ++k) {
        const int body = c->dof_body[k];
        const int on_a = c->anc[(size_t)a * nb + (size_t)body], on_b = c->anc[(size_t)b * nb + (size_t)body];
        if (on_a == on_b) {
            // A joint that carries both pins (or neither) moves them
            // together: L does not depend on it at any q, so both partials
            // are exactly 0 (computed, they would be rounding noise). Only
            // the joints between the two bodies cost anything, which keeps
            // a long chain's lever arms linear in its length.
            if (dL_dq) dL_dq[k] = 0.0;
            if (dLdot_dq) dLdot_dq[k] = 0.0;
            continue;
        }
        double ja[3] = {0, 0, 0}, jda[3] = {0, 0, 0}, jb[3] = {0, 0, 0}, jdb[3] = {0, 0, 0};
        if (on_a) jac_col(c, w, body, xa, va, ja, dLdot_dq ? jda : NULL);
        if (on_b) jac_col(c, w, body, xb, vb, jb, dLdot_dq ? jdb : NULL);
        const double dj[3] = {jb[0] - ja[0], jb[1] - ja[1], jb[2] - ja[2]};
        if (dL_dq) dL_dq[k] = dot(u, dj);
        if (dLdot_dq) {
            const double djd[3] = {jdb[0] - jda[0], jdb[1] - jda[1], jdb[2] - jda[2]};
            dLdot_dq[k] = dot(ud, dj) + dot(u, djd);
        }
    }
    return L;
}

// d(J_k)/dq_j for a point on body i, J_k its Jacobian column of DOF k, for
// DOFs j and k whose bodies are both i or its ancestors (else 0): of the two
// joints the one nearer the root (e, the smaller body index) moves the
// other's axis, origin and the point together, so for a rotation e the
// derivative is s_e x J_l (l the other DOF; e = l included: s x (s x (p - o))),
// and for a slide e it is 0 (a translation changes no column).
static void jac_second(const chain* c, const chain_ws* w, int i, int j, int k, const double* Jcols, double o[3]) {
    const size_t nb = (size_t)c->nbody;
    const int bj = c->dof_body[j], bk = c->dof_body[k];
    o[0] = o[1] = o[2] = 0;
    if (!c->anc[(size_t)i * nb + (size_t)bj] || !c->anc[(size_t)i * nb + (size_t)bk]) return;
    const int e = bj < bk ? bj : bk, l = bj < bk ? k : j;
    if (c->kind[e] == K_PRIS) return;
    cross(&w->s[3 * e], &Jcols[3 * l], o);
}

void chain_cylinder_hessian(const chain* c, chain_ws* w, int a, const double pa[3], int b, const double pb[3],
                            double* H) {
    const int nd = c->ndof;
    const size_t nb = (size_t)c->nbody;
    double xa[3], xb[3];
    chain_world_point(c, w, a, pa, xa, NULL);
    chain_world_point(c, w, b, pb, xb, NULL);
    const double d[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
    const double L = sqrt(dot(d, d));
    const double u[3] = {d[0] / L, d[1] / L, d[2] / L};
    // Both points' Jacobian columns in the Newton-Euler scratch (3 ndof <= 6 nbody each).
    double* Ja = w->a;
    double* Jb = w->f;
    // The joints between the two bodies (carrying exactly one pin): L does
    // not depend on any other at any q, so their rows and columns are 0.
    double* act = w->tmp; // DOF indices of those joints (the solve's scratch; exact as doubles)
    int na = 0;
    for (int k = 0; k < nd; ++k) {
        const int body = c->dof_body[k];
        double* ja = &Ja[3 * k];
        double* jb = &Jb[3 * k];
        ja[0] = ja[1] = ja[2] = jb[0] = jb[1] = jb[2] = 0;
        const int on_a = c->anc[(size_t)a * nb + (size_t)body], on_b = c->anc[(size_t)b * nb + (size_t)body];
        if (on_a == on_b) continue;
        act[na++] = k;
        if (on_a) jac_col(c, w, body, xa, xa, ja, NULL);
        if (on_b) jac_col(c, w, body, xb, xb, jb, NULL);
    }
    memset(H, 0, (size_t)nd * (size_t)nd * sizeof *H);
    // L = |d|: d2L/dqj dqk = (Dj . Dk - (u . Dj)(u . Dk)) / L + u . dDk/dqj, D = Jb - Ja.
    for (int jj = 0; jj < na; ++jj)
        for (int kk = jj; kk < na; ++kk) {
            const int j = (int)act[jj], k = (int)act[kk];
            const double Dj[3] = {Jb[3 * j] - Ja[3 * j], Jb[3 * j + 1] - Ja[3 * j + 1], Jb[3 * j + 2] - Ja[3 * j + 2]};
            const double Dk[3] = {Jb[3 * k] - Ja[3 * k], Jb[3 * k + 1] - Ja[3 * k + 1], Jb[3 * k + 2] - Ja[3 * k + 2]};
            double sa[3], sb[3];
            jac_second(c, w, a, j, k, Ja, sa);
            jac_second(c, w, b, j, k, Jb, sb);
            const double ds[3] = {sb[0] - sa[0], sb[1] - sa[1], sb[2] - sa[2]};
            const double h = (dot(Dj, Dk) - dot(u, Dj) * dot(u, Dk)) / L + dot(u, ds);
            H[j * nd + k] = H[k * nd + j] = h;
        }
}

/* ---- dynamics ---- */

// (n, f) = I (w, v) for the spatial inertia (m, h, Ib).
static inline void inertia_mul(double m, const double* h, const double* Ib, const double* wv, const double* vv,
                               double* n, double* f) {
    double t[3];
    mv(Ib, wv, n);
    cross(h, vv, t);
    n[0] += t[0], n[1] += t[1], n[2] += t[2];
    cross(h, wv, t);
    f[0] = m * vv[0] - t[0], f[1] = m * vv[1] - t[1], f[2] = m * vv[2] - t[2];
}

// S^T (n, f) for body i's joint.
static inline double proj(int kind, const double* n, const double* f) {
    return kind == K_SLEW ? n[2] : kind == K_REV ? -n[1] : f[0];
}

void chain_inverse_dynamics(const chain* c, chain_ws* w, const double* qdd, int terms, double* tau) {
    const int nb = c->nbody;
    const int vel = (terms & CHAIN_VELOCITY) != 0;
    for (int i = 0; i < nb; ++i) {
        const int p = c->parent[i], kind = c->kind[i], d = c->dof[i];
        const double* cs = &w->cs[2 * i];
        const double* r = &w->r[3 * i];
        double* a = &w->a[6 * i]; // angular 0..2, linear (of the body origin) 3..5
        if (p < 0) {
            // The base accelerates upwards at -g: gravity for every body at once.
            double ab[3] = {0, 0, 0};
            if (terms & CHAIN_GRAVITY) ab[0] = -c->g[0], ab[1] = -c->g[1], ab[2] = -c->g[2];
            a[0] = a[1] = a[2] = 0;
            erot(1, cs, ab, a + 3);
        } else {
            const double* ap = &w->a[6 * p];
            double t[3];
            cross(ap, r, t); // linear acceleration of the child origin: ap_v + ap_w x r
            t[0] += ap[3], t[1] += ap[4], t[2] += ap[5];
            erot(0, cs, ap, a);
            erot(0, cs, t, a + 3);
        }
        const double qa = qdd && d >= 0 ? qdd[d] : 0.0;
        const double* wi = &w->wb[3 * i];
        const double* vi = &w->vb[3 * i];
        const double qdi = w->qdb[i];
        // + S qdd + v x (S qd): the axis turning with the body and, for a
        // slide, the rate's own transport.
        if (kind == K_PRIS) {
            a[3] += qa;
            if (vel) { // (w, v) x (0, x qd) = (0, w x x qd)
                a[4] += wi[2] * qdi;
                a[5] -= wi[1] * qdi;
            }
        } else {
            double ax[3] = {0, 0, 0};
            ax[kind == K_SLEW ? 2 : 1] = kind == K_SLEW ? 1.0 : -1.0;
            for (int k = 0; k < 3; ++k) a[k] += ax[k] * qa;
            if (vel) { // (w, v) x (ax qd, 0) = (w x ax qd, v x ax qd)
                double t[3];
                cross(wi, ax, t);
                for (int k = 0; k < 3; ++k) a[k] += t[k] * qdi;
                cross(vi, ax, t);
                for (int k = 0; k < 3; ++k) a[3 + k] += t[k] * qdi;
            }
        }
        double* f = &w->f[6 * i]; // moment 0..2 about the body origin, force 3..5
        const double m = c->m[i];
        const double* h = &c->h[3 * i];
        const double* Ib = &c->Ib[9 * i];
        inertia_mul(m, h, Ib, a, a + 3, f, f + 3);
        if (vel) { // + v x* (I v) = (w x n + v x f, w x f)
            double n[3], fl[3], t[3];
            inertia_mul(m, h, Ib, wi, vi, n, fl);
            cross(wi, n, t);
            f[0] += t[0], f[1] += t[1], f[2] += t[2];
            cross(vi, fl, t);
            f[0] += t[0], f[1] += t[1], f[2] += t[2];
            cross(wi, fl, t);
            f[3] += t[0], f[4] += t[1], f[5] += t[2];
        }
    }
    for (int i = nb - 1; i >= 0; --i) {
        const double* f = &w->f[6 * i];
        if (c->dof[i] >= 0) tau[c->dof[i]] = proj(c->kind[i], f, f + 3);
        const int p = c->parent[i];
        if (p < 0) continue;
        // To the parent: f_p = E^T f, n_p = E^T n + r x f_p.
        const double* cs = &w->cs[2 * i];
        const double* r = &w->r[3 * i];
        double fp[3], np[3], t[3];
        erot_t(i == 0, cs, f + 3, fp);
        erot_t(i == 0, cs, f, np);
        cross(r, fp, t);
        double* F = &w->f[6 * p];
        for (int k = 0; k < 3; ++k) F[k] += np[k] + t[k], F[3 + k] += fp[k];
    }
}

void chain_mass_matrix(const chain* c, chain_ws* w, double* M) {
    const int nb = c->nbody, nd = c->ndof;
    // Only ancestor-descendant pairs are written below; two DOFs on
    // different branches of a tree do not couple.
    memset(M, 0, (size_t)nd * (size_t)nd * sizeof *M);
    for (int i = 0; i < nb; ++i) {
        double* I = &w->Ic[13 * i];
        I[0] = c->m[i];
        memcpy(I + 1, &c->h[3 * i], 3 * sizeof(double));
        memcpy(I + 4, &c->Ib[9 * i], 9 * sizeof(double));
    }
    // Composite inertias, leaves first: the child's (m, h, Ib) in the parent's
    // coordinates is m, h' = y + m r with y = E^T h, and
    // Ib' = E^T Ib E + (2 r.y + m r.r) 1 - (y r^T + r y^T + m r r^T).
    for (int i = nb - 1; i > 0; --i) {
        const double* E = &w->E[9 * i];
        const double* r = &w->r[3 * i];
        const double* I = &w->Ic[13 * i];
        double* Ip = &w->Ic[13 * c->parent[i]];
        const double m = I[0];
        double y[3];
        mtv(E, I + 1, y);
        double B[9], A[9]; // B = Ib E, A = E^T B
        for (int x = 0; x < 3; ++x)
            for (int z = 0; z < 3; ++z)
                B[3 * x + z] = I[4 + 3 * x] * E[z] + I[4 + 3 * x + 1] * E[3 + z] + I[4 + 3 * x + 2] * E[6 + z];
        for (int x = 0; x < 3; ++x)
            for (int z = 0; z < 3; ++z) A[3 * x + z] = E[x] * B[z] + E[3 + x] * B[3 + z] + E[6 + x] * B[6 + z];
        const double diag = 2.0 * dot(r, y) + m * dot(r, r);
        Ip[0] += m;
        for (int k = 0; k < 3; ++k) Ip[1 + k] += y[k] + m * r[k];
        for (int x = 0; x < 3; ++x)
            for (int z = 0; z < 3; ++z)
                Ip[4 + 3 * x + z] += A[3 * x + z] + (x == z) * diag - (y[x] * r[z] + r[x] * y[z] + m * r[x] * r[z]);
    }
    for (int i = 0; i < nb; ++i) {
        const int k = c->dof[i];
        if (k < 0) continue;
        const double* I = &w->Ic[13 * i];
        double n[3], f[3];
        const int kind = c->kind[i];
        if (kind == K_PRIS) { // I (0, x): n = h x x, f = m x
            n[0] = 0, n[1] = I[3], n[2] = -I[2];
            f[0] = I[0], f[1] = 0, f[2] = 0;
        } else { // I (e, 0): n = Ib e, f = e x h, e = z (slew) or -y
            const int col = kind == K_SLEW ? 2 : 1;
            const double sg = kind == K_SLEW ? 1.0 : -1.0;
            for (int x = 0; x < 3; ++x) n[x] = sg * I[4 + 3 * x + col];
            const double e[3] = {0, kind == K_SLEW ? 0 : -1.0, kind == K_SLEW ? 1.0 : 0};
            cross(e, I + 1, f);
        }
        M[k * nd + k] = proj(kind, n, f);
        for (int j = i; c->parent[j] >= 0; j = c->parent[j]) {
            const double* cs = &w->cs[2 * j];
            const double* r = &w->r[3 * j];
            double fp[3], np[3], t[3];
            erot_t(j == 0, cs, f, fp);
            erot_t(j == 0, cs, n, np);
            cross(r, fp, t);
            for (int x = 0; x < 3; ++x) n[x] = np[x] + t[x], f[x] = fp[x];
            const int l = c->dof[c->parent[j]];
            if (l >= 0) M[k * nd + l] = M[l * nd + k] = proj(c->kind[c->parent[j]], n, f);
        }
    }
}

int chain_forward_dynamics(const chain* c, chain_ws* w, const double* tau, double* qdd) {
    const int nd = c->ndof;
    chain_mass_matrix(c, w, w->M);
    chain_inverse_dynamics(c, w, NULL, CHAIN_VELOCITY | CHAIN_GRAVITY, w->tmp);
    // Cholesky M = L L^T (lower, row-major).
    double* L = w->L;
    w->factored = 0;
    for (int i = 0; i < nd; ++i) {
        for (int j = 0; j <= i; ++j) {
            double s = w->M[i * nd + j];
            for (int k = 0; k < j; ++k) s -= L[i * nd + k] * L[j * nd + k];
            if (i == j) {
                if (!(s > 0)) {
                    for (int x = 0; x < nd; ++x) qdd[x] = NAN;
                    return -1;
                }
                L[i * nd + i] = sqrt(s);
                w->dinv[i] = 1.0 / L[i * nd + i];
            } else {
                L[i * nd + j] = s * w->dinv[j];
            }
        }
    }
    w->factored = 1;
    for (int k = 0; k < nd; ++k) qdd[k] = (tau ? tau[k] : 0.0) - w->tmp[k];
    chain_solve(c, w, qdd, qdd);
    return 0;
}

void chain_solve(const chain* c, const chain_ws* w, const double* b, double* x) {
    const int nd = c->ndof;
    const double* L = w->L;
    for (int i = 0; i < nd; ++i) {
        double s = b[i];
        for (int k = 0; k < i; ++k) s -= L[i * nd + k] * x[k];
        x[i] = s * w->dinv[i];
    }
    for (int i = nd - 1; i >= 0; --i) {
        double s = x[i];
        for (int k = i + 1; k < nd; ++k) s -= L[k * nd + i] * x[k];
        x[i] = s * w->dinv[i];
    }
}

double chain_kinetic_energy(const chain* c, const chain_ws* w) {
    double T = 0;
    for (int i = 0; i < c->nbody; ++i) {
        double n[3], f[3];
        const double* wi = &w->wb[3 * i];
        const double* vi = &w->vb[3 * i];
        inertia_mul(c->m[i], &c->h[3 * i], &c->Ib[9 * i], wi, vi, n, f);
        T += 0.5 * (dot(wi, n) + dot(vi, f));
    }
    return T;
}

double chain_potential_energy(const chain* c, const chain_ws* w) {
    double V = 0;
    for (int i = 0; i < c->nbody; ++i) {
        double p[3];
        chain_world_point(c, w, i, c->def[i].com, p, NULL);
        V -= c->m[i] * dot(c->g, p);
    }
    return V;
}
