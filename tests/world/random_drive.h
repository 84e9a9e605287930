// random_drive.h: a seeded random operator in the sandbox, stepped through
// the engine as `drive` steps it (10 ms frames, commands through
// engine_set_commands and so through the rated capacity limiter), with the
// limiter's figures: its largest utilisation, the time at or above 90 %,
// and how much of that time the lift cylinder was near an end stop. The
// same seed gives the same drive, bit for bit. Used by test_rcl (a short
// drive) and rcl_soak (any length; not a ctest).
#ifndef RANDOM_DRIVE_H
#define RANDOM_DRIVE_H

#include "engine.h"
#include "model.h"
#include "rcl.h"
#include "sim.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// xorshift64*: a fixed, portable sequence per seed.
static inline double rd_rand(uint64_t* s) {
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * 0x1.0p-53; // [0, 1)
}

// One stick: linear from (t0, u0) to (t1, u1), then a new segment of
// 0.5..4 s towards a random opening, a third of them 0 (the operator lets
// go of the stick often).
typedef struct rd_ramp {
    double t0, t1, u0, u1;
} rd_ramp;

static inline double rd_command(rd_ramp* r, uint64_t* rng, double t) {
    while (t >= r->t1) {
        r->t0 = r->t1;
        r->u0 = r->u1;
        r->t1 = r->t0 + 0.5 + 3.5 * rd_rand(rng);
        const double a = rd_rand(rng);
        r->u1 = a < 1.0 / 3 ? 0.0 : 2.0 * rd_rand(rng) - 1.0;
    }
    return r->u0 + (r->u1 - r->u0) * (t - r->t0) / (r->t1 - r->t0);
}

typedef struct rd_result {
    double t_end;        ///< simulated time reached [s]
    double util_max;     ///< largest rcl_util [-]
    double t_util_max;   ///< when [s]
    double t90;          ///< time at or above RCL_WARN [s]
    double t90_stop;     ///< of which the lift cylinder was within 10 mm of an end stop [s]
    double t90_over;     ///< of which the hooked load was over the chart (its mass over the capacity >= RCL_WARN) [s]
    double t90_contact;  ///< of which a crane body touched the world or the truck within the last 2 s (the
                         ///< filter's settling) [s]
    double t90_other;    ///< none of these [s]
    double t90_run;      ///< the longest uninterrupted stretch at or above RCL_WARN [s]
    double t90_run_at;   ///< when it ended [s]
    double t_stop;       ///< time the lift cylinder spent within the band [s]
    double u_cut;        ///< time a command was cut by the limiter [s]
    double true_max;     ///< largest hooked mass over the capacity where it hangs [-]
    int picks;           ///< loads hooked
    int failed;          ///< the engine stopped (a failed check)
    char err[300];
} rd_result;

/// A random drive of `duration` s in the sandbox on model m, seed `seed`,
/// the limiter on. verbose: a line per second at or above 90 %.
static inline int random_drive(const model* m, uint64_t seed, double duration, bool verbose, rd_result* res) {
    memset(res, 0, sizeof *res);
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = CRANESIM_ASSETS "/worlds/sandbox.json";
    o.rcl = true;
    const double q0[2] = {117.3 * M_PI / 180, -65.8 * M_PI / 180};
    engine* e = engine_create(m, &o, q0, -60 * M_PI / 180, -1, res->err, sizeof res->err);
    if (!e) return -1;
    const rcl* r = engine_rcl(e);
    if (!r) {
        snprintf(res->err, sizeof res->err, "the engine has no limiter");
        engine_destroy(e);
        return -1;
    }
    // The lift cylinder near an end stop: within 10 mm of either end (the
    // limiter's RCL_STOP_BAND), from q1 as the limiter has it.
    double AA, AB, stroke;
    hyd_model_cylinder_geometry(m->hyd, m->cyl[0], &AA, &AB, &stroke);
    uint64_t rng = seed ? seed : 1;
    rd_ramp ramp[3];
    memset(ramp, 0, sizeof ramp);
    double next_hook = 2.0 + 8.0 * rd_rand(&rng);
    int attach = 1;
    const double frame = 0.01;
    const long nframes = (long)ceil(duration / frame - 1e-9);
    double row[SIM_NCOL], last_print = -1, run = 0;
    for (long i = 0; i < nframes; ++i) {
        const double tm = (i + 0.5) * frame;
        const double u[3] = {rd_command(&ramp[0], &rng, tm), rd_command(&ramp[1], &rng, tm),
                             rd_command(&ramp[2], &rng, tm)};
        if (tm >= next_hook) {
            const int got = engine_hook(e, attach);
            res->picks += attach && got >= 0;
            // Released, or nothing in reach: try the other way next time.
            attach = attach && got >= 0 ? 0 : 1;
            next_hook = tm + 5.0 + 15.0 * rd_rand(&rng);
        }
        engine_set_commands(e, u);
        if (r->stopped) res->u_cut += frame;
        if (engine_advance_to(e, (i + 1) * frame, NULL, NULL)) {
            res->failed = 1;
            snprintf(res->err, sizeof res->err, "%s", engine_error(e));
            break;
        }
        engine_row(e, row);
        const double util = row[COL_RCL_UTIL];
        double mass = 0;
        const int att = (int)row[COL_ATTACHED];
        if (att >= 0) engine_load_name(e, att, &mass);
        const double cap = loadchart_capacity(&r->chart, r->R, row[COL_SLEW], NULL);
        const double tru = cap > 0 ? mass / cap : 0;
        res->true_max = fmax(res->true_max, tru);
        if (util > res->util_max) res->util_max = util, res->t_util_max = row[COL_T];
        const double x_lift = crane_stroke(&m->mech.act[0], row[COL_Q1]);
        const bool near = x_lift < 0.01 || x_lift > stroke - 0.01;
        if (near) res->t_stop += frame;
        const sim_collisions* co = engine_collisions(e);
        bool touch = false;
        for (int k = 0; co && k < co->npair; ++k) touch |= co->last_t[k] > row[COL_T] - 2.0;
        run = util >= RCL_WARN ? run + frame : 0;
        if (run > res->t90_run) res->t90_run = run, res->t90_run_at = row[COL_T];
        if (util >= RCL_WARN) {
            res->t90 += frame;
            if (near) res->t90_stop += frame;
            if (tru >= RCL_WARN) res->t90_over += frame;
            if (touch) res->t90_contact += frame;
            if (!near && tru < RCL_WARN && !touch) {
                res->t90_other += frame;
                if (verbose) printf("  t %7.2f s: util %.3f, other\n", row[COL_T], util);
            }
            if (verbose && row[COL_T] - last_print >= 0.5) {
                last_print = row[COL_T];
                printf("  t %7.2f s: util %.3f, hooked %.0f kg over capacity %.0f kg at R %.2f m, slew %.1f deg, "
                       "lift x %.3f m (%s), p1A %.2f p1B %.2f MPa, end_stop %d; sticks %+.2f %+.2f %+.2f, "
                       "let through %+.2f %+.2f %+.2f\n",
                       row[COL_T], util, mass, cap, r->R, row[COL_SLEW] * 180 / M_PI, x_lift,
                       near ? "near a stop" : "clear", row[COL_P1A] * 1e-6, row[COL_P1B] * 1e-6,
                       (int)row[COL_END_STOP], u[0], u[1], u[2], row[COL_U1_CMD], row[COL_U2_CMD], row[COL_U3_CMD]);
                // What the crane touches (the booms' contacts with the truck
                // or the world), the pairs that touched within the last second.
                for (int k = 0; co && k < co->npair; ++k)
                    if (co->last_t[k] > row[COL_T] - 1.0) printf("      touching: %s\n", co->pair[k]);
            }
        }
    }
    res->t_end = engine_time(e);
    engine_destroy(e);
    return 0;
}

#endif
