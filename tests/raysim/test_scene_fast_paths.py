"""The ray engine's fast paths against the plain computations they replace, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from raysim.motion import ConstantVelocity, Stationary
from raysim.scene import NO_HIT, SEA_ID, Hits, Scene, intersect_sea
from raysim.scene.hits import drop_beyond
from raysim.scene.rays import RayBatch

from .scene_helpers import make_object


def _plain_sea_range(oz_m: np.ndarray, dz: np.ndarray) -> np.ndarray:
    """The sea range as first written: divide, negate, inf where not ahead (nan too)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.divide(oz_m, dz, dtype=np.float64)
    np.negative(t, out=t)
    t[~(t >= 0.0)] = np.inf
    return t


def _plain_sea_hits(rng: np.ndarray, dz: np.ndarray, sea_material: int) -> Hits:
    """Sea hits by masked writes (the reference of ``Scene._sea_hits``)."""
    n = rng.size
    hit = rng < np.inf
    obj = np.full(n, NO_HIT, dtype=np.int32)
    np.copyto(obj, SEA_ID, where=hit)
    material = np.full(n, -1, dtype=np.int16)
    np.copyto(material, sea_material, where=hit)
    normal = np.zeros((n, 3), dtype=np.float32)
    np.copyto(normal[:, 2], np.where(dz < 0, np.float32(1.0), np.float32(-1.0)), where=hit)
    return Hits(rng, obj, normal, material, np.full(n, -1, dtype=np.int32))


def _assert_same_hits(a: Hits, b: Hits) -> None:
    """Every field of two Hits equal byte for byte (dtype, shape and bits: -0.0 differs from 0.0)."""
    for name in ("range_m", "object_id", "normal", "material", "primitive"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert x.tobytes() == y.tobytes(), name


def _edge_rays(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Origins above, on and below the sea and directions with dz < 0, = 0, > 0 (and -0.0)."""
    o = rng.uniform(-50.0, 50.0, (n, 3))
    o[:, 2] = rng.choice([3.0, 0.0, -1.5, 12.0], n)
    d = rng.standard_normal((n, 3))
    d[::7, 2] = 0.0
    d[3::11, 2] = -0.0
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return o, d


def test_the_sea_range_equals_the_plain_formula_and_its_limit_cuts_exactly_beyond():
    rng = np.random.default_rng(3)
    o, d = _edge_rays(rng, 50_000)
    plain = _plain_sea_range(o[:, 2], d[:, 2])
    assert np.isinf(plain).sum() > 1000 and np.isfinite(plain).sum() > 1000
    assert intersect_sea(o[:, 2], d[:, 2]).tobytes() == plain.tobytes()
    finite = plain[np.isfinite(plain)]
    for limit in (np.float64(25.0), np.asarray(25.0), finite[7], rng.uniform(0.0, 60.0, plain.size)):
        expected = plain.copy()
        expected[plain > limit] = np.inf  # the range cut as drop_beyond does it
        assert intersect_sea(o[:, 2], d[:, 2], limit).tobytes() == expected.tobytes()
    on_limit = intersect_sea(o[:, 2], d[:, 2], finite[7])  # a range equal to the limit is kept
    assert np.any(on_limit == finite[7])


@pytest.mark.parametrize("sea_material", [-1, 0, 5, 300])
def test_the_sea_hits_equal_the_masked_writes(sea_material):
    rng = np.random.default_rng(4)
    o, d = _edge_rays(rng, 20_000)
    scene = Scene([], sea=True, sea_material=sea_material)
    batch = RayBatch(o, d, np.zeros(len(o)), None)
    batch.sea_range = intersect_sea(o[:, 2], d[:, 2])
    got = scene._sea_hits(batch)
    _assert_same_hits(got, _plain_sea_hits(batch.sea_range, d[:, 2], sea_material))
    assert (got.object_id == SEA_ID).sum() > 1000 and (got.normal[:, 2] == -1).sum() > 100  # hits from below too


def _plain_cast(scene: Scene, o: np.ndarray, d: np.ndarray, t: np.ndarray, max_range) -> Hits:
    """The cast as first written on the candidate path: uncut sea hits, the static merge, then the range cut."""
    mr = np.asarray(max_range, dtype=np.float64)
    batch = RayBatch(o, d, t, mr)
    scene._prepare(batch)
    assert batch.static_candidates is not None and batch.static_candidates.size > 100  # the path under test
    batch.sea_range = _plain_sea_range(o[:, 2], d[:, 2])
    hits = _plain_sea_hits(batch.sea_range.copy(), d[:, 2], scene.sea_material)
    cut = batch.max_range
    batch.max_range = None  # the old merge kept every nearer static hit
    scene._static.merge_some(hits, batch, batch.static_candidates)
    drop_beyond(hits, mr)
    batch.max_range = cut
    scene._moving.cast(hits, batch)
    return hits


def test_the_culled_cast_cuts_sea_and_static_hits_at_the_range_limit_as_the_final_cut_did():
    """Sea ranges cut in the pre-pass and static hits cut in their merge: the hits of a cut at the end."""
    rng = np.random.default_rng(11)
    objects = []
    for k in range(10):  # static spheres 20-120 m out, across the 60 m limit
        r, a = rng.uniform(20.0, 120.0), rng.uniform(-np.pi, np.pi)
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=rng.uniform(2.0, 8.0))
        objects.append(make_object(k + 1, mesh, Stationary((r * np.cos(a), r * np.sin(a), 0.0)),
                                   rng.integers(0, 6, len(mesh.faces))))
    boat = trimesh.creation.box(extents=(6.0, 3.0, 3.0))
    objects.append(make_object(40, boat, ConstantVelocity((30.0, 5.0, 0.0), (-2.0, 0.5, 0.0)), np.full(12, 3)))
    n = 40_000
    o = np.tile([0.5, -0.3, 4.0], (n, 1)) + rng.uniform(-0.2, 0.2, (n, 3))
    az, el = rng.uniform(-np.pi, np.pi, n), np.radians(rng.uniform(-25.0, 8.0, n))
    d = np.column_stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    t = np.sort(rng.uniform(0.0, 0.1, n))
    for limit in (60.0, rng.uniform(20.0, 110.0, n)):
        scene = Scene(objects, sea=True, sea_material=9)
        got = scene.cast(o, d, t, max_range_m=limit)
        expected = _plain_cast(Scene(objects, sea=True, sea_material=9), o, d, t, limit)
        _assert_same_hits(got, expected)
        kinds = got.object_id
        assert (kinds == SEA_ID).sum() > 1000 and (kinds == NO_HIT).sum() > 1000
        assert ((kinds > 0) & (kinds < 40)).sum() > 100 and (kinds == 40).sum() > 10


def _old_near_table(part, batch: RayBatch) -> np.ndarray | None:
    """The near table as first written: every object, the far part's table merged whatever its entries."""
    from raysim.scene import static

    centre, spread = np.asarray(batch.origin_centre, dtype=np.float64), float(batch.spread_m)
    reach = np.linalg.norm(part.sphere_centres - centre, axis=1) - part.sphere_radii
    if np.any(reach <= spread):
        return None
    everything = np.ones(reach.size, dtype=bool)
    if spread > static.NEAR_TABLE_MARGIN_M:
        return part._build_near_table(everything, centre, spread)
    far, far_table = part._near_cache[2], part._near_cache[3]  # the cache the new call left (same rule)
    if far_table is None:
        return part._build_near_table(everything, centre, spread)
    if far.all():
        return far_table
    return np.minimum(far_table, part._build_near_table(~far, centre, spread))


def test_the_near_table_leaves_out_what_lies_beyond_the_range_limit_and_the_same_rays_are_cast():
    """Objects and the far part beyond the limit are left out: fewer table entries, the same candidates."""
    rng = np.random.default_rng(21)
    objects = []
    for k in range(120):  # tiles 20 m to 2 km out: some within the 80 m limit, most beyond, many far
        r, a = rng.uniform(20.0, 2000.0) if k >= 6 else rng.uniform(20.0, 70.0), rng.uniform(0.0, 2 * np.pi)
        mesh = trimesh.creation.box(extents=rng.uniform(2.0, 30.0, 3))
        objects.append(make_object(k + 1, mesh, Stationary([r * np.sin(a), r * np.cos(a), 2.0])))
    scene = Scene(objects, sea=True)
    d = rng.standard_normal((30_000, 3))
    d[:, 2] = -np.abs(d[:, 2]) * 0.2 - 0.01  # down: the sea limits most rays
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    for step, limit in enumerate((80.0, 80.0, rng.uniform(10.0, 80.0, len(d)), np.inf)):
        o = np.tile([3.0 * step, 0.0, 3.0], (len(d), 1)) + rng.uniform(-0.5, 0.5, (len(d), 3))
        batch = RayBatch(o, d, np.zeros(len(d)), None if np.all(np.isinf(limit)) else np.asarray(limit))
        scene._prepare(batch)
        new_table = scene._static.near_table(batch)
        old_table = _old_near_table(scene._static, batch)
        limit_of = batch.limit(slice(None))
        assert batch.cells is not None and batch.static_candidates is not None  # the culled path
        cells = batch.cells
        assert np.array_equal(np.flatnonzero(new_table[cells] < limit_of), np.flatnonzero(old_table[cells] < limit_of))
        assert np.array_equal(np.flatnonzero(new_table[cells] < limit_of), batch.static_candidates)
        if np.isfinite(limit).all():
            assert np.isfinite(new_table).sum() < np.isfinite(old_table).sum()  # objects were left out
            assert batch.static_candidates.size > 50
        else:
            assert np.array_equal(new_table, old_table)
