#!/usr/bin/env python3
"""The benchmark tables of docs/benchmarks.md: written from what the bench programs print, and
checked against them, so the page's figures come from a run and its columns from today's code.

    python3 scripts/bench-tables.py run BUILD [NAME ...]   # make bench: run, capture, rewrite
    python3 scripts/bench-tables.py write BUILD [NAME ...] # make bench-docs: rewrite from captures
    python3 scripts/bench-tables.py check BUILD            # make test: the page against the code

NAME is a benchmark, bench/bench_NAME.c, one of the Makefile's BENCHES (default: all of them).

The page holds one block per benchmark between two markers:

    <!-- bench:NAME begin -->
    Measured by `make bench` on DATE at commit C, on N cores (CPU), load average L at the start; the run took T.
    ```text
    what BUILD/bench_NAME printed
    ```
    <!-- bench:NAME end -->

`run` runs each BUILD/bench_NAME from the top of the tree (OMP_WAIT_POLICY=passive unless set),
its output shown as it comes and kept in BUILD/bench/NAME.txt with the stamp line in
BUILD/bench/NAME.stamp (a failed run keeps the previous capture), then rewrites those blocks.
`write` rewrites the blocks of the benchmarks that have a capture and leaves the others as they
are (a benchmark that takes long can keep the figures of its last run).

`check` runs nothing long. It fails unless the Makefile's BENCHES and bench/bench_*.c name the
same programs, every marker pair is well formed and names one of them, every one of them has
exactly one block, every block is a stamp line and one text fence, and every line that
`BUILD/bench_NAME --header` prints (the tables' titles and column lines) occurs, in order, in the
block: a changed output format fails it until the block is regenerated, and so does a block
edited by hand into a header the program does not print. Prints one line per check and, last,
"N passed, N failed".
"""
import datetime
import os
import re
import shutil
import subprocess
import sys
import time

TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGE = os.path.join(TOP, "docs", "benchmarks.md")
MARKER = re.compile(r"^<!-- bench:([A-Za-z0-9_]+) (begin|end) -->$")
STAMP = re.compile(r"^Measured by `make bench` on \d{4}-\d\d-\d\d at commit \S+.*, on \d+ cores? \(.*\).*\.$")
HEADER_TIMEOUT = 20  # seconds a `--header` run may take (it prints a few lines)


def benches():
    """The Makefile's BENCHES list, in its order."""
    with open(os.path.join(TOP, "Makefile"), encoding="utf-8") as f:
        for line in f:
            m = re.match(r"^BENCHES\s*\??:?=\s*(.*)$", line)
            if m:
                return m.group(1).split()
    return []


def bench_sources():
    return sorted(n[len("bench_"):-2] for n in os.listdir(os.path.join(TOP, "bench"))
                  if n.startswith("bench_") and n.endswith(".c"))


def blocks(lines):
    """(name, first line, last line) of the page's marker pairs (0-based, the markers' lines), and
    a list of errors in the markers themselves."""
    out, errors, open_at, open_name = [], [], None, None
    for i, line in enumerate(lines):
        m = MARKER.match(line.strip())
        if not m:
            if line.strip().startswith("<!-- bench:"):  # a marker mistyped (one quoted in text is fine)
                errors.append("line %d: a bench marker not of the form <!-- bench:NAME begin|end -->" % (i + 1))
            continue
        name, what = m.group(1), m.group(2)
        if what == "begin":
            if open_name is not None:
                errors.append("line %d: bench:%s begins inside bench:%s (line %d)" % (i + 1, name, open_name, open_at + 1))
            open_at, open_name = i, name
        else:
            if open_name != name:
                errors.append("line %d: bench:%s ends where %s" % (
                    i + 1, name, "bench:%s is open" % open_name if open_name else "no block is open"))
            else:
                out.append((name, open_at, i))
            open_at, open_name = None, None
    if open_name is not None:
        errors.append("line %d: bench:%s never ends" % (open_at + 1, open_name))
    return out, errors


def block_text(body):
    """(stamp, fenced text) of a block's lines, or an error string."""
    body = [l for l in body if l.strip()]
    if len(body) < 3 or not STAMP.match(body[0].strip()):
        return None, "the block does not start with a stamp line (Measured by `make bench` on ...)"
    if body[1].strip() != "```text" or body[-1].strip() != "```":
        return None, "the block is not a stamp line and one ```text fence"
    inner = body[2:-1]
    if any(l.strip().startswith("```") for l in inner):
        return None, "the block holds more than one fence"
    return body[0], "\n".join(inner)


def header_lines(build, name):
    """The non-empty lines `bench_NAME --header` prints, right-stripped, or an error string."""
    exe = os.path.join(build, "bench_" + name)
    if not os.access(exe, os.X_OK):
        return None, "%s is not built (make test builds it)" % os.path.relpath(exe, TOP)
    try:
        p = subprocess.run([exe, "--header"], cwd=TOP, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, timeout=HEADER_TIMEOUT)
    except subprocess.TimeoutExpired:
        return None, "bench_%s --header ran for more than %d s" % (name, HEADER_TIMEOUT)
    out = p.stdout.decode("utf-8", "replace")
    lines = [l.rstrip() for l in out.split("\n") if l.strip()]
    if p.returncode != 0 or not lines:
        return None, "bench_%s --header exited with %d and printed %d lines" % (name, p.returncode, len(lines))
    return lines, None


def missing_in_order(want, text):
    """The first of the lines want that does not occur, in order, among the lines of text."""
    have = [l.rstrip() for l in text.split("\n")]
    i = 0
    for w in want:
        while i < len(have) and have[i] != w:
            i += 1
        if i == len(have):
            return w
        i += 1
    return None


def check(build):
    results = []

    def result(what, ok, why=""):
        results.append((what, ok, why))

    listed, sources = benches(), bench_sources()
    result("Makefile BENCHES", bool(listed), "no BENCHES line in the Makefile")
    unbuilt = [b for b in sources if b not in listed]
    unlisted = [b for b in listed if b not in sources]
    result("bench/ against BENCHES", not unbuilt and not unlisted,
           "; ".join(["bench/bench_%s.c is not in BENCHES" % b for b in unbuilt] +
                     ["BENCHES names %s, which has no bench/bench_%s.c" % (b, b) for b in unlisted]))
    with open(PAGE, encoding="utf-8") as f:
        lines = f.read().split("\n")
    found, errors = blocks(lines)
    result("docs/benchmarks.md markers", not errors, "; ".join(errors))
    names = [n for n, _, _ in found]
    for n in sorted(set(names)):
        if n not in listed:
            result("bench:%s" % n, False, "the page has a block for %s, which is not one of BENCHES" % n)
        elif names.count(n) > 1:
            result("bench:%s" % n, False, "the page has %d blocks for %s" % (names.count(n), n))
    for b in listed:
        if b not in names:
            result("bench:%s" % b, False, "docs/benchmarks.md has no block for %s (<!-- bench:%s begin -->)" % (b, b))
    for name, first, last in found:
        if name not in listed or names.count(name) > 1:
            continue
        where = "bench:%s (docs/benchmarks.md:%d)" % (name, first + 1)
        stamp, text = block_text(lines[first + 1:last])
        if stamp is None:
            result(where, False, text)
            continue
        want, why = header_lines(build, name)
        if want is None:
            result(where, False, why)
            continue
        miss = missing_in_order(want, text)
        result(where, miss is None, "" if miss is None else
               "bench_%s --header prints a line the block lacks (in order), regenerate it (make bench "
               "BENCHES=%s): %s" % (name, name, miss))
    for what, ok, why in results:
        print("%s %s%s" % ("ok  " if ok else "FAIL", what, "\n    " + why if why and not ok else ""))
    failed = sum(1 for r in results if not r[1])
    print("%d passed, %d failed" % (len(results) - failed, failed))
    return 1 if failed else 0


def git(*args):
    try:
        p = subprocess.run(["git"] + list(args), cwd=TOP, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        return p.stdout.decode().strip() if p.returncode == 0 else None
    except OSError:
        return None


def stamp_line(seconds, before=None):
    """Date, commit, machine, the load average now and a run's duration, as the block's first line.
    Made before the run (the code it ran, the load it started under), then given the run's seconds
    as stamp_line(seconds, before)."""
    if before is not None:
        return re.sub(r"the run took [^.]*\.$", "the run took %s." % took(seconds), before)
    commit = git("rev-parse", "--short", "HEAD")
    if commit is None:
        commit = "unknown (not a git clone)"
    elif git("status", "--porcelain", "--untracked-files=no", "--", ".", ":!docs"):
        commit += " with uncommitted changes"
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    n = os.cpu_count() or 0
    return ("Measured by `make bench` on %s at commit %s, on %d core%s (%s), load average %.1f at the start; "
            "the run took %s." % (datetime.date.today().isoformat(), commit, n, "" if n == 1 else "s", cpu,
                                  os.getloadavg()[0], took(seconds)))


def took(seconds):
    return "%.0f s" % seconds if seconds < 120 else "%.0f min" % (seconds / 60)


def capture(build, name):
    return os.path.join(build, "bench", name + ".txt"), os.path.join(build, "bench", name + ".stamp")


def run(build, names):
    os.makedirs(os.path.join(build, "bench"), exist_ok=True)
    env = dict(os.environ)
    env.setdefault("OMP_WAIT_POLICY", "passive")
    for name in names:
        exe = os.path.join(build, "bench_" + name)
        print("%s  (captured in %s)" % (os.path.relpath(exe, TOP), os.path.relpath(capture(build, name)[0], TOP)))
        sys.stdout.flush()
        before, t0 = stamp_line(0), time.time()  # the code and the load the run starts with
        # line-buffered, so the output shows as it comes (stdio buffers a pipe whole)
        cmd = (["stdbuf", "-oL"] if shutil.which("stdbuf") else []) + [exe]
        p = subprocess.Popen(cmd, cwd=TOP, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE)
        out = []
        for raw in p.stdout:
            line = raw.decode("utf-8", "replace")
            out.append(line)
            sys.stdout.write(line)
            sys.stdout.flush()
        if p.wait() != 0:
            print("bench-tables: bench_%s exited with %d; its previous capture is kept" % (name, p.returncode),
                  file=sys.stderr)
            return 1
        seconds = time.time() - t0
        txt, st = capture(build, name)
        with open(txt, "w", encoding="utf-8") as f:
            f.write("".join(out))
        with open(st, "w", encoding="utf-8") as f:
            f.write(stamp_line(seconds, before) + "\n")
    return write(build, names)


def write(build, names):
    with open(PAGE, encoding="utf-8") as f:
        lines = f.read().split("\n")
    found, errors = blocks(lines)
    if errors:
        print("bench-tables: docs/benchmarks.md: " + "; ".join(errors), file=sys.stderr)
        return 1
    where = {n: (a, b) for n, a, b in found}
    missing = [n for n in names if n not in where]
    if missing:
        print("bench-tables: docs/benchmarks.md has no block for %s: add <!-- bench:NAME begin --> and "
              "<!-- bench:NAME end --> where the table belongs" % ", ".join(missing), file=sys.stderr)
        return 1
    done = []
    for name in sorted(names, key=lambda n: -where[n][0]):  # from the bottom: line numbers stay valid
        txt, st = capture(build, name)
        if not (os.path.exists(txt) and os.path.exists(st)):
            continue
        with open(txt, encoding="utf-8") as f:
            out = [l.rstrip() for l in f.read().split("\n")]
        while out and not out[0]:
            out.pop(0)
        while out and not out[-1]:
            out.pop()
        with open(st, encoding="utf-8") as f:
            stamp = f.read().strip()
        a, b = where[name]
        lines[a + 1:b] = [stamp, "", "```text"] + out + ["```"]
        done.append(name)
    with open(PAGE, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))
    skipped = [n for n in names if n not in done]
    print("docs/benchmarks.md: rewrote %s%s" % (", ".join(sorted(done)) or "no block",
                                                 "; no capture of %s, its block kept" % ", ".join(skipped)
                                                 if skipped else ""))
    return 0


def main(argv):
    if len(argv) < 2 or argv[0] not in ("run", "write", "check"):
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    build = os.path.abspath(argv[1])  # as given from the caller's directory (run-tests.sh: tests/)
    names = argv[2:] or benches()
    unknown = [n for n in names if n not in benches()]
    if unknown:
        print("bench-tables: not in the Makefile's BENCHES: %s" % " ".join(unknown), file=sys.stderr)
        return 2
    if argv[0] == "check":
        return check(build)
    return (run if argv[0] == "run" else write)(build, names)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
