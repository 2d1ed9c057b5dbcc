#!/usr/bin/env python3
"""No source file of the crates holds more than 480 lines of code.

Counts, for every `.rs` file under the given directories (default: the
crates' sources and the Python binding), the non-blank lines that are not
`//` comments, before the file's `#[cfg(test)]` (its unit tests), and fails
naming each file over the limit. Tests, benches and examples are not
counted.

    python3 scripts/code_sizes.py [DIR...] [--max N]
"""

import argparse
import sys
from pathlib import Path

DIRS = ["bci/src", "robot/src", "sim/src", "sweep/src", "src", "valid/src", "python/rust", "lsl/src"]


def code_lines(path: Path) -> int:
    n = 0
    for line in path.read_text(encoding="utf-8").splitlines():
        s = line.strip()
        if s.startswith("#[cfg(test)]"):
            break
        if s and not s.startswith("//"):
            n += 1
    return n


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dirs", nargs="*", default=DIRS, help="directories to count")
    parser.add_argument("--max", type=int, default=480, help="most code lines a file may hold")
    args = parser.parse_args()
    root = Path(__file__).resolve().parent.parent
    sizes = {}
    for d in args.dirs:
        for path in sorted((root / d).rglob("*.rs")):
            sizes[path.relative_to(root)] = code_lines(path)
    over = {p: n for p, n in sizes.items() if n > args.max}
    for p, n in sorted(over.items(), key=lambda x: -x[1]):
        print(f"code_sizes: {p}: {n} code lines, more than {args.max}", file=sys.stderr)
    if over:
        return 1
    biggest = max(sizes.items(), key=lambda x: x[1]) if sizes else ("-", 0)
    print(
        f"code_sizes: {len(sizes)} files, none over {args.max} code lines "
        f"(the largest: {biggest[0]}, {biggest[1]})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
