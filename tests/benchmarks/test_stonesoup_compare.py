"""Our trackers against Stone Soup's GNN + EKF on the same detections (benchmarks/stonesoup_compare.py).

Marked ``bench`` (not run by the default test command): each test runs ``tdm run`` and
Stone Soup trackers at two process-noise intensities on a 40 s session recording and scores
both with ``tdm.evaluate.evaluate``. Ours must reach a lower GOSPA than Stone Soup at the
better of its two q values.
"""

from __future__ import annotations

import math

import pytest

pytest.importorskip("stonesoup")

from benchmarks.stonesoup_compare import compare  # noqa: E402

pytestmark = pytest.mark.bench

#: Stone Soup's process-noise intensities tried, m^2/s^3 (the benchmark's sweep picks among more).
Q_VALUES = (0.01, 1.0)


def best_stonesoup_gospa(result: dict, name: str) -> float:
    """Lowest GOSPA of Stone Soup tracker ``name`` over the q values tried, m."""
    values = [result["stonesoup"][q][name]["gospa_m"] for q in result["stonesoup"]]
    values = [v for v in values if v is not None]
    assert values, f"Stone Soup {name} output no tracks"
    return min(values)


def test_crossing_silent_ship_radar_and_fused_beat_stonesoup(crossing_recording, tmp_path):
    """The silent ship crossing: our radar tracker and our fused targets against Stone Soup's."""
    result = compare(crossing_recording, tmp_path, Q_VALUES, names=("radar", "central", "central_ais"))
    ours = result["ours"]
    assert result["detections"]["radar"] > 0
    assert ours["radar"]["gospa_m"] < best_stonesoup_gospa(result, "radar")
    central = min(best_stonesoup_gospa(result, "central"), best_stonesoup_gospa(result, "central_ais"))
    assert ours["fused"]["gospa_m"] < central
    assert math.isfinite(central)


def test_busy_open_sea_lidar_and_fused_beat_stonesoup(bos_recording, tmp_path):
    """Busy open sea: our LiDAR tracker and our fused targets against Stone Soup's (central with AIS positions)."""
    result = compare(bos_recording, tmp_path, Q_VALUES, names=("lidar", "central_ais"))
    ours = result["ours"]
    assert result["detections"]["lidar"] > 0
    assert ours["lidar"]["gospa_m"] < best_stonesoup_gospa(result, "lidar")
    assert ours["fused"]["gospa_m"] < best_stonesoup_gospa(result, "central_ais")
