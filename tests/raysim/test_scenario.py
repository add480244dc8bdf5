"""Scenario loading: strict validation, defaults, resolution and round trips."""

from __future__ import annotations

import copy
import math
import subprocess
import sys

import pytest
import yaml

from raysim.cli import main
from raysim.errors import InputError
from raysim.scenario import describe_markdown, load_scenario, scenario_to_yaml
from tests.conftest import BASE, REPO


def _variant(path_keys, value, base=BASE):
    data = copy.deepcopy(base)
    node = data
    for key in path_keys[:-1]:
        node = node[key]
    if value is _DELETE:
        del node[path_keys[-1]]
    else:
        node[path_keys[-1]] = value
    return data


_DELETE = object()


def test_valid_scenario_loads_with_defaults_filled(write_scenario):
    s = load_scenario(write_scenario(BASE))
    assert s.name == "small"
    assert s.duration_s == 5.0
    assert s.start_time.isoformat() == "2017-06-01T12:00:00+00:00"
    assert s.sensors.lidar.mount.x_m == 1.0 and s.sensors.lidar.mount.z_m == 3.0
    assert s.sensors.radar.spokes == 2048 and s.sensors.radar.samples == 1024
    assert s.sensors.ais.noise.position_bias_time_constant_sec == 20.0
    # derived defaults
    iceberg, buoy = s.obstacles
    assert iceberg.seed is not None and buoy.radius_m is None
    ship, anchored = s.ships
    assert ship.beam_m == pytest.approx(100 / (3.2 + 3.0), abs=0.01)
    assert ship.heading_time_constant_s == 10.0
    assert 240 < ship.heading_deg < 250  # course of the first leg, WSW
    assert anchored.heading_deg == 45.0
    assert s.own_ship.motion.roll_amplitude_deg == 3.0  # sea state 3 table
    assert s.own_ship.route.heading_time_constant_s == 2.0


def test_origin_defaults_to_own_ship_start(write_scenario):
    s = load_scenario(write_scenario(_variant(["origin"], _DELETE)))
    assert (s.origin.lat, s.origin.lon) == (59.43777, 10.47165)


def test_resolved_yaml_round_trips(write_scenario, tmp_path):
    s = load_scenario(write_scenario(BASE))
    text = scenario_to_yaml(s)
    again = load_scenario(write_scenario(text, "resolved.yaml"))
    assert again == s
    assert scenario_to_yaml(again) == text


def test_iceberg_seed_does_not_follow_scenario_seed(write_scenario):
    a = load_scenario(write_scenario(BASE, "a.yaml"))
    b = load_scenario(write_scenario(_variant(["seed"], 99), "b.yaml"))
    assert a.obstacles[0].seed == b.obstacles[0].seed


def test_docs_list_every_key():
    doc = (REPO / "docs" / "scenario.md").read_text(encoding="utf-8")
    table = describe_markdown()
    assert table in doc, "docs/scenario.md is out of date: regenerate with python -m raysim.scenario --doc"


BAD = [
    # (description, mutate, expected key path, words in the message)
    ("unknown top-level key", lambda d: d.update(durration_s=3), "durration_s", "unknown key"),
    ("unknown nested key", lambda d: d["sensors"]["lidar"].update(rotation_rate=10), "sensors.lidar.rotation_rate", "unknown key"),
    ("unknown key in a list item", lambda d: d["ships"][0].update(colour="red"), "ships[0].colour", "unknown key"),
    ("AIS call sign too long", lambda d: d["ships"][0]["ais"].update(call_sign="LAHB5123"), "ships[0].ais.call_sign", "at most 7"),
    ("AIS name off the 6-bit set", lambda d: d["ships"][0]["ais"].update(name="Ødin"), "ships[0].ais.name", "6-bit"),
    ("thesis name and its alias both given",
     lambda d: d.setdefault("sensors", {}).setdefault("ais", {}).update(
         noise={"AIS_SOG_measure_variance_knots2": 1.0, "sog_measure_variance_knots2": 2.0}),
     "sensors.ais.noise.sog_measure_variance_knots2", "given twice (as AIS_SOG_measure_variance_knots2 and as sog_"),
    ("wrong type", lambda d: d.update(duration_s="long"), "duration_s", "must be a number"),
    ("NaN", lambda d: d.update(duration_s=float("nan")), "duration_s", "finite"),
    ("inf", lambda d: d["environment"].update(wind_speed_mps=float("inf")), "environment.wind_speed_mps", "finite"),
    ("latitude out of range", lambda d: d["obstacles"][0].update(position=[95.0, 10.0]), "obstacles[0].position", "latitude"),
    ("longitude out of range", lambda d: d["ships"][0]["waypoints"].append([59.0, 190.0]), "ships[0].waypoints", "longitude"),
    ("negative radius", lambda d: d["obstacles"][0].update(radius_m=-5), "obstacles[0].radius_m", "> 0"),
    ("negative speed", lambda d: d["ships"][0].update(speed_kn=-1), "ships[0].speed_kn", ">= 0"),
    ("MMSI with 8 digits", lambda d: d["ships"][0]["ais"].update(mmsi=25700000), "ships[0].ais.mmsi", "9 digits"),
    ("MMSI with 10 digits", lambda d: d["ships"][0]["ais"].update(mmsi=2570000020), "ships[0].ais.mmsi", "9 digits"),
    ("rpm zero", lambda d: d["sensors"]["radar"].update(rpm=0), "sensors.radar.rpm", "> 0"),
    ("rpm negative", lambda d: d["sensors"]["radar"].update(rpm=-24), "sensors.radar.rpm", "> 0"),
    ("empty waypoint list", lambda d: d["ships"][0].update(waypoints=[]), "ships[0].waypoints", "at least 1"),
    ("empty own-ship route", lambda d: d["own_ship"]["route"].update(waypoints=[]), "own_ship.route.waypoints", "at least 1"),
    ("waypoint not a pair", lambda d: d["ships"][0].update(waypoints=[[59.0]]), "ships[0].waypoints[0]", "2 items"),
    ("boolean as number", lambda d: d.update(duration_s=True), "duration_s", "must be a number"),
    ("float seed", lambda d: d.update(seed=1.5), "seed", "integer"),
    ("bad sea state", lambda d: d["environment"].update(sea_state=9), "environment.sea_state", "<= 6"),
    ("missing mesh file", lambda d: d["obstacles"].append({"name": "Pier", "kind": "mesh", "position": [59.438, 10.47], "mesh": "nope.glb"}), "obstacles[2].mesh", "file not found"),
    ("mesh kind without mesh", lambda d: d["obstacles"].append({"name": "Pier", "kind": "mesh", "position": [59.438, 10.47]}), "obstacles[2].mesh", "required"),
    ("radius on a buoy", lambda d: d["obstacles"][1].update(radius_m=3), "obstacles[1].radius_m", "only applies"),
    ("duplicate names", lambda d: d["ships"][1].update(name="Iceberg_1"), "ships[1].name", "already used"),
    ("duplicate MMSI", lambda d: d["ships"][1].update(ais={"mmsi": 257000002}), "ships[1].ais.mmsi", "already used"),
    ("two own-ship modes", lambda d: d["own_ship"].update(position=[59.43, 10.47]), "own_ship", "only one"),
    ("no own-ship mode", lambda d: d["own_ship"].pop("route"), "own_ship", "needs a route"),
    ("unknown material", lambda d: d["own_ship"].update(material="kryptonite"), "own_ship.material", "unknown material"),
    ("material without a mesh", lambda d: d["ships"][0].update(material="grp"), "ships[0].material", "only applies"),
    ("anchored ship with speed", lambda d: d["ships"][1].update(speed_kn=5), "ships[1].speed_kn", "anchored"),
    ("far away", lambda d: d["ships"][0]["waypoints"].append([61.0, 10.47]), "ships[0].waypoints[2]", "km from the origin"),
    ("bad start time", lambda d: d.update(start_time="yesterday"), "start_time", "ISO 8601"),
    ("bad model", lambda d: d["sensors"]["lidar"].update(model="VLP-16"), "sensors.lidar.model", "one of"),
    ("list instead of mapping", lambda d: d.update(environment=[1, 2]), "environment", "mapping"),
    ("repeated waypoint", lambda d: d["ships"][0]["waypoints"].append(d["ships"][0]["waypoints"][-1]), "ships[0].waypoints", "repeats"),
]


@pytest.mark.parametrize("description,mutate,where,words", BAD, ids=[b[0] for b in BAD])
def test_bad_scenario_is_one_clear_error(description, mutate, where, words, write_scenario):
    data = copy.deepcopy(BASE)
    mutate(data)
    path = write_scenario(data)
    with pytest.raises(InputError) as info:
        load_scenario(path)
    assert info.value.file == str(path)
    assert info.value.where == where, str(info.value)
    assert words in info.value.what, str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "text,where,words",
    [
        ("", "(file)", "empty"),
        ("   \n\n", "(file)", "empty"),
        ("# only a comment\n", "(file)", "holds no scenario"),
        ("name: [unclosed\n", "line 2, column 1", "not valid YAML"),
        ("duration_s: 5\n  bad indent: 3\n", "line 2, column 13", "not valid YAML"),
        ("- a list\n- at the top\n", "(top level)", "mapping"),
        ("just a string\n", "(top level)", "mapping"),
        ("duration_s: .nan\n", "duration_s", "finite"),
        ("!!python/object:os.system {}\n", "line 1, column 1", "not valid YAML"),
    ],
)
def test_unparsable_files(text, where, words, write_scenario):
    path = write_scenario(text)
    with pytest.raises(InputError) as info:
        load_scenario(path)
    assert info.value.where == where
    assert words in info.value.what


def test_missing_scenario_file(tmp_path):
    with pytest.raises(InputError, match="file not found"):
        load_scenario(tmp_path / "nope.yaml")


def _run_cli(args, capsys):
    code = main(args)
    captured = capsys.readouterr()
    return code, captured.err


def test_cli_bad_scenario_exits_2_with_one_line_and_writes_nothing(write_scenario, tmp_path, capsys):
    data = copy.deepcopy(BASE)
    data["ships"][0]["ais"]["mmsi"] = 123
    path = write_scenario(data)
    out = tmp_path / "rec"
    code, err = _run_cli(["render", str(path), "-o", str(out), "--no-progress"], capsys)
    assert code == 2
    assert err.count("\n") == 1
    assert err.startswith(f"error: {path}: ships[0].ais.mmsi: ")
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def test_cli_unreadable_mesh_exits_2_and_writes_nothing(write_scenario, tmp_path, capsys):
    garbage = tmp_path / "broken.stl"
    garbage.write_bytes(b"\x00\x01 definitely not a mesh \xff" * 10)
    data = copy.deepcopy(BASE)
    data["obstacles"].append({"name": "Pier", "kind": "mesh", "position": [59.438, 10.47], "mesh": "broken.stl"})
    path = write_scenario(data)
    out = tmp_path / "rec"
    code, err = _run_cli(["render", str(path), "-o", str(out), "--no-progress"], capsys)
    assert code == 2, err
    assert err.startswith(f"error: {path}: obstacles[2].mesh: ")
    assert err.count("\n") == 1
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize(
    "extra,where",
    [
        (["--duration", "-3"], "--duration"),
        (["--duration", "nan"], "--duration"),
        (["--seed", "x"], "--seed"),
        (["--sensors", "lidar,sonar"], "--sensors"),
        (["--bogus"], "raysim"),
    ],
)
def test_cli_bad_options(extra, where, write_scenario, tmp_path, capsys):
    path = write_scenario(BASE)
    code, err = _run_cli(["render", str(path), "-o", str(tmp_path / "rec"), *extra], capsys)
    assert code == 2
    assert err.startswith(f"error: command line: {where}")
    assert err.count("\n") == 1
    assert not (tmp_path / "rec").exists()


def test_cli_refuses_a_foreign_nonempty_output_dir(write_scenario, tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.docx").write_text("precious")
    code, err = _run_cli(["render", str(write_scenario(BASE)), "-o", str(out)], capsys)
    assert code == 2 and "not empty" in err
    assert sorted(p.name for p in out.iterdir()) == ["thesis.docx"]


def test_console_script_prints_no_traceback(write_scenario, tmp_path):
    path = write_scenario("duration_s: [\n")
    result = subprocess.run([sys.executable, "-m", "raysim.cli", "render", str(path), "-o", str(tmp_path / "o")],
                            capture_output=True, text=True, cwd=REPO)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert result.stderr.startswith(f"error: {path}: line ")
    assert len(result.stderr.strip().splitlines()) == 1


def test_safe_load_only(write_scenario):
    """A YAML tag that would construct Python objects is rejected, not executed."""
    path = write_scenario("name: !!python/object/apply:os.getcwd []\n")
    with pytest.raises(InputError, match="not valid YAML"):
        load_scenario(path)


def test_numbers_accept_ints_and_reject_huge_values(write_scenario):
    s = load_scenario(write_scenario(_variant(["duration_s"], 7)))
    assert isinstance(s.duration_s, float) and s.duration_s == 7.0
    with pytest.raises(InputError, match="<= 86400"):
        load_scenario(write_scenario(_variant(["duration_s"], 1e9)))
    assert math.isfinite(s.duration_s)


def test_all_committed_scenarios_load():
    for path in sorted((REPO / "scenarios").glob("*.yaml")):
        s = load_scenario(path)
        assert s.duration_s > 0, path
        yaml.safe_load(scenario_to_yaml(s))
