"""Importing the 2017 HIL simulator's configuration files."""

from __future__ import annotations

import shutil

import pytest
import yaml

from raysim.cli import main
from raysim.errors import InputError
from raysim.geodesy import LocalFrame
from raysim.hilsim import import_hilsim
from raysim.scenario import load_scenario
from tests.conftest import REPO

# The thesis's busy-open-sea configuration files (its appendix B, Listings B.1-B.3), kept here so these tests never skip.
THESIS = REPO / "tests" / "data" / "hilsim_busy_open_sea"
FILES = [THESIS / "obstacle_params.yaml", THESIS / "sensor_params.yaml", THESIS / "dynamics_params.yaml"]

BUSY_ROUTE = "59.437774,10.471651;59.438762,10.472885;59.437281,10.477643;59.438851,10.479229;59.441185,10.476057;59.441185,10.469007"


def _copy_thesis(tmp_path):
    for f in FILES:
        shutil.copy(f, tmp_path / f.name)
    return [tmp_path / f.name for f in FILES]


def test_thesis_files_convert_with_decimal_commas_and_noise_names():
    scenario, comments = import_hilsim(*FILES)
    bergs = scenario["obstacles"]
    assert len(bergs) == 14 and all(b["kind"] == "iceberg" and b["radius_m"] == 15 for b in bergs)
    assert bergs[0] == {"name": "Iceberg_1", "kind": "iceberg", "position": [59.436573, 10.470952], "radius_m": 15.0}
    ships = {s["name"]: s for s in scenario["ships"]}
    assert ships["support_vessel"]["length_m"] == 30 and ships["support_vessel"]["speed_kn"] == 1
    assert ships["support_vessel"]["waypoints"][0] == [59.440308, 10.468943]
    assert len(ships["support_vessel"]["waypoints"]) == 4
    assert ships["research_ship"]["waypoints"] == [[59.438875, 10.483932], [59.432853, 10.460502]]
    assert ships["research_ship"]["ais"]["mmsi"] == 257000002
    noise = scenario["sensors"]["ais"]["noise"]
    assert noise["position_measure_variance_m2"] == 5 and noise["cog_bias_time_constant_sec"] == 10
    assert noise["rot_measure_variance_deg2_pr_min2"] == 2000 and noise["sog_bias_variance_knots2"] == 0.1
    assert scenario["sensors"]["lidar"]["range_max_m"] == 100 and scenario["sensors"]["radar"]["range_m"] == 1852
    assert scenario["origin"] == {"lat": 59.4377744115633, "lon": 10.4716511800410}
    assert scenario["environment"] == {"sea_state": 4, "wind_speed_mps": 10.0, "wind_from_deg": 90.0}
    assert any("radar_position_measure_variance_m2: 10" in c for c in comments)
    assert any("current_speed: 0.5" in c for c in comments)


def test_committed_busy_open_sea_is_exactly_the_import(tmp_path, capsys):
    files = _copy_thesis(tmp_path)
    out = tmp_path / "busy_open_sea.yaml"
    code = main(["import-hilsim", *map(str, files), "-o", str(out), "--route", BUSY_ROUTE])
    assert code == 0, capsys.readouterr().err
    assert out.read_text() == (REPO / "scenarios" / "busy_open_sea.yaml").read_text()


def test_busy_open_sea_takes_odin_through_the_field_past_both_ships():
    import numpy as np

    from raysim.world import World

    world = World(load_scenario(REPO / "scenarios" / "busy_open_sea.yaml"))
    t = np.arange(0.0, 300.0, 1.0)
    own = world.own_ship.motion.poses(t).position_m[:, :2]
    assert world.own_ship.length_m == pytest.approx(10.9, abs=0.6)
    own3 = world.own_ship.motion.poses(t).position_m
    for o in world.objects[1:]:
        poses = o.motion.poses(t)
        distance = np.hypot(*(own - poses.position_m[:, :2]).T)
        if o.kind == "ship":
            assert distance.min() < 100.0, o.name  # within LiDAR range at some point
        # no collision: the own ship stays 10 m clear of each object's footprint box
        body = poses.to_body(own3)
        clear = (np.abs(body[:, 0]) > o.length_m / 2 + 10) | (np.abs(body[:, 1]) > o.beam_m / 2 + 10)
        assert clear.all(), o.name
    bergs_close = sum(np.hypot(*(own - o.motion.poses(t).position_m[:, :2]).T).min() < 100 for o in world.objects if o.kind == "iceberg")
    assert bergs_close >= 4


@pytest.mark.parametrize(
    "which,text,where",
    [
        (0, "fixed_obstacles: {A: 'RADIUS=15 COORD=10.47'}\n", "fixed_obstacles.A"),
        (0, "fixed_obstacles: {A: 'RADIUS=15 COORD=10,4/95,0'}\n", "fixed_obstacles.A"),
        (0, "fixed_obstacles: {A: 'RADIUS=x COORD=10,4/59,4'}\n", "fixed_obstacles.A"),
        (0, "ships: {S: 'LENGTH=30 SpeedInKnots=1'}\n", "ships.S"),
        (0, "ships: {S: 'LENGTH=30 Colour=red WP=10,4/59,4'}\n", "ships.S"),
        (0, "obstacles: {}\n", "obstacles"),
        (1, "AIS_range_m: lots\n", "AIS_range_m"),
        (1, "AIS_rnage_m: 5\n", "AIS_rnage_m"),
        (2, "wave_hieght: 2\n", "wave_hieght"),
        (0, "", "(file)"),
        (0, "a: [\n", "line 2, column 1"),
    ],
)
def test_bad_thesis_files_exit_2_with_the_place(which, text, where, tmp_path, capsys):
    files = _copy_thesis(tmp_path)
    files[which].write_text(text)
    out = tmp_path / "out.yaml"
    code = main(["import-hilsim", *map(str, files), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith(f"error: {files[which]}: {where}: "), err
    assert err.count("\n") == 1
    assert not out.exists()


def test_imported_scenario_without_route_lies_still_at_the_start(tmp_path):
    files = _copy_thesis(tmp_path)
    scenario, _ = import_hilsim(*files)
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(scenario))
    s = load_scenario(path)
    assert s.own_ship.position == (59.4377744115633, 10.4716511800410)
    frame = LocalFrame(s.origin.lat, s.origin.lon)
    x, y = frame.to_local(*s.own_ship.position)
    assert abs(x) < 1e-6 and abs(y) < 1e-6


def test_missing_dynamics_and_no_route_is_an_error(tmp_path):
    with pytest.raises(InputError, match="no start position"):
        import_hilsim(FILES[0], FILES[1])
