// session.h: a drive's session file, what `cranesim replay` and
// `cranesim drive --replay` run again (format in docs/replay.md).
//
// A text file: a magic line with the format version, one JSON header line
// (the model document and its hash, the scenario document when its faults
// were applied, the run settings, the initial state, the engine and the
// functions the commands are for), then one line per command tick ("k" hook
// events, "t" tick with one command per function, "r" the row recorded after
// it, as the record's CSV line), and "e" with why it ended. Written as the
// drive goes, so a drive cut short leaves the ticks up to there.
//
// Version 2 names the functions (any crane chain); version 1 (the two-link
// crane's, always lift, jib, slew) is still read, and replays as it did.
#ifndef SESSION_H
#define SESSION_H

#include <stdbool.h>
#include <stdio.h>

#include "model.h"
#include "scenario.h"
#include "sim.h"

#define SESSION_VERSION 2
/// The oldest version read: 1, three commands (lift, jib, slew) per tick.
#define SESSION_VERSION_MIN 1
#define SESSION_MAGIC "cranesim-session"
/// The most columns a version 2 row may have (a chain model's rows are
/// sized by it; this bounds only a corrupt header).
#define SESSION_MAX_NCOL 100000

struct engine;

/// One command tick: the hook events applied first (attach 1 / release 0),
/// then the commands, then an advance to target (when target > the engine's
/// time), then (row) one row recorded.
typedef struct session_tick {
    double tm;         ///< the time the operator's input was sampled at (faults apply at it) [s]
    double target;     ///< the engine time advanced to [s]
    const double* u;   ///< session.nfn commands [-1, 1], in session.fn's order (in session.uv)
    int nhook;
    signed char hook[4]; ///< hook events of the tick, in order
    bool row;          ///< a row was recorded after the tick
    long row_line;     ///< index of its text in session.rows (-1: none)
} session_tick;

typedef struct session {
    char path[512];
    int version;         ///< the file's format version (SESSION_VERSION_MIN .. SESSION_VERSION)
    int nfn;             ///< the functions each tick commands
    const char** fn;     ///< their names (version 1: lift, jib, slew)
    double* uv;          ///< every tick's commands, nfn per tick
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
    int nfn;             ///< commands per tick (the engine's functions)
    double* u;           ///< nfn commands read back from the engine (session_writer_tick_engine)
} session_writer;
/// Open path and write the header. scenario_path: the scenario whose faults
/// the drive applies (NULL: none). Returns 0, or -1 with one line in err.
/// model_doc: the model document before any fault components (the replay adds them).
/// l: the engine driven (its backend and its functions, whose commands every
/// tick carries, in engine_function_name order).
int session_writer_open(session_writer* w, const char* path, const cJSON* model_doc, const char* model_file,
                        const struct engine* l, const sim_opts* o,
                        const char* scenario_path, const double q0[2], double slew0, double m3, bool window, int ncol,
                        char* err, size_t errsz);
/// A hook event of the tick to come.
void session_writer_hook(session_writer* w, int attach);
/// A tick: u, the nu commands by function (nu the engine's functions, as
/// opened; another count fails the writer with EINVAL); row (ncol values,
/// may be NULL) is the row recorded after it, as the record writes it (the
/// window's with its `segment` value last).
void session_writer_tick(session_writer* w, double tm, double target, const double* u, int nu, const double* row,
                         int ncol);
/// A tick whose commands are those engine l (the one opened with) holds now,
/// as the operator gave them (engine_function_command): what a driver that
/// sets them by whatever path (the window's sticks, a chain's functions)
/// records after setting them.
void session_writer_tick_engine(session_writer* w, const struct engine* l, double tm, double target,
                                const double* row, int ncol);
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
/// The recorded CSV header (window sessions add `segment`): engine l's
/// channels, as the drive wrote them.
void session_csv_header(const session* s, const struct engine* l, FILE* f);

/// The session's command of each of engine l's functions, by name: map[k]
/// (k < engine_nfunction(l)) is the session's function index, or -1 for a
/// function the session does not command (held at 0). A version 1 session
/// on a two-link engine maps lift, jib, slew in order. A function of the
/// session that l lacks is left out only when every recorded command of it
/// is 0 (it carried no operator input: a two-link session's slew outside
/// the sandbox); its name then goes into dropped (may be NULL), ", "
/// separated. Returns the number of the engine's functions the session
/// commands, or -1 with one line in err when the session commands a
/// function l lacks: "session FILE: functions: 'x' is not a function of
/// this model (its functions: ...)".
int session_function_map(const session* s, const struct engine* l, int* map, char* dropped, size_t dsz, char* err,
                         size_t errsz);
/// Tick i's commands for the engine's n functions (map from
/// session_function_map) into u[n].
void session_tick_commands(const session* s, long i, const int* map, int n, double* u);

#endif
