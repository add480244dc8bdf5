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
from tdm.frontend.radar_clutter import cell_window_power, clutter_map
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
        windows (:func:`tdm.frontend.radar_clutter.cell_window_power`), as a plot's peak's is (step 5).
    """
    n_samples = echo.shape[1]
    flat = _nonzero_flat(echo)
    first = _first_valid_sample(range_m, config.blanking_m)
    if first > 0:
        flat = flat[flat % n_samples >= first]
    if flat.size == 0:
        return flat
    spoke, sample = np.divmod(flat, n_samples)
    value, row = cell_window_power(integrated, spoke, sample, g)
    candidate = np.flatnonzero(value >= np.float32(10.0 ** (config.min_seed_db / 10.0)))
    if candidate.size == 0:
        return flat[:0]
    seed = clutter_map(integrated, g, config)
    ba = max(1, config.clutter_block_spokes // g)
    threshold = seed[row[candidate] // ba, sample[candidate] // config.clutter_block_samples]
    return flat[candidate[value[candidate] >= threshold]]
