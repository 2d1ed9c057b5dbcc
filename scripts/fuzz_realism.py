"""The realism cases of fuzz_cli.py: every field of the simulated user's
`[realism]` table given an edge value, through each way a user sets it.

* in a scenario file: `errp run FILE` (grid with the oracle decoder and
  e-puck with one run, so that a valid case takes seconds), and the same
  file as the user of `errp realism --grid FILE` and `errp table1
  --realism FILE --episodes 1`;
* as a sweep level: `errp sweep --scenario FILE --param realism.FIELD=V,W`
  (two levels, the shipped value and the edge one).

Each must exit 0 or 2 (never a panic, an abort or a hang); on 2 print
`error: ` naming the field (`realism.FIELD`) or the file (or the accuracy
that a user so changed cannot reach), and leave its output directory
empty; on 0 leave no temporary or lock.
"""

import math
import os
import random
import re
import shutil
import tempfile
import tomllib
from pathlib import Path

from fuzz_common import judged, toml_value

ROOT = Path(__file__).resolve().parent.parent

#: Every field of `[realism]` (bci/src/generator/realism.rs, `Realism`).
FIELDS = [
    "background_drift", "alpha_drift", "drift_secs", "electrode_drift_uv",
    "electrode_drift_secs", "errp_amplitude_per_hour", "errp_latency_ms_per_hour",
    "expectancy", "expectancy_reference", "expectancy_actions", "erp_latency_shift_ms",
    "erp_gain", "clock_offset_secs", "lapse_rate", "lapse_per_hour", "misjudge_rate",
    "emg_rate_hz", "emg_uv", "emg_secs", "pop_rate_hz", "pop_uv", "bad_channel",
    "bad_channel_uv", "task_latency_ms", "task_gain", "day", "day_latency_sd_ms",
    "day_gain_sd", "action_blink_probability", "action_blink_latency_ms",
    "trial_latency_sd_ms",
]

#: Values of every TOML type at the edges of what a field could take.
VALUES = [
    0, 1, -1, 3650, 3651, 10**11, 2**63 - 1, -(2**63),
    0.0, 0.5, 1.0, 1.5, -0.5, 300.0, 300.5, 1e6, 1e308, 1e-300, -1e308,
    math.nan, math.inf, -math.inf,
    "", "FCz", "Q9", "x" * 10_000, True, [], [1.0], {},
]

#: The scenarios whose user is changed: one of each task.
SCENARIOS = {
    "grid": ROOT / "scenarios" / "grid_fixed_goals.toml",
    "epuck": ROOT / "scenarios" / "mexico_to_pisa.toml",
}


def with_field(text, field, value):
    """`text` (a scenario) with `realism.FIELD = value`, in its `[realism]`
    table (made if it has none), the field's own line replaced."""
    line = f"{field} = {toml_value(value)}"
    lines = [l for l in text.splitlines() if not re.match(rf"\s*{field}\s*=", l)]
    if any(l.strip() == "[realism]" for l in lines):
        at = next(i for i, l in enumerate(lines) if l.strip() == "[realism]")
        lines.insert(at + 1, line)
    else:
        lines += ["", "[realism]", line]
    return "\n".join(lines) + "\n"


def level_text(value):
    """`value` as a sweep level writes it, or None if a level cannot hold it
    (`--param` levels are numbers or words, no arrays or tables)."""
    if isinstance(value, (list, dict)) or isinstance(value, bool):
        return None
    if isinstance(value, str):
        return value if value and "," not in value and len(value) < 200 else None
    if isinstance(value, float) and math.isnan(value):
        return "nan"
    if isinstance(value, float) and math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return repr(value) if isinstance(value, float) else str(value)


class RealismCase:
    """One field set to one value, through `way` ("run", "realism",
    "table1" or "sweep"), on the `task`'s shipped scenario."""

    def __init__(self, task, field, value, way):
        self.task, self.field, self.value, self.way = task, field, value, way
        shown = toml_value(value)
        if len(shown) > 40:
            shown = shown[:20] + f"... ({len(shown)} characters)"
        self.label = f"realism {task} {way}: {field} = {shown}"

    def command(self):
        return {
            "run": f"errp run <{self.task} scenario with {self.label.split(': ', 1)[1]}>",
            "realism": "errp realism --grid <that scenario>",
            "table1": "errp table1 --realism <that scenario> --episodes 1",
            "sweep": f"errp sweep --scenario <{self.task} scenario> --param "
                     f"realism.{self.field}=<shipped>,{level_text(self.value)}",
        }[self.way]

    def argv(self, file, out):
        if self.way == "run":
            extra = ["--decoder", "oracle"] if self.task == "grid" else ["--runs", "1"]
            return ["run", str(file), "--quiet", "--save", str(out / "x.rrd")] + extra
        if self.way == "realism":
            return ["realism", "--grid", str(file), "--epuck", str(SCENARIOS["epuck"]),
                    "--quiet"]
        if self.way == "table1":
            return ["table1", "--realism", str(file), "--episodes", "1", "--decoder", "oracle",
                    "--quiet"]
        shipped = tomllib.loads(SCENARIOS[self.task].read_text()).get("realism", {})
        base = level_text(shipped.get(self.field, 0))
        return ["sweep", "--scenario", str(file), "--param",
                f"realism.{self.field}={base},{level_text(self.value)}", "--episodes", "1",
                "--seed", "1", "--no-cache", "--quiet", "--out", str(out / "s")]


def realism_cases(seed):
    """Every field with every value in a file (`run`, both tasks), and a
    seeded sample of them as sweep levels and through `errp realism` and
    `errp table1` (which take longer)."""
    rng = random.Random(seed)
    cases = []
    for task in SCENARIOS:
        for field in FIELDS:
            for value in VALUES:
                cases.append(RealismCase(task, field, value, "run"))
                # (A level is a number or a word: not the empty channel
                # name the shipped user has.)
                if (field != "bad_channel" and level_text(value) is not None
                        and rng.random() < 0.25):
                    cases.append(RealismCase(task, field, value, "sweep"))
    for field in FIELDS:
        for value in rng.sample(VALUES, 6):
            cases.append(RealismCase("grid", field, value, "realism"))
            cases.append(RealismCase("grid", field, value, "table1"))
    return cases


def run_realism(errp, case, gib, limit_memory):
    """Runs one case; returns (failure or None, exit code)."""
    work = Path(tempfile.mkdtemp(prefix="errp-fuzz-realism-"))
    try:
        file = work / f"{case.task}.toml"
        text = SCENARIOS[case.task].read_text()
        # A sweep's file is the shipped one; its level holds the value.
        file.write_text(text if case.way == "sweep" else
                        with_field(text, case.field, case.value))
        out = work / "out"
        out.mkdir()
        # A user so unlike a person that the decoder cannot reach the
        # scenario's accuracy (no ErrP, half the actions misjudged) is
        # refused for that accuracy, naming it.
        names = (f"realism.{case.field}", file.name, "realism", "accuracy = ")
        return judged(case, [errp] + case.argv(file, out), out, names, "the field or the file",
                      gib, limit_memory, cwd=work,
                      env=dict(os.environ, ERRP_CACHE_DIR=str(work / "cache")))
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    # A module of fuzz_cli.py: it runs nothing by itself.
    from fuzz_common import module_help

    module_help(__doc__)
