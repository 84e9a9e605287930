// linkage.c: the four-bar knuckle linkage (linkage.h). The derivation is in
// docs/mechanism.md, "A cylinder through a linkage".
#include "linkage.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// Samples over the range for the dead-centre scan (a sign change of dL/dq
// between neighbours is then located by bisection).
#define LINKAGE_SCAN 1024

static double cross2(const double u[2], const double v[2]) { return u[0] * v[1] - u[1] * v[0]; }
static double dot2(const double u[2], const double v[2]) { return u[0] * v[0] + u[1] * v[1]; }

// C = J + R(angle0 + q) c: the rocker's pin in the parent frame; positive
// angles turn x towards z (a counter-clockwise turn in (x, z)).
static void rocker_point(const linkage_def* d, double q, double C[2]) {
    double th = d->angle0 + q, ct = cos(th), st = sin(th);
    C[0] = d->joint[0] + ct * d->rocker_pin[0] - st * d->rocker_pin[1];
    C[1] = d->joint[1] + st * d->rocker_pin[0] + ct * d->rocker_pin[1];
}

static int eval(const linkage_def* d, double q, linkage_state* s) {
    const double* A = d->link_pin;
    double l1 = d->link_len, l2 = d->rocker_len;
    rocker_point(d, q, s->C);
    // P is on the circle of radius l1 about A and of radius l2 about C. Along
    // u = (C - A) / D it lies a = (l1^2 - l2^2 + D^2) / (2 D) from A, and
    // h = sqrt(l1^2 - a^2) off the line, on the branch's side (n = u turned
    // +90 degrees: cross(u, n) = 1 > 0).
    double dx = s->C[0] - A[0], dz = s->C[1] - A[1];
    double D = hypot(dx, dz);
    double a = D > 0 ? (l1 * l1 - l2 * l2 + D * D) / (2 * D) : NAN;
    double h2 = l1 * l1 - a * a;
    if (!(D > 0) || !(h2 > 0)) goto fail;
    double h = d->branch * sqrt(h2);
    double ux = dx / D, uz = dz / D;
    s->P[0] = A[0] + a * ux - h * uz;
    s->P[1] = A[1] + a * uz + h * ux;

    // Derivatives by differentiating the two loop constraints
    //   |P - A|^2 = l1^2,   |P - C|^2 = l2^2
    // in q (A fixed; C turns about J: C' = perp(C - J), C'' = -(C - J)):
    //   (P - A).P'  = 0
    //   (P - C).P'  = (P - C).C'
    //   (P - A).P'' = -|P'|^2
    //   (P - C).P'' = (P - C).C'' - |P' - C'|^2
    // Both are 2x2 systems with rows r1 = P - A, r2 = P - C; their
    // determinant cross(r1, r2) = l1 l2 sin(mu) vanishes only at a toggle.
    double r1[2] = {s->P[0] - A[0], s->P[1] - A[1]};
    double r2[2] = {s->P[0] - s->C[0], s->P[1] - s->C[1]};
    double rc[2] = {s->C[0] - d->joint[0], s->C[1] - d->joint[1]};
    double Cd[2] = {-rc[1], rc[0]};
    double Cdd[2] = {-rc[0], -rc[1]};
    double det = cross2(r1, r2);
    s->sin_mu = fabs(det) / (l1 * l2);
    if (!(s->sin_mu > 1e-12)) goto fail;
    // Cramer: for rows r1, r2 and right sides b1, b2, x = (b1 r2z - b2 r1z,
    // b2 r1x - b1 r2x) / det.
    double b1 = 0, b2 = dot2(r2, Cd);
    s->dP[0] = (b1 * r2[1] - b2 * r1[1]) / det;
    s->dP[1] = (b2 * r1[0] - b1 * r2[0]) / det;
    double w[2] = {s->dP[0] - Cd[0], s->dP[1] - Cd[1]};
    b1 = -dot2(s->dP, s->dP);
    b2 = dot2(r2, Cdd) - dot2(w, w);
    s->d2P[0] = (b1 * r2[1] - b2 * r1[1]) / det;
    s->d2P[1] = (b2 * r1[0] - b1 * r2[0]) / det;

    // L = |P - B|, e = (P - B) / L:
    //   L'  = e.P'
    //   L'' = e.P'' + (|P'|^2 - (e.P')^2) / L
    double eb[2] = {s->P[0] - d->base[0], s->P[1] - d->base[1]};
    s->L = hypot(eb[0], eb[1]);
    if (!(s->L > 0)) goto fail;
    eb[0] /= s->L;
    eb[1] /= s->L;
    s->dL = dot2(eb, s->dP);
    s->d2L = dot2(eb, s->d2P) + (dot2(s->dP, s->dP) - s->dL * s->dL) / s->L;
    s->link_angle = atan2(r1[1], r1[0]);
    s->rocker_angle = atan2(r2[1], r2[0]);
    return 0;
fail:
    s->P[0] = s->P[1] = s->L = s->dL = s->d2L = NAN;
    s->dP[0] = s->dP[1] = s->d2P[0] = s->d2P[1] = NAN;
    s->link_angle = s->rocker_angle = s->sin_mu = NAN;
    return -1;
}

int linkage_eval(const linkage* lk, double q, linkage_state* s) { return eval(&lk->d, q, s); }

double linkage_length(const linkage* lk, double q) {
    linkage_state s;
    eval(&lk->d, q, &s);
    return s.L;
}

static int fail(char* err, size_t errsz, const char* fmt, double a, double b, double c) {
    if (err && errsz) snprintf(err, errsz, fmt, a, b, c);
    return -1;
}

// The range of D^2(q) = |C(q) - A|^2 over [q_min, q_max], exactly:
// C - A = (J - A) + R(th) c, so D^2 = K + 2 (J - A).R(th) c = K + M cos(th - phi)
// with K = |J - A|^2 + |c|^2, M = 2 |J - A| |c|. Its extremes are at the
// range's ends or where th - phi is a multiple of pi inside it.
static void distance_range(const linkage_def* d, double* Dmin, double* Dmax, double* qmin_at, double* qmax_at) {
    double g[2] = {d->joint[0] - d->link_pin[0], d->joint[1] - d->link_pin[1]};
    const double* c = d->rocker_pin;
    double K = dot2(g, g) + dot2(c, c);
    // (J - A).R(th) c = cos th (g.c) + sin th cross(c, g)... written out:
    // R(th) c = (ct cx - st cz, st cx + ct cz), so the product is
    // ct (g.c) + st (gz cx - gx cz) = M/2 cos(th - phi).
    double gc = dot2(g, c), gs = g[1] * c[0] - g[0] * c[1];
    double M = 2 * hypot(gc, gs), phi = atan2(gs, gc);
    double t0 = d->angle0 + d->q_min, t1 = d->angle0 + d->q_max;
    double cand[64];
    int n = 0;
    cand[n++] = d->q_min;
    cand[n++] = d->q_max;
    for (double k = ceil((t0 - phi) / M_PI); k * M_PI + phi <= t1 && n < 64; k += 1) cand[n++] = k * M_PI + phi - d->angle0;
    *Dmin = INFINITY;
    *Dmax = -INFINITY;
    for (int i = 0; i < n; i++) {
        double D = sqrt(fmax(0, K + M * cos(cand[i] + d->angle0 - phi)));
        if (D < *Dmin) *Dmin = D, *qmin_at = cand[i];
        if (D > *Dmax) *Dmax = D, *qmax_at = cand[i];
    }
}

int linkage_init(linkage* lk, const linkage_def* d, char* err, size_t errsz) {
    const double* nums[] = {d->joint, d->joint + 1, &d->angle0, d->base, d->base + 1, d->link_pin, d->link_pin + 1,
                            d->rocker_pin, d->rocker_pin + 1, &d->link_len, &d->rocker_len, &d->q_min, &d->q_max,
                            &d->link_mass, &d->rocker_mass};
    const char* names[] = {"joint[0]", "joint[1]", "angle0", "base[0]", "base[1]", "link_pin[0]", "link_pin[1]",
                           "rocker_pin[0]", "rocker_pin[1]", "link_len", "rocker_len", "q_min", "q_max",
                           "link_mass", "rocker_mass"};
    for (size_t i = 0; i < sizeof nums / sizeof nums[0]; i++)
        if (!isfinite(*nums[i])) {
            if (err && errsz) snprintf(err, errsz, "linkage.%s: not a finite number", names[i]);
            return -1;
        }
    if (!(d->link_len > 0)) return fail(err, errsz, "linkage.link_len: %g m, must be > 0 m", d->link_len, 0, 0);
    if (!(d->rocker_len > 0)) return fail(err, errsz, "linkage.rocker_len: %g m, must be > 0 m", d->rocker_len, 0, 0);
    if (d->branch != 1 && d->branch != -1)
        return fail(err, errsz, "linkage.branch: %g, must be +1 or -1", d->branch, 0, 0);
    if (!(d->q_min < d->q_max))
        return fail(err, errsz, "linkage.q_min: %g rad, must be < q_max (%g rad)", d->q_min, d->q_max, 0);
    if (!(d->q_max - d->q_min < 2 * M_PI))
        return fail(err, errsz, "linkage.q_max: range %g rad, must be < 2 pi rad", d->q_max - d->q_min, 0, 0);
    if (d->link_mass < 0) return fail(err, errsz, "linkage.link_mass: %g kg, must be >= 0 kg", d->link_mass, 0, 0);
    if (d->rocker_mass < 0)
        return fail(err, errsz, "linkage.rocker_mass: %g kg, must be >= 0 kg", d->rocker_mass, 0, 0);

    // Closure: P exists where |l1 - l2| < D < l1 + l2 (strictly: at equality
    // the loop is at a toggle, where the lever arm is unbounded and the two
    // branches meet).
    double Dmin, Dmax, qa = 0, qb = 0;
    distance_range(d, &Dmin, &Dmax, &qa, &qb);
    double lo = fabs(d->link_len - d->rocker_len), hi = d->link_len + d->rocker_len;
    double tol = 1e-9 * hi;
    if (!(Dmax < hi - tol))
        return fail(err, errsz,
                    "linkage.link_len: the loop cannot close at q = %g rad: link pin to rocker pin %.6g m >= "
                    "link_len + rocker_len = %.6g m",
                    qb, Dmax, hi);
    if (!(Dmin > lo + tol))
        return fail(err, errsz,
                    "linkage.rocker_len: the loop cannot close at q = %g rad: link pin to rocker pin %.6g m <= "
                    "|link_len - rocker_len| = %.6g m",
                    qa, Dmin, lo);

    lk->d = *d;
    linkage_state s0, s1;
    // The closure check leaves only a cylinder length of (nearly) 0 to fail:
    // the base on the common pin's path. Inside the range that is a kink of
    // L (dL/dq flips sign), caught by the dead-centre scan below; at the
    // range's ends it is refused here (1e-9 of the links' size: rounding).
    eval(d, d->q_min, &s0);
    eval(d, d->q_max, &s1);
    if (!(s0.L > tol))
        return fail(err, errsz, "linkage.base: the cylinder length is %.3g m at q = %g rad, must be > 0 m", s0.L,
                    d->q_min, 0);
    if (!(s1.L > tol))
        return fail(err, errsz, "linkage.base: the cylinder length is %.3g m at q = %g rad, must be > 0 m", s1.L,
                    d->q_max, 0);
    lk->L_qmin = s0.L;
    lk->L_qmax = s1.L;
    lk->sign = s1.L > s0.L ? 1 : -1;
    lk->min_lever = INFINITY;
    lk->min_sin_mu = INFINITY;
    // Dead centre: dL/dq changes sign (or is 0) inside the range; then L(q)
    // is not monotonic, the cylinder has no lever there and q(L) is not
    // unique. Scan, then bisect the first sign change to name the angle.
    double qprev = d->q_min, dprev = s0.dL;
    for (int i = 0; i <= LINKAGE_SCAN; i++) {
        double q = d->q_min + (d->q_max - d->q_min) * i / LINKAGE_SCAN;
        linkage_state s;
        if (eval(d, q, &s))
            return fail(err, errsz, "linkage.base: the cylinder length is 0 m at q = %g rad, must be > 0 m", q, 0, 0);
        if (fabs(s.dL) < lk->min_lever) lk->min_lever = fabs(s.dL);
        if (s.sin_mu < lk->min_sin_mu) lk->min_sin_mu = s.sin_mu;
        if (s.dL == 0 || (s.dL > 0) != (dprev > 0)) {
            double a = qprev, b = q, fa = dprev;
            for (int k = 0; k < 200 && b - a > 1e-14; k++) {
                double m = 0.5 * (a + b);
                linkage_state sm;
                eval(d, m, &sm);
                if ((sm.dL > 0) == (fa > 0) && sm.dL != 0)
                    a = m, fa = sm.dL;
                else
                    b = m;
            }
            return fail(err, errsz,
                        "linkage.base: dead centre at q = %.6g rad inside the range [%g, %g] rad (dL/dq = 0: the "
                        "cylinder has no lever there)",
                        0.5 * (a + b), d->q_min, d->q_max);
        }
        qprev = q;
        dprev = s.dL;
    }
    return 0;
}

int linkage_angle(const linkage* lk, double L, double* q) {
    double lo = lk->d.q_min, hi = lk->d.q_max;
    double Llo = lk->L_qmin, Lhi = lk->L_qmax;
    double Lmin = fmin(Llo, Lhi), Lmax = fmax(Llo, Lhi);
    if (!(L >= Lmin && L <= Lmax)) return -1;
    // f(q) = sign (L(q) - L) grows with q over the range (no dead centre),
    // so [lo, hi] stays a bracket: Newton steps inside it, bisection when a
    // step would leave it.
    double s = lk->sign;
    double x = lo + (hi - lo) * (L - Llo) / (Lhi - Llo);
    if (!(x >= lo && x <= hi)) x = 0.5 * (lo + hi);
    for (int it = 0; it < 200; it++) {
        linkage_state st;
        eval(&lk->d, x, &st);
        double f = s * (st.L - L);
        if (f == 0) break;
        if (f > 0)
            hi = x;
        else
            lo = x;
        double xn = x - f / (s * st.dL);
        if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
        // Stop when the step is at rounding of q (or the bracket is).
        if (fabs(xn - x) <= 4e-16 * fmax(1, fabs(x)) || hi - lo <= 4e-16 * fmax(1, fabs(x))) {
            x = xn;
            break;
        }
        x = xn;
    }
    *q = x;
    return 0;
}

void linkage_lump(const linkage* lk, chain_body_def* parent, chain_body_def* child) {
    if (parent && lk->d.link_mass > 0) {
        double p[3] = {lk->d.link_pin[0], 0, lk->d.link_pin[1]};
        chain_body_add_point_mass(parent, lk->d.link_mass, p);
    }
    if (child && lk->d.rocker_mass > 0) {
        double p[3] = {lk->d.rocker_pin[0], 0, lk->d.rocker_pin[1]};
        chain_body_add_point_mass(child, lk->d.rocker_mass, p);
    }
}

int linkage_links(const linkage* lk, double q, const double g[2], linkage_links_terms* t) {
    linkage_state s;
    if (eval(&lk->d, q, &s)) {
        t->I = t->G = t->I_lumped = t->G_lumped = NAN;
        return -1;
    }
    double m1 = lk->d.link_mass, m2 = lk->d.rocker_mass, l2 = lk->d.rocker_len;
    const double* J = lk->d.joint;
    // C' = perp(C - J) [m/rad]; the link's centre (A + P) / 2 moves at P'/2,
    // the rocker's (C + P) / 2 at (C' + P') / 2.
    double Cd[2] = {-(s.C[1] - J[1]), s.C[0] - J[0]};
    double v2[2] = {0.5 * (Cd[0] + s.dP[0]), 0.5 * (Cd[1] + s.dP[1])};
    // The link turns about A at |P'| / l1 (P' is normal to A-P), so its
    // 1/2 m |P'/2|^2 + 1/2 (m l1^2 / 12) (|P'| / l1)^2 = 1/2 (m / 3) |P'|^2.
    // The rocker turns at w2 = cross(P - C, P' - C') / l2^2 [rad/rad].
    double r2[2] = {s.P[0] - s.C[0], s.P[1] - s.C[1]};
    double rel[2] = {s.dP[0] - Cd[0], s.dP[1] - Cd[1]};
    double w2 = cross2(r2, rel) / (l2 * l2);
    t->I = m1 * dot2(s.dP, s.dP) / 3 + m2 * dot2(v2, v2) + m2 * l2 * l2 / 12 * w2 * w2;
    // V = -sum m g.r, so dV/dq = -sum m g.dr/dq.
    t->G = -(m1 * 0.5 * dot2(g, s.dP) + m2 * dot2(g, v2));
    // Lumped: the link's mass at A does not move; the rocker's at C moves at C'.
    t->I_lumped = m2 * dot2(Cd, Cd);
    t->G_lumped = -m2 * dot2(g, Cd);
    return 0;
}

int linkage_def_from_pose(linkage_def* d, const double P_ref[2], double q_ref, char* err, size_t errsz) {
    double C[2];
    rocker_point(d, q_ref, C);
    double r1[2] = {P_ref[0] - d->link_pin[0], P_ref[1] - d->link_pin[1]};
    double r2[2] = {P_ref[0] - C[0], P_ref[1] - C[1]};
    double ac[2] = {C[0] - d->link_pin[0], C[1] - d->link_pin[1]};
    double l1 = hypot(r1[0], r1[1]), l2 = hypot(r2[0], r2[1]);
    // The side of A->C: the sign of cross(C - A, P - A); relative to l1 |AC|
    // it is the sine of the angle at A, and near 0 the pin is at a toggle.
    double side = cross2(ac, r1);
    double scale = l1 * hypot(ac[0], ac[1]);
    if (!isfinite(side) || !isfinite(l1) || !isfinite(l2) || !(l1 > 0) || !(l2 > 0) || !(fabs(side) > 1e-9 * scale)) {
        if (err && errsz)
            snprintf(err, errsz,
                     "linkage.common_pin: (%g, %g) m at q = %g rad is on the line through the link's and the rocker's "
                     "pins (a toggle: no assembly branch)",
                     P_ref[0], P_ref[1], q_ref);
        return -1;
    }
    d->link_len = l1;
    d->rocker_len = l2;
    d->branch = side > 0 ? 1 : -1;
    return 0;
}

double linkage_cylinder(const linkage* lk, const chain* c, const chain_ws* w, int child, double* Ldot,
                        double* dL_dq, double* dLdot_dq) {
    const int nd = chain_ndof(c), k = chain_body_dof(c, child);
    double qd;
    const double q = chain_joint_q(c, w, child, &qd);
    linkage_state s;
    linkage_eval(lk, q, &s); // NaN where the loop cannot close: every output then NaN
    if (Ldot) *Ldot = s.dL * qd;
    for (int j = 0; j < nd; ++j) {
        if (dL_dq) dL_dq[j] = j == k ? s.dL : 0.0;
        if (dLdot_dq) dLdot_dq[j] = j == k ? s.d2L * qd : 0.0;
    }
    return s.L;
}

void linkage_cylinder_hessian(const linkage* lk, const chain* c, const chain_ws* w, int child, double* H) {
    const int nd = chain_ndof(c), k = chain_body_dof(c, child);
    for (int j = 0; j < nd * nd; ++j) H[j] = 0.0;
    if (k < 0) return;
    linkage_state s;
    linkage_eval(lk, chain_joint_q(c, w, child, NULL), &s);
    H[(size_t)k * (size_t)nd + (size_t)k] = s.d2L;
}
