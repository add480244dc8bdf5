"""tdm.tracker_config.hit_weight: what a detection counts towards confirmation, the weak limit rising with a radar
plot's size in resolution cells."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from tdm.tracker_config import STRONG_HIT, TrackerConfig, hit_weight
from tests.tdm.test_tracker import scan

RISING = TrackerConfig(weak_below_db=13.0, strong_from_db=15.0, weak_hit=0.5, weak_rise_db_per_doubling=1.0,
                       weak_rise_from_cells=5.0, min_beam_fill=0.5)


def _plot(strength_db: float, resolution_cells: float | None, beam_fill: float = 1.0):
    d = scan(0.0, [[600.0, 0.0]])
    d.strength_db, d.beam_fill = np.array([strength_db]), np.array([beam_fill])
    d.resolution_cells = None if resolution_cells is None else np.array([resolution_cells])
    return d


@pytest.mark.parametrize("cells, limit_db", [(2.0, 13.0), (5.0, 13.0), (10.0, 14.0), (20.0, 15.0), (40.0, 16.0)])
def test_the_weak_limit_rises_one_db_for_every_doubling_of_the_cells_beyond_five(cells, limit_db):
    # just under the limit counts weak (up to the strong limit, which stays at 15 dB), just over it counts 1 (under the
    # strong limit) or STRONG_HIT (from it)
    assert hit_weight(RISING, _plot(min(limit_db, 15.0) - 0.01, cells), 0) == 0.5
    over = hit_weight(RISING, _plot(limit_db + 0.01, cells), 0)
    assert over == (1.0 if limit_db + 0.01 < 15.0 else STRONG_HIT)


def test_the_strong_limit_does_not_rise_and_a_flat_configuration_ignores_the_size():
    assert hit_weight(RISING, _plot(15.0, 1000.0), 0) == STRONG_HIT
    flat = TrackerConfig(weak_below_db=13.0, strong_from_db=15.0)
    assert hit_weight(flat, _plot(14.0, 1000.0), 0) == 1.0
    assert hit_weight(RISING, _plot(14.0, None), 0) == 1.0  # no size known: the flat limit
    assert hit_weight(RISING, _plot(25.0, 1.0, beam_fill=0.2), 0) == 0.5  # narrower than the beam: weak, however strong
    lidar = scan(0.0, [[10.0, 0.0]])
    assert hit_weight(RISING, lidar, 0) == 1.0


def test_a_wide_weak_clutter_patch_does_not_confirm_where_a_small_plot_as_strong_does():
    from tdm.tracker import PositionTracker

    def confirmed_after(resolution_cells, config, scans=4):
        tracker = PositionTracker("radar", replace(config, confirm_m=3, confirm_n=4, coast_s=10.0, position_floor_m2=0.0,
                                                   max_range_m=1e4))
        for k in range(scans):
            d = _plot(14.0, resolution_cells)
            d.time_s = np.array([2.5 * k])
            tracker.process(d, np.zeros(2))
        return bool(tracker.confirmed_tracks())

    # 14 dB over the clutter: a hit of 1 from a plot of 4 cells; from one of 16 cells (limit 13 + log2(16/5) = 14.7
    # dB) half a hit, and 4 x 0.5 never reaches 3
    assert 13.0 + math.log2(16.0 / 5.0) > 14.0
    assert confirmed_after(4.0, RISING, scans=3)
    assert not confirmed_after(16.0, RISING)
    assert confirmed_after(16.0, TrackerConfig(weak_below_db=13.0, strong_from_db=15.0), scans=3)
