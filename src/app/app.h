// app.h: shared pieces of the cranesim command line (the only place that ties
// hydraulics, world and render together).
#ifndef APP_H
#define APP_H

#include <stdbool.h>
#include <stdio.h>

#include "model.h"
#include "scenario.h"
#include "sim.h"

#define APP_MAX_SET 64

/// Exit codes (SPEC section 5).
enum { EXIT_OK_ = 0, EXIT_RUNTIME = 1, EXIT_USAGE = 2 };

/// Options common to the subcommands that run a model.
typedef struct app_common {
    const char* model_path;      ///< NULL: built-in default
    const char* scenario_path;   ///< file, or a name in assets/scenarios
    const char* sets[APP_MAX_SET];
    int nset;
    sim_opts sim;
    bool quiet;
} app_common;

/// Try to consume argv[*i] (and its value) as a common option. Returns 1 if
/// consumed, 0 if not a common option, -1 on a bad value (message printed).
int app_parse_common(app_common* c, int argc, char** argv, int* i);
/// Help text for the common options.
void app_common_help(FILE* f, bool with_solver);

/// Resolve a scenario argument: an existing file, or assets/scenarios/<name>.json.
const char* app_scenario_path(const char* arg, char* buf, size_t n);

/// Load model and scenario for c (scenario "ramp" when c names none). Returns
/// 0, or EXIT_USAGE with a one-line message in err (an unknown scenario name
/// lists the shipped ones).
int app_load_msg(const app_common* c, model** m, scenario* sc, char* err, size_t errsz);
/// app_load_msg, printing the message as "cranesim: ..." on stderr.
int app_load(const app_common* c, model** m, scenario* sc);

typedef struct live live;
/// The scripted operator (a scenario's command tables and hook events) at
/// simulated time tm: the stick positions into u[3], and every hook event
/// due by tm, from *ev on, applied to l (*ev advances). on_hook (may be
/// NULL) hears each: attach or release, and live_hook's answer.
void app_scripted_input(const scenario* sc, live* l, double tm, int* ev, double u[3],
                        void (*on_hook)(void* user, live* l, int attach, int got), void* user);

/// Progress bar on stderr, only when stderr is a terminal.
void app_progress(void* user, double t, double t_end);
void app_progress_done(void);

/// Parse a double with a unit-less strict check; returns 0 on success.
int app_parse_double(const char* s, double* v);
/// Set one sim_opts field from its option value ("lagrange"/"ode"; "full",
/// "paper", "paper-typo"; a solver name or "cvode"). opt names the option in
/// the one-line error on stderr. Return 0, or -1 on a bad value.
int app_set_mechanics(sim_opts* o, const char* opt, const char* v);
int app_set_variant(sim_opts* o, const char* opt, const char* v);
int app_set_solver(sim_opts* o, const char* opt, const char* v);
/// Sort v[0..n-1] ascending in place.
void app_sort(double* v, int n);
/// The median of v[0..n-1] (v is sorted in place; n >= 1).
double app_median(double* v, int n);
/// The scenario drive uses when none is given: the sandbox pick-and-place for
/// the ode world, the scripted lagrange demo otherwise.
const char* app_default_drive_scenario(sim_mechanics mech);

int cmd_run(int argc, char** argv);
int cmd_bench(int argc, char** argv);
int cmd_compare(int argc, char** argv);
int cmd_drive(int argc, char** argv);
int cmd_study(int argc, char** argv);

/// Plot a run's main time histories to a PNG (PLplot). Returns 0, or -1 with
/// a message (also when cranesim was built without PLplot).
int app_plot_run(const sim_trace* tr, const char* title, const char* png, char* err, size_t errsz);
/// Overlay two runs (a: solid, b: dashed) to a PNG.
int app_plot_compare(const sim_trace* a, const char* la, const sim_trace* b, const char* lb,
                     const char* title, const char* png, char* err, size_t errsz);

#endif
