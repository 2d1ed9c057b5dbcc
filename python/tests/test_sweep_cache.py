"""errp.sweep's targeting cache: shared across sweeps, checked before use,
and what it finds wrong raised as errp.SweepWarning."""

import json
import re
import warnings

import pandas as pd
import pytest

import errp


def grid(tmp_path, cache, name):
    return errp.sweep(tmp_path / name, task="grid", accuracy=0.7, episodes=3, seed=1,
                      cache=cache, threads=1)


def test_a_cached_targeting_is_used_again_without_a_warning(tmp_path):
    cache = tmp_path / "cache"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        first = grid(tmp_path, cache, "a")
        again = grid(tmp_path, cache, "b")
    assert len(list(cache.glob("*.json"))) == 1
    pd.testing.assert_frame_equal(again.episodes, first.episodes)


@pytest.mark.parametrize("ratio", [0.0, 1e308, "times 3"])
def test_a_tampered_entry_warns_naming_it_and_is_searched_again(tmp_path, ratio):
    cache = tmp_path / "cache"
    first = grid(tmp_path, cache, "a")
    [entry] = cache.glob("*.json")
    original = entry.read_text()
    data = json.loads(original)
    found = data["result"]["ratio"]
    data["result"]["ratio"] = found * 3 if ratio == "times 3" else ratio
    entry.write_text(json.dumps(data))
    text = rf"the cached targeting .*{re.escape(entry.name)} is not what its search finds"
    with pytest.warns(errp.SweepWarning, match=text):
        again = grid(tmp_path, cache, "b")
    # The search's own result is written back, and the sweep is the same.
    assert entry.read_text() == original
    pd.testing.assert_frame_equal(again.episodes, first.episodes)


def test_a_cache_that_cannot_be_written_warns_and_the_sweep_goes_on(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("mine")
    with pytest.warns(errp.SweepWarning) as seen:
        res = grid(tmp_path, blocker, "a")
    [w] = seen
    message = str(w.message)
    assert message.startswith("cache: the targeting cache cannot be written"), message
    assert str(blocker) in message and "give another cache= directory" in message, message
    assert blocker.read_text() == "mine" and len(res.episodes) == 3


def test_an_entry_that_cannot_be_stored_warns_naming_it(tmp_path):
    cache = tmp_path / "cache"
    first = grid(tmp_path, cache, "a")
    [entry] = cache.glob("*.json")
    entry.unlink()
    entry.mkdir()  # where the entry goes, something that is not ours to replace
    with pytest.warns(errp.SweepWarning, match=rf"{re.escape(entry.name)} could not be stored"):
        again = grid(tmp_path, cache, "b")
    assert entry.is_dir() and [p.name for p in cache.iterdir()] == [entry.name]
    pd.testing.assert_frame_equal(again.episodes, first.episodes)
