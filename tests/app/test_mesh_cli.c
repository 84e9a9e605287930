// test_mesh_cli.c: bad CAD meshes named by a world file, through the real
// binary: one line naming the world file, the field, the mesh file and the
// problem, exit 2; and the shipped site world runs.
#include "check.h"
#include "cli_util.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static char g_dir[512];

// A copy of the shipped site world whose pallet load names mesh (relative
// to the world file, so in g_dir). Returns the world path in out.
static void site_with_pallet(const char* mesh, char* out, size_t n) {
    char text[65536], path[600];
    if (cli_read_file(CRANESIM_ASSETS "/worlds/site.json", text, sizeof text) < 0) return;
    // Meshes the site names relative to assets/worlds: point them at the assets.
    char fixed[70000] = "";
    const char* s = text;
    for (const char* q; (q = strstr(s, "\"../meshes/"));) {
        strncat(fixed, s, (size_t)(q - s));
        strcat(fixed, "\"" CRANESIM_ASSETS "/meshes/");
        s = q + strlen("\"../meshes/");
    }
    strcat(fixed, s);
    char* p = strstr(fixed, CRANESIM_ASSETS "/meshes/site_pallet.obj");
    if (p) {
        char rest[70000];
        snprintf(rest, sizeof rest, "%s", p + strlen(CRANESIM_ASSETS "/meshes/site_pallet.obj"));
        snprintf(p, sizeof fixed - (size_t)(p - fixed), "%s%s", mesh, rest);
    }
    snprintf(path, sizeof path, "%s/site_bad.json", g_dir);
    FILE* f = fopen(path, "w");
    if (f) {
        fputs(fixed, f);
        fclose(f);
    }
    snprintf(out, n, "%s", path);
}

static void expect(const char* mesh, const char* want) {
    char world[600], cmd[1200], out[4096];
    site_with_pallet(mesh, world, sizeof world);
    snprintf(cmd, sizeof cmd,
             "run --quiet --mechanics ode --world %s --scenario sandbox_swing --duration 0.01 --out /dev/null", world);
    int rc = cli_run(cmd, out, sizeof out);
    CHECK(rc == 2, "exit %d for %s: %s", rc, mesh, out);
    CHECK(strstr(out, "site_bad.json: loads[0].mesh.file: ") && strstr(out, mesh) && strstr(out, want) &&
              cli_count_lines(out) == 1,
          "message for %s: %s", mesh, out);
}

static void test_bad_mesh_exit_codes(void) {
    char path[600];
    expect("missing.obj", "cannot open the mesh file");
    snprintf(path, sizeof path, "%s/open.obj", g_dir);
    FILE* f = fopen(path, "w");
    if (f) {
        fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", f);
        fclose(f);
    }
    expect("open.obj", "is not closed");
    snprintf(path, sizeof path, "%s/empty.stl", g_dir);
    f = fopen(path, "w");
    if (f) {
        fputs("solid empty\nendsolid empty\n", f);
        fclose(f);
    }
    expect("empty.stl", "no triangles");
}

static void test_site_runs(void) {
    char out[8192];
    int rc = cli_run("run --quiet --mechanics ode --world site --scenario sandbox_pick_place --out /dev/null", out,
                     sizeof out);
    CHECK(rc == 0, "site world: exit %d: %s", rc, out);
}

int main(int argc, char** argv) {
    snprintf(g_dir, sizeof g_dir, "%s/mesh_cli_files", CRANESIM_BINARY_DIR);
    mkdir(g_dir, 0755);
    RUN_TEST(test_bad_mesh_exit_codes);
    RUN_TEST(test_site_runs);
    TEST_MAIN_END();
}
