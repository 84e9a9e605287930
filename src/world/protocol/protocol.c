// protocol.c: encoding and checked decoding of the serve protocol
// (protocol.h, docs/protocol.md). Byte order is fixed (little-endian) by
// shifting bytes, so the code does not depend on the host's order; a double
// travels as its IEEE 754 bit pattern, so a value arrives bit for bit.
#include "protocol.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

// ---- writing ----

typedef struct wr {
    uint8_t* b;
    size_t cap, n;
    int fail;
} wr;

static void put_bytes(wr* w, const void* p, size_t k) {
    if (w->fail || k > w->cap - w->n) {
        w->fail = 1;
        return;
    }
    if (k) memcpy(w->b + w->n, p, k); // p may be NULL when k is 0
    w->n += k;
}
static void put_u64(wr* w, uint64_t v) {
    uint8_t t[8];
    for (int i = 0; i < 8; ++i) t[i] = (uint8_t)(v >> (8 * i));
    put_bytes(w, t, 8);
}
static void put_u32(wr* w, uint32_t v) {
    uint8_t t[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    put_bytes(w, t, 4);
}
static void put_u16(wr* w, uint16_t v) {
    uint8_t t[2] = {(uint8_t)v, (uint8_t)(v >> 8)};
    put_bytes(w, t, 2);
}
static void put_u8(wr* w, uint8_t v) { put_bytes(w, &v, 1); }
static void put_f64(wr* w, double d) {
    uint64_t v;
    memcpy(&v, &d, 8);
    put_u64(w, v);
}
static void put_f64s(wr* w, const double* d, int k) {
    for (int i = 0; i < k; ++i) put_f64(w, d[i]);
}

// Start a frame: room for the length, then the type.
static void begin(wr* w, uint8_t* buf, size_t cap, uint8_t type) {
    *w = (wr){.b = buf, .cap = cap};
    put_u32(w, 0);
    put_u8(w, type);
}
// Write the length; 0 when the frame did not fit.
static size_t end(wr* w) {
    if (w->fail || w->n - 4 > PROTO_MAX_SERVER_FRAME) return 0;
    const uint32_t len = (uint32_t)(w->n - 4);
    for (int i = 0; i < 4; ++i) w->b[i] = (uint8_t)(len >> (8 * i));
    return w->n;
}

size_t proto_put_client_hello(uint8_t* buf, size_t cap, uint32_t version, uint8_t role) {
    wr w;
    begin(&w, buf, cap, PROTO_CLIENT_HELLO);
    put_u32(&w, PROTO_MAGIC);
    put_u16(&w, (uint16_t)version);
    put_u8(&w, role);
    return end(&w);
}

size_t proto_put_server_hello(uint8_t* buf, size_t cap, const proto_server_hello* h) {
    wr w;
    begin(&w, buf, cap, PROTO_SERVER_HELLO);
    put_u32(&w, PROTO_MAGIC);
    put_u16(&w, (uint16_t)h->version);
    put_u8(&w, h->role);
    put_u8(&w, h->lockstep);
    put_f64(&w, h->rate);
    put_u32(&w, h->json_len);
    put_bytes(&w, h->json, h->json_len);
    return end(&w);
}

size_t proto_put_command(uint8_t* buf, size_t cap, const proto_command* c) {
    wr w;
    begin(&w, buf, cap, PROTO_COMMAND);
    put_u64(&w, c->seq);
    put_u8(&w, c->op);
    switch (c->op) {
    case PROTO_OP_VALVES:
        if (c->nu < 1 || c->nu > PROTO_MAX_FN) return 0;
        put_u8(&w, c->nu);
        put_f64s(&w, c->u, c->nu);
        break;
    case PROTO_OP_HOOK:
    case PROTO_OP_PAUSE: put_u8(&w, c->flag); break;
    case PROTO_OP_RESET: break;
    case PROTO_OP_SET: {
        const size_t n = strnlen(c->path, PROTO_MAX_PATH + 1);
        if (n > PROTO_MAX_PATH) return 0;
        put_u16(&w, (uint16_t)n);
        put_bytes(&w, c->path, n);
        put_f64(&w, c->value);
        break;
    }
    case PROTO_OP_STEP: put_u32(&w, c->frames); break;
    default: return 0;
    }
    return end(&w);
}

size_t proto_put_state(uint8_t* buf, size_t cap, const proto_state* s) {
    if (s->nrow > PROTO_MAX_ROW || s->nbody > PROTO_MAX_BODIES || s->ncyl > PROTO_MAX_CYL ||
        s->nrope > PROTO_MAX_ROPE || s->npad > PROTO_MAX_PADS || s->nrelief > PROTO_MAX_RELIEFS ||
        s->nfn > PROTO_MAX_FN)
        return 0;
    for (int i = 0; i < s->nrelief; ++i) {
        const size_t k = strnlen(s->relief[i].name, PROTO_RELIEF_NAME + 1);
        if (k == 0 || k > PROTO_RELIEF_NAME || s->relief[i].cyl < -1 || s->relief[i].cyl >= s->ncyl ||
            s->relief[i].port > 1)
            return 0;
    }
    wr w;
    begin(&w, buf, cap, PROTO_STATE);
    put_f64s(&w, s->nine, 9);
    put_u64(&w, s->seq);
    put_u64(&w, s->cmd_seq);
    put_u32(&w, s->flags);
    put_f64(&w, s->slew);
    put_f64s(&w, s->hook, 3);
    put_f64(&w, s->load_mass);
    put_u32(&w, (uint32_t)s->attached);
    put_f64s(&w, s->tip, 3);
    put_f64(&w, s->roll);
    put_f64(&w, s->pitch);
    put_f64(&w, s->p_supply);
    put_f64(&w, s->rcl_util);
    put_f64(&w, s->stab_margin);
    put_u8(&w, s->npad);
    put_f64s(&w, s->pad_F, s->npad);
    put_u16(&w, s->nrow);
    put_f64s(&w, s->row, s->nrow);
    put_u16(&w, s->nbody);
    for (int i = 0; i < s->nbody; ++i) put_f64s(&w, s->pose[i], 12);
    put_u8(&w, s->ncyl);
    for (int i = 0; i < s->ncyl; ++i) {
        put_f64s(&w, s->cyl[i], PROTO_CYL_VALUES);
        put_u8(&w, s->cyl_bits[i]);
    }
    put_u8(&w, s->nrope);
    for (int i = 0; i < s->nrope; ++i) put_f64s(&w, s->rope[i], 3);
    put_u8(&w, s->nrelief);
    for (int i = 0; i < s->nrelief; ++i) {
        const proto_relief* q = &s->relief[i];
        const size_t k = strlen(q->name);
        put_u8(&w, (uint8_t)(q->cyl + 1)); // 0: no cylinder
        put_u8(&w, q->port);
        put_u8(&w, (uint8_t)k);
        put_bytes(&w, q->name, k);
    }
    put_u8(&w, s->nfn);
    for (int i = 0; i < s->nfn; ++i) put_f64s(&w, s->fn[i], PROTO_FN_VALUES);
    return end(&w);
}

size_t proto_put_text(uint8_t* buf, size_t cap, uint8_t type, uint64_t seq, uint16_t code, const char* text) {
    wr w;
    begin(&w, buf, cap, type);
    const size_t n = strnlen(text, PROTO_MAX_TEXT);
    put_u64(&w, seq);
    put_u16(&w, code);
    put_u16(&w, (uint16_t)n);
    put_bytes(&w, text, n);
    return end(&w);
}

void proto_roll_pitch(const double rot[9], double* roll, double* pitch) {
    double s = -rot[6]; // sin(pitch) = -R[2][0]
    if (s > 1) s = 1;
    if (s < -1) s = -1;
    *pitch = asin(s);
    *roll = atan2(rot[7], rot[8]);
}

// ---- reading ----

typedef struct rd {
    const uint8_t* b;
    size_t n, i;
    int fail; // read past the end of the frame
} rd;

static const uint8_t* get_bytes(rd* r, size_t k) {
    if (r->fail || k > r->n - r->i) {
        r->fail = 1;
        return NULL;
    }
    const uint8_t* p = r->b + r->i;
    r->i += k;
    return p;
}
static uint64_t get_u64(rd* r) {
    const uint8_t* p = get_bytes(r, 8);
    uint64_t v = 0;
    if (p)
        for (int i = 0; i < 8; ++i) v |= (uint64_t)p[i] << (8 * i);
    return v;
}
static uint32_t get_u32(rd* r) {
    const uint8_t* p = get_bytes(r, 4);
    return p ? (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24 : 0;
}
static uint16_t get_u16(rd* r) {
    const uint8_t* p = get_bytes(r, 2);
    return p ? (uint16_t)(p[0] | p[1] << 8) : 0;
}
static uint8_t get_u8(rd* r) {
    const uint8_t* p = get_bytes(r, 1);
    return p ? p[0] : 0;
}
static double get_f64(rd* r) {
    uint64_t v = get_u64(r);
    double d;
    memcpy(&d, &v, 8);
    return d;
}
static void get_f64s(rd* r, double* d, int k) {
    for (int i = 0; i < k; ++i) d[i] = get_f64(r);
}

static const char* type_name(int t) {
    static const char* const names[] = {"?", "client hello", "server hello", "state", "command", "error", "notice"};
    return t >= 1 && t <= 6 ? names[t] : "?";
}

const char* proto_op_name(int op) {
    static const char* const names[] = {"?", "valves", "hook", "pause", "reset", "set", "step"};
    return op >= 1 && op < PROTO_OP_COUNT ? names[op] : "unknown";
}

static int parse_command(rd* r, proto_command* c, char* err, size_t errsz) {
    memset(c, 0, sizeof *c);
    c->seq = get_u64(r);
    c->op = get_u8(r);
    if (r->fail) return 0;
    switch (c->op) {
    case PROTO_OP_VALVES:
        c->nu = get_u8(r);
        if (r->fail) return 0;
        if (c->nu < 1 || c->nu > PROTO_MAX_FN) {
            snprintf(err, errsz, "command %llu: valves: %u openings, expected 1..%d (one per function)",
                     (unsigned long long)c->seq, c->nu, PROTO_MAX_FN);
            return -1;
        }
        get_f64s(r, c->u, c->nu);
        if (r->fail) return 0;
        for (int k = 0; k < c->nu; ++k)
            if (!isfinite(c->u[k]) || c->u[k] < -1 || c->u[k] > 1) {
                snprintf(err, errsz, "command %llu: valves: opening %d must be a number in [-1, 1], got %g",
                         (unsigned long long)c->seq, k + 1, c->u[k]);
                return -1;
            }
        return 1;
    case PROTO_OP_HOOK:
    case PROTO_OP_PAUSE:
        c->flag = get_u8(r);
        if (r->fail) return 0;
        if (c->flag > 1) {
            snprintf(err, errsz, "command %llu: %s: flag must be 0 or 1, got %u", (unsigned long long)c->seq,
                     proto_op_name(c->op), c->flag);
            return -1;
        }
        return 1;
    case PROTO_OP_RESET: return 1;
    case PROTO_OP_SET: {
        const uint16_t n = get_u16(r);
        if (r->fail) return 0;
        if (n == 0 || n > PROTO_MAX_PATH) {
            snprintf(err, errsz, "command %llu: set: path length must be 1..%d bytes, got %u",
                     (unsigned long long)c->seq, PROTO_MAX_PATH, n);
            return -1;
        }
        const uint8_t* p = get_bytes(r, n);
        c->value = get_f64(r);
        if (r->fail) return 0;
        if (memchr(p, 0, n)) {
            snprintf(err, errsz, "command %llu: set: path contains a NUL byte", (unsigned long long)c->seq);
            return -1;
        }
        memcpy(c->path, p, n);
        c->path[n] = 0;
        if (!isfinite(c->value)) {
            snprintf(err, errsz, "command %llu: set %s: value must be a finite number, got %g",
                     (unsigned long long)c->seq, c->path, c->value);
            return -1;
        }
        return 1;
    }
    case PROTO_OP_STEP:
        c->frames = get_u32(r);
        if (r->fail) return 0;
        if (c->frames < 1 || c->frames > 100000) {
            snprintf(err, errsz, "command %llu: step: frames must be 1..100000, got %u", (unsigned long long)c->seq,
                     c->frames);
            return -1;
        }
        return 1;
    default:
        snprintf(err, errsz, "command %llu: unknown op %u", (unsigned long long)c->seq, c->op);
        return -1;
    }
}

// The first of k values that is not a finite number, or -1.
static int first_nonfinite(const double* d, int k) {
    for (int i = 0; i < k; ++i)
        if (!isfinite(d[i])) return i;
    return -1;
}

static int parse_state(rd* r, proto_state* s, char* err, size_t errsz) {
    get_f64s(r, s->nine, 9);
    if (!r->fail && first_nonfinite(s->nine, 9) >= 0) {
        snprintf(err, errsz, "state: nine value %d is not a finite number", first_nonfinite(s->nine, 9) + 1);
        return -1;
    }
    s->seq = get_u64(r);
    s->cmd_seq = get_u64(r);
    s->flags = get_u32(r);
    s->slew = get_f64(r);
    get_f64s(r, s->hook, 3);
    s->load_mass = get_f64(r);
    s->attached = (int32_t)get_u32(r);
    get_f64s(r, s->tip, 3);
    s->roll = get_f64(r);
    s->pitch = get_f64(r);
    s->p_supply = get_f64(r);
    s->rcl_util = get_f64(r);
    s->stab_margin = get_f64(r);
    s->npad = get_u8(r);
    if (r->fail) return 0;
    if (s->npad > PROTO_MAX_PADS) {
        snprintf(err, errsz, "state: %u supports, at most %d", s->npad, PROTO_MAX_PADS);
        return -1;
    }
    get_f64s(r, s->pad_F, s->npad);
    s->nrow = get_u16(r);
    if (r->fail) return 0;
    if (s->nrow > PROTO_MAX_ROW) {
        snprintf(err, errsz, "state: %u row values, at most %d", s->nrow, PROTO_MAX_ROW);
        return -1;
    }
    get_f64s(r, s->row, s->nrow);
    s->nbody = get_u16(r);
    if (r->fail) return 0;
    if (s->nbody > PROTO_MAX_BODIES) {
        snprintf(err, errsz, "state: %u bodies, at most %d", s->nbody, PROTO_MAX_BODIES);
        return -1;
    }
    for (int i = 0; i < s->nbody; ++i) {
        get_f64s(r, s->pose[i], 12);
        if (!r->fail && first_nonfinite(s->pose[i], 12) >= 0) {
            snprintf(err, errsz, "state: body %d: pose value %d is not a finite number", i,
                     first_nonfinite(s->pose[i], 12) + 1);
            return -1;
        }
    }
    s->ncyl = get_u8(r);
    if (r->fail) return 0;
    if (s->ncyl > PROTO_MAX_CYL) {
        snprintf(err, errsz, "state: %u cylinders, at most %d", s->ncyl, PROTO_MAX_CYL);
        return -1;
    }
    for (int i = 0; i < s->ncyl; ++i) {
        get_f64s(r, s->cyl[i], PROTO_CYL_VALUES);
        s->cyl_bits[i] = get_u8(r);
        if (r->fail) return 0;
        if (s->cyl_bits[i] > (PROTO_CYL_RELIEF | PROTO_CYL_END_STOP | PROTO_CYL_NO_PINS)) {
            snprintf(err, errsz, "state: cylinder %d: status bits 0x%02x, only 0x07 defined", i, s->cyl_bits[i]);
            return -1;
        }
        const int bad = first_nonfinite(s->cyl[i], PROTO_CYL_VALUES);
        if (bad >= 0) {
            snprintf(err, errsz, "state: cylinder %d: value %d is not a finite number", i, bad + 1);
            return -1;
        }
        // Openings u (spool) and u_cmd (command) [-].
        for (int k = 9; k <= 10; ++k)
            if (s->cyl[i][k] < -1 || s->cyl[i][k] > 1) {
                snprintf(err, errsz, "state: cylinder %d: %s %g outside [-1, 1]", i, k == 9 ? "spool" : "command",
                         s->cyl[i][k]);
                return -1;
            }
    }
    s->nrope = get_u8(r);
    if (r->fail) return 0;
    if (s->nrope > PROTO_MAX_ROPE) {
        snprintf(err, errsz, "state: %u rope points, at most %d", s->nrope, PROTO_MAX_ROPE);
        return -1;
    }
    for (int i = 0; i < s->nrope; ++i) get_f64s(r, s->rope[i], 3);
    s->nrelief = get_u8(r);
    if (r->fail) return 0;
    if (s->nrelief > PROTO_MAX_RELIEFS) {
        snprintf(err, errsz, "state: %u open reliefs, at most %d", s->nrelief, PROTO_MAX_RELIEFS);
        return -1;
    }
    for (int i = 0; i < s->nrelief; ++i) {
        proto_relief* q = &s->relief[i];
        const int cyl = (int)get_u8(r) - 1;
        q->port = get_u8(r);
        const uint8_t k = get_u8(r);
        if (r->fail) return 0;
        if (cyl >= s->ncyl || q->port > 1 || k == 0 || k > PROTO_RELIEF_NAME) {
            snprintf(err, errsz, "state: relief %d: cylinder %d of %u, port %u or name of %u bytes (1..%d) out of range",
                     i, cyl, s->ncyl, q->port, k, PROTO_RELIEF_NAME);
            return -1;
        }
        const uint8_t* p = get_bytes(r, k);
        if (!p) return 0;
        if (memchr(p, 0, k)) {
            snprintf(err, errsz, "state: relief %d: name contains a NUL byte", i);
            return -1;
        }
        q->cyl = (int8_t)cyl;
        memcpy(q->name, p, k);
        q->name[k] = 0;
    }
    s->nfn = get_u8(r);
    if (r->fail) return 0;
    if (s->nfn > PROTO_MAX_FN) {
        snprintf(err, errsz, "state: %u functions, at most %d", s->nfn, PROTO_MAX_FN);
        return -1;
    }
    for (int i = 0; i < s->nfn; ++i) {
        get_f64s(r, s->fn[i], PROTO_FN_VALUES);
        if (r->fail) return 0;
        for (int k = 0; k < PROTO_FN_VALUES; ++k)
            if (!(s->fn[i][k] >= -1 && s->fn[i][k] <= 1)) { // NaN fails too
                snprintf(err, errsz, "state: function %d: %s %g must be a number in [-1, 1]", i,
                         k ? "spool" : "command", s->fn[i][k]);
                return -1;
            }
    }
    return r->fail ? 0 : 1;
}

int proto_parse(const uint8_t* buf, size_t len, uint32_t max_len, size_t* used, proto_msg* out, char* err,
                size_t errsz) {
    *used = 0;
    if (len < 4) return 0;
    const uint32_t flen = (uint32_t)buf[0] | (uint32_t)buf[1] << 8 | (uint32_t)buf[2] << 16 | (uint32_t)buf[3] << 24;
    // Checked on the header alone: a length of 2^31 is refused before a
    // byte of it is buffered.
    if (flen == 0 || flen > max_len) {
        snprintf(err, errsz, "frame length %u outside 1..%u bytes", flen, max_len);
        return -1;
    }
    if (len - 4 < flen) return 0;
    rd r = {.b = buf + 4, .n = flen};
    const uint8_t type = get_u8(&r);
    int rc;
    switch (type) {
    case PROTO_CLIENT_HELLO: {
        const uint32_t magic = get_u32(&r);
        out->u.chello.version = get_u16(&r);
        out->u.chello.role = get_u8(&r);
        rc = r.fail ? 0 : 1;
        if (rc && magic != PROTO_MAGIC) {
            snprintf(err, errsz, "client hello: bad magic 0x%08x (not a cranesim client)", magic);
            return -1;
        }
        if (rc && out->u.chello.role > PROTO_CONTROL) {
            snprintf(err, errsz, "client hello: role must be 0 (watch) or 1 (control), got %u", out->u.chello.role);
            return -1;
        }
        break;
    }
    case PROTO_SERVER_HELLO: {
        proto_server_hello* h = &out->u.shello;
        const uint32_t magic = get_u32(&r);
        h->version = get_u16(&r);
        h->role = get_u8(&r);
        h->lockstep = get_u8(&r);
        h->rate = get_f64(&r);
        h->json_len = get_u32(&r);
        h->json = (const char*)get_bytes(&r, h->json_len);
        rc = r.fail ? 0 : 1;
        if (rc && magic != PROTO_MAGIC) {
            snprintf(err, errsz, "server hello: bad magic 0x%08x (not a cranesim server)", magic);
            return -1;
        }
        if (rc && (h->role > 1 || h->lockstep > 1 || !isfinite(h->rate) || h->rate <= 0)) {
            snprintf(err, errsz, "server hello: role %u, lockstep %u or rate %g out of range", h->role, h->lockstep,
                     h->rate);
            return -1;
        }
        break;
    }
    case PROTO_STATE:
        if (!out->u.state) {
            snprintf(err, errsz, "unexpected state frame");
            return -1;
        }
        rc = parse_state(&r, out->u.state, err, errsz);
        break;
    case PROTO_COMMAND: rc = parse_command(&r, &out->u.cmd, err, errsz); break;
    case PROTO_ERROR:
    case PROTO_NOTICE: {
        proto_text* t = &out->u.text;
        t->seq = get_u64(&r);
        t->code = get_u16(&r);
        const uint16_t n = get_u16(&r);
        rc = r.fail ? 0 : 1;
        if (rc && n > PROTO_MAX_TEXT) {
            snprintf(err, errsz, "%s: text of %u bytes, at most %d", type_name(type), n, PROTO_MAX_TEXT);
            return -1;
        }
        const uint8_t* p = rc ? get_bytes(&r, n) : NULL;
        rc = r.fail ? 0 : 1;
        if (rc) {
            memcpy(t->text, p, n);
            t->text[n] = 0;
        }
        break;
    }
    default: snprintf(err, errsz, "unknown frame type %u", type); return -1;
    }
    if (rc < 0) return -1;
    // The whole frame is here, so a field that ran past its end means the
    // frame is shorter than its type says; bytes left over, longer.
    if (rc == 0) {
        snprintf(err, errsz, "%s frame of %u bytes is too short for its fields", type_name(type), flen);
        return -1;
    }
    if (r.i != r.n) {
        snprintf(err, errsz, "%s frame has %zu bytes after its fields", type_name(type), r.n - r.i);
        return -1;
    }
    out->type = type;
    *used = 4 + (size_t)flen;
    return 1;
}
