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


@pytest.mark.parametrize("realism, name", [
    ({"lapse_rate": 1.5}, "realism.lapse_rate"),
    ({"bad_channel": "Q9"}, "realism.bad_channel"),
    ({"lapse": 0.1}, "lapse"),
])
def test_a_bad_effect_is_a_value_error_naming_it(realism, name):
    with pytest.raises(ValueError, match=name.replace(".", r"\.")):
        errp.EegGenerator(seed=1, params={"realism": realism})
