"""A radar track's painted face and its object's centre behind it (tdm.fusion_face)."""

import numpy as np
import pytest

from tdm.fusion import Fuser, FusionConfig
from tdm.fusion_face import face_report, hidden_depth_m, sight_covariance
from tdm.tracker import Track

from .test_fusion import make_track


def radar_track(east_m: float, north_m: float, length_m: float = 12.0, core_width_m: float = float("nan")) -> Track:
    x = np.array([east_m, north_m, 0.0, 0.0, 0.0, 50.0])
    p = np.diag([4.0, 9.0, 1.0, 0.25, 1e-4, 100.0])
    track = Track(1, "radar", x, p, 0.0, 0.0, 0.0, confirmed=True, length_m=length_m, core_width_m=core_width_m,
                  extent_sigma_fraction=0.5)
    return track


def test_the_offset_lies_along_the_line_of_sight_with_the_depth_and_its_spread():
    """A 12 m track (no core width: the length rule) 300 m north-east: depth 0.6 x 12 m, sigma 0.25 x 12 m; the
    covariance is (depth^2 + sigma^2) u u^T with u the unit vector from the own ship, nothing across it."""
    config = FusionConfig()
    own = np.array([100.0, -50.0])
    track = radar_track(100.0 + 300.0 / np.sqrt(2.0), -50.0 + 300.0 / np.sqrt(2.0))
    depth, sigma = hidden_depth_m(track, 300.0, config)
    assert (depth, sigma) == pytest.approx((0.6 * 12.0, 0.25 * 12.0))
    cov = sight_covariance(track, track.x, own, config)
    u = np.array([1.0, 1.0]) / np.sqrt(2.0)
    assert cov == pytest.approx((depth ** 2 + sigma ** 2) * np.outer(u, u))
    across = np.array([-u[1], u[0]])
    assert across @ cov @ across == pytest.approx(0.0, abs=1e-9)
    assert np.all(sight_covariance(track, track.x, track.x[:2], config) == 0.0)  # on the own ship: no direction


@pytest.mark.parametrize("on", [True, False])
def test_a_radar_track_reports_its_face_offset_in_place_of_a_fraction_of_its_length(on):
    """In sensor_tracks.jsonl: with ``radar_track_face_covariance`` the predicted covariance plus the offset along the
    line of sight (east here); without it, Track.reported (0.5 x 12 m per axis)."""
    config = FusionConfig(radar_track_face_covariance=on)
    track = radar_track(500.0, 0.0, core_width_m=55.0)  # 55 m spans over half the 5.2 deg beam at 500 m
    x, p = face_report(track, 2.0, np.zeros(2), config)
    x_pred, p_pred = track.predicted(2.0)
    assert x == pytest.approx(x_pred)
    if on:
        depth, sigma = 0.5 * 55.0, 0.2 * 55.0
        assert p[:2, :2] == pytest.approx(p_pred[:2, :2] + np.diag([depth ** 2 + sigma ** 2, 0.0]))
    else:
        assert p[:2, :2] == pytest.approx(p_pred[:2, :2] + 36.0 * np.eye(2))
    assert p[2:, 2:] == pytest.approx(p_pred[2:, 2:])
    unknown_own = face_report(track, 2.0, None, config)[1]
    assert unknown_own == pytest.approx(track.reported(2.0)[1])


def test_a_radar_track_with_an_own_position_not_finite_reports_as_without_one():
    config = FusionConfig()
    track = radar_track(500.0, 0.0, core_width_m=55.0)
    x, p = face_report(track, 2.0, np.array([np.nan, 0.0]), config)
    assert p == pytest.approx(track.reported(2.0)[1]) and x == pytest.approx(track.reported(2.0)[0])


def test_a_radar_track_that_joins_a_still_target_during_the_step_is_widened_not_left_bare():
    """An iceberg seen by the LiDAR alone; a radar track 12 m long starts on it 300 m east and joins it in that step.
    ``behind_the_face`` ran before it joined, so it stays on its face: its offset, depth^2 + sigma^2 along the line
    of sight (east), is reported through its fusion weight (here 1/2: both tracks 4 m^2), and nothing across it.
    The next step it is moved, and only the depth's variance is carried."""
    config = FusionConfig(weigh_extent=False, consider_lidar_extent=False)
    fuser = Fuser(config)
    own = np.zeros(2)
    lidar = make_track(1, "lidar", 300.0, 0.0)
    (alone,) = fuser.step(0.0, {"lidar": [lidar]}, own)
    alone.target.descriptor = "iceberg"
    lidar = make_track(1, "lidar", 300.0, 0.0, t=1.0)  # updated at 1 s: both tracks 4 m^2 then
    radar = make_track(2, "radar", 300.0, 0.0, t=1.0)
    radar.length_m = 12.0
    (joined,) = fuser.step(1.0, {"lidar": [lidar], "radar": [radar]}, own)
    assert joined.sources == ["lidar", "radar"]
    bare = Fuser(FusionConfig(weigh_extent=False, consider_lidar_extent=False, consider_radar_face=False))
    (b,) = bare.step(0.0, {"lidar": [lidar]}, own)
    b.target.descriptor = "iceberg"
    (plain,) = bare.step(1.0, {"lidar": [lidar], "radar": [radar]}, own)
    depth = config.radar_hidden_depth_length_fraction * 12.0
    sigma = config.radar_hidden_depth_length_sigma_fraction * 12.0
    added = joined.p[:2, :2] - plain.p[:2, :2]
    assert added == pytest.approx(np.diag([0.25 * (depth ** 2 + sigma ** 2), 0.0]))


def test_a_radar_track_moved_behind_its_face_is_not_widened_again_in_a_vessels_target():
    """``face_covariance`` goes by what ``behind_the_face`` did, not by the target's class at the step's end: a track
    moved (its depth's variance already in its state) adds nothing even in a vessel's target; one not moved adds
    its offset even in an iceberg's; a target with AIS, or an unknown own position, adds nothing."""
    from tdm.fusion_target import FusedTarget
    from tdm.fusion_face import face_covariance, sight_covariance

    config = FusionConfig()
    radar = make_track(2, "radar", 300.0, 0.0)
    radar.length_m = 12.0
    own = np.zeros(2)
    full = sight_covariance(radar, radar.x, own, config)
    assert full[0, 0] > 0.0
    for descriptor in ("vessel", "iceberg", "unknown"):
        target = FusedTarget(1, created_s=0.0)
        target.descriptor, target.members = descriptor, {"radar": 2}
        assert np.all(face_covariance(target, True, radar.x, radar, own, config) == 0.0)
        assert face_covariance(target, False, radar.x, radar, own, config) == pytest.approx(full)
        assert np.all(face_covariance(target, False, radar.x, radar, None, config) == 0.0)
        target.members["ais"] = 5
        assert np.all(face_covariance(target, False, radar.x, radar, own, config) == 0.0)


def test_an_own_position_that_is_not_finite_counts_as_unknown():
    """A NaN own-ship position gives what None gives (``Fuser.step`` takes it for unknown): a second radar track 3 m
    from a radar target is absorbed, by its footprint alone, and no offset is reported. A guard: before 01ca88e
    this held by accident (a NaN resolution lost in ``max`` and in the merge), not by design."""
    config = FusionConfig()
    first = make_track(1, "radar", 300.0, 0.0)
    second = make_track(2, "radar", 303.0, 0.0, t=1.0)
    for t in (first, second):
        t.length_m = 12.0
    out = {}
    for name, own in (("nan", np.array([np.nan, 0.0])), ("none", None)):
        fuser = Fuser(config)
        fuser.step(0.0, {"radar": [first]}, own)
        out[name] = fuser.step(1.0, {"radar": [first, second]}, own)
    assert len(out["none"]) == len(out["nan"]) == 1
    assert out["nan"][0].x == pytest.approx(out["none"][0].x) and out["nan"][0].p == pytest.approx(out["none"][0].p)


def test_a_lidar_track_at_the_range_limit_reports_its_sigma_along_the_line_of_sight_only():
    """A LiDAR track cut by the range limit, 60 m east and 80 m north of the own ship (line of sight (0.6, 0.8)):
    sensor_tracks.jsonl's covariance grows by sigma^2 u u^T, nothing across; unflagged, nothing; the own ship
    unknown, sigma^2 per axis."""
    from tdm.fusion_face import range_cut_covariance, sensor_report

    config = FusionConfig(consider_nav_bias=False)
    track = make_track(1, "lidar", 60.0, 80.0)
    own = np.array([0.0, 0.0])
    _, plain = sensor_report("lidar", track, 0.0, own, config)
    track.range_cut, track.range_cut_sigma_m = True, 7.0
    x, cut = sensor_report("lidar", track, 0.0, own, config)
    u = np.array([0.6, 0.8])
    np.testing.assert_allclose(cut[:2, :2] - plain[:2, :2], 49.0 * np.outer(u, u), atol=1e-9)
    np.testing.assert_array_equal(cut[2:, 2:], plain[2:, 2:])
    assert x[:2] == pytest.approx([60.0, 80.0])
    w = np.array([-0.8, 0.6])
    assert w @ (cut[:2, :2] - plain[:2, :2]) @ w == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(range_cut_covariance(x[:2], None, 7.0), 49.0 * np.eye(2))
    np.testing.assert_allclose(range_cut_covariance(x[:2], np.array([np.nan, 0.0]), 7.0), 49.0 * np.eye(2))
    track.range_cut_sigma_m = 0.0
    np.testing.assert_array_equal(sensor_report("lidar", track, 0.0, own, config)[1], plain)
