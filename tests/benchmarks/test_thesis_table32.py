"""The thesis's Table 3.2 claim on raw sensors: the fused track beats every single sensor's (where it does).

Renders the whole 300 s of scenarios/thesis_table32.yaml (one vessel at 5 m/s with an
oscillating heading, the own ship keeping pace), runs the TDM and computes the steady-state
(t >= 50 s) error statistics with ``table32`` of benchmarks/thesis_table32.py (the benchmark
that writes benchmarks/results/thesis_table32.md). Heavy: marked ``bench``, run with
``pytest -m bench tests/tdm/test_thesis_table32.py``.
"""

from __future__ import annotations

import importlib.util
import math

import pytest

from tests.conftest import REPO, render_recording

#: Scenario seconds rendered: the thesis's 5 minutes (50 s transient, 250 s steady state). With only
#: 70 s of steady state the comparison is at the mercy of a few AIS reports (fused north std 1.55 m
#: against AIS 1.47 m in one such run).
DURATION_S = 300.0


def _benchmark_module():
    """benchmarks/thesis_table32.py loaded by path (benchmarks/ is a folder of scripts, not a package)."""
    spec = importlib.util.spec_from_file_location("bench_thesis_table32", REPO / "benchmarks" / "thesis_table32.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def table(tmp_path_factory) -> dict:
    from tdm.pipeline import run_tdm

    rec = render_recording(REPO / "scenarios" / "thesis_table32.yaml", tmp_path_factory.mktemp("t32") / "rec", DURATION_S)
    run_tdm(rec)
    return _benchmark_module().table32(rec)


@pytest.mark.bench
def test_every_source_tracks_the_vessel(table):
    for source, stats in table["sources"].items():
        assert stats["coverage"] > 0.9, (source, stats["coverage"], stats["track_ids"])


def _assert_fused_below_every_sensor(table: dict, state: str, measure: str) -> None:
    """The fused track's ``measure`` ("std" or "rmse") of ``state`` is under each single sensor's."""
    fused = table["sources"]["fused"][state][measure]
    for sensor in ("ais", "radar", "lidar"):
        single = table["sources"][sensor][state][measure]
        assert math.isfinite(single) and math.isfinite(fused), (sensor, state, single, fused)
        assert fused < single, f"{state}: fused {measure} {fused:.4g} >= {sensor} {measure} {single:.4g}"


@pytest.mark.bench
@pytest.mark.parametrize("state", ["north_m", "east_m", "cog_deg", "sog_mps"])
def test_fused_std_below_every_sensor_after_the_first_50_s(table, state):
    """Held again since 2026-11-28 (the LiDAR's track scattered less in north position and speed from 2026-11-27,
    when its front end began to put a cluster's centre behind its face, until the hull-side offset of 56c1c09)."""
    _assert_fused_below_every_sensor(table, state, "std")


@pytest.mark.bench
@pytest.mark.parametrize("state", ["north_m", "east_m", "cog_deg", "sog_mps"])
def test_fused_rmse_below_every_sensor_after_the_first_50_s(table, state):
    _assert_fused_below_every_sensor(table, state, "rmse")
