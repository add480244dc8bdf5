"""Send the live streams on the wall clock: producers render ahead, one loop sends each payload at its time.

Each stream's batches (:mod:`raysim.live.streams`) are rendered by a :class:`Producer` thread into a short
queue; :func:`send_streams` takes the earliest due payload of any stream, waits for its wall-clock
time (scenario time / speed after the start), sends it by UDP, and measures how late it left. A
stream whose next batch is not rendered yet does not hold the others back: its payloads go as soon
as they exist and their lateness says so. Nothing is dropped.
"""

from __future__ import annotations

import queue
import socket
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Callable, Iterator

import numpy as np

from raysim.live.streams import Batch

__all__ = ["Producer", "LiveStream", "Lateness", "send_streams", "LATE_S"]

#: A payload that leaves more than this after its time counts as late, s.
LATE_S = 0.010
#: Longest sleep of the send loop, s (newly rendered batches and Ctrl-C are seen this often).
POLL_S = 0.005
#: How long after the end of the session a stream still rendering is waited for, s of scenario time.
END_GRACE_S = 5.0
#: Batches a producer may render ahead of the sender.
QUEUE_DEPTH = 2
#: Seconds between two "behind schedule" lines of one stream.
REPORT_EVERY_S = 1.0
_DONE = object()


class Producer(threading.Thread):
    """Runs one stream's batch generator into a bounded queue, ahead of the clock.

    Parameters
    ----------
    name : str
        Stream name (for errors and reports).
    batches : iterator of Batch
        The stream, in time order.
    stop : threading.Event
        Set to end the stream early.
    ready_before : callable, optional
        Called with a batch's first time before the next batch is rendered; it may block to keep the
        producer from running too far ahead (the fed own ship's extrapolation limit).
    """

    def __init__(self, name: str, batches: Iterator[Batch], stop: threading.Event,
                 ready_before: Callable[[float], None] | None = None):
        super().__init__(name=f"live-{name}", daemon=True)
        self.stream_name = name
        self.batches = batches
        self.stop = stop
        self.ready_before = ready_before
        self.queue: queue.Queue = queue.Queue(maxsize=QUEUE_DEPTH)
        self.error: BaseException | None = None

    def run(self) -> None:
        try:
            for batch in self.batches:
                if len(batch.payloads) and not self._put(batch):
                    return
                if self.stop.is_set():
                    return
                if self.ready_before is not None:
                    self.ready_before(batch.end_s)
        except BaseException as exc:  # surfaced by the sender, which stops the session
            self.error = exc
        finally:
            self._put(_DONE)

    def _put(self, item) -> bool:
        while not self.stop.is_set():
            try:
                self.queue.put(item, timeout=0.1)
                return True
            except queue.Full:
                continue
        return False


@dataclass
class Lateness:
    """Per-stream send lateness, s (wall time of sending minus the payload's scheduled wall time)."""

    late_s: dict[str, list[np.ndarray]] = field(default_factory=dict)
    behind_reports: dict[str, int] = field(default_factory=dict)

    def add(self, name: str, late_s: np.ndarray) -> None:
        self.late_s.setdefault(name, []).append(np.asarray(late_s, np.float64))

    def summary(self) -> dict[str, dict]:
        """Per stream: payloads sent, late ones (over LATE_S), median / p99 / max lateness in ms."""
        out = {}
        for name, parts in self.late_s.items():
            late = np.concatenate(parts) if parts else np.zeros(0)
            out[name] = {"sent": int(late.size), "late": int(np.count_nonzero(late > LATE_S)),
                         "median_ms": _ms(np.median(late)) if late.size else 0.0,
                         "p99_ms": _ms(np.percentile(late, 99)) if late.size else 0.0,
                         "max_ms": _ms(late.max()) if late.size else 0.0,
                         "behind_reports": self.behind_reports.get(name, 0)}
        return out


def _ms(seconds: float) -> float:
    return round(float(seconds) * 1000.0, 3)


@dataclass
class LiveStream:
    """One stream on the wire: its producer and where its datagrams go."""

    name: str
    address: tuple[str, int]
    producer: Producer
    batch: Batch | None = None
    index: int = 0
    finished: bool = False
    #: rendered for the live TDM only (its port 0): consumed on time, nothing sent
    muted: bool = False
    #: print "behind its schedule" lines (not for the TDM's targets: their lateness is the TDM's latency)
    report_behind: bool = True

    def next_time(self) -> float | None:
        """Scenario time of the next payload (None: nothing rendered yet, or the stream is over)."""
        if self.batch is None and not self.finished:
            try:
                item = self.producer.queue.get_nowait()
            except queue.Empty:
                return None
            if item is _DONE:
                self.finished = True
                if self.producer.error is not None:
                    raise self.producer.error
                return None
            self.batch, self.index = item, 0
        return None if self.batch is None else float(self.batch.times_s[self.index])


def send_streams(streams: list[LiveStream], sock: socket.socket, start_wall_s: float, speed: float,
                 end_s: float, lateness: Lateness, stop: threading.Event, log=sys.stderr) -> float:
    """Send every stream's payloads at their wall-clock times until all are over or ``end_s`` is reached.

    Parameters
    ----------
    streams : list of LiveStream
    sock : socket.socket
        A UDP socket.
    start_wall_s : float
        ``time.perf_counter()`` of scenario time 0.
    speed : float
        Multiple of real time.
    end_s : float
        Scenario time at which the session ends, s.
    lateness : Lateness
        Filled with every payload's lateness.
    stop : threading.Event
        Ends the loop when set.

    Returns
    -------
    float
        Scenario time reached, s.
    """
    last_report = {s.name: -np.inf for s in streams}
    while not stop.is_set():
        heads = [(t, s) for s in streams if (t := s.next_time()) is not None and t <= end_s]
        if not heads and all(s.finished or s.batch is not None for s in streams):
            break  # every stream over, or with nothing left before the end
        now = time.perf_counter()
        clock_s = (now - start_wall_s) * speed
        if clock_s >= end_s + END_GRACE_S:
            break  # a stream still rendering this long after the end: what it has not sent is reported as lost
        if not heads:
            time.sleep(POLL_S)
            continue
        t_next, stream = min(heads, key=lambda h: h[0])
        wait_s = start_wall_s + t_next / speed - now
        if wait_s > 0:
            time.sleep(min(wait_s, POLL_S))
            continue
        _send_due(stream, sock, start_wall_s, speed, lateness)
        if stream.muted or not stream.report_behind:
            continue
        worst = lateness.late_s[stream.name][-1].max()
        if worst > LATE_S and now - last_report[stream.name] > REPORT_EVERY_S:
            last_report[stream.name] = now
            lateness.behind_reports[stream.name] = lateness.behind_reports.get(stream.name, 0) + 1
            print(f"live: {stream.name} {worst * 1000:.0f} ms behind its schedule at t = {t_next:.1f} s", file=log)
    return min((time.perf_counter() - start_wall_s) * speed, end_s)


def _send_due(stream: LiveStream, sock: socket.socket, start_wall_s: float, speed: float, lateness: Lateness) -> None:
    """Send the stream's payloads that are due now (at least one); record their lateness."""
    batch = stream.batch
    clock_s = (time.perf_counter() - start_wall_s) * speed
    stop = max(stream.index + 1, int(np.searchsorted(batch.times_s, clock_s, side="right")))
    if stream.muted:
        stream.index = stop
        if stop >= len(batch.payloads):
            stream.batch = None
        return
    sent_at = np.empty(stop - stream.index)
    for k in range(stream.index, stop):
        sock.sendto(batch.payloads[k], stream.address)
        sent_at[k - stream.index] = time.perf_counter()
    lateness.add(stream.name, sent_at - (start_wall_s + batch.times_s[stream.index:stop] / speed))
    stream.index = stop
    if stop >= len(batch.payloads):
        stream.batch = None
