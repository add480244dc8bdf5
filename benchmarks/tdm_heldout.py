"""The TDM judged on scenarios it was not tuned on (issue 22): the done-when criteria, every scenario and seed.

Usage::

    python benchmarks/tdm_heldout.py [--seeds 31-35] [--duration 300] [--scenarios NAME,...] [--work DIR]
                                     [--keep-seeds 31] [--rerun] [--out benchmarks/results/tdm_heldout.md]
                                     [--json benchmarks/results/tdm_heldout.json]

The TDM's configuration is tuned on ``busy_open_sea`` only; the other scenarios are held out. For each
scenario and seed (seed-major, so that a stopped run has every scenario for its first seeds): ``raysim
render`` with every sensor and without the bag and pictures (``render(derived=False)``: the TDM does not
read them) into ``WORK/<scenario>_<seed>``, ``tdm run`` and ``tdm evaluate`` with the default
configuration; the run's metrics.json is kept in ``WORK/metrics/``, the sensors' files are deleted
unless the seed is one of ``--keep-seeds`` (a 300 s recording is about 2 GB); a run whose metrics are there
is not done again and a kept recording is not rendered again (a stopped benchmark goes on where it
stopped). ``--rerun``: run the TDM and evaluate
again on the kept recordings (after a TDM change) and report those runs only. ``--json``: every run's
criteria (``{"generated", "seeds", "duration_s", "runs"}``), which benchmarks/tdm_criteria.py tabulates run by
run into benchmarks/results/tdm_criteria.md.

The criteria (issue 22, "Done when"), per run:

- every object that comes within 1.5 km of the own ship (truth) is reported within 10 s of coming into
  view (``latency_s`` of tdm/evaluate.py: from the start of the first run of in-view epochs lasting 5 s;
  never reported counts as missed);
- median fused position error <= 3 m within LiDAR range and <= 8 m beyond;
- at most 1 id switch per object;
- false targets <= 0.5 a minute;
- fused NEES in its 95 % interval for >= 0.8 of the matched (object, epoch) pairs.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import statistics
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.common import machine_line  # noqa: E402
from raysim.recording.jsonl import row_centre_xy  # noqa: E402
from raysim.render import render  # noqa: E402
from raysim.scenario import load_scenario, with_overrides  # noqa: E402
from tdm.eval_best_sensor import FIGURES  # noqa: E402
from tdm.evaluate import evaluate, write_metrics  # noqa: E402
from tdm.pipeline import TdmConfig, run_tdm  # noqa: E402

TUNED = "busy_open_sea"
HELD_OUT = ("crossing_silent_ship", "rough_sea_rain", "harbour_approach", "near_shore", "busy_port")
#: Objects that come this close to the own ship must be reported within LATENCY_MAX_S of coming into view, m.
NEAR_M = 1500.0
#: (key, label, limit, "max" or "min": the value must be at most / at least the limit)
CRITERIA = (
    ("latency_max_s", "latency from in view, max over objects within 1.5 km [s]", 10.0, "max"),
    ("missed_within_1500_m", "objects within 1.5 km never reported", 0, "max"),
    ("median_error_within_lidar_m", "median fused error within LiDAR range [m]", 3.0, "max"),
    ("median_error_beyond_lidar_m", "median fused error beyond LiDAR range [m]", 8.0, "max"),
    ("id_switches_max", "id switches of one object, max", 1, "max"),
    ("false_targets_per_min", "false targets per minute", 0.5, "max"),
    ("nees_fraction_in_95", "fused NEES in its 95 % interval (fraction)", 0.8, "min"),
)


def closest_approach_m(recording: Path) -> dict[str, float]:
    """Per truth object (by name): its centre's closest distance to the own ship over the run, m (truth.jsonl; the
    body origin in a recording from before truth carried the centre)."""
    own: dict[float, tuple[float, float]] = {}
    rows: list[tuple[str, float, float, float]] = []
    with open(recording / "truth.jsonl", encoding="utf-8") as f:
        for line in f:
            row = json.loads(line)
            if row["kind"] == "ownship":
                own[row["t"]] = (row["x"], row["y"])
            else:
                rows.append((row["name"], row["t"], *row_centre_xy(row)))
    closest: dict[str, float] = {}
    for name, t, x, y in rows:
        ox, oy = own[t]
        closest[name] = min(closest.get(name, math.inf), math.hypot(x - ox, y - oy))
    return closest


def run_criteria(metrics: dict, closest: dict[str, float]) -> dict:
    """The criteria's values of one run from its metrics.json and the objects' closest approaches."""
    near = [o for o in metrics["per_object"] if closest.get(o["name"], math.inf) <= NEAR_M]
    latencies = [o["latency_s"] for o in near]
    missed = [o["name"] for o in near if o["latency_s"] is None]
    found = [lat for lat in latencies if lat is not None]
    return {
        "latency_max_s": (math.inf if missed else max(found)) if near else 0.0,
        "missed_within_1500_m": len(missed),
        "missed_names": missed,
        "latency_by_object_s": {o["name"]: o["latency_s"] for o in near},
        "median_error_within_lidar_m": metrics["median_position_error_within_lidar_range_m"],
        "median_error_beyond_lidar_m": metrics["median_position_error_beyond_lidar_range_m"],
        "id_switches_max": metrics["id_switches_max_per_object"],
        "id_switches_by_object": {o["name"]: o["id_switches"] for o in metrics["per_object"] if o["id_switches"]},
        "id_switches_per_epoch_assignment_max": max(
            (o.get("id_switches_per_epoch_assignment", 0) for o in metrics["per_object"]), default=0),
        "false_targets_per_min": metrics["false_targets_per_min"],
        "nees_fraction_in_95": metrics["nees_fraction_in_95"],
        "gospa_m": metrics.get("gospa_m"),
        "gospa_within_lidar_c10_m": metrics.get("gospa_within_lidar_range_c10_m"),
        "latency_from_first_in_range_max_s": max(
            (o["latency_from_first_in_range_s"] for o in near if o["latency_from_first_in_range_s"] is not None),
            default=None),
        "cog_rmse_deg": metrics.get("cog_rmse_deg"),
        "nees_fraction_in_95_per_sensor": {s: m.get("nees_fraction_in_95") for s, m in metrics["per_sensor"].items()},
        "fusion_against_sensors": _versus(metrics.get("fusion_against_sensors")),
    }


def _versus(versus: dict | None) -> dict | None:
    """The summary of the fusion against its best sensor, and per object it loses on: the figures and reasons."""
    if versus is None:
        return None
    losing = [{"name": o["name"], "sensors": o["sensors"],
               "lost": {k: [v["fused"], v["best_sensor"], v["sensor"]] for k, v in o["figures"].items()
                        if not o["beats"][k]},
               "why_not": o["why_not"]} for o in versus["objects"] if not o["beats_best_on_all"]]
    return {**versus["summary"], "losing": losing}


def passes(value, limit, sense: str) -> bool | None:
    """Whether a criterion's value meets its limit (None: no value, e.g. no object within LiDAR range)."""
    if value is None:
        return None
    return value <= limit if sense == "max" else value >= limit


def one_run(scenario: str, seed: int, duration_s: float, work: Path, keep: bool, rerun: bool) -> dict | None:
    """Render (unless re-running), run the TDM, evaluate; returns the run's criteria (None: skipped)."""
    recording = work / f"{scenario}_{seed}"
    metrics_path = work / "metrics" / f"{scenario}_{seed}.json"
    if rerun and not (recording / "manifest.json").is_file():
        return None  # not kept: its metrics are of the TDM before the change
    if not rerun and metrics_path.is_file():
        return json.loads(metrics_path.read_text())
    if not (recording / "manifest.json").is_file():  # a kept recording is not rendered again
        s = with_overrides(load_scenario(ROOT / "scenarios" / f"{scenario}.yaml"), seed=seed, duration_s=duration_s)
        render(s, recording, progress=False, derived=False)
    run_tdm(recording, recording / "tdm", TdmConfig.for_recording(recording))
    metrics = evaluate(recording)
    write_metrics(recording, metrics)
    result = {"scenario": scenario, "seed": seed, "duration_s": duration_s,
              **run_criteria(metrics, closest_approach_m(recording))}
    metrics_path.parent.mkdir(parents=True, exist_ok=True)
    metrics_path.write_text(json.dumps(result, indent=1) + "\n")
    if not keep:
        shutil.rmtree(recording)
    return result


def _fmt(value) -> str:
    if value is None:
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "missed"
    return f"{value:.2f}" if isinstance(value, float) else str(value)


def report(runs: list[dict], scenarios: list[str], seeds: list[int], duration_s: float) -> str:
    """The markdown results: per scenario and criterion, the values over seeds and how many runs pass."""
    head = "| scenario | " + " | ".join(label for _, label, *_ in CRITERIA) + " |"
    lines = [head, "|---|" + "---:|" * len(CRITERIA),
             "| asked | " + " | ".join(("<= " if sense == "max" else ">= ") + str(limit)
                                       for _, _, limit, sense in CRITERIA) + " |"]
    for scenario in scenarios:
        mine = [r for r in runs if r["scenario"] == scenario]
        if not mine:
            continue
        cells = []
        for key, _, limit, sense in CRITERIA:
            values = [r[key] for r in mine]
            verdicts = [passes(v, limit, sense) for v in values]
            judged = [v for v in verdicts if v is not None]
            finite = [v for v in values if v is not None and not (isinstance(v, float) and math.isinf(v))]
            middle = _fmt(float(statistics.median(finite))) if finite else "-"
            spread = f" ({_fmt(float(min(finite)))}-{_fmt(float(max(finite)))})" if len(finite) > 1 else ""
            missed = sum(1 for v in values if isinstance(v, float) and math.isinf(v))
            cells.append(f"{middle}{spread}{f', {missed} missed' if missed else ''}; "
                         f"**{sum(judged)}/{len(judged)}**" if judged else f"{middle}; -")
        tag = " (tuned)" if scenario == TUNED else ""
        lines.append(f"| {scenario}{tag}, {len(mine)} seeds | " + " | ".join(cells) + " |")
    extra = ("latency_from_first_in_range_max_s", "gospa_m", "gospa_within_lidar_c10_m", "cog_rmse_deg")
    per_run = ["| scenario | seed | " + " | ".join(key for key, *_ in CRITERIA) + " | " + " | ".join(extra)
               + " | NEES in 95 % per sensor | missed within 1.5 km |",
               "|---|---:|" + "---:|" * (len(CRITERIA) + len(extra)) + "---|---|"]
    for r in runs:
        sensors = ", ".join(f"{s} {_fmt(v)}" for s, v in sorted(r.get("nees_fraction_in_95_per_sensor", {}).items()))
        per_run.append(f"| {r['scenario']} | {r['seed']} | " + " | ".join(_fmt(r[key]) for key, *_ in CRITERIA)
                       + " | " + " | ".join(_fmt(r.get(key)) for key in extra)
                       + f" | {sensors} | {', '.join(r['missed_names']) or '-'} |")
    intro = [machine_line("tdm_heldout", False), "",
             f"Default TDM configuration, tuned on {TUNED} only; every scenario rendered for {duration_s:g} s with "
             f"seeds {seeds[0]}-{seeds[-1]} (every sensor). A cell: the median over the seeds (min-max), then "
             "**how many runs meet the criterion / how many runs it applies to** (an error within LiDAR range "
             "applies only to runs with an object within it).", ""]
    return "\n".join(["# The TDM on held-out scenarios", "", *intro, *lines, "", *versus_report(runs, scenarios),
                      "## Every run", "", *per_run, ""])


def versus_report(runs: list[dict], scenarios: list[str]) -> list[str]:
    """Markdown: per scenario, the objects on which the fusion beats its best sensor, per figure; the losses."""
    names = [name for name, *_ in FIGURES]
    lines = ["## The fusion against its best sensor", "",
             "Per object seen by two or more sensors' own tracks (on at least 10 epochs each shared with the fused "
             "targets), the fused error against the best sensor's on the epochs both report it "
             "(tdm/eval_best_sensor.py). A cell: objects where the fusion is no worse / objects compared, summed "
             "over the seeds.", "",
             "| scenario | beats on all six | " + " | ".join(names) + " |", "|---|---:|" + "---:|" * len(names)]
    losses = []
    for scenario in scenarios:
        mine = [r for r in runs if r["scenario"] == scenario and r.get("fusion_against_sensors")]
        if not mine:
            continue
        v = [r["fusion_against_sensors"] for r in mine]
        cells = [f"{sum(x['per_figure'][n]['beats'] for x in v)}/{sum(x['per_figure'][n]['compared'] for x in v)}"
                 for n in names]
        lines.append(f"| {scenario}, {len(mine)} seeds | {sum(x['objects_fusion_beats_best_on_all'] for x in v)}/"
                     f"{sum(x['objects_compared'] for x in v)} | " + " | ".join(cells) + " |")
        for r in mine:
            for o in r["fusion_against_sensors"]["losing"]:
                lost = ", ".join(f"{k} {f:.3g} vs {b} {b_v:.3g}" for k, (f, b, b_v) in o["lost"].items())
                losses.append(f"| {scenario} | {r['seed']} | {o['name']} | {', '.join(o['sensors'])} | {lost} | "
                              f"{'; '.join(o['why_not'])} |")
    if losses:
        lines += ["", "Where the fusion loses (fused vs best sensor on their common epochs; the computed reason):", "",
                  "| scenario | seed | object | sensors | lost | why |", "|---|---:|---|---|---|---|", *losses]
    return lines + [""]


def _seeds(text: str) -> list[int]:
    if "-" in text:
        a, b = text.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(s) for s in text.split(",")]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="31-35")
    parser.add_argument("--duration", type=float, default=300.0)
    parser.add_argument("--scenarios", default=",".join((TUNED, *HELD_OUT)))
    parser.add_argument("--work", type=Path, default=Path("/tmp/tdm_heldout"))
    parser.add_argument("--keep-seeds", default="31", help="seeds whose recordings are kept for --rerun")
    parser.add_argument("--rerun", action="store_true", help="TDM and evaluation again on the kept recordings")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "tdm_heldout.md")
    parser.add_argument("--json", type=Path, default=ROOT / "benchmarks" / "results" / "tdm_heldout.json",
                        help="the runs' criteria as JSON (benchmarks/tdm_criteria.py tabulates them)")
    args = parser.parse_args(argv)
    seeds, scenarios, keep = _seeds(args.seeds), args.scenarios.split(","), set(_seeds(args.keep_seeds))
    runs = []
    for seed in seeds:
        for scenario in scenarios:
            result = one_run(scenario, seed, args.duration, args.work, seed in keep, args.rerun)
            if result is not None:
                runs.append(result)
                print(f"{scenario} seed {seed}: " + ", ".join(f"{k} {_fmt(result[k])}" for k, *_ in CRITERIA),
                      flush=True)
    text = report(runs, scenarios, seeds, args.duration)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text, encoding="utf-8")
    args.json.write_text(json.dumps({"generated": machine_line("tdm_heldout", False), "seeds": seeds,
                                     "duration_s": args.duration, "runs": runs}, indent=1) + "\n", encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
