"""The recordings cases of fuzz_cli.py: `errp inspect` on recordings that
are cut short, have bits flipped, are empty, doubled or followed by
garbage (see fuzz_cli.py's docstring).

Three recordings are made once (a grid run, an e-puck run, a calibration);
each case damages a copy and runs `errp inspect FILE --csv OUT/tables`,
which must exit 0 (the damage is in bytes it does not need) or 2 (with
`error: ` naming the file), never panic or hang, and on exit 2 leave
nothing in OUT. A recording that is read must give the same tables as the
undamaged one whenever its bytes are unchanged where the tables live; that
is not checked here (the digest tests do), only that nothing is invented
on exit 2.
"""

import random
import shutil
import subprocess
import tempfile
from pathlib import Path

from fuzz_common import judged

ROOT = Path(__file__).resolve().parent.parent

#: What each base recording is made with (`OUT` is the file).
MAKERS = {
    "grid": ["run", "scenarios/grid_fixed_goals.toml", "--decoder", "oracle", "-q",
             "--save", "OUT"],
    "epuck": ["run", "scenarios/mexico_to_pisa.toml", "--runs", "1", "-q", "--save", "OUT"],
    "calibration": ["calibrate", "--accuracy", "0.75", "--seed", "2", "-q", "--save", "OUT"],
}

#: Truncation points and bit flips per recording.
CUTS, FLIPS = 30, 60


class Damage:
    """One damaged copy: `kind` of recording, `how` it is damaged."""

    def __init__(self, kind, how, apply):
        self.kind, self.how, self.apply = kind, how, apply
        self.label = f"recording {kind}: {how}"

    def command(self):
        return f"errp inspect <{self.kind} recording, {self.how}> --csv OUT/tables"


def make_bases(errp, into):
    """The three base recordings, made once into `into`."""
    bases = {}
    for kind, args in MAKERS.items():
        path = Path(into) / f"{kind}.rrd"
        subprocess.run([errp] + [str(path) if a == "OUT" else a for a in args],
                       cwd=ROOT, check=True, capture_output=True, timeout=600)
        bases[kind] = path.read_bytes()
    return bases


def recording_cases(seed, sizes):
    """The damages, for recordings of `sizes` (kind -> bytes), drawn from
    `seed`: CUTS truncations and FLIPS bit flips of each, and four whole-file
    damages."""
    rng = random.Random(seed)
    cases = []
    for kind, size in sizes.items():
        cuts = sorted({0, 1, 4, 8, 12, 16, size - 1, size - 32, size - 33}
                      | {rng.randrange(size) for _ in range(CUTS)})
        for at in cuts[:CUTS + 9]:
            cases.append(Damage(kind, f"cut at byte {at} of {size}",
                                lambda b, at=at: b[:at]))
        for _ in range(FLIPS):
            at, bit = rng.randrange(size), rng.randrange(8)

            def flip(b, at=at, bit=bit):
                b = bytearray(b)
                b[at] ^= 1 << bit
                return bytes(b)

            cases.append(Damage(kind, f"bit {bit} of byte {at} flipped", flip))
        cases.append(Damage(kind, "doubled", lambda b: b + b))
        cases.append(Damage(kind, "followed by 1000 bytes of garbage",
                            lambda b, r=rng.randbytes(1000): b + r))
        cases.append(Damage(kind, "its header only", lambda b: b[:12]))
        cases.append(Damage(kind, "zeros of its length", lambda b: bytes(len(b))))
    return cases


def run_damage(errp, bases, case, gib, limit_memory):
    """Runs one case; returns (failure or None, exit code)."""
    work = Path(tempfile.mkdtemp(prefix="errp-fuzz-rrd-"))
    try:
        f = work / "x.rrd"
        f.write_bytes(case.apply(bases[case.kind]))
        out = work / "out"
        out.mkdir()
        return judged(case, [errp, "inspect", str(f), "--csv", str(out / "tables")], out,
                      ("x.rrd",), "the file", gib, limit_memory, cwd=work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    # A module of fuzz_cli.py: it runs nothing by itself.
    from fuzz_common import module_help

    module_help(__doc__)
