#!/usr/bin/env python3
"""Checks the links and quoted figures of the project's Markdown.

    python3 scripts/check_docs.py

Reads README.md, CONTRIBUTING.md, ARCHITECTURE.md, python/README.md and
every docs/guide/*.md, and checks that:

* every relative link or image target, `[text](path)` or `![alt](path)`
  (not http, https or mailto; links in fenced code blocks and inline code
  are not links), exists relative to the file; with `#anchor`, that a
  heading of the target Markdown file has that anchor (GitHub's rules:
  lowercase, punctuation but '-' and '_' removed, spaces to '-', the text
  of inline code kept, a repeated heading gets -1, -2, ...); a bare
  `#anchor` is looked up in the same file;
* every `docs/figures/NAME.txt` the files mention (in prose, code or links)
  exists, and NAME is a figure of scripts/readme_figures.sh's FIGURES
  array, so that every figure quoted is one the script reruns (a pattern
  such as `docs/figures/epuck_*.txt` must match at least one such figure;
  a NAME in capitals only is a placeholder and skipped);
* every chapter of docs/guide/ is linked from docs/guide/README.md, and
  docs/guide/README.md from README.md;
* ARCHITECTURE.md's tables match the tree: under each crate's heading
  (### `name` (`dir/`)), a table row for every source file of the crate
  (`dir/src/**/*.rs`; the Python package: `python/rust/*.rs` and
  `python/src/errp/*`), and no row for a file that does not exist; in its
  folder and script tables, every folder named exists, every folder of
  scenarios/ has a row and every script of scripts/ is named.

Prints each problem as FILE:LINE: message and exits 1 if there is any;
otherwise prints a one-line summary and exits 0. Runs from any directory.
Standard library only.
"""

import fnmatch
import os
import re
import sys
import unicodedata
from pathlib import Path
from urllib.parse import unquote

ROOT = Path(__file__).resolve().parent.parent
FIXED_FILES = ["README.md", "CONTRIBUTING.md", "ARCHITECTURE.md", "python/README.md"]
GUIDE = Path("docs/guide")
FIGURES_SCRIPT = Path("scripts/readme_figures.sh")

FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})")
# An inline code span: a run of backticks, then anything up to the same run,
# within one paragraph (a code span may wrap, but not across a blank line).
CODE_SPAN = re.compile(r"(?<!`)(`+)(?!`)((?:(?!\n[ \t]*\n).)+?)(?<!`)\1(?!`)", re.S)
# [text](target) or ![alt](target): the text may wrap and hold one level of
# brackets; the target may be <...> or a plain one with balanced parentheses,
# optionally followed by a title.
LINK = re.compile(
    r"(!?)\[((?:[^\[\]]|\[[^\[\]]*\])*)\]"
    r"\(\s*(<[^>\n]*>|(?:[^()\s]|\([^()\s]*\))+)(?:\s+(?:\"[^\"]*\"|'[^']*'|\([^()]*\)))?\s*\)",
    re.S,
)
REF_DEF = re.compile(r"^ {0,3}\[([^\]]+)\]:\s*(<[^>]*>|\S+)", re.M)
HEADING = re.compile(r"^ {0,3}(#{1,6})[ \t]+(.*?)[ \t]*#*[ \t]*$")
HTML_ANCHOR = re.compile(r"<a\s+(?:name|id)=\"([^\"]+)\"", re.I)
FIGURE = re.compile(r"docs/figures/([A-Za-z0-9_.*?\[\]-]+?)\.txt")
FIGURE_ENTRY = re.compile(r'^\s*"([^"|]+)\|[^"|]*\|')


def blank_code(text):
    """The text with fenced code blocks and inline code spans replaced by
    spaces (newlines kept), so that offsets and line numbers still hold."""
    out = []
    fence = None
    for line in text.splitlines(keepends=True):
        m = FENCE.match(line)
        if fence is None and m:
            fence = m.group(1)
            out.append(re.sub(r"[^\n]", " ", line))
        elif fence is not None:
            if m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence) \
                    and not line.strip()[len(m.group(1)):].strip():
                fence = None
            out.append(re.sub(r"[^\n]", " ", line))
        else:
            out.append(line)
    prose = "".join(out)
    return CODE_SPAN.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), prose)


def strip_inline_code_keep_text(text):
    """Heading text as GitHub renders it: code spans keep their text."""
    return CODE_SPAN.sub(lambda m: m.group(2).strip(), text)


def slug(heading):
    """GitHub's anchor of a heading's text (before de-duplication)."""
    text = strip_inline_code_keep_text(heading)
    # Links keep their text; images and HTML tags go.
    text = re.sub(r"!\[[^\]]*\]\([^)]*\)", "", text)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"<[^>]+>", "", text)
    text = text.strip().lower()
    kept = []
    for ch in text:
        cat = unicodedata.category(ch)
        if ch in "-_ " or cat[0] in "LNM":
            kept.append(ch)
    return "".join(kept).replace(" ", "-")


def anchors_of(path, cache={}):
    """Every anchor a Markdown file defines: its headings' slugs (repeats
    numbered as GitHub numbers them) and explicit HTML anchors."""
    if path in cache:
        return cache[path]
    text = path.read_text(encoding="utf-8")
    found = set()
    counts = {}
    fence = None
    for line in text.splitlines():
        m = FENCE.match(line)
        if fence is None and m:
            fence = m.group(1)
            continue
        if fence is not None:
            if m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence):
                fence = None
            continue
        for a in HTML_ANCHOR.findall(line):
            found.add(a)
        h = HEADING.match(line)
        if h:
            base = slug(h.group(2))
            n = counts.get(base, 0)
            counts[base] = n + 1
            found.add(base if n == 0 else f"{base}-{n}")
    cache[path] = found
    return found


def line_of(text, offset):
    return text.count("\n", 0, offset) + 1


def figure_names():
    names = []
    for line in (ROOT / FIGURES_SCRIPT).read_text(encoding="utf-8").splitlines():
        m = FIGURE_ENTRY.match(line)
        if m:
            names.append(m.group(1))
    return names


ARCH = Path("ARCHITECTURE.md")
CRATE_HEADING = re.compile(r"^### `([a-z_]+)` \(`([a-z_]+)/`\)")
ROW = re.compile(r"^\|\s*`([^`]+)`")


def crate_files(folder):
    """The source files a crate's table must list, relative to `folder`."""
    if folder == "python":
        files = [f"rust/{p.name}" for p in Path("python/rust").glob("*.rs")]
        files += [f"src/errp/{p.name}" for p in Path("python/src/errp").iterdir()
                  if p.suffix in (".py", ".pyi")]
        return set(files)
    base = Path(folder) / "src"
    return {str(p.relative_to(base)) for p in base.rglob("*.rs")}


def check_architecture(problems):
    """ARCHITECTURE.md's module, folder and script tables against the tree;
    returns the number of module rows checked."""
    if not ARCH.is_file():
        return 0
    lines = ARCH.read_text(encoding="utf-8").splitlines()
    sections = []  # (crate, folder, line, {file: line})
    current = None
    in_code = False
    named = set()  # every backticked path in a table's first cell
    for n, line in enumerate(lines, 1):
        if FENCE.match(line):
            in_code = not in_code
            continue
        if in_code:
            continue
        m = CRATE_HEADING.match(line)
        if m:
            current = (m.group(1), "." if m.group(2) == "src" else m.group(2), n, {})
            sections.append(current)
            continue
        if line.startswith("#"):
            current = None
            continue
        m = ROW.match(line)
        if not m:
            continue
        for cell in re.findall(r"`([^`]+)`", line.split("|")[1]):
            named.add(cell)
        if current is not None:
            current[3][m.group(1)] = n
    checked = 0
    if not sections:
        problems.append(f"{ARCH}:1: no crate table (### `name` (`dir/`))")
    for crate, folder, at, rows in sections:
        want = crate_files(folder) if folder != "." else {
            str(p.relative_to("src")) for p in Path("src").rglob("*.rs")}
        if not want:
            problems.append(f"{ARCH}:{at}: {crate}: no source files under {folder}/")
        for f, n in rows.items():
            checked += 1
            if f not in want:
                problems.append(f"{ARCH}:{n}: {crate}: {f} is no source file of the crate")
        for f in sorted(want - set(rows)):
            problems.append(f"{ARCH}:{at}: {crate}: {f} has no row in the table")
    # The folder and script tables.
    for cell in sorted(named):
        path = cell.split(" ")[0]
        if path.endswith("/") or path.startswith("scripts/") or path.startswith(".ci/"):
            if "*" in path:
                if not list(Path(".").glob(path.rstrip("/"))):
                    problems.append(f"{ARCH}:1: {path} matches nothing")
            elif not Path(path).exists():
                problems.append(f"{ARCH}:1: {path} does not exist")
    for d in sorted(p for p in Path("scenarios").iterdir() if p.is_dir()):
        if f"{d}/" not in named:
            problems.append(f"{ARCH}:1: the folder {d}/ has no row")
    text = ARCH.read_text(encoding="utf-8")
    for p in sorted(Path("scripts").iterdir()):
        name = p.name + ("/" if p.is_dir() else "")
        if not re.search(r"`(scripts/)?" + re.escape(name) + r"`", text):
            problems.append(f"{ARCH}:1: scripts/{name} is not named")
    return checked


def main():
    os.chdir(ROOT)
    problems = []
    files = [Path(f) for f in FIXED_FILES if Path(f).is_file()]
    missing = [f for f in FIXED_FILES if not Path(f).is_file()]
    for f in missing:
        problems.append(f"{f}:1: file not found")
    chapters = sorted(GUIDE.glob("*.md"))
    files += chapters
    figures = figure_names()
    if not figures:
        problems.append(f"{FIGURES_SCRIPT}:1: no figure lines (\"name|cost|...\") in FIGURES")

    links_checked = 0
    anchors_checked = 0
    figures_checked = 0
    # Resolved targets linked from each file, for the guide's index checks.
    linked_from = {}

    for f in files:
        text = f.read_text(encoding="utf-8")
        prose = blank_code(text)
        targets = []
        for m in LINK.finditer(prose):
            target = m.group(3)
            if target.startswith("<") and target.endswith(">"):
                target = target[1:-1]
            targets.append((line_of(prose, m.start(3)), target))
        for m in REF_DEF.finditer(prose):
            target = m.group(2)
            if target.startswith("<") and target.endswith(">"):
                target = target[1:-1]
            targets.append((line_of(prose, m.start(2)), target))

        resolved_here = set()
        for line, target in targets:
            if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):
                if not re.match(r"^(https?|mailto):", target, re.I):
                    problems.append(f"{f}:{line}: link to {target}: scheme is not http, https or mailto")
                continue
            links_checked += 1
            path_part, _, anchor = target.partition("#")
            path_part = unquote(path_part)
            if path_part:
                dest = (f.parent / path_part)
                if not dest.exists():
                    problems.append(f"{f}:{line}: link target {path_part} does not exist "
                                    f"(resolved to {os.path.normpath(dest)})")
                    continue
                dest_norm = Path(os.path.normpath(dest))
            else:
                dest_norm = Path(os.path.normpath(f))
            resolved_here.add(dest_norm)
            if anchor:
                anchor = unquote(anchor)
                if dest_norm.is_dir():
                    readme = dest_norm / "README.md"
                    md = readme if readme.is_file() else None
                else:
                    md = dest_norm if dest_norm.suffix.lower() in (".md", ".markdown") else None
                if md is None:
                    continue
                anchors_checked += 1
                if anchor not in anchors_of(md):
                    problems.append(f"{f}:{line}: no heading with anchor #{anchor} in {md}")
        linked_from[Path(os.path.normpath(f))] = resolved_here

        # Figures quoted anywhere in the file, code included.
        for m in FIGURE.finditer(text):
            name = m.group(1)
            line = line_of(text, m.start())
            if re.fullmatch(r"[A-Z_]+", name):
                continue  # a placeholder, as in "docs/figures/NAME.txt"
            figures_checked += 1
            if any(c in name for c in "*?["):
                matched = fnmatch.filter(figures, name)
                if not matched:
                    problems.append(f"{f}:{line}: docs/figures/{name}.txt matches no figure of "
                                    f"{FIGURES_SCRIPT}")
                for n in matched:
                    if not Path(f"docs/figures/{n}.txt").is_file():
                        problems.append(f"{f}:{line}: docs/figures/{n}.txt (from "
                                        f"docs/figures/{name}.txt) does not exist")
                continue
            if not Path(f"docs/figures/{name}.txt").is_file():
                problems.append(f"{f}:{line}: docs/figures/{name}.txt does not exist")
            if name not in figures:
                problems.append(f"{f}:{line}: docs/figures/{name}.txt is not a figure of "
                                f"{FIGURES_SCRIPT} (its FIGURES array), so nothing reruns it")

    index = GUIDE / "README.md"
    if not index.is_file():
        problems.append(f"{index}:1: the guide's index does not exist")
    else:
        from_index = linked_from.get(index, set())
        for chapter in chapters:
            if chapter == index:
                continue
            if Path(os.path.normpath(chapter)) not in from_index:
                problems.append(f"{index}:1: chapter {chapter.name} is not linked from the index")
        from_readme = linked_from.get(Path("README.md"), set())
        if index not in from_readme and GUIDE not in from_readme:
            problems.append(f"README.md:1: the guide's index {index} is not linked")

    modules_checked = check_architecture(problems)

    for p in problems:
        print(p)
    if problems:
        print(f"check_docs: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print(f"check_docs: {len(files)} files, {links_checked} relative links "
          f"({anchors_checked} with anchors), {figures_checked} figure mentions and "
          f"ARCHITECTURE.md's {modules_checked} module rows checked; all good")
    return 0


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):
        print(__doc__.strip())
        sys.exit(0)
    sys.exit(main())
