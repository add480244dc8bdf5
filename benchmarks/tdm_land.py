"""The TDM near land: near_shore and busy_port rendered for their full 300 s, run and evaluated (issue 20).

Usage::

    python benchmarks/tdm_land.py [--duration S] [--reuse] [--out benchmarks/results/tdm_land.md] [--json FILE]

For each scenario: ``raysim render`` into ``/tmp/tdm_land_<name>`` (every sensor), ``tdm run`` and
``tdm evaluate`` with the default configuration, then the done-when criteria of docs/tdm.md (the same
as benchmarks/tdm_criteria.py tabulates for the open-sea scenarios) and, checked here independently of
the TDM's own land mask, how many reported (target, epoch) positions lie on the recording's land
(``land.geojson``, shapely) and how far outside the land the radar-only false targets lie.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import sys
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import shape

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.common import machine_line  # noqa: E402
from raysim.cli import main as raysim_main  # noqa: E402
from tdm.cli import main as tdm_main  # noqa: E402

SCENARIOS = ("near_shore", "busy_port")
ASKED = {"detection_latency_max_s": ("latency, max [s]", "<= 10"),
         "median_position_error_within_lidar_range_m": ("median error within LiDAR range [m]", "<= 5.0"),
         "radar_median_position_error_m": ("median error, radar alone [m]", "<= 15.0"),
         "false_targets_per_min": ("false targets per minute", "<= 1.0"),
         "id_switches_max_per_object": ("id switches of one object, max", "<= 1")}


def on_land(recording: Path) -> tuple[int, int, list[float]]:
    """Reported (target, epoch) rows on the recording's land, all rows, and each false target's median distance
    from the land (m, by an equirectangular approximation about the land's centre)."""
    chart = json.loads((recording / "land.geojson").read_text())
    land = shapely.union_all([shape(f["geometry"]) for f in chart["features"]])
    rows = [json.loads(line) for line in (recording / "tdm" / "detected_targets.jsonl").read_text().splitlines()]
    lon = np.array([r["longitude"] for r in rows])
    lat = np.array([r["latitude"] for r in rows])
    inside = shapely.contains_xy(land, lon, lat)
    metrics = json.loads((recording / "tdm" / "metrics.json").read_text())
    false_ids = set(metrics["false_target_ids"])
    lat0 = math.radians(float(np.mean(lat))) if rows else 0.0
    distances = []
    for tid in sorted(false_ids):
        pick = [i for i, r in enumerate(rows) if r["target_id"] == tid]
        d_deg = shapely.distance(land, shapely.points(lon[pick], lat[pick]))
        distances.append(float(np.median(d_deg)) * 111_195.0 * math.cos(lat0))
    return int(inside.sum()), len(rows), distances


def run(name: str, duration_s: float, reuse: bool = False) -> dict:
    out = Path(f"/tmp/tdm_land_{name}")
    scenario = ROOT / "scenarios" / f"{name}.yaml"
    manifest = out / "manifest.json"
    if not (reuse and manifest.is_file() and abs(json.loads(manifest.read_text())["duration_s"] - duration_s) < 1e-9):
        shutil.rmtree(out, ignore_errors=True)
        assert raysim_main(["render", str(scenario), "-o", str(out), "--duration", f"{duration_s:g}",
                            "--no-progress"]) == 0
    assert tdm_main(["run", str(out)]) == 0
    assert tdm_main(["evaluate", str(out), "--no-plots"]) == 0
    metrics = json.loads((out / "tdm" / "metrics.json").read_text())
    rows_on_land, rows, false_distances = on_land(out)
    return {**{k: metrics[k] for k in ASKED if k in metrics},
            "radar_median_position_error_m": metrics["per_sensor"]["radar"]["median_position_error_m"],
            "missed_objects": metrics["missed_objects"], "objects_in_range": metrics["objects_in_range"],
            "false_target_ids": metrics["false_target_ids"], "rows_on_land": rows_on_land, "rows": rows,
            "false_target_distance_from_land_m": false_distances}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--duration", type=float, default=300.0)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "tdm_land.md")
    parser.add_argument("--json", type=Path)
    parser.add_argument("--reuse", action="store_true",
                        help="run the TDM on the renders already in /tmp/tdm_land_<name> (after a TDM change)")
    args = parser.parse_args(argv)
    results = {name: run(name, args.duration, args.reuse) for name in SCENARIOS}
    fmt = lambda v: "-" if v is None else (f"{v:.2f}" if isinstance(v, float) else str(v))  # noqa: E731
    lines = ["| criterion | " + " | ".join(f"{n}, {args.duration:g} s" for n in SCENARIOS) + " | asked |",
             "|---|" + "---:|" * (len(SCENARIOS) + 1)]
    for key, (label, asked) in ASKED.items():
        lines.append(f"| {label} | " + " | ".join(fmt(results[n].get(key)) for n in SCENARIOS) + f" | {asked} |")
    lines.append("| objects in view / missed | " + " | ".join(
        f"{results[n]['objects_in_range']} / {len(results[n]['missed_objects'])}" for n in SCENARIOS) + " | - / 0 |")
    lines.append("| reported positions on land (checked on land.geojson here) | " + " | ".join(
        f"{results[n]['rows_on_land']} of {results[n]['rows']}" for n in SCENARIOS) + " | 0 |")
    def spread(d: list[float]) -> str:
        return f"{len(d)}: median {np.median(d):.0f} ({min(d):.0f}-{max(d):.0f})" if d else "-"

    lines.append("| false targets: count, median (range) of their median distance from land [m] | " + " | ".join(
        spread(results[n]["false_target_distance_from_land_m"]) for n in SCENARIOS) + " | - |")
    intro = [machine_line("tdm_land", False), "",
             "Default configuration (`tdm run`, `tdm evaluate`) on scenarios/near_shore.yaml and "
             "scenarios/busy_port.yaml (near_shore's land schematic, busy_port's Erie Basin, Brooklyn, from NYC's "
             "shoreline data; docs/land.md). The criteria are those of docs/tdm.md, "
             "stated for these scenarios whatever they are; the TDM was tuned on busy_open_sea only.", "",
             *lines]
    text = "\n".join(["# The TDM near land", "", *intro, ""])
    print(text)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text, encoding="utf-8")
    if args.json:
        args.json.write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
