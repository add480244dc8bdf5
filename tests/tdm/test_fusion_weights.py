"""tdm.fusion_weights: what the fusion's output weighs."""

import math

import numpy as np
import pytest

from tdm.fusion import Fuser, FusionConfig
from tdm.fusion_target import FusedTarget
from tdm.fusion_weights import face_turn_speed_sigma_mps, with_fragments

from .test_fusion import make_track


def _state(east, north, var=4.0):
    return np.array([east, north, 0.0, 0.0, 0.0, 50.0]), np.diag([var, var, 1.0, 0.25, 1e-4, 100.0])


def test_a_target_is_reported_at_the_mean_of_its_parts_with_their_scatter():
    """Three radar tracks on one 60 m object (its ends and its middle, the member on one end): the middle."""
    states = {("radar", 1): _state(-30.0, 0.0), ("radar", 2): _state(30.0, 0.0), ("radar", 3): _state(0.0, 3.0),
              ("lidar", 4): _state(-29.0, 0.0)}
    target = FusedTarget(1, members={"radar": 1, "lidar": 4}, absorbed={("radar", 2), ("radar", 3), ("lidar", 9)})
    out = with_fragments(states, [target])
    x, p = out[("radar", 1)]
    assert x[:2] == pytest.approx([0.0, 1.0])
    positions = np.array([[-30.0, 0.0], [30.0, 0.0], [0.0, 3.0]])
    assert p[:2, :2] == pytest.approx(4.0 * np.eye(2) + np.cov(positions.T, bias=True))
    assert out[("lidar", 4)] is states[("lidar", 4)] and states[("radar", 1)][0][0] == -30.0  # input untouched


def test_an_ais_ship_and_a_target_without_parts_are_left_as_they_are():
    states = {("radar", 1): _state(-30.0, 0.0), ("radar", 2): _state(30.0, 0.0), ("ais", 5): _state(0.0, 0.0)}
    ship = FusedTarget(1, members={"radar": 1, "ais": 5}, absorbed={("radar", 2)})
    alone = FusedTarget(2, members={"radar": 2})
    assert with_fragments(states, [ship, alone]) is states


def test_the_fuser_reports_a_fragmented_object_at_its_middle():
    fuser = Fuser(FusionConfig())
    bow = make_track(1, "radar", 0.0, 0.0, var=4.0)
    bow.length_m = 80.0  # absorbing radius 60 m
    fuser.step(1.0, {"radar": [bow]})
    stern = make_track(2, "radar", 40.0, 0.0, var=4.0)
    (out,) = fuser.step(2.0, {"radar": [bow, stern]})
    assert out.x[0] == pytest.approx(20.0)
    (plain,) = Fuser(FusionConfig(fragment_sensors=())).step(1.0, {"radar": [bow]})
    assert plain.x[0] == pytest.approx(0.0)


def test_a_seen_side_turns_with_the_line_of_sight():
    """Own ship at the origin going east at 5 m/s, a still berg 100 m north: the line of sight turns at 0.05 rad/s, so
    a side 10 m (one sd) off the berg's centre moves 0.5 m/s; a boat keeping station with the own ship: nothing."""
    x = np.array([[0.0, 100.0, 0.0, 0.0, 0.0, 50.0], [0.0, 100.0, math.pi / 2, 5.0, 0.0, 50.0]])
    sigma = face_turn_speed_sigma_mps(x, np.array([10.0, 10.0]), np.zeros(2), np.array([5.0, 0.0]))
    assert sigma == pytest.approx([0.5, 0.0], abs=1e-12)
    # twice the range: half the rate
    x[0, 1] = 200.0
    assert face_turn_speed_sigma_mps(x[:1], np.array([10.0]), np.zeros(2), np.array([5.0, 0.0]))[0] == \
        pytest.approx(0.25)


def test_the_fuser_weighs_a_lidar_tracks_velocity_with_its_side_turning():
    """A 40 m berg's LiDAR track (extent sd 0.15 x 40 = 6 m) 50 m north, the own ship passing east at 5 m/s
    (0.1 rad/s: 0.6 m/s more sd on the LiDAR's speed), with a radar track: the fused speed moves toward the
    radar's; without the own ship's velocity, or with the scale 0, it does not."""
    lidar = make_track(1, "lidar", 0.0, 50.0, var=1.0)
    lidar.x[3], lidar.p[3, 3] = 0.8, 0.3**2
    lidar.length_m, lidar.extent_sigma_fraction = 40.0, 0.15
    radar = make_track(2, "radar", 1.0, 50.0, var=9.0)
    radar.x[3], radar.p[3, 3] = 0.2, 0.3**2
    own, own_v = np.zeros(2), np.array([5.0, 0.0])
    cfg = dict(consider_nav_bias=False, fuse_velocity="cartesian", radar_hidden_depth_fraction=0.0)

    def fused_speed(scale, velocity):
        fuser = Fuser(FusionConfig(face_turn_scale=scale, **cfg))
        fuser.step(0.0, {"lidar": [lidar], "radar": [radar]}, own, velocity)
        (out,) = fuser.step(0.0, {"lidar": [lidar], "radar": [radar]}, own, velocity)
        return out.x[3]

    plain = fused_speed(0.0, own_v)
    assert plain == pytest.approx(0.5, abs=0.01)  # equal speed variances: the middle
    turned = fused_speed(1.0, own_v)
    expected = (0.8 / (0.09 + 0.36) + 0.2 / 0.09) / (1 / (0.09 + 0.36) + 1 / 0.09)
    assert turned == pytest.approx(expected, abs=0.02), turned
    assert fused_speed(1.0, None) == pytest.approx(plain)
