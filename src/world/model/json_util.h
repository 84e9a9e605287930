// json_util.h: strict, path-aware reading of JSON model, scenario and world files.
//
// Every getter names the file and the full field path in its one-line error,
// e.g. "hiab031.json: mechanics.links[1].mass: must be > 0, got -3". The first
// error wins; later calls become no-ops so a loader can read everything and
// check once at the end.
#ifndef JSON_UTIL_H
#define JSON_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <cjson/cJSON.h>

#ifdef __cplusplus
extern "C" {
#endif

#define JSON_MAX_NOTES 8

typedef struct json_ctx {
    const char* file; ///< file name used in messages
    char* err;        ///< caller's buffer for the first error
    size_t errsz;
    bool failed;
    int nnotes; ///< queued notes (json_note), sent by json_flush_notes
    char notes[JSON_MAX_NOTES][400]; // a note that says what will happen takes up to ~300 characters
} json_ctx;

/// Record an error "file: path: message" (printf-style message). First one wins.
void json_fail(json_ctx* c, const char* path, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

/// Largest input file accepted [bytes]: 1 MiB, over 100 times the largest
/// shipped file (sandbox.json, 7.7 kB). Checked before reading.
#define JSON_MAX_FILE_BYTES (1L << 20)

/// Read and parse a whole file. A file over JSON_MAX_FILE_BYTES is refused
/// before it is read: "file: too large (N bytes; ...)". NULL with "file: line L, column C: message" on
/// a syntax error, also for a number JSON does not allow (00.1, 1.), and
/// "file: field.path: given twice (duplicate field)" for a repeated member.
cJSON* json_load_file(const char* path, char* err, size_t errsz);

/// The names of the .json files in folder, without the extension, sorted
/// and comma-separated into out ("none" when there is none or the folder
/// cannot be read; at most 64 names, cut at n bytes): what a message says
/// when a model or world named on the command line does not exist.
void json_list_files(const char* folder, char* out, size_t n);

/// The checks of json_load_file on a text in memory (name is used in messages).
cJSON* json_parse(const char* text, const char* name, char* err, size_t errsz);

/// What kind of cranesim file a document looks like, from the members only
/// that kind has: "model" (mechanics, hydraulics), "world" (type),
/// "scenario" (duration, commands), or NULL.
const char* json_file_kind(const cJSON* root);
/// If root looks like another kind of file than want ("model", "scenario",
/// "world"), fail with "file: this is a scenario file (use --scenario), not a
/// model" and return true: better than "duration: unknown field".
bool json_wrong_kind(json_ctx* c, const cJSON* root, const char* want);

/// Join a parent path and a key ("a.b" + "c" -> "a.b.c"; "" + "c" -> "c").
void json_path(char* out, size_t n, const char* parent, const char* key);
/// Parent path plus an index ("a.b" + 3 -> "a.b[3]").
void json_path_index(char* out, size_t n, const char* parent, int index);

/// Object member that must be an object (required) or NULL if absent and optional.
const cJSON* json_obj(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required);
/// Member that must be an array.
const cJSON* json_arr(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required);

/// Number with range check: value must satisfy lo <= v <= hi (use -INFINITY /
/// INFINITY for open ends); if positive is true it must also be > 0.
/// Absent and not required: returns def.
double json_num(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                double def, double lo, double hi);
/// Physically meaningful range of a value. Outside [lo, hi] (hard) the file
/// is refused: "must be in [1, 1e5] kg, got 1e-300" ("must be > 0, got -3"
/// for a non-positive value when lo > 0). Outside [tlo, thi] (typical) the
/// load goes on with a note: "note: file: path: 6000 kg is outside the
/// typical range [20, 5000] kg". unit is printed after the range ("" for none).
typedef struct json_range {
    double lo, hi;
    double tlo, thi;
    const char* unit;
} json_range;

/// Number checked against a json_range (notes are queued in the context and
/// sent by json_flush_notes).
double json_num_r(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                  double def, const json_range* r);
/// Fixed-length number array, every element checked against r.
void json_vec_r(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                double* out, int n, const json_range* r);
/// Check a value already read (full: its whole path) against r.
void json_range_check(json_ctx* c, const char* full, double v, const json_range* r);
/// Queue a note "file: path: message" (at most JSON_MAX_NOTES per load).
void json_note(json_ctx* c, const char* path, const char* fmt, ...) __attribute__((format(printf, 3, 4)));
/// Send the queued notes (hyd_note: stderr by default) if the load succeeded;
/// a refused file gets its error line only.
void json_flush_notes(json_ctx* c);

/// Number that must be > 0.
double json_pos(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
                double def);
/// Integer in [lo, hi].
int json_int(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required, int def,
             int lo, int hi);
bool json_bool(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool def);
/// String copied into out (truncated to n-1); absent and optional: def.
void json_str(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
              const char* def, char* out, size_t n);
/// Fixed-length number array [v0, v1, ...].
void json_vec(json_ctx* c, const cJSON* obj, const char* path, const char* key, bool required,
              double* out, int n);

/// Reject members not named in allowed (a NULL-terminated list): catches typos.
void json_only_keys(json_ctx* c, const cJSON* obj, const char* path, const char* const* allowed);

/// Apply "path=value" to a parsed document: path is dot-separated with [i]
/// indices, and an array element can also be picked by its "name" member
/// ("hydraulics.components.lift_cyl.bore"); an empty name ("a..b"), an
/// unclosed or non-numeric index is an error. value must be exactly one JSON
/// value (number, true/false, "string", [array]; nothing after it); a bare
/// word becomes a string. The member must already exist (a typo must not be
/// silently added) and keep its type. Returns 0 or -1 with a message in err
/// that quotes the whole assignment ("--set 'a.b=1': ...").
int json_set_path(cJSON* root, const char* assignment, char* err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
