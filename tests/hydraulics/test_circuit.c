// test_circuit.c: the compiled default crane circuit. State layout and
// lookups, the analytic Jacobian and coupling partials against central
// differences, flow continuity, live parameters and JSON round trips.
#include "circuits.h"
#include "check.h"
#include "hydraulics.h"
#include "hyd_fused.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>

#define NMAX 16

static double urand(double a, double b) { return a + (b - a) * rand() / (double)RAND_MAX; }

static void test_layout(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (!m)
        return;
    CHECK(hyd_model_nstate(m) == 11, "nstate %d", hyd_model_nstate(m));
    const char* expect[11] = {"pump_line.p",  "lift_valve.spool", "lift_hose_A.p", "lift_hose_B.p",
                              "lift_cyl.pA",  "lift_cyl.pB",      "jib_valve.spool", "jib_hose_A.p",
                              "jib_hose_B.p", "jib_cyl.pA",       "jib_cyl.pB"};
    for (int i = 0; i < 11; ++i) {
        CHECK(!strcmp(hyd_model_state_name(m, i), expect[i]), "state %d: %s", i,
              hyd_model_state_name(m, i));
        CHECK(hyd_model_find_state(m, expect[i]) == i, "find_state %s", expect[i]);
    }
    const int lc = hyd_model_cylinder(m, "lift_cyl"), jc = hyd_model_cylinder(m, "jib_cyl");
    CHECK(lc == 0 && jc == 1, "cylinder indices %d %d", lc, jc);
    int iA, iB;
    hyd_model_cylinder_states(m, jc, &iA, &iB);
    CHECK(iA == 9 && iB == 10, "jib chamber states %d %d", iA, iB);
    CHECK(hyd_model_valve_state(m, hyd_model_valve(m, "jib_valve")) == 6, "jib spool state");
    CHECK(hyd_model_find(m, "lift_relief_B") >= 0, "find component");
    CHECK(hyd_model_find(m, "nope") < 0 && hyd_model_cylinder(m, "lift_valve") < 0, "misses");
    CHECK(hyd_model_node_state(m, hyd_model_find_node(m, "lift_cyl.B")) == 5, "node state");
    CHECK(hyd_model_node_state(m, hyd_model_find_node(m, "tank")) == -1, "tank has no state");
    double AA, AB, s;
    hyd_model_cylinder_geometry(m, lc, &AA, &AB, &s);
    CHECK_REL(AA, 0.25 * 3.14159265358979 * 0.01, 1e-12);
    CHECK_REL(AB, 0.25 * 3.14159265358979 * (0.01 - 0.0036), 1e-12);
    hyd_model_free(m);
}

// A random state of the default crane, biased into the corners where the
// laws switch: valve edges near p_tr and near closed, reliefs near cracking,
// the pump in its band, chambers near vacuum, pistons near the end stops.
static void random_state(const hyd_model* m, hyd_data* d, double* y) {
    const int n = hyd_model_nstate(m);
    hyd_fluid_def f = hyd_model_fluid(m);
    for (int i = 0; i < n; ++i)
        y[i] = urand(0.2e6, 24e6);
    const int pl = hyd_model_find_state(m, "pump_line.p");
    const int mode = rand() % 4;
    if (mode == 0)
        y[pl] = 1e5 + 20e6 + urand(-0.1e6, 0.6e6); // compensator band
    else if (mode == 1)
        y[pl] = 1e5 + 22e6 + urand(-0.05e6, 1.2e6); // main relief corner
    for (int c = 0; c < hyd_model_ncylinder(m); ++c) {
        double AA, AB, s;
        hyd_model_cylinder_geometry(m, c, &AA, &AB, &s);
        int iA, iB;
        hyd_model_cylinder_states(m, c, &iA, &iB);
        for (int k = 0; k < 2; ++k) {
            const int i = k ? iB : iA;
            switch (rand() % 5) {
            case 0: y[i] = urand(1e3, 6e4); break;               // check valve open, near vacuum
            case 1: y[i] = 1e5 + 25e6 + urand(-2e4, 1.2e6); break; // port relief corner
            case 2: y[i] = urand(150.0, 2e3); break;              // Be(p) near zero pressure
            default: break;
            }
        }
        const int sm = rand() % 3;
        d->cyl_x[c] = sm == 0 ? urand(-2.5e-3, 2.5e-3) : sm == 1 ? s + urand(-2.5e-3, 2.5e-3) : urand(0, s);
        d->cyl_v[c] = urand(-0.3, 0.3);
    }
    for (int v = 0; v < hyd_model_nvalve(m); ++v) {
        const int iu = hyd_model_valve_state(m, v);
        const int um = rand() % 3;
        y[iu] = um == 0 ? urand(-1, 1) : um == 1 ? urand(-1e-3, 1e-3) : urand(-1e-6, 1e-6);
        d->valve_cmd[v] = urand(-1.2, 1.2);
        // Put one metering edge's drop near its transition pressure.
        if (rand() % 2) {
            const double Amax = 6.6667e-4 / (0.65 * sqrt(2e6 / f.density));
            const double ptr = hyd_orifice_p_tr(&f, 0.65, Amax * fabs(y[iu]));
            const int ih = iu + (y[iu] >= 0 ? 1 : 2); // hose A (u > 0) or B (u < 0)
            y[ih] = y[pl] - ptr * urand(0.9, 1.1);
        }
    }
}

// Compare an analytic partial with a central difference. Tolerance: relative
// 1e-4 of the entry, plus 1e-7 of the row's largest entry, plus the
// difference quotient's round-off, noise = 1e-14 * (magnitude of the terms
// summed into f_i) / h. The last term matters for tiny entries such as the
// leakage C_L Be/V next to check-valve flows at near-vacuum pressures.
static int near_fd(double a, double fd, double rowscale, double noise) {
    return fabs(a - fd) <= 1e-4 * fabs(fd) + 1e-7 * rowscale + noise + 1e-300;
}

// Magnitude of the terms in ydot_i: Be/V times the sum of all flows (for a
// pressure state), or 1/tau (a spool).
static void term_scale(const hyd_model* m, const hyd_data* d, double* fs) {
    double qs = 0.0;
    for (int c = 0; c < hyd_model_ncomp(m); ++c)
        qs += fabs(d->comp_q[2 * c]) + fabs(d->comp_q[2 * c + 1]);
    for (int c = 0; c < hyd_model_ncylinder(m); ++c)
        qs += 0.01 * fabs(d->cyl_v[c]); // displacement flows, A <= 0.01 m^2
    for (int i = 0; i < hyd_model_nstate(m); ++i)
        fs[i] = 1.0 / 0.03;
    for (int node = 0; node < hyd_model_nnode(m); ++node) {
        const int i = hyd_model_node_state(m, node);
        if (i >= 0)
            fs[i] = d->node_be[node] / d->node_V[node] * qs;
    }
}

static void test_jacobian_fd(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m)
        return;
    hyd_data* d = hyd_data_create(m);
    const int n = hyd_model_nstate(m), nc = hyd_model_ncylinder(m);
    double y[NMAX], f0[NMAX], fp[NMAX], fm[NMAX], J[NMAX * NMAX], Jfd[NMAX * NMAX];
    srand(12345);
    int bad = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        random_state(m, d, y);
        // Embedded in a bigger matrix at an offset, to test ldj/row0/col0.
        double big[(NMAX + 3) * (NMAX + 5)];
        const int ld = n + 5;
        for (int i = 0; i < (n + 3) * ld; ++i)
            big[i] = 99.0;
        hyd_jacobian(m, d, 0, y, f0, big, ld, 2, 3);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j)
                J[i * n + j] = big[(i + 2) * ld + j + 3];
        CHECK(big[0] == 99.0 && big[1 * ld + 3] == 99.0 && big[2 * ld + 2] == 99.0 &&
                  big[2 * ld + 3 + n] == 99.0,
              "wrote outside its block");
        double F0[4];
        for (int c = 0; c < nc; ++c)
            F0[c] = d->cyl_F[c];
        double dydx[4 * NMAX], dydv[4 * NMAX], dFdy[4 * NMAX], dFdx[4], dFdv[4];
        memcpy(dydx, d->dydx, sizeof(double) * nc * n);
        memcpy(dydv, d->dydv, sizeof(double) * nc * n);
        memcpy(dFdy, d->dFdy, sizeof(double) * nc * n);
        memcpy(dFdx, d->dFdx, sizeof(double) * nc);
        memcpy(dFdv, d->dFdv, sizeof(double) * nc);
        double dFdy_fd[4 * NMAX], fs[NMAX], hs[NMAX];
        term_scale(m, d, fs);
        for (int j = 0; j < n; ++j) {
            const double yj = y[j];
            // Relative steps: a spool near 0 (|u| ~ 1e-6) needs h << |u|.
            const double h = 1e-7 * fabs(yj) + 1e-14;
            hs[j] = h;
            double Fp[4], Fm[4];
            y[j] = yj + h;
            hyd_eval(m, d, 0, y, fp);
            for (int c = 0; c < nc; ++c)
                Fp[c] = d->cyl_F[c];
            y[j] = yj - h;
            hyd_eval(m, d, 0, y, fm);
            for (int c = 0; c < nc; ++c)
                Fm[c] = d->cyl_F[c];
            y[j] = yj;
            for (int i = 0; i < n; ++i)
                Jfd[i * n + j] = (fp[i] - fm[i]) / (2 * h);
            for (int c = 0; c < nc; ++c)
                dFdy_fd[c * n + j] = (Fp[c] - Fm[c]) / (2 * h);
        }
        for (int i = 0; i < n; ++i) {
            double rs = 0;
            for (int j = 0; j < n; ++j)
                rs = fmax(rs, fabs(J[i * n + j]));
            for (int j = 0; j < n; ++j) {
                if (near_fd(J[i * n + j], Jfd[i * n + j], rs, 1e-14 * fs[i] / hs[j]))
                    continue;
                // The laws are C1 but not C2 at regime switches (orifice p_tr,
                // relief and pump corners), where a difference quotient that
                // straddles the switch has an O(h) error. The analytic value is
                // right if the quotient converges to it as h shrinks.
                int ok = 0;
                for (double hh = hs[j] / 16; hh > hs[j] / 5000 && !ok; hh /= 16) {
                    const double yj = y[j];
                    y[j] = yj + hh;
                    hyd_eval(m, d, 0, y, fp);
                    y[j] = yj - hh;
                    hyd_eval(m, d, 0, y, fm);
                    y[j] = yj;
                    // Same tolerance as at h: a smaller step must not loosen it.
                    ok = near_fd(J[i * n + j], (fp[i] - fm[i]) / (2 * hh), rs, 1e-14 * fs[i] / hs[j]);
                }
                if (!ok && bad++ < 10)
                    CHECK(0, "trial %d J[%s][%s] = %.10g, fd %.10g", trial,
                          hyd_model_state_name(m, i), hyd_model_state_name(m, j), J[i * n + j],
                          Jfd[i * n + j]);
            }
        }
        // Coupling partials: x and x' of each cylinder.
        for (int c = 0; c < nc; ++c) {
            for (int which = 0; which < 2; ++which) {
                double* in = which ? &d->cyl_v[c] : &d->cyl_x[c];
                const double v0 = *in, h = which ? 1e-7 : 1e-8;
                double Fp, Fm;
                *in = v0 + h;
                hyd_eval(m, d, 0, y, fp);
                Fp = d->cyl_F[c];
                *in = v0 - h;
                hyd_eval(m, d, 0, y, fm);
                Fm = d->cyl_F[c];
                *in = v0;
                const double* an = which ? dydv + c * n : dydx + c * n;
                double rs = 0;
                for (int i = 0; i < n; ++i)
                    rs = fmax(rs, fabs(an[i]));
                for (int i = 0; i < n; ++i) {
                    const double fd = (fp[i] - fm[i]) / (2 * h);
                    if (!near_fd(an[i], fd, rs, 1e-14 * fs[i] / h) && bad++ < 10)
                        CHECK(0, "trial %d d%s/d%s[%d] = %.10g, fd %.10g", trial,
                              hyd_model_state_name(m, i), which ? "v" : "x", c, an[i], fd);
                }
                const double dF = which ? dFdv[c] : dFdx[c];
                const double fdF = (Fp - Fm) / (2 * h);
                if (!near_fd(dF, fdF, 0.0, 1e-14 * (fabs(F0[c]) + 1e6) / h) && bad++ < 10)
                    CHECK(0, "trial %d dF/d%s[%d] = %.10g, fd %.10g (x=%g v=%g)", trial,
                          which ? "v" : "x", c, dF, fdF, d->cyl_x[c], d->cyl_v[c]);
            }
            for (int j = 0; j < n; ++j)
                if (!near_fd(dFdy[c * n + j], dFdy_fd[c * n + j], 0.0, 1e-14 * (fabs(F0[c]) + 1e6) / hs[j]) && bad++ < 10)
                    CHECK(0, "dF[%d]/d%s = %g, fd %g", c, hyd_model_state_name(m, j),
                          dFdy[c * n + j], dFdy_fd[c * n + j]);
        }
    }
    CHECK(bad == 0, "%d partials disagree with finite differences", bad);
    hyd_data_free(d);
    hyd_model_free(m);
}

// Flow continuity: every component flow leaves one node and enters another,
// so sum_i (V_i/Be_i dp_i/dt + dV_i/dt) over all volume nodes equals the net
// flow that enters from the tank (pump suction, check valves) minus what
// returns to it (reliefs, valve T ports). Internal leakage cancels.
static void test_flow_continuity(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m)
        return;
    hyd_data* d = hyd_data_create(m);
    const int n = hyd_model_nstate(m);
    double y[NMAX], yd[NMAX];
    srand(99);
    for (int trial = 0; trial < 500; ++trial) {
        random_state(m, d, y);
        hyd_eval(m, d, 0, y, yd);
        double stored = 0.0, scale = 0.0;
        for (int node = 0; node < hyd_model_nnode(m); ++node) {
            const int i = hyd_model_node_state(m, node);
            if (i < 0)
                continue;
            stored += d->node_V[node] / d->node_be[node] * yd[i] + d->node_dV[node];
        }
        double from_tank = 0.0;
        for (int c = 0; c < hyd_model_ncomp(m); ++c) {
            const double q = d->comp_q[2 * c];
            scale += fabs(q) + fabs(d->comp_q[2 * c + 1]);
            switch (hyd_model_comp_type(m, c)) {
            case HYD_PUMP: from_tank += q; break;
            case HYD_CHECK: from_tank += q; break;
            case HYD_RELIEF: from_tank -= q; break;
            case HYD_VALVE: {
                // comp_q = [into A, out of B]; the T edge drains B (u >= 0) or A (u < 0).
                int v = -1;
                for (int k = 0; k < hyd_model_nvalve(m); ++k)
                    if (hyd_model_valve_comp(m, k) == c)
                        v = k;
                const double u = y[hyd_model_valve_state(m, v)];
                from_tank -= u >= 0 ? d->comp_q[2 * c + 1] : -d->comp_q[2 * c];
                break;
            }
            default: break;
            }
        }
        CHECK_NEAR(stored, from_tank, 1e-12 * scale + 1e-18);
    }
    (void)n;
    hyd_data_free(d);
    hyd_model_free(m);
}

// hyd_eval_mapped on a permuted, padded state vector gives hyd_eval's
// derivatives bit for bit, in the mapped slots, and leaves the rest alone.
static void test_eval_mapped(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m)
        return;
    hyd_data* d = hyd_data_create(m);
    const int n = hyd_model_nstate(m);
    double y[NMAX], yd[NMAX], ym[2 * NMAX], ydm[2 * NMAX];
    int map[NMAX];
    srand(7);
    for (int trial = 0; trial < 200; ++trial) {
        // A random injective map into 2n slots.
        int slot[2 * NMAX];
        for (int i = 0; i < 2 * n; ++i) slot[i] = i;
        for (int i = 2 * n - 1; i > 0; --i) {
            const int j = rand() % (i + 1), t = slot[i];
            slot[i] = slot[j], slot[j] = t;
        }
        for (int i = 0; i < n; ++i) map[i] = slot[i];
        random_state(m, d, y);
        hyd_eval(m, d, 0, y, yd);
        for (int i = 0; i < 2 * n; ++i) ym[i] = 1e300, ydm[i] = -7.0;
        for (int i = 0; i < n; ++i) ym[map[i]] = y[i];
        hyd_eval_mapped(m, d, 0, ym, ydm, map);
        int bad = 0;
        for (int i = 0; i < n; ++i) bad += memcmp(&ydm[map[i]], &yd[i], sizeof yd[i]) != 0;
        int touched = 0;
        for (int i = 0; i < 2 * n; ++i) touched += ydm[i] != -7.0;
        CHECK(bad == 0, "trial %d: %d states differ from hyd_eval", trial, bad);
        CHECK(touched <= n, "trial %d: wrote %d slots", trial, touched);
        hyd_eval_mapped(m, d, 0, y, ydm, NULL);
        CHECK(memcmp(ydm, yd, (size_t)n * sizeof *yd) == 0, "NULL map is hyd_eval");
    }
    hyd_data_free(d);
    hyd_model_free(m);
}

// The fused kernel (hyd_fused.h) against the general evaluation: the same
// laws summed in a different order, so every derivative agrees to rounding
// of the terms it sums (term_scale), over random states concentrated at the
// regime switches; the Jacobian rows and the coupling partials likewise,
// entry by entry, including the entries the general Jacobian has as zero.
static void test_fused(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m)
        return;
    hyd_data* d = hyd_data_create(m);
    const int n = hyd_model_nstate(m);
    int valve[2], cyl[2];
    for (int k = 0; k < 2; ++k) {
        cyl[k] = hyd_model_cylinder(m, k ? "jib_cyl" : "lift_cyl");
        valve[k] = hyd_model_valve(m, k ? "jib_valve" : "lift_valve");
    }
    hyd_fused f;
    char why[128] = "";
    CHECK(hyd_fused_build(m, valve, cyl, 2, &f, why, sizeof why) == 0, "refused: %s", why);
    double y[NMAX], yd[NMAX], ydf[NMAX], fs[NMAX], J[NMAX * NMAX], Jf[NMAX * NMAX];
    srand(4242);
    int nbad_f = 0, nbad_j = 0, nbad_c = 0, nbad_2 = 0;
    CHECK(f.lanes_ok, "the two-lane kernel does not apply to the default crane");
    for (int trial = 0; trial < 3000; ++trial) {
        random_state(m, d, y);
        double x[2], v[2], cmd[2], F[2], Ff[2];
        for (int k = 0; k < 2; ++k)
            x[k] = d->cyl_x[cyl[k]], v[k] = d->cyl_v[cyl[k]], cmd[k] = d->valve_cmd[valve[k]];
        hyd_jacobian(m, d, 0, y, yd, J, n, 0, 0);
        term_scale(m, d, fs);
        for (int k = 0; k < 2; ++k) F[k] = d->cyl_F[cyl[k]];
        hyd_fused_eval(&f, y, x, v, cmd, ydf, Ff);
        for (int i = 0; i < n; ++i)
            nbad_f += !(fabs(ydf[i] - yd[i]) <= 1e-13 * fs[i] + 1e-300);
        // The two-lane kernel: bit for bit (== also takes 0 for -0).
        double yd2[NMAX], F2[2];
        hyd_fused_eval2(&f, y, x, v, cmd, yd2, F2);
        for (int i = 0; i < n; ++i) nbad_2 += !(yd2[i] == ydf[i] || (isnan(yd2[i]) && isnan(ydf[i])));
        for (int k = 0; k < 2; ++k) nbad_2 += !(F2[k] == Ff[k] || (isnan(F2[k]) && isnan(Ff[k])));
        for (int k = 0; k < 2; ++k)
            nbad_f += !(fabs(Ff[k] - F[k]) <= 1e-13 * (fabs(F[k]) + 1e6));
        memset(Jf, 0, sizeof Jf);
        hyd_fused_coupling cp[2];
        double ydj[NMAX];
        hyd_fused_jacobian(&f, y, x, v, cmd, ydj, Ff, Jf, n, cp);
        for (int i = 0; i < n; ++i) {
            nbad_f += memcmp(&ydj[i], &ydf[i], sizeof ydf[i]) != 0;
            double rs = 0.0;
            for (int j = 0; j < n; ++j) rs = fmax(rs, fabs(J[i * n + j]));
            for (int j = 0; j < n; ++j)
                nbad_j += !(fabs(Jf[i * n + j] - J[i * n + j]) <= 1e-12 * rs + 1e-300);
        }
        for (int k = 0; k < 2; ++k) {
            int iA, iB;
            hyd_model_cylinder_states(m, cyl[k], &iA, &iB);
            const double* gx = d->dydx + (size_t)cyl[k] * n;
            const double* gv = d->dydv + (size_t)cyl[k] * n;
            nbad_c += !(fabs(cp[k].dA_dx - gx[iA]) <= 1e-12 * fabs(gx[iA]) + 1e-13 * fs[iA]);
            nbad_c += !(fabs(cp[k].dB_dx - gx[iB]) <= 1e-12 * fabs(gx[iB]) + 1e-13 * fs[iB]);
            nbad_c += !(fabs(cp[k].dA_dv - gv[iA]) <= 1e-13 * fabs(gv[iA]));
            nbad_c += !(fabs(cp[k].dB_dv - gv[iB]) <= 1e-13 * fabs(gv[iB]));
            nbad_c += cp[k].dF_dx != d->dFdx[cyl[k]] || cp[k].dF_dv != d->dFdv[cyl[k]];
        }
    }
    CHECK(nbad_f == 0, "%d derivatives or forces differ beyond rounding", nbad_f);
    CHECK(nbad_2 == 0, "%d derivatives or forces of the two-lane kernel differ from the scalar one", nbad_2);
    CHECK(nbad_j == 0, "%d Jacobian entries differ", nbad_j);
    CHECK(nbad_c == 0, "%d coupling partials differ", nbad_c);

    // A mapped copy reads and writes the caller's slots.
    int map[NMAX];
    for (int i = 0; i < n; ++i) map[i] = n - 1 - i;
    hyd_fused fm = f;
    hyd_fused_map(&fm, map);
    random_state(m, d, y);
    double yr[NMAX], ydr[NMAX], x[2], v[2], cmd[2], F[2];
    for (int i = 0; i < n; ++i) yr[map[i]] = y[i];
    for (int k = 0; k < 2; ++k)
        x[k] = d->cyl_x[cyl[k]], v[k] = d->cyl_v[cyl[k]], cmd[k] = d->valve_cmd[valve[k]];
    hyd_fused_eval(&f, y, x, v, cmd, ydf, F);
    hyd_fused_eval(&fm, yr, x, v, cmd, ydr, F);
    int bad = 0;
    for (int i = 0; i < n; ++i) bad += memcmp(&ydr[map[i]], &ydf[i], sizeof ydf[i]) != 0;
    CHECK(bad == 0, "mapped fused evaluation differs in %d states", bad);
    hyd_fused_eval2(&fm, yr, x, v, cmd, ydr, F);
    bad = 0;
    for (int i = 0; i < n; ++i) bad += !(ydr[map[i]] == ydf[i]);
    CHECK(bad == 0, "mapped two-lane evaluation differs in %d states", bad);
    hyd_data_free(d);
    hyd_model_free(m);
}

// A pressure for the event test: mostly at the edges the event levels
// switch on (powers of two, the node's knee and its relief/check
// thresholds, each exactly and one ulp either side), sometimes anywhere,
// 0, negative or NaN.
static double event_pressure(const hyd_fused_node* n) {
    const int r = rand() % 16;
    double p;
    if (r < 4) p = ldexp(1.0, 10 + rand() % 16);
    else if (r < 6) p = n->p_knee;
    else if (r < 8) p = n->p_lo;
    else if (r < 10) p = n->p_hi;
    else if (r == 10) p = 0.0;
    else if (r == 11) p = -urand(0.0, 1e5);
    else if (r == 12) p = NAN;
    else p = exp(urand(log(1e3), log(4e7)));
    if (!isfinite(p)) return r == 12 ? p : 1e6;
    const int side = rand() % 3;
    return side == 0 ? p : nextafter(p, side == 1 ? -HUGE_VAL : HUGE_VAL);
}

// hyd_fused_events_update skips the nodes whose pressure stays inside the
// interval where their octave and ramp levels hold, and checks strokes
// inside [0, s] and the commands two lanes at a time. Against the same
// counter taken without those shortcuts (the intervals invalidated before
// every call, the stops and commands one by one): the same count after
// every call and the same stored levels, over random walks that change one
// to three nodes at a time at the exact switching pressures (and strokes
// and commands at theirs), and across a model edit that moves a relief's
// threshold (a rebuilt record at a new revision).
static void test_fused_events_hold(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m) return;
    const int n = hyd_model_nstate(m);
    int valve[2], cyl[2];
    for (int k = 0; k < 2; ++k) {
        cyl[k] = hyd_model_cylinder(m, k ? "jib_cyl" : "lift_cyl");
        valve[k] = hyd_model_valve(m, k ? "jib_valve" : "lift_valve");
    }
    hyd_fused f;
    char why[128] = "";
    CHECK(hyd_fused_build(m, valve, cyl, 2, &f, why, sizeof why) == 0, "refused: %s", why);
    hyd_fused_events ec, er;
    memset(&ec, 0, sizeof ec);
    memset(&er, 0, sizeof er);
    srand(77);
    double y[NMAX];
    for (int i = 0; i < n; ++i) y[i] = 1e6;
    double x[2] = {0.5 * f.act[0].s, 0.5 * f.act[1].s}, cmd[2] = {0.0, 0.0};
    int bad = 0, skipped = 0;
    for (int call = 0; call < 20000; ++call) {
        if (call == 10000) { // a live edit: the relief thresholds move
            // Every node between the old and the new cracking pressure, held
            // there by the old record's intervals.
            for (int j = 0; j < f.nev; ++j) y[f.ev_s[j]] = 2.2e7;
            hyd_fused_events_update(&ec, &f, y, x, cmd);
            er.hold_f = NULL;
            hyd_fused_events_update(&er, &f, y, x, cmd);
            CHECK(hyd_model_set(m, "lift_relief_A.p_crack", 2.0e7, err, sizeof err) == 0, "%s", err);
            CHECK(hyd_fused_build(m, valve, cyl, 2, &f, why, sizeof why) == 0, "refused: %s", why);
        }
        const int nch = 1 + rand() % 3;
        for (int c = 0; c < nch; ++c) {
            const int j = rand() % f.nev;
            const hyd_fused_act* a = &f.act[j / 4 < 2 ? j / 4 : 0];
            const hyd_fused_node* an[4] = {&a->hA, &a->hB, &a->cA, &a->cB};
            const hyd_fused_node* nd = j == f.nev - 1 ? &f.pl : an[j % 4];
            y[f.ev_s[j]] = event_pressure(nd);
        }
        // Strokes and commands: mostly still, sometimes at or beyond an end
        // stop's edges (one ulp either side), a command step, or NaN.
        for (int k = 0; k < 2; ++k) {
            const double sk = f.act[k].s, wk = f.act[k].ws;
            const double xs[9] = {0.5 * sk, 0.0, -0.0, nextafter(0.0, -1.0), sk, nextafter(sk, 2 * sk),
                                  -0.5 * wk, sk + 2.0 * wk, NAN};
            if (rand() % 8 == 0) x[k] = xs[rand() % 9];
            if (rand() % 8 == 0) {
                const int r = rand() % 4;
                cmd[k] = r == 0 ? NAN : (r == 1 ? cmd[k] + 0.3 : urand(-1.0, 1.0) * 0.04 + (isnan(cmd[k]) ? 0.0 : cmd[k]));
                if (fabs(cmd[k]) > 1.0) cmd[k] = 0.0;
            }
        }
        // The reference evaluates every node and the stops and commands one
        // by one (no two-lane check).
        hyd_fused fr = f;
        fr.stops_plain = 0;
        er.hold_f = NULL;
        const unsigned long before = ec.count;
        const unsigned long cc = hyd_fused_events_update(&ec, &f, y, x, cmd);
        const unsigned long cr = hyd_fused_events_update(&er, &fr, y, x, cmd);
        skipped += cc == before;
        bad += cc != cr || memcmp(ec.oct, er.oct, sizeof ec.oct) != 0 || memcmp(ec.lv, er.lv, sizeof ec.lv) != 0 ||
               memcmp(ec.stop, er.stop, sizeof ec.stop) != 0 || memcmp(ec.cmd, er.cmd, sizeof ec.cmd) != 0;
    }
    printf("  events: %lu counted in 20000 calls, %d calls without a switch\n", ec.count, skipped);
    CHECK(bad == 0, "%d calls where the held intervals changed the count or the levels", bad);
    CHECK(ec.count > 1000 && skipped > 1000, "the walk does not exercise both cases (%lu, %d)", ec.count, skipped);
    hyd_model_free(m);
}

// Circuits of another shape are refused with a reason, not mis-evaluated.
static void test_fused_refuses(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m)
        return;
    hyd_fused f;
    char why[128] = "";
    int valve[2] = {0, 1}, cyl[2] = {0, 1};
    // One actuator of two: the other's nodes are unaccounted for.
    CHECK(hyd_fused_build(m, valve, cyl, 1, &f, why, sizeof why) != 0, "one of two actuators accepted");
    CHECK(why[0] != 0, "no reason given");
    // Valve 0 paired with cylinder 1: its hoses lead elsewhere.
    int swapped[2] = {1, 0};
    why[0] = 0;
    CHECK(hyd_fused_build(m, valve, swapped, 2, &f, why, sizeof why) != 0, "crossed actuators accepted");
    CHECK(strstr(why, "hose") != NULL, "reason: %s", why);
    hyd_model_free(m);

    // An orifice anywhere: the general path only.
    hyd_builder* b = hyd_builder_create();
    add_tank(b, "tank", 0);
    add_volume(b, "line", 1e-3);
    add_pump(b, "pump", "tank", "line", 1e-4, 1e7);
    add_orifice(b, "bleed", "line", "tank", 1e-6);
    hyd_model* m2 = hyd_compile(b, err, sizeof err);
    hyd_builder_free(b);
    CHECK(m2 != NULL, "compile: %s", err);
    if (m2) {
        why[0] = 0;
        int none[1] = {0};
        CHECK(hyd_fused_build(m2, none, none, 1, &f, why, sizeof why) != 0, "orifice circuit accepted");
        CHECK(why[0] != 0, "no reason");
        hyd_model_free(m2);
    }
}

static void test_live_parameters(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m)
        return;
    double v;
    CHECK(hyd_model_get(m, "lift_cyl.bore", &v) == 0 && v == 0.1, "get bore");
    CHECK(hyd_model_set(m, "lift_cyl.bore", 0.12, err, sizeof err) == 0, "%s", err);
    double AA, AB, s;
    hyd_model_cylinder_geometry(m, 0, &AA, &AB, &s);
    CHECK_REL(AA, 0.25 * 3.14159265358979 * 0.0144, 1e-12);
    // Rejected values leave the model unchanged and say why.
    CHECK(hyd_model_set(m, "lift_cyl.rod", 0.2, err, sizeof err) == -1, "rod >= bore accepted");
    CHECK(strstr(err, "lift_cyl.rod") && strstr(err, "bore"), "message: %s", err);
    CHECK(hyd_model_get(m, "lift_cyl.rod", &v) == 0 && v == 0.06, "rod unchanged");
    CHECK(hyd_model_set(m, "pump.q_max", -1.0, err, sizeof err) == -1 && strstr(err, "> 0"), "%s", err);
    CHECK(hyd_model_set(m, "pump.qmax", 1.0, err, sizeof err) == -1 && strstr(err, "unknown"), "%s", err);
    CHECK(hyd_model_set(m, "fluid.density", 900.0, err, sizeof err) == 0, "%s", err);
    CHECK(hyd_model_get(m, "fluid.density", &v) == 0 && v == 900.0, "fluid get");
    CHECK(hyd_model_set(m, "tank.pressure", 2e5, err, sizeof err) == 0, "%s", err);
    // A tank pressure change reaches the evaluation: with the valve closed
    // and chamber A below the new crack point, only its check valve flows.
    hyd_data* d = hyd_data_create(m);
    double y[NMAX], yd[NMAX];
    hyd_model_initial_state(m, y);
    int iA, iB;
    hyd_model_cylinder_states(m, 0, &iA, &iB);
    y[iA] = 2e5 - 0.05e6 - 0.02e6; // exactly at full opening: rated flow
    d->cyl_x[0] = 0.3;
    hyd_eval(m, d, 0, y, yd);
    const int ck = hyd_model_find(m, "lift_check_A");
    CHECK_REL(d->comp_q[2 * ck], 40.0 / 60000.0, 1e-9);
    hyd_data_free(d);
    hyd_model_free(m);
}

// The JSON example equals the C default circuit (same layout; same f up to
// the 5-digit rounding of the flows written in the file).
static void test_json_matches_default(void) {
    char err[512];
    hyd_model* a = hyd_model_default_crane(err, sizeof err);
    hyd_model* b = hyd_model_load_json(HYD_TESTDATA "/crane_circuit.json", err, sizeof err);
    CHECK(b != NULL, "%s", err);
    if (!a || !b)
        return;
    const int n = hyd_model_nstate(a);
    CHECK(hyd_model_nstate(b) == n, "nstate");
    for (int i = 0; i < n && i < hyd_model_nstate(b); ++i)
        CHECK(!strcmp(hyd_model_state_name(a, i), hyd_model_state_name(b, i)), "state %d", i);
    // Round trip through hyd_model_to_json gives identical evaluations.
    cJSON* j = hyd_model_to_json(b);
    hyd_model* c = hyd_model_from_json(j, "roundtrip", "", err, sizeof err);
    CHECK(c != NULL, "%s", err);
    cJSON_Delete(j);
    hyd_data *da = hyd_data_create(a), *db = hyd_data_create(b), *dc = c ? hyd_data_create(c) : NULL;
    double y[NMAX], fa[NMAX], fb[NMAX], fc[NMAX];
    srand(5);
    for (int t = 0; t < 200 && dc; ++t) {
        random_state(a, da, y);
        for (int k = 0; k < 2; ++k) {
            db->cyl_x[k] = dc->cyl_x[k] = da->cyl_x[k];
            db->cyl_v[k] = dc->cyl_v[k] = da->cyl_v[k];
            db->valve_cmd[k] = dc->valve_cmd[k] = da->valve_cmd[k];
        }
        hyd_eval(a, da, 0, y, fa);
        hyd_eval(b, db, 0, y, fb);
        hyd_eval(c, dc, 0, y, fc);
        double fs[NMAX];
        term_scale(a, da, fs);
        for (int i = 0; i < n; ++i) {
            CHECK(fb[i] == fc[i], "round trip f[%d] %g vs %g", i, fb[i], fc[i]);
            // The file writes 40 L/min as 6.6667e-4 (5e-6 relative rounding).
            CHECK_NEAR(fa[i], fb[i], 1e-5 * fs[i]);
        }
    }
    hyd_data_free(da);
    hyd_data_free(db);
    hyd_data_free(dc);
    hyd_model_free(a);
    hyd_model_free(b);
    hyd_model_free(c);
}

// The circuit's fastest mode (hyd_model_fastest_rate), on a one-state
// circuit solved by hand: a volume V draining to the tank through an
// orifice, at the tank's pressure, is dp/dt = -(Be(p) / V) g (p - p_T) with
// g the orifice's laminar conductance: rate Be g / V.
static void test_fastest_rate(void) {
    hyd_builder* b = hyd_builder_create();
    add_tank(b, "tank", 0);
    add_volume(b, "line", 1e-3);
    const double A = 1e-6, cd = hyd_default_orifice_def().cd;
    add_orifice(b, "bleed", "line", "tank", A);
    char err[256];
    hyd_model* m = hyd_compile(b, err, sizeof err);
    hyd_builder_free(b);
    CHECK(m != NULL, "%s", err);
    if (!m) return;
    const hyd_fluid_def f = hyd_model_fluid(m);
    const double pT = hyd_default_tank_def().pressure;
    double g;
    hyd_orifice_flow(&f, cd, A, 0.0, &g, NULL);
    const double expect = hyd_bulk_modulus(&f, f.bulk_modulus, pT, NULL) * g / 1e-3;
    CHECK_REL(hyd_model_fastest_rate(m, pT, 0.0), expect, 1e-3);
    hyd_model_free(m);
    // The crane: the hose/chamber pairs are its fastest modes, 1e4..1e5 1/s
    // (docs/hydraulics.md: a calibration prototype found 4e4..9e4).
    hyd_model* c = hyd_model_default_crane(err, sizeof err);
    if (!c) return;
    const double r = hyd_model_fastest_rate(c, 10e6, 0.0);
    printf("  crane circuit at 10 MPa, valves closed: fastest mode %.3g 1/s\n", r);
    CHECK(r > 1e4 && r < 1e6, "rate %g", r);
    hyd_model_free(c);
}

// Seal friction: dF/dx' of the reference evaluation against central
// differences, across its regimes (sticking |v| < v_sm, the Stribeck dip
// around v_st, sliding), and the one-pass kernels (scalar and two-lane) give
// the reference force to rounding and the same dF/dx'.
static void test_seal_partials(void) {
    char err[256];
    hyd_model* m = hyd_model_default_crane(err, sizeof err);
    if (!m) return;
    static const char* const set[] = {"lift_cyl.coulomb", "lift_cyl.stribeck", "jib_cyl.coulomb", "jib_cyl.stribeck"};
    static const double val[] = {3000.0, 1500.0, 2000.0, 1000.0};
    for (int i = 0; i < 4; ++i) CHECK(hyd_model_set(m, set[i], val[i], err, sizeof err) == 0, "%s", err);
    hyd_data* d = hyd_data_create(m);
    const int n = hyd_model_nstate(m);
    int valve[2], cyl[2];
    for (int k = 0; k < 2; ++k) {
        cyl[k] = hyd_model_cylinder(m, k ? "jib_cyl" : "lift_cyl");
        valve[k] = hyd_model_valve(m, k ? "jib_valve" : "lift_valve");
    }
    hyd_fused f;
    char why[128] = "";
    CHECK(hyd_fused_build(m, valve, cyl, 2, &f, why, sizeof why) == 0, "refused: %s", why);
    double y[NMAX], yd[NMAX], J[NMAX * NMAX];
    srand(777);
    int bad_fd = 0, bad_k = 0, bad_2 = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 2000; ++trial) {
        random_state(m, d, y);
        for (int k = 0; k < 2; ++k) {
            const int r = rand() % 3; // v_sm = 1 mm/s, v_st = 10 mm/s
            d->cyl_v[cyl[k]] = r == 0 ? urand(-3e-3, 3e-3) : r == 1 ? urand(-0.03, 0.03) : urand(-0.3, 0.3);
            d->cyl_x[cyl[k]] = urand(0.05, 0.5); // off the end stops: the seal term alone
        }
        hyd_jacobian(m, d, 0, y, yd, J, n, 0, 0);
        double F[2], dFdv[2], x[2], v[2], cmd[2];
        for (int k = 0; k < 2; ++k) {
            F[k] = d->cyl_F[cyl[k]], dFdv[k] = d->dFdv[cyl[k]];
            x[k] = d->cyl_x[cyl[k]], v[k] = d->cyl_v[cyl[k]], cmd[k] = d->valve_cmd[valve[k]];
        }
        for (int k = 0; k < 2; ++k) {
            double* in = &d->cyl_v[cyl[k]];
            const double v0 = *in, h = 1e-7;
            *in = v0 + h;
            hyd_eval(m, d, 0, y, yd);
            const double Fp = d->cyl_F[cyl[k]];
            *in = v0 - h;
            hyd_eval(m, d, 0, y, yd);
            const double Fm = d->cyl_F[cyl[k]];
            *in = v0;
            const double fd = (Fp - Fm) / (2 * h);
            const double err_fd = fabs(fd - dFdv[k]) / (1e-5 * fabs(dFdv[k]) + 1e-14 * (fabs(F[k]) + 1e6) / h);
            worst = fmax(worst, err_fd);
            if (err_fd > 1.0 && bad_fd++ < 5)
                CHECK(0, "trial %d cyl %d v = %g: dF/dv = %.10g, fd %.10g", trial, k, v0, dFdv[k], fd);
        }
        double ydf[NMAX], Ff[2], yd2[NMAX], F2[2], ydj[NMAX], Jf[NMAX * NMAX];
        hyd_fused_eval(&f, y, x, v, cmd, ydf, Ff);
        hyd_fused_eval2(&f, y, x, v, cmd, yd2, F2);
        hyd_fused_coupling cp[2];
        hyd_fused_jacobian(&f, y, x, v, cmd, ydj, Ff, Jf, n, cp);
        for (int k = 0; k < 2; ++k) {
            bad_k += !(fabs(Ff[k] - F[k]) <= 1e-12 * (fabs(F[k]) + 1e6));
            bad_k += !(fabs(cp[k].dF_dv - dFdv[k]) <= 1e-12 * fabs(dFdv[k]));
            bad_2 += !(F2[k] == Ff[k]);
        }
    }
    // The seal force itself, by hand: F depends on x' only through -b_v x',
    // the seal and the end stops (off here), so F(v) - F(-v) = -2 b_v v -
    // 2 (F_c + F_s exp(-(v/v_st)^2)) tanh(v/v_sm). At v = v_st = 10 mm/s on
    // the lift cylinder: -2 (5e3 0.01) - 2 (3000 + 1500/e) tanh(10) = -7203.6 N.
    random_state(m, d, y);
    d->cyl_x[cyl[0]] = 0.3;
    d->cyl_v[cyl[0]] = 0.01;
    hyd_eval(m, d, 0, y, yd);
    const double Fplus = d->cyl_F[cyl[0]];
    d->cyl_v[cyl[0]] = -0.01;
    hyd_eval(m, d, 0, y, yd);
    const double Fminus = d->cyl_F[cyl[0]];
    CHECK_NEAR(Fplus - Fminus, -2 * 5e3 * 0.01 - 2 * (3000 + 1500 * exp(-1.0)) * tanh(10.0), 1e-6 * 1e6);
    printf("  seal dF/dv: worst |fd - analytic| / tolerance %.3g\n", worst);
    CHECK(bad_fd == 0, "%d seal partials disagree with central differences", bad_fd);
    CHECK(bad_k == 0, "%d one-pass forces or dF/dv differ from the reference", bad_k);
    CHECK(bad_2 == 0, "%d two-lane forces differ from the scalar kernel", bad_2);
    hyd_data_free(d);
    hyd_model_free(m);
}

int main(int argc, char** argv) {
    RUN_TEST(test_layout);
    RUN_TEST(test_jacobian_fd);
    RUN_TEST(test_flow_continuity);
    RUN_TEST(test_eval_mapped);
    RUN_TEST(test_fused);
    RUN_TEST(test_seal_partials);
    RUN_TEST(test_fused_events_hold);
    RUN_TEST(test_fused_refuses);
    RUN_TEST(test_live_parameters);
    RUN_TEST(test_json_matches_default);
    RUN_TEST(test_fastest_rate);
    TEST_MAIN_END();
}
