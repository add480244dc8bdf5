"""Pictures of a TDM run against truth: tracks on the plane, errors over time.

Drawn with matplotlib's object API (``matplotlib.figure.Figure`` on a ``FigureCanvasAgg``),
never pyplot, so no global figure state is touched and no display is needed. PNGs are
written without the "Software" metadata chunk, so the same inputs give the same bytes, and
atomically (temporary name, then rename). Default outputs go to ``RECORDING/tdm/``.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from tdm.errors import RecordingError
from tdm.eval_lines import read_reports
from tdm.eval_truth import read_truth_samples, truth_enu_and_span, truth_span

#: Figure resolution, dots per inch.
DPI = 100
#: Qualitative colour map for ids (20 distinct colours, reused cyclically).
ID_COLORMAP = "tab20"
#: A gap longer than this many epoch steps breaks an error curve.
GAP_EPOCHS = 1.5
#: Truth tracks are drawn through the samples at (or around) every this many seconds, and each object's first
#: and last, s: the picture's memory does not grow with the 10 Hz truth.
TRUTH_STEP_S = 1.0
#: Most times the truth tracks are drawn at (the step grows beyond it for very long recordings).
MAX_TRUTH_TIMES = 20_000


def _save(fig: Figure, out_png: Path) -> Path:
    """Render ``fig`` to ``out_png`` atomically, without time- or version-dependent metadata."""
    out_png = Path(out_png)
    out_png.parent.mkdir(parents=True, exist_ok=True)
    tmp = out_png.with_name(f".{out_png.name}.{os.getpid()}.tmp")
    try:
        fig.savefig(tmp, format="png", dpi=DPI, metadata={"Software": None})
        os.replace(tmp, out_png)
    finally:
        if tmp.exists():
            tmp.unlink()
    return out_png


def _figure(width_in: float, height_in: float) -> Figure:
    """A new figure on its own Agg canvas (no pyplot)."""
    fig = Figure(figsize=(width_in, height_in), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _colour(index: int):
    return matplotlib.colormaps[ID_COLORMAP](index % 20)


def recording_title(recording: Path) -> str:
    """The recording's name for titles: ``"<scenario> (seed N)"`` from its manifest or scenario.yaml.

    Never the directory's name, which differs between identical runs (``raysim run`` evaluates in a
    staging directory ``.NAME.partial-PID``); ``"recording"`` when neither file names the scenario.
    """
    from tdm.io import read_scenario

    recording = Path(recording)
    for read in (lambda: json.loads((recording / "manifest.json").read_text(encoding="utf-8")),
                 lambda: read_scenario(recording)):
        try:
            meta = read()
        except (OSError, ValueError, RecordingError):
            continue
        if isinstance(meta, dict) and meta.get("scenario", meta.get("name")):
            name = meta.get("scenario", meta.get("name"))
            return f"{name} (seed {meta['seed']})" if meta.get("seed") is not None else str(name)
    return "recording"


def _truth_for_plot(recording: Path) -> tuple:
    """(frame, truth columns) of the samples at about every :data:`TRUTH_STEP_S` s (:func:`tdm.eval_truth.read_truth_enu`)."""
    path = Path(recording) / "truth.jsonl"
    t0_s, t1_s = truth_span(path) or read_truth_samples(path, np.zeros(0))[1]
    step_s = max(TRUTH_STEP_S, (t1_s - t0_s) / MAX_TRUTH_TIMES)
    times_s = np.floor(t0_s) + step_s * np.arange(int((t1_s - np.floor(t0_s)) // step_s) + 1)
    frame, truth, _ = truth_enu_and_span(recording, times_s)
    return frame, truth


def plot_tracks(recording: Path, out_png: Path | None = None) -> Path:
    """Targets' tracks coloured by target id over the truth tracks and the own ship's path.

    Parameters
    ----------
    recording : Path
        Recording directory with ``tdm/detected_targets.jsonl``.
    out_png : Path, optional
        Output; default ``RECORDING/tdm/tracks.png``.

    Returns
    -------
    Path
        The PNG written (ENU metres about the own ship's first position, equal aspect).
    """
    recording = Path(recording)
    targets_path = recording / "tdm" / "detected_targets.jsonl"
    if not targets_path.is_file():
        raise RecordingError(str(targets_path), "(file)", "missing: run `tdm run` first")
    frame, truth = _truth_for_plot(recording)
    targets = read_reports(targets_path, frame)

    fig = _figure(8, 8)
    ax = fig.add_subplot()
    for object_id in np.unique(truth["id"]):  # loop over truth objects
        rows = np.flatnonzero(truth["id"] == object_id)
        rows = rows[np.argsort(truth["t"][rows], kind="stable")]
        e, n = truth["east_m"][rows], truth["north_m"][rows]
        if truth["kind"][rows[0]] == "ownship":
            ax.plot(e, n, color="black", lw=1.5, zorder=3, label="own ship")
            ax.plot(e[:1], n[:1], "o", color="black", ms=5, zorder=3)
            continue
        ax.plot(e, n, color="0.6", lw=4, alpha=0.6, solid_capstyle="round", zorder=1)
        ax.plot(e[-1:], n[-1:], "s", color="0.45", ms=4, zorder=1)
        ax.annotate(str(truth["name"][rows[0]]), (e[-1], n[-1]), xytext=(4, 4), textcoords="offset points",
                    fontsize=7, color="0.3")
    for i, target_id in enumerate(np.unique(targets["target_id"])):  # loop over target ids
        rows = np.flatnonzero(targets["target_id"] == target_id)
        rows = rows[np.argsort(targets["t"][rows], kind="stable")]
        e, n = targets["east_m"][rows], targets["north_m"][rows]
        ax.plot(e, n, ".-", color=_colour(i), lw=1, ms=3, zorder=2)
        ax.annotate(f"T{int(target_id)}", (e[-1], n[-1]), xytext=(-4, -9), textcoords="offset points",
                    fontsize=6, color=_colour(i))
    ax.plot([], [], color="0.6", lw=4, alpha=0.6, label="truth (end: square)")
    ax.plot([], [], ".-", color=_colour(0), lw=1, label="detected targets (colour = id)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.grid(True, lw=0.4, alpha=0.5)
    ax.legend(loc="best", fontsize=8)
    ax.set_title(f"{recording_title(recording)}: detected targets over truth (ENU about the own ship's start)",
                 fontsize=9)
    return _save(fig, out_png if out_png is not None else recording / "tdm" / "tracks.png")


def _with_gaps(t_s: np.ndarray, y: np.ndarray, step_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Insert NaN between samples further apart than GAP_EPOCHS steps, so a line breaks there."""
    if t_s.size < 2:
        return t_s, y
    breaks = np.flatnonzero(np.diff(t_s) > GAP_EPOCHS * step_s) + 1
    return np.insert(t_s, breaks, np.nan), np.insert(y, breaks, np.nan)


def plot_errors(recording: Path, metrics_or_series: dict | None = None, out_png: Path | None = None) -> Path:
    """Position error over time per truth object, and OSPA and GOSPA over time.

    Parameters
    ----------
    recording : Path
        Recording directory.
    metrics_or_series : dict, optional
        What :func:`tdm.evaluate.evaluate` returns, or its ``"series"`` entry; default: read
        ``RECORDING/tdm/metrics.json``.
    out_png : Path, optional
        Output; default ``RECORDING/tdm/errors.png``.

    Returns
    -------
    Path
        The PNG written.
    """
    recording = Path(recording)
    if metrics_or_series is None:
        path = recording / "tdm" / "metrics.json"
        try:
            metrics_or_series = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise RecordingError(str(path), "(file)", "missing: run `tdm evaluate` first") from None
        except json.JSONDecodeError as exc:
            raise RecordingError(str(path), f"line {exc.lineno}", f"not valid JSON: {exc.msg}") from None
    series = metrics_or_series.get("series", metrics_or_series)
    c_m = series.get("c_m", (metrics_or_series.get("parameters") or {}).get("c_m"))
    t_s = np.asarray(series["t_s"], dtype=float)
    step_s = float(np.median(np.diff(t_s))) if t_s.size > 1 else 1.0
    pairs = series["pairs"]
    pt, pid = np.asarray(pairs["t_s"], dtype=float), np.asarray(pairs["truth_id"], dtype=np.int64)
    perr = np.asarray(pairs["error_m"], dtype=float)
    names = series.get("objects", {})

    fig = _figure(9, 7)
    ax_err, ax_set = fig.subplots(2, 1, sharex=True)
    for i, object_id in enumerate(np.unique(pid)):  # loop over truth objects
        m = pid == object_id
        order = np.argsort(pt[m], kind="stable")
        x, y = _with_gaps(pt[m][order], perr[m][order], step_s)
        ax_err.plot(x, y, ".-", color=_colour(i), lw=1, ms=3, label=names.get(str(int(object_id)), str(object_id)))
    ax_err.set_ylabel("position error [m]")
    ax_err.grid(True, lw=0.4, alpha=0.5)
    if pid.size:
        ax_err.legend(loc="upper right", fontsize=6, ncol=2)
    ax_err.set_title(f"{recording_title(recording)}: matched position error per truth object", fontsize=9)

    ax_set.plot(t_s, np.asarray(series["ospa_m"], dtype=float), "-", color="tab:blue", lw=1.2, label="OSPA")
    ax_set.plot(t_s, np.asarray(series["gospa_m"], dtype=float), "-", color="tab:red", lw=1.2, label="GOSPA")
    if c_m is not None:
        ax_set.axhline(float(c_m), color="0.5", ls="--", lw=0.8, label=f"cut-off c = {float(c_m):g} m")
    ax_set.set_xlabel("time [s]")
    ax_set.set_ylabel("distance [m]")
    ax_set.grid(True, lw=0.4, alpha=0.5)
    ax_set.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return _save(fig, out_png if out_png is not None else recording / "tdm" / "errors.png")
