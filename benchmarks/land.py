"""Rendering speed with land: busy_open_sea with and without 100,000 triangles of coast (issue 20).

Usage::

    python benchmarks/land.py [--quick] [--out benchmarks/results/land.md]

The land: a coast all round the scene (a polygon of 3 km radius with a hole of 1.2 km radius whose
shoreline is jagged by +-30 m over tens of thousands of vertices: the radar paints it from 1.2 km
out, faces, shadow and all) and a pier 60-110 m south-south-east of the own ship's start (the LiDAR
sees it for the first 20 s of the route); together about 100,000 triangles. A second coast has the same
number of shoreline vertices on the east half of the horizon only (bearings 0-180 deg), as a scene
near a shore has it; again about 100,000 triangles. For each of LiDAR and
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


def land_files(folder: Path, frame: LocalFrame, coast: str = "ring") -> list[dict]:
    """Write the coast and the pier as GeoJSON into ``folder``; returns the scenario's ``land`` entries.

    ``coast``: "ring", all round the scene, or "half", the same number of shoreline vertices on its east half
    (bearings 0-180 deg).
    """
    rng = np.random.default_rng(20)
    jag = np.convolve(rng.uniform(-30.0, 30.0, COAST_VERTICES + 8), np.ones(9) / 9.0, mode="valid")
    ring = coast == "ring"
    a = np.linspace(0.0, (2.0 if ring else 1.0) * math.pi, COAST_VERTICES, endpoint=not ring)
    inner = np.stack([(1200.0 + jag) * np.sin(a), (1200.0 + jag) * np.cos(a)], axis=1)
    b = np.linspace(0.0, 2.0 * math.pi, 64, endpoint=False) if ring else np.linspace(math.pi, 0.0, 32)
    outer = np.stack([3000.0 * np.sin(b), 3000.0 * np.cos(b)], axis=1)
    bearing = math.radians(160.0)
    along, across = np.array([math.sin(bearing), math.cos(bearing)]), np.array([math.cos(bearing), -math.sin(bearing)])
    pier = np.array([60.0 * along - 5.0 * across, 110.0 * along - 5.0 * across, 110.0 * along + 5.0 * across,
                     60.0 * along + 5.0 * across])
    rings = [_ring(frame, outer), _ring(frame, inner[::-1])] if ring else [_ring(frame, np.concatenate([inner, outer]))]
    (folder / "coast.geojson").write_text(json.dumps({"type": "Polygon", "coordinates": rings}))
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
    cases = ("sea", "ring", "half")
    with tempfile.TemporaryDirectory() as tmp:
        frame = LocalFrame(sea.origin.lat, sea.origin.lon)
        scenarios = {"sea": sea}
        for coast in cases[1:]:
            (Path(tmp) / coast).mkdir()
            scenarios[coast] = load_scenario(SCENARIO, changes={"land": land_files(Path(tmp) / coast, frame, coast)})
        triangles = {c: sum(o.mesh.n_triangles for o in World(scenarios[c]).objects if o.kind == "land")
                     for c in cases[1:]}
        walls = {(sensor, c): [] for sensor in ("lidar", "radar") for c in cases}
        for _ in range(repeats):
            for c in cases:
                walls["lidar", c].append(lidar_bench.steady_state(scenarios[c], duration)[0])  # wall s per scenario s
                walls["radar", c].append(radar_bench.steady_state(scenarios[c], duration)[0])  # wall s per revolution
    med = {k: statistics.median(v) for k, v in walls.items()}
    rev_s = 60.0 / sea.sensors.radar.rpm
    figures = {f"land_triangles_{c}": triangles[c] for c in cases[1:]}
    for c in cases:
        figures[f"lidar_x_real_time_{c}"] = 1.0 / med["lidar", c]
        figures[f"radar_x_real_time_{c}"] = rev_s / med["radar", c]
    for c in cases[1:]:
        for sensor in ("lidar", "radar"):
            figures[f"{sensor}_{c}_over_sea"] = figures[f"{sensor}_x_real_time_{c}"] / figures[f"{sensor}_x_real_time_sea"]
    rows = [
        ("land triangles: coast all round at 1.2 km / coast on the east half, each + a pier at 60-110 m",
         f"{triangles['ring']:,} / {triangles['half']:,}"),
    ]
    for sensor, name in (("lidar", "LiDAR"), ("radar", "radar")):
        rows += [
            (f"{name}, multiple of real time: open sea / coast all round / coast on the east half",
             " / ".join(f"{figures[f'{sensor}_x_real_time_{c}']:.2f}" for c in cases)),
            (f"**{name} with the coast all round over open sea**", f"**{figures[f'{sensor}_ring_over_sea']:.2f}**"),
            (f"**{name} with the coast on the east half over open sea**",
             f"**{figures[f'{sensor}_half_over_sea']:.2f}**"),
        ]
    intro = [machine_line("land", args.quick), "",
             f"`scenarios/busy_open_sea.yaml` with and without land, {duration:g} s runs, alternately, {repeats} "
             "each; marginal wall time per revolution (median over the run, the first excluded; LiDAR: per scenario "
             "second of its chunks), every output written. Asked (issue 20): with 100,000 triangles of land, at "
             "least 0.8 of the open-sea speed. Two coasts of the same size: all round the ship (every spoke paints "
             "land: the hard case) and on the east half of the horizon."]
    publish("Rendering with land", intro, rows, args.out, args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
