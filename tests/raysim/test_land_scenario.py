"""Scenarios with land (issue 20): routes, starts and objects on land are refused with one line and exit 2."""

from __future__ import annotations

import pytest
import yaml

from raysim.cli import main
from tests.raysim.helpers import land_file, latlon, scenario

ISLAND = [(-50.0, 100.0), (50.0, 100.0), (50.0, 200.0), (-50.0, 200.0)]


def refused(tmp_path, capsys, data):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    assert main(["render", str(path), "-o", str(out), "--sensors", "nav", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {path}: ")
    assert not out.exists()
    return err[0]


def with_island(tmp_path, **kw):
    data = scenario(tmp_path, **kw)
    data["land"] = [{"name": "island", "file": land_file(tmp_path, "island", ISLAND, 20.0)}]
    return data


def test_a_ship_route_crossing_land_is_refused(tmp_path, capsys):
    ship = {"name": "ferry", "speed_kn": 10.0, "waypoints": [latlon(-200.0, 150.0), latlon(200.0, 150.0)]}
    line = refused(tmp_path, capsys, with_island(tmp_path, ships=[ship]))
    assert "ships[0].waypoints: the leg from waypoint 0 to 1 crosses land 'island'" in line


def test_the_own_ship_route_crossing_land_is_refused(tmp_path, capsys):
    own = {"route": {"waypoints": [latlon(0.0, 0.0), latlon(0.0, 400.0)], "speed_kn": 5.0}}
    line = refused(tmp_path, capsys, with_island(tmp_path, own=own))
    assert "own_ship.route.waypoints: the leg from waypoint 0 to 1 crosses land" in line


def test_an_object_inside_land_and_a_start_on_land_are_refused(tmp_path, capsys):
    berg = {"name": "berg", "kind": "iceberg", "position": latlon(0.0, 150.0)}
    assert "obstacles[0].position: is on land 'island'" in refused(tmp_path, capsys, with_island(tmp_path, obstacles=[berg]))
    own = {"position": latlon(10.0, 120.0), "heading_deg": 0}
    assert "own_ship.position: is on land" in refused(tmp_path, capsys, with_island(tmp_path, own=own))


def test_a_land_name_must_be_unique_among_all_objects(tmp_path, capsys):
    data = with_island(tmp_path, ships=[{"name": "island", "waypoints": [latlon(300.0, 0.0)]}])
    assert "land[0].name: name 'island' is already used by ships[0]" in refused(tmp_path, capsys, data)


@pytest.mark.parametrize("text, what", [
    ("{", "not JSON"),
    ('{"type": "Point", "coordinates": [10.47, 59.43]}', "Point"),
    ('{"type": "Polygon", "coordinates": [[[10.47, 59.43], [10.48, 59.43], [10.48, 59.44]]]}', "4"),
])
def test_a_bad_geojson_file_is_refused_naming_the_file(tmp_path, capsys, text, what):
    data = scenario(tmp_path)
    (tmp_path / "bad.geojson").write_text(text)
    data["land"] = [{"name": "bad", "file": "bad.geojson"}]
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["render", str(path), "-o", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {tmp_path / 'bad.geojson'}: ") and what in err[0], err
    assert not (tmp_path / "out").exists()
