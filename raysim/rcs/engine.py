"""Monostatic radar cross-section of a triangle mesh by SBR + PO (far field, plane wave).

See :mod:`raysim.rcs.sbr` (ray tubes) and :mod:`raysim.rcs.po` (PO integration) and
docs/radar.md "Radar cross-section: shooting and bouncing rays, ``raysim rcs``".
Source: H. Ling, R.-C. Chou and S.-W. Lee, "Shooting and bouncing rays: calculating the RCS
of an arbitrarily shaped cavity", IEEE Trans. Antennas Propag. 37(2), 194-205, 1989.
"""

from __future__ import annotations

import math

import numpy as np

from raysim.rcs.po import scattered_field
from raysim.rcs.sbr import launch_grid, trace
from raysim.rcs.sea import SeaSurface

__all__ = ["C_M_S", "POLARISATIONS", "radar_frame", "monostatic_rcs", "default_spacing_m", "cull_under_sea"]

C_M_S = 299_792_458.0
POLARISATIONS = ("HH", "VV", "HV", "VH")


def radar_frame(aspect_deg: float, elevation_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit vectors towards the radar ``s``, horizontal ``h`` and vertical ``v`` polarisation, (3,) each.

    Aspect 0 puts the radar on the body's +x axis; the aspect increases clockwise seen from
    above (90 deg: the radar on the -y, starboard, side). Elevation is the radar's angle above
    the body's xy plane.
    """
    a, el = math.radians(aspect_deg), math.radians(elevation_deg)
    s = np.array([math.cos(el) * math.cos(a), -math.cos(el) * math.sin(a), math.sin(el)])
    h = np.cross([0.0, 0.0, 1.0], s)
    h /= np.linalg.norm(h)
    v = np.cross(s, h)
    return s, h, v


def default_spacing_m(vertices_m: np.ndarray, wavelength_m: float, max_tubes: int, sea: bool) -> float:
    """Tube side: lambda / 4, widened so that at most about ``max_tubes`` tubes cover the target, m."""
    extent = vertices_m.max(axis=0) - vertices_m.min(axis=0)
    if sea:
        extent = extent * np.array([1.0, 1.0, 2.0])
    cross = float(np.sort(extent)[-1] * np.sort(extent)[-2])  # upper bound of the projected area
    return max(wavelength_m / 4.0, math.sqrt(cross / max_tubes))


def cull_under_sea(vertices_m: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Faces (K, 3) with at least one vertex above z = 0 (the part under the sea is ignored)."""
    return faces[(vertices_m[faces][:, :, 2] > 0.0).any(axis=1)]


def monostatic_rcs(
    vertices_m: np.ndarray, faces: np.ndarray, aspect_deg: float, elevation_deg: float = 0.0,
    frequency_hz: float = 9.41e9, polarisation: str = "HH", gamma: float = 1.0, sea: bool = False,
    n_bounces: int = 3, spacing_m: float | None = None, max_tubes: int = 200_000, sea_state: int = 3,
    sea_conductor: bool = False, plating_rms_m: float = 0.0,
) -> float:
    """Monostatic RCS of a mesh seen from one direction, m^2.

    Parameters
    ----------
    vertices_m : (V, 3) float64
        Vertices, body frame (x forward, y left, z up), m.
    faces : (F, 3) int
        Triangles.
    aspect_deg, elevation_deg : float
        Radar direction (see :func:`radar_frame`), deg.
    frequency_hz : float
        Radar frequency, Hz.
    polarisation : str
        Transmit-receive: ``HH``, ``VV``, ``HV`` or ``VH``.
    gamma : float
        Amplitude reflection coefficient of the mesh material per bounce (1: perfect conductor).
    sea : bool
        Sea at z = 0 (faces wholly under it are dropped): Fresnel reflection of sea water times
        the rough-sea specular reduction (:class:`raysim.rcs.sea.SeaSurface`).
    n_bounces : int
        Maximum hits per ray tube (mesh and sea).
    spacing_m : float, optional
        Ray-tube side, m; default :func:`default_spacing_m`.
    max_tubes : int
        Tube budget for the default spacing.
    sea_state : int
        Douglas sea state 0..6 of the sea (roughness; 0: flat).
    sea_conductor : bool
        The sea is a flat perfect conductor instead (an upper bound).
    plating_rms_m : float
        rms unfairness (waviness) of the mesh's plating, m; reduces each mesh reflection to its
        coherent part (:func:`raysim.rcs.sbr.trace`, :func:`raysim.rcs.po.scattered_field`).

    Returns
    -------
    float
        sigma, m^2.
    """
    wavelength = C_M_S / frequency_hz
    k = 2.0 * math.pi / wavelength
    if sea:
        faces = cull_under_sea(vertices_m, faces)
        if len(faces) == 0:
            return 0.0
    spacing = default_spacing_m(vertices_m, wavelength, max_tubes, sea) if spacing_m is None else spacing_m
    s, h, v = radar_frame(aspect_deg, elevation_deg)
    pol = {"H": h, "V": v}
    tx, rx = pol[polarisation[0]], pol[polarisation[1]]
    used = vertices_m[np.unique(faces)]
    origins, offset, centre = launch_grid(used, s, h, v, spacing, mirror_sea=sea)
    surface = SeaSurface(sea_state, frequency_hz / 1e9, sea_conductor) if sea else None
    k_rms = k * plating_rms_m
    bounces = trace(vertices_m, faces, origins, -s, tx, (h, v), gamma, n_bounces, surface, k_rms)
    field = scattered_field(bounces, k, spacing, gamma, s, centre, offset, surface, k_rms)
    return float(4.0 * math.pi * abs(np.dot(rx, field)) ** 2)
