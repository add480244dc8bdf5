"""Compiled kernels of the ray engine's per-batch pre-pass (:mod:`raysim.jit`), beside the numpy code they replace.

:func:`prepass` is :meth:`raysim.scene.engine.Scene._prepass_part` in one pass per ray: the ray's
direction cell (:func:`raysim.scene.geometry.direction_cells`, the same float32 steps), its range to
the sea (:func:`raysim.scene.geometry.intersect_sea`) and whether the static near table lets it
through. :func:`origin_box` is :func:`raysim.scene.geometry.origin_box` in one pass. The values are
the numpy path's, bit for bit (tests/raysim/test_scene_kernels.py).
"""

from __future__ import annotations

import numpy as np

from raysim.jit import kernel
from raysim.scene.geometry import _AZ_SCALE, _EL_SCALE, EL_BINS

_AZ = np.float32(_AZ_SCALE)
_EL = np.float32(_EL_SCALE)
_EL_TOP = np.float32(EL_BINS - 0.5)


@kernel
def _prepass(origins, directions, max_range, near_table, use_near, use_sea, a, b, cells, sea_range, candidates):
    n_cand = 0
    several = max_range.shape[0] > 1
    for i in range(a, b):
        x = np.float32(directions[i, 0])
        y = np.float32(directions[i, 1])
        z = np.float32(directions[i, 2])
        s = (np.abs(x) + np.abs(y)) + np.float32(1e-30)
        p = y / s
        if x < 0:
            p = np.float32(np.copysign(np.float32(2.0), y)) - p
        az = (p + np.float32(2.0)) * _AZ
        el = (z + np.float32(1.0)) * _EL
        el = min(max(el, np.float32(0.0)), _EL_TOP)
        cell = np.uint16(np.uint16(az) * np.uint16(EL_BINS) + np.uint16(el))
        cells[i] = cell
        mr = max_range[i if several else 0]
        limit = mr
        if use_sea:
            t = -(origins[i, 2] / directions[i, 2])
            sea = t if (t >= 0.0 and t <= mr) else np.inf
            sea_range[i] = sea
            limit = min(sea, mr)
        if use_near and near_table[cell] < limit:
            candidates[n_cand] = i
            n_cand += 1
    return n_cand


def prepass(origins: np.ndarray, directions: np.ndarray, max_range: np.ndarray | None, near_table: np.ndarray | None,
            cells: np.ndarray, sea_range: np.ndarray | None, a: int, b: int) -> np.ndarray | None:
    """Direction cells and sea ranges of rays ``a:b`` (written in place), and their static candidates.

    Parameters
    ----------
    origins, directions : (N, 3) float64
        The batch's rays, m and unit.
    max_range : None, scalar or (N,) float64
        The batch's range limit, m (None: none).
    near_table : (CELLS,) float32 or None
        The static objects' nearest distance per direction cell, m (None: no candidates asked).
    cells : (N,) uint16
        Written at ``a:b``.
    sea_range : (N,) float64 or None
        Written at ``a:b`` (None: the scene has no sea).
    a, b : int
        The rays of this part.

    Returns
    -------
    (M,) int64 or None
        The rays of ``a:b`` the near table lets through (None without a table).
    """
    limit = np.full(1, np.inf) if max_range is None else np.ascontiguousarray(max_range, dtype=np.float64).reshape(-1)
    use_near, use_sea = near_table is not None, sea_range is not None
    candidates = np.empty(b - a if use_near else 0, dtype=np.int64)
    n = _prepass(origins, directions, limit, near_table if use_near else np.zeros(1, np.float32), use_near, use_sea,
                 a, b, cells, sea_range if use_sea else np.zeros(1), candidates)
    return candidates[:n] if use_near else None


__all__ = ["prepass"]


@kernel
def _origin_box(origins, lo, hi):
    for a in range(3):
        lo[a] = np.inf
        hi[a] = -np.inf
    for i in range(origins.shape[0]):
        for a in range(3):
            v = origins[i, a]
            if np.isnan(v):  # a NaN stays, as numpy's min and max keep it (no comparison with it holds)
                lo[a] = v
                hi[a] = v
            else:
                if v < lo[a]:
                    lo[a] = v
                if v > hi[a]:
                    hi[a] = v


def origin_box(origins: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-axis min and max of (N, 3) float64 origins, N >= 1, m (:func:`raysim.scene.geometry.origin_box`)."""
    lo, hi = np.empty(3), np.empty(3)
    _origin_box(np.ascontiguousarray(origins, dtype=np.float64), lo, hi)
    return lo, hi
