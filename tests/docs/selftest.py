#!/usr/bin/env python3
"""The doc-command test's own test: run_doc_commands.py on selftest/page.md
must report exactly the failures the page's EXPECT lines name (by line, or
line 0 for a page-wide one) and nothing else.

usage: selftest.py --cranesim BINARY --work DIR
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cranesim", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    # A repository root of its own: the page as README.md and a .gitignore
    # that covers *.csv (so kept.csv passes and stray.txt does not).
    src = os.path.join(os.path.abspath(a.work), "src")
    shutil.rmtree(src, ignore_errors=True)
    os.makedirs(src)
    shutil.copy(os.path.join(HERE, "selftest", "page.md"), os.path.join(src, "README.md"))
    with open(os.path.join(src, ".gitignore"), "w") as f:
        f.write("/build*/\n/*.csv\n")
    # Each EXPECT applies to the next block: the lines from its fence (or
    # indented line) to its end; "EXPECT page" to line 0.
    page = open(os.path.join(src, "README.md")).read().split("\n")
    expect = []  # (first line, last line, text)
    for i, line in enumerate(page):
        m = re.match(r"EXPECT( page)?: (.*)$", line)
        if not m:
            continue
        if m.group(1):
            expect.append((0, 0, m.group(2)))
            continue
        j = i + 1
        while j < len(page) and not (page[j].startswith("```") or page[j].startswith("    ")):
            j += 1
        k = j + 1
        if page[j].startswith("```"):
            while k < len(page) and not page[k].startswith("```"):
                k += 1
        expect.append((j + 1, k + 1, m.group(2)))
    r = subprocess.run([sys.executable, os.path.join(HERE, "run_doc_commands.py"), "--source", src, "--cranesim",
                        a.cranesim, "--work", os.path.join(os.path.abspath(a.work), "run"),
                        os.path.join(src, "README.md")], capture_output=True, text=True)
    print(r.stdout)
    summary = r.stdout.split("failures:\n", 1)[1] if "failures:\n" in r.stdout else ""
    got = {}
    for line in summary.split("\n"):
        line = line.strip()
        m = re.match(r"README\.md:(\d+)(: |:\s)(.*)$", line) or re.match(r"README\.md(): (.*)$", line)
        if not line:
            continue
        if m and m.lastindex == 3:
            got.setdefault(int(m.group(1)), []).append(line)
        else:
            got.setdefault(0, []).append(line)
    bad = 0
    matched = set()
    for lo, hi, text in expect:
        hit = [(n, g) for n in got for g in got[n] if lo <= n <= hi and text in g]
        if not hit:
            print("SELFTEST: expected a failure in lines %d..%d with '%s'" % (lo, hi, text))
            bad += 1
        matched.update(hit)
    for n in sorted(got):
        for g in got[n]:
            if (n, g) not in matched:
                print("SELFTEST: unexpected failure: %s" % g)
                bad += 1
    if r.returncode != 1:
        print("SELFTEST: the runner exited %d on a page with failures" % r.returncode)
        bad += 1
    print("SELFTEST: %d failures expected, %d problems" % (len(expect), bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
