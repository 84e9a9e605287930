// app.h: shared pieces of the cranesim command line (the only place that ties
// hydraulics, world and render together).
#ifndef APP_H
#define APP_H

#include <stdbool.h>
#include <signal.h>
#include <stdio.h>

#include "engine_backend.h"
#include "model.h"
#include "scenario.h"
#include "sim.h"

#define APP_MAX_SET 64

/// Exit codes (README, "Exit codes"); an interrupted run exits 128 + the signal.
enum { EXIT_OK_ = 0, EXIT_RUNTIME = 1, EXIT_USAGE = 2 };

/// The exit code of a world-library status (sim_status): SIM_FAILED is a
/// runtime failure (1); SIM_REFUSED is bad input (2), unless rows were
/// already written (rows > 0: then the run failed on its way, 1).
int app_exit_code(int status, long rows);

/// The common options, as bits of app_common.given (APP_GIVEN(APP_OPT_DT)):
/// which ones the user gave, so a command can tell a choice from a default,
/// note an option that has no effect and reject one it cannot honour.
enum app_opt {
    APP_OPT_MODEL, APP_OPT_SCENARIO, APP_OPT_MECHANICS, APP_OPT_VARIANT, APP_OPT_SOLVER, APP_OPT_DT,
    APP_OPT_RTOL, APP_OPT_ATOL, APP_OPT_DURATION, APP_OPT_EVERY, APP_OPT_SET, APP_OPT_JAC_EVERY,
    APP_OPT_LOAD, APP_OPT_WORLD, APP_OPT_DT_ODE, APP_OPT_KERNEL, APP_OPT_DENSE_JAC, APP_OPT_NO_RETRY, APP_OPT_NO_STEP_PROBE, APP_OPT_QUIET,
    APP_OPT_COUNT
};
#define APP_GIVEN(opt) (1u << (opt))
/// Option names by app_opt ("--model", ...).
extern const char* const app_opt_name[APP_OPT_COUNT];
/// Tell the world library the option that sets each of its run settings
/// (sim_name_params), so its messages name "--dt", not "h". main() calls it
/// first.
void app_name_params(void);

/// Options common to the subcommands that run a model.
typedef struct app_common {
    const char* model_path;      ///< NULL: built-in default
    const char* scenario_path;   ///< file, or a name in assets/scenarios
    const char* sets[APP_MAX_SET];
    int nset;
    sim_opts sim;
    bool quiet;
    unsigned given;              ///< APP_GIVEN bits of the options on the command line
} app_common;

/// Try to consume argv[*i] (and its value) as a common option. Returns 1 if
/// consumed, 0 if not a common option, -1 on a bad value (message printed).
int app_parse_common(app_common* c, int argc, char** argv, int* i);
/// The value of the option argv[*i], advancing *i; NULL after "option X needs
/// a value" on stderr when it is missing: argv[*i] is the last argument, or
/// the next one is itself an option ("--out --quiet": starts with "--").
const char* app_value(int argc, char** argv, int* i);
/// Before cmd parses its arguments: every option of cmd that takes a value
/// (its own and the common ones) has one. Returns 0, or EXIT_USAGE after
/// "cranesim CMD: option X needs a value" (so `drive --record` at the end is
/// not called an unknown option).
int app_check_values(const char* cmd, int argc, char** argv);
/// The command line of cmd with each "--opt=value" of a value-taking option
/// split into "--opt" "value" (as getopt_long takes both). Returns a new
/// NULL-terminated array (free it; the strings are argv's) with its length in
/// *argc, or NULL when out of memory.
char** app_split_equals(const char* cmd, int* argc, char** argv);
/// Help text for the common options.
void app_common_help(FILE* f, bool with_solver);
/// Help text for the common options in `which` (APP_GIVEN bits), in the usual order.
void app_options_help(FILE* f, unsigned which);

/// Check an output file named by option opt before anything runs, without
/// creating it: a non-empty name, not a directory, its folder exists and is
/// writable, an existing file is writable; with ext (".png") the name must end
/// in it unless it is an existing device or pipe (/dev/stdout). Returns 0, or
/// -1 after one line "cranesim CMD: OPT FILE: problem" on stderr.
int app_check_output(const char* cmd, const char* opt, const char* path, const char* ext);
/// Refuse two of a command's outputs naming one file (the second write would
/// replace the first): paths[k] (NULL: not given) for option opts[k]. Same
/// file: the same inode when both exist, else the same real folder and
/// name. Devices and pipes may be shared. Returns 0, or -1 after one line.
int app_check_distinct(const char* cmd, const char* const* opts, const char* const* paths, int n);
/// Flush and close f. Returns 0, or the errno of the first failure: first
/// (a write the caller already saw fail, 0 if none), else the flush's or the
/// close's, else EIO for an error flagged on the stream with no errno left
/// to tell (a failed write's errno is gone once later calls ran: callers
/// that want it pass it as first).
int app_fclose_checked(FILE* f, int first);

/// SIGINT and SIGTERM caught for a long loop that stops cleanly (run, the
/// headless drive): the first signal sets app_signal_caught() and the loop
/// ends after the row or frame it is on; a second one kills at once
/// (SA_RESETHAND). app_signals_restore puts the previous handlers back.
typedef struct app_signals {
    struct sigaction old_int, old_term;
} app_signals;
void app_signals_catch(app_signals* s);
void app_signals_restore(const app_signals* s);
/// The signal caught since app_signals_catch (SIGINT, SIGTERM), or 0.
int app_signal_caught(void);
/// "SIGINT" or "SIGTERM".
const char* app_signal_name(int sig);
/// An output file that replaces an existing one only when the command is
/// done with it: a regular file (existing or new) is written to a temporary
/// file in the same folder, ".NAME.XXXXXX", that app_out_close renames over
/// the final name (through a symlink to its target), so the previous file
/// is intact until then, and a run killed outright (SIGKILL) leaves it
/// untouched. A device or a pipe (/dev/stdout, /dev/null) is written in place.
typedef struct app_out {
    char path[1024]; ///< the final name
    char tmp[1100];  ///< the temporary file, "" when writing in place
    FILE* f;
} app_out;
/// Open path for writing ("w" or "wb"). Returns the stream, or NULL with errno set.
FILE* app_out_open(app_out* o, const char* path, const char* mode);
/// Flush and close the stream; then, when keep and nothing failed, rename the
/// temporary file over the final name, else remove it (the final name keeps
/// its old contents: a half-written file from a full disk is not kept).
/// first: the errno of a write the caller already saw fail, 0 if none.
/// Returns 0, or the errno of the first failure. Safe on an unopened o.
int app_out_close(app_out* o, int first, bool keep);
/// Rename the temporary file over the final name from a signal handler
/// (async-signal-safe: rename only; the caller has written whole lines with
/// write(2) or flushed). Returns 0 or -1.
int app_out_commit_signal(const app_out* o);

/// Create directory dir (its last component only: the parent must exist) and
/// check it is a writable directory. Returns 0, or -1 after one line on stderr naming opt and dir.
int app_make_dir(const char* cmd, const char* opt, const char* dir);
/// Reject, before anything runs, a run sim_run cannot honour as asked:
/// --solver cvode with ode or without CVODE in the build, an output period
/// (--every) that is not a whole multiple of the fixed step (--dt; with ode,
/// the ODE step), --load on a sandbox world. given: the options the user gave
/// (APP_GIVEN bits). Returns 0, or EXIT_USAGE after one line on stderr.
int app_check_sim(const char* cmd, const sim_opts* o, unsigned given);
/// Give an option that has no effect in this run a value that cannot be
/// refused: with --mechanics ode and an adaptive hydraulic solver, --dt (unused:
/// the solver spans each ODE step) becomes the ODE step, so sim.c's check that
/// a fixed sub-step divides the ODE step does not reject it.
void app_settle_unused(sim_opts* o);
/// One line "cranesim CMD: note: --X has no effect with ..." on stderr for each
/// given option that none of the n runs o[0..n) uses (--dt with adaptive
/// solvers, --rtol/--atol with fixed steps, --world/--dt-ode with lagrange, ...).
void app_note_unused(const char* cmd, unsigned given, const sim_opts* o, int n);
/// A note when a --set of mechanics.load_mass is overridden (decision 9: --load >
/// the scenario's load_mass > the model's), or unused (the sandbox world).
void app_note_load(const char* cmd, const app_common* c, const sim_opts* o, const scenario* sc);
/// The period a run writes rows at [s]: --every, or one row per fixed step
/// when the step is longer (decision 7); with ode a whole number of ODE steps.
double app_output_period(const sim_opts* o);

/// A scenario that slews the crane or works the hook (slew commands, an
/// initial slew, hook events) is written for a world with a slewing column
/// and a hook: the sandbox. Run elsewhere its slew and hook would be dropped.
/// A --world of that kind (sandbox, site) given without --mechanics makes o
/// ode (a world is the ode backend's; one note on stderr, *switched set).
/// With may_switch, no --world and no --mechanics other than ode given, o
/// becomes ode on the sandbox (the same): the scenario runs in its world.
/// Otherwise a run o cannot honour is refused: one line saying how to run
/// it, EXIT_USAGE. Returns 0 when o runs it as written; also when o names
/// (--mechanics) a backend without a world whose scripted runs slew the
/// column by the model m's slew drive (engine_backend.slew_dof) and the
/// scenario slews without hook events: the slew is then a degree of
/// freedom of that run.
/// drive's counterpart: the scenario is a scripted operator there, so a
/// slew it commands in a world without one (lagrange, the validation world)
/// is not refused but said, once, on stderr. world_kind: the kind of o's
/// world where its backend has one (else not read). (Hook events are said
/// as they happen.)
void app_note_scenario_slew(const char* cmd, const sim_opts* o, const model* m, const scenario* sc,
                            int world_kind);
int app_scenario_world(const char* cmd, sim_opts* o, unsigned given, const model* m, const scenario* sc,
                       bool may_switch, bool* switched);
/// app_scenario_world with the advice after the refusal given by the caller
/// (NULL: "run it with --mechanics ode --world sandbox"), for a command whose
/// own options put the run where it is (compare's --backends); quiet: no
/// note of a switch (compare says it once for both sides).
int app_scenario_world_remedy(const char* cmd, sim_opts* o, unsigned given, const model* m, const scenario* sc,
                              bool may_switch, bool* switched, const char* remedy, bool quiet);

/// Resolve a scenario argument: an existing file, or assets/scenarios/<name>.json.
const char* app_scenario_path(const char* arg, char* buf, size_t n);

/// Load model and scenario for c (scenario "ramp" when c names none). Returns
/// 0, or EXIT_USAGE with a one-line message in err (an unknown scenario name
/// lists the shipped ones).
int app_load_msg(const app_common* c, model** m, scenario* sc, char* err, size_t errsz);
/// app_load_msg, printing the message as "cranesim: ..." on stderr.
int app_load(const app_common* c, model** m, scenario* sc);

/// Progress bar on stderr, only when stderr is a terminal.
void app_progress(void* user, double t, double t_end);
void app_progress_done(void);

/// Parse a double with a unit-less strict check; returns 0 on success.
int app_parse_double(const char* s, double* v);
/// Set one sim_opts field from its option value (a backend's name,
/// engine_backend.h: "lagrange", "ode"; "full", "paper", "paper-typo"; a
/// solver name or "cvode"). opt names the option in the one-line error on
/// stderr ("--mechanics: unknown backend 'foo' (known: lagrange, ode)").
/// Return 0, or -1 on a bad value.
int app_set_mechanics(sim_opts* o, const char* opt, const char* v);
int app_set_variant(sim_opts* o, const char* opt, const char* v);
int app_set_solver(sim_opts* o, const char* opt, const char* v);
/// Sort v[0..n-1] ascending in place.
void app_sort(double* v, int n);
/// The median of v[0..n-1] (v is sorted in place; n >= 1).
double app_median(double* v, int n);
/// v in the shortest "%.15g" / "%.16g" / "%.17g" form that reads back equal
/// (CSV cells, --set assignments); returns buf.
const char* app_fmt_double(char* buf, size_t n, double v);
/// The double of v's 15-significant-digit decimal when that is within 4 ulps
/// of v, else v: a computed grid point lo + (hi - lo) j / (n - 1) becomes the
/// decimal it stands for (0.11, as `--set ...=0.11` gives it, not
/// 0.11000000000000001).
double app_snap_decimal(double v);
/// The run metrics' units as a user reads and types them (app_units.c):
/// metrics are SI (metric_unit: Pa, rad, J, m, s, N); the run summary shows
/// MPa, deg, kJ, m, s, kN. met is a metric_id. The display unit, the factor
/// display = SI * scale, and "NAME [UNIT]" for a plot axis.
const char* app_metric_disp_unit(int met);
double app_metric_disp_scale(int met);
const char* app_metric_label(int met, char* buf, size_t n);
/// "24MPa", "24e6Pa", "24 MPa", "5deg", "1.5kJ", "30mm" for metric met, into SI.
/// A metric with a unit needs one (a bare number is refused); a count or a
/// ratio takes a bare number only. 0, or -1 with one line in err.
int app_metric_parse_value(int met, const char* text, double* si, char* err, size_t errsz);
/// The SI value of one `unit` of metric met (a report unit); 0, or -1 with err.
int app_metric_unit_scale(int met, const char* unit, double* si, char* err, size_t errsz);
/// A simulated-to-wall time ratio for "Nx real time": whole numbers from 1,
/// two significant digits below (0.42); returns buf.
const char* app_fmt_speed(char* buf, size_t n, double ratio);
/// The backend o runs (engine_backend.h): what the drivers ask instead of
/// testing which one it is. o->mechanics is set only from the table (by
/// name, or a session's value checked against it); a value that names none
/// ends the program with one line (exit 1), never runs another backend.
const engine_backend* app_backend(const sim_opts* o);
/// Run o on backend b (o->mechanics = b's).
void app_use_backend(sim_opts* o, const engine_backend* b);
/// The scenario a stepped driver (drive, serve) plays when none is given:
/// its backend's (the sandbox pick-and-place for the ode world, the
/// scripted lift-and-jib demo without a world).
const char* app_default_drive_scenario(const sim_opts* o);
/// The scripted lift-and-jib demo: the operator of a crane without a hook or
/// a slew (the validation world, a headless link).
#define APP_DEMO_SCENARIO "drive_demo"

int cmd_run(int argc, char** argv);
int cmd_bench(int argc, char** argv);
int cmd_compare(int argc, char** argv);
/// compare's pressure figure, with no side taken as right (neither run is
/// known to be the accurate one: CVODE at its default rtol 1e-3 is further
/// from the converged peak than Krus at 0.1 ms): the largest RMS difference
/// [Pa] of the four chamber pressures over the rows both traces have, the
/// higher of the two runs' peak chamber pressures [Pa abs] (*peak_side: 0 A,
/// 1 B), and the RMS as a percentage of it (0 when it is not positive). The
/// same for (a, b) and (b, a).
void app_compare_pressure(const sim_trace* a, const sim_trace* b, double* rms_pa, double* peak_pa, double* pct,
                          int* peak_side);
int cmd_drive(int argc, char** argv);
int cmd_study(int argc, char** argv);
int cmd_sweep(int argc, char** argv);
int cmd_optimize(int argc, char** argv);

/// A --param range of sweep and optimize: a model path in the --set syntax,
/// from lo to hi (lo <= hi, finite), in n values (1 when not a grid).
typedef struct app_range {
    char path[256];
    double lo, hi;
    long n;
} app_range;
/// Parse "PATH=LO:HI:N" (want_n) or "PATH=LO:HI" for command cmd. 0, or -1
/// after one line on stderr.
int app_parse_range(const char* cmd, const char* arg, bool want_n, app_range* p);
/// The options sweep and optimize share: --param (up to APP_MAX_PARAM), --out
/// and --plot, their values as given (the defaults stay when absent).
enum { APP_MAX_PARAM = 8 };
typedef struct app_design_opts {
    const char* param[APP_MAX_PARAM];
    int nparam;
    const char* out;
    const char* plot;
} app_design_opts;
/// argv[*i] one of them: 1 (its value taken, *i moved past it); 0 not one of
/// them; -1 after one line on stderr (no value, too many --param).
int app_parse_design_opt(const char* cmd, int argc, char** argv, int* i, app_design_opts* d);
int cmd_replay(int argc, char** argv);
int cmd_loadchart(int argc, char** argv);
int cmd_serve(int argc, char** argv);
/// bench --config serve (bench_serve.c): one JSON line; returns 0 or EXIT_RUNTIME.
/// realtime: the server runs with --realtime (config serve) or without (serve-plain).
int bench_serve(const app_common* c, double duration, bool realtime);
/// drive --connect HOST:PORT, headless (drive_connect.c): the scripted
/// operator sc drives a remote serve for duration seconds of wall time,
/// reconnecting when the link drops. Returns 0, or EXIT_USAGE / EXIT_RUNTIME.
/// sets: the drive's --set values, sent to the server as SET commands on
/// each link; its answer (accepted or refused with its reason) on stdout.
int drive_connect(const char* addr, const scenario* sc, double duration, const char* const* sets, int nset);
/// A drive --set (hydraulics.components.lift_cyl.bore=0.1) as the protocol's
/// SET path (lift_cyl.bore) and value: 0, or -1 when it is not PATH=NUMBER.
int drive_set_path(const char* set, char* path, size_t np, double* v);

/// Render a PLplot page into memory and write it to the PNG file png, checking
/// every write (PLplot itself does not report a failed write). Before draw it
/// selects the PNG device, the geometry ("1400x1000") and a white background
/// with black as colour 15; draw starts the page (plinit or plstar) and draws;
/// after it the plot is ended. Returns 0, or -1 with "cannot write FILE:
/// reason" in err (also when built without PLplot). A failed write removes a
/// partly written regular file.
int app_png_render(const char* png, const char* geometry, void (*draw)(void* user), void* user, char* err,
                   size_t errsz);
/// Axis ticks of the plots (pure; no PLplot): the step, 1, 2 or 5 times a
/// power of ten, that puts at most max_ticks intervals on [lo, hi] (1 for an
/// empty or non-finite range); the decimals a label needs at that step; and
/// the label of tick value v, so that labels one step apart always differ.
double app_tick_step(double lo, double hi, int max_ticks);
int app_tick_decimals(double step);
void app_tick_label(double v, double step, char* buf, size_t n);

/// A point's text label for app_place_labels: the point (x, y) and the
/// text's width and height in one unit (mm on the page); the placement comes
/// back as the text's reference point (lx, ly: the text's vertical centre, its
/// left edge when just = 0, its right edge when just = 1) and whether a
/// leader line must join it to its point (placed farther out).
typedef struct app_label {
    double x, y, w, h;
    double lx, ly, just;
    bool leader;
} app_label;
/// Place labels nfixed..n-1 so that no two of l[0..n) overlap (the first
/// nfixed are placed already: a legend, say), none covers a point's marker (of
/// radius r, at (px, py)[0..np), the labelled points among them) and each
/// stays inside area {x0, y0, x1, y1}: beside its point (right, left, above,
/// below, the diagonals), farther out with a leader line when nothing nearer
/// is free. Returns how many labels could not be placed free of overlaps
/// (placed where they overlap least).
int app_place_labels(app_label* l, int nfixed, int n, const double area[4], const double* px, const double* py,
                     int np, double r);
/// The area two placed labels share (0: none), in the unit of their sizes.
double app_label_overlap(const app_label* a, const app_label* b);

/// Plot a run's main time histories to a PNG (PLplot); slew: the run's world
/// has a slew drive, whose channels are drawn too. Returns 0, or -1 with a
/// message (also when cranesim was built without PLplot).
int app_plot_run(const sim_trace* tr, const char* title, bool slew, const char* png, char* err, size_t errsz);
/// The run plot's time panels (0 strokes, 1 chamber pressures, 2 valve spools
/// and commands): their columns and legend names (pure; no PLplot), the lift
/// and jib, and with slew the slew's. Returns how many.
#define APP_PLOT_MAXSERIES 6
int app_plot_run_channels(int panel, bool slew, int cols[APP_PLOT_MAXSERIES], const char* names[APP_PLOT_MAXSERIES]);
/// A chain run's plot (app_plot_chain_run): its panels' series by the
/// run's chain columns col[0..ncol), found at index off of a row: panel 0
/// strokes (x_<actuator>), 1 A-chamber and 2 B-chamber pressures
/// (pA_, pB_<actuator>), 3 spools and 4 commands (u_, ucmd_<function>), 5
/// joint angles (q_<body> of a revolute joint); slew: the world's slew
/// drive too, from the base columns (x3, p3A, p3B, u3, u3_cmd, slew), named
/// "slew", unless the chain columns have the rack's own. Fills at most max
/// column indices and legend names (the actuator's, function's or body's
/// name, pointing into col); returns how many (pure; no PLplot).
#define APP_PLOT_CHAIN_PANELS 6
int app_plot_chain_channels(const crane_column* col, int ncol, int off, bool slew, int panel, int* cols,
                            const char** names, int max);
/// Plot a chain run to a PNG: nrow rows of stride = SIM_NCOL + ncol columns
/// (the base columns, then the chain's col[0..ncol)); slew: the world has a
/// slew drive (app_world_has_slew), drawn too. 0, or -1 with a message.
int app_plot_chain_run(const double* rows, int nrow, int stride, const crane_column* col, int ncol, bool slew,
                       const char* title, const char* png, char* err, size_t errsz);
/// Overlay two chain runs of the same columns (compare): A solid, B dashed,
/// na and nb rows of stride = SIM_NCOL + ncol each, on app_plot_chain_run's page.
int app_plot_chain_compare(const double* a, int na, const char* la, const double* b, int nb, const char* lb,
                           int stride, const crane_column* col, int ncol, bool slew, const char* title,
                           const char* png, char* err, size_t errsz);
/// The run with options o has a slew drive (an ode world with a slewing column).
bool app_world_has_slew(const sim_opts* o);
// The energy balance's summary lines (app_energy.c, docs/energy.md).
struct sim_energy;
struct sim_energy_balance;
struct engine;
/// The balance b of en, as run prints it: "  energy: in ... kJ ..." (who:
/// "energy WHO:" instead, e.g. "A"; NULL: "energy:").
void app_print_energy(const struct sim_energy* en, const struct sim_energy_balance* b, const char* who);
/// b[1] - b[0] (b: two)' balances, term by term, in kJ ("energy WHO: ...").
void app_print_energy_diff(const struct sim_energy* const en[2], const struct sim_energy_balance* b,
                           const char* who);
/// A new balance kept by engine e from now on (engine_follow_energy); NULL
/// (with a note on stderr) when it cannot be made.
struct sim_energy* app_energy_follow(const char* cmd, struct engine* e);
/// Finish en, print it (after the line title, when not NULL) and free it.
/// NULL: nothing.
void app_energy_report(struct sim_energy* en, const char* title);

/// A bar chart of n energies kj [kJ] named names (one bar each, in order) to a PNG.
int app_plot_energy(const char* const* names, const double* kj, int n, const char* title, const char* png, char* err,
                    size_t errsz);
/// The sweep's plots: metric y against parameter x over n designs, and a
/// heat map of z (nx x ny, the second parameter fastest, NaN: no value) over
/// the grid [x0, x1] x [y0, y1]. Return 0, or -1 with a message.
int app_plot_sweep(const char* png, const char* title, const char* xlab, const char* ylab, const double* x,
                   const double* y, long n, char* err, size_t errsz);
int app_plot_heat(const char* png, const char* title, const char* xlab, const char* ylab, const double* z,
                  long nx, long ny, double x0, double x1, double y0, double y1, char* err, size_t errsz);
/// The optimiser's convergence: objective f of n evaluations (NaN: failed),
/// feasible or not, and the best feasible so far. 0, or -1 with a message.
int app_plot_convergence(const char* png, const char* title, const char* ylab, const double* f, const bool* feasible,
                         long n, char* err, size_t errsz);
/// Overlay two runs (a: solid, b: dashed) to a PNG; slew: both runs' worlds
/// have a slew drive, whose channels are drawn too.
int app_plot_compare(const sim_trace* a, const char* la, const sim_trace* b, const char* lb,
                     const char* title, bool slew, const char* png, char* err, size_t errsz);

// A chain model's outputs by actuator and function (app_chain_out.c): read
// from the rows' chain columns (crane_chain_columns) by name.
#include "metrics.h"
struct crane_chain;
typedef struct app_act_stats {
    char name[40];
    int cx, cA, cB, cF;  ///< row columns of x_, pA_, pB_, F_<name>
    double stroke;       ///< the cylinder's stroke [m]; NaN: not a chain actuator (the slew rack)
    double xmin, xmax;   ///< [m]
    double pA, pB, Fabs; ///< peaks [Pa abs, Pa abs, N]
    int stops;           ///< entries into an end stop (x < 0 or x > stroke), at the rows
    bool at_stop;
} app_act_stats;
typedef struct app_fn_stats {
    char name[40];
    int cu;      ///< row column of u_<name>
    double umax; ///< largest |spool opening| [-]
} app_fn_stats;
typedef struct app_chain_stats {
    bool bound;
    int nact, nfn;
    app_act_stats* act;
    app_fn_stats* fn;
    long rows;
} app_chain_stats;
/// Bind to a run's chain columns, which follow off base columns in its rows;
/// nothing (nact = nfn = 0) for NULL or the two-link shorthand. 0, or -1
/// out of memory.
int app_chain_stats_bind(app_chain_stats* s, const struct crane_chain* cc, int off);
void app_chain_stats_row(app_chain_stats* s, const double* row);
/// The summary's lines by actuator (strokes, peak pressures, forces,
/// end-stop hits); every: the output period [s], t_end the run's end [s].
void app_chain_stats_print(const app_chain_stats* s, double every, double t_end, FILE* f);
/// met's JSON document (metrics_write_json) with the per-actuator and
/// per-function entries ("peak_pA.lift", ...) added. 0, or -1.
int app_chain_stats_write_json(const app_chain_stats* s, const run_metrics* met, FILE* f);
void app_chain_stats_free(app_chain_stats* s);
/// The summary's metrics block (metrics_print) for a run whose actuators s
/// names: without the end-stop hits of the first two by position (the
/// per-actuator line has every one by name). s without actuators: as is.
void app_chain_metrics_print(const app_chain_stats* s, const run_metrics* met, FILE* f);

/// A run's chain columns, kept row by row (compare: its sim_trace has the
/// base columns only). Set off (sim_ncol of the run), model_chain (the
/// model's chain) and pass &run_chain to sim_run_energy_chain; rows via
/// app_ext_rows_cb. Nothing is kept for the two-link shorthand (ncol 0).
typedef struct app_ext_rows {
    int off;
    const struct crane_chain* model_chain;
    const struct crane_chain* run_chain; ///< set by the run where its columns differ
    bool bound, oom;
    int ncol;                  ///< chain columns kept per row
    struct crane_column* col;  ///< their names and units (a copy)
    double* v;                 ///< nrow x ncol
    long nrow, cap;
} app_ext_rows;
int app_ext_rows_cb(void* user, const double* row);
/// The index of column name in r's columns, or -1.
int app_ext_rows_find(const app_ext_rows* r, const char* name);
void app_ext_rows_free(app_ext_rows* r);

#endif
