"""Loading user mesh files (anything trimesh reads) into a :class:`BodyMesh`."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import trimesh

from raysim.materials import MATERIALS, material_index
from raysim.meshes.body import BodyMesh

__all__ = ["MeshError", "load_mesh"]


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
