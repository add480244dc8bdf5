"""Seeded procedural icebergs: smooth, watertight, irregular, with their underwater part."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import trimesh

from raysim.meshes.body import BodyMesh, waterline_section
from raysim.meshes.parts import assemble, require_positive

__all__ = ["ICEBERG_DRAFT_RATIO", "iceberg"]

#: Draft / height-above-water ratio of generated icebergs. Icebergs float with about 87-90 % of
#: their volume below water (ice 900-917 kg/m^3 in sea water 1025 kg/m^3); draft-to-height
#: ratios of about 3 to 5 are commonly quoted for icebergs (unverified). 3 is the default.
ICEBERG_DRAFT_RATIO = 3.0

# Number of random plane waves summed into the radial field of an iceberg.
_ICEBERG_WAVES = 7
# Spatial frequency of each wave, cycles per unit length on the unit sphere (diameter 2), so
# 0.6-1.5 cycles across the berg: lumps, no spikes.
_ICEBERG_FREQ_RANGE = (0.3, 0.75)
# Standard deviation of log(radius): exp(0.17 z), z ~ +-2 gives radii about 0.71-1.40,
# i.e. +-30-40 % lumps.
_ICEBERG_LOG_RADIUS_STD = 0.17
# Largest horizontal shear of the above-water part per unit height: moves the summit off
# centre (a lopsided, tilted top) by up to this fraction of the height.
_ICEBERG_MAX_SHEAR = 0.35
# Width (unit-sphere units) of the band about the waterline over which the different
# vertical scales above and below water blend (about two icosphere edges at 4 subdivisions).
_ICEBERG_WATERLINE_BLEND = 0.08
# Horizontal aspect ratio (short/long axis) range of the berg's footprint (unverified).
_ICEBERG_ASPECT_RANGE = (0.65, 1.0)


@lru_cache(maxsize=8)
def _unit_icosphere(subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    """Read-only ((V, 3) unit vertices, (F, 3) faces) of a trimesh icosphere."""
    sphere = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    vertices = np.asarray(sphere.vertices, dtype=np.float64)
    vertices = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    faces = np.asarray(sphere.faces, dtype=np.int64)
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return vertices, faces


def _smooth_log_radius(directions: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Smooth random field on the unit sphere: a sum of low-frequency 3D cosines.

    Parameters
    ----------
    directions : (V, 3) float64
        Unit vectors.
    rng : numpy.random.Generator
        Source of the wave directions, frequencies, phases and weights.

    Returns
    -------
    (V,) float64
        Field normalised to zero mean and standard deviation ``_ICEBERG_LOG_RADIUS_STD``.
    """
    wave_dirs = rng.normal(size=(_ICEBERG_WAVES, 3))
    wave_dirs /= np.linalg.norm(wave_dirs, axis=1, keepdims=True)
    freq = rng.uniform(*_ICEBERG_FREQ_RANGE, size=_ICEBERG_WAVES)
    phase = rng.uniform(0.0, 2.0 * np.pi, size=_ICEBERG_WAVES)
    weight = rng.uniform(0.5, 1.0, size=_ICEBERG_WAVES)
    field = np.cos(2.0 * np.pi * (directions @ (wave_dirs * freq[:, None]).T) + phase) @ weight
    field -= field.mean()
    std = field.std()
    return field * (_ICEBERG_LOG_RADIUS_STD / std) if std > 0 else field


def iceberg(
    radius_m: float,
    height_m: float,
    seed: int,
    draft_ratio: float = ICEBERG_DRAFT_RATIO,
    subdivisions: int = 4,
) -> BodyMesh:
    """Seeded procedural iceberg: smooth, watertight, irregular, with its underwater part.

    A unit icosphere is displaced radially by ``exp(f(u))`` where ``f`` is a sum of a few
    random low-frequency 3D cosines of the unit direction ``u`` (no per-vertex noise, so
    the surface is smooth, and radial displacement keeps it star-shaped about the origin:
    watertight and free of self-intersections). The smooth one-to-one maps that follow
    keep it closed and, for moderate radius/height ratios, star-shaped (checked in the
    tests; very flat or very tall bergs get sharper rims or keels). The footprint is then stretched to a random aspect ratio
    in a random direction, the part above water is sheared sideways (summit off centre by up
    to 35 % of its height), the part above z = 0 is scaled to ``height_m`` and the part below
    to the draft ``draft_ratio * height_m``, and x, y are scaled so that the largest
    horizontal distance from the z axis of the above-water part (vertices with z >= 0 and
    the waterline section) is exactly ``radius_m``.

    Parameters
    ----------
    radius_m : float
        Largest horizontal distance of the above-water part from the z axis, m.
    height_m : float
        Highest point above the waterline, m.
    seed : int
        Seed of :func:`numpy.random.default_rng`; same seed, identical mesh.
    draft_ratio : float, optional
        Draft / height ratio (default :data:`ICEBERG_DRAFT_RATIO` = 3, unverified).
    subdivisions : int, optional
        Icosphere subdivisions: 4 gives 2562 vertices and 5120 triangles.

    Returns
    -------
    BodyMesh
        All faces of material ``ice``; ``name`` is ``"iceberg"``.
    """
    require_positive(radius_m=radius_m, height_m=height_m, draft_ratio=draft_ratio)
    if subdivisions < 1:
        raise ValueError(f"subdivisions must be >= 1, got {subdivisions}")
    rng = np.random.default_rng(seed)
    directions, faces = _unit_icosphere(int(subdivisions))
    vertices = directions * np.exp(_smooth_log_radius(directions, rng))[:, None]
    vertices = _stretch_footprint(vertices, rng)
    vertices = _shear_top(vertices, rng)
    vertices[:, 2] = _scale_vertical(vertices[:, 2], height_m, draft_ratio * height_m)
    section = waterline_section(vertices, faces)
    above = np.concatenate([vertices[vertices[:, 2] >= 0.0], section])
    horizontal_max = np.sqrt(np.max(above[:, 0] ** 2 + above[:, 1] ** 2))
    vertices[:, :2] *= radius_m / horizontal_max
    return assemble([(vertices, faces.copy(), "ice")], name="iceberg")


def _stretch_footprint(vertices: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Squash (V, 3) vertices along a random horizontal direction (linear, shape-preserving)."""
    aspect = rng.uniform(*_ICEBERG_ASPECT_RANGE)
    yaw_rad = rng.uniform(0.0, np.pi)
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    squash = np.diag([1.0, aspect, 1.0])
    return vertices @ (rotation @ squash @ rotation.T).T


def _soft_positive_part(z: np.ndarray) -> np.ndarray:
    """Smooth version of ``max(z, 0)`` on the unit sphere: ``w (log(1 + e^(z/w)) - log 2)``.

    Zero at z = 0, slope 1/2 there, ``z - w log 2`` for z >> w and ``-w log 2`` for
    z << -w, with w = ``_ICEBERG_WATERLINE_BLEND`` (about two icosphere edges at 4
    subdivisions). Used so that the maps applied above and below the waterline blend
    smoothly instead of leaving a crease along z = 0.
    """
    w = _ICEBERG_WATERLINE_BLEND
    return w * (np.logaddexp(0.0, z / w) - np.log(2.0))


def _shear_top(vertices: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Shift (V, 3) vertices horizontally by ``k * soft_max(z, 0)`` in a random direction.

    Moves the summit off centre (a lopsided, tilted top) and leaves the underwater part
    almost untouched. The map is smooth and one-to-one (z is unchanged).
    """
    shear = rng.uniform(0.0, _ICEBERG_MAX_SHEAR)
    direction_rad = rng.uniform(0.0, 2.0 * np.pi)
    lift = _soft_positive_part(vertices[:, 2])
    sheared = vertices.copy()
    sheared[:, 0] += shear * np.cos(direction_rad) * lift
    sheared[:, 1] += shear * np.sin(direction_rad) * lift
    return sheared


def _scale_vertical(z: np.ndarray, height_m: float, draft_m: float) -> np.ndarray:
    """Map (V,) z smoothly and monotonically so that max z = height_m, min z = -draft_m.

    ``z' = s_above P(z) + s_below (z - P(z))`` with ``P`` = :func:`_soft_positive_part`:
    the local vertical scale ``dz'/dz`` blends from ``s_below`` under water to
    ``s_above`` above it over a narrow band, with z' = 0 at z = 0. The two scales solve
    the 2 x 2 linear system given by the top and bottom vertices, exactly.
    """
    top, bottom = z.max(), z.min()
    p_top, p_bottom = _soft_positive_part(np.array([top, bottom]))
    system = np.array([[p_top, top - p_top], [p_bottom, bottom - p_bottom]])
    s_above, s_below = np.linalg.solve(system, np.array([height_m, -draft_m]))
    if not (s_above > 0.0 and s_below > 0.0):  # degenerate shapes: fall back to piecewise scaling
        return np.where(z >= 0.0, z * (height_m / top), z * (draft_m / -bottom))
    p = _soft_positive_part(z)
    return s_above * p + s_below * (z - p)
