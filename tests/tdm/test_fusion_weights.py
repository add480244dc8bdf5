"""tdm.fusion_weights: what the fusion's output weighs."""

import numpy as np
import pytest

from tdm.fusion import FusedTarget, Fuser, FusionConfig
from tdm.fusion_weights import with_fragments

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
