// test_model_chain.c: the chain form of a model file (mechanics.bodies,
// docs/model.md "The chain form"): the default crane written as a chain
// gives the shorthand's chain field for field; the 3-boom and the 10-body
// test models load, bind and build their mechanism, and their cylinders
// cover their joint limits and hold the rated load (checked with the
// mechanism library, independently of the script that sized them); every
// bad file (one edit of a good one) is refused with one line naming the file
// and the field, in process and through `cranesim run --model` (exit 2); and
// every two-link consumer refuses a chain model instead of running the wrong
// crane.
#include "check.h"
#include "app/cli_util.h"
#include "app/fixture_edit.h"
#include "engine.h"
#include "loadchart.h"
#include "model.h"
#include "rcl.h"
#include "sim.h"

#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define DATA CRANESIM_TESTDATA
#define CHAIN_3BOOM DATA "/chain_3boom_ext.json"
#define CHAIN_8FN DATA "/chain_8fn_10link.json"
#define HIAB_CHAIN DATA "/hiab031_chain.json"

static model* load(const char* path) {
    char err[1024];
    model* m = model_load(path, NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s: %s", path, err);
    return m;
}

// Equal to 1e-12, or both the same infinity (unbounded limits).
static int same(double a, double b) { return a == b || fabs(a - b) <= 1e-12; }

// hiab031_chain.json is the default crane in the chain form: its chain is the
// one crane_chain_from_mech makes of the shorthand, every field.
static void test_hiab031_chain_equals_shorthand(void) {
    model* s = load(NULL);
    model* c = load(HIAB_CHAIN);
    if (!s || !c) goto out;
    const crane_chain *a = &s->chain, *b = &c->chain;
    CHECK(a->two_link && !b->two_link, "two_link: shorthand %d, chain file %d", a->two_link, b->two_link);
    CHECK(a->nbody == b->nbody && a->nact == b->nact && a->nfn == b->nfn, "counts %d %d %d vs %d %d %d", a->nbody,
          a->nact, a->nfn, b->nbody, b->nact, b->nfn);
    if (a->nbody != b->nbody || a->nact != b->nact || a->nfn != b->nfn) goto out;
    for (int i = 0; i < a->nbody; ++i) {
        const crane_body *x = &a->body[i], *y = &b->body[i];
        const chain_body_def *p = &x->def, *q = &y->def;
        CHECK(!strcmp(p->name, q->name) && p->parent == q->parent && p->joint == q->joint && p->fixed == q->fixed,
              "body %d: %s/%s parent %d/%d joint %d/%d fixed %d/%d", i, p->name, q->name, p->parent, q->parent,
              p->joint, q->joint, p->fixed, q->fixed);
        int ok = same(p->q_fixed, q->q_fixed) && same(p->angle0, q->angle0) && same(p->offset0, q->offset0) &&
                 same(p->mass, q->mass) && same(p->q_min, q->q_min) && same(p->q_max, q->q_max) &&
                 same(x->length, y->length) && same(x->width, y->width) && same(x->height, y->height);
        for (int k = 0; k < 3; ++k) ok = ok && same(p->origin[k], q->origin[k]) && same(p->com[k], q->com[k]);
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) ok = ok && same(p->inertia[r][k], q->inertia[r][k]);
        CHECK(ok, "body %d (%s): a numeric field differs (origin z %.17g/%.17g, angle0 %.17g/%.17g, Iyy %.17g/%.17g)",
              i, p->name, p->origin[2], q->origin[2], p->angle0, q->angle0, p->inertia[1][1], q->inertia[1][1]);
    }
    for (int k = 0; k < a->nact; ++k) {
        const crane_act *x = &a->act[k], *y = &b->act[k];
        int ok = !strcmp(x->name, y->name) && !strcmp(x->cylinder, y->cylinder) && !strcmp(x->valve, y->valve) &&
                 x->kind == y->kind && x->body_a == y->body_a && x->body_b == y->body_b && x->cyl == y->cyl &&
                 x->function == y->function && same(x->closed_length, y->closed_length) && same(x->stroke, y->stroke);
        for (int j = 0; j < 3; ++j) ok = ok && same(x->pa[j], y->pa[j]) && same(x->pb[j], y->pb[j]);
        CHECK(ok, "actuator %d (%s): differs (pa %.17g %.17g, pb %.17g %.17g / pa %.17g %.17g, pb %.17g %.17g)", k,
              x->name, x->pa[0], x->pa[2], x->pb[0], x->pb[2], y->pa[0], y->pa[2], y->pb[0], y->pb[2]);
    }
    for (int f = 0; f < a->nfn; ++f)
        CHECK(!strcmp(a->fn[f].name, b->fn[f].name) && !strcmp(a->fn[f].valve, b->fn[f].valve) &&
                  a->fn[f].valve_idx == b->fn[f].valve_idx,
              "function %d: %s %s %d / %s %s %d", f, a->fn[f].name, a->fn[f].valve, a->fn[f].valve_idx,
              b->fn[f].name, b->fn[f].valve, b->fn[f].valve_idx);
    CHECK(a->tip_body == b->tip_body && same(a->tip[0], b->tip[0]) && same(a->tip[1], b->tip[1]) &&
              same(a->tip[2], b->tip[2]) && same(a->gravity, b->gravity) && a->slew_free == b->slew_free,
          "tip %d (%g %g %g) / %d (%g %g %g), gravity %g / %g", a->tip_body, a->tip[0], a->tip[1], a->tip[2],
          b->tip_body, b->tip[0], b->tip[1], b->tip[2], a->gravity, b->gravity);
    // The slew drive (mechanics.slew), read alike by both forms.
    const crane_slew *sa = &a->slew, *sb = &b->slew;
    CHECK(sa->present && sb->present && !strcmp(sa->cylinder, sb->cylinder) && !strcmp(sa->valve, sb->valve) &&
              same(sa->pinion_radius, sb->pinion_radius) && same(sa->column_radius, sb->column_radius) &&
              same(sa->damping, sb->damping),
          "slew drive: %d %s %s %g / %d %s %s %g", sa->present, sa->cylinder, sa->valve, sa->pinion_radius,
          sb->present, sb->cylinder, sb->valve, sb->pinion_radius);
    CHECK(s->mech.load_mass == c->mech.load_mass && s->mech.rated_moment == c->mech.rated_moment &&
              s->mech.rated_load == c->mech.rated_load && s->mech.column_height == c->mech.column_height &&
              s->mech.column_mass == c->mech.column_mass,
          "the scalars every model has differ");
out:
    model_free(s);
    model_free(c);
}

typedef struct expect {
    const char* file;
    int nbody, nact, nfn, nprismatic;
    const char* bodies[12];
    const char* functions[10];
} expect;

static const expect k_models[] = {
    {CHAIN_3BOOM, 5, 4, 4, 1, {"column", "lifting_arm", "end_arm", "jib2", "ext"}, {"lift", "jib", "jib2", "ext"}},
    {CHAIN_8FN,
     10,
     9,
     8,
     6,
     {"column", "lifting_arm", "end_arm", "ext1", "ext2", "ext3", "jib", "jib_ext1", "jib_ext2", "jib_ext3"},
     // Left to the default: one per valve, named after its first actuator
     // (ext1 and ext2 share ext1_valve).
     {"lift", "fold", "ext1", "ext3", "jib", "jib_ext1", "jib_ext2", "jib_ext3"}},
};

// Counts, names, binding to the circuit, the mechanism.
static void test_models_load(void) {
    for (size_t t = 0; t < sizeof k_models / sizeof k_models[0]; ++t) {
        const expect* e = &k_models[t];
        model* m = load(e->file);
        if (!m) continue;
        const crane_chain* cc = &m->chain;
        CHECK(!cc->two_link && !cc->slew_free, "%s: two_link %d slew_free %d", e->file, cc->two_link, cc->slew_free);
        CHECK(cc->nbody == e->nbody && cc->nact == e->nact && cc->nfn == e->nfn, "%s: %d bodies %d actuators %d functions",
              e->file, cc->nbody, cc->nact, cc->nfn);
        if (cc->nbody != e->nbody || cc->nfn != e->nfn) {
            model_free(m);
            continue;
        }
        int npris = 0;
        for (int i = 0; i < cc->nbody; ++i) {
            CHECK(!strcmp(cc->body[i].def.name, e->bodies[i]), "%s: body %d is %s, want %s", e->file, i,
                  cc->body[i].def.name, e->bodies[i]);
            CHECK(i == 0 ? cc->body[i].def.parent == -1 : cc->body[i].def.parent >= 0 && cc->body[i].def.parent < i,
                  "%s: body %d parent %d", e->file, i, cc->body[i].def.parent);
            npris += cc->body[i].def.joint == CHAIN_PRISMATIC;
        }
        CHECK(npris == e->nprismatic, "%s: %d prismatic joints, want %d", e->file, npris, e->nprismatic);
        for (int f = 0; f < cc->nfn; ++f) {
            CHECK(!strcmp(cc->fn[f].name, e->functions[f]), "%s: function %d is %s, want %s", e->file, f,
                  cc->fn[f].name, e->functions[f]);
            CHECK(cc->fn[f].valve_idx >= 0 && cc->fn[f].valve_idx == hyd_model_valve(m->hyd, cc->fn[f].valve),
                  "%s: function %s: valve %s bound to %d", e->file, cc->fn[f].name, cc->fn[f].valve,
                  cc->fn[f].valve_idx);
        }
        for (int k = 0; k < cc->nact; ++k) {
            const crane_act* a = &cc->act[k];
            double AA, AB, st;
            CHECK(a->cyl >= 0 && a->cyl == hyd_model_cylinder(m->hyd, a->cylinder), "%s: %s: cylinder %s bound to %d",
                  e->file, a->name, a->cylinder, a->cyl);
            if (a->cyl < 0) continue;
            hyd_model_cylinder_geometry(m->hyd, a->cyl, &AA, &AB, &st);
            CHECK(a->stroke == st && st > 0, "%s: %s: stroke %g, circuit %g", e->file, a->name, a->stroke, st);
            CHECK(a->function >= 0 && a->function < cc->nfn && !strcmp(cc->fn[a->function].valve, a->valve),
                  "%s: %s: function %d", e->file, a->name, a->function);
        }
        // Every cylinder and valve of the circuit is some actuator's or function's.
        CHECK(hyd_model_ncylinder(m->hyd) == cc->nact && hyd_model_nvalve(m->hyd) == cc->nfn,
              "%s: circuit has %d cylinders, %d valves", e->file, hyd_model_ncylinder(m->hyd), hyd_model_nvalve(m->hyd));
        char err[512];
        chain* ch = crane_chain_mechanism(cc, m->mech.load_mass, false, 0.0, err, sizeof err);
        CHECK(ch && chain_nbody(ch) == cc->nbody && chain_ndof(ch) == cc->nbody - 1, "%s: mechanism: %s", e->file,
              ch ? "wrong size" : err);
        chain_free(ch);
        ch = crane_chain_mechanism(cc, 0.0, true, 0.0, err, sizeof err);
        CHECK(ch && chain_ndof(ch) == cc->nbody, "%s: slewing mechanism: %s", e->file, ch ? "wrong size" : err);
        chain_free(ch);
        model_free(m);
    }
}

// The body whose joint actuator a spans (a parent-child pair), or -1.
static int spanned(const crane_chain* cc, const crane_act* a) {
    if (cc->body[a->body_b].def.parent == a->body_a) return a->body_b;
    if (cc->body[a->body_a].def.parent == a->body_b) return a->body_a;
    return -1;
}

// The test models' cylinders: at both limits of its joint each cylinder is
// within its stroke (it covers the joint range), and over a grid of poses
// within all limits, with the rated load at the tip, the static force it
// must hold, G_j / (dL/dq_j) from the mechanism's gravity terms (RNEA),
// needs at most the pump's setting on the weaker (rod) side. The script
// sized them with its own kinematics; this is the mechanism library's view.
static void test_cylinders_cover_and_hold(void) {
    const char* files[] = {CHAIN_3BOOM, CHAIN_8FN};
    for (int t = 0; t < 2; ++t) {
        model* m = load(files[t]);
        if (!m) continue;
        const crane_chain* cc = &m->chain;
        char err[512];
        chain* ch = crane_chain_mechanism(cc, m->mech.load_mass, false, 0.0, err, sizeof err);
        CHECK(ch != NULL, "%s", err);
        if (!ch) {
            model_free(m);
            continue;
        }
        double p_set = 0;
        CHECK(hyd_model_get(m->hyd, "pump.p_set", &p_set) == 0 && p_set > 0, "pump.p_set");
        const int n = chain_ndof(ch);
        chain_ws* w = chain_ws_create(ch);
        double *q = calloc((size_t)n, sizeof *q), *G = calloc((size_t)n, sizeof *G), *dL = calloc((size_t)n, sizeof *dL);
        // Poses: each joint at its lower limit, middle or upper limit, cycled
        // over 3^min(n, 6) combinations (all of them for the 3-boom crane).
        const int nd = n < 6 ? n : 6;
        int combos = 1;
        for (int i = 0; i < nd; ++i) combos *= 3;
        double worst_ratio = 0;
        for (int c = 0; c < combos; ++c) {
            int code = c;
            for (int j = 0; j < n; ++j) {
                const chain_body_def* d = chain_body(ch, chain_dof_body(ch, j));
                const int level = j < nd ? code % 3 : (c + j) % 3;
                if (j < nd) code /= 3;
                q[j] = d->q_min + (d->q_max - d->q_min) * 0.5 * level;
            }
            chain_update(ch, w, q, NULL);
            chain_inverse_dynamics(ch, w, NULL, CHAIN_GRAVITY, G);
            for (int k = 0; k < cc->nact; ++k) {
                const crane_act* a = &cc->act[k];
                const int jb = spanned(cc, a), dof = jb >= 0 ? chain_body_dof(ch, jb) : -1;
                CHECK(dof >= 0, "%s: %s spans no single joint", files[t], a->name);
                if (dof < 0) continue;
                chain_cylinder(ch, w, a->body_a, a->pa, a->body_b, a->pb, NULL, dL, NULL);
                // Several cylinders on one joint would share its load; these
                // models have one each.
                double AA, AB, st;
                hyd_model_cylinder_geometry(m->hyd, a->cyl, &AA, &AB, &st);
                const double F = fabs(G[dof] / dL[dof]), cap = p_set * fmin(AA, AB);
                if (F / cap > worst_ratio) worst_ratio = F / cap;
                CHECK(F <= cap, "%s: %s holds %.1f kN, its rod side gives %.1f kN at %.0f MPa", files[t], a->name,
                      F / 1e3, cap / 1e3, p_set / 1e6);
            }
        }
        printf("  %s: worst holding force %.0f %% of the rod side at the pump setting\n", files[t], 100 * worst_ratio);
        // Each joint at its limits, the others anywhere: the pins within the stroke.
        memset(q, 0, (size_t)n * sizeof *q);
        for (int k = 0; k < cc->nact; ++k) {
            const crane_act* a = &cc->act[k];
            const int jb = spanned(cc, a), dof = jb >= 0 ? chain_body_dof(ch, jb) : -1;
            if (dof < 0) continue;
            const chain_body_def* d = chain_body(ch, jb);
            for (int end = 0; end < 2; ++end) {
                q[dof] = end ? d->q_max : d->q_min;
                chain_update(ch, w, q, NULL);
                const double L = chain_cylinder(ch, w, a->body_a, a->pa, a->body_b, a->pb, NULL, NULL, NULL);
                const double x = L - a->closed_length;
                CHECK(x >= 0 && x <= a->stroke, "%s: %s at %s's %s limit %g: stroke position %.4f m outside [0, %.4f]",
                      files[t], a->name, d->name, end ? "upper" : "lower", q[dof], x, a->stroke);
            }
            q[dof] = 0;
        }
        free(q), free(G), free(dL);
        chain_ws_free(w);
        chain_free(ch);
        model_free(m);
    }
}

// ---- bad files ---------------------------------------------------------------

typedef struct bad_case {
    const char* name;  ///< generated file name
    const char* base;  ///< good file it is made from
    const char* set;   ///< "path=value" (json_set_path), or NULL
    const char* from;  ///< text replaced (first occurrence), or NULL
    const char* to;
    const char* field; ///< must follow "<name>: " in the message
    const char* msg;   ///< must appear in the message
    const char* drop;  ///< instead of an edit: the line holding this text is deleted
} bad_case;

static const bad_case k_bad[] = {
    {"c_parent_missing.json", CHAIN_3BOOM, "mechanics.bodies.ext.parent=nowhere", NULL, NULL, "mechanics.bodies[4].parent",
     "no body \"nowhere\"", NULL},
    {"c_parent_self.json", CHAIN_3BOOM, "mechanics.bodies.ext.parent=ext", NULL, NULL, "mechanics.bodies[4].parent",
     "this body itself", NULL},
    {"c_parent_later.json", CHAIN_3BOOM, NULL, "\"name\": \"end_arm\", \"joint\": \"revolute\",",
     "\"name\": \"end_arm\", \"joint\": \"revolute\", \"parent\": \"jib2\",", "mechanics.bodies[2].parent",
     "comes after this one", NULL},
    {"c_joint_unknown.json", CHAIN_3BOOM, "mechanics.bodies.jib2.joint=hinge", NULL, NULL, "mechanics.bodies[3].joint",
     "unknown joint type \"hinge\"", NULL},
    {"c_joint_slew_boom.json", CHAIN_3BOOM, "mechanics.bodies.jib2.joint=slew", NULL, NULL, "mechanics.bodies[3].joint",
     "only body 0", NULL},
    {"c_column_not_slew.json", CHAIN_3BOOM, "mechanics.bodies.column.joint=revolute", NULL, NULL,
     "mechanics.bodies[0].joint", "must be \"slew\"", NULL},
    {"c_cylinder_missing.json", CHAIN_3BOOM, "mechanics.actuators.jib2.cylinder=nope_cyl", NULL, NULL,
     "mechanics.actuators[2].cylinder", "no cylinder named \"nope_cyl\"", NULL},
    {"c_valve_missing.json", CHAIN_8FN, "mechanics.actuators.jib.valve=nope_valve", NULL, NULL,
     "mechanics.actuators[5].valve", "no valve named \"nope_valve\"", NULL},
    {"c_fn_valve_missing.json", CHAIN_3BOOM, "mechanics.functions.jib2.valve=nope_valve", NULL, NULL,
     "mechanics.actuators[2].valve", "no function commands valve \"jib2_valve\"", NULL},
    {"c_prismatic_negative.json", CHAIN_3BOOM, "mechanics.bodies.ext.limits=[1.0,0.0]", NULL, NULL,
     "mechanics.bodies[4].limits", "must not be negative", NULL},
    {"c_prismatic_no_limits.json", CHAIN_3BOOM, NULL, ", \"limits\": [0.0, 1.0]}", "}", "mechanics.bodies[4].limits",
     "missing", NULL},
    {"c_mount_far.json", CHAIN_3BOOM, "mechanics.actuators.jib2.rod.point=[5,0,0]", NULL, NULL,
     "mechanics.actuators[2].rod.point", "outside its reach", NULL},
    {"c_com_far.json", CHAIN_3BOOM, "mechanics.bodies.jib2.com=[0,0,3]", NULL, NULL, "mechanics.bodies[3].com",
     "outside its reach", NULL},
    {"c_column_com_far.json", CHAIN_3BOOM, NULL, "\"radius\": 0.1}", "\"radius\": 0.1, \"com\": [0, 0, 2.5]}",
     "mechanics.bodies[0].com", "outside its reach of 1.7 m", NULL},
    {"c_tip_far.json", CHAIN_3BOOM, "mechanics.tip.point=[9,0,0]", NULL, NULL, "mechanics.tip.point",
     "outside its reach", NULL},
    {"c_act_body_missing.json", CHAIN_3BOOM, "mechanics.actuators.ext.rod.body=ghost", NULL, NULL,
     "mechanics.actuators[3].rod.body", "no body \"ghost\"", NULL},
    {"c_tip_body_missing.json", CHAIN_3BOOM, "mechanics.tip.body=ghost", NULL, NULL, "mechanics.tip.body",
     "no body \"ghost\"", NULL},
    {"c_act_one_body.json", CHAIN_3BOOM, "mechanics.actuators.jib2.rod.body=end_arm", NULL, NULL,
     "mechanics.actuators[2].rod.body", "two pins of one body", NULL},
    {"c_dup_body.json", CHAIN_3BOOM, "mechanics.bodies.jib2.name=end_arm", NULL, NULL, "mechanics.bodies[3].name",
     "already the name of bodies[2]", NULL},
    {"c_dup_actuator.json", CHAIN_3BOOM, "mechanics.actuators.jib2.name=jib", NULL, NULL,
     "mechanics.actuators[2].name", "already the name of actuators[1]", NULL},
    {"c_dup_function.json", CHAIN_3BOOM, "mechanics.functions.jib2.name=jib", NULL, NULL,
     "mechanics.functions[2].name", "already the name of functions[1]", NULL},
    {"c_dup_fn_valve.json", CHAIN_3BOOM, "mechanics.functions.jib2.valve=jib_valve", NULL, NULL,
     "mechanics.functions[2].valve", "also the valve of functions[1]", NULL},
    {"c_dup_cylinder.json", CHAIN_3BOOM, "mechanics.actuators.jib2.cylinder=jib_cyl", NULL, NULL,
     "mechanics.actuators[2].cylinder", "also the cylinder of actuators[1]", NULL},
    // The ext2 actuator's line deleted: its cylinder drives nothing.
    {"c_cylinder_unused.json", CHAIN_8FN, NULL, NULL, NULL, "hydraulics.components[",
     "cylinder \"ext2_cyl\" is driven by no actuator", "{\"name\": \"ext2\", \"cylinder\""},
    {"c_inertia_triangle.json", CHAIN_3BOOM, "mechanics.bodies.jib2.inertia=100", NULL, NULL,
     "mechanics.bodies[3] (jib2).inertia", "triangle inequality", NULL},
    {"c_inertia_asym.json", CHAIN_3BOOM, NULL, "\"inertia\": 30.2168", "\"inertia\": [[1, 0, 0.5], [0, 30, 0], [0, 0, 30]]",
     "mechanics.bodies[3] (jib2).inertia", "not symmetric", NULL},
    {"c_column_inertia_number.json", CHAIN_3BOOM, NULL, "\"radius\": 0.1}", "\"radius\": 0.1, \"inertia\": 50}",
     "mechanics.bodies[0].inertia", "3x3 tensor", NULL},
    {"c_stroke_unreachable.json", CHAIN_3BOOM, "mechanics.actuators.jib2.closed_length=3.0", NULL, NULL,
     "mechanics.actuators[2].closed_length", "reaches no pose within the limits", NULL},
    {"c_offset0_revolute.json", CHAIN_3BOOM, NULL, "\"name\": \"jib2\", \"joint\": \"revolute\",",
     "\"name\": \"jib2\", \"joint\": \"revolute\", \"offset0\": 0.1,", "mechanics.bodies[3].offset0",
     "unknown field", NULL},
    {"c_links_too.json", CHAIN_3BOOM, NULL, "\"load_mass\": 300.0,", "\"load_mass\": 300.0, \"links\": [],",
     "mechanics.links", "not both", NULL},
    {"c_one_body.json", CHAIN_3BOOM, "mechanics.bodies=[]", NULL, NULL, "mechanics.bodies", "at least one boom", NULL},
    {"c_mass_range.json", CHAIN_3BOOM, "mechanics.bodies.jib2.mass=0.001", NULL, NULL, "mechanics.bodies[3].mass",
     "must be in", NULL},
};

static const char* out_dir(void) {
    static char d[512];
    if (!d[0]) {
        snprintf(d, sizeof d, "%s/tests/world/model_chain", CRANESIM_BINARY_DIR);
        mkdir(d, 0755);
    }
    return d;
}

static void test_bad_files(void) {
    // The text replacements above must match the generated files' layout.
    for (size_t i = 0; i < sizeof k_bad / sizeof k_bad[0]; ++i) {
        const bad_case* k = &k_bad[i];
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", out_dir(), k->name);
        char line[2048] = "";
        const char *from = k->from, *to = k->to;
        if (k->drop) {
            // The whole line (with its newline) that holds the text.
            char* text = fixture_read_all(k->base);
            const char* at = text ? strstr(text, k->drop) : NULL;
            if (at) {
                const char* b = at;
                while (b > text && b[-1] != '\n') --b;
                const char* e = strchr(at, '\n');
                snprintf(line, sizeof line, "%.*s", (int)(e ? e - b + 1 : (long)strlen(b)), b);
            }
            free(text);
            from = line, to = "";
        }
        if (fixture_edit(k->base, path, k->set, from, to)) {
            CHECK(0, "%s: could not make the file", k->name);
            continue;
        }
        char want[512], err[2048] = "";
        snprintf(want, sizeof want, "%s: %s", k->name, k->field);
        model* m = model_load(path, NULL, 0, err, sizeof err);
        CHECK(m == NULL, "%s: loaded", k->name);
        model_free(m);
        CHECK(strstr(err, want) == err && strstr(err, k->msg) && !strchr(err, '\n'),
              "%s: message '%s' (want it to start with '%s' and say '%s')", k->name, err, want, k->msg);
        // The same through the command line: exit 2, the message on one line.
        char args[2600], out[8192];
        snprintf(args, sizeof args, "run --model %s --out %s/never.csv", path, out_dir());
        const int rc = cli_run(args, out, sizeof out);
        CHECK(rc == 2 && strstr(out, want) && strstr(out, k->msg), "%s: cranesim run exit %d: %s", k->name, rc, out);
    }
}

// The loader's stroke check against the mechanism library: for a revolute
// (jib2) and a prismatic (ext) actuator, the pin length range over the
// joint's limits from chain_cylinder; a closed length 2 mm past either end of
// what the cylinder can reach is refused, 2 mm inside it loads.
static void test_stroke_check_edges(void) {
    model* m = load(CHAIN_3BOOM);
    if (!m) return;
    char err[1024];
    chain* ch = crane_chain_mechanism(&m->chain, 0.0, false, 0.0, err, sizeof err);
    chain_ws* w = ch ? chain_ws_create(ch) : NULL;
    CHECK(ch && w, "%s", err);
    const char* names[] = {"jib2", "ext"};
    for (int t = 0; t < 2 && w; ++t) {
        const crane_act* a = &m->chain.act[crane_chain_find_act(&m->chain, names[t])];
        const int jb = a->body_b, dof = chain_body_dof(ch, jb);
        const chain_body_def* d = chain_body(ch, jb);
        double q[16] = {0}, Lmin = INFINITY, Lmax = -INFINITY;
        for (int s = 0; s <= 4000; ++s) {
            q[dof] = d->q_min + (d->q_max - d->q_min) * s / 4000.0;
            chain_update(ch, w, q, NULL);
            const double L = chain_cylinder(ch, w, a->body_a, a->pa, a->body_b, a->pb, NULL, NULL, NULL);
            Lmin = fmin(Lmin, L), Lmax = fmax(Lmax, L);
        }
        // closed > Lmax: never reached; closed + stroke < Lmin: never reached.
        const double cl[4] = {Lmax + 0.002, Lmax - 0.002, Lmin - a->stroke - 0.002, Lmin - a->stroke + 0.002};
        for (int k = 0; k < 4; ++k) {
            char set[128], path[1024], name[64];
            snprintf(set, sizeof set, "mechanics.actuators.%s.closed_length=%.6f", names[t], cl[k]);
            snprintf(name, sizeof name, "c_edge_%s_%d.json", names[t], k);
            snprintf(path, sizeof path, "%s/%s", out_dir(), name);
            if (fixture_edit(CHAIN_3BOOM, path, set, NULL, NULL)) {
                CHECK(0, "%s: could not make the file", name);
                continue;
            }
            err[0] = 0;
            model* e = model_load(path, NULL, 0, err, sizeof err);
            const int refused = e == NULL;
            model_free(e);
            CHECK(refused == (k % 2 == 0) && (!refused || strstr(err, "reaches no pose")),
                  "%s: %s: %s (pins %.4f..%.4f m, stroke %.4f m)", names[t], set, refused ? err : "loaded", Lmin, Lmax,
                  a->stroke);
        }
    }
    chain_ws_free(w);
    chain_free(ch);
    model_free(m);
}

// No fixed maximum: a chain of 1 + N bodies, each boom driven by its own
// cylinder and valve section (N functions), built in memory, loads, binds
// and builds its mechanism; --set reaches its bodies by name.
static void test_large_chain(void) {
    enum { N = 120 };
    size_t cap = 4096 + (size_t)N * 900, n = 0;
    char* t = malloc(cap);
    if (!t) return;
#define PUT(...) (n += (size_t)snprintf(t + n, cap - n, __VA_ARGS__))
    PUT("{\"name\": \"big\", \"mechanics\": {\"load_mass\": 10, \"bodies\": [");
    PUT("{\"name\": \"column\", \"joint\": \"slew\", \"height\": 1.6, \"mass\": 250}");
    for (int i = 1; i <= N; ++i)
        PUT(", {\"name\": \"b%d\", \"joint\": \"revolute\", \"origin\": %s, \"length\": 1.0, \"mass\": 20, "
            "\"com\": [0.5, 0, 0], \"inertia\": 1.76, \"limits\": [-0.5, 0.5]}",
            i, i == 1 ? "[0, 0, 1.6]" : "[1.0, 0, 0]");
    PUT("], \"actuators\": [");
    for (int i = 1; i <= N; ++i)
        PUT("%s{\"name\": \"a%d\", \"cylinder\": \"c%d\", \"valve\": \"v%d\", \"base\": {\"body\": \"%s%.0d\", "
            "\"point\": %s}, \"rod\": {\"body\": \"b%d\", \"point\": [0.2, 0, 0.12]}, \"closed_length\": 0.5}",
            i > 1 ? ", " : "", i, i, i, i == 1 ? "column" : "b", i == 1 ? 0 : i - 1,
            i == 1 ? "[0.2, 0, 1.2]" : "[0.5, 0, 0.12]", i);
    PUT("]}, \"hydraulics\": {\"nodes\": [{\"name\": \"tank\", \"type\": \"tank\", \"pressure\": 100000}, "
        "{\"name\": \"pump_line\", \"type\": \"volume\", \"volume\": 0.001, \"p0\": 2e7}], \"components\": ["
        "{\"name\": \"pump\", \"type\": \"pump\", \"inlet\": \"tank\", \"outlet\": \"pump_line\", \"q_max\": 0.0006, "
        "\"p_set\": 2e7, \"band\": 500000}, {\"name\": \"main_relief\", \"type\": \"relief\", \"inlet\": \"pump_line\", "
        "\"outlet\": \"tank\", \"p_crack\": 2.2e7, \"dp_override\": 1e6, \"q_rated\": 0.0007}");
    for (int i = 1; i <= N; ++i)
        PUT(", {\"name\": \"v%d\", \"type\": \"valve\", \"P\": \"pump_line\", \"T\": \"tank\", \"A\": \"h%dA\", "
            "\"B\": \"h%dB\", \"q_nominal\": 0.0006, \"dp_nominal\": 1e6}, {\"name\": \"h%dA\", \"type\": \"hose\", "
            "\"to\": \"c%d.A\", \"length\": 2, \"diameter\": 0.0127}, {\"name\": \"h%dB\", \"type\": \"hose\", "
            "\"to\": \"c%d.B\", \"length\": 2, \"diameter\": 0.0127}, {\"name\": \"c%d\", \"type\": \"cylinder\", "
            "\"bore\": 0.05, \"rod\": 0.03, \"stroke\": 0.4}",
            i, i, i, i, i, i, i, i);
    PUT("]}}");
#undef PUT
    CHECK(n < cap, "buffer");
    char err[1024] = "";
    cJSON* root = cJSON_Parse(t);
    free(t);
    CHECK(root != NULL, "the generated document does not parse");
    model* m = root ? model_from_json(root, "big.json", err, sizeof err) : NULL;
    CHECK(m && m->chain.nbody == N + 1 && m->chain.nact == N && m->chain.nfn == N, "%s", m ? "wrong counts" : err);
    if (m) {
        chain* ch = crane_chain_mechanism(&m->chain, m->mech.load_mass, false, 0.0, err, sizeof err);
        CHECK(ch && chain_ndof(ch) == N, "%s", ch ? "wrong size" : err);
        chain_free(ch);
        CHECK(!strcmp(m->chain.fn[N - 1].name, "a120") && m->chain.act[N - 1].body_a == N - 1 &&
                  m->chain.act[N - 1].body_b == N,
              "last function %s, last actuator on %d-%d", m->chain.fn[N - 1].name, m->chain.act[N - 1].body_a,
              m->chain.act[N - 1].body_b);
    }
    model_free(m);
    // --set by name on a chain file: a body's mass, an actuator's pin.
    // (Mass and moment together: with a moment about y alone, the other two
    // scale with the mass and a heavier boom soon breaks the triangle
    // inequality.)
    const char* sets[] = {"mechanics.bodies.jib2.mass=100", "mechanics.bodies.jib2.inertia=33.5",
                          "mechanics.actuators.ext.rod.point=[1.2,0,0.02]"};
    model* s = model_load(CHAIN_3BOOM, sets, 3, err, sizeof err);
    CHECK(s && s->chain.body[3].def.mass == 100 && s->chain.body[3].def.inertia[1][1] == 33.5 &&
              s->chain.act[3].pb[0] == 1.2,
          "%s", s ? "not applied" : err);
    model_free(s);
    // A cylinder between bodies further apart than parent and child (the
    // jib's barrel moved onto the column): loads, its pins where the file
    // puts them (its stroke range spans two joints and is not checked).
    const char* far[] = {"mechanics.actuators.jib.base.body=column", "mechanics.actuators.jib.base.point=[0.3,0,1.5]"};
    s = model_load(CHAIN_3BOOM, far, 2, err, sizeof err);
    CHECK(s && s->chain.act[1].body_a == 0 && s->chain.act[1].body_b == 2 && s->chain.act[1].pa[2] == 1.5, "%s",
          s ? "wrong pins" : err);
    model_free(s);
    const char* bad[] = {"mechanics.bodies.jib2.mass=-1"};
    s = model_load(CHAIN_3BOOM, bad, 1, err, sizeof err);
    CHECK(!s && strstr(err, "chain_3boom_ext.json: mechanics.bodies[3].mass:") &&
              strstr(err, "mechanics.bodies.jib2.mass=-1')"),
          "%s", s ? "loaded" : err);
    model_free(s);
}

// Every two-link consumer refuses a chain model with the one line, rather
// than read the empty two-link fields; the shorthand passes them all.
static void test_two_link_consumers_refuse(void) {
    model* m = load(CHAIN_3BOOM);
    model* d = load(NULL);
    if (!m || !d) goto out;
    char err[1024] = "";
    const char* line = "chain_3boom_ext.json: a chain of 5 bodies and 4 functions; the ";
    CHECK(model_require_two_link(d, "x", err, sizeof err) == 0, "the default crane refused: %s", err);
    // The two-link fields of a chain model are poison, not zeros.
    CHECK(isnan(m->mech.link[0].length) && isnan(m->mech.link[1].mass) && isnan(m->mech.act[1].closed_length) &&
              isnan(m->stroke[0]) && m->cyl[0] == -1 && m->valve[1] == -1 && m->mech.load_mass == 300 &&
              m->mech.column_height == 1.6,
          "two-link fields of a chain model: link length %g, stroke %g, cyl %d", m->mech.link[0].length, m->stroke[0],
          m->cyl[0]);
    CHECK(model_require_two_link(m, "test path", err, sizeof err) == -1 && strstr(err, line) == err &&
              strstr(err, "test path handles the two-link crane (mechanics.links) only"),
          "%s", err);
    // The stepped engines of a chain model are the chain's
    // (engine_chain_step.c, engine_ode_chain_step.c): no two-link commands
    // or snapshot, a limiter by function (rcl_filter_fn), and a driver that
    // needs one asks first (engine_require): one line naming the file.
    const double q0[2] = {100 * M_PI / 180, -110 * M_PI / 180};
    for (int b = 0; b < 2; ++b) {
        sim_opts o = sim_default_opts();
        o.mechanics = b ? SIM_ODE : SIM_LAGRANGE;
        o.no_step_probe = true;
        err[0] = 0;
        engine* e = engine_create(m, &o, q0, 0.0, -1, err, sizeof err);
        CHECK(e != NULL && !(engine_caps(e) & (ENGINE_CAP_TWO_LINK | ENGINE_CAP_SNAPSHOT)) &&
                  (engine_caps(e) & ENGINE_CAP_LIMITER),
              "engine_create (%s): %s", b ? "ode" : "lagrange", err);
        if (e) engine_destroy(e);
        CHECK(engine_require(m, &o, ENGINE_CAP_SNAPSHOT, "drive window", err, sizeof err) == -1 &&
                  strstr(err, "drive window: ") == err && strstr(err, "chain_3boom_ext.json") &&
                  strstr(err, "picture for the renderer") && !strchr(err, '\n'),
              "%s", err);
        CHECK(engine_require(d, &o, ENGINE_CAP_SNAPSHOT | ENGINE_CAP_TWO_LINK | ENGINE_CAP_LIMITER, "x", err,
                             sizeof err) == 0,
              "the default crane: %s", err);
    }
    // The chart and the limiter on a chain (docs/safety.md "On a crane
    // chain"): what they cannot read is refused in one line. This chain
    // has no rating (the limiter needs one); the ten-link chain's search
    // over every joint would be too large.
    lc_truck t = {0};
    lc_opts lo = lc_default_opts();
    lo.lo = 1.0, lo.hi = 2.0, lo.n = 3;
    static loadchart ch;
    rcl r;
    err[0] = 0;
    CHECK(rcl_init(&r, m, NULL, err, sizeof err) == -1 && strstr(err, "chain_3boom_ext.json: rated capacity limiter: "
                                                                      "mechanics.rated_moment") == err,
          "%s", err);
    model* m8 = load(CHAIN_8FN);
    if (m8) {
        err[0] = 0;
        CHECK(loadchart_compute(m8, &t, &lo, &ch, err, sizeof err) == -1 &&
                  strstr(err, "chain_8fn_10link.json: load chart: the search over every joint") && !strchr(err, '\n'),
              "%s", err);
        m8->mech.rated_moment = 10;
        err[0] = 0;
        CHECK(rcl_init(&r, m8, NULL, err, sizeof err) == -1 && strstr(err, "rated capacity limiter: its chart would "
                                                                          "search"),
              "%s", err);
        model_free(m8);
    }
    // The command line: the valid chain model runs (test_ode_engine_chain),
    // in the sandbox too (test_ode_sandbox_chain), but not from a start that
    // puts its tip in the ground (the default scenario's q1 = 100 deg,
    // q2 = -110 deg with jib2 at mid-range): exit 2, one line.
    char args[1600], out[4096];
    snprintf(args, sizeof args, "run --model %s --mechanics ode --world sandbox --out %s/never.csv", CHAIN_3BOOM,
             out_dir());
    const int rc = cli_run(args, out, sizeof out);
    // (The scenario's load_mass note comes first, on its own line.)
    const char* ref = strstr(out, "cranesim run: initial pose q1 = 100.0 deg, q2 = -110.0 deg leaves no room for the "
                                  "rope and hook");
    CHECK(rc == 2 && ref && cli_count_lines(ref) == 1, "cranesim run: exit %d: %s", rc, out);
    snprintf(args, sizeof args, "loadchart --model %s --out %s/never.csv", CHAIN_8FN, out_dir());
    const int rc2 = cli_run(args, out, sizeof out);
    CHECK(rc2 == 2 && strstr(out, "chain_8fn_10link.json: load chart: the search over every joint of its 9 booms"),
          "cranesim loadchart: exit %d: %s", rc2, out);
out:
    model_free(m);
    model_free(d);
}

// A chain model's own output columns (crane_chain_columns): five per
// actuator, two per function, two per degree of freedom, named after them
// with their units; none for the two-link shorthand; crane_chain_row puts
// each value under its name.
static void test_chain_columns(void) {
    model* m = load(CHAIN_3BOOM);
    if (!m) return;
    const crane_chain* cc = &m->chain;
    const int ndof = crane_chain_ndof(cc);
    // The column is fixed: lifting arm, end arm, jib2 and the extension move.
    CHECK(ndof == 4 && crane_chain_dof_body(cc, 0) == 1 && crane_chain_dof_body(cc, 3) == 4, "ndof %d", ndof);
    CHECK(cc->ncol == 5 * 4 + 2 * 4 + 2 * 4, "%d columns", cc->ncol);
    static const struct {
        int k;
        const char *name, *unit;
        bool p;
    } want[] = {{0, "x_lift", "m", false},   {2, "pA_lift", "Pa", true},   {4, "F_lift", "N", false},
                {19, "F_ext", "N", false},   {20, "u_lift", "-", false},   {27, "ucmd_ext", "-", false},
                {28, "q_lifting_arm", "rad", false}, {33, "qd_jib2", "rad/s", false}, {34, "q_ext", "m", false},
                {35, "qd_ext", "m/s", false}};
    for (size_t i = 0; i < sizeof want / sizeof want[0] && cc->ncol == 36; ++i) {
        const crane_column* c = &cc->col[want[i].k];
        CHECK(!strcmp(c->name, want[i].name) && !strcmp(c->unit, want[i].unit) && c->pressure == want[i].p,
              "column %d: %s [%s] pressure %d, want %s [%s]", want[i].k, c->name, c->unit, c->pressure, want[i].name,
              want[i].unit);
    }
    // Each value lands under its name: value = 100 * group + index.
    double x[4], v[4], pA[4], pB[4], F[4], u[4], uc[4], q[4], qd[4], out[36];
    for (int i = 0; i < 4; ++i)
        x[i] = 100 + i, v[i] = 200 + i, pA[i] = 300 + i, pB[i] = 400 + i, F[i] = 500 + i, u[i] = 600 + i,
        uc[i] = 700 + i, q[i] = 800 + i, qd[i] = 900 + i;
    const crane_chain_sample smp = {x, v, pA, pB, F, u, uc, q, qd};
    crane_chain_row(cc, &smp, out);
    CHECK(out[0] == 100 && out[3] == 400 && out[19] == 503 && out[20] == 600 && out[27] == 703 && out[28] == 800 &&
              out[35] == 903,
          "row %g %g %g %g %g %g %g", out[0], out[3], out[19], out[20], out[27], out[28], out[35]);
    model_free(m);
    char err[512];
    model* h = model_load(NULL, NULL, 0, err, sizeof err);
    CHECK(h && h->chain.two_link && h->chain.ncol == 0, "the shorthand has %d chain columns", h ? h->chain.ncol : -1);
    model_free(h);
}

int main(int argc, char** argv) {
    RUN_TEST(test_hiab031_chain_equals_shorthand);
    RUN_TEST(test_models_load);
    RUN_TEST(test_cylinders_cover_and_hold);
    RUN_TEST(test_bad_files);
    RUN_TEST(test_stroke_check_edges);
    RUN_TEST(test_large_chain);
    RUN_TEST(test_two_link_consumers_refuse);
    RUN_TEST(test_chain_columns);
    TEST_MAIN_END();
}
