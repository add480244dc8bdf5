"""Own-ship navigation (issue part 3): ownship.jsonl with GNSS/INS errors and nav/nav.nmea."""

from __future__ import annotations

import copy
import dataclasses
import datetime as dt
import json
import re
from functools import reduce

import numpy as np
import pytest

from raysim.cli import main
from raysim.recording import nmea
from raysim.scenario import Nav, load_scenario
from raysim.sensors.nav import NavErrorModel, grid_size, navigation_chunks, nmea_indices
from raysim.world import World
from tests.conftest import BASE

ZERO_ERRORS = dict(position_noise_m=0.0, position_bias_m=0.0, velocity_noise_mps=0.0, heading_noise_deg=0.0,
                   heading_bias_deg=0.0, attitude_noise_deg=0.0)
START_UNIX_S = dt.datetime(2017, 6, 1, 12, tzinfo=dt.timezone.utc).timestamp()
LINE = re.compile(r"^\\(c:(\d+))\*([0-9A-F]{2})\\\$([^*$!\\]+)\*([0-9A-F]{2})$")


def _scenario(**nav) -> dict:
    """BASE with only the own ship, AIS off, and ``sensors.nav`` overrides."""
    data = copy.deepcopy(BASE)
    data["ships"], data["obstacles"] = [], []
    data["sensors"]["ais"] = {"enabled": False}
    data["sensors"]["nav"] = nav
    return data


def _render(write_scenario, tmp_path, data, name="rec", *extra):
    out = tmp_path / name
    assert main(["render", str(write_scenario(data, f"{name}.yaml")), "-o", str(out), "--no-progress", *extra]) == 0
    return out


def _jsonl(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def _xor(text: str) -> str:
    return f"{reduce(lambda a, c: a ^ ord(c), text, 0):02X}"


def _parse(line: str) -> tuple[int, list[str]]:
    """(TAG block unix time, sentence fields); asserts both checksums."""
    m = LINE.match(line)
    assert m, line
    tag_body, unix, tag_sum, body, body_sum = m.group(1), int(m.group(2)), m.group(3), m.group(4), m.group(5)
    assert _xor(tag_body) == tag_sum, line
    assert _xor(body) == body_sum, line
    return unix, body.split(",")


def _degrees(value: str, hemisphere: str, degree_digits: int) -> float:
    deg = int(value[:degree_digits]) + float(value[degree_digits:]) / 60.0
    return -deg if hemisphere in "SW" else deg


def _hhmmss_s(value: str) -> float:
    return int(value[:2]) * 3600 + int(value[2:4]) * 60 + float(value[4:])


def _angle_diff(a, b):
    return (np.asarray(a) - np.asarray(b) + 180.0) % 360.0 - 180.0


# ----------------------------------------------------------------------------- NMEA sentences


def test_gpgga_and_hehdt_layouts():
    utc = dt.datetime(2017, 6, 1, 12, 34, 56, 780000, tzinfo=dt.timezone.utc)
    gga = nmea.gpgga(utc, -59.5, -10.25, 1.234)
    assert gga.startswith("$GPGGA,123456.78,5930.0000,S,01015.0000,W,1,10,0.9,1.23,M,0.0,M,,*")
    assert gga[-2:] == _xor(gga[1:-3])
    assert len(gga.split(",")) == 15  # talker+type and 14 fields
    hdt = nmea.hehdt(359.999)
    assert hdt == f"$HEHDT,0.00,T*{_xor('HEHDT,0.00,T')}"
    assert nmea.hehdt(-0.5).startswith("$HEHDT,359.50,T*")


def test_minutes_never_round_to_sixty():
    # 59.99999999 deg: 4-decimal minutes round up to the next whole degree
    assert nmea.gpgga(dt.datetime(2017, 6, 1, tzinfo=dt.timezone.utc), 59.99999999, 10.99999999, 0.0).split(",")[2:6] \
        == ["6000.0000", "N", "01100.0000", "E"]


def test_nmea_epochs_on_the_navigation_grid():
    assert np.array_equal(nmea_indices(5.0, 50.0, 1.0), np.arange(6) * 50)
    assert np.array_equal(nmea_indices(1.0, 10.0, 3.0), [0, 3, 7, 10])  # nearest samples to 0, 1/3, 2/3, 1 s
    assert np.array_equal(nmea_indices(1.0, 10.0, 40.0), np.arange(11))  # capped at the navigation rate
    assert grid_size(5.0, 50.0) == 251


# ----------------------------------------------------------------------------- nav/nav.nmea


@pytest.fixture
def nav_recording(write_scenario, tmp_path):
    return _render(write_scenario, tmp_path, _scenario(nmea_rate_hz=2.0))


def test_every_nmea_line_has_valid_tag_block_and_checksum(nav_recording):
    lines = (nav_recording / "nav" / "nav.nmea").read_text(encoding="ascii").splitlines()
    assert len(lines) == 5 * 11  # 2 Hz over 5 s: epochs 0, 0.5, ..., 5 s
    manifest = json.loads((nav_recording / "manifest.json").read_text())
    assert manifest["counts"]["nav/nav.nmea"] == len(lines) and "nav" in manifest["sensors_rendered"]
    for j in range(11):
        epoch = [_parse(line) for line in lines[5 * j : 5 * j + 5]]
        assert [fields[0] for _, fields in epoch] == ["GPRMC", "GPGGA", "GPVTG", "GPZDA", "HEHDT"]
        assert {unix for unix, _ in epoch} == {int(START_UNIX_S + j * 0.5)}


def test_nmea_agrees_with_ownship_at_the_same_epoch(nav_recording):
    rows = {round(r["t"], 4): r for r in _jsonl(nav_recording / "ownship.jsonl")}
    lines = (nav_recording / "nav" / "nav.nmea").read_text(encoding="ascii").splitlines()
    for j in range(len(lines) // 5):
        (_, rmc), (_, gga), _, _, (_, hdt) = (_parse(line) for line in lines[5 * j : 5 * j + 5])
        t = j * 0.5
        r = rows[t]
        # $GPRMC,hhmmss.ss,A,lat,N,lon,E,sog_kn,cog,ddmmyy,,,A
        assert len(rmc) == 13 and rmc[2] == "A" and rmc[9] == "010617" and rmc[12] == "A"
        assert _hhmmss_s(rmc[1]) == pytest.approx(12 * 3600 + t, abs=1e-9)
        assert _degrees(rmc[3], rmc[4], 2) == pytest.approx(r["lat"], abs=1e-6)  # 0.0001' = 1.7e-6 deg
        assert _degrees(rmc[5], rmc[6], 3) == pytest.approx(r["lon"], abs=1e-6)
        assert float(rmc[7]) == pytest.approx(r["sog_mps"] * 3600 / 1852, abs=0.006)
        assert abs(_angle_diff(float(rmc[8]), r["cog_deg"])) <= 0.0051
        # $GPGGA,hhmmss.ss,lat,N,lon,E,1,10,0.9,alt,M,0.0,M,,
        assert len(gga) == 15 and gga[6:9] == ["1", "10", "0.9"] and gga[10] == "M" and gga[11:15] == ["0.0", "M", "", ""]
        assert gga[1] == rmc[1] and gga[2:6] == rmc[3:7]
        assert float(gga[9]) == pytest.approx(r["z"], abs=0.0051)
        # $HEHDT,heading,T
        assert len(hdt) == 3 and hdt[2] == "T"
        assert abs(_angle_diff(float(hdt[1]), r["heading_deg"])) <= 0.0051


def test_nav_disabled_writes_no_nmea_but_ownship(write_scenario, tmp_path):
    rec = _render(write_scenario, tmp_path, _scenario(enabled=False))
    assert not (rec / "nav").exists()
    assert len(_jsonl(rec / "ownship.jsonl")) == 251


# ----------------------------------------------------------------------------- errors


def test_zero_errors_reproduce_the_true_motion(write_scenario, tmp_path):
    rec = _render(write_scenario, tmp_path, _scenario(**ZERO_ERRORS))
    own = {r["t"]: r for r in _jsonl(rec / "ownship.jsonl")}
    truth = [r for r in _jsonl(rec / "truth.jsonl") if r["id"] == 0]
    assert len(truth) == 51
    for r in truth:  # truth.jsonl is written from the motion directly, with the same decimals
        o = own[r["t"]]
        assert [o[k] for k in ("lat", "lon", "x", "y", "heading_deg", "cog_deg", "sog_mps")] == \
            [r[k] for k in ("lat", "lon", "x", "y", "heading_deg", "cog_deg", "sog_mps")]
    # and the solution itself is the motion, bit for bit
    world = World(load_scenario(rec / "scenario.yaml"))
    t, c = next(navigation_chunks(world, 10_000))
    poses = world.own_ship.motion.poses(t)
    assert np.array_equal(c["x"], poses.position_m[:, 0]) and np.array_equal(c["y"], poses.position_m[:, 1])
    assert np.array_equal(c["z"], poses.position_m[:, 2])
    assert np.array_equal(c["heading_deg"], poses.heading_deg)
    assert np.array_equal(c["roll_deg"], np.degrees(poses.roll_rad))
    assert np.array_equal(c["pitch_deg"], -np.degrees(poses.pitch_rad))
    v = world.own_ship.motion.velocity_mps(t)
    assert np.array_equal(c["sog_mps"], np.hypot(v[:, 0], v[:, 1]))


def test_default_errors_are_small_and_present(nav_recording):
    own = {r["t"]: r for r in _jsonl(nav_recording / "ownship.jsonl")}
    truth = [r for r in _jsonl(nav_recording / "truth.jsonl") if r["id"] == 0]
    dx = np.array([own[r["t"]]["x"] - r["x"] for r in truth])
    dh = _angle_diff([own[r["t"]]["heading_deg"] for r in truth], [r["heading_deg"] for r in truth])
    assert 0 < np.abs(dx).max() < 5 * np.hypot(0.1, 0.5)
    assert 0 < np.abs(dh).max() < 5 * np.hypot(0.05, 0.1)


def _bin_autocorrelation(e: np.ndarray, samples_per_bin: int, lag_bins: int) -> float:
    """Autocorrelation at ``lag_bins`` of ``e`` averaged in bins of ``samples_per_bin`` samples."""
    b = e[: e.size // samples_per_bin * samples_per_bin].reshape(-1, samples_per_bin).mean(axis=1)
    b = b - b.mean()
    return float(np.dot(b[:-lag_bins], b[lag_bins:]) / np.dot(b, b) * b.size / (b.size - lag_bins))


def test_error_statistics_of_a_long_stationary_run(write_scenario, tmp_path):
    # 20000 s at 50 Hz (1 M samples) with 20 s time constants: 1000 bias correlation times
    tau_s = 20.0
    data = _scenario(position_bias_time_constant_s=tau_s, heading_bias_time_constant_s=tau_s)
    data["duration_s"] = 20_000
    data["environment"]["sea_state"] = 0
    data["own_ship"] = {"position": [59.4377744115633, 10.4716511800410], "heading_deg": 30.0,
                        "motion": {"roll_amplitude_deg": 0, "pitch_amplitude_deg": 0, "heave_amplitude_m": 0}}
    world = World(load_scenario(write_scenario(data)))
    cfg = world.scenario.sensors.nav
    truth = world.own_ship.motion.poses(np.zeros(1))
    parts = list(navigation_chunks(world, 1_500))
    col = {k: np.concatenate([c[k] for _, c in parts]) for k in parts[0][1]}
    assert col["x"].size == 1_000_001
    east, north = col["x"] - truth.position_m[0, 0], col["y"] - truth.position_m[0, 1]
    heading = _angle_diff(col["heading_deg"], 30.0)
    rate = int(cfg.rate_hz)
    for e, white, bias in ((east, cfg.position_noise_m, cfg.position_bias_m),
                           (north, cfg.position_noise_m, cfg.position_bias_m),
                           (heading, cfg.heading_noise_deg, cfg.heading_bias_deg)):
        assert abs(e.mean()) < 0.15 * bias
        assert e.std() == pytest.approx(np.hypot(white, bias), rel=0.06)
        # white part: variance minus lag-1 covariance = white^2 + bias^2 (1 - exp(-dt/T))
        white_var = e.var() - np.mean((e[1:] - e.mean()) * (e[:-1] - e.mean()))
        assert white_var == pytest.approx(white**2 + bias**2 * -np.expm1(-1 / (rate * tau_s)), rel=0.05)
        # bias correlation time: 1 s averages correlate exp(-1) at lag T
        assert _bin_autocorrelation(e, rate, int(tau_s)) == pytest.approx(np.exp(-1.0), abs=0.06)
    # velocity: SOG of a still ship is Rayleigh, E[sog^2] = 2 sd^2
    assert np.sqrt(np.mean(col["sog_mps"] ** 2)) == pytest.approx(np.sqrt(2) * cfg.velocity_noise_mps, rel=0.02)
    assert np.std(col["roll_deg"]) == pytest.approx(cfg.attitude_noise_deg, rel=0.02)
    assert np.std(col["pitch_deg"]) == pytest.approx(cfg.attitude_noise_deg, rel=0.02)
    assert abs(np.corrcoef(col["roll_deg"], col["pitch_deg"])[0, 1]) < 0.01
    assert abs(np.corrcoef(east, north)[0, 1]) < 0.1
    assert np.all((col["heading_deg"] >= 0) & (col["heading_deg"] < 360))
    assert np.all((col["cog_deg"] >= 0) & (col["cog_deg"] < 360))


def test_errors_do_not_depend_on_the_chunk_size():
    cfg = Nav()
    whole = NavErrorModel(cfg, 3).next(1000)
    model = NavErrorModel(cfg, 3)
    parts = [model.next(m) for m in (1, 0, 250, 749)]
    for name in ("east_m", "north_m", "velocity_east_mps", "velocity_north_mps", "heading_deg", "roll_deg", "pitch_deg"):
        assert np.array_equal(np.concatenate([getattr(p, name) for p in parts]), getattr(whole, name)), name
    assert not np.allclose(NavErrorModel(cfg, 4).next(10).east_m, whole.east_m[:10])


def test_the_nmea_subset_is_the_full_solution_at_those_samples(write_scenario):
    world = World(load_scenario(write_scenario(_scenario())))
    full = list(navigation_chunks(world, 64))
    t_full = np.concatenate([t for t, _ in full])
    idx = nmea_indices(world.scenario.duration_s, 50.0, 1.0)
    sub = list(navigation_chunks(world, 100, idx))
    assert np.array_equal(np.concatenate([t for t, _ in sub]), t_full[idx])
    for key in ("lat", "lon", "x", "y", "heading_deg", "cog_deg", "sog_mps", "roll_deg", "pitch_deg"):
        a = np.concatenate([c[key] for _, c in full])[idx]
        b = np.concatenate([c[key] for _, c in sub])
        assert np.allclose(a, b, rtol=0, atol=1e-9), key


def test_same_inputs_same_bytes(write_scenario, tmp_path):
    data = _scenario()
    a = _render(write_scenario, tmp_path, data, "a")
    b = _render(write_scenario, tmp_path, data, "b")
    c = _render(write_scenario, tmp_path, data, "c", "--seed", "8")
    for name in ("ownship.jsonl", "nav/nav.nmea", "nav/nav_plain.nmea"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
        assert (a / name).read_bytes() != (c / name).read_bytes(), name


def test_error_streams_are_independent_of_each_other():
    base = NavErrorModel(Nav(), 5).next(500)
    other = NavErrorModel(dataclasses.replace(Nav(), heading_noise_deg=1.0, velocity_noise_mps=0.0), 5).next(500)
    assert np.array_equal(base.east_m, other.east_m) and np.array_equal(base.roll_deg, other.roll_deg)
    assert not np.array_equal(base.heading_deg, other.heading_deg)
