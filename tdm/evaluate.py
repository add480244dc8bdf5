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
    ``ais`` true and distance <= ``sensors.ais.range_m``. A sensor counts when it is in the
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
    (radar sweeps' ``object_id``, LiDAR points' ``object_id``: occluded, below the horizon)
    and that no other sensor sees is neither to be found nor a false alarm: at each epoch
    the reports are assigned (same cost and cut-off) to the in-range and the hidden
    objects together, and those given to hidden objects are ignored (``ignored_reports``),
    the MOT/KITTI "don't care" convention. A tracker that coasts through an occlusion is
    not punished for it.
False targets
    A target id is false when it is matched at fewer than half of the epochs it is
    reported at (ignored reports not counted); ``false_targets_per_min`` = number of false
    ids / (manifest ``duration_s`` / 60). ``false_reports_per_min`` = unmatched, not
    ignored (target, epoch) reports per minute.
ID switches
    Per truth object, the number of changes of the matched target id between its consecutive
    matched epochs (gaps do not count as switches); ``id_switches`` is the total,
    ``id_switches_max_per_object`` the largest.
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
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tdm.errors import RecordingError
from tdm.frames import EnuFrame
from tdm.io import read_jsonl, read_manifest, read_scenario
from tdm.metrics import DEFAULT_CUTOFF_M, DEFAULT_ORDER_P, GOSPA_ALPHA, assign_distances, distance_matrix, \
    gospa_distances, ospa_distances

#: Default TDM output rate when the scenario gives none, Hz (the default of ``tdm.update_rate_hz``, docs/scenario.md).
DEFAULT_UPDATE_RATE_HZ = 1.0
#: Half-width of the window about an epoch in which a LiDAR hit, or the radar's view of an object, makes it
#: visible, s (task definition).
VISIBLE_WINDOW_S = 0.5
#: Fewest spokes of a revolution whose rays must reach an object for the radar to see it (0.5 deg at 2048
#: spokes; a radar plot needs 3 spokes too, docs/tdm.md).
RADAR_VISIBLE_MIN_SPOKES = 3
#: Shortest run of in-range epochs that brings an object into view for the latency, s: two radar
#: revolutions. A glimpse (one revolution's rays between two occlusions) cannot start a track that needs
#: two plots, so it does not start the latency clock (docs/tdm.md).
MIN_IN_VIEW_S = 5.0
#: LiDAR range when the scenario gives none, m (docs/reference.md section 2: HDL-32E returns to 100 m).
DEFAULT_LIDAR_RANGE_M = 100.0
#: Truth SOG above which an object counts as moving for the COG error, m/s (task definition).
MOVING_SOG_MPS = 0.5
#: Two-sided 95 % interval of chi-square with 2 degrees of freedom (CDF 1 - exp(-x/2)), dimensionless.
NEES_95_INTERVAL = (-2.0 * math.log(0.975), -2.0 * math.log(0.025))
#: Epoch times are compared after rounding to this many decimals of a second (1 us).
EPOCH_DECIMALS = 6
#: A truth object exists at an epoch within this tolerance of its first/last sample, s (half the 0.1 s truth step).
TRUTH_TIME_TOLERANCE_S = 0.05
#: Significant digits kept for floats in metrics.json.
SIGNIFICANT_DIGITS = 6
#: Keys whose floats keep more digits (latitude/longitude: 6 significant digits would be ~10 m).
FULL_PRECISION_KEYS = frozenset({"frame_origin_lat_lon_deg"})
FULL_PRECISION_DIGITS = 12
#: Target descriptor expected for a truth kind (docs/formats.md, tdm/detected_targets.jsonl: "vessel" | "iceberg" | "unknown").
DESCRIPTOR_OF_KIND = {"ship": "vessel", "iceberg": "iceberg"}
#: Sensors whose in-range region the evaluation knows.
SENSORS = ("lidar", "radar", "ais")

DEFINITIONS = {
    "frame": "ENU metres, transverse Mercator centred on the own ship's first truth position",
    "epochs": "every 1/tdm.update_rate_hz s, phase of the first reported time, over the truth's span, "
              "united with all reported times",
    "truth_at_epoch": "position and SOG linearly interpolated in the 0.1 s truth, COG and AIS flag nearest; "
                      "own ship excluded",
    "in_range": "radar: distance <= radar range_m and, if the sweeps carry object_id, reached on >= 3 spokes "
                "of a revolution, seen from the beam's pass over it to the next pass, within +-0.5 s; "
                "lidar: hit by a LiDAR point within +-0.5 s (object_id); ais: truth ais and distance <= ais range_m; "
                "any rendered sensor",
    "matching": "per epoch, linear_sum_assignment on min(d, c)^p of targets to in-range truth; pairs with d >= c "
                "unmatched",
    "ospa_m": "mean over epochs of OSPA (Schuhmacher 2008) on positions, cut-off c, order p",
    "gospa_m": "mean over epochs of GOSPA (Rahmathullah 2017, alpha 2); gospa_localisation_m, "
               "gospa_missed_mean, gospa_false_mean are the means of its terms",
    "position_rmse_m": "RMS of ENU position error over matched pairs",
    "median_position_error_m": "median over matched pairs; _within/_beyond_lidar_range_m split by truth distance "
                               "from own ship vs lidar range_max_m",
    "cog_rmse_deg": "RMS of wrapped COG difference over matched pairs with truth SOG > 0.5 m/s",
    "sog_rmse_mps": "RMS of SOG difference over matched pairs",
    "detection_rate": "matched (object, epoch) pairs / in-range (object, epoch) pairs",
    "detection_latency_s": "per object: first matched epoch - start of the first run of in-range epochs lasting "
                           ">= 5 s (at least 0; the first in-range epoch if no run is so long); null when never "
                           "matched",
    "false_targets_per_min": "target ids matched at fewer than half of their reported epochs, per minute of "
                             "manifest duration",
    "false_reports_per_min": "unmatched (target, epoch) reports per minute, ignored ones not counted",
    "ignored_reports": "reports assigned to objects within a sensor's range but hidden from every sensor (ray "
                       "truth): neither matched nor false",
    "id_switches": "total over objects of changes of matched target id between consecutive matched epochs",
    "nees": "mean of e^T P^-1 e over matched pairs (ideal 2); nees_fraction_in_95: inside [0.0506, 7.378]",
    "classification_accuracy": "matched ship/iceberg pairs whose descriptor is vessel/iceberg",
    "per_sensor": "same metrics per sensor of sensor_tracks.jsonl against that sensor's in-range objects",
}


# ----------------------------------------------------------------------------------------------- reading


def _line_number(path: Path, record: int) -> int:
    """File line of the ``record``-th (1-based) JSON object of a JSON-lines file (blank lines skipped)."""
    with open(path, encoding="utf-8") as handle:
        seen = 0
        for number, line in enumerate(handle, start=1):
            seen += bool(line.strip())
            if seen == record:
                return number
    return record


def _column(rows: list[dict], key: str, path: Path, dtype=float, default=None) -> np.ndarray:
    """One field of every row as an array (null -> NaN for floats); ``default`` for an absent field.

    A missing (when no default) or malformed field raises RecordingError naming its line.
    """
    def get(row):
        return row[key] if default is None else row.get(key, default)

    try:
        values = [get(r) for r in rows]
        if dtype is float:
            return np.array([np.nan if v is None else v for v in values], dtype=float)
        return np.array(values, dtype=dtype)
    except (KeyError, TypeError, ValueError, AttributeError):
        pass
    for number, row in enumerate(rows, start=1):  # find the culprit (error path only)
        if not isinstance(row, dict):
            raise RecordingError(str(path), f"line {_line_number(path, number)}", "not a JSON object")
        if default is None and key not in row:
            raise RecordingError(str(path), f"line {_line_number(path, number)}", f"field {key!r} missing")
        value = get(row)
        try:
            np.array([np.nan if (value is None and dtype is float) else value], dtype=dtype)
        except (TypeError, ValueError):
            raise RecordingError(str(path), f"line {_line_number(path, number)}",
                                 f"field {key!r}: bad value {value!r}") from None
    raise RecordingError(str(path), "(file)", f"field {key!r}: unreadable values")


def read_truth_enu(recording: Path) -> tuple[EnuFrame, dict[str, np.ndarray]]:
    """truth.jsonl in the evaluation's ENU frame.

    Parameters
    ----------
    recording : Path
        Recording directory.

    Returns
    -------
    frame : EnuFrame
        Centred on the own ship's first truth position.
    truth : dict of (R,) arrays
        One entry per truth line: ``t`` (s), ``id`` (int64), ``name``, ``kind`` (str),
        ``east_m``, ``north_m`` (m), ``cog_deg``, ``sog_mps``, ``ais`` (bool).
    """
    path = Path(recording) / "truth.jsonl"
    rows = read_jsonl(path)
    if not rows:
        raise RecordingError(str(path), "(file)", "holds no truth samples")
    out = {"t": _column(rows, "t", path), "id": _column(rows, "id", path, np.int64),
           "name": _column(rows, "name", path, object), "kind": _column(rows, "kind", path, object),
           "cog_deg": _column(rows, "cog_deg", path, default=np.nan),
           "sog_mps": _column(rows, "sog_mps", path, default=np.nan),
           "ais": _column(rows, "ais", path, object, default=False).astype(bool)}
    lat, lon = _column(rows, "lat", path), _column(rows, "lon", path)
    own = np.flatnonzero(out["kind"] == "ownship")
    if own.size == 0:
        raise RecordingError(str(path), "(file)", "no own ship (kind 'ownship')")
    first = own[np.argmin(out["t"][own])]
    frame = EnuFrame(lat[first], lon[first])
    out["east_m"], out["north_m"] = frame.to_enu(lat, lon)
    return frame, out


def read_reports(path: Path, frame: EnuFrame, with_sensor: bool = False) -> dict[str, np.ndarray]:
    """detected_targets.jsonl (or sensor_tracks.jsonl) as columns in the frame ``frame``.

    Parameters
    ----------
    path : Path
        The JSON-lines file.
    frame : EnuFrame
        The evaluation's frame.
    with_sensor : bool
        Also read the ``sensor`` field (sensor_tracks.jsonl).

    Returns
    -------
    dict of arrays
        ``t`` (N,) s, ``target_id`` (N,) int64, ``east_m``, ``north_m`` (N,) m, ``cog_deg``,
        ``sog_mps`` (N,) (NaN when null), ``position_cov_m2`` (N, 2, 2) m^2 (NaN when
        absent), ``descriptor`` (N,) str, and ``sensor`` (N,) str when asked for.
    """
    path = Path(path)
    rows = read_jsonl(path)
    out = {"t": _column(rows, "t", path), "target_id": _column(rows, "target_id", path, np.int64),
           "cog_deg": _column(rows, "cog_deg", path, default=np.nan),
           "sog_mps": _column(rows, "sog_mps", path, default=np.nan),
           "descriptor": _column(rows, "object_descriptor", path, object, default="unknown")}
    lat, lon = _column(rows, "latitude", path), _column(rows, "longitude", path)
    out["east_m"], out["north_m"] = frame.to_enu(lat, lon) if rows else (np.zeros(0), np.zeros(0))
    cov = np.full((len(rows), 2, 2), np.nan)
    for number, row in enumerate(rows, start=1):  # one small list per report; no per-point work
        value = row.get("position_cov_m2")
        if value is None:
            continue
        try:
            cov[number - 1] = np.asarray(value, dtype=float).reshape(2, 2)
        except (TypeError, ValueError):
            raise RecordingError(str(path), f"line {_line_number(path, number)}",
                                 "field 'position_cov_m2': not a 2x2 matrix") from None
    out["position_cov_m2"] = cov
    if with_sensor:
        out["sensor"] = _column(rows, "sensor", path, object)
    return out


def _lidar_hit_times(recording: Path) -> dict[int, np.ndarray] | None:
    """Times of the LiDAR points on each truth object: {id: sorted (H,) s}; None without ``object_id``.

    Each sweep is reduced to the first and last hit time per object: the visibility window
    (+-0.5 s) is longer than a revolution, so a window that meets a sweep's hits on an
    object contains one of those two times.
    """
    files = sorted((Path(recording) / "lidar" / "sweeps").glob("*.npz"))
    if not files:
        return None
    ids, times = [], []
    for file in files:  # loop over sweeps (chunks), vectorised within
        try:
            with np.load(file) as z:
                if "object_id" not in z.files or "time" not in z.files:
                    return None
                oid = z["object_id"]
                hit = oid >= 0
                if not hit.any():
                    continue
                o, t = oid[hit].astype(np.int64), z["time"][hit].astype(float)
        except (OSError, ValueError, KeyError) as exc:
            raise RecordingError(str(file), "(file)", f"not a readable NPZ ({type(exc).__name__})") from None
        order = np.lexsort((t, o))
        o, t = o[order], t[order]
        starts = np.flatnonzero(np.r_[True, o[1:] != o[:-1]])
        ends = np.r_[starts[1:], o.size] - 1
        ids.extend([o[starts], o[ends]])
        times.extend([t[starts], t[ends]])
    if not ids:
        return {}
    ids_all, times_all = np.concatenate(ids), np.concatenate(times)
    order = np.lexsort((times_all, ids_all))
    ids_all, times_all = ids_all[order], times_all[order]
    uniq, starts = np.unique(ids_all, return_index=True)
    bounds = np.r_[starts, ids_all.size]
    return {int(u): times_all[bounds[i]:bounds[i + 1]] for i, u in enumerate(uniq)}


def _radar_seen_intervals(recording: Path, truth: TruthAtEpochs) -> dict[int, tuple[np.ndarray, np.ndarray]] | None:
    """When the radar saw each truth object: {id: ((R,) start s, (R,) end s)}, one interval per revolution.

    An object counts as seen in a revolution when its rays reached it on at least
    :data:`RADAR_VISIBLE_MIN_SPOKES` spokes (the sweep's ``object_id`` / ``object_spokes``). It is
    seen from the beam's pass over it (the time of the spoke whose compass bearing, azimuth +
    heading, is nearest the object's bearing from the own ship at the middle of the revolution) until
    one revolution later, when the next pass looks again. None when the sweeps carry no ``object_id``.
    """
    files = sorted((Path(recording) / "radar" / "sweeps").glob("*.npz"))
    if not files:
        return None
    column = {int(object_id): k for k, object_id in enumerate(truth.ids)}
    fields = ("object_id", "object_spokes", "time", "azimuth_deg", "heading_deg")
    seen: dict[int, list[tuple[float, float]]] = {}
    for file in files:  # loop over sweeps, a few ids each
        try:
            with np.load(file) as z:
                if not set(fields) <= set(z.files):
                    return None
                ids, spokes, t, azimuth_deg, heading_deg = (z[name] for name in fields)
        except (OSError, ValueError, KeyError) as exc:
            raise RecordingError(str(file), "(file)", f"not a readable NPZ ({type(exc).__name__})") from None
        if t.size == 0:
            continue
        period_s = float(t[-1] - t[0]) * t.size / max(t.size - 1, 1)
        reached = [int(i) for i in ids[spokes >= RADAR_VISIBLE_MIN_SPOKES] if int(i) in column]
        if not reached:
            continue
        k = np.array([column[i] for i in reached])
        t_mid = 0.5 * float(t[0] + t[-1])
        east = np.array([np.interp(t_mid, truth.t_s, truth.east_m[:, j]) for j in k])  # a few objects
        north = np.array([np.interp(t_mid, truth.t_s, truth.north_m[:, j]) for j in k])
        bearing_deg = np.degrees(np.arctan2(east - np.interp(t_mid, truth.t_s, truth.own_east_m),
                                            north - np.interp(t_mid, truth.t_s, truth.own_north_m)))
        compass_deg = azimuth_deg.astype(np.float64) + heading_deg.astype(np.float64)
        off = np.abs((compass_deg[None, :] - bearing_deg[:, None] + 180.0) % 360.0 - 180.0)
        t_pass = np.where(np.isfinite(bearing_deg), t[np.argmin(off, axis=1)], t[0])
        for object_id, start in zip(reached, t_pass):
            seen.setdefault(object_id, []).append((float(start), float(start) + period_s))
    return {k: (np.array([a for a, _ in v]), np.array([b for _, b in v])) for k, v in seen.items()}


def _overlaps(starts: np.ndarray, ends: np.ndarray, t_s: np.ndarray, half_window_s: float) -> np.ndarray:
    """(E,) bool: some interval [start, end] meets [t - w, t + w] (starts ascending, ends ascending)."""
    if starts.size == 0:
        return np.zeros(t_s.shape, dtype=bool)
    idx = np.searchsorted(ends, t_s - half_window_s, side="left")
    return (idx < ends.size) & (starts[np.minimum(idx, ends.size - 1)] <= t_s + half_window_s)


# ----------------------------------------------------------------------------------------------- truth at epochs


@dataclass
class TruthAtEpochs:
    """Truth objects (own ship excluded) at the evaluation epochs.

    Attributes
    ----------
    t_s : (E,) float64
        Epoch times, s since the recording's start.
    ids : (K,) int64
        Truth ids.
    names, kinds : list of str
        Per object.
    east_m, north_m : (E, K) float64
        ENU position, metres; NaN where the object does not exist.
    cog_deg, sog_mps : (E, K) float64
        Course (compass deg) and speed (m/s).
    ais : (E, K) bool
        The object transmits AIS.
    range_m : (E, K) float64
        Distance from the own ship, metres (NaN where absent).
    own_east_m, own_north_m : (E,) float64
        The own ship's position, metres.
    """

    t_s: np.ndarray
    ids: np.ndarray
    names: list
    kinds: list
    east_m: np.ndarray
    north_m: np.ndarray
    cog_deg: np.ndarray
    sog_mps: np.ndarray
    ais: np.ndarray
    range_m: np.ndarray
    own_east_m: np.ndarray
    own_north_m: np.ndarray


def _nearest_index(t_samples: np.ndarray, t_query: np.ndarray) -> np.ndarray:
    idx = np.clip(np.searchsorted(t_samples, t_query), 1, max(t_samples.size - 1, 1))
    if t_samples.size == 1:
        return np.zeros(t_query.shape, dtype=np.int64)
    left_closer = (t_query - t_samples[idx - 1]) <= (t_samples[idx] - t_query)
    return np.where(left_closer, idx - 1, idx)


def _truth_at(truth: dict[str, np.ndarray], t_s: np.ndarray) -> TruthAtEpochs:
    ids = np.unique(truth["id"][truth["kind"] != "ownship"])
    E, K = t_s.size, ids.size
    cols = {name: np.full((E, K), np.nan) for name in ("east_m", "north_m", "cog_deg", "sog_mps")}
    ais = np.zeros((E, K), dtype=bool)
    names, kinds = [], []

    def sample(mask):
        order = np.flatnonzero(mask)[np.argsort(truth["t"][mask], kind="stable")]
        ts = truth["t"][order]
        present = (t_s >= ts[0] - TRUTH_TIME_TOLERANCE_S) & (t_s <= ts[-1] + TRUTH_TIME_TOLERANCE_S)
        near = order[_nearest_index(ts, t_s)]
        return order, ts, present, near

    own_order, own_t, _, _ = sample(truth["kind"] == "ownship")
    own_e = np.interp(t_s, own_t, truth["east_m"][own_order])
    own_n = np.interp(t_s, own_t, truth["north_m"][own_order])
    for k, object_id in enumerate(ids):  # loop over objects
        order, ts, present, near = sample(truth["id"] == object_id)
        names.append(str(truth["name"][order[0]]))
        kinds.append(str(truth["kind"][order[0]]))
        for name in ("east_m", "north_m", "sog_mps"):
            cols[name][present, k] = np.interp(t_s[present], ts, truth[name][order])
        cols["cog_deg"][present, k] = truth["cog_deg"][near[present]]
        ais[present, k] = truth["ais"][near[present]]
    range_m = np.hypot(cols["east_m"] - own_e[:, None], cols["north_m"] - own_n[:, None])
    return TruthAtEpochs(t_s=t_s, ids=ids, names=names, kinds=kinds, ais=ais, range_m=range_m,
                         own_east_m=own_e, own_north_m=own_n, **cols)


def _epochs(report_t_s: np.ndarray, rate_hz: float, t0_s: float, t1_s: float) -> np.ndarray:
    """Epoch times (module docstring): the output grid united with the reported times."""
    dt = 1.0 / rate_hz
    phase = 0.0
    if report_t_s.size:
        first = float(np.min(report_t_s))
        phase = first - math.floor(first / dt + 1e-9) * dt
    k0 = math.ceil((t0_s - phase) / dt - 1e-9)
    k1 = math.floor((t1_s - phase) / dt + 1e-9)
    grid = phase + dt * np.arange(k0, k1 + 1)
    tol = 10.0 ** -EPOCH_DECIMALS
    inside = report_t_s[(report_t_s >= t0_s - tol) & (report_t_s <= t1_s + tol)]
    return np.unique(np.round(np.concatenate([grid, inside]), EPOCH_DECIMALS))


def _epoch_index(t_s: np.ndarray, epochs: np.ndarray) -> np.ndarray:
    """Index of each report's epoch, -1 for reports outside the truth's span."""
    rounded = np.round(t_s, EPOCH_DECIMALS)
    idx = np.searchsorted(epochs, rounded)
    ok = idx < epochs.size
    ok[ok] = epochs[idx[ok]] == rounded[ok]
    return np.where(ok, idx, -1)


# ----------------------------------------------------------------------------------------------- visibility


def _sensor_config(scenario: dict, sensor: str) -> dict:
    sensors = scenario.get("sensors") or {}
    value = sensors.get(sensor)
    return value if isinstance(value, dict) else {}


def _rendered(manifest: dict, scenario: dict) -> list[str]:
    if "sensors_rendered" in manifest:
        names = set(manifest["sensors_rendered"] or [])
    else:
        names = {s for s in SENSORS if _sensor_config(scenario, s) and _sensor_config(scenario, s).get("enabled", True)}
    return [s for s in SENSORS if s in names and _sensor_config(scenario, s).get("enabled", True) is not False]


def _number(value, default: float, file: Path, where: str) -> float:
    """A positive scenario number (``default`` when absent); anything else names its key path."""
    if value is None:
        return float(default)
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if isinstance(value, bool) or not x > 0:
        raise RecordingError(str(file), where, f"{value!r} is not a positive number")
    return x


def _range_param(recording: Path, scenario: dict, sensor: str, key: str, default: float) -> float:
    return _number(_sensor_config(scenario, sensor).get(key), default, Path(recording) / "scenario.yaml",
                   f"sensors.{sensor}.{key}")


def _visibility(recording: Path, scenario: dict, manifest: dict, truth: TruthAtEpochs) -> tuple[dict, dict, dict]:
    """Per rendered sensor, the (E, K) in-range mask; per sensor whose view is ray truth, the (E, K) mask of
    objects within its range but hidden from it (occluded, below the horizon); and the parameters used."""
    present = np.isfinite(truth.range_m)
    rng = np.where(present, truth.range_m, np.inf)
    rendered = _rendered(manifest, scenario)
    radar_range_m = _range_param(recording, scenario, "radar", "range_m", math.inf)
    ais_range_m = _range_param(recording, scenario, "ais", "range_m", math.inf)
    lidar_range_m = _range_param(recording, scenario, "lidar", "range_max_m", DEFAULT_LIDAR_RANGE_M)
    visible, hidden = {}, {}
    lidar_mode = radar_mode = None
    if "radar" in rendered:
        visible["radar"] = rng <= radar_range_m
        seen = _radar_seen_intervals(recording, truth)
        radar_mode = "range" if seen is None else "rays"
        if seen is not None:
            mask = np.zeros(rng.shape, dtype=bool)
            for k, object_id in enumerate(truth.ids):  # loop over objects
                if int(object_id) in seen:
                    mask[:, k] = _overlaps(*seen[int(object_id)], truth.t_s, VISIBLE_WINDOW_S)
            hidden["radar"] = visible["radar"] & present & ~mask
            visible["radar"] &= mask
    if "ais" in rendered:
        visible["ais"] = truth.ais & (rng <= ais_range_m)
    if "lidar" in rendered:
        hits = _lidar_hit_times(recording)
        if hits is None:
            lidar_mode = "range"
            visible["lidar"] = rng <= lidar_range_m
        else:
            lidar_mode = "hits"
            mask = np.zeros(rng.shape, dtype=bool)
            for k, object_id in enumerate(truth.ids):  # loop over objects
                h = hits.get(int(object_id))
                if h is not None:
                    mask[:, k] = _overlaps(h, h, truth.t_s, VISIBLE_WINDOW_S)
            visible["lidar"] = mask & present
            hidden["lidar"] = (rng <= lidar_range_m) & present & ~mask
    params = {"sensors_rendered": rendered, "radar_range_m": radar_range_m, "ais_range_m": ais_range_m,
              "lidar_range_max_m": lidar_range_m, "lidar_visibility": lidar_mode, "radar_visibility": radar_mode}
    return visible, hidden, params


# ----------------------------------------------------------------------------------------------- scoring


def _sustained_start(vis_e: np.ndarray, t_s: np.ndarray) -> int:
    """Epoch at which an object comes into view: the first epoch of the first run of consecutive in-range
    epochs lasting at least :data:`MIN_IN_VIEW_S`; the first in-range epoch when no run lasts so long.

    ``vis_e`` are the object's in-range epoch indices, ascending; ``t_s`` the epoch times.
    """
    brk = np.flatnonzero(np.diff(vis_e) != 1)
    starts = vis_e[np.r_[0, brk + 1]]
    ends = vis_e[np.r_[brk, vis_e.size - 1]]
    long_enough = np.flatnonzero(t_s[ends] - t_s[starts] >= MIN_IN_VIEW_S)
    return int(starts[long_enough[0]]) if long_enough.size else int(vis_e[0])


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x ** 2))) if x.size else math.nan


def _median(x: np.ndarray) -> float:
    return float(np.median(x)) if x.size else math.nan


def _nees(err_m: np.ndarray, cov_m2: np.ndarray) -> np.ndarray:
    """(P,) NEES ``e^T P^-1 e`` from (P, 2) errors and (P, 2, 2) covariances; NaN where P is not positive definite."""
    sym = 0.5 * (cov_m2 + np.swapaxes(cov_m2, 1, 2))
    a, b, d = sym[:, 0, 0], sym[:, 0, 1], sym[:, 1, 1]
    det = a * d - b * b
    with np.errstate(invalid="ignore", divide="ignore"):
        value = (d * err_m[:, 0] ** 2 - 2 * b * err_m[:, 0] * err_m[:, 1] + a * err_m[:, 1] ** 2) / det
    ok = np.isfinite(det) & (det > 0) & (a > 0) & np.isfinite(value)
    return np.where(ok, value, np.nan)


def _score(truth: TruthAtEpochs, visible: np.ndarray, reports: dict[str, np.ndarray], report_epoch: np.ndarray,
           c_m: float, p: float, duration_s: float, lidar_range_m: float, with_series: bool,
           dont_care: np.ndarray | None = None) -> dict:
    """The metrics of one report set against the in-range truth (module docstring).

    ``dont_care`` (E, K): objects hidden from the sensors though within their range (those in range at
    an epoch are never don't care); reports that the assignment gives to them are ignored (neither
    matched nor false).
    """
    E, K = visible.shape
    t_s = truth.t_s
    kept = np.flatnonzero(report_epoch >= 0)
    order = kept[np.argsort(report_epoch[kept], kind="stable")]
    bounds = np.searchsorted(report_epoch[order], np.arange(E + 1))
    truth_pos = np.stack([truth.east_m, truth.north_m], axis=-1)  # (E, K, 2)
    rep_pos = np.stack([reports["east_m"], reports["north_m"]], axis=-1)  # (N, 2)

    per_epoch = {name: np.zeros(E) for name in ("ospa", "gospa", "gospa_loc", "gospa_missed", "gospa_false")}
    n_vis_e, n_rep_e = visible.sum(axis=1), np.diff(bounds)
    pairs_e, pairs_k, pairs_r, pairs_d = [], [], [], []
    is_ignored = np.zeros(report_epoch.size, dtype=bool)
    for e in range(E):  # loop over epochs (scans); each assignment is a small matrix
        rows = order[bounds[e]:bounds[e + 1]]
        ks = np.flatnonzero(visible[e])
        hs = np.flatnonzero(dont_care[e] & ~visible[e]) if dont_care is not None else np.zeros(0, np.int64)
        if hs.size and rows.size:  # reports of hidden objects leave the set (one assignment over both)
            rj, cj = assign_distances(distance_matrix(truth_pos[e, np.r_[ks, hs]], rep_pos[rows]), c_m, p)
            drop = cj[rj >= ks.size]
            is_ignored[rows[drop]] = True
            rows = np.delete(rows, drop)
            n_rep_e[e] = rows.size
        d = distance_matrix(truth_pos[e, ks], rep_pos[rows])
        per_epoch["ospa"][e] = ospa_distances(d, c_m, p)
        g = gospa_distances(d, c_m, p, GOSPA_ALPHA)
        per_epoch["gospa"][e], per_epoch["gospa_loc"][e] = g["total"], g["localisation"]
        per_epoch["gospa_missed"][e], per_epoch["gospa_false"][e] = g["missed"], g["false"]
        r, cc = assign_distances(d, c_m, p)
        pairs_e.append(np.full(r.size, e))
        pairs_k.append(ks[r])
        pairs_r.append(rows[cc])
        pairs_d.append(d[r, cc])
    pe, pk, pr = (np.concatenate(x).astype(np.int64) if x else np.zeros(0, np.int64)
                  for x in (pairs_e, pairs_k, pairs_r))
    pd = np.concatenate(pairs_d) if pairs_d else np.zeros(0)

    # errors over matched pairs
    err = rep_pos[pr] - truth_pos[pe, pk]
    within = truth.range_m[pe, pk] <= lidar_range_m
    cog_t, sog_t = truth.cog_deg[pe, pk], truth.sog_mps[pe, pk]
    cog_r, sog_r = reports["cog_deg"][pr], reports["sog_mps"][pr]
    moving = (sog_t > MOVING_SOG_MPS) & np.isfinite(cog_r) & np.isfinite(cog_t)
    cog_diff = np.mod(cog_r[moving] - cog_t[moving] + 180.0, 360.0) - 180.0
    sog_ok = np.isfinite(sog_r) & np.isfinite(sog_t)
    nees = _nees(err, reports["position_cov_m2"][pr])
    nees = nees[np.isfinite(nees)]
    kinds = [truth.kinds[k] for k in pk]
    classed = np.array([k in DESCRIPTOR_OF_KIND for k in kinds], dtype=bool)
    expected = np.array([DESCRIPTOR_OF_KIND.get(k, "") for k in kinds], dtype=object)
    correct = (reports["descriptor"][pr] == expected)[classed] if pr.size else np.zeros(0, dtype=bool)

    # detection, latency, id switches, per object
    matched_tid = np.full((E, K), -1, dtype=np.int64)
    matched_tid[pe, pk] = reports["target_id"][pr]
    err_mat = np.full((E, K), np.nan)
    err_mat[pe, pk] = pd
    n_visible = int(visible.sum())
    per_object, latency, missed = [], {}, []
    switches_total, switches_max = 0, 0
    for k in range(K):  # loop over objects
        vis_e = np.flatnonzero(visible[:, k])
        if vis_e.size == 0:
            continue
        m_e = np.flatnonzero(matched_tid[:, k] >= 0)
        start_e = _sustained_start(vis_e, t_s)
        lat_s = max(float(t_s[m_e[0]] - t_s[start_e]), 0.0) if m_e.size else None
        glimpse_lat_s = float(t_s[m_e[0]] - t_s[vis_e[0]]) if m_e.size else None
        switches = int(np.count_nonzero(np.diff(matched_tid[m_e, k]))) if m_e.size else 0
        switches_total += switches
        switches_max = max(switches_max, switches)
        name = truth.names[k] if truth.names.count(truth.names[k]) == 1 else f"{truth.names[k]}#{truth.ids[k]}"
        latency[name] = lat_s
        if lat_s is None:
            missed.append(name)
        per_object.append({"id": int(truth.ids[k]), "name": truth.names[k], "kind": truth.kinds[k],
                           "first_in_range_s": float(t_s[vis_e[0]]), "in_view_from_s": float(t_s[start_e]),
                           "epochs_in_range": int(vis_e.size), "latency_from_first_in_range_s": glimpse_lat_s,
                           "epochs_matched": int(m_e.size), "matched_fraction": m_e.size / vis_e.size,
                           "latency_s": lat_s, "id_switches": switches,
                           "target_ids": sorted({int(x) for x in matched_tid[m_e, k]}),
                           "median_error_m": _median(err_mat[m_e, k])})
    latencies = np.array([v for v in latency.values() if v is not None])

    # false targets and false reports
    duration_min = duration_s / 60.0
    is_matched = np.zeros(report_epoch.size, dtype=bool)
    is_matched[pr] = True
    uids, inv = np.unique(reports["target_id"][kept], return_inverse=True)
    n_reported = np.bincount(inv, weights=~is_ignored[kept], minlength=uids.size)
    n_matched_id = np.bincount(inv, weights=is_matched[kept], minlength=uids.size)
    false_ids = uids[(n_matched_id < 0.5 * n_reported) & (n_reported > 0)]
    n_ignored = int(np.count_nonzero(is_ignored[kept]))
    n_false_reports = int(kept.size - n_ignored - np.count_nonzero(is_matched[kept]))

    out = {
        "ospa_m": float(np.mean(per_epoch["ospa"])) if E else math.nan,
        "gospa_m": float(np.mean(per_epoch["gospa"])) if E else math.nan,
        "gospa_localisation_m": float(np.mean(per_epoch["gospa_loc"])) if E else math.nan,
        "gospa_missed_mean": float(np.mean(per_epoch["gospa_missed"])) if E else math.nan,
        "gospa_false_mean": float(np.mean(per_epoch["gospa_false"])) if E else math.nan,
        "position_rmse_m": _rms(pd),
        "median_position_error_m": _median(pd),
        "median_position_error_within_lidar_range_m": _median(pd[within]),
        "median_position_error_beyond_lidar_range_m": _median(pd[~within]),
        "position_bias_east_m": float(np.mean(err[:, 0])) if pd.size else math.nan,
        "position_bias_north_m": float(np.mean(err[:, 1])) if pd.size else math.nan,
        "cog_rmse_deg": _rms(cog_diff),
        "sog_rmse_mps": _rms(sog_r[sog_ok] - sog_t[sog_ok]),
        "detection_rate": pd.size / n_visible if n_visible else math.nan,
        "detection_latency_s": latency,
        "detection_latency_max_s": float(np.max(latencies)) if latencies.size else math.nan,
        "detection_latency_mean_s": float(np.mean(latencies)) if latencies.size else math.nan,
        "objects_in_range": len(latency),
        "missed_objects": sorted(missed),
        "false_target_ids": [int(x) for x in false_ids],
        "false_targets_per_min": false_ids.size / duration_min if duration_min > 0 else math.nan,
        "false_reports": n_false_reports,
        "ignored_reports": n_ignored,
        "false_reports_per_min": n_false_reports / duration_min if duration_min > 0 else math.nan,
        "id_switches": switches_total,
        "id_switches_max_per_object": switches_max,
        "nees": float(np.mean(nees)) if nees.size else math.nan,
        "nees_fraction_in_95": float(np.mean((nees >= NEES_95_INTERVAL[0]) & (nees <= NEES_95_INTERVAL[1])))
        if nees.size else math.nan,
        "nees_pairs": int(nees.size),
        "classification_accuracy": float(np.mean(correct)) if correct.size else math.nan,
        "epochs": E,
        "reports": int(kept.size),
        "reports_outside_truth_span": int(report_epoch.size - kept.size),
        "target_ids": int(uids.size),
        "in_range_pairs": n_visible,
        "matched_pairs": int(pd.size),
        "per_object": per_object,
    }
    if with_series:
        out["series"] = {
            "c_m": c_m, "t_s": t_s.tolist(), "ospa_m": per_epoch["ospa"].tolist(),
            "gospa_m": per_epoch["gospa"].tolist(), "gospa_localisation_m": per_epoch["gospa_loc"].tolist(),
            "n_in_range": n_vis_e.tolist(), "n_reports": n_rep_e.tolist(),
            "objects": {str(int(i)): n for i, n in zip(truth.ids, truth.names)},
            "pairs": {"t_s": t_s[pe].tolist(), "truth_id": truth.ids[pk].tolist(),
                      "target_id": reports["target_id"][pr].tolist(), "error_m": pd.tolist()},
        }
    return out


def _subset(reports: dict[str, np.ndarray], mask: np.ndarray) -> dict[str, np.ndarray]:
    return {key: value[mask] for key, value in reports.items()}


def _clean(value, digits: int = SIGNIFICANT_DIGITS):
    """JSON-ready copy: numpy scalars to Python, floats to ``digits`` significant digits, NaN/inf to None.

    Keys in :data:`FULL_PRECISION_KEYS` keep 12 significant digits (geodetic coordinates).
    """
    if isinstance(value, dict):
        return {str(k): _clean(v, FULL_PRECISION_DIGITS if k in FULL_PRECISION_KEYS else digits)
                for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v, digits) for v in value]
    if isinstance(value, np.ndarray):
        return [_clean(v, digits) for v in value.tolist()]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        x = float(value)
        if not math.isfinite(x):
            return None
        return float(f"{x:.{digits}g}")
    return value


# ----------------------------------------------------------------------------------------------- public API


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
        and ``definitions``.

    Raises
    ------
    RecordingError
        A file missing or malformed; ``detected_targets.jsonl`` missing ("run `tdm run` first").
    """
    recording = Path(recording)
    targets_path = recording / "tdm" / "detected_targets.jsonl"
    if not targets_path.is_file():
        raise RecordingError(str(targets_path), "(file)", "missing: run `tdm run` first")
    manifest = read_manifest(recording)
    scenario = read_scenario(recording)
    frame, truth_rows = read_truth_enu(recording)
    targets = read_reports(targets_path, frame)
    tracks_path = recording / "tdm" / "sensor_tracks.jsonl"
    tracks = read_reports(tracks_path, frame, with_sensor=True) if tracks_path.is_file() else None

    tdm_config = scenario.get("tdm") if isinstance(scenario.get("tdm"), dict) else {}
    rate_hz = _number(tdm_config.get("update_rate_hz"), DEFAULT_UPDATE_RATE_HZ, recording / "scenario.yaml",
                      "tdm.update_rate_hz")
    t0_s, t1_s = float(np.min(truth_rows["t"])), float(np.max(truth_rows["t"]))
    epochs = _epochs(targets["t"], rate_hz, t0_s, t1_s)
    truth = _truth_at(truth_rows, epochs)
    visible_by_sensor, hidden_by_sensor, params = _visibility(recording, scenario, manifest, truth)
    visible = np.zeros(truth.range_m.shape, dtype=bool)
    for mask in visible_by_sensor.values():
        visible |= mask
    hidden = np.zeros(truth.range_m.shape, dtype=bool)
    for mask in hidden_by_sensor.values():
        hidden |= mask
    duration_s = float(manifest.get("duration_s") or (t1_s - t0_s))
    lidar_range_m = params["lidar_range_max_m"]

    metrics = _score(truth, visible, targets, _epoch_index(targets["t"], epochs), c_m, p, duration_s,
                     lidar_range_m, with_series=True, dont_care=hidden)
    per_sensor = {}
    if tracks is not None:
        track_epoch = _epoch_index(tracks["t"], epochs)
        for sensor in sorted({str(s) for s in tracks["sensor"]}):
            mask = tracks["sensor"] == sensor
            per_sensor[sensor] = _score(truth, visible_by_sensor.get(sensor, visible), _subset(tracks, mask),
                                        track_epoch[mask], c_m, p, duration_s, lidar_range_m, with_series=False,
                                        dont_care=hidden_by_sensor.get(sensor))
    metrics["per_sensor"] = per_sensor
    metrics["parameters"] = {**params, "c_m": c_m, "p": p, "gospa_alpha": GOSPA_ALPHA, "update_rate_hz": rate_hz,
                             "duration_s": duration_s, "moving_sog_mps": MOVING_SOG_MPS,
                             "lidar_visible_window_s": VISIBLE_WINDOW_S,
                             "nees_95_interval": list(NEES_95_INTERVAL),
                             "frame_origin_lat_lon_deg": [frame.lat0_deg, frame.lon0_deg]}
    metrics["definitions"] = dict(DEFINITIONS)
    return _clean(metrics)


def write_metrics(recording: Path, metrics: dict) -> Path:
    """Write ``RECORDING/tdm/metrics.json`` atomically (temporary name, then rename); returns its path.

    Keys are sorted, floats rounded to 6 significant digits, NaN written as null.
    """
    out = Path(recording) / "tdm" / "metrics.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(json.dumps(_clean(metrics), sort_keys=True, indent=1, allow_nan=False) + "\n",
                       encoding="utf-8")
        os.replace(tmp, out)
    finally:
        if tmp.exists():
            tmp.unlink()
    return out


def _fmt(value, digits: int = 2) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


#: Rows of the terminal table: (label, key, digits).
_TABLE_ROWS = (
    ("OSPA [m]", "ospa_m", 2),
    ("GOSPA [m]", "gospa_m", 2),
    ("position RMSE [m]", "position_rmse_m", 2),
    ("median position error [m]", "median_position_error_m", 2),
    ("  within LiDAR range [m]", "median_position_error_within_lidar_range_m", 2),
    ("  beyond LiDAR range [m]", "median_position_error_beyond_lidar_range_m", 2),
    ("COG RMSE [deg]", "cog_rmse_deg", 2),
    ("SOG RMSE [m/s]", "sog_rmse_mps", 3),
    ("detection rate", "detection_rate", 3),
    ("max detection latency [s]", "detection_latency_max_s", 1),
    ("false targets / min", "false_targets_per_min", 2),
    ("false reports / min", "false_reports_per_min", 2),
    ("ID switches", "id_switches", 0),
    ("NEES mean (ideal 2)", "nees", 2),
    ("NEES in 95 % interval", "nees_fraction_in_95", 3),
    ("classification accuracy", "classification_accuracy", 3),
)


def format_table(metrics: dict) -> str:
    """A short readable table of the metrics for the terminal.

    Parameters
    ----------
    metrics : dict
        What :func:`evaluate` returns (or metrics.json loaded).

    Returns
    -------
    str
        The fused metrics with one column per sensor, then one line per truth object.
    """
    params = metrics.get("parameters", {})
    sensors = sorted(metrics.get("per_sensor") or {})
    columns = [("fused", metrics)] + [(s, metrics["per_sensor"][s]) for s in sensors]
    label_w = max(len(label) for label, _, _ in _TABLE_ROWS) + 2
    lines = [f"TDM evaluation: c = {_fmt(params.get('c_m'), 0)} m, p = {_fmt(params.get('p'), 0)}, "
             f"{metrics.get('epochs')} epochs, {_fmt(params.get('duration_s'), 1)} s, "
             f"sensors {', '.join(params.get('sensors_rendered') or []) or 'none'}",
             "metric".ljust(label_w) + "".join(name.rjust(9) for name, _ in columns)]
    for label, key, digits in _TABLE_ROWS:
        lines.append(label.ljust(label_w) + "".join(_fmt(m.get(key), digits).rjust(9) for _, m in columns))
    objects = metrics.get("per_object") or []
    if objects:
        name_w = max(12, max(len(o["name"]) for o in objects) + 2)
        lines.append("")
        lines.append("object".ljust(name_w) + "kind".ljust(10) + "latency_s".rjust(10) + "matched".rjust(9)
                     + "switches".rjust(9) + "median_err_m".rjust(13))
        for o in objects:
            lines.append(o["name"].ljust(name_w) + str(o["kind"]).ljust(10) + _fmt(o["latency_s"], 1).rjust(10)
                         + _fmt(o["matched_fraction"], 2).rjust(9) + _fmt(o["id_switches"]).rjust(9)
                         + _fmt(o["median_error_m"], 2).rjust(13))
    return "\n".join(lines)
