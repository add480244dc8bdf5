"""tdm.frontend.radar_land: the chart's land kept out of the radar clutter map's level."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tdm.frames import EnuFrame, Mount
from tdm.frontend import radar_clutter
from tdm.frontend.radar import RadarFrontEndConfig, radar_detections
from tdm.frontend.radar_land import land_blocks
from tdm.land import DETECTION_MARGIN_M, LandMask
from tdm.recording.land import ChartLand

from .test_frontend_radar import LAT0, LON0, RANGE_M, SPOKES, static_track, sweep_with
from .test_land import _polygons, land_geojson

#: A coast 60 deg wide (compass 60-120 deg) from 860 to 950 m: as a polar sector in ENU, m.
COAST_BEARINGS_DEG = np.arange(60.0, 120.1, 2.0)


def sector(r0_m: float, r1_m: float, bearings_deg: np.ndarray) -> list[tuple[float, float]]:
    """Corners (east, north) of the polar sector between two ranges over the bearings, m."""
    b = np.radians(bearings_deg)
    near = [(r0_m * np.sin(x), r0_m * np.cos(x)) for x in b]
    far = [(r1_m * np.sin(x), r1_m * np.cos(x)) for x in b[::-1]]
    return near + far


def chart(corners_xy_m) -> LandMask:
    frame = EnuFrame(LAT0, LON0)
    land = ChartLand(tuple(_polygons(land_geojson(corners_xy_m, frame))), Path("land.geojson"))
    return LandMask(land, frame, DETECTION_MARGIN_M)


def spoke_of(bearing_deg: float) -> int:
    return int(round(bearing_deg * SPOKES / 360.0)) % SPOKES


def sample_of(range_m: float) -> int:
    return int(np.argmin(np.abs(RANGE_M - range_m)))


def coast_and_boat_sweep() -> dict:
    """The coast's echo (level 13 on its sector) and a boat's clean point echo (peak level 7) at 900 m,
    compass 20 deg: the coast fills a third of the boat's clutter annulus (183 deg wide)."""
    first, last = spoke_of(60.0), spoke_of(120.0)
    s0, s1 = sample_of(860.0), sample_of(950.0)
    return sweep_with(blobs=[(first, last - first, s0, s1 - s0, 13)], points=[(spoke_of(20.0), sample_of(900.0), 7)])


def boat_plots(det) -> np.ndarray:
    boat_m = 900.0 * np.array([np.sin(np.radians(20.0)), np.cos(np.radians(20.0))])
    return np.flatnonzero(np.hypot(*(det.position_m - boat_m).T) < 15.0)


def test_a_boat_on_the_same_range_as_a_coast_is_plotted_once_the_coast_is_out_of_its_clutter_level():
    sweep, track, mount = coast_and_boat_sweep(), static_track(), Mount(z_m=4.0)
    coast = chart(sector(860.0, 950.0, COAST_BEARINGS_DEG))
    config = RadarFrontEndConfig()
    # without the chart, the coast's echo is the 0.9 quantile of the boat's annulus: 5 dB over the boat
    assert boat_plots(radar_detections(sweep, track, mount, config)).size == 0
    assert boat_plots(radar_detections(sweep, track, mount, RadarFrontEndConfig(clutter_map_without_land=False),
                                       coast)).size == 0  # the chart given, the rule off
    with_chart = radar_detections(sweep, track, mount, config, coast)
    found = boat_plots(with_chart)
    assert found.size == 1
    # its strength is now over the quiet sea's floor: 9.6 dB + 3 dB x 6.5 at its peak, less the beam
    # integration's fall over the window (a point echo, not a patch)
    assert 20.0 < with_chart.strength_db[found[0]] < 29.1


def test_land_far_out_of_the_annuli_changes_nothing():
    sweep, track, mount = sweep_with(points=[(spoke_of(20.0), sample_of(900.0), 7), (spoke_of(200.0), 300, 9)]), \
        static_track(), Mount(z_m=4.0)
    far_island = chart([(5000.0, 5000.0), (5100.0, 5000.0), (5100.0, 5100.0), (5000.0, 5100.0)])
    config = RadarFrontEndConfig()
    plain, charted = radar_detections(sweep, track, mount, config), radar_detections(sweep, track, mount, config,
                                                                                       far_island)
    assert len(plain) == 2
    for name in ("position_m", "position_cov_m2", "strength_db", "n_cells", "range_m"):
        assert np.array_equal(getattr(plain, name), getattr(charted, name)), name


def test_land_blocks_are_the_tested_blocks_within_the_beams_smear_of_the_land():
    sweep, track, mount = sweep_with(), static_track(), Mount(z_m=4.0)
    coast = chart(sector(860.0, 950.0, COAST_BEARINGS_DEG))
    spokes_per_block, samples_per_block = 16, 8
    sb, nb = SPOKES // spokes_per_block, -(-RANGE_M.size // samples_per_block)
    every = np.ones((sb, nb), dtype=bool)
    out = land_blocks(coast, every, spokes_per_block, samples_per_block, sweep["azimuth_deg"], sweep["heading_deg"],
                      sweep["time"], sweep["range_m"], track, mount, 0.5, 5.2)
    row = lambda bearing: spoke_of(bearing) // spokes_per_block  # noqa: E731
    col = lambda range_m: sample_of(range_m) // samples_per_block  # noqa: E731
    assert out[row(90.0), col(900.0)] and out[row(61.0), col(900.0)]
    # beyond the smear: half a beam (2.6 deg, 41 m at 900 m) plus half a block (1.4 deg) off its edge
    assert not out[row(50.0), col(900.0)] and not out[row(90.0), col(700.0)] and not out[row(270.0), col(900.0)]
    assert out[row(58.0), col(900.0)]  # 2 deg off the edge: within the smear
    some = np.zeros_like(every)
    some[row(90.0), col(900.0)] = True
    only = land_blocks(coast, some, spokes_per_block, samples_per_block, sweep["azimuth_deg"], sweep["heading_deg"],
                       sweep["time"], sweep["range_m"], track, mount, 0.5, 5.2)
    assert only.sum() == 1 and only[row(90.0), col(900.0)]  # untested blocks are not land


def test_the_clutter_level_without_excluded_blocks_is_the_quantile_of_the_others():
    config = RadarFrontEndConfig()
    rng = np.random.default_rng(5)
    block_db = rng.uniform(0.0, 30.0, (128, 16)).astype(np.float32)
    bi, bj = np.array([0, 40, 100, 127]), np.array([0, 7, 15, 3])
    none = np.zeros(block_db.shape, dtype=bool)
    assert np.array_equal(radar_clutter._clutter_level_db(block_db, bi, bj, config, none),
                          radar_clutter._clutter_level_db(block_db, bi, bj, config))
    # strong "land" on a third of the rows: with it the level is the land's, without it the sea's
    land = np.zeros(block_db.shape, dtype=bool)
    land[20:60] = True
    loud = np.where(land, np.float32(60.0), block_db)
    with_land = radar_clutter._clutter_level_db(loud, bi[1:2], bj[1:2], config)
    without = radar_clutter._clutter_level_db(loud, bi[1:2], bj[1:2], config, land)
    assert with_land[0] == 60.0 and without[0] < 30.0
    # the same as the quantile of the annulus's sea blocks, worked out directly
    half_a, half_r = config.clutter_window_blocks[0] // 2, config.clutter_window_blocks[1] // 2
    ga, gr = config.clutter_guard_blocks[0] // 2, config.clutter_guard_blocks[1] // 2
    values = [loud[a % 128, r] for a in range(40 - half_a, 40 + half_a + 1) for r in range(7 - half_r, 8 + half_r)
              if 0 <= r < 16 and not land[a % 128, r] and not (abs(a - 40) <= ga and abs(r - 7) <= gr)]
    values = np.sort(values)
    assert without[0] == values[int(np.ceil(config.clutter_quantile * values.size)) - 1]
    # an annulus all land: the thermal noise mean
    assert radar_clutter._clutter_level_db(loud, bi[1:2], bj[1:2], config, np.ones_like(land))[0] == 0.0
