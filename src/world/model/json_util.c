// json_util.c: see json_util.h.
#include "json_util.h"
#include "param_names.h"

#include "hydraulics.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/stat.h>

void json_fail(json_ctx* c, const char* path, const char* fmt, ...) {
    if (c->failed) return;
    c->failed = true;
    if (!c->err || c->errsz == 0) return;
    int k = snprintf(c->err, c->errsz, "%s: %s: ", c->file ? c->file : "(input)",
                     path && *path ? path : "(top level)");
    if (k < 0 || (size_t)k >= c->errsz) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->err + k, c->errsz - (size_t)k, fmt, ap);
    va_end(ap);
}

// Length of the JSON number at s (RFC 8259: -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?),
// or 0 if s does not start with one. cJSON hands any run of [0-9+-.eE] to
// strtod, so it takes 00.1 or 1. that other JSON readers reject; our files
// must stay readable by every tool.
static size_t json_number_len(const char* s) {
    const char* p = s;
    if (*p == '-') ++p;
    if (*p == '0') ++p;
    else if (*p >= '1' && *p <= '9') while (isdigit((unsigned char)*p)) ++p;
    else return 0;
    if (*p == '.') {
        ++p;
        if (!isdigit((unsigned char)*p)) return 0;
        while (isdigit((unsigned char)*p)) ++p;
    }
    if (*p == 'e' || *p == 'E') {
        ++p;
        if (*p == '+' || *p == '-') ++p;
        if (!isdigit((unsigned char)*p)) return 0;
        while (isdigit((unsigned char)*p)) ++p;
    }
    return (size_t)(p - s);
}

// True if c can continue a token cJSON reads as a number.
static bool number_char(char c) { return isdigit((unsigned char)c) || strchr("+-.eE", c); }

// Every number outside strings of an already parsed text must be a JSON
// number: "file: line L, column C: invalid number '00.1'".
static int check_numbers(const char* text, const char* path, char* err, size_t errsz) {
    int line = 1, col = 1;
    for (const char* p = text; *p;) {
        if (*p == '"') { // skip the string, escapes included
            for (++p, ++col; *p && *p != '"'; ++p, ++col)
                if (*p == '\\' && p[1]) {
                    // cJSON ends the string at an escaped NUL: "lift\u0000_cyl"
                    // would silently become "lift".
                    if (!strncmp(p, "\\u0000", 6)) {
                        snprintf(err, errsz, "%s: line %d, column %d: \\u0000 (a NUL character) is not allowed in a string",
                                 path, line, col);
                        return -1;
                    }
                    ++p, ++col;
                }
            if (*p) ++p, ++col;
            continue;
        }
        if (*p == '-' || isdigit((unsigned char)*p)) {
            size_t run = 0;
            while (p[run] && number_char(p[run])) ++run;
            if (json_number_len(p) != run) {
                snprintf(err, errsz, "%s: line %d, column %d: invalid number '%.*s' (JSON: no leading zeros, digits "
                                     "on both sides of a decimal point)",
                         path, line, col, (int)(run < 32 ? run : 32), p);
                return -1;
            }
            p += run, col += (int)run;
            continue;
        }
        if (*p == '\n') ++line, col = 1;
        else ++col;
        ++p;
    }
    return 0;
}

// One member of an object, for the duplicate search: its key and its place.
typedef struct key_pos {
    const char* key;
    int pos;
} key_pos;

static int cmp_key_pos(const void* a, const void* b) {
    const key_pos *x = a, *y = b;
    int d = strcmp(x->key, y->key);
    return d ? d : (x->pos > y->pos) - (x->pos < y->pos);
}

// The key of node's first member (in document order) that is given again
// later in the same object, or NULL. Sorting the keys makes this O(n log n):
// the pairwise scan it replaces took 17 minutes on an object of 800,000 keys.
// Small objects (every object of a shipped file: the largest, sandbox.json's
// truck, has 17 members) keep the pairwise scan, which needs no allocation.
// Sets *oom when the sort buffer cannot be had.
static const char* first_duplicate(const cJSON* node, bool* oom) {
    int n = 0;
    for (const cJSON* it = node->child; it; it = it->next) ++n;
    if (n <= 32) {
        for (const cJSON* it = node->child; it; it = it->next)
            for (const cJSON* later = it->next; later; later = later->next)
                if (it->string && later->string && !strcmp(it->string, later->string)) return it->string;
        return NULL;
    }
    key_pos* k = malloc((size_t)n * sizeof *k);
    if (!k) {
        *oom = true;
        return NULL;
    }
    int m = 0, i = 0;
    for (const cJSON* it = node->child; it; it = it->next, ++i)
        if (it->string) k[m++] = (key_pos){it->string, i};
    qsort(k, (size_t)m, sizeof *k, cmp_key_pos);
    // Equal keys are now adjacent, each run in document order: the run whose
    // first member comes earliest is the one the pairwise scan would report.
    const char* dup = NULL;
    int dup_pos = n;
    for (int j = 1; j < m; ++j)
        if (!strcmp(k[j - 1].key, k[j].key) && (j == 1 || strcmp(k[j - 2].key, k[j].key)) && k[j - 1].pos < dup_pos) {
            dup = k[j - 1].key;
            dup_pos = k[j - 1].pos;
        }
    free(k);
    return dup;
}

// Reject an object member given twice: cJSON keeps both and every lookup
// finds the first, so the second would be silently ignored.
static int check_duplicates(const cJSON* node, const char* at, const char* path, char* err, size_t errsz) {
    char p[256];
    if (cJSON_IsObject(node)) {
        bool oom = false;
        const char* dup = first_duplicate(node, &oom);
        if (oom) {
            snprintf(err, errsz, "%s: out of memory", path);
            return -1;
        }
        if (dup) {
            json_path(p, sizeof p, at, dup);
            snprintf(err, errsz, "%s: %s: given twice (duplicate field)", path, p);
            return -1;
        }
    }
    int i = 0;
    for (const cJSON* it = node ? node->child : NULL; it; it = it->next, ++i) {
        if (!cJSON_IsObject(it) && !cJSON_IsArray(it)) continue;
        if (cJSON_IsObject(node)) json_path(p, sizeof p, at, it->string ? it->string : "?");
        else json_path_index(p, sizeof p, at, i);
        if (check_duplicates(it, p, path, err, errsz)) return -1;
    }
    return 0;
}

cJSON* json_load_file(const char* path, char* err, size_t errsz) {
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        snprintf(err, errsz, "%s: not a regular file", path);
        return NULL;
    }
    // Refused before reading: parsing costs about 20 bytes of memory per
    // byte of text (a 59 MB scenario took 1.2 GB before it was refused).
    if (stat(path, &st) == 0 && st.st_size > JSON_MAX_FILE_BYTES) {
        snprintf(err, errsz, "%s: too large (%lld bytes; input files are limited to %ld bytes, docs/files.md)", path,
                 (long long)st.st_size, (long)JSON_MAX_FILE_BYTES);
        return NULL;
    }
    FILE* f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errsz, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    if (n < 0 || n > JSON_MAX_FILE_BYTES) {
        fclose(f);
        snprintf(err, errsz, "%s: cannot read (size %ld bytes)", path, n);
        return NULL;
    }
    char* buf = malloc((size_t)n + 1);
    if (!buf) {
        fclose(f);
        snprintf(err, errsz, "%s: out of memory", path);
        return NULL;
    }
    size_t got = fread(buf, 1, (size_t)n, f);
    fclose(f);
    buf[got] = 0;
    cJSON* root = json_parse(buf, path, err, errsz);
    free(buf);
    return root;
}

cJSON* json_parse(const char* text, const char* name, char* err, size_t errsz) {
    const char* end = NULL;
    cJSON* root = cJSON_ParseWithOpts(text, &end, 1);
    if (!root) {
        // Report line and column of the parse failure: the one thing a user
        // needs to find a missing comma.
        const char* at = end ? end : cJSON_GetErrorPtr();
        int line = 1, col = 1;
        for (const char* p = text; at && p < at && *p; ++p) {
            if (*p == '\n') { ++line; col = 1; } else ++col;
        }
        snprintf(err, errsz, "%s: line %d, column %d: invalid JSON", name, line, col);
    } else if (check_numbers(text, name, err, errsz) || check_duplicates(root, "", name, err, errsz)) {
        cJSON_Delete(root);
        root = NULL;
    }
    return root;
}

const char* json_file_kind(const cJSON* root) {
    if (!cJSON_IsObject(root)) return NULL;
    if (cJSON_GetObjectItemCaseSensitive(root, "mechanics") || cJSON_GetObjectItemCaseSensitive(root, "hydraulics"))
        return "model";
    if (cJSON_GetObjectItemCaseSensitive(root, "type")) return "world";
    if (cJSON_GetObjectItemCaseSensitive(root, "duration") || cJSON_GetObjectItemCaseSensitive(root, "commands"))
        return "scenario";
    return NULL;
}

bool json_wrong_kind(json_ctx* c, const cJSON* root, const char* want) {
    const char* k = json_file_kind(root);
    if (!k || !strcmp(k, want) || c->failed) return false;
    c->failed = true;
    if (c->err && c->errsz)
        snprintf(c->err, c->errsz, "%s: this is a %s file (use --%s), not a %s", c->file ? c->file : "(input)", k, k,
                 want);
    return true;
}

void json_path(char* out, size_t n, const char* parent, const char* key) {
    if (parent && *parent) snprintf(out, n, "%s.%s", parent, key);
    else snprintf(out, n, "%s", key);
}

void json_path_index(char* out, size_t n, const char* parent, int index) {
    snprintf(out, n, "%s[%d]", parent ? parent : "", index);
}

static const char* type_name(const cJSON* v) {
    if (cJSON_IsNumber(v)) return "a number";
    if (cJSON_IsString(v)) return "a string";
    if (cJSON_IsBool(v)) return "a boolean";
    if (cJSON_IsNull(v)) return "null";
    if (cJSON_IsArray(v)) return "an array";
    if (cJSON_IsObject(v)) return "an object";
    return "invalid";
}

// Member lookup shared by the getters: reports "missing" for required members.
static const cJSON* member(json_ctx* c, const cJSON* obj, const char* path, const char* key,
                           bool required, char* full, size_t fn) {
    json_path(full, fn, path, key);
    if (c->failed || !obj) return NULL;
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v && required) json_fail(c, full, "missing (required)");
    return v;
}

const cJSON* json_obj(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required) {
    char full[256];
    const cJSON* v = member(c, obj, path, key, required, full, sizeof full);
    if (v && !cJSON_IsObject(v)) {
        json_fail(c, full, "must be an object, got %s", type_name(v));
        return NULL;
    }
    return v;
}

const cJSON* json_arr(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required) {
    char full[256];
    const cJSON* v = member(c, obj, path, key, required, full, sizeof full);
    if (v && !cJSON_IsArray(v)) {
        json_fail(c, full, "must be an array, got %s", type_name(v));
        return NULL;
    }
    return v;
}

// The member key of obj that must be a number: NULL when absent (and not
// required) or not a number (the failure recorded); its full path in full.
static const cJSON* number_member(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                                  char* full, size_t n) {
    const cJSON* v = member(c, obj, path, key, required, full, n);
    if (v && !cJSON_IsNumber(v)) {
        json_fail(c, full, "must be a number, got %s", type_name(v));
        return NULL;
    }
    return v;
}

double json_num(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                double def, double lo, double hi) {
    char full[256];
    const cJSON* v = number_member(c, obj, path, key, required, full, sizeof full);
    if (!v) return def;
    double x = v->valuedouble;
    if (!isfinite(x)) json_fail(c, full, "must be a finite number");
    else if (x < lo) json_fail(c, full, "must be >= %g, got %g", lo, x);
    else if (x > hi) json_fail(c, full, "must be <= %g, got %g", hi, x);
    return x;
}

void json_note(json_ctx* c, const char* path, const char* fmt, ...) {
    if (c->nnotes >= JSON_MAX_NOTES) return;
    char* out = c->notes[c->nnotes++];
    const size_t n = sizeof c->notes[0];
    int k = snprintf(out, n, "%s: %s: ", c->file ? c->file : "(input)", path && *path ? path : "(top level)");
    if (k < 0 || (size_t)k >= n) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(out + k, n - (size_t)k, fmt, ap);
    va_end(ap);
}

void json_flush_notes(json_ctx* c) {
    if (!c->failed)
        for (int i = 0; i < c->nnotes; ++i) hyd_note(c->notes[i]);
    c->nnotes = 0;
}

void json_range_check(json_ctx* c, const char* full, double v, const json_range* r) {
    if (c->failed) return;
    char got[24], rng[80];
    hyd_fmt_num(got, sizeof got, v);
    if (!isfinite(v)) {
        json_fail(c, full, "must be a finite number");
    } else if (r->lo > 0 && !(v > 0)) {
        json_fail(c, full, "must be > 0, got %s", got);
    } else if (v < r->lo || v > r->hi) {
        hyd_fmt_range(rng, sizeof rng, r->lo, r->hi, r->unit);
        json_fail(c, full, "must be in %s, got %s", rng, got);
    } else if (v < r->tlo || v > r->thi) {
        hyd_fmt_range(rng, sizeof rng, r->tlo, r->thi, r->unit);
        json_note(c, full, "%s%s%s is outside the typical range %s", got, r->unit && *r->unit ? " " : "",
                  r->unit ? r->unit : "", rng);
    }
}

double json_num_r(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                  double def, const json_range* r) {
    char full[256];
    const cJSON* v = number_member(c, obj, path, key, required, full, sizeof full);
    if (!v) return def;
    json_range_check(c, full, v->valuedouble, r);
    return v->valuedouble;
}

void json_vec_r(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                double* out, int n, const json_range* r) {
    char full[256];
    json_path(full, sizeof full, path, key);
    if (!required && !cJSON_GetObjectItemCaseSensitive(obj, key)) return;
    json_vec(c, obj, path, key, required, out, n);
    for (int i = 0; i < n && !c->failed; ++i) {
        char p[272];
        json_path_index(p, sizeof p, full, i);
        json_range_check(c, p, out[i], r);
    }
}

double json_pos(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                double def) {
    char full[256];
    json_path(full, sizeof full, path, key);
    double x = json_num(c, obj, path, key, required, def, -INFINITY, INFINITY);
    if (!c->failed && !(x > 0)) json_fail(c, full, "must be > 0, got %g", x);
    return x;
}

int json_int(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required, int def,
             int lo, int hi) {
    char full[256];
    json_path(full, sizeof full, path, key);
    double x = json_num(c, obj, path, key, required, def, lo, hi);
    if (!c->failed && x != floor(x)) json_fail(c, full, "must be a whole number, got %g", x);
    // Converted only once it is known to fit: (int)2e67 is undefined
    // behaviour (it gave INT_MIN here), so a failed field yields def.
    return c->failed ? def : (int)x;
}

bool json_bool(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool def) {
    char full[256];
    const cJSON* v = member(c, obj, path, key, false, full, sizeof full);
    if (!v) return def;
    if (!cJSON_IsBool(v)) {
        json_fail(c, full, "must be true or false, got %s", type_name(v));
        return def;
    }
    return cJSON_IsTrue(v);
}

void json_str(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
              const char* def, char* out, size_t n) {
    char full[256];
    const cJSON* v = member(c, obj, path, key, required, full, sizeof full);
    const char* s = def ? def : "";
    if (v) {
        if (!cJSON_IsString(v)) {
            json_fail(c, full, "must be a string, got %s", type_name(v));
        } else {
            s = v->valuestring;
            if (strlen(s) >= n) json_fail(c, full, "too long (max %zu characters)", n - 1);
        }
    }
    snprintf(out, n, "%s", s);
}

void json_vec(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
              double* out, int n) {
    char full[256];
    const cJSON* v = member(c, obj, path, key, required, full, sizeof full);
    if (!v) return;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n) {
        json_fail(c, full, "must be an array of %d numbers", n);
        return;
    }
    for (int i = 0; i < n; ++i) {
        const cJSON* e = cJSON_GetArrayItem(v, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) {
            char p[272];
            json_path_index(p, sizeof p, full, i);
            if (cJSON_IsNumber(e)) json_fail(c, p, "must be a finite number");
            else json_fail(c, p, "must be a finite number, got %s", type_name(e));
            return;
        }
        out[i] = e->valuedouble;
    }
}

void json_only_keys(json_ctx* c, const cJSON* obj, const char* path, const char* const* allowed) {
    if (c->failed || !obj) return;
    const cJSON* it;
    cJSON_ArrayForEach(it, obj) {
        bool ok = false;
        for (const char* const* a = allowed; *a && !ok; ++a) ok = it->string && !strcmp(*a, it->string);
        if (!ok) {
            char full[256];
            json_path(full, sizeof full, path, it->string ? it->string : "?");
            json_fail(c, full, "unknown field (typo?)");
            return;
        }
    }
}

// One step of a --set path: a field name (".name", also an array element's
// "name" member, or its index when all digits) or an index ("[i]").
typedef struct path_seg {
    char key[64];
    bool index; ///< written as [i]
} path_seg;

// Split a --set path into segments. The grammar is strict so that a typo
// such as "mechanics..gravity" or "links[0" is an error, not a guess:
//   path := name ( "." name | "[" digits "]" )*
// Returns the number of segments, or -1 with the problem in why.
static int parse_set_path(const char* path, path_seg* seg, int maxseg, char* why, size_t whysz) {
    int n = 0;
    const char* p = path;
    for (;;) {
        const bool index = n > 0 && *p == '[';
        if (n > 0 && !index) {
            if (*p != '.') {
                snprintf(why, whysz, "expected '.' or '[' at character %d", (int)(p - path) + 1);
                return -1;
            }
            ++p;
        }
        if (index) ++p;
        const char* start = p;
        size_t k = 0;
        if (index) {
            while (isdigit((unsigned char)p[k])) ++k;
            if (!k || p[k] != ']') {
                snprintf(why, whysz, "expected an index [0], [1], ... at character %d", (int)(start - path));
                return -1;
            }
        } else {
            while (p[k] && !strchr(".[]", p[k])) ++k;
            if (!k) {
                snprintf(why, whysz, "empty field name at character %d", (int)(start - path) + 1);
                return -1;
            }
        }
        // An index is written as JSON writes numbers: "[01]" (or ".01") is
        // no index anyone writes on purpose, and reading it as [1] hides a
        // slip (links[01] vs links[0]).
        if (k > 1 && start[0] == '0' && strspn(start, "0123456789") >= k) {
            snprintf(why, whysz, "index '%.*s' at character %d has a leading zero (write %s%ld%s)", (int)k, start,
                     (int)(start - path) + 1, index ? "[" : ".", strtol(start, NULL, 10), index ? "]" : "");
            return -1;
        }
        if (n == maxseg || k >= sizeof seg[0].key) {
            snprintf(why, whysz, "path too deep or a name too long");
            return -1;
        }
        memcpy(seg[n].key, start, k);
        seg[n].key[k] = 0;
        seg[n].index = index;
        ++n;
        p = start + k + (index ? 1 : 0);
        if (!*p) return n;
    }
}

// Find the child named by one path segment: an object key, or for arrays an
// index or the element whose "name" equals the segment.
static cJSON* child_by_segment(cJSON* node, const path_seg* seg) {
    if (seg->index) {
        if (!cJSON_IsArray(node)) return NULL;
        char* endp;
        long i = strtol(seg->key, &endp, 10);
        return i < cJSON_GetArraySize(node) ? cJSON_GetArrayItem(node, (int)i) : NULL;
    }
    if (cJSON_IsObject(node)) return cJSON_GetObjectItemCaseSensitive(node, seg->key);
    if (cJSON_IsArray(node)) {
        char* endp;
        long i = strtol(seg->key, &endp, 10);
        if (isdigit((unsigned char)seg->key[0]) && !*endp)
            return i < cJSON_GetArraySize(node) ? cJSON_GetArrayItem(node, (int)i) : NULL;
        cJSON* e;
        cJSON_ArrayForEach(e, node) {
            cJSON* nm = cJSON_GetObjectItemCaseSensitive(e, "name");
            if (cJSON_IsString(nm) && !strcmp(nm->valuestring, seg->key)) return e;
        }
    }
    return NULL;
}

// Every number in a --set value must be a JSON number (see check_numbers).
static bool value_numbers_ok(const char* v) {
    char e[8];
    return check_numbers(v, "", e, sizeof e) == 0;
}

// Why segment seg names nothing below node (at: its path): an index past the
// end of an array says so with the length, an unknown name says "no field".
static void set_path_missing(const char* assignment, const cJSON* node, const char* at, const path_seg* seg,
                             char* err, size_t errsz) {
    const bool digits = seg->key[0] && strspn(seg->key, "0123456789") == strlen(seg->key);
    if (cJSON_IsArray(node) && digits) {
        const int n = cJSON_GetArraySize(node);
        snprintf(err, errsz, "%s '%s': index %s out of range: %s has %d element%s (0..%d)", sim_param_name(SIM_PARAM_SET), assignment, seg->key,
                 at, n, n == 1 ? "" : "s", n - 1);
    } else if (cJSON_IsArray(node)) {
        snprintf(err, errsz, "%s '%s': no element named '%s' in %s", sim_param_name(SIM_PARAM_SET), assignment, seg->key, at);
    } else if (seg->index) {
        snprintf(err, errsz, "%s '%s': %s is not an array (index [%s])", sim_param_name(SIM_PARAM_SET), assignment, at, seg->key);
    } else {
        snprintf(err, errsz, "%s '%s': no field '%s' in the model%s%s", sim_param_name(SIM_PARAM_SET), assignment, seg->key, at[0] ? " under " : "",
                 at);
    }
}

// Whether key is a numeric field of the circuit element obj (an object with
// a "type" the circuit knows, or the fluid: prev is the segment above obj):
// a --set may then add it although the file leaves it at its default (the
// loader range-checks it as any value in the file).
static bool schema_field(const cJSON* obj, const char* prev, const char* key) {
    if (!cJSON_IsObject(obj)) return false;
    if (prev && !strcmp(prev, "fluid")) {
        for (int k = 0; k < hyd_fluid_param_count(); ++k)
            if (!strcmp(hyd_fluid_param_name(k), key)) return true;
        return false;
    }
    const cJSON* ty = cJSON_GetObjectItemCaseSensitive(obj, "type");
    const int t = cJSON_IsString(ty) ? hyd_type_parse(ty->valuestring) : -1;
    if (t < 0) return false;
    for (int k = 0; k < hyd_param_count((hyd_type)t); ++k)
        if (!strcmp(hyd_param_name((hyd_type)t, k), key)) return true;
    return false;
}

int json_set_path(cJSON* root, const char* assignment, char* err, size_t errsz) {
    // Messages quote the whole argument: it is what the user typed.
    const char* eq = strchr(assignment, '=');
    if (!eq || eq == assignment) {
        snprintf(err, errsz, "%s '%s': expected PATH=VALUE", sim_param_name(SIM_PARAM_SET), assignment);
        return -1;
    }
    char path[256];
    size_t plen = (size_t)(eq - assignment);
    if (plen >= sizeof path) {
        snprintf(err, errsz, "%s '%.40s...': path too long", sim_param_name(SIM_PARAM_SET), assignment);
        return -1;
    }
    memcpy(path, assignment, plen);
    path[plen] = 0;
    const char* value = eq + 1;

    path_seg segs[32];
    char why[96];
    const int nseg = parse_set_path(path, segs, 32, why, sizeof why);
    if (nseg < 0) {
        snprintf(err, errsz, "%s '%s': malformed path '%s': %s", sim_param_name(SIM_PARAM_SET), assignment, path, why);
        return -1;
    }
    cJSON* parent = root;
    cJSON* old = NULL;
    char at[256] = ""; // the path walked so far, for messages
    for (int i = 0; i < nseg; ++i) {
        cJSON* next = child_by_segment(parent, &segs[i]);
        if (!next && i == nseg - 1 && !segs[i].index && schema_field(parent, i ? segs[i - 1].key : NULL, segs[i].key)) {
            // A field of the element's type absent from the file: added as a
            // number (its type in the schema), then range-checked on load.
            const char* vend = NULL;
            cJSON* nv = value_numbers_ok(value) ? cJSON_ParseWithOpts(value, &vend, 1) : NULL;
            if (!cJSON_IsNumber(nv)) {
                snprintf(err, errsz, "%s '%s': %s must be a number, got '%s'", sim_param_name(SIM_PARAM_SET), assignment,
                         path, value);
                cJSON_Delete(nv);
                return -1;
            }
            cJSON_AddItemToObject(parent, segs[i].key, nv);
            return 0;
        }
        if (!next) {
            set_path_missing(assignment, parent, at, &segs[i], err, errsz);
            return -1;
        }
        const size_t L = strlen(at);
        snprintf(at + L, sizeof at - L, segs[i].index ? "[%s]" : (L ? ".%s" : "%s"), segs[i].key);
        if (i < nseg - 1) parent = next;
        else old = next;
    }
    const path_seg* last = &segs[nseg - 1];
    // The whole value must be one JSON value: "5 xyz", "5,6" or "5}" are
    // typos, not 5 (cJSON alone stops at the end of the first value).
    const char* vend = NULL;
    cJSON* nv = value_numbers_ok(value) ? cJSON_ParseWithOpts(value, &vend, 1) : NULL;
    if (!nv) {
        // A bare word (no quotes) is taken as a string: --set solver=ros2.
        bool word = *value != 0;
        for (const char* q = value; *q; ++q) word = word && (isalnum((unsigned char)*q) || strchr("_-./:", *q));
        if (!word) {
            snprintf(err, errsz, "%s '%s': cannot parse the value '%s' (a number, true/false, \"text\", "
                                 "[array] or a bare word)",
                     sim_param_name(SIM_PARAM_SET), assignment, value);
            return -1;
        }
        nv = cJSON_CreateString(value);
    }
    // Keep the member's type: a number stays a number, so a mistyped value is
    // caught here and not deep inside the loader.
    if ((cJSON_IsNumber(old) && !cJSON_IsNumber(nv)) || (cJSON_IsBool(old) && !cJSON_IsBool(nv)) ||
        (cJSON_IsString(old) && !cJSON_IsString(nv)) || (cJSON_IsObject(old) && !cJSON_IsObject(nv)) ||
        (cJSON_IsArray(old) && !cJSON_IsArray(nv))) {
        snprintf(err, errsz, "%s '%s': %s must be %s, got '%s'", sim_param_name(SIM_PARAM_SET), assignment, path, type_name(old), value);
        cJSON_Delete(nv);
        return -1;
    }
    if (cJSON_IsArray(parent)) cJSON_ReplaceItemViaPointer(parent, old, nv);
    else cJSON_ReplaceItemInObjectCaseSensitive(parent, last->key, nv);
    return 0;
}

static int cmp_name(const void* a, const void* b) { return strcmp(*(char* const*)a, *(char* const*)b); }

void json_list_files(const char* folder, char* out, size_t n) {
    char* names[64];
    int k = 0;
    DIR* d = opendir(folder);
    for (struct dirent* e; d && k < 64 && (e = readdir(d));) {
        const size_t L = strlen(e->d_name);
        if (L > 5 && !strcmp(e->d_name + L - 5, ".json") && (names[k] = malloc(L - 4))) {
            snprintf(names[k], L - 4, "%s", e->d_name);
            ++k;
        }
    }
    if (d) closedir(d);
    qsort(names, (size_t)k, sizeof *names, cmp_name);
    snprintf(out, n, "%s", k ? "" : "none");
    for (int i = 0; i < k; ++i) {
        const size_t L = strlen(out);
        snprintf(out + L, n - L, "%s%s", i ? ", " : "", names[i]);
        free(names[i]);
    }
}
