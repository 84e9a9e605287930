// session.c: the session file of a drive (session.h; format in docs/replay.md).
#include "session.h"

#include "engine.h"
#include "engine_backend.h"
#include "json_util.h"

#include <errno.h>
#include <inttypes.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

void session_model_hash(const cJSON* model_doc, char out[17]) {
    char* text = cJSON_PrintUnformatted(model_doc);
    uint64_t h = 1469598103934665603ull; // FNV-1a offset basis
    for (const unsigned char* p = (const unsigned char*)(text ? text : ""); *p; ++p) {
        h ^= *p;
        h *= 1099511628211ull; // FNV prime
    }
    free(text);
    snprintf(out, 17, "%016" PRIx64, h);
}

static void wcheck(session_writer* w) {
    if (!w->err && ferror(w->f)) w->err = errno ? errno : EIO;
}

int session_writer_open(session_writer* w, const char* path, const cJSON* model_doc, const char* model_file,
                        const engine* l, const sim_opts* o,
                        const char* scenario_path, const double q0[2], double slew0, double m3, bool window, int ncol,
                        char* err, size_t errsz) {
    memset(w, 0, sizeof *w);
    snprintf(w->path, sizeof w->path, "%s", path);
    cJSON* h = cJSON_CreateObject();
    cJSON* sc = NULL;
    if (scenario_path) {
        sc = json_load_file(scenario_path, err, errsz);
        if (!sc) {
            cJSON_Delete(h);
            return -1;
        }
    }
    char hash[17];
    session_model_hash(model_doc, hash);
    cJSON_AddNumberToObject(h, "version", SESSION_VERSION);
    cJSON_AddStringToObject(h, "recorded_by", window ? "window" : "headless");
    cJSON_AddStringToObject(h, "model_hash", hash);
    cJSON_AddStringToObject(h, "model_file", model_file);
    cJSON_AddItemToObject(h, "model", cJSON_Duplicate(model_doc, 1));
    const cJSON* mname = cJSON_GetObjectItemCaseSensitive(model_doc, "name");
    cJSON_AddStringToObject(h, "model_name", cJSON_IsString(mname) ? mname->valuestring : "");
    cJSON_AddStringToObject(h, "engine", engine_backend_name(l));
    // The functions every tick commands, in the engine's order: a replay
    // finds each by name (docs/replay.md), on this model or a changed one.
    w->nfn = engine_nfunction(l);
    w->u = calloc((size_t)w->nfn + 1, sizeof *w->u);
    if (!w->u) {
        snprintf(err, errsz, "out of memory");
        cJSON_Delete(h);
        cJSON_Delete(sc);
        return -1;
    }
    cJSON* fns = cJSON_AddArrayToObject(h, "functions");
    for (int k = 0; k < w->nfn; ++k) cJSON_AddItemToArray(fns, cJSON_CreateString(engine_function_name(l, k)));
    if (sc) cJSON_AddItemToObject(h, "scenario", sc);
    cJSON* s = cJSON_AddObjectToObject(h, "sim");
    cJSON_AddNumberToObject(s, "mechanics", o->mechanics);
    cJSON_AddNumberToObject(s, "variant", o->variant);
    cJSON_AddNumberToObject(s, "solver", o->solver);
    cJSON_AddNumberToObject(s, "h", o->h);
    cJSON_AddNumberToObject(s, "rtol", o->rtol);
    cJSON_AddNumberToObject(s, "atol", o->atol);
    cJSON_AddNumberToObject(s, "dt_ode", o->dt_ode);
    cJSON_AddNumberToObject(s, "jac_every", o->jac_every);
    cJSON_AddBoolToObject(s, "dense_jac", o->dense_jac);
    cJSON_AddNumberToObject(s, "kernel", o->kernel);
    cJSON_AddStringToObject(s, "world", o->world ? o->world : "");
    // The limiter acts on the commands: without its setting a replay cannot
    // give the drive's rows (docs/replay.md).
    cJSON_AddBoolToObject(s, "rcl", o->rcl);
    cJSON* st = cJSON_AddObjectToObject(h, "initial");
    cJSON_AddItemToObject(st, "q0", cJSON_CreateDoubleArray(q0, 2));
    cJSON_AddNumberToObject(st, "slew0", slew0);
    cJSON_AddNumberToObject(st, "load_mass", m3);
    cJSON_AddNumberToObject(h, "ncol", ncol);
    char* text = cJSON_PrintUnformatted(h);
    cJSON_Delete(h);
    if (!text) {
        snprintf(err, errsz, "out of memory");
        free(w->u);
        w->u = NULL;
        return -1;
    }
    w->f = fopen(path, "w");
    if (!w->f) {
        snprintf(err, errsz, "cannot write %s: %s", path, strerror(errno));
        free(text);
        free(w->u);
        w->u = NULL;
        return -1;
    }
    errno = 0;
    fprintf(w->f, "%s %d\n%s\n", SESSION_MAGIC, SESSION_VERSION, text);
    free(text);
    wcheck(w);
    return 0;
}

void session_writer_hook(session_writer* w, int attach) {
    if (w->f && w->nhook < 4) w->hook[w->nhook++] = (signed char)(attach != 0);
}

void session_writer_tick(session_writer* w, double tm, double target, const double* u, int nu, const double* row,
                         int ncol) {
    if (!w->f || w->err) return;
    if (nu != w->nfn) { // the header names nfn functions: another count would be read back wrong
        w->err = EINVAL;
        return;
    }
    errno = 0;
    for (int k = 0; k < w->nhook; ++k) fprintf(w->f, "k %d\n", w->hook[k]);
    w->nhook = 0;
    // %.17g: every double reads back to the same bits.
    fprintf(w->f, "t %.17g %.17g", tm, target);
    for (int k = 0; k < nu; ++k) fprintf(w->f, " %.17g", u[k]);
    fprintf(w->f, " %d\n", row ? 1 : 0);
    if (row) {
        // The row as the record writes it (sim_csv_row), so the replay's
        // CSV can be compared byte for byte.
        fputs("r ", w->f);
        sim_csv_row(w->f, row, ncol);
        ++w->rows;
    }
    wcheck(w);
}

void session_writer_tick_engine(session_writer* w, const engine* l, double tm, double target, const double* row,
                                int ncol) {
    if (!w->f || w->err || !w->u) return;
    const int n = engine_nfunction(l) < w->nfn ? engine_nfunction(l) : w->nfn;
    for (int k = 0; k < n; ++k) w->u[k] = engine_function_command(l, k);
    session_writer_tick(w, tm, target, w->u, engine_nfunction(l), row, ncol);
}

int session_writer_close(session_writer* w, const char* why) {
    free(w->u);
    w->u = NULL;
    if (!w->f) return w->err;
    errno = 0;
    fprintf(w->f, "e %s\n", why);
    wcheck(w);
    int e = fclose(w->f) ? (errno ? errno : EIO) : 0;
    w->f = NULL;
    return w->err ? w->err : e;
}

static int fail(session* s, char* err, size_t errsz, const char* fmt, const char* what, long line) {
    char msg[400];
    snprintf(msg, sizeof msg, fmt, what);
    if (line > 0) snprintf(err, errsz, "session %s: line %ld: %s", s->path, line, msg);
    else snprintf(err, errsz, "session %s: %s", s->path, msg);
    session_free(s);
    return -1;
}

// One line of any length into *buf (without the newline); false at the end.
static bool read_line(FILE* f, char** buf, size_t* cap) {
    size_t n = 0;
    int ch;
    while ((ch = fgetc(f)) != EOF && ch != '\n') {
        if (n + 2 > *cap) {
            size_t nc = *cap ? *cap * 2 : 4096;
            char* b = realloc(*buf, nc);
            if (!b) return false;
            *buf = b;
            *cap = nc;
        }
        (*buf)[n++] = (char)ch;
    }
    if (ch == EOF && n == 0) return false;
    if (!*buf) {
        *buf = malloc(1);
        *cap = 1;
    }
    (*buf)[n] = 0;
    return true;
}

static double num(const cJSON* o, const char* key, bool* ok) {
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!cJSON_IsNumber(v)) {
        *ok = false;
        return 0;
    }
    return v->valuedouble;
}

int session_load(const char* path, session* s, char* err, size_t errsz) {
    memset(s, 0, sizeof *s);
    snprintf(s->path, sizeof s->path, "%s", path);
    FILE* f = fopen(path, "r");
    if (!f) return fail(s, err, errsz, "cannot read: %s", strerror(errno), 0);
    char* line = NULL;
    size_t cap = 0;
    long ln = 1;
    int ver = 0;
    if (!read_line(f, &line, &cap) || strncmp(line, SESSION_MAGIC " ", strlen(SESSION_MAGIC) + 1)) {
        fclose(f);
        free(line);
        return fail(s, err, errsz, "not a cranesim session file (its first line is not '%s N')", SESSION_MAGIC, 0);
    }
    if (sscanf(line + strlen(SESSION_MAGIC), "%d", &ver) != 1 || ver < SESSION_VERSION_MIN || ver > SESSION_VERSION) {
        char v[64];
        snprintf(v, sizeof v, "%.40s", line + strlen(SESSION_MAGIC) + 1);
        fclose(f);
        free(line);
        char msg[160];
        snprintf(msg, sizeof msg, "format version %s, this cranesim reads versions %d to %d", v, SESSION_VERSION_MIN,
                 SESSION_VERSION);
        return fail(s, err, errsz, "%s", msg, 1);
    }
    s->version = ver;
    ++ln;
    if (!read_line(f, &line, &cap) || !(s->header = cJSON_Parse(line)) || !cJSON_IsObject(s->header)) {
        fclose(f);
        free(line);
        return fail(s, err, errsz, "%s", "header: expected one line of JSON", 2);
    }
    bool ok = true;
    const cJSON* h = s->header;
    s->model = cJSON_GetObjectItemCaseSensitive(h, "model");
    const cJSON* hash = cJSON_GetObjectItemCaseSensitive(h, "model_hash");
    if (!cJSON_IsObject(s->model) || !cJSON_IsString(hash)) {
        fclose(f);
        free(line);
        return fail(s, err, errsz, "%s", "header: model and model_hash are required", 2);
    }
    char want[17];
    session_model_hash(s->model, want);
    if (strcmp(want, hash->valuestring)) {
        fclose(f);
        free(line);
        char msg[200];
        snprintf(msg, sizeof msg,
                 "model_hash: the model in the file hashes to %s, not the recorded %.20s (the model was changed "
                 "after recording, or recorded by another model version)",
                 want, hash->valuestring);
        return fail(s, err, errsz, "%s", msg, 2);
    }
    const cJSON* sc = cJSON_GetObjectItemCaseSensitive(h, "scenario");
    s->scenario = cJSON_IsObject(sc) ? sc : NULL;
    const cJSON* rb = cJSON_GetObjectItemCaseSensitive(h, "recorded_by");
    s->window = cJSON_IsString(rb) && !strcmp(rb->valuestring, "window");
    const cJSON* so = cJSON_GetObjectItemCaseSensitive(h, "sim");
    const cJSON* in = cJSON_GetObjectItemCaseSensitive(h, "initial");
    s->sim = sim_default_opts();
    if (!cJSON_IsObject(so) || !cJSON_IsObject(in)) ok = false;
    else {
        s->sim.mechanics = (sim_mechanics)(int)num(so, "mechanics", &ok);
        s->sim.variant = (lagrange_variant)(int)num(so, "variant", &ok);
        s->sim.solver = (hyd_method)(int)num(so, "solver", &ok);
        s->sim.h = num(so, "h", &ok);
        s->sim.rtol = num(so, "rtol", &ok);
        s->sim.atol = num(so, "atol", &ok);
        s->sim.dt_ode = num(so, "dt_ode", &ok);
        s->sim.jac_every = (int)num(so, "jac_every", &ok);
        s->sim.dense_jac = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(so, "dense_jac"));
        s->sim.kernel = (sim_kernel)(int)num(so, "kernel", &ok);
        // A session written before the limiter's setting was recorded has
        // none: it replays with the limiter on, drive's default then as now
        // (session.h; docs/replay.md).
        const cJSON* rcl = cJSON_GetObjectItemCaseSensitive(so, "rcl");
        s->rcl_recorded = cJSON_IsBool(rcl);
        s->sim.rcl = s->rcl_recorded ? cJSON_IsTrue(rcl) : true;
        if (rcl && !s->rcl_recorded) ok = false;
        const cJSON* w = cJSON_GetObjectItemCaseSensitive(so, "world");
        if (cJSON_IsString(w)) snprintf(s->world, sizeof s->world, "%s", w->valuestring);
        s->sim.world = s->world[0] ? s->world : NULL;
        const cJSON* q = cJSON_GetObjectItemCaseSensitive(in, "q0");
        if (cJSON_GetArraySize(q) != 2) ok = false;
        else {
            s->q0[0] = cJSON_GetArrayItem(q, 0)->valuedouble;
            s->q0[1] = cJSON_GetArrayItem(q, 1)->valuedouble;
        }
        s->slew0 = num(in, "slew0", &ok);
        s->m3 = num(in, "load_mass", &ok);
        s->ncol = (int)num(h, "ncol", &ok);
    }
    // The functions the ticks command: version 1 has the two-link crane's
    // three, version 2 names them.
    static const char* const v1_fn[3] = {"lift", "jib", "slew"};
    const cJSON* fns = cJSON_GetObjectItemCaseSensitive(h, "functions");
    if (ok && ver == 1) {
        s->nfn = 3;
        s->fn = calloc(3, sizeof *s->fn);
        if (s->fn) memcpy(s->fn, v1_fn, sizeof v1_fn);
    } else if (ok) {
        s->nfn = cJSON_GetArraySize(fns);
        s->fn = cJSON_IsArray(fns) && s->nfn > 0 ? calloc((size_t)s->nfn, sizeof *s->fn) : NULL;
        for (int k = 0; s->fn && k < s->nfn; ++k) {
            const cJSON* n = cJSON_GetArrayItem(fns, k);
            s->fn[k] = cJSON_IsString(n) && n->valuestring[0] ? n->valuestring : NULL;
            for (int j = 0; j < k && s->fn[k]; ++j)
                if (s->fn[j] && !strcmp(s->fn[j], s->fn[k])) s->fn[k] = NULL; // a name twice
            if (!s->fn[k]) {
                free(s->fn);
                s->fn = NULL;
            }
        }
    }
    if (ok && !s->fn) {
        fclose(f);
        free(line);
        return fail(s, err, errsz, "%s",
                    "header: functions: expected an array of the functions' names, each once", 2);
    }
    if (ok && !engine_backend_of(&s->sim)) { // a backend this build does not have: never replayed on another
        fclose(f);
        free(line);
        char known[128], msg[256];
        snprintf(msg, sizeof msg, "header: sim.mechanics: %d names no backend (known: %s)", (int)s->sim.mechanics,
                 engine_backend_names(known, sizeof known, NULL));
        return fail(s, err, errsz, "%s", msg, 2);
    }
    // Version 1 rows are the two-link crane's (SIM_NCOL at most); version 2
    // a chain's, sized by its model (a bound only against a corrupt file).
    if (!ok || s->ncol < 1 || s->ncol > (ver == 1 ? SIM_NCOL : SESSION_MAX_NCOL) || !(s->sim.h > 0)) {
        fclose(f);
        free(line);
        return fail(s, err, errsz, "%s", "header: sim, initial and ncol are required and must be valid", 2);
    }
    long captick = 0, caprow = 0;
    int nhook = 0;
    signed char hooks[4];
    bool ended = false;
    char tbad[200];
    while (read_line(f, &line, &cap)) {
        ++ln;
        const char* bad = NULL;
        if (ended) bad = "text after the end line";
        else if (line[0] == 'k' && line[1] == ' ') {
            int a;
            if (sscanf(line + 2, "%d", &a) != 1 || (a != 0 && a != 1) || nhook >= 4) bad = "expected 'k 0' or 'k 1'";
            else hooks[nhook++] = (signed char)a;
        } else if (line[0] == 't' && line[1] == ' ') {
            session_tick t = {.row_line = -1};
            int row = 0;
            if (s->ntick == captick) {
                captick = captick ? 2 * captick : 1024;
                session_tick* nt = realloc(s->tick, sizeof *nt * (size_t)captick);
                double* nu = realloc(s->uv, sizeof *nu * (size_t)captick * (size_t)s->nfn);
                if (nt) s->tick = nt;
                if (nu) s->uv = nu;
                if (!nt || !nu) bad = "out of memory";
            }
            // TM TARGET, one command per function, ROW (0 or 1).
            double* u = bad ? NULL : s->uv + (size_t)s->ntick * (size_t)s->nfn;
            char* p = line + 2;
            char* e;
            int got = 0;
            for (int k = 0; u && k < s->nfn + 2; ++k, ++got, p = e) {
                const double v = strtod(p, &e);
                if (e == p || (*e != ' ' && *e)) break;
                if (k == 0) t.tm = v;
                else if (k == 1) t.target = v;
                else u[k - 2] = v;
            }
            if (u && got == s->nfn + 2) {
                const long r = strtol(p, &e, 10);
                if (e == p || *e || (r != 0 && r != 1)) got = -1;
                else row = (int)r;
            }
            if (!bad && got != s->nfn + 2) {
                snprintf(tbad, sizeof tbad, "expected 't TM TARGET' then %d commands (%s%s) and ROW 0 or 1", s->nfn,
                         s->fn[0], s->nfn > 1 ? " ..." : "");
                bad = tbad;
            } else if (!bad) {
                t.row = row != 0;
                t.nhook = nhook;
                memcpy(t.hook, hooks, sizeof hooks);
                nhook = 0;
                s->tick[s->ntick++] = t;
            }
        } else if (line[0] == 'r' && line[1] == ' ') {
            if (s->ntick == 0 || !s->tick[s->ntick - 1].row || s->tick[s->ntick - 1].row_line >= 0)
                bad = "a row without its tick";
            else {
                if (s->nrow == caprow) {
                    caprow = caprow ? 2 * caprow : 1024;
                    char** nr = realloc(s->rows, sizeof *nr * (size_t)caprow);
                    if (!nr) bad = "out of memory";
                    else s->rows = nr;
                }
                if (!bad && !(s->rows[s->nrow] = strdup(line + 2))) bad = "out of memory";
                if (!bad) s->tick[s->ntick - 1].row_line = s->nrow++;
            }
        } else if (line[0] == 'e' && (line[1] == ' ' || !line[1])) {
            snprintf(s->end, sizeof s->end, "%s", line[1] ? line + 2 : "");
            ended = true;
        } else
            bad = "expected a line starting 'k', 't', 'r' or 'e'";
        if (bad) {
            fclose(f);
            free(line);
            return fail(s, err, errsz, "%s", bad, ln);
        }
    }
    fclose(f);
    free(line);
    // Each tick's commands, now that uv no longer moves.
    for (long i = 0; i < s->ntick; ++i) s->tick[i].u = s->uv + (size_t)i * (size_t)s->nfn;
    // A session of a drive killed outright has no end line: its ticks up to
    // there still replay.
    if (!ended) snprintf(s->end, sizeof s->end, "no end line (the drive was cut short)");
    return 0;
}

void session_free(session* s) {
    cJSON_Delete(s->header);
    free(s->tick);
    free(s->uv);
    free(s->fn);
    s->uv = NULL;
    s->fn = NULL;
    for (long i = 0; i < s->nrow; ++i) free(s->rows[i]);
    free(s->rows);
    s->header = NULL;
    s->tick = NULL;
    s->rows = NULL;
    s->ntick = s->nrow = 0;
}

model* session_model(const session* s, const char* model_path, const char* const* sets, int nset, char* err,
                     size_t errsz) {
    if (model_path) return model_load(model_path, sets, nset, err, errsz);
    cJSON* root = cJSON_Duplicate(s->model, 1);
    for (int i = 0; i < nset; ++i) {
        char e[400];
        if (json_set_path(root, sets[i], e, sizeof e)) {
            snprintf(err, errsz, "session %s: model: %s", s->path, e);
            cJSON_Delete(root);
            return NULL;
        }
    }
    const cJSON* file = cJSON_GetObjectItemCaseSensitive(s->header, "model_file");
    char name[300];
    snprintf(name, sizeof name, "%s (recorded in the session)", cJSON_IsString(file) && file->valuestring[0] ? file->valuestring : "model");
    return model_from_json(root, name, err, errsz);
}

void session_csv_header(const session* s, const engine* l, FILE* f) {
    int n;
    const sim_channel* ch = engine_channels(l, &n);
    for (int c = 0; c < n; ++c) fprintf(f, "%s%s", c ? "," : "", ch[c].name);
    fputs(s->window ? ",segment\n" : "\n", f);
}

int session_function_map(const session* s, const engine* l, int* map, char* dropped, size_t dsz, char* err,
                         size_t errsz) {
    if (dropped && dsz) dropped[0] = 0;
    const int n = engine_nfunction(l);
    // Version 1 carries the two-link crane's commands, lift, jib, slew, in
    // the two-link engine's order: as they were replayed before names.
    const bool v1_two_link = s->version == 1 && (engine_caps(l) & ENGINE_CAP_TWO_LINK) && n == 3;
    for (int k = 0; k < n; ++k) map[k] = v1_two_link ? k : -1;
    if (v1_two_link) return n;
    int found = 0;
    for (int j = 0; j < s->nfn; ++j) {
        const int k = engine_find_function(l, s->fn[j]);
        bool commanded = k < 0 ? false : true;
        for (long i = 0; k < 0 && i < s->ntick && !commanded; ++i) commanded = s->tick[i].u[j] != 0.0;
        if (k < 0 && !commanded) {
            // Never commanded: leaving it out replays the same operator.
            const size_t L = dropped ? strlen(dropped) : 0;
            if (dropped && L + 1 < dsz) snprintf(dropped + L, dsz - L, "%s%s", L ? ", " : "", s->fn[j]);
            continue;
        }
        if (k < 0) {
            char list[600];
            int w = 0;
            for (int i = 0; i < n && w >= 0 && (size_t)w < sizeof list; ++i)
                w += snprintf(list + w, sizeof list - (size_t)w, "%s%s", i ? ", " : "", engine_function_name(l, i));
            snprintf(err, errsz,
                     "session %s: functions: '%s' is not a function of this model (its functions: %s); the session "
                     "commands it, so the replay would not be the recorded operator's",
                     s->path, s->fn[j], list);
            return -1;
        }
        map[k] = j;
        ++found;
    }
    return found;
}

void session_tick_commands(const session* s, long i, const int* map, int n, double* u) {
    const double* su = s->tick[i].u;
    for (int k = 0; k < n; ++k) u[k] = map[k] >= 0 ? su[map[k]] : 0.0;
}
