"""Where on a ship's hull a radar track may lie (tdm/hull.py) and how the fusion weighs it (FusionConfig.weigh_hull)."""

import math

import numpy as np
import pytest

from tdm import ekf
from tdm.fusion import Fuser, FusionConfig
from tdm.hull import BEAM_PER_LENGTH, hull_covariance
from tdm.tracker import Track


def _state(course_deg: float, speed_mps: float, speed_sigma_mps: float = 0.2) -> tuple[np.ndarray, np.ndarray]:
    x = np.array([0.0, 0.0, math.radians(course_deg), speed_mps, 0.0, 0.0])
    p = np.diag([4.0, 4.0, 0.01, speed_sigma_mps ** 2, 1e-4, 100.0])
    return x, p


@pytest.mark.parametrize("course_deg, along_axis", [(0.0, np.array([0.0, 1.0])), (90.0, np.array([1.0, 0.0])),
                                                     (45.0, np.array([1.0, 1.0]) / math.sqrt(2.0))])
def test_a_moving_ships_hull_spreads_l2_over_12_along_its_course_and_b2_over_12_across(course_deg, along_axis):
    """A 120 m x 18 m ship: variance 1200 m^2 along the course, 27 m^2 across it, whatever the course."""
    cov = hull_covariance(120.0, 18.0, *_state(course_deg, 5.0))
    across_axis = np.array([-along_axis[1], along_axis[0]])
    assert along_axis @ cov @ along_axis == pytest.approx(120.0 ** 2 / 12.0)
    assert across_axis @ cov @ across_axis == pytest.approx(18.0 ** 2 / 12.0)
    assert along_axis @ cov @ across_axis == pytest.approx(0.0, abs=1e-9)


def test_a_ship_whose_course_is_not_known_spreads_the_mean_both_ways():
    """Anchored (0 m/s) or slower than two standard deviations of its speed: (L^2 + B^2) / 24 on each axis."""
    for x, p in (_state(30.0, 0.0), _state(30.0, 0.3, speed_sigma_mps=0.2)):
        np.testing.assert_allclose(hull_covariance(120.0, 18.0, x, p), (120.0 ** 2 + 18.0 ** 2) / 24.0 * np.eye(2))


def test_a_beam_not_known_is_a_sixth_of_the_length():
    x, p = _state(0.0, 5.0)
    np.testing.assert_allclose(hull_covariance(60.0, math.nan, x, p), hull_covariance(60.0, 60.0 * BEAM_PER_LENGTH, x, p))


def _track(track_id, sensor, north_m, mmsi=None):
    x = np.array([0.0, north_m, 0.0, 5.0, 0.0, 50.0])  # north at 5 m/s
    p = np.diag([4.0, 4.0, 1e-3, 0.04, 1e-4, 100.0])
    return Track(track_id, sensor, x, p, 0.0, 0.0, 0.0, confirmed=True, mmsi=mmsi)


@pytest.mark.parametrize("weigh", [False, True])
def test_an_ais_ships_radar_track_weighs_with_where_on_the_hull_it_may_lie(weigh):
    """An AIS ship (100 m x 16 m, north at 5 m/s, var 4 m^2) and its radar track 3 m ahead (var 4 m^2): without the
    hull the fused north is their mean, 1.5 m; with it the radar's north variance is 4 + 100^2 / 12 and its east
    4 + 16^2 / 12, so the fused position stays by the AIS; the covariance says so too."""
    fuser = Fuser(FusionConfig(consider_nav_bias=False, weigh_hull=weigh))
    fuser.lengths_by_mmsi, fuser.beams_by_mmsi = {257000001: 100.0}, {257000001: 16.0}
    ais, radar = _track(1, "ais", 0.0, mmsi=257000001), _track(2, "radar", 3.0)
    (out,) = fuser.step(0.0, {"ais": [ais], "radar": [radar]})
    assert out.sources == ["ais", "radar"]
    north_var = 4.0 + (100.0 ** 2 / 12.0 if weigh else 0.0)
    east_var = 4.0 + (16.0 ** 2 / 12.0 if weigh else 0.0)
    assert out.x[1] == pytest.approx(3.0 / north_var / (1.0 / 4.0 + 1.0 / north_var))
    assert out.p[1, 1] == pytest.approx(1.0 / (1.0 / 4.0 + 1.0 / north_var))
    assert out.p[0, 0] == pytest.approx(1.0 / (1.0 / 4.0 + 1.0 / east_var))
    np.testing.assert_array_equal(radar.p, _track(2, "radar", 3.0).p)  # the track itself untouched


def test_without_ais_dimensions_or_without_ais_the_radar_weighs_as_its_filter_says():
    """No length known for the MMSI, or a LiDAR and a radar track of a ship without AIS: no hull term."""
    for tracks, lengths in (({"ais": [_track(1, "ais", 0.0, mmsi=257000001)], "radar": [_track(2, "radar", 3.0)]}, {}),
                            ({"lidar": [_track(1, "lidar", 0.0)], "radar": [_track(2, "radar", 3.0)]},
                             {257000001: 100.0})):
        fuser = Fuser(FusionConfig(consider_nav_bias=False))
        fuser.lengths_by_mmsi = lengths
        (out,) = fuser.step(0.0, tracks)
        assert out.x[1] == pytest.approx(1.5)
        assert out.p[1, 1] == pytest.approx(2.0)


def test_an_ais_ships_lidar_track_weighs_with_the_hull_less_the_part_it_sees():
    """The same ship and a LiDAR track 3 m ahead whose clusters span 60 m of its 100 m: the LiDAR lies at the middle
    of what it sees, so its north variance is 4 + (100 - 60)^2 / 12; one seeing the whole hull gets the beam's
    variance across only."""
    for seen_m, north_extra in ((60.0, 40.0 ** 2 / 12.0), (120.0, 0.0)):
        fuser = Fuser(FusionConfig(consider_nav_bias=False))
        fuser.lengths_by_mmsi, fuser.beams_by_mmsi = {257000001: 100.0}, {257000001: 16.0}
        ais, lidar = _track(1, "ais", 0.0, mmsi=257000001), _track(2, "lidar", 3.0)
        lidar.length_m = seen_m
        (out,) = fuser.step(0.0, {"ais": [ais], "lidar": [lidar]})
        north_var = 4.0 + north_extra
        assert out.sources == ["ais", "lidar"]
        assert out.p[1, 1] == pytest.approx(1.0 / (1.0 / 4.0 + 1.0 / north_var))
        assert out.p[0, 0] == pytest.approx(1.0 / (1.0 / 4.0 + 1.0 / (4.0 + 16.0 ** 2 / 12.0)))


def test_an_absorbed_lidar_track_moving_with_the_ais_ship_becomes_its_member_and_a_still_berg_beside_it_does_not():
    """crossing_silent_ship: a 60 m ferry's LiDAR track, 20 m off its AIS track across its course (outside the
    fusion's gate of the two filters' covariances), is absorbed by the ship's footprint, and an absorbed track is not
    fused. Once it is ``promote_after_s`` old, moves as the ship does and lies on the hull (the gate with the hull's
    variance), it becomes the target's LiDAR member. A berg's LiDAR track at the same place, known to be still,
    stays absorbed (busy_open_sea: a berg beside the 100 m research ship)."""
    for speed_mps, promoted in ((5.0, True), (0.0, False)):
        fuser = Fuser(FusionConfig())
        fuser.lengths_by_mmsi, fuser.beams_by_mmsi = {257000112: 60.0}, {257000112: 12.0}
        ais = _track(1, "ais", 0.0, mmsi=257000112)
        lidar = _track(2, "lidar", 0.0)
        lidar.x[:2] = [20.0, 5.0]  # where the ship's hull is at t = 1 s, 20 m east of its AIS track's line
        lidar.x[ekf.U], lidar.length_m = speed_mps, 15.0
        lidar.t_s = lidar.created_s = lidar.updated_s = 1.0
        fuser.step(0.0, {"ais": [ais], "lidar": []})  # the ship's target, from its AIS
        (first,) = fuser.step(1.0, {"ais": [ais], "lidar": [lidar]})
        assert first.sources == ["ais"] and ("lidar", 2) in first.target.absorbed
        assert fuser.config.promote_after_s == 10.0
        (early,) = fuser.step(10.0, {"ais": [ais], "lidar": [lidar]})
        assert early.sources == ["ais"]
        (later,) = fuser.step(11.0, {"ais": [ais], "lidar": [lidar]})
        assert (later.sources == ["ais", "lidar"]) == promoted
        assert (("lidar", 2) in later.target.absorbed) == (not promoted)
