"""The EEG model's realism from Python: a dict of the effects, checked by
name, and each effect where it should be."""

import numpy as np
import pytest

import errp


def test_an_effect_changes_what_it_should_and_nothing_else():
    ideal = errp.EegGenerator(seed=3)
    bad = errp.EegGenerator(
        seed=3, params={"realism": {"bad_channel": "Cz", "bad_channel_uv": 20.0}})
    a, b = ideal.generate(256 * 20), bad.generate(256 * 20)
    cz = ideal.ch_names.index("Cz")
    others = [i for i in range(a.shape[0]) if i != cz]
    np.testing.assert_array_equal(a[others], b[others])
    extra = np.std(b[cz] - a[cz])
    assert 18.0 < extra < 22.0, extra


def test_an_empty_realism_is_the_ideal_user():
    a = errp.EegGenerator(seed=5).generate(512)
    b = errp.EegGenerator(seed=5, params={"realism": {}}).generate(512)
    np.testing.assert_array_equal(a, b)


def test_the_trial_latency_sd_set_to_the_models_own_is_the_same_user():
    # The EEG model's single-trial latency SD is 25 ms: set to it, the same
    # samples; set to another, other ERPs.
    def erps(realism):
        g = errp.EegGenerator(seed=5, params={"realism": realism})
        for k in range(6):
            g.schedule(0.5 + 1.5 * k, "error")
        return g.generate(10 * 256)

    np.testing.assert_array_equal(erps({}), erps({"trial_latency_sd_ms": 25.0}))
    assert not np.array_equal(erps({}), erps({"trial_latency_sd_ms": 17.0}))


@pytest.mark.parametrize("realism, name", [
    ({"lapse_rate": 1.5}, "realism.lapse_rate"),
    ({"bad_channel": "Q9"}, "realism.bad_channel"),
    ({"lapse": 0.1}, "lapse"),
    ({"trial_latency_sd_ms": 150.0}, "realism.trial_latency_sd_ms"),
])
def test_a_bad_effect_is_a_value_error_naming_it(realism, name):
    with pytest.raises(ValueError, match=name.replace(".", r"\.")):
        errp.EegGenerator(seed=1, params={"realism": realism})
