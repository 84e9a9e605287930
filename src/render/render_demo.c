// render_demo.c: render the synthetic crane scene headlessly to a PNG and
// report frame times. Not installed; used for docs/img and benchmarking.
//
//   render_demo [out.png] [--frames N] [--size WxH] [--shadow N] [--msaa N]
//               [--primitives] [--terrain] [--no-hud] [--panel] [--window]
//
// --window draws into a real (visible) window instead of the offscreen FBO.
#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "panel.h"
#include "render.h"

static int cmp_double(const void* a, const void* b) {
    double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

static void noop(void* user) {
    (void)user;
}

int main(int argc, char** argv) {
    const char* out = "render_demo.png";
    int frames = 1;
    render_config cfg = render_default_config();
    cfg.offscreen = true;
    render_demo_params dp = render_demo_default_params();
    bool want_panel = false;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc)
            sscanf(argv[++i], "%dx%d", &cfg.width, &cfg.height);
        else if (!strcmp(argv[i], "--shadow") && i + 1 < argc)
            cfg.shadow_size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--msaa") && i + 1 < argc)
            cfg.msaa = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--primitives"))
            dp.use_meshes = false;
        else if (!strcmp(argv[i], "--terrain"))
            dp.terrain = true;
        else if (!strcmp(argv[i], "--no-hud"))
            cfg.hud = false;
        else if (!strcmp(argv[i], "--panel"))
            want_panel = true;
        else if (!strcmp(argv[i], "--window"))
            cfg.offscreen = false, cfg.vsync = false;
        else if (!strcmp(argv[i], "--help")) {
            printf(
                "usage: render_demo [out.png] [--frames N] [--size WxH] [--shadow N] [--msaa N]\n"
                "                   [--primitives] [--terrain] [--no-hud] [--panel] [--window]\n");
            return 0;
        } else if (argv[i][0] != '-')
            out = argv[i];
        else {
            fprintf(stderr, "render_demo: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (frames < 1) frames = 1;
    char err[256];
    render* r = render_create(&cfg, err, sizeof err);
    if (!r) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    panel* pn = NULL;
    double bore = 0.1, load = 500;
    if (want_panel) {
        pn = panel_create();
        panel_param_def d = {"bore", "lift cylinder", "m", &bore, 0.05, 0.2, 0.005, false};
        panel_add_param(pn, &d);
        panel_param_def d2 = {"load mass", "scenario", "kg", &load, 0, 2000, 10, false};
        panel_add_param(pn, &d2);
        panel_add_action(pn, "reset", noop, NULL);
        panel_add_action(pn, "pause", noop, NULL);
        if (!render_attach_panel(r, pn)) fprintf(stderr, "render_demo: ImGui panel unavailable\n");
    }
    static world_snapshot snap;
    static float terrain[RENDER_DEMO_TERRAIN_N * RENDER_DEMO_TERRAIN_N];
    render_charts_default(r, 2);
    double* ms = malloc((size_t)frames * sizeof *ms);
    // Fill the strip charts with a few seconds of made-up history first.
    for (int k = 0; k < 600; ++k) {
        render_demo_params q = dp;
        double t = k * 0.02;
        q.pA[0] = dp.pA[0] * (1 + 0.2 * sin(t * 1.3));
        q.pB[1] = dp.pB[1] * (1 + 0.3 * sin(t * 0.7));
        q.u[0] = 0.5 * sin(t * 0.5);
        render_demo_scene(&snap, &q, terrain);
        snap.t = t;
        render_charts_sample(r, &snap);
    }
    // Process CPU time (all threads, llvmpipe's included): a load-independent
    // cost measure on a shared machine, next to the wall-clock frame time.
    clock_t c0 = clock();
    Uint64 w0 = SDL_GetPerformanceCounter();
    for (int f = 0; f < frames; ++f) {
        render_demo_params q = dp;
        // Animate a little so the benchmark is not a still frame.
        q.slew = dp.slew + 0.002 * f;
        q.q1_deg = dp.q1_deg + 3.0 * sin(0.02 * f);
        render_demo_scene(&snap, &q, terrain);
        snap.t = 12.0 + f / 60.0;
        render_charts_sample(r, &snap);
        Uint64 t0 = SDL_GetPerformanceCounter();
        render_frame(r, &snap);
        render_present(r);
        ms[f] = 1e3 * (double)(SDL_GetPerformanceCounter() - t0) /
                (double)SDL_GetPerformanceFrequency();
    }
    double cpu_ms = 1e3 * (double)(clock() - c0) / CLOCKS_PER_SEC / frames;
    // Throughput: frames may overlap in the driver, so total time / frames
    // is the honest frame rate; the median per-frame time is shown too.
    double avg_ms = 1e3 * (double)(SDL_GetPerformanceCounter() - w0) /
                    (double)SDL_GetPerformanceFrequency() / frames;
    render_stats st = render_get_stats(r);
    qsort(ms, (size_t)frames, sizeof *ms, cmp_double);
    double med = ms[frames / 2];
    printf("render_demo: %dx%d, %d frames, %.2f ms/frame = %.1f fps (median frame %.2f ms), CPU "
           "%.2f ms/frame, "
           "triangles %ld, draw calls %d, mesh warnings %d\n",
           cfg.width, cfg.height, frames, avg_ms, 1e3 / avg_ms, med, cpu_ms, st.triangles,
           st.draw_calls, st.mesh_warnings);
    free(ms);
    int rc = render_screenshot(r, out) == 0 ? 0 : 1;
    if (!rc) printf("render_demo: wrote %s\n", out);
    render_destroy(r);
    panel_destroy(pn);
    SDL_Quit();
    return rc;
}
