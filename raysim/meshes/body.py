"""The body mesh: triangles in the body frame with one material each, and its waterline section.

Body frame (REP-103): x forward, y left, z up, metres, z = 0 at the waterline. The origin is
the object's reference point, the point placed at the object's scenario ``position``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import trimesh

from raysim.materials import MATERIALS

__all__ = ["BodyMesh", "waterline_section"]


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
        return np.concatenate([above, waterline_section(self.vertices_m, self.faces)])

    def extents_above_water_m(self) -> tuple[float, float, float]:
        """Size of the part above the waterline.

        Returns
        -------
        length_m, beam_m, height_m : float
            Extent along body x, extent along body y (m), and the highest z (m above the
            waterline). All zero if nothing is above water.
        """
        bounds = self._above_water_bounds_m
        if bounds is None:
            return 0.0, 0.0, 0.0
        low, high = bounds
        return float(high[0] - low[0]), float(high[1] - low[1]), float(high[2])

    def centre_above_water_m(self) -> tuple[float, float]:
        """Centre of the above-water part's extents in the body frame: the middle of the
        length x beam box of :meth:`extents_above_water_m`.

        Returns
        -------
        x_m, y_m : float
            Along body x and body y, m; (0, 0) if nothing is above water. Not the body origin
            in general: a mesh's origin may be at one end (a pier's landward end), and an
            iceberg's is where its generator started, not the middle of what stands above water.
        """
        bounds = self._above_water_bounds_m
        if bounds is None:
            return 0.0, 0.0
        middle = 0.5 * (bounds[0] + bounds[1])
        return float(middle[0]), float(middle[1])

    @cached_property
    def _above_water_bounds_m(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(3,) least and (3,) greatest coordinates of :meth:`above_water_points_m`, m; None if nothing is
        above water. Worked out once per mesh (the waterline section walks every triangle)."""
        points = self.above_water_points_m()
        if points.shape[0] == 0:
            return None
        return points.min(axis=0), points.max(axis=0)

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



def _unique_edges(faces: np.ndarray) -> np.ndarray:
    """(E, 2) int64 unique undirected edges of (F, 3) triangles."""
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    n = int(edges.max()) + 1 if edges.size else 1
    keys = np.unique(edges[:, 0] * n + edges[:, 1])  # 1-D unique is much faster than unique(axis=0)
    return np.stack([keys // n, keys % n], axis=1)


def waterline_section(vertices_m: np.ndarray, faces: np.ndarray) -> np.ndarray:
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
