"""Helpers shared by the raysim tests: a local frame, box meshes and small scenarios.

(Test modules import these from here, never from each other.)
"""

from __future__ import annotations

from pathlib import Path

import trimesh
import yaml

from raysim.geodesy import LocalFrame

ORIGIN = (59.43, 10.47)
FRAME = LocalFrame(*ORIGIN)

#: Seeds of the Monte-Carlo batch tests; the tiny scenario's own seed is the first.
BATCH_SEEDS = (11, 12)


def latlon(x_m: float, y_m: float) -> list[float]:
    """[lat, lon] of a point x_m east, y_m north of :data:`ORIGIN`."""
    lat, lon = FRAME.to_geodetic(x_m, y_m)
    return [float(lat), float(lon)]


def box_file(tmp_path, name: str, size_m, centre_m=(0.0, 0.0, 0.0)) -> str:
    """A box mesh in the body frame, written as STL."""
    mesh = trimesh.creation.box(extents=size_m)
    mesh.apply_translation(centre_m)
    path = tmp_path / f"{name}.stl"
    mesh.export(path)
    return path.name


def scenario(tmp_path, obstacles=(), ships=(), own=None, lidar=None, duration=0.25, environment=None):
    """A LiDAR test scenario: a still own ship at the origin, calm sea, the LiDAR 3 m up."""
    data = {
        "name": "lidar_test",
        "duration_s": duration,
        "seed": 3,
        "origin": {"lat": ORIGIN[0], "lon": ORIGIN[1]},
        "environment": environment or {"sea_state": 0, "wind_speed_mps": 0},
        "own_ship": own or {"position": latlon(0, 0), "heading_deg": 0,
                             "motion": {"roll_amplitude_deg": 0, "pitch_amplitude_deg": 0, "heave_amplitude_m": 0}},
        "sensors": {"lidar": {"mount": {"x_m": 0.0, "z_m": 3.0}, **(lidar or {})}},
        "obstacles": list(obstacles),
        "ships": list(ships),
    }
    return data


def tiny_scenario(folder: Path) -> Path:
    """6 s: a berg at 60 m (LiDAR and radar), an AIS ferry at 300 m, a mesh buoy; small radar sweeps."""
    folder.mkdir(parents=True, exist_ok=True)
    box_file(folder, "buoy", (3.0, 3.0, 3.0), (0.0, 0.0, 1.0))
    (folder / "broken.obj").write_text("this is not a mesh\n", encoding="utf-8")
    data = {
        "name": "batch_test", "duration_s": 6.0, "seed": BATCH_SEEDS[0],
        "origin": {"lat": ORIGIN[0], "lon": ORIGIN[1]},
        "environment": {"sea_state": 1, "wind_speed_mps": 3},
        "own_ship": {"position": latlon(0, 0), "heading_deg": 0},
        "sensors": {"radar": {"spokes": 512, "samples": 512, "range_m": 926}},
        "obstacles": [{"name": "berg", "kind": "iceberg", "position": latlon(20, 60), "radius_m": 8, "height_m": 5},
                      {"name": "buoy", "kind": "mesh", "mesh": "buoy.stl", "position": latlon(-30, 80)}],
        "ships": [{"name": "ferry", "speed_kn": 8, "length_m": 40, "ais": {"mmsi": 257000009},
                   "waypoints": [latlon(-200, 300), latlon(400, 300)]}],
    }
    path = folder / "tiny.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def land_file(tmp_path, name: str, corners_xy_m, height_m: float | None = None, material: str | None = None) -> str:
    """A GeoJSON file of one polygon given by its corners (x east, y north of :data:`ORIGIN`, m); returns its name."""
    import json

    ring = [[latlon(x, y)[1], latlon(x, y)[0]] for x, y in corners_xy_m]
    ring.append(ring[0])
    properties = {k: v for k, v in (("height_m", height_m), ("material", material)) if v is not None}
    feature = {"type": "Feature", "properties": properties, "geometry": {"type": "Polygon", "coordinates": [ring]}}
    path = tmp_path / f"{name}.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}), encoding="utf-8")
    return path.name
