"""tdm.frontend.ais: AIS NMEA log to reports in ENU and static data, bad lines counted and skipped."""

from __future__ import annotations

import datetime as dt
import json
import math
from functools import reduce
from pathlib import Path

import numpy as np
import pytest
from pyais import encode_dict

from tdm.detections import ReadStats
from tdm.frames import EnuFrame
from tdm.frontend.ais import MPS_PER_KNOT, read_ais, rot_deg_per_min
from tdm.io import read_ownship, read_truth

START = 1496318400.0  # 2017-06-01T12:00:00Z
P = "ais/nmea: "


def start_unix_s(recording: Path) -> float:
    return dt.datetime.fromisoformat(json.loads((recording / "manifest.json").read_text())["start_time"]).timestamp()


def recording_frame(recording: Path) -> EnuFrame:
    nav = read_ownship(recording)
    return EnuFrame(nav["lat"][0], nav["lon"][0])


def xor(text: str) -> str:
    return f"{reduce(lambda a, c: a ^ ord(c), text, 0):02X}"


def tagged(unix_s, sentence: str) -> str:
    body = f"c:{unix_s}"
    return f"\\{body}*{xor(body)}\\{sentence}"


def vdm(fields: dict, seq_id: int | None = None, channel: str = "A") -> list[str]:
    return encode_dict(fields, talker_id="AI", sentence_type="VDM", radio_channel=channel,
                       **({} if seq_id is None else {"seq_id": seq_id}))


def type1(mmsi=257000009, turn=0.0, speed=10.0, lon=10.48, lat=59.44, course=90.0, heading=91, msg_type=1) -> dict:
    return {"msg_type": msg_type, "mmsi": mmsi, "status": 0, "turn": turn, "speed": speed, "accuracy": 1, "lon": lon,
            "lat": lat, "course": course, "heading": heading, "second": 0, "maneuver": 0, "raim": 0, "radio": 0}


def write_lines(path: Path, lines: list[str]) -> Path:
    path.write_text("\n".join(lines) + "\n")
    return path


# ----------------------------------------------------------------------------- a rendered recording


def test_reports_and_static_data_of_a_rendered_recording(bos_recording):
    frame = recording_frame(bos_recording)
    stats = ReadStats()
    reports, static = read_ais(bos_recording / "ais" / "ais.nmea", frame, start_unix_s(bos_recording), stats)
    assert stats.warnings == {}
    assert {r.mmsi for r in reports} == {257000001, 257000002}
    times = np.array([r.time_s for r in reports])
    assert np.all(np.diff(times) >= 0) and times[0] >= 0 and times[-1] <= 40
    truth = [row for row in read_truth(bos_recording) if row["mmsi"] in (257000001, 257000002)]
    for mmsi in (257000001, 257000002):
        rows = [row for row in truth if row["mmsi"] == mmsi]
        t = np.array([row["t"] for row in rows])
        mine = [r for r in reports if r.mmsi == mmsi]
        assert len(mine) >= 3
        for r in mine:
            # the TAG block time is the whole UNIX second; the front end takes its middle
            at = r.time_s
            assert (at - 0.5) == pytest.approx(round(at - 0.5))
            east, north = frame.to_enu(np.interp(at, t, [row["lat"] for row in rows]),
                                       np.interp(at, t, [row["lon"] for row in rows]))
            assert np.hypot(r.position_m[0] - east, r.position_m[1] - north) < 20.0
            assert r.position_m.shape == (2,)
            assert abs(r.sog_mps - np.interp(at, t, [row["sog_mps"] for row in rows])) < 1.0
            assert abs((r.cog_deg - np.interp(at, t, [row["cog_deg"] for row in rows]) + 180) % 360 - 180) < 6.0
            assert abs((r.heading_deg - np.interp(at, t, [row["heading_deg"] for row in rows]) + 180) % 360 - 180) < 6.0
            assert r.msg_type in (1, 3) and math.isfinite(r.rot_deg_per_min)
        entry = static[mmsi]
        assert entry.name == rows[0]["name"].upper()
        assert entry.length_m == pytest.approx(rows[0]["length_m"], abs=1.0)
        assert entry.beam_m == pytest.approx(rows[0]["beam_m"], abs=1.0)
        assert entry.ship_type == 70


def test_bad_lines_are_counted_and_skipped(bos_recording, tmp_path):
    frame = recording_frame(bos_recording)
    start = start_unix_s(bos_recording)
    good = (bos_recording / "ais" / "ais.nmea").read_text().splitlines()
    want, want_static = read_ais(bos_recording / "ais" / "ais.nmea", frame, start, ReadStats())
    single = next(line for line in good if ",1,1,," in line)
    first_fragment = next(line for line in good if "!AIVDM,2,1," in line)
    tag, sentence = single.rsplit("\\", 1)
    payload = sentence.split(",")[5]
    flipped = payload[:3] + ("0" if payload[3] != "0" else "1") + payload[4:]
    bad = [
        single.replace(payload, flipped),  # bad checksum
        single[: len(single) // 2],  # truncated
        "\x07\x1b#%&/()=?`" + "".join(chr(c) for c in range(200, 230)),  # random bytes
        "\x00\xff garbage",
        first_fragment.replace(",2,1,0,", ",2,1,7,").rsplit("*", 1)[0],  # a truncated first fragment
        tagged(int(START) + 2, "!AIVDM,2,2,8,B,00000000000,2*" + xor("AIVDM,2,2,8,B,00000000000,2")),  # orphan
        sentence,  # no TAG block
        "\\c:1496318401*00\\" + sentence,  # bad TAG block checksum
        tagged(int(START) + 3, vdm(type1(lon=181.0, lat=91.0))[0]),  # no position
        tagged(int(START) + 3, vdm({"msg_type": 4, "mmsi": 2570001, "year": 2017, "month": 6, "day": 1,
                                    "lon": 10.4, "lat": 59.4, "epfd": 1})[0]),  # a base station: not used
        "$GPRMC,120000.00,A,5926.2665,N,01028.2991,E,8.00,32.47,010617,,,A*6E",  # not AIS
        "",  # an empty line is just ignored
    ]
    orphan_first = tagged(int(START) + 1, first_fragment.rsplit("\\", 1)[1].replace(",0,A,", ",0,A,"))
    lines = []
    for k, line in enumerate(good):
        if line == first_fragment:
            lines.append(orphan_first)  # a first fragment whose partner never comes (the real pair follows)
        lines.append(line)
        if k < len(bad):
            lines.append(bad[k])
    lines += bad[len(good):]
    stats = ReadStats()
    got, got_static = read_ais(write_lines(tmp_path / "ais.nmea", lines), frame, start, stats)
    assert stats.warnings == {
        P + "bad checksum skipped": 2,  # a flipped character; a fragment cut before its checksum
        P + "unparsable line skipped": 3,  # truncated in the payload, random bytes, garbage
        P + "orphan fragment skipped": 2,
        P + "line without a (valid) TAG block time skipped": 2,
        P + "position report without a position (lon 181 / lat 91) skipped": 1,
        P + "message type 4 skipped (not used)": 1,
        P + "sentence other than !AIVDM skipped": 1,
    }
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert (g.time_s, g.mmsi, g.msg_type) == (w.time_s, w.mmsi, w.msg_type)
        np.testing.assert_array_equal(g.position_m, w.position_m)
    assert got_static == want_static


def test_a_missing_file_reads_as_no_ais(tmp_path):
    stats = ReadStats()
    assert read_ais(tmp_path / "ais.nmea", EnuFrame(59.44, 10.47), START, stats) == ([], {})
    assert stats.warnings == {}


# ----------------------------------------------------------------------------- fields


def test_rot_indicator_decodes_to_degrees_per_minute():
    k = np.arange(-126, 127)
    rot = rot_deg_per_min(k)
    np.testing.assert_allclose(rot, np.sign(k) * (k / 4.733) ** 2)
    # the inverse is the ITU encoding: k = round(4.733 sqrt(|ROT|)), sign kept
    np.testing.assert_array_equal(np.sign(rot) * np.round(4.733 * np.sqrt(np.abs(rot))), k)
    assert rot_deg_per_min(126) == pytest.approx(708.7, abs=0.1)
    assert all(math.isnan(rot_deg_per_min(v)) for v in (-128, -127, 127))


def test_fields_of_hand_made_messages(tmp_path):
    frame = EnuFrame(59.44, 10.47)
    codes = [0, 5, -16, 126, -128, 127, -127]
    lines = [tagged(int(START) + 10 + i, vdm(type1(turn=math.copysign((abs(c) / 4.733) ** 2, c) if abs(c) < 127 else c,
                                                   mmsi=257000100 + i))[0])
             for i, c in enumerate(codes)]
    lines += [
        tagged(int(START) + 20, vdm(type1(mmsi=257000200, speed=102.3, course=360.0, heading=511, msg_type=3))[0]),
        tagged(int(START) + 21, vdm({"msg_type": 18, "mmsi": 257000300, "speed": 3.0, "accuracy": 1, "lon": 10.47,
                                     "lat": 59.45, "course": 180.0, "heading": 179, "second": 0, "cs": 1,
                                     "band": 1, "radio": 0})[0]),
        tagged(int(START) + 22, vdm({"msg_type": 24, "mmsi": 257000300, "partno": 0, "shipname": "SAILOR"})[0]),
        tagged(int(START) + 22, vdm({"msg_type": 24, "mmsi": 257000300, "partno": 1, "ship_type": 37, "to_bow": 5,
                                     "to_stern": 4, "to_port": 1, "to_starboard": 2})[0]),
    ]
    static5 = {"msg_type": 5, "mmsi": 257000100, "shipname": "FIRST ONE", "ship_type": 52, "to_bow": 0,
               "to_stern": 0, "to_port": 3, "to_starboard": 3, "epfd": 1, "hour": 24, "minute": 60}
    lines += [tagged(int(START) + 23, s) for s in vdm(static5, seq_id=3, channel="B")]
    lines.insert(0, tagged(int(START) * 1000 + 30500, vdm(type1(mmsi=257000400))[0]))  # milliseconds, out of order
    stats = ReadStats()
    reports, static = read_ais(write_lines(tmp_path / "ais.nmea", lines), frame, START, stats)
    assert stats.warnings == {}
    assert [r.time_s for r in reports] == sorted(r.time_s for r in reports)
    by_mmsi = {r.mmsi: r for r in reports}
    for i, c in enumerate(codes):
        r = by_mmsi[257000100 + i]
        assert r.time_s == 10 + i + 0.5 and r.msg_type == 1  # the middle of the whole second
        if c in (-128, 127, -127):
            assert math.isnan(r.rot_deg_per_min)
        else:
            assert r.rot_deg_per_min == pytest.approx(math.copysign((c / 4.733) ** 2, c))
        assert r.sog_mps == pytest.approx(10.0 * MPS_PER_KNOT)
        assert (r.cog_deg, r.heading_deg) == (90.0, 91.0)
        east, north = frame.to_enu(59.44, 10.48)
        np.testing.assert_allclose(r.position_m, [east, north], atol=0.2)  # 1/10000 min of arc: 0.19 m
    na = by_mmsi[257000200]
    assert na.msg_type == 3 and math.isnan(na.sog_mps) and math.isnan(na.cog_deg) and math.isnan(na.heading_deg)
    b = by_mmsi[257000300]
    assert b.msg_type == 18 and math.isnan(b.rot_deg_per_min) and b.sog_mps == pytest.approx(3.0 * MPS_PER_KNOT)
    assert by_mmsi[257000400].time_s == pytest.approx(30.5)
    assert reports[-1].mmsi == 257000400
    assert static[257000300].name == "SAILOR" and static[257000300].ship_type == 37
    assert (static[257000300].length_m, static[257000300].beam_m) == (9.0, 3.0)
    first = static[257000100]
    assert first.name == "FIRST ONE" and first.ship_type == 52 and math.isnan(first.length_m) and first.beam_m == 6.0


def test_the_navigational_status_of_class_a_reports_is_read_and_class_b_has_none(tmp_path):
    frame = EnuFrame(59.44, 10.47)
    lines = [tagged(int(START) + 10 + i, vdm({**type1(mmsi=257000500 + i), "status": status})[0])
             for i, status in enumerate([0, 1, 5])]
    lines.append(tagged(int(START) + 20, vdm({"msg_type": 18, "mmsi": 257000600, "speed": 1.3, "accuracy": 1,
                                               "lon": 10.47, "lat": 59.45, "course": 64.0, "heading": 64,
                                               "second": 0, "cs": 1, "band": 1, "radio": 0})[0]))
    reports, _ = read_ais(write_lines(tmp_path / "ais.nmea", lines), frame, START, ReadStats())
    assert {r.mmsi: r.nav_status for r in reports} == {257000500: 0, 257000501: 1, 257000502: 5, 257000600: 15}
