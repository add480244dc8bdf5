"""Navico Broadband 3G/4G frames and the radar's beacon, read back with the layouts of radar_pi."""

from __future__ import annotations

import struct

import numpy as np

from raysim.live.navico import BEACON_FORMAT, beacon, range_fields, spoke_frames, status_report


def address(packed: bytes) -> str:
    return ".".join(str(b) for b in packed[:4]) + f":{int.from_bytes(packed[4:6], 'big')}"


def test_the_range_field_is_quarter_metres_up_to_16_km_then_the_halo_form():
    assert range_fields(1852.0) == (0x80, 7408)  # radar_pi: large 0x80 -> small / 4 m
    large, small = range_fields(44448.0)  # 24 nm
    assert large * small / 512 == 44448.0


def test_frames_hold_32_spokes_of_packed_nibbles_and_resample_other_sample_counts():
    rng = np.random.default_rng(1)
    levels = rng.integers(0, 16, (64, 512), dtype=np.uint8)
    frames = spoke_frames(levels, np.arange(64), 2048, np.full(64, 90.0), 926.0)
    assert len(frames) == 2 and all(len(f) == 8 + 32 * 536 for f in frames)
    line = frames[1][8 + 536 * 3: 8 + 536 * 4]  # spoke 35
    assert struct.unpack_from("<H", line, 8)[0] == 70  # angle: 2 a spoke
    assert struct.unpack_from("<H", line, 10)[0] == 0x4000 | 1024  # 90 deg true
    data = np.frombuffer(line[24:], np.uint8)
    samples = np.empty(1024, np.uint8)
    samples[0::2], samples[1::2] = data & 0x0F, data >> 4
    assert np.array_equal(samples, np.repeat(levels[35], 2))  # 512 samples -> 1024 by nearest sample


def test_the_beacon_announces_the_spoke_command_and_report_groups_as_radar_pi_reads_them():
    fields = struct.unpack(BEACON_FORMAT, beacon())
    assert len(beacon()) == 222 and beacon()[:2] == b"\x01\xb2"
    data_a, send_a, report_a = (address(fields[i]) for i in (12, 14, 16))  # addrDataA, addrSendA, addrReportA
    assert (data_a, send_a, report_a) == ("236.6.7.8:6678", "236.6.7.10:6680", "236.6.7.9:6679")
    assert status_report()[:3] == b"\x01\xc4\x02"  # 01 C4 status: transmitting
