"""The scenario's ``land`` entries as meshes of the world: one object of kind ``land`` per entry.

Each entry's polygons (:func:`raysim.land.geojson.read_land_file`) are taken into the world's local
frame (:func:`raysim.land.mesh.to_local`), meshed (:func:`raysim.land.mesh.land_mesh`) and joined
into one :class:`raysim.meshes.BodyMesh` whose body frame IS the local frame (ENU metres; the
object stands at the origin with yaw 0), each face with its polygon's material.

For the ray engine the mesh is cut into tiles (:func:`land_tiles`): its triangles subdivided to at most
:data:`TILE_MAX_EDGE_M` (a flat top's earcut triangles can be kilometres long) and grouped by their
centroid on a :data:`TILE_M` grid, each tile a geometry of its own with its own bounding sphere, so
that the engine's culling keeps a LiDAR's 100 m rays off a coast a kilometre away (one geometry the
size of the coast would hold every ray of the scene inside its bounding sphere).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import trimesh

from raysim.land.geojson import read_land_file
from raysim.land.mesh import land_mesh, to_local
from raysim.materials import material_index
from raysim.meshes import BodyMesh


#: Side of the square tiles the ray engine gets a land mesh in, m.
TILE_M = 250.0
#: Longest triangle edge in a tile, m (longer ones are subdivided first).
TILE_MAX_EDGE_M = 100.0


@dataclass(frozen=True)
class LandBody:
    """One ``land`` entry as a mesh.

    Attributes
    ----------
    name : str
        The entry's name.
    mesh : BodyMesh
        Every polygon of the entry, local ENU metres (z up from the sea).
    key_path : str
        ``land[i]``, for messages.
    """

    name: str
    mesh: BodyMesh
    key_path: str


def land_bodies(scenario, frame) -> list[LandBody]:
    """The meshes of every ``land`` entry of a scenario, in file order.

    Parameters
    ----------
    scenario : raysim.scenario.Scenario
        Its ``land`` entries (GeoJSON files already checked by :func:`raysim.scenario.load_scenario`).
    frame : raysim.geodesy.LocalFrame
        The world's local frame.

    Returns
    -------
    list of LandBody
    """
    bodies = []
    for i, entry in enumerate(scenario.land):
        vertices, faces, materials = [], [], []
        offset = 0
        for polygon in read_land_file(entry.file, entry.height_m, entry.material):
            slope = polygon.slope_deg if polygon.slope_deg is not None else entry.slope_deg
            v, f = land_mesh(to_local(polygon.polygon, frame), polygon.height_m, slope)
            vertices.append(v)
            faces.append(f + offset)
            materials.append(np.full(len(f), material_index(polygon.material), np.int16))
            offset += len(v)
        mesh = BodyMesh(np.concatenate(vertices), np.concatenate(faces), np.concatenate(materials), entry.name)
        bodies.append(LandBody(entry.name, mesh, f"land[{i}]"))
    return bodies


def land_tiles(mesh: BodyMesh) -> list[BodyMesh]:
    """The mesh cut into tiles for the ray engine (the same surface; see the module docstring).

    Parameters
    ----------
    mesh : BodyMesh
        A land mesh in the local frame.

    Returns
    -------
    list of BodyMesh
        One per occupied :data:`TILE_M` square, triangles with edges of at most :data:`TILE_MAX_EDGE_M`.
    """
    vertices, faces, index = trimesh.remesh.subdivide_to_size(mesh.vertices_m, mesh.faces, TILE_MAX_EDGE_M,
                                                              max_iter=20, return_index=True)
    material = mesh.face_material[index]
    centroid = vertices[faces].mean(axis=1)
    cell = np.floor(centroid[:, :2] / TILE_M).astype(np.int64)
    _, tile = np.unique(cell, axis=0, return_inverse=True)
    order = np.argsort(tile.reshape(-1), kind="stable")
    starts = np.flatnonzero(np.diff(tile.reshape(-1)[order], prepend=-1))
    tiles = []
    for k, pick in enumerate(np.split(order, starts[1:])):  # one BodyMesh per tile (tens to hundreds)
        used, local = np.unique(faces[pick], return_inverse=True)
        tiles.append(BodyMesh(vertices[used], local.reshape(-1, 3), material[pick], f"{mesh.name}#{k}"))
    return tiles


__all__ = ["LandBody", "land_bodies", "land_tiles"]
