// sim.c: headless runs of the lagrange crane (the ode backend plugs in here
// through ode_world when present).
#include "sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef CRANESIM_HAVE_CVODE
#include "hyd_cvode.h"
#endif
#include "ode_world.h"

const char* const sim_col_name[SIM_NCOL] = {
    "t", "x1", "x2", "p1A", "p1B", "p2A", "p2B", "u1", "u2", "q1", "q2",
    "tip_x", "tip_z", "F1", "F2", "u1_cmd", "u2_cmd",
    "v1", "v2", "p_pump", "relief_open", "end_stop",
    "slew", "hook_x", "hook_y", "hook_z", "load_x", "load_y", "load_z", "attached", "truck_tilt", "contacts",
    "max_depth", "x3", "v3", "p3A", "p3B", "u3", "u3_cmd", "F3"};
const char* const sim_col_unit[SIM_NCOL] = {
    "s", "m", "m", "Pa", "Pa", "Pa", "Pa", "-", "-", "rad", "rad",
    "m", "m", "N", "N", "-", "-",
    "m/s", "m/s", "Pa", "count", "bits",
    "rad", "m", "m", "m", "m", "m", "m", "index", "rad", "count", "m", "m", "m/s", "Pa", "Pa", "-", "-", "N"};

sim_opts sim_default_opts(void) {
    sim_opts o;
    memset(&o, 0, sizeof o);
    o.mechanics = SIM_LAGRANGE;
    o.variant = LAGRANGE_FULL;
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

void sim_trace_free(sim_trace* tr) {
    free(tr->v);
    memset(tr, 0, sizeof *tr);
}

static int trace_push(sim_trace* tr, const double* row) {
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

int sim_ncol(const sim_opts* o) { return o->mechanics == SIM_ODE ? SIM_NCOL : SIM_NCOL_BASE; }

void sim_csv_header(FILE* f, int ncol) {
    for (int c = 0; c < ncol; ++c) fprintf(f, "%s%s", c ? "," : "", sim_col_name[c]);
    fputc('\n', f);
}

void sim_csv_row(FILE* f, const double* row, int ncol) {
    // %.9g keeps 1e-9 relative precision: sub-micrometre strokes, mPa pressures.
    for (int c = 0; c < ncol; ++c) fprintf(f, "%s%.9g", c ? "," : "", row[c]);
    fputc('\n', f);
}

const char* sim_world_path(const char* arg, char* buf, size_t n) {
    if (!arg) arg = "validation";
    if (strchr(arg, '/') || strstr(arg, ".json")) return arg;
    snprintf(buf, n, "%s/worlds/%s.json", model_assets_dir(), arg);
    return buf;
}

typedef struct run_ctx {
    lsim* ls;
    const sim_opts* o;
    sim_row_fn row_fn;
    void* row_user;
    sim_trace* trace;
    sim_progress_fn progress;
    void* progress_user;
    double t_end, t_last_row, wall_next;
    long rows;
    int stop;
    // The run checks (sim_check_value): what failed, its text and time; the
    // dips below zero.
    sim_checks chk;
    double bad_t;
    char bad[200];
    bool all_states; ///< emit sees every state (else only the pressures are interpolated)
    // Peak chamber pressures p1A, p1B, p2A, p2B [Pa abs] (lagrange: system
    // state indices pidx), from every step and every row.
    int pidx[4];
    double peak[4];
    int npress;    ///< pressure states (emit checks only these)
    int press[LSIM_MAX_STATES];
} run_ctx;

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

static bool col_is_pressure(int c) {
    return c == COL_P1A || c == COL_P1B || c == COL_P2A || c == COL_P2B || c == COL_P_PUMP || c == COL_P3A ||
           c == COL_P3B;
}

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
    snprintf(note, n, "%s dipped below absolute zero, to %.3g kPa, at t = %.6g s: %s", k->dip_name,
             k->dip_value * 1e-3, k->dip_t,
             adaptive ? "the tolerance let the integration overshoot at a stiff event (a smaller --rtol avoids it)"
                      : "the fixed step rings at a stiff event (a smaller --dt or an adaptive solver avoids it)");
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
    return adaptive ? "the tolerance is too loose for this transient: try a smaller --rtol"
                    : "the step is too long for this transient: try a smaller --dt or an adaptive solver";
}

int sim_check_start(const hyd_model* hm, const double* row, int ncol, double m3, char* err, size_t errsz) {
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
        snprintf(err, errsz,
                 "the start pose needs %s = %.4g MPa to hold the crane still with %g kg at the tip, above the "
                 "circuit's highest relief setting (%s: %.4g MPa, p_crack + dp_override): the crane cannot hold "
                 "this load here (a smaller --load or another start pose)",
                 sim_col_name[c], row[c] * 1e-6, m3, which, pmax * 1e-6);
        return 2;
    }
    return 0;
}

int sim_check_times(double t_end, double dt_out, char* err, size_t errsz) {
    if (!(t_end > 0) || t_end > SIM_MAX_DURATION) {
        snprintf(err, errsz, "--duration: expected a simulated time in s, 0 < T <= 1e6, got %g",
                 t_end);
        return 2;
    }
    if (!(dt_out > 0) || dt_out > SIM_MAX_DURATION) {
        snprintf(err, errsz, "--every: expected an output period in s, 0 < DT <= 1e6, got %g",
                 dt_out);
        return 2;
    }
    if (t_end / dt_out > 1e12) {
        snprintf(err, errsz, "--every %g s over %g s is %.3g rows, more than 1e12: use a larger --every", dt_out,
                 t_end, t_end / dt_out);
        return 2;
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
    if (t_end > 0 && h > t_end) {
        snprintf(err, errsz, "--dt %g s is longer than the run (%g s)", h, t_end);
        return 2;
    }
    if (t_end > 0 && t_end / h > 1e12) {
        snprintf(err, errsz, "--dt %g s over %g s is %.3g steps, more than 1e12: use a larger --dt or a shorter run",
                 h, t_end, t_end / h);
        return 2;
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
                     "25 MPa) needs h < %.3g s at the least; use --dt %g or a stiff solver (krus, ros2, rodas3)",
                     h, rate, 2.785 / rate, stable_step(2.785 / rate, o->dt_out));
            return 2;
        }
    }
    return 0;
}

static int check_fixed_step(const hyd_model* hm, const sim_opts* o, double h, double t_end, sim_result* res) {
    return res->status = sim_check_fixed_step(hm, o, h, t_end, res->message, sizeof res->message);
}

static int deliver(run_ctx* c, const double* row);

static void track_peaks(run_ctx* c, const double* y) {
    for (int k = 0; k < 4; ++k) c->peak[k] = fmax(c->peak[k], y[c->pidx[k]]);
}

// hyd_solver_opts.on_step: peaks between the rows too.
static void on_step(void* user, double t, const double* y) {
    (void)t;
    track_peaks(user, y);
}

static const char* state_name(const lsim* ls, int i, char* buf, size_t n);

// A failed run check: remember what and when, and stop the integration.
static int check_failed(run_ctx* c, double t) {
    c->bad_t = t;
    return (c->stop = 3);
}

static int emit(void* user, double t, const double* y) {
    run_ctx* c = user;
    track_peaks(c, y);
    // Segments share their end points: write each output time once.
    if (c->rows > 0 && t <= c->t_last_row + 1e-9 * c->o->dt_out) return 0;
    char nb[96];
    // Every state (when the solver interpolated them all), the pressures as
    // pressures; benchmarks see only the pressure states.
    for (int i = 0; i < c->ls->n; ++i) {
        const bool p = i < c->ls->nh && c->ls->is_pressure[i];
        if (!p && !c->all_states) continue;
        // The common case first, without naming the state (this runs at
        // every output time, also in benchmarks).
        if (isfinite(y[i]) && (!p || y[i] >= 0.0)) continue;
        const int rc = sim_check_value(&c->chk, state_name(c->ls, i, nb, sizeof nb), y[i], p, t, c->bad,
                                       sizeof c->bad);
        if (rc) return check_failed(c, t);
    }
    c->t_last_row = t;
    ++c->rows;
    // Benchmarks consume nothing: skip the output evaluation entirely.
    if (!c->trace && !c->row_fn && !c->progress) return 0;
    lsim_out o;
    lsim_outputs(c->ls, t, y, &o);
    double row[SIM_NCOL];
    sim_lagrange_row(t, &o, row);
    // The derived columns too (a force or a tip position can overflow while
    // the states are finite).
    const int rc = sim_check_row(&c->chk, row, SIM_NCOL_BASE, c->bad, sizeof c->bad);
    if (rc) {
        --c->rows;
        return check_failed(c, t);
    }
    return deliver(c, row);
}

// Hand a finished row to the trace, the row callback and the progress bar.
static int deliver(run_ctx* c, const double* row) {
    const double t = row[COL_T];
    if (c->trace && trace_push(c->trace, row)) return (c->stop = 2);
    if (c->row_fn && c->row_fn(c->row_user, row)) return (c->stop = 2);
    if (c->progress) {
        double w = sim_wall_time();
        if (w >= c->wall_next) {
            c->wall_next = w + 0.1;
            c->progress(c->progress_user, t, c->t_end);
        }
    }
    return 0;
}

static const char* state_name(const lsim* ls, int i, char* buf, size_t n) {
    static const char* const mech[4] = {"q1", "q2", "q1_dot", "q2_dot"};
    if (i >= ls->iq) return mech[i - ls->iq];
    snprintf(buf, n, "%s", hyd_model_state_name(ls->mdl->hyd, ls->perm[i]));
    return buf;
}

void sim_lagrange_row(double t, const lsim_out* o, double* row) {
    const double v[SIM_NCOL] = {
        t, o->x[0], o->x[1], o->pA[0], o->pB[0], o->pA[1], o->pB[1], o->u[0], o->u[1], o->q[0], o->q[1],
        o->tip[0], o->tip[1], o->F[0], o->F[1], o->u_cmd[0], o->u_cmd[1],
        o->v[0], o->v[1], o->p_pump, o->relief_open, o->end_stop};
    memcpy(row, v, sizeof v);
}

// One CSV row from the ode world's state.
void sim_ode_row(ode_world* w, double* row) {
    ode_world_state st;
    ode_world_get_state(w, &st);
    const double v[SIM_NCOL] = {
        st.t, st.x[0], st.x[1], st.pA[0], st.pB[0], st.pA[1], st.pB[1], st.u[0], st.u[1], st.q[0], st.q[1],
        st.tip[0], st.tip[1], st.F[0], st.F[1], st.u_cmd[0], st.u_cmd[1],
        st.v[0], st.v[1], st.p_pump, st.relief_open, st.end_stop,
        st.slew, st.hook[0], st.hook[1], st.hook[2], 0, 0, 0, st.attached, st.truck_tilt, st.ncontact,
        st.max_depth, st.x[2], st.v[2], st.pA[2], st.pB[2], st.u[2], st.u_cmd[2], st.F[2]};
    memcpy(row, v, sizeof v);
    // The attached load, else the first one: where the payload is.
    int li = st.attached >= 0 ? st.attached : (ode_world_nload(w) > 0 ? 0 : -1);
    if (li >= 0) {
        double pos[3], vel[3];
        ode_world_load_state(w, li, pos, vel);
        row[COL_LOAD_X] = pos[0];
        row[COL_LOAD_Y] = pos[1];
        row[COL_LOAD_Z] = pos[2];
    }
}

ode_world* sim_ode_world_create(const model* m, const sim_opts* o, const char* default_world, const double q0[2],
                                double slew0, double m3, char* err, size_t errsz) {
    char wbuf[512];
    const char* wpath = sim_world_path(o->world ? o->world : default_world, wbuf, sizeof wbuf);
    world_desc wd;
    if (world_desc_load(wpath, &wd, err, errsz)) return NULL;
    ode_world_opts wo = ode_world_default_opts();
    wo.dt_ode = o->dt_ode > 0 ? o->dt_ode : 1e-3;
    // The bodies feel the cylinder forces one ODE step late (explicit
    // coupling, docs/ode_world.md). Against the lagrange backend on `step`:
    // 0.8 % of peak pressure at 1 ms, 15 % at 10 ms, 36 % at 20 ms; `hold`
    // goes unstable between 30 and 50 ms and reported 27 MPa in every
    // chamber as a success. Beyond 10 ms the result is not worth having.
    if (wo.dt_ode > 0.01 + 1e-12) {
        snprintf(err, errsz,
                 "--dt-ode %g s is too long: the cylinder forces lag the bodies by one ODE step, which beyond "
                 "0.01 s distorts the pressures by more than 15 %% and then goes unstable (docs/ode_world.md)",
                 wo.dt_ode);
        world_desc_free(&wd);
        return NULL;
    }
    // Adaptive hydraulics choose their own steps inside each ODE step and
    // never use dt_hyd: --dt does not apply, so it cannot be wrong.
    wo.dt_hyd = hyd_method_is_adaptive(o->solver) || o->h >= wo.dt_ode ? wo.dt_ode : o->h;
    const double ratio = wo.dt_ode / wo.dt_hyd;
    if (fabs(ratio - floor(ratio + 0.5)) > 1e-6) {
        // ode_world_create checks this too; here it is said in the options' words.
        snprintf(err, errsz, "--dt %g s must divide the ODE step %g s (hydraulic sub-steps)", wo.dt_hyd, wo.dt_ode);
        world_desc_free(&wd);
        return NULL;
    }
    wo.solver = o->solver;
    wo.jac_every = o->jac_every > 0 ? o->jac_every : 1;
    wo.rtol = o->rtol;
    wo.atol = o->atol;
    wo.dense_jac = o->dense_jac;
    wo.general_circuit = o->general_kernel;
    wo.q0[0] = q0[0];
    wo.q0[1] = q0[1];
    wo.slew0 = slew0;
    wo.load_mass = m3;
    wo.p_low = 0.5e6; // as the lagrange backend, so both start from the same state
    wo.model_file = m->file;
    const cJSON* hyd = cJSON_GetObjectItemCaseSensitive(m->json, "hydraulics");
    ode_world* w = ode_world_create(&m->mech, hyd, &wd, &wo, err, errsz);
    world_desc_free(&wd);
    return w;
}

static int run_ode(const model* m, const scenario* sc, const sim_opts* o, run_ctx* c, sim_result* res) {
    if (o->cvode) {
        snprintf(res->message, sizeof res->message,
                 "--mechanics ode steps the hydraulics inside each ODE step: use krus, ros2, rk4, ros34pw2 or rodas3");
        return res->status = 2;
    }
    ode_world* w = sim_ode_world_create(m, o, "validation", sc->q0, sc->slew0, sim_load_mass(m, sc, o), res->message,
                                        sizeof res->message);
    if (!w) return res->status = 2;
    res->fused = ode_world_fused(w);
    const long ode_msgs = ode_world_messages(NULL);
    const double h_hyd = o->h < ode_world_dt(w) ? o->h : ode_world_dt(w); // as sim_ode_world_create
    if (check_fixed_step(ode_world_circuit(w), o, h_hyd, c->t_end, res)) {
        ode_world_destroy(w);
        return res->status;
    }

    const double dt = ode_world_dt(w);
    // Counted in longs: refused before a conversion could overflow (the
    // output period is at most the run, sim_check_times).
    if (c->t_end / dt > 1e12) {
        snprintf(res->message, sizeof res->message,
                 "--dt-ode %g s over %g s is %.3g steps, more than 1e12: use a larger --dt-ode or a shorter run", dt,
                 c->t_end, c->t_end / dt);
        ode_world_destroy(w);
        return res->status = 2;
    }
    const long nstep = (long)floor(c->t_end / dt + 0.5);
    long nout = (long)floor(fmin(o->dt_out, c->t_end) / dt + 0.5);
    if (nout < 1) nout = 1;
    double row[SIM_NCOL];
    int ev = 0;
    double w0 = sim_wall_time();
    sim_ode_row(w, row);
    for (int k = 0; k < 4; ++k) res->p_peak[k] = row[COL_P1A + k];
    {
        // The start state too: a model value that overflows shows at t = 0.
        char what[200];
        const int rc = sim_check_row(&c->chk, row, SIM_NCOL, what, sizeof what);
        if (rc) {
            snprintf(res->message, sizeof res->message, "%s: %s", what,
                     sim_blowup_hint(hyd_method_is_adaptive(o->solver), 0.0, c->chk.bad_value));
            ode_world_destroy(w);
            return res->status = 2;
        }
        if (sim_check_start(ode_world_circuit(w), row, SIM_NCOL, sim_load_mass(m, sc, o), res->message,
                            sizeof res->message)) {
            ode_world_destroy(w);
            return res->status = 2;
        }
    }
    deliver(c, row);
    ++c->rows;
    for (long i = 0; i < nstep && !c->stop; ++i) {
        const double t = (double)i * dt;
        // Commands at the step's midpoint: second-order accurate for ramps,
        // and steps land within half an ODE step of their time.
        const double tm = t + 0.5 * dt;
        const double u[3] = {scenario_command(sc, 0, tm), scenario_command(sc, 1, tm), scenario_command(sc, 2, tm)};
        ode_world_set_commands(w, u);
        while (ev < sc->nevent && sc->event[ev].t <= tm) {
            ode_world_hook(w, sc->event[ev].kind == SCENARIO_ATTACH);
            ++ev;
        }
        if (ode_world_step(w, dt)) {
            res->status = 1;
            snprintf(res->message, sizeof res->message, "numerical blow-up: %s", ode_world_error(w));
            break;
        }
        {
            // Peaks at every ODE step, not only at the rows.
            double pA[ODE_NACT], pB[ODE_NACT];
            ode_world_chamber_pressures(w, pA, pB);
            const double p[4] = {pA[0], pB[0], pA[1], pB[1]};
            for (int k = 0; k < 4; ++k) res->p_peak[k] = fmax(res->p_peak[k], p[k]);
        }
        if ((i + 1) % nout && i + 1 != nstep) continue;
        sim_ode_row(w, row);
        row[COL_T] = (double)(i + 1) * dt; // exact grid times, no accumulated round-off
        {
            char what[200];
            const int rc = sim_check_row(&c->chk, row, SIM_NCOL, what, sizeof what);
            if (rc) {
                res->status = 1;
                snprintf(res->message, sizeof res->message, "numerical blow-up: %s (solver %s, h = %g s, ODE step %g s): %s",
                         what, hyd_method_name(o->solver), o->h < dt ? o->h : dt, dt,
                         sim_blowup_hint(hyd_method_is_adaptive(o->solver), row[COL_T], c->chk.bad_value));
            }
        }
        if (res->status) break;
        c->t_last_row = row[COL_T];
        ++c->rows;
        deliver(c, row);
    }
    res->wall = sim_wall_time() - w0;
    res->stats = ode_world_hyd_stats(w);
    res->stats.steps = ode_world_hyd_steps(w); // fixed-step sub-steps are counted by the world
    res->rows = c->rows;
    res->t_end = c->t_last_row;
    ode_world_destroy(w);
    res->peak_steps = true;
    const char* last;
    const long msgs = ode_world_messages(&last) - ode_msgs;
    if (!res->status && c->chk.dip)
        sim_checks_note(&c->chk, hyd_method_is_adaptive(o->solver), res->note, sizeof res->note);
    else if (msgs > 0)
        snprintf(res->note, sizeof res->note,
                 "ODE reported %ld solver message%s during the run (last: %.120s): a degenerate contact set, which "
                 "ODE stepped through",
                 msgs, msgs > 1 ? "s" : "", last);
    if (c->stop && !res->status) {
        res->status = 2;
        snprintf(res->message, sizeof res->message, "stopped at t = %.6g s", c->t_last_row);
    }
    return res->status;
}

int sim_run(const model* m, const scenario* sc, const sim_opts* o, sim_row_fn row_fn, void* row_user,
            sim_trace* trace, sim_progress_fn progress, void* progress_user, sim_result* res) {
    memset(res, 0, sizeof *res);
    if (o->mechanics == SIM_ODE) {
        run_ctx c = {.o = o, .row_fn = row_fn, .row_user = row_user, .trace = trace, .progress = progress,
                     .progress_user = progress_user, .t_end = o->duration > 0 ? o->duration : sc->duration,
                     .all_states = true};
        if (sim_check_times(c.t_end, o->dt_out, res->message, sizeof res->message)) return res->status = 2;
        return run_ode(m, sc, o, &c, res);
    }
    if (sim_check_times(o->duration > 0 ? o->duration : sc->duration, o->dt_out, res->message, sizeof res->message))
        return res->status = 2;
    lsim ls;
    double m3 = sim_load_mass(m, sc, o);
    if (lsim_init(&ls, m, o->variant, m3, res->message, sizeof res->message)) return res->status = 2;
    ls.scn = sc;
    ls.use_fused = ls.have_fused && !o->general_kernel;
    ls.use_w = ls.w_layout && !o->general_kernel; // the crane-specialised W too (lsim_w.c)
    ls.use_split = ls.w_layout && !o->general_kernel && !o->whole_step;
    res->fused = ls.use_fused;
    double y[LSIM_MAX_STATES];
    if (lsim_check_pose(&ls, sc->q0, res->message, sizeof res->message) ||
        check_fixed_step(m->hyd, o, o->h, o->duration > 0 ? o->duration : sc->duration, res)) {
        lsim_free(&ls);
        return res->status = 2;
    }
    lsim_initial_state(&ls, sc->q0, 0.5e6, y);
    {
        lsim_out lo;
        lsim_outputs(&ls, 0.0, y, &lo);
        const double row0[SIM_NCOL_BASE] = {[COL_P1A] = lo.pA[0], [COL_P1B] = lo.pB[0], [COL_P2A] = lo.pA[1],
                                            [COL_P2B] = lo.pB[1]};
        if (sim_check_start(m->hyd, row0, SIM_NCOL_BASE, m3, res->message, sizeof res->message)) {
            lsim_free(&ls);
            return res->status = 2;
        }
    }

    const bool adaptive = o->cvode || hyd_method_is_adaptive(o->solver);
#ifndef CRANESIM_HAVE_CVODE
    if (o->cvode) {
        snprintf(res->message, sizeof res->message, "this build has no CVODE (install libsundials-dev)");
        lsim_free(&ls);
        return res->status = 2;
    }
#endif
    hyd_problem prob = lsim_problem(&ls, !adaptive && !o->dense_jac);
    res->split = prob.wstep && (o->solver == HYD_KRUS || o->solver == HYD_ROS2) && !o->cvode;
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = adaptive ? 0.0 : o->h;
    so.rtol = o->rtol;
    so.atol = o->atol;
    so.h_max = 0.5;
    so.jac_every = adaptive ? 1 : (o->jac_every > 0 ? o->jac_every : 1);
    // A fixed-step run ends by construction (check_fixed_step bounds it to
    // 1e12 steps): no per-call budget, which at 1e8 stopped a 1 ns step at
    // 0.1 s. The adaptive budget guards against a controller that stalls.
    if (!adaptive) so.max_steps = 0;
    // emit checks the pressure states at every output; when no row is
    // consumed (benchmarks) that is all it reads, so an adaptive solver
    // interpolates only those.
    int press[LSIM_MAX_STATES], npress = 0;
    for (int i = 0; i < ls.nh; ++i)
        if (ls.is_pressure[i]) press[npress++] = i;
    if (!trace && !row_fn && !progress) {
        so.out_states = press;
        so.n_out_states = npress;
    }
    // The run's context, filled below; its address goes to the solver now.
    run_ctx c;
    if (trace || row_fn) { // someone reads the summary: peaks from every step
        so.on_step = on_step;
        so.on_step_user = &c;
    }
    // CVODE brings its own integrator; the in-house one is not created then.
    hyd_solver* s = o->cvode ? NULL : hyd_solver_create(&prob, o->solver, &so);
    if (!s && !o->cvode) {
        snprintf(res->message, sizeof res->message, "cannot create the %s solver", hyd_method_name(o->solver));
        lsim_free(&ls);
        return res->status = 2;
    }

    const double t_end = o->duration > 0 ? o->duration : sc->duration;
    // A fixed step longer than the output period outputs once per step
    // (fixed-step methods land on every output time).
    sim_opts oo = *o;
    if (!adaptive && oo.h > oo.dt_out) oo.dt_out = oo.h;
    // An output period longer than the run: rows at the start and the end
    // (the breakpoints are rounded to this grid, so it must not pass t_end).
    if (oo.dt_out > t_end && t_end > 0) oo.dt_out = t_end;
    o = &oo;
    c = (run_ctx){.ls = &ls, .o = o, .row_fn = row_fn, .row_user = row_user, .trace = trace,
                  .progress = progress, .progress_user = progress_user, .t_end = t_end,
                  .all_states = so.out_states == NULL,
                  .pidx = {ls.ip[0][0], ls.ip[0][1], ls.ip[1][0], ls.ip[1][1]}};
    memcpy(c.press, press, sizeof press);
    c.npress = npress;
    // Integrate between command breakpoints (rounded to the output grid) and
    // reset the solver at each: a kink in a valve command is a discontinuity
    // in f' that an adaptive controller should not have to discover.
    double bp[2 * SCENARIO_MAX_POINTS * SCENARIO_NCMD + SCENARIO_MAX_EVENTS + 2];
    int nbp = scenario_breakpoints(sc, bp, (int)(sizeof bp / sizeof bp[0]) - 1);
    double t = 0.0;
    hyd_solver_stats cv = {0};
    double w0 = sim_wall_time();
    int rc = HYD_OK;
    emit(&c, 0.0, y);
    for (int i = 0; i <= nbp && rc == HYD_OK && !c.stop && t < t_end; ++i) {
        double tb = i < nbp ? ceil(bp[i] / o->dt_out - 1e-9) * o->dt_out : t_end;
        if (tb > t_end) tb = t_end;
        if (tb <= t + 1e-12) continue;
        if (s) hyd_solver_reset(s);
#ifdef CRANESIM_HAVE_CVODE
        if (o->cvode) {
            hyd_cvode_opts co = hyd_cvode_default_opts();
            co.rtol = o->rtol;
            co.atol = o->atol;
            co.h_max = 0.5;
            hyd_solver_stats cs = {0};
            rc = hyd_cvode_integrate(&prob, &co, t, y, tb, o->dt_out, emit, &c, &cs);
            cv.steps += cs.steps;
            cv.rejected += cs.rejected;
            cv.fevals += cs.fevals;
            cv.jevals += cs.jevals;
            cv.lus += cs.lus;
        } else
#endif
            rc = hyd_solver_integrate(s, t, y, tb, o->dt_out, emit, &c);
        if (rc == HYD_OK && !c.stop) t = tb;
    }
    res->wall = sim_wall_time() - w0;
    res->stats = o->cvode ? cv : *hyd_solver_get_stats(s);
    res->rows = c.rows;
    res->t_end = c.t_last_row;
    char nb[96];
    if (c.stop == 3) {
        // A failed check at t = 0 is the model's start state (no step ran):
        // refused like bad input, nothing written.
        res->status = c.bad_t > 0 ? 1 : 2;
        // The step for fixed-step methods, the last step tried for ours, the
        // tolerance for CVODE (whose steps are its own).
        char how[48];
        if (o->cvode) snprintf(how, sizeof how, "rtol %g", o->rtol);
        else snprintf(how, sizeof how, "h = %g s", adaptive && s ? hyd_solver_last_h(s) : o->h);
        if (res->status == 2)
            snprintf(res->message, sizeof res->message, "%s: %s", c.bad,
                     sim_blowup_hint(adaptive, 0.0, c.chk.bad_value));
        else
            snprintf(res->message, sizeof res->message, "numerical blow-up: %s (solver %s, %s): %s", c.bad,
                     o->cvode ? "cvode" : hyd_method_name(o->solver), how,
                     sim_blowup_hint(adaptive, c.bad_t, c.chk.bad_value));
    } else if (c.stop) {
        res->status = 2;
        snprintf(res->message, sizeof res->message, "stopped at t = %.6g s", c.t_last_row);
    } else if (rc != HYD_OK) {
        res->status = 1;
        double tb = c.t_last_row;
        int bi = s ? hyd_solver_bad_state(s, &tb) : -1;
        if (rc == HYD_ERR_NONFINITE && bi >= 0)
            snprintf(res->message, sizeof res->message,
                     "numerical blow-up: state %s became non-finite at t = %.6g s (solver %s, h = %g s)",
                     state_name(&ls, bi, nb, sizeof nb), tb, hyd_method_name(o->solver),
                     adaptive && s ? hyd_solver_last_h(s) : o->h);
        else if (rc == HYD_ERR_DOMAIN && bi >= 0)
            snprintf(res->message, sizeof res->message,
                     "numerical failure: every step the %s controller tried took state %s below absolute zero at "
                     "t = %.6g s, down to the smallest step",
                     hyd_method_name(o->solver), state_name(&ls, bi, nb, sizeof nb), tb);
        else
            snprintf(res->message, sizeof res->message, "solver %s stopped near t = %.6g s: %s",
                     o->cvode ? "cvode" : hyd_method_name(o->solver), c.t_last_row, hyd_error_text(rc));
    }
    memcpy(res->p_peak, c.peak, sizeof res->p_peak);
    res->peak_steps = !o->cvode && (trace || row_fn);
    if (!res->status) sim_checks_note(&c.chk, adaptive, res->note, sizeof res->note);
    hyd_solver_destroy(s);
    lsim_free(&ls);
    return res->status;
}
