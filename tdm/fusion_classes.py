"""What a fused target is: the classifier of :class:`tdm.fusion.Fuser` (``object_descriptor`` of docs/contracts.md).

- ``vessel``: it has an AIS track, or it has moved at over ``vessel_speed_mps`` with confidence (by
  :data:`VESSEL_SIGMAS` standard deviations, for :data:`VESSEL_MOVING_S`);
- still: speed under :data:`STILL_SPEED_FRACTION` of ``vessel_speed_mps`` with a standard deviation under it (two
  sigmas were too strict: radar tracks of still bergs keep about 0.5 m/s of speed uncertainty);
- ``iceberg``: still for ``settle_s`` with a footprint over ``iceberg_area_m2`` or a LiDAR height over
  ``iceberg_height_m``; ``fixed obstacle``: still and smaller; else ``unknown``.

A class once given to a target is kept unless a vessel is seen.
"""

from __future__ import annotations

import numpy as np

from tdm import ekf
from tdm.fusion_config import FusionConfig

__all__ = ["STILL_SPEED_FRACTION", "VESSEL_MOVING_S", "VESSEL_SIGMAS", "Classifier"]

#: A target is a vessel once it has moved (faster than ``vessel_speed_mps`` by VESSEL_SIGMAS standard
#: deviations of its speed) for this long, s.
VESSEL_MOVING_S = 5.0
VESSEL_SIGMAS = 2
#: A target is still while its speed is under this fraction of ``vessel_speed_mps``.
STILL_SPEED_FRACTION = 0.5


class Classifier:
    """Gives each fused target its class from its fused state over time (module docstring).

    Parameters
    ----------
    config : FusionConfig
        ``vessel_speed_mps``, ``settle_s``, ``iceberg_area_m2`` and ``iceberg_height_m``.
    """

    def __init__(self, config: FusionConfig):
        self.config = config
        self._moving_since: dict[int, float] = {}  # target id -> when it began to move with confidence, s
        self._still_since: dict[int, float] = {}  # target id -> when it became still, s

    def classify(self, target, x: np.ndarray, p: np.ndarray, t_s: float, height_m: float) -> None:
        """Set ``target.descriptor`` from its fused state.

        Parameters
        ----------
        target : FusedTarget
        x : (6,) float
            Fused state (:mod:`tdm.ekf`; its speed in m/s, its cross-section in m^2).
        p : (6, 6) float
            Its covariance.
        t_s : float
            Time of the state, s.
        height_m : float
            Height of the target's LiDAR track, m; NaN without one.
        """
        cfg = self.config
        if "ais" in target.members:
            target.descriptor = "vessel"
            return
        speed, sigma = x[ekf.U], np.sqrt(max(p[ekf.U, ekf.U], 0.0))
        tid = target.target_id
        if speed - VESSEL_SIGMAS * sigma > cfg.vessel_speed_mps:
            self._moving_since.setdefault(tid, t_s)
            if t_s - self._moving_since[tid] >= VESSEL_MOVING_S:
                target.descriptor = "vessel"
        else:
            self._moving_since.pop(tid, None)
        if target.descriptor == "vessel":
            return
        if abs(speed) < STILL_SPEED_FRACTION * cfg.vessel_speed_mps and sigma < cfg.vessel_speed_mps:
            self._still_since.setdefault(tid, t_s)
            if t_s - self._still_since[tid] >= cfg.settle_s:
                big = x[ekf.ALPHA] >= cfg.iceberg_area_m2 or (np.isfinite(height_m) and height_m >= cfg.iceberg_height_m)
                target.descriptor = "iceberg" if big else "fixed obstacle"
        else:
            self._still_since.pop(tid, None)
