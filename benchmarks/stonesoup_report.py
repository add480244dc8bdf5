"""The results file of benchmarks/stonesoup_compare.py: opening paragraphs, tables, chosen settings, grid."""

from __future__ import annotations

import json
import math
from dataclasses import asdict

from benchmarks.common import machine_line
from benchmarks.stonesoup_trackers import CHUNK_S, TRACKER_SENSORS, Context
from benchmarks.stonesoup_tuning import GRID, PARAMETERS, PASSES, TABLE_METRICS
from tdm.metrics import DEFAULT_CUTOFF_M, DEFAULT_ORDER_P, GOSPA_ALPHA

#: Columns of the tables: (side, algorithm or None, tracker, label).
COLUMNS = (("ours", None, "radar", "ours radar"), ("ours", None, "lidar", "ours LiDAR"),
           ("ours", None, "fused", "ours fused (LiDAR+radar+AIS)"),
           *((("stonesoup", a, n, f"SS {a.upper()} {label}") for a in ("gnn", "jpda")
              for n, label in (("radar", "radar"), ("lidar", "LiDAR"), ("central", "central L+R"),
                               ("central_ais", "central L+R+AIS")))))
#: Marker of the machine-readable chosen settings in the results file (read by the bench tests).
CHOSEN_MARKER = "chosen-settings-json:"


def fmt(value, digits: int) -> str:
    """``value`` with ``digits`` decimals; ``-`` when missing or not finite."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value:.{digits}f}" if digits else f"{value:.0f}"


def column_metrics(result: dict, side: str, algorithm: str | None, name: str) -> dict:
    """The metrics of one column of one recording's result."""
    if side == "ours":
        return result["ours"].get(name, {})
    return result["stonesoup"][algorithm][name]


def summary_rows(results: dict) -> list[tuple[str, str]]:
    """The summary table: GOSPA (c = 50 m) of every column on every recording."""
    return [(f"{scenario}: GOSPA, m, {label}", fmt(column_metrics(res, side, a, n).get("gospa_m"), 2))
            for scenario, res in results.items() for side, a, n, label in COLUMNS]


def intro_lines(results: dict, tuning: str, ctx: Context, quick: bool, version: str, total_s: float,
                run_note: str = "") -> list[str]:
    """The opening paragraphs: recordings, metric, what Stone Soup is given and how it is tuned.

    ``run_note``: how the run went, in place of its wall time (a run resumed from a cut one).
    """
    first = results[tuning]
    dens = ctx.clutter_density_per_m2
    return [
        machine_line("stonesoup_compare", quick) + f" Stone Soup {version}. "
        + (run_note or f"Whole benchmark: {total_s / 60:.0f} min."),
        "",
        "Recordings: " + "; ".join(
            f"`scenarios/{s}.yaml` rendered with `raysim render --duration {r['duration_s']:g}` ("
            f"{'tuning' if s == tuning else 'held out'}; {r['detections'].get('lidar', 0)} LiDAR and "
            f"{r['detections'].get('radar', 0)} radar detections, {r['detections'].get('ais', 0)} AIS reports)"
            for s, r in results.items()) + ".",
        "",
        "Same detections (the front ends of `tdm run`, read through `tdm.pipeline.DetectionStream`), same metric "
        f"code (`tdm.evaluate.evaluate`: GOSPA cut-off c = {DEFAULT_CUTOFF_M:g} m, p = {DEFAULT_ORDER_P:g}, "
        f"alpha = {GOSPA_ALPHA:g}, means over epochs every {1 / first['rate_hz']:g} s; also GOSPA at c = 10 m over "
        "the objects within LiDAR range). Per-sensor figures are scored against the objects in that sensor's range; "
        "fused and central ones against the objects in range of any sensor (AIS included, so the LiDAR+radar "
        "central trackers cannot see AIS-only targets). Lower is better for all but the detection rate.",
        "",
        "Stone Soup (benchmarks/stonesoup_trackers.py): state [east, v_east, north, v_north], "
        "`CombinedLinearGaussianTransitionModel([ConstantVelocity(q)] * 2)`, `ExtendedKalmanPredictor`/`Updater`; "
        "each LiDAR/radar detection a `LinearGaussian` on (east, north) with its own covariance; **AIS reports a "
        "4-D `LinearGaussian` on position and velocity** (SOG/COG to velocity, covariances from our AIS tracker's "
        f"variances: position {ctx.ais_position_var_m2:g} m^2, SOG {ctx.ais_sog_var_mps2:.3f} (m/s)^2, COG "
        f"{ctx.ais_cog_var_rad2:.2e} rad^2; position only below our AIS COG speed or without COG); **plot strengths "
        "as a seeding gate**: a radar plot may start a track only when its `strength_db` >= s and its beam fill >= "
        f"our {ctx.min_beam_fill} (a `SimpleMeasurementInitiator` subclass inside `MultiMeasurementInitiator`), every "
        "plot may update; s on the grid (none = no gate). GNN: `DistanceHypothesiser` (`Mahalanobis`, missed "
        f"distance {ctx.missed_distance:.2f} = our gate) + `GNNWith2DAssignment` + `MultiTargetTracker`. JPDA: "
        f"`PDAHypothesiser` (prob_gate {ctx.gate_probability:g}; clutter density and detection probability per "
        "sensor) + `JPDA` + `MultiTargetMixtureTracker`; clutter densities = grid factor x the tuning recording's "
        f"detections per scan over the covered disc (every detection counted as clutter, truth not used): LiDAR "
        f"{dens['lidar']:.2e}, radar {dens['radar']:.2e} per m^2, AIS the radar's over a "
        f"{math.sqrt(dens['radar'] / ctx.ais_clutter_density):g} m/s square of velocities. Both: "
        "`MultiMeasurementInitiator` (GNN on holding tracks, prior velocity sigma = our new tracks'), its holding "
        "tracks deleted by `UpdateTimeDeleter` of hold x the slowest sensor's revolution, tracks by "
        "`UpdateTimeDeleter` of delete_s. Detections sorted by their own times and fed in one-sensor chunks of "
        f"at most {CHUNK_S['lidar']:g} s (LiDAR) or {CHUNK_S['radar']:g} s (radar), one scan per chunk (no "
        "prediction goes back in time; Stone Soup gets each radar plot a chunk after it is measured, ours a sweep "
        "when it ends); tracks predicted to each output epoch.",
        "",
        f"Tuning: on {tuning} only, per tracker, coordinate descent ({PASSES} pass) over the grid in the notes from "
        "our confirmation count, holding (N - M + 1 scans) and coasting time, q = 0.1, no strength gate; the "
        "setting with the lowest GOSPA (c = 50 m) is kept and run unchanged on the held-out recordings.",
        "",
        "Ours: `tdm run` defaults (`TdmConfig`, tuned on busy_open_sea): thesis EKF (course, speed, turn rate, "
        "cross-section), GNN, M of N with strength-weighted hits, merge and speed checks per sensor; fused: thesis "
        "eq. 3.2 over the LiDAR, radar and AIS tracks.",
    ]


def metric_table(res: dict) -> list[str]:
    """One recording's table: metrics x columns."""
    lines = ["| metric | " + " | ".join(label for *_, label in COLUMNS) + " |", "|---|" + "---:|" * len(COLUMNS)]
    for label, key, digits in TABLE_METRICS:
        lines.append(f"| {label} | " + " | ".join(fmt(column_metrics(res, side, a, n).get(key), digits)
                                                 for side, a, n, _ in COLUMNS) + " |")
    return lines


def _setting_text(setting) -> str:
    """A chosen setting in words."""
    s = asdict(setting)
    gate = "none" if s["min_strength_db"] is None else f"{s['min_strength_db']:g} dB"
    text = (f"q {s['q_m2_s3']:g} m^2/s^3, min_points {s['min_points']}, hold {s['hold_periods']:g} rev, "
            f"delete {s['delete_s']:g} s, strength gate {gate}")
    if s["algorithm"] == "jpda":
        text += f", clutter x{s['clutter_scale']:g}, Pd {s['prob_detect']:g}"
    return text


def note_lines(results: dict, tuning: str, chosen: dict, trails: dict, ctx: Context) -> list[str]:
    """Tables (tuning, then held out), the chosen settings, the grid and the descent trails, wall times.

    The chosen settings and the context are also written as one JSON comment (after
    :data:`CHOSEN_MARKER`), which the bench tests read.
    """
    notes = [f"## Tuning recording: {tuning}, {results[tuning]['duration_s']:g} s "
             f"({results[tuning].get('runs', 0)} Stone Soup runs scored)", "", *metric_table(results[tuning]), ""]
    for scenario, res in results.items():
        if scenario != tuning:
            notes += [f"## Held out: {scenario}, {res['duration_s']:g} s (settings unchanged)", "",
                      *metric_table(res), ""]
    notes += ["\"-\": not scored (no tracks output).", "",
              "## Chosen settings (lowest GOSPA on the tuning recording)", "", "| tracker | setting |", "|---|---|"]
    notes += [f"| {a.upper()} {n} | {_setting_text(s)} |" for a, c in chosen.items() for n, s in c.items()]
    machine = {"chosen": {a: {n: asdict(s) for n, s in c.items()} for a, c in chosen.items()}, "context": asdict(ctx)}
    notes += ["", f"<!-- {CHOSEN_MARKER} {json.dumps(machine, separators=(',', ':'))} -->", "",
              "## Grid", "", "| parameter | LiDAR | radar, central |", "|---|---|---|"]
    for parameter, values in GRID.items():
        notes.append(f"| {parameter} | {', '.join(map(str, values.get('lidar', values['*'])))} | "
                     f"{', '.join(map(str, values['*']))} |")
    notes += ["", "Parameters per algorithm (descent order): " + "; ".join(f"{a}: {', '.join(p)}"
                                                                        for a, p in PARAMETERS.items()) + ".",
              "", "## Descent trails (GOSPA c = 50 m on the tuning recording)", ""]
    for a, c in trails.items():
        for n, trail in c.items():
            notes.append(f"- {a.upper()} {n}: " + ", ".join(
                f"start {g:.2f}" if p == "start" else "time budget reached" if p == "budget" else f"{p}={v}: {g:.2f}"
                for p, v, g in trail))
    notes += ["", "Wall time, s: ours = whole `tdm run` (front ends in 2 worker processes, trackers, fusion, "
              "writing); Stone Soup = tracking alone at the chosen setting (front ends excluded). " + "; ".join(
                  f"{s}: ours {r['ours_wall_s']:.1f}, " + ", ".join(
                      f"{a.upper()} {n} {r['wall_s'][a][n]:.1f}" for a in r["wall_s"] for n in TRACKER_SENSORS)
                  for s, r in results.items()) + ".", ""]
    return notes
