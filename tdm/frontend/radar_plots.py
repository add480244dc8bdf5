"""Radar plots: gap filling along range and connected components of a sweep's detections
(module docstring of :mod:`tdm.frontend.radar`, steps 3-4).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

__all__ = ["fill_gaps", "label_max_min", "label_plots"]


def _fill_runs(flat: np.ndarray, n_samples: int, detected: np.ndarray) -> np.ndarray:
    """(M,) bool: cells from the first to the last detection of their run.

    ``flat`` are the ascending flat indices of the cells strong enough to fill; a run is a maximal
    sequence of them that are consecutive samples of one spoke.
    """
    m = flat.size
    if m == 0:
        return np.zeros(0, dtype=bool)
    brk = np.ones(m, dtype=bool)
    brk[1:] = (np.diff(flat) != 1) | (flat[1:] % n_samples == 0)
    starts = np.flatnonzero(brk)
    run = np.cumsum(brk) - 1
    pos = np.arange(m)
    first_det = np.minimum.reduceat(np.where(detected, pos, m), starts)
    last_det = np.maximum.reduceat(np.where(detected, pos, -1), starts)
    return (pos >= first_det[run]) & (pos <= last_det[run])


def fill_gaps(mask: np.ndarray, echo: np.ndarray, fill_level: float) -> np.ndarray:
    """Detections plus every cell between two detections of a spoke joined by echo >= ``fill_level``.

    Parameters
    ----------
    mask : (S, N) bool
        CFAR detections.
    echo : (S, N) array
        Video levels (or power) the run condition is tested on.
    fill_level : float
        Lowest value of a filling cell.

    Returns
    -------
    (S, N) bool
    """
    mask = np.asarray(mask, dtype=bool)
    flat = np.flatnonzero((np.asarray(echo) >= fill_level) | mask)
    out = mask.copy()
    filled = _fill_runs(flat, mask.shape[1], mask.ravel()[flat])
    out.ravel()[flat[filled]] = True
    return out


def label_plots(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """Connected components of a sweep's detections, circular in azimuth.

    8-connected (a cell touches the 8 around it); the last spoke touches the first (the revolution
    is circular).

    Parameters
    ----------
    mask : (S, N) bool

    Returns
    -------
    labels : (S, N) int32
        0 = background, 1..n = plot, numbered in the order of their first cell.
    n : int
        Number of plots.
    """
    mask = np.asarray(mask, dtype=bool)
    flat = np.flatnonzero(mask)
    lab, n = _label_cells(flat, *mask.shape)
    labels = np.zeros(mask.shape, dtype=np.int32)
    labels.ravel()[flat] = lab
    return labels, n


def _runs(flat: np.ndarray, n_samples: int) -> tuple[np.ndarray, np.ndarray]:
    """Runs of ascending flat cell indices: (M_runs,) first and (M_runs,) last position in ``flat``.

    A run is a maximal sequence of consecutive samples of one spoke.
    """
    brk = np.ones(flat.size, dtype=bool)
    brk[1:] = (np.diff(flat) != 1) | (flat[1:] % n_samples == 0)
    starts = np.flatnonzero(brk)
    return starts, np.append(starts[1:], flat.size) - 1


def _label_cells(flat: np.ndarray, n_spokes: int, n_samples: int) -> tuple[np.ndarray, int]:
    """Labels 1..n of the cells ``flat`` (ascending flat indices) by 8-connectivity, circular in azimuth.

    Works on runs along range: two runs on neighbouring spokes (the last spoke's neighbour is the
    first) touch when their sample intervals, widened by one, overlap; the runs' graph goes through
    ``scipy.sparse.csgraph.connected_components``.
    """
    if flat.size == 0:
        return np.zeros(0, dtype=np.int32), 0
    starts, ends = _runs(flat, n_samples)
    spoke = flat[starts] // n_samples
    a, b = flat[starts] % n_samples, flat[ends] % n_samples
    width = n_samples + 2  # keys keep spokes apart: spoke * width + sample, samples -1 .. n_samples
    key_end, key_start = spoke * width + b, spoke * width + a
    prev = (spoke - 1) % n_spokes
    lo = np.searchsorted(key_end, prev * width + a - 1, side="left")  # first run on prev ending at >= a - 1
    hi = np.searchsorted(key_start, prev * width + b + 1, side="right")  # past the last starting at <= b + 1
    count = np.maximum(hi - lo, 0)
    if n_spokes < 3:  # a spoke is its own neighbour's neighbour: no seam logic needed, but no self-loops either
        count = np.where(prev == spoke, 0, count)
    j = np.repeat(np.arange(starts.size), count)
    i = np.repeat(lo, count) + (np.arange(j.size) - np.repeat(np.cumsum(count) - count, count))
    graph = coo_matrix((np.ones(j.size, dtype=np.int8), (i, j)), shape=(starts.size, starts.size))
    _, comp = connected_components(graph, directed=False)
    # number components 1..n in the order of their first run
    _, first_run, inverse = np.unique(comp, return_index=True, return_inverse=True)
    order = np.argsort(first_run)
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    run_label = (rank[inverse] + 1).astype(np.int32)
    return np.repeat(run_label, ends - starts + 1), int(order.size)


def _spokes_per_label(lab: np.ndarray, spoke: np.ndarray, n_labels: int, n_spokes: int) -> np.ndarray:
    """(n_labels,) number of distinct spokes of each label's cells (cells spoke-major, ascending)."""
    new = np.ones(lab.size, dtype=bool)  # a (label, spoke) pair not seen on the previous cells of the spoke
    new[1:] = (spoke[1:] != spoke[:-1]) | (lab[1:] != lab[:-1])
    pair = np.unique(lab[new].astype(np.int64) * n_spokes + spoke[new])
    return np.bincount(pair // n_spokes, minlength=n_labels)


def label_max_min(values: np.ndarray, lab: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(n,) largest and (n,) smallest of ``values`` (M,) per label 0..n-1 of ``lab`` (M,), in the values' dtype
    (``scipy.ndimage.maximum`` / ``minimum``; every label holds a cell)."""
    if np.issubdtype(values.dtype, np.floating):
        low, high = np.inf, -np.inf
    else:
        low, high = np.iinfo(values.dtype).max, np.iinfo(values.dtype).min
    largest, smallest = np.full(n, high, dtype=values.dtype), np.full(n, low, dtype=values.dtype)
    np.maximum.at(largest, lab, values)
    np.minimum.at(smallest, lab, values)
    return largest, smallest
