// hydraulics.h: the hydraulic circuit library of cranesim (pure C11, libm only).
//
// A circuit is data: named pressure nodes (volumes with a pressure state, or
// fixed-pressure tanks) joined by typed components (pump, relief, check,
// orifice, hose, 4/3 valve, cylinder). It is described with default-filled
// definition structs (or loaded from JSON by hydraulics_json), compiled once
// into index arrays (hyd_model, read-only during a step), and evaluated with a
// separate hyd_data that holds inputs, outputs and scratch. hyd_eval and
// hyd_jacobian never allocate.
//
// Conventions: SI units everywhere. Node pressures are ABSOLUTE [Pa]. Valve,
// relief, pump and check settings are DIFFERENTIAL pressures [Pa] across the
// component. Flows are volume flows [m^3/s]. Cylinder force is positive when
// it pushes the rod out (extends). See docs/hydraulics.md for the equations.
#ifndef HYDRAULICS_H
#define HYDRAULICS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Element types. Tanks and volumes are nodes; the rest are components.
/// Hoses and cylinders also create nodes of their own: a hose "h" creates node
/// "h" (its volume), a cylinder "c" creates chamber nodes "c.A" and "c.B".
typedef enum hyd_type {
    HYD_TANK = 0, ///< fixed-pressure node (tank, or an ideal supply)
    HYD_VOLUME,   ///< pressure node with a fixed volume (e.g. the pump line)
    HYD_PUMP,     ///< pressure-compensated flow source, inlet -> outlet
    HYD_RELIEF,   ///< pressure relief valve, inlet -> outlet
    HYD_CHECK,    ///< anti-cavitation check valve, inlet (tank) -> outlet (port)
    HYD_ORIFICE,  ///< fixed two-regime orifice, inlet -> outlet (positive flow)
    HYD_HOSE,     ///< hose volume node plus a laminar resistance to node "to"
    HYD_VALVE,    ///< 4/3 closed-centre proportional valve, ports P, T, A, B
    HYD_CYLINDER, ///< double-acting cylinder with chambers "<name>.A", "<name>.B"
    HYD_LS_PUMP,  ///< load-sensing variable pump, inlet -> outlet, LS port "ls"
    HYD_SHUTTLE,  ///< LS shuttle: smooth max of ports a, b into node "out"
    HYD_COMPENSATOR, ///< section pressure compensator, inlet -> outlet (valve P), senses load, ref
    HYD_COUNTERBALANCE, ///< counterbalance valve: check valve -> load, pilot-assisted relief load -> valve
    HYD_ACCUMULATOR, ///< gas-charged accumulator on node "port", oil volume state "<name>.oil"
    HYD_TYPE_COUNT
} hyd_type;

/// Type name as used in JSON ("tank", "volume", "pump", ...).
const char* hyd_type_name(hyd_type t);
/// Parse a type name; returns -1 if unknown.
int hyd_type_parse(const char* name);

// ---------------------------------------------------------------------------
// Definitions (Box2D style: get defaults from hyd_default_*_def(), change what
// differs). Fields whose default is 0 and that must be > 0 are REQUIRED; the
// compiler (and the JSON loader) reject a circuit that leaves them at 0.
// Strings are copied when added to a builder.
// ---------------------------------------------------------------------------

/// Hydraulic fluid. air_fraction = 0 gives a constant bulk modulus.
typedef struct hyd_fluid_def {
    double density;          ///< rho [kg/m^3]; default 870
    double viscosity;        ///< kinematic viscosity nu [m^2/s]; default 32e-6
    double bulk_modulus;     ///< liquid bulk modulus Be_l [Pa]; default 1.2e9
    double air_fraction;     ///< free air volume fraction alpha at p_atm [-]; default 0.005
    double polytropic_index; ///< polytropic index n of the air [-]; default 1.4
    double p_atm;            ///< atmospheric pressure p_a [Pa abs]; default 101325
    double re_transition;    ///< orifice transition Reynolds number Re_tr [-]; default 100
} hyd_fluid_def;

/// Fixed-pressure node.
typedef struct hyd_tank_def {
    const char* name;
    double pressure; ///< node pressure [Pa abs]; default 1e5
} hyd_tank_def;

/// Volume node with a pressure state "<name>.p".
typedef struct hyd_volume_def {
    const char* name;
    double volume;       ///< REQUIRED fixed volume [m^3]
    double bulk_modulus; ///< liquid/wall bulk modulus Be_l [Pa]; 0 (default) uses the fluid's
    double p0;           ///< initial pressure [Pa abs]; default 1e5
} hyd_volume_def;

/// Pressure-compensated pump: Q_max while p_out - p_in <= p_set, falling C1 to
/// 0 at p_set + band.
typedef struct hyd_pump_def {
    const char* name;
    const char* inlet;  ///< suction node (usually the tank)
    const char* outlet; ///< delivery node (usually the pump line)
    double q_max;       ///< REQUIRED maximum flow [m^3/s] (35 L/min = 5.8333e-4)
    double p_set;       ///< REQUIRED compensator setting, differential [Pa]
    double band;        ///< regulation band [Pa]; default 0.5e6
} hyd_pump_def;

/// Relief valve: 0 below p_crack, q_rated at p_crack + dp_override (C1 quadratic
/// corner), linear with slope 2 q_rated / dp_override beyond.
typedef struct hyd_relief_def {
    const char* name;
    const char* inlet;  ///< protected node
    const char* outlet; ///< usually the tank
    double p_crack;     ///< REQUIRED cracking pressure, differential inlet - outlet [Pa]
    double dp_override; ///< pressure rise from crack to rated flow [Pa]; default 1e6
    double q_rated;     ///< flow at p_crack + dp_override [m^3/s]; default 6.6667e-4 (40 L/min)
} hyd_relief_def;

/// Anti-cavitation check valve, tank -> port: opens when p_out < p_in - p_crack,
/// q_rated after a further dp_open (C1 quadratic corner), linear beyond.
typedef struct hyd_check_def {
    const char* name;
    const char* inlet;  ///< supply side (the tank)
    const char* outlet; ///< protected port (a cylinder chamber)
    double p_crack;     ///< cracking pressure, differential inlet - outlet [Pa]; default 0.05e6
    double dp_open;     ///< pressure from crack to rated flow [Pa]; default 0.02e6
    double q_rated;     ///< flow at p_crack + dp_open [m^3/s]; default 6.6667e-4 (40 L/min)
} hyd_check_def;

/// Fixed sharp-edged orifice (two-regime law, see orifice functions below).
typedef struct hyd_orifice_def {
    const char* name;
    const char* inlet;  ///< positive flow goes inlet -> outlet
    const char* outlet;
    double area; ///< REQUIRED opening area [m^2]
    double cd;   ///< discharge coefficient [-]; default 0.65
} hyd_orifice_def;

/// Hose: a volume node named after the hose (state "<name>.p") of volume
/// pi d^2 L / 4, plus a laminar (Hagen-Poiseuille) resistance to node "to".
typedef struct hyd_hose_def {
    const char* name;
    const char* to;      ///< node at the far end (usually a cylinder chamber)
    double length;       ///< REQUIRED hose length [m]
    double diameter;     ///< REQUIRED inner diameter [m]
    double bulk_modulus; ///< effective (oil + wall) bulk modulus [Pa]; default 0.8e9
    double p0;           ///< initial pressure [Pa abs]; default 1e5
} hyd_hose_def;

/// 4/3 closed-centre proportional valve. Spool state "<name>.spool" u in
/// [-1, 1]: u > 0 opens P->A and B->T, u < 0 opens P->B and A->T, each edge an
/// orifice of area |u| A_max with A_max = q_nominal / (cd sqrt(2 dp_nominal / rho)).
typedef struct hyd_valve_def {
    const char* name;
    const char* P; ///< pressure port node
    const char* T; ///< tank port node
    const char* A; ///< work port A node
    const char* B; ///< work port B node
    double q_nominal;  ///< rated flow per edge at dp_nominal [m^3/s]; default 6.6667e-4 (40 L/min)
    double dp_nominal; ///< rated pressure drop per edge [Pa]; default 1e6
    double cd;         ///< discharge coefficient [-]; default 0.65
    double tau;        ///< spool time constant [s]; default 0.03
    double u0;         ///< initial spool position [-]; default 0
} hyd_valve_def;

/// Double-acting cylinder. Chamber A (piston side) extends the rod.
typedef struct hyd_cylinder_def {
    const char* name;
    double bore;           ///< REQUIRED piston diameter D [m]
    double rod;            ///< REQUIRED rod diameter d [m], 0 < d < D
    double stroke;         ///< REQUIRED stroke s [m]; x in [0, s]
    double dead_volume_a;  ///< chamber A volume at x = 0 [m^3]; default 1e-4
    double dead_volume_b;  ///< chamber B volume at x = s [m^3]; default 1e-4
    double leakage;        ///< internal leakage C_L [m^3/(s Pa)]; default 1e-14
    double friction;       ///< viscous friction b_v [N s/m]; default 5e3
    double stop_stiffness; ///< end-stop spring k [N/m]; default 5e8
    double stop_damping;   ///< end-stop damper c [N s/m]; default 1e6
    double stop_width;     ///< end-stop onset depth delta [m] (C1 smoothing); default 1e-3
    double p0_a;           ///< initial chamber A pressure [Pa abs]; default 1e5
    double p0_b;           ///< initial chamber B pressure [Pa abs]; default 1e5
    double coulomb;        ///< seal Coulomb friction F_c [N]; default 0 (off)
    double stribeck;       ///< seal breakaway excess F_s [N] (static force F_c + F_s); default 0
    double v_stribeck;     ///< Stribeck velocity v_st [m/s]; default 0.01
    double v_smooth;       ///< friction regularisation width v_sm [m/s] (tanh); default 1e-3
} hyd_cylinder_def;

/// Load-sensing variable pump: displacement state "<name>.disp" eps in [0, 1],
/// delivery eps q_max; the displacement follows, with time constant tau, the
/// setting that holds p_out - p_ls at margin, cut back above p_cutoff.
typedef struct hyd_ls_pump_def {
    const char* name;
    const char* inlet;  ///< suction node (usually the tank)
    const char* outlet; ///< delivery node (the pump line)
    const char* ls;     ///< load-sensing line node (sensed only, no flow)
    double q_max;       ///< REQUIRED flow at full displacement and the shaft speed [m^3/s]
    double margin;      ///< LS margin p_out - p_ls held by the controller [Pa]; default 2e6
    double band;        ///< LS controller band around the margin [Pa]; default 5e4
    double p_cutoff;    ///< pressure cut-off, outlet - inlet, where the flow starts to fall [Pa]; default 22e6
    double cutoff_band; ///< pressure rise from cut-off start to zero flow [Pa]; default 0.5e6
    double tau;         ///< displacement time constant (stroke time) [s]; default 0.08
    double eps0;        ///< initial displacement [-]; default 0
    double leakage;     ///< internal leakage outlet -> inlet per pressure difference [m^3/(s Pa)]; default 0
} hyd_ls_pump_def;

/// LS shuttle (signal network). Max-select mode (valve NULL): flow
/// G (smax(p_a, p_b) - p_out) into node out, drawn from a and b; smax is max
/// with a C1 corner of half-width "width". Spool mode (valve names a 4/3
/// valve whose A and B are a and b): the section's LS port, which senses the
/// work port the spool feeds (a for u > 0, b for u < 0) and drains to the
/// valve's T in neutral, switching smoothly over spool_width of travel.
typedef struct hyd_shuttle_def {
    const char* name;
    const char* a;       ///< first sensed node (a work port or an upstream shuttle)
    const char* b;       ///< second sensed node
    const char* out;     ///< LS line node (declare it as a volume)
    const char* valve;   ///< optional: the valve whose spool it follows (spool mode); NULL: max-select
    double conductance;  ///< laminar conductance of the signal path [m^3/(s Pa)]; default 2e-11
    double width;        ///< half-width of the max-select corner [Pa]; default 1e5
    double spool_width;  ///< spool mode: spool travel over which the LS edge opens [-]; default 0.2
} hyd_shuttle_def;

/// Section pressure compensator: an orifice inlet -> outlet of area x area,
/// x in [0, 1] (a spool state lagging its set point by tau) set so that the meter-in drop p_outlet - p_load of the valve
/// it feeds is setting (mode 0, pre-compensated) or p_inlet - p_ref - setting
/// (mode 1, post-compensated / flow sharing; ref = the highest LS pressure).
typedef struct hyd_compensator_def {
    const char* name;
    const char* inlet;  ///< pump line
    const char* outlet; ///< the valve's P port node (declare it as a volume)
    const char* load;   ///< the section's load pressure (work port or section LS node), sensed
    const char* ref;    ///< the highest LS pressure (the LS line), sensed (mode 1)
    double area;        ///< REQUIRED full opening [m^2]
    double cd;          ///< discharge coefficient [-]; default 0.65
    double setting;     ///< spring setting [Pa]; default 1e6 (pre), see mode
    double band;        ///< drop error from open to closed [Pa]; default 5e4
    double mode;        ///< 0: pre-compensated, 1: post-compensated (flow sharing); default 1
    double tau;         ///< spool time constant [s] (state "<name>.spool", starts open); default 0.005
} hyd_compensator_def;

/// Counterbalance (over-centre) valve between a valve-side node and a load
/// (cylinder) node. Free flow valve -> load through a check valve; out of the
/// load through a relief whose spool (state "<name>.spool", x in [0, 1])
/// follows, with time constant tau, the opening asked by
/// (p_load - p_valve) + pilot_ratio (p_pilot - p_valve) - p_setting.
typedef struct hyd_counterbalance_def {
    const char* name;
    const char* valve;  ///< valve-side node (the hose to the directional valve)
    const char* load;   ///< the cylinder chamber it holds
    const char* pilot;  ///< pilot node (the opposite line)
    double p_setting;   ///< REQUIRED relief setting [Pa] (typically 1.3 x the load-holding pressure)
    double pilot_ratio; ///< pilot area ratio R [-]; default 3
    double band;        ///< opening signal from crack to full open [Pa]; default 1e6
    double area;        ///< relief full opening [m^2]; default 2e-5
    double cd;          ///< discharge coefficient [-]; default 0.65
    double tau;         ///< spool time constant [s]; default 0.01
    double check_crack; ///< check valve cracking pressure [Pa]; default 0.05e6
    double check_open;  ///< check valve pressure from crack to rated flow [Pa]; default 0.2e6
    double check_q;     ///< check valve rated flow [m^3/s]; default 1.6667e-3 (100 L/min)
    double vented;      ///< 1: spring chamber vented to atmosphere (z referenced to p_atm, not p_valve); default 0
} hyd_counterbalance_def;

/// Gas-charged accumulator: gas p V_g^n = p0 V0^n, oil volume V = V0 - V_g
/// (state "<name>.oil" [m^3]), fed from node "port" through a laminar
/// conductance.
typedef struct hyd_accumulator_def {
    const char* name;
    const char* port;   ///< the node it is mounted on
    double p0;          ///< REQUIRED precharge pressure [Pa abs]
    double V0;          ///< REQUIRED gas volume at precharge (the size) [m^3]
    double n;           ///< polytropic index [-]: 1 isothermal, 1.4 adiabatic; default 1.4
    double conductance; ///< laminar conductance of the connection [m^3/(s Pa)]; default 1e-9
    double p_init;      ///< initial gas pressure [Pa abs]; 0 (default): the precharge (empty)
} hyd_accumulator_def;

hyd_fluid_def hyd_default_fluid_def(void);
hyd_tank_def hyd_default_tank_def(void);
hyd_volume_def hyd_default_volume_def(void);
hyd_pump_def hyd_default_pump_def(void);
hyd_relief_def hyd_default_relief_def(void);
hyd_check_def hyd_default_check_def(void);
hyd_orifice_def hyd_default_orifice_def(void);
hyd_hose_def hyd_default_hose_def(void);
hyd_valve_def hyd_default_valve_def(void);
hyd_cylinder_def hyd_default_cylinder_def(void);
hyd_ls_pump_def hyd_default_ls_pump_def(void);
hyd_shuttle_def hyd_default_shuttle_def(void);
hyd_compensator_def hyd_default_compensator_def(void);
hyd_counterbalance_def hyd_default_counterbalance_def(void);
hyd_accumulator_def hyd_default_accumulator_def(void);

// ---------------------------------------------------------------------------
// Building and compiling
// ---------------------------------------------------------------------------

typedef struct hyd_builder hyd_builder;
typedef struct hyd_model hyd_model;

/// An empty circuit with the default fluid. Returns NULL only if out of memory.
hyd_builder* hyd_builder_create(void);
void hyd_builder_free(hyd_builder* b);
void hyd_builder_set_fluid(hyd_builder* b, const hyd_fluid_def* fluid);

/// Add a node or component; returns its index among nodes (tank, volume) or
/// among components (the rest), in the order added, or -1 if out of memory.
/// Port names are resolved, and values checked, in hyd_compile, so
/// components may name nodes that are added later.
int hyd_add_tank(hyd_builder* b, const hyd_tank_def* def);
int hyd_add_volume(hyd_builder* b, const hyd_volume_def* def);
int hyd_add_pump(hyd_builder* b, const hyd_pump_def* def);
int hyd_add_relief(hyd_builder* b, const hyd_relief_def* def);
int hyd_add_check(hyd_builder* b, const hyd_check_def* def);
int hyd_add_orifice(hyd_builder* b, const hyd_orifice_def* def);
int hyd_add_hose(hyd_builder* b, const hyd_hose_def* def);
int hyd_add_valve(hyd_builder* b, const hyd_valve_def* def);
int hyd_add_cylinder(hyd_builder* b, const hyd_cylinder_def* def);
/// Add an element of type t from its def struct (def points to the
/// hyd_<type>_def of t); the same as the typed hyd_add_* functions.
int hyd_add(hyd_builder* b, hyd_type t, const void* def);

/// Where a build error was found (used by the JSON loader to name JSON paths).
typedef struct hyd_build_error {
    int where;       ///< 0: fluid, 1: nodes[index], 2: components[index], -1: none
    int index;       ///< index in nodes or components
    char field[32];  ///< offending field ("bore", "inlet", "name", ...)
    char msg[224];   ///< problem, e.g. "must be > 0, got -0.08"
} hyd_build_error;

/// Validate and compile. On error returns NULL and writes one line
/// "<element>.<field>: <problem>" into err (if non-NULL); e fills structured
/// detail (may be NULL). State order: volume-node pressures in node order,
/// then component states in component order (valve: spool; hose: p;
/// cylinder: pA, pB).
hyd_model* hyd_compile(const hyd_builder* b, char* err, size_t errsz);
hyd_model* hyd_compile_ex(const hyd_builder* b, hyd_build_error* e);
void hyd_model_free(hyd_model* m);

/// The default two-actuator crane circuit of docs/model.md (components named
/// as in tests/hydraulics/data/crane_circuit.json: "lift_valve", "lift_cyl",
/// "jib_valve", "jib_cyl", ...), without the seals' Coulomb and Stribeck
/// friction that assets/models/hiab031.json carries (the component default,
/// off; tests of the seal law set it themselves). 11 states.
hyd_model* hyd_model_default_crane(char* err, size_t errsz);
/// A synthetic circuit with nact in [1, 64] actuators for tests and benches:
/// tank, pump line, a pump (35 L/min per actuator) and main relief, then per
/// actuator k = 1..nact "act<k>_valve", two hoses "act<k>_hose_A/B", the
/// cylinder "act<k>_cyl" (the lift cylinder's size for odd k, the jib's for
/// even k), port reliefs and anti-cavitation checks on both chambers.
hyd_model* hyd_model_synthetic(int nact, char* err, size_t errsz);

// ---------------------------------------------------------------------------
// Model queries (cheap; not for the hot loop)
// ---------------------------------------------------------------------------

int hyd_model_nstate(const hyd_model* m);    ///< number of states
int hyd_model_nnode(const hyd_model* m);     ///< number of nodes, including owned ones
int hyd_model_ncomp(const hyd_model* m);     ///< number of components
int hyd_model_ncylinder(const hyd_model* m); ///< number of cylinders
int hyd_model_nvalve(const hyd_model* m);    ///< number of valves

/// Component index by name, or -1.
int hyd_model_find(const hyd_model* m, const char* name);
/// Node index by name ("tank", "pump_line", "lift_hose_A", "lift_cyl.A"), or -1.
int hyd_model_find_node(const hyd_model* m, const char* name);
/// Cylinder index (into hyd_data cyl_* arrays) by component name, or -1.
int hyd_model_cylinder(const hyd_model* m, const char* name);
/// Valve index (into hyd_data valve_cmd) by component name, or -1.
int hyd_model_valve(const hyd_model* m, const char* name);
/// State index by name ("lift_cyl.pA", "lift_valve.spool", "pump_line.p"), or -1.
int hyd_model_find_state(const hyd_model* m, const char* name);

const char* hyd_model_comp_name(const hyd_model* m, int comp);
hyd_type hyd_model_comp_type(const hyd_model* m, int comp);
const char* hyd_model_node_name(const hyd_model* m, int node);
/// State index of a node's pressure [Pa abs], or -1 for a tank node.
int hyd_model_node_state(const hyd_model* m, int node);
/// Name of state i (e.g. "jib_cyl.pB").
const char* hyd_model_state_name(const hyd_model* m, int i);
/// State indices of cylinder c's chamber pressures pA, pB [Pa abs].
void hyd_model_cylinder_states(const hyd_model* m, int cyl, int* iA, int* iB);
/// State index of valve v's spool position u [-].
int hyd_model_valve_state(const hyd_model* m, int valve);
/// Component index of cylinder cyl / valve v.
int hyd_model_cylinder_comp(const hyd_model* m, int cyl);
int hyd_model_valve_comp(const hyd_model* m, int valve);
/// Cylinder geometry: piston area A_A [m^2], annulus area A_B [m^2], stroke [m].
void hyd_model_cylinder_geometry(const hyd_model* m, int cyl, double* AA, double* AB, double* s);
/// Node a relief valve guards (its inlet), or -1 when comp is not a relief.
/// The drive HUD names the cylinder chamber behind an open relief with it.
int hyd_model_relief_inlet(const hyd_model* m, int comp);
/// Fill y (nstate) with the initial state (p0 of each node, u0 of each valve).
void hyd_model_initial_state(const hyd_model* m, double* y);
/// Set to exactly 0 each component state that closes towards 0 (compensator
/// and counterbalance spools, a LS pump's displacement; not the valve spool,
/// which its command drives and the callers settle by it) once
/// its magnitude is below one that means nothing physically (1e-10 of the
/// full opening or displacement). A lag towards 0 decays geometrically and
/// never gets there: without this it ends in subnormal numbers, on which
/// every later step is slower (1.2-1.6x per step on the LS crane's long
/// holds). Call after an accepted step (hyd_problem.settle); state i is
/// y[pos ? pos[i] : i]. Returns the number of states changed.
int hyd_model_flush(const hyd_model* m, double* y, const int* pos);
/// The circuit's fastest mode [1/s]: the spectral radius of its Jacobian
/// with every volume node at p [Pa abs], every cylinder at mid-stroke and at
/// rest, every spool at u (0: closed). An explicit method of real stability
/// interval [-r, 0] is unstable for h > r / rate (RK4: r = 2.785). Returns
/// 0 when the circuit has no states, or -1 when it cannot be evaluated.
double hyd_model_fastest_rate(const hyd_model* m, double p, double u);
/// The fluid the model was compiled with.
hyd_fluid_def hyd_model_fluid(const hyd_model* m);

// ---------------------------------------------------------------------------
// Structure queries: what the circuit is made of, so that callers need not
// guess it from names (".p" suffixes, "pump_line", hoses found by name).
// ---------------------------------------------------------------------------

/// What a state is.
typedef enum hyd_state_kind {
    HYD_STATE_PRESSURE = 0, ///< a node's pressure [Pa abs] (volumes, hoses, chambers)
    HYD_STATE_SPOOL,        ///< a valve's spool position [-]
    HYD_STATE_OTHER         ///< any other state a component owns
} hyd_state_kind;
/// Kind of state i (HYD_STATE_OTHER when i is out of range).
hyd_state_kind hyd_model_state_kind(const hyd_model* m, int i);
/// Node whose pressure state i is, or -1 when state i is not a pressure.
int hyd_model_state_node(const hyd_model* m, int i);

/// What a node does in the circuit.
typedef enum hyd_node_role {
    HYD_NODE_LINE = 0, ///< any other pressure node (a line, a hose, a chamber)
    HYD_NODE_TANK,     ///< fixed pressure (a tank node; no state)
    HYD_NODE_SUPPLY,   ///< a pump delivers into it (the pump line)
    HYD_NODE_LS        ///< a load-sensing line (the "ls" port of a LS pump)
} hyd_node_role;
/// Role of node i (HYD_NODE_LINE when i is out of range).
hyd_node_role hyd_model_node_role(const hyd_model* m, int i);
/// The first node with role HYD_NODE_SUPPLY, or -1 when no pump feeds a node.
int hyd_model_supply_node(const hyd_model* m);
/// Component that owns node i (a hose's volume, a cylinder's chambers), or -1
/// for a node declared under "nodes" (tank, volume).
int hyd_model_node_owner(const hyd_model* m, int i);
/// The k-th node component comp owns (hose: 0 its volume; cylinder: 0 chamber
/// A, 1 chamber B), or -1.
int hyd_model_comp_node(const hyd_model* m, int comp, int k);
/// The node at port k of component comp (in the order of its JSON ports:
/// pump/relief/check/orifice inlet, outlet; hose to; valve P, T, A, B; shuttle
/// a, b, out and, in spool mode, its valve's T as port 3), or -1.
int hyd_model_port_node(const hyd_model* m, int comp, int k);
/// The hose whose far end ("to") is node i (a cylinder chamber), as a
/// component index, or -1. Its own pressure state is
/// hyd_model_node_state(m, hyd_model_comp_node(m, hose, 0)).
int hyd_model_feed_hose(const hyd_model* m, int node);
/// Structural pattern of d ydot / d y: pattern[i * n + j] = 1 where the entry
/// can be non-zero at some state, else 0 (n = nstate; the caller's array of
/// n * n bytes). A node's pressure rate depends on its own pressure and on
/// the pressures and states of every component connected to it; a spool
/// rate on its spool only; the displacement, spool or oil volume of a LS
/// pump, counterbalance valve or accumulator on the pressures at its ports
/// too. hyd_jacobian never writes a non-zero outside it.
void hyd_model_jacobian_pattern(const hyd_model* m, unsigned char* pattern);

// ---------------------------------------------------------------------------
// Live parameters. A path is "<element>.<field>" ("lift_cyl.bore",
// "pump.p_set", "tank.pressure") or "fluid.<field>". Setting validates the
// value (and cross-field rules such as rod < bore) and recomputes the derived
// arrays; call it between steps only. The state layout never changes.
// ---------------------------------------------------------------------------

/// Returns 0, or -1 with a one-line message in err.
int hyd_model_set(hyd_model* m, const char* path, double value, char* err, size_t errsz);
/// Counts the accepted hyd_model_set calls: a packed copy of the parameters
/// (hyd_fused_build) made at another revision is stale.
unsigned hyd_model_revision(const hyd_model* m);
/// Returns 0 and writes *value, or -1 if the path is unknown.
int hyd_model_get(const hyd_model* m, const char* path, double* value);
/// Number of numeric parameters of type t, and their names and units.
int hyd_param_count(hyd_type t);
const char* hyd_param_name(hyd_type t, int k);
const char* hyd_param_unit(hyd_type t, int k);
/// Hard range [lo, hi] (outside it a circuit is refused) and typical range
/// [tlo, thi] (outside it the loader notes it) of parameter k of type t, in
/// its unit (hyd_param_unit). Returns 0, or -1 when there is no such parameter.
int hyd_param_range(hyd_type t, int k, double* lo, double* hi, double* tlo, double* thi);
/// The fluid's parameters ("fluid.<name>"), likewise.
int hyd_fluid_param_count(void);
const char* hyd_fluid_param_name(int k);
const char* hyd_fluid_param_unit(int k);
int hyd_fluid_param_range(int k, double* lo, double* hi, double* tlo, double* thi);
/// Elements with parameters: the declared nodes (tank, volume) first, then
/// the components, in file order. hyd_model_element gives element i's name
/// (the "<element>" of a parameter path) and type, or NULL when i is out of range.
int hyd_model_nelement(const hyd_model* m);
const char* hyd_model_element(const hyd_model* m, int i, hyd_type* type);

// ---------------------------------------------------------------------------
// Data: inputs, outputs, scratch. One per thread of use; the model may be shared.
// Arrays are allocated by hyd_data_create with the sizes in the comments.
// ---------------------------------------------------------------------------

typedef struct hyd_data {
    // Inputs, written by the caller before hyd_eval / hyd_jacobian.
    double* cyl_x;     ///< (ncyl) stroke x [m], 0 = retracted, s = extended
    double* cyl_v;     ///< (ncyl) stroke rate x' [m/s], + extends
    double* valve_cmd; ///< (nvalve) spool command u_cmd [-], clamped to [-1, 1]

    // Outputs of the last hyd_eval / hyd_jacobian.
    double* cyl_F;    ///< (ncyl) cylinder force F [N], + extends
    int* cyl_stop;    ///< (ncyl) end stop engaged: -1 retracted stop, +1 extended stop, 0 none
    double* comp_q;   ///< (ncomp x 2) flows [m^3/s]: pump delivery; relief/check/orifice
                      ///< inlet->outlet; hose hose->to; valve [into A, out of B];
                      ///< cylinder [leakage A->B, 0]; second entry 0 unless stated
    int* comp_open;   ///< (ncomp) relief/check open, pump regulating, cylinder in stop: 1, else 0
    double* node_p;   ///< (nnode) node pressure [Pa abs]
    double* node_V;   ///< (nnode) node volume [m^3]
    double* node_be;  ///< (nnode) effective bulk modulus Be(p) [Pa]
    double* node_q;   ///< (nnode) net inflow from components [m^3/s] (excluding dV/dt); 0 for tanks
    double* node_dV;  ///< (nnode) volume rate dV/dt [m^3/s]

    // Coupling partials, written by hyd_jacobian (row-major, n = nstate).
    double* dydx; ///< (ncyl x n) d ydot_i / d x_c [state unit / (s m)]
    double* dydv; ///< (ncyl x n) d ydot_i / d x'_c [state unit / m]
    double* dFdy; ///< (ncyl x n) d F_c / d y_i [N / state unit]
    double* dFdx; ///< (ncyl) d F_c / d x_c [N/m]
    double* dFdv; ///< (ncyl) d F_c / d x'_c [N s/m]

    // Private scratch (flow partials); do not touch.
    double* scratch_;
    double* flow_; ///< (ncomp x 4) flow into the node at each port [m^3/s]
    int n_, nnode_, ncomp_, ncyl_, nvalve_;
} hyd_data;

/// Allocate data for m, inputs zeroed (x = 0, x' = 0, u_cmd = 0). NULL if out of memory.
hyd_data* hyd_data_create(const hyd_model* m);
void hyd_data_free(hyd_data* d);

// ---------------------------------------------------------------------------
// Evaluation
// ---------------------------------------------------------------------------

/// ydot = f(t, y) for the hydraulic states, given the inputs in d. Also fills
/// the outputs (forces, flows, node quantities). t [s] is unused by the
/// circuit itself (commands are inputs) and kept for solver symmetry.
void hyd_eval(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot);
/// hyd_eval on a caller's state vector in its own order: circuit state i is
/// y[map[i]] and its derivative goes to ydot[map[i]] (map injective; other
/// entries of ydot are left alone). map NULL is hyd_eval. The same
/// arithmetic as hyd_eval, without gathering into a circuit-ordered copy.
void hyd_eval_mapped(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot,
                     const int* map);

/// Analytic Jacobian d ydot / d y at (t, y), written into the n x n block of a
/// caller's dense row-major matrix J at rows row0.., columns col0.. with leading
/// dimension ldj (J[(row0+i)*ldj + col0+j] = d ydot_i / d y_j). Every entry of
/// the block is written (zeros included); nothing outside it is touched. J
/// may be NULL to get only the coupling partials. Also fills d->dydx, dydv,
/// dFdy, dFdx, dFdv and all hyd_eval outputs; if ydot is non-NULL it receives f.
void hyd_jacobian(const hyd_model* m, hyd_data* d, double t, const double* y, double* ydot,
                  double* J, int ldj, int row0, int col0);

// ---------------------------------------------------------------------------
// JSON (in the separate library hydraulics_json, which links cJSON; the core
// needs libm only). Schema: docs/hydraulics.md. Errors are one line,
// "<file>: <prefix>.<path>: <problem>", e.g.
// "model.json: hydraulics.components[1].bore: must be > 0, got -0.08".
// ---------------------------------------------------------------------------

struct cJSON;

/// Build a model from an already-parsed circuit object. file names the source
/// in messages; prefix is the JSON path of the circuit object ("hydraulics",
/// or "" when the circuit is the whole document). NULL on error, with err set.
hyd_model* hyd_model_from_json(const struct cJSON* circuit, const char* file, const char* prefix,
                               char* err, size_t errsz);
/// hyd_model_from_json with a fragment appended: the "nodes" and
/// "components" of extra (each optional) after the circuit's own, compiled
/// as one circuit (a world's extra circuit on a model's). An error in the
/// fragment names extra_file, extra_prefix and the fragment's own index
/// ("sandbox.json: circuit.components[3].bore: ..."); notes are given for the
/// fragment only (the circuit's own were given when it was loaded alone).
hyd_model* hyd_model_from_json_extra(const struct cJSON* circuit, const char* file, const char* prefix,
                                     const struct cJSON* extra, const char* extra_file,
                                     const char* extra_prefix, char* err, size_t errsz);
/// Load a circuit file: either the circuit object itself or a document with a
/// "hydraulics" member holding it (prefix "hydraulics"). NULL on error.
hyd_model* hyd_model_load_json(const char* path, char* err, size_t errsz);
/// Notes (non-fatal remarks such as a value outside its typical range, one
/// line each, without a newline) go to this handler. The default writes
/// "note: <line>" to stderr, each distinct line once per process (a run loads
/// its model and world more than once); NULL restores it. Handlers are
/// process-wide and not thread-safe: set them before loading.
typedef void (*hyd_note_fn)(const char* line, void* user);
void hyd_set_note_handler(hyd_note_fn fn, void* user);
/// The handler in use (NULL: the default) and its user pointer.
hyd_note_fn hyd_get_note_handler(void** user);
/// Send one note line to the handler.
void hyd_note(const char* line);
/// Notes for a circuit fragment that is not compiled on its own (a world's
/// extra components, appended to the model's circuit): each numeric member
/// of "nodes" and "components" outside its typical range, as
/// "file: prefix.components[i].field: ...". Members the compiler would
/// refuse are left to it.
void hyd_json_fragment_notes(const struct cJSON* fragment, const char* file, const char* prefix);
/// A number for a message as a user writes it: 22, 0.005, 1e5, 2.5e9 (6
/// significant digits; %g would give 100000 and 2.5e+09).
void hyd_fmt_num(char* out, size_t n, double v);
/// A range for a message: "[1e5, 1e8] Pa" (no unit for NULL, "" or "-").
void hyd_fmt_range(char* out, size_t n, double lo, double hi, const char* unit);
/// The model's current definition (fluid, nodes, components with every
/// parameter, including live changes) as a new cJSON object; the caller frees
/// it with cJSON_Delete. NULL if out of memory.
struct cJSON* hyd_model_to_json(const hyd_model* m);

// ---------------------------------------------------------------------------
// Component laws, exposed for tests and for callers that build their own
// circuits. All are pure functions.
// ---------------------------------------------------------------------------

/// Effective bulk modulus Be(p) [Pa] at absolute pressure p [Pa], entrained-air
/// law; *dbe = dBe/dp [-] if dbe is non-NULL. Positive and C1 for all p.
double hyd_bulk_modulus(const hyd_fluid_def* f, double be_liquid, double p, double* dbe);

/// Two-regime orifice flow [m^3/s] for pressure drop dp [Pa] through area A
/// [m^2] with discharge coefficient cd; optional partials dQ/ddp [m^3/(s Pa)]
/// and dQ/dA [m/s]. A = 0 gives Q = 0, dQ/ddp = 0 without a special case.
double hyd_orifice_flow(const hyd_fluid_def* f, double cd, double A, double dp, double* dq_ddp,
                        double* dq_dA);
/// Laminar-turbulent transition pressure p_tr [Pa] of an orifice of area A [m^2].
double hyd_orifice_p_tr(const hyd_fluid_def* f, double cd, double A);

/// C1 "valve opening" ramp used by relief and check valves: 0 for d <= 0,
/// (d/w)^2 for 0 < d < w, 1 + 2 (d - w)/w beyond. *dr = dr/dd [1/Pa].
double hyd_open_ramp(double d, double w, double* dr);

// ---------------------------------------------------------------------------
// Energy (energy.c; docs/energy.md). From the outputs of the last hyd_eval /
// hyd_jacobian in d. Signs: power taken from the fluid is positive, so a
// pump's is negative (it delivers). At every evaluation
//   sum_c hyd_comp_power + sum_c hyd_comp_piston_power + hyd_stored_power
//     = hyd_boundary_power
// exactly (each term from the same flows), for any circuit.
// ---------------------------------------------------------------------------

/// The flows of component comp from the last evaluation: for each of its
/// flow slots (its owned nodes, then its ports) the node (node[k]) and the
/// flow into it (q[k], m^3/s; 4 slots at most). Every term below is made
/// from these; they also let a caller account for every flow into a set of
/// nodes (tests/world/test_flow_accounting.c). Returns the number of slots.
int hyd_comp_flows(const hyd_model* m, const hyd_data* d, int comp, int* node, double* q);
/// Hydraulic power component comp takes from the fluid at its ports and owned
/// nodes [W]: - sum over its flow slots of p_node * (flow into that node).
double hyd_comp_power(const hyd_model* m, const hyd_data* d, int comp);
/// Power comp takes through the moving volume of the nodes it owns [W]:
/// sum p dV/dt (a cylinder's piston work on the mechanics; 0 otherwise).
double hyd_comp_piston_power(const hyd_model* m, const hyd_data* d, int comp);
/// A valve's loss per metering edge [W]: e[0] meter-in (P to the fed work
/// port), e[1] meter-out (the other work port to T); e[0] + e[1] =
/// hyd_comp_power. Returns 2, or 0 when comp is not a valve.
int hyd_valve_edge_power(const hyd_model* m, const hyd_data* d, int comp, double e[2]);
/// Power the fixed-pressure nodes (tanks) deliver into the circuit [W]:
/// - sum p_t Q_t, Q_t the net flow into tank t.
double hyd_boundary_power(const hyd_model* m, const hyd_data* d);
/// Rate of compression energy stored in the fluid [W]: sum over pressure
/// nodes of p V/Be dp/dt = p (Q_in - dV/dt).
double hyd_stored_power(const hyd_model* m, const hyd_data* d);
/// All of the above in one pass over the slots and nodes (an energy balance
/// that follows every step): comp_P and piston_P (ncomp each) as
/// hyd_comp_power and hyd_comp_piston_power of every component, *boundary
/// as hyd_boundary_power, *stored as hyd_stored_power.
void hyd_power_terms(const hyd_model* m, const hyd_data* d, double* comp_P, double* piston_P, double* boundary,
                     double* stored);
/// Compression energy stored in the fluid [J], a state function of the node
/// pressures p and volumes V (nnode each, as hyd_data node_p, node_V):
/// sum V phi(p), phi(p) = integral from p_atm to p of s / Be(s) ds.
double hyd_stored_energy(const hyd_model* m, const double* p, const double* V);
/// The compression energy that leaves with the fluid a moving volume
/// displaces [W]: - sum phi(p) dV/dt over nodes whose volume moves. The
/// volume-flow node equation makes hyd_stored_power = d(sum V phi)/dt -
/// sum phi dV/dt, so d(hyd_stored_energy)/dt = hyd_stored_power -
/// hyd_expansion_power along any trajectory (docs/energy.md).
double hyd_expansion_power(const hyd_model* m, const hyd_data* d);
/// phi(p) of node [J/m^3] (0 for a tank); and phi(p1) - phi(p0) for a
/// small step (one Simpson panel: cheap enough to follow phi at every step).
double hyd_node_phi(const hyd_model* m, int node, double p);
double hyd_node_phi_increment(const hyd_model* m, int node, double p0, double p1);
/// One node's term V phi(p) of hyd_stored_energy [J] (0 for a tank).
double hyd_node_stored_energy(const hyd_model* m, int node, double p, double V);
/// An accumulator's gas (0 for any other component): the power the oil does
/// compressing it, p_g q [W] (q into the accumulator; hyd_comp_power minus
/// it is the loss in its inlet, (p_port - p_g) q), and its compression
/// energy relative to the precharge (oil volume 0) [J], a state function of
/// the gas pressure: the polytropic work integral of p_g dV from 0 to the
/// oil volume, p0 V0 ((p_g/p0)^((n-1)/n) - 1)/(n - 1) (n = 1: p0 V0
/// ln(p_g/p0)). From the outputs of the last hyd_eval in d.
double hyd_comp_gas_power(const hyd_model* m, const hyd_data* d, int comp);
double hyd_comp_gas_energy(const hyd_model* m, const hyd_data* d, int comp);

#ifdef __cplusplus
}
#endif
#endif
