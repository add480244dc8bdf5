"""Velodyne HDL-32E facts: lasers, firing schedule, packet azimuths, beam geometry.

Everything here comes from docs/reference.md section 2 (HDL-32E user manual 63-9113,
ros-drivers/velodyne ``32db.yaml``, valgur/velodyne_decoder ``calib_db.cpp`` and
``packet_decoder.cpp``). The functions are pure and vectorised over firing cycles.

Geometry as decoders reconstruct it (velodyne_decoder, VeloView): laser ``j`` fires
from ``(0, 0, z_offset_j)`` in the sensor frame along
``(cos w cos a, -cos w sin a, sin w)`` (``w`` elevation, ``a`` encoder azimuth
clockwise seen from above; x forward, y left, z up). raysim casts each beam along
exactly the azimuth a decoder computes for it from the packet (the block azimuth in
0.01 deg plus the decoder's rotation-rate interpolation), so decoding our PCAP gives
exactly our points.
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
BLOCKS_PER_PACKET = 12
PACKET_BYTES = 1206
DISTANCE_UNIT_M = 0.002  # 2 mm units
MAX_ENCODED_RANGE_M = 65535 * DISTANCE_UNIT_M  # 131.07 m
PRODUCT_ID = 0x21
RETURN_MODE_BYTE = {"strongest": 0x37, "last": 0x38, "dual": 0x39}
DATA_PORT = 2368
POSITION_PORT = 8308


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


def decoder_azimuths_centideg(block_az: np.ndarray, dual: bool = False) -> np.ndarray:
    """Per-firing azimuths as a decoder computes them from packet block azimuths.

    velodyne_decoder (``unpack_16_32_beam``): the rotation rate of a packet is
    ``wrap(az[11] - az[0]) / (t[11] - t[0])`` and firing ``j`` of a block lies at
    ``wrap(lround(block_az + rate * j * 1.152 us))``, all in float32.

    Parameters
    ----------
    block_az : (P, 12) uint16
        Block azimuths of P packets, 0.01 deg.
    dual : bool
        Dual-return packets (6 firing cycles, blocks in pairs).

    Returns
    -------
    (P, 12, 32) uint16
        Azimuth of every firing slot, 0.01 deg.
    """
    az = block_az.astype(np.int64)
    diff = np.mod(az[:, -1] - az[:, 0], 36000).astype(np.float32)
    last_cycle = (BLOCKS_PER_PACKET - 1) // 2 if dual else BLOCKS_PER_PACKET - 1
    duration = np.float32(CYCLE_DT_S * last_cycle) - np.float32(0.0)
    rate = diff / duration  # (P,) float32, 0.01 deg per s
    # the decoder's timing table holds float32 of (cycle*46.08us + j*1.152us); dt = t[j] - t[0]
    cycles = (np.arange(BLOCKS_PER_PACKET) // (2 if dual else 1)).astype(np.float64)
    table = (CYCLE_DT_S * cycles[:, None] + FIRING_DT_S * np.arange(N_LASERS)[None, :]).astype(np.float32)
    dt = (table - table[:, :1]).astype(np.float32)  # (12, 32)
    value = block_az.astype(np.float32)[:, :, None] + rate[:, None, None] * dt[None, :, :]
    value = value.astype(np.float32) + np.float32(36000.0)
    rounded = np.floor(value.astype(np.float64) + 0.5).astype(np.int64)  # lround of a positive float
    return (rounded % 36000).astype(np.uint16)


#: cosines and sines of the 36000 encoder steps and of the 32 elevations (tables shared with the renderer)
COS_AZIMUTH_STEP = np.cos(np.radians(np.arange(36000) * 0.01))
SIN_AZIMUTH_STEP = np.sin(np.radians(np.arange(36000) * 0.01))
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
    out[..., 0] = COS_ELEVATION * COS_AZIMUTH_STEP[azimuth_centideg]
    out[..., 1] = -COS_ELEVATION * SIN_AZIMUTH_STEP[azimuth_centideg]
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
