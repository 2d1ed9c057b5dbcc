"""`errp stream` with a decoder in another process, over Lab Streaming Layer
on this machine: the grid's loop closes with the reference client (the
e-puck's closes in .ci/run's step with five runs) and its recording
replays to the same table, the EEG stream's metadata read by MNE-LSL, and
the timing rules (no reader, no decoder, a decoder that stops, a wrong
stream, late decisions).

The streams have fixed names, so these tests run one after another, each
bridge and its decoder in this process's own session (`--session`), so that
another run of these tests, or a lab's session, on the host is never
found."""

import os
import subprocess
import sys
import time
from pathlib import Path

import errp
import numpy as np
import pytest

from conftest import ROOT, errp_bin

pylsl = pytest.importorskip("pylsl")

CLIENT = ROOT / "python" / "examples" / "lsl_decoder.py"
GRID = str(ROOT / "scenarios" / "grid_fixed_goals.toml")


def liblsl() -> str:
    lib = Path(pylsl.lib.__file__).parent
    for name in ("liblsl.so", "liblsl.dylib", "lsl.dll"):
        if (lib / name).is_file():
            return str(lib / name)
    pytest.skip("pylsl without its bundled liblsl")


#: This run's session: its streams' source ids end with it.
SESSION = f"test{os.getpid()}"


def bridge(*args: str) -> subprocess.Popen:
    """`errp stream ARGS` in the background, in `SESSION` unless ARGS name
    another."""
    env = dict(os.environ, ERRP_LIBLSL=liblsl())
    session = () if "--session" in args else ("--session", SESSION)
    return subprocess.Popen(
        [str(errp_bin()), "stream", *args, *session],
        cwd=ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def client(*args: str) -> subprocess.Popen:
    """The reference client, in `SESSION` unless ARGS name another."""
    session = () if "--session" in args else ("--session", SESSION)
    return python(str(CLIENT), *args, *session)


def python(*args: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, *args], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )


def finish(p: subprocess.Popen, timeout: float = 240) -> tuple[int, str, str]:
    out, err = p.communicate(timeout=timeout)
    return p.returncode, out, err


def beside(helper: subprocess.Popen, *args: str) -> tuple[int, str, str]:
    """`errp stream ARGS` run to its end beside `helper` (a decoder or a
    reader), which is then stopped."""
    result = finish(bridge(*args))
    helper.kill()
    helper.communicate()
    return result


# A program that reads the EEG of session `argv[1]` and never decides; with
# `channels` (`argv[2]`), it publishes a decoder stream of that many
# channels, for that session or the one given after it.
READER = """
import sys, time, pylsl
session = sys.argv[1]
eeg = pylsl.resolve_byprop("source_id", f"errp-eeg-{session}", 1, 30)[0]
inlet = pylsl.StreamInlet(eeg)
inlet.open_stream(10)
outlet = None
if len(sys.argv) > 2:
    session = sys.argv[3] if len(sys.argv) > 3 else session
    info = pylsl.StreamInfo(
        "errp-decoder", "Decisions", int(sys.argv[2]), 0.0, "double64", f"x-{session}"
    )
    outlet = pylsl.StreamOutlet(info)
end = time.time() + 60
while time.time() < end:
    inlet.pull_chunk(timeout=0.05)
"""


def inspect(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(errp_bin()), "inspect", *args], capture_output=True, text=True, timeout=120
    )


def rows(text: str) -> list[str]:
    """The rows of a grid table: lines that start with a run number."""
    return [line for line in text.splitlines() if line[:3].strip().isdigit()]


def test_the_loop_closes_and_its_recording_replays(tmp_path):
    saved = tmp_path / "live.rrd"
    # At speed 40 the client has 55 ms per action; a busy machine can
    # still delay a decision past its action, and a missed decision changes
    # the rest of the session (the seeded draws follow the actions taken).
    # So the goals are checked exactly when nothing was missed, and the
    # decisions applied in any case.
    b = bridge(GRID, "--speed", "40", "--runs", "2", "--timeout", "60", "--save", str(saved))
    c = client("--timeout", "60")
    code, out, err = finish(b)
    said = c.communicate(timeout=60)[0]
    assert code == 0, err + said
    summary = [line.strip() for line in out.splitlines() if "runs reached their goal" in line]
    assert len(summary) == 1, out
    applied = int(summary[0].split("decisions: ")[1].split(" applied")[0])
    missed = int(summary[0].split("; ")[-1].split(" missed")[0])
    assert applied >= 20 and missed <= applied // 10, out
    if missed == 0:
        assert summary[0].startswith("2 of 2 runs reached their goal"), out
    assert "trained on 400 epochs" in said
    # Latencies, median and 95th percentile, per run and over all.
    assert out.count("latency from the action's onset median") == 3, out
    assert "0 stray" in out
    assert "cost at speed 40" in out
    assert f"Wrote {saved}" in out
    # The recording holds the decisions as received; the runs replayed
    # offline with them give the table the stream printed.
    r = inspect(str(saved), "--replay")
    assert r.returncode == 0, r.stderr
    printed = rows(out)
    assert len(printed) == 2, out
    recomputed, replayed = r.stdout.split("Replayed offline")
    assert rows(recomputed.split("Decisions from the online decoder")[0]) == printed
    assert rows(replayed) == printed, r.stdout
    assert "the same per-run table as recorded (2 runs)" in r.stdout
    assert "live:     errp stream at speed 40, decisions from name=errp-decoder" in r.stdout
    # Its decisions, one line per run: as many applied as the run's actions.
    decided = [line for line in recomputed.splitlines() if " applied, latency" in line]
    assert len(decided) == 3, recomputed
    # The decisions table: the action each applied decision decided, from
    # 1 as the runs, in order within a run; none (pandas' NA) for one
    # late or stray.
    d = errp.read_recording(saved).tables["decisions"]
    assert str(d["applied_to"].dtype) == "Int64", d.dtypes
    assert (d["applied_to"].isna() == (d["fate"] != "applied")).all(), d
    for _, one in d[d["fate"] == "applied"].groupby("run"):
        steps = one["applied_to"].astype(int).tolist()
        assert steps[0] >= 1 and steps == sorted(set(steps)), steps
    # A recording of `errp run` has no decisions to replay.
    plain = tmp_path / "plain.rrd"
    made = subprocess.run(
        [str(errp_bin()), "run", GRID, "--decoder", "oracle", "--save", str(plain)],
        capture_output=True, text=True, timeout=300,
    )
    assert made.returncode == 0, made.stderr
    r = inspect(str(plain), "--replay")
    assert r.returncode == 2
    assert "not a live session's recording" in r.stderr, r.stderr


def test_a_bad_save_path_is_refused_before_streaming(tmp_path):
    foreign = tmp_path / "notes.rrd"
    foreign.write_text("mine")
    for path, says in [
        (tmp_path / "x.txt", "--save"),
        (foreign, "is not a Rerun recording"),
    ]:
        code, _, err = finish(bridge(GRID, "--save", str(path)), timeout=30)
        assert code == 2, err
        assert says in err, err
    assert foreign.read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.rrd"]


def test_the_eeg_metadata_reads_in_mne_lsl():
    from mne_lsl.stream import StreamLSL


    b = bridge(GRID, "--timeout", "30", "--calibration-actions", "40", "--speed", "20")
    try:
        stream = StreamLSL(bufsize=2, source_id=f"errp-eeg-{SESSION}").connect(timeout=20)
        info = stream.info
        assert info["sfreq"] == 256 * 20
        names = info.ch_names
        assert len(names) == 40 and "FCz" in names and names[-1] == "EOG RO"
        types = stream.get_channel_types()
        assert types.count("eeg") == 34 and types.count("eog") == 6
        units = {u for u in stream.get_channel_units()}
        assert len(units) == 1 and "FIFF_UNITM_MU" in str(units), units
        # The channels' positions: the montage's, on MNE's 95 mm head, as
        # the channels' loc and as the montage MNE makes of the stream.
        positions = stream.get_montage().get_positions()["ch_pos"]
        for ch in stream.info["chs"]:
            if ch["ch_name"] in positions:
                assert np.allclose(ch["loc"][:3], positions[ch["ch_name"]])
        montage = {}
        for line in (ROOT / "assets" / "electrodes.csv").read_text().splitlines():
            if line and not line.startswith("#") and not line.startswith("name"):
                name, kind, x, y, z = (f.strip() for f in line.split(","))
                if kind == "eeg":
                    montage[name] = np.array([float(x), float(y), float(z)]) * 0.095
        assert set(positions) == set(montage), set(positions) ^ set(montage)
        for name, want in montage.items():
            assert np.allclose(positions[name], want, atol=1e-6), (name, positions[name], want)
        stream.disconnect()
    finally:
        b.kill()
        b.communicate()


def test_no_reader_within_the_timeout_is_refused(tmp_path):
    code, out, err = finish(bridge(GRID, "--timeout", "1", "--save", str(tmp_path / "a.rrd")))
    assert code == 2
    assert "no program opened the EEG stream errp-eeg within 1 s (--timeout)" in err
    # A session that stops leaves no recording, whole or partial.
    assert list(tmp_path.iterdir()) == []


def test_no_decoder_within_the_timeout_is_refused():
    code, out, err = beside(
        python("-c", READER, SESSION), GRID, "--timeout", "2", "--speed", "100",
        "--calibration-actions", "40",
    )
    assert code == 2, err
    assert 'no decoder stream "errp-decoder" appeared within 2 s after the calibration' in err
    # No stream of another session was seen, so none is named.
    assert "other sessions" not in err


def test_a_decoder_stream_of_the_wrong_shape_is_refused():
    code, out, err = beside(
        python("-c", READER, SESSION, "3"), GRID, "--timeout", "10", "--speed", "100",
        "--calibration-actions", "40",
    )
    assert code == 2, err
    assert 'the decoder stream "errp-decoder" (name=errp-decoder) has 3 channels' in err
    assert "expected 2 numeric channels (action, p(error))" in err


def test_a_decoder_of_another_session_is_refused():
    # Published for another session than this bridge's.
    theirs = f"{SESSION}x"
    code, out, err = beside(
        python("-c", READER, SESSION, "2", theirs), GRID, "--timeout", "3", "--speed", "100",
        "--calibration-actions", "40",
    )
    assert code == 2, err
    assert 'no decoder stream "errp-decoder" of this session appeared within 3 s' in err, err
    assert f'source ids "x-{theirs}"' in err and f'session\'s id "{SESSION}"' in err, err
    assert f"as session {SESSION}" in err


def test_two_sessions_on_one_host_each_close_their_own_loop():
    # The same scenario and seed, so the same stream names: each bridge and
    # its decoder find each other by the session's id alone.
    bridges, clients = [], []
    sessions = (f"{SESSION}a", f"{SESSION}b")
    for session in sessions:
        bridges.append(bridge(
            GRID, "--speed", "40", "--runs", "1", "--timeout", "60",
            "--calibration-actions", "200", "--session", session,
        ))
        clients.append(client("--timeout", "60", "--session", session))
    for session, b, c in zip(sessions, bridges, clients):
        code, out, err = finish(b)
        said = c.communicate(timeout=60)[0]
        assert code == 0, err + said
        assert f"as session {session}" in err
        summary = [line.strip() for line in out.splitlines() if "runs reached their goal" in line]
        assert len(summary) == 1 and "0 stray" in summary[0], out
        applied = int(summary[0].split("decisions: ")[1].split(" applied")[0])
        assert applied >= 5, out
        assert "trained on 200 epochs" in said, said


def test_a_decoder_that_stops_mid_run_is_reported():
    c = client("--stop-after", "3")
    code, out, err = finish(
        bridge(GRID, "--timeout", "5", "--speed", "100", "--calibration-actions", "80")
    )
    c.communicate(timeout=30)
    assert code == 2, err
    # errp's message alone: liblsl's own lines ("... ERR| Stream
    # transmission broke off") do not come before it.
    assert "ERR|" not in err and "broke off" not in err, err
    assert "errp-decoder" in err
    assert "was lost" in err or "sent nothing for" in err, err


def test_late_decisions_are_counted_not_applied():
    code, out, err = beside(
        client("--delay", "0.05"), GRID, "--timeout", "10", "--speed", "100",
        "--calibration-actions", "80", "--runs", "1",
    )
    assert code == 0, err
    last = out.strip().splitlines()
    summary = [line for line in last if "runs reached their goal" in line][0]
    assert summary.startswith("0 of 1 runs"), summary
    assert "decisions: 0 applied" in summary, summary
    late = int(summary.split(" missed, ")[1].split(" late")[0])
    assert late > 0, summary
