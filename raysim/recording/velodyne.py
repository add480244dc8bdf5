"""Velodyne HDL-32E packets and their PCAP file (docs/reference.md section 2).

Data packets (UDP 2368, 1206 bytes, little-endian): 12 blocks of ``FF EE``,
azimuth (0.01 deg), 32 x (distance in 2 mm, reflectivity); then the timestamp
(microseconds since the top of the UTC hour), the return-mode byte and the
product id 0x21. Position packets (UDP 8308, 512 bytes): timestamp at offset
198 and an NMEA $GPRMC sentence at offset 206. The PCAP holds Ethernet II /
IPv4 / UDP frames (1248 bytes for data packets), as a capture of the sensor's
broadcast would.
"""

from __future__ import annotations

import struct
from typing import BinaryIO

import numpy as np

from groundfloor.hdl32e import (BLOCK_DTYPE, BLOCK_FLAG, DATA_PORT, PACKET_BYTES, PACKET_DTYPE,  # noqa: F401
                                POSITION_PACKET_BYTES, POSITION_PORT, PRODUCT_ID)

SENSOR_IP = bytes([192, 168, 1, 201])  # the HDL-32E's factory address
BROADCAST_IP = bytes([255, 255, 255, 255])
SENSOR_MAC = bytes([0x60, 0x76, 0x88, 0x00, 0x00, 0x01])  # Velodyne's OUI 60:76:88
BROADCAST_MAC = b"\xff" * 6


def encode_data_packets(azimuth_centideg: np.ndarray, distance_units: np.ndarray, reflectivity: np.ndarray,
                        timestamp_us: np.ndarray, return_mode: int) -> np.ndarray:
    """Data packets as a structured array.

    Parameters
    ----------
    azimuth_centideg : (P, 12) uint16
        Block azimuths.
    distance_units : (P, 12, 32) uint16
        Distances in 2 mm units, 0 = no return.
    reflectivity : (P, 12, 32) uint8
    timestamp_us : (P,) uint32
        Microseconds since the top of the hour of each packet's first firing.
    return_mode : int
        0x37 strongest, 0x38 last, 0x39 dual.

    Returns
    -------
    (P,) PACKET_DTYPE
        ``.tobytes()`` is the concatenation of the 1206-byte UDP payloads.
    """
    n = azimuth_centideg.shape[0]
    packets = np.zeros(n, dtype=PACKET_DTYPE)
    packets["blocks"]["flag"] = BLOCK_FLAG
    packets["blocks"]["azimuth"] = azimuth_centideg
    packets["blocks"]["returns"]["distance"] = distance_units
    packets["blocks"]["returns"]["reflectivity"] = reflectivity
    packets["timestamp"] = timestamp_us
    packets["return_mode"] = return_mode
    packets["product_id"] = PRODUCT_ID
    return packets


def encode_position_packet(timestamp_us: int, gprmc: str) -> bytes:
    """One 512-byte position packet: timestamp at 198, the $GPRMC sentence at 206."""
    out = bytearray(POSITION_PACKET_BYTES)
    struct.pack_into("<I", out, 198, int(timestamp_us) & 0xFFFFFFFF)
    text = gprmc.encode("ascii")[: POSITION_PACKET_BYTES - 206 - 1]
    out[206 : 206 + len(text)] = text
    return bytes(out)


def _ip_checksum(header: np.ndarray) -> np.ndarray:
    """Internet checksums of (N, 20) uint8 IPv4 headers (checksum field zero)."""
    words = header.reshape(header.shape[0], 10, 2).astype(np.uint32)
    total = (words[:, :, 0] << 8 | words[:, :, 1]).sum(axis=1)
    total = (total & 0xFFFF) + (total >> 16)
    total = (total & 0xFFFF) + (total >> 16)
    return (~total & 0xFFFF).astype(np.uint16)


def _fill_udp_headers(frames: np.ndarray, length: int, port: int, ip_id_start: int) -> None:
    """The 42 bytes of Ethernet II, IPv4 and UDP header in ``frames[:, :42]`` ((N, >= 42) uint8, written in place)."""
    n = frames.shape[0]
    frames[:, 0:6] = np.frombuffer(BROADCAST_MAC, np.uint8)
    frames[:, 6:12] = np.frombuffer(SENSOR_MAC, np.uint8)
    frames[:, 12:14] = (0x08, 0x00)
    ip = np.zeros((n, 20), dtype=np.uint8)
    ip[:, 0] = 0x45
    total = 20 + 8 + length
    ip[:, 2:4] = (total >> 8, total & 0xFF)
    ident = (ip_id_start + np.arange(n)) & 0xFFFF
    ip[:, 4] = ident >> 8
    ip[:, 5] = ident & 0xFF
    ip[:, 6] = 0x40  # don't fragment
    ip[:, 8] = 64  # TTL
    ip[:, 9] = 17  # UDP
    ip[:, 12:16] = np.frombuffer(SENSOR_IP, np.uint8)
    ip[:, 16:20] = np.frombuffer(BROADCAST_IP, np.uint8)
    checksum = _ip_checksum(ip)
    ip[:, 10] = checksum >> 8
    ip[:, 11] = checksum & 0xFF
    frames[:, 14:34] = ip
    frames[:, 34:36] = (port >> 8, port & 0xFF)
    frames[:, 36:38] = (port >> 8, port & 0xFF)
    udp_length = 8 + length
    frames[:, 38:40] = (udp_length >> 8, udp_length & 0xFF)
    frames[:, 40:42] = 0  # UDP checksum optional over IPv4


def udp_frames(payloads: np.ndarray, port: int, ip_id_start: int) -> np.ndarray:
    """Ethernet II / IPv4 / UDP frames around equal-sized payloads.

    Parameters
    ----------
    payloads : (N, L) uint8
    port : int
        Source and destination UDP port.
    ip_id_start : int
        IPv4 identification of the first frame (then counting up, modulo 2^16).

    Returns
    -------
    (N, 42 + L) uint8
    """
    n, length = payloads.shape
    frames = np.empty((n, 42 + length), dtype=np.uint8)
    _fill_udp_headers(frames, length, port, ip_id_start)
    frames[:, 42:] = payloads
    return frames


def _fill_record_headers(records: np.ndarray, length: int, unix_time_s: np.ndarray) -> None:
    """The 16-byte PCAP record headers in ``records[:, :16]`` ((N, >= 16) uint8): seconds, microseconds, lengths."""
    n = records.shape[0]
    usec_total = np.round(np.asarray(unix_time_s, dtype=np.float64) * 1e6).astype(np.int64)
    header = np.empty((n, 4), dtype="<u4")
    header[:, 0] = usec_total // 1_000_000
    header[:, 1] = usec_total % 1_000_000
    header[:, 2] = length
    header[:, 3] = length
    records[:, :16] = header.view(np.uint8).reshape(n, 16)


class PcapWriter:
    """Streams frames into a classic PCAP file (microsecond timestamps, Ethernet link type)."""

    HEADER = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)

    def __init__(self, handle: BinaryIO, header: bool = True, frames_before: int = 0):
        """``header`` False and ``frames_before`` > 0: the records that follow ``frames_before`` others (a
        file's later part, appended to it: the IP identification field continues their count)."""
        self.handle = handle
        if header:
            self.handle.write(self.HEADER)
        self.frames = 0
        self._ip_id = frames_before & 0xFFFF

    def write(self, frames: np.ndarray, unix_time_s: np.ndarray) -> None:
        """Append (N, L) uint8 frames captured at the (N,) float64 UNIX times given."""
        n, length = frames.shape
        if n == 0:
            return
        records = np.empty((n, 16 + length), dtype=np.uint8)
        _fill_record_headers(records, length, unix_time_s)
        records[:, 16:] = frames
        self.handle.write(records.data)  # the buffer itself, no bytes copy
        self.frames += n

    def write_udp(self, payloads: np.ndarray, port: int, unix_time_s: np.ndarray) -> None:
        """Wrap (N, L) payloads in UDP frames and append them (one buffer: record headers, frame headers, payloads)."""
        n, length = payloads.shape
        if n:
            records = np.empty((n, 16 + 42 + length), dtype=np.uint8)
            _fill_record_headers(records, 42 + length, unix_time_s)
            _fill_udp_headers(records[:, 16:], length, port, self._ip_id)
            records[:, 16 + 42:] = payloads
            self.handle.write(records.data)
            self.frames += n
        self._ip_id = (self._ip_id + n) & 0xFFFF


__all__ = ["PACKET_DTYPE", "encode_data_packets", "encode_position_packet", "udp_frames", "PcapWriter",
           "DATA_PORT", "POSITION_PORT"]
