"""Rigid-body poses evaluated for arrays of times.

Frames follow REP-103 (see docs/architecture.md):

- world: local ENU, x east, y north, z up, metres, origin at the scenario origin;
- body: x forward, y left, z up, z = 0 at the waterline.

Angles inside the code are radians in the right-handed FLU convention:
``yaw`` counter-clockwise from east, ``roll`` about body x (positive = starboard
down, same sign as the marine convention), ``pitch`` about body y-left
(positive = bow DOWN, the opposite sign of the marine convention).
Conversion to marine degrees happens only at I/O, with the helpers below.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def heading_deg_from_yaw(yaw_rad: np.ndarray) -> np.ndarray:
    """Compass heading in [0, 360) deg (clockwise from north) from ENU yaw.

    Parameters
    ----------
    yaw_rad : (N,) float
        ENU yaw, counter-clockwise from east, radians.
    """
    return np.mod(90.0 - np.degrees(yaw_rad), 360.0)


def yaw_from_heading_deg(heading_deg: np.ndarray) -> np.ndarray:
    """ENU yaw in radians (counter-clockwise from east) from compass heading in degrees."""
    return np.radians(90.0 - np.asarray(heading_deg, dtype=float))


def rotation_matrices(yaw_rad: np.ndarray, pitch_rad: np.ndarray, roll_rad: np.ndarray) -> np.ndarray:
    """Body-to-world rotation matrices ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``.

    Parameters
    ----------
    yaw_rad, pitch_rad, roll_rad : (N,) float
        FLU Euler angles, radians (see module docstring).

    Returns
    -------
    (N, 3, 3) float64
        ``world_vector = R @ body_vector``.
    """
    yaw = np.asarray(yaw_rad, dtype=float)
    cy, sy = np.cos(yaw), np.sin(yaw)
    cp, sp = np.cos(pitch_rad), np.sin(pitch_rad)
    cr, sr = np.cos(roll_rad), np.sin(roll_rad)
    cy, sy, cp, sp, cr, sr = np.broadcast_arrays(cy, sy, cp, sp, cr, sr)
    r = np.empty(cy.shape + (3, 3))
    r[..., 0, 0] = cy * cp
    r[..., 0, 1] = cy * sp * sr - sy * cr
    r[..., 0, 2] = cy * sp * cr + sy * sr
    r[..., 1, 0] = sy * cp
    r[..., 1, 1] = sy * sp * sr + cy * cr
    r[..., 1, 2] = sy * sp * cr - cy * sr
    r[..., 2, 0] = -sp
    r[..., 2, 1] = cp * sr
    r[..., 2, 2] = cp * cr
    return r


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
