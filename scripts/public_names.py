#!/usr/bin/env python3
"""No two public types of the workspace share a name.

Reads every `pub struct`, `pub enum`, `pub trait`, `pub type` and
`pub union` of the crates' sources (not their tests), and fails naming each
name that two of them give, with where. One name is shared on purpose:

- `Result`, each crate's `Result<T>` over its own error type (the
  `thiserror` convention of every crate the project takes after: `io`,
  `serde_json`, `rerun`); it is always written through its crate's path.

    python3 scripts/public_names.py [DIR...]
"""

import os
import re
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from module_cycles import strip_comments_and_strings, without_tests  # noqa: E402

DIRS = ["src", "valid/src", "bci/src", "robot/src", "sim/src", "sweep/src", "python/rust", "lsl/src"]
SHARED = {"Result"}


def main() -> int:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    dirs = sys.argv[1:] or DIRS
    seen = defaultdict(list)
    for d in dirs:
        for dirpath, _, files in os.walk(os.path.join(root, d)):
            for f in sorted(files):
                if not f.endswith(".rs"):
                    continue
                path = os.path.join(dirpath, f)
                code = without_tests(strip_comments_and_strings(open(path, encoding="utf-8").read()))
                for m in re.finditer(r"(?m)^\s*pub\s+(struct|enum|trait|type|union)\s+([A-Za-z_][A-Za-z0-9_]*)", code):
                    seen[m.group(2)].append(os.path.relpath(path, root))
    bad = {name: paths for name, paths in seen.items() if len(paths) > 1 and name not in SHARED}
    for name, paths in sorted(bad.items()):
        print(f"public_names: {name} is the name of {len(paths)} public types: {', '.join(paths)}", file=sys.stderr)
    if bad:
        return 1
    print(f"public_names: {len(seen)} public type names, each given once (but {', '.join(sorted(SHARED))})")
    return 0


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):
        print(__doc__.strip())
        sys.exit(0)
    sys.exit(main())
