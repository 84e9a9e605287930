// energy_acc.h: the energy balance of a run (docs/energy.md): per-component
// hydraulic power from the circuit (hydraulics.h, energy.c), integrated over
// every step of the solver by that step's own method (the powers as extra
// states of the integrated system, hyd_solver_step_quadrature), the fluid's stored energy
// as a state function at the start and the end, and the mechanics' energy
// (kinetic + potential) from the backend. Optionally a CSV of the powers at
// the row period.
#ifndef ENERGY_ACC_H
#define ENERGY_ACC_H

#include "hydraulics.h"
#include "hyd_solver.h"

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Groups of the columns (what a loss is, for the summary).
typedef enum sim_energy_group {
    SIM_EG_SUPPLY = 0, ///< pumps (power taken < 0: they deliver)
    SIM_EG_VALVE_IN,   ///< valve meter-in edges
    SIM_EG_VALVE_OUT,  ///< valve meter-out edges
    SIM_EG_RELIEF,
    SIM_EG_CHECK,
    SIM_EG_ORIFICE,
    SIM_EG_HOSE,
    SIM_EG_LEAK,       ///< cylinder internal leakage
    SIM_EG_COMPENSATOR, ///< pressure compensators (the drop they hold)
    SIM_EG_COUNTERBALANCE, ///< counterbalance valves (check and pilot-assisted relief)
    SIM_EG_OTHER,      ///< any other component type (its whole P_c)
    SIM_EG_WORK,       ///< piston work on the mechanics
    SIM_EG_TANK,       ///< taken by the tanks (boundary flow work p_t Q_t)
    SIM_EG_STORED,     ///< rate of compression energy in the fluid, p V/Be dp/dt, and in accumulators' gas, p_g q
    SIM_EG_EXPANSION,  ///< compression energy leaving with displaced fluid (hyd_expansion_power)
    SIM_EG_COUNT
} sim_energy_group;

/// Name of a group ("valve meter-in", "relief", ...).
const char* sim_energy_group_name(sim_energy_group g);

typedef struct sim_energy sim_energy;

/// An empty accumulator; the run binds it to the circuit it integrates
/// (the ode world uses its own copy). NULL if out of memory.
sim_energy* sim_energy_create(void);
void sim_energy_free(sim_energy* e);
/// Make the columns for circuit m, which must live until sim_energy_finish.
/// 0, or -1 (out of memory, or already bound: one run per accumulator).
int sim_energy_bind(sim_energy* e, const hyd_model* m);
/// The end of the run: the stored energy of the last sample is evaluated and
/// the circuit is let go (the results and columns stay).
void sim_energy_finish(sim_energy* e);
/// A data of the bound circuit the caller may evaluate into (its
/// sim_energy_eval_fn; the ode world does).
hyd_data* sim_energy_data(sim_energy* e);
/// The balance follows the solver's steps: the energies of each
/// step are integrated by the method that took it, with its own stages
/// (hyd_solver_step_quadrature), not by the trapezoid between samples,
/// which over-counts a transient a step or the sample period does not
/// resolve (docs/energy.md). eval evaluates the circuit at (t, y), y a
/// state of the solver's system (n values), and returns the data with
/// every output filled (NULL: failed); it may share its buffer between
/// calls. Call after bind. 0, or -1 (out of memory, bad arguments).
typedef const hyd_data* (*sim_energy_eval_fn)(void* user, double t, const double* y);
int sim_energy_follow(sim_energy* e, int n, sim_energy_eval_fn eval, void* user);
/// A sample at (t, y) where no step was taken since the last one (the
/// run's start): the powers there, the trapezoid from the last sample
/// (nothing when none). 0, or -1 (eval failed, not following).
int sim_energy_follow_sample(sim_energy* e, double t, const double* y, double e_mech);
/// The same with the columns' energies since the last sample integrated by
/// the caller (dE, ncol values [J]; NULL: the trapezoid): a solver that
/// integrates them with its state (CVODE's quadrature, hyd_cvode.h).
int sim_energy_follow_integrated(sim_energy* e, double t, const double* y, double e_mech, const double* dE);
/// hyd_quad_fn (user: a following sim_energy): every column's power [W] at
/// (t, y) of the solver's system, into P (ncol values). 0, or -1.
int sim_energy_quad(void* user, double t, const double* y, double* P);
/// The inputs the circuit reads besides its state (the strokes and rates an
/// ODE step hands it, a command, a fault) changed at the last sample's
/// state (t, y): a sample there with the new inputs, so the next step
/// starts from their powers. A volume they moved (the ode world re-anchors
/// the chambers to the bodies' strokes at each ODE step) changes the
/// fluid's compression energy at the same pressures by phi(p) dV, which no
/// flow brought: that is added to the balance's coupling term. 0, or -1.
int sim_energy_follow_inputs(sim_energy* e, double t, const double* y);
/// The mechanics' energy [J] at the last sample (the ode world knows it
/// only at the end of each ODE step, its hydraulic sub-steps pass NAN).
void sim_energy_mech(sim_energy* e, double e_mech);
/// After an accepted step of s (its on_step, or after hyd_solver_step) that
/// went from the last sample to (t, y): the step's energies by its method.
/// e_mech: the mechanics' energy at t [J] (NAN: unknown there, the last
/// one kept). 0, or -1 (an evaluation failed, not following).
int sim_energy_follow_step(sim_energy* e, hyd_solver* s, double t, const double* y, double e_mech);

/// Write the powers to f [W] (header at bind, a row at the first sample and
/// then one per dt [s] on the grid); f stays the caller's. Call before the run.
void sim_energy_csv(sim_energy* e, FILE* f, double dt);

/// Columns: per component (a valve two, meter-in and meter-out; a cylinder
/// two, leak and work; an accumulator two, its inlet's loss and gas), then "tank", "stored" and "expansion". All but the
/// last sum to zero at every sample (the identity of hydraulics.h).
int sim_energy_ncol(const sim_energy* e);
const char* sim_energy_col_name(const sim_energy* e, int i);
sim_energy_group sim_energy_col_group(const sim_energy* e, int i);
/// Energy taken from the fluid by column i over the run [J].
double sim_energy_col_energy(const sim_energy* e, int i);
/// Time column i's component passed flow over the run [s], at the
/// resolution of the samples (every integration step): a step counts when
/// the component is open at its end. Relief columns only (0 for the others).
double sim_energy_col_open_time(const sim_energy* e, int i);

/// The balance over the run [J].
typedef struct sim_energy_balance {
    double pump;       ///< delivered by the pumps
    double tank;       ///< delivered by the tanks (boundary flow work; < 0 when they take more back)
    double in;         ///< pump + tank
    double group[SIM_EG_COUNT]; ///< taken by each group (SUPPLY is -pump, TANK -tank)
    double loss;       ///< sum of the loss groups (valves .. other)
    double expansion;  ///< compression energy released by fluid the chambers displaced
    double coupling;   ///< compression energy the volumes' jumps between steps put into the fluid (ode world's
                       ///< re-anchoring of the strokes; 0 on the lagrange crane) [J]
    double work;       ///< piston work on the mechanics
    double stored;     ///< change of the compression energy of the fluid and the accumulators' gas, from the
                       ///< end states (state functions)
    double gas;        ///< of it, the accumulators' gas
    double stored_rate;///< the same from the integrated rate (for comparison)
    double residual;   ///< in + coupling - loss - expansion - work - stored
    double turnover;   ///< energy turned over: the larger of the sources' and the sinks' sums of the terms
                       ///< in, coupling, -loss, -expansion, -work, -stored (each counted on the side its sign
                       ///< gives)
    double residual_pct; ///< 100 residual / turnover
    double mech;       ///< change of the mechanics' energy (kinetic + potential); NAN when unknown
    double t0, t1;     ///< the samples' first and last time [s]
    long samples;
} sim_energy_balance;
void sim_energy_result(const sim_energy* e, sim_energy_balance* b);

#ifdef __cplusplus
}
#endif
#endif
