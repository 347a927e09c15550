#!/usr/bin/env python3
"""Runs the commands that README.md and docs/ mark runnable, so that a documented command cannot
rot. `make test` runs it (scripts/run-tests.sh); by hand:

    BUILD=$PWD/build python3 scripts/doc-commands.py [FILE.md ...]     # default: README + docs/
    python3 scripts/doc-commands.py --list                             # the blocks, not run

The convention (docs/index.md, "Runnable commands"), on the fence's info string:

    ```sh runnable            run with bash -e -o pipefail; must exit 0
    ```sh runnable exit=N     must exit with status N (a documented error)
    ```text output            every non-empty line must occur in what the runnable block just
                              before it printed (stdout and stderr): a documented message
    ```json file=NAME         written to NAME before the later blocks of the page run (a scene
                              shown in the page is the one the page's commands use)
    ```c excerpt=PATH         every non-empty line must occur, in order, in PATH (an excerpt of a
                              file that the suite builds, such as docs/examples/traction.c)

Fences without these words are illustrations and are not run. The blocks of one page run in
order in one scratch directory that mirrors the top of the source tree through symbolic links
(apps/, data/, docs/, the Makefile, ...), so commands are written as from a clone's top and their
outputs (out/, ...) land in the scratch directory; HOME is a scratch directory too, so
`make install PREFIX=$HOME/.local` installs nowhere that matters. BUILD (the build directory,
made absolute) is exported, so `make` targets use the build the tests use, and PLUME_DEMO_QUICK=1,
so `make demo` runs every step with the feather and the wing cut short (scripts/demo.sh).

Every relative link of a page (outside code) must name an existing file, and its #anchor a
heading of that page.

Prints one line per block and, last, "N passed, N failed"; exits 1 if any failed.
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TIMEOUT = 300  # seconds a block may take
SKIP_TOP = {"out", ".git", "build", "build-asan", "build-fuzz"}

FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*(.*)$")


def blocks(path):
    """(line, words, attrs, text) of every fenced block of a Markdown file."""
    out = []
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, info = m.group(1), m.group(2), m.group(3)
        start = i + 1
        body = []
        i += 1
        while i < len(lines) and not (lines[i].strip().startswith(fence) and lines[i].strip().strip(fence[0]) == ""):
            body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i])
            i += 1
        i += 1
        words = shlex.split(info) if info else []
        attrs = dict(w.split("=", 1) for w in words if "=" in w)
        out.append((start, [w for w in words if "=" not in w], attrs, "\n".join(body) + "\n"))
    return out


def interesting(words, attrs):
    return "runnable" in words or "output" in words or "file" in attrs or "excerpt" in attrs


def scratch_tree(root):
    """A directory that looks like the top of the source tree (symbolic links), and a HOME."""
    work = os.path.join(root, "work")
    home = os.path.join(root, "home")
    os.makedirs(work)
    os.makedirs(home)
    for name in os.listdir(TOP):
        if name in SKIP_TOP or name.startswith("build"):
            continue
        os.symlink(os.path.join(TOP, name), os.path.join(work, name))
    return work, home


def check_excerpt(text, path):
    """None if every non-empty line of text occurs in order in path, else the first that does not."""
    with open(os.path.join(TOP, path), encoding="utf-8") as f:
        lines = [l.strip() for l in f.read().split("\n")]
    k = 0
    for want in (l.strip() for l in text.split("\n")):
        if not want:
            continue
        while k < len(lines) and lines[k] != want:
            k += 1
        if k == len(lines):
            return want
        k += 1
    return None


LINK = re.compile(r"\]\(([^)\s]+)\)")


def slug(title):
    """GitHub's anchor of a heading."""
    t = re.sub(r"[^\w\- ]", "", title.strip().lower().replace("`", ""))
    return t.replace(" ", "-")


def anchors(path):
    out, inside = set(), False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if FENCE.match(line):
                inside = not inside
            elif not inside and line.startswith("#"):
                out.add(slug(line.lstrip("#")))
    return out


def broken_links(path):
    """The relative link targets of a Markdown file (outside code) that name no file."""
    bad = []
    inside = False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if FENCE.match(line):
                inside = not inside
                continue
            if inside:
                continue
            for target in LINK.findall(re.sub(r"`[^`]*`", "", line)):
                if re.match(r"^[a-z]+:", target):
                    continue
                file, _, anchor = target.partition("#")
                full = os.path.join(os.path.dirname(path), file) if file else path
                if not os.path.exists(full):
                    bad.append(target)
                elif anchor and full.endswith(".md") and anchor not in anchors(full):
                    bad.append(target)
    return bad


def run_page(path, env, results, verbose):
    rel = os.path.relpath(path, TOP)
    bad = broken_links(path)
    results.append((rel + " (links)", not bad, 0.0, "broken links: " + ", ".join(bad) if bad else ""))
    page = [b for b in blocks(path) if interesting(b[1], b[2])]
    if not page:
        return
    root = tempfile.mkdtemp(prefix="plume-docs-")
    try:
        work, home = scratch_tree(root)
        penv = dict(env, HOME=home)
        last_output = None
        for line, words, attrs, text in page:
            where = "%s:%d" % (rel, line)
            if "excerpt" in attrs:
                bad = check_excerpt(text, attrs["excerpt"])
                results.append((where, bad is None, 0.0,
                                "" if bad is None else "not in %s (in order): %s" % (attrs["excerpt"], bad)))
            elif "file" in attrs:
                dest = os.path.join(work, attrs["file"])
                os.makedirs(os.path.dirname(dest), exist_ok=True)
                with open(dest, "w", encoding="utf-8") as f:
                    f.write(text)
                results.append((where, True, 0.0, "wrote " + attrs["file"]))
            elif "output" in words:
                if last_output is None:
                    results.append((where, False, 0.0, "an output block with no runnable block before it"))
                    continue
                missing = [l.strip() for l in text.split("\n") if l.strip() and l.strip() not in last_output]
                results.append((where, not missing, 0.0, "not printed: " + missing[0] if missing else ""))
            elif "runnable" in words:
                want = int(attrs.get("exit", "0"))
                script = ("set -eo pipefail\n" if want == 0 else "") + text
                t0 = time.time()
                try:
                    p = subprocess.run(["bash", "-c", script], cwd=work, env=penv, stdin=subprocess.DEVNULL,
                                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=TIMEOUT)
                    rc, out = p.returncode, p.stdout.decode("utf-8", "replace")
                except subprocess.TimeoutExpired as e:
                    rc, out = -1, (e.stdout or b"").decode("utf-8", "replace") + "\n(timed out after %d s)" % TIMEOUT
                dt = time.time() - t0
                last_output = out
                ok = rc == want
                why = "" if ok else "exit status %d, expected %d; output:\n%s" % (
                    rc, want, "\n".join("    " + l for l in out.rstrip().split("\n")[-25:]))
                if verbose and ok:
                    why = out
                results.append((where, ok, dt, why))
    finally:
        shutil.rmtree(root, ignore_errors=True)


def main(argv):
    verbose = "-v" in argv
    listing = "--list" in argv
    files = [a for a in argv if not a.startswith("-")]
    if not files:
        files = [os.path.join(TOP, "README.md")]
        for d, _, names in sorted(os.walk(os.path.join(TOP, "docs"))):
            files += [os.path.join(d, n) for n in sorted(names) if n.endswith(".md")]
    files = [os.path.abspath(f) for f in files]
    if listing:
        for f in files:
            for line, words, attrs, text in blocks(f):
                if interesting(words, attrs):
                    print("%s:%d %s %s" % (os.path.relpath(f, TOP), line, " ".join(words),
                                           " ".join("%s=%s" % kv for kv in attrs.items())))
        return 0
    # a make that runs this (make test) passes its jobserver and command-line variables down in
    # MAKEFLAGS; the documented `make` commands must see only BUILD, as a user's shell would
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "MAKEOVERRIDES")}
    build = env.get("BUILD", "build")
    env["BUILD"] = build if os.path.isabs(build) else os.path.join(TOP, build)
    env.setdefault("OMP_WAIT_POLICY", "passive")
    env.setdefault("MPLBACKEND", "Agg")
    env["PLUME_DEMO_QUICK"] = "1"  # make demo: every step, the 3D runs cut short (scripts/demo.sh)
    results = []
    t0 = time.time()
    for f in files:
        n = len(results)
        run_page(f, env, results, verbose)
        for where, ok, dt, why in results[n:]:
            print("%s %s (%.1f s)%s" % ("ok  " if ok else "FAIL", where, dt, ("\n" + why) if why and (not ok or verbose) else ""))
            sys.stdout.flush()
    failed = sum(1 for r in results if not r[1])
    print("documented commands: %.1f s" % (time.time() - t0))
    print("%d passed, %d failed" % (len(results) - failed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
