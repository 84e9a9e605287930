// world_desc.c: world file loading (schema in docs/ode_world.md).
#include "world_desc.h"
#include "param_names.h"

#include "hydraulics.h"
#include "json_util.h"
#include "model.h"
#include "mesh_geom.h"

#include <limits.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

const char* const world_mesh_key[WORLD_MESH_COUNT] = {
    "truck", "wheel", "outrigger", "column", "boom1", "boom2", "hook", "load", "wall", "box", "building"};

static const char* const default_mesh_file[WORLD_MESH_COUNT] = {
    "truck.obj", "", "", "column.obj", "boom1.obj", "boom2.obj", "hook.obj", "load_block.obj", "wall.obj",
    "", ""};

int world_kind_parse(const char* s) {
    if (!strcmp(s, "validation")) return WORLD_VALIDATION;
    if (!strcmp(s, "sandbox")) return WORLD_SANDBOX;
    return -1;
}

const char* world_kind_name(world_kind k) { return k == WORLD_SANDBOX ? "sandbox" : "validation"; }

static void set3(double* v, double a, double b, double c) {
    v[0] = a;
    v[1] = b;
    v[2] = c;
}

void world_desc_default(world_desc* w, world_kind kind) {
    memset(w, 0, sizeof *w);
    snprintf(w->name, sizeof w->name, "%s", world_kind_name(kind));
    w->kind = kind;
    w->gravity = -1; // the model's (a file may set 0: weightless)
    // dWorldStep solves the constraints directly, so a tiny CFM only keeps the
    // LCP matrix regular; ERP 0.2 removes drift over about 5 steps without
    // adding noticeable energy (docs/ode_world.md, "ERP and CFM").
    w->ode.erp = 0.2;
    w->ode.cfm = 1e-10;
    w->ode.contact_erp = 0.2;
    w->ode.contact_cfm = 1e-5;
    w->ode.surface_layer = 0.5e-3;
    w->ode.max_contacts = 8;

    world_terrain* t = &w->terrain;
    t->size[0] = t->size[1] = 120.0;
    t->samples[0] = t->samples[1] = 121;
    t->flat_radius = 18.0;
    t->friction = 0.9;

    // A 6.5 t two-axle truck with a small knuckle-boom crane behind the cab.
    world_truck* k = &w->truck;
    k->mass = 6500.0;
    set3(k->chassis, 6.4, 2.3, 0.5);
    k->bed_height = 1.1;
    set3(k->cab, 1.7, 2.3, 1.6);
    k->cab_x = 2.3;
    k->wheel_radius = 0.45;
    k->wheel_width = 0.3;
    k->wheel_x[0] = 2.1;
    k->wheel_x[1] = -1.6;
    k->track = 1.9;
    k->outriggers = 1;
    k->outrigger_x[0] = 1.0;
    k->outrigger_x[1] = -2.9;
    k->outrigger_span = 4.0;
    set3(k->pad, 0.4, 0.4, 0.08);
    k->column_x = 0.9;
    k->friction = 0.8;

    w->slew.pinion_radius = 0.1;
    snprintf(w->slew.cylinder, sizeof w->slew.cylinder, "slew_cyl");
    snprintf(w->slew.valve, sizeof w->slew.valve, "slew_valve");
    w->slew.column_radius = 0.16;
    w->slew.damping = 2000.0;

    w->rope.length = 1.2;
    w->rope.links = 4;
    w->rope.radius = 0.012;
    w->rope.mass_per_m = 0.6;

    w->hook.mass = 40.0;
    set3(w->hook.size, 0.2, 0.12, 0.3);
    w->hook.reach = 0.5;

    for (int i = 0; i < WORLD_MESH_COUNT; ++i) {
        snprintf(w->mesh[i].file, sizeof w->mesh[i].file, "%s", default_mesh_file[i]);
        w->mesh[i].scale = 1.0;
        w->mesh[i].up = 2;
    }
}

void world_desc_free(world_desc* w) {
    if (!w) return;
    cJSON_Delete(w->circuit);
    cJSON_Delete(w->circuit_ls);
    w->circuit = w->circuit_ls = NULL;
}

const cJSON* world_desc_circuit_for(const world_desc* w, const cJSON* hydraulics) {
    if (!w) return NULL;
    const cJSON* comps = cJSON_GetObjectItemCaseSensitive(hydraulics, "components");
    const cJSON* it;
    cJSON_ArrayForEach(it, comps) {
        const cJSON* t = cJSON_GetObjectItemCaseSensitive(it, "type");
        if (cJSON_IsString(t) && !strcmp(t->valuestring, "ls_pump")) return w->circuit_ls ? w->circuit_ls : w->circuit;
    }
    return w->circuit;
}

double world_desc_terrain_height(const world_desc* w, double x, double y) {
    const world_terrain* t = &w->terrain;
    double h = 0;
    for (int i = 0; i < t->nhill; ++i) {
        const world_hill* g = &t->hill[i];
        double dx = x - g->x, dy = y - g->y;
        h += g->height * exp(-(dx * dx + dy * dy) / (2.0 * g->radius * g->radius));
    }
    // Fade the hills out over 6 m towards the work area, with a smoothstep so the
    // ground has no kink where it meets the flat (the heightfield is piecewise
    // linear anyway; this keeps its facets gentle).
    double r = hypot(x, y), s = (r - t->flat_radius) / 6.0;
    if (s <= 0) return 0.0;
    if (s < 1) h *= s * s * (3.0 - 2.0 * s);
    return h;
}

// Hard and typical ranges of the world's values (docs/ode_world.md, "Value
// ranges"). Hard: ODE aborts the process (dxNormalize, dCollideHeightfield)
// on a truck of 1e308 kg, a load 1e308 m long or a truck 1e30 m away, and
// values like that are typos; typical: a truck-mounted crane's yard.
static const json_range R_GRAVITY = {0, 30, 9.7, 9.9, "m/s^2"};
static const json_range R_TERRAIN_SIZE = {10, 1e4, 20, 2000, "m"};
static const json_range R_FLAT_RADIUS = {0, 1e4, 5, 500, "m"};
static const json_range R_FRICTION = {0, 10, 0.1, 1.5, ""};
static const json_range R_HILL_XY = {-1e4, 1e4, -1e3, 1e3, "m"};
static const json_range R_HILL_RADIUS = {0.1, 1e4, 1, 200, "m"};
static const json_range R_HILL_HEIGHT = {-100, 100, -20, 20, "m"};
static const json_range R_TRUCK_MASS = {100, 1e6, 2000, 6e4, "kg"};
static const json_range R_TRUCK_SIZE = {0.05, 30, 0.2, 15, "m"};
static const json_range R_TRUCK_X = {-20, 20, -10, 10, "m"};
static const json_range R_BED_HEIGHT = {0.2, 5, 0.6, 2, "m"};
static const json_range R_WHEEL_RADIUS = {0.1, 2, 0.2, 0.8, "m"};
static const json_range R_WHEEL_WIDTH = {0.05, 2, 0.1, 0.6, "m"};
static const json_range R_TRACK = {0.5, 5, 1.2, 2.6, "m"};
static const json_range R_SPAN = {0.5, 20, 2, 10, "m"};
static const json_range R_PAD = {0.01, 3, 0.05, 1, "m"};
static const json_range R_PINION = {0.01, 1, 0.03, 0.3, "m"};
static const json_range R_COLUMN_RADIUS = {0.02, 2, 0.05, 0.5, "m"};
static const json_range R_SLEW_DAMPING = {0, 1e7, 0, 1e5, "N m s/rad"};
static const json_range R_ROPE_LENGTH = {0.2, 50, 0.5, 10, "m"};
static const json_range R_ROPE_RADIUS = {0.002, 0.2, 0.005, 0.05, "m"};
static const json_range R_ROPE_MASS = {0.01, 100, 0.1, 10, "kg/m"};
static const json_range R_HOOK_MASS = {0.5, 5000, 5, 500, "kg"};
static const json_range R_HOOK_SIZE = {0.01, 2, 0.05, 1, "m"};
static const json_range R_HOOK_REACH = {0.01, 5, 0.1, 2, "m"};
static const json_range R_LOAD_MASS = {0.1, 1e5, 1, 5000, "kg"};
static const json_range R_LOAD_SIZE = {0.01, 20, 0.1, 5, "m"};
static const json_range R_OBST_SIZE = {0.01, 100, 0.1, 50, "m"};
static const json_range R_OBST_MASS = {0, 1e6, 0, 2e4, "kg"};
static const json_range R_HEIGHT = {-1, 1e3, -1, 100, "m"}; // z < 0: rest on the ground
static const json_range R_CONTACT_CFM = {1e-10, 1, 1e-8, 1e-3, ""};
static const json_range R_MESH_SCALE = {1e-4, 1e4, 1e-3, 1e3, ""};
static const json_range R_MESH_OFFSET = {-100, 100, -20, 20, "m"};

static const json_range R_DENSITY = {1, 3e4, 50, 1e4, "kg/m^3"};

// A meshed object's box size (its collision mesh's bounds) and, for a loose
// body, its mass from "mass" or "density" (exactly one) and the volume.
static double mesh_object_mass(json_ctx* c, const cJSON* o, const char* path, world_obj_mesh* om, double* size,
                               const json_range* rmass, bool loose) {
    for (int k = 0; k < 3; ++k) size[k] = om->hi[k] - om->lo[k];
    if (!loose || c->failed) return 0;
    const bool hm = cJSON_GetObjectItemCaseSensitive(o, "mass") != NULL;
    const bool hd = cJSON_GetObjectItemCaseSensitive(o, "density") != NULL;
    char fp[96];
    if (hm && hd) {
        json_path(fp, sizeof fp, path, "density");
        json_fail(c, fp, "give \"mass\" or \"density\", not both");
        return 0;
    }
    if (hm) return json_num_r(c, o, path, "mass", true, 0, rmass);
    const double rho = json_num_r(c, o, path, "density", true, 0, &R_DENSITY);
    if (c->failed) return 0;
    const double m = rho * om->volume;
    json_path(fp, sizeof fp, path, "density");
    if (!(m >= rmass->lo && m <= rmass->hi))
        json_fail(c, fp, "%g kg/m^3 times the mesh's volume %g m^3 gives %g kg, outside [%g, %g] kg", rho, om->volume,
                  m, rmass->lo, rmass->hi);
    return m;
}

// Position [x, y] or [x, y, z]; a missing or negative z means "rest on the
// ground" and is resolved after the terrain is known (z = -1 marks it).
static void read_position(json_ctx* c, const cJSON* o, const char* path, double* p) {
    char full[256];
    json_path(full, sizeof full, path, "position");
    const cJSON* a = json_arr(c, o, path, "position", true);
    if (c->failed) return;
    int n = cJSON_GetArraySize(a);
    if (n != 2 && n != 3) {
        json_fail(c, full, "must be [x, y] or [x, y, z], got %d numbers", n);
        return;
    }
    p[2] = -1.0;
    for (int i = 0; i < n; ++i) {
        const cJSON* v = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble)) {
            json_fail(c, full, "element %d must be a finite number", i);
            return;
        }
        p[i] = v->valuedouble;
    }
}

static void read_size(json_ctx* c, const cJSON* o, const char* path, const char* key, bool required,
                      double* v, const json_range* r) {
    char full[256];
    json_path(full, sizeof full, path, key);
    if (!cJSON_GetObjectItemCaseSensitive(o, key) && !required) return;
    json_vec(c, o, path, key, required, v, 3);
    for (int i = 0; i < 3 && !c->failed; ++i)
        if (!(v[i] > 0)) json_fail(c, full, "all sizes must be > 0, got %g", v[i]);
    for (int i = 0; i < 3 && !c->failed; ++i) {
        char p[272];
        json_path_index(p, sizeof p, full, i);
        json_range_check(c, p, v[i], r);
    }
}

// ---- object meshes (CAD files) ----

// Largest extent [m] an object mesh may have after scaling: a yard object
// beyond 1 km is a unit mistake (a model in millimetres given scale 1).
#define MESH_MAX_EXTENT 1000.0
#define MESH_MIN_EXTENT 0.01

// A mesh file named in the world file: absolute, or relative to the world
// file's folder.
static void resolve_path(char* out, size_t n, const char* dir, const char* file) {
    if (file[0] == '/' || !dir[0]) snprintf(out, n, "%s", file);
    else snprintf(out, n, "%s/%s", dir, file);
}

// Read {"file", "collision", "scale", "up"} (plus extra keys the caller
// allows) at path.mesh, load the collision mesh and check it: bounds, and
// for a loose body (loose = 1) a closed surface with a volume, its centre.
// max_extent bounds the object's size [m].
static void read_obj_mesh(json_ctx* c, const cJSON* m, const char* path, const char* dir, int loose,
                          double max_extent, const char* const* keys, world_obj_mesh* om) {
    char p[96], fp[112];
    snprintf(p, sizeof p, "%s.mesh", path);
    if (!cJSON_IsObject(m)) {
        json_fail(c, p, "must be an object {\"file\": ..., \"scale\": ..., \"up\": ...}");
        return;
    }
    json_only_keys(c, m, p, keys);
    char file[256] = "", coll[256] = "", up[8];
    json_str(c, m, p, "file", true, "", file, sizeof file);
    json_str(c, m, p, "collision", false, "", coll, sizeof coll);
    om->scale = json_num_r(c, m, p, "scale", false, 1.0, &R_MESH_SCALE);
    json_str(c, m, p, "up", false, "z", up, sizeof up);
    if (c->failed) return;
    if (!strcmp(up, "y")) om->up = 1;
    else if (!strcmp(up, "z")) om->up = 2;
    else {
        json_path(fp, sizeof fp, p, "up");
        json_fail(c, fp, "must be \"y\" or \"z\", got \"%s\"", up);
        return;
    }
    if (!file[0]) {
        json_path(fp, sizeof fp, p, "file");
        json_fail(c, fp, "must name a mesh file");
        return;
    }
    resolve_path(om->file, sizeof om->file, dir, file);
    if (coll[0]) resolve_path(om->collision, sizeof om->collision, dir, coll);
    const char* cpath = coll[0] ? om->collision : om->file;
    json_path(fp, sizeof fp, p, coll[0] ? "collision" : "file");
    mesh_tri t;
    char why[256];
    if (mesh_load(cpath, om->scale, om->up, &t, why, sizeof why)) {
        json_fail(c, fp, "%s: %s", cpath, why);
        return;
    }
    if (t.dropped)
        fprintf(stderr, "warning: %s: %s: %d degenerate (zero-area) triangles left out of the collision shape\n", fp,
                cpath, t.dropped);
    mesh_bounds(&t, om->lo, om->hi);
    om->ntri = t.nt;
    const double ext = fmax(om->hi[0] - om->lo[0], fmax(om->hi[1] - om->lo[1], om->hi[2] - om->lo[2]));
    if (!(ext >= MESH_MIN_EXTENT && ext <= max_extent)) {
        json_fail(c, fp, "%s: the mesh is %g m across at scale %g; it must be %g..%g m (a model in millimetres needs "
                  "\"scale\": 0.001)", cpath, ext, om->scale, MESH_MIN_EXTENT, max_extent);
    } else if (loose) {
        const int open = mesh_open_edges(&t);
        double I[9];
        if (open)
            json_fail(c, fp, "%s: the mesh is not closed (%d open or inconsistently wound edges), so it has no volume; "
                      "a loose body needs a closed mesh (give one as \"collision\")", cpath, open);
        else if (mesh_mass_props(&t, &om->volume, om->com, I))
            json_fail(c, fp, "%s: the mesh encloses no volume", cpath);
    }
    mesh_free(&t);
}

static const char* const OBJ_MESH_KEYS[] = {"file", "collision", "scale", "up", NULL};

static void load_ode(json_ctx* c, const cJSON* o, world_ode_params* p) {
    if (!o) return;
    static const char* const keys[] = {"erp", "cfm", "contact_erp", "contact_cfm", "surface_layer",
                                       "max_contacts", NULL};
    json_only_keys(c, o, "ode", keys);
    p->erp = json_num(c, o, "ode", "erp", false, p->erp, 0.0, 1.0);
    p->cfm = json_num(c, o, "ode", "cfm", false, p->cfm, 0.0, 1.0);
    p->contact_erp = json_num(c, o, "ode", "contact_erp", false, p->contact_erp, 0.0, 1.0);
    // A contact CFM of 0 makes the contact rows of bodies that start in
    // touch singular: the fuzzer found ODE aborting (dxNormalize4) on it.
    p->contact_cfm = json_num_r(c, o, "ode", "contact_cfm", false, p->contact_cfm, &R_CONTACT_CFM);
    p->surface_layer = json_num(c, o, "ode", "surface_layer", false, p->surface_layer, 0.0, 0.1);
    p->max_contacts = json_int(c, o, "ode", "max_contacts", false, p->max_contacts, 1, 32);
}

static void load_terrain(json_ctx* c, const cJSON* o, world_terrain* t, const char* dir) {
    if (!o) return;
    static const char* const keys[] = {"size", "samples", "flat_radius", "friction", "hills", "mesh", NULL};
    json_only_keys(c, o, "terrain", keys);
    if (cJSON_GetObjectItemCaseSensitive(o, "size")) {
        json_vec(c, o, "terrain", "size", true, t->size, 2);
        if (!c->failed && !(t->size[0] >= 10 && t->size[1] >= 10))
            json_fail(c, "terrain.size", "must be >= 10 m each way, got [%g, %g]", t->size[0], t->size[1]);
        json_range_check(c, "terrain.size[0]", t->size[0], &R_TERRAIN_SIZE);
        json_range_check(c, "terrain.size[1]", t->size[1], &R_TERRAIN_SIZE);
    }
    if (cJSON_GetObjectItemCaseSensitive(o, "samples")) {
        double s[2];
        json_vec(c, o, "terrain", "samples", true, s, 2);
        for (int i = 0; i < 2 && !c->failed; ++i) {
            // Range first, then the conversion: (int)1e300 is undefined.
            if (s[i] != floor(s[i]) || s[i] < 2 || s[i] > 1024)
                json_fail(c, "terrain.samples", "must be whole numbers in [2, 1024], got %g", s[i]);
            else t->samples[i] = (int)s[i];
        }
    }
    t->flat_radius = json_num_r(c, o, "terrain", "flat_radius", false, t->flat_radius, &R_FLAT_RADIUS);
    t->friction = json_num_r(c, o, "terrain", "friction", false, t->friction, &R_FRICTION);
    const cJSON* tm = cJSON_GetObjectItemCaseSensitive(o, "mesh");
    if (tm && !c->failed) {
        static const char* const mkeys[] = {"file", "collision", "scale", "up", "position", "yaw_deg", NULL};
        read_obj_mesh(c, tm, "terrain", dir, 0, 1e4, mkeys, &t->mesh);
        if (!c->failed && cJSON_GetObjectItemCaseSensitive(tm, "position"))
            json_vec_r(c, tm, "terrain.mesh", "position", true, t->mesh_pos, 3, &R_HILL_XY);
        if (!c->failed) t->mesh_yaw = json_num(c, tm, "terrain.mesh", "yaw_deg", false, 0, -360, 360) * DEG;
    }
    const cJSON* hills = json_arr(c, o, "terrain", "hills", false);
    if (!hills || c->failed) return;
    int n = cJSON_GetArraySize(hills);
    if (n > WORLD_DESC_MAX_HILLS) {
        json_fail(c, "terrain.hills", "at most %d hills, got %d", WORLD_DESC_MAX_HILLS, n);
        return;
    }
    for (int i = 0; i < n && !c->failed; ++i) {
        char p[64];
        json_path_index(p, sizeof p, "terrain.hills", i);
        const cJSON* h = cJSON_GetArrayItem(hills, i);
        if (!cJSON_IsObject(h)) {
            json_fail(c, p, "must be an object");
            return;
        }
        json_only_keys(c, h, p, (const char* const[]){"x", "y", "radius", "height", NULL});
        world_hill* g = &t->hill[i];
        g->x = json_num_r(c, h, p, "x", true, 0, &R_HILL_XY);
        g->y = json_num_r(c, h, p, "y", true, 0, &R_HILL_XY);
        g->radius = json_num_r(c, h, p, "radius", true, 1, &R_HILL_RADIUS);
        g->height = json_num_r(c, h, p, "height", true, 0, &R_HILL_HEIGHT);
        t->nhill = i + 1;
    }
}

static void load_truck(json_ctx* c, const cJSON* o, world_truck* k) {
    if (!o) return;
    static const char* const keys[] = {"position", "yaw_deg", "mass", "chassis", "bed_height", "cab",
                                       "cab_x", "wheel_radius", "wheel_width", "wheel_x", "track",
                                       "outriggers", "outrigger_x", "outrigger_span", "pad",
                                       "column_x", "friction", NULL};
    const char* p = "truck";
    json_only_keys(c, o, p, keys);
    if (cJSON_GetObjectItemCaseSensitive(o, "position")) json_vec(c, o, p, "position", true, k->position, 2);
    k->yaw = json_num(c, o, p, "yaw_deg", false, k->yaw / DEG, -360, 360) * DEG;
    k->mass = json_num_r(c, o, p, "mass", false, k->mass, &R_TRUCK_MASS);
    read_size(c, o, p, "chassis", false, k->chassis, &R_TRUCK_SIZE);
    k->bed_height = json_num_r(c, o, p, "bed_height", false, k->bed_height, &R_BED_HEIGHT);
    read_size(c, o, p, "cab", false, k->cab, &R_TRUCK_SIZE);
    k->cab_x = json_num_r(c, o, p, "cab_x", false, k->cab_x, &R_TRUCK_X);
    k->wheel_radius = json_num_r(c, o, p, "wheel_radius", false, k->wheel_radius, &R_WHEEL_RADIUS);
    k->wheel_width = json_num_r(c, o, p, "wheel_width", false, k->wheel_width, &R_WHEEL_WIDTH);
    json_vec_r(c, o, p, "wheel_x", false, k->wheel_x, 2, &R_TRUCK_X);
    k->track = json_num_r(c, o, p, "track", false, k->track, &R_TRACK);
    k->outriggers = json_bool(c, o, p, "outriggers", k->outriggers != 0);
    json_vec_r(c, o, p, "outrigger_x", false, k->outrigger_x, 2, &R_TRUCK_X);
    k->outrigger_span = json_num_r(c, o, p, "outrigger_span", false, k->outrigger_span, &R_SPAN);
    read_size(c, o, p, "pad", false, k->pad, &R_PAD);
    k->column_x = json_num_r(c, o, p, "column_x", false, k->column_x, &R_TRUCK_X);
    k->friction = json_num_r(c, o, p, "friction", false, k->friction, &R_FRICTION);
    if (c->failed) return;
    // The chassis sits on the wheels: the bed must be above the axles, or the
    // wheels would be inside the chassis box.
    if (k->bed_height - k->chassis[2] < k->wheel_radius * 0.5)
        json_fail(c, "truck.bed_height", "chassis bottom (bed_height - chassis height = %g m) must be above half the wheel radius",
                  k->bed_height - k->chassis[2]);
    else if (k->outriggers && k->outrigger_span <= k->track)
        json_fail(c, "truck.outrigger_span", "must exceed the track (%g m) when outriggers are out, got %g",
                  k->track, k->outrigger_span);
}

static void load_slew(json_ctx* c, const cJSON* o, world_slew* s) {
    if (!o) return;
    static const char* const keys[] = {"pinion_radius", "cylinder", "valve", "column_radius", "damping", NULL};
    json_only_keys(c, o, "slew", keys);
    s->pinion_radius = json_num_r(c, o, "slew", "pinion_radius", false, s->pinion_radius, &R_PINION);
    json_str(c, o, "slew", "cylinder", false, s->cylinder, s->cylinder, sizeof s->cylinder);
    json_str(c, o, "slew", "valve", false, s->valve, s->valve, sizeof s->valve);
    s->column_radius = json_num_r(c, o, "slew", "column_radius", false, s->column_radius, &R_COLUMN_RADIUS);
    s->damping = json_num_r(c, o, "slew", "damping", false, s->damping, &R_SLEW_DAMPING);
}

static void load_rope(json_ctx* c, const cJSON* o, world_rope* r) {
    if (!o) return;
    static const char* const keys[] = {"length", "links", "radius", "mass_per_m", NULL};
    json_only_keys(c, o, "rope", keys);
    r->length = json_num_r(c, o, "rope", "length", false, r->length, &R_ROPE_LENGTH);
    r->links = json_int(c, o, "rope", "links", false, r->links, 1, WORLD_DESC_MAX_ROPE);
    r->radius = json_num_r(c, o, "rope", "radius", false, r->radius, &R_ROPE_RADIUS);
    r->mass_per_m = json_num_r(c, o, "rope", "mass_per_m", false, r->mass_per_m, &R_ROPE_MASS);
}

static void load_hook(json_ctx* c, const cJSON* o, world_hook* h) {
    if (!o) return;
    static const char* const keys[] = {"mass", "size", "reach", NULL};
    json_only_keys(c, o, "hook", keys);
    h->mass = json_num_r(c, o, "hook", "mass", false, h->mass, &R_HOOK_MASS);
    read_size(c, o, "hook", "size", false, h->size, &R_HOOK_SIZE);
    h->reach = json_num_r(c, o, "hook", "reach", false, h->reach, &R_HOOK_REACH);
}

static void load_loads(json_ctx* c, const cJSON* arr, world_desc* w, const char* dir) {
    if (!arr) return;
    int n = cJSON_GetArraySize(arr);
    if (n > WORLD_DESC_MAX_LOADS) {
        json_fail(c, "loads", "at most %d loads, got %d", WORLD_DESC_MAX_LOADS, n);
        return;
    }
    for (int i = 0; i < n && !c->failed; ++i) {
        char p[64];
        json_path_index(p, sizeof p, "loads", i);
        const cJSON* o = cJSON_GetArrayItem(arr, i);
        if (!cJSON_IsObject(o)) {
            json_fail(c, p, "must be an object");
            return;
        }
        static const char* const keys[] = {"name", "mass", "size", "position", "yaw_deg", "friction", "mesh",
                                           "density", NULL};
        json_only_keys(c, o, p, keys);
        world_load* l = &w->load[i];
        char def[WORLD_DESC_NAME];
        snprintf(def, sizeof def, "load_%d", i);
        json_str(c, o, p, "name", false, def, l->name, sizeof l->name);
        const cJSON* me = cJSON_GetObjectItemCaseSensitive(o, "mesh");
        if (me && !c->failed) {
            if (cJSON_GetObjectItemCaseSensitive(o, "size")) {
                char fp[80];
                json_path(fp, sizeof fp, p, "size");
                json_fail(c, fp, "not used with a mesh (the mesh gives the shape)");
            }
            read_obj_mesh(c, me, p, dir, 1, 20.0, OBJ_MESH_KEYS, &l->mesh);
            l->mass = mesh_object_mass(c, o, p, &l->mesh, l->size, &R_LOAD_MASS, true);
        } else {
            if (cJSON_GetObjectItemCaseSensitive(o, "density") && !c->failed) {
                char fp[80];
                json_path(fp, sizeof fp, p, "density");
                json_fail(c, fp, "only a load with a mesh takes a density (a box load gives its mass)");
            }
            l->mass = json_num_r(c, o, p, "mass", true, 0, &R_LOAD_MASS);
            read_size(c, o, p, "size", true, l->size, &R_LOAD_SIZE);
            for (int k = 0; k < 3; ++k) l->mesh.lo[k] = -0.5 * l->size[k], l->mesh.hi[k] = 0.5 * l->size[k];
        }
        read_position(c, o, p, l->position);
        l->yaw = json_num(c, o, p, "yaw_deg", false, 0, -360, 360) * DEG;
        l->friction = json_num_r(c, o, p, "friction", false, 0.6, &R_FRICTION);
        w->nload = i + 1;
    }
}

static void load_obstacles(json_ctx* c, const cJSON* arr, world_desc* w, const char* dir) {
    if (!arr) return;
    int n = cJSON_GetArraySize(arr);
    if (n > WORLD_DESC_MAX_OBSTACLES) {
        json_fail(c, "obstacles", "at most %d obstacles, got %d", WORLD_DESC_MAX_OBSTACLES, n);
        return;
    }
    for (int i = 0; i < n && !c->failed; ++i) {
        char p[64];
        json_path_index(p, sizeof p, "obstacles", i);
        const cJSON* o = cJSON_GetArrayItem(arr, i);
        if (!cJSON_IsObject(o)) {
            json_fail(c, p, "must be an object");
            return;
        }
        static const char* const keys[] = {"name", "kind", "size", "position", "yaw_deg", "mass", "friction",
                                           "mesh", "density", NULL};
        json_only_keys(c, o, p, keys);
        world_obstacle* b = &w->obstacle[i];
        char def[WORLD_DESC_NAME], kind[16];
        snprintf(def, sizeof def, "obstacle_%d", i);
        json_str(c, o, p, "name", false, def, b->name, sizeof b->name);
        json_str(c, o, p, "kind", false, "box", kind, sizeof kind);
        if (!c->failed) {
            if (!strcmp(kind, "wall")) b->kind = WORLD_OBST_WALL;
            else if (!strcmp(kind, "box")) b->kind = WORLD_OBST_BOX;
            else if (!strcmp(kind, "building")) b->kind = WORLD_OBST_BUILDING;
            else {
                char f[80];
                json_path(f, sizeof f, p, "kind");
                json_fail(c, f, "must be \"wall\", \"box\" or \"building\", got \"%s\"", kind);
            }
        }
        const cJSON* me = cJSON_GetObjectItemCaseSensitive(o, "mesh");
        if (me && !c->failed) {
            if (cJSON_GetObjectItemCaseSensitive(o, "size")) {
                char fp[80];
                json_path(fp, sizeof fp, p, "size");
                json_fail(c, fp, "not used with a mesh (the mesh gives the shape)");
            }
            // Loose (given a mass or a density): the convex hull moves; else
            // the mesh itself is fixed in place.
            const bool loose = cJSON_GetObjectItemCaseSensitive(o, "density") ||
                               (cJSON_GetObjectItemCaseSensitive(o, "mass") &&
                                json_num_r(c, o, p, "mass", false, 0, &R_OBST_MASS) > 0);
            read_obj_mesh(c, me, p, dir, loose, MESH_MAX_EXTENT, OBJ_MESH_KEYS, &b->mesh);
            b->mass = mesh_object_mass(c, o, p, &b->mesh, b->size, &R_OBST_MASS, loose);
        } else {
            read_size(c, o, p, "size", true, b->size, &R_OBST_SIZE);
            if (cJSON_GetObjectItemCaseSensitive(o, "density") && !c->failed) {
                char fp[80];
                json_path(fp, sizeof fp, p, "density");
                json_fail(c, fp, "only an obstacle with a mesh takes a density (a box gives its mass)");
            }
            b->mass = json_num_r(c, o, p, "mass", false, 0, &R_OBST_MASS);
            for (int k = 0; k < 3; ++k) b->mesh.lo[k] = -0.5 * b->size[k], b->mesh.hi[k] = 0.5 * b->size[k];
        }
        read_position(c, o, p, b->position);
        b->yaw = json_num(c, o, p, "yaw_deg", false, 0, -360, 360) * DEG;
        b->friction = json_num_r(c, o, p, "friction", false, 0.6, &R_FRICTION);
        w->nobstacle = i + 1;
    }
}

static void load_meshes(json_ctx* c, const cJSON* o, world_desc* w) {
    if (!o) return;
    // json_only_keys needs a NULL-terminated list.
    const char* allowed[WORLD_MESH_COUNT + 1];
    for (int i = 0; i < WORLD_MESH_COUNT; ++i) allowed[i] = world_mesh_key[i];
    allowed[WORLD_MESH_COUNT] = NULL;
    json_only_keys(c, o, "meshes", allowed);
    for (int i = 0; i < WORLD_MESH_COUNT && !c->failed; ++i) {
        char p[64];
        json_path(p, sizeof p, "meshes", world_mesh_key[i]);
        const cJSON* m = json_obj(c, o, "meshes", world_mesh_key[i], false);
        if (!m) continue;
        json_only_keys(c, m, p, (const char* const[]){"file", "scale", "up", "offset", NULL});
        world_mesh* s = &w->mesh[i];
        json_str(c, m, p, "file", false, s->file, s->file, sizeof s->file);
        s->scale = json_num_r(c, m, p, "scale", false, s->scale, &R_MESH_SCALE);
        char up[8];
        json_str(c, m, p, "up", false, s->up == 1 ? "y" : "z", up, sizeof up);
        if (!c->failed) {
            if (!strcmp(up, "y")) s->up = 1;
            else if (!strcmp(up, "z")) s->up = 2;
            else {
                char f[80];
                json_path(f, sizeof f, p, "up");
                json_fail(c, f, "must be \"y\" or \"z\", got \"%s\"", up);
            }
        }
        if (cJSON_GetObjectItemCaseSensitive(m, "offset")) {
            json_vec_r(c, m, p, "offset", true, s->offset, 3, &R_MESH_OFFSET);
            s->has_offset = 1;
        }
    }
}

// The circuit fragment must look like a hydraulics section's lists; its
// contents are checked when the merged circuit is compiled. circuit_ls may
// also patch the model's components: "component.field": "node name" (the
// component and its field are checked against the model when it is merged).
static void load_circuit(json_ctx* c, const cJSON* o, const char* key, cJSON** out) {
    if (!o) return;
    const bool ls = !strcmp(key, "circuit_ls");
    json_only_keys(c, o, key, ls ? (const char* const[]){"nodes", "components", "patch", NULL}
                                 : (const char* const[]){"nodes", "components", NULL});
    json_arr(c, o, key, "nodes", false);
    json_arr(c, o, key, "components", false);
    const cJSON* patch = ls ? json_obj(c, o, key, "patch", false) : NULL;
    const cJSON* it;
    cJSON_ArrayForEach(it, patch) {
        char path[160];
        snprintf(path, sizeof path, "%s.patch.%s", key, it->string);
        const char* dot = strchr(it->string, '.');
        if (!dot || dot == it->string || !dot[1]) json_fail(c, path, "expected \"component.field\" as the key");
        else if (!cJSON_IsString(it) || !it->valuestring[0]) json_fail(c, path, "expected a node name (a string)");
        if (c->failed) return;
    }
    if (c->failed) return;
    *out = cJSON_Duplicate(o, 1);
    if (!*out) json_fail(c, key, "out of memory");
}

// A body must stand on the terrain (centred on the origin): ODE aborted on a
// truck placed 1e30 m away, and off the heightfield there is no ground.
static void check_on_terrain(json_ctx* c, const char* path, const double* pos, bool has_z, const world_terrain* t) {
    if (c->failed) return;
    const double hx = 0.5 * t->size[0], hy = 0.5 * t->size[1];
    if (!(fabs(pos[0]) <= hx && fabs(pos[1]) <= hy)) {
        char x[24], y[24];
        hyd_fmt_num(x, sizeof x, pos[0]);
        hyd_fmt_num(y, sizeof y, pos[1]);
        json_fail(c, path, "must lie on the terrain (|x| <= %g m, |y| <= %g m; terrain.size), got [%s, %s]", hx, hy,
                  x, y);
    } else if (has_z && pos[2] >= 0) {
        char p2[96];
        snprintf(p2, sizeof p2, "%s[2]", path);
        json_range_check(c, p2, pos[2], &R_HEIGHT);
    }
}

// A body's box for the overlap check: centre, half sizes in its own frame,
// heading, and its height interval [m].
typedef struct ovl_box {
    double x, y, hx, hy, yaw, z0, z1;
} ovl_box;

// Separating-axis test of two boxes that are only turned about z: the
// footprints (rectangles) overlap by more than tol on every one of the four
// edge normals, and the height intervals by more than tol.
static bool boxes_overlap(const ovl_box* a, const ovl_box* b, double tol) {
    if (a->z1 - tol <= b->z0 || b->z1 - tol <= a->z0) return false;
    const ovl_box* bx[2] = {a, b};
    for (int k = 0; k < 2; ++k)
        for (int e = 0; e < 2; ++e) {
            const double ang = bx[k]->yaw + (e ? M_PI / 2 : 0), ux = cos(ang), uy = sin(ang);
            double r[2];
            for (int j = 0; j < 2; ++j) {
                const ovl_box* q = bx[j];
                const double c = cos(q->yaw), sn = sin(q->yaw);
                r[j] = q->hx * fabs(c * ux + sn * uy) + q->hy * fabs(-sn * ux + c * uy);
            }
            const double d = fabs((b->x - a->x) * ux + (b->y - a->y) * uy);
            if (d >= r[0] + r[1] - tol) return false;
        }
    return true;
}

// Truck-frame box (centre px, py; half sizes; heights) placed in the world.
static ovl_box truck_part(const world_truck* k, double px, double py, double hx, double hy, double z0, double z1) {
    const double c = cos(k->yaw), s = sin(k->yaw);
    return (ovl_box){k->position[0] + c * px - s * py, k->position[1] + s * px + c * py, hx, hy, k->yaw, z0, z1};
}

// No body may start inside another (the truck, its outriggers, loads and
// obstacles): ODE meets a deep initial penetration with a huge contact
// impulse, and the fuzzer found a fixed wall through the truck aborting ODE.
// Bodies that touch (a stack of boxes) are fine: the tolerance is 1 cm.
static void check_overlaps(json_ctx* c, const world_desc* w) {
    enum { MAXB = 3 + WORLD_DESC_MAX_LOADS + WORLD_DESC_MAX_OBSTACLES };
    ovl_box b[MAXB];
    char name[MAXB][WORLD_DESC_NAME + 16], path[MAXB][64];
    int n = 0;
    const world_truck* k = &w->truck;
    b[n] = truck_part(k, 0, 0, 0.5 * k->chassis[0], 0.5 * k->chassis[1], 0, k->bed_height + k->cab[2]);
    snprintf(name[n], sizeof name[n], "the truck");
    snprintf(path[n++], sizeof path[0], "truck");
    if (k->outriggers)
        for (int a = 0; a < 2; ++a) {
            // Beam and pad on both sides as one strip across the truck.
            const double hx = 0.5 * fmax(0.2, k->pad[0]), hy = 0.5 * (k->outrigger_span + k->pad[1]);
            b[n] = truck_part(k, k->outrigger_x[a], 0, hx, hy, 0, k->bed_height);
            snprintf(name[n], sizeof name[n], "the truck's outriggers");
            snprintf(path[n++], sizeof path[0], "truck.outrigger_x[%d]", a);
        }
    for (int i = 0; i < w->nload + w->nobstacle; ++i) {
        const bool ld = i < w->nload;
        const double* p = ld ? w->load[i].position : w->obstacle[i - w->nload].position;
        const double* sz = ld ? w->load[i].size : w->obstacle[i - w->nload].size;
        // The box's centre is the position; a mesh's bounds sit around its origin.
        const world_obj_mesh* om = ld ? &w->load[i].mesh : &w->obstacle[i - w->nload].mesh;
        const double yaw = ld ? w->load[i].yaw : w->obstacle[i - w->nload].yaw;
        const double cx = 0.5 * (om->lo[0] + om->hi[0]), cy = 0.5 * (om->lo[1] + om->hi[1]);
        b[n] = (ovl_box){p[0] + cos(yaw) * cx - sin(yaw) * cy, p[1] + sin(yaw) * cx + cos(yaw) * cy, 0.5 * sz[0],
                         0.5 * sz[1], yaw, p[2] + om->lo[2], p[2] + om->hi[2]};
        snprintf(name[n], sizeof name[n], "%s \"%s\"", ld ? "load" : "obstacle",
                 ld ? w->load[i].name : w->obstacle[i - w->nload].name);
        if (ld) snprintf(path[n], sizeof path[0], "loads[%d].position", i);
        else snprintf(path[n], sizeof path[0], "obstacles[%d].position", i - w->nload);
        ++n;
    }
    const int ntruck = k->outriggers ? 3 : 1;
    for (int i = ntruck; i < n; ++i)
        for (int j = 0; j < i; ++j)
            if (boxes_overlap(&b[i], &b[j], 0.01)) {
                json_fail(c, path[i], "%s starts inside %s; bodies must not overlap at the start", name[i], name[j]);
                return;
            }
}

// Resolve "rest on the ground" positions (z < 0) now that the terrain is
// known: the lowest point (a box's bottom, a mesh's lowest vertex) on the
// ground under the position.
static void settle_on_ground(const world_desc* w, double* pos, const world_obj_mesh* om) {
    if (pos[2] >= 0) return;
    pos[2] = world_desc_terrain_height(w, pos[0], pos[1]) - om->lo[2];
}

static int from_json_in(const cJSON* root, const char* file, const char* dir, world_desc* w, char* err,
                        size_t errsz) {
    json_ctx c = {.file = file, .err = err, .errsz = errsz};
    char kind[32];
    world_desc_default(w, WORLD_VALIDATION);
    if (!cJSON_IsObject(root)) {
        json_fail(&c, "", "a world must be a JSON object");
        return -1;
    }
    static const char* const keys[] = {"name", "description", "type", "gravity", "ode", "terrain", "truck",
                                       "slew", "circuit", "circuit_ls", "rope", "hook", "loads", "obstacles",
                                       "meshes", NULL};
    if (json_wrong_kind(&c, root, "world")) return -1;
    json_only_keys(&c, root, "", keys);
    json_str(&c, root, "", "type", true, "", kind, sizeof kind);
    if (c.failed) return -1;
    int k = world_kind_parse(kind);
    if (k < 0) {
        json_fail(&c, "type", "must be \"validation\" or \"sandbox\", got \"%s\"", kind);
        return -1;
    }
    world_desc_default(w, (world_kind)k);
    if (k == WORLD_VALIDATION) {
        // The validation world is the lagrange crane in ODE (docs/ode_world.md): no
        // terrain, truck, rope or loads. A sandbox section there would be
        // silently ignored, so it is an error.
        static const char* const vkeys[] = {"name", "description", "type", "gravity", "ode", NULL};
        const cJSON* it;
        cJSON_ArrayForEach(it, root) {
            bool ok = false;
            for (const char* const* a = vkeys; *a && !ok; ++a) ok = !strcmp(*a, it->string);
            if (!ok) {
                json_fail(&c, it->string, "only a sandbox world has this (type is \"validation\")");
                return -1;
            }
        }
    }
    snprintf(w->file, sizeof w->file, "%s", file);
    json_str(&c, root, "", "name", false, w->name, w->name, sizeof w->name);
    if (cJSON_GetObjectItemCaseSensitive(root, "gravity"))
        w->gravity = json_num_r(&c, root, "", "gravity", false, w->gravity, &R_GRAVITY);
    load_ode(&c, json_obj(&c, root, "", "ode", false), &w->ode);
    load_terrain(&c, json_obj(&c, root, "", "terrain", false), &w->terrain, dir);
    load_truck(&c, json_obj(&c, root, "", "truck", false), &w->truck);
    load_slew(&c, json_obj(&c, root, "", "slew", false), &w->slew);
    load_rope(&c, json_obj(&c, root, "", "rope", false), &w->rope);
    load_hook(&c, json_obj(&c, root, "", "hook", false), &w->hook);
    load_loads(&c, json_arr(&c, root, "", "loads", false), w, dir);
    load_obstacles(&c, json_arr(&c, root, "", "obstacles", false), w, dir);
    load_meshes(&c, json_obj(&c, root, "", "meshes", false), w);
    load_circuit(&c, json_obj(&c, root, "", "circuit", false), "circuit", &w->circuit);
    load_circuit(&c, json_obj(&c, root, "", "circuit_ls", false), "circuit_ls", &w->circuit_ls);
    if (!c.failed && w->kind == WORLD_SANDBOX) {
        check_on_terrain(&c, "truck.position", w->truck.position, false, &w->terrain);
        for (int i = 0; i < w->nload && !c.failed; ++i) {
            char p[64];
            snprintf(p, sizeof p, "loads[%d].position", i);
            check_on_terrain(&c, p, w->load[i].position, true, &w->terrain);
        }
        for (int i = 0; i < w->nobstacle && !c.failed; ++i) {
            char p[64];
            snprintf(p, sizeof p, "obstacles[%d].position", i);
            check_on_terrain(&c, p, w->obstacle[i].position, true, &w->terrain);
        }
    }
    if (!c.failed) {
        for (int i = 0; i < w->nload; ++i) settle_on_ground(w, w->load[i].position, &w->load[i].mesh);
        for (int i = 0; i < w->nobstacle; ++i) settle_on_ground(w, w->obstacle[i].position, &w->obstacle[i].mesh);
        if (w->kind == WORLD_SANDBOX) check_overlaps(&c, w);
        // Names must be unique: the snapshot and the CSV address bodies by name.
        for (int i = 0; i < w->nload + w->nobstacle && !c.failed; ++i) {
            const char* a = i < w->nload ? w->load[i].name : w->obstacle[i - w->nload].name;
            for (int j = 0; j < i; ++j) {
                const char* b = j < w->nload ? w->load[j].name : w->obstacle[j - w->nload].name;
                if (!strcmp(a, b)) {
                    char p[64];
                    if (i < w->nload) snprintf(p, sizeof p, "loads[%d].name", i);
                    else snprintf(p, sizeof p, "obstacles[%d].name", i - w->nload);
                    json_fail(&c, p, "duplicate name \"%s\"", a);
                    break;
                }
            }
        }
    }
    json_flush_notes(&c);
    if (c.failed) {
        world_desc_free(w);
        return -1;
    }
    return 0;
}

int world_desc_from_json(const cJSON* root, const char* file, world_desc* w, char* err, size_t errsz) {
    return from_json_in(root, file, "", w, err, errsz);
}

// A world named on the command line (--world NAME is <assets>/worlds/NAME.json)
// that does not exist: list the worlds there instead of "cannot open".
static int missing_named_world(const char* path, char* err, size_t errsz) {
    char folder[512], list[512];
    snprintf(folder, sizeof folder, "%s/worlds/", model_assets_dir());
    const size_t n = strlen(folder);
    struct stat st;
    if (strncmp(path, folder, n) || strchr(path + n, '/') || stat(path, &st) == 0) return 0;
    json_list_files(folder, list, sizeof list);
    const char* base = path + n;
    const size_t bl = strlen(base) > 5 ? strlen(base) - 5 : strlen(base);
    snprintf(err, errsz, "%s %.*s: no such world (available: %s; or the path of a world file)",
             sim_param_name(SIM_PARAM_WORLD), (int)bl, base, list);
    return 1;
}

int world_desc_load(const char* path, world_desc* w, char* err, size_t errsz) {
    memset(w, 0, sizeof *w);
    if (missing_named_world(path, err, errsz)) return -1;
    cJSON* root = json_load_file(path, err, errsz);
    if (!root) return -1;
    const char* base = strrchr(path, '/');
    // Mesh files are relative to the world file's folder, made absolute so
    // the renderer (which resolves bare names against assets/meshes) finds
    // them wherever the program runs.
    char dir[PATH_MAX] = "", cwd[PATH_MAX];
    if (base) snprintf(dir, sizeof dir, "%.*s", (int)(base - path), path);
    if (base == path) snprintf(dir, sizeof dir, "/");
    if (dir[0] != '/' && getcwd(cwd, sizeof cwd)) {
        const size_t lc = strlen(cwd), ld = strlen(dir);
        if (lc + 1 + ld < sizeof dir) {
            memmove(dir + lc + (ld ? 1 : 0), dir, ld + 1);
            memcpy(dir, cwd, lc);
            if (ld) dir[lc] = '/';
        }
    }
    int rc = from_json_in(root, base ? base + 1 : path, dir, w, err, errsz);
    cJSON_Delete(root);
    return rc;
}
