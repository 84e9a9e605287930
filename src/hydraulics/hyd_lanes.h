// hyd_lanes.h: the two-lane (SSE2) helpers shared by the one-pass kernels,
// the standard crane's (circuit_kernel.c) and the load-sensing crane's
// (circuit_fast_ls.c): loads and stores of two lanes, a lane blend, the
// orifice law on both regimes, and Be(P)/V from the gathered table entries.
// Each is the scalar law's header macros on __m128d, so the lanes are bit for
// bit the scalar kernel's; one text for both kernels.
#ifndef HYD_LANES_H
#define HYD_LANES_H

#if defined(__SSE2__) && defined(__GNUC__)
#include <emmintrin.h>
#include <stdint.h>

#include "hyd_internal.h"
#include "hyd_orifice.h"

typedef __m128d v2;

// Memory that nothing wrote just before (model constants, y): a 16-byte load.
// Values a kernel has just produced go lane by lane through _mm_set_pd
// instead: a 16-byte load of two fresh 8-byte stores cannot be
// store-forwarded and stalls.
static inline v2 ld(const double* p) { return _mm_loadu_pd(p); }
static inline v2 set2(double l0, double l1) { return _mm_set_pd(l1, l0); }
// Lanes from two scattered places (i[0], i[1]) and back.
static inline v2 ld_at(const double* y, const int* i) { return _mm_set_pd(y[i[1]], y[i[0]]); }
static inline void st_at(double* y, const int* i, v2 v) {
    _mm_storel_pd(&y[i[0]], v);
    _mm_storeh_pd(&y[i[1]], v);
}
static inline v2 blend(v2 m, v2 a, v2 b) { return _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b)); }

// hyd_orifice_q's flow (hyd_orifice.h), both regimes, blended on |x| < 1.
static inline v2 orifice2(v2 k, v2 invP0, v2 kl, v2 A, v2 sA, v2 dp) {
    const v2 sign = _mm_set1_pd(-0.0);
    const v2 x = HYD_ORIFICE_X(invP0, A, dp);
    const v2 lamm = _mm_cmplt_pd(_mm_andnot_pd(sign, x), _mm_set1_pd(1.0));
    const v2 ql = HYD_ORIFICE_LAMINAR(kl, A, sA, dp, x);
    const v2 sdp = _mm_or_pd(_mm_sqrt_pd(_mm_andnot_pd(sign, dp)), _mm_and_pd(sign, dp)); // copysign
    const v2 qt = HYD_ORIFICE_TURBULENT(k, A, sdp);
    return blend(lamm, ql, qt);
}

// Be(P) / V of two nodes on the table path (hyd_node_c through hyd_be_nd and
// hyd_air_ratio), from each lane's table segment c[l] and octave factor
// oct[l] (hyd_air_index of its pressure's bits; each kernel gathers them
// its own way): the mantissa in [1, 2) in both lanes at once, the air
// polynomial and the modulus.
static inline v2 hyd_node_c2_tab(const hyd_model* m, const double* bel, const double* bec, v2 P, v2 V,
                                 const double* const c[2], const double oct[2]) {
    const __m128i bits = _mm_castpd_si128(P);
    const v2 mant = _mm_castsi128_pd(_mm_or_si128(_mm_and_si128(bits, _mm_set1_epi64x((long long)HYD_AIR_MANT_MASK)),
                                                  _mm_set1_epi64x((long long)HYD_AIR_ONE_BITS)));
#define CO(i) _mm_set_pd(c[1][i], c[0][i])
    const v2 x = mant - CO(HYD_AIR_DEG + 1);
    const v2 x2 = x * x;
    const v2 p = HYD_AIR_POLY(CO, x, x2);
#undef CO
    const v2 rr = set2(oct[0], oct[1]) * p;
    const v2 N = HYD_BE_N(ld(bel), m->be_alpha, rr, P);
    const v2 D = HYD_BE_D(ld(bec), rr, P);
    return HYD_BE_C(N, D, V);
}
#endif
#endif
