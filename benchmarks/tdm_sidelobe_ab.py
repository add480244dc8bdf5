"""The radar front end's sidelobe rule off and on, on the same recordings (docs/tdm.md, "Sidelobe arcs").

Usage::

    python benchmarks/tdm_sidelobe_ab.py RECORDING [RECORDING ...] [--work /tmp/sl]

For each recording (a raysim render with its truth and sweeps, e.g. the held-out benchmark's kept
recordings), ``tdm run`` and ``tdm evaluate`` twice in this process (no workers): the radar front end's
``sidelobe_margin_db`` None (off) and at its default (on). A shadow directory of symbolic links per run
keeps each run's ``tdm/`` apart from the recording's own. Prints one line of the criteria per run.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import tdm.frontend.radar_config as radar_config  # noqa: E402
from tdm.evaluate import evaluate  # noqa: E402
from tdm.pipeline import TdmConfig, run_tdm  # noqa: E402

KEYS = ("false_targets_per_min", "detection_latency_max_s", "missed_objects", "id_switches_max_per_object",
        "median_position_error_within_lidar_range_m", "median_position_error_beyond_lidar_range_m",
        "nees_fraction_in_95", "gospa_m")
_FROM_SCENARIO = radar_config.RadarFrontEndConfig.from_scenario.__func__


def _shadow(recording: Path, work: Path, tag: str) -> Path:
    """A directory of links to ``recording``'s files but its ``tdm/``."""
    shadow = work / f"{recording.name}_{tag}"
    shadow.mkdir(parents=True, exist_ok=True)
    for entry in recording.iterdir():  # loop over a recording's few top-level entries
        if entry.name != "tdm" and not (shadow / entry.name).exists():
            os.symlink(entry, shadow / entry.name)
    return shadow


def run(recording: Path, work: Path, margin_db: float | None, tag: str) -> dict:
    """The criteria of one ``tdm run`` + ``tdm evaluate`` with the sidelobe margin ``margin_db``."""
    radar_config.RadarFrontEndConfig.from_scenario = classmethod(
        lambda cls, scenario: dataclasses.replace(_FROM_SCENARIO(cls, scenario), sidelobe_margin_db=margin_db))
    try:
        shadow = _shadow(recording, work, tag)
        run_tdm(shadow, shadow / "tdm", TdmConfig.for_recording(shadow, workers=0))
        metrics = evaluate(shadow)
    finally:
        radar_config.RadarFrontEndConfig.from_scenario = classmethod(_FROM_SCENARIO)
    return {key: metrics[key] for key in KEYS}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("recordings", type=Path, nargs="+")
    parser.add_argument("--work", type=Path, default=Path("/tmp/sl"))
    args = parser.parse_args(argv)
    default = radar_config.RadarFrontEndConfig().sidelobe_margin_db
    for recording in args.recordings:  # loop over recordings, a few minutes each
        for tag, margin in (("off", None), ("on", default)):
            print(recording.name, tag, json.dumps(run(recording, args.work, margin, tag)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
