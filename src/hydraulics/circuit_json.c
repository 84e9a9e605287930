// circuit_json.c: the JSON face of the circuit (cJSON). Built as its own
// library so the core stays libm-only.
//
// The loader walks the document, turning every field into the same definition
// structs the C API uses (via each type's descriptor, component_table.c),
// then compiles. Value and cross-field rules live once, in the compiler;
// errors it reports (element index + field) are mapped back to JSON paths
// here. Unknown keys are rejected so a typo never silently falls back to a
// default. Keys starting with '_' are comments and are ignored.
#include "hyd_internal.h"

#include <cjson/cJSON.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct jctx {
    const char* file;
    const char* prefix; ///< "" or "hydraulics" (no trailing dot)
    char* err;
    size_t errsz;
} jctx;

// "<file>: <prefix>.<path>: <msg>" (the prefix and its dot are left out when empty).
static void jerr(const jctx* c, const char* path, const char* fmt, ...) {
    if (!c->err || !c->errsz)
        return;
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    const int pre = c->prefix && c->prefix[0];
    const int has = path && path[0];
    snprintf(c->err, c->errsz, "%s: %s%s%s%s%s", c->file ? c->file : "<json>",
             pre ? c->prefix : "", pre && has ? "." : "", has ? path : "",
             (pre || has) ? ": " : "", msg);
}

static const char* jtype(const cJSON* j) {
    if (cJSON_IsNumber(j)) return "number";
    if (cJSON_IsString(j)) return "string";
    if (cJSON_IsBool(j)) return "boolean";
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsArray(j)) return "array";
    if (cJSON_IsObject(j)) return "object";
    return "invalid";
}

// Set the numeric fields of a def struct from object o; report unknown keys.
// allowed_extra: keys handled by the caller (name, type, ports).
static int read_params(const jctx* c, const cJSON* o, const char* path, void* def,
                       const hyd_param_info* p, int np, const hyd_port_info* ports, int nports,
                       const char** port_out, int is_elem, const char* type_name) {
    for (const cJSON* it = o->child; it; it = it->next) {
        const char* key = it->string;
        char fpath[200];
        snprintf(fpath, sizeof fpath, "%s.%s", path, key);
        if (key[0] == '_')
            continue;
        if (is_elem && (!strcmp(key, "name") || !strcmp(key, "type")))
            continue;
        int found = 0;
        for (int k = 0; k < nports && !found; ++k)
            if (!strcmp(key, ports[k].name)) {
                found = 1;
                if (!cJSON_IsString(it) || !it->valuestring[0]) {
                    jerr(c, fpath, "must be a %s name (non-empty string), got %s",
                         ports[k].ref ? "component" : "node", jtype(it));
                    return -1;
                }
                port_out[k] = it->valuestring;
            }
        for (int k = 0; k < np && !found; ++k)
            if (!strcmp(key, p[k].name)) {
                found = 1;
                if (!cJSON_IsNumber(it)) {
                    jerr(c, fpath, "must be a number, got %s", jtype(it));
                    return -1;
                }
                *(double*)((char*)def + p[k].off) = it->valuedouble;
            }
        if (!found) {
            char known[400] = "";
            size_t len = 0;
            for (int k = 0; k < nports + np; ++k) {
                const char* nm = k < nports ? ports[k].name : p[k - nports].name;
                len += (size_t)snprintf(known + len, len < sizeof known ? sizeof known - len : 0,
                                        "%s%s", k ? ", " : "", nm);
            }
            jerr(c, fpath, "unknown field for %s (known: %s%s)", type_name,
                 is_elem ? "name, type, " : "", known);
            return -1;
        }
    }
    for (int k = 0; k < np; ++k)
        if (p[k].required && !cJSON_GetObjectItemCaseSensitive(o, p[k].name)) {
            char fpath[200];
            snprintf(fpath, sizeof fpath, "%s.%s", path, p[k].name);
            jerr(c, fpath, "missing required field [%s]", p[k].unit);
            return -1;
        }
    for (int k = 0; k < nports; ++k)
        if (!port_out[k] && !ports[k].ref) { // a component reference is optional
            char fpath[200];
            snprintf(fpath, sizeof fpath, "%s.%s", path, ports[k].name);
            jerr(c, fpath, "missing required port (a node name)");
            return -1;
        }
    return 0;
}

// One entry of "nodes" (nodes = 1) or "components" (nodes = 0).
static int read_elem(const jctx* c, hyd_builder* b, const cJSON* o, const char* list, int i,
                     int nodes) {
    char path[96];
    snprintf(path, sizeof path, "%s[%d]", list, i);
    if (!cJSON_IsObject(o)) {
        jerr(c, path, "must be an object, got %s", jtype(o));
        return -1;
    }
    const cJSON* jn = cJSON_GetObjectItemCaseSensitive(o, "name");
    const cJSON* jt = cJSON_GetObjectItemCaseSensitive(o, "type");
    char fpath[128];
    snprintf(fpath, sizeof fpath, "%s.name", path);
    if (!jn) {
        jerr(c, fpath, "missing required field (a unique name)");
        return -1;
    }
    if (!cJSON_IsString(jn)) {
        jerr(c, fpath, "must be a string, got %s", jtype(jn));
        return -1;
    }
    snprintf(fpath, sizeof fpath, "%s.type", path);
    if (!jt) {
        jerr(c, fpath, "missing required field");
        return -1;
    }
    if (!cJSON_IsString(jt)) {
        jerr(c, fpath, "must be a string, got %s", jtype(jt));
        return -1;
    }
    const int t = hyd_type_parse(jt->valuestring);
    const hyd_component* desc = t >= 0 ? hyd_component_of((hyd_type)t) : NULL;
    if (!desc || desc->is_node != nodes) {
        // The known types of this list, in table order.
        char known[200] = "";
        size_t len = 0;
        for (int k = 0; k < HYD_TYPE_COUNT; ++k) {
            const hyd_component* d = hyd_component_of((hyd_type)k);
            if (d && d->is_node == nodes)
                len += (size_t)snprintf(known + len, len < sizeof known ? sizeof known - len : 0,
                                        "%s%s", len ? ", " : "", d->name);
        }
        jerr(c, fpath, "unknown %s type '%s' (known: %s)", nodes ? "node" : "component",
             jt->valuestring, known);
        return -1;
    }
    hyd_elem e;
    memset(&e, 0, sizeof e);
    e.type = (hyd_type)t;
    desc->defaults(&e.def);
    int np, nports;
    const hyd_param_info* p = hyd_params_of(e.type, &np);
    const hyd_port_info* ports = hyd_ports_of(e.type, &nports);
    const char* port_names[HYD_MAXPORT] = {0};
    if (read_params(c, o, path, &e.def, p, np, ports, nports, port_names, 1, jt->valuestring))
        return -1;
    char* base = (char*)&e.def;
    *(const char**)base = jn->valuestring;
    for (int k = 0; k < nports; ++k)
        *(const char**)(base + ports[k].off) = port_names[k];
    if (hyd_add(b, e.type, &e.def) < 0) {
        jerr(c, path, "out of memory");
        return -1;
    }
    return 0;
}

static int read_list(const jctx* c, hyd_builder* b, const cJSON* root, const char* key,
                     int nodes) {
    const cJSON* a = cJSON_GetObjectItemCaseSensitive(root, key);
    if (!a) {
        jerr(c, key, "missing required array");
        return -1;
    }
    if (!cJSON_IsArray(a)) {
        jerr(c, key, "must be an array, got %s", jtype(a));
        return -1;
    }
    int i = 0;
    for (const cJSON* it = a->child; it; it = it->next, ++i)
        if (read_elem(c, b, it, key, i, nodes))
            return -1;
    return 0;
}

// ---------------------------------------------------------------------------
// Notes
// ---------------------------------------------------------------------------

static hyd_note_fn note_fn = NULL;
static void* note_user = NULL;

void hyd_set_note_handler(hyd_note_fn fn, void* user) {
    note_fn = fn;
    note_user = user;
}

hyd_note_fn hyd_get_note_handler(void** user) {
    if (user)
        *user = note_user;
    return note_fn;
}

// Lines already printed by the default handler, so a model loaded three
// times in one run notes each value once. A fixed table: beyond it notes
// repeat rather than being lost.
#define NOTE_SEEN 64
static char* note_seen[NOTE_SEEN];
static int note_nseen;

void hyd_note(const char* line) {
    if (note_fn) {
        note_fn(line, note_user);
        return;
    }
    for (int i = 0; i < note_nseen; ++i)
        if (!strcmp(note_seen[i], line))
            return;
    if (note_nseen < NOTE_SEEN) {
        size_t n = strlen(line) + 1;
        char* c = malloc(n);
        if (c) {
            memcpy(c, line, n);
            note_seen[note_nseen++] = c;
        }
    }
    fprintf(stderr, "note: %s\n", line);
}

// A note per parameter outside its typical range: "file: path.field: v is
// outside the typical range [lo, hi] unit".
static void note_params(const jctx* c, const char* path, const void* def, const hyd_param_info* p,
                        int np) {
    for (int k = 0; k < np; ++k) {
        char msg[200], line[400];
        if (!hyd_param_typical(&p[k], *(const double*)((const char*)def + p[k].off), msg, sizeof msg))
            continue;
        const int pre = c->prefix && c->prefix[0];
        snprintf(line, sizeof line, "%s: %s%s%s.%s: %s", c->file ? c->file : "<json>",
                 pre ? c->prefix : "", pre ? "." : "", path, p[k].name, msg);
        hyd_note(line);
    }
}

static void note_model(const jctx* c, const hyd_model* m) {
    int np;
    const hyd_param_info* p = hyd_fluid_params(&np);
    note_params(c, "fluid", &m->fluid, p, np);
    for (int i = 0; i < m->nunode + m->ncomp; ++i) {
        const hyd_elem* e = i < m->nunode ? &m->unode[i] : &m->comp[i - m->nunode];
        char path[64];
        snprintf(path, sizeof path, "%s[%d]", i < m->nunode ? "nodes" : "components",
                 i < m->nunode ? i : i - m->nunode);
        p = hyd_params_of(e->type, &np);
        note_params(c, path, &e->def, p, np);
    }
}

void hyd_json_fragment_notes(const cJSON* fragment, const char* file, const char* prefix) {
    jctx c = {file, prefix ? prefix : "", NULL, 0};
    static const char* const lists[2] = {"nodes", "components"};
    for (int l = 0; l < 2; ++l) {
        const cJSON* a = cJSON_GetObjectItemCaseSensitive(fragment, lists[l]);
        int i = 0;
        for (const cJSON* e = cJSON_IsArray(a) ? a->child : NULL; e; e = e->next, ++i) {
            const cJSON* jt = cJSON_GetObjectItemCaseSensitive(e, "type");
            const int t = cJSON_IsString(jt) ? hyd_type_parse(jt->valuestring) : -1;
            if (t < 0)
                continue;
            int np;
            const hyd_param_info* p = hyd_params_of((hyd_type)t, &np);
            char path[64];
            snprintf(path, sizeof path, "%s[%d]", lists[l], i);
            // One parameter at a time through a def of defaults: absent
            // members keep their (typical) default and give no note.
            for (int k = 0; k < np; ++k) {
                const cJSON* v = cJSON_GetObjectItemCaseSensitive(e, p[k].name);
                if (!cJSON_IsNumber(v))
                    continue;
                hyd_elem tmp;
                memset(&tmp, 0, sizeof tmp);
                *(double*)((char*)&tmp.def + p[k].off) = v->valuedouble;
                note_params(&c, path, &tmp.def, &p[k], 1);
            }
        }
    }
}

// Nodes and components of an appended fragment (optional lists).
static int read_extra(const jctx* c, hyd_builder* b, const cJSON* extra) {
    if (!cJSON_IsObject(extra)) {
        jerr(c, "", "must be an object, got %s", jtype(extra));
        return -1;
    }
    for (const cJSON* it = extra->child; it; it = it->next)
        if (it->string[0] != '_' && strcmp(it->string, "nodes") && strcmp(it->string, "components")) {
            jerr(c, it->string, "unknown field (known: nodes, components)");
            return -1;
        }
    static const char* const lists[2] = {"nodes", "components"};
    for (int l = 0; l < 2; ++l)
        if (cJSON_GetObjectItemCaseSensitive(extra, lists[l]) && read_list(c, b, extra, lists[l], l == 0))
            return -1;
    return 0;
}

static int list_size(const cJSON* o, const char* key) {
    const cJSON* a = o ? cJSON_GetObjectItemCaseSensitive(o, key) : NULL;
    return cJSON_IsArray(a) ? cJSON_GetArraySize(a) : 0;
}

// The circuit, with the fragment extra (NULL: none) appended; errors and
// notes in the fragment are reported against cx with the fragment's own
// indices.
static hyd_model* from_json(const cJSON* circuit, const jctx* cc, const cJSON* extra, const jctx* cx) {
    const jctx c = *cc;
    if (!cJSON_IsObject(circuit)) {
        jerr(&c, "", "circuit must be an object, got %s", circuit ? jtype(circuit) : "nothing");
        return NULL;
    }
    for (const cJSON* it = circuit->child; it; it = it->next)
        if (it->string[0] != '_' && strcmp(it->string, "fluid") && strcmp(it->string, "nodes") &&
            strcmp(it->string, "components")) {
            jerr(&c, it->string, "unknown field (known: fluid, nodes, components)");
            return NULL;
        }
    hyd_builder* b = hyd_builder_create();
    if (!b) {
        jerr(&c, "", "out of memory");
        return NULL;
    }
    hyd_model* m = NULL;
    const cJSON* jf = cJSON_GetObjectItemCaseSensitive(circuit, "fluid");
    if (jf) {
        if (!cJSON_IsObject(jf)) {
            jerr(&c, "fluid", "must be an object, got %s", jtype(jf));
            goto done;
        }
        hyd_fluid_def f = hyd_default_fluid_def();
        int np;
        const hyd_param_info* p = hyd_fluid_params(&np);
        if (read_params(&c, jf, "fluid", &f, p, np, NULL, 0, NULL, 0, "fluid"))
            goto done;
        hyd_builder_set_fluid(b, &f);
    }
    if (read_list(&c, b, circuit, "nodes", 1) || read_list(&c, b, circuit, "components", 0))
        goto done;
    const int nbase[2] = {list_size(circuit, "nodes"), list_size(circuit, "components")};
    if (extra && read_extra(cx, b, extra))
        goto done;
    hyd_build_error e;
    m = hyd_compile_ex(b, &e);
    if (!m) {
        char path[160];
        const jctx* at = &c;
        int index = e.index;
        if (extra && (e.where == 1 || e.where == 2) && e.index >= nbase[e.where - 1]) {
            at = cx;
            index -= nbase[e.where - 1];
        }
        if (e.where == 0)
            snprintf(path, sizeof path, "fluid.%s", e.field);
        else if (e.where == 1 || e.where == 2)
            snprintf(path, sizeof path, "%s[%d].%s", e.where == 1 ? "nodes" : "components",
                     index, e.field);
        else
            path[0] = 0;
        // The message goes to the caller's buffer whichever part it names.
        jctx out = *at;
        out.err = c.err, out.errsz = c.errsz;
        jerr(&out, path, "%s", e.msg);
    } else if (extra) {
        // The base circuit's notes were given when it was loaded on its own.
        hyd_json_fragment_notes(extra, cx->file, cx->prefix);
    } else {
        note_model(&c, m);
    }
done:
    hyd_builder_free(b);
    return m;
}

hyd_model* hyd_model_from_json(const cJSON* circuit, const char* file, const char* prefix,
                               char* err, size_t errsz) {
    const jctx c = {file, prefix ? prefix : "", err, errsz};
    return from_json(circuit, &c, NULL, NULL);
}

hyd_model* hyd_model_from_json_extra(const cJSON* circuit, const char* file, const char* prefix,
                                     const cJSON* extra, const char* extra_file,
                                     const char* extra_prefix, char* err, size_t errsz) {
    const jctx c = {file, prefix ? prefix : "", err, errsz};
    const jctx cx = {extra_file, extra_prefix ? extra_prefix : "", err, errsz};
    return from_json(circuit, &c, extra, &cx);
}

hyd_model* hyd_model_load_json(const char* path, char* err, size_t errsz) {
    jctx c = {path, "", err, errsz};
    FILE* fp = fopen(path, "rb");
    if (!fp) {
        jerr(&c, "", "cannot open file");
        return NULL;
    }
    char* text = NULL;
    long n = -1;
    // The same limit as the model loader (json_util.h, JSON_MAX_FILE_BYTES):
    // parsing costs about 20 bytes of memory per byte of text.
    if (fseek(fp, 0, SEEK_END) == 0 && (n = ftell(fp)) >= 0 && n > (1L << 20)) {
        fclose(fp);
        jerr(&c, "", "too large (%ld bytes; input files are limited to %ld bytes)", n, 1L << 20);
        return NULL;
    }
    if (n >= 0 && fseek(fp, 0, SEEK_SET) == 0) {
        text = malloc((size_t)n + 1);
        if (text && fread(text, 1, (size_t)n, fp) != (size_t)n) {
            free(text);
            text = NULL;
        }
    }
    fclose(fp);
    if (!text) {
        jerr(&c, "", "cannot read file");
        return NULL;
    }
    text[n] = 0;
    const char* end = NULL;
    cJSON* root = cJSON_ParseWithOpts(text, &end, 1);
    if (!root) {
        // Report the line of the syntax error.
        int line = 1;
        for (const char* q = text; end && q < end && *q; ++q)
            line += *q == '\n';
        jerr(&c, "", "JSON syntax error near line %d", line);
        free(text);
        return NULL;
    }
    free(text);
    const cJSON* h = cJSON_GetObjectItemCaseSensitive(root, "hydraulics");
    hyd_model* m = h ? hyd_model_from_json(h, path, "hydraulics", err, errsz)
                     : hyd_model_from_json(root, path, "", err, errsz);
    cJSON_Delete(root);
    return m;
}

// Export: every numeric parameter (defaults included) so the saved file is
// complete and self-describing.
static cJSON* elem_to_json(const hyd_elem* e) {
    cJSON* o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddStringToObject(o, "name", e->name);
    cJSON_AddStringToObject(o, "type", hyd_type_name(e->type));
    int np, nports;
    const hyd_param_info* p = hyd_params_of(e->type, &np);
    const hyd_port_info* ports = hyd_ports_of(e->type, &nports);
    for (int k = 0; k < nports; ++k)
        if (e->port[k]) // an optional component reference may be unset
            cJSON_AddStringToObject(o, ports[k].name, e->port[k]);
    for (int k = 0; k < np; ++k)
        cJSON_AddNumberToObject(o, p[k].name, *(const double*)((const char*)&e->def + p[k].off));
    return o;
}

cJSON* hyd_model_to_json(const hyd_model* m) {
    cJSON* root = cJSON_CreateObject();
    cJSON* fl = cJSON_AddObjectToObject(root, "fluid");
    cJSON* nodes = cJSON_AddArrayToObject(root, "nodes");
    cJSON* comps = cJSON_AddArrayToObject(root, "components");
    if (!root || !fl || !nodes || !comps) {
        cJSON_Delete(root);
        return NULL;
    }
    int np;
    const hyd_param_info* p = hyd_fluid_params(&np);
    for (int k = 0; k < np; ++k)
        cJSON_AddNumberToObject(fl, p[k].name, *(const double*)((const char*)&m->fluid + p[k].off));
    for (int i = 0; i < m->nunode; ++i)
        cJSON_AddItemToArray(nodes, elem_to_json(&m->unode[i]));
    for (int i = 0; i < m->ncomp; ++i)
        cJSON_AddItemToArray(comps, elem_to_json(&m->comp[i]));
    return root;
}
