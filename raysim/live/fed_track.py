"""The live TDM's own ship when it is fed from outside (``--ownship-in`` with ``--targets-port``).

The TDM places each detection with the own ship's pose at the detection's time
(:class:`tdm.frames.OwnshipTrack`, read from ``ownship.jsonl`` in a recording). In a live session
with a fed own ship that pose is the fed one (:class:`raysim.live.ownship_in.FedMotion`), known only as
the fixes arrive: this track asks the fed motion at each call, in the TDM's frame.
"""

from __future__ import annotations

import numpy as np

from raysim.pose import heading_deg_from_yaw
from tdm.frames import OwnshipTrack, marine_rotation

__all__ = ["FedOwnshipTrack"]


class FedOwnshipTrack(OwnshipTrack):
    """:class:`tdm.frames.OwnshipTrack` answered by a :class:`raysim.motion.Motion` (the fed own ship).

    Parameters
    ----------
    motion : raysim.motion.Motion
        The own ship's motion (world frame of the scenario).
    world_frame : LocalFrame
        The scenario's local frame (the motion's positions).
    tdm_frame : LocalFrame
        The TDM's frame (its own-ship track's, from the working recording).
    """

    def __init__(self, motion, world_frame, tdm_frame):  # noqa: D107 (no nav arrays: nothing to interpolate)
        self.motion, self.world_frame, self.frame = motion, world_frame, tdm_frame

    @staticmethod
    def _times(t_s) -> np.ndarray:
        return np.atleast_1d(np.asarray(t_s, dtype=float))

    def position_m(self, t_s) -> np.ndarray:
        """(N, 3) own-ship origin in the TDM's ENU frame, metres (3,) for a scalar time."""
        pos = self.motion.poses(self._times(t_s)).position_m
        lat, lon = self.world_frame.to_geodetic(pos[:, 0], pos[:, 1])
        east, north = self.frame.to_enu(lat, lon)
        out = np.stack([east, north, pos[:, 2]], axis=-1)
        return out if np.ndim(t_s) else out[0]

    def heading_deg(self, t_s) -> np.ndarray:
        """(N,) compass heading in [0, 360), deg."""
        out = np.mod(heading_deg_from_yaw(self.motion.poses(self._times(t_s)).yaw_rad), 360.0)
        return out if np.ndim(t_s) else out[0]

    def velocity_mps(self, t_s) -> np.ndarray:
        """(N, 2) velocity (east, north), m/s."""
        out = self.motion.velocity_mps(self._times(t_s))[:, :2]
        return out if np.ndim(t_s) else out[0]

    def rotation(self, t_s) -> np.ndarray:
        """(N, 3, 3) body-to-ENU rotations (the navigation's conventions: roll starboard down, pitch bow up)."""
        poses = self.motion.poses(self._times(t_s))
        return marine_rotation(heading_deg_from_yaw(poses.yaw_rad), -np.degrees(poses.pitch_rad),
                               np.degrees(poses.roll_rad))
