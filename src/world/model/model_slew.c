// model_slew.c: the model's slew drive (mechanics.slew) and its circuit
// fragment (hydraulics_slew), in both forms of the mechanics section
// (docs/model.md "The slew drive"). The fragment is not part of the model's
// circuit (model.hyd): only a run that slews (the ODE sandbox) appends it,
// so the analytic runs keep their circuit and its fast kernels. Here it is
// compiled once with the model's circuit to check it at load.
#include <stdio.h>
#include <string.h>

#include "hydraulics.h"
#include "model_chain.h"

// The same ranges and units a world's slew section is checked against
// (world_desc.c): a slew drive moved from a world into a model keeps its
// limits.
static const json_range R_PINION = {0.01, 1, 0.03, 0.3, "m"};
static const json_range R_COLUMN_RADIUS = {0.02, 2, 0.05, 0.5, "m"};
static const json_range R_SLEW_DAMPING = {0, 1e7, 0, 1e5, "N m s/rad"};

int model_slew_read(json_ctx* c, const cJSON* root, const cJSON* mech, crane_slew* s) {
    memset(s, 0, sizeof *s);
    const cJSON* o = json_obj(c, mech, "mechanics", "slew", false);
    const cJSON* frag = json_obj(c, root, "", "hydraulics_slew", false);
    if (c->failed) return -1;
    // One without the other is a drive with no oil or oil with no drive.
    if (o && !frag) {
        json_fail(c, "mechanics.slew", "needs its circuit: a hydraulics_slew section with the slew valve and cylinder");
        return -1;
    }
    if (frag && !o) {
        json_fail(c, "hydraulics_slew", "is the circuit of a slew drive, but mechanics has no slew");
        return -1;
    }
    if (!o) return 0;
    static const char* const keys[] = {"pinion_radius", "cylinder", "valve", "column_radius", "damping", NULL};
    json_only_keys(c, o, "mechanics.slew", keys);
    s->pinion_radius = json_num_r(c, o, "mechanics.slew", "pinion_radius", true, 0, &R_PINION);
    json_str(c, o, "mechanics.slew", "cylinder", true, "", s->cylinder, sizeof s->cylinder);
    json_str(c, o, "mechanics.slew", "valve", true, "", s->valve, sizeof s->valve);
    // Absent: the defaults a world's slew section has (world_desc.c), so a
    // section moved from a world into a model keeps its crane.
    s->column_radius = json_num_r(c, o, "mechanics.slew", "column_radius", false, 0.16, &R_COLUMN_RADIUS);
    s->damping = json_num_r(c, o, "mechanics.slew", "damping", false, 2000.0, &R_SLEW_DAMPING);
    json_only_keys(c, frag, "hydraulics_slew", (const char* const[]){"nodes", "components", "patch", NULL});
    json_arr(c, frag, "hydraulics_slew", "nodes", false);
    json_arr(c, frag, "hydraulics_slew", "components", true);
    json_obj(c, frag, "hydraulics_slew", "patch", false);
    if (c->failed) return -1;
    s->present = true;
    return 0;
}

// The component of that name in a components array, or NULL.
static cJSON* find_comp(const cJSON* comps, const char* name) {
    cJSON* e;
    cJSON_ArrayForEach(e, comps) {
        const cJSON* n = cJSON_GetObjectItemCaseSensitive(e, "name");
        if (cJSON_IsString(n) && !strcmp(n->valuestring, name)) return e;
    }
    return NULL;
}

// The slew's cylinder (valve) must be a component of the fragment of the
// given type: one in the model's own circuit would change the analytic runs'
// circuit, and one of the booms' would couple the slew to a boom.
static void check_part(json_ctx* c, const cJSON* frag, const char* field, const char* name, const char* type) {
    char f[48];
    snprintf(f, sizeof f, "mechanics.slew.%s", field);
    const cJSON* e = find_comp(cJSON_GetObjectItemCaseSensitive(frag, "components"), name);
    const cJSON* t = e ? cJSON_GetObjectItemCaseSensitive(e, "type") : NULL;
    if (!e)
        json_fail(c, f, "no %s named \"%s\" in hydraulics_slew.components", type, name);
    else if (!cJSON_IsString(t) || strcmp(t->valuestring, type))
        json_fail(c, f, "\"%s\" in hydraulics_slew.components is a %s, not a %s", name,
                  cJSON_IsString(t) ? t->valuestring : "component without a type", type);
}

hyd_model* model_circuit_with_fragment(const cJSON* hydraulics, const char* mfile, const cJSON* frag,
                                       const char* ffile, const char* fpart, char* err, size_t errsz) {
    cJSON* h = cJSON_Duplicate(hydraulics, 1);
    cJSON* fx = cJSON_Duplicate(frag, 1);
    if (!h || !fx) {
        snprintf(err, errsz, "%s: %s: out of memory", ffile, fpart);
        cJSON_Delete(h);
        cJSON_Delete(fx);
        return NULL;
    }
    // The patch rewires the model's own components ("component.field":
    // "node", the LS shuttle's output): the component must exist and the
    // field name a node already, so a patch moves a port and nothing else.
    bool bad = false;
    const cJSON* it;
    cJSON_ArrayForEach(it, cJSON_GetObjectItemCaseSensitive(frag, "patch")) {
        char comp[128];
        const char* dot = strchr(it->string, '.');
        if (!dot || dot == it->string || !dot[1]) {
            snprintf(err, errsz, "%s: %s.patch.%s: expected \"component.field\" as the key", ffile, fpart, it->string);
            bad = true;
            break;
        }
        if (!cJSON_IsString(it) || !it->valuestring[0]) {
            snprintf(err, errsz, "%s: %s.patch.%s: expected a node name (a string)", ffile, fpart, it->string);
            bad = true;
            break;
        }
        snprintf(comp, sizeof comp, "%.*s", (int)(dot - it->string), it->string);
        cJSON* e = find_comp(cJSON_GetObjectItemCaseSensitive(h, "components"), comp);
        const cJSON* fv = e ? cJSON_GetObjectItemCaseSensitive(e, dot + 1) : NULL;
        if (!cJSON_IsString(fv)) {
            // The wording of the sandbox's own check (ode_coupling.c).
            snprintf(err, errsz, "%s: %s.patch.%s: %s %s in %s", ffile, fpart, it->string,
                     e ? "no port field" : "no component", e ? dot + 1 : comp, mfile);
            bad = true;
            break;
        }
        cJSON_ReplaceItemInObjectCaseSensitive(e, dot + 1, cJSON_CreateString(it->valuestring));
    }
    cJSON_DeleteItemFromObjectCaseSensitive(fx, "patch");
    // An error in the fragment names its own file, field and index.
    hyd_model* hm = bad ? NULL : hyd_model_from_json_extra(h, mfile, "hydraulics", fx, ffile, fpart, err, errsz);
    cJSON_Delete(h);
    cJSON_Delete(fx);
    return hm;
}

int model_slew_check(json_ctx* c, const cJSON* root, const crane_slew* s) {
    if (!s->present) return 0;
    const cJSON* frag = cJSON_GetObjectItemCaseSensitive(root, "hydraulics_slew");
    check_part(c, frag, "cylinder", s->cylinder, "cylinder");
    check_part(c, frag, "valve", s->valve, "valve");
    if (c->failed) return -1;
    // The merged circuit as the sandbox compiles it.
    hyd_model* hm = model_circuit_with_fragment(cJSON_GetObjectItemCaseSensitive(root, "hydraulics"), c->file, frag,
                                                c->file, "hydraulics_slew", c->err, c->errsz);
    if (!hm) {
        c->failed = true;
        return -1;
    }
    hyd_model_free(hm);
    return 0;
}
