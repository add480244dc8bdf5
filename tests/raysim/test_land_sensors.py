"""Land seen by the sensors through the ray engine (issue 20): coast faces at their range, shadow behind islands."""

from __future__ import annotations

import glob
import json

import numpy as np
import pytest
import yaml

from groundfloor import hdl32e
from raysim.cli import main
from raysim.materials import material_index
from raysim.scenario import load_scenario
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarRenderer
from raysim.world import World
from tests.raysim.helpers import land_file, latlon, scenario

#: A ship sailing east 60 m north of the own ship, behind an island 25-45 m north and 15 m either side of north
SHIP_Y_M, SHIP_SPEED_MPS, SHIP_START_X_M = 60.0, 14.0, -70.0
ISLAND = [(-15.0, 25.0), (15.0, 25.0), (15.0, 45.0), (-15.0, 45.0)]


def write(tmp_path, data, name):
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def render_lidar(tmp_path, data, name):
    out = tmp_path / name
    assert main(["render", str(write(tmp_path, data, name)), "-o", str(out), "--sensors", "lidar", "--no-progress"]) == 0
    return out, [dict(np.load(f)) for f in sorted(glob.glob(str(out / "lidar" / "sweeps" / "*.npz")))]


def test_lidar_ranges_a_vertical_coast_face_within_2_cm(tmp_path):
    coast = land_file(tmp_path, "coast", [(-150.0, 40.0), (150.0, 40.0), (150.0, 240.0), (-150.0, 240.0)], 12.0)
    data = scenario(tmp_path)
    data["land"] = [{"name": "coast", "file": coast}]
    out, sweeps = render_lidar(tmp_path, data, "coast")
    manifest = json.loads((out / "manifest.json").read_text())
    land = [o for o in manifest["objects"] if o["kind"] == "land"]
    assert [o["name"] for o in land] == ["coast"]
    land_id = land[0]["id"]
    chart = json.loads((out / "land.geojson").read_text())  # the recording carries its own chart
    assert [f["properties"]["id"] for f in chart["features"]] == [land_id]
    on = [d["object_id"] == land_id for d in sweeps]
    pts = np.concatenate([np.stack([d["x"], d["y"], d["z"]], 1)[m] for d, m in zip(sweeps, on)]).astype(float)
    dsr = np.argsort(hdl32e.RING)[np.concatenate([d["ring"][m] for d, m in zip(sweeps, on)])]
    assert pts.shape[0] > 1000
    # the coast face is the plane 40 m ahead (north; the own ship heads north): range along each beam against it
    beam = pts - np.stack([np.zeros(len(dsr)), np.zeros(len(dsr)), hdl32e.Z_OFFSET_M[dsr]], 1)
    measured = np.linalg.norm(beam, axis=1)
    residual = measured - 40.0 * measured / beam[:, 0]
    assert abs(residual.mean()) < 0.002
    assert np.quantile(np.abs(residual), 0.95) < 0.02
    # land is in the manifest, not in truth's epochs
    names = {json.loads(line)["name"] for line in (out / "truth.jsonl").read_text().splitlines()}
    assert "coast" not in names


def radar_renderer(tmp_path, data, name):
    data["sensors"] = {"lidar": {"enabled": False},
                       "radar": {"spokes": 1024, "samples": 512, "range_m": 600.0, "rpm": 48.0, "mount": {"z_m": 4.0}}}
    world = World(load_scenario(write(tmp_path, data, name)))
    return RadarRenderer(world, CarrierScene(world.scene_objects(), carrier_id=0, sea_material=material_index("sea")))


def test_radar_paints_the_coast_at_its_range_and_nothing_behind_a_higher_island(tmp_path):
    island = land_file(tmp_path, "island", [(-80.0, 250.0), (80.0, 250.0), (80.0, 300.0), (-80.0, 300.0)], 30.0)
    coast = land_file(tmp_path, "coast", [(-600.0, 450.0), (600.0, 450.0), (600.0, 900.0), (-600.0, 900.0)], 10.0)
    data = scenario(tmp_path, duration=2.0)
    data["land"] = [{"name": "island", "file": island}, {"name": "coast", "file": coast}]
    r = radar_renderer(tmp_path, data, "radar_land")
    rev = r.revolution(0)
    rng = r.range_m
    az = (np.arange(r.spokes) * 360.0 / r.spokes + 180.0) % 360.0 - 180.0
    behind = np.abs(az) <= 10.0  # the island spans +-17.7 deg
    open_coast = np.abs(az - 30.0) <= 4.0  # the coast in the open, 520 m along 30 deg
    # the island's face at 250 m paints on every spoke in front of it, and is the first hit there
    assert (rev.echo[behind][:, np.abs(rng - 250.0) <= 3.0].max(axis=1) >= 8).all()
    assert np.all(np.abs(rev.first_hit_m[behind] - 250.0 / np.cos(np.radians(az[behind]))) < 3.0)
    # the coast paints at its range where the island does not hide it
    assert (rev.echo[open_coast][:, (rng >= 515.0) & (rng <= 530.0)].max(axis=1) >= 8).mean() > 0.9
    # behind the island the coast paints nothing of its own: what remains there is the open coast's sidelobes
    shadow_db = 10 * np.log10(rev.target_snr[behind][:, (rng > 460.0) & (rng < 590.0)].max() + 1e-12)
    lit_db = 10 * np.log10(rev.target_snr[open_coast][:, (rng > 515.0) & (rng < 530.0)].max())
    assert shadow_db < lit_db - 30.0


def ship_x_m(t_s):
    return SHIP_START_X_M + SHIP_SPEED_MPS * np.asarray(t_s)


def ship_behind_island(tmp_path):
    island = land_file(tmp_path, "island", ISLAND, 12.0)
    ship = {"name": "crosser", "length_m": 10.0, "speed_kn": SHIP_SPEED_MPS / 0.514444,
            "waypoints": [latlon(SHIP_START_X_M, SHIP_Y_M), latlon(SHIP_START_X_M + 400.0, SHIP_Y_M)]}
    data = scenario(tmp_path, ships=[ship], duration=10.0)
    data["land"] = [{"name": "island", "file": island}]
    return data


def test_a_ship_behind_an_island_is_absent_from_the_lidar_while_hidden_and_present_after(tmp_path):
    out, sweeps = render_lidar(tmp_path, ship_behind_island(tmp_path), "hidden")
    ids = {o["name"]: o["id"] for o in json.loads((out / "manifest.json").read_text())["objects"]}
    ship = ids["crosser"]
    hidden = visible = 0
    for d in sweeps:
        x = ship_x_m([d["time"].min(), d["time"].max()]) if "time" in d else None
        if x is None:
            pytest.skip("sweeps carry no time")
        seen = bool(np.any(d["object_id"] == ship))
        if np.all(np.abs(x) < 28.0):  # behind the island (it spans +-31 deg; the ship is 10 m long)
            assert not seen
            hidden += 1
        elif np.all((np.abs(x) > 45.0) & (np.abs(x) < 70.0)):  # clear of it, within the LiDAR's 100 m
            assert seen
            visible += 1
    assert hidden >= 30 and visible >= 10


def test_a_ship_behind_an_island_is_absent_from_the_radar_object_list_while_hidden(tmp_path):
    r = radar_renderer(tmp_path, ship_behind_island(tmp_path), "hidden_radar")
    ship = next(o.object_id for o in r.world.objects if o.name == "crosser")
    hidden = visible = 0
    for k in range(r.n_revolutions):
        rev = r.revolution(k)
        x = ship_x_m(rev.time[[0, -1]])
        seen = ship in set(rev.object_id.tolist())
        if np.all(np.abs(x) < 28.0):
            assert not seen
            hidden += 1
        elif np.all(np.abs(x) > 45.0):
            assert seen
            visible += 1
    assert hidden >= 2 and visible >= 2
