#!/usr/bin/env python3
"""Random sandbox drives: seeded scenario files, and runs of them.

  random_drives.py gen SEED [--duration T] [--out FILE]
      write the scenario of SEED (JSON) to FILE or stdout
  random_drives.py run --seeds 1-10[,12,...] [--model M ...] [--duration T]
                       [--stop T] [--cranesim PATH] [--keep DIR] [-- extra run options]
      generate each seed's scenario, run `cranesim run` on it with each model,
      print one line per drive and a summary per model; exit 1 when a drive
      failed (cranesim exit 1), 2 on bad usage or a refused scenario.
      --stop T runs only the first T seconds of the T-second scenarios
      (the same drive, cut short: --duration would make other scenarios).

A drive is an operator working the sticks at random for T seconds (default
120) in the sandbox world: lift, jib and slew each hold a random opening for
0.3..5 s, then move to the next one over 0..2.5 s (a third of the moves to 0,
letting go of the stick; a move of 0 s is a step); hook attach and release
alternate every 3..20 s. Half the drives start over the 200 kg load with the
hook attached at 0.5 s (the pick-and-place pose), so loaded drives happen;
the others start at a random pose. Everything comes from Python's
random.Random(seed).random(), whose sequence is fixed for an integer seed, so
a seed names the same scenario on every machine (docs/solvers.md,
"Robustness: random drives").
"""

import argparse
import json
import os
import random
import re
import subprocess
import sys
import tempfile
import time

# Limits of the scenario loader (docs/files.md): 64 points per command
# table, 32 hook events.
MAX_POINTS = 64
MAX_HOOK = 32

# The pick-and-place start (assets/scenarios/sandbox_pick_place.json): the
# hook over the 200 kg load's top, within the hook's 0.5 m reach.
PICK_POSE = {"q1_deg": 117.3, "q2_deg": -65.8, "slew_deg": -60}


def _r3(x):
    return round(x, 3)


def command_table(rng, duration):
    """One stick: [[t, u], ...], holds and ramps, at most MAX_POINTS points."""
    pts = [[0.0, 0.0]]
    t, u = 0.0, 0.0
    while len(pts) + 2 <= MAX_POINTS:
        t += 0.3 + 4.7 * rng.random()  # hold [s]
        if t >= duration:
            break
        a = rng.random()
        u_new = 0.0 if a < 1.0 / 3.0 else 2.0 * rng.random() - 1.0
        ramp = 0.0 if rng.random() < 0.2 else 2.5 * rng.random()  # a fifth are steps
        pts.append([_r3(t), _r3(u)])
        t = min(t + ramp, duration)
        u = u_new
        pts.append([_r3(t), _r3(u)])
    return pts


def scenario(seed, duration=120.0):
    """The scenario dict of seed."""
    rng = random.Random(seed)
    pick = rng.random() < 0.5
    if pick:
        initial = dict(PICK_POSE)
    else:
        # Poses the cylinders reach with the hook clear of the ground on
        # both models (q1 70..160 deg and q2 -135..-36.9 deg are the
        # default crane's stroke ranges; the rope needs the tip up).
        initial = {
            "q1_deg": _r3(100.0 + 35.0 * rng.random()),
            "q2_deg": _r3(-100.0 + 45.0 * rng.random()),
            "slew_deg": _r3(-170.0 + 340.0 * rng.random()),
        }
    commands = {k: command_table(rng, duration) for k in ("lift", "jib", "slew")}
    hook = []
    attach = True
    t = 0.5 if pick else 3.0 + 17.0 * rng.random()
    while t < duration and len(hook) < MAX_HOOK:
        hook.append([_r3(t), "attach" if attach else "release"])
        attach = not attach
        t += 3.0 + 17.0 * rng.random()
    return {
        "name": "random_drive_%d" % seed,
        "description": "scripts/random_drives.py seed %d: %g s of random lift, jib and slew commands "
        "with hook events in the sandbox%s" % (seed, duration, ", starting over the 200 kg load" if pick else ""),
        "duration": duration,
        "initial": initial,
        "commands": commands,
        "hook": hook,
    }


def parse_seeds(text):
    seeds = []
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        m = re.fullmatch(r"(\d+)-(\d+)", part)
        if m:
            a, b = int(m.group(1)), int(m.group(2))
            if b < a:
                raise ValueError("seed range %s runs backwards" % part)
            seeds.extend(range(a, b + 1))
        elif part.isdigit():
            seeds.append(int(part))
        else:
            raise ValueError("seed '%s' is not a number or a range a-b" % part)
    if not seeds:
        raise ValueError("no seeds")
    return seeds


def run_one(cranesim, scen_path, model, extra, csv_path):
    """Runs one drive; returns (exit code, wall s, failure line or '')."""
    cmd = [cranesim, "run", "--scenario", scen_path, "--out", csv_path, "--every", "0.1"]
    if model:
        cmd += ["--model", model]
    cmd += extra
    t0 = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.monotonic() - t0
    lines = [l for l in p.stderr.splitlines() if l.strip() and "note:" not in l]
    # The summary's work line says when fixed steps had to be retried in
    # sub-steps (docs/solvers.md, "Step failures of the fixed-step methods").
    m = re.search(r"(\d+) retried as (\d+) shorter steps", p.stdout)
    retried = "%s retried (%s sub-steps)" % (m.group(1), m.group(2)) if m else ""
    return p.returncode, wall, (lines[-1] if lines else ""), retried


def cmd_run(a):
    try:
        seeds = parse_seeds(a.seeds)
    except ValueError as e:
        print("random_drives.py: --seeds: %s" % e, file=sys.stderr)
        return 2
    models = a.model or [""]
    keep = a.keep
    if keep:
        os.makedirs(keep, exist_ok=True)
    tmp = tempfile.TemporaryDirectory(prefix="random_drives.")
    work = keep or tmp.name
    fails = {m: [] for m in models}
    usage = 0
    for seed in seeds:
        sp = os.path.join(work, "random_drive_%d.json" % seed)
        with open(sp, "w") as f:
            json.dump(scenario(seed, a.duration), f, indent=1)
        for m in models:
            rc, wall, msg, retried = run_one(a.cranesim, sp, m, a.extra, os.path.join(work, "run.csv"))
            name = os.path.splitext(os.path.basename(m))[0] if m else "default"
            status = {0: "ok", 1: "FAILED"}.get(rc, "exit %d" % rc)
            print("seed %d model %s: %s (%.1f s wall%s)%s" % (seed, name, status, wall,
                                                            (", steps " + retried) if retried else "",
                                                            (": " + msg) if rc else ""), flush=True)
            if rc == 1:
                fails[m].append(seed)
            elif rc != 0:
                usage = 1
    for m in models:
        name = os.path.splitext(os.path.basename(m))[0] if m else "default"
        print("model %s: %d of %d drives failed%s" % (name, len(fails[m]), len(seeds),
                                                      (" (seeds %s)" % ",".join(map(str, fails[m])))
                                                      if fails[m] else ""))
    tmp.cleanup()
    if usage:
        return 2
    return 1 if any(fails.values()) else 0


def main(argv):
    ap = argparse.ArgumentParser(prog="random_drives.py", description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    g = sub.add_parser("gen", help="write one seed's scenario")
    g.add_argument("seed", type=int)
    g.add_argument("--duration", type=float, default=120.0)
    g.add_argument("--out", default="-")
    r = sub.add_parser("run", help="generate and run drives")
    r.add_argument("--seeds", required=True, help="e.g. 1-10 or 3,7,12-14")
    r.add_argument("--model", action="append", help="model file (repeatable; default: cranesim's default model)")
    r.add_argument("--duration", type=float, default=120.0)
    r.add_argument("--stop", type=float, help="stop each run at this time [s] (cranesim run --duration)")
    r.add_argument("--cranesim", default="build/cranesim")
    r.add_argument("--keep", help="write the scenarios (and the last CSV) to this folder")
    r.add_argument("extra", nargs="*", help="after --: more `cranesim run` options (e.g. --dt 5e-5)")
    a = ap.parse_args(argv)
    if a.cmd == "gen":
        if not (0 < a.duration <= 3600):
            print("random_drives.py: --duration: must be in (0, 3600] s, got %g" % a.duration, file=sys.stderr)
            return 2
        text = json.dumps(scenario(a.seed, a.duration), indent=1) + "\n"
        if a.out == "-":
            sys.stdout.write(text)
        else:
            with open(a.out, "w") as f:
                f.write(text)
        return 0
    if not (0 < a.duration <= 3600):
        print("random_drives.py: --duration: must be in (0, 3600] s, got %g" % a.duration, file=sys.stderr)
        return 2
    if a.stop is not None:
        if not (0 < a.stop <= a.duration):
            print("random_drives.py: --stop: must be in (0, %g] s (the drives' duration), got %g" % (a.duration, a.stop),
                  file=sys.stderr)
            return 2
        a.extra = ["--duration", repr(a.stop)] + a.extra
    return cmd_run(a)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
