// test_serve_chain.c: `cranesim serve` on a crane chain of 8 functions
// (tests/world/data/chain_8fn_10link.json, 10 bodies, 9 actuators) in the
// sandbox, protocol version 3 (docs/protocol.md).
//
// 1. The hello lists every function (the model's 8 and the sandbox's
//    slew, in the engine's order), the actuators each drives with their
//    units, every crane body with its joint's unit, and every channel.
// 2. VALVES with the wrong number of openings gets a NOTICE naming the
//    functions; the connection stays.
// 3. Bit for bit: a lockstep client sends 9 openings (a different one per
//    function) and STEP 1 per frame; every state frame's row equals the row
//    of the same commands on a local engine of the same model, every
//    function record is that function's command and spool there, every
//    cylinder record its actuator's stroke and pressures, and the nine
//    values are the first two functions' (docs/protocol.md). Then the
//    controller leaves with every valve open: the next one finds every
//    function at neutral (dead-man).
// 4. What stays unsupported is refused in one line, exit 2: a chain
//    without a picture (--mechanics lagrange), --rcl on (no limiter for a
//    chain yet).
// 5. The shipped loader10.json: its functions (ext on two cylinders) and
//    a frame with a record for each.
#define _DEFAULT_SOURCE // usleep, in serve_util.h
#include "check.h"
#include "crane_chain.h"
#include "engine.h"
#include "model.h"
#include "scenario.h"
#include "serve_util.h"

#include <cJSON.h>
#include <math.h>

#define MODEL CRANESIM_SOURCE_DIR "/tests/world/data/chain_8fn_10link.json"
#define SCEN "sandbox_pick_place"

static proto_state g_st;

// The column of the local engine's channel called name, or -1.
static int col_of(engine* l, const char* name) {
    int n = 0;
    const sim_channel* ch = engine_channels(l, &n);
    for (int i = 0; i < n; ++i)
        if (!strcmp(ch[i].name, name)) return i;
    return -1;
}

static void served_chain(void) {
    char err[512], path[1024];
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = "sandbox";
    model* m = model_load(MODEL, NULL, 0, err, sizeof err);
    snprintf(path, sizeof path, "%s/scenarios/%s.json", model_assets_dir(), SCEN);
    scenario sc;
    CHECK(m && scenario_load(path, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    engine* l = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
    CHECK(l != NULL, "local engine: %s", err);
    if (!l) {
        model_free(m);
        return;
    }
    const int nfn = engine_nfunction(l), ncol = engine_ncol(l);
    const crane_chain* cc = &m->chain;
    CHECK(nfn == 9 && cc->nfn == 8 && cc->nact == 9 && cc->nbody == 10, "%d functions (chain %d), %d actuators, %d bodies",
          nfn, cc->nfn, cc->nact, cc->nbody);

    const char* args[] = {"--model", MODEL, "--scenario", SCEN, "--lockstep", NULL};
    served sv = {.pid = 0};
    CHECK(serve_start(&sv, NULL, args) == 0, "server started on the 8-function chain");
    int fd = tcp_connect(sv.port);
    uint8_t b[64];
    size_t n = proto_put_client_hello(b, sizeof b, PROTO_VERSION, PROTO_CONTROL);
    proto_msg msg;
    CHECK(fd >= 0 && send_all(fd, b, n) == 0 && recv_frame(fd, &msg, &g_st, 5000) == PROTO_SERVER_HELLO,
          "hello answered");
    cJSON* j = cJSON_ParseWithLength(msg.u.shello.json, msg.u.shello.json_len);
    CHECK(j && msg.u.shello.version == 3 && msg.u.shello.role == PROTO_CONTROL, "a version-3 hello, control");

    // 1. the hello: functions, actuators, bodies, channels
    const cJSON* fa = cJSON_GetObjectItem(j, "functions");
    CHECK(cJSON_GetArraySize(fa) == nfn, "%d functions in the hello, the engine has %d", cJSON_GetArraySize(fa), nfn);
    int acts_listed = 0;
    for (int k = 0; k < nfn && k < cJSON_GetArraySize(fa); ++k) {
        const cJSON* f = cJSON_GetArrayItem(fa, k);
        const char* name = cJSON_GetStringValue(cJSON_GetObjectItem(f, "name"));
        CHECK(name && !strcmp(name, engine_function_name(l, k)), "function %d: '%s', the engine's '%s'", k,
              name ? name : "?", engine_function_name(l, k));
        CHECK(!strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(f, "unit")), "-"), "function %d: unit '-'", k);
        const cJSON* aa = cJSON_GetObjectItem(f, "actuators");
        // The model's actuators on this function (crane_chain_bind's
        // act.function), and the slew rack for the sandbox's slew.
        int want = 0;
        for (int a = 0; a < cc->nact; ++a)
            if (name && !strcmp(cc->fn[cc->act[a].function].name, name)) ++want;
        if (name && !strcmp(name, "slew")) want = 1;
        CHECK(cJSON_GetArraySize(aa) == want, "function %s drives %d actuators in the hello, the model says %d",
              name ? name : "?", cJSON_GetArraySize(aa), want);
        for (int i = 0; i < cJSON_GetArraySize(aa); ++i) {
            const cJSON* a = cJSON_GetArrayItem(aa, i);
            const char* an = cJSON_GetStringValue(cJSON_GetObjectItem(a, "name"));
            const int ia = an ? crane_chain_find_act(cc, an) : -1;
            CHECK((ia >= 0 && !strcmp(cc->fn[cc->act[ia].function].name, name)) || (an && !strcmp(an, "slew")),
                  "function %s: actuator '%s' is its own", name, an ? an : "?");
            const cJSON* u = cJSON_GetObjectItem(a, "units");
            CHECK(!strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(u, "stroke")), "m") &&
                      !strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(u, "pA")), "Pa abs") &&
                      !strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(u, "pB")), "Pa abs") &&
                      !strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(u, "force")), "N"),
                  "actuator %s: units m, Pa abs, N", an ? an : "?");
            ++acts_listed;
        }
    }
    CHECK(acts_listed == cc->nact + 1, "%d actuators listed, the model's %d and the slew rack", acts_listed,
          cc->nact);
    const cJSON* cb = cJSON_GetObjectItem(j, "crane_bodies");
    CHECK(cJSON_GetArraySize(cb) == cc->nbody, "%d crane bodies, the model's %d", cJSON_GetArraySize(cb), cc->nbody);
    for (int i = 0; i < cc->nbody && i < cJSON_GetArraySize(cb); ++i) {
        const cJSON* o1 = cJSON_GetArrayItem(cb, i);
        const bool pri = cc->body[i].def.joint == CHAIN_PRISMATIC;
        CHECK(!strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(o1, "name")), cc->body[i].def.name) &&
                  !strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(o1, "unit")), pri ? "m" : "rad"),
              "crane body %d: %s in %s", i, cc->body[i].def.name, pri ? "m" : "rad");
    }
    const cJSON* ch = cJSON_GetObjectItem(j, "channels");
    int nch = 0;
    const sim_channel* chs = engine_channels(l, &nch);
    CHECK(cJSON_GetArraySize(ch) == ncol && ncol == nch, "%d channels in the hello, %d columns", cJSON_GetArraySize(ch),
          ncol);
    int name_diff = 0;
    for (int i = 0; i < nch && i < cJSON_GetArraySize(ch); ++i)
        name_diff += strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(ch, i), "name")),
                            chs[i].name) != 0;
    CHECK(name_diff == 0, "%d channel names differ", name_diff);
    // The cylinder record of each function's first actuator, by the hello.
    int fcyl[PROTO_MAX_FN];
    for (int k = 0; k < nfn; ++k) {
        const cJSON* a0 = cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetArrayItem(fa, k), "actuators"), 0);
        fcyl[k] = a0 ? cJSON_GetObjectItem(a0, "cylinder")->valueint : -1;
    }
    const cJSON* cyls = cJSON_GetObjectItem(j, "cylinders");
    CHECK(fd >= 0 && next_state(fd, &g_st, 5000) == 0 && g_st.nine[8] == 0, "the state at t = 0 first");

    // 2. three openings for nine functions: a notice, the link stays
    {
        proto_command c = {.seq = 1, .op = PROTO_OP_VALVES, .nu = 3, .u = {0.5, 0, 0}};
        send_cmd(fd, &c);
        int t;
        do t = recv_frame(fd, &msg, &g_st, 5000);
        while (t == PROTO_STATE);
        CHECK(t == PROTO_NOTICE && msg.u.text.code == PROTO_E_REFUSED &&
                  strstr(msg.u.text.text, "valves: 3 openings for the 9 functions lift, fold, ext1, ext3, jib, "
                                          "jib_ext1, jib_ext2, jib_ext3, slew"),
              "wrong count: '%s'", t == PROTO_NOTICE ? msg.u.text.text : "(no notice)");
        printf("wrong count: %s\n", t == PROTO_NOTICE ? msg.u.text.text : "(no notice)");
    }

    // 3. nine openings per frame, bit for bit with the local engine
    const double frame = 1.0 / 75;
    const int nframes = 60;
    double* row = calloc((size_t)ncol + SIM_NCOL, sizeof *row);
    world_snapshot* snap = malloc(sizeof *snap);
    double sent[PROTO_MAX_FN];
    long echo_diff = 0, row_diff = 0, fn_diff = 0, cyl_diff = 0, nine_diff = 0, moved = 0;
    uint64_t seq = 1;
    double x0[PROTO_MAX_CYL];
    for (int i = 0; i < nframes && fd >= 0 && row && snap; ++i) {
        proto_command c = {.seq = ++seq, .op = PROTO_OP_VALVES, .nu = (uint8_t)nfn};
        // A different opening per function, each changing sign half-way.
        for (int k = 0; k < nfn; ++k) c.u[k] = sent[k] = (i < nframes / 2 ? 1 : -1) * (0.3 + 0.07 * k);
        CHECK(engine_set_function_commands(l, c.u, nfn, err, sizeof err) == 0, "%s", err);
        CHECK(engine_advance(l, (i + 1) * frame - engine_time(l)) == 0, "local step %d", i);
        engine_row(l, row);
        engine_snapshot(l, snap);
        send_cmd(fd, &c);
        c = (proto_command){.seq = ++seq, .op = PROTO_OP_STEP, .frames = 1};
        send_cmd(fd, &c);
        if (next_state(fd, &g_st, 10000)) {
            CHECK(0, "no state after step %d", i);
            break;
        }
        CHECK(g_st.cmd_seq == seq, "frame %d echoes %llu", i, (unsigned long long)seq);
        if (g_st.nrow != ncol || memcmp(g_st.row, row, (size_t)ncol * sizeof *row)) ++row_diff;
        // Every function: its command and spool as the local engine has them
        // (a chain function's columns; the slew's rack cylinder).
        if (g_st.nfn != nfn) ++fn_diff;
        for (int k = 0; k < nfn && k < g_st.nfn; ++k) {
            const char* fname = engine_function_name(l, k);
            char cu[64], cm[64];
            snprintf(cu, sizeof cu, "u_%s", fname);
            snprintf(cm, sizeof cm, "ucmd_%s", fname);
            double want_cmd, want_u;
            if (col_of(l, cu) >= 0) want_cmd = row[col_of(l, cm)], want_u = row[col_of(l, cu)];
            else {
                int y = -1;
                for (int q = 0; q < snap->ncyl; ++q)
                    if (!strcmp(snap->cyl[q].name, fname)) y = q;
                want_cmd = y >= 0 ? snap->cyl[y].u_cmd : NAN, want_u = y >= 0 ? snap->cyl[y].u : NAN;
            }
            if (g_st.fn[k][0] != want_cmd || g_st.fn[k][1] != want_u) ++fn_diff;
            if (g_st.fn[k][0] != sent[k]) ++echo_diff; // the opening this client sent for it
        }
        // Every cylinder record: its actuator's stroke and pressures.
        if (g_st.ncyl != cJSON_GetArraySize(cyls)) ++cyl_diff;
        for (int q = 0; q < g_st.ncyl && q < cJSON_GetArraySize(cyls); ++q) {
            const char* an = cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(cyls, q), "name"));
            char cx[64], ca[64], cbn[64];
            snprintf(cx, sizeof cx, "x_%s", an);
            snprintf(ca, sizeof ca, "pA_%s", an);
            snprintf(cbn, sizeof cbn, "pB_%s", an);
            if (col_of(l, cx) >= 0 &&
                (g_st.cyl[q][6] != row[col_of(l, cx)] || g_st.cyl[q][7] != row[col_of(l, ca)] ||
                 g_st.cyl[q][8] != row[col_of(l, cbn)]))
                ++cyl_diff;
            if (i == 0) x0[q] = g_st.cyl[q][6];
            if (i == nframes / 2 - 1 && fabs(g_st.cyl[q][6] - x0[q]) > 1e-3) ++moved;
        }
        // The nine: lift's and fold's strokes and pressures, their spools, t.
        const double nine[9] = {row[col_of(l, "x_lift")],  row[col_of(l, "x_fold")],  row[col_of(l, "pA_lift")],
                                row[col_of(l, "pB_lift")], row[col_of(l, "pA_fold")], row[col_of(l, "pB_fold")],
                                row[col_of(l, "u_lift")],  row[col_of(l, "u_fold")],  engine_time(l)};
        if (memcmp(nine, g_st.nine, sizeof nine)) ++nine_diff;
    }
    printf("chain: %d frames, rows differ in %ld, function records in %ld, cylinder records in %ld, nine in %ld; "
           "%ld of %d cylinders moved by more than 1 mm in the first half\n",
           nframes, row_diff, fn_diff, cyl_diff, nine_diff, moved, g_st.ncyl);
    CHECK(row_diff == 0 && fn_diff == 0 && cyl_diff == 0 && nine_diff == 0,
          "served frames differ from the local engine: rows %ld, functions %ld, cylinders %ld, nine %ld", row_diff,
          fn_diff, cyl_diff, nine_diff);
    CHECK(echo_diff == 0, "%ld function commands differ from the openings sent", echo_diff);
    CHECK(g_st.ncyl == 10 && g_st.nfn == 9, "10 cylinder records (%u), 9 function records (%u)", g_st.ncyl,
          g_st.nfn);
    CHECK(moved >= 8, "the commands moved %ld cylinders", moved);
    for (int k = 0; k < nfn; ++k)
        CHECK(fcyl[k] >= 0 && fcyl[k] < g_st.ncyl, "function %d has a cylinder record (%d)", k, fcyl[k]);
    // Dead-man: the controller leaves with every function's valve open; the
    // next controller finds every function's command at 0 (neutral), and
    // after 0.2 s every spool closed.
    if (fd >= 0) close(fd);
    int fd2 = -1, role = -1;
    for (int k = 0; k < 100 && role != PROTO_CONTROL; ++k) {
        if (fd2 >= 0) close(fd2);
        fd2 = serve_join(sv.port, PROTO_CONTROL, &role);
        if (role != PROTO_CONTROL) usleep(20000);
    }
    CHECK(fd2 >= 0 && role == PROTO_CONTROL, "the next client got control");
    if (fd2 >= 0) {
        proto_command c = {.seq = 1, .op = PROTO_OP_STEP, .frames = 15};
        send_cmd(fd2, &c);
        int open_fn = 0;
        double worst = 0;
        CHECK(next_state(fd2, &g_st, 5000) == 0 && next_state(fd2, &g_st, 10000) == 0, "state after 15 frames");
        for (int k = 0; k < g_st.nfn; ++k) {
            if (g_st.fn[k][0] != 0) ++open_fn;
            worst = fmax(worst, fabs(g_st.fn[k][1]));
        }
        printf("dead-man: %d of %u function commands not at 0, largest spool %.3g after 0.2 s\n", open_fn, g_st.nfn,
               worst);
        CHECK(g_st.nfn == 9 && open_fn == 0 && worst < 0.01, "dead-man: %d commands open, spool %g", open_fn, worst);
        close(fd2);
    }
    CHECK(serve_stop(&sv) == 0, "server exits 0 on SIGINT");
    cJSON_Delete(j);
    free(row);
    free(snap);
    engine_destroy(l);
    model_free(m);
}

// 5. The shipped chain model, loader10.json (three functions, the ext
// function on two telescope cylinders, the model's own slew drive): the
// hello's functions and actuators, and a frame with a record for each.
static void served_loader10(void) {
    const char* args[] = {"--model", CRANESIM_ASSETS "/models/loader10.json", "--lockstep", NULL};
    served sv = {.pid = 0};
    CHECK(serve_start(&sv, NULL, args) == 0, "server started on loader10");
    int fd = tcp_connect(sv.port);
    uint8_t b[64];
    size_t n = proto_put_client_hello(b, sizeof b, PROTO_VERSION, PROTO_CONTROL);
    proto_msg msg;
    CHECK(fd >= 0 && send_all(fd, b, n) == 0 && recv_frame(fd, &msg, &g_st, 5000) == PROTO_SERVER_HELLO,
          "hello answered");
    cJSON* j = cJSON_ParseWithLength(msg.u.shello.json, msg.u.shello.json_len);
    const cJSON* fa = cJSON_GetObjectItem(j, "functions");
    char names[256] = "";
    for (int k = 0; k < cJSON_GetArraySize(fa); ++k) {
        const cJSON* f = cJSON_GetArrayItem(fa, k);
        const cJSON* aa = cJSON_GetObjectItem(f, "actuators");
        size_t L = strlen(names);
        snprintf(names + L, sizeof names - L, "%s%s(", k ? " " : "", cJSON_GetStringValue(cJSON_GetObjectItem(f, "name")));
        for (int i = 0; i < cJSON_GetArraySize(aa); ++i) {
            L = strlen(names);
            snprintf(names + L, sizeof names - L, "%s%s", i ? "," : "",
                     cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(aa, i), "name")));
        }
        L = strlen(names);
        snprintf(names + L, sizeof names - L, ")");
    }
    printf("loader10: functions %s\n", names);
    CHECK(!strcmp(names, "lift(lift) jib(jib) ext(ext1,ext2) slew(slew)"), "loader10 functions: %s", names);
    proto_command c = {.seq = 1, .op = PROTO_OP_VALVES, .nu = 4, .u = {0, 0, 0.8, 0}};
    send_cmd(fd, &c);
    c = (proto_command){.seq = 2, .op = PROTO_OP_STEP, .frames = 30};
    send_cmd(fd, &c);
    CHECK(next_state(fd, &g_st, 5000) == 0 && next_state(fd, &g_st, 10000) == 0, "state after 30 frames");
    CHECK(g_st.nfn == 4 && g_st.ncyl == 5 && g_st.fn[2][0] == 0.8 && g_st.fn[2][1] > 0.5 && g_st.fn[0][0] == 0,
          "loader10 frame: %u functions, %u cylinders, ext command %g spool %g", g_st.nfn, g_st.ncyl, g_st.fn[2][0],
          g_st.fn[2][1]);
    cJSON_Delete(j);
    if (fd >= 0) close(fd);
    CHECK(serve_stop(&sv) == 0, "server exits 0 on SIGINT");
}

// 6. serve --rcl on on loader10 (a chain with the maker's rating,
// mechanics.rated_moment): the engine has a chain limiter
// (ENGINE_CAP_LIMITER), so serve starts with it on; every state frame
// carries its utilisation (PROTO_F_RCL_HAVE, PROTO_F_RCL_ON), the same as a
// local engine's limiter with the same options over the same commands (the
// limiter's own physics is test_rcl_chain's), while the ext function runs out.
static void served_loader10_rcl(void) {
    char err[512], path[1024];
    sim_opts o = sim_default_opts();
    o.mechanics = SIM_ODE;
    o.world = "sandbox"; // serve's only world for a chain (the renderer's picture)
    o.rcl = true;
    model* m = model_load(CRANESIM_ASSETS "/models/loader10.json", NULL, 0, err, sizeof err);
    snprintf(path, sizeof path, "%s/scenarios/%s.json", model_assets_dir(), SCEN);
    scenario sc;
    CHECK(m && scenario_load(path, &sc, err, sizeof err) == 0, "%s", err);
    if (!m) return;
    engine* l = engine_create(m, &o, sc.q0, sc.slew0, sim_load_mass(m, &sc, &o), err, sizeof err);
    CHECK(l != NULL, "local engine: %s", err);
    world_snapshot* snap = malloc(sizeof *snap);
    const char* args[] = {"--model", CRANESIM_ASSETS "/models/loader10.json", "--scenario", SCEN, "--rcl", "on",
                          "--lockstep", NULL};
    served sv = {.pid = 0};
    CHECK(serve_start(&sv, NULL, args) == 0, "server started on loader10 with --rcl on");
    int fd = tcp_connect(sv.port);
    uint8_t b[64];
    size_t n = proto_put_client_hello(b, sizeof b, PROTO_VERSION, PROTO_CONTROL);
    proto_msg msg;
    CHECK(fd >= 0 && send_all(fd, b, n) == 0 && recv_frame(fd, &msg, &g_st, 5000) == PROTO_SERVER_HELLO,
          "hello answered");
    CHECK(fd >= 0 && next_state(fd, &g_st, 5000) == 0, "the state at t = 0");
    const int nfn = l ? engine_nfunction(l) : 0, nframes = 30;
    int have = 0, differ = 0;
    double u0 = NAN, u1 = NAN, worst = 0;
    uint64_t seq = 0;
    for (int i = 0; i < nframes && fd >= 0 && l && snap; ++i) {
        // ext (function 2: lift, jib, ext, slew) runs out at 0.8.
        proto_command c = {.seq = ++seq, .op = PROTO_OP_VALVES, .nu = (uint8_t)nfn, .u = {0, 0, 0.8, 0}};
        CHECK(engine_set_function_commands(l, c.u, nfn, err, sizeof err) == 0, "%s", err);
        CHECK(engine_advance(l, (i + 1) / 75.0 - engine_time(l)) == 0, "local step %d", i);
        engine_snapshot(l, snap);
        send_cmd(fd, &c);
        c = (proto_command){.seq = ++seq, .op = PROTO_OP_STEP, .frames = 1};
        send_cmd(fd, &c);
        if (next_state(fd, &g_st, 10000)) {
            CHECK(0, "no state after step %d", i);
            break;
        }
        const uint32_t want = PROTO_F_RCL_HAVE | PROTO_F_RCL_ON;
        have += (g_st.flags & want) == want && isfinite(g_st.rcl_util);
        if (g_st.rcl_util != snap->rcl_util) ++differ;
        worst = fmax(worst, fabs(g_st.rcl_util - snap->rcl_util));
        if (i == 0) u0 = g_st.rcl_util;
        u1 = g_st.rcl_util;
    }
    printf("loader10 --rcl on: %d of %d frames with the limiter on and its utilisation; %.4f -> %.4f over the ext "
           "run-out; %d differ from the local engine's (largest %.3g)\n",
           have, nframes, u0, u1, differ, worst);
    CHECK(have == nframes, "%d of %d state frames flag the limiter (PROTO_F_RCL_HAVE | PROTO_F_RCL_ON)", have,
          nframes);
    CHECK(differ == 0, "%d frames' rcl_util differ from the local engine's limiter (largest %g)", differ, worst);
    // The sandbox's loads lie on the ground until hooked: the limiter reads
    // only the empty hook, a small utilisation that grows from 0 as the
    // lift's pressure settles (a hooked load's reading is test_rcl_chain's
    // sandbox test).
    CHECK(u0 >= 0 && u1 > 0 && u1 < 0.05, "the utilisation of the empty hook: %g -> %g", u0, u1);
    if (fd >= 0) close(fd);
    CHECK(serve_stop(&sv) == 0, "server exits 0 on SIGINT");
    free(snap);
    if (l) engine_destroy(l);
    model_free(m);
}

// 4. cranesim serve ARGS: exit 2 and one line on stderr naming want.
static void refused(const char* args, const char* want) {
    char cmd[1024], out[2048] = "";
    snprintf(cmd, sizeof cmd, "%s/cranesim serve --listen 127.0.0.1:0 --model %s %s 2>&1 >/dev/null; echo \"exit $?\"",
             CRANESIM_BINARY_DIR, MODEL, args);
    FILE* p = popen(cmd, "r");
    size_t n = p ? fread(out, 1, sizeof out - 1, p) : 0;
    out[n] = 0;
    if (p) pclose(p);
    int lines = 0;
    for (const char* q = out; *q; ++q) lines += *q == '\n';
    printf("serve %s: %s", args, out);
    CHECK(strstr(out, want) && strstr(out, "exit 2") && lines == 2, "serve %s: want '%s' in one line, exit 2; got %s",
          args, want, out);
}

int main(void) {
    signal(SIGPIPE, SIG_IGN);
    served_chain();
    served_loader10();
    refused("--mechanics lagrange",
            "the serve protocol: chain_8fn_10link.json: the stepped lagrange engine for this crane chain (8 "
            "functions) has no picture for the renderer yet");
    // The 8-function chain has no rating (mechanics.rated_moment): a limiter
    // asked for by name is refused for that, not for being a chain.
    refused("--rcl on", "cranesim serve: --rcl on: chain_8fn_10link.json: rated capacity limiter: "
                       "mechanics.rated_moment [kN m] is missing; a crane chain's limiter needs the maker's rating");
    served_loader10_rcl();
    TEST_MAIN_END();
}
