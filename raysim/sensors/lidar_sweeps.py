"""The LiDAR's per-revolution sweep files, gathered chunk by chunk (docs/formats.md, lidar/sweeps).

Shared by the file render (:meth:`raysim.sensors.lidar.LidarRenderer.run`) and live mode, which
writes the same sweeps for its TDM while it sends the packets.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from groundfloor import hdl32e
from groundfloor.recording import LIDAR_SWEEP
from raysim.recording.npz import write_sweep

__all__ = ["LidarSweeps"]

DEG_PER_TURN = 360.0


class LidarSweeps:
    """Points of a render's chunks gathered into revolutions; each written once the next one starts.

    Parameters
    ----------
    renderer : raysim.sensors.lidar.LidarRenderer
    sweeps_dir : Path
        Where ``NNNNNN.npz`` go (created).
    """

    def __init__(self, renderer, sweeps_dir: Path):
        self.renderer = renderer
        self.sweeps_dir = Path(sweeps_dir)
        self.sweeps_dir.mkdir(parents=True, exist_ok=True)
        self.pending: list[dict] = []
        self.current = 0
        self.counts = {"sweeps": 0, "points": 0}

    def _revolution(self, t_s: np.ndarray) -> np.ndarray:
        cfg = self.renderer.cfg
        return np.floor((cfg.azimuth0_deg + DEG_PER_TURN * cfg.rotation_hz * t_s) / DEG_PER_TURN).astype(np.int64)

    def add(self, chunk) -> None:
        """The points of one :class:`raysim.sensors.lidar.LidarChunk`; revolutions it completes are written."""
        revolution = self._revolution(chunk.time_s)
        pts, cycle_of_point = self.renderer.points(chunk.firings)
        point_rev = revolution[cycle_of_point]
        for rev in np.unique(revolution):
            if rev > self.current:
                self._flush()
                self.pending, self.current = [], int(rev)
            self.pending.append({k: v[point_rev == rev] for k, v in pts.items()})

    def finish(self) -> None:
        """Write the last revolution if the render completed it."""
        r = self.renderer
        t_next = np.array([r.n_packets * r.cycles_per_packet * hdl32e.CYCLE_DT_S])
        if self.pending and self._revolution(t_next)[0] > self.current:
            self._flush()

    def _flush(self) -> None:
        arrays = {k: np.concatenate([p[k] for p in self.pending]) for k in self.pending[0]}
        write_sweep(self.sweeps_dir, self.current, LIDAR_SWEEP, arrays)
        self.counts["sweeps"] += 1
        self.counts["points"] += int(arrays["x"].shape[0])
