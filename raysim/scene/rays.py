"""Ray batches, ray packing for Open3D, and the small thread pool of the per-ray numpy work.

Open3D holds the GIL while casting, so numpy work cannot overlap with Embree;
instead large batches split their per-ray numpy work over a small shared
thread pool (numpy releases the GIL in its loops), chunk by chunk so that
temporaries stay in cache. :class:`RayBatch` carries one cast's rays and the
per-batch quantities (origin box, direction cells, sea ranges, candidates)
that the static and moving parts share.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Callable

import numpy as np

from raysim.scene.geometry import CELLS

CHUNK = 65536
"""Rays per chunk of the per-ray numpy passes (keeps temporaries in cache)."""
PARALLEL_MIN_RAYS = 262144
"""Batches at least this large split their per-ray numpy work over threads."""

_POOLS: dict[int, ThreadPoolExecutor] = {}
_POOL_LOCK = threading.Lock()


def _pool(workers: int) -> ThreadPoolExecutor:
    """A shared thread pool with ``workers`` threads (created on first use)."""
    with _POOL_LOCK:
        if workers not in _POOLS:
            _POOLS[workers] = ThreadPoolExecutor(workers, thread_name_prefix="raysim-scene")
        return _POOLS[workers]


def split_run(n: int, workers: int, fn: Callable[[int, int], object]) -> list:
    """Run ``fn(a, b)`` over contiguous parts of ``range(n)``, in parallel if large.

    Returns the results in the order of the parts.
    """
    if workers <= 1 or n < PARALLEL_MIN_RAYS:
        return [fn(0, n)]
    bounds = np.linspace(0, n, workers + 1).astype(int)
    futures = [_pool(workers).submit(fn, int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]
    return [f.result() for f in futures]


_SCRATCH = threading.local()


def scratch(name: str, shape: tuple[int, ...], dtype: type = np.float32) -> np.ndarray:
    """A per-thread scratch array of at least ``shape`` (reused across calls, never returned)."""
    buf = getattr(_SCRATCH, name, None)
    if buf is None or buf.shape[0] < shape[0] or buf.shape[1:] != shape[1:] or buf.dtype != dtype:
        buf = np.empty(shape, dtype=dtype)
        setattr(_SCRATCH, name, buf)
    return buf[: shape[0]]


def _pack_rays_part(
    origins: np.ndarray,
    directions: np.ndarray,
    idx: np.ndarray | None,
    offset_tile: np.ndarray | None,
    out: np.ndarray,
    a: int,
    b: int,
) -> None:
    """Fill ``out[a:b]`` with float32 ``[o - offset, d]`` rows of rays ``a:b`` (or ``idx[a:b]``).

    Works chunk by chunk through a float64 (chunk, 6) scratch array that stays in
    cache: rows are interleaved as 24-byte items (one long 1-D copy per input
    instead of N tiny row copies), the offset is subtracted with one flat
    vectorised pass, and a single contiguous cast writes the float32 rows.
    """
    s64 = scratch("pack_s64", (CHUNK, 6), np.float64)
    o_items = origins.view("V24")[:, 0]
    d_items = directions.view("V24")[:, 0]
    for s in range(a, b, CHUNK):
        e = min(b, s + CHUNK)
        rows = s64[: e - s]
        items = rows.view("V24")
        if idx is None:
            items[:, 0] = o_items[s:e]
            items[:, 1] = d_items[s:e]
        else:
            items[:, 0] = np.take(o_items, idx[s:e])
            items[:, 1] = np.take(d_items, idx[s:e])
        if offset_tile is not None:
            flat = rows.reshape(-1)
            np.subtract(flat, offset_tile[: flat.size], out=flat)
        np.copyto(out[s:e], rows, casting="same_kind")


def offset_tile(offset_m: np.ndarray | None) -> np.ndarray | None:
    """``[ox, oy, oz, 0, 0, 0]`` repeated for one chunk (None for no offset)."""
    if offset_m is None or not np.any(offset_m):
        return None
    return np.tile(np.concatenate([np.asarray(offset_m, dtype=np.float64), np.zeros(3)]), CHUNK)


def pack_rays(
    origins_m: np.ndarray,
    directions: np.ndarray,
    offset_m: np.ndarray | None = None,
    workers: int = 1,
    out: np.ndarray | None = None,
    idx: np.ndarray | None = None,
) -> np.ndarray:
    """Pack rays into the float32 (N, 6) layout Open3D casts.

    Parameters
    ----------
    origins_m : (N, 3) float64, C-contiguous
        Ray origins, metres.
    directions : (N, 3) float64, C-contiguous
        Unit directions.
    offset_m : (3,) float64 or None
        Subtracted from the origins in float64 before rounding to float32.
    workers : int
        Threads to split large batches over.
    out : (>= M, 6) float32 or None
        Where to write (a new array if None).
    idx : (M,) int or None
        Pack only these rays (all if None).

    Returns
    -------
    (M, 6) float32
        ``[ox - offset_x, oy - offset_y, oz - offset_z, dx, dy, dz]`` rows.
    """
    m = origins_m.shape[0] if idx is None else idx.shape[0]
    out = np.empty((m, 6), dtype=np.float32) if out is None else out[:m]
    tile = offset_tile(offset_m)
    split_run(m, workers, lambda a, b: _pack_rays_part(origins_m, directions, idx, tile, out, a, b))
    return out


@dataclass
class RayBatch:
    """One cast's rays and the per-batch quantities shared by all objects."""

    origins: np.ndarray  # (N, 3) float64
    directions: np.ndarray  # (N, 3) float64
    times: np.ndarray  # (N,) float64
    max_range: np.ndarray | None  # scalar or (N,) float64; None if unlimited
    origin_centre: np.ndarray | None = None  # (3,) centre of the origins' bounding box
    spread_m: float = 0.0  # half-diagonal of that box
    cells: np.ndarray | None = None  # (N,) uint16 direction cells
    sea_range: np.ndarray | None = None  # (N,) float64 range to the sea (inf if none)
    static_candidates: np.ndarray | None = None  # (M,) rays to cast at the static scene
    order: np.ndarray | None = None  # (N,) rays sorted by cell
    cell_start: np.ndarray | None = None  # (CELLS + 1,) first sorted position of each cell

    @property
    def n(self) -> int:
        return self.origins.shape[0]

    def limit(self, s: slice | np.ndarray) -> np.ndarray | float:
        """Nearest range at which rays ``s`` can still get a new hit (sea, max range), metres."""
        lim: np.ndarray | float = np.inf if self.sea_range is None else self.sea_range[s]
        if self.max_range is not None:
            mr = self.max_range[s] if self.max_range.ndim else float(self.max_range)
            lim = np.minimum(lim, mr)
        return lim

    def sort_by_cell(self, limit: np.ndarray, min_near_m: float) -> None:
        """Counting-sort by direction cell the rays that may reach beyond ``min_near_m``.

        Parameters
        ----------
        limit : (N,) float64
            Range beyond which each ray can get no new hit, metres.
        min_near_m : float
            Nearest distance at which any moving object can be met, metres.
        """
        reach = np.flatnonzero(limit > min_near_m)
        cells = self.cells if reach.size == self.n else self.cells[reach]
        order = np.argsort(cells, kind="stable")
        self.order = order if reach.size == self.n else reach[order]
        self.cell_start = np.concatenate(([0], np.cumsum(np.bincount(cells, minlength=CELLS))))
