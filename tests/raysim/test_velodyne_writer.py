"""The PCAP writer's one-buffer path and the HDL-32E beam table lookup against the reference code, bit for bit."""

from __future__ import annotations

import io

import numpy as np

from groundfloor import hdl32e
from raysim.recording import velodyne


def reference_pcap(chunks) -> bytes:
    """The writer as it was: UDP frames built, then copied into records, then copied to bytes."""
    out = io.BytesIO()
    out.write(velodyne.PcapWriter.HEADER)
    ip_id = 0
    for payloads, port, times in chunks:
        frames = velodyne.udp_frames(payloads, port, ip_id)
        n, length = frames.shape
        if n:
            usec = np.round(np.asarray(times, dtype=np.float64) * 1e6).astype(np.int64)
            records = np.empty((n, 16 + length), dtype=np.uint8)
            header = np.empty((n, 4), dtype="<u4")
            header[:, 0], header[:, 1], header[:, 2], header[:, 3] = usec // 1_000_000, usec % 1_000_000, length, length
            records[:, :16] = header.view(np.uint8).reshape(n, 16)
            records[:, 16:] = frames
            out.write(records.tobytes())
        ip_id = (ip_id + n) & 0xFFFF
    return out.getvalue()


def test_pcap_is_the_reference_bytes():
    rng = np.random.default_rng(8)
    chunks = []
    for i, n in enumerate([181, 0, 1, 40000, 3]):  # 40000: the IPv4 identification wraps
        size = hdl32e.POSITION_PACKET_BYTES if i == 2 else hdl32e.PACKET_BYTES
        port = hdl32e.POSITION_PORT if i == 2 else hdl32e.DATA_PORT
        chunks.append((rng.integers(0, 256, (n, size), dtype=np.uint8), port, 1.7e9 + i + rng.random(n)))
    handle = io.BytesIO()
    writer = velodyne.PcapWriter(handle)
    for payloads, port, times in chunks:
        writer.write_udp(payloads, port, times)
    assert handle.getvalue() == reference_pcap(chunks)
    assert writer.frames == sum(c[0].shape[0] for c in chunks)


def test_beam_directions_are_the_table_lookups():
    az = np.random.default_rng(10).integers(0, 36000, (500, 32)).astype(np.uint16)
    d = hdl32e.beam_directions(az)
    assert d[..., 0].tobytes() == (hdl32e.COS_ELEVATION * hdl32e.COS_AZIMUTH_STEP[az]).tobytes()
    assert d[..., 1].tobytes() == (-hdl32e.COS_ELEVATION * hdl32e.SIN_AZIMUTH_STEP[az]).tobytes()
    assert np.array_equal(d[..., 2], np.broadcast_to(hdl32e.SIN_ELEVATION, az.shape))
