// test_protocol.c: the serve protocol's frames (docs/protocol.md): every
// frame type encoded and parsed back bit for bit, the byte layout of the
// header and the nine values checked by hand against the document, and the
// parser's refusals (each malformed frame refused with a reason, none read
// past its input).
#include "check.h"
#include "protocol.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static proto_state s_in, s_out;

static int parse(const uint8_t* b, size_t n, uint32_t max, proto_msg* m, char* err) {
    size_t used = 0;
    memset(m, 0, sizeof *m);
    m->u.state = &s_out;
    int rc = proto_parse(b, n, max, &used, m, err, 256);
    if (rc == 1) CHECK(used == n, "used %zu of %zu", used, n);
    return rc;
}

// A command frame written by hand: header, seq, op, then raw payload.
static size_t raw_cmd(uint8_t* b, uint64_t seq, uint8_t op, const void* pay, size_t np) {
    const uint32_t len = (uint32_t)(1 + 8 + 1 + np);
    for (int i = 0; i < 4; ++i) b[i] = (uint8_t)(len >> (8 * i));
    b[4] = PROTO_COMMAND;
    for (int i = 0; i < 8; ++i) b[5 + i] = (uint8_t)(seq >> (8 * i));
    b[13] = op;
    if (np) memcpy(b + 14, pay, np);
    return 14 + np;
}

int main(void) {
    uint8_t buf[1 << 16];
    char err[256];
    proto_msg m;

    // Client hello: 4 length + 1 type + 4 magic + 2 version + 1 role = 12 bytes.
    size_t n = proto_put_client_hello(buf, sizeof buf, PROTO_VERSION, PROTO_CONTROL);
    CHECK(n == 12, "hello is %zu bytes", n);
    CHECK(buf[0] == 8 && buf[1] == 0 && buf[4] == 1 && buf[5] == 'C' && buf[6] == 'S' && buf[7] == 'I' &&
              buf[8] == 'M' && buf[9] == 3 && buf[10] == 0 && buf[11] == 1,
          "hello bytes");
    CHECK(parse(buf, n, PROTO_MAX_CLIENT_FRAME, &m, err) == 1 && m.type == PROTO_CLIENT_HELLO &&
              m.u.chello.version == 3 && m.u.chello.role == 1,
          "hello parsed: %s", err);
    // Every partial prefix asks for more.
    for (size_t k = 0; k < n; ++k) CHECK(parse(buf, k, PROTO_MAX_CLIENT_FRAME, &m, err) == 0, "prefix %zu", k);

    // Server hello with its JSON.
    const char* js = "{\"model\":\"x\"}";
    proto_server_hello h = {.version = 1, .role = 0, .lockstep = 1, .rate = 75, .json = js, .json_len = 13};
    n = proto_put_server_hello(buf, sizeof buf, &h);
    CHECK(parse(buf, n, PROTO_MAX_SERVER_FRAME, &m, err) == 1 && m.type == PROTO_SERVER_HELLO &&
              m.u.shello.rate == 75 && m.u.shello.lockstep == 1 && m.u.shello.json_len == 13 &&
              !memcmp(m.u.shello.json, js, 13),
          "server hello: %s", err);

    // State: bit for bit, including a NaN payload and -0.
    memset(&s_in, 0, sizeof s_in);
    for (int k = 0; k < 9; ++k) s_in.nine[k] = 0.1 * (k + 1) + 1e-17 * k;
    s_in.nine[8] = -0.0;
    s_in.seq = 0x0102030405060708ull;
    s_in.cmd_seq = 42;
    s_in.flags = PROTO_F_ATTACHED | PROTO_F_LOCKSTEP;
    s_in.slew = 1.25;
    s_in.attached = -1;
    s_in.nrow = 30;
    for (int k = 0; k < 30; ++k) s_in.row[k] = k * 3.3;
    s_in.row[5] = NAN;
    s_in.nbody = 17;
    for (int i = 0; i < 17; ++i)
        for (int k = 0; k < 12; ++k) s_in.pose[i][k] = i - k * 0.5;
    s_in.ncyl = 3;
    s_in.cyl[2][11] = 1e5;
    s_in.cyl[1][12] = -0.25;
    s_in.cyl_bits[1] = PROTO_CYL_END_STOP;
    s_in.nrope = 2;
    s_in.rope[1][2] = -4;
    s_in.tip[0] = 3.5, s_in.tip[1] = -1.25, s_in.tip[2] = 4.75;
    s_in.roll = 0.03, s_in.pitch = -0.02;
    s_in.p_supply = 17.5e6;
    s_in.rcl_util = 0.93;
    s_in.stab_margin = 1.7;
    s_in.npad = 4;
    for (int i = 0; i < 4; ++i) s_in.pad_F[i] = 1e4 * (i + 1);
    s_in.nrelief = 2;
    s_in.relief[0] = (proto_relief){.cyl = 1, .port = 1, .name = "jib_relief_B"};
    s_in.relief[1] = (proto_relief){.cyl = -1, .port = 0, .name = "main_relief"};
    s_in.nfn = 3;
    for (int k = 0; k < 3; ++k) s_in.fn[k][0] = 0.25 * k, s_in.fn[k][1] = -0.125 * k;
    n = proto_put_state(buf, sizeof buf, &s_in);
    // 5 header + 9*8 + 8 + 8 + 4 + 8 + 24 + 8 + 4, then (version 2) tip 24 + roll, pitch 16 + p_supply 8 +
    // rcl 8 + margin 8 + 1 + 4*8 pads, then 2 + 30*8 + 2 + 17*96 + 1 + 3*(13*8 + 1) + 1 + 2*24, then
    // 1 + (3 + 12) + (3 + 11) reliefs, then (version 3) 1 + 3*16 functions.
    const size_t head = 5 + 72 + 8 + 8 + 4 + 8 + 24 + 8 + 4, fnb = 1 + 3 * 16;
    CHECK(n == head + 24 + 16 + 8 + 8 + 8 + 1 + 32 + 2 + 240 + 2 + 17 * 96 + 1 + 3 * 105 + 1 + 48 + 1 + 15 + 14 + fnb,
          "state %zu", n);
    double fn2;
    memcpy(&fn2, buf + n - 16, 8); // the last function's command, 8 bytes before its spool at the end
    CHECK(fn2 == 0.5 && buf[n - fnb] == 3, "the function records end the frame: count %u, command %g",
          buf[n - fnb], fn2);
    double x1, tip_x, p_s;
    memcpy(&x1, buf + 5, 8); // the first value after the header is x1 (a little-endian host)
    CHECK(x1 == s_in.nine[0], "x1 first: %g", x1);
    memcpy(&tip_x, buf + head, 8); // the tip right after `attached`, as docs/protocol.md lays it out
    memcpy(&p_s, buf + head + 40, 8);
    CHECK(tip_x == 3.5 && p_s == 17.5e6, "tip x %g and p_supply %g where the document puts them", tip_x, p_s);
    CHECK(parse(buf, n, PROTO_MAX_SERVER_FRAME, &m, err) == 1 && m.type == PROTO_STATE, "state: %s", err);
    CHECK(!memcmp(s_out.nine, s_in.nine, sizeof s_in.nine) && s_out.seq == s_in.seq && s_out.cmd_seq == 42 &&
              s_out.flags == s_in.flags && s_out.attached == -1 && s_out.nrow == 30 &&
              !memcmp(s_out.row, s_in.row, 30 * 8) && s_out.nbody == 17 &&
              !memcmp(s_out.pose, s_in.pose, 17 * 96) && s_out.ncyl == 3 && s_out.cyl[2][11] == 1e5 &&
              s_out.nrope == 2 && s_out.rope[1][2] == -4 && signbit(s_out.nine[8]),
          "state round trip");
    CHECK(!memcmp(s_out.tip, s_in.tip, sizeof s_in.tip) && s_out.roll == 0.03 && s_out.pitch == -0.02 &&
              s_out.p_supply == 17.5e6 && s_out.rcl_util == 0.93 && s_out.stab_margin == 1.7 && s_out.npad == 4 &&
              !memcmp(s_out.pad_F, s_in.pad_F, sizeof s_in.pad_F) && s_out.cyl[1][12] == -0.25 &&
              s_out.cyl_bits[1] == PROTO_CYL_END_STOP && s_out.cyl_bits[0] == 0 && s_out.nrelief == 2 &&
              s_out.relief[0].cyl == 1 && s_out.relief[0].port == 1 && !strcmp(s_out.relief[0].name, "jib_relief_B") &&
              s_out.relief[1].cyl == -1 && !strcmp(s_out.relief[1].name, "main_relief"),
          "state round trip (version 2 fields)");
    CHECK(s_out.nfn == 3 && !memcmp(s_out.fn, s_in.fn, 3 * sizeof s_in.fn[0]), "state round trip (functions)");
    // Version 2 refusals: a relief naming a cylinder the frame does not have,
    // five supports, unknown cylinder status bits.
    {
        uint8_t bad[1 << 16];
        memcpy(bad, buf, n);
        bad[n - fnb - 14] = 9; // relief 1's cylinder byte: cylinder 8 of 3
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "relief 1"), "relief: %s", err);
        memcpy(bad, buf, n);
        bad[head + 64] = 5;
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "supports"), "pads: %s", err);
        memcpy(bad, buf, n);
        const size_t cyl0 = head + 64 + 1 + 32 + 2 + 240 + 2 + 17 * 96 + 1;
        bad[cyl0 + 104] = 8;
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "status bits"), "bits: %s", err);
        bad[cyl0 + 104] = PROTO_CYL_NO_PINS; // version 3's bit 2: the picture does not draw it
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == 1 && s_out.cyl_bits[0] == PROTO_CYL_NO_PINS,
              "no-pins bit: %s", err);
    }
    // Version 3 range checks, each by a byte or a value changed in place:
    // a function's command past 1, a NaN spool, 17 functions, a cylinder's
    // spool past 1, a NaN nine value, an infinite pose.
    {
        uint8_t bad[1 << 16];
        const double big = 1.5, nan = NAN, inf = INFINITY;
        memcpy(bad, buf, n);
        memcpy(bad + n - 32, &big, 8); // function 1's command
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "function 1: command 1.5"),
              "fn command: %s", err);
        memcpy(bad, buf, n);
        memcpy(bad + n - 8, &nan, 8); // function 2's spool
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "function 2: spool"),
              "fn spool: %s", err);
        memcpy(bad, buf, n);
        bad[n - fnb] = PROTO_MAX_FN + 1;
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "17 functions, at most 16"),
              "nfn: %s", err);
        const size_t cyl0 = head + 64 + 1 + 32 + 2 + 240 + 2 + 17 * 96 + 1;
        memcpy(bad, buf, n);
        memcpy(bad + cyl0 + 105 + 9 * 8, &big, 8); // cylinder 1's spool u
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "cylinder 1: spool 1.5"),
              "cyl spool: %s", err);
        memcpy(bad, buf, n);
        memcpy(bad + cyl0 + 2 * 105 + 7 * 8, &nan, 8); // cylinder 2's pA
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "cylinder 2: value 8"),
              "cyl NaN: %s", err);
        memcpy(bad, buf, n);
        memcpy(bad + 5 + 8, &nan, 8); // x2
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "nine value 2"), "nine: %s", err);
        memcpy(bad, buf, n);
        memcpy(bad + head + 64 + 1 + 32 + 2 + 240 + 2 + 3 * 96 + 4 * 8, &inf, 8); // body 3, rot[1]
        CHECK(parse(bad, n, PROTO_MAX_SERVER_FRAME, &m, err) == -1 && strstr(err, "body 3: pose value 5"),
              "pose: %s", err);
    }
    // A crane chain of 9 functions and 10 cylinders (the 8-function model
    // in the sandbox: its functions and the slew) with a 128-column row,
    // bit for bit; VALVES with 9 openings.
    {
        static proto_state a, *bk = &s_out;
        memset(&a, 0, sizeof a);
        a.nrow = 128;
        for (int k = 0; k < 128; ++k) a.row[k] = 1.0 / (k + 1);
        a.nbody = 12;
        a.ncyl = 10;
        for (int i = 0; i < 10; ++i) {
            for (int k = 0; k < PROTO_CYL_VALUES; ++k) a.cyl[i][k] = (k == 9 || k == 10) ? 0.1 * (i - 5) : i * 100.0 + k;
            a.cyl_bits[i] = (uint8_t)(i < 3 ? PROTO_CYL_END_STOP : PROTO_CYL_NO_PINS);
        }
        a.nfn = 9;
        for (int k = 0; k < 9; ++k) a.fn[k][0] = (k - 4) / 4.0, a.fn[k][1] = (4 - k) / 8.0;
        a.nrelief = 1;
        a.relief[0] = (proto_relief){.cyl = 9, .port = 0, .name = "jib_ext3_relief_A"};
        static uint8_t big[1 << 16];
        const size_t nb = proto_put_state(big, sizeof big, &a);
        CHECK(nb > 0 && parse(big, nb, PROTO_MAX_SERVER_FRAME, &m, err) == 1, "chain state: %s", err);
        CHECK(bk->nrow == 128 && !memcmp(bk->row, a.row, 128 * 8) && bk->ncyl == 10 &&
                  !memcmp(bk->cyl, a.cyl, 10 * sizeof a.cyl[0]) && !memcmp(bk->cyl_bits, a.cyl_bits, 10) &&
                  bk->nfn == 9 && !memcmp(bk->fn, a.fn, 9 * sizeof a.fn[0]) && bk->relief[0].cyl == 9,
              "chain state round trip");
        a.ncyl = PROTO_MAX_CYL + 1;
        CHECK(proto_put_state(big, sizeof big, &a) == 0, "17 cylinders are not encoded");
        a.ncyl = 10, a.nfn = PROTO_MAX_FN + 1;
        CHECK(proto_put_state(big, sizeof big, &a) == 0, "17 functions are not encoded");
        proto_command c9 = {.seq = 11, .op = PROTO_OP_VALVES, .nu = 9};
        for (int k = 0; k < 9; ++k) c9.u[k] = (k - 4) / 4.0;
        const size_t nc = proto_put_command(big, sizeof big, &c9);
        CHECK(nc == 5 + 8 + 1 + 1 + 72, "valves of 9: %zu bytes", nc);
        CHECK(parse(big, nc, PROTO_MAX_CLIENT_FRAME, &m, err) == 1 && m.u.cmd.nu == 9 &&
                  !memcmp(m.u.cmd.u, c9.u, 9 * sizeof(double)),
              "valves of 9 round trip: %s", err);
        c9.nu = 0;
        CHECK(proto_put_command(big, sizeof big, &c9) == 0, "valves of 0 are not encoded");
        c9.nu = PROTO_MAX_FN + 1;
        CHECK(proto_put_command(big, sizeof big, &c9) == 0, "valves of 17 are not encoded");
    }
    // Roll and pitch from a rotation built from known angles, R = Rz Ry Rx,
    // and the tilt from upright acos(R[2][2]) = acos(cos roll cos pitch).
    {
        const double yaw = 0.7, pitch = -0.13, roll = 0.21;
        const double cy = cos(yaw), sy = sin(yaw), cp = cos(pitch), sp = sin(pitch), cr = cos(roll), sr = sin(roll);
        const double R[9] = {cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,
                             sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,
                             -sp,     cp * sr,                cp * cr};
        double r2, p2;
        proto_roll_pitch(R, &r2, &p2);
        CHECK(fabs(r2 - roll) < 1e-15 && fabs(p2 - pitch) < 1e-15, "roll %.17g pitch %.17g", r2, p2);
        CHECK(fabs(acos(cos(r2) * cos(p2)) - acos(R[8])) < 1e-14, "tilt from roll and pitch");
        const double up[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        proto_roll_pitch(up, &r2, &p2);
        CHECK(r2 == 0 && p2 == 0, "upright: roll %g pitch %g", r2, p2);
    }
    // A state frame is refused where the caller has no buffer for it (a server).
    m.u.state = NULL;
    size_t used;
    CHECK(proto_parse(buf, n, PROTO_MAX_SERVER_FRAME, &used, &m, err, sizeof err) == -1, "state refused");
    // ...and by the client limit when it is longer.
    CHECK(parse(buf, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "length"), "%s", err);

    // Commands: every op round trips.
    proto_command c = {.seq = 7, .op = PROTO_OP_VALVES, .nu = 3, .u = {0.5, -1, 1}};
    n = proto_put_command(buf, sizeof buf, &c);
    CHECK(n == 5 + 8 + 1 + 1 + 24, "valves %zu", n);
    CHECK(parse(buf, n, PROTO_MAX_CLIENT_FRAME, &m, err) == 1 && m.u.cmd.seq == 7 && m.u.cmd.u[1] == -1, "%s", err);
    c = (proto_command){.seq = 8, .op = PROTO_OP_SET, .path = "lift_cyl.bore", .value = 0.11};
    n = proto_put_command(buf, sizeof buf, &c);
    CHECK(parse(buf, n, PROTO_MAX_CLIENT_FRAME, &m, err) == 1 && !strcmp(m.u.cmd.path, "lift_cyl.bore") &&
              m.u.cmd.value == 0.11,
          "set: %s", err);
    c = (proto_command){.seq = 9, .op = PROTO_OP_STEP, .frames = 3};
    n = proto_put_command(buf, sizeof buf, &c);
    CHECK(parse(buf, n, PROTO_MAX_CLIENT_FRAME, &m, err) == 1 && m.u.cmd.frames == 3, "step: %s", err);
    c = (proto_command){.seq = 10, .op = PROTO_OP_HOOK, .flag = 1};
    n = proto_put_command(buf, sizeof buf, &c);
    CHECK(parse(buf, n, PROTO_MAX_CLIENT_FRAME, &m, err) == 1 && m.u.cmd.flag == 1, "hook: %s", err);
    n = proto_put_text(buf, sizeof buf, PROTO_NOTICE, 8, PROTO_E_REFUSED, "no such parameter");
    CHECK(parse(buf, n, PROTO_MAX_SERVER_FRAME, &m, err) == 1 && m.type == PROTO_NOTICE && m.u.text.seq == 8 &&
              !strcmp(m.u.text.text, "no such parameter"),
          "notice: %s", err);

    // Refusals, each with its reason.
    uint8_t b[512];
    // length 2^31, refused from the header alone (5 bytes here)
    b[0] = 0, b[1] = 0, b[2] = 0, b[3] = 0x80, b[4] = 4;
    CHECK(parse(b, 5, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "2147483648"), "2^31: %s", err);
    // length 0
    memset(b, 0, 8);
    CHECK(parse(b, 8, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "length"), "0: %s", err);
    // unknown type
    b[0] = 1, b[1] = b[2] = b[3] = 0, b[4] = 99;
    CHECK(parse(b, 5, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "unknown frame type 99"), "%s", err);
    // unknown op
    n = raw_cmd(b, 1, 77, NULL, 0);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "unknown op 77"), "%s", err);
    // NaN, infinity and 1.5 in valves (u8 count, then the openings)
    uint8_t vp[1 + 17 * 8];
    double u[3] = {0, NAN, 0};
    vp[0] = 3;
    memcpy(vp + 1, u, sizeof u);
    n = raw_cmd(b, 2, PROTO_OP_VALVES, vp, 1 + sizeof u);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "opening 2"), "NaN: %s", err);
    u[1] = INFINITY;
    memcpy(vp + 1, u, sizeof u);
    n = raw_cmd(b, 2, PROTO_OP_VALVES, vp, 1 + sizeof u);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1, "inf");
    u[1] = 0, u[2] = 1.5;
    memcpy(vp + 1, u, sizeof u);
    n = raw_cmd(b, 2, PROTO_OP_VALVES, vp, 1 + sizeof u);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "[-1, 1]"), "1.5: %s", err);
    // a valves frame two bytes short, with a header that says so
    u[2] = 0;
    memcpy(vp + 1, u, sizeof u);
    n = raw_cmd(b, 2, PROTO_OP_VALVES, vp, 1 + sizeof u - 2);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "too short"), "short: %s", err);
    // a count of 0 or 17 (version 3: one opening per function, 1..16)
    vp[0] = 0;
    n = raw_cmd(b, 2, PROTO_OP_VALVES, vp, 1);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "0 openings, expected 1..16"), "0: %s",
          err);
    vp[0] = 17;
    memset(vp + 1, 0, 17 * 8);
    n = raw_cmd(b, 2, PROTO_OP_VALVES, vp, 1 + 17 * 8);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "17 openings"), "17: %s", err);
    // a version-2 VALVES (three openings, no count): its first byte read as
    // a count of 0 (the low byte of lift 0.0) is refused, not misread
    memset(vp, 0, 24);
    n = raw_cmd(b, 2, PROTO_OP_VALVES, vp, 24);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1, "a version-2 valves frame is refused");
    // one byte too many
    n = raw_cmd(b, 2, PROTO_OP_RESET, "x", 1);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "after its fields"), "long: %s", err);
    // a hook flag of 2, steps of 0
    n = raw_cmd(b, 3, PROTO_OP_HOOK, "\2", 1);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1, "hook 2");
    uint32_t zero = 0;
    n = raw_cmd(b, 3, PROTO_OP_STEP, &zero, 4);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1, "step 0");
    // a set path with a NUL, an empty one, a length past the frame, a NaN value
    uint8_t sp[64];
    sp[0] = 3, sp[1] = 0, memcpy(sp + 2, "a\0b", 3);
    double v = 1;
    memcpy(sp + 5, &v, 8);
    n = raw_cmd(b, 4, PROTO_OP_SET, sp, 13);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "NUL"), "%s", err);
    sp[0] = 0;
    n = raw_cmd(b, 4, PROTO_OP_SET, sp, 10);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "path length"), "%s", err);
    sp[0] = 200, memcpy(sp + 2, "abc", 3);
    n = raw_cmd(b, 4, PROTO_OP_SET, sp, 13);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "too short"), "%s", err);
    sp[0] = 3, v = NAN;
    memcpy(sp + 5, &v, 8);
    n = raw_cmd(b, 4, PROTO_OP_SET, sp, 13);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "finite"), "%s", err);
    // a hello with the wrong magic, a role of 2
    n = proto_put_client_hello(b, sizeof b, 1, 2);
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "role"), "%s", err);
    n = proto_put_client_hello(b, sizeof b, 1, 0);
    b[5] = 'X';
    CHECK(parse(b, n, PROTO_MAX_CLIENT_FRAME, &m, err) == -1 && strstr(err, "magic"), "%s", err);

    // Random bytes: the parser never claims more than it was given.
    srand(1);
    for (int it = 0; it < 20000; ++it) {
        size_t k = (size_t)(rand() % 64);
        for (size_t i = 0; i < k; ++i) b[i] = (uint8_t)rand();
        if (k >= 4 && it % 2) b[0] = (uint8_t)(rand() % 40), b[1] = b[2] = b[3] = 0;
        memset(&m, 0, sizeof m);
        m.u.state = &s_out;
        int rc = proto_parse(b, k, PROTO_MAX_CLIENT_FRAME, &used, &m, err, sizeof err);
        CHECK(rc != 1 || (used <= k && used >= PROTO_HEADER), "used %zu of %zu", used, k);
    }
    TEST_MAIN_END();
}
