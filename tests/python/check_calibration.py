"""Reads back what `errp calibrate --save X.rrd --export X.edf` wrote, with
independent clients: the Rerun CLI (rerun-sdk 0.36.3, or the newest, 0.41),
MNE-Python, and pyedflib, a strict EDF+ reader (it refuses a file whose
header does not match the standard).

usage: python check_calibration.py RRD [EDF]
"""

import subprocess
import sys


def check_rrd(path: str) -> None:
    subprocess.run(["rerun", "rrd", "verify", path], check=True)
    printed = subprocess.run(
        ["rerun", "rrd", "print", path], check=True, capture_output=True, text=True
    ).stdout
    for entity in [
        "/grand_average/FCz/error",
        "/grand_average/FCz/correct",
        "/grand_average/FCz/difference",
        "/grand_average/Cz/difference",
        "/topography/map",
        "/topography/electrodes",
        "/summary",
    ]:
        assert entity in printed, f"{path}: entity {entity} missing"
    assert "Blueprint" in printed, f"{path}: no default layout"
    print(f"{path}: verified, all entities and a layout present")


EOG = ["LA", "LB", "RA", "RB", "LO", "RO"]


def check_edf(path: str) -> None:
    import mne

    # EDF+ labels are "type name": MNE types the six "EOG XX" channels as
    # EOG (and drops the prefix), so an average reference leaves them out.
    raw = mne.io.read_raw_edf(path, preload=True, infer_types=True, verbose="error")
    assert raw.info["sfreq"] == 256.0, raw.info["sfreq"]
    assert len(raw.ch_names) == 40, raw.ch_names
    types = dict(zip(raw.ch_names, raw.get_channel_types()))
    assert [ch for ch, t in types.items() if t == "eog"] == EOG, types
    assert sum(t == "eeg" for t in types.values()) == 34, types
    for ch in ["Fz", "FC1", "FCz", "FC2", "C1", "Cz", "C2", "CPz"]:
        assert types.get(ch) == "eeg", (ch, types.get(ch))
    ann = raw.annotations
    assert len(ann) == 400, len(ann)
    assert set(ann.description) == {"error", "correct"}, set(ann.description)
    n_err = int((ann.description == "error").sum())
    assert 50 <= n_err <= 110, n_err
    gaps = ann.onset[1:] - ann.onset[:-1]
    assert gaps.min() >= 3.0 - 1e-3 and gaps.max() <= 3.5 + 1e-3, (gaps.min(), gaps.max())
    sd_uv = raw.get_data(picks=["FCz"]).std() * 1e6
    assert 5.0 < sd_uv < 50.0, sd_uv
    print(f"{path}: {len(raw.ch_names)} channels at 256 Hz (MNE types 34 EEG, 6 EOG), "
          f"{len(ann)} events ({n_err} error), FCz sd {sd_uv:.1f} uV")


def check_edf_strict(path: str) -> None:
    import pyedflib

    with pyedflib.EdfReader(path) as f:
        assert f.filetype == pyedflib.FILETYPE_EDFPLUS, f.filetype
        labels = f.getSignalLabels()
        assert len(labels) == 40, labels
        assert labels[-6:] == [f"EOG {e}" for e in EOG], labels[-6:]
        assert set(f.getSampleFrequencies()) == {256.0}, set(f.getSampleFrequencies())
        assert {f.getPhysicalDimension(i) for i in range(40)} == {"uV"}
        onsets, _, texts = f.readAnnotations()
        assert len(onsets) == 400 and set(texts) == {"error", "correct"}, len(onsets)
        fcz = f.readSignal(labels.index("FCz"))
        assert len(fcz) == f.getNSamples()[0] and 5.0 < fcz.std() < 50.0, fcz.std()
    print(f"{path}: pyedflib reads an EDF+ file: 40 signals, 400 annotations")


if __name__ == "__main__":
    check_rrd(sys.argv[1])
    if len(sys.argv) > 2:
        check_edf(sys.argv[2])
        check_edf_strict(sys.argv[2])
