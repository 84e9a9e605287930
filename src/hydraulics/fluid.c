// fluid.c: fluid properties and the effective bulk modulus Be(p).
//
// Be(p) follows the entrained-air law of docs/hydraulics.md, written in absolute
// pressure P = p_a + p_gauge:
//   r(P)  = (p_a / P)^(1/n)                  (free-air volume per unit air at p_a)
//   Be(P) = Be_l (1 + alpha r) / (1 + alpha Be_l r / (n P))
// It tends to n P as P -> 0, so a node cannot be pushed through absolute zero
// by a finite flow. Below P_LO the law is continued by a tail that matches
// value and slope, so an integrator that overshoots into P <= 0 still
// gets a positive, C1 modulus instead of pow() of a negative number (NaN).
// The continuation is rational, Be_lo^2 / (Be_lo + Be'_lo (P_LO - P)): it
// matches value and slope at P_LO and decays like 1/|P| without underflowing
// to 0 (a zero modulus would freeze the node).
//
// Speed. The law runs once per pressure node per f evaluation, and pow() (as
// exp(log)) was ~40 % of a whole crane step. A compiled model therefore takes
// r = (p_a/P)^(1/n) from tables built here at derive time (hyd_air_ratio in
// hyd_internal.h): P = 2^e m splits r into oct[e] (one pow per octave, exact
// to rounding) times m^(-1/n) on [1, 2), which is a degree-6 Taylor polynomial
// about the centre of one of 128 segments. With |x| <= 1/256 the remainder is
// |binom(-1/n, 7)| (1/256)^7 < 1.4e-17 for n >= 1, so r and Be agree with
// exp(log) to a few ulp (tests/hydraulics/test_components.c checks 1e-13 over
// the whole range). The law is then written with one division (see
// hyd_be_nd). The public hyd_bulk_modulus keeps the plain exp/log form as the
// reference.
#include "hyd_internal.h"

#include <math.h>

hyd_fluid_def hyd_default_fluid_def(void) {
    hyd_fluid_def f;
    f.density = 870.0;
    f.viscosity = 32e-6;
    f.bulk_modulus = 1.2e9;
    f.air_fraction = 0.005;
    f.polytropic_index = 1.4;
    f.p_atm = 101325.0;
    f.re_transition = 100.0;
    return f;
}

// The law itself at P >= P_LO; alpha = 0 reduces it to Be_l exactly, which is
// the constant-bulk-modulus option (and skips the pow()). Written with two
// divisions (1/P, 1/D). Compiled models use it only off the table's range
// (hyd_be_slow); hyd_bulk_modulus is the reference the table is tested on.
//   q = (alpha Be_l / n) r / P,  D = 1 + q,  N = 1 + alpha r
//   dN/dP = -alpha r / (n P),    dD/dP = -(1 + 1/n) q / P
static double be_law(double alpha, double inv_n, double pa, double bel, double P, double* dbe) {
    if (alpha == 0.0) {
        *dbe = 0.0;
        return bel;
    }
    const double iP = 1.0 / P;
    const double r = exp(-inv_n * log(P / pa)); // (p_a/P)^(1/n); exp(log) is cheaper than pow
    const double ar = alpha * r;
    const double q = bel * inv_n * ar * iP;
    const double iD = 1.0 / (1.0 + q);
    const double be = bel * (1.0 + ar) * iD;
    const double dN = -inv_n * ar * iP;
    const double dD = -(1.0 + inv_n) * q * iP;
    *dbe = (bel * dN - be * dD) * iD;
    return be;
}

static double be_eval(double alpha, double inv_n, double pa, double bel, double P, double* dbe) {
    double d;
    if (P >= HYD_BE_P_LO) {
        double be = be_law(alpha, inv_n, pa, bel, P, &d);
        if (dbe)
            *dbe = d;
        return be;
    }
    // C1 rational continuation below P_LO (see the file comment).
    const double be_lo = be_law(alpha, inv_n, pa, bel, HYD_BE_P_LO, &d);
    const double den = be_lo + d * (HYD_BE_P_LO - P);
    const double be = be_lo * be_lo / den;
    if (dbe)
        *dbe = be * d / den;
    return be;
}

double hyd_bulk_modulus(const hyd_fluid_def* f, double be_liquid, double p, double* dbe) {
    return be_eval(f->air_fraction, 1.0 / f->polytropic_index, f->p_atm, be_liquid, p, dbe);
}

double hyd_be_slow(const hyd_model* m, double bel, double P, double* dbe) {
    return be_eval(m->be_alpha, m->be_inv_n, m->fluid.p_atm, bel, P, dbe);
}

// Below n = 1 the Taylor remainder grows (|binom(-1/n, 7)| is 36 at n = 1/3);
// such fluids keep the exact exp/log path rather than a weaker guarantee.
void hyd_air_tab_init(hyd_air_tab* t, const hyd_fluid_def* f) {
    const double a = -1.0 / f->polytropic_index;
    t->use = f->air_fraction > 0.0 && f->polytropic_index >= 1.0;
    if (!t->use)
        return;
    for (int e = 0; e < HYD_AIR_OCT; ++e)
        t->oct[e] = pow(ldexp(1.0, e) / f->p_atm, a);
    for (int j = 0; j < HYD_AIR_SEG; ++j) {
        const double mc = 1.0 + (j + 0.5) / HYD_AIR_SEG;
        // f(mc + x) = sum_k binom(a, k) mc^(a - k) x^k
        double binom = 1.0;
        for (int k = 0; k <= HYD_AIR_DEG; ++k) {
            t->seg[j][k] = binom * pow(mc, a - k);
            binom *= (a - k) / (k + 1);
        }
        t->seg[j][HYD_AIR_DEG + 1] = mc;
    }
}
