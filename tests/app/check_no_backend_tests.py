#!/usr/bin/env python3
"""No file of src/app asks which backend runs (issue 26, item 4).

The drivers ask the backend table instead (src/world/run/engine_backend.h:
does it take a world, which options apply, its default world and scenario,
its outer step, whether a sweep needs worker processes). A test of which
backend runs -- `o->mechanics == SIM_ODE`, `strcmp(name, "ode")`,
`const bool ode = ...` -- sends a third backend into an `else` written for
another, so this check fails on each one, naming file:line.

It first checks itself: every pattern must catch its example of a backend
test and must pass the driver code that asks the table (a check that cannot
fail would prove nothing).

usage: check_no_backend_tests.py [--root DIR]   (DIR: the repository root)
exit 0: none found; 1: some found (listed), or the self-check failed.
"""
import argparse
import os
import re
import sys

NAMES = r"(?:ode|lagrange)"
# Each rule: a pattern over one line of code (comments removed, string
# contents kept: a name literal is what a test compares with), and what it
# catches.
RULES = [
    (re.compile(r"\bSIM_(?:ODE|LAGRANGE)\b"), "a backend's enum value (SIM_ODE, SIM_LAGRANGE)"),
    (re.compile(r"\bmechanics\s*[!=]=|[!=]=\s*[\w.>\-\[\]()]*\bmechanics\b"),
     "a comparison of sim_opts.mechanics"),
    (re.compile(r"\bmechanics\s*[<>]=?(?![>])|(?<![-])[<>]=?\s*[\w.>\-\[\]()]*\bmechanics\b"),
     "an ordering of sim_opts.mechanics"),
    (re.compile(r"\bswitch\s*\([^)]*\bmechanics\b"), "a switch over sim_opts.mechanics"),
    (re.compile(r"\bstr(?:n?case)?n?cmp\s*\([^;]*\"" + NAMES + r"\""),
     "a string comparison with a backend's name"),
    (re.compile(r"[!=]=\s*\"" + NAMES + r"\"|\"" + NAMES + r"\"\s*[!=]="),
     "a pointer comparison with a backend's name"),
    (re.compile(r"\bengine_backend_name\s*\([^)]*\)\s*[!=]=|[!=]=\s*engine_backend_name\s*\("),
     "a comparison of engine_backend_name"),
    (re.compile(r"\bbool\s+(?:is_|use_|on_)?" + NAMES + r"\b"), "a flag named after a backend"),
]

# The self-check: lines each rule must catch, and lines no rule may catch.
MUST_CATCH = [
    "    if (o->mechanics == SIM_ODE) {",
    "    const double step = SIM_LAGRANGE;",
    "    if (side[s].mechanics != other) x();",
    "    if (kind == c.sim.mechanics) x();",
    "    if (s->sim.mechanics > 1) bad();",
    "    switch (o->mechanics) {",
    "    c.sim.x = strcmp(backend, \"ode\") ? 1 : 2;",
    "    if (!strncmp(name, \"lagrange\", 8)) x();",
    "    if (!strcasecmp(v, \"ode\")) x();",
    "    if (name == \"lagrange\") x();",
    "    if (!strcmp(engine_backend_name(e), other)) x(); if (engine_backend_name(e) == n) y();",
    "    const bool ode = app_uses(o);",
    "    bool is_lagrange;",
]
MUST_PASS = [
    "    if (app_backend(o)->world) {",
    "    cJSON_AddNumberToObject(s, \"mechanics\", o->mechanics);",
    "    s->sim.mechanics = (sim_mechanics)(int)num(so, \"mechanics\", &ok);",
    "    app_use_backend(&c.sim, engine_backend_with_world());",
    "    fprintf(stderr, \"--mechanics ode: %s\\n\", why);",
    "    {APP_OPT_MECHANICS, \"  --mechanics M        lagrange (analytic 2-DOF, default) or ode\\n\"},",
    "    printf(\"  energy: work on mechanics %.3f kJ\", w);",
    "    if (engine_backend_select(&c.sim, backend, err, sizeof err)) return 1;",
    "    if (!strcmp(path, \"mechanics.load_mass\")) {",
    "    const bool sandbox = world && kind == WORLD_SANDBOX;",
]


def strip_comments(text):
    """The text with // and /* */ comments blanked (newlines kept, so line
    numbers stay), string and character literals kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def findings(text):
    """(line number, rule text, line) for each line a rule catches."""
    found = []
    for no, line in enumerate(strip_comments(text).split("\n"), 1):
        for pat, what in RULES:
            if pat.search(line):
                found.append((no, what, line.strip()))
                break
    return found


def selfcheck():
    bad = []
    for line in MUST_CATCH:
        if not findings(line):
            bad.append("self-check: no rule catches the backend test: " + line.strip())
    for line in MUST_PASS:
        for _, what, _ in findings(line):
            bad.append("self-check: %s caught in code that asks the table: %s" % (what, line.strip()))
    if findings("// if (o->mechanics == SIM_ODE)\n/* SIM_LAGRANGE */\n"):
        bad.append("self-check: a comment was taken for code")
    return bad


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    a = ap.parse_args()
    bad = selfcheck()
    if bad:
        print("\n".join(bad))
        return 1
    app = os.path.join(a.root, "src", "app")
    if not os.path.isdir(app):
        print("no directory %s" % app)
        return 1
    nfile, hits = 0, []
    for dirpath, _, files in os.walk(app):
        for f in sorted(files):
            if not f.endswith((".c", ".h")):
                continue
            path = os.path.join(dirpath, f)
            nfile += 1
            with open(path, encoding="utf-8", errors="replace") as fh:
                text = fh.read()
            rel = os.path.relpath(path, a.root)
            for no, what, line in findings(text):
                hits.append("%s:%d: %s: %s" % (rel, no, what, line))
    if nfile == 0:
        print("no .c or .h files under %s" % app)
        return 1
    if hits:
        print("\n".join(hits))
        print("%d place(s) in src/app ask which backend runs: ask the backend table instead "
              "(engine_backend.h; docs/architecture.md, \"Adding a backend\")" % len(hits))
        return 1
    print("src/app: %d files, no test of which backend runs" % nfile)
    return 0


if __name__ == "__main__":
    sys.exit(main())
