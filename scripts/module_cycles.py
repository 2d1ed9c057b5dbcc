"""Reports import circles between the modules of each crate: module A uses
`crate::B...` while B uses `crate::A...` (directly or through up to four
others). A parent's re-exports of its children do not count. Exits 1 if it
finds one.

usage: python3 scripts/module_cycles.py CRATE_SRC_DIR ...
"""

import os
import re
import sys


def module_of(root: str, path: str) -> str:
    rel = os.path.relpath(path, root)[:-3].replace(os.sep, "::")
    rel = rel.removesuffix("::mod")
    return "crate" if rel in ("lib", "main") else rel


def is_module(root: str, parts: list[str]) -> bool:
    base = os.path.join(root, *parts)
    return os.path.exists(base + ".rs") or os.path.exists(os.path.join(base, "mod.rs"))


def edges(root: str) -> dict[str, set[str]]:
    out = {}
    for dirpath, _, files in os.walk(root):
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(dirpath, f)
            me = module_of(root, path)
            text = open(path, encoding="utf-8").read().split("#[cfg(test)]")[0]
            deps = set()
            for m in re.finditer(r"crate::([a-z_]+(?:::[a-z_]+)*)", text):
                parts = m.group(1).split("::")
                for k in range(len(parts), 0, -1):
                    if is_module(root, parts[:k]):
                        deps.add("::".join(parts[:k]))
                        break
            deps.discard(me)
            out[me] = deps
    return out


def cycles(graph: dict[str, set[str]]) -> set[tuple[str, ...]]:
    found = set()
    for start in graph:
        stack = [(start, [start])]
        while stack:
            node, path = stack.pop()
            for dep in graph.get(node, ()):
                if start.startswith(dep + "::") or node.startswith(dep + "::"):
                    continue  # a child using its parent's re-exports
                if dep == start:
                    found.add(tuple(sorted(path)))
                elif dep not in path and len(path) < 5:
                    stack.append((dep, path + [dep]))
    return found


if __name__ == "__main__":
    bad = 0
    for root in sys.argv[1:]:
        for c in sorted(cycles(edges(root))):
            print(f"{root}: import circle between {', '.join(c)}", file=sys.stderr)
            bad += 1
    sys.exit(1 if bad else 0)
