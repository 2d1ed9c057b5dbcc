"""What the fuzz families of fuzz_cli.py share: a value written as TOML,
the verdict on a finished command, a case's command run and judged, and
the `--help` of a family's module (see fuzz_cli.py's docstring)."""

import math
import subprocess
import sys


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def verdict(p, out, names, named):
    """What is wrong with a finished command `p` whose outputs go to `out`,
    or None: an exit code other than 0 or 2; on 2, a message that does not
    start with `error: ` or names none of `names` (`named` says what they
    are), or anything left in `out`; on 0, a temporary or a lock left."""
    left = sorted(str(x.relative_to(out)) for x in out.rglob("*"))
    if p.returncode not in (0, 2):
        return f"exit code {p.returncode}"
    if p.returncode == 2:
        if not p.stderr.startswith("error:") or not any(n in p.stderr for n in names):
            return f"exit 2 without `error:` naming {named}"
        if left:
            return f"exit 2 left {left}"
    elif any(".partial-" in x or x.endswith(".lock") for x in left):
        return f"exit 0 left {left}"
    return None


def judged(case, argv, out, names, named, gib, limit_memory, **run):
    """Runs `case`'s command `argv` (its address space limited to `gib`
    GiB, at most two minutes; `run`: `cwd`, `env`) and judges it by
    `verdict`: (failure or None, exit code)."""
    try:
        p = subprocess.run(argv, capture_output=True, text=True, timeout=120,
                           preexec_fn=limit_memory(gib), **run)
    except subprocess.TimeoutExpired:
        return f"{case.label}: no answer within 120 s: {case.command()}", None
    why = verdict(p, out, names, named)
    if why:
        return f"{case.label}: {why}: {case.command()}\n{p.stderr[-600:]}", p.returncode
    return None, p.returncode


def module_help(doc):
    """A family's module run by itself: it runs nothing, prints `doc`, and
    exits 0 if asked for help (2 otherwise)."""
    print(doc.strip())
    sys.exit(0 if {"-h", "--help"} & set(sys.argv[1:]) else 2)


if __name__ == "__main__":
    module_help(__doc__)
