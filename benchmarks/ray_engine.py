"""Ray engine against raw Embree, in one run on this machine.

Usage::

    python benchmarks/ray_engine.py [--quick] [--runs N] [--json FILE] [--out benchmarks/results/ray_engine.md]

Measures (a) a static iceberg scene (Scene.cast against raw Open3D
``cast_rays`` on a prebuilt tensor of the same rays, and raw embreex), (b) the
cost against the triangle count, (c) the cost per ray against the number of
moving ships (576 k-ray batches and one-revolution 69 k-ray batches), and the
own ship around the sensor with and without ``carrier=``. The measuring and the
formatting live in :mod:`raysim.benchmarking` (also behind ``raysim bench``);
this script only parses its arguments.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from raysim import benchmarking  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer rays and repetitions")
    ap.add_argument("--runs", type=int, default=3, help="complete runs (their headline figures show the noise)")
    ap.add_argument("--json", type=Path, help="also write the raw results as JSON")
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "results" / "ray_engine.md")
    args = ap.parse_args(argv)
    return benchmarking.main(quick=args.quick, json_path=args.json, out_path=args.out, runs=args.runs)


if __name__ == "__main__":
    raise SystemExit(main())
