"""A lab's online ErrP decoder for ``errp stream``, built from the streams
alone: it knows nothing of errp's internals.

It reads the EEG (``errp-eeg``) and the markers (``errp-markers``) over Lab
Streaming Layer, preprocesses causally as an online pipeline must (50 Hz
notch, 1-10 Hz band-pass, common average, EOG regression fitted on the
calibration) and cuts the calibration's labelled 800 ms epochs. Then it
publishes its outlet ``errp-decoder`` (2 channels) and decides:

- grid (``calibration_action`` markers): ``errp.decoders.discrete_decoder()``
  trained on the epochs from each action's onset; each action of the
  control phase is decided once its epoch has arrived, as ``[action id,
  p(error)]``;
- e-puck (``calibration_example`` markers): ``continuous_decoder()``
  trained on the windows from each button press; every 16 samples (62.5
  ms) the window ending at the newest sample is decided, as ``[timestamp of
  its last sample, p(error)]``.

Run it beside the bridge (either first)::

    errp stream scenarios/grid_fixed_goals.toml --speed 20 &
    python python/examples/lsl_decoder.py

Its outlet's source id ends with the session's id (``desc/errp/session`` of
the EEG stream), as the bridge requires. With more than one session on the
host, give each bridge ``--session ID`` and its decoder the same
``--session ID``.

Needs ``pip install pylsl scipy scikit-learn`` and the ``errp`` package
(for ``errp.decoders``).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np
from pylsl import StreamInfo, StreamInlet, StreamOutlet, local_clock, resolve_byprop
from scipy import signal

from errp.decoders import continuous_decoder, discrete_decoder

#: The paper's decoding channels (sec. 2.2.1).
DECODING = ["Fz", "FC1", "FCz", "FC2", "C1", "Cz", "C2", "CPz"]
EPOCH_SECS = 0.8


def find(name: str, timeout: float, session: str | None) -> StreamInlet:
    """An inlet on the stream ``name`` (of ``session``, whose source id is
    ``name-session``, if given), or exit 2 naming it."""
    if session is None:
        found = resolve_byprop("name", name, 1, timeout)
    else:
        found = resolve_byprop("source_id", f"{name}-{session}", 1, timeout)
    if not found:
        which = name if session is None else f"{name}-{session}"
        print(f"error: no LSL stream {which!r} within {timeout} s: is errp stream running?",
              file=sys.stderr)
        sys.exit(2)
    return StreamInlet(found[0], max_buflen=600, processing_flags=0)


def channels(inlet: StreamInlet) -> tuple[list[str], list[str], float, float, str]:
    """Labels, types, the true sampling rate, the speed and the session,
    from the stream's description."""
    root = ET.fromstring(inlet.info(timeout=10.0).as_xml())
    chans = root.find("desc/channels")
    labels = [c.findtext("label") for c in chans]
    types = [c.findtext("type") for c in chans]
    fs = float(root.findtext("desc/errp/sampling_rate_hz"))
    speed = float(root.findtext("desc/errp/speed"))
    return labels, types, fs, speed, root.findtext("desc/errp/session")


class Preprocess:
    """Causal filters with state kept between chunks, then a common average
    over the EEG channels; keeps the decoding and EOG channels."""

    def __init__(self, labels, types, fs):
        eeg = [i for i, t in enumerate(types) if t == "EEG"]
        self.eeg = np.array(eeg)
        self.keep = np.array([labels.index(c) for c in DECODING])
        self.eog = np.array([i for i, t in enumerate(types) if t == "EOG"])
        b, a = signal.iirnotch(50.0, 30.0, fs)
        notch = signal.tf2sos(b, a)
        band = signal.butter(4, [1.0, 10.0], btype="bandpass", fs=fs, output="sos")
        self.sos = np.vstack([notch, band])
        self.zi = np.zeros((self.sos.shape[0], 2, len(labels)))

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """Chunk ``(n, channels)`` in, ``(n, 8 + n_eog)`` out."""
        y, self.zi = signal.sosfilt(self.sos, x, axis=0, zi=self.zi)
        car = y[:, self.eeg].mean(axis=1, keepdims=True)
        return np.hstack([y[:, self.keep] - car, y[:, self.eog]])


def session_id(text: str) -> str:
    """A session id as ``errp stream --session`` takes it: 1 to 16 letters,
    digits or ``_``."""
    if not (1 <= len(text) <= 16 and all(c.isascii() and (c.isalnum() or c == "_")
                                          for c in text)):
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected 1 to 16 letters, digits or _ (the bridge's --session)")
    return text


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--name", default="errp-decoder", help="this decoder's stream")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds to find the streams")
    ap.add_argument("--session", default=None, type=session_id,
                    help="the bridge's session id (errp stream --session): needed only when "
                         "more than one session runs on the host")
    ap.add_argument("--stop-after", type=int, default=None,
                    help="stop after this many decisions (to test the bridge's rules)")
    ap.add_argument("--delay", type=float, default=0.0,
                    help="wait this many seconds before each decision (to test late ones)")
    args = ap.parse_args()

    eeg_in = find("errp-eeg", args.timeout, args.session)
    labels, types, fs, speed, session = channels(eeg_in)
    markers_in = find("errp-markers", args.timeout, session)
    # The markers first: every EEG sample received then has its markers.
    markers_in.open_stream(timeout=10.0)
    eeg_in.open_stream(timeout=10.0)
    pre = Preprocess(labels, types, fs)
    n_keep = len(DECODING)
    span = int(round(EPOCH_SECS * fs))
    # A marker's sample: the first stamped at most half a period before it
    # (stamps are sums of floating-point periods, not exact).
    half = 0.5 / (fs * speed)
    print(f"EEG: {len(labels)} channels at {fs:g} Hz x speed {speed:g}", file=sys.stderr)

    parts = [np.zeros((0, n_keep + len(pre.eog)), np.float32)]
    times = [np.zeros(0)]
    calibration: list[tuple[float, int]] = []
    actions: list[tuple[float, int]] = []
    model = weights = outlet = None
    sent = 0
    t_ready = None
    windows = False  # the e-puck's windows (after the first example marker)
    next_end = None  # the e-puck: the sample index of the next window's end
    while True:
        chunk, ts = eeg_in.pull_chunk(timeout=0.01, max_samples=8192)
        if ts:
            parts.append(pre(np.asarray(chunk, float)).astype(np.float32))
            times.append(np.asarray(ts))
        while True:
            m, t = markers_in.pull_sample(timeout=0.0)
            if m is None:
                break
            event = json.loads(m[0])
            kind = event["event"]
            if kind in ("calibration_action", "calibration_example"):
                windows = kind == "calibration_example"
                calibration.append((t, int(event["label"] == "error")))
            elif kind == "action":
                actions.append((t, int(event["action"])))
            elif kind == "end":
                print(f"{sent} decisions sent", file=sys.stderr)
                return 0
            elif kind == "calibration_end":
                t_ready = t
        if (model is None and t_ready is None) or (model is not None and not (actions or windows)):
            continue
        # The samples so far, as one array (kept whole until the training,
        # then the last 30 s).
        data, stamps = np.concatenate(parts), np.concatenate(times)
        keep = int(30 * fs)
        if model is not None and len(stamps) > keep:
            if next_end is not None:
                next_end -= len(stamps) - keep
            data, stamps = data[-keep:], stamps[-keep:]
        parts, times = [data], [stamps]
        if model is None and stamps.size and stamps[-1] >= t_ready:
            model, weights = train(data, stamps, calibration, t_ready, span, n_keep, windows)
            # The source id ends with the session's id: the bridge takes
            # no decoder of another session.
            info = StreamInfo(args.name, "Decisions", 2, 0.0, "double64", f"{args.name}-{session}")
            outlet = StreamOutlet(info)
            print(f"trained on {len(calibration)} epochs; publishing {args.name}", file=sys.stderr)
        if model is not None and windows:
            # Every 16th sample ends a window: all those arrived, at once.
            if next_end is None:
                next_end = len(stamps) - 1
            ends = np.arange(next_end, len(stamps), 16)
            ends = ends[ends >= span - 1]
            if ends.size:
                X = np.stack([clean(data[e - span + 1:e + 1], weights, n_keep) for e in ends])
                p = model.predict_proba(X)[:, 1]
                for e, pe in zip(ends, p):
                    outlet.push_sample([float(stamps[e]), float(pe)], local_clock())
                sent += len(ends)
                next_end = int(ends[-1]) + 16
        while model is not None and actions:
            t, action = actions[0]
            start = int(np.searchsorted(stamps, t - half))
            if start + span > len(stamps):
                break
            actions.pop(0)
            epoch = clean(data[start:start + span], weights, n_keep)
            p = float(model.predict_proba(epoch[None])[0, 1])
            if args.delay:
                time.sleep(args.delay)
            outlet.push_sample([float(action), p], local_clock())
            sent += 1
            if args.stop_after is not None and sent >= args.stop_after:
                print(f"stopping after {sent} decisions", file=sys.stderr)
                return 0


def clean(x: np.ndarray, weights: np.ndarray, n_keep: int) -> np.ndarray:
    """An epoch ``(span, 8 + n_eog)`` less its EOG: ``(8, span)``."""
    eeg, eog = x[:, :n_keep], x[:, n_keep:]
    return (eeg - eog @ weights).T


def train(data, stamps, calibration, end, span, n_keep, windows):
    """EOG regression weights (least squares over the calibration, from its
    first marker to ``end``, so that they do not depend on when training
    starts) and the decoder fitted on its epochs: the continuous one on the
    e-puck's windows, the discrete one on the grid's epochs."""
    half = 0.5 * (stamps[1] - stamps[0])
    first = int(np.searchsorted(stamps, calibration[0][0] - half))
    last = int(np.searchsorted(stamps, end - half))
    eeg, eog = data[first:last, :n_keep].astype(float), data[first:last, n_keep:].astype(float)
    weights = np.linalg.lstsq(eog, eeg, rcond=None)[0] if eog.shape[1] else np.zeros((0, n_keep))
    X, y = [], []
    for t, label in calibration:
        start = int(np.searchsorted(stamps, t - half))
        if start + span <= len(stamps):
            X.append(clean(data[start:start + span], weights, n_keep))
            y.append(label)
    decoder = continuous_decoder() if windows else discrete_decoder()
    model = decoder.fit(np.asarray(X), np.asarray(y))
    return model, weights


if __name__ == "__main__":
    sys.exit(main())
