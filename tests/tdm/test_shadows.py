"""tdm.shadows: the sector a detection hides from the sensor, against analytic cases."""

from __future__ import annotations

import numpy as np

from tdm.shadows import across_sight_m, shadowed


def test_a_box_is_as_wide_across_the_sight_as_its_side_facing_the_sensor():
    # 30 x 10 m, long side north-south (0 deg): seen from the south (sight 0 deg) it shows its 10 m end, from the
    # west (sight 90 deg) its 30 m side; at 45 deg (30 + 10) / sqrt(2)
    got = across_sight_m(np.full(3, 30.0), np.full(3, 10.0), np.zeros(3), np.array([0.0, 90.0, 45.0]))
    assert np.allclose(got, [10.0, 30.0, 40.0 / np.sqrt(2.0)])
    assert across_sight_m(np.array([np.nan]), np.array([5.0]), np.zeros(1), np.zeros(1))[0] == 0.0


def test_a_position_is_shadowed_only_behind_the_detection_and_within_its_bearings():
    own = np.array([100.0, -50.0])
    det = own + np.array([[0.0, 200.0]])  # 200 m north of the sensor, 20 m across: +-atan(10 / 200) = +-2.86 deg
    across = np.array([20.0])
    half = np.arctan2(10.0, 200.0)
    behind_in = own + 300.0 * np.array([np.sin(0.9 * half), np.cos(0.9 * half)])
    behind_out = own + 300.0 * np.array([np.sin(1.1 * half), np.cos(1.1 * half)])
    nearer = own + 150.0 * np.array([0.0, 1.0])
    other_side = own + np.array([0.0, -300.0])
    got = shadowed(np.array([behind_in, behind_out, nearer, other_side]), own, det, across)
    assert got.tolist() == [True, False, False, False]


def test_bearings_wrap_at_north_and_nothing_hides_without_detections():
    own = np.zeros(2)
    det = np.array([[-1.0, 100.0]])  # just west of north
    target = np.array([[2.0, 300.0]])  # just east of north, 300 m: within +-atan(5 / 100) of it across the wrap
    assert shadowed(target, own, det, np.array([10.0])).tolist() == [True]
    assert shadowed(target, own, np.zeros((0, 2)), np.zeros(0)).tolist() == [False]
    assert shadowed(np.zeros((0, 2)), own, det, np.array([10.0])).shape == (0,)
