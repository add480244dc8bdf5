"""Radar clutter map: beam-integrated power and the local clutter level of a plot
(module docstring of :mod:`tdm.frontend.radar`, step 5).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache

import numpy as np

from tdm.frontend.radar_config import RadarFrontEndConfig

__all__ = ["LandBlocks", "beam_integrated_power", "cell_window_power", "clutter_map"]

#: Which clutter-map blocks lie within the beam's smear of the land: called with the (sb, nb) bool blocks to
#: test, the spokes and the samples per block and the fraction of the beamwidth; returns (sb, nb) bool
#: (:func:`tdm.frontend.radar_land.land_blocks`, bound to a sweep).
LandBlocks = Callable[[np.ndarray, int, int, float], np.ndarray]

#: Cells per part of the integration windows' float64 temporaries (they stay in cache).
_WINDOW_PART_CELLS = 1 << 15
#: Block maxima are floored here (linear power over the mean noise) before they go to dB: no log of 0.
BLOCK_POWER_FLOOR = 1e-6


def _group_spokes(n_spokes: int, wanted: int) -> int:
    """Largest divisor of ``n_spokes`` not above ``wanted`` (at least 1)."""
    for g in range(max(1, wanted), 0, -1):
        if n_spokes % g == 0:
            return g
    return 1


def _group_sums(rows: np.ndarray, cols: np.ndarray, excess: np.ndarray, n_groups: int, g: int,
                n_samples: int) -> np.ndarray:
    """(n_groups, n_samples) float64 sums of ``excess`` (M,) = power - 1 (units of the mean noise) of the
    cells (``rows``, ``cols``) (M,) over groups of ``g`` spokes, added in the cells' order."""
    return np.bincount((rows // g) * n_samples + cols, weights=excess,
                       minlength=n_groups * n_samples).reshape(n_groups, n_samples)


def _windows(groups: np.ndarray, g: int) -> np.ndarray:
    """(A, N) float32 integrated power, units of the mean noise: row i the mean of groups i and i + 1
    (circular) of ``g`` spokes' excess each (:func:`_group_sums`, (A, N)), plus the floor."""
    window = np.empty(groups.shape, dtype=np.float32)
    rows_per_part = max(1, _WINDOW_PART_CELLS // max(1, groups.shape[1]))
    for lo in range(0, groups.shape[0], rows_per_part):  # parts: small temporaries
        hi = min(lo + rows_per_part, groups.shape[0])
        after = groups[lo + 1:hi + 1] if hi < groups.shape[0] else np.concatenate([groups[lo + 1:hi], groups[:1]])
        part = groups[lo:hi] + after
        part *= 0.5 / g
        np.add(part, 1.0, out=window[lo:hi])  # in float64, then rounded to float32 once
    return window


def _integrate_cells(rows: np.ndarray, cols: np.ndarray, excess: np.ndarray, shape: tuple[int, int],
                     config: RadarFrontEndConfig) -> tuple[np.ndarray, int]:
    """:func:`beam_integrated_power` from the cells above the floor only: (M,) spokes ``rows``,
    samples ``cols`` and ``excess`` = power - 1 (units of the mean noise) of the cells of a sweep of ``shape``."""
    n_spokes, n_samples = shape
    g = integration_group(n_spokes, config)
    return _windows(_group_sums(rows, cols, excess, n_spokes // g, g, n_samples), g), g


def integration_group(n_spokes: int, config: RadarFrontEndConfig) -> int:
    """Spokes per group of the beam integration (:func:`beam_integrated_power`): ``integration_spokes / 2``,
    or the largest divisor of ``n_spokes`` under it."""
    return _group_spokes(n_spokes, max(1, config.integration_spokes // 2))


def beam_integrated_power(power: np.ndarray, config: RadarFrontEndConfig) -> tuple[np.ndarray, int]:
    """Power averaged over ``integration_spokes`` neighbouring spokes, decimated in azimuth.

    Spokes are summed in groups of ``g = integration_spokes / 2`` (a divisor of the spoke count) and
    two neighbouring groups make one window: row i is the mean of spokes ``g i .. g i + 2 g - 1``
    (circular), every sample. A target's echo holds over the beam while the sea's speckle changes
    from spoke to spoke (docs/reference.md 3.8), so this non-coherent integration lowers the clutter's
    spikes, not the target. Decimating by g (1.4 deg at 2048 spokes) costs a target's peak at most
    0.5 dB in a 5.2 deg two-way Gaussian beam.

    Parameters
    ----------
    power : (S, N) float
        Linear power per cell (:func:`video_power`).
    config : RadarFrontEndConfig

    Returns
    -------
    integrated : (S / g, N) float32
    g : int
        Spokes per group.
    """
    power = np.asarray(power, dtype=np.float64)
    rows, cols = np.nonzero(power != 1.0)
    return _integrate_cells(rows, cols, power[rows, cols] - 1.0, power.shape, config)


@lru_cache(maxsize=8)
def _annulus_offsets(window: tuple[int, int], guard: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Block offsets (azimuth, range) of a centred window minus its centred guard."""
    wa, wr = window
    ga, gr = guard
    a, r = np.meshgrid(np.arange(wa) - wa // 2, np.arange(wr) - wr // 2, indexing="ij")
    keep = ~((np.abs(a) <= ga // 2) & (np.abs(r) <= gr // 2))
    return a[keep], r[keep]


def clutter_map(integrated: np.ndarray, group_spokes: int, config: RadarFrontEndConfig) -> np.ndarray:
    """Seed threshold of every block: the integrated power a plot must reach to stand out of the clutter.

    The integrated sweep (:func:`beam_integrated_power`) is cut into blocks of
    ``clutter_block_spokes x clutter_block_samples`` cells and each block's maximum is taken. The
    local clutter level of a block is the ``clutter_quantile`` of the block maxima (in dB) over an
    annulus of ``clutter_window_blocks`` (azimuth, range) minus ``clutter_guard_blocks`` about it,
    circular in azimuth and cut at the ends of the range scale (a spatial clutter map, after
    Nitzberg's scan-to-scan one). The guard keeps a target's own blocks out; other targets fill a
    few blocks of the annulus, under the quantile. The seed threshold is that level plus
    ``clutter_margin_db``, at least ``min_seed_db``. Only blocks whose own maximum reaches
    ``min_seed_db`` are worked out (the others cannot hold a seed and get ``min_seed_db``).

    Parameters
    ----------
    integrated : (A, N) float
        Integrated power over the mean noise, rows ``group_spokes`` spokes apart.
    group_spokes : int
    config : RadarFrontEndConfig

    Returns
    -------
    (ceil(A / ba), ceil(N / bn)) float32
        Seed threshold per block, linear power over the mean noise; block (i, j) holds rows
        ``i ba .. (i + 1) ba - 1`` and samples ``j bn .. (j + 1) bn - 1``, with
        ``ba = max(1, clutter_block_spokes // group_spokes)``, ``bn = clutter_block_samples``.
    """
    block_db, _ = _block_max_db(integrated, group_spokes, config)
    seed_db = np.full(block_db.shape, config.min_seed_db, dtype=np.float32)
    bi, bj = np.nonzero(block_db >= config.min_seed_db)
    if bi.size:
        seed_db[bi, bj] = np.maximum(_clutter_level_db(block_db, bi, bj, config) + config.clutter_margin_db,
                                     config.min_seed_db)
    return (10.0 ** (seed_db / 10.0)).astype(np.float32)


def _block_max_db(integrated: np.ndarray, group_spokes: int, config: RadarFrontEndConfig) -> tuple[np.ndarray, int]:
    """(sb, nb) float32 block maxima of the integrated power in dB, and rows per block ``ba``."""
    ba = max(1, config.clutter_block_spokes // group_spokes)
    bn = config.clutter_block_samples
    a, n = integrated.shape
    sb, nb = -(-a // ba), -(-n // bn)
    padded = np.asarray(integrated, dtype=np.float32)
    if (sb * ba, nb * bn) != (a, n):
        padded = np.ones((sb * ba, nb * bn), dtype=np.float32)
        padded[:a, :n] = integrated
    rows = padded.reshape(sb, ba, nb * bn)
    rows_max = rows[:, 0].copy()
    for i in range(1, ba):  # element-wise maxima over the block's rows and then its samples: no short reduced axis
        np.maximum(rows_max, rows[:, i], out=rows_max)
    samples = rows_max.reshape(sb, nb, bn)
    block_max = samples[:, :, 0].copy()
    for j in range(1, bn):
        np.maximum(block_max, samples[:, :, j], out=block_max)
    return 10.0 * np.log10(np.maximum(block_max, np.float32(BLOCK_POWER_FLOOR))), ba


def _clutter_level_db(block_db: np.ndarray, bi: np.ndarray, bj: np.ndarray, config: RadarFrontEndConfig,
                      excluded: np.ndarray | None = None) -> np.ndarray:
    """(K,) float32 clutter level (dB) of blocks (bi, bj): the quantile of their annulus's block maxima.

    The annulus is read from the block maxima padded by half a window: circular in azimuth, -inf
    beyond the ends of the range scale (one gather of K x annulus values). Blocks marked in
    ``excluded`` ((sb, nb) bool, the chart's land: :mod:`tdm.frontend.radar_land`) count as outside
    the annulus too; a block whose annulus is all excluded gets the thermal noise mean, 0 dB.
    """
    sb, nb = block_db.shape
    half_a, half_r = config.clutter_window_blocks[0] // 2, config.clutter_window_blocks[1] // 2
    da, dr = _annulus_offsets(tuple(config.clutter_window_blocks), tuple(config.clutter_guard_blocks))
    width = nb + 2 * half_r
    padded = np.full((sb + 2 * half_a, width), -np.inf, dtype=block_db.dtype)
    rows = np.arange(-half_a, sb + half_a) % sb
    padded[:, half_r:half_r + nb] = block_db[rows] if excluded is None else np.where(excluded[rows], -np.inf,
                                                                                      block_db[rows])
    values = padded.reshape(-1)[(bi * width + bj)[:, None] + ((da + half_a) * width + dr + half_r)[None, :]]
    if excluded is None:
        n_valid = _annulus_columns_in_range(nb, tuple(config.clutter_window_blocks),
                                            tuple(config.clutter_guard_blocks))[bj]
        return _ranked_quantile_db(values, n_valid, config)
    n_valid = np.count_nonzero(np.isfinite(values), axis=1)
    q_db = _ranked_quantile_db(values, n_valid, config)
    q_db[n_valid == 0] = 0.0  # an annulus all land: the thermal noise mean
    return q_db


def _ranked_quantile_db(values: np.ndarray, n_valid: np.ndarray, config: RadarFrontEndConfig) -> np.ndarray:
    """(K,) float32: per row of ``values`` (K, W) dB, the ``clutter_quantile`` of its ``n_valid`` (K,) valid values,
    the others -inf: rank ceil(q n) among them (-inf sort first). A row with none gets its largest value."""
    width = values.shape[1]
    rank = np.minimum(width - n_valid + np.maximum(np.ceil(config.clutter_quantile * n_valid).astype(np.int64), 1) - 1,
                      width - 1)
    q_db = np.empty(values.shape[0], dtype=np.float32)
    full = n_valid == width
    if full.any():  # one rank for all blocks with a whole annulus: partition
        k = int(rank[full][0])
        q_db[full] = np.partition(values[full], k, axis=1)[:, k]
    if (~full).any():
        part = np.sort(values[~full], axis=1)
        q_db[~full] = part[np.arange(part.shape[0]), rank[~full]]
    return q_db


@lru_cache(maxsize=8)
def _annulus_columns_in_range(nb: int, window: tuple[int, int], guard: tuple[int, int]) -> np.ndarray:
    """(nb,) int64: how many of the annulus's blocks lie inside the range scale, per block column."""
    _, dr = _annulus_offsets(window, guard)
    col = np.arange(nb)[:, None] + dr[None, :]
    return np.count_nonzero((col >= 0) & (col < nb), axis=1).astype(np.int64)


def cell_window_power(integrated: np.ndarray, spoke: np.ndarray, sample: np.ndarray,
                      g: int) -> tuple[np.ndarray, np.ndarray]:
    """The beam-integrated power of cells: a cell of spoke group k lies in integration windows k - 1 (circular)
    and k and takes the larger.

    Parameters
    ----------
    integrated : (A, N) float32
        :func:`beam_integrated_power` of the sweep.
    spoke, sample : (M,) int
        The cells.
    g : int
        Spokes per integration group.

    Returns
    -------
    value : (M,) float32
        The larger window's power, units of the mean noise.
    row : (M,) int64
        That window's row of ``integrated``.
    """
    a, n_samples = integrated.shape
    k = spoke // g
    here_at = k * n_samples + sample
    before_at = here_at - n_samples  # window k - 1, circular
    before_at[k == 0] += a * n_samples
    before, here = integrated.reshape(-1)[before_at], integrated.reshape(-1)[here_at]
    return np.maximum(before, here), np.where(before > here, (k - 1) % a, k)


def _margin_over_clutter_db(lab: np.ndarray, spoke: np.ndarray, sample: np.ndarray, n_labels: int,
                            eligible: np.ndarray, integrated: np.ndarray, g: int,
                            config: RadarFrontEndConfig, land: LandBlocks | None = None) -> np.ndarray:
    """(n_labels,) float32: each eligible plot's peak beam-integrated power over its clutter level, dB
    (-inf for the others and for plots with no cell above the lowest seed threshold).

    A cell of spoke group k lies in integration windows k - 1 and k and takes the larger; a plot's
    peak is its largest, and the clutter level is worked out for the peak's block only
    (:func:`clutter_map` gives the same threshold for every block). ``land``, when given, says which
    blocks are the chart's land: a plot whose peak block lies clear of it (``land_clear_beam_fraction``)
    is measured against the clutter of the annulus without the land's blocks (``land_beam_fraction``;
    :mod:`tdm.frontend.radar_land`).
    """
    margin_db = np.full(n_labels, -np.inf, dtype=np.float32)
    cells = np.flatnonzero(eligible[lab])
    value, row = cell_window_power(integrated, spoke[cells], sample[cells], g)
    # only cells above the lowest seed threshold can be a kept plot's peak
    seed = np.flatnonzero(value >= np.float32(10.0 ** (config.min_seed_db / 10.0)))
    if seed.size == 0:
        return margin_db
    cells, value, row = cells[seed], value[seed], row[seed]
    lab_c = lab[cells]
    peak = np.full(n_labels, -np.inf, dtype=np.float32)
    np.maximum.at(peak, lab_c, value)
    at_peak = np.flatnonzero(value == peak[lab_c])
    labels, first = np.unique(lab_c[at_peak], return_index=True)
    peak_cell = at_peak[first]
    peak_db = 10.0 * np.log10(peak[labels])
    block_db, ba = _block_max_db(integrated, g, config)
    block = (row[peak_cell] // ba) * block_db.shape[1] + sample[cells[peak_cell]] // config.clutter_block_samples
    block, plot_block = np.unique(block, return_inverse=True)  # plots sharing a block share its level
    bi, bj = np.divmod(block, block_db.shape[1])
    clear = np.zeros(bi.size, dtype=bool)  # peak blocks clear of the land: their level without the land's blocks
    if land is not None:
        peaks = np.zeros(block_db.shape, dtype=bool)
        peaks[bi, bj] = True
        clear = ~land(peaks, ba * g, config.clutter_block_samples, config.land_clear_beam_fraction)[bi, bj]
    level_db = np.empty(bi.size, dtype=np.float32)
    level_db[~clear] = _clutter_level_db(block_db, bi[~clear], bj[~clear], config)
    if clear.any():
        excluded = land(block_db >= config.min_seed_db, ba * g, config.clutter_block_samples, config.land_beam_fraction)
        level_db[clear] = _clutter_level_db(block_db, bi[clear], bj[clear], config, excluded)
    margin_db[labels] = peak_db - level_db[plot_block]
    return margin_db
