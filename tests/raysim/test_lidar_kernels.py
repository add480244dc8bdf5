"""The LiDAR's compiled kernels (raysim.jit) against the numpy code they replace.

Both paths run in every test: the numpy path with ``raysim.jit.ENABLED`` off, the kernel with it on.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from groundfloor import hdl32e
from raysim import jit
from raysim.materials import material_index
from raysim.scenario import load_scenario, with_overrides
from raysim.sensors.blas_threads import single_blas_thread
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.lidar import LidarRenderer
from raysim.world import World

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(jit.numba is None, reason="numba is not installed")


def busy_open_sea(duration_s: float, **overrides):
    return with_overrides(load_scenario(ROOT / "scenarios" / "busy_open_sea.yaml"), duration_s=duration_s,
                          sensors=("lidar",), **overrides)


@pytest.fixture(scope="module")
def renderer():
    """busy_open_sea's LiDAR (own ship rolling, pitching and heaving), no ray engine."""
    return LidarRenderer(World(busy_open_sea(1.0)), scene=None)


def _cycles(renderer, t0_s: float, c: int):
    t = (int(t0_s / hdl32e.CYCLE_DT_S) + np.arange(c)) * hdl32e.CYCLE_DT_S
    block = hdl32e.block_azimuth_centideg(t, renderer.cfg.rotation_hz, renderer.cfg.azimuth0_deg)
    firing = hdl32e.decoder_azimuths_centideg(block.reshape(-1, hdl32e.BLOCKS_PER_PACKET)).reshape(-1, hdl32e.N_LASERS)
    return t, firing


def _no_own_ship(n_keys: int = 36000 * 32) -> dict:
    return {"hit": np.zeros(n_keys, bool), "wet": np.zeros(n_keys, bool), "range_m": np.zeros(n_keys, np.float32),
            "power": np.zeros(n_keys, np.float32), "byte": np.zeros(n_keys, np.uint8), "object_id": 0}


@pytest.mark.parametrize("t0_s", [0.0, 37.3, 251.9])
def test_world_rays_kernel_is_the_numpy_path(renderer, t0_s, monkeypatch):
    """With no own ship in the beam table every firing's ray is gathered: the numpy path's rays, in order."""
    from raysim.sensors.lidar import _Candidates

    c = 181 * hdl32e.BLOCKS_PER_PACKET
    t, firing = _cycles(renderer, t0_s, c)
    origins, directions = renderer._sensor_rays(firing)
    with single_blas_thread():
        o_np, d_np, t_np = renderer._world_rays(t, origins, directions)
    monkeypatch.setattr(renderer, "own_table", _no_own_ship())
    free, cast = renderer._rays_past_own_ship(t, firing, _Candidates.empty(c * hdl32e.N_LASERS, 1))
    n = c * hdl32e.N_LASERS
    assert np.array_equal(free, np.arange(n)) and cast.origins_m.shape == cast.directions.shape == (n, 3)
    # the origins' sums are the same operations; the directions' 3-term sums may differ from BLAS's in the last bit
    assert np.array_equal(cast.origins_m, o_np.reshape(n, 3)) and np.array_equal(cast.times_s, t_np.reshape(n))
    assert np.max(np.abs(cast.directions - d_np.reshape(n, 3))) <= 4 * np.finfo(float).eps
    assert np.allclose(np.linalg.norm(cast.directions, axis=-1), 1.0, atol=1e-12)
    assert np.isfinite(cast.directions).all()


def test_fused_own_ship_pass_is_the_numpy_path(monkeypatch):
    """busy_open_sea's real beam table over two revolutions: the compiled pass answers the same firings from the
    own ship as the numpy path (range, power, byte, id) and gathers the same rays, in the same order."""
    from raysim.sensors.lidar import _Candidates, _Rays

    world = World(busy_open_sea(1.0))
    lidar = LidarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))
    monkeypatch.setattr(lidar, "_cast", lambda rays: None)  # the lookups only
    c = 2 * 181 * hdl32e.BLOCKS_PER_PACKET
    t, firing = _cycles(lidar, 3.1, c)
    n = c * hdl32e.N_LASERS
    cand_k, cand_np = _Candidates.empty(n, 1), _Candidates.empty(n, 1)
    free_k, cast_k = lidar._rays_past_own_ship(t, firing, cand_k)
    with single_blas_thread():
        o, d, tf = lidar._world_rays(t, *lidar._sensor_rays(firing))
    o, d = o.reshape(n, 3), d.reshape(n, 3)
    # the numpy lookups on the kernel's own directions (which may differ from BLAS's in the last bit)
    _, free_np, cast_np, _ = lidar._cast_past_own_ship(cand_np, _Rays(o, _scatter(d, free_k, cast_k.directions), tf.reshape(n)),
                                                       firing)
    assert np.array_equal(free_k, free_np) and 0.5 * n < free_k.size < n  # the own ship stops some beams
    for name in ("range_m", "power", "byte", "object_id", "source"):
        assert np.array_equal(getattr(cand_k, name), getattr(cand_np, name)), name
    assert np.array_equal(cast_k.origins_m, cast_np.origins_m) and np.array_equal(cast_k.times_s, cast_np.times_s)
    assert np.array_equal(cast_k.directions, cast_np.directions)


def _scatter(full: np.ndarray, rows: np.ndarray, values: np.ndarray) -> np.ndarray:
    out = full.copy()
    out[rows] = values
    return out


def measured_firings(enabled: bool, monkeypatch, duration_s: float = 0.3):
    monkeypatch.setattr(jit, "ENABLED", enabled)
    world = World(busy_open_sea(duration_s))
    lidar = LidarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))
    return [(c.firings, c.payloads) for c in lidar.chunks()]


def test_render_with_kernels_is_the_numpy_render(monkeypatch):
    """Three revolutions of busy_open_sea, every return and every packet byte, with the kernels and without."""
    compiled = measured_firings(True, monkeypatch)
    numpy_path = measured_firings(False, monkeypatch)
    assert len(compiled) == len(numpy_path) >= 3
    hits = 0
    for (fire_k, payload_k), (fire_np, payload_np) in zip(compiled, numpy_path):
        for name in ("distance_units", "reflectivity", "object_id", "source"):
            assert np.array_equal(getattr(fire_k, name), getattr(fire_np, name)), name
        assert payload_k.tobytes() == payload_np.tobytes()
        hits += int((fire_k.distance_units > 0).sum())
    assert hits > 10_000  # the comparison saw real returns (own ship, ships, sea foam)


@pytest.mark.parametrize("dual", [False, True])
def test_decoder_azimuths_kernel_is_the_decoders_arithmetic(dual):
    """Every firing slot's azimuth as groundfloor.hdl32e computes it (velodyne_decoder's float32 steps), on a
    rotating head's packets (wrapping through 0) and on arbitrary block azimuths."""
    from raysim.sensors import lidar_kernels

    t = np.arange(12 * 181 * 12) * hdl32e.CYCLE_DT_S
    blocks = hdl32e.block_azimuth_centideg(t, 10.0, 37.0)
    if dual:
        blocks = np.repeat(blocks, 2)[: blocks.size]
    arbitrary = np.random.default_rng(3).integers(0, 36000, (4000, 12)).astype(np.uint16)
    for block_az in (blocks.reshape(-1, 12), arbitrary):
        expected = hdl32e.decoder_azimuths_centideg(block_az, dual=dual)
        got = lidar_kernels.decoder_azimuths(block_az, dual)
        assert got.dtype == expected.dtype == np.uint16 and np.array_equal(got, expected)


def test_own_ship_pass_sends_wet_beams_to_the_sea():
    """A synthetic beam table: beams 0-9 on the own ship at 5 m, 0-4 of them low on the hull (wet). Beams 20 cm
    above the sea looking down at 1/10 meet the sea at 2 m, before the hull: those wet beams go to the world,
    as do the beams off the ship; the others are the ship's, with its range, power, byte and id."""
    from raysim.sensors import lidar_kernels
    from raysim.sensors.lidar import _Candidates

    table = _no_own_ship()
    table["hit"][:10] = True
    table["wet"][:5] = True
    table.update(range_m=np.full(36000 * 32, 5.0, np.float32), power=np.full(36000 * 32, 0.25, np.float32),
                 byte=np.full(36000 * 32, 40, np.uint8))
    firing_az = np.zeros((1, 32), np.uint16)  # keys 0..31, azimuth step 0: along x
    sin_el = np.full(32, -0.1)
    sin_el[2] = 0.0  # a wet beam level with the sea: it never meets it, the hull answers
    beams = (np.sqrt(1.0 - sin_el**2), sin_el, np.ones(36000), np.zeros(36000), np.zeros(32))
    a0 = np.zeros((1, 4, 3))
    a0[0, :3] = np.eye(3)
    a0[0, 3] = [0.0, 0.0, 0.2]  # the sensor 20 cm above the sea, level
    times = (np.arange(32) * 1e-6)[None, :]
    cand = _Candidates.empty(32, 1)
    free, o_free, d_free, t_free = lidar_kernels.rays_past_own_ship(firing_az, beams, a0, np.zeros((1, 4, 3)),
                                                                    np.zeros(32), times, table, cand)
    assert free.tolist() == [0, 1, 3, 4] + list(range(10, 32))
    assert np.array_equal(o_free, np.tile([0.0, 0.0, 0.2], (free.size, 1)))
    assert np.allclose(d_free[:, 2], -0.1) and np.array_equal(t_free, times[0, free])
    own = [2, 5, 6, 7, 8, 9]
    assert np.all(cand.range_m[own, 0] == 5.0) and np.all(cand.power[own, 0] == 0.25)
    assert np.all(cand.byte[own, 0] == 40) and np.all(cand.object_id[own, 0] == 0)
    assert np.all(np.isinf(cand.range_m[free, 0])) and np.all(cand.object_id[free, 0] == -1)


@pytest.mark.parametrize("alpha_per_m", [0.0, 0.004])
def test_world_echoes_kernel_is_the_numpy_path(renderer, monkeypatch, alpha_per_m):
    """Synthetic hits of every kind (none, the sea near and far with and without foam, a retro-reflector, grazing
    and head-on hulls) through LidarRenderer._world_echoes with the kernels and without: the same candidates."""
    from raysim.scene import NO_HIT, SEA_ID, Hits
    from raysim.sensors.lidar import _Candidates, _Rays

    rng = np.random.default_rng(11)
    n = 4000
    d = rng.normal(size=(n, 3))
    d[:, 2] = -np.abs(d[:, 2]) * 0.3
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.column_stack([rng.uniform(-20, 20, n), rng.uniform(-20, 20, n), np.full(n, 3.0)])
    t = np.sort(rng.uniform(0.0, 0.1, n))
    free = np.sort(rng.choice(n, 3000, replace=False))
    m = free.size
    kind = rng.integers(0, 4, m)  # no hit, sea, hull, retro-reflector
    object_id = np.where(kind == 0, NO_HIT, np.where(kind == 1, SEA_ID, 5)).astype(np.int32)
    material = np.where(kind == 3, 9, np.where(kind == 1, renderer.sea_material, 2)).astype(np.int16)
    normal = rng.normal(size=(m, 3)).astype(np.float32)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    normal[kind == 1] = [0.0, 0.0, 1.0]
    range_m = np.where(kind == 0, np.inf, rng.uniform(1.0, 110.0, m))
    hits = Hits(range_m, object_id, normal, material, np.zeros(m, np.int32))
    rays = _Rays(o[free], d[free], t[free])  # the rays cast
    monkeypatch.setattr(renderer, "alpha", alpha_per_m)
    monkeypatch.setattr(renderer.foam, "coverage", 0.3)  # plenty of foam to test
    results = []
    for enabled in (True, False):
        monkeypatch.setattr(jit, "ENABLED", enabled)
        cand = _Candidates.empty(n, 1)
        renderer._world_echoes(cand, rays, hits, free, None, 1)
        results.append(cand)
    compiled, numpy_path = results
    for name in ("range_m", "power", "byte", "object_id", "source"):
        assert np.array_equal(getattr(compiled, name), getattr(numpy_path, name)), name
    assert (compiled.byte > 100).any() and (compiled.source == 1).any()  # retro-reflector and sea seen
    if alpha_per_m == 0:  # in clear air some of the sea is foam (in this fog, too faint to be seen)
        assert len(np.unique(compiled.byte[compiled.source == 1])) > 1


def test_single_returns_kernel_is_the_numpy_path(renderer, monkeypatch):
    """Candidates of every kind (none, too weak, too near, too far, in range), noise from equal generators:
    LidarRenderer._returns gives the same distance units, bytes, ids and sources with the kernel and without."""
    from raysim.random_streams import stream
    from raysim.sensors.lidar import _Candidates

    rng = np.random.default_rng(4)
    f = 5000
    cand = _Candidates.empty(f, 1)
    kind = rng.integers(0, 5, f)
    cand.range_m[:, 0] = np.where(kind == 0, np.inf, np.where(kind == 2, 0.01, np.where(kind == 3, 100.005,
                                                                                           rng.uniform(0.5, 99.0, f))))
    cand.power[:, 0] = np.where(kind == 1, renderer.threshold * 0.5, renderer.threshold * rng.uniform(1.0, 50.0, f))
    cand.power[np.flatnonzero(kind == 4)[:20], 0] = renderer.threshold  # exactly at the threshold: detected
    cand.byte[:, 0] = rng.integers(1, 255, f)
    cand.object_id[:, 0] = rng.integers(-1, 9, f)
    cand.source[:, 0] = rng.integers(0, 3, f)
    results = []
    for enabled in (True, False):
        monkeypatch.setattr(jit, "ENABLED", enabled)
        monkeypatch.setattr(renderer, "noise_rng", stream(7, "test.noise"))
        results.append(renderer._returns(cand, f))
    for compiled, numpy_path in zip(*results):
        assert compiled.shape == numpy_path.shape == (1, f) and compiled.dtype == numpy_path.dtype
        assert np.array_equal(compiled, numpy_path)
    units = results[0][0][0]
    assert (units > 0).sum() > f // 5 and (units[kind == 0] == 0).all() and (units[kind == 1] == 0).all()
    assert (units[np.flatnonzero(kind == 4)[:20]] > 0).all()


def test_points_kernel_is_the_numpy_path(monkeypatch):
    """A rendered chunk's sweep arrays (every field, dtype and order) and point cycles, with the kernel and without."""
    world = World(busy_open_sea(0.2))
    lidar = LidarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))
    fire = next(lidar.chunks()).firings
    results = []
    for enabled in (True, False):
        monkeypatch.setattr(jit, "ENABLED", enabled)
        results.append(lidar.points(fire))
    (arrays_k, cycle_k), (arrays_np, cycle_np) = results
    assert list(arrays_k) == list(arrays_np) and np.array_equal(cycle_k, cycle_np)
    for name in arrays_np:
        assert arrays_k[name].dtype == arrays_np[name].dtype, name
        assert np.array_equal(arrays_k[name], arrays_np[name]), name
    assert arrays_np["x"].size > 5000
