"""The producers of a live session: each stream's batches rendered ahead of the clock into a short queue.

A :class:`Producer` thread runs one stream's generator (:mod:`raysim.live.streams`) and hands each
batch to the send process (:mod:`raysim.live.wire`) through a multiprocessing queue of
:data:`QUEUE_DEPTH` batches, so a renderer runs at most that far ahead of the wire.
"""

from __future__ import annotations

import queue
import threading
from typing import Callable, Iterator

from raysim.live.streams import Batch

__all__ = ["Producer", "QUEUE_DEPTH"]

#: Batches a producer may render ahead of the send loop.
QUEUE_DEPTH = 2


class Producer(threading.Thread):
    """Runs one stream's batch generator into a bounded queue, ahead of the clock.

    Parameters
    ----------
    name : str
        Stream name (for errors and reports).
    batches : iterator of Batch
        The stream, in time order.
    out : queue
        Where the batches go, as ``("batch", times_s, payloads)``; ``("done", None, None)`` at the end.
    stop : event
        Set to end the stream early.
    ready_before : callable, optional
        Called with a batch's last time before the next batch is rendered; it may block to keep the
        producer from running too far ahead (the fed own ship's extrapolation limit).
    """

    def __init__(self, name: str, batches: Iterator[Batch], out, stop,
                 ready_before: Callable[[float], None] | None = None):
        super().__init__(name=f"live-{name}", daemon=True)
        self.stream_name = name
        self.batches = batches
        self.out = out
        self.stop = stop
        self.ready_before = ready_before
        self.error: BaseException | None = None

    def run(self) -> None:
        try:
            for batch in self.batches:
                if len(batch.payloads) and not self._put(("batch", batch.times_s, batch.payloads)):
                    return
                if self.stop.is_set():
                    return
                if self.ready_before is not None:
                    self.ready_before(batch.end_s)
        except BaseException as exc:  # re-raised by the session once the wire has stopped
            self.error = exc
            self.stop.set()
        finally:
            self._put(("done", None, None))

    def _put(self, item) -> bool:
        while not self.stop.is_set():
            try:
                self.out.put(item, timeout=0.1)
                return True
            except queue.Full:
                continue
        return False
