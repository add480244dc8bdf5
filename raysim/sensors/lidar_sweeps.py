"""The LiDAR's per-revolution sweep files, gathered chunk by chunk (docs/formats.md, lidar/sweeps).

Shared by the file render (:meth:`raysim.sensors.lidar.LidarRenderer.run`) and live mode, which
writes the same sweeps for its TDM while it sends the packets.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from groundfloor.recording import LIDAR_SWEEP
from raysim.recording.npz import write_sweep_pieces

__all__ = ["LidarSweeps"]

DEG_PER_TURN = 360.0


class LidarSweeps:
    """Points of a render's chunks gathered into revolutions; each written once the next one starts.

    Parameters
    ----------
    renderer : raysim.sensors.lidar.LidarRenderer
    sweeps_dir : Path
        Where ``NNNNNN.npz`` go (created).
    from_s : float
        Revolutions that began before the one under way at this time, s, are not written (a later
        part of a run: their points are another part's).
    """

    def __init__(self, renderer, sweeps_dir: Path, from_s: float = 0.0):
        self.renderer = renderer
        self.sweeps_dir = Path(sweeps_dir)
        self.sweeps_dir.mkdir(parents=True, exist_ok=True)
        self.pending: list[dict] = []
        self.first_revolution = self.current = int(self._revolution(np.array([from_s]))[0]) if from_s > 0 else 0
        self.counts = {"sweeps": 0, "points": 0}

    def _revolution(self, t_s: np.ndarray) -> np.ndarray:
        cfg = self.renderer.cfg
        return np.floor((cfg.azimuth0_deg + DEG_PER_TURN * cfg.rotation_hz * t_s) / DEG_PER_TURN).astype(np.int64)

    def add(self, chunk) -> None:
        """The points of one :class:`raysim.sensors.lidar.LidarChunk`; revolutions it completes are written.

        Points come in time order, so each revolution's points are one slice of the chunk's
        arrays: views of them wait for the write, nothing is copied.
        """
        revolution = self._revolution(chunk.time_s)
        pts, cycle_of_point = self.renderer.points(chunk.firings)
        revs = np.unique(revolution)
        # first point of each revolution of the chunk (its cycles are in time order, so are the points)
        cut = np.searchsorted(np.take(revolution, cycle_of_point), revs, side="left").tolist() + [cycle_of_point.size]
        for i, rev in enumerate(revs):
            if rev < self.first_revolution:
                continue
            if rev > self.current:
                self._flush()
                self.pending, self.current = [], int(rev)
            self.pending.append({k: v[cut[i]:cut[i + 1]] for k, v in pts.items()})

    def finish(self, end_s: float | None = None) -> None:
        """Write the last revolution if the render completed it (before ``end_s``: by default the run's end)."""
        r = self.renderer
        end_s = r.chunk_start_s(r.n_chunks) if end_s is None else end_s
        if self.pending and self._revolution(np.array([end_s]))[0] > self.current:
            self._flush()

    def _flush(self) -> None:
        pieces = {k: [p[k] for p in self.pending] for k in self.pending[0]}
        write_sweep_pieces(self.sweeps_dir, self.current, LIDAR_SWEEP, pieces)
        self.counts["sweeps"] += 1
        self.counts["points"] += sum(int(p.shape[0]) for p in pieces["x"])
