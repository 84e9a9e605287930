// crane_fixture.h: the default crane model with one shipped scenario, for
// the tests that run whole scenarios through sim_run.
#ifndef TEST_CRANE_FIXTURE_H
#define TEST_CRANE_FIXTURE_H

#include "check.h"
#include "sim.h"

#include <stdio.h>

/// assets/scenarios/<name>.json into *sc.
static inline int load_scenario(const char* name, scenario* sc) {
    char path[512], err[512];
    snprintf(path, sizeof path, "%s/scenarios/%s.json", CRANESIM_ASSETS, name);
    const int rc = scenario_load(path, sc, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    return rc;
}

/// assets/models/<file> (e.g. "hiab031_ls.json"); NULL, the failure
/// CHECKed, when it does not load.
static inline model* load_model(const char* file) {
    char path[512], err[512];
    snprintf(path, sizeof path, "%s/models/%s", CRANESIM_ASSETS, file);
    model* m = model_load(path, NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s: %s", file, err);
    return m;
}

/// The default model (assets/models/hiab031.json) and scenario `name`;
/// NULL (the failure CHECKed) when either does not load.
static inline model* load_crane(const char* name, scenario* sc) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", NULL, 0, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (m && load_scenario(name, sc)) {
        model_free(m);
        return NULL;
    }
    return m;
}

/// The shipped crane with the seal friction the paper modelled: none beyond
/// the viscous b_v (docs/model.md, "Seal friction"; the paper-validation
/// runs switch the Coulomb and Stribeck forces off with these four --set
/// paths). The shipped file carries realistic seal friction.
static const char* const paper_friction_sets[4] = {
    "hydraulics.components.lift_cyl.coulomb=0", "hydraulics.components.lift_cyl.stribeck=0",
    "hydraulics.components.jib_cyl.coulomb=0", "hydraulics.components.jib_cyl.stribeck=0"};

/// load_crane with paper_friction_sets applied.
static inline model* load_crane_paper_friction(const char* name, scenario* sc) {
    char err[512];
    model* m = model_load(CRANESIM_ASSETS "/models/hiab031.json", paper_friction_sets, 4, err, sizeof err);
    CHECK(m != NULL, "%s", err);
    if (m && load_scenario(name, sc)) {
        model_free(m);
        return NULL;
    }
    return m;
}

#endif
