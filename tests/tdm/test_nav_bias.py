"""The own ship's navigation bias in the reported covariances (tdm.nav_bias, consider_nav_bias)."""

import math

import numpy as np
import pytest
import yaml

from tdm.errors import RecordingError
from tdm.fusion import Fuser, FusionConfig
from tdm.fusion_face import sensor_report
from tdm.fusion_rules import consider_covariance
from tdm.nav_bias import nav_bias_covariance
from tdm.run_config import TdmConfig
from tdm.tracker import Track


def track(track_id: int, sensor: str, east_m: float, north_m: float, var_m2: float = 4.0, mmsi=None) -> Track:
    x = np.array([east_m, north_m, 0.0, 0.0, 0.0, 50.0])
    return Track(track_id, sensor, x, np.diag([var_m2, var_m2, 1.0, 0.25, 1e-4, 100.0]), 0.0, 0.0, 0.0,
                 confirmed=True, mmsi=mmsi, length_m=10.0)


def test_the_position_bias_is_per_axis_and_the_heading_bias_turns_the_object_across_the_line_of_sight():
    """An object 300 m east: 0.5 m per axis, and 300 m x 0.1 deg = 0.52 m north (across the sight line) only;
    without an own position, the position bias alone."""
    cov = nav_bias_covariance(np.array([[300.0, 0.0], [0.0, -200.0]]), np.zeros(2), 0.5, 0.1)
    turn = math.radians(0.1)
    assert cov[0] == pytest.approx(np.diag([0.25, 0.25 + (300.0 * turn) ** 2]))
    assert cov[1] == pytest.approx(np.diag([0.25 + (200.0 * turn) ** 2, 0.25]))
    assert nav_bias_covariance(np.array([300.0, 0.0]), None, 0.5, 0.1) == pytest.approx(0.25 * np.eye(2))
    assert nav_bias_covariance(np.array([300.0, 0.0]), np.array([np.nan, 0.0]), 0.5, 0.1) == pytest.approx(
        0.25 * np.eye(2))


def test_a_bias_shared_by_every_estimate_passes_through_the_fusion_whole():
    """Two estimates of one object: a bias both carry is not averaged down (S = W_1 + W_2 = I on the position);
    one that only the first carries enters with its weight (1/2 here: equal covariances)."""
    p = np.diag([4.0, 4.0, 0.01, 0.25, 1e-4, 100.0])
    xs = np.array([[0.0, 0.0, 0.1, 5.0, 0.0, 10.0], [1.0, 2.0, 0.1, 5.0, 0.0, 10.0]])
    c = np.array([[1.0, 0.3], [0.3, 2.0]])
    both = consider_covariance(xs, np.array([p, p]), np.zeros(2), "simple", c, np.array([True, True]))
    assert both[:2, :2] == pytest.approx(c)
    first = consider_covariance(xs, np.array([p, p]), np.zeros(2), "simple", c, np.array([True, False]))
    assert first[:2, :2] == pytest.approx(0.25 * c)
    lone = consider_covariance(xs[:1], np.array([p]), np.zeros(1), "simple", c, np.array([False]))
    assert np.all(lone == 0.0)


def test_targets_and_sensor_tracks_measured_from_the_own_ship_carry_its_navigation_bias_and_ais_does_not():
    config = FusionConfig()
    own = np.zeros(2)
    radar, ais = track(1, "radar", 0.0, 400.0), track(2, "ais", 600.0, 0.0, mmsi=257000001)
    with_bias = Fuser(config).step(0.0, {"radar": [radar], "ais": [ais]}, own)
    without = Fuser(FusionConfig(consider_nav_bias=False)).step(0.0, {"radar": [radar], "ais": [ais]}, own)
    added = {e.target.target_id: a.p[:2, :2] - e.p[:2, :2] for a, e in zip(with_bias, without)}
    by_source = {tuple(e.sources): e.target.target_id for e in with_bias}
    expected = nav_bias_covariance(np.array([0.0, 400.0]), own, 0.5, 0.1)
    assert added[by_source[("radar",)]] == pytest.approx(expected)
    assert added[by_source[("ais",)]] == pytest.approx(np.zeros((2, 2)))
    lidar = track(3, "lidar", 0.0, 50.0)
    assert sensor_report("lidar", lidar, 0.0, own, config)[1][:2, :2] == pytest.approx(
        lidar.reported(0.0)[1][:2, :2] + nav_bias_covariance(np.array([0.0, 50.0]), own, 0.5, 0.1))
    assert sensor_report("ais", ais, 0.0, own, config)[1] == pytest.approx(ais.reported(0.0)[1])


def test_the_bias_is_the_recordings_and_a_bad_value_is_refused(tmp_path):
    """TdmConfig.for_recording takes sensors.nav.position_bias_m and heading_bias_deg from scenario.yaml, also into a
    fusion_config it is given."""
    (tmp_path / "scenario.yaml").write_text(yaml.safe_dump(
        {"sensors": {"nav": {"position_bias_m": 2.0, "heading_bias_deg": 0.5}}}))
    fusion = TdmConfig.for_recording(tmp_path).fusion_config
    assert (fusion.nav_position_bias_m, fusion.nav_heading_bias_deg) == (2.0, 0.5)
    given = TdmConfig.for_recording(tmp_path, fusion_config=FusionConfig(consider_radar_face=False)).fusion_config
    assert (given.nav_position_bias_m, given.consider_radar_face) == (2.0, False)
    (tmp_path / "scenario.yaml").write_text(yaml.safe_dump({"sensors": {"nav": {"enabled": False}}}))
    assert TdmConfig.for_recording(tmp_path).fusion_config.nav_position_bias_m == FusionConfig().nav_position_bias_m
    (tmp_path / "scenario.yaml").write_text(yaml.safe_dump({"sensors": {"nav": {"position_bias_m": -1.0}}}))
    with pytest.raises(RecordingError, match="sensors.nav.position_bias_m"):
        TdmConfig.for_recording(tmp_path)
    with pytest.raises(ValueError, match="nav_heading_bias_deg"):
        FusionConfig(nav_heading_bias_deg=float("nan"))
