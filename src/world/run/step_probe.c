// step_probe.c: the step probe (step_probe.h): the `step` scenario's
// commands run on the analytic backend at the step asked for and at
// SIM_PROBE_ABOVE, compared. Moved whole out of sim.c: engine.c applies it,
// and it runs the analytic backend's scripted run directly, so neither
// depends on the other in a circle (sim_run -> engine_run -> probe -> sim_run).
#include "step_probe.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "engine_lagrange.h"

// The probe's rows into its trace (sim_trace_push); non-zero stops the run.
static int probe_row(void* user, const double* row) { return user && sim_trace_push(user, row); }

// The probe: the `step` scenario's commands (assets/scenarios/step.json):
// the lift valve opened and closed as steps, then the jib's, then the
// lift lowering, 500 kg from the pose (100, -110) deg. These are the
// transients on which the shipped cranes' fixed steps fail first (the LS
// crane at Krus 0.2 ms, ROS2 0.5 ms; issue 25).
static const char probe_json[] =
    "{\"name\": \"step probe\", \"description\": \"abrupt valve steps\", \"duration\": 6.5, \"load_mass\": 500,"
    " \"initial\": {\"q1_deg\": 100, \"q2_deg\": -110},"
    " \"commands\": {\"lift\": [[0, 0], [1, 0], [1, 0.8], [3, 0.8], [3, 0], [5, 0], [5, -0.6], [6, -0.6], [6, 0]],"
    " \"jib\": [[0, 0], [3.5, 0], [3.5, 0.8], [5.5, 0.8], [5.5, 0]]}}";

// The probe's accuracy limits: RMS of the difference from the run at
// SIM_PROBE_ABOVE over the probe, relative to the reference's peak. The
// gross failure they catch is a spool or check valve that a long fixed step
// leaves ringing or stuck (the LS crane at Krus 0.2 ms: the jib's stroke
// 31 % off on these commands, where ROS2 at 1 ms is 1.2 % and the standard
// crane at Krus 1 ms 0.2 %; issue 25 item 7).
#define PROBE_STROKE_TOL 0.05
#define PROBE_PRESSURE_TOL 0.15

// 0 when the probe runs through at step h, 1 on a numerical failure (what
// in why), -1 when it could not be run (then nothing is refused). The rows
// (every 1 ms) go to tr when it is not NULL.
static int probe_at(const model* m, const scenario* sc, const sim_opts* o, double h, sim_trace* tr, char* why,
                    size_t whysz) {
    sim_opts p = sim_default_opts();
    p.solver = o->solver;
    p.h = h;
    p.dt_out = h > 1e-3 ? h : 1e-3;
    p.jac_every = o->jac_every;
    p.dense_jac = o->dense_jac;
    p.kernel = o->kernel;
    p.variant = o->variant;
    p.no_retry = o->no_retry;
    p.no_step_probe = true;
    // The analytic backend's scripted run itself, as sim_run would reach it
    // for these options (lagrange, no faults, probe off: p.no_step_probe),
    // without the engine, which applies this probe.
    sim_result r;
    memset(&r, 0, sizeof r);
    const double t_end = sc->duration;
    if (sim_check_times(t_end, p.dt_out, r.message, sizeof r.message)) return -1;
    const engine_sink k = {.row = probe_row, .user = tr, .rows = tr != NULL, .summary = tr != NULL, .t_end = t_end};
    const int rc = engine_lagrange_ops.run(m, sc, &p, &k, &r);
    if (rc == SIM_OK) return 0;
    if (rc != SIM_FAILED) return -1;
    // "numerical blow-up: state X = V Pa (...) at t = T s (solver ...": up to the solver.
    const char* cut = strstr(r.message, " (solver");
    snprintf(why, whysz, "%.*s", cut ? (int)(cut - r.message) : (int)strlen(r.message), r.message);
    return 1;
}

// Compare a probe's rows with the reference's: 0 when every stroke and
// chamber pressure is within the limits, else 1 with the worst in why.
static int probe_compare(const sim_trace* a, const sim_trace* ref, char* why, size_t whysz) {
    static const int col[6] = {COL_X1, COL_X2, COL_P1A, COL_P1B, COL_P2A, COL_P2B};
    static const char* name[6] = {"lift stroke x1", "jib stroke x2", "p1A", "p1B", "p2A", "p2B"};
    // The reference's rows are every 1 ms from t = 0; a row of a at t is
    // compared with the reference's row at the same t (a step longer than
    // 1 ms writes one row per step).
    double worst = 0.0;
    int wi = -1;
    for (int k = 0; k < 6; ++k) {
        double ss = 0.0, peak = 0.0;
        int n = 0;
        for (int i = 0; i < a->nrow; ++i) {
            const double* ra = a->v + (size_t)i * SIM_NCOL;
            const long j = lround(ra[COL_T] / 1e-3);
            if (j < 0 || j >= ref->nrow) continue;
            const double* rr = ref->v + (size_t)j * SIM_NCOL;
            if (fabs(rr[COL_T] - ra[COL_T]) > 1e-9) continue;
            const double d = ra[col[k]] - rr[col[k]];
            ss += d * d;
            ++n;
        }
        for (int j = 0; j < ref->nrow; ++j) peak = fmax(peak, fabs(ref->v[(size_t)j * SIM_NCOL + col[k]]));
        if (n < 2 || !(peak > 0.0)) continue;
        const double rel = sqrt(ss / n) / peak;
        const double tol = k < 2 ? PROBE_STROKE_TOL : PROBE_PRESSURE_TOL;
        if (!(rel <= tol) && (wi < 0 || rel / tol > worst)) {
            worst = rel / tol;
            wi = k;
            snprintf(why, whysz, "the %s %.0f %% RMS of its peak off the %g ms run, more than %.0f %%", name[k],
                     100.0 * rel, 1e3 * SIM_PROBE_ABOVE, 100.0 * tol);
        }
    }
    return wi >= 0;
}

// 0 when step h runs the probe through and within the limits; 1 with the
// reason in why otherwise; -1 when it could not be judged.
static int probe_judge(const model* m, const scenario* sc, const sim_opts* o, double h, const sim_trace* ref,
                       char* why, size_t whysz) {
    sim_trace tr = {0};
    int rc = probe_at(m, sc, o, h, ref ? &tr : NULL, why, whysz);
    if (rc == 0 && ref && probe_compare(&tr, ref, why, whysz)) rc = 2;
    sim_trace_free(&tr);
    return rc;
}

int sim_check_step_probe(const model* m, const sim_opts* o, double h, char* err, size_t errsz) {
    if (o->no_step_probe || o->cvode || (o->solver != HYD_KRUS && o->solver != HYD_ROS2)) return 0;
    if (!(h > SIM_PROBE_ABOVE * (1.0 + 1e-9))) return 0;
    cJSON* root = cJSON_Parse(probe_json);
    scenario sc;
    char why[256] = "", e2[256];
    int rc = -1;
    sim_trace ref = {0};
    const bool have_sc = root && scenario_from_json(root, "(step probe)", &sc, e2, sizeof e2) == 0;
    // The reference: the same method at SIM_PROBE_ABOVE, the step every
    // shipped model is validated at. Without it (it failed) only blow-ups
    // are judged.
    const sim_trace* refp = NULL;
    if (have_sc) {
        char w0[256];
        if (probe_at(m, &sc, o, SIM_PROBE_ABOVE, &ref, w0, sizeof w0) == 0) refp = &ref;
        rc = probe_judge(m, &sc, o, h, refp, why, sizeof why);
    }
    if (rc != 1 && rc != 2) {
        if (root) cJSON_Delete(root);
        sim_trace_free(&ref);
        return 0;
    }
    // The largest {5, 2, 1} x 10^k below h dividing the output period that
    // passes; SIM_PROBE_ABOVE (not probed) when none above it does.
    double ok = SIM_PROBE_ABOVE;
    char w2[256];
    for (double p10 = pow(10.0, floor(log10(h))); p10 > SIM_PROBE_ABOVE * 0.999 && ok == SIM_PROBE_ABOVE; p10 /= 10.0)
        for (int k = 0; k < 3; ++k) {
            static const double lead[3] = {5.0, 2.0, 1.0};
            const double c = lead[k] * p10;
            const double r = o->dt_out / c;
            if (!(c < h * (1.0 - 1e-9)) || !(c > SIM_PROBE_ABOVE * (1.0 + 1e-9)) ||
                fabs(r - floor(r + 0.5)) > 1e-9 * r)
                continue;
            if (probe_judge(m, &sc, o, c, refp, w2, sizeof w2) == 0) {
                ok = c;
                break;
            }
        }
    cJSON_Delete(root);
    sim_trace_free(&ref);
    const int which = o->h > h ? SIM_PARAM_DT_ODE : SIM_PARAM_DT;
    snprintf(err, errsz,
             "%s at %s %g s %s on this model's abrupt valve steps (the `step` scenario's commands, 500 kg, "
             "probed before the run: %s); the largest step that runs them %s is %g s: use %s %g or an adaptive "
             "solver (ros34pw2, rodas3), or %s to run this step unchecked",
             hyd_method_name(o->solver), sim_param_name(which), h, rc == 1 ? "blows up" : "is inaccurate", why,
             refp ? "within the limits" : "through", ok, sim_param_name(SIM_PARAM_DT), ok,
             sim_param_name(SIM_PARAM_NO_STEP_PROBE));
    return SIM_REFUSED;
}
