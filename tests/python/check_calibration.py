"""Reads back what `errp calibrate --save X.rrd --export X.edf` wrote, with
independent clients: the Rerun CLI (rerun-sdk 0.36.3) and MNE-Python.

usage: python check_calibration.py RRD EDF
"""

import subprocess
import sys

import mne


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


def check_edf(path: str) -> None:
    raw = mne.io.read_raw_edf(path, preload=True, verbose="error")
    assert raw.info["sfreq"] == 256.0, raw.info["sfreq"]
    assert len(raw.ch_names) == 40, raw.ch_names
    for ch in ["Fz", "FC1", "FCz", "FC2", "C1", "Cz", "C2", "CPz", "EOG-LA", "EOG-RO"]:
        assert ch in raw.ch_names, ch
    ann = raw.annotations
    assert len(ann) == 400, len(ann)
    assert set(ann.description) == {"error", "correct"}, set(ann.description)
    n_err = int((ann.description == "error").sum())
    assert 50 <= n_err <= 110, n_err
    gaps = ann.onset[1:] - ann.onset[:-1]
    assert gaps.min() >= 3.0 - 1e-3 and gaps.max() <= 3.5 + 1e-3, (gaps.min(), gaps.max())
    sd_uv = raw.get_data(picks=["FCz"]).std() * 1e6
    assert 5.0 < sd_uv < 50.0, sd_uv
    print(f"{path}: {len(raw.ch_names)} channels at 256 Hz, {len(ann)} events "
          f"({n_err} error), FCz sd {sd_uv:.1f} uV")


if __name__ == "__main__":
    check_rrd(sys.argv[1])
    check_edf(sys.argv[2])
