// test_chain_stops.c: the joint-limit stops of the general analytic mode
// (chain_stops.h) on synthetic chains with ideal cylinder forces (no
// circuit): a boom and a telescopic stage pushed into their limits.
//   - the stop's constants: k = m w0^2, c = 2 zeta m w0 with m = 1 /
//     (M^-1)_ii from the mechanism's mass matrix (chain_mass_matrix);
//   - the rest against the stop: from the static balance k S(d) = tau, the
//     generalised force of the cylinder and gravity at the rest pose
//     (chain_inverse_dynamics with q'' = 0 and the lever arm dL/dq), d =
//     tau / k + w / 2 beyond the spring's onset width w;
//   - little bounce (critically damped; ODE's stop is inelastic): the
//     rebound at most e^-2 of the approach, a free contact's;
//   - the Jacobian (the stop's partials) against central differences at
//     the rest against the stop;
//   - the energy balance: E_mech + the stop springs' energy - sum F0 x (the
//     constant forces' potential) + the stop's dissipation integrated over
//     time stays constant within 0.1 % of the energy the forces put in;
//   - a joint without limits (the slewing column) gets no stop, and a run
//     that stays within its limits is the run without stops, bit for bit.
#include "chain_sim.h"
#include "check.h"
#include "crane_chain_synth.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// The run of one chain: joint j pushed by its actuator's constant force,
// the other actuators holding their start (their force at the start's
// balance plus a spring of their load over 20 mm).
typedef struct stop_run {
    double q_end, qd_end;   ///< joint j at the end [rad or m, rad/s or m/s]
    double d_expect;        ///< its penetration from the static balance [rad or m]
    double k, k_expect;     ///< its stop's stiffness and m w0^2 from the mass matrix
    double c, c_expect;
    double e_err, e_in;     ///< the balance's largest error and the forces' work [J]
    double lim;             ///< the limit it met
    double v_in, v_out;     ///< its rate at the first contact and the fastest rebound after it
    double jac_err;         ///< the Jacobian's q'' row of joint j against central differences, relative
} stop_run;

// The stop's spring S^-1: the penetration at which k S(d) = tau.
static double spring_inverse(double tau, double k, double w) {
    const double s = tau / k;
    return s >= 0.5 * w ? s + 0.5 * w : sqrt(2.0 * w * s);
}

static stop_run push_into_limit(const char* joints, bool slew_free, int j, double push, double gap) {
    stop_run r;
    memset(&r, 0, sizeof r);
    crane_chain cc;
    hyd_model* hm;
    double qb[8];
    char err[256];
    CHECK(crane_chain_synthetic(joints, slew_free, &cc, &hm, qb, err, sizeof err) == 0, "%s", err);
    chain_sim cs;
    CHECK(chain_sim_init(&cs, &cc, hm, 50.0, 0.0, err, sizeof err) == 0, "%s", err);
    const int nd = cs.ndof, na = cc.nact, o = slew_free ? 1 : 0;
    double q0[9] = {0};
    for (int i = 0; i < na; ++i) q0[i + o] = qb[i];
    // The pushed joint starts gap below its upper limit (a slow approach,
    // as a cylinder's: the stop meets it at a fraction of a rad/s or m/s).
    q0[j + o] = chain_body(cs.ch, chain_dof_body(cs.ch, j + o))->q_max - gap;
    double* y = calloc((size_t)cs.n, sizeof *y);
    double* f = calloc((size_t)cs.n, sizeof *f);
    CHECK(chain_sim_initial_state(&cs, q0, 0.5e6, y, err, sizeof err) == 0, "%s", err);
    // A slewing column has no limits: no stop on it.
    CHECK(cs.stops.n == na, "%d stops for %d limited joints", cs.stops.n, na);
    for (int s = 0; s < cs.stops.n; ++s) CHECK(cs.stops.dof[s] >= o, "a stop on DOF %d", cs.stops.dof[s]);
    // The stop's constants against the mass matrix at the reference pose
    // (every DOF mid-limits; the slew at 0).
    const int dj = j + o;
    {
        double qr[9] = {0}, M[81], e[9] = {0}, x[9];
        for (int i = 0; i < nd; ++i) {
            const chain_body_def* b = chain_body(cs.ch, chain_dof_body(cs.ch, i));
            qr[i] = isfinite(b->q_min) && isfinite(b->q_max) ? 0.5 * (b->q_min + b->q_max) : 0.0;
        }
        chain_update(cs.ch, cs.ws, qr, NULL);
        chain_mass_matrix(cs.ch, cs.ws, M);
        // (M^-1)_jj by Gauss-Jordan on a copy (independent of chain_solve).
        double A[81];
        memcpy(A, M, sizeof A);
        e[dj] = 1.0;
        for (int c = 0; c < nd; ++c) {
            for (int i = 0; i < nd; ++i) {
                if (i == c) continue;
                const double fct = A[i * nd + c] / A[c * nd + c];
                for (int l = 0; l < nd; ++l) A[i * nd + l] -= fct * A[c * nd + l];
                e[i] -= fct * e[c];
            }
        }
        for (int i = 0; i < nd; ++i) x[i] = e[i] / A[i * nd + i];
        const double m = 1.0 / x[dj];
        r.k_expect = m * CHAIN_STOP_OMEGA * CHAIN_STOP_OMEGA;
        r.c_expect = 2.0 * CHAIN_STOP_ZETA * m * CHAIN_STOP_OMEGA;
        for (int s = 0; s < cs.stops.n; ++s)
            if (cs.stops.dof[s] == dj) r.k = cs.stops.k[s], r.c = cs.stops.c[s], r.lim = cs.stops.hi[s];
    }
    // The forces: the start's balance (chamber pressures at rest), each a
    // spring; actuator j pushes by `push` more and has no spring.
    double F0[8], K[8], xk[8], dL[9];
    chain_sim_out out = {.x = xk};
    chain_sim_outputs(&cs, 0.0, y, &out);
    for (int k = 0; k < na; ++k) {
        double AA, AB, st;
        hyd_model_cylinder_geometry(hm, cc.act[k].cyl, &AA, &AB, &st);
        const double Feq = y[cs.ipA[k]] * AA - y[cs.ipB[k]] * AB;
        K[k] = k == j ? 0.0 : fabs(Feq) / 0.02;
        F0[k] = Feq + K[k] * xk[k] + (k == j ? push : 0.0);
    }
    cs.ideal_F = F0;
    cs.ideal_K = K;
    // The upper limit when the push raises q_j (its lever arm dL/dq > 0).
    chain_update(cs.ch, cs.ws, y + cs.iq, NULL);
    crane_act_length(&cc.act[j], cs.ch, cs.ws, NULL, dL, NULL);
    CHECK(push * dL[dj] > 0.0, "the push drives joint %d up", dj);
    // RK4 at 2.5 us: the stop's 5000 rad/s at h w0 = 0.0125; the
    // dissipation by the trapezoid on each step.
    hyd_problem p = chain_sim_problem(&cs, false);
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = 2.5e-6;
    hyd_solver* sol = hyd_solver_create(&p, HYD_RK4, &so);
    double t = 0.0, Ediss = 0.0, Pprev = 0.0, E0 = 0.0, xj0 = 0.0;
    bool touched = false;
    const double T = 1.5;
    for (long i = 0;; ++i) {
        chain_sim_outputs(&cs, t, y, &out);
        const double* q = y + cs.iq;
        const double P = chain_stops_dissipation(&cs.stops, q, q + nd);
        if (i) Ediss += 0.5 * (P + Pprev) * so.h;
        Pprev = P;
        double E = chain_sim_energy(&cs, y) + chain_stops_energy(&cs.stops, q) + Ediss;
        for (int k = 0; k < na; ++k) E -= F0[k] * xk[k] - 0.5 * K[k] * xk[k] * xk[k];
        if (!i) E0 = E, xj0 = xk[j];
        r.e_err = fmax(r.e_err, fabs(E - E0));
        if (q[dj] > r.lim && !touched) touched = true, r.v_in = q[nd + dj];
        if (touched) r.v_out = fmax(r.v_out, -q[nd + dj]);
        if (t >= T - 1e-12) break;
        if (hyd_solver_advance(sol, &t, y, (double)(i + 1) * so.h) != HYD_OK) {
            CHECK(0, "advance failed at %g", t);
            break;
        }
    }
    CHECK(touched, "joint %d never reached its limit %g (at %g)", dj, r.lim, y[cs.iq + dj]);
    // The pushed force's work from the start [J], F0 (x - x0).
    r.e_in = fabs(F0[j] * (xk[j] - xj0));
    r.q_end = y[cs.iq + dj];
    r.qd_end = y[cs.iq + nd + dj];
    // The static balance at the end pose: the force the stop must hold is
    // tau = sum_k F_k dL_k/dq_j - G_j (at rest, q'' = 0).
    {
        double G[9], tau = 0.0;
        chain_update(cs.ch, cs.ws, y + cs.iq, NULL);
        chain_inverse_dynamics(cs.ch, cs.ws, NULL, CHAIN_GRAVITY, G);
        for (int k = 0; k < na; ++k) {
            crane_act_length(&cc.act[k], cs.ch, cs.ws, NULL, dL, NULL);
            tau += (F0[k] - K[k] * (crane_act_length(&cc.act[k], cs.ch, cs.ws, NULL, NULL, NULL) -
                                    cc.act[k].closed_length)) * dL[dj];
        }
        tau -= G[dj];
        r.d_expect = spring_inverse(tau, r.k, CHAIN_STOP_WIDTH);
    }
    // The Jacobian at the rest against the stop (the stop's partials in
    // d q''/dq and d q''/dq'), against central differences of f.
    {
        const int n = cs.n, row = cs.iq + nd + dj;
        double* J = calloc((size_t)n * (size_t)n, sizeof *J);
        double* fp = calloc((size_t)n, sizeof *fp);
        chain_sim_jac(&cs, T, y, J);
        double scale = 0.0;
        for (int c = 0; c < 2; ++c) scale = fmax(scale, fabs(J[(size_t)row * n + cs.iq + c * nd + dj]));
        for (int c = 0; c < 2; ++c) {
            const int col = cs.iq + c * nd + dj;
            const double y0 = y[col], h = c ? 1e-6 : 1e-9;
            y[col] = y0 + h;
            chain_sim_rhs(&cs, T, y, fp);
            y[col] = y0 - h;
            chain_sim_rhs(&cs, T, y, f);
            y[col] = y0;
            const double fd = (fp[row] - f[row]) / (2.0 * h);
            r.jac_err = fmax(r.jac_err, fabs(J[(size_t)row * n + col] - fd) / scale);
        }
        free(J);
        free(fp);
    }
    hyd_solver_destroy(sol);
    free(y);
    free(f);
    chain_sim_free(&cs);
    crane_chain_free(&cc);
    hyd_model_free(hm);
    return r;
}

static void report(const char* what, const stop_run* r, double unit, const char* u) {
    const double d = r->q_end - r->lim;
    printf("  %s: k %.4g (mass matrix %.4g), c %.4g (%.4g); rest %.5f %s past the limit, static balance %.5f %s; "
           "contact at %.4g, rebound %.4g (restitution %.3f); Jacobian %.2g; energy balance %.3g J of %.4g J in (%.4f %%)\n",
           what, r->k, r->k_expect, r->c, r->c_expect, d * unit, u, r->d_expect * unit, u, r->v_in, r->v_out,
           r->v_out / r->v_in, r->jac_err, r->e_err, r->e_in, 100.0 * r->e_err / r->e_in);
    CHECK(fabs(r->k / r->k_expect - 1.0) < 1e-9 && fabs(r->c / r->c_expect - 1.0) < 1e-9, "%s: constants", what);
    CHECK(fabs(d / r->d_expect - 1.0) < 0.01, "%s: rest %.6g past the limit, static balance %.6g", what, d,
          r->d_expect);
    CHECK(fabs(r->qd_end) < 1e-6, "%s: still moving at %g", what, r->qd_end);
    CHECK(r->jac_err < 1e-5, "%s: Jacobian off central differences by %.3g of its row", what, r->jac_err);
    // Critically damped: a free contact's rebound is e^-2 = 0.135 of its
    // approach (the damper would pull from t = 2/w0 on, which a stop cannot:
    // the body leaves there).
    // The spring's onset width, where the damper fades in, adds a little:
    // at most 0.2.
    CHECK(r->v_in > 0.0 && r->v_out <= 0.2 * r->v_in, "%s: rebound %.4g of a contact at %.4g", what, r->v_out,
          r->v_in);
    CHECK(r->e_err < 1e-3 * r->e_in, "%s: energy balance off by %.3g J of %.3g J (%.3g %%)", what, r->e_err, r->e_in,
          100.0 * r->e_err / r->e_in);
}

// A boom (the lifting arm alone, the column fixed) lifted into its upper
// limit by its cylinder.
static void test_boom_into_stop(void) {
    const stop_run r = push_into_limit("R", false, 0, 3e4, 0.01);
    report("boom", &r, 1e3, "mrad");
}

// A telescopic stage pushed out into its upper limit, the boom it slides in
// held by its cylinder's spring, on a slewing column (no limits: no stop).
static void test_stage_into_stop(void) {
    const stop_run r = push_into_limit("RP", true, 1, 2e3, 0.01);
    report("stage", &r, 1e3, "mm");
}

int main(int argc, char** argv) {
    RUN_TEST(test_boom_into_stop);
    RUN_TEST(test_stage_into_stop);
    TEST_MAIN_END();
}
