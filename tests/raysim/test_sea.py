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


def _plain_is_foam(field: FoamField, x_m: np.ndarray, y_m: np.ndarray, t_s: np.ndarray) -> np.ndarray:
    """The foam test as first written (broadcast phase add, row reduction, division, threshold)."""
    from raysim.sea import N_WAVES

    x0, y0, t0 = float(x_m[0]), float(y_m[0]), float(t_s[0])
    phase = np.mod(field.phase + field.kx * x0 + field.ky * y0 - field.omega * t0, 2 * np.pi).astype(np.float32)
    local = np.empty((x_m.shape[0], 3), dtype=np.float32)
    local[:, 0] = x_m - x0
    local[:, 1] = y_m - y0
    local[:, 2] = t_s - t0
    waves = np.stack([field.kx, field.ky, -field.omega]).astype(np.float32)
    arg = local @ waves
    arg += phase
    value = np.cos(arg, out=arg).sum(axis=1) / np.float32(np.sqrt(N_WAVES / 2.0))
    return value > field.threshold


@pytest.mark.parametrize("n", [1, 31, 32, 1000, 27_613])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_the_foam_test_equals_the_plain_formula_bit_for_bit(n, dtype):
    rng = np.random.default_rng(n)
    for seed, (wind, state) in enumerate([(10.0, 4), (15.0, 5), (25.0, 6)]):
        field = FoamField(wind, state, 37.0 * seed, np.random.default_rng(seed))
        x = rng.uniform(-3000.0, 3000.0, n).astype(dtype)
        y = rng.uniform(-3000.0, 3000.0, n).astype(dtype)
        t = np.sort(rng.uniform(100.0, 100.1, n)).astype(dtype)
        got = field.is_foam(x, y, t)
        assert got.dtype == bool and np.array_equal(got, _plain_is_foam(field, x, y, t))


def test_row_sums_and_row_adds_equal_numpys():
    """sum_rows keeps NumPy's pairwise order (other orders differ on about half the rows); add_to_rows is +=."""
    from raysim.sea import add_to_rows, sum_rows

    rng = np.random.default_rng(12)
    a = np.cos(rng.uniform(-40.0, 40.0, (50_017, 8))).astype(np.float32)
    assert np.array_equal(sum_rows(a), a.sum(axis=1))
    in_order = a[:, 0].copy()
    for k in range(1, 8):
        in_order += a[:, k]
    assert np.count_nonzero(in_order != a.sum(axis=1)) > 1000  # the order matters: the test can fail
    assert np.array_equal(sum_rows(a[:, :5]), a[:, :5].sum(axis=1))
    row = rng.uniform(0.0, 6.3, 8).astype(np.float32)
    for n in (0, 5, 32, 50_017):
        b, c = a[:n].copy(), a[:n].copy()
        add_to_rows(b, row)
        c += row
        assert b.tobytes() == c.tobytes()
