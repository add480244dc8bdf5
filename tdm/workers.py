"""The front ends' worker pool of ``tdm run``: scans in, detections out, in time order.

Scans are independent, so their front ends (:func:`tdm.frontend.lidar.lidar_detections`,
:func:`tdm.frontend.radar.radar_detections`, then the chart's land mask, :mod:`tdm.land`) run in a
pool of worker processes. Each worker gets
the own-ship track, the mounts and the front ends' settings once (:func:`_init_worker`); a job is a
sweep file to read (checked in the worker) or a sweep already read (the PCAP's). Results come back
in submission order and pass a reorder buffer that puts them in exact end-time order
(:func:`detections_in_time_order`).
"""

from __future__ import annotations

import heapq
from collections import deque
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Iterable, Iterator

import numpy as np

from tdm.detections import Detections, ReadStats
from tdm.frontend.lidar import lidar_detections
from tdm.frontend.radar import radar_detections
from tdm.frontend.radar_sidelobes import drop_sidelobes
from tdm.land import drop_on_land
from tdm.recording.npz import Unreadable
from tdm.recording.sweep_files import SweepOrder
from tdm.recording.sweeps import SCHEMAS, read_sweep, unreadable_warning

__all__ = ["BATCH_SCANS", "LIDAR_FIELDS", "RADAR_FIELDS", "detections_in_time_order"]

LIDAR_FIELDS = ("x", "y", "z", "ring", "time")  # what the LiDAR front end reads
RADAR_FIELDS = ("echo", "azimuth_deg", "heading_deg", "time", "range_m")

#: Scans per worker task: enough to hide the inter-process overhead (about a millisecond a task).
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


def _frontend(job: tuple[str, object]) -> FrontendResult:
    """Detections of one scan: (sensor, start and end time s, detections or None, problem or None, file or None).

    A sweep file that breaks the format raises :class:`tdm.errors.RecordingError` (also from a worker).
    """
    sensor, source = job
    path = Path(source) if isinstance(source, (str, Path)) else None
    if path is not None:
        sweep = _read_sweep_file(sensor, path)
        if isinstance(sweep, str):
            return sensor, -1.0, -1.0, None, unreadable_warning(sensor, sweep), path
    else:
        sweep = source
    times = sweep["time"]
    if times.size == 0:
        return sensor, -1.0, -1.0, None, f"{sensor}: empty sweeps", path
    mount, cfg = _WORKER[sensor]
    land = _WORKER.get("land")  # the chart's land mask (tdm.land), or None
    if sensor == "lidar":
        dets = lidar_detections(sweep, _WORKER["track"], mount, cfg, land)
    else:
        dets = drop_sidelobes(radar_detections(sweep, _WORKER["track"], mount, cfg), _WORKER["track"], mount, cfg)
    beam = (cfg.land_beam_fraction, cfg.beam_az_deg) if sensor == "radar" else (0.0, 0.0)
    dets = drop_on_land(dets, land, *beam)  # radar: also within half a beam of the land
    return sensor, float(np.min(times)), float(np.max(times)), dets, None, path


def _frontend_batch(batch: list) -> list:
    return [_frontend(job) for job in batch]


def _pooled_results(jobs: Iterable[tuple[str, object]], executor: ProcessPoolExecutor | None,
                    in_flight: int) -> Iterator[FrontendResult]:
    """Front-end results of ``jobs`` in submission order: batches of :data:`BATCH_SCANS` with at most
    ``in_flight`` batches ahead (in this process without an executor)."""
    if executor is None:
        yield from map(_frontend, jobs)
        return
    pending: deque = deque()
    batch: list = []
    for job in jobs:
        batch.append(job)
        if len(batch) == BATCH_SCANS:
            pending.append(executor.submit(_frontend_batch, batch))
            batch = []
        if len(pending) > in_flight:
            yield from pending.popleft().result()
    if batch:
        pending.append(executor.submit(_frontend_batch, batch))
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
                             initargs: tuple, stats: ReadStats) -> Iterator[tuple[float, str, Detections]]:
    """(end time, sensor, Detections) of every scan of ``jobs``, in time order.

    Jobs (in expected-time order, :func:`tdm.scans.interleaved`) go to ``workers`` processes (0: this
    process) with a bounded number in flight (memory stays flat, and the trackers start at once);
    results come back in submission order and pass a reorder buffer one scan period long, which puts
    them in exact end-time order.
    """
    lag_s = longest_period_s + REORDER_MARGIN_S
    if workers > 0:
        executor = ProcessPoolExecutor(max_workers=workers, initializer=_init_worker, initargs=initargs)
    else:
        executor = None
        _init_worker(*initargs)
    try:
        yield from _reordered(_pooled_results(jobs, executor, BATCHES_AHEAD_PER_WORKER * max(workers, 1)), lag_s,
                              stats)
    finally:
        if executor:
            executor.shutdown(cancel_futures=True)
