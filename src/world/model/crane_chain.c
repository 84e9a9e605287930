// crane_chain.c: the crane as a chain (crane_chain.h): the two-link
// shorthand converted, the binding to the circuit, the mechanism built.
#include "crane_chain.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "chain_crane.h"
#include "hydraulics.h"

void crane_chain_free(crane_chain* cc) {
    if (!cc) return;
    free(cc->body);
    free(cc->act);
    free(cc->fn);
    free(cc->col);
    memset(cc, 0, sizeof *cc);
}

static int alloc_arrays(crane_chain* cc, int nbody, int nact, int nfn) {
    cc->body = calloc((size_t)(nbody > 0 ? nbody : 1), sizeof *cc->body);
    cc->act = calloc((size_t)(nact > 0 ? nact : 1), sizeof *cc->act);
    cc->fn = calloc((size_t)(nfn > 0 ? nfn : 1), sizeof *cc->fn);
    if (!cc->body || !cc->act || !cc->fn) {
        crane_chain_free(cc);
        return -1;
    }
    cc->nbody = nbody, cc->nact = nact, cc->nfn = nfn;
    return 0;
}

int crane_chain_copy(crane_chain* dst, const crane_chain* src) {
    crane_chain c = *src;
    if (alloc_arrays(&c, src->nbody, src->nact, src->nfn)) return -1;
    memcpy(c.body, src->body, (size_t)src->nbody * sizeof *c.body);
    memcpy(c.act, src->act, (size_t)src->nact * sizeof *c.act);
    memcpy(c.fn, src->fn, (size_t)src->nfn * sizeof *c.fn);
    c.col = NULL;
    c.ncol = 0;
    if (src->ncol > 0) {
        c.col = malloc((size_t)src->ncol * sizeof *c.col);
        if (!c.col) {
            crane_chain_free(&c);
            return -1;
        }
        memcpy(c.col, src->col, (size_t)src->ncol * sizeof *c.col);
        c.ncol = src->ncol;
    }
    *dst = c;
    return 0;
}

int crane_chain_from_mech(const crane_mech* m, crane_chain* out, char* err, size_t errsz) {
    memset(out, 0, sizeof *out);
    chain_crane cr;
    if (chain_from_crane_mech(m, 0.0, NULL, &cr)) {
        snprintf(err, errsz, "mechanics.actuators: each actuator's joint must be 0 or 1");
        return -1;
    }
    if (alloc_arrays(out, 3, 2, 2)) {
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    // The column's drawing: its height along z, a 0.2 m diameter (the
    // radius chain_from_crane_mech gives its inertia).
    out->body[0].def = cr.body[0];
    out->body[0].length = m->column_height;
    out->body[0].width = out->body[0].height = 0.2;
    for (int i = 0; i < 2; ++i) {
        crane_body* b = &out->body[i + 1];
        b->def = cr.body[i + 1];
        b->length = m->link[i].length;
        b->width = m->link[i].width;
        b->height = m->link[i].height;
    }
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &m->act[k];
        crane_act* c = &out->act[k];
        snprintf(c->name, sizeof c->name, "%s", a->name);
        snprintf(c->cylinder, sizeof c->cylinder, "%s", a->cylinder);
        snprintf(c->valve, sizeof c->valve, "%s", a->valve);
        c->kind = CRANE_ACT_CYLINDER;
        c->body_a = cr.cyl[k].body_a;
        c->body_b = cr.cyl[k].body_b;
        memcpy(c->pa, cr.cyl[k].pa, sizeof c->pa);
        memcpy(c->pb, cr.cyl[k].pb, sizeof c->pb);
        c->closed_length = a->closed_length;
        c->cyl = -1;
        c->function = k;
        crane_function* f = &out->fn[k];
        snprintf(f->name, sizeof f->name, "%s", a->name);
        snprintf(f->valve, sizeof f->valve, "%s", a->valve);
        f->valve_idx = -1;
    }
    out->tip_body = 2;
    out->tip[0] = m->link[1].length;
    out->gravity = m->gravity;
    out->slew_free = false;
    out->two_link = true;
    return 0;
}

int crane_chain_bind(crane_chain* cc, const hyd_model* h, char* err, size_t errsz) {
    for (int f = 0; f < cc->nfn; ++f) {
        crane_function* fn = &cc->fn[f];
        fn->valve_idx = hyd_model_valve(h, fn->valve);
        if (fn->valve_idx < 0) {
            snprintf(err, errsz, "mechanics.functions[%d].valve: no valve '%s' in the circuit", f, fn->valve);
            return -1;
        }
    }
    for (int k = 0; k < cc->nact; ++k) {
        crane_act* a = &cc->act[k];
        a->cyl = hyd_model_cylinder(h, a->cylinder);
        if (a->cyl < 0) {
            snprintf(err, errsz, "mechanics.actuators[%d].cylinder: no cylinder '%s' in the circuit", k,
                     a->cylinder);
            return -1;
        }
        double AA, AB;
        hyd_model_cylinder_geometry(h, a->cyl, &AA, &AB, &a->stroke);
        a->function = -1;
        for (int f = 0; f < cc->nfn; ++f)
            if (!strcmp(cc->fn[f].valve, a->valve)) a->function = f;
        if (a->function < 0) {
            snprintf(err, errsz,
                     "mechanics.actuators[%d].valve: no function commands valve '%s' (list it in "
                     "mechanics.functions)",
                     k, a->valve);
            return -1;
        }
    }
    if (crane_chain_columns(cc)) {
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    return 0;
}

// Body i's joint is a degree of freedom: the column's when it slews, any
// other's unless locked (as crane_chain_mechanism builds the mechanism).
static bool dof_joint(const crane_chain* cc, int i) { return i == 0 ? cc->slew_free : !cc->body[i].def.fixed; }

int crane_chain_ndof(const crane_chain* cc) {
    int n = 0;
    for (int i = 0; i < cc->nbody; ++i) n += dof_joint(cc, i);
    return n;
}

int crane_chain_dof_body(const crane_chain* cc, int k) {
    for (int i = 0; i < cc->nbody; ++i)
        if (dof_joint(cc, i) && k-- == 0) return i;
    return -1;
}

void crane_chain_start_pose(const crane_chain* cc, const double q12[2], double slew0, double* q0) {
    int d = 0, boom = 0;
    for (int i = 0; i < cc->nbody; ++i) {
        if (!dof_joint(cc, i)) continue;
        const chain_body_def* b = &cc->body[i].def;
        double q = i == 0 ? slew0 : boom < 2 ? q12[boom] : 0.0;
        // A DOF the scenario does not place: the middle of its joint
        // limits, or 0 when they are open.
        if (i > 0 && boom >= 2 && isfinite(b->q_min) && isfinite(b->q_max)) q = 0.5 * (b->q_min + b->q_max);
        else if (i > 0 && boom >= 2) q = fmin(fmax(q, b->q_min), b->q_max);
        if (i > 0) ++boom;
        q0[d++] = q;
    }
}

int crane_chain_columns(crane_chain* cc) {
    free(cc->col);
    cc->col = NULL;
    cc->ncol = 0;
    // The slew rack, where the column slews by its drive: an actuator and a
    // function named "slew" after the chain's (chain_sim.h).
    const bool rack = cc->slew_rack_columns && cc->slew_free && cc->slew.present;
    if (cc->two_link && !rack) return 0;
    // The two-link shorthand's base columns say everything but the slew's:
    // then only the rack, its function and the slew DOF.
    const int na = cc->two_link ? 0 : cc->nact, nf = cc->two_link ? 0 : cc->nfn;
    const int ndof = cc->two_link ? 1 : crane_chain_ndof(cc);
    const int n = 5 * (na + rack) + 2 * (nf + rack) + 2 * ndof;
    if (n == 0) return 0;
    crane_column* c = calloc((size_t)n, sizeof *c);
    if (!c) return -1;
    int k = 0;
    for (int a = 0; a < na + rack; ++a) {
        static const char* const what[5] = {"x", "v", "pA", "pB", "F"};
        static const char* const unit[5] = {"m", "m/s", "Pa", "Pa", "N"};
        for (int j = 0; j < 5; ++j, ++k) {
            snprintf(c[k].name, sizeof c[k].name, "%s_%s", what[j], a < na ? cc->act[a].name : "slew");
            c[k].unit = unit[j];
            c[k].pressure = j == 2 || j == 3;
        }
    }
    for (int f = 0; f < nf + rack; ++f)
        for (int j = 0; j < 2; ++j, ++k) {
            snprintf(c[k].name, sizeof c[k].name, "%s_%s", j ? "ucmd" : "u", f < nf ? cc->fn[f].name : "slew");
            c[k].unit = "-";
        }
    for (int d = 0; d < ndof; ++d) {
        const crane_body* b = &cc->body[crane_chain_dof_body(cc, d)];
        const bool slide = b->def.joint == CHAIN_PRISMATIC;
        for (int j = 0; j < 2; ++j, ++k) {
            snprintf(c[k].name, sizeof c[k].name, "%s_%s", j ? "qd" : "q", b->def.name);
            c[k].unit = j ? (slide ? "m/s" : "rad/s") : (slide ? "m" : "rad");
        }
    }
    cc->col = c;
    cc->ncol = n;
    return 0;
}

void crane_chain_row(const crane_chain* cc, const crane_chain_sample* s, double* out) {
    if (cc->ncol == 0) return;
    int k = 0;
    // As crane_chain_columns: the rack and its function (index nact, nfn of
    // the sample) after the chain's, and the two-link shorthand's only them.
    const bool rack = cc->slew_rack_columns && cc->slew_free && cc->slew.present;
    for (int a = cc->two_link ? cc->nact : 0; a < cc->nact + rack; ++a) {
        out[k++] = s->x[a];
        out[k++] = s->v[a];
        out[k++] = s->pA[a];
        out[k++] = s->pB[a];
        out[k++] = s->F[a];
    }
    for (int f = cc->two_link ? cc->nfn : 0; f < cc->nfn + rack; ++f) {
        out[k++] = s->u[f];
        out[k++] = s->ucmd[f];
    }
    const int ndof = cc->two_link ? 1 : crane_chain_ndof(cc);
    for (int d = 0; d < ndof; ++d) {
        out[k++] = s->q[d];
        out[k++] = s->qd[d];
    }
}

chain* crane_chain_mechanism(const crane_chain* cc, double tip_mass, bool slew_free, double slew, char* err,
                             size_t errsz) {
    return crane_chain_mechanism_links(cc, tip_mass, slew_free, slew, true, err, errsz);
}

double crane_act_length(const crane_act* a, const chain* ch, const chain_ws* w, double* Ldot, double* dL_dq,
                        double* dLdot_dq) {
    if (a->kind == CRANE_ACT_LINKAGE) return linkage_cylinder(&a->lk, ch, w, a->body_b, Ldot, dL_dq, dLdot_dq);
    return chain_cylinder(ch, w, a->body_a, a->pa, a->body_b, a->pb, Ldot, dL_dq, dLdot_dq);
}

void crane_act_hessian(const crane_act* a, const chain* ch, chain_ws* w, double* H) {
    if (a->kind == CRANE_ACT_LINKAGE) linkage_cylinder_hessian(&a->lk, ch, w, a->body_b, H);
    else chain_cylinder_hessian(ch, w, a->body_a, a->pa, a->body_b, a->pb, H);
}

chain* crane_chain_mechanism_links(const crane_chain* cc, double tip_mass, bool slew_free, double slew,
                                   bool lump_links, char* err, size_t errsz) {
    chain_body_def* defs = malloc((size_t)cc->nbody * sizeof *defs);
    if (!defs) {
        snprintf(err, errsz, "out of memory");
        return NULL;
    }
    for (int i = 0; i < cc->nbody; ++i) defs[i] = cc->body[i].def;
    defs[0].fixed = !slew_free;
    defs[0].q_fixed = slew;
    if (tip_mass > 0 && cc->tip_body >= 0 && cc->tip_body < cc->nbody)
        chain_body_add_point_mass(&defs[cc->tip_body], tip_mass, cc->tip);
    // The linkages' links: their masses at their pins (the analytic mode's
    // one DOF per joint; docs/mechanism.md bounds what that leaves out).
    for (int k = 0; k < cc->nact && lump_links; ++k)
        if (cc->act[k].kind == CRANE_ACT_LINKAGE)
            linkage_lump(&cc->act[k].lk, &defs[cc->act[k].body_a], &defs[cc->act[k].body_b]);
    const double g[3] = {0.0, 0.0, -cc->gravity};
    chain* c = chain_create(defs, cc->nbody, g, err, errsz);
    free(defs);
    return c;
}

int crane_chain_find_body(const crane_chain* cc, const char* name) {
    for (int i = 0; i < cc->nbody; ++i)
        if (!strcmp(cc->body[i].def.name, name)) return i;
    return -1;
}

int crane_chain_find_act(const crane_chain* cc, const char* name) {
    for (int i = 0; i < cc->nact; ++i)
        if (!strcmp(cc->act[i].name, name)) return i;
    return -1;
}

int crane_chain_find_function(const crane_chain* cc, const char* name) {
    for (int i = 0; i < cc->nfn; ++i)
        if (!strcmp(cc->fn[i].name, name)) return i;
    return -1;
}

int crane_chain_find_column(const crane_chain* cc, const char* what, const char* name) {
    const size_t lw = strlen(what);
    for (int c = 0; c < cc->ncol; ++c) {
        const char* n = cc->col[c].name;
        if (!strncmp(n, what, lw) && n[lw] == '_' && !strcmp(n + lw + 1, name)) return c;
    }
    return -1;
}
