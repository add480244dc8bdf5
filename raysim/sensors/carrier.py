"""The world as seen from a sensor on the own ship.

A sensor's rays start on the own ship, so the own ship's bounding sphere holds every
ray origin: cast against it like any moving object, every ray would pay for a pose
evaluation and a transformation. The sensor already knows its rays in the own-ship
body frame (the mount is fixed), so :class:`CarrierScene` casts the own ship there,
without any pose, and the rest of the world in world coordinates.

Rays stopped by the own ship (a mast-top LiDAR sees a lot of its own deck) are not
cast into the world at all: nothing else can lie between a sensor and its own
deck, except the sea where a ray meets the hull below the waterline, which is
checked analytically.

A sensor whose body-frame rays repeat (the LiDAR's beams depend only on the
encoder azimuth and the laser) can precompute the own-ship hits once:
:meth:`CarrierScene.carrier_hits` on all of them, then pass the looked-up
:class:`raysim.scene.Hits` to :meth:`CarrierScene.cast`.

This is the ray engine's one own-ship mechanism (the renderers and
``benchmarks/ray_engine.py`` use it): :class:`raysim.scene.Scene` itself knows
no carrier, and two plain scenes do the work, one of the world without the own
ship and one of the own ship's body-frame mesh alone (a static scene, so no
pose is ever evaluated for it).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from raysim.motion import Stationary
from raysim.scene import NO_HIT, SEA_ID, Hits, Scene, SceneObject, intersect_sea


#: Margin of the own ship's bounding box for the rays' box test, m (float32 meshes, rounding).
BOX_MARGIN_M = 0.01


def _meets_box(origins_m: np.ndarray, directions: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(N,) bool: which rays (origins (N, 3) m, directions (N, 3)) meet the box [lo, hi] ahead of their origin.

    The slab test, vectorised; a direction component of 0 gives +-inf slab distances (the ray meets the slab
    everywhere or nowhere).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / np.asarray(directions, dtype=float)
        t1 = (lo[None, :] - origins_m) * inv
        t2 = (hi[None, :] - origins_m) * inv
    t_near = np.nanmax(np.minimum(t1, t2), axis=1)
    t_far = np.nanmin(np.maximum(t1, t2), axis=1)
    return t_far >= np.maximum(t_near, 0.0)


class CarrierScene:
    """Ray engine for sensors carried by the own ship (truth id ``carrier_id``).

    Parameters
    ----------
    objects : sequence of SceneObject
        Every object of the world, the own ship included.
    carrier_id : int
        Truth id of the own ship (0).
    sea_material : int
        Material index of sea hits.
    sea : bool
        Include the flat sea surface z = 0.

    Notes
    -----
    Normals of own-ship hits are in the own-ship *body* frame (use them with the
    body-frame directions); all other normals are in the world frame.
    """

    def __init__(self, objects: Sequence[SceneObject], carrier_id: int = 0, sea_material: int = -1, sea: bool = True):
        carrier = [o for o in objects if o.object_id == carrier_id]
        self.sea_material = sea_material
        self.sea = bool(sea)
        self.world = Scene([o for o in objects if o.object_id != carrier_id], sea=self.sea, sea_material=sea_material)
        self.carrier = None
        if carrier:
            body = carrier[0]
            self.carrier = Scene([SceneObject(body.object_id, body.vertices_m, body.faces, body.face_material,
                                              Stationary([0.0, 0.0, 0.0]))], sea=False)
            vertices = np.asarray(body.vertices_m, dtype=float)
            self._box = (vertices.min(axis=0) - BOX_MARGIN_M, vertices.max(axis=0) + BOX_MARGIN_M)

    def carrier_hits(self, origins_body_m: np.ndarray, directions_body: np.ndarray, max_range_m=np.inf) -> Hits:
        """Hits of body-frame rays on the own ship alone.

        Parameters
        ----------
        origins_body_m, directions_body : (N, 3) float
            Ray origins (metres) and unit directions in the own-ship body frame.
        max_range_m : float or (N,) float
            Hits farther than this count as no hit, metres.

        Returns
        -------
        Hits
            N hits, normals in the body frame (no hit anywhere if the world has no own ship).
        """
        n = origins_body_m.shape[0]
        if self.carrier is None:
            return Hits.empty(n)
        near = np.flatnonzero(_meets_box(origins_body_m, directions_body, *self._box))
        if near.size == n:
            return self.carrier.cast(origins_body_m, directions_body, np.zeros(n), max_range_m=max_range_m)
        hits = Hits.empty(n)  # only rays that meet the own ship's bounding box can hit it (a radar's rarely do)
        if near.size:
            limit = max_range_m if np.ndim(max_range_m) == 0 else np.asarray(max_range_m)[near]
            some = self.carrier.cast(np.asarray(origins_body_m)[near], np.asarray(directions_body)[near],
                                     np.zeros(near.size), max_range_m=limit)
            for name in ("range_m", "object_id", "normal", "material", "primitive"):
                getattr(hits, name)[near] = getattr(some, name)
        return hits

    def cast(self, origins_world_m: np.ndarray, directions_world: np.ndarray, times_s: np.ndarray,
             origins_body_m: np.ndarray | None = None, directions_body: np.ndarray | None = None,
             max_range_m=np.inf, carrier_hits: Hits | None = None) -> tuple[Hits, np.ndarray]:
        """First hits of rays given in the world and in the own-ship body frame.

        Parameters
        ----------
        origins_world_m, directions_world : (N, 3) float
            Ray origins (metres) and unit directions in the world (ENU) frame.
        times_s : (N,) float
            Time of each ray, seconds since scenario start.
        origins_body_m, directions_body : (N, 3) float
            The same rays in the own-ship body frame at their times (needed unless
            ``carrier_hits`` is given).
        max_range_m : float or (N,) float
            Hits farther than this count as no hit, metres.
        carrier_hits : Hits, optional
            Precomputed own-ship hits of these rays (:meth:`carrier_hits`).

        Returns
        -------
        hits : Hits
            Nearest hit per ray.
        on_carrier : (N,) bool
            Which rays hit the own ship first (their normals are body-frame).
        """
        n = np.shape(origins_world_m)[0]
        if carrier_hits is None and (np.shape(origins_body_m) != (n, 3) or np.shape(directions_body) != (n, 3)):
            raise ValueError("the body-frame rays must be (N, 3) like the world rays")
        own = carrier_hits if carrier_hits is not None else self.carrier_hits(origins_body_m, directions_body, max_range_m)
        on_carrier = own.object_id != NO_HIT
        if self.sea and on_carrier.any():
            # the sea can come first where a ray meets the hull below the waterline
            idx = np.flatnonzero(on_carrier)
            sea = intersect_sea(origins_world_m[idx, 2], directions_world[idx, 2])
            wet = sea < own.range_m[idx]
            on_carrier[idx[wet]] = False
        if not on_carrier.any():  # nothing on the own ship (a radar's usual case): the world's hits as they are
            return self.world.cast(origins_world_m, directions_world, times_s, max_range_m=max_range_m), on_carrier
        free = np.flatnonzero(~on_carrier)
        hits = Hits(own.range_m.copy(), own.object_id.copy(), own.normal.copy(), own.material.copy(), own.primitive.copy())
        if free.size:
            world = self.world.cast(origins_world_m[free], directions_world[free], times_s[free], max_range_m=max_range_m)
            hits.range_m[free] = world.range_m
            hits.object_id[free] = world.object_id
            hits.normal[free] = world.normal
            hits.material[free] = world.material
            hits.primitive[free] = world.primitive
        return hits, on_carrier


__all__ = ["CarrierScene", "Hits", "SEA_ID"]
