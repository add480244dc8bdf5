"""Recordings the TDM tests run on, rendered once per session with raysim.

The tdm package never imports raysim; its tests use raysim only to make recordings
with known truth, as a user would with the ``raysim render`` command.
"""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def render_recording(scenario_path: Path, out: Path, duration_s: float, sensors=None, seed=None) -> Path:
    """Render a scenario file into ``out`` for ``duration_s`` seconds; returns ``out``."""
    from raysim.render import render
    from raysim.scenario import load_scenario, with_overrides

    scenario = with_overrides(load_scenario(Path(scenario_path)), duration_s, seed, sensors)
    render(scenario, Path(out), progress=False)
    return Path(out)


@pytest.fixture(scope="session")
def bos_recording(tmp_path_factory) -> Path:
    """busy_open_sea, first 40 s, every sensor."""
    return render_recording(REPO / "scenarios" / "busy_open_sea.yaml", tmp_path_factory.mktemp("bos") / "rec", 40.0)


@pytest.fixture(scope="session")
def crossing_recording(tmp_path_factory) -> Path:
    """crossing_silent_ship, first 40 s, every sensor."""
    return render_recording(REPO / "scenarios" / "crossing_silent_ship.yaml",
                            tmp_path_factory.mktemp("crossing") / "rec", 40.0)
