// app_checks.c: what a run is refused or told before it starts (options it
// cannot honour, options with no effect, the world a scenario needs), and the
// exit code of a world-library status.
#include "app.h"
#include "engine.h"
#include "world_desc.h"

#include <ctype.h>
#include <limits.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

static bool is_adaptive(const sim_opts* o) { return o->cvode || hyd_method_is_adaptive(o->solver); }
static const char* solver_name(const sim_opts* o) { return o->cvode ? "cvode" : hyd_method_name(o->solver); }

// The kind of the ode world o runs on (WORLD_VALIDATION, WORLD_SANDBOX), or
// -1 with the loader's message in err.
static int world_kind_of(const sim_opts* o, char* err, size_t errsz) {
    char buf[512];
    world_desc wd;
    if (world_desc_load(sim_world_path(o->world, buf, sizeof buf), &wd, err, errsz)) return -1;
    const int kind = (int)wd.kind;
    world_desc_free(&wd);
    return kind;
}

// The run o is in a world (its backend takes one) that is a sandbox: the
// hook, the loads as bodies, the slewing column.
static bool in_sandbox(const sim_opts* o) {
    char err[512];
    return app_backend(o)->world && world_kind_of(o, err, sizeof err) == WORLD_SANDBOX;
}

bool app_world_has_slew(const sim_opts* o) { return in_sandbox(o); }

// Filters for engine_backend_names: the backends an option applies to.
static bool takes_world(const engine_backend* b) { return b->world; }
static bool takes_outer_step(const engine_backend* b) { return b->outer_step_opt != NULL; }
static bool takes_variant(const engine_backend* b) { return b->variant; }
static bool takes_cvode(const engine_backend* b) { return b->no_cvode == NULL; }

// |a / b - round(a / b)| within 1e-9 relative: a is a whole multiple of b.
static bool whole_multiple(double a, double b) {
    const double r = a / b;
    return fabs(r - floor(r + 0.5)) <= 1e-9 * r;
}

double app_output_period(const sim_opts* o) {
    if (app_backend(o)->outer_step_opt) { // rows at whole outer steps
        const double n = floor(o->dt_out / o->dt_ode + 0.5);
        return (n < 1 ? 1 : n) * o->dt_ode;
    }
    if (!is_adaptive(o) && o->h > o->dt_out) return o->h;
    return o->dt_out;
}

int app_check_sim(const char* cmd, const sim_opts* o, unsigned given) {
    if (o->cvode && !sim_have_cvode()) {
        fprintf(stderr, "cranesim %s: --solver cvode: this build has no CVODE (install libsundials-dev and rebuild)\n",
                cmd);
        return EXIT_USAGE;
    }
    const engine_backend* b = app_backend(o);
    if (o->cvode && b->no_cvode) {
        char names[128];
        fprintf(stderr, "cranesim %s: --solver cvode works with --mechanics %s only (%s): use krus, ros2, rk4, "
                        "ros34pw2 or rodas3\n",
                cmd, engine_backend_names(names, sizeof names, takes_cvode), b->no_cvode);
        return EXIT_USAGE;
    }
    // Fixed steps land on every output time: an output period that is not a
    // whole number of steps would shorten steps (more steps, more LUs and
    // different results than the --dt asked for); the ode world writes rows
    // at whole ODE steps only. A step longer than the period gives one row
    // per step (decision 7).
    const bool outer = b->outer_step_opt != NULL; // rows at whole steps of the backend's own step
    const double step = outer ? o->dt_ode : o->h;
    if ((outer || !is_adaptive(o)) && o->dt_out > step && !whole_multiple(o->dt_out, step)) {
        const double lo = floor(o->dt_out / step) * step, hi = lo + step;
        const bool given_every = given & APP_GIVEN(APP_OPT_EVERY);
        char what[96], why[96], alt[96];
        snprintf(what, sizeof what, "the %s %s", outer ? b->step_name : "fixed step",
                 outer ? b->outer_step_opt : "--dt");
        if (outer) snprintf(why, sizeof why, "rows come at whole %ss", b->step_name);
        else snprintf(why, sizeof why, "the solver would shorten steps to land on the output times");
        snprintf(alt, sizeof alt, ", or a %s that divides it", outer ? b->outer_step_opt : "--dt");
        fprintf(stderr, "cranesim %s: %s %g s is not a whole multiple of %s %g s (%s): use --every %g or %g%s\n",
                cmd, given_every ? "--every" : "the default output period --every", o->dt_out, what, step, why, lo,
                hi, given_every ? "" : alt);
        return EXIT_USAGE;
    }
    if (b->world && (given & APP_GIVEN(APP_OPT_LOAD))) {
        char err[512];
        const int kind = world_kind_of(o, err, sizeof err);
        if (kind < 0) {
            fprintf(stderr, "cranesim %s: %s\n", cmd, err);
            return EXIT_USAGE;
        }
        if (kind == WORLD_SANDBOX) {
            fprintf(stderr,
                    "cranesim %s: --load: the sandbox world's loads are objects of the world file (loads[].mass); "
                    "--load sets the tip load of lagrange and the validation world\n",
                    cmd);
            return EXIT_USAGE;
        }
    }
    return 0;
}

void app_settle_unused(sim_opts* o) {
    if (app_backend(o)->outer_step_opt && is_adaptive(o)) o->h = o->dt_ode;
}

void app_note_unused(const char* cmd, unsigned given, const sim_opts* o, int n) {
    // Each rule: the option, and why a run does not use it (NULL: it does).
    for (int opt = 0; opt < APP_OPT_COUNT; ++opt) {
        if (!(given & APP_GIVEN(opt))) continue;
        const char* why = NULL;
        char buf[160];
        for (int s = 0; s < n; ++s) {
            const sim_opts* r = &o[s];
            const char* w = NULL;
            switch (opt) {
            case APP_OPT_DT:
                if (is_adaptive(r)) {
                    snprintf(buf, sizeof buf, "with the adaptive solver %s (steps from --rtol/--atol)", solver_name(r));
                    w = buf;
                }
                break;
            case APP_OPT_RTOL:
            case APP_OPT_ATOL:
                if (!is_adaptive(r)) {
                    snprintf(buf, sizeof buf, "with the fixed-step solver %s (steps of --dt)", solver_name(r));
                    w = buf;
                }
                break;
            case APP_OPT_NO_RETRY:
            case APP_OPT_NO_STEP_PROBE:
                if (is_adaptive(r)) {
                    snprintf(buf, sizeof buf, "with the adaptive solver %s (fixed-step solvers only)", solver_name(r));
                    w = buf;
                }
                break;
            case APP_OPT_JAC_EVERY:
            case APP_OPT_DENSE_JAC:
                if (is_adaptive(r)) {
                    snprintf(buf, sizeof buf, "with the adaptive solver %s (fixed-step solvers only)", solver_name(r));
                    w = buf;
                } else if (r->solver == HYD_RK4) {
                    w = "with rk4 (an explicit method: no Jacobian)";
                }
                break;
            case APP_OPT_WORLD:
            case APP_OPT_DT_ODE: {
                const engine_backend* b = app_backend(r);
                const bool world = opt == APP_OPT_WORLD;
                if (world ? !b->world : !b->outer_step_opt) {
                    char names[128];
                    snprintf(buf, sizeof buf, "with --mechanics %s (%s only)", b->name,
                             engine_backend_names(names, sizeof names, world ? takes_world : takes_outer_step));
                    w = buf;
                }
                break;
            }
            case APP_OPT_VARIANT:
                if (!app_backend(r)->variant) {
                    char names[128];
                    snprintf(buf, sizeof buf, "with --mechanics %s (the Lagrange equations are %s's)",
                             app_backend(r)->name, engine_backend_names(names, sizeof names, takes_variant));
                    w = buf;
                }
                break;
            default: break;
            }
            if (!w) { // this run uses the option
                why = NULL;
                break;
            }
            why = w;
        }
        if (why) fprintf(stderr, "cranesim %s: note: %s has no effect %s%s\n", cmd, app_opt_name[opt], why,
                         n > 1 ? " in both runs" : "");
    }
}

void app_note_load(const char* cmd, const app_common* c, const sim_opts* o, const scenario* sc) {
    const char* set = NULL;
    static const char path[] = "mechanics.load_mass=";
    for (int i = 0; i < c->nset; ++i)
        if (!strncmp(c->sets[i], path, sizeof path - 1)) set = c->sets[i];
    // A scenario written for the tip load (overload, hold) run in the
    // sandbox: its load_mass does not apply there either.
    if (!set && sc->load_mass >= 0 && in_sandbox(o))
        fprintf(stderr,
                "cranesim %s: note: scenario %s's load_mass (%g kg) has no effect: the sandbox world's loads are "
                "world objects\n",
                cmd, sc->name, sc->load_mass);
    if (!set) return;
    const char* v = set + sizeof path - 1;
    if (in_sandbox(o))
        fprintf(stderr, "cranesim %s: note: --set %s has no effect: the sandbox world's loads are world objects\n", cmd,
                set);
    else if (o->load_mass >= 0)
        fprintf(stderr, "cranesim %s: note: --set %s has no effect: --load %g kg sets the tip load\n", cmd, set,
                o->load_mass);
    else if (sc->load_mass >= 0)
        fprintf(stderr,
                "cranesim %s: note: --set %s has no effect: scenario %s sets its own load (%g kg); use --load %s\n",
                cmd, set, sc->name, sc->load_mass, v);
}

// What in a scenario needs a slewing column (NULL: nothing).
static const char* slew_use(const scenario* sc) {
    const scenario_signal* sl = &sc->cmd[2];
    for (int i = 0; i < sl->n; ++i)
        if (sl->u[i] != 0) return "slews the crane";
    return sc->slew0 != 0 ? "starts slewed" : NULL;
}

// What in a scenario needs the sandbox (NULL: nothing): the hook, the slew.
static const char* sandbox_use(const scenario* sc) { return sc->nevent > 0 ? "works the hook" : slew_use(sc); }

// The crane a backend runs for model m, as the slew messages name it: the
// backend's own words for the two-link crane ("lagrange 2-DOF crane"), "the
// lagrange crane chain" for any other chain, and why it cannot slew where
// the backend could but the model has no slew drive.
static void crane_words(const engine_backend* b, const model* m, char* out, size_t n) {
    if (!m || m->chain.two_link) {
        snprintf(out, n, "%s crane", b->crane);
        return;
    }
    snprintf(out, n, "%s crane chain%s", b->name,
             b->slew_dof && !m->chain.slew.present ? " (its model has no slew drive: mechanics.slew)" : "");
}

void app_note_scenario_slew(const char* cmd, const sim_opts* o, const model* m, const scenario* sc,
                            int world_kind) {
    const engine_backend* b = app_backend(o);
    const char* why = b->world && world_kind == WORLD_SANDBOX ? NULL : slew_use(sc);
    if (!why) return;
    const engine_backend* wb = engine_backend_with_world();
    char crane[128], remedy[256] = "";
    if (b->world) snprintf(crane, sizeof crane, "validation world");
    else crane_words(b, m, crane, sizeof crane);
    // A backend whose scripted runs slew the model's drive (the slew as a
    // degree of freedom) still drives a column that stands still.
    const bool scripted = b->slew_dof && !b->world && m->chain.slew.present && sc->nevent == 0 &&
                          scenario_commands(sc, "slew");
    if (wb)
        snprintf(remedy, sizeof remedy, " (the %s has one: --mechanics %s --world %s%s%s%s)", wb->drive_world,
                 wb->name, wb->drive_world, scripted ? "; cranesim run --mechanics " : "", scripted ? b->name : "",
                 scripted ? " slews it" : "");
    fprintf(stderr, "cranesim %s: note: scenario %s %s, which the %s has not%s: its slew is ignored%s\n", cmd,
            sc->name[0] ? sc->name : "the scenario", why, crane, scripted ? " when driven" : "", remedy);
}

int app_scenario_world(const char* cmd, sim_opts* o, unsigned given, const model* m, const scenario* sc,
                       bool may_switch, bool* switched) {
    return app_scenario_world_remedy(cmd, o, given, m, sc, may_switch, switched, NULL, false);
}

int app_scenario_world_remedy(const char* cmd, sim_opts* o, unsigned given, const model* m, const scenario* sc,
                              bool may_switch, bool* switched, const char* remedy, bool quiet) {
    if (switched) *switched = false;
    const char* why = sandbox_use(sc);
    if (!why) return 0;
    const char* name = sc->name[0] ? sc->name : "the scenario";
    const bool world_given = given & APP_GIVEN(APP_OPT_WORLD), mech_given = given & APP_GIVEN(APP_OPT_MECHANICS);
    char err[512];
    const engine_backend* b = app_backend(o);
    // A backend without a world asked for by name (--mechanics) that slews
    // the model's drive as a degree of freedom runs a scenario that only
    // slews (no hook events) as it is: the column turns by the rack and the
    // scenario's slew commands (decisions.d/slewdof.md). Without --mechanics
    // the scenario still goes to its world (decision 51).
    if (b->slew_dof && !b->world && mech_given && !world_given && sc->nevent == 0 && m && m->chain.slew.present &&
        scenario_commands(sc, "slew"))
        return 0;
    // The backend with a world: --world without --mechanics asks for it as
    // much as --mechanics naming it does.
    const engine_backend* wb = engine_backend_with_world();
    if (!wb) {
        fprintf(stderr, "cranesim %s: scenario %s %s: no backend has a world\n", cmd, name, why);
        return EXIT_USAGE;
    }
    if (b->world || (world_given && !mech_given)) {
        const int kind = world_kind_of(o, err, sizeof err);
        // A world file that does not load is the first thing wrong: say that,
        // not that the scenario needs another world.
        if (kind < 0 && (b->world || world_given)) {
            fprintf(stderr, "cranesim %s: %s\n", cmd, err);
            return EXIT_USAGE;
        }
        if (kind == WORLD_SANDBOX) {
            if (!b->world) {
                app_use_backend(o, wb);
                if (switched) *switched = true;
                if (!quiet)
                    fprintf(stderr, "cranesim %s: note: scenario %s %s: it runs with --mechanics %s in --world %s\n",
                            cmd, name, why, wb->name, o->world);
            }
            return 0;
        }
    }
    // No world chosen (--world), and no backend or one with a world: the
    // world the scenario needs, that backend's drive world.
    if (may_switch && !world_given && (!mech_given || b->world)) {
        const engine_backend* to = b->world ? b : wb;
        app_use_backend(o, to);
        o->world = to->drive_world;
        if (switched) *switched = true;
        if (!quiet)
            fprintf(stderr, "cranesim %s: note: scenario %s %s: it runs in its world, --mechanics %s --world %s\n",
                    cmd, name, why, to->name, to->drive_world);
        return 0;
    }
    char crane[128], dflt[160];
    if (b->world || (world_given && !mech_given)) snprintf(crane, sizeof crane, "validation world");
    else crane_words(b, m, crane, sizeof crane);
    snprintf(dflt, sizeof dflt, "run it with --mechanics %s --world %s", wb->name, wb->drive_world);
    fprintf(stderr, "cranesim %s: scenario %s %s, which the %s has not: %s\n", cmd, name, why, crane,
            remedy ? remedy : dflt);
    return EXIT_USAGE;
}

int app_exit_code(int status, long rows) {
    if (status == SIM_OK) return EXIT_OK_;
    if (status == SIM_FAILED || rows > 0) return EXIT_RUNTIME;
    return EXIT_USAGE;
}
