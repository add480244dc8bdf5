"""Frames: local ENU metres about an origin, body-to-world rotations, sensor mounts.

Frames follow REP-103 (docs/architecture.md):

- local (world) frame: a transverse Mercator projection (WGS84, scale factor 1) centred on an
  origin, which docs/reference.md section 1 allows as the local ENU frame: x east, y north,
  metres, exact in both directions;
- body: x forward, y left, z up, z = 0 at the waterline.

Angles inside the code are radians in the right-handed FLU convention: ``yaw`` counter-clockwise
from east, ``roll`` about body x (positive = starboard down, the marine sign), ``pitch`` about
body y-left (positive = bow DOWN, the opposite of the marine sign). Marine degrees (heading
clockwise from north, pitch bow up positive) are converted with the helpers below.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from pyproj import Transformer

__all__ = ["LocalFrame", "Mount", "heading_deg_from_yaw", "marine_rotation", "mount_transform", "rotation_matrices",
           "yaw_from_heading_deg"]


@lru_cache(maxsize=32)
def _transformers(lat0: float, lon0: float) -> tuple[Transformer, Transformer]:
    proj = f"+proj=tmerc +lat_0={lat0!r} +lon_0={lon0!r} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs"
    forward = Transformer.from_crs("EPSG:4326", proj, always_xy=True)
    inverse = Transformer.from_crs(proj, "EPSG:4326", always_xy=True)
    return forward, inverse


class LocalFrame:
    """Local ENU metres about an origin.

    Parameters
    ----------
    lat0_deg, lon0_deg : float
        Origin latitude and longitude, degrees (WGS84).
    """

    def __init__(self, lat0_deg: float, lon0_deg: float):
        self.lat0_deg = float(lat0_deg)
        self.lon0_deg = float(lon0_deg)
        self._forward, self._inverse = _transformers(self.lat0_deg, self.lon0_deg)

    def to_local(self, lat_deg, lon_deg) -> tuple[np.ndarray, np.ndarray]:
        """(x east, y north) in metres, arrays of the inputs' shape, from lat/lon in degrees."""
        x, y = self._forward.transform(np.asarray(lon_deg, dtype=float), np.asarray(lat_deg, dtype=float))
        return np.asarray(x, dtype=float), np.asarray(y, dtype=float)

    #: The TDM's name of :meth:`to_local`: (east, north) metres.
    to_enu = to_local

    def to_geodetic(self, x_m, y_m) -> tuple[np.ndarray, np.ndarray]:
        """(lat, lon) in degrees from local (x east, y north) metres."""
        lon, lat = self._inverse.transform(np.asarray(x_m, dtype=float), np.asarray(y_m, dtype=float))
        return np.asarray(lat, dtype=float), np.asarray(lon, dtype=float)


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
    yaw_rad, pitch_rad, roll_rad : (N,) float (or scalars, or any shapes that broadcast)
        FLU Euler angles, radians (module docstring).

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


def marine_rotation(heading_deg, pitch_deg, roll_deg) -> np.ndarray:
    """(N, 3, 3) body-to-ENU rotations from marine angles in degrees (module docstring)."""
    return rotation_matrices(np.radians(90.0 - np.asarray(heading_deg, dtype=float)),
                             -np.radians(np.asarray(pitch_deg, dtype=float)),
                             np.radians(np.asarray(roll_deg, dtype=float)))


MOUNT_KEYS = ("x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg")


@dataclass(frozen=True)
class Mount:
    """A sensor's mounting on the own ship (body frame; marine angles, yaw clockwise from the bow).

    The keys of ``sensors.<name>.mount`` in a scenario (docs/formats.md).
    """

    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    roll_deg: float = 0.0
    pitch_deg: float = 0.0
    yaw_deg: float = 0.0

    @classmethod
    def from_dict(cls, d: dict | None) -> "Mount":
        """From a ``mount`` mapping; missing keys are 0."""
        d = d or {}
        return cls(**{k: float(d.get(k, 0.0)) for k in MOUNT_KEYS})

    def rotation(self) -> np.ndarray:
        """(3, 3) sensor-to-body rotation."""
        return rotation_matrices(np.radians(-self.yaw_deg), -np.radians(self.pitch_deg), np.radians(self.roll_deg))

    def translation_m(self) -> np.ndarray:
        """(3,) sensor origin in the body frame, metres."""
        return np.array([self.x_m, self.y_m, self.z_m])


def mount_transform(mount) -> tuple[np.ndarray, np.ndarray]:
    """Sensor-to-body rotation (3, 3) and translation (3,) of a mount (marine angles in, FLU out).

    ``mount`` is anything with the attributes of :class:`Mount` (raysim's scenario mounts too).
    """
    rotation = rotation_matrices(np.array([np.radians(-mount.yaw_deg)]), np.array([np.radians(-mount.pitch_deg)]),
                                 np.array([np.radians(mount.roll_deg)]))[0]
    return rotation, np.array([mount.x_m, mount.y_m, mount.z_m])
