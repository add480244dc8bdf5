"""tdm.frontend.radar_sidelobes: plots that are sidelobe echoes of a stronger plot at the same range."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tdm.detections import Detections
from tdm.frames import Mount, OwnshipTrack
from tdm.frontend.radar import radar_detections
from tdm.frontend.radar_config import RadarFrontEndConfig
from tdm.frontend.radar_sidelobes import drop_sidelobes, sidelobe_plots
from tests.conftest import BASE
from tests.tdm.test_frontend_radar import SPOKES, static_track, sweep_with

LAT0, LON0 = BASE["origin"]["lat"], BASE["origin"]["lon"]
RULE = dict(range_gate_m=10.0, min_offset_deg=5.2, max_offset_deg=60.0, margin_db=10.0)


def _plots_at(bearing_deg, range_m, strength_db):
    bearing = np.radians(np.asarray(bearing_deg, dtype=float))
    range_m = np.asarray(range_m, dtype=float)
    return np.stack([range_m * np.sin(bearing), range_m * np.cos(bearing)], axis=1), range_m, np.asarray(strength_db,
                                                                                                           float)


@pytest.mark.parametrize("bearing_deg, range_m, strength_db, dropped", [
    (15.0, 503.0, 20.0, True),    # 15 deg off, same range, 20 dB weaker: the ship's sidelobe
    (345.0, 497.0, 20.0, True),   # the other side, across north (offsets wrap)
    (15.0, 540.0, 20.0, False),   # 40 m further: another target
    (3.0, 500.0, 20.0, False),    # inside the main lobe: the ship's own echo
    (90.0, 500.0, 20.0, False),   # beyond the sidelobes
    (15.0, 500.0, 35.0, False),   # only 5 dB weaker
])
def test_only_a_much_weaker_plot_at_the_same_range_in_the_sidelobes_is_dropped(bearing_deg, range_m, strength_db,
                                                                               dropped):
    position, ranges, strength = _plots_at([0.0, bearing_deg], [500.0, range_m], [40.0, strength_db])
    drop = sidelobe_plots(position, np.zeros((2, 2)), ranges, strength, **RULE)
    assert drop.tolist() == [False, dropped]


def test_the_bearing_is_taken_from_the_antenna_and_the_sidelobe_of_a_sidelobe_needs_its_own_margin():
    position, range_m, strength = _plots_at([0, 20], [300, 300], [30, 15])
    sensor = np.array([[1000.0, -2000.0]] * 2)
    assert sidelobe_plots(position + sensor, sensor, range_m, strength, **RULE).tolist() == [False, True]
    # seen from elsewhere the two plots are not at one range: nothing dropped
    assert not sidelobe_plots(position + sensor, np.zeros((2, 2)), range_m, strength, **RULE).any()
    assert not sidelobe_plots(position[:1], np.zeros((1, 2)), range_m[:1], strength[:1], **RULE).any()


def _detections(position, range_m, strength) -> Detections:
    n = range_m.shape[0]
    z = np.zeros(n)
    return Detections("radar", 10.0, np.full(n, 10.0), position, np.tile(np.eye(2), (n, 1, 1)), z, z, z, z,
                      np.full(n, np.nan), np.full(n, 20, np.int64), range_m, strength, np.ones(n))


def test_drop_sidelobes_keeps_every_field_of_the_other_plots_and_can_be_turned_off():
    zero = np.zeros(2)
    track = OwnshipTrack({"t": np.array([0.0, 60.0]), "lat": np.full(2, LAT0), "lon": np.full(2, LON0), "z": zero,
                          "heading_deg": zero, "roll_deg": zero, "pitch_deg": zero, "cog_deg": zero, "sog_mps": zero})
    plots = _detections(*_plots_at([0, 15, 90], [500, 502, 500], [40, 20, 20]))
    kept = drop_sidelobes(plots, track, Mount(), RadarFrontEndConfig())
    assert len(kept) == 2 and kept.strength_db.tolist() == [40, 20] and kept.position_m.shape == (2, 2)
    assert kept.scan_time_s == plots.scan_time_s and kept.position_cov_m2.shape == (2, 2, 2)
    off = RadarFrontEndConfig(sidelobe_margin_db=None)
    assert drop_sidelobes(plots, track, Mount(), off) is plots


def test_the_front_end_drops_a_broken_arcs_plot_beside_a_strong_echo_and_keeps_a_weak_target_elsewhere():
    """Synthetic video: a saturating point echo at 000 deg, 543 m; a weak beam-shaped echo 15 deg off at
    the same range (a piece of its sidelobe arc that rose over the clutter); a target as weak at 90 deg."""
    spokes_per_deg = SPOKES / 360.0
    sweep = sweep_with(points=[(0, 300, 15), (round(15 * spokes_per_deg), 300, 6),
                               (round(90 * spokes_per_deg), 300, 6)])
    config = RadarFrontEndConfig()
    every = radar_detections(sweep, static_track(), Mount(z_m=4.0), dataclasses.replace(config,
                                                                                          sidelobe_margin_db=None))
    assert len(every) == 3
    kept = drop_sidelobes(every, static_track(), Mount(z_m=4.0), config)
    bearing = np.degrees(np.arctan2(kept.position_m[:, 0], kept.position_m[:, 1]))
    assert len(kept) == 2 and np.allclose(np.sort(bearing), [0.0, 90.0], atol=0.5)
