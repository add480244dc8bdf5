"""Our trackers against tuned Stone Soup trackers (GNN and JPDA) on the same detections, scored by GOSPA.

Usage::

    python benchmarks/stonesoup_compare.py [--quick] [--workdir /tmp/ss_work] [--duration 120] [--fresh]
                                           [--heldout crossing_silent_ship rough_sea_rain] [--json FILE]
                                           [--budget-scale 1] [--resume-log LOG] [--from-json FILE]
                                           [--out benchmarks/results/stonesoup_compare.md]

``--quick``: 30 s recordings, one held-out recording. ``--fresh``: render the recordings again.
``--resume-log``: take the trackers a cut run tuned from its printed output. ``--from-json``: only
rewrite the results file from a run's ``--json`` figures.

Recordings are rendered with ``raysim render`` into ``WORKDIR/ss_<short name>`` unless already
there with the asked duration. The tuning recording is busy_open_sea (the one ours was tuned
on); the held-out ones are crossing_silent_ship and rough_sea_rain.

- **ours**: ``tdm run`` (:func:`tdm.pipeline.run_tdm`, default :class:`~tdm.pipeline.TdmConfig`)
  then :func:`tdm.evaluate.evaluate`: the per-sensor tracks (LiDAR, radar) and the fused targets
  (LiDAR, radar and AIS, thesis eq. 3.2).
- **Stone Soup**: the same detections, read once with :class:`tdm.pipeline.DetectionStream` (the
  front ends of ``tdm run``), given the information ours uses (AIS position and velocity, radar
  plot strengths: :mod:`benchmarks.stonesoup_trackers`), to eight trackers: {GNN, JPDA} x
  {LiDAR, radar, central LiDAR+radar, central LiDAR+radar+AIS}. Each is tuned on the tuning
  recording by coordinate descent over its grid (:mod:`benchmarks.stonesoup_tuning`: process
  noise, ``min_points``, holding time, deletion time, strength gate; JPDA also clutter density
  and detection probability) for the lowest GOSPA, then run unchanged on the held-out recordings.
  Tracks are predicted to every output epoch and written as ``sensor_tracks.jsonl`` lines into a
  directory that links the recording, and scored by the same :func:`tdm.evaluate.evaluate`
  (per sensor: against the objects in that sensor's range; ``central*``: in range of any sensor,
  as our fused targets).

JPDA rather than GM-PHD as the stronger multi-target tracker: the scenes have a handful of
targets in light clutter, where JPDA's soft association is the textbook step up from GNN, and it
keeps labelled tracks (the evaluation counts ID switches and per-target errors); a GM-PHD filter
gives unlabelled components and would need a labelling scheme of its own.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import asdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.common import ensure_recording, publish  # noqa: E402
from benchmarks.stonesoup_report import intro_lines, note_lines, summary_rows  # noqa: E402
from benchmarks.stonesoup_trackers import TRACKER_SENSORS, Context, Setting, context_from  # noqa: E402
from benchmarks.stonesoup_tuning import (BUDGET_S, PARAMETERS, PARAMETERS_CENTRAL, Runner,  # noqa: E402
                                         clutter_density_estimate, coordinate_descent, pick, scoring_dir,
                                         start_setting)
from tdm.detections import AisReport, ReadStats  # noqa: E402
from tdm.evaluate import evaluate  # noqa: E402
from tdm.io import read_manifest, read_scenario  # noqa: E402
from tdm.pipeline import DetectionStream, TdmConfig, run_tdm  # noqa: E402

#: Tuning recording: (scenario file stem, directory name under the work directory).
TUNING = ("busy_open_sea", "ss_bos")
#: Held-out recordings.
HELDOUT = (("crossing_silent_ship", "ss_css"), ("rough_sea_rain", "ss_rsr"))
ALGORITHMS = ("gnn", "jpda")


def run_ours(recording: Path, workdir: Path, config: TdmConfig) -> tuple[dict, float]:
    """``tdm run`` + ``tdm evaluate`` into a scoring directory: ({fused, lidar, radar, ...: metrics}, wall time s)."""
    out = scoring_dir(recording, workdir / "ours")
    start = time.perf_counter()
    run_tdm(recording, out / "tdm", config)
    wall = time.perf_counter() - start
    m = evaluate(out)
    return {"fused": pick(m), **{s: pick(v) for s, v in m["per_sensor"].items()}}, wall


def sensor_geometry(recording: Path) -> tuple[dict, dict]:
    """Revolution period (s) and coverage radius (m) of the LiDAR and the radar, from scenario.yaml."""
    sensors = read_scenario(recording).get("sensors") or {}
    lidar, radar = sensors.get("lidar") or {}, sensors.get("radar") or {}
    period = {"lidar": 1.0 / float(lidar.get("rotation_hz", 10.0)), "radar": 60.0 / float(radar.get("rpm", 24.0))}
    range_m = {"lidar": float(lidar.get("range_max_m", 100.0)), "radar": float(radar.get("range_m", 1852.0))}
    return period, range_m


def read_events(recording: Path, config: TdmConfig) -> tuple[list, DetectionStream, dict]:
    """Every event of the recording's detection stream (front ends run once) and the counts per sensor."""
    stream = DetectionStream(recording, config, ReadStats())
    events = list(stream.events())
    counts: dict[str, int] = {}
    for _, sensor, payload in events:
        counts[sensor] = counts.get(sensor, 0) + (1 if isinstance(payload, AisReport) else len(payload))
    return events, stream, counts


def _recording_result(recording: Path, workdir: Path, config: TdmConfig, counts: dict) -> dict:
    ours, wall = run_ours(recording, workdir, config)
    return {"ours": ours, "ours_wall_s": wall, "detections": counts, "recording": str(recording),
            "duration_s": float(read_manifest(recording).get("duration_s")), "rate_hz": config.update_rate_hz}


def tune(recording: Path, workdir: Path, budget_scale: float = 1.0, done: dict | None = None) \
        -> tuple[dict, dict, Context, dict]:
    """Tune every Stone Soup tracker on ``recording`` (time budgets :data:`BUDGET_S` times ``budget_scale``).

    ``done``: {(algorithm, name): (setting, trail)} already tuned (by a cut run, :func:`read_log`).

    Returns
    -------
    result : dict
        ``ours``, ``stonesoup`` ({algorithm: {name: metrics at the chosen setting}}), ``wall_s``,
        ``detections``, ``duration_s``, ``rate_hz``.
    chosen : dict
        {algorithm: {name: Setting}}.
    ctx : Context
        The fixed inputs (clutter densities estimated here), reused on the held-out recordings.
    trails : dict
        {algorithm: {name: coordinate-descent trail}}.
    """
    config = TdmConfig.for_recording(recording)
    events, stream, counts = read_events(recording, config)
    result = _recording_result(recording, workdir, config, counts)
    period, range_m = sensor_geometry(recording)
    ctx = context_from(config, period, clutter_density_estimate(events, range_m),
                       2.0 * config.radar_tracker.max_speed_mps)
    runner = Runner(recording, events, stream.ownship.frame, ctx, config.update_rate_hz, workdir, fast=True)
    chosen: dict = {a: {} for a in ALGORITHMS}
    trails: dict = {a: {} for a in ALGORITHMS}
    for algorithm in ALGORITHMS:
        for name in TRACKER_SENSORS:
            if (algorithm, name) in (done or {}):
                chosen[algorithm][name], trails[algorithm][name] = done[(algorithm, name)]
                continue
            t0 = time.perf_counter()
            central = name.startswith("central")
            start = chosen[algorithm]["radar"] if central else start_setting(algorithm, name, config)
            chosen[algorithm][name], trails[algorithm][name] = coordinate_descent(
                runner, name, start, PARAMETERS_CENTRAL if central else PARAMETERS[algorithm],
                BUDGET_S[name] * budget_scale)
            print(f"tuned {algorithm} {name} in {time.perf_counter() - t0:.0f} s: {chosen[algorithm][name]}",
                  flush=True)
    result["stonesoup"] = {a: {n: runner.evaluated(n, s) for n, s in chosen[a].items()} for a in ALGORITHMS}
    for a in ALGORITHMS:  # the fast scorer must agree with tdm.evaluate.evaluate
        for n, s in chosen[a].items():
            fast, full = runner.metrics(n, s).get("gospa_m"), result["stonesoup"][a][n].get("gospa_m")
            if fast is not None and full is not None and abs(fast - full) > 1e-3 * max(1.0, abs(full)):
                print(f"warning: {a} {n}: fast scorer GOSPA {fast} != evaluate {full}", flush=True)
    result["wall_s"] = {a: {n: runner.walls[(n, s)] for n, s in chosen[a].items()} for a in ALGORITHMS}
    result["runs"] = len(runner.cache)
    return result, chosen, ctx, trails


def read_log(path: Path) -> dict:
    """The trackers a cut run tuned, from its printed log: {(algorithm, name): (setting, trail)}.

    The trail is the points the log printed (the start point's GOSPA is not printed: its first
    entry is the start value of the first parameter, or for centralised trackers missing).
    """
    done, trails = {}, {}
    for line in path.read_text(encoding="utf-8").splitlines():
        words = line.split()
        if line.startswith("  ") and len(words) >= 5 and words[3] == "GOSPA":
            parameter, value = words[2].rstrip(":").split("=", 1)
            parsed = None if value == "None" else (int(value) if parameter == "min_points" else float(value))
            trails.setdefault((words[0], words[1]), []).append((parameter, parsed, float(words[4])))
        elif line.startswith("tuned "):
            setting = eval(line.split(": ", 1)[1], {"Setting": Setting})  # our own repr of a Setting
            done[(words[1], words[2])] = (setting, trails.get((words[1], words[2]), []))
    return done


def held_out(recording: Path, workdir: Path, chosen: dict, ctx: Context) -> dict:
    """Ours and every Stone Soup tracker at its chosen setting on one held-out recording."""
    config = TdmConfig.for_recording(recording)
    events, stream, counts = read_events(recording, config)
    result = _recording_result(recording, workdir, config, counts)
    runner = Runner(recording, events, stream.ownship.frame, ctx, config.update_rate_hz, workdir)
    result["stonesoup"] = {a: {n: runner.metrics(n, s) for n, s in chosen[a].items()} for a in ALGORITHMS}
    result["wall_s"] = {a: {n: runner.walls[(n, s)] for n, s in chosen[a].items()} for a in ALGORITHMS}
    return result


def publish_figures(figures: dict, out: Path, json_path: Path | None) -> None:
    """Write the results file (and the JSON figures) from the figures of a run."""
    chosen = {a: {n: Setting(**s) for n, s in c.items()} for a, c in figures["chosen"].items()}
    ctx = Context(**figures["context"])
    results = figures["results"]
    import stonesoup

    intro = intro_lines(results, TUNING[0], ctx, figures.get("quick", False),
                        figures.get("stonesoup_version", stonesoup.__version__), figures["total_s"],
                        figures.get("run_note", ""))
    notes = note_lines(results, TUNING[0], chosen, figures["trails"], ctx)
    publish("Our trackers against tuned Stone Soup trackers (GNN and JPDA): the same detections and information",
            intro, summary_rows(results), out, json_path, figures, notes)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="30 s recordings, one held-out recording")
    parser.add_argument("--workdir", type=Path, default=Path("/tmp/ss_work"),
                        help="where the recordings are (or are rendered) and the scoring directories go")
    parser.add_argument("--duration", type=float, default=None, help="recording length, s (default 120; quick 30)")
    parser.add_argument("--fresh", action="store_true", help="render the recordings again")
    parser.add_argument("--heldout", nargs="*", default=None, help="held-out scenarios (default: all of HELDOUT)")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "stonesoup_compare.md")
    parser.add_argument("--json", type=Path, help="also write the figures as JSON")
    parser.add_argument("--budget-scale", type=float, default=1.0, help="multiply the tuning time budgets (BUDGET_S)")
    parser.add_argument("--resume-log", type=Path, help="take the trackers a cut run tuned from its printed log")
    parser.add_argument("--from-json", type=Path, help="only write the results file from a run's --json figures")
    args = parser.parse_args(argv)
    if args.from_json:
        publish_figures(json.loads(args.from_json.read_text(encoding="utf-8")), args.out, None)
        return 0
    duration_s = args.duration or (30.0 if args.quick else 120.0)
    suffix = "" if duration_s == 120.0 else f"_{duration_s:g}s"
    wanted = args.heldout if args.heldout is not None else [s for s, _ in HELDOUT[:1 if args.quick else None]]
    start = time.perf_counter()

    def recording(scenario: str, dirname: str) -> Path:
        rec, _ = ensure_recording(ROOT / "scenarios" / f"{scenario}.yaml", args.workdir / f"{dirname}{suffix}",
                                  duration_s, args.fresh)
        return rec

    results: dict = {}
    tuning_rec = recording(*TUNING)
    results[TUNING[0]], chosen, ctx, trails = tune(tuning_rec, args.workdir / f"{TUNING[1]}{suffix}_compare",
                                                   args.budget_scale,
                                                   read_log(args.resume_log) if args.resume_log else None)
    import stonesoup

    def write() -> None:
        figures = {"results": results, "chosen": {a: {n: asdict(s) for n, s in c.items()} for a, c in chosen.items()},
                   "context": asdict(ctx), "trails": trails, "total_s": time.perf_counter() - start,
                   "quick": args.quick, "stonesoup_version": stonesoup.__version__}
        publish_figures(figures, args.out, args.json)

    write()  # after each recording, so that a cut run leaves what it measured
    for scenario, dirname in HELDOUT:
        if scenario in wanted:
            results[scenario] = held_out(recording(scenario, dirname), args.workdir / f"{dirname}{suffix}_compare",
                                         chosen, ctx)
            print(f"held out {scenario} done at {time.perf_counter() - start:.0f} s", flush=True)
            write()
    return 0


if __name__ == "__main__":
    sys.exit(main())
