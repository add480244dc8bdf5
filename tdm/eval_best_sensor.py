"""Does the fusion beat its best sensor? Per object, on position, course and speed, by RMSE and by median.

For every truth object that two or more sensors' own tracks report (``sensor_tracks.jsonl``, each matched
to truth by the same assignment as the fused targets, :mod:`tdm.eval_scoring`), the fused targets' errors
are set against each sensor's **on the epochs both report the object** (a sensor that reports an object
only where it is easy is not credited for the epochs it is silent). For each of six figures (position
error, absolute COG error, absolute SOG error; each RMSE and median) the *best sensor* is the one with the
lowest value on its common epochs; the fusion *beats* it when its value on the same epochs is no higher.

Where the fusion does not beat the best sensor, a computed reason is given (no judgement added): for the
position, whether the fused targets carry a larger mean error (bias) than the best sensor's, and which other
sensor's bias points the same way (the fusion pulled by a worse sensor), or else a larger scatter about the
mean; for COG and SOG the same with signed errors.

COG errors count only where the object moves (truth SOG over :data:`~tdm.eval_scoring.MOVING_SOG_MPS`), as
the fused COG RMSE does.
"""

from __future__ import annotations

import numpy as np

#: Epochs an object must be reported by both the fused targets and a sensor for the two to be compared.
MIN_COMMON_EPOCHS = 10
#: The six figures compared: (name, quantity, statistic).
FIGURES = (("position_rmse_m", "position", "rmse"), ("position_median_m", "position", "median"),
           ("cog_rmse_deg", "cog", "rmse"), ("cog_median_deg", "cog", "median"),
           ("sog_rmse_mps", "sog", "rmse"), ("sog_median_mps", "sog", "median"))
#: Relative margin within which a fused figure counts as equal to the sensor's (float noise only).
TIE_REL = 1e-9
_UNIT = {"position": "m", "cog": "deg", "sog": "m/s"}


def pair_errors(pe: np.ndarray, pk: np.ndarray, err_m: np.ndarray, cog_err_deg: np.ndarray,
                sog_err_mps: np.ndarray) -> dict[str, np.ndarray]:
    """The matched pairs' errors in the form :func:`fusion_against_sensors` reads.

    Parameters
    ----------
    pe, pk : (P,) int
        Epoch and object index of each matched (object, report) pair.
    err_m : (P, 2) float
        Report minus truth, east and north, m.
    cog_err_deg : (P,) float
        Report COG minus truth COG wrapped to [-180, 180), deg; NaN where the object does not move or either is
        missing.
    sog_err_mps : (P,) float
        Report SOG minus truth SOG, m/s; NaN where either is missing.
    """
    return {"epoch": np.asarray(pe, np.int64), "object": np.asarray(pk, np.int64),
            "err_m": np.asarray(err_m, float).reshape(-1, 2), "cog_err_deg": np.asarray(cog_err_deg, float),
            "sog_err_mps": np.asarray(sog_err_mps, float)}


def _on_object(pairs: dict[str, np.ndarray], k: int, epochs: int) -> dict[str, np.ndarray]:
    """One object's errors as (E, ...) arrays over the epochs, NaN where not matched."""
    sel = np.flatnonzero(pairs["object"] == k)
    e = pairs["epoch"][sel]
    out = {"err_m": np.full((epochs, 2), np.nan), "cog": np.full(epochs, np.nan), "sog": np.full(epochs, np.nan)}
    out["err_m"][e] = pairs["err_m"][sel]
    out["cog"][e] = pairs["cog_err_deg"][sel]
    out["sog"][e] = pairs["sog_err_mps"][sel]
    return out


def _signed(errors: dict[str, np.ndarray], quantity: str, mask: np.ndarray) -> np.ndarray:
    """(M, 2) position errors or (M,) signed COG/SOG errors at the epochs ``mask``."""
    return errors["err_m"][mask] if quantity == "position" else errors[quantity][mask]


def _common(fused: dict, sensor: dict, quantity: str) -> np.ndarray:
    """(E,) bool: epochs where both have a finite error of ``quantity``."""
    key = "err_m" if quantity == "position" else quantity
    a, b = fused[key], sensor[key]
    if a.ndim == 2:
        return np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
    return np.isfinite(a) & np.isfinite(b)


def _sizes(signed: np.ndarray) -> np.ndarray:
    """(M,) error sizes of (M, 2) position errors (their length) or (M,) signed errors (absolute)."""
    return np.linalg.norm(signed, axis=1) if signed.ndim == 2 else np.abs(signed)


def _rms_size(signed: np.ndarray) -> float:
    return float(np.sqrt(np.mean(_sizes(signed) ** 2)))


def _statistic(signed: np.ndarray, statistic: str) -> float:
    return _rms_size(signed) if statistic == "rmse" else float(np.median(_sizes(signed)))


def _why_not(quantity: str, fused_e: np.ndarray, best_e: np.ndarray, best: str,
             others: dict[str, np.ndarray]) -> str:
    """A computed reason the fusion loses to ``best`` on ``quantity`` (module docstring).

    ``fused_e``, ``best_e``: signed errors on their common epochs, (M, 2) or (M,); ``others``: other
    sensors' mean signed errors (their common epochs with the fusion), (2,) or ().
    """
    unit = _UNIT[quantity]
    bias_f, bias_b = fused_e.mean(axis=0), best_e.mean(axis=0)
    size_f, size_b = float(np.linalg.norm(bias_f)), float(np.linalg.norm(bias_b))
    spread_f, spread_b = _rms_size(fused_e - bias_f), _rms_size(best_e - bias_b)
    if size_f > size_b and size_f ** 2 - size_b ** 2 >= spread_f ** 2 - spread_b ** 2:
        text = f"{quantity}: fused bias {size_f:.3g} {unit} against {best}'s {size_b:.3g} {unit}"
        pull = {s: float(np.dot(np.atleast_1d(b), np.atleast_1d(bias_f)) / size_f) for s, b in others.items()
                if size_f > 0}
        toward = max(pull, key=pull.get) if pull else None
        if toward is not None and pull[toward] > size_b:
            text += f", toward {toward}'s bias ({float(np.linalg.norm(others[toward])):.3g} {unit})"
        return text
    return f"{quantity}: fused scatter {spread_f:.3g} {unit} against {best}'s {spread_b:.3g} {unit}"


def _compare_object(fused: dict, sensors: dict[str, dict]) -> dict:
    """The six figures of one object for the fusion and its sensors (common epochs), the verdicts, reasons."""
    figures, beats, why = {}, {}, []
    for name, quantity, statistic in FIGURES:
        values = {}
        for sensor, errors in sensors.items():
            mask = _common(fused, errors, quantity)
            if np.count_nonzero(mask) >= MIN_COMMON_EPOCHS:
                values[sensor] = (_statistic(_signed(errors, quantity, mask), statistic),
                                  _statistic(_signed(fused, quantity, mask), statistic), mask)
        if len(values) < 1:
            continue
        best = min(values, key=lambda s: values[s][0])
        sensor_value, fused_value, mask = values[best]
        figures[name] = {"best_sensor": best, "sensor": sensor_value, "fused": fused_value,
                         "common_epochs": int(np.count_nonzero(mask))}
        beats[name] = bool(fused_value <= sensor_value * (1.0 + TIE_REL))
        if not beats[name] and not any(w.startswith(f"{quantity}:") for w in why):  # one reason per quantity
            others = {s: _signed(sensors[s], quantity, values[s][2]).mean(axis=0) for s in values if s != best}
            why.append(_why_not(quantity, _signed(fused, quantity, mask), _signed(sensors[best], quantity, mask),
                                best, others))
    return {"figures": figures, "beats": beats, "why_not": why}


def fusion_against_sensors(names: list[str], ids: np.ndarray, epochs: int, fused_pairs: dict[str, np.ndarray],
                           sensor_pairs: dict[str, dict[str, np.ndarray]]) -> dict:
    """Per object: the fused targets against the best of their sensors (module docstring).

    Parameters
    ----------
    names : list of str
        The K truth objects' names.
    ids : (K,) int
        Their ids.
    epochs : int
        E, the evaluation's epochs.
    fused_pairs : dict
        :func:`pair_errors` of the fused targets.
    sensor_pairs : dict
        Sensor name -> :func:`pair_errors` of that sensor's own tracks.

    Returns
    -------
    dict
        ``objects``: one entry per object that two or more sensors report on at least
        :data:`MIN_COMMON_EPOCHS` epochs shared with the fusion (``id``, ``name``, ``sensors``, ``figures``:
        figure -> best sensor, its value, the fused value and the common epochs; ``beats``: figure -> bool;
        ``beats_best_on_all``; ``why_not``); ``summary``: objects compared, objects where the fusion beats its
        best sensor on every figure, and per figure how many objects it beats it on (of how many compared).
    """
    objects = []
    for k in np.unique(fused_pairs["object"]):  # loop over objects the fusion reports
        fused = _on_object(fused_pairs, int(k), epochs)
        sensors = {s: _on_object(p, int(k), epochs) for s, p in sorted(sensor_pairs.items())}
        sensors = {s: e for s, e in sensors.items()
                   if np.count_nonzero(_common(fused, e, "position")) >= MIN_COMMON_EPOCHS}
        if len(sensors) < 2:
            continue
        entry = _compare_object(fused, sensors)
        objects.append({"id": int(ids[k]), "name": names[k], "sensors": sorted(sensors), **entry,
                        "beats_best_on_all": bool(entry["beats"]) and all(entry["beats"].values())})
    per_figure = {}
    for name, _, _ in FIGURES:
        compared = [o["beats"][name] for o in objects if name in o["beats"]]
        per_figure[name] = {"beats": int(sum(compared)), "compared": len(compared)}
    summary = {"objects_compared": len(objects),
               "objects_fusion_beats_best_on_all": int(sum(o["beats_best_on_all"] for o in objects)),
               "per_figure": per_figure}
    return {"objects": objects, "summary": summary, "min_common_epochs": MIN_COMMON_EPOCHS}
