"""The LiDAR renderer's fast paths against the reference computations they replace, bit for bit.

Each reference is the computation as it stood before the fast path (same numpy operations), so a
fast path that changed any value, even in its last bit, fails here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from groundfloor import hdl32e
from raysim.scenario import load_scenario, with_overrides
from raysim.sensors.blas_threads import single_blas_thread
from raysim.sensors.lidar import LidarRenderer
from raysim.world import World

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def renderer():
    """busy_open_sea's LiDAR (own ship rolling, pitching and heaving), no ray engine."""
    s = with_overrides(load_scenario(ROOT / "scenarios" / "busy_open_sea.yaml"), duration_s=1.0, sensors=("lidar",))
    return LidarRenderer(World(s), scene=None)


def one_revolution(lidar: LidarRenderer, t0_s: float):
    """Cycle times (C,), block azimuths (C,) and firing azimuths (C, 32) of one revolution from t0_s."""
    c = 181 * hdl32e.BLOCKS_PER_PACKET
    t = (int(t0_s / hdl32e.CYCLE_DT_S) + np.arange(c)) * hdl32e.CYCLE_DT_S
    block = hdl32e.block_azimuth_centideg(t, lidar.cfg.rotation_hz, lidar.cfg.azimuth0_deg)
    firing = hdl32e.decoder_azimuths_centideg(block.reshape(-1, hdl32e.BLOCKS_PER_PACKET)).reshape(-1, hdl32e.N_LASERS)
    return t, block, firing


def reference_world_rays(lidar: LidarRenderer, cycle_time_s, origins_s, directions_s):
    """The world rays as computed before the fast path (one product per cycle and per term)."""
    t_edges = np.append(cycle_time_s, cycle_time_s[-1] + hdl32e.CYCLE_DT_S)
    poses = lidar.world.own_ship.motion.poses(t_edges)
    rot = poses.rotation() @ lidar.mount_rotation
    pos = poses.position_m + np.einsum("nij,j->ni", poses.rotation(), lidar.mount_translation)
    c, _, k, _ = directions_s.shape
    frac = np.repeat(np.arange(hdl32e.N_LASERS) * (hdl32e.FIRING_DT_S / hdl32e.CYCLE_DT_S), k)
    r0t = np.ascontiguousarray(rot[:-1].transpose(0, 2, 1))
    drt = np.ascontiguousarray((rot[1:] - rot[:-1]).transpose(0, 2, 1))
    d = directions_s.reshape(c, hdl32e.N_LASERS * k, 3)
    f = frac[None, :, None]
    d_world = d @ r0t
    d_world += (d @ drt) * f
    homogeneous = np.ones((hdl32e.N_LASERS * k, 4))
    homogeneous[:, :3] = origins_s[0].reshape(-1, 3)
    a0 = np.concatenate([r0t, pos[:-1, None, :]], axis=1)
    da = np.concatenate([drt, (pos[1:] - pos[:-1])[:, None, :]], axis=1)
    o_world = homogeneous @ a0
    o_world += (homogeneous @ da) * f
    t_firing = cycle_time_s[:, None] + np.arange(hdl32e.N_LASERS)[None, :] * hdl32e.FIRING_DT_S
    return o_world.reshape(c, hdl32e.N_LASERS, k, 3), d_world.reshape(c, hdl32e.N_LASERS, k, 3), t_firing


@pytest.mark.parametrize("t0_s", [0.0, 37.3])
def test_world_rays_are_the_reference_bit_for_bit(renderer, t0_s):
    t, _, firing = one_revolution(renderer, t0_s)
    origins, directions = renderer._sensor_rays(firing)
    with single_blas_thread():
        fast = renderer._world_rays(t, origins, directions)
    reference = reference_world_rays(renderer, t, origins, directions)
    for a, b in zip(fast, reference):
        assert a.shape == b.shape and a.dtype == b.dtype
        assert np.ascontiguousarray(a).tobytes() == b.tobytes()
