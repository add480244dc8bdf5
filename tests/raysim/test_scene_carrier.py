"""The ray engine's pose bank against the motions, and the own ship through CarrierScene (real Embree, no mocks)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from raysim.motion import ConstantVelocity, Stationary
from raysim.scene import SEA_ID, Scene, intersect_sea

from .scene_helpers import brute_force, make_object


# ------------------------------------------------------ pose bank, carrier


class _Circling:
    """A motion of a kind the engine does not know (asked object by object): a pitching circle."""

    max_speed_mps = 6.0 * 1.001

    def poses(self, t_s):
        from raysim.pose import Poses

        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        a = 0.2 * t
        pos = np.column_stack([60.0 + 30.0 * np.cos(a), -20.0 + 30.0 * np.sin(a), 0.2 * np.sin(t)])
        return Poses(pos, a + np.pi / 2, 0.05 * np.sin(0.7 * t), 0.08 * np.cos(0.9 * t))

    def velocity_mps(self, t_s):
        raise NotImplementedError

    def yaw_rate_rps(self, t_s):
        raise NotImplementedError


def _motions_of_every_kind():
    from raysim.motion import ShipMotion, WaveMotion, waypoint_track

    track = waypoint_track(np.array([[-40.0, 30.0], [40.0, 35.0], [60.0, -20.0]]), 6.0, 30.0, 4.0)
    rolling = waypoint_track(np.array([[-30.0, 60.0], [50.0, 70.0]]), 5.0, 30.0, 4.0)
    waves = WaveMotion(4.0, 5.0, 2.0, 4.0, 0.4, 6.0, np.random.default_rng(3))
    other = waypoint_track(np.array([[-50.0, -10.0], [-20.0, -60.0]]), 4.0, 30.0, 4.0)
    still = waypoint_track(np.array([[25.0, -30.0]]), 0.0, 30.0, 4.0, heading_rad=0.4)  # a one-sample track
    return [
        ConstantVelocity((30.0, -5.0, 0.0), (3.0, -1.0, 0.0), 0.2, 0.1),
        ShipMotion(track),
        ShipMotion(rolling, waves),
        other,
        ShipMotion(still, waves),
        _Circling(),
    ]


def test_pose_bank_matches_each_motion():
    from raysim.scene.poses import PoseBank as _PoseBank

    motions = _motions_of_every_kind()
    bank = _PoseBank(motions)
    rng = np.random.default_rng(11)
    label = np.sort(rng.integers(0, len(motions), 4000))
    t = rng.uniform(-1.0, 45.0, label.size)  # also before the start and after the end of the tracks
    position, yaw, pitch, roll = bank.poses(label, t)
    for k, m in enumerate(motions):
        j = np.flatnonzero(label == k)
        ref = m.poses(t[j])
        np.testing.assert_array_equal(position[:, j].T, ref.position_m)
        np.testing.assert_array_equal(yaw[j], ref.yaw_rad)
        np.testing.assert_array_equal(pitch[j], ref.pitch_rad)
        np.testing.assert_array_equal(roll[j], ref.roll_rad)
        one = bank.poses(k, t[j])  # one object for all pairs
        np.testing.assert_array_equal(one[0].T, ref.position_m)
        np.testing.assert_array_equal(one[1], ref.yaw_rad)
        for got, want in zip(one[2:], (ref.pitch_rad, ref.roll_rad)):
            np.testing.assert_array_equal(np.zeros_like(want) if got is None else got, want)
    planar = bank.poses(np.array([0, 1, 3]), np.array([1.0, 2.0, 3.0]))
    assert planar[2] is None and planar[3] is None  # no pitch or roll anywhere: yaw-only path


def _own_ship_scene(with_others: bool = True):
    """An own ship (deck box and mast, rolling and pitching on a turning track) and other objects."""
    from raysim.motion import ShipMotion, WaveMotion, waypoint_track

    track = waypoint_track(np.array([[0.0, 0.0], [30.0, 10.0], [40.0, 50.0]]), 5.0, 30.0, 3.0)
    own_motion = ShipMotion(track, WaveMotion(5.0, 4.0, 2.0, 3.5, 0.3, 5.0, np.random.default_rng(4)))
    deck = trimesh.creation.box(extents=(12.0, 5.0, 2.0))
    mast = trimesh.creation.box(extents=(0.6, 0.6, 6.0))
    mast.apply_translation((-2.0, 0.0, 3.0))
    hull = trimesh.util.concatenate([deck, mast])
    own = make_object(0, hull, own_motion, materials=np.arange(len(hull.faces)) % 5 + 10)
    objects = [own]
    if with_others:
        for k, m in enumerate(_motions_of_every_kind()):
            ext = (8.0 + 2 * k, 3.0, 3.0)
            objects.append(make_object(1 + k, trimesh.creation.box(extents=ext), m, materials=np.full(12, k)))
        objects.append(make_object(20, trimesh.creation.icosphere(subdivisions=2, radius=6.0), Stationary((-30.0, -25.0, 0.0))))
    return objects, own_motion


def _sensor_rays(motion, n_azimuths: int = 400, mount=(1.5, 0.0, 3.0)):
    """HDL-like rays from a sensor mounted on the own ship: body-frame and world rays, rotations."""
    el = np.radians(np.linspace(-30.67, 10.67, 32))
    az = np.linspace(-np.pi, np.pi, n_azimuths, endpoint=False)
    a, e = np.meshgrid(az, el, indexing="ij")
    d_b = np.column_stack([(np.cos(e) * np.cos(a)).ravel(), (np.cos(e) * np.sin(a)).ravel(), np.sin(e).ravel()])
    o_b = np.tile(mount, (len(d_b), 1))
    times = np.repeat(np.linspace(2.0, 2.1, n_azimuths), 32)
    poses = motion.poses(times)
    r = poses.rotation()
    o = np.einsum("nij,nj->ni", r, o_b) + poses.position_m
    d = np.einsum("nij,nj->ni", r, d_b)
    return o, d, times, o_b, d_b, r


def _carrier_cast(objects, o, d, times, o_b, d_b, r, carrier_id=0, **kwargs):
    """CarrierScene's hits, own-ship normals rotated to the world frame with ``r`` (as a sensor does)."""
    from raysim.sensors.carrier import CarrierScene

    sea = kwargs.pop("sea", True)
    hits, on_carrier = CarrierScene(objects, carrier_id=carrier_id, sea_material=kwargs.pop("sea_material", -1),
                                    sea=sea).cast(o, d, times, o_b, d_b, **kwargs)
    hits.normal[on_carrier] = np.einsum("nij,nj->ni", r[on_carrier], hits.normal[on_carrier].astype(np.float64))
    return hits


@pytest.mark.parametrize("sea", [False, True])
def test_carrier_fast_path_equals_plain_cast(sea):
    objects, motion = _own_ship_scene()
    o, d, times, o_b, d_b, r = _sensor_rays(motion)
    ref_range, ref_ids = brute_force(objects, o, d, times)
    assert (ref_ids == 0).sum() > 500 and len(np.unique(ref_ids[ref_ids > 0])) >= 4  # sees its deck, mast and others
    scene = Scene(objects, sea=sea, sea_material=9)
    plain = scene.cast(o, d, times)
    fast = _carrier_cast(objects, o, d, times, o_b, d_b, r, sea=sea, sea_material=9)
    exp_ids, exp_range = ref_ids, ref_range
    if sea:
        sea_t = intersect_sea(o[:, 2], d[:, 2])
        exp_ids = np.where(sea_t < ref_range, SEA_ID, ref_ids)
        exp_range = np.minimum(ref_range, sea_t)
    for hits in (plain, fast):
        np.testing.assert_array_equal(hits.object_id, exp_ids)
        np.testing.assert_allclose(hits.range_m, exp_range, rtol=0, atol=5e-4)
    np.testing.assert_array_equal(fast.primitive, plain.primitive)
    np.testing.assert_array_equal(fast.material, plain.material)
    np.testing.assert_allclose(fast.normal, plain.normal, atol=1e-5)
    own = fast.object_id == 0
    assert np.all(fast.material[own] >= 10) and np.all(np.einsum("ij,ij->i", fast.normal, d) <= 1e-7)
    # the deck seen from above: world normal = the ship's body z axis
    top = own & (np.abs(fast.range_m - (3.0 - 1.0) / -d_b[:, 2]) < 1e-3) & (d_b[:, 2] < -0.5)
    assert top.sum() > 50
    np.testing.assert_allclose(fast.normal[top], r[top][:, :, 2], atol=1e-5)
    # a range limit, and brute-force (no culling) mode
    limited = _carrier_cast(objects, o, d, times, o_b, d_b, r, max_range_m=20.0)
    expected = Scene(objects, sea=True, cull=False).cast(o, d, times, max_range_m=20.0)
    np.testing.assert_array_equal(limited.object_id, expected.object_id)
    np.testing.assert_allclose(limited.range_m, expected.range_m, rtol=0, atol=5e-4)


def test_carrier_alone_and_bad_carriers():
    from raysim.sensors.carrier import CarrierScene

    objects, motion = _own_ship_scene(with_others=False)
    o, d, times, o_b, d_b, r = _sensor_rays(motion, n_azimuths=100)
    scene = Scene(objects, sea=True)
    fast = _carrier_cast(objects, o, d, times, o_b, d_b, r)
    plain = scene.cast(o, d, times)
    np.testing.assert_array_equal(fast.object_id, plain.object_id)
    assert (fast.object_id == 0).sum() > 100
    # an id that is no object of the scene: no carrier, the world cast as usual
    other = _carrier_cast(objects, o, d, times, o_b, d_b, r, carrier_id=77)
    np.testing.assert_array_equal(other.object_id, plain.object_id)
    with pytest.raises(ValueError):
        CarrierScene(objects).cast(o, d, times, o_b[:-1], d_b)
    with pytest.raises(ValueError):
        CarrierScene(objects).cast(o, d, times, o_b, d_b[:, :2])
