// test_energy_compare_cli.c: compare and replay print the energy balance as run
// does (docs/energy.md): compare each side's lines, the same numbers run
// prints for that side's settings, and B - A term by term; replay the
// replayed run's, which agree with a scripted run of the same commands (the
// stepped engine against the scripted one) and close within the bound of
// the balance.
#include "check.h"
#include "cli_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static char out[1 << 16], ref[1 << 16];

// The energy line of out that starts with "  <tag>: in" (tag: "energy",
// "energy A", ...), from its "in" on, up to the end of the three lines it
// starts (the next line not of that tag), into buf; NULL if absent.
static const char* energy_lines(const char* text, const char* tag, char* buf, size_t n) {
    char key[64];
    snprintf(key, sizeof key, "  %s: in ", tag);
    const char* p = strstr(text, key);
    if (!p) return NULL;
    size_t k = 0;
    char pre[64];
    snprintf(pre, sizeof pre, "  %s: ", tag);
    // The tag's consecutive lines, each without its tag.
    while (p && !strncmp(p, pre, strlen(pre))) {
        p += strlen(pre);
        const char* e = strchr(p, '\n');
        const size_t L = e ? (size_t)(e - p) : strlen(p);
        if (k + L + 2 >= n) break;
        memcpy(buf + k, p, L);
        k += L;
        buf[k++] = '\n';
        p = e ? e + 1 : NULL;
    }
    buf[k] = 0;
    return buf;
}

// The number after "what " in s (e.g. "in 49.252 kJ"), NAN if absent.
static double number_after(const char* s, const char* what) {
    const char* p = s ? strstr(s, what) : NULL;
    return p ? strtod(p + strlen(what), NULL) : NAN;
}

// compare's sides print what run prints for the same settings: its default
// backends are lagrange (A) and ode (B); B - A is the difference of the two.
static void test_compare(void) {
    int rc = cli_run("compare --scenario hold", out, sizeof out);
    CHECK(rc == 0, "compare exit %d: %s", rc, out);
    char a[2048], b[2048], d[2048], r[2048];
    const char* la = energy_lines(out, "energy A", a, sizeof a);
    const char* lb = energy_lines(out, "energy B", b, sizeof b);
    const char* ld = energy_lines(out, "energy B - A", d, sizeof d);
    CHECK(la && lb && ld, "compare printed no energy lines (A %s, B %s, B - A %s):\n%s", la ? "yes" : "no",
          lb ? "yes" : "no", ld ? "yes" : "no", out);
    rc = cli_run("run --scenario hold --out ec_run.csv", ref, sizeof ref);
    CHECK(rc == 0, "run exit %d: %s", rc, ref);
    CHECK(la && energy_lines(ref, "energy", r, sizeof r) && !strcmp(la, r),
          "compare's side A (lagrange) is not run's:\ncompare:\n%s\nrun:\n%s", la ? la : "", r);
    rc = cli_run("run --scenario hold --mechanics ode --out ec_run.csv", ref, sizeof ref);
    CHECK(rc == 0, "run exit %d: %s", rc, ref);
    CHECK(lb && energy_lines(ref, "energy", r, sizeof r) && !strcmp(lb, r),
          "compare's side B (ode) is not run's:\ncompare:\n%s\nrun:\n%s", lb ? lb : "", r);
    // B - A of the terms, to the printed rounding (1 J).
    static const char* const terms[] = {"in ", "losses ", "work on mechanics "};
    for (int k = 0; k < 3 && la && lb && ld; ++k) {
        const double va = number_after(la, terms[k]), vb = number_after(lb, terms[k]), vd = number_after(ld, terms[k]);
        CHECK(fabs(vd - (vb - va)) <= 0.0015, "B - A of '%s': %g kJ printed, %g - %g = %g kJ", terms[k], vd, vb, va,
              vb - va);
    }
}

// Two designs: the metrics table has the energy rows, and each side's lines.
static void test_compare_designs(void) {
    int rc = cli_run("compare --scenario ramp --duration 2 --model " CRANESIM_ASSETS "/models/hiab031.json --model "
                     CRANESIM_ASSETS "/models/hiab031_ls.json",
                     out, sizeof out);
    CHECK(rc == 0, "compare exit %d: %s", rc, out);
    CHECK(strstr(out, "energy_in [J]") && strstr(out, "energy_loss [J]"), "no energy metrics in:\n%s", out);
    char b[2048];
    // The LS side's groups are named (compensators, counterbalance valves).
    const char* lb = energy_lines(out, "energy B", b, sizeof b);
    CHECK(lb && strstr(lb, "compensators") && strstr(lb, "counterbalance valves"), "side B's lines:\n%s", out);
}

// replay prints the replayed run's balance. A headless lagrange drive of
// ramp's first 3 s and its replay (the stepped engine, commands per 10 ms
// frame) against run on the same 3 s (the scripted engine, commands
// continuous): the energy in agrees to 0.5 %, and the balance closes.
static void test_replay(void) {
    int rc = cli_run("drive --headless --quiet --mechanics lagrange --scenario ramp --duration 3 --frame-rate 100 "
                     "--record ec_rec.csv --session ec.session",
                     out, sizeof out);
    CHECK(rc == 0, "drive exit %d: %s", rc, out);
    rc = cli_run("replay ec.session --quiet", out, sizeof out);
    CHECK(rc == 0, "replay exit %d: %s", rc, out);
    char a[2048], r[2048];
    const char* la = energy_lines(out, "energy", a, sizeof a);
    CHECK(la != NULL, "replay printed no energy lines:\n%s", out);
    rc = cli_run("run --scenario ramp --duration 3 --out ec_run.csv", ref, sizeof ref);
    CHECK(rc == 0, "run exit %d: %s", rc, ref);
    const char* lr = energy_lines(ref, "energy", r, sizeof r);
    const double in_rep = number_after(la, "in "), in_run = number_after(lr, "in ");
    CHECK(in_run > 5.0 && fabs(in_rep - in_run) <= 0.005 * in_run, "energy in: replay %g kJ, run %g kJ", in_rep,
          in_run);
    const double res = number_after(la, "residual ");
    CHECK(fabs(res) < 0.25, "replay's residual %g %%:\n%s", res, la ? la : "");
}

int main(void) {
    test_compare();
    test_compare_designs();
    test_replay();
    printf("%d checks, %d failed\n", check_count_, check_failures_);
    return check_failures_ != 0;
}
