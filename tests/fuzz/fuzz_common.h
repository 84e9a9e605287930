// fuzz_common.h: shared by the libFuzzer targets. The input bytes become a
// NUL-terminated text and go through the same checks as a file
// (json_parse: syntax, strict numbers, duplicates, \u0000), then to a loader.
// Notes (typical ranges) are silenced: they are not findings, and stderr
// would drown libFuzzer's report.
#ifndef CRANESIM_FUZZ_COMMON_H
#define CRANESIM_FUZZ_COMMON_H

#include "hydraulics.h"
#include "json_util.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static void fuzz_silent_note(const char* line, void* user) {
    (void)line;
    (void)user;
}

// The input as a parsed document, or NULL when the reader refuses it (a
// refusal is a correct answer, not a finding). Inputs over the file limit
// are skipped: json_load_file refuses them before parsing.
static inline cJSON* fuzz_parse(const uint8_t* data, size_t size) {
    hyd_set_note_handler(fuzz_silent_note, NULL);
    if (size > (size_t)JSON_MAX_FILE_BYTES) return NULL;
    char* text = malloc(size + 1);
    if (!text) return NULL;
    memcpy(text, data, size);
    text[size] = 0;
    char err[512];
    cJSON* root = json_parse(text, "fuzz.json", err, sizeof err);
    free(text);
    return root;
}

#endif
