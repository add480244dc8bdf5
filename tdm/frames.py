"""Frames of the TDM: local ENU metres, the own ship's pose over time, sensor mounts.

The TDM works in its own local frame (docs/reference.md section 5: "work in local ENU
metres and convert to lon/lat only for output"): a transverse Mercator projection
(WGS84, scale 1) centred on the own ship's first navigation fix, x east, y north.
It is built from the recording alone, so it does not depend on how the recording
was made.

Body frame (REP-103): x forward, y left, z up. Angles read from the recording are
marine degrees (heading clockwise from north, roll starboard down positive, pitch
bow up positive) and are turned into the FLU rotation ``Rz(yaw) Ry(pitch) Rx(roll)``
here, with ``yaw = 90 deg - heading`` and FLU pitch = -(marine pitch). The frame, the rotations and
the mounts are :mod:`groundfloor.frames`, shared with raysim.
"""

from __future__ import annotations

import numpy as np

from groundfloor.frames import LocalFrame, Mount, marine_rotation, rotation_matrices  # noqa: F401 (tdm's names)

__all__ = ["EnuFrame", "Mount", "OwnshipTrack", "marine_rotation", "rotation_matrices"]

#: Local ENU metres about an origin (lat0, lon0 in degrees, WGS84): ``to_enu``, ``to_geodetic``.
EnuFrame = LocalFrame


class OwnshipTrack:
    """The own ship's navigation solution, interpolated at any times.

    Parameters
    ----------
    nav : dict of (M,) arrays
        ``ownship.jsonl`` columns (t, lat, lon, z, heading_deg, roll_deg, pitch_deg, ...).
    frame : EnuFrame, optional
        The TDM's frame; default: centred on the first fix.
    """

    def __init__(self, nav: dict[str, np.ndarray], frame: EnuFrame | None = None):
        self.t_s = np.asarray(nav["t"], dtype=float)
        self.frame = frame or EnuFrame(nav["lat"][0], nav["lon"][0])
        east, north = self.frame.to_enu(nav["lat"], nav["lon"])
        self._east, self._north = east, north
        self._z = np.asarray(nav.get("z", np.zeros_like(self.t_s)), dtype=float)
        self._heading_unwrapped_deg = np.degrees(np.unwrap(np.radians(nav["heading_deg"])))
        self._roll_deg = np.asarray(nav["roll_deg"], dtype=float)
        self._pitch_deg = np.asarray(nav["pitch_deg"], dtype=float)
        self._cog_deg = np.asarray(nav.get("cog_deg", nav["heading_deg"]), dtype=float)
        self._sog = np.asarray(nav.get("sog_mps", np.zeros_like(self.t_s)), dtype=float)

    def _interp(self, t, values):
        return np.interp(np.asarray(t, dtype=float), self.t_s, values)

    def position_m(self, t_s) -> np.ndarray:
        """(N, 3) own-ship origin in ENU (east, north, up), metres, at times (N,) s."""
        return np.stack([self._interp(t_s, self._east), self._interp(t_s, self._north), self._interp(t_s, self._z)], axis=-1)

    def heading_deg(self, t_s) -> np.ndarray:
        """(N,) compass heading in [0, 360) at times (N,) s."""
        return np.mod(self._interp(t_s, self._heading_unwrapped_deg), 360.0)

    def velocity_mps(self, t_s) -> np.ndarray:
        """(N, 2) own-ship velocity (east, north) from COG and SOG, m/s."""
        cog = np.radians(self._interp(t_s, self._cog_deg))
        sog = self._interp(t_s, self._sog)
        return np.stack([sog * np.sin(cog), sog * np.cos(cog)], axis=-1)

    def rotation(self, t_s) -> np.ndarray:
        """(N, 3, 3) body-to-ENU rotations at times (N,) s."""
        return marine_rotation(self._interp(t_s, self._heading_unwrapped_deg), self._interp(t_s, self._pitch_deg),
                               self._interp(t_s, self._roll_deg))

    def sensor_to_enu(self, points_sensor_m: np.ndarray, t_s: np.ndarray, mount: Mount) -> np.ndarray:
        """Map sensor-frame points to ENU, each with the pose at its own time (deskew).

        Parameters
        ----------
        points_sensor_m : (N, 3) float
            Points in the sensor frame, metres.
        t_s : (N,) float
            Each point's time, s since the recording's start.
        mount : Mount
            The sensor's mounting.

        Returns
        -------
        (N, 3) float64
            ENU points, metres.
        """
        body = np.asarray(points_sensor_m, dtype=float) @ mount.rotation().T + mount.translation_m()
        return np.einsum("nij,nj->ni", self.rotation(t_s), body) + self.position_m(t_s)
