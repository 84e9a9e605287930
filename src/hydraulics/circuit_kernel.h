// circuit_kernel.h: the one-pass circuit kernel. The "standard actuator
// circuit" evaluated by one straight-line kernel instead of the general
// per-type component loops (the reference). The names keep their hyd_fused_
// prefix so callers stay source-compatible; hyd_fused.h includes this file.
//
// The general evaluation (hyd_eval) walks component arrays, writes every flow
// into per-port slots and gathers them per node: flexible, but about 2,200
// instructions per call on the crane circuit, most of it bookkeeping. Almost
// every crane circuit has one shape, though:
//
//   tank --pump--> pump line (a volume node), valves P = pump line, T = a tank;
//   per actuator: valve A/B -> hose -> cylinder chamber A/B;
//   reliefs and check valves only between a tank and a volume node.
//
// hyd_fused_build() recognises that shape on a compiled model and packs its
// derived constants per actuator; hyd_fused_eval() then computes the same
// right-hand side (the same component laws, the same Be(p) kernel) in one pass
// with every flow in a register. A circuit of any other shape (orifices,
// valves fed from another node, reliefs between two volumes...) is refused
// with a reason, and the caller keeps the general path. See
// docs/performance.md and the bit-level comparison in
// test_fused in tests/hydraulics/test_circuit.c.
#ifndef HYD_CIRCUIT_KERNEL_H
#define HYD_CIRCUIT_KERNEL_H

#include <stdint.h>

#include "hydraulics.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HYD_FUSED_MAXACT 4  ///< actuators (valve + hoses + cylinder)
#define HYD_FUSED_MAXRAMP 4 ///< reliefs/checks between one node and a tank

/// A relief (flow out of the node to a tank) or check valve (flow from a tank
/// into the node), q = qr ramp((dp - pcr) / w).
typedef struct hyd_fused_ramp {
    double pcr, inv_w, qr; ///< cracking pressure [Pa], 1/override band [1/Pa], rated flow [m^3/s]
    double p_tank;         ///< pressure of the tank at the other end [Pa abs]
    int into;              ///< 1: check valve (tank -> node), 0: relief (node -> tank)
} hyd_fused_ramp;

/// A pressure node: its state index (caller order), fixed volume, liquid
/// modulus and air weight, and the ramps to tanks.
typedef struct hyd_fused_node {
    int s;                 ///< state index in the caller's vector
    double V0;             ///< fixed volume [m^3] (0 for chambers)
    double bel, bec;       ///< liquid modulus [Pa], alpha bel / n [Pa]
    int nramp;
    hyd_fused_ramp ramp[HYD_FUSED_MAXRAMP];
    /// Every ramp is closed while p_lo < p < p_hi [Pa abs] (checks crack
    /// below p_lo, reliefs above p_hi): the common case costs two compares.
    double p_lo, p_hi;
    double p_knee;         ///< Be(p) < 0.9 bel below it [Pa abs] (0: no air, constant Be)
} hyd_fused_node;

typedef struct hyd_fused_act {
    int su;                ///< spool state index (caller order)
    hyd_fused_node hA, hB, cA, cB; ///< hoses and chambers
    double Amax, inv_tau;  ///< valve: full opening area [m^2], 1 / spool time constant [1/s]
    double ok, oinvP0, okl; ///< orifice constants (hyd_orif_k: k, 1/P0, kl)
    double pT;             ///< valve tank pressure [Pa abs]
    double GA, GB;         ///< hose conductances [m^3/(s Pa)]
    double AA, AB, s, VA0, VB0, CL, bv, ks, cs, ws; ///< cylinder (hyd_cyl_c)
    double Fc, Fs, vst, vsm;                        ///< seal friction (hyd_cyl_seal)
    double inv_ws;         ///< 1 / ws [1/m] (the end stops' event levels)
} hyd_fused_act;

/// Coupling partials of one actuator for the mechanics (hyd_fused_jacobian).
typedef struct hyd_fused_coupling {
    double dA_dx, dA_dv;   ///< d pA' / dx [Pa/(s m)], d pA' / dx' [Pa/m]
    double dB_dx, dB_dv;
    double dF_dx, dF_dv;   ///< cylinder force partials [N/m], [N s/m] (dF/dpA = AA, dF/dpB = -AB)
} hyd_fused_coupling;

/// Two actuators side by side, lane k = actuator k, for the two-lane kernel
/// (hyd_fused_eval2). Node order in the [4] arrays: hose A, hose B, chamber A,
/// chamber B.
typedef struct hyd_fused_lanes {
    double Amax[2], inv_tau[2], ok[2], oinvP0[2], okl[2], pT[2], GA[2], GB[2];
    double AA[2], AB[2], s[2], VA0[2], VB0[2], VAmin[2], VBmin[2], CL[2], bv[2];
    double hV0[2][2];      ///< hose volumes [side A, B][lane] [m^3]
    double bel[4][2], bec[4][2], p_lo[4][2], p_hi[4][2];
    int su[2], s_node[4][2]; ///< state indices (caller order)
} hyd_fused_lanes;

typedef struct hyd_fused {
    const hyd_model* m;    ///< the model the constants came from
    int nact;
    hyd_fused_act act[HYD_FUSED_MAXACT];
    hyd_fused_node pl;     ///< the pump line
    double qmax, pset, inv_band, p_in; ///< pump; p_in: its tank pressure [Pa abs]
    int lanes_ok;          ///< nact == 2 and the air tables are in use: hyd_fused_eval2 applies
    hyd_fused_lanes ln;
    int nev;               ///< pressure nodes: 4 nact + 1
    int ev_s[4 * HYD_FUSED_MAXACT + 1]; ///< their state indices in hyd_fused_events' slot order
    int stops_plain;       ///< two actuators, 1/ws finite and > 0 (the events' two-lane stop check)
    double stroke2[2];     ///< the two strokes s [m], side by side
    int seal;              ///< some cylinder has seal friction (else its terms are skipped)
} hyd_fused;

/// Pack model m for actuators k = 0..nact-1 (valve[k] drives cylinder[k];
/// model indices). Returns 0, or -1 with the reason in why when the circuit is
/// not of the standard shape. State indices are the circuit's own until
/// hyd_fused_map. Rebuild after any hyd_model_set.
int hyd_fused_build(const hyd_model* m, const int* valve, const int* cyl, int nact, hyd_fused* f,
                    char* why, size_t whysz);

/// Renumber states: circuit state i lives at y[map[i]] from now on.
void hyd_fused_map(hyd_fused* f, const int* map);

/// ydot of every circuit state and the cylinder forces F[k] [N], given the
/// strokes x [m], rates v [m/s] and valve commands cmd [-] of the actuators.
/// The same laws as hyd_eval, summed in a different order (agreement to
/// rounding, not bit for bit).
void hyd_fused_eval(const hyd_fused* f, const double* y, const double* x, const double* v,
                    const double* cmd, double* ydot, double* F);

/// The same as hyd_fused_eval, bit for bit, with the two actuators of a
/// two-actuator circuit in the two lanes of SSE2 registers. It takes the
/// common case only (no end stop touched, every pressure on the fast path of
/// the Be(p) tables) and hands anything else to hyd_fused_eval. Without SSE2, or unless f->lanes_ok, it is hyd_fused_eval.
void hyd_fused_eval2(const hyd_fused* f, const double* y, const double* x, const double* v,
                     const double* cmd, double* ydot, double* F);

/// The circuit's Jacobian rows, written into J (row-major, leading dimension
/// ldj, caller's state order): only the non-zero entries of the circuit's
/// rows and columns are written, so J must be zeroed by the caller. Also
/// ydot and F as hyd_fused_eval, and the coupling partials per actuator.
void hyd_fused_jacobian(const hyd_fused* f, const double* y, const double* x, const double* v,
                        const double* cmd, double* ydot, double* F, double* J, int ldj,
                        hyd_fused_coupling* cpl);

/// A spool opening that is no opening [-, of full stroke]: 1e-12 (an orifice
/// area of 1e-12 A_max). A spool lag towards a command of 0 gets there 27.6
/// time constants after the command (0.83 s at tau = 30 ms); the callers'
/// hyd_problem.settle then set it to exactly 0.
#define HYD_SPOOL_SETTLE 1e-12

/// A valve command change between two calls of hyd_fused_events_update that
/// counts as a command step [-]: 5 % of the full opening (a ramp of the
/// shipped scenarios moves at most 1e-3 per 1 ms step, their steps 0.6 to
/// 0.8).
#define HYD_FUSED_CMD_EVENT 0.05

/// An event counter for hyd_problem.events on a fused circuit: where each
/// piecewise law stood at the previous call (see hyd_fused_events_update).
typedef struct hyd_fused_events {
    unsigned long count;   ///< switches seen so far
    double cmd[HYD_FUSED_MAXACT]; ///< commands at the previous call [-]
    int oct[4 * HYD_FUSED_MAXACT + 1]; ///< pressure octave per node below its knee (hoses, chambers, pump line)
    unsigned char lv[(4 * HYD_FUSED_MAXACT + 1) * HYD_FUSED_MAXRAMP]; ///< ramp levels: 0 closed, 1 on the corner, 2 open
    unsigned char stop[2 * HYD_FUSED_MAXACT]; ///< end stops (low, high): 0 free, 1 in the width, 2 engaged
    unsigned char pump;    ///< the pump's cut-off: 0 below its band, 1 in it, 2 above
    int have;              ///< the fields above are set
    /// Per node (as oct): its octave and ramp levels hold while hold_lo < p <
    /// hold_hi [Pa abs], so the node needs no evaluation (NaN: always one).
    double hold_lo[4 * HYD_FUSED_MAXACT + 1], hold_hi[4 * HYD_FUSED_MAXACT + 1];
    const hyd_fused* hold_f; ///< the record and model revision the intervals were taken from
    unsigned hold_rev;
} hyd_fused_events;

/// Count a switch that stiffens the circuit since the previous call: a
/// command cmd[k] (k < f->nact) moving by more than HYD_FUSED_CMD_EVENT (a
/// NaN counts), a relief or check valve reaching or passing the corner of
/// its opening law, an end stop engaging or pressing beyond its smoothing
/// width, the pump line entering the pump's cut-off band, a node below the
/// knee of its bulk-modulus law (p_knee) rising into a higher octave of
/// pressure (Be, and with it the node's stiffness, grows about 3x per
/// octave there). Switches back are not counted: a J from before them
/// overestimates the stiffness, which the W-methods tolerate (circuit_kernel.c).
/// Returns the count. y in the caller's order, x the strokes [m].
unsigned long hyd_fused_events_update(hyd_fused_events* e, const hyd_fused* f, const double* y,
                                      const double* x, const double* cmd);

#ifdef __cplusplus
}
#endif
#endif
