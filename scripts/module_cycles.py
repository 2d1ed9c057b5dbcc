"""Reports import circles between the modules of each crate: module A uses
`crate::B...` while B uses `crate::A...` (directly or through up to four
others). A parent's re-exports of its children do not count.

With --layers FILE, also checks each crate against the floor plan in FILE
(ARCHITECTURE.md): a fenced ```layers block with one line per crate,
`DIR: a b | c | d e`, the top-level modules from the bottom layer up. A
module may use a module of its own top-level module or of a lower layer;
anything else (a shared module using a task's, a task using another task's)
is reported, as is a module the plan does not place.

Exits 1 if it finds anything.

usage: python3 scripts/module_cycles.py [--layers ARCHITECTURE.md] CRATE_SRC_DIR ...
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


def read_layers(path: str) -> dict[str, list[set[str]]]:
    """The ```layers block of `path`: crate directory -> layers, bottom first."""
    plan, inside = {}, False
    for line in open(path, encoding="utf-8"):
        line = line.rstrip("\n")
        if line.strip() == "```layers":
            inside = True
        elif inside and line.strip() == "```":
            inside = False
        elif inside and ":" in line and not line.lstrip().startswith("#"):
            root, rest = line.split(":", 1)
            plan[root.strip()] = [set(layer.split()) for layer in rest.split("|")]
    return plan


def layer_errors(root: str, graph: dict[str, set[str]], layers: list[set[str]]) -> list[str]:
    def top(module: str) -> str:
        return module.split("::")[0]

    level = {m: i for i, layer in enumerate(layers) for m in layer}
    out = []
    for module in sorted(graph):
        if module == "crate":
            continue  # lib.rs / main.rs: the crate's front, above every layer
        if top(module) not in level:
            out.append(f"{root}: {module} is in no layer of the floor plan")
            continue
        for dep in sorted(graph[module]):
            if dep == "crate" or top(dep) == top(module):
                continue
            if top(dep) not in level:
                continue  # reported as a module of its own
            if level[top(dep)] >= level[top(module)]:
                where = "the same layer" if level[top(dep)] == level[top(module)] else "a higher layer"
                out.append(f"{root}: {module} uses {dep}, in {where}")
    return out


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):
        print(__doc__.strip())
        sys.exit(0)
    args = sys.argv[1:]
    plan = None
    if args[:1] == ["--layers"]:
        plan = read_layers(args[1])
        args = args[2:]
    bad = 0
    for root in args:
        graph = edges(root)
        for c in sorted(cycles(graph)):
            print(f"{root}: import circle between {', '.join(c)}", file=sys.stderr)
            bad += 1
        if plan is not None:
            if root not in plan:
                print(f"{root}: not in the floor plan of {sys.argv[2]}", file=sys.stderr)
                bad += 1
                continue
            for e in layer_errors(root, graph, plan[root]):
                print(e, file=sys.stderr)
                bad += 1
    sys.exit(1 if bad else 0)
