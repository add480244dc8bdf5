"""A silent ship hidden behind an island and coming back (issue 22: "same id after it comes back within 60 s").

The scene, rendered by raysim's radar (rays, not rules, hide the ship): the own ship lies still; an island 200 m x
60 m, 15 m high, its south shore 300 m north; a 30 m ship without AIS runs east at 6 m/s 450 m north, from x = -300 m.
The island's shadow at the ship's track spans x = -150 to 150 m: the ship is hidden from about 25 s to 75 s.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from tdm.cli import main as tdm_main

from .conftest import render_recording

SHIP_SPEED_MPS = 6.0
SHIP_START_X_M, SHIP_Y_M = -300.0, 450.0
ISLAND_XY_M = [(-100.0, 300.0), (100.0, 300.0), (100.0, 360.0), (-100.0, 360.0)]
DURATION_S = 130.0


def shadow_times_s() -> tuple[float, float]:
    """When the ship's centre enters and leaves the island's shadow (straight lines from the radar), s."""
    x_edge = 100.0 * SHIP_Y_M / 300.0  # the shadow widens with range: 150 m either side at the ship's track
    return (-x_edge - SHIP_START_X_M) / SHIP_SPEED_MPS, (x_edge - SHIP_START_X_M) / SHIP_SPEED_MPS


@pytest.fixture(scope="module")
def hidden(tmp_path_factory) -> Path:
    from tests.raysim.helpers import land_file, latlon, scenario

    folder = tmp_path_factory.mktemp("hidden")
    data = scenario(folder, duration=DURATION_S, environment={"sea_state": 2, "wind_speed_mps": 5})
    data["name"] = "hidden_ship"
    data["land"] = [{"name": "island", "file": land_file(folder, "island", ISLAND_XY_M, 15.0, "rock")}]
    data["sensors"] = {"lidar": {"enabled": False}, "radar": {"rpm": 24, "range_m": 926.0, "mount": {"z_m": 4.0}}}
    end_x_m = SHIP_START_X_M + 1.2 * SHIP_SPEED_MPS * DURATION_S
    data["ships"] = [{"name": "silent", "speed_kn": SHIP_SPEED_MPS * 3600.0 / 1852.0, "length_m": 30,
                      "waypoints": [latlon(SHIP_START_X_M, SHIP_Y_M), latlon(end_x_m, SHIP_Y_M)]}]
    path = folder / "hidden.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    rec = render_recording(path, folder / "rec", DURATION_S, sensors=("radar", "ais", "nav"))
    shutil.rmtree(rec / "rosbag", ignore_errors=True)
    assert tdm_main(["run", str(rec)]) == 0
    assert tdm_main(["evaluate", str(rec), "--no-plots"]) == 0
    return rec


def test_the_island_hides_the_ship_for_about_50_s():
    enter_s, leave_s = shadow_times_s()
    assert (enter_s, leave_s) == (pytest.approx(25.0), pytest.approx(75.0))


def test_a_silent_ship_back_from_behind_an_island_keeps_its_id(hidden):
    metrics = json.loads((hidden / "tdm" / "metrics.json").read_text())
    (ship,) = [o for o in metrics["per_object"] if o["name"] == "silent"]
    assert ship["id_switches"] == 0 and ship["target_ids"] == [ship["target_ids"][0]]
    rows = [json.loads(line) for line in (hidden / "tdm" / "detected_targets.jsonl").read_text().splitlines()]
    enter_s, leave_s = shadow_times_s()
    before = {r["target_id"] for r in rows if r["t"] < enter_s - 5.0}
    after = {r["target_id"] for r in rows if r["t"] > leave_s + 20.0}
    assert len(before) == 1 and after == before  # one target, the same before and after, nothing else


def test_the_ship_is_tracked_at_its_speed_and_course_after_it_comes_back(hidden):
    """The radar alone, 450-700 m off: its two-point velocity cannot tell the course (``course_retry_s``)."""
    rows = [json.loads(line) for line in (hidden / "tdm" / "detected_targets.jsonl").read_text().splitlines()]
    _, leave_s = shadow_times_s()
    late = [r for r in rows if r["t"] > leave_s + 30.0]
    assert len(late) >= 20
    assert np.median([r["sog_mps"] for r in late]) == pytest.approx(SHIP_SPEED_MPS, abs=0.6)
    course_error = [abs((r["cog_deg"] - 90.0 + 180.0) % 360.0 - 180.0) for r in late]
    assert np.median(course_error) < 8.0
    metrics = json.loads((hidden / "tdm" / "metrics.json").read_text())
    (ship,) = [o for o in metrics["per_object"] if o["name"] == "silent"]
    assert ship["median_error_m"] < 10.0
    assert math.isfinite(ship["latency_s"]) and ship["latency_s"] <= 10.0
