"""Monte-Carlo batches: one scenario over many seeds and parameter variants, on Dask.

``raysim batch SCENARIO --seeds N --vary key=v1,v2 -o DIR`` plans one run per (variant, seed):
the scenario with the variant's values set (:func:`raysim.scenario.load_scenario` ``changes``,
validated like the file) and an explicit seed, ``base + i`` for i = 0..N-1 (``base``: ``--seed``
or the scenario's own). Each run renders, runs the TDM and evaluates it, like ``raysim run``:

- ``DIR/runs/<run>/`` the recording (written whole or not at all), with ``tdm/`` inside;
- ``DIR/results/<run>.json`` the run's row (status, parameters, metrics or error, wall time)
  and, for a failed run, ``DIR/results/<run>.log`` with the traceback;
- ``DIR/summary.csv`` one row per run of the batch, ``DIR/summary.png`` the metrics' spread.

Runs are tasks of a Dask distributed cluster: a :class:`distributed.LocalCluster` on this machine
by default (one single-threaded worker process per core, no dashboard), or the scheduler at
``--scheduler``. Tasks are submitted with ``pure=False`` and carry their seed, so Dask never
takes two runs for one. A run that raises is recorded as failed and the batch goes on; a run
whose worker dies is recorded the same way. Re-running a batch skips the runs whose result is
``ok``, whose recording is there and whose scenario (the resolved YAML, hashed) is unchanged;
failed runs are tried again, and what an interrupted batch left half-written of them is removed.
"""

from __future__ import annotations

import csv
import dataclasses
import hashlib
import io
import itertools
import json
import logging
import os
import re
import shutil
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path

import yaml

from raysim.errors import InputError
from raysim.recording.staging import atomic_path, is_write_fault, write_fault
from raysim.scenario import Scenario, load_scenario, scenario_to_yaml, with_overrides

__all__ = ["METRIC_COLUMNS", "RunSpec", "execute_run", "parse_vary", "plan_batch", "run_batch", "write_summary"]

#: metrics.json values copied into the summary, in this order (``radar_*`` from ``per_sensor.radar``).
METRIC_COLUMNS = ("ospa_m", "gospa_m", "position_rmse_m", "median_position_error_within_lidar_range_m",
                  "median_position_error_beyond_lidar_range_m", "radar_median_position_error_m", "detection_rate",
                  "detection_latency_max_s", "false_targets_per_min", "id_switches", "id_switches_max_per_object",
                  "nees", "classification_accuracy")
#: Metrics drawn in summary.png: column, label.
PLOTTED = (("gospa_m", "GOSPA [m]"), ("median_position_error_within_lidar_range_m", "median error, LiDAR range [m]"),
           ("radar_median_position_error_m", "median error, radar alone [m]"), ("detection_rate", "detection rate"),
           ("detection_latency_max_s", "max latency [s]"), ("false_targets_per_min", "false targets / min"))
#: Characters kept in run names (the rest become "_").
_NAME_UNSAFE = re.compile(r"[^A-Za-z0-9._=+-]")


@dataclasses.dataclass(frozen=True)
class RunSpec:
    """One run of a batch.

    Attributes
    ----------
    name : str
        Directory name of the run (``key=value__...__seed=N``).
    seed : int
    params : tuple of (str, object)
        The varied keys and this run's values, in ``--vary`` order.
    scenario : Scenario
        Resolved, with the values, the seed and the duration applied.
    fingerprint : str
        sha256 of the resolved scenario's YAML (a changed scenario file is a new run).
    """

    name: str
    seed: int
    params: tuple[tuple[str, object], ...]
    scenario: Scenario
    fingerprint: str


def parse_vary(text: str) -> tuple[str, list]:
    """``key=v1,v2,...`` into the key path and its values (each value read as YAML: ``4`` is a number).

    Raises
    ------
    InputError
        Naming ``--vary`` and the text.
    """
    key, sep, values = text.partition("=")
    key = key.strip()
    if not sep or not key or not values.strip():
        raise InputError("command line", "--vary", f"expected key=value1,value2,..., got {text!r}")
    out = []
    for token in values.split(","):
        token = token.strip()
        if not token:
            raise InputError("command line", "--vary", f"empty value in {text!r}")
        try:
            out.append(yaml.safe_load(token))
        except yaml.YAMLError:
            raise InputError("command line", "--vary", f"value {token!r} of {key} is not a YAML scalar") from None
    if len({json.dumps(v, sort_keys=True, default=str) for v in out}) != len(out):
        raise InputError("command line", "--vary", f"{key} is given the same value twice")
    return key, out


def _run_name(params: tuple[tuple[str, object], ...], seed: int) -> str:
    parts = [f"{key}={_value_text(value)}" for key, value in params] + [f"seed={seed}"]
    return _NAME_UNSAFE.sub("_", "__".join(parts))


def _value_text(value: object) -> str:
    return value if isinstance(value, str) else json.dumps(value, separators=(",", ":"), default=str)


def plan_batch(scenario_path: Path, seeds: int = 1, vary: list[tuple[str, list]] = (), duration_s: float | None = None,
               base_seed: int | None = None) -> list[RunSpec]:
    """Every run of a batch, validated before anything runs.

    Parameters
    ----------
    scenario_path : Path
        The scenario file.
    seeds : int
        Runs per variant, seeds ``base + 0 .. base + seeds - 1``.
    vary : list of (key path, values)
        The variants are all combinations of the values (cartesian product, in order).
    duration_s : float, optional
        Override of the scenario's duration.
    base_seed : int, optional
        First seed (default: the scenario's seed).

    Raises
    ------
    InputError
        A variant that is not a valid scenario names the file and the key; names that collide.
    """
    if seeds < 1:
        raise InputError("command line", "--seeds", f"must be >= 1, got {seeds}")
    keys = [k for k, _ in vary]
    if len(set(keys)) != len(keys):
        raise InputError("command line", "--vary", "a key is varied twice")
    if "seed" in keys:
        raise InputError("command line", "--vary", "seeds are set with --seeds and --seed, not varied")
    if "duration_s" in keys and duration_s is not None:
        raise InputError("command line", "--vary", "duration_s is varied and set by --duration at once")
    base = load_scenario(scenario_path)
    first_seed = base.seed if base_seed is None else int(base_seed)
    runs, names = [], set()
    for values in itertools.product(*[v for _, v in vary]):
        params = tuple(zip(keys, values))
        try:
            variant = load_scenario(scenario_path, changes=dict(params)) if params else base
        except InputError as exc:
            shown = ", ".join(f"{k}={_value_text(v)}" for k, v in params)
            raise InputError(exc.file, exc.where, f"{exc.what} (in the variant {shown})") from None
        for i in range(seeds):
            seed = first_seed + i
            scenario = with_overrides(variant, duration_s, seed)
            name = _run_name(params, seed)
            if name in names:
                raise InputError("command line", "--vary", f"two runs would share the directory {name}")
            names.add(name)
            fingerprint = hashlib.sha256(scenario_to_yaml(scenario).encode()).hexdigest()
            runs.append(RunSpec(name, seed, params, scenario, fingerprint))
    return runs


# ---------------------------------------------------------------------------------------------- one run


def _row(spec: RunSpec) -> dict:
    return {"run": spec.name, "status": "", "seed": spec.seed, **{k: v for k, v in spec.params},
            "duration_s": spec.scenario.duration_s, "wall_s": None, "fingerprint": spec.fingerprint,
            **{c: None for c in METRIC_COLUMNS}, "error": ""}


def _metrics_row(metrics: dict) -> dict:
    out = {c: metrics.get(c) for c in METRIC_COLUMNS}
    out["radar_median_position_error_m"] = ((metrics.get("per_sensor") or {}).get("radar") or {}).get(
        "median_position_error_m")
    return out


def execute_run(spec: RunSpec, batch_dir: str) -> dict:
    """Render, run the TDM and evaluate one run (a Dask task); its row, also written to ``results/``.

    Never raises for a failure of the run itself: the row says ``failed`` with the error, and the
    traceback goes to ``results/<run>.log``. A write fault (full disk, ...: an ``OSError`` of
    :data:`raysim.recording.staging.WRITE_ERRNOS`) is returned at once as the row's ``write_errno``,
    nothing more written: it stops the batch (:func:`run_batch`). The TDM runs in the task's own
    process (no front-end workers: the batch's parallelism is across runs).
    """
    from raysim.runner import render_detect_evaluate

    batch = Path(batch_dir)
    results = batch / "results"
    results.mkdir(parents=True, exist_ok=True)
    row = _row(spec)
    started = time.perf_counter()
    log = results / f"{spec.name}.log"
    try:
        _, metrics = render_detect_evaluate(spec.scenario, batch / "runs" / spec.name, progress=False, tdm_workers=0)
        row.update(_metrics_row(metrics), status="ok")
        log.unlink(missing_ok=True)
    except Exception as exc:  # a failed run is recorded and the batch goes on
        row.update(status="failed", error=_one_line(exc))
        if is_write_fault(exc):  # but not on a full disk: every run would fail the same way
            return {**row, "write_errno": exc.errno}
        with atomic_path(log) as tmp:
            tmp.write_text(traceback.format_exc(), encoding="utf-8")
    row["wall_s"] = round(time.perf_counter() - started, 3)
    with atomic_path(results / f"{spec.name}.json") as tmp:
        tmp.write_text(json.dumps(row, indent=1, default=str) + "\n", encoding="utf-8")
    return row


def _one_line(exc: BaseException) -> str:
    return " ".join(f"{type(exc).__name__}: {exc}".split())


def finished_row(spec: RunSpec, batch_dir: Path) -> dict | None:
    """The stored row of a run that need not run again (ok, recording there, same scenario), else None."""
    path = Path(batch_dir) / "results" / f"{spec.name}.json"
    try:
        row = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if (row.get("status") == "ok" and row.get("fingerprint") == spec.fingerprint
            and (Path(batch_dir) / "runs" / spec.name / "manifest.json").is_file()):
        return row
    return None


# ---------------------------------------------------------------------------------------------- the batch


#: How long to try to reach a Dask scheduler given by address, s.
SCHEDULER_TIMEOUT_S = 10.0


def _client(scheduler: str | None, workers: int | None):
    """A Dask client: on the scheduler at ``scheduler``, or on a new LocalCluster (no dashboard)."""
    from distributed import Client, LocalCluster

    for name in ("distributed", "tornado"):
        logging.getLogger(name).setLevel(logging.ERROR)
    if scheduler:
        try:
            return Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT_S:g}s"), None
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError("command line", "--scheduler", f"cannot connect to {scheduler}: {_one_line(exc)}") from None
    n = max(1, int(workers) if workers else (os.cpu_count() or 1))
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


def run_batch(runs: list[RunSpec], batch_dir: Path, scheduler: str | None = None, workers: int | None = None,
              progress: Callable[[str], None] | None = None) -> list[dict]:
    """Run every run not finished before on Dask; write the summary; the rows in plan order.

    Parameters
    ----------
    runs : list of RunSpec
        From :func:`plan_batch`.
    batch_dir : Path
        The batch's directory (created).
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:8786``); default: a LocalCluster here.
    workers : int, optional
        LocalCluster worker processes (default: one per core).
    progress : callable, optional
        Called with one line per event (start, each run done).
    """
    say = progress or (lambda line: None)
    batch_dir = Path(batch_dir)
    rows: dict[str, dict] = {}
    todo = []
    for spec in runs:
        done = finished_row(spec, batch_dir)
        if done is not None:
            rows[spec.name] = done
        else:
            todo.append(spec)
    client, cluster = _client(scheduler, workers) if todo else (None, None)
    try:
        batch_dir.mkdir(parents=True, exist_ok=True)
        if client is None:
            where = "nothing to run"
        elif scheduler:
            where = f"{len(todo)} to run on the scheduler at {scheduler}"
        else:
            where = f"{len(todo)} to run on a local cluster of {len(client.scheduler_info()['workers'])} workers"
        say(f"batch: {len(runs)} runs, {len(runs) - len(todo)} finished before (skipped), {where}")
        if todo:
            from distributed import as_completed

            for spec in todo:  # what an interrupted earlier batch left half-written
                for stale in (batch_dir / "runs").glob(f".{spec.name}.partial-*"):
                    shutil.rmtree(stale, ignore_errors=True)

            futures = {client.submit(execute_run, spec, str(batch_dir.resolve()), pure=False,
                                     key=f"raysim-run-{spec.name}-{os.urandom(4).hex()}"): spec for spec in todo}
            for n, future in enumerate(as_completed(futures), start=1):
                spec = futures[future]
                try:
                    row = future.result()
                except Exception as exc:  # the task itself was lost (worker died, cannot be sent, ...)
                    if is_write_fault(exc):  # a full disk stops the batch (raysim's one-line error)
                        raise write_fault(exc, batch_dir) from None
                    row = {**_row(spec), "status": "failed", "error": _one_line(exc)}
                if row.get("write_errno"):
                    raise write_fault(OSError(row["write_errno"], os.strerror(row["write_errno"])), batch_dir)
                rows[spec.name] = row
                write_summary([rows[s.name] for s in runs if s.name in rows], batch_dir, runs)
                detail = f"GOSPA {row['gospa_m']:.1f} m" if row["status"] == "ok" and row.get("gospa_m") is not None \
                    else row.get("error", "")
                say(f"[{n}/{len(todo)}] {spec.name}: {row['status']} in {row.get('wall_s') or 0:.0f} s ({detail})")
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    ordered = [rows[s.name] for s in runs]
    write_summary(ordered, batch_dir, runs, with_plot=True)
    return ordered


def write_summary(rows: list[dict], batch_dir: Path, runs: list[RunSpec], with_plot: bool = False) -> None:
    """``summary.csv`` (one row per run: run, status, seed, the varied keys, duration, wall time, metrics,
    error) and, with ``with_plot``, ``summary.png``."""
    keys = list(dict.fromkeys(k for spec in runs for k, _ in spec.params))
    columns = list(dict.fromkeys(["run", "status", "seed", *keys, "duration_s", "wall_s", *METRIC_COLUMNS, "error"]))
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({c: _cell(row.get(c)) for c in columns})
    with atomic_path(Path(batch_dir) / "summary.csv") as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
    if with_plot:
        with atomic_path(Path(batch_dir) / "summary.png") as tmp:
            plot_summary(rows, keys, tmp)


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (dict, list)):
        return json.dumps(value, separators=(",", ":"))
    return str(value)


def plot_summary(rows: list[dict], keys: list[str], path: Path) -> None:
    """The spread of the main metrics over the runs: one panel per metric, one column of points per
    variant (its seeds), a bar at their median."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    def label(row: dict) -> str:
        return "\n".join(f"{k.rsplit('.', 1)[-1]}={_value_text(row.get(k))}" for k in keys) or "all runs"

    variants = list(dict.fromkeys(label(r) for r in rows))
    ok = [r for r in rows if r.get("status") == "ok"]
    fig = Figure(figsize=(12, 7), dpi=100)
    FigureCanvasAgg(fig)
    failed = len(rows) - len(ok)
    fig.suptitle(f"{len(rows)} runs, {failed} failed" if failed else f"{len(rows)} runs")
    for i, (column, title) in enumerate(PLOTTED):
        ax = fig.add_subplot(2, 3, i + 1)
        for x, variant in enumerate(variants):
            values = np.array([r[column] for r in ok if label(r) == variant and r.get(column) is not None], dtype=float)
            values = values[np.isfinite(values)]
            if values.size:
                ax.plot(np.full(values.size, x), values, "o", color="tab:blue", alpha=0.6, markersize=5)
                ax.plot([x - 0.3, x + 0.3], [np.median(values)] * 2, "-", color="tab:red", linewidth=2)
        ax.set_title(title, fontsize=10)
        ax.set_xticks(range(len(variants)))
        ax.set_xticklabels(variants, fontsize=8)
        ax.set_xlim(-0.6, len(variants) - 0.4)
        ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, format="png")


def progress_printer(enabled: bool) -> Callable[[str], None] | None:
    """Progress lines on stderr, flushed (``--no-progress``: none)."""
    if not enabled:
        return None

    def say(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    return say
