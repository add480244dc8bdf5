"""Compiled kernels of the LiDAR renderer (:mod:`raysim.jit`), each beside the numpy code it replaces.

:func:`rays_past_own_ship` is :meth:`raysim.sensors.lidar.LidarRenderer._world_rays` for one ray
per beam, with :func:`groundfloor.hdl32e.beam_directions` folded in (:func:`_ray`: a firing's beam
from the encoder-step tables, then the own-ship's affine map at the cycle start plus its change over
the cycle times the firing's fraction of it, in the numpy path's order of operations), fused with the
own ship's beam-table lookups: a ray the own ship stops is never written out, the others once.
"""

from __future__ import annotations

import numpy as np

from groundfloor import hdl32e
from raysim.jit import kernel
from raysim.scene import NO_HIT as NO_HIT_ID

TURN = hdl32e.CENTIDEG_PER_TURN
#: Encoder steps (0.01 deg) to degrees.
DEG_PER_STEP = 0.01


@kernel
def _ray(c, j, firing_az, cos_el, sin_el, cos_az, sin_az, z_offset_m, a0, da, frac, origin_out, direction_out):
    """The world ray of laser ``j`` in cycle ``c`` into the (3,) outputs (the numpy path's order of operations)."""
    step = firing_az[c, j]
    d0 = cos_el[j] * cos_az[step]
    d1 = -cos_el[j] * sin_az[step]
    d2 = sin_el[j]
    z = z_offset_m[j]
    f = frac[j]
    for i in range(3):
        start = d0 * a0[c, 0, i] + d1 * a0[c, 1, i] + d2 * a0[c, 2, i]
        change = d0 * da[c, 0, i] + d1 * da[c, 1, i] + d2 * da[c, 2, i]
        direction_out[i] = start + change * f
        start = z * a0[c, 2, i] + a0[c, 3, i]
        change = z * da[c, 2, i] + da[c, 3, i]
        origin_out[i] = start + change * f


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
def _rays_past_own_ship(firing_az, cos_el, sin_el, cos_az, sin_az, z_offset_m, a0, da, frac, firing_times,
                        hit, wet, table_range, table_power, table_byte, own_id,
                        cand_range, cand_power, cand_byte, cand_id, free, free_origins, free_directions, free_times):
    n_cycles, n_lasers = firing_az.shape
    origin, direction = np.empty(3), np.empty(3)
    n_free = 0
    for c in range(n_cycles):
        for j in range(n_lasers):
            i = c * n_lasers + j
            k = np.int64(firing_az[c, j]) * n_lasers + j
            _ray(c, j, firing_az, cos_el, sin_el, cos_az, sin_az, z_offset_m, a0, da, frac, origin, direction)
            on_own = hit[k]
            if on_own and wet[k]:  # the sea first? (raysim.scene.intersect_sea: -(oz / dz), kept where >= 0)
                sea = -(origin[2] / direction[2])
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
                    free_origins[n_free, a] = origin[a]
                    free_directions[n_free, a] = direction[a]
                free_times[n_free] = firing_times[c, j]
                n_free += 1
    return n_free


def rays_past_own_ship(firing_az: np.ndarray, beams: tuple, a0: np.ndarray, da: np.ndarray, frac: np.ndarray,
                       firing_times_s: np.ndarray, table: dict,
                       cand) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each firing's world ray (:func:`_ray`), answered from the own-ship beam table or gathered to be cast.

    :meth:`raysim.sensors.lidar.LidarRenderer._cast_past_own_ship`'s lookups fused with the world rays in one
    pass (one ray per beam): the rays the own ship stops are never written out, the others only once.

    Parameters
    ----------
    firing_az : (C, 32) uint16
        Encoder step of each firing.
    beams : tuple
        ``(cos_el, sin_el, cos_az, sin_az, z_offset_m)``: each laser's elevation cosine and sine, (32,); the
        cosine and sine of each encoder step, (36000,); each beam origin's height in the sensor frame, (32,) m.
    a0, da : (C, 4, 3) float64
        The sensor -> world affine map at each cycle start and its change over the cycle.
    frac : (32,) float64
        Each firing's fraction of the cycle.
    firing_times_s : (C, 32) float64
        Each firing's time, s.
    table : dict
        The own-ship beam table (``LidarRenderer._own_ship_table``), (36000 x 32,) per beam.
    cand : raysim.sensors.lidar._Candidates
        (32 C, E) candidates, written in column 0 where the own ship answers.

    Returns
    -------
    free : (M,) int64
        The rays not stopped by the own ship (firing index), in order.
    origins_m, directions, times_s : (M, 3), (M, 3), (M,)
        Those rays in the world: m, unit, s.
    """
    n = firing_az.size
    free = np.empty(n, dtype=np.int64)
    free_o, free_d, free_t = np.empty((n, 3)), np.empty((n, 3)), np.empty(n)
    m = _rays_past_own_ship(np.ascontiguousarray(firing_az), *beams, np.ascontiguousarray(a0), np.ascontiguousarray(da),
                            frac, np.ascontiguousarray(firing_times_s), table["hit"], table["wet"], table["range_m"],
                            table["power"], table["byte"], np.int32(table["object_id"]), cand.range_m, cand.power,
                            cand.byte, cand.object_id, free, free_o, free_d, free_t)
    return free[:m], free_o[:m], free_d[:m], free_t[:m]


@kernel
def _echo_geometry(hit_rows, ranges, normals, materials, object_ids, origins, directions, times,
                   reflectance_table, sea_id, foam_reflectance, attenuation, threshold,
                   cos_out, reflectance_out, foam_rows, foam_x, foam_y, foam_t):
    n_foam = 0
    for j in range(hit_rows.shape[0]):
        row = hit_rows[j]
        r = ranges[row]
        # numpy's einsum("ij,ij->i") sums a row of 3 as (x + z) + y: the same order gives the same bits
        cos = abs((np.float64(normals[row, 0]) * directions[row, 0] + np.float64(normals[row, 2]) * directions[row, 2])
                  + np.float64(normals[row, 1]) * directions[row, 1])
        cos_out[j] = cos
        if object_ids[row] == sea_id:  # calm water: a mirror; foam where a foam echo could be detected at all
            reflectance_out[j] = 0.0
            if ((foam_reflectance * cos) * attenuation[j]) / (r * r) >= threshold:
                foam_rows[n_foam] = j
                foam_x[n_foam] = origins[row, 0] + r * directions[row, 0]
                foam_y[n_foam] = origins[row, 1] + r * directions[row, 1]
                foam_t[n_foam] = times[row]
                n_foam += 1
        else:
            reflectance_out[j] = np.float64(reflectance_table[materials[row]])
    return n_foam


@kernel
def _echo_values(hit_rows, free, ranges, materials, object_ids, sea_id, cos_h, reflectance, attenuation, retro_table,
                 source_sea, cand_range, cand_power, cand_byte, cand_id, cand_source):
    for j in range(hit_rows.shape[0]):
        row = hit_rows[j]
        h = free[row]
        r = ranges[row]
        cos = cos_h[j]
        rho = reflectance[j]
        cand_range[h, 0] = r
        cand_power[h, 0] = ((rho * cos) * attenuation[j]) / (r * r)
        if retro_table[materials[row]]:
            cand_byte[h, 0] = np.uint8(101.0 + np.rint(154.0 * min(max(cos, 0.0), 1.0)))
        else:
            cand_byte[h, 0] = np.uint8(min(max(np.rint((100.0 * rho) * cos), 1.0), 100.0))
        sea = object_ids[row] == sea_id
        cand_id[h, 0] = -1 if sea else object_ids[row]
        cand_source[h, 0] = source_sea if sea else 0


def world_echoes(hits, free: np.ndarray, origins_m: np.ndarray, directions: np.ndarray, times_s: np.ndarray,
                 materials: dict, alpha_per_m: float, threshold: float, foam, cand, sea_id: int, source_sea: int,
                 foam_reflectance: float) -> None:
    """The world's echoes of one ray per beam into candidate column 0 (``LidarRenderer._world_echoes``, K = 1).

    Two compiled passes around the foam field's test (numpy, :meth:`raysim.sea.FoamField.is_foam`): the
    incidence cosine, reflectance and the sea hits that could show foam; then each echo's range, power
    ``rho cos exp(-2 alpha R) / R^2``, reflectivity byte, id and source. The atmosphere's
    ``exp(-2 alpha R)`` is numpy's (1 without fog or rain), so the powers are the numpy path's.

    Parameters
    ----------
    hits : raysim.scene.Hits
        The world's first hits of the M rays cast.
    free : (M,) int64
        The chunk's ray index of each ray cast.
    origins_m, directions : (M, 3) float64; times_s : (M,) float64
        The rays cast (row i: the chunk's ray ``free[i]``).
    materials : dict
        :func:`raysim.materials.material_table`.
    alpha_per_m, threshold : float
        Extinction, 1/m, and the detection threshold (relative power).
    foam : raysim.sea.FoamField
    cand : raysim.sensors.lidar._Candidates
        (N, E) candidates, column 0 written at the rays that hit something.
    sea_id, source_sea : int
        The sea's hit id and the sea's return source.
    foam_reflectance : float
        Foam's diffuse reflectance at 905 nm.
    """
    hit_rows = np.flatnonzero(hits.object_id != NO_HIT_ID)
    m = hit_rows.size
    ranges = hits.range_m
    attenuation = (np.exp(-2.0 * alpha_per_m * np.take(ranges, hit_rows)) if alpha_per_m > 0 else np.ones(m))
    cos_h, reflectance = np.empty(m), np.empty(m)
    foam_rows, foam_x, foam_y, foam_t = np.empty(m, np.int64), np.empty(m), np.empty(m), np.empty(m)
    normals = np.ascontiguousarray(hits.normal)
    n_foam = _echo_geometry(hit_rows, ranges, normals, hits.material, hits.object_id, origins_m, directions,
                            times_s, materials["reflectance_905nm"], sea_id, foam_reflectance, attenuation, threshold,
                            cos_h, reflectance, foam_rows, foam_x, foam_y, foam_t)
    if n_foam:
        is_foam = foam.is_foam(foam_x[:n_foam], foam_y[:n_foam], foam_t[:n_foam])
        reflectance[foam_rows[:n_foam][is_foam]] = foam_reflectance
    _echo_values(hit_rows, free, ranges, hits.material, hits.object_id, sea_id, cos_h, reflectance, attenuation,
                 materials["retroreflective"], source_sea, cand.range_m, cand.power, cand.byte, cand.object_id,
                 cand.source)


@kernel
def _detected(range_m, power, threshold, rows):
    n = 0
    for i in range(range_m.shape[0]):
        if np.isfinite(range_m[i, 0]) and power[i, 0] >= threshold:
            rows[n] = i
            n += 1
    return n


@kernel
def _quantised(rows, range_m, noise_m, unit_m, range_min_m, range_max_m, max_units, byte, object_id, source,
               units_out, byte_out, id_out, source_out):
    for i in range(rows.shape[0]):
        row = rows[i]
        measured = range_m[row, 0] + noise_m[i]
        q = np.rint(measured / unit_m)
        if measured >= range_min_m and measured <= range_max_m and q >= 1 and q <= max_units:
            units_out[row] = np.uint16(q)
            byte_out[row] = byte[row, 0]
            id_out[row] = object_id[row, 0]
            source_out[row] = source[row, 0]


def single_returns(cand, threshold: float, noise_rng, noise_m: float, unit_m: float, range_min_m: float,
                   range_max_m: float, max_units: int):
    """``LidarRenderer._returns`` for one candidate per firing (one ray per beam, clear air), one return each.

    A firing returns its candidate when it is detected (finite range, power at the threshold or
    above); its range gets the range noise (numpy's draws, one per return in firing order, as the
    numpy path draws them) and is quantised to the packets' units, kept within the sensor's range.

    Returns
    -------
    units, byte, object_id, source : (1, F)
        uint16 distance units (0: no return), uint8 reflectivity, int32 ids (-1: none), uint8 sources.
    """
    f = cand.range_m.shape[0]
    rows = np.empty(f, dtype=np.int64)
    rows = rows[:_detected(cand.range_m, cand.power, threshold, rows)]
    noise = noise_rng.normal(0.0, noise_m, rows.size) if noise_m > 0 else np.zeros(rows.size)
    units, byte = np.zeros((1, f), dtype=np.uint16), np.zeros((1, f), dtype=np.uint8)
    object_id, source = np.full((1, f), -1, dtype=np.int32), np.zeros((1, f), dtype=np.uint8)
    _quantised(rows, cand.range_m, noise, unit_m, range_min_m, range_max_m, max_units, cand.byte, cand.object_id,
               cand.source, units[0], byte[0], object_id[0], source[0])
    return units, byte, object_id, source


@kernel
def _count_returns(units):
    n = 0
    for c in range(units.shape[0]):
        for j in range(units.shape[2]):
            if units[c, 0, j] > 0:
                n += 1
    return n


@kernel
def _points(units, reflectivity, object_ids, sources, firing_az, cycle_time_s, cos_el, sin_el, z_offset_m, cos_az,
            sin_az, ring, unit_m, firing_dt_s, deg_per_step, x, y, z, intensity, ring_out, time, azimuth_deg, ids,
            source_out, cycle_out):
    n_cycles, n_lasers = firing_az.shape
    k = 0
    for c in range(n_cycles):
        for j in range(n_lasers):
            u = units[c, 0, j]
            if u == 0:
                continue
            d = np.float64(u) * unit_m
            a = firing_az[c, j]
            xy = d * cos_el[j]
            x[k] = np.float32(xy * cos_az[a])
            y[k] = np.float32(-xy * sin_az[a])
            z[k] = np.float32(d * sin_el[j] + z_offset_m[j])
            intensity[k] = reflectivity[c, 0, j]
            ring_out[k] = ring[j]
            time[k] = cycle_time_s[c] + np.float64(j) * firing_dt_s
            azimuth_deg[k] = np.float32(np.float64(a) * deg_per_step)
            ids[k] = object_ids[c, 0, j]
            source_out[k] = sources[c, 0, j]
            cycle_out[k] = c
            k += 1


def points(distance_units: np.ndarray, reflectivity: np.ndarray, object_id: np.ndarray, source: np.ndarray,
           firing_az: np.ndarray, cycle_time_s: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """``LidarRenderer.points`` of single-return firings in one pass: the sweep arrays and each point's cycle.

    Parameters
    ----------
    distance_units, reflectivity, object_id, source : (C, 1, 32)
        The chunk's returns (uint16 units of 2 mm, 0: none; uint8; int32; uint8).
    firing_az : (C, 32) uint16
        Encoder step of each firing.
    cycle_time_s : (C,) float64
        Start of each cycle, s.

    Returns
    -------
    arrays : dict of (N,) arrays
        The NPZ contract's x, y, z (float32, m), intensity, ring, time (s), azimuth_deg, object_id,
        return_source, return_index, in firing order.
    cycle : (N,) int64
        Each point's cycle.
    """
    n = _count_returns(distance_units)
    x, y, z = np.empty(n, np.float32), np.empty(n, np.float32), np.empty(n, np.float32)
    intensity, ring, time = np.empty(n, np.uint8), np.empty(n, np.uint8), np.empty(n)
    azimuth_deg, ids, source_out = np.empty(n, np.float32), np.empty(n, np.int32), np.empty(n, np.uint8)
    cycle = np.empty(n, np.int64)
    _points(distance_units, reflectivity, object_id, source, np.ascontiguousarray(firing_az), cycle_time_s,
            hdl32e.COS_ELEVATION, hdl32e.SIN_ELEVATION, hdl32e.Z_OFFSET_M, hdl32e.COS_AZIMUTH_STEP,
            hdl32e.SIN_AZIMUTH_STEP, hdl32e.RING, hdl32e.DISTANCE_UNIT_M, hdl32e.FIRING_DT_S, DEG_PER_STEP,
            x, y, z, intensity, ring, time, azimuth_deg, ids, source_out, cycle)
    arrays = {"x": x, "y": y, "z": z, "intensity": intensity, "ring": ring, "time": time, "azimuth_deg": azimuth_deg,
              "object_id": ids, "return_source": source_out, "return_index": np.zeros(n, np.uint8)}
    return arrays, cycle


__all__ = ["decoder_azimuths", "points", "rays_past_own_ship", "single_returns", "world_echoes"]
