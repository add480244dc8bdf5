"""Rendering speed with land: busy_open_sea with and without 100,000 triangles of coast (issue 20).

Usage::

    python benchmarks/land.py [--quick] [--out benchmarks/results/land.md]

The land: a coast all round the scene (a polygon of 3 km radius with a hole of 1.2 km radius whose
shoreline is jagged by +-30 m over tens of thousands of vertices: the radar paints it from 1.2 km
out, faces, shadow and all) and a pier 60-110 m south-south-east of the own ship's start (the LiDAR
sees it for the first 20 s of the route); together about 100,000 triangles. For each of LiDAR and
radar the marginal wall time (median over the revolutions of a run, the first excluded) is measured
with and without the land, alternately, ``--repeats`` times each; the figure is the ratio of the
medians (asked: at least 0.8 of the open-sea speed).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks import lidar as lidar_bench  # noqa: E402
from benchmarks import radar as radar_bench  # noqa: E402
from benchmarks.common import machine_line, publish  # noqa: E402
from raysim.geodesy import LocalFrame  # noqa: E402
from raysim.scenario import load_scenario  # noqa: E402
from raysim.world import World  # noqa: E402

SCENARIO = ROOT / "scenarios" / "busy_open_sea.yaml"
#: Shoreline vertices of the coast's jagged inner ring (about 3 triangles each with walls and top).
COAST_VERTICES = 25_000


def _ring(frame: LocalFrame, xy_m: np.ndarray) -> list[list[float]]:
    lat, lon = frame.to_geodetic(xy_m[:, 0], xy_m[:, 1])
    ring = np.stack([lon, lat], axis=1).tolist()
    return ring + ring[:1]


def land_files(folder: Path, frame: LocalFrame) -> list[dict]:
    """Write the coast and the pier as GeoJSON into ``folder``; returns the scenario's ``land`` entries."""
    rng = np.random.default_rng(20)
    a = np.linspace(0.0, 2.0 * math.pi, COAST_VERTICES, endpoint=False)
    jag = np.convolve(rng.uniform(-30.0, 30.0, COAST_VERTICES + 8), np.ones(9) / 9.0, mode="valid")
    inner = np.stack([(1200.0 + jag) * np.sin(a), (1200.0 + jag) * np.cos(a)], axis=1)
    b = np.linspace(0.0, 2.0 * math.pi, 64, endpoint=False)
    outer = np.stack([3000.0 * np.sin(b), 3000.0 * np.cos(b)], axis=1)
    bearing = math.radians(160.0)
    along, across = np.array([math.sin(bearing), math.cos(bearing)]), np.array([math.cos(bearing), -math.sin(bearing)])
    pier = np.array([60.0 * along - 5.0 * across, 110.0 * along - 5.0 * across, 110.0 * along + 5.0 * across,
                     60.0 * along + 5.0 * across])
    coast = {"type": "Polygon", "coordinates": [_ring(frame, outer), _ring(frame, inner[::-1])]}
    (folder / "coast.geojson").write_text(json.dumps(coast))
    (folder / "pier.geojson").write_text(json.dumps({"type": "Polygon", "coordinates": [_ring(frame, pier)]}))
    return [{"name": "coast", "file": str(folder / "coast.geojson"), "height_m": 20.0},
            {"name": "pier", "file": str(folder / "pier.geojson"), "height_m": 2.0, "material": "concrete"}]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="one repeat of 10 s runs")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "land.md")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    duration, repeats = (10.0, 1) if args.quick else (20.0, args.repeats)
    sea = load_scenario(SCENARIO)
    with tempfile.TemporaryDirectory() as tmp:
        entries = land_files(Path(tmp), LocalFrame(sea.origin.lat, sea.origin.lon))
        land = load_scenario(SCENARIO, changes={"land": entries})
        triangles = sum(o.mesh.n_triangles for o in World(land).objects if o.kind == "land")
        walls = {("lidar", "sea"): [], ("lidar", "land"): [], ("radar", "sea"): [], ("radar", "land"): []}
        for _ in range(repeats):
            for name, scenario in (("sea", sea), ("land", land)):
                walls["lidar", name].append(lidar_bench.steady_state(scenario, duration)[0])  # wall s per scenario s
                walls["radar", name].append(radar_bench.steady_state(scenario, duration)[0])  # wall s per revolution
    med = {k: statistics.median(v) for k, v in walls.items()}
    rev_s = 60.0 / sea.sensors.radar.rpm
    figures = {"land_triangles": triangles,
               "lidar_x_real_time_sea": 1.0 / med["lidar", "sea"], "lidar_x_real_time_land": 1.0 / med["lidar", "land"],
               "radar_x_real_time_sea": rev_s / med["radar", "sea"], "radar_x_real_time_land": rev_s / med["radar", "land"]}
    figures["lidar_land_over_sea"] = figures["lidar_x_real_time_land"] / figures["lidar_x_real_time_sea"]
    figures["radar_land_over_sea"] = figures["radar_x_real_time_land"] / figures["radar_x_real_time_sea"]
    rows = [
        ("land triangles (coast all round at 1.2 km + a pier at 60-110 m)", f"{triangles:,}"),
        ("LiDAR, multiple of real time: open sea / with land", f"{figures['lidar_x_real_time_sea']:.2f} / "
                                                               f"{figures['lidar_x_real_time_land']:.2f}"),
        ("**LiDAR with land over open sea**", f"**{figures['lidar_land_over_sea']:.2f}**"),
        ("radar, multiple of real time: open sea / with land", f"{figures['radar_x_real_time_sea']:.2f} / "
                                                               f"{figures['radar_x_real_time_land']:.2f}"),
        ("**radar with land over open sea**", f"**{figures['radar_land_over_sea']:.2f}**"),
    ]
    intro = [machine_line("land", args.quick), "",
             f"`scenarios/busy_open_sea.yaml` with and without land, {duration:g} s runs, alternately, {repeats} "
             "each; marginal wall time per revolution (median over the run, the first excluded; LiDAR: per scenario "
             "second of its chunks), every output written. Asked (issue 20): with 100,000 triangles of land, at "
             "least 0.8 of the open-sea speed."]
    publish("Rendering with land", intro, rows, args.out, args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
