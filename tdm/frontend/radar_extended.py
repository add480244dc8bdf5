"""Radar detections of extended echoes: the cells a range CFAR cannot pass inside a long echo
(module docstring of :mod:`tdm.frontend.radar`, step 3b).

An ordered-statistic CFAR along range (:mod:`tdm.frontend.radar_cfar`) takes its threshold from the
``3 N / 4``-th of its ``N`` training cells. An echo longer in range than about ``G + N / 4`` samples
(the guard plus a quarter of the window: 11 m at 0.9 m samples, 22 m at 1.8 m) fills that many training
cells of its own cells under test and masks itself: only its sharp edges pass, and where its edges
rise over a few samples (the range point-spread) not even those. Gap filling (step 3) joins two
detections of one spoke but cannot start where a spoke has none. A 120 m tanker seen 57 deg off
its beam at 480 m paints 20 deg x 70 m of video, saturated over half of it, and gave two plots on its
two ends and none between (harbour_approach, seed 32), so neither plot lay within 50 m of its centre.

The clutter map of step 5 (:func:`tdm.frontend.radar_clutter.clutter_map`: a quantile of block maxima
over a wide annulus, which a few targets do not raise) is the two-dimensional CFAR that such an echo
does not mask. Every cell above level 0 whose beam-integrated power reaches its block's seed threshold
(the clutter level plus ``clutter_margin_db``) is a detection too: the interior of an extended echo
joins its edges in one plot. The threshold is the one a plot's peak must reach to be kept, so this
adds no plot that step 5 would keep and that was not there as a weaker one; it makes plots whole.
"""

from __future__ import annotations

import numpy as np

from tdm.frontend.radar_cfar import _first_valid_sample, _nonzero_flat
from tdm.frontend.radar_clutter import clutter_map
from tdm.frontend.radar_config import RadarFrontEndConfig

__all__ = ["clutter_map_cells"]


def clutter_map_cells(echo: np.ndarray, range_m: np.ndarray, integrated: np.ndarray, g: int,
                      config: RadarFrontEndConfig) -> np.ndarray:
    """Cells above level 0 whose beam-integrated power reaches their block's clutter-map seed threshold.

    Parameters
    ----------
    echo : (S, N) uint8
        Video levels of the sweep.
    range_m : (N,) float
        Range of each sample, m (cells within ``blanking_m`` are left out, as the CFAR leaves them).
    integrated : (S / g, N) float32
        :func:`tdm.frontend.radar_clutter.beam_integrated_power` of the sweep.
    g : int
        Spokes per integration group.
    config : RadarFrontEndConfig

    Returns
    -------
    (M,) int64
        Ascending flat indices into ``echo``. A cell's power is that of the larger of its two integration
        windows (:func:`tdm.frontend.radar_clutter.cell_window_power`), as a plot's peak's is (step 5), and its
        threshold that of the larger window's block. Worked out once per window row and sample (every spoke of
        a group shares its windows), then read for the non-zero cells.
    """
    n_spokes, n_samples = echo.shape
    passes = _window_passes(integrated, g, config)
    first = _first_valid_sample(range_m, config.blanking_m)
    passes[:, :first] = False
    if not passes.any():
        return np.zeros(0, dtype=np.int64)
    flat = _nonzero_flat(echo)
    spoke, sample = np.divmod(flat, n_samples)
    return flat[passes.reshape(-1)[(spoke // g) * n_samples + sample]]


def _window_passes(integrated: np.ndarray, g: int, config: RadarFrontEndConfig) -> np.ndarray:
    """(A, N) bool: per integration row k and sample, whether a cell there reaches its seed threshold: the larger of
    windows k - 1 (circular) and k (window k on a tie) at least ``min_seed_db`` and the clutter map's threshold of
    that window's block (:func:`tdm.frontend.radar_clutter.clutter_map`)."""
    a, n_samples = integrated.shape
    ba = max(1, config.clutter_block_spokes // g)
    seed = clutter_map(integrated, g, config)
    threshold = np.repeat(np.repeat(seed, ba, axis=0)[:a], config.clutter_block_samples, axis=1)[:, :n_samples]
    before = np.roll(integrated, 1, axis=0)
    use_before = before > integrated
    value = np.where(use_before, before, integrated)
    passes = value >= np.where(use_before, np.roll(threshold, 1, axis=0), threshold)
    passes &= value >= np.float32(10.0 ** (config.min_seed_db / 10.0))
    return passes
