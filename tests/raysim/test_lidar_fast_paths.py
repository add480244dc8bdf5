"""The LiDAR renderer's fast paths against the reference computations they replace, bit for bit.

Each reference is the computation as it stood before the fast path (same numpy operations), so a
fast path that changed any value, even in its last bit, fails here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from groundfloor import hdl32e
from raysim import jit
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


# ---------------------------------------------------------------------- measure and points


def reference_cast_past_own_ship(self, cand, rays, firing_azimuth):
    """The own-ship table lookup as it was (fancy indexing)."""
    from raysim.scene import intersect_sea
    from raysim.sensors.lidar import CAST_RANGE_MARGIN_M, _Rays

    t = self.own_table
    azimuth = firing_azimuth.reshape(-1).astype(np.int64)
    key = azimuth * hdl32e.N_LASERS + np.tile(np.arange(hdl32e.N_LASERS), azimuth.size // hdl32e.N_LASERS)
    r_own = t["range_m"][key].astype(np.float64)
    on_own = np.isfinite(r_own)
    wet = np.flatnonzero(t["wet"][key])
    if wet.size:
        on_own[wet] &= ~(intersect_sea(rays.origins_m[wet, 2], rays.directions[wet, 2]) < r_own[wet])
    own = np.flatnonzero(on_own)
    cand.range_m[own, 0] = r_own[own]
    cand.power[own, 0] = t["power"][key[own]]
    cand.byte[own, 0] = t["byte"][key[own]]
    cand.object_id[own, 0] = t["object_id"]
    free = np.flatnonzero(~on_own)
    cast = _Rays(rays.origins_m[free], rays.directions[free], rays.times_s[free])
    hits = self.scene.world.cast(cast.origins_m, cast.directions, cast.times_s,
                                 max_range_m=self.cfg.range_max_m + CAST_RANGE_MARGIN_M)
    return hits, free, cast, None


def reference_world_echoes(self, cand, cast, hits, free, own_body, k):
    """The echoes of the world's hits as they were (fancy indexing, (row, column) writes); ``cast``: the rays cast."""
    from raysim.scene import NO_HIT, SEA_ID
    from raysim.sensors import lidar_physics as phys
    from raysim.sensors.lidar import FOAM_REFLECTANCE, SOURCE_SEA

    o_w, d_w, times = cast.origins_m, cast.directions, cast.times_s
    hit_local = np.flatnonzero(hits.object_id != NO_HIT)
    h = free[hit_local]
    r_h = hits.range_m[hit_local]
    obj_h = hits.object_id[hit_local]
    cos_h = np.abs(np.einsum("ij,ij->i", hits.normal[hit_local], d_w[hit_local]))
    if own_body is not None:
        on_carrier, d_b = own_body
        own_h = np.flatnonzero(on_carrier[h])
        cos_h[own_h] = np.abs(np.einsum("ij,ij->i", hits.normal[hit_local[own_h]], d_b[h[own_h]]))
    mat_h = hits.material[hit_local]
    reflectance = self.materials["reflectance_905nm"][mat_h].astype(np.float64)
    retro = self.materials["retroreflective"][mat_h]
    source = np.zeros(h.size, dtype=np.uint8)
    sea = obj_h == SEA_ID
    if sea.any():
        reflectance[sea] = 0.0
        source[sea] = SOURCE_SEA
        could = np.nonzero(sea & (phys.echo_power(FOAM_REFLECTANCE * cos_h, r_h, self.alpha) >= self.threshold))[0]
        if could.size:
            on_sea = hit_local[could]
            x = o_w[on_sea, 0] + r_h[could] * d_w[on_sea, 0]
            y = o_w[on_sea, 1] + r_h[could] * d_w[on_sea, 1]
            foam = self.foam.is_foam(x, y, times[on_sea])
            reflectance[could[foam]] = FOAM_REFLECTANCE
    power_h = phys.echo_power(reflectance * cos_h, r_h, self.alpha) / k
    row, col = h // k, h % k
    cand.range_m[row, col] = r_h
    cand.power[row, col] = power_h
    cand.byte[row, col] = phys.reflectivity_byte(reflectance, cos_h, retro)
    cand.object_id[row, col] = np.where(sea, -1, obj_h)
    cand.source[row, col] = source


def reference_returns(self, cand, f):
    """The reported returns as they were ((row, column) fancy indexing)."""
    from raysim.sensors import lidar_physics as phys
    from raysim.sensors.lidar import MAX_DISTANCE_UNITS

    echoes = phys.select_echoes(cand.range_m, cand.power, self.threshold)
    strongest, last, group_r, group_id = echoes.strongest, echoes.last, echoes.group_range, echoes.group
    picks = [last, phys.dual_pick(echoes)] if self.dual else [last if self.cfg.return_mode == "last" else strongest]
    n_ret = len(picks)
    units = np.zeros((n_ret, f), dtype=np.uint16)
    refl = np.zeros((n_ret, f), dtype=np.uint8)
    oid = np.full((n_ret, f), -1, dtype=np.int32)
    src = np.zeros((n_ret, f), dtype=np.uint8)
    for i, pick in enumerate(picks):
        rows = np.nonzero(pick >= 0)[0]
        cols = pick[rows]
        measured = group_r[rows, cols]
        if self.cfg.range_noise_m > 0:
            measured = measured + self.noise_rng.normal(0.0, self.cfg.range_noise_m, rows.size)
        q = np.round(measured / hdl32e.DISTANCE_UNIT_M)
        ok = ((measured >= self.cfg.range_min_m) & (measured <= self.cfg.range_max_m) & (q >= 1)
              & (q <= MAX_DISTANCE_UNITS))
        rows, cols = rows[ok], cols[ok]
        units[i, rows] = q[ok]
        refl[i, rows] = cand.byte[rows, cols]
        oid[i, rows] = cand.object_id[rows, cols]
        src[i, rows] = cand.source[rows, cols]
    if self.dual:
        rows = np.arange(f)
        same = (group_id[rows, np.maximum(picks[0], 0)] == group_id[rows, np.maximum(picks[1], 0)]) & (units[0] > 0)
        units[1] = np.where(same, units[0], units[1])
        refl[1] = np.where(same, refl[0], refl[1])
        oid[1] = np.where(same, oid[0], oid[1])
        src[1] = np.where(same, src[0], src[1])
    return units, refl, oid, src


def reference_points(self, fire):
    """The sweep arrays as they were (np.nonzero and fancy indexing)."""
    from raysim.sensors.lidar import DEG_PER_CENTIDEG

    units = fire.distance_units
    keep = units > 0
    if self.dual:
        keep[:, 1] &= units[:, 1] != units[:, 0]
    cc, rr, jj = np.nonzero(keep)
    d = units[cc, rr, jj].astype(np.float64) * hdl32e.DISTANCE_UNIT_M
    az = fire.firing_azimuth[cc, jj]
    xy = d * hdl32e.COS_ELEVATION[jj]
    arrays = {
        "x": (xy * hdl32e.COS_AZIMUTH_STEP[az]).astype(np.float32),
        "y": (-xy * hdl32e.SIN_AZIMUTH_STEP[az]).astype(np.float32),
        "z": (d * hdl32e.SIN_ELEVATION[jj] + hdl32e.Z_OFFSET_M[jj]).astype(np.float32),
        "intensity": fire.reflectivity[cc, rr, jj].astype(np.uint8),
        "ring": hdl32e.RING[jj],
        "time": fire.cycle_time_s[cc] + jj * hdl32e.FIRING_DT_S,
        "azimuth_deg": (az.astype(np.float64) * DEG_PER_CENTIDEG).astype(np.float32),
        "object_id": fire.object_id[cc, rr, jj].astype(np.int32),
        "return_source": fire.source[cc, rr, jj].astype(np.uint8),
        "return_index": rr.astype(np.uint8),
    }
    return arrays, cc


def lidar_of(scenario_file: str, **lidar_changes) -> LidarRenderer:
    """A LiDAR renderer with its ray engine on a scenario of scenarios/, LiDAR settings changed."""
    import dataclasses

    from raysim.materials import material_index
    from raysim.sensors.carrier import CarrierScene

    s = with_overrides(load_scenario(ROOT / "scenarios" / scenario_file), duration_s=3.0, sensors=("lidar",))
    lidar_cfg = dataclasses.replace(s.sensors.lidar, **lidar_changes)
    s = dataclasses.replace(s, sensors=dataclasses.replace(s.sensors, lidar=lidar_cfg))
    world = World(s)
    return LidarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))


@pytest.mark.parametrize("scenario_file, changes", [
    ("busy_open_sea.yaml", {}),
    ("busy_open_sea.yaml", {"return_mode": "dual"}),
    ("rough_sea_rain.yaml", {"return_mode": "last"}),  # weather: a false-echo candidate column
    ("near_shore.yaml", {}),
])
def test_measure_and_points_are_the_reference_bit_for_bit(scenario_file, changes, monkeypatch):
    """A revolution measured and turned into points by the fast paths and by the reference code."""
    import types

    fast, slow = lidar_of(scenario_file, **changes), lidar_of(scenario_file, **changes)  # same seeds: same noise
    slow._cast_past_own_ship = types.MethodType(reference_cast_past_own_ship, slow)
    slow._world_echoes = types.MethodType(reference_world_echoes, slow)
    slow._returns = types.MethodType(reference_returns, slow)
    t, block, _ = one_revolution(fast, 1.5)
    blocks = np.repeat(block, 2) if fast.dual else block
    firing = hdl32e.decoder_azimuths_centideg(blocks.reshape(-1, hdl32e.BLOCKS_PER_PACKET), dual=fast.dual)
    firing = (firing[:, ::2] if fast.dual else firing).reshape(-1, hdl32e.N_LASERS)
    with single_blas_thread():
        a = fast.measure(t, block, firing)
        points, cycles = fast.points(a)
        monkeypatch.setattr(jit, "ENABLED", False)  # the reference: numpy's world rays, then the code above
        b = slow.measure(t, block, firing)
    for name in ("distance_units", "reflectivity", "object_id", "source"):
        assert np.ascontiguousarray(getattr(a, name)).tobytes() == np.ascontiguousarray(getattr(b, name)).tobytes(), name
    assert (a.distance_units > 0).sum() > 1000
    ref_points, ref_cycles = reference_points(slow, b)
    assert list(points) == list(ref_points) and cycles.tobytes() == ref_cycles.tobytes()
    for name, value in points.items():
        assert value.dtype == ref_points[name].dtype and value.tobytes() == ref_points[name].tobytes(), name


def test_reflectivity_byte_without_retro_reflectors_is_the_full_formula():
    from raysim.sensors import lidar_physics as phys

    rng = np.random.default_rng(6)
    reflectance, cos = rng.random(5000), rng.uniform(-0.1, 1.1, 5000)
    for retro in (np.zeros(5000, bool), rng.random(5000) < 0.3):
        diffuse = np.clip(np.round(100.0 * reflectance * cos), 1, 100)
        full = np.where(retro, 101 + np.round(154.0 * np.clip(cos, 0.0, 1.0)), diffuse).astype(np.uint8)
        fast = phys.reflectivity_byte(reflectance, cos, retro)
        assert fast.dtype == np.uint8 and fast.tobytes() == full.tobytes()
