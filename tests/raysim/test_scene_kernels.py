"""raysim.scene.kernels: the compiled pre-pass gives the numpy pre-pass's cells, sea ranges and candidates, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from raysim import jit
from raysim.scene import kernels
from raysim.scene.geometry import CELLS, direction_cells, intersect_sea

pytestmark = pytest.mark.skipif(jit.numba is None, reason="numba is not installed")


def _rays(n: int, seed: int = 5):
    """Unit directions all round (some level, straight up and down, on the axes, negative zeros) from 0-30 m up."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d[:50, 2] = 0.0
    d[50:60] = [0.0, 0.0, 1.0]
    d[60:70] = [0.0, 0.0, -1.0]
    d[70:80] = [-1.0, 0.0, 0.0]
    d[80:90] = [0.0, -1.0, -0.0]
    d[90:100] = [-0.0, 1.0, -1e-9]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.column_stack([rng.uniform(-50, 50, n), rng.uniform(-50, 50, n), rng.uniform(0.0, 30.0, n)])
    return o, d


@pytest.mark.parametrize("max_range", [None, 120.0, "per ray"])
def test_prepass_is_the_numpy_prepass(max_range):
    o, d = _rays(20_000)
    n = o.shape[0]
    if max_range == "per ray":
        max_range = np.random.default_rng(1).uniform(10.0, 200.0, n)
    near = np.random.default_rng(2).uniform(0.0, 300.0, CELLS).astype(np.float32)
    near[::7] = np.inf
    cells, sea = np.zeros(n, np.uint16), np.zeros(n)
    a, b = 100, n - 3  # a part of the batch
    candidates = kernels.prepass(o, d, None if max_range is None else np.asarray(max_range), near, cells, sea, a, b)
    d32 = d[a:b].T.astype(np.float32)
    ref_cells = direction_cells(d32[0], d32[1], d32[2])
    mr = None if max_range is None else (max_range[a:b] if np.ndim(max_range) else max_range)
    ref_sea = intersect_sea(o[a:b, 2], d[a:b, 2], mr)
    limit = ref_sea if mr is None else np.minimum(ref_sea, mr)
    ref_candidates = np.flatnonzero(np.take(near, ref_cells) < limit) + a
    assert np.array_equal(cells[a:b], ref_cells) and not cells[:a].any() and not cells[b:].any()
    assert np.array_equal(sea[a:b], ref_sea)
    assert np.array_equal(candidates, ref_candidates) and 0 < candidates.size < b - a


def test_prepass_without_sea_or_table():
    o, d = _rays(3000)
    cells = np.zeros(3000, np.uint16)
    assert kernels.prepass(o, d, 50.0, None, cells, None, 0, 3000) is None
    d32 = d.T.astype(np.float32)
    assert np.array_equal(cells, direction_cells(d32[0], d32[1], d32[2]))


def test_origin_box_is_numpys_min_and_max():
    """Random origins (whole and in blocks), one origin, and a NaN, which numpy's min and max keep."""
    from raysim.scene.geometry import origin_box

    rng = np.random.default_rng(4)
    for origins in (rng.normal(0.0, 50.0, (69_121, 3)), rng.normal(size=(1, 3)), rng.normal(size=(300, 3)) * 1e-300):
        lo, hi = kernels.origin_box(origins)
        lo_np, hi_np = origin_box(origins)
        assert np.array_equal(lo, lo_np) and np.array_equal(hi, hi_np)
    with_nan = rng.normal(size=(1000, 3))
    with_nan[500, 1] = np.nan
    lo, hi = kernels.origin_box(with_nan)
    assert np.isnan(lo[1]) and np.isnan(hi[1]) and np.isfinite(lo[[0, 2]]).all()
    assert lo[0] == with_nan[:, 0].min() and hi[2] == with_nan[:, 2].max()
