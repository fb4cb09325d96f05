"""Scenario sets as numpy arrays: the counter-based numbers of the C++ library (thesis §4.4.2, §4.7)."""
import numpy as np
import pytest

import pegasus


def test_plain_scenarios_are_open_unit_uniforms_fixed_by_the_seed():
    a = pegasus.ScenarioSet(seed=7, count=50, horizon=20, noise_dim=3, initial_noise_dim=2)
    b = pegasus.ScenarioSet(seed=7, count=50, horizon=20, noise_dim=3, initial_noise_dim=2)
    c = pegasus.ScenarioSet(seed=8, count=50, horizon=20, noise_dim=3, initial_noise_dim=2)
    noise = a.step_noise()
    assert noise.shape == (50, 20, 3) and a.initial_noise().shape == (50, 2)
    assert np.all((noise > 0) & (noise < 1))
    assert np.array_equal(noise, b.step_noise()) and np.array_equal(a.initial_noise(), b.initial_noise())
    assert not np.any(noise == c.step_noise())
    assert abs(noise.mean() - 0.5) < 0.02


def test_antithetic_pairs_mirror_every_uniform():
    s = pegasus.ScenarioSet(seed=3, count=10, horizon=5, noise_dim=2, initial_noise_dim=2, variant="antithetic")
    noise, init = s.step_noise(), s.initial_noise()
    assert np.array_equal(noise[1::2], 1.0 - noise[0::2])
    assert np.array_equal(init[1::2], 1.0 - init[0::2])


def test_stratified_initial_noise_has_one_scenario_per_stratum():
    m = 16
    s = pegasus.ScenarioSet(seed=3, count=m, horizon=2, noise_dim=1, initial_noise_dim=3, variant="stratified")
    strata = np.floor(s.initial_noise() * m).astype(int)
    for dim in range(3):
        assert sorted(strata[:, dim]) == list(range(m))


def test_sobol_points_fill_the_cube_more_evenly_than_plain_ones():
    m = 64
    sobol = pegasus.ScenarioSet(seed=5, count=m, horizon=1, noise_dim=1, initial_noise_dim=1, variant="sobol")
    plain = pegasus.ScenarioSet(seed=5, count=m, horizon=1, noise_dim=1, initial_noise_dim=1)
    def worst_gap(x):
        return np.max(np.abs(np.sort(x) - (np.arange(m) + 0.5) / m))
    assert worst_gap(sobol.initial_noise()[:, 0]) <= 1.0 / m
    assert worst_gap(sobol.initial_noise()[:, 0]) < worst_gap(plain.initial_noise()[:, 0])


@pytest.mark.parametrize("field,value", [("count", 0), ("count", -3), ("horizon", 0), ("noise_dim", -1),
                                         ("initial_noise_dim", -2)])
def test_bad_sizes_raise_value_error_naming_the_argument(field, value):
    kwargs = dict(seed=1, count=2, horizon=3, noise_dim=1, initial_noise_dim=0)
    kwargs[field] = value
    with pytest.raises(ValueError, match=field):
        pegasus.ScenarioSet(**kwargs)


def test_bad_seed_and_variant_raise_value_error():
    with pytest.raises(ValueError, match="seed"):
        pegasus.ScenarioSet(seed=-1, count=2, horizon=3, noise_dim=1)
    with pytest.raises(ValueError, match="variant"):
        pegasus.ScenarioSet(seed=1, count=2, horizon=3, noise_dim=1, variant="quasi")
