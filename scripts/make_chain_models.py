#!/usr/bin/env python3
"""Writes the chain-form test models (docs/model.md "The chain form"):

  tests/world/data/hiab031_chain.json    the default crane (assets/models/hiab031.json)
                                         written in the chain form, value for value
  tests/world/data/chain_3boom_ext.json  column, lifting arm, end arm, a third boom
                                         (jib) and a telescopic extension in it:
                                         4 functions (lift, jib, jib2, ext)
  tests/world/data/chain_8fn_10link.json 10 bodies (5 of them extensions), 8 functions,
                                         9 cylinders (two extension cylinders on one valve)

Run from the repository root: python3 scripts/make_chain_models.py. The
generated files are kept in git; the script is how they are changed.
With --check it writes nothing and fails when a file differs from what it
would write (ctest test_chain_models_current).

Every geometric value is an estimate for a knuckle-boom crane of the class of
the shipped HIAB 031 model (docs/model.md says which). The cylinders are not
guessed: for each actuator the script takes the joint range it must cover
(the body's limits), computes the pin length over that range with the same
kinematics as the mechanism library (src/world/mechanism/chain.h), and sets
the closed length and stroke so the cylinder spans exactly that range plus
5 mm at each end; the bore is the smallest standard one whose weaker side
(the rod annulus) holds the worst static load of the rated tip load over the
joint limits at 70 % of the pump setting.
"""
import copy
import itertools
import json
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "world", "data")
G = 9.81
P_PUMP = 20e6          # the hiab031 pump's setting [Pa]
HOLD_FRACTION = 0.7    # holding force at most this share of p_pump x A_annulus
END_MARGIN = 0.005     # stroke left at each end of the joint range [m]
BORES = [0.05, 0.063, 0.08, 0.1, 0.125, 0.14, 0.16, 0.18, 0.2, 0.22, 0.25]


# ---- kinematics (chain.h's frames, in the boom plane x-z) -----------------

def rot(th, p):
    """Point p of a frame turned by th in the boom plane (x towards z)."""
    c, s = math.cos(th), math.sin(th)
    return (c * p[0] - s * p[2], p[1], s * p[0] + c * p[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def poses(bodies, q):
    """Each body's (angle in the column's boom plane, origin in the column
    frame); the column fixed at slew 0 so its frame is the base's."""
    out = [(0.0, tuple(bodies[0].get("origin", [0, 0, 0])))]
    for i, b in enumerate(bodies[1:], start=1):
        pa, po = out[b["_parent"]]
        o = add(po, rot(pa, tuple(b.get("origin", [0, 0, 0]))))
        a0 = b.get("angle0", 0.0)
        if b["joint"] == "revolute":
            out.append((pa + a0 + q[i - 1], o))
        else:
            th = pa + a0
            out.append((th, add(o, rot(th, (b.get("offset0", 0.0) + q[i - 1], 0, 0)))))
    return out


def world(pose, p):
    th, o = pose
    return add(o, rot(th, tuple(p)))


def resolve(bodies, acts):
    names = [b["name"] for b in bodies]
    for i, b in enumerate(bodies[1:], start=1):
        b["_parent"] = names.index(b.get("parent", names[i - 1]))
    for a in acts:
        a["_a"] = names.index(a["base"]["body"])
        a["_b"] = names.index(a["rod"]["body"])


def box_inertia_list(bodies):
    """The bodies with an "inertia" (after "com") of a uniform box about its
    centre, about y: m (L^2 + h^2) / 12."""
    res = []
    for b in bodies:
        I = round(b["mass"] * (b["length"] ** 2 + b["height"] ** 2) / 12, 4)
        out = {}
        for k, v in b.items():
            out[k] = v
            if k == "com":
                out["inertia"] = I
        res.append(out)
    return res


def strip(o):
    """The document without the script's working fields (keys starting _)."""
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if not k.startswith("_")}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o


# ---- cylinders fitted to the joint ranges --------------------------------

def local_pin_length(bodies, a, child, qj):
    """Pin length of actuator a across the joint of `child` at qj [m]: the
    child's pin in the parent's frame (the other joints do not matter)."""
    b = bodies[child]
    pc, pp = (a["rod"]["point"], a["base"]["point"]) if a["_b"] == child else (a["base"]["point"], a["rod"]["point"])
    a0, o = b.get("angle0", 0.0), tuple(b.get("origin", [0, 0, 0]))
    if b["joint"] == "revolute":
        w = add(o, rot(a0 + qj, tuple(pc)))
    else:
        w = add(o, rot(a0, (pc[0] + b.get("offset0", 0.0) + qj, pc[1], pc[2])))
    return math.dist(w, tuple(pp))


def size_cylinders(bodies, acts, tip_body, tip, load):
    """closed_length and stroke over each actuator's joint range; the bore
    that holds the worst static joint load. Returns {actuator: (closed,
    stroke, bore, rod, worst force N)}."""
    resolve(bodies, acts)
    n = len(bodies) - 1
    # The bodies each joint carries (itself and its descendants).
    carried = [{i} for i in range(len(bodies))]
    for i in range(len(bodies) - 1, 0, -1):
        carried[bodies[i]["_parent"]] |= carried[i]
    coms = [b.get("com", [0, 0, 0.5 * b.get("height", 0)]) if i == 0 else b["com"] for i, b in enumerate(bodies)]
    fit = []
    for a in acts:
        child = a["_b"] if bodies[a["_b"]]["_parent"] == a["_a"] else a["_a"]
        lo, hi = bodies[child]["limits"]
        Ls = [local_pin_length(bodies, a, child, lo + (hi - lo) * s / 400) for s in range(401)]
        fit.append((child, min(Ls) - END_MARGIN, max(Ls) - min(Ls) + 2 * END_MARGIN))
    # Worst static force of each cylinder over a grid of poses within the
    # limits (5 points a joint up to 4 joints, else 3: 3^9 poses for 9):
    # F = tau_j / (dL/dq_j), tau_j = -dV/dq_j by virtual work (a rotation
    # about the joint raises a point by its horizontal distance from the
    # joint, a slide by the sine of its angle).
    npt = 5 if n <= 4 else 3
    grid = [[b["limits"][0] + (b["limits"][1] - b["limits"][0]) * k / (npt - 1) for k in range(npt)]
            for b in bodies[1:]]
    worst = [0.0] * len(acts)
    h = 1e-6
    for q in itertools.product(*grid):
        ps = poses(bodies, q)
        r = [world(ps[i], coms[i]) for i in range(len(bodies))]
        rt = world(ps[tip_body], tip)
        for k, a in enumerate(acts):
            child = fit[k][0]
            th, o = ps[child]
            if bodies[child]["joint"] == "revolute":
                dV = sum(bodies[i]["mass"] * G * (r[i][0] - o[0]) for i in carried[child])
                dV += load * G * (rt[0] - o[0]) if tip_body in carried[child] else 0.0
            else:
                m = sum(bodies[i]["mass"] for i in carried[child]) + (load if tip_body in carried[child] else 0.0)
                dV = m * G * math.sin(th)
            qj = q[child - 1]
            dL = (local_pin_length(bodies, a, child, qj + h) - local_pin_length(bodies, a, child, qj - h)) / (2 * h)
            if abs(dL) < 1e-9:
                sys.exit(f"{a['name']}: no lever arm at {q}")
            worst[k] = max(worst[k], abs(dV / dL))
    out = {}
    for k, a in enumerate(acts):
        _, closed, stroke = fit[k]
        for bore in BORES:
            rod = round(0.6 * bore, 4)
            ann = math.pi / 4 * (bore * bore - rod * rod)
            if worst[k] <= HOLD_FRACTION * P_PUMP * ann:
                break
        else:
            sys.exit(f"{a['name']}: {worst[k]:.0f} N needs a bore over {BORES[-1]} m")
        out[a["name"]] = (closed, stroke, bore, rod, worst[k])
        if closed < stroke + 0.2:
            print(f"note: {a['name']}: closed length {closed:.3f} m < stroke {stroke:.3f} m + 0.2 m", file=sys.stderr)
    return out


# ---- the circuit: hiab031's, one section per function ---------------------

def section(base, valve, cyls, sizes):
    """The hiab031 lift section (valve, hoses, cylinder, port reliefs,
    anti-cavitation checks) for one valve and its cylinders (several
    cylinders on one valve: a tee orifice from the first cylinder's hose to
    each further one's)."""
    comps = {c["name"]: c for c in base["hydraulics"]["components"]}
    out = []
    v = copy.deepcopy(comps["lift_valve"])
    v.update(name=valve + "_valve", A=valve + "_hose_A", B=valve + "_hose_B")
    out.append(v)
    for i, cyl in enumerate(cyls):
        for side in "AB":
            hose = copy.deepcopy(comps["lift_hose_" + side])
            hname = f"{valve}_hose_{side}" if i == 0 else f"{cyl}_hose_{side}"
            hose.update(name=hname, to=f"{cyl}_cyl.{side}")
            out.append(hose)
            if i:
                out.append({"name": f"{cyl}_tee_{side}", "type": "orifice", "inlet": f"{valve}_hose_{side}",
                            "outlet": hname, "area": 1e-4, "cd": 0.7})
        c = copy.deepcopy(comps["lift_cyl"])
        closed, stroke, bore, rod, _ = sizes[cyl]
        c.update(name=cyl + "_cyl", bore=bore, rod=rod, stroke=round(stroke, 4))
        out.append(c)
        for side in "AB":
            r = copy.deepcopy(comps["lift_relief_" + side])
            r.update(name=f"{cyl}_relief_{side}", inlet=f"{cyl}_cyl.{side}")
            out.append(r)
        for side in "AB":
            k = copy.deepcopy(comps["lift_check_" + side])
            k.update(name=f"{cyl}_check_{side}", outlet=f"{cyl}_cyl.{side}")
            out.append(k)
    return out


def circuit(base, functions, sizes):
    h = copy.deepcopy(base["hydraulics"])
    keep = [c for c in h["components"] if c["name"] in ("pump", "main_relief")]
    for valve, cyls in functions:
        keep += section(base, valve, cyls, sizes)
    h["components"] = keep
    return h


def dumps(o, ind=0):
    """hiab031.json's layout: objects one member a line, each element of a
    list of objects on one line, lists of numbers inline."""
    pad = "  " * (ind + 1)
    if isinstance(o, dict) and ind < 2:
        items = [f"{pad}{json.dumps(k)}: {dumps(v, ind + 1)}" for k, v in o.items()]
        return "{\n" + ",\n".join(items) + "\n" + "  " * ind + "}"
    if isinstance(o, list) and o and all(isinstance(v, dict) for v in o):
        items = [pad + json.dumps(v, separators=(", ", ": ")) for v in o]
        return "[\n" + ",\n".join(items) + "\n" + "  " * ind + "]"
    return json.dumps(o, separators=(", ", ": "))


CHECK = "--check" in sys.argv[1:]
STALE = []


def write(name, doc):
    path = os.path.join(OUT, name)
    text = dumps(strip(doc)) + "\n"
    if CHECK:
        # The files in git must be what this script writes (edit the script,
        # not the files).
        try:
            with open(path) as f:
                same = f.read() == text
        except OSError:
            same = False
        if not same:
            STALE.append(os.path.relpath(path, ROOT))
        return
    with open(path, "w") as f:
        f.write(text)
    print("wrote", os.path.relpath(path, ROOT))


# ---- 1. hiab031 in the chain form ----------------------------------------

def hiab031_chain(base):
    m = base["mechanics"]
    h = m["column"]["height"]
    L = m["links"]
    doc = {
        "name": "HIAB 031 class knuckle-boom crane, chain form (the default crane, docs/model.md)",
        "description": "assets/models/hiab031.json with its mechanics written as a chain of bodies "
                       "(scripts/make_chain_models.py): the same crane, value for value.",
        "mechanics": {
            "gravity": m["gravity"], "load_mass": m["load_mass"],
            "rated_moment": m["rated_moment"], "rated_load": m["rated_load"],
            "bodies": [{"name": "column", "joint": "slew", "height": h, "mass": m["column"]["mass"],
                        # the slew drive's column: one column, one radius
                        "radius": m["slew"]["column_radius"] if "slew" in m else 0.1}],
            "tip": {"body": L[1]["name"], "point": [L[1]["length"], 0, 0]},
            "actuators": [], "functions": []}}
    for i, l in enumerate(L):
        # The shorthand's joints: joint 1 on the column axis at its top, q1
        # from the downward vertical (angle0 = -pi/2); joint 2 at the lifting
        # arm's tip, q2 relative to it (mechanism/chain_crane.c).
        doc["mechanics"]["bodies"].append({
            "name": l["name"], "joint": "revolute",
            "origin": [L[0]["length"] if i else 0.0, 0, 0.0 if i else h],
            "angle0": 0.0 if i else -0.5 * math.pi,
            "length": l["length"], "mass": l["mass"], "com": [l["com"], 0, 0], "inertia": l["inertia"],
            "width": l["width"], "height": l["height"]})
    for a in m["actuators"]:
        j = a["joint"]
        # Mounts relative to the joint they act across, moved into the body
        # frames: the lift's barrel on the column (+ h), the jib's on the
        # lifting arm (+ its length), the same sums chain_crane.c makes.
        bm, rm = a["base_mount"], a["rod_mount"]
        doc["mechanics"]["actuators"].append({
            "name": a["name"], "cylinder": a["cylinder"], "valve": a["valve"],
            "base": {"body": "column" if j == 0 else L[0]["name"],
                     "point": [bm[0] + (L[0]["length"] if j else 0.0), 0, bm[1] + (0.0 if j else h)]},
            "rod": {"body": L[j]["name"], "point": [rm[0], 0, rm[1]]},
            "closed_length": a["closed_length"]})
        doc["mechanics"]["functions"].append({"name": a["name"], "valve": a["valve"]})
    # The slew drive, as the shorthand has it (both forms take it as it is).
    doc["mechanics"]["slew"] = m["slew"]
    doc["hydraulics"] = base["hydraulics"]
    doc["hydraulics_slew"] = base["hydraulics_slew"]
    return doc


# ---- 2. three booms and an extension --------------------------------------

def chain_3boom_ext(base):
    load = 300.0
    bodies = [
        {"name": "column", "joint": "slew", "height": 1.6, "mass": 250.0, "radius": 0.1},
        # The lifting arm and the end arm of the default crane, limited to
        # the joint ranges its cylinders cover (lift 70..160 deg from the
        # downward vertical, jib -135..-37 deg).
        {"name": "lifting_arm", "joint": "revolute", "origin": [0, 0, 1.6], "angle0": -0.5 * math.pi,
         "length": 2.3, "mass": 180.0, "com": [1.15, 0, 0], "inertia": 79.35, "width": 0.18, "height": 0.24,
         "limits": [1.23, 2.78]},
        {"name": "end_arm", "joint": "revolute", "origin": [2.3, 0, 0], "length": 2.5, "mass": 140.0,
         "com": [1.25, 0, 0], "inertia": 72.916667, "width": 0.15, "height": 0.2, "limits": [-2.35, -0.65]},
        # A third boom (knuckle jib) on the end arm's tip, lighter.
        {"name": "jib2", "joint": "revolute", "origin": [2.5, 0, 0], "length": 2.0, "mass": 90.0,
         "com": [1.0, 0, 0], "width": 0.13, "height": 0.17, "limits": [-0.5, 1.2]},
        # A telescopic extension sliding inside the third boom: 1 m stroke,
        # flush with its tip when retracted.
        {"name": "ext", "joint": "prismatic", "parent": "jib2", "origin": [0, 0, 0], "offset0": 0.4,
         "length": 1.6, "mass": 45.0, "com": [0.8, 0, 0], "width": 0.1, "height": 0.13,
         "limits": [0.0, 1.0]},
    ]
    bodies[3:] = box_inertia_list(bodies[3:])
    tip_body, tip = 4, [1.6, 0, 0]
    acts = [
        {"name": "lift", "cylinder": "lift_cyl", "valve": "lift_valve",
         "base": {"body": "column", "point": [0.2113, 0, 1.1468]},
         "rod": {"body": "lifting_arm", "point": [1.5541, 0, -0.136]}},
        {"name": "jib", "cylinder": "jib_cyl", "valve": "jib_valve",
         "base": {"body": "lifting_arm", "point": [1.1046, 0, 0.1046]},
         "rod": {"body": "end_arm", "point": [0.3864, 0, -0.1035]}},
        # The third boom's cylinder lies along the end arm, above it.
        {"name": "jib2", "cylinder": "jib2_cyl", "valve": "jib2_valve",
         "base": {"body": "end_arm", "point": [1.0, 0, 0.12]},
         "rod": {"body": "jib2", "point": [-0.25, 0, 0.4]}},
        # The extension cylinder inside the third boom.
        {"name": "ext", "cylinder": "ext_cyl", "valve": "ext_valve",
         "base": {"body": "jib2", "point": [0.15, 0, 0.02]},
         "rod": {"body": "ext", "point": [1.3, 0, 0.02]}},
    ]
    sizes = size_cylinders(bodies, acts, tip_body, tip, load)
    for a in acts:
        a["closed_length"] = round(sizes[a["name"]][0], 4)
    functions = [(a["name"], [a["name"]]) for a in acts]
    doc = {
        "name": "Knuckle-boom crane with a third boom and one extension (test model, estimated values)",
        "description": "Four hydraulic functions (lift, jib, jib2, ext), each a 4/3 valve section of the hiab031 "
                       "circuit with its own cylinder; cylinders fitted to the joint limits and sized to hold "
                       f"{load:g} kg at the tip (scripts/make_chain_models.py, docs/model.md).",
        "mechanics": {"gravity": G, "load_mass": load,
                      "bodies": bodies, "tip": {"body": bodies[tip_body]["name"], "point": tip},
                      "actuators": acts,
                      "functions": [{"name": a["name"], "valve": a["valve"]} for a in acts]},
        "hydraulics": circuit(base, functions, sizes)}
    return doc, sizes


# ---- 3. ten bodies, eight functions ---------------------------------------

def chain_8fn_10link(base):
    load = 200.0
    bodies = [
        {"name": "column", "joint": "slew", "height": 1.8, "mass": 350.0, "radius": 0.12},
        {"name": "lifting_arm", "joint": "revolute", "origin": [0, 0, 1.8], "angle0": -0.5 * math.pi,
         "length": 2.4, "mass": 200.0, "com": [1.2, 0, 0], "inertia": 96.0, "width": 0.2, "height": 0.26,
         "limits": [1.23, 2.78]},
        {"name": "end_arm", "joint": "revolute", "origin": [2.4, 0, 0], "length": 2.6, "mass": 150.0,
         "com": [1.3, 0, 0], "inertia": 84.5, "width": 0.17, "height": 0.22, "limits": [-2.35, -0.65]},
        {"name": "ext1", "joint": "prismatic", "origin": [0, 0, 0], "offset0": 0.5, "length": 2.1, "mass": 60.0,
         "com": [1.05, 0, 0], "width": 0.14, "height": 0.18, "limits": [0.0, 0.9]},
        {"name": "ext2", "joint": "prismatic", "origin": [0, 0, 0], "offset0": 0.3, "length": 1.8, "mass": 45.0,
         "com": [0.9, 0, 0], "width": 0.12, "height": 0.16, "limits": [0.0, 0.9]},
        {"name": "ext3", "joint": "prismatic", "origin": [0, 0, 0], "offset0": 0.3, "length": 1.5, "mass": 32.0,
         "com": [0.75, 0, 0], "width": 0.1, "height": 0.14, "limits": [0.0, 0.8]},
        # A jib (fly jib) at the tip of the last extension, its own three extensions.
        {"name": "jib", "joint": "revolute", "origin": [1.5, 0, 0], "length": 1.8, "mass": 70.0,
         "com": [0.9, 0, 0], "width": 0.12, "height": 0.16, "limits": [-0.6, 1.2]},
        {"name": "jib_ext1", "joint": "prismatic", "origin": [0, 0, 0], "offset0": 0.4, "length": 1.4, "mass": 25.0,
         "com": [0.7, 0, 0], "width": 0.09, "height": 0.12, "limits": [0.0, 0.7]},
        {"name": "jib_ext2", "joint": "prismatic", "origin": [0, 0, 0], "offset0": 0.3, "length": 1.2, "mass": 22.0,
         "com": [0.6, 0, 0], "width": 0.08, "height": 0.1, "limits": [0.0, 0.6]},
        {"name": "jib_ext3", "joint": "prismatic", "origin": [0, 0, 0], "offset0": 0.3, "length": 1.0, "mass": 20.0,
         "com": [0.5, 0, 0], "width": 0.07, "height": 0.09, "limits": [0.0, 0.5]},
    ]
    bodies[3:] = box_inertia_list(bodies[3:])
    tip_body, tip = 9, [1.0, 0, 0]
    ext = lambda name, parent, body, bx, rx: {
        "name": name, "cylinder": name + "_cyl", "valve": name + "_valve",
        "base": {"body": parent, "point": [bx, 0, 0.03]}, "rod": {"body": body, "point": [rx, 0, 0.03]}}
    acts = [
        {"name": "lift", "cylinder": "lift_cyl", "valve": "lift_valve",
         "base": {"body": "column", "point": [0.24, 0, 1.3]},
         "rod": {"body": "lifting_arm", "point": [1.6, 0, -0.15]}},
        {"name": "fold", "cylinder": "fold_cyl", "valve": "fold_valve",
         "base": {"body": "lifting_arm", "point": [1.15, 0, 0.12]},
         "rod": {"body": "end_arm", "point": [0.4, 0, -0.11]}},
        # Two extension stages on one valve section (ext): a cylinder each.
        ext("ext1", "end_arm", "ext1", 0.2, 1.8),
        ext("ext2", "ext1", "ext2", 0.15, 1.5),
        ext("ext3", "ext2", "ext3", 0.15, 1.2),
        {"name": "jib", "cylinder": "jib_cyl", "valve": "jib_valve",
         "base": {"body": "ext3", "point": [0.4, 0, 0.12]},
         "rod": {"body": "jib", "point": [-0.2, 0, 0.35]}},
        ext("jib_ext1", "jib", "jib_ext1", 0.15, 1.2),
        ext("jib_ext2", "jib_ext1", "jib_ext2", 0.1, 1.0),
        ext("jib_ext3", "jib_ext2", "jib_ext3", 0.1, 0.8),
    ]
    acts[3]["valve"] = "ext1_valve"  # ext2 rides on ext1's section
    sizes = size_cylinders(bodies, acts, tip_body, tip, load)
    for a in acts:
        a["closed_length"] = round(sizes[a["name"]][0], 4)
    functions = []
    for a in acts:
        v = a["valve"][: -len("_valve")]
        for f in functions:
            if f[0] == v:
                f[1].append(a["name"])
                break
        else:
            functions.append((v, [a["name"]]))
    doc = {
        "name": "Ten-body crane with eight functions (synthetic test model, estimated values)",
        "description": "Column, lifting arm, end arm with three extensions, a fly jib with three extensions: "
                       "9 cylinders on 8 valve sections (ext1 and ext2 share one), the hiab031 circuit per "
                       "section; functions left to the default (one per valve, named after its first actuator).",
        "mechanics": {"gravity": G, "load_mass": load,
                      "bodies": bodies, "tip": {"body": bodies[tip_body]["name"], "point": tip},
                      "actuators": acts},
        "hydraulics": circuit(base, functions, sizes)}
    return doc, sizes


def main():
    with open(os.path.join(ROOT, "assets", "models", "hiab031.json")) as f:
        base = json.load(f)
    os.makedirs(OUT, exist_ok=True)
    write("hiab031_chain.json", hiab031_chain(base))
    for name, make in (("chain_3boom_ext.json", chain_3boom_ext), ("chain_8fn_10link.json", chain_8fn_10link)):
        doc, sizes = make(base)
        write(name, doc)
        for a, (closed, stroke, bore, rod, worst) in sizes.items() if not CHECK else ():
            print(f"  {a:9s} closed {closed:.3f} m  stroke {stroke:.3f} m  bore {bore * 1e3:.0f} mm  "
                  f"rod {rod * 1e3:.0f} mm  worst holding force {worst / 1e3:.1f} kN")


if __name__ == "__main__":
    main()
    if STALE:
        sys.exit("not what scripts/make_chain_models.py writes (run it, or edit it instead of the file): "
                 + ", ".join(STALE))
