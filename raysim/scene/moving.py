"""The moving objects: one atlas of body-frame meshes, candidate pairs, one Embree call per batch.

All moving objects share ONE ``RaycastingScene``, the *atlas*, built once and
never rebuilt: each object's body-frame mesh (its own copy, even where objects
share a mesh) sits in its own cell of a square grid in the x-z plane, the
cells ``2 r_max + 10 m`` apart (``r_max``: the largest bounding radius of a
body about its origin), so the cells' spheres are disjoint and coordinates
stay within a few kilometres (float32 keeps sub-millimetre precision). The
grid is a vertical plane because sensors see bodies along near-horizontal
rays, which then leave the plane instead of crossing other cells (Embree
time).

For a batch: a swept bounding sphere per object over the batch's time span
(:func:`raysim.scene.poses.swept_spheres`); the rays that can still get a hit
beyond the nearest sphere are counting-sorted by direction cell; for all
objects at once (vectorised over (ray, object) pairs) the rays of each
object's cells, minus those whose current best hit is nearer than the sphere
can be, minus those failing an exact ray/sphere test. An object seen in every
direction (its sphere holds the origins, e.g. the own ship in a plain cast)
takes all rays that can still get a hit. The survivors get their poses at
their own times (:class:`raysim.scene.poses.PoseBank`; one pose per run of
pairs sharing an instant when that halves the work), are moved into the body
frame (``o' = R^T (o - p)``, ``d' = R^T d``, float64), pass a slab test
against the body's bounding box, are moved forward to the entry of the body's
bounding sphere (``t_entry = max(0, entry)``) and shifted into the body's
cell, and go to the atlas in ONE call. A hit counts only if its geometry is
the ray's own object (a ray starts at its own sphere and the spheres are
disjoint, so a hit on its own object comes first); the range is
``t_entry + t_hit`` in float64, normals are rotated back to the world frame,
and the nearest hit per ray replaces farther ones. No Python loop runs over
the objects (except over those seen in every direction and those with motions
of unknown kinds).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import open3d as o3d

from raysim.pose import rotation_matrices
from raysim.scene.geometry import (AZ_BINS, EL_BINS, SPHERE_PAD_M, gather_columns, pairs_hit_boxes, pairs_reach_spheres,
                                   sphere_cells, sphere_near_m)
from raysim.scene.hits import Hits, SceneObject
from raysim.scene.poses import PoseBank, swept_spheres
from raysim.scene.rays import RayBatch


@dataclass
class _Body:
    """A distinct moving mesh (shared by the objects that use the same one; each still gets its atlas copy)."""

    radius_m: float  # max vertex distance from the body origin


@dataclass
class _Mover:
    """A moving object and its body-frame mesh."""

    obj: SceneObject
    body: _Body
    face_material: np.ndarray  # (F,) int16


def _mesh_key(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    """Content hash of a mesh (objects with equal meshes share one :class:`_Body` record)."""
    h = hashlib.blake2b(digest_size=16)
    h.update(np.ascontiguousarray(vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(faces, dtype=np.int64).tobytes())
    return h.digest()


def _build_movers(objects: Sequence[SceneObject]) -> list[_Mover]:
    """One entry per moving object; its body record (bounding radius) computed once per distinct mesh."""
    bodies: dict[bytes, _Body] = {}
    movers = []
    for obj in objects:
        key = _mesh_key(obj.vertices_m, obj.faces)
        if key not in bodies:
            v = np.asarray(obj.vertices_m, dtype=np.float64)
            radius = float(np.sqrt((v * v).sum(axis=1).max())) if len(v) else 0.0
            bodies[key] = _Body(radius)
        movers.append(_Mover(obj, bodies[key], np.asarray(obj.face_material, dtype=np.int16)))
    return movers


def _build_atlas(movers: list[_Mover], radii: np.ndarray, nthreads: int):
    """ONE Open3D scene holding every moving object's body-frame mesh in its own cell.

    Object k's mesh sits at ``offset[:, k]``, the centre of cell k of a square grid in
    the body x-z plane whose spacing is twice the largest bounding radius plus 10 m
    (geometry id = object label).

    Parameters
    ----------
    movers : list of _Mover
    radii : (K,) float64
        Bounding radius of each body about its origin (padded), metres.
    nthreads : int
        Embree threads (0 = all cores).

    Returns
    -------
    scene : RaycastingScene or None
    offsets : (3, K) float64
        Atlas position of each body origin, metres.
    """
    if not movers:
        return None, np.zeros((3, 0))
    spacing = 2.0 * float(radii.max()) + 10.0
    side = 1
    while side**2 < len(movers):
        side += 1
    index = np.arange(len(movers))
    cells = np.stack([index % side, np.full(len(movers), (side - 1) / 2.0), index // side]).astype(np.float64)
    offsets = (cells - (side - 1) / 2.0) * spacing  # y = 0
    scene = o3d.t.geometry.RaycastingScene(nthreads=nthreads)
    for k, mover in enumerate(movers):
        vertices = np.asarray(mover.obj.vertices_m, dtype=np.float64) + offsets[:, k]
        gid = scene.add_triangles(
            o3d.core.Tensor(np.ascontiguousarray(vertices, dtype=np.float32)),
            o3d.core.Tensor(np.ascontiguousarray(mover.obj.faces, dtype=np.uint32)),
        )
        if gid != k:
            raise RuntimeError(f"unexpected Open3D geometry id {gid}")
    return scene, offsets


def _rotate_back(r: np.ndarray, planar: bool, v: np.ndarray, out: np.ndarray) -> None:
    """``out = R^T v`` for (3, P) vectors; ``r``: (2, P) cos/sin of yaw if ``planar``, else (9, P) rows of R."""
    if planar:
        c, s = r
        out[0] = c * v[0] + s * v[1]
        out[1] = c * v[1] - s * v[0]
        out[2] = v[2]
    else:
        for i in range(3):
            out[i] = r[i] * v[0] + r[3 + i] * v[1] + r[6 + i] * v[2]


def _rotate(r: np.ndarray, planar: bool, n_b: np.ndarray) -> np.ndarray:
    """``R n`` of (3, S) body-frame vectors, as (S, 3) world vectors (``r`` as in :func:`_rotate_back`)."""
    if planar:
        c, s = r
        return np.stack([c * n_b[0] - s * n_b[1], s * n_b[0] + c * n_b[1], n_b[2]], axis=1)
    return np.stack([r[3 * i] * n_b[0] + r[3 * i + 1] * n_b[1] + r[3 * i + 2] * n_b[2] for i in range(3)], axis=1)


class MovingPart:
    """Every moving object of a scene, cast together through the atlas.

    Parameters
    ----------
    objects : sequence of SceneObject
        The moving objects (none static, none with an empty mesh).
    nthreads : int
        Embree threads (0 = all cores).
    cull : bool
        Cull (ray, object) pairs; ``False`` casts every ray at every object (a brute-force reference).
    """

    def __init__(self, objects: Sequence[SceneObject], nthreads: int = 0, cull: bool = True) -> None:
        self.nthreads = int(nthreads)
        self.cull = bool(cull)
        self.movers = _build_movers(objects)
        self.ids = np.array([m.obj.object_id for m in self.movers], dtype=np.int32)
        self.speed = np.array([float(m.obj.motion.max_speed_mps) for m in self.movers], dtype=np.float64)
        self.bank = PoseBank([m.obj.motion for m in self.movers])
        n_faces = [len(m.face_material) for m in self.movers]
        self.face_offset = np.concatenate(([0], np.cumsum(n_faces)[:-1])).astype(np.int64)
        boxes = [(m.obj.vertices_m.min(axis=0), m.obj.vertices_m.max(axis=0)) for m in self.movers]
        pad = SPHERE_PAD_M
        self.box_lo = np.array([b[0] - pad for b in boxes]).reshape(-1, 3).T  # (3, K) body frame
        self.box_hi = np.array([b[1] + pad for b in boxes]).reshape(-1, 3).T
        self.materials = np.concatenate([m.face_material for m in self.movers]) if self.movers else np.zeros(0, np.int16)
        self.radius = np.array([m.body.radius_m for m in self.movers], dtype=np.float64) + SPHERE_PAD_M
        self.radius2 = self.radius**2
        self.atlas, self.atlas_offset = _build_atlas(self.movers, self.radius, self.nthreads)

    def __len__(self) -> int:
        return len(self.movers)

    @property
    def n_bodies(self) -> int:
        """Number of distinct moving meshes."""
        return len({id(m.body) for m in self.movers})

    def cast(self, hits: Hits, batch: RayBatch) -> None:
        """Cast a batch against every moving object, keeping nearer hits (in place).

        Candidate (ray, object) pairs are selected for all objects at once, their
        poses are evaluated in one vectorised pass per motion kind, transformed with
        one vectorised pass, cast with one Open3D call for all objects (the atlas),
        and the nearest hit per ray is merged in one pass.

        Parameters
        ----------
        hits : Hits
            The batch's N current hits (sea, static objects, range limit), updated in place.
        batch : RayBatch
            N world-frame rays (metres, seconds), with the pre-pass done when culling.
        """
        if not self.cull:  # brute force, one object at a time (bounded memory)
            ray = np.arange(batch.n)
            o, d = np.ascontiguousarray(batch.origins.T), np.ascontiguousarray(batch.directions.T)
            for k in range(len(self.movers)):
                self._merge(hits, self._cast_pairs(batch, hits, ray, np.full(batch.n, k), o, d))
            return
        tmin, tmax = float(batch.times.min()), float(batch.times.max())
        range_cap = np.inf if batch.max_range is None else float(np.max(batch.max_range))
        centres, radii = swept_spheres(self.bank, self.speed, self.radius, tmin, tmax)
        if not np.any(sphere_near_m(centres, radii, batch.origin_centre, batch.spread_m) <= range_cap):
            return  # every object beyond the range limit (sphere_cells' near_m, without the cells)
        cells = sphere_cells(centres, radii, batch.origin_centre, batch.spread_m)
        live = np.flatnonzero(cells.near_m <= range_cap)
        limit = hits.range_m
        if batch.max_range is not None:
            limit = np.minimum(limit, batch.max_range)
        everywhere = (cells.a0 == 0) & (cells.a1 == AZ_BINS - 1) & (cells.e0 == 0) & (cells.e1 == EL_BINS - 1)
        around, rest = live[everywhere[live]], live[~everywhere[live]]
        parts = []
        if rest.size:  # rays of the objects' cells, via the cell-sorted order
            parts.append(self._culled_pairs(batch, limit, cells, rest, centres, radii))
        for k in around.tolist():
            # An object seen in every direction (e.g. the ship carrying the sensor):
            # its rays in ray order (runs of equal times share one pose); a sphere
            # test would filter next to nothing.
            ray = np.flatnonzero(limit > cells.near_m[k])
            parts.append((ray, np.full(ray.size, k), gather_columns(batch.origins, ray),
                          gather_columns(batch.directions, ray)))
        if len(parts) > 1:
            ray, label = np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
            o, d = np.concatenate([p[2] for p in parts], axis=1), np.concatenate([p[3] for p in parts], axis=1)
        else:
            ray, label, o, d = parts[0]
        if ray.size:
            self._merge(hits, self._cast_pairs(batch, hits, ray, label, o, d))

    def _culled_pairs(self, batch: RayBatch, limit: np.ndarray, cells, rest: np.ndarray, centres: np.ndarray,
                      radii: np.ndarray) -> tuple[np.ndarray, ...]:
        """(ray, label) pairs of the objects ``rest`` that pass the cell, distance and sphere tests.

        Parameters
        ----------
        limit : (N,) float64
            Range beyond which each ray can get no new hit, metres.
        cells : SphereCells
            Of all K objects' swept spheres ``centres`` (K, 3) and ``radii`` (K,), metres.
        rest : (R,) int
            Objects not seen in every direction.

        Returns
        -------
        ray, label : (P,) int64
        o, d : (3, P) float64
            World origins (metres) and directions of the pairs' rays.
        """
        batch.sort_by_cell(limit, float(cells.near_m[rest].min()))
        ray, label = self._pairs_in_cells(batch, *cells.runs(rest))
        keep = np.take(limit, ray) > np.take(cells.near_m, label)
        ray, label = ray[keep], label[keep]
        o, d = gather_columns(batch.origins, ray), gather_columns(batch.directions, ray)
        keep = np.flatnonzero(
            pairs_reach_spheres(o, d, np.take(centres.T, label, axis=1), np.take(radii, label), np.take(limit, ray))
        )
        if keep.size < ray.size:
            ray, label, o, d = ray[keep], label[keep], np.take(o, keep, axis=1), np.take(d, keep, axis=1)
        return ray, label, o, d

    @staticmethod
    def _pairs_in_cells(
        batch: RayBatch, label: np.ndarray, lo: np.ndarray, hi: np.ndarray, e0: np.ndarray, e1: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """All (ray, object label) pairs whose ray direction lies in the object's cells.

        Parameters
        ----------
        label, lo, hi, e0, e1 : (R,) int64
            Azimuth runs (see :meth:`SphereCells.runs`).

        Returns
        -------
        ray, label : (P,) int64
            Pairs grouped by label, labels ascending.
        """
        full = (e0 == 0) & (e1 == EL_BINS - 1)  # whole azimuth run is one contiguous block
        n_bins = np.where(full, 1, hi - lo + 1)
        row = np.repeat(np.arange(label.size), n_bins)
        a = lo[row] + (np.arange(row.size) - np.repeat(np.cumsum(n_bins) - n_bins, n_bins))  # azimuth bin
        first = np.where(full[row], lo[row] * EL_BINS, a * EL_BINS + e0[row])
        end = np.where(full[row], (hi[row] + 1) * EL_BINS, a * EL_BINS + e1[row] + 1)
        start = batch.cell_start
        first = start[first]
        length = start[end] - first
        total = int(length.sum())
        if total == 0:
            return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
        pos = np.repeat(first - (np.cumsum(length) - length), length) + np.arange(total)
        return batch.order[pos], np.repeat(label[row], length)

    def _pair_rotations(self, batch: RayBatch, ray: np.ndarray, label: np.ndarray):
        """Poses of (ray, object) pairs at the rays' times.

        Consecutive pairs of one object may share an instant (the rays of a LiDAR
        firing or a radar spoke in ray order): one pose per run of equal times, when
        that saves much; otherwise one pose per pair.

        Returns
        -------
        position : (3, P) float64
            Body origin of each pair, metres.
        rot : (2, U) or (9, U) float64
            cos and sin of yaw (``planar``) or the rows of R (``rot[3 i + j] = R[i, j]``), per instant.
        instant : (P,) int64 or None
            Instant of each pair (None: one instant per pair).
        planar : bool
            Yaw-only rotations.
        """
        times = np.take(batch.times, ray)
        new = np.empty(ray.size, dtype=bool)
        new[0] = True
        np.not_equal(times[1:], times[:-1], out=new[1:])
        new[1:] |= label[1:] != label[:-1]
        first = np.flatnonzero(new)  # first pair of each instant
        if 2 * first.size > ray.size:
            instant = None
            position, yaw, pitch, roll = self.bank.poses(label, times)
        else:
            instant = np.cumsum(new) - 1
            position, yaw, pitch, roll = self.bank.poses(label[first], times[first])
            position = np.take(position, instant, axis=1)
        planar = pitch is None
        if planar:  # yaw only: R = Rz(yaw)
            rot = np.stack([np.cos(yaw), np.sin(yaw)])  # (2, U)
        else:
            rot = rotation_matrices(yaw, pitch, roll).reshape(-1, 9).T  # (9, U): row 3 i + j = R[i, j]
        return position, rot, instant, planar

    def _cast_pairs(
        self, batch: RayBatch, hits: Hits, ray: np.ndarray, label: np.ndarray, o: np.ndarray, d: np.ndarray
    ) -> dict[str, np.ndarray] | None:
        """Cast (ray, object) pairs at the objects' poses at the rays' times (one Embree call).

        Parameters
        ----------
        ray, label : (P,) int
            Pairs (consecutive pairs of one object and one time share a pose).
        o, d : (3, P) float64
            World origin (metres) and unit direction of each pair's ray.

        Returns
        -------
        dict or None
            For the pairs that hit their object nearer than the ray's current best:
            ``ray``, ``label``, ``t`` (range, m), ``prim``, ``normal`` (world, (M, 3)).
        """
        position, rot, instant, planar = self._pair_rotations(batch, ray, label)
        if instant is None:
            instant = np.arange(ray.size)
            r = rot
        else:
            r = np.take(rot, instant, axis=1)
        body_o, body_d = np.empty((3, ray.size)), np.empty((3, ray.size))
        _rotate_back(r, planar, o - position, body_o)
        _rotate_back(r, planar, d, body_d)
        lo = np.take(self.box_lo, label, axis=1)
        hi = np.take(self.box_hi, label, axis=1)
        inside = np.flatnonzero(pairs_hit_boxes(body_o, body_d, lo, hi))
        if inside.size == 0:
            return None
        if inside.size < ray.size:
            ray, label, instant = ray[inside], label[inside], instant[inside]
            body_o, body_d, d = (np.take(x, inside, axis=1) for x in (body_o, body_d, d))
        t, res = self._cast_atlas(label, body_o, body_d)
        better = (res["geometry_ids"].numpy().view(np.int32) == label) & (t < np.take(hits.range_m, ray))
        if batch.max_range is not None:  # (another cell's object is never nearer than the ray's own)
            better &= t <= (np.take(batch.max_range, ray) if batch.max_range.ndim else float(batch.max_range))
        sel = np.flatnonzero(better)
        if sel.size == 0:
            return None
        n_world = _rotate(np.take(rot, instant[sel], axis=1), planar,
                          res["primitive_normals"].numpy()[sel].T.astype(np.float64))
        flip = np.einsum("ni,in->n", n_world, np.take(d, sel, axis=1)) > 0
        n_world[flip] *= -1.0
        prim = res["primitive_ids"].numpy().view(np.int32)[sel]
        return {"ray": ray[sel], "label": label[sel], "t": t[sel], "prim": prim, "normal": n_world}

    def _cast_atlas(self, label: np.ndarray, body_o: np.ndarray, body_d: np.ndarray) -> tuple[np.ndarray, dict]:
        """One Open3D call for all objects' body-frame rays (the atlas).

        Each ray starts where it enters its object's bounding sphere (float64),
        moved into the object's atlas cell.

        Parameters
        ----------
        label : (P,) int
            Object of each ray.
        body_o, body_d : (3, P) float64
            Body-frame origins (metres) and unit directions.

        Returns
        -------
        t : (P,) float64
            Range from the body-frame origin to the atlas hit, metres (``inf`` if none).
        res : dict
            Open3D's answers.
        """
        b = np.einsum("ij,ij->j", body_o, body_d)
        c = np.einsum("ij,ij->j", body_o, body_o) - np.take(self.radius2, label)
        disc = b * b - c
        np.maximum(disc, 0.0, out=disc)
        np.sqrt(disc, out=disc)
        t_entry = -b - disc
        np.maximum(t_entry, 0.0, out=t_entry)
        shifted = np.empty((label.size, 6), dtype=np.float32)
        shifted[:, :3] = (body_o + t_entry * body_d + np.take(self.atlas_offset, label, axis=1)).T
        shifted[:, 3:] = body_d.T
        res = self.atlas.cast_rays(o3d.core.Tensor.from_numpy(shifted), nthreads=self.nthreads)
        return t_entry + res["t_hit"].numpy(), res

    def _merge(self, hits: Hits, found: dict[str, np.ndarray] | None) -> None:
        """Write the nearest moving-object hit of each ray into ``hits`` (in place)."""
        if found is None:
            return
        ray, t = found["ray"], found["t"]
        order = np.lexsort((t, ray))
        first = order[np.r_[True, ray[order][1:] != ray[order][:-1]]]  # nearest per ray
        first = first[t[first] < hits.range_m[ray[first]]]
        j, label, prim = ray[first], found["label"][first], found["prim"][first]
        hits.range_m[j] = t[first]
        hits.object_id[j] = self.ids[label]
        hits.primitive[j] = prim
        hits.material[j] = self.materials[self.face_offset[label] + prim]
        hits.normal[j] = found["normal"][first]
