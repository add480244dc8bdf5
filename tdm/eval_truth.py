"""Truth for the evaluation: truth.jsonl in one streaming pass, kept only around the epochs it is used at.

truth.jsonl holds every object every 0.1 s (docs/formats.md); the evaluation needs it only at its
epochs (1 Hz by default). :func:`read_truth_samples` reads the file line by line, checks every line
(a mapping; ``t``, ``id``, ``name``, ``kind``, ``lat``, ``lon`` of the right types, numbers finite, an
``mmsi`` null or of nine digits at most,
``t`` in [0, 1e8] s and in order, one sample per object and time, one own ship, an object's name and
kind the same on every line), and keeps per object only the samples that bracket a wanted time (the
last sample at or before it and the first at or after it) plus the object's first and last samples.
Linear interpolation and the nearest sample at the wanted times are then exactly what they are over
every sample (``np.interp`` uses the two bracketing samples only), in memory that grows with the
epochs, not with the 10 Hz lines.
"""

from __future__ import annotations

import json
import math
from array import array
from bisect import bisect_right
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tdm.errors import RecordingError
from tdm.eval_lines import LAT_BOUND_DEG, LON_BOUND_DEG, MAX_TIME_S, LineReader, _object_array
from tdm.frames import EnuFrame

#: Epoch times are compared after rounding to this many decimals of a second (1 us).
EPOCH_DECIMALS = 6
#: A truth object exists at an epoch within this tolerance of its first/last sample, s (half the 0.1 s truth step).
TRUTH_TIME_TOLERANCE_S = 0.05
#: The own ship's ``kind`` in truth.jsonl.
OWNSHIP_KIND = "ownship"
#: Bytes read back from the end of truth.jsonl to find its last line's time (a line is about 300 bytes).
TAIL_BYTES = 65536
#: Most epochs the evaluation grid may have (1 Hz for 11 days, 10 Hz for 27 h): a bad time or rate in a
#: file must not make the evaluation allocate without bound.
MAX_EPOCHS = 1_000_000
#: Most (epoch, object) cells of the truth-at-epochs matrices (about 80 MB per float64 matrix).
MAX_EPOCH_OBJECT_CELLS = 10_000_000

_COLUMNS = ("t", "lat", "lon", "cog_deg", "sog_mps")
#: An object's MMSI when truth.jsonl gives none (it sends no AIS, or the file predates the field).
NO_MMSI = -1
#: Largest MMSI (nine digits, ITU-R M.585).
MAX_MMSI = 999_999_999


class _Object:
    """Streaming state of one truth id: its name and kind, its latest sample and whether it is kept."""

    __slots__ = ("name", "kind", "mmsi", "last", "last_kept")

    def __init__(self, name: str, kind: str):
        self.name, self.kind = name, kind
        self.mmsi = NO_MMSI
        self.last: tuple = ()
        self.last_kept = True


class _Kept:
    """Kept truth samples as compact columns, in the order kept (per object: in time order)."""

    def __init__(self):
        self.cols = {name: array("d") for name in _COLUMNS}
        self.ids = array("q")
        self.ais = array("b")

    def add(self, sample: tuple) -> None:
        t, object_id, lat, lon, cog, sog, ais = sample
        cols = self.cols
        cols["t"].append(t)
        cols["lat"].append(lat)
        cols["lon"].append(lon)
        cols["cog_deg"].append(cog)
        cols["sog_mps"].append(sog)
        self.ids.append(object_id)
        self.ais.append(ais)


def _parse_sample(reader: LineReader, row: dict) -> tuple[tuple, str, str]:
    """(sample (t, id, lat, lon, cog, sog, ais), name, kind) of one truth line, every field checked.

    ``lat``, ``lon`` of the sample are the object's centre (``centre_lat``, ``centre_lon``: the middle
    of its above-water extents, which the TDM is asked to report) when the line has them, and its body
    origin otherwise (files from before truth carried the centre). The own ship keeps its body origin:
    the frame of the sensors' mounts and of the navigation. The body origin is checked either way.
    """
    t, object_id = reader.number_field(row, "t", lo=0.0, hi=MAX_TIME_S), reader.int_field(row, "id")
    lat = reader.number_field(row, "lat", lo=-LAT_BOUND_DEG, hi=LAT_BOUND_DEG)
    lon = reader.number_field(row, "lon", lo=-LON_BOUND_DEG, hi=LON_BOUND_DEG)
    cog = reader.number_field(row, "cog_deg", default=math.nan, null=True)
    sog = reader.number_field(row, "sog_mps", default=math.nan, null=True)
    ais = reader.bool_field(row, "ais")
    name, kind = reader.str_field(row, "name"), reader.str_field(row, "kind")
    has_lat, has_lon = "centre_lat" in row, "centre_lon" in row
    if has_lat != has_lon:
        present, absent = ("centre_lat", "centre_lon") if has_lat else ("centre_lon", "centre_lat")
        raise reader.fail(f"field {present!r} without {absent!r}")
    if has_lat:
        centre = (reader.number_field(row, "centre_lat", lo=-LAT_BOUND_DEG, hi=LAT_BOUND_DEG),
                  reader.number_field(row, "centre_lon", lo=-LON_BOUND_DEG, hi=LON_BOUND_DEG))
        if kind != OWNSHIP_KIND:
            lat, lon = centre
    return (t, object_id, lat, lon, cog, sog, ais), name, kind


def _mmsi(reader: LineReader, row: dict) -> int:
    """The line's ``mmsi``: a nine-digit integer, or :data:`NO_MMSI` when absent or null."""
    value = row.get("mmsi")
    if value is None:
        return NO_MMSI
    if type(value) is int and 0 <= value <= MAX_MMSI:
        return value
    raise reader.fail(f"field 'mmsi': {value!r} is not an MMSI (an integer of at most nine digits)"[:200])


def _new_object(reader: LineReader, objects: dict, object_id: int, name: str, kind: str) -> _Object:
    if kind == OWNSHIP_KIND:
        own = [i for i, o in objects.items() if o.kind == OWNSHIP_KIND]
        if own:
            raise reader.fail(f"a second own ship (id {object_id}; the first is id {own[0]})")
    objects[object_id] = obj = _Object(name, kind)
    return obj


def read_truth_samples(path: Path, keep_t_s: np.ndarray | None = None) -> tuple[dict[str, np.ndarray], tuple[float, float]]:
    """truth.jsonl's samples needed at the times ``keep_t_s`` (all of them when None), read line by line.

    Parameters
    ----------
    path : Path
        truth.jsonl.
    keep_t_s : (W,) float64, ascending, or None
        Times the truth will be interpolated at, s. Per object, the samples kept are its first
        and last, and for each wanted time the last sample at or before it and the first after
        it (one sample when it falls on the time).

    Returns
    -------
    truth : dict
        Columns of the kept samples (per object in time order): ``t`` (R,) s, ``id`` (R,) int64,
        ``name``, ``kind`` (R,) str, ``lat``, ``lon`` (R,) deg, ``cog_deg``, ``sog_mps`` (R,)
        (NaN when absent or null), ``ais`` (R,) bool, ``mmsi`` (R,) int64 (the object's first
        ``mmsi`` in the file, :data:`NO_MMSI` when it has none).
    span_s : tuple of float
        Times of the file's first and last lines, s: its span, the times being in order.

    Raises
    ------
    RecordingError
        A line that is not a truth sample, times out of order, an object twice at one time, an
        object whose name or kind changes, a second own ship; no samples; no own ship.
    """
    reader = LineReader(path)
    wanted = None if keep_t_s is None else np.asarray(keep_t_s, dtype=float).tolist()
    n_wanted = 0 if wanted is None else len(wanted)
    kept, objects = _Kept(), {}
    first_s = previous_s = -math.inf
    for row in reader.rows():  # loop over lines (JSON parsing is per line); bisection per line
        sample, name, kind = _parse_sample(reader, row)
        t, object_id = sample[0], sample[1]
        previous_s = reader.in_order(t, previous_s)
        first_s = t if first_s == -math.inf else first_s
        obj = objects.get(object_id)
        if obj is None:
            obj = _new_object(reader, objects, object_id, name, kind)
            kept.add(sample)
            keep = True
        else:
            if name != obj.name or kind != obj.kind:
                raise reader.fail(f"id {object_id} is {name!r} ({kind}) here but {obj.name!r} ({obj.kind}) before")
            last_s = obj.last[0]
            if t == last_s:
                raise reader.fail(f"id {object_id} a second time at t = {t!r}")
            if wanted is None:
                keep = True
            else:
                j = bisect_right(wanted, last_s)  # first wanted time after the object's previous sample
                keep = j < n_wanted and wanted[j] <= t
                if keep and wanted[j] < t and not obj.last_kept:
                    kept.add(obj.last)
            if keep:
                kept.add(sample)
        mmsi = _mmsi(reader, row)
        obj.mmsi = mmsi if obj.mmsi == NO_MMSI else obj.mmsi
        obj.last, obj.last_kept = sample, keep
    if not objects:
        raise RecordingError(str(path), "(file)", "holds no truth samples")
    if not any(o.kind == OWNSHIP_KIND for o in objects.values()):
        raise RecordingError(str(path), "(file)", f"no own ship (kind {OWNSHIP_KIND!r})")
    for obj in objects.values():  # loop over objects: their last samples
        if not obj.last_kept:
            kept.add(obj.last)
    return _columns(kept, objects), (first_s, previous_s)


def _columns(kept: _Kept, objects: dict) -> dict:
    out = {name: np.frombuffer(col, dtype=float).copy() for name, col in kept.cols.items()}
    out["id"] = np.frombuffer(kept.ids, dtype=np.int64).copy()
    out["ais"] = np.frombuffer(kept.ais, dtype=np.int8).astype(bool)
    ids = np.array(sorted(objects), dtype=np.int64)
    index = np.searchsorted(ids, out["id"])
    out["name"] = _object_array([objects[int(i)].name for i in ids])[index]
    out["kind"] = _object_array([objects[int(i)].kind for i in ids])[index]
    out["mmsi"] = np.array([objects[int(i)].mmsi for i in ids], dtype=np.int64)[index]
    return out


def truth_span(path: Path) -> tuple[float, float] | None:
    """Times of truth.jsonl's first and last lines, s, read without reading the file through.

    None when either line cannot be read as a mapping with a number ``t`` in [0, 1e8] (the full pass
    then finds what is wrong); the full pass also checks that the times are in order, which makes
    these two the span.
    """
    try:
        with open(path, "rb") as handle:
            first = next((line for line in handle if line.strip()), b"")
            size = handle.seek(0, 2)
            handle.seek(max(0, size - TAIL_BYTES))
            tail = handle.read().rstrip()
            start = tail.rfind(b"\n")
            if start < 0 and size > TAIL_BYTES:
                return None
            times = [json.loads(line)["t"] for line in (first, tail[start + 1:])]
    except (OSError, ValueError, KeyError, TypeError, IndexError):
        return None
    if all(type(t) in (int, float) and 0.0 <= t <= MAX_TIME_S for t in times):
        return float(times[0]), float(times[1])
    return None


def read_truth_enu(recording: Path, keep_t_s: np.ndarray | None = None) -> tuple[EnuFrame, dict[str, np.ndarray]]:
    """truth.jsonl in the evaluation's ENU frame (read line by line, checked; :func:`read_truth_samples`).

    Parameters
    ----------
    recording : Path
        Recording directory.
    keep_t_s : (W,) float64, ascending, optional
        Keep only the samples needed to interpolate at these times, s (:func:`read_truth_samples`);
        default every sample.

    Returns
    -------
    frame : EnuFrame
        Centred on the own ship's first truth position.
    truth : dict of (R,) arrays
        One entry per kept truth line: ``t`` (s), ``id`` (int64), ``name``, ``kind`` (str),
        ``east_m``, ``north_m`` (m), ``cog_deg``, ``sog_mps``, ``ais`` (bool), ``mmsi`` (int64).
    """
    frame, truth, _ = truth_enu_and_span(recording, keep_t_s)
    return frame, truth


def truth_enu_and_span(recording: Path, keep_t_s: np.ndarray | None = None) \
        -> tuple[EnuFrame, dict[str, np.ndarray], tuple[float, float]]:
    """:func:`read_truth_enu` and the times of truth.jsonl's first and last lines, s."""
    truth, span_s = read_truth_samples(Path(recording) / "truth.jsonl", keep_t_s)
    lat, lon = truth.pop("lat"), truth.pop("lon")
    first = int(np.flatnonzero(truth["kind"] == OWNSHIP_KIND)[0])  # the own ship's first sample (times in order)
    frame = EnuFrame(lat[first], lon[first])
    truth["east_m"], truth["north_m"] = frame.to_enu(lat, lon)
    return frame, truth, span_s


# ----------------------------------------------------------------------------------------------- epochs


def epoch_grid(report_t_s: np.ndarray, rate_hz: float, t0_s: float, t1_s: float) -> np.ndarray:
    """Epoch times (tdm.evaluate docstring): the output grid over [t0, t1] united with the reported times.

    Parameters
    ----------
    report_t_s : (N,) float64
        Reported times, s.
    rate_hz : float
        Output rate, Hz.
    t0_s, t1_s : float
        The truth's span, s.

    Returns
    -------
    (E,) float64
        Ascending, unique, rounded to :data:`EPOCH_DECIMALS`.
    """
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


def check_epoch_count(truth_path: Path, rate_hz: float, t0_s: float, t1_s: float) -> None:
    """Refuse a grid of more than :data:`MAX_EPOCHS` epochs before it is made (RecordingError on truth.jsonl)."""
    n = (t1_s - t0_s) * rate_hz
    if not n <= MAX_EPOCHS:
        raise RecordingError(str(truth_path), "(file)",
                             f"spans {t1_s - t0_s:.6g} s: at tdm.update_rate_hz = {rate_hz:g} Hz that is {n:.3g} "
                             f"epochs, more than the evaluation's {MAX_EPOCHS}")


def epoch_index(t_s: np.ndarray, epochs: np.ndarray) -> np.ndarray:
    """(N,) index of each report's epoch, -1 for reports outside the truth's span."""
    rounded = np.round(t_s, EPOCH_DECIMALS)
    idx = np.searchsorted(epochs, rounded)
    ok = idx < epochs.size
    ok[ok] = epochs[idx[ok]] == rounded[ok]
    return np.where(ok, idx, -1)


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
    mmsi : (K,) int64 or None
        Each object's MMSI (:data:`NO_MMSI` when it has none); None: not known.
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
    mmsi: np.ndarray | None = None


def _nearest_index(t_samples: np.ndarray, t_query: np.ndarray) -> np.ndarray:
    idx = np.clip(np.searchsorted(t_samples, t_query), 1, max(t_samples.size - 1, 1))
    if t_samples.size == 1:
        return np.zeros(t_query.shape, dtype=np.int64)
    left_closer = (t_query - t_samples[idx - 1]) <= (t_samples[idx] - t_query)
    return np.where(left_closer, idx - 1, idx)


def check_cell_count(truth_path: Path, n_epochs: int, truth: dict[str, np.ndarray]) -> None:
    """Refuse more than :data:`MAX_EPOCH_OBJECT_CELLS` (epoch, object) cells before they are allocated."""
    n_objects = np.unique(truth["id"][truth["kind"] != OWNSHIP_KIND]).size
    if n_epochs * n_objects > MAX_EPOCH_OBJECT_CELLS:
        raise RecordingError(str(truth_path), "(file)",
                             f"{n_objects} objects at {n_epochs} epochs is more than the evaluation's "
                             f"{MAX_EPOCH_OBJECT_CELLS} (object, epoch) pairs")


def truth_at(truth: dict[str, np.ndarray], t_s: np.ndarray) -> TruthAtEpochs:
    """Truth interpolated at the epochs ``t_s`` (E,) s (tdm.evaluate docstring, "Truth at an epoch").

    ``truth`` is :func:`read_truth_enu`'s (the samples kept around ``t_s`` suffice).
    """
    objects = truth["kind"] != OWNSHIP_KIND
    ids = np.unique(truth["id"][objects])
    E, K = t_s.size, ids.size
    cols = {name: np.full((E, K), np.nan) for name in ("east_m", "north_m", "cog_deg", "sog_mps")}
    ais = np.zeros((E, K), dtype=bool)
    names, kinds = [], []
    by_id = np.argsort(truth["id"], kind="stable")  # per id: its samples in file (= time) order
    bounds = np.searchsorted(truth["id"][by_id], ids, side="left")
    ends = np.searchsorted(truth["id"][by_id], ids, side="right")

    def sample(order):
        ts = truth["t"][order]
        present = (t_s >= ts[0] - TRUTH_TIME_TOLERANCE_S) & (t_s <= ts[-1] + TRUTH_TIME_TOLERANCE_S)
        near = order[_nearest_index(ts, t_s)]
        return ts, present, near

    own_order = np.flatnonzero(~objects)
    own_t = truth["t"][own_order]
    own_e = np.interp(t_s, own_t, truth["east_m"][own_order])
    own_n = np.interp(t_s, own_t, truth["north_m"][own_order])
    for k in range(K):  # loop over objects
        order = by_id[bounds[k]:ends[k]]
        ts, present, near = sample(order)
        names.append(str(truth["name"][order[0]]))
        kinds.append(str(truth["kind"][order[0]]))
        for name in ("east_m", "north_m", "sog_mps"):
            cols[name][present, k] = np.interp(t_s[present], ts, truth[name][order])
        cols["cog_deg"][present, k] = truth["cog_deg"][near[present]]
        ais[present, k] = truth["ais"][near[present]]
    range_m = np.hypot(cols["east_m"] - own_e[:, None], cols["north_m"] - own_n[:, None])
    mmsi = None
    if "mmsi" in truth:
        mmsi = np.full(K, NO_MMSI, dtype=np.int64)
        mmsi[np.searchsorted(ids, truth["id"][objects])] = truth["mmsi"][objects]
    return TruthAtEpochs(t_s=t_s, ids=ids, names=names, kinds=kinds, ais=ais, range_m=range_m,
                         own_east_m=own_e, own_north_m=own_n, mmsi=mmsi, **cols)
