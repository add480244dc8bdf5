"""Simple Fusion (thesis eq. 3.2), covariance intersection and target management."""

import numpy as np
import pytest

from tdm import ekf, fusion_rules
from tdm.fusion import Fuser, FusionConfig, fuse
from tdm.tracker import Track


def test_simple_fusion_is_the_information_weighted_mean():
    x1 = np.array([0.0, 0.0, 0.1, 5.0, 0.0, 10.0])
    x2 = np.array([3.0, 6.0, 0.2, 5.5, 0.0, 20.0])
    p1 = np.diag([1.0, 4.0, 0.01, 1.0, 1e-4, 100.0])
    p2 = np.diag([2.0, 2.0, 0.04, 0.25, 1e-4, 100.0])
    x, p = fuse(np.array([x1, x2]), np.array([p1, p2]))
    assert x[0] == pytest.approx((0 / 1 + 3 / 2) / (1 / 1 + 1 / 2))
    assert x[1] == pytest.approx((0 / 4 + 6 / 2) / (1 / 4 + 1 / 2))
    assert p[0, 0] == pytest.approx(1 / (1 / 1 + 1 / 2))
    assert np.all(np.diag(p) <= np.minimum(np.diag(p1), np.diag(p2)) + 1e-12)


def test_fusion_of_courses_across_north():
    x1 = np.array([0, 0, np.radians(359.0), 5, 0, 0.0])
    x2 = np.array([0, 0, np.radians(3.0), 5, 0, 0.0])
    p = np.eye(6)
    x, _ = fuse(np.array([x1, x2]), np.array([p, p]))
    assert np.degrees(ekf.wrap_pi(x[ekf.PSI])) == pytest.approx(1.0)


@pytest.mark.parametrize("rule", ["simple", "ci"])
def test_a_track_with_its_speed_negative_and_its_course_reversed_fuses_as_the_same_motion(rule):
    """(psi, u) and (psi + pi, -u) are one motion: fused, position and velocity stay those of both tracks."""
    p = np.array([[4.0, 0.5, 0.3, 0.4, 0.0, 0.0], [0.5, 5.0, 0.2, 0.6, 0.0, 0.0], [0.3, 0.2, 0.05, 0.1, 0.0, 0.0],
                  [0.4, 0.6, 0.1, 0.5, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1e-4, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 100.0]])
    ahead = np.array([284.0, 219.0, np.radians(181.0), 2.6, 0.0, 20.0])
    reversed_ = ahead.copy()
    reversed_[ekf.PSI], reversed_[ekf.U] = np.radians(1.0), -2.6
    flip = np.diag([1.0, 1.0, 1.0, -1.0, 1.0, 1.0])
    x, pf = fuse(np.array([ahead, reversed_]), np.array([p, flip @ p @ flip]), rule)
    assert x[:2] == pytest.approx(ahead[:2], abs=1e-9)
    assert ekf.velocity_en(x) == pytest.approx(ekf.velocity_en(ahead), abs=1e-9)
    assert np.all(np.linalg.eigvalsh(pf) > 0)


def test_covariance_intersection_stays_wider_than_simple_fusion():
    p1, p2 = np.diag([1.0, 4.0, 1, 1, 1, 1]), np.diag([4.0, 1.0, 1, 1, 1, 1])
    xs = np.zeros((2, 6))
    _, ps = fuse(xs, np.array([p1, p2]), "simple")
    _, pc = fuse(xs, np.array([p1, p2]), "ci")
    assert np.all(np.linalg.eigvalsh(pc - ps) > -1e-12)
    # CI never claims more than the better input along any axis
    assert pc[0, 0] >= 1.0 - 1e-12 and pc[1, 1] >= 1.0 - 1e-12


def make_track(track_id, sensor, east, north, var=4.0, t=0.0, mmsi=None):
    x = np.array([east, north, 0.0, 0.0, 0.0, 50.0])
    p = np.diag([var, var, 1.0, 0.25, 1e-4, 100.0])
    return Track(track_id, sensor, x, p, t, t, t, confirmed=True, mmsi=mmsi)


def test_a_still_targets_radar_track_is_put_its_hidden_depth_behind_the_face_along_the_line_of_sight():
    """A berg's radar track 500 m north of the own ship, 12 m long (no core width: its length is its size): reported
    ``radar_hidden_depth_length_fraction`` x 12 m farther north once the target is still (an iceberg); a vessel's,
    or a track with AIS, as it is."""
    fuser = Fuser(FusionConfig(consider_nav_bias=False))
    radar = make_track(1, "radar", 0.0, 500.0)
    radar.length_m = 12.0
    own = np.array([0.0, 0.0])
    (first,) = fuser.step(0.0, {"radar": [radar]}, own)
    assert first.x[:2] == pytest.approx([0.0, 500.0])  # not yet known to be still
    first.target.descriptor = "iceberg"
    (still,) = fuser.step(1.0, {"radar": [radar]}, own)
    depth = FusionConfig(consider_nav_bias=False).radar_hidden_depth_length_fraction * 12.0
    assert depth > 0.0 and still.x[:2] == pytest.approx([0.0, 500.0 + depth])
    # the depth's uncertainty, along the sight line
    sigma = FusionConfig(consider_nav_bias=False).radar_hidden_depth_length_sigma_fraction * 12.0
    predicted = radar.predicted(1.0)[1][:2, :2]
    assert still.p[:2, :2] == pytest.approx(predicted + np.diag([0.0, sigma**2]))
    assert radar.x[:2] == pytest.approx([0.0, 500.0])  # the track itself is untouched
    (no_own,) = fuser.step(2.0, {"radar": [radar]})
    assert no_own.x[:2] == pytest.approx([0.0, 500.0])
    still.target.descriptor = "vessel"
    (vessel,) = fuser.step(3.0, {"radar": [radar]}, own)
    assert vessel.x[:2] == pytest.approx([0.0, 500.0])


def test_the_hidden_depth_is_a_fraction_of_the_core_width_where_the_object_spans_half_a_beam_else_of_its_length():
    """A 68 m berg whose rain-cut plots are 12 m long but whose core width is 55 m: 500 m off (6.3 deg, over half
    the 5.2 deg beam) put 0.5 x 55 m behind its face, not by its length; 2 km off (1.6 deg) the core width is
    ill-conditioned (a few tenths of a degree of smear change it by tens of metres) and the length rule holds;
    with ``radar_hidden_depth_size="length"`` the length rule holds everywhere."""
    for size, north_m, by_core in (("core_width", 500.0, True), ("core_width", 2000.0, False),
                                   ("length", 500.0, False)):
        config = FusionConfig(consider_nav_bias=False, radar_hidden_depth_size=size)
        fuser = Fuser(config)
        radar = make_track(1, "radar", 0.0, north_m)
        radar.length_m, radar.core_width_m = 12.0, 55.0
        (first,) = fuser.step(0.0, {"radar": [radar]}, np.zeros(2))
        first.target.descriptor = "iceberg"
        (still,) = fuser.step(1.0, {"radar": [radar]}, np.zeros(2))
        depth_m, sigma_m = ((config.radar_hidden_depth_fraction * 55.0, config.radar_hidden_depth_sigma_fraction * 55.0)
                            if by_core else (config.radar_hidden_depth_length_fraction * 12.0,
                                             config.radar_hidden_depth_length_sigma_fraction * 12.0))
        assert still.x[:2] == pytest.approx([0.0, north_m + depth_m])
        assert still.p[1, 1] == pytest.approx(radar.predicted(1.0)[1][1, 1] + sigma_m ** 2)
    with pytest.raises(ValueError, match="radar_hidden_depth_size"):
        FusionConfig(consider_nav_bias=False, radar_hidden_depth_size="width")


@pytest.mark.parametrize("field", ["join_free_slot", "hull_sensors", "fragment_sensors", "face_turn_sensors"])
def test_a_misspelt_sensor_in_a_fusion_setting_is_an_error_not_a_rule_quietly_off(field):
    with pytest.raises(ValueError, match=f"{field}: unknown sensor 'lider'"):
        FusionConfig(**{field: ("lider",)})
    with pytest.raises(ValueError, match="promote_after_s"):
        FusionConfig(promote_after_s=float("nan"))
    with pytest.raises(ValueError, match="fuse_velocity"):
        FusionConfig(fuse_velocity="east-north")
    with pytest.raises(ValueError, match="face_turn_scale"):
        FusionConfig(face_turn_scale=-1.0)
    with pytest.raises(ValueError, match="ais_velocity_gate_probability"):
        FusionConfig(ais_velocity_gate_probability=1.0)
    assert getattr(FusionConfig(**{field: ()}), field) == ()


def test_an_ais_track_joins_a_new_radar_target_within_the_ships_length_and_both_uncertainties():
    """busy_port seed 32: a 30 m ferry's first AIS report lies 36 m from the radar target started on it a second
    before (its first plots, 370 m off: metres of cross-range uncertainty); judged by the AIS track's covariance
    alone it started a target of its own and was merged into the radar's 7 s later, two id switches. The two
    positions' difference has both covariances: with the radar's 8 m sigma the report joins the radar target; with a
    radar track as certain as the AIS it stays a ship of its own."""
    for radar_var, joined in ((64.0, True), (1.0, False)):
        fuser = Fuser(FusionConfig())
        fuser.lengths_by_mmsi = {367000401: 30.0}
        radar = make_track(1, "radar", 0.0, 370.0, var=radar_var)
        ais = make_track(1, "ais", 36.0, 370.0, var=4.0, mmsi=367000401)
        fuser.step(0.0, {"radar": [radar]}, np.zeros(2))
        out = fuser.step(1.0, {"radar": [radar], "ais": [ais]}, np.zeros(2))
        assert (len(out) == 1) == joined
        if joined:
            assert out[0].target.members == {"radar": 1, "ais": 1} and out[0].target.mmsi == 367000401


def test_a_ship_passing_close_to_a_still_berg_does_not_swallow_it():
    """busy_open_sea seeds 9 and 11: a 100 m ship with AIS passes 40 m from a berg the radar has tracked
    for a while; the berg's target is not folded into the ship's (two objects), and keeps its id."""
    fuser = Fuser(FusionConfig())
    fuser.lengths_by_mmsi = {257000002: 100.0}
    berg = make_track(1, "radar", 0.0, 0.0, var=25.0)
    berg.x[ekf.ALPHA] = 400.0
    for t in range(1, 26):  # settles as an iceberg (20 s still, 400 m2)
        (first,) = fuser.step(float(t), {"radar": [berg]})
    assert first.target.descriptor == "iceberg"
    berg_id = first.target.target_id
    for t in range(26, 66):  # the ship steams north at 5 m/s, 40 m east of the berg: -100 m .. +95 m
        north = -100.0 + 5.0 * (t - 26)
        ship = make_track(5, "ais", 40.0, north, var=5.0, t=float(t), mmsi=257000002)
        ship.x[ekf.U] = 5.0
        ship_radar = make_track(2, "radar", 40.0, north, var=25.0, t=float(t))
        ship_radar.x[ekf.U] = 5.0
        berg_now = make_track(1, "radar", 0.0, 0.0, var=25.0, t=float(t))
        berg_now.x[ekf.ALPHA] = 400.0
        out = fuser.step(float(t), {"radar": [berg_now, ship_radar], "ais": [ship]})
        assert len(out) == 2, t
        (berg_target,) = [e.target for e in out if e.target.mmsi is None]
        assert berg_target.target_id == berg_id and berg_target.descriptor == "iceberg"


@pytest.mark.parametrize("weigh", [False, True])
def test_the_centres_uncertainty_weighs_the_output_only_when_asked(weigh):
    """A LiDAR track (var 1 m^2) and a radar track 4 m east (var 4 m^2, 12 m long, extent 0.5 of it: +36 m^2):
    by default the fusion weighs the filters' covariances (1 : 4); with ``weigh_extent`` the radar's 40 m^2."""
    fuser = Fuser(FusionConfig(consider_nav_bias=False, weigh_extent=weigh))
    lidar = make_track(1, "lidar", 0.0, 100.0, var=1.0)
    radar = make_track(2, "radar", 4.0, 100.0, var=4.0)
    radar.length_m, radar.extent_sigma_fraction = 12.0, 0.5
    (out,) = fuser.step(0.0, {"lidar": [lidar], "radar": [radar]})
    radar_var = 4.0 + (36.0 if weigh else 0.0)
    assert out.x[0] == pytest.approx(4.0 * (1.0 / radar_var) / (1.0 + 1.0 / radar_var))
    assert out.p[0, 0] == pytest.approx(1.0 / (1.0 + 1.0 / radar_var))
    np.testing.assert_array_equal(radar.predicted(0.0)[1], make_track(2, "radar", 4.0, 100.0, var=4.0).p)


def _moving_track(track_id, sensor, east, north, course_deg, speed_mps, speed_sigma_mps, mmsi=None,
                  heading_sigma_deg=2.0):
    track = make_track(track_id, sensor, east, north, var=4.0, mmsi=mmsi)
    track.x[ekf.PSI], track.x[ekf.U] = np.radians(course_deg), speed_mps
    track.p[ekf.U, ekf.U], track.p[ekf.PSI, ekf.PSI] = speed_sigma_mps**2, np.radians(heading_sigma_deg) ** 2
    return track


@pytest.mark.parametrize("speed_sigma_mps, heading_sigma_deg, folds", [(0.3, 2.0, False), (3.0, 60.0, True)])
def test_a_ship_crossing_inside_an_ais_ships_footprint_keeps_its_target(speed_sigma_mps, heading_sigma_deg, folds):
    """crossing_silent_ship: a silent ship (west at 3.5 m/s, tracked long: speed known to 0.3 m/s, heading to
    2 deg) passes 20 m from a 60 m AIS ferry going north at 6 m/s: two objects, each keeps its id. A new radar
    track of the ferry's bow with an unknown velocity (speed to 3 m/s, heading to 60 deg) at the same place folds
    into the ferry."""
    fuser = Fuser(FusionConfig())
    fuser.lengths_by_mmsi = {257000112: 60.0}
    crosser = _moving_track(1, "radar", 20.0, 0.0, 270.0, 3.5, speed_sigma_mps, heading_sigma_deg=heading_sigma_deg)
    ferry = _moving_track(5, "ais", 0.0, 0.0, 0.0, 6.0, 0.2, mmsi=257000112)
    out = fuser.step(1.0, {"radar": [crosser]})
    crosser_id = out[0].target.target_id
    for t_s in (2.0, 3.0):  # the ferry's length is known from its second epoch on (its target's MMSI)
        out = fuser.step(t_s, {"radar": [crosser], "ais": [ferry]})
    if folds:
        assert len(out) == 1 and out[0].target.mmsi == 257000112
    else:
        assert len(out) == 2
        (silent,) = [e for e in out if e.target.mmsi is None]
        assert silent.target.target_id == crosser_id and silent.sources == ["radar"]


@pytest.mark.parametrize("heading_sigma_deg, speed_sigma_mps, course_deg, speed_mps, apart", [
    (30.6, 0.62, 270.0, 3.62, True),   # crossing_silent_ship seed 35: a coasting crosser, heading uncertain
    (2.0, 0.3, 270.0, 3.5, True),      # a crosser tracked long
    (30.0, 3.0, 10.0, 5.0, False),     # a new fragment of the ferry: near its velocity, uncertain
    (2.0, 0.3, 5.0, 5.5, False),       # the ferry's own fragment, well known: within the 2 m/s margin
    (60.0, 3.0, 270.0, 3.5, False),    # nothing known of the crosser's velocity: it may be the ferry's
])
def test_moves_apart_weighs_the_velocity_difference_in_the_targets_own_velocity_covariance(
        heading_sigma_deg, speed_sigma_mps, course_deg, speed_mps, apart):
    """The ferry goes north at 6.9 m/s. On seed 35 the first form of the rule (speed error plus speed times
    heading error, 2.03 m/s, in every direction) let the coasting crosser, 8 m/s off in velocity, fold in."""
    from tdm.fusion import _moves_apart

    ferry = np.zeros(6), np.eye(6)
    ferry[0][ekf.PSI], ferry[0][ekf.U] = np.radians(2.0), 6.9
    other = np.zeros(6), np.zeros((6, 6))
    other[0][ekf.PSI], other[0][ekf.U] = np.radians(course_deg), speed_mps
    other[1][ekf.U, ekf.U], other[1][ekf.PSI, ekf.PSI] = speed_sigma_mps**2, np.radians(heading_sigma_deg) ** 2
    assert _moves_apart(ferry, other, True) is apart
    assert _moves_apart(other, ferry, False) is apart


def test_footprint_test_decides_as_the_reference_also_at_its_edge():
    """Fuser._inside's closed-form decision is the reference's (LAPACK eigenvalue, np.hypot) for random tracks and
    for tracks placed on the footprint's edge to the last bits, where only the reference can tell."""
    from tdm.fusion_geometry import FOOTPRINT_SIGMAS, inside_reference as _inside_reference

    rng = np.random.default_rng(3)
    n_edge = 0
    for k in range(4000):
        m = rng.normal(size=(2, 2)) * rng.choice([0.01, 1.0, 30.0])
        p = np.eye(6)
        p[:2, :2] = m @ m.T + (0.0 if k % 3 else 1e-3) * np.eye(2)
        centre = rng.normal(0, 300, 6)
        half = float(rng.uniform(10, 60))
        radius = half + FOOTPRINT_SIGMAS * np.sqrt(max(np.linalg.eigvalsh(p[:2, :2])[-1], 0.0))
        bearing = rng.uniform(0, 2 * np.pi)
        scale = radius * (1.0 + rng.choice([-1, 1]) * rng.choice([0.0, 1e-16, 1e-14, 1e-9, 0.1, 1.0]))
        x = centre.copy()
        x[:2] += scale * np.array([np.cos(bearing), np.sin(bearing)])
        n_edge += abs(scale - radius) < 1e-9 * radius
        assert Fuser._inside((x, p), centre, half) == _inside_reference((x, p), centre, half)
    assert n_edge > 1000


def test_targets_found_clearly_apart_all_at_once_are_apart_one_by_one():
    """_clearly_apart (the merge's vectorised first look) is True only where the reference footprint test says
    outside, also for targets placed on each other's footprint edge, and leaves few outside pairs to it."""
    from tdm.fusion_geometry import FOOTPRINT_SIGMAS
    from tdm.fusion_geometry import clearly_apart as _clearly_apart
    from tdm.fusion_geometry import inside_reference as _inside_reference

    rng = np.random.default_rng(8)
    n_apart = n_outside = 0
    for _ in range(60):
        n = int(rng.integers(2, 25))
        estimates, halves = [], [float(h) for h in rng.uniform(10, 60, n)]
        for k in range(n):
            m = rng.normal(size=(2, 2)) * rng.choice([0.01, 1.0, 20.0])
            p = np.eye(6)
            p[:2, :2] = m @ m.T
            x = rng.normal(0, 150, 6)
            if k and k % 2:  # on the edge of the previous target's footprint
                radius = max(halves[k - 1], halves[k]) + FOOTPRINT_SIGMAS * np.sqrt(np.linalg.eigvalsh(p[:2, :2])[-1])
                bearing = rng.uniform(0, 2 * np.pi)
                x[:2] = estimates[k - 1][0][:2] + radius * (1 + rng.choice([-1e-15, 0.0, 1e-15, 1e-12])) * \
                    np.array([np.cos(bearing), np.sin(bearing)])
            estimates.append((x, p))
        apart = _clearly_apart(estimates, halves)
        for i in range(n):
            for j in range(n):
                outside = i < j and not _inside_reference(estimates[j], estimates[i][0], max(halves[i], halves[j]))
                assert not apart[i, j] or outside
                n_apart += bool(apart[i, j])
                n_outside += outside
    assert n_apart > 0.9 * n_outside


def test_a_bias_of_one_estimate_reaches_the_fused_covariance_through_its_weight():
    """Two estimates with equal covariances fuse with weights 1/2 each: independent position biases of variance
    v1 and v2 per axis add (v1 + v2) / 4 to the fused position's variance; a lone estimate keeps its v whole."""
    from tdm.fusion_rules import consider_covariance

    p = np.diag([4.0, 4.0, 0.01, 0.25, 1e-4, 100.0])
    xs = np.array([[0.0, 0.0, 0.1, 5.0, 0.0, 10.0], [1.0, 2.0, 0.1, 5.0, 0.0, 10.0]])
    out = consider_covariance(xs, np.array([p, p]), np.array([9.0, 1.0]))
    np.testing.assert_allclose(out[:2, :2], (9.0 + 1.0) / 4.0 * np.eye(2), atol=1e-12)
    np.testing.assert_allclose(out[2:, 2:], 0.0, atol=1e-12)
    lone = consider_covariance(xs[:1], np.array([p]), np.array([9.0]))
    np.testing.assert_allclose(lone[:2, :2], 9.0 * np.eye(2))
    assert np.count_nonzero(lone) == 2
    # a bias of the less certain estimate reaches the fused state by its smaller weight: 1 / (1 + 4) of 4 m^2 vs 1 m^2
    q = p.copy()
    q[:2, :2] = 16.0 * np.eye(2)
    weighted = consider_covariance(xs, np.array([p, q]), np.array([0.0, 25.0]))
    np.testing.assert_allclose(weighted[:2, :2], 25.0 * (4.0 / 20.0) ** 2 * np.eye(2), atol=1e-12)


def test_a_bias_along_one_axis_reaches_the_fused_covariance_along_that_axis_only():
    """A bias covariance (2, 2) per estimate: 16 m^2 north on the first of two equally certain estimates adds
    16 / 4 m^2 north and nothing east; a per-axis variance v is the matrix v I."""
    from tdm.fusion_rules import consider_covariance

    p = np.diag([4.0, 4.0, 0.01, 0.25, 1e-4, 100.0])
    xs = np.array([[0.0, 0.0, 0.1, 5.0, 0.0, 10.0], [1.0, 2.0, 0.1, 5.0, 0.0, 10.0]])
    v = np.zeros((2, 2, 2))
    v[0, 1, 1] = 16.0
    out = consider_covariance(xs, np.array([p, p]), v)
    np.testing.assert_allclose(out[:2, :2], np.diag([0.0, 4.0]), atol=1e-12)
    np.testing.assert_allclose(consider_covariance(xs, np.array([p, p]), np.array([9.0, 1.0])),
                               consider_covariance(xs, np.array([p, p]), np.array([9.0, 1.0])[:, None, None] * np.eye(2)))
    lone = consider_covariance(xs[:1], np.array([p]), v[:1])
    np.testing.assert_allclose(lone[:2, :2], np.diag([0.0, 16.0]))


def test_a_bias_across_the_axes_reaches_the_fused_covariance_as_w_v_w_transposed():
    """Two estimates whose position covariances do not commute, a bias along 45 deg on the first: the term is
    W_1[:, :2] V W_1[:, :2]^T with W_1 = P P_1^-1 (off-diagonal terms of V kept)."""
    from tdm.fusion_rules import consider_covariance

    p1 = np.diag([4.0, 1.0, 0.01, 0.25, 1e-4, 100.0])
    p2 = p1.copy()
    p2[:2, :2] = [[2.0, 1.5], [1.5, 5.0]]
    xs = np.array([[0.0, 0.0, 0.1, 5.0, 0.0, 10.0], [1.0, 2.0, 0.1, 5.0, 0.0, 10.0]])
    u = np.array([1.0, 1.0]) / np.sqrt(2.0)
    v = np.zeros((2, 2, 2))
    v[0] = 25.0 * np.outer(u, u)
    p = np.linalg.inv(np.linalg.inv(p1) + np.linalg.inv(p2))
    w1 = (p @ np.linalg.inv(p1))[:, :2]
    np.testing.assert_allclose(consider_covariance(xs, np.array([p1, p2]), v), w1 @ v[0] @ w1.T, atol=1e-12)


@pytest.mark.parametrize("consider", [False, True])
def test_a_radar_track_left_on_its_face_reports_the_hidden_depth_in_its_covariance_not_its_state(consider):
    """A radar track 300 m east of the own ship, 12 m long, of a target without AIS not yet classified: reported where
    it is, with the hidden depth (0.6 x 12 m) squared plus its variance (0.25 x 12 m, squared) added east, along the
    line of sight, with ``consider_radar_face``; once the target is an iceberg, moved behind its face with only
    the depth's variance (as before); with an AIS track, nothing added (the hull's spread holds it)."""
    config = FusionConfig(consider_nav_bias=False, consider_radar_face=consider)
    fuser = Fuser(config)
    radar = make_track(1, "radar", 300.0, 0.0)
    radar.length_m = 12.0
    own = np.zeros(2)
    (first,) = fuser.step(0.0, {"radar": [radar]}, own)
    depth, sigma = config.radar_hidden_depth_length_fraction * 12.0, config.radar_hidden_depth_length_sigma_fraction * 12.0
    predicted = radar.predicted(0.0)[1]
    assert first.x[:2] == pytest.approx([300.0, 0.0])
    added = np.diag([depth ** 2 + sigma ** 2, 0.0]) if consider else np.zeros((2, 2))
    assert first.p[:2, :2] == pytest.approx(predicted[:2, :2] + added)
    assert first.p[2:, 2:] == pytest.approx(predicted[2:, 2:])
    (no_own,) = fuser.step(0.5, {"radar": [radar]})
    assert no_own.p[:2, :2] == pytest.approx(radar.predicted(0.5)[1][:2, :2])
    first.target.descriptor = "iceberg"
    (still,) = fuser.step(1.0, {"radar": [radar]}, own)
    assert still.x[:2] == pytest.approx([300.0 + depth, 0.0])
    assert still.p[:2, :2] == pytest.approx(radar.predicted(1.0)[1][:2, :2] + np.diag([sigma ** 2, 0.0]))
    ship = Fuser(config)
    ais = make_track(2, "ais", 300.0, 0.0, mmsi=257000001)
    (with_ais,) = ship.step(0.0, {"radar": [radar], "ais": [ais]}, own)
    assert "ais" in with_ais.sources
    plain = Fuser(FusionConfig(consider_nav_bias=False, consider_radar_face=False)).step(
        0.0, {"radar": [radar], "ais": [ais]}, own)[0]
    assert with_ais.p == pytest.approx(plain.p)


@pytest.mark.parametrize("consider", [False, True])
def test_the_lidars_near_side_offset_is_reported_in_the_covariance_not_the_state(consider):
    """A LiDAR track (var 1 m^2, 10 m long, extent 0.3 of it: 9 m^2 of offset) and a radar track 4 m east (var
    4 m^2): the fused position is the same either way; the reported variance gains 9 x (0.8)^2 = 5.76 m^2 (the
    LiDAR's weight 4 / 5) with ``consider_lidar_extent``."""
    fuser = Fuser(FusionConfig(consider_nav_bias=False, consider_lidar_extent=consider))
    lidar = make_track(1, "lidar", 0.0, 100.0, var=1.0)
    lidar.length_m, lidar.extent_sigma_fraction = 10.0, 0.3
    radar = make_track(2, "radar", 4.0, 100.0, var=4.0)
    (out,) = fuser.step(0.0, {"lidar": [lidar], "radar": [radar]})
    assert out.x[0] == pytest.approx(4.0 * 0.25 / 1.25)
    assert out.p[0, 0] == pytest.approx(1.0 / 1.25 + (9.0 * 0.8 ** 2 if consider else 0.0))


def test_a_velocity_the_ais_rules_out_is_left_out_of_the_state_and_of_the_reported_covariance():
    """An AIS ship going north at 5 m/s and a LiDAR track on it going south (its speed correlated with its east
    position): the fused course is the AIS's, and the reported covariance is that fusion's (the LiDAR's velocity
    and its correlations left out) with the LiDAR's near-side offset taken through the same weights, not through
    the weights of the LiDAR's velocity kept."""
    config = FusionConfig(consider_nav_bias=False, weigh_extent=False, weigh_hull=False)
    fuser = Fuser(config)
    ais = make_track(1, "ais", 0.0, 100.0, var=4.0, mmsi=257000001)
    ais.x[ekf.U] = 5.0
    ais.p[ekf.PSI, ekf.PSI], ais.p[ekf.U, ekf.U] = 0.01, 0.04
    lidar = make_track(2, "lidar", 1.0, 100.0, var=1.0)
    lidar.x[ekf.PSI], lidar.x[ekf.U] = np.pi, 5.0
    lidar.p[ekf.PSI, ekf.PSI], lidar.p[ekf.U, ekf.U] = 0.01, 0.04
    lidar.p[0, ekf.U] = lidar.p[ekf.U, 0] = 0.15  # correlation 0.75
    lidar.length_m, lidar.extent_sigma_fraction = 10.0, 0.3
    (out,) = fuser.step(0.0, {"ais": [ais], "lidar": [lidar]})
    assert out.sources == ["ais", "lidar"]
    assert out.x[ekf.PSI] == pytest.approx(0.0, abs=1e-6) and out.x[ekf.U] == pytest.approx(5.0, abs=1e-6)
    xs, ps = np.array([ais.x, lidar.x]), np.array([ais.p, lidar.p])
    gated = fusion_rules.without_stray_velocities(xs, ps, 0, fuser._velocity_gate)
    offset_m2 = np.array([0.0, lidar.extent_var_m2])
    expected = fuse(xs, gated)[1] + fusion_rules.consider_covariance(xs, gated, offset_m2)
    assert out.p == pytest.approx(expected)
    kept = fuse(xs, gated)[1] + fusion_rules.consider_covariance(xs, ps, offset_m2)
    assert not np.allclose(out.p, kept)  # the offset through the weights of the velocity kept differs


@pytest.mark.parametrize("across_m, own, smear, absorbed", [
    # half a beamwidth at 600 m is 27.2 m; the target's footprint 10 m (min_extent_m); 3 sigma 6 m
    (22.0, True, False, True),    # within the larger of the two (27.2 m + 3 sigma)
    (30.0, True, False, True),
    (40.0, True, False, False),   # resolved: a new target
    (40.0, True, True, True),     # within their sum (37.2 m + 3 sigma): the object's echo smeared by the beam
    (45.0, True, True, False),
    (22.0, False, True, False),   # without the own ship's position: the footprint alone
])
def test_a_new_radar_track_within_the_beams_resolution_of_a_target_is_absorbed(across_m, own, smear, absorbed):
    config = FusionConfig(radar_smear_beyond_size=smear)
    fuser = Fuser(config)
    own_m = np.array([0.0, 0.0]) if own else None
    first = make_track(1, "radar", 0.0, 600.0, var=4.0)
    fuser.step(1.0, {"radar": [first]}, own_m)
    second = make_track(2, "radar", across_m, 600.0, var=4.0)
    out = fuser.step(2.0, {"radar": [first, second]}, own_m)
    assert len(out) == (1 if absorbed else 2)
    assert 0.5 * 600.0 * np.radians(config.radar_beam_deg) == pytest.approx(27.2, abs=0.05)
    lidar = make_track(3, "lidar", -across_m, 600.0, var=4.0)  # the rule is the radar's: a LiDAR track is resolved
    assert len(fuser.step(3.0, {"radar": [first, second], "lidar": [lidar]}, own_m)) == len(out) + 1


def test_an_ais_track_is_never_absorbed():
    """harbour_approach seed 31: the moored supply ship's AIS track lay inside the footprint of the radar target of
    the pier it is moored to (one echo) and was absorbed: the ship was never reported with its MMSI. An AIS track
    inside a target without AIS joins it; inside an AIS ship's footprint it is a ship of its own."""
    fuser = Fuser(FusionConfig())
    fuser.lengths_by_mmsi = {257000002: 100.0, 257000003: 30.0}
    pier = make_track(1, "radar", 0.0, 0.0, var=4.0)
    pier.length_m = 120.0  # absorbing radius 90 m
    (radar_only,) = fuser.step(1.0, {"radar": [pier]})
    supply = make_track(5, "ais", 0.0, 70.0, var=5.0, mmsi=257000002)  # beyond the 60 m join distance
    (both,) = fuser.step(2.0, {"radar": [pier], "ais": [supply]})
    assert both.target.target_id == radar_only.target.target_id and both.target.mmsi == 257000002
    tug = make_track(6, "ais", 10.0, 60.0, var=5.0, mmsi=257000003)  # alongside the supply ship
    out = fuser.step(3.0, {"radar": [pier], "ais": [supply, tug]})
    assert sorted(e.target.mmsi for e in out if e.target.mmsi) == [257000002, 257000003]


def test_a_target_swollen_by_sidelobes_does_not_take_an_ais_ship_beyond_that_ships_length():
    """harbour_approach seed 31: the pier's radar target, its extent grown to 900 m by a sidelobe ring, took the AIS
    of an anchored 120 m tanker 400 m away (one object by the pier's footprint): the AIS ship's length decides."""
    fuser = Fuser(FusionConfig())
    fuser.lengths_by_mmsi = {257000201: 120.0}
    pier = make_track(1, "radar", 0.0, 0.0, var=4.0)
    pier.length_m = 900.0
    (first,) = fuser.step(1.0, {"radar": [pier]})
    tanker = make_track(5, "ais", -300.0, -260.0, var=5.0, mmsi=257000201)
    for t_s in (2.0, 3.0):
        out = fuser.step(t_s, {"radar": [pier], "ais": [tanker]})
        assert len(out) == 2 and sorted(e.sources for e in out) == [["ais"], ["radar"]]
        (pier_out,) = [e for e in out if e.sources == ["radar"]]
        assert pier_out.target.target_id == first.target.target_id and not pier_out.target.absorbed


@pytest.mark.parametrize("least_precise", [True, False])
def test_of_two_members_that_disagree_the_less_precise_leaves_and_the_target_keeps_the_better(least_precise):
    """A boat's LiDAR track (sd 2 m) and a radar track (sd 20 m) that joined its target and then lies 130 m away
    (beyond twice max_distance_m): with ``release_least_precise`` the radar track leaves and the target keeps its id
    with the LiDAR track; otherwise the LiDAR track, checked first as it joined first, leaves under a new id."""
    fuser = Fuser(FusionConfig(release_least_precise=least_precise))
    lidar = make_track(1, "lidar", 0.0, 0.0, var=4.0)
    (first,) = fuser.step(0.0, {"lidar": [lidar]})
    radar = make_track(2, "radar", 3.0, 0.0, var=400.0)
    (joined,) = fuser.step(1.0, {"lidar": [lidar], "radar": [radar]})
    assert joined.target.target_id == first.target.target_id and joined.sources == ["lidar", "radar"]
    radar.x[0] = 130.0
    out = fuser.step(2.0, {"lidar": [lidar], "radar": [radar]})
    by_sources = {tuple(e.sources): e.target.target_id for e in out}
    assert set(by_sources) == {("lidar",), ("radar",)}
    kept = ("lidar",) if least_precise else ("radar",)
    assert by_sources[kept] == first.target.target_id


@pytest.mark.parametrize("spread, kept", [(True, True), (False, False)])
def test_a_member_stays_with_an_ais_ship_whose_coasting_track_is_far_but_uncertain(spread, kept):
    """A moving boat's radar track 122 m from its AIS track, 30 s since the last report (sd 62 m each way): within
    the release gate, beyond twice max_distance_m (120 m). With ``release_beyond_ais_spread`` the limit grows by
    three of the AIS track's standard deviations and the radar track stays; without, it leaves under a new id.
    A still ship (speed under ``vessel_speed_mps``) keeps the plain limit."""
    fuser = Fuser(FusionConfig(release_beyond_ais_spread=spread))
    ais = make_track(1, "ais", 0.0, 0.0, var=4.0, mmsi=367000402)
    radar = make_track(2, "radar", 3.0, 0.0, var=16.0)
    ais.x[ekf.U] = radar.x[ekf.U] = 5.0  # heading north at 5 m/s: a moving ship (a still one's coast is not spread)
    (joined,) = fuser.step(0.0, {"ais": [ais], "radar": [radar]})
    assert joined.sources == ["ais", "radar"]
    ais.x[0], ais.p[0, 0], ais.p[1, 1] = 125.0, 3800.0, 3800.0
    out = fuser.step(1.0, {"ais": [ais], "radar": [radar]})
    assert len(out) == (1 if kept else 2)
    assert out[0].target.target_id == joined.target.target_id and out[0].sources == (["ais", "radar"] if kept else ["ais"])


def test_a_still_ais_ships_coast_does_not_hold_a_far_member():
    """The same far member against an AIS ship at anchor (speed 0): released under the plain limit, as before."""
    fuser = Fuser(FusionConfig())
    ais = make_track(1, "ais", 0.0, 0.0, var=4.0, mmsi=367000402)
    radar = make_track(2, "radar", 3.0, 0.0, var=16.0)
    fuser.step(0.0, {"ais": [ais], "radar": [radar]})
    ais.x[0], ais.p[0, 0], ais.p[1, 1] = 125.0, 3800.0, 3800.0
    assert len(fuser.step(1.0, {"ais": [ais], "radar": [radar]})) == 2


def test_a_broken_ais_covariance_does_not_hold_a_far_member_for_ever():
    """The release test's widening by the AIS coast is left out where that covariance is not finite: a member 500 m
    off leaves (a NaN limit would keep it for good)."""
    fuser = Fuser(FusionConfig())
    far, summed = np.array([500.0, 0.0]), 4.0 * np.eye(2)
    for broken in (np.full((2, 2), np.nan), np.diag([np.inf, 1.0])):  # the gate test cannot tell either
        with np.errstate(invalid="ignore"):  # inf x 0 in the gate's algebra
            assert fuser._released(far, summed + broken, broken)
    coast = np.diag([1e5, 1.0])  # sd 316 m east: within the gate and within 120 + 3 x 316 m
    assert not fuser._released(far, summed + coast, coast)

