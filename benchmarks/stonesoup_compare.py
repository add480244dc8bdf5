"""Our trackers against Stone Soup's GNN + EKF on the same detections, scored by GOSPA (issue point 7b).

Usage::

    python benchmarks/stonesoup_compare.py [--quick] [--workdir /tmp] [--duration 120] [--fresh]
                                           [--q 0.001 0.01 ...] [--floor] [--json FILE]
                                           [--out benchmarks/results/stonesoup_compare.md]

``--quick``: 30 s recordings and q in {0.01, 1}. ``--fresh``: render the recordings again.

For each recording (busy_open_sea and crossing_silent_ship, rendered with ``raysim render`` into
``WORKDIR/ss_<scenario>`` unless already there with the asked duration):

- **ours**: ``tdm run`` (:func:`tdm.pipeline.run_tdm`, default :class:`~tdm.pipeline.TdmConfig`)
  then ``tdm evaluate`` (:func:`tdm.evaluate.evaluate`): the per-sensor tracks (LiDAR, radar)
  and the fused targets (LiDAR, radar and AIS);
- **Stone Soup** (1.9): the same detections, read once with :class:`tdm.pipeline.DetectionStream`
  (the front ends of ``tdm run``), fed to a ``MultiTargetTracker`` per position sensor and to
  centralised ones (every LiDAR and radar detection in one tracker; and the same with the AIS
  position reports as detections as well). Each tracker is Stone Soup's textbook GNN + EKF:

  - ``ExtendedKalmanPredictor`` on a nearly-constant-velocity model
    ``CombinedLinearGaussianTransitionModel([ConstantVelocity(q), ConstantVelocity(q)])``,
    state ``[east, v_east, north, v_north]``;
  - ``ExtendedKalmanUpdater``; every detection carries its own ``LinearGaussian`` measurement
    model whose covariance is the detection's ``position_cov_m2`` (AIS reports: the position
    variance our AIS tracker assumes), plus optionally our per-sensor floor (``--floor``);
  - ``DistanceHypothesiser`` with ``Mahalanobis`` and as missed distance our gate
    (sqrt of the chi-square(2) quantile of our ``gate_probability``), ``GNNWith2DAssignment``;
  - ``MultiMeasurementInitiator`` with ``min_points`` = our M: its holding tracks are deleted by
    ``UpdateTimeStepsDeleter(N - M + 1)`` (per sensor: N - M misses in a row survive, the nearest
    a step deleter gets to our M of N) or, centralised (scans of different rates), by
    ``UpdateTimeDeleter`` of (N - M + 1) radar revolutions; the prior velocity standard
    deviation is our new tracks' ``init_speed_sigma_mps``;
  - ``UpdateTimeDeleter`` of our ``coast_s`` (centralised: the radar's).

  Every one of these numbers is read from :class:`~tdm.pipeline.TdmConfig` (the tracker
  configurations ``tdm run`` uses), so the two sides stay alike when ours is retuned.

  Scans are fed as (scan end time, set of detections); each detection keeps its own time, to
  which the hypothesiser predicts. At every output epoch ``k / tdm.update_rate_hz`` the tracks
  the tracker holds are predicted to the epoch and written in the ``detected_targets.jsonl``
  schema (lat/lon through the stream's ``ownship.frame``) to ``sensor_tracks.jsonl`` with
  ``"sensor"`` = ``lidar``, ``radar``, ``central`` (LiDAR + radar) or ``central_ais``, in a
  directory that links the recording's truth, scenario, manifest and LiDAR sweeps, and is scored
  by the same :func:`tdm.evaluate.evaluate` (per sensor: against the objects in that sensor's
  range; ``central*``: against the objects in range of any sensor, as our fused targets).

The process-noise intensity q (m^2/s^3) is swept over ``--q`` and for each Stone Soup tracker the
q with the lowest GOSPA averaged over the recordings is reported (one setting for every recording,
as ours has one configuration); the whole sweep is in the notes.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import math
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.common import ensure_recording, machine_line, publish  # noqa: E402
from tdm.detections import AisReport, ReadStats  # noqa: E402
from tdm.evaluate import evaluate  # noqa: E402
from tdm.io import read_manifest, read_scenario  # noqa: E402
from tdm.metrics import DEFAULT_CUTOFF_M, DEFAULT_ORDER_P, GOSPA_ALPHA  # noqa: E402
from tdm.pipeline import DetectionStream, TdmConfig, run_tdm  # noqa: E402

#: Recordings compared: (scenario file stem, directory name under the work directory).
RECORDINGS = (("busy_open_sea", "ss_bos"), ("crossing_silent_ship", "ss_css"))
#: Process-noise intensities swept, m^2/s^3 (ConstantVelocity noise_diff_coeff).
Q_SWEEP = (0.001, 0.01, 0.1, 1.0, 10.0)
#: Files of a recording the evaluation reads (linked into each scoring directory).
LINKED = ("truth.jsonl", "scenario.yaml", "manifest.json", "ownship.jsonl", "lidar", "radar")
#: Stone Soup trackers: name -> sensors whose scans it takes.
STONESOUP_TRACKERS = {"lidar": ("lidar",), "radar": ("radar",), "central": ("lidar", "radar"),
                      "central_ais": ("lidar", "radar", "ais")}
#: Metrics in the table: (label, key, digits).
TABLE_METRICS = (("GOSPA, m", "gospa_m", 2), ("OSPA, m", "ospa_m", 2), ("position RMSE, m", "position_rmse_m", 2),
                 ("detection rate", "detection_rate", 3), ("false targets / min", "false_targets_per_min", 2),
                 ("ID switches", "id_switches", 0), ("NEES (ideal 2)", "nees", 1))
EPOCH = dt.datetime(2000, 1, 1)


@dataclass(frozen=True)
class SensorSettings:
    """Stone Soup settings of one sensor's tracker, taken from our tracker's configuration.

    Attributes
    ----------
    min_points : int
        Updates to confirm (our M).
    hold_misses : int
        Misses in a row a holding (tentative) track survives (our N - M).
    coast_s : float
        Delete a confirmed track not updated for this long, s (our ``coast_s``).
    missed_distance : float
        Mahalanobis gate: sqrt of the chi-square(2) quantile of our ``gate_probability``
        (-2 ln(1 - P), closed form for 2 degrees of freedom).
    prior_speed_sigma_mps : float
        Velocity standard deviation per axis of a new track, m/s (our ``init_speed_sigma_mps``).
    floor_m2 : float
        Added to each detection's covariance per axis, m^2 (0: the detection's own covariance;
        AIS reports carry none, so for AIS it is the whole variance: our AIS tracker's
        ``position_var_m2``).
    """

    min_points: int
    hold_misses: int
    coast_s: float
    missed_distance: float
    prior_speed_sigma_mps: float
    floor_m2: float = 0.0


def settings_from(config: TdmConfig, floor: bool) -> dict[str, SensorSettings]:
    """Settings mirroring our LiDAR and radar tracker configurations (and the AIS position variance).

    ``floor``: add our per-sensor ``position_floor_m2`` to each detection's covariance.
    """
    out = {}
    for sensor, cfg in (("lidar", config.lidar_tracker), ("radar", config.radar_tracker)):
        out[sensor] = SensorSettings(cfg.confirm_m, cfg.confirm_n - cfg.confirm_m, cfg.coast_s,
                                     math.sqrt(-2.0 * math.log(1.0 - cfg.gate_probability)), cfg.init_speed_sigma_mps,
                                     cfg.position_floor_m2 if floor else 0.0)
    out["ais"] = replace(out["radar"], floor_m2=config.ais_tracker.position_var_m2)
    return out


# ---- recordings and scoring directories -------------------------------------------------------

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


# ---- Stone Soup ---------------------------------------------------------------------------------

def _stamp(t_s: float) -> dt.datetime:
    return EPOCH + dt.timedelta(seconds=float(t_s))


def to_stonesoup(sensor: str, payload, floor_m2: float) -> list:
    """Stone Soup ``Detection`` s of one scan (or AIS report), each with its own measurement model and time."""
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.types.detection import Detection

    if isinstance(payload, AisReport):
        positions = payload.position_m[None, :]
        covs = np.zeros((1, 2, 2))
        times = np.array([payload.time_s])
    else:
        positions, covs, times = payload.position_m, payload.position_cov_m2, payload.time_s
    covs = 0.5 * (covs + np.swapaxes(covs, 1, 2)) + np.eye(2) * floor_m2
    return [Detection(positions[j].reshape(2, 1), timestamp=_stamp(times[j]),
                      measurement_model=LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=covs[j]),
                      metadata={"sensor": sensor})
            for j in range(positions.shape[0])]


def build_tracker(q: float, settings: SensorSettings, hold_s: float | None, scans):
    """Stone Soup's GNN + EKF ``MultiTargetTracker`` over ``scans`` (iterable of (datetime, set of Detection)).

    ``hold_s`` None: holding tracks deleted after ``settings.hold_misses`` misses in a row
    (``UpdateTimeStepsDeleter``); else when not updated for ``hold_s`` seconds (``UpdateTimeDeleter``).
    """
    from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
    from stonesoup.deleter.time import UpdateTimeDeleter, UpdateTimeStepsDeleter
    from stonesoup.hypothesiser.distance import DistanceHypothesiser
    from stonesoup.initiator.simple import MultiMeasurementInitiator
    from stonesoup.measures import Mahalanobis
    from stonesoup.models.transition.linear import CombinedLinearGaussianTransitionModel, ConstantVelocity
    from stonesoup.predictor.kalman import ExtendedKalmanPredictor
    from stonesoup.tracker.simple import MultiTargetTracker
    from stonesoup.types.state import GaussianState
    from stonesoup.updater.kalman import ExtendedKalmanUpdater

    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(q), ConstantVelocity(q)])
    predictor = ExtendedKalmanPredictor(transition)
    updater = ExtendedKalmanUpdater(measurement_model=None)  # each detection brings its own
    hypothesiser = DistanceHypothesiser(predictor, updater, measure=Mahalanobis(),
                                        missed_distance=settings.missed_distance)
    associator = GNNWith2DAssignment(hypothesiser)
    var_v = settings.prior_speed_sigma_mps ** 2
    prior = GaussianState(np.zeros((4, 1)), np.diag([0.0, var_v, 0.0, var_v]))
    hold_deleter = (UpdateTimeStepsDeleter(settings.hold_misses + 1) if hold_s is None
                    else UpdateTimeDeleter(dt.timedelta(seconds=hold_s)))
    initiator = MultiMeasurementInitiator(prior_state=prior, deleter=hold_deleter, data_associator=associator,
                                          updater=updater, min_points=settings.min_points)
    deleter = UpdateTimeDeleter(dt.timedelta(seconds=settings.coast_s))
    tracker = MultiTargetTracker(initiator=initiator, deleter=deleter, detector=scans, data_associator=associator,
                                 updater=updater)
    return tracker, predictor


def track_record(t_s: float, track_id: int, sensor: str, x: np.ndarray, p: np.ndarray, frame) -> dict:
    """One ``sensor_tracks.jsonl`` line (docs/formats.md schema) from a constant-velocity state (4,) and covariance (4, 4)."""
    east, ve, north, vn = (float(v) for v in x)
    lat, lon = frame.to_geodetic(east, north)
    cov = p[np.ix_((0, 2), (0, 2))]
    return {"t": round(float(t_s), 6), "target_id": int(track_id), "object_descriptor": "unknown",
            "longitude": round(float(lon), 8), "latitude": round(float(lat), 8),
            "cog_deg": round(float(np.mod(np.degrees(np.arctan2(ve, vn)), 360.0)), 3),
            "sog_mps": round(float(np.hypot(ve, vn)), 4), "cross_section_m2": 0.0, "sources": [sensor],
            "position_cov_m2": [[round(float(cov[0, 0]), 4), round(float(cov[0, 1]), 4)],
                                [round(float(cov[1, 0]), 4), round(float(cov[1, 1]), 4)]],
            "mmsi": None, "sensor": sensor}


def run_stonesoup(events: list, name: str, q: float, settings: dict[str, SensorSettings], epochs: np.ndarray,
                  frame, radar_period_s: float) -> tuple[list[dict], float]:
    """Run one Stone Soup tracker over the events of its sensors; its tracks at every epoch.

    Parameters
    ----------
    events : list of (t_s, sensor, payload)
        :meth:`tdm.pipeline.DetectionStream.events`, in time order.
    name : str
        A key of :data:`STONESOUP_TRACKERS`.
    q : float
        Process-noise intensity, m^2/s^3.
    settings : dict
        ``lidar`` and ``radar`` :class:`SensorSettings`.
    epochs : (E,) float
        Output times, s.
    frame : EnuFrame
        The stream's frame (for lat/lon).
    radar_period_s : float
        One radar revolution, s (centralised holding time).

    Returns
    -------
    records : list of dict
        ``sensor_tracks.jsonl`` lines with ``"sensor"`` = ``name``.
    wall_s : float
        Tracking time (without the front ends), s.
    """
    sensors = STONESOUP_TRACKERS[name]
    if len(sensors) == 1:
        s = settings[sensors[0]]
        hold_s = None
    else:  # centralised: radar's confirmation and coasting, holding measured in radar revolutions
        s = settings["radar"]
        hold_s = (s.hold_misses + 1) * radar_period_s
    floors = {k: v.floor_m2 for k, v in settings.items()}
    records: list[dict] = []
    ids: dict[str, int] = {}
    state = {"k": 0}
    tracker_box: list = []

    def emit_until(t_s: float) -> None:
        """Write the tracks at every epoch before ``t_s`` (the tracker holds all scans before it)."""
        tracker, predictor = tracker_box
        while state["k"] < epochs.size and epochs[state["k"]] < t_s:
            t_out = float(epochs[state["k"]])
            for track in tracker.tracks:
                pred = predictor.predict(track.state, timestamp=_stamp(t_out))
                tid = ids.setdefault(track.id, len(ids) + 1)
                records.append(track_record(t_out, tid, name, np.asarray(pred.state_vector, float).ravel(),
                                            np.asarray(pred.covar, float), frame))
            state["k"] += 1

    def scans():
        for t_end, sensor, payload in events:
            if sensor not in sensors:
                continue
            emit_until(t_end)
            detections = to_stonesoup(sensor, payload, floors[sensor])
            yield _stamp(t_end), set(detections)
        emit_until(math.inf)

    tracker, predictor = build_tracker(q, s, hold_s, scans())
    tracker_box[:] = [tracker, predictor]
    start = time.perf_counter()
    for _ in tracker:  # the scans generator writes the epochs between scans
        pass
    return records, time.perf_counter() - start


def write_jsonl(path: Path, records: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", encoding="utf-8") as handle:
        for r in records:
            handle.write(json.dumps(r, separators=(", ", ": ")) + "\n")


# ---- the comparison -----------------------------------------------------------------------------

def _pick(metrics: dict) -> dict:
    return {key: metrics.get(key) for _, key, _ in TABLE_METRICS}


def run_ours(recording: Path, workdir: Path, config: TdmConfig) -> tuple[dict, float]:
    """``tdm run`` + ``tdm evaluate`` into a scoring directory: {fused, lidar, radar} metrics; wall time s."""
    out = scoring_dir(recording, workdir / "ours")
    start = time.perf_counter()
    run_tdm(recording, out / "tdm", config)
    wall = time.perf_counter() - start
    m = evaluate(out)
    return {"fused": _pick(m), **{s: _pick(v) for s, v in m["per_sensor"].items()}}, wall


def read_events(recording: Path, config: TdmConfig) -> tuple[list, DetectionStream]:
    """Every event of the recording's detection stream (front ends run once)."""
    stream = DetectionStream(recording, config, ReadStats())
    return list(stream.events()), stream


def run_stonesoup_all(recording: Path, events: list, stream: DetectionStream, workdir: Path, q: float,
                      settings: dict[str, SensorSettings], rate_hz: float, names=tuple(STONESOUP_TRACKERS)) \
        -> tuple[dict, dict]:
    """Every Stone Soup tracker of :data:`STONESOUP_TRACKERS` at one q, scored: {name: metrics}, {name: wall s}."""
    epochs = output_epochs(recording, rate_hz)
    scenario = read_scenario(recording)
    radar_period_s = 60.0 / float(((scenario.get("sensors") or {}).get("radar") or {}).get("rpm", 24.0))
    out = scoring_dir(recording, workdir / f"stonesoup_q{q:g}")
    records, walls = [], {}
    for name in names:
        recs, walls[name] = run_stonesoup(events, name, q, settings, epochs, stream.ownship.frame, radar_period_s)
        records.extend(recs)
    central = next((n for n in ("central_ais", "central") if n in names), None)  # the "fused" file: not scored here
    write_jsonl(out / "tdm" / "detected_targets.jsonl",
                [{k: v for k, v in dict(r, sources=list(STONESOUP_TRACKERS[central])).items() if k != "sensor"}
                 for r in records if r["sensor"] == central])
    records.sort(key=lambda r: r["t"])  # the format's time order (tdm evaluate refuses lines going back in time)
    write_jsonl(out / "tdm" / "sensor_tracks.jsonl", records)
    m = evaluate(out)
    return {name: _pick(m["per_sensor"].get(name, {})) for name in names}, walls


def compare(recording: Path, workdir: Path, q_values=Q_SWEEP, floor: bool = False, config: TdmConfig | None = None,
            names=tuple(STONESOUP_TRACKERS)) -> dict:
    """Ours and Stone Soup on one recording.

    Returns
    -------
    dict
        ``ours``: {fused, lidar, radar, ais: metrics}; ``ours_wall_s``; ``stonesoup``: {q: {name:
        metrics}}; ``stonesoup_wall_s``: {q: {name: s}}; ``detections``: counts per sensor;
        ``duration_s``; ``rate_hz``.
    """
    recording = Path(recording)
    config = config or TdmConfig.for_recording(recording)
    rate_hz = config.update_rate_hz
    workdir = Path(workdir)
    ours, ours_wall = run_ours(recording, workdir, config)
    events, stream = read_events(recording, config)
    counts: dict[str, int] = {}
    for _, sensor, payload in events:
        counts[sensor] = counts.get(sensor, 0) + (1 if isinstance(payload, AisReport) else len(payload))
    settings = settings_from(config, floor)
    ss, walls = {}, {}
    for q in q_values:
        ss[q], walls[q] = run_stonesoup_all(recording, events, stream, workdir, q, settings, rate_hz, names)
    return {"ours": ours, "ours_wall_s": ours_wall, "stonesoup": ss, "stonesoup_wall_s": walls,
            "detections": counts, "duration_s": float(read_manifest(recording).get("duration_s")), "rate_hz": rate_hz,
            "settings": {k: v.__dict__ for k, v in settings.items()}}


# ---- the results file ---------------------------------------------------------------------------

def _fmt(value, digits: int) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value:.{digits}f}" if digits else f"{value:.0f}"


def best_q(results: dict[str, dict], name: str) -> float:
    """The q whose GOSPA of tracker ``name``, averaged over the recordings, is lowest (unscored ones skipped)."""
    qs = list(next(iter(results.values()))["stonesoup"].keys())

    def mean_gospa(q):
        values = [r["stonesoup"][q][name]["gospa_m"] for r in results.values()]
        values = [v for v in values if v is not None]
        return float(np.mean(values)) if values else math.inf

    return min(qs, key=mean_gospa)


#: Columns of the results: (side, tracker, label).
COLUMNS = (("ours", "radar", "ours radar"), ("ours", "lidar", "ours LiDAR"),
           ("ours", "fused", "ours fused (LiDAR+radar+AIS)"), ("stonesoup", "radar", "Stone Soup radar"),
           ("stonesoup", "lidar", "Stone Soup LiDAR"), ("stonesoup", "central", "Stone Soup central (LiDAR+radar)"),
           ("stonesoup", "central_ais", "Stone Soup central (LiDAR+radar+AIS positions)"))


def _metrics_of(res: dict, side: str, name: str, chosen: dict) -> dict:
    """The metrics of one column: ours by sensor, or Stone Soup's tracker at its chosen q."""
    return res["ours"].get(name, {}) if side == "ours" else res["stonesoup"][chosen[name]][name]


def _intro(results: dict, chosen: dict, q_values: tuple, floor: bool, quick: bool, version: str) -> list[str]:
    """The report's opening paragraphs: recordings, metric, both trackers' set-ups and the chosen q."""
    first = next(iter(results.values()))
    settings = first["settings"]
    return [
        machine_line("stonesoup_compare", quick) + f" Stone Soup {version}.",
        "",
        "Recordings: " + "; ".join(f"`scenarios/{s}.yaml` rendered with `raysim render --duration {r['duration_s']:g}` "
                                   f"(seed of the scenario; {r['detections'].get('lidar', 0)} LiDAR and "
                                   f"{r['detections'].get('radar', 0)} radar detections, {r['detections'].get('ais', 0)} "
                                   "AIS reports)" for s, r in results.items()) + ".",
        "",
        "Same detections (the front ends of `tdm run`, read through `tdm.pipeline.DetectionStream`), same metric "
        f"code (`tdm.evaluate.evaluate`: GOSPA/OSPA cut-off c = {DEFAULT_CUTOFF_M:g} m, p = {DEFAULT_ORDER_P:g}, "
        f"alpha = {GOSPA_ALPHA:g}, means over epochs every "
        f"{1 / first['rate_hz']:g} s). Per-sensor figures are scored against the objects in that sensor's range; "
        "fused and central ones against the objects in range of any sensor (AIS included, so the LiDAR+radar "
        "central tracker cannot see AIS-only targets). Lower is better.",
        "",
        "Stone Soup: `MultiTargetTracker`; `ExtendedKalmanPredictor` on "
        "`CombinedLinearGaussianTransitionModel([ConstantVelocity(q), ConstantVelocity(q)])`; `ExtendedKalmanUpdater` "
        "with each detection's own `LinearGaussian` (covariance = its `position_cov_m2`"
        f"{' + our floor' if floor else ''}; AIS {settings['ais']['floor_m2']:g} m^2 per axis, our AIS "
        "tracker's); `DistanceHypothesiser` (`Mahalanobis`, missed distance = our gate); `GNNWith2DAssignment`; "
        "`MultiMeasurementInitiator` (prior velocity sigma = our new tracks' speed sigma); `UpdateTimeDeleter`. Scans fed "
        "as (scan end time, detections at their own times); tracks predicted to each output epoch. From our "
        "configuration: " + "; ".join(
            f"{k}: min_points {v['min_points']}, holding track dropped after {v['hold_misses'] + 1} scans without "
            f"update (`UpdateTimeStepsDeleter`), coast {v['coast_s']:g} s, missed distance {v['missed_distance']:.2f}, "
            f"prior velocity sigma {v['prior_speed_sigma_mps']:g} m/s, floor {v['floor_m2']:g} m^2"
            for k, v in settings.items() if k != "ais")
        + "; central: radar's, holding time (hold + 1) radar revolutions. "
        f"q swept over {', '.join(f'{q:g}' for q in q_values)} m^2/s^3 and chosen per tracker by the lowest GOSPA "
        "averaged over the recordings: " + ", ".join(f"{k} q = {v:g}" for k, v in chosen.items()) + ".",
        "",
        ("Ours: `tdm run` defaults (`TdmConfig`): thesis EKF (course, speed, turn rate, cross-section), GNN, M of N, "
         "merge and speed checks per sensor; fused: thesis eq. 3.2 over the LiDAR, radar and AIS tracks."),
    ]


def _notes(results: dict, chosen: dict, q_values: tuple) -> list[str]:
    """Per-scenario tables, the Stone Soup q sweep and the wall times."""
    notes = []
    for scenario, res in results.items():
        notes += [f"## {scenario}, {res['duration_s']:g} s", "",
                  "| metric | " + " | ".join(label for _, _, label in COLUMNS) + " |",
                  "|---|" + "---:|" * len(COLUMNS)]
        for label, key, digits in TABLE_METRICS:
            notes.append(f"| {label} | " + " | ".join(_fmt(_metrics_of(res, side, name, chosen).get(key), digits)
                                                     for side, name, _ in COLUMNS) + " |")
        notes.append("")
    if any(_metrics_of(res, side, name, chosen).get("gospa_m") is None for res in results.values() for side, name, _ in COLUMNS):
        notes += ["\"-\": not scored (`tdm.evaluate` scores a sensor only when it output tracks).", ""]
    notes += ["## Stone Soup q sweep (GOSPA, m)", "",
              "| recording | q, m^2/s^3 | " + " | ".join(STONESOUP_TRACKERS) + " |",
              "|---|---:|" + "---:|" * len(STONESOUP_TRACKERS)]
    for scenario, res in results.items():
        for q in q_values:
            notes.append(f"| {scenario} | {q:g} | " + " | ".join(
                _fmt(res["stonesoup"][q][n].get("gospa_m"), 2) for n in STONESOUP_TRACKERS) + " |")
    notes += ["", "Wall time, s: ours = whole `tdm run` (front ends in 2 worker processes, trackers, fusion, "
              "writing); Stone Soup = tracking alone at the chosen q (front ends excluded). " + "; ".join(
                  f"{s}: ours {r['ours_wall_s']:.1f}, " + ", ".join(
                      f"{n} {r['stonesoup_wall_s'][chosen[n]][n]:.1f}" for n in STONESOUP_TRACKERS)
                  for s, r in results.items()) + ".", ""]
    return notes


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="30 s recordings, two q values")
    parser.add_argument("--workdir", type=Path, default=Path(tempfile.gettempdir()),
                        help="where the recordings are (or are rendered) and the scoring directories go")
    parser.add_argument("--duration", type=float, default=None, help="recording length, s (default 120; quick 30)")
    parser.add_argument("--fresh", action="store_true", help="render the recordings again")
    parser.add_argument("--q", type=float, nargs="+", default=None, help="process-noise intensities swept, m^2/s^3")
    parser.add_argument("--floor", action="store_true",
                        help="add our trackers' per-sensor variance floor to each detection's covariance")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "stonesoup_compare.md")
    parser.add_argument("--json", type=Path, help="also write the figures as JSON")
    args = parser.parse_args(argv)
    duration_s = args.duration or (30.0 if args.quick else 120.0)
    q_values = tuple(args.q) if args.q else ((0.01, 1.0) if args.quick else Q_SWEEP)
    results = {}
    for scenario, dirname in RECORDINGS:
        suffix = "" if duration_s == 120.0 else f"_{duration_s:g}s"
        rec, _ = ensure_recording(ROOT / "scenarios" / f"{scenario}.yaml", args.workdir / f"{dirname}{suffix}", duration_s,
                                  args.fresh)
        results[scenario] = compare(rec, args.workdir / f"{dirname}{suffix}_compare", q_values, args.floor)
        results[scenario]["recording"] = str(rec)
    import stonesoup

    chosen = {name: best_q(results, name) for name in STONESOUP_TRACKERS}
    rows = [(f"{scenario}: GOSPA, m, {label}", _fmt(_metrics_of(res, side, name, chosen).get("gospa_m"), 2))
            for scenario, res in results.items() for side, name, label in COLUMNS]
    intro = _intro(results, chosen, q_values, args.floor, args.quick, stonesoup.__version__)
    notes = _notes(results, chosen, q_values)
    figures = {s: {"ours": r["ours"], "stonesoup_chosen": {n: r["stonesoup"][chosen[n]][n] for n in STONESOUP_TRACKERS},
                   "stonesoup_sweep": {str(q): v for q, v in r["stonesoup"].items()}, "detections": r["detections"],
                   "duration_s": r["duration_s"]} for s, r in results.items()}
    figures["chosen_q"] = chosen
    publish("Our trackers against Stone Soup (GNN + EKF): GOSPA on the same detections", intro, rows, args.out,
            args.json, figures, notes)
    return 0


if __name__ == "__main__":
    sys.exit(main())
