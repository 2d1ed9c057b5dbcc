"""What the fuzz families of fuzz_cli.py share: a value written as TOML,
and the verdict on a finished command (see fuzz_cli.py's docstring)."""

import math


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


if __name__ == "__main__":
    # A module of fuzz_cli.py: it runs nothing by itself.
    import sys as _sys

    print(__doc__.strip())
    _sys.exit(0 if {"-h", "--help"} & set(_sys.argv[1:]) else 2)
