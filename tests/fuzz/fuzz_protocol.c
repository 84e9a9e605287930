// fuzz_protocol.c: libFuzzer target for the serve protocol's frame parser:
// any bytes, parsed frame after frame as a server (client frames) and as a
// client (server frames, up to the larger limit), must end in frames or a
// one-line refusal, never a crash or a read past the input. Each command
// and state frame parsed is encoded again and must give the same bytes
// (the encoding is canonical: a value travels as its bit pattern), so the
// parser keeps nothing the encoder would drop (version 3: the openings by
// function, the function records).
#include "protocol.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static proto_state g_state;

static void walk(const uint8_t* data, size_t size, uint32_t max_len) {
    size_t off = 0;
    for (;;) {
        proto_msg m;
        memset(&m, 0, sizeof m);
        m.u.state = &g_state;
        size_t used;
        char err[256];
        const int rc = proto_parse(data + off, size - off, max_len, &used, &m, err, sizeof err);
        if (rc <= 0) return;
        if (used < PROTO_HEADER || used > size - off) abort();
        if (m.type == PROTO_COMMAND) {
            uint8_t buf[PROTO_MAX_CLIENT_FRAME + 8];
            const size_t n = proto_put_command(buf, sizeof buf, &m.u.cmd);
            proto_msg back;
            memset(&back, 0, sizeof back);
            size_t u2;
            if (!n || proto_parse(buf, n, PROTO_MAX_CLIENT_FRAME, &u2, &back, err, sizeof err) != 1 || u2 != n ||
                back.u.cmd.seq != m.u.cmd.seq || back.u.cmd.op != m.u.cmd.op || back.u.cmd.nu != m.u.cmd.nu ||
                memcmp(back.u.cmd.u, m.u.cmd.u, sizeof m.u.cmd.u) || strcmp(back.u.cmd.path, m.u.cmd.path))
                abort();
            if (n != used || memcmp(buf, data + off, n)) abort();
        }
        if (m.type == PROTO_STATE) {
            static uint8_t buf[PROTO_MAX_SERVER_FRAME + 8];
            const size_t n = proto_put_state(buf, sizeof buf, &g_state);
            if (n != used || memcmp(buf, data + off, n)) abort();
        }
        off += used;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    walk(data, size, PROTO_MAX_CLIENT_FRAME);
    walk(data, size, PROTO_MAX_SERVER_FRAME);
    return 0;
}
