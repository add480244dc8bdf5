"""Motion: waypoint tracks with first-order heading lag, trajectories, waves, poses for arrays of times."""

from __future__ import annotations

import numpy as np
import pytest

from raysim.motion import (
    ConstantVelocity,
    SampledTrack,
    ShipMotion,
    Stationary,
    WaveMotion,
    waypoint_track,
    wheel_over_distance_m,
)
from raysim.pose import Poses, heading_deg_from_yaw, rotation_matrices, yaw_from_heading_deg

KN = 1852.0 / 3600.0


def test_ten_knots_for_sixty_seconds_is_308_7_m_along_track():
    # A leg heading 030 deg (compass): 10 kn for 60 s = 308.67 m (1 kn = 1852/3600 m/s).
    heading = np.radians(30.0)
    end = 5000.0 * np.array([np.sin(heading), np.cos(heading)])
    track = waypoint_track(np.array([[0.0, 0.0], end]), 10 * KN, 120.0, 5.0)
    p = track.poses(np.array([60.0])).position_m[0]
    assert np.hypot(p[0], p[1]) == pytest.approx(308.667, abs=0.005)
    assert heading_deg_from_yaw(track.poses(np.array([60.0])).yaw_rad)[0] == pytest.approx(30.0, abs=1e-9)


def test_ninety_degree_turn_follows_the_first_order_lag():
    T, U = 8.0, 6.0
    track = waypoint_track(np.array([[0.0, 0.0], [600.0, 0.0], [600.0, 600.0]]), U, 200.0, T)
    t = np.arange(0.0, 200.0, 0.05)
    yaw = track.poses(t).yaw_rad
    turning = np.nonzero(yaw > 1e-9)[0]
    assert turning.size
    t_switch = t[turning[0]] - 0.05  # the last sample on the old course
    after = t > t_switch
    expected = np.pi / 2 * (1.0 - np.exp(-(t[after] - t_switch) / T))
    assert np.max(np.abs(yaw[after] - expected)) < np.radians(0.01)
    # 63 % of the turn after one time constant
    i = np.argmin(np.abs(t - (t_switch + T)))
    assert yaw[i] / (np.pi / 2) == pytest.approx(1 - np.exp(-1), abs=0.005)
    # the wheel-over point puts the ship onto the next leg (x = 600) instead of overshooting it
    late = track.poses(np.array([t_switch + 8 * T])).position_m[0]
    assert late[0] == pytest.approx(600.0, abs=0.3)
    # no teleporting: heading changes at most U-limited rate 90 deg / T per second
    assert np.max(np.abs(np.diff(yaw))) <= np.pi / 2 / T * 0.05 + 1e-9


def test_wheel_over_distance_small_turn_limit_is_speed_times_time_constant():
    assert wheel_over_distance_m(1e-4, 5.0, 10.0) == pytest.approx(50.0, rel=1e-3)
    assert wheel_over_distance_m(0.0, 5.0, 10.0) == 0.0


def test_anchored_ship_stays_put_with_its_heading():
    track = waypoint_track(np.array([[10.0, 20.0]]), 0.0, 60.0, 5.0, heading_rad=0.3)
    poses = track.poses(np.array([0.0, 30.0, 59.0]))
    assert np.allclose(poses.position_m[:, :2], [[10, 20]] * 3)
    assert np.allclose(poses.yaw_rad, 0.3)
    assert np.allclose(track.velocity_mps(np.array([5.0])), 0.0)


def test_stop_and_continue_and_loop_at_the_end():
    wps = np.array([[0.0, 0.0], [100.0, 0.0]])
    stop = waypoint_track(wps, 5.0, 60.0, 2.0, at_end="stop")
    assert stop.poses(np.array([59.0])).position_m[0, 0] == pytest.approx(100.0, abs=0.3)
    assert np.allclose(stop.velocity_mps(np.array([59.0])), 0.0)
    cont = waypoint_track(wps, 5.0, 60.0, 2.0, at_end="continue")
    assert cont.poses(np.array([40.0])).position_m[0, 0] == pytest.approx(200.0, abs=0.01)
    square = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]])
    loop = waypoint_track(square, 5.0, 200.0, 2.0, at_end="loop")
    p = loop.poses(np.arange(0.0, 200.0, 1.0)).position_m
    assert p[:, 0].min() > -5 and p[:, 0].max() < 105 and p[:, 1].min() > -5 and p[:, 1].max() < 105
    closing = loop.poses(np.array([65.0])).position_m[0]  # about 320 m along: on the closing leg x = 0
    assert abs(closing[0]) < 1 and 30 < closing[1] < 70
    again = loop.poses(np.array([85.0])).position_m[0]  # second lap, back on the first leg y = 0
    assert abs(again[1]) < 1 and 30 < again[0] < 70


def test_poses_are_vectorised_and_interpolated():
    track = waypoint_track(np.array([[0.0, 0.0], [1000.0, 0.0]]), 10.0, 100.0, 3.0)
    t = np.random.default_rng(0).uniform(0, 100, 1000)
    poses = track.poses(t)
    assert poses.position_m.shape == (1000, 3) and poses.yaw_rad.shape == (1000,)
    assert np.allclose(poses.position_m[:, 0], 10.0 * t, atol=1e-9)
    assert np.allclose(track.velocity_mps(t)[:, 0], 10.0)


def test_wave_motion_amplitudes_and_signs():
    waves = WaveMotion(3.0, 5.0, 1.5, 4.0, 0.3, 6.0, np.random.default_rng(1))
    t = np.arange(0.0, 60.0, 0.01)
    roll, pitch, heave = waves.angles(t)
    assert np.degrees(roll).max() == pytest.approx(3.0, abs=0.01)
    assert np.degrees(-pitch).max() == pytest.approx(1.5, abs=0.01)
    assert heave.max() == pytest.approx(0.3, abs=0.001)
    assert np.allclose(np.gradient(heave, t)[1:-1], waves.heave_rate_mps(t)[1:-1], atol=1e-3)
    # a ship with waves rolls about its own axis and carries heave in z
    ship = ShipMotion(waypoint_track(np.array([[0.0, 0.0]]), 0.0, 60.0, 2.0), waves)
    poses = ship.poses(t)
    assert np.allclose(poses.position_m[:, 2], heave)
    assert ship.max_speed_mps >= np.abs(waves.heave_rate_mps(t)).max()


def test_sampled_track_holds_end_poses_outside_its_range():
    track = SampledTrack(0.5, [0.0, 1.0, 2.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    p = track.poses(np.array([-1.0, 0.25, 10.0])).position_m[:, 0]
    assert np.allclose(p, [0.0, 0.5, 2.0])


def test_constant_velocity_and_stationary():
    cv = ConstantVelocity([1.0, 2.0, 0.0], [3.0, 0.0, 0.0], yaw_rad=0.1, yaw_rate_rps=0.2)
    poses = cv.poses(np.array([0.0, 2.0]))
    assert np.allclose(poses.position_m[1], [7.0, 2.0, 0.0])
    assert np.allclose(poses.yaw_rad, [0.1, 0.5])
    still = Stationary([5.0, 6.0, 0.0], 1.0)
    assert np.allclose(still.poses(np.zeros(3)).position_m, [[5, 6, 0]] * 3)


def test_rotation_conventions():
    # yaw 90 deg (ENU) = heading north... compass 0 deg: body x points north (+y)
    r = rotation_matrices(np.array([yaw_from_heading_deg(0.0)]), np.zeros(1), np.zeros(1))[0]
    assert np.allclose(r @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    # positive FLU roll lifts the port (left, +y) side: starboard down
    r = rotation_matrices(np.zeros(1), np.zeros(1), np.radians([10.0]))[0]
    assert (r @ [0, 1, 0])[2] > 0
    # positive FLU pitch puts the bow down (marine pitch is the opposite sign)
    r = rotation_matrices(np.zeros(1), np.radians([10.0]), np.zeros(1))[0]
    assert (r @ [1, 0, 0])[2] < 0
    poses = Poses(np.array([[1.0, 2.0, 3.0]]), np.array([0.7]), np.array([0.1]), np.array([-0.2]))
    pt = np.array([[4.0, -5.0, 6.0]])
    assert np.allclose(poses.to_body(poses.to_world(pt)), pt)
