// test_malformed.c: a corpus of malformed model, scenario and world files.
// Each bad file is made at test time from a shipped file with one change
// (a --set style path assignment, or one text replacement), run through
// `cranesim run`, and must be refused with exit 2 and one line naming the
// file and the field, leaving an existing output file byte for byte as it
// was. Also: values outside the hard ranges of docs/files.md are refused
// with the range and the unit; outside the typical range, a one-line note;
// the shipped files give no note at all.
#include "check.h"
#include "cli_util.h"
#include "fixture_edit.h"
#include "json_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#define ASSETS CRANESIM_ASSETS

enum kind { MODEL, SCENARIO, WORLD, WORLD_LS };

typedef struct bad_case {
    enum kind kind;
    const char* name;  ///< file name of the generated file
    const char* base;  ///< shipped file it is made from (relative to assets/)
    const char* set;   ///< "path=value" applied with json_set_path, or NULL
    const char* from;  ///< text replaced in the shipped file (first occurrence), or NULL
    const char* to;    ///< replacement
    const char* field; ///< must appear in the message
    const char* msg;   ///< must appear in the message too (NULL: no check)
} bad_case;

// A section compensator of the LS crane as the file writes it (sec: "lift",
// "jib"), with the line break and indent before the next component: deleting
// it leaves the section valve's P on a node nothing feeds.
#define LS_COMP(sec)                                                                                                   \
    "{\n        \"name\": \"" sec "_comp\",\n        \"type\": \"compensator\",\n        \"inlet\": \"pump_line\",\n"     \
    "        \"outlet\": \"" sec "_P\",\n        \"load\": \"" sec "_ls\",\n        \"ref\": \"ls_line\",\n"              \
    "        \"area\": 3e-05,\n        \"setting\": 200000.0,\n        \"mode\": 1,\n        \"band\": 20000.0,\n"       \
    "        \"tau\": 0.02\n      },\n      "

// Cases that need a second text replacement after the first (a node declared,
// then wired in), by file name.
static const struct {
    const char *name, *from, *to;
} second_edit[] = {
    {"m_ls_orphan_out.json", "\"out\": \"lift_ls\",", "\"out\": \"lift_ls_orphan\","},
    {"m_ls_orphan_load.json", "\"load\": \"lift_ls\",", "\"load\": \"lift_ls_orphan\","},
    {"m_ls_no_comps.json", LS_COMP("jib"), ""},
};

static char out_buf[16384];



static const char* dir(void) {
    static char d[512];
    if (!d[0]) {
        snprintf(d, sizeof d, "%s/tests/app/malformed", CRANESIM_BINARY_DIR);
        mkdir(d, 0755);
    }
    return d;
}

// Make the bad file of case k; returns its path (static) or NULL.
static const char* make_case(const bad_case* k) {
    static char path[1024];
    char base[1024];
    snprintf(base, sizeof base, "%s/%s", ASSETS, k->base);
    snprintf(path, sizeof path, "%s/%s", dir(), k->name);
    if (fixture_edit(base, path, k->set, k->from, k->to)) return NULL;
    for (size_t i = 0; i < sizeof second_edit / sizeof second_edit[0]; ++i)
        if (!strcmp(k->name, second_edit[i].name) &&
            fixture_edit(path, path, NULL, second_edit[i].from, second_edit[i].to))
            return NULL;
    return path;
}

static const char SENTINEL[] = "t,x1\n0,0.5\nthis file must survive a refused run\n";

static void command_for(const bad_case* k, const char* file, const char* out, char* cmd, size_t n) {
    if (k->kind == MODEL)
        snprintf(cmd, n, "run --quiet --model %s --scenario hold --duration 0.01 --out %s", file, out);
    else if (k->kind == SCENARIO)
        snprintf(cmd, n, "run --quiet --scenario %s --duration 0.01 --out %s", file, out);
    else if (k->kind == WORLD_LS) // the LS slew section is only merged into an LS model's circuit
        snprintf(cmd, n,
                 "run --quiet --model %s/models/hiab031_ls.json --mechanics ode --world %s --scenario sandbox_swing "
                 "--duration 0.01 --out %s",
                 ASSETS, file, out);
    else if (strstr(k->base, "sandbox"))
        snprintf(cmd, n, "run --quiet --mechanics ode --world %s --scenario sandbox_swing --duration 0.01 --out %s",
                 file, out);
    else
        snprintf(cmd, n, "run --quiet --mechanics ode --world %s --scenario hold --duration 0.01 --out %s", file, out);
}

static void run_cases(const bad_case* cases, int n) {
    char out[1024];
    snprintf(out, sizeof out, "%s/out.csv", dir());
    for (int i = 0; i < n; ++i) {
        const bad_case* k = &cases[i];
        const char* file = make_case(k);
        CHECK(file != NULL, "%s: could not be made", k->name);
        if (!file) continue;
        cli_write_file(out, SENTINEL);
        char cmd[4096];
        command_for(k, file, out, cmd, sizeof cmd);
        int rc = cli_run(cmd, out_buf, sizeof out_buf);
        CHECK(rc == 2, "%s: exit %d, want 2: %s", k->name, rc, out_buf);
        CHECK(strstr(out_buf, k->name) != NULL, "%s: message does not name the file: %s", k->name, out_buf);
        CHECK(strstr(out_buf, k->field) != NULL, "%s: message does not name %s: %s", k->name, k->field, out_buf);
        CHECK(!k->msg || strstr(out_buf, k->msg), "%s: message lacks '%s': %s", k->name, k->msg, out_buf);
        CHECK(cli_count_lines(out_buf) == 1, "%s: want one line, got: %s", k->name, out_buf);
        char* now = fixture_read_all(out);
        CHECK(now && !strcmp(now, SENTINEL), "%s: the existing output file was changed", k->name);
        free(now);
    }
}

#define M "models/hiab031.json"
#define S "scenarios/ramp.json"
#define SB "scenarios/sandbox_swing.json"
#define SF "scenarios/hose_burst.json"
#define W "worlds/sandbox.json"
#define WV "worlds/validation.json"

// The cases of issue 13 that ran (or aborted in ODE) before the ranges.
static const bad_case range_cases[] = {
    {WORLD, "w_truck_mass.json", W, "truck.mass=1e308", NULL, NULL, "truck.mass", "must be in [100, 1e6] kg, got 1e308"},
    {WORLD, "w_load_size.json", W, "loads[0].size=[1e308, 1, 1]", NULL, NULL, "loads[0].size[0]", "must be in [0.01, 20] m"},
    {WORLD, "w_truck_far.json", W, "truck.position=[1e30, 0]", NULL, NULL, "truck.position", "must lie on the terrain"},
    {WORLD, "w_column_radius.json", W, "slew.column_radius=5", NULL, NULL, "slew.column_radius", "[0.02, 2] m"},
    {WORLD, "w_patch_key.json", W, NULL, "\"ls_shuttle.out\": \"ls_line_booms\"", "\"ls_shuttle\": \"ls_line_booms\"",
     "circuit_ls.patch.ls_shuttle", "expected \"component.field\""},
    {WORLD, "w_patch_value.json", W, NULL, "\"ls_shuttle.out\": \"ls_line_booms\"", "\"ls_shuttle.out\": 3",
     "circuit_ls.patch.ls_shuttle.out", "expected a node name"},
    {WORLD_LS, "w_patch_comp.json", W, NULL, "\"ls_shuttle.out\": \"ls_line_booms\"",
     "\"no_shuttle.out\": \"ls_line_booms\"", "circuit_ls.patch.no_shuttle.out", "no component no_shuttle"},
    {WORLD_LS, "w_patch_field.json", W, NULL, "\"ls_shuttle.out\": \"ls_line_booms\"",
     "\"ls_shuttle.margin\": \"ls_line_booms\"", "circuit_ls.patch.ls_shuttle.margin", "no port field margin"},
    {WORLD_LS, "w_ls_node.json", W, NULL, "\"b\": \"slew_ls\"", "\"b\": \"slew_lx\"", "circuit_ls", "slew_lx"},
    {MODEL, "m_link_mass.json", M, "mechanics.links[1].mass=1e-300", NULL, NULL, "mechanics.links[1].mass",
     "must be in [1, 1e5] kg, got 1e-300"},
    {MODEL, "m_p_crack.json", M, "hydraulics.components.main_relief.p_crack=22", NULL, NULL,
     "hydraulics.components[1].p_crack", "must be in [1e5, 1e8] Pa, got 22"},
    {MODEL, "m_bulk_low.json", M, "hydraulics.fluid.bulk_modulus=1", NULL, NULL, "hydraulics.fluid.bulk_modulus",
     "must be in [1e7, 1e10] Pa, got 1"},
    {MODEL, "m_bulk_high.json", M, "hydraulics.fluid.bulk_modulus=1e20", NULL, NULL, "hydraulics.fluid.bulk_modulus",
     "got 1e20"},
    {MODEL, "m_bore_huge.json", M, "hydraulics.components.lift_cyl.bore=1e300", NULL, NULL,
     "hydraulics.components[5].bore", "must be in [0.005, 1] m"},
    {MODEL, "m_tip_load.json", M, "mechanics.load_mass=1e5", NULL, NULL, "mechanics.load_mass", "[0, 1e4] kg"},
    {SCENARIO, "s_tip_load.json", S, "load_mass=1e5", NULL, NULL, "load_mass", "[0, 1e4] kg"},
};

static void test_hard_ranges(void) { run_cases(range_cases, (int)(sizeof range_cases / sizeof range_cases[0])); }

#define ML "models/hiab031_ls.json"

// A node "lift_ls_orphan" declared next to "lift_ls" (a second replacement
// wires a section's signal into it).
#define LS_ORPHAN_FROM "\"name\": \"lift_ls\","
#define LS_ORPHAN_TO                                                                                                   \
    "\"name\": \"lift_ls_orphan\", \"type\": \"volume\", \"volume\": 5e-06, \"p0\": 100000.0}, {\"name\": \"lift_ls\","

// Malformed load-sensing components in the LS crane model.
static const bad_case ls_cases[] = {
    {MODEL, "m_ls_no_port.json", ML, NULL, "\"ls\": \"ls_line\",", "", "hydraulics.components[0].ls",
     "missing required port"},
    {MODEL, "m_ls_margin.json", ML, "hydraulics.components.pump.margin=-2e6", NULL, NULL,
     "hydraulics.components[0].margin", "must be > 0, got -2e6"},
    {MODEL, "m_ls_pilot.json", ML, "hydraulics.components.lift_cbv.pilot_ratio=0", NULL, NULL,
     "hydraulics.components[8].pilot_ratio", "must be > 0, got 0"},
    {MODEL, "m_ls_mode.json", ML, "hydraulics.components.lift_comp.mode=2", NULL, NULL,
     "hydraulics.components[3].mode", NULL},
    // The main shuttle wired into the pump line: the LS line keeps only the
    // pump's sensing port, so no load pressure reaches the pump.
    {MODEL, "m_ls_unreached.json", ML, NULL, "\"out\": \"ls_line\"", "\"out\": \"pump_line\"",
     "hydraulics.components[0].ls", "the LS network does not reach the pump"},
    // A section whose LS signal ends in a node of its own: the pump's ls node
    // is still fed (by the main shuttle), but never by this section.
    {MODEL, "m_ls_orphan_out.json", ML, NULL, LS_ORPHAN_FROM, LS_ORPHAN_TO, "hydraulics.components[5].out",
     "node 'lift_ls_orphan' leads through no shuttle to the ls node 'ls_line'"},
    {MODEL, "m_ls_orphan_load.json", ML, NULL, LS_ORPHAN_FROM, LS_ORPHAN_TO, "hydraulics.components[3].load",
     "node 'lift_ls_orphan' leads through no shuttle"},
    {MODEL, "m_ls_comp_ref_tank.json", ML, NULL, "\"ref\": \"ls_line\",", "\"ref\": \"tank\",",
     "hydraulics.components[3].ref", "must be the ls node 'ls_line' of pump 'pump'"},
    // A cut-off below the margin: the pump never reaches its standby pressure.
    {MODEL, "m_ls_cutoff_margin.json", ML, "hydraulics.components.pump.p_cutoff=1e6", NULL, NULL,
     "hydraulics.components[0].p_cutoff", "must be above the margin (2e6 Pa), got 1e6 Pa"},
    // Both compensators deleted: the valves' P nodes are fed by nothing.
    {MODEL, "m_ls_no_comps.json", ML, NULL, LS_COMP("lift"), "", "hydraulics.components[3].P",
     "node 'lift_P' is fed by nothing"},
};

static void test_ls_components(void) {
    run_cases(ls_cases, (int)(sizeof ls_cases / sizeof ls_cases[0]));
    // The model itself loads and runs without a note.
    int rc = cli_run("run --quiet --model " ASSETS "/" ML " --scenario ramp --duration 0.01 --out /dev/null", out_buf,
                     sizeof out_buf);
    CHECK(rc == 0 && !out_buf[0], "hiab031_ls: exit %d: %s", rc, out_buf);
}

#define SP "scenarios/sandbox_pick_place.json"

// The corpus: one change each to a shipped file. Text replacements make what
// a --set cannot (a wrong type, a repeated key, a number JSON forbids).
static const bad_case corpus[] = {
    // models
    {MODEL, "m_joint_huge.json", M, NULL, "\"joint\": 0", "\"joint\": 2E67", "mechanics.actuators[0].joint", "<= 1"},
    {MODEL, "m_gravity_neg.json", M, "mechanics.gravity=-9.81", NULL, NULL, "mechanics.gravity", "[0, 30] m/s^2"},
    {MODEL, "m_column_zero.json", M, "mechanics.column.height=0", NULL, NULL, "mechanics.column.height", "must be > 0"},
    {MODEL, "m_link_long.json", M, "mechanics.links[0].length=1e6", NULL, NULL, "mechanics.links[0].length", "[0.1, 30] m"},
    {MODEL, "m_inertia_neg.json", M, "mechanics.links[1].inertia=-1", NULL, NULL, "mechanics.links[1].inertia", "> 0"},
    {MODEL, "m_mount_far.json", M, "mechanics.actuators[0].base_mount=[1e9, 0]", NULL, NULL,
     "mechanics.actuators[0].base_mount[0]", "[-10, 10] m"},
    {MODEL, "m_closed_neg.json", M, "mechanics.actuators[1].closed_length=-0.9", NULL, NULL,
     "mechanics.actuators[1].closed_length", "> 0"},
    {MODEL, "m_rod_ge_bore.json", M, "hydraulics.components.lift_cyl.rod=0.2", NULL, NULL,
     "hydraulics.components[5].rod", "must be < bore"},
    {MODEL, "m_valve_t_chamber.json", M, NULL, "\"T\": \"tank\", \"A\": \"lift_hose_A\"",
     "\"T\": \"lift_cyl.A\", \"A\": \"lift_hose_A\"", "hydraulics.components[2].T", "is a cylinder chamber"},
    {MODEL, "m_isolated_node.json", M, NULL, "{\"name\": \"tank\", \"type\": \"tank\", \"pressure\": 100000},",
     "{\"name\": \"tank\", \"type\": \"tank\", \"pressure\": 100000}, {\"name\": \"spare\", \"type\": \"volume\", "
     "\"volume\": 0.001},",
     "hydraulics.nodes[1]", "'spare' is connected to no component"},
    {MODEL, "m_nul_name.json", M, NULL, "\"name\": \"lift_cyl\"", "\"name\": \"lift\\u0000_cyl\"", "\\u0000",
     "not allowed in a string"},
    {MODEL, "m_dup_key.json", M, NULL, "\"bore\": 0.1,", "\"bore\": 0.1, \"bore\": 0.2,", "hydraulics.components[5].bore",
     "given twice"},
    {MODEL, "m_mass_string.json", M, NULL, "\"mass\": 180.0", "\"mass\": \"heavy\"", "mechanics.links[0].mass",
     "must be a number"},
    {MODEL, "m_unknown_node.json", M, NULL, "\"to\": \"lift_cyl.A\"", "\"to\": \"lift_cyl.C\"",
     "hydraulics.components[3].to", "unknown node"},
    {MODEL, "m_leading_zero.json", M, NULL, "\"stroke\": 0.7", "\"stroke\": 00.7", "line", "invalid number"},
    {MODEL, "m_length_inf.json", M, NULL, "\"length\": 2.3", "\"length\": 1e400", "mechanics.links[0].length",
     "must be a finite number"},
    {MODEL, "m_is_scenario.json", S, NULL, "\"name\"", "\"name\"", "this is a scenario file (use --scenario)", NULL},
    {MODEL, "m_is_world.json", W, NULL, "\"name\"", "\"name\"", "this is a world file (use --world)", NULL},
    {MODEL, "m_tau_zero.json", M, "hydraulics.components.lift_valve.tau=0", NULL, NULL, "hydraulics.components[2].tau",
     "> 0"},
    {MODEL, "m_air.json", M, "hydraulics.fluid.air_fraction=0.9", NULL, NULL, "hydraulics.fluid.air_fraction", "[0, 0.5]"},
    {MODEL, "m_viscosity.json", M, "hydraulics.fluid.viscosity=1", NULL, NULL, "hydraulics.fluid.viscosity",
     "[1e-7, 0.01] m^2/s"},
    {MODEL, "m_typo.json", M, NULL, "\"load_mass\": 500.0", "\"load_mas\": 500.0", "mechanics.load_mas", "unknown field"},
    // scenarios
    {SCENARIO, "s_time_inf.json", S, NULL, "[16, -0.5]", "[1e400, -0.5]", "commands.lift[7]", "must be a finite number"},
    {SCENARIO, "s_time_order.json", S, NULL, "[5, 0.6]", "[0.5, 0.6]", "commands.lift[3]", "must not decrease"},
    {SCENARIO, "s_u_range.json", S, NULL, "[2, 0.6]", "[2, 1.6]", "commands.lift[2]", "[-1, 1]"},
    {SCENARIO, "s_duration_neg.json", S, "duration=-1", NULL, NULL, "duration", "must be > 0"},
    {SCENARIO, "s_duration_huge.json", S, "duration=1e9", NULL, NULL, "duration", "[0.001, 86400] s"},
    {SCENARIO, "s_q1.json", S, "initial.q1_deg=400", NULL, NULL, "initial.q1_deg", "<= 360"},
    // Poses whose strokes are in range but on the mirror branch of the
    // mounts (boom folded backwards, jib bent the wrong way): they ran.
    {SCENARIO, "s_q1_mirror.json", S, "initial.q1_deg=300", NULL, NULL, "initial.q1_deg",
     "300.00 deg is outside joint 1's range"},
    {SCENARIO, "s_q2_mirror.json", S, "initial.q2_deg=100", NULL, NULL, "initial.q2_deg",
     "100.00 deg is outside joint 2's range -135"},
    {SCENARIO, "s_is_model.json", M, NULL, "\"name\"", "\"name\"", "this is a model file (use --model)", NULL},
    {SCENARIO, "s_is_world.json", W, NULL, "\"name\"", "\"name\"", "this is a world file (use --world)", NULL},
    {SCENARIO, "s_hook_inf.json", SP, NULL, "[24.0, \"release\"]", "[1e400, \"release\"]", "hook[1]",
     "must be a finite number"},
    {SCENARIO, "s_channel.json", S, NULL, "\"jib\":", "\"boom\":", "commands.boom", "unknown field"},
    // fault events (scenarios/hose_burst.json)
    {SCENARIO, "s_fault_kind.json", SF, NULL, "\"kind\": \"hose_burst\"", "\"kind\": \"hose_leak\"", "faults[0].kind",
     "must be \"hose_burst\" or \"pump_stop\""},
    {SCENARIO, "s_fault_at.json", SF, NULL, "\"at\": \"lift_cyl.A\", ", "", "faults[0].at", NULL},
    {SCENARIO, "s_fault_node.json", SF, NULL, "\"lift_cyl.A\"", "\"lift_cyl.C\"", "faults[0].at", "no node 'lift_cyl.C'"},
    {SCENARIO, "s_fault_tank.json", SF, NULL, "\"lift_cyl.A\"", "\"tank\"", "faults[0].at", "cannot open at the tank"},
    {SCENARIO, "s_fault_area.json", SF, NULL, "\"area\": 2e-6", "\"area\": 5", "faults[0].area", "m^2"},
    // The old maximum, 1e-2 m^2, blew up at the first step after the burst.
    {SCENARIO, "s_fault_area_max.json", SF, NULL, "\"area\": 2e-6", "\"area\": 1e-2", "faults[0].area",
     "must be in [1e-8, 5e-5] m^2, got 0.01"},
    {SCENARIO, "s_fault_key.json", SF, NULL, "\"area\": 2e-6", "\"areas\": 2e-6", "faults[0].areas", "unknown field"},
    {SCENARIO, "s_fault_ramp.json", SF, NULL, "\"area\": 2e-6}", "\"area\": 2e-6}, {\"t\": 3, \"kind\": \"pump_stop\", \"ramp\": -1}",
     "faults[1].ramp", "[0, 10] s"},
    {SCENARIO, "s_fault_order.json", SF, NULL, "\"area\": 2e-6}", "\"area\": 2e-6}, {\"t\": 1, \"kind\": \"pump_stop\"}",
     "faults[1].t", "must not decrease"},
    {SCENARIO, "s_fault_obj.json", SF, NULL, "{\"t\": 2.0, \"kind\": \"hose_burst\", \"at\": \"lift_cyl.A\", \"area\": 2e-6}", "[2, \"burst\"]",
     "faults[0]", "must be an object"},
    // worlds
    {WORLD, "w_max_contacts.json", W, "ode.max_contacts=1e300", NULL, NULL, "ode.max_contacts", "<= 32"},
    {WORLD, "w_rope_links.json", W, "rope.links=2E67", NULL, NULL, "rope.links", "<= 16"},
    {WORLD, "w_samples.json", W, "terrain.samples=[1e300, 121]", NULL, NULL, "terrain.samples", "[2, 1024]"},
    {WORLD, "w_hook_mass.json", W, "hook.mass=0", NULL, NULL, "hook.mass", "must be > 0"},
    {WORLD, "w_load_far.json", W, "loads[1].position=[500, 0]", NULL, NULL, "loads[1].position", "must lie on the terrain"},
    {WORLD, "w_obstacle_mass.json", W, "obstacles[2].mass=-5", NULL, NULL, "obstacles[2].mass", "[0, 1e6] kg"},
    {WORLD, "w_is_scenario.json", S, NULL, "\"name\"", "\"name\"", "this is a scenario file (use --scenario)", NULL},
    {WORLD, "w_validation_rope.json", WV, NULL, "\"type\": \"validation\",", "\"type\": \"validation\", \"rope\": {},",
     "rope", "only a sandbox world"},
    {WORLD, "w_circuit_bore.json", W, "circuit.components.slew_cyl.bore=1e300", NULL, NULL, "circuit.components[3].bore",
     "[0.005, 1] m"},
    {WORLD, "w_dup_name.json", W, "loads[1].name=load_200", NULL, NULL, "loads[1].name", "duplicate name"},
    // found by fuzz_world_build: a fixed wall through the truck with a contact
    // CFM of 0 aborted ODE (dxNormalize4); each alone is now refused
    {WORLD, "w_wall_in_truck.json", W, "obstacles[1].position=[0, -2]", NULL, NULL, "obstacles[1].position",
     "obstacle \"wall_yard\" starts inside the truck"},
    {WORLD, "w_contact_cfm0.json", W, "ode.contact_cfm=0", NULL, NULL, "ode.contact_cfm", "must be > 0"},
    {WORLD, "w_load_in_load.json", W, "loads[1].position=[3.0, -3.3]", NULL, NULL, "loads[1].position",
     "load \"load_500\" starts inside load \"load_200\""},
    {WORLD, "w_gravity.json", WV, NULL, "\"type\": \"validation\",", "\"type\": \"validation\", \"gravity\": 1e400,",
     "gravity", "must be a finite number"},
};

static void test_corpus(void) {
    const int n = (int)(sizeof corpus / sizeof corpus[0]);
    CHECK(n + (int)(sizeof range_cases / sizeof range_cases[0]) >= 40, "corpus too small: %d", n);
    run_cases(corpus, n);
}

// A file over the 1 MiB limit (docs/files.md, File limits) is refused before
// it is read, in one line, and the output file stays as it was.
static void test_oversize(void) {
    char path[1024], out[1024], cmd[4096];
    snprintf(path, sizeof path, "%s/s_oversize.json", dir());
    snprintf(out, sizeof out, "%s/out.csv", dir());
    FILE* f = fopen(path, "w");
    fputs("{\"name\": \"big\", \"description\": \"", f);
    for (long i = 0; i < (1L << 20); ++i) fputc('x', f);
    fputs("\", \"duration\": 1, \"initial\": {\"q1_deg\": 100, \"q2_deg\": -110}, \"commands\": {}}\n", f);
    fclose(f);
    cli_write_file(out, SENTINEL);
    snprintf(cmd, sizeof cmd, "run --quiet --scenario %s --out %s", path, out);
    int rc = cli_run(cmd, out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "s_oversize.json: too large (") && cli_count_lines(out_buf) == 1, "exit %d: %s", rc,
          out_buf);
    char* now = fixture_read_all(out);
    CHECK(now && !strcmp(now, SENTINEL), "the existing output file was changed");
    free(now);
    remove(path);
}

// Messages that are not about one file: a world name that does not exist
// lists the worlds; an index past the end of an array gives the length.
static void test_messages(void) {
    int rc = cli_run("run --quiet --mechanics ode --world nosuch --scenario hold --out /dev/null", out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "--world nosuch: no such world (available: sandbox, site, validation") &&
              cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --scenario hold --out /dev/null --set 'mechanics.links[5].mass=1'", out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "index 5 out of range: mechanics.links has 2 elements") &&
              cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --scenario hold --out /dev/null --set 'hydraulics.components.nosuch.bore=1'", out_buf,
             sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "no element named 'nosuch' in hydraulics.components"), "exit %d: %s", rc, out_buf);
}

// The largest burst the scenario accepts runs through on the default solver
// and step, at the site measured worst (the LS crane's lift chamber A, burst
// during ramp's commands, in the ode world): at 1e-4 m^2 p1A fell below
// -0.1 MPa there about a second later, as the boom hit its stop; 1e-2 was
// accepted and blew up at the first step after the burst.
static void test_burst_max_area_runs(void) {
    char path[600], cmd[1600];
    snprintf(path, sizeof path, "%s/burst_max.json", dir());
    for (int k = 0; k < 2; ++k) {
        const double t = k ? 8.0 : 5.0;
        char text[1200];
        snprintf(text, sizeof text,
                 "{\"duration\": %g, \"load_mass\": 500, \"initial\": {\"q1_deg\": 100, \"q2_deg\": -110},"
                 " \"commands\": {\"lift\": [[0, 0], [1, 0], [2, 0.6], [5, 0.6], [6, 0], [12, 0], [13, -0.5], [16, -0.5], [17, 0]],"
                 " \"jib\": [[0, 0], [4, 0], [5, 0.5], [7, 0.5], [8, 0], [13, 0], [14, -0.4], [16, -0.4], [17, 0]]},"
                 " \"faults\": [{\"t\": %g, \"kind\": \"hose_burst\", \"at\": \"lift_cyl.A\", \"area\": 5e-5}]}\n",
                 t + 1.5, t);
        cli_write_file(path, text);
        snprintf(cmd, sizeof cmd, "run --quiet --model hiab031_ls --mechanics ode --scenario %s --out /dev/null", path);
        const int rc = cli_run(cmd, out_buf, sizeof out_buf);
        CHECK(rc == 0 && !strstr(out_buf, "blow-up"), "burst at %g s: exit %d: %s", t, rc, out_buf);
    }
    remove(path);
}

// The lift stroke x1 [m] in the first and the last row of a run's CSV (NAN
// when it cannot be read).
static void csv_x1(const char* csv, double* first, double* last) {
    static char text[1 << 21];
    *first = *last = NAN;
    if (cli_read_file(csv, text, sizeof text) <= 0) return;
    int col = 0; // x1's column: the commas before "x1," in the header
    for (const char* q = text; *q && *q != '\n' && strncmp(q, ",x1,", 4); ++q) col += *q == ',';
    ++col;
    for (const char* line = strchr(text, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
        const char* q = line + 1;
        for (int k = 0; k < col && q; ++k) q = strchr(q, ',') ? strchr(q, ',') + 1 : NULL;
        if (!q) break;
        const double v = strtod(q, NULL);
        if (isnan(*first)) *first = v;
        *last = v;
    }
}

// Column name of a run's CSV at the last row with t <= tq (NAN when it
// cannot be read).
static double csv_at(const char* csv, const char* name, double tq) {
    static char text[1 << 22];
    if (cli_read_file(csv, text, sizeof text) <= 0) return NAN;
    char key[64];
    snprintf(key, sizeof key, ",%s,", name);
    const char* hit = strstr(text, key);
    const char* eol = strchr(text, '\n');
    if (!hit || !eol || hit > eol) return NAN;
    int col = 1;
    for (const char* q = text; q < hit; ++q) col += *q == ',';
    double v = NAN;
    for (const char* line = eol; line && line[1]; line = strchr(line + 1, '\n')) {
        const char* q = line + 1;
        if (strtod(q, NULL) > tq + 1e-9) break;
        for (int k = 0; k < col && q; ++k) q = strchr(q, ',') ? strchr(q, ',') + 1 : NULL;
        if (!q) break;
        v = strtod(q, NULL);
    }
    return v;
}

// A burst at a node the world's circuit adds (the sandbox's slew cylinder)
// opens there: it was refused as "no node 'slew_cyl.A' in the circuit of
// hiab031.json" although the running circuit has it. Before the burst the
// run is the run without it (but for the closed hole's trace of a leak);
// after a 5e-5 m^2 hole the chamber sits at the
// tank: the slew valve 0.6 open from the 20 MPa pump line passes at most
// 1e-4 sqrt(20 / 1) 0.6 = 2.7e-4 m^3/s (q_nominal at 1 MPa), which the hole
// takes with rho/2 (Q / (cd A))^2 = 30 kPa, so p3A stays below 0.2 MPa,
// where the intact run drives the slew at over 5 MPa. Where no world circuit is (lagrange),
// or the world lacks the node, the refusal names both.
static void test_burst_in_world_circuit(void) {
    char path[600], csv[600], cmd[1600];
    snprintf(path, sizeof path, "%s/slew_burst.json", dir());
    snprintf(csv, sizeof csv, "%s/slew_burst.csv", dir());
    double p3A[2][2], x3[2];
    for (int with = 0; with < 2; ++with) {
        char text[1000];
        snprintf(text, sizeof text,
                 "{\"duration\": 2, \"initial\": {\"q1_deg\": 100, \"q2_deg\": -110, \"slew_deg\": -90},"
                 " \"commands\": {\"slew\": [[0, 0], [1, 0], [1.1, 0.6]]}%s}\n",
                 with ? ", \"faults\": [{\"t\": 1, \"kind\": \"hose_burst\", \"at\": \"slew_cyl.A\", \"area\": 5e-5}]" : "");
        cli_write_file(path, text);
        snprintf(cmd, sizeof cmd, "run --quiet --mechanics ode --world sandbox --scenario %s --out %s", path, csv);
        const int rc = cli_run(cmd, out_buf, sizeof out_buf);
        CHECK(rc == 0, "burst %s: exit %d: %s", with ? "on" : "off", rc, out_buf);
        p3A[with][0] = csv_at(csv, "p3A", 0.99);
        p3A[with][1] = csv_at(csv, "p3A", 1.9);
        x3[with] = csv_at(csv, "x3", 0.99);
    }
    printf("  p3A at 0.99 s: %.4g / %.4g Pa, at 1.9 s: intact %.4g Pa, burst %.4g Pa\n", p3A[0][0], p3A[1][0], p3A[0][1],
           p3A[1][1]);
    // Before it the closed hole (1e-10 m^2) leaks a trace: 25 Pa in 1 s.
    CHECK(fabs(p3A[0][0] - p3A[1][0]) < 1e3 && fabs(x3[0] - x3[1]) < 1e-6,
          "before the burst the runs differ: p3A %g / %g Pa, x3 %g / %g m", p3A[0][0], p3A[1][0], x3[0], x3[1]);
    CHECK(p3A[0][1] > 5e6 && p3A[1][1] < 0.2e6, "at 1.9 s p3A intact %g Pa, burst %g Pa", p3A[0][1], p3A[1][1]);
    // No world circuit: refused, naming the model's circuit.
    cli_write_file(path, "{\"duration\": 1, \"initial\": {\"q1_deg\": 100, \"q2_deg\": -110},"
                         " \"faults\": [{\"t\": 0.5, \"kind\": \"hose_burst\", \"at\": \"slew_cyl.A\", \"area\": 1e-6}]}\n");
    snprintf(cmd, sizeof cmd, "run --quiet --mechanics lagrange --scenario %s --out /dev/null", path);
    int rc = cli_run(cmd, out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "slew_burst.json: faults[0].at: no node 'slew_cyl.A' in the circuit of hiab031.json") &&
              cli_count_lines(out_buf) == 1,
          "lagrange: exit %d: %s", rc, out_buf);
    // The sandbox without such a node: both circuits named.
    cli_write_file(path, "{\"duration\": 1, \"initial\": {\"q1_deg\": 100, \"q2_deg\": -110},"
                         " \"faults\": [{\"t\": 0.5, \"kind\": \"hose_burst\", \"at\": \"slew_cyl.C\", \"area\": 1e-6}]}\n");
    snprintf(cmd, sizeof cmd, "run --quiet --mechanics ode --world sandbox --scenario %s --out /dev/null", path);
    rc = cli_run(cmd, out_buf, sizeof out_buf);
    // (The default model carries the slew drive: its hydraulics_slew is the
    // other circuit.)
    CHECK(rc == 2 && strstr(out_buf, "no node 'slew_cyl.C' in the circuit of hiab031.json or of its hydraulics_slew") &&
              cli_count_lines(out_buf) == 1,
          "sandbox: exit %d: %s", rc, out_buf);
    remove(path);
    remove(csv);
}

// A scenario without "commands" is a hold (every valve centred), as
// docs/files.md says: it runs, and the crane holds its start pose (the lift
// stroke moves less than 0.1 mm in 0.5 s). The loader used to require it.
static void test_scenario_without_commands(void) {
    char path[600], csv[600], cmd[1400];
    snprintf(path, sizeof path, "%s/no_commands.json", dir());
    snprintf(csv, sizeof csv, "%s/no_commands.csv", dir());
    cli_write_file(path, "{\"duration\": 0.5, \"initial\": {\"q1_deg\": 100, \"q2_deg\": -110}}\n");
    snprintf(cmd, sizeof cmd, "run --quiet --scenario %s --out %s", path, csv);
    const int rc = cli_run(cmd, out_buf, sizeof out_buf);
    CHECK(rc == 0 && !strstr(out_buf, "commands"), "exit %d: %s", rc, out_buf);
    if (rc) return;
    double first, last;
    csv_x1(csv, &first, &last);
    CHECK(isfinite(first) && fabs(last - first) < 1e-4, "x1 from %g to %g m", first, last);
    remove(csv);
    remove(path);
}

// Mounts that cannot reach the cylinder's pin lengths are reported against
// the mounts, not only closed_length (a rod_mount copied from base_mount
// used to read "closed_length: pin length ... outside the reachable ...").
static void test_mount_message(void) {
    int rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null "
                     "--set 'mechanics.actuators[0].rod_mount=[0.2113, -0.4532]'",
                     out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "mechanics.actuators[0]: base_mount") && strstr(out_buf, "rod_mount") &&
              strstr(out_buf, "given the same coordinates") && strstr(out_buf, "pin lengths 0.000..1.000 m") &&
              cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
    // A closed length too long for good mounts says what would fit: the lift
    // mounts (0.5 m, 1.56 m) reach 1.06..2.06 m; with 0.7 m of stroke the
    // closed length must lie in 1.06..1.36 m.
    rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null "
                 "--set 'mechanics.actuators[0].closed_length=3'",
                 out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "closed_length would have to lie in 1.060..1.360 m") &&
              !strstr(out_buf, "same coordinates") && cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
}

// --model takes a name in assets/models as --scenario and --world do, and a
// name that is no model lists the shipped ones.
static void test_model_names(void) {
    int rc = cli_run("run --quiet --model hiab031_ls --scenario hold --duration 0.01 --out /dev/null", out_buf,
                     sizeof out_buf);
    CHECK(rc == 0, "--model hiab031_ls: exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --model nosuch --scenario hold --out /dev/null", out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "--model nosuch: no such file or model (models: hiab031, hiab031_ls, loader10;") &&
              cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
    // A path stays a path: a missing file is not looked up as a name.
    rc = cli_run("run --quiet --model nosuch.json --scenario hold --out /dev/null", out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "nosuch.json: cannot open"), "exit %d: %s", rc, out_buf);
}

// --set gets the same ranges (it edits the document before loading), and
// --load the tip-load range.
static void test_set_and_load(void) {
    int rc = cli_run("run --quiet --scenario ramp --duration 0.01 --out /dev/null --set "
                 "hydraulics.components.main_relief.p_crack=22",
                 out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "hiab031.json: hydraulics.components[1].p_crack: must be in [1e5, 1e8] Pa, got 22") &&
              strstr(out_buf, "(from --set"),
          "exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null --load 1e5", out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "--load") && strstr(out_buf, "kg"), "--load 1e5: exit %d: %s", rc, out_buf);
}

// One value, one range: a discharge coefficient of 5 and of 0 both name the
// hard range [0.1, 1] (5 named the rule's [0, 1] before).
static void test_one_range_per_value(void) {
    int rc = cli_run("run --quiet --set hydraulics.components.lift_valve.cd=5 --out /dev/null", out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "must be in [0.1, 1], got 5"), "exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --set hydraulics.components.lift_valve.cd=0 --out /dev/null", out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "must be in [0.1, 1], got 0"), "exit %d: %s", rc, out_buf);
}

// A sandbox start the reliefs cannot hold is the world's hook, not a tip
// load: the refusal says so and does not suggest --load, which the sandbox
// refuses (it said "with 500 kg at the tip ... a smaller --load").
static void test_sandbox_start_names_the_hook(void) {
    bad_case w = {WORLD, "w_hook_5t.json", "worlds/sandbox.json", "hook.mass=5000", NULL, NULL, "", NULL};
    const char* wf = make_case(&w);
    CHECK(wf != NULL, "cannot make %s", w.name);
    if (!wf) return;
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "run --quiet --mechanics ode --world %s --scenario sandbox_swing --out /dev/null", wf);
    int rc = cli_run(cmd, out_buf, sizeof out_buf);
    CHECK(rc == 2 && strstr(out_buf, "the world's hook and rope at the tip") && !strstr(out_buf, "--load") &&
              !strstr(out_buf, "kg at the tip"),
          "exit %d: %s", rc, out_buf);
}

// Outside the typical range: the run goes on (exit 0) with one note naming
// file, field, range and unit.
static void test_typical_notes(void) {
    int rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null --set hydraulics.fluid.bulk_modulus=4e8",
                 out_buf, sizeof out_buf);
    CHECK(rc == 0 && strstr(out_buf, "note: hiab031.json: hydraulics.fluid.bulk_modulus: 4e8 is outside the typical "
                                     "range [5e8, 2.5e9] Pa") &&
              cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null --set mechanics.links[0].mass=15", out_buf,
             sizeof out_buf);
    CHECK(rc == 0 && strstr(out_buf, "note: hiab031.json: mechanics.links[0].mass: 15 kg is outside the typical "
                                     "range [20, 5000] kg") &&
              strstr(out_buf, "mechanics.links[0].inertia") && cli_count_lines(out_buf) == 2, // 79 kg m^2 left as it was
          "exit %d: %s", rc, out_buf);
    // An inertia far from a box of the link's mass and size (kg cm^2 meant?).
    rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null --set mechanics.links[0].inertia=7935",
             out_buf, sizeof out_buf);
    CHECK(rc == 0 && strstr(out_buf, "note: hiab031.json: mechanics.links[0].inertia: 7935 kg m^2 is outside the typical "
                                     "range [0.2, 4] times a uniform box") &&
              cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
    // A world's circuit component is noted under the world file's own path,
    // not as a component of the model's merged circuit.
    bad_case w = {WORLD, "w_note_bore.json", W, "circuit.components.slew_cyl.bore=0.025", NULL, NULL, "", NULL};
    const char* wf = make_case(&w);
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "run --quiet --mechanics ode --world %s --scenario sandbox_swing --duration 0.01 --out /dev/null", wf);
    rc = cli_run(cmd, out_buf, sizeof out_buf);
    CHECK(rc == 0 &&
              strstr(out_buf, "note: w_note_bore.json: circuit.components[3].bore: 0.025 is outside the typical range "
                              "[0.03, 0.3] m") &&
              // The default model has its own slew drive, which is used: said once.
              strstr(out_buf, "note: w_note_bore.json: slew, circuit: the model's slew drive (hiab031.json: "
                              "mechanics.slew, hydraulics_slew) is used instead") &&
              cli_count_lines(out_buf) == 2,
          "exit %d: %s", rc, out_buf);
    // Values in range that do not fit together (the LS crane): a main relief
    // below the pump's cut-off plus band, a post compensator's setting not
    // below the pump's margin. One line each, the run goes on.
    rc = cli_run("run --quiet --model " ASSETS "/" ML " --scenario hold --duration 0.01 --out /dev/null "
                 "--set hydraulics.components.main_relief.p_crack=21.2e6",
                 out_buf, sizeof out_buf);
    CHECK(rc == 0 &&
              strstr(out_buf, "note: hiab031_ls.json: hydraulics.components[1].p_crack: 2.12e7 Pa is below the cut-off "
                              "of LS pump 'pump' plus its band (2.1e7 + 5e5 Pa)") &&
              cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --model " ASSETS "/" ML " --scenario hold --duration 0.01 --out /dev/null "
                 "--set hydraulics.components.jib_comp.setting=2e6",
                 out_buf, sizeof out_buf);
    CHECK(rc == 0 &&
              strstr(out_buf, "note: hiab031_ls.json: hydraulics.components[15].setting: 2e6 Pa is not below the margin "
                              "of LS pump 'pump' (2e6 Pa)") &&
              cli_count_lines(out_buf) == 2, // and the typical range [1e5, 1.5e6] Pa
          "exit %d: %s", rc, out_buf);
    // The same for a pressure-compensated pump (issue 25, 11a: a main relief
    // at 5 MPa under a 20 MPa pump ran without a word, the relief open 17 s
    // of 20): the note says the relief limits the pressure, at p_crack +
    // dp_override = 6 MPa. Above the setting plus band (20.5 MPa): no note.
    rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null "
                 "--set hydraulics.components.main_relief.p_crack=5e6",
                 out_buf, sizeof out_buf);
    CHECK(rc == 0 &&
              strstr(out_buf, "note: hiab031.json: hydraulics.components[1].p_crack: 5 MPa is below the setting of "
                              "pump 'pump' plus its band (20 + 0.5 MPa): the relief, not the pump, limits the "
                              "pressure to about 6 MPa") &&
              cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null "
                 "--set hydraulics.components.main_relief.p_crack=20.6e6",
                 out_buf, sizeof out_buf);
    CHECK(rc == 0 && !out_buf[0], "exit %d: %s", rc, out_buf);
    // A port relief below the chamber's holding pressure at the start (issue
    // 25, 11b: lift_relief_A at 2 MPa under hold's 12.1 MPa let the boom sink
    // from t = 0 with only a typical-range note): one more line saying so,
    // on both backends.
    for (int ode = 0; ode < 2; ++ode) {
        char cmd2[512];
        snprintf(cmd2, sizeof cmd2,
                 "run --quiet --scenario hold --duration 0.01 --out /dev/null --mechanics %s "
                 "--set hydraulics.components.lift_relief_A.p_crack=2e6",
                 ode ? "ode" : "lagrange");
        rc = cli_run(cmd2, out_buf, sizeof out_buf);
        CHECK(rc == 0 &&
                  strstr(out_buf, "note: lift_relief_A cracks at 2 MPa, below the 12.1 MPa that lift_cyl.A (p1A) "
                                  "needs to hold the start pose: the relief opens at t = 0") &&
                  cli_count_lines(out_buf) == 2, // and the typical range [5e6, 4.5e7] Pa
              "%s: exit %d: %s", ode ? "ode" : "lagrange", rc, out_buf);
    }
    // What the note says happens: over 1 s of hold the lift stroke falls by
    // more than 10 mm with the relief at 2 MPa; at the shipped 25 MPa it
    // moves less than 0.1 mm.
    for (int low = 0; low < 2; ++low) {
        char cmd2[900], csv[600];
        snprintf(csv, sizeof csv, "%s/relief_hold.csv", dir());
        snprintf(cmd2, sizeof cmd2, "run --quiet --scenario hold --duration 1 --out %s%s", csv,
                 low ? " --set hydraulics.components.lift_relief_A.p_crack=2e6" : "");
        rc = cli_run(cmd2, out_buf, sizeof out_buf);
        double x0, x1;
        csv_x1(csv, &x0, &x1);
        CHECK(rc == 0 && (low ? x0 - x1 > 0.01 : fabs(x1 - x0) < 1e-4), "relief %s: exit %d, x1 %g -> %g m: %s",
              low ? "2 MPa" : "25 MPa", rc, x0, x1, out_buf);
        remove(csv);
    }
    // Just above the holding pressure: no such note.
    rc = cli_run("run --quiet --scenario hold --duration 0.01 --out /dev/null "
                 "--set hydraulics.components.lift_relief_A.p_crack=12.5e6",
                 out_buf, sizeof out_buf);
    CHECK(rc == 0 && !strstr(out_buf, "start pose"), "exit %d: %s", rc, out_buf);
    rc = cli_run("run --quiet --scenario ramp --duration 0.01 --out /dev/null --load 4000", out_buf, sizeof out_buf);
    CHECK(rc == 0 && strstr(out_buf, "note:") && strstr(out_buf, "--load 4000 kg") && cli_count_lines(out_buf) == 1,
          "exit %d: %s", rc, out_buf);
}

// Every shipped file is inside the hard ranges and gives no note, in every
// world it can run in.
static void test_shipped_quiet(void) {
    const char* lag[] = {"ramp", "step", "hold", "overload", "drive_demo"};
    const char* sbx[] = {"sandbox_wall", "sandbox_swing", "sandbox_pick_place"};
    for (int i = 0; i < 5; ++i) {
        char a[512];
        snprintf(a, sizeof a, "run --quiet --scenario %s --duration 0.01 --out /dev/null", lag[i]);
        int rc = cli_run(a, out_buf, sizeof out_buf);
        CHECK(rc == 0 && !out_buf[0], "%s: exit %d: %s", lag[i], rc, out_buf);
        snprintf(a, sizeof a, "run --quiet --mechanics ode --world validation --scenario %s --duration 0.01 --out /dev/null",
                 lag[i]);
        rc = cli_run(a, out_buf, sizeof out_buf);
        CHECK(rc == 0 && !out_buf[0], "%s (validation): exit %d: %s", lag[i], rc, out_buf);
    }
    for (int i = 0; i < 3; ++i) {
        char a[512];
        snprintf(a, sizeof a, "run --quiet --mechanics ode --world sandbox --scenario %s --duration 0.01 --out /dev/null",
                 sbx[i]);
        int rc = cli_run(a, out_buf, sizeof out_buf);
        CHECK(rc == 0 && !out_buf[0], "%s: exit %d: %s", sbx[i], rc, out_buf);
    }
}

// The ode backend refuses a mirror-branch start pose the same way (its
// hinge limits were set from the stroke only, around the backwards boom).
static void test_start_pose_ode(void) {
    const bad_case cases[] = {
        {SCENARIO, "s_sb_q1_mirror.json", SB, "initial.q1_deg=300", NULL, NULL, "initial.q1_deg", "outside joint 1"},
        {SCENARIO, "s_sb_q2_mirror.json", SB, "initial.q2_deg=100", NULL, NULL, "initial.q2_deg", "outside joint 2"},
    };
    for (int i = 0; i < 2; ++i) {
        const char* file = make_case(&cases[i]);
        CHECK(file != NULL, "cannot make %s", cases[i].name);
        if (!file) continue;
        char cmd[2048];
        snprintf(cmd, sizeof cmd, "run --quiet --mechanics ode --world sandbox --scenario %s --duration 0.01 --out /dev/null",
                 file);
        int rc = cli_run(cmd, out_buf, sizeof out_buf);
        CHECK(rc == 2 && strstr(out_buf, cases[i].name) && strstr(out_buf, cases[i].field) &&
                  strstr(out_buf, cases[i].msg) && strstr(out_buf, " deg") && cli_count_lines(out_buf) == 1,
              "%s: exit %d: %s", cases[i].name, rc, out_buf);
    }
}

int main(int argc, char** argv) {
    RUN_TEST(test_hard_ranges);
    RUN_TEST(test_ls_components);
    RUN_TEST(test_corpus);
    RUN_TEST(test_messages);
    RUN_TEST(test_model_names);
    RUN_TEST(test_burst_in_world_circuit);
    RUN_TEST(test_burst_max_area_runs);
    RUN_TEST(test_mount_message);
    RUN_TEST(test_scenario_without_commands);
    RUN_TEST(test_oversize);
    RUN_TEST(test_set_and_load);
    RUN_TEST(test_typical_notes);
    RUN_TEST(test_sandbox_start_names_the_hook);
    RUN_TEST(test_one_range_per_value);
    RUN_TEST(test_shipped_quiet);
    RUN_TEST(test_start_pose_ode);
    TEST_MAIN_END();
}
