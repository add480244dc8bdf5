"""The scenario's ``land`` entries as meshes of the world: one object of kind ``land`` per entry.

Each entry's polygons (:func:`raysim.land.geojson.read_land_file`) are taken into the world's local
frame (:func:`raysim.land.mesh.to_local`), meshed (:func:`raysim.land.mesh.land_mesh`) and joined
into one :class:`raysim.meshes.BodyMesh` whose body frame IS the local frame (ENU metres; the
object stands at the origin with yaw 0), each face with its polygon's material.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from raysim.land.geojson import read_land_file
from raysim.land.mesh import land_mesh, to_local
from raysim.materials import material_index
from raysim.meshes import BodyMesh


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


__all__ = ["LandBody", "land_bodies"]
