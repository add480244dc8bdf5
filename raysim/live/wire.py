"""The send loop of a live session, in a process of its own: each payload on the wire at its time.

The rendering threads of the session hold the interpreter in calls that do not release it (some
numpy operations, the ray engine's bookkeeping); a send loop sharing that interpreter waits for
them (p99 lateness 6-7 ms over ten minutes). Here the loop runs in a spawned process that imports
nothing but numpy: the session's producers hand it each stream's batches through a short
multiprocessing queue, it takes the earliest due payload of any stream, waits for its wall-clock
time (scenario time / speed after the start; ``time.perf_counter`` is the system's monotonic clock,
the same in both processes), sends it by UDP and measures how late it left. A stream whose next
batch is not there yet does not hold the others back: its payloads go as soon as they arrive and
their lateness says so. Nothing is dropped.

A batch on a queue is ``("batch", times_s, payloads)``; ``("done", None, None)`` ends a stream. A reader
thread per stream takes the batches off the session's queues into this process's own (one batch deep),
so that the send loop never waits for a batch still crossing the pipe.
"""

from __future__ import annotations

import os
import queue
import signal
import socket
import sys
import threading
import time
from dataclasses import dataclass, field

import numpy as np

__all__ = ["LATE_S", "POLL_S", "Lateness", "WireStream", "send_streams", "preroll", "wire_main", "summary"]

#: A payload that leaves more than this after its time counts as late, s.
LATE_S = 0.010
#: Longest sleep of the send loop, s (new batches and the stop flag are seen this often).
POLL_S = 0.002
#: How long after the end of the session a stream still rendering is waited for, s of scenario time.
END_GRACE_S = 5.0
#: Seconds between two "behind schedule" lines of one stream.
REPORT_EVERY_S = 1.0
#: Longest wait for the first batch of every stream before the clock starts, s.
PREROLL_TIMEOUT_S = 120.0
#: Pause between the first batches of every stream being there and the clock's start, s.
SETTLE_S = 0.2
#: Multicast TTL (1: this network segment only).
MULTICAST_TTL = 1


@dataclass
class WireStream:
    """One stream on the wire: where its datagrams go and where its batches come from."""

    name: str
    address: tuple[str, int]
    source: object  # a queue of ("batch", times_s, payloads) / ("done", None, None)
    muted: bool = False  # rendered for the TDM or the Foxglove view only: consumed on time, nothing sent
    report_behind: bool = True  # the TDM's targets: their lateness is its latency, not a schedule slip
    preroll: bool = True  # wait for its first batch before the clock starts (not the TDM's targets)
    times: np.ndarray | None = None
    payloads: list | None = None
    index: int = 0
    finished: bool = False

    def next_time(self) -> float | None:
        """Scenario time of the next payload (None: nothing there yet, or the stream is over)."""
        if self.payloads is None and not self.finished:
            try:
                kind, times, payloads = self.source.get_nowait()
            except queue.Empty:
                return None
            if kind == "done":
                self.finished = True
                return None
            self.times, self.payloads, self.index = np.asarray(times, np.float64), payloads, 0
        return None if self.payloads is None else float(self.times[self.index])


@dataclass
class Lateness:
    """Per-stream send lateness, s (wall time of sending minus the payload's scheduled wall time)."""

    late_s: dict[str, list[np.ndarray]] = field(default_factory=dict)
    behind_reports: dict[str, int] = field(default_factory=dict)

    def add(self, name: str, late_s: np.ndarray) -> None:
        self.late_s.setdefault(name, []).append(np.asarray(late_s, np.float64))

    def arrays(self) -> dict[str, np.ndarray]:
        return {name: np.concatenate(parts) if parts else np.zeros(0) for name, parts in self.late_s.items()}


def summary(arrays: dict[str, np.ndarray], behind_reports: dict[str, int]) -> dict[str, dict]:
    """Per stream: payloads sent, late ones (over LATE_S), median / p99 / max lateness in ms."""
    out = {}
    for name, late in arrays.items():
        out[name] = {"sent": int(late.size), "late": int(np.count_nonzero(late > LATE_S)),
                     "median_ms": _ms(np.median(late)) if late.size else 0.0,
                     "p99_ms": _ms(np.percentile(late, 99)) if late.size else 0.0,
                     "max_ms": _ms(late.max()) if late.size else 0.0,
                     "behind_reports": behind_reports.get(name, 0)}
    return out


def _ms(seconds: float) -> float:
    return round(float(seconds) * 1000.0, 3)


def preroll(streams: list[WireStream], stop) -> bool:
    """Wait until every stream that prerolls has its first batch (or is over); False if stopped or timed out."""
    deadline = time.perf_counter() + PREROLL_TIMEOUT_S
    while not stop.is_set() and time.perf_counter() < deadline:
        if all(s.next_time() is not None or s.finished or not s.preroll for s in streams):
            return True
        time.sleep(0.01)
    return False


def send_streams(streams: list[WireStream], sock: socket.socket, start_wall_s: float, speed: float,
                 end_s: float, lateness: Lateness, stop, log=sys.stderr) -> float:
    """Send every stream's payloads at their wall-clock times until all are over or ``end_s`` is passed.

    Returns the scenario time reached, s.
    """
    last_report = {s.name: -np.inf for s in streams}
    while not stop.is_set():
        heads = [(t, s) for s in streams if (t := s.next_time()) is not None and t <= end_s]
        if not heads and all(s.finished or s.payloads is not None for s in streams):
            break  # every stream over, or with nothing left before the end
        now = time.perf_counter()
        if (now - start_wall_s) * speed >= end_s + END_GRACE_S:
            break  # a stream still rendering this long after the end: what it has not sent is not sent
        if not heads:
            time.sleep(POLL_S)
            continue
        t_next, stream = min(heads, key=lambda h: h[0])
        wait_s = start_wall_s + t_next / speed - now
        if wait_s > 0:
            time.sleep(min(wait_s, POLL_S))
            continue
        worst = _send_due(stream, sock, start_wall_s, speed, lateness)
        if stream.report_behind and worst > LATE_S and now - last_report[stream.name] > REPORT_EVERY_S:
            last_report[stream.name] = now
            lateness.behind_reports[stream.name] = lateness.behind_reports.get(stream.name, 0) + 1
            print(f"live: {stream.name} {worst * 1000:.0f} ms behind its schedule at t = {t_next:.1f} s", file=log)
    return min((time.perf_counter() - start_wall_s) * speed, end_s)


def _send_due(stream: WireStream, sock: socket.socket, start_wall_s: float, speed: float, lateness: Lateness) -> float:
    """Send the stream's payloads that are due now (at least one); record their lateness; return the worst, s."""
    clock_s = (time.perf_counter() - start_wall_s) * speed
    stop = max(stream.index + 1, int(np.searchsorted(stream.times, clock_s, side="right")))
    worst = 0.0
    if not stream.muted:
        sent_at = np.empty(stop - stream.index)
        for k in range(stream.index, stop):
            sock.sendto(stream.payloads[k], stream.address)
            sent_at[k - stream.index] = time.perf_counter()
        late = sent_at - (start_wall_s + stream.times[stream.index:stop] / speed)
        lateness.add(stream.name, late)
        worst = float(late.max())
    stream.index = stop
    if stop >= len(stream.payloads):
        stream.times = stream.payloads = None
    return worst


#: Scheduling asked for the send process, first choice: round-robin real time at a low priority (it wakes a few
#: hundred times a second for microseconds and sleeps between, while the renderers keep both cores busy); needs
#: root or CAP_SYS_NICE. Second choice: a lower niceness (the same privilege). Without either it keeps the default.
WIRE_RT_PRIORITY = 10
WIRE_NICE = -10


def _raise_priority() -> str:
    """Ask the scheduler to run this process before the renderers; returns what it got."""
    try:
        os.sched_setscheduler(0, os.SCHED_RR, os.sched_param(WIRE_RT_PRIORITY))
        return "SCHED_RR"
    except (AttributeError, PermissionError, OSError):
        pass
    try:
        os.setpriority(os.PRIO_PROCESS, 0, WIRE_NICE)
        return f"nice {WIRE_NICE}"
    except (AttributeError, PermissionError, OSError):
        return "default"


def _read(source, out: queue.Queue, stop) -> None:
    """Move one stream's batches from the session's queue to this process's, ahead of the send loop.

    A batch crosses the pipe from the session's feeder thread, which shares the renderers' interpreter:
    reading it in the send loop would hold the loop until the last byte came (milliseconds for a radar
    revolution of 1 MB). Here a thread waits for it, its interpreter released while it reads.
    """
    while not stop.is_set():
        try:
            item = source.get(timeout=0.1)
        except queue.Empty:
            continue
        while not stop.is_set():
            try:
                out.put(item, timeout=0.1)
                break
            except queue.Full:
                continue
        if item[0] == "done":
            return


def wire_main(specs: list[dict], sources: list, speed: float, end_s: float, multicast: bool, stop, started,
              start_at, results) -> None:
    """The send process: preroll, then the loop; puts ``(lateness arrays, behind reports, reached s, scheduling)``
    on ``results``.

    Ctrl-C reaches the whole process group: this process ignores it and ends when the session sets ``stop``.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    scheduling = _raise_priority()
    local = [queue.Queue(maxsize=1) for _ in sources]
    readers = [threading.Thread(target=_read, args=(src, out, stop), daemon=True) for src, out in zip(sources, local)]
    for r in readers:
        r.start()
    streams = [WireStream(source=out, **spec) for spec, out in zip(specs, local)]
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    if multicast:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, MULTICAST_TTL)
    lateness, reached = Lateness(), 0.0
    try:
        if preroll(streams, stop):
            time.sleep(SETTLE_S)  # the readers take the next batches off the pipes before the clock starts
            start_at.value = time.perf_counter()
            started.set()
            reached = send_streams(streams, sock, start_at.value, speed, end_s, lateness, stop)
        elif not stop.is_set():
            print(f"live: streams not ready after {PREROLL_TIMEOUT_S:g} s", file=sys.stderr)
    finally:
        sock.close()
        results.put((lateness.arrays(), dict(lateness.behind_reports), reached, scheduling))
