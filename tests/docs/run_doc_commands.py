#!/usr/bin/env python3
"""Runs every command shown in one page of the user docs (README.md, docs/*.md).

usage: run_doc_commands.py --source ROOT --cranesim BINARY --work DIR PAGE.md [--list]

The rules a page follows (this test holds the docs to them):

* A fenced block tagged `sh` holds commands, one per line; a line ending in a
  backslash goes on in the next, `#` lines are comments. Each command runs
  with `sh -c` from a scratch copy of the repository root (DIR/root: the
  checkout's files as links, so what a command writes lands there and never
  in the checkout), in page order, so a command may read what an earlier one
  of the page wrote. `cranesim` and `build/cranesim` are the binary under test.
* A fenced block tagged `console` shows commands after a `$ ` prompt and their
  output on the other lines; its commands run as above, the output is not
  compared (it holds wall times).
* A command must exit 0, or with the status its trailing comment names:
  `... --tol-pressure 1   # exit 1: over the tolerance`.
* A command ending in `&` starts a server (one simple command): the next
  command starts when it has printed a line on stdout; at the end of the
  block it gets SIGINT and must then exit 0 (or what its comment names). (The page runs in a network namespace of its own when
  `unshare` allows one, so a fixed port such as 7575 is free.)
* The commands run without a display (DISPLAY and WAYLAND_DISPLAY unset), as
  on a machine without one: `drive` runs headless, `--screenshot` offscreen.
* Any other block (untagged, `json`, `text`, indented by four spaces) must not
  show a cranesim command or a `$ ` prompt: tag it `sh` or `console` so it is
  run, or mark it.
* A marker on the line just above a fence, `<!-- doc-test: KIND reason -->`,
  says how a block that must not simply run is checked. KIND is one of
    synopsis  a usage pattern ([--opt ...], FILE, M|N): not run; each of its
              cranesim lines must hold such a placeholder.
    long      takes minutes: each command is started and must still be running
              after PROBE_S seconds (cranesim checks its options and files before
              it computes anything, so a bad one fails here), then it is stopped;
              one that ends 0 within PROBE_S is not long, and is refused.
    cluster   a batch or MPI launch (srun, mpirun, mpiexec; #SBATCH lines are
              comments): the launcher and its options are taken off and the
              cranesim command is probed as for long (ending 0 within PROBE_S is
              fine here).
    skip      not run at all (installs packages, builds, needs a person): refused
              on a block that holds a cranesim command, so a plain short cranesim
              command is never skipped.
  The test lists every marked block with its kind and reason.
* What the page's commands leave in the repository root must be covered by
  .gitignore (so running the examples in a checkout leaves it clean); the
  README's test also refuses tracked files that .gitignore covers.

A failure names the page, the line and the command, and shows the end of the
command's output.
"""
import argparse
import fnmatch
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time

PROBE_S = 3.0  # how long a `long` or `cluster` command must survive [s]
COMMAND_TIMEOUT_S = 90.0  # a plain command that takes longer must be shortened or marked long [s]
READY_TIMEOUT_S = 30.0  # a background server must print its first line within this [s]
STOP_TIMEOUT_S = 15.0  # a server must exit this long after SIGINT [s]
KINDS = ("synopsis", "long", "cluster", "skip")
LAUNCHERS = ("srun", "mpirun", "mpiexec", "sbatch")

FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([^\s`]*)")
MARKER = re.compile(r"^\s*<!--\s*doc-test:\s*(\S+)\s*(.*?)\s*-->\s*$")
# A cranesim command as a line of a block shows it: `cranesim run ...`,
# `build/cranesim run`, after a `$ ` prompt or a launcher; not the first line
# of a command's output (`cranesim run: ramp, ...`).
CRANESIM_CMD = re.compile(r"^\s*(\$\s+)?((srun|mpirun|mpiexec)(\s+-\S+(\s+\d+)?)*\s+)?(\S*/)?cranesim\s+[a-z]+(?!:)(\s|$)")
PROMPT = re.compile(r"^\s*\$\s+\S")
EXIT_COMMENT = re.compile(r"#\s*exit\s+(\d+)")
PLACEHOLDER = re.compile(r"\[|\||\b[A-Z][A-Z0-9_]*\b")


class Block:
    def __init__(self, page, line, lang, body, marker):
        self.page, self.line, self.lang, self.body = page, line, lang, body
        self.kind, self.reason = marker if marker else (None, "")

    def where(self):
        return "%s:%d" % (self.page, self.line)


def split_comment(text):
    """(code, comment) of a shell line: the comment starts at a # that begins a word outside quotes."""
    quote, i = None, 0
    while i < len(text):
        ch = text[i]
        if ch == "\\" and quote != "'":
            i += 2  # an escaped character
            continue
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or text[i - 1].isspace()):
            return text[:i].rstrip(), text[i:]
        i += 1
    return text.rstrip(), ""


class Command:
    def __init__(self, block, line, text):
        self.block, self.line, self.text = block, line, text
        self.code, comment = split_comment(text)
        m = EXIT_COMMENT.search(comment)
        self.expect = int(m.group(1)) if m else 0
        self.background = self.code.endswith("&") and not self.code.endswith("&&")
        if self.background:
            self.code = self.code[:-1].rstrip()

    def where(self):
        return "%s:%d" % (self.block.page, self.line)


def parse_blocks(page, text):
    """Fenced blocks (with the marker above each) and indented code lines."""
    lines = text.split("\n")
    blocks, indented = [], []
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            if lines[i].startswith("    ") and (i == 0 or not lines[i - 1].strip() or lines[i - 1].startswith("    ")):
                indented.append((i + 1, lines[i]))
            i += 1
            continue
        fence, lang, start = m.group(2), m.group(3).lower(), i
        j = start - 1
        while j >= 0 and not lines[j].strip():
            j -= 1
        marker = None
        if j >= 0:
            mm = MARKER.match(lines[j])
            if mm:
                marker = (mm.group(1), mm.group(2))
        i += 1
        body = []
        while i < len(lines) and not lines[i].strip().startswith(fence[0] * len(fence)):
            body.append((i + 1, lines[i]))
            i += 1
        blocks.append(Block(page, start + 1, lang, body, marker))
        i += 1
    return blocks, indented


def commands_of(block):
    """The block's commands: logical lines joined over backslashes."""
    cmds, cur, first = [], [], None
    prompt = block.lang == "console"
    for n, raw in block.body:
        line = raw.rstrip()
        if not cur:
            stripped = line.strip()
            if prompt:
                if not PROMPT.match(line):
                    continue  # output
                line = stripped[1:].strip()
            elif not stripped or stripped.startswith("#"):
                continue
            first = n
        cur.append(line.strip())
        if line.endswith("\\"):
            cur[-1] = cur[-1][:-1].rstrip()
            continue
        cmds.append(Command(block, first, " ".join(cur)))
        cur = []
    if cur:
        cmds.append(Command(block, first, " ".join(cur)))
    return cmds


# .gitignore, as far as this repository uses it: `/pat` anchored at the root,
# `pat/` a folder, `pat` without a slash matches a name at any depth, shell
# globs in each part. Negations (`!pat`) are not used and not supported.
def read_ignores(root):
    pats = []
    try:
        with open(os.path.join(root, ".gitignore")) as f:
            for line in f:
                line = line.strip()
                if line and not line.startswith("#"):
                    pats.append(line)
    except OSError:
        pass
    return pats


def ignored(pats, rel, is_dir):
    parts = rel.split("/")
    for p in pats:
        dir_only = p.endswith("/")
        p = p.rstrip("/")
        if dir_only and not is_dir:
            continue
        if p.startswith("/") or "/" in p:
            if fnmatch.fnmatchcase(rel, p.lstrip("/")):
                return True
        elif fnmatch.fnmatchcase(parts[-1], p):
            return True
    return False


def mirror(source, root, pats):
    """DIR/root: the checkout's directories, its files as symbolic links.

    cranesim writes through a temporary file renamed over the target, which
    replaces a link instead of writing through it; anything new stays here.
    Build trees, .git and what .gitignore covers at the root are left out.
    """
    if os.path.exists(root):
        shutil.rmtree(root)
    os.makedirs(root)
    for name in sorted(os.listdir(source)):
        src = os.path.join(source, name)
        is_dir = os.path.isdir(src) and not os.path.islink(src)
        if name == ".git" or ignored(pats, name, is_dir):
            continue
        if not is_dir:
            os.symlink(src, os.path.join(root, name))
            continue
        for d, subdirs, files in os.walk(src):
            rel = os.path.relpath(d, source)
            os.makedirs(os.path.join(root, rel), exist_ok=True)
            for f in files:
                os.symlink(os.path.join(d, f), os.path.join(root, rel, f))
    return snapshot(root)


def snapshot(root):
    out = set()
    for d, subdirs, files in os.walk(root):
        for x in subdirs + files:
            out.add(os.path.relpath(os.path.join(d, x), root))
    return out


class Runner:
    def __init__(self, args):
        self.source = os.path.abspath(args.source)
        self.page = os.path.relpath(os.path.abspath(args.page), self.source)
        self.work = os.path.abspath(args.work)
        self.root = os.path.join(self.work, "root")
        self.logs = os.path.join(self.work, "logs")
        self.binary = os.path.abspath(args.cranesim)
        self.failures, self.notes, self.marked = [], [], []
        self.ran = 0
        self.servers = []
        self.groups = []  # (command, process group) of everything started
        self.seq = 0

    # --- environment -------------------------------------------------------
    def setup(self):
        self.pats = read_ignores(self.source)
        self.before = mirror(self.source, self.root, self.pats)
        os.makedirs(os.path.join(self.root, "build"), exist_ok=True)
        link = os.path.join(self.root, "build", "cranesim")
        if os.path.lexists(link):
            os.remove(link)
        os.symlink(self.binary, link)
        self.before |= {"build", "build/cranesim"}
        shutil.rmtree(self.logs, ignore_errors=True)
        os.makedirs(self.logs)
        bindir = os.path.join(self.work, "bin")  # `cranesim` as typed
        shutil.rmtree(bindir, ignore_errors=True)
        os.makedirs(bindir)
        os.symlink(self.binary, os.path.join(bindir, "cranesim"))
        env = dict(os.environ)
        for k in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER"):
            env.pop(k, None)
        env["PATH"] = bindir + os.pathsep + env.get("PATH", "")
        env["SDL_AUDIODRIVER"] = "dummy"
        env["EGL_PLATFORM"] = "surfaceless"
        self.env = env

    def fail(self, cmd_or_block, what, log=None):
        where = cmd_or_block.where()
        text = getattr(cmd_or_block, "text", None)
        msg = "%s: %s" % (where, what)
        if text:
            msg = "%s: `%s`: %s" % (where, text, what)
        if log:
            msg += "\n" + tail(log)
        self.failures.append(msg)
        print("FAIL " + msg, flush=True)

    def start(self, text, cmd):
        self.seq += 1
        log = os.path.join(self.logs, "%03d_line%d.log" % (self.seq, cmd.line))
        out = open(log, "wb")
        out.write(("$ %s\n" % text).encode())
        out.flush()
        p = subprocess.Popen(["sh", "-c", text], cwd=self.root, env=self.env, stdin=subprocess.DEVNULL,
                             stdout=subprocess.PIPE if cmd.background else out, stderr=out,
                             start_new_session=True)
        self.groups.append((cmd, p.pid))
        return p, log, out

    # --- one command -------------------------------------------------------
    def run(self, cmd):
        self.ran += 1
        t0 = time.monotonic()
        if cmd.background:
            return self.run_server(cmd)
        p, log, out = self.start(cmd.code, cmd)
        try:
            rc = p.wait(timeout=COMMAND_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            stop(p)
            out.close()
            self.fail(cmd, "still running after %.0f s: show a shorter command, or mark the block "
                      "`<!-- doc-test: long ... -->` and say in the text that it is long" % COMMAND_TIMEOUT_S, log)
            return
        out.close()
        dt = time.monotonic() - t0
        if rc != cmd.expect:
            self.fail(cmd, "exit %d, the page implies %d" % (rc, cmd.expect), log)
        else:
            print("ok   %s (%.1f s, exit %d): %s" % (cmd.where(), dt, rc, cmd.text), flush=True)

    def run_server(self, cmd):
        # exec: the server itself gets the SIGINT and its exit status is the one seen.
        p, log, out = self.start("exec " + cmd.code, cmd)
        # Ready when it prints a line; its stdout goes on into the log.
        deadline = time.monotonic() + READY_TIMEOUT_S
        import selectors
        sel = selectors.DefaultSelector()
        sel.register(p.stdout, selectors.EVENT_READ)
        first = b""
        while time.monotonic() < deadline and b"\n" not in first:
            if sel.select(timeout=0.2):
                chunk = os.read(p.stdout.fileno(), 4096)
                if not chunk:
                    break
                first += chunk
            if p.poll() is not None and b"\n" not in first:
                break
        out.write(first)
        out.flush()
        if b"\n" not in first:
            rc = p.poll()
            stop(p)
            out.close()
            self.fail(cmd, "a server (a line ending in &) must print a line when ready: %s" %
                      ("it exited %d first" % rc if rc is not None else "nothing in %.0f s" % READY_TIMEOUT_S), log)
            return
        print("ok   %s (started in the background): %s" % (cmd.where(), cmd.text), flush=True)
        self.servers.append((cmd, p, log, out, sel))

    def stop_servers(self):
        for cmd, p, log, out, sel in self.servers:
            # Keep draining its stdout so it never blocks on a full pipe.
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGINT)
            deadline = time.monotonic() + STOP_TIMEOUT_S
            while time.monotonic() < deadline:
                if sel.select(timeout=0.2):
                    chunk = os.read(p.stdout.fileno(), 4096)
                    if chunk:
                        out.write(chunk)
                        continue
                if p.poll() is not None:
                    break
            rc = p.poll()
            if rc is None:
                stop(p)
                out.close()
                self.fail(cmd, "the server did not stop within %.0f s of SIGINT" % STOP_TIMEOUT_S, log)
                continue
            out.close()
            if rc != cmd.expect:
                self.fail(cmd, "the server exited %d after SIGINT, the page implies %d" % (rc, cmd.expect), log)
            else:
                print("ok   %s (stopped by SIGINT, exit %d)" % (cmd.where(), rc), flush=True)
        self.servers = []

    def probe(self, cmd, text, finish_ok):
        """A long command: it must pass its checks and still run after PROBE_S."""
        self.ran += 1
        p, log, out = self.start(text, cmd)
        try:
            rc = p.wait(timeout=PROBE_S)
        except subprocess.TimeoutExpired:
            stop(p)
            out.close()
            print("ok   %s (%s: still running after %.0f s, stopped): %s" %
                  (cmd.where(), cmd.block.kind, PROBE_S, text), flush=True)
            return
        out.close()
        if rc != 0:
            self.fail(cmd, "exit %d within %.0f s (%s block, run as `%s`)" % (rc, PROBE_S, cmd.block.kind, text), log)
        elif not finish_ok:
            self.fail(cmd, "finished (exit 0) within %.0f s: it is not long, remove the block's "
                      "`long` marker" % PROBE_S, log)
        else:
            print("ok   %s (%s, finished, exit 0): %s" % (cmd.where(), cmd.block.kind, text), flush=True)

    # --- one block ---------------------------------------------------------
    def block(self, b):
        runnable = b.lang in ("sh", "console")
        if b.kind is None:
            if runnable:
                for c in commands_of(b):
                    self.run(c)
                self.stop_servers()
            else:
                for n, line in b.body:
                    if CRANESIM_CMD.match(line) or PROMPT.match(line):
                        self.fail(b, "line %d shows a command in a block tagged `%s`: tag the block `sh` "
                                  "(or `console` with `$ ` prompts) so this test runs it, or mark it "
                                  "(tests/docs/run_doc_commands.py): %s" % (n, b.lang or "(none)", line.strip()))
                        break
            return
        if b.kind not in KINDS:
            self.fail(b, "unknown doc-test marker kind `%s` (one of %s)" % (b.kind, ", ".join(KINDS)))
            return
        if not b.reason:
            self.fail(b, "the `%s` marker must say why" % b.kind)
            return
        self.marked.append("%s %s: %s" % (b.where(), b.kind, b.reason))
        cmds = commands_of(b) if runnable else [Command(b, n, l.strip()) for n, l in b.body
                                                if CRANESIM_CMD.match(l) or PROMPT.match(l)]
        if b.kind == "skip":
            for c in cmds:
                if CRANESIM_CMD.match(c.text):
                    self.fail(c, "a `skip` block must not hold a cranesim command: run it, or mark the "
                              "block `long` or `cluster` if it is one")
            return
        if b.kind == "synopsis":
            for c in cmds:
                if CRANESIM_CMD.match(c.text) and not PLACEHOLDER.search(c.text.split("cranesim", 1)[1]):
                    self.fail(c, "a synopsis line without a placeholder ([...], FILE, A|B) is a command: run it")
            return
        if not runnable:
            self.fail(b, "a `%s` block must be tagged `sh` or `console`" % b.kind)
            return
        for c in cmds:
            if b.kind == "long":
                self.probe(c, c.code, finish_ok=False)
                continue
            words = shlex.split(c.text, comments=True)
            k = next((i for i, w in enumerate(words) if w == "cranesim" or w.endswith("/cranesim")), None)
            if k is None:
                self.fail(c, "a `cluster` block's commands are cranesim commands, launched or not")
                continue
            if k > 0 and os.path.basename(words[0]) not in LAUNCHERS:
                self.fail(c, "`%s` is not a launcher this test knows (%s)" % (words[0], ", ".join(LAUNCHERS)))
                continue
            self.probe(c, shlex.join(words[k:]), finish_ok=True)

    # --- the page ----------------------------------------------------------
    def check_processes(self):
        # A command must not leave a process behind (a `&` inside a command,
        # a server that ignored SIGINT): each ran in a process group of its own.
        for cmd, pgid in self.groups:
            try:
                os.killpg(pgid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                continue
            self.fail(cmd, "left a process running after it ended (killed now); a server is "
                      "a line ending in ` &`")

    def check_leftovers(self):
        after = snapshot(self.root)
        new = sorted(after - self.before)
        left = []
        for rel in new:
            if any(rel.startswith(x + "/") for x in left):
                continue
            full = os.path.join(self.root, rel)
            is_dir = os.path.isdir(full) and not os.path.islink(full)
            parent_ignored = any(ignored(self.pats, "/".join(rel.split("/")[:i]), True)
                                 for i in range(1, rel.count("/") + 1))
            if not parent_ignored and not ignored(self.pats, rel, is_dir):
                left.append(rel)
        for rel in left:
            self.failures.append("%s: its commands leave `%s%s` in the repository root, which .gitignore "
                                 "does not cover: write it under a scratch folder, or add it to .gitignore"
                                 % (self.page, rel, "/" if os.path.isdir(os.path.join(self.root, rel)) else ""))
            print("FAIL " + self.failures[-1], flush=True)

    def check_tracked(self):
        # Outputs committed by mistake (e.g. a test's stderr capture): a tracked
        # file .gitignore covers.
        if not shutil.which("git") or not os.path.exists(os.path.join(self.source, ".git")):
            self.notes.append("not a git checkout: tracked outputs not checked")
            return
        r = subprocess.run(["git", "-C", self.source, "ls-files", "-ci", "--exclude-standard"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            self.notes.append("git ls-files failed: tracked outputs not checked: " + r.stderr.strip())
            return
        for f in r.stdout.split():
            self.failures.append("%s is tracked although .gitignore covers it (an output committed by mistake?)" % f)
            print("FAIL " + self.failures[-1], flush=True)

    def main(self, list_only):
        with open(os.path.join(self.source, self.page)) as f:
            blocks, indented = parse_blocks(self.page, f.read())
        if list_only:
            for b in blocks:
                if b.lang in ("sh", "console"):
                    for c in commands_of(b):
                        print("%s [%s, exit %d] %s" % (c.where(), b.kind or "run", c.expect, c.text))
            return 0
        self.setup()
        for n, line in indented:
            if CRANESIM_CMD.match(line) or PROMPT.match(line):
                self.failures.append("%s:%d: a command in an indented code block: show it in a fenced block "
                                     "tagged `sh` so this test runs it: %s" % (self.page, n, line.strip()))
                print("FAIL " + self.failures[-1], flush=True)
        for b in blocks:
            self.block(b)
        self.check_processes()
        self.check_leftovers()
        if self.page == "README.md":
            self.check_tracked()
        print("\n%s: %d commands run, %d blocks marked%s" %
              (self.page, self.ran, len(self.marked), ":" if self.marked else ""))
        for m in self.marked:
            print("  " + m)
        for n in self.notes:
            print("note: " + n)
        if self.failures:
            print("\n%d failures:" % len(self.failures))
            for f in self.failures:
                print("  " + f.split("\n")[0])
            return 1
        return 0


def tail(path, n=12):
    try:
        with open(path, errors="replace") as f:
            lines = f.read().rstrip().split("\n")
    except OSError:
        return ""
    return "\n".join("    | " + l for l in lines[-n:])


def stop(p):
    try:
        os.killpg(p.pid, signal.SIGINT)
        p.wait(timeout=10)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()
    except ProcessLookupError:
        p.wait()


def private_network():
    """Re-run in a network namespace of our own (fixed ports cannot clash)."""
    if os.environ.get("CRANESIM_DOCTEST_NETNS") or not shutil.which("unshare") or not shutil.which("ip"):
        return None
    probe = subprocess.run(["unshare", "-rn", "ip", "link", "set", "lo", "up"], capture_output=True)
    if probe.returncode != 0:
        return None
    env = dict(os.environ, CRANESIM_DOCTEST_NETNS="1")
    inner = "ip link set lo up && exec " + shlex.join([sys.executable] + sys.argv)
    return subprocess.run(["unshare", "-rn", "sh", "-c", inner], env=env).returncode


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", required=True)
    ap.add_argument("--cranesim", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--list", action="store_true")
    ap.add_argument("page")
    args = ap.parse_args()
    if not args.list:
        with open(args.page) as f:
            servers = any(c.background for b in parse_blocks(args.page, f.read())[0]
                          if b.lang in ("sh", "console") and b.kind is None for c in commands_of(b))
        if servers:
            rc = private_network()
            if rc is not None:
                return rc
            print("note: no private network namespace (unshare -rn): servers use the machine's ports")
    return Runner(args).main(args.list)


if __name__ == "__main__":
    sys.exit(main())
