"""The EDF/BDF cases of fuzz_cli.py: a person's own EEG file (the input of
`[eeg] recording`) that lies in its header, is cut short, has bits flipped,
keeps time oddly, annotates events twice or labels two channels alike, as
EDF+ and as BDF+; and the same session written by other tools (MNE's
export, pyEDFlib, edfio, with a sub-second start) when the `--python`
interpreter has them.

The base is `errp calibrate --accuracy 0.78 --seed 1 --export` cut to its
first RECORDS one-second records (enough events of each class for a
calibration, a fraction of the time to read). Each case writes its file
beside a copy of `scenarios/recorded/own_eeg.toml` (two episodes) and runs
`errp run own_eeg.toml --save OUT/x.rrd`, which must exit 0 (a file the
standard allows, read as its header says) or 2 (with `error: ` naming the
file), never panic or hang, and on exit 2 leave nothing in OUT.
"""

import random
import shutil
import struct
import subprocess
import tempfile
from pathlib import Path

from fuzz_common import judged

ROOT = Path(__file__).resolve().parent.parent

#: One-second records kept of the exported session.
RECORDS = 300

#: Truncation points and bit flips per format.
CUTS, FLIPS = 12, 24

#: The fixed header's fields: name, offset, size (EDF spec, section 2.1).
HEADER = [
    ("version", 0, 8), ("patient", 8, 80), ("recording", 88, 80), ("startdate", 168, 8),
    ("starttime", 176, 8), ("header bytes", 184, 8), ("reserved", 192, 44),
    ("records", 236, 8), ("record duration", 244, 8), ("signals", 252, 4),
]

#: Each signal's fields: name, size (stored field by field for all signals).
SIGNAL = [
    ("label", 16), ("transducer", 80), ("physical dimension", 8), ("physical minimum", 8),
    ("physical maximum", 8), ("digital minimum", 8), ("digital maximum", 8),
    ("prefiltering", 80), ("samples per record", 8), ("reserved", 32),
]

#: Texts a lying field might hold.
LIES = ["", "-1", "0", "1", "1e-300", "1e300", "nan", "inf", "99999999", "abc", "\x00" * 4,
        "é", "-0", " 256", "2.5"]


class Edf:
    """A parsed EDF+/BDF+ file: the fixed header, the signal headers, and
    each record's bytes."""

    def __init__(self, data):
        self.ns = int(data[252:256])
        self.head = bytearray(data[:256 + 256 * self.ns])
        self.bps = 3 if data[:1] == b"\xff" else 2
        self.spr = [int(self.field("samples per record", i)) for i in range(self.ns)]
        self.labels = [self.field("label", i).strip() for i in range(self.ns)]
        size = sum(self.spr) * self.bps
        body = data[len(self.head):]
        self.records = [bytearray(body[k * size:(k + 1) * size]) for k in range(len(body) // size)]
        self.ann = next(i for i, l in enumerate(self.labels) if l.endswith("Annotations"))

    def offset(self, name, i):
        at = 256
        for n, size in SIGNAL:
            if n == name:
                return at + i * size, size
            at += self.ns * size
        raise KeyError(name)

    def field(self, name, i):
        at, size = self.offset(name, i)
        return self.head[at:at + size].decode("latin-1")

    def set(self, name, value, i=None):
        if i is None:
            at, size = next((a, s) for n, a, s in HEADER if n == name)
        else:
            at, size = self.offset(name, i)
        self.head[at:at + size] = value.encode("latin-1")[:size].ljust(size, b" ")

    def area(self, k):
        """Record k's annotation bytes: (start, end) in the record."""
        start = sum(self.spr[:self.ann]) * self.bps
        return start, start + self.spr[self.ann] * self.bps

    def tals(self, k):
        a, b = self.area(k)
        return [t for t in bytes(self.records[k][a:b]).split(b"\x00") if t]

    def set_tals(self, k, tals):
        a, b = self.area(k)
        text = b"".join(t + b"\x00" for t in tals)
        if len(text) > b - a:
            return False
        self.records[k][a:b] = text.ljust(b - a, b"\x00")
        return True

    def bytes(self):
        return bytes(self.head) + b"".join(self.records)

    def to_bdf(self):
        """The same session as BDF+: 24-bit samples (the 16-bit values
        sign-extended), the annotations in three bytes per sample."""
        bdf = Edf.__new__(Edf)
        bdf.__dict__.update(self.__dict__)
        bdf.head = bytearray(self.head)
        bdf.bps = 3
        bdf.head[0:8] = b"\xffBIOSEMI"
        bdf.set("version", "\xffBIOSEMI")
        bdf.set("reserved", "BDF+C")
        bdf.labels = [l.replace("EDF Annotations", "BDF Annotations") for l in self.labels]
        bdf.set("label", "BDF Annotations", self.ann)
        bdf.records = []
        for rec in self.records:
            out = bytearray()
            at = 0
            for i, n in enumerate(self.spr):
                chunk = rec[at:at + 2 * n]
                at += 2 * n
                if i == self.ann:
                    out += chunk + bytes(n)
                else:
                    for (v,) in struct.iter_unpack("<h", chunk):
                        out += struct.pack("<i", v)[:3]
            bdf.records.append(out)
        return bdf


class EdfCase:
    """One file: `fmt` ("edf" or "bdf"), damaged as `how` by `apply`
    (parsed file -> bytes)."""

    def __init__(self, fmt, how, apply):
        self.fmt, self.how, self.apply = fmt, how, apply
        self.label = f"own EEG {fmt}: {how}"

    def command(self):
        return f"errp run own_eeg.toml  (its recording: the {self.fmt.upper()} file, {self.how})"


def make_edf_base(errp, into):
    """The exported session cut to RECORDS records, as bytes."""
    path = Path(into) / "base.edf"
    subprocess.run([errp, "calibrate", "--accuracy", "0.78", "--seed", "1", "--quiet",
                    "--export", str(path)], cwd=ROOT, check=True, capture_output=True,
                   timeout=600)
    edf = Edf(path.read_bytes())
    edf.records = edf.records[:RECORDS]
    edf.set("records", str(RECORDS))
    return edf.bytes()


def lied(fmt, name, value, signal=None):
    def apply(edf):
        edf.set(name, value, signal)
        return edf.bytes()
    where = f"signal {signal}'s " if signal is not None else ""
    return EdfCase(fmt, f"{where}{name} = {value!r}", apply)


def timekeeping(fmt, how, change):
    def apply(edf):
        for k in range(len(edf.records)):
            tals = edf.tals(k)
            onset = float(tals[0].split(b"\x14")[0])
            new = change(k, onset)
            if new is None:
                tals = tals[1:]
            else:
                tals[0] = b"+%s\x14\x14" % (repr(new).rstrip("0").rstrip(".").encode()
                                           if new != int(new) else str(int(new)).encode())
            # Event onsets move with their record.
            if new is not None and new != onset:
                moved = []
                for t in tals[1:]:
                    at, rest = t.split(b"\x14", 1)
                    at, dur = (at.split(b"\x15", 1) + [None])[:2]
                    shifted = b"%+.4f" % (float(at) + new - onset)
                    moved.append(shifted + (b"\x15" + dur if dur else b"") + b"\x14" + rest)
                tals = tals[:1] + moved
            edf.set_tals(k, tals)
        return edf.bytes()
    return EdfCase(fmt, how, apply)


def events(fmt, how, change):
    def apply(edf):
        for k in range(len(edf.records)):
            tals = edf.tals(k)
            edf.set_tals(k, tals[:1] + change(tals[1:]))
        return edf.bytes()
    return EdfCase(fmt, how, apply)


def relabel(fmt, signal, label):
    def apply(edf):
        edf.set("label", label, signal)
        return edf.bytes()
    return EdfCase(fmt, f"signal {signal} relabelled {label!r}", apply)


def edf_cases(seed, size):
    """The damages of the base (of `size` bytes as EDF), for both formats,
    drawn from `seed`."""
    rng = random.Random(seed)
    cases = []
    for fmt in ("edf", "bdf"):
        for name, _, _ in HEADER:
            for value in rng.sample(LIES, 4):
                cases.append(lied(fmt, name, value))
        for name, _ in SIGNAL:
            for value in rng.sample(LIES, 3):
                cases.append(lied(fmt, name, value, rng.choice([0, 20, 40])))
        total = size if fmt == "edf" else size * 3 // 2
        for at in sorted({0, 100, 255, 256, 300, total - 1} |
                         {rng.randrange(total) for _ in range(CUTS)}):
            cases.append(EdfCase(fmt, f"cut at byte {at}", lambda e, at=at: e.bytes()[:at]))
        for _ in range(FLIPS):
            at, bit = rng.randrange(total), rng.randrange(8)

            def flip(e, at=at, bit=bit):
                b = bytearray(e.bytes())
                if at < len(b):
                    b[at] ^= 1 << bit
                return bytes(b)

            cases.append(EdfCase(fmt, f"bit {bit} of byte {at} flipped", flip))
        cases += [
            EdfCase(fmt, "1000 bytes after the last record",
                    lambda e: e.bytes() + bytes(1000)),
            timekeeping(fmt, "records start at +0.5 s (a sub-second start)",
                        lambda k, t: t + 0.5),
            timekeeping(fmt, "records start at +100 s", lambda k, t: t + 100),
            timekeeping(fmt, "a gap of 1 s after record 50",
                        lambda k, t: t + (1 if k > 50 else 0)),
            timekeeping(fmt, "record 7 without its time-keeping TAL",
                        lambda k, t: None if k == 7 else t),
            timekeeping(fmt, "records out of order", lambda k, t: t - 2 if k == 9 else t),
            events(fmt, "every event annotated twice", lambda ev: ev + ev),
            events(fmt, "every event also annotated as the other class",
                   lambda ev: ev + [t.replace(b"correct", b"error") if b"correct" in t
                                    else t.replace(b"error", b"correct") for t in ev]),
            events(fmt, "no events", lambda ev: []),
            events(fmt, "events with a duration", lambda ev: [
                t.replace(b"\x14", b"\x150.5\x14", 1) for t in ev]),
            events(fmt, "events labelled in capitals", lambda ev: [t.upper() for t in ev]),
            relabel(fmt, 1, "FCz"),
            relabel(fmt, 0, ""),
            relabel(fmt, 5, "EEG Fp1-REF"),
            relabel(fmt, 39, "EDF Annotations"),
        ]
    return cases


#: The session written by other tools, by the `--python` interpreter (a
#: case is skipped, as passed, when the tool is not installed there).
WRITERS = {
    "MNE export (edfio)": """
import mne, sys
raw = mne.io.read_raw_edf(sys.argv[1], preload=True, verbose="error")
mne.export.export_raw(sys.argv[2], raw, fmt="edf", overwrite=True, verbose="error")
""",
    "edfio, starting at 0.5 s": """
import datetime, sys, edfio
edf = edfio.read_edf(sys.argv[1])
edf.starttime = datetime.time(0, 0, 0, 500000)
edf.write(sys.argv[2])
""",
    "pyEDFlib": """
import sys, pyedflib
r = pyedflib.EdfReader(sys.argv[1])
n = r.signals_in_file
w = pyedflib.EdfWriter(sys.argv[2], n, file_type=pyedflib.FILETYPE_EDFPLUS)
w.setSignalHeaders([r.getSignalHeader(i) for i in range(n)])
w.writeSamples([r.readSignal(i, digital=True) for i in range(n)], digital=True)
for onset, duration, text in zip(*r.readAnnotations()):
    w.writeAnnotation(onset, duration if duration > 0 else -1, text)
w.close()
""",
}


def writer_cases():
    return [EdfCase("edf", f"written by {tool}", ("tool", tool)) for tool in WRITERS]


def run_edf(errp, base, case, python, gib, limit_memory):
    """Runs one case; returns (failure or None, exit code)."""
    work = Path(tempfile.mkdtemp(prefix="errp-fuzz-edf-"))
    try:
        name = f"x.{case.fmt}"
        f = work / name
        if isinstance(case.apply, tuple):
            (work / "base.edf").write_bytes(base)
            made = subprocess.run([python, "-c", WRITERS[case.apply[1]], str(work / "base.edf"),
                                   str(f)], capture_output=True, text=True, timeout=300)
            if made.returncode != 0:
                if "ModuleNotFoundError" in made.stderr:
                    return None, 0
                return f"{case.label}: the tool failed\n{made.stderr[-600:]}", None
        else:
            edf = Edf(base)
            f.write_bytes(case.apply(edf if case.fmt == "edf" else edf.to_bdf()))
        scenario = (ROOT / "scenarios" / "recorded" / "own_eeg.toml").read_text()
        scenario = scenario.replace('recording = "s01.edf"', f'recording = "{name}"')
        scenario = scenario.replace("count = 40", "count = 2")
        (work / "own_eeg.toml").write_text(scenario)
        out = work / "out"
        out.mkdir()
        return judged(case, [errp, "run", "own_eeg.toml", "--quiet", "--save",
                             str(out / "x.rrd")], out, (name,), "the file", gib, limit_memory,
                      cwd=work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    # A module of fuzz_cli.py: it runs nothing by itself.
    from fuzz_common import module_help

    module_help(__doc__)
