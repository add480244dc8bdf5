"""Which truth objects each sensor could see at each epoch: ranges, and the sweeps' ray truth.

The LiDAR sweeps' ``object_id`` (which object each point hit) and the radar sweeps'
``object_id`` / ``object_spokes`` (which objects each revolution's rays reached) are read one
sweep at a time; only what the (E, K) masks need is kept.

Sweep files (docs/formats.md, "What tdm evaluate refuses"):

- a file that is not a readable archive (zero bytes, not a zip, cut short, damaged array data:
  what a crash or a broken copy leaves) is a *warning*, counted in the returned warnings under
  the same key as ``tdm run`` counts it (:mod:`tdm.recording.npz`): that sweep saw nothing;
- anything else that does not read as the format says (an array of the wrong dtype or shape,
  lengths that disagree, non-finite times or angles, an array header that declares more data
  than its file holds, a pickled array) is an *error* (:class:`tdm.errors.RecordingError`);
- sweeps without the ray-truth arrays (made before they existed) make the sensor's
  visibility its range, as before.
"""

from __future__ import annotations

from array import array
from pathlib import Path

import numpy as np

from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.eval_params import EvalParams
from tdm.eval_truth import TruthAtEpochs
from tdm.frames import EnuFrame
from tdm.frontend.ais import read_ais
from tdm.recording.files import is_present, regular_file
from tdm.recording.npz import ArrayHeader, NpzFile, Unreadable
from tdm.recording.sweeps import unreadable_warning

#: Half-width of the window about an epoch in which a LiDAR hit, or the radar's view of an object, makes it
#: visible, s (task definition).
VISIBLE_WINDOW_S = 0.5
#: Fewest spokes of a revolution whose rays must reach an object for the radar to see it (0.5 deg at 2048
#: spokes; a radar plot needs 3 spokes too, docs/tdm.md).
RADAR_VISIBLE_MIN_SPOKES = 3
#: Arrays read from a LiDAR sweep: name -> (accepted dtype kinds, ndim).
LIDAR_ARRAYS = {"object_id": ("iu", 1), "time": ("f", 1)}
#: Arrays read from a radar sweep: name -> (accepted dtype kinds, ndim).
RADAR_ARRAYS = {"object_id": ("iu", 1), "object_spokes": ("iu", 1), "time": ("f", 1), "azimuth_deg": ("f", 1),
                "heading_deg": ("f", 1)}
#: Returned by :func:`load_sweep` for a sweep without the ray-truth arrays.
NO_RAY_TRUTH = "no ray truth"
#: An AIS ship is in the AIS's view from each position report received from it until this long after it, s:
#: the longest nominal reporting interval (ITU-R M.1371-5: class A at anchor or moored, class B at 2 kn or less,
#: every 3 min; docs/reference.md section 4). Before its first report no AIS receiver knows of it.
AIS_IN_VIEW_S = 180.0
def _count(warnings: dict[str, int], what: str) -> None:
    warnings[what] = warnings.get(what, 0) + 1


def _check_spec(file: Path, layout: dict[str, ArrayHeader], spec: dict[str, tuple[str, int]]) -> None:
    """Each array of ``spec``: its header's dtype kind and number of dimensions."""
    for name, (kinds, ndim) in spec.items():
        header = layout[name]
        if header.dtype.kind not in kinds or len(header.shape) != ndim:
            raise RecordingError(str(file), name, f"array of dtype {header.dtype} and shape {header.shape}: expected "
                                                  f"{ndim}-D of kind {' or '.join(repr(k) for k in kinds)} (docs/formats.md)")


def load_sweep(file: Path, spec: dict[str, tuple[str, int]], sensor: str, warnings: dict[str, int]):
    """The arrays ``spec`` of one sweep file, checked (headers first: :mod:`tdm.recording.npz`).

    Returns
    -------
    dict of arrays, None or :data:`NO_RAY_TRUTH`
        The arrays; None for a file that is not a readable archive (counted in ``warnings``);
        NO_RAY_TRUTH when the file lacks one of the arrays.

    Raises
    ------
    RecordingError
        An array not as ``spec`` says, or beyond what its file holds (module docstring).
    """
    try:
        with NpzFile(file) as npz:  # one pass over the archive: headers checked, then the arrays read
            if not all(name in npz.layout for name in spec):
                return NO_RAY_TRUTH
            _check_spec(file, npz.layout, spec)
            return npz.load(tuple(spec))
    except Unreadable as exc:
        _count(warnings, f"{unreadable_warning(sensor, exc.reason)}, counted as not seen")
        return None


def _same_length(file: Path, arrays: dict[str, np.ndarray], names: tuple[str, ...]) -> None:
    sizes = {name: arrays[name].size for name in names}
    if len(set(sizes.values())) > 1:
        raise RecordingError(str(file), ", ".join(names), f"lengths differ: {sizes}")


def _finite(file: Path, arrays: dict[str, np.ndarray], names: tuple[str, ...]) -> None:
    for name in names:
        if not np.all(np.isfinite(arrays[name])):
            raise RecordingError(str(file), name, "holds NaN or infinite values")


def _sweep_files(recording: Path, sensor: str) -> list[Path]:
    return sorted((Path(recording) / sensor / "sweeps").glob("*.npz"))


def lidar_visible(recording: Path, truth: TruthAtEpochs, warnings: dict[str, int]) -> np.ndarray | None:
    """(E, K) bool: a LiDAR point hit the object within +-:data:`VISIBLE_WINDOW_S` of the epoch; None without ray truth.

    Each sweep is reduced to the first and last hit time per object (the window is longer than a
    revolution, so a window that meets a sweep's hits on an object contains one of the two), and
    each of those times marks the epochs t with ``t - w <= hit <= t + w`` (difference array,
    cumulated at the end).
    """
    files = _sweep_files(recording, "lidar")
    if not files:
        return None
    column = {int(object_id): k for k, object_id in enumerate(truth.ids)}
    lo_s, hi_s = truth.t_s - VISIBLE_WINDOW_S, truth.t_s + VISIBLE_WINDOW_S
    marks = np.zeros((truth.t_s.size + 1, truth.ids.size), dtype=np.int64)
    for file in files:  # loop over sweeps, vectorised within
        sweep = load_sweep(file, LIDAR_ARRAYS, "lidar", warnings)
        if sweep is NO_RAY_TRUTH:
            return None
        if sweep is None:
            continue
        _same_length(file, sweep, ("object_id", "time"))
        oid, t = sweep["object_id"], sweep["time"]
        hit = oid >= 0
        if not hit.any():
            continue
        o, t = oid[hit].astype(np.int64), t[hit].astype(float)
        _finite(file, {"time": t}, ("time",))
        order = np.lexsort((t, o))
        o, t = o[order], t[order]
        starts = np.flatnonzero(np.r_[True, o[1:] != o[:-1]])
        ends = np.r_[starts[1:], o.size] - 1
        ids, times = np.r_[o[starts], o[ends]], np.r_[t[starts], t[ends]]
        known = np.array([int(i) in column for i in ids], dtype=bool)  # a few objects a sweep
        k = np.array([column[int(i)] for i in ids[known]], dtype=np.int64)
        first_e = np.searchsorted(hi_s, times[known], side="left")  # first epoch with t + w >= hit
        stop_e = np.searchsorted(lo_s, times[known], side="right")  # epochs with t - w <= hit end here
        np.add.at(marks, (first_e, k), 1)
        np.add.at(marks, (stop_e, k), -1)
    return np.cumsum(marks, axis=0)[:-1] > 0


def _radar_passes(sweep: dict[str, np.ndarray], truth: TruthAtEpochs, column: dict[int, int]):
    """(objects reached on enough spokes, their beam-pass times s, the revolution's period s) of one sweep."""
    ids, spokes, t = sweep["object_id"], sweep["object_spokes"], sweep["time"]
    period_s = float(t[-1] - t[0]) * t.size / max(t.size - 1, 1)
    reached = [int(i) for i in ids[spokes >= RADAR_VISIBLE_MIN_SPOKES] if int(i) in column]
    if not reached:
        return reached, np.zeros(0), period_s
    k = np.array([column[i] for i in reached])
    t_mid = 0.5 * float(t[0] + t[-1])
    east = np.array([np.interp(t_mid, truth.t_s, truth.east_m[:, j]) for j in k])  # a few objects
    north = np.array([np.interp(t_mid, truth.t_s, truth.north_m[:, j]) for j in k])
    bearing_deg = np.degrees(np.arctan2(east - np.interp(t_mid, truth.t_s, truth.own_east_m),
                                        north - np.interp(t_mid, truth.t_s, truth.own_north_m)))
    compass_deg = sweep["azimuth_deg"].astype(np.float64) + sweep["heading_deg"].astype(np.float64)
    off = np.abs((compass_deg[None, :] - bearing_deg[:, None] + 180.0) % 360.0 - 180.0)
    t_pass = np.where(np.isfinite(bearing_deg), t[np.argmin(off, axis=1)], t[0])
    return reached, t_pass, period_s


def radar_seen_intervals(recording: Path, truth: TruthAtEpochs,
                         warnings: dict[str, int]) -> dict[int, tuple[np.ndarray, np.ndarray]] | None:
    """When the radar saw each truth object: {id: ((R,) start s, (R,) end s)}, one interval per revolution.

    An object counts as seen in a revolution when its rays reached it on at least
    :data:`RADAR_VISIBLE_MIN_SPOKES` spokes (the sweep's ``object_id`` / ``object_spokes``). It is
    seen from the beam's pass over it (the time of the spoke whose compass bearing, azimuth +
    heading, is nearest the object's bearing from the own ship at the middle of the revolution) until
    one revolution later, when the next pass looks again. None when the sweeps carry no ``object_id``.
    """
    files = _sweep_files(recording, "radar")
    if not files:
        return None
    column = {int(object_id): k for k, object_id in enumerate(truth.ids)}
    seen: dict[int, array] = {}  # id -> start, end, start, end, ... s
    for file in files:  # loop over sweeps, a few ids each
        sweep = load_sweep(file, RADAR_ARRAYS, "radar", warnings)
        if sweep is NO_RAY_TRUTH:
            return None
        if sweep is None:
            continue
        _same_length(file, sweep, ("object_id", "object_spokes"))
        _same_length(file, sweep, ("time", "azimuth_deg", "heading_deg"))
        _finite(file, sweep, ("time", "azimuth_deg", "heading_deg"))
        if sweep["time"].size == 0:
            continue
        reached, t_pass, period_s = _radar_passes(sweep, truth, column)
        for object_id, start in zip(reached, t_pass):
            seen.setdefault(object_id, array("d")).extend((float(start), float(start) + period_s))
    return {k: (np.array(v[0::2]), np.array(v[1::2])) for k, v in seen.items()}


def _overlaps(starts: np.ndarray, ends: np.ndarray, t_s: np.ndarray, half_window_s: float) -> np.ndarray:
    """(E,) bool: some interval [start, end] meets [t - w, t + w] (starts ascending, ends ascending)."""
    if starts.size == 0:
        return np.zeros(t_s.shape, dtype=bool)
    idx = np.searchsorted(ends, t_s - half_window_s, side="left")
    return (idx < ends.size) & (starts[np.minimum(idx, ends.size - 1)] <= t_s + half_window_s)


def ais_reception_times(recording: Path, frame: EnuFrame, start_time_unix_s: float,
                        warnings: dict[str, int]) -> dict[int, np.ndarray] | None:
    """Reception times of each MMSI's position reports in ``ais/ais.nmea`` (s since the start); None without it.

    Read by the TDM's own reader (:func:`tdm.frontend.ais.read_ais`): a line it skips is counted in
    ``warnings`` as ``tdm run`` counts it, and is not a report received.
    """
    path = Path(recording) / "ais" / "ais.nmea"
    if not is_present(path):
        return None
    regular_file(path)
    stats = ReadStats()
    reports, _ = read_ais(path, frame, start_time_unix_s, stats)
    for what, n in stats.warnings.items():
        warnings[what] = warnings.get(what, 0) + n
    times: dict[int, list[float]] = {}
    for report in reports:  # loop over reports: a few per ship a minute
        times.setdefault(int(report.mmsi), []).append(float(report.time_s))
    return {mmsi: np.array(t) for mmsi, t in times.items()}


def ais_in_view(truth: TruthAtEpochs, received_s: dict[int, np.ndarray]) -> np.ndarray:
    """(E, K) bool: a position report of the object's MMSI was received within the last :data:`AIS_IN_VIEW_S`.

    Parameters
    ----------
    truth : TruthAtEpochs
        With ``mmsi`` (K,).
    received_s : dict of int to (M,) float
        Reception times of each MMSI's position reports, s since the recording's start.
    """
    out = np.zeros(truth.range_m.shape, dtype=bool)
    for k, mmsi in enumerate(truth.mmsi):  # loop over objects
        times = np.sort(np.asarray(received_s.get(int(mmsi), ()), dtype=float))
        if times.size:
            last = np.searchsorted(times, truth.t_s, side="right") - 1  # the last report at or before each epoch
            out[:, k] = (last >= 0) & (truth.t_s - times[np.maximum(last, 0)] <= AIS_IN_VIEW_S)
    return out


def visibility(recording: Path, params: EvalParams, truth: TruthAtEpochs, warnings: dict[str, int],
               ais_received_s: dict[int, np.ndarray] | None = None) -> tuple[dict, dict, dict]:
    """Per rendered sensor, the (E, K) in-range mask; per sensor whose view is ray truth, the (E, K) mask of
    objects within its range but hidden from it (occluded, below the horizon); and the parameters used.

    ``warnings`` receives a count per kind of sweep file cut short (module docstring). ``ais_received_s``
    (MMSI -> reception times of its position reports, s; :func:`ais_in_view`): the AIS sees a ship from its
    first report received; None (no ``ais/ais.nmea``, or truth without MMSIs): from the truth's ``ais`` flag.
    """
    present = np.isfinite(truth.range_m)
    rng = np.where(present, truth.range_m, np.inf)
    visible, hidden = {}, {}
    lidar_mode = radar_mode = None
    if "radar" in params.rendered:
        visible["radar"] = rng <= params.radar_range_m
        seen = radar_seen_intervals(recording, truth, warnings)
        radar_mode = "range" if seen is None else "rays"
        if seen is not None:
            mask = np.zeros(rng.shape, dtype=bool)
            for k, object_id in enumerate(truth.ids):  # loop over objects
                if int(object_id) in seen:
                    mask[:, k] = _overlaps(*seen[int(object_id)], truth.t_s, VISIBLE_WINDOW_S)
            hidden["radar"] = visible["radar"] & present & ~mask
            visible["radar"] &= mask
    ais_mode = None
    if "ais" in params.rendered:
        visible["ais"] = truth.ais & (rng <= params.ais_range_m)
        ais_mode = "range"
        if ais_received_s is not None and truth.mmsi is not None:
            ais_mode = "reports"
            heard = ais_in_view(truth, ais_received_s)
            hidden["ais"] = visible["ais"] & present & ~heard
            visible["ais"] &= heard
    if "lidar" in params.rendered:
        mask = lidar_visible(recording, truth, warnings)
        if mask is None:
            lidar_mode = "range"
            visible["lidar"] = rng <= params.lidar_range_m
        else:
            lidar_mode = "hits"
            visible["lidar"] = mask & present
            hidden["lidar"] = (rng <= params.lidar_range_m) & present & ~mask
    used = {"sensors_rendered": list(params.rendered), "radar_range_m": params.radar_range_m,
            "ais_range_m": params.ais_range_m, "lidar_range_max_m": params.lidar_range_m,
            "lidar_visibility": lidar_mode, "radar_visibility": radar_mode,
            "ais_visibility": ais_mode, "ais_in_view_s": AIS_IN_VIEW_S}
    return visible, hidden, used
