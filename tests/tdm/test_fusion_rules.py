"""tdm.fusion_rules: the velocity frame a fusion averages in, and velocities an AIS track rules out."""

import math

import numpy as np
import pytest

from tdm import ekf, fusion_rules
from tdm.fusion_rules import from_cartesian, fuse, to_cartesian, velocity_frame, without_stray_velocities


def _estimate(east, north, course_deg, speed_mps, var_m2=4.0, course_sd_deg=20.0, speed_sd_mps=0.3):
    x = np.array([east, north, math.radians(course_deg), speed_mps, 0.0, 50.0])
    p = np.diag([var_m2, var_m2, math.radians(course_sd_deg) ** 2, speed_sd_mps**2, 1e-4, 100.0])
    return x, p


def test_east_and_north_average_a_still_objects_velocity_errors_where_course_and_speed_add_them():
    """A still berg seen by two sensors whose velocities err 0.5 m/s east and 0.5 m/s west (equal covariances,
    along-track 0.3 m/s, across 0.5 x 20 deg): east and north average to standing still; course and speed
    average the speeds, each the size of its error."""
    a, b = _estimate(0.0, 0.0, 90.0, 0.5), _estimate(0.0, 0.0, -90.0, 0.5)
    xs, ps = np.array([a[0], b[0]]), np.array([a[1], b[1]])
    x_cart, _ = fuse(xs, ps, velocity="cartesian")
    x_polar, _ = fuse(xs, ps, velocity="polar")
    assert x_cart[ekf.U] == pytest.approx(0.0, abs=1e-9)
    assert x_polar[ekf.U] == pytest.approx(0.5)
    assert x_cart[:2] == pytest.approx([0.0, 0.0])


def test_estimates_that_agree_fuse_alike_in_either_frame():
    a, b = _estimate(10.0, 5.0, 30.0, 5.0, course_sd_deg=2.0), _estimate(12.0, 5.0, 31.0, 5.2, course_sd_deg=2.0)
    xs, ps = np.array([a[0], b[0]]), np.array([a[1], b[1]])
    x_cart, p_cart = fuse(xs, ps, velocity="cartesian")
    x_polar, p_polar = fuse(xs, ps, velocity="polar")
    assert x_cart[:2] == pytest.approx(x_polar[:2], abs=1e-3)
    assert math.degrees(x_cart[ekf.PSI]) == pytest.approx(math.degrees(x_polar[ekf.PSI]), abs=0.05)
    assert x_cart[ekf.U] == pytest.approx(x_polar[ekf.U], abs=0.01)
    assert np.diag(p_cart)[2:4] == pytest.approx(np.diag(p_polar)[2:4], rel=0.02)
    with pytest.raises(ValueError, match="velocity frame"):
        fuse(xs, ps, velocity="spherical")


def test_to_and_from_cartesian_are_each_others_inverse():
    x, p = _estimate(3.0, -4.0, 135.0, 2.0)
    p[0, 3] = p[3, 0] = 0.2  # a correlation carried through
    ys, qs = to_cartesian(x[None], p[None])
    assert ys[0, 2:4] == pytest.approx([2.0 * math.sin(math.radians(135.0)), 2.0 * math.cos(math.radians(135.0))])
    # across track: the speed times the course's standard deviation
    across = np.array([math.cos(math.radians(135.0)), -math.sin(math.radians(135.0))])
    assert across @ qs[0, 2:4, 2:4] @ across == pytest.approx((2.0 * math.radians(20.0)) ** 2)
    x2, p2 = from_cartesian(ys[0], qs[0])
    assert x2 == pytest.approx(x)
    assert p2 == pytest.approx(p)


def test_a_velocity_the_ais_rules_out_is_left_out_and_its_position_kept():
    """A 0.5 m/s ship (AIS, sd 0.4 m/s) with a LiDAR track 2 m/s the other way (sd 0.3 m/s): 25 sd^2 apart,
    beyond the gate; the LiDAR adds its position alone. A radar track at 0.7 m/s is kept."""
    ais = _estimate(0.0, 0.0, 90.0, 0.5, var_m2=25.0, course_sd_deg=5.0, speed_sd_mps=0.4)
    lidar = _estimate(2.0, 0.0, -90.0, 2.0, var_m2=1.0, course_sd_deg=10.0)
    radar = _estimate(1.0, 0.0, 90.0, 0.7, var_m2=16.0, course_sd_deg=40.0, speed_sd_mps=0.5)
    xs = np.array([ais[0], lidar[0], radar[0]])
    ps = np.array([ais[1], lidar[1], radar[1]])
    out = without_stray_velocities(xs, ps, anchor=0, gate_chi2=18.42)
    assert out is not ps and out[1, ekf.U, ekf.U] > 1e5 and out[1, ekf.PSI, ekf.PSI] > 1e5
    assert out[0] == pytest.approx(ps[0]) and out[2] == pytest.approx(ps[2])
    assert out[1, :2, :2] == pytest.approx(ps[1, :2, :2])
    x_all, _ = fuse(xs, ps, velocity="cartesian")
    x_gated, _ = fuse(xs, out, velocity="cartesian")
    assert math.cos(x_gated[ekf.PSI] - math.pi / 2) > 0.99  # eastward, with the AIS and the radar
    assert math.cos(x_all[ekf.PSI] - math.pi / 2) < 0.0  # the LiDAR's velocity turned it west
    assert x_gated[0] == pytest.approx(x_all[0], abs=0.2)  # the LiDAR's position still counts
    kept = ps[[0, 2]]
    assert without_stray_velocities(xs[[0, 2]], kept, 0, 18.42) is kept


def test_a_target_with_ais_fuses_course_and_speed_one_without_east_and_north():
    """The AIS measures course and speed: with it among the members the velocities are averaged as those (a slow
    ship's AIS course holds against a radar velocity 1 m/s the other way, where east and north would turn it)."""
    assert velocity_frame("cartesian_without_ais", {"ais": 1, "radar": 2}) == "polar"
    assert velocity_frame("cartesian_without_ais", ["lidar", "radar"]) == "cartesian"
    assert velocity_frame("polar", ["lidar"]) == "polar" and velocity_frame("cartesian", ["ais"]) == "cartesian"
    ais = _estimate(0.0, 0.0, 90.0, 0.5, course_sd_deg=3.0, speed_sd_mps=0.4)
    radar = _estimate(0.0, 0.0, -90.0, 0.6, course_sd_deg=40.0, speed_sd_mps=0.5)
    xs, ps = np.array([ais[0], radar[0]]), np.array([ais[1], radar[1]])
    x_polar, _ = fuse(xs, ps, velocity=velocity_frame("cartesian_without_ais", ["ais", "radar"]))
    x_cart, _ = fuse(xs, ps, velocity="cartesian")
    assert math.degrees(x_polar[ekf.PSI]) == pytest.approx(90.0, abs=3.0)
    assert math.cos(x_cart[ekf.PSI] - math.pi / 2) < 0.0 or x_cart[ekf.U] < 0.1


def _correlated_estimates():
    """Two tracks of one object moving north at 5 m/s, their positions 10 m apart (a bias), the same velocity; each
    filter's position and speed correlated (a track that lies ahead has gained speed)."""
    xs = np.array([[0.0, 0.0, 0.0, 5.0, 0.0, 10.0], [0.0, 10.0, 0.0, 5.0, 0.0, 10.0]])
    p1 = np.diag([4.0, 4.0, 0.01, 1.0, 1e-4, 100.0])
    p1[ekf.N, ekf.U] = p1[ekf.U, ekf.N] = 1.6  # correlation 0.8
    p2 = np.diag([4.0, 9.0, 0.01, 0.5, 1e-4, 100.0])
    p2[ekf.N, ekf.U] = p2[ekf.U, ekf.N] = 1.5
    return xs, np.array([p1, p2])


@pytest.mark.parametrize("velocity", ["polar", "cartesian"])
def test_apart_fusion_keeps_a_position_difference_out_of_the_velocity(velocity):
    xs, ps = _correlated_estimates()
    x_whole, _ = fusion_rules.fuse(xs, ps, "simple", velocity)
    x_apart, p_apart = fusion_rules.fuse(xs, ps, "simple", velocity, apart=True)
    assert abs(x_whole[ekf.U] - 5.0) > 0.1  # fused as one state, the 10 m turns into speed
    assert x_apart[ekf.U] == pytest.approx(5.0)
    assert x_apart[ekf.PSI] == pytest.approx(0.0, abs=1e-12)
    # the positions fused from their marginals alone: information-weighted north, 1/4 against 1/9
    assert x_apart[ekf.N] == pytest.approx((0.0 / 4 + 10.0 / 9) / (1 / 4 + 1 / 9))
    assert p_apart[ekf.N, ekf.N] == pytest.approx(1 / (1 / 4 + 1 / 9))
    assert np.all(p_apart[:2, 2:] == 0.0)


def test_apart_covariances_zero_only_the_position_motion_blocks():
    _, ps = _correlated_estimates()
    out = fusion_rules.apart_covariances(ps)
    assert np.all(out[:, :2, 2:] == 0.0) and np.all(out[:, 2:, :2] == 0.0)
    assert np.array_equal(out[:, :2, :2], ps[:, :2, :2]) and np.array_equal(out[:, 2:, 2:], ps[:, 2:, 2:])
    assert ps[0, ekf.N, ekf.U] == 1.6  # the input untouched


def test_consider_covariance_follows_the_apart_weights():
    """A position bias of one estimate reaches only the fused position when the fusion keeps them apart."""
    xs, ps = _correlated_estimates()
    bias = np.array([25.0, 0.0])
    whole = fusion_rules.consider_covariance(xs, ps, bias)
    apart = fusion_rules.consider_covariance(xs, ps, bias, apart=True)
    assert whole[ekf.U, ekf.U] > 0.01
    assert apart[ekf.U, ekf.U] == pytest.approx(0.0, abs=1e-12)
    assert apart[ekf.N, ekf.N] == pytest.approx(25.0 * ((1 / 4) / (1 / 4 + 1 / 9)) ** 2)


def test_apart_members_takes_apart_only_the_sensors_named():
    assert fusion_rules.apart_members({"ais": 1, "lidar": 4, "radar": 2}, ("lidar", "radar")).tolist() == \
        [False, True, True]
    _, ps = _correlated_estimates()
    out = fusion_rules.apart_covariances(ps, np.array([False, True]))
    assert out[0, ekf.N, ekf.U] == 1.6 and out[1, ekf.N, ekf.U] == 0.0
    assert fusion_rules.apart_covariances(ps, False) is ps


def test_a_whole_estimate_keeps_what_its_cross_covariance_says():
    """An AIS track coasting since its last report: its position error is its speed's error carried on (the
    cross-covariance). A second estimate that knows the speed well then narrows the fused position when the first
    stays whole, and does not when it is taken apart."""
    coast_s = 60.0
    x_ais = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    p_ais = np.diag([1.0, 1.0 + coast_s**2 * 0.25, 1.0, 0.25, 1e-4, 100.0])
    p_ais[ekf.N, ekf.U] = p_ais[ekf.U, ekf.N] = coast_s * 0.25
    p_radar = np.diag([400.0, 400.0, 1.0, 0.01, 1e-4, 100.0])
    xs, ps = np.array([x_ais, x_ais]), np.array([p_ais, p_radar])
    _, p_whole = fusion_rules.fuse(xs, ps, "simple", "polar", apart=np.array([False, True]))
    _, p_apart = fusion_rules.fuse(xs, ps, "simple", "polar", apart=True)
    assert p_whole[ekf.N, ekf.N] < 0.3 * p_apart[ekf.N, ekf.N]
