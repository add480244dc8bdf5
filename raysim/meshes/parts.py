"""Building a :class:`BodyMesh` from closed parts: boxes, concatenation with materials, checks."""

from __future__ import annotations

import numpy as np
import trimesh

from raysim.materials import material_index
from raysim.meshes.body import BodyMesh

__all__ = ["Part", "assemble", "box", "require_positive"]

#: A closed part: (V, 3) float64 vertices, (F, 3) int64 faces, material name.
Part = tuple[np.ndarray, np.ndarray, str]


def box(
    lower_m: tuple[float, float, float], upper_m: tuple[float, float, float]
) -> tuple[np.ndarray, np.ndarray]:
    """Closed axis-aligned box: ((8, 3) float64 vertices, (12, 3) int64 faces), outward wound."""
    mesh = trimesh.creation.box(bounds=np.array([lower_m, upper_m], dtype=np.float64))
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def assemble(parts: list[Part], name: str) -> BodyMesh:
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


def require_positive(**values: float | None) -> None:
    """Raise ValueError unless every given (non-None) value is finite and > 0."""
    for key, value in values.items():
        if value is not None and not (np.isfinite(value) and value > 0.0):
            raise ValueError(f"{key} must be a finite number > 0, got {value!r}")
