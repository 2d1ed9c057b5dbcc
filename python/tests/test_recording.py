"""Recordings read back: `errp.read_recording` gives the tables of `errp
inspect --csv` as DataFrames, identical value for value, with each run
recomputed from the recording as `errp run` scored it; bad files raise."""

import numpy as np
import pandas as pd
import pytest

import errp
from conftest import cli

pytestmark = pytest.mark.skipif(not errp.HAS_RERUN, reason="built without Rerun")


def test_epuck_recording_tables_match_the_program(root, tmp_path):
    rrd = tmp_path / "m.rrd"
    df = errp.run(seed=4, runs=6, save=rrd)
    rec = errp.read_recording(rrd)
    assert rec.task == "epuck"
    assert rec.provenance["seed"] == 4 and rec.provenance["runs"] == 6
    assert "Mexico" in rec.provenance["scenario_text"]
    runs = rec.runs
    assert list(runs.run) == list(range(1, 7))
    # Each run recomputed from the recording is the run errp.run scored.
    assert list(runs.reached) == list(df.success.astype(bool))
    assert np.allclose(runs.time_s, df.time_secs, atol=1 / 64)
    assert list(runs.detected) == list(df.detected)
    # Identical to the CSV files of `errp inspect --csv`.
    out = tmp_path / "csv"
    cli("inspect", str(rrd), "--csv", str(out))
    for name, frame in rec.tables.items():
        from_csv = pd.read_csv(out / f"{name}.csv", keep_default_na=False, na_values=[""])
        assert list(from_csv.columns) == list(frame.columns), name
        for c in frame.columns:
            a, b = frame[c].to_numpy(), from_csv[c].to_numpy()
            if pd.api.types.is_numeric_dtype(frame[c]) or pd.api.types.is_bool_dtype(frame[c]):
                assert np.array_equal(a.astype(float), b.astype(float), equal_nan=True), (name, c)
            else:
                assert [str(x) for x in a] == ["" if pd.isna(x) else str(x) for x in b], (name, c)
    # The same tables as Parquet files (`--parquet`), typed, value for value.
    pq = tmp_path / "parquet"
    cli("inspect", str(rrd), "--parquet", str(pq))
    assert sorted(p.stem for p in pq.glob("*.parquet")) == sorted(rec.tables)
    for name, frame in rec.tables.items():
        from_pq = pd.read_parquet(pq / f"{name}.parquet")
        assert list(from_pq.columns) == list(frame.columns), name
        for c in frame.columns:
            a, b = frame[c], from_pq[c]
            if pd.api.types.is_bool_dtype(frame[c]):
                assert pd.api.types.is_bool_dtype(b) and list(a) == list(b), (name, c)
            elif pd.api.types.is_numeric_dtype(frame[c]):
                assert np.array_equal(
                    a.to_numpy(float), b.to_numpy(float, na_value=np.nan), equal_nan=True
                ), (name, c)
            else:
                assert [str(x) for x in a] == [str(x) for x in b], (name, c)
    # One trajectory row per physics step.
    assert len(rec.trajectory) == pytest.approx(64 * runs.time_s.sum(), abs=6 * 1.5)
    ax = rec.plot(run=2)
    assert len(ax.lines) > 25


def test_grid_recording(root, tmp_path):
    rrd = tmp_path / "g.rrd"
    df = errp.run(str(root / "scenarios/grid_fixed_goals.toml"), seed=3, save=rrd)
    rec = errp.read_recording(rrd)
    assert rec.task == "grid"
    assert list(rec.runs.actions) == list(df.actions)
    assert rec.actions.groupby("run").size().tolist() == list(df.actions)
    assert rec.visits.groupby("run").visits.sum().tolist() == [a + 1 for a in df.actions]
    rec.plot()


@pytest.mark.parametrize(
    "content, why",
    [(b"", "empty"), (b"not a recording at all", "not a Rerun recording")],
)
def test_bad_files_raise(tmp_path, content, why):
    p = tmp_path / "bad.rrd"
    p.write_bytes(content)
    with pytest.raises(ValueError, match=why):
        errp.read_recording(p)
    with pytest.raises(FileNotFoundError):
        errp.read_recording(tmp_path / "missing.rrd")


def test_fig5_for_lisbon_to_tokyo(root, tmp_path):
    """The other city run draws too: its path runs from Lisbon (top left)
    to Tokyo (right), with red marks at its detections."""
    from PIL import Image

    rrd = tmp_path / "l.rrd"
    df = errp.run(str(root / "scenarios/lisbon_to_tokyo.toml"), seed=2, runs=2, save=rrd)
    png = tmp_path / "fig5.png"
    cli("inspect", str(rrd), "--figure", str(png), "--run", "2")
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    assert img.shape[0] > 400 and img.shape[1] > 400
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    blue = (b > 150) & (r < 120) & (g < 170)
    red = (r > 180) & (g < 80) & (b < 80)
    assert blue.sum() > 500, "no path drawn"
    # Run 2's detections (36 at seed 2) are drawn as red marks.
    rec = errp.read_recording(rrd)
    assert list(rec.runs.detected) == list(df.detected)
    assert rec.runs.detected.iloc[1] > 10
    assert red.sum() > 50, "no detection drawn"
    # The path spans much of the arena's width: Lisbon to Tokyo.
    cols = np.flatnonzero(blue.any(axis=0))
    assert cols.max() - cols.min() > img.shape[1] / 4
