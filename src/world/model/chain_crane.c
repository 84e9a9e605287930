// chain_crane.c: the two-link crane_mech as a chain (chain_crane.h).
#include "chain_crane.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

int chain_from_crane_mech(const crane_mech* m, double tip_mass, const chain_crane_opts* opt, chain_crane* out) {
    const chain_crane_opts dflt = {0, 0.0, 0.1};
    if (!opt) opt = &dflt;
    memset(out, 0, sizeof *out);
    const double h = m->column_height, rc = opt->column_radius;

    // Column: a solid cylinder from the truck bed to joint 1 (as the ODE sandbox builds it).
    chain_body_def* b = &out->body[0];
    chain_body_init(b, -1);
    snprintf(b->name, sizeof b->name, "column");
    b->fixed = !opt->slew_free;
    b->q_fixed = opt->slew;
    b->mass = m->column_mass;
    b->com[2] = 0.5 * h;
    b->inertia[0][0] = b->inertia[1][1] = m->column_mass * (3.0 * rc * rc + h * h) / 12.0;
    b->inertia[2][2] = 0.5 * m->column_mass * rc * rc;

    for (int i = 0; i < 2; ++i) {
        const crane_link* l = &m->link[i];
        b = &out->body[i + 1];
        chain_body_init(b, i);
        snprintf(b->name, sizeof b->name, "%s", l->name);
        b->joint = CHAIN_REVOLUTE;
        // Lifting arm: joint 1 on the column axis at the column top, q1 from
        // the downward vertical (angle0 = -90 deg); end arm: joint 2 at the
        // lifting arm's tip, q2 relative to it.
        b->origin[0] = i ? m->link[0].length : 0.0;
        b->origin[2] = i ? 0.0 : h;
        b->angle0 = i ? 0.0 : -0.5 * M_PI;
        b->mass = l->mass;
        b->com[0] = l->com;
        // About the joint axis (y) as given, the others from the box, as
        // the ODE world's boom_mass: the same crane, the same bodies.
        chain_inertia_section(l->mass, l->inertia, l->length, l->width, l->height, b->inertia);
    }
    if (tip_mass > 0) {
        const double tip[3] = {m->link[1].length, 0, 0};
        chain_body_add_point_mass(&out->body[2], tip_mass, tip);
    }

    // Mounts are given in the boom plane (x, z) relative to the joint they act
    // across; the parent frame's origin is the column base (lift) or joint 1 (jib).
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &m->act[k];
        if (a->joint != 0 && a->joint != 1) return -1;
        chain_crane_cyl* c = &out->cyl[k];
        c->body_a = a->joint;
        c->body_b = a->joint + 1;
        c->pa[0] = a->base_mount[0] + (a->joint ? m->link[0].length : 0.0);
        c->pa[2] = a->base_mount[1] + (a->joint ? 0.0 : h);
        c->pb[0] = a->rod_mount[0];
        c->pb[2] = a->rod_mount[1];
        c->closed_length = a->closed_length;
    }
    return 0;
}
