// cmd_drive.c: `cranesim drive`: the real-time simulator.
//
// With a display (and the render module built) it opens the 3D window. Without
// one, or when no window opens on the display the environment names, it runs
// the same real-time loop headless on a scripted operator input, paced to
// wall time, and reports what it did: simulated time, real-time factor
// capacity, missed frame deadlines, and where the record went. Every option
// is checked before any of that, whichever mode follows.
#include "app.h"
#include "engine.h"
#include "session.h"
#include "world_desc.h"
#ifdef CRANESIM_HAVE_RENDER
#include "drive_session.h"
#include "render.h"
#endif

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include "rcl.h"
#include <string.h>
#include <time.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void drive_help(FILE* f) {
    fprintf(f,
            "usage: cranesim drive [--model M] [--world W] [--headless] [--duration T] [--record FILE.csv]\n"
            "\n"
            "Drive the crane in real time, by default in the sandbox world (truck, terrain, hook,\n"
            "loads, obstacles; --world validation for the column and booms alone, --mechanics\n"
            "lagrange for the bare 2-DOF crane). With a display: a 3D window, joystick or keyboard.\n"
            "Without a display, or when the window cannot open (or with --headless): the same\n"
            "real-time loop driven by a scripted operator (assets/scenarios/sandbox_pick_place.json\n"
            "in the sandbox, drive_demo.json otherwise), paced to wall time.\n"
            "\n"
            "options:\n"
            "  --headless          no window, even if a display is available\n"
            "  --duration T        seconds to drive (headless default: the scenario's; window: until Esc)\n"
            "  --record FILE.csv   record every frame to CSV (default: no record); headless, SIGINT or\n"
            "                      SIGTERM stop the drive with the record kept (exit 130, 143)\n"
            "  --frame-rate F      headless: command updates per second (default 75, the paper's rate);\n"
            "                      window: frame-rate cap (default 65)\n"
            "  --scripted          window: drive by the scenario's commands instead of the devices\n"
            "  --session FILE      record the operator's input stream (commands per update, hook\n"
            "                      events, model, settings, start) for cranesim replay (docs/replay.md)\n"
            "  --replay SESSION    window: drive by a recorded session's commands instead of the devices\n"
            "  --rcl on|off        the rated capacity limiter (default on): warns at 90 %% of the load\n"
            "                      chart, at 100 %% stops the motions that carry the load outwards and\n"
            "                      slewing towards a weaker sector (docs/safety.md); with --replay the\n"
            "                      default is the session's setting; with --connect the server's limiter acts\n"
            "  --mapping FILE      input mapping by function (JSON, see docs/render.md)\n"
            "  --charts LIST       strip-chart channels, CSV column names (up to 8), e.g.\n"
            "                      p1A,p1B,x1,u1,F1 (default: pressures, strokes, spools), or the\n"
            "                      circuit's channels: NODE.p, VALVE.spool, VALVE.qA/.qB, COMPONENT.q,\n"
            "                      and the other component states: PUMP.disp, COMPENSATOR.spool,\n"
            "                      COUNTERBALANCE.spool, ACCUMULATOR.oil (lift_cyl.A.p, pump_line.p,\n"
            "                      lift_valve.qA, pump.q, lift_comp.spool; docs/render.md)\n"
            "  --readouts LIST     window: HUD readouts of these channels (names as --charts, up to 8),\n"
            "                      in display units (MPa, L/min, mm), under the fixed ones\n"
            "  --screenshot FILE   save a PNG of the view at --screenshot-at seconds and stop\n"
            "                      (offscreen when there is no display)\n"
            "  --screenshot-at T   simulated time of the screenshot [s] (default 2)\n"
            "  --collision-view    window: start with the collision shapes drawn over the scene\n"
            "                      (what the physics hits; G toggles it)\n"
            "  --connect HOST:PORT drive a remote `cranesim serve` (docs/protocol.md): the window draws\n"
            "                      its crane with this drive's scene, HUD and charts (link, frames lost and\n"
            "                      latency top right) and sends the sticks; --screenshot works as locally;\n"
            "                      headless: the scripted operator for --duration s of wall time (default\n"
            "                      10); both reconnect when the link drops\n"
            "  --save-as FILE      window: the panel's \"save model\" writes FILE (default: a new\n"
            "                      cranesim_model_N.json each time, never an existing file)\n"
            "  --size WxH          window size in pixels (default 1280x720)\n"
            "  --scenario S         the scripted operator: a scenario JSON file or a name in\n"
            "                       assets/scenarios (default sandbox_pick_place in the sandbox,\n"
            "                       drive_demo otherwise)\n"
            "  --mechanics M        ode (default: the 3D world) or lagrange (analytic 2-DOF)\n"
            "  --world W            ode: world file or name: sandbox (default), validation\n");
    // The common options less those whose drive defaults differ (above)
    // and --duration (drive's own, above) and --every (not for drive).
    const unsigned all = APP_GIVEN(APP_OPT_COUNT) - 1u;
    app_options_help(f, all & ~(APP_GIVEN(APP_OPT_SCENARIO) | APP_GIVEN(APP_OPT_MECHANICS) | APP_GIVEN(APP_OPT_WORLD) |
                                APP_GIVEN(APP_OPT_DURATION) | APP_GIVEN(APP_OPT_EVERY)));
    // Keys last: they are what an operator looks up while the window is open.
    fprintf(f,
            "(--solver cvode and --every do not apply to drive: it steps in real time and records one\n"
            "row per command update)\n"
            "keys: arrows = lift, W/S = jib, A/D = slew, H = hook, Tab = parameter panel, P = pause, R = reset,\n"
            "      C / F1..F4 = camera, G = collision shapes, F5 = record CSV, F12 = screenshot, Esc = quit\n"
            "      (in the parameter panel Esc only leaves the panel; with panel changes not saved, Esc twice);\n"
            "      hold Shift for fine mode (the keys command 25 %% of full opening)\n");
}

static void sleep_until(double wall) {
    double now = sim_wall_time();
    if (wall <= now) return;
    double d = wall - now;
    struct timespec ts = {(time_t)d, (long)((d - floor(d)) * 1e9)};
    nanosleep(&ts, NULL);
}

// A display the environment names and that can exist: DISPLAY (an X server,
// perhaps remote, so only SDL can tell whether it answers), or
// WAYLAND_DISPLAY naming a socket that is there. Otherwise false, with why
// in one line.
// A display a window could open on (render_display_available); a build
// without the render module has none.
static bool have_display(char* why, size_t n) {
#ifdef CRANESIM_HAVE_RENDER
    return render_display_available(why, n);
#else
    snprintf(why, n, "this build has no window (the render module was not built)");
    return false;
#endif
}

// The ode world's kind and name, from its file. Returns the kind, or -1
// with the loader's one-line message.
static int world_info(const app_common* c, char* name, size_t n, char* err, size_t errsz) {
    char buf[512];
    const char* path = sim_world_path(c->sim.world ? c->sim.world : "sandbox", buf, sizeof buf);
    world_desc* wd = malloc(sizeof *wd); // large (fixed arrays of loads, obstacles)
    if (!wd) {
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    int kind = -1;
    if (world_desc_load(path, wd, err, errsz) == 0) {
        kind = (int)wd->kind;
        snprintf(name, n, "%s", wd->name[0] ? wd->name : world_kind_name(wd->kind));
        world_desc_free(wd);
    }
    free(wd);
    return kind;
}

// What the world has, so the report says only that.
typedef struct drive_world {
    bool hook;        // a hook to attach loads (sandbox)
    bool noted;       // said once that a hook event had nothing to act on
    bool noted_empty; // said once that a release found nothing on the hook
    int held;         // the load on the hook, -1: none (only the scenario works the hook here)
    session_writer* sess; // the session file, or NULL
} drive_world;

// Say what the scripted operator's hook did, and only that: a load picked
// up or let go by name; a release with nothing on the hook once.
static void report_hook(void* user, engine* l, int attach, int got) {
    drive_world* dw = user;
    if (dw->sess) session_writer_hook(dw->sess, attach);
    if (!dw->hook) {
        if (!dw->noted) printf("  (the scenario's hook events are ignored: this world has no hook)\n");
        dw->noted = true;
        return;
    }
    double mass = 0;
    const double t = engine_time(l);
    if (attach) {
        const char* name = got >= 0 ? engine_load_name(l, got, &mass) : NULL;
        if (got >= 0 && got == dw->held) return; // already on the hook: nothing happened
        if (name) printf("  t = %5.2f s: hook picked up %s (%.0f kg)\n", t, name, mass);
        else printf("  t = %5.2f s: hook found no load in reach\n", t);
        dw->held = got;
    } else if (dw->held >= 0) {
        const char* name = engine_load_name(l, dw->held, &mass);
        printf("  t = %5.2f s: hook released %s (%.0f kg)\n", t, name ? name : "its load", mass);
        dw->held = -1;
    } else if (!dw->noted_empty) {
        printf("  t = %5.2f s: the scenario releases the hook with nothing on it (said once)\n", t);
        dw->noted_empty = true;
    }
}

// One CSV row; false (errno kept) when the stream has failed.
static bool write_row(FILE* f, const double* row, int ncol) {
    errno = 0;
    sim_csv_row(f, row, ncol);
    return !ferror(f);
}


// The CSV header of engine l's row: its channels by name (a chain engine's
// are the backend's, then the chain's, as a scripted run's CSV).
static void write_header(FILE* f, const engine* l) {
    int n;
    const sim_channel* ch = engine_channels(l, &n);
    for (int k = 0; k < n; ++k) fprintf(f, "%s%s", k ? "," : "", ch[k].name);
    fputc('\n', f);
}

// The final strokes of a chain engine: every actuator's x_<name> column
// [mm]; the two-link chain (--variant general) has none: its first two
// actuators' base columns x1, x2.
static void print_chain_strokes(const engine* l, const model* m, const double* row) {
    int n;
    const sim_channel* ch = engine_channels(l, &n);
    printf("  final: strokes");
    const char* sep = " ";
    for (int k = SIM_NCOL_BASE; k < n; ++k)
        if (!strncmp(ch[k].name, "x_", 2)) {
            printf("%s%s %.0f mm", sep, ch[k].name + 2, row[k] * 1e3);
            sep = ", ";
        }
    for (int k = 0; k < 2 && k < m->chain.nact && !strcmp(sep, " "); ++k)
        printf("%s%s %.0f mm", k ? ", " : " ", m->chain.act[k].name, row[k ? COL_X2 : COL_X1] * 1e3);
    printf("; tip at reach %.2f m, height %.2f m from the first boom's joint", row[COL_TIP_X], row[COL_TIP_Z]);
}

static int drive_headless(app_common* c, double frame_rate, const char* record, const char* session_path,
                          const char* why, int kind, const char* world_name, bool rcl_given) {
    model* m;
    scenario sc;
    const bool world = app_backend(&c->sim)->world;
    if (!c->scenario_path) c->scenario_path = app_default_drive_scenario(&c->sim);
    int rc = app_load(c, &m, &sc);
    if (rc) return rc;
    app_note_scenario_slew("drive", &c->sim, m, &sc, kind);
    double duration = c->sim.duration > 0 ? c->sim.duration : sc.duration;
    // At most SIM_MAX_DURATION (the option is capped by app_parse_common, a
    // scenario's here) at <= 1000 frames/s: at most 1e9 frames, counted in a long.
    if (!(duration > 0) || duration > SIM_MAX_DURATION) {
        fprintf(stderr, "cranesim drive: %s: duration: expected a simulated time in s, 0 < T <= 1e6, got %g\n",
                sc.name, duration);
        model_free(m);
        return EXIT_USAGE;
    }
    char err[512];
    // The session keeps the model as loaded: a replay adds the bursts itself.
    cJSON* doc0 = session_path ? cJSON_Duplicate(m->json, 1) : NULL;
    if (sc.nfault) { // bursts need their orifices in the circuit (engine_fault_model)
        model* fm = engine_fault_model(m, &sc, err, sizeof err);
        model_free(m);
        if (!fm) {
            fprintf(stderr, "cranesim drive: %s\n", err);
            cJSON_Delete(doc0);
            return EXIT_USAGE;
        }
        m = fm;
    }
    double m3 = sim_load_mass(m, &sc, &c->sim);
    // A crane chain drives headless by function, and its session records
    // the commands by function (session.h); a limiter asked for by name is
    // refused before anything starts (rcl.h refuses chains; on by default,
    // it is then off with a note below).
    engine* l = NULL;
    if (rcl_given && c->sim.rcl &&
               engine_require(m, &c->sim, ENGINE_CAP_LIMITER, "--rcl on", err, sizeof err)) {
    } else {
        l = engine_create(m, &c->sim, sc.q0, sc.slew0, m3, err, sizeof err);
    }
    if (!l) {
        fprintf(stderr, "cranesim drive: %s\n", err);
        model_free(m);
        cJSON_Delete(doc0);
        return EXIT_USAGE;
    }
    // Replaces a previous record only when the drive ends (app_out). No
    // --record, no file: a Quick-start drive leaves nothing in the folder it
    // was started from.
    app_out rec = {.f = NULL};
    FILE* f = record ? app_out_open(&rec, record, "w") : NULL;
    if (record && !f) {
        fprintf(stderr, "cranesim drive: cannot write %s: %s\n", record, strerror(errno));
        cJSON_Delete(doc0);
        engine_destroy(l);
        model_free(m);
        return EXIT_USAGE;
    }
    const int ncol = engine_ncol(l);
    // The session: what replay runs again (docs/replay.md). The scenario goes
    // in only for its faults, which the replay applies at the same ticks.
    session_writer sw = {.f = NULL};
    if (session_path) {
        char sbuf[512];
        const char* sp = app_scenario_path(c->scenario_path, sbuf, sizeof sbuf);
        const int so = session_writer_open(&sw, session_path, doc0, m->file, l, &c->sim, sc.nfault ? sp : NULL, sc.q0,
                                           sc.slew0, m3, false, ncol, err, sizeof err);
        cJSON_Delete(doc0);
        if (so) {
            fprintf(stderr, "cranesim drive: --session: %s\n", err);
            app_out_close(&rec, 0, false);
            engine_destroy(l);
            model_free(m);
            return EXIT_USAGE;
        }
    }
    // The sandbox has the truck, the slew and the hook; loads only if its
    // file has some. The validation world and the lagrange view have none.
    const bool sandbox = world && kind == WORLD_SANDBOX;
    const bool loads = sandbox && engine_load_name(l, 0, NULL) != NULL;
    drive_world dw = {.hook = sandbox, .held = -1, .sess = session_path ? &sw : NULL};
    int wr = 0; // errno of the first failed write to the record
    const bool two_link = engine_caps(l) & ENGINE_CAP_TWO_LINK, limiter = engine_rcl(l) != NULL;
    const int nfn = engine_nfunction(l);
    if (f && two_link) sim_csv_header(f, ncol);
    else if (f) write_header(f, l);
    if (f && ferror(f)) wr = errno ? errno : EIO;
    printf("cranesim drive: %s: driving %s headless in real time for %.1f s\n", why, m->name, duration);
    char nowhere[96];
    // The backend's crane where it has no world is its two-link one; a
    // chain engine says what it runs instead.
    if (two_link) snprintf(nowhere, sizeof nowhere, "%s (no world)", app_backend(&c->sim)->crane);
    else snprintf(nowhere, sizeof nowhere, "%s crane chain of %d functions (no world)", engine_backend_name(l), nfn);
    printf("  world: %s; operator input: scripted (%s), %.0f commands/s; hydraulics %s at h = %g ms\n",
           world ? world_name : nowhere, sc.name, frame_rate, hyd_method_name(c->sim.solver),
           c->sim.h * 1e3);
    const double frame = 1.0 / frame_rate;
    const long nframes = (long)ceil(duration * frame_rate - 1e-9);
    double w0 = sim_wall_time(), busy = 0, worst = 0;
    int missed = 0, code = 0, ev = 0, frames_done = 0;
    double rcl_max = 0, rcl_t90 = 0; // the limiter's utilisation [-] and the time at or above 90 % [s]
    if (!limiter && c->sim.rcl) {
        // Why: the chain's allow-list (rcl_check_model), else its chart failed.
        char why[400] = "its chart could not be made";
        rcl_check_model(m, why, sizeof why);
        printf("  rated capacity limiter: none for this crane chain (%s; rcl_util not measured; --rcl off silences "
               "this)\n",
               why);
    }
    // A row of engine_ncol columns (a chain engine's are more than
    // SIM_NCOL), and the commands by function.
    double* row = calloc((size_t)(ncol > SIM_NCOL ? ncol : SIM_NCOL), sizeof *row);
    double* uf = calloc((size_t)nfn + 1, sizeof *uf);
    if (!row || !uf) {
        fprintf(stderr, "cranesim drive: out of memory\n");
        free(row);
        free(uf);
        app_out_close(&rec, 0, false);
        engine_destroy(l);
        model_free(m);
        return EXIT_RUNTIME;
    }
    engine_row(l, row);
    // As in run: the first signal stops the loop, a second kills at once.
    app_signals sig;
    app_signals_catch(&sig);
    for (long i = 0; i < nframes && !wr && !app_signal_caught(); ++i) {
        double ws = sim_wall_time();
        double t = engine_time(l);
        // The operator's stick positions at the middle of this frame.
        const double tm = t + 0.5 * frame;
        double u[3] = {0, 0, 0};
        if (two_link) {
            engine_play(l, &sc, tm, &ev, u, report_hook, &dw);
            engine_set_commands(l, u);
        } else {
            engine_play_functions(l, &sc, tm, &ev, uf, report_hook, &dw);
            engine_set_function_commands(l, uf, nfn, NULL, 0);
        }
        // Advance to the frame's end on the simulated clock (the ode world
        // steps whole ODE steps, so aim at the target, not at +frame).
        const double target = (i + 1) * frame;
        if (engine_advance(l, target - engine_time(l))) {
            session_writer_tick(&sw, tm, target, two_link ? u : uf, two_link ? 3 : nfn, NULL, ncol);
            if (!c->quiet) app_progress_done();
            if (record) fprintf(stderr, "cranesim drive: %s; record kept in %s\n", engine_error(l), record);
            else fprintf(stderr, "cranesim drive: %s\n", engine_error(l));
            code = EXIT_RUNTIME;
            break;
        }
        engine_row(l, row);
        session_writer_tick(&sw, tm, target, two_link ? u : uf, two_link ? 3 : nfn, row, ncol);
        if (limiter) { // the limiter's own reading: a chain's rows may have no rcl_util column
            const double ut = engine_rcl(l)->util;
            if (ut >= RCL_WARN) rcl_t90 += frame;
            rcl_max = fmax(rcl_max, ut);
        }
        // A record that cannot be written stops the run: driving on would
        // only lose more of it.
        if (f && !write_row(f, row, ncol)) {
            wr = errno ? errno : EIO;
            break;
        }
        ++frames_done;
        double we = sim_wall_time();
        busy += we - ws;
        worst = fmax(worst, we - ws);
        // A deadline is missed when the frame's work ends after its slot.
        if (we > w0 + (i + 1) * frame) ++missed;
        if (!c->quiet) app_progress(NULL, engine_time(l), duration);
        sleep_until(w0 + (i + 1) * frame);
    }
    if (!c->quiet) app_progress_done();
    app_signals_restore(&sig);
    if (app_signal_caught() && !code) {
        fprintf(stderr, "cranesim drive: interrupted (%s) at t = %.6g s%s%s\n", app_signal_name(app_signal_caught()),
                engine_time(l), record ? "; record kept in " : "", record ? record : "");
        code = 128 + app_signal_caught();
    }
    if (!code) {
        char note[320];
        engine_note(l, note, sizeof note);
        if (note[0]) fprintf(stderr, "cranesim drive: note: %s\n", note);
    }
    wr = app_out_close(&rec, wr, true);
    if (session_path) {
        char why_end[96];
        if (code) snprintf(why_end, sizeof why_end, "stopped at t = %.6g s (exit %d)", engine_time(l), code);
        else snprintf(why_end, sizeof why_end, "completed at t = %.6g s", engine_time(l));
        const int se = session_writer_close(&sw, why_end);
        if (se) {
            fprintf(stderr, "cranesim drive: cannot write %s: %s\n", session_path, strerror(se));
            if (!code) code = EXIT_RUNTIME;
        } else {
            printf("  session -> %s (%ld rows; cranesim replay %s runs it again)\n", session_path, sw.rows,
                   session_path);
        }
    }
    if (wr) {
        fprintf(stderr, "cranesim drive: cannot write %s: %s\n", record, strerror(wr));
        code = EXIT_RUNTIME;
    }
    double wall = sim_wall_time() - w0;
    char speed[32];
    printf("  simulated %.2f s in %.2f s wall; physics busy %.1f %% of the time: capacity %sx real time\n",
           engine_time(l), wall, wall > 0 ? 100 * busy / wall : 0.0,
           app_fmt_speed(speed, sizeof speed, busy > 0 ? engine_time(l) / busy : 0.0));
    printf("  frames: %d of %.1f ms, worst frame %.2f ms, missed deadlines %d\n", frames_done, frame * 1e3,
           worst * 1e3, missed);
    if (two_link)
        printf("  final: lift stroke %.0f mm, jib stroke %.0f mm, tip at reach %.2f m, height %.2f m",
               row[COL_X1] * 1e3, row[COL_X2] * 1e3, row[COL_TIP_X], row[COL_TIP_Z]);
    else print_chain_strokes(l, m, row);
    if (sandbox) printf("; slew %.1f deg", row[COL_SLEW] * 180 / M_PI);
    if (loads) printf("; load at (%.2f, %.2f, %.2f) m", row[COL_LOAD_X], row[COL_LOAD_Y], row[COL_LOAD_Z]);
    if (sandbox) printf("; truck tilt %.2f deg", row[COL_TRUCK_TILT] * 180 / M_PI);
    if (!sandbox && m3 > 0) printf("; %.0f kg at the tip", m3);
    printf("\n");
    if (limiter)
        printf("  rated capacity limiter %s: utilisation max %.0f %%, %.2f s at or above 90 %%\n",
               c->sim.rcl ? "on" : "off (measuring only)", 100 * rcl_max, rcl_t90);
    // As a scripted run's metrics line counts them (the sandbox only).
    const sim_collisions* coll = engine_collisions(l);
    if (coll) {
        char t[SIM_COLL_TEXT];
        sim_collisions_text(coll, t, sizeof t);
        printf("  %s\n", t);
    }
    if (!wr && record)
        printf("  record -> %s (%d rows); for the 3D window run it on a machine with a display\n", record,
               frames_done);
    else if (!wr)
        printf("  no record (--record FILE.csv writes one); for the 3D window run it on a machine with a "
               "display\n");
    engine_destroy(l);
    model_free(m);
    free(row);
    free(uf);
    return code;
}

int cmd_drive(int argc, char** argv) {
    app_common c = {.sim = sim_default_opts()};
    // drive's default: the backend with a world, in its drive world (the sandbox)
    app_use_backend(&c.sim, engine_backend_with_world() ? engine_backend_with_world() : engine_backend_default());
    c.sim.rcl = true;          // the rated capacity limiter, unless --rcl off
    bool headless = false, scripted = false, rate_given = false, rcl_given = false;
    double frame_rate = 75.0, shot_at = 2.0;
    const char* record = NULL;
    const char* session_path = NULL;
    const char* replay = NULL;
    const char* shot = NULL;
    const char* mapping = NULL;
    const char* charts = NULL;
    const char* readouts = NULL;
    const char* save_as = NULL;
    bool collision_view = false;
    const char* connect_to = NULL;
    int width = 1280, height = 720;
    bool size_given = false, shot_at_given = false; // for the headless note
    for (int i = 0; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            drive_help(stdout);
            return 0;
        }
        if (!strcmp(argv[i], "--every")) {
            // A common option drive would otherwise take and ignore.
            fprintf(stderr, "cranesim drive: --every: drive records one row per command update (use --frame-rate)\n");
            return EXIT_USAGE;
        }
        int rc = app_parse_common(&c, argc, argv, &i);
        if (rc < 0) return EXIT_USAGE;
        if (rc > 0) continue;
        if (!strcmp(argv[i], "--headless")) {
            headless = true;
            continue;
        }
        if (!strcmp(argv[i], "--record") && i + 1 < argc) {
            record = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--session") && i + 1 < argc) {
            session_path = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--replay") && i + 1 < argc) {
            replay = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--scripted")) {
            scripted = true;
            continue;
        }
        if (!strcmp(argv[i], "--charts") && i + 1 < argc) {
            charts = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--readouts") && i + 1 < argc) {
            readouts = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--mapping") && i + 1 < argc) {
            mapping = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--connect") && i + 1 < argc) {
            connect_to = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--save-as") && i + 1 < argc) {
            save_as = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--collision-view")) {
            collision_view = true;
            continue;
        }
        if (!strcmp(argv[i], "--screenshot") && i + 1 < argc) {
            shot = argv[++i];
            continue;
        }
        if (!strcmp(argv[i], "--screenshot-at") && i + 1 < argc) {
            shot_at_given = true;
            // Capped like --duration: a simulated time, compared and counted
            // against the run's.
            if (app_parse_double(argv[++i], &shot_at) || shot_at < 0 || shot_at > SIM_MAX_DURATION) {
                fprintf(stderr, "cranesim drive: --screenshot-at: expected a time in s, 0 <= T <= 1e6, got '%s'\n",
                        argv[i]);
                return EXIT_USAGE;
            }
            continue;
        }
        if (!strcmp(argv[i], "--size") && i + 1 < argc) {
            size_given = true;
            if (sscanf(argv[++i], "%dx%d", &width, &height) != 2 || width < 64 || height < 64 || width > 8192 ||
                height > 8192) {
                fprintf(stderr, "cranesim drive: --size: expected WxH like 1280x720, got '%s'\n", argv[i]);
                return EXIT_USAGE;
            }
            continue;
        }
        if (!strcmp(argv[i], "--frame-rate") && i + 1 < argc) {
            rate_given = true;
            if (app_parse_double(argv[++i], &frame_rate) || frame_rate < 10 || frame_rate > 1000) {
                fprintf(stderr, "cranesim drive: --frame-rate: expected 10..1000 frames/s, got '%s'\n", argv[i]);
                return EXIT_USAGE;
            }
            continue;
        }
        if (!strcmp(argv[i], "--rcl") && i + 1 < argc) {
            const char* v = argv[++i];
            if (strcmp(v, "on") && strcmp(v, "off")) {
                fprintf(stderr, "cranesim drive: --rcl: expected on or off, got '%s'\n", v);
                return EXIT_USAGE;
            }
            c.sim.rcl = !strcmp(v, "on");
            rcl_given = true;
            continue;
        }
        fprintf(stderr, "cranesim drive: unknown option '%s' (see cranesim drive --help)\n", argv[i]);
        return EXIT_USAGE;
    }
    if (replay && session_path) {
        fprintf(stderr, "cranesim drive: --session: a replay records no session\n");
        return EXIT_USAGE;
    }
    // Every option is checked before anything runs, whichever mode follows:
    // an option accepted in one mode and ignored in another would hide a
    // mistake until the other mode is used.
    if ((record && app_check_output("drive", "--record", record, NULL)) ||
        (session_path && app_check_output("drive", "--session", session_path, NULL)) ||
        (shot && app_check_output("drive", "--screenshot", shot, ".png")) ||
        (save_as && app_check_output("drive", "--save-as", save_as, ".json")) ||
        app_check_distinct("drive", (const char* const[]){"--record", "--session", "--screenshot", "--save-as", "--replay"},
                           (const char* const[]){record, session_path, shot, save_as, replay}, 5))
        return EXIT_USAGE;
    // A session that is not there is the first thing wrong, before any word
    // on the window it would play in.
    if (replay) {
        FILE* rf = fopen(replay, "rb");
        if (!rf) {
            fprintf(stderr, "cranesim drive: --replay %s: cannot read: %s\n", replay, strerror(errno));
            return EXIT_USAGE;
        }
        fclose(rf);
    }
#ifdef CRANESIM_HAVE_RENDER
    // The window's options, the same for a local drive and a remote one.
    drive_opts win = drive_default_opts();
    win.width = width;
    win.height = height;
    if (rate_given) win.fps_cap = frame_rate;
    win.mapping_file = mapping;
    win.charts = charts;
    win.readouts = readouts;
    win.record_path = record;
#endif
    if (connect_to) { // the visual computer's link to a cranesim serve (docs/protocol.md)
        if (replay || session_path || save_as) {
            fprintf(stderr, "cranesim drive: --connect: %s applies to a local drive only\n",
                    replay ? "--replay" : session_path ? "--session" : "--save-as");
            return EXIT_USAGE;
        }
        // The limiter that acts is the server's (its --rcl): a local one
        // would filter nothing the server steps.
        if (rcl_given) {
            fprintf(stderr, "cranesim drive: --connect: --rcl: the rated capacity limiter is the server's (cranesim "
                            "serve --rcl on|off); the HUD shows its state\n");
            return EXIT_USAGE;
        }
        char cwhy[700];
        const bool cdisplay = !headless && have_display(cwhy, sizeof cwhy);
#ifdef CRANESIM_HAVE_RENDER
        if (!headless && (cdisplay || shot)) {
            // The window (or an offscreen view for a screenshot) draws the
            // remote crane with the local drive's scene, HUD and charts.
            drive_opts o = win; // the local drive's window options, for the remote crane
            o.offscreen = !cdisplay;
            o.scripted = scripted || o.offscreen;
            char err[600];
            if (app_backend(&c.sim)->world && !c.sim.world) c.sim.world = app_backend(&c.sim)->drive_world;
            int rc = drive_opts_check(&c, &o, err, sizeof err);
            if (rc) {
                fprintf(stderr, "cranesim drive: %s\n", err);
                return rc;
            }
            char nowin[512];
            rc = drive_connect_window(&c, &o, connect_to, c.sim.duration, shot, shot_at, nowin, sizeof nowin);
            if (rc != DRIVE_NO_WINDOW) return rc;
            if (shot) {
                o.offscreen = true;
                o.scripted = true;
                rc = drive_connect_window(&c, &o, connect_to, c.sim.duration, shot, shot_at, nowin, sizeof nowin);
                if (rc == DRIVE_NO_WINDOW) {
                    fprintf(stderr, "cranesim drive: %s\n", nowin);
                    return EXIT_RUNTIME;
                }
                return rc;
            }
            printf("cranesim drive: %s: the link runs headless\n", strncmp(nowin, "render: ", 8) ? nowin : nowin + 8);
        }
#else
        (void)cdisplay;
        if (shot) {
            fprintf(stderr, "cranesim drive: --screenshot needs the render module (built without SDL2/GL)\n");
            return EXIT_USAGE;
        }
#endif
        if (!c.scenario_path) c.scenario_path = APP_DEMO_SCENARIO;
        model* m;
        scenario sc;
        int rc = app_load(&c, &m, &sc);
        if (rc) return rc;
        model_free(m);
        printf("cranesim drive: --connect %s: headless link (scripted operator %s)\n", connect_to, sc.name);
        return drive_connect(connect_to, &sc, c.sim.duration > 0 ? c.sim.duration : 10.0, c.sets, c.nset);
    }
    // drive's ode world is the sandbox unless --world says otherwise (run's
    // is the validation world): name it, so the checks see the same world.
    const engine_backend* be = app_backend(&c.sim);
    if (be->world && !c.sim.world) c.sim.world = be->drive_world;
    if (app_check_sim("drive", &c.sim, c.given)) return EXIT_USAGE;
    app_note_unused("drive", c.given, &c.sim, 1);
    app_settle_unused(&c.sim);
    char err[600], wname[64] = "";
    int kind = -1;
    if (be->world) {
        kind = world_info(&c, wname, sizeof wname, err, sizeof err);
        if (kind < 0) {
            fprintf(stderr, "cranesim drive: %s\n", err);
            return EXIT_USAGE;
        }
        // The validation world has no hook, loads or slew: its scripted
        // operator is the 2-DOF demo (lift and jib), not the pick-and-place.
        if (!c.scenario_path && kind == WORLD_VALIDATION) c.scenario_path = APP_DEMO_SCENARIO;
    }
    char why[700];
    const bool display = have_display(why, sizeof why);
    if (headless) snprintf(why, sizeof why, "--headless");
#ifdef CRANESIM_HAVE_RENDER
    drive_opts o = win;
    o.session_path = session_path;
    o.replay_path = replay;
    o.replay_rcl = replay && rcl_given ? c.sim.rcl : -1;
    o.save_as = save_as;
    o.collision_view = collision_view;
    o.world_name = be->world ? wname : NULL;
    int rc = drive_opts_check(&c, &o, err, sizeof err);
    if (rc) {
        fprintf(stderr, "cranesim drive: %s\n", err);
        return rc;
    }
    // A window when there is a display; an offscreen view when only a
    // screenshot is wanted; else the headless loop below.
    if (!headless && (display || shot)) {
        // A limiter asked for by name that the engine for this model does
        // not have (a crane chain's, until it has one) is refused, as the
        // headless drive refuses it; on by default, the window goes without.
        if (rcl_given && c.sim.rcl) {
            char me[400];
            model* rm = model_load(c.model_path, c.sets, c.nset, me, sizeof me);
            const int miss = rm && engine_require(rm, &c.sim, ENGINE_CAP_LIMITER, "--rcl on", err, sizeof err);
            model_free(rm);
            if (miss) {
                fprintf(stderr, "cranesim drive: %s\n", err);
                return EXIT_USAGE;
            }
        }
        o.offscreen = !display;
        o.scripted = scripted || o.offscreen;
        char nowin[512];
        rc = drive_window_main(&c, &o, c.sim.duration, shot, shot_at, nowin, sizeof nowin);
        if (rc != DRIVE_NO_WINDOW) return rc;
        // The display is named but no window opens on it (no X server
        // there, or SDL only found a driver with no screen). A window nobody
        // sees would be a session nobody drives: do what no display does.
        const char* reason = strncmp(nowin, "render: ", 8) ? nowin : nowin + 8;
        if (!shot) {
            snprintf(why, sizeof why, "%s", reason);
        } else {
            printf("cranesim drive: %s: rendering offscreen\n", reason);
            o.offscreen = true;
            o.scripted = true;
            rc = drive_window_main(&c, &o, c.sim.duration, shot, shot_at, nowin, sizeof nowin);
            if (rc == DRIVE_NO_WINDOW) {
                fprintf(stderr, "cranesim drive: %s\n", nowin);
                return EXIT_RUNTIME;
            }
            return rc;
        }
    }
#else
    (void)scripted, (void)width, (void)height, (void)shot_at, (void)rate_given;
    // Without the render module these options have nothing to act on.
    const char* needs = shot ? "--screenshot" : mapping ? "--mapping" : charts ? "--charts" : readouts ? "--readouts"
                        : collision_view ? "--collision-view" : NULL;
    if (needs) {
        fprintf(stderr, "cranesim drive: %s needs the render module (built without SDL2/GL)\n", needs);
        return EXIT_USAGE;
    }
    if (c.sim.cvode) {
        fprintf(stderr, "cranesim drive: --solver cvode: drive steps the hydraulics in real time with the in-house "
                        "solvers: use krus, ros2, rk4, ros34pw2 or rodas3\n");
        return EXIT_USAGE;
    }
    if (!headless && display) snprintf(why, sizeof why, "this binary was built without the render module (CRANESIM_CORE_ONLY)");
#endif
    // The headless counterpart of the window's replay is its own command.
    if (replay) {
        fprintf(stderr, "cranesim drive: --replay %s: needs the 3D window, which is not open (%s): "
                        "cranesim replay %s runs it headless\n", replay, why, replay);
        return EXIT_USAGE;
    }
    // The headless run has no parameter panel, so nothing to save.
    if (save_as) fprintf(stderr, "cranesim drive: note: --save-as has no effect without the window (no parameter panel)\n");
    // The window's own options do nothing here: one note naming them (a
    // note, not an error, as for --save-as: the same command line works
    // with and without a display).
    {
        const struct {
            bool given;
            const char* name;
        } win[] = {{charts != NULL, "--charts"}, {readouts != NULL, "--readouts"}, {size_given, "--size"},
                   {mapping != NULL, "--mapping"}, {scripted, "--scripted"}, {collision_view, "--collision-view"},
                   {shot != NULL, "--screenshot"}, {shot_at_given, "--screenshot-at"}};
        char list[200] = "";
        size_t L = 0;
        int n = 0;
        for (size_t k = 0; k < sizeof win / sizeof win[0]; ++k)
            if (win[k].given && L < sizeof list)
                L += (size_t)snprintf(list + L, sizeof list - L, "%s%s", n++ ? ", " : "", win[k].name);
        if (n)
            fprintf(stderr, "cranesim drive: note: %s %s no effect headless (%s): %s only for the window\n", list,
                    n > 1 ? "have" : "has", why, n > 1 ? "they are" : "it is");
    }
    return drive_headless(&c, frame_rate, record, session_path, why, kind, wname, rcl_given);
}
