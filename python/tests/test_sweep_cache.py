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


@pytest.fixture(scope="module")
def first(tmp_path_factory):
    """One sweep that searched its targeting and cached it: its episodes and
    its cache entry's name and text (each test starts from a copy)."""
    tmp = tmp_path_factory.mktemp("first")
    cache = tmp / "cache"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = grid(tmp, cache, "a")
    [entry] = cache.glob("*.json")
    return res.episodes, entry.name, entry.read_text()


def cached(tmp_path, first):
    """A cache directory holding the first sweep's entry; the entry's path."""
    cache = tmp_path / "cache"
    cache.mkdir()
    entry = cache / first[1]
    entry.write_text(first[2])
    return cache, entry


def test_a_cached_targeting_is_used_again_without_a_warning(tmp_path, first):
    cache, _ = cached(tmp_path, first)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = grid(tmp_path, cache, "b")
    assert len(list(cache.glob("*.json"))) == 1
    pd.testing.assert_frame_equal(again.episodes, first[0])


@pytest.mark.parametrize("ratio", [0.0, 1e308, "times 3"])
def test_a_tampered_entry_warns_naming_it_and_is_searched_again(tmp_path, first, ratio):
    cache, entry = cached(tmp_path, first)
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
    pd.testing.assert_frame_equal(again.episodes, first[0])


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


def test_an_entry_that_cannot_be_stored_warns_naming_it(tmp_path, first):
    cache, entry = cached(tmp_path, first)
    entry.unlink()
    entry.mkdir()  # where the entry goes, something that is not ours to replace
    with pytest.warns(errp.SweepWarning, match=rf"{re.escape(entry.name)} could not be stored"):
        again = grid(tmp_path, cache, "b")
    assert entry.is_dir() and [p.name for p in cache.iterdir()] == [entry.name]
    pd.testing.assert_frame_equal(again.episodes, first[0])
