"""Frames of the TDM: local ENU metres, the own ship's pose over time, sensor mounts.

The TDM works in its own local frame (docs/reference.md section 5: "work in local ENU
metres and convert to lon/lat only for output"): a transverse Mercator projection
(WGS84, scale 1) centred on the own ship's first navigation fix, x east, y north.
It is built from the recording alone, so it does not depend on how the recording
was made.

Body frame (REP-103): x forward, y left, z up. Angles read from the recording are
marine degrees (heading clockwise from north, roll starboard down positive, pitch
bow up positive) and are turned into the FLU rotation ``Rz(yaw) Ry(pitch) Rx(roll)``
here, with ``yaw = 90 deg - heading`` and FLU pitch = -(marine pitch).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from pyproj import Transformer


@lru_cache(maxsize=16)
def _transformers(lat0: float, lon0: float) -> tuple[Transformer, Transformer]:
    proj = f"+proj=tmerc +lat_0={lat0!r} +lon_0={lon0!r} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs"
    return (Transformer.from_crs("EPSG:4326", proj, always_xy=True),
            Transformer.from_crs(proj, "EPSG:4326", always_xy=True))


class EnuFrame:
    """Local ENU metres about an origin (lat0, lon0 in degrees, WGS84)."""

    def __init__(self, lat0_deg: float, lon0_deg: float):
        self.lat0_deg, self.lon0_deg = float(lat0_deg), float(lon0_deg)
        self._forward, self._inverse = _transformers(self.lat0_deg, self.lon0_deg)

    def to_enu(self, lat_deg, lon_deg) -> tuple[np.ndarray, np.ndarray]:
        """(east, north) in metres, arrays of the inputs' shape."""
        x, y = self._forward.transform(np.asarray(lon_deg, dtype=float), np.asarray(lat_deg, dtype=float))
        return np.asarray(x, dtype=float), np.asarray(y, dtype=float)

    def to_geodetic(self, east_m, north_m) -> tuple[np.ndarray, np.ndarray]:
        """(lat, lon) in degrees from ENU metres."""
        lon, lat = self._inverse.transform(np.asarray(east_m, dtype=float), np.asarray(north_m, dtype=float))
        return np.asarray(lat, dtype=float), np.asarray(lon, dtype=float)


def rotation_matrices(yaw_rad, pitch_rad, roll_rad) -> np.ndarray:
    """(N, 3, 3) body-to-ENU rotations ``Rz(yaw) @ Ry(pitch) @ Rx(roll)`` (FLU angles, radians)."""
    cy, sy = np.cos(yaw_rad), np.sin(yaw_rad)
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


def marine_rotation(heading_deg, pitch_deg, roll_deg) -> np.ndarray:
    """(N, 3, 3) body-to-ENU rotations from marine angles in degrees (module docstring)."""
    return rotation_matrices(np.radians(90.0 - np.asarray(heading_deg, dtype=float)),
                             -np.radians(np.asarray(pitch_deg, dtype=float)),
                             np.radians(np.asarray(roll_deg, dtype=float)))


@dataclass(frozen=True)
class Mount:
    """A sensor's mounting on the own ship (body frame; marine angles, yaw clockwise from the bow)."""

    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    roll_deg: float = 0.0
    pitch_deg: float = 0.0
    yaw_deg: float = 0.0

    @classmethod
    def from_dict(cls, d: dict | None) -> "Mount":
        d = d or {}
        return cls(**{k: float(d.get(k, 0.0)) for k in ("x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg")})

    def rotation(self) -> np.ndarray:
        """(3, 3) sensor-to-body rotation."""
        return rotation_matrices(np.radians(-self.yaw_deg), -np.radians(self.pitch_deg), np.radians(self.roll_deg))

    def translation_m(self) -> np.ndarray:
        """(3,) sensor origin in the body frame, metres."""
        return np.array([self.x_m, self.y_m, self.z_m])


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
