// test_flow_accounting.c: where the pump's flow goes when the load-sensing
// crane shares it (ls_flow_sharing, both sections at full command, the pump
// saturated; docs/model.md, "Where the pump's flow goes"). The pistons take
// less than the pump delivers; this accounts for every flow over the supply
// side of the circuit (every node the pump feeds: the pump line, the
// sections' P and LS nodes, the fed hoses, the counterbalance valves' valve
// ports and the piston chambers) and checks that the terms close:
//
//   pump delivery = into the pistons + compression of the oil on the supply
//                   side + every flow that leaves it (relief, LS drains,
//                   cylinder leakage) - every flow that enters it otherwise
//                   (anti-cavitation checks)
//
// with each term found on its own: the pistons' flow from the strokes'
// change times the piston areas, the compression from the pressures'
// trajectory (the integral of V / Be(p) dp per node, step by step), the
// flows across the boundary from the components' own flows. The pump's
// delivery is checked against its law by hand, q_max minus its leakage.
#include "check.h"
#include "crane_fixture.h"
#include "engine.h"
#include "hydraulics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAXN 64
#define MAXC 64

// Nodes on the rod side of cylinder chambers B: each chamber B and what a
// hose or an orifice joins to it (its hose, the counterbalance valve's
// pilot behind its damping orifice). Not through valves, shuttles or
// counterbalance valves: those are where the supply side meets it.
static void rod_side(const hyd_model* m, bool* R) {
    const int nn = hyd_model_nnode(m), nc = hyd_model_ncomp(m);
    for (int c = 0; c < nc; ++c)
        if (hyd_model_comp_type(m, c) == HYD_CYLINDER) R[hyd_model_comp_node(m, c, 1)] = true;
    for (bool grew = true; grew;) {
        grew = false;
        for (int c = 0; c < nc; ++c) {
            const hyd_type t = hyd_model_comp_type(m, c);
            if (t != HYD_HOSE && t != HYD_ORIFICE) continue;
            int nodes[2] = {t == HYD_HOSE ? hyd_model_comp_node(m, c, 0) : hyd_model_port_node(m, c, 0),
                            t == HYD_HOSE ? hyd_model_port_node(m, c, 0) : hyd_model_port_node(m, c, 1)};
            if (nodes[0] < 0 || nodes[1] < 0 || nodes[0] >= nn || nodes[1] >= nn) continue;
            if (hyd_model_node_state(m, nodes[0]) < 0 || hyd_model_node_state(m, nodes[1]) < 0) continue;
            if (R[nodes[0]] != R[nodes[1]]) {
                R[nodes[0]] = R[nodes[1]] = true;
                grew = true;
            }
        }
    }
}

static void test_flow_sharing_accounts(void) {
    model* m = load_model("hiab031_ls.json");
    scenario sc;
    if (!m || load_scenario("ls_flow_sharing", &sc)) {
        model_free(m);
        return;
    }
    sim_opts o = sim_default_opts(); // Krus, 0.1 ms, lagrange
    char err[512];
    engine* e = engine_create(m, &o, sc.q0, 0.0, sc.load_mass, err, sizeof err);
    CHECK(e != NULL, "%s", err);
    if (!e) {
        model_free(m);
        return;
    }
    const hyd_model* hm = engine_circuit(e);
    const int nn = hyd_model_nnode(hm), nc = hyd_model_ncomp(hm), ncyl = hyd_model_ncylinder(hm);
    CHECK(nn <= MAXN && nc <= MAXC, "%d nodes, %d components", nn, nc);
    if (nn > MAXN || nc > MAXC) {
        engine_destroy(e);
        model_free(m);
        return;
    }
    // The supply side S: every node with a pressure state but the rod sides.
    bool R[MAXN] = {false}, S[MAXN] = {false};
    rod_side(hm, R);
    for (int n = 0; n < nn; ++n) S[n] = hyd_model_node_state(hm, n) >= 0 && !R[n];

    hyd_data* d = hyd_data_create(hm);
    double y[MAXN + MAXC], yd[MAXN + MAXC];
    const double t0 = 1.5, t1 = 3.0, h = o.h; // the window: both at full command, the jib no longer overrunning
    // Trapezoid sums over the window: each component's flow across S's
    // boundary (into S), and each S node's compression V / Be dp.
    double qb[MAXC] = {0}, qb_prev[MAXC] = {0}, comp[MAXN] = {0}, cp_prev[MAXN] = {0}, p_prev[MAXN] = {0};
    double x0[8] = {0}, x1[8] = {0}, AA[8], AB[8], stroke[8], pump_q = 0, pump_prev = 0, dp_pump = 0;
    int pump = -1, samples = 0;
    bool saturated = true, extending = true;
    for (int c = 0; c < nc; ++c)
        if (hyd_model_comp_type(hm, c) == HYD_LS_PUMP) pump = c;
    for (int k = 0; k < ncyl && k < 8; ++k) hyd_model_cylinder_geometry(hm, k, &AA[k], &AB[k], &stroke[k]);
    const long nstep = (long)floor(t1 / h + 0.5), k0 = (long)floor(t0 / h + 0.5);
    for (long i = 0; i <= nstep; ++i) {
        const double t = (double)i * h;
        if (i > 0) {
            // The commands at the step's midpoint, held over it.
            const double u[3] = {scenario_command(&sc, 0, t - 0.5 * h), scenario_command(&sc, 1, t - 0.5 * h), 0};
            engine_set_commands(e, u);
            if (engine_advance(e, h)) {
                CHECK(0, "step failed at %g s: %s", t, engine_error(e));
                break;
            }
        }
        if (i < k0) continue;
        const hyd_data* in;
        engine_circuit_state(e, y, &in);
        for (int k = 0; k < ncyl; ++k) d->cyl_x[k] = in->cyl_x[k], d->cyl_v[k] = in->cyl_v[k];
        for (int v = 0; v < hyd_model_nvalve(hm); ++v) d->valve_cmd[v] = in->valve_cmd[v];
        hyd_eval(hm, d, t, y, yd);
        // Each component's flow into S from outside it (a slot on an S node
        // of a component with a slot off S; a component with every slot in
        // S only moves oil within it: a compensator, the fed hose, the
        // counterbalance valve, the main shuttle).
        for (int c = 0; c < nc; ++c) {
            int node[4];
            double f[4];
            const int ns = hyd_comp_flows(hm, d, c, node, f);
            bool crosses = false;
            for (int s = 0; s < ns; ++s) crosses = crosses || !S[node[s]];
            double qc = 0.0;
            for (int s = 0; s < ns && crosses; ++s)
                if (S[node[s]]) qc += f[s];
            if (i > k0) qb[c] += 0.5 * h * (qc + qb_prev[c]);
            qb_prev[c] = qc;
        }
        for (int n = 0; n < nn; ++n) {
            if (!S[n]) continue;
            const double c = d->node_V[n] / d->node_be[n];
            if (i > k0) comp[n] += 0.5 * (c + cp_prev[n]) * (d->node_p[n] - p_prev[n]);
            cp_prev[n] = c, p_prev[n] = d->node_p[n];
        }
        const double qp = pump >= 0 ? d->comp_q[2 * pump] : 0.0;
        if (i > k0) pump_q += 0.5 * h * (qp + pump_prev);
        pump_prev = qp;
        if (pump >= 0) {
            const int out = hyd_model_port_node(hm, pump, 1), inl = hyd_model_port_node(hm, pump, 0);
            dp_pump += (d->node_p[out] - d->node_p[inl]) / (double)(nstep - k0 + 1);
            saturated = saturated && !d->comp_open[pump];
        }
        for (int k = 0; k < ncyl && k < 8; ++k) {
            if (i == k0) x0[k] = d->cyl_x[k];
            x1[k] = d->cyl_x[k];
            extending = extending && d->cyl_v[k] > 0.0;
        }
        ++samples;
    }
    const double T = t1 - t0, L = 6e4 / T; // volumes over the window to mean flows [L/min]
    CHECK(samples == nstep - k0 + 1, "%d samples", samples);
    CHECK(saturated, "the pump regulated in the window: not saturated");
    CHECK(extending, "a cylinder did not extend throughout the window");
    // The pump's delivery by its law (docs/hydraulics.md): at full
    // displacement q_max less its leakage, C_L (p_out - p_in).
    const double qmax = 0.00058333, cleak = 5.6e-13; // hiab031_ls.json
    const double hand = qmax - cleak * dp_pump;
    printf("pump: %.4f L/min delivered, by hand %.4f (35 - %.4f leakage at %.2f MPa)\n", pump_q * L, hand * 6e4,
           cleak * dp_pump * 6e4, dp_pump * 1e-6);
    CHECK(fabs(pump_q / T - hand) < 1e-4 * qmax, "pump %.6g m^3/s, by hand %.6g", pump_q / T, hand);
    // Into the pistons: the strokes' change times the piston areas.
    double pistons = 0.0;
    for (int k = 0; k < ncyl && k < 8; ++k) {
        const double v = AA[k] * (x1[k] - x0[k]);
        printf("piston %d: %.4f L/min (stroke %+.1f mm)\n", k, v * L, 1e3 * (x1[k] - x0[k]));
        pistons += v;
    }
    // The compression of the oil on the supply side, per node.
    double compression = 0.0;
    for (int n = 0; n < nn; ++n) {
        if (!S[n]) continue;
        compression += comp[n];
        printf("compression %-16s %+.4f L/min\n", hyd_model_node_name(hm, n), comp[n] * L);
    }
    // Across the supply side's boundary (the pump's own among them).
    double other = 0.0;
    for (int c = 0; c < nc; ++c) {
        if (qb[c] == 0.0) continue;
        printf("into the supply side from %-16s %+.4f L/min\n", hyd_model_comp_name(hm, c), qb[c] * L);
        if (c != pump) other += qb[c];
    }
    const double residual = pump_q + other - pistons - compression;
    printf("pump %.4f + other flows %+.4f = pistons %.4f + compression %.4f + residual %+.5f L/min\n", pump_q * L,
           other * L, pistons * L, compression * L, residual * L);
    // Closes to 0.01 L/min (0.03 % of the pump's flow): what is left is the
    // trapezoid sums' error over 0.1 ms steps.
    CHECK(fabs(residual * L) < 0.01, "the flows do not close: residual %.5f L/min", residual * L);
    // The pistons do take less than the pump delivers, and the compression
    // is where most of the difference goes (the finding).
    CHECK(pistons < pump_q && compression > 0.5 * (pump_q - pistons), "pistons %.4f, pump %.4f, compression %.4f",
          pistons * L, pump_q * L, compression * L);
    hyd_data_free(d);
    engine_destroy(e);
    model_free(m);
}

int main(void) {
    test_flow_sharing_accounts();
    printf("%d checks, %d failed\n", check_count_, check_failures_);
    return check_failures_ != 0;
}
