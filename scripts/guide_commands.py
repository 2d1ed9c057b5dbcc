#!/usr/bin/env python3
"""Every command the README and the guide quote, accounted for, and run.

    python3 scripts/guide_commands.py [--run] [--quick] [--errp PATH]

Reads the shell blocks (```sh) of README.md and docs/guide/*.md, joins
continued lines, drops comments, expands the variables a block sets itself
(`args="..."`, `export VAR=...`) and reads `cargo run --release --` as the
`errp` program. Every command found must be one of:

* a figure of scripts/readme_figures.sh (the same `errp` arguments, leaving
  out `--quiet` and the output directory): that script reruns it and checks
  its output (`--check --cheap` in CI, the slow ones by hand);
* a command that another CI step runs, listed in ELSEWHERE with the step;
* otherwise it is run here, with `--run`: each block's commands in order,
  in a fresh directory that holds the repository's `scenarios/` and
  `python/`, and each must exit 0. With `--quick` (CI), the sizes are cut
  so that the run takes a minute: a sweep's `--episodes` to 2 and a run's
  `--runs` to at most 5; the commands are otherwise as quoted.

Without `--run` it only checks that every command is accounted for. Prints
each problem as FILE:LINE: message and exits 1 if there is any. Standard
library only; runs from any directory.
"""

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FILES = ["README.md"] + sorted(
    str(p.relative_to(ROOT)) for p in (ROOT / "docs/guide").glob("*.md"))
FIGURES_SCRIPT = ROOT / "scripts/readme_figures.sh"

# Commands another step of .ci/run runs, by their first words.
ELSEWHERE = {
    "cargo test --workspace": ".ci/run, step 'tests (the README's command)'",
    "python3 -m venv .venv": ".ci/run, step 'the Python package' (a venv, pip install "
                             "\"./python[examples,test]\")",
    "scripts/slurm/submit.sh": ".ci/run, step 'Slurm' (scripts/slurm/test.sh submits with it)",
    "errp stream ": ".ci/run, step 'your online BCI in the loop' (beside the reference client)",
    "python python/examples/lsl_decoder.py": ".ci/run, step 'your online BCI in the loop'",
}
# Lines that only set the shell up: kept for the variables, not commands.
ASSIGNMENT = re.compile(r"^(?:export\s+)?([A-Za-z_][A-Za-z0-9_]*=\S.*)$")
FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})\s*(\w*)")


def blocks(path):
    """The shell blocks of `path`: (first line number, [(line, text)])."""
    out, current, fence = [], None, None
    for n, line in enumerate((ROOT / path).read_text().splitlines(), 1):
        m = FENCE.match(line)
        if fence is None and m:
            fence = m.group(1)
            current = (n + 1, []) if m.group(2) in ("sh", "bash") else None
        elif fence is not None and m and m.group(1)[0] == fence[0] \
                and not m.group(2):
            if current:
                out.append(current)
            fence, current = None, None
        elif current is not None:
            current[1].append((n, line))
    return out


def strip_comment(text):
    """`text` without a trailing `# ...` outside quotes."""
    quote = None
    for i, c in enumerate(text):
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or text[i - 1].isspace()):
            return text[:i].rstrip()
    return text.rstrip()


def commands(path):
    """Each block's commands: (block start, [(line, command text)])."""
    result = []
    for start, lines in blocks(path):
        cmds, pending, first = [], "", None
        for n, line in lines:
            text = strip_comment(line).strip()
            if not text and not pending:
                continue
            first = first or n
            if text.endswith("\\"):
                pending += text[:-1] + " "
                continue
            cmds.append((first, pending + text))
            pending, first = "", None
        result.append((start, cmds))
    return result


def expand(text, env):
    """`$VAR` and `${VAR}` of `env` expanded (others left as they are)."""
    return re.sub(r"\$\{?([A-Za-z_][A-Za-z0-9_]*)\}?",
                  lambda m: env.get(m.group(1), m.group(0)), text)


def errp_args(text):
    """The `errp` arguments of a command, or None if it is not one."""
    for prefix in ("cargo run --release -- ", "errp "):
        if text.startswith(prefix):
            return shlex.split(text[len(prefix):])
    return None


def figure_form(args):
    """The arguments as readme_figures.sh compares them: without `--quiet`
    and the output directory."""
    out, skip = [], False
    for a in args:
        if skip:
            skip = False
        elif a == "--quiet":
            pass
        elif a == "--out":
            skip = True
        else:
            out.append(a)
    return tuple(out)


def figure_commands():
    """name -> arguments of every `errp` figure of readme_figures.sh."""
    found = {}
    for m in re.finditer(r'^\s*"([^"|]+)\|[^"|]*\|([^"]*)"', FIGURES_SCRIPT.read_text(), re.M):
        name, args = m.groups()
        if not args.startswith("sh:"):
            found[figure_form(shlex.split(args.replace("OUT_DIR", "out")))] = name
    return found


def quick(args):
    """The arguments at a size that runs in seconds (--quick)."""
    args = list(args)
    def set_flag(flag, value):
        if flag in args:
            i = args.index(flag)
            args[i + 1] = value(args[i + 1])
        else:
            args.extend([flag, value(None)])
    if args and args[0] == "sweep":
        set_flag("--episodes", lambda _: "2")
    elif args and args[0] == "run" and "--runs" in args:
        set_flag("--runs", lambda v: str(min(int(v), 5)))
    return args


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", action="store_true", help="run the commands no other step runs")
    ap.add_argument("--quick", action="store_true", help="with --run: sizes cut to seconds")
    ap.add_argument("--errp", default=str(ROOT / "target/release/errp"),
                    help="the errp program (default: target/release/errp)")
    opts = ap.parse_args()
    figures = figure_commands()
    problems, to_run, counts = [], [], {"figure": 0, "elsewhere": 0, "run": 0}
    for path in FILES:
        for start, cmds in commands(path):
            env, block = {}, []
            for line, text in cmds:
                m = ASSIGNMENT.match(text)
                if m:
                    name, value = m.group(1).split("=", 1)
                    env[name] = expand(" ".join(shlex.split(value)), env)
                    continue
                text = expand(text, env)
                where = f"{path}:{line}"
                if any(text.startswith(k) for k in ELSEWHERE):
                    counts["elsewhere"] += 1
                    continue
                args = errp_args(text)
                if args is not None and figure_form(args) in figures:
                    counts["figure"] += 1
                    continue
                block.append((where, text, args))
            if block:
                to_run.append((f"{path}:{start}", block))
                counts["run"] += len(block)
    if not opts.run:
        print(f"guide commands: {counts['figure']} are figures of readme_figures.sh, "
              f"{counts['elsewhere']} run in other CI steps, {counts['run']} to run here")
        return 0
    errp = Path(opts.errp).resolve()
    if not errp.is_file():
        print(f"error: --errp {errp}: no such program (cargo build --release)", file=sys.stderr)
        return 2
    for where, block in to_run:
        with tempfile.TemporaryDirectory(prefix="guide-") as work:
            for d in ("scenarios", "python"):
                os.symlink(ROOT / d, Path(work) / d)
            bin_dir = Path(work) / ".bin"
            bin_dir.mkdir()
            os.symlink(errp, bin_dir / "errp")
            env = dict(os.environ, PATH=f"{bin_dir}:{os.environ['PATH']}",
                       ERRP_CACHE_DIR=str(Path(work) / ".cache"))
            for line, text, args in block:
                if args is not None:
                    text = "errp " + text.split(" ", 4 if text.startswith("cargo") else 1)[-1]
                    if opts.quick and quick(args) != args:
                        text = " ".join(shlex.quote(a) for a in ["errp"] + quick(args))
                elif opts.quick and text.startswith("parallel "):
                    text = re.sub(r"--episodes \d+", "--episodes 2", text)
                if text.startswith("parallel ") and shutil.which("parallel") is None:
                    problems.append(f"{line}: needs GNU parallel (apt-get install parallel)")
                    break
                shown = text if len(text) < 110 else text[:107] + "..."
                print(f"{line}: $ {shown}", flush=True)
                r = subprocess.run(["bash", "-c", text], cwd=work, env=env,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                   text=True, timeout=900)
                if r.returncode != 0:
                    tail = r.stderr.strip().splitlines()[-3:]
                    problems.append(f"{line}: exit {r.returncode}: " + " | ".join(tail))
                    break
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        return 1
    print(f"guide commands: {counts['run']} run, {counts['figure']} are figures of "
          f"readme_figures.sh, {counts['elsewhere']} run in other CI steps")
    return 0


if __name__ == "__main__":
    sys.exit(main())
