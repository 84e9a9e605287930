// protocol.h: the wire format of `cranesim serve` (docs/protocol.md): the
// simulation computer and its clients (a viewer, an instructor, a hardware
// valve controller). Pure encoding and decoding of length-prefixed
// little-endian frames; no sockets, no allocation. The parser checks every
// length against the frame and every value against its range, so a server
// can hand it whatever a peer sent.
#ifndef PROTOCOL_H
#define PROTOCOL_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// "CSIM" as a little-endian u32: the first field of both hellos.
#define PROTO_MAGIC 0x4D495343u
/// 3: by function, for any crane chain: the hello's JSON lists the functions
/// (with the actuators each drives), the crane's bodies and the channels;
/// VALVES carries one opening per function in the hello's order; the state
/// frame ends with every function's command and spool. (2 added the tip,
/// the truck's roll and pitch, the supply pressure and the HUD's values.)
#define PROTO_VERSION 3u
/// Frame header: u32 length of what follows (type byte + payload), then the type.
#define PROTO_HEADER 5
/// The longest frame a client may send (a SET with its path is the longest) [bytes after the length].
#define PROTO_MAX_CLIENT_FRAME 1024u
/// The longest frame a server sends (a hello with its JSON description) [bytes after the length].
#define PROTO_MAX_SERVER_FRAME (1u << 20)
/// Row columns: 128 for the 8-function, 10-body chain in the sandbox
/// (tests/world/data/chain_8fn_10link.json), twice that for room.
#define PROTO_MAX_ROW 256
#define PROTO_MAX_BODIES 160
/// Cylinder records: every actuator of the chain and the slew rack.
#define PROTO_MAX_CYL 16
/// Functions the operator commands (VALVES openings, the state's function records).
#define PROTO_MAX_FN 16
#define PROTO_FN_VALUES 2 ///< f64 per function record: command, spool
#define PROTO_MAX_ROPE 32
#define PROTO_MAX_PATH 256
#define PROTO_MAX_PADS 4
#define PROTO_MAX_RELIEFS 8
#define PROTO_RELIEF_NAME 47 ///< longest relief name [bytes]
#define PROTO_CYL_VALUES 13  ///< f64 per cylinder record
#define PROTO_MAX_TEXT 512

enum proto_type {
    PROTO_CLIENT_HELLO = 1, ///< client -> server: magic, version, role asked
    PROTO_SERVER_HELLO = 2, ///< server -> client: magic, version, role granted, rates, JSON description
    PROTO_STATE = 3,        ///< server -> client: the state at one frame
    PROTO_COMMAND = 4,      ///< client -> server: one command with its sequence number
    PROTO_ERROR = 5,        ///< server -> client: why the server closes the connection
    PROTO_NOTICE = 6,       ///< server -> client: a command refused (the connection stays)
};

enum proto_role { PROTO_WATCH = 0, PROTO_CONTROL = 1 };

enum proto_op {
    PROTO_OP_VALVES = 1, ///< u8 n (1..PROTO_MAX_FN), n f64 openings in [-1, 1], one per function in the hello's order
    PROTO_OP_HOOK = 2,   ///< u8: 1 attach the nearest load, 0 release
    PROTO_OP_PAUSE = 3,  ///< u8: 1 pause, 0 run
    PROTO_OP_RESET = 4,  ///< start again from the initial state
    PROTO_OP_SET = 5,    ///< u16 path length, path, f64 value: a model parameter
    PROTO_OP_STEP = 6,   ///< u32 frames to advance (lockstep servers only), 1..100000
    PROTO_OP_COUNT
};

/// State flags (proto_state.flags).
enum {
    PROTO_F_PAUSED = 1u << 0,
    PROTO_F_ATTACHED = 1u << 1,
    PROTO_F_STOPPED = 1u << 2,  ///< the simulation failed a check and stays stopped
    PROTO_F_LOCKSTEP = 1u << 3, ///< the server advances only on STEP commands
    PROTO_F_TIPPING = 1u << 4,
    PROTO_F_RELIEF = 1u << 5,
    PROTO_F_COLLISION = 1u << 6, ///< a crane part touches an obstacle
    PROTO_F_RCL_HAVE = 1u << 7,  ///< the rated capacity limiter measures (rcl_util valid)
    PROTO_F_RCL_ON = 1u << 8,    ///< ... and stops the motions that increase the load moment
    PROTO_F_PAD_LIFTED0 = 1u << 9, ///< bits 9..12: support FL, FR, RL, RR lifted off
    PROTO_F_RCL_CUT0 = 1u << 13, ///< bits 13..15: the limiter cut the lift, jib, slew command (a client
                                 ///< that ignores them reads the frame as before)
};
/// Cylinder status bits (proto_state.cyl_bits).
/// PROTO_CYL_NO_PINS: the world's picture does not draw this cylinder, so
/// its pins are 0 and its relief and end-stop bits are not known (0); its
/// stroke, rate, pressures, force and openings are the row's.
enum { PROTO_CYL_RELIEF = 1u << 0, PROTO_CYL_END_STOP = 1u << 1, PROTO_CYL_NO_PINS = 1u << 2 };

/// An open relief valve: its circuit name and the chamber it guards.
typedef struct proto_relief {
    int8_t cyl;   ///< index into the frame's cylinders, -1: none (a pump-line relief)
    uint8_t port; ///< 0 chamber A, 1 chamber B
    char name[PROTO_RELIEF_NAME + 1];
} proto_relief;

typedef struct proto_client_hello {
    uint32_t version;
    uint8_t role; ///< proto_role asked for
} proto_client_hello;

typedef struct proto_server_hello {
    uint32_t version;
    uint8_t role;       ///< granted: PROTO_CONTROL only to the first client that asked
    uint8_t lockstep;   ///< 1: the server advances only on STEP
    double rate;        ///< state frames per simulated second [Hz]
    const char* json;   ///< the description (model, world, channels, bodies); not NUL-terminated when parsed
    uint32_t json_len;
} proto_server_hello;

typedef struct proto_command {
    uint64_t seq;
    uint8_t op;
    uint8_t nu;                  ///< VALVES: openings, one per function (the hello's "functions")
    double u[PROTO_MAX_FN];      ///< VALVES [-]
    uint8_t flag;                ///< HOOK, PAUSE
    uint32_t frames;             ///< STEP
    char path[PROTO_MAX_PATH + 1]; ///< SET, NUL-terminated
    double value;                ///< SET
} proto_command;

/// One state frame. nine: x1, x2 [m], p1A, p1B, p2A, p2B [Pa abs], u1, u2 [-], t [s]: the paper's packet
/// (for a crane chain: the first actuator of the first two functions, and their spools).
typedef struct proto_state {
    double nine[9];
    uint64_t seq;     ///< frame number since the server started (gaps: frames this client lost)
    uint64_t cmd_seq; ///< sequence number of the last command applied from the controlling client (0: none)
    uint32_t flags;
    double slew;      ///< [rad]
    double hook[3];   ///< [m], world frame
    double load_mass; ///< on the hook or at the tip [kg]
    int32_t attached; ///< load index on the hook, -1 none
    double tip[3];    ///< end-arm tip, world frame [m]
    double roll, pitch; ///< truck attitude [rad]: roll about its x axis (+ left side up), pitch about
                        ///< its y axis (+ nose down); body rotation Rz(yaw) Ry(pitch) Rx(roll); 0 without a truck
    double p_supply;  ///< supply (pump line) pressure, absolute [Pa]
    double rcl_util;  ///< rated capacity limiter: load moment over rated [-] (flag PROTO_F_RCL_HAVE)
    double stab_margin; ///< restoring over tipping moment [-] (with supports)
    uint8_t npad;     ///< truck supports, 0 or 4: FL, FR, RL, RR
    double pad_F[PROTO_MAX_PADS]; ///< their vertical ground reactions [N]
    uint16_t nrow;    ///< the row's columns (names in the hello's "channels")
    double row[PROTO_MAX_ROW];
    uint16_t nbody;   ///< body poses, in the hello's "bodies" order: pos[3] [m], rot[9] row-major
    double pose[PROTO_MAX_BODIES][12];
    uint8_t ncyl;     ///< cylinders: base[3], rod_end[3] [m], x [m], pA, pB [Pa], u, u_cmd [-], force [N], v [m/s]
    double cyl[PROTO_MAX_CYL][PROTO_CYL_VALUES];
    uint8_t cyl_bits[PROTO_MAX_CYL]; ///< PROTO_CYL_RELIEF, PROTO_CYL_END_STOP
    uint8_t nrope;    ///< rope polyline, tip to hook [m]
    double rope[PROTO_MAX_ROPE][3];
    uint8_t nrelief;  ///< relief valves passing flow
    proto_relief relief[PROTO_MAX_RELIEFS];
    uint8_t nfn;      ///< functions, in the hello's "functions" order: command (after the limiter) [-], spool [-]
    double fn[PROTO_MAX_FN][PROTO_FN_VALUES];
} proto_state;

/// The truck's roll and pitch [rad] from its body-to-world rotation
/// (row-major), for R = Rz(yaw) Ry(pitch) Rx(roll): pitch = -asin(R[2][0]),
/// roll = atan2(R[2][1], R[2][2]). The tilt from upright is then
/// acos(cos(roll) cos(pitch)).
void proto_roll_pitch(const double rot[9], double* roll, double* pitch);

typedef struct proto_text {
    uint64_t seq;   ///< NOTICE: the command refused; ERROR: 0
    uint16_t code;  ///< proto_err
    char text[PROTO_MAX_TEXT + 1];
} proto_text;

enum proto_err {
    PROTO_E_MALFORMED = 1, PROTO_E_VERSION = 2, PROTO_E_FULL = 3, PROTO_E_TIMEOUT = 4, PROTO_E_SLOW = 5,
    PROTO_E_READONLY = 6, PROTO_E_REFUSED = 7, PROTO_E_SHUTDOWN = 8
};

typedef struct proto_msg {
    uint8_t type;
    union {
        proto_client_hello chello;
        proto_server_hello shello;
        proto_command cmd;
        proto_state* state; ///< the caller's buffer (large), set before parsing; NULL: STATE frames refused
        proto_text text;
    } u;
} proto_msg;

/// Parse the first frame of buf[0..len). Returns 1 with *used bytes consumed
/// and *out filled, 0 when buf holds only part of a frame (read more), -1
/// with one line in err when the bytes cannot be a valid frame: a length of
/// 0 or above max_len, an unknown type or op, a payload shorter or longer
/// than its type says, a non-finite or out-of-range value, a path with a NUL
/// or an empty one. A header announcing more than max_len is refused at
/// once, before its bytes arrive. For STATE frames set out->u.state first.
int proto_parse(const uint8_t* buf, size_t len, uint32_t max_len, size_t* used, proto_msg* out, char* err,
                size_t errsz);

/// Encoders: write one whole frame (header included) into buf[0..cap).
/// Return its length, or 0 when it does not fit (or a field is out of range).
size_t proto_put_client_hello(uint8_t* buf, size_t cap, uint32_t version, uint8_t role);
size_t proto_put_server_hello(uint8_t* buf, size_t cap, const proto_server_hello* h);
size_t proto_put_command(uint8_t* buf, size_t cap, const proto_command* c);
size_t proto_put_state(uint8_t* buf, size_t cap, const proto_state* s);
/// ERROR or NOTICE (type), text truncated to PROTO_MAX_TEXT.
size_t proto_put_text(uint8_t* buf, size_t cap, uint8_t type, uint64_t seq, uint16_t code, const char* text);
/// The name of an op ("valves", ...), or "unknown".
const char* proto_op_name(int op);

#ifdef __cplusplus
}
#endif
#endif
