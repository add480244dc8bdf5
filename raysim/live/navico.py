"""Radar spokes in the Navico Broadband 3G/4G network format (what OpenCPN's radar_pi reads).

Layout (radar_pi ``src/navico/br4gatype.h`` and ``NavicoReceive.cpp``; checked against a real HALO
capture, docs/live.md): a UDP datagram is a frame of an 8-byte frame header and up to 120 (32 on the
real sets) spoke lines, each a 24-byte ``br4g_header`` and 512 bytes of 4-bit samples, the nearer
sample of each pair in the low nibble. The header, little-endian:

====== ============ ===================================================================
offset field        value written here
====== ============ ===================================================================
0      headerLen    0x18
1      status       0x02 (valid spoke)
2-3    scan_number  spoke counter, 0..4095
4-5    u00          0x4400 (bytes 00 44), "always"
6-7    largerange   0x0080: the range is in ``smallrange`` in quarter metres
8-9    angle        antenna angle from the bow, 4096 a turn (2 steps a spoke at 2048 spokes)
10-11  heading      true heading, 4096 a turn, with the 0x4000 "true heading" flag
12-13  smallrange   range of the last sample, quarter metres
14-15  rotation     the angle again
16-19  u02          -1
20-23  u03          -1 with 0x80 in the last byte
====== ============ ===================================================================

Range scales over 16,383 m do not fit quarter metres in 16 bits; they are written HALO-style,
``largerange = metres``, ``smallrange = 512`` (metres = large x small / 512), which radar_pi and the
other open decoders read the same way for 4G and HALO.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FRAME_HEADER", "SPOKE_HEADER_BYTES", "SPOKE_DATA_BYTES", "SPOKES_PER_FRAME", "ANGLE_UNITS_PER_TURN",
           "HEADING_TRUE_FLAG", "RADAR_MULTICAST", "spoke_frames", "range_fields"]

#: Frame header as the real sets send it (HALO capture; bytes 5 and 7: 32 spokes, 0x02).
FRAME_HEADER = bytes([0x01, 0x00, 0x00, 0x00, 0x00, 0x20, 0x00, 0x02])
SPOKE_HEADER_BYTES = 24
#: 1024 samples of 4 bits.
SPOKE_DATA_BYTES = 512
#: Spokes in one frame (datagram), as the real sets send.
SPOKES_PER_FRAME = 32
ANGLE_UNITS_PER_TURN = 4096
HEADING_TRUE_FLAG = 0x4000
#: Where a real Broadband 3G/4G multicasts its spokes (radar_pi NavicoCommon.h).
RADAR_MULTICAST = ("236.6.7.8", 6678)
#: Largest range scale written as quarter metres in ``smallrange``, m.
QUARTER_METRE_MAX_M = 0xFFFE // 4
#: ``largerange`` value that flags quarter metres in ``smallrange``.
LARGE_RANGE_QUARTER_METRES = 0x80
#: ``smallrange`` of the HALO form (metres = large x small / 512).
SMALL_RANGE_HALO = 512


def range_fields(range_m: float) -> tuple[int, int]:
    """(largerange, smallrange) of a range scale, metres (module docstring)."""
    if range_m <= QUARTER_METRE_MAX_M:
        return LARGE_RANGE_QUARTER_METRES, int(round(range_m * 4.0))
    return min(int(round(range_m)), 0xFFFF), SMALL_RANGE_HALO


def _pack_nibbles(levels: np.ndarray) -> np.ndarray:
    """(S, 1024) levels 0..15 -> (S, 512) bytes, even samples in the low nibble."""
    lv = np.minimum(levels, 15).astype(np.uint8)
    return (lv[:, 0::2] | (lv[:, 1::2] << 4)).astype(np.uint8)


def spoke_frames(levels: np.ndarray, spoke_index: np.ndarray, n_spokes: int, heading_deg: np.ndarray,
                 range_m: float, spokes_per_frame: int = SPOKES_PER_FRAME) -> list[bytes]:
    """Datagrams of spokes in the Broadband 3G/4G format.

    Parameters
    ----------
    levels : (S, N) uint8
        Video levels 0..15 of S spokes; N samples (resampled to 1024 if N differs, nearest sample).
    spoke_index : (S,) int
        Each spoke's index in the revolution (0 = dead ahead), of ``n_spokes``.
    n_spokes : int
        Spokes in a revolution.
    heading_deg : (S,) float
        The own ship's true heading at each spoke, degrees.
    range_m : float
        Range of the last sample, metres.
    spokes_per_frame : int
        Spokes per datagram.

    Returns
    -------
    list of bytes
        ``ceil(S / spokes_per_frame)`` datagrams, spokes in the given order.
    """
    s, n = levels.shape
    if n != 2 * SPOKE_DATA_BYTES:
        levels = levels[:, (np.arange(2 * SPOKE_DATA_BYTES) * n) // (2 * SPOKE_DATA_BYTES)]
    angle = (np.asarray(spoke_index, np.int64) * ANGLE_UNITS_PER_TURN // n_spokes) % ANGLE_UNITS_PER_TURN
    heading = np.rint(np.mod(heading_deg, 360.0) * ANGLE_UNITS_PER_TURN / 360.0).astype(np.int64) % ANGLE_UNITS_PER_TURN
    large, small = range_fields(range_m)
    header = np.zeros((s, SPOKE_HEADER_BYTES), np.uint8)
    header[:, 0] = SPOKE_HEADER_BYTES
    header[:, 1] = 0x02
    header[:, 2:4] = _le16(np.asarray(spoke_index, np.int64) % ANGLE_UNITS_PER_TURN)
    header[:, 4:6] = (0x00, 0x44)
    header[:, 6:8] = _le16(np.full(s, large))
    header[:, 8:10] = _le16(angle)
    header[:, 10:12] = _le16(heading | HEADING_TRUE_FLAG)
    header[:, 12:14] = _le16(np.full(s, small))
    header[:, 14:16] = _le16(angle)
    header[:, 16:20] = 0xFF
    header[:, 20:24] = (0xFF, 0xFF, 0xFF, 0x80)
    lines = np.concatenate([header, _pack_nibbles(levels)], axis=1)
    return [FRAME_HEADER + lines[a:a + spokes_per_frame].tobytes() for a in range(0, s, spokes_per_frame)]


def _le16(values: np.ndarray) -> np.ndarray:
    """(S, 2) little-endian bytes of 16-bit values."""
    v = np.asarray(values, np.int64) & 0xFFFF
    return np.stack([v & 0xFF, v >> 8], axis=1).astype(np.uint8)


#: Where a Navico radar announces itself (radar_pi ``NavicoLocate.cpp``: the 01 B2 beacon).
BEACON_ADDRESS = ("236.6.7.5", 6878)
#: Field layout of the 01 B2 beacon (radar_pi ``RadarReport_01B2``): id, serial number, then address
#: blocks of 4 bytes of IPv4 and 2 of port (network order) with unknown bytes between; radar A's data,
#: command and report addresses are the 6th, 7th and 8th address blocks (radar B's the 9th to 11th).
BEACON_FORMAT = "<H16s6s12s6s4s6s10s6s4s6s10s6s4s6s4s6s10s6s4s6s4s6s10s6s4s6s4s6s10s6s4s6s4s6s"
#: Radar A's command and report groups of a Broadband 4G (radar_pi ``NavicoCommon.h``).
COMMAND_ADDRESS = ("236.6.7.10", 6680)
REPORT_ADDRESS = ("236.6.7.9", 6679)
#: The beacon's serial number field (ASCII): says what sends it.
BEACON_SERIAL = b"RAYSIM"


def _packed(address: tuple[str, int]) -> bytes:
    host, port = address
    return bytes(int(v) for v in host.split(".")) + int(port).to_bytes(2, "big")


def beacon(data_address: tuple[str, int] = RADAR_MULTICAST, command_address: tuple[str, int] = COMMAND_ADDRESS,
           report_address: tuple[str, int] = REPORT_ADDRESS) -> bytes:
    """The 01 B2 beacon announcing radar A's spoke, command and report groups (radar B: the same).

    Only the addresses and the id are meaningful here; the unknown bytes are zeros, and the other
    address blocks repeat radar A's (the real set fills them with its other groups).
    """
    import struct

    sizes = [int(n) for n in BEACON_FORMAT[1:].replace("H", "").split("s") if n]
    fields: list = [0x01 | (0xB2 << 8), BEACON_SERIAL.ljust(16, b"\0")]
    addresses = [data_address, command_address, report_address]
    k = 0
    for size in sizes[1:]:
        if size == 6:
            fields.append(_packed(addresses[(k - 5) % 3] if k >= 5 else data_address))
            k += 1
        else:
            fields.append(bytes(size))
    return struct.pack(BEACON_FORMAT, *fields)


def status_report(transmitting: bool = True) -> bytes:
    """The 18-byte 01 C4 status report (radar_pi ``RadarReport_01C4_18``: byte 2 = 0x02 transmit, 0x01 standby)."""
    body = bytearray(18)
    body[0], body[1], body[2] = 0x01, 0xC4, 0x02 if transmitting else 0x01
    return bytes(body)
