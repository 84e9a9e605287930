// crane_chain_synth.c: synthetic crane chains (crane_chain_synth.h).
#include "crane_chain_synth.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

int crane_chain_synthetic(const char* joints, bool slew_free, crane_chain* out, hyd_model** hm, double* q0,
                          char* err, size_t errsz) {
    memset(out, 0, sizeof *out);
    *hm = NULL;
    const int n = (int)strlen(joints);
    if (n < 1 || joints[0] != 'R' || strspn(joints, "RP") != (size_t)n) {
        snprintf(err, errsz, "synthetic chain '%s': joints must be R or P, the first R", joints);
        return -1;
    }
    *hm = hyd_model_synthetic(n, err, errsz);
    if (!*hm) return -1;
    out->nbody = n + 1;
    out->nact = out->nfn = n;
    out->body = calloc((size_t)n + 1, sizeof *out->body);
    out->act = calloc((size_t)n, sizeof *out->act);
    out->fn = calloc((size_t)n, sizeof *out->fn);
    if (!out->body || !out->act || !out->fn) {
        snprintf(err, errsz, "out of memory");
        goto fail;
    }
    // The column: 2 m high, 300 kg, a solid cylinder of radius 0.1 m.
    crane_body* col = &out->body[0];
    chain_body_init(&col->def, -1);
    snprintf(col->def.name, sizeof col->def.name, "column");
    col->def.mass = 300.0;
    col->def.com[2] = 1.0;
    chain_inertia_box(300.0, 0.2, 0.2, 2.0, col->def.inertia);
    col->length = 2.0;
    col->width = col->height = 0.2;
    for (int k = 1; k <= n; ++k) {
        crane_body* b = &out->body[k];
        const crane_body* p = &out->body[k - 1];
        const bool pr = joints[k - 1] == 'P';
        chain_body_init(&b->def, k - 1);
        snprintf(b->def.name, sizeof b->def.name, "%s%d", pr ? "ext" : "boom", k);
        b->def.joint = pr ? CHAIN_PRISMATIC : CHAIN_REVOLUTE;
        b->length = pr ? 0.8 * p->length : 2.4 * pow(0.8, k - 1);
        b->width = 0.2 * pow(0.9, k - 1);
        b->height = 0.25 * pow(0.9, k - 1);
        b->def.mass = 200.0 * pow(0.75, k - 1);
        b->def.com[0] = 0.5 * b->length;
        chain_inertia_box(b->def.mass, b->length, b->width, b->height, b->def.inertia);
        if (k == 1) { // on the column top, q from the downward vertical
            b->def.origin[2] = 2.0;
            b->def.angle0 = -M_PI / 2;
        } else if (pr) { // sliding inside its boom from half its length out
            b->def.offset0 = 0.5 * p->length;
        } else { // at the tip of the body before
            b->def.origin[0] = p->length;
        }
        crane_act* a = &out->act[k - 1];
        snprintf(a->name, sizeof a->name, "f%d", k);
        snprintf(a->cylinder, sizeof a->cylinder, "act%d_cyl", k);
        snprintf(a->valve, sizeof a->valve, "act%d_valve", k);
        a->kind = CRANE_ACT_CYLINDER;
        a->body_a = k - 1;
        a->body_b = k;
        if (k == 1) { // lift: column below the joint to the arm's underside
            a->pa[0] = 0.25, a->pa[2] = 1.0;
            a->pb[0] = 0.8, a->pb[2] = -0.15;
            q0[k - 1] = 1.6;
        } else if (pr) { // extension: along the slide, above the boom's axis
            a->pa[0] = 0.1 * p->length, a->pa[2] = 0.1;
            a->pb[0] = 0.5 * b->length, a->pb[2] = 0.1;
            q0[k - 1] = 0.3;
        } else { // knuckle: from above the body before to below this one
            // (a lever arm of 0.24 to 0.35 m about the joint, folded down)
            a->pa[0] = 0.6 * p->length, a->pa[2] = 0.25;
            a->pb[0] = 0.4, a->pb[2] = -0.25;
            q0[k - 1] = (k % 2) ? -0.5 : -0.9;
        }
        // Joint limits: 0.5 rad either side of the start, an extension
        // [0, 0.6] m (the start pose in their middle).
        b->def.q_min = pr ? 0.0 : q0[k - 1] - 0.5;
        b->def.q_max = pr ? 0.6 : q0[k - 1] + 0.5;
        crane_function* f = &out->fn[k - 1];
        snprintf(f->name, sizeof f->name, "f%d", k);
        snprintf(f->valve, sizeof f->valve, "act%d_valve", k);
    }
    out->tip_body = n;
    out->tip[0] = out->body[n].length;
    out->gravity = 9.81;
    out->slew_free = slew_free;
    out->two_link = false;
    if (crane_chain_bind(out, *hm, err, errsz)) goto fail;
    // Closed lengths: half stroke at q0 (the column at slew 0; the pins do
    // not depend on the slew).
    chain* ch = crane_chain_mechanism(out, 0.0, false, 0.0, err, errsz);
    chain_ws* w = ch ? chain_ws_create(ch) : NULL;
    if (!w) {
        if (ch) snprintf(err, errsz, "out of memory");
        chain_free(ch);
        goto fail;
    }
    chain_update(ch, w, q0, NULL);
    for (int k = 0; k < n; ++k) {
        crane_act* a = &out->act[k];
        const double L = chain_cylinder(ch, w, a->body_a, a->pa, a->body_b, a->pb, NULL, NULL, NULL);
        a->closed_length = L - 0.5 * a->stroke;
    }
    chain_ws_free(w);
    chain_free(ch);
    return 0;
fail:
    crane_chain_free(out);
    hyd_model_free(*hm);
    *hm = NULL;
    return -1;
}
