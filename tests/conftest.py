"""Shared fixtures: small scenario files written into tmp_path."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

REPO = Path(__file__).resolve().parents[1]

#: A small valid scenario (the example scenario of docs/contracts.md, shortened).
BASE = {
    "name": "small",
    "start_time": "2017-06-01T12:00:00Z",
    "duration_s": 5,
    "seed": 7,
    "origin": {"lat": 59.4377744115633, "lon": 10.4716511800410},
    "environment": {"sea_state": 3, "wind_speed_mps": 10, "wind_from_deg": 90},
    "own_ship": {
        "length_m": 10.9,
        "beam_m": 3.5,
        "route": {"speed_kn": 8, "waypoints": [[59.43777, 10.47165], [59.4400, 10.4750]]},
    },
    # sensors off: these tests are about the foundation; sensor tests switch theirs on
    "sensors": {"lidar": {"enabled": False, "rotation_hz": 10, "mount": {"x_m": 1.0, "z_m": 3.0}},
                "radar": {"enabled": False, "rpm": 24}},
    "obstacles": [
        {"name": "Iceberg_1", "kind": "iceberg", "position": [59.436573, 10.470952], "radius_m": 15, "height_m": 8},
        {"name": "Buoy_1", "kind": "buoy", "position": [59.4379, 10.4730]},
    ],
    "ships": [
        {"name": "research_ship", "length_m": 100, "speed_kn": 10,
         "waypoints": [[59.438875, 10.483932], [59.432853, 10.460502]], "ais": {"mmsi": 257000002}},
        {"name": "anchored", "length_m": 20, "waypoints": [[59.4390, 10.4700]], "heading_deg": 45},
    ],
}


@pytest.fixture
def write_scenario(tmp_path):
    """Write a scenario dict (or raw text) to tmp_path and return its path."""

    def write(data, name: str = "scenario.yaml") -> Path:
        path = tmp_path / name
        if isinstance(data, str):
            path.write_text(data, encoding="utf-8")
        else:
            path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
        return path

    return write
