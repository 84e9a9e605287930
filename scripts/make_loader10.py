#!/usr/bin/env python3
"""Writes assets/models/loader10.json: the second shipped crane, a ~10 t m
knuckle-boom loader crane (docs/model.md "The second crane: loader10").

  column (slew drive), lifting arm, knuckle arm, two telescopic extensions
  (a cylinder each, both on one valve section), a load-sensing circuit with
  a post-compensated section each for lift, jib, ext and slew.

Run from the repository root: python3 scripts/make_loader10.py. The file is
kept in git; the script is how it is changed. With --check it writes nothing
and fails when the file differs from what it would write (ctest
test_loader10_current).

The figures and where each comes from are in docs/model.md. The cylinders
are not guessed: make_chain_models.size_cylinders fits each closed length
and stroke to its joint's limits (5 mm spare at each end) and picks the
smallest standard bore whose rod side holds the worst static load of
SIZING_LOAD at the tip over a grid of poses at 70 % of the pump's cut-off.
"""
import copy
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_chain_models as mcm  # noqa: E402  (the shared kinematics and sizing)

ROOT = mcm.ROOT
OUT = os.path.join(ROOT, "assets", "models", "loader10.json")
G = 9.81

P_CUTOFF = 25e6        # LS pump cut-off [Pa] (docs/model.md: class working pressure)
SIZING_LOAD = 1000.0   # [kg] at the tip over every pose: ~80 kN m at the 7.9 m reach
LOAD = 600.0           # the model's default load [kg]
Q_PUMP = 40.0 / 60000  # 40 L/min [m^3/s]
SLEW_RANGE_DEG = 400.0 # slew range, rack and pinion
PINION_R = 0.12        # [m]


def linkage_length(bodies, a, q):
    """The cylinder length [m] of actuator a through its linkage at the
    knuckle angle q [rad] (the loop in the parent's (x, z); src/world/
    mechanism/linkage.c solves the same), or None where it cannot close."""
    k = a["linkage"]
    b = next(x for x in bodies if x["name"] == k["body"])
    J, th = (b["origin"][0], b["origin"][2]), b.get("angle0", 0.0) + q
    c, A, B = k["rocker_pin"], k["link_pin"], a["base"]["point"]
    C = (J[0] + math.cos(th) * c[0] - math.sin(th) * c[2], J[1] + math.sin(th) * c[0] + math.cos(th) * c[2])
    dx, dz = C[0] - A[0], C[1] - A[2]
    D = math.hypot(dx, dz)
    l1, l2 = k["link_len"], k["rocker_len"]
    f = (l1 * l1 - l2 * l2 + D * D) / (2 * D)
    if l1 * l1 - f * f <= 0:
        return None
    h = k["branch"] * math.sqrt(l1 * l1 - f * f)
    P = (A[0] + (f * dx - h * dz) / D, A[2] + (f * dz + h * dx) / D)
    return math.dist(P, (B[0], B[2]))


_direct_length = mcm.local_pin_length


def local_pin_length(bodies, a, child, qj):
    """mcm.local_pin_length, through the linkage for an actuator with one."""
    if "linkage" in a:
        return linkage_length(bodies, a, qj)
    return _direct_length(bodies, a, child, qj)


mcm.local_pin_length = local_pin_length


def lmin(q):
    """L/min to m^3/s."""
    return round(q / 60000.0, 8)


def bodies_and_actuators():
    bodies = [
        {"name": "column", "joint": "slew", "height": 1.9, "mass": 330.0, "radius": 0.16},
        # Lifting arm: 70..160 deg from the downward vertical (the range a
        # single lift cylinder covers on the default crane).
        {"name": "lifting_arm", "joint": "revolute", "origin": [0, 0, 1.9], "angle0": -0.5 * math.pi,
         "length": 2.9, "mass": 260.0, "com": [1.45, 0, 0], "width": 0.2, "height": 0.28,
         "limits": [1.23, 2.78]},
        # Knuckle (outer) arm, the housing of the extensions: -149..-11 deg
        # through the jib cylinder's four-bar linkage (a direct cylinder
        # covered -126..-26 deg; docs/model.md).
        {"name": "knuckle_arm", "joint": "revolute", "origin": [2.9, 0, 0], "length": 2.3, "mass": 170.0,
         "com": [1.1, 0, 0], "width": 0.17, "height": 0.24, "limits": [-2.6, -0.2]},
        # Two extensions, 1.3 m each, nested: flush-ish with the housing's
        # tip when retracted (offset0 + length = housing length - 0.2 m).
        {"name": "ext1", "joint": "prismatic", "parent": "knuckle_arm", "offset0": 0.3, "length": 2.0,
         "mass": 75.0, "com": [1.0, 0, 0], "width": 0.14, "height": 0.2, "limits": [0.0, 1.3]},
        {"name": "ext2", "joint": "prismatic", "parent": "ext1", "offset0": 0.2, "length": 1.8,
         "mass": 55.0, "com": [0.9, 0, 0], "width": 0.11, "height": 0.17, "limits": [0.0, 1.3]},
    ]
    bodies[1:] = mcm.box_inertia_list(bodies[1:])
    acts = [
        {"name": "lift", "cylinder": "lift_cyl", "valve": "lift_valve",
         "base": {"body": "column", "point": [0.32, 0, 1.2]},
         "rod": {"body": "lifting_arm", "point": [1.85, 0, -0.25]}},
        # The jib cylinder through a four-bar linkage (docs/model.md): its rod
        # pushes the common pin of a link (0.70 m, pinned on the lifting
        # arm's tip) and a rocker (0.45 m, pinned on the knuckle arm).
        {"name": "jib", "cylinder": "jib_cyl", "valve": "jib_valve",
         "base": {"body": "lifting_arm", "point": [0.9, 0, 0.3]},
         "linkage": {"body": "knuckle_arm", "link_pin": [2.8, 0, 0.27], "rocker_pin": [0.39, 0, 0.07],
                     "link_len": 0.7, "rocker_len": 0.45, "branch": -1, "link_mass": 17.0, "rocker_mass": 14.0}},
        # One cylinder per stage, inside the booms, both on the ext section.
        {"name": "ext1", "cylinder": "ext1_cyl", "valve": "ext_valve",
         "base": {"body": "knuckle_arm", "point": [0.25, 0, 0.03]},
         "rod": {"body": "ext1", "point": [1.75, 0, 0.03]}},
        {"name": "ext2", "cylinder": "ext2_cyl", "valve": "ext_valve",
         "base": {"body": "ext1", "point": [0.15, 0, 0.03]},
         "rod": {"body": "ext2", "point": [1.6, 0, 0.03]}},
    ]
    return bodies, acts


# ---- the load-sensing circuit: hiab031_ls's sections, one per function ----

def ls_section(ls, fn, cyls, sizes, cbv_setting, q_nom):
    """One post-compensated LS section (compensator, valve, LS shuttle,
    hoses, counterbalance valve on the piston side when cbv_setting, port
    reliefs, anti-cavitation checks) after hiab031_ls's lift section, for
    valve `fn`_valve and its cylinders (a second cylinder on the same
    section: tee orifices from the first cylinder's hoses)."""
    comps = {c["name"]: c for c in ls["hydraulics"]["components"]}
    nodes = {n["name"]: n for n in ls["hydraulics"]["nodes"]}
    out_n, out_c = [], []
    for suffix in ("P", "ls"):
        n = copy.deepcopy(nodes["lift_" + suffix])
        n["name"] = f"{fn}_{suffix}"
        out_n.append(n)
    c = copy.deepcopy(comps["lift_comp"])
    c.update(name=fn + "_comp", outlet=fn + "_P", load=fn + "_ls")
    out_c.append(c)
    v = copy.deepcopy(comps["lift_valve"])
    v.update(name=fn + "_valve", P=fn + "_P", A=fn + "_hose_A", B=fn + "_hose_B", q_nominal=q_nom)
    out_c.append(v)
    s = copy.deepcopy(comps["lift_shuttle"])
    s.update(name=fn + "_shuttle", a=fn + "_hose_A", b=fn + "_hose_B", out=fn + "_ls", valve=fn + "_valve")
    out_c.append(s)
    for i, cyl in enumerate(cyls):
        pre = fn if i == 0 else cyl
        for side in "AB":
            hose = copy.deepcopy(comps["lift_hose_" + side])
            to = f"{cyl}_cyl.{side}"
            if side == "A" and cbv_setting:
                to = f"{cyl}_cbv_A"
            hose.update(name=f"{pre}_hose_{side}", to=to)
            out_c.append(hose)
            if i:
                out_c.append({"name": f"{cyl}_tee_{side}", "type": "orifice", "inlet": f"{fn}_hose_{side}",
                              "outlet": f"{pre}_hose_{side}", "area": 1e-4, "cd": 0.7})
        if cbv_setting:
            for suffix in ("cbv_A", "cbv_pilot"):
                n = copy.deepcopy(nodes["lift_" + suffix])
                n["name"] = f"{cyl}_{suffix}"
                out_n.append(n)
            cb = copy.deepcopy(comps["lift_cbv"])
            cb.update(name=cyl + "_cbv", valve=cyl + "_cbv_A", load=cyl + "_cyl.A", pilot=cyl + "_cbv_pilot",
                      p_setting=cbv_setting)
            out_c.append(cb)
            d = copy.deepcopy(comps["lift_cbv_damping"])
            d.update(name=cyl + "_cbv_damping", inlet=f"{pre}_hose_B", outlet=cyl + "_cbv_pilot")
            out_c.append(d)
        cy = copy.deepcopy(comps["lift_cyl"])
        closed, stroke, bore, rod, _ = sizes[cyl]
        cy.update(name=cyl + "_cyl", bore=bore, rod=rod, stroke=round(stroke, 4))
        out_c.append(cy)
        for side in "AB":
            r = copy.deepcopy(comps["lift_relief_" + side])
            r.update(name=f"{cyl}_relief_{side}", inlet=f"{cyl}_cyl.{side}", p_crack=P_CUTOFF + 4e6,
                     q_rated=q_nom)
            out_c.append(r)
        for side in "AB":
            k = copy.deepcopy(comps["lift_check_" + side])
            k.update(name=f"{cyl}_check_{side}", outlet=f"{cyl}_cyl.{side}", q_rated=q_nom)
            out_c.append(k)
    return out_n, out_c


def circuit(ls, sizes):
    h = copy.deepcopy(ls["hydraulics"])
    keep_n = [n for n in h["nodes"] if n["name"] in ("tank", "pump_line", "ls_line")]
    comps = {c["name"]: c for c in h["components"]}
    pump = copy.deepcopy(comps["pump"])
    pump.update(q_max=round(Q_PUMP, 8), p_cutoff=P_CUTOFF)
    relief = copy.deepcopy(comps["main_relief"])
    relief.update(p_crack=P_CUTOFF + 2e6, q_rated=round(1.2 * Q_PUMP, 8))
    keep_c = [pump, relief]
    # The LS signal: the highest of the three boom sections' (two shuttles,
    # the last into ls_line; hydraulics_slew re-routes it through the slew's).
    keep_n.append({"name": "ls_lift_jib", "type": "volume", "volume": 5e-06, "p0": 100000.0})
    keep_c.append({"name": "ls_shuttle_lj", "type": "shuttle", "a": "lift_ls", "b": "jib_ls", "out": "ls_lift_jib"})
    keep_c.append({"name": "ls_shuttle", "type": "shuttle", "a": "ls_lift_jib", "b": "ext_ls", "out": "ls_line"})
    # Counterbalance valves: lift and jib hold their booms (as hiab031_ls,
    # settings 4 MPa over the port reliefs' cut-off share, see docs); the
    # extensions are held by the closed spool (docs/decisions.d/crane2.md).
    for fn, cyls, cbv in (("lift", ["lift"], P_CUTOFF + 4e6), ("jib", ["jib"], P_CUTOFF + 2e6),
                          ("ext", ["ext1", "ext2"], None)):
        n, c = ls_section(ls, fn, cyls, sizes, cbv, round(Q_PUMP, 8))
        keep_n += n
        keep_c += c
    h["nodes"] = keep_n
    h["components"] = keep_c
    return h


def slew_circuit(ls):
    hs = copy.deepcopy(ls["hydraulics_slew"])
    comps = {c["name"]: c for c in hs["components"]}
    # Rack cylinder: stroke = the slew range on the pinion; bore for ~11 kN m
    # at the 16 MPa port reliefs (docs/model.md).
    stroke = round(math.radians(SLEW_RANGE_DEG) * PINION_R, 4)
    comps["slew_cyl"].update(bore=0.09, rod=0.03, stroke=stroke)
    comps["slew_valve"].update(q_nominal=lmin(15.0))
    for side in "AB":
        comps["slew_relief_" + side].update(q_rated=lmin(15.0))
    return hs


def main():
    with open(os.path.join(ROOT, "assets", "models", "hiab031_ls.json")) as f:
        ls = json.load(f)
    bodies, acts = bodies_and_actuators()
    tip_body, tip = 4, [1.8, 0, 0]
    # The sizing names the knuckle as a linkage cylinder's "rod" body (its
    # lengths come from local_pin_length above); the file has no rod there.
    for a in acts:
        if "linkage" in a:
            a["rod"] = {"body": a["linkage"]["body"], "point": [0, 0, 0]}
    sizes = mcm.size_cylinders(bodies, acts, tip_body, tip, SIZING_LOAD)
    for a in acts:
        if "linkage" in a:
            del a["rod"]
    # size_cylinders sized at the hiab031 pump's 20 MPa; re-pick each bore
    # at this crane's cut-off (the same 70 % rule).
    for a in acts:
        closed, stroke, _, _, worst = sizes[a["name"]]
        for bore in mcm.BORES:
            rod = round(0.6 * bore, 4)
            if worst <= mcm.HOLD_FRACTION * P_CUTOFF * math.pi / 4 * (bore * bore - rod * rod):
                break
        else:
            sys.exit(f"{a['name']}: {worst:.0f} N needs a bore over {mcm.BORES[-1]} m")
        sizes[a["name"]] = (closed, stroke, bore, rod, worst)
        a["closed_length"] = round(closed, 4)
    slew = {"pinion_radius": PINION_R, "cylinder": "slew_cyl", "valve": "slew_valve",
            "column_radius": bodies[0]["radius"], "damping": 3000}
    doc = {
        "name": "loader10: 10 t m knuckle-boom crane, two extensions, load sensing (estimated, docs/model.md)",
        "description": "Second shipped crane (scripts/make_loader10.py): slewing column (rack and pinion, 400 deg), "
                       "lifting arm, knuckle arm with the jib cylinder through a four-bar linkage, two telescopic extensions with a cylinder "
                       "each on one valve section; LS pump 40 L/min, 25 MPa cut-off, a post-compensated section each "
                       "for lift, jib, ext and slew, counterbalance valves on lift and jib. Figures and their sources: "
                       "docs/model.md, 'The second crane: loader10'.",
        "mechanics": {"gravity": G, "load_mass": LOAD, "rated_moment": 98.0, "rated_load": 4000.0,
                      "bodies": bodies, "tip": {"body": bodies[tip_body]["name"], "point": tip},
                      "actuators": acts,
                      "functions": [{"name": "lift", "valve": "lift_valve"}, {"name": "jib", "valve": "jib_valve"},
                                    {"name": "ext", "valve": "ext_valve"}],
                      "slew": slew},
        "hydraulics": circuit(ls, sizes),
        "hydraulics_slew": slew_circuit(ls)}
    text = mcm.dumps(mcm.strip(doc)) + "\n"
    if "--check" in sys.argv[1:]:
        try:
            with open(OUT) as f:
                same = f.read() == text
        except OSError:
            same = False
        if not same:
            sys.exit("assets/models/loader10.json is not what scripts/make_loader10.py writes "
                     "(run it, or edit it instead of the file)")
        return
    with open(OUT, "w") as f:
        f.write(text)
    print("wrote", os.path.relpath(OUT, ROOT))
    for a, (closed, stroke, bore, rod, worst) in sizes.items():
        print(f"  {a:5s} closed {closed:.3f} m  stroke {stroke:.3f} m  bore {bore * 1e3:.0f} mm  "
              f"rod {rod * 1e3:.0f} mm  worst holding force {worst / 1e3:.1f} kN")


if __name__ == "__main__":
    main()
