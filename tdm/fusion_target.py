"""What the fusion hands on: a detected target (:class:`FusedTarget`, the per-sensor tracks of one object) and its
fused state at one time (:class:`FusedEstimate`).

The fuser (:mod:`tdm.fusion`) makes and keeps them; the modules that classify, weigh and report them
(:mod:`tdm.fusion_classes`, :mod:`tdm.fusion_weights`, :mod:`tdm.fusion_face`, :mod:`tdm.fusion_consider`) read them.
They live here, under all of these, so that none imports the fuser for its types.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["FusedEstimate", "FusedTarget"]


@dataclass
class FusedTarget:
    """A detected target: the per-sensor tracks of one object."""

    target_id: int
    members: dict[str, int] = field(default_factory=dict)  # sensor -> track id
    absorbed: set = field(default_factory=set)  # (sensor, track id) of extra tracks on this object
    last_x: np.ndarray | None = None  # the last fused state (6,) reported, and its time
    last_p: np.ndarray | None = None  # its covariance (6, 6)
    last_t_s: float = 0.0
    radius_m: float = 0.0  # its absorbing radius then
    created_s: float = 0.0
    descriptor: str = "unknown"
    mmsi: int | None = None


@dataclass
class FusedEstimate:
    """A target's fused state at one time."""

    target: FusedTarget
    x: np.ndarray  # (6,)
    p: np.ndarray  # (6, 6)
    sources: list[str]
