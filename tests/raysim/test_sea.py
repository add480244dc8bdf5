"""raysim.sea: the whitecap formula and the foam field's coverage, against the formula."""

from __future__ import annotations

import numpy as np
import pytest

from raysim.sea import SEA_STATE_WIND_MPS, FoamField, whitecap_fraction


@pytest.mark.parametrize("wind", [0.0, 3.0, 7.5, 10.0, 15.0])
def test_whitecap_fraction_is_monahan_and_omuircheartaigh(wind):
    assert whitecap_fraction(wind) == pytest.approx(3.84e-6 * wind ** 3.41, rel=1e-12)


def test_whitecap_fraction_is_zero_for_no_wind_and_at_most_one():
    assert whitecap_fraction(-5.0) == 0.0
    assert whitecap_fraction(1000.0) == 1.0


def test_effective_wind_is_the_larger_of_the_configured_and_the_sea_states():
    assert FoamField(1.0, 4, 0.0, np.random.default_rng(0)).effective_wind_mps == SEA_STATE_WIND_MPS[4]
    field = FoamField(20.0, 1, 0.0, np.random.default_rng(0))
    assert field.effective_wind_mps == 20.0
    assert field.coverage == pytest.approx(whitecap_fraction(20.0))


def test_no_wind_no_foam():
    field = FoamField(0.0, 0, 0.0, np.random.default_rng(1))
    x = np.linspace(-100.0, 100.0, 1000)
    assert field.coverage == 0.0
    assert not field.is_foam(x, x, np.zeros_like(x)).any()


def test_foam_covers_the_whitecap_fraction_of_the_sea():
    field = FoamField(15.0, 5, 270.0, np.random.default_rng(2))
    rng = np.random.default_rng(3)
    n = 400_000
    x, y = rng.uniform(-5000.0, 5000.0, n), rng.uniform(-5000.0, 5000.0, n)
    t = rng.uniform(0.0, 600.0, n)
    covered = field.is_foam(x, y, t).mean()
    assert covered == pytest.approx(field.coverage, rel=0.15)


def test_foam_is_a_function_of_place_and_time_only():
    a = FoamField(12.0, 4, 45.0, np.random.default_rng(5))
    b = FoamField(12.0, 4, 45.0, np.random.default_rng(5))
    rng = np.random.default_rng(6)
    x, y, t = rng.uniform(-300, 300, 5000), rng.uniform(-300, 300, 5000), rng.uniform(0, 60, 5000)
    assert np.array_equal(a.is_foam(x, y, t), b.is_foam(x, y, t))
    # evaluated in any order or grouping: the same answer (the reference point only changes float32 rounding)
    order = rng.permutation(5000)
    assert (a.is_foam(x[order], y[order], t[order]) == a.is_foam(x, y, t)[order]).mean() > 0.999
