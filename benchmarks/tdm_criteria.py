"""The TDM's done-when criteria (issue 7) on the full scenarios, and the radar plot strengths behind them.

Usage::

    python benchmarks/tdm_criteria.py [--quick] [--fresh] [--out benchmarks/results/tdm_criteria.md] [--json FILE]
                                      [--batch DIR]...

- Renders scenarios/busy_open_sea.yaml for its full 300 s (into ``/tmp/tdm_bench_bos``, shared with
  benchmarks/tdm_speed.py) and scenarios/crossing_silent_ship.yaml for 120 s (into
  ``/tmp/tdm_bench_crossing``), reused when a matching render newer than the scenario and the
  renderer's code is there (``--fresh`` renders again). ``--quick``: busy_open_sea for 90 s only
  (``/tmp/tdm_bench_bos_90``), as the test suite runs it.
- Runs ``tdm run`` and ``tdm evaluate`` (default configuration) on each and tabulates the criteria:
  the largest detection latency (from when an object comes into view), the median position error
  within LiDAR range and with the radar alone, false targets per minute and the most id switches
  of one object, against what the issue asks.
- Radar plot strengths: every plot of the first 60 sweeps of busy_open_sea that passes the radar
  front end (:func:`tdm.frontend.radar.radar_detections`), split into plots on an object (within
  20 m of its hull's outline, from truth) and the rest (sea clutter), with the strength
  (``Detections.strength_db``, dB over the local clutter level) percentiles and the fractions
  under 13 dB and from 15 dB: the weights of the radar tracker's confirmation
  (``TdmConfig.radar_tracker``: weak_below_db, strong_from_db); and, of the plots from 15 dB, the
  median beam fill and the fraction under 0.5 (``Detections.beam_fill``, min_beam_fill).
- ``--batch DIR`` (repeatable): also tabulates the criteria of every run of a ``raysim batch`` of
  a scenario over other seeds (made beforehand, for example
  ``raysim batch scenarios/busy_open_sea.yaml --seeds 5 -o DIR``: seeds 7-11, the scenario's
  own first; ``raysim batch scenarios/crossing_silent_ship.yaml --seeds 5 --duration 120 -o DIR``),
  from each run's ``tdm/metrics.json``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.common import ensure_recording, machine_line  # noqa: E402
from tdm.detections import ReadStats  # noqa: E402
from tdm.evaluate import evaluate, write_metrics  # noqa: E402
from tdm.frames import EnuFrame  # noqa: E402
from tdm.pipeline import DetectionStream, TdmConfig, run_tdm  # noqa: E402

SCENARIOS = {  # name: (scenario file, duration s, default recording directory)
    "busy_open_sea": (ROOT / "scenarios" / "busy_open_sea.yaml", 300.0, Path("/tmp/tdm_bench_bos")),
    "crossing_silent_ship": (ROOT / "scenarios" / "crossing_silent_ship.yaml", 120.0, Path("/tmp/tdm_bench_crossing")),
}
#: The criteria (issue 7, "Done when"): metrics.json key, label, limit, decimals.
CRITERIA = (
    ("detection_latency_max_s", "latency, max [s]", 10.0, 0),
    ("median_position_error_within_lidar_range_m", "median error within LiDAR range [m]", 5.0, 2),
    ("radar_median_position_error_m", "median error, radar alone [m]", 15.0, 2),
    ("false_targets_per_min", "false targets per minute", 1.0, 2),
    ("id_switches_max_per_object", "id switches of one object, max", 1, 0),
)
#: A plot within this distance of an object's outline (truth position less half its length) is on it, m.
ON_OBJECT_M = 20.0
STRENGTH_SWEEPS = 60


def criteria(metrics: dict) -> dict:
    """The criteria's values from a metrics.json dict, plus the objects in view and missed."""
    out = {key: metrics[key] for key, *_ in CRITERIA if key in metrics}
    out["radar_median_position_error_m"] = metrics["per_sensor"]["radar"]["median_position_error_m"]
    out["missed_objects"] = metrics["missed_objects"]
    out["objects_in_range"] = metrics["objects_in_range"]
    return out


def run_and_evaluate(recording: Path) -> dict:
    """``tdm run`` and ``tdm evaluate`` (default configuration); the metrics."""
    run_tdm(recording, recording / "tdm", TdmConfig.for_recording(recording))
    metrics = evaluate(recording)
    write_metrics(recording, metrics)
    return metrics


def plot_strengths(recording: Path, sweeps: int = STRENGTH_SWEEPS) -> dict:
    """Strengths (dB over the clutter level) of the radar plots on objects and of the others."""
    stream = DetectionStream(recording, TdmConfig.for_recording(recording, workers=0), ReadStats())
    frame: EnuFrame = stream.ownship.frame
    times, positions, half_lengths = {}, {}, {}
    with open(recording / "truth.jsonl", encoding="utf-8") as f:
        for line in f:
            row = json.loads(line)
            if row["kind"] == "ownship":
                continue
            key = round(row["t"], 1)
            positions.setdefault(key, []).append(frame.to_enu(row["lat"], row["lon"]))
            half_lengths.setdefault(key, []).append(0.5 * row["length_m"])
    on, off, n = [], [], 0
    for _, sensor, dets in stream.events():
        if sensor != "radar":
            continue
        n += 1
        if n > sweeps:
            break
        if not len(dets):
            continue
        keys = np.round(dets.time_s, 1)
        for key in np.unique(keys):  # a few truth epochs per sweep
            sel = keys == key
            objs = np.asarray(positions[float(key)], dtype=float)
            d = np.linalg.norm(dets.position_m[sel, None, :] - objs[None], axis=2) - np.asarray(half_lengths[float(key)])
            near = d.min(axis=1) <= ON_OBJECT_M
            both = np.stack([dets.strength_db[sel], dets.beam_fill[sel]], axis=1)
            on.append(both[near])
            off.append(both[~near])
    out = {}
    for name, values in (("objects", on), ("clutter", off)):
        both = np.concatenate(values) if values else np.zeros((0, 2))
        v, fill = both[:, 0], both[:, 1]
        strong = fill[v >= 15.0]
        out[name] = {"plots": int(v.size), "per_sweep": v.size / max(min(n, sweeps), 1),
                     "p10_db": float(np.percentile(v, 10)) if v.size else float("nan"),
                     "p50_db": float(np.percentile(v, 50)) if v.size else float("nan"),
                     "p90_db": float(np.percentile(v, 90)) if v.size else float("nan"),
                     "under_13_db": float(np.mean(v < 13.0)) if v.size else float("nan"),
                     "from_15_db": float(np.mean(v >= 15.0)) if v.size else float("nan"),
                     "from_15_db_fill_p50": float(np.median(strong)) if strong.size else float("nan"),
                     "from_15_db_fill_under_half": float(np.mean(strong < 0.5)) if strong.size else float("nan")}
    return out


def _fmt(value, decimals: int) -> str:
    return "-" if value is None else f"{value:.{decimals}f}"


def report(results: dict, strengths: dict, durations: dict, quick: bool = False) -> str:
    names = list(results)
    lines = ["# TDM done-when criteria", "", machine_line("tdm_criteria", quick), "",
             "Full scenarios, default configuration (`tdm run`, `tdm evaluate`). Latency counts from when an",
             "object comes into view (first run of in-range epochs lasting 5 s; the radar's view is ray truth:",
             "the sweeps' `object_id`, from the beam's pass over the object), docs/tdm.md.", "",
             "| criterion | " + " | ".join(f"{n}, {durations[n]:.0f} s" for n in names) + " | asked |",
             "|---|" + "---:|" * (len(names) + 1)]
    for key, label, limit, decimals in CRITERIA:
        cells = []
        for n in names:
            value = results[n][key]
            cells.append(_fmt(value, decimals) + ("" if value is not None and value <= limit else " (not met)"))
        lines.append(f"| {label} | " + " | ".join(cells) + f" | <= {limit} |")
    lines.append("| objects in view / missed | " + " | ".join(
        f"{results[n]['objects_in_range']} / {len(results[n]['missed_objects'])}" for n in names) + " | - / 0 |")
    lines += ["", f"## Radar plot strengths, busy_open_sea, first {STRENGTH_SWEEPS} sweeps", "",
              "Plots that pass the front end; 'objects': within 20 m of an object's outline (truth).", "",
              "| plots on | per sweep | p10 [dB] | median [dB] | p90 [dB] | under 13 dB | from 15 dB "
              "| from 15 dB: median beam fill | from 15 dB: fill under 0.5 |",
              "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, s in strengths.items():
        lines.append(f"| {name} | {s['per_sweep']:.1f} | {s['p10_db']:.1f} | {s['p50_db']:.1f} | {s['p90_db']:.1f} | "
                     f"{s['under_13_db']:.2f} | {s['from_15_db']:.2f} | {s['from_15_db_fill_p50']:.2f} | "
                     f"{s['from_15_db_fill_under_half']:.2f} |")
    lines += ["", "The radar tracker counts a plot under 13 dB as half a hit and one from 15 dB as 1.5 hits",
              "(3 needed in 4 scans): most clutter plots never add up, most object plots confirm in two scans.",
              "Beam fill (`Detections.beam_fill`): a plot's azimuth extent over what the two-way beam paints",
              "between its strongest and weakest cells. The clutter plots that do stand out are sea spikes",
              "narrower than the beam; the tracker counts a plot with a fill under 0.5 as half a hit, whatever",
              "its strength."]
    return "\n".join(lines) + "\n"


def seeds_report(batch: Path) -> str:
    """The criteria of every run of a ``raysim batch`` (its summary.csv and each run's metrics.json)."""
    import csv

    with open(batch / "summary.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    import yaml

    first = next((batch / "runs" / row["run"] / "scenario.yaml" for row in rows), None)
    name = yaml.safe_load(first.read_text(encoding="utf-8")).get("name", batch.name) if first else batch.name
    lines = ["", f"## {name} over seeds (`raysim batch`, {len(rows)} runs)", "",
             "The criteria of each run; the objects behind a latency over 10 s and an object with more than one",
             "id switch are named.", "",
             "| seed | duration [s] | " + " | ".join(label for _, label, *_ in CRITERIA) + " | slow objects | switching objects |",
             "|---:|---:|" + "---:|" * len(CRITERIA) + "---|---|"]
    for row in rows:
        if row["status"] != "ok":
            lines.append(f"| {row['seed']} | {row['duration_s']} | failed: {row['error']} |")
            continue
        metrics = json.loads((batch / "runs" / row["run"] / "tdm" / "metrics.json").read_text(encoding="utf-8"))
        values = criteria(metrics)
        cells = [_fmt(values[key], decimals) + ("" if values[key] is not None and values[key] <= limit else " (not met)")
                 for key, _, limit, decimals in CRITERIA]
        slow = ", ".join(f"{o['name']} {o['latency_s']:.0f} s" for o in metrics["per_object"] if (o["latency_s"] or 0) > 10)
        switching = ", ".join(f"{o['name']} {o['id_switches']}" for o in metrics["per_object"] if o["id_switches"] > 1)
        lines.append(f"| {row['seed']} | {float(row['duration_s']):.0f} | " + " | ".join(cells)
                     + f" | {slow or '-'} | {switching or '-'} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fresh", action="store_true", help="render again even if a matching render exists")
    parser.add_argument("--quick", action="store_true", help="busy_open_sea for 90 s only")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "tdm_criteria.md")
    parser.add_argument("--json", type=Path, help="also write the figures as JSON")
    parser.add_argument("--batch", type=Path, action="append", default=[],
                        help="a raysim batch of a scenario over seeds to tabulate as well (repeatable)")
    args = parser.parse_args(argv)
    results, recordings, durations = {}, {}, {}
    for name, (scenario, duration_s, directory) in SCENARIOS.items():
        if args.quick and name == "busy_open_sea":
            duration_s, directory = 90.0, Path(f"{directory}_90")
        durations[name] = duration_s
        recordings[name], _ = ensure_recording(scenario, directory, duration_s, fresh=args.fresh)
        results[name] = criteria(run_and_evaluate(recordings[name]))
    strengths = plot_strengths(recordings["busy_open_sea"])
    text = report(results, strengths, durations, args.quick)
    for batch in args.batch:
        text += seeds_report(batch)
    print(text)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text, encoding="utf-8")
    if args.json:
        args.json.write_text(json.dumps({"criteria": results, "durations_s": durations, "radar_plot_strengths": strengths},
                                        indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
