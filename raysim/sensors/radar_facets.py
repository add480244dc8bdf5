"""Flat facets of the world's meshes, the apertures of the radar's physical-optics term.

A radar sees a flat panel (a hull side, a plate, a berg face) as one coherent aperture: its
specular RCS grows with the square of its area (REF 3.6). Meshes describe such panels with
several coplanar triangles, so each triangle is mapped to its *facet*: the group of adjacent
coplanar triangles it belongs to (trimesh ``facets``), with the facet's area and centre.

Per hit the renderer needs the facet's area and the line of sight from the antenna to the
facet's centre at the ray's time (objects move): :meth:`FacetTable.lookup`.
"""

from __future__ import annotations

import numpy as np
import trimesh

__all__ = ["FacetTable", "face_facets"]


def face_facets(vertices_m: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Area and centre of the flat facet each triangle belongs to.

    Parameters
    ----------
    vertices_m : (V, 3) float
    faces : (F, 3) int

    Returns
    -------
    area_m2 : (F,) float64
        Area of the triangle's facet (its own area if no coplanar neighbour).
    centre_m : (F, 3) float64
        Area-weighted centre of the facet, body frame.
    """
    mesh = trimesh.Trimesh(np.asarray(vertices_m, dtype=float), np.asarray(faces), process=False)
    mesh.merge_vertices()  # renumbers vertices only: face order (the ray engine's primitive ids) is kept
    tri_area = mesh.area_faces
    tri_centre = mesh.triangles_center
    area = tri_area.copy()
    centre = tri_centre.copy()
    for group in mesh.facets:  # one iteration per facet (not per ray); meshes have few
        a = tri_area[group]
        total = a.sum()
        area[group] = total
        centre[group] = (tri_centre[group] * a[:, None]).sum(axis=0) / max(total, 1e-300)
    return area, centre


class FacetTable:
    """Facet area and centre of every triangle of every object, addressed by (object id, primitive).

    Parameters
    ----------
    objects : sequence of raysim.world.WorldObject
        Objects with ``object_id``, ``mesh`` (:class:`raysim.meshes.BodyMesh`) and ``motion``.
    """

    def __init__(self, objects):
        self.objects = {o.object_id: o for o in objects}
        n = max(self.objects) + 1 if self.objects else 0
        self.offset = np.zeros(n + 1, dtype=np.int64)
        areas, centres = [], []
        start = 0
        for oid in range(n):
            self.offset[oid] = start
            obj = self.objects.get(oid)
            if obj is None:
                continue
            a, c = face_facets(obj.mesh.vertices_m, obj.mesh.faces)
            areas.append(a)
            centres.append(c)
            start += a.size
        self.offset[n] = start
        self.area_m2 = np.concatenate(areas) if areas else np.zeros(0)
        self.centre_body_m = np.concatenate(centres) if centres else np.zeros((0, 3))

    def lookup(self, object_id: np.ndarray, primitive: np.ndarray, times_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Facet area and world-frame centre of hits.

        Parameters
        ----------
        object_id, primitive : (H,) int
            Object hit and triangle index within its mesh.
        times_s : (H,) float
            Time of each hit's ray (the object's pose at that time places the centre).

        Returns
        -------
        area_m2 : (H,) float64
        centre_world_m : (H, 3) float64
        """
        g = self.offset[object_id] + primitive
        area = self.area_m2[g]
        centre = np.empty((g.size, 3))
        for oid in np.unique(object_id):  # one pose evaluation per object hit, vectorised over its hits
            sel = np.flatnonzero(object_id == oid)
            poses = self.objects[int(oid)].motion.poses(times_s[sel])
            rot = poses.rotation()
            centre[sel] = np.einsum("nij,nj->ni", rot, self.centre_body_m[g[sel]]) + poses.position_m
        return area, centre
