// fixture_edit.h: bad input files made at test time from a shipped file with
// one change, instead of stored copies that drift from the file they copy.
#ifndef CRANESIM_FIXTURE_EDIT_H
#define CRANESIM_FIXTURE_EDIT_H

#include "json_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/// The whole file, NUL-terminated and malloc'd, or NULL.
static inline char* fixture_read_all(const char* path) {
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char* s = n >= 0 ? malloc((size_t)n + 1) : NULL;
    size_t got = s ? fread(s, 1, (size_t)n, f) : 0;
    if (s) s[got] = 0;
    fclose(f);
    return s;
}

// Remove the member at a dotted path of objects ("mechanics.links"); 0 or -1.
static inline int fixture_remove(cJSON* root, const char* path) {
    char buf[256];
    snprintf(buf, sizeof buf, "%s", path);
    cJSON* o = root;
    char* key = buf;
    for (char* dot; (dot = strchr(key, '.')); key = dot + 1) {
        *dot = 0;
        o = cJSON_GetObjectItemCaseSensitive(o, key);
        if (!cJSON_IsObject(o)) return -1;
    }
    if (!cJSON_GetObjectItemCaseSensitive(o, key)) return -1;
    cJSON_DeleteItemFromObjectCaseSensitive(o, key);
    return 0;
}

/// Write base (a file) to path with one change: the assignment set
/// ("a.b[1].c=value", as --set takes it; "-a.b" removes member a.b) when
/// set is not NULL, else the
/// first occurrence of the text from replaced by to (for what a JSON
/// assignment cannot express: a syntax error, a duplicate key, a renamed or
/// removed member). 0, or -1 after printing why (the change did not apply).
static inline int fixture_edit(const char* base, const char* path, const char* set, const char* from,
                               const char* to) {
    char* text = fixture_read_all(base);
    if (!text) {
        fprintf(stderr, "fixture: cannot read %s\n", base);
        return -1;
    }
    char* s = NULL;
    if (set) {
        char err[512] = "";
        cJSON* root = cJSON_Parse(text);
        const int bad = !root || (set[0] == '-' ? fixture_remove(root, set + 1)
                                                : json_set_path(root, set, err, sizeof err));
        if (bad) {
            fprintf(stderr, "fixture %s: cannot apply %s: %s\n", path, set, err);
            cJSON_Delete(root);
            free(text);
            return -1;
        }
        s = cJSON_Print(root);
        cJSON_Delete(root);
    } else {
        char* at = strstr(text, from);
        if (!at) {
            fprintf(stderr, "fixture %s: '%s' is not in %s\n", path, from, base);
            free(text);
            return -1;
        }
        const size_t n = strlen(text) + strlen(to) + 1;
        s = malloc(n);
        snprintf(s, n, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
    }
    free(text);
    FILE* f = fopen(path, "wb");
    const int ok = f && fputs(s, f) >= 0;
    if (f && fclose(f)) {
        free(s);
        return -1;
    }
    free(s);
    return ok ? 0 : -1;
}

#endif
