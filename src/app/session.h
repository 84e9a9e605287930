// session.h: a drive's session file, what `cranesim replay` and
// `cranesim drive --replay` run again (format in docs/replay.md).
//
// A text file: a magic line with the format version, one JSON header line
// (the model document and its hash, the scenario document when its faults
// were applied, the run settings, the initial state), then one line per
// command tick ("k" hook events, "t" tick, "r" the row recorded after it, as
// the record's CSV line), and "e" with why it ended. Written as the drive
// goes, so a drive cut short leaves the ticks up to there.
#ifndef SESSION_H
#define SESSION_H

#include <stdbool.h>
#include <stdio.h>

#include "model.h"
#include "scenario.h"
#include "sim.h"

#define SESSION_VERSION 1
#define SESSION_MAGIC "cranesim-session"

/// One command tick: the hook events applied first (attach 1 / release 0),
/// then the commands, then an advance to target (when target > the engine's
/// time), then (row) one row recorded.
typedef struct session_tick {
    double tm;         ///< the time the operator's input was sampled at (faults apply at it) [s]
    double target;     ///< the engine time advanced to [s]
    double u[3];       ///< valve commands lift, jib, slew [-1, 1]
    int nhook;
    signed char hook[4]; ///< hook events of the tick, in order
    bool row;          ///< a row was recorded after the tick
    long row_line;     ///< index of its text in session.rows (-1: none)
} session_tick;

typedef struct session {
    char path[512];
    cJSON* header;       ///< the parsed header (owned)
    const cJSON* model;  ///< its model document (in header)
    const cJSON* scenario; ///< its scenario document, or NULL (faults not replayed)
    sim_opts sim;        ///< the recorded settings; sim.rcl the limiter's
    bool rcl_recorded;   ///< the header has the limiter's setting ("sim": {"rcl": ...}); a session
                         ///< written before it was recorded has not, and sim.rcl is then true
                         ///< (drive's default)
    char world[256];     ///< ode world name or file ("" none)
    double q0[2], slew0, m3;
    bool window;         ///< recorded by the window: the record has a `segment` column
    int ncol;
    session_tick* tick;
    long ntick;
    char** rows;         ///< the recorded rows' CSV text (no newline)
    long nrow;
    char end[160];       ///< why the recording ended
} session;

/// 64-bit FNV-1a of the model document's compact JSON text, as 16 hex digits.
void session_model_hash(const cJSON* model_doc, char out[17]);

/// Writing a session as a drive goes.
typedef struct session_writer {
    FILE* f;
    char path[512];
    int err;             ///< errno of the first failed write (0: none)
    int nhook;
    signed char hook[4];
    double t_last;       ///< the last recorded row's time (window: one row per instant)
    long rows;
} session_writer;
/// Open path and write the header. scenario_path: the scenario whose faults
/// the drive applies (NULL: none). Returns 0, or -1 with one line in err.
/// model_doc: the model document before any fault components (the replay adds them).
int session_writer_open(session_writer* w, const char* path, const cJSON* model_doc, const char* model_file,
                        const sim_opts* o,
                        const char* scenario_path, const double q0[2], double slew0, double m3, bool window, int ncol,
                        char* err, size_t errsz);
/// A hook event of the tick to come.
void session_writer_hook(session_writer* w, int attach);
/// A tick; row (ncol values, may be NULL) is the row recorded after it, as
/// the record writes it (the window's with its `segment` value last).
void session_writer_tick(session_writer* w, double tm, double target, const double u[3], const double* row,
                         int ncol);
/// End the file with why; close it. Returns 0, or the errno of the first failure.
int session_writer_close(session_writer* w, const char* why);

/// Load a session. Returns 0, or -1 with one line "session FILE: problem" in
/// err (unreadable, not a session, another format version, a model that does
/// not match its hash, a malformed line).
int session_load(const char* path, session* s, char* err, size_t errsz);
void session_free(session* s);

/// The model to replay on: the recorded document, or the file model_path,
/// with the sets applied. NULL with one line in err.
model* session_model(const session* s, const char* model_path, const char* const* sets, int nset, char* err,
                     size_t errsz);
/// The recorded CSV header (window sessions add `segment`).
void session_csv_header(const session* s, FILE* f);

#endif
