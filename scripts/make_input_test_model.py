#!/usr/bin/env python3
"""Writes tests/world/data/chain_6fn_controls.json: the test model of the
input mapping by function (docs/render.md "Mapping by function",
tests/render/test_input_map.c, tests/app/test_drive_functions.c).

chain_3boom_ext.json's crane (scripts/make_chain_models.py: lift, jib, jib2,
ext) with a second extension (ext2) sliding in the first: five functions on
the chain, six in the sandbox, which adds its slew drive. Its cylinders are
sized by make_chain_models.py's own rules (size_cylinders). A "controls"
section moves ext2 from its default place (the shoulder buttons, Insert /
Delete) to the d-pad and the keys Y / N, so a test can tell the model's
mapping from the defaults.

Run from the repository root: python3 scripts/make_input_test_model.py.
With --check it writes nothing and fails when the file differs from what it
would write (ctest test_input_model_current).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_chain_models as mcm  # noqa: E402
import json  # noqa: E402


def chain_6fn_controls(base):
    doc, _ = mcm.chain_3boom_ext(base)
    m = doc["mechanics"]
    load = m["load_mass"] = 200.0
    bodies = mcm.strip(m["bodies"])
    # A second extension inside the first: 0.8 m stroke, as a jib extension
    # of chain_8fn_10link.json.
    bodies.append({"name": "ext2", "joint": "prismatic", "parent": "ext", "origin": [0, 0, 0], "offset0": 0.3,
                   "length": 1.2, "mass": 25.0, "com": [0.6, 0, 0], "width": 0.08, "height": 0.1,
                   "limits": [0.0, 0.8]})
    bodies[-1:] = mcm.box_inertia_list(bodies[-1:])
    acts = [{k: v for k, v in a.items() if k != "closed_length"} for a in mcm.strip(m["actuators"])]
    acts.append({"name": "ext2", "cylinder": "ext2_cyl", "valve": "ext2_valve",
                 "base": {"body": "ext", "point": [0.1, 0, 0.02]},
                 "rod": {"body": "ext2", "point": [1.0, 0, 0.02]}})
    tip_body, tip = len(bodies) - 1, [1.2, 0, 0]
    sizes = mcm.size_cylinders(bodies, acts, tip_body, tip, load)
    for a in acts:
        a["closed_length"] = round(sizes[a["name"]][0], 4)
    doc = {
        "name": "Knuckle-boom crane with a third boom and two extensions (input mapping test model)",
        "description": "chain_3boom_ext.json with a second extension: five functions (lift, jib, jib2, ext, "
                       "ext2), six with the sandbox's slew; its controls put ext2 on the d-pad and Y / N "
                       "(scripts/make_input_test_model.py, docs/render.md).",
        "mechanics": {"gravity": mcm.G, "load_mass": load, "bodies": bodies,
                      "tip": {"body": "ext2", "point": tip}, "actuators": acts,
                      "functions": [{"name": a["name"], "valve": a["valve"]} for a in acts]},
        "hydraulics": mcm.circuit(base, [(a["name"], [a["name"]]) for a in acts], sizes),
        "controls": {"axes": {"ext2": {"controller": ["dpup", "dpdown"], "joystick_buttons": [5, 4],
                                       "keys": ["Y", "N"]}}},
    }
    return doc


def main():
    with open(os.path.join(mcm.ROOT, "assets", "models", "hiab031.json")) as f:
        base = json.load(f)
    mcm.write("chain_6fn_controls.json", chain_6fn_controls(base))
    if mcm.STALE:
        sys.exit("stale (run python3 scripts/make_input_test_model.py): " + ", ".join(mcm.STALE))


if __name__ == "__main__":
    main()
