"""Velodyne HDL-32E PCAP reader: ``lidar/hdl32e.pcap`` to revolutions ("sweeps").

The file is a classic libpcap capture (any of its four magics: micro- or
nanosecond timestamps, either byte order) of the sensor's UDP broadcast over
Ethernet II (or Linux cooked / raw IPv4) and IPv4. Data packets go to UDP port
2368 and are 1206 bytes long (docs/reference.md section 2): 12 blocks of the flag
``FF EE``, the block's azimuth (uint16, 0.01 deg) and 32 x (distance uint16 in
2 mm units, reflectivity uint8); then the packet's timestamp (uint32,
microseconds since the top of the UTC hour) and two factory bytes (return mode,
product id). Position packets (UDP 8308) are skipped.

Reading is vectorised and streams through the file in chunks, so memory stays
flat however long the recording is. The record headers are walked with a fast
path for the common case (runs of records of one size: one strided numpy check
per run); only records that break a run (a position packet, a damaged record)
are handled one by one.

Each point is reconstructed as the decoders do (valgur/velodyne_decoder
``packet_decoder.cpp``, VeloView; docs/reference.md section 2):

* azimuth of firing ``j`` of a block: the block azimuth plus the packet's rotation
  rate (from its first and last block azimuths) times the firing's time offset,
  rounded to 0.01 deg (velodyne_decoder ``unpack_16_32_beam``, float32 arithmetic);
* ``x = d cos(w) cos(a)``, ``y = -d cos(w) sin(a)``, ``z = d sin(w) + z_offset``
  (``w`` the laser's elevation, ``a`` the azimuth, clockwise seen from above;
  x forward, y left, z up);
* ``t = t_packet + 46.08 us * cycle + 1.152 us * DSR`` with ``t_packet`` the first
  firing of the packet: the capture record's UNIX time selects the hour, the
  packet's microseconds past the hour give the time within it.

Revolutions are split where the block azimuth wraps (drops by more than half a
turn), so a firing cycle whose encoder azimuth reads 0.00 deg starts the new
revolution even when the head was still 0.005 deg short of it (the packet cannot
tell; the renderer's NPZ files, which know the exact time, then differ by that
one cycle at the boundary). The first revolution of a file may be partial (the capture starts
mid-turn) and is yielded; the last one is yielded only if it is complete (its
next firing cycle would wrap), so a cut file never yields a partial last sweep.

Problems are counted in :class:`tdm.detections.ReadStats` under keys starting
with ``"lidar/pcap: "`` and skipped; a file that is not a PCAP at all raises
:class:`tdm.errors.RecordingError`.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from groundfloor.hdl32e import (BLOCK_FLAG, BLOCKS_PER_PACKET, CENTIDEG_PER_TURN, COS_AZIMUTH_STEP, COS_ELEVATION,
                                CYCLE_DT_NS, DATA_PORT, DISTANCE_UNIT_M, ELEVATION_DEG, FIRING_DT_NS,
                                PACKET_BYTES, PACKET_DTYPE, POSITION_PORT, PRODUCT_IDS_ACCEPTED, RETURN_MODE_DUAL, RING,
                                SIN_AZIMUTH_STEP, SIN_ELEVATION, Z_OFFSET_M, firing_azimuths_centideg)
from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.recording.files import regular_file
from tdm.recording.pcap_times import PacketClock

__all__ = ["iter_pcap_sweeps", "check_pcap_header", "decode_packets", "firing_azimuths_centideg", "ELEVATION_DEG",
           "Z_OFFSET_M", "RING"]

# ----------------------------------------------------------------------------- HDL-32E facts
# groundfloor.hdl32e (docs/reference.md section 2), the same facts raysim's writer uses; the
# decoders' cos/sin tables of the 36000 encoder steps and of the 32 elevations.
_COS_AZ, _SIN_AZ = COS_AZIMUTH_STEP, SIN_AZIMUTH_STEP
_COS_EL, _SIN_EL = COS_ELEVATION, SIN_ELEVATION

# ----------------------------------------------------------------------------- PCAP facts
# libpcap file format (tcpdump.org "pcap-savefile(5)", IETF draft-ietf-opsawg-pcap).
_MAGICS = {  # first four bytes -> (byte order, nanoseconds per fraction unit)
    b"\xd4\xc3\xb2\xa1": ("<", 1000), b"\xa1\xb2\xc3\xd4": (">", 1000),  # microsecond timestamps
    b"\x4d\x3c\xb2\xa1": ("<", 1), b"\xa1\xb2\x3c\x4d": (">", 1),  # nanosecond timestamps
}
_PCAPNG_MAGIC = b"\x0a\x0d\x0d\x0a"
GLOBAL_HEADER_BYTES = 24
RECORD_HEADER_BYTES = 16
MAX_RECORD_BYTES = 262144  # libpcap's MAXIMUM_SNAPLEN: a longer record length is a damaged header
#: link-layer header length by link type: 1 Ethernet II, 113 Linux cooked (SLL), 101/228 raw IPv4
_LINK_HEADER_BYTES = {1: 14, 113: 16, 101: 0, 228: 0}
_ETHERTYPE_IPV4 = 0x0800
_ETHERTYPE_VLAN = 0x8100
_IP_PROTO_UDP = 17
_NS_PER_HOUR = 3_600_000_000_000
#: A packet timestamp further than this from its capture time means the sensor clock is not
#: synchronised (no GPS/PPS): the capture time is used instead (counted).
MAX_CLOCK_OFFSET_NS = 10_000_000_000

DEFAULT_CHUNK_BYTES = 4 << 20  # read 4 MiB at a time (about 3 400 data packets, 1.9 s at 1808 packets/s)


@dataclass(frozen=True)
class _Format:
    order: str  # "<" or ">"
    frac_ns: int  # nanoseconds per unit of the record's fractional timestamp
    link_type: int


def _read_global_header(path: Path, head: bytes) -> _Format:
    """Check the 24-byte global header; RecordingError if the file is not a classic PCAP."""
    magic = head[:4]
    if magic == _PCAPNG_MAGIC:
        raise RecordingError(str(path), "byte 0", "not a pcap file: pcapng is not supported (convert it with "
                                                  "'editcap -F pcap')")
    if magic not in _MAGICS:
        raise RecordingError(str(path), "byte 0", f"not a pcap file (magic {magic.hex() or 'missing'}, expected "
                                                  "a1b2c3d4 or a1b23c4d in either byte order)")
    if len(head) < GLOBAL_HEADER_BYTES:
        raise RecordingError(str(path), "byte 0", f"not a pcap file: {len(head)} bytes, shorter than the "
                                                  f"{GLOBAL_HEADER_BYTES}-byte header")
    order, frac_ns = _MAGICS[magic]
    link_type = struct.unpack(order + "I", head[20:24])[0] & 0x0FFFFFFF  # upper bits: FCS information
    if link_type not in _LINK_HEADER_BYTES:
        raise RecordingError(str(path), "byte 20", f"link type {link_type} not supported (expected 1 Ethernet, "
                                                   "113 Linux cooked or 101/228 raw IPv4)")
    return _Format(order, frac_ns, link_type)


def check_pcap_header(path: Path) -> None:
    """RecordingError unless ``path`` is a readable classic PCAP of a supported link type (its 24-byte header)."""
    regular_file(path)
    with open(path, "rb") as handle:
        _read_global_header(Path(path), handle.read(GLOBAL_HEADER_BYTES))


# ----------------------------------------------------------------------------- record walking


def _u32(buf: np.ndarray, offsets: np.ndarray, order: str) -> np.ndarray:
    """uint32 fields at byte ``offsets`` (int64 array) of ``buf``, as int64."""
    b = buf[offsets[:, None] + np.arange(4)].astype(np.int64)
    if order == "<":
        return b[:, 0] | b[:, 1] << 8 | b[:, 2] << 16 | b[:, 3] << 24
    return b[:, 3] | b[:, 2] << 8 | b[:, 1] << 16 | b[:, 0] << 24


def _plausible_headers(buf: np.ndarray, q: np.ndarray, fmt: _Format, last_sec: int | None) -> np.ndarray:
    """Which byte offsets ``q`` (int64, each with 16 bytes after it) look like record headers."""
    sec, frac = _u32(buf, q, fmt.order), _u32(buf, q + 4, fmt.order)
    incl, orig = _u32(buf, q + 8, fmt.order), _u32(buf, q + 12, fmt.order)
    ok = (frac < 1_000_000_000 // fmt.frac_ns) & (incl <= orig) & (orig <= MAX_RECORD_BYTES) & (incl > 0)
    if last_sec is not None:
        ok &= np.abs(sec - last_sec) <= 86400
    return ok


def _resync(buf: np.ndarray, start: int, fmt: _Format, last_sec: int | None, final: bool) -> int | None:
    """First offset >= ``start`` where a chain of two plausible record headers begins.

    A chain of two (or one that ends the file exactly) keeps a payload that happens to look
    like a header from being taken for one. Searched in windows of 64 KiB (bounded memory).
    Returns None when the buffer holds none.
    """
    end = buf.shape[0]
    last = end - RECORD_HEADER_BYTES  # last offset with a whole header after it
    window = 1 << 16
    for first in range(start, last + 1, window):
        q = np.arange(first, min(first + window, last + 1), dtype=np.int64)
        q = q[_plausible_headers(buf, q, fmt, last_sec)]
        if q.size == 0:
            continue
        nxt = q + RECORD_HEADER_BYTES + _u32(buf, q + 8, fmt.order)
        good = final & (nxt == end)
        inside = np.flatnonzero(nxt <= last)
        good[inside] |= _plausible_headers(buf, nxt[inside], fmt, last_sec)
        hits = np.flatnonzero(good)
        if hits.size:
            return int(q[hits[0]])
    return None


def _walk_records(buf: np.ndarray, fmt: _Format, stats: ReadStats, final: bool,
                  state: dict) -> tuple[list[tuple[int, int, int]], int]:
    """Split a buffer that starts at a record boundary into runs of equal-sized records.

    Parameters
    ----------
    buf : (B,) uint8
        Bytes of the file from a record boundary on.
    fmt : _Format
    stats : ReadStats
    final : bool
        ``buf`` reaches the end of the file.
    state : dict
        ``last_sec``: the UNIX second of the last good record (for resynchronisation).

    Returns
    -------
    runs : list of (offset, count, record length)
        ``count`` consecutive records of ``16 + length`` bytes each, starting at ``offset``.
    consumed : int
        Bytes of ``buf`` fully handled; the rest (an incomplete record) waits for more data.
    """
    end = buf.shape[0]
    runs: list[tuple[int, int, int]] = []
    pos = 0
    probe = 16  # records checked at once; grows while runs are long (the fast path)
    while end - pos >= RECORD_HEADER_BYTES:
        head = np.array([pos], dtype=np.int64)
        if not _plausible_headers(buf, head, fmt, state.get("last_sec"))[0]:
            if not state.get("resyncing"):  # one count per damaged stretch, however long
                stats.count("lidar/pcap: record with a bad header or length skipped")
                state["resyncing"] = True
            nxt = _resync(buf, pos + 1, fmt, state.get("last_sec"), final)
            if nxt is None:
                if final:
                    return runs, end
                # keep the tail (a header may straddle the chunk boundary) and wait for more data
                return runs, max(pos + 1, end - MAX_RECORD_BYTES - 2 * RECORD_HEADER_BYTES)
            pos = nxt
            continue
        state["resyncing"] = False
        length = int(_u32(buf, head + 8, fmt.order)[0])
        size = RECORD_HEADER_BYTES + length
        if pos + size > end:
            break
        k_max = min((end - pos) // size, probe)
        count = 1
        if k_max > 1:
            lengths = _u32(buf, pos + 8 + size * np.arange(1, k_max, dtype=np.int64), fmt.order)
            mismatch = np.flatnonzero(lengths != length)
            count = 1 + (int(mismatch[0]) if mismatch.size else k_max - 1)
        runs.append((pos, count, length))
        last_sec = int(_u32(buf, np.array([pos + size * (count - 1)], dtype=np.int64), fmt.order)[0])
        if last_sec > 0:  # a record time of 0 (a clock never set) must not make every later record look damaged
            state["last_sec"] = last_sec
        pos += count * size
        probe = min(probe * 4, 1 << 16) if count == k_max else 16
    if final and pos < end:
        stats.count("lidar/pcap: truncated last record skipped (file cut)")
        return runs, end
    return runs, pos


# ----------------------------------------------------------------------------- frames to payloads


def _udp_payloads(records: np.ndarray, fmt: _Format, stats: ReadStats) -> tuple[np.ndarray, np.ndarray]:
    """Velodyne data payloads of equal-sized records.

    Parameters
    ----------
    records : (N, 16 + L) uint8
        Record headers and captured frames.

    Returns
    -------
    capture_ns : (M,) int64
        UNIX capture time of each data packet, ns.
    payloads : (M, 1206) uint8
    """
    n, size = records.shape
    empty = (np.zeros(0, dtype=np.int64), np.zeros((0, PACKET_BYTES), dtype=np.uint8))
    link = _LINK_HEADER_BYTES[fmt.link_type]
    if size < RECORD_HEADER_BYTES + link + 28:
        stats.count("lidar/pcap: frames other than UDP 2368/8308 skipped", n)
        return empty
    hdr = records[:, :RECORD_HEADER_BYTES].copy().view(fmt.order + "u4")
    capture_ns = hdr[:, 0].astype(np.int64) * 1_000_000_000 + hdr[:, 1].astype(np.int64) * fmt.frac_ns
    frame = records[:, RECORD_HEADER_BYTES:]
    ip = np.full(n, link, dtype=np.int64)
    ipv4 = np.ones(n, dtype=bool)
    if fmt.link_type == 1:  # Ethernet II, optionally one 802.1Q VLAN tag
        ethertype = frame[:, 12].astype(np.int64) << 8 | frame[:, 13]
        vlan = ethertype == _ETHERTYPE_VLAN
        if vlan.any():
            ip[vlan] += 4
            ethertype[vlan] = frame[vlan, 16].astype(np.int64) << 8 | frame[vlan, 17]
        ipv4 = ethertype == _ETHERTYPE_IPV4
    elif fmt.link_type == 113:  # Linux cooked: protocol at 14
        ipv4 = (frame[:, 14].astype(np.int64) << 8 | frame[:, 15]) == _ETHERTYPE_IPV4
    rows = np.arange(n)
    max_ip = frame.shape[1] - 28
    ip = np.minimum(ip, max_ip)
    version_ihl = frame[rows, ip]
    ihl = (version_ihl & 0x0F).astype(np.int64) * 4
    udp = ip + ihl
    ok = ipv4 & (version_ihl >> 4 == 4) & (ihl >= 20) & (frame[rows, ip + 9] == _IP_PROTO_UDP)
    ok &= udp + 8 <= frame.shape[1]
    udp = np.where(ok, udp, 0)
    dst_port = frame[rows, udp + 2].astype(np.int64) << 8 | frame[rows, udp + 3]
    udp_len = frame[rows, udp + 4].astype(np.int64) << 8 | frame[rows, udp + 5]
    data = ok & (dst_port == DATA_PORT)
    other = ~ok | ((dst_port != DATA_PORT) & (dst_port != POSITION_PORT))
    if other.any():
        stats.count("lidar/pcap: frames other than UDP 2368/8308 skipped", int(other.sum()))
    payload_at = udp + 8
    right_size = data & (udp_len - 8 == PACKET_BYTES) & (payload_at + PACKET_BYTES <= frame.shape[1])
    if (data & ~right_size).any():
        stats.count("lidar/pcap: data packet of the wrong size skipped", int((data & ~right_size).sum()))
    keep = np.flatnonzero(right_size)
    if keep.size == 0:
        return empty
    starts = payload_at[keep]
    if np.all(starts == starts[0]):  # the common case: one layout for the whole run
        payloads = frame[keep, starts[0]: starts[0] + PACKET_BYTES]
    else:
        payloads = frame[keep[:, None], starts[:, None] + np.arange(PACKET_BYTES)]
    return capture_ns[keep], np.ascontiguousarray(payloads)


# ----------------------------------------------------------------------------- packets to points


def decode_packets(payloads: np.ndarray, capture_ns: np.ndarray, start_ns: int,
                   stats: ReadStats, clock: PacketClock | None = None) -> dict[str, np.ndarray] | None:
    """Points and firing cycles of consecutive HDL-32E data packets.

    Parameters
    ----------
    payloads : (P, 1206) uint8
        UDP payloads of data packets, in capture order.
    capture_ns : (P,) int64
        UNIX capture time of each packet, ns (selects the hour of the packet timestamp).
    start_ns : int
        UNIX time of the recording's start, ns.
    stats : ReadStats
    clock : PacketClock, optional
        Skips (and counts) packets whose time is outside the run or going back
        (:mod:`tdm.recording.pcap_times`).

    Returns
    -------
    dict or None (no valid packet)
        ``cycle_az`` (C,) int64 azimuth of each firing cycle, 0.01 deg; ``point_cycle`` (N,) int64 the
        cycle of each point (non-decreasing); and the sweep fields of each point: ``x, y, z`` (N,) float32
        metres (sensor frame), ``intensity`` (N,) uint8, ``ring`` (N,) uint8, ``time`` (N,) float64 s
        since the start, ``azimuth_deg`` (N,) float32. Cycles are numbered in firing order over the valid
        packets (12 per single-return packet, 6 per dual-return one). ``cycle_step_centideg`` (float):
        the azimuth advance per firing cycle in the last packet, 0.01 deg.
    """
    packets, capture_ns = _valid_packets(payloads, capture_ns, stats)
    if packets.shape[0] == 0:
        return None
    blocks, dual = packets["blocks"], packets["return_mode"] == RETURN_MODE_DUAL
    rel_ns = _first_firing_ns(packets["timestamp"].astype(np.int64), capture_ns, dual, stats) - int(start_ns)
    if clock is not None:
        timely = clock.keep(rel_ns, stats)
        if not timely.all():
            blocks, dual, rel_ns = blocks[timely], dual[timely], rel_ns[timely]
            if blocks.shape[0] == 0:
                return None
    return _points(blocks, dual, rel_ns)


def _valid_packets(payloads: np.ndarray, capture_ns: np.ndarray, stats: ReadStats) -> tuple[np.ndarray, np.ndarray]:
    """The packets (P',) of :data:`PACKET_DTYPE` with good block flags, an HDL-32E product id and a
    timestamp within the hour, and their capture times (P',) int64 ns; the others counted."""
    packets = payloads.view(PACKET_DTYPE).reshape(-1)
    valid = np.all(packets["blocks"]["flag"] == BLOCK_FLAG, axis=1)
    if (~valid).any():
        stats.count("lidar/pcap: data packet with a bad block flag skipped", int((~valid).sum()))
    model_ok = np.isin(packets["product_id"], PRODUCT_IDS_ACCEPTED)
    other_model = valid & ~model_ok
    if other_model.any():
        stats.count("lidar/pcap: data packet of another Velodyne model skipped (product id)", int(other_model.sum()))
    stamp_ok = packets["timestamp"].astype(np.int64) < 3_600_000_000
    bad_stamp = valid & model_ok & ~stamp_ok
    if bad_stamp.any():
        stats.count("lidar/pcap: data packet with a timestamp past the hour skipped", int(bad_stamp.sum()))
    keep = valid & model_ok & stamp_ok
    return packets[keep], np.asarray(capture_ns, dtype=np.int64)[keep]


def _first_firing_ns(stamp_us: np.ndarray, capture_ns: np.ndarray, dual: np.ndarray, stats: ReadStats) -> np.ndarray:
    """UNIX time (P,) int64 ns of each packet's first firing: its microseconds past the hour, the hour
    from the capture time; the capture time itself where the two disagree by more than 10 s (counted)."""
    first_ns = (capture_ns // _NS_PER_HOUR) * _NS_PER_HOUR + stamp_us * 1000
    first_ns -= np.where(first_ns - capture_ns > _NS_PER_HOUR // 2, _NS_PER_HOUR, 0)
    first_ns += np.where(capture_ns - first_ns > _NS_PER_HOUR // 2, _NS_PER_HOUR, 0)
    unsynced = np.abs(first_ns - capture_ns) > MAX_CLOCK_OFFSET_NS
    if unsynced.any():
        stats.count("lidar/pcap: packet clock off the capture time by > 10 s (capture time used)", int(unsynced.sum()))
        cycles = np.where(dual, BLOCKS_PER_PACKET // 2, BLOCKS_PER_PACKET)
        first_ns = np.where(unsynced, capture_ns - cycles * CYCLE_DT_NS, first_ns)
    return first_ns


def _points(blocks: np.ndarray, dual: np.ndarray, rel_ns: np.ndarray) -> dict[str, np.ndarray]:
    """The firing cycles and points of packets' blocks (P, 12), as :func:`decode_packets` returns them."""
    p = blocks.shape[0]
    # firing cycles: one per block (single return) or per pair of blocks (dual)
    block_az = blocks["azimuth"]
    firing_az = firing_azimuths_centideg(block_az, dual)
    cycle_in_packet = np.where(dual[:, None], np.arange(BLOCKS_PER_PACKET) // 2, np.arange(BLOCKS_PER_PACKET))
    cycles_per_packet = np.where(dual, BLOCKS_PER_PACKET // 2, BLOCKS_PER_PACKET)
    first_cycle = np.concatenate([[0], np.cumsum(cycles_per_packet)[:-1]])
    block_cycle = first_cycle[:, None] + cycle_in_packet  # (P, 12) global cycle index of each block
    first_block_of_cycle = np.ones((p, BLOCKS_PER_PACKET), dtype=bool)
    first_block_of_cycle[dual, 1::2] = False
    cycle_az = block_az[first_block_of_cycle].astype(np.int64)  # (C,) in cycle order

    distance = blocks["returns"]["distance"]  # (P, 12, 32)
    keep_point = distance > 0
    if dual.any():  # the same echo in both blocks of a pair is one point (as decoders report it)
        same = np.zeros_like(keep_point)
        same[:, 1::2] = distance[:, 1::2] == distance[:, 0::2]
        keep_point &= ~(same & dual[:, None, None])
    pp, bb, jj = np.nonzero(keep_point)
    d_m = distance[pp, bb, jj].astype(np.float64) * DISTANCE_UNIT_M
    az = firing_az[pp, bb, jj]
    xy = d_m * _COS_EL[jj]
    t_ns = rel_ns[pp] + CYCLE_DT_NS * cycle_in_packet[pp, bb] + FIRING_DT_NS * jj
    return {
        "cycle_az": cycle_az,
        "point_cycle": block_cycle[pp, bb],
        "x": (xy * _COS_AZ[az]).astype(np.float32),
        "y": (-xy * _SIN_AZ[az]).astype(np.float32),
        "z": (d_m * _SIN_EL[jj] + Z_OFFSET_M[jj]).astype(np.float32),
        "intensity": blocks["returns"]["reflectivity"][pp, bb, jj].astype(np.uint8),
        "ring": RING[jj],
        "time": t_ns.astype(np.float64) * 1e-9,
        "azimuth_deg": (az.astype(np.float64) * 0.01).astype(np.float32),
        "cycle_step_centideg": float(np.mod(block_az[-1, -1].astype(np.int64) - block_az[-1, 0], CENTIDEG_PER_TURN)
                                     / (cycles_per_packet[-1] - 1)),
    }


SWEEP_FIELDS = ("x", "y", "z", "intensity", "ring", "time", "azimuth_deg")


def _concat(pieces: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    return {k: np.concatenate([piece[k] for piece in pieces]) for k in SWEEP_FIELDS}


# ----------------------------------------------------------------------------- the reader


def iter_pcap_sweeps(path: Path, start_time_unix_s: float, stats: ReadStats,
                     chunk_bytes: int = DEFAULT_CHUNK_BYTES,
                     window_s: tuple[float, float] | None = None) -> Iterator[dict[str, np.ndarray]]:
    """Revolutions of an HDL-32E PCAP file, in time order.

    Parameters
    ----------
    path : Path
        ``lidar/hdl32e.pcap`` (classic libpcap; Ethernet, Linux cooked or raw IPv4 link).
    start_time_unix_s : float
        UNIX time of the recording's start (manifest.json ``start_time``), s; point times are
        relative to it.
    stats : ReadStats
        Receives a count for every problem met (keys ``"lidar/pcap: ..."``): a truncated last
        record, a record with a bad header or length (the reader resynchronises on the next
        plausible pair of headers), a data packet of the wrong size, a bad block flag, another
        model's product id, frames other than UDP 2368/8308.
    chunk_bytes : int
        Bytes read at a time. Peak memory is about 25 times this (about 100 MB at the default,
        measured on a 60 s recording), whatever the file's length.
    window_s : (float, float), optional
        Times a packet of this run may have, s since the start: packets outside it or going back
        in time are counted and skipped (:class:`~tdm.recording.pcap_times.PacketClock`).

    Yields
    ------
    dict
        One revolution with the NPZ sweep contract's fields (no ``object_id``: a PCAP holds no
        truth): ``x, y, z`` (N,) float32 sensor frame, metres; ``intensity`` (N,) uint8;
        ``ring`` (N,) uint8; ``time`` (N,) float64 s since the recording's start;
        ``azimuth_deg`` (N,) float32. Points are in firing order; zero-distance slots (no return)
        are dropped. Revolutions split where the block azimuth wraps; the first may be partial,
        the last is yielded only if complete (module docstring).

    Raises
    ------
    RecordingError
        The file is missing or not a readable regular file, is not a classic PCAP (bad magic,
        short header), or has an unsupported link type.
    """
    path = Path(path)
    start_ns = int(round(float(start_time_unix_s) * 1e6)) * 1000
    clock = PacketClock(window_s) if window_s is not None else None
    pending: list[dict[str, np.ndarray]] = []  # pieces of the revolution in progress
    last_az: int | None = None  # azimuth of the last firing cycle seen
    step = 0.0  # azimuth step per cycle of the last packet, 0.01 deg
    for captures, payloads in _packet_chunks(path, stats, chunk_bytes):
        decoded = decode_packets(payloads, captures, start_ns, stats, clock)
        if decoded is None:
            continue
        step = decoded["cycle_step_centideg"]
        az = decoded["cycle_az"]
        previous = np.concatenate([[az[0] if last_az is None else last_az], az[:-1]])
        wraps = np.flatnonzero(az - previous < -CENTIDEG_PER_TURN // 2)  # first cycles of new revolutions
        last_az = int(az[-1])
        cuts = np.searchsorted(decoded["point_cycle"], wraps)
        bounds = np.concatenate([[0], cuts, [decoded["point_cycle"].shape[0]]])
        for i in range(bounds.shape[0] - 1):
            if i > 0:  # a wrap closes the revolution in progress
                if pending:
                    yield _concat(pending)
                pending = []
            pending.append({k: decoded[k][bounds[i]: bounds[i + 1]] for k in SWEEP_FIELDS})
    if pending and last_az is not None and last_az + step >= CENTIDEG_PER_TURN:
        yield _concat(pending)


def _packet_chunks(path: Path, stats: ReadStats, chunk_bytes: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """The file's HDL-32E data packets, ``chunk_bytes`` of file at a time.

    Yields
    ------
    captures : (P,) int64
        UNIX capture time of each packet, ns.
    payloads : (P, 1206) uint8
        Their UDP payloads.
    """
    regular_file(path)
    with open(path, "rb") as handle:
        fmt = _read_global_header(path, handle.read(GLOBAL_HEADER_BYTES))
        carry = np.zeros(0, dtype=np.uint8)
        state: dict = {}
        final = False
        while not final:
            data = handle.read(chunk_bytes)
            final = len(data) < chunk_bytes
            buf = np.concatenate([carry, np.frombuffer(data, dtype=np.uint8)]) if carry.size else \
                np.frombuffer(data, dtype=np.uint8)
            runs, consumed = _walk_records(buf, fmt, stats, final, state)
            carry = buf[consumed:].copy() if not final else buf[:0]
            captures, payloads = [], []
            for offset, count, length in runs:
                records = buf[offset: offset + count * (RECORD_HEADER_BYTES + length)].reshape(count, -1)
                c, pl = _udp_payloads(records, fmt, stats)
                if c.size:
                    captures.append(c)
                    payloads.append(pl)
            if payloads:
                yield np.concatenate(captures), np.concatenate(payloads)
