"""Rigid-body poses evaluated for arrays of times.

Frames follow REP-103 (see docs/architecture.md):

- world: local ENU, x east, y north, z up, metres, origin at the scenario origin;
- body: x forward, y left, z up, z = 0 at the waterline.

Angles inside the code are radians in the right-handed FLU convention:
``yaw`` counter-clockwise from east, ``roll`` about body x (positive = starboard
down, same sign as the marine convention), ``pitch`` about body y-left
(positive = bow DOWN, the opposite sign of the marine convention).
Conversion to marine degrees happens only at I/O, with the helpers of :mod:`groundfloor.frames`
(re-exported here with the rotations, shared with the TDM).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from groundfloor.frames import heading_deg_from_yaw, rotation_matrices, yaw_from_heading_deg  # noqa: F401


@dataclass(frozen=True)
class Poses:
    """Poses of one body at N instants.

    Attributes
    ----------
    position_m : (N, 3) float64
        Body origin in the world (ENU) frame, metres.
    yaw_rad, pitch_rad, roll_rad : (N,) float64
        FLU Euler angles, radians (module docstring). ``yaw_rad`` is continuous
        (unwrapped) along a trajectory.
    """

    position_m: np.ndarray
    yaw_rad: np.ndarray
    pitch_rad: np.ndarray
    roll_rad: np.ndarray

    def rotation(self) -> np.ndarray:
        """(N, 3, 3) body-to-world rotation matrices."""
        return rotation_matrices(self.yaw_rad, self.pitch_rad, self.roll_rad)

    def to_world(self, points_body_m: np.ndarray) -> np.ndarray:
        """Map (N, 3) body-frame points (one per pose) to the world frame."""
        return np.einsum("nij,nj->ni", self.rotation(), points_body_m) + self.position_m

    def to_body(self, points_world_m: np.ndarray) -> np.ndarray:
        """Map (N, 3) world points (one per pose) into the body frame."""
        return np.einsum("nji,nj->ni", self.rotation(), points_world_m - self.position_m)

    @property
    def heading_deg(self) -> np.ndarray:
        """(N,) compass heading, degrees clockwise from north, [0, 360)."""
        return heading_deg_from_yaw(self.yaw_rad)
