"""Body meshes: procedural icebergs, ship hulls, buoys, piers, and user mesh files.

Body frame (REP-103): x forward, y left, z up, metres, z = 0 at the waterline. The origin is
the object's reference point, the point placed at the object's scenario ``position``: the
centre of the waterline footprint for floating objects, the landward end centre for a pier.

Every generator returns a :class:`BodyMesh`: float64 vertices, int64 triangles, and one
material index per triangle into :data:`raysim.materials.MATERIALS`. Generated meshes are
closed (watertight) per component and smooth: the ray engine (Embree) is up to five times
slower on spiky meshes (docs/reference.md section 7).

Default dimensions of generated ships are rules of thumb chosen to look plausible on sensors
(unverified, documented on each function); scenarios can override length, beam and height.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import trimesh

from raysim.materials import MATERIALS, material_index

__all__ = [
    "BodyMesh",
    "MeshError",
    "OWN_SHIP_MAX_HEIGHT_M",
    "ICEBERG_DRAFT_RATIO",
    "default_beam_m",
    "default_freeboard_m",
    "default_draft_m",
    "iceberg",
    "ship_hull",
    "own_ship",
    "buoy",
    "pier",
    "load_mesh",
]

# trimesh logs through the "trimesh" logger; without any handler Python's last-resort handler
# would print its warnings to stderr. A NullHandler (standard library practice) keeps loading
# silent unless the application configures logging itself.
logging.getLogger("trimesh").addHandler(logging.NullHandler())

#: Draft / height-above-water ratio of generated icebergs. Icebergs float with about 87-90 % of
#: their volume below water (ice 900-917 kg/m^3 in sea water 1025 kg/m^3); draft-to-height
#: ratios of about 3 to 5 are commonly quoted for icebergs (unverified). 3 is the default.
ICEBERG_DRAFT_RATIO = 3.0

#: Nothing of :func:`own_ship` rises above this height (m above the waterline), so that
#: sensors mounted at z >= 3 m are outside the own-ship mesh.
OWN_SHIP_MAX_HEIGHT_M = 2.5

# Smallest ship length (m) built in steel; shorter craft are GRP (rule of thumb, unverified).
STEEL_HULL_MIN_LENGTH_M = 15.0


class MeshError(ValueError):
    """A mesh file cannot be used: missing, unreadable, no triangles or non-finite vertices.

    Attributes
    ----------
    path : str
        The offending file.
    message : str
        What is wrong (also ``str(error)``).
    """

    def __init__(self, path: str | os.PathLike, message: str) -> None:
        super().__init__(message)
        self.path = str(path)
        self.message = message

    def __str__(self) -> str:
        return self.message


@dataclass(frozen=True, eq=False)
class BodyMesh:
    """A triangle mesh in the body frame with one material per triangle.

    Attributes
    ----------
    vertices_m : (V, 3) float64
        Vertex positions, body frame (x forward, y left, z up, z = 0 at the waterline), m.
    faces : (F, 3) int64
        Vertex indices of each triangle, counter-clockwise seen from outside.
    face_material : (F,) int16
        Index into :data:`raysim.materials.MATERIALS` for each triangle.
    name : str
        Human-readable name (generator or file stem).
    """

    vertices_m: np.ndarray
    faces: np.ndarray
    face_material: np.ndarray
    name: str

    def __post_init__(self) -> None:
        vertices = np.ascontiguousarray(self.vertices_m, dtype=np.float64)
        faces = np.ascontiguousarray(self.faces, dtype=np.int64)
        face_material = np.ascontiguousarray(self.face_material, dtype=np.int16)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"vertices_m must have shape (V, 3), got {vertices.shape}")
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f"faces must have shape (F, 3), got {faces.shape}")
        if face_material.shape != (faces.shape[0],):
            raise ValueError(
                f"face_material must have shape ({faces.shape[0]},), got {face_material.shape}"
            )
        if faces.size and (faces.min() < 0 or faces.max() >= vertices.shape[0]):
            raise ValueError("faces index vertices out of range")
        if face_material.size and (
            face_material.min() < 0 or face_material.max() >= len(MATERIALS)
        ):
            raise ValueError("face_material holds an unknown material index")
        object.__setattr__(self, "vertices_m", vertices)
        object.__setattr__(self, "faces", faces)
        object.__setattr__(self, "face_material", face_material)

    @property
    def n_triangles(self) -> int:
        """Number of triangles F."""
        return int(self.faces.shape[0])

    @property
    def bounding_radius_m(self) -> float:
        """Largest distance of a vertex from the body origin, m."""
        if self.vertices_m.shape[0] == 0:
            return 0.0
        return float(np.sqrt(np.max(np.einsum("ij,ij->i", self.vertices_m, self.vertices_m))))

    def above_water_points_m(self) -> np.ndarray:
        """Vertices with z >= 0 plus the waterline section (edges crossing z = 0).

        Returns
        -------
        (P, 3) float64
            Points of the mesh at or above the waterline, m. The part above water is
            approximated by these points: exact for extents of a triangle mesh, since the
            extreme points of the clipped surface are vertices or waterline crossings.
        """
        above = self.vertices_m[self.vertices_m[:, 2] >= 0.0]
        return np.concatenate([above, _waterline_section(self.vertices_m, self.faces)])

    def extents_above_water_m(self) -> tuple[float, float, float]:
        """Size of the part above the waterline.

        Returns
        -------
        length_m, beam_m, height_m : float
            Extent along body x, extent along body y (m), and the highest z (m above the
            waterline). All zero if nothing is above water.
        """
        points = self.above_water_points_m()
        if points.shape[0] == 0:
            return 0.0, 0.0, 0.0
        span = np.ptp(points, axis=0)
        return float(span[0]), float(span[1]), float(points[:, 2].max())

    def to_trimesh(self) -> trimesh.Trimesh:
        """A :class:`trimesh.Trimesh` with the same vertices and faces, in the same order.

        Created with ``process=False`` so that face order (and hence ``face_material``)
        is preserved; ``metadata["face_material"]`` holds a copy of the material indices.
        """
        mesh = trimesh.Trimesh(
            vertices=self.vertices_m.copy(), faces=self.faces.copy(), process=False
        )
        mesh.metadata["name"] = self.name
        mesh.metadata["face_material"] = self.face_material.copy()
        return mesh

    def to_scene(self) -> trimesh.Scene:
        """A :class:`trimesh.Scene` with one geometry per material, named after it.

        Exporting this scene (e.g. to GLB) keeps materials: :func:`load_mesh` gives the
        faces of a geometry named after a material that material.
        """
        scene = trimesh.Scene()
        for index in np.unique(self.face_material):
            faces = self.faces[self.face_material == index]
            used, local_faces = np.unique(faces, return_inverse=True)
            part = trimesh.Trimesh(
                vertices=self.vertices_m[used],
                faces=local_faces.reshape(-1, 3),
                process=False,
            )
            name = MATERIALS[int(index)].name
            scene.add_geometry(part, geom_name=name, node_name=name)
        return scene


# --------------------------------------------------------------------------------------------
# Small geometry helpers
# --------------------------------------------------------------------------------------------


def _unique_edges(faces: np.ndarray) -> np.ndarray:
    """(E, 2) int64 unique undirected edges of (F, 3) triangles."""
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    n = int(edges.max()) + 1 if edges.size else 1
    keys = np.unique(edges[:, 0] * n + edges[:, 1])  # 1-D unique is much faster than unique(axis=0)
    return np.stack([keys // n, keys % n], axis=1)


def _waterline_section(vertices_m: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(K, 3) points where mesh edges cross z = 0 strictly (z of the result is 0)."""
    if faces.shape[0] == 0:
        return np.zeros((0, 3))
    edges = _unique_edges(faces)
    p0 = vertices_m[edges[:, 0]]
    p1 = vertices_m[edges[:, 1]]
    z0, z1 = p0[:, 2], p1[:, 2]
    crossing = ((z0 < 0.0) & (z1 > 0.0)) | ((z0 > 0.0) & (z1 < 0.0))
    p0, p1, z0, z1 = p0[crossing], p1[crossing], z0[crossing], z1[crossing]
    t = (z0 / (z0 - z1))[:, None]
    points = p0 + t * (p1 - p0)
    points[:, 2] = 0.0
    return points


def _box(lower_m: tuple[float, float, float], upper_m: tuple[float, float, float]):
    """Closed axis-aligned box: ((8, 3) float64 vertices, (12, 3) int64 faces), outward wound."""
    mesh = trimesh.creation.box(bounds=np.array([lower_m, upper_m], dtype=np.float64))
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def _assemble(parts: list[tuple[np.ndarray, np.ndarray, str]], name: str) -> BodyMesh:
    """Concatenate closed parts ``(vertices (V,3), faces (F,3), material name)`` into a mesh."""
    vertices, faces, materials = [], [], []
    offset = 0
    for part_vertices, part_faces, material in parts:
        vertices.append(part_vertices)
        faces.append(part_faces + offset)
        materials.append(np.full(part_faces.shape[0], material_index(material), dtype=np.int16))
        offset += part_vertices.shape[0]
    return BodyMesh(
        vertices_m=np.concatenate(vertices),
        faces=np.concatenate(faces),
        face_material=np.concatenate(materials),
        name=name,
    )


def _require_positive(**values: float | None) -> None:
    """Raise ValueError unless every given (non-None) value is finite and > 0."""
    for key, value in values.items():
        if value is not None and not (np.isfinite(value) and value > 0.0):
            raise ValueError(f"{key} must be a finite number > 0, got {value!r}")


# --------------------------------------------------------------------------------------------
# Icebergs
# --------------------------------------------------------------------------------------------

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
    _require_positive(radius_m=radius_m, height_m=height_m, draft_ratio=draft_ratio)
    if subdivisions < 1:
        raise ValueError(f"subdivisions must be >= 1, got {subdivisions}")
    rng = np.random.default_rng(seed)
    directions, faces = _unit_icosphere(int(subdivisions))
    vertices = directions * np.exp(_smooth_log_radius(directions, rng))[:, None]
    vertices = _stretch_footprint(vertices, rng)
    vertices = _shear_top(vertices, rng)
    vertices[:, 2] = _scale_vertical(vertices[:, 2], height_m, draft_ratio * height_m)
    section = _waterline_section(vertices, faces)
    above = np.concatenate([vertices[vertices[:, 2] >= 0.0], section])
    horizontal_max = np.sqrt(np.max(above[:, 0] ** 2 + above[:, 1] ** 2))
    vertices[:, :2] *= radius_m / horizontal_max
    return _assemble([(vertices, faces.copy(), "ice")], name="iceberg")


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


# --------------------------------------------------------------------------------------------
# Ships
# --------------------------------------------------------------------------------------------


def default_beam_m(length_m: float) -> float:
    """Default beam of a generated ship, m: ``L / (3.2 + 0.03 L)`` (rule of thumb, unverified).

    10.9 m -> 3.1 m, 30 m -> 7.3 m, 100 m -> 16.1 m.
    """
    return float(length_m) / (3.2 + 0.03 * float(length_m))


def default_freeboard_m(length_m: float) -> float:
    """Default hull depth above the waterline (deck height), m: ``0.08 L + 1.0`` (unverified)."""
    return 0.08 * float(length_m) + 1.0


def default_draft_m(length_m: float) -> float:
    """Default draft (keel depth below the waterline), m: ``0.04 L + 0.4`` (unverified)."""
    return 0.04 * float(length_m) + 0.4


def _superstructure_height_m(length_m: float) -> float:
    """Default superstructure height above the deck, m: ``0.10 L + 1.2`` (unverified)."""
    return 0.10 * length_m + 1.2


def _mast_height_m(length_m: float) -> float:
    """Default mast height above the superstructure top, m: ``0.10 L + 0.5`` (unverified).

    With the defaults a 100 m ship's mast top is at 9.0 + 11.2 + 10.5 = 30.7 m above water.
    """
    return 0.10 * length_m + 0.5


def _deck_half_beam(s: np.ndarray) -> np.ndarray:
    """Deck half-beam as a fraction of beam/2 at stations s in [0, 1] (stern to bow).

    0.85 at the transom, full from s = 0.15 to 0.6, then a parabolic taper to a point at
    the bow. The outline is convex, so a convex hull keeps it.
    """
    stern = 0.85 + 0.15 * np.clip(s / 0.15, 0.0, 1.0)
    taper = 1.0 - np.clip((s - 0.6) / 0.4, 0.0, 1.0) ** 2
    return stern * taper


def _hull(length_m: float, beam_m: float, freeboard_m: float, draft_m: float):
    """Closed convex hull of a ship: ((V, 3) vertices, (F, 3) faces).

    Deck outline at z = freeboard from x = -L/2 (transom) to x = +L/2 (bow point), the
    waterline outline at z = 0 spans x in [-0.46 L, 0.46 L] (raked bow and overhanging
    transom, so the waterline footprint is centred on the origin), the keel at z = -draft
    spans x in [-0.40 L, 0.30 L] with a narrow flat bottom, and a forefoot rounds the stem.
    """
    half_l, half_b = 0.5 * length_m, 0.5 * beam_m
    s = np.linspace(0.0, 1.0, 17)
    deck = _outline(-half_l + length_m * s, half_b * _deck_half_beam(s), freeboard_m)
    waterline_x = -0.46 * length_m + 0.92 * length_m * s
    waterline = _outline(waterline_x, 0.95 * half_b * _deck_half_beam(s), 0.0)
    keel_x = np.array([-0.40, -0.1, 0.30]) * length_m
    keel = _outline(keel_x, np.full(3, 0.12 * half_b), -draft_m)
    transom_bottom = _outline(
        np.array([-0.45 * length_m]), np.array([0.5 * half_b]), -0.5 * draft_m
    )
    forefoot = np.array([[0.42 * length_m, 0.0, -0.35 * draft_m]])
    points = np.concatenate([deck, waterline, keel, transom_bottom, forefoot])
    hull = trimesh.convex.convex_hull(points)
    return np.asarray(hull.vertices, dtype=np.float64), np.asarray(hull.faces, dtype=np.int64)


def _outline(x: np.ndarray, half_beam: np.ndarray, z: float) -> np.ndarray:
    """(2N, 3) points at (x, +-half_beam, z); points with zero half-beam appear twice."""
    port = np.column_stack([x, half_beam, np.full_like(x, z)])
    starboard = port * np.array([1.0, -1.0, 1.0])
    return np.concatenate([port, starboard])


def ship_hull(
    length_m: float,
    beam_m: float | None = None,
    height_m: float | None = None,
    mast: bool = True,
) -> BodyMesh:
    """Generated ship of a given length: hull, superstructure and (optionally) a mast.

    Dimensions (rules of thumb, unverified):

    - beam ``default_beam_m(L) = L / (3.2 + 0.03 L)`` unless given;
    - hull: convex hull with a pointed, raked bow and a transom stern; deck (freeboard)
      ``0.08 L + 1.0`` m above water, draft ``0.04 L + 0.4`` m;
    - superstructure of two tiers (deckhouse 0.8 B wide, bridge 0.95 B wide on top), total
      height ``0.10 L + 1.2`` m above the deck; aft of midships (centre near x = -0.2 L) for
      L >= 15 m, slightly forward of midships (a wheelhouse) for smaller craft;
    - mast: a thin square box (side ``0.005 L + 0.1`` m) on the bridge, ``0.10 L + 0.5`` m
      tall (100 m ship: mast top 30.7 m above water).

    If ``height_m`` is given, the superstructure and mast heights are scaled so that the
    highest point is at ``height_m`` (the freeboard is reduced to ``height_m / 2`` if it
    would otherwise exceed that).

    Parameters
    ----------
    length_m : float
        Length overall, m (the hull spans x in [-L/2, L/2]).
    beam_m : float, optional
        Beam, m; default ``default_beam_m(length_m)``.
    height_m : float, optional
        Overall height above the waterline, m; default from the rules above.
    mast : bool, optional
        Add the mast (material ``aluminium``).

    Returns
    -------
    BodyMesh
        Separate closed components: hull, deckhouse, bridge[, mast]. Hull and superstructure
        are ``steel_painted`` for L >= 15 m, ``grp`` for smaller craft.
    """
    beam_m = default_beam_m(length_m) if beam_m is None else beam_m
    _require_positive(length_m=length_m, beam_m=beam_m, height_m=height_m)
    freeboard_m = default_freeboard_m(length_m)
    super_m = _superstructure_height_m(length_m)
    mast_m = _mast_height_m(length_m) if mast else 0.0
    if height_m is not None:
        freeboard_m = min(freeboard_m, 0.5 * height_m)
        scale = (height_m - freeboard_m) / (super_m + mast_m)
        super_m, mast_m = super_m * scale, mast_m * scale
    body = "steel_painted" if length_m >= STEEL_HULL_MIN_LENGTH_M else "grp"
    hull_v, hull_f = _hull(length_m, beam_m, freeboard_m, default_draft_m(length_m))
    parts = [(hull_v, hull_f, body)]
    centre_x = -0.2 * length_m if length_m >= STEEL_HULL_MIN_LENGTH_M else 0.05 * length_m
    parts += _superstructure(length_m, beam_m, centre_x, freeboard_m, super_m, body)
    if mast:
        parts.append(_mast(length_m, centre_x, freeboard_m + super_m, mast_m))
    return _assemble(parts, name="ship")


def _superstructure(
    length_m: float, beam_m: float, centre_x: float, deck_z: float, height_m: float, material: str
) -> list[tuple[np.ndarray, np.ndarray, str]]:
    """Deckhouse (0.20 L long, 0.8 B wide, 60 % of height) and bridge (0.12 L, 0.95 B) boxes.

    Both boxes reach below the level they stand on (into the hull or the deckhouse) so that
    no coplanar faces meet and no gap is visible.
    """
    house_top = deck_z + 0.6 * height_m
    house = _box(
        (centre_x - 0.10 * length_m, -0.40 * beam_m, 0.5 * deck_z),
        (centre_x + 0.10 * length_m, 0.40 * beam_m, house_top),
    )
    bridge = _box(
        (centre_x - 0.06 * length_m, -0.475 * beam_m, house_top - 0.2 * height_m),
        (centre_x + 0.06 * length_m, 0.475 * beam_m, deck_z + height_m),
    )
    return [(*house, material), (*bridge, material)]


def _mast(
    length_m: float, centre_x: float, base_z: float, height_m: float
) -> tuple[np.ndarray, np.ndarray, str]:
    """Thin square aluminium box from 0.25 m (or a quarter of its height) below ``base_z``."""
    half_w = 0.5 * (0.005 * length_m + 0.1)
    embed = min(0.25, 0.25 * height_m)
    vertices, faces = _box(
        (centre_x - half_w, -half_w, base_z - embed), (centre_x + half_w, half_w, base_z + height_m)
    )
    return vertices, faces, "aluminium"


def own_ship(length_m: float, beam_m: float) -> BodyMesh:
    """Own ship: a small GRP workboat hull with a low wheelhouse, nothing above 2.5 m.

    The hull is the :func:`ship_hull` hull with freeboard ``clip(0.1 L, 0.4, 1.2)`` m and
    draft ``0.04 L + 0.4`` m; a wheelhouse box (0.3 L long, 0.7 B wide, x in
    [-0.15 L, 0.15 L]) reaches 2.4 m above water. There is no mast: everything stays below
    :data:`OWN_SHIP_MAX_HEIGHT_M` = 2.5 m, so sensors mounted at z >= 3 m are outside the
    mesh (the real sensor mast is not modelled). Low LiDAR beams do see the deck and
    wheelhouse roof, as on the real boat.

    Parameters
    ----------
    length_m : float
        Length overall, m (Odin: 10.9).
    beam_m : float
        Beam, m (Odin: 3.5).

    Returns
    -------
    BodyMesh
        Two closed components (hull, wheelhouse), all ``grp``; ``name`` ``"own_ship"``.
    """
    _require_positive(length_m=length_m, beam_m=beam_m)
    freeboard_m = float(np.clip(0.1 * length_m, 0.4, 1.2))
    wheelhouse_top_m = OWN_SHIP_MAX_HEIGHT_M - 0.1
    hull_v, hull_f = _hull(length_m, beam_m, freeboard_m, default_draft_m(length_m))
    house = _box(
        (-0.15 * length_m, -0.35 * beam_m, 0.5 * freeboard_m),
        (0.15 * length_m, 0.35 * beam_m, wheelhouse_top_m),
    )
    return _assemble([(hull_v, hull_f, "grp"), (*house, "grp")], name="own_ship")


# --------------------------------------------------------------------------------------------
# Buoy and pier
# --------------------------------------------------------------------------------------------


def _revolve_mesh(
    profile_rz_m: np.ndarray, segment_material: list[str], n_around: int, name: str
) -> BodyMesh:
    """Closed surface of revolution about the z axis as one watertight :class:`BodyMesh`.

    Parameters
    ----------
    profile_rz_m : (K, 2) float64
        (radius, z) from the bottom pole (radius 0) to the top pole (radius 0), m; the
        K - 2 interior points must have radius > 0.
    segment_material : list of str
        Material of each of the K - 1 profile segments (bottom cap first).
    n_around : int
        Number of sectors around the axis.
    name : str
        Mesh name.
    """
    rings_rz = profile_rz_m[1:-1]
    n_rings = rings_rz.shape[0]
    theta = np.linspace(0.0, 2.0 * np.pi, n_around, endpoint=False)
    ring_xyz = np.stack(
        [
            rings_rz[:, :1] * np.cos(theta)[None, :],
            rings_rz[:, :1] * np.sin(theta)[None, :],
            np.repeat(rings_rz[:, 1:2], n_around, axis=1),
        ],
        axis=-1,
    ).reshape(-1, 3)
    bottom, top = 0, 1 + n_rings * n_around
    vertices = np.concatenate(
        [[[0.0, 0.0, profile_rz_m[0, 1]]], ring_xyz, [[0.0, 0.0, profile_rz_m[-1, 1]]]]
    )
    j = np.arange(n_around)
    j_next = (j + 1) % n_around
    first, last = 1, 1 + (n_rings - 1) * n_around
    faces = [np.column_stack([np.full(n_around, bottom), first + j_next, first + j])]
    for k in range(n_rings - 1):  # loop over profile segments, not vertices
        a, b = 1 + k * n_around + j, 1 + k * n_around + j_next
        c, d = b + n_around, a + n_around
        faces.append(np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]))
    faces.append(np.column_stack([last + j, last + j_next, np.full(n_around, top)]))
    materials = [
        np.full(f.shape[0], material_index(m), dtype=np.int16)
        for f, m in zip(faces, segment_material, strict=True)
    ]
    return BodyMesh(vertices, np.concatenate(faces), np.concatenate(materials), name)


# Buoy profile (radius m, z m) from the bottom pole to the top pole and segment materials:
# a 1 m diameter can buoy, 1 m below water, a retro-reflective band from 1.0 to 1.4 m and a
# conical top to 2.5 m (shape after IALA can/spar buoys; dimensions unverified).
_BUOY_PROFILE_RZ_M = np.array(
    [
        [0.0, -1.0],
        [0.30, -1.0],
        [0.50, -0.6],
        [0.50, 1.0],
        [0.50, 1.4],
        [0.50, 1.5],
        [0.12, 2.3],
        [0.12, 2.5],
        [0.0, 2.5],
    ]
)
_BUOY_SEGMENT_MATERIALS = [
    "steel_painted",  # bottom cap
    "steel_painted",  # bilge
    "steel_painted",  # body
    "retroreflector",  # band, z 1.0-1.4 m
    "steel_painted",  # shoulder
    "steel_painted",  # cone
    "steel_painted",  # top mark stem
    "steel_painted",  # top cap
]


def buoy(n_around: int = 24) -> BodyMesh:
    """Navigation buoy: 1 m diameter, 2.5 m above and 1 m below water, retro-reflective band.

    A closed surface of revolution (steel body and conical top) with a band of material
    ``retroreflector`` from z = 1.0 m to 1.4 m.

    Parameters
    ----------
    n_around : int, optional
        Sectors around the axis (24 gives 336 triangles).

    Returns
    -------
    BodyMesh
        One watertight component; ``name`` ``"buoy"``.
    """
    if n_around < 3:
        raise ValueError(f"n_around must be >= 3, got {n_around}")
    return _revolve_mesh(_BUOY_PROFILE_RZ_M, _BUOY_SEGMENT_MATERIALS, int(n_around), "buoy")


# Pier piles: spacing along the pier, square side, and depth of their foot (m, unverified).
_PIER_PILE_SPACING_M = 6.0
_PIER_PILE_SIDE_M = 0.5
_PIER_PILE_FOOT_Z_M = -3.0


def _pier_station(
    x: float, side: float, half_w: float, deck_height_m: float, slab_m: float, fenders: bool
) -> list[tuple[np.ndarray, np.ndarray, str]]:
    """Pile (and fender) boxes at station ``x`` on one side (``side`` = +1 port, -1 starboard)."""
    half_pile = 0.5 * _PIER_PILE_SIDE_M
    y = side * (half_w - 0.5)
    pile = _box(
        (x - half_pile, y - half_pile, _PIER_PILE_FOOT_Z_M),
        (x + half_pile, y + half_pile, deck_height_m - 0.5 * slab_m),
    )
    parts = [(*pile, "concrete")]
    if fenders:
        inner, outer = side * (half_w - 0.05), side * (half_w + 0.3)
        fender = _box(
            (x - 0.2, min(inner, outer), min(0.3, 0.5 * deck_height_m)),
            (x + 0.2, max(inner, outer), deck_height_m),
        )
        parts.append((*fender, "rubber"))
    return parts


def pier(
    length_m: float = 60.0,
    width_m: float = 8.0,
    deck_height_m: float = 2.0,
    fenders: bool = True,
) -> BodyMesh:
    """Concrete pier: a deck slab on square piles, with rubber fenders along both sides.

    The origin is at the centre of the landward end; the pier extends along +x to
    ``length_m``. Deck: top at ``deck_height_m``, thickness ``min(0.6, deck_height_m / 2)`` m.
    Piles: 0.5 m square, every 6 m (at least two rows), 0.5 m in from each side, from 3 m
    below water into the deck. Fenders: 0.3 m thick, 0.4 m wide rubber blocks on the outer
    side faces at each pile station, from 0.3 m above water to the deck top.

    Parameters
    ----------
    length_m, width_m, deck_height_m : float, optional
        Pier length along x, width along y, deck top above the waterline, m.
    fenders : bool, optional
        Add the rubber fenders.

    Returns
    -------
    BodyMesh
        Closed boxes; deck and piles ``concrete``, fenders ``rubber``; ``name`` ``"pier"``.
    """
    _require_positive(length_m=length_m, width_m=width_m, deck_height_m=deck_height_m)
    half_w = 0.5 * width_m
    slab_m = min(0.6, 0.5 * deck_height_m)
    deck = _box((0.0, -half_w, deck_height_m - slab_m), (length_m, half_w, deck_height_m))
    parts = [(*deck, "concrete")]
    n_stations = max(2, int(round(length_m / _PIER_PILE_SPACING_M)))
    station_x = (np.arange(n_stations) + 0.5) * (length_m / n_stations)
    for x in station_x:  # loop over pile stations (objects), not vertices
        for side in (-1.0, 1.0):
            parts.extend(_pier_station(x, side, half_w, deck_height_m, slab_m, fenders))
    return _assemble(parts, name="pier")


# --------------------------------------------------------------------------------------------
# Loading user meshes
# --------------------------------------------------------------------------------------------


def load_mesh(path: str | os.PathLike, material: str = "steel_painted") -> BodyMesh:
    """Load a mesh file (anything trimesh reads: OBJ, STL, PLY, GLB/GLTF, ...).

    The file must already be in the body frame (x forward, y left, z up, z = 0 at the
    waterline, metres); no axis conversion is applied (note that glTF viewers assume y up).
    Scenes are flattened with their node transforms. A scene geometry whose name is a
    material name of :mod:`raysim.materials` (as written by :meth:`BodyMesh.to_scene`) gets
    that material; every other triangle gets ``material``. Duplicate vertices are merged
    (face order is kept). Nothing is printed.

    Parameters
    ----------
    path : str or os.PathLike
        Mesh file.
    material : str, optional
        Material of triangles without a material-named geometry.

    Returns
    -------
    BodyMesh
        ``name`` is the file stem.

    Raises
    ------
    MeshError
        The file is missing, cannot be parsed, holds no triangles or has non-finite vertices.
    KeyError
        ``material`` is not a known material name.
    """
    default_index = material_index(material)
    path = Path(path)
    if not path.is_file():
        raise MeshError(path, f"{path}: mesh file not found")
    try:
        loaded = trimesh.load(path, process=False)
    except Exception as exc:  # trimesh raises many types for bad files
        detail = " ".join(str(exc).split())  # one line, for the CLI's one-line errors
        raise MeshError(path, f"{path}: cannot read mesh ({type(exc).__name__}: {detail})") from exc
    parts = _mesh_parts(loaded, default_index)
    if not parts:
        raise MeshError(path, f"{path}: no triangles in mesh file")
    vertices = np.concatenate([p[0] for p in parts])
    offsets = np.cumsum([0] + [p[0].shape[0] for p in parts[:-1]])
    faces = np.concatenate([p[1] + off for p, off in zip(parts, offsets, strict=True)])
    face_material = np.concatenate([np.full(p[1].shape[0], p[2], np.int16) for p in parts])
    if not np.all(np.isfinite(vertices)):
        raise MeshError(path, f"{path}: mesh has non-finite (NaN or infinite) vertex coordinates")
    if faces.min() < 0 or faces.max() >= vertices.shape[0]:
        raise MeshError(path, f"{path}: mesh faces reference missing vertices")
    merged = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
    merged.merge_vertices()
    return BodyMesh(
        np.asarray(merged.vertices), np.asarray(merged.faces), face_material, name=path.stem
    )


def _mesh_parts(loaded: object, default_index: int) -> list[tuple[np.ndarray, np.ndarray, int]]:
    """Triangle parts ``(vertices (V,3), faces (F,3), material index)`` of a loaded object."""
    if isinstance(loaded, trimesh.Trimesh):
        part = _triangles(loaded, np.eye(4))
        return [(*part, default_index)] if part is not None else []
    if not isinstance(loaded, trimesh.Scene):
        return []
    names = {m.name: i for i, m in enumerate(MATERIALS)}
    parts = []
    for node in loaded.graph.nodes_geometry:
        transform, geometry_name = loaded.graph[node]
        geometry = loaded.geometry.get(geometry_name)
        if not isinstance(geometry, trimesh.Trimesh):
            continue
        part = _triangles(geometry, transform)
        if part is not None:
            parts.append((*part, names.get(geometry_name, default_index)))
    return parts


def _triangles(
    mesh: trimesh.Trimesh, transform: np.ndarray
) -> tuple[np.ndarray, np.ndarray] | None:
    """((V, 3) float64 transformed vertices, (F, 3) int64 faces) or None if no triangles."""
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    if faces.shape[0] == 0:
        return None
    vertices = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
    transform = np.asarray(transform, dtype=np.float64)
    return vertices @ transform[:3, :3].T + transform[:3, 3], faces
