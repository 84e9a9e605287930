#!/usr/bin/env python3
"""check_layout.py: src/world's include graph against its folder map.

Reads every `#include "..."` of src/world/**/*.[ch] (and src/hydraulics, which
must include nothing of src/world), resolves each header to the file that
holds it (the including file's own folder first, then the one folder of
src/world or src/hydraulics that has a file of that name; a name found in two
folders, or in none, is an error: the include path would pick one silently)
and builds three graphs:

  - modules: a .c file and the header of the same stem are one module
    (engine.c + engine.h). An edge A -> B: a file of A includes a header of
    B. A header with no .c of its stem, or one that no file outside its own
    folder includes, is passed through: A depends on what it includes. A
    cycle here is the "include circle" (issue 26): files that cannot be
    read, built or tested one without the other.
  - folders: an edge from a file's folder to each folder of a header it
    includes. Every edge must be one the folder map allows, and there must be
    no cycle.
  - symbols (with --objects): which object file calls or reads a symbol
    another defines (nm). A declaration in one folder's header defined in
    another folder's .c (the way sim_param_name once hid the loaders'
    dependency on the run layer) shows up here even where no include does.

The folder map, "may include", is read from the table under the heading
"### Folders of src/world" in docs/architecture.md (one row per folder:
| `folder` | what it holds | `a`, `b` |, "-" for nothing), so the document
and the check cannot disagree. `hydraulics` stands for src/hydraulics.

Exit 0 when the tree follows the map; 1 with one line per problem (each
cycle with its modules or folders in order, each edge the map forbids with
the files that make it); 2 on bad usage or a missing map.
"""
import argparse
import os
import re
import subprocess
import sys
from collections import defaultdict

INCLUDE_RE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
NM_RE = re.compile(r"^.*:([^:/]+\.o):\s*[0-9a-fA-F]*\s+([A-Za-z])\s+(\S+)$")
MAP_HEADING = "### Folders of src/world"


def read_map(doc):
    """{folder: set(allowed)} from the architecture page's folder table."""
    try:
        text = open(doc, encoding="utf-8").read()
    except OSError as e:
        sys.exit(f"check_layout: {doc}: {e.strerror}")
    at = text.find(MAP_HEADING)
    if at < 0:
        print(f"check_layout: {doc}: no heading '{MAP_HEADING}' (the folder map this check reads)", file=sys.stderr)
        sys.exit(2)
    allowed = {}
    in_table = False
    for line in text[at:].splitlines()[1:]:
        if line.startswith("#"):
            break
        if not line.startswith("|"):
            if in_table:
                break
            continue
        in_table = True
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 3 or set(cells[0]) <= set("-: "):
            continue
        m = re.fullmatch(r"`([a-z_]+)/?`", cells[0])
        if not m:
            continue  # the header row
        deps = set(re.findall(r"`([a-z_]+)/?`", cells[-1]))
        allowed[m.group(1)] = deps
    if not allowed:
        print(f"check_layout: {doc}: the table under '{MAP_HEADING}' has no folder rows", file=sys.stderr)
        sys.exit(2)
    return allowed


def scan(root):
    """Files of src/world and src/hydraulics: {relpath: folder}."""
    files = {}
    world = os.path.join(root, "src", "world")
    for d, _, names in os.walk(world):
        for n in names:
            if n.endswith((".c", ".h")):
                p = os.path.relpath(os.path.join(d, n), root)
                rel = os.path.relpath(d, world)
                if rel == ".":
                    files[p] = "(src/world)"  # a file outside any folder: reported
                else:
                    files[p] = rel.split(os.sep)[0]
    hyd = os.path.join(root, "src", "hydraulics")
    for d, _, names in os.walk(hyd):
        for n in names:
            if n.endswith((".c", ".h")):
                files[os.path.relpath(os.path.join(d, n), root)] = "hydraulics"
    return files


def sccs(graph):
    """Strongly connected components with more than one node (Tarjan, iterative)."""
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]
    nodes = sorted(set(graph) | {v for vs in graph.values() for v in vs})
    for start in nodes:
        if start in index:
            continue
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on.add(start)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    advanced = True
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


def a_cycle(graph, comp):
    """One closed path through the component, as a list starting and ending at its first node."""
    members = set(comp)
    start = comp[0]
    # Breadth-first from start back to start inside the component: the shortest circle.
    prev = {}
    frontier = [start]
    seen = set()
    while frontier:
        nxt = []
        for v in frontier:
            for w in sorted(graph.get(v, ())):
                if w not in members:
                    continue
                if w == start:
                    path = [v]
                    while path[-1] != start:
                        path.append(prev[path[-1]])
                    return list(reversed(path)) + [start]
                if w not in seen:
                    seen.add(w)
                    prev[w] = v
                    nxt.append(w)
        frontier = nxt
    return comp + [start]


def module_of(path):
    d, n = os.path.split(path)
    return os.path.join(d, os.path.splitext(n)[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", required=True, help="the repository root")
    ap.add_argument("--doc", help="the page with the folder map (default: SOURCE/docs/architecture.md)")
    ap.add_argument("--objects", nargs="*", default=[],
                    help="static libraries of src/world to check by symbol (nm) as well")
    ap.add_argument("--print", action="store_true", help="also print the folder graph")
    a = ap.parse_args()
    root = a.source
    allowed = read_map(a.doc or os.path.join(root, "docs", "architecture.md"))
    files = scan(root)
    if not any(f != "hydraulics" for f in files.values()):
        print(f"check_layout: {root}: no src/world files", file=sys.stderr)
        return 2
    by_name = defaultdict(list)
    for p in files:
        by_name[os.path.basename(p)].append(p)

    problems = []
    folders = sorted({f for f in files.values()})
    for f in folders:
        if f not in allowed and f != "hydraulics":
            problems.append(f"folder {f}/ is not in the folder map ({MAP_HEADING}, docs/architecture.md)")
    for f in sorted(allowed):
        for dep in sorted(allowed[f]):
            if dep not in allowed and dep != "hydraulics":
                problems.append(f"folder map: {f} may include '{dep}', which is no folder of the map")

    inc = defaultdict(list)  # file -> the files it includes
    folder_edges = defaultdict(lambda: defaultdict(list))  # from -> to -> ["file includes header"]
    for p, folder in sorted(files.items()):
        try:
            text = open(os.path.join(root, p), encoding="utf-8", errors="replace").read()
        except OSError as e:
            problems.append(f"{p}: {e.strerror}")
            continue
        for name in INCLUDE_RE.findall(text):
            base = os.path.basename(name)
            same = os.path.normpath(os.path.join(os.path.dirname(p), name))
            if same in files:
                target = same
            else:
                cands = by_name.get(base, [])
                if folder == "hydraulics":
                    cands = [c for c in cands if files[c] == "hydraulics"] or cands
                if len(cands) == 1:
                    target = cands[0]
                elif not cands:
                    if folder == "hydraulics":
                        continue  # a system or third-party header in quotes (the library's own business)
                    problems.append(f'{p}: #include "{name}" is no file of src/world or src/hydraulics '
                                    f'(a library header belongs in <...>)')
                    continue
                else:
                    problems.append(f'{p}: #include "{name}" is ambiguous: ' + ", ".join(sorted(cands)))
                    continue
            inc[p].append(target)
            tf = files[target]
            if tf != folder:
                folder_edges[folder][tf].append(f"{os.path.basename(p)} includes {base}")

    # Modules: a .c and the header of its stem. A header without a .c of its
    # stem (engine_impl.h, world_snapshot.h, an _internal.h) is part of no
    # module: a module depends through it on the modules it includes, so
    # X.c -> X_internal.h -> X.h is no circle. So is a header no file
    # outside its own folder includes (src, tests, examples, tools): it is
    # the folder's own business, one part split in files (a loader in two
    # .c files, its second's header read only by the first), not an
    # interface a circle can run through.
    outside = defaultdict(set)  # header basename -> folders (or trees) that include it
    for top in ("src", "tests", "examples", "tools"):
        for d, _, names in os.walk(os.path.join(root, top)):
            for n in names:
                if not n.endswith((".c", ".h", ".cpp", ".hpp", ".cc")):
                    continue
                full = os.path.join(d, n)
                rel = os.path.relpath(full, root)
                where = files.get(rel, "(" + rel.split(os.sep)[0] + "/" + rel.split(os.sep)[1] + ")")
                try:
                    text = open(full, encoding="utf-8", errors="replace").read()
                except OSError:
                    continue
                for name in INCLUDE_RE.findall(text):
                    outside[os.path.basename(name)].add(where)
    internal = {p for p in files if p.endswith(".h") and files[p] != "hydraulics"
                and outside.get(os.path.basename(p), set()) <= {files[p]}}
    real = {module_of(p) for p in files if p.endswith(".c")}
    modules = defaultdict(set)
    for p in sorted(files):
        me = module_of(p)
        if me not in real:
            continue
        seen, todo = set(), list(inc.get(p, ()))
        while todo:
            t = todo.pop()
            if t in seen:
                continue
            seen.add(t)
            mt = module_of(t)
            if mt in real and t not in internal:
                if mt != me:
                    modules[me].add(mt)
            else:
                todo.extend(inc.get(t, ()))  # passed through: its includes are the includer's
    # Headers among themselves: a circle of #include (only guards stop it).
    headers = {p: {t for t in inc.get(p, ()) if t.endswith(".h")} for p in files if p.endswith(".h")}

    # The folder map: every edge allowed.
    for src in sorted(folder_edges):
        for dst in sorted(folder_edges[src]):
            if src == "hydraulics" or src not in allowed:
                ok = False
            else:
                ok = dst in allowed[src]
            if not ok:
                why = folder_edges[src][dst]
                more = f" (and {len(why) - 3} more)" if len(why) > 3 else ""
                problems.append(f"folder {src} includes {dst}, which the map does not allow: "
                                + "; ".join(why[:3]) + more)

    fgraph = {s: set(d) for s, d in folder_edges.items()}
    for comp in sccs(fgraph):
        problems.append(f"folder cycle ({len(comp)} folders: " + ", ".join(comp) + "): "
                        + " -> ".join(a_cycle(fgraph, comp)))
    short = lambda m: m.replace(os.path.join("src", "world") + os.sep, "")
    for comp in sccs(modules):
        cyc = a_cycle(modules, comp)
        problems.append(f"module cycle ({len(comp)} modules: " + ", ".join(short(c) for c in comp) + "): "
                        + " -> ".join(short(c) for c in cyc))

    for comp in sccs(headers):
        problems.append(f"header cycle ({len(comp)} headers: " + ", ".join(short(c) for c in comp) + "): "
                        + " -> ".join(short(c) for c in a_cycle(headers, comp)))

    # Symbols: who uses what another object defines.
    if a.objects:
        defs, uses = {}, defaultdict(set)
        for lib in a.objects:
            r = subprocess.run(["nm", "-A", lib], capture_output=True, text=True)
            if r.returncode != 0:
                print(f"check_layout: nm {lib}: {r.stderr.strip()}", file=sys.stderr)
                return 2
            for line in r.stdout.splitlines():
                # "lib.a:member.c.o:0000000000000000 T name", "lib.a:member.c.o:                 U name"
                m = NM_RE.match(line)
                if not m:
                    continue
                obj, kind, sym = m.group(1), m.group(2), m.group(3)
                if kind in "TDRBC":
                    defs[sym] = obj
                elif kind == "U":
                    uses[obj].add(sym)
        src_of = {}
        for p, folder in files.items():
            if p.endswith(".c"):
                src_of[os.path.basename(p) + ".o"] = p
        sym_edges = defaultdict(lambda: defaultdict(set))
        for obj, syms in uses.items():
            for s in syms:
                d = defs.get(s)
                if d and d != obj and obj in src_of and d in src_of:
                    fo, fd = files[src_of[obj]], files[src_of[d]]
                    if fo != fd:
                        sym_edges[fo][fd].add(f"{obj[:-4]} uses {s} of {d[:-4]}")
        sgraph = {s_: set(d) for s_, d in sym_edges.items()}
        for comp in sccs(sgraph):
            cyc = a_cycle(sgraph, comp)
            why = [sorted(sym_edges[x][y])[0] for x, y in zip(cyc, cyc[1:])]
            problems.append(f"folder cycle by symbols ({len(comp)} folders: " + ", ".join(comp) + "): "
                            + " -> ".join(cyc) + " (" + "; ".join(why) + ")")
        for src in sorted(sym_edges):
            for dst in sorted(sym_edges[src]):
                if src == "hydraulics" or dst not in allowed.get(src, ()):
                    why = sorted(sym_edges[src][dst])
                    more = f" (and {len(why) - 3} more)" if len(why) > 3 else ""
                    problems.append(f"folder {src} uses symbols of {dst}, which the map does not allow: "
                                    + "; ".join(why[:3]) + more)

    if a.print:
        for s in sorted(folder_edges):
            print(f"{s} -> " + ", ".join(sorted(folder_edges[s])))
    for p in problems:
        print(p)
    if problems:
        print(f"check_layout: {len(problems)} problem(s) in src/world's layout (map: docs/architecture.md, "
              f"'{MAP_HEADING}')")
        return 1
    n_inc = sum(len(v) for d in folder_edges.values() for v in d.values())
    print(f"check_layout: {len([f for f in files if files[f] != 'hydraulics'])} files in "
          f"{len([f for f in folders if f != 'hydraulics'])} folders, {n_inc} includes across folders, "
          f"all allowed, no cycle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
