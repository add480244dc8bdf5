"""A LiDAR render into a recording's ``lidar/`` directory, whole or in two parts rendered side by side.

The render goes a chunk (about one revolution) at a time (:meth:`raysim.sensors.lidar.LidarRenderer.chunks`),
and a chunk's bytes do not depend on the chunks before it (its random numbers are its own), so two
processes can share one run: the second process renders from the start while this one renders the
other sensors; then this one takes the later half of what is left (:class:`ChunkClaims`) and renders
it beside the second. The later part writes its packets to a part file, appended to ``hdl32e.pcap``
when both are done (:func:`join_pcap_parts`), and its sweeps from the first revolution the earlier part
could not finish: it starts one chunk early, for that revolution's first points. The recording is the
same bytes whichever way it was split (tests/raysim/test_lidar_run.py).
"""

from __future__ import annotations

import shutil
from collections import deque
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

from raysim.recording.staging import atomic_path
from raysim.recording.velodyne import PcapWriter
from raysim.sensors.context import SensorContext

PCAP_NAME = "hdl32e.pcap"
#: A later part's packets, before they are appended to hdl32e.pcap: ``.hdl32e.pcap.part-NNNNNN`` (its first chunk).
PART_PREFIX = f".{PCAP_NAME}.part-"
#: Fewest chunks left for which this process takes half of them (fewer: the second process renders them all).
MIN_CHUNKS_TO_SHARE = 4
#: Chunks handed to the writer thread and not yet written, at most.
CHUNKS_IN_FLIGHT = 2
#: The end of a run's claims before this process takes its share (the run's own end stops the render first).
UNBOUNDED = 2**62

__all__ = ["ChunkClaims", "ChunkWriter", "join_pcap_parts", "render_chunks", "render_lidar"]


def render_chunks(renderer, out_dir: Path, progress=None, first: int = 0, end: int | None = None, claim=None) -> dict:
    """Render chunks ``first .. end - 1`` of a run into ``out_dir/lidar``; returns counts for the manifest.

    ``first`` 0: ``hdl32e.pcap`` itself; later: a part file (:data:`PART_PREFIX`) of records alone, to be
    appended (:func:`join_pcap_parts`). Sweeps: every revolution that ends within the chunks rendered
    and starts at or after the first chunk's revolution. ``claim``: as in ``chunks``.

    A chunk's files are written on a writer thread while the next chunk renders (:class:`ChunkWriter`):
    the compiled kernels, numpy's loops over large arrays and the files' system calls release the GIL
    (Open3D's cast does not), so the two overlap on a second core.
    """
    from raysim.sensors.lidar_sweeps import LidarSweeps

    lidar_dir = out_dir / "lidar"
    start_s = renderer.chunk_start_s(first)
    # from the revolution under way at the first chunk: its first points are in the chunk before
    sweeps = LidarSweeps(renderer, lidar_dir / "sweeps", from_s=start_s)
    counts = {"packets": 0, "position_packets": 0}
    last = first  # the chunk after the last one written
    path = lidar_dir / (PCAP_NAME if first == 0 else f"{PART_PREFIX}{first:06d}")
    frames_before = first * renderer.chunk_packets + renderer._positions_before(first)[1]
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        pcap = PcapWriter(handle, header=first == 0, frames_before=frames_before)

        def write(chunk) -> None:  # on the writer thread, one chunk after another in order
            nonlocal last
            sweeps.add(chunk)
            if chunk.time_s[0] < start_s:  # the chunk before the part: its sweep points only
                return
            renderer._write_in_order(pcap, chunk.payloads, chunk.sent_s, chunk.position_times_s)
            counts["packets"] += chunk.payloads.shape[0]
            counts["position_packets"] += len(chunk.position_times_s)
            last += 1

        with ChunkWriter(write) as writer:
            for chunk in renderer.chunks(progress, first=max(first - 1, 0), end=end, claim=claim):
                writer.put(chunk)
        sweeps.finish(renderer.chunk_start_s(last))
    return {**counts, **sweeps.counts}


class ChunkWriter:
    """One writer thread that takes chunks in order; at most :data:`CHUNKS_IN_FLIGHT` wait for it.

    Use as a context manager: leaving it waits for every chunk put (and raises the first fault of the
    writer, if the block itself did not raise). Memory stays flat: :meth:`put` waits while the writer
    is :data:`CHUNKS_IN_FLIGHT` chunks behind.

    Parameters
    ----------
    write : callable
        Called with each chunk, on the writer thread, in the order the chunks were put.
    """

    def __init__(self, write):
        self.write = write
        self._pool = ThreadPoolExecutor(1, thread_name_prefix="lidar-writer")
        self._pending: deque[Future] = deque()
        self._failed = False

    def put(self, chunk) -> None:
        """Hand ``chunk`` to the writer (after waiting for the oldest, if too many are pending)."""
        while len(self._pending) >= CHUNKS_IN_FLIGHT:
            self._pending.popleft().result()
        self._pending.append(self._pool.submit(self._write_unless_failed, chunk))

    def _write_unless_failed(self, chunk) -> None:
        """On the writer thread: after a fault, the chunks queued behind it are not written."""
        if self._failed:
            return
        try:
            self.write(chunk)
        except BaseException:
            self._failed = True
            raise

    def __enter__(self) -> "ChunkWriter":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            if exc_type is None:
                while self._pending:
                    self._pending.popleft().result()
        finally:
            for future in self._pending:  # leaving by an exception: drop what has not started
                future.cancel()
            self._pool.shutdown(wait=True)


def join_pcap_parts(lidar_dir: Path) -> None:
    """Append the later parts' records to ``hdl32e.pcap``, in order, and remove the part files."""
    parts = sorted(Path(lidar_dir).glob(f"{PART_PREFIX}*"))
    if not parts:
        return
    with open(Path(lidar_dir) / PCAP_NAME, "ab") as whole:
        for part in parts:
            with open(part, "rb") as handle:
                shutil.copyfileobj(handle, whole, length=1 << 22)
            part.unlink()


class ChunkClaims:
    """Which chunks of a run the second process may still render: a shared ``[next, end)`` of chunk indices.

    Parameters
    ----------
    shared : multiprocessing Array of 2 int64 with a lock
        ``[next chunk the second process would render, end]`` (:meth:`make`).
    """

    def __init__(self, shared):
        self.shared = shared

    @classmethod
    def make(cls, context) -> "ChunkClaims":
        """Claims of a run, every chunk the second process's until this one takes some (``context``: a
        multiprocessing context, whose Array a spawned child inherits)."""
        return cls(context.Array("q", [0, UNBOUNDED]))

    def claim(self, index: int) -> bool:
        """The second process, before chunk ``index``: whether it is still its to render."""
        with self.shared.get_lock():
            if index >= self.shared[1]:
                return False
            self.shared[0] = index + 1
            return True

    def take_later_half(self, n_chunks: int) -> tuple[int, int]:
        """This process's share of a run of ``n_chunks``: the later half of the chunks not yet claimed,
        as ``(first, end)``; ``first == end`` (nothing) when fewer than :data:`MIN_CHUNKS_TO_SHARE` are left.
        """
        with self.shared.get_lock():
            claimed, end = int(self.shared[0]), min(int(self.shared[1]), int(n_chunks))
            left = end - claimed
            if left < MIN_CHUNKS_TO_SHARE:
                return end, end
            first = claimed + left // 2
            self.shared[1] = first
            return first, end


def render_lidar(renderer, ctx: SensorContext) -> None:
    """Render the ``lidar`` entry of :data:`raysim.render.SENSOR_RENDERERS` with ``renderer`` (a
    :class:`raysim.sensors.lidar.LidarRenderer` made for ``ctx``'s world and scene; in a second process: the chunks
    it may claim, ``ctx.lidar_claims``)."""
    claims = getattr(ctx, "lidar_claims", None)
    from tqdm import tqdm

    progress = (lambda it: tqdm(it, desc="lidar", unit="rev", leave=False)) if ctx.progress else None
    counts = render_chunks(renderer, ctx.out_dir, progress, claim=None if claims is None else ChunkClaims(claims).claim)
    ctx.counts.update({f"lidar/{k}": v for k, v in counts.items()})


def render_lidar_later_half(renderer, ctx: SensorContext, claims: ChunkClaims) -> dict:
    """This process's share of a LiDAR run the second process renders (:meth:`ChunkClaims.take_later_half`), with
    ``renderer`` (a :class:`raysim.sensors.lidar.LidarRenderer` made for ``ctx``'s world and scene): its counts
    (``lidar/...``), empty when it took nothing."""
    first, end = claims.take_later_half(renderer.n_chunks)
    if first >= end:
        return {}
    counts = render_chunks(renderer, ctx.out_dir, first=first, end=end)
    return {f"lidar/{k}": v for k, v in counts.items()}
