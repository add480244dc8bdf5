"""NMEA files for chart plotters and parsers: nav/nav_plain.nmea, ais/ais_plain.nmea, ais/ais_received.jsonl.

The plain files are read back with independent parsers (pynmea2 for the own ship's sentences,
pyais's file stream for AIS) and compared with ownship.jsonl and the time-tagged files.
"""

from __future__ import annotations

import copy
import datetime as dt
import json
import re
from functools import reduce

import pynmea2
import pytest
import yaml
from pyais import decode
from pyais.stream import FileReaderStream

from raysim.cli import main
from raysim.errors import InputError
from raysim.recording import nmea
from raysim.scenario import load_scenario
from tests.conftest import BASE

START = dt.datetime(2017, 6, 1, 12, tzinfo=dt.timezone.utc)
NMEA_RATE_HZ = 2.0
GEOID_SEPARATION_M = 38.4  # about the EGM96 value of the Oslo fjord
EPOCH = [("GP", "RMC"), ("GP", "GGA"), ("GP", "VTG"), ("GP", "ZDA"), ("HE", "HDT")]


def _xor(text: str) -> str:
    return f"{reduce(lambda a, c: a ^ ord(c), text, 0):02X}"


def _scenario() -> dict:
    """BASE over 30 s: a Class A ship (type 5 static data: two sentences) and a Class B ship."""
    data = copy.deepcopy(BASE)
    data["duration_s"] = 30
    data["ships"][1]["ais"] = {"mmsi": 257000003, "ais_class": "B"}
    data["sensors"]["nav"] = {"nmea_rate_hz": NMEA_RATE_HZ, "geoid_separation_m": GEOID_SEPARATION_M}
    return data


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    root = tmp_path_factory.mktemp("nmea")
    path = root / "scenario.yaml"
    path.write_text(yaml.safe_dump(_scenario(), sort_keys=False), encoding="utf-8")
    assert main(["render", str(path), "-o", str(root / "rec"), "--no-progress", "--sensors", "ais,nav"]) == 0
    return root / "rec"


def _plain_lines(path) -> list[str]:
    """Lines of a plain NMEA file, asserting CR LF after every line and no TAG block anywhere."""
    raw = path.read_bytes()
    assert raw and raw.endswith(b"\r\n") and b"\\" not in raw
    lines = raw.decode("ascii").split("\r\n")[:-1]
    assert all("\r" not in line and "\n" not in line for line in lines)
    return lines


def _tagged_sentences(path) -> list[str]:
    return [line.split("\\")[2] for line in path.read_text(encoding="ascii").splitlines()]


# ----------------------------------------------------------------------------- sentences


def test_gpvtg_and_gpzda_layouts():
    vtg = nmea.gpvtg(4.1, 359.999)
    assert vtg == f"$GPVTG,0.00,T,,M,7.97,N,14.76,K,A*{_xor('GPVTG,0.00,T,,M,7.97,N,14.76,K,A')}"
    assert len(vtg.split("*")[0].split(",")) == 10  # talker+type and 9 fields (NMEA 0183 v3+: mode indicator)
    utc = dt.datetime(2017, 6, 1, 23, 59, 59, 999999, tzinfo=dt.timezone.utc)
    assert nmea.gpzda(utc) == f"$GPZDA,235959.99,01,06,2017,00,00*{_xor('GPZDA,235959.99,01,06,2017,00,00')}"
    for sentence in (vtg, nmea.gpzda(utc)):
        pynmea2.parse(sentence, check=True)


def test_gga_geoid_separation_field():
    def sep(value_m):
        return nmea.gpgga(START, 59.4, 10.5, 1.0, geoid_separation_m=value_m).split(",")[11]

    assert [sep(v) for v in (0.0, -0.04, 38.44, -35.26, 120.0)] == ["0.0", "0.0", "38.4", "-35.3", "120.0"]
    assert nmea.gpgga(START, 59.4, 10.5, 1.0) == nmea.gpgga(START, 59.4, 10.5, 1.0, geoid_separation_m=0.0)


def test_geoid_separation_key_is_validated(write_scenario):
    data = _scenario()
    assert load_scenario(write_scenario(data)).sensors.nav.geoid_separation_m == GEOID_SEPARATION_M
    data["sensors"]["nav"]["geoid_separation_m"] = 130.0
    with pytest.raises(InputError, match="geoid_separation_m"):
        load_scenario(write_scenario(data, "bad.yaml"))
    default = copy.deepcopy(BASE)
    assert load_scenario(write_scenario(default, "default.yaml")).sensors.nav.geoid_separation_m == 0.0


# ----------------------------------------------------------------------------- nav/nav_plain.nmea


def test_plain_nav_is_the_tagged_file_without_tag_blocks(recording):
    plain = _plain_lines(recording / "nav" / "nav_plain.nmea")
    assert plain == _tagged_sentences(recording / "nav" / "nav.nmea")
    counts = json.loads((recording / "manifest.json").read_text())["counts"]
    assert counts["nav/nav_plain.nmea"] == counts["nav/nav.nmea"] == len(plain) == 5 * 61  # 2 Hz over 30 s


def test_pynmea2_reads_the_plain_nav_file_as_the_navigation_solution(recording):
    rows = {round(r["t"], 4): r for r in map(json.loads, (recording / "ownship.jsonl").read_text().splitlines())}
    plain = _plain_lines(recording / "nav" / "nav_plain.nmea")
    n = len(EPOCH)
    for j in range(len(plain) // n):
        msgs = [pynmea2.parse(line, check=True) for line in plain[n * j : n * j + n]]
        assert [(m.talker, m.sentence_type) for m in msgs] == EPOCH
        rmc, gga, vtg, zda, hdt = msgs
        t = j / NMEA_RATE_HZ
        r = rows[t]
        utc = START + dt.timedelta(seconds=t)
        # time and date: RMC, GGA and ZDA agree with start_time + t
        assert dt.datetime.combine(zda.datestamp, zda.timestamp) == utc
        assert (int(zda.local_zone), int(zda.local_zone_minutes)) == (0, 0)
        assert dt.datetime.combine(rmc.datestamp, rmc.timestamp) == utc and gga.timestamp == rmc.timestamp
        # position to the 1e-4 min of the fields
        for m in (rmc, gga):
            assert abs(m.latitude - r["lat"]) * 60 <= 0.5e-4 + 1e-9
            assert abs(m.longitude - r["lon"]) * 60 <= 0.5e-4 + 1e-9
        assert gga.gps_qual == 1 and gga.altitude == pytest.approx(r["z"], abs=0.005 + 1e-9)
        assert gga.geo_sep == f"{GEOID_SEPARATION_M}" and gga.geo_sep_units == "M"
        # speed and course: RMC and VTG, knots and km/h
        sog_kn = r["sog_mps"] * nmea.KNOTS_PER_MPS
        assert rmc.spd_over_grnd == pytest.approx(sog_kn, abs=0.0051 + 0.002)  # ownship.jsonl has 3 decimals of m/s
        assert float(vtg.spd_over_grnd_kts) == rmc.spd_over_grnd
        assert vtg.spd_over_grnd_kmph == pytest.approx(float(vtg.spd_over_grnd_kts) * 1.852, abs=0.0051 + 0.0051 * 1.852)
        assert vtg.spd_over_grnd_kmph == pytest.approx(r["sog_mps"] * 3.6, abs=0.0051 + 0.0036)
        assert (vtg.true_track_sym, vtg.mag_track, vtg.mag_track_sym, vtg.faa_mode) == ("T", None, "M", "A")
        assert vtg.true_track == rmc.true_course
        assert abs((rmc.true_course - r["cog_deg"] + 180.0) % 360.0 - 180.0) <= 0.0051
        assert abs((float(hdt.heading) - r["heading_deg"] + 180.0) % 360.0 - 180.0) <= 0.0051 and hdt.hdg_true == "T"


def test_geoid_separation_reaches_gga_of_both_files(recording):
    for name in ("nav.nmea", "nav_plain.nmea"):
        gga = [s for s in (recording / "nav" / name).read_text(encoding="ascii").splitlines() if "GPGGA" in s]
        assert gga and {s.split(",")[11:13] == [f"{GEOID_SEPARATION_M}", "M"] for s in gga} == {True}
    scenario = load_scenario(recording / "scenario.yaml")
    assert scenario.sensors.nav.geoid_separation_m == GEOID_SEPARATION_M  # kept in the resolved scenario.yaml


# ----------------------------------------------------------------------------- ais/ais_plain.nmea, ais_received.jsonl


def test_pyais_decodes_the_plain_ais_file_as_the_tagged_one(recording):
    plain = _plain_lines(recording / "ais" / "ais_plain.nmea")
    tagged = _tagged_sentences(recording / "ais" / "ais.nmea")
    assert plain == tagged and any(s.startswith("!AIVDM,2,") for s in plain)  # a two-sentence message among them
    from_plain = [m.decode().asdict() for m in FileReaderStream(str(recording / "ais" / "ais_plain.nmea"))]
    from_tagged = [m.decode().asdict() for m in FileReaderStream(str(recording / "ais" / "ais.nmea"))]
    assert from_plain == from_tagged and len(from_plain) < len(plain)
    # and joined by hand: fragments on consecutive lines
    joined, pending = [], []
    for sentence in plain:
        pending.append(sentence)
        if sentence.split(",")[1] == sentence.split(",")[2]:
            joined.append(decode(*pending).asdict())
            pending = []
    assert joined == from_plain and not pending
    counts = json.loads((recording / "manifest.json").read_text())["counts"]
    assert counts["ais/ais_plain.nmea"] == counts["ais/ais.nmea"] == len(plain)


def test_ais_received_times_match_the_tagged_lines(recording):
    tagged = (recording / "ais" / "ais.nmea").read_text(encoding="ascii").splitlines()
    text = (recording / "ais" / "ais_received.jsonl").read_text(encoding="ascii")
    assert all(re.fullmatch(r'\{"t": \d+\.\d{6}, "sentence": "![^"\\]+"\}', line) for line in text.splitlines())
    rows = [json.loads(line) for line in text.splitlines()]
    assert len(rows) == len(tagged) == json.loads((recording / "manifest.json").read_text())["counts"][
        "ais/ais_received.jsonl"]
    start_unix_s = START.timestamp()
    for row, line in zip(rows, tagged):
        c = int(line[3:].split("*")[0])
        assert row["sentence"] == line.split("\\")[2]
        assert c - 1e-6 <= start_unix_s + row["t"] < c + 1
    t = [row["t"] for row in rows]
    assert t == sorted(t) and t[-1] < 30.0
    # the fragments of a message share its time; times are not all whole seconds
    for a, b in zip(rows, rows[1:]):
        if b["sentence"].split(",")[2] != "1":
            assert a["t"] == b["t"]
    assert any(x != int(x) for x in t)


def test_same_inputs_same_bytes_for_the_new_files(recording, tmp_path):
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(_scenario(), sort_keys=False), encoding="utf-8")
    assert main(["render", str(path), "-o", str(tmp_path / "again"), "--no-progress", "--sensors", "ais,nav"]) == 0
    for name in ("nav/nav_plain.nmea", "ais/ais_plain.nmea", "ais/ais_received.jsonl", "nav/nav.nmea", "ais/ais.nmea"):
        assert (tmp_path / "again" / name).read_bytes() == (recording / name).read_bytes(), name
