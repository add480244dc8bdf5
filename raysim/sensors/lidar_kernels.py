"""Compiled kernels of the LiDAR renderer (:mod:`raysim.jit`), each beside the numpy code it replaces.

:func:`world_rays` is :meth:`raysim.sensors.lidar.LidarRenderer._world_rays` for one ray per
beam, with :func:`groundfloor.hdl32e.beam_directions` folded in: a firing's beam from the
encoder-step tables, then the own-ship's affine map at the cycle start plus its change over
the cycle times the firing's fraction of it, in the numpy path's order of operations.
"""

from __future__ import annotations

import numpy as np

from groundfloor import hdl32e
from raysim.jit import kernel

TURN = hdl32e.CENTIDEG_PER_TURN


@kernel
def _world_rays(firing_az, cos_el, sin_el, cos_az, sin_az, z_offset_m, a0, da, frac, origins_out, directions_out):
    n_cycles, n_lasers = firing_az.shape
    for c in range(n_cycles):
        for j in range(n_lasers):
            step = firing_az[c, j]
            d0 = cos_el[j] * cos_az[step]
            d1 = -cos_el[j] * sin_az[step]
            d2 = sin_el[j]
            z = z_offset_m[j]
            f = frac[j]
            for i in range(3):
                start = d0 * a0[c, 0, i] + d1 * a0[c, 1, i] + d2 * a0[c, 2, i]
                change = d0 * da[c, 0, i] + d1 * da[c, 1, i] + d2 * da[c, 2, i]
                directions_out[c, j, i] = start + change * f
                start = z * a0[c, 2, i] + a0[c, 3, i]
                change = z * da[c, 2, i] + da[c, 3, i]
                origins_out[c, j, i] = start + change * f


def world_rays(firing_az: np.ndarray, cos_el: np.ndarray, sin_el: np.ndarray, cos_az: np.ndarray,
               sin_az: np.ndarray, z_offset_m: np.ndarray, a0: np.ndarray, da: np.ndarray,
               frac: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World rays of C firing cycles of one ray per beam, in one pass.

    Parameters
    ----------
    firing_az : (C, L) uint16
        Encoder step (0.01 deg) of each firing, L lasers.
    cos_el, sin_el, z_offset_m : (L,) float64
        Each laser's elevation cosine and sine and its beam origin's height in the sensor frame, m.
    cos_az, sin_az : (36000,) float64
        Cosine and sine of each encoder step.
    a0, da : (C, 4, 3) float64
        The sensor -> world affine map at each cycle start (rows: R^T, then the origin in m) and its
        change over the cycle.
    frac : (L,) float64
        Each firing's fraction of the cycle.

    Returns
    -------
    origins_m, directions : (C, L, 3) float64
        Ray origins in the world, m, and unit directions (to the map's interpolation).
    """
    shape = firing_az.shape + (3,)
    origins, directions = np.empty(shape), np.empty(shape)
    _world_rays(np.ascontiguousarray(firing_az), cos_el, sin_el, cos_az, sin_az, z_offset_m,
                np.ascontiguousarray(a0), np.ascontiguousarray(da), frac, origins, directions)
    return origins, directions


@kernel
def _decoder_azimuths(block_az, duration, dt, out):
    n_packets, n_blocks = block_az.shape
    n_lasers = dt.shape[1]
    for p in range(n_packets):
        diff = (np.int64(block_az[p, n_blocks - 1]) - np.int64(block_az[p, 0])) % TURN
        rate = np.float32(diff) / duration
        for b in range(n_blocks):
            start = np.float32(block_az[p, b])
            for j in range(n_lasers):
                value = (start + rate * dt[b, j]) + np.float32(TURN)
                out[p, b, j] = np.uint16(np.int64(np.floor(np.float64(value) + 0.5)) % TURN)


def decoder_azimuths(block_az: np.ndarray, dual: bool) -> np.ndarray:
    """:func:`groundfloor.hdl32e.decoder_azimuths_centideg` in one compiled pass, the same float32 steps.

    Parameters
    ----------
    block_az : (P, 12) uint16
        Block azimuths of P packets, 0.01 deg.
    dual : bool
        Dual-return packets.

    Returns
    -------
    (P, 12, 32) uint16
        The azimuth of every firing slot as velodyne_decoder computes it, 0.01 deg.
    """
    duration, dt = hdl32e.firing_time_offsets(dual)
    out = np.empty(block_az.shape + (dt.shape[1],), dtype=np.uint16)
    _decoder_azimuths(np.ascontiguousarray(block_az, dtype=np.uint16), np.float32(duration), dt, out)
    return out


@kernel
def _past_own_ship(key, hit, wet, table_range, table_power, table_byte, own_id, origins, directions, times,
                   cand_range, cand_power, cand_byte, cand_id, free, free_origins, free_directions, free_times):
    n_free = 0
    for i in range(key.shape[0]):
        k = key[i]
        on_own = hit[k]
        if on_own and wet[k]:  # the sea first? (raysim.scene.intersect_sea: -(oz / dz), kept where >= 0)
            sea = -(origins[i, 2] / directions[i, 2])
            if sea >= 0.0 and sea < np.float64(table_range[k]):
                on_own = False
        if on_own:
            cand_range[i, 0] = table_range[k]
            cand_power[i, 0] = table_power[k]
            cand_byte[i, 0] = table_byte[k]
            cand_id[i, 0] = own_id
        else:
            free[n_free] = i
            for a in range(3):
                free_origins[n_free, a] = origins[i, a]
                free_directions[n_free, a] = directions[i, a]
            free_times[n_free] = times[i]
            n_free += 1
    return n_free


def past_own_ship(firing_az: np.ndarray, table: dict, origins_m: np.ndarray, directions: np.ndarray,
                  times_s: np.ndarray, cand) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The own ship's echoes from its beam table into candidate column 0; the other rays gathered to be cast.

    :meth:`raysim.sensors.lidar.LidarRenderer._cast_past_own_ship`'s lookups in one pass (one ray per beam).

    Parameters
    ----------
    firing_az : (C, 32) uint16
        Encoder step of each firing.
    table : dict
        The own-ship beam table (``LidarRenderer._own_ship_table``), (36000 x 32,) per beam.
    origins_m, directions : (N, 3) float64
        The N = 32 C rays in the world, m and unit.
    times_s : (N,) float64
        Each ray's time, s.
    cand : raysim.sensors.lidar._Candidates
        (N, E) candidates, written in column 0 where the own ship answers.

    Returns
    -------
    free : (M,) int64
        The rays not stopped by the own ship, in order.
    origins_m, directions, times_s : (M, 3), (M, 3), (M,)
        Those rays.
    """
    n = origins_m.shape[0]
    key = (firing_az.astype(np.int64) * firing_az.shape[1] + np.arange(firing_az.shape[1])).reshape(-1)
    free = np.empty(n, dtype=np.int64)
    free_o, free_d, free_t = np.empty((n, 3)), np.empty((n, 3)), np.empty(n)
    m = _past_own_ship(key, table["hit"], table["wet"], table["range_m"], table["power"], table["byte"],
                       np.int32(table["object_id"]), origins_m, directions, times_s, cand.range_m, cand.power,
                       cand.byte, cand.object_id, free, free_o, free_d, free_t)
    return free[:m], free_o[:m], free_d[:m], free_t[:m]


__all__ = ["decoder_azimuths", "past_own_ship", "world_rays"]
