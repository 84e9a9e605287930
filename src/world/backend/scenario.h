// scenario.h: scripted runs. Valve commands as piecewise-linear (t, u)
// tables, hook events, initial joint angles and the load.
#ifndef SCENARIO_H
#define SCENARIO_H

#include <stdbool.h>
#include <cjson/cJSON.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SCENARIO_MAX_POINTS 64
#define SCENARIO_MAX_EVENTS 32
#define SCENARIO_NCMD 3 ///< lift, jib, slew
/// Command columns in all: lift, jib, slew, then up to 13 more named after
/// any function of the model's chain (crane_chain.h: "ext", "jib_ext").
#define SCENARIO_MAX_CMD 16
#define SCENARIO_CMD_NAME 48

/// A piecewise-linear signal u(t), held constant before the first and after
/// the last point. A step is two points with the same t.
typedef struct scenario_signal {
    int n;
    double t[SCENARIO_MAX_POINTS]; ///< [s], non-decreasing
    double u[SCENARIO_MAX_POINTS]; ///< valve opening command, -1..1
} scenario_signal;

typedef enum scenario_event_kind { SCENARIO_ATTACH = 1, SCENARIO_RELEASE = 2 } scenario_event_kind;

typedef struct scenario_event {
    double t;                  ///< [s]
    scenario_event_kind kind;
} scenario_event;

#define SCENARIO_MAX_FAULTS 8

/// Fault events (docs/files.md, "faults"): a hose burst opens an orifice to
/// the tank at a circuit node; a pump stop ramps the pump's flow to zero.
typedef enum scenario_fault_kind { SCENARIO_HOSE_BURST = 1, SCENARIO_PUMP_STOP = 2 } scenario_fault_kind;

typedef struct scenario_fault {
    double t;                  ///< [s] when it starts
    scenario_fault_kind kind;
    char at[64];               ///< hose burst: the node (a hose or "<cylinder>.A"/".B")
    double area;               ///< hose burst: opening area of the break [m^2]
    double cd;                 ///< hose burst: discharge coefficient [-]
    double ramp;               ///< pump stop: time for the flow to fall to zero [s]
} scenario_fault;

typedef struct scenario {
    char name[64];
    char description[256];
    char model[256];           ///< model file it was written for ("" = default)
    double duration;           ///< [s]
    double load_mass;          ///< [kg]; < 0 means "use the model's"
    double q0[2];              ///< initial joint angles, paper convention [rad]
    double slew0;              ///< initial slew angle [rad]
    scenario_signal cmd[SCENARIO_MAX_CMD]; ///< lift, jib, slew, then the named columns
    /// Columns in cmd: 0 or 3 (lift, jib, slew only), or 3 + the named ones.
    int ncmd;
    /// Names of columns 3 .. ncmd - 1 (0 .. 2 are scenario_cmd_name's).
    char cmd_name[SCENARIO_MAX_CMD][SCENARIO_CMD_NAME];
    int nevent;
    scenario_event event[SCENARIO_MAX_EVENTS];
    int nfault;
    scenario_fault fault[SCENARIO_MAX_FAULTS];
    char file[128];            ///< file name it was loaded from, for messages
} scenario;

/// Names of the command channels: "lift", "jib", "slew".
extern const char* const scenario_cmd_name[SCENARIO_NCMD];

/// The column commanding the function named name: lift, jib, slew are 0, 1,
/// 2 (every scenario has them, empty tables hold 0), the others as the file
/// names them; -1 when the scenario has no such column.
int scenario_find_command(const scenario* s, const char* name);
/// True when the scenario commands function name: it has that column and a
/// command in it is not 0.
bool scenario_commands(const scenario* s, const char* name);
/// Columns in s->cmd (at least SCENARIO_NCMD).
int scenario_ncmd(const scenario* s);

/// Load from a file. Returns 0, or -1 with "file: field: problem" in err.
int scenario_load(const char* path, scenario* s, char* err, size_t errsz);
/// Load from a parsed document; file is used in messages.
int scenario_from_json(const cJSON* root, const char* file, scenario* s, char* err, size_t errsz);

/// Command of channel k at time t [s] (piecewise-linear, clamped to [-1, 1]).
double scenario_command(const scenario* s, int k, double t);
/// scenario_command with a cached segment index *seg (start it at 0, keep one
/// per caller and channel): the same value for any t, in any order, but a
/// run that moves forward in time skips the scan from the first point.
double scenario_command_seg(const scenario* s, int k, double t, int* seg);
static inline double scenario_command_hint(const scenario* s, int k, double t, int* seg) {
    // Fast path: t strictly inside the cached segment [t_i, t_i+1), which is
    // then the segment scenario_command would find (the last with t_i <= t),
    // and the same interpolation formula gives the same bits.
    const scenario_signal* g = &s->cmd[k];
    const int i = *seg;
    if (i + 1 < g->n && g->t[i] <= t && t < g->t[i + 1] && t > g->t[0]) {
        const double w = (t - g->t[i]) / (g->t[i + 1] - g->t[i]);
        return g->u[i] + w * (g->u[i + 1] - g->u[i]);
    }
    return scenario_command_seg(s, k, t, seg);
}

/// Slope du/dt [1/s] of channel k at time t (0 outside the table and on
/// flat segments; at a breakpoint, the slope of the segment that starts there).
double scenario_command_rate(const scenario* s, int k, double t);

/// Times [s] at which any command has a kink or step (for solver resets), in
/// increasing order without duplicates. Returns the count (<= cap).
int scenario_breakpoints(const scenario* s, double* t, int cap);

/// Hook events go to hook(user, attach: 1 attach, 0 release); it returns
/// the load attached or -1.
typedef int (*scenario_hook_fn)(void* user, int attach);
/// The scripted operator, the one player of a scenario step by step (run
/// on the ode world at each ODE step, drive at each frame): the commands at
/// time tm [s] into u[3], and every event due by tm (t <= tm), from *ev on,
/// to hook (may be NULL); *ev advances past them.
void scenario_play(const scenario* s, double tm, int* ev, double u[SCENARIO_NCMD], scenario_hook_fn hook,
                   void* user);

#ifdef __cplusplus
}
#endif
#endif
