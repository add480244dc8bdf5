"""Scoring the TDM's detected targets against a recording's ground truth.

Reads ``RECORDING/tdm/detected_targets.jsonl`` (and ``sensor_tracks.jsonl`` when present),
``truth.jsonl``, ``scenario.yaml``, ``manifest.json`` and the LiDAR sweeps' ``object_id``
(truth: evaluation only, never detection), and returns the metrics that
``RECORDING/tdm/metrics.json`` holds (docs/contracts.md, "Recording directory").

Definitions (also returned under ``"definitions"``):

Frame
    Local ENU metres (:class:`tdm.frames.EnuFrame`, transverse Mercator) centred on the own
    ship's first truth position; truth and targets are both converted from lat/lon with it.
Epochs
    The TDM's output times: a grid every ``1 / tdm.update_rate_hz`` s (scenario.yaml,
    default 1 Hz) whose phase is that of the first reported time (0 when nothing is
    reported), from the truth's first to its last sample, united with every reported time
    (rounded to 1 us). An epoch without reports is one where the TDM reported nothing.
Truth at an epoch
    Positions and SOG interpolated linearly between the 0.1 s truth samples; COG and the AIS
    flag from the nearest sample. An object exists between its first and last sample. The
    own ship (kind ``ownship``) is never a target; every other kind (ship, iceberg, buoy,
    mesh, ...) is.
In range (visible)
    At epoch t an object is in range when any rendered sensor could see it: radar:
    distance from the own ship <= ``sensors.radar.range_m`` and, when the sweeps carry
    ``object_id`` / ``object_spokes``, reached by the rays of at least 3 spokes of a
    revolution (not hidden behind another object or below the radar horizon) whose time of
    seeing it overlaps t +- 0.5 s: from the beam's pass over the object to one revolution
    later (the next pass); LiDAR: hit by at least one
    LiDAR point whose time is within +-0.5 s of t (``object_id`` of the sweeps; if the
    sweeps carry no ``object_id``: distance <= ``sensors.lidar.range_max_m``); AIS: truth
    ``ais`` true, distance <= ``sensors.ais.range_m`` and a position report of the object's
    MMSI received in ``ais/ais.nmea`` within the last 180 s (``AIS_IN_VIEW_S``, the longest
    nominal reporting interval of ITU-R M.1371; before its first report no receiver knows of the
    ship; without the file or truth MMSIs, the flag and distance alone). A sensor counts when it is in the
    manifest's ``sensors_rendered`` (or, without that key, enabled in the scenario). A
    missing radar/AIS range means no range limit. An object becomes visible at the first
    epoch it is in range.
Matching
    Per epoch, optimal assignment (``scipy.optimize.linear_sum_assignment``, cost
    ``min(d, c)^p`` on ENU position distance d) of all reported targets to the in-range
    truth objects; pairs at ``d >= c`` are not matched (:mod:`tdm.metrics`).
OSPA, GOSPA
    Per epoch between the in-range truth set and the reported set (:mod:`tdm.metrics`,
    docs/reference.md section 5; GOSPA alpha = 2); ``ospa_m`` and ``gospa_m`` are means over
    all epochs (an epoch with nothing in range and nothing reported scores 0).
Errors
    Over matched pairs, error = target - truth: ``position_rmse_m``,
    ``median_position_error_m`` (also split by the truth object's distance from the own
    ship: ``<=`` / ``>`` ``sensors.lidar.range_max_m``, default 100 m, docs/reference.md section 2),
    ``sog_rmse_mps``, ``cog_rmse_deg`` (difference wrapped to [-180, 180); only pairs whose
    truth SOG > 0.5 m/s). Pairs whose reported value is null are skipped.
Detection
    ``detection_rate`` = matched (object, epoch) pairs / in-range (object, epoch) pairs.
    Detection latency of an object = time of its first matched epoch - time it came into
    view (not less than 0): the first epoch of its first run of consecutive in-range epochs
    lasting at least 5 s (``MIN_IN_VIEW_S``; the first in-range epoch if none lasts so long);
    null when it was visible but never matched (it is then in ``missed_objects``). Per
    object, ``latency_from_first_in_range_s`` counts from the first in-range epoch instead.
    ``detection_latency_max_s`` is over the objects matched at least once.
Hidden objects ("don't care")
    An object within a sensor's range that the sensor's ray truth says it cannot see
    (radar sweeps' ``object_id``, LiDAR points' ``object_id``: occluded, below the horizon;
    for the AIS, a ship none of whose reports has been received for 180 s or yet)
    and that no other sensor sees is neither to be found nor a false alarm: at each epoch
    the reports are assigned (same cost and cut-off) to the in-range and the hidden
    objects together, and those given to hidden objects are ignored (``ignored_reports``),
    the MOT/KITTI "don't care" convention. A tracker that coasts through an occlusion is
    not punished for it.
Land
    A report whose position lies on the recording's land (``land.geojson``, the polygons
    themselves, boundary included; no file: no land) is never matched and never ignored: it is
    false even next to an object. ``targets_on_land`` counts the target ids reported on land at
    least once, ``reports_on_land`` the (target, epoch) reports on land (both also per sensor).
False targets
    A target id is false when it is matched at fewer than half of the epochs it is
    reported at (ignored reports not counted); ``false_targets_per_min`` = number of false
    ids / (manifest ``duration_s`` / 60). ``false_reports_per_min`` = unmatched, not
    ignored (target, epoch) reports per minute.
ID switches
    Per truth object, the number of changes of its matched target id between its consecutive
    matched epochs (gaps do not count as switches), the matching being the CLEAR MOT
    correspondence (Bernardin and Stiefelhagen 2008; py-motmetrics): an object keeps its last
    target while that target is reported within the cut-off of it, and the rest are assigned
    optimally (:mod:`tdm.eval_identity`); ``id_switches`` is the total,
    ``id_switches_max_per_object`` the largest. ``id_switches_per_epoch_assignment``: the same
    count on the optimal assignment at each epoch (the errors' matching; the count of
    2026-11-29 and before), which also counts the hand-overs of two targets between two objects
    each about as far from both.
NEES
    Per matched pair, ``e^T P^-1 e`` with e the 2-D ENU position error and P the reported
    ``position_cov_m2`` (pairs without a positive-definite P are skipped); ``nees`` is the mean
    (ideal 2), ``nees_fraction_in_95`` the fraction inside the two-sided 95 % interval of
    chi-square(2): [-2 ln 0.975, -2 ln 0.025] = [0.0506, 7.378] (ideal 0.95).
Classification
    ``classification_accuracy``: matched pairs whose ``object_descriptor`` is the truth
    kind's (ship -> "vessel", iceberg -> "iceberg") over matched pairs of those kinds.
Per sensor
    ``per_sensor[s]``: the same metrics for the tracks of sensor s in ``sensor_tracks.jsonl``,
    against the objects in range of that sensor alone (any sensor's when s is not one of
    lidar/radar/ais or was not rendered); without series, definitions or per_sensor.

Numbers in the returned dict are rounded to 6 significant digits; NaN and infinities are
``None`` (null in JSON).

Reading (memory flat in the recording's length): truth.jsonl and the reports are read line by line
and checked (:mod:`tdm.eval_lines`, :mod:`tdm.eval_truth`); of the 10 Hz truth only the samples
around the epochs are kept; the sweeps are read one at a time (:mod:`tdm.eval_visibility`). A
broken input is a :class:`tdm.errors.RecordingError` (docs/formats.md, "What tdm evaluate
refuses"); a sweep file cut short is a warning, counted under ``"warnings"`` (only present then).

Modules: :mod:`tdm.eval_params` (manifest and scenario values), :mod:`tdm.eval_truth` (truth,
epochs), :mod:`tdm.eval_visibility` (in range), :mod:`tdm.eval_scoring` (the metrics),
:mod:`tdm.eval_best_sensor` (the fusion against its best sensor, per object),
:mod:`tdm.eval_report` (metrics.json, table); this module puts them together.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tdm.errors import RecordingError
from tdm.eval_lines import read_report_columns, read_reports, reports_in_frame
from tdm.eval_params import DEFAULT_LIDAR_RANGE_M, DEFAULT_UPDATE_RATE_HZ, SENSORS, read_params
from tdm.eval_best_sensor import fusion_against_sensors
from tdm.eval_report import FULL_PRECISION_DIGITS, FULL_PRECISION_KEYS, SIGNIFICANT_DIGITS, _clean, format_table, \
    write_metrics
from tdm.eval_scoring import DESCRIPTOR_OF_KIND, MIN_IN_VIEW_S, MOVING_SOG_MPS, NEES_95_INTERVAL, score, subset
from tdm.eval_scoring import sustained_start as _sustained_start
from tdm.eval_truth import EPOCH_DECIMALS, TRUTH_TIME_TOLERANCE_S, TruthAtEpochs, check_cell_count, \
    check_epoch_count, epoch_grid, epoch_index, read_truth_enu, read_truth_samples, truth_at, truth_enu_and_span, \
    truth_span
from tdm.eval_visibility import AIS_IN_VIEW_S, RADAR_VISIBLE_MIN_SPOKES, VISIBLE_WINDOW_S, ais_reception_times, \
    visibility
from tdm.io import read_manifest, read_scenario
from tdm.land import on_chart_land
from tdm.metrics import DEFAULT_CUTOFF_M, DEFAULT_ORDER_P, GOSPA_ALPHA
from tdm.recording.land import read_land
from tdm.recording.manifest import start_time_unix_s

__all__ = ["evaluate", "write_metrics", "format_table", "read_truth_enu", "read_reports",
           "TruthAtEpochs", "DEFINITIONS",
           # constants of the modules above, importable from here as before the split
           "DEFAULT_LIDAR_RANGE_M", "DEFAULT_UPDATE_RATE_HZ", "SENSORS", "FULL_PRECISION_DIGITS", "FULL_PRECISION_KEYS",
           "SIGNIFICANT_DIGITS", "DESCRIPTOR_OF_KIND", "MIN_IN_VIEW_S", "NEES_95_INTERVAL", "EPOCH_DECIMALS",
           "TRUTH_TIME_TOLERANCE_S", "RADAR_VISIBLE_MIN_SPOKES", "VISIBLE_WINDOW_S", "MOVING_SOG_MPS",
           "AIS_IN_VIEW_S"]

DEFINITIONS = {
    "frame": "ENU metres, transverse Mercator centred on the own ship's first truth position",
    "epochs": "every 1/tdm.update_rate_hz s, phase of the first reported time, over the truth's span, "
              "united with all reported times",
    "truth_at_epoch": "position and SOG linearly interpolated in the 0.1 s truth, COG and AIS flag nearest; "
                      "own ship excluded",
    "in_range": "radar: distance <= radar range_m and, if the sweeps carry object_id, reached on >= 3 spokes "
                "of a revolution, seen from the beam's pass over it to the next pass, within +-0.5 s; "
                "lidar: hit by a LiDAR point within +-0.5 s (object_id); ais: truth ais, distance <= ais range_m and a "
                "position report of its MMSI received within the last 180 s (ais/ais.nmea); any rendered sensor",
    "matching": "per epoch, linear_sum_assignment on min(d, c)^p of targets to in-range truth; pairs with d >= c "
                "unmatched",
    "ospa_m": "mean over epochs of OSPA (Schuhmacher 2008) on positions, cut-off c, order p",
    "gospa_m": "mean over epochs of GOSPA (Rahmathullah 2017, alpha 2); gospa_localisation_m, "
               "gospa_missed_mean, gospa_false_mean are the means of its terms",
    "gospa_within_lidar_range_c10_m": "mean over epochs of GOSPA with c = 10 m (alpha 2, the same p) over the "
                                      "in-range objects and the reports within the LiDAR's range of the own ship",
    "position_rmse_m": "RMS of ENU position error over matched pairs",
    "median_position_error_m": "median over matched pairs; _within/_beyond_lidar_range_m split by truth distance "
                               "from own ship vs lidar range_max_m",
    "cog_rmse_deg": "RMS of wrapped COG difference over matched pairs with truth SOG > 0.5 m/s",
    "sog_rmse_mps": "RMS of SOG difference over matched pairs",
    "detection_rate": "matched (object, epoch) pairs / in-range (object, epoch) pairs",
    "detection_latency_s": "per object: first matched epoch - start of the first run of in-range epochs lasting "
                           ">= 5 s (at least 0; the first in-range epoch if no run is so long); null when never "
                           "matched; detection_latency_from_first_in_range_max_s: the largest over objects of the "
                           "first matched epoch - the first in-range epoch (per_object latency_from_first_in_range_s)",
    "false_targets_per_min": "target ids matched at fewer than half of their reported epochs, per minute of "
                             "manifest duration",
    "false_reports_per_min": "unmatched (target, epoch) reports per minute, ignored ones not counted",
    "targets_on_land": "target ids reported on the recording's land (land.geojson, boundary included) at least "
                      "once; a report on land is never matched nor ignored: it is false even near an object "
                      "(reports_on_land: such (target, epoch) reports)",
    "ignored_reports": "reports assigned to objects within a sensor's range but hidden from every sensor (ray "
                       "truth): neither matched nor false",
    "id_switches": "total over objects of changes of matched target id between consecutive matched epochs, "
                   "on the CLEAR MOT correspondence (a kept target is not re-assigned while within the cut-off)",
    "id_switches_per_epoch_assignment": "the same count on the optimal assignment at each epoch",
    "nees": "mean of e^T P^-1 e over matched pairs (ideal 2); nees_fraction_in_95: inside [0.0506, 7.378]",
    "classification_accuracy": "matched ship/iceberg pairs whose descriptor is vessel/iceberg",
    "per_sensor": "same metrics per sensor of sensor_tracks.jsonl against that sensor's in-range objects",
    "fusion_against_sensors": "per object reported by two or more sensors' tracks on >= 10 epochs each shared "
                              "with the fused targets: position error, |COG error| (moving objects) and |SOG "
                              "error|, each RMSE and median, of the fused targets against the best sensor's on "
                              "the epochs both report the object; beats: fused <= best sensor; why_not: the "
                              "computed reason where it loses on an RMSE (tdm/eval_best_sensor.py)",
}


def _read_inputs(recording: Path, warnings: dict[str, int]) -> dict:
    """Everything the scoring needs, read and checked: parameters, frame, epochs, truth at the epochs, reports.

    Reports first (their times set the epochs), then the truth's span from its first and last
    lines, then one pass over truth.jsonl keeping only the samples around the epochs.
    """
    targets_path = recording / "tdm" / "detected_targets.jsonl"
    if not targets_path.is_file():
        raise RecordingError(str(targets_path), "(file)", "missing: run `tdm run` first")
    manifest = read_manifest(recording)
    params = read_params(recording, manifest, read_scenario(recording))
    targets = read_report_columns(targets_path)
    tracks_path = recording / "tdm" / "sensor_tracks.jsonl"
    tracks = read_report_columns(tracks_path, with_sensor=True) if tracks_path.is_file() else None
    land = read_land(recording)
    for columns in (targets, tracks):
        if columns is not None:
            columns["on_land"] = on_chart_land(land, columns["latitude"], columns["longitude"])

    truth_path = recording / "truth.jsonl"
    span_s = truth_span(truth_path)
    if span_s is None:  # first or last line unreadable: a checking pass names the line (or finds the span)
        span_s = read_truth_samples(truth_path, np.zeros(0))[1]
    t0_s, t1_s = span_s
    check_epoch_count(truth_path, params.rate_hz, t0_s, t1_s)
    epochs = epoch_grid(targets["t"], params.rate_hz, t0_s, t1_s)
    frame, truth_rows, read_span_s = truth_enu_and_span(recording, epochs)
    if read_span_s != span_s:
        raise RecordingError(str(truth_path), "(file)", "changed while it was being read")
    check_cell_count(truth_path, epochs.size, truth_rows)
    truth = truth_at(truth_rows, epochs)
    del truth_rows
    ais_received_s = ais_reception_times(recording, frame, start_time_unix_s(manifest, recording), warnings) \
        if "ais" in params.rendered else None
    visible_by_sensor, hidden_by_sensor, used = visibility(recording, params, truth, warnings, ais_received_s)
    return {"params": params, "used": used, "frame": frame, "epochs": epochs, "truth": truth,
            "targets": reports_in_frame(targets, frame),
            "tracks": None if tracks is None else reports_in_frame(tracks, frame),
            "visible_by_sensor": visible_by_sensor, "hidden_by_sensor": hidden_by_sensor,
            "land_polygons": 0 if land is None else len(land.polygons),
            "duration_s": params.duration_s if params.duration_s is not None else t1_s - t0_s}


def evaluate(recording: Path, c_m: float = DEFAULT_CUTOFF_M, p: float = DEFAULT_ORDER_P) -> dict:
    """Score the TDM's outputs in ``RECORDING/tdm/`` against the recording's truth.

    Parameters
    ----------
    recording : Path
        Recording directory holding ``tdm/detected_targets.jsonl`` (written by ``tdm run``).
    c_m : float
        OSPA/GOSPA cut-off and matching gate, metres.
    p : float
        OSPA/GOSPA order.

    Returns
    -------
    dict
        JSON-ready metrics (module docstring): at least ``ospa_m``, ``gospa_m``,
        ``position_rmse_m``, ``cog_rmse_deg``, ``sog_rmse_mps``, ``detection_rate``,
        ``false_targets_per_min``, ``id_switches``, ``nees``, ``per_sensor``; also
        ``per_object`` (list), ``series`` (per-epoch values for plots), ``parameters``
        and ``definitions``; ``warnings`` ({what: count}) only when a sweep file was cut short.

    Raises
    ------
    RecordingError
        A file missing or malformed (docs/formats.md, "What tdm evaluate refuses");
        ``detected_targets.jsonl`` missing ("run `tdm run` first").
    """
    recording = Path(recording)
    warnings: dict[str, int] = {}
    inputs = _read_inputs(recording, warnings)
    truth, targets, tracks, epochs = inputs["truth"], inputs["targets"], inputs["tracks"], inputs["epochs"]
    visible_by_sensor, hidden_by_sensor = inputs["visible_by_sensor"], inputs["hidden_by_sensor"]
    visible = np.zeros(truth.range_m.shape, dtype=bool)
    for mask in visible_by_sensor.values():
        visible |= mask
    hidden = np.zeros(truth.range_m.shape, dtype=bool)
    for mask in hidden_by_sensor.values():
        hidden |= mask
    duration_s, lidar_range_m = float(inputs["duration_s"]), inputs["used"]["lidar_range_max_m"]

    metrics = score(truth, visible, targets, epoch_index(targets["t"], epochs), c_m, p, duration_s, lidar_range_m,
                    with_series=True, dont_care=hidden)
    per_sensor = {}
    if tracks is not None:
        track_epoch = epoch_index(tracks["t"], epochs)
        for sensor in sorted({str(s) for s in tracks["sensor"]}):  # loop over sensors
            mask = tracks["sensor"] == sensor
            per_sensor[sensor] = score(truth, visible_by_sensor.get(sensor, visible), subset(tracks, mask),
                                       track_epoch[mask], c_m, p, duration_s, lidar_range_m, with_series=False,
                                       dont_care=hidden_by_sensor.get(sensor))
    metrics["fusion_against_sensors"] = fusion_against_sensors(
        truth.names, truth.ids, truth.range_m.shape[0], metrics.pop("_pairs"),
        {sensor: m.pop("_pairs") for sensor, m in per_sensor.items()})
    metrics["per_sensor"] = per_sensor
    frame = inputs["frame"]
    metrics["parameters"] = {**inputs["used"], "c_m": c_m, "p": p, "gospa_alpha": GOSPA_ALPHA,
                             "update_rate_hz": inputs["params"].rate_hz, "duration_s": duration_s,
                             "moving_sog_mps": MOVING_SOG_MPS, "lidar_visible_window_s": VISIBLE_WINDOW_S,
                             "nees_95_interval": list(NEES_95_INTERVAL),
                             "frame_origin_lat_lon_deg": [frame.lat0_deg, frame.lon0_deg],
                             "land_polygons": inputs["land_polygons"]}
    metrics["definitions"] = dict(DEFINITIONS)
    if warnings:
        metrics["warnings"] = dict(sorted(warnings.items()))
    return _clean(metrics)
