"""Scoring one set of reports against the in-range truth at the epochs (tdm.evaluate docstring).

:func:`score` assigns reports to truth per epoch (:mod:`tdm.metrics`), then computes the errors
over matched pairs, detection and latency per object, false targets and reports, and the
per-epoch series for the plots.
"""

from __future__ import annotations

import math

import numpy as np

from tdm.eval_best_sensor import pair_errors
from tdm.eval_identity import carry_forward_assignment, switches
from tdm.eval_truth import TruthAtEpochs
from tdm.metrics import GOSPA_ALPHA, assign_distances, distance_matrix, gospa_distances, ospa_distances

#: Shortest run of in-range epochs that brings an object into view for the latency, s: two radar
#: revolutions. A glimpse (one revolution's rays between two occlusions) cannot start a track that needs
#: two plots, so it does not start the latency clock (docs/tdm.md).
MIN_IN_VIEW_S = 5.0
#: Truth SOG above which an object counts as moving for the COG error, m/s (task definition).
MOVING_SOG_MPS = 0.5
#: GOSPA's cut-off within LiDAR range, m: c = 50 m counts a 49 m error as a detection; near the own ship, where
#: collision avoidance acts, 10 m (issue 22), beside the c of the whole scene.
NEAR_GOSPA_C_M = 10.0
#: Two-sided 95 % interval of chi-square with 2 degrees of freedom (CDF 1 - exp(-x/2)), dimensionless.
NEES_95_INTERVAL = (-2.0 * math.log(0.975), -2.0 * math.log(0.025))
#: Target descriptor expected for a truth kind (docs/formats.md, tdm/detected_targets.jsonl: "vessel" | "iceberg" | "unknown").
DESCRIPTOR_OF_KIND = {"ship": "vessel", "iceberg": "iceberg"}


def sustained_start(vis_e: np.ndarray, t_s: np.ndarray) -> int:
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


def _mean(x: np.ndarray) -> float:
    return float(np.mean(x)) if x.size else math.nan


def nees(err_m: np.ndarray, cov_m2: np.ndarray) -> np.ndarray:
    """(P,) NEES ``e^T P^-1 e`` from (P, 2) errors and (P, 2, 2) covariances; NaN where P is not positive definite."""
    sym = 0.5 * (cov_m2 + np.swapaxes(cov_m2, 1, 2))
    a, b, d = sym[:, 0, 0], sym[:, 0, 1], sym[:, 1, 1]
    det = a * d - b * b
    with np.errstate(invalid="ignore", divide="ignore"):
        value = (d * err_m[:, 0] ** 2 - 2 * b * err_m[:, 0] * err_m[:, 1] + a * err_m[:, 1] ** 2) / det
    ok = np.isfinite(det) & (det > 0) & (a > 0) & np.isfinite(value)
    return np.where(ok, value, np.nan)


def subset(reports: dict[str, np.ndarray], mask: np.ndarray) -> dict[str, np.ndarray]:
    """The reports where ``mask`` (N,) is True."""
    return {key: value[mask] for key, value in reports.items()}


def _assign(truth: TruthAtEpochs, visible: np.ndarray, rep_pos: np.ndarray, report_epoch: np.ndarray,
            target_id: np.ndarray, c_m: float, p: float, dont_care: np.ndarray | None,
            on_land: np.ndarray | None = None, near: tuple[float, float] | None = None) -> dict:
    """Per epoch: the assignment, OSPA and GOSPA terms; the matched pairs (epoch, object, report, distance); and
    from the reports' ``target_id`` (N,) the CLEAR MOT correspondence (:mod:`tdm.eval_identity`), ``mot_tid``
    (E, K), each object's matched target id per epoch (-1: not matched), for the id switches.

    A report ``on_land`` (N,) is at least the cut-off from every object: never matched nor ignored,
    a false report (and a cardinality error in OSPA and GOSPA). ``near`` (range m, cut-off m): also GOSPA
    with that cut-off over the objects and the (not ignored) reports within that range of the own ship
    (``per_epoch["gospa_near"]``).
    """
    land = np.zeros(report_epoch.size, dtype=bool) if on_land is None else np.asarray(on_land, dtype=bool)
    E = visible.shape[0]
    kept = np.flatnonzero(report_epoch >= 0)
    order = kept[np.argsort(report_epoch[kept], kind="stable")]
    bounds = np.searchsorted(report_epoch[order], np.arange(E + 1))
    truth_pos = np.stack([truth.east_m, truth.north_m], axis=-1)  # (E, K, 2)
    per_epoch = {name: np.zeros(E) for name in ("ospa", "gospa", "gospa_loc", "gospa_missed", "gospa_false",
                                                 "gospa_near")}
    own = np.stack([truth.own_east_m, truth.own_north_m], axis=-1)  # (E, 2)
    n_rep_e = np.diff(bounds)
    pairs_e, pairs_k, pairs_r, pairs_d = [], [], [], []
    is_ignored = np.zeros(report_epoch.size, dtype=bool)
    K = visible.shape[1]
    mot_tid = np.full((E, K), -1, dtype=np.int64)
    last_tid = np.full(K, -1, dtype=np.int64)
    for e in range(E):  # loop over epochs (scans); each assignment is a small matrix
        rows = order[bounds[e]:bounds[e + 1]]
        ks = np.flatnonzero(visible[e])
        hs = np.flatnonzero(dont_care[e] & ~visible[e]) if dont_care is not None else np.zeros(0, np.int64)
        if hs.size and rows.size:  # reports of hidden objects leave the set (one assignment over both)
            rj, cj = assign_distances(_off_land(distance_matrix(truth_pos[e, np.r_[ks, hs]], rep_pos[rows]),
                                                land[rows], c_m), c_m, p)
            drop = cj[rj >= ks.size]
            is_ignored[rows[drop]] = True
            rows = np.delete(rows, drop)
            n_rep_e[e] = rows.size
        d = _off_land(distance_matrix(truth_pos[e, ks], rep_pos[rows]), land[rows], c_m)
        per_epoch["ospa"][e] = ospa_distances(d, c_m, p)
        g = gospa_distances(d, c_m, p, GOSPA_ALPHA)
        per_epoch["gospa"][e], per_epoch["gospa_loc"][e] = g["total"], g["localisation"]
        per_epoch["gospa_missed"][e], per_epoch["gospa_false"][e] = g["missed"], g["false"]
        if near is not None:
            close_k = truth.range_m[e, ks] <= near[0]
            close_r = np.hypot(*(rep_pos[rows] - own[e]).T) <= near[0]
            per_epoch["gospa_near"][e] = gospa_distances(
                _off_land(distance_matrix(truth_pos[e, ks[close_k]], rep_pos[rows[close_r]]), land[rows[close_r]],
                          near[1]), near[1], p, GOSPA_ALPHA)["total"]
        r, cc = assign_distances(d, c_m, p)
        mr, mc = carry_forward_assignment(d, target_id[rows], last_tid[ks], c_m, p)
        mot_tid[e, ks[mr]] = last_tid[ks[mr]] = target_id[rows[mc]]
        pairs_e.append(np.full(r.size, e))
        pairs_k.append(ks[r])
        pairs_r.append(rows[cc])
        pairs_d.append(d[r, cc])
    pe, pk, pr = (np.concatenate(x).astype(np.int64) if x else np.zeros(0, np.int64)
                  for x in (pairs_e, pairs_k, pairs_r))
    pd = np.concatenate(pairs_d) if pairs_d else np.zeros(0)
    return {"per_epoch": per_epoch, "n_rep_e": n_rep_e, "kept": kept, "is_ignored": is_ignored,
            "pe": pe, "pk": pk, "pr": pr, "pd": pd, "truth_pos": truth_pos, "mot_tid": mot_tid}


def _off_land(d_m: np.ndarray, on_land: np.ndarray, c_m: float) -> np.ndarray:
    """The distances ``d_m`` (objects x reports) with those of the reports ``on_land`` raised to the cut-off."""
    if on_land.any():
        d_m[:, on_land] = np.maximum(d_m[:, on_land], c_m)
    return d_m


def _pair_errors(truth: TruthAtEpochs, reports: dict[str, np.ndarray], rep_pos: np.ndarray, a: dict,
                 lidar_range_m: float) -> dict:
    """Position, COG, SOG errors, NEES and classification over the matched pairs."""
    pe, pk, pr, pd = a["pe"], a["pk"], a["pr"], a["pd"]
    err = rep_pos[pr] - a["truth_pos"][pe, pk]
    within = truth.range_m[pe, pk] <= lidar_range_m
    cog_t, sog_t = truth.cog_deg[pe, pk], truth.sog_mps[pe, pk]
    cog_r, sog_r = reports["cog_deg"][pr], reports["sog_mps"][pr]
    moving = (sog_t > MOVING_SOG_MPS) & np.isfinite(cog_r) & np.isfinite(cog_t)
    cog_diff = np.mod(cog_r[moving] - cog_t[moving] + 180.0, 360.0) - 180.0
    sog_ok = np.isfinite(sog_r) & np.isfinite(sog_t)
    value = nees(err, reports["position_cov_m2"][pr])
    value = value[np.isfinite(value)]
    kinds = [truth.kinds[k] for k in pk]
    classed = np.array([k in DESCRIPTOR_OF_KIND for k in kinds], dtype=bool)
    expected = np.array([DESCRIPTOR_OF_KIND.get(k, "") for k in kinds], dtype=object)
    correct = (reports["descriptor"][pr] == expected)[classed] if pr.size else np.zeros(0, dtype=bool)
    cog_err = np.full(pr.size, np.nan)
    cog_err[moving] = cog_diff
    sog_err = np.where(sog_ok, sog_r - sog_t, np.nan)
    return {
        "_pairs": pair_errors(pe, pk, err, cog_err, sog_err),
        "position_rmse_m": _rms(pd),
        "median_position_error_m": _median(pd),
        "median_position_error_within_lidar_range_m": _median(pd[within]),
        "median_position_error_beyond_lidar_range_m": _median(pd[~within]),
        "position_bias_east_m": float(np.mean(err[:, 0])) if pd.size else math.nan,
        "position_bias_north_m": float(np.mean(err[:, 1])) if pd.size else math.nan,
        "cog_rmse_deg": _rms(cog_diff),
        "sog_rmse_mps": _rms(sog_r[sog_ok] - sog_t[sog_ok]),
        "nees": _mean(value),
        "nees_fraction_in_95": float(np.mean((value >= NEES_95_INTERVAL[0]) & (value <= NEES_95_INTERVAL[1])))
        if value.size else math.nan,
        "nees_pairs": int(value.size),
        "classification_accuracy": _mean(correct),
    }


def _per_object(truth: TruthAtEpochs, visible: np.ndarray, reports: dict[str, np.ndarray], a: dict) -> dict:
    """Detection, latency and id switches per object (those in range at least once)."""
    E, K = visible.shape
    t_s = truth.t_s
    matched_tid = np.full((E, K), -1, dtype=np.int64)
    matched_tid[a["pe"], a["pk"]] = reports["target_id"][a["pr"]]
    err_mat = np.full((E, K), np.nan)
    err_mat[a["pe"], a["pk"]] = a["pd"]
    per_object, latency, missed = [], {}, []
    switches_total, switches_max, optimal_total = 0, 0, 0
    for k in range(K):  # loop over objects
        vis_e = np.flatnonzero(visible[:, k])
        if vis_e.size == 0:
            continue
        m_e = np.flatnonzero(matched_tid[:, k] >= 0)
        start_e = sustained_start(vis_e, t_s)
        lat_s = max(float(t_s[m_e[0]] - t_s[start_e]), 0.0) if m_e.size else None
        glimpse_lat_s = float(t_s[m_e[0]] - t_s[vis_e[0]]) if m_e.size else None
        n_switches = switches(a["mot_tid"][:, k])
        n_optimal = switches(matched_tid[:, k])
        switches_total += n_switches
        optimal_total += n_optimal
        switches_max = max(switches_max, n_switches)
        name = truth.names[k] if truth.names.count(truth.names[k]) == 1 else f"{truth.names[k]}#{truth.ids[k]}"
        latency[name] = lat_s
        if lat_s is None:
            missed.append(name)
        per_object.append({"id": int(truth.ids[k]), "name": truth.names[k], "kind": truth.kinds[k],
                           "first_in_range_s": float(t_s[vis_e[0]]), "in_view_from_s": float(t_s[start_e]),
                           "epochs_in_range": int(vis_e.size), "latency_from_first_in_range_s": glimpse_lat_s,
                           "epochs_matched": int(m_e.size), "matched_fraction": m_e.size / vis_e.size,
                           "latency_s": lat_s, "id_switches": n_switches,
                           "id_switches_per_epoch_assignment": n_optimal,
                           "target_ids": sorted({int(x) for x in matched_tid[m_e, k]}),
                           "median_error_m": _median(err_mat[m_e, k])})
    latencies = np.array([v for v in latency.values() if v is not None])
    from_first = np.array([o["latency_from_first_in_range_s"] for o in per_object
                           if o["latency_from_first_in_range_s"] is not None])
    return {"detection_latency_s": latency,
            "detection_latency_max_s": float(np.max(latencies)) if latencies.size else math.nan,
            "detection_latency_from_first_in_range_max_s": float(np.max(from_first)) if from_first.size else math.nan,
            "detection_latency_mean_s": _mean(latencies),
            "objects_in_range": len(latency), "missed_objects": sorted(missed),
            "id_switches": switches_total, "id_switches_max_per_object": switches_max,
            "id_switches_per_epoch_assignment": optimal_total, "per_object": per_object}


def _false(reports: dict[str, np.ndarray], report_epoch: np.ndarray, a: dict, duration_s: float) -> dict:
    """False target ids (matched at fewer than half their reported epochs) and false reports, per minute."""
    kept, is_ignored = a["kept"], a["is_ignored"]
    duration_min = duration_s / 60.0
    is_matched = np.zeros(report_epoch.size, dtype=bool)
    is_matched[a["pr"]] = True
    uids, inv = np.unique(reports["target_id"][kept], return_inverse=True)
    n_reported = np.bincount(inv, weights=~is_ignored[kept], minlength=uids.size)
    n_matched_id = np.bincount(inv, weights=is_matched[kept], minlength=uids.size)
    false_ids = uids[(n_matched_id < 0.5 * n_reported) & (n_reported > 0)]
    n_ignored = int(np.count_nonzero(is_ignored[kept]))
    n_false_reports = int(kept.size - n_ignored - np.count_nonzero(is_matched[kept]))
    return {"false_target_ids": [int(x) for x in false_ids],
            "false_targets_per_min": false_ids.size / duration_min if duration_min > 0 else math.nan,
            "false_reports": n_false_reports, "ignored_reports": n_ignored,
            "false_reports_per_min": n_false_reports / duration_min if duration_min > 0 else math.nan,
            "reports": int(kept.size), "reports_outside_truth_span": int(report_epoch.size - kept.size),
            "target_ids": int(uids.size)}


def _on_land(reports: dict[str, np.ndarray], report_epoch: np.ndarray, on_land: np.ndarray | None) -> dict:
    """``targets_on_land`` (ids reported on land at least once, within the truth's span) and ``reports_on_land``."""
    if on_land is None:
        return {"targets_on_land": 0, "reports_on_land": 0, "target_ids_on_land": []}
    land = np.asarray(on_land, dtype=bool) & (report_epoch >= 0)
    ids = np.unique(reports["target_id"][land])
    return {"targets_on_land": int(ids.size), "reports_on_land": int(np.count_nonzero(land)),
            "target_ids_on_land": [int(x) for x in ids]}


def score(truth: TruthAtEpochs, visible: np.ndarray, reports: dict[str, np.ndarray], report_epoch: np.ndarray,
          c_m: float, p: float, duration_s: float, lidar_range_m: float, with_series: bool,
          dont_care: np.ndarray | None = None) -> dict:
    """The metrics of one report set against the in-range truth (tdm.evaluate docstring).

    Parameters
    ----------
    truth : TruthAtEpochs
        Truth at the E epochs, K objects.
    visible : (E, K) bool
        In range.
    reports : dict of (N,) arrays
        :func:`tdm.eval_lines.read_reports`'s columns.
    report_epoch : (N,) int64
        Each report's epoch, -1 outside the truth's span.
    c_m, p : float
        Cut-off (m) and order.
    duration_s : float
        For the rates per minute, s.
    lidar_range_m : float
        Splits the median error, m.
    with_series : bool
        Also the per-epoch ``series`` for the plots.
    dont_care : (E, K) bool, optional
        Objects hidden from the sensors though within their range (those in range at an epoch are
        never don't care); reports that the assignment gives to them are ignored (neither matched
        nor false).

    ``reports["on_land"]`` (N,) bool, when present, marks the reports on the recording's land:
    never matched or ignored (false), and counted (``targets_on_land``, ``reports_on_land``).

    Returns
    -------
    dict
        The metrics (not yet rounded).
    """
    E = visible.shape[0]
    rep_pos = np.stack([reports["east_m"], reports["north_m"]], axis=-1)  # (N, 2)
    on_land = reports.get("on_land")
    a = _assign(truth, visible, rep_pos, report_epoch, reports["target_id"], c_m, p, dont_care, on_land,
                (lidar_range_m, NEAR_GOSPA_C_M))
    per_epoch, pd = a["per_epoch"], a["pd"]
    n_visible = int(visible.sum())
    out = {name: float(np.mean(per_epoch[key])) if E else math.nan
           for name, key in (("ospa_m", "ospa"), ("gospa_m", "gospa"), ("gospa_localisation_m", "gospa_loc"),
                             ("gospa_missed_mean", "gospa_missed"), ("gospa_false_mean", "gospa_false"),
                             ("gospa_within_lidar_range_c10_m", "gospa_near"))}
    out.update(_pair_errors(truth, reports, rep_pos, a, lidar_range_m))
    out["detection_rate"] = pd.size / n_visible if n_visible else math.nan
    out.update(_per_object(truth, visible, reports, a))
    out.update(_false(reports, report_epoch, a, duration_s))
    out.update(_on_land(reports, report_epoch, on_land))
    out.update({"epochs": E, "in_range_pairs": n_visible, "matched_pairs": int(pd.size)})
    if with_series:
        t_s, pe, pk, pr = truth.t_s, a["pe"], a["pk"], a["pr"]
        out["series"] = {
            "c_m": c_m, "t_s": t_s.tolist(), "ospa_m": per_epoch["ospa"].tolist(),
            "gospa_m": per_epoch["gospa"].tolist(), "gospa_localisation_m": per_epoch["gospa_loc"].tolist(),
            "n_in_range": visible.sum(axis=1).tolist(), "n_reports": a["n_rep_e"].tolist(),
            "objects": {str(int(i)): n for i, n in zip(truth.ids, truth.names)},
            "pairs": {"t_s": t_s[pe].tolist(), "truth_id": truth.ids[pk].tolist(),
                      "target_id": reports["target_id"][pr].tolist(), "error_m": pd.tolist()},
        }
    return out
