"""The held-out benchmark's bookkeeping (benchmarks/tdm_heldout.py): criteria, pass counts, the fusion table.

Fast: no rendering; the runs are dictionaries as the benchmark caches them.
"""

from __future__ import annotations

import math

from benchmarks.tdm_heldout import CRITERIA, passes, report

_FIGURES = ("position_rmse_m", "position_median_m", "cog_rmse_deg", "cog_median_deg", "sog_rmse_mps",
            "sog_median_mps")


def _run(seed: int, latency_s: float, false_per_min: float, beats_all: int, losing: list[dict]) -> dict:
    per_figure = {name: {"beats": 1, "compared": 2} for name in _FIGURES}
    return {"scenario": "near_shore", "seed": seed, "duration_s": 300.0, "latency_max_s": latency_s,
            "missed_within_1500_m": 0 if math.isfinite(latency_s) else 1,
            "missed_names": [] if math.isfinite(latency_s) else ["dinghy"],
            "median_error_within_lidar_m": 1.5, "median_error_beyond_lidar_m": 3.0, "id_switches_max": 0,
            "false_targets_per_min": false_per_min, "nees_fraction_in_95": 0.9,
            "nees_fraction_in_95_per_sensor": {"radar": 0.9},
            "fusion_against_sensors": {"objects_compared": 2, "objects_fusion_beats_best_on_all": beats_all,
                                       "per_figure": per_figure, "losing": losing}}


def test_a_criterion_passes_on_its_side_of_the_limit():
    assert passes(10.0, 10.0, "max") and not passes(10.5, 10.0, "max")
    assert passes(0.8, 0.8, "min") and not passes(0.79, 0.8, "min")
    assert passes(None, 1.0, "max") is None
    assert not passes(math.inf, 10.0, "max")  # a missed object fails the latency
    assert [key for key, *_ in CRITERIA][0] == "latency_max_s"


def test_report_counts_passing_runs_and_sums_the_fusion_table_over_seeds():
    loss = {"name": "coaster", "sensors": ["ais", "radar"], "lost": {"position_rmse_m": [4.0, "ais", 3.7]},
            "why_not": ["position: fused bias 1.3 m against ais's 0.5 m, toward radar's bias (10 m)"]}
    runs = [_run(31, 5.0, 0.4, 1, [loss]), _run(32, math.inf, 0.6, 2, [])]
    text = report(runs, ["near_shore"], [31, 32], 300.0)
    row = next(line for line in text.splitlines() if line.startswith("| near_shore, 2 seeds |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1] == "5.00, 1 missed; **1/2**"  # latency: one run met, one missed an object
    assert cells[6] == "0.50 (0.40-0.60); **1/2**"  # false targets: 0.4 meets 0.5, 0.6 does not
    fusion = next(line for line in text.splitlines() if line.startswith("| near_shore, 2 seeds | 3/4 |"))
    assert fusion.count("2/4") == len(_FIGURES)  # each figure: 1 of 2 objects, two seeds
    assert "| near_shore | 31 | coaster | ais, radar | position_rmse_m 4 vs ais 3.7 | position: fused bias" in text
