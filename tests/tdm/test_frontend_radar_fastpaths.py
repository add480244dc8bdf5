"""tdm.frontend.radar's fast paths (byte-parallel CFAR counts, word-wise scans, block-wise plots, the padded clutter
map, run labels) against straightforward references on random video."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import ndimage

from tdm.frontend import radar, radar_cfar, radar_clutter, radar_plots
from tdm.frontend.radar import (RadarFrontEndConfig, _filled_between_detections, _label_runs,
                                _numbered_by_first, _run_cells, _spokes_per_label, beam_integrated_power, cfar_mask,
                                fill_gaps, video_power)

from tdm.frontend.radar_plots import label_max_min

from .test_frontend_radar import RANGE_M, SAMPLES


def random_video(rng: np.random.Generator, shape: tuple[int, int], p_zero: float) -> np.ndarray:
    """(S, N) uint8 video levels: 0 with probability ``p_zero``, else uniform over 1..15."""
    return np.where(rng.random(shape) < p_zero, 0, rng.integers(1, 16, size=shape)).astype(np.uint8)


@pytest.mark.parametrize("bit_plane_fraction", [0.0, 0.05, math.inf])  # every level / common levels / none on planes
def test_byte_parallel_os_counts_equal_the_counts_of_the_gathered_training_cells(bit_plane_fraction, monkeypatch):
    monkeypatch.setattr(radar_cfar, "_BIT_PLANE_MIN_FRACTION", bit_plane_fraction)
    rng = np.random.default_rng(11)
    for trial in range(60):
        n_training, guard = int(rng.choice([2, 4, 10, 16, 22, 32, 48, 66])), int(rng.integers(0, 7))
        n_samples = int(rng.integers(n_training + 2 * guard + 3, 180))
        config = RadarFrontEndConfig(training_cells=n_training, guard_cells=guard,
                                     os_rank=int(rng.integers(1, n_training + 1)))
        echo = random_video(rng, (int(rng.integers(1, 7)), n_samples), float(rng.choice([0.3, 0.9])))
        if trial % 3 == 1:
            echo = echo[:, 1:]  # not C-contiguous, nor a whole number of words: the copied words
        first = int(rng.integers(0, 3))
        rows, cols = np.nonzero(np.broadcast_to(np.arange(echo.shape[1]) >= first, echo.shape))
        train = radar_cfar._training_values(echo, rows, cols, config, first)
        blocking = radar_cfar._os_blocking_level(config.alpha, config.video_threshold_db, config.video_step_db)
        expected = np.count_nonzero(train >= blocking[echo[rows, cols]][:, None], axis=1) < n_training - config.rank + 1
        assert np.array_equal(radar_cfar._cfar_cells(echo, rows, cols, config, first), expected), trial


def test_nonzero_cells_through_words_equal_flatnonzero():
    rng = np.random.default_rng(12)
    for shape, p_zero in (((64, 128), 0.99), ((64, 128), 0.3), ((7, 13), 0.9), ((1, 1), 0.0), ((3, 8), 1.0)):
        echo = random_video(rng, shape, p_zero)
        for levels in (echo, echo[:, 1:], echo[::2]):
            assert np.array_equal(radar_cfar._nonzero_flat(levels), np.flatnonzero(levels))


def test_gap_filling_between_neighbouring_detections_equals_filling_each_run():
    rng = np.random.default_rng(13)
    for trial in range(40):
        n_samples = int(rng.integers(1, 40))
        flat = np.flatnonzero(rng.random((int(rng.integers(1, 9)), n_samples)) < rng.choice([0.3, 0.8, 1.0]))
        detected = rng.random(flat.size) < rng.choice([0.05, 0.3, 0.7])
        expected = detected | radar_plots._fill_runs(flat, n_samples, detected)
        assert np.array_equal(detected | _filled_between_detections(flat, detected, n_samples), expected), trial


def test_beam_integration_of_the_cells_above_the_floor_equals_the_sum_over_spokes(monkeypatch):
    monkeypatch.setattr(radar_clutter, "_WINDOW_PART_CELLS", 3 * 64)  # windows worked out 3 rows at a time
    rng = np.random.default_rng(14)
    config = RadarFrontEndConfig()
    for n_spokes in (2048, 96, 8, 1):
        power = video_power(random_video(rng, (n_spokes, 64), 0.9), config).astype(np.float64)
        integrated, g = beam_integrated_power(power, config)
        groups = power.reshape(n_spokes // g, g, 64).sum(axis=1) - g  # group sums of the excess over the floor
        expected = ((groups + np.roll(groups, -1, axis=0)) * (0.5 / g) + 1.0).astype(np.float32)
        assert np.array_equal(integrated, expected)


@pytest.mark.parametrize("block_cells", [1, 3 * 8 * SAMPLES, 1 << 30])  # 1 integration group, 3, the sweep
def test_plot_cells_by_blocks_of_spokes_equal_cfar_gap_filling_and_integration_of_the_sweep(block_cells, monkeypatch):
    monkeypatch.setattr(radar, "_BLOCK_CELLS", block_cells)
    rng = np.random.default_rng(17)
    config = RadarFrontEndConfig()
    for n_spokes in (96, 10):
        echo = random_video(rng, (n_spokes, SAMPLES), 0.95)
        echo[:, 600:640] = rng.integers(3, 8, size=(n_spokes, 40))  # extended echoes: runs to fill
        flat, integrated, g = radar._plot_cells(echo, RANGE_M, config)
        first = int(np.searchsorted(RANGE_M, config.blanking_m))
        blanked = np.where(np.arange(SAMPLES) < first, 0, echo).astype(np.uint8)
        expected = fill_gaps(cfar_mask(blanked, config, RANGE_M), blanked, config.fill_level)
        assert np.array_equal(flat, np.flatnonzero(expected))
        expected_integrated, expected_g = beam_integrated_power(video_power(blanked, config).astype(np.float64), config)
        assert g == expected_g and np.array_equal(integrated, expected_integrated)


def reference_clutter_level_db(block_db: np.ndarray, bi: int, bj: int, config: RadarFrontEndConfig) -> float:
    """The clutter_quantile of the block maxima of one block's annulus (circular in azimuth, cut in range)."""
    (wa, wr), (ga, gr) = config.clutter_window_blocks, config.clutter_guard_blocks
    values = [block_db[(bi + da) % block_db.shape[0], bj + dr]
              for da in range(-(wa // 2), wa // 2 + 1) for dr in range(-(wr // 2), wr // 2 + 1)
              if not (abs(da) <= ga // 2 and abs(dr) <= gr // 2) and 0 <= bj + dr < block_db.shape[1]]
    return float(np.sort(values)[max(math.ceil(config.clutter_quantile * len(values)), 1) - 1])


def test_clutter_level_from_the_padded_block_maxima_equals_the_annulus_quantile():
    rng = np.random.default_rng(15)
    for window, guard, shape in (((65, 5), (5, 3), (16, 128)), ((5, 7), (1, 3), (3, 4)), ((3, 1), (1, 1), (40, 2))):
        config = RadarFrontEndConfig(clutter_window_blocks=window, clutter_guard_blocks=guard, clutter_quantile=0.9)
        block_db = rng.normal(10.0, 5.0, shape).astype(np.float32)
        bi, bj = (a.ravel() for a in np.indices(shape))
        expected = [reference_clutter_level_db(block_db, i, j, config) for i, j in zip(bi, bj)]
        assert np.array_equal(radar_clutter._clutter_level_db(block_db, bi, bj, config), np.float32(expected))


def reference_block_max_db(integrated: np.ndarray, ba: int, bn: int) -> np.ndarray:
    """Block maxima (dB) one block at a time; a block cut by the sweep's edge is padded with the floor (1)."""
    sb, nb = -(-integrated.shape[0] // ba), -(-integrated.shape[1] // bn)
    block_max = np.ones((sb, nb), dtype=np.float32)
    for i, j in np.ndindex(sb, nb):
        part = integrated[i * ba:(i + 1) * ba, j * bn:(j + 1) * bn]
        block_max[i, j] = part.max() if part.shape == (ba, bn) else max(part.max(), np.float32(1.0))
    return 10.0 * np.log10(np.maximum(block_max, np.float32(radar_clutter.BLOCK_POWER_FLOOR)))


def test_margin_over_clutter_equals_each_plots_peak_over_its_blocks_clutter_level():
    rng = np.random.default_rng(18)
    config = RadarFrontEndConfig(clutter_window_blocks=(7, 3), clutter_guard_blocks=(3, 1))
    for n_spokes, n_samples, g in ((64, 60, 4), (48, 64, 8)):
        integrated = (1.0 + rng.exponential(3.0, (n_spokes // g, n_samples))).astype(np.float32)
        integrated[rng.random(integrated.shape) < 0.2] = 30.0  # ties: the first cell at the peak decides its block
        spoke, sample = (a.ravel() for a in np.indices((n_spokes, n_samples)))
        lab, eligible = rng.integers(1, 40, spoke.size), rng.random(40) < 0.7
        margin = radar_clutter._margin_over_clutter_db(lab, spoke, sample, 40, eligible, integrated, g, config)
        (ba, bn), a = (max(1, config.clutter_block_spokes // g), config.clutter_block_samples), integrated.shape[0]
        block_db = reference_block_max_db(integrated, ba, bn)
        assert np.array_equal(radar_clutter._block_max_db(integrated, g, config)[0], block_db)
        before, here = integrated[(spoke // g - 1) % a, sample], integrated[spoke // g, sample]
        value = np.where(np.maximum(before, here) >= np.float32(10.0), np.maximum(before, here), -np.inf)
        for label in range(40):
            cells = np.flatnonzero(lab == label)
            if not eligible[label] or cells.size == 0 or not np.isfinite(value[cells]).any():
                assert margin[label] == -np.inf
                continue
            peak = cells[np.argmax(value[cells])]  # the first of the cells at the peak
            row = (spoke[peak] // g - 1) % a if before[peak] > here[peak] else spoke[peak] // g
            level = reference_clutter_level_db(block_db, row // ba, sample[peak] // bn, config)
            assert margin[label] == (10.0 * np.log10(value[[peak]].astype(np.float32)) - np.float32(level))[0], label


def test_runs_labels_spokes_and_per_label_extremes_equal_the_cell_labels_and_ndimage():
    numbered = [_numbered_by_first(np.array(c)).tolist() for c in ([2, 2, 0, 1, 0, 2], [0, 1, 0, 2, 1])]
    assert numbered == [[0, 0, 1, 2, 1, 0], [0, 1, 0, 2, 1]]  # renumbered in the order of first appearance; already so
    rng = np.random.default_rng(16)
    for trial in range(30):
        shape = (int(rng.integers(1, 12)), int(rng.integers(1, 20)))
        flat = np.flatnonzero(rng.random(shape) < rng.choice([0.2, 0.5, 0.9]))
        if flat.size == 0:
            continue
        runs = _label_runs(flat, *shape)
        pos, lab, spoke = _run_cells(runs, np.arange(runs.start.size))
        expected, n = radar_plots._label_cells(flat, *shape)
        assert np.array_equal(pos, np.arange(flat.size)) and np.array_equal(spoke, flat // shape[1])
        assert np.array_equal(lab, expected) and runs.n == n, trial
        assert np.array_equal(_spokes_per_label(runs.label, runs.spoke, n + 1, shape[0]),
                              radar_plots._spokes_per_label(lab, spoke, n + 1, shape[0]))
        for values in (rng.normal(size=flat.size), flat % shape[1]):
            largest, smallest = label_max_min(values, lab - 1, n)
            assert np.array_equal(largest, ndimage.maximum(values, lab - 1, np.arange(n)))
            assert np.array_equal(smallest, ndimage.minimum(values, lab - 1, np.arange(n)))
