// sim_base.c: the half of sim.h a backend needs (sim_base.h): the channel
// list, the default options, the run checks and their messages, the start
// check, collisions, the world file a name resolves to. Moved whole out of
// sim.c, which keeps the runs, the CSV and the step probe.
#include "sim_base.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define CH_ENTRY_(id, name, unit, kind) {name, unit, kind},
#define CH_NAME_(id, name, unit, kind) name,
#define CH_UNIT_(id, name, unit, kind) unit,
const sim_channel sim_channels[SIM_NCOL] = {SIM_CHANNELS_BASE(CH_ENTRY_) SIM_CHANNELS_WORLD(CH_ENTRY_)};
const char* const sim_col_name[SIM_NCOL] = {SIM_CHANNELS_BASE(CH_NAME_) SIM_CHANNELS_WORLD(CH_NAME_)};
const char* const sim_col_unit[SIM_NCOL] = {SIM_CHANNELS_BASE(CH_UNIT_) SIM_CHANNELS_WORLD(CH_UNIT_)};
// The README's fixed order of the first columns, and the world extras right after the base.
_Static_assert(COL_U2_CMD == 16 && COL_END_STOP == 21 && COL_SLEW == SIM_NCOL_BASE && COL_F3 == COL_SLEW + 17,
               "the channel list lost its documented order");

sim_opts sim_default_opts(void) {
    sim_opts o;
    memset(&o, 0, sizeof o);
    o.mechanics = SIM_LAGRANGE;
    // o.variant stays 0, LAGRANGE_FULL (lagrange.h asserts it): the analytic backend's full model.
    o.solver = HYD_KRUS;
    o.h = 1e-4;
    o.rtol = 1e-3;
    o.atol = 1e-6;
    o.dt_out = 1e-3;
    o.jac_every = 10;
    o.load_mass = -1.0;
    o.dt_ode = 1e-3;
    return o;
}

bool sim_have_cvode(void) {
#ifdef CRANESIM_HAVE_CVODE
    return true;
#else
    return false;
#endif
}

double sim_load_mass(const model* m, const scenario* sc, const sim_opts* o) {
    if (o->load_mass >= 0) return o->load_mass;
    return sc->load_mass >= 0 ? sc->load_mass : m->mech.load_mass;
}

double sim_wall_time(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const char* sim_world_path(const char* arg, char* buf, size_t n) {
    if (!arg) arg = "validation";
    if (strchr(arg, '/') || strstr(arg, ".json")) return arg;
    snprintf(buf, n, "%s/worlds/%s.json", model_assets_dir(), arg);
    return buf;
}

// A pressure below absolute zero cannot be physical: the pressure-dependent
// bulk modulus makes absolute zero a barrier the exact solution never
// crosses (accurate runs of every shipped scenario stay above 23 kPa). The
// fixed-step W-methods still dip below it for a step or two at a stiff event
// (Krus rings, R(-inf) = -1): -57 kPa with ROS2 at 1 ms on `overload`, -62 kPa
// with Krus in the sandbox at 0.1 ms ODE steps as a load is set down. Such a
// dip is reported as a note. Deeper than one atmosphere below zero the
// integration has left the physical range (CVODE at rtol 1e-2 on `ramp`:
// -192 kPa, then a crane falling while commanded up): a failure, like NaN
// (decision 6). The adaptive methods keep to >= 0 on their own
// (hyd_problem.outside).
static const double P_IMPLAUSIBLE = -1e5;

void sim_checks_init(sim_checks* k) { memset(k, 0, sizeof *k); }

int sim_check_value(sim_checks* k, const char* name, double v, bool pressure, double t, char* msg, size_t n) {
    // Finite first: +inf passes any lower bound, and the first row of a
    // model with an absurd value can hold it before any step ran.
    if (!isfinite(v)) {
        k->bad_value = v;
        snprintf(msg, n, "state %s = %s (not a finite number) at t = %.6g s", name,
                 isnan(v) ? "nan" : v > 0 ? "inf" : "-inf", t);
        return 1;
    }
    if (!pressure) return 0;
    if (v <= P_IMPLAUSIBLE) {
        k->bad_value = v;
        snprintf(msg, n, "state %s = %.4g Pa (more than 0.1 MPa below absolute zero) at t = %.6g s", name, v, t);
        return 2;
    }
    if (v < 0.0 && (!k->dip || v < k->dip_value)) {
        k->dip = true;
        snprintf(k->dip_name, sizeof k->dip_name, "%s", name);
        k->dip_value = v;
        k->dip_t = t;
    }
    return 0;
}

static bool col_is_pressure(int c) { return sim_channels[c].kind == SIM_CH_PRESSURE; }

int sim_check_row(sim_checks* k, const double* row, int ncol, char* msg, size_t n) {
    for (int c = 0; c < ncol; ++c) {
        const int rc = sim_check_value(k, sim_col_name[c], row[c], col_is_pressure(c), row[COL_T], msg, n);
        if (rc) return rc;
    }
    return 0;
}

void sim_checks_note(const sim_checks* k, bool adaptive, char* note, size_t n) {
    if (!k->dip) {
        if (n) note[0] = 0;
        return;
    }
    // With an adaptive solver (CVODE has no domain hook: -1.5 kPa on `step`
    // at rtol 5e-3, none at 1e-3) the step is not the user's to shorten.
    char why[160];
    if (adaptive)
        snprintf(why, sizeof why,
                 "the tolerance let the integration overshoot at a stiff event (a smaller %s avoids it)",
                 sim_param_name(SIM_PARAM_RTOL));
    else
        snprintf(why, sizeof why, "the fixed step rings at a stiff event (a smaller %s or an adaptive solver avoids it)",
                 sim_param_name(SIM_PARAM_DT));
    snprintf(note, n, "%s dipped below absolute zero, to %.3g kPa, at t = %.6g s: %s", k->dip_name,
             k->dip_value * 1e-3, k->dip_t, why);
}

// A smaller step (or tolerance) is the likely cure only after steps from an
// admissible state went wrong: not in the initial state (t = 0, no step
// taken: a bore of 1e300 gave NaN pressures there, and the advice to
// shorten a step never taken), and not for a value that is no number at all
// (the per-step check catches a NaN that a step produces, so one here comes
// from the model's values). With an adaptive solver the steps are its own:
// the tolerance is the user's lever.
const char* sim_blowup_hint(bool adaptive, double t, double value) {
    if (!(t > 0.0))
        return "the initial state is already outside the physical range (no step was taken): check the model's values";
    if (!isfinite(value)) return "a component law gave no finite number: check the model's values";
    // Per thread: sweeps run designs on several threads at once.
    static _Thread_local char hint[160];
    if (adaptive)
        snprintf(hint, sizeof hint, "the tolerance is too loose for this transient: try a smaller %s",
                 sim_param_name(SIM_PARAM_RTOL));
    else
        snprintf(hint, sizeof hint, "the step is too long for this transient: try a smaller %s or an adaptive solver",
                 sim_param_name(SIM_PARAM_DT));
    return hint;
}

void sim_check_message(char* out, size_t n, const char* what, const char* how, bool adaptive, double t,
                       double bad) {
    if (!how) snprintf(out, n, "%s: %s", what, sim_blowup_hint(adaptive, 0.0, bad));
    else snprintf(out, n, "numerical blow-up: %s (%s): %s", what, how, sim_blowup_hint(adaptive, t, bad));
}

// A relief on a boom cylinder's chamber (or on the hose that feeds it) that
// cracks below the pressure the chamber needs to hold the start pose opens
// at t = 0: the chamber cannot keep its holding pressure and the boom sinks
// from the start (a port relief set at 2 MPa under a 3.8 MPa hold). A note,
// not a refusal: a relief set to let a load down is a test one may want. The
// slew holds no weight, so only the two boom cylinders are looked at.
static void start_relief_notes(const hyd_model* hm, const double* row, int ncol, const sim_start_load* ld) {
    if (!ld || !ld->mech) return;
    static const int pcol[2][2] = {{COL_P1A, COL_P1B}, {COL_P2A, COL_P2B}};
    static const char* const joint[2] = {"lift", "jib"};
    for (int k = 0; k < 2; ++k) {
        const int cyl = hyd_model_find(hm, ld->mech->act[k].cylinder); // its component index
        if (cyl < 0 || hyd_model_comp_type(hm, cyl) != HYD_CYLINDER) continue;
        for (int s = 0; s < 2; ++s) {
            const int col = pcol[k][s];
            if (col >= ncol) continue;
            const int chamber = hyd_model_comp_node(hm, cyl, s);
            const int hose = hyd_model_feed_hose(hm, chamber);
            const int hose_node = hose >= 0 ? hyd_model_comp_node(hm, hose, 0) : -1;
            for (int i = 0; i < hyd_model_ncomp(hm); ++i) {
                if (hyd_model_comp_type(hm, i) != HYD_RELIEF) continue;
                const int in = hyd_model_port_node(hm, i, 0);
                if (in < 0 || (in != chamber && in != hose_node)) continue;
                char path[160];
                double crack = 0;
                snprintf(path, sizeof path, "%s.p_crack", hyd_model_comp_name(hm, i));
                if (hyd_model_get(hm, path, &crack) || !(row[col] > crack)) continue;
                char line[400];
                snprintf(line, sizeof line,
                         "%s cracks at %.3g MPa, below the %.3g MPa that %s (%s) needs to hold the start pose: the "
                         "relief opens at t = 0 and the %s cylinder gives way from the start",
                         hyd_model_comp_name(hm, i), crack * 1e-6, row[col] * 1e-6, hyd_model_node_name(hm, chamber),
                         sim_col_name[col], joint[k]);
                hyd_note(line);
            }
        }
    }
}

int sim_check_start(const hyd_model* hm, const double* row, int ncol, const sim_start_load* ld, char* err,
                    size_t errsz) {
    if (!hm) return 0;
    double pmax = -1;
    const char* which = NULL;
    for (int i = 0; i < hyd_model_ncomp(hm); ++i) {
        if (hyd_model_comp_type(hm, i) != HYD_RELIEF) continue;
        char path[160];
        double crack = 0, over = 0;
        const char* name = hyd_model_comp_name(hm, i);
        snprintf(path, sizeof path, "%s.p_crack", name);
        if (hyd_model_get(hm, path, &crack)) continue;
        snprintf(path, sizeof path, "%s.dp_override", name);
        if (hyd_model_get(hm, path, &over)) over = 0;
        if (crack + over > pmax) pmax = crack + over, which = name;
    }
    if (!which) return 0; // no relief: nothing bounds the pressure
    static const int pcol[6] = {COL_P1A, COL_P1B, COL_P2A, COL_P2B, COL_P3A, COL_P3B};
    for (int j = 0; j < 6; ++j) {
        const int c = pcol[j];
        if (c >= ncol || !(row[c] > pmax)) continue;
        char tip[96];
        if (ld->world_tip) snprintf(tip, sizeof tip, "the world's hook and rope at the tip (%.4g kg)", ld->m_tip);
        else snprintf(tip, sizeof tip, "%.4g kg at the tip", ld->m_tip);
        const int n = snprintf(err, errsz,
                               "the start pose needs %s = %.4g MPa to hold still, above the highest relief setting "
                               "(%s: %.4g MPa, p_crack + dp_override)",
                               sim_col_name[c], row[c] * 1e-6, which, pmax * 1e-6);
        if (n < 0 || (size_t)n >= errsz) return SIM_REFUSED;
        char* e = err + n;
        const size_t en = errsz - (size_t)n;
        // What the holding torque of the boom joint at fault is for: the
        // gravity torque G(q) with the tip mass against G without it (the
        // statics the start state is set from). The slew holds no weight.
        const int k = j / 2;
        double share = NAN; // the tip mass's share of joint k's torque
        if (ld->mech && k < 2) {
            double G[2], G0[2];
            crane_gravity(ld->mech, ld->m_tip, ld->q, G);
            crane_gravity(ld->mech, 0.0, ld->q, G0);
            if (fabs(G[k]) > 0) share = fmin(fmax((G[k] - G0[k]) / G[k], 0.0), 1.0);
        }
        static const char* const joint[2] = {"lift", "jib"};
        if (isnan(share)) {
            snprintf(e, en, ": the crane cannot hold itself and %s here (another start pose)", tip);
        } else if (share >= 0.5) {
            char fix[96];
            if (ld->world_tip) snprintf(fix, sizeof fix, "a lighter hook or rope in the world file");
            else snprintf(fix, sizeof fix, "a smaller %s", sim_param_name(SIM_PARAM_LOAD));
            snprintf(e, en, ": the crane cannot hold %s here: %.0f %% of the %s's torque, the booms' own weight %.0f %% "
                     "(%s, or another start pose)", tip, 100 * share, joint[k], 100 * (1 - share), fix);
        } else {
            snprintf(e, en,
                     ": the crane cannot hold its own booms here: their weight (mechanics.links[0].mass %.0f kg and "
                     "links[1].mass %.0f kg) is %.0f %% of the %s's torque, %s %.0f %% (lighter booms or another "
                     "start pose)",
                     ld->mech->link[0].mass, ld->mech->link[1].mass, 100 * (1 - share), joint[k], tip, 100 * share);
        }
        return SIM_REFUSED;
    }
    start_relief_notes(hm, row, ncol, ld);
    return 0;
}

int sim_check_times(double t_end, double dt_out, char* err, size_t errsz) {
    if (!(t_end > 0) || t_end > SIM_MAX_DURATION) {
        snprintf(err, errsz, "%s: expected a simulated time in s, 0 < T <= 1e6, got %g",
                 sim_param_name(SIM_PARAM_DURATION), t_end);
        return SIM_REFUSED;
    }
    if (!(dt_out > 0) || dt_out > SIM_MAX_DURATION) {
        snprintf(err, errsz, "%s: expected an output period in s, 0 < DT <= 1e6, got %g",
                 sim_param_name(SIM_PARAM_EVERY), dt_out);
        return SIM_REFUSED;
    }
    if (t_end / dt_out > 1e12) {
        snprintf(err, errsz, "%s %g s over %g s is %.3g rows, more than 1e12: use a larger %s",
                 sim_param_name(SIM_PARAM_EVERY), dt_out, t_end, t_end / dt_out, sim_param_name(SIM_PARAM_EVERY));
        return SIM_REFUSED;
    }
    return 0;
}

// A step to suggest below a stability limit lim [s]: the largest of
// {5, 2, 1} x 10^k at most lim / 2 (the limit is only a necessary condition)
// that divides the output period dt_out, so the run's own check accepts it.
static double stable_step(double lim, double dt_out) {
    for (double p10 = pow(10.0, floor(log10(0.5 * lim))); p10 > 1e-15; p10 /= 10.0)
        for (int k = 0; k < 3; ++k) {
            static const double lead[3] = {5.0, 2.0, 1.0};
            const double h = lead[k] * p10;
            const double r = dt_out / h;
            if (h <= 0.5 * lim && fabs(r - floor(r + 0.5)) <= 1e-9 * r) return h;
        }
    return 0.5 * lim;
}

// Refuse a fixed-step run the method cannot do: RK4 beyond its stability
// interval on the circuit's fastest mode (it would ring or freeze instead of
// integrating), a step longer than the run, or more than 1e12 steps.
// Returns 0, or 2 with the reason in res->message.
int sim_check_fixed_step(const hyd_model* hm, const sim_opts* o, double h, double t_end, char* err, size_t errsz) {
    if (o->cvode || hyd_method_is_adaptive(o->solver)) return 0;
    // The step h is the hydraulic one: in the ode world min(dt, dt_ode),
    // so name the setting it came from.
    const int which = h < o->h ? SIM_PARAM_DT_ODE : SIM_PARAM_DT;
    if (t_end > 0 && h > t_end) {
        snprintf(err, errsz, "%s %g s is longer than the run (%g s)", sim_param_name(which), h, t_end);
        return SIM_REFUSED;
    }
    if (t_end > 0 && t_end / h > 1e12) {
        snprintf(err, errsz, "%s %g s over %g s is %.3g steps, more than 1e12: use a larger %s or a shorter run",
                 sim_param_name(which), h, t_end, t_end / h, sim_param_name(which));
        return SIM_REFUSED;
    }
    if (o->solver == HYD_RK4) {
        // RK4's stability interval on the negative real axis is [-2.785, 0].
        // The circuit's fastest mode: an open valve edge with no pressure
        // drop across it (laminar, steepest) between the pump line and a
        // hose, at the reliefs' pressure (2.6e5 1/s on the default crane;
        // 4.8e4 with the valves closed). A necessary condition only: the
        // mechanics and the end stops are not in this J.
        const double rate = fmax(hyd_model_fastest_rate(hm, 25e6, 0.0), hyd_model_fastest_rate(hm, 25e6, 1.0));
        if (rate > 0.0 && h * rate > 2.785) {
            snprintf(err, errsz,
                     "rk4 is unstable at h = %g s on this circuit: its fastest mode (%.3g 1/s, an open valve at "
                     "25 MPa) needs h < %.3g s at the least; use %s %g or a stiff solver (krus, ros2, rodas3)",
                     h, rate, 2.785 / rate, sim_param_name(SIM_PARAM_DT), stable_step(2.785 / rate, o->dt_out));
            return SIM_REFUSED;
        }
    }
    return 0;
}

void sim_collisions_step(sim_collisions* c, double t, const char* const names[][2], int n) {
    c->have = true;
    for (int i = 0; i < n; ++i) {
        char nm[sizeof c->pair[0]];
        snprintf(nm, sizeof nm, "%s x %s", names[i][0], names[i][1]);
        int k = 0;
        while (k < c->npair && strcmp(c->pair[k], nm)) ++k;
        if (k == c->npair) {
            // A pair never seen: a new event.
            if (c->npair == SIM_MAXCOLL) continue;
            ++c->count;
            memcpy(c->pair[k], nm, sizeof nm);
            c->first_t[k] = c->last_t[k] = t;
            ++c->npair;
            continue;
        }
        if (t - c->last_t[k] >= SIM_COLL_GAP) ++c->count; // touching again after a gap
        c->last_t[k] = t;
    }
}

void sim_collisions_text(const sim_collisions* c, char* buf, size_t n) {
    if (n == 0) return;
    size_t L = (size_t)snprintf(buf, n, "collisions %ld", c->count);
    for (int k = 0; k < c->npair && L < n; ++k)
        L += (size_t)snprintf(buf + L, n - L, "%s%s at %.3f s", k ? ", " : " (", c->pair[k], c->first_t[k]);
    if (c->npair && L < n) snprintf(buf + L, n - L, ")");
}

void sim_trace_free(sim_trace* tr) {
    free(tr->v);
    memset(tr, 0, sizeof *tr);
}

int sim_trace_push(sim_trace* tr, const double* row) {
    if (tr->nrow == tr->cap) {
        int cap = tr->cap ? 2 * tr->cap : 4096;
        double* v = realloc(tr->v, (size_t)cap * SIM_NCOL * sizeof(double));
        if (!v) return -1;
        tr->v = v;
        tr->cap = cap;
    }
    memcpy(tr->v + (size_t)tr->nrow * SIM_NCOL, row, SIM_NCOL * sizeof(double));
    ++tr->nrow;
    return 0;
}
