#!/usr/bin/env python3
"""selftest.py: check_layout.py's own test.

Builds small source trees in a scratch folder, each with a folder map in its
docs/architecture.md, and runs check_layout.py on them: a tree that follows
its map passes (with a loader split in two files of one folder, whose second
header only its folder includes); a tree with known mistakes (a folder
cycle, a module circle across folders, a module circle through a header
another folder includes, an include the map forbids, a header circle, an
include that names no file, a folder missing from the map) fails naming each
of them, and nothing else.
"""
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
MAP = """# Architecture

### Folders of src/world

| folder | holds | may include |
|---|---|---|
| `low` | the bottom | `hydraulics` |
| `mid` | the middle | `low`, `hydraulics` |
| `top` | the top | `mid`, `low` |

## Next
"""


def tree(root, files):
    for path, text in files.items():
        p = os.path.join(root, path)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        with open(p, "w") as f:
            f.write(text)


def run(root):
    r = subprocess.run([sys.executable, os.path.join(HERE, "check_layout.py"), "--source", root],
                       capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


CLEAN = {
    "docs/architecture.md": MAP,
    "src/hydraulics/hydraulics.h": "",
    "src/hydraulics/hyd.c": '#include "hydraulics.h"\n#include "cJSON.h"\n',
    "src/world/low/a.h": '#include "hydraulics.h"\n',
    "src/world/low/a.c": '#include "a.h"\n',
    "src/world/mid/b.h": '#include "a.h"\n',
    "src/world/mid/b.c": '#include "b.h"\n#include "b_internal.h"\n',
    # An internal header that includes its module's header: no circle.
    "src/world/mid/b_internal.h": '#include "b.h"\n',
    "src/world/top/c.c": '#include "b.h"\n  #  include "a.h"\n#include <stdio.h>\n',
    # One part split in two files: q.c uses b's interface and b.c calls q's,
    # whose header no file outside mid includes: no circle.
    "src/world/mid/q.h": '#include "b.h"\n',
    "src/world/mid/q.c": '#include "q.h"\n',
}
CLEAN["src/world/mid/b.c"] = '#include "b.h"\n#include "b_internal.h"\n#include "q.h"\n'


BAD = dict(CLEAN)
BAD.update({
    # low -> mid: forbidden, and a folder cycle low -> mid -> low, and a
    # module circle a -> b -> a.
    "src/world/low/a.c": '#include "a.h"\n#include "b.h"\n',
    # Two headers that include each other.
    "src/world/top/h1.h": '#include "h2.h"\n',
    "src/world/top/h2.h": '#include "h1.h"\n',
    # No such file.
    "src/world/top/d.c": '#include "nowhere.h"\n',
    # A folder the map does not list.
    "src/world/extra/e.c": '#include "a.h"\n',
    # The same split, but r.h is an interface (top includes it): r <-> b2r.
    "src/world/mid/r.h": '#include "b2r.h"\n',
    "src/world/mid/r.c": '#include "r.h"\n',
    "src/world/mid/b2r.h": "",
    "src/world/mid/b2r.c": '#include "b2r.h"\n#include "r.h"\n',
    "src/world/top/f.c": '#include "r.h"\n#include "b2r.h"\n',
})

EXPECT_BAD = [
    "folder extra/ is not in the folder map",
    "folder extra includes low, which the map does not allow: e.c includes a.h",
    "folder low includes mid, which the map does not allow: a.c includes b.h",
    "folder cycle (2 folders: low, mid): low -> mid -> low",
    "module cycle (2 modules: low/a, mid/b): low/a -> mid/b -> low/a",
    "header cycle (2 headers: top/h1.h, top/h2.h): top/h1.h -> top/h2.h -> top/h1.h",
    'src/world/top/d.c: #include "nowhere.h" is no file of src/world or src/hydraulics',
    "module cycle (2 modules: mid/b2r, mid/r): mid/b2r -> mid/r -> mid/b2r",
]


def main():
    work = tempfile.mkdtemp(prefix="layout_selftest_")
    fails = []
    try:
        good = os.path.join(work, "good")
        tree(good, CLEAN)
        rc, out = run(good)
        if rc != 0 or "all allowed, no cycle" not in out:
            fails.append(f"the clean tree: exit {rc}, expected 0:\n{out}")
        bad = os.path.join(work, "bad")
        tree(bad, BAD)
        rc, out = run(bad)
        if rc != 1:
            fails.append(f"the tree with mistakes: exit {rc}, expected 1")
        lines = [l for l in out.splitlines() if not l.startswith("check_layout:")]
        for e in EXPECT_BAD:
            if not any(l.startswith(e) for l in lines):
                fails.append(f"not reported: {e}")
        for l in lines:
            if not any(l.startswith(e) for e in EXPECT_BAD):
                fails.append(f"reported, not a mistake of the tree: {l}")
        nomap = os.path.join(work, "nomap")
        tree(nomap, {k: v for k, v in CLEAN.items() if k != "docs/architecture.md"})
        tree(nomap, {"docs/architecture.md": "# Architecture\n"})
        rc, out = run(nomap)
        if rc != 2 or "no heading" not in out:
            fails.append(f"a page without the map: exit {rc}, expected 2 naming the heading:\n{out}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    for f in fails:
        print("FAIL:", f)
    if fails:
        return 1
    print("layout selftest: the clean tree passes, each of the 8 mistakes is reported, a missing map refused")
    return 0


if __name__ == "__main__":
    sys.exit(main())
