"""Reports dependencies a workspace crate declares and never uses, as
`cargo machete` does: a `[dependencies]` entry whose crate name appears in
none of the crate's sources (`name::`, `use name`, `name!`, `extern crate
name`), or a `[dev-dependencies]` entry that its tests, benches, examples
and sources never name. A dependency kept for its features alone is listed
in `[package.metadata.unused-deps] ignored = [...]` with the reason beside
it. Exits 1 if it finds one.

usage: python3 scripts/unused_deps.py   (from anywhere in the repository)
"""

import os
import re
import sys
import tomllib

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def sources(crate_dir: str, folders: list[str]) -> str:
    text = []
    for folder in folders:
        base = os.path.join(crate_dir, folder)
        if os.path.isfile(base):
            text.append(open(base, encoding="utf-8").read())
            continue
        for dirpath, _, files in os.walk(base):
            if "target" in dirpath.split(os.sep):
                continue
            for f in files:
                if f.endswith(".rs"):
                    text.append(open(os.path.join(dirpath, f), encoding="utf-8").read())
    return "\n".join(text)


def used(ident: str, text: str) -> bool:
    pattern = rf"(\b{ident}\s*::|\buse\s+{ident}\b|\b{ident}!|extern\s+crate\s+{ident}\b)"
    return re.search(pattern, text) is not None


def check(crate_dir: str) -> list[str]:
    manifest = tomllib.load(open(os.path.join(crate_dir, "Cargo.toml"), "rb"))
    ignored = set(
        manifest.get("package", {}).get("metadata", {}).get("unused-deps", {}).get("ignored", [])
    )
    name = manifest.get("package", {}).get("name", crate_dir)
    main = sources(crate_dir, ["src", "build.rs", "rust"])
    every = main + sources(crate_dir, ["tests", "benches", "examples"])
    out = []
    for table, text in (("dependencies", main), ("dev-dependencies", every)):
        for dep, spec in manifest.get(table, {}).items():
            package = spec.get("package", dep) if isinstance(spec, dict) else dep
            ident = dep.replace("-", "_")
            if dep in ignored or package in ignored:
                continue
            if not used(ident, text):
                out.append(f"{crate_dir}/Cargo.toml: [{table}] {dep} is never used by {name}")
    return out


def main() -> int:
    workspace = tomllib.load(open(os.path.join(ROOT, "Cargo.toml"), "rb"))
    members = ["."] + workspace.get("workspace", {}).get("members", [])
    problems = [p for m in members for p in check(os.path.normpath(os.path.join(ROOT, m)))]
    for p in problems:
        print(os.path.relpath(p, ROOT) if p.startswith("/") else p, file=sys.stderr)
    if not problems:
        print(f"unused_deps: {len(members)} crates, every dependency used")
    return 1 if problems else 0


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):
        print(__doc__.strip())
        sys.exit(0)
    sys.exit(main())
