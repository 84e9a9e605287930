// app_load.c: the model and the scenario a command runs, from the options.
#include "app.h"
#include "engine.h"
#include "world_desc.h"

#include <ctype.h>
#include <limits.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

const char* app_scenario_path(const char* arg, char* buf, size_t n) {
    // A path if it looks like one or is a readable file; else a name in the
    // assets (a folder called "step" in the working directory is not a file).
    struct stat st;
    bool file = stat(arg, &st) == 0 && S_ISREG(st.st_mode);
    if (file || strchr(arg, '/') || strstr(arg, ".json")) return arg;
    snprintf(buf, n, "%s/scenarios/%s.json", model_assets_dir(), arg);
    return buf;
}

int app_load(const app_common* c, model** m, scenario* sc) {
    char err[1024];
    const int rc = app_load_msg(c, m, sc, err, sizeof err);
    if (rc) fprintf(stderr, "cranesim: %s\n", err);
    return rc;
}

int app_load_msg(const app_common* c, model** m, scenario* sc, char* err, size_t errsz) {
    *m = model_load(c->model_path, c->sets, c->nset, err, errsz);
    if (!*m) return EXIT_USAGE;
    char buf[512];
    const char* arg = c->scenario_path ? c->scenario_path : "ramp";
    const char* sp = app_scenario_path(arg, buf, sizeof buf);
    if (sp == buf && access(sp, R_OK) != 0) {
        // A name that is not in the assets: say which names there are.
        char names[512] = "";
        char dir[512];
        snprintf(dir, sizeof dir, "%s/scenarios", model_assets_dir());
        DIR* d = opendir(dir);
        for (struct dirent* e; d && (e = readdir(d));) {
            size_t L = strlen(e->d_name);
            if (L < 6 || strcmp(e->d_name + L - 5, ".json")) continue;
            size_t k = strlen(names);
            snprintf(names + k, sizeof names - k, "%s%.*s", k ? ", " : "", (int)(L - 5), e->d_name);
        }
        if (d) closedir(d);
        snprintf(err, errsz, "--scenario %s: no such file or scenario (scenarios: %s)", arg, names);
        model_free(*m);
        *m = NULL;
        return EXIT_USAGE;
    }
    if (scenario_load(sp, sc, err, errsz)) {
        model_free(*m);
        *m = NULL;
        return EXIT_USAGE;
    }
    // The start pose against this model's joint ranges, here where the file
    // name is known (the engines check again, for callers without a file).
    // The scenario's q0[2] is the two-link crane's pose.
    if (model_require_two_link(*m, "start-pose check of the scenario's q0", err, errsz)) {
        model_free(*m);
        *m = NULL;
        return EXIT_USAGE;
    }
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &(*m)->mech.act[k];
        char why[400];
        if (crane_check_pose(a, (*m)->stroke[k], sc->q0[a->joint], why, sizeof why)) {
            snprintf(err, errsz, "%s: %s", sp, why);
            model_free(*m);
            *m = NULL;
            return EXIT_USAGE;
        }
    }
    return 0;
}
