"""The front ends' worker pool of ``tdm run``: scans in, detections out, in time order.

Scans are independent, so their front ends (:func:`tdm.frontend.lidar.lidar_detections_batch`,
:func:`tdm.frontend.radar.radar_detections`, then the chart's land mask, :mod:`tdm.land`) run in a
pool of worker processes. Each worker gets the own-ship track, the mounts and the front ends' settings
once (:func:`_init_worker`); a job is a sweep file to read (checked in the worker) or a sweep already
read (the PCAP's). Jobs go in chunks of :data:`BATCH_SCANS` (in this process too, without workers;
live mode takes chunks of one scan), and a chunk's LiDAR sweeps go through their front end together,
each with the result it has alone (:func:`_frontend_chunk`). Results come back in submission order and
pass a reorder buffer that puts them in exact end-time order (:func:`detections_in_time_order`).
"""

from __future__ import annotations

import heapq
from collections import deque
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Iterable, Iterator

import numpy as np

from tdm.detections import Detections, ReadStats
from tdm.frontend.lidar import LIDAR_FIELDS, lidar_detections_batch
from tdm.frontend.radar import radar_detections
from tdm.frontend.radar_sidelobes import drop_sidelobes
from tdm.land import drop_on_land
from tdm.recording.npz import Unreadable
from tdm.recording.sweep_files import SweepOrder
from tdm.recording.sweeps import SCHEMAS, read_sweep, unreadable_warning

__all__ = ["BATCH_SCANS", "LIDAR_FIELDS", "RADAR_FIELDS", "detections_in_time_order"]

RADAR_FIELDS = ("echo", "azimuth_deg", "heading_deg", "time", "range_m")

#: Scans per chunk, a worker task: enough to hide the inter-process overhead (about a millisecond a task)
#: and numpy's per-call overhead (the chunk's LiDAR sweeps go through their front end together).
BATCH_SCANS = 16
#: Batches submitted ahead per worker: the workers never wait for the next batch, and memory stays flat.
BATCHES_AHEAD_PER_WORKER = 3
#: Margin of the reorder buffer over the longest scan period, s: a scan that ends later than one
#: already out by less than a period and this margin is still put in its place.
REORDER_MARGIN_S = 0.5

_WORKER: dict = {}

#: One front-end result: (sensor, start and end time s, detections or None, problem or None, file or None).
FrontendResult = tuple[str, float, float, Detections | None, str | None, Path | None]


def _init_worker(track, lidar_mount, lidar_cfg, radar_mount, radar_cfg, limits=None, land=None) -> None:
    _WORKER.update(track=track, lidar=(lidar_mount, lidar_cfg), radar=(radar_mount, radar_cfg),
                   limits=limits or {}, land=land)


def _read_sweep_file(sensor: str, path: Path) -> dict | str:
    """A sweep file's arrays, checked (:func:`tdm.recording.sweeps.read_sweep`), or the reason it is unreadable."""
    window_s, expected = _WORKER["limits"].get(sensor, ((-np.inf, np.inf), None))
    try:
        return read_sweep(path, SCHEMAS[sensor], LIDAR_FIELDS if sensor == "lidar" else RADAR_FIELDS, window_s,
                          expected)
    except Unreadable as exc:  # zero bytes, cut short, not a zip: counted, skipped
        return exc.reason


def _read_job(job: tuple[str, object]) -> tuple[dict | None, Path | None, FrontendResult | None]:
    """A job's sweep (read and checked when it is a file) and file, or the result that says why it has none."""
    sensor, source = job
    path = Path(source) if isinstance(source, (str, Path)) else None
    sweep = _read_sweep_file(sensor, path) if path is not None else source
    if isinstance(sweep, str):
        return None, path, (sensor, -1.0, -1.0, None, unreadable_warning(sensor, sweep), path)
    if sweep["time"].size == 0:
        return None, path, (sensor, -1.0, -1.0, None, f"{sensor}: empty sweeps", path)
    return sweep, path, None


def _finished(sensor: str, sweep: dict, dets: Detections, path: Path | None) -> FrontendResult:
    """A scan's result: its detections off the chart's land (radar: also within half a beam of it)."""
    cfg = _WORKER[sensor][1]
    beam = (cfg.land_beam_fraction, cfg.beam_az_deg) if sensor == "radar" else (0.0, 0.0)
    dets = drop_on_land(dets, _WORKER.get("land"), *beam)
    times = sweep["time"]
    return sensor, float(np.min(times)), float(np.max(times)), dets, None, path


def _frontend_chunk(jobs: list[tuple[str, object]]) -> list[FrontendResult]:
    """Detections of consecutive scans, in the jobs' order: each (sensor, start and end time s, detections or
    None, problem or None, file or None).

    The chunk's LiDAR sweeps go through the front end together (:func:`tdm.frontend.lidar.lidar_detections_batch`,
    each with the result it has alone), the radar sweeps one by one. A sweep file that breaks the format
    raises :class:`tdm.errors.RecordingError` (also from a worker).
    """
    results: list = [None] * len(jobs)
    lidar: list = []
    track, land = _WORKER["track"], _WORKER.get("land")  # land: the chart's mask (tdm.land), or None
    for k, job in enumerate(jobs):
        sweep, path, problem = _read_job(job)
        if problem is not None:
            results[k] = problem
        elif job[0] == "lidar":
            lidar.append((k, sweep, path))
        else:
            mount, cfg = _WORKER["radar"]
            dets = drop_sidelobes(radar_detections(sweep, track, mount, cfg, land), track, mount, cfg)
            results[k] = _finished("radar", sweep, dets, path)
    if lidar:
        mount, cfg = _WORKER["lidar"]
        dets = lidar_detections_batch([sweep for _, sweep, _ in lidar], track, mount, cfg, land)
        for (k, sweep, path), d in zip(lidar, dets):
            results[k] = _finished("lidar", sweep, d, path)
    return results


def _chunks(jobs: Iterable[tuple[str, object]], size: int) -> Iterator[list[tuple[str, object]]]:
    """``jobs`` in lists of ``size`` consecutive jobs (the last one shorter)."""
    chunk: list = []
    for job in jobs:
        chunk.append(job)
        if len(chunk) == size:
            yield chunk
            chunk = []
    if chunk:
        yield chunk


def _pooled_results(jobs: Iterable[tuple[str, object]], executor: ProcessPoolExecutor | None, in_flight: int,
                    chunk_scans: int = BATCH_SCANS) -> Iterator[FrontendResult]:
    """Front-end results of ``jobs`` in submission order: chunks of ``chunk_scans`` with at most
    ``in_flight`` chunks ahead (in this process, one chunk at a time, without an executor)."""
    if executor is None:
        for chunk in _chunks(jobs, chunk_scans):
            yield from _frontend_chunk(chunk)
        return
    pending: deque = deque()
    for chunk in _chunks(jobs, chunk_scans):
        pending.append(executor.submit(_frontend_chunk, chunk))
        if len(pending) > in_flight:
            yield from pending.popleft().result()
    while pending:
        yield from pending.popleft().result()


def _reordered(results: Iterable[FrontendResult], lag_s: float,
               stats: ReadStats) -> Iterator[tuple[float, str, Detections]]:
    """(end time, sensor, Detections) of ``results`` in end-time order through a buffer ``lag_s`` long.

    Problems are counted in ``stats`` and skipped; sweep files out of order or duplicated raise
    (:class:`tdm.recording.sweep_files.SweepOrder`).
    """
    buffer: list = []
    seq = 0
    last = -np.inf
    order = SweepOrder()
    for sensor, t_start, t_end, dets, problem, path in results:
        if problem:
            stats.count(problem)
            continue
        if path is not None:  # sweep files renamed out of order or duplicated (a PCAP's are in order)
            order.check(sensor, path, t_start, t_end)
        heapq.heappush(buffer, (t_end, seq, sensor, dets))
        seq += 1
        while buffer and buffer[0][0] < t_end - lag_s:
            t, _, name, item = heapq.heappop(buffer)
            if t < last:
                raise RuntimeError(f"scans out of order: {name} at {t} s after {last} s")
            last = t
            yield t, name, item
    while buffer:
        t, _, name, item = heapq.heappop(buffer)
        yield t, name, item


def detections_in_time_order(jobs: Iterable[tuple[str, object]], longest_period_s: float, workers: int,
                             initargs: tuple, stats: ReadStats,
                             chunk_scans: int = BATCH_SCANS) -> Iterator[tuple[float, str, Detections]]:
    """(end time, sensor, Detections) of every scan of ``jobs``, in time order.

    Jobs (in expected-time order, :func:`tdm.scans.interleaved`) go in chunks of ``chunk_scans`` to
    ``workers`` processes (0: this process) with a bounded number in flight (memory stays flat, and the
    trackers start at once); results come back in submission order and pass a reorder buffer one scan
    period long, which puts them in exact end-time order. Live mode takes chunks of one scan: a chunk
    waits for its last scan.
    """
    lag_s = longest_period_s + REORDER_MARGIN_S
    if workers > 0:
        executor = ProcessPoolExecutor(max_workers=workers, initializer=_init_worker, initargs=initargs)
    else:
        executor = None
        _init_worker(*initargs)
    try:
        yield from _reordered(_pooled_results(jobs, executor, BATCHES_AHEAD_PER_WORKER * max(workers, 1), chunk_scans),
                              lag_s, stats)
    finally:
        if executor:
            executor.shutdown(cancel_futures=True)
