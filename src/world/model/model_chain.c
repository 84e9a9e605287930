// model_chain.c: the chain form of a model's mechanics (model_chain.h,
// docs/model.md "The chain form"): bodies, tip, actuators and functions read
// into model.chain, checked field by field, bound to the circuit.
#include "model_chain.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crane_chain.h"
#include "hydraulics.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

// Points in a body frame (origins, centres of mass, pins) [m]: a boom is at
// most 30 m (MODEL_R_LINK_LENGTH), a crane of this class rarely puts a point
// more than 10 m from the body's origin.
static const json_range R_POINT = {-30, 30, -10, 10, "m"};
// A body's constant angle in the boom plane [rad]: one turn either way.
static const json_range R_ANGLE0 = {-2 * M_PI, 2 * M_PI, -M_PI, M_PI, "rad"};
// A prismatic joint's slide at q = 0 [m].
static const json_range R_OFFSET0 = {-30, 30, -10, 10, "m"};
// The column's radius [m] (its inertia when the file gives none, its drawing).
static const json_range R_COLUMN_RADIUS = {0.01, 2, 0.05, 0.5, "m"};
// Joint limits [rad] or [m]: two turns, or a 30 m slide.
static const json_range R_LIMIT_REV = {-4 * M_PI, 4 * M_PI, -M_PI, M_PI, "rad"};
static const json_range R_LIMIT_PRIS = {-30, 30, -10, 10, "m"};
// Inertia tensor entries [kg m^2] (the diagonal's hard range is the link's).
static const json_range R_INERTIA_ENTRY = {-1e7, 1e7, -1e5, 1e5, "kg m^2"};

bool model_chain_form(const cJSON* mech) {
    return cJSON_IsObject(mech) && cJSON_GetObjectItemCaseSensitive(mech, "bodies") != NULL;
}

// The message of a layer that writes "field: problem" without the file
// (chain_create, crane_chain_bind), under the mechanics section.
static void fail_under_mechanics(json_ctx* c, const char* msg) {
    if (c->failed) return;
    c->failed = true;
    if (c->err && c->errsz) snprintf(c->err, c->errsz, "%s: mechanics.%s", c->file ? c->file : "(input)", msg);
}

// The reach of a body: the farthest a point on it may be from its origin
// [m]. A boom is a box of its length along x and its section: a pin or a
// centre of mass farther from the joint than the length plus half the
// section height is off the body (a bracket sticks out by less than that on
// every crane of this class). The column: its height plus its radius.
static double body_reach(const crane_body* b) { return b->length + 0.5 * b->height; }

static void check_reach(json_ctx* c, const char* field, const crane_chain* cc, int body, const double p[3],
                        const char* what) {
    if (c->failed) return;
    const crane_body* b = &cc->body[body];
    const double d = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), reach = body_reach(b);
    if (d > reach)
        json_fail(c, field,
                  "%s (%g, %g, %g) m is %.4g m from the origin of body '%s', outside its reach of %.4g m (%s %g m "
                  "plus half its %s %g m)",
                  what, p[0], p[1], p[2], d, b->def.name, reach, body ? "length" : "height", b->length,
                  body ? "section height" : "diameter", b->height);
}

// The index of the body named name in the file's bodies array, or -1.
static int file_body_index(const cJSON* bodies, const char* name) {
    int i = 0;
    const cJSON* o;
    cJSON_ArrayForEach(o, bodies) {
        const cJSON* n = cJSON_GetObjectItemCaseSensitive(o, "name");
        if (cJSON_IsString(n) && !strcmp(n->valuestring, name)) return i;
        ++i;
    }
    return -1;
}

// "inertia": a number (the moment about the centre of mass about an axis
// parallel to the joint axis y, the other two from the box section, as the
// two-link shorthand gives it) or a 3x3 tensor about the centre of mass in
// body axes [kg m^2]. Absent: returns 0 (the caller's default).
static int read_inertia(json_ctx* c, const cJSON* o, const char* p, crane_body* b, bool column) {
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, "inertia");
    if (!v) return 0;
    char f[160];
    json_path(f, sizeof f, p, "inertia");
    if (cJSON_IsNumber(v) && column) {
        // The moment about y alone names no column: it is no boom section.
        json_fail(c, f, "the column's inertia is a 3x3 tensor about its centre of mass [kg m^2] (or left out: a "
                        "solid cylinder of its height and radius)");
        return 0;
    }
    if (cJSON_IsNumber(v)) {
        const double Iyy = json_num_r(c, o, p, "inertia", true, 0, &MODEL_R_LINK_INERTIA);
        chain_inertia_section(b->def.mass, Iyy, b->length, b->width, b->height, b->def.inertia);
        return 1;
    }
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3) {
        json_fail(c, f, "must be a number (the moment about the joint axis y, kg m^2) or a 3x3 array (the tensor "
                        "about the centre of mass, kg m^2)");
        return 0;
    }
    for (int r = 0; r < 3 && !c->failed; ++r) {
        const cJSON* row = cJSON_GetArrayItem(v, r);
        char fr[176];
        json_path_index(fr, sizeof fr, f, r);
        if (!cJSON_IsArray(row) || cJSON_GetArraySize(row) != 3) {
            json_fail(c, fr, "must be an array of 3 numbers (a row of the 3x3 tensor, kg m^2)");
            return 0;
        }
        for (int k = 0; k < 3 && !c->failed; ++k) {
            const cJSON* e = cJSON_GetArrayItem(row, k);
            char fe[192];
            json_path_index(fe, sizeof fe, fr, k);
            if (!cJSON_IsNumber(e)) {
                json_fail(c, fe, "must be a number [kg m^2]");
                return 0;
            }
            b->def.inertia[r][k] = e->valuedouble;
            json_range_check(c, fe, e->valuedouble, r == k ? &MODEL_R_LINK_INERTIA : &R_INERTIA_ENTRY);
        }
    }
    return 1;
}

static void read_limits(json_ctx* c, const cJSON* o, const char* p, crane_body* b, bool required) {
    if (!required && !cJSON_GetObjectItemCaseSensitive(o, "limits")) return;
    const bool pris = b->def.joint == CHAIN_PRISMATIC;
    double lim[2] = {0, 0};
    json_vec_r(c, o, p, "limits", required, lim, 2, pris ? &R_LIMIT_PRIS : &R_LIMIT_REV);
    if (c->failed) return;
    if (lim[1] < lim[0]) {
        char f[160];
        json_path(f, sizeof f, p, "limits");
        json_fail(c, f, "the range must not be negative: limits[1] = %g %s is below limits[0] = %g %s", lim[1],
                  pris ? "m" : "rad", lim[0], pris ? "m" : "rad");
        return;
    }
    b->def.q_min = lim[0];
    b->def.q_max = lim[1];
}

static void read_body(json_ctx* c, const cJSON* bodies, int i, crane_chain* cc) {
    char p[64];
    json_path_index(p, sizeof p, "mechanics.bodies", i);
    const cJSON* o = cJSON_GetArrayItem(bodies, i);
    if (!cJSON_IsObject(o)) {
        json_fail(c, p, "must be an object");
        return;
    }
    crane_body* b = &cc->body[i];
    chain_body_def* d = &b->def;
    chain_body_init(d, i - 1);
    char f[160];
    json_str(c, o, p, "name", true, "", d->name, sizeof d->name);
    json_path(f, sizeof f, p, "name");
    if (!c->failed && !d->name[0]) json_fail(c, f, "must not be empty (actuators and the tip name their bodies)");
    for (int j = 0; j < i && !c->failed; ++j)
        if (!strcmp(cc->body[j].def.name, d->name))
            json_fail(c, f, "\"%s\" is already the name of bodies[%d]", d->name, j);
    char joint[32] = "";
    json_str(c, o, p, "joint", true, "", joint, sizeof joint);
    if (c->failed) return;
    json_path(f, sizeof f, p, "joint");
    if (i == 0) {
        // The column: the slew about the base z (fixed for now, slew_free false).
        if (strcmp(joint, "slew")) {
            json_fail(c, f, "body 0 is the column: its joint must be \"slew\", got \"%s\"", joint);
            return;
        }
        static const char* const keys[] = {"name", "joint", "origin", "height", "radius", "mass", "com",
                                           "inertia", "limits", NULL};
        json_only_keys(c, o, p, keys);
        json_vec_r(c, o, p, "origin", false, d->origin, 3, &R_POINT);
        b->length = json_num_r(c, o, p, "height", true, 0, &MODEL_R_COLUMN_HEIGHT);
        const double r = json_num_r(c, o, p, "radius", false, 0.1, &R_COLUMN_RADIUS);
        b->width = b->height = 2.0 * r;
        d->mass = json_num_r(c, o, p, "mass", true, 0, &MODEL_R_COLUMN_MASS);
        // Default: a solid cylinder, its centre of mass half way up (as the
        // two-link shorthand's column).
        d->com[2] = 0.5 * b->length;
        json_vec_r(c, o, p, "com", false, d->com, 3, &R_POINT);
        json_path(f, sizeof f, p, "com");
        check_reach(c, f, cc, 0, d->com, "the centre of mass");
        if (!c->failed && !read_inertia(c, o, p, b, true)) {
            memset(d->inertia, 0, sizeof d->inertia);
            d->inertia[0][0] = d->inertia[1][1] = d->mass * (3.0 * r * r + b->length * b->length) / 12.0;
            d->inertia[2][2] = 0.5 * d->mass * r * r;
        }
        d->fixed = 1; // slew_free false: the slew drive in the model is later work
        d->q_fixed = 0.0;
        read_limits(c, o, p, b, false);
        return;
    }
    if (!strcmp(joint, "revolute")) d->joint = CHAIN_REVOLUTE;
    else if (!strcmp(joint, "prismatic")) d->joint = CHAIN_PRISMATIC;
    else if (!strcmp(joint, "slew")) {
        json_fail(c, f, "only body 0, the column, slews; a boom's joint is \"revolute\" or \"prismatic\"");
        return;
    } else {
        json_fail(c, f, "unknown joint type \"%s\" (slew for body 0; revolute or prismatic)", joint);
        return;
    }
    const bool pris = d->joint == CHAIN_PRISMATIC;
    static const char* const rkeys[] = {"name", "joint", "parent", "origin", "angle0", "length", "width", "height",
                                        "mass", "com", "inertia", "limits", NULL};
    static const char* const pkeys[] = {"name",   "joint", "parent", "origin", "angle0",  "offset0", "length",
                                        "width", "height", "mass", "com", "inertia", "limits", NULL};
    json_only_keys(c, o, p, pris ? pkeys : rkeys);
    // The parent: by name, default the previous body; it must come first
    // (the mechanism's recursions run parent before child).
    char parent[CHAIN_NAME];
    json_str(c, o, p, "parent", false, cc->body[i - 1].def.name, parent, sizeof parent);
    if (c->failed) return;
    json_path(f, sizeof f, p, "parent");
    int pi = -1;
    for (int j = 0; j < i; ++j)
        if (!strcmp(cc->body[j].def.name, parent)) pi = j;
    if (pi < 0) {
        const int later = file_body_index(bodies, parent);
        if (later == i) json_fail(c, f, "\"%s\" is this body itself", parent);
        else if (later > i)
            json_fail(c, f, "\"%s\" is bodies[%d], which comes after this one: list every parent before its children",
                      parent, later);
        else json_fail(c, f, "no body \"%s\" in mechanics.bodies", parent);
        return;
    }
    d->parent = pi;
    json_vec_r(c, o, p, "origin", false, d->origin, 3, &R_POINT);
    d->angle0 = json_num_r(c, o, p, "angle0", false, 0, &R_ANGLE0);
    if (pris) d->offset0 = json_num_r(c, o, p, "offset0", false, 0, &R_OFFSET0);
    b->length = json_num_r(c, o, p, "length", true, 0, &MODEL_R_LINK_LENGTH);
    b->width = json_num_r(c, o, p, "width", false, 0.18, &MODEL_R_LINK_SECTION);
    b->height = json_num_r(c, o, p, "height", false, 0.24, &MODEL_R_LINK_SECTION);
    d->mass = json_num_r(c, o, p, "mass", true, 0, &MODEL_R_LINK_MASS);
    json_vec_r(c, o, p, "com", true, d->com, 3, &R_POINT);
    json_path(f, sizeof f, p, "com");
    check_reach(c, f, cc, i, d->com, "the centre of mass");
    if (!c->failed && !read_inertia(c, o, p, b, false)) {
        json_path(f, sizeof f, p, "inertia");
        json_fail(c, f, "missing (a number, the moment about the joint axis y, or a 3x3 tensor about the centre of "
                        "mass, kg m^2)");
    }
    // A revolute joint is unbounded unless the file bounds it; a slide must
    // be bounded (an extension has a stroke).
    read_limits(c, o, p, b, pris);
}

// {"body": name, "point": [x, y, z]}: the body's index and the point, checked
// against the body's reach.
static int read_pin(json_ctx* c, const cJSON* o, const char* p, const char* key, const crane_chain* cc,
                    double pt[3], const char* what) {
    const cJSON* pin = json_obj(c, o, p, key, true);
    if (c->failed) return -1;
    char pp[96], f[128];
    json_path(pp, sizeof pp, p, key);
    json_only_keys(c, pin, pp, (const char* const[]){"body", "point", NULL});
    char name[CHAIN_NAME];
    json_str(c, pin, pp, "body", true, "", name, sizeof name);
    if (c->failed) return -1;
    const int b = crane_chain_find_body(cc, name);
    json_path(f, sizeof f, pp, "body");
    if (b < 0) {
        json_fail(c, f, "no body \"%s\" in mechanics.bodies (the chain's bodies: %s ... %s)", name, cc->body[0].def.name,
                  cc->body[cc->nbody - 1].def.name);
        return -1;
    }
    json_vec_r(c, pin, pp, "point", true, pt, 3, &R_POINT);
    json_path(f, sizeof f, pp, "point");
    check_reach(c, f, cc, b, pt, what);
    return c->failed ? -1 : b;
}

// A linkage's link lengths [m]: a loader crane's links are 0.1..1 m; a few
// centimetres to 3 m is every sane drawing.
static const json_range R_LINK_LEN = {0.01, 5, 0.1, 1.5, "m"};
// The links' masses [kg]: > 0, as the ODE world makes them bodies (a link of
// a 10 t m crane weighs 5..50 kg).
static const json_range R_LINK_PART_MASS = {0.01, 1000, 1, 200, "kg"};

// "linkage": the knuckle cylinder's four-bar (linkage.h). The base pin is
// the actuator's base (B, on the knuckle's parent), the knuckle is "body"
// (its parent must be the base's body), link_pin A on the base's body,
// rocker_pin c on the knuckle, both [x, y, z] in their body's frame. The
// loop is planar in the boom plane y = 0: every y must be 0.
static void read_linkage(json_ctx* c, const cJSON* o, const char* p, crane_chain* cc, crane_act* a) {
    char pp[96], f[160];
    const cJSON* lo = json_obj(c, o, p, "linkage", true);
    if (c->failed) return;
    json_path(pp, sizeof pp, p, "linkage");
    static const char* const keys[] = {"body",      "link_pin",    "rocker_pin", "link_len",      "rocker_len", "branch",
                                       "link_mass", "rocker_mass", "common_pin", "common_pin_at", NULL};
    json_only_keys(c, lo, pp, keys);
    char name[CHAIN_NAME];
    json_str(c, lo, pp, "body", true, "", name, sizeof name);
    if (c->failed) return;
    const int kb = crane_chain_find_body(cc, name);
    json_path(f, sizeof f, pp, "body");
    if (kb < 0) {
        json_fail(c, f, "no body \"%s\" in mechanics.bodies (the knuckle the linkage turns)", name);
        return;
    }
    const chain_body_def* kd = &cc->body[kb].def;
    if (kb == 0 || kd->parent != a->body_a) {
        json_fail(c, f,
                  "\"%s\" is not a child of the base's body \"%s\": the linkage turns the joint between the base's "
                  "body and its child",
                  name, cc->body[a->body_a].def.name);
        return;
    }
    if (kd->joint != CHAIN_REVOLUTE) {
        json_fail(c, f, "\"%s\" slides (prismatic); a linkage turns a revolute joint", name);
        return;
    }
    if (kd->fixed) {
        json_fail(c, f, "\"%s\"'s joint is fixed; a linkage turns a moving joint", name);
        return;
    }
    if (!(isfinite(kd->q_min) && isfinite(kd->q_max))) {
        json_fail(c, f, "\"%s\"'s joint has no limits; a linkage needs the joint's range (limits, rad)", name);
        return;
    }
    a->body_b = kb;
    double A[3], C[3];
    json_vec_r(c, lo, pp, "link_pin", true, A, 3, &R_POINT);
    json_path(f, sizeof f, pp, "link_pin");
    check_reach(c, f, cc, a->body_a, A, "the link's pin");
    json_vec_r(c, lo, pp, "rocker_pin", true, C, 3, &R_POINT);
    json_path(f, sizeof f, pp, "rocker_pin");
    check_reach(c, f, cc, kb, C, "the rocker's pin");
    linkage_def d;
    memset(&d, 0, sizeof d);
    // The lengths and the branch, or (as a drawing gives them) the common
    // pin P in the base's body's frame at the knuckle angle common_pin_at.
    const bool drawn = cJSON_GetObjectItemCaseSensitive(lo, "common_pin") != NULL;
    double P[3] = {0, 0, 0}, q_ref = 0;
    if (drawn) {
        static const char* const lens[] = {"link_len", "rocker_len", "branch"};
        for (int i = 0; i < 3 && !c->failed; ++i)
            if (cJSON_GetObjectItemCaseSensitive(lo, lens[i])) {
                json_path(f, sizeof f, pp, lens[i]);
                json_fail(c, f, "given with common_pin; give the lengths and the branch or the common pin, not both");
            }
        json_vec_r(c, lo, pp, "common_pin", true, P, 3, &R_POINT);
        json_path(f, sizeof f, pp, "common_pin");
        check_reach(c, f, cc, a->body_a, P, "the common pin");
        q_ref = json_num_r(c, lo, pp, "common_pin_at", true, 0, &R_LIMIT_REV);
        json_path(f, sizeof f, pp, "common_pin_at");
        if (!c->failed && !(q_ref >= kd->q_min && q_ref <= kd->q_max))
            json_fail(c, f, "%g rad, outside %s's joint range [%g, %g] rad", q_ref, name, kd->q_min, kd->q_max);
    } else {
        d.link_len = json_num_r(c, lo, pp, "link_len", true, 0, &R_LINK_LEN);
        d.rocker_len = json_num_r(c, lo, pp, "rocker_len", true, 0, &R_LINK_LEN);
        d.branch = json_int(c, lo, pp, "branch", true, 0, -1, 1);
        json_path(f, sizeof f, pp, "branch");
        if (!c->failed && d.branch == 0)
            json_fail(c, f, "0; must be +1 or -1 (the side of link pin -> rocker pin the common pin is on)");
    }
    d.link_mass = json_num_r(c, lo, pp, "link_mass", true, 0, &R_LINK_PART_MASS);
    d.rocker_mass = json_num_r(c, lo, pp, "rocker_mass", true, 0, &R_LINK_PART_MASS);
    if (c->failed) return;
    // The plane: y = 0 for the base, both pins and the knuckle's joint.
    const struct {
        const char* field;
        double y;
    } ys[] = {{"base.point[1]", a->pa[1]},
              {"linkage.link_pin[1]", A[1]},
              {"linkage.rocker_pin[1]", C[1]},
              {"linkage.common_pin[1]", P[1]}};
    for (int i = 0; i < 4; ++i)
        if (ys[i].y != 0.0) {
            snprintf(f, sizeof f, "%s.%s", p, ys[i].field);
            json_fail(c, f, "%g m; a linkage works in the boom plane, y must be 0", ys[i].y);
            return;
        }
    if (kd->origin[1] != 0.0) {
        json_fail(c, pp, "the joint of \"%s\" is at y = %g m; a linkage works in the boom plane y = 0", name,
                  kd->origin[1]);
        return;
    }
    d.joint[0] = kd->origin[0], d.joint[1] = kd->origin[2];
    d.angle0 = kd->angle0;
    d.base[0] = a->pa[0], d.base[1] = a->pa[2];
    d.link_pin[0] = A[0], d.link_pin[1] = A[2];
    d.rocker_pin[0] = C[0], d.rocker_pin[1] = C[2];
    d.q_min = kd->q_min, d.q_max = kd->q_max;
    char e[320];
    if (drawn) {
        const double Pr[2] = {P[0], P[2]};
        json_path(f, sizeof f, pp, "common_pin");
        if (linkage_def_from_pose(&d, Pr, q_ref, e, sizeof e)) {
            const char* colon = strstr(e, ": ");
            json_fail(c, f, "%s", colon ? colon + 2 : e);
            return;
        }
        // The lengths it gives, in the range the lengths form takes.
        const double l[2] = {d.link_len, d.rocker_len};
        for (int i = 0; i < 2; ++i)
            if (!(l[i] >= R_LINK_LEN.lo && l[i] <= R_LINK_LEN.hi)) {
                json_fail(c, f, "gives a %s of %g m, outside [%g, %g] m", i ? "rocker_len" : "link_len", l[i],
                          R_LINK_LEN.lo, R_LINK_LEN.hi);
                return;
            }
    }
    if (linkage_init(&a->lk, &d, e, sizeof e)) {
        // linkage_init names its own fields ("linkage.x: ..."): its base is
        // the actuator's, its range the knuckle's limits.
        const char* colon = strstr(e, ": ");
        const char* msg = colon ? colon + 2 : e;
        char field[64] = "linkage";
        if (colon && !strncmp(e, "linkage.base: ", 14)) snprintf(field, sizeof field, "base");
        else if (colon && (size_t)(colon - e) < sizeof field) snprintf(field, sizeof field, "%.*s", (int)(colon - e), e);
        json_path(f, sizeof f, p, field);
        // The knuckle's range, unless the message gives it already.
        if (strstr(msg, "range")) json_fail(c, f, "%s (the joint of %s)", msg, name);
        else json_fail(c, f, "%s (%s's joint range [%g, %g] rad)", msg, name, kd->q_min, kd->q_max);
        return;
    }
    a->kind = CRANE_ACT_LINKAGE;
    a->pb[0] = a->pb[1] = a->pb[2] = 0.0;
}

static void read_actuator(json_ctx* c, const cJSON* acts, int k, crane_chain* cc) {
    char p[64], f[128];
    json_path_index(p, sizeof p, "mechanics.actuators", k);
    const cJSON* o = cJSON_GetArrayItem(acts, k);
    if (!cJSON_IsObject(o)) {
        json_fail(c, p, "must be an object");
        return;
    }
    static const char* const keys[] = {"name", "cylinder", "valve", "base", "rod", "linkage", "closed_length", NULL};
    json_only_keys(c, o, p, keys);
    crane_act* a = &cc->act[k];
    a->kind = CRANE_ACT_CYLINDER;
    a->cyl = a->function = -1;
    json_str(c, o, p, "name", true, "", a->name, sizeof a->name);
    json_path(f, sizeof f, p, "name");
    if (!c->failed && !a->name[0]) json_fail(c, f, "must not be empty");
    for (int j = 0; j < k && !c->failed; ++j)
        if (!strcmp(cc->act[j].name, a->name)) json_fail(c, f, "\"%s\" is already the name of actuators[%d]", a->name, j);
    json_str(c, o, p, "cylinder", true, "", a->cylinder, sizeof a->cylinder);
    json_str(c, o, p, "valve", true, "", a->valve, sizeof a->valve);
    a->body_a = read_pin(c, o, p, "base", cc, a->pa, "the barrel pin");
    // The rod: on a pin of a body, or on the common pin of a linkage (not both).
    const bool linked = cJSON_GetObjectItemCaseSensitive(o, "linkage") != NULL;
    if (!c->failed && linked && cJSON_GetObjectItemCaseSensitive(o, "rod")) {
        json_path(f, sizeof f, p, "rod");
        json_fail(c, f, "given with linkage; the rod of a cylinder through a linkage pushes the linkage's common pin");
    }
    if (linked) read_linkage(c, o, p, cc, a);
    else a->body_b = read_pin(c, o, p, "rod", cc, a->pb, "the rod pin");
    if (!c->failed && a->body_a == a->body_b) {
        json_path(f, sizeof f, p, "rod.body");
        json_fail(c, f, "\"%s\" is also the base's body: a cylinder between two pins of one body never moves",
                  cc->body[a->body_b].def.name);
    }
    a->closed_length = json_num_r(c, o, p, "closed_length", true, 0, &MODEL_R_CLOSED_LENGTH);
}

static void read_functions(json_ctx* c, const cJSON* mech, crane_chain* cc) {
    const cJSON* fns = json_arr(c, mech, "mechanics", "functions", false);
    if (c->failed) return;
    if (fns) {
        const int n = cJSON_GetArraySize(fns);
        if (n < 1) {
            json_fail(c, "mechanics.functions", "must list at least one function (or be left out: one per valve)");
            return;
        }
        cc->fn = calloc((size_t)n, sizeof *cc->fn);
        if (!cc->fn) {
            json_fail(c, "mechanics.functions", "out of memory for %d functions", n);
            return;
        }
        cc->nfn = n;
        for (int i = 0; i < n && !c->failed; ++i) {
            char p[64], f[128];
            json_path_index(p, sizeof p, "mechanics.functions", i);
            const cJSON* o = cJSON_GetArrayItem(fns, i);
            if (!cJSON_IsObject(o)) {
                json_fail(c, p, "must be an object");
                return;
            }
            json_only_keys(c, o, p, (const char* const[]){"name", "valve", NULL});
            crane_function* fn = &cc->fn[i];
            fn->valve_idx = -1;
            json_str(c, o, p, "name", true, "", fn->name, sizeof fn->name);
            json_path(f, sizeof f, p, "name");
            if (!c->failed && !fn->name[0]) json_fail(c, f, "must not be empty");
            for (int j = 0; j < i && !c->failed; ++j)
                if (!strcmp(cc->fn[j].name, fn->name))
                    json_fail(c, f, "\"%s\" is already the name of functions[%d]", fn->name, j);
            json_str(c, o, p, "valve", true, "", fn->valve, sizeof fn->valve);
            json_path(f, sizeof f, p, "valve");
            // One valve section, one function: an actuator finds its
            // function by its valve.
            for (int j = 0; j < i && !c->failed; ++j)
                if (!strcmp(cc->fn[j].valve, fn->valve))
                    json_fail(c, f, "\"%s\" is also the valve of functions[%d]; each function is its own valve section",
                              fn->valve, j);
        }
    } else {
        // One function per distinct valve, in the actuators' order, named
        // after the first actuator on it.
        cc->fn = calloc((size_t)cc->nact, sizeof *cc->fn);
        if (!cc->fn) {
            json_fail(c, "mechanics.actuators", "out of memory");
            return;
        }
        for (int k = 0; k < cc->nact; ++k) {
            bool seen = false;
            for (int f = 0; f < cc->nfn && !seen; ++f) seen = !strcmp(cc->fn[f].valve, cc->act[k].valve);
            if (seen) continue;
            crane_function* fn = &cc->fn[cc->nfn++];
            snprintf(fn->name, sizeof fn->name, "%s", cc->act[k].name);
            snprintf(fn->valve, sizeof fn->valve, "%s", cc->act[k].valve);
            fn->valve_idx = -1;
        }
    }
    for (int k = 0; k < cc->nact && !c->failed; ++k) {
        int f = -1;
        for (int j = 0; j < cc->nfn; ++j)
            if (!strcmp(cc->fn[j].valve, cc->act[k].valve)) f = j;
        char fld[96];
        snprintf(fld, sizeof fld, "mechanics.actuators[%d].valve", k);
        if (f < 0) json_fail(c, fld, "no function commands valve \"%s\" (list it in mechanics.functions)", cc->act[k].valve);
        cc->act[k].function = f;
    }
}

int model_chain_read(json_ctx* c, const cJSON* mech, model* m) {
    crane_chain* cc = &m->chain;
    memset(cc, 0, sizeof *cc);
    // One form or the other: links, column or by-joint actuators next to
    // bodies would be a second crane the loader silently ignores.
    static const char* const shorthand[] = {"links", "column", NULL};
    for (const char* const* s = shorthand; *s; ++s)
        if (cJSON_GetObjectItemCaseSensitive(mech, *s)) {
            char f[64];
            json_path(f, sizeof f, "mechanics", *s);
            json_fail(c, f, "the chain form (mechanics.bodies) has no %s: give bodies, or the two-link shorthand "
                            "(column, links, actuators by joint), not both", *s);
            return -1;
        }
    static const char* const keys[] = {"gravity", "load_mass", "rated_moment", "rated_load", "bodies",
                                       "tip",     "actuators", "functions",    "slew",       NULL};
    json_only_keys(c, mech, "mechanics", keys);
    crane_mech* me = &m->mech;
    me->gravity = json_num_r(c, mech, "mechanics", "gravity", false, 9.81, &MODEL_R_GRAVITY);
    me->load_mass = json_num_r(c, mech, "mechanics", "load_mass", true, 0, &MODEL_R_LOAD);
    me->rated_moment = json_num_r(c, mech, "mechanics", "rated_moment", false, 0, &MODEL_R_RATED_MOMENT);
    me->rated_load = json_num_r(c, mech, "mechanics", "rated_load", false, 0, &MODEL_R_RATED_LOAD);
    cc->gravity = me->gravity;
    const cJSON* bodies = json_arr(c, mech, "mechanics", "bodies", true);
    if (c->failed) return -1;
    const int nb = cJSON_GetArraySize(bodies);
    if (nb < 2) {
        json_fail(c, "mechanics.bodies", "a chain needs the column and at least one boom, got %d bodies", nb);
        return -1;
    }
    cc->body = calloc((size_t)nb, sizeof *cc->body);
    if (!cc->body) {
        json_fail(c, "mechanics.bodies", "out of memory for %d bodies", nb);
        return -1;
    }
    cc->nbody = nb;
    for (int i = 0; i < nb && !c->failed; ++i) read_body(c, bodies, i, cc);
    if (c->failed) return -1;
    me->column_height = cc->body[0].length;
    me->column_mass = cc->body[0].def.mass;

    // The tip (the hook point, where load_mass hangs): default the end of
    // the last body.
    const cJSON* tip = json_obj(c, mech, "mechanics", "tip", false);
    cc->tip_body = nb - 1;
    cc->tip[0] = cc->body[nb - 1].length;
    if (tip) {
        json_only_keys(c, tip, "mechanics.tip", (const char* const[]){"body", "point", NULL});
        char name[CHAIN_NAME];
        json_str(c, tip, "mechanics.tip", "body", true, "", name, sizeof name);
        if (c->failed) return -1;
        cc->tip_body = crane_chain_find_body(cc, name);
        if (cc->tip_body < 0) {
            json_fail(c, "mechanics.tip.body", "no body \"%s\" in mechanics.bodies", name);
            return -1;
        }
        json_vec_r(c, tip, "mechanics.tip", "point", true, cc->tip, 3, &R_POINT);
        check_reach(c, "mechanics.tip.point", cc, cc->tip_body, cc->tip, "the tip");
    }

    const cJSON* acts = json_arr(c, mech, "mechanics", "actuators", true);
    if (c->failed) return -1;
    const int na = cJSON_GetArraySize(acts);
    if (na < 1) {
        json_fail(c, "mechanics.actuators", "must list at least one actuator (a cylinder between two bodies)");
        return -1;
    }
    cc->act = calloc((size_t)na, sizeof *cc->act);
    if (!cc->act) {
        json_fail(c, "mechanics.actuators", "out of memory for %d actuators", na);
        return -1;
    }
    cc->nact = na;
    for (int k = 0; k < na && !c->failed; ++k) read_actuator(c, acts, k, cc);
    if (c->failed) return -1;
    read_functions(c, mech, cc);
    if (c->failed) return -1;
    cc->slew_free = false;
    cc->two_link = false;
    // The two-link fields are not this crane: nothing may read them for a
    // chain (model_require_two_link). Their geometry is NaN, so a path that
    // missed the gate computes NaN (which every run check refuses) rather
    // than a plausible answer for a crane of zero-length links.
    for (int k = 0; k < 2; ++k) {
        crane_link* l = &me->link[k];
        l->length = l->mass = l->com = l->inertia = l->width = l->height = NAN;
        crane_actuator* a = &me->act[k];
        a->joint = -1;
        a->base_mount[0] = a->base_mount[1] = a->rod_mount[0] = a->rod_mount[1] = NAN;
        a->closed_length = a->a = a->b = a->phi_offset = a->sin_offset = a->cos_offset = NAN;
        m->cyl[k] = m->valve[k] = -1;
        m->stroke[k] = NAN;
    }
    return 0;
}

// A point p of body `child` in its parent's frame at joint coordinate q
// (chain.h's joints, in the boom plane): revolute, the child's frame turned
// by angle0 + q about y (x towards z) at the joint origin; prismatic, turned
// by angle0 and slid by offset0 + q along its own x.
static void child_to_parent(const chain_body_def* d, double q, const double p[3], double out[3]) {
    const bool pris = d->joint == CHAIN_PRISMATIC;
    const double th = d->angle0 + (pris ? 0.0 : q), c = cos(th), s = sin(th);
    const double x = p[0] + (pris ? d->offset0 + q : 0.0);
    out[0] = d->origin[0] + c * x - s * p[2];
    out[1] = d->origin[1] + p[1];
    out[2] = d->origin[2] + s * x + c * p[2];
}

// The pin length range [m] of actuator a over the limits of the one joint it
// spans (its two bodies are parent and child): the length depends on that
// joint only, so it is evaluated in the parent's frame, O(1) a sample (a
// file of thousands of bodies and actuators checks in linear time). Returns
// 0, or -1 when the actuator spans more than one joint (not checked: a
// multi-joint range is no cheap interval).
static int pin_range(const crane_chain* cc, const crane_act* a, double* Lmin, double* Lmax) {
    if (a->kind == CRANE_ACT_LINKAGE) {
        // Monotonic over the range (linkage_init refuses a dead centre).
        *Lmin = fmin(a->lk.L_qmin, a->lk.L_qmax), *Lmax = fmax(a->lk.L_qmin, a->lk.L_qmax);
        return 0;
    }
    int child;
    const double *pc, *pp; // the pin on the child, the pin on the parent
    if (cc->body[a->body_b].def.parent == a->body_a) child = a->body_b, pc = a->pb, pp = a->pa;
    else if (cc->body[a->body_a].def.parent == a->body_b) child = a->body_a, pc = a->pa, pp = a->pb;
    else return -1;
    const chain_body_def* d = &cc->body[child].def;
    double lo = d->q_min, hi = d->q_max;
    // An unbounded revolute joint: one turn covers every pose.
    if (!isfinite(lo)) lo = -M_PI;
    if (!isfinite(hi)) hi = M_PI;
    if (hi - lo > 2 * M_PI) hi = lo + 2 * M_PI;
    // 720 samples: 0.5 deg on a full turn, 1.4 mm on a 1 m slide; the
    // length is smooth, so its extremes are found to well under the
    // millimetres a stroke is designed to.
    const int N = 720;
    *Lmin = INFINITY, *Lmax = -INFINITY;
    for (int s = 0; s <= N; ++s) {
        double w[3];
        child_to_parent(d, lo + (hi - lo) * s / N, pc, w);
        const double L = sqrt((w[0] - pp[0]) * (w[0] - pp[0]) + (w[1] - pp[1]) * (w[1] - pp[1]) +
                              (w[2] - pp[2]) * (w[2] - pp[2]));
        if (L < *Lmin) *Lmin = L;
        if (L > *Lmax) *Lmax = L;
    }
    return 0;
}

int model_chain_bind(json_ctx* c, model* m) {
    crane_chain* cc = &m->chain;
    const hyd_model* h = m->hyd;
    char f[96];
    for (int k = 0; k < cc->nact && !c->failed; ++k) {
        const crane_act* a = &cc->act[k];
        const int cyl = hyd_model_cylinder(h, a->cylinder);
        snprintf(f, sizeof f, "mechanics.actuators[%d].cylinder", k);
        if (cyl < 0) json_fail(c, f, "no cylinder named \"%s\" in hydraulics", a->cylinder);
        // Two actuators on one cylinder are two rigid constraints on one
        // stroke: the integrators meet that as a blow-up, not an error.
        for (int j = 0; j < k && !c->failed; ++j)
            if (!strcmp(cc->act[j].cylinder, a->cylinder))
                json_fail(c, f, "\"%s\" is also the cylinder of actuators[%d]; each actuator needs its own",
                          a->cylinder, j);
        snprintf(f, sizeof f, "mechanics.actuators[%d].valve", k);
        if (!c->failed && hyd_model_valve(h, a->valve) < 0)
            json_fail(c, f, "no valve named \"%s\" in hydraulics", a->valve);
    }
    for (int i = 0; i < cc->nfn && !c->failed; ++i) {
        snprintf(f, sizeof f, "mechanics.functions[%d].valve", i);
        if (hyd_model_valve(h, cc->fn[i].valve) < 0)
            json_fail(c, f, "no valve named \"%s\" in hydraulics", cc->fn[i].valve);
    }
    if (c->failed) return -1;
    // Every cylinder drives a body and every valve is a function: a cylinder
    // no actuator names would move nothing, a valve no function names would
    // never get a command (the two-link loader's blind spot, issue 26).
    for (int k = 0; k < hyd_model_ncylinder(h) && !c->failed; ++k) {
        const int comp = hyd_model_cylinder_comp(h, k);
        const char* name = hyd_model_comp_name(h, comp);
        bool used = false;
        for (int j = 0; j < cc->nact && !used; ++j) used = !strcmp(cc->act[j].cylinder, name);
        snprintf(f, sizeof f, "hydraulics.components[%d]", comp);
        if (!used) json_fail(c, f, "cylinder \"%s\" is driven by no actuator (name it in mechanics.actuators)", name);
    }
    for (int k = 0; k < hyd_model_nvalve(h) && !c->failed; ++k) {
        const int comp = hyd_model_valve_comp(h, k);
        const char* name = hyd_model_comp_name(h, comp);
        bool used = false;
        for (int j = 0; j < cc->nfn && !used; ++j) used = !strcmp(cc->fn[j].valve, name);
        snprintf(f, sizeof f, "hydraulics.components[%d]", comp);
        if (!used) json_fail(c, f, "valve \"%s\" is commanded by no function (name it in mechanics.functions)", name);
    }
    if (c->failed) return -1;
    char e[512];
    if (crane_chain_bind(cc, h, e, sizeof e)) {
        fail_under_mechanics(c, e);
        return -1;
    }
    // The mechanism once, with the rated tip load: chain_create's checks
    // (masses, inertia tensors, limits) name the body and field.
    chain* ch = crane_chain_mechanism(cc, m->mech.load_mass, false, 0.0, e, sizeof e);
    if (!ch) {
        fail_under_mechanics(c, e);
        return -1;
    }
    chain_free(ch);
    // Each cylinder across one joint must reach a pose within that joint's
    // limits: its pin length range there must overlap [closed, closed +
    // stroke]. A pin pair that never fits is a wrong mount or limit.
    for (int k = 0; k < cc->nact && !c->failed; ++k) {
        const crane_act* a = &cc->act[k];
        double Lmin, Lmax;
        if (pin_range(cc, a, &Lmin, &Lmax)) continue;
        const double L0 = a->closed_length, L1 = a->closed_length + a->stroke;
        if (Lmax < L0 || Lmin > L1) {
            const int child = cc->body[a->body_b].def.parent == a->body_a ? a->body_b : a->body_a;
            snprintf(f, sizeof f, "mechanics.actuators[%d].closed_length", k);
            json_fail(c, f,
                      "the pins are %.4g..%.4g m apart within the limits of body '%s''s joint, the cylinder spans "
                      "%.4g..%.4g m (closed length plus its %.4g m stroke): it reaches no pose within the limits",
                      Lmin, Lmax, cc->body[child].def.name, L0, L1, a->stroke);
        }
    }
    return c->failed ? -1 : 0;
}

int model_require_two_link(const model* m, const char* what, char* err, size_t errsz) {
    if (m->chain.two_link) return 0;
    if (err && errsz)
        snprintf(err, errsz,
                 "%s: a chain of %d bodies and %d functions; the %s handles the two-link crane (mechanics.links) "
                 "only",
                 m->file[0] ? m->file : "model", m->chain.nbody, m->chain.nfn, what);
    return -1;
}
