"""Ray engine against analytic answers (real Embree through Open3D, no mocks)."""

from __future__ import annotations

import numpy as np
import open3d as o3d
import pytest
import trimesh

from raysim.motion import ConstantVelocity, Stationary
from raysim.pose import rotation_matrices
from raysim.scene import NO_HIT, SEA_ID, Hits, Scene, SceneObject, intersect_sea, pseudo_azimuth



from .scene_helpers import MM, brute_force, make_object, quad, rays_towards, slab, unit, world_to_body  # noqa: F401


# ------------------------------------------------------------ plane / sphere


@pytest.mark.parametrize(
    "origin, plane_x",
    [
        ((0.0, 0.0, 1.0), 25.0),  # near
        ((0.0, 0.0, 3.0), 1500.0),  # plane 1.5 km away
        ((1480.0, -900.0, 5.0), 1510.0),  # sensor and plane about 1.75 km from the world origin
    ],
)
def test_plane_ranges_analytic(origin, plane_x):
    rng = np.random.default_rng(1)
    half = 400.0
    # a second static object far away moves the static scene offset off the plane
    far = make_object(9, trimesh.creation.box(extents=(2, 2, 2)), Stationary((plane_x - 3000.0, 2000.0, 0.0)))
    plane = make_object(3, quad(half), Stationary((plane_x, origin[1], origin[2])))
    scene = Scene([plane, far], sea=False)
    dist = plane_x - origin[0]
    # oblique rays: up to ~60 deg off the plane normal, staying inside the quad
    max_off = min(np.tan(np.radians(60)) * dist, 0.9 * half) / np.sqrt(2)
    targets = np.column_stack(
        [np.full(2000, plane_x), origin[1] + rng.uniform(-max_off, max_off, 2000), origin[2] + rng.uniform(-max_off, max_off, 2000)]
    )
    o, d = rays_towards(origin, targets)
    hits = scene.cast(o, d, np.zeros(len(o)))
    expected = dist / d[:, 0]
    assert np.all(hits.object_id == 3)
    np.testing.assert_allclose(hits.range_m, expected, rtol=0, atol=MM)
    np.testing.assert_allclose(hits.normal, np.tile([-1.0, 0.0, 0.0], (len(o), 1)), atol=1e-6)
    assert np.all(np.isin(hits.primitive, [0, 1]))


def test_sphere_ranges_analytic():
    rng = np.random.default_rng(2)
    radius, centre = 5.0, np.array([20.0, 6.0, 2.0])
    mesh = trimesh.creation.icosphere(subdivisions=6, radius=radius)
    scene = Scene([make_object(1, mesh, Stationary(centre))], sea=False)
    origin = np.array([0.0, 0.0, 1.5])
    # aim at points of the sphere's disc seen from the origin, within 70 % of its radius
    axis = unit(centre - origin)
    e1 = unit(np.cross(axis, [0.0, 0.0, 1.0]))
    e2 = np.cross(axis, e1)
    r = 0.7 * radius * np.sqrt(rng.uniform(0, 1, 5000))
    phi = rng.uniform(0, 2 * np.pi, 5000)
    targets = centre + (r * np.cos(phi))[:, None] * e1 + (r * np.sin(phi))[:, None] * e2
    o, d = rays_towards(origin, targets)
    hits = scene.cast(o, d, np.zeros(len(o)))
    w = o - centre
    b = np.einsum("ij,ij->i", w, d)
    expected = -b - np.sqrt(b * b - (np.einsum("ij,ij->i", w, w) - radius**2))
    assert np.all(hits.object_id == 1)
    np.testing.assert_allclose(hits.range_m, expected, rtol=0, atol=MM)
    radial = unit(o + expected[:, None] * d - centre)
    assert np.all(np.einsum("ij,ij->i", hits.normal, radial) > 0.999)
    assert np.all(np.einsum("ij,ij->i", hits.normal, d) <= 0)


# -------------------------------------------------------------------- boxes


def test_static_box_ranges_and_normals():
    rng = np.random.default_rng(3)
    ext = np.array([4.0, 2.0, 3.0])
    pos, yaw = np.array([15.0, -3.0, 1.0]), 0.6
    scene = Scene([make_object(7, trimesh.creation.box(extents=ext), Stationary(pos, yaw))], sea=False)
    origin = np.array([0.0, 0.0, 2.0])
    # targets inside the box -> every ray hits; plus some clear misses
    r = rotation_matrices(np.array([yaw]), np.zeros(1), np.zeros(1))[0]
    inside = pos + (rng.uniform(-0.5, 0.5, (3000, 3)) * ext) @ r.T
    outside = pos + np.array([0.0, 0.0, 10.0]) + rng.uniform(-1, 1, (500, 3))
    o, d = rays_towards(origin, np.vstack([inside, outside]))
    hits = scene.cast(o, d, np.zeros(len(o)))
    o_b, d_b, _ = world_to_body(o, d, pos, yaw)
    expected, axis, sign, gap = slab(o_b, d_b, ext / 2)
    assert np.all(np.isfinite(expected[:3000])) and np.all(np.isinf(expected[3000:]))
    np.testing.assert_array_equal(hits.object_id, np.where(np.isfinite(expected), 7, NO_HIT))
    np.testing.assert_allclose(hits.range_m[:3000], expected[:3000], rtol=0, atol=MM)
    assert np.all(np.isinf(hits.range_m[3000:]))
    n_body = np.zeros((len(o), 3))
    n_body[np.arange(len(o)), axis] = sign
    n_world = n_body @ r.T
    clear = np.isfinite(expected) & (gap > 1e-3)
    np.testing.assert_allclose(hits.normal[clear], n_world[clear], atol=1e-5)
    np.testing.assert_array_equal(hits.normal[3000:], 0.0)
    assert hits.normal.dtype == np.float32 and hits.range_m.dtype == np.float64


def moving_box_rays(motion: ConstantVelocity, ext: np.ndarray, n: int, duration_s: float, seed: int):
    """Rays from near the origin aimed inside a moving box at each ray's own time."""
    rng = np.random.default_rng(seed)
    times = np.sort(rng.uniform(0, duration_s, n))
    poses = motion.poses(times)
    r = poses.rotation()
    targets = poses.position_m + np.einsum("nij,nj->ni", r, rng.uniform(-0.45, 0.45, (n, 3)) * ext)
    origins = rng.normal(0, 0.2, (n, 3)) + [0.0, 0.0, 2.0]
    return origins, unit(targets - origins), times


@pytest.mark.parametrize(
    "motion",
    [
        ConstantVelocity((-5.0, 20.0, 0.5), (10.0, 0.0, 0.0), yaw_rad=0.3),  # 10 m/s
        ConstantVelocity((12.0, -8.0, 0.5), (0.0, 0.0, 0.0), yaw_rad=0.0, yaw_rate_rps=1.2),  # yawing only
        ConstantVelocity((-30.0, -4.0, 0.5), (0.0, 8.0, 0.0), yaw_rad=1.0, yaw_rate_rps=-0.5),  # across +-pi azimuth
    ],
)
def test_moving_box_hit_at_each_rays_own_time(motion):
    ext = np.array([6.0, 2.5, 2.0])
    scene = Scene([make_object(4, trimesh.creation.box(extents=ext), motion)], sea=False)
    o, d, times = moving_box_rays(motion, ext, 3000, 1.0, seed=4)
    hits = scene.cast(o, d, times)
    poses = motion.poses(times)
    o_b, d_b, _ = world_to_body(o, d, poses.position_m, poses.yaw_rad)
    expected, *_ = slab(o_b, d_b, ext / 2)
    assert np.all(np.isfinite(expected))
    assert np.all(hits.object_id == 4)
    np.testing.assert_allclose(hits.range_m, expected, rtol=0, atol=MM)
    # the answer really depends on each ray's time: a frozen box at t=0.5 s would differ
    p0 = motion.poses(np.full(len(o), 0.5))
    o_f, d_f, _ = world_to_body(o, d, p0.position_m, p0.yaw_rad)
    frozen, *_ = slab(o_f, d_f, ext / 2)
    differs = ~np.isclose(np.nan_to_num(frozen, posinf=1e9), expected, atol=0.05)
    assert differs.mean() > 0.5
    assert np.all(np.einsum("ij,ij->i", hits.normal, d) <= 0)
    np.testing.assert_allclose(np.linalg.norm(hits.normal, axis=1), 1.0, atol=1e-6)


# ------------------------------------------------------ occlusion, sea, range


def test_first_hit_wins_static():
    big = make_object(1, trimesh.creation.box(extents=(1, 10, 10)), Stationary((20.0, 0.0, 0.0)))
    small = make_object(2, trimesh.creation.box(extents=(1, 1, 1)), Stationary((30.0, 0.0, 0.0)))
    scene = Scene([small, big], sea=False)
    rng = np.random.default_rng(5)
    o, d = rays_towards((0.0, 0.0, 0.0), np.column_stack([np.full(500, 30.0), rng.uniform(-0.4, 0.4, (500, 2))]))
    hits = scene.cast(o, d, np.zeros(500))
    assert np.all(hits.object_id == 1)
    np.testing.assert_allclose(hits.range_m, 19.5 / d[:, 0], atol=MM)
    # without the big box the same rays hit the small one
    hits2 = Scene([small], sea=False).cast(o, d, np.zeros(500))
    assert np.all(hits2.object_id == 2)


@pytest.mark.parametrize("moving_in_front", [True, False])
def test_static_and_moving_occlude_each_other(moving_in_front):
    near_x, far_x = 20.0, 35.0
    mx, sx = (near_x, far_x) if moving_in_front else (far_x, near_x)
    moving = make_object(11, trimesh.creation.box(extents=(1, 8, 8)), ConstantVelocity((mx, -0.5, 0.0), (0.0, 1.0, 0.0)))
    static = make_object(12, trimesh.creation.box(extents=(1, 8, 8)), Stationary((sx, 0.0, 0.0)))
    scene = Scene([static, moving], sea=False)
    rng = np.random.default_rng(6)
    times = rng.uniform(0, 1, 400)
    o, d = rays_towards((0.0, 0.0, 0.0), np.column_stack([np.full(400, 50.0), rng.uniform(-2, 2, (400, 2))]))
    hits = scene.cast(o, d, times)
    assert np.all(hits.object_id == (11 if moving_in_front else 12))
    np.testing.assert_allclose(hits.range_m, (near_x - 0.5) / d[:, 0], atol=MM)


def test_sea_hit_for_downward_rays():
    h = 3.0
    elev = np.radians(np.linspace(-30.67, -1.0, 24))
    az = np.linspace(-np.pi, np.pi, 24)
    e, a = np.meshgrid(elev, az)
    d = np.column_stack([(np.cos(e) * np.cos(a)).ravel(), (np.cos(e) * np.sin(a)).ravel(), np.sin(e).ravel()])
    o = np.tile([100.0, -50.0, h], (len(d), 1))
    up = d * [1, 1, -1]  # the same rays pointing up miss the sea
    scene = Scene([], sea=True, sea_material=5)
    hits = scene.cast(np.vstack([o, o]), np.vstack([d, up]), np.zeros(2 * len(d)))
    n = len(d)
    np.testing.assert_allclose(hits.range_m[:n], h / np.sin(-e.ravel()), rtol=0, atol=MM)
    assert np.all(hits.object_id[:n] == SEA_ID) and np.all(hits.object_id[n:] == NO_HIT)
    assert np.all(hits.material[:n] == 5) and np.all(hits.material[n:] == -1)
    assert np.all(hits.primitive == -1)
    np.testing.assert_array_equal(hits.normal[:n], np.tile([0, 0, 1], (n, 1)))
    assert np.all(np.isinf(hits.range_m[n:]))
    none = Scene([], sea=False).cast(o, d, np.zeros(n))
    assert np.all(none.object_id == NO_HIT) and np.all(np.isinf(none.range_m))


def test_sea_hides_underwater_part_and_objects_hide_sea():
    # a box half under water: rays aimed at its underwater part hit the sea first
    box = make_object(1, trimesh.creation.box(extents=(2, 6, 4)), Stationary((20.0, 0.0, 0.0)), np.full(12, 4))
    o = np.tile([0.0, 0.0, 2.0], (2, 1))
    d = unit(np.array([[19.0, 0.0, -3.0], [19.0, 0.0, 1.0]]) - o)  # below / above the waterline
    for cull in (True, False):
        hits = Scene([box], sea=True, sea_material=9, cull=cull).cast(o, d, np.zeros(2))
        assert hits.object_id.tolist() == [SEA_ID, 1]
        np.testing.assert_allclose(hits.range_m[0], 2.0 / -d[0, 2], atol=MM)
        assert hits.material.tolist() == [9, 4] and hits.primitive[0] == -1 and hits.primitive[1] >= 0
        np.testing.assert_array_equal(hits.normal, [[0, 0, 1], [-1, 0, 0]])


def test_intersect_sea_function():
    t = intersect_sea(np.array([3.0, 3.0, 3.0, -2.0, 0.0]), np.array([-0.5, 0.5, 0.0, 0.25, 0.0]))
    np.testing.assert_allclose(t, [6.0, np.inf, np.inf, 8.0, np.inf])


def test_max_range_respected():
    wall = make_object(1, quad(50.0), Stationary((40.0, 0.0, 0.0)))
    mover = make_object(2, trimesh.creation.box(extents=(1, 4, 4)), ConstantVelocity((25.0, 0.0, 0.0), (1.0, 0.0, 0.0)))
    scene = Scene([wall, mover], sea=True)
    o = np.zeros((4, 3)) + [0.0, 0.0, 1.0]
    d = unit(np.array([[1.0, 0.0, 0.0], [1.0, 0.5, 0.0], [1.0, 0.0, -0.2], [1.0, 0.0, -0.01]]))
    t = np.zeros(4)
    full = scene.cast(o, d, t)
    assert full.object_id.tolist() == [2, 1, SEA_ID, 2]
    lim = scene.cast(o, d, t, max_range_m=20.0)
    assert lim.object_id.tolist() == [NO_HIT, NO_HIT, SEA_ID, NO_HIT]
    assert np.all(np.isinf(lim.range_m[[0, 1, 3]]))
    per_ray = scene.cast(o, d, t, max_range_m=np.array([30.0, 30.0, 30.0, 10.0]))
    assert per_ray.object_id.tolist() == [2, NO_HIT, SEA_ID, NO_HIT]
    assert np.all(per_ray.normal[[1, 3]] == 0) and np.all(per_ray.material[[1, 3]] == -1)


# --------------------------------------------------- ids, materials, primitives


def _hit_triangle_contains(hits: Hits, o, d, world_vertices, faces) -> np.ndarray:
    """Whether each hit point lies on (inside) the reported triangle."""
    p = o + hits.range_m[:, None] * d
    tri = world_vertices[faces[hits.primitive]]
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = unit(np.cross(b - a, c - a))
    on_plane = np.abs(np.einsum("ij,ij->i", p - a, n)) < 1e-3
    inside = np.ones(len(p), bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, p - u), n) >= -1e-3
    return on_plane & inside


@pytest.mark.parametrize("moving", [False, True])
def test_ids_materials_primitives(moving):
    rng = np.random.default_rng(7)
    box_a = trimesh.creation.box(extents=(3, 3, 3))
    box_b = trimesh.creation.icosphere(subdivisions=2, radius=2.0)
    pa, pb = np.array([15.0, 5.0, 0.0]), np.array([10.0, -8.0, 1.0])
    motion_a = ConstantVelocity(pa, (0.0, 0.0, 0.0), 0.4) if moving else Stationary(pa, 0.4)
    obj_a = make_object(21, box_a, motion_a, materials=100 + np.arange(len(box_a.faces)))
    motion_b = ConstantVelocity(pb, (0.0, 0.0, 0.0), 0.0, 0.1) if moving else Stationary(pb)
    obj_b = make_object(22, box_b, motion_b, materials=np.full(len(box_b.faces), 7))
    scene = Scene([obj_b, obj_a], sea=False)
    ra = rotation_matrices(np.array([0.4]), np.zeros(1), np.zeros(1))[0]
    targets = np.vstack([pa + rng.uniform(-1.4, 1.4, (800, 3)) @ ra.T, pb + rng.uniform(-1, 1, (800, 3))])
    o, d = rays_towards((0.0, -6.0, 8.0), targets)  # sees three faces of box a
    hits = scene.cast(o, d, np.zeros(len(o)))
    ids = hits.object_id
    assert np.all(ids[:800] == 21) and np.all(ids[800:] == 22)
    np.testing.assert_array_equal(hits.material[:800], 100 + hits.primitive[:800])
    assert len(np.unique(hits.primitive[:800])) >= 4
    assert np.all(hits.material[800:] == 7)
    assert _hit_triangle_contains(_sub(hits, slice(0, 800)), o[:800], d[:800], box_a.vertices @ ra.T + pa, box_a.faces).all()
    assert _hit_triangle_contains(_sub(hits, slice(800, None)), o[800:], d[800:], box_b.vertices + pb, box_b.faces).all()
    assert hits.primitive.dtype == np.int32 and hits.material.dtype == np.int16 and hits.object_id.dtype == np.int32


def _sub(h: Hits, s) -> Hits:
    return Hits(h.range_m[s], h.object_id[s], h.normal[s], h.material[s], h.primitive[s])


# ------------------------------------------------------- culling vs brute force


def test_culling_matches_brute_force_with_50_moving_boxes():
    """50 boxes around the sensor plus the ship carrying it; culled cast == brute force."""
    rng = np.random.default_rng(8)
    objects = []
    for i in range(50):
        dist, az = rng.uniform(15, 300), rng.uniform(-np.pi, np.pi)
        ext = rng.uniform([4, 2, 2], [30, 8, 8])
        motion = ConstantVelocity(
            (dist * np.cos(az), dist * np.sin(az), rng.uniform(-1, 1)),
            rng.uniform(-8, 8, 3) * [1, 1, 0.1],
            rng.uniform(-np.pi, np.pi),
            rng.uniform(-0.5, 0.5),
        )
        objects.append(make_object(i, trimesh.creation.box(extents=ext), motion))
    # the ship carrying the sensor: its sphere contains every ray origin (seen in every direction)
    own = ConstantVelocity((0.0, 0.0, 0.0), (5.0, 0.0, 0.0), 0.0, 0.3)
    objects.append(make_object(50, trimesh.creation.box(extents=(12.0, 5.0, 2.0)), own))
    # HDL-32E-like batch: 32 lasers, 1000 azimuths over 360 deg in 0.1 s, sensor moving at 5 m/s
    el = np.radians(np.linspace(-30.67, 10.67, 32))
    azi = np.linspace(-np.pi, np.pi, 1000, endpoint=False)
    a, e = np.meshgrid(azi, el, indexing="ij")
    d = np.column_stack([(np.cos(e) * np.cos(a)).ravel(), (np.cos(e) * np.sin(a)).ravel(), np.sin(e).ravel()])
    times = np.repeat(np.linspace(0, 0.1, 1000), 32)
    o = np.column_stack([5.0 * times, np.zeros_like(times), np.full_like(times, 3.0)])
    culled = Scene(objects, sea=False).cast(o, d, times)
    ref_range, ref_ids = brute_force(objects, o, d, times)
    assert (ref_ids >= 0).sum() > 1000  # the test means something
    assert len(np.unique(ref_ids[ref_ids >= 0])) > 10 and (ref_ids == 50).sum() > 100
    np.testing.assert_array_equal(culled.object_id, ref_ids)
    np.testing.assert_allclose(culled.range_m, ref_range, rtol=0, atol=5e-4)  # float32 rounding differs: the engine casts from near each object
    no_cull = Scene(objects, sea=False, cull=False).cast(o, d, times)
    np.testing.assert_array_equal(no_cull.object_id, culled.object_id)
    # with the sea (culling by the sea's nearer hits) and a range limit, still exact
    scene = Scene(objects, sea=True)
    with_sea = scene.cast(o, d, times, max_range_m=150.0)
    sea_t = intersect_sea(o[:, 2], d[:, 2])
    exp_ids = np.where(ref_range < sea_t, ref_ids, SEA_ID)
    exp_range = np.minimum(ref_range, sea_t)
    exp_ids[exp_range > 150.0] = NO_HIT
    np.testing.assert_array_equal(with_sea.object_id, exp_ids)


def test_moving_objects_share_one_acceleration_structure():
    box = trimesh.creation.box(extents=(2, 2, 2))
    objs = [make_object(i, box, ConstantVelocity((10.0 * (i + 1), 0.0, 0.0), (1.0, 0.0, 0.0))) for i in range(5)]
    objs.append(make_object(9, trimesh.creation.box(extents=(3, 2, 2)), ConstantVelocity((0.0, 10.0, 0.0), (0.0, 0.0, 0.0), 0, 1)))
    scene = Scene(objs)
    assert scene.n_bodies == 2  # distinct meshes
    assert scene.n_atlas_geometries == 6  # one structure holding each moving object once


# ------------------------------------------------------------------- edges


def test_vertical_rays_and_empty_batch():
    roof = make_object(1, trimesh.creation.box(extents=(4, 4, 1)), Stationary((0.5, 0.0, 20.0)))
    mover = make_object(2, trimesh.creation.box(extents=(4, 4, 1)), ConstantVelocity((0.0, 0.5, -10.0), (0.0, 0.0, 0.0), 0, 0.3))
    scene = Scene([roof, mover], sea=False)
    o = np.array([[0.0, 0.0, 2.0], [0.0, 0.0, 2.0], [10.0, 10.0, 2.0]])
    d = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])
    hits = scene.cast(o, d, np.array([0.0, 0.5, 1.0]))
    assert hits.object_id.tolist() == [1, 2, NO_HIT]
    np.testing.assert_allclose(hits.range_m[:2], [17.5, 11.5], atol=MM)
    np.testing.assert_allclose(hits.normal[:2], [[0, 0, -1], [0, 0, 1]], atol=1e-6)
    sea_scene = Scene([roof], sea=True)
    down = sea_scene.cast(o[1:2], d[1:2], np.zeros(1))
    assert down.object_id[0] == SEA_ID and down.range_m[0] == pytest.approx(2.0)
    empty = scene.cast(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0))
    assert empty.range_m.shape == (0,) and empty.normal.shape == (0, 3) and empty.object_id.dtype == np.int32


def test_pseudo_azimuth_is_monotonic():
    ang = np.linspace(-np.pi + 1e-9, np.pi, 10001)
    p = pseudo_azimuth(np.cos(ang), np.sin(ang))
    assert np.all(np.diff(p) > 0) and p[0] >= -2 and p[-1] <= 2


def test_bad_shapes_rejected():
    scene = Scene([], sea=True)
    with pytest.raises(ValueError):
        scene.cast(np.zeros((3, 3)), np.zeros((3, 2)), np.zeros(3))
    with pytest.raises(ValueError):
        scene.cast(np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(3), max_range_m=np.ones(2))


# ------------------------------------------------- static culling vs plain cast


def static_reference(objects: list[SceneObject], o, d) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All static objects in one plain Open3D scene, every ray cast: range, id, primitive."""
    sc = o3d.t.geometry.RaycastingScene()
    for obj in objects:
        pose = obj.motion.poses(np.zeros(1))
        world = obj.vertices_m @ pose.rotation()[0].T + pose.position_m[0]
        sc.add_triangles(o3d.core.Tensor(world.astype(np.float32)), o3d.core.Tensor(obj.faces.astype(np.uint32)))
    res = sc.cast_rays(o3d.core.Tensor(np.hstack([o, d]).astype(np.float32)))
    gid = res["geometry_ids"].numpy().view(np.int32)
    ids = np.where(gid >= 0, np.array([x.object_id for x in objects] + [NO_HIT])[gid], NO_HIT)
    return res["t_hit"].numpy().astype(float), ids, res["primitive_ids"].numpy().view(np.int32)


def hdl_like_rays(n_azimuths: int, origin=(0.0, 0.0, 3.0)):
    el = np.radians(np.linspace(-30.67, 10.67, 32))
    az = np.linspace(-np.pi, np.pi, n_azimuths, endpoint=False)
    a, e = np.meshgrid(az, el, indexing="ij")
    d = np.column_stack([(np.cos(e) * np.cos(a)).ravel(), (np.cos(e) * np.sin(a)).ravel(), np.sin(e).ravel()])
    return np.tile(origin, (len(d), 1)), d


@pytest.mark.parametrize("dense", [False, True])
def test_static_culling_matches_plain_cast(dense):
    rng = np.random.default_rng(9)
    objects = []
    for i in range(12):
        dist = rng.uniform(15, 30) if dense else rng.uniform(60, 400)
        az = rng.uniform(-np.pi, np.pi)
        mesh = trimesh.creation.icosphere(subdivisions=3, radius=rng.uniform(4, 12))
        mats = rng.integers(0, 5, len(mesh.faces))
        objects.append(make_object(i, mesh, Stationary((dist * np.cos(az), dist * np.sin(az), 0.0)), mats))
    o, d = hdl_like_rays(3000, origin=(5.0, -3.0, 3.0))
    t = np.zeros(len(o))
    ref_t, ref_id, ref_prim = static_reference(objects, o, d)
    assert (ref_id >= 0).mean() > (0.3 if dense else 0.005)
    culled, plain = Scene(objects, sea=False), Scene(objects, sea=False, cull=False)
    # white box: the sparse scene really takes the culled path, the dense one casts every ray
    from raysim.scene.rays import RayBatch as _Batch

    batch = _Batch(o, d, t, None)
    culled._prepare(batch)
    assert (batch.static_candidates is None) == dense
    for scene in (culled, plain):
        hits = scene.cast(o, d, t)
        np.testing.assert_array_equal(hits.object_id, ref_id)
        np.testing.assert_array_equal(hits.primitive, np.where(ref_id >= 0, ref_prim, -1))
        np.testing.assert_allclose(hits.range_m, ref_t, rtol=0, atol=MM)
        mats = np.array([objects[i].face_material[p] if i >= 0 else -1 for i, p in zip(ref_id, ref_prim)])
        np.testing.assert_array_equal(hits.material, mats)
        assert np.all(np.einsum("ij,ij->i", hits.normal, d) <= 0)
    # with the sea and a range limit both paths still agree with the reference
    sea_t = intersect_sea(o[:, 2], d[:, 2])
    exp_id = np.where(sea_t < ref_t, SEA_ID, ref_id)
    exp_id[np.minimum(sea_t, ref_t) > 200.0] = NO_HIT
    for scene in (Scene(objects, sea=True), Scene(objects, sea=True, cull=False)):
        hits = scene.cast(o, d, t, max_range_m=200.0)
        np.testing.assert_array_equal(hits.object_id, exp_id)
        np.testing.assert_allclose(hits.range_m[exp_id != NO_HIT], np.minimum(sea_t, ref_t)[exp_id != NO_HIT], atol=MM)
        sea = exp_id == SEA_ID
        np.testing.assert_array_equal(hits.normal[sea], np.tile([0, 0, 1], (sea.sum(), 1)))
        np.testing.assert_array_equal(hits.primitive[sea], -1)


def test_the_near_table_of_many_static_objects_by_one_scatter_equals_block_by_block(monkeypatch):
    """Land in tiles gives hundreds of static objects: their near table is filled by one scatter, to the same values."""
    import raysim.scene.static as static
    from raysim.scene.rays import RayBatch

    rng = np.random.default_rng(5)
    objects = []
    for k in range(200):  # boxes around the origin, 30 m to 2 km out
        r, a = rng.uniform(30.0, 2000.0), rng.uniform(0.0, 2 * np.pi)
        mesh = trimesh.creation.box(extents=rng.uniform(2.0, 60.0, 3))
        objects.append(make_object(k + 1, mesh, Stationary([r * np.sin(a), r * np.cos(a), 2.0])))
    part = static.StaticPart.build(objects, nthreads=0, workers=1)
    batch = RayBatch(np.zeros((4, 3)), np.tile([1.0, 0.0, 0.0], (4, 1)), np.zeros(4), None)
    centre, spread = np.array([3.0, -2.0, 4.0]), 12.0
    everything = np.ones(len(objects), dtype=bool)
    scattered = part._build_near_table(everything, centre, spread)
    monkeypatch.setattr(static, "NEAR_TABLE_LOOP_MAX_RUNS", 10**9)
    blocks = part._build_near_table(everything, centre, spread)
    assert np.isfinite(blocks).sum() > 1000
    assert np.array_equal(scattered, blocks)


def _tiles_around(rng: np.random.Generator, n: int) -> list:
    """``n`` static boxes 30 m to 2 km round the origin (land in tiles)."""
    objects = []
    for k in range(n):
        r, a = rng.uniform(30.0, 2000.0), rng.uniform(0.0, 2 * np.pi)
        mesh = trimesh.creation.box(extents=rng.uniform(2.0, 60.0, 3))
        objects.append(make_object(k + 1, mesh, Stationary([r * np.sin(a), r * np.cos(a), 2.0])))
    return objects


def test_the_near_table_is_kept_while_the_origins_stay_in_its_grown_box_and_the_hits_do_not_change():
    """A sensor moving within NEAR_TABLE_MARGIN_M reuses one table (white box) and gets the brute-force hits."""
    import raysim.scene.static as static

    objects = _tiles_around(np.random.default_rng(6), 150)
    culled, plain = Scene(objects, sea=True), Scene(objects, sea=True, cull=False)
    rng = np.random.default_rng(7)
    d = rng.standard_normal((20_000, 3))
    d[:, 2] = np.abs(d[:, 2]) * 0.05 - 0.01
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    tables = []
    for step in range(6):  # 8 m a step: 40 m in all, inside the 50 m margin
        o = np.tile([8.0 * step, 0.0, 3.0], (d.shape[0], 1)) + rng.uniform(-0.5, 0.5, (d.shape[0], 3))
        t = np.zeros(d.shape[0])
        a, b = culled.cast(o, d, t, max_range_m=1500.0), plain.cast(o, d, t, max_range_m=1500.0)
        np.testing.assert_array_equal(a.object_id, b.object_id)
        np.testing.assert_array_equal(a.range_m, b.range_m)
        tables.append(culled._static._near_cache[3])
        assert (b.object_id > 0).sum() > 100  # the tiles are hit
    assert tables[0] is not None and culled._static._near_cache[2].sum() > 50  # most tiles are far
    assert all(table is tables[0] for table in tables)  # built once for the 40 m
    assert static.NEAR_TABLE_MARGIN_M == 50.0


def test_the_near_table_is_skipped_when_the_origins_are_within_a_static_bounding_sphere():
    """Rays from a coast (second bounces) start inside the tiles' spheres: every ray is a candidate, no table."""
    from raysim.scene.rays import RayBatch

    objects = _tiles_around(np.random.default_rng(8), 50)
    part = Scene(objects, sea=True)._static
    batch = RayBatch(np.zeros((4, 3)), np.tile([1.0, 0.0, 0.0], (4, 1)), np.zeros(4), None)
    batch.origin_centre, batch.spread_m = part.sphere_centres[3].copy(), 1.0
    assert part.near_table(batch) is None
    batch.origin_centre = np.array([0.0, 0.0, 3.0])
    assert part.near_table(batch) is not None
