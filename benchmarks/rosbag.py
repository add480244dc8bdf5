"""Cost of writing the ROS 2 bag against LiDAR rendering, on scenarios/busy_open_sea.yaml.

Usage::

    python benchmarks/rosbag.py [--quick] [--out benchmarks/results/rosbag.md]

Renders the scenario with every sensor and reads the manifest's wall times: the bag (every
topic: LiDAR clouds, radar sectors and pictures, AIS, own ship with IMU and odometry, tf, truth
boxes, labels and GeoJSON; zstd chunks with CRCs) against the LiDAR renderer, and the bag's size
against its chunks' uncompressed size (from the MCAP summary).
Asked (issue 6): the bag costs at most 25 % of LiDAR rendering time.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.common import machine_line, publish  # noqa: E402
from raysim import render as render_module  # noqa: E402
from raysim.scenario import load_scenario, with_overrides  # noqa: E402


def _chunk_sizes(bag_dir: Path) -> tuple[int, int]:
    """(compressed, uncompressed) bytes of the bag's chunks, from its MCAP summary."""
    from mcap.reader import make_reader

    (path,) = bag_dir.glob("*.mcap")
    with open(path, "rb") as handle:
        chunks = make_reader(handle).get_summary().chunk_indexes
    return sum(c.compressed_size for c in chunks), sum(c.uncompressed_size for c in chunks)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "rosbag.md")
    parser.add_argument("--json", type=Path, help="also write the figures as JSON")
    args = parser.parse_args(argv)
    duration = 10.0 if args.quick else 60.0
    reps = 1 if args.quick else 3
    scenario = with_overrides(load_scenario(ROOT / "scenarios" / "busy_open_sea.yaml"), duration_s=duration)
    runs = []
    for _ in range(reps):
        with tempfile.TemporaryDirectory() as tmp:
            manifest = render_module.render(scenario, Path(tmp) / "rec", progress=False).manifest
            size = sum(p.stat().st_size for p in (Path(tmp) / "rec" / "rosbag").iterdir())
            compressed, uncompressed = _chunk_sizes(Path(tmp) / "rec" / "rosbag")
        runs.append((manifest["wall_time_s"]["lidar"], manifest["wall_time_s"]["rosbag"], size))
    lidar = statistics.median(r[0] for r in runs)
    bag = statistics.median(r[1] for r in runs)
    counts = {k: v for k, v in manifest["counts"].items() if k.startswith("rosbag/")}
    rows = [
        ("scenario seconds rendered", f"{duration:g}"),
        ("LiDAR rendering wall time, s", f"{lidar:.2f}"),
        ("bag writing wall time, s (all topics)", f"{bag:.2f}"),
        ("**bag / LiDAR rendering**", f"**{bag / lidar:.2f}**"),
        ("bag size, MB", f"{runs[0][2] / 1e6:.0f}"),
        ("chunks uncompressed, MB", f"{uncompressed / 1e6:.0f}"),
        ("**compressed / uncompressed (zstd)**", f"**{compressed / uncompressed:.2f}**"),
        *[(f"messages on {k[len('rosbag'):]}", f"{v:,}") for k, v in sorted(counts.items())],
    ]
    intro = [machine_line("rosbag", args.quick), "",
             f"Medians of {reps} renders of {duration:g} s of busy_open_sea with every sensor; times from the manifests. "
             "Asked (issue 6): at most 0.25."]
    publish("ROS 2 bag writing benchmark", intro, rows, args.out, args.json,
            {"bag_over_lidar": bag / lidar, "bag_s": bag, "lidar_s": lidar, "size_mb": runs[0][2] / 1e6,
             "compression_ratio": compressed / uncompressed})
    return 0


if __name__ == "__main__":
    sys.exit(main())
