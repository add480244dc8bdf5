"""AIS transponders as heard by the own ship: ais/ais.nmea decoded with pyais (issue 5)."""

from __future__ import annotations

import copy
import math
from functools import reduce

import numpy as np
import pytest
from pyais import decode, encode_dict

from raysim.cli import main
from raysim.geodesy import LocalFrame
from raysim.scenario import load_scenario
from raysim import ais_fields as fields
from raysim.sensors.ais import ais_lines, radio_horizon_m, received_messages, ship_messages
from raysim.world import World
from tests.conftest import BASE, REPO as BASE_DIR

ORIGIN = (BASE["origin"]["lat"], BASE["origin"]["lon"])
FRAME = LocalFrame(*ORIGIN)


def ll(x_m: float, y_m: float) -> list[float]:
    lat, lon = FRAME.to_geodetic(x_m, y_m)
    return [float(lat), float(lon)]


def ship(name, mmsi, speed_kn, start=(0.0, 500.0), course_deg=90.0, length_m=40.0, **ais):
    x0, y0 = start
    c = math.radians(course_deg)
    end = (x0 + 20_000 * math.sin(c), y0 + 20_000 * math.cos(c))
    waypoints = [ll(*start)] if speed_kn == 0 else [ll(*start), ll(*end)]
    entry = {"name": name, "length_m": length_m, "speed_kn": speed_kn, "waypoints": waypoints}
    if mmsi is not None:
        entry["ais"] = {"mmsi": mmsi, **ais}
    return entry


def scenario_dict(ships, duration_s=600.0, noise=None, receiver=None):
    data = copy.deepcopy(BASE)
    data["duration_s"] = duration_s
    data["obstacles"] = []
    data["own_ship"] = {"length_m": 10.9, "beam_m": 3.5, "position": ll(0.0, 0.0), "heading_deg": 0,
                        "motion": {"roll_amplitude_deg": 0, "pitch_amplitude_deg": 0, "heave_amplitude_m": 0}}
    data["sensors"] = {"lidar": {"enabled": False}, "radar": {"enabled": False}, "nav": {"enabled": False},
                       "ais": {"range_m": 50_000, **(receiver or {}), **({"noise": noise} if noise else {})}}
    data["ships"] = ships
    return data


def world_of(write_scenario, data, name="ais.yaml"):
    return World(load_scenario(write_scenario(data, name)))


def transmissions(world, name):
    obj = next(o for o in world.objects if o.name == name)
    cfg = next(s for s in world.scenario.ships if s.name == name)
    return obj, ship_messages(world, obj, cfg)


def nmea_checksum_ok(sentence: str) -> bool:
    body, hh = sentence[1:].split("*")
    return f"{reduce(lambda a, c: a ^ ord(c), body, 0):02X}" == hh


def split_line(line: str) -> tuple[int, str]:
    """(unix time of the TAG block, sentence), checking the TAG block's own checksum."""
    assert line.startswith("\\")
    tag, sentence = line[1:].split("\\", 1)
    body, hh = tag.split("*")
    assert f"{reduce(lambda a, c: a ^ ord(c), body, 0):02X}" == hh
    assert body.startswith("c:")
    return int(body[2:]), sentence


def decode_file(path):
    """Decode every line of an ais.nmea file, grouping fragments; returns [(unix time, message)]."""
    out, pending = [], []
    for line in path.read_text(encoding="ascii").splitlines():
        t, sentence = split_line(line)
        assert nmea_checksum_ok(sentence), line
        parts = sentence.split(",")
        count, index = int(parts[1]), int(parts[2])
        pending.append(sentence)
        if index == count:
            if count > 1:
                assert len({p.split(",")[3] for p in pending}) == 1  # one sequential message id for all fragments
                assert [int(p.split(",")[2]) for p in pending] == list(range(1, count + 1))
            out.append((t, decode(*pending)))
            pending = []
    assert not pending
    return out


# ---------------------------------------------------------------- the file a render writes


FLEET = [
    ship("cargo", 257000001, 10.0, start=(-2000.0, 800.0)),
    ship("anchored", 257000002, 0.0, start=(600.0, -900.0), length_m=60.0),
    ship("yacht", 257000003, 6.0, start=(-500.0, -1500.0), length_m=9.0, ais_class="B"),
    ship("silent", 257000004, 12.0, start=(1500.0, 1500.0), course_deg=200.0, enabled=False),
    ship("no_transponder", None, 12.0, start=(-1500.0, 2500.0)),
]


def test_render_writes_decodable_nmea_from_the_right_ships(write_scenario, tmp_path):
    data = scenario_dict(FLEET, duration_s=400.0)
    data["sensors"]["nav"] = {"enabled": True}
    path = write_scenario(data)
    assert main(["render", str(path), "-o", str(tmp_path / "rec"), "--sensors", "ais,nav"]) == 0
    assert (tmp_path / "rec" / "nav" / "nav.nmea").is_file() and (tmp_path / "rec" / "ownship.jsonl").is_file()
    decoded = decode_file(tmp_path / "rec" / "ais" / "ais.nmea")
    times = [t for t, _ in decoded]
    assert times == sorted(times)
    senders = {m.mmsi for _, m in decoded}
    assert senders == {257000001, 257000002, 257000003}  # the silent ship and the one without a transponder never
    types = {(m.mmsi, m.msg_type) for _, m in decoded}
    assert {(257000001, 5), (257000002, 5), (257000003, 24)} <= types
    assert {m.msg_type for _, m in decoded if m.mmsi == 257000003} == {18, 24}
    assert {m.status for _, m in decoded if m.mmsi == 257000002 and m.msg_type in (1, 3)} == {1}  # at anchor
    assert {m.status for _, m in decoded if m.mmsi == 257000001 and m.msg_type in (1, 3)} == {0}  # under way
    part_b = {(m.vendorid, m.model, m.serial) for _, m in decoded if m.msg_type == 24 and m.partno == 1}
    assert part_b == {("RSM", 1, 3)}  # manufacturer, unit model, serial (the MMSI's last six digits)
    statics = [m for _, m in decoded if m.msg_type == 5 and m.mmsi == 257000001]
    assert statics[0].shipname == "CARGO" and statics[0].to_bow + statics[0].to_stern == 40
    channels = [line.split(",")[4] for line in (tmp_path / "rec" / "ais" / "ais.nmea").read_text().splitlines()]
    assert set(channels) == {"A", "B"}
    # same inputs, same bytes
    assert main(["render", str(path), "-o", str(tmp_path / "again"), "--sensors", "ais,nav"]) == 0
    assert (tmp_path / "again" / "ais" / "ais.nmea").read_bytes() == (tmp_path / "rec" / "ais" / "ais.nmea").read_bytes()


# ---------------------------------------------------------------- reporting intervals (ITU-R M.1371)


@pytest.mark.parametrize("speed_kn, ais_class, expected_s", [
    (8.0, "A", 10.0), (18.0, "A", 6.0), (25.0, "A", 2.0), (0.0, "A", 180.0), (6.0, "B", 30.0), (1.0, "B", 180.0)])
def test_reporting_interval_per_speed_class(write_scenario, speed_kn, ais_class, expected_s):
    duration = 3600.0 if expected_s == 180.0 else 600.0
    world = world_of(write_scenario, scenario_dict([ship("s", 257000009, speed_kn, ais_class=ais_class)], duration))
    _, sent = transmissions(world, "s")
    t = np.array([m.t_s for m in sent if m.data["msg_type"] in (1, 2, 3, 18)])
    assert np.median(np.diff(t)) == pytest.approx(expected_s, rel=0.05)
    assert np.all(np.diff(t) > 0.75 * expected_s)  # jitter stays within the selection interval
    static = np.array([m.t_s for m in sent if m.data["msg_type"] in (5, 24)])
    assert static.min() < 6.0 + 0.1  # static data at start ...
    assert np.diff(np.unique(static.round(0))).min() == pytest.approx(360.0, abs=1.0)  # ... and every 6 min


def test_reporting_interval_while_changing_course(write_scenario):
    # 10 kn north, then a 90 deg turn to the east at the second waypoint: 3 1/3 s while turning
    entry = {"name": "turner", "length_m": 40.0, "speed_kn": 10.0, "heading_time_constant_s": 30.0,
             "waypoints": [ll(0.0, -600.0), ll(0.0, 400.0), ll(5000.0, 400.0)], "ais": {"mmsi": 257000010}}
    world = world_of(write_scenario, scenario_dict([entry], 400.0))
    obj, sent = transmissions(world, "turner")
    t = np.array([m.t_s for m in sent if m.data["msg_type"] in (1, 3)])
    yaw = np.unwrap(obj.motion.poses(t).yaw_rad)
    rot_deg_per_min = np.abs(np.gradient(np.degrees(yaw), t)) * 60.0
    gaps = np.diff(t)
    turning = (rot_deg_per_min[:-1] > 30.0) & (rot_deg_per_min[1:] > 30.0)
    straight = (rot_deg_per_min[:-1] < 1.0) & (rot_deg_per_min[1:] < 1.0)
    assert turning.sum() >= 5 and straight.sum() >= 5
    assert np.median(gaps[turning]) == pytest.approx(10.0 / 3.0, rel=0.1)
    assert np.median(gaps[straight]) == pytest.approx(10.0, rel=0.1)
    assert any(m.data["msg_type"] == 3 for m in sent)  # the rate change is announced (ITDMA)


# ---------------------------------------------------------------- errors (thesis section 2.5)


def decoded_errors(world, name):
    """Errors of the decoded reports against the truth at the transmission times."""
    obj, sent = transmissions(world, name)
    reports = [m for m in sent if m.data["msg_type"] in (1, 3)]
    t = np.array([m.t_s for m in reports])
    msgs = [decode(*encode_dict(m.data, talker_id="AI", sentence_type="VDM")) for m in reports]
    poses = obj.motion.poses(t)
    lat = np.array([m.lat for m in msgs])
    lon = np.array([m.lon for m in msgs])
    x, y = FRAME.to_local(lat, lon)
    sog_kn = np.hypot(*obj.motion.velocity_mps(t)[:, :2].T) * 3600 / 1852
    return t, {
        "east": x - poses.position_m[:, 0], "north": y - poses.position_m[:, 1],
        "sog": np.array([m.speed for m in msgs]) - sog_kn,
        "heading": (np.array([m.heading for m in msgs]) - (90.0 - np.degrees(poses.yaw_rad)) + 180.0) % 360.0 - 180.0,
    }


def test_noise_variances_match_the_thesis_parameters(write_scenario):
    world = world_of(write_scenario, scenario_dict([ship("fast", 257000011, 25.0)], 3600.0))
    _, err = decoded_errors(world, "fast")
    n = world.scenario.sensors.ais.noise
    # white + stationary bias; the decoded fields add their quantisation (1/10000 min, 0.1 kn, 1 deg)
    assert np.var(err["east"]) == pytest.approx(n.position_measure_variance_m2 + n.position_bias_variance_m2, rel=0.12)
    assert np.var(err["north"]) == pytest.approx(n.position_measure_variance_m2 + n.position_bias_variance_m2, rel=0.12)
    assert np.var(err["sog"]) == pytest.approx(n.sog_measure_variance_knots2 + n.sog_bias_variance_knots2 + 0.1**2 / 12, rel=0.12)
    assert np.var(err["heading"]) == pytest.approx(n.track_measure_variance_deg2 + n.track_bias_variance_deg2 + 1 / 12, rel=0.15)
    assert abs(np.mean(err["east"])) < 0.3 and abs(np.mean(err["sog"])) < 0.1


def test_bias_correlation_time_matches_the_configuration(write_scenario):
    # bias-dominated errors, time constants a few report intervals long: many independent bias samples
    noise = {"position_measure_variance_m2": 0.01, "position_bias_variance_m2": 25.0, "position_bias_time_constant_sec": 6.0,
             "sog_measure_variance_knots2": 0.0, "sog_bias_variance_knots2": 4.0, "sog_bias_time_constant_sec": 4.0}
    world = world_of(write_scenario, scenario_dict([ship("fast", 257000012, 30.0)], 7200.0, noise=noise))
    t, err = decoded_errors(world, "fast")
    for key, var, tau in (("east", 25.0, 6.0), ("north", 25.0, 6.0), ("sog", 4.0, 4.0)):
        e = err[key] - err[key].mean()
        for lag in (tau, 2 * tau):
            j = np.searchsorted(t, t + lag)
            ok = j < t.size
            lags = t[j[ok]] - t[ok]
            rho = np.mean(e[ok] * e[j[ok]]) / var
            assert rho == pytest.approx(np.mean(np.exp(-lags / tau)), abs=0.08), (key, lag)
        assert np.var(e) == pytest.approx(var, rel=0.12)


# ---------------------------------------------------------------- clamping before encoding


def roundtrip(data):
    return decode(*encode_dict(data, talker_id="AI", sentence_type="VDM"))


def test_fields_are_clamped_to_their_legal_ranges_and_not_available_codes():
    m = roundtrip(fields.position_report(1, 257000001, 0, 800.0, 150.0, True, 10.5, 59.4, 725.0, 600.0, 61.0))
    assert m.turn == pytest.approx(708.7, abs=0.5)  # +126, not a wrapped left turn
    assert m.speed == 102.2 and m.course == 5.0 and m.heading == 240 and m.second == 59
    m = roundtrip(fields.position_report(1, 257000001, 0, -800.0, -3.0, True, 10.5, 59.4, -10.0, -0.4, 0))
    assert m.turn == pytest.approx(-708.7, abs=0.5) and m.speed == 0.0 and m.course == 350.0 and m.heading == 0
    nan = float("nan")
    m = roundtrip(fields.position_report(3, 257000001, 1, nan, nan, False, nan, nan, nan, nan, nan))
    assert (m.speed, m.lon, m.lat, m.course, m.heading, m.second) == (102.3, 181.0, 91.0, 360.0, 511, 60)
    assert int(m.turn) == -128
    assert [fields.rot_code(r) for r in (0.0, 1.0, -1.0, 127.0, 128.0, 708.0, 1e6)] == [0, 5, -5, 53, 54, 126, 126]
    assert roundtrip(fields.position_report(1, 257000001, 0, 127.0, 1, 1, 0, 0, 0, 0, 0)).turn == pytest.approx(127, abs=2)
    m = roundtrip(fields.class_b_report(257000001, 200.0, True, 10.5, 59.4, 359.96, 359.6, 12))
    assert m.speed == 102.2 and m.course == 0.0 and m.heading == 0
    m = roundtrip(fields.static_report(257000001, "a very long name of a ship", "toolongsign", 70, 1000.0, 200.0, 40.0, None))
    assert m.shipname == "A VERY LONG NAME OF" and m.callsign == "TOOLONG" and m.to_bow == 500 and m.to_port == 63
    assert m.draught == 25.5


# ---------------------------------------------------------------- failure modes and reception


def test_off_periods_dropouts_and_offset_positions(write_scenario):
    ships = [ship("off", 257000021, 10.0, off_periods_s=[[100.0, 250.0]]),
             ship("lossy", 257000022, 25.0, start=(0.0, -500.0), dropout_probability=0.3),
             ship("spoofed", 257000023, 10.0, start=(0.0, 1500.0), position_offset_m=[300.0, -200.0])]
    world = world_of(write_scenario, scenario_dict(ships, 600.0))
    obj, sent = transmissions(world, "off")
    heard = [m.t_s for m in received_messages(world, sent, obj)]
    assert heard and not any(100.0 <= t < 250.0 for t in heard) and any(t >= 250.0 for t in heard)
    obj, sent = transmissions(world, "lossy")
    assert len(received_messages(world, sent, obj)) / len(sent) == pytest.approx(0.7, abs=0.06)
    obj, sent = transmissions(world, "spoofed")
    reports = [m for m in sent if m.data["msg_type"] in (1, 3)]
    t = np.array([m.t_s for m in reports])
    x, y = FRAME.to_local(np.array([m.data["lat"] for m in reports]), np.array([m.data["lon"] for m in reports]))
    truth = obj.motion.poses(t).position_m
    assert np.mean(x - truth[:, 0]) == pytest.approx(300.0, abs=3.0)
    assert np.mean(y - truth[:, 1]) == pytest.approx(-200.0, abs=3.0)


def test_reception_is_limited_by_range_and_the_radio_horizon(write_scenario):
    # own antenna 5 m, a 2 m high transmitter: horizon 4.12 (sqrt 2 + sqrt 5) km = 15.0 km
    assert radio_horizon_m(2.0, 5.0) == pytest.approx(15_039.0, rel=1e-3)
    ships = [ship("near", 257000031, 0.0, start=(0.0, 12_000.0), antenna_height_m=2.0),
             ship("beyond_horizon", 257000032, 0.0, start=(0.0, 20_000.0), antenna_height_m=2.0),
             ship("tall_far", 257000033, 0.0, start=(0.0, 25_000.0), antenna_height_m=30.0)]  # horizon 31.8 km
    for horizon, expected in ((True, {257000031, 257000033}), (False, {257000031, 257000032, 257000033})):
        world = world_of(write_scenario, scenario_dict(ships, 400.0, receiver={"radio_horizon": horizon}), f"h{horizon}.yaml")
        heard = set()
        for name in ("near", "beyond_horizon", "tall_far"):
            obj, sent = transmissions(world, name)
            heard |= {m.mmsi for m in received_messages(world, sent, obj)}
        assert heard == expected
    world = world_of(write_scenario, scenario_dict(ships, 400.0, receiver={"range_m": 10_000}), "short.yaml")
    obj, sent = transmissions(world, "near")
    assert received_messages(world, sent, obj) == []


def test_multi_sentence_messages_get_cycling_sequence_ids():
    import datetime as dt

    from raysim.sensors.ais import AisMessage

    static = fields.static_report(257000001, "SHIP", "CALL", 70, 50, 10, 3.0, "OSLO")
    report = fields.position_report(1, 257000001, 0, 0.0, 10.0, True, 10.5, 59.4, 90.0, 90.0, 0)
    msgs = [AisMessage(float(k), 257000001, "A", static if k % 2 == 0 else report) for k in range(24)]
    lines = ais_lines(msgs, dt.datetime(2017, 6, 1, 12, tzinfo=dt.timezone.utc))
    parts = [line.split("\\")[2].split(",") for line in lines]
    seq = [p[3] for p in parts if p[1] == "2" and p[2] == "1"]
    assert all(p[3] == "" for p in parts if p[1] == "1")
    assert seq == [str(k % 10) for k in range(12)]
    assert all(line.startswith("\\c:14963184") for line in lines)


def test_the_thesis_noise_parameters_are_accepted_as_named_there(write_scenario):
    import yaml

    thesis = yaml.safe_load((BASE_DIR / "tests" / "data" / "hilsim_busy_open_sea" / "sensor_params.yaml").read_text())
    noise = {k: v for k, v in thesis.items() if k.startswith("AIS_") and k != "AIS_range_m"}
    assert len(noise) == 15
    world = world_of(write_scenario, scenario_dict([ship("s", 257000041, 10.0)], 60.0, noise=noise))
    n = world.scenario.sensors.ais.noise
    assert (n.cog_measure_variance_deg2, n.rot_measure_variance_deg2_pr_min2, n.position_bias_time_constant_sec) == (1, 2000, 20)
    data = scenario_dict([ship("s", 257000041, 10.0)], 60.0,
                         noise={"AIS_SOG_measure_variance_knots2": 0.5, "sog_measure_variance_knots2": 0.4})
    path = write_scenario(data, "twice.yaml")
    assert main(["render", str(path), "-o", str(path.parent / "out")]) == 2


def test_message_24_part_b_vendor_id_is_manufacturer_model_and_serial_as_itu_lays_them_out():
    """ITU-R M.1371-5 message 24 part B: the 42-bit vendor ID is 18 bits of manufacturer's ID (3 six-bit
    characters), 4 bits of unit model code, 20 bits of serial number; "RAYSIM" used to be cut to "RAY"."""
    data = fields.static_report_b(257123456, 1, "yacht", "LA1234", 37, 10.0, 4.0)
    sentences = encode_dict(data, radio_channel="B", talker_id="AI")
    m = decode(*sentences)
    assert (m.msg_type, m.partno, m.mmsi) == (24, 1, 257123456)
    assert (m.vendorid, m.model, m.serial) == ("RSM", 1, 123456) == (fields.VENDOR_ID, fields.UNIT_MODEL_CODE,
                                                                       fields.unit_serial(257123456))
    assert (m.callsign, m.ship_type, m.to_bow + m.to_stern, m.to_port + m.to_starboard) == ("LA1234", 37, 10, 4)
    # the bits themselves: payload characters to six-bit values, the vendor ID at bits 48..89
    payload = sentences[0].split(",")[5]
    bits = "".join(format((ord(c) - 48) - (8 if ord(c) - 48 > 40 else 0), "06b") for c in payload)
    six_bit = {c: i for i, c in enumerate(fields.AIS_CHARS)}
    assert bits[48:66] == "".join(format(six_bit[c], "06b") for c in "RSM")
    assert int(bits[66:70], 2) == 1 and int(bits[70:90], 2) == 123456
    # every MMSI's serial fits the 20-bit field
    assert fields.unit_serial(999_999_999) == 999_999 <= fields.SERIAL_MAX
