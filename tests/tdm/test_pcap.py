"""tdm.pcap: the HDL-32E PCAP gives the same sweeps as the recording's NPZ files.

The NPZ sweeps are what raysim's renderer measured; the PCAP is the same data as the
sensor would have sent it. Decoding the PCAP (without raysim) must give back every point
to within the 2 mm quantisation (in fact exactly: both use the decoder's geometry), with the
same ring, intensity and azimuth, and times within a microsecond (the packet timestamp's
resolution). Damaged files are read as far as they go, with every problem counted.
"""

from __future__ import annotations

import datetime as dt
import itertools
import json
import struct
from pathlib import Path

import numpy as np
import pytest
import yaml

from groundfloor.hdl32e import CYCLE_DT_S, FIRING_DT_S, RING
from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.pcap import iter_pcap_sweeps
from tests.tdm.conftest import render_recording

FIELDS = ("x", "y", "z", "intensity", "ring", "time", "azimuth_deg")
DSR_OF_RING = np.argsort(RING)
TRUNCATED = "lidar/pcap: truncated last record skipped (file cut)"
BAD_RECORD = "lidar/pcap: record with a bad header or length skipped"
WRONG_SIZE = "lidar/pcap: data packet of the wrong size skipped"
OTHER = "lidar/pcap: frames other than UDP 2368/8308 skipped"


def start_unix_s(recording: Path) -> float:
    manifest = json.loads((recording / "manifest.json").read_text())
    return dt.datetime.fromisoformat(manifest["start_time"]).timestamp()


def npz_sweep(recording: Path, index: int) -> dict[str, np.ndarray]:
    with np.load(recording / "lidar" / "sweeps" / f"{index:06d}.npz") as data:
        return {k: data[k] for k in FIELDS}


def firing_keys(sweep: dict[str, np.ndarray]) -> np.ndarray:
    """A key per point (single return): firing cycle (from the time) * 32 + DSR slot (from the ring)."""
    dsr = DSR_OF_RING[sweep["ring"]]
    cycle = np.round((sweep["time"] - dsr * FIRING_DT_S) / CYCLE_DT_S).astype(np.int64)
    return cycle * 32 + dsr


def assert_same_points(a: dict, b: dict, ia=slice(None), ib=slice(None)) -> None:
    for k in ("x", "y", "z"):
        assert np.abs(a[k][ia] - b[k][ib]).max(initial=0.0) <= 0.002, k  # 2 mm quantisation
    for k in ("ring", "intensity", "azimuth_deg"):
        np.testing.assert_array_equal(a[k][ia], b[k][ib], err_msg=k)
    assert np.abs(a["time"][ia] - b["time"][ib]).max(initial=0.0) < 2e-6


def assert_same_sweeps(got: list[dict], want: list[dict]) -> None:
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert g["x"].shape == w["x"].shape
        assert_same_points(g, w)


# ----------------------------------------------------------------------------- raw PCAP helpers (tests only)


def pcap_records(data: bytes) -> list[tuple[int, int]]:
    """(offset, size) of each complete record of a little-endian microsecond PCAP held in memory."""
    out, pos = [], 24
    while pos + 16 <= len(data):
        size = 16 + struct.unpack_from("<I", data, pos + 8)[0]
        if pos + size > len(data):
            break
        out.append((pos, size))
        pos += size
    return out


def udp_port(data: bytes, offset: int) -> int:
    return struct.unpack_from(">H", data, offset + 16 + 36)[0]


def prefix(pcap: Path, n_bytes: int) -> bytes:
    with open(pcap, "rb") as handle:
        return handle.read(n_bytes)


def read_all(path: Path, start: float, **kw) -> tuple[list[dict], ReadStats]:
    stats = ReadStats()
    return list(iter_pcap_sweeps(path, start, stats, **kw)), stats


# ----------------------------------------------------------------------------- the match


def test_pcap_sweeps_match_the_npz_sweeps(bos_recording):
    pcap = bos_recording / "lidar" / "hdl32e.pcap"
    start = start_unix_s(bos_recording)
    n_npz = len(list((bos_recording / "lidar" / "sweeps").glob("*.npz")))
    stats = ReadStats()
    previous_keys = None
    moved = 0
    sweeps = iter_pcap_sweeps(pcap, start, stats, chunk_bytes=3 << 20)  # several chunks, sweeps across them
    got = list(itertools.islice(sweeps, n_npz + 1))
    assert len(got) == n_npz  # the last, incomplete revolution is not yielded (as the renderer does)
    for i, p in enumerate(got):
        n = npz_sweep(bos_recording, i)
        assert set(p) == set(FIELDS)
        assert p["x"].dtype == np.float32 and p["ring"].dtype == np.uint8 and p["time"].dtype == np.float64
        assert p["intensity"].dtype == np.uint8 and p["azimuth_deg"].dtype == np.float32
        kp, kn = firing_keys(p), firing_keys(n)
        common, ip, in_ = np.intersect1d(kp, kn, assume_unique=True, return_indices=True)
        assert_same_points(p, n, ip, in_)
        # a firing cycle whose encoder azimuth rounds to 0.00 deg may start the next revolution
        # in the PCAP while the renderer (which knows the exact time) ended the previous one with it
        only_p, only_n = np.setdiff1d(kp, kn, assume_unique=True), np.setdiff1d(kn, kp, assume_unique=True)
        assert np.unique(only_p // 32).size <= 1 and np.unique(only_n // 32).size <= 1
        if only_p.size:
            assert previous_keys is not None and np.isin(only_p, previous_keys).all()
            assert (p["azimuth_deg"][np.isin(kp, only_p)] < 0.2).all()
            moved += 1
        if only_n.size:
            assert i + 1 < len(got) and np.isin(only_n, firing_keys(got[i + 1])).all()
            assert (n["azimuth_deg"][np.isin(kn, only_n)] < 0.2).all()
        if i in (0, len(got) // 2, len(got) - 1) and not (only_p.size or only_n.size):
            assert_same_points(p, n)  # whole sweeps, point for point, in firing order
        previous_keys = kn
    assert moved < 0.1 * n_npz
    assert stats.warnings == {}  # position packets (UDP 8308) are skipped without a warning


def test_dual_return_and_a_partial_first_revolution_across_the_hour(tmp_path):
    """Dual-return packets (blocks in pairs), a head starting at 200 deg, a start 0.2 s before the hour."""
    scenario = {
        "name": "dual_mini", "start_time": "2017-06-01T12:59:59.8Z", "duration_s": 0.5, "seed": 3,
        "own_ship": {"name": "odin", "length_m": 10.9, "beam_m": 3.5,
                     "position": [59.4377744115633, 10.471651180041], "heading_deg": 0},
        "sensors": {"lidar": {"return_mode": "dual", "azimuth0_deg": 200.0, "sub_rays": 7,
                              "beam_divergence_mrad": 20}},
        "obstacles": [{"name": "Iceberg_1", "kind": "iceberg", "position": [59.43795, 10.47165], "radius_m": 8,
                       "height_m": 6, "seed": 1}],
    }
    path = tmp_path / "dual.yaml"
    path.write_text(yaml.safe_dump(scenario))
    rec = render_recording(path, tmp_path / "rec", 0.5, sensors=["lidar"])
    got, stats = read_all(rec / "lidar" / "hdl32e.pcap", start_unix_s(rec))
    want = [npz_sweep(rec, i) for i in range(len(list((rec / "lidar" / "sweeps").glob("*.npz"))))]
    assert len(want) == 5  # 160 deg of the first turn, then four whole turns
    assert_same_sweeps(got, want)
    with np.load(rec / "lidar" / "sweeps" / "000002.npz") as data:
        assert (data["return_index"] == 1).sum() > 50  # second returns really are in the packets
    assert got[0]["azimuth_deg"][0] == pytest.approx(200.0, abs=0.01)
    assert stats.warnings == {}


# ----------------------------------------------------------------------------- damaged files


def test_a_cut_file_gives_the_sweeps_before_the_cut_and_a_warning(bos_recording, tmp_path):
    pcap = bos_recording / "lidar" / "hdl32e.pcap"
    start = start_unix_s(bos_recording)
    data = prefix(pcap, 4_000_037)
    records = pcap_records(data)
    assert records[-1][0] + records[-1][1] < len(data)  # the cut is inside a record
    cut = tmp_path / "cut.pcap"
    cut.write_bytes(data)
    got, stats = read_all(cut, start)
    assert stats.warnings == {TRUNCATED: 1}
    # every revolution that ended before the last whole packet, and no more
    last_capture = struct.unpack_from("<II", data, records[-1][0])
    t_last = last_capture[0] + 1e-6 * last_capture[1] - start
    full = list(itertools.islice(iter_pcap_sweeps(pcap, start, ReadStats()), len(got) + 1))
    assert full[len(got) - 1]["time"].max() < t_last < full[len(got)]["time"].max()
    assert len(got) >= 15
    assert_same_sweeps(got, full[: len(got)])


@pytest.mark.parametrize("bad_length, expected", [
    (0xFFFF0000, {BAD_RECORD: 1}),  # an impossible length: resynchronise on the next header
    (1000, {BAD_RECORD: 1, WRONG_SIZE: 1}),  # a plausible but wrong one: the frame is short, then resynchronise
])
def test_a_record_with_a_bad_length_is_skipped(bos_recording, tmp_path, bad_length, expected):
    pcap = bos_recording / "lidar" / "hdl32e.pcap"
    start = start_unix_s(bos_recording)
    data = prefix(pcap, 3_000_000)
    records = pcap_records(data)
    clean = data[: records[-1][0] + records[-1][1]]  # ends on a record boundary: nothing truncated
    victim = next(k for k in range(1500, len(records)) if udp_port(clean, records[k][0]) == 2368)
    offset = records[victim][0]
    damaged = bytearray(clean)
    struct.pack_into("<I", damaged, offset + 8, bad_length)
    (tmp_path / "clean.pcap").write_bytes(clean)
    (tmp_path / "damaged.pcap").write_bytes(bytes(damaged))
    want, clean_stats = read_all(tmp_path / "clean.pcap", start)
    got, stats = read_all(tmp_path / "damaged.pcap", start, chunk_bytes=1 << 20)
    assert clean_stats.warnings == {}
    assert stats.warnings == expected
    assert len(got) == len(want) >= 10
    # the damaged packet's 12 firing cycles are missing from one sweep; everything else is there
    differs = [i for i, (g, w) in enumerate(zip(got, want)) if g["x"].shape != w["x"].shape]
    assert len(differs) == 1
    for i, (g, w) in enumerate(zip(got, want)):
        kg, kw = firing_keys(g), firing_keys(w)
        assert np.isin(kg, kw).all()
        missing = np.setdiff1d(kw, kg, assume_unique=True)
        assert np.unique(missing // 32).size <= 12 and (missing.size > 0) == (i in differs)
        _, ig, iw = np.intersect1d(kg, kw, assume_unique=True, return_indices=True)
        assert_same_points(g, w, ig, iw)


def _global_header(order: str = "<", nanoseconds: bool = False, link_type: int = 1) -> bytes:
    return struct.pack(order + "IHHiIII", 0xA1B23C4D if nanoseconds else 0xA1B2C3D4, 2, 4, 0, 0, 65535, link_type)


def _record(order: str, sec: int, frac: int, frame: bytes) -> bytes:
    return struct.pack(order + "IIII", sec, frac, len(frame), len(frame)) + frame


def _records_of(data: bytes, count: int) -> list[tuple[int, int, bytes]]:
    """(sec, usec, frame) of the first ``count`` records."""
    out = []
    for offset, size in pcap_records(data)[:count]:
        sec, usec = struct.unpack_from("<II", data, offset)
        out.append((sec, usec, data[offset + 16: offset + size]))
    return out


def _udp_frame(template: bytes, port: int, payload: bytes) -> bytes:
    """An Ethernet/IPv4/UDP frame like ``template`` (a captured one) with another port and payload."""
    frame = bytearray(template[:42])
    struct.pack_into(">H", frame, 16, 28 + len(payload))
    struct.pack_into(">HHH", frame, 34, port, port, 8 + len(payload))
    return bytes(frame) + payload


def test_odd_frames_are_counted_and_skipped(bos_recording, tmp_path):
    pcap = bos_recording / "lidar" / "hdl32e.pcap"
    start = start_unix_s(bos_recording)
    records = _records_of(prefix(pcap, 2_000_000), 400)  # 0.22 s: two revolutions
    template = records[1][2]
    sec, usec = records[200][:2]
    odd = [
        (sec, usec, _udp_frame(template, 2368, template[42:1042])),  # a data packet of 1000 bytes
        (sec, usec, _udp_frame(template, 53, b"\x00" * 40)),  # DNS, not the sensor
        (sec, usec, b"\xff" * 6 + template[6:12] + b"\x08\x06" + b"\x00" * 28),  # ARP
    ]
    plain = _global_header() + b"".join(_record("<", *r) for r in records)
    mixed = _global_header() + b"".join(_record("<", *r) for r in records[:200] + odd + records[200:])
    (tmp_path / "plain.pcap").write_bytes(plain)
    (tmp_path / "mixed.pcap").write_bytes(mixed)
    want, plain_stats = read_all(tmp_path / "plain.pcap", start)
    got, stats = read_all(tmp_path / "mixed.pcap", start)
    assert plain_stats.warnings == {} and len(want) == 2
    assert stats.warnings == {WRONG_SIZE: 1, OTHER: 2}
    assert_same_sweeps(got, want)


@pytest.mark.parametrize("order, nanoseconds, link", [(">", False, "ethernet"), ("<", True, "ethernet"),
                                                      ("<", False, "linux-cooked"), (">", True, "raw-ip")])
def test_other_pcap_flavours_read_the_same(bos_recording, tmp_path, order, nanoseconds, link):
    """Big-endian files, nanosecond timestamps, Linux cooked and raw-IP link layers."""
    pcap = bos_recording / "lidar" / "hdl32e.pcap"
    start = start_unix_s(bos_recording)
    records = _records_of(prefix(pcap, 2_000_000), 400)
    link_type = {"ethernet": 1, "linux-cooked": 113, "raw-ip": 101}[link]

    def frame(f: bytes) -> bytes:
        if link == "linux-cooked":
            return struct.pack(">HHH8sH", 1, 1, 6, f[6:12] + b"\x00\x00", 0x0800) + f[14:]
        return f[14:] if link == "raw-ip" else f

    body = b"".join(_record(order, s, u * 1000 if nanoseconds else u, frame(f)) for s, u, f in records)
    (tmp_path / "plain.pcap").write_bytes(_global_header() + b"".join(_record("<", *r) for r in records))
    (tmp_path / "flavour.pcap").write_bytes(_global_header(order, nanoseconds, link_type) + body)
    want, _ = read_all(tmp_path / "plain.pcap", start)
    got, stats = read_all(tmp_path / "flavour.pcap", start)
    assert stats.warnings == {}
    assert len(want) == 2
    assert_same_sweeps(got, want)


@pytest.mark.parametrize("content", [
    b"",
    bytes(np.random.default_rng(1).integers(0, 256, 5000, dtype=np.uint8)),
    b"\x0a\x0d\x0d\x0a" + b"\x00" * 60,  # pcapng
    b"\xd4\xc3\xb2\xa1\x02\x00",  # a PCAP magic, but no header after it
])
def test_a_file_that_is_not_a_pcap_is_an_error(tmp_path, content):
    path = tmp_path / "garbage.pcap"
    path.write_bytes(content)
    with pytest.raises(RecordingError) as info:
        list(iter_pcap_sweeps(path, 0.0, ReadStats()))
    assert info.value.where == "byte 0" and "not a pcap file" in info.value.what
    assert str(path) in str(info.value)


def test_a_missing_file_is_an_error(tmp_path):
    with pytest.raises(RecordingError):
        list(iter_pcap_sweeps(tmp_path / "none.pcap", 0.0, ReadStats()))
