"""Ray engine against analytic answers (real Embree through Open3D, no mocks)."""

from __future__ import annotations

import numpy as np
import open3d as o3d
import pytest
import trimesh

from raysim.motion import ConstantVelocity, Stationary
from raysim.pose import rotation_matrices
from raysim.scene import NO_HIT, SEA_ID, Hits, Scene, SceneObject, intersect_sea, pseudo_azimuth

MM = 1e-3


# ----------------------------------------------------------------- helpers


def make_object(object_id, mesh: trimesh.Trimesh, motion, materials=None) -> SceneObject:
    """A SceneObject from a trimesh mesh (body frame)."""
    n = len(mesh.faces)
    mat = np.zeros(n, dtype=np.int16) if materials is None else np.asarray(materials, dtype=np.int16)
    return SceneObject(object_id, np.asarray(mesh.vertices, float), np.asarray(mesh.faces), mat, motion)


def quad(half_m: float) -> trimesh.Trimesh:
    """A square in the body y-z plane at x = 0 (two triangles)."""
    h = half_m
    v = np.array([[0, -h, -h], [0, h, -h], [0, h, h], [0, -h, h]], float)
    return trimesh.Trimesh(v, np.array([[0, 1, 2], [0, 2, 3]]), process=False)


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def slab(o_b: np.ndarray, d_b: np.ndarray, half: np.ndarray):
    """Analytic ray / axis-aligned box (centred at 0, half extents ``half``) in the body frame.

    Returns entry range (inf if missed), entry axis, entry normal sign and the
    gap between the largest and second largest slab entry (edge ambiguity).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-half - o_b) / d_b
        t2 = (half - o_b) / d_b
    tn = np.where(np.isnan(t1), -np.inf, np.minimum(t1, t2))
    tf = np.where(np.isnan(t1), np.inf, np.maximum(t1, t2))
    near, far = tn.max(axis=1), tf.min(axis=1)
    hit = (near <= far) & (near > 0)
    axis = tn.argmax(axis=1)
    sign = -np.sign(d_b[np.arange(len(d_b)), axis])
    srt = np.sort(tn, axis=1)
    return np.where(hit, near, np.inf), axis, sign, srt[:, 2] - srt[:, 1]


def world_to_body(o, d, pos, yaw):
    """Rays into a yawed body frame (per ray positions/yaws allowed)."""
    yaw = np.broadcast_to(yaw, (len(o),))
    r = rotation_matrices(yaw, np.zeros_like(yaw), np.zeros_like(yaw))
    return np.einsum("nji,nj->ni", r, o - pos), np.einsum("nji,nj->ni", r, d), r


def rays_towards(origin, targets):
    o = np.broadcast_to(np.asarray(origin, float), targets.shape).copy()
    return o, unit(targets - o)


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


def brute_force(objects: list[SceneObject], o, d, times) -> tuple[np.ndarray, np.ndarray]:
    """Every ray against every object with plain Open3D (no culling): nearest range and id."""
    best = np.full(len(o), np.inf)
    ids = np.full(len(o), NO_HIT, dtype=np.int32)
    for obj in objects:
        sc = o3d.t.geometry.RaycastingScene()
        sc.add_triangles(o3d.core.Tensor(obj.vertices_m.astype(np.float32)), o3d.core.Tensor(obj.faces.astype(np.uint32)))
        poses = obj.motion.poses(times)
        r = poses.rotation()
        rays = np.hstack([np.einsum("nji,nj->ni", r, o - poses.position_m), np.einsum("nji,nj->ni", r, d)])
        t = sc.cast_rays(o3d.core.Tensor(rays.astype(np.float32)))["t_hit"].numpy().astype(float)
        better = t < best
        best[better] = t[better]
        ids[better] = obj.object_id
    return best, ids


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


def _ray_engine_bench():
    """benchmarks/ray_engine.py loaded by path (benchmarks/ is a folder of scripts, not a package)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "benchmarks" / "ray_engine.py"
    spec = importlib.util.spec_from_file_location("bench_ray_engine", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.bench
def test_benchmark_functions_run():
    benchmarking = _ray_engine_bench()

    st = benchmarking.bench_static(n_firings=200, reps=1, with_embreex=True)
    assert st["rays"] == 6400 and st["raw_o3d_rays_per_s"] > 0 and st["fraction_of_raw"] > 0
    rows = benchmarking.bench_moving(counts=(1, 3), n_firings=200, reps=1)
    assert [r["moving_objects"] for r in rows] == [1, 3]


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


def test_benchmark_report_and_main(tmp_path, monkeypatch, capsys):
    """The report formatter and ``run`` of benchmarks/ray_engine.py on a tiny real measurement (fast, not a benchmark)."""
    import json

    benchmarking = _ray_engine_bench()

    rows = benchmarking.bench_moving(counts=(1, 2), n_firings=40, reps=1)
    res = {
        "machine": benchmarking.machine_info(),
        "quick": True,
        "moving_one_revolution": rows,
        "own_ship": {"rays": 1280, "own_ship_hit_fraction": 0.07, "ns_per_ray_without": 25.0,
                     "ns_per_ray_with": 200.0, "ns_per_ray_with_carrier": 40.0},
    }
    figures = benchmarking.key_figures(res)
    assert figures["own ship: ns/ray with it, carrier="] == 40.0 and len(figures) == 4
    text = benchmarking.to_markdown(dict(res, runs=[figures, figures]))
    assert "| 2 | " in text and "| with own ship, `CarrierScene.cast(...)`" in text
    assert "| figure | run 1 | run 2 | median |" in text and "| 40.00 | 40.00 | 40.00 |" in text
    monkeypatch.setattr(benchmarking, "run_all", lambda quick=False: res)
    out, js = tmp_path / "r" / "ray_engine.md", tmp_path / "r.json"
    assert benchmarking.run(quick=True, json_path=js, out_path=out, runs=2) == 0
    assert capsys.readouterr().out == out.read_text(encoding="utf-8") + "\n"  # printed and written
    assert json.loads(js.read_text())["runs"] == [figures, figures]
    assert not list(tmp_path.rglob("*.tmp"))
