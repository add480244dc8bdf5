"""The HDL-32E's rays: the own ship's beam table, sensor-frame beams, and each firing's ray in the world.

A mixin of :class:`raysim.sensors.lidar.LidarRenderer` (it uses the renderer's ``world``, ``scene``,
``cfg``, ``offsets``, ``mount_rotation``, ``mount_translation`` and ``materials``). Every firing is cast
from the sensor pose at its own instant: the own ship's pose at every cycle boundary, interpolated to
each firing. One ray per beam goes through a compiled kernel (:mod:`raysim.sensors.lidar_kernels`),
sub-rays through numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from groundfloor import hdl32e
from raysim.scene import NO_HIT
from raysim.sensors import lidar_kernels
from raysim.sensors import lidar_physics as phys

#: Rays are cast this far past the maximum range, m, so that range noise can bring an echo just
#: beyond it back in (the measured range is checked against the maximum after the noise).
CAST_RANGE_MARGIN_M = 1.0
#: Own-ship hits below this height above the waterline, m, may have the sea in front of them when
#: the ship rolls or heaves; those beams are checked against the sea at each firing.
WET_HIT_MAX_Z_M = 1.0
#: Each laser's firing instant as a fraction of the 46.08 us cycle, (32,).
FIRING_FRACTION = np.arange(hdl32e.N_LASERS) * (hdl32e.FIRING_DT_S / hdl32e.CYCLE_DT_S)


def _firing_times(cycle_time_s: np.ndarray) -> np.ndarray:
    """(C, 32) time of each firing of C cycles, s."""
    return cycle_time_s[:, None] + np.arange(hdl32e.N_LASERS)[None, :] * hdl32e.FIRING_DT_S


def _add_scaled(total: np.ndarray, change: np.ndarray, scale: np.ndarray) -> None:
    """``total += change * scale`` in place, over rows: total, change (C, M, 3); scale (3 M,).

    Each cycle's row of 3 M values is one pass (a broadcast over the last axis of 3 would step
    three values at a time); ``change`` is overwritten.
    """
    flat_total, flat = total.view(), change.view()
    flat_total.shape = flat.shape = (total.shape[0], -1)  # views (an error, never a silent copy)
    np.multiply(flat, scale, out=flat)
    np.add(flat_total, flat, out=flat_total)


@dataclass
class _Rays:
    """A chunk's N = F K rays in the world: origins (N, 3) m, unit directions (N, 3), firing times (N,) s."""

    origins_m: np.ndarray
    directions: np.ndarray
    times_s: np.ndarray


class LidarGeometry:
    """Ray geometry of :class:`raysim.sensors.lidar.LidarRenderer` (a mixin)."""

    def _own_ship_table(self):
        """Own-ship hits of every beam the sensor can fire: 36000 encoder steps x 32 lasers.

        The own ship is rigid and the mount fixed, so in the body frame these rays never
        change: they are cast once here and looked up for every firing. Kept compact:
        per beam the range, the echo's relative power and reflectivity byte (all constant:
        the incidence and material do not change), and whether the hit is low enough on
        the hull for the sea to come first.
        """
        if self.scene is None or self.scene.carrier is None:
            return None
        steps = hdl32e.CENTIDEG_PER_TURN
        az = np.broadcast_to(np.arange(steps, dtype=np.uint16)[:, None], (steps, hdl32e.N_LASERS))
        origins, directions = self._sensor_rays(az)
        n = origins.shape[0] * hdl32e.N_LASERS
        o_b = origins.reshape(n, 3) @ self.mount_rotation.T + self.mount_translation
        d_b = directions.reshape(n, 3) @ self.mount_rotation.T
        hits = self.scene.carrier_hits(o_b, d_b, max_range_m=self.cfg.range_max_m + CAST_RANGE_MARGIN_M)
        hit = hits.object_id != NO_HIT
        cos_inc = np.abs(np.einsum("ij,ij->i", hits.normal, d_b))
        mat = np.where(hit, hits.material, 0)
        reflectance = np.where(hit, self.materials["reflectance_905nm"][mat], 0.0)
        rng = np.where(hit, hits.range_m, np.inf)
        hit_z = o_b[:, 2] + np.where(hit, hits.range_m, 0.0) * d_b[:, 2]
        return {
            "hit": hit,
            "range_m": rng.astype(np.float32),
            "power": np.where(hit, phys.echo_power(reflectance * cos_inc, rng, self.alpha), 0.0).astype(np.float32),
            "byte": phys.reflectivity_byte(reflectance, cos_inc, self.materials["retroreflective"][mat] & hit),
            # hits near or below the waterline: the sea may come first when the ship rolls or heaves
            "wet": hit & (hit_z < WET_HIT_MAX_Z_M),
            "object_id": self.world.own_ship.object_id,
        }

    def _sensor_rays(self, firing_azimuth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Sensor-frame beam origins and directions, (C, 32, K, 3) each (K sub-rays)."""
        axis = hdl32e.beam_directions(firing_azimuth)  # (C, 32, 3)
        if self.offsets.shape[0] == 1:
            directions = axis[:, :, None, :]
        else:
            # perpendicular unit vectors: u horizontal (azimuth direction), v up-ish
            u = np.stack([-axis[..., 1], axis[..., 0], np.zeros(axis.shape[:-1])], axis=-1)
            u /= np.linalg.norm(u, axis=-1, keepdims=True)
            v = np.cross(axis, u)
            directions = (axis[:, :, None, :] + self.offsets[None, None, :, 0, None] * u[:, :, None, :]
                          + self.offsets[None, None, :, 1, None] * v[:, :, None, :])
            directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
        origins = np.broadcast_to(hdl32e.beam_origins()[None, :, None, :], directions.shape)
        return origins, directions

    def _world_rays(self, cycle_time_s: np.ndarray, origins_s: np.ndarray, directions_s: np.ndarray):
        """Rays in the world at each firing's own instant.

        The own-ship pose is evaluated at the C cycle starts and the next one, and
        interpolated linearly to each firing (1.152 us steps): the error of that
        interpolation over 46 us is below 1e-9 rad.

        Parameters
        ----------
        cycle_time_s : (C,) float64
            Start of each firing cycle, s.
        origins_s, directions_s : (C, 32, K, 3) float64
            Beam origins (m) and unit directions in the sensor frame.

        Returns
        -------
        o_world : (C, 32, K, 3) float64
            Ray origins in the world, m.
        d_world : (C, 32, K, 3) float64
            Unit ray directions in the world.
        t_firing : (C, 32) float64
            Time of each firing, s.
        """
        c, _, k, _ = directions_s.shape
        m = hdl32e.N_LASERS * k
        a0, da = self._cycle_maps(cycle_time_s)
        # the fraction of the cycle at each firing, for every coordinate of its rays: (3 m,)
        frac = np.repeat(FIRING_FRACTION, 3 * k)
        d_world = directions_s.reshape(c, m, 3) @ a0[:, :3]
        _add_scaled(d_world, directions_s.reshape(c, m, 3) @ da[:, :3], frac)
        # origins in homogeneous coordinates [x, y, z, 1] (the same for every cycle)
        homogeneous = np.ones((m, 4))
        homogeneous[:, :3] = origins_s[0].reshape(-1, 3)
        o_world = homogeneous @ a0
        _add_scaled(o_world, homogeneous @ da, frac)
        return o_world.reshape(c, hdl32e.N_LASERS, k, 3), d_world.reshape(c, hdl32e.N_LASERS, k, 3), _firing_times(cycle_time_s)

    def _cycle_maps(self, cycle_time_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The sensor -> world affine map at each cycle start and its change over the cycle, (C, 4, 3) each.

        Row-vector form: ``[x, y, z, 1] @ map`` is the world point of sensor point ``(x, y, z)``
        (rows 0-2 the rotation ``R^T``, row 3 the sensor's origin in the world, m).
        """
        t_edges = np.append(cycle_time_s, cycle_time_s[-1] + hdl32e.CYCLE_DT_S)
        poses = self.world.own_ship.motion.poses(t_edges)
        body = poses.rotation()  # body -> world, (C + 1, 3, 3)
        c = cycle_time_s.shape[0]
        # sensor -> world R^T of every edge in one product of (3 (C + 1), 3) rows
        rot_t = (body.reshape(-1, 3) @ self.mount_rotation).reshape(c + 1, 3, 3).transpose(0, 2, 1)
        pos = poses.position_m + np.einsum("nij,j->ni", body, self.mount_translation)
        a0 = np.empty((c, 4, 3))  # the affine map at each cycle start
        da = np.empty((c, 4, 3))  # and its change over the cycle
        a0[:, :3], a0[:, 3] = rot_t[:-1], pos[:-1]
        np.subtract(rot_t[1:], rot_t[:-1], out=da[:, :3])
        np.subtract(pos[1:], pos[:-1], out=da[:, 3])
        return a0, da

    def _rays_past_own_ship(self, cycle_time_s: np.ndarray, firing_azimuth: np.ndarray, cand):
        """One ray per beam in one compiled pass (:mod:`raysim.jit`): each firing's world ray, the own ship's
        echoes from its beam table into candidate column 0, the other rays gathered to be cast.

        The compiled path of :meth:`_world_rays` (beams included) and ``_cast_past_own_ship``'s lookups.
        Returns the (M,) indices of the rays to cast and those rays (a ``_Rays`` of (M, 3) origins, m,
        unit directions and (M,) times, s).
        """
        a0, da = self._cycle_maps(cycle_time_s)
        beams = (hdl32e.COS_ELEVATION, hdl32e.SIN_ELEVATION, hdl32e.COS_AZIMUTH_STEP, hdl32e.SIN_AZIMUTH_STEP,
                 hdl32e.beam_origins()[:, 2])
        free, o_free, d_free, t_free = lidar_kernels.rays_past_own_ship(
            firing_azimuth, beams, a0, da, FIRING_FRACTION, _firing_times(cycle_time_s), self.own_table, cand)
        return free, _Rays(o_free, d_free, t_free)

    # ------------------------------------------------------------------ physics


__all__ = ["CAST_RANGE_MARGIN_M", "FIRING_FRACTION", "LidarGeometry", "WET_HIT_MAX_Z_M"]
