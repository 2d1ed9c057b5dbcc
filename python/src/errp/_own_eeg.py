"""A person's own EEG as the grid's EEG (``GridTask(eeg=...)``): an MNE
object, or a file MNE reads, turned into the channels, data, rate and events
the testbed's decoder takes, with what identifies it."""

import hashlib
import json
import os
from typing import Any, Mapping, Optional

import numpy as np

#: The decoder's sampling rate (Hz): a recording at another rate is
#: resampled to it with MNE (``resample``, FFT-based).
SFREQ = 256.0

#: The largest file read (1 GiB), as the program reads at most.
MAX_FILE_BYTES = 1 << 30

_KINDS = (
    "an mne.io.Raw with annotations, an mne.Epochs, or the path of a file MNE "
    "reads (EDF, BDF, FIF, BrainVision, EEGLAB, GDF, ...)"
)


def _mne():
    try:
        import mne
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError(
            "eeg=...: a recording is read with MNE-Python: pip install mne"
        ) from None
    return mne


def _file_digest(path: str) -> tuple:
    """(name, size, SHA-256) of the file at ``path``."""
    h = hashlib.sha256()
    size = 0
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
            size += len(chunk)
    return os.path.basename(path), size, h.hexdigest()


def _data_digest(name: str, eeg: dict) -> tuple:
    """(name, size, SHA-256) of the data as passed: the samples (float64,
    little-endian), then the channel names, rate and events as JSON."""
    h = hashlib.sha256()
    data = np.ascontiguousarray(eeg["data"], dtype="<f8")
    h.update(data.tobytes())
    h.update(
        json.dumps([eeg["ch_names"], eeg["sfreq"], eeg["onsets"], eeg["errors"]]).encode()
    )
    return name, data.nbytes, h.hexdigest()


def _check_edf(path: str) -> None:
    """Refuses an EDF or BDF file shorter than its header declares (MNE
    reads the whole records of a truncated file without a word)."""
    with open(path, "rb") as f:
        head = f.read(256)
        if len(head) < 256 or not (head[:8] == b"0       " or head[:8] == b"\xffBIOSEMI"):
            return
        try:
            header_bytes = int(head[184:192])
            n_records = int(head[236:244])
            ns = int(head[252:256])
            f.seek(256 + ns * 216)
            spr = [int(f.read(8)) for _ in range(ns)]
        except ValueError:
            return  # MNE says what is wrong
    width = 3 if head[:1] == b"\xff" else 2
    record = sum(spr) * width
    size = os.path.getsize(path)
    if n_records > 0 and record > 0 and size < header_bytes + n_records * record:
        whole = max(0, size - header_bytes) // record
        raise ValueError(
            f"eeg: {path}: truncated: the header declares {n_records} data records of "
            f"{record} bytes, the file holds {whole} whole ones"
        )


def _names(options: Mapping[str, Any]) -> tuple:
    names = []
    for key in ("error", "correct"):
        v = options.get(key, key)
        if not isinstance(v, str) or not v.strip():
            raise ValueError(
                f"eeg_options[{key!r}] = {v!r} is invalid: expected the annotation text of "
                f'the {key} events (default "{key}")'
            )
        names.append(v)
    return tuple(names)


def _volt_channels(info) -> list:
    """The channels measured in volts (EEG, EOG, ...), the ones the decoder
    may read."""
    mne = _mne()
    volt = mne.io.constants.FIFF.FIFF_UNIT_V
    return [ch["ch_name"] for ch in info["chs"] if ch["unit"] == volt]


def _from_raw(raw, error: str, correct: str) -> dict:
    mne = _mne()
    if raw.info["sfreq"] != SFREQ:
        raw = raw.copy().load_data(verbose="error").resample(SFREQ, verbose="error")
    present = sorted({str(d) for d in raw.annotations.description})
    for name in (error, correct):
        if name not in present:
            kind = "error" if name == error else "correct"
            raise ValueError(
                f"eeg: no events of class {kind} (annotations {name!r}); the recording's "
                f"annotations are: {', '.join(repr(p) for p in present) or 'none'} "
                "(eeg_options={'error': ..., 'correct': ...} names them)"
            )
    events, _ = mne.events_from_annotations(
        raw, event_id={error: 1, correct: 2}, verbose="error"
    )
    picks = _volt_channels(raw.info)
    data = raw.get_data(picks=picks) * 1e6
    onsets = ((events[:, 0] - raw.first_samp) / SFREQ).tolist()
    return dict(
        ch_names=picks,
        data=np.ascontiguousarray(data, dtype=np.float64),
        sfreq=SFREQ,
        onsets=onsets,
        errors=(events[:, 2] == 1).tolist(),
    )


def _from_epochs(epochs, error: str, correct: str) -> dict:
    if epochs.info["sfreq"] != SFREQ:
        epochs = epochs.copy().load_data().resample(SFREQ, verbose="error")
    for name in (error, correct):
        if name not in epochs.event_id:
            raise ValueError(
                f"eeg: the epochs have no event {name!r}; their events are: "
                f"{', '.join(repr(k) for k in epochs.event_id)} "
                "(eeg_options={'error': ..., 'correct': ...} names them)"
            )
    if epochs.tmin > 0:
        raise ValueError(
            f"eeg: the epochs start {epochs.tmin} s after their event; they must hold the "
            "event itself (tmin <= 0)"
        )
    picks = _volt_channels(epochs.info)
    data = epochs.get_data(picks=picks) * 1e6  # (n_epochs, n_channels, n_times)
    n_epochs, _, n_times = data.shape
    codes = epochs.events[:, 2]
    # The epochs laid end to end: each event at its epoch's time 0.
    onsets = (np.arange(n_epochs) * n_times / SFREQ - epochs.tmin).tolist()
    keep = np.isin(codes, [epochs.event_id[error], epochs.event_id[correct]])
    return dict(
        ch_names=picks,
        data=np.ascontiguousarray(np.concatenate(list(data), axis=1), dtype=np.float64),
        sfreq=SFREQ,
        onsets=[o for o, k in zip(onsets, keep) if k],
        errors=[bool(c == epochs.event_id[error]) for c, k in zip(codes, keep) if k],
    )


def read(eeg: Any, options: Optional[Mapping[str, Any]]) -> dict:
    """What ``_core.GridTask(eeg=...)`` and ``_core.EpuckTask(eeg=...)``
    take from ``eeg``, with
    ``options`` (an ``[eeg]`` table's keys but ``recording``)."""
    if options is not None and not isinstance(options, Mapping):
        raise TypeError(
            f"eeg_options: expected a dict of the [eeg] table's keys (calibration, "
            f"calibration_events, error, correct, draw or false_alarms_per_min), got "
            f"{type(options).__name__}"
        )
    options = dict(options or {})
    error, correct = _names(options)
    mne = _mne()
    digest = None
    if isinstance(eeg, (str, os.PathLike)):
        path = os.fspath(eeg)
        if not os.path.isfile(path):
            raise ValueError(f"eeg: {path} is not a file: {_KINDS} was expected")
        if os.path.getsize(path) > MAX_FILE_BYTES:
            raise ValueError(
                f"eeg: {path}: {os.path.getsize(path)} bytes; a recording may have at most "
                f"{MAX_FILE_BYTES} bytes (1 GiB)"
            )
        _check_edf(path)
        try:
            eeg = mne.io.read_raw(path, preload=True, verbose="error")
        except Exception as e:  # MNE's errors differ by format
            raise ValueError(f"eeg: {path}: MNE cannot read it as a recording: {e}") from None
        digest = _file_digest(path)
    if isinstance(eeg, mne.BaseEpochs):
        out = _from_epochs(eeg, error, correct)
        kind = "mne.Epochs"
    elif isinstance(eeg, mne.io.BaseRaw):
        out = _from_raw(eeg, error, correct)
        kind = "mne.io.Raw"
    else:
        raise TypeError(f"eeg: expected {_KINDS}, got {type(eeg).__name__}")
    if digest is None:
        files = [f for f in (getattr(eeg, "filenames", None) or []) if f]
        name = f"{os.path.basename(str(files[0]))} ({kind})" if files else kind
        digest = _data_digest(name, out)
    out["name"], out["bytes"], out["sha256"] = digest
    out["options"] = options
    return out
