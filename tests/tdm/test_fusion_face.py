"""A radar track's painted face and its object's centre behind it (tdm.fusion_face)."""

import numpy as np
import pytest

from tdm.fusion import FusionConfig
from tdm.fusion_face import face_report, hidden_depth_m, sight_covariance
from tdm.tracker import Track


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
