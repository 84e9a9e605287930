// circuit_fast_ls.h: the fast kernel's one-pass evaluation of the
// load-sensing crane layout (internal to circuit_fast.c; see
// circuit_fast_ls.c for the layout and why it is bit for bit the loops).
#ifndef HYD_CIRCUIT_FAST_LS_H
#define HYD_CIRCUIT_FAST_LS_H

#include "hyd_internal.h"
#include "hyd_ls_pump.h"
#include "hyd_shuttle.h"

/// A section's nodes, in the order of the slots (slot 2 j + lane): the valve's
/// P (the compensator's outlet), the section's LS node, the two hoses, the
/// counterbalance valve's valve-side node, its pilot volume, the chambers.
enum { LSK_P, LSK_LS, LSK_HA, LSK_HB, LSK_CV, LSK_PI, LSK_CA, LSK_CB, LSK_NSEC };
#define LSK_PL (2 * LSK_NSEC)     ///< slot of the pump line
#define LSK_LL (2 * LSK_NSEC + 1) ///< slot of the LS line
#define LSK_NSLOT (2 * LSK_NSEC + 2)
#define LSK_MAXRAMP 16

/// A relief or check valve of the layout, in the reference loops' order
/// (reliefs, then checks, each in record order): its ends as slots (-1: a
/// tank, at pin / pout) and its law's constants.
typedef struct hyd_fast_ls_ramp {
    int in, out;
    double pin, pout;      ///< tank pressures [Pa abs] (ends with slot -1)
    double pcr, inv_w, qr; ///< hyd_ramp_q's constants
} hyd_fast_ls_ramp;

/// The layout's constants, packed for two lanes (lane 0: the first record of
/// each section type, the lift; lane 1: the second, the jib).
typedef struct hyd_fast_ls {
    int ok;                    ///< the layout was recognised (else the loops run)
    char why[160];             ///< why not, when !ok (hyd_fast_lanes_why)
    int node[LSK_NSLOT];       ///< model node of each slot
    int s[LSK_NSLOT];          ///< its state in the caller's order
    double bel[LSK_NSLOT], bec[LSK_NSLOT], V0[LSK_NSLOT];
    int nramp;
    hyd_fast_ls_ramp ramp[LSK_MAXRAMP];
    /// Every relief and check is closed (t <= 0, the loops skip it) exactly
    /// when lo <= p <= hi in every slot [Pa abs] (hyd_fast_ls_pack finds the
    /// bounds on the ramps' own rounded t). ramp_any: a ramp between two
    /// volumes, which no bound describes (the ramps are then tried each time).
    double lo[LSK_NSLOT], hi[LSK_NSLOT];
    int ramp_any;
    hyd_ls_pump_c pump;        ///< adr in the caller's order
    double pump_pin;           ///< its inlet tank's pressure [Pa abs]
    hyd_shuttle_c lssh;        ///< the LS shuttle (max-select) of the two sections' LS nodes
    // Per lane.
    int su[2], sx[2], sc[2];   ///< states: valve spool, compensator spool, counterbalance spool
    int vi[2], ci[2];          ///< valve index (valve_cmd), cylinder index (cyl_x, cyl_F)
    double Amax[2], vtau[2], vk[2], vinvP0[2], vkl[2], pT[2];     ///< valve (hyd_valve_c), its tank [Pa abs]
    double shG[2], shinv_uw[2];                                   ///< section shuttle (spool mode)
    double GA[2], GB[2];                                          ///< hoses A, B
    double oA[2], osA[2], ok_[2], oinvP0[2], okl[2];              ///< damping orifice, sqrt of its area
    double cA[2], cset[2], cinv_band[2], ctau[2], ck[2], cinvP0[2], ckl[2];
    double cpost[2];           ///< all bits set: post-compensated (the target follows p_in - p_ref)
    double bpset[2], bR[2], binv_band[2], bA[2], btau[2], bccr[2], binv_cw[2], bcq[2];
    double bk[2], binvP0[2], bkl[2];
    double bvent[2];           ///< all bits set: spring chamber vented to bpvent
    double bpvent[2];
    double AA[2], AB[2], stroke[2], VA0[2], VB0[2], VAmin[2], VBmin[2], CL[2], bv[2];
    double Fc[2], Fs[2], vst[2], vsm[2];
    int seal;                  ///< some cylinder has seal friction
    int avx;                   ///< take the AVX form of the kernel (hyd_fast_ls_avx)
    int seal_l[2];             ///< cylinder l has (F_c or F_s non-zero)
    double seal_m[2];          ///< all bits set where seal_l
} hyd_fast_ls;

/// Recognise the layout on model m with the caller's state order smap and
/// node states ns (hyd_fast's), and pack it into L; L->ok = 0 with the reason
/// in L->why when m is of any other shape (or the air tables are off, or SSE2
/// is missing). The recognition is an allow-list: the exact number of
/// components of each type the pass packs (reliefs and checks: any, up to
/// LSK_MAXRAMP), none of any other type, and every connection checked.
void hyd_fast_ls_pack(const hyd_model* m, const int* smap, const int* ns, hyd_fast_ls* L);

/// Take the AVX form of the one-pass kernel (on, and the CPU has AVX) or the
/// SSE2 form; the same values bit for bit. hyd_fast_ls_pack chooses AVX.
void hyd_fast_ls_avx(hyd_fast_ls* L, int on);

/// hyd_fast_eval on the layout in one pass. Returns 0 without writing
/// anything when the state is not the common case (an end stop touched, a
/// pressure off the Be table): the caller then runs the loops.
int hyd_fast_ls_eval(const hyd_fast_ls* L, const hyd_model* m, hyd_data* d, const double* y, double* ydot);

#endif
