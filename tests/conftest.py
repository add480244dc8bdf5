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


def render_recording(scenario_path: Path, out: Path, duration_s: float, sensors=None, seed=None,
                     derived: bool = False) -> Path:
    """Render a scenario file into ``out`` for ``duration_s`` seconds; returns ``out``.

    The tdm package never imports raysim; its tests (and the benchmarks' tests) use raysim only
    to make recordings with known truth, as a user would with the ``raysim render`` command. The
    files made from the recording's own (bag, map, bird's-eye views), which the TDM does not read,
    are left out unless ``derived``.
    """
    from raysim.render import render
    from raysim.scenario import load_scenario, with_overrides

    scenario = with_overrides(load_scenario(Path(scenario_path)), duration_s, seed, sensors)
    render(scenario, Path(out), progress=False, derived=derived)
    return Path(out)


@pytest.fixture(scope="session")
def bos_recording(tmp_path_factory) -> Path:
    """busy_open_sea, first 40 s, every sensor (rendered once per session, for tests/tdm and tests/benchmarks)."""
    return render_recording(REPO / "scenarios" / "busy_open_sea.yaml", tmp_path_factory.mktemp("bos") / "rec", 40.0)


@pytest.fixture(scope="session")
def crossing_recording(tmp_path_factory) -> Path:
    """crossing_silent_ship, first 40 s, every sensor."""
    return render_recording(REPO / "scenarios" / "crossing_silent_ship.yaml",
                            tmp_path_factory.mktemp("crossing") / "rec", 40.0)
