// every_type.h: one instance of each component type, as a circuit fragment
// to append to a shipped circuit where it carries flow (tests/hydraulics/
// test_every_type.c, tests/lagrange/test_every_type_lsim.c). A type without
// an instance here fails both tests: a new type gets its line in instance().
#ifndef CRANESIM_TEST_EVERY_TYPE_H
#define CRANESIM_TEST_EVERY_TYPE_H

#include "hydraulics.h"

#include <stdio.h>
#include <string.h>

// Where an instance is connected, by node name in the base circuit.
typedef struct anchors {
    char supply[64]; ///< the pump line (hyd_model_supply_node)
    char tank[64];   ///< a tank
    char chA[64];    ///< chamber A and B of the first cylinder
    char chB[64];
    char ls[64];     ///< the LS line, or "" when the circuit has none
    char lsload[64]; ///< a node a shuttle passes to the LS line (a section's LS node), else chA
} anchors;

static int find_anchors(const hyd_model* m, anchors* a) {
    memset(a, 0, sizeof *a);
    const int sup = hyd_model_supply_node(m);
    if (sup < 0) return -1;
    snprintf(a->supply, sizeof a->supply, "%s", hyd_model_node_name(m, sup));
    for (int i = 0; i < hyd_model_nnode(m); ++i) {
        if (hyd_model_node_role(m, i) == HYD_NODE_TANK && !a->tank[0])
            snprintf(a->tank, sizeof a->tank, "%s", hyd_model_node_name(m, i));
        if (hyd_model_node_role(m, i) == HYD_NODE_LS && !a->ls[0])
            snprintf(a->ls, sizeof a->ls, "%s", hyd_model_node_name(m, i));
    }
    if (!a->tank[0] || hyd_model_ncylinder(m) < 1) return -1;
    const int c = hyd_model_cylinder_comp(m, 0);
    snprintf(a->chA, sizeof a->chA, "%s", hyd_model_node_name(m, hyd_model_comp_node(m, c, 0)));
    snprintf(a->chB, sizeof a->chB, "%s", hyd_model_node_name(m, hyd_model_comp_node(m, c, 1)));
    snprintf(a->lsload, sizeof a->lsload, "%s", a->chA);
    const int ls = a->ls[0] ? hyd_model_find_node(m, a->ls) : -1;
    for (int k = 0; k < hyd_model_ncomp(m) && ls >= 0; ++k)
        if (hyd_model_comp_type(m, k) == HYD_SHUTTLE && hyd_model_port_node(m, k, 2) == ls) {
            snprintf(a->lsload, sizeof a->lsload, "%s",
                     hyd_model_node_name(m, hyd_model_port_node(m, k, 0)));
            break;
        }
    return 0;
}

// One instance of type t as a circuit fragment {"nodes": [...], "components":
// [...]}, connected so that it carries flow: from the pump line, into a
// chamber, or between the chambers. NULL when the test has none for t.
static char* instance(hyd_type t, const anchors* a) {
    static char s[2048];
    const char* ls = a->ls[0] ? a->ls : "x_ls";
    const char* ls_node =
        a->ls[0] ? "" : "{\"name\": \"x_ls\", \"type\": \"volume\", \"volume\": 5e-6, \"p0\": 1e5}";
    switch (t) {
    case HYD_TANK: // a second tank, bled into from the pump line
        snprintf(
            s, sizeof s,
            "{\"nodes\": [{\"name\": \"x_tank\", \"type\": \"tank\", \"pressure\": 3e5}],"
            " \"components\": [{\"name\": \"x_bleed\", \"type\": \"orifice\", \"inlet\": \"%s\","
            " \"outlet\": \"x_tank\", \"area\": 2e-6}]}",
            a->supply);
        break;
    case HYD_VOLUME: // a line fed from the pump line through an orifice
        snprintf(
            s, sizeof s,
            "{\"nodes\": [{\"name\": \"x_vol\", \"type\": \"volume\", \"volume\": 1e-4, \"p0\": "
            "5e6}],"
            " \"components\": [{\"name\": \"x_feed\", \"type\": \"orifice\", \"inlet\": \"%s\","
            " \"outlet\": \"x_vol\", \"area\": 2e-6}]}",
            a->supply);
        break;
    case HYD_PUMP: // a second (fixed) pump into the pump line
        snprintf(s, sizeof s,
                 "{\"components\": [{\"name\": \"x_pump\", \"type\": \"pump\", \"inlet\": \"%s\","
                 " \"outlet\": \"%s\", \"q_max\": 2e-4, \"p_set\": 18e6, \"band\": 5e5}]}",
                 a->tank, a->supply);
        break;
    case HYD_RELIEF: // chamber A to tank, cracking inside the random pressures
        snprintf(
            s, sizeof s,
            "{\"components\": [{\"name\": \"x_relief\", \"type\": \"relief\", \"inlet\": \"%s\","
            " \"outlet\": \"%s\", \"p_crack\": 12e6, \"dp_override\": 1e6, \"q_rated\": 3e-4}]}",
            a->chA, a->tank);
        break;
    case HYD_CHECK: // tank into chamber B, open near vacuum
        snprintf(s, sizeof s,
                 "{\"components\": [{\"name\": \"x_check\", \"type\": \"check\", \"inlet\": \"%s\","
                 " \"outlet\": \"%s\", \"p_crack\": 3e4, \"dp_open\": 2e4, \"q_rated\": 3e-4}]}",
                 a->tank, a->chB);
        break;
    case HYD_ORIFICE: // a bypass between the chambers
        snprintf(
            s, sizeof s,
            "{\"components\": [{\"name\": \"x_orifice\", \"type\": \"orifice\", \"inlet\": \"%s\","
            " \"outlet\": \"%s\", \"area\": 1e-6}]}",
            a->chA, a->chB);
        break;
    case HYD_HOSE: // a hose volume hanging on chamber A
        snprintf(s, sizeof s,
                 "{\"components\": [{\"name\": \"x_hose\", \"type\": \"hose\", \"to\": \"%s\","
                 " \"length\": 1.0, \"diameter\": 0.01}]}",
                 a->chA);
        break;
    case HYD_VALVE: // a valve from the pump line into two lines
        snprintf(s, sizeof s,
                 "{\"nodes\": [{\"name\": \"x_va\", \"type\": \"volume\", \"volume\": 5e-5, "
                 "\"p0\": 1e6},"
                 " {\"name\": \"x_vb\", \"type\": \"volume\", \"volume\": 5e-5, \"p0\": 1e6}],"
                 " \"components\": [{\"name\": \"x_valve\", \"type\": \"valve\", \"P\": \"%s\", "
                 "\"T\": \"%s\","
                 " \"A\": \"x_va\", \"B\": \"x_vb\", \"q_nominal\": 3e-4, \"dp_nominal\": 1e6}]}",
                 a->supply, a->tank);
        break;
    case HYD_CYLINDER: // a cylinder fed from the pump line through an orifice
        snprintf(s, sizeof s,
                 "{\"components\": [{\"name\": \"x_cyl\", \"type\": \"cylinder\", \"bore\": 0.063,"
                 " \"rod\": 0.03, \"stroke\": 0.5, \"leakage\": 1e-12, \"coulomb\": 500, "
                 "\"stribeck\": 200},"
                 " {\"name\": \"x_cyl_feed\", \"type\": \"orifice\", \"inlet\": \"%s\", "
                 "\"outlet\": \"x_cyl.A\","
                 " \"area\": 1e-6}]}",
                 a->supply);
        break;
    case HYD_LS_PUMP: // a second LS pump into the pump line, sensing the LS line (else
        // chamber A: a model's LS pump must sense a node its work lines reach)
        snprintf(s, sizeof s,
                 "{\"components\": [{\"name\": \"x_lspump\", \"type\": \"ls_pump\","
                 " \"inlet\": \"%s\", \"outlet\": \"%s\", \"ls\": \"%s\", \"q_max\": 2e-4}]}",
                 a->tank, a->supply, a->ls[0] ? a->ls : a->chA);
        break;
    case HYD_SHUTTLE: // the max of the chambers into the LS line
        snprintf(
            s, sizeof s,
            "{\"nodes\": [%s], \"components\": [{\"name\": \"x_shuttle\", \"type\": \"shuttle\","
            " \"a\": \"%s\", \"b\": \"%s\", \"out\": \"%s\"}]}",
            ls_node, a->chA, a->chB, ls);
        break;
    case HYD_COMPENSATOR: // from the pump line into a section line, sensing a section's
        // LS node against the LS line (else chamber A against chamber B): a
        // model's compensator must sense a load its pump's LS line sees
        snprintf(
            s, sizeof s,
            "{\"nodes\": [{\"name\": \"x_P\", \"type\": \"volume\", \"volume\": 1e-4, \"p0\": "
            "2e6}],"
            " \"components\": [{\"name\": \"x_comp\", \"type\": \"compensator\", \"inlet\": \"%s\","
            " \"outlet\": \"x_P\", \"load\": \"%s\", \"ref\": \"%s\", \"area\": 3e-5, \"mode\": "
            "1}]}",
            a->supply, a->lsload, a->ls[0] ? a->ls : a->chB);
        break;
    case HYD_COUNTERBALANCE: // between a valve-side line and chamber A, piloted by chamber B
        snprintf(s, sizeof s,
                 "{\"nodes\": [{\"name\": \"x_cbv_v\", \"type\": \"volume\", \"volume\": 5e-5, "
                 "\"p0\": 1e6}],"
                 " \"components\": [{\"name\": \"x_cbv\", \"type\": \"counterbalance\", \"valve\": "
                 "\"x_cbv_v\","
                 " \"load\": \"%s\", \"pilot\": \"%s\", \"p_setting\": 12e6, \"area\": 2e-5}]}",
                 a->chA, a->chB);
        break;
    case HYD_ACCUMULATOR: // on the pump line
        snprintf(
            s, sizeof s,
            "{\"components\": [{\"name\": \"x_acc\", \"type\": \"accumulator\", \"port\": \"%s\","
            " \"p0\": 5e6, \"V0\": 1e-3, \"conductance\": 1e-10}]}",
            a->supply);
        break;
    default:
        return NULL;
    }
    return s;
}

#endif
