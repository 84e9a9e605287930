// lagrange.c: mass matrix, velocity and gravity terms of the 2-DOF crane.
#include "lagrange.h"

#include <math.h>
#include <string.h>

static const char* const variant_names[] = {"full", "paper", "paper-typo", "general"};

const char* lagrange_variant_name(lagrange_variant v) {
    return (unsigned)v < 4 ? variant_names[v] : "?";
}

int lagrange_variant_parse(const char* s) {
    for (int i = 0; i < 4; ++i)
        if (!strcmp(s, variant_names[i])) return i;
    return -1;
}

void lagrange_eval_terms(const crane_mech* m, lagrange_variant v, double m3, const double q[2],
                         const double qd[2], lagrange_terms* o) {
    const double trig[4] = {sin(q[0]), cos(q[0]), sin(q[1]), cos(q[1])};
    lagrange_eval_terms_trig(m, v, m3, trig, qd, o);
}

void lagrange_eval_terms_trig(const crane_mech* m, lagrange_variant v, double m3, const double trig[4],
                              const double qd[2], lagrange_terms* o) {
    if (v == LAGRANGE_GENERAL) v = LAGRANGE_FULL; // the same equations
    // The paper's Eq. 2 is the point-mass special case (I = 0 in the constants).
    lagrange_consts lk;
    lagrange_consts_init(m, v, m3, &lk);
    const double kc = lk.kc, H22 = lk.H22;

    // One sincos pair per angle; sin/cos(q1 + q2) by the addition identities.
    const double s1 = trig[0], c1 = trig[1];
    const double s2 = trig[2], c2 = trig[3];
    const double s12 = s1 * c2 + c1 * s2, c12 = c1 * c2 - s1 * s2;

    o->H[0][0] = lk.H11c + 2.0 * kc * c2;
    o->H[0][1] = o->H[1][0] = H22 + kc * c2;
    o->H[1][1] = H22;
    o->dH_dq2[0][0] = -2.0 * kc * s2;
    o->dH_dq2[0][1] = o->dH_dq2[1][0] = -kc * s2;
    o->dH_dq2[1][1] = 0.0;

    if (v == LAGRANGE_FULL) {
        const double k = kc * s2;
        o->C[0] = -k * (2.0 * qd[0] * qd[1] + qd[1] * qd[1]);
        o->C[1] = k * qd[0] * qd[0];
        const double dk = kc * c2;
        o->dC_dq2[0] = -dk * (2.0 * qd[0] * qd[1] + qd[1] * qd[1]);
        o->dC_dq2[1] = dk * qd[0] * qd[0];
        o->dC_dqd1[0] = -2.0 * k * qd[1];
        o->dC_dqd1[1] = 2.0 * k * qd[0];
        o->dC_dqd2[0] = -2.0 * k * (qd[0] + qd[1]);
        o->dC_dqd2[1] = 0.0;
    } else {
        // The paper neglects C at the crane's low angular speeds.
        o->C[0] = o->C[1] = 0.0;
        o->dC_dq2[0] = o->dC_dq2[1] = 0.0;
        o->dC_dqd1[0] = o->dC_dqd1[1] = 0.0;
        o->dC_dqd2[0] = o->dC_dqd2[1] = 0.0;
    }

    const double A = lk.A, B = lk.B;
    o->G[0] = A * s1 + B * s12;
    o->G[1] = B * s12;
    o->dG_dq1[0] = A * c1 + B * c12;
    o->dG_dq1[1] = B * c12;
    o->dG_dq2[0] = B * c12;
    o->dG_dq2[1] = B * c12;
}

void lagrange_accel(const lagrange_terms* t, const double tau[2], double qdd[2]) {
    // 2x2 inverse in closed form (the paper's point: no decomposition needed).
    const double r0 = tau[0] - t->C[0] - t->G[0];
    const double r1 = tau[1] - t->C[1] - t->G[1];
    const double det = t->H[0][0] * t->H[1][1] - t->H[0][1] * t->H[1][0];
    qdd[0] = (t->H[1][1] * r0 - t->H[0][1] * r1) / det;
    qdd[1] = (t->H[0][0] * r1 - t->H[1][0] * r0) / det;
}

void lagrange_consts_init(const crane_mech* m, lagrange_variant v, double m3, lagrange_consts* k) {
    if (v == LAGRANGE_GENERAL) v = LAGRANGE_FULL; // the same equations
    const double g = m->gravity;
    const double L1 = m->link[0].length, L2 = m->link[1].length;
    const double m1 = m->link[0].mass, m2 = m->link[1].mass;
    const double e1 = m->link[0].com, e2 = m->link[1].com;
    const double I1 = v == LAGRANGE_FULL ? m->link[0].inertia : 0.0;
    const double I2 = v == LAGRANGE_FULL ? m->link[1].inertia : 0.0;
    const double mu = m2 * e2 + m3 * L2;
    k->kc = mu * L1;
    k->H22 = I2 + m2 * e2 * e2 + m3 * L2 * L2;
    k->H11c = I1 + m1 * e1 * e1 + (m2 + m3) * L1 * L1 + k->H22;
    // Eq. 3 as printed has (m2 + m3) L2 where the derivation gives (m2 + m3) L1.
    const double Lg = v == LAGRANGE_PAPER_TYPO ? L2 : L1;
    k->A = (m1 * e1 + (m2 + m3) * Lg) * g;
    k->B = mu * g;
    k->coriolis = v == LAGRANGE_FULL;
}

void lagrange_accel_fast(const lagrange_consts* k, const double trig[4], const double qd[2],
                         const double tau[2], double qdd[2]) {
    const double s1 = trig[0], c1 = trig[1], s2 = trig[2], c2 = trig[3];
    const double s12 = s1 * c2 + c1 * s2;
    const double kc2 = k->kc * c2;
    const double H00 = k->H11c + 2.0 * kc2, H01 = k->H22 + kc2, H11 = k->H22;
    double C0 = 0.0, C1 = 0.0;
    if (k->coriolis) {
        const double ks = k->kc * s2;
        C0 = -ks * (2.0 * qd[0] * qd[1] + qd[1] * qd[1]);
        C1 = ks * qd[0] * qd[0];
    }
    const double Bs = k->B * s12;
    const double r0 = tau[0] - C0 - (k->A * s1 + Bs);
    const double r1 = tau[1] - C1 - Bs;
    const double det = H00 * H11 - H01 * H01;
    qdd[0] = (H11 * r0 - H01 * r1) / det;
    qdd[1] = (H00 * r1 - H01 * r0) / det;
}

// Cody-Waite: pi/2 = P1 + P2 + P3, P1 and P2 with 33 significant bits, so
// n P1 and n P2 are exact for |n| < 2^20 (|x| < 1e5 gives |n| < 65,000).
// Taylor remainders on |r| <= pi/4: r^17/17! < 5e-17 (sin), r^18/18! < 3e-18
// (cos), below half an ulp of the results there.
void lagrange_sincos(double x, double* s, double* c) {
    if (!(fabs(x) < 1e5)) {
        *s = sin(x);
        *c = cos(x);
        return;
    }
    static const double P1 = 1.5707963267341256e+00; // 0x3FF921FB54400000
    static const double P2 = 6.0771005063039660e-11; // 0x3DD0B4611A600000
    static const double P3 = 2.0222662487959506e-21; // pi/2 - P1 - P2
    static const double TWO_OVER_PI = 6.3661977236758138e-01;
    // Round to nearest by the 1.5 * 2^52 trick (no libm call, no SSE4.1).
    const double big = 6755399441055744.0;
    const double fn = (x * TWO_OVER_PI + big) - big;
    const double r = ((x - fn * P1) - fn * P2) - fn * P3;
    const double r2 = r * r;
    const double sp =
        r + r * r2 *
                (-1.0 / 6 + r2 * (1.0 / 120 + r2 * (-1.0 / 5040 + r2 * (1.0 / 362880 +
                 r2 * (-1.0 / 39916800 + r2 * (1.0 / 6227020800.0 + r2 * (-1.0 / 1307674368000.0)))))));
    const double cp =
        1.0 + r2 * (-0.5 + r2 * (1.0 / 24 + r2 * (-1.0 / 720 + r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800 +
              r2 * (1.0 / 479001600 + r2 * (-1.0 / 87178291200.0 + r2 * (1.0 / 20922789888000.0))))))));
    switch ((long)fn & 3) {
    case 0: *s = sp, *c = cp; break;
    case 1: *s = cp, *c = -sp; break;
    case 2: *s = -sp, *c = -cp; break;
    default: *s = -cp, *c = sp; break;
    }
}

double lagrange_energy(const crane_mech* m, double m3, const double q[2], const double qd[2]) {
    lagrange_terms t;
    lagrange_eval_terms(m, LAGRANGE_FULL, m3, q, qd, &t);
    const double T = 0.5 * (t.H[0][0] * qd[0] * qd[0] + 2.0 * t.H[0][1] * qd[0] * qd[1] +
                            t.H[1][1] * qd[1] * qd[1]);
    const double g = m->gravity;
    const double L1 = m->link[0].length, L2 = m->link[1].length;
    const double m1 = m->link[0].mass, m2 = m->link[1].mass;
    const double e1 = m->link[0].com, e2 = m->link[1].com;
    // Heights of the mass centres: z = -e cos(angle from downward vertical).
    const double V = -(m1 * e1 + (m2 + m3) * L1) * g * cos(q[0]) - (m2 * e2 + m3 * L2) * g * cos(q[0] + q[1]);
    return T + V;
}

void lagrange_gravity(const crane_mech* m, lagrange_variant v, double m3, const double q[2], double G[2]) {
    if (v == LAGRANGE_GENERAL) v = LAGRANGE_FULL; // the same equations
    lagrange_terms t;
    const double qd[2] = {0, 0};
    lagrange_eval_terms(m, v, m3, q, qd, &t);
    G[0] = t.G[0];
    G[1] = t.G[1];
}
