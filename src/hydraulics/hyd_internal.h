// hyd_internal.h: module-private layout of the compiled circuit (hyd_model) and
// the per-type evaluation kernels. Not installed; include only from
// src/hydraulics/*.c.
#ifndef HYD_INTERNAL_H
#define HYD_INTERNAL_H

#include "hydraulics.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define HYD_MAXPORT 4
/// pi (M_PI is not part of strict C11).
#define HYD_PI 3.14159265358979323846
/// Chamber volumes never fall below this fraction of their dead volume, so a
/// piston driven far into a stop cannot make V <= 0 (cylinder.c).
#define HYD_VMIN_FRAC 0.05

/// A node or component as the user defined it (names owned by the holder).
/// Kept in the model so live parameter changes and JSON export see the same
/// values that the derived arrays were computed from.
typedef struct hyd_elem {
    hyd_type type;
    char* name;
    char* port[HYD_MAXPORT]; ///< port node names, by the type's port table order
    union {
        hyd_tank_def tank;
        hyd_volume_def volume;
        hyd_pump_def pump;
        hyd_relief_def relief;
        hyd_check_def check;
        hyd_orifice_def orifice;
        hyd_hose_def hose;
        hyd_valve_def valve;
        hyd_cylinder_def cylinder;
    } def;
} hyd_elem;

/// Parameter checking rules (sign and closed ranges; the magnitude is the
/// table's hard range). HYD_R_ZERO_DEF: 0 means "the fluid's value", any
/// other value must be in the hard range.
enum { HYD_R_POS = 0, HYD_R_NONNEG, HYD_R_ANY, HYD_R_UNIT, HYD_R_FRAC, HYD_R_ZERO_DEF };

/// A port of a component type: its name and the offset of its const char*
/// field inside the type's def struct.
typedef struct hyd_port_info {
    const char* name;
    size_t off;
} hyd_port_info;

typedef struct hyd_param_info {
    const char* name;
    const char* unit;
    size_t off;   ///< byte offset of the double inside the type's def struct
    int rule;     ///< HYD_R_*
    int required; ///< must be given in JSON (C defaults leave it 0, which fails the rule)
    double lo, hi;   ///< hard range [unit]: outside it the circuit is refused
    double tlo, thi; ///< typical range [unit]: outside it the loader prints a note
} hyd_param_info;

/// Parameter and port tables of a type (circuit.c).
const hyd_param_info* hyd_params_of(hyd_type t, int* count);
const hyd_port_info* hyd_ports_of(hyd_type t, int* count);
/// Pointer to an element's def struct (the active union member).
void* hyd_elem_def(hyd_elem* e);
const void* hyd_elem_cdef(const hyd_elem* e);
/// Check one value against its rule and hard range; returns 0 or writes a
/// message ("must be in [1e5, 1e8] Pa, got 22") and returns -1.
int hyd_param_check(const hyd_param_info* p, double v, char* msg, size_t msgsz);
/// 0 if v is in the typical range, else -1 with "v is outside the typical range [lo, hi] unit".
int hyd_param_typical(const hyd_param_info* p, double v, char* msg, size_t msgsz);

/// Fluid parameter table (name, unit, offset into hyd_fluid_def).
const hyd_param_info* hyd_fluid_params(int* count);

// ---------------------------------------------------------------------------
// Compiled per-type records. Each holds node indices (into hyd_data node_*)
// and derived constants, so the kernels read one small struct per component.
// ---------------------------------------------------------------------------

typedef struct hyd_pump_c {
    int in, out, comp;
    double qmax, pset, inv_band;
} hyd_pump_c;

/// Relief and check valves share this record: q = q_rated * ramp(dp - p_crack, w).
typedef struct hyd_ramp_c {
    int in, out, comp;
    double pcr, inv_w, qr;
} hyd_ramp_c;

/// Orifice constants: K = k A, p_tr = P0 / A, laminar conductance G = kl A^1.5.
typedef struct hyd_orif_k {
    double k;     ///< cd sqrt(2/rho) [m^1.5/kg^0.5]
    double P0;    ///< p_tr * A [Pa m^2]
    double invP0; ///< 1 / P0
    double kl;    ///< 5 k / (4 sqrt(P0))
} hyd_orif_k;

typedef struct hyd_orifice_c {
    int in, out, comp;
    double A;
    hyd_orif_k ok;
} hyd_orifice_c;

typedef struct hyd_hose_c {
    int node, to, comp;
    double G; ///< laminar conductance [m^3/(s Pa)]
} hyd_hose_c;

typedef struct hyd_valve_c {
    int P, T, A, B, adr, comp;
    double Amax, inv_tau;
    hyd_orif_k ok;
} hyd_valve_c;

typedef struct hyd_cyl_c {
    int nA, nB, sA, sB, comp; ///< chamber nodes and their state indices
    double AA, AB, s, VA0, VB0, CL, bv, ks, cs, ws;
} hyd_cyl_c;

/// Segments per octave of the air-ratio table (a power of two).
#define HYD_AIR_SEG 128
/// Octaves covered: absolute pressures in [1, 2^HYD_AIR_OCT) Pa (the law is
/// only used above HYD_BE_P_LO = 100 Pa; beyond 2^64 Pa the exact law runs).
#define HYD_AIR_OCT 64
/// Degree of the per-segment Taylor polynomial of m^(-1/n).
#define HYD_AIR_DEG 6
/// Below this absolute pressure [Pa] Be is continued by a rational tail (fluid.c).
#define HYD_BE_P_LO 100.0

/// Tables for the air ratio r(P) = (p_a / P)^(1/n) of the entrained-air law,
/// built at derive time (fluid.c). With P = 2^e m, m in [1, 2):
///   r = oct[e] * m^(-1/n),  oct[e] = (2^e / p_a)^(-1/n)
/// and m^(-1/n) is a degree-6 Taylor polynomial about the centre of one of
/// HYD_AIR_SEG segments of [1, 2). The truncation error is below 1e-16
/// relative for n >= 1 (see fluid.c), so r is exact to a few ulp: a fast pow
/// for a fixed exponent, not an approximation of the law.
typedef struct hyd_air_tab {
    int use;                                   ///< 0: evaluate the law with exp/log
    double oct[HYD_AIR_OCT];                   ///< (p_a / 2^e)^(1/n)
    double seg[HYD_AIR_SEG][HYD_AIR_DEG + 2];  ///< Taylor coefficients c_0..c_6, then the centre
} hyd_air_tab;

struct hyd_model {
    hyd_fluid_def fluid;
    int nstate, nnode, ncomp, nunode; ///< nunode: user-declared nodes (first in node order)
    unsigned revision; ///< bumped by every accepted hyd_model_set (packed copies go stale)

    hyd_elem* unode; ///< (nunode) user node definitions
    hyd_elem* comp;  ///< (ncomp) component definitions

    // Nodes: user nodes first, then owned nodes (hoses, cylinder chambers).
    char** node_name;  ///< (nnode)
    int* node_state;   ///< (nnode) state index, or -1 for a tank
    int* node_sidx;    ///< (nnode) state index, or nstate for a tank (dummy row/col)
    double* node_V0;   ///< (nnode) fixed volume [m^3] (0 for chambers: the cylinder sets V)
    double* node_bel;  ///< (nnode) liquid bulk modulus [Pa]
    double* node_pfix; ///< (nnode) tank pressure [Pa abs] (0 for volume nodes)
    double* node_p0;   ///< (nnode) initial pressure [Pa abs]

    int nvol, ntank;
    int* vol_node;  ///< (nvol) state-carrying nodes, in state order of appearance
    int* tank_node; ///< (ntank)

    int npump, nrelief, ncheck, norifice, nhose, nvalve, ncyl;
    hyd_pump_c* pump;
    hyd_ramp_c* relief;
    hyd_ramp_c* check;
    hyd_orifice_c* orifice;
    hyd_hose_c* hose;
    hyd_valve_c* valve;
    hyd_cyl_c* cyl;
    int* comp_sub; ///< (ncomp) index within its type's array
    /// Incidence, CSR over volume nodes in vol_node order: node vol_node[k]
    /// receives flow slots vol_flow[vol_ptr[k] .. vol_ptr[k+1]-1] (indices into
    /// hyd_data flow_, 4 per component: port order pump/relief/check/orifice
    /// [inlet, outlet], hose [own node, to], valve [P, T, A, B], cylinder [A, B]).
    int* vol_ptr;  ///< (nvol + 1)
    int* vol_flow; ///< (vol_ptr[nvol])

    // Fluid constants used by the bulk-modulus law for every node.
    double be_inv_n, be_alpha;
    double* node_bec; ///< (nnode) alpha Be_l / n [Pa], the air term's weight
    hyd_air_tab air;

    char** state_name; ///< (nstate)
    double* y0;        ///< (nstate) initial state
};

/// Recompute every derived array from the definitions (after compile or a
/// parameter change). Returns 0, or -1 with e filled if a value is invalid.
int hyd_model_derive(hyd_model* m, hyd_build_error* e);

// Component derivations (each in its own file).
void hyd_pump_derive(const hyd_pump_def* d, hyd_pump_c* c);
void hyd_relief_derive(const hyd_relief_def* d, hyd_ramp_c* c);
void hyd_check_derive(const hyd_check_def* d, hyd_ramp_c* c);
hyd_orif_k hyd_orifice_constants(const hyd_fluid_def* f, double cd);
void hyd_hose_derive(const hyd_fluid_def* f, const hyd_hose_def* d, hyd_hose_c* c);
double hyd_hose_volume(const hyd_hose_def* d);
void hyd_valve_derive(const hyd_fluid_def* f, const hyd_valve_def* d, hyd_valve_c* c);
void hyd_cylinder_derive(const hyd_cylinder_def* d, hyd_cyl_c* c);
/// Cross-field checks a table cannot express; return 0 or fill field/msg.
int hyd_cylinder_validate(const hyd_cylinder_def* d, char* field, size_t fsz, char* msg,
                          size_t msz);

/// Orifice law on precomputed constants: Q [m^3/s], *g = dQ/ddp, *gA = dQ/dA
/// (see orifice.c). Inline: it runs twice per valve per evaluation, and the
/// caller's unused partials then cost nothing.
static inline double hyd_orifice_q(const hyd_orif_k* k, double A, double dp, double* g, double* gA) {
    const double x = dp * A * k->invP0;
    if (fabs(x) < 1.0) {
        const double sA = sqrt(A);
        const double G = k->kl * A * sA;
        const double x2 = x * x;
        const double lam = 1.0 - 0.2 * x2;
        *g = G * (1.0 - 0.6 * x2);
        // dQ/dA = dG/dA dp (1 - x^2/5) - G dp (2x/5) dx/dA, dx/dA = dp / P0
        *gA = 1.5 * k->kl * sA * dp * lam - G * dp * 0.4 * x * dp * k->invP0;
        return G * dp * lam;
    }
    const double s = sqrt(fabs(dp));
    *g = 0.5 * k->k * A / s;
    *gA = k->k * copysign(s, dp);
    return k->k * A * copysign(s, dp);
}

// ---------------------------------------------------------------------------
// Kernels: each loops over all components of its type, adds flows into
// d->node_q and, when G is non-NULL, flow partials into G, an (n+1) x (n+1)
// row-major matrix indexed by state (tank nodes map to the dummy index n),
// so a kernel needs no branch on node kind.
// ---------------------------------------------------------------------------

void hyd_cylinders_eval(const hyd_model* m, hyd_data* d, double* G);
void hyd_pumps_eval(const hyd_model* m, hyd_data* d, double* G);
void hyd_reliefs_eval(const hyd_model* m, hyd_data* d, double* G);
void hyd_checks_eval(const hyd_model* m, hyd_data* d, double* G);
/// Relief and check kernel on an array of ramp records (relief.c).
void hyd_ramps_eval(const hyd_model* m, hyd_data* d, double* G, const hyd_ramp_c* v, int nv);
void hyd_orifices_eval(const hyd_model* m, hyd_data* d, double* G);
void hyd_hoses_eval(const hyd_model* m, hyd_data* d, double* G);
void hyd_valves_eval(const hyd_model* m, hyd_data* d, const double* y, double* ydot, double* G);
/// hyd_valves_eval without G, circuit state i at y[map[i]] (hyd_eval_mapped).
void hyd_valves_eval_mapped(const hyd_model* m, hyd_data* d, const double* y, double* ydot,
                            const int* map);
/// The plain evaluation with circuit state i written to ydot[map[i]].
void hyd_volumes_eval_mapped(const hyd_model* m, hyd_data* d, double* ydot, const int* map);
/// Pressure derivative of every volume node; with J non-NULL also the node
/// rows of the Jacobian (see volume.c).
void hyd_volumes_eval(const hyd_model* m, hyd_data* d, double* ydot, const double* G, double* J,
                      int ldj);

/// Build m->air from the fluid (fluid.c).
void hyd_air_tab_init(hyd_air_tab* t, const hyd_fluid_def* f);
/// The entrained-air law away from the fast path (P < P_LO, P >= 2^64, NaN,
/// or no table): exact, with exp/log (fluid.c).
double hyd_be_slow(const hyd_model* m, double bel, double P, double* dbe);

/// r(P) = (p_a / P)^(1/n) from the table, for P in [1, 2^HYD_AIR_OCT).
/// The exponent and the top mantissa bits of P index the tables directly, so
/// there is no log, exp or division.
static inline double hyd_air_ratio(const hyd_air_tab* t, double P) {
    uint64_t b;
    memcpy(&b, &P, sizeof b);
    const int e = (int)(b >> 52) - 1023;
    const int j = (int)(b >> (52 - 7)) & (HYD_AIR_SEG - 1);
    const uint64_t mb = (b & 0x000FFFFFFFFFFFFFull) | 0x3FF0000000000000ull;
    double mant;
    memcpy(&mant, &mb, sizeof mant);
    const double* c = t->seg[j];
    const double x = mant - c[HYD_AIR_DEG + 1]; // exact: both in [1, 2]
    // Estrin's scheme: a shorter dependency chain than Horner, same rounding class.
    const double x2 = x * x;
    const double p01 = c[0] + c[1] * x, p23 = c[2] + c[3] * x, p45 = c[4] + c[5] * x;
    const double p = p01 + x2 * (p23 + x2 * (p45 + x2 * c[6]));
    return t->oct[e] * p;
}

/// Numerator and denominator of the law at absolute pressure P for a node with
/// liquid modulus bel and air weight bec = alpha bel / n:
///   Be = N / D,  N = bel (1 + alpha r) P,  D = P + bec r
/// (the SPEC form multiplied through by P, so Be costs one division, which the
/// caller can share with 1/V). Returns 0 when P is off the fast path; the
/// caller then uses hyd_be_slow.
static inline int hyd_be_nd(const hyd_model* m, double bel, double bec, double P, double* N,
                            double* D, double* r) {
    const hyd_air_tab* restrict t = &m->air;
    if (!t->use) {
        // alpha = 0 or an unusual n: constant modulus or the slow path.
        *N = bel, *D = 1.0, *r = 0.0;
        return m->be_alpha == 0.0;
    }
    if (!(P >= HYD_BE_P_LO && P < 18446744073709551616.0)) // 2^64; false for NaN
        return 0;
    const double rr = hyd_air_ratio(t, P);
    *r = rr;
    *N = bel * (1.0 + m->be_alpha * rr) * P;
    *D = P + bec * rr;
    return 1;
}

/// Be / V of a node at absolute pressure P [Pa] and volume V [m^3]: the table
/// path of hyd_be_nd, else the exact law (hyd_be_slow). Optionally Be itself
/// (*be; c V on the table path, saving a division) and dBe/dP (*dbe; on the
/// table path from the same N, D and r, so one table evaluation serves both:
///   dN/dP = bel (1 + alpha r (1 - 1/n)),  dD/dP = 1 - bec r / (n P)).
static inline double hyd_node_c(const hyd_model* m, double bel, double bec, double P, double V, double* be,
                                double* dbe) {
    double N, D, r;
    if (hyd_be_nd(m, bel, bec, P, &N, &D, &r)) {
        const double c = N / (D * V);
        if (be) *be = c * V;
        if (dbe) {
            if (m->air.use) {
                const double iD = 1.0 / D;
                const double b = N * iD;
                const double dN = bel * (1.0 + m->be_alpha * r * (1.0 - m->be_inv_n));
                const double dD = 1.0 - bec * r * m->be_inv_n / P;
                *dbe = (dN - b * dD) * iD;
            } else {
                *dbe = 0.0; // alpha = 0: constant modulus
            }
        }
        return c;
    }
    const double b = hyd_be_slow(m, bel, P, dbe);
    if (be) *be = b;
    return b / V;
}

/// Flow partials of a flow from node a to node b: ga = dq/dp_a, gb = dq/dp_b.
static inline void hyd_jac_flow(const hyd_model* m, double* G, int a, int b, double ga, double gb) {
    const int ld = m->nstate + 1;
    const int sa = m->node_sidx[a], sb = m->node_sidx[b];
    G[sa * ld + sa] -= ga;
    G[sa * ld + sb] -= gb;
    G[sb * ld + sa] += ga;
    G[sb * ld + sb] += gb;
}

/// A flow q from port 0 (node a) to port 1 (node b) of component c: written
/// as "flow into the node at port k" slots, which volume.c gathers per node
/// (a gather keeps each node's sum in a register instead of a chain of
/// read-modify-writes through memory, e.g. on the tank). With G non-NULL the
/// partials ga = dq/dp_a, gb = dq/dp_b are added too.
static inline void hyd_flow2(const hyd_model* m, hyd_data* d, double* G, int c, int a, int b,
                             double q, double ga, double gb) {
    d->flow_[4 * c] = -q;
    d->flow_[4 * c + 1] = q;
    if (G)
        hyd_jac_flow(m, G, a, b, ga, gb);
}

/// C1 smoothstep s(t) = 3t^2 - 2t^3 on [0,1], 0 below, 1 above; *ds = ds/dt.
static inline double hyd_smoothstep(double t, double* ds) {
    if (t <= 0.0) {
        *ds = 0.0;
        return 0.0;
    }
    if (t >= 1.0) {
        *ds = 0.0;
        return 1.0;
    }
    *ds = 6.0 * t * (1.0 - t);
    return t * t * (3.0 - 2.0 * t);
}

/// Relief/check opening law on t = d / w (see relief.c): 0, t^2, then 2t - 1;
/// *dr = d ramp / d d (so it includes 1/w).
static inline double hyd_open_ramp_t(double t, double inv_w, double* dr) {
    if (t <= 0.0) {
        *dr = 0.0;
        return 0.0;
    }
    if (t < 1.0) {
        *dr = 2.0 * t * inv_w;
        return t * t;
    }
    *dr = 2.0 * inv_w;
    return 2.0 * t - 1.0;
}

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


#endif
