"""Checks how the files of each crate import each other.

- No import circle between files: every `use` and every path written in
  the code (`crate::a::b`, `super::c`, `self::d`) is an arrow from the file
  to the file that defines what it names (following `pub use` re-exports);
  an arrow from a file to one of its ancestors (a child using what its
  parent holds) does not count. Any circle that is left, between siblings
  or through other files, is reported with its files.
- No glue: no `use super::*` outside a `#[cfg(test)]` module, no
  `#[allow(unused_imports)]` or `#[allow(clippy::wildcard_imports)]`
  outside tests; every other `#[allow(...)]` outside tests says why
  (`reason = "..."`), and there are at most eight.
- With --layers FILE, each crate is checked against the floor plan in FILE
  (ARCHITECTURE.md): a fenced ```layers block with one line per crate,
  `DIR: a b | c | d e`, the top-level modules from the bottom layer up. A
  module may use a module of its own top-level module or of a lower layer;
  anything else (a shared module using a task's, a task using another
  task's: an arrow back up) is reported, as is a module the plan does not
  place.

Exits 1 if it finds anything.

usage: python3 scripts/module_cycles.py [--layers ARCHITECTURE.md] CRATE_SRC_DIR ...
"""

import os
import re
import sys

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"


def module_of(root: str, path: str) -> tuple[str, ...]:
    """The module path of the file at `path` (`()` for the crate root)."""
    rel = os.path.relpath(path, root)[:-3].split(os.sep)
    if rel[-1] == "mod":
        rel = rel[:-1]
    if rel in (["lib"], ["main"]):
        return ()
    return tuple(rel)


def strip_comments_and_strings(text: str) -> str:
    """`text` with comments, strings and character literals blanked."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            i = n if j < 0 else j + 2
        elif c == "r" and re.match(r'r#*"', text[i:]) and not re.match(r"[A-Za-z0-9_]", text[i - 1 : i] or " "):
            m = re.match(r'r(#*)"', text[i:])
            end = '"' + m.group(1)
            j = text.find(end, i + len(m.group(0)))
            i = n if j < 0 else j + len(end)
            out.append('""')
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            i = j + 1
            out.append('""')
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[i:]):
            i += len(re.match(r"'(\\.|[^\\'])'", text[i:]).group(0))
            out.append("' '")
        else:
            out.append(c)
            i += 1
    return "".join(out)


def without_tests(code: str) -> str:
    """`code` without the items marked `#[cfg(test)]` (a module, or one
    item up to its `;` or the end of its block)."""
    out, i = [], 0
    for m in re.finditer(r"#\[cfg\((?:test|all\(test\b[^\]]*\))\)\]", code):
        if m.start() < i:
            continue
        out.append(code[i : m.start()])
        j = m.end()
        depth = 0
        while j < len(code):
            ch = code[j]
            if ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
                if depth == 0:
                    j += 1
                    break
            elif ch == ";" and depth == 0:
                j += 1
                break
            j += 1
        i = j
    out.append(code[i:])
    return "".join(out)


def use_paths(tree: str) -> list[tuple[list[str], str]]:
    """The paths of a `use` tree (`a::{b, c::{d as e}, *}`), each as its
    segments and the name it brings (`*` for a glob)."""
    tree = re.sub(r"\s+", " ", tree).strip()
    tree = re.sub(r"\s*(::|\{|\}|,)\s*", r"\1", tree)
    out = []

    def walk(prefix: list[str], t: str) -> None:
        if "{" in t:
            k = t.index("{")
            head = [p for p in t[:k].split("::") if p]
            inner = t[k + 1 : t.rindex("}")]
            parts, depth, cur = [], 0, ""
            for ch in inner:
                if ch == "," and depth == 0:
                    parts.append(cur)
                    cur = ""
                    continue
                depth += ch == "{"
                depth -= ch == "}"
                cur += ch
            parts.append(cur)
            for p in parts:
                if p:
                    walk(prefix + head, p)
            return
        path, _, alias = t.partition(" as ")
        full = prefix + [p for p in path.split("::") if p]
        if full and full[-1] == "self":
            full = full[:-1]
        name = alias or (full[-1] if full else "")
        out.append((full, name))

    walk([], tree)
    return out


class Crate:
    def __init__(self, root: str):
        self.root = root
        self.files: dict[tuple[str, ...], str] = {}
        self.code: dict[tuple[str, ...], str] = {}
        for dirpath, _, files in os.walk(root):
            for f in files:
                if f.endswith(".rs"):
                    path = os.path.join(dirpath, f)
                    mod = module_of(root, path)
                    self.files[mod] = path
                    text = open(path, encoding="utf-8").read()
                    self.code[mod] = without_tests(strip_comments_and_strings(text))
        # Only modules that are declared (or the root) count.
        self.reexports: dict[tuple[str, ...], dict[str, list[str]]] = {}
        self.globs: dict[tuple[str, ...], list[list[str]]] = {}
        for mod, code in self.code.items():
            names, globs = {}, []
            for m in re.finditer(r"\bpub(?:\([^)]*\))?\s+use\s+([^;]+);", code):
                for segs, name in use_paths(m.group(1)):
                    if name == "*":
                        globs.append(segs[:-1])
                    elif segs:
                        names[name] = segs
            self.reexports[mod] = names
            self.globs[mod] = globs

    def absolute(self, here: tuple[str, ...], segs: list[str]) -> list[str] | None:
        """The crate-absolute segments of `segs` written in module `here`,
        or None for a path into another crate."""
        if not segs:
            return None
        if segs[0] == "crate":
            return segs[1:]
        if segs[0] in ("super", "self"):
            base = list(here)
            i = 0
            while i < len(segs) and segs[i] in ("super", "self"):
                if segs[i] == "super":
                    base = base[:-1]
                i += 1
            return base + segs[i:]
        # A path relative to the current module: a child module of it.
        if tuple(here) + (segs[0],) in self.files:
            return list(here) + segs
        return None

    def target(self, segs: list[str], seen: int = 0) -> tuple[str, ...] | None:
        """The file that defines the item at crate-absolute `segs`."""
        k = len(segs)
        while k > 0 and tuple(segs[:k]) not in self.files:
            k -= 1
        mod = tuple(segs[:k])
        if mod not in self.files and mod != ():
            return None
        rest = segs[k:]
        if rest and seen < 8:
            re_ = self.reexports.get(mod, {}).get(rest[0])
            if re_ is not None:
                follow = self.absolute(mod, re_)
                if follow is not None:
                    t = self.target(follow + rest[1:], seen + 1)
                    if t is not None:
                        return t
        return mod

    def edges(self) -> dict[tuple[str, ...], set[tuple[str, ...]]]:
        out = {}
        for mod, code in self.code.items():
            deps = set()
            paths = []
            for m in re.finditer(r"\buse\s+([^;]+);", code):
                paths += [segs for segs, name in use_paths(m.group(1))]
            for m in re.finditer(rf"(?<![A-Za-z0-9_:])((?:crate|super|self)(?:::{IDENT})+)", code):
                paths.append(m.group(1).split("::"))
            for segs in paths:
                segs = [s for s in segs if s != "*"]
                a = self.absolute(mod, segs)
                if a is None:
                    continue
                t = self.target(a)
                if t is None or t == mod:
                    continue
                deps.add(t)
            out[mod] = deps
        return out


def is_ancestor(a: tuple[str, ...], b: tuple[str, ...]) -> bool:
    return len(a) < len(b) and b[: len(a)] == a


def circles(graph: dict[tuple[str, ...], set[tuple[str, ...]]]) -> list[list[tuple[str, ...]]]:
    """The strongly connected components of more than one file, once the
    arrows to an ancestor are left out (Tarjan)."""
    g = {m: {d for d in deps if not is_ancestor(d, m)} for m, deps in graph.items()}
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(g.get(v, ())):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
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

    sys.setrecursionlimit(10000)
    for v in sorted(g):
        if v not in index:
            strong(v)
    return out


MAX_ALLOWS = 8


def glue(crate: Crate) -> tuple[list[str], int]:
    """The glue a crate's files hold outside tests, and its `#[allow]`s."""
    out, allows = [], 0
    for mod, code in sorted(crate.code.items()):
        path = crate.files[mod]
        if re.search(r"\buse\s+super::\*\s*;", code):
            out.append(f"{path}: `use super::*` outside a test module: import what the module uses")
        if re.search(r"#\[allow\([^)]*(unused_imports|wildcard_imports)", code):
            out.append(f"{path}: an allowed unused or wildcard import outside tests")
        # (Strings are blanked: a reason reads `reason = ""`.)
        for m in re.finditer(r"#!?\[allow\(([^\]]*)\)\]", code):
            allows += 1
            if "reason" not in m.group(1):
                out.append(f"{path}: #[allow({m.group(1).strip()})] without a reason")
    return out, allows


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


def layer_errors(root: str, graph, layers: list[set[str]]) -> list[str]:
    level = {m: i for i, layer in enumerate(layers) for m in layer}
    out = []
    for module in sorted(graph):
        if module == ():
            continue  # lib.rs / main.rs: the crate's front, above every layer
        top = module[0]
        if top not in level:
            out.append(f"{root}: {'::'.join(module)} is in no layer of the floor plan")
            continue
        for dep in sorted(graph[module]):
            if dep == () or dep[0] == top or dep[0] not in level:
                continue
            if level[dep[0]] >= level[top]:
                where = "the same layer" if level[dep[0]] == level[top] else "a higher layer"
                out.append(f"{root}: {'::'.join(module)} uses {'::'.join(dep)}, in {where}")
    tops = {m[0] for m in graph if m}
    for m in sorted(set(level) - tops):
        out.append(f"{root}: the floor plan places {m}, which is no module")
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
    files = 0
    allows = 0
    for root in args:
        crate = Crate(root)
        files += len(crate.files)
        graph = crate.edges()
        for c in circles(graph):
            names = ", ".join(crate.files[m] for m in c)
            print(f"{root}: import circle between {names}", file=sys.stderr)
            bad += 1
        problems, n = glue(crate)
        allows += n
        for e in problems:
            print(e, file=sys.stderr)
            bad += 1
        if plan is not None:
            if root not in plan:
                print(f"{root}: not in the floor plan of {sys.argv[2]}", file=sys.stderr)
                bad += 1
                continue
            for e in layer_errors(root, graph, plan[root]):
                print(e, file=sys.stderr)
                bad += 1
    if allows > MAX_ALLOWS:
        print(f"{allows} #[allow]s outside tests, more than {MAX_ALLOWS}", file=sys.stderr)
        bad += 1
    if not bad:
        print(
            f"module_cycles: {files} files in {len(args)} crates, no import circle, no glue, "
            f"{allows} #[allow]s each with a reason"
        )
    sys.exit(1 if bad else 0)
