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

/// Room for the largest def struct in an element (hyd_elem.def.raw). Each
/// component file asserts its def fits, so a new component needs no edit here.
#define HYD_DEF_MAX 192

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
        double align_;
        unsigned char raw[HYD_DEF_MAX]; ///< any type's def, by its descriptor's def_size
    } def;
} hyd_elem;

/// Parameter checking rules (sign and closed ranges; the magnitude is the
/// table's hard range). HYD_R_ZERO_DEF: 0 means "the fluid's value", any
/// other value must be in the hard range.
enum { HYD_R_POS = 0, HYD_R_NONNEG, HYD_R_ANY, HYD_R_UNIT, HYD_R_FRAC, HYD_R_ZERO_DEF };

/// A port of a component type: its name and the offset of its const char*
/// field inside the type's def struct. ref = 1: not a node but the optional
/// name of another component (a shuttle's "valve", whose spool it follows);
/// the type's bind_ref hook resolves it and names the node of its flow slot.
typedef struct hyd_port_info {
    const char* name;
    size_t off;
    int ref;
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

/// Table entries: HYD_PARAM(def type, field, unit, rule, required, hard lo, hi,
/// typical lo, hi); HYD_PORT(def type, field); HYD_COUNT(array).
#define HYD_PARAM(T, f, unit, rule, req, lo, hi, tlo, thi) {#f, unit, offsetof(T, f), rule, req, lo, hi, tlo, thi}
#define HYD_PORT(T, f) {#f, offsetof(T, f), 0}
/// An optional component reference (hyd_port_info.ref); at most one per type,
/// and the last of its ports.
#define HYD_PORT_REF(T, f) {#f, offsetof(T, f), 1}
#define HYD_COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))
/// A def struct must fit the element's storage (hyd_elem.def.raw).
#define HYD_DEF_FITS(T) _Static_assert(sizeof(T) <= HYD_DEF_MAX, #T " is larger than HYD_DEF_MAX")

/// A node an element owns: a tank or volume owns itself, a hose its volume,
/// a cylinder its two chambers.
typedef struct hyd_owned_node {
    const char* suffix; ///< node name "<element>.<suffix>", or NULL: the element's own name
    const char* state;  ///< its pressure state "<element>.<state>", or NULL: a fixed-pressure node
} hyd_owned_node;

/// Flow slots per component: hyd_data.flow_ holds this many "flow into the
/// node at slot k" entries per component; slots are the owned nodes, then
/// the ports, in table order.
#define HYD_MAXSLOT 4

/// One element type, as data: everything the builder, the compiler, the JSON
/// loader, live parameters and the reference evaluation need to know about it.
/// Each component file defines one (hyd_<type>_component) and component_table.c
/// lists them by hyd_type. Hooks that a type does not need are NULL.
typedef struct hyd_component {
    hyd_type type;
    const char* name;  ///< type name in JSON ("pump")
    int is_node;       ///< 1: listed under "nodes" (tank, volume); 0: under "components"
    size_t def_size;   ///< sizeof its hyd_<type>_def (every def starts with const char* name)
    const hyd_param_info* params;
    int nparam;
    const hyd_port_info* ports; ///< ports (const char* fields of the def naming nodes)
    int nport;
    const hyd_owned_node* nodes; ///< nodes it creates, in node order
    int nnode;
    const char* const* states; ///< states other than its nodes' pressures ("spool"), after them
    int nstate;
    size_t rec_size;   ///< its packed record in hyd_model.rec[type] (0: none, for user nodes)
    /// Role its port k gives the node there (hyd_model_node_role): NULL, or
    /// nport entries, HYD_NODE_LINE for "no role" (a LS pump's outlet is a
    /// supply node, its "ls" port a load-sensing line).
    const hyd_node_role* port_roles;
    /// 1: the rates of its own states depend on the pressures at its flow
    /// slots (a lag whose set point is a pressure: LS pump displacement,
    /// counterbalance spool, accumulator oil volume), so its state rows
    /// are not diagonal (hyd_model_jacobian_pattern). 0: a lag on its own
    /// state only (the valve spool).
    int states_sense_ports;
    /// NULL, or per states[] entry the magnitude [the state's unit] below
    /// which hyd_model_flush sets it to exactly 0 (0: never). For states
    /// whose lag closes towards 0 (a spool's opening, a pump's
    /// displacement): it decays geometrically, never gets there, and ends
    /// in subnormal numbers (about 5e-322), on which every operation of a
    /// step is slow. The magnitude is one that means nothing physically.
    const double* state_flush;
    /// Fill def with the documented defaults (name and ports NULL).
    void (*defaults)(void* def);
    /// Cross-field value rules a parameter table cannot express (rod < bore):
    /// 0, or -1 with the offending field and a message.
    int (*validate)(const void* def, char* field, size_t fsz, char* msg, size_t msz);
    /// Port rules that need the compiled nodes (a valve's T on a cylinder
    /// chamber, a hose ending at its own node): 0 or -1 with field and message.
    int (*check_ports)(const hyd_model* m, const char* const* port_name, const int* port,
                       const int* own, char* field, size_t fsz, char* msg, size_t msz);
    /// Write the node and state indices into the packed record: comp is the
    /// component index, port[k] the node of port k, own[k] the k-th owned
    /// node, state[k] the k-th state (owned-node pressures, then states[]).
    void (*bind)(void* rec, int comp, const int* port, const int* own, const int* state);
    /// The component named by its reference port (index ref, after every
    /// record is bound): check it, write what the record needs of it, and
    /// return the node of the reference port's flow slot (>= 0), or -1 with
    /// a message. NULL for types without a reference port.
    int (*bind_ref)(const hyd_model* m, void* rec, int ref, char* msg, size_t msz);
    /// A state of another component that its flows depend on (a shuttle's
    /// valve spool), or -1: hyd_model_jacobian_pattern gives the rows of its
    /// flow slots that column. NULL: none.
    int (*ref_state)(const void* rec);
    /// Derived values: the record's constants from def and the fluid, and the
    /// fixed volume, liquid modulus, initial and fixed pressure of each owned
    /// node (node0: the first owned node; they are consecutive). rec is NULL
    /// when rec_size is 0.
    void (*derive)(hyd_model* m, const void* def, void* rec, int node0);
    /// Initial values of its non-pressure states (states[]), written to y0.
    void (*initial)(const void* def, const void* rec, double* y0);
    /// Reference evaluation over all n records of the type: flows into the
    /// flow slots (hyd_flow2), outputs into d, flow partials into G when non-NULL
    /// (see the kernels below), and the derivatives of its own states into
    /// ydot (state i at ydot[map ? map[i] : i]; map is non-NULL only without G).
    void (*eval)(const hyd_model* m, hyd_data* d, const void* rec, int n, const double* y,
                 double* ydot, double* G, const int* map);
    /// After the node rows of the Jacobian are written: the rows of its own
    /// states in the n x n block Jb (leading dimension ldj; NULL: none asked)
    /// and the coupling partials in d.
    void (*jacobian)(const hyd_model* m, hyd_data* d, const void* rec, int n, double* Jb, int ldj);
} hyd_component;

/// The table (component_table.c): the descriptor of type t, or NULL.
const hyd_component* hyd_component_of(hyd_type t);

/// Parameter and port tables of a type (from its descriptor).
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
    double Fc, Fs, vst, vsm; ///< seal friction: Coulomb, breakaway excess [N], Stribeck, smoothing [m/s]
} hyd_cyl_c;

/// A fraction (of a full spool opening, of a pump's full displacement)
/// that is none [-]: hyd_component.state_flush sets such states to 0 below
/// it. 1e-10 of an orifice's area passes 1e-10 of its flow; a lag of 10-30
/// ms reaches it 23 time constants after closing, under a second. (ROS34PW2
/// at rtol 1e-2 on the LS crane's `ramp` lowers through a stick-slip whose
/// end is sensitive to any perturbation: strokes 0.26, 0.80 and 0.27 mm RMS
/// off a Krus 0.01 ms reference with the threshold at 1e-14, 1e-12 and
/// 1e-10, 0.32 without the flush; test_ls_crane allows 0.5.)
#define HYD_STATE_FLUSH 1e-10

/// calloc of n (at least 1) elements into p; true on success.
#define HYD_ALLOC(p, n) ((p) = calloc((size_t)((n) > 0 ? (n) : 1), sizeof *(p)), (p) != NULL)

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

    /// Packed records per type (hyd_component.rec_size each), in component
    /// order; comp_sub gives a component's index among its type's records.
    void* rec[HYD_TYPE_COUNT];
    int nrec[HYD_TYPE_COUNT];
    int* node_owner; ///< (nnode) component that owns the node, or -1 for a user node
    int* comp_node0; ///< (ncomp) first owned node of each component (owned nodes are consecutive)
    int* comp_state0; ///< (ncomp) first state of each component (its states are consecutive)
    int* comp_slot;  ///< (ncomp x HYD_MAXSLOT) node at each flow slot, -1 unused
    /// Typed views of rec[] for the kernels and queries that know their type.
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
    /// The states hyd_model_flush sets to 0 below flush_below (their
    /// descriptors' state_flush), in state order.
    int nflush;
    int* flush_state;    ///< (nflush)
    double* flush_below; ///< (nflush) [the state's unit]
};

/// Recompute every derived array from the definitions (after compile or a
/// parameter change). Returns 0, or -1 with e filled if a value is invalid.
int hyd_model_derive(hyd_model* m, hyd_build_error* e);

// Component helpers used by more than one file.
hyd_orif_k hyd_orifice_constants(const hyd_fluid_def* f, double cd);
double hyd_hose_volume(const hyd_hose_def* d);
/// Relief and check valves share their record, binding and evaluation (relief.c).
void hyd_ramp_bind(void* rec, int comp, const int* port, const int* own, const int* state);
void hyd_ramps_component_eval(const hyd_model* m, hyd_data* d, const void* rec, int n,
                              const double* y, double* ydot, double* G, const int* map);

/// Fluid value rules (table and cross-field); element value rules (table and
/// the type's validate hook). 0, or -1 with e filled (circuit_params.c).
int hyd_validate_fluid(const hyd_fluid_def* f, hyd_build_error* e);
int hyd_validate_values(const hyd_elem* el, int where, int index, hyd_build_error* e);
int hyd_set_err(hyd_build_error* e, int where, int index, const char* field, const char* msg);
/// Copy an element (name and port strings duplicated); free its strings.
int hyd_elem_copy(hyd_elem* dst, const hyd_elem* src);
void hyd_elem_free(hyd_elem* e);
char* hyd_strdup(const char* s);

// ---------------------------------------------------------------------------
// Kernels: each type's eval hook loops over all its records, adds flows into
// d->node_q and, when G is non-NULL, flow partials into G, an (n+1) x (n+1)
// row-major matrix indexed by state (tank nodes map to the dummy index n),
// so a kernel needs no branch on node kind.
// ---------------------------------------------------------------------------

/// Relief and check kernel on an array of ramp records (relief.c).
void hyd_ramps_eval(const hyd_model* m, hyd_data* d, double* G, const hyd_ramp_c* v, int nv);
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

/// Upper end of the table path [Pa abs] (2^64): above it, the exact law.
#define HYD_BE_P_HI 18446744073709551616.0
/// The bits of P = 2^e m that keep m in [1, 2): mask, then or the exponent of 1.
#define HYD_AIR_MANT_MASK 0x000FFFFFFFFFFFFFull
#define HYD_AIR_ONE_BITS 0x3FF0000000000000ull

/// The table entries for P with bit pattern b: the octave e (index of
/// oct[]) and the segment j of [1, 2) its mantissa falls in.
static inline void hyd_air_index(uint64_t b, int* e, int* j) {
    *e = (int)(b >> 52) - 1023;
    *j = (int)(b >> (52 - 7)) & (HYD_AIR_SEG - 1);
}

/// The segment polynomial of m^(-1/n) at x = m - centre (x2 = x x), C(i) its
/// coefficient i: Estrin's scheme, a shorter dependency chain than Horner,
/// same rounding class. + - * only: one text for a double and the two lanes
/// of circuit_kernel.c.
#define HYD_AIR_POLY(C, x, x2)                                                                       \
    (((C(0)) + (C(1)) * (x)) + (x2) * (((C(2)) + (C(3)) * (x)) + (x2) * (((C(4)) + (C(5)) * (x)) + (x2) * (C(6)))))

/// The entrained-air law multiplied through by P (see hyd_be_nd), from the
/// air ratio r: Be = N / D, and Be / V = N / (D V) with one division. One
/// text for a double and the two lanes of circuit_kernel.c.
#define HYD_BE_N(bel, alpha, r, P) ((bel) * (1.0 + (alpha) * (r)) * (P))
#define HYD_BE_D(bec, r, P) ((P) + (bec) * (r))
#define HYD_BE_C(N, D, V) ((N) / ((D) * (V)))

/// r(P) = (p_a / P)^(1/n) from the table, for P in [1, 2^HYD_AIR_OCT).
/// The exponent and the top mantissa bits of P index the tables directly, so
/// there is no log, exp or division.
static inline double hyd_air_ratio(const hyd_air_tab* t, double P) {
    uint64_t b;
    memcpy(&b, &P, sizeof b);
    int e, j;
    hyd_air_index(b, &e, &j);
    const uint64_t mb = (b & HYD_AIR_MANT_MASK) | HYD_AIR_ONE_BITS;
    double mant;
    memcpy(&mant, &mb, sizeof mant);
    const double* c = t->seg[j];
    const double x = mant - c[HYD_AIR_DEG + 1]; // exact: both in [1, 2]
    const double x2 = x * x;
#define HYD_C_(i) c[i]
    const double p = HYD_AIR_POLY(HYD_C_, x, x2);
#undef HYD_C_
    return t->oct[e] * p;
}

/// Numerator and denominator of the law at absolute pressure P for a node with
/// liquid modulus bel and air weight bec = alpha bel / n:
///   Be = N / D,  N = bel (1 + alpha r) P,  D = P + bec r
/// (the law of docs/hydraulics.md multiplied through by P, so Be costs one division, which the
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
    if (!(P >= HYD_BE_P_LO && P < HYD_BE_P_HI)) // false for NaN
        return 0;
    const double rr = hyd_air_ratio(t, P);
    *r = rr;
    *N = HYD_BE_N(bel, m->be_alpha, rr, P);
    *D = HYD_BE_D(bec, rr, P);
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
        const double c = HYD_BE_C(N, D, V);
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

/// A component's own (non-pressure) state s whose rate depends on pressures
/// or on other states: its eval hook writes d ydot_s / d y into row s of G
/// (rows of non-pressure states are not used by the node rows, volume.c),
/// and its jacobian hook copies that row into the block with this (G is
/// d->scratch_ in both the reference and the fast kernel's fallback; the
/// tank column n is dropped).
static inline void hyd_state_row_from_G(const hyd_model* m, const hyd_data* d, int s, double* Jb,
                                        int ldj) {
    const int n = m->nstate;
    memcpy(Jb + (size_t)s * ldj, d->scratch_ + (size_t)s * (n + 1), (size_t)n * sizeof(double));
}

/// The smoothstep's cubic t^2 (3 - 2t) (+ - * only: one text for a double and
/// the two lanes of circuit_fast_ls.c). On t clamped to [0, 1] it is
/// hyd_smoothstep bit for bit: 0 (also for t = -0) and 1 at the clamps.
#define HYD_SMOOTHSTEP_POLY(t) ((t) * (t) * (3.0 - 2.0 * (t)))

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
    return HYD_SMOOTHSTEP_POLY(t);
}


#endif
