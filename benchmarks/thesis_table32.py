"""The thesis's Table 3.2 with raw sensors: steady-state errors of each sensor's track and of the fused target.

Usage::

    python benchmarks/thesis_table32.py [--quick] [--fresh] [--recording DIR] [--out benchmarks/results/thesis_table32.md]

Renders ``scenarios/thesis_table32.yaml`` (300 s, one vessel at 5 m/s with an oscillating heading,
MMSI 257000032, the own ship keeping pace 50 m to the west; ``--quick``: the first 120 s), runs the
TDM on it (:func:`tdm.pipeline.run_tdm`, default configuration) and computes, for every epoch at
``t >= 50 s`` (the thesis drops the first 50 s; docs/reference.md section 5):

- Which track is the vessel's: at each epoch, among a source's lines (one sensor's tracks in
  ``tdm/sensor_tracks.jsonl``, or the fused targets in ``tdm/detected_targets.jsonl``), the one
  whose position is nearest the truth vessel's, if within :data:`GATE_M`. Every track id so
  picked is used (and listed).
- Error = estimate - truth, the truth interpolated at the epoch in ``truth.jsonl`` (0.1 s):
  position north ("lat" in the thesis) and east ("lon"), m; COG, deg (difference wrapped to
  [-180, 180)); SOG, m/s. For each: standard deviation (the thesis's figure), bias (mean) and RMSE.
- Cross-section, m^2: the standard deviation of the estimate itself (the thesis has no truth for it).
- NEES of the position, ``e^T P^-1 e`` with P the reported ``position_cov_m2`` (ideal mean 2).
- Whether the fused estimate beats every single sensor in position north and east, heading and
  speed, as the thesis claims, and where it does not: on standard deviation (the thesis's measure)
  and on RMSE, over t >= 50 s and over the whole run.

The recording is rendered into ``--recording`` (default ``/tmp/thesis_table32_bench`` or
``..._quick``) and reused when it already holds a render of the same duration newer than the
scenario file (``--fresh`` renders again).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.common import ensure_recording, machine_line, publish  # noqa: E402
from tdm.evaluate import read_truth_enu  # noqa: E402
from tdm.frames import EnuFrame  # noqa: E402
from tdm.io import read_jsonl  # noqa: E402

SCENARIO = ROOT / "scenarios" / "thesis_table32.yaml"
#: The vessel's MMSI in scenarios/thesis_table32.yaml.
VESSEL_MMSI = 257000032
#: The thesis drops the first 50 s as the transient (docs/reference.md section 5, Table 3.2), s.
STEADY_FROM_S = 50.0
#: A track is the vessel's at an epoch when it is the source's nearest to the truth vessel and within this, m (task brief).
GATE_M = 50.0
#: Sources in table order; "fused" is detected_targets.jsonl.
SOURCES = ("ais", "radar", "lidar", "fused")
#: States compared for "fused beats every sensor" (the thesis's claim, docs/reference.md section 5).
COMPARED = ("north_m", "east_m", "cog_deg", "sog_mps")
#: Thesis Table 3.2 (docs/reference.md section 5): steady-state standard deviations
#: (pos lat m, pos lon m, heading deg, speed m/s, cross-section m^2).
THESIS_TABLE32 = {
    "ais": {"north_m": 2.315, "east_m": 1.499, "cog_deg": 3.240, "sog_mps": 0.013, "cross_section_m2": 0.000},
    "radar": {"north_m": 0.863, "east_m": 2.414, "cog_deg": 4.839, "sog_mps": 0.018, "cross_section_m2": 0.024},
    "lidar": {"north_m": 0.807, "east_m": 2.426, "cog_deg": 4.066, "sog_mps": 0.008, "cross_section_m2": 0.013},
    "fused": {"north_m": 0.795, "east_m": 1.562, "cog_deg": 3.002, "sog_mps": 0.005, "cross_section_m2": 0.003},
}
LABELS = {"ais": "AIS", "radar": "Radar", "lidar": "LiDAR", "fused": "Simple Fusion (fused)",
          "north_m": "position north (lat), m", "east_m": "position east (lon), m", "cog_deg": "heading (COG), deg",
          "sog_mps": "speed (SOG), m/s", "cross_section_m2": "cross-section, m^2"}
#: Two-sided 95 % interval of chi-square with 2 degrees of freedom (as tdm.evaluate), dimensionless.
NEES_95_INTERVAL = (-2.0 * math.log(0.975), -2.0 * math.log(0.025))


# ------------------------------------------------------------------------------------------ the computation


def _wrap_deg(d: np.ndarray) -> np.ndarray:
    return (np.asarray(d, dtype=float) + 180.0) % 360.0 - 180.0


def vessel_truth(recording: Path, mmsi: int = VESSEL_MMSI) -> tuple[EnuFrame, dict[str, np.ndarray]]:
    """The vessel's truth samples in the evaluation's ENU frame (:func:`tdm.evaluate.read_truth_enu`).

    Returns
    -------
    frame : EnuFrame
    truth : dict of (T,) arrays
        ``t`` s, ``east_m``, ``north_m`` m, ``cog_deg`` deg, ``sog_mps`` m/s, sorted by time.
    """
    frame, truth = read_truth_enu(recording)
    rows = read_jsonl(Path(recording) / "truth.jsonl")
    mmsis = np.array([r.get("mmsi") if r.get("mmsi") is not None else -1 for r in rows], dtype=np.int64)
    ids = np.unique(truth["id"][mmsis == mmsi])
    if ids.size != 1:
        raise ValueError(f"{recording}: {ids.size} truth objects with MMSI {mmsi}, expected one")
    sel = truth["id"] == ids[0]
    order = np.argsort(truth["t"][sel], kind="stable")
    return frame, {k: truth[k][sel][order] for k in ("t", "east_m", "north_m", "cog_deg", "sog_mps")}


def truth_at(truth: dict[str, np.ndarray], t_s: np.ndarray) -> dict[str, np.ndarray]:
    """Truth linearly interpolated at times ``t_s`` (N,) s (COG unwrapped first); dict of (N,) arrays."""
    cog = np.degrees(np.unwrap(np.radians(truth["cog_deg"])))
    return {"east_m": np.interp(t_s, truth["t"], truth["east_m"]),
            "north_m": np.interp(t_s, truth["t"], truth["north_m"]),
            "cog_deg": np.mod(np.interp(t_s, truth["t"], cog), 360.0),
            "sog_mps": np.interp(t_s, truth["t"], truth["sog_mps"])}


def read_lines(path: Path, frame: EnuFrame) -> dict[str, np.ndarray]:
    """detected_targets.jsonl / sensor_tracks.jsonl as columns in ``frame``.

    Returns
    -------
    dict of (N,) arrays
        ``t`` s, ``target_id``, ``sensor`` ("fused" in detected_targets.jsonl), ``east_m``,
        ``north_m`` m, ``cog_deg``, ``sog_mps``, ``cross_section_m2`` (NaN when null) and
        ``cov`` (N, 2, 2) m^2 ENU position covariance (NaN when absent).
    """
    rows = read_jsonl(path)

    def col(key, default=np.nan):
        return np.array([default if r.get(key) is None else r[key] for r in rows], dtype=float)

    out = {"t": col("t"), "target_id": col("target_id").astype(np.int64),
           "sensor": np.array([r.get("sensor", "fused") for r in rows], dtype=object),
           "cog_deg": col("cog_deg"), "sog_mps": col("sog_mps"), "cross_section_m2": col("cross_section_m2")}
    lat, lon = col("latitude"), col("longitude")
    out["east_m"], out["north_m"] = frame.to_enu(lat, lon) if rows else (np.zeros(0), np.zeros(0))
    cov = np.full((len(rows), 2, 2), np.nan)
    for i, r in enumerate(rows):  # one small 2x2 list per line
        if r.get("position_cov_m2") is not None:
            cov[i] = np.asarray(r["position_cov_m2"], dtype=float)
    out["cov"] = cov
    return out


def nearest_per_epoch(lines: dict[str, np.ndarray], truth: dict[str, np.ndarray], gate_m: float = GATE_M
                      ) -> np.ndarray:
    """Indices of the lines that are the vessel's: per epoch, the line nearest the truth, if within ``gate_m``."""
    if lines["t"].size == 0:
        return np.zeros(0, dtype=np.int64)
    at = truth_at(truth, lines["t"])
    dist = np.hypot(lines["east_m"] - at["east_m"], lines["north_m"] - at["north_m"])
    order = np.lexsort((dist, lines["t"]))
    t_sorted = lines["t"][order]
    first = np.ones(order.size, dtype=bool)
    first[1:] = t_sorted[1:] != t_sorted[:-1]
    best = order[first]
    return np.sort(best[dist[best] <= gate_m])


def _nees(err: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """(P,) ``e^T P^-1 e`` from (P, 2) errors and (P, 2, 2) covariances; NaN where P is not positive definite."""
    a, b, d = cov[:, 0, 0], 0.5 * (cov[:, 0, 1] + cov[:, 1, 0]), cov[:, 1, 1]
    det = a * d - b * b
    with np.errstate(invalid="ignore", divide="ignore"):
        value = (d * err[:, 0] ** 2 - 2 * b * err[:, 0] * err[:, 1] + a * err[:, 1] ** 2) / det
    return np.where(np.isfinite(value) & (det > 0) & (a > 0), value, np.nan)


def _stats(err: np.ndarray) -> dict:
    err = err[np.isfinite(err)]
    if err.size < 2:
        return {"n": int(err.size), "std": math.nan, "bias": math.nan, "rmse": math.nan}
    return {"n": int(err.size), "std": float(np.std(err, ddof=1)), "bias": float(np.mean(err)),
            "rmse": float(np.sqrt(np.mean(err ** 2)))}


def source_errors(lines: dict[str, np.ndarray], truth: dict[str, np.ndarray], n_epochs: int) -> dict:
    """Steady-state error statistics of one source's vessel track (module docstring).

    Parameters
    ----------
    lines : dict of (N,) arrays
        That source's lines (:func:`read_lines`), already restricted to ``t >= STEADY_FROM_S``.
    truth : dict of (T,) arrays
        :func:`vessel_truth`.
    n_epochs : int
        Output epochs in the steady-state window (for the coverage).
    """
    pick = nearest_per_epoch(lines, truth)
    sel = {k: v[pick] for k, v in lines.items()}
    at = truth_at(truth, sel["t"])
    err = {"north_m": sel["north_m"] - at["north_m"], "east_m": sel["east_m"] - at["east_m"],
           "cog_deg": _wrap_deg(sel["cog_deg"] - at["cog_deg"]), "sog_mps": sel["sog_mps"] - at["sog_mps"]}
    out = {k: _stats(v) for k, v in err.items()}
    xs = sel["cross_section_m2"][np.isfinite(sel["cross_section_m2"])]
    out["cross_section_m2"] = {"n": int(xs.size), "std": float(np.std(xs, ddof=1)) if xs.size > 1 else math.nan,
                               "mean": float(np.mean(xs)) if xs.size else math.nan}
    nees = _nees(np.column_stack([err["east_m"], err["north_m"]]), sel["cov"])
    nees = nees[np.isfinite(nees)]
    ids, counts = np.unique(sel["target_id"], return_counts=True)
    out.update({
        "epochs_matched": int(pick.size), "coverage": pick.size / n_epochs if n_epochs else math.nan,
        "track_ids": {int(i): int(c) for i, c in zip(ids, counts)},
        "nees_mean": float(np.mean(nees)) if nees.size else math.nan,
        "nees_fraction_in_95": float(np.mean((nees >= NEES_95_INTERVAL[0]) & (nees <= NEES_95_INTERVAL[1])))
        if nees.size else math.nan,
        "position_error_max_m": float(np.max(np.hypot(err["east_m"], err["north_m"]))) if pick.size else math.nan,
        "epochs_with_lines": int(np.unique(lines["t"]).size),
    })
    return out


def table32(recording: Path, tdm_dir: Path | None = None, steady_from_s: float = STEADY_FROM_S,
            mmsi: int = VESSEL_MMSI) -> dict:
    """Table 3.2 of the thesis from a recording the TDM has run on (module docstring).

    Parameters
    ----------
    recording : Path
        A render of scenarios/thesis_table32.yaml (truth.jsonl, manifest.json).
    tdm_dir : Path, optional
        Where ``detected_targets.jsonl`` and ``sensor_tracks.jsonl`` are; default ``RECORDING/tdm``.
    steady_from_s : float
        Epochs before this time are the transient and left out, s.
    mmsi : int
        The vessel's MMSI in truth.jsonl.

    Returns
    -------
    dict
        ``sources[s]`` for s in ais, radar, lidar, fused: per state (``north_m``, ``east_m``,
        ``cog_deg``, ``sog_mps``) ``{"n", "std", "bias", "rmse"}``; ``cross_section_m2``
        ``{"n", "std", "mean"}``; ``epochs_matched``, ``coverage`` (fraction of steady-state
        epochs), ``track_ids`` ({id: epochs}), ``nees_mean``, ``nees_fraction_in_95``,
        ``position_error_max_m``. Also ``fused_beats_every_sensor`` (bool), ``exceptions``
        (list of str: where it does not), ``n_epochs``, ``steady_from_s``, ``thesis`` (Table 3.2).
    """
    rec = Path(recording)
    out_dir = Path(tdm_dir) if tdm_dir is not None else rec / "tdm"
    frame, truth = vessel_truth(rec, mmsi)
    tracks = read_lines(out_dir / "sensor_tracks.jsonl", frame)
    fused = read_lines(out_dir / "detected_targets.jsonl", frame)
    epochs = np.unique(np.concatenate([tracks["t"], fused["t"]]))
    epochs = epochs[epochs >= steady_from_s - 1e-9]
    n_epochs = int(epochs.size)
    sources = {}
    for source in SOURCES:
        lines = fused if source == "fused" else tracks
        keep = (lines["t"] >= steady_from_s - 1e-9) & ((lines["sensor"] == source) | (source == "fused"))
        sources[source] = source_errors({k: v[keep] for k, v in lines.items()}, truth, n_epochs)
    exceptions = {measure: _not_beaten(sources, measure) for measure in ("std", "rmse")}
    return {"sources": sources, "fused_beats_every_sensor": not exceptions["std"], "exceptions": exceptions["std"],
            "fused_beats_every_sensor_rmse": not exceptions["rmse"], "exceptions_rmse": exceptions["rmse"],
            "n_epochs": n_epochs, "steady_from_s": steady_from_s, "gate_m": GATE_M, "thesis": THESIS_TABLE32}


def _not_beaten(sources: dict, measure: str) -> list[str]:
    """Where the fused estimate's ``measure`` ("std" or "rmse") is not under every sensor's (list of str)."""
    out = []
    for sensor in ("ais", "radar", "lidar"):
        for state in COMPARED:
            f, s = sources["fused"][state][measure], sources[sensor][state][measure]
            if not math.isfinite(s):
                out.append(f"{LABELS[state]}: {LABELS[sensor]} has no track of the vessel")
            elif not (math.isfinite(f) and f < s):
                out.append(f"{LABELS[state]}: fused {measure} {f:.4g} >= {LABELS[sensor]} {measure} {s:.4g}")
    return out


def raw_measurement_errors(recording: Path, steady_from_s: float = STEADY_FROM_S, mmsi: int = VESSEL_MMSI) -> dict:
    """Errors of the front ends' measurements of the vessel, before any tracking (diagnosis).

    Every LiDAR cluster and radar plot (from :class:`tdm.pipeline.DetectionStream`, the
    pipeline's own front ends, default configuration) and every AIS report of ``mmsi`` at
    ``t >= steady_from_s``; per scan, the detection nearest the truth vessel at its own time
    (within :data:`GATE_M`). Error = measurement - truth at the measurement's time.

    Returns
    -------
    dict
        Per sensor: ``n``, ``bias_east_m``, ``bias_north_m``, ``std_east_m``, ``std_north_m``,
        ``reported_sigma_east_m``, ``reported_sigma_north_m`` (square roots of the mean reported
        ``position_cov_m2`` diagonal; NaN for AIS, whose reports carry none); for AIS also
        ``cog_bias_deg``, ``cog_std_deg``, ``sog_bias_mps``, ``sog_std_mps``; for LiDAR and radar
        ``cross_section_mean_m2``, ``cross_section_std_m2``.
    """
    from tdm.detections import ReadStats
    from tdm.pipeline import DetectionStream, TdmConfig

    rec = Path(recording)
    frame, truth = vessel_truth(rec, mmsi)
    stream = DetectionStream(rec, TdmConfig(workers=0), ReadStats())
    tdm_frame = stream.ownship.frame
    acc = {s: {"t": [], "e": [], "n": [], "cov": [], "cog": [], "sog": [], "xs": []} for s in ("ais", "radar", "lidar")}
    for t_s, sensor, payload in stream.events():
        if sensor == "ais":
            if payload.mmsi != mmsi or payload.time_s < steady_from_s:
                continue
            a = acc["ais"]
            a["t"].append(payload.time_s)
            a["e"].append(payload.position_m[0])
            a["n"].append(payload.position_m[1])
            a["cog"].append(payload.cog_deg)
            a["sog"].append(payload.sog_mps)
            continue
        if payload.time_s.size == 0 or t_s < steady_from_s:
            continue
        lat, lon = tdm_frame.to_geodetic(payload.position_m[:, 0], payload.position_m[:, 1])
        east, north = frame.to_enu(lat, lon)
        at = truth_at(truth, payload.time_s)
        dist = np.hypot(east - at["east_m"], north - at["north_m"])
        i = int(np.argmin(dist))
        if dist[i] > GATE_M:
            continue
        a = acc[sensor]
        a["t"].append(payload.time_s[i])
        a["e"].append(east[i])
        a["n"].append(north[i])
        a["cov"].append(payload.position_cov_m2[i])
        a["xs"].append(payload.cross_section_m2[i])
    out = {}
    for sensor, a in acc.items():
        t = np.asarray(a["t"], dtype=float)
        at = truth_at(truth, t)
        de, dn = np.asarray(a["e"]) - at["east_m"], np.asarray(a["n"]) - at["north_m"]
        res = {"n": int(t.size)}
        for name, d in (("east", de), ("north", dn)):
            res[f"bias_{name}_m"] = float(np.mean(d)) if d.size else math.nan
            res[f"std_{name}_m"] = float(np.std(d, ddof=1)) if d.size > 1 else math.nan
        if a["cov"]:
            cov = np.mean(np.asarray(a["cov"]), axis=0)
            res["reported_sigma_east_m"], res["reported_sigma_north_m"] = float(np.sqrt(cov[0, 0])), float(np.sqrt(cov[1, 1]))
            xs = np.asarray(a["xs"], dtype=float)
            res["cross_section_mean_m2"] = float(np.nanmean(xs))
            res["cross_section_std_m2"] = float(np.nanstd(xs, ddof=1)) if xs.size > 1 else math.nan
        else:
            res["reported_sigma_east_m"] = res["reported_sigma_north_m"] = math.nan
        if sensor == "ais":
            dc = _wrap_deg(np.asarray(a["cog"]) - at["cog_deg"])
            ds = np.asarray(a["sog"]) - at["sog_mps"]
            res.update({"cog_bias_deg": float(np.nanmean(dc)) if dc.size else math.nan,
                        "cog_std_deg": float(np.nanstd(dc, ddof=1)) if dc.size > 1 else math.nan,
                        "sog_bias_mps": float(np.nanmean(ds)) if ds.size else math.nan,
                        "sog_std_mps": float(np.nanstd(ds, ddof=1)) if ds.size > 1 else math.nan})
        out[sensor] = res
    return out


def raw_table(raw: dict) -> list[str]:
    """Markdown table of :func:`raw_measurement_errors`."""
    lines = ["Measurements before tracking (front ends' detections of the vessel at t >= 50 s, each against truth "
             "at its own time): bias and scatter, and the scatter the front end reports (its position_cov_m2):", "",
             "| | measurements | bias east / north, m | std east / north, m | reported sigma east / north, m "
             "| COG bias / std, deg | SOG bias / std, m/s | cross-section mean / std, m^2 |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for s in ("ais", "radar", "lidar"):
        r = raw[s]
        cog = f"{_fmt(r.get('cog_bias_deg', math.nan), 2)} / {_fmt(r.get('cog_std_deg', math.nan), 2)}" if s == "ais" else "-"
        sog = f"{_fmt(r.get('sog_bias_mps', math.nan))} / {_fmt(r.get('sog_std_mps', math.nan))}" if s == "ais" else "-"
        xs = "-" if s == "ais" else f"{_fmt(r['cross_section_mean_m2'], 1)} / {_fmt(r['cross_section_std_m2'], 1)}"
        lines.append(f"| {LABELS[s]} | {r['n']} | {_fmt(r['bias_east_m'], 2)} / {_fmt(r['bias_north_m'], 2)} "
                     f"| {_fmt(r['std_east_m'], 2)} / {_fmt(r['std_north_m'], 2)} "
                     f"| {_fmt(r['reported_sigma_east_m'], 2)} / {_fmt(r['reported_sigma_north_m'], 2)} | {cog} | {sog} | {xs} |")
    return lines


# ------------------------------------------------------------------------------------------ rendering and report


def _fmt(x: float, digits: int = 3) -> str:
    return "n/a" if x is None or not math.isfinite(x) else f"{x:.{digits}f}"


def tables(result: dict) -> list[str]:
    """Markdown tables of a :func:`table32` result: std (with the thesis's), bias, RMSE, tracks."""
    states = ("north_m", "east_m", "cog_deg", "sog_mps")
    src = result["sources"]
    head = "| | " + " | ".join(LABELS[s] for s in (*states, "cross_section_m2")) + " |"
    rule = "|---|" + "---:|" * (len(states) + 1)
    std = ["Standard deviation, ours (thesis Table 3.2):", "", head, rule]
    for s in SOURCES:
        cells = [f"{_fmt(src[s][k]['std'])} ({THESIS_TABLE32[s][k]:.3f})" for k in (*states, "cross_section_m2")]
        std.append(f"| {LABELS[s]} | " + " | ".join(cells) + " |")
    bias = ["Bias (mean error) and RMSE, ours; cross-section: mean estimate:", "", head, rule]
    for s in SOURCES:
        cells = [f"{_fmt(src[s][k]['bias'])} / {_fmt(src[s][k]['rmse'])}" for k in states]
        cells.append(_fmt(src[s]["cross_section_m2"]["mean"], 1))
        bias.append(f"| {LABELS[s]} | " + " | ".join(cells) + " |")
    tr = ["Tracks used (nearest to the truth vessel within "
          f"{result['gate_m']:g} m at each epoch), coverage of the {result['n_epochs']} steady-state epochs, NEES:", "",
          "| | track ids (epochs) | coverage | max position error, m | position NEES mean (ideal 2) | NEES in 95 % |",
          "|---|---|---:|---:|---:|---:|"]
    for s in SOURCES:
        ids = ", ".join(f"{i} ({n})" for i, n in src[s]["track_ids"].items()) or "none"
        tr.append(f"| {LABELS[s]} | {ids} | {_fmt(src[s]['coverage'], 2)} | {_fmt(src[s]['position_error_max_m'], 1)} "
                  f"| {_fmt(src[s]['nees_mean'], 2)} | {_fmt(src[s]['nees_fraction_in_95'], 2)} |")
    return [*std, "", *bias, "", *tr]


def diagnosis(result: dict, raw: dict) -> list[str]:
    """Notes comparing each sensor's track with its own measurements (from the numbers, not hand-written)."""
    src, out = result["sources"], []
    for s in ("ais", "radar", "lidar"):
        r, t = raw[s], src[s]
        line = (f"- {LABELS[s]}: measurements scatter {_fmt(r['std_east_m'], 2)} / {_fmt(r['std_north_m'], 2)} m "
                f"(east / north) about a bias of {_fmt(r['bias_east_m'], 2)} / {_fmt(r['bias_north_m'], 2)} m")
        if math.isfinite(r["reported_sigma_east_m"]):
            ratio = math.hypot(r["reported_sigma_east_m"], r["reported_sigma_north_m"]) / math.hypot(r["std_east_m"],
                                                                                                    r["std_north_m"])
            line += f"; the front end reports {ratio:.1f} times that scatter"
        worse = [k for k, raw_k in (("east_m", "std_east_m"), ("north_m", "std_north_m"))
                 if math.isfinite(t[k]["std"]) and t[k]["std"] > r[raw_k]]
        line += (f"; the track's std ({_fmt(t['east_m']['std'], 2)} / {_fmt(t['north_m']['std'], 2)} m) is "
                 + ("larger than the measurements' scatter (" + ", ".join(w[:-2] for w in worse) + "): the filter lags"
                    if worse else "below the measurements' scatter"))
        if s == "ais":
            line += (f"; SOG reports scatter {_fmt(r['sog_std_mps'])} m/s, the track's SOG {_fmt(t['sog_mps']['std'])} m/s; "
                     f"COG reports {_fmt(r['cog_std_deg'], 2)} deg, the track's COG {_fmt(t['cog_deg']['std'], 2)} deg")
        out.append(line + ".")
    return ["Each sensor's track against its own measurements:", "", *out, ""]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="120 s instead of 300 s")
    parser.add_argument("--fresh", action="store_true", help="render again even if a matching render exists")
    parser.add_argument("--recording", type=Path, help="where to render (default /tmp/thesis_table32_bench[_quick])")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "thesis_table32.md")
    parser.add_argument("--json", type=Path, help="also write the figures as JSON")
    args = parser.parse_args(argv)
    from tdm.pipeline import run_tdm

    duration = 120.0 if args.quick else 300.0
    rec_dir = args.recording or Path("/tmp/thesis_table32_bench" + ("_quick" if args.quick else ""))
    rec, render_s = ensure_recording(SCENARIO, rec_dir, duration, args.fresh)
    start = time.perf_counter()
    run = run_tdm(rec)
    tdm_s = time.perf_counter() - start
    result = table32(rec)
    whole = table32(rec, steady_from_s=0.0)
    raw = raw_measurement_errors(rec)
    src = result["sources"]

    def verdict(r: dict, key: str) -> str:
        return f"**{'yes' if r[key] else 'no'}**"

    rows = [
        ("**fused beats every single sensor, t >= 50 s: on standard deviation (the thesis's measure)** "
         "(position north, east, heading, speed)", verdict(result, "fused_beats_every_sensor")),
        ("**... t >= 50 s: on RMSE**", verdict(result, "fused_beats_every_sensor_rmse")),
        ("**... the whole run (t >= 0): on standard deviation**", verdict(whole, "fused_beats_every_sensor")),
        ("**... the whole run (t >= 0): on RMSE**", verdict(whole, "fused_beats_every_sensor_rmse")),
        ("fused position NEES, mean (ideal 2)", _fmt(src["fused"]["nees_mean"], 2)),
        ("fused position NEES inside the 95 % interval (ideal 0.95)", _fmt(src["fused"]["nees_fraction_in_95"], 2)),
        ("steady-state epochs (t >= 50 s, 1 Hz)", f"{result['n_epochs']}"),
        ("TDM wall time, s", f"{tdm_s:.1f}"),
        ("render wall time, s", "reused" if render_s is None else f"{render_s:.0f}"),
        ("scans read (lidar / radar / AIS reports)", f"{run.scans.get('lidar', 0)} / {run.scans.get('radar', 0)} / "
                                                      f"{run.scans.get('ais', 0)}"),
    ]
    intro = [
        machine_line("thesis_table32", args.quick), "",
        f"Scenario `scenarios/thesis_table32.yaml`, {duration:g} s rendered (raw LiDAR sweeps, radar sweeps, AIS "
        "NMEA), `tdm run` with its default configuration (simple fusion), errors over the epochs at t >= 50 s "
        "against truth.jsonl interpolated at each epoch. Position error is of the reported position against the "
        "truth reference point of the vessel (its centre); heading is the reported COG (wrapped difference); "
        "the cross-section figure is the standard deviation of the estimate itself. The thesis's own numbers "
        "(docs/reference.md section 5) come from sensors simulated as noisy copies of truth at 0.5 Hz; ours from "
        "ray-cast raw data and the TDM's front ends (LiDAR at 10 Hz, radar at 0.4 Hz, AIS at its reporting "
        "rate), so only the order and the claim are comparable.", "",
        *tables(result), "",
        *raw_table(raw),
    ]
    intro += ["", "The whole run, t >= 0 s (the first 50 s included):", "", *tables(whole)[4 + len(SOURCES):]]
    notes = []
    for label, r, key in (("t >= 50 s, standard deviation", result, "exceptions"),
                          ("t >= 50 s, RMSE", result, "exceptions_rmse"),
                          ("whole run, standard deviation", whole, "exceptions"),
                          ("whole run, RMSE", whole, "exceptions_rmse")):
        if r[key]:
            notes += [f"Where the fused estimate does not beat a sensor ({label}):", "",
                      *[f"- {e}" for e in r[key]], ""]
    notes += diagnosis(result, raw)
    multi = [s for s in SOURCES if len(src[s]["track_ids"]) > 1]
    if multi:
        notes.append("Sources whose vessel track had several ids over time (all used): "
                     + ", ".join(f"{LABELS[s]} ({len(src[s]['track_ids'])} ids)" for s in multi) + ".")
    figures = {"fused_beats_every_sensor": result["fused_beats_every_sensor"], "exceptions": result["exceptions"],
               "fused_beats_every_sensor_rmse": result["fused_beats_every_sensor_rmse"],
               "exceptions_rmse": result["exceptions_rmse"],
               "whole_run": {"fused_beats_every_sensor": whole["fused_beats_every_sensor"],
                             "fused_beats_every_sensor_rmse": whole["fused_beats_every_sensor_rmse"],
                             "rmse": {s: {k: whole["sources"][s][k]["rmse"] for k in COMPARED} for s in SOURCES}},
               "std": {s: {k: src[s][k]["std"] for k in (*COMPARED, "cross_section_m2")} for s in SOURCES},
               "bias": {s: {k: src[s][k]["bias"] for k in COMPARED} for s in SOURCES},
               "rmse": {s: {k: src[s][k]["rmse"] for k in COMPARED} for s in SOURCES},
               "coverage": {s: src[s]["coverage"] for s in SOURCES},
               "nees_mean": {s: src[s]["nees_mean"] for s in SOURCES}, "tdm_wall_s": tdm_s, "raw_measurements": raw}
    publish("Thesis Table 3.2 with raw sensors", intro, rows, args.out, args.json, figures, notes)
    return 0


if __name__ == "__main__":
    sys.exit(main())
