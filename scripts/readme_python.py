#!/usr/bin/env python3
"""Runs every Python block of the README and the guide, and checks the
values they quote.

    python scripts/readme_python.py [FILE.md ...]

Reads the ```python blocks of README.md, docs/guide/*.md and
python/README.md (or the files given) and runs each in a fresh process, in
an empty temporary directory (a snippet must not depend on where it is run
from), with matplotlib's Agg backend. A line that prints and quotes what it
prints,

    print(len(raw.annotations))   # -> 400

is checked: the printed line must be the quoted text, except that numbers
are compared to the digits quoted (``0.744`` matches 0.7438). Fails (exit
1) on an exception, a block that takes over 10 minutes, or a quoted value
that differs, naming FILE:LINE. Needs the `errp` package and what the
blocks import (the package's `examples` and `test` extras).
"""

import glob
import json
import os
import re
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})\s*(\w*)")
QUOTED = re.compile(r"#\s*->\s*(.+?)\s*$")
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")

# Run in the block's process: records each print by the line it was called
# from, then writes them as JSON to the file named by argv[1].
HARNESS = textwrap.dedent("""
    import builtins, io, json, sys
    _printed, _print = {}, builtins.print
    def _recording_print(*args, **kwargs):
        buf = io.StringIO()
        _print(*args, **{**kwargs, "file": buf})
        line = sys._getframe(1).f_lineno
        if sys._getframe(1).f_code.co_filename == "<snippet>":
            _printed.setdefault(line, []).append(buf.getvalue().rstrip("\\n"))
        _print(*args, **kwargs)
    builtins.print = _recording_print
    source = open(sys.argv[2]).read()
    try:
        exec(compile(source, "<snippet>", "exec"), {"__name__": "__main__"})
    finally:
        with open(sys.argv[1], "w") as f:
            json.dump(_printed, f)
""")


def blocks(path):
    """(first line, source) of each python block of `path`."""
    out, lines, fence, start = [], None, None, 0
    for n, line in enumerate(path.read_text().splitlines(), 1):
        m = FENCE.match(line)
        if fence is None and m:
            fence = m.group(1)
            if m.group(2) == "python":
                lines, start = [], n + 1
        elif fence is not None and m and m.group(1)[0] == fence[0] and not m.group(2):
            if lines is not None:
                out.append((start, "\n".join(lines) + "\n"))
            fence, lines = None, None
        elif lines is not None:
            lines.append(line)
    return out


def matches(quoted, printed):
    """Whether `printed` is `quoted`, numbers to the digits quoted."""
    q_nums, p_nums = NUMBER.findall(quoted), NUMBER.findall(printed)
    if NUMBER.sub("#", quoted).replace(" ", "") != NUMBER.sub("#", printed).replace(" ", ""):
        return False
    if len(q_nums) != len(p_nums):
        return False
    for q, p in zip(q_nums, p_nums):
        decimals = len(q.split(".")[1]) if "." in q and "e" not in q.lower() else 0
        if abs(float(q) - float(p)) > 0.5 * 10 ** -decimals + 1e-12:
            return False
    return True


def run_block(path, start, source):
    """Problems of one block (an empty list if none)."""
    where = f"{path.relative_to(ROOT)}:{start}"
    quotes = {}
    for i, line in enumerate(source.splitlines(), 1):
        m = QUOTED.search(line)
        if m and "print(" in line:
            quotes[i] = m.group(1)
    with tempfile.TemporaryDirectory(prefix="snippet-") as work:
        snippet = Path(work) / "snippet.py"
        snippet.write_text(source)
        printed_file = Path(work) / "printed.json"
        env = dict(os.environ, MPLBACKEND="Agg")
        print(f"{where}: running ({len(source.splitlines())} lines)", flush=True)
        try:
            r = subprocess.run(
                [sys.executable, "-c", HARNESS, str(printed_file), str(snippet)],
                cwd=work, env=env, capture_output=True, text=True, timeout=600,
            )
        except subprocess.TimeoutExpired:
            return [f"{where}: took over 10 minutes"]
        if r.returncode != 0:
            tail = r.stderr.strip().splitlines()[-4:]
            return [f"{where}: failed: " + " | ".join(tail)]
        printed = {int(k): v for k, v in json.loads(printed_file.read_text()).items()}
    problems = []
    for line, quoted in quotes.items():
        got = printed.get(line)
        if not got:
            problems.append(f"{where}: line {start + line - 1} printed nothing "
                            f"(it quotes {quoted!r})")
        elif not matches(quoted, got[-1]):
            problems.append(f"{where}: line {start + line - 1} printed {got[-1]!r}, "
                            f"the text quotes {quoted!r}")
    if not problems:
        print(f"{where}: ok, {len(quotes)} quoted value(s) checked", flush=True)
    return problems


def main(argv):
    files = [Path(a).resolve() for a in argv] or [
        ROOT / "README.md", *sorted(Path(p) for p in glob.glob(str(ROOT / "docs/guide/*.md"))),
        ROOT / "python/README.md",
    ]
    problems, n = [], 0
    for path in files:
        for start, source in blocks(path):
            n += 1
            problems += run_block(path, start, source)
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        return 1
    print(f"readme_python: {n} blocks ran, every quoted value as printed")
    return 0


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):
        print(__doc__.strip())
        sys.exit(0)
    sys.exit(main(sys.argv[1:]))
