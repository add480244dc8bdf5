"""Velodyne HDL-32E facts: lasers, firing schedule, packet layout, packet azimuths, beam geometry.

Everything here comes from docs/reference.md section 2 (HDL-32E user manual 63-9113,
ros-drivers/velodyne ``32db.yaml``, valgur/velodyne_decoder ``calib_db.cpp`` and
``packet_decoder.cpp``). The functions are pure and vectorised over firing cycles.

Geometry as decoders reconstruct it (velodyne_decoder, VeloView): laser ``j`` fires
from ``(0, 0, z_offset_j)`` in the sensor frame along
``(cos w cos a, -cos w sin a, sin w)`` (``w`` elevation, ``a`` encoder azimuth
clockwise seen from above; x forward, y left, z up). raysim casts each beam along
exactly the azimuth a decoder computes for it from the packet (the block azimuth in
0.01 deg plus the decoder's rotation-rate interpolation), so decoding our PCAP gives
exactly our points. raysim's writer (raysim.recording.velodyne, raysim.sensors.lidar) and the
TDM's PCAP reader (tdm.pcap) both take these facts from here.
"""

from __future__ import annotations

import numpy as np

#: Laser table in DSR (firing / packet slot) order: elevation (deg) and vertical origin offset (m).
#: docs/reference.md section 2 table (velodyne_decoder calib_db.cpp, ros-drivers 32db.yaml).
ELEVATION_DEG = np.array([
    -30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33, -25.33, -4.00, -24.00, -2.67, -22.67, -1.33, -21.33, 0.00,
    -20.00, 1.33, -18.67, 2.67, -17.33, 4.00, -16.00, 5.33, -14.67, 6.67, -13.33, 8.00, -12.00, 9.33, -10.67, 10.67,
])
Z_OFFSET_M = 1e-3 * np.array([
    17.17, 4.76, 16.27, 4.07, 15.40, 3.38, 14.54, 2.70, 13.71, 2.02, 12.89, 1.35, 12.09, 0.67, 11.31, 0.00,
    10.54, -0.67, 9.78, -1.35, 9.04, -2.02, 8.30, -2.70, 7.58, -3.38, 6.86, -4.07, 6.15, -4.76, 5.45, -5.45,
])
#: Ring = rank of the laser by elevation (0 = lowest), per DSR slot.
RING = np.argsort(np.argsort(ELEVATION_DEG, kind="stable"), kind="stable").astype(np.uint8)
N_LASERS = 32

FIRING_DT_S = 1.152e-6  # one laser every 1.152 us
CYCLE_DT_S = 46.08e-6  # 32 firings + 9.216 us recharge
FIRING_DT_NS = 1152  # the same in integer nanoseconds (exact)
CYCLE_DT_NS = 46080
BLOCKS_PER_PACKET = 12
PACKET_BYTES = 1206  # UDP payload of a data packet
POSITION_PACKET_BYTES = 512
DISTANCE_UNIT_M = 0.002  # 2 mm units, 0 = no return
MAX_ENCODED_RANGE_M = 65535 * DISTANCE_UNIT_M  # 131.07 m
PRODUCT_ID = 0x21
#: Product id bytes (1205) a reader accepts: 0x00 too (firmware that leaves it blank) (unverified).
PRODUCT_IDS_ACCEPTED = (PRODUCT_ID, 0x00)
RETURN_MODE_BYTE = {"strongest": 0x37, "last": 0x38, "dual": 0x39}  # byte 1204
RETURN_MODE_DUAL = RETURN_MODE_BYTE["dual"]
DATA_PORT = 2368
POSITION_PORT = 8308
BLOCK_FLAG = 0xEEFF  # bytes FF EE read little-endian
CENTIDEG_PER_TURN = 36000

#: A data packet's 1206 bytes: 12 blocks (flag, azimuth in 0.01 deg, 32 x (distance in 2 mm,
#: reflectivity)), the timestamp (microseconds past the UTC hour), the return mode, the product id.
BLOCK_DTYPE = np.dtype([("flag", "<u2"), ("azimuth", "<u2"),
                        ("returns", np.dtype([("distance", "<u2"), ("reflectivity", "u1")]), (N_LASERS,))])
PACKET_DTYPE = np.dtype([("blocks", BLOCK_DTYPE, (BLOCKS_PER_PACKET,)), ("timestamp", "<u4"),
                         ("return_mode", "u1"), ("product_id", "u1")])
assert PACKET_DTYPE.itemsize == PACKET_BYTES


def block_azimuth_centideg(cycle_time_s: np.ndarray, rotation_hz: float, azimuth0_deg: float = 0.0) -> np.ndarray:
    """Encoder azimuth of each block's first firing, in 0.01 deg units (uint16, 0..35999).

    Parameters
    ----------
    cycle_time_s : (C,) float64
        Time of each firing cycle's first firing, s.
    rotation_hz : float
        Head rotation rate, Hz (clockwise seen from above).
    azimuth0_deg : float
        Azimuth at t = 0, deg.
    """
    azimuth = azimuth0_deg + 360.0 * rotation_hz * np.asarray(cycle_time_s, dtype=float)
    return (np.round(np.mod(azimuth, 360.0) * 100.0).astype(np.int64) % 36000).astype(np.uint16)


def firing_azimuths_centideg(block_az: np.ndarray, dual) -> np.ndarray:
    """Azimuth of every firing slot as velodyne_decoder computes it from the block azimuths.

    velodyne_decoder (``unpack_16_32_beam``): the rotation rate of a packet is
    ``wrap(az[11] - az[0]) / (t[11] - t[0])`` and firing ``j`` of a block lies at
    ``wrap(lround(block_az + rate * (t_j - t_0)))``, all in float32.

    Parameters
    ----------
    block_az : (P, 12) uint16
        Block azimuths of P packets, 0.01 deg.
    dual : bool or (P,) bool
        Dual-return packets (6 firing cycles, blocks in pairs with the same azimuth).

    Returns
    -------
    (P, 12, 32) int64
        Azimuth of every firing slot, 0.01 deg, in 0..35999.
    """
    dual = np.broadcast_to(np.asarray(dual, dtype=bool), block_az.shape[:1])
    az = block_az.astype(np.int64)
    diff = np.mod(az[:, -1] - az[:, 0], CENTIDEG_PER_TURN).astype(np.float32)
    out = np.empty(block_az.shape + (N_LASERS,), dtype=np.int64)
    for is_dual in (False, True):
        rows = np.flatnonzero(dual == is_dual)
        if rows.size == 0:
            continue
        duration, dt = firing_time_offsets(is_dual)
        rate = diff[rows] / duration  # (R,) float32, 0.01 deg per s
        value = block_az[rows].astype(np.float32)[:, :, None] + rate[:, None, None] * dt[None, :, :]
        value = value.astype(np.float32) + np.float32(CENTIDEG_PER_TURN)
        out[rows] = np.floor(value.astype(np.float64) + 0.5).astype(np.int64) % CENTIDEG_PER_TURN  # lround (> 0)
    return out


def firing_time_offsets(dual: bool) -> tuple[np.float32, np.ndarray]:
    """velodyne_decoder's timing of a packet, in float32: the time from its first to its last block, s,
    and (12, 32) each firing slot's time since its block's first firing, s.

    The decoder's timing table holds float32 of (cycle * 46.08 us + j * 1.152 us); in dual-return
    packets blocks come in pairs of one cycle.
    """
    cycles = np.arange(BLOCKS_PER_PACKET, dtype=np.float64)
    if dual:
        cycles = cycles // 2
    duration = np.float32(CYCLE_DT_S * cycles[-1])
    table = (CYCLE_DT_S * cycles[:, None] + FIRING_DT_S * np.arange(N_LASERS)[None, :]).astype(np.float32)
    return duration, (table - table[:, :1]).astype(np.float32)


def decoder_azimuths_centideg(block_az: np.ndarray, dual: bool = False) -> np.ndarray:
    """(P, 12, 32) uint16: :func:`firing_azimuths_centideg` of packets all single- or all dual-return."""
    return firing_azimuths_centideg(block_az, dual).astype(np.uint16)


#: cosines and sines of the 36000 encoder steps and of the 32 elevations (the decoders' lookup tables, shared by the renderer and the reader)
COS_AZIMUTH_STEP = np.cos(np.radians(np.arange(CENTIDEG_PER_TURN) * 0.01))
SIN_AZIMUTH_STEP = np.sin(np.radians(np.arange(CENTIDEG_PER_TURN) * 0.01))
COS_ELEVATION = np.cos(np.radians(ELEVATION_DEG))
SIN_ELEVATION = np.sin(np.radians(ELEVATION_DEG))


def beam_directions(azimuth_centideg: np.ndarray) -> np.ndarray:
    """Unit beam directions in the sensor frame for firing slots.

    Parameters
    ----------
    azimuth_centideg : (..., 32) uint16
        Decoder azimuth of each firing slot (last axis = DSR).

    Returns
    -------
    (..., 32, 3) float64
        ``(cos w cos a, -cos w sin a, sin w)`` (cosines from a table of the 36000 encoder steps).
    """
    out = np.empty(azimuth_centideg.shape + (3,))
    out[..., 0] = COS_ELEVATION * np.take(COS_AZIMUTH_STEP, azimuth_centideg)  # np.take: fancy indexing's values, faster
    out[..., 1] = -COS_ELEVATION * np.take(SIN_AZIMUTH_STEP, azimuth_centideg)
    out[..., 2] = SIN_ELEVATION
    return out


def beam_origins() -> np.ndarray:
    """(32, 3) origins of the beams in the sensor frame, metres: (0, 0, z_offset)."""
    out = np.zeros((N_LASERS, 3))
    out[:, 2] = Z_OFFSET_M
    return out


def cycles_per_revolution(rotation_hz: float) -> float:
    """Firing cycles in one revolution (2170.1 at 10 Hz)."""
    return 1.0 / (rotation_hz * CYCLE_DT_S)
