#!/usr/bin/env python3
"""Writes the small EDF+/BDF+ files that other tools make, and what MNE
reads from each, into tests/data/edf/: the fixtures that the crates'
tests read (`bci/tests/it/edf_fixtures.rs`) to check errp's reader against
the files and the readings of the field's own tools.

usage: python3 scripts/edf_fixtures.py   (with mne, edfio and pyedflib installed;
                                          the versions used are written in
                                          tests/data/edf/fixtures.json)

Every file holds the same short session: three channels (Fz, Cz, EOG) of
10 s at 256 Hz, sine waves whose values the tests can predict, and four
events (`error` and `correct`, at onsets that are not on a sample). The
files:

* `edfio_subsecond.edf`: written by edfio with a start time of 0.5 s past
  the second (EDF+ keeps the half second in each record's time-keeping
  annotation), the case MNE's export meets when a recording does not
  start on a second;
* `mne_export.edf`: written by `mne.export.export_raw` (which uses edfio);
* `pyedflib.edf` and `pyedflib.bdf`: written by pyEDFlib's EdfWriter, EDF+
  with 16-bit and BDF+ with 24-bit samples.

For each, `fixtures.json` keeps what MNE reads (`mne.io.read_raw_edf` /
`read_raw_bdf`): the channel names, the rate, the number of samples, the
first samples of Fz in microvolts, and the events' onsets from the first
sample with their descriptions.
"""

import datetime
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "tests" / "data" / "edf"

SFREQ = 256
SECONDS = 10
CHANNELS = ["Fz", "Cz", "EOG"]
#: Onsets (s, from the first sample) and descriptions.
EVENTS = [(1.25, "correct"), (3.5078125, "error"), (6.0, "correct"), (8.7421875, "error")]


def signals():
    """The three channels, in microvolts: sines of 3, 5 and 1 Hz."""
    import numpy as np

    t = np.arange(SFREQ * SECONDS) / SFREQ
    return np.stack([
        40.0 * np.sin(2 * np.pi * 3 * t),
        25.0 * np.sin(2 * np.pi * 5 * t + 0.5),
        150.0 * np.sin(2 * np.pi * 1 * t),
    ])


def with_edfio(path, start_us):
    import edfio

    data = signals()
    edf = edfio.Edf(
        [edfio.EdfSignal(data[i], SFREQ, label=name, physical_dimension="uV",
                         physical_range=(-200.0, 200.0))
         for i, name in enumerate(CHANNELS)],
        starttime=datetime.time(10, 0, 0, start_us),
        annotations=[edfio.EdfAnnotation(onset, None, text) for onset, text in EVENTS],
    )
    edf.write(path)


def with_mne(path):
    import mne

    info = mne.create_info(CHANNELS, SFREQ, ["eeg", "eeg", "eog"])
    raw = mne.io.RawArray(signals() * 1e-6, info, verbose="error")
    raw.set_annotations(mne.Annotations([o for o, _ in EVENTS], [0.0] * len(EVENTS),
                                        [d for _, d in EVENTS]))
    mne.export.export_raw(path, raw, fmt="edf",
                          overwrite=True, verbose="error")


def with_pyedflib(path, bdf):
    import pyedflib

    kind = pyedflib.FILETYPE_BDFPLUS if bdf else pyedflib.FILETYPE_EDFPLUS
    w = pyedflib.EdfWriter(str(path), len(CHANNELS), file_type=kind)
    top = 8388607 if bdf else 32767
    w.setSignalHeaders([{
        "label": name, "dimension": "uV", "sample_frequency": SFREQ,
        "physical_min": -200.0, "physical_max": 200.0,
        "digital_min": -top - 1, "digital_max": top, "transducer": "", "prefilter": "",
    } for name in CHANNELS])
    w.writeSamples(list(signals()))
    for onset, text in EVENTS:
        w.writeAnnotation(onset, -1, text)
    w.close()


def read_with_mne(path):
    import mne

    read = mne.io.read_raw_bdf if path.suffix == ".bdf" else mne.io.read_raw_edf
    raw = read(path, preload=True, verbose="error")
    fz = raw.get_data(picks=["Fz"])[0] * 1e6
    return {
        "channels": [c for c in raw.ch_names],
        "sfreq_hz": float(raw.info["sfreq"]),
        "samples": int(raw.n_times),
        "fz_first_uv": [round(float(v), 6) for v in fz[:8]],
        "events": [[round(float(a["onset"]), 7), a["description"]] for a in raw.annotations],
    }


def main():
    import edfio
    import mne
    import numpy as np
    import pyedflib

    OUT.mkdir(parents=True, exist_ok=True)
    makers = {
        "edfio_subsecond.edf": lambda p: with_edfio(p, 500_000),
        "mne_export.edf": with_mne,
        "pyedflib.edf": lambda p: with_pyedflib(p, False),
        "pyedflib.bdf": lambda p: with_pyedflib(p, True),
    }
    files = {}
    for name, make in makers.items():
        path = OUT / name
        make(path)
        files[name] = read_with_mne(path)
        print(f"wrote {path.relative_to(ROOT)} ({path.stat().st_size} bytes)")
    meta = {
        "made_by": "scripts/edf_fixtures.py",
        "versions": {"mne": mne.__version__, "edfio": edfio.__version__,
                     "pyedflib": pyedflib.__version__, "numpy": np.__version__},
        "written": {"channels": CHANNELS, "sfreq_hz": SFREQ, "seconds": SECONDS,
                    "events": [list(e) for e in EVENTS]},
        "read_by_mne": files,
    }
    (OUT / "fixtures.json").write_text(json.dumps(meta, indent=1) + "\n")
    print(f"wrote {(OUT / 'fixtures.json').relative_to(ROOT)}")


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):
        print(__doc__.strip())
        sys.exit(0)
    main()
