"""Recording basics: scenario.yaml, manifest.json, truth.jsonl, ownship.jsonl; determinism; all-or-nothing."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from pyproj import Geod

from raysim import render as render_module
from raysim.cli import main
from raysim.scenario import load_scenario
from tests.conftest import BASE

CONTRACT_TRUTH_KEYS = ["t", "id", "name", "kind", "lat", "lon", "x", "y", "centre_lat", "centre_lon", "centre_x", "centre_y",
                       "heading_deg", "cog_deg", "sog_mps", "length_m", "beam_m", "height_m", "ais", "mmsi"]
REPO = Path(__file__).resolve().parents[2]
CONTRACT_OWNSHIP_KEYS = ["t", "lat", "lon", "x", "y", "z", "heading_deg", "roll_deg", "pitch_deg", "cog_deg", "sog_mps"]


def _render(path, out, *extra):
    code = main(["render", str(path), "-o", str(out), "--no-progress", *extra])
    assert code == 0
    return out


def _lines(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


@pytest.fixture
def recording(write_scenario, tmp_path):
    return _render(write_scenario(BASE), tmp_path / "rec")


def test_recording_holds_the_contract_files(recording):
    names = sorted(p.name for p in recording.iterdir())
    # LiDAR and radar are off in this scenario; AIS and navigation are on by default
    assert names == ["ais", "manifest.json", "map.png", "nav", "ownship.jsonl", "rosbag", "scenario.yaml", "truth.jsonl"]
    assert (recording / "ais" / "ais.nmea").is_file()
    manifest = json.loads((recording / "manifest.json").read_text())
    assert manifest["seed"] == 7 and manifest["duration_s"] == 5.0 and manifest["start_time"] == "2017-06-01T12:00:00Z"
    assert manifest["counts"]["truth.jsonl"] == 5 * 51 and manifest["counts"]["ownship.jsonl"] == 251
    assert {"numpy", "open3d", "python", "raysim"} <= set(manifest["versions"])


def test_truth_has_every_object_every_tenth_of_a_second(recording):
    rows = _lines(recording / "truth.jsonl")
    assert [list(r) for r in rows[:1]] == [CONTRACT_TRUTH_KEYS]
    assert len(rows) == 51 * 5
    times = sorted({r["t"] for r in rows})
    assert np.allclose(times, np.arange(51) / 10)
    kinds = {r["id"]: (r["name"], r["kind"]) for r in rows}
    assert kinds == {0: ("odin", "ownship"), 1: ("Iceberg_1", "iceberg"), 2: ("Buoy_1", "buoy"),
                     3: ("research_ship", "ship"), 4: ("anchored", "ship")}
    ship = [r for r in rows if r["id"] == 3]
    assert ship[0]["ais"] is True and ship[0]["mmsi"] == 257000002
    assert ship[0]["length_m"] == 100.0 and ship[0]["sog_mps"] == pytest.approx(10 * 1852 / 3600, abs=1e-3)
    anchored = [r for r in rows if r["id"] == 4]
    assert anchored[-1]["sog_mps"] == 0.0 and anchored[-1]["heading_deg"] == 45.0 and anchored[-1]["mmsi"] is None
    berg = [r for r in rows if r["id"] == 1][0]
    assert berg["height_m"] == pytest.approx(8.0, abs=0.01)
    assert berg["lat"] == pytest.approx(59.436573, abs=1e-9) and berg["lon"] == pytest.approx(10.470952, abs=1e-9)


@pytest.mark.parametrize("heading_deg, east_m, north_m", [(180.0, 0.0, -30.0), (90.0, 30.0, 0.0), (45.0, 21.2132, 21.2132)])
def test_truth_centre_is_the_middle_of_what_stands_above_water(write_scenario, tmp_path, heading_deg, east_m, north_m):
    """meshes/pier.glb has its origin at its landward end (above water: x 0..60 m, y -4.3..4.3 m), so its centre
    lies 30 m from the origin along its heading; the truth box (length x beam) stands about that centre."""
    data = copy.deepcopy(BASE)
    data["duration_s"] = 1
    data["obstacles"] = [{"name": "pier", "kind": "mesh", "position": [59.4390, 10.4700], "heading_deg": heading_deg,
                          "mesh": str(REPO / "meshes" / "pier.glb"), "material": "concrete"}]
    data["ships"] = [{"name": "anchored", "length_m": 20, "waypoints": [[59.4380, 10.4700]], "heading_deg": 45}]
    rows = _lines(_render(write_scenario(data), tmp_path / "rec") / "truth.jsonl")
    pier = [r for r in rows if r["name"] == "pier"][0]
    assert (pier["length_m"], pier["beam_m"]) == (60.0, 8.6)
    assert pier["centre_x"] - pier["x"] == pytest.approx(east_m, abs=2e-3)
    assert pier["centre_y"] - pier["y"] == pytest.approx(north_m, abs=2e-3)
    azimuth, _, distance = Geod(ellps="WGS84").inv(pier["lon"], pier["lat"], pier["centre_lon"], pier["centre_lat"])
    assert distance == pytest.approx(30.0, abs=0.01) and azimuth % 360.0 == pytest.approx(heading_deg, abs=0.05)
    ship = [r for r in rows if r["name"] == "anchored"][0]  # a generated hull is centred on its origin
    assert np.hypot(ship["centre_x"] - ship["x"], ship["centre_y"] - ship["y"]) < 0.5


def test_ship_in_truth_moves_along_the_geodesic_at_its_speed(write_scenario, tmp_path):
    data = copy.deepcopy(BASE)
    data["duration_s"] = 60
    data["ships"] = [{"name": "north", "length_m": 50, "speed_kn": 10, "waypoints": [[59.4300, 10.4700], [59.4600, 10.4700]]}]
    rec = _render(write_scenario(data), tmp_path / "rec")
    rows = [r for r in _lines(rec / "truth.jsonl") if r["name"] == "north"]
    first, last = rows[0], rows[-1]
    assert last["t"] == 60.0
    _, _, distance = Geod(ellps="WGS84").inv(first["lon"], first["lat"], last["lon"], last["lat"])
    assert distance == pytest.approx(308.667, abs=0.02)
    assert last["heading_deg"] == pytest.approx(0.0, abs=0.02) or last["heading_deg"] == pytest.approx(360.0, abs=0.02)


def test_ownship_at_the_nav_rate_with_wave_motion(recording):
    rows = _lines(recording / "ownship.jsonl")
    assert list(rows[0]) == CONTRACT_OWNSHIP_KEYS
    assert len(rows) == 251  # 50 Hz for 5 s
    assert np.allclose(np.diff([r["t"] for r in rows]), 0.02)
    roll = np.array([r["roll_deg"] for r in rows])
    z = np.array([r["z"] for r in rows])
    # sea state 3: 3 deg roll amplitude, plus the navigation's attitude noise (0.02 deg sd; test_nav.py)
    assert 1.0 < np.abs(roll).max() <= 3.0 + 5 * 0.02
    assert np.abs(z).max() <= 0.3 + 1e-6  # heave carries no navigation error
    assert rows[0]["sog_mps"] == pytest.approx(8 * 1852 / 3600, abs=5 * 0.02)


def test_same_seed_same_bytes_other_seed_other_motion(write_scenario, tmp_path):
    path = write_scenario(BASE)
    a = _render(path, tmp_path / "a")
    b = _render(path, tmp_path / "b")
    c = _render(path, tmp_path / "c", "--seed", "8")
    for name in ("truth.jsonl", "ownship.jsonl", "scenario.yaml"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    assert (a / "ownship.jsonl").read_bytes() != (c / "ownship.jsonl").read_bytes()  # wave phases follow the seed
    ma, mb = (json.loads((d / "manifest.json").read_text()) for d in (a, b))
    ma.pop("wall_time_s"), mb.pop("wall_time_s")
    assert ma == mb


def test_resolved_scenario_renders_the_same_recording(recording, tmp_path):
    again = _render(recording / "scenario.yaml", tmp_path / "again")
    for name in ("truth.jsonl", "ownship.jsonl", "scenario.yaml"):
        assert (recording / name).read_bytes() == (again / name).read_bytes(), name


def test_rerender_replaces_an_old_recording(write_scenario, tmp_path):
    path = write_scenario(BASE)
    out = _render(path, tmp_path / "rec")
    _render(path, out, "--duration", "2")
    assert json.loads((out / "manifest.json").read_text())["duration_s"] == 2.0
    assert len(_lines(out / "truth.jsonl")) == 21 * 5
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_a_failing_run_leaves_nothing_behind(write_scenario, tmp_path, monkeypatch):
    def broken(ctx):
        (ctx.out_dir / "lidar").mkdir()
        (ctx.out_dir / "lidar" / "half.npz").write_bytes(b"half")
        raise RuntimeError("sensor crashed")

    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "lidar", broken)
    data = copy.deepcopy(BASE)
    data["sensors"]["lidar"]["enabled"] = True
    with pytest.raises(RuntimeError):
        render_module.render(load_scenario(write_scenario(data)), tmp_path / "rec", progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def test_trajectory_csv_own_ship(write_scenario, tmp_path):
    csv = tmp_path / "track.csv"
    t = np.arange(0.0, 10.5, 0.5)
    lines = ["t_s,lat,lon,heading_deg,roll_deg,pitch_deg,heave_m"]
    lines += [f"{ti},{59.43 + ti * 1e-5:.8f},10.47,0.0,{2 * np.sin(ti):.4f},1.0,0.1" for ti in t]
    csv.write_text("\n".join(lines) + "\n")
    data = copy.deepcopy(BASE)
    data["own_ship"] = {"trajectory_csv": "track.csv"}
    data["sensors"]["nav"] = {"position_noise_m": 0, "position_bias_m": 0, "velocity_noise_mps": 0,
                              "heading_noise_deg": 0, "heading_bias_deg": 0, "attitude_noise_deg": 0}  # the truth
    rec = _render(write_scenario(data), tmp_path / "rec")
    rows = _lines(rec / "ownship.jsonl")
    at5 = [r for r in rows if r["t"] == 5.0][0]
    assert at5["lat"] == pytest.approx(59.43005, abs=1e-8)
    assert at5["pitch_deg"] == pytest.approx(1.0, abs=1e-6) and at5["z"] == pytest.approx(0.1, abs=1e-6)
    assert at5["roll_deg"] == pytest.approx(2 * np.sin(5.0), abs=1e-3)


@pytest.mark.parametrize(
    "content,where",
    [
        ("t_s,lat,lon\n0,59,10\n1,59,10\n", "line 1"),
        ("t_s,lat,lon,heading_deg\n0,59,10,0\n0,59,10,0\n", "line 3"),
        ("t_s,lat,lon,heading_deg\n0,59,10,0\n1,59,abc,0\n", "line 3"),
        ("t_s,lat,lon,heading_deg\n0,59,10,0\n1,59,nan,0\n", "line 3"),
        ("t_s,lat,lon,heading_deg,speed\n0,59,10,0,1\n1,59,10,0,1\n", "line 1"),
        ("", "(file)"),
        ("t_s,lat,lon,heading_deg\n0,59.43,10.47,0\n3,59.43,10.47,0\n", "own_ship.trajectory_csv"),
    ],
)
def test_bad_trajectory_csv(content, where, write_scenario, tmp_path, capsys):
    csv = tmp_path / "track.csv"
    csv.write_text(content)
    data = copy.deepcopy(BASE)
    data["own_ship"] = {"trajectory_csv": "track.csv"}
    path = write_scenario(data)
    code = main(["render", str(path), "-o", str(tmp_path / "rec")])
    err = capsys.readouterr().err
    assert code == 2
    assert f": {where}: " in err and err.count("\n") == 1, err
    assert not (tmp_path / "rec").exists()


def test_map_shows_the_run_from_above(recording):
    from PIL import Image

    from raysim.recording.map_picture import COLOURS

    image = np.asarray(Image.open(recording / "map.png").convert("RGB"))
    assert image.shape == (1000, 1000, 3)
    for kind in ("ownship", "ship", "iceberg", "buoy"):  # every kind of object of the scenario is drawn
        assert np.all(image == np.array(COLOURS[kind]), axis=-1).sum() > 5, kind
