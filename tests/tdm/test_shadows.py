"""tdm.shadows: the sector a detection hides from the sensor, against analytic cases."""

from __future__ import annotations

import numpy as np

from tdm.shadows import box_extents_m, shadowed


def test_a_box_shows_its_side_facing_the_sensor_across_the_sight_and_the_other_along_it():
    # 30 x 10 m, long side north-south (0 deg): seen from the south (sight 0 deg) it shows its 10 m end and is 30 m
    # deep, from the west (sight 90 deg) its 30 m side, 10 m deep; at 45 deg (30 + 10) / sqrt(2) both ways
    across, along = box_extents_m(np.full(3, 30.0), np.full(3, 10.0), np.zeros(3), np.array([0.0, 90.0, 45.0]))
    assert np.allclose(across, [10.0, 30.0, 40.0 / np.sqrt(2.0)])
    assert np.allclose(along, [30.0, 10.0, 40.0 / np.sqrt(2.0)])
    across, along = box_extents_m(np.array([np.nan, 12.0]), np.array([5.0, 4.0]), np.array([0.0, np.nan]), np.zeros(2))
    assert across.tolist() == [0.0, 12.0] and along.tolist() == [0.0, 12.0]  # no size: none; no orientation: length


def test_a_position_is_shadowed_only_beyond_the_far_side_and_within_the_bearings():
    own = np.array([100.0, -50.0])
    det = own + np.array([[0.0, 200.0]])  # 200 m north of the sensor, 20 m across (+-atan(10 / 200)), 30 m deep:
    # a 30 x 20 m box, its long side north-south along the line of sight
    half = np.arctan2(10.0, 200.0)
    behind_in = own + 300.0 * np.array([np.sin(0.9 * half), np.cos(0.9 * half)])
    behind_out = own + 300.0 * np.array([np.sin(1.1 * half), np.cos(1.1 * half)])
    within_depth = own + np.array([0.0, 212.0])  # behind the centre but not the far side (215 m): its own object
    nearer = own + 150.0 * np.array([0.0, 1.0])
    other_side = own + np.array([0.0, -300.0])
    got = shadowed(np.array([behind_in, behind_out, within_depth, nearer, other_side]), own, det, np.array([30.0]),
                   np.array([20.0]), np.zeros(1))
    assert got.tolist() == [True, False, False, False, False]


def test_bearings_wrap_at_south_and_a_detection_holding_the_sensor_hides_nothing():
    own = np.zeros(2)
    det = np.array([[1.0, -100.0]])  # just east of south: bearing 179.4 deg
    target = np.array([[-2.0, -300.0]])  # just west of south, -179.6 deg: 1.0 deg away across the wrap
    ten = (np.array([10.0]), np.array([10.0]), np.zeros(1))  # a 10 m square
    assert shadowed(target, own, det, *ten).tolist() == [True]
    assert shadowed(target, own, np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros(0)).tolist() == [False]
    assert shadowed(np.zeros((0, 2)), own, det, *ten).shape == (0,)
    # a plot on the own ship (a range of 0, under half its extent) would otherwise hide half the sea
    far = np.array([[500.0, 500.0], [-500.0, 500.0], [0.0, -500.0]])
    assert not shadowed(far, own, np.array([[0.0, 0.0], [1.0, 2.0]]), np.array([10.0, 10.0]), np.array([10.0, 10.0]),
                        np.zeros(2)).any()
