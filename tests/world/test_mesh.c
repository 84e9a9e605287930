// test_mesh.c: CAD meshes in the world: mass properties against the
// analytic solids, the convex hull, a load at rest on a wedge at the height
// its surface gives, a box obstacle against the same box as a mesh, the boom
// stopped by a mesh wall, and the bad-mesh messages.
#include "check.h"

#include "json_util.h"
#include "mesh_geom.h"
#include "model.h"
#include "ode_world.h"
#include "ode_world_internal.h"
#include "scenario.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdint.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static model* g_model;
static char g_dir[512];

// ---- writing meshes ----

typedef struct obj_out {
    FILE* f;
    int nv;
} obj_out;

static int obj_open(obj_out* o, const char* name, char* path, size_t n) {
    snprintf(path, n, "%s/%s", g_dir, name);
    o->f = fopen(path, "w");
    o->nv = 0;
    return o->f ? 0 : -1;
}
static int obj_v(obj_out* o, double x, double y, double z) {
    fprintf(o->f, "v %.9g %.9g %.9g\n", x, y, z);
    return ++o->nv; // OBJ indices start at 1
}
static void obj_f(obj_out* o, int a, int b, int c) { fprintf(o->f, "f %d %d %d\n", a, b, c); }
static void obj_quad(obj_out* o, int a, int b, int c, int d) { fprintf(o->f, "f %d %d %d %d\n", a, b, c, d); }

// A box from lo to hi, outward winding (quads: the reader's fans).
static void write_box(const char* name, const double lo[3], const double hi[3], char* path, size_t n) {
    obj_out o;
    if (obj_open(&o, name, path, n)) return;
    int v[8];
    for (int i = 0; i < 8; ++i) v[i] = obj_v(&o, i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]);
    obj_quad(&o, v[0], v[2], v[3], v[1]); // -z
    obj_quad(&o, v[4], v[5], v[7], v[6]); // +z
    obj_quad(&o, v[0], v[1], v[5], v[4]); // -y
    obj_quad(&o, v[2], v[6], v[7], v[3]); // +y
    obj_quad(&o, v[0], v[4], v[6], v[2]); // -x
    obj_quad(&o, v[1], v[3], v[7], v[5]); // +x
    fclose(o.f);
}

// A box from lo to hi with every face cut into a grid of cells of about
// cell metres (two triangles a cell, as the bench's 50,000-triangle wall and
// as CAD exports of flat faces often are), faces wound outward. bump > 0
// lifts the middle grid vertex of the +z face by bump metres (a shape the
// merge must keep). Returns the triangles written.
static int write_dense_box(const char* name, const double lo[3], const double hi[3], double cell, double bump,
                           char* path, size_t n) {
    obj_out o;
    if (obj_open(&o, name, path, n)) return 0;
    int nt = 0;
    for (int a = 0; a < 3; ++a)
        for (int side = 0; side < 2; ++side) {
            const int u = (a + 1) % 3, v = (a + 2) % 3;
            const int nu = (int)ceil((hi[u] - lo[u]) / cell), nw = (int)ceil((hi[v] - lo[v]) / cell);
            const int base = o.nv + 1;
            for (int j = 0; j <= nw; ++j)
                for (int i = 0; i <= nu; ++i) {
                    double p[3];
                    p[a] = side ? hi[a] : lo[a];
                    p[u] = lo[u] + (hi[u] - lo[u]) * i / nu;
                    p[v] = lo[v] + (hi[v] - lo[v]) * j / nw;
                    if (a == 2 && side && i == nu / 2 && j == nw / 2) p[a] += bump;
                    obj_v(&o, p[0], p[1], p[2]);
                }
            for (int j = 0; j < nw; ++j)
                for (int i = 0; i < nu; ++i) {
                    const int q = base + j * (nu + 1) + i, r = q + nu + 1;
                    if (side) obj_f(&o, q, q + 1, r + 1), obj_f(&o, q, r + 1, r);
                    else obj_f(&o, q, r + 1, q + 1), obj_f(&o, q, r, r + 1);
                    nt += 2;
                }
        }
    fclose(o.f);
    return nt;
}

// A cylinder of radius r, height h along z, base centred at c, seg sides.
static void write_cylinder(const char* name, double r, double h, const double c[3], int seg, char* path, size_t n) {
    obj_out o;
    if (obj_open(&o, name, path, n)) return;
    const int b0 = obj_v(&o, c[0], c[1], c[2]), t0 = obj_v(&o, c[0], c[1], c[2] + h);
    int first = 0;
    for (int i = 0; i < seg; ++i) {
        const double a = 2 * PI * i / seg;
        const int k = obj_v(&o, c[0] + r * cos(a), c[1] + r * sin(a), c[2]);
        obj_v(&o, c[0] + r * cos(a), c[1] + r * sin(a), c[2] + h);
        if (!i) first = k;
    }
    for (int i = 0; i < seg; ++i) {
        const int a = first + 2 * i, b = first + 2 * ((i + 1) % seg);
        obj_f(&o, b0, b, a);
        obj_f(&o, t0, a + 1, b + 1);
        obj_quad(&o, a, b, b + 1, a + 1);
    }
    fclose(o.f);
}

// A wedge: footprint [-L/2, L/2] x [-W/2, W/2], height z0 at x = -L/2
// rising to z1 at x = +L/2.
static void write_wedge(const char* name, double L, double W, double z0, double z1, char* path, size_t n) {
    obj_out o;
    if (obj_open(&o, name, path, n)) return;
    const double x0 = -0.5 * L, x1 = 0.5 * L, y0 = -0.5 * W, y1 = 0.5 * W;
    const int a = obj_v(&o, x0, y0, 0), b = obj_v(&o, x1, y0, 0), c = obj_v(&o, x1, y1, 0), d = obj_v(&o, x0, y1, 0);
    const int e = obj_v(&o, x0, y0, z0), f = obj_v(&o, x1, y0, z1), g = obj_v(&o, x1, y1, z1), h = obj_v(&o, x0, y1, z0);
    obj_quad(&o, a, d, c, b); // bottom
    obj_quad(&o, e, f, g, h); // top slope
    obj_quad(&o, a, b, f, e); // -y
    obj_quad(&o, d, h, g, c); // +y
    obj_quad(&o, a, e, h, d); // -x
    obj_quad(&o, b, c, g, f); // +x
    fclose(o.f);
}

// ---- worlds ----

// The shipped sandbox with its loads and obstacles replaced by the JSON
// arrays given (text), built into d. 0, or -1 with err.
static int sandbox_with(const char* loads, const char* obstacles, world_desc* d, char* err, size_t errsz) {
    cJSON* root = json_load_file(CRANESIM_ASSETS "/worlds/sandbox.json", err, errsz);
    if (!root) return -1;
    cJSON_DeleteItemFromObjectCaseSensitive(root, "loads");
    cJSON_DeleteItemFromObjectCaseSensitive(root, "obstacles");
    if (loads) cJSON_AddItemToObject(root, "loads", cJSON_Parse(loads));
    if (obstacles) cJSON_AddItemToObject(root, "obstacles", cJSON_Parse(obstacles));
    int rc = world_desc_from_json(root, "test_world.json", d, err, errsz);
    cJSON_Delete(root);
    return rc;
}

static ode_world* make(const world_desc* d, double q1, double q2, double slew0) {
    char err[512] = "";
    ode_world_opts o = ode_world_default_opts();
    o.q0[0] = q1 * DEG, o.q0[1] = q2 * DEG, o.slew0 = slew0 * DEG;
    o.model_file = "hiab031.json";
    ode_world* w = ode_world_create(&g_model->mech, cJSON_GetObjectItemCaseSensitive(g_model->json, "hydraulics"), d,
                                    &o, err, sizeof err);
    if (!w) fprintf(stderr, "create: %s\n", err);
    return w;
}

// ---- mass properties ----

static void test_mass_cube(void) {
    char path[600], err[256];
    const double lo[3] = {0, 1.5, 2.75}, hi[3] = {2, 2.5, 3.25}; // 2 x 1 x 0.5 m about (1, 2, 3)
    write_box("cube.obj", lo, hi, path, sizeof path);
    mesh_tri t;
    CHECK(mesh_load(path, 1.0, 2, &t, err, sizeof err) == 0, "load: %s", err);
    CHECK(t.nv == 8 && t.nt == 12, "welded %d vertices, %d triangles", t.nv, t.nt);
    CHECK(mesh_open_edges(&t) == 0, "closed");
    double V, c[3], I[9];
    CHECK(mesh_mass_props(&t, &V, c, I) == 0, "props");
    // Per unit density: V = abc, I_xx = V (b^2 + c^2) / 12, no products.
    const double a = 2, b = 1, h = 0.5;
    CHECK_REL(V, a * b * h, 1e-6);
    CHECK_NEAR(c[0], 1, 1e-6);
    CHECK_NEAR(c[1], 2, 1e-6);
    CHECK_NEAR(c[2], 3, 1e-6);
    CHECK_REL(I[0], V * (b * b + h * h) / 12, 1e-5);
    CHECK_REL(I[4], V * (a * a + h * h) / 12, 1e-5);
    CHECK_REL(I[8], V * (a * a + b * b) / 12, 1e-5);
    CHECK(fabs(I[1]) < 1e-6 && fabs(I[2]) < 1e-6 && fabs(I[5]) < 1e-6, "products %g %g %g", I[1], I[2], I[5]);
    // Inside-out winding gives the same solid.
    for (int k = 0; k < t.nt; ++k) {
        int s = t.idx[3 * k + 1];
        t.idx[3 * k + 1] = t.idx[3 * k + 2];
        t.idx[3 * k + 2] = s;
    }
    double V2, c2[3], I2[9];
    CHECK(mesh_mass_props(&t, &V2, c2, I2) == 0 && fabs(V2 - V) < 1e-9 && fabs(I2[0] - I[0]) < 1e-9, "flipped");
    mesh_free(&t);
}

static void test_mass_cylinder(void) {
    char path[600], err[256];
    const double r = 0.5, h = 1.2, base[3] = {-3, 4, 0.5};
    write_cylinder("cyl.obj", r, h, base, 256, path, sizeof path);
    // y-up conversion and a scale: the file is in the same units, so scale
    // 2 doubles every length: V x 8, I x 32 per unit density.
    mesh_tri t;
    CHECK(mesh_load(path, 2.0, 2, &t, err, sizeof err) == 0, "load: %s", err);
    CHECK(mesh_open_edges(&t) == 0, "closed");
    double V, c[3], I[9];
    CHECK(mesh_mass_props(&t, &V, c, I) == 0, "props");
    const double R = 2 * r, H = 2 * h, Va = PI * R * R * H;
    CHECK_REL(V, Va, 0.01);
    CHECK_NEAR(c[0], 2 * base[0], 1e-4);
    CHECK_NEAR(c[1], 2 * base[1], 1e-4);
    CHECK_NEAR(c[2], 2 * (base[2] + 0.5 * h), 1e-4);
    CHECK_REL(I[8], Va * R * R / 2, 0.01);
    CHECK_REL(I[0], Va * (3 * R * R + H * H) / 12, 0.01);
    CHECK_REL(I[4], Va * (3 * R * R + H * H) / 12, 0.01);
    // Its hull: every rim vertex is on it, the centres of the caps are not.
    double* p = malloc((size_t)3 * t.nv * sizeof *p);
    for (int i = 0; i < 3 * t.nv; ++i) p[i] = t.v[i];
    mesh_hull hl;
    CHECK(mesh_hull_build(p, t.nv, &hl) == 0, "hull");
    // (a cap centre lies on the hull's cap plane: it may be kept or not)
    CHECK(hl.nv >= 2 * 256 && hl.nv <= 2 * 256 + 2, "hull vertices %d", hl.nv);
    // Every vertex inside or on every plane.
    double worst = 0;
    for (int f = 0; f < hl.nf; ++f)
        for (int i = 0; i < t.nv; ++i) {
            const double s = hl.plane[4 * f] * p[3 * i] + hl.plane[4 * f + 1] * p[3 * i + 1] +
                             hl.plane[4 * f + 2] * p[3 * i + 2] - hl.plane[4 * f + 3];
            if (s > worst) worst = s;
        }
    CHECK(worst < 1e-6, "a point %g m outside the hull", worst);
    mesh_hull_free(&hl);
    free(p);
    mesh_free(&t);
    // y-up: the cylinder's axis (file z) becomes world -y.
    CHECK(mesh_load(path, 1.0, 1, &t, err, sizeof err) == 0, "load y-up");
    double lo[3], hi[3];
    mesh_bounds(&t, lo, hi);
    CHECK_NEAR(hi[1] - lo[1], h, 1e-5);
    CHECK_NEAR(hi[2] - lo[2], 2 * r, 1e-3);
    mesh_free(&t);
}

// The world's meshed load gets the closed mesh's mass properties in ODE.
static void test_load_mass_in_world(void) {
    char path[600], err[512], loads[1200];
    const double lo[3] = {-0.5, -0.3, 0}, hi[3] = {0.5, 0.3, 0.4};
    write_box("crate.obj", lo, hi, path, sizeof path);
    snprintf(loads, sizeof loads,
             "[{\"name\": \"crate\", \"mesh\": {\"file\": \"%s\"}, \"density\": 500, \"position\": [4, -3]}]", path);
    world_desc d;
    if (sandbox_with(loads, NULL, &d, err, sizeof err)) {
        CHECK(0, "world: %s", err);
        return;
    }
    CHECK_REL(d.load[0].mass, 500 * 0.24, 1e-6);
    CHECK_NEAR(d.load[0].position[2], 0.0, 1e-9); // lowest point on the flat ground
    ode_world* w = make(&d, 117.3, -65.8, -60);
    if (!w) { CHECK(0, "world"); world_desc_free(&d); return; }
    dMass m;
    dBodyGetMass(w->load[0], &m);
    CHECK_REL(m.mass, 120, 1e-6); // float vertices
    CHECK_REL(m.I[0], 120 * (0.6 * 0.6 + 0.4 * 0.4) / 12, 1e-5);
    CHECK_REL(m.I[5], 120 * (1.0 + 0.4 * 0.4) / 12, 1e-5);
    CHECK_REL(m.I[10], 120 * (1.0 + 0.6 * 0.6) / 12, 1e-5);
    // Body origin at the centre of mass: 0.2 m above the ground.
    double p[3], v[3];
    ode_world_load_state(w, 0, p, v);
    CHECK_NEAR(p[2], 0.2, 1e-6);
    ode_world_destroy(w);
    world_desc_free(&d);
}

// ---- contact geometry ----

// A 0.4 m box load dropped onto a static wedge comes to rest on the slope,
// its centre h/2 / cos(theta) above the surface under it, far below the
// wedge's bounding box top (1.2 m).
static void test_rest_on_wedge(void) {
    char path[600], err[512], obst[1200];
    const double L = 3, z0 = 0.2, z1 = 1.2, hb = 0.4;
    write_wedge("wedge.obj", L, 2, z0, z1, path, sizeof path);
    snprintf(obst, sizeof obst,
             "[{\"name\": \"wedge\", \"kind\": \"building\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-6, -9], "
             "\"friction\": 1.2}]",
             path);
    world_desc d;
    if (sandbox_with("[{\"name\": \"box\", \"mass\": 100, \"size\": [0.4, 0.4, 0.4], \"position\": [-6, -9, 1.6], "
                     "\"friction\": 1.2}]",
                     obst, &d, err, sizeof err)) {
        CHECK(0, "world: %s", err);
        return;
    }
    CHECK_NEAR(d.obstacle[0].position[2], 0, 1e-9);
    ode_world* w = make(&d, 117.3, -65.8, -60);
    if (!w) { CHECK(0, "world"); world_desc_free(&d); return; }
    for (int i = 0; i < 300; ++i)
        if (ode_world_step(w, 0.01)) {
            CHECK(0, "step: %s", ode_world_error(w));
            break;
        }
    double p[3], v[3];
    ode_world_load_state(w, 0, p, v);
    const double slope = (z1 - z0) / L, ct = 1 / sqrt(1 + slope * slope);
    const double surf = z0 + slope * (p[0] - (-6) + 0.5 * L);
    CHECK_NEAR(p[2], surf + 0.5 * hb / ct, 2e-3);
    CHECK(p[2] < z1, "below the bounding box top");
    CHECK(sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) < 0.01, "at rest (%.3g m/s)",
          sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    ode_world_destroy(w);
    world_desc_free(&d);
}

// A load pushed along the ground into a fixed block at 45 deg slides along
// it; the block as a box and as a box-shaped mesh give the same path.
static void slide_path(const char* obst, double out[3], double* min_x) {
    char err[512];
    world_desc d;
    if (sandbox_with("[{\"name\": \"l\", \"mass\": 300, \"size\": [0.6, 0.6, 0.5], \"position\": [-6, -8], "
                     "\"friction\": 0.3}]",
                     obst, &d, err, sizeof err)) {
        CHECK(0, "world: %s", err);
        return;
    }
    ode_world* w = make(&d, 117.3, -65.8, -60);
    if (!w) { CHECK(0, "world"); world_desc_free(&d); return; }
    dBodySetLinearVel(w->load[0], 2.0, -2.0, 0);
    *min_x = 1e9;
    for (int i = 0; i < 200; ++i) {
        if (ode_world_step(w, 0.01)) {
            CHECK(0, "step: %s", ode_world_error(w));
            break;
        }
        double p[3], v[3];
        ode_world_load_state(w, 0, p, v);
        if (p[1] < *min_x) *min_x = p[1];
    }
    double v[3];
    ode_world_load_state(w, 0, out, v);
    ode_world_destroy(w);
    world_desc_free(&d);
}

static void test_box_vs_mesh_box(void) {
    char path[600], obst[1200];
    const double lo[3] = {-2, -0.5, 0}, hi[3] = {2, 0.5, 1};
    write_box("block.obj", lo, hi, path, sizeof path);
    double pa[3], pb[3], ya, yb;
    slide_path("[{\"name\": \"b\", \"kind\": \"box\", \"size\": [4, 1, 1], \"position\": [-4, -10]}]", pa, &ya);
    snprintf(obst, sizeof obst,
             "[{\"name\": \"b\", \"kind\": \"box\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-4, -10]}]", path);
    slide_path(obst, pb, &yb);
    // Turned by -35 deg (both the same way): the mesh turns with its yaw.
    double qa[3], qb[3], za, zb;
    slide_path("[{\"name\": \"b\", \"kind\": \"box\", \"size\": [4, 1, 1], \"position\": [-4, -10], "
               "\"yaw_deg\": -35}]", qa, &za);
    snprintf(obst, sizeof obst,
             "[{\"name\": \"b\", \"kind\": \"box\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-4, -10], "
             "\"yaw_deg\": -35}]", path);
    slide_path(obst, qb, &zb);
    CHECK(hypot(qa[0] - pa[0], qa[1] - pa[1]) > 0.05, "the turned block changes the path (%.3f %.3f vs %.3f %.3f)", qa[0], qa[1], pa[0], pa[1]);
    CHECK_NEAR(qb[0], qa[0], 0.02);
    CHECK_NEAR(qb[1], qa[1], 0.02);
    // The load stops against the block's face at y = -9.5 (its half width
    // 0.3 m): it must not pass it, and both paths agree.
    CHECK(ya > -9.5 + 0.25 && yb > -9.5 + 0.25, "stopped at the face: box %.3f, mesh %.3f", ya, yb);
    CHECK(pa[0] > -6 + 0.2, "slid along the face (x %.3f)", pa[0]);
    CHECK_NEAR(pb[0], pa[0], 0.02);
    CHECK_NEAR(pb[1], pa[1], 0.02);
    CHECK_NEAR(pb[2], pa[2], 0.005);
    // The block with its faces cut into 5 cm cells slides the load the same.
    double pc[3], yc;
    write_dense_box("block_dense.obj", lo, hi, 0.05, 0, path, sizeof path);
    snprintf(obst, sizeof obst,
             "[{\"name\": \"b\", \"kind\": \"box\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-4, -10]}]", path);
    slide_path(obst, pc, &yc);
    CHECK(yc > -9.5 + 0.25, "stopped at the dense block's face: %.3f", yc);
    CHECK_NEAR(pc[0], pa[0], 0.02);
    CHECK_NEAR(pc[1], pa[1], 0.02);
    CHECK_NEAR(pc[2], pa[2], 0.005);
}

// The sandbox_wall scenario with its radial wall as a mesh: the end arm
// stops at it (a crane contact: the COLLISION warning) and does not pass.
static void boom_mesh_wall(const char* path, int nt_file) {
    char err[512];
    cJSON* root = json_load_file(CRANESIM_ASSETS "/worlds/sandbox.json", err, sizeof err);
    if (!root) { CHECK(0, "%s", err); return; }
    cJSON* obs = cJSON_GetObjectItemCaseSensitive(root, "obstacles");
    cJSON* wall = cJSON_GetArrayItem(obs, 0); // wall_slew
    cJSON_DeleteItemFromObjectCaseSensitive(wall, "size");
    cJSON* pos = cJSON_GetObjectItemCaseSensitive(wall, "position");
    cJSON_AddItemToArray(pos, cJSON_CreateNumber(0)); // mesh origin on the ground
    cJSON* m = cJSON_AddObjectToObject(wall, "mesh");
    cJSON_AddStringToObject(m, "file", path);
    world_desc d;
    int rc = world_desc_from_json(root, "wall_world.json", &d, err, sizeof err);
    cJSON_Delete(root);
    if (rc) { CHECK(0, "world: %s", err); return; }
    CHECK(d.obstacle[0].mesh.file[0] && d.obstacle[0].mass == 0, "a static mesh wall");
    scenario sc;
    if (scenario_load(CRANESIM_ASSETS "/scenarios/sandbox_wall.json", &sc, err, sizeof err)) {
        CHECK(0, "%s", err);
        world_desc_free(&d);
        return;
    }
    ode_world* w = make(&d, sc.q0[0] / DEG, sc.q0[1] / DEG, sc.slew0 / DEG);
    if (!w) { CHECK(0, "world"); world_desc_free(&d); return; }
    // The ODE trimesh is the wall's 12 triangles however finely the file
    // cuts its faces.
    int mk = -1;
    for (int k = 0; k < w->nmesh; ++k)
        if (w->mesh[k].tmd) mk = k;
    CHECK(mk >= 0 && w->mesh[mk].nt == 12 && w->mesh[mk].nt_file == nt_file, "trimesh of %d triangles from %d",
          mk >= 0 ? w->mesh[mk].nt : -1, mk >= 0 ? w->mesh[mk].nt_file : -1);
    double depth = 0, slew10 = 0;
    int collision = 0;
    static world_snapshot snap;
    for (long i = 0; i < (long)(sc.duration / 0.01 + 0.5); ++i) {
        double u[3];
        for (int k = 0; k < 3; ++k) u[k] = scenario_command(&sc, k, i * 0.01);
        ode_world_set_commands(w, u);
        if (ode_world_step(w, 0.01)) {
            CHECK(0, "step: %s", ode_world_error(w));
            break;
        }
        ode_world_state s;
        ode_world_get_state(w, &s);
        if (s.max_depth_crane > depth) depth = s.max_depth_crane;
        if (i == 1000) slew10 = s.slew;
        ode_world_snapshot(w, &snap);
        collision |= snap.collision;
    }
    ode_world_state s;
    ode_world_get_state(w, &s);
    CHECK(s.slew > 45 * DEG && s.slew < 60 * DEG, "slew stopped at %.2f deg", s.slew / DEG);
    // At rest while pushing: the mean slew rate of the last 2 s (the
    // trimesh contact jitters by about 1e-3 rad/s about it).
    CHECK(fabs(s.slew - slew10) / 2 < 1e-3, "slew at rest (%.2g rad/s mean, %.2g now) while pushing",
          (s.slew - slew10) / 2, s.slew_rate);
    CHECK(collision, "COLLISION flagged");
    CHECK(depth > 0 && depth < 5e-3, "penetration %.4f m", depth);
    ode_world_destroy(w);
    world_desc_free(&d);
}

// ---- flat faces merged (mesh_merge_coplanar) ----

static double mesh_area(const mesh_tri* m) {
    double A = 0;
    for (int f = 0; f < m->nt; ++f) {
        const float* a = m->v + 3 * m->idx[3 * f];
        const float* b = m->v + 3 * m->idx[3 * f + 1];
        const float* c = m->v + 3 * m->idx[3 * f + 2];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2], z = u[0] * w[1] - u[1] * w[0];
        A += 0.5 * sqrt(x * x + y * y + z * z);
    }
    return A;
}

// A box cut into 0.05 m cells is a box: 12 triangles on its 8 corners, the
// same closed surface (area, volume and bounds of the analytic box).
static void test_merge_flat_box(void) {
    char path[600], err[256];
    const double lo[3] = {-1.25, -0.15, 0}, hi[3] = {1.25, 0.15, 4.5};
    const int nt = write_dense_box("dense_box.obj", lo, hi, 0.05, 0, path, sizeof path);
    mesh_tri t;
    if (mesh_load(path, 1, 2, &t, err, sizeof err)) { CHECK(0, "load: %s", err); return; }
    CHECK(t.nt == nt && nt > 10000, "%d triangles loaded of %d", t.nt, nt);
    const int removed = mesh_merge_coplanar(&t, MESH_FLAT_TOL_RAD, MESH_FLAT_TOL_M);
    CHECK(removed == nt - 12 && t.nt == 12 && t.nv == 8, "%d triangles, %d vertices left (removed %d)", t.nt, t.nv,
          removed);
    CHECK(mesh_open_edges(&t) == 0, "still closed");
    const double L[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    CHECK_NEAR(mesh_area(&t), 2 * (L[0] * L[1] + L[1] * L[2] + L[0] * L[2]), 1e-4);
    double V, c[3], I[9], blo[3], bhi[3];
    CHECK(mesh_mass_props(&t, &V, c, I) == 0, "volume");
    CHECK_NEAR(V, L[0] * L[1] * L[2], 1e-5);
    mesh_bounds(&t, blo, bhi);
    for (int k = 0; k < 3; ++k) {
        CHECK_NEAR(blo[k], lo[k], 1e-6);
        CHECK_NEAR(bhi[k], hi[k], 1e-6);
    }
    // mesh_load_flat gives the merged mesh (cached the second time), and
    // mesh_load of the same file still the file's own triangles.
    mesh_tri a, b, c0;
    const unsigned long long p0 = mesh_cache_parses();
    CHECK(mesh_load_flat(path, 1, 2, &a, err, sizeof err) == 0, "load flat: %s", err);
    CHECK(mesh_load_flat(path, 1, 2, &b, err, sizeof err) == 0, "load flat again: %s", err);
    CHECK(mesh_load(path, 1, 2, &c0, err, sizeof err) == 0, "load: %s", err);
    CHECK(mesh_cache_parses() == p0, "no parse (%llu)", mesh_cache_parses() - p0);
    CHECK(a.nt == 12 && b.nt == 12 && a.merged == nt - 12 && b.merged == nt - 12 && a.nv == t.nv &&
              !memcmp(a.v, t.v, 3 * sizeof(float) * t.nv) && !memcmp(b.idx, t.idx, 3 * sizeof(int) * t.nt),
          "flat loads: %d and %d triangles, as merged here", a.nt, b.nt);
    CHECK(c0.nt == nt && c0.merged == 0, "mesh_load unmerged (%d triangles)", c0.nt);
    mesh_free(&a);
    mesh_free(&b);
    mesh_free(&c0);
    mesh_free(&t);
}

// What is not flat stays: a 2 mm bump on a finely cut face keeps its vertex
// and the volume its cone adds, and a cylinder keeps every side facet (only
// the caps' centre vertices go, two triangles each).
static void test_merge_keeps_shape(void) {
    char path[600], err[256];
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0.5}, bump = 2e-3;
    write_dense_box("bump_box.obj", lo, hi, 0.05, bump, path, sizeof path);
    mesh_tri t;
    if (mesh_load(path, 1, 2, &t, err, sizeof err)) { CHECK(0, "load: %s", err); return; }
    double V0, V1, c[3], I[9];
    CHECK(mesh_mass_props(&t, &V0, c, I) == 0, "volume");
    const double A0 = mesh_area(&t);
    CHECK(V0 - 0.5 > 1e-7, "the bump adds volume (%.3g m^3)", V0 - 0.5);
    CHECK(mesh_merge_coplanar(&t, MESH_FLAT_TOL_RAD, MESH_FLAT_TOL_M) > 0, "merged");
    int found = 0;
    for (int i = 0; i < t.nv; ++i)
        found |= fabs(t.v[3 * i] - 0.5) < 1e-6 && fabs(t.v[3 * i + 1] - 0.5) < 1e-6 &&
                 fabs(t.v[3 * i + 2] - (0.5 + bump)) < 1e-6;
    CHECK(found, "the bump's vertex is kept");
    CHECK(mesh_mass_props(&t, &V1, c, I) == 0, "volume after");
    CHECK_NEAR(V1, V0, 1e-9);
    CHECK_NEAR(mesh_area(&t), A0, 1e-6);
    CHECK(mesh_open_edges(&t) == 0, "still closed");
    CHECK(t.nt < 40, "the flat parts merged (%d triangles)", t.nt);
    mesh_free(&t);

    const int seg = 48;
    write_cylinder("merge_cyl.obj", 0.5, 1.0, (const double[3]){0, 0, 0}, seg, path, sizeof path);
    if (mesh_load(path, 1, 2, &t, err, sizeof err)) { CHECK(0, "load: %s", err); return; }
    CHECK(t.nt == 4 * seg && t.nv == 2 * seg + 2, "cylinder as written (%d, %d)", t.nt, t.nv);
    CHECK(mesh_mass_props(&t, &V0, c, I) == 0, "volume");
    CHECK(mesh_merge_coplanar(&t, MESH_FLAT_TOL_RAD, MESH_FLAT_TOL_M) == 4, "the caps' centres go");
    CHECK(t.nt == 4 * seg - 4 && t.nv == 2 * seg, "%d triangles, %d vertices", t.nt, t.nv);
    CHECK(mesh_mass_props(&t, &V1, c, I) == 0, "volume after");
    CHECK_NEAR(V1, V0, 1e-9);
    mesh_free(&t);
}

static void test_boom_mesh_wall(void) {
    char path[600];
    const double lo[3] = {-1.25, -0.15, 0}, hi[3] = {1.25, 0.15, 4.5};
    write_box("wall.obj", lo, hi, path, sizeof path);
    boom_mesh_wall(path, 12);
    // The same wall cut into 5 cm cells (10,000 triangles and more).
    const int nt = write_dense_box("wall_dense.obj", lo, hi, 0.05, 0, path, sizeof path);
    boom_mesh_wall(path, nt);
}

// ---- the convex hull bounded (issue 25, item 23) ----

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// The hull as a mesh: closed and consistently wound (every edge twice, once
// each way), Euler V - E + F = 2, every point inside or within the hull's
// tolerance of every plane; its volume returned.
static double check_hull(const mesh_hull* h, const double* P, int n) {
    mesh_tri t = {.nv = h->nv, .nt = h->nf};
    t.v = malloc((size_t)3 * h->nv * sizeof *t.v);
    t.idx = malloc((size_t)3 * h->nf * sizeof *t.idx);
    for (int i = 0; i < 3 * h->nv; ++i) t.v[i] = (float)h->v[i];
    memcpy(t.idx, h->f, (size_t)3 * h->nf * sizeof *t.idx);
    CHECK(mesh_open_edges(&t) == 0, "the hull is closed and consistently wound");
    const int E = 3 * h->nf / 2;
    CHECK(3 * h->nf % 2 == 0 && h->nv - E + h->nf == 2, "Euler: V %d - E %d + F %d = %d", h->nv, E, h->nf,
          h->nv - E + h->nf);
    double worst = -INFINITY;
    for (int i = 0; i < n; ++i) {
        double w = -INFINITY;
        for (int f = 0; f < h->nf; ++f) {
            const double* pl = h->plane + 4 * f;
            const double s = pl[0] * P[3 * i] + pl[1] * P[3 * i + 1] + pl[2] * P[3 * i + 2] - pl[3];
            if (s > w) w = s;
        }
        if (w > worst) worst = w;
    }
    CHECK(worst <= h->tol + 1e-12, "a point %g m outside the hull (tolerance %g m)", worst, h->tol);
    double V = 0, c[3], I[9];
    CHECK(mesh_mass_props(&t, &V, c, I) == 0, "hull volume");
    mesh_free(&t);
    return V;
}

static void test_hull_bounded(void) {
    // 505 points: the corners of a 2 x 1 x 0.5 m box and 497 points on its
    // faces with float rounding (6e-8 of the size off the face, as a finely
    // cut CAD face in float coordinates): the earlier hull built 79,151
    // faces from such a cloud in 13.6 s (and more from 200 such points).
    enum { N = 505 };
    static double P[3 * N];
    const double L[3] = {2, 1, 0.5};
    unsigned r = 12345;
    for (int i = 0; i < N; ++i) {
        double q[3];
        if (i < 8) {
            for (int k = 0; k < 3; ++k) q[k] = (i >> k & 1) ? L[k] / 2 : -L[k] / 2;
        } else {
            const int face = i % 6, ax = face / 2;
            for (int k = 0; k < 3; ++k) {
                r = r * 1103515245u + 12345u;
                q[k] = ((r >> 8) / 16777216.0 - 0.5) * L[k];
            }
            r = r * 1103515245u + 12345u;
            q[ax] = (face & 1 ? 0.5 : -0.5) * L[ax] + ((r >> 8) / 16777216.0 - 0.5) * 2.4e-7;
        }
        for (int k = 0; k < 3; ++k) P[3 * i + k] = (float)q[k];
    }
    mesh_hull h;
    double t0 = now_s();
    CHECK(mesh_hull_build(P, N, &h) == 0, "hull of 505 points");
    const double dt = now_s() - t0;
    printf("505 points: %.3f s\n", dt); // reported, not checked: speed lives in benchmarks
    CHECK(h.nf <= MESH_HULL_MAX_FACES && h.nf <= 2 * h.nv - 4, "%d faces for %d vertices", h.nf, h.nv);
    // The box: 8 corners; the face points lie within the tolerance.
    CHECK(h.nv == 8 && h.nf == 12, "the box's hull: %d vertices, %d faces (tolerance %g m)", h.nv, h.nf, h.tol);
    CHECK_REL(check_hull(&h, P, N), L[0] * L[1] * L[2], 1e-6);
    mesh_hull_free(&h);
    // The same points with no noise, and exactly on the faces: the same box.
    for (int i = 8; i < N; ++i) {
        const int ax = i % 6 / 2;
        P[3 * i + ax] = (i % 6 & 1 ? 0.5 : -0.5) * L[ax];
    }
    CHECK(mesh_hull_build(P, N, &h) == 0, "hull, exact faces");
    CHECK_REL(check_hull(&h, P, N), L[0] * L[1] * L[2], 1e-9);
    CHECK(h.nf <= 2 * h.nv - 4 && h.nf <= MESH_HULL_MAX_FACES, "%d faces for %d vertices", h.nf, h.nv);
    mesh_hull_free(&h);
    // 20,000 points on a sphere of radius 1 m (a Fibonacci lattice): every
    // one is a hull vertex, 39,996 faces exactly; bounded to the cap by the
    // tolerance, the volume between the ball's and that of the ball shrunk
    // by the tolerance.
    enum { M = 20000 };
    static double S[3 * M];
    for (int i = 0; i < M; ++i) {
        const double z = 1 - (2.0 * i + 1) / M, rr = sqrt(1 - z * z), a = i * PI * (3 - sqrt(5.0));
        S[3 * i] = rr * cos(a), S[3 * i + 1] = rr * sin(a), S[3 * i + 2] = z;
    }
    t0 = now_s();
    CHECK(mesh_hull_build(S, M, &h) == 0, "hull of 20,000 sphere points");
    const double ds = now_s() - t0;
    // Reported, not checked (speed lives in benchmarks); the face cap below is
    // what bounds the work, and ctest's timeout catches a hang (0.24 s in
    // Release; 56.7 s before the exact predicates).
    printf("20,000 sphere points: %.3f s\n", ds);
    CHECK(h.nf <= MESH_HULL_MAX_FACES, "%d faces", h.nf);
    CHECK(h.tol <= 0.02 * 1.0001, "tolerance %g m", h.tol);
    const double Vs = check_hull(&h, S, M), Vball = 4.0 / 3.0 * PI;
    CHECK(Vs <= Vball && Vs >= 4.0 / 3.0 * PI * pow(1 - h.tol, 3) * 0.98, "sphere hull volume %g (ball %g)", Vs, Vball);
    mesh_hull_free(&h);
    // Four points on a plane: no volume.
    const double flat[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    CHECK(mesh_hull_build(flat, 4, &h) == -1, "flat refused");
}

// Many clouds of the kinds that find faults: points on the faces of a unit
// cube scattered by 1e-7 (float CAD faces), and very flat boxes (1e-3 by 1 by
// 1e3 m). Each hull closed, Euler, at most 2n - 4 faces, and every point
// within its tolerance of every plane (before the planes were taken from the
// exact grid, a sliver's plane through the given points had a point 8e-5 of
// the size above it, and 52 of 3,000 clouds one more than 1e-9 above).
static void test_hull_stress(void) {
    int clouds = 0, faults = 0, flat = 0;
    static double P[3 * 3004];
    for (int seed = 1; seed <= 2100; ++seed) {
        if (seed % 9 != 4 && seed % 9 != 7) continue;
        unsigned r = (unsigned)seed;
#define RND() (r = r * 1103515245u + 12345u, (r >> 8) / 16777216.0)
        const int n = 4 + (int)(RND() * (seed % 7 == 0 ? 3000 : 200));
        for (int i = 0; i < n; ++i) {
            double q[3];
            for (int k = 0; k < 3; ++k) q[k] = RND();
            if (seed % 9 == 4) {
                const int ax = i % 6 / 2;
                q[ax] = (i % 6 & 1) ? 1 : 0;
                q[ax] += 1e-7 * (RND() - 0.5);
                for (int k = 0; k < 3; ++k) q[k] = (float)q[k];
            } else {
                q[0] *= 1e-3, q[1] *= 1e3;
            }
            for (int k = 0; k < 3; ++k) P[3 * i + k] = q[k];
        }
#undef RND
        mesh_hull h;
        const int rc = mesh_hull_build(P, n, &h);
        // A flat box is 1e-3 m thick on 1e3 m: at the flatness threshold
        // (1e-6 of the size), so some are refused as flat; no cube may be.
        if (rc == -1 && seed % 9 == 7) {
            ++flat;
            continue;
        }
        if (rc) {
            ++faults;
            fprintf(stderr, "  seed %d: hull %d\n", seed, rc);
            continue;
        }
        ++clouds;
        const int before = check_failures_;
        (void)check_hull(&h, P, n);
        if (h.nf > 2 * h.nv - 4) CHECK(0, "seed %d: %d faces for %d vertices", seed, h.nf, h.nv);
        if (check_failures_ != before) {
            ++faults;
            fprintf(stderr, "  (seed %d, %d points)\n", seed, n);
        }
        mesh_hull_free(&h);
    }
    CHECK(faults == 0 && clouds > 300, "%d of %d clouds faulty (%d flat)", faults, clouds, flat);
    printf("  %d clouds, %d flat boxes refused as flat\n", clouds, flat);
}

// Cancelling (the app's SIGINT flag): the hull and the parser stop at the
// next poll. The flag is raised after a few polls, so the loops are under way.
static int g_polls, g_stop_after;
static int cancel_after(void) { return ++g_polls > g_stop_after; }

static void test_cancel(void) {
    enum { M = 20000 };
    static double S[3 * M];
    for (int i = 0; i < M; ++i) {
        const double z = 1 - (2.0 * i + 1) / M, rr = sqrt(1 - z * z), a = i * PI * (3 - sqrt(5.0));
        S[3 * i] = rr * cos(a), S[3 * i + 1] = rr * sin(a), S[3 * i + 2] = z;
    }
    mesh_hull h;
    g_polls = 0, g_stop_after = 50;
    mesh_set_cancel(cancel_after);
    CHECK(mesh_hull_build(S, M, &h) == -3 && h.nf == 0, "hull cancelled");
    CHECK(g_polls == 51, "stopped at the first poll after the flag (%d polls)", g_polls);
    // A 20,000-triangle OBJ (a dense box) stops in its parse.
    char path[600], err[256];
    write_dense_box("cancel_box.obj", (const double[3]){0, 0, 0}, (const double[3]){1, 1, 1}, 0.02, 0, path,
                    sizeof path);
    mesh_cache_clear();
    g_polls = 0, g_stop_after = 2;
    mesh_tri t;
    CHECK(mesh_load(path, 1, 2, &t, err, sizeof err) == -1 && !strcmp(err, "interrupted"), "parse cancelled: %s", err);
    mesh_set_cancel(NULL);
    CHECK(mesh_load(path, 1, 2, &t, err, sizeof err) == 0, "loads without the flag: %s", err);
    mesh_free(&t);
    CHECK(mesh_hull_build(S, M, &h) == 0, "hull without the flag");
    mesh_hull_free(&h);
}

// ---- bad meshes ----

static void expect_bad(const char* loads, const char* obst, const char* want1, const char* want2) {
    char err[1024] = "";
    world_desc d;
    int rc = sandbox_with(loads, obst, &d, err, sizeof err);
    CHECK(rc == -1, "refused (%s)", want1);
    if (rc == 0) world_desc_free(&d);
    CHECK(strstr(err, want1) && (!want2 || strstr(err, want2)) && !strchr(err, '\n'), "message: %s", err);
}

static void test_bad_meshes(void) {
    char path[600], p2[600], buf[1400];
    // Missing file.
    expect_bad(NULL, "[{\"name\": \"x\", \"mesh\": {\"file\": \"/nonexistent/site.obj\"}, \"position\": [-6, -9]}]",
               "obstacles[0].mesh.file: /nonexistent/site.obj", "cannot open the mesh file");
    // Empty mesh.
    obj_out o;
    obj_open(&o, "empty.obj", path, sizeof path);
    fprintf(o.f, "# nothing\n");
    fclose(o.f);
    snprintf(buf, sizeof buf, "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-6, -9]}]", path);
    expect_bad(NULL, buf, "empty.obj", "no triangles");
    // Unreadable: a face that names no vertex.
    obj_open(&o, "broken.obj", path, sizeof path);
    fprintf(o.f, "v 0 0 0\nf 1 2 3\n");
    fclose(o.f);
    snprintf(buf, sizeof buf, "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-6, -9]}]", path);
    expect_bad(NULL, buf, "broken.obj", "line 2: face index 2 refers to no vertex");
    // Only degenerate triangles (all corners on a line).
    obj_open(&o, "flat.obj", path, sizeof path);
    fprintf(o.f, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 3 2\n");
    fclose(o.f);
    snprintf(buf, sizeof buf, "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-6, -9]}]", path);
    expect_bad(NULL, buf, "flat.obj", "all 2 triangles are degenerate");
    // A load that is not closed: the wedge without its bottom.
    obj_open(&o, "open.obj", path, sizeof path);
    fprintf(o.f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    fclose(o.f);
    snprintf(buf, sizeof buf, "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s\"}, \"mass\": 50, \"position\": [-6, -9]}]",
             path);
    expect_bad(buf, NULL, "loads[0].mesh.file", "is not closed (3 open");
    // The same mesh as a fixed obstacle is fine (no volume needed).
    {
        char err[512];
        world_desc d;
        snprintf(buf, sizeof buf, "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-6, -9]}]", path);
        CHECK(sandbox_with(NULL, buf, &d, err, sizeof err) == 0, "open mesh as a fixed obstacle: %s", err);
        world_desc_free(&d);
    }
    // Absurd scale: a 4 m block read as millimetres given as metres x 1000.
    const double lo[3] = {-2, -0.5, 0}, hi[3] = {2, 0.5, 1};
    write_box("big.obj", lo, hi, p2, sizeof p2);
    snprintf(buf, sizeof buf,
             "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s\", \"scale\": 1000}, \"position\": [-6, -9]}]", p2);
    expect_bad(NULL, buf, "4000 m across at scale 1000", "\"scale\": 0.001");
    // Too many triangles.
    obj_open(&o, "huge.obj", path, sizeof path);
    fprintf(o.f, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for (int i = 0; i <= MESH_MAX_TRIANGLES; ++i) fprintf(o.f, "f 1 2 3\n");
    fclose(o.f);
    snprintf(buf, sizeof buf, "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s\"}, \"position\": [-6, -9]}]", path);
    expect_bad(NULL, buf, "huge.obj", "more than 200000 triangles");
    // A format the core does not read, without the importer.
    snprintf(buf, sizeof buf, "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s/site.glb\"}, \"position\": [-6, -9]}]",
             g_dir);
    FILE* f = fopen(strchr(buf, '/') ? g_dir : "", "r");
    if (f) fclose(f);
    snprintf(path, sizeof path, "%s/site.glb", g_dir);
    f = fopen(path, "w");
    if (f) {
        fputs("glTF", f);
        fclose(f);
    }
    expect_bad(NULL, buf, "site.glb", "needs the assimp importer");
    // Size and mesh together.
    snprintf(buf, sizeof buf,
             "[{\"name\": \"x\", \"size\": [1, 1, 1], \"mesh\": {\"file\": \"%s\"}, \"position\": [-6, -9]}]", p2);
    expect_bad(NULL, buf, "obstacles[0].size", "not used with a mesh");
}

// ---- files that are not whole meshes (issue 25 items 24, 25, 11c, 16b) ----

// The unit cube's 12 triangles, wound outward.
static void cube_tris(float t[12][9]) {
    static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; ++f)
        for (int h = 0; h < 2; ++h) {
            const int c[3] = {q[f][0], q[f][1 + h], q[f][2 + h]};
            for (int k = 0; k < 3; ++k)
                for (int a = 0; a < 3; ++a) t[2 * f + h][3 * k + a] = (float)(c[k] >> a & 1);
        }
}

// A binary STL of `write` facets (the cube's, repeated) under a header that
// says `count`; `extra` bytes of a further facet appended. Returns the size.
static long write_stl_bin(const char* name, uint32_t count, int write, int extra, char* path, size_t n) {
    snprintf(path, n, "%s/%s", g_dir, name);
    FILE* f = fopen(path, "wb");
    if (!f) return -1;
    unsigned char head[84] = "solid but binary";
    for (int k = 0; k < 4; ++k) head[80 + k] = (unsigned char)(count >> 8 * k);
    fwrite(head, 1, 84, f);
    float t[12][9];
    cube_tris(t);
    for (int i = 0; i < write; ++i) {
        unsigned char rec[50] = {0};
        for (int k = 0; k < 9; ++k) memcpy(rec + 12 + 4 * k, &t[i % 12][k], 4); // little-endian host (x86, arm)
        fwrite(rec, 1, 50, f);
    }
    for (int i = 0; i < extra; ++i) fputc(0, f);
    const long size = ftell(f);
    fclose(f);
    return size;
}

// An ASCII STL of the cube, cut in the middle of its cut_vertex-th "vertex"
// line (1-based; whole if 0).
static void write_stl_ascii(const char* name, int cut_vertex, char* path, size_t n) {
    char text[8192] = "solid cube exported by a CAD program\n";
    float t[12][9];
    cube_tris(t);
    for (int i = 0; i < 12; ++i) {
        char fac[512];
        snprintf(fac, sizeof fac,
                 "  facet normal 0 0 0\n    outer loop\n      vertex %g %g %g\n      vertex %g %g %g\n"
                 "      vertex %g %g %g\n    endloop\n  endfacet\n",
                 t[i][0], t[i][1], t[i][2], t[i][3], t[i][4], t[i][5], t[i][6], t[i][7], t[i][8]);
        strcat(text, fac);
    }
    strcat(text, "endsolid cube\n");
    size_t keep = strlen(text);
    const char* q = text;
    for (int i = 0; i < cut_vertex && q; ++i) q = strstr(q + 1, "vertex");
    if (cut_vertex > 0 && q) keep = (size_t)(q - text) + 10; // "vertex 0 0" of "vertex 0 0 1"
    snprintf(path, n, "%s/%s", g_dir, name);
    FILE* f = fopen(path, "wb");
    if (!f) return;
    fwrite(text, 1, keep, f);
    fclose(f);
}

static void expect_load(const char* path, const char* want1, const char* want2) {
    char err[512] = "";
    mesh_tri t;
    const int rc = mesh_load(path, 1, 2, &t, err, sizeof err);
    CHECK(rc == -1, "%s refused (%s)", path, want1);
    if (!rc) mesh_free(&t);
    CHECK(strstr(err, want1) && (!want2 || strstr(err, want2)), "%s: message: %s", path, err);
    CHECK(!strstr(err, "no triangles"), "%s: says no triangles: %s", path, err);
}

static void test_bad_files(void) {
    char path[600], buf[1400];
    mesh_tri t;
    char err[512];
    // The whole files load: 12 triangles, 8 vertices.
    write_stl_bin("cube_bin.stl", 12, 12, 0, path, sizeof path);
    CHECK(mesh_load(path, 1, 2, &t, err, sizeof err) == 0 && t.nt == 12 && t.nv == 8, "binary cube: %s", err);
    mesh_free(&t);
    write_stl_ascii("cube_ascii.stl", 0, path, sizeof path);
    CHECK(mesh_load(path, 1, 2, &t, err, sizeof err) == 0 && t.nt == 12 && t.nv == 8, "ASCII cube: %s", err);
    if (!err[0]) mesh_free(&t);
    // Item 25: 10 whole facets under a header saying 1000, or 0xffffffff.
    write_stl_bin("count1000.stl", 1000, 10, 0, path, sizeof path);
    expect_load(path, "binary STL truncated: the header says 1000 facets (50084 bytes)", "584 bytes (10 whole facets)");
    write_stl_bin("countmax.stl", 0xffffffffu, 10, 0, path, sizeof path);
    expect_load(path, "the header says 4294967295 facets", "(10 whole facets)");
    // A count of 0 with facets after it.
    write_stl_bin("count0.stl", 0, 10, 0, path, sizeof path);
    expect_load(path, "the header says 0 facets (84 bytes) but the file has 584 bytes", "500 more");
    // Item 16b: cut short, 12 whole triangles and part of the 13th of 20.
    write_stl_bin("cut.stl", 20, 12, 17, path, sizeof path);
    expect_load(path, "binary STL truncated: the header says 20 facets (1084 bytes)",
                "the file has 701 bytes (12 whole facets and a part of one)");
    // Items 25 and 11c: an ASCII STL cut inside a facet (in the 5th facet's
    // second vertex line), and one cut between facets (no endsolid).
    write_stl_ascii("cut_ascii.stl", 14, path, sizeof path);
    expect_load(path, "ASCII STL truncated: the file ends at line 33 inside facet 5", NULL);
    snprintf(path, sizeof path, "%s/noend_ascii.stl", g_dir);
    {
        FILE* f = fopen(path, "wb");
        if (f) fputs("solid cube\n", f), fclose(f);
        f = fopen(path, "ab");
        if (f) {
            fputs("  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n      vertex 0 1 0\n"
                  "    endloop\n  endfacet\n",
                  f);
            fclose(f);
        }
    }
    expect_load(path, "ASCII STL truncated: the file ends at line 9 after 1 facets without \"endsolid\"", NULL);
    // A facet with a fourth vertex, and a word that is not a number.
    snprintf(path, sizeof path, "%s/quad_ascii.stl", g_dir);
    FILE* f = fopen(path, "wb");
    if (f) {
        fputs("solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\n"
              "endloop\nendfacet\nendsolid q\n", f);
        fclose(f);
    }
    expect_load(path, "ASCII STL: line 7 (facet 1): expected \"endloop\", found \"vertex\"", NULL);
    // Item 25: a directory given as the mesh.
    snprintf(path, sizeof path, "%s/adir.stl", g_dir);
    mkdir(path, 0755);
    expect_load(path, "is a directory", NULL);
    // Item 24: a mesh that never ends (a link to /dev/zero and to
    // /dev/urandom): refused before any read, so this returns at once.
    snprintf(path, sizeof path, "%s/zero.stl", g_dir);
    unlink(path);
    CHECK(symlink("/dev/zero", path) == 0, "symlink");
    expect_load(path, "is not a regular file", NULL);
    snprintf(path, sizeof path, "%s/random.obj", g_dir);
    unlink(path);
    CHECK(symlink("/dev/urandom", path) == 0, "symlink");
    expect_load(path, "is not a regular file", NULL);
    expect_load("/dev/zero", "is not a regular file", NULL);
    // A named pipe with no writer: opening it would block for ever.
    snprintf(path, sizeof path, "%s/pipe.obj", g_dir);
    unlink(path);
    CHECK(mkfifo(path, 0644) == 0, "mkfifo");
    expect_load(path, "is not a regular file", NULL);
    // Over the size limit (a sparse file: no disk used).
    snprintf(path, sizeof path, "%s/huge_sparse.obj", g_dir);
    f = fopen(path, "wb");
    if (f) {
        fclose(f);
        CHECK(truncate(path, MESH_MAX_FILE_BYTES + 1) == 0, "truncate");
    }
    expect_load(path, "more than the 256 MiB a mesh file may have", NULL);
    unlink(path);
    // Through a world file: the field, the file and the problem on one line.
    snprintf(buf, sizeof buf, "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s/zero.stl\"}, \"position\": [-6, -9]}]",
             g_dir);
    expect_bad(NULL, buf, "obstacles[0].mesh.file: ", "zero.stl: is not a regular file");
    snprintf(buf, sizeof buf,
             "[{\"name\": \"x\", \"mesh\": {\"file\": \"%s/cut.stl\"}, \"mass\": 50, \"position\": [-6, -9]}]", g_dir);
    expect_bad(buf, NULL, "loads[0].mesh.file: ", "cut.stl: binary STL truncated");
}

// The per-process cache: a second load of an unchanged file parses nothing
// and gives the same mesh; another scale is a different entry; a rewrite of
// equal size (same tick possible) is parsed again and gives the new mesh;
// a world file's validation and its ODE world parse its mesh once together.
static void test_cache(void) {
    char path[600], err[512];
    const double lo[3] = {0, 0, 0}, hi1[3] = {1, 2, 3}, hi2[3] = {3, 2, 1};
    write_box("cache_box.obj", lo, hi1, path, sizeof path);
    mesh_tri a, b;
    const unsigned long long p0 = mesh_cache_parses();
    CHECK(mesh_load(path, 1.0, 2, &a, err, sizeof err) == 0, "load: %s", err);
    CHECK(mesh_load(path, 1.0, 2, &b, err, sizeof err) == 0, "load again: %s", err);
    CHECK(mesh_cache_parses() - p0 == 1, "%llu parses for two loads of one file", mesh_cache_parses() - p0);
    CHECK(a.nv == b.nv && a.nt == b.nt && !memcmp(a.v, b.v, 3 * sizeof(float) * a.nv) &&
              !memcmp(a.idx, b.idx, 3 * sizeof(int) * a.nt) && a.v != b.v,
          "a cached load is an equal copy");
    mesh_free(&b);
    CHECK(mesh_load(path, 2.0, 2, &b, err, sizeof err) == 0, "load at scale 2: %s", err);
    double blo[3], bhi[3];
    mesh_bounds(&b, blo, bhi);
    CHECK_NEAR(bhi[2], 6.0, 1e-6);
    CHECK(mesh_cache_parses() - p0 == 2, "another scale is parsed (%llu)", mesh_cache_parses() - p0);
    mesh_free(&b);
    // Same digit count, so the same size; z now 1 m.
    write_box("cache_box.obj", lo, hi2, path, sizeof path);
    CHECK(mesh_load(path, 1.0, 2, &b, err, sizeof err) == 0, "load rewritten: %s", err);
    mesh_bounds(&b, blo, bhi);
    CHECK_NEAR(bhi[0], 3.0, 1e-6);
    CHECK_NEAR(bhi[2], 1.0, 1e-6);
    CHECK(mesh_cache_parses() - p0 == 3, "a rewritten file is parsed again (%llu)", mesh_cache_parses() - p0);
    mesh_free(&a);
    mesh_free(&b);
    // A world with a fixed mesh obstacle: validation and the ODE world share one parse.
    write_box("cache_wall.obj", (const double[3]){-0.5, -2, 0}, (const double[3]){0.5, 2, 3}, path, sizeof path);
    char obs[900];
    snprintf(obs, sizeof obs, "[{\"name\":\"w\",\"kind\":\"box\",\"position\":[-4,-10],\"mesh\":{\"file\":\"%s\"}}]",
             path);
    const unsigned long long p1 = mesh_cache_parses();
    world_desc d;
    CHECK(sandbox_with(NULL, obs, &d, err, sizeof err) == 0, "world: %s", err);
    ode_world* w = make(&d, 117.3, -65.8, -60);
    CHECK(w != NULL, "ode world");
    CHECK(mesh_cache_parses() - p1 == 1, "%llu parses for one world", mesh_cache_parses() - p1);
    if (w) ode_world_destroy(w);
    world_desc_free(&d);
}

int main(int argc, char** argv) {
    (void)argc;
    (void)argv;
    snprintf(g_dir, sizeof g_dir, "%s/mesh_test_files", CRANESIM_BINARY_DIR);
    mkdir(g_dir, 0755);
    char err[512];
    g_model = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    if (!g_model) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    RUN_TEST(test_mass_cube);
    RUN_TEST(test_mass_cylinder);
    RUN_TEST(test_hull_bounded);
    RUN_TEST(test_hull_stress);
    RUN_TEST(test_cancel);
    RUN_TEST(test_load_mass_in_world);
    RUN_TEST(test_rest_on_wedge);
    RUN_TEST(test_box_vs_mesh_box);
    RUN_TEST(test_boom_mesh_wall);
    RUN_TEST(test_bad_meshes);
    RUN_TEST(test_bad_files);
    RUN_TEST(test_cache);
    RUN_TEST(test_merge_flat_box);
    RUN_TEST(test_merge_keeps_shape);
    model_free(g_model);
    TEST_MAIN_END();
}
