"""What the ray engine answers with, and what it casts at: hits and scene objects.

:class:`SceneObject` is one rigid object (body-frame mesh, materials, motion);
:class:`Hits` holds the first hit of each ray of a batch. :data:`SEA_ID` and
:data:`NO_HIT` are the object ids of sea hits and of rays that hit nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from raysim.motion import Motion, Stationary

SEA_ID = -2
"""Object id reported for hits on the sea surface."""
NO_HIT = -1
"""Object id reported for rays that hit nothing (within range)."""


@dataclass(frozen=True)
class SceneObject:
    """One rigid object of the scene.

    Attributes
    ----------
    object_id : int
        Truth id, >= 0.
    vertices_m : (V, 3) float64
        Vertices in the body frame (x forward, y left, z up, z = 0 at the
        waterline), metres.
    faces : (F, 3) int
        Triangle vertex indices.
    face_material : (F,) int16
        Material index of each face.
    motion : Motion
        Pose over time; :class:`raysim.motion.Stationary` for fixed objects
        (those go into the static acceleration structure).
    """

    object_id: int
    vertices_m: np.ndarray
    faces: np.ndarray
    face_material: np.ndarray
    motion: Motion

    @property
    def is_static(self) -> bool:
        """True if the object never moves (Stationary motion, zero speed)."""
        return isinstance(self.motion, Stationary) and float(self.motion.max_speed_mps) == 0.0


@dataclass
class Hits:
    """First hit of each of N rays.

    Attributes
    ----------
    range_m : (N,) float64
        Distance along the unit direction to the first hit, metres; ``inf`` if
        none.
    object_id : (N,) int32
        Truth id of the object hit, :data:`SEA_ID`, or :data:`NO_HIT`.
    normal : (N, 3) float32
        Unit surface normal in the world frame, facing against the ray
        (``n . d <= 0``); zeros if no hit.
    material : (N,) int16
        Material index of the face hit (the scene's ``sea_material`` for the
        sea); -1 if no hit.
    primitive : (N,) int32
        Triangle index within the object's mesh; -1 for the sea or no hit.
    """

    range_m: np.ndarray
    object_id: np.ndarray
    normal: np.ndarray
    material: np.ndarray
    primitive: np.ndarray

    @classmethod
    def empty(cls, n: int) -> "Hits":
        """Hits of ``n`` rays that hit nothing."""
        return cls(
            np.full(n, np.inf),
            np.full(n, NO_HIT, dtype=np.int32),
            np.zeros((n, 3), dtype=np.float32),
            np.full(n, -1, dtype=np.int16),
            np.full(n, -1, dtype=np.int32),
        )

    @property
    def hit(self) -> np.ndarray:
        """(N,) bool, True where the ray hit something (object or sea)."""
        return self.object_id != NO_HIT


def check_object(obj: SceneObject) -> None:
    """Raise ValueError if an object's arrays are inconsistent.

    Parameters
    ----------
    obj : SceneObject
        Checked: (V, 3) vertices, (F, 3) faces indexing them, (F,) materials, id >= 0.
    """
    v, f, m = np.asarray(obj.vertices_m), np.asarray(obj.faces), np.asarray(obj.face_material)
    if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"object {obj.object_id}: vertices and faces must be (V, 3) and (F, 3)")
    if m.shape != (f.shape[0],):
        raise ValueError(f"object {obj.object_id}: face_material must have one entry per face")
    if f.size and (f.min() < 0 or f.max() >= v.shape[0]):
        raise ValueError(f"object {obj.object_id}: face index out of range")
    if obj.object_id < 0:
        raise ValueError(f"object id must be >= 0, got {obj.object_id}")


def drop_beyond(hits: Hits, max_range: np.ndarray) -> None:
    """Turn hits farther than ``max_range`` into no hits (in place).

    Parameters
    ----------
    hits : Hits
        N hits, modified in place.
    max_range : float or (N,) float64
        Range limit, metres.
    """
    idx = np.flatnonzero(hits.range_m > max_range)
    if idx.size == 0:
        return
    hits.range_m[idx] = np.inf
    hits.object_id[idx] = NO_HIT
    hits.material[idx] = -1
    hits.primitive[idx] = -1
    hits.normal[idx] = 0.0
