"""Scoring Stone Soup runs with ``tdm.evaluate`` and tuning them by coordinate descent on one recording.

The tuning grid (:data:`GRID`) is searched by coordinate descent, not in full (a Stone Soup run
of the radar on busy_open_sea, 120 s, takes about half a minute on 2 cores, a centralised one over
a minute: the full grid, thousands of points per tracker, would take days): starting from the
settings nearest ours (:func:`start_setting`), each parameter in turn is set to the value of its
grid with the lowest GOSPA (c = 50 m) on the tuning recording, the others held; one pass over
the parameters, within a time budget per tracker (:data:`BUDGET_S`; parameters not reached keep
their start values, and the results file lists every point tried). The centralised trackers start
from the radar tracker's chosen setting of the same algorithm and descend over
:data:`PARAMETERS_CENTRAL` only.

Scoring: the tuning points are scored by :class:`Scorer`, which reads a recording's truth and
visibility once with ``tdm.evaluate``'s own reader and scores each run with ``tdm.evaluate``'s
own ``score`` (what :func:`tdm.evaluate.evaluate` does per sensor, without rereading the 1200
LiDAR sweeps per point); the reported figures are from :func:`tdm.evaluate.evaluate` itself.
"""

from __future__ import annotations

import json
import math
import shutil
import time
from dataclasses import replace
from pathlib import Path
from typing import Callable

import numpy as np

from benchmarks.stonesoup_trackers import TRACKER_SENSORS, Context, Setting, chunks, run_tracker
from tdm.detections import AisReport
from tdm.evaluate import evaluate
from tdm.io import read_manifest
from tdm.pipeline import TdmConfig

#: Files of a recording the evaluation reads (linked into each scoring directory).
LINKED = ("truth.jsonl", "scenario.yaml", "manifest.json", "ownship.jsonl", "lidar", "radar")
#: Metrics kept: (label, key, digits).
TABLE_METRICS = (("GOSPA c = 50 m, m", "gospa_m", 2),
                 ("GOSPA c = 10 m within LiDAR range, m", "gospa_within_lidar_range_c10_m", 2),
                 ("position RMSE, m", "position_rmse_m", 2), ("median position error, m", "median_position_error_m", 2),
                 ("detection rate", "detection_rate", 3), ("false targets / min", "false_targets_per_min", 2),
                 ("ID switches", "id_switches", 0), ("NEES (ideal 2)", "nees", 1))
#: Values tried per parameter; per tracker where the sensors differ (``lidar`` / radar-bearing trackers).
GRID = {
    "min_strength_db": {"lidar": (None,), "*": (13.0, None, 10.0, 15.0, 18.0)},
    "q_m2_s3": {"lidar": (0.1, 0.01, 1.0, 10.0), "*": (0.1, 0.01, 1.0)},
    "min_points": {"lidar": (3, 4, 6, 8), "*": (2, 3, 4)},
    "hold_periods": {"lidar": (2.0, 5.0, 10.0), "*": (1.0, 2.0, 3.0)},
    "delete_s": {"lidar": (1.0, 2.0, 4.0), "*": (4.0, 8.0, 15.0)},
    "clutter_scale": {"*": (0.01, 0.1, 1.0)},
    "prob_detect": {"*": (0.7, 0.9)},
}
#: Parameters of each algorithm, in the order coordinate descent visits them.
PARAMETERS = {"gnn": ("min_strength_db", "q_m2_s3", "min_points", "hold_periods", "delete_s"),
              "jpda": ("min_strength_db", "clutter_scale", "prob_detect", "q_m2_s3", "min_points", "hold_periods",
                       "delete_s")}
#: Parameters the centralised trackers descend over (from the radar tracker's chosen setting).
PARAMETERS_CENTRAL = ("q_m2_s3", "delete_s", "min_points")
#: Passes of coordinate descent over the parameters.
PASSES = 1
#: Tuning time budget per tracker, s: no new point is started after it.
BUDGET_S = {"lidar": 150.0, "radar": 360.0, "central": 200.0, "central_ais": 200.0}


def grid_values(parameter: str, name: str) -> tuple:
    """The values of ``parameter`` tried for tracker ``name``."""
    values = GRID[parameter]
    return values.get(name, values["*"])


def start_setting(algorithm: str, name: str, config: TdmConfig) -> Setting:
    """Coordinate descent's start: our confirmation count, holding (N - M + 1 scans) and coasting times.

    Radar-bearing trackers start with the strength gate at our ``weak_below_db`` (plots under it
    count half a hit in ours).
    """
    cfg = config.lidar_tracker if name == "lidar" else config.radar_tracker
    return Setting(algorithm=algorithm, q_m2_s3=0.1, min_points=cfg.confirm_m,
                   hold_periods=float(cfg.confirm_n - cfg.confirm_m + 1), delete_s=cfg.coast_s,
                   min_strength_db=None if name == "lidar" else config.radar_tracker.weak_below_db)


# ---- scoring ------------------------------------------------------------------------------------

def scoring_dir(recording: Path, out: Path) -> Path:
    """A directory ``tdm.evaluate.evaluate`` can read: the recording's files linked, an empty ``tdm/``."""
    if out.exists():
        shutil.rmtree(out)
    (out / "tdm").mkdir(parents=True)
    for name in LINKED:
        if (recording / name).exists():
            (out / name).symlink_to((recording / name).resolve())
    return out


def output_epochs(recording: Path, rate_hz: float) -> np.ndarray:
    """The output times of ``tdm run``: ``k / rate_hz`` for k = 1 .. floor(duration * rate), s."""
    duration_s = float(read_manifest(recording).get("duration_s"))
    return np.arange(1, int(np.floor(duration_s * rate_hz + 1e-9)) + 1) / rate_hz


def pick(metrics: dict) -> dict:
    """The :data:`TABLE_METRICS` of one metrics dict."""
    return {key: metrics.get(key) for _, key, _ in TABLE_METRICS}


def write_jsonl(path: Path, records: list[dict]) -> None:
    """Write ``records`` one JSON object a line."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", encoding="utf-8") as handle:
        for r in records:
            handle.write(json.dumps(r, separators=(", ", ": ")) + "\n")


def write_scoring_dir(recording: Path, out: Path, records: list[dict]) -> Path:
    """A scoring directory holding one tracker's lines.

    The lines go to ``sensor_tracks.jsonl`` (scored against the objects in range of the sensor
    named in them; ``central*``: of any sensor) and, without ``sensor``, to
    ``detected_targets.jsonl`` (which ``evaluate`` requires).
    """
    out = scoring_dir(recording, out)
    records = sorted(records, key=lambda r: r["t"])
    write_jsonl(out / "tdm" / "sensor_tracks.jsonl", records)
    write_jsonl(out / "tdm" / "detected_targets.jsonl",
                [{k: v for k, v in r.items() if k != "sensor"} for r in records])
    return out


def score_records(recording: Path, out: Path, records: list[dict]) -> dict:
    """Score one tracker's ``sensor_tracks.jsonl`` lines with :func:`tdm.evaluate.evaluate`: its per-sensor metrics."""
    if not records:
        return {}
    out = write_scoring_dir(recording, out, records)
    return pick(evaluate(out)["per_sensor"].get(records[0]["sensor"], {}))


class Scorer:
    """``tdm.evaluate``'s scoring of many runs on one recording, reading truth and visibility once.

    Parameters
    ----------
    recording : Path
    out : Path
        Scoring directory made from ``records`` (their times set the epochs, as in ``evaluate``).
    records : list of dict
        Any tracker's lines on the recording's output epochs.
    """

    def __init__(self, recording: Path, out: Path, records: list[dict]):
        from tdm.evaluate import _read_inputs
        from tdm.recording.land import read_land

        self.inputs = _read_inputs(write_scoring_dir(recording, out, records), {})
        self.land = read_land(Path(recording))
        masks = self.inputs["visible_by_sensor"].values()
        self.visible = np.logical_or.reduce(list(masks)) if masks else None

    def score(self, records: list[dict], name: str) -> dict:
        """The per-sensor metrics ``evaluate`` gives tracker ``name``'s lines (docs/formats.md schema)."""
        from tdm.eval_lines import reports_in_frame
        from tdm.eval_scoring import score
        from tdm.eval_truth import epoch_index
        from tdm.evaluate import DEFAULT_CUTOFF_M, DEFAULT_ORDER_P

        if not records:
            return {}
        inp = self.inputs
        columns = _columns(records, self.land)
        tracks = reports_in_frame(columns, inp["frame"])
        m = score(inp["truth"], inp["visible_by_sensor"].get(name, self.visible), tracks,
                  epoch_index(tracks["t"], inp["epochs"]), DEFAULT_CUTOFF_M, DEFAULT_ORDER_P,
                  float(inp["duration_s"]), inp["used"]["lidar_range_max_m"], with_series=False,
                  dont_care=inp["hidden_by_sensor"].get(name))
        return pick(m)


def _columns(records: list[dict], land) -> dict:
    """``tdm.eval_lines.read_report_columns`` of ``records`` (written to a file and read back, the same reader)."""
    import tempfile

    from tdm.eval_lines import read_report_columns
    from tdm.land import on_chart_land

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sensor_tracks.jsonl"
        write_jsonl(path, sorted(records, key=lambda r: r["t"]))
        columns = read_report_columns(path, with_sensor=True)
    columns["on_land"] = on_chart_land(land, columns["latitude"], columns["longitude"])
    return columns


class Runner:
    """Runs and scores Stone Soup trackers on one recording; remembers every (tracker, setting) scored.

    Parameters
    ----------
    recording : Path
    events : list
        :meth:`tdm.pipeline.DetectionStream.events` of the recording.
    frame : EnuFrame
        The stream's frame.
    ctx : Context
    rate_hz : float
        Output rate, Hz.
    workdir : Path
        Where the scoring directories go.
    fast : bool
        Score with :class:`Scorer` (tuning) rather than :func:`tdm.evaluate.evaluate` (reported figures).
    """

    def __init__(self, recording: Path, events: list, frame, ctx: Context, rate_hz: float, workdir: Path,
                 fast: bool = False):
        self.recording, self.frame, self.ctx, self.workdir = Path(recording), frame, ctx, Path(workdir)
        self.epochs = output_epochs(self.recording, rate_hz)
        self.fed = {name: chunks(events, sensors, ctx) for name, sensors in TRACKER_SENSORS.items()}
        self.fast = fast
        self.scorer: Scorer | None = None
        self.cache: dict[tuple[str, Setting], dict] = {}
        self.files: dict[tuple[str, Setting], Path] = {}
        self.walls: dict[tuple[str, Setting], float] = {}

    def metrics(self, name: str, setting: Setting) -> dict:
        """Metrics of tracker ``name`` at ``setting`` (run and scored once; the lines kept on disk)."""
        key = (name, setting)
        if key not in self.cache:
            records, self.walls[key] = run_tracker(self.fed[name], name, setting, self.ctx, self.epochs, self.frame)
            self.files[key] = self.workdir / "runs" / f"{setting.algorithm}_{name}_{len(self.files)}.jsonl"
            write_jsonl(self.files[key], records)
            if not self.fast:
                self.cache[key] = score_records(self.recording, self.workdir / f"ss_{setting.algorithm}_{name}",
                                                records)
                return self.cache[key]
            if self.scorer is None and records:
                self.scorer = Scorer(self.recording, self.workdir / "ss_scorer", records)
            self.cache[key] = self.scorer.score(records, name) if records else {}
        return self.cache[key]

    def evaluated(self, name: str, setting: Setting) -> dict:
        """Metrics of an already run (tracker, setting) from :func:`tdm.evaluate.evaluate` itself."""
        key = (name, setting)
        fast = self.metrics(name, setting)  # runs it when not yet run (a resumed tuning)
        if not self.fast:
            return fast
        with open(self.files[key], encoding="utf-8") as handle:
            records = [json.loads(line) for line in handle]
        return score_records(self.recording, self.workdir / f"ss_{setting.algorithm}_{name}", records)


def gospa_of(metrics: dict) -> float:
    """GOSPA (c = 50 m) of a metrics dict; inf when not scored (no tracks)."""
    value = metrics.get("gospa_m")
    return math.inf if value is None or not math.isfinite(value) else float(value)


def coordinate_descent(runner: Runner, name: str, start: Setting, parameters: tuple, budget_s: float,
                       log: Callable[[str], None] = print) -> tuple[Setting, list[tuple[str, object, float]]]:
    """Tune tracker ``name`` from ``start`` over :data:`GRID` by coordinate descent on GOSPA.

    Parameters
    ----------
    runner : Runner
    name : str
        Tracker (a key of ``TRACKER_SENSORS``).
    start : Setting
    parameters : tuple of str
        Visited in this order, :data:`PASSES` times.
    budget_s : float
        No new point is started after this long, s.

    Returns
    -------
    best : Setting
    trail : list of (parameter, value, GOSPA m)
        Every point tried, in order (``("budget", None, nan)`` where the budget stopped it).
    """
    t0 = time.perf_counter()
    best = start
    best_g = gospa_of(runner.metrics(name, best))
    trail: list[tuple[str, object, float]] = [("start", None, best_g)]
    for _ in range(PASSES):
        for parameter in parameters:
            for value in grid_values(parameter, name):
                candidate = replace(best, **{parameter: value})
                if (name, candidate) not in runner.cache and time.perf_counter() - t0 > budget_s:
                    trail.append(("budget", None, math.nan))
                    return best, trail
                g = gospa_of(runner.metrics(name, candidate))
                trail.append((parameter, value, g))
                log(f"  {start.algorithm} {name} {parameter}={value}: GOSPA {g:.2f} "
                    f"({time.perf_counter() - t0:.0f} s)")
                if g < best_g - 1e-9:
                    best, best_g = candidate, g
    return best, trail


# ---- clutter density estimate ------------------------------------------------------------------

def clutter_density_estimate(events: list, range_m: dict) -> dict:
    """Upper bounds of the clutter densities of the tuning recording, 1/m^2, truth-free.

    Every detection is counted as clutter: mean detections per scan over the disc the sensor
    covers (pi r^2). The JPDA grid scales these down (``clutter_scale``).

    Parameters
    ----------
    events : list
        The recording's detection stream events.
    range_m : dict
        ``lidar`` and ``radar`` coverage radius, m.
    """
    counts: dict[str, list[int]] = {"lidar": [], "radar": []}
    for _, sensor, payload in events:
        if sensor in counts and not isinstance(payload, AisReport):
            counts[sensor].append(len(payload))
    return {s: float(np.mean(c)) / (math.pi * range_m[s] ** 2) if c else 1e-9 for s, c in counts.items()}
