"""The LiDAR front end's graph (:mod:`tdm.frontend.lidar`, steps 5 and 6), for one sweep or several at once.

Points carry the index of their sweep, and every key below has the sweep as its leading digit, so
that the sweeps of a batch share each array pass and never join: the voxels of a sweep, their
Euclidean pairs and the range-image links come out as for that sweep alone, in the same order.

* :func:`voxel_grid`: horizontal voxels (pillars) and their mean points;
* :func:`voxel_pairs`: pairs of voxel centres within a tolerance on the horizontal plane (the pairs
  ``scipy.spatial.cKDTree.query_pairs`` finds, from the voxel grid instead of a tree);
* :func:`range_image_links`: pairs of points on one surface, neighbours in the range image;
* :func:`components`: connected components of a graph, numbered as scipy numbers them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tdm.frontend.lidar_config import HDL32E_FIRING_CYCLE_S, LINK_WINDOW_CYCLES, LidarFrontEndConfig

__all__ = ["NEIGHBOUR_AZIMUTH_STEPS", "VoxelGrid", "components", "range_image_links", "voxel_grid", "voxel_pairs"]

#: Range-image neighbours lie within this many azimuth steps of each other (a firing cycle apart,
#: or two when one firing had no return).
NEIGHBOUR_AZIMUTH_STEPS = 2
#: Spare azimuth bins per ring in the range image's keys, beyond one revolution (the bins of a
#: ring stay apart from the next ring's whatever the rounding of the azimuths).
_SPARE_AZIMUTH_BINS = 8


@dataclass
class VoxelGrid:
    """The occupied voxels of one or more sweeps, in the order of (sweep, east cell, north cell).

    Attributes
    ----------
    inverse : (N,) intp
        Each point's voxel.
    centres_m : (V, 2) float64
        Each voxel's mean point (east, north), m.
    keys : (V,) int64
        Each voxel's key, ``(sweep * n_east + east cell) * n_north + north cell`` (ascending); the cells
        are padded by ``reach`` on every side, so that a neighbour ``reach`` cells away has a key of the
        same sweep.
    n_north : int
        Cells per column in the keys.
    reach : int
        Cells within which two voxel centres may lie closer than the tolerance.
    """

    inverse: np.ndarray
    centres_m: np.ndarray
    keys: np.ndarray
    n_north: int
    reach: int


def voxel_grid(enu_m: np.ndarray, sweep: np.ndarray, voxel_m: float, tolerance_m: float) -> VoxelGrid:
    """Horizontal voxels (pillars) of ``voxel_m`` of the points, one set per sweep (step 5).

    Parameters
    ----------
    enu_m : (N, 3) float64
        Points in ENU, m.
    sweep : (N,) int64
        Each point's sweep (0 .. S-1), non-decreasing.
    voxel_m, tolerance_m : float
        Voxel size and the Euclidean clustering tolerance (which sets ``reach``), m.

    Returns
    -------
    VoxelGrid
    """
    reach = int(math.floor(tolerance_m / voxel_m)) + 1  # centres d cells apart are more than (d - 1) voxels apart
    cell = np.floor(enu_m[:, :2] / voxel_m).astype(np.int64)
    cell -= cell.min(axis=0) - reach
    n_east, n_north = int(cell[:, 0].max()) + 1 + reach, int(cell[:, 1].max()) + 1 + reach
    key = (sweep * n_east + cell[:, 0]) * n_north + cell[:, 1]
    keys, inverse, voxel_count = np.unique(key, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    n_voxels = voxel_count.shape[0]
    centres = np.stack([np.bincount(inverse, enu_m[:, 0], n_voxels), np.bincount(inverse, enu_m[:, 1], n_voxels)],
                       axis=1) / voxel_count[:, None]
    return VoxelGrid(inverse, centres, keys, n_north, reach)


def voxel_pairs(grid: VoxelGrid, tolerance_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of voxels of one sweep whose centres lie within ``tolerance_m`` on the horizontal plane (step 6).

    A voxel's centre lies in its cell, so a centre within the tolerance lies at most ``reach`` cells
    away: for each voxel, the voxels of the next ``reach`` columns (and of its own column above it)
    within ``reach`` rows are a run of consecutive keys, found by two binary searches. A pair is kept
    when ``de^2 + dn^2 <= tolerance^2``, the test ``cKDTree.query_pairs`` makes (sum of squares in the
    order of the axes, against the tolerance squared), so the pairs are the same.

    Returns
    -------
    i, j : (K,) intp
        The pairs' voxels, ``i < j``.
    """
    keys, reach = grid.keys, grid.reach
    n = keys.shape[0]
    lows, highs = [], []
    for column in range(reach + 1):  # a few columns, each a pass over every voxel
        base = keys + column * grid.n_north
        lows.append(np.searchsorted(keys, base + 1 if column == 0 else base - reach))
        highs.append(np.searchsorted(keys, base + reach, side="right"))
    low, high = np.concatenate(lows), np.concatenate(highs)
    count = np.maximum(high - low, 0)
    first = np.repeat(np.tile(np.arange(n), reach + 1), count)
    run_start = np.cumsum(count) - count
    second = np.repeat(low - run_start, count) + np.arange(first.shape[0])
    east, north = grid.centres_m[:, 0].copy(), grid.centres_m[:, 1].copy()  # contiguous: faster gathers
    d_east = east[first] - east[second]
    d_north = north[first] - north[second]
    near = d_east * d_east + d_north * d_north <= tolerance_m * tolerance_m
    return first[near], second[near]


def range_image_links(ring: np.ndarray, sweep: np.ndarray, points_m: np.ndarray, range_m: np.ndarray,
                      t_s: np.ndarray, config: LidarFrontEndConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs of points on one surface, neighbours in the range image (:mod:`tdm.frontend.lidar`, step 6).

    The points are sorted (stably) by (sweep, ring, azimuth bin of one azimuth step). Along a ring,
    each point is paired with the next one when it lies within two azimuth steps; across rings, with
    the point nearest in azimuth (within two steps) of the ring ``step`` above
    (``step = 1 .. ring_link_max_step``). A pair is kept when ``beta > theta``. With
    ``p, q`` the two points (ranges ``d1 >= d2``), ``d2 sin a = |p x q| / d1`` and
    ``d2 cos a = p.q / d1``, so ``d2 sin a > tan(theta) (d1 - d2 cos a)`` reads
    ``|p x q|^2 > tan^2(theta) (d1^2 - p.q)^2`` (both sides >= 0), with
    ``|p x q|^2 = |p|^2 |q|^2 - (p.q)^2``: no angles needed. Neighbours must also be
    fired within ``LINK_WINDOW_CYCLES`` firing cycles of each other: at the sweep's seam,
    points next to each other in azimuth were fired a revolution apart, and the own ship
    has moved in between.

    Parameters
    ----------
    ring : (N,) int64
        Laser ring of each point (0 = lowest).
    sweep : (N,) int64
        Each point's sweep.
    points_m : (N, 3) float64
        Points in the sensor frame, m.
    range_m : (N,) float64
        Their ranges, m.
    t_s : (N,) float64
        Their times, s.

    Returns
    -------
    i, j : (K,) intp
        Indices of linked points.
    on_surface : (N,) bool
        Points linked to a neighbour along their own ring (the same laser's next or
        previous firing hit the same surface).
    """
    n = ring.shape[0]
    on_surface = np.zeros(n, dtype=bool)
    if n < 2:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp), on_surface
    step_rad = config.azimuth_step_rad
    n_bins = int(math.ceil(2.0 * math.pi / step_rad)) + _SPARE_AZIMUTH_BINS
    azimuth_bin = ((np.arctan2(points_m[:, 1], points_m[:, 0]) + math.pi) / step_rad).astype(np.int64)
    rings_per_sweep = int(ring.max()) + 1 + config.ring_link_max_step  # a ring `step` up stays in its sweep
    key = (sweep * rings_per_sweep + ring) * n_bins + azimuth_bin
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    range2 = range_m * range_m
    tan2 = math.tan(math.radians(config.ring_link_angle_deg)) ** 2
    window_s = LINK_WINDOW_CYCLES * HDL32E_FIRING_CYCLE_S

    def same_surface(i, j):
        dot = np.einsum("ij,ij->i", points_m[i], points_m[j])
        r2i, r2j = range2[i], range2[j]
        gap = np.maximum(r2i, r2j) - dot
        return (r2i * r2j - dot * dot > tan2 * gap * gap) & (np.abs(t_s[i] - t_s[j]) <= window_s)

    # along each ring: successive points in the sorted order
    close = np.nonzero(sorted_key[1:] - sorted_key[:-1] <= NEIGHBOUR_AZIMUTH_STEPS)[0]
    i, j = order[close], order[close + 1]
    linked = same_surface(i, j)
    firsts, seconds = [i[linked]], [j[linked]]
    on_surface[firsts[0]] = True
    on_surface[seconds[0]] = True
    # across rings
    for step in range(1, config.ring_link_max_step + 1):
        query = key + step * n_bins
        pos = np.searchsorted(sorted_key, query)
        lo = order[np.maximum(pos - 1, 0)]
        hi = order[np.minimum(pos, n - 1)]
        d_lo = np.abs(key[lo] - query)  # in azimuth bins when in the right ring
        d_hi = np.abs(key[hi] - query)
        i = np.nonzero(np.minimum(d_lo, d_hi) <= NEIGHBOUR_AZIMUTH_STEPS)[0]
        j = np.where(d_hi[i] < d_lo[i], hi[i], lo[i])
        linked = same_surface(i, j)
        firsts.append(i[linked])
        seconds.append(j[linked])
    return np.concatenate(firsts), np.concatenate(seconds), on_surface


def components(rows: np.ndarray, cols: np.ndarray, n: int) -> np.ndarray:
    """(n,) connected component of each of ``n`` nodes joined by the undirected edges ``rows[k] - cols[k]`` (E,),
    numbered in the order of each component's lowest node: the labels of
    ``scipy.sparse.csgraph.connected_components`` (which numbers components as its scan over the nodes
    meets them), without its per-call graph checks.

    Min-label hooking with pointer jumping (Shiloach & Vishkin, "An O(log n) parallel connectivity
    algorithm", J. Algorithms 3(1), 1982): every node points at a node of no higher index; each round
    hooks the root of each edge's higher end on the lower, then every pointer jumps to its root. A
    component's lowest node never moves, so at the end it is every member's root.
    """
    parent = np.arange(n)
    while rows.size:  # a few rounds: each at least halves the trees' depth
        low = np.minimum(parent[rows], parent[cols])
        np.minimum.at(parent, parent[rows], low)
        np.minimum.at(parent, parent[cols], low)
        while True:  # pointer jumping until every node points at its root
            jumped = parent[parent]
            if np.array_equal(jumped, parent):
                break
            parent = jumped
        if np.array_equal(parent[rows], parent[cols]):
            break
    return np.unique(parent, return_inverse=True)[1].reshape(-1)
