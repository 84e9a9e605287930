// hyd_cylinder.h: the cylinder's laws (cylinder.c has the equations),
// written once for the reference loop (cylinder.c) and the one-pass kernel
// (circuit_kernel.c).
#ifndef HYD_CYLINDER_H
#define HYD_CYLINDER_H

#include "hyd_internal.h"

#include <math.h>

/// Cylinder end stop (see cylinder.c) of stiffness ks [N/m], damping cs
/// [N s/m] and smoothing width ws [m]: force magnitude for penetration delta
/// and its rate ddelta, with partials d|F|/ddelta (*fd) and d|F|/dddelta (*fv).
static inline double hyd_stop_force(double ks, double cs, double ws, double delta, double ddelta, double* fd,
                                    double* fv) {
    if (delta <= 0.0) {
        *fd = 0.0;
        *fv = 0.0;
        return 0.0;
    }
    const double t = delta / ws;
    double S, dS, dW;
    if (t < 1.0) {
        S = 0.5 * delta * t;
        dS = t;
    } else {
        S = delta - 0.5 * ws;
        dS = 1.0;
    }
    const double W = hyd_smoothstep(t, &dW);
    *fd = ks * dS + cs * dW / ws * ddelta;
    *fv = cs * W;
    return ks * S + cs * W * ddelta;
}

/// The cylinder's laws as expressions of + - * only, one text for a double
/// and the two lanes of circuit_kernel.c: the chamber volumes before their
/// floor, the leakage, and the rod force with the stop forces flo, fhi.
#define HYD_CYL_VA(VA0, AA, x) ((VA0) + (AA) * (x))
#define HYD_CYL_VB(VB0, AB, s, x) ((VB0) + (AB) * ((s) - (x)))
#define HYD_CYL_VMIN(V0) (HYD_VMIN_FRAC * (V0))
#define HYD_CYL_LEAK(CL, pA, pB) ((CL) * ((pA) - (pB)))
#define HYD_CYL_FORCE(AA, AB, bv, pA, pB, v, flo, fhi) ((pA) * (AA) - (pB) * (AB) - (bv) * (v) + (flo) - (fhi))

/// Chamber volumes [m^3] at stroke x [m]: V_A = V_A0 + A_A x, V_B = V_B0 +
/// A_B (s - x), each floored at HYD_VMIN_FRAC of its dead volume; *dVA, *dVB
/// = dV/dx [m^2] (0 once the floor holds V).
static inline void hyd_cyl_volumes(double VA0, double VB0, double AA, double AB, double s, double x,
                                   double* VA, double* VB, double* dVA, double* dVB) {
    const double va = HYD_CYL_VA(VA0, AA, x), vb = HYD_CYL_VB(VB0, AB, s, x);
    const double vamin = HYD_CYL_VMIN(VA0), vbmin = HYD_CYL_VMIN(VB0);
    *VA = va > vamin ? va : vamin;
    *VB = vb > vbmin ? vb : vbmin;
    *dVA = va > vamin ? AA : 0.0;
    *dVB = vb > vbmin ? -AB : 0.0;
}

/// Internal leakage A -> B [m^3/s] with coefficient CL [m^3/(s Pa)].
static inline double hyd_cyl_leak(double CL, double pA, double pB) { return HYD_CYL_LEAK(CL, pA, pB); }

/// Rod force F [N] (+ extends): pA A_A - pB A_B - b_v x' plus the end stops
/// (stiffness ks [N/m], damping cs [N s/m], width ws [m]) below 0 and beyond
/// the stroke s [m]. *dFdx [N/m] and *dFdv [N s/m] are its partials (dF/dpA =
/// A_A and dF/dpB = -A_B need none).
static inline double hyd_cyl_force(double AA, double AB, double bv, double ks, double cs, double ws,
                                   double s, double pA, double pB, double x, double v, double* dFdx,
                                   double* dFdv) {
    // Retracted stop pushes out (+), extended stop pushes in (-).
    double fdl, fvl, fdh, fvh;
    const double flo = hyd_stop_force(ks, cs, ws, -x, -v, &fdl, &fvl);
    const double fhi = hyd_stop_force(ks, cs, ws, x - s, v, &fdh, &fvh);
    *dFdx = -fdl - fdh;
    *dFdv = -bv - fvl - fvh;
    return HYD_CYL_FORCE(AA, AB, bv, pA, pB, v, flo, fhi);
}

/// The seal friction's algebra as expressions of + - * / only (one text for
/// a double and the two lanes of circuit_fast_ls.c; exp and tanh stay the
/// libm functions, called lane by lane): the Stribeck ratio r = v / v_st and
/// the regularisation argument v / v_sm, the magnitude F_c + F_s exp(-r^2)
/// from e = F_s exp(-r^2), the force, and its rate partial.
#define HYD_CYL_SEAL_R(v, vst) ((v) / (vst))
#define HYD_CYL_SEAL_ARG(v, vsm) ((v) / (vsm))
#define HYD_CYL_SEAL_MAG(Fc, e) ((Fc) + (e))
#define HYD_CYL_SEAL_F(mag, th) ((mag) * (th))
#define HYD_CYL_SEAL_DFDV(mag, th, vsm, r, vst, e) ((mag) * (1.0 - (th) * (th)) / (vsm) - 2.0 * (r) / (vst) * (e) * (th))

/// Seal friction [N] (Coulomb + Stribeck, opposing x'), smooth through zero:
///   F_seal = (F_c + F_s exp(-(v/v_st)^2)) tanh(v/v_sm)
/// F_c Coulomb [N], F_s breakaway excess [N] (static force F_c + F_s),
/// v_st Stribeck velocity [m/s], v_sm regularisation width [m/s]. *dFdv [N s/m]
/// is dF_seal/dv. With F_c = F_s = 0 it returns +0.0 and *dFdv = 0, so
/// subtracting it leaves a force bit for bit (x - +0.0 == x for every x).
static inline double hyd_cyl_seal(double Fc, double Fs, double vst, double vsm, double v, double* dFdv) {
    if (Fc == 0.0 && Fs == 0.0) {
        *dFdv = 0.0;
        return 0.0;
    }
    const double r = HYD_CYL_SEAL_R(v, vst), e = Fs * exp(-r * r), th = tanh(HYD_CYL_SEAL_ARG(v, vsm));
    const double mag = HYD_CYL_SEAL_MAG(Fc, e);
    // d/dv: mag (1 - th^2)/v_sm + th dmag/dv, dmag/dv = -2 r e / v_st.
    *dFdv = HYD_CYL_SEAL_DFDV(mag, th, vsm, r, vst, e);
    return HYD_CYL_SEAL_F(mag, th);
}

#endif
